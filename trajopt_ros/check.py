"""An independent clearance check of a trajectory against a map, before it is published.

It shares nothing with the planner's certificate: positions sampled densely in time
(at most a quarter cell apart) against the exact point-to-square distance of every
occupied cell nearby (found with a k-d tree of the occupied cell centres); the outside of
the map counts as occupied, as for the planner.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy.spatial import cKDTree

import astar

__all__ = ["collides", "clearance_radius"]

_LAST: list[Any] = [None, None]  # the last map and its tree (maps are immutable values)
_TOL_M = 1e-6


def clearance_radius(robot: Any) -> float:
    """Return the clearance (m) checked: the radius of a disc robot, the inscribed one of a footprint."""
    return float(robot.inscribed_radius if robot.footprint is not None else robot.radius)


def _tree(grid: astar.OccupancyGrid) -> cKDTree | None:
    if _LAST[0] is grid:
        return _LAST[1]
    iy, ix = np.nonzero(grid.occupied)
    res, (ox, oy) = grid.resolution, grid.origin
    centres = np.column_stack([ox + (ix + 0.5) * res, oy + (iy + 0.5) * res])
    tree = cKDTree(centres) if len(centres) else None
    _LAST[:] = [grid, tree]
    return tree


def collides(traj: Any, grid: Any, robot: Any, t_from: float = 0.0) -> bool:
    """Whether ``traj`` from time ``t_from`` (s) on comes closer than the robot's clearance.

    Parameters
    ----------
    traj : trajopt trajectory
        Anything with ``duration`` and a vectorised ``sample(t)``.
    grid : astar.OccupancyGrid or astar.Costmap
        The map (a costmap's obstacle cells).
    robot : trajopt.Robot
        Gives the clearance (:func:`clearance_radius`) and the speed bound for the sampling.
    t_from : float, optional
        Start of the checked part (s).

    Returns
    -------
    bool
    """
    g = grid.grid if isinstance(grid, astar.Costmap) else grid
    r = clearance_radius(robot)
    duration = float(traj.duration)
    t_from = min(max(float(t_from), 0.0), duration)
    v_bound = max(float(robot.v_max), float(getattr(robot, "v_max_reverse", None) or 0.0))
    step = 0.25 * g.resolution / max(v_bound, 1e-6)
    n = max(2, int(math.ceil((duration - t_from) / step)) + 1)
    smp = traj.sample(np.linspace(t_from, duration, n))
    pts = np.column_stack([np.asarray(smp.x, float), np.asarray(smp.y, float)])
    lo = np.array(g.origin) + r - _TOL_M
    hi = np.array(g.origin) + np.array([g.width, g.height]) - r + _TOL_M
    if np.any(pts < lo) or np.any(pts > hi):
        return True
    tree = _tree(g)
    if tree is None:
        return False
    half = 0.5 * g.resolution
    for i, near in enumerate(tree.query_ball_point(pts, r + half * math.sqrt(2.0))):
        if not near:
            continue
        c = tree.data[near]
        d = np.hypot(
            np.maximum(np.abs(pts[i, 0] - c[:, 0]) - half, 0.0),
            np.maximum(np.abs(pts[i, 1] - c[:, 1]) - half, 0.0),
        )
        if d.min() < r - _TOL_M:
            return True
    return False
