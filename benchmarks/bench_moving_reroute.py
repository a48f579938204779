"""Re-routing around movers that block the path: wall time against a plain plan, same run.

For seeded random start/goal pairs on the shared house-size ROS maps (a warm
:class:`trajopt.Planner` per map, default robot), each query is planned without movers (the
plain plan, timed), then with one mover that blocks its path, two kinds:

* ``stop``: a cart (radius 0.25 m) drives in from 1 m beside the plan's middle and stops on
  it after 2 s (it stays there);
* ``head-on``: a mover (radius 0.2 m) drives the plan's path backwards from the goal at
  0.5 m/s, starting at once, and stays at the start's side once its prediction ends;
* ``trapped``: the same mover, which then drives the path forwards again at 0.5 m/s and stays
  on the goal: no route works, the query ends in a :class:`BlockedError`.

For each it records the outcome (``stats["moving"]["route"]``: ``retimed``, ``rerouted``,
``waited``; or ``BlockedError``), the wall time, and checks every returned plan with the
certificate and on 1 ms samples (the reference of ``tests/trajopt/moving/reference.py``).
The ratio is each query's time with the mover over its plain plan's; the issue's target is a
re-route within 2x a plain plan. With ``--rounds R`` every query's plain plan and its plans with
movers are timed ``R`` times, round by round over all the queries (a fresh mover each time, so
no table kept for a mover or a curve of the same query is found), and the ratio is its median
time with the mover over its plain plan's median (one sample each is noisy on a shared
machine; the other columns and the second table stay the first round's). ``reroute ms`` is the share after the re-timing along the
static path was found blocked (``stats["moving"]["reroute_time_s"]``: marking the map,
planning and re-timing the new route), and ``rr ratio`` its ratio to the plain plan; the
rest is the static plan (its search alone where the screen of its grid path finds it
blocked) and the proof that it is blocked. ``proof ms`` is the quick proofs on the static
plan (:func:`trajopt.moving.parked_on_path`, then :func:`trajopt.moving.no_way_past` when it
finds nothing), timed here on the same static plan (the planner runs them on the grid path
first, with a slack, and on the curve when they find nothing there); ``raise ms`` (``trapped``) is the time from that proof to the :class:`BlockedError`:
the query's time less its plain plan's and the proof's (a difference of wall times, so
noisy; negative where the screen of the grid path skips the static plan's fit, the proof's
time on the curve being that of a plan not made). ``cpu ms`` is the query's CPU time (``time.process_time``). The machine is shared:
times are noisy. The kernels are loaded before the timed parts (``trajopt.warm_up()``): the
plain plans are timed after an untimed call of the same query, and without it the first
queries with movers (on the first map) would load the moving-obstacle kernels from numba's
disk cache inside their timed call.

A second table splits the re-routes' wall time (medians, ms; ``x plain``: each part over the
query's plain plan): ``static`` (the static plan and the proof that it is blocked: the
query's time less ``reroute ms``; the timing is skipped where the proof holds on the curve,
``stats["moving"]["blocked_before_timing"]``, counted in ``early``; the static plan is not
fitted either where the screen of its grid path finds it blocked,
``stats["moving"]["blocked_on_grid_path"]``, counted in ``grid``), ``leg`` (the
returned route's own plan, its ``stats["stages_s"]``: ``search``, ``smooth`` with the
corridor, ``timing``), ``retime`` (its re-timing and certificate for the movers,
``stats["moving"]["time_s"]``) and ``other`` (the rest of ``reroute ms``: marking the map,
the derived caches, candidates tried before).

A second part (``--part replan``) times :meth:`trajopt.Planner.replan` with movers that block
the rest of the path being driven. Each query is planned without movers (the plan driven),
then re-planned ``REPLAN_AT`` s in (``latency=0``, the robot moving) with one mover on that
plan's clock that blocks its rest: ``stop`` (the cart drives in from 1 m beside the middle of
the rest and stops on it after 2 s) or ``head-on`` (the walker drives the plan's path backwards
from the goal at 0.5 m/s from ``t = 0``). The re-plan brakes along the path and goes on from
the stop (``stats["moving"]["route"]``: ``stopped: rerouted``, ...). It is timed against a
plain plan (no movers, same warm planner, timed after one untimed call of the same query) from
the pose where the result stops (``stats["moving"]["head_s"]``) to the goal with that heading:
the re-route's target is 2x such a plan. Each re-plan and its plain plan are timed
``--repeat`` times, alternating (the plain plan after one untimed call); ``ratio`` is the
median re-plan's time over the median plain plan's, ``first med`` the first re-plan's alone
(the later ones find the re-timing's tables of the kept rest warm). Every result is checked with the reference
(``check_trajectory``: 1 ms samples, Lipschitz bounds, the static map) on the movers seen from
the splice (shifted to the result's clock), and for continuity at the splice and at the stop.

Run from the repository root (needs the shared data, ``$TRAJOPT_DATA`` or
``../shared/data``)::

    python benchmarks/bench_moving_reroute.py
    python benchmarks/bench_moving_reroute.py --queries 10 --seed 3
    python benchmarks/bench_moving_reroute.py --part replan --queries 10
    python benchmarks/bench_moving_reroute.py --part plan --maps turtlebot3_world --rounds 7
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import astar  # noqa: E402
import trajopt  # noqa: E402
from tests.trajopt.moving.reference import check_trajectory, dense_min  # noqa: E402
from trajopt.errors import BlockedError, TrajoptError  # noqa: E402

MAPS = ("turtlebot3_world", "smoothers_world", "depot")
#: Time (s) into the plan driven at which it is re-planned with movers (``--part replan``).
REPLAN_AT = 1.0


def data_dir() -> Path:
    env = os.environ.get("TRAJOPT_DATA")
    return Path(env) if env else Path(__file__).resolve().parents[2] / "shared" / "data"


def queries(grid, robot, n, rng):
    """``n`` random (start, goal) pairs at least 2 m apart in free space."""
    free = np.argwhere(
        ~astar.inflate(grid, robot.radius + 0.1, metric="square", outside_occupied=True).occupied
    )
    out = []
    for _ in range(50 * n):
        if len(out) == n or len(free) == 0:
            break
        a, b = free[rng.integers(len(free), size=2)]
        p0, p1 = grid.cell_to_world(a[::-1]), grid.cell_to_world(b[::-1])
        if math.dist(p0, p1) >= 2.0:
            out.append((tuple(p0), tuple(p1)))
    return out


def stop_mover(base):
    smp = base.sample(np.array([0.5 * base.duration]))
    p = np.array([smp.x[0], smp.y[0]])
    n = np.array([-math.sin(smp.theta[0]), math.cos(smp.theta[0])])
    return trajopt.MovingObstacle.from_waypoints(
        [0.0, 2.0], [p + 1.0 * n, p], radius=0.25, name="cart"
    )


def head_on_mover(base):
    s = np.linspace(0.0, base.length, 60)
    pts = np.asarray(base.path(base.path.u_at_s(s)))[::-1]
    t = (base.length - s[::-1]) / 0.5
    return trajopt.MovingObstacle.from_waypoints(t, pts, radius=0.2, name="walker")


def trapped_mover(base):
    s = np.linspace(0.0, base.length, 60)
    pts = np.asarray(base.path(base.path.u_at_s(s)))
    t_back = (base.length - s[::-1]) / 0.5
    t_fwd = t_back[-1] + s[1:] / 0.5
    return trajopt.MovingObstacle.from_waypoints(
        np.concatenate([t_back, t_fwd]), np.concatenate([pts[::-1], pts[1:]]), radius=0.2,
        name="walker",
    )  # fmt: skip


def proof_time(base, mover):
    """Wall time (s) of the planner's quick proofs on the static plan."""
    t0 = time.perf_counter()
    if trajopt.moving.parked_on_path(base, [mover], 0.02) is None:
        trajopt.moving.no_way_past(base, [mover], 0.02)
    return time.perf_counter() - t0


