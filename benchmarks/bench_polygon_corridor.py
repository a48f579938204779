"""Benchmark: polygon corridors (:mod:`trajopt.corridor`) vs box corridors.

On start/goal pairs drawn from the shared Moving AI maps (robot radius 2.5 cells) and ROS
maps (radius 0.2 m), the A* path (clearance-aware search, as ``Planner`` does by default,
or ``--search shortest``) on ``astar.inflate(raw, r, metric="square",
outside_occupied=True)`` is kept when it has 100-300 cells. On each path, in the same run:

* **boxes**: ``build_corridor(inflated, path, radius=r, raw_grid=raw)`` (with the 45-degree
  bridges, as the planner builds it; the inflated grid is computed once per map and not
  timed, as the planner caches it);
* **polygons**: ``build_polygon_corridor(raw, path, r)`` (everything per call: obstacle
  rectangles, centring, simplification, growth, certificate, overlaps).

Each build is timed as the best of ``--repeats`` warm calls (the shared VM this runs on
takes the CPU away now and then); the script prints the median and p95 of both, their
ratio, and the corridors' shapes: regions per path, the smallest and median overlap
length (path inside two consecutive regions), degenerate regions, and the area of the
region covering each path cell over that of the box covering it (median over cells).

Targets (issue 16): polygon build median <= 3 ms and p95 <= 15 ms on 100-300 cell paths.

Run: ``python benchmarks/bench_polygon_corridor.py [--per-map 20] [--seed 0] [--repeats 3]
[--search clearance|shortest]`` (``TRAJOPT_DATA`` may point to the shared data; the script
exits with a message when it is absent).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from bench_curvature import data_dir  # noqa: E402

import astar  # noqa: E402
from trajopt.corridor import build_corridor, build_polygon_corridor  # noqa: E402
from trajopt.errors import TrajoptError  # noqa: E402

MOVINGAI = [
    "arena",
    "den312d",
    "Berlin_0_256",
    "rmtst01",
    "random512-40-5",
    "AR0046SR",
    "Boston_0_1024",
]
ROS = ["turtlebot3_world", "smoothers_world", "depot", "willow-2010-02-18-0.10"]


def load_maps() -> list[tuple[str, object, float]]:
    d = data_dir()
    out = []
    for name in MOVINGAI:
        f = d / "movingai" / "maps" / f"{name}.map"
        if f.exists():
            raw = astar.load_map(f)
            out.append((name, raw, 2.5 * raw.resolution))
    for name in ROS:
        f = d / "ros" / f"{name}.yaml"
        if f.exists():
            out.append((name, astar.load_map(f), 0.2))
    return out


def draw_paths(raw, infl, cost, n: int, rng: np.random.Generator):
    """``n`` A* paths of 100-300 cells between random free cells."""
    ys, xs = np.nonzero(~infl.occupied)
    out = []
    if len(xs) < 2:
        return out
    for _ in range(100 * n):
        if len(out) == n:
            break
        i, j = rng.choice(len(xs), 2, replace=False)
        a, b = (int(xs[i]), int(ys[i])), (int(xs[j]), int(ys[j]))
        if not 60 <= math.hypot(a[0] - b[0], a[1] - b[1]) <= 300:
            continue
        try:
            path = astar.find_path(infl, a, b, cost=cost)
        except astar.NoPathError:
            continue
        if 100 <= len(path) <= 300:
            out.append(path)
    return out


def best_time(fn, repeats: int):
    out = fn()
    best = math.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def area_ratio(poly, boxes, cells) -> float:
    """Median over path cells of (area of the polygon region owning the cell) over (area
    of the box owning it), by path index."""
    ratios = []
    n = len(cells)
    for i in range(n):
        kb = int(np.searchsorted(boxes.path_ranges[:, 1], i, side="left"))
        b = boxes.boxes[min(kb, len(boxes) - 1)]
        area_b = (b.xmax - b.xmin) * (b.ymax - b.ymin)
        j = int(np.searchsorted(poly.source_index, i, side="right")) - 1
        k = min(max(j, 0), len(poly) - 1)
        area_p = poly.regions[k].area
        if area_b > 0:
            ratios.append(area_p / area_b)
    return float(np.median(ratios)) if ratios else float("nan")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--per-map", type=int, default=20, help="paths per map")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--search", choices=["clearance", "shortest"], default="clearance")
    args = ap.parse_args()
    maps = load_maps()
    if not maps:
        print(f"skipped: no shared maps under {data_dir()} (set TRAJOPT_DATA)")
        return
    rng = np.random.default_rng(args.seed)
    rows = []
    failures = []
    for name, raw, r in maps:
        infl = astar.inflate(raw, r, metric="square", outside_occupied=True)
        cost = (
            astar.clearance_cost(raw, r, outside_occupied=True)
            if args.search == "clearance"
            else None
        )
        for path in draw_paths(raw, infl, cost, args.per_map, rng):
            tb, boxes = best_time(
                lambda: build_corridor(infl, path, radius=r, raw_grid=raw),  # noqa: B023
                args.repeats,
            )
            try:
                tp, poly = best_time(
                    lambda: build_polygon_corridor(raw, path, r),  # noqa: B023
                    args.repeats,
                )
            except TrajoptError as exc:
                failures.append(f"{name} {path!r}: {exc}")
                continue
            ov = poly.overlap_lengths_m / raw.resolution
            rows.append(
                {
                    "map": name,
                    "cells": len(path),
                    "boxes_s": tb,
                    "poly_s": tp,
                    "n_boxes": len(boxes),
                    "n_poly": len(poly),
                    "ov_min": float(ov.min()) if len(ov) else math.inf,
                    "ov_med": float(np.median(ov)) if len(ov) else math.inf,
                    "degenerate": sum(g.degenerate for g in poly.regions),
                    "area_ratio": area_ratio(poly, boxes, path.cells),
                    "sides_max": max(g.n_sides for g in poly.regions),
                }
            )
    if not rows:
        print("no paths of 100-300 cells drawn")
        return
    tb = np.array([x["boxes_s"] for x in rows]) * 1e3
    tp = np.array([x["poly_s"] for x in rows]) * 1e3
    used = list(dict.fromkeys(x["map"] for x in rows))
    unused = [name for name, _, _ in maps if name not in used]
    print(
        f"{len(rows)} paths of 100-300 cells on {len(used)} maps (search={args.search}, "
        f"best of {args.repeats}); {len(failures)} polygon failures"
        + (f"; no such path drawn on {', '.join(unused)}" if unused else "")
    )
    print(f"{'':28}{'boxes':>10}{'polygons':>10}{'ratio':>8}")
    for q, label in ((50, "build median (ms)"), (95, "build p95 (ms)"), (100, "build max (ms)")):
        a, b = np.percentile(tb, q), np.percentile(tp, q)
        print(f"{label:28}{a:10.2f}{b:10.2f}{b / a:8.2f}")
    nb = np.array([x["n_boxes"] for x in rows])
    npg = np.array([x["n_poly"] for x in rows])
    print(f"{'regions per path (median)':28}{np.median(nb):10.0f}{np.median(npg):10.0f}")
    ovmin = np.array([x["ov_min"] for x in rows])
    ovmed = np.array([x["ov_med"] for x in rows])
    print(
        f"polygon overlap along the path (cells): smallest {ovmin.min():.2f}, "
        f"p5 of per-path smallest {np.percentile(ovmin, 5):.2f}, median {np.median(ovmed):.2f}"
    )
    print(
        f"degenerate regions: {sum(x['degenerate'] for x in rows)}; most sides: "
        f"{max(x['sides_max'] for x in rows)}"
    )
    print(
        f"region area per path cell, polygon / box (median over paths): "
        f"{np.median([x['area_ratio'] for x in rows]):.2f}"
    )
    print("\nper map (median ms, boxes / polygons):")
    for name in dict.fromkeys(x["map"] for x in rows):
        sub = [x for x in rows if x["map"] == name]
        print(
            f"  {name:26} n={len(sub):3d}  {1e3 * np.median([x['boxes_s'] for x in sub]):6.2f}"
            f"  {1e3 * np.median([x['poly_s'] for x in sub]):6.2f}"
        )
    for f in failures:
        print("failed:", f[:200])


if __name__ == "__main__":
    main()
