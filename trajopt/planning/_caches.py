"""Map updates of a :class:`~trajopt._planner.Planner`.

The inflated grid and the clearance cost are recomputed only where the change reaches. The
search landmarks (``Planner(landmarks=k)``), whose distances span the whole map, are kept
(:meth:`astar.Landmarks.rebase`: still exact lower bounds) when the change only adds
obstacles, so that no inflated cell is freed and no cost falls; otherwise they are dropped
and built again by the next search.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from astar.errors import InvalidInputError as AstarInputError
from astar.grid import OccupancyGrid
from trajopt.errors import InvalidInputError


def update_caches(planner: Any, grid: OccupancyGrid) -> dict[str, Any]:
    """Return what :meth:`~trajopt._planner.Planner.update_map` reports, after doing it."""
    if not isinstance(grid, OccupancyGrid):
        raise InvalidInputError(f"grid must be an astar.OccupancyGrid, got {type(grid).__name__}")
    if planner.costmap is not None:
        raise InvalidInputError(
            "this planner plans on a costmap: build a new Planner from the updated costmap"
        )
    with planner._lock:
        for disc in planner._disc_planners.values():  # a footprint robot's disc models
            update_caches(disc, grid)
        old = planner.grid
        same = (
            grid.shape == old.shape
            and grid.resolution == old.resolution
            and grid.origin == old.origin
        )
        if not same:
            planner.grid, planner._inflated, planner._cost = grid, None, None
            had = planner._landmarks is not None
            planner._landmarks = None
            return {"changed_cells": None, "window": None, "reset": True,
                    "landmarks": "dropped" if had else None}  # fmt: skip
        changed = np.flatnonzero(np.asarray(grid.occupied) != np.asarray(old.occupied))
        n_changed = int(changed.size)
        planner.grid = grid
        lms = planner._landmarks
        if n_changed == 0:
            return {"changed_cells": 0, "window": None, "reset": False,
                    "landmarks": None if lms is None else "kept"}  # fmt: skip
        planner._landmarks = None
        iy, ix = np.divmod(changed, grid.nx)  # flatnonzero: far faster than a 2-D nonzero
        box = (int(ix.min()), int(ix.max()), int(iy.min()), int(iy.max()))
        r_cells, reach_cost = change_reach(planner, grid.resolution)
        window = _grow(box, max(r_cells, reach_cost), grid.shape)
        if planner._inflated is not None:
            occ = np.array(planner._inflated.occupied)
            _patch(occ, grid, window, r_cells, planner._inflate)
            planner._inflated = grid.with_occupied(occ)
        if planner._cost is not None:
            cost = np.array(planner._cost)
            _patch(cost, grid, window, reach_cost, planner._clearance_cost)
            cost.flags.writeable = False  # shared with the landmarks
            planner._cost = cost
        state = None
        if lms is not None:
            try:
                planner._landmarks = lms.rebase(planner._inflated, planner._cost, window)
                state = "rebased"
            except AstarInputError:  # a cell freed or a cost lowered
                state = "dropped"
        return {"changed_cells": n_changed, "window": window, "reset": False,
                "landmarks": state}  # fmt: skip


def change_reach(planner: Any, resolution: float) -> tuple[int, int]:
    """Cells a changed cell can reach: ``(inflated grid, search cost)``.

    The inflated grid changes within the robot radius (plus the avoidance area with
    ``inflation="paper"``) of a changed cell, plus 2 cells of rounding; the search cost
    within that plus the clearance cost's 3-cell fall-off, rounded up.
    """
    r_cells = int(math.ceil(planner.robot.radius / resolution)) + 2
    if planner.inflation == "paper":
        r_cells += planner.w_cells + 1
    return r_cells, r_cells + 5


def _grow(box: tuple[int, int, int, int], k: int, shape: tuple[int, int]):
    """Grow the cell box ``(x0, x1, y0, y1)`` (inclusive) by ``k`` cells, inside ``shape``."""
    ny, nx = shape
    return (
        max(0, box[0] - k),
        min(nx - 1, box[1] + k),
        max(0, box[2] - k),
        min(ny - 1, box[3] + k),
    )


def _patch(target: np.ndarray, grid: OccupancyGrid, window, reach: int, compute) -> None:
    """Recompute ``target`` (a per-cell array of ``grid``) inside ``window``.

    ``compute`` runs on the map cut to ``window`` grown by ``reach`` more cells; cells of
    ``window`` are at least ``reach`` from that cut's made-up outside (where it is not the
    map's own edge), so they get exactly the values of a whole-map computation.
    """
    x0, x1, y0, y1 = window
    cx0, cx1, cy0, cy1 = _grow(window, reach, grid.shape)
    res = grid.resolution
    ox, oy = grid.origin
    sub = OccupancyGrid(
        grid.occupied[cy0 : cy1 + 1, cx0 : cx1 + 1], res, (ox + cx0 * res, oy + cy0 * res)
    )
    vals = compute(sub)
    target[y0 : y1 + 1, x0 : x1 + 1] = vals[y0 - cy0 : y1 - cy0 + 1, x0 - cx0 : x1 - cx0 + 1]
