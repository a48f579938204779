"""A* speed: ``astar.find_path`` against ``pyastar2d`` on the same Moving AI queries, one run.

For each map the queries are the scenarios of the longest buckets (at least ``--n`` of them).
Both planners get the same grid: ours an :class:`astar.OccupancyGrid`, pyastar2d a float32 weight
grid with ``np.inf`` on walls and 1 elsewhere (its required format). Each query is timed
``--repeat`` times for each planner, interleaved, and the best time per query is kept; the script
prints the median time ratio ours/pyastar2d, our worst relative length error against the
benchmark's optimal length, and pyastar2d's excess length (its paths measured with the octile
metric: it charges a diagonal step like a straight one and cuts corners, so it is not
octile-optimal and is only a speed reference).

A second table times the clearance-cost search (``cost=astar.clearance_cost(...)``, the
planner's default ``search="clearance"``) on a warehouse-size map, willow at 5 cm cells
(each 10 cm cell split in four, 1132 x 1216 cells), robot radius 0.25 m: the ``--long`` longest
of 3x as many random connected queries, best of ``--repeat``, without and with 6 ALT
landmarks (:func:`astar.build_landmarks`, build time reported) in the same run; the three
longest are checked against scipy's Dijkstra on the same graph (costs must agree to 1e-9),
and the landmark searches against the plain ones.

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
    ap.add_argument(
        "--long",
        type=int,
        default=20,
        help="clearance-cost queries timed on the warehouse-size map (0: none)",
    )
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
    if args.long:
        bench_clearance_search(args.long, args.repeat)
    return 0


def step_graph(occ: np.ndarray, cost: np.ndarray):
    """The 8-connected step graph without corner cutting, as a scipy CSR matrix."""
    from scipy.sparse import csr_matrix

    ny, nx = occ.shape
    free = ~occ
    idx = np.arange(ny * nx).reshape(ny, nx)
    rows, cols, w = [], [], []
    for dx, dy in ((1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (1, -1), (-1, 1), (-1, -1)):
        ok = free.copy()
        ok &= np.roll(np.roll(free, -dy, axis=0), -dx, axis=1)
        if dx and dy:  # both orthogonal neighbours free
            ok &= np.roll(free, -dx, axis=1) & np.roll(free, -dy, axis=0)
        ys, xs = np.nonzero(ok)
        keep = (xs + dx >= 0) & (xs + dx < nx) & (ys + dy >= 0) & (ys + dy < ny)
        ys, xs = ys[keep], xs[keep]
        length = math.sqrt(2.0) if dx and dy else 1.0
        rows.append(idx[ys, xs])
        cols.append(idx[ys + dy, xs + dx])
        w.append(length * (1.0 + 0.5 * (cost[ys, xs] + cost[ys + dy, xs + dx])))
    n = ny * nx
    return csr_matrix((np.concatenate(w), (np.concatenate(rows), np.concatenate(cols))), (n, n))


def bench_clearance_search(n_long: int, repeat: int) -> None:
    from scipy.sparse.csgraph import dijkstra

    f = data_dir() / "ros" / "willow-2010-02-18-0.10.yaml"
    if not f.exists():
        print(f"clearance-cost search: skipped ({f} not found)")
        return
    w = astar.load_map(f)
    big = astar.OccupancyGrid(
        np.repeat(np.repeat(w.occupied, 2, axis=0), 2, axis=1), w.resolution / 2, w.origin
    )
    inflated = astar.inflate(big, 0.25)
    cost = astar.clearance_cost(big, 0.25)
    free = np.argwhere(~inflated.occupied)
    rng = np.random.default_rng(0)
    found = []
    while len(found) < 3 * n_long:
        a, b = free[rng.integers(len(free), size=2)]
        try:
            p = astar.find_path(inflated, (a[1], a[0]), (b[1], b[0]), cost=cost)
        except astar.NoPathError:
            continue
        found.append((p.cost, (a[1], a[0]), (b[1], b[0])))
    found.sort(reverse=True)
    t0 = time.perf_counter()
    lms = astar.build_landmarks(inflated, cost, 6)
    build_s = time.perf_counter() - t0
    times, expanded, times_alt, expanded_alt, alt_err = [], [], [], [], 0.0
    for c, s, g in found[:n_long]:
        best = best_alt = math.inf
        for _ in range(repeat):
            t0 = time.perf_counter()
            p = astar.find_path(inflated, s, g, cost=cost)
            t1 = time.perf_counter()
            q = astar.find_path(inflated, s, g, landmarks=lms)
            best = min(best, t1 - t0)
            best_alt = min(best_alt, time.perf_counter() - t1)
        times.append(1e3 * best)
        expanded.append(p.expanded)
        times_alt.append(1e3 * best_alt)
        expanded_alt.append(q.expanded)
        alt_err = max(alt_err, abs(q.cost - c) / c)
    graph = step_graph(np.asarray(inflated.occupied), cost)
    worst = 0.0
    for c, s, g in found[:3]:
        d = dijkstra(graph, indices=s[1] * big.nx + s[0])[g[1] * big.nx + g[0]]
        worst = max(worst, abs(d - c) / d)
    t = np.array(times)
    print(
        f"\nclearance-cost search, willow at 5 cm ({big.nx} x {big.ny}), radius 0.25 m, the "
        f"{n_long} longest of {3 * n_long} queries (path cost {found[n_long - 1][0]:.0f}-"
        f"{found[0][0]:.0f} cells)"
    )
    print(
        f"  time median {np.median(t):.1f} ms, p95 {np.percentile(t, 95):.1f} ms, max "
        f"{t.max():.1f} ms (target <= 30 ms); expansions median {np.median(expanded):.0f}; "
        f"{np.median(t * 1e6 / np.array(expanded)):.0f} ns per expansion"
    )
    ta = np.array(times_alt)
    print(
        f"  with 6 landmarks (built once in {build_s:.2f} s): median {np.median(ta):.1f} ms, p95 "
        f"{np.percentile(ta, 95):.1f} ms, max {ta.max():.1f} ms; expansions median "
        f"{np.median(expanded_alt):.0f}; median time ratio landmarks / none "
        f"{np.median(ta / t):.2f}; cost vs the plain search max relative error "
        f"{alt_err:.1e}"
    )
    print(f"  cost vs scipy's Dijkstra on the 3 longest: max relative error {worst:.1e}")


if __name__ == "__main__":
    raise SystemExit(main())
