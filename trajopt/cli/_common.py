"""What the commands share: the parser classes, the user-facing error, the map and robot options.

:class:`Parser` turns argparse's errors into one line and exit code 2; :class:`CliError` is
a failure the user can fix (``main`` prints it as one line, exit code 2). The option groups
(:func:`map_args`, :func:`robot_args`, :func:`shape_args`) and their readers
(:func:`load_map`, :func:`robot_from_args`) are shared by ``plan`` and ``compare``; the
output helpers (:func:`atomic_output`, :func:`save_figure`) write files atomically.
"""

from __future__ import annotations

import argparse
import math
import os
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, NoReturn

from astar.files import atomic_write

EXIT_USAGE = 2


class Formatter(argparse.HelpFormatter):
    """Help formatter that shows an action's ``usage_metavar`` verbatim when it has one."""

    def _format_args(self, action: argparse.Action, default_metavar: str) -> str:
        fixed = getattr(action, "usage_metavar", None)
        return fixed if fixed is not None else super()._format_args(action, default_metavar)


class Parser(argparse.ArgumentParser):
    """argparse that reports errors as one line and exit code 2."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("formatter_class", Formatter)
        super().__init__(*args, **kwargs)

    def error(self, message: str) -> NoReturn:
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message}\n")


class FootprintAction(argparse.Action):
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


def finite_angle(text: str) -> float:
    """Return an angle (rad) given on the command line: a finite number, else a usage error."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an angle in radians, got {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"the angle must be finite (rad), got {text!r}")
    return value


# ----------------------------------------------------------------- arguments
def shape_args(g: Any, radius_help: str) -> None:
    """Add ``--radius``, ``--footprint`` and ``--footprint-file``, mutually exclusive."""
    shape = g.add_mutually_exclusive_group()
    shape.add_argument("--radius", type=float, help=radius_help)
    shape.add_argument(
        "--footprint",
        nargs="+",
        type=float,
        action=FootprintAction,
        help="rectangular footprint [m]: length L (x forward), width W and the rear offset "
        "REAR from the rotation centre back to the rear edge (default L/2); the disc-model "
        "stages keep its circumscribed radius clear",
    )
    shape.add_argument(
        "--footprint-file",
        metavar="PATH",
        help="convex footprint polygon [m, robot frame, x forward]: JSON (a list of [x, y] "
        "or {\"vertices\": [[x, y], ...]}) or CSV/text rows 'x, y'",
    )


def robot_args(p: argparse.ArgumentParser) -> None:
    """Add the robot's shape and limits (``plan``)."""
    g = p.add_argument_group("robot and limits (SI units; defaults: trajopt.Robot())")
    shape_args(g, "disc robot radius [m]")
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
    g.add_argument(
        "--drive",
        default="differential",
        metavar="{differential,omni,ackermann}",
        help="how the base moves: 'differential' (default; faces its direction of travel, "
        "turns in place at rest), 'omni' (mecanum/omni wheels: the orientation is "
        "independent of the direction of travel) or 'ackermann' (car-like: needs "
        "--min-turning-radius and both --start-heading and --goal-heading; may reverse)",
    )
    g.add_argument(
        "--min-turning-radius", type=float, help="car-like robot's minimum turning radius [m]"
    )
    g.add_argument("--wheelbase", type=float, help="car-like robot's wheelbase [m]")
    g.add_argument("--v-max-reverse", type=float, help="car-like robot's max speed backwards [m/s]")
    g.add_argument(
        "--steer-rate-max", type=float, help="car-like robot's max steering rate [rad/s]"
    )
    g.add_argument(
        "--forward-only", action="store_true", help="car-like robot never reverses (Dubins)"
    )


def map_args(p: argparse.ArgumentParser) -> None:
    """Add ``MAP``, ``--resolution``, ``--start`` and ``--goal``."""
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


# --------------------------------------------------------------------- readers
def load_map(args: argparse.Namespace):
    """Return the grid of ``MAP`` (with ``--resolution`` when given)."""
    import astar

    kwargs: dict[str, Any] = {}
    if args.resolution is not None:
        kwargs["resolution"] = args.resolution
    return astar.load_map(args.map, **kwargs)


def read_footprint_file(path: str) -> Any:
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
    from trajopt.robot import Footprint

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


def robot_from_args(args: argparse.Namespace):
    """Return the :class:`~trajopt.Robot` of the robot options (defaults where not given)."""
    from trajopt.errors import InvalidInputError
    from trajopt.robot import Footprint, Robot

    names = (
        "radius",
        "v_max",
        "a_max",
        "j_max",
        "a_lat_max",
        "omega_max",
        "track_width",
        "wheel_v_max",
        "min_turning_radius",
        "wheelbase",
        "v_max_reverse",
        "steer_rate_max",
    )
    kwargs = {k: getattr(args, k, None) for k in names}
    kwargs = {k: v for k, v in kwargs.items() if v is not None}
    if getattr(args, "drive", None) is not None:
        kwargs["drive"] = args.drive  # validated by Robot
    if getattr(args, "forward_only", False):
        kwargs["reverse"] = False  # refused by Robot unless drive='ackermann'
    if getattr(args, "no_wheels", False):
        kwargs["track_width"] = None
        kwargs["wheel_v_max"] = None
    if args.footprint is not None:
        try:
            kwargs["footprint"] = Footprint.rectangle(*args.footprint)
        except InvalidInputError as exc:
            raise InvalidInputError(f"--footprint {_numbers(args.footprint)}: {exc}") from None
    elif args.footprint_file is not None:
        kwargs["footprint"] = read_footprint_file(args.footprint_file)
    return Robot(**kwargs)


# --------------------------------------------------------------------- outputs
def atomic_output(path: str | os.PathLike, write: Callable[[Path], None]) -> Path:
    """Call ``write(tmp)`` on a temporary file beside ``path``, then move it into place."""
    target = Path(path)
    if target.parent and not target.parent.exists():
        raise CliError(f"output folder {str(target.parent)!r} does not exist")
    return atomic_write(target, write)


def require_matplotlib() -> None:
    """Select matplotlib's Agg backend; :class:`CliError` when matplotlib is missing."""
    try:
        import matplotlib

        matplotlib.use("Agg")
    except ImportError as exc:
        raise CliError("figures need matplotlib: pip install 'trajopt[analysis]'") from exc


def save_figure(fig: Any, path: str | os.PathLike) -> Path:
    """Write ``fig`` atomically (the format from the suffix, 150 dpi) and close it."""
    suffix = Path(path).suffix.lower()
    if suffix not in (".png", ".pdf", ".svg", ".jpg", ".jpeg"):
        raise CliError(f"--plot file must end in .png, .pdf, .svg or .jpg, got {str(path)!r}")
    out = atomic_output(path, lambda tmp: fig.savefig(tmp, dpi=150, format=suffix[1:]))
    import matplotlib.pyplot as plt

    plt.close(fig)
    return out
