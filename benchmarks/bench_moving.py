"""Moving obstacles (issue 46): success, violations and arrival against witnesses; re-time latency.

Scenarios (:mod:`benchmarks.moving_cases`) on the house-size shared maps (smoothers_world,
15 x 15 m, and depot, 30 x 15 m, both at 5 cm), robot radius 0.2 m, the default limits
(0.5 m/s, 0.5 m/s^2), mover margin 0.05 m: for each kind (crossing, head-on, following,
overtaking, stopping, mixed) and map, ``--per-kind`` seeded scenarios on random queries (start
and goal at least 2 m apart that a warm planner solves), with 1, 2, ..., 10 movers in turn.
Each scenario is run through the public API, ``Planner.plan(start, goal,
moving_obstacles=..., mover_margin=...)``, and every returned trajectory is checked by the
independent check :func:`tests.trajopt.moving.reference.check_trajectory` (1 ms samples
over the trajectory and the standing at the goal until the last prediction ends, plus the
Lipschitz bound between them, the static map's squares included).

Witnesses (:mod:`benchmarks.moving_witness`): the waiting witness (rest at the start, then
drive the static plan, planned again around the movers' final discs when needed; checked by
the same check) and the ``(s, t, v)`` lattice optimum along the static path (``--dp-dt``;
its dynamics model is in that module: constant accelerations, no jerk limit). Success is
counted on the scenarios that have a witness (``wit``: either witness; ``wait``: the
waiting one, ``latt``: the lattice one), and again on those witnessed along the static
path itself (``path``: the lattice's, or a waiting witness that did not plan again: what a
re-timing along the path can reach); ``proven``: refusals where
:func:`benchmarks.moving_witness.path_blocked` proves that no motion along the static path
exists (a relaxation: speed and acceleration bounds only); ``later`` counts those where the planner's
arrival is later than the waiting witness's (by more than 1 ms); the lattice ratio is the
planner's arrival over the lattice optimum's (``static/lattice``: the same ratio for the
static plan without movers, the models' gap).

Re-time when only the predictions change: on each map, ``--retime`` queries with 10 movers
(``mixed``); the plan with them, then each mover's prediction is shifted (time by up to
0.3 s, position by up to 0.1 m), three times, and the new predictions go in through
``Planner.replan(trajectory, t, moving_obstacles=...)`` when the planner has it (``t`` =
0.5 s, latency 0; found from its signature), else ``trajopt.retime_for_movers`` on the static plan's path (the script says which).
Every re-timed trajectory is checked as above. The times are also given apart for the
target's case, no new path: the re-plan kept the rest of the trajectory (``stats["replan"]
== "kept"``) and the re-timing kept its path (``stats["moving"]["route"] == "retimed"``:
the rest as planned, or re-timed along its path); and for the new paths: re-plans that
stopped and planned again after the re-timing found no way (``route`` ``"stopped: ..."``),
and re-plans whose rest could not be kept (``stats["replan"]`` ``"planned: ..."`` or
``"braked: ..."``, e.g. a first plan re-routed around the movers, whose freed cells make the
re-plan plan anew: braked to a stop, the plan from rest is a new path even when the
re-timing then keeps it, ``route`` ``"retimed"``); and the CPU time of the first
(``time.process_time``: on a shared machine the wall time also counts the waits for a
core). The three re-plans at 0.5 s share their splice (a plan that waits at the start keeps
its whole path), so the later ones find the re-timing's tables of that rest warm; a fourth
re-plan per query, 0.4 s after the plan starts moving with predictions shifted again, cuts
the path at a new place, as a robot re-planning while it drives does, and is timed apart
(no new path only). The kernels are loaded before the timed part (``trajopt.warm_up()``), so no timed
call loads one from numba's cache. Each timed re-plan starts after an untimed
``gc.collect()``: the benchmark's own checks (the reference's brute force) leave many
objects behind, and a full collection of them (60-90 ms) landing inside a timed call would
measure the harness; collections the re-plan's own allocations trigger still count.

``--shape`` sets the movers' shapes in both parts: discs (the default), carts (convex
rectangles heading along their motion, :mod:`benchmarks.moving_cases`) or a random mix.

Run from the repository root (needs the shared data, ``$TRAJOPT_DATA`` or
``../shared/data``)::

    python benchmarks/bench_moving.py
    python benchmarks/bench_moving.py --quick
    python benchmarks/bench_moving.py --per-kind 20 --retime 30 --seed 1
    python benchmarks/bench_moving.py --shape polygon
"""

