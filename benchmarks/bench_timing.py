"""Benchmark: jerk-limited timing (ours) vs TOPP-RA's time-optimal timing (no jerk limit).

Both time the same 1-DoF problem along arc length ``s`` of the same smooth path: the speed
cap ``Robot.speed_cap(kappa(s))`` (v_max, lateral acceleration, yaw rate, wheel speeds) and
``|a| <= a_max``, from rest to rest. TOPP-RA has no jerk limit, so its duration is a lower
bound (and it may overshoot the cap between its grid points). Paths: the smoother's output
(``trajopt.Planner``) for the paper scene targets and for Moving AI scenarios of the shared
maps (loaded at 0.4 m/cell, robot-scale), default robot.

Run::

    python benchmarks/bench_timing.py            # ~60 Moving AI scenarios + paper scene
    python benchmarks/bench_timing.py --limit 20

``benchmarks/compare_timing.py`` compares the compute time and the durations with an
earlier commit's timing on the same curves.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

RESOLUTION = 0.4  # m/cell: a cell centre next to a wall is 0.2 m > robot radius 0.165 m from it
MAPS = ("arena.map", "den312d.map", "Berlin_0_256.map", "Boston_0_1024.map", "rmtst01.map")


def toppra_duration(curve, robot, n_grid: int) -> tuple[float, float]:
    """TOPP-RA's time-optimal duration (s) and its compute time (s) for the 1-DoF problem."""
    import toppra
    import toppra.algorithm as algo
    import toppra.constraint as constraint

    length = curve.length
    s_fine = np.linspace(0.0, length, 20 * n_grid)
    cap_fine = robot.speed_cap(curve.curvature(curve.u_at_s(s_fine)))
    t0 = time.perf_counter()
    ss = np.linspace(0.0, length, n_grid)
    path = toppra.SplineInterpolator(ss, ss.reshape(-1, 1))

    def vlim(s):
        c = float(np.interp(s, s_fine, cap_fine))
        return np.array([[-c, c]])

    vel = constraint.JointVelocityConstraintVarying(vlim)
    acc = constraint.JointAccelerationConstraint(np.array([[-robot.a_max, robot.a_max]]))
    inst = algo.TOPPRA([vel, acc], path, gridpoints=ss, parametrizer="ParametrizeConstAccel")
    traj = inst.compute_trajectory(0.0, 0.0)
    el = time.perf_counter() - t0
    if traj is None:
        return math.nan, el
    return float(traj.duration), el


def forward_backward_duration(curve, robot, ds: float = 0.001) -> float:
    """Exact jerk-free time-optimal duration by the classic forward-backward pass on a fine
    grid (a second, independent lower bound)."""
    length = curve.length
    n = max(2, int(math.ceil(length / ds)) + 1)
    s = np.linspace(0.0, length, n)
    cap = robot.speed_cap(curve.curvature(curve.u_at_s(s)))
    h = s[1] - s[0]
    v2 = cap**2
    v2[0] = v2[-1] = 0.0
    for i in range(1, n):
        v2[i] = min(v2[i], v2[i - 1] + 2 * robot.a_max * h)
    for i in range(n - 2, -1, -1):
        v2[i] = min(v2[i], v2[i + 1] + 2 * robot.a_max * h)
    v = np.sqrt(np.maximum(v2, 0.0))
    return float(np.sum(2 * h / np.maximum(v[1:] + v[:-1], 1e-12)))


def paper_curves(robot):
    from trajopt._planner import Planner
    from trajopt.analysis import scenes

    scene = scenes.paper()
    planner = Planner(scene.grid, robot)
    out = []
    for name, target in scene.targets.items():
        try:
            out.append((f"paper:{name}", planner.plan(scene.start, target).path))
        except Exception as exc:  # noqa: BLE001 - a benchmark records and goes on
            print(f"  paper:{name}: planning failed ({type(exc).__name__}: {exc})")
    return out


