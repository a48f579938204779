"""IPOPT against piqp (and the SCP) in the default polygon corridor, on the same queries.

Plans every query of a named suite of the shared maps (``trajopt.bench.suite``) six ways,
in the same run and the same process:

* ``piqp``: the default planner (the corridor QP by piqp);
* ``ipopt``: ``Smoother(qp_solver="ipopt")`` (the same convex QP by IPOPT);
* ``polish``: ``Smoother(refine="ipopt")`` (piqp, then IPOPT on the same problem, warm
  started; kept when not worse and certified);
* ``scp``: ``Smoother(kappa_max=1 / (2 r))`` (the QP, then the sequential convex programme);
* ``kappa-ipopt``: ``Smoother(kappa_max=1 / (2 r), curvature_solver="ipopt")`` (the QP, then
  the exact non-convex curvature-bounded NLP by IPOPT, warm started from the QP);
* ``scp-polish``: ``Smoother(kappa_max=1 / (2 r), refine="ipopt")`` (the SCP, then IPOPT on
  the exact problem).

Reported per variant: success rate and corridor kind, and over the queries every variant of
its group (no bound, bound) planned: the median smoothing-stage time, objective value
(``stats["cost"]``, cell units) and trajectory duration; per pair (``ipopt`` and ``polish``
against ``piqp``, ``kappa-ipopt`` and ``scp-polish`` against ``scp``), over the queries both
planned: the trajectory duration ratio (median, smallest, largest, and the share within 3 %),
the median smoothing-stage time of each and their ratio, the same without the one-off IPOPT
builds (a solver is built once per problem shape, then re-solved with parameters), and the
median solver time of each; the polish outcomes (kept, not better, failed).

With ``--costmap-queries N`` (> 0), also N seeded random queries per shared ROS map on its
Nav2-style inflation costmap (``bench_costmap_smoother.nav2_values``, a disc of 0.15 m,
``costmap_weight`` 2), smoothed three ways: ``rounds`` (the default: the QP rounds of the
linearised cost term), ``ipopt-cost`` (``qp_solver="ipopt"``: IPOPT on the exact cost term)
and ``polish`` (the rounds, then ``refine="ipopt"``): success, median smoothing time,
objective (``stats["cost"]`` plus the cost term at the curve, bilinear, as the rounds
measure it), the trajectory's mean cost per metre against its A* path's, and duration.
Each query is planned once per variant after one warm-up plan per map and variant.

Run: ``python benchmarks/bench_ipopt.py [--suite shared-small] [--limit N] [--costmap-queries
N]`` (the shared data: ``$TRAJOPT_DATA`` or ``../shared/data``; skipped with a message when
absent).
"""

from __future__ import annotations

import argparse
import logging
import statistics
import time

import numpy as np

import astar
import trajopt
from trajopt._planner import Planner
from trajopt.analysis.bench._suites import data_dir
from trajopt.errors import TrajoptError
from trajopt.robot._robot import Robot
from trajopt.smoother import Smoother

VARIANTS = ("piqp", "ipopt", "polish", "scp", "kappa-ipopt", "scp-polish")
GROUPS = (("piqp", "ipopt", "polish"), ("scp", "kappa-ipopt", "scp-polish"))
PAIRS = (("ipopt", "piqp"), ("polish", "piqp"), ("kappa-ipopt", "scp"), ("scp-polish", "scp"))
COST_VARIANTS = ("rounds", "ipopt-cost", "polish")
COST_WEIGHT = 2.0


def smoothers(radius: float) -> dict[str, Smoother]:
    """The six smoothers of one robot radius (m)."""
    k = 1.0 / (2.0 * radius)
    return {
        "piqp": Smoother(),
        "ipopt": Smoother(qp_solver="ipopt"),
        "polish": Smoother(refine="ipopt"),
        "scp": Smoother(kappa_max=k),
        "kappa-ipopt": Smoother(kappa_max=k, curvature_solver="ipopt"),
        "scp-polish": Smoother(kappa_max=k, refine="ipopt"),
    }


def plan_one(planner: Planner, p0, p1) -> dict:
    """One plan: its outcome, duration, smoothing-stage and solver times (s)."""
    t0 = time.perf_counter()
    try:
        traj = planner.plan(p0, p1)
    except TrajoptError as exc:
        return {"ok": False, "err": f"{type(exc).__name__}: {exc}"[:200]}
    wall = time.perf_counter() - t0
    sp = getattr(traj.steps, "smooth_path", None)
    st = {} if sp is None else sp.stats
    return {
        "ok": True,
        "duration": float(traj.duration),
        "corridor": traj.stats.get("corridor", ""),
        "smooth_s": float(traj.stats["stages_s"]["smooth"]),
        "build_s": float(st.get("build_time_s", 0.0))
        + float(st.get("refine", {}).get("build_time_s", 0.0)),
        "solve_s": float(st.get("solve_time_s", float("nan"))),
        "wall_s": wall,
        "objective": float(st.get("cost", float("nan"))),
        "refine": st.get("refine", {}).get("status", "") + ("+" if _kept(st) else ""),
    }


