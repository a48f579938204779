"""Benchmark: plans whose cost does not grow with the map's resolution (issue #35).

A *site* is a shared ROS map at a base resolution; the same site is then planned with every
cell split 2 x 2 and 3 x 3 (:meth:`astar.OccupancyGrid.split`: the same metres, 4x and 9x the
cells). On every version the same long queries (> 20 m on willow, > 10 m on depot; seeded,
drawn on the base map) are planned by the default ``trajopt.Planner`` (robot radius
0.25 m), warm, in one process, best of ``--repeat`` per query. Printed per version:

* the first plan on the new map (a new Planner: inflation, search cost, the coarse search's
  blocks and the first query; the compiled kernels are already loaded);
* the warm plan's median, p95 and worst time, and its stages' medians;
* against the site's base version, measured in the same run: the ratio of the total and
  of the smoothing stage's medians, and the durations' and clearances' relative
  differences on the same queries;
* the search's mode and its proven suboptimality bound (``stats["search_info"]``);
* the trajectory's exact clearance from the raw map (dense samples, independent of the
  certificate).

``--memory CELLS_M`` (default 15) then plans three queries on the willow site split so
that it has at least that many million cells, in a fresh process, and prints the peak
resident memory (``VmHWM``), the interpreter and libraries included.

Run::

    python benchmarks/bench_scale.py                       # willow at 3.3 cm, depot at 5 cm
    python benchmarks/bench_scale.py --sites willow:3 --queries 6 --repeat 2 --memory 0

Needs ``../shared/data`` (or ``$TRAJOPT_DATA``).
"""

from __future__ import annotations

import argparse
import math
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

RADIUS = 0.25
MAPS = {"willow": "willow-2010-02-18-0.10", "depot": "depot"}
#: shortest query (m) per map: long queries on each map's scale
MIN_LENGTH_M = {"willow": 20.0, "depot": 10.0}


def data_dir() -> Path:
    env = os.environ.get("TRAJOPT_DATA")
    return Path(env) if env else Path(__file__).resolve().parents[2] / "shared" / "data"


def load(name: str, split: int):
    import astar

    return astar.load_map(data_dir() / "ros" / f"{MAPS[name]}.yaml").split(split)


def long_queries(grid, n: int, min_m: float, seed: int = 1) -> list[tuple]:
    """``n`` start/goal pairs at least ``min_m`` apart, both 2 radii clear, joined by a path."""
    import astar
    import trajopt

    planner = trajopt.Planner(grid, trajopt.Robot(radius=RADIUS))
    clr = astar.clearance(grid, metric="square", outside_occupied=True)
    ok = np.argwhere(clr >= 2 * RADIUS)  # (iy, ix)
    rng = np.random.default_rng(seed)
    out: list[tuple] = []
    for _ in range(200 * n):
        if len(out) == n:
            break
        a, b = ok[rng.integers(len(ok), size=2)]
        p0, p1 = grid.cell_to_world((a[1], a[0])), grid.cell_to_world((b[1], b[0]))
        if math.hypot(*(p1 - p0)) < min_m:
            continue
        try:
            astar.find_path(planner.inflated_grid, (a[1], a[0]), (b[1], b[0]))
        except astar.NoPathError:
            continue
        out.append((tuple(map(float, p0)), tuple(map(float, p1))))
    return out


def true_clearance(traj, grid) -> float:
    """Exact least distance (m) of the trajectory's curve from the raw map (1 cm samples).

    Independent of the smoother's certificate (whose reported clearance is capped at the
    radius plus two cells, so it would differ between resolutions by the cap alone).
    """
    from trajopt.analysis.metrics import min_clearance

    curve = traj.steps.smooth_path.curve
    u0, u1 = curve.domain
    xy = curve(np.linspace(u0, u1, max(2, int(math.ceil((u1 - u0) / 0.01)) + 1)))
    return min_clearance(xy, grid, border_occupied=True)


def run_version(grid, queries, repeat: int) -> dict:
    """First plan on a new Planner of ``grid``, then the warm queries (best of ``repeat``)."""
    import trajopt

    t0 = time.perf_counter()
    planner = trajopt.Planner(grid, trajopt.Robot(radius=RADIUS))
    planner.plan(*queries[0])
    first = time.perf_counter() - t0
    rows = []
    for q in queries:
        best = None
        for _ in range(repeat):
            tr = planner.plan(*q)
            st = tr.stats["stages_s"]
            if best is None or st["total"] < best[0]["total"]:
                best = (dict(st), tr)
        st, tr = best
        info = tr.stats.get("search_info") or {}
        rows.append(
            {
                **st,
                "duration": tr.duration,
                "clearance": true_clearance(tr, grid),
                "mode": info.get("mode", "exact"),
                "bound": info.get("bound", 1.0),
            }
        )
    return {"first": first, "rows": rows}


