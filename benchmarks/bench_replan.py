"""Re-planning from a moving robot: latency, splice continuity and limits, same run.

For each query on the shared ROS maps (seeded random start/goal pairs that a warm
:class:`trajopt.Planner` solves), the robot drives the trajectory and re-plans every
``--every`` seconds of trajectory time to the same goal (``Planner.replan`` with the
latency set to 0, so the splice is at the re-plan time), twice: as a user calls it (the
map and goal are unchanged, so the rest of the trajectory is kept) and with
``reuse=False`` (a full plan from the moving state); then once to a new goal. For every
re-plan it records the wall time, the jump of position, heading, curvature, speed and
acceleration between the old trajectory at the splice and the new one at its start, and
whether the new trajectory holds every limit on 1 ms samples (``trajectory_metrics``). A
re-plan that brakes, turns in place and goes (no smooth curve leaves the moving state, e.g.
a new goal behind the robot: ``stats["replan"]`` starts with ``"braked"``) is counted as
braked; one that raises a typed error is counted as refused, with its type. The reference
is a fresh ``plan`` from rest at the same point, timed in the same run.

Then the robot drives each query while obstacles appear: before every re-plan a 2 x 2
block of free cells turns occupied at a random place away from the robot, and the robot
re-plans on the updated map and drives the new trajectory (kept when the block is far from
its rest, planned anew otherwise; "path kept" counts the planned ones that reused the rest
of the old grid path instead of searching). Each new trajectory's clearance on its updated
map is measured independently of its certificate (``trajopt.metrics.point_clearance`` on
10 ms samples). For the planned re-plans that kept regions of the old polygon corridor
(``stats["corridor_regions_kept"]``), the corridor stage is compared with a fresh
``build_polygon_corridor`` on the same path, timed right after it.

A second part runs on a warehouse-size map, willow at 5 cm cells (each 10 cm cell split in
four, 1132 x 1216 cells), robot radius 0.25 m, with warm planners (``trajopt.warmup``, one
untimed plan), one with 6 search landmarks (``Planner(landmarks=6)``) and one without, in
the same run: the whole ``plan`` of each query (start and goal at least 5 m apart: a new
goal for the planner), and, with the landmarks, a re-plan to a new goal (the next query's)
from the moving robot 2 s into each trajectory, with the stage split of the plans; then,
on a third planner (6 landmarks) whose map gains a 0.4 m block on each query's path ahead,
the re-plan to the same goal on the updated map, and whether the landmarks were carried
over (``Landmarks.rebase``) instead of being built again.

Run from the repository root (needs the shared data, ``$TRAJOPT_DATA`` or
``../shared/data``)::

    python benchmarks/bench_replan.py
    python benchmarks/bench_replan.py --queries 8 --every 0.5
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
from trajopt.analysis.metrics import point_clearance, trajectory_metrics
from trajopt.corridor import build_polygon_corridor
from trajopt.errors import TrajoptError

MAPS = ("turtlebot3_world", "smoothers_world", "depot", "willow-2010-02-18-0.10")


def data_dir() -> Path:
    env = os.environ.get("TRAJOPT_DATA")
    return Path(env) if env else Path(__file__).resolve().parents[2] / "shared" / "data"


def ros_dir() -> Path | None:
    """The shared ROS maps' folder, or ``None`` (said on stdout) when it is absent."""
    d = data_dir() / "ros"
    if not d.is_dir():
        print(f"shared data not found at {d} (set TRAJOPT_DATA)")
        return None
    return d


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
        p0 = grid.cell_to_world(a[::-1])
        p1 = grid.cell_to_world(b[::-1])
        if math.dist(p0, p1) >= 2.0:
            out.append((tuple(p0), tuple(p1)))
    return out


