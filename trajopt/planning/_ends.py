"""The ends of a query: :func:`check_endpoint` against the map, :func:`check_steer` against the robot.

Every drive's plan and re-plan checks its start and goal this way (a disc's radius, a car's
inscribed radius), before any search.
"""

from __future__ import annotations

import math

import numpy as np

from astar.grid import OccupancyGrid
from trajopt.errors import InvalidInputError
from trajopt.geometry import points_clearance
from trajopt.planning._options import PlannerOptions, PlanRequest
from trajopt.robot import Robot


def check_endpoint(
    options: PlannerOptions,
    grid: OccupancyGrid,
    name: str,
    p: np.ndarray,
    radius: float | None = None,
) -> np.ndarray:
    """Return the cell of an end point ``p`` (m), or raise naming why it is not valid.

    ``radius`` (m): the clearance the point needs; default ``options.robot.radius``.

    Raises
    ------
    InvalidInputError
        ``p`` outside the map, on an occupied cell, or closer to an obstacle (or the map
        edge) than the robot radius (the message gives the clearance found).
    """
    c = grid.world_to_cell(p)
    if not grid.in_bounds(c):
        ox, oy = grid.origin
        raise InvalidInputError(
            f"{name} {p.tolist()} m is outside the map "
            f"[{ox}, {ox + grid.width}] x [{oy}, {oy + grid.height}] m"
        )
    if grid.occupied[c[1], c[0]]:
        raise InvalidInputError(
            f"{name} {p.tolist()} m lies on an occupied cell {(int(c[0]), int(c[1]))} of the map"
        )
    r = options.robot.radius if radius is None else radius
    clr = _point_clearance(grid, p, r)
    if clr < r:
        raise InvalidInputError(
            f"{name} {p.tolist()} m is {clr:.4g} m from the nearest obstacle (or the map "
            f"edge); the robot needs at least its radius {r} m"
        )
    return c


def _point_clearance(grid: OccupancyGrid, p: np.ndarray, radius: float) -> float:
    """Clearance (m) of a world point from the raw map (outside occupied), exact below ``radius``.

    The search stops a cell beyond ``radius``: on a fine map the distance to the nearest
    obstacle of a point in open space would take a search over far more cells.
    """
    window = float(radius) + float(grid.resolution)
    return float(points_clearance(np.asarray(p, dtype=float).reshape(1, 2), grid, window)[0])


def check_steer(robot: Robot, request: PlanRequest) -> None:
    """Refuse steering angles the robot cannot take at the ends of ``request``.

    ``start_steer`` other than 0 and ``goal_steer`` other than ``None`` need a drive with a
    steering geometry (a car with a ``wheelbase``), and then an angle within the car's
    largest, ``atan(wheelbase / min_turning_radius)`` (to a relative 1e-6, the tolerance of
    the curvature a car's curves are certified to: a re-plan starts with the steering angle
    of the old curve where it stopped).

    Raises
    ------
    InvalidInputError
        Naming the field, its value (rad) and the rule.
    """
    asked = {"start_steer": request.start_steer, "goal_steer": request.goal_steer}
    asked = {k: v for k, v in asked.items() if v is not None and (k == "goal_steer" or v != 0.0)}
    if not asked:
        return
    steering = robot.drive.steering
    if steering is None:
        what = ", ".join(f"{k}={v!r} rad" for k, v in asked.items())
        raise InvalidInputError(
            f"{what}: a steering angle needs a car with a wheelbase "
            f"(trajopt.Ackermann(wheelbase=...)), got drive={robot.drive!r}"
        )
    radius = getattr(robot.drive, "min_turning_radius", None)
    top = 0.5 * math.pi if radius is None else math.atan(steering.wheelbase / radius)
    for k, v in asked.items():
        if abs(v) > top * (1.0 + 1e-6):
            raise InvalidInputError(
                f"{k}={v!r} rad exceeds the car's largest steering angle "
                f"atan(wheelbase / min_turning_radius) = {top:.6g} rad"
            )
