"""IPOPT against piqp (and the SCP) in the default polygon corridor, on the same queries.

Plans every query of a named suite of the shared maps (``trajopt.bench.suite``) four ways,
in the same run and the same process:

* ``piqp``: the default planner (the corridor QP by piqp);
* ``ipopt``: ``Smoother(qp_solver="ipopt")`` (the same convex QP by IPOPT);
* ``scp``: ``Smoother(kappa_max=1 / (2 r))`` (the QP, then the sequential convex programme);
* ``kappa-ipopt``: ``Smoother(kappa_max=1 / (2 r), curvature_solver="ipopt")`` (the QP, then
  the exact non-convex curvature-bounded NLP by IPOPT, warm started from the QP).

Reported per variant: success rate and corridor kind; per pair (``ipopt`` against ``piqp``,
``kappa-ipopt`` against ``scp``), over the queries both planned: the trajectory duration ratio
(median, smallest, largest, and the share within 3 %), the median smoothing-stage time of
each and their ratio, the same without the one-off IPOPT builds (a solver is built once per
problem shape, then re-solved with parameters), and the median solver time of each. Each
query is planned once per variant after one warm-up plan per map and variant.

Run: ``python benchmarks/bench_ipopt.py [--suite shared-small] [--limit N]`` (the shared
data: ``$TRAJOPT_DATA`` or ``../shared/data``; skipped with a message when absent).
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

VARIANTS = ("piqp", "ipopt", "scp", "kappa-ipopt")
PAIRS = (("ipopt", "piqp"), ("kappa-ipopt", "scp"))


def smoothers(radius: float) -> dict[str, Smoother]:
    """The four smoothers of one robot radius (m)."""
    k = 1.0 / (2.0 * radius)
    return {
        "piqp": Smoother(),
        "ipopt": Smoother(qp_solver="ipopt"),
        "scp": Smoother(kappa_max=k),
        "kappa-ipopt": Smoother(kappa_max=k, curvature_solver="ipopt"),
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
        "build_s": float(st.get("build_time_s", 0.0)),
        "solve_s": float(st.get("solve_time_s", float("nan"))),
        "wall_s": wall,
    }


def _median(xs) -> float:
    xs = [x for x in xs if np.isfinite(x)]
    return statistics.median(xs) if xs else float("nan")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--suite", choices=("shared-small", "shared-full"), default="shared-small")
    ap.add_argument("--limit", type=int, default=None, help="at most this many queries per map")
    ap.add_argument("--seed", type=int, default=0)
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
    print(f"{'variant':<13}{'success':>9}{'polygons':>10}{'median smooth ms':>18}")
    for v in VARIANTS:
        ok = [r[v] for r in rows if r[v]["ok"]]
        poly = sum(1 for o in ok if o["corridor"] == "polygons")
        print(
            f"{v:<13}{len(ok) / n:>9.1%}{poly:>10}{1e3 * _median(o['smooth_s'] for o in ok):>18.2f}"
        )
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
    print(f"\nwall time {time.perf_counter() - t_all:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