def jump(a, b) -> float:
    return max(
        math.hypot(a.x - b.x, a.y - b.y),
        abs(math.remainder(a.theta - b.theta, 2 * math.pi)),
        abs(a.kappa - b.kappa),
        abs(a.v - b.v),
        abs(a.a - b.a),
    )


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--queries", type=int, default=6, help="queries per map")
    ap.add_argument("--every", type=float, default=0.5, help="re-plan period (s)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument(
        "--warehouse",
        type=int,
        default=12,
        help="queries on the warehouse-size map (0: skip that part)",
    )
    args = ap.parse_args(argv)
    d = ros_dir()
    if d is None:
        return 1
    rng = np.random.default_rng(args.seed)
    robot = trajopt.Robot(radius=0.2)
    print(
        f"robot radius {robot.radius} m, v_max {robot.v_max} m/s; re-plan every "
        f"{args.every} s of trajectory time, latency 0"
    )
    print(
        f"{'map':26s} {'replans':>7s} {'ok':>4s} {'refused':>7s} {'kept':>4s} {'braked':>6s} "
        f"{'kept ms':>7s} {'full ms':>7s} {'full p95':>8s} {'fresh ms':>8s} {'max jump':>9s} "
        f"{'limits':>6s} {'new goal ok (braked)':>20s}"
    )
    all_kept: list[float] = []
    all_full: list[float] = []
    goal_ms: dict[str, list[float]] = {"smooth": [], "braked": []}
    for name in MAPS:
        grid = astar.load_map(d / f"{name}.yaml")
        planner = trajopt.Planner(grid, robot)
        kept, full, fresh, worst, refused, ok_limits, n_ok, n_kept = [], [], [], 0.0, {}, True, 0, 0
        new_goal, n_braked = {"ok": 0, "refused": 0, "braked": 0}, 0
        qs = queries(grid, robot, args.queries, rng)
        for k, (p0, p1) in enumerate(qs):
            try:
                traj = planner.plan(p0, p1)
            except TrajoptError:
                continue
            t = args.every
            while t < traj.duration - 0.5:
                for reuse, times in ((True, kept), (False, full)):
                    t0 = time.perf_counter()
                    try:
                        new = planner.replan(traj, t, latency=0.0, reuse=reuse)
                    except TrajoptError as exc:
                        refused[type(exc).__name__] = refused.get(type(exc).__name__, 0) + 1
                        continue
                    times.append(1e3 * (time.perf_counter() - t0))
                    n_ok += 1
                    n_kept += new.stats["replan"] == "kept"
                    n_braked += new.stats["replan"].startswith("braked")
                    worst = max(worst, jump(traj.state_at(t), new.state_at(0.0)))
                    ok_limits &= bool(trajectory_metrics(new, robot)["within_limits"])
                s = traj.state_at(t)
                t1 = time.perf_counter()
                try:
                    planner.plan(s.position, p1)
                    fresh.append(1e3 * (time.perf_counter() - t1))
                except TrajoptError:
                    pass
                t += args.every
            other = qs[(k + 1) % len(qs)][1]
            t0 = time.perf_counter()
            try:
                new = planner.replan(traj, min(1.0, traj.duration / 2), goal=other, latency=0.0)
                braked = new.stats["replan"].startswith("braked")
                goal_ms["braked" if braked else "smooth"].append(1e3 * (time.perf_counter() - t0))
                worst = max(
                    worst, jump(traj.state_at(min(1.0, traj.duration / 2)), new.state_at(0.0))
                )
                ok_limits &= bool(trajectory_metrics(new, robot)["within_limits"])
                new_goal["ok"] += 1
                new_goal["braked"] += braked
            except TrajoptError:
                new_goal["refused"] += 1
        all_kept += kept
        all_full += full
        ref = ", ".join(f"{v} {k}" for k, v in refused.items()) or "0"
        goals = f"{new_goal['ok']}/{new_goal['ok'] + new_goal['refused']} ({new_goal['braked']})"
        print(
            f"{name:26s} {n_ok + sum(refused.values()):7d} {n_ok:4d} {ref:>7s} {n_kept:4d} "
            f"{n_braked:6d} {_med(kept):7.1f} {_med(full):7.1f} {_p95(full):8.1f} "
            f"{_med(fresh):8.1f} {worst:9.1e} {str(ok_limits):>6s} {goals:>20s}"
        )
    if all_full:
        print(
            f"all maps, same goal and map: kept re-plans median {_med(all_kept):.2f} ms, p95 "
            f"{_p95(all_kept):.2f} ms ({len(all_kept)}); full re-plans (reuse=False) median "
            f"{_med(all_full):.1f} ms, p95 {_p95(all_full):.1f} ms ({len(all_full)})"
        )
        print(
            f"new goal: smooth re-plans median {_med(goal_ms['smooth']):.1f} ms, p95 "
            f"{_p95(goal_ms['smooth']):.1f} ms ({len(goal_ms['smooth'])}); braked re-plans "
            f"median {_med(goal_ms['braked']):.1f} ms, p95 {_p95(goal_ms['braked']):.1f} ms "
            f"({len(goal_ms['braked'])})"
        )
    appearing(d, robot, args, np.random.default_rng(args.seed))
    if args.warehouse:
        warehouse(d, args.warehouse, np.random.default_rng(args.seed))
    return 0


def _med(x) -> float:
    return statistics.median(x) if x else float("nan")


