"""Building the box corridor around a grid path (:func:`build_corridor`)."""

from __future__ import annotations

import logging
from typing import Any

import numpy as np

from trajopt.corridor._boxes.bridges import bridge_box, insert_bridges
from trajopt.corridor._boxes.growth import RectTester, grow_boxes
from trajopt.corridor._boxes.regions import Box, Corridor
from trajopt.errors import InvalidInputError

logger = logging.getLogger("trajopt.corridor")


def _as_cells(grid_path: Any) -> np.ndarray:
    cells = getattr(grid_path, "cells", grid_path)
    c = np.asarray(cells)
    if c.ndim != 2 or c.shape[1] != 2 or len(c) < 1:
        raise InvalidInputError(
            f"grid_path cells must have shape (n, 2) with n >= 1, got {c.shape}"
        )
    if not np.issubdtype(c.dtype, np.integer):
        if not np.all(np.isfinite(c)) or np.any(c != np.round(c)):
            raise InvalidInputError("grid_path cells must be integer (ix, iy) pairs")
        c = c.astype(np.int64)
    c = c.astype(np.int64)
    steps = np.abs(np.diff(c, axis=0))
    if len(c) > 1 and (np.any(steps.max(axis=1) != 1)):
        bad = int(np.nonzero(steps.max(axis=1) != 1)[0][0])
        raise InvalidInputError(
            f"grid_path must move to an 8-neighbour at every step; step {bad} goes from "
            f"{c[bad].tolist()} to {c[bad + 1].tolist()}"
        )
    return c