from __future__ import annotations

import argparse
import gc
import inspect
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import astar  # noqa: E402
import trajopt  # noqa: E402
from benchmarks.bench_replan import queries, ros_dir  # noqa: E402
from benchmarks.moving_cases import KINDS, SHAPES, make_movers  # noqa: E402
from benchmarks.moving_witness import grid_optimum, path_blocked, waiting_witness  # noqa: E402
from tests.trajopt.moving.reference import check_trajectory  # noqa: E402

MAPS = ("smoothers_world", "depot")
MARGIN = 0.05


def pct(xs, q):
    return float(np.percentile(xs, q)) if xs else math.nan


def med(xs):
    return statistics.median(xs) if xs else math.nan


def shifted(m, rng):
    """``m``'s prediction moved by up to 0.3 s and 0.1 m (same shape, same name)."""
    dt = float(rng.uniform(-0.3, 0.3))
    times = np.maximum(m.times + dt, 0.0)
    keep = np.r_[True, np.diff(times) > 1e-9]
    pos = m.positions[keep] + rng.uniform(-0.1, 0.1, size=2)
    return trajopt.MovingObstacle.from_waypoints(
        times[keep],
        pos,
        radius=m.radius,
        growth=m.growth,
        headings=m.headings[keep],
        vertices=m.vertices,
        name=m.name,
    )


def on_clock(movers, t0):
    """The movers seen from a clock that starts at ``t0`` (s) of theirs."""
    if t0 == 0.0:
        return movers
    out = []
    for m in movers:
        times = m.times - t0
        k = max(int(np.searchsorted(times, 0.0, side="right")) - 1, 0)
        p0 = [np.interp(0.0, times, m.positions[:, i]) for i in (0, 1)]
        h0 = np.interp(0.0, times, m.headings)
        t = np.r_[0.0, times[k + 1 :]] if times[-1] > 0 else np.zeros(1)
        p = np.vstack([p0, m.positions[k + 1 :]]) if times[-1] > 0 else np.array([p0])
        h = np.r_[h0, m.headings[k + 1 :]] if times[-1] > 0 else np.array([h0])
        out.append(
            trajopt.MovingObstacle.from_waypoints(
                t,
                p,
                radius=m.radius + m.growth * max(t0, 0.0),
                growth=m.growth,
                headings=h,
                vertices=m.vertices,
                name=m.name,
            )
        )
    return out


def run_scenario(planner, grid, static, start, goal, movers, dp_dt):
    row = {"n": len(movers)}
    t0 = time.perf_counter()
    try:
        out = planner.plan(start, goal, moving_obstacles=movers, mover_margin=MARGIN)
    except trajopt.errors.BlockedError:
        out, row["outcome"] = None, "blocked"
    except trajopt.TrajoptError as exc:
        out, row["outcome"] = None, f"error:{type(exc).__name__}"
    row["plan_s"] = time.perf_counter() - t0
    if out is not None:
        chk = check_trajectory(out, movers, margin=MARGIN, grid=grid)
        row["outcome"] = "ok" if chk.ok else ("violated" if chk.violated else "unproven")
        row["arrival"] = float(out.duration)
        row["slack"] = min(chk.mover_slack, chk.static_slack)
    w = waiting_witness(grid, static, start, goal, movers, MARGIN)
    row["wait"] = None if w is None else w.arrival
    row["same_path"] = w is not None and not w.replanned
    row["lattice"] = grid_optimum(static, movers, MARGIN, dt=dp_dt)
    if out is None:
        row["proven"] = path_blocked(static, movers, MARGIN, ds=0.02, dt=0.02)
    return row


