"""trajopt: occupancy grid + start + goal -> timed, collision-free, smooth trajectory.

Pipeline: :func:`astar.inflate` -> :func:`astar.find_path` -> :func:`build_polygon_corridor`
(or :func:`build_corridor`) -> :class:`Smoother` -> :func:`time_parameterize`, or all at once
with :func:`plan` (one query) and :class:`Planner` (many queries and re-plans on one map).

**Core**: :func:`plan`, :class:`Planner` (settings as one value: :class:`PlannerOptions`),
:class:`Robot` with its drive (:class:`Differential`, :class:`Omni`, :class:`Ackermann`, the
:class:`Drive` protocol), :class:`Trajectory` (every plan is a :class:`PlanResult`),
:class:`State`, :class:`Smoother`, the errors (:class:`TrajoptError` and its subclasses)
and :func:`warm_up` (compile the numerical kernels ahead of time).

**Moving obstacles**: :class:`MovingObstacle` (a predicted disc or convex polygon),
:func:`certify_movers` (a continuous-time proof of the distance to them) and
:func:`retime_for_movers` (the same path re-timed so that they pass; :class:`BlockedError`).

**Stages**, for users who compose them: the corridors (:class:`PolygonCorridor` of
:class:`ConvexPolygon`, :class:`Corridor` of :class:`Box`), :class:`SmoothPath`, the curves
(:class:`ParametricCurve`, :class:`BSplineCurve`), :func:`time_parameterize` with
:class:`SpeedLimits` (:func:`load_speed_mask`), the stop-and-turn motion
(:func:`stop_and_turn`, :class:`StopAndTurnTrajectory`), :class:`TurnInPlace` and
:class:`TrajectoryChain` (a differential drive's pose-to-pose plans), :class:`SteerInPlace`
(a car's steering at rest, at its cusps and ends), :class:`OmniTrajectory`
(an omnidirectional base's), and the ROS 2 MCAP files (:func:`write_mcap`, :func:`read_mcap`).

**Analysis**: :func:`compare` and :class:`ComparisonTable` (the chapter's table), and the
modules ``trajopt.metrics``, ``trajopt.fits``, ``trajopt.scenes``, ``trajopt.plotting``,
``trajopt.comparison`` and ``trajopt.bench`` (all in :mod:`trajopt.analysis`).

The packages below hold the stages (``geometry``, ``drive``, ``robot``, ``motion``, ``corridor``,
``smoother``, ``timing``, ``moving``, ``planning``, ``replan``, ``analysis``); ``docs/architecture.md``
draws the flow. Names are imported lazily (PEP 562) so that ``import trajopt`` stays fast;
heavy dependencies (CasADi, ruckig, matplotlib) load when first used.
"""

from __future__ import annotations

import importlib
import logging
from typing import TYPE_CHECKING, Any

logging.getLogger(__name__).addHandler(logging.NullHandler())

__version__ = "0.1.0"

_EXPORTS: dict[str, str] = {
    # core
    "plan": "trajopt._planner",
    "Planner": "trajopt._planner",
    "PlannerOptions": "trajopt._planner",
    "Robot": "trajopt.robot",
    "Differential": "trajopt.drive",
    "Omni": "trajopt.drive",
    "Ackermann": "trajopt.drive",
    "Drive": "trajopt.drive",
    "PlanResult": "trajopt.motion",
    "State": "trajopt.robot",
    "Trajectory": "trajopt.motion",
    "MovingObstacle": "trajopt.moving",
    "certify_movers": "trajopt.moving",
    "retime_for_movers": "trajopt.moving",
    "Smoother": "trajopt.smoother",
    "warm_up": "trajopt.warmup",
    "TrajoptError": "trajopt.errors",
    "InvalidInputError": "trajopt.errors",
    "NoPathError": "trajopt.errors",
    "SmoothingError": "trajopt.errors",
    "TimingError": "trajopt.errors",
    "BlockedError": "trajopt.errors",
    "IllPosedFitError": "trajopt.errors",
    # stages
    "ParametricCurve": "trajopt.geometry",
    "BSplineCurve": "trajopt.geometry",
    "Box": "trajopt.corridor",
    "Corridor": "trajopt.corridor",
    "build_corridor": "trajopt.corridor",
    "ConvexPolygon": "trajopt.corridor",
    "PolygonCorridor": "trajopt.corridor",
    "build_polygon_corridor": "trajopt.corridor",
    "SmoothPath": "trajopt.smoother",
    "time_parameterize": "trajopt.timing",
    "SpeedLimits": "trajopt.timing",
    "load_speed_mask": "trajopt.timing",
    "stop_and_turn": "trajopt.timing",
    "StopAndTurnTrajectory": "trajopt.motion",
    "TrajectoryChain": "trajopt.motion",
    "TurnInPlace": "trajopt.motion",
    "SteerInPlace": "trajopt.motion",
    "OmniTrajectory": "trajopt.motion",
    "read_mcap": "trajopt.motion",
    "write_mcap": "trajopt.motion",
    # analysis
    "compare": "trajopt.analysis.comparison",
    "ComparisonTable": "trajopt.analysis.comparison",
}

#: Public modules reachable as ``trajopt.<name>`` (loaded on first use).
_SUBMODULES: dict[str, str] = {
    "scenes": "trajopt.analysis.scenes",
    "fits": "trajopt.analysis.fits",
    "metrics": "trajopt.analysis.metrics",
    "plotting": "trajopt.analysis.plotting",
    "comparison": "trajopt.analysis.comparison",
    "bench": "trajopt.analysis.bench",
    "cli": "trajopt.cli",
}

__all__ = sorted(_EXPORTS) + sorted(_SUBMODULES)


def __getattr__(name: str) -> Any:
    module_name = _SUBMODULES.get(name)
    if module_name is not None:
        module = importlib.import_module(module_name)
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
    from trajopt import cli
    from trajopt._planner import Planner, PlannerOptions, plan
    from trajopt.analysis import bench, comparison, fits, metrics, plotting, scenes
    from trajopt.analysis.comparison import ComparisonTable, compare
    from trajopt.corridor import (
        Box,
        ConvexPolygon,
        Corridor,
        PolygonCorridor,
        build_corridor,
        build_polygon_corridor,
    )
    from trajopt.drive import Ackermann, Differential, Drive, Omni
    from trajopt.errors import (
        BlockedError,
        IllPosedFitError,
        InvalidInputError,
        NoPathError,
        SmoothingError,
        TimingError,
        TrajoptError,
    )
    from trajopt.geometry import BSplineCurve, ParametricCurve
    from trajopt.motion import (
        OmniTrajectory,
        PlanResult,
        SteerInPlace,
        StopAndTurnTrajectory,
        Trajectory,
        TrajectoryChain,
        TurnInPlace,
        read_mcap,
        write_mcap,
    )
    from trajopt.moving import MovingObstacle, certify_movers, retime_for_movers
    from trajopt.robot import Robot, State
    from trajopt.smoother import Smoother, SmoothPath
    from trajopt.timing import SpeedLimits, load_speed_mask, stop_and_turn, time_parameterize
    from trajopt.warmup import warm_up
