"""Exact A* vs coarse-to-fine on the willow map split into finer cells (issue #35, part 2).

``python benchmarks/bench_search_scale.py [--splits 1,3,6] [--queries 12]`` splits every cell
of the willow map (10 cm) into ``k x k`` cells, inflates it by a 0.25 m radius with the
planner's clearance cost, draws long queries (> 20 m, seeded, in the largest component)
and runs, on the same queries, :func:`astar.find_path` (exact) and
:func:`astar.find_path_coarse_to_fine` with the planner's block (the robot radius): search
medians and maxima, the proven bounds, and the cost ratio against the exact search.
Needs ``../shared/data`` (or ``$TRAJOPT_DATA``).
"""

from __future__ import annotations

import argparse
import math
import os
import time
from pathlib import Path

import numpy as np

import astar
from trajopt import PlannerOptions, Robot
from trajopt.planning._caches import component_labels, falloff_cells

RADIUS = 0.25


def _data() -> Path:
    root = Path(
        os.environ.get("TRAJOPT_DATA", Path(__file__).resolve().parents[2] / "shared" / "data")
    )
    return root / "ros" / "willow-2010-02-18-0.10.yaml"


def _setup(split: int):
    g = astar.load_map(_data())
    if split > 1:
        occ = np.repeat(np.repeat(g.occupied, split, 0), split, 1)
        g = astar.OccupancyGrid(occ, g.resolution / split, g.origin)
    inflated = g.with_occupied(
        astar.inflate(g, RADIUS, metric="square", outside_occupied=True).occupied
    )
    options = PlannerOptions(robot=Robot(radius=RADIUS))  # the planner's fall-off
    cost = astar.clearance_cost(
        g, RADIUS, falloff_cells=falloff_cells(options, g.resolution), outside_occupied=True
    )
    cost.flags.writeable = False
    return inflated, cost


def _queries(inflated, n: int, min_m: float, seed: int = 1):
    labels = component_labels(inflated.occupied)
    big = int(np.bincount(labels.ravel())[1:].argmax()) + 1
    cells = np.argwhere(labels == big)
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < n:
        a, b = cells[rng.integers(len(cells), size=2)]
        if math.hypot(*(a - b)) * inflated.resolution > min_m:
            out.append(((int(a[1]), int(a[0])), (int(b[1]), int(b[0]))))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--splits", default="1,3,6")
    ap.add_argument("--queries", type=int, default=12)
    args = ap.parse_args()
    for split in (int(s) for s in args.splits.split(",")):
        inflated, cost = _setup(split)
        queries = _queries(inflated, args.queries, 20.0)
        k = max(2, round(RADIUS / inflated.resolution))
        t0 = time.perf_counter()
        coarse = astar.build_coarse_grid(inflated, k, cost)
        build = time.perf_counter() - t0
        astar.find_path(inflated, *queries[0], cost=cost)  # warm: padded grid, kernels
        astar.find_path_coarse_to_fine(coarse, *queries[0])
        exact_t, ctf_t, bounds, ratios, fallbacks = [], [], [], [], []
        for s, g in queries:
            t0 = time.perf_counter()
            p = astar.find_path(inflated, s, g, cost=cost)
            exact_t.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            r = astar.find_path_coarse_to_fine(coarse, s, g)
            ctf_t.append(time.perf_counter() - t0)
            bounds.append(r.bound)
            ratios.append(r.path.cost / p.cost)
            fallbacks.extend([r.fallback] if r.fallback else [])
        ms = 1e3
        print(
            f"willow split {split} ({inflated.nx} x {inflated.ny}, {inflated.occupied.size / 1e6:.1f} M "
            f"cells, {inflated.resolution * 100:.2f} cm), block {k} cells ({k * inflated.resolution:.3f} m, "
            f"built in {build * ms:.0f} ms), {len(queries)} queries > 20 m:\n"
            f"  exact:          median {np.median(exact_t) * ms:.1f} ms, max {max(exact_t) * ms:.1f} ms\n"
            f"  coarse-to-fine: median {np.median(ctf_t) * ms:.1f} ms, max {max(ctf_t) * ms:.1f} ms "
            f"(median speed-up {np.median(np.array(exact_t) / np.array(ctf_t)):.1f}x)\n"
            f"  proven bound:   median {np.median(bounds):.3f}, max {max(bounds):.3f}; cost / exact "
            f"median {np.median(ratios):.4f}, max {max(ratios):.4f}; fallbacks {fallbacks or 'none'}",
            flush=True,
        )


if __name__ == "__main__":
    main()
