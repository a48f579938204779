"""The planner's corridor-and-fit stage.

Polygons first, boxes where they fail, and the witness rescue of a curvature-bounded fit.

Functions take the planner's options (:class:`~trajopt.planning._options.PlannerOptions`:
robot, inflation, corridor kind, smoother), the raw map and the query record
(:class:`~trajopt.planning._query.PlanQuery`: the ends, the footprint the smoother must also
certify), whose timer gets the corridor builds under ``corridor`` and the fits (and the
witness search) under ``smooth``.
"""

from __future__ import annotations

import dataclasses
import logging
import math
import time

import numpy as np

import astar
from astar.grid import OccupancyGrid
from trajopt.corridor import (
    Box,
    Corridor,
    PolygonCorridor,
    build_corridor,
    build_polygon_corridor,
    corridor_with_rest,
)
from trajopt.errors import InvalidInputError, SmoothingError, TimingError
from trajopt.geometry import box_clearance
from trajopt.planning._feasibility import curvature_witness, witness_grid_path
from trajopt.planning._options import PlannerOptions
from trajopt.planning._query import PlanQuery, PlanSteps
from trajopt.smoother import Smoother, SmoothPath

logger = logging.getLogger("trajopt._planner")


def fit_in_corridor(
    options: PlannerOptions,
    grid: OccupancyGrid,
    q: PlanQuery,
    path: astar.GridPath,
    smoother: Smoother,
    witness: np.ndarray | None = None,
) -> tuple[PolygonCorridor | Corridor, SmoothPath]:
    """Build the corridor around ``path`` and fit in it.

    Polygons first (when chosen), then boxes; the fits share ``smoother.time_budget_s``
    (the corridor builds do not count against it). With a curvature ``witness`` (points, m,
    from :func:`~trajopt.planning._feasibility.curvature_witness`), the polygons are grown around the
    witness itself (:func:`witness_corridor`), the boxes around ``path``.

    Returns ``(corridor, smooth_path)``; raises the box fit's ``SmoothingError`` (or
    ``InvalidInputError``) when every corridor failed.
    """
    spent = 0.0  # seconds spent fitting: the corridor builds (and numba's first
    # compilation of their kernels) do not count against the smoother's budget
    kinds = ["boxes"]
    if options.corridor == "polygons" and options.inflation == "exact":
        kinds.insert(0, "polygons")
    first_failure: SmoothingError | None = None
    for i, kind in enumerate(kinds):
        last = i == len(kinds) - 1
        try:
            with q.timer.stage("corridor"):
                if kind == "polygons" and witness is not None:
                    corridor = witness_corridor(grid, options.robot.radius, witness)
                    q.regions_kept = 0
                elif kind == "polygons":
                    # a footprint's rounds need the corridor of cells (Smoother.fit)
                    corridor, q.regions_kept = polygon_corridor(
                        grid,
                        options.robot.radius,
                        path,
                        q.start,
                        q.goal,
                        q.previous,
                        unit_m=None if q.footprint is None else grid.resolution,
                    )
                else:
                    corridor = box_corridor(options, grid, q.inflated, path, q.start, q.goal)
        except InvalidInputError as exc:
            if last and first_failure is not None:
                # the polygons were built but the fit in them failed: that is the failure
                raise first_failure from exc
            if last:
                raise
            logger.debug("%s corridor not built (%s); trying the next kind", kind, exc)
            continue
        left = smoother.time_budget_s - spent
        t_fit = time.perf_counter()
        try:
            if left <= 0:
                raise SmoothingError("time budget exhausted before the box corridor", {})
            sm = smoother if i == 0 else dataclasses.replace(smoother, time_budget_s=left)
            # a costmap's graded cost (search "costmap" or "costmap+clearance") enters the
            # smoother's objective with costmap_weight
            cost = q.cost
            with q.timer.stage("smooth"):
                smooth = sm.fit(
                    path,
                    corridor,
                    raw_grid=grid,
                    radius=options.robot.radius,
                    start=q.start,
                    goal=q.goal,
                    start_heading=q.start_heading,
                    goal_heading=q.goal_heading,
                    start_curvature=q.start_curvature,
                    footprint=q.footprint,
                    cost=cost,
                    cost_weight=options.costmap_weight,
                )
            return corridor, smooth
        except SmoothingError as exc:
            spent += time.perf_counter() - t_fit
            if last:
                raise
            first_failure = first_failure or exc
            logger.debug("fit in the %s corridor failed (%s); trying the next kind", kind, exc)
    raise AssertionError("unreachable")  # pragma: no cover


