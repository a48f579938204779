"""Benchmark: re-timing a plan for new predictions of moving obstacles, this tree vs an earlier one.

On the house-size shared ROS maps (``smoothers_world``, 15 x 15 m, and ``depot``, 30 x 15 m,
5 cm cells), a :class:`trajopt.Planner` (robot radius 0.2 m, default limits) plans seeded
random queries whose path is 10-20 m long. Each plan then gets ``--sets`` sets of
predictions, one after the other, as a robot's tracker would send them while the path stays
the same: 10 disc movers (radius 0.2-0.4 m, 0.3-1.5 m/s, constant velocity until the
plan's duration + 10 s) that cross the path near where and when the static plan is there,
so that most sets force a real re-timing (waits, stops). Each set is re-timed by
:func:`trajopt.retime_for_movers` of this tree and by the same function as it was at
``--before`` (default ``3379fc7``, before the speed-up): its ``trajopt/moving`` modules are
exported with ``git show`` into a temporary package and imported beside this tree's (the
movers are this tree's :class:`trajopt.MovingObstacle`, the rest of ``trajopt`` is shared).
The two run one after the other on each set, so that both see the same machine load.

Each set is also given to ``Planner.replan(traj, 2.0, latency=0, moving_obstacles=...)``
(the robot 2 s into the plan: the kept rest re-timed from the moving state, its predictions
on the plan's clock); it prints that re-plan's wall and CPU time, its re-timing's own time
(``stats["moving"]["time_s"]``) and the smallest slack of its results on 1 ms samples (the
movers shifted to the re-plan's clock).

It prints the median and p99 (ms) of the wall time of both and of the CPU time of this
tree (``time.process_time``: on a shared machine the wall time also counts the time the
process waits for a core), over all sets and over the sets that
were really re-timed (not returned as planned, no :class:`~trajopt.errors.BlockedError`),
the first set of each plan (this tree builds the path's tables then: ``cold``) apart from
the later ones (``warm``: the tables of the same path are reused); the arrival times of the
two on the sets both re-timed (ratio this / before); and an independent check of every
trajectory this tree returned: the slack to every mover on 1 ms samples over the whole
horizon (distance minus radius sum minus margin, from the trajectory's own samples).

The target of issue #46: a re-time when only the predictions change, <= 10 ms median and
<= 25 ms p99 (``warm``). The machine is shared: the numbers are noisy; run it when quiet.

Run from the repository root (needs the shared data, ``$TRAJOPT_DATA`` or
``../shared/data``, and git)::

    python benchmarks/bench_moving_retime.py
    python benchmarks/bench_moving_retime.py --plans 4 --sets 6 --before main
"""

from __future__ import annotations

import argparse
import importlib
import math
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import astar  # noqa: E402
import trajopt  # noqa: E402
from trajopt.errors import BlockedError, InvalidInputError, TrajoptError  # noqa: E402

MAPS = ("smoothers_world", "depot")
BEFORE = "3379fc7"  # trajopt.moving before the speed-up
REPLAN_AT = 2.0  # s into each plan: the re-plan for the same sets of predictions


def data_dir() -> Path:
    env = os.environ.get("TRAJOPT_DATA")
    return Path(env) if env else ROOT.parent / "shared" / "data"


