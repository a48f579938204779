"""Run every benchmark and write ``docs/benchmarks.md`` from what they print.

Each benchmark script measures one thing against a reference in the same run (a peer
library or a textbook method) and prints its table; this script runs them one after the
other in fresh processes, with the quick or the full settings, and writes one section per
benchmark: what it measures, the exact command, the wall time of the run and the printed
figures. The page header records the machine, the library versions and the date, so the
page always states one run of the present code.

Run from the repository root (the benchmarks on real maps need the shared data,
``$TRAJOPT_DATA`` or ``../shared/data``)::

    python benchmarks/run_all.py --quick            # about 15-25 min on 2 cores
    python benchmarks/run_all.py --full             # the settings quoted in the scripts
    python benchmarks/run_all.py --quick --only inflate astar --out /tmp/b.md
"""

from __future__ import annotations

import argparse
import datetime as dt
import os
import platform
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


@dataclass(frozen=True)
class Bench:
    """One benchmark script and its two settings.

    ``quick`` and ``full`` are the arguments of the section's first run; each tuple of
    ``more`` is a further run of the same script in the same section, with both settings
    (a suite run on a second grid, say).
    """

    name: str
    title: str
    script: str
    what: str
    quick: tuple[str, ...]
    full: tuple[str, ...] = ()
    more: tuple[tuple[str, ...], ...] = ()

    def runs(self, full: bool) -> tuple[tuple[str, ...], ...]:
        """The argument lists of the section's runs, in order."""
        return ((self.full if full else self.quick), *self.more)