def split(out, took: float, plain: float) -> dict[str, float]:
    """The parts (ms) of a re-routed query's wall time ``took`` (s); ``x``: over ``plain``."""
    mv = out.stats["moving"]
    rr = mv["reroute_time_s"]
    st = out.stats["stages_s"]
    leg = st["total"]
    parts = {
        "static": took - rr,
        "search": st.get("search", 0.0),
        "smooth": st.get("smooth", 0.0) + st.get("corridor", 0.0),
        "timing": st.get("timing", 0.0),
        "leg": leg,
        "retime": mv["time_s"],
        "other": rr - leg - mv["time_s"],
    }
    out_ms = {k: 1e3 * v for k, v in parts.items()}
    out_ms.update({f"x {k}": v / plain for k, v in parts.items() if k in PARTS_X})
    out_ms["early"] = float(bool(mv.get("blocked_before_timing")))
    out_ms["grid"] = float(bool(mv.get("blocked_on_grid_path")))
    return out_ms


#: The parts also given as a ratio to the plain plan.
PARTS_X = ("static", "leg", "retime", "other")


def print_split(split_rows) -> None:
    """Print the second table: the medians of each re-route kind's parts."""
    if not split_rows:
        return
    keys = ("static", "search", "smooth", "timing", "leg", "retime", "other")
    print()
    print(
        f"{'re-routes: ms':18s} {'kind':8s} {'n':>3s} {'early':>5s} {'grid':>4s} "
        + " ".join(f"{k:>7s}" for k in keys)
        + " "
        + " ".join(f"{'x ' + k:>8s}" for k in PARTS_X)
    )
    for name, kind, parts in split_rows:
        n = len(parts["leg"])
        print(
            f"{name:18s} {kind:8s} {n:3d} {int(sum(parts['early'])):5d} "
            f"{int(sum(parts['grid'])):4d} "
            + " ".join(f"{statistics.median(parts[k]):7.1f}" for k in keys)
            + " "
            + " ".join(f"{statistics.median(parts['x ' + k]):8.2f}" for k in PARTS_X)
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--queries", type=int, default=6, help="queries per map")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--part", choices=("plan", "replan", "both"), default="both")
    ap.add_argument(
        "--maps", nargs="+", choices=MAPS, default=list(MAPS), help="the maps (default: all)"
    )
    ap.add_argument(
        "--repeat", type=int, default=3, help="timings of each re-plan and its plain plan"
    )
    ap.add_argument(
        "--rounds",
        type=int,
        default=1,
        help="plan part: timings of each plan and its plain plan, round by round (medians)",
    )
    args = ap.parse_args()
    d = data_dir() / "ros"
    if not d.is_dir():
        print(f"shared data not found at {d} (set TRAJOPT_DATA)")
        return
    trajopt.warm_up()  # every kernel loaded: none loads inside a timed call
    if args.part in ("plan", "both"):
        plan_part(d, args)
    if args.part in ("replan", "both"):
        replan_part(d, args)


