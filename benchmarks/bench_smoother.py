"""Benchmark of the corridor-constrained smoother (``trajopt.Smoother``).

Measures, on A* paths of about 100-500 cells from the shared Moving AI maps (robot radius
2.5 cells) and ROS maps (0.2 m), plus the paper scene's targets A-D:

* first-build time (the CasADi solvers built for a new padded size),
* warm per-query time (solver only, and the whole ``fit`` incl. the certificate),
  without and with a curvature bound ``kappa_max = 1 / (2 r)``,
* success rates and the minimum clearance margin,
* the peer: scipy ``make_lsq_spline`` on the same points (uniform knots, same number of
  control points): its time and how often it violates the clearance.

Run: ``python benchmarks/bench_smoother.py [--n 40] [--kappa-n 20] [--write /tmp/smoother_results.md]``
"""

from __future__ import annotations

import argparse
import math
import platform
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import astar  # noqa: E402
import trajopt.smoother._layout as smoother_layout  # noqa: E402
import trajopt.smoother._qp as smoother_qp  # noqa: E402
from trajopt.corridor import build_corridor  # noqa: E402
from trajopt.errors import SmoothingError  # noqa: E402
from trajopt.geometry._bspline import clamped_uniform_knots  # noqa: E402
from trajopt.geometry._clearance import points_clearance  # noqa: E402
from trajopt.smoother import Smoother  # noqa: E402
from trajopt.smoother._basis import CURV_SAMPLES  # noqa: E402


def data_dir() -> Path:
    import os

    env = os.environ.get("TRAJOPT_DATA")
    return Path(env) if env else ROOT.parent / "shared" / "data"


def scenarios(n_total: int, seed: int = 0):
    """(name, raw, inflated, radius, path) with A* paths of 100-500 cells."""
    rng = np.random.default_rng(seed)
    d = data_dir()
    maps = []
    for name in ["arena", "den312d", "Berlin_0_256", "rmtst01", "random512-40-5"]:
        raw = astar.load_map(d / "movingai" / "maps" / f"{name}.map")
        maps.append((name, raw, 2.5 * raw.resolution))
    for name in ["turtlebot3_world", "smoothers_world", "depot", "willow-2010-02-18-0.10"]:
        raw = astar.load_map(d / "ros" / f"{name}.yaml")
        maps.append((name, raw, 0.2))
    per_map = int(math.ceil(n_total / len(maps)))
    out = []
    for name, raw, r in maps:
        infl = astar.inflate(raw, r, metric="square", outside_occupied=True)
        ys, xs = np.nonzero(~infl.occupied)
        if len(xs) < 2:  # e.g. random512-40-5 has no room for this radius
            continue
        got = tries = 0
        while got < per_map and tries < 60 * per_map:
            tries += 1
            i, j = rng.choice(len(xs), 2, replace=False)
            a, b = (int(xs[i]), int(ys[i])), (int(xs[j]), int(ys[j]))
            if not 70 <= math.hypot(a[0] - b[0], a[1] - b[1]) <= 400:
                continue
            try:
                path = astar.find_path(infl, a, b)
            except astar.NoPathError:
                continue
            if not 100 <= len(path.cells) <= 500:
                continue
            out.append((name, raw, infl, r, path))
            got += 1
    return out[:n_total]


def paper_cases():
    try:
        from trajopt.analysis import scenes
    except ImportError:
        return []
    sc = scenes.paper()
    r = sc.robot_width / 2
    infl = astar.inflate(sc.grid, r, metric="square", outside_occupied=True)
    out = []
    for t in sc.targets:
        path = astar.find_path(infl, sc.start_cell, sc.goal_cell(t))
        out.append((f"paper-{t}", sc.grid, infl, r, path))
    return out


def pct(a, q):
    return float(np.percentile(a, q)) if len(a) else float("nan")


