"""The planning commands: ``plan``, ``compare`` and ``demo``.

``plan`` plans one query on a map, ``compare`` runs the chapter's methods on one query, ``demo``
runs the paper scene to every target.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any

from trajopt.cli._common import (
    CliError,
    atomic_output,
    finite_angle,
    load_map,
    map_args,
    require_matplotlib,
    robot_args,
    robot_from_args,
    save_figure,
    shape_args,
)

_OUT_SUFFIXES = (".csv", ".json", ".mcap")
_PLOT_POSES = (5, 40)  # least and most footprints drawn along the trajectory by plan --plot
_PLOT_ARROWS = 16  # heading arrows drawn by plan --plot when a heading is asked or the base is omni


# ----------------------------------------------------------------- arguments
def _ros_args(p: argparse.ArgumentParser) -> None:
    """Add ``plan``'s ROS 2 / Nav2 options: costmap, speed mask, frame."""
    g = p.add_argument_group("ROS 2 / Nav2 inputs")
    g.add_argument(
        "--costmap",
        action="store_true",
        help="MAP is a costmap saved by Nav2's map saver (OccupancyGrid values, best in "
        "mode raw): lethal cells are obstacles, the graded cost steers the search",
    )
    g.add_argument(
        "--costmap-weight",
        type=float,
        default=2.0,
        help="weight of the costmap's normalised cost in the search (default 2)",
    )
    g.add_argument("--speed-mask", metavar="YAML", help="Nav2 speed filter mask (map_server YAML)")
    g.add_argument(
        "--speed-mask-type",
        choices=("percentage", "absolute"),
        default="percentage",
        help="limit in percent of --v-max or in m/s (Nav2 filter type 1 or 2; default percentage)",
    )
    g.add_argument(
        "--speed-mask-base",
        type=float,
        default=0.0,
        help="Nav2 'base': limit = value * multiplier + base (default 0)",
    )
    g.add_argument(
        "--speed-mask-multiplier", type=float, default=1.0, help="Nav2 'multiplier' (default 1)"
    )
    g.add_argument("--frame-id", default="map", help="frame of the written poses (default map)")


def add_parsers(sub: Any) -> None:
    """Add ``plan``, ``compare`` and ``demo`` to the subparsers ``sub``."""
    p = sub.add_parser(
        "plan",
        help="plan a timed trajectory on a map",
        description="Plan a timed trajectory: inflate -> A* -> corridor -> "
        "smoother -> ruckig timing.",
    )
    map_args(p)
    robot_args(p)
    p.add_argument(
        "--inflation",
        choices=("exact", "paper"),
        default="exact",
        help="exact disk inflation or the chapter's avoidance area (default exact)",
    )
    p.add_argument(
        "--search",
        choices=("clearance", "shortest", "costmap", "costmap+clearance"),
        default=None,
        help="A* cost (default clearance-aware; with --costmap the costmap's graded cost)",
    )
    _ros_args(p)
    p.add_argument(
        "--corridor",
        choices=("polygons", "boxes"),
        default="polygons",
        help="convex polygons grown around the path (default; boxes where they fail) or "
        "axis-aligned boxes of free cells only",
    )
    p.add_argument("--kappa-max", type=float, help="curvature bound [1/m] for the smoother")
    p.add_argument(
        "--start-heading",
        type=finite_angle,
        metavar="RAD",
        help="heading the robot starts with [rad, map frame, finite]; a differential drive "
        "turns in place first when that is needed or faster",
    )
    p.add_argument(
        "--goal-heading",
        type=finite_angle,
        metavar="RAD",
        help="heading required at the goal [rad, map frame, finite]; a differential drive "
        "turns in place at the goal when that is needed or faster",
    )
    p.add_argument(
        "--fallback",
        action="store_true",
        help="if the smoother (or the timing) fails, return the A* polyline driven "
        "with stops and turns in place at the corners (differential drive; "
        "checked against the map) instead of an error",
    )
    p.add_argument(
        "--movers",
        metavar="FILE",
        help="predicted moving obstacles (.json/.yaml movers file, times in seconds from the "
        "plan's start; format: trajopt.moving.load_movers): the trajectory is certified "
        "against them at every instant, re-timed or re-routed round them; .mcap output "
        "shows them",
    )
    p.add_argument(
        "--mover-margin",
        type=float,
        default=0.0,
        metavar="M",
        help="extra distance kept from every mover [m, >= 0] (default 0)",
    )
    p.add_argument(
        "--out", help="write the trajectory (.csv, .json, or .mcap for ROS 2 / Foxglove)"
    )
    p.add_argument("--dt", type=float, default=0.01, help="sample step of --out [s]")
    p.add_argument("--plot", help="write a figure (.png/.pdf/.svg)")
    p.set_defaults(func=_cmd_plan)

    p = sub.add_parser(
        "compare",
        help="compare the chapter's methods and the proposed one",
        description="Table of path metrics: traditional A*, A* with avoidance "
        "area, polynomial fit, B-spline fit and the proposed smoother.",
    )
    map_args(p)
    shape_args(
        p.add_argument_group("robot (SI units; default trajopt.Robot())"), "robot radius [m]"
    )
    p.add_argument(
        "--format",
        choices=("text", "markdown", "csv"),
        default="text",
        help="table format on stdout (default text)",
    )
    p.add_argument("--out", help="also write the table to this file (.csv, .md or .txt)")
    p.add_argument("--plot", help="write a figure of all paths (.png/.pdf/.svg)")
    p.set_defaults(func=_cmd_compare)

    p = sub.add_parser(
        "demo",
        help="the paper scene, SP to A-D, every method",
        description="Runs the chapter's scene (trajopt.scenes.paper()): every "
        "method from SP to each target; writes tables and figures.",
    )
    p.add_argument("--out", default="trajopt_demo", help="output folder (default trajopt_demo)")
    p.add_argument("--no-plots", action="store_true", help="skip the figures")
    p.set_defaults(func=_cmd_demo)


