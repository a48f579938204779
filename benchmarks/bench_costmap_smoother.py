"""The costmap's cost in the smoother: mean cost, weight, duration and smoothing time.

On Nav2-style inflation costmaps of the shared ROS maps (static layer from the map, the
inflation layer's formula with inscribed radius 0.15 m, inflation radius 0.6 m and cost
scaling 3, distances from :func:`scipy.ndimage.distance_transform_edt`), seeded random
queries between free cells at least 2 m apart are planned by a disc robot of radius
0.15 m (search ``"costmap"``) at several ``costmap_weight`` values, with the smoother's
cost term, and once at the default weight without it (the cost-blind smoother of before
issue 34, obtained by switching the term off in the same process).

Reported, over the queries every variant planned: the trajectory's mean normalised cost per
metre (dense samples of the smooth curve, nearest cell) against its A* path's (the
polyline of cell centres): the median of the per-query ratio and the ratio of the means; the median trajectory
duration relative to the cost-blind one; the median smoothing-stage time (the least of
``--repeat`` plans of each query) and its ratio to the cost-blind one. Targets (issue 34): mean-cost ratio <= 1.05 at the default weight,
non-increasing in the weight; smoothing time median <= 2x.

Run: ``python benchmarks/bench_costmap_smoother.py [--queries N] [--seed S] [--repeat R]`` (the shared
data: ``$TRAJOPT_DATA`` or ``../shared/data``; skipped with a message when absent).
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import statistics
from unittest import mock

import numpy as np

import astar
from trajopt._planner import Planner
from trajopt.analysis.bench._suites import data_dir
from trajopt.errors import TrajoptError
from trajopt.robot._robot import Robot

WEIGHTS = (1.0, 2.0, 5.0, 10.0)
R_INS, R_INF, K = 0.15, 0.6, 3.0


def nav2_values(occupied: np.ndarray, res: float) -> np.ndarray:
    """costmap_2d values (uint8) of a static + inflation layer (Nav2's formulas)."""
    from scipy import ndimage

    d = ndimage.distance_transform_edt(~occupied) * res
    c = np.zeros(occupied.shape, np.int64)
    band = (d > R_INS) & (d <= R_INF)
    c[band] = np.floor(252.0 * np.exp(-K * (d[band] - R_INS))).astype(np.int64)
    c[d <= R_INS] = 253
    c[occupied] = 254
    return c.astype(np.uint8)


def mean_cost(pts: np.ndarray, cm: astar.Costmap) -> float:
    """Mean normalised cost per metre along a densely sampled polyline ``pts`` (m)."""
    g = cm.grid
    seg = np.diff(pts, axis=0)
    d = np.linalg.norm(seg, axis=1)
    mid = 0.5 * (pts[1:] + pts[:-1])
    ix = np.floor((mid - np.asarray(g.origin)) / g.resolution).astype(int)
    ix[:, 0] = np.clip(ix[:, 0], 0, g.nx - 1)
    ix[:, 1] = np.clip(ix[:, 1], 0, g.ny - 1)
    return float(np.sum(cm.cost[ix[:, 1], ix[:, 0]] * d) / max(np.sum(d), 1e-12))


def densify(pts: np.ndarray, step: float) -> np.ndarray:
    """The polyline ``pts`` resampled every ``step`` m or less."""
    out = [pts[:1]]
    for a, b in zip(pts[:-1], pts[1:], strict=False):
        k = max(1, int(np.ceil(np.linalg.norm(b - a) / step)))
        out.append(a + (b - a) * np.linspace(0, 1, k + 1)[1:, None])
    return np.vstack(out)


def path_costs(traj, cm: astar.Costmap) -> tuple[float, float] | None:
    """Mean cost per metre of ``traj``'s smooth curve and of its A* path (None: a fallback)."""
    sp = getattr(traj.steps, "smooth_path", None)
    gp = getattr(traj.steps, "grid_path", None)
    if sp is None or gp is None:
        return None
    res = cm.grid.resolution
    a, b = sp.curve.domain
    curve = sp.curve(np.linspace(a, b, max(200, int(40 * (b - a) / res))))
    cells = np.asarray(gp.cells, dtype=float)
    poly = densify(np.asarray(cm.grid.origin) + (cells + 0.5) * res, 0.1 * res)
    return mean_cost(curve, cm), mean_cost(poly, cm)


@contextlib.contextmanager
def cost_blind():
    """The smoother without its cost term (the behaviour before issue 34)."""
    with mock.patch("trajopt.smoother._attempts.cost_field", lambda *a, **k: None):
        yield


def plan_one(planner: Planner, cm: astar.Costmap, p0, p1, repeat: int = 1) -> dict:
    """One query: mean costs of trajectory and A* path, duration, smoothing time (s).

    The query is planned ``repeat`` times; the smoothing time is the least of them (the
    plans are identical; the least time is the one least disturbed by other processes).
    """
    try:
        runs = [planner.plan(p0, p1) for _ in range(repeat)]
    except TrajoptError as exc:
        return {"ok": False, "err": str(exc)[:120]}
    traj = runs[0]
    costs = path_costs(traj, cm)
    if costs is None:
        return {"ok": False, "err": "no smooth path (fallback)"}
    return {
        "ok": True,
        "traj": costs[0],
        "astar": costs[1],
        "duration": float(traj.duration),
        "smooth_s": min(float(t.stats["stages_s"]["smooth"]) for t in runs),
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--queries", type=int, default=10, help="queries per map")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument(
        "--repeat", type=int, default=3, help="plans per query; the least smoothing time counts"
    )
    args = ap.parse_args(argv)
    root = data_dir(None) / "ros"
    maps = sorted(root.glob("*.yaml")) if root.is_dir() else []
    if not maps:
        print(f"skipped: no shared ROS maps under {root} (set TRAJOPT_DATA)")
        return 0
    logging.getLogger("trajopt").setLevel(logging.ERROR)
    rng = np.random.default_rng(args.seed)
    robot = Robot(radius=R_INS)
    variants = ["blind"] + [f"w={w:g}" for w in WEIGHTS]
    rows = []
    for path in maps:
        grid = astar.load_map(path)
        cm = astar.from_costmap(
            nav2_values(~grid.free, grid.resolution),
            grid.resolution,
            grid.origin,
            convention="costmap_2d",
        )
        planners = {f"w={w:g}": Planner(cm, robot, costmap_weight=w) for w in WEIGHTS}
        planners["blind"] = Planner(cm, robot)
        free = np.argwhere(cm.cost < 0.5)  # (iy, ix) well away from obstacles
        pairs = []
        while len(pairs) < args.queries:
            i, j = rng.integers(len(free), size=2)
            p0 = grid.cell_to_world(free[i][::-1].copy())
            p1 = grid.cell_to_world(free[j][::-1].copy())
            if np.linalg.norm(p1 - p0) >= 2.0:
                pairs.append((p0, p1))
        for name, p in planners.items():  # warm-up
            with cost_blind() if name == "blind" else contextlib.nullcontext():
                plan_one(p, cm, *pairs[0])
        for p0, p1 in pairs:
            row = {"map": path.stem}
            for name, p in planners.items():
                with cost_blind() if name == "blind" else contextlib.nullcontext():
                    row[name] = plan_one(p, cm, p0, p1, args.repeat)
            rows.append(row)
    both = [r for r in rows if all(r[v]["ok"] for v in variants)]
    print(
        f"{len(maps)} maps, {args.queries} queries each (seed {args.seed}): "
        f"{len(both)} of {len(rows)} planned by every variant"
    )
    if not both:
        return 0
    print(
        f"{'variant':<9}{'cost/A* med':>12}{'of means':>10}{'mean cost':>11}{'A* cost':>9}"
        f"{'dur/blind':>11}{'smooth ms':>11}{'smooth/blind':>14}"
    )
    for v in variants:
        ratio = [r[v]["traj"] / max(r[v]["astar"], 1e-9) for r in both]
        dur = [r[v]["duration"] / r["blind"]["duration"] for r in both]
        sm = [r[v]["smooth_s"] / r["blind"]["smooth_s"] for r in both]
        print(
            f"{v:<9}{statistics.median(ratio):>12.3f}"
            f"{sum(r[v]['traj'] for r in both) / sum(r[v]['astar'] for r in both):>10.3f}"
            f"{statistics.mean(r[v]['traj'] for r in both):>11.4f}"
            f"{statistics.mean(r[v]['astar'] for r in both):>9.4f}"
            f"{statistics.median(dur):>11.3f}"
            f"{1e3 * statistics.median(r[v]['smooth_s'] for r in both):>11.2f}"
            f"{statistics.median(sm):>14.2f}"
        )
    print(
        "cost/A*: the trajectory's mean normalised cost per metre over its A* path's (per "
        "query); blind: costmap_weight 2 without the smoother's cost term"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
