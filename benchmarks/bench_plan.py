"""Benchmark: warm per-query latency of ``trajopt.Planner.plan``, by stage.

Queries: the paper scene (SP to each of A-D) and reachable start/goal pairs on the shared ROS
maps (random free cells far enough from walls, fixed seed). Each planner is warmed up with
one query (numba kernels loaded, CasADi solvers built for that size); then every query is
repeated and the best time per query is kept. Prints the median and p95 per stage.
The peer measured in the same run is the plain B-spline fit of the same A* path
(scipy ``make_lsq_spline``), for scale.

Run::

    python benchmarks/bench_plan.py                 # paper scene + shared ROS maps
    python benchmarks/bench_plan.py --ros-queries 5 --repeat 3
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

STAGES = ("inflate", "search", "corridor", "smooth", "timing", "total")


def data_dir() -> Path:
    env = os.environ.get("TRAJOPT_DATA")
    return Path(env) if env else Path(__file__).resolve().parents[2] / "shared" / "data"


def ros_queries(planner, n: int, rng: np.random.Generator) -> list[tuple]:
    """``n`` reachable start/goal pairs at least 2 m apart with clearance >= 2 radii."""
    import astar

    grid = planner.grid
    clr = astar.clearance(grid, metric="square", outside_occupied=True)
    ok = np.argwhere(clr >= 2 * planner.robot.radius)  # (iy, ix)
    out: list[tuple] = []
    tries = 0
    while len(out) < n and tries < 50 * n:
        tries += 1
        a, b = ok[rng.integers(len(ok), size=2)]
        p0 = grid.cell_to_world((a[1], a[0]))
        p1 = grid.cell_to_world((b[1], b[0]))
        if np.hypot(*(p1 - p0)) < 2.0:
            continue
        try:
            astar.find_path(planner.inflated_grid, (a[1], a[0]), (b[1], b[0]))
        except astar.NoPathError:
            continue
        out.append((tuple(p0), tuple(p1)))
    return out


def run(planner, queries, repeat: int) -> tuple[list[dict], list[float], int]:
    from scipy.interpolate import make_lsq_spline

    import trajopt

    best: list[dict] = []
    peer: list[float] = []
    failures = 0
    for start, goal in queries:
        stage_best: dict[str, float] | None = None
        for _ in range(repeat):
            try:
                traj = planner.plan(start, goal)
            except trajopt.TrajoptError as exc:
                print(f"  {start} -> {goal}: {type(exc).__name__}: {str(exc)[:100]}")
                failures += 1
                break
            st = traj.stats["stages_s"]
            if stage_best is None or st["total"] < stage_best["total"]:
                stage_best = dict(st)
            pts = traj.steps.grid_path.to_world(planner.grid)
            u = np.concatenate([[0], np.cumsum(np.hypot(*np.diff(pts, axis=0).T))])
            n_ctrl = max(4, min(len(pts) - 1, len(pts) // 4))
            knots = np.r_[[0.0] * 3, np.linspace(0, u[-1], n_ctrl - 2), [u[-1]] * 3]
            t0 = time.perf_counter()
            make_lsq_spline(u, pts, knots, 3)
            peer.append(time.perf_counter() - t0)
        if stage_best is not None:
            best.append(stage_best)
    return best, peer, failures


def report(name: str, best: list[dict], peer: list[float], failures: int) -> None:
    print(f"\n{name}: {len(best)} queries ok, {failures} failed")
    if not best:
        return
    print(f"  {'stage':<10}{'median ms':>12}{'p95 ms':>10}")
    for s in STAGES:
        v = np.array([b.get(s, np.nan) for b in best]) * 1e3
        print(f"  {s:<10}{np.nanmedian(v):>12.2f}{np.nanpercentile(v, 95):>10.2f}")
    if peer:
        print(
            f"  peer: plain make_lsq_spline fit of the same A* path, median "
            f"{1e3 * np.median(peer):.2f} ms"
        )
        total = np.median([b["total"] for b in best])
        print(f"  ratio total/plain-fit (median) {total / np.median(peer):.1f}x")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--ros-queries", type=int, default=10)
    args = ap.parse_args()

    import astar
    import trajopt

    scene = trajopt.scenes.paper()
    planner = trajopt.Planner(scene.grid, trajopt.Robot(radius=scene.robot_radius))
    queries = [(scene.start, scene.goal(n)) for n in scene.target_names]
    for q in queries:  # warm-up: kernels and solvers of every size these queries use
        planner.plan(*q)
    best, peer, failures = run(planner, queries, args.repeat)
    report("paper scene (SP -> A-D), warm", best, peer, failures)
    if best:
        med = 1e3 * np.median([b["total"] for b in best])
        print(
            f"  target: median <= 20 ms per warm query -> {med:.1f} ms "
            f"({'met' if med <= 20 else 'NOT met'})"
        )

    ros = data_dir() / "ros"
    if not ros.is_dir():
        print(f"\nshared ROS maps not found at {ros} (set TRAJOPT_DATA); skipped")
        return
    rng = np.random.default_rng(0)
    for yaml in sorted(ros.glob("*.yaml")):
        grid = astar.load_map(yaml)
        planner = trajopt.Planner(grid, trajopt.Robot(radius=0.2))
        qs = ros_queries(planner, args.ros_queries, rng)
        for q in qs:
            try:
                planner.plan(*q)
            except trajopt.TrajoptError:
                pass
        best, peer, failures = run(planner, qs, args.repeat)
        report(
            f"{yaml.stem} ({grid.nx}x{grid.ny}, {grid.resolution} m), warm", best, peer, failures
        )


if __name__ == "__main__":
    main()
