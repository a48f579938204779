"""Re-plans from moving robots, checked for every guarantee: outcomes, latency, violations.

For seeded random queries on the shared ROS maps (start and goal at least 2 m apart), a warm
:class:`trajopt.Planner` plans each query, and every ``--every`` seconds of its trajectory
re-plans from the moving robot with ``reuse=False`` (a plan from the moving state, or a
brake, turn in place and go) to three goals: the same one, the next query's goal and the
start of the query after it. Each braked result (a ``TrajectoryChain``) is re-planned once
more halfway through its brake and turn, to the query's start. Every result is checked
independently of the planner's own certificates:

* the jump between the old trajectory at the splice and the new one at its start
  (position, heading, curvature, speed, acceleration) is below 1e-6;
* every limit holds on 1 ms samples (``trajopt.metrics.trajectory_metrics``);
* every 10 ms sample is at least the robot radius (less 1e-6 m) from an occupied cell
  (``trajopt.metrics.point_clearance``, the map border counted as occupied);
* nothing but a typed ``TrajoptError`` is raised.

It prints the outcome counts per map (planned, braked, refused by error type), the latency
of planned and braked re-plans, and every violation with what reproduces it; the exit code
is 1 when a guarantee broke. Run from the repository root (needs the shared data,
``$TRAJOPT_DATA`` or ``../shared/data``)::

    python benchmarks/replan_robustness.py               # 8 queries per map
    python benchmarks/replan_robustness.py --queries 3
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from collections import Counter
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_replan import MAPS, jump, queries, ros_dir  # noqa: E402

import astar  # noqa: E402
import trajopt  # noqa: E402
from trajopt.analysis.metrics import point_clearance, trajectory_metrics
from trajopt.errors import TrajoptError

JUMP_TOL = 1e-6


def check(old, t: float, new, grid, robot) -> list[str]:
    """The guarantees ``new``, spliced onto ``old`` at ``t``, breaks (empty: none)."""
    broken = []
    j = jump(old.state_at(t), new.state_at(0.0))
    if not j < JUMP_TOL:
        broken.append(f"jump {j:.3g} at the splice")
    if not trajectory_metrics(new, robot)["within_limits"]:
        broken.append("a limit broken on 1 ms samples")
    smp = new.sample_uniform(0.01)
    clear = point_clearance(np.column_stack([smp.x, smp.y]), grid, border_occupied=True).min()
    if clear < robot.radius - 1e-6:
        broken.append(f"clearance {clear:.4g} m < radius {robot.radius} m")
    return broken


def replan(planner, old, t, goal, grid, robot, out, times, bad, where) -> object | None:
    """Re-plan ``old`` at ``t`` to ``goal``; count the outcome, check it, return it."""
    t0 = time.perf_counter()
    try:
        new = planner.replan(old, t, goal=goal, latency=0.0, reuse=False)
    except TrajoptError as exc:
        out[f"refused ({type(exc).__name__})"] += 1
        return None
    except Exception as exc:  # noqa: BLE001 - an untyped error is what this run looks for
        out["untyped error"] += 1
        bad.append(f"{where}: {type(exc).__name__}: {str(exc)[:300]}")
        return None
    how = new.stats["replan"].split(":")[0]
    times.setdefault(how, []).append(1e3 * (time.perf_counter() - t0))
    out[how] += 1
    for b in check(old, t, new, grid, robot):
        out["violation"] += 1
        bad.append(f"{where}: {b}")
    return new


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--queries", type=int, default=8, help="queries per map")
    ap.add_argument("--every", type=float, default=1.5, help="re-plan period (s)")
    ap.add_argument("--seed", type=int, default=7)
    args = ap.parse_args(argv)
    d = ros_dir()
    if d is None:
        return 1
    rng = np.random.default_rng(args.seed)
    robot = trajopt.Robot(radius=0.2)
    total: Counter = Counter()
    times: dict[str, list[float]] = {}
    bad: list[str] = []
    print(
        f"robot radius {robot.radius} m; re-plans every {args.every} s with reuse=False to "
        f"the same goal, the next query's goal and another query's start; braked results "
        f"re-planned again halfway through their brake and turn"
    )
    for name in MAPS:
        grid = astar.load_map(d / f"{name}.yaml")
        planner = trajopt.Planner(grid, robot)
        qs = queries(grid, robot, args.queries, rng)
        out: Counter = Counter()
        for k, (p0, p1) in enumerate(qs):
            try:
                traj = planner.plan(p0, p1)
            except TrajoptError:
                continue
            goals = (None, qs[(k + 1) % len(qs)][1], qs[(k + 2) % len(qs)][0])
            for t in np.arange(0.5, traj.duration - 0.3, args.every):
                for goal in goals:
                    where = f"{name} query {k} {p0} -> {p1}, t {t:.2f} s, goal {goal}"
                    new = replan(planner, traj, float(t), goal, grid, robot, out, times, bad, where)
                    if isinstance(new, trajopt.TrajectoryChain) and len(new.pieces) > 1:
                        tq = float(0.5 * new.piece_times[-2])
                        replan(
                            planner,
                            new,
                            tq,
                            p0,
                            grid,
                            robot,
                            out,
                            times,
                            bad,
                            f"{where}, then the chain at {tq:.2f} s to {p0}",
                        )
        total.update(out)
        print(f"  {name:26s} " + ", ".join(f"{k} {v}" for k, v in sorted(out.items())))
    print("all maps: " + ", ".join(f"{k} {v}" for k, v in sorted(total.items())))
    for how, v in sorted(times.items()):
        print(
            f"  {how:8s} re-plans: median {statistics.median(v):.1f} ms, p95 "
            f"{np.percentile(v, 95):.1f} ms, max {max(v):.0f} ms ({len(v)})"
        )
    print(f"violations: {len(bad)}")
    for b in bad:
        print("  " + b)
    return 1 if bad else 0


if __name__ == "__main__":
    raise SystemExit(main())
