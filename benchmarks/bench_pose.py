"""Pose to pose: random start and goal headings on the shared maps, both drives, checked independently.

Every query of a shared suite (:func:`trajopt.bench.suite`: the feasible Moving AI scenarios,
disc radius 2.5 cells, and seeded random free pairs on the ROS maps, radius 0.165 m) is
planned with a disc robot, ``Robot(radius=r, drive=D)`` for ``D`` in ``differential`` and
``omni``, twice in the same warm planner: with free headings (``plan(start, goal)``) and with
seeded random headings (``plan(start, goal, start_heading=h0, goal_heading=h1)``, each
uniform in ``[-pi, pi)`` from ``numpy.random.default_rng([seed, crc32(map file name),
query index])``). Each plan with headings is checked on 1 ms samples by code that
shares nothing with the planner's clearance code:

* **collisions**: the exact distance from every sample's centre to the raw map's occupied
  squares (cells as closed squares, the outside of the map occupied), from a KD-tree of the
  obstacles' boundary cells; a sample collides when that distance is below the radius by
  more than 1e-9 m (the smallest margin is printed, with that of the free-heading plans
  of the same queries beside it);
* **headings**: ``theta`` at ``t = 0`` and ``t = duration`` against ``h0`` and ``h1``, modulo
  ``2 pi``, to 1e-6 rad; the end points to 1e-6 m;
* **limits**: a differential drive's turns in place (:class:`trajopt.TurnInPlace` pieces)
  against :func:`trajopt.timing.turn_limits` (yaw rate from the samples, yaw acceleration
  and jerk from their first and second differences, relative tolerance 1e-6), its curve
  by ``trajopt.metrics.trajectory_metrics(piece, robot, dt=0.001)["within_limits"]``; an
  omni plan by ``trajectory_metrics`` (speed, acceleration, jerk, lateral acceleration, the
  orientation's rate against ``omega_max``) and the orientation's yaw rate, acceleration
  and jerk (from the samples, as for the turns) against ``turn_limits`` (the limits
  :func:`trajopt.timing.orient` holds);
* **differential**: the duration overhead against the free-heading plan, the share of plans
  with a turn in place, and that the plan chosen is never slower than the pure
  turn-drive-turn plan (``stats["pose"]["durations_s"]["turn"]``; that figure is also
  recomputed as the free plan plus two :func:`trajopt.timing.turn_in_place`);
* **omni**: the duration ratio against the free-heading plan (targets: median <= 1.02,
  max <= 1.10);
* **plan time**: wall time of the plan with headings over that of the free plan, per query
  (target: median <= 1.5), both measured in the same run after one warm-up query per map
  and drive, their order alternating from query to query; each query is planned
  ``--repeat`` times both ways, alternately, and the smallest time of each kept (a smoother
  solver built for a new problem size, or a burst of load, would otherwise land on one
  side of the ratio).

The omni part needs the planner to return an orientation profile (a trajectory whose
samples carry ``course`` besides ``theta``); a probe on an empty map decides, and without
it the omni lines read "omni: not available" with the reason.

Run: ``python benchmarks/bench_pose.py [--limit 8] [--seed 0] [--quick]`` (``--quick``:
the ``shared-small`` suite as it is, 4 queries per map, under a minute; the default: the
``shared-full`` suite, ``--limit`` queries per map). Needs the shared data
(``$TRAJOPT_DATA`` or ``../shared/data``); skipped with a message when it is absent.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
import time
import zlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial import cKDTree

import astar
import trajopt
from trajopt.analysis.bench._suites import SUITES
from trajopt.analysis.metrics import trajectory_metrics
from trajopt.errors import TrajoptError
from trajopt.timing import turn_in_place, turn_limits

ROOT = Path(__file__).resolve().parents[1]
DT = 1e-3  # sampling step of every check (s)
HEADING_TOL = 1e-6  # rad
POINT_TOL = 1e-6  # m
COLLISION_TOL = 1e-9  # m
LIMIT_TOL = 1e-6  # relative
DRIVES = ("differential", "omni")


def data_root() -> Path | None:
    """The shared data folder ($TRAJOPT_DATA, else ../shared/data), or None when absent."""
    env = os.environ.get("TRAJOPT_DATA")
    d = Path(env) if env else ROOT.parent / "shared" / "data"
    return d if (d / "movingai").is_dir() and (d / "ros").is_dir() else None


def wrap(a: np.ndarray | float) -> np.ndarray:
    """Angles wrapped to [-pi, pi]."""
    return np.remainder(np.asarray(a, dtype=float) + math.pi, 2.0 * math.pi) - math.pi


# ------------------------------------------------------------------ independent clearance
class Obstacles:
    """Exact distances from points to a map's occupied squares (outside the map occupied).

    Only the boundary squares (occupied, with a free 4-neighbour) can be nearest to a point
    in free space; a point inside an occupied square (or outside the map) is at distance 0.
    """

    def __init__(self, grid: Any) -> None:
        occ = np.asarray(grid.occupied, dtype=bool)
        self.occ = occ
        self.res = float(grid.resolution)
        self.ox, self.oy = (float(v) for v in grid.origin)
        pad = np.pad(occ, 2, constant_values=True)
        free = ~pad
        nb_free = np.zeros_like(pad)
        nb_free[1:, :] |= free[:-1, :]
        nb_free[:-1, :] |= free[1:, :]
        nb_free[:, 1:] |= free[:, :-1]
        nb_free[:, :-1] |= free[:, 1:]
        iy, ix = np.nonzero(pad & nb_free)
        self.cx = self.ox + (ix - 2 + 0.5) * self.res
        self.cy = self.oy + (iy - 2 + 0.5) * self.res
        self.tree = cKDTree(np.column_stack([self.cx, self.cy]))

    def distance(self, x: np.ndarray, y: np.ndarray, reach: float) -> np.ndarray:
        """Exact distance to the nearest occupied square, where it is below ``reach`` (m).

        Points farther than ``reach - res / sqrt 2`` from every square may get ``inf``.
        """
        x = np.asarray(x, dtype=float).ravel()
        y = np.asarray(y, dtype=float).ravel()
        out = np.full(x.size, np.inf)
        step = 200_000
        for k in range(0, x.size, step):
            xs, ys = x[k : k + step], y[k : k + step]
            pts = np.column_stack([xs, ys])
            ptree = cKDTree(pts)
            m = ptree.sparse_distance_matrix(self.tree, reach, output_type="ndarray")
            d = np.full(xs.size, np.inf)
            if m.size:
                i, j = m["i"], m["j"]
                dx = np.maximum(np.abs(xs[i] - self.cx[j]) - 0.5 * self.res, 0.0)
                dy = np.maximum(np.abs(ys[i] - self.cy[j]) - 0.5 * self.res, 0.0)
                np.minimum.at(d, i, np.hypot(dx, dy))
            cx = np.floor((xs - self.ox) / self.res).astype(np.int64)
            cy = np.floor((ys - self.oy) / self.res).astype(np.int64)
            ny, nx = self.occ.shape
            inside = (cx >= 0) & (cx < nx) & (cy >= 0) & (cy < ny)
            blocked = ~inside
            blocked[inside] = self.occ[cy[inside], cx[inside]]
            d[blocked] = 0.0
            out[k : k + step] = d
        return out


def times(duration: float) -> np.ndarray:
    """Sample times every DT from 0, and the end."""
    t = np.arange(0.0, duration, DT)
    return np.append(t, duration)


# ------------------------------------------------------------------ limits
def diff_limits(a: np.ndarray, t: np.ndarray) -> tuple[float, float]:
    """Peaks of the first and second differences of ``a`` sampled at ``t``."""
    if a.size < 2:
        return 0.0, 0.0
    dt = np.diff(t)
    keep = dt > 1e-9
    d1 = np.diff(a)[keep] / dt[keep]
    tm = 0.5 * (t[1:] + t[:-1])[keep]
    p1 = float(np.max(np.abs(d1))) if d1.size else 0.0
    if d1.size < 2:
        return p1, 0.0
    dtm = np.diff(tm)
    keep2 = dtm > 0.5 * DT  # the short last interval gives a noisy second difference
    d2 = np.diff(d1)[keep2] / dtm[keep2]
    return p1, float(np.max(np.abs(d2))) if d2.size else 0.0


def yaw_violations(
    label: str, t: np.ndarray, omega: np.ndarray, limits: tuple[float, float, float]
) -> list[str]:
    """Yaw rate, acceleration and jerk (first and second differences) over their limits."""
    alpha, zeta = diff_limits(omega, t)
    out = []
    for name, peak, lim in zip(
        ("yaw rate", "yaw acceleration", "yaw jerk"),
        (float(np.max(np.abs(omega))), alpha, zeta),
        limits,
        strict=True,
    ):
        if peak > lim * (1.0 + LIMIT_TOL):
            out.append(f"{label} {name} {peak:.6g} > {lim:.6g}")
    return out


def turn_violations(turn: Any, robot: Any) -> list[str]:
    """The limits a turn in place exceeds on 1 ms samples (empty if none)."""
    t = times(turn.duration)
    smp = turn.sample(t)
    out = yaw_violations("turn", t, np.asarray(smp.omega), turn_limits(robot))
    if float(np.max(np.abs(smp.v))) > 0.0:
        out.append("turn in place moves")
    return out


def orientation_limits(traj: Any, robot: Any) -> tuple[tuple[float, float, float], str]:
    """The orientation's yaw limits: ``turn_limits(robot)``, and where its stats name others."""
    own = turn_limits(robot)
    ori = (getattr(traj, "stats", None) or {}).get("orientation") or {}
    lim = ori.get("limits") or {}
    named = tuple(float(lim.get(k, math.nan)) for k in ("omega", "alpha", "zeta"))
    if all(math.isfinite(v) for v in named):
        if all(abs(a - b) <= 1e-12 * max(1.0, b) for a, b in zip(named, own, strict=True)):
            return own, "turn_limits(robot) (= stats['orientation']['limits'])"
        return tuple(min(a, b) for a, b in zip(named, own, strict=True)), (
            "the smaller of turn_limits(robot) and stats['orientation']['limits'] "
            f"{named} (they differ)"
        )
    return own, "turn_limits(robot)"