def witness_rescue(
    options: PlannerOptions,
    grid: OccupancyGrid,
    q: PlanQuery,
    exc: SmoothingError,
    t_start: float,
) -> tuple[astar.GridPath, PolygonCorridor | Corridor, SmoothPath]:
    """Return the second try of a curvature-bounded fit, along a witness.

    A witness that keeps one cell more than the radius is tried first (its grid path
    stays off the inflated grid's edges, so the corridor has room to turn; its search
    is capped at 1 s), then one with the exact radius. The polygons of each try are grown
    around the witness (:func:`witness_corridor`), the boxes around the grid path that
    follows it. Both tries share the smoother's time budget, counted from ``t_start``.

    Raises
    ------
    SmoothingError
        ``exc`` itself without a curvature bound (no rescue); else, when no try gives a
        curve, ``exc`` with what the rescue found appended to its message and under
        ``stats["witness"]``: whether the witness search found a curvature-bounded path.
    """
    sm = options.smoother
    if sm.kappa_max is None:
        raise exc
    radius = options.robot.radius
    note = "no time left for the witness search"
    for margin, cap_s in ((grid.resolution, 1.0), (0.0, math.inf)):
        left = sm.time_budget_s - (time.perf_counter() - t_start)
        if left <= 0:
            break
        with q.timer.stage("smooth"):
            witness = curvature_witness(
                grid,
                radius + margin,
                q.start,
                q.goal,
                sm.kappa_max,
                time_limit_s=min(left, cap_s),
            )
            cells = None if witness is None else witness_grid_path(witness, q.inflated)
        if cells is None or len(cells) < 2:
            if not note.startswith("a curvature-bounded path exists"):
                note = "no curvature-bounded path found by the witness search"
            continue
        note = "a curvature-bounded path exists, but no certified curve was fitted along it"
        steps = np.abs(np.diff(cells, axis=0)).sum(axis=1)
        length = float(np.sum(np.where(steps == 2, np.sqrt(2.0), 1.0)))
        path = astar.GridPath(cells=cells, length=length, cost=length, expanded=0)
        left = sm.time_budget_s - (time.perf_counter() - t_start)
        if left <= 0:
            break
        try:
            corridor, smooth = fit_in_corridor(
                options, grid, q, path, dataclasses.replace(sm, time_budget_s=left), witness
            )
        except (SmoothingError, InvalidInputError) as exc2:
            logger.debug("witness rescue (margin %g m) failed after %s: %s", margin, exc, exc2)
            continue
        return path, corridor, smooth
    raise SmoothingError(f"{exc}; witness rescue: {note}", dict(exc.stats, witness=note)) from exc


#: the polygons of a witness rescue are grown around every this-many-th witness point (the
#: witness is sampled at most an eighth of a cell apart: about every half cell)
WITNESS_STRIDE = 4


def witness_corridor(
    raw_grid: OccupancyGrid, radius: float, witness: np.ndarray
) -> PolygonCorridor:
    """Polygons around a curvature witness's own points (m), not centred.

    A witness keeps the exact radius and bends at the curvature bound, often along a wall;
    the corridor of the grid path that follows it is centred away from the walls and
    simplified into long segments, and can leave the witness's arcs outside every region
    (no curvature-bounded curve in it). Grown around about every half cell of the witness,
    without centring (``centre_cells=0``), the regions follow its arcs.
    """
    pts = np.vstack([witness[::WITNESS_STRIDE][:-1], witness[-1:]])
    return build_polygon_corridor(raw_grid, pts, radius, centre_cells=0.0)


def polygon_corridor(
    grid: OccupancyGrid,
    radius: float,
    path: astar.GridPath,
    p0: np.ndarray,
    p1: np.ndarray,
    previous: PlanSteps | None = None,
    unit_m: float | None = None,
) -> tuple[PolygonCorridor, int]:
    """Polygons around the A* path, from the exact start to the exact goal.

    With a re-plan's ``previous`` steps, their polygon corridor's regions along the rest
    of the path the two share are kept when still certified
    (:func:`~trajopt.corridor._polygons.reuse.corridor_with_rest`). ``unit_m``: the
    corridor's length unit (:func:`~trajopt.corridor.build_polygon_corridor`). Returns the
    corridor and the number of regions kept.
    """
    centres = np.asarray(grid.cell_to_world(np.asarray(path.cells)), dtype=float)
    points = np.vstack([p0, centres.reshape(-1, 2)[1:-1], p1])
    if previous is not None and isinstance(previous.corridor, PolygonCorridor):
        out = corridor_with_rest(grid, points, radius, previous.corridor, previous.raw_grid)
        if out is not None:
            return out
    return build_polygon_corridor(grid, points, radius, unit_m=unit_m), 0


