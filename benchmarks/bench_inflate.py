"""Inflation speed: ``astar.inflation`` against a plain ``distance_transform_edt`` threshold.

A random 4000 x 4000 grid (0.03 m cells, 120 m x 120 m) is inflated by a 0.3 m radius (10
cells) with both metrics of :func:`astar.inflation` and, in the same run, by thresholding
``scipy.ndimage.distance_transform_edt`` (the textbook exact method). Each is timed ``--repeat``
times; the script prints the medians, the ratio, and checks that the centre-metric results are
identical. Then the clearance field (:func:`astar.clearance`, both metrics, from the exact
transform of :mod:`astar.distance_transform`) against scipy's transform on the same grid (for
the square metric on the grid refined by two, the exact method it replaced); the fields must be
identical.

Run from the repository root::

    python benchmarks/bench_inflate.py
    python benchmarks/bench_inflate.py --size 2000 --density 0.02 --repeat 5
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from scipy import ndimage

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import astar  # noqa: E402
from tests.reference import scipy_distance_cells  # noqa: E402


def timed(fn, repeat: int) -> tuple[float, object]:
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--size", type=int, default=4000, help="cells per side")
    ap.add_argument("--resolution", type=float, default=0.03, help="metres per cell")
    ap.add_argument("--radius", type=float, default=0.3, help="metres")
    ap.add_argument("--density", type=float, default=0.01, help="fraction of occupied cells")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)

    rng = np.random.default_rng(0)
    occ = rng.random((args.size, args.size)) < args.density
    grid = astar.OccupancyGrid(occ, args.resolution)
    astar.inflate(astar.OccupancyGrid(occ[:50, :50], args.resolution), args.radius)  # warm up
    r_cells = args.radius / args.resolution

    t_centre, ours = timed(lambda: astar.inflate(grid, args.radius), args.repeat)
    t_square, _ = timed(lambda: astar.inflate(grid, args.radius, metric="square"), args.repeat)
    t_edt, ref = timed(
        lambda: ndimage.distance_transform_edt(~occ) <= r_cells * (1 + 1e-9), args.repeat
    )
    same = bool(np.array_equal(ours.occupied, ref))
    print(
        f"grid {args.size} x {args.size}, {args.resolution} m cells, radius {args.radius} m "
        f"({r_cells:.2f} cells), density {args.density}, median of {args.repeat}"
    )
    print(f"  astar.inflation (centre)         {1e3 * t_centre:9.1f} ms")
    print(f"  astar.inflation (square)         {1e3 * t_square:9.1f} ms")
    print(f"  distance_transform_edt <= r    {1e3 * t_edt:9.1f} ms")
    print(f"  ratio edt / inflate(centre)    {t_edt / t_centre:9.2f}x   identical: {same}")
    print("clearance field (metres, every cell)")
    for metric in ("centre", "square"):
        t_ours, field = timed(lambda m=metric: astar.clearance(grid, metric=m), args.repeat)
        t_ref, ref_field = timed(
            lambda m=metric: scipy_distance_cells(occ, m) * args.resolution, args.repeat
        )
        equal = bool(np.array_equal(field, ref_field))
        same &= equal
        print(
            f"  astar.clearance ({metric}) {1e3 * t_ours:9.1f} ms   scipy {1e3 * t_ref:9.1f} ms"
            f"   ratio scipy / ours {t_ref / t_ours:6.2f}x   identical: {equal}"
        )
    return 0 if same else 1


if __name__ == "__main__":
    raise SystemExit(main())