def limit_violations(traj: Any, robot: Any, drive: str) -> list[str]:
    """Every limit exceeded on 1 ms samples, piece by piece (empty if none)."""
    out: list[str] = []
    if drive == "omni":
        m = trajectory_metrics(traj, robot, dt=DT, tol=LIMIT_TOL)
        if not m["within_limits"]:
            bad = [
                f"{k[6:]} {m[k]:.6g}"
                for k in m
                if k.startswith("ratio_") and math.isfinite(m[k]) and m[k] > 1 + LIMIT_TOL
            ]
            out.append("metrics: " + ", ".join(bad))
        t = times(traj.duration)
        lims, _ = orientation_limits(traj, robot)
        out += yaw_violations("orientation", t, np.asarray(traj.sample(t).omega), lims)
        return out
    for piece in getattr(traj, "pieces", (traj,)):
        if isinstance(piece, trajopt.TurnInPlace):
            out += turn_violations(piece, robot)
        else:
            m = trajectory_metrics(piece, robot, dt=DT, tol=LIMIT_TOL)
            if not m["within_limits"]:
                bad = [
                    f"{k[6:]} {m[k]:.6g}"
                    for k in m
                    if k.startswith("ratio_") and math.isfinite(m[k]) and m[k] > 1 + LIMIT_TOL
                ]
                out.append(f"{type(piece).__name__}: " + ", ".join(bad))
    return out


