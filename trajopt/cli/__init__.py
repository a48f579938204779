"""The ``trajopt`` command line: ``plan``, ``compare``, ``demo``, ``bench`` (``run``, ``report``), ``warm-up``, ``ros``.

Every failure the user can fix (bad arguments, unreadable maps, blocked or unreachable
start/goal, infeasible limits) exits with code 2 and one line on stderr, no traceback.
Output files are written atomically: a partial file never replaces a good one.

The first planning command in a new environment compiles the numba kernels first, in two
worker processes, with a line (and a progress bar on a terminal) on stderr saying so;
``trajopt warm-up`` compiles and loads all of them ahead of time.

Here: the parser and :func:`main`. The commands live in internal modules, one per group:
``_plan`` (``plan``, ``compare``, ``demo``), ``_bench`` (``bench run``, ``bench report``),
``_warm_up`` (``warm-up`` and the compile notice); ``_common`` holds the parser classes, the
user-facing error and the map and robot options they share. ``trajopt ros ...`` is the ROS 2
node's own command line (``trajopt-ros``, in the optional ``trajopt_ros`` package: its
``--ros-args`` are not this parser's), handed over before parsing.
"""

from __future__ import annotations

import argparse
import logging
import sys
from collections.abc import Sequence

from trajopt.cli import _bench, _plan, _warm_up
from trajopt.cli._common import EXIT_USAGE, CliError, Parser

__all__ = ["main", "build_parser"]

logger = logging.getLogger(__name__)


def build_parser() -> argparse.ArgumentParser:
    """Return the argument parser of the ``trajopt`` command."""
    parser = Parser(
        prog="trajopt",
        description="Occupancy grid + start + goal -> timed, collision-free, smooth trajectory.",
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress to stderr")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=Parser)
    _plan.add_parsers(sub)  # plan, compare, demo
    _bench.add_parsers(sub)  # bench run, bench report
    _warm_up.add_parser(sub)  # warm-up
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``trajopt`` console script; returns the exit code."""
    given = list(sys.argv[1:] if argv is None else argv)
    if given[:1] == ["ros"]:  # the node's command line (pip install -e ".[ros2]")
        try:
            from trajopt_ros.cli import main as ros_main
        except ImportError as exc:
            print(
                f"trajopt ros: error: {exc} (install the extra: pip install 'trajopt[ros2]')",
                file=sys.stderr,
            )
            return EXIT_USAGE
        return ros_main(given[1:])
    parser = build_parser()
    args = parser.parse_args(given)
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
        compiling = _warm_up.compile_notice(args)
        return int(args.func(args))
    except (CliError, AstarError, TrajoptError, OSError) as exc:
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        print(f"trajopt {args.command}: error: {type(exc).__name__}: {msg}", file=sys.stderr)
        return EXIT_USAGE
    finally:
        if compiling is not None and compiling.wait().cold:
            print(
                f"trajopt: compiled {len(compiling.compiled)} kernels in {compiling.seconds:.1f} s",
                file=sys.stderr,
            )