def build_corridor(
    inflated_grid: Any,
    grid_path: Any,
    *,
    max_side_cells: int = 32,
    seed_back_cells: int = 3,
    min_share_cells: float = 1.5,
    radius: float | None = None,
    raw_grid: Any = None,
) -> Corridor:
    """Grow a chain of overlapping free boxes around a grid path.

    Parameters
    ----------
    inflated_grid : astar.OccupancyGrid
        The grid the robot *centre* moves in. For certified clearance ``r`` from the raw
        map it must be ``astar.inflate(raw, r, metric="square", outside_occupied=True)``
        (module docstring).
    grid_path : astar.GridPath or array_like of int, shape (n, 2)
        Path cells ``(ix, iy)``, 8-connected, all free in ``inflated_grid``.
    max_side_cells : int, optional
        Largest box side in cells (>= 2). Default 32.
    seed_back_cells : int, optional
        How many already covered path cells each new box is seeded with (>= 1), so that
        consecutive boxes share a run of path cells. Default 3.
    min_share_cells : float, optional
        Transitions are moved inside their overlap runs so that each box's share of the
        path is at least this long (cells) where possible. Default 1.5.
    radius : float, optional
        The clearance (m) ``inflated_grid`` was built for; stored on the corridor.
    raw_grid : astar.OccupancyGrid, optional
        The raw map ``inflated_grid`` was inflated from (same shape, resolution and
        origin; requires ``radius``). When given, *bridges* are inserted where the path
        crosses diagonally between two boxes that meet only at a point or along a line
        (diagonal gaps, staircase passages): 45-degree rectangles around the path, grown
        while their exact distance to every occupied square of ``raw_grid`` (and to the
        outside of the map) stays ``>= radius``. Without bridges the smoother's control
        points are squeezed into that point and the curve stops there.

    Returns
    -------
    Corridor

    Raises
    ------
    InvalidInputError
        When a path cell is blocked or outside the grid, or an option breaks its rule.

    Notes
    -----
    Each box starts from the first path cell not yet covered, seeded with the bounding
    box of up to ``seed_back_cells`` previous path cells (shrunk until free), extends
    forward along the path while its bounding box stays free, then grows one cell at a
    time round-robin (+x, -x, +y, -y) while free and within ``max_side_cells``, using
    O(1) summed-area-table tests. A box made redundant by its successor (the successor
    overlaps the box before it) is dropped. Deterministic: no randomness, no ties broken
    by hashing.
    """
    if int(max_side_cells) != max_side_cells or max_side_cells < 2:
        raise InvalidInputError(f"max_side_cells must be an integer >= 2, got {max_side_cells!r}")
    if int(seed_back_cells) != seed_back_cells or seed_back_cells < 1:
        raise InvalidInputError(f"seed_back_cells must be an integer >= 1, got {seed_back_cells!r}")
    if not (np.isfinite(min_share_cells) and min_share_cells >= 0):
        raise InvalidInputError(f"min_share_cells must be finite and >= 0, got {min_share_cells!r}")
    if radius is not None and not (np.isfinite(radius) and radius >= 0):
        raise InvalidInputError(f"radius must be finite and >= 0 m, got {radius!r}")
    occ = np.asarray(inflated_grid.occupied, dtype=bool)
    raw_occ = None
    if raw_grid is not None:
        if radius is None:
            raise InvalidInputError("radius is required with raw_grid (bridges certify it)")
        raw_occ = np.asarray(raw_grid.occupied, dtype=bool)
        same = (
            raw_occ.shape == occ.shape
            and float(raw_grid.resolution) == float(inflated_grid.resolution)
            and tuple(map(float, raw_grid.origin)) == tuple(map(float, inflated_grid.origin))
        )
        if not same:
            raise InvalidInputError(
                "raw_grid must have the inflated grid's shape, resolution and origin; got "
                f"{raw_occ.shape} at {raw_grid.resolution} m vs {occ.shape} at "
                f"{inflated_grid.resolution} m"
            )
    ny, nx = occ.shape
    cells = _as_cells(grid_path)
    inb = (cells[:, 0] >= 0) & (cells[:, 0] < nx) & (cells[:, 1] >= 0) & (cells[:, 1] < ny)
    if not np.all(inb):
        i = int(np.nonzero(~inb)[0][0])
        raise InvalidInputError(
            f"grid_path cell {i} = {cells[i].tolist()} is outside the {nx}x{ny} grid"
        )
    blocked = occ[cells[:, 1], cells[:, 0]]
    if np.any(blocked):
        i = int(np.nonzero(blocked)[0][0])
        raise InvalidInputError(
            f"grid_path cell {i} = {cells[i].tolist()} is blocked in the inflated grid; "
            "the path must be searched on the same inflated grid"
        )
    res = float(inflated_grid.resolution)
    ox, oy = (float(v) for v in inflated_grid.origin)
    n = len(cells)
    cap = int(max_side_cells)
    window = (
        max(0, int(cells[:, 0].min()) - cap),
        min(nx - 1, int(cells[:, 0].max()) + cap),
        max(0, int(cells[:, 1].min()) - cap),
        min(ny - 1, int(cells[:, 1].max()) + cap),
    )
    tester = RectTester(occ, window)

    rects, runs = grow_boxes(cells, tester, cap, int(seed_back_cells))

    diags: list[tuple[float, float, float, float] | None] = [None] * len(rects)
    if raw_occ is not None:
        rects, runs, diags = insert_bridges(rects, runs, cells, raw_occ, float(radius) / res)

    pts = np.column_stack([ox + (cells[:, 0] + 0.5) * res, oy + (cells[:, 1] + 0.5) * res])
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(pts, axis=0).T))])
    m = len(rects)
    ov_lo = np.empty(m - 1)
    ov_hi = np.empty(m - 1)
    for k in range(m - 1):
        lo_i = max(runs[k][0], runs[k + 1][0])
        hi_i = runs[k][1]
        if lo_i > hi_i:
            # only a diagonal step between two blocked cells (corner cutting) leaves two
            # consecutive path cells that no free box holds together
            a_c, b_c = cells[runs[k][1]].tolist(), cells[runs[k + 1][0]].tolist()
            raise InvalidInputError(
                f"grid_path step {runs[k][1]} from {a_c} to {b_c} cuts a corner of the inflated "
                "grid (a diagonal step whose two orthogonal neighbours are not both free), so no "
                "free box holds both cells; search with corner_cutting=False"
                + ("" if raw_occ is not None else " or pass raw_grid and radius for bridges")
            )
        ov_lo[k], ov_hi[k] = s[lo_i], s[hi_i]
    trans = _place_transitions(ov_lo, ov_hi, float(s[-1]), min_share_cells * res)
    boxes = tuple(
        Box(
            xmin=ox + (r[0] + 0.5) * res,
            xmax=ox + (r[1] + 0.5) * res,
            ymin=oy + (r[2] + 0.5) * res,
            ymax=oy + (r[3] + 0.5) * res,
            ix0=r[0],
            ix1=r[1],
            iy0=r[2],
            iy1=r[3],
        )
        if dg is None
        else bridge_box(dg, res, ox, oy)
        for r, dg in zip(rects, diags, strict=True)
    )
    logger.debug("corridor: %d boxes for %d path cells", m, n)
    return Corridor(
        boxes=boxes,
        path_ranges=np.array(runs, dtype=np.int64).reshape(-1, 2),
        transitions_m=trans,
        overlap_start_m=ov_lo,
        overlap_end_m=ov_hi,
        path_points=pts,
        path_s=s,
        resolution=res,
        origin=(ox, oy),
        radius=None if radius is None else float(radius),
    )


def _place_transitions(
    lo: np.ndarray, hi: np.ndarray, length: float, min_share: float
) -> np.ndarray:
    """Transitions at the overlap midpoints, then nudged.

    Transitions at the overlap midpoints, then nudged (inside their overlaps) so that every
    box's share is at least ``min_share`` where the overlaps allow it.
    """
    t = 0.5 * (lo + hi)
    m = len(t)
    if m == 0:
        return t
    for _ in range(3):
        for k in range(m + 1):
            left = t[k - 1] if k > 0 else 0.0
            right = t[k] if k < m else length
            deficit = min_share - (right - left)
            if deficit <= 0:
                continue
            if k < m:
                room = hi[k] - t[k]
                step = min(room, 0.5 * deficit if k > 0 else deficit)
                t[k] += step
                deficit -= step
            if k > 0 and deficit > 0:
                room = t[k - 1] - lo[k - 1]
                t[k - 1] -= min(room, deficit)
    # keep strictly increasing (guaranteed by the overlap structure; enforce defensively)
    for k in range(1, m):
        if t[k] <= t[k - 1]:
            t[k] = min(hi[k], t[k - 1] + 1e-9 * max(1.0, length))
    return t