BENCHES: tuple[Bench, ...] = (
    Bench(
        "inflate",
        "Inflation and clearance: `astar` vs SciPy's distance transform",
        "bench_inflate.py",
        "Median time to inflate a random grid by 10 cells with both metrics, against "
        "thresholding `scipy.ndimage.distance_transform_edt`, and to compute the clearance "
        "field with both metrics, against scipy's transform; the results must agree.",
        ("--size", "2000", "--repeat", "3"),
    ),
    Bench(
        "astar",
        "A*: `astar.find_path` vs `pyastar2d`",
        "bench_astar.py",
        "Median search time on Moving AI scenarios of the shared maps, against pyastar2d "
        "on the same queries (path costs must agree); then the clearance-cost search on a "
        "warehouse-size map (willow at 5 cm), checked against scipy's Dijkstra.",
        ("--n", "10", "--repeat", "3"),
    ),
    Bench(
        "search-scale",
        "A* on fine maps: exact vs coarse-to-fine (issue 35, part 2)",
        "bench_search_scale.py",
        "The willow map split k x k, inflated by a 0.25 m radius with the planner's "
        "clearance cost; long seeded queries; the exact search against "
        "`astar.find_path_coarse_to_fine` with the planner's block on the same queries: "
        "medians, worst times, the proven bounds and the cost against the exact search.",
        (),
    ),
    Bench(
        "scale",
        "Fine maps: the whole plan at 1x, 2x2 and 3x3 the cells (issue 35)",
        "bench_scale.py",
        "The same long queries on a site at its resolution and with every cell split 2 x 2 "
        "and 3 x 3 (the same metres): the default planner's first plan on the new map, "
        "warm medians, worst times and stages, the ratios against the site's own "
        "resolution, the durations' and exact clearances' differences on the same "
        "queries, the search's proven bounds, and the peak memory of a new process "
        "planning on the site split to at least 15 M cells.",
        ("--queries", "8", "--repeat", "2"),
        (),
    ),
    Bench(
        "timing",
        "Timing: jerk-limited timing vs TOPP-RA",
        "bench_timing.py",
        "Compute time and duration of `time_parameterize` against TOPP-RA's jerk-free "
        "time-optimal profile on the same paths.",
        ("--limit", "20", "--repeat", "3"),
    ),
    Bench(
        "timing_compare",
        "Timing: compute time against the timing before its speed-up",
        "compare_timing.py",
        "`time_parameterize` of this tree against commit 1510844 (before issue #19's faster "
        "timing) on the same saved curves, alternating fresh processes: compute time per "
        "second of trajectory and the relative difference of the durations.",
        ("--limit", "20", "--repeat", "3", "--rounds", "2"),
    ),
    Bench(
        "smoother",
        "Smoother: corridor-constrained B-spline",
        "bench_smoother.py",
        "Warm solve and first-build times, success and clearance of the smoother, "
        "against a plain least-squares B-spline on the same paths.",
        ("--n", "15", "--kappa-n", "6", "--reps", "2"),
    ),
    Bench(
        "plan",
        "Whole pipeline: warm per-query latency",
        "bench_plan.py",
        "Per-stage wall time of `Planner.plan` on the paper scene and the shared ROS maps.",
        ("--repeat", "3", "--ros-queries", "5"),
    ),
    Bench(
        "polygon_corridor",
        "Corridors: convex polygons vs boxes",
        "bench_polygon_corridor.py",
        "Build time, area and overlap of the polygon corridor against the box corridor "
        "on the same A* paths.",
        ("--per-map", "8", "--repeats", "2"),
    ),
    Bench(
        "corridor",
        "Planner: polygon corridors vs box corridors",
        "bench_corridor.py",
        "Success, smoothing time and path quality of `plan` with polygons against boxes "
        "on held-out queries.",
        ("--per-map", "6", "--repeats", "1"),
    ),
    Bench(
        "curvature",
        "Curvature-bounded smoothing",
        "bench_curvature.py",
        "The SCP curvature bound against IPOPT on the same problems.",
        ("--per-map", "8", "--repeats", "2"),
    ),
    Bench(
        "budget",
        "Smoother time budget",
        "bench_budget.py",
        "Success rate of curvature-bounded plans for several time budgets.",
        ("--per-map", "4", "--repeats", "1"),
    ),
    Bench(
        "fallback",
        "Robustness: smoother, stop-and-turn fallback, failures",
        "bench_fallback.py",
        "Outcome of every query on the shared maps with and without the fallback.",
        ("--limit-per-map", "10"),
    ),
    Bench(
        "failures",
        "Failures at scale: default and curvature-bounded planner",
        "bench_failures.py",
        "Failures of the default and the curvature-bounded (1/(2r)) planner on the "
        "shared-full suite and on random queries at several radii; curvature-bounded "
        "failures classified by a curvature witness; median time of a failing query.",
        ("--limit", "40", "--random", "40", "--radii", "1.5,2.5"),
        ("--limit", "400", "--random", "250", "--radii", "1.5,2.5,3.5"),
    ),
    Bench(
        "ipopt",
        "IPOPT vs piqp and the SCP in polygon corridors",
        "bench_ipopt.py",
        "On the shared-small suite, the same queries planned with piqp, with "
        '`qp_solver="ipopt"` and with `refine="ipopt"` (the IPOPT polish), and with a bound '
        '1/(2r) by the SCP, by `curvature_solver="ipopt"` and by the SCP polished: success '
        "rates, median smoothing time, objective and duration, duration ratios, smoothing and "
        "solver time ratios (with and without the one-off IPOPT builds), the polish's "
        "outcomes; then on Nav2-style inflation costmaps of the shared ROS maps at weight 2, "
        'the cost term by the QP rounds, by IPOPT (`qp_solver="ipopt"`) and the rounds '
        "polished: success, smoothing time, objective, cost against the A* path, duration.",
        ("--limit", "5", "--costmap-queries", "3"),
        ("--costmap-queries", "10"),
    ),
    Bench(
        "costmap-smoother",
        "The costmap's cost in the smoother",
        "bench_costmap_smoother.py",
        "On Nav2-style inflation costmaps of the shared ROS maps, seeded random queries at "
        "costmap_weight 1, 2, 5, 10 with the smoother's cost term and at 2 without it: the "
        "trajectory's mean normalised cost per metre against its A* path's, the duration "
        "and the smoothing time against the cost-blind smoother's.",
        ("--queries", "4"),
        ("--queries", "20"),
    ),
    Bench(
        "refusals",
        "Fast refusals: unconnected queries",
        "bench_refusals.py",
        "Refusal time of queries whose ends lie in different components of the inflated "
        "grid (an island of the map, or a goal walled into a closed room), start in the "
        "largest component, on the larger shared Moving AI maps, the shared ROS maps and a "
        "warehouse-size map (willow at 5 cm): `Planner.plan` until its `NoPathError` (from "
        "the component labels) against the A* the planner ran before on the same queries "
        "(until it had exhausted the start's component), with the labelling time.",
        ("--queries", "10", "--repeat", "2"),
    ),
    Bench(
        "timing_property",
        "Timing: the speed cap on sharp curvature peaks",
        "timing_property_run.py",
        "Random curves with sharp curvature peaks: worst ratio of the sampled speed to its cap.",
        ("--examples", "100"),
    ),
    Bench(
        "mcap",
        "ROS 2 export: MCAP writing speed",
        "bench_mcap.py",
        "Writing a 60 s trajectory at 100 Hz to MCAP, against mcap_ros2's generic "
        "writer in the same run.",
        ("--repeat", "3"),
    ),
    Bench(
        "replan",
        "Re-planning from a moving robot",
        "bench_replan.py",
        "Re-plan latency every 0.5 s of trajectory time on the shared ROS maps (same goal: "
        "the rest kept, and with `reuse=False` a full plan; then one new goal), the jump "
        "at the splice and the limits of the new trajectory, against a fresh plan from "
        "rest at the same point; a drive with obstacles appearing before every re-plan; "
        "then whole plans and re-plans to a new goal on a warehouse-size map (willow at "
        "5 cm).",
        ("--queries", "4"),
    ),
    Bench(
        "replan_robustness",
        "Re-planning: every guarantee on many re-plans",
        "replan_robustness.py",
        "Re-plans with `reuse=False` from moving robots on the shared ROS maps to the same "
        "goal and to two other goals, and braked results re-planned again mid-brake: "
        "outcomes (planned, braked, refused by type), latency, and every violation of the "
        "splice continuity, the limits, the clearance, or an untyped error.",
        ("--queries", "3"),
    ),
    Bench(
        "first_call",
        "First plan in a fresh process",
        "bench_first_call.py",
        "Wall time of the first `plan` after `import trajopt` (paper scene, numba cache "
        "warm on disk), split into imports, numba cache loads, solver build and the "
        "rest, and of the first plan after `trajopt.warm_up()` at start-up.",
        ("--runs", "5"),
    ),
    Bench(
        "footprint",
        "Rectangular robots: collisions and doors",
        "bench_footprint.py",
        "Rectangles (1.6 x 1.0 and 2:1 of the disc's diameter) on the shared maps, checked "
        "by an independent collision test, why refused queries were refused, the "
        "smoothing stage with the footprint certificate and rounds, the same queries "
        "without the footprint rounds (the previous design), and door passages narrower "
        "than the circumscribed disc, against that disc in the same run.",
        ("--per-map", "15"),
    ),
    Bench(
        "pose",
        "Pose to pose: random end headings, differential and omni drives",
        "bench_pose.py",
        "The shared suite's queries (Moving AI scenarios at 2.5 cells, seeded random pairs "
        "on the ROS maps) with seeded random start and goal headings, for a disc robot with "
        '`drive="differential"` and `drive="omni"`: success, collisions under an '
        "independent exact check on 1 ms samples (distance to the raw map's occupied "
        "squares), both headings to 1e-6 rad, every limit on 1 ms samples (turns in place "
        "against `turn_limits`); the duration against the same query with free headings "
        "(differential: overhead, turns in place, never slower than turn-drive-turn; omni: "
        "ratio), and the warm plan time with headings over the free plan's, same run.",
        ("--quick",),
        ("--limit", "30"),
    ),
    Bench(
        "harness",
        "Benchmark harness: Dask scaling",
        "bench_harness.py",
        "Throughput of `trajopt bench` with 1 and 2 Dask workers on the same queries, "
        "and the report on 10^5 rows.",
        ("--limit", "6"),
    ),
    Bench(
        "harness_scaling",
        "Benchmark harness: 1 vs 2 workers on shared-small, and why",
        "bench_harness_scaling.py",
        "`trajopt bench`'s throughput on `shared-small` with 1 and 2 local Dask workers in "
        "the same run (3 rounds; measured after the workers' warm-up, and end to end), "
        "where the workers' time goes (planning, scoring, the rest of the tasks, idle), a "
        "cProfile of a serial pass, and the machine's own 1-vs-2-process ceiling for the "
        "same work without Dask. Each measurement waits for other processes to go quiet "
        "and reports the cores they used meanwhile (a round where they used more than "
        "0.15 cores, or where the workers got under 85 % of their wall time as CPU, is "
        "not counted and is repeated). On this 2-vCPU VM the host's speed "
        "drifts by tens of per cent from minute to minute (the fixed loop's time), so a "
        "single round's ratio moves by about as much: read the quiet rounds' median and "
        "the per-run split.",
        ("--rounds", "3"),
    ),
    Bench(
        "hybrid",
        "Car-like robots: Hybrid-A* over (x, y, heading) vs OMPL Reeds-Shepp/Dubins",
        "bench_hybrid.py",
        "`astar.find_pose_path` (Hybrid-A*, Reeds-Shepp shots; forward only: Dubins) on the "
        "shared suite `shared-full`, seeded random start and goal headings, R = 2 x the robot "
        "radius, on the map inflated by the radius, against OMPL's `RRTstar` in "
        "`ReedsSheppStateSpace(R)` / `DubinsStateSpace(R)` on the same inflated grid (its "
        "first solution or its time limit, then `simplifySolution`). Every Hybrid-A* path is "
        "re-integrated independently (exact chords every 0.05 cells) against the inflated "
        "grid; the 2-D heuristic (a Dijkstra over the free grid) is reported apart from the "
        "search.",
        ("--limit", "4"),
        ("--limit", "10", "--ompl-time", "2.0"),
    ),
    Bench(
        "car",
        "Car-like robots end to end",
        "bench_car.py",
        "`trajopt.plan` for a car-like disc robot (`Ackermann`, R = 2 x radius, with and "
        "without reversing: search, split at cusps, certified B-spline per segment with "
        "curvature <= 1/R, rest-to-rest timing) as the `trajopt.bench` methods "
        "`trajopt-ackermann` / `trajopt-ackermann-forward`, against `ompl-reedsshepp` / "
        "`ompl-dubins` (OMPL's `RRTstar`, first exact solution or 2 s, then "
        "`simplifySolution`) on `shared-full` with seeded random end headings. All methods "
        "are judged by the same independent checks (`trajopt/analysis/bench/_car.py`: "
        "clearance on dense samples against the raw map, curvature by circles through three "
        "points against 1/R, speed at every join, heading against the direction of travel, "
        "the end headings); OMPL's path is not timed, so it is compared by length, cusps and "
        "reverse length, and its time is the time to its first solution.",
        ("--limit", "3", "--workers", "1"),
        ("--limit", "10", "--workers", "2"),
    ),
    Bench(
        "ros",
        "ROS 2 node: round trips, map updates, start-up, soak",
        "bench_ros.py",
        "The `trajopt_ros` node in its own process and the benchmark's client node in "
        "another, over Fast DDS on localhost (LOCALHOST discovery, a domain id of its own, a "
        "temporary log folder), on a 400 x 400 map of 0.05 m cells: the start-up to "
        "`get_plan` found, a map's publication to the planner ready, the node's share of a "
        "`get_plan` round trip (the round trip less the library's plan time the node logged "
        "and this client's deserialisation), a map update to the re-planned `/plan`, and a "
        "soak of requests (every third one bad) with the node's memory before and after. "
        "Needs the `ros2` extra; the script's docstring defines each number.",
        ("--requests", "150", "--repeats", "20"),
        ("--requests", "1000", "--repeats", "60"),
    ),
    Bench(
        "moving",
        "Moving obstacles",
        "bench_moving.py",
        "Seeded moving-obstacle scenarios (`benchmarks/moving_cases.py`: crossing, head-on, "
        "following, overtaking a slow mover, a mover stopping on the path, a mix; 1-10 disc "
        "movers of radius 0.15-0.35 m at 0.3-1.5 m/s, placed from the static plan so that "
        "they meet the robot) on the house-size shared maps, robot radius 0.2 m, 0.5 m/s, "
        "0.5 m/s^2, mover margin 0.05 m, through `Planner.plan(..., moving_obstacles=...)`. "
        "Every returned trajectory is checked independently of `trajopt.moving` "
        "(`tests/trajopt/moving/reference.py`: 1 ms samples over the trajectory and the "
        "standing at the goal until the last prediction ends, and a Lipschitz bound between "
        "them, the map's clearance included), so a pass is a proof. Witnesses "
        "(`benchmarks/moving_witness.py`): `wait` rests at the start while that is safe and "
        "then drives the static plan (10 ms grid of waits); `latt` is the earliest arrival "
        "over an (s, t, v) lattice along the static path. Columns: the script's docstring. "
        "Issue 46's targets: 0 violations; success >= 99 % of witnessed scenarios; arrival "
        "<= 1.05x the lattice optimum (median) and never later than the waiting witness; "
        "a re-time when only the predictions of 10 movers change (the second run: "
        "`Planner.replan` 0.5 s into each plan, predictions shifted; its 'no new path' line) "
        "<= 10 ms median, <= 25 ms p99; its last line times a re-plan at a new splice while "
        "the robot drives (a rest curve the re-timing has not seen), what a robot re-planning "
        "as it goes meets.",
        ("--retime", "0"),
        ("--retime", "0"),
        more=(("--per-kind", "0", "--retime", "15"),),
    ),
    Bench(
        "moving_carts",
        "Moving obstacles: polygon movers (carts)",
        "bench_moving.py",
        "The re-time part of the previous section with cart-shaped movers (convex rectangles "
        'heading along their motion, `make_movers(..., shape="polygon")`), whose windows '
        "and certificates take the exact polygon distances: the same targets (<= 10 ms "
        "median, <= 25 ms p99 for a re-plan that keeps its path); then the scenario table "
        "with carts (4 per kind and map; `--full` runs one with 10 first), the same checks "
        "and witnesses.",
        ("--shape", "polygon", "--per-kind", "0", "--retime", "15"),
        ("--shape", "polygon"),
        more=(("--shape", "polygon", "--retime", "0", "--per-kind", "4"),),
    ),
    Bench(
        "reroute",
        "Moving obstacles: re-routing around a mover that blocks the path",
        "bench_moving_reroute.py",
        "On the shared house-size ROS maps, random queries planned plain, then with one mover "
        "that no re-timing along the plan avoids: a cart stopping on the path (`stop`), a "
        "walker driving the path backwards (`head-on`), and the walker then standing on the "
        "goal (`trapped`: a `BlockedError` is the answer). Each result is checked by the "
        "certificate and the reference on 1 ms samples. The ratio is the query's time over a "
        "plain plan's in the same run; issue 46's target for a re-route is 2x. The first run "
        "times `Planner.plan`; the second `Planner.replan` 1 s into a plan, which brakes and "
        "goes on from the stop, against a plain plan from where it stops. Method and columns: "
        "the script's docstring.",
        ("--part", "plan", "--queries", "10"),
        ("--part", "plan", "--queries", "10"),
        more=(("--part", "replan", "--queries", "8"),),
    ),
    Bench(
        "parking",
        "Parking",
        "bench_parking.py",
        "A seeded suite of 40 parking cases (`benchmarks/parking_cases.py`): parallel slots "
        "1.2-1.6 car lengths long, perpendicular and angled (45-60 degree) bays 1.15-1.4 car "
        "widths wide, entered forwards and backwards off aisles 4-7 m wide, parked cars and "
        "kerbs as polygons, starts in the aisle with random headings; the full-size car of "
        "the public automated-parking cases (4.69 x 1.94 m, wheelbase 2.8 m, R = 3.0 m, rear "
        "axle reference) on 0.1 m and 0.05 m grids rasterised from the polygons "
        "(`OccupancyGrid.from_polygons`), and a small delivery car (0.9 x 0.5 m, R = 0.6 m) "
        "at 0.05 m. Every plan is checked by an exact body-against-polygon test "
        "(`parking_cases.check_trajectory`, samples bisected until no body corner moves more "
        "than 1 cm between two). `--feasibility` reads the verdicts of "
        "`benchmarks/parking_feasibility.py` (a flood fill of the free (x, y, heading) space "
        "that proves a path exists or not: all 80 cases are feasible), so the planned rate "
        "is over proven-feasible cases. The first run also plans each case with OMPL's "
        "Reeds-Shepp BIT* (1.5 s a case, 5 s with `--full`; the same exact body test) for "
        "the cusps per plan. Issue "
        "45's targets (full-size car, 0.1 m): >= 98 % planned, 0 overlaps, median <= 300 ms, "
        "p95 <= 1 s, and the 0.05 m suite within 2x the time.",
        ("--feasibility", "benchmarks/parking_feasibility_full.json"),
        ("--ompl-time", "5", "--feasibility", "benchmarks/parking_feasibility_full.json"),
        more=(
            (
                "--no-ompl",
                "--resolution",
                "0.05",
                "--feasibility",
                "benchmarks/parking_feasibility_full.json",
            ),
            (
                "--no-ompl",
                "--car",
                "small",
                "--resolution",
                "0.05",
                "--feasibility",
                "benchmarks/parking_feasibility_small.json",
            ),
        ),
    ),
)


