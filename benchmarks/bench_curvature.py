"""Benchmark of the curvature-bounded smoother with both A* seeds (issue 8, section 3).

On scenarios drawn from the shared Moving AI maps (robot radius 2.5 cells) and ROS maps
(radius 0.2 m), for the shortest-path seed and the clearance-aware seed
(:func:`astar.clearance_cost`), each with the corridor's 45-degree bridges, plans with
``Planner(..., smoother=Smoother(kappa_max=1 / (2 r)))`` (the smoother along the A* path,
then, if it fails, the planner's witness rescue along a curvature witness) and reports side
by side:

* success rate of the curvature-bounded smoother (a certified curve returned);
* median and p95 warm solve time: the whole smoothing stage (QP, SCP, certificate; for a
  rescued query also the witness search and the second fit) and the solver time alone
  (for a rescued query, the whole stage), each the best of ``--repeats`` calls of the same
  query after an untimed first call (solvers built). The best of repeats, because the
  shared VM this was written on takes the CPU away for 0.1-2 s in a good fraction of calls;
  the outcome of a query is the same in every call (the pipeline is deterministic);
* median minimum clearance over the radius (dense samples against the raw map);
* median Hausdorff deviation from the A* polyline (cells) and the length ratio;
* near-stops of the timed trajectory (``time_parameterize`` with ``Robot(radius=r)``):
  intervals inside the path (not touching its start or end) where the speed is below
  20 % of ``v_max``.

Targets (issue 8): success >= 98 % of *feasible* scenarios, median <= 10 ms, p95 <= 50 ms.
A random query may admit no curve of bounded curvature at all (a pocket reached through a
passage narrower than the turning radius). Every failure is therefore handed to
:func:`trajopt.planning._feasibility.curvature_witness` (a hybrid A* over arcs of radius
``1 / kappa_max`` with exact clearance checks): a failure with a witness is a failure on a
feasible query; one without is counted apart (probably infeasible, not proven). A success is
its own witness, so the success rate over feasible queries is
``successes / (successes + failures with a witness)``.

Run: ``python benchmarks/bench_curvature.py [--per-map 25] [--seed 0] [--repeats 5]``
(``TRAJOPT_DATA`` may point to the shared data).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from pathlib import Path

import numpy as np
from scipy.spatial.distance import directed_hausdorff

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import astar  # noqa: E402
from trajopt._planner import Planner  # noqa: E402
from trajopt.errors import SmoothingError, TimingError  # noqa: E402
from trajopt.planning._feasibility import curvature_witness  # noqa: E402
from trajopt.robot._robot import Robot  # noqa: E402
from trajopt.smoother import Smoother  # noqa: E402

MOVINGAI = ["arena", "den312d", "Berlin_0_256", "rmtst01", "random512-40-5"]
ROS = ["turtlebot3_world", "smoothers_world", "depot", "willow-2010-02-18-0.10"]


def data_dir() -> Path:
    env = os.environ.get("TRAJOPT_DATA")
    return Path(env) if env else ROOT.parent / "shared" / "data"


def load_maps() -> list[tuple[str, object, float]]:
    d = data_dir()
    out = []
    for name in MOVINGAI:
        raw = astar.load_map(d / "movingai" / "maps" / f"{name}.map")
        out.append((name, raw, 2.5 * raw.resolution))
    for name in ROS:
        out.append((name, astar.load_map(d / "ros" / f"{name}.yaml"), 0.2))
    return out


def draw_pairs(raw, radius: float, n: int, rng: np.random.Generator):
    """``n`` start/goal cell pairs, free after inflation, reachable, 20-300 cells apart."""
    infl = astar.inflate(raw, radius, metric="square", outside_occupied=True)
    ys, xs = np.nonzero(~infl.occupied)
    if len(xs) < 2:
        return infl, []
    pairs = []
    for _ in range(200 * n):
        if len(pairs) == n:
            break
        i, j = rng.choice(len(xs), 2, replace=False)
        a, b = (int(xs[i]), int(ys[i])), (int(xs[j]), int(ys[j]))
        if not 20 <= math.hypot(a[0] - b[0], a[1] - b[1]) <= 300:
            continue
        try:
            astar.find_path(infl, a, b)
        except astar.NoPathError:
            continue
        pairs.append((a, b))
    return infl, pairs


def near_stops(traj, v_max: float) -> int:
    """Intervals with speed < 0.2 v_max that touch neither end of the trajectory."""
    smp = traj.sample_uniform(0.01)
    slow = smp.v < 0.2 * v_max
    if not slow.any():
        return 0
    edges = np.diff(slow.astype(np.int8))
    starts = np.nonzero(edges == 1)[0] + 1
    ends = np.nonzero(edges == -1)[0] + 1
    if slow[0]:
        ends = ends[1:]
    if slow[-1]:
        starts = starts[:-1]
    return int(min(len(starts), len(ends)))


def run_case(raw, infl, radius, a, b, cost, planner, repeats=1):
    """One query through ``planner.plan`` (smoother, witness rescue, timing), timed warm:
    the best of ``repeats`` calls (the first call, which builds new solver sizes, is not
    timed)."""
    path = astar.find_path(infl, a, b, cost=cost)
    p0, p1 = raw.cell_to_world(np.array(a)), raw.cell_to_world(np.array(b))
    try:
        planner.plan(p0, p1)  # builds any new solver size
    except (SmoothingError, TimingError):
        pass
    try:
        best_smooth = best_solve = wall = math.inf
        for _ in range(repeats):
            t0 = time.perf_counter()
            traj = planner.plan(p0, p1)
            wall = min(wall, time.perf_counter() - t0)
            smooth_s = traj.stats["stages_s"]["smooth"]
            st = traj.stats["smoother"]
            best_smooth = min(best_smooth, smooth_s)
            # a rescued query's solver time is the whole smoothing stage (both fits, witness)
            best_solve = min(best_solve, smooth_s if st["rescue"] else st["solve_time_s"])
    except (SmoothingError, TimingError) as exc:
        t0 = time.perf_counter()
        w = curvature_witness(raw, radius, p0, p1, planner.smoother.kappa_max, time_limit_s=20.0)
        return {
            "ok": False,
            "why": str(exc),
            "witness": w is not None,
            "witness_s": time.perf_counter() - t0,
        }
    sp = traj.steps.smooth_path
    st = traj.stats["smoother"]
    rescued = st["rescue"] is not None
    res = raw.resolution
    u = np.linspace(*sp.domain, max(200, int(sp.length / res * 4)))
    xy = sp(u) / res
    poly = raw.cell_to_world(path.cells) / res
    haus = max(directed_hausdorff(xy, poly)[0], directed_hausdorff(poly, xy)[0])
    return {
        "ok": True,
        "wall": best_smooth,
        "solve": best_solve,
        "plan": wall,
        "rescued": rescued,
        "clear_ratio": sp.certificate.min_clearance_m / radius,
        "hausdorff": haus,
        "length_ratio": sp.length / (path.length * res),
        "attempts": st["attempts"],
        "near_stops": near_stops(traj, planner.robot.v_max),
    }


def pct(values, q):
    return float(np.percentile(values, q)) if len(values) else float("nan")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--per-map", type=int, default=25, help="scenarios per map")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument(
        "--repeats",
        type=int,
        default=5,
        help="timed calls per query; the best is reported (default 5)",
    )
    args = ap.parse_args()
    if args.repeats < 1:
        ap.error(f"--repeats must be >= 1, got {args.repeats}")
    rng = np.random.default_rng(args.seed)
    cases = []
    for name, raw, r in load_maps():
        infl, pairs = draw_pairs(raw, r, args.per_map, rng)
        cost = astar.clearance_cost(raw, r, outside_occupied=True)
        cases += [(name, raw, infl, r, a, b, cost) for a, b in pairs]
    print(f"{len(cases)} scenarios on {len(MOVINGAI) + len(ROS)} maps")
    table = {}
    failures = {}
    for seed_name in ("shortest", "clearance"):
        recs = []
        fails = []
        planners = {}
        for name, raw, infl, r, a, b, cost in cases:
            if name not in planners:
                sm = Smoother(kappa_max=1.0 / (2.0 * r), time_budget_s=10.0)
                planners[name] = Planner(raw, Robot(radius=r), search=seed_name, smoother=sm)
            c = cost if seed_name == "clearance" else None
            rec = run_case(raw, infl, r, a, b, c, planners[name], args.repeats)
            rec["map"] = name
            recs.append(rec)
            if not rec["ok"]:
                wit = "witness found" if rec["witness"] else "no witness"
                fails.append(f"{name} {a}->{b} ({wit}): {rec['why'][:110]}")
        ok = [x for x in recs if x["ok"]]
        feasible = len(ok) + sum(1 for x in recs if not x["ok"] and x["witness"])
        table[seed_name] = {
            "success": f"{len(ok)}/{len(recs)} ({len(ok) / max(1, len(recs)):.1%})",
            "success on feasible": f"{len(ok)}/{feasible} ({len(ok) / max(1, feasible):.1%})",
            "failures without witness": f"{len(recs) - feasible}",
            "fit median ms": f"{1e3 * pct([x['wall'] for x in ok], 50):.1f}",
            "fit p95 ms": f"{1e3 * pct([x['wall'] for x in ok], 95):.1f}",
            "solver median ms": f"{1e3 * pct([x['solve'] for x in ok], 50):.1f}",
            "solver p95 ms": f"{1e3 * pct([x['solve'] for x in ok], 95):.1f}",
            "min clearance / r (median)": f"{pct([x['clear_ratio'] for x in ok], 50):.2f}",
            "Hausdorff to A* (cells, median)": f"{pct([x['hausdorff'] for x in ok], 50):.2f}",
            "length ratio (median)": f"{pct([x['length_ratio'] for x in ok], 50):.3f}",
            "near-stops (total)": f"{int(np.nansum([x['near_stops'] for x in ok]))}",
            "refined (attempts > 1)": f"{sum(x['attempts'] > 1 for x in ok)}",
            "rescued along a witness": f"{sum(x['rescued'] for x in ok)}",
        }
        failures[seed_name] = fails
    keys = list(table["shortest"])
    w = max(len(k) for k in keys)
    print(f"\n{'':{w}}  {'shortest seed':>16}  {'clearance seed':>16}")
    for k in keys:
        print(f"{k:{w}}  {table['shortest'][k]:>16}  {table['clearance'][k]:>16}")
    for seed_name, fails in failures.items():
        for f in fails:
            print(f"failed ({seed_name}): {f}")


if __name__ == "__main__":
    main()
