"""How often the smoother solves a Moving AI scenario, how often the stop-and-turn fallback
does, and how often planning fails (issue 7, section 2).

Every scenario of the shared Moving AI maps (or ``--limit-per-map`` of them, evenly spread
over the buckets as ``trajopt bench`` picks them) is planned by one ``trajopt.Planner`` per
map with ``fallback="stop_and_turn"``, a robot of radius 2.5 cells (the setup of
``trajopt bench`` and ``benchmarks/bench_curvature.py``: ``Robot(radius=2.5 * resolution)``,
default limits, 1 m cells) and the default smoother (``--kappa off``) or the curvature-bounded
one ``Smoother(kappa_max=1 / (2 r))`` (``--kappa on``). Outcomes:

* ``smoother``: a smooth, certified trajectory;
* ``fallback``: the stop-and-turn trajectory along the A* polyline; each one is also checked
  independently: ``trajopt.metrics.path_metrics`` samples the polyline every 0.05 cells and
  measures the distance to the raw map (outside occupied), ``fb collide`` counts those
  closer than the radius (expected 0);
* ``failed``: any other error, by type (e.g. a ``SmoothingError`` whose polyline failed the
  planner's clearance check);
* not counted as failures, reported apart: ``infeasible`` (start or goal closer than the
  radius to an obstacle or blocked by the inflation: ``InvalidInputError``) and ``no path``
  (no path for the radius on the inflated grid: ``NoPathError``).

Percentages are of the solvable scenarios (all minus infeasible minus no path).

Most Moving AI scenarios start or end next to a wall (a cell of clearance 0.5), which a
robot of radius 2.5 cells cannot reach: ``--snap K`` moves such an end point to the nearest
cell centre that is free on the planner's inflated grid, if one lies within ``K`` cells
(Euclidean; ties broken by ``scipy.ndimage.distance_transform_edt``), else the scenario
stays infeasible. Snapped runs measure the planner on more queries; they are not the
benchmark's own queries.

Run::

    python benchmarks/bench_fallback.py --maps arena den312d            # every scenario
    python benchmarks/bench_fallback.py --maps Boston_0_1024 --limit-per-map 200 --kappa both
    python benchmarks/bench_fallback.py --maps arena den312d --snap 4

``TRAJOPT_DATA`` may point to the shared data (default ``../shared/data`` beside the repo).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from collections import Counter
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import astar  # noqa: E402
from trajopt._planner import Planner  # noqa: E402
from trajopt.analysis.bench._suites import select_evenly as select_scenarios  # noqa: E402
from trajopt.analysis.metrics import path_metrics  # noqa: E402
from trajopt.errors import InvalidInputError, NoPathError, TrajoptError  # noqa: E402
from trajopt.motion._stop_and_turn import StopAndTurnTrajectory  # noqa: E402
from trajopt.robot._robot import Robot  # noqa: E402
from trajopt.smoother import Smoother  # noqa: E402

MAPS = [
    "arena",
    "den312d",
    "rmtst01",
    "Berlin_0_256",
    "random512-40-5",
    "maze512-1-0",
    "Boston_0_1024",
]
RADIUS_CELLS = 2.5


def data_dir() -> Path:
    env = os.environ.get("TRAJOPT_DATA")
    return Path(env) if env else ROOT.parent / "shared" / "data"


def snapper(inflated, max_cells: float):
    """``cell -> cell``: the nearest cell free on ``inflated`` within ``max_cells``, or the
    cell itself (then the planner reports it as infeasible)."""
    from scipy.ndimage import distance_transform_edt

    dist, idx = distance_transform_edt(inflated.occupied, return_indices=True)

    def snap(cell):
        ix, iy = int(cell[0]), int(cell[1])
        if dist[iy, ix] == 0 or dist[iy, ix] > max_cells:
            return (ix, iy)
        return (int(idx[1][iy, ix]), int(idx[0][iy, ix]))

    return snap


def run_map(name: str, kappa: bool, limit: int | None, data: Path, snap: float = 0.0) -> dict:
    grid = astar.load_map(data / "movingai" / "maps" / f"{name}.map")
    scen = astar.read_scenarios(data / "movingai" / "scen" / f"{name}.map.scen")
    if limit is not None:
        scen = select_scenarios(scen, limit)
    radius = RADIUS_CELLS * grid.resolution
    smoother = Smoother(kappa_max=1.0 / (2.0 * radius)) if kappa else Smoother()
    planner = Planner(grid, Robot(radius=radius), smoother=smoother, fallback="stop_and_turn")
    move = snapper(planner.inflated_grid, snap) if snap > 0 else tuple
    counts: Counter[str] = Counter()
    times: dict[str, list[float]] = {"smoother": [], "fallback": []}
    fb_clear: list[float] = []
    reasons: Counter[str] = Counter()
    examples: list[str] = []
    t_map = time.perf_counter()
    for i, sc in enumerate(scen):
        start = grid.cell_to_world(move(sc.start))
        goal = grid.cell_to_world(move(sc.goal))
        t0 = time.perf_counter()
        try:
            traj = planner.plan(start, goal)
        except InvalidInputError:
            counts["infeasible"] += 1
        except NoPathError:
            counts["no path"] += 1
        except (TrajoptError, astar.AstarError) as exc:
            counts[f"failed: {type(exc).__name__}"] += 1
            if len(examples) < 5:
                examples.append(f"{sc.start}->{sc.goal}: {str(exc).splitlines()[0][:140]}")
        else:
            kind = "fallback" if isinstance(traj, StopAndTurnTrajectory) else "smoother"
            counts[kind] += 1
            times[kind].append(time.perf_counter() - t0)
            if kind == "fallback":
                reasons[reason_of(traj.stats)] += 1
                m = path_metrics(
                    traj.path,
                    grid=grid,
                    reference=traj.steps.grid_path.to_world(grid),
                    radius=radius,
                    sample_spacing=0.05 * grid.resolution,
                    border_occupied=True,
                )
                fb_clear.append(m.min_clearance_m / radius)
                if m.collision:
                    counts["fallback collisions"] += 1
        if (i + 1) % 25 == 0 or i + 1 == len(scen):
            sys.stderr.write(
                f"\r{name} kappa={'on' if kappa else 'off'}: {i + 1}/{len(scen)} "
                f"{time.perf_counter() - t_map:.0f} s   "
            )
            sys.stderr.flush()
    sys.stderr.write("\n")
    return {
        "map": name,
        "n": len(scen),
        "counts": counts,
        "times": times,
        "fb_clear": fb_clear,
        "examples": examples,
        "reasons": reasons,
        "wall_s": time.perf_counter() - t_map,
    }


def reason_of(stats: dict) -> str:
    """A short group name for why the smoother (or timing) failed: the last attempt's failure
    up to its first colon, e.g. ``certificate``, ``curvature bound (scp)``, ``time budget
    exhausted``; ``TimingError`` for a timing failure."""
    if stats.get("fallback_error") != "SmoothingError":
        return str(stats.get("fallback_error"))
    msg = str(stats.get("fallback_reason", "")).splitlines()[0]
    tail = msg.split("): ", 1)[1] if "): " in msg else msg
    return tail.split(":", 1)[0].strip()[:60]


def pct(k: int, n: int) -> str:
    return f"{k} ({100.0 * k / n:.1f}%)" if n else f"{k}"


def med_ms(values: list[float]) -> str:
    return f"{1e3 * float(np.median(values)):.0f}" if values else "-"


def print_table(rows: list[dict], kappa: bool, snap: float) -> None:
    title = "kappa_max = 1/(2r)" if kappa else "no curvature bound (default Smoother)"
    ends = f"end points snapped within {snap:g} cells" if snap > 0 else "exact end points"
    print(f"\n## {title}; robot radius {RADIUS_CELLS} cells; {ends}; fallback='stop_and_turn'\n")
    head = (
        "| map | scenarios | infeasible | no path | solvable | smoother | fallback | failed "
        "| fb collide | fb min clear/r | median ms smooth/fb | wall s |"
    )
    print(head)
    print("|" + "---|" * (head.count("|") - 1))
    total: Counter[str] = Counter()
    tot_n = 0
    all_times: dict[str, list[float]] = {"smoother": [], "fallback": []}
    all_clear: list[float] = []
    wall = 0.0
    for r in rows + [None]:
        if r is None:
            c, n, name = total, tot_n, "**total**"
            times, clear, w = all_times, all_clear, wall
        else:
            c, n, name = r["counts"], r["n"], r["map"]
            times, clear, w = r["times"], r["fb_clear"], r["wall_s"]
            total.update(c)
            tot_n += n
            for k in all_times:
                all_times[k] += times[k]
            all_clear += clear
            wall += w
        failed = {k[8:]: v for k, v in c.items() if k.startswith("failed: ")}
        nf = sum(failed.values())
        solvable = n - c["infeasible"] - c["no path"]
        fail_txt = pct(nf, solvable) + (
            " " + ", ".join(f"{k} {v}" for k, v in sorted(failed.items())) if failed else ""
        )
        min_clear = f"{min(clear):.3f}" if clear else "-"
        print(
            f"| {name} | {n} | {c['infeasible']} | {c['no path']} | {solvable} "
            f"| {pct(c['smoother'], solvable)} | {pct(c['fallback'], solvable)} | {fail_txt} "
            f"| {c['fallback collisions']} | {min_clear} "
            f"| {med_ms(times['smoother'])}/{med_ms(times['fallback'])} | {w:.0f} |"
        )
    for r in rows:
        if r["reasons"]:
            why = ", ".join(f"{k} {v}" for k, v in r["reasons"].most_common())
            print(f"fallback reasons ({r['map']}): {why}")
    for r in rows:
        for ex in r["examples"]:
            print(f"failed ({r['map']}): {ex}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--maps",
        nargs="+",
        default=MAPS,
        choices=MAPS,
        metavar="MAP",
        help=f"Moving AI maps (default all: {' '.join(MAPS)})",
    )
    ap.add_argument(
        "--limit-per-map",
        type=int,
        default=None,
        help="scenarios per map, evenly spread over the buckets (default all)",
    )
    ap.add_argument(
        "--kappa",
        choices=("off", "on", "both"),
        default="off",
        help="curvature bound 1/(2r) in the smoother (default off)",
    )
    ap.add_argument(
        "--snap",
        type=float,
        default=0.0,
        metavar="K",
        help="move infeasible end points to the nearest free cell within K cells (default 0: off)",
    )
    args = ap.parse_args()
    if args.limit_per_map is not None and args.limit_per_map < 1:
        ap.error(f"--limit-per-map must be >= 1, got {args.limit_per_map}")
    data = data_dir()
    if not (data / "movingai").is_dir():
        ap.error(f"shared map data not found at {data} (set TRAJOPT_DATA)")
    settings = {"off": [False], "on": [True], "both": [False, True]}[args.kappa]
    for kappa in settings:
        rows = [run_map(name, kappa, args.limit_per_map, data, args.snap) for name in args.maps]
        print_table(rows, kappa, args.snap)
    sys.stdout.flush()


if __name__ == "__main__":
    main()
