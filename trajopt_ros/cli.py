"""The ``trajopt-ros`` command (also ``trajopt ros``).

``trajopt-ros [--managed] [--ros-args ...]`` runs the node (``--managed``: as a lifecycle
node, :class:`~trajopt_ros.node.ManagedPlannerNode`); ``trajopt-ros build-interfaces [--force]``
builds (or finds cached) the interface packages and prints where and how long it took.
Exit codes: 0 after a clean shutdown (SIGINT/SIGTERM), 2 for invalid parameters or a
failed interface build (one line on stderr naming the cause).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

__all__ = ["main"]

EXIT_USAGE = 2


def main(argv: Sequence[str] | None = None) -> int:
    """Run the node or a sub-command; returns the exit code."""
    args = list(sys.argv[1:] if argv is None else argv)
    ros_args: list[str] = []
    if "--ros-args" in args:
        i = args.index("--ros-args")
        args, ros_args = args[:i], args[i:]
    parser = argparse.ArgumentParser(
        prog="trajopt-ros",
        description="The trajopt planner as a ROS 2 node (default), or a maintenance command.",
        epilog="ROS arguments follow --ros-args, e.g. --ros-args --params-file robot.yaml",
    )
    parser.add_argument("command", nargs="?", choices=["run", "build-interfaces"], default="run")
    parser.add_argument("--force", action="store_true", help="build-interfaces: build again")
    parser.add_argument(
        "--managed",
        action="store_true",
        help="run: a managed (lifecycle) node, unconfigured until told by ~/change_state",
    )
    opts = parser.parse_args(args)
    from trajopt_ros.errors import InterfaceBuildError, ParameterError

    if opts.command == "build-interfaces":
        from trajopt_ros.build import build_interfaces

        try:
            build = build_interfaces(force=opts.force)
        except InterfaceBuildError as exc:
            print(f"trajopt-ros build-interfaces: error: {exc}", file=sys.stderr)
            return EXIT_USAGE
        how = "cached" if build.cached else f"built in {build.seconds:.1f} s"
        print(f"{build.prefix} ({how})")
        return 0
    try:
        import rclpy
    except ImportError:
        print(
            "trajopt-ros: error: rclpy is not installed; pip install 'trajopt[ros2]'",
            file=sys.stderr,
        )
        return EXIT_USAGE
    from rclpy.executors import MultiThreadedExecutor
    from rclpy.signals import SignalHandlerOptions

    from trajopt_ros.node import ManagedPlannerNode, PlannerNode, spin

    rclpy.init(args=["trajopt-ros", *ros_args], signal_handler_options=SignalHandlerOptions.ALL)
    executor = MultiThreadedExecutor(num_threads=4)
    try:
        kind = ManagedPlannerNode if opts.managed else PlannerNode
        node = kind(freeze_gc=True)  # this process runs the node and nothing else
    except (ParameterError, InterfaceBuildError) as exc:
        print(f"trajopt-ros: error: {type(exc).__name__}: {exc}", file=sys.stderr)
        rclpy.try_shutdown()
        return EXIT_USAGE
    except Exception as exc:  # e.g. a parameter of the wrong type in the params file
        if not rclpy.ok():  # a signal arrived during the start-up
            return 0
        if type(exc).__module__.startswith("rclpy"):
            print(f"trajopt-ros: error: {type(exc).__name__}: {exc}", file=sys.stderr)
            rclpy.try_shutdown()
            return EXIT_USAGE
        raise
    spin(node, executor)
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