def _p95(x) -> float:
    return float(np.percentile(x, 95)) if x else float("nan")


def appearing(d: Path, robot, args, rng) -> None:
    """Drive each query re-planning every ``args.every`` s while obstacles appear."""
    print(
        f"\nobstacles appearing: before every re-plan a 2 x 2 cell block turns occupied at "
        f"a random free place at least {robot.radius + 0.3:.2f} m from the robot; the robot "
        f"drives each new trajectory"
    )
    print(
        f"{'map':26s} {'replans':>7s} {'kept':>5s} {'planned':>7s} {'path kept':>9s} "
        f"{'braked':>6s} {'refused':>7s} {'median ms':>9s} {'p95 ms':>7s} {'max jump':>9s} "
        f"{'limits':>6s} {'min clear m':>11s}"
    )
    kept_regions: list[tuple[float, float, int, int]] = []  # corridor s, fresh s, kept, all
    for name in MAPS:
        grid = astar.load_map(d / f"{name}.yaml")
        planner = trajopt.Planner(grid, robot)
        times, kept, planned, refused, worst, ok_limits, reused = [], 0, 0, 0, 0.0, True, 0
        braked = 0
        clear = math.inf  # independent clearance of every new trajectory on its updated map
        for p0, p1 in queries(grid, robot, args.queries, rng):
            planner.update_map(grid)
            try:
                traj = planner.plan(p0, p1)
            except TrajoptError:
                continue
            occ = np.array(grid.occupied)
            while traj.duration > args.every + 0.5:
                here = np.asarray(traj.state_at(args.every).position)
                free = np.argwhere(~occ[:-1, :-1])
                for _ in range(100):
                    iy, ix = free[rng.integers(len(free))]
                    c = np.asarray(grid.cell_to_world((ix, iy)))
                    if np.hypot(*(c - here)) > robot.radius + 0.3:
                        occ[iy : iy + 2, ix : ix + 2] = True
                        break
                t0 = time.perf_counter()
                try:
                    new = planner.replan(
                        traj, args.every, grid=grid.with_occupied(occ.copy()), latency=0.0
                    )
                except TrajoptError:
                    refused += 1
                    break
                times.append(1e3 * (time.perf_counter() - t0))
                how = new.stats["replan"]
                kept += how == "kept"
                braked += how.startswith("braked")
                planned += how.startswith("planned")
                reused += how.startswith("planned") and new.stats["grid_path"] == "reused"
                if how.startswith("planned") and new.stats.get("corridor_regions_kept", 0):
                    cor = new.steps.corridor
                    t1 = time.perf_counter()
                    build_polygon_corridor(planner.grid, cor.input_path, robot.radius)
                    kept_regions.append(
                        (
                            new.stats["stages_s"]["corridor"],
                            time.perf_counter() - t1,
                            new.stats["corridor_regions_kept"],
                            len(cor.regions),
                        )
                    )
                worst = max(worst, jump(traj.state_at(args.every), new.state_at(0.0)))
                ok_limits &= bool(trajectory_metrics(new, robot)["within_limits"])
                smp = new.sample_uniform(0.01)
                clear = min(
                    clear,
                    float(
                        point_clearance(
                            np.column_stack([smp.x, smp.y]), planner.grid, border_occupied=True
                        ).min()
                    ),
                )
                traj = new
        print(
            f"{name:26s} {kept + planned + braked + refused:7d} {kept:5d} {planned:7d} "
            f"{reused:9d} {braked:6d} {refused:7d} {_med(times):9.1f} {_p95(times):7.1f} {worst:9.1e} "
            f"{str(ok_limits):>6s} {clear:11.4f}"
        )
    print(
        f"(min clear: the smallest distance from a 10 ms sample of any new trajectory to an "
        f"occupied cell of its updated map, by trajopt.metrics.point_clearance; the robot "
        f"radius is {robot.radius} m)"
    )
    if kept_regions:
        cor = [1e3 * c for c, _, _, _ in kept_regions]
        fresh = [1e3 * f for _, f, _, _ in kept_regions]
        share = [k / n for _, _, k, n in kept_regions]
        print(
            f"planned re-plans that kept corridor regions: {len(cor)}, median share kept "
            f"{100 * _med(share):.0f} %; corridor stage median {_med(cor):.2f} ms against "
            f"{_med(fresh):.2f} ms for a fresh corridor on the same path (ratio "
            f"{_med(fresh) / _med(cor):.2f})"
        )


