"""What a planner keeps across queries on one map: :class:`PlannerCaches`.

The inflated grid, the search cost and the ALT landmarks are computed on first use and
kept; :meth:`PlannerCaches.update` recomputes the inflated grid and the clearance cost only
where a map change reaches. The search landmarks, whose distances span the whole map, are
kept (:meth:`astar.Landmarks.rebase`: still exact lower bounds) when the change only adds
obstacles, so that no inflated cell is freed and no cost falls; otherwise they are dropped
and built again by the next search. A footprint robot's disc models have caches of their
own (:meth:`PlannerCaches.disc`), updated with the map.
"""

from __future__ import annotations

import math
import threading
from typing import Any

import numpy as np

import astar
from astar.costmap import Costmap
from astar.errors import InvalidInputError as AstarInputError
from astar.grid import OccupancyGrid
from trajopt.errors import InvalidInputError
from trajopt.planning._options import PlannerOptions


class PlannerCaches:
    """The per-map caches of one planner (and of its footprint robot's disc models).

    Parameters
    ----------
    grid : astar.OccupancyGrid
        The raw map.
    costmap : astar.Costmap or None
        The costmap the map came from (its graded cost feeds ``search="costmap"``).
    options : PlannerOptions
        Options resolved for the map (:meth:`PlannerOptions.for_map`); the caches depend on
        the robot radius, ``inflation``, ``w_cells``, ``search``, ``costmap_weight`` and
        ``landmarks``.

    Notes
    -----
    The lazy builds hold a lock, so caches may be read from several threads.
    """

    def __init__(self, grid: OccupancyGrid, costmap: Costmap | None, options: PlannerOptions):
        self.grid = grid
        self.costmap = costmap
        self.options = options
        self._lock = threading.RLock()
        self._inflated: OccupancyGrid | None = None
        self._cost: np.ndarray | None = None
        self._landmarks: astar.Landmarks | None = None
        self._discs: dict[float, PlannerCaches] = {}

    @property
    def inflated(self) -> OccupancyGrid:
        """The grid the robot centre moves in (computed once per map)."""
        with self._lock:
            if self._inflated is None:
                self._inflated = self.grid.with_occupied(self._inflate(self.grid))
            return self._inflated

    @property
    def search_cost(self) -> np.ndarray | None:
        """Per-cell A* cost (``None`` for ``search="shortest"``), computed once per map."""
        o = self.options
        if o.search == "shortest":
            return None
        with self._lock:
            if self._cost is None:
                cost = self._clearance_cost(self.grid)
                if self.costmap is not None and o.search.startswith("costmap"):
                    cost += self.costmap.search_cost(o.costmap_weight)
                self._cost = cost
            return self._cost

    @property
    def landmarks(self) -> astar.Landmarks | None:
        """ALT landmarks of the inflated grid and search cost (``None`` without), built once."""
        o = self.options
        if o.landmarks == 0 or o.search == "shortest":
            return None
        with self._lock:
            if self._landmarks is None:
                self._landmarks = astar.build_landmarks(
                    self.inflated, self.search_cost, o.landmarks
                )
            return self._landmarks

    @property
    def built_landmarks(self) -> astar.Landmarks | None:
        """The landmarks if a search has built them (``None`` otherwise; builds nothing)."""
        return self._landmarks

    def disc(self, options: PlannerOptions) -> PlannerCaches:
        """Return (and keep) the caches of a disc model with ``options`` on this map."""
        radius = options.robot.radius
        with self._lock:
            if radius not in self._discs:
                self._discs[radius] = PlannerCaches(self.grid, self.costmap, options)
            return self._discs[radius]

    def _inflate(self, grid: OccupancyGrid) -> np.ndarray:
        o = self.options
        occ = astar.inflate(grid, o.robot.radius, metric="square", outside_occupied=True)
        out = occ.occupied
        if o.inflation == "paper":
            out = out | astar.avoidance_area(grid, o.w_cells, border=True).occupied
        return out

    def _clearance_cost(self, grid: OccupancyGrid) -> np.ndarray:
        cost = np.zeros(grid.shape)
        if self.options.search in ("clearance", "costmap+clearance"):
            cost += astar.clearance_cost(grid, self.options.robot.radius, outside_occupied=True)
        return cost

    def update(self, grid: OccupancyGrid) -> dict[str, Any]:
        """Replace the raw map, recomputing the caches only where the change reaches.

        See :meth:`trajopt.Planner.update_map` for what is kept and what is reported.
        """
        if not isinstance(grid, OccupancyGrid):
            raise InvalidInputError(
                f"grid must be an astar.OccupancyGrid, got {type(grid).__name__}"
            )
        if self.costmap is not None:
            raise InvalidInputError(
                "this planner plans on a costmap: build a new Planner from the updated costmap"
            )
        with self._lock:
            for disc in self._discs.values():  # a footprint robot's disc models
                disc.update(grid)
            old = self.grid
            same = (
                grid.shape == old.shape
                and grid.resolution == old.resolution
                and grid.origin == old.origin
            )
            if not same:
                self.grid, self._inflated, self._cost = grid, None, None
                had = self._landmarks is not None
                self._landmarks = None
                return {
                    "changed_cells": None,
                    "window": None,
                    "reset": True,
                    "landmarks": "dropped" if had else None,
                }
            changed = np.flatnonzero(np.asarray(grid.occupied) != np.asarray(old.occupied))
            n_changed = int(changed.size)
            self.grid = grid
            lms = self._landmarks
            if n_changed == 0:
                return {
                    "changed_cells": 0,
                    "window": None,
                    "reset": False,
                    "landmarks": None if lms is None else "kept",
                }
            self._landmarks = None
            iy, ix = np.divmod(changed, grid.nx)  # flatnonzero: far faster than a 2-D nonzero
            box = (int(ix.min()), int(ix.max()), int(iy.min()), int(iy.max()))
            r_cells, reach_cost = change_reach(self.options, grid.resolution)
            window = _grow(box, max(r_cells, reach_cost), grid.shape)
            if self._inflated is not None:
                occ = np.array(self._inflated.occupied)
                _patch(occ, grid, window, r_cells, self._inflate)
                self._inflated = grid.with_occupied(occ)
            if self._cost is not None:
                cost = np.array(self._cost)
                _patch(cost, grid, window, reach_cost, self._clearance_cost)
                cost.flags.writeable = False  # shared with the landmarks
                self._cost = cost
            state = None
            if lms is not None:
                try:
                    self._landmarks = lms.rebase(self._inflated, self._cost, window)
                    state = "rebased"
                except AstarInputError:  # a cell freed or a cost lowered
                    state = "dropped"
            return {
                "changed_cells": n_changed,
                "window": window,
                "reset": False,
                "landmarks": state,
            }


def change_reach(options: PlannerOptions, resolution: float) -> tuple[int, int]:
    """Cells a changed cell can reach: ``(inflated grid, search cost)``.

    The inflated grid changes within the robot radius (plus the avoidance area with
    ``inflation="paper"``) of a changed cell, plus 2 cells of rounding; the search cost
    within that plus the clearance cost's 3-cell fall-off, rounded up.
    """
    r_cells = int(math.ceil(options.robot.radius / resolution)) + 2
    if options.inflation == "paper":
        r_cells += options.w_cells + 1
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