# ------------------------------------------------------------------ one query
@dataclass
class Row:
    map_name: str
    drive: str
    start: tuple[float, float]
    goal: tuple[float, float]
    h0: float
    h1: float
    err: str = ""
    free_err: str = ""
    t_free: float = math.nan
    t_head: float = math.nan
    d_free: float = math.nan
    d_head: float = math.nan
    min_margin: float = math.inf
    inner_margin: float = math.inf
    free_margin: float = math.inf
    alpha_src: str = ""
    collided: bool = False
    heading_err: float = math.nan
    point_err: float = math.nan
    limits: list[str] = field(default_factory=list)
    turned: bool = False
    chosen: str = ""
    d_turn: float = math.nan
    d_turn_indep: float = math.nan


def timed(fn: Any) -> tuple[Any, float, str]:
    t0 = time.perf_counter()
    try:
        out = fn()
    except TrajoptError as exc:
        return None, time.perf_counter() - t0, f"{type(exc).__name__}: {exc}"
    return out, time.perf_counter() - t0, ""


def run_pair(
    planner: Any, s: Any, g: Any, h0: float, h1: float, free_first: bool, repeat: int = 1
) -> tuple:
    """Plan a query with free headings and with (h0, h1), alternately ``repeat`` times each.

    Returns ``((free, t, err), (with headings, t, err))``: the first results and the
    smallest wall time of each (s).
    """

    def free() -> Any:
        return planner.plan(s, g)

    def head() -> Any:
        return planner.plan(s, g, start_heading=h0, goal_heading=h1)

    order = (free, head) if free_first else (head, free)
    got: dict[Any, tuple] = {}
    for _ in range(max(1, repeat)):
        for fn in order:
            out, t, err = timed(fn)
            if fn in got:
                out, t0, err = got[fn][0], min(t, got[fn][1]), got[fn][2]
                t = t0
            got[fn] = (out, t, err)
    return got[free], got[head]