def warehouse(d: Path, n: int, rng) -> None:
    """Whole plans and re-plans to a new goal on willow at 5 cm (module docstring)."""
    w = astar.load_map(d / "willow-2010-02-18-0.10.yaml")
    grid = astar.OccupancyGrid(
        np.repeat(np.repeat(w.occupied, 2, axis=0), 2, axis=1), w.resolution / 2, w.origin
    )
    robot = trajopt.Robot(radius=0.25)
    planner = trajopt.Planner(grid, robot, landmarks=6)
    plain = trajopt.Planner(grid, robot)
    trajopt.warm_up(planner)
    free = np.argwhere(
        ~astar.inflate(grid, robot.radius + 0.1, metric="square", outside_occupied=True).occupied
    )
    qs = []
    while len(qs) < n + 1:
        a, b = free[rng.integers(len(free), size=2)]
        p0, p1 = grid.cell_to_world(a[::-1]), grid.cell_to_world(b[::-1])
        if math.dist(p0, p1) < 5.0:
            continue
        try:
            planner.plan(p0, p1)  # also the untimed first plans of this map
            plain.plan(p0, p1)
        except TrajoptError:
            continue
        qs.append((tuple(p0), tuple(p1)))
    upd = trajopt.Planner(grid, robot, landmarks=6)  # its map gains a block per query
    upd.plan(*qs[0])  # builds its landmarks, untimed
    occ = np.array(grid.occupied)
    blocked, blocked_refused, lm_kept = [], 0, 0
    plans, plain_ms, replans, stages, refused = [], [], [], {}, 0
    braked = {"new goal": 0, "block": 0}
    for k, (p0, p1) in enumerate(qs[1:]):
        t0 = time.perf_counter()
        plain.plan(p0, p1)
        plain_ms.append(1e3 * (time.perf_counter() - t0))
        t0 = time.perf_counter()
        traj = planner.plan(p0, p1)
        plans.append(1e3 * (time.perf_counter() - t0))
        for key, v in traj.stats["stages_s"].items():
            stages.setdefault(key, []).append(1e3 * v)
        t0 = time.perf_counter()
        try:
            new = planner.replan(traj, min(2.0, traj.duration / 2), goal=qs[k][1], latency=0.0)
            replans.append(1e3 * (time.perf_counter() - t0))
            braked["new goal"] += new.stats["replan"].startswith("braked")
        except TrajoptError:
            refused += 1
        # a 0.4 m block appears on the path ahead: re-plan to the same goal on the new map
        ix, iy = grid.world_to_cell(traj.state_at(min(0.6 * traj.duration, 6.0)).position)
        occ[iy - 4 : iy + 4, ix - 4 : ix + 4] = True
        t0 = time.perf_counter()
        try:
            new = upd.replan(
                traj, min(2.0, traj.duration / 3), grid=grid.with_occupied(occ.copy()), latency=0.0
            )
            blocked.append(1e3 * (time.perf_counter() - t0))
            braked["block"] += new.stats["replan"].startswith("braked")
        except TrajoptError:
            blocked_refused += 1
        lm_kept += upd._landmarks is not None
    print(
        f"\nwarehouse-size map: willow at 5 cm ({grid.nx} x {grid.ny} cells), radius 0.25 m, "
        f"{len(plans)} queries 5 m or more apart, warm planner"
    )
    print(
        f"  whole plan (new goal), landmarks=6: median {statistics.median(plans):.1f} ms, p95 "
        f"{np.percentile(plans, 95):.1f} ms (target median <= 40 ms); without landmarks: "
        f"median {statistics.median(plain_ms):.1f} ms, p95 {np.percentile(plain_ms, 95):.1f} "
        f"ms"
    )
    split = ", ".join(f"{k} {statistics.median(v):.1f}" for k, v in stages.items() if k != "total")
    print(f"  stage medians (ms): {split}")
    if replans:
        print(
            f"  re-plan to a new goal from the moving robot: median "
            f"{statistics.median(replans):.1f} ms, p95 {np.percentile(replans, 95):.1f} ms "
            f"({len(replans)} re-plans, {braked['new goal']} braked, {refused} refused; target "
            f"median <= 40 ms)"
        )
    if blocked:
        print(
            f"  re-plan after a 0.4 m block appears on the path ahead (landmarks=6, the "
            f"blocks accumulating): median {statistics.median(blocked):.1f} ms, p95 "
            f"{np.percentile(blocked, 95):.1f} ms ({len(blocked)} re-plans, {braked['block']} "
            f"braked, {blocked_refused} refused); landmarks carried over {lm_kept} of "
            f"{len(qs) - 1} updates"
        )


if __name__ == "__main__":
    raise SystemExit(main())
