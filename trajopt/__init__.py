"""trajopt: occupancy grid + start + goal -> timed, collision-free, smooth trajectory.

Pipeline: :func:`astar.inflate` -> :func:`astar.find_path` -> :func:`build_corridor`
-> :class:`Smoother` -> :func:`time_parameterize`, or all at once with :func:`plan`.

Public names are imported lazily (PEP 562) so that ``import trajopt`` stays fast;
heavy dependencies (CasADi, ruckig, matplotlib) load when first used.
"""

from __future__ import annotations

import importlib
import logging
from typing import TYPE_CHECKING, Any

logging.getLogger(__name__).addHandler(logging.NullHandler())

__version__ = "0.1.0"

_EXPORTS: dict[str, str] = {
    # errors
    "TrajoptError": "trajopt.errors",
    "InvalidInputError": "trajopt.errors",
    "NoPathError": "trajopt.errors",
    "SmoothingError": "trajopt.errors",
    "TimingError": "trajopt.errors",
    "IllPosedFitError": "trajopt.errors",
    # curves
    "ParametricCurve": "trajopt.curve",
    "BSplineCurve": "trajopt.bspline",
    # corridor and smoother
    "Box": "trajopt.corridor",
    "Corridor": "trajopt.corridor",
    "build_corridor": "trajopt.corridor",
    "ConvexPolygon": "trajopt.polygon_corridor",
    "PolygonCorridor": "trajopt.polygon_corridor",
    "build_polygon_corridor": "trajopt.polygon_corridor",
    "Smoother": "trajopt.smoother",
    "SmoothPath": "trajopt.smoother",
    # timing
    "Robot": "trajopt.robot",
    "time_parameterize": "trajopt.timing",
    "Trajectory": "trajopt.trajectory",
    "TrajectoryChain": "trajopt.trajectory_chain",
    "TurnInPlace": "trajopt.trajectory_chain",
    "State": "trajopt.state",
    "SpeedLimits": "trajopt.speed_limits",
    "load_speed_mask": "trajopt.speed_limits",
    # ROS 2 files
    "read_mcap": "trajopt.ros_mcap",
    "write_mcap": "trajopt.ros_mcap",
    # the opt-in stop-and-turn fallback
    "StopAndTurnTrajectory": "trajopt.fallback",
    "stop_and_turn": "trajopt.fallback",
    # pipeline and analysis
    "plan": "trajopt.pipeline",
    "Planner": "trajopt.pipeline",
    "warm_up": "trajopt.warm_up",
    "compare": "trajopt.comparison",
    "ComparisonTable": "trajopt.comparison",
}

_SUBMODULES = {"scenes", "fits", "metrics", "plotting", "cli", "fallback"}

__all__ = sorted(_EXPORTS) + sorted(_SUBMODULES)


def __getattr__(name: str) -> Any:
    if name in _SUBMODULES:
        module = importlib.import_module(f"trajopt.{name}")
        globals()[name] = module
        return module
    module_name = _EXPORTS.get(name)
    if module_name is None:
        raise AttributeError(f"module 'trajopt' has no attribute {name!r}")
    value = getattr(importlib.import_module(module_name), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


if TYPE_CHECKING:  # pragma: no cover
    from trajopt import cli, fallback, fits, metrics, plotting, scenes
    from trajopt.bspline import BSplineCurve
    from trajopt.comparison import ComparisonTable, compare
    from trajopt.corridor import Box, Corridor, build_corridor
    from trajopt.curve import ParametricCurve
    from trajopt.errors import (
        IllPosedFitError,
        InvalidInputError,
        NoPathError,
        SmoothingError,
        TimingError,
        TrajoptError,
    )
    from trajopt.fallback import StopAndTurnTrajectory, stop_and_turn
    from trajopt.pipeline import Planner, plan
    from trajopt.polygon_corridor import ConvexPolygon, PolygonCorridor, build_polygon_corridor
    from trajopt.robot import Robot
    from trajopt.ros_mcap import read_mcap, write_mcap
    from trajopt.smoother import Smoother, SmoothPath
    from trajopt.speed_limits import SpeedLimits, load_speed_mask
    from trajopt.state import State
    from trajopt.timing import time_parameterize
    from trajopt.trajectory import Trajectory
    from trajopt.trajectory_chain import TrajectoryChain, TurnInPlace
    from trajopt.warm_up import warm_up
