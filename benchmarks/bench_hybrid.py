"""Hybrid-A* pose-to-pose search (astar.find_pose_path) against OMPL's Reeds-Shepp/Dubins planners.

Queries: the shared suite (``trajopt.analysis.bench`` ``shared-full``: the feasible Moving AI
scenarios at robot radius 2.5 cells and seeded random pairs on the ROS maps at 0.165 m; at most
``--limit`` per map), each with seeded random start and goal headings (uniform in
``[-pi, pi)``, ``numpy.random.default_rng([seed, crc32(map name), query index])``); turning
radius ``R = 2 x robot radius``; the search runs on the map inflated by the radius (as the
suite, ``astar.inflate(..., metric="square", outside_occupied=True)``), poses at the cell
centres.

Per query and mode (``reverse``: Reeds-Shepp, forwards and backwards; ``forward``: Dubins):

* **hybrid**: ``astar.find_pose_path(free, start, goal, turning_radius=R, reverse=...,
  time_budget=--budget)``: success, search time (``stats["search_s"]``; the 2-D heuristic's
  Dijkstra ``stats["heuristic_s"]`` is reported apart) and total time, cusps, backwards
  length, length (cells). Every path is checked independently: its pieces re-integrated
  (exact chords every 0.05 cells) against the inflated grid (collisions), its curvature
  against ``1/R``, its end pose against the goal;
* **ompl**: OMPL's ``RRTstar`` in ``ReedsSheppStateSpace(R)`` / ``DubinsStateSpace(R)`` with
  a state validity checker on the same inflated grid (cell of the state's centre free; motion
  checked every 0.2 cells), stopped at its first exact solution (cost threshold infinite) or
  at ``--ompl-time`` seconds, then ``simplifySolution``: success, time to the first solution,
  cusps and backwards length of the simplified path (interpolated every 0.1 cells).

Reported per mode: success rates, hybrid success among the queries OMPL solved (target of
issue 36: >= 98 %), median and 95th percentile times, median cusps and backwards length
(over the queries both solved), independent-check violations.

Run: ``python benchmarks/bench_hybrid.py [--limit 6] [--seed 0] [--budget 1.0]
[--ompl-time 1.0] [--no-ompl]``. Needs the shared data (``$TRAJOPT_DATA`` or
``../shared/data``; skipped with a message when absent) and, for the OMPL columns, the
``ompl`` wheel (skipped with a message when not importable).
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
import zlib
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import astar  # noqa: E402
from astar.hybrid import NoPosePathError  # noqa: E402


def _pct(values: list[float], q: float) -> float:
    return float(np.percentile(values, q)) if values else math.nan


def check_path(
    p: astar.PosePath, free: np.ndarray, goal: tuple, radius: float
) -> tuple[int, int, float]:
    """Independent check: (colliding samples, curvature violations, end pose error)."""
    ny, nx = free.shape
    pts = []
    x = y = th = 0.0
    for px, py, pth, k, s in p.pieces:
        m = max(1, math.ceil(abs(s) / 0.05))
        ds = s / m
        chord = ds if k == 0 else 2.0 * math.sin(0.5 * k * ds) / k
        i = np.arange(m)
        thm = pth + (i + 0.5) * k * ds
        xs = px + np.cumsum(chord * np.cos(thm))
        ys = py + np.cumsum(chord * np.sin(thm))
        pts.append(np.column_stack([xs, ys]))
        x, y, th = xs[-1], ys[-1], pth + k * s
    if not pts:
        return 0, 0, 0.0
    q = np.concatenate(pts)
    ix = np.floor(q[:, 0] + 0.5).astype(int)
    iy = np.floor(q[:, 1] + 0.5).astype(int)
    inside = (ix >= 0) & (ix < nx) & (iy >= 0) & (iy < ny)
    ok = inside.copy()
    ok[inside] = free[iy[inside], ix[inside]]
    curv = int(np.count_nonzero(np.abs(p.pieces[:, 3]) > 1.0 / radius * (1 + 1e-12)))
    dth = (th - goal[2] + math.pi) % (2 * math.pi) - math.pi
    return int(np.count_nonzero(~ok)), curv, math.hypot(x - goal[0], y - goal[1]) + abs(dth)


class Ompl:
    """OMPL's RRT* in a Reeds-Shepp or Dubins space on one inflated grid."""

    def __init__(self, free: np.ndarray, radius: float, reverse: bool, time_limit: float) -> None:
        from ompl import base as ob
        from ompl import geometric as og
        from ompl import util as ou

        ou.setLogLevel(ou.LogLevel.LOG_NONE)
        self.ob, self.og = ob, og
        self.free = free
        ny, nx = free.shape
        self.space = ob.ReedsSheppStateSpace(radius) if reverse else ob.DubinsStateSpace(radius)
        b = ob.RealVectorBounds(2)
        b.setLow(0, -0.5)
        b.setHigh(0, nx - 0.5)
        b.setLow(1, -0.5)
        b.setHigh(1, ny - 0.5)
        self.space.setBounds(b)
        self.time_limit = time_limit
        self.reverse = reverse
        self.nx, self.ny = nx, ny

    def valid(self, s) -> bool:
        ix = math.floor(s.getX() + 0.5)
        iy = math.floor(s.getY() + 0.5)
        return 0 <= ix < self.nx and 0 <= iy < self.ny and bool(self.free[iy, ix])

    def solve(self, start: tuple, goal: tuple) -> dict:
        ob, og = self.ob, self.og
        ss = og.SimpleSetup(self.space)
        ss.setStateValidityChecker(self.valid)
        si = ss.getSpaceInformation()
        si.setStateValidityCheckingResolution(0.2 / self.space.getMaximumExtent())
        a = self.space.allocState()
        g = self.space.allocState()
        for st, v in ((a, start), (g, goal)):
            st.setX(float(v[0]))
            st.setY(float(v[1]))
            st.setYaw(float(v[2]))
        ss.setStartAndGoalStates(a, g, 1e-6)
        obj = ob.PathLengthOptimizationObjective(si)
        obj.setCostThreshold(ob.Cost(math.inf))  # stop at the first solution
        ss.setOptimizationObjective(obj)
        ss.setPlanner(og.RRTstar(si))
        t = time.perf_counter()
        ss.solve(self.time_limit)
        dt = time.perf_counter() - t
        if not ss.haveExactSolutionPath():
            return {"ok": False, "time": dt}
        ss.simplifySolution(0.2)
        path = ss.getSolutionPath()
        length = path.length()
        path.interpolate(max(2, int(length / 0.1)))
        xy = np.array(
            [
                [path.getState(i).getX(), path.getState(i).getY()]
                for i in range(path.getStateCount())
            ]
        )
        yaw = np.array([path.getState(i).getYaw() for i in range(path.getStateCount())])
        d = np.diff(xy, axis=0)
        along = d[:, 0] * np.cos(yaw[:-1]) + d[:, 1] * np.sin(yaw[:-1])
        sig = np.sign(along[np.abs(along) > 1e-9])
        cusps = int(np.count_nonzero(sig[1:] != sig[:-1]))
        back = float(-along[along < 0].sum())
        return {"ok": True, "time": dt, "cusps": cusps, "reverse_length": back, "length": length}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--limit", type=int, default=6, help="queries per map")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--budget", type=float, default=1.0, help="hybrid time budget (s)")
    ap.add_argument("--ompl-time", type=float, default=1.0, help="OMPL time limit (s)")
    ap.add_argument("--no-ompl", action="store_true")
    ap.add_argument("--suite", default="shared-full")
    args = ap.parse_args()

    from trajopt.analysis.bench._suites import data_dir, suite
    from trajopt.errors import BenchmarkError

    try:
        maps = suite(args.suite, limit=args.limit, seed=args.seed)
    except BenchmarkError as e:
        print(
            f"skipped: shared data not available ({e}); set TRAJOPT_DATA (looked in {data_dir()})"
        )
        return 0
    have_ompl = not args.no_ompl
    if have_ompl:
        try:
            import ompl.base  # noqa: F401
        except ImportError as e:
            print(f"OMPL columns skipped: ompl not importable ({e}); pip install ompl")
            have_ompl = False

    # warm-up: load the compiled kernels
    warm = np.ones((20, 20), bool)
    astar.find_pose_path(warm, (5, 5, 0), (12, 12, 1), turning_radius=2.0)
    astar.find_pose_path(warm, (5, 5, 0), (12, 12, 1), turning_radius=2.0, reverse=False)

    rows = {m: [] for m in ("reverse", "forward")}
    for mq in maps:
        grid = astar.load_map(mq.map_path)
        infl = astar.inflate(grid, mq.radius_m, metric="square", outside_occupied=True)
        free = ~np.asarray(infl.occupied)
        radius = 2.0 * mq.radius_m / mq.resolution_m  # cells
        planners = {}
        if have_ompl:
            planners = {m: Ompl(free, radius, m == "reverse", args.ompl_time) for m in rows}
        for q in mq.queries:
            rng = np.random.default_rng([args.seed, zlib.crc32(mq.map_name.encode()), q.index])
            h0, h1 = rng.uniform(-math.pi, math.pi, 2)
            start = (float(q.start[0]), float(q.start[1]), float(h0))
            goal = (float(q.goal[0]), float(q.goal[1]), float(h1))
            for mode in rows:
                row = {"map": mq.map_name, "id": q.query_id, "cells": free.size}
                try:
                    p = astar.find_pose_path(
                        free,
                        start,
                        goal,
                        turning_radius=radius,
                        reverse=mode == "reverse",
                        time_budget=args.budget,
                    )
                    col, curv, end = check_path(p, free, goal, radius)
                    row.update(
                        ok=True,
                        search=p.stats["search_s"],
                        heur=p.stats["heuristic_s"],
                        total=p.stats["total_s"],
                        cusps=p.cusps,
                        back=p.reverse_length,
                        length=p.length,
                        collisions=col,
                        curv=curv,
                        end=end,
                        expanded=p.stats["expanded"],
                    )
                except NoPosePathError as e:
                    row.update(
                        ok=False,
                        reason=e.reason,
                        search=e.stats["search_s"],
                        heur=e.stats["heuristic_s"],
                        total=e.stats["total_s"],
                    )
                if have_ompl:
                    row["ompl"] = planners[mode].solve(start, goal)
                rows[mode].append(row)
        print(f"  {mq.map_name}: {len(mq.queries)} queries, R = {radius:.2f} cells", flush=True)

    print(
        f"\nbench_hybrid: {args.suite}, limit {args.limit}/map, seed {args.seed}, "
        f"hybrid budget {args.budget} s, OMPL RRT* first solution within {args.ompl_time} s"
    )
    for mode, rs in rows.items():
        n = len(rs)
        ok = [r for r in rs if r["ok"]]
        print(
            f"\n[{mode}] {n} queries ({'Reeds-Shepp' if mode == 'reverse' else 'Dubins, forwards only'})"
        )
        print(f"  hybrid success        {len(ok)}/{n} = {100 * len(ok) / max(n, 1):.1f} %")
        reasons: dict[str, int] = {}
        for r in rs:
            if not r["ok"]:
                reasons[r["reason"]] = reasons.get(r["reason"], 0) + 1
        if reasons:
            print(f"  hybrid failures       {reasons}")
        st = [1e3 * r["search"] for r in ok]
        tt = [1e3 * r["total"] for r in ok]
        ht = [1e3 * r["heur"] for r in ok]
        print(f"  hybrid search ms      median {_pct(st, 50):.1f}  p95 {_pct(st, 95):.1f}")
        print(
            f"  hybrid 2-D heuristic  median {_pct(ht, 50):.1f} ms; total median {_pct(tt, 50):.1f}  p95 {_pct(tt, 95):.1f} ms"
        )
        small = [1e3 * r["total"] for r in ok if r["cells"] <= 70_000]
        print(
            f"  hybrid total, maps <= 256x256: median {_pct(small, 50):.1f} ms ({len(small)} queries)"
        )
        print(
            f"  checks: collisions {sum(r['collisions'] > 0 for r in ok)}, curvature > 1/R "
            f"{sum(r['curv'] for r in ok)}, max end error {max([r['end'] for r in ok], default=0):.1e}"
        )
        if have_ompl:
            oks = [r for r in rs if r["ompl"]["ok"]]
            both = [r for r in oks if r["ok"]]
            ot = [1e3 * r["ompl"]["time"] for r in oks]
            print(f"  ompl success          {len(oks)}/{n} = {100 * len(oks) / max(n, 1):.1f} %")
            print(
                f"  hybrid | ompl solved  {len(both)}/{len(oks)} = {100 * len(both) / max(len(oks), 1):.1f} %"
            )
            print(f"  ompl first solution   median {_pct(ot, 50):.1f}  p95 {_pct(ot, 95):.1f} ms")
            if both:
                hc = [r["cusps"] for r in both]
                oc = [r["ompl"]["cusps"] for r in both]
                hb = [r["back"] for r in both]
                obk = [r["ompl"]["reverse_length"] for r in both]
                hl = [r["length"] for r in both]
                ol = [r["ompl"]["length"] for r in both]
                print(f"  on {len(both)} queries both solved:")
                print(
                    f"    cusps        hybrid mean {statistics.mean(hc):.2f} median {statistics.median(hc):g}"
                    f" | ompl mean {statistics.mean(oc):.2f} median {statistics.median(oc):g}"
                )
                print(
                    f"    backwards    hybrid mean {statistics.mean(hb):.1f} | ompl mean {statistics.mean(obk):.1f} cells"
                )
                print(
                    f"    length       hybrid median {statistics.median(hl):.1f} | ompl median {statistics.median(ol):.1f} cells"
                    f" (ratio median {statistics.median([a / b for a, b in zip(hl, ol, strict=True)]):.3f})"
                )
            only_h = sum(1 for r in rs if r["ok"] and not r["ompl"]["ok"])
            print(f"  hybrid solved, ompl did not: {only_h}")
        else:
            hc = [r["cusps"] for r in ok]
            if hc:
                print(
                    f"  cusps mean {statistics.mean(hc):.2f}, backwards mean {statistics.mean([r['back'] for r in ok]):.1f} cells"
                )
    return 0


if __name__ == "__main__":
    sys.exit(main())
