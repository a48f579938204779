"""Car-like robots end to end: trajopt.plan (Hybrid-A*, segments, certified splines, timing) vs OMPL.

Queries: the shared suite (``trajopt.analysis.bench`` ``shared-full``: the feasible Moving AI
scenarios at robot radius 2.5 cells and seeded random pairs on the ROS maps at 0.165 m; at most
``--limit`` per map), each with seeded random start and goal headings
(:func:`trajopt.analysis.bench._suites.with_headings`: uniform in ``[-pi, pi)``,
``numpy.random.default_rng([seed, crc32(map name), query index])``, the headings of
``bench_hybrid.py``); minimum turning radius ``R = 2 x robot radius``.

Methods (``trajopt.bench``, scored by the same independent checks,
:mod:`trajopt.analysis.bench._car`):

* ``trajopt-ackermann`` / ``trajopt-ackermann-forward``: ``trajopt.Planner`` with
  ``Robot(radius, drive="ackermann", min_turning_radius=R, reverse=True / False)``,
  ``plan(start, goal, start_heading=..., goal_heading=...)``: the whole pipeline, timed;
* ``ompl-reedsshepp`` / ``ompl-dubins``: OMPL's RRT* in ``ReedsSheppStateSpace(R)`` /
  ``DubinsStateSpace(R)`` on the grid inflated by the radius (state valid when its cell is
  free, motions checked every 0.2 cells), stopped at its first exact solution or 2 s, then
  ``simplifySolution`` (0.2 s at most). OMPL's path is not timed: it is compared by length
  (and cusps, reverse length); its time is the time to its first solution.

Reported per mode (reverse: Reeds-Shepp; forward only: Dubins): trajopt's success among the
queries OMPL solved (target of issue 36: >= 98 %), the failure classes, the independent checks
(collisions: clearance below the radius on dense samples against the raw map; curvature above
``1/R`` by circles through three points 0.05 cells apart within each stretch between cusps;
``|v|`` at every cusp; the angle between each displacement and the heading (or its reverse);
the end headings), the plans that rest between cusps (a stretch fitted in pieces), median
plan time on the maps of at most 256 x 256 cells beside OMPL's time
to its first solution, the Hybrid-A* search alone (its stage, 2-D heuristic included), cusps
and reverse length per plan against OMPL's.

Run: ``python benchmarks/bench_car.py [--limit 10] [--seed 0] [--workers 2] [--out DIR]
[--no-ompl]``. Needs the shared data (``$TRAJOPT_DATA`` or ``../shared/data``; skipped with a
message when absent) and the ``bench`` extra; the OMPL rows need the ``ompl`` wheel (skipped
with a message when not importable).
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

MODES = {
    "reverse (Reeds-Shepp)": ("trajopt-ackermann", "ompl-reedsshepp"),
    "forward only (Dubins)": ("trajopt-ackermann-forward", "ompl-dubins"),
}
SMALL_CELLS = 256 * 256


def failure_class(failure: str, note: str) -> str:
    """A short class of a failed row, from its error type and message."""
    if failure == "InvalidInputError" and "blocked on the car's search grid" in note:
        return "end cell blocked on the car's search grid (radius + 0.76 cells)"
    if failure == "NoPathError":
        for reason in ("exhausted", "time_budget", "disconnected", "expansions"):
            if f"({reason})" in note or reason in note.split(":")[0]:
                return f"NoPathError ({reason})"
        return "NoPathError"
    if failure == "SmoothingError":
        seg = "backwards" if "backwards segment" in note else "forwards"
        return f"SmoothingError ({seg} segment, no certified curve within 1/R)"
    return failure or "?"


def _med(x) -> float:
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    return float(np.median(x)) if len(x) else math.nan


def _pct(x, q) -> float:
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    return float(np.percentile(x, q)) if len(x) else math.nan


def report(df, cells: dict[str, int], have_ompl: bool) -> str:
    """The text report of a car dataset (module docstring)."""
    lines = []
    for mode, (mt, mo) in MODES.items():
        t = df[df["method"] == mt].set_index("query_id")
        if not len(t):
            continue
        n = len(t)
        ok = t[t["ok"]]
        lines.append(f"\n[{mode}] {n} queries; {mt}" + (f" vs {mo}" if have_ompl else ""))
        lines.append(f"  trajopt success        {len(ok)}/{n} = {100 * len(ok) / n:.1f} %")
        fails = t[~t["ok"]]
        classes: dict[str, int] = {}
        for f, note in zip(fails["failure"], fails["note"], strict=True):
            c = failure_class(f, note)
            classes[c] = classes.get(c, 0) + 1
        for c, k in sorted(classes.items(), key=lambda kv: -kv[1]):
            lines.append(f"    failure: {k:3d} x {c}")
        if len(ok):
            lines.append(
                "  checks (trajopt plans): collisions {}, rows with curvature > 1/R {} "
                "(max kappa R {:.6f}), max |v| at cusps {:.1e} m/s, max angle motion/heading "
                "{:.1e} rad, max end heading error {:.1e} rad, max end position error {:.1e} m".format(
                    int(ok["collision"].sum()),
                    int((ok["curvature_violations"] > 0).sum()),
                    float(ok["kappa_over_kmax"].max()),
                    float(np.nan_to_num(ok["cusp_speed_max_mps"]).max()),
                    float(ok["heading_motion_error_rad"].max()),
                    float(ok["end_heading_error_rad"].max()),
                    float(
                        np.max(
                            np.abs(
                                ok[
                                    [
                                        "start_error_x_m",
                                        "start_error_y_m",
                                        "end_error_x_m",
                                        "end_error_y_m",
                                    ]
                                ].to_numpy()
                            )
                        )
                    ),
                )
            )
            small = ok[ok["map"].map(cells) <= SMALL_CELLS]
            rt = 1e3 * ok["runtime_s"]
            lines.append(
                f"  trajopt plan time      median {_med(rt):.0f} ms, p95 {_pct(rt, 95):.0f} ms "
                f"(all maps); maps <= 256 x 256: median {_med(1e3 * small['runtime_s']):.0f} ms "
                f"({len(small)} plans; target <= 100 ms)"
            )
            lines.append(
                f"  Hybrid-A* search alone median {_med(1e3 * ok['stage_search_s']):.1f} ms "
                f"(2-D heuristic {_med(1e3 * ok['hybrid_heuristic_s']):.1f} ms, expansions "
                f"{_med(1e3 * ok['hybrid_search_s']):.1f} ms); maps <= 256 x 256: "
                f"{_med(1e3 * small['stage_search_s']):.1f} ms"
            )
            st = {
                k: _med(1e3 * ok[f"stage_{k}_s"])
                for k in ("inflate", "corridor", "smooth", "timing")
            }
            fits = ok["corridor"].fillna("").str.count(",") + 1
            joins = fits - 1 - ok["cusps"]  # joins of stretches fitted in pieces
            rests = ok["rests"] if "rests" in ok else joins
            lines.append(
                f"  rests between cusps    {int((rests > 0).sum())} plans "
                f"({int(rests.sum())} of the {int(joins.sum())} joins of stretches fitted in "
                "pieces; the others are driven through)"
            )
            lines.append(
                "  trajopt stages median  "
                + ", ".join(f"{k} {v:.1f} ms" for k, v in st.items())
                + f"; duration median {_med(ok['duration_s']):.1f} s"
            )
        if not have_ompl:
            continue
        o = df[df["method"] == mo].set_index("query_id").reindex(t.index)
        ook = o[o["ok"].fillna(False).astype(bool)]
        oclean = ook[~ook["collision"].astype(bool)]
        lines.append(f"  OMPL success           {len(ook)}/{n} = {100 * len(ook) / n:.1f} %")
        both = ook.index.intersection(ok.index)
        lines.append(
            f"  trajopt | OMPL solved  {len(both)}/{len(ook)} = "
            f"{100 * len(both) / max(len(ook), 1):.1f} %  (target >= 98 %)"
        )
        bc = oclean.index.intersection(ok.index)
        lines.append(
            f"  trajopt | OMPL solved without collision  {len(bc)}/{len(oclean)} = "
            f"{100 * len(bc) / max(len(oclean), 1):.1f} %"
        )
        missed = t.loc[ook.index.difference(ok.index)]
        mc: dict[str, int] = {}
        for f, note in zip(missed["failure"], missed["note"], strict=True):
            c = failure_class(f, note)
            mc[c] = mc.get(c, 0) + 1
        for c, k in sorted(mc.items(), key=lambda kv: -kv[1]):
            lines.append(f"    OMPL solved, trajopt failed: {k:3d} x {c}")
        lines.append(f"  trajopt solved, OMPL did not: {len(ok.index.difference(ook.index))}")
        lines.append(
            "  checks (OMPL paths): collisions {} (its checker tests cell centres every 0.2 "
            "cells), rows with curvature > 1/R {}".format(
                int(ook["collision"].sum()), int((ook["curvature_violations"] > 0).sum())
            )
        )
        osmall = ook[ook["map"].map(cells) <= SMALL_CELLS]
        lines.append(
            f"  OMPL first solution    median {_med(1e3 * ook['first_solution_s']):.0f} ms, p95 "
            f"{_pct(1e3 * ook['first_solution_s'], 95):.0f} ms (all maps); maps <= 256 x 256: "
            f"median {_med(1e3 * osmall['first_solution_s']):.0f} ms; with simplification "
            f"median {_med(1e3 * ook['runtime_s']):.0f} ms"
        )
        if len(both):
            a, b = ok.loc[both], ook.loc[both]
            lines.append(
                f"  on the {len(both)} queries both solved: cusps per plan mean trajopt "
                f"{a['cusps'].mean():.2f} | OMPL {b['cusps'].mean():.2f}; reverse length per "
                f"plan mean trajopt {a['reverse_length_m'].mean():.2f} m | OMPL "
                f"{b['reverse_length_m'].mean():.2f} m; length ratio trajopt / OMPL median "
                f"{_med(a['length_m'].to_numpy() / b['length_m'].to_numpy()):.3f}"
            )
    return "\n".join(lines)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--limit", type=int, default=10, help="queries per map")
    ap.add_argument("--seed", type=int, default=0, help="seed of the headings")
    ap.add_argument("--suite", default="shared-full")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--scheduler", default="local", help="'local', 'serial' or a Dask address")
    ap.add_argument("--out", default=None, help="dataset folder (default: a temporary one)")
    ap.add_argument("--no-ompl", action="store_true")
    args = ap.parse_args()

    import astar
    from trajopt.analysis import bench
    from trajopt.analysis.bench._suites import data_dir, with_headings
    from trajopt.errors import BenchmarkError

    try:
        maps = with_headings(bench.suite(args.suite, limit=args.limit), args.seed)
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
            print(f"OMPL rows skipped: ompl not importable ({e}); pip install ompl")
            have_ompl = False
    methods = [m for pair in MODES.values() for m in (pair if have_ompl else pair[:1])]
    cells = {}
    for mq in maps:
        cells[mq.map_name] = int(np.asarray(astar.load_map(mq.map_path).occupied).size)
    out = Path(args.out) if args.out else Path(tempfile.mkdtemp(prefix="bench_car-")) / "ds"
    t0 = time.perf_counter()
    s = bench.run(
        maps,
        out,
        methods=methods,
        scheduler=args.scheduler,
        workers=args.workers,
        progress=False,
        resume=bool(args.out),
    )
    wall = time.perf_counter() - t0
    df = bench.read_dataset(out)
    nq = sum(len(mq.queries) for mq in maps)
    print(
        f"bench_car: {args.suite}, limit {args.limit}/map, {nq} queries on {len(maps)} maps, "
        f"heading seed {args.seed}, R = 2 x radius; {s.workers} worker(s), {wall:.0f} s; "
        f"dataset {out}"
    )
    print(report(df, cells, have_ompl))
    return 0


if __name__ == "__main__":
    sys.exit(main())