# -------------------------------------------------------------------- commands
def _cmd_plan(args: argparse.Namespace) -> int:
    from trajopt import Planner
    from trajopt.smoother import Smoother

    if args.out and Path(args.out).suffix.lower() not in _OUT_SUFFIXES:
        raise CliError(f"--out must end in .csv, .json or .mcap, got {args.out!r}")
    if args.costmap:
        import astar

        grid = astar.load_costmap(args.map)
    else:
        grid = load_map(args)
    robot = robot_from_args(args)
    movers = None
    if args.movers:
        from trajopt.moving import load_movers

        movers = load_movers(args.movers)
    speed_limits = None
    if args.speed_mask:
        from trajopt.timing import load_speed_mask

        speed_limits = load_speed_mask(
            args.speed_mask,
            type=args.speed_mask_type,
            base=args.speed_mask_base,
            multiplier=args.speed_mask_multiplier,
        )
    smoother = Smoother(kappa_max=args.kappa_max) if args.kappa_max is not None else None
    planner = Planner(
        grid,
        robot,
        inflation=args.inflation,
        search=args.search,
        smoother=smoother,
        fallback="stop_and_turn" if args.fallback else None,
        corridor=args.corridor,
        costmap_weight=args.costmap_weight,
        speed_limits=speed_limits,
    )
    t0 = time.perf_counter()
    traj = planner.plan(
        args.start,
        args.goal,
        start_heading=args.start_heading,
        goal_heading=args.goal_heading,
        moving_obstacles=movers,
        mover_margin=args.mover_margin,
    )
    wall = time.perf_counter() - t0
    # a pose plan's stage times are its chosen candidate's: the query took the wall time
    total = wall if traj.stats.get("pose") else traj.stats.get("stages_s", {}).get("total")
    line = (
        f"duration {traj.duration:.3f} s, length {traj.length:.3f} m, "
        f"planned in {1e3 * (float('nan') if total is None else total):.1f} ms"
    )
    line += f", {robot.drive.name} drive"
    if traj.stats.get("corridor"):
        line += f", corridor {traj.stats['corridor']}"
    line += _turn_note(traj.stats)
    if movers:
        moving = traj.stats.get("moving", {})
        line += f"; {len(movers)} movers, route {moving.get('route')}"
    if traj.stats.get("fallback"):
        reason = str(traj.stats.get("fallback_reason", "")).splitlines()[0][:120]
        line += (
            f"; FALLBACK {traj.stats['fallback']} ({traj.stats['n_turns']} turns in "
            f"place) after {traj.stats.get('fallback_error')}: {reason}"
        )
    print(line)
    if args.out:
        suffix = Path(args.out).suffix.lower()
        if suffix == ".csv":
            traj.to_csv(args.out, dt=args.dt, frame_id=args.frame_id)
        elif suffix == ".json":
            traj.to_json(args.out, dt=args.dt, frame_id=args.frame_id)
        else:
            traj.to_mcap(args.out, dt=args.dt, frame_id=args.frame_id, movers=movers)
        print(f"wrote {args.out}")
    if args.plot:
        require_matplotlib()
        import matplotlib.pyplot as plt
        import numpy as np

        from trajopt.analysis.plotting import plot_footprints, plot_paths

        steps = traj.steps
        fig, ax = plt.subplots(figsize=(7, 7))
        name = "stop and turn" if traj.stats.get("fallback") else "proposed"
        posed = (
            robot.drive.orients_body
            or robot.drive.signed_speed
            or (args.start_heading is not None or args.goal_heading is not None)
        )
        plot_paths(
            grid,
            {"A*": steps.grid_path.to_world(grid), name: traj},
            inflated=steps.inflated_grid,
            corridor=steps.corridor,
            start=steps.start,
            goals={"goal": steps.goal},
            arrows=_PLOT_ARROWS if posed else 0,
            ax=ax,
        )
        if robot.footprint is not None:
            # evenly spaced in time, about one circumscribed diameter apart on average
            poses = int(np.clip(round(traj.path.length / robot.width) + 1, *_PLOT_POSES))
            every_s = max(traj.duration, 1e-6) / (poses - 1)
            plot_footprints(ax, traj, robot, every_s=every_s)
            ax.legend(loc="best", fontsize="small")
        print(f"wrote {save_figure(fig, args.plot)}")
    return 0