def kind_line(kind, rows, gap):
    wit = [r for r in rows if r["wait"] is not None or r["lattice"] is not None]
    ok = [r for r in wit if r["outcome"] == "ok"]
    path = [r for r in rows if r["same_path"] or r["lattice"] is not None]
    ok_path = [r for r in path if r["outcome"] == "ok"]
    viol = sum(r["outcome"] == "violated" for r in rows)
    unproven = sum(r["outcome"] == "unproven" for r in rows)
    blocked = sum(r["outcome"] == "blocked" for r in rows)
    proven = sum(r["outcome"] == "blocked" and r["proven"] for r in rows)
    errs = sum(r["outcome"].startswith("error") for r in rows)
    ratio = [r["arrival"] / r["lattice"] for r in rows if "arrival" in r and r["lattice"]]
    both = [r for r in rows if "arrival" in r and r["wait"] is not None]
    later = [r["arrival"] - r["wait"] for r in both if r["arrival"] > r["wait"] + 1e-3]
    plan_ms = [1e3 * r["plan_s"] for r in rows if r["outcome"] == "ok"]
    ref_ms = [1e3 * r["plan_s"] for r in rows if r["outcome"] == "blocked"]
    succ = 100.0 * len(ok) / len(wit) if wit else math.nan
    succ_path = 100.0 * len(ok_path) / len(path) if path else math.nan
    print(
        f"{kind:11s} {len(rows):5d} {len(wit):4d} "
        f"{sum(r['wait'] is not None for r in rows):4d} "
        f"{sum(r['lattice'] is not None for r in rows):4d} {succ:7.1f} {len(path):4d} "
        f"{succ_path:7.1f} {blocked:7d} {proven:6d} {errs:4d} "
        f"{viol:5d} {unproven:8d} {med(ratio):7.3f} {max(ratio, default=math.nan):7.3f} "
        f"{len(later):3d}/{len(both):<3d} {med(later):6.3f} {max(later, default=0.0):6.3f} "
        f"{med(plan_ms):7.1f} {pct(plan_ms, 95):7.1f} {med(ref_ms):7.1f} {med(gap):6.3f}"
    )


