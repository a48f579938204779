"""The ``trajopt`` command line: ``plan``, ``compare``, ``demo``, ``bench`` (``run``, ``report``), ``warm-up``.

Every failure the user can fix (bad arguments, unreadable maps, blocked or unreachable
start/goal, infeasible limits) exits with code 2 and one line on stderr, no traceback.
Output files are written atomically: a partial file never replaces a good one.

The first planning command in a new environment compiles the numba kernels first, in two
worker processes, with a line (and a progress bar on a terminal) on stderr saying so;
``trajopt warm-up`` compiles and loads all of them ahead of time.
"""

from __future__ import annotations

import argparse
import logging
import os
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, NoReturn

from astar.files import atomic_write

__all__ = ["main", "build_parser"]

logger = logging.getLogger(__name__)

EXIT_USAGE = 2


class _Formatter(argparse.HelpFormatter):
    """Help formatter that shows an action's ``usage_metavar`` verbatim when it has one."""

    def _format_args(self, action: argparse.Action, default_metavar: str) -> str:
        fixed = getattr(action, "usage_metavar", None)
        return fixed if fixed is not None else super()._format_args(action, default_metavar)


class _Parser(argparse.ArgumentParser):
    """argparse that reports errors as one line and exit code 2."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("formatter_class", _Formatter)
        super().__init__(*args, **kwargs)

    def error(self, message: str) -> NoReturn:
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message}\n")


class _FootprintAction(argparse.Action):
    """``--footprint L W [REAR]``: 2 or 3 numbers (m), else a usage error (exit code 2)."""

    usage_metavar = "L W [REAR]"

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: Any,
        option_string: str | None = None,
    ) -> None:
        if len(values) not in (2, 3):
            parser.error(
                f"argument {option_string}: expected 2 or 3 numbers (length, width and "
                f"optionally the rear offset, m), got {len(values)}"
            )
        setattr(namespace, self.dest, list(values))


class CliError(Exception):
    """A user-facing failure: printed as one line, exit code 2."""


# ----------------------------------------------------------------- arguments
def _shape_args(g: Any, radius_help: str) -> None:
    """Add ``--radius``, ``--footprint`` and ``--footprint-file``, mutually exclusive."""
    shape = g.add_mutually_exclusive_group()
    shape.add_argument("--radius", type=float, help=radius_help)
    shape.add_argument(
        "--footprint", nargs="+", type=float, action=_FootprintAction,
        help="rectangular footprint [m]: length L (x forward), width W and the rear offset "
        "REAR from the rotation centre back to the rear edge (default L/2); the disc-model "
        "stages keep its circumscribed radius clear",
    )  # fmt: skip
    shape.add_argument(
        "--footprint-file", metavar="PATH",
        help="convex footprint polygon [m, robot frame, x forward]: JSON (a list of [x, y] "
        "or {\"vertices\": [[x, y], ...]}) or CSV/text rows 'x, y'",
    )  # fmt: skip


def _robot_args(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("robot and limits (SI units; defaults: trajopt.Robot())")
    _shape_args(g, "disc robot radius [m]")
    g.add_argument("--v-max", type=float, help="max speed [m/s]")
    g.add_argument("--a-max", type=float, help="max tangential acceleration [m/s^2]")
    g.add_argument("--j-max", type=float, help="max jerk [m/s^3]")
    g.add_argument("--a-lat-max", type=float, help="max lateral acceleration [m/s^2]")
    g.add_argument("--omega-max", type=float, help="max yaw rate [rad/s]")
    g.add_argument("--track-width", type=float, help="differential-drive track width [m]")
    g.add_argument("--wheel-v-max", type=float, help="max wheel speed [m/s]")
    g.add_argument(
        "--no-wheels", action="store_true", help="no differential-drive wheel-speed limit"
    )


def _map_args(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "map", metavar="MAP", help="map file: ROS .yaml, Moving AI .map, .pgm/.png, .npy"
    )
    p.add_argument(
        "--resolution", type=float, help="cell size [m] for images/.npy (and to override .map)"
    )
    p.add_argument(
        "--start", nargs=2, type=float, metavar=("X", "Y"), required=True, help="start point [m]"
    )
    p.add_argument(
        "--goal", nargs=2, type=float, metavar=("X", "Y"), required=True, help="goal point [m]"
    )


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
        "--costmap-weight", type=float, default=2.0,
        help="weight of the costmap's normalised cost in the search (default 2)",
    )  # fmt: skip
    g.add_argument("--speed-mask", metavar="YAML", help="Nav2 speed filter mask (map_server YAML)")
    g.add_argument(
        "--speed-mask-type", choices=("percentage", "absolute"), default="percentage",
        help="limit in percent of --v-max or in m/s (Nav2 filter type 1 or 2; default percentage)",
    )  # fmt: skip
    g.add_argument("--speed-mask-base", type=float, default=0.0,
                   help="Nav2 'base': limit = value * multiplier + base (default 0)")  # fmt: skip
    g.add_argument("--speed-mask-multiplier", type=float, default=1.0,
                   help="Nav2 'multiplier' (default 1)")  # fmt: skip
    g.add_argument("--frame-id", default="map", help="frame of the written poses (default map)")


def build_parser() -> argparse.ArgumentParser:
    """Return the argument parser of the ``trajopt`` command."""
    parser = _Parser(
        prog="trajopt",
        description="Occupancy grid + start + goal -> timed, collision-free, smooth trajectory.",
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress to stderr")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    p = sub.add_parser(
        "plan",
        help="plan a timed trajectory on a map",
        description="Plan a timed trajectory: inflate -> A* -> corridor -> "
        "smoother -> ruckig timing.",
    )
    _map_args(p)
    _robot_args(p)
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
    p.add_argument("--start-heading", type=float, help="exact start heading [rad]")
    p.add_argument("--goal-heading", type=float, help="exact goal heading [rad]")
    p.add_argument(
        "--fallback",
        action="store_true",
        help="if the smoother (or the timing) fails, return the A* polyline driven "
        "with stops and turns in place at the corners (differential drive; "
        "checked against the map) instead of an error",
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
    _map_args(p)
    _shape_args(
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

    p = sub.add_parser(
        "bench",
        help="benchmark methods on maps and scenarios (Dask, Parquet dataset)",
        description="Run maps x queries x methods on Dask distributed into a Parquet "
        "dataset (bench run), and summarise a dataset (bench report).",
    )
    bsub = p.add_subparsers(dest="bench_command", metavar="{run,report}", required=True)
    r = bsub.add_parser(
        "run",
        help="run methods on scenario files, maps or a named suite",
        description="Each INPUT is a Moving AI .scen file (its map found beside it or in "
        "../maps, or given with --map) or a map file (.yaml, .map) for seeded random "
        "queries (--queries, --seed). Rows, one per (query, method), go to the Parquet "
        "dataset --out; the summary table is printed at the end.",
    )
    r.add_argument("inputs", metavar="INPUT", nargs="*", help=".scen or map files")
    r.add_argument("--suite", help="a named suite: shared-small or shared-full")
    r.add_argument("--data", help="shared data folder for --suite (default $TRAJOPT_DATA)")
    r.add_argument("--map", help="the .map of a single .scen INPUT")
    r.add_argument("--out", required=True, help="dataset folder (Parquet files)")
    r.add_argument("--resume", action="store_true", help="skip rows the dataset already holds")
    r.add_argument("--methods", help="comma-separated methods (default: all but the peers)")
    r.add_argument("--limit", type=int, help="scenarios (or random queries) per map")
    r.add_argument(
        "--queries", type=int, default=20, help="random queries per map INPUT (default 20)"
    )
    r.add_argument("--seed", type=int, default=0, help="seed of the random queries (default 0)")
    r.add_argument(
        "--radius-cells",
        type=float,
        default=2.5,
        help="robot radius on Moving AI maps, in cells (default 2.5)",
    )
    r.add_argument(
        "--radius", type=float, default=0.165, help="robot radius on other maps [m] (default 0.165)"
    )
    r.add_argument(
        "--feasible-only",
        action="store_true",
        help="keep only scenarios whose end cells are free for the radius",
    )
    r.add_argument(
        "--scheduler",
        default="local",
        help="'local' (LocalCluster, default), 'serial', or tcp://host:8786",
    )
    r.add_argument("--workers", type=int, help="local worker processes (default: cores)")
    r.add_argument(
        "--chunk-size",
        type=int,
        help="queries per task (default: at least 8 tasks per worker, at most 4 queries each)",
    )
    r.add_argument("--no-progress", action="store_true", help="no progress bar")
    r.set_defaults(func=_cmd_bench_run)
    r = bsub.add_parser(
        "report",
        help="summary table and figures of a dataset",
        description="Prints the per-method summary of a dataset written by bench run and "
        "writes distribution figures with --figures.",
    )
    r.add_argument("dataset", metavar="DATASET", help="dataset folder (or .parquet file)")
    r.add_argument("--figures", help="folder for the figures (PNG)")
    r.set_defaults(func=_cmd_bench_report)

    p = sub.add_parser(
        "warm-up",
        help="compile and load every compiled kernel (once per environment)",
        description="Compile every numba kernel of astar and trajopt that numba's disk cache "
        "does not hold yet (in worker processes), then load them all and plan one small "
        "query. Run it once after installing (a container build, a CI cache step) so that "
        "no later command compiles.",
    )
    p.add_argument("--workers", type=int, default=None,
                   help="worker processes that compile (default: min(2, CPUs); 1: this one)")  # fmt: skip
    p.set_defaults(func=_cmd_warm_up)
    return parser


# --------------------------------------------------------------------- helpers
def _atomic_write(path: str | os.PathLike, write: Callable[[Path], None]) -> Path:
    """Call ``write(tmp)`` on a temporary file beside ``path``, then move it into place."""
    target = Path(path)
    if target.parent and not target.parent.exists():
        raise CliError(f"output folder {str(target.parent)!r} does not exist")
    return atomic_write(target, write)


def _save_figure(fig: Any, path: str | os.PathLike) -> Path:
    suffix = Path(path).suffix.lower()
    if suffix not in (".png", ".pdf", ".svg", ".jpg", ".jpeg"):
        raise CliError(f"--plot file must end in .png, .pdf, .svg or .jpg, got {str(path)!r}")
    out = _atomic_write(path, lambda tmp: fig.savefig(tmp, dpi=150, format=suffix[1:]))
    import matplotlib.pyplot as plt

    plt.close(fig)
    return out


def _load(args: argparse.Namespace):
    import astar

    kwargs: dict[str, Any] = {}
    if args.resolution is not None:
        kwargs["resolution"] = args.resolution
    return astar.load_map(args.map, **kwargs)


def _read_footprint_file(path: str) -> Any:
    """Return the footprint of a ``--footprint-file`` (JSON or CSV/text rows ``x, y``).

    Parameters
    ----------
    path : str
        A JSON file holding a list of ``[x, y]`` vertices (m) or an object with the key
        ``"vertices"``, or a text file of rows ``x, y`` (m; commas or spaces between the
        numbers, ``#`` comments, blank lines and one header line such as ``x,y`` allowed).

    Returns
    -------
    Footprint

    Raises
    ------
    CliError
        The file is missing, unreadable or does not follow the format.
    InvalidInputError
        The vertices do not form a valid footprint (the rule is named, with the file).
    """
    import json
    import math

    from trajopt.errors import InvalidInputError
    from trajopt.robot._footprint import Footprint

    where = f"--footprint-file {path!r}"
    file = Path(path)
    if not file.is_file():
        raise CliError(f"{where} does not exist or is not a file")
    try:
        text = file.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise CliError(f"{where} cannot be read: {exc}") from None
    rule_json = 'a JSON list of [x, y] vertices (m) or an object {"vertices": [[x, y], ...]}'
    rule_rows = "rows of two numbers 'x, y' (m)"
    if file.suffix.lower() == ".json" or text.lstrip()[:1] in ("[", "{"):
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise CliError(f"{where} is not valid JSON ({exc}); expected {rule_json}") from None
        if isinstance(data, dict):
            if "vertices" not in data:
                raise CliError(f"{where} has no key 'vertices'; expected {rule_json}")
            data = data["vertices"]
        ok = isinstance(data, list) and all(
            isinstance(v, list)
            and len(v) == 2
            and all(isinstance(c, (int, float)) and not isinstance(c, bool) for c in v)
            for v in data
        )
        if not ok:
            raise CliError(f"{where} must hold {rule_json}; got {json.dumps(data)[:60]}")
        vertices = [[float(x), float(y)] for x, y in data]
    else:
        vertices = []
        header_allowed = True
        for lineno, raw in enumerate(text.splitlines(), 1):
            line = raw.split("#", 1)[0].strip()
            if not line:
                continue
            cells = line.replace(",", " ").replace(";", " ").split()
            try:
                row = [float(c) for c in cells]
            except ValueError:
                if header_allowed:
                    header_allowed = False
                    continue  # one header line such as "x, y"
                row = []
            header_allowed = False
            if len(row) != 2 or not all(math.isfinite(c) for c in row):
                raise CliError(f"{where} line {lineno}: {raw.strip()!r} is not {rule_rows}")
            vertices.append(row)
    try:
        return Footprint(vertices)
    except InvalidInputError as exc:
        raise InvalidInputError(f"{where}: {exc}") from None


def _numbers(values: Sequence[float]) -> str:
    return " ".join(f"{v:g}" for v in values)


def _robot(args: argparse.Namespace):
    from trajopt.errors import InvalidInputError
    from trajopt.robot._footprint import Footprint
    from trajopt.robot._robot import Robot

    names = ("radius", "v_max", "a_max", "j_max", "a_lat_max", "omega_max", "track_width",
             "wheel_v_max")  # fmt: skip
    kwargs = {k: getattr(args, k, None) for k in names}
    kwargs = {k: v for k, v in kwargs.items() if v is not None}
    if getattr(args, "no_wheels", False):
        kwargs["track_width"] = None
        kwargs["wheel_v_max"] = None
    if args.footprint is not None:
        try:
            kwargs["footprint"] = Footprint.rectangle(*args.footprint)
        except InvalidInputError as exc:
            raise InvalidInputError(f"--footprint {_numbers(args.footprint)}: {exc}") from None
    elif args.footprint_file is not None:
        kwargs["footprint"] = _read_footprint_file(args.footprint_file)
    return Robot(**kwargs)


def _require_matplotlib() -> None:
    try:
        import matplotlib

        matplotlib.use("Agg")
    except ImportError as exc:
        raise CliError("figures need matplotlib: pip install 'trajopt[analysis]'") from exc


# -------------------------------------------------------------------- commands
_OUT_SUFFIXES = (".csv", ".json", ".mcap")
_PLOT_POSES = (5, 40)  # least and most footprints drawn along the trajectory by plan --plot


def _cmd_plan(args: argparse.Namespace) -> int:
    from trajopt._planner import Planner
    from trajopt.smoother import Smoother

    if args.out and Path(args.out).suffix.lower() not in _OUT_SUFFIXES:
        raise CliError(f"--out must end in .csv, .json or .mcap, got {args.out!r}")
    if args.costmap:
        import astar

        grid = astar.load_costmap(args.map)
    else:
        grid = _load(args)
    robot = _robot(args)
    speed_limits = None
    if args.speed_mask:
        from trajopt.timing._speed_limits import load_speed_mask

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
    traj = planner.plan(
        args.start, args.goal, start_heading=args.start_heading, goal_heading=args.goal_heading
    )
    stages = traj.stats.get("stages_s", {})
    line = (
        f"duration {traj.duration:.3f} s, length {traj.path.length:.3f} m, "
        f"planned in {1e3 * stages.get('total', float('nan')):.1f} ms"
    )
    if traj.stats.get("corridor"):
        line += f", corridor {traj.stats['corridor']}"
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
            traj.to_mcap(args.out, dt=args.dt, frame_id=args.frame_id)
        print(f"wrote {args.out}")
    if args.plot:
        _require_matplotlib()
        import matplotlib.pyplot as plt
        import numpy as np

        from trajopt.analysis.plotting import plot_footprints, plot_paths

        steps = traj.steps
        fig, ax = plt.subplots(figsize=(7, 7))
        name = "stop and turn" if traj.stats.get("fallback") else "proposed"
        plot_paths(
            grid,
            {"A*": steps.grid_path.to_world(grid), name: traj.path},
            inflated=steps.inflated_grid,
            corridor=steps.corridor,
            start=steps.start,
            goals={"goal": steps.goal},
            ax=ax,
        )
        if robot.footprint is not None:
            # evenly spaced in time, about one circumscribed diameter apart on average
            poses = int(np.clip(round(traj.path.length / robot.width) + 1, *_PLOT_POSES))
            every_s = max(traj.duration, 1e-6) / (poses - 1)
            plot_footprints(ax, traj, robot, every_s=every_s)
            ax.legend(loc="best", fontsize="small")
        print(f"wrote {_save_figure(fig, args.plot)}")
    return 0


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

    grid = _load(args)
    # the comparison's methods are disc models: a footprint enters by its circumscribed radius
    radius = args.radius if args.radius is not None else _robot(args).radius
    table = compare(grid, tuple(args.start), tuple(args.goal), robot_radius=radius)
    print(_table_text(table, args.format))
    if args.out:
        suffix = Path(args.out).suffix.lower()
        fmt = {".csv": "csv", ".md": "markdown"}.get(suffix, "text")
        text = _table_text(table, fmt)
        _atomic_write(args.out, lambda tmp: tmp.write_text(text + "\n"))
    if args.plot:
        _require_matplotlib()
        from trajopt.analysis.plotting import plot_paths

        paths = {k: v for k, v in table.paths.items() if v is not None}
        fig, _ = plot_paths(
            grid,
            paths,
            inflated=_avoidance(grid, table),
            start=tuple(args.start),
            goals={"goal": tuple(args.goal)},
        )
        print(f"wrote {_save_figure(fig, args.plot)}")
    return 0


def _cmd_demo(args: argparse.Namespace) -> int:
    from trajopt._planner import Planner
    from trajopt.analysis.comparison import compare
    from trajopt.analysis.scenes import paper
    from trajopt.robot._robot import Robot

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    scene = paper()
    plots = not args.no_plots
    if plots:
        try:
            _require_matplotlib()
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
        _atomic_write(out / f"compare_{name}.csv", lambda tmp, s=csv_text: tmp.write_text(s))
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
            _save_figure(fig, out / f"paths_{name}.png")
            traj = planner.plan(scene.start, scene.goal(name))
            fig, _ = plot_profiles(traj)
            _save_figure(fig, out / f"profile_{name}.png")
    report = "# trajopt demo: the paper scene\n\n" + "\n".join(sections)
    _atomic_write(out / "compare.md", lambda tmp: tmp.write_text(report))
    print(f"\nwrote tables{' and figures' if plots else ''} to {out}/")
    return 0


def _bench_sources(args: argparse.Namespace) -> list[Any]:
    from trajopt.analysis import bench

    if args.limit is not None and args.limit < 1:
        raise CliError(f"--limit must be >= 1, got {args.limit}")
    if not args.inputs and not args.suite:
        raise CliError("give INPUT files or --suite")
    if args.map and len(args.inputs) != 1:
        raise CliError(f"--map needs exactly one .scen INPUT, got {len(args.inputs)}")
    sources = []
    if args.suite:
        sources += bench.suite(
            args.suite,
            args.data,
            limit=args.limit,
            radius_cells=args.radius_cells,
            radius_m=args.radius,
            seed=args.seed,
        )
    for item in args.inputs:
        if item.endswith(".scen"):
            sources.append(
                bench.movingai_queries(
                    item,
                    args.map,
                    limit=args.limit,
                    radius_cells=args.radius_cells,
                    feasible_only=args.feasible_only,
                )
            )
        else:
            n = args.queries if args.limit is None else min(args.queries, args.limit)
            sources.append(bench.random_queries(item, n, seed=args.seed, radius_m=args.radius))
    return sources


def _cmd_bench_run(args: argparse.Namespace) -> int:
    from trajopt.analysis import bench

    sources = _bench_sources(args)
    res = bench.run(
        sources,
        args.out,
        methods=args.methods,
        scheduler=args.scheduler,
        workers=args.workers,
        chunk_size=args.chunk_size,
        resume=args.resume,
        progress=not args.no_progress,
    )
    print(
        f"{res.rows_written} rows written, {res.rows_skipped} already held, "
        f"{res.rows_expected} in all ({res.chunks} chunks, {res.workers} workers, "
        f"{res.elapsed_s:.1f} s) -> {res.out}"
    )
    print(bench.report(res.out))
    return 0


def _cmd_bench_report(args: argparse.Namespace) -> int:
    from trajopt.analysis import bench

    print(bench.report(args.dataset, figures_dir=args.figures))
    if args.figures:
        print(f"wrote figures to {args.figures}/")
    return 0


def _cmd_warm_up(args: argparse.Namespace) -> int:
    import trajopt._kernel_cache as kernel_cache

    warm_up = kernel_cache.warm_up_module().warm_up
    if args.workers is not None and args.workers < 1:
        raise CliError(f"--workers must be >= 1, got {args.workers}")
    t0 = time.perf_counter()
    report = _compile_kernels(None, args.workers)
    if report.cold and not report.failed:
        print(f"compiled {len(report.compiled)} of {len(report.cold)} uncached kernels in "
              f"{report.seconds:.1f} s ({report.workers or 1} process(es))")  # fmt: skip
    for name, error in report.failed.items():
        print(f"trajopt warm-up: exercise {name!r} failed: {error}", file=sys.stderr)
    warm_up()
    n = len(kernel_cache.kernels())
    left = kernel_cache.cold_kernels()
    print(f"{n - len(left)} of {n} kernels compiled and loaded; warm-up took "
          f"{time.perf_counter() - t0:.1f} s")  # fmt: skip
    if left:
        print(f"trajopt warm-up: not compiled: {', '.join(left)}", file=sys.stderr)
        return 1
    return 0


# ---------------------------------------------------------------- compile notice
#: commands that plan
_PLANNING = ("plan", "compare", "demo", "bench")


def _compile_kernels(first: Sequence[str] | None, workers: int | None) -> Any:
    """Compile the uncached kernels with a notice on stderr; a progress bar on a terminal.

    With ``first`` (warm-up exercises) it returns when those are compiled, the rest going on
    in the background (the report's ``wait()``).
    """
    import trajopt._kernel_cache as kernel_cache

    cold = kernel_cache.cold_kernels()
    if not cold:
        return kernel_cache.CompileReport()
    n_workers = workers if workers is not None else min(2, os.cpu_count() or 1)
    about = kernel_cache.estimate_seconds(len(cold), n_workers)
    print(f"trajopt: compiling numerical kernels once for this environment (about "
          f"{about:.0f} s; later runs load them from numba's cache)...", file=sys.stderr,
          flush=True)  # fmt: skip
    bar = None
    if sys.stderr.isatty():
        try:
            from tqdm import tqdm

            bar = tqdm(total=len(cold), unit="kernel", file=sys.stderr, leave=False)
        except ImportError:
            pass

    def progress(done: int, total: int, kernel: str) -> None:
        if bar is not None:
            bar.n = done
            bar.set_postfix_str(kernel.rsplit(".", 1)[-1], refresh=True)

    try:
        report = kernel_cache.compile_kernels(workers=n_workers, progress=progress, first=first)
    finally:
        if bar is not None:
            bar.close()
    if first is None:
        print(f"trajopt: compiled {len(report.compiled)} kernels in {report.seconds:.1f} s",
              file=sys.stderr, flush=True)  # fmt: skip
    return report


def _compile_notice(args: argparse.Namespace) -> Any:
    """Before a planning command: compile what is not cached, and say so (stderr).

    The kernels of a default plan and of the comparison come first; the command starts when
    they are compiled while the worker processes go on with the others (the returned
    report's ``wait()``, called when the command is done). A kernel the command needs that
    is not compiled yet compiles when first used, with the library's one-line notice (logger
    ``trajopt._kernel_cache``) on stderr.
    """
    if args.command not in _PLANNING or getattr(args, "bench_command", "run") != "run":
        return None
    import trajopt._kernel_cache as kernel_cache

    notice = logging.getLogger("trajopt._kernel_cache")
    if not any(isinstance(h, _StderrLines) for h in notice.handlers):
        notice.addHandler(_StderrLines())
        notice.propagate = False
    return _compile_kernels(kernel_cache.warm_up_module().CORE_EXERCISES, None)


class _StderrLines(logging.StreamHandler):
    """Log records as plain lines on the current ``sys.stderr`` (as :data:`logging.lastResort`)."""

    def __init__(self) -> None:
        super().__init__()
        self.setFormatter(logging.Formatter("%(message)s"))

    @property
    def stream(self) -> Any:  # noqa: D102
        return sys.stderr

    @stream.setter
    def stream(self, value: Any) -> None:
        pass


# ------------------------------------------------------------------------ main
def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``trajopt`` console script; returns the exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(
        level=logging.INFO if args.verbose else logging.WARNING,
        format="%(levelname)s %(name)s: %(message)s",
    )
    if args.command is None:
        parser.print_help()
        return EXIT_USAGE
    from astar.errors import AstarError
    from trajopt.errors import TrajoptError

    compiling = None
    try:
        compiling = _compile_notice(args)
        return int(args.func(args))
    except (CliError, AstarError, TrajoptError, OSError) as exc:
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        print(f"trajopt {args.command}: error: {type(exc).__name__}: {msg}", file=sys.stderr)
        return EXIT_USAGE
    finally:
        if compiling is not None and compiling.wait().cold:
            print(f"trajopt: compiled {len(compiling.compiled)} kernels in "
                  f"{compiling.seconds:.1f} s", file=sys.stderr)  # fmt: skip


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