def plan_part(d: Path, args: argparse.Namespace) -> None:
    """The first part: :meth:`trajopt.Planner.plan` with a mover that blocks its path."""
    rng = np.random.default_rng(args.seed)
    robot = trajopt.Robot()
    print(f"robot radius {robot.radius} m, v_max {robot.v_max} m/s; margin 0.02 m")
    print(
        f"{'map':18s} {'kind':8s} {'n':>3s} {'retimed':>7s} {'rerouted':>8s} {'waited':>6s} "
        f"{'blocked':>7s} {'plain ms':>8s} {'mover ms':>8s} {'ratio med':>9s} {'ratio max':>9s} "
        f"{'reroute ms':>10s} {'rr ratio':>8s} {'worst slack':>11s} {'proof ms':>8s} "
        f"{'cpu ms':>7s} {'raise ms':>8s}"
    )
    ratios_all: dict[str, list[float]] = {}
    split_rows: list[tuple[str, str, dict[str, list[float]]]] = []
    raises: list[float] = []
    for name in MAPS:
        grid = astar.load_map(d / f"{name}.yaml")
        qs = queries(grid, robot, args.queries, rng)
        if name not in args.maps:  # its queries drawn all the same, as in a run of every map
            continue
        planner = trajopt.Planner(grid, robot)
        kinds = (("stop", stop_mover), ("head-on", head_on_mover), ("trapped", trapped_mover))
        rows = {k: {"n": 0, "t0": [], "t1": [], "ratio": [], "rr": [], "rr_ratio": [],
                    "slack": math.inf, "out": {}, "proof": [], "cpu": [], "raise": []}
                for k, _ in kinds}  # fmt: skip
        timed: list[tuple[tuple, Any, list[float], dict[str, list[float]]]] = []
        for p0, p1 in qs:
            try:
                planner.plan(p0, p1)  # warm (the first plan of a map pays its caches)
                t0 = time.perf_counter()
                base = planner.plan(p0, p1)
                plain = time.perf_counter() - t0
            except TrajoptError:
                continue
            timed.append(((p0, p1), base, [plain], {}))
            for kind, make in kinds:
                row = rows[kind]
                mover = make(base)
                proof = proof_time(base, mover)
                c0 = time.process_time()
                t0 = time.perf_counter()
                try:
                    out = planner.plan(p0, p1, moving_obstacles=[mover], mover_margin=0.02)
                except BlockedError:
                    what = "blocked"
                    out = None
                except TrajoptError as exc:
                    what = type(exc).__name__
                    out = None
                took = time.perf_counter() - t0
                timed[-1][3][kind] = [took]
                row["cpu"].append(1e3 * (time.process_time() - c0))
                row["proof"].append(1e3 * proof)
                if out is None and what == "blocked":
                    row["raise"].append(1e3 * (took - plain - proof))
                if out is not None:
                    what = out.stats["moving"]["route"]
                    row["slack"] = min(row["slack"], dense_min(out, [mover], margin=0.02)[0])
                row["n"] += 1
                row["out"][what] = row["out"].get(what, 0) + 1
                row["t0"].append(1e3 * plain)
                row["t1"].append(1e3 * took)
                if what == "rerouted":
                    parts = split(out, took, plain)
                    for key, val in parts.items():
                        row.setdefault("parts", {}).setdefault(key, []).append(val)
                if what in ("rerouted", "waited"):
                    rr = out.stats["moving"]["reroute_time_s"]
                    row["rr"].append(1e3 * rr)
                    row["rr_ratio"].append(rr / plain)
                    row["counted"] = [*row.get("counted", []), len(timed) - 1]
                    if args.rounds == 1:
                        row["ratio"].append(took / plain)
                        ratios_all.setdefault(kind, []).append(took / plain)
        if args.rounds > 1:
            more_rounds(planner, kinds, timed, rows, ratios_all, args.rounds)
        for kind, row in rows.items():
            raises += row["raise"]
            if not row["n"]:
                continue
            o = row["out"]
            r = row["ratio"]
            print(
                f"{name:18s} {kind:8s} {row['n']:3d} {o.get('retimed', 0):7d} "
                f"{o.get('rerouted', 0):8d} {o.get('waited', 0):6d} {o.get('blocked', 0):7d} "
                f"{statistics.median(row['t0']):8.1f} {statistics.median(row['t1']):8.1f} "
                f"{(statistics.median(r) if r else math.nan):9.2f} {(max(r) if r else math.nan):9.2f} "
                f"{(statistics.median(row['rr']) if r else math.nan):10.1f} "
                f"{(statistics.median(row['rr_ratio']) if r else math.nan):8.2f} "
                f"{row['slack']:11.4f} {statistics.median(row['proof']):8.1f} "
                f"{statistics.median(row['cpu']):7.1f} "
                f"{(statistics.median(row['raise']) if row['raise'] else math.nan):8.1f}"
            )
        for kind, row in rows.items():
            if row.get("parts"):
                split_rows.append((name, kind, row["parts"]))
    print_split(split_rows)
    if raises:
        print(
            f"all maps, from the proof to the BlockedError: median {statistics.median(raises):.1f} "
            f"ms, max {max(raises):.1f} ms over {len(raises)} queries"
        )
    for kind, r in ratios_all.items():
        print(
            f"all maps, {kind}: re-route / plain plan, median {statistics.median(r):.2f}x, "
            f"max {max(r):.2f}x over {len(r)} re-routes"
        )