def machine() -> str:
    """One line describing this machine and the library versions."""
    import numpy

    try:
        import casadi

        casadi_v = casadi.__version__
    except ImportError:  # pragma: no cover
        casadi_v = "missing"
    try:
        import ruckig

        ruckig_v = getattr(ruckig, "__version__", "installed")
    except ImportError:  # pragma: no cover
        ruckig_v = "missing"
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    return (
        f"{platform.platform()}, {os.cpu_count()} cores, Python {platform.python_version()}, "
        f"numpy {numpy.__version__}, casadi {casadi_v}, ruckig {ruckig_v}; "
        f"load average {load:.2f} at the start"
    )


def run_one(bench: Bench, args: tuple[str, ...]) -> tuple[str, float, int, str]:
    """Run one benchmark command.

    Returns its output, its wall time (s), its exit code and when it started (UTC, with the
    machine's load average then).
    """
    cmd = [sys.executable, str(ROOT / "benchmarks" / bench.script), *args]
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    started = dt.datetime.now(dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    started += f", load average {load:.2f}"
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, check=False)
    wall = time.perf_counter() - t0
    out = proc.stdout.rstrip()
    if proc.returncode != 0:
        tail = "\n".join(proc.stderr.rstrip().splitlines()[-15:])
        out = f"{out}\n\n[exit code {proc.returncode}]\n{tail}".strip()
    return out, wall, proc.returncode, started


