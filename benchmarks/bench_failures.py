"""Failures at scale: the default and the curvature-bounded planner on many feasible queries.

Plans every query of two sets with ``Planner(grid, Robot(radius=r))`` (``default``) and with
``Smoother(kappa_max=1 / (2 r))`` (``kappa``), and counts the failures by type and message:

* ``shared-full``: the named benchmark suite (:func:`trajopt.analysis.bench._suites.suite`): the
  feasible scenarios of the shared Moving AI maps (radius 2.5 cells) and seeded random
  queries on the shared ROS maps (radius 0.165 m), at most ``--limit`` per map;
* ``random``: seeded random start/goal pairs (both ends free for the robot and connected,
  :func:`trajopt.analysis.bench._suites.random_queries`) on the shared Moving AI maps at several radii
  (``--radii``, in cells): small rooms, one-robot-wide passages and diagonal streets, where
  the rare failures live.

Every failure of ``kappa`` is handed to :func:`trajopt.planning._feasibility.curvature_witness` (20 s,
2 M expansions): with a witness the query is feasible for the bound and the failure counts
against the planner; without one it is counted apart (probably infeasible: a pocket behind a
passage narrower than the turning radius). Reported per set and variant: queries, failures,
the success rate (``kappa``: also over witnessed-feasible queries), the median and maximum
wall time of a failing query (warm process), and each failure's message.

Run: ``python benchmarks/bench_failures.py [--limit 400] [--random 250] [--radii 1.5,2.5,3.5]``
(``TRAJOPT_DATA`` may point to the shared data; the full settings take about 30 min on one
core).
"""

from __future__ import annotations

import argparse
import collections
import statistics
import time

import numpy as np

import astar
from trajopt._planner import Planner
from trajopt.analysis.bench._suites import data_dir, random_queries, suite
from trajopt.errors import TrajoptError
from trajopt.planning._feasibility import curvature_witness
from trajopt.robot._robot import Robot
from trajopt.smoother import Smoother

MAPS = ("den312d", "rmtst01", "AR0046SR", "Berlin_0_256", "arena")


def planners(grid, radius: float) -> dict[str, Planner]:
    robot = Robot(radius=radius)
    return {
        "default": Planner(grid, robot),
        "kappa": Planner(grid, robot, smoother=Smoother(kappa_max=1.0 / (2.0 * radius))),
    }


def run_queries(grid, radius: float, pairs, rows: list, label: str) -> None:
    ps = planners(grid, radius)
    for s, g in pairs:
        for name, p in ps.items():
            t0 = time.perf_counter()
            err = ""
            try:
                p.plan(s, g)
            except TrajoptError as exc:
                err = f"{type(exc).__name__}: {exc}"
            rows.append(
                dict(
                    set=label,
                    variant=name,
                    grid=grid,
                    radius=radius,
                    start=s,
                    goal=g,
                    err=err,
                    t=time.perf_counter() - t0,
                )
            )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--limit", type=int, default=400, help="shared-full queries per map")
    ap.add_argument("--random", type=int, default=250, help="random queries per map and radius")
    ap.add_argument("--radii", default="1.5,2.5,3.5", help="radii of the random set (cells)")
    ap.add_argument("--seed", type=int, default=7)
    args = ap.parse_args()
    root = data_dir(None)
    rows: list[dict] = []
    t_all = time.perf_counter()
    for mq in suite("shared-full", limit=args.limit):
        grid = astar.load_map(mq.map_path)
        cells = [
            (grid.cell_to_world(np.array(q.start)), grid.cell_to_world(np.array(q.goal)))
            for q in mq.queries
        ]
        run_queries(grid, mq.radius_m, cells, rows, "shared-full")
    for r_cells in (float(v) for v in args.radii.split(",")):
        for name in MAPS:
            path = root / "movingai" / "maps" / f"{name}.map"
            grid = astar.load_map(path)
            r = r_cells * grid.resolution
            try:
                mq = random_queries(path, args.random, seed=args.seed, radius_m=r)
            except TrajoptError:  # no room for this radius on this map
                continue
            cells = [
                (grid.cell_to_world(np.array(q.start)), grid.cell_to_world(np.array(q.goal)))
                for q in mq.queries
            ]
            run_queries(grid, r, cells, rows, f"random r={r_cells:g} cells")
    # witness every curvature-bounded failure
    for row in rows:
        row["witness"] = None
        if row["err"] and row["variant"] == "kappa":
            w = curvature_witness(
                row["grid"],
                row["radius"],
                row["start"],
                row["goal"],
                1.0 / (2.0 * row["radius"]),
                time_limit_s=20.0,
                max_expansions=2_000_000,
            )
            row["witness"] = w is not None
    groups: dict[tuple[str, str], list[dict]] = collections.defaultdict(list)
    for row in rows:
        groups[(row["set"], row["variant"])].append(row)
    print(
        f"{'set':<24}{'variant':<9}{'queries':>8}{'failed':>8}{'success':>9}"
        f"{'feasible*':>10}{'fail median s':>14}{'fail max s':>11}"
    )
    for (label, variant), rs in groups.items():
        fails = [r for r in rs if r["err"]]
        witnessed = [r for r in fails if r["witness"]]
        ok = len(rs) - len(fails)
        feas = ok / (ok + len(witnessed)) if variant == "kappa" and ok + len(witnessed) else None
        ts = [r["t"] for r in fails]
        print(
            f"{label:<24}{variant:<9}{len(rs):>8}{len(fails):>8}{ok / len(rs):>9.2%}"
            f"{'' if feas is None else f'{feas:.2%}':>10}"
            f"{statistics.median(ts) if ts else float('nan'):>14.2f}"
            f"{max(ts) if ts else float('nan'):>11.2f}"
        )
    print("* kappa: successes / (successes + failures on queries with a curvature witness)")
    print()
    for row in rows:
        if row["err"]:
            tag = {None: "", True: " [witness found]", False: " [no witness]"}[row["witness"]]
            print(
                f"{row['set']} {row['variant']} r={row['radius']:g} "
                f"{np.round(row['start'], 2).tolist()} -> {np.round(row['goal'], 2).tolist()}"
                f" ({row['t']:.2f} s){tag}: {row['err'][:220]}"
            )
    print(f"\nwall time {time.perf_counter() - t_all:.0f} s")


if __name__ == "__main__":
    main()