def more_rounds(planner, kinds, timed, rows, ratios_all, rounds: int) -> None:
    """Time every query's plain plan and its plans with movers ``rounds - 1`` times more.

    Round by round over all the queries (a fresh mover each time, so that no table kept for a
    mover or a curve of the same query is found), as the first round's; each query's ratio
    becomes its median time with the mover over its plain plan's median, and the ``plain ms``
    and ``mover ms`` columns the medians of those medians.
    """
    for _ in range(rounds - 1):
        for (p0, p1), base, plains, tooks in timed:
            t0 = time.perf_counter()
            planner.plan(p0, p1)
            plains.append(time.perf_counter() - t0)
            for kind, make in kinds:
                mover = make(base)
                t0 = time.perf_counter()
                try:
                    planner.plan(p0, p1, moving_obstacles=[mover], mover_margin=0.02)
                except TrajoptError:
                    pass
                tooks[kind].append(time.perf_counter() - t0)
    for kind, row in rows.items():
        med = [
            (statistics.median(plains), statistics.median(tooks[kind]))
            for _, _, plains, tooks in timed
        ]
        row["t0"] = [1e3 * a for a, _ in med]
        row["t1"] = [1e3 * b for _, b in med]
        for q in row.get("counted", []):
            row["ratio"].append(med[q][1] / med[q][0])
            ratios_all.setdefault(kind, []).append(med[q][1] / med[q][0])


