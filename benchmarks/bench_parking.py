"""Parking (issue 45): trajopt's car planner vs OMPL's Reeds-Shepp BIT* on a seeded suite.

Cases: :mod:`parking_cases` (parallel slots 1.2-1.6 car lengths, perpendicular and angled
bays 1.15-1.4 car widths, aisles 4-7 m scaled by the car, parked cars and kerbs as
polygons, starts in the aisle with random headings, forwards and backwards entry), for the
full-size car (4.69 x 1.94 m, R = 3.0 m) or the small delivery car (0.9 x 0.5 m,
R = 0.6 m); the grid is ``astar.OccupancyGrid.from_polygons`` at ``--resolution``.

Methods, in the same process, case by case:

* ``trajopt``: ``trajopt.plan(grid, start_xy, goal_xy, robot, start_heading=...,
  goal_heading=...)`` with ``Robot.rectangle(..., rear_offset, drive=Ackermann(R,
  wheelbase, steer_rate_max))``, timed (wall clock, warm: one plan on the first case runs
  before the timed ones);
* ``ompl``: OMPL's BIT* (``--ompl-planner rrtstar`` for RRT*) in ``ReedsSheppStateSpace(R)``
  over the map's bounds, a state valid when the body at it is clear of the polygons (the
  exact test below, compiled: about 1 us a call), motions checked every 2 cm (scaled) of
  state-space distance (the rear axle's travel; a corner moves up to ``1 + r_c / R`` times
  as far), optimising path length for ``--ompl-time`` seconds, then ``simplifySolution``
  (0.2 s at most), each case in a forked process of its own (a crash inside OMPL is
  recorded as that case's failure, ``crashed``). Its time is the whole budget. On the first
  12 full-size cases at 1.5 s, BIT* found 6 and RRT* 4.

Both answers get the same independent check (:func:`parking_cases.check_trajectory` /
``check_poses``): the body polygon (rear-axle reference, oriented by the pose's heading)
against the obstacle polygons, exact intersection, at poses so dense that no body corner
moves more than 1 cm between consecutive ones; ``overlaps`` counts the poses that touch
or overlap a polygon. Cusps: changes of the direction of travel (trajopt: its chain's
``stats["car"]["cusps"]``; OMPL: from the signs of the dense path's steps along the
heading).

Printed per category and entry: planned %, plans with overlaps (overlapping poses), median
and p95 plan time, cusps per plan (trajopt vs OMPL), OMPL's planned % and overlaps, and
trajopt's failure reasons (error type and the first words of the message).

Run: ``python benchmarks/bench_parking.py [--limit 40] [--resolution 0.1] [--car full|small]
[--seed 0] [--ompl-time 1.5] [--ompl-planner bitstar|rrtstar] [--no-ompl] [--out rows.csv|rows.parquet]
[--cases 3,17,full-parallel-forwards-1] [--feasibility compute|FILE.json]`` (``--cases``: a
subset of the suite to iterate on).

``--feasibility``: each case's verdict of :mod:`parking_feasibility` (feasible, infeasible or
unknown, from the connectivity of the car's free configuration space), either computed in
the run (``compute``: 5-20 s a case) or read from a file its CLI wrote (``--json``; the
suite's are ``benchmarks/parking_feasibility_full.json`` and ``..._small.json``, for seed 0;
a file whose start, goal or size of a case differs from the suite's is refused). The report
then ends with trajopt's planned rate over all cases and over the cases proven feasible.
"""

from __future__ import annotations

import argparse
import math
import re
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import parking_cases as pc  # noqa: E402


def failure_reason(kind: str, note: str, words: int = 6) -> str:
    """A short class of a failure: the error type and what its message says first.

    The search's refusals are told apart by their tag (``(time_budget)``, ``(exhausted)``,
    ...), an end pose refused on the grid by "meets the occupied cell", a segment without a
    certified curve by its direction; anything else is the type and the message's first
    ``words`` words, numbers replaced by ``#``.
    """
    head = note.split(" (tries:")[0]
    if kind == "NoPathError":
        tag = re.search(r"\((time_budget|exhausted|max_expansions|disconnected)\)", head)
        if tag:
            return f"NoPathError: the search ran out ({tag.group(1)})"
    if kind == "InvalidInputError" and "meets the occupied cell" in head:
        end = "goal" if head.startswith("goal") else "start"
        return (
            f"InvalidInputError: {end} pose refused, its footprint + margin + sampling "
            "slack meets a grid cell"
        )
    if kind == "InvalidInputError" and "footprint meets an obstacle" in head:
        end = "goal" if head.startswith("goal") else "start"
        return f"InvalidInputError: {end} pose refused, its footprint meets a grid cell"
    if kind == "SmoothingError" and "segment" in head:
        seg = "backwards" if "backwards segment" in head else "forwards"
        return f"SmoothingError: no certified curve for a {seg} segment"
    text = re.sub(r"[-+]?\d[\d.e+-]*", "#", head.replace("\n", " "))
    return f"{kind}: " + " ".join(text.split()[:words])