def run_set(cases, smoother: Smoother, reps: int):
    """First call (may build), then ``reps`` warm calls; returns per-case records."""
    recs = []
    for name, raw, infl, r, path in cases:
        corr = build_corridor(infl, path, radius=r)
        rec = {"name": name, "cells": len(path.cells)}
        try:
            t0 = time.perf_counter()
            sp = smoother.fit(path, corr, raw_grid=raw)
            rec["first_s"] = time.perf_counter() - t0
            rec["build_s"] = sp.stats["build_time_s"]
            solve, total = [], []
            for _ in range(reps):
                t0 = time.perf_counter()
                sp = smoother.fit(path, corr, raw_grid=raw)
                total.append(time.perf_counter() - t0)
                solve.append(sp.stats["solve_time_s"])
            rec.update(
                ok=True,
                solve_s=float(np.median(solve)),
                total_s=float(np.median(total)),
                attempts=sp.stats["attempts"],
                margin_m=sp.certificate.min_clearance_m - r,
                kappa=sp.certificate.kappa_max_sampled,
                n_ctrl=sp.stats["n_control_points"],
            )
        except SmoothingError as exc:
            rec.update(ok=False, why=str(exc)[:120], attempts=exc.stats.get("attempts", 0))
        recs.append(rec)
    return recs


def peer(cases, n_ctrl_by_case):
    """scipy make_lsq_spline on the same points: time and clearance violations."""
    from scipy.interpolate import make_lsq_spline

    times, viol = [], 0
    for (_name, raw, infl, r, path), n in zip(cases, n_ctrl_by_case, strict=True):
        corr = build_corridor(infl, path, radius=r)
        n = min(n, len(corr.path_s) - 1)
        t = clamped_uniform_knots(n, 3, (0.0, corr.length_m))
        t0 = time.perf_counter()
        spl = make_lsq_spline(corr.path_s, corr.path_points, t, k=3)
        times.append(time.perf_counter() - t0)
        u = np.linspace(0, corr.length_m, int(corr.length_m / raw.resolution * 8) + 2)
        xy = spl(u)
        if (
            not np.all(np.isfinite(xy))
            or points_clearance(xy, raw, r + raw.resolution).min() < r - 1e-9
        ):
            viol += 1
    return times, viol


def summarise(label, recs):
    ok = [r for r in recs if r["ok"]]
    solve = [r["solve_s"] * 1e3 for r in ok]
    total = [r["total_s"] * 1e3 for r in ok]
    builds = [r["build_s"] * 1e3 for r in ok if r["build_s"] > 0]
    margin = [r["margin_m"] for r in ok]
    row = {
        "label": label,
        "n": len(recs),
        "success": len(ok) / max(1, len(recs)),
        "solve_med": pct(solve, 50),
        "solve_p95": pct(solve, 95),
        "total_med": pct(total, 50),
        "total_p95": pct(total, 95),
        "build_med": pct(builds, 50),
        "build_max": max(builds) if builds else float("nan"),
        "refined": sum(1 for r in ok if r["attempts"] > 1),
        "margin_min": min(margin) if margin else float("nan"),
    }
    print(
        f"{label:<34} n={row['n']:3d} success={row['success']:.1%} "
        f"solve med/p95 {row['solve_med']:.2f}/{row['solve_p95']:.2f} ms, "
        f"fit total med/p95 {row['total_med']:.2f}/{row['total_p95']:.2f} ms, "
        f"first build med/max {row['build_med']:.0f}/{row['build_max']:.0f} ms, "
        f"refined {row['refined']}, min margin {row['margin_min']:.2e} m"
    )
    return row


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=40, help="shared-map scenarios (QP)")
    ap.add_argument("--kappa-n", type=int, default=16, help="scenarios with the curvature bound")
    ap.add_argument("--reps", type=int, default=3, help="warm repetitions per scenario")
    ap.add_argument("--write", type=Path, default=None, help="write a markdown summary here")
    args = ap.parse_args()

    t0 = time.perf_counter()
    cases = scenarios(args.n)
    pcases = paper_cases()
    print(
        f"{len(cases)} shared-map scenarios ({time.perf_counter() - t0:.1f} s to load and search),"
        f" {len(pcases)} paper targets; path cells median "
        f"{np.median([len(c[4].cells) for c in cases]):.0f}"
    )
    rows = []
    qp = Smoother()
    recs = run_set(cases, qp, args.reps)
    rows.append(summarise("QP (piqp), shared maps", recs))
    rows.append(summarise("QP (piqp), paper A-D", run_set(pcases, qp, args.reps)))
    rows.append(
        summarise("QP (osqp), shared maps", run_set(cases, Smoother(qp_solver="osqp"), args.reps))
    )
    n_ctrl = [r.get("n_ctrl", 40) for r in recs]
    ptimes, viol = peer(cases, n_ctrl)
    print(
        f"peer scipy make_lsq_spline: median {np.median(ptimes) * 1e3:.2f} ms, clearance "
        f"violated on {viol}/{len(cases)} ({viol / max(1, len(cases)):.0%}); ratio of medians "
        f"smoother fit / lsq = {rows[0]['total_med'] / (np.median(ptimes) * 1e3):.1f}x"
    )
    kcases = cases[: args.kappa_n]
    krows = []
    for label, cs in (
        ("curvature bound, shared maps", kcases),
        ("curvature bound, paper A-D", pcases),
    ):
        recs_k = []
        for c in cs:
            sm = Smoother(kappa_max=1.0 / (2.0 * c[3]), time_budget_s=30.0)
            recs_k += run_set([c], sm, max(1, args.reps - 1))
        krows.append(summarise(label, recs_k))
    rows += krows
    # cold build of fresh sizes (cache cleared): the QP's conic and the layout of the SCP's
    # sample rows (the SCP's QPs go to piqp directly: nothing else to build)
    smoother_qp.qp_solver.cache_clear()
    smoother_layout.constraint_layout.cache_clear()
    tb = []
    for nb in (64, 128):
        t0 = time.perf_counter()
        smoother_qp.qp_solver(nb, 3, "piqp", 0, False)
        tq = time.perf_counter() - t0
        t0 = time.perf_counter()
        smoother_layout.constraint_layout(nb, 3, CURV_SAMPLES)
        tb.append((nb, tq, time.perf_counter() - t0))
        print(
            f"cold build nb={nb}: piqp conic {tq * 1e3:.1f} ms, SCP row layout "
            f"{tb[-1][2] * 1e3:.1f} ms"
        )
    if args.write:
        write_md(args, rows, ptimes, viol, len(cases), tb)