def rest_stop_mover(base, t_r):
    """The cart: in from 1 m beside the middle of the rest after ``t_r`` (s), stops there at 2 s."""
    smp = base.sample(np.array([0.5 * (t_r + base.duration)]))
    p = np.array([smp.x[0], smp.y[0]])
    n = np.array([-math.sin(smp.theta[0]), math.cos(smp.theta[0])])
    return trajopt.MovingObstacle.from_waypoints(
        [0.0, 2.0], [p + 1.0 * n, p], radius=0.25, name="cart"
    )


def on_clock(movers, t0):
    """The movers seen from ``t0`` (s) of their clock (as ``benchmarks/bench_moving.py``'s)."""
    out = []
    for m in movers:
        times = m.times - t0
        k = max(int(np.searchsorted(times, 0.0, side="right")) - 1, 0)
        p0 = [np.interp(0.0, times, m.positions[:, i]) for i in (0, 1)]
        h0 = np.interp(0.0, times, m.headings)
        later = times[-1] > 0
        t = np.r_[0.0, times[k + 1 :]] if later else np.zeros(1)
        p = np.vstack([p0, m.positions[k + 1 :]]) if later else np.array([p0])
        h = np.r_[h0, m.headings[k + 1 :]] if later else np.array([h0])
        out.append(
            trajopt.MovingObstacle.from_waypoints(
                t, p, radius=m.radius + m.growth * max(t0, 0.0), growth=m.growth, headings=h,
                vertices=m.vertices, name=m.name,
            )
        )  # fmt: skip
    return out


def jumps(a, ta: float, b, tb: float) -> float:
    """Largest difference of position (m), heading (rad), speed and acceleration of two samples."""
    sa, sb = a.sample(np.array([ta])), b.sample(np.array([tb]))
    dh = abs(math.remainder(float(sa.theta[0] - sb.theta[0]), 2.0 * math.pi))
    return max(
        math.hypot(float(sa.x[0] - sb.x[0]), float(sa.y[0] - sb.y[0])),
        dh,
        abs(float(sa.v[0] - sb.v[0])),
        abs(float(sa.a[0] - sb.a[0])),
    )