def movingai_curves(robot, limit: int, data: Path):
    import astar
    from trajopt._planner import Planner

    per_map = max(1, math.ceil(limit / len(MAPS)) + 4)
    out, fails = [], 0
    for map_name in MAPS:
        mp = data / "movingai" / "maps" / map_name
        sc = data / "movingai" / "scen" / f"{map_name}.scen"
        if not (mp.exists() and sc.exists()):
            continue
        grid = astar.load_map(mp, resolution=RESOLUTION)
        scen = [x for x in astar.read_scenarios(sc) if 10 <= x.optimal_length <= 60]
        if not scen:
            continue
        pick = np.unique(np.round(np.linspace(0, len(scen) - 1, per_map)).astype(int))
        planner = Planner(grid, robot)
        got = 0
        for i in pick:
            x = scen[i]
            try:
                traj = planner.plan(grid.cell_to_world(x.start), grid.cell_to_world(x.goal))
            except Exception:  # noqa: BLE001 - scenarios blocked at robot scale are skipped
                fails += 1
                continue
            out.append((f"{map_name}:{x.bucket}:{tuple(x.start)}", traj.path))
            got += 1
            if got >= math.ceil(limit / len(MAPS)):
                break
    return out, fails


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--limit", type=int, default=60, help="Moving AI scenarios (default 60)")
    ap.add_argument("--repeat", type=int, default=5, help="timing repeats per path (median)")
    args = ap.parse_args()
    warnings.filterwarnings("ignore")
    import logging

    logging.getLogger("toppra").setLevel(logging.ERROR)
    from tests.conftest import data_dir
    from trajopt.robot._robot import Robot
    from trajopt.timing import time_parameterize

    robot = Robot()
    print(f"robot: {robot}")
    curves = paper_curves(robot)
    n_paper = len(curves)
    mai, fails = movingai_curves(robot, args.limit, data_dir())
    curves += mai
    print(
        f"paths: {n_paper} paper-scene targets + {len(mai)} Moving AI scenarios "
        f"({RESOLUTION} m/cell; {fails} skipped: no path/smoothing failure at robot scale)"
    )
    time_parameterize(curves[0][1], robot)  # load the numba cache
    rows = []
    for name, curve in curves:
        times = []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            traj = time_parameterize(curve, robot)
            times.append(time.perf_counter() - t0)
        ts = np.linspace(0.0, traj.duration, 10_000)
        t0 = time.perf_counter()
        traj.sample(ts)
        t_sample = time.perf_counter() - t0
        n_grid = int(np.clip(curve.length / 0.01, 200, 1000))
        d_topp, t_topp = toppra_duration(curve, robot, n_grid)
        d_fb = forward_backward_duration(curve, robot)
        rows.append(
            dict(
                name=name,
                length=curve.length,
                ours=traj.duration,
                topp=d_topp,
                fb=d_fb,
                t_ours=float(np.median(times)),
                t_min=float(np.min(times)),
                t_topp=t_topp,
                t_sample=t_sample,
                greedy=traj.stats["timing_greedy_duration"],
            )
        )
        r = rows[-1]
        print(
            f"  {name:42s} L={r['length']:6.2f} m  ours {r['ours']:7.3f} s  TOPP-RA "
            f"{r['topp']:7.3f} s  ratio {r['ours'] / r['topp']:.4f}  fwd-bwd ratio "
            f"{r['ours'] / r['fb']:.4f}  time {1e3 * r['t_min']:6.2f} ms (best) "
            f"(TOPP-RA {1e3 * r['t_topp']:6.1f} ms)"
        )

    def summary(sel, label):
        if not sel:
            return
        ratio = np.array([r["ours"] / r["topp"] for r in sel])
        ratio_fb = np.array([r["ours"] / r["fb"] for r in sel])
        greedy = np.array([r["greedy"] / r["topp"] for r in sel])
        t_ours = np.array([r["t_ours"] for r in sel])
        per10 = np.array([r["t_min"] * 10.0 / r["length"] for r in sel])
        per_s = np.array([r["t_min"] / r["ours"] for r in sel])  # per s of trajectory
        t_min = np.array([r["t_min"] for r in sel])
        print(
            f"\n{label} ({len(sel)} paths, median length "
            f"{np.median([r['length'] for r in sel]):.2f} m)"
        )
        print(
            f"  duration ratio ours/TOPP-RA     median {np.median(ratio):.4f}  "
            f"p90 {np.percentile(ratio, 90):.4f}  max {ratio.max():.4f}"
        )
        print(
            f"  duration ratio ours/fwd-bwd     median {np.median(ratio_fb):.4f}  "
            f"max {ratio_fb.max():.4f}"
        )
        print(f"  greedy alone / TOPP-RA          median {np.median(greedy):.4f}")
        print(
            f"  compute time ours               median {1e3 * np.median(t_ours):.2f} ms  "
            f"p90 {1e3 * np.percentile(t_ours, 90):.2f} ms"
        )
        print(f"  compute time ours, best of runs median {1e3 * np.median(t_min):.2f} ms")
        print(f"  best-of-runs time per 10 m      median {1e3 * np.median(per10):.2f} ms")
        print(
            f"  best-of-runs time per s of traj median {1e3 * np.median(per_s):.4f} ms  "
            f"max {1e3 * per_s.max():.4f} ms"
        )
        print(
            f"  compute time TOPP-RA            median "
            f"{1e3 * np.median([r['t_topp'] for r in sel]):.2f} ms"
        )
        print(
            f"  sample(10 000 times)            median "
            f"{1e3 * np.median([r['t_sample'] for r in sel]):.2f} ms"
        )

    summary(rows[:n_paper], "paper scene")
    summary(rows[n_paper:], "Moving AI scenarios")
    near10 = [r for r in rows if 8.0 <= r["length"] <= 12.0]
    summary(near10, "paths of 8-12 m")
    summary(rows, "all")


if __name__ == "__main__":
    main()
