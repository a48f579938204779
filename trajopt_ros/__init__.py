"""trajopt_ros: the trajopt planner as a ROS 2 node (``trajopt-ros``, ``trajopt ros``).

Modules: :mod:`trajopt_ros.node` (the node; needs rclpy), :mod:`trajopt_ros.params` (its
parameters and their validation), :mod:`trajopt_ros.convert` (messages <-> trajopt values),
:mod:`trajopt_ros.check` (the independent clearance check before publishing),
:mod:`trajopt_ros.codes` (error codes per interface), :mod:`trajopt_ros.build` (the
interface packages, built and cached with the pip-installed ROS tools) and
:mod:`trajopt_ros.cli` (the command line). Importing this package does not import rclpy;
the core library :mod:`trajopt` never does.
"""

from __future__ import annotations

__all__ = ["main"]


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``trajopt-ros`` (see :func:`trajopt_ros.cli.main`)."""
    from trajopt_ros.cli import main as _main

    return _main(argv)