def replan_part(d: Path, args: argparse.Namespace) -> None:
    """The second part: :meth:`trajopt.Planner.replan` with a mover that blocks the rest."""
    rng = np.random.default_rng(args.seed)
    robot = trajopt.Robot()
    print()
    print(
        f"Planner.replan(plan, {REPLAN_AT} s, latency=0, moving_obstacles=[mover], "
        "mover_margin=0.02) against a plain plan from the result's stop to the goal"
    )
    print(
        f"{'map':18s} {'kind':8s} {'n':>3s} {'outcomes':30s} {'plain ms':>8s} {'replan ms':>9s} "
        f"{'ratio med':>9s} {'p95':>6s} {'max':>6s} {'first med':>9s} {'check':>7s} "
        f"{'worst slack':>11s} {'jump':>8s}"
    )
    all_ratios: dict[str, list[float]] = {}
    all_first: dict[str, list[float]] = {}
    failed = 0
    for name in MAPS:
        grid = astar.load_map(d / f"{name}.yaml")
        qs = queries(grid, robot, args.queries, rng)
        if name not in args.maps:  # its queries drawn all the same, as in a run of every map
            continue
        planner = trajopt.Planner(grid, robot)
        kinds = (("stop", lambda b: rest_stop_mover(b, REPLAN_AT)), ("head-on", head_on_mover))
        rows = {k: {"out": {}, "plain": [], "took": [], "ratio": [], "first": [], "bad": 0, "n": 0,
                    "slack": math.inf, "jump": 0.0} for k, _ in kinds}  # fmt: skip
        for p0, p1 in qs:
            try:
                planner.plan(p0, p1)
                base = planner.plan(p0, p1)
            except TrajoptError:
                continue
            if base.duration < REPLAN_AT + 3.0:
                continue
            for kind, make in kinds:
                row = rows[kind]
                mover = make(base)

                def replan(mover=mover, base=base, planner=planner):
                    return planner.replan(
                        base, REPLAN_AT, latency=0.0, moving_obstacles=[mover], mover_margin=0.02
                    )

                t0 = time.perf_counter()
                try:
                    out = replan()
                except TrajoptError as exc:
                    what, out = type(exc).__name__, None
                took = time.perf_counter() - t0
                row["n"] += 1
                if out is None:
                    row["out"][what] = row["out"].get(what, 0) + 1
                    continue
                mv = out.stats["moving"]
                what = mv["route"]
                row["out"][what] = row["out"].get(what, 0) + 1
                chk = check_trajectory(out, on_clock([mover], REPLAN_AT), margin=0.02, grid=grid)
                row["slack"] = min(row["slack"], float(chk.mover_slack))
                jump = jumps(base, REPLAN_AT, out, 0.0)
                if "head_s" in mv:
                    h = float(mv["head_s"])
                    jump = max(jump, jumps(out, h - 1e-9, out, h + 1e-9))
                row["jump"] = max(row["jump"], jump)
                row["bad"] += int(not chk.ok)
                failed += int(not chk.ok)
                if not what.startswith("stopped"):
                    continue
                stop = out.sample(np.array([float(mv["head_s"])]))
                q = ((float(stop.x[0]), float(stop.y[0])), p1)
                heading = float(stop.theta[0])
                try:
                    planner.plan(*q, start_heading=heading)
                except TrajoptError:
                    continue
                plains, tooks = [], [took]
                for k in range(args.repeat):
                    c0 = time.perf_counter()
                    planner.plan(*q, start_heading=heading)
                    plains.append(time.perf_counter() - c0)
                    if k + 1 < args.repeat:
                        c0 = time.perf_counter()
                        replan()
                        tooks.append(time.perf_counter() - c0)
                plain = statistics.median(plains)
                row["plain"].append(1e3 * plain)
                row["took"].append(1e3 * statistics.median(tooks))
                row["ratio"].append(statistics.median(tooks) / plain)
                row["first"].append(took / plain)
                all_ratios.setdefault(kind, []).append(statistics.median(tooks) / plain)
                all_first.setdefault(kind, []).append(took / plain)
        for kind, row in rows.items():
            if not row["n"]:
                continue
            r = row["ratio"]
            outs = ", ".join(f"{k} {v}" for k, v in sorted(row["out"].items()))
            med = statistics.median
            print(
                f"{name:18s} {kind:8s} {row['n']:3d} {outs:30s} "
                f"{(med(row['plain']) if r else math.nan):8.1f} "
                f"{(med(row['took']) if r else math.nan):9.1f} "
                f"{(med(r) if r else math.nan):9.2f} {(pct(r, 95) if r else math.nan):6.2f} "
                f"{(max(r) if r else math.nan):6.2f} "
                f"{(med(row['first']) if r else math.nan):9.2f} {row['bad']:3d} bad "
                f"{row['slack']:11.4f} "
                f"{row['jump']:8.1e}"
            )
    for kind, r in all_ratios.items():
        print(
            f"all maps, replan {kind}: re-route / plain plan from the stop, median "
            f"{statistics.median(r):.2f}x, p95 {pct(r, 95):.2f}x, max {max(r):.2f}x over "
            f"{len(r)} re-plans that stopped; the first call alone: median "
            f"{statistics.median(all_first[kind]):.2f}x, p95 {pct(all_first[kind], 95):.2f}x"
        )
    print(f"results failing the independent check: {failed}")


def pct(values, q: float) -> float:
    """The ``q`` th percentile of ``values``."""
    return float(np.percentile(np.asarray(values, dtype=float), q))


if __name__ == "__main__":
    main()