def end_blocked_on_first_grid(note: str) -> bool:
    """Whether a failure's tries say an end pose was refused on the first search grid."""
    return "meets the occupied cell" in note


def run_trajopt(case: pc.ParkingCase, grid, robot) -> dict:
    """Plan one case with trajopt and check it exactly (a row of the dataset)."""
    import trajopt

    row: dict = {"method": "trajopt"}
    t0 = time.perf_counter()
    try:
        traj = trajopt.plan(
            grid,
            case.start[:2],
            case.goal[:2],
            robot,
            start_heading=case.start[2],
            goal_heading=case.goal[2],
        )
    except Exception as exc:  # noqa: BLE001 - every failure is a row
        row.update(
            ok=False,
            runtime_s=time.perf_counter() - t0,
            failure=type(exc).__name__,
            note=str(exc)[:4000],
        )
        return row
    row["runtime_s"] = time.perf_counter() - t0
    check = pc.check_trajectory(traj, case.car.body(), case.polygons)
    row.update(
        ok=True,
        failure="",
        note="",
        overlaps=check.overlaps,
        min_clearance_m=check.min_clearance,
        checked_poses=check.poses,
        cusps=int(traj.stats["car"]["cusps"]),
        duration_s=float(traj.duration),
        length_m=float(sum(p.length for p in traj.pieces)),
    )
    return row


def run_ompl(case: pc.ParkingCase, time_limit: float, seed: int, planner: str = "rrtstar") -> dict:
    """Plan one case with OMPL (BIT* or RRT*) in a Reeds-Shepp space, then the same exact check."""
    from ompl import base as ob
    from ompl import geometric as og
    from ompl import util as ou

    ou.setLogLevel(ou.LOG_NONE)
    ou.RNG.setSeed(seed)
    car = case.car
    body = car.body()
    polys = case.polygons
    row: dict = {"method": "ompl"}
    space = ob.ReedsSheppStateSpace(car.turning_radius)
    xmin, ymin, xmax, ymax = case.bounds
    b = ob.RealVectorBounds(2)
    b.setLow(0, xmin)
    b.setHigh(0, xmax)
    b.setLow(1, ymin)
    b.setHigh(1, ymax)
    space.setBounds(b)
    ss = og.SimpleSetup(space)

    clear = pc.PoseChecker(body, polys)

    def valid(state) -> bool:
        return clear(state.getX(), state.getY(), state.getYaw())

    ss.setStateValidityChecker(valid)
    si = ss.getSpaceInformation()
    si.setStateValidityCheckingResolution(0.02 * car.scale / space.getMaximumExtent())
    a, g = space.allocState(), space.allocState()
    for st, p in ((a, case.start), (g, case.goal)):
        st.setX(p[0])
        st.setY(p[1])
        st.setYaw(p[2])
    ss.setStartAndGoalStates(a, g, 1e-3)
    ss.setOptimizationObjective(ob.PathLengthOptimizationObjective(si))
    ss.setPlanner({"rrtstar": og.RRTstar, "bitstar": og.BITstar}[planner](si))
    t0 = time.perf_counter()
    ss.solve(time_limit)
    if not ss.haveExactSolutionPath():
        row.update(
            ok=False,
            runtime_s=time.perf_counter() - t0,
            failure="NoSolution",
            note=f"{planner} (Reeds-Shepp): no exact solution in {time_limit} s",
        )
        return row
    ss.simplifySolution(0.2)
    row["runtime_s"] = time.perf_counter() - t0
    path = ss.getSolutionPath()
    # corners move at most (1 + r_c / R) per unit of path length: 8 mm steps, then verified
    rc = float(np.max(np.hypot(body[:, 0], body[:, 1])))
    n = max(2, math.ceil(path.length() * (1.0 + rc / car.turning_radius) / 0.008) + 1)
    path.interpolate(n)
    m = path.getStateCount()
    poses = np.array(
        [
            [path.getState(i).getX(), path.getState(i).getY(), path.getState(i).getYaw()]
            for i in range(m)
        ]
    )
    poses[:, 2] = np.unwrap(poses[:, 2])
    check = pc.check_poses(body, poses, polys)
    row.update(
        ok=True,
        failure="",
        note="",
        overlaps=check.overlaps,
        min_clearance_m=check.min_clearance,
        checked_poses=check.poses,
        max_corner_step_m=check.max_corner_step,
        cusps=pc.count_cusps(poses),
        length_m=float(path.length()),
    )
    return row


