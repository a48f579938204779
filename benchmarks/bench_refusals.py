"""Fast refusals: unconnected queries refused from component labels, against the search.

``Planner.plan`` refuses a query whose start and goal cells lie in different components of
the inflated grid (:attr:`trajopt.planning._caches.PlannerCaches.components`, 4-connected
labels, built once per map and map change) before any search; before issue #33 the
planner found out by running its A* until it had expanded every cell reachable from the
start. This script times both in the same run, on the same queries.

Maps: the larger shared Moving AI maps (radius 2.5 cells; 0.5 cells on the 1-cell maze and
the 40 % random map, where nothing wider fits), the shared ROS maps (radius 0.165 m) and a
warehouse-size map, willow at 5 cm cells (each 10 cm cell split in four, 1132 x 1216
cells, radius 0.25 m, as in ``bench_astar.py`` and ``bench_replan.py``). Two kinds of
seeded unconnected queries on each map, the start always in the largest component (where
the search has most to exhaust):

* ``island``: the goal in another component of the map as it is (an island of free space
  the robot cannot reach; maps without one are skipped with the reason);
* ``closed room``: the goal walled in by a one-cell square ring of obstacles added to the
  raw map (a closed room), several rooms on one map.

Per map and kind: the number of components, the labelling time (once per map), the
refusal time (the whole ``Planner.plan`` call until its ``NoPathError``, best of
``--repeat``) and the time of the search the planner ran before (``astar.find_path`` on the
planner's inflated grid with its search cost, exactly its former ``_search`` call, until
``astar.NoPathError``; the old refusal also ran the end checks, so this is a lower bound of
it), their medians and maxima, and the median of the per-query ratios (before / now).
Every query must be refused by both (``agree``). The planners are warm (one untimed
refusal first: compiled kernels loaded, labels built).

Run from the repository root (needs the shared data, ``$TRAJOPT_DATA`` or
``../shared/data``; exits 0 with a message when it is absent)::

    python benchmarks/bench_refusals.py
    python benchmarks/bench_refusals.py --queries 10 --repeat 2
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
from trajopt.planning._caches import component_labels  # noqa: E402

#: Moving AI maps (the larger shared ones) and the robot radius on each, in cells
MOVINGAI = {
    "Boston_0_1024": 2.5,
    "AR0046SR": 2.5,
    "Berlin_0_256": 2.5,
    "maze512-1-0": 0.5,
    "random512-40-5": 0.5,
}
#: shared ROS maps, robot radius 0.165 m (trajopt.Robot's default footprint)
ROS = ("willow-2010-02-18-0.10", "depot", "smoothers_world", "turtlebot3_world")
ROS_RADIUS_M = 0.165
#: the warehouse-size map: willow at 5 cm, robot radius 0.25 m
WAREHOUSE_RADIUS_M = 0.25


def data_dir() -> Path:
    env = os.environ.get("TRAJOPT_DATA")
    return Path(env) if env else Path(__file__).resolve().parents[2] / "shared" / "data"


def load_maps(root: Path) -> list[tuple[str, astar.OccupancyGrid, float]]:
    """``(label, grid, radius in m)`` of every map found; says which are missing."""
    out = []
    for name, r_cells in MOVINGAI.items():
        f = root / "movingai" / "maps" / f"{name}.map"
        if not f.is_file():
            print(f"{name}: skipped ({f} not found)")
            continue
        g = astar.load_map(f)
        out.append((name, g, r_cells * g.resolution))
    for name in ROS:
        f = root / "ros" / f"{name}.yaml"
        if not f.is_file():
            print(f"{name}: skipped ({f} not found)")
            continue
        g = astar.load_map(f)
        out.append((name, g, ROS_RADIUS_M))
        if name.startswith("willow"):
            occ = np.repeat(np.repeat(g.occupied, 2, axis=0), 2, axis=1)
            big = astar.OccupancyGrid(occ, g.resolution / 2, g.origin)
            out.append(("willow at 5 cm", big, WAREHOUSE_RADIUS_M))
    return out


def wall_in(grid: astar.OccupancyGrid, goals: list[tuple[int, int]], k: int):
    """``grid`` with a one-cell square ring of obstacles at ``k`` cells around each goal."""
    occ = np.array(grid.occupied)
    ny, nx = occ.shape
    for gx, gy in goals:
        x0, x1, y0, y1 = max(gx - k, 0), min(gx + k, nx - 1), max(gy - k, 0), min(gy + k, ny - 1)
        occ[y0, x0 : x1 + 1] = occ[y1, x0 : x1 + 1] = True
        occ[y0 : y1 + 1, x0] = occ[y0 : y1 + 1, x1] = True
    return astar.OccupancyGrid(occ, grid.resolution, grid.origin)


def room_goals(labels: np.ndarray, n: int, k: int, rng) -> list[tuple[int, int]]:
    """Up to ``n`` cells ``(ix, iy)`` of the largest component, at least ``2 k + 2`` apart."""
    big = np.bincount(labels.ravel())[1:].argmax() + 1
    cells = np.argwhere(labels == big)[:, ::-1]
    rng.shuffle(cells)
    out: list[tuple[int, int]] = []
    for c in cells:
        if len(out) == n:
            break
        if all(max(abs(c[0] - o[0]), abs(c[1] - o[1])) >= 2 * k + 2 for o in out):
            out.append((int(c[0]), int(c[1])))
    return out


def pairs(labels: np.ndarray, n: int, rng, goals=None) -> list[tuple]:
    """``n`` (start, goal) cells: start in the largest component, goal in another one."""
    counts = np.bincount(labels.ravel())
    counts[0] = 0
    big = int(counts.argmax())
    starts = np.argwhere(labels == big)[:, ::-1]
    if goals is None:
        other = np.argwhere((labels > 0) & (labels != big))[:, ::-1]
        if len(other) == 0:
            return []
        goals = [tuple(int(v) for v in other[i]) for i in rng.integers(len(other), size=n)]
    chosen = starts[rng.integers(len(starts), size=n)]
    return [(tuple(int(v) for v in s), goals[i % len(goals)]) for i, s in enumerate(chosen)]


def best_of(repeat: int, fn) -> float:
    """Smallest wall time (s) of ``repeat`` calls of ``fn``."""
    best = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def time_map(grid, radius: float, queries: list[tuple], repeat: int) -> dict:
    """Refusal (now) and the search (before) of every query on one map."""
    planner = trajopt.Planner(grid, trajopt.Robot(radius=radius))
    caches = planner.caches
    inflated, cost = caches.inflated, caches.search_cost
    t0 = time.perf_counter()
    labels = component_labels(inflated.occupied)
    label_s = time.perf_counter() - t0
    xy = [(grid.cell_to_world(np.array(s)), grid.cell_to_world(np.array(g))) for s, g in queries]
    agree = 0

    def refuse(p0, p1) -> bool:
        try:
            planner.plan(tuple(p0), tuple(p1))
        except trajopt.NoPathError as exc:
            return "not connected" in str(exc)
        return False

    def search(s, g) -> bool:
        try:
            astar.find_path(inflated, s, g, cost=cost)
        except astar.NoPathError:
            return True
        return False

    refuse(*xy[0])  # warm: kernels loaded, labels built
    new, old = [], []
    for (s, g), (p0, p1) in zip(queries, xy, strict=True):
        agree += refuse(p0, p1) and search(s, g)
        new.append(best_of(repeat, lambda p0=p0, p1=p1: refuse(p0, p1)))
        old.append(best_of(repeat, lambda s=s, g=g: search(s, g)))
    return {
        "components": int(labels.max()),
        "label_ms": 1e3 * label_s,
        "new": np.array(new) * 1e3,
        "old": np.array(old) * 1e3,
        "agree": agree,
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--queries", type=int, default=20, help="queries per map and kind")
    ap.add_argument("--repeat", type=int, default=3, help="timings per query (best kept)")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    root = data_dir()
    if not ((root / "movingai").is_dir() or (root / "ros").is_dir()):
        print(f"skipped: shared data not found at {root} (set TRAJOPT_DATA)")
        return 0
    maps = load_maps(root)
    print(
        f"unconnected queries, start in the largest component; {args.queries} per map and "
        f"kind, best of {args.repeat}; now = Planner.plan until NoPathError, before = the "
        "A* it ran (astar.find_path on the inflated grid, with the search cost)"
    )
    print(
        f"{'map':24s} {'cells':>9s} {'radius':>8s} {'kind':11s} {'n':>3s} {'comps':>5s} "
        f"{'labels ms':>9s} {'now med/max ms':>15s} {'before med/max ms':>18s} "
        f"{'ratio':>6s} {'agree':>5s}"
    )
    all_new: list[float] = []
    all_old: list[float] = []
    ratios: list[float] = []
    warehouse: list[float] = []
    for label, grid, radius in maps:
        rng = np.random.default_rng([args.seed, len(label), grid.nx])
        inflated = astar.inflate(grid, radius, metric="square", outside_occupied=True)
        labels = component_labels(inflated.occupied)
        if labels.max() == 0:
            print(f"{label}: skipped (no cell free for radius {radius:g} m)")
            continue
        k = math.ceil(radius / grid.resolution) + 3
        goals = room_goals(labels, min(args.queries, 8), k, rng)
        walled = wall_in(grid, goals, k)
        walled_labels = component_labels(
            astar.inflate(walled, radius, metric="square", outside_occupied=True).occupied
        )
        kinds = (
            ("island", grid, pairs(labels, args.queries, rng)),
            ("closed room", walled, pairs(walled_labels, args.queries, rng, goals)),
        )
        for kind, g, queries in kinds:
            if not queries:
                print(f"{label:24s} {kind}: skipped (one component: no island to aim at)")
                continue
            r = time_map(g, radius, queries, args.repeat)
            new, old = r["new"], r["old"]
            ratio = float(np.median(old / new))
            all_new += new.tolist()
            all_old += old.tolist()
            ratios += (old / new).tolist()
            if label == "willow at 5 cm":
                warehouse += new.tolist()
            print(
                f"{label:24s} {g.nx * g.ny:>9d} {radius:>7.3g}m {kind:11s} {len(queries):>3d} "
                f"{r['components']:>5d} {r['label_ms']:>9.1f} "
                f"{np.median(new):>7.2f}/{new.max():<7.2f} "
                f"{np.median(old):>9.1f}/{old.max():<8.1f} {ratio:>6.0f} "
                f"{r['agree']:>2d}/{len(queries):<2d}"
            )
    if not all_new:
        print("skipped: no map with unconnected queries")
        return 0
    n = len(all_new)
    print(
        f"\nall maps, {n} queries: refusal median {statistics.median(all_new):.2f} ms, max "
        f"{max(all_new):.2f} ms (target < 50 ms median); the search before: median "
        f"{statistics.median(all_old):.1f} ms, max {max(all_old):.1f} ms; median ratio "
        f"before / now {statistics.median(ratios):.0f}"
    )
    if warehouse:
        print(
            f"warehouse-size map (willow at 5 cm), {len(warehouse)} queries: refusal median "
            f"{statistics.median(warehouse):.2f} ms, max {max(warehouse):.2f} ms (target well "
            "under 0.5 s)"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