def report(name: str, split: int, grid, res: dict, base: dict | None) -> None:
    rows = res["rows"]
    tot = np.array([r["total"] for r in rows]) * 1e3
    print(
        f"\n{name} split {split}x{split}: {grid.nx} x {grid.ny} = {grid.nx * grid.ny / 1e6:.2f} M "
        f"cells of {100 * grid.resolution:.2f} cm; {len(rows)} queries"
    )
    print(f"  first plan on the new map {res['first']:.2f} s")
    print(
        f"  warm plan: median {np.median(tot):.1f} ms, p95 {np.percentile(tot, 95):.1f} ms, "
        f"worst {tot.max():.1f} ms ({tot.max() / np.median(tot):.2f}x the median)"
    )
    stages = ("search", "corridor", "smooth", "timing")
    print(
        "  stages (median ms): "
        + ", ".join(f"{s} {1e3 * np.median([r.get(s, 0.0) for r in rows]):.1f}" for s in stages)
    )
    modes = sorted({r["mode"] for r in rows})
    bounds = [r["bound"] for r in rows if r["bound"] is not None]
    print(
        f"  search: {', '.join(modes)}; proven bound median {np.median(bounds):.3f}, "
        f"worst {max(bounds):.3f}"
    )
    if base is not None:
        b = base["rows"]
        med = lambda rs, k: np.median([r[k] for r in rs])  # noqa: E731
        dur = np.array([r["duration"] / s["duration"] - 1 for r, s in zip(rows, b, strict=True)])
        clr = np.array([r["clearance"] / s["clearance"] - 1 for r, s in zip(rows, b, strict=True)])
        print(
            f"  vs 1x1: total {med(rows, 'total') / med(b, 'total'):.2f}x, smoothing "
            f"{med(rows, 'smooth') / med(b, 'smooth'):.2f}x; durations {100 * np.median(dur):+.2f} % "
            f"median (worst {100 * np.abs(dur).max():.2f} %), clearance {100 * np.median(clr):+.2f} % "
            f"median (worst {100 * np.abs(clr).max():.2f} %)"
        )


def memory_child(split: int) -> None:
    """Plan three long queries on willow split ``split`` x ``split``; print the peak RSS."""
    import trajopt

    grid = load("willow", split)
    queries = long_queries(load("willow", 1), 3, MIN_LENGTH_M["willow"])
    planner = trajopt.Planner(grid, trajopt.Robot(radius=RADIUS))
    for q in queries:
        planner.plan(*q)
    print(f"{grid.nx * grid.ny} {peak_rss()}")


def peak_rss() -> int:
    """This process's peak resident memory (bytes).

    ``VmHWM`` of ``/proc/self/status`` where there is one: ``ru_maxrss`` survives ``exec``,
    so in a child of a large parent it reports the parent's size at the fork.
    """
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) * 1024
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024  # Linux: KiB


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--sites",
        default="willow:3,depot:1",
        help="map:base_split,... (willow is 10 cm, depot 5 cm; default willow:3,depot:1; "
        "none: only the memory)",
    )
    ap.add_argument("--queries", type=int, default=12)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--memory", type=float, default=15.0, help="million cells (0: skip)")
    ap.add_argument("--memory-child", type=int, default=0, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.memory_child:
        memory_child(args.memory_child)
        return
    if not (data_dir() / "ros").is_dir():
        print(f"shared ROS maps not found under {data_dir()} (set TRAJOPT_DATA); skipped")
        return
    import trajopt

    trajopt.warm_up()
    for site in [] if args.sites == "none" else args.sites.split(","):
        name, base = site.split(":")
        base = int(base)
        queries = long_queries(load(name, 1), args.queries, MIN_LENGTH_M[name])
        first = None
        for k in (1, 2, 3):
            grid = load(name, base * k)
            res = run_version(grid, queries, args.repeat)
            report(f"{name} at {base}x{base}", k, grid, res, first)
            first = first or res
    if args.memory > 0:
        cells = load("willow", 1)
        split = math.ceil(math.sqrt(args.memory * 1e6 / (cells.nx * cells.ny)))
        out = subprocess.run(
            [sys.executable, __file__, "--memory-child", str(split)],
            capture_output=True,
            text=True,
            check=True,
        ).stdout.split()
        n, peak = int(out[-2]), int(out[-1])
        print(
            f"\nmemory: willow split {split}x{split} ({n / 1e6:.1f} M cells), a new process "
            f"planning 3 long queries: peak RSS {peak / 2**30:.2f} GiB (target <= 1 GiB)"
        )


if __name__ == "__main__":
    main()