def section(bench: Bench, results: list[tuple[tuple[str, ...], str, float, int, str]]) -> str:
    """The markdown section of one benchmark: its text, then each run's command and output."""
    body = []
    for args, out, wall, code, started in results:
        cmd = " ".join(["python", f"benchmarks/{bench.script}", *args])
        status = "" if code == 0 else f" **(failed, exit code {code})**"
        body.append(f"`{cmd}`: {wall:.0f} s{status} (run {started})\n\n```text\n{out}\n```\n")
    return f"## {bench.title}\n\n{bench.what}\n\n" + "\n".join(body)


def _merge(existing: str, parts: list[str]) -> list[str]:
    """Put the new sections (``parts[1:]``) into an existing page in the benchmarks' order,
    keeping the other sections; the header lists every section rerun since the whole page
    was written."""
    head_lines: list[str] = []
    old: dict[str, list[str]] = {}
    current: list[str] = head_lines
    in_code = False
    for line in existing.split("\n"):
        if line.startswith("```"):
            in_code = not in_code
        if not in_code and line.startswith("## "):
            current = old.setdefault(line[3:], [])
        current.append(line)
    old = {k: "\n".join(v).rstrip() + "\n" for k, v in old.items()}
    new = {p.split("\n", 1)[0][3:]: p for p in parts[1:]}
    titles = [b.title for b in BENCHES]
    merged = {**old, **new}
    ordered = [merged[t] for t in titles if t in merged]
    ordered += [v for k, v in merged.items() if k not in titles]
    head = "\n".join(head_lines).rstrip()
    head, _, before = head.partition("\n\nSections rerun since with `--only`: ")
    earlier = [t for t in before.rstrip(".").split("; ") if t and t not in new]
    rerun = "; ".join([*earlier, *new])
    head += f"\n\nSections rerun since with `--only`: {rerun}.\n"
    return [head, *ordered]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    mode = ap.add_mutually_exclusive_group()
    mode.add_argument("--quick", action="store_true", help="small settings (default)")
    mode.add_argument("--full", action="store_true", help="the scripts' own defaults")
    ap.add_argument(
        "--only", nargs="+", choices=[b.name for b in BENCHES], help="run these benchmarks only"
    )
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "benchmarks.md")
    args = ap.parse_args(argv)
    chosen = [b for b in BENCHES if args.only is None or b.name in args.only]
    when = dt.datetime.now(dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    head = (
        "# Benchmarks\n\n"
        "Every figure on this page comes from one run of "
        f"`python benchmarks/run_all.py {'--full' if args.full else '--quick'}`, which "
        "runs each script of `benchmarks/` in a fresh process and writes this page from "
        "what it prints. Each benchmark measures against a reference in the same run; "
        "absolute times depend on the machine and its load, ratios much less.\n\n"
        f"- **Date**: {when}\n- **Machine**: {machine()}\n"
        f"- **Settings**: {'full' if args.full else 'quick'} "
        "(`--full` uses each script's own defaults)\n\n"
        "Regenerate with the same command; rerun one section with `--only NAME`.\n"
    )
    parts = [head]
    failed = 0
    for bench in chosen:
        results = []
        for run_args in bench.runs(args.full):
            print(f"running {bench.name} {' '.join(run_args)} ...", flush=True)
            out, wall, code, started = run_one(bench, run_args)
            failed += code != 0
            print(f"  {wall:.0f} s, exit code {code}", flush=True)
            results.append((run_args, out, wall, code, started))
        parts.append(section(bench, results))
    if args.only is not None and args.out.is_file():
        parts = _merge(args.out.read_text(), parts)
    text = "\n".join(parts)
    tmp = args.out.with_suffix(".tmp")
    tmp.write_text(text)
    os.replace(tmp, args.out)
    print(f"wrote {args.out} ({len(chosen)} benchmarks, {failed} runs failed)")
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