def _turn_note(stats: Any) -> str:
    """Return the summary line's note on how the plan met the end headings.

    A differential drive's pose plan (``stats["pose"]``) says which ends it turned in place
    at; an omnidirectional one (``stats["orientation"]``) how far its body turned while it
    drove, and how long it stood at the goal to finish the turn.
    """
    pose, orientation = stats.get("pose"), stats.get("orientation")
    if pose:
        turns = {e: float(pose.get(f"turn_{e}_rad", 0.0)) for e in ("start", "goal")}
        done = [f"{e} {a:+.3f} rad" for e, a in turns.items() if a != 0.0]
        if not done:
            return "; end headings met by the curve, no turn in place"
        return f"; turned in place at the {', '.join(done)}"
    if orientation:
        note = f"; orientation turned {float(orientation.get('turn_rad', 0.0)):+.3f} rad"
        hold = float(orientation.get("hold_s", 0.0))
        if hold > 0.0:
            return note + f" while driving and {hold:.3f} s standing at the goal"
        return note + " while driving"
    return ""


def _table_text(table: Any, fmt: str) -> str:
    if fmt == "markdown":
        return table.to_markdown()
    if fmt == "csv":
        import csv
        import io

        records = table.to_records()
        # rows differ in their columns (the proposed method adds timed metrics): the
        # union, in first-seen order, with empty cells where a method has no value
        fields = list(dict.fromkeys(k for rec in records for k in rec))
        buf = io.StringIO()
        writer = csv.DictWriter(buf, fieldnames=fields, restval="", lineterminator="\n")
        writer.writeheader()
        writer.writerows(records)
        return buf.getvalue()
    return str(table)


def _avoidance(grid: Any, table: Any) -> Any:
    from astar.inflation import avoidance_area

    return avoidance_area(grid, int(table.meta["w_cells"]), border=True)


def _cmd_compare(args: argparse.Namespace) -> int:
    from trajopt.analysis.comparison import compare

    grid = load_map(args)
    # the comparison's methods are disc models: a footprint enters by its circumscribed radius
    radius = args.radius if args.radius is not None else robot_from_args(args).radius
    table = compare(grid, tuple(args.start), tuple(args.goal), robot_radius=radius)
    print(_table_text(table, args.format))
    if args.out:
        suffix = Path(args.out).suffix.lower()
        fmt = {".csv": "csv", ".md": "markdown"}.get(suffix, "text")
        text = _table_text(table, fmt)
        atomic_output(args.out, lambda tmp: tmp.write_text(text + "\n"))
    if args.plot:
        require_matplotlib()
        from trajopt.analysis.plotting import plot_paths

        paths = {k: v for k, v in table.paths.items() if v is not None}
        fig, _ = plot_paths(
            grid,
            paths,
            inflated=_avoidance(grid, table),
            start=tuple(args.start),
            goals={"goal": tuple(args.goal)},
        )
        print(f"wrote {save_figure(fig, args.plot)}")
    return 0


def _cmd_demo(args: argparse.Namespace) -> int:
    from trajopt import Planner
    from trajopt.analysis.comparison import compare
    from trajopt.analysis.scenes import paper
    from trajopt.robot import Robot

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    scene = paper()
    plots = not args.no_plots
    if plots:
        try:
            require_matplotlib()
        except CliError as exc:
            print(f"note: {exc}; figures skipped", file=sys.stderr)
            plots = False
    planner = Planner(scene.grid, Robot(radius=scene.robot_radius))
    sections = []
    for name in scene.target_names:
        t0 = time.perf_counter()
        table = compare(
            scene.grid,
            scene.start,
            scene.goal(name),
            robot_radius=scene.robot_radius,
            w_cells=scene.w_cells,
        )
        dt = time.perf_counter() - t0
        print(f"\n== SP -> {name} ({dt:.2f} s) ==")
        print(table)
        sections.append(f"## SP -> {name}\n\n{table.to_markdown()}\n")
        csv_text = _table_text(table, "csv")
        atomic_output(out / f"compare_{name}.csv", lambda tmp, s=csv_text: tmp.write_text(s))
        if plots:
            from trajopt.analysis.plotting import plot_paths, plot_profiles

            paths = {k: v for k, v in table.paths.items() if v is not None}
            fig, _ = plot_paths(
                scene.grid,
                paths,
                inflated=_avoidance(scene.grid, table),
                start=scene.start,
                goals={name: scene.goal(name)},
            )
            save_figure(fig, out / f"paths_{name}.png")
            traj = planner.plan(scene.start, scene.goal(name))
            fig, _ = plot_profiles(traj)
            save_figure(fig, out / f"profile_{name}.png")
    report = "# trajopt demo: the paper scene\n\n" + "\n".join(sections)
    atomic_output(out / "compare.md", lambda tmp: tmp.write_text(report))
    print(f"\nwrote tables{' and figures' if plots else ''} to {out}/")
    return 0
