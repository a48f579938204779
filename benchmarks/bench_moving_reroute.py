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
re-route within 2x a plain plan. ``reroute ms`` is the share after the re-timing along the
static path was found blocked (``stats["moving"]["reroute_time_s"]``: marking the map,
planning and re-timing the new route), and ``rr ratio`` its ratio to the plain plan; the
rest is the static plan and the proof that it is blocked. ``proof ms`` is the quick proofs
the planner runs on the static plan before re-routing (:func:`trajopt.moving.parked_on_path`,
then :func:`trajopt.moving.no_way_past` when it finds nothing), timed here on the same static
plan; ``raise ms`` (``trapped``) is the time from that proof to the :class:`BlockedError`:
the query's time less its plain plan's and the proof's (a difference of wall times, so
noisy). ``cpu ms`` is the query's CPU time (``time.process_time``). The machine is shared:
times are noisy.

A second table splits the re-routes' wall time (medians, ms; ``x plain``: each part over the
query's plain plan): ``static`` (the static plan and the proof that it is blocked: the
query's time less ``reroute ms``; the timing is skipped where the proof holds on the curve,
``stats["moving"]["blocked_before_timing"]``, counted in ``early``), ``leg`` (the
returned route's own plan, its ``stats["stages_s"]``: ``search``, ``smooth`` with the
corridor, ``timing``), ``retime`` (its re-timing and certificate for the movers,
``stats["moving"]["time_s"]``) and ``other`` (the rest of ``reroute ms``: marking the map,
the derived caches, candidates tried before).

Run from the repository root (needs the shared data, ``$TRAJOPT_DATA`` or
``../shared/data``)::

    python benchmarks/bench_moving_reroute.py
    python benchmarks/bench_moving_reroute.py --queries 10 --seed 3
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import astar  # noqa: E402
import trajopt  # noqa: E402
from tests.trajopt.moving.reference import dense_min  # noqa: E402
from trajopt.errors import BlockedError, TrajoptError  # noqa: E402

MAPS = ("turtlebot3_world", "smoothers_world", "depot")


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
        f"{'re-routes: ms':18s} {'kind':8s} {'n':>3s} {'early':>5s} "
        + " ".join(f"{k:>7s}" for k in keys)
        + " "
        + " ".join(f"{'x ' + k:>8s}" for k in PARTS_X)
    )
    for name, kind, parts in split_rows:
        n = len(parts["leg"])
        print(
            f"{name:18s} {kind:8s} {n:3d} {int(sum(parts['early'])):5d} "
            + " ".join(f"{statistics.median(parts[k]):7.1f}" for k in keys)
            + " "
            + " ".join(f"{statistics.median(parts['x ' + k]):8.2f}" for k in PARTS_X)
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--queries", type=int, default=6, help="queries per map")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    d = data_dir() / "ros"
    if not d.is_dir():
        print(f"shared data not found at {d} (set TRAJOPT_DATA)")
        return
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
        planner = trajopt.Planner(grid, robot)
        qs = queries(grid, robot, args.queries, rng)
        kinds = (("stop", stop_mover), ("head-on", head_on_mover), ("trapped", trapped_mover))
        rows = {k: {"n": 0, "t0": [], "t1": [], "ratio": [], "rr": [], "rr_ratio": [],
                    "slack": math.inf, "out": {}, "proof": [], "cpu": [], "raise": []}
                for k, _ in kinds}  # fmt: skip
        for p0, p1 in qs:
            try:
                planner.plan(p0, p1)  # warm (the first plan of a map pays its caches)
                t0 = time.perf_counter()
                base = planner.plan(p0, p1)
                plain = time.perf_counter() - t0
            except TrajoptError:
                continue
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
                    row["ratio"].append(took / plain)
                    ratios_all.setdefault(kind, []).append(took / plain)
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


if __name__ == "__main__":
    main()