def _ompl_child(conn, case, time_limit: float, seed: int, planner: str) -> None:
    conn.send(run_ompl(case, time_limit, seed, planner))
    conn.close()


def run_ompl_isolated(case: pc.ParkingCase, time_limit: float, seed: int, planner: str) -> dict:
    """:func:`run_ompl` in a forked process, so that a crash inside OMPL costs one case.

    Long runs of OMPL's Python bindings in one process have ended in a segmentation fault;
    here such a case is recorded as ``failure="crashed"`` (with the exit code) and the run
    goes on.
    """
    import multiprocessing

    ctx = multiprocessing.get_context("fork")
    recv, send = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_ompl_child, args=(send, case, time_limit, seed, planner))
    proc.start()
    send.close()
    try:
        row = recv.recv()
    except EOFError:
        row = None
    proc.join()
    if row is None:
        return {
            "method": "ompl",
            "ok": False,
            "runtime_s": math.nan,
            "failure": "crashed",
            "note": f"OMPL's process ended with exit code {proc.exitcode}",
        }
    return row


def _q(x, q: float) -> float:
    x = np.asarray([v for v in x if v == v], dtype=float)
    return float(np.percentile(x, q)) if len(x) else math.nan


def report(rows: list[dict], have_ompl: bool) -> str:
    """The text table of a run (module docstring)."""
    import pandas as pd

    df = pd.DataFrame(rows)
    lines = []
    head = (
        f"{'category':<26}{'n':>4}{'planned':>9}{'overlaps':>10}{'median ms':>11}{'p95 ms':>9}"
        f"{'cusps':>7}"
    )
    if have_ompl:
        head += f"{'OMPL planned':>14}{'overlaps':>10}{'cusps':>7}"
    lines.append(head)
    groups = [("all", df)]
    for cat in pc.CATEGORIES:
        sub = df[df["category"] == cat]
        if len(sub):
            groups.append((cat, sub))
            for e in pc.ENTRIES:
                s2 = sub[sub["entry"] == e]
                if len(s2):
                    groups.append((f"  {cat} {e}", s2))
    for name, sub in groups:
        t = sub[sub["method"] == "trajopt"]
        ok = t[t["ok"]]
        n = len(t)
        over = ok["overlaps"].fillna(0) if len(ok) else pd.Series(dtype=float)
        line = (
            f"{name:<26}{n:>4}{100 * len(ok) / max(n, 1):>8.0f}%"
            f"{f'{int((over > 0).sum())} ({int(over.sum())})':>10}"
            f"{1e3 * _q(ok['runtime_s'], 50):>11.0f}{1e3 * _q(ok['runtime_s'], 95):>9.0f}"
            f"{_q(ok['cusps'], 50) if len(ok) else math.nan:>7.1f}"
        )
        if have_ompl:
            o = sub[sub["method"] == "ompl"]
            ook = o[o["ok"]]
            oo = ook["overlaps"].fillna(0) if len(ook) else pd.Series(dtype=float)
            line += (
                f"{100 * len(ook) / max(len(o), 1):>13.0f}%"
                f"{f'{int((oo > 0).sum())} ({int(oo.sum())})':>10}"
                f"{_q(ook['cusps'], 50) if len(ook) else math.nan:>7.1f}"
            )
        lines.append(line)
    t = df[df["method"] == "trajopt"]
    fails = t[~t["ok"]]
    if len(fails):
        lines.append("trajopt failures:")
        counts = fails.apply(
            lambda r: failure_reason(r["failure"], r["note"]), axis=1
        ).value_counts()
        for reason, k in counts.items():
            cats = sorted(
                set(
                    fails[
                        fails.apply(lambda r: failure_reason(r["failure"], r["note"]), axis=1)
                        == reason
                    ]["category"]
                )
            )
            lines.append(f"  {k:3d} x {reason} [{', '.join(cats)}]")
        blocked = int(fails["note"].map(end_blocked_on_first_grid).sum())
        lines.append(
            f"  ({blocked} of the {len(fails)} failures name an end pose whose footprint + "
            "margin + slack meets a grid cell on a search grid)"
        )
    ok = t[t["ok"]]
    if len(ok):
        lines.append(
            f"trajopt plans: least body clearance {ok['min_clearance_m'].min():.3f} m "
            f"(median {ok['min_clearance_m'].median():.3f} m), checked poses per plan median "
            f"{ok['checked_poses'].median():.0f}"
        )
    if have_ompl:
        o = df[(df["method"] == "ompl") & df["ok"]]
        both = set(ok["case_id"]) & set(o["case_id"])
        if both:
            tc = ok.set_index("case_id").loc[sorted(both), "cusps"]
            oc = o.set_index("case_id").loc[sorted(both), "cusps"]
            lines.append(
                f"cases both planned: {len(both)}; cusps per plan mean trajopt {tc.mean():.2f} "
                f"vs OMPL {oc.mean():.2f}"
            )
        only = set(o["case_id"]) - set(ok["case_id"])
        lines.append(f"cases OMPL planned and trajopt did not: {len(only)}")
        of = df[(df["method"] == "ompl") & ~df["ok"]]
        if len(of):
            kinds = ", ".join(f"{k} {v}" for k, v in of["failure"].value_counts().items())
            lines.append(f"OMPL failures: {kinds}")
    return "\n".join(lines)


