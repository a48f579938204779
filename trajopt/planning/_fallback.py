"""The planner's opt-in fallback: the A* polyline driven with stops and turns in place.

Used by :func:`~trajopt.planning._disc.plan_disc` when the smoother or the timing fails
(``fallback="stop_and_turn"``); the motion itself is :func:`trajopt.stop_and_turn`'s.
"""

from __future__ import annotations

import logging
from typing import Any

import numpy as np

from astar.grid import OccupancyGrid
from trajopt.errors import SmoothingError
from trajopt.geometry import polyline_clearance
from trajopt.motion import StopAndTurnTrajectory
from trajopt.planning._corridor_fit import box_corridor
from trajopt.planning._options import PlannerOptions
from trajopt.planning._query import PlanQuery
from trajopt.timing import stop_and_turn

logger = logging.getLogger(__name__)


def polyline_fallback(
    options: PlannerOptions, grid: OccupancyGrid, q: PlanQuery, exc: Exception
) -> tuple[StopAndTurnTrajectory, dict[str, Any]]:
    """Return the stop-and-turn trajectory along the A* polyline, or re-raise ``exc``.

    The polyline *exact start -> A* path cell centres -> exact goal* of the query ``q``
    must keep the robot radius from the raw map ``grid`` (exact distance to the obstacle squares); otherwise ``exc``, the smoother's or the
    timing's error, is raised again. Also returns the statistics the trajectory gets
    (``fallback_error``, ``fallback_reason``, ``fallback_min_clearance_m``, ``smoother``).
    """
    robot = options.robot
    if q.corridor is None:
        with q.timer.stage("corridor"):
            q.corridor = box_corridor(options, grid, q.inflated, q.path, q.start, q.goal)
    centres = np.asarray(grid.cell_to_world(np.asarray(q.path.cells)), dtype=float)
    points = np.vstack([q.start, centres.reshape(-1, 2), q.goal])
    radius = robot.radius
    window = radius + 2.0 * float(grid.resolution)
    clearance = polyline_clearance(points, grid, window_m=window, outside_occupied=True)
    if clearance < radius - 1e-9:
        logger.warning(
            "stop_and_turn fallback rejected: the A* polyline comes %.6g m from an obstacle "
            "(radius %.6g m)",
            clearance,
            radius,
        )
        raise exc
    traj = stop_and_turn(
        points,
        robot,
        start_heading=q.start_heading,
        goal_heading=q.goal_heading,
        speed_limits=options.speed_limits,
    )
    logger.info("smoother/timing failed (%s); returned the stop_and_turn fallback", exc)
    extra: dict[str, Any] = {
        "fallback_error": type(exc).__name__,
        "fallback_reason": str(exc),
        "fallback_min_clearance_m": float(clearance),
    }
    if isinstance(exc, SmoothingError):
        extra["smoother"] = dict(exc.stats)
    return traj, extra