def _kept(st: dict) -> bool:
    return bool(st.get("refine", {}).get("kept", False))


def _median(xs) -> float:
    xs = [x for x in xs if np.isfinite(x)]
    return statistics.median(xs) if xs else float("nan")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--suite", choices=("shared-small", "shared-full"), default="shared-small")
    ap.add_argument("--limit", type=int, default=None, help="at most this many queries per map")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument(
        "--costmap-queries", type=int, default=0, help="random queries per ROS costmap (0: none)"
    )
    args = ap.parse_args(argv)
    root = data_dir(None)
    if not (root / "movingai").is_dir() or not (root / "ros").is_dir():
        print(f"skipped: no shared data under {root} (set TRAJOPT_DATA or use ../shared/data)")
        return 0
    logging.getLogger("trajopt").setLevel(logging.ERROR)
    t_all = time.perf_counter()
    rows: list[dict] = []
    mqs = [
        mq
        for mq in trajopt.bench.suite(args.suite, root, limit=args.limit, seed=args.seed)
        if mq.queries
    ]
    for mq in mqs:
        grid = astar.load_map(mq.map_path)
        robot = Robot(radius=mq.radius_m)
        planners = {
            name: Planner(grid, robot, smoother=s) for name, s in smoothers(mq.radius_m).items()
        }
        pairs = [
            (grid.cell_to_world(np.array(q.start)), grid.cell_to_world(np.array(q.goal)))
            for q in mq.queries
        ]
        for p in planners.values():  # warm-up: imports, kernels, first solver builds
            plan_one(p, *pairs[0])
        for i, (p0, p1) in enumerate(pairs):
            row = {"map": mq.map_name, "i": i}
            for name, p in planners.items():
                row[name] = plan_one(p, p0, p1)
            rows.append(row)
    n = len(rows)
    print(f"suite {args.suite}, limit {args.limit}: {n} queries on {len(mqs)} maps")
    print(
        f"{'variant':<13}{'success':>9}{'polygons':>10}{'common':>8}{'smooth ms':>11}"
        f"{'objective':>12}{'duration s':>12}"
    )
    for group in GROUPS:
        common = [r for r in rows if all(r[v]["ok"] for v in group)]
        for v in group:
            ok = [r[v] for r in rows if r[v]["ok"]]
            poly = sum(1 for o in ok if o["corridor"] == "polygons")
            print(
                f"{v:<13}{len(ok) / n:>9.1%}{poly:>10}{len(common):>8}"
                f"{1e3 * _median(r[v]['smooth_s'] for r in common):>11.2f}"
                f"{_median(r[v]['objective'] for r in common):>12.3f}"
                f"{_median(r[v]['duration'] for r in common):>12.3f}"
            )
    print("smooth ms, objective (stats['cost'], cell units), duration: medians over `common`")
    print("outcomes: status of the polish, + when kept")
    for v in ("polish", "scp-polish"):
        counts = {}
        for r in rows:
            if r[v]["ok"]:
                counts[r[v]["refine"]] = counts.get(r[v]["refine"], 0) + 1
        print(f"{v} outcomes: " + ", ".join(f"{k} {c}" for k, c in sorted(counts.items())))
    print()
    print(
        f"{'pair':<20}{'both':>6}{'dur med':>9}{'dur min':>9}{'dur max':>9}{'<=3%':>7}"
        f"{'smooth ms a/b':>16}{'ratio':>8}{'no-build ratio':>16}{'solve ms a/b':>16}"
    )
    for a, b in PAIRS:
        both = [r for r in rows if r[a]["ok"] and r[b]["ok"]]
        if not both:
            print(f"{a + '/' + b:<20}{0:>6}")
            continue
        dr = np.array([r[a]["duration"] / r[b]["duration"] for r in both])
        sa = _median(r[a]["smooth_s"] for r in both)
        sb = _median(r[b]["smooth_s"] for r in both)
        ratio = _median(r[a]["smooth_s"] / r[b]["smooth_s"] for r in both)
        nb_ratio = _median(
            (r[a]["smooth_s"] - r[a]["build_s"]) / max(r[b]["smooth_s"] - r[b]["build_s"], 1e-9)
            for r in both
        )
        va = _median(r[a]["solve_s"] for r in both)
        vb = _median(r[b]["solve_s"] for r in both)
        within = float(np.mean(np.abs(dr - 1.0) <= 0.03))
        print(
            f"{a + '/' + b:<20}{len(both):>6}{np.median(dr):>9.4f}{dr.min():>9.4f}"
            f"{dr.max():>9.4f}{within:>7.0%}{f'{1e3 * sa:.1f}/{1e3 * sb:.1f}':>16}"
            f"{ratio:>8.1f}{nb_ratio:>16.1f}{f'{1e3 * va:.1f}/{1e3 * vb:.1f}':>16}"
        )
    print("ratios: per query a/b, then the median; no-build: less the one-off IPOPT builds")
    fails = [(r, v) for r in rows for v in VARIANTS if not r[v]["ok"]]
    if fails:
        print()
        for r, v in fails:
            print(f"{v} {r['map']} #{r['i']}: {r[v]['err']}")
    if args.costmap_queries > 0:
        print()
        costmap_section(root, args.costmap_queries, args.seed)
    print(f"\nwall time {time.perf_counter() - t_all:.0f} s")
    return 0


