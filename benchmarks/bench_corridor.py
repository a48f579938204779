"""Polygon corridors against box corridors, side by side on the same queries (issue 16).

For every query (start/goal cell pairs drawn from the shared Moving AI maps, radius 2.5
cells, and ROS maps, radius 0.2 m, as in ``bench_curvature.py``; plus 30- and 45-degree
staircase passages of free width 2r + 1 to 2r + 4 cells between cell-centre walls, drawn in
code; the narrow ones that leave no grid path after inflation are skipped and named), plans with
``Planner(corridor="polygons")`` (the default: polygons, then boxes where they fail) and
``Planner(corridor="boxes")``, for both A* seeds (``search="clearance"`` and
``"shortest"``), without a curvature bound and with ``kappa_max = 1 / (2 r)``, and prints:

* success: a certified trajectory returned (``plan`` raised nothing), and for polygons how
  many were fitted in the polygons themselves;
* certificate violations under an independent dense check: exact point-to-square distance
  from the raw map's occupied cells and the map's outside, at 20 samples per cell of length
  (numpy here, not the library's kernel);
* median trajectory duration ratio polygons / boxes on the queries both solved, median
  min-clearance / radius, median integral of squared curvature ``int kappa^2 ds``;
* *touching* failures apart: queries whose start and goal are joined only through free
  space of zero width (no grid path for a radius a millionth of a cell larger: an end point
  or a gap exactly at the radius from the walls), where no curve has room;
* warm times (best of ``--repeats`` calls after an untimed first): corridor build,
  smoothing stage, whole ``plan`` (also per map, with willow at 5 cm cells, 1216 x 1132, as
  a warehouse-size map).

With a curvature bound a failure is a failure on a *feasible* query only when
:func:`trajopt.planning._feasibility.curvature_witness` finds a witness (``--witness``).

Run: ``python benchmarks/bench_corridor.py [--per-map 12] [--seed 0] [--repeats 3]``.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from bench_curvature import data_dir, draw_pairs  # noqa: E402

import astar  # noqa: E402
from trajopt._planner import Planner  # noqa: E402
from trajopt.errors import InvalidInputError, SmoothingError, TimingError  # noqa: E402
from trajopt.planning._feasibility import curvature_witness  # noqa: E402
from trajopt.robot._robot import Robot  # noqa: E402
from trajopt.smoother import Smoother  # noqa: E402

MOVINGAI = ["arena", "den312d", "Berlin_0_256", "rmtst01", "random512-40-5", "AR0046SR"]
ROS = ["turtlebot3_world", "smoothers_world", "depot", "willow-2010-02-18-0.10"]


def staircase(angle_deg: float, width_cells: float, r_cells: float = 2.5):
    """A straight street at ``angle_deg`` of free width ``2 r + width_cells`` cells through
    a solid 1 m-cell map, start and goal on its axis near either end."""
    n = 90
    occ = np.ones((n, n), bool)
    th = math.radians(angle_deg)
    d = np.array([math.cos(th), math.sin(th)])
    nrm = np.array([-d[1], d[0]])
    a = np.array([8.0, 8.0])
    half = r_cells + 0.5 * width_cells
    yy, xx = np.mgrid[0:n, 0:n]
    c = np.stack([xx + 0.5, yy + 0.5], -1) - a
    along = c @ d
    across = c @ nrm
    # a cell is free when its centre lies in the street
    occ[(along > -1) & (along < 100) & (np.abs(across) <= half)] = False
    grid = astar.OccupancyGrid(occ, 1.0, (0.0, 0.0))
    length = min((n - 12 - a[0]) / max(d[0], 1e-9), (n - 12 - a[1]) / max(d[1], 1e-9))
    infl = astar.inflate(grid, r_cells, metric="square", outside_occupied=True)
    fy, fx = np.nonzero(~infl.occupied)
    if len(fx) == 0:
        return grid, r_cells, None, None
    centres = np.column_stack([fx + 0.5, fy + 0.5])

    def nearest(p):
        i = int(np.argmin(np.hypot(*(centres - p).T)))
        return int(fx[i]), int(fy[i])

    return grid, r_cells, nearest(a + 3.0 * d), nearest(a + length * d)


def dense_clearance(raw, xy: np.ndarray, window: float) -> float:
    """Exact distance (m) from points to the nearest occupied square or the map's outside."""
    res = raw.resolution
    ox, oy = raw.origin
    occ = raw.occupied
    ny, nx = occ.shape
    out = np.inf
    w = int(math.ceil(window / res)) + 1
    for p in xy:
        out = min(out, p[0] - ox, ox + nx * res - p[0], p[1] - oy, oy + ny * res - p[1])
        ix, iy = int((p[0] - ox) // res), int((p[1] - oy) // res)
        x0, x1 = max(ix - w, 0), min(ix + w + 1, nx)
        y0, y1 = max(iy - w, 0), min(iy + w + 1, ny)
        sub = occ[y0:y1, x0:x1]
        if not sub.any():
            continue
        jy, jx = np.nonzero(sub)
        lx = ox + (x0 + jx) * res
        ly = oy + (y0 + jy) * res
        dx = np.maximum(np.maximum(lx - p[0], p[0] - lx - res), 0.0)
        dy = np.maximum(np.maximum(ly - p[1], p[1] - ly - res), 0.0)
        out = min(out, float(np.min(np.hypot(dx, dy))))
    return float(out)


_TOUCH: dict = {}


def touching(raw, radius: float, a, b) -> bool:
    """Whether start and goal are joined only through free space of zero width: no grid
    path for a radius one millionth of a cell larger (an end point, or a gap, at exactly the
    radius from the walls)."""
    key = (id(raw), radius, a, b)
    if key not in _TOUCH:
        g = astar.inflate(
            raw, radius + 1e-6 * raw.resolution, metric="square", outside_occupied=True
        )
        try:
            astar.find_path(g, a, b)
            _TOUCH[key] = False
        except (astar.NoPathError, astar.InvalidInputError):
            _TOUCH[key] = True
    return _TOUCH[key]


def run(planner: Planner, p0, p1, repeats: int):
    """Plan once (untimed), then ``repeats`` times: the result and the best stage times."""
    try:
        traj = planner.plan(p0, p1)
    except (SmoothingError, TimingError, InvalidInputError) as exc:
        return None, type(exc).__name__, {}
    best: dict[str, float] = defaultdict(lambda: math.inf)
    for _ in range(repeats):
        t = time.perf_counter()
        tr = planner.plan(p0, p1)
        best["plan"] = min(best["plan"], time.perf_counter() - t)
        for k in ("corridor", "smooth", "timing"):
            best[k] = min(best[k], tr.stats["stages_s"].get(k, math.nan))
    return traj, "", dict(best)


def measure(traj, raw, radius: float) -> dict[str, float]:
    sp = traj.steps.smooth_path
    n = max(200, int(20 * sp.length / raw.resolution))
    u = sp.u_at_s(np.linspace(0.0, sp.length, n))
    xy = sp(u)
    k = np.abs(sp.curvature(u))
    clr = dense_clearance(raw, xy, radius + 2 * raw.resolution)
    return {
        "duration": traj.duration,
        "clearance_ratio": clr / radius,
        "violation": clr < radius - 1e-9,
        "int_k2": float(np.trapezoid(k**2, np.linspace(0.0, sp.length, n))),
        "in_polygons": traj.stats.get("corridor") == "polygons",
    }


def queries(per_map: int, seed: int):
    rng = np.random.default_rng(seed)
    d = data_dir()
    for name in MOVINGAI + ROS:
        kind = "movingai" if name in MOVINGAI else "ros"
        f = (
            d
            / kind
            / ("maps" if kind == "movingai" else "")
            / (f"{name}.map" if kind == "movingai" else f"{name}.yaml")
        )
        if not f.exists():
            print(f"skipped {name}: {f} not found (set TRAJOPT_DATA)")
            continue
        raw = astar.load_map(f)
        radius = 2.5 * raw.resolution if kind == "movingai" else 0.2
        _, pairs = draw_pairs(raw, radius, per_map, rng)
        for a, b in pairs:
            yield name, raw, radius, a, b
    # a warehouse-size map: willow at 5 cm cells (each 10 cm cell split in four), 1216 x 1132
    f = d / "ros" / "willow-2010-02-18-0.10.yaml"
    if f.exists():
        w = astar.load_map(f)
        occ = np.repeat(np.repeat(w.occupied, 2, axis=0), 2, axis=1)
        big = astar.OccupancyGrid(occ, w.resolution / 2, w.origin)
        _, pairs = draw_pairs(big, 0.25, per_map, rng)
        for a, b in pairs:
            yield "willow-5cm", big, 0.25, a, b
    for angle in (30.0, 45.0):
        for width in (1.0, 2.0, 3.0, 4.0):
            grid, r_cells, a, b = staircase(angle, width)
            infl = astar.inflate(grid, r_cells, metric="square", outside_occupied=True)
            try:
                if a is None or math.hypot(a[0] - b[0], a[1] - b[1]) < 40:
                    raise astar.NoPathError("no street")
                astar.find_path(infl, a, b)
            except astar.NoPathError:
                print(f"street {angle:.0f} deg, width 2r + {width:.0f}: no grid path, skipped")
                continue
            yield f"street{angle:.0f}w{width:.0f}", grid, r_cells * grid.resolution, a, b


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--per-map", type=int, default=12)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--witness", action="store_true", help="classify kappa failures")
    args = ap.parse_args(argv)
    configs = [
        (corr, search, kap)
        for kap in (False, True)
        for search in ("clearance", "shortest")
        for corr in ("boxes", "polygons")
    ]
    rows: dict[tuple, list] = defaultdict(list)
    t_all = time.perf_counter()
    n_q = 0
    planners: dict[tuple, Planner] = {}
    for name, raw, radius, a, b in queries(args.per_map, args.seed):
        n_q += 1
        p0, p1 = raw.cell_to_world(np.array(a)), raw.cell_to_world(np.array(b))
        for cfg in configs:
            corr, search, kap = cfg
            key = (name, radius, cfg)
            if key not in planners:
                sm = Smoother(kappa_max=1.0 / (2 * radius), time_budget_s=5) if kap else None
                planners[key] = Planner(
                    raw, Robot(radius=radius), search=search, smoother=sm, corridor=corr
                )
            traj, err, times = run(planners[key], p0, p1, args.repeats)
            rec = {
                "map": name,
                "query": (a, b),
                "error": err,
                "times": times,
                "touching": touching(raw, radius, a, b),
            }
            if traj is not None:
                rec.update(measure(traj, raw, radius))
            elif kap and args.witness:
                w = curvature_witness(raw, radius, p0, p1, 1.0 / (2 * radius), time_limit_s=5)
                rec["feasible"] = w is not None
            rows[cfg].append(rec)
    print(f"{n_q} queries, {time.perf_counter() - t_all:.0f} s")
    print(
        "| bound | search | corridor | solved | in polygons | dense violations | "
        "median min-clearance/r | median int k^2 ds | corridor ms med/p95 | "
        "smooth ms med/p95 | plan ms med |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for cfg in configs:
        corr, search, kap = cfg
        rs = rows[cfg]
        ok = [r for r in rs if not r["error"]]
        fails = [r for r in rs if r["error"]]
        feas = ""
        if kap and args.witness:
            feas = f" ({sum(1 for r in fails if r.get('feasible'))} feasible)"

        def pct(key, q, src=ok):
            v = [r["times"][key] * 1e3 for r in src if key in r["times"]]
            return float(np.percentile(v, q)) if v else math.nan

        n_touch = sum(1 for r in fails if r["touching"])
        if n_touch:
            feas += f" ({n_touch} touching)"
        print(
            f"| {'1/(2r)' if kap else 'none'} | {search} | {corr} | {len(ok)}/{len(rs)}{feas} | "
            f"{sum(r['in_polygons'] for r in ok) if corr == 'polygons' else '-'} | "
            f"{sum(r['violation'] for r in ok)} | "
            f"{np.median([r['clearance_ratio'] for r in ok]):.2f} | "
            f"{np.median([r['int_k2'] for r in ok]):.3g} | "
            f"{pct('corridor', 50):.2f} / {pct('corridor', 95):.2f} | "
            f"{pct('smooth', 50):.2f} / {pct('smooth', 95):.2f} | {pct('plan', 50):.1f} |"
        )
        for r in fails:
            print(
                f"    failed: {r['map']} {r['query']} {r['error']}"
                + (f" feasible={r.get('feasible')}" if "feasible" in r else "")
                + (" touching" if r["touching"] else "")
            )
        if corr == "polygons":
            for r in ok:
                if not r["in_polygons"]:
                    print(f"    fitted in boxes: {r['map']} {r['query']}")
    print()
    print("Whole plan (warm, best of repeats), no bound, clearance search, median ms per map:")
    print("| map | queries | boxes | polygons | ratio |")
    print("|---|---|---|---|---|")
    b_rows, p_rows = rows[("boxes", "clearance", False)], rows[("polygons", "clearance", False)]
    for name in dict.fromkeys(r["map"] for r in b_rows):
        pairs_ = [
            (x, y)
            for x, y in zip(b_rows, p_rows, strict=True)
            if x["map"] == name and not x["error"] and not y["error"]
        ]
        if not pairs_:
            continue
        tb = np.median([x["times"]["plan"] for x, _ in pairs_]) * 1e3
        tp = np.median([y["times"]["plan"] for _, y in pairs_]) * 1e3
        print(f"| {name} | {len(pairs_)} | {tb:.1f} | {tp:.1f} | {tp / tb:.2f} |")
    print()
    print(
        "| bound | search | queries both solved | median duration polygons / boxes | "
        "p10 / p90 | median int k^2 polygons / boxes |"
    )
    print("|---|---|---|---|---|---|")
    for kap in (False, True):
        for search in ("clearance", "shortest"):
            b = rows[("boxes", search, kap)]
            p = rows[("polygons", search, kap)]
            both = [(x, y) for x, y in zip(b, p, strict=True) if not x["error"] and not y["error"]]
            if not both:
                continue
            ratio = np.array([y["duration"] / x["duration"] for x, y in both])
            k2 = np.array([(y["int_k2"] + 1e-12) / (x["int_k2"] + 1e-12) for x, y in both])
            print(
                f"| {'1/(2r)' if kap else 'none'} | {search} | {len(both)} | "
                f"{np.median(ratio):.3f} | {np.percentile(ratio, 10):.3f} / "
                f"{np.percentile(ratio, 90):.3f} | {np.median(k2):.3f} |"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
