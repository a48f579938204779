"""A* speed: ``astar.find_path`` against ``pyastar2d`` on the same Moving AI queries, one run.

For each map the queries are the scenarios of the longest buckets (at least ``--n`` of them).
Both planners get the same grid: ours an :class:`astar.OccupancyGrid`, pyastar2d a float32 weight
grid with ``np.inf`` on walls and 1 elsewhere (its required format). Each query is timed
``--repeat`` times for each planner, interleaved, and the best time per query is kept; the script
prints the median time ratio ours/pyastar2d, our worst relative length error against the
benchmark's optimal length, and pyastar2d's excess length (its paths measured with the octile
metric: it charges a diagonal step like a straight one and cuts corners, so it is not
octile-optimal and is only a speed reference).

Run from the repository root::

    python benchmarks/bench_astar.py            # Boston_0_1024 and maze512-1-0
    python benchmarks/bench_astar.py --n 40 --repeat 5

The maps are read from ``$TRAJOPT_DATA`` (default ``../shared/data``).
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

DEFAULT_MAPS = ("Boston_0_1024", "maze512-1-0")


def data_dir() -> Path:
    env = os.environ.get("TRAJOPT_DATA")
    return Path(env) if env else Path(__file__).resolve().parents[2] / "shared" / "data"


def octile_length(cells: np.ndarray) -> float:
    """Length of a cell path with 1 per straight and sqrt(2) per diagonal step."""
    d = np.abs(np.diff(np.asarray(cells, dtype=np.int64), axis=0))
    diag = int(np.count_nonzero((d[:, 0] == 1) & (d[:, 1] == 1)))
    return (d.shape[0] - diag) + diag * math.sqrt(2.0)


def longest_queries(scens: list, n: int) -> list:
    """The scenarios of the longest buckets, at least ``n`` of them (whole buckets)."""
    buckets = sorted({s.bucket for s in scens}, reverse=True)
    out: list = []
    for b in buckets:
        out.extend(s for s in scens if s.bucket == b)
        if len(out) >= n:
            break
    return out


def bench_map(name: str, n: int, repeat: int) -> dict[str, float]:
    import pyastar2d

    root = data_dir() / "movingai"
    grid = astar.load_map(root / "maps" / f"{name}.map")
    scens = longest_queries(astar.read_scenarios(root / "scen" / f"{name}.map.scen"), n)
    weights = np.where(grid.occupied, np.inf, 1.0).astype(np.float32)

    # warm up: numba cache load / compile, pyastar2d import
    s0 = scens[0]
    astar.find_path(grid, s0.start, s0.goal)
    pyastar2d.astar_path(weights, s0.start[::-1], s0.goal[::-1], allow_diagonal=True)

    ratios, ours_t, peer_t, errors, excess, expanded = [], [], [], [], [], []
    for s in scens:
        best_ours = best_peer = math.inf
        for _ in range(repeat):
            t0 = time.perf_counter()
            path = astar.find_path(grid, s.start, s.goal)
            t1 = time.perf_counter()
            peer = pyastar2d.astar_path(
                weights, (s.start[1], s.start[0]), (s.goal[1], s.goal[0]), allow_diagonal=True
            )
            t2 = time.perf_counter()
            best_ours = min(best_ours, t1 - t0)
            best_peer = min(best_peer, t2 - t1)
        ours_t.append(best_ours)
        peer_t.append(best_peer)
        ratios.append(best_ours / best_peer)
        errors.append(abs(path.length - s.optimal_length) / s.optimal_length)
        expanded.append(path.expanded)
        if peer is not None:
            excess.append(octile_length(peer[:, ::-1]) / s.optimal_length - 1.0)
    return {
        "queries": len(scens),
        "buckets": f"{min(s.bucket for s in scens)}-{max(s.bucket for s in scens)}",
        "ours_ms": 1e3 * statistics.median(ours_t),
        "peer_ms": 1e3 * statistics.median(peer_t),
        "ratio": statistics.median(ratios),
        "ratio_max": max(ratios),
        "max_rel_err": max(errors),
        "expanded": statistics.median(expanded),
        "excess_med": 100 * statistics.median(excess),
        "excess_max": 100 * max(excess),
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--maps", nargs="+", default=list(DEFAULT_MAPS))
    ap.add_argument("--n", type=int, default=20, help="queries per map (whole longest buckets)")
    ap.add_argument("--repeat", type=int, default=3, help="timings per query (best kept)")
    args = ap.parse_args(argv)
    print(
        f"{'map':<16}{'queries':>8}{'buckets':>10}{'ours ms':>10}{'pyastar2d ms':>14}"
        f"{'ratio':>8}{'max':>7}{'exp(med)':>10}{'len err':>10}{'peer excess med/max %':>24}"
    )
    for name in args.maps:
        r = bench_map(name, args.n, args.repeat)
        print(
            f"{name:<16}{r['queries']:>8}{r['buckets']:>10}{r['ours_ms']:>10.2f}"
            f"{r['peer_ms']:>14.2f}{r['ratio']:>8.2f}{r['ratio_max']:>7.2f}"
            f"{r['expanded']:>10.0f}{r['max_rel_err']:>10.1e}"
            f"{r['excess_med']:>12.2f} / {r['excess_max']:.2f}"
        )
    print(
        "ratio = median over queries of (our best time / pyastar2d's best time); "
        "len err = max relative error of our length vs the benchmark optimum"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