def retime_part(maps, n_queries, seed, shape="disc"):
    """Re-time latency when only the predictions change (module docstring)."""
    if n_queries <= 0:
        return
    print(
        f"\nre-time when only the predictions change: 10 movers (mixed kinds, {shape} shapes), "
        "predictions shifted by up to 0.3 s and 0.1 m, three times per query"
    )
    trajopt.warm_up()  # every kernel loaded: none loads inside a timed call
    robot = trajopt.Robot(radius=0.2)
    # the re-plan with movers where the planner has it, else the re-timing on the path
    has = "moving_obstacles" in inspect.signature(trajopt.Planner.replan).parameters
    via = "replan" if has else "retime_for_movers"
    times_ok, times_blocked, errors, bad, n_checked = [], [], {}, 0, 0
    # (stats["moving"]["route"], its plan, stats["replan"]) of each
    routes: list[tuple[str, str, str]] = []
    cpu_ok: list[float] = []  # CPU time (s) of each: on a shared machine the wall time waits too
    # re-plans at a new splice while driving, no new path: (wall s, CPU s)
    driving: list[tuple[float, float]] = []
    for mi, (_, grid) in enumerate(maps):
        planner = trajopt.Planner(grid, robot)
        rng = np.random.default_rng([seed, 7, mi])
        for qi, (start, goal) in enumerate(queries(grid, robot, n_queries, rng)):
            try:
                static = planner.plan(start, goal)
                movers = make_movers(
                    static, "mixed", 10, seed * 100_000 + mi * 1000 + qi, shape=shape
                )
                first = planner.plan(start, goal, moving_obstacles=movers, mover_margin=MARGIN)
            except trajopt.TrajoptError:
                continue
            for _ in range(3):
                new = [shifted(m, rng) for m in movers]
                gc.collect()  # the harness's garbage, not the re-plan's (module docstring)
                c0 = time.process_time()
                t0 = time.perf_counter()
                try:
                    if via == "replan":
                        out = planner.replan(
                            first, 0.5, latency=0.0, moving_obstacles=new, mover_margin=MARGIN
                        )
                    else:
                        out = trajopt.retime_for_movers(static, new, margin=MARGIN)
                except trajopt.errors.BlockedError:
                    times_blocked.append(time.perf_counter() - t0)
                    continue
                except trajopt.TrajoptError as exc:
                    errors[type(exc).__name__] = errors.get(type(exc).__name__, 0) + 1
                    continue
                times_ok.append(time.perf_counter() - t0)
                cpu_ok.append(time.process_time() - c0)
                route = out.stats.get("moving", {}).get("route", "retimed")
                plan = out.stats.get("moving", {}).get("plan", "")
                routes.append((route, plan, str(out.stats.get("replan", "kept"))))
                clock = float(out.stats.get("splice_time_s", 0.0)) if via == "replan" else 0.0
                chk = check_trajectory(out, on_clock(new, clock), margin=MARGIN, grid=grid)
                n_checked += 1
                bad += not chk.ok
            if via != "replan":
                continue
            ts = driving_splice(first)
            if ts is None:
                continue
            srng = np.random.default_rng([seed, 8, mi, qi])  # the part above draws the same
            new = [shifted(m, srng) for m in movers]
            gc.collect()
            c0 = time.process_time()
            t0 = time.perf_counter()
            try:
                out = planner.replan(
                    first, ts, latency=0.0, moving_obstacles=new, mover_margin=MARGIN
                )
            except trajopt.TrajoptError:
                continue
            wall, cpu = time.perf_counter() - t0, time.process_time() - c0
            moving = out.stats.get("moving", {})
            if moving.get("route") == "retimed" and str(out.stats.get("replan")) == "kept":
                driving.append((wall, cpu))
            clock = float(out.stats.get("splice_time_s", 0.0))
            chk = check_trajectory(out, on_clock(new, clock), margin=MARGIN, grid=grid)
            n_checked += 1
            bad += not chk.ok
    ms = [1e3 * t for t in times_ok]
    how = (
        "Planner.replan(trajectory, 0.5, latency=0, moving_obstacles=...)"
        if via == "replan"
        else "trajopt.retime_for_movers on the static plan (no replan with movers here)"
    )
    print(
        f"via {how}: {len(ms)} re-timed, median {med(ms):.2f} ms, p99 {pct(ms, 99):.2f} ms, "
        f"max {max(ms, default=math.nan):.2f} ms (target <= 10 ms median, <= 25 ms p99); "
        f"{len(times_blocked)} blocked, refusal median "
        f"{med([1e3 * t for t in times_blocked]):.2f} ms; other errors {errors or 0}; "
        f"checked {n_checked}, failing the check {bad}"
    )
    # the target's case: no new path (the kept rest, re-timed along its path), apart from
    # the new paths (stopped and planned again, or the rest not kept: module docstring)
    same_path = [r == "retimed" and why == "kept" for r, _, why in routes]
    same = [m for m, k in zip(ms, same_path, strict=True) if k]
    same_cpu = [1e3 * c for c, k in zip(cpu_ok, same_path, strict=True) if k]
    as_planned = [k and p == "as planned" for k, (_, p, _) in zip(same_path, routes, strict=True)]
    kept = [m for m, k in zip(ms, as_planned, strict=True) if k]
    moved = [m for m, k, a in zip(ms, same_path, as_planned, strict=True) if k and not a]
    other = [m for m, k in zip(ms, same_path, strict=True) if not k]
    braked = sum(r == "retimed" and why != "kept" for r, _, why in routes)
    print(
        f"  no new path (rest kept, route 'retimed'): {len(same)}, median {med(same):.2f} ms, p99 "
        f"{pct(same, 99):.2f} ms, max {max(same, default=math.nan):.2f} ms (kept as planned: "
        f"{len(kept)}, median {med(kept):.2f} ms; re-timed: {len(moved)}, median "
        f"{med(moved):.2f} ms, p90 {pct(moved, 90):.2f} ms); a new path: {len(other)} "
        f"(stopped and planned again: {len(other) - braked}; the rest not kept, the new plan "
        f"re-timed: {braked}), median {med(other):.2f} ms; CPU time of the no-new-path "
        f"ones: median {med(same_cpu):.2f} ms, p99 {pct(same_cpu, 99):.2f} ms"
    )
    if via == "replan":
        dw = [1e3 * w for w, _ in driving]
        dc = [1e3 * c for _, c in driving]
        print(
            f"  at a new splice while driving (0.4 s after the plan starts moving, new "
            f"predictions; the rest a curve not re-timed before), no new path: {len(dw)}, "
            f"median {med(dw):.2f} ms, p99 {pct(dw, 99):.2f} ms, max "
            f"{max(dw, default=math.nan):.2f} ms; CPU median {med(dc):.2f} ms, p99 "
            f"{pct(dc, 99):.2f} ms (checked with the others above)"
        )


