"""Running the comparison: the shared context (grids, A* paths), each method, its metrics."""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

import astar.errors as _astar_errors
import trajopt.validation as validation
from astar.grid import OccupancyGrid
from trajopt.analysis.comparison._records import ComparisonContext, MethodFn, MethodResult
from trajopt.analysis.comparison._registry import resolve_methods
from trajopt.analysis.comparison._table import ComparisonTable
from trajopt.analysis.metrics import DEFAULT_SAMPLE_SPACING, PathMetrics, path_metrics
from trajopt.errors import InvalidInputError, NoPathError, SmoothingError, TimingError
from trajopt.robot import avoidance_width

logger = logging.getLogger(__name__)

_SOFT_ERRORS = (
    NoPathError,
    SmoothingError,
    TimingError,
    _astar_errors.NoPathError,
)


def _run_method(
    name: str,
    fn: MethodFn,
    ctx: ComparisonContext,
    sample_spacing: float,
    border_occupied: bool,
) -> tuple[Any, dict[str, Any]]:
    """Run one method on ``ctx`` and score it: ``(path, table row)``.

    The errors of :data:`_SOFT_ERRORS` give an invalid row with NaN metrics; any other
    exception propagates.
    """
    t0 = time.perf_counter()
    try:
        out = fn(ctx)
    except _SOFT_ERRORS as exc:
        logger.warning("compare: method %r failed: %s", name, exc)
        out = MethodResult(None, False, f"{type(exc).__name__}: {exc}")
    elapsed = time.perf_counter() - t0
    if not isinstance(out, MethodResult):
        out = MethodResult(out)
    runtime = out.runtime_s if out.runtime_s is not None else elapsed
    if out.path is None:
        metrics = PathMetrics.nan(sample_spacing)
    else:
        metrics = path_metrics(
            out.path,
            grid=ctx.grid,
            reference=ctx.reference,
            radius=ctx.robot_radius,
            sample_spacing=sample_spacing,
            border_occupied=border_occupied,
        )
    row = {
        "method": name,
        "valid": bool(out.valid),
        **metrics.as_dict(),
        "fit_mse_m2": math.nan,
        **dict(out.extras),
        "runtime_s": float(runtime),
        "note": out.note,
    }
    return out.path, row


def _search(grid: OccupancyGrid, s: tuple[int, int], g: tuple[int, int], what: str) -> Any:
    try:
        from astar.search import find_path

        return find_path(grid, s, g)
    except _astar_errors.NoPathError as exc:
        raise NoPathError(f"no path from {s} to {g} on the {what}: {exc}") from exc
    except _astar_errors.InvalidInputError as exc:
        if isinstance(exc, InvalidInputError):
            raise
        raise InvalidInputError(f"A* on the {what}: {exc}") from exc