def check(row: Row, traj: Any, free: Any, robot: Any, obstacles: Obstacles) -> None:
    """Fill the row's checks of the plan with headings."""
    t = times(traj.duration)
    smp = traj.sample(t)
    x, y = np.asarray(smp.x), np.asarray(smp.y)
    r = robot.radius
    d = obstacles.distance(x, y, r + obstacles.res)
    margin = float(np.min(d)) - r
    row.min_margin = margin
    away = (np.hypot(x - row.start[0], y - row.start[1]) > r) & (
        np.hypot(x - row.goal[0], y - row.goal[1]) > r
    )
    row.inner_margin = float(np.min(d[away])) - r if np.any(away) else math.inf
    row.collided = margin < -COLLISION_TOL
    th = np.asarray(smp.theta)
    row.heading_err = float(max(abs(wrap(th[0] - row.h0)), abs(wrap(th[-1] - row.h1))))
    row.point_err = float(
        max(
            math.hypot(x[0] - row.start[0], y[0] - row.start[1]),
            math.hypot(x[-1] - row.goal[0], y[-1] - row.goal[1]),
        )
    )
    row.limits = limit_violations(traj, robot, row.drive)
    if free is not None:
        fs = free.sample(times(free.duration))
        row.free_margin = float(np.min(obstacles.distance(fs.x, fs.y, r + obstacles.res))) - r
    if row.drive == "omni":
        row.alpha_src = orientation_limits(traj, robot)[1]
    if row.drive == "differential":
        pieces = getattr(traj, "pieces", ())
        row.turned = any(isinstance(p, trajopt.TurnInPlace) for p in pieces)
        pose = (getattr(traj, "stats", None) or {}).get("pose") or {}
        row.chosen = str(pose.get("chosen", "?"))
        row.d_turn = float((pose.get("durations_s") or {}).get("turn", math.nan))
        if free is not None:  # the turn-drive-turn plan rebuilt from the free plan
            ends = free.sample(np.array([0.0, free.duration]))
            p0 = (float(ends.x[0]), float(ends.y[0]))
            p1 = (float(ends.x[1]), float(ends.y[1]))
            a = turn_in_place(p0, row.h0, float(ends.theta[0]), robot).duration
            b = turn_in_place(p1, float(ends.theta[1]), row.h1, robot).duration
            row.d_turn_indep = free.duration + a + b