def costmap_section(root, queries: int, seed: int) -> None:
    """The cost term by the QP rounds, by IPOPT, and the rounds polished by IPOPT."""
    from bench_costmap_smoother import R_INS, nav2_values, path_costs

    rng = np.random.default_rng(seed)
    robot = Robot(radius=R_INS)
    smo = {
        "rounds": Smoother(),
        "ipopt-cost": Smoother(qp_solver="ipopt"),
        "polish": Smoother(refine="ipopt"),
    }
    rows = []
    maps = sorted((root / "ros").glob("*.yaml"))
    for path in maps:
        grid = astar.load_map(path)
        values = nav2_values(~grid.free, grid.resolution)
        cm = astar.from_costmap(values, grid.resolution, grid.origin, convention="costmap_2d")
        planners = {
            v: Planner(cm, robot, costmap_weight=COST_WEIGHT, smoother=s) for v, s in smo.items()
        }
        free = np.argwhere(cm.cost < 0.5)
        pairs = []
        while len(pairs) < queries:
            i, j = rng.integers(len(free), size=2)
            p0 = grid.cell_to_world(free[i][::-1].copy())
            p1 = grid.cell_to_world(free[j][::-1].copy())
            if np.linalg.norm(p1 - p0) >= 2.0:
                pairs.append((p0, p1))
        for p in planners.values():  # warm-up
            _cost_plan(p, cm, *pairs[0], path_costs)
        for p0, p1 in pairs:
            rows.append({v: _cost_plan(p, cm, p0, p1, path_costs) for v, p in planners.items()})
    n = len(rows)
    common = [r for r in rows if all(r[v]["ok"] for v in COST_VARIANTS)]
    print(
        f"costmaps: {len(maps)} ROS maps, {queries} queries each (seed {seed}), weight "
        f"{COST_WEIGHT:g}; {len(common)} of {n} planned by every variant"
    )
    print(
        f"{'variant':<12}{'success':>9}{'smooth ms':>11}{'no-build':>10}{'objective':>12}"
        f"{'obj/rounds':>12}{'cost/A*':>9}{'duration s':>12}{'dur/rounds':>12}"
    )
    for v in COST_VARIANTS:
        ok = sum(1 for r in rows if r[v]["ok"])
        rel = _median(r[v]["objective"] / r["rounds"]["objective"] for r in common)
        dur = _median(r[v]["duration"] / r["rounds"]["duration"] for r in common)
        print(
            f"{v:<12}{ok / max(n, 1):>9.1%}"
            f"{1e3 * _median(r[v]['smooth_s'] for r in common):>11.2f}"
            f"{1e3 * _median(r[v]['smooth_s'] - r[v]['build_s'] for r in common):>10.2f}"
            f"{_median(r[v]['objective'] for r in common):>12.3f}{rel:>12.5f}"
            f"{_median(r[v]['traj'] / max(r[v]['astar'], 1e-9) for r in common):>9.3f}"
            f"{_median(r[v]['duration'] for r in common):>12.3f}{dur:>12.5f}"
        )
    counts = {}
    for r in rows:
        if r["polish"]["ok"]:
            counts[r["polish"]["refine"]] = counts.get(r["polish"]["refine"], 0) + 1
    print("polish outcomes: " + ", ".join(f"{k} {c}" for k, c in sorted(counts.items())))
    print(
        "medians over the common queries; no-build: less the one-off IPOPT builds; objective: "
        "stats['cost'] + the cost term (bilinear) at the curve, cell units; cost/A*: mean cost "
        "per metre, trajectory / A* path"
    )
    for r in rows:
        for v in COST_VARIANTS:
            if not r[v]["ok"]:
                print(f"{v}: {r[v]['err']}")


def _cost_plan(planner: Planner, cm, p0, p1, path_costs) -> dict:
    """One costmap query: objective, mean costs of trajectory and A* path, duration, time."""
    try:
        traj = planner.plan(p0, p1)
    except TrajoptError as exc:
        return {"ok": False, "err": f"{type(exc).__name__}: {exc}"[:200]}
    costs = path_costs(traj, cm)
    if costs is None:
        return {"ok": False, "err": "no smooth path (fallback)"}
    sp = traj.steps.smooth_path
    st = sp.stats
    term = st.get("cost_rounds", {}).get("cost_term", 0.0)
    return {
        "ok": True,
        "objective": float(st["cost"]) + float(term),
        "traj": costs[0],
        "astar": costs[1],
        "duration": float(traj.duration),
        "smooth_s": float(traj.stats["stages_s"]["smooth"]),
        "build_s": float(st.get("build_time_s", 0.0))
        + float(st.get("refine", {}).get("build_time_s", 0.0)),
        "refine": st.get("refine", {}).get("status", "") + ("+" if _kept(st) else ""),
    }


if __name__ == "__main__":
    raise SystemExit(main())