def driving_splice(traj):
    """Return 0.4 s after ``traj`` starts moving (s), or ``None`` when it is not one curve or
    then lies within 0.5 s of its end."""
    v = np.asarray(getattr(traj, "phase_v", []), dtype=float)
    if getattr(traj, "pieces", None) is not None or v.shape[0] == 0:
        return None
    go = np.flatnonzero(v > 0.0)
    t_go = float(traj.phase_t[go[0] - 1]) if go.shape[0] and go[0] > 0 else 0.0
    ts = t_go + 0.4
    return ts if ts < float(traj.duration) - 0.5 else None


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--per-kind", type=int, help="scenarios per kind and map (default 10)")
    ap.add_argument("--retime", type=int, help="queries per map, re-time part (default 15)")
    ap.add_argument("--max-movers", type=int, default=10)
    ap.add_argument("--dp-dt", type=float, default=0.05, help="lattice time step (s)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument(
        "--shape",
        choices=SHAPES,
        default="disc",
        help="the movers' shapes: discs, carts (convex polygons) or a random mix",
    )
    ap.add_argument(
        "--quick", action="store_true", help="one map; 2 per kind, 3 re-time queries unless given"
    )
    args = ap.parse_args(argv)
    quick = (2, 3) if args.quick else (10, 15)
    args.per_kind = quick[0] if args.per_kind is None else args.per_kind
    args.retime = quick[1] if args.retime is None else args.retime
    d = ros_dir()
    if d is None:
        return 1
    names = MAPS[:1] if args.quick else MAPS
    maps = [(n, astar.load_map(d / f"{n}.yaml")) for n in names]
    robot = trajopt.Robot(radius=0.2)
    print(
        f"robot radius {robot.radius} m, v_max {robot.v_max} m/s, a_max {robot.a_max} m/s^2; "
        f"mover margin {MARGIN} m; maps {', '.join(names)}; {args.per_kind} scenarios per "
        f"kind and map, 1-{args.max_movers} movers ({args.shape} shapes); lattice dt "
        f"{args.dp_dt} s"
    )
    rows = {k: [] for k in (*KINDS, "mixed")}
    gap, plain_ms = [], []
    for mi, (_, grid) in enumerate(maps):
        planner = trajopt.Planner(grid, robot)
        rng = np.random.default_rng([args.seed, mi])
        statics = []
        for start, goal in queries(grid, robot, 4 * args.per_kind, rng):
            t0 = time.perf_counter()
            try:
                statics.append((start, goal, planner.plan(start, goal)))
            except trajopt.TrajoptError:
                continue
            plain_ms.append(1e3 * (time.perf_counter() - t0))
        if not statics:
            continue
        for *_, static in statics[: args.per_kind]:
            lat = grid_optimum(static, [], MARGIN, dt=args.dp_dt)
            if lat:
                gap.append(float(static.duration) / lat)
        for ki, kind in enumerate(rows):
            for i in range(args.per_kind):
                start, goal, static = statics[(i + ki) % len(statics)]
                n = 1 + i % args.max_movers
                seed = args.seed * 100_000 + mi * 10_000 + ki * 1000 + i
                movers = make_movers(static, kind, n, seed, margin=MARGIN, shape=args.shape)
                rows[kind].append(
                    run_scenario(planner, grid, static, start, goal, movers, args.dp_dt)
                )
    print(
        f"\n{'kind':11s} {'scen':>5s} {'wit':>4s} {'wait':>4s} {'latt':>4s} {'succ %':>7s} {'path':>4s} {'succ %':>7s} "
        f"{'blocked':>7s} {'proven':>6s} {'err':>4s} {'viol':>5s} {'unproven':>8s} {'/latt':>7s} {'max':>7s} "
        f"{'later':>7s} {'med s':>6s} {'max s':>6s} {'plan ms':>7s} {'p95':>7s} {'refuse':>7s} {'gap':>6s}"
    )
    for kind, rs in rows.items():
        kind_line(kind, rs, gap)
    kind_line("all", [r for rs in rows.values() for r in rs], gap)
    print(
        f"plain plans (no movers) of the same queries: median {med(plain_ms[1:]):.1f} ms, "
        f"p95 {pct(plain_ms[1:], 95):.1f} ms (the first, cold, left out)"
    )
    retime_part(maps, args.retime, args.seed, args.shape)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
