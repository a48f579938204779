"""One query for a disc robot: validate the ends, search, fit in a corridor, time.

:func:`plan_disc` runs the stages of :mod:`trajopt._planner` (module docstring there) for a
robot whose shape is its disc (a footprint robot's disc models run here too, with the
footprint the smoother must also certify and an optional check of the grid path). Every
input is explicit: the options, the map's caches, the request and a re-plan's warm start.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable
from typing import Any

import numpy as np

import astar
from astar.grid import OccupancyGrid
from trajopt.corridor import PolygonCorridor
from trajopt.errors import InvalidInputError, NoPathError, SmoothingError, TimingError
from trajopt.geometry import polygon_clearance
from trajopt.motion import PlanResult, Trajectory
from trajopt.planning._caches import PlannerCaches
from trajopt.planning._corridor_fit import fit_in_corridor, smooth_for_speed, witness_rescue
from trajopt.planning._ends import check_endpoint
from trajopt.planning._fallback import polyline_fallback
from trajopt.planning._options import (
    COARSE_MIN_BLOCKS,
    COARSE_MIN_CELLS,
    PlannerOptions,
    PlanRequest,
)
from trajopt.planning._query import PlanQuery, PlanSteps, WarmStart
from trajopt.robot import Footprint, State
from trajopt.smoother import SmoothPath
from trajopt.timing import time_parameterize
from trajopt.validation import point

#: What a query returns: a smooth trajectory, or the stop-and-turn fallback.
#: A check of the grid path after the search: ``(caches, query) -> (grid path, inflated
#: grid it was found on)`` (a footprint robot's oriented check).
PathCheck = Callable[[PlannerCaches, PlanQuery], tuple[astar.GridPath, OccupancyGrid]]


def plan_disc(
    options: PlannerOptions,
    caches: PlannerCaches,
    request: PlanRequest,
    warm: WarmStart | None = None,
    *,
    footprint: Footprint | None = None,
    path_check: PathCheck | None = None,
) -> PlanResult:
    """Plan one query for the disc of ``options.robot`` (see :meth:`trajopt.Planner.plan`).

    Parameters
    ----------
    options : PlannerOptions
        Resolved for the map of ``caches``.
    caches : PlannerCaches
        The map and its inflated grid, search cost and landmarks for ``options``.
    request : PlanRequest
        The ends, headings and speeds.
    warm : WarmStart, optional
        A re-plan's grid path (used instead of a search when its end cells are the
        query's) and old steps (whose polygon regions the corridor may keep).
    footprint : Footprint, optional
        The footprint the smoother must also certify (a footprint robot's disc model).
    path_check : callable, optional
        Run on the grid path after the search (:data:`PathCheck`).

    Returns
    -------
    Trajectory or StopAndTurnTrajectory

    Raises
    ------
    InvalidInputError, NoPathError, SmoothingError, TimingError
        As :meth:`trajopt.Planner.plan`.
    """
    start, goal = request.start, request.goal
    start_heading, v_start = request.start_heading, request.v_start
    kappa0 = None
    a0 = 0.0
    if isinstance(start, State):
        if start_heading is not None or v_start != 0.0:
            raise InvalidInputError(
                "start is a State: its theta and v are the start heading and speed; "
                f"leave start_heading (got {start_heading!r}) and v_start (got "
                f"{v_start!r}) at their defaults"
            )
        start_heading, kappa0, v_start, a0 = start.theta, start.kappa, start.v, start.a
        start = start.position
    p0 = point("start", start)
    p1 = point("goal", goal)
    q = PlanQuery(
        start=p0,
        goal=p1,
        start_cell=check_endpoint(options, caches.grid, "start", p0),
        goal_cell=check_endpoint(options, caches.grid, "goal", p1),
        start_heading=start_heading,
        goal_heading=request.goal_heading,
        start_curvature=kappa0,
        v_start=v_start,
        v_end=request.v_end,
        a_start=a0,
        previous=None if warm is None else warm.previous,
        footprint=footprint,
    )
    if caches.costmap is not None and options.search.startswith("costmap"):
        q.cost = caches.costmap  # the smoother minimises its graded cost too
    with q.timer.stage("inflate"):
        q.inflated = caches.inflated
    _check_reachable_ends(options, caches.grid, q)
    ends = [q.start_cell, q.goal_cell]
    grid_path = None if warm is None else warm.grid_path
    reused = grid_path is not None and np.array_equal(grid_path.cells[[0, -1]], ends)
    search_info = None
    with q.timer.stage("search"):
        if not reused:
            _check_connected(options, caches, q)
            grid_path, search_info = _search(options, caches, q)
        q.path = grid_path
        if path_check is not None:
            q.path, q.inflated = path_check(caches, q)
    if request.check_grid_path is not None and footprint is None and path_check is None:
        pts = np.asarray(caches.grid.cell_to_world(q.path.cells), dtype=float).reshape(-1, 2)
        request.check_grid_path(np.concatenate([q.start[None, :], pts[1:-1], q.goal[None, :]]))
    smooth = None
    try:
        smooth = _smooth(options, caches.grid, q)
        if request.check_curve is not None and footprint is None and path_check is None:
            request.check_curve(smooth)
        try:
            traj = _time(options, q, smooth)
        except TimingError:
            if q.v_start <= 0.0:
                raise
            smooth = smooth_for_speed(options, caches.grid, q)
            traj = _time(options, q, smooth)
    except (SmoothingError, TimingError) as exc:
        if options.fallback is None or q.v_start != 0.0 or q.v_end != 0.0 or q.a_start != 0.0:
            raise
        with q.timer.stage("fallback"):
            fallback, extra = polyline_fallback(options, caches.grid, q, exc)
        return _result(options, caches.grid, q, fallback, None, search_info=search_info, **extra)
    smoother_stats = dict(smooth.stats)
    smoother_stats["rescue"] = q.rescue
    kind = "polygons" if isinstance(q.corridor, PolygonCorridor) else "boxes"
    return _result(
        options,
        caches.grid,
        q,
        traj,
        smooth,
        smoother=smoother_stats,
        corridor=kind,
        grid_path="reused" if reused else "searched",
        corridor_regions_kept=q.regions_kept,
        search_info=search_info,
    )


def _search(
    options: PlannerOptions, caches: PlannerCaches, q: PlanQuery
) -> tuple[astar.GridPath, dict[str, Any]]:
    """Return the A* path of the query on the inflated grid and ``stats["search_info"]``.

    ``search_mode`` picks the exact search or the coarse-to-fine one
    (:func:`astar.find_path_coarse_to_fine` on :attr:`PlannerCaches.coarse`; ``"auto"``:
    on inflated grids of :data:`COARSE_MIN_CELLS` cells or more, for ends
    :data:`COARSE_MIN_BLOCKS` blocks apart or more, without landmarks). Raises a typed
    error without a path.
    """
    s, g = _cell(q.start_cell), _cell(q.goal_cell)
    res = caches.grid.resolution
    k = options.search_block_cells(res)
    mode = options.search_mode
    if mode == "auto":
        ax, ay = abs(s[0] - g[0]), abs(s[1] - g[1])
        octile = max(ax, ay) + (math.sqrt(2.0) - 1.0) * min(ax, ay)
        coarse = (
            caches.grid.occupied.size >= COARSE_MIN_CELLS
            and octile >= COARSE_MIN_BLOCKS * k
            and (options.landmarks == 0 or options.search == "shortest")
        )
    else:
        coarse = mode == "coarse"
    try:
        if coarse:
            found = astar.find_path_coarse_to_fine(
                caches.coarse, s, g, max_bound=options.search_bound
            )
            return found.path, {
                "requested": mode,
                "mode": found.mode,
                "block_cells": found.block,
                "block_m": found.block * res,
                "bound": found.bound,
                "lower_bound": found.lower_bound,
                "cost": found.path.cost,
                "fallback": found.fallback,
                "band_cells": found.band_cells,
                "times_s": dict(found.times_s),
            }
        lms = caches.landmarks
        path = astar.find_path(
            q.inflated,
            s,
            g,
            cost=caches.search_cost if lms is None else None,
            landmarks=lms,
        )
        return path, {
            "requested": mode,
            "mode": "exact",
            "bound": 1.0,
            "cost": path.cost,
            "fallback": None,
        }
    except astar.NoPathError as exc:
        raise NoPathError(
            f"no path from start {q.start.tolist()} m to goal {q.goal.tolist()} m for a "
            f"robot of radius {options.robot.radius} m (inflation={options.inflation!r}): {exc}"
        ) from exc


def _check_connected(options: PlannerOptions, caches: PlannerCaches, q: PlanQuery) -> None:
    """Refuse at once when the end cells lie in different components of the inflated grid.

    The search reaches exactly the cells of the start's component
    (:func:`~trajopt.planning._caches.component_labels`), so this raises the
    :class:`NoPathError` it would raise after exhausting that component.
    """
    labels = caches.components
    (sx, sy), (gx, gy) = _cell(q.start_cell), _cell(q.goal_cell)
    a, b = int(labels[sy, sx]), int(labels[gy, gx])
    if a != b:
        raise NoPathError(
            f"no path from start {q.start.tolist()} m to goal {q.goal.tolist()} m for a "
            f"robot of radius {options.robot.radius} m (inflation={options.inflation!r}): "
            f"they are not connected for this robot radius (start cell ({sx}, {sy}) lies "
            f"in component {a} of the inflated grid, goal cell ({gx}, {gy}) in component "
            f"{b})"
        )


def _time(options: PlannerOptions, q: PlanQuery, smooth: SmoothPath) -> Trajectory:
    with q.timer.stage("timing"):
        return time_parameterize(
            smooth,
            options.robot,
            v_start=q.v_start,
            v_end=q.v_end,
            dt=options.timing_dt,
            speed_limits=options.speed_limits,
            a_start=q.a_start,
        )


def _smooth(options: PlannerOptions, grid: OccupancyGrid, q: PlanQuery) -> SmoothPath:
    """Return the certified curve, setting ``q.corridor`` (and ``q.path`` after a rescue)."""
    t_start = time.perf_counter()
    try:
        q.corridor, smooth = fit_in_corridor(options, grid, q, q.path, options.smoother)
    except SmoothingError as exc:
        q.path, q.corridor, smooth = witness_rescue(options, grid, q, exc, t_start)
        q.rescue = "witness"
    return smooth


def _check_reachable_ends(options: PlannerOptions, grid: OccupancyGrid, q: PlanQuery) -> None:
    for name, p, c in (("start", q.start, q.start_cell), ("goal", q.goal, q.goal_cell)):
        if q.inflated.occupied[c[1], c[0]]:
            raise InvalidInputError(
                f"{name} {p.tolist()} m lies in cell {_cell(c)}, which is blocked by the "
                f"inflation={options.inflation!r} avoidance area (robot radius "
                f"{options.robot.radius} m); clearance of the cell centre "
                f"{_centre_clearance(grid, c):.4g} m"
            )
    if tuple(q.start_cell) == tuple(q.goal_cell):
        raise InvalidInputError(
            f"start {q.start.tolist()} m and goal {q.goal.tolist()} m lie in the same cell "
            f"{_cell(q.start_cell)}; the planner needs them at least one cell apart"
        )


def _result(
    options: PlannerOptions,
    grid: OccupancyGrid,
    q: PlanQuery,
    traj: PlanResult,
    smooth: SmoothPath | None,
    **extra: Any,
) -> PlanResult:
    """Attach :class:`PlanSteps` and the planner's statistics (the one place that does)."""
    stages = q.timer.finish()
    steps = PlanSteps(
        raw_grid=grid,
        inflated_grid=q.inflated,
        grid_path=q.path,
        corridor=q.corridor,
        smooth_path=smooth,
        start=(float(q.start[0]), float(q.start[1])),
        goal=(float(q.goal[0]), float(q.goal[1])),
        stages_s=stages,
        start_heading=q.start_heading,
        goal_heading=q.goal_heading,
    )
    stats = dict(traj.stats)
    stats.update(extra)
    stats["stages_s"] = dict(stages)
    stats["inflation"] = options.inflation
    stats["search"] = options.search
    return dataclasses.replace(traj, stats=stats, steps=steps)


def _cell(c: np.ndarray) -> tuple[int, int]:
    """Return a cell ``(ix, iy)`` as plain ints (for messages)."""
    return (int(c[0]), int(c[1]))


def _centre_clearance(grid: OccupancyGrid, c: np.ndarray) -> float:
    """Exact clearance (m) of the centre of cell ``c`` from the raw map (outside occupied)."""
    return polygon_clearance(np.asarray(grid.cell_to_world(c), dtype=float).reshape(1, 2), grid)