# ------------------------------------------------------------------ omni probe
def omni_probe() -> str:
    """'' when the planner gives an omni robot an orientation profile, else why not."""
    grid = astar.OccupancyGrid(np.zeros((60, 60), dtype=bool), 0.05, (0.0, 0.0))
    planner = trajopt.Planner(grid, trajopt.Robot(drive="omni"))
    try:
        traj = planner.plan((0.6, 0.6), (2.4, 0.6), start_heading=0.0, goal_heading=1.5)
    except TrajoptError as exc:
        return f"plan with headings raised {type(exc).__name__}: {str(exc)[:160]}"
    smp = traj.sample(np.array([0.0, traj.duration]))
    if getattr(smp, "course", None) is None:
        return (
            f"the planner returned a {type(traj).__name__} whose samples have no 'course' "
            "(theta is the direction of travel, not an orientation)"
        )
    return ""


# ------------------------------------------------------------------ report
def pct(xs: list[float]) -> str:
    return f"{statistics.median(xs):+.2%} / {max(xs):+.2%}" if xs else "n/a"


def report(rows: list[Row], drives: tuple[str, ...], omni_why: str, n_maps: int) -> None:
    print(
        f"{'drive':<13}{'queries':>8}{'planned':>8}{'success':>9}{'collide':>8}"
        f"{'min margin m':>13}{'heading err':>12}{'end err m':>10}{'limits':>7}"
    )
    for drive in drives:
        rs = [r for r in rows if r.drive == drive]
        ok = [r for r in rs if not r.err]
        if not rs:
            continue
        margins = [r.min_margin for r in ok]
        inner = [r.inner_margin for r in ok if math.isfinite(r.inner_margin)]
        herr = [r.heading_err for r in ok]
        perr = [r.point_err for r in ok]
        print(
            f"{drive:<13}{len(rs):>8}{len(ok):>8}{len(ok) / len(rs):>9.1%}"
            f"{sum(r.collided for r in ok):>8}"
            f"{min(margins) if margins else math.nan:>13.2e}"
            f"{max(herr) if herr else math.nan:>12.1e}"
            f"{max(perr) if perr else math.nan:>10.1e}"
            f"{sum(bool(r.limits) for r in ok):>7}"
        )
        fm = [r.free_margin for r in ok if math.isfinite(r.free_margin)]
        if fm:
            print(
                f"{'':<13}smallest margin of the same queries' free-heading plans: {min(fm):.2e} m"
            )
        if inner:
            print(
                f"{'':<13}smallest margin farther than one radius from both end points: "
                f"{min(inner):.2e} m; plans within 1e-6 m of touching there: "
                f"{sum(m < 1e-6 for m in inner)} of {len(inner)}"
            )
    if omni_why:
        print(f"{'omni':<13}not available: {omni_why}")
    print(
        f"(checks on {DT * 1e3:g} ms samples; 'collide': samples closer than the radius to an "
        f"occupied square by > {COLLISION_TOL:g} m; 'min margin': smallest distance minus "
        "radius; 'heading err': worst |theta - h| mod 2 pi at either end (rad); 'limits': "
        "plans exceeding a limit)"
    )
    print()
    diff = [r for r in rows if r.drive == "differential" and not r.err and not r.free_err]
    if diff:
        over = [r.d_head / r.d_free - 1.0 for r in diff]
        turned = sum(r.turned for r in diff)
        chosen = {k: sum(r.chosen == k for r in diff) for k in sorted({r.chosen for r in diff})}
        excess = [r.d_head - r.d_turn for r in diff if math.isfinite(r.d_turn)]
        slower = sum(e > 1e-9 for e in excess)
        recomputed = [
            abs(r.d_turn - r.d_turn_indep)
            for r in diff
            if math.isfinite(r.d_turn) and math.isfinite(r.d_turn_indep)
        ]
        print(f"differential ({len(diff)} queries planned both ways):")
        print(f"  duration overhead vs free headings, median / max: {pct(over)}")
        print(
            f"  plans with a turn in place: {turned} ({turned / len(diff):.0%}); chosen: "
            + ", ".join(f"{k} {v}" for k, v in chosen.items())
        )
        saved = [1.0 - r.d_head / r.d_turn for r in diff if r.chosen == "pinned" and r.d_turn > 0]
        if saved:
            print(
                f"  where 'pinned' was chosen: duration saved vs turn-drive-turn, median "
                f"{statistics.median(saved):.1%}, max {max(saved):.1%}"
            )
        print(
            f"  chosen slower than the pure turn-drive-turn plan: {slower} of {len(excess)} "
            f"(largest chosen - turn: {max(excess) if excess else math.nan:+.3g} s; turn-drive-"
            f"turn recomputed from the free plan + 2 turn_in_place: max |diff| "
            f"{max(recomputed) if recomputed else math.nan:.2g} s)"
        )
    omni = [r for r in rows if r.drive == "omni" and not r.err and not r.free_err]
    if omni:
        ratio = [r.d_head / r.d_free for r in omni]
        med, mx = statistics.median(ratio), max(ratio)
        print(f"omni ({len(omni)} queries planned both ways):")
        srcs = sorted({r.alpha_src for r in omni})
        print(f"  orientation yaw rate, acceleration and jerk checked against: {', '.join(srcs)}")
        print(
            f"  duration with headings / free, median {med:.4f} (target <= 1.02: "
            f"{'met' if med <= 1.02 else 'MISSED'}), max {mx:.4f} (target <= 1.10: "
            f"{'met' if mx <= 1.10 else 'MISSED'}); ratio > 1.001 on {sum(x > 1.001 for x in ratio)}"
        )
    elif omni_why:
        print("omni: not available")
    print()
    print(
        f"plan time, warm (one warm-up query per map and drive), same run:\n"
        f"{'drive':<13}{'median free ms':>15}{'median head ms':>15}{'ratio median':>13}"
        f"{'p90':>7}{'max':>7}  target"
    )
    for drive in drives:
        rs = [r for r in rows if r.drive == drive and not r.err and not r.free_err]
        if not rs:
            continue
        ratio = [r.t_head / r.t_free for r in rs]
        med = statistics.median(ratio)
        print(
            f"{drive:<13}{statistics.median(r.t_free for r in rs) * 1e3:>15.1f}"
            f"{statistics.median(r.t_head for r in rs) * 1e3:>15.1f}{med:>13.2f}"
            f"{float(np.percentile(ratio, 90)):>7.2f}{max(ratio):>7.2f}  <= 1.5: "
            f"{'met' if med <= 1.5 else 'MISSED'}"
        )
    print()
    print(f"per map ({n_maps} maps):")
    print(
        f"{'map':<30}{'drive':<13}{'n':>3}{'ok':>4}{'overhead/ratio med':>19}{'time ratio med':>15}"
    )
    for name in dict.fromkeys(r.map_name for r in rows):
        for drive in drives:
            rs = [r for r in rows if r.map_name == name and r.drive == drive]
            if not rs:
                continue
            both = [r for r in rs if not r.err and not r.free_err]
            dur = [r.d_head / r.d_free for r in both]
            tr = [r.t_head / r.t_free for r in both]
            print(
                f"{name:<30}{drive:<13}{len(rs):>3}{len(rs) - sum(bool(r.err) for r in rs):>4}"
                f"{(statistics.median(dur) - (drive == 'differential')) if dur else math.nan:>19.3f}"
                f"{statistics.median(tr) if tr else math.nan:>15.2f}"
            )
    print("(differential: median overhead; omni: median duration ratio)")
    bad = [
        r
        for r in rows
        if r.err
        or r.free_err
        or r.collided
        or r.limits
        or r.heading_err > HEADING_TOL
        or r.point_err > POINT_TOL
    ]
    print(f"\nfailures and violations: {len(bad)}")
    for r in bad:
        what = []
        if r.err:
            what.append(f"with headings: {r.err[:240]}")
        if r.free_err:
            what.append(f"free headings: {r.free_err[:240]}")
        if r.collided:
            what.append(f"collision, margin {r.min_margin:.3g} m")
        if r.heading_err > HEADING_TOL:
            what.append(f"heading error {r.heading_err:.3g} rad")
        if r.point_err > POINT_TOL:
            what.append(f"end point error {r.point_err:.3g} m")
        what += r.limits
        print(
            f"  {r.map_name} {r.drive} {np.round(r.start, 3).tolist()} -> "
            f"{np.round(r.goal, 3).tolist()} h0={r.h0:.4f} h1={r.h1:.4f}: " + "; ".join(what)
        )