def write_md(args, rows, ptimes, viol, ncases, tb):
    import os

    lines = [
        "## Smoother (`benchmarks/bench_smoother.py`)",
        "",
        f"Rerun: `python benchmarks/bench_smoother.py --n {args.n} --kappa-n {args.kappa_n} "
        f"--reps {args.reps} --write /tmp/smoother_results.md`",
        "",
        f"Machine: {platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}; "
        f"load average at the end {os.getloadavg()[0]:.1f} (the machine was shared: wall times "
        "are inflated, most for IPOPT).",
        "",
        "A* paths of 100-500 cells on the shared Moving AI maps (radius 2.5 cells) and ROS maps "
        "(0.2 m); curvature bound `kappa_max = 1/(2 r)`. *solve* = solver calls only (warm, "
        "solvers cached); *fit* = the whole `Smoother.fit` incl. problem assembly and the "
        "certificate; *first build* = solver construction for a new padded size.",
        "",
        "| case | n | success | solve med / p95 (ms) | fit med / p95 (ms) | first build med / max (ms) | refined | min margin (m) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['label']} | {r['n']} | {r['success']:.0%} | {r['solve_med']:.2f} / {r['solve_p95']:.2f} "
            f"| {r['total_med']:.2f} / {r['total_p95']:.2f} | {r['build_med']:.0f} / {r['build_max']:.0f} "
            f"| {r['refined']} | {r['margin_min']:.1e} |"
        )
    lines += [
        "",
        f"Peer, scipy `make_lsq_spline` on the same points (uniform knots, same number of control "
        f"points): median {np.median(ptimes) * 1e3:.2f} ms; it violated the clearance on "
        f"{viol}/{ncases} scenarios ({viol / max(1, ncases):.0%}); the smoother on none "
        "(every returned curve is certified).",
        "",
        "Cold builds: "
        + "; ".join(
            f"nb={nb}: piqp conic {tq * 1e3:.1f} ms, SCP row layout {ti * 1e3:.1f} ms"
            for nb, tq, ti in tb
        ),
        "",
    ]
    args.write.parent.mkdir(parents=True, exist_ok=True)
    args.write.write_text("\n".join(lines))
    print(f"wrote {args.write}")


if __name__ == "__main__":
    main()
