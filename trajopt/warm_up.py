"""Warm-up: pay a process's one-time start costs before the first real query.

The first :func:`~trajopt.plan` in a new process spends most of its time on costs that
do not depend on the query: importing numba, SciPy and CasADi, initialising numba's
compiler context, loading each compiled kernel from numba's disk cache and loading the
CasADi solver plugins (``python benchmarks/bench_first_call.py`` prints the split). A
robot program that calls :func:`warm_up` at start-up, before its first goal arrives,
pays them there; the first real plan then costs about what a warm one does.

The warm-up plans one query on a small built-in map (a wall with a gap, so the search,
the corridor, the smoother and the timing all run) with the planner's own settings: its
robot (or footprint), search mode, corridor kind, smoother options, timing step and
fallback, so the kernels loaded are the ones its queries use. The map and its
resolution are scaled to the robot, so the warm-up takes the same short time for any
robot size. Two paths stay cold: the stop-and-turn fallback, which only a failed smoother
or timing runs, may load kernels of its own the first time it is used; and speed-limit zones are not
copied (their lookup is plain NumPy).
"""

from __future__ import annotations

import math
import time

import numpy as np

from astar.costmap import from_costmap
from astar.grid import OccupancyGrid
from trajopt.errors import InvalidInputError
from trajopt.pipeline import Planner

#: side of the warm-up map in cells
WARM_UP_CELLS = 60


def warm_up_map(planner: Planner) -> tuple[OccupancyGrid, tuple[float, float], tuple[float, float]]:
    """Return the warm-up map for ``planner`` and its query.

    Parameters
    ----------
    planner : Planner
        Its robot's (circumscribed) radius and its smoother's curvature bound set the
        map's scale.

    Returns
    -------
    grid : astar.OccupancyGrid
        ``WARM_UP_CELLS`` square cells, side ``12 * max(radius, 1 / kappa_max)`` metres
        (three radii with ``inflation="paper"``),
        with a wall up from the bottom edge over 60 % of the height in the middle and a
        block 1.6 radii left of the start (so the clearance checks meet an obstacle).
    start, goal : tuple of float
        World points (m) on either side of the wall, ``0.2`` of the side from the
        bottom and from the left and right edges.
    """
    scale = planner.robot.radius
    if planner.inflation == "paper":  # the avoidance area adds about 2 radii
        scale *= 3.0
    if planner.smoother.kappa_max is not None:
        scale = max(scale, 1.0 / planner.smoother.kappa_max)
    n = WARM_UP_CELLS
    resolution = 12.0 * scale / n
    occupied = np.zeros((n, n), dtype=bool)
    half = max(1, math.ceil(0.05 * n))
    occupied[: int(0.6 * n), n // 2 - half : n // 2 + half] = True
    occupied[int(0.17 * n) : int(0.23 * n), int(0.03 * n) : int(0.07 * n)] = True  # near the start
    side = n * resolution
    return OccupancyGrid(occupied, resolution), (0.2 * side, 0.2 * side), (0.8 * side, 0.2 * side)


def warm_up(planner: Planner | None = None) -> float:
    """Load what a plan needs once per process, before the first real query.

    Parameters
    ----------
    planner : Planner, optional
        The planner whose settings the warm-up copies (robot, search mode, corridor,
        smoother, timing step, fallback); its map and caches are not touched. Default: a
        planner with :func:`~trajopt.plan`'s defaults.

    Returns
    -------
    float
        Wall time the warm-up took (s).

    Raises
    ------
    InvalidInputError
        ``planner`` is not a :class:`Planner`.
    TrajoptError
        The warm-up query failed (it should not: the map is built for the robot; the
        error says which stage).
    """
    t0 = time.perf_counter()
    if planner is None:
        planner = Planner(OccupancyGrid(np.zeros((2, 2), dtype=bool), 1.0))
    if not isinstance(planner, Planner):
        raise InvalidInputError(f"planner must be a trajopt.Planner, got {type(planner).__name__}")
    grid, start, goal = warm_up_map(planner)
    search_map: OccupancyGrid | object = grid
    if planner.costmap is not None:
        values = np.zeros(grid.occupied.shape, dtype=np.uint8)
        values[:, : WARM_UP_CELLS // 4] = 100  # a graded band for the costmap's cost term
        values[grid.occupied] = 254  # lethal
        search_map = from_costmap(values, grid.resolution, grid.origin, convention="costmap_2d")
    copy = Planner(
        search_map,
        planner.robot,
        inflation=planner.inflation,
        search=planner.search,
        smoother=planner.smoother,
        timing_dt=planner.timing_dt,
        fallback=planner.fallback,
        corridor=planner.corridor,
        costmap_weight=planner.costmap_weight,
        landmarks=planner.landmarks,
    )
    copy.plan(start, goal)
    return time.perf_counter() - t0