# ------------------------------------------------------------------ main
def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--limit", type=int, default=8, help="queries per map (default 8)")
    ap.add_argument("--seed", type=int, default=0, help="seed of the ROS queries and headings")
    ap.add_argument(
        "--quick", action="store_true", help="the shared-small suite as it is (under a minute)"
    )
    ap.add_argument(
        "--repeat",
        type=int,
        default=3,
        help="plan each query this many times, alternating free and with headings; the "
        "smallest time of each is kept (default 3)",
    )
    ap.add_argument("--suite", choices=("shared-small", "shared-full"), default=None)
    args = ap.parse_args(argv)
    root = data_root()
    if root is None:
        print("skipped: no shared data (set TRAJOPT_DATA or put it in ../shared/data)")
        return 0
    name = args.suite or ("shared-small" if args.quick else "shared-full")
    limit = None if args.quick else args.limit
    import logging

    logging.getLogger("trajopt").setLevel(logging.ERROR)  # maps left out are named below
    mqs = [mq for mq in trajopt.bench.suite(name, root, limit=limit, seed=args.seed) if mq.queries]
    names = {mq.map_name for mq in mqs}
    left_out = [m for m in SUITES[name]["movingai"] if f"{m}.map" not in names]
    omni_why = omni_probe()
    drives = DRIVES if not omni_why else ("differential",)
    n_q = sum(len(mq.queries) for mq in mqs)
    per_map = "the suite's" if limit is None else f"at most {limit}"
    print(
        f"suite {name}, {per_map} queries per map, seed {args.seed}: {len(mqs)} maps, "
        f"{n_q} queries; disc robot (radius 2.5 cells on Moving AI maps, "
        f"{mqs[-1].radius_m if mqs else math.nan:g} m on ROS maps), other limits the Robot "
        "defaults; headings uniform in [-pi, pi)"
    )
    print("maps: " + ", ".join(f"{mq.map_name} ({len(mq.queries)})" for mq in mqs))
    if left_out:
        print(f"left out by the suite (no scenario feasible for 2.5 cells): {', '.join(left_out)}")
    print(
        f"plan times: each query planned {args.repeat} times both ways, alternating, the "
        "smallest time kept; the first plans are the ones checked"
    )
    print()
    try:
        from tqdm import tqdm
    except ImportError:  # pragma: no cover
        tqdm = None
    bar = (
        tqdm(total=n_q * len(drives), desc="bench_pose", file=sys.stderr, disable=None)
        if tqdm
        else None
    )
    rows: list[Row] = []
    t_all = time.perf_counter()
    for mq in mqs:
        grid = astar.load_map(mq.map_path)
        obstacles = Obstacles(grid)
        for drive in drives:
            robot = trajopt.Robot(radius=mq.radius_m, drive=drive)
            planner = trajopt.Planner(grid, robot)
            queries = []
            for q in mq.queries:
                rng = np.random.default_rng([args.seed, zlib.crc32(mq.map_name.encode()), q.index])
                h0, h1 = (float(v) for v in rng.uniform(-math.pi, math.pi, 2))
                s = tuple(float(v) for v in grid.cell_to_world(np.array(q.start)))
                g = tuple(float(v) for v in grid.cell_to_world(np.array(q.goal)))
                queries.append((s, g, h0, h1))
            s, g, h0, h1 = queries[0]  # warm-up: not recorded
            run_pair(planner, s, g, h0, h1, True)
            for k, (s, g, h0, h1) in enumerate(queries):
                row = Row(mq.map_name, drive, s, g, h0, h1)
                (free, row.t_free, row.free_err), (traj, row.t_head, row.err) = run_pair(
                    planner, s, g, h0, h1, k % 2 == 0, args.repeat
                )
                if free is not None:
                    row.d_free = float(free.duration)
                if traj is not None:
                    row.d_head = float(traj.duration)
                    check(row, traj, free, robot, obstacles)
                rows.append(row)
                if bar is not None:
                    bar.update(1)
    if bar is not None:
        bar.close()
    report(rows, drives, omni_why, len(mqs))
    print(f"\nwall time {time.perf_counter() - t_all:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