def feasibility_verdicts(cases: list[pc.ParkingCase], how: str) -> dict[str, str]:
    """Each case's feasibility verdict: computed (``how == "compute"``) or read from a JSON file.

    The file is a list of rows with ``case_id``, ``verdict``, ``start``, ``goal`` and
    ``size`` (``parking_feasibility.py --json``); a case missing from it, or whose start,
    goal or size differ from the suite's by more than 1e-9, raises ``ValueError``.
    """
    if how == "compute":
        # the package's module: numba's cache of its kernels names benchmarks.parking_feasibility
        from benchmarks import parking_feasibility as pfz

        out = {}
        for case in cases:
            v = pfz.case_feasibility(case)
            print(
                f"feasibility {case.case_id}: {v.verdict} ({v.resolution:.3f} m, {v.seconds:.0f} s)"
            )
            out[case.case_id] = v.verdict
        return out
    import json

    rows = {r["case_id"]: r for r in json.loads(Path(how).read_text())}
    out = {}
    for case in cases:
        r = rows.get(case.case_id)
        if r is None:
            raise ValueError(f"--feasibility {how}: no verdict for case {case.case_id!r}")
        same = np.allclose(r["start"], case.start, atol=1e-9, rtol=0) and np.allclose(
            r["goal"], case.goal, atol=1e-9, rtol=0
        )
        if not same or abs(r["size"] - case.size) > 1e-9:
            raise ValueError(
                f"--feasibility {how}: case {case.case_id!r} differs from the suite's "
                "(start, goal or size): the file is stale, recompute it"
            )
        out[case.case_id] = r["verdict"]
    return out