def compare(
    grid: OccupancyGrid,
    start: tuple[float, float],
    goal: tuple[float, float],
    *,
    robot_radius: float = 0.165,
    w_cells: int | None = None,
    poly: Mapping[str, Any] | None = None,
    bspline: Mapping[str, Any] | None = None,
    methods: Sequence[str] | Mapping[str, MethodFn | str] | None = None,
    options: Mapping[str, Mapping[str, Any]] | None = None,
    sample_spacing: float = DEFAULT_SAMPLE_SPACING,
    border_occupied: bool = True,
) -> ComparisonTable:
    """Run the chapter's methods (and any registered ones) and tabulate the metrics.

    Parameters
    ----------
    grid : astar.OccupancyGrid
        The raw map.
    start, goal : tuple of float
        World points ``(x, y)`` in metres.
    robot_radius : float
        Robot radius (m, > 0): collision threshold of the clearance.
    w_cells : int, optional
        Avoidance-area width ``W`` in cells; default :func:`trajopt.robot._robot.avoidance_width` of
        the robot width ``2 * robot_radius`` (the chapter's ``W = 11`` for 0.33 m at 0.03 m).
    poly : Mapping, optional
        Keyword arguments of :func:`trajopt.fits.fit_polynomial` (``order``, ``method``,
        ``weights``, ``tol``); missing keys come from :data:`DEFAULT_POLY`.
    bspline : Mapping, optional
        Keyword arguments of :func:`trajopt.fits.fit_bspline` (``degree``, ``n_ctrl``,
        ``parameterization``); missing keys from :data:`DEFAULT_BSPLINE`. ``n_ctrl`` is
        reduced to the number of path points when the path is shorter; when the data cannot
        determine the fit (Schoenberg-Whitney fails, the collocation matrix is numerically
        singular, or the solution swings: a control point more than
        :data:`~trajopt.fits.BSPLINE_SWING_MAX` data extents outside the data's bounding
        box; typically for such a square system) the row is ``valid=False`` without a
        curve, and its note says how many control points the data allow.
    methods : sequence of str or Mapping[str, callable], optional
        Registered method names to run (default: every registered default method), or a
        mapping name -> method callable for one-off methods.
    options : Mapping[str, Mapping], optional
        Per-method options by name (``poly``/``bspline`` fill the built-in entries).
    sample_spacing : float
        Arc-length spacing of the metric samples (m).
    border_occupied : bool
        The map border counts as an obstacle (avoidance area, inflation and clearance), as
        in the chapter. Default ``True``.

    Returns
    -------
    ComparisonTable

    Raises
    ------
    InvalidInputError
        Bad arguments, or start/goal outside the map or blocked in the avoidance area.
    NoPathError
        No path in the avoidance area (or the raw grid).
    """
    if not isinstance(grid, OccupancyGrid):
        raise InvalidInputError(f"grid must be an astar.OccupancyGrid, got {type(grid).__name__}")
    s_xy = tuple(float(v) for v in validation.point("start", start))
    g_xy = tuple(float(v) for v in validation.point("goal", goal))
    radius = validation.positive("robot_radius", robot_radius, "m")
    if w_cells is None:
        w = avoidance_width(2.0 * radius, grid.resolution)
    elif isinstance(w_cells, bool) or not isinstance(w_cells, (int, np.integer)) or w_cells < 0:
        raise InvalidInputError(f"w_cells must be an integer >= 0 or None, got {w_cells!r}")
    else:
        w = int(w_cells)
    s_cell = tuple(int(v) for v in grid.world_to_cell(s_xy))
    g_cell = tuple(int(v) for v in grid.world_to_cell(g_xy))
    for name, cell, xy in (("start", s_cell, s_xy), ("goal", g_cell, g_xy)):
        if not grid.in_bounds(cell):
            raise InvalidInputError(f"{name} {xy} m is outside the map (cell {cell})")
    opts: dict[str, Mapping[str, Any]] = {k: dict(v) for k, v in dict(options or {}).items()}
    if poly is not None:
        opts["polynomial fit"] = {**opts.get("polynomial fit", {}), **dict(poly)}
        opts.setdefault("polynomial fit (parametric)", dict(opts["polynomial fit"]))
    if bspline is not None:
        opts["B-spline fit"] = {**opts.get("B-spline fit", {}), **dict(bspline)}
    runs = resolve_methods(methods)

    timings: dict[str, float] = {}
    # direct imports: the package attribute ``astar.inflation`` can be the submodule
    from astar.inflation import avoidance_area, inflate

    t0 = time.perf_counter()
    avoid = avoidance_area(grid, w, border=border_occupied)
    inflated = inflate(grid, radius, metric="square", outside_occupied=border_occupied)
    timings["grids"] = time.perf_counter() - t0
    for name, cell, xy in (("start", s_cell, s_xy), ("goal", g_cell, g_xy)):
        if not avoid.is_free(cell):
            raise InvalidInputError(
                f"{name} {xy} m (cell {cell}) is blocked in the avoidance area (W = {w} "
                "cells): it is too close to an obstacle or the border"
            )
    t0 = time.perf_counter()
    path_raw = _search(grid, s_cell, g_cell, "raw grid")
    timings["astar_raw"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    path_avoid = _search(avoid, s_cell, g_cell, f"avoidance area (W = {w})")
    timings["astar_avoid"] = time.perf_counter() - t0
    ctx = ComparisonContext(
        grid=grid,
        start=s_xy,
        goal=g_xy,
        start_cell=s_cell,  # type: ignore[arg-type]
        goal_cell=g_cell,  # type: ignore[arg-type]
        robot_radius=radius,
        w_cells=w,
        border_occupied=bool(border_occupied),
        avoidance=avoid,
        inflated=inflated,
        path_raw=path_raw,
        path_avoid=path_avoid,
        reference=grid.cell_to_world(path_avoid.cells),
        options=opts,
        timings=timings,
    )

    rows, paths = [], {}
    for name, fn in runs:
        paths[name], row = _run_method(name, fn, ctx, sample_spacing, border_occupied)
        rows.append(row)
    meta = {
        "start": s_xy,
        "goal": g_xy,
        "start_cell": s_cell,
        "goal_cell": g_cell,
        "robot_radius": radius,
        "w_cells": w,
        "border_occupied": bool(border_occupied),
        "sample_spacing_m": float(sample_spacing),
        "options": opts,
        "reference": "A* + avoidance area (cell centres)",
    }
    return ComparisonTable(rows=tuple(rows), meta=meta, paths=paths)