def box_corridor(
    options: PlannerOptions,
    grid: OccupancyGrid,
    inflated: OccupancyGrid,
    path: astar.GridPath,
    p0: np.ndarray,
    p1: np.ndarray,
) -> Corridor:
    """Boxes of free cells around the A* path, the end boxes widened to the exact ends.

    Bridges (45-degree regions certified against the raw map) cross diagonal gaps; not
    with the chapter's avoidance area, which the curve must not enter either.
    """
    radius = options.robot.radius
    bridge_map = grid if options.inflation == "exact" else None
    corridor = build_corridor(inflated, path, radius=radius, raw_grid=bridge_map)
    return widen_end_boxes(corridor, grid, p0, p1, radius)


def widen_end_boxes(
    corridor: Corridor, raw: OccupancyGrid, p0: np.ndarray, p1: np.ndarray, radius: float
) -> Corridor:
    """Widen the first/last box to hold the exact start/goal, after an exact clearance check."""
    boxes = list(corridor.boxes)
    changed = False
    for name, idx, p in (("start", 0, p0), ("goal", len(boxes) - 1, p1)):
        b = boxes[idx]
        if b.contains(p):
            continue
        lo = np.minimum([b.xmin, b.ymin], p)
        hi = np.maximum([b.xmax, b.ymax], p)
        clr = box_clearance(raw, lo, hi)
        if clr < radius:
            raise InvalidInputError(
                f"{name} {p.tolist()} m cannot join the corridor with clearance {radius} m: "
                f"the box joining it to the path comes {clr:.4g} m from an obstacle; move it "
                "towards free space or onto the centre of its cell"
            )
        boxes[idx] = Box(
            xmin=float(lo[0]),
            xmax=float(hi[0]),
            ymin=float(lo[1]),
            ymax=float(hi[1]),
            ix0=b.ix0,
            ix1=b.ix1,
            iy0=b.iy0,
            iy1=b.iy1,
        )
        changed = True
    if not changed:
        return corridor
    return dataclasses.replace(corridor, boxes=tuple(boxes))


def smooth_for_speed(options: PlannerOptions, grid: OccupancyGrid, q: PlanQuery) -> SmoothPath:
    """Fit again with a curvature bound the start speed can follow.

    A moving start whose speed cannot be brought under the cap of the first curve
    (too sharp a turn too soon) gets a second fit bounded by the curvature whose cap
    is that speed (``Robot.speed_cap``), 5 % tighter but never below the state's own
    curvature, which must already be within it.

    Raises
    ------
    TimingError
        The state's speed plus ``a^2 / (2 j)`` (its peak before a positive acceleration
        can be undone) is above the cap at its own curvature.
    SmoothingError
        No curve within that bound (the message says why the bound was imposed).
    """
    r = options.robot
    # the speed rises by a^2 / (2 j) before a positive acceleration can be undone
    v = q.v_start + max(q.a_start, 0.0) ** 2 / (2.0 * r.j_max)
    bounds = [r.a_lat_max / (v * v), r.omega_max / v]
    if r.track_width is not None and r.wheel_v_max is not None and v < r.wheel_v_max:
        bounds.append((r.wheel_v_max / v - 1.0) * 2.0 / r.track_width)
    k0 = abs(q.start_curvature or 0.0)
    if k0 > min(bounds):
        raise TimingError(
            f"the start state reaches {v:.6g} m/s on curvature {k0:.6g} 1/m (its speed "
            f"{q.v_start:.6g} m/s plus a^2 / (2 j)): above the speed cap there "
            f"({float(r.speed_cap(k0)):.6g} m/s)"
        )
    # a little below the cap, but never below the state's own curvature
    k_speed = max(0.95 * min(bounds), k0)
    sm = options.smoother
    kmax = k_speed if sm.kappa_max is None else min(k_speed, sm.kappa_max)
    sm = dataclasses.replace(sm, kappa_max=kmax)
    try:
        q.corridor, smooth = fit_in_corridor(options, grid, q, q.path, sm)
    except SmoothingError as exc:
        raise SmoothingError(
            f"the start state moves at {v:.6g} m/s: no curve from it turns gently enough "
            f"(curvature <= {kmax:.6g} 1/m) to slow down under the speed cap in time: {exc}",
            exc.stats,
        ) from exc
    q.rescue = "speed"
    return smooth