def feasibility_lines(rows: list[dict]) -> list[str]:
    """trajopt's planned rate over all cases and over the cases proven feasible."""
    t = [r for r in rows if r["method"] == "trajopt"]
    feas = [r for r in t if r["feasibility"] == "feasible"]
    counts = {
        k: sum(r["feasibility"] == k for r in t) for k in ("feasible", "infeasible", "unknown")
    }
    ok_all = sum(bool(r["ok"]) for r in t)
    ok_feas = sum(bool(r["ok"]) for r in feas)
    return [
        "feasibility (parking_feasibility): " + ", ".join(f"{n} {k}" for k, n in counts.items()),
        f"trajopt planned {ok_all}/{len(t)} of all cases ({100 * ok_all / max(len(t), 1):.1f}%), "
        f"{ok_feas}/{len(feas)} of the cases proven feasible "
        f"({100 * ok_feas / max(len(feas), 1):.1f}%)",
    ]


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark (module docstring)."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--limit", type=int, default=40, help="number of cases (default 40)")
    ap.add_argument("--resolution", type=float, default=0.1, help="grid cell side (m)")
    ap.add_argument("--car", choices=sorted(pc.CARS), default="full")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--ompl-time", type=float, default=1.5, help="OMPL's budget per case (s)")
    ap.add_argument("--ompl-planner", choices=("bitstar", "rrtstar"), default="bitstar")
    ap.add_argument("--no-ompl", action="store_true")
    ap.add_argument("--out", type=Path, default=None, help="rows as .csv or .parquet")
    ap.add_argument(
        "--cases",
        type=str,
        default=None,
        help="only these cases of the suite: comma-separated indices (0-based) or case ids",
    )
    ap.add_argument(
        "--feasibility",
        type=str,
        default=None,
        help="'compute' or a JSON file of parking_feasibility.py --json: also report the "
        "planned rate over the cases proven feasible",
    )
    args = ap.parse_args(argv)

    import trajopt  # noqa: F401 - imported before timing

    car = pc.CARS[args.car]
    robot = car.robot()
    cases = pc.make_cases(car, args.limit, args.seed)
    if args.cases:
        picks = [w.strip() for w in args.cases.split(",") if w.strip()]
        cases = [c for i, c in enumerate(cases) if str(i) in picks or c.case_id in picks]
    verdicts = feasibility_verdicts(cases, args.feasibility) if args.feasibility else None
    have_ompl = not args.no_ompl
    if have_ompl:
        try:
            import ompl  # noqa: F401
        except ImportError:
            print("ompl not importable: the OMPL rows are skipped")
            have_ompl = False
    print(
        f"parking suite: {len(cases)} cases, car {car.name} ({car.length} x {car.width} m, "
        f"R {car.turning_radius} m, wheelbase {car.wheelbase} m), grid {args.resolution} m, "
        f"seed {args.seed}"
        + (f", OMPL {args.ompl_planner} {args.ompl_time} s" if have_ompl else "")
    )
    # warm-up (numba's cache, first imports): one plan, not timed
    try:
        run_trajopt(cases[0], cases[0].grid(args.resolution), robot)
    except Exception:  # noqa: BLE001
        pass
    rows = []
    t_all = time.perf_counter()
    for i, case in enumerate(cases):
        t0 = time.perf_counter()
        grid = case.grid(args.resolution)
        grid_s = time.perf_counter() - t0
        base = {
            "case_id": case.case_id,
            "category": case.category,
            "entry": case.entry,
            "car": car.name,
            "resolution_m": args.resolution,
            "size": case.size,
            "aisle_m": case.aisle,
            "angle_deg": case.angle,
            "cells": grid.nx * grid.ny,
            "grid_s": grid_s,
        }
        if verdicts is not None:
            base["feasibility"] = verdicts[case.case_id]
        r = run_trajopt(case, grid, robot)
        rows.append({**base, **r})
        msg = (
            f"[{i + 1}/{len(cases)}] {case.case_id} size {case.size:.2f} aisle {case.aisle:.1f}: "
            + (
                f"trajopt {1e3 * r['runtime_s']:.0f} ms, {r['cusps']} cusps, {r['overlaps']} overlaps"
                if r["ok"]
                else f"trajopt {r['failure']} ({1e3 * r['runtime_s']:.0f} ms)"
            )
        )
        if have_ompl:
            o = run_ompl_isolated(case, args.ompl_time, args.seed + i, args.ompl_planner)
            rows.append({**base, **o})
            msg += (
                f"; OMPL {o['cusps']} cusps, {o['overlaps']} overlaps"
                if o["ok"]
                else f"; OMPL none ({o['failure']})"
            )
        print(msg, flush=True)
    print(f"total {time.perf_counter() - t_all:.0f} s\n")
    print(report(rows, have_ompl))
    if verdicts is not None:
        print("\n".join(feasibility_lines(rows)))
    if args.out is not None:
        import pandas as pd

        df = pd.DataFrame(rows)
        if args.out.suffix == ".parquet":
            df.to_parquet(args.out)
        else:
            df.to_csv(args.out, index=False)
        print(f"rows: {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