def load_before(rev: str, tmp: Path):
    """Return ``retime_for_movers`` of ``trajopt/moving`` at ``rev`` (a temporary package)."""
    pkg = tmp / "moving_before"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    listing = subprocess.run(
        ["git", "ls-tree", "--name-only", f"{rev}:trajopt/moving/"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=True,
    ).stdout.split()
    # every private module of the package at rev but the obstacle class (this tree's)
    mods = [f[:-3] for f in listing if f.startswith("_") and f.endswith(".py")]
    mods = [m for m in mods if m not in ("__init__", "_obstacle")]
    pattern = r"trajopt\.moving\.(" + "|".join(mods) + r")\b"
    for mod in mods:
        src = subprocess.run(
            ["git", "show", f"{rev}:trajopt/moving/{mod}.py"],
            cwd=ROOT,
            capture_output=True,
            text=True,
            check=True,
        ).stdout
        # its sibling modules from the temporary package
        (pkg / f"{mod}.py").write_text(re.sub(pattern, r"moving_before.\1", src))
    sys.path.insert(0, str(tmp))
    return importlib.import_module("moving_before._retime").retime_for_movers


def plans(name: str, n: int, rng: np.random.Generator) -> list[tuple[trajopt.Planner, Any]]:
    """``n`` plans (with their planner) of one curve from rest to rest, paths of 10-20 m."""
    grid = astar.load_map(data_dir() / "ros" / f"{name}.yaml")
    planner = trajopt.Planner(grid, trajopt.Robot(radius=0.2))
    free = np.argwhere(~astar.inflate(grid, 0.35, metric="square", outside_occupied=True).occupied)
    out: list[tuple[trajopt.Planner, Any]] = []
    for _ in range(100 * n):
        if len(out) == n:
            break
        a, b = free[rng.integers(len(free), size=2)]
        p0, p1 = grid.cell_to_world(a[::-1]), grid.cell_to_world(b[::-1])
        if not 7.0 <= math.dist(p0, p1) <= 20.0:
            continue
        try:
            traj = planner.plan(tuple(p0), tuple(p1))
        except TrajoptError:
            continue
        if traj.single_curve and 10.0 <= traj.length <= 20.0:
            out.append((planner, traj))
    return out


def movers(traj: trajopt.Trajectory, rng: np.random.Generator, n: int = 10) -> list:
    """``n`` disc movers crossing the path near where and when the static plan is there."""
    out = []
    while len(out) < n:
        t_c = rng.uniform(0.1, 0.9) * traj.duration
        smp = traj.sample(np.array([t_c]))
        p = np.array([smp.x[0], smp.y[0]])
        ang = smp.theta[0] + rng.uniform(0.5, math.pi - 0.5) * rng.choice([-1.0, 1.0])
        vel = rng.uniform(0.3, 1.5) * np.array([math.cos(ang), math.sin(ang)])
        start = p - vel * (t_c + rng.uniform(-1.0, 1.0))
        m = trajopt.MovingObstacle.constant_velocity(
            start,
            vel,
            radius=float(rng.uniform(0.2, 0.4)),
            horizon=traj.duration + 10.0,
            name=f"m{len(out)}",
        )
        p0 = traj.sample(np.zeros(1))
        if math.hypot(start[0] - p0.x[0], start[1] - p0.y[0]) > m.radius + 0.3:
            out.append(m)
    return out


def replan(planner, traj, ms):
    """Re-plan ``traj`` at ``REPLAN_AT`` s for the movers ``ms``.

    Returns ``(times, plan, re-time s, what the re-plan did, smallest slack)``; ``plan`` is
    ``None`` on a typed refusal, whose name is then the fourth field.
    """
    t0, c0 = time.perf_counter(), time.process_time()
    try:
        out = planner.replan(traj, REPLAN_AT, latency=0.0, moving_obstacles=ms)
    except (BlockedError, InvalidInputError) as exc:  # a mover over the robot at the splice
        took = (time.perf_counter() - t0, time.process_time() - c0)
        return took, None, 0.0, type(exc).__name__, math.inf
    took = (time.perf_counter() - t0, time.process_time() - c0)
    mv = out.stats["moving"]
    shifted = [trajopt.moving.shift_clock(m, REPLAN_AT) for m in ms]
    return took, mv["plan"], mv["time_s"], mv["replan"], dense_slack(out, shifted)


def dense_slack(traj, ms) -> float:
    """Smallest slack (m) to the movers over 1 ms samples of the whole horizon."""
    end = max([traj.duration] + [m.t_last for m in ms])
    t = np.append(np.arange(0.0, end, 1e-3), end)
    smp = traj.sample(t)
    worst = math.inf
    for m in ms:
        c = np.stack([np.interp(t, m.times, m.positions[:, i]) for i in (0, 1)], axis=-1)
        d = np.hypot(smp.x - c[:, 0], smp.y - c[:, 1])
        rad = m.radius + m.growth * np.clip(t, 0.0, m.t_last)
        worst = min(worst, float(np.min(d - rad - traj.robot.radius)))
    return worst


def run(fn, traj, ms):
    """Return ``((wall s, cpu s), result or None, plan or error name)`` of ``fn(traj, ms)``."""
    t0, c0 = time.perf_counter(), time.process_time()
    try:
        out = fn(traj, ms)
    except (BlockedError, InvalidInputError) as exc:
        return (time.perf_counter() - t0, time.process_time() - c0), None, type(exc).__name__
    took = (time.perf_counter() - t0, time.process_time() - c0)
    return took, out, out.stats["moving"]["plan"]


def stats(xs: list[tuple[float, float]], which: int) -> str:
    """Median and p99 (ms) of the wall (``which = 0``) or CPU (1) times ``xs``."""
    if not xs:
        return f"{'-':>6s} {'-':>7s}"
    a = 1e3 * np.asarray([x[which] for x in xs])
    return f"{np.median(a):6.1f} {np.percentile(a, 99):7.1f}"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plans", type=int, default=5, help="plans per map")
    ap.add_argument("--sets", type=int, default=8, help="prediction sets per plan")
    ap.add_argument("--before", default=BEFORE, help=f"git revision compared (default {BEFORE})")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    if not (data_dir() / "ros").is_dir():
        print(f"shared data not found at {data_dir()} (set TRAJOPT_DATA)")
        return 1
    from trajopt.moving import retime_for_movers

    rng = np.random.default_rng(args.seed)
    with tempfile.TemporaryDirectory() as tmp:
        before = load_before(args.before, Path(tmp))
        rows = {k: [] for k in ("new_cold", "new_warm", "old_cold", "old_warm")}
        retimed = {k: [] for k in ("new_cold", "new_warm", "old_cold", "old_warm")}
        ratios: list[float] = []
        worst, n_sets, n_new, n_old, blocked = math.inf, 0, 0, 0, 0
        replans: list[tuple] = []
        for name in MAPS:
            for planner, traj in plans(name, args.plans, rng):
                for k in range(args.sets):
                    ms = movers(traj, rng)
                    replans.append(replan(planner, traj, ms))
                    phase = "cold" if k == 0 else "warm"
                    w_new, out_new, what_new = run(retime_for_movers, traj, ms)
                    w_old, out_old, what_old = run(before, traj, ms)
                    n_sets += 1
                    rows[f"new_{phase}"].append(w_new)
                    rows[f"old_{phase}"].append(w_old)
                    if out_new is not None and what_new != "as planned":
                        retimed[f"new_{phase}"].append(w_new)
                        n_new += 1
                        worst = min(worst, dense_slack(out_new, ms))
                    if out_old is not None and what_old != "as planned":
                        retimed[f"old_{phase}"].append(w_old)
                        n_old += 1
                    blocked += out_new is None
                    if out_new is not None and out_old is not None and what_old != "as planned":
                        ratios.append(out_new.duration / out_old.duration)
        print(
            f"{n_sets} prediction sets (10 disc movers each) on {', '.join(MAPS)}; "
            f"re-timed: this tree {n_new}, before {n_old}; BlockedError (this tree): {blocked}"
        )
        print(
            f"{'(ms)':26s} {'wall: median':>12s} {'p99':>7s} {'cpu: median':>12s} {'p99':>7s}"
            f"   {'before wall: median':>19s} {'p99':>7s}"
        )
        for label, src in (("all sets", rows), ("re-timed sets", retimed)):
            for phase in ("warm", "cold"):
                new, old = src["new_" + phase], src["old_" + phase]
                print(
                    f"{label + ', ' + phase:26s} {stats(new, 0):>20s} {stats(new, 1):>20s}"
                    f"   {stats(old, 0):>27s}"
                )
        if ratios:
            r = np.asarray(ratios)
            print(
                f"arrival time this / before ({r.size} sets re-timed by both): median "
                f"{np.median(r):.3f}, min {r.min():.3f}, max {r.max():.3f}"
            )
        print(f"independent check, smallest slack on 1 ms samples (this tree): {worst:.2e} m")
        done = [r for r in replans if r[1] is not None]
        moved = [r for r in done if r[1] != "as planned"]
        print(
            f"Planner.replan(traj, {REPLAN_AT} s, latency=0, moving_obstacles=...) on the same "
            f"sets: {len(done)} returned ({len(moved)} re-timed, "
            f"{sum(r[3] == 'kept' for r in done)} kept their path), "
            f"{sum(r[3] == 'BlockedError' for r in replans)} BlockedError, "
            f"{sum(r[3] == 'InvalidInputError' for r in replans)} InvalidInputError (a mover "
            "over the robot at the splice); whole re-plan wall median "
            f"{stats([r[0] for r in done], 0)[:6].strip()} ms, cpu "
            f"{stats([r[0] for r in done], 1)[:6].strip()} ms; its re-time (stats['moving']"
            f"['time_s']) over the re-timed ones: median "
            f"{1e3 * np.median([r[2] for r in moved]) if moved else math.nan:.1f} ms, p99 "
            f"{1e3 * np.percentile([r[2] for r in moved], 99) if moved else math.nan:.1f} ms; "
            f"smallest slack on 1 ms samples {min([r[4] for r in done], default=math.inf):.2e} m"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
