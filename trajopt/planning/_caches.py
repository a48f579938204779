"""What a planner keeps across queries on one map: :class:`PlannerCaches`.

The inflated grid, its connected components, the search cost and the ALT landmarks are
computed on first use and kept; :meth:`PlannerCaches.update` recomputes the inflated grid
and the clearance cost only where a map change reaches (from the newly blocked cells alone
when the change frees no cell, as a re-route's marks, :func:`_blocked_patch`). The search landmarks, whose
distances span the whole map, are kept (:meth:`astar.Landmarks.rebase`: still exact lower
bounds) when the change only adds obstacles, so that no inflated cell is freed and no cost
falls; otherwise they are dropped and built again by the next search. The component labels
are updated from a labelling of the changed box when that settles the change
(:func:`update_labels`), and otherwise dropped and labelled again on next use. A footprint
robot's disc models have caches of their own (:meth:`PlannerCaches.disc`), updated with
the map. The blocks of the coarse-to-fine search (:attr:`PlannerCaches.coarse`) are built on
the first coarse search and recomputed by :meth:`PlannerCaches.update` only in the blocks
the changed window touches (:meth:`astar.CoarseGrid.update`).
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
from trajopt.geometry import derive_blocks, length_unit
from trajopt.planning._label_kernel import label_kernel
from trajopt.planning._memory import check_memory
from trajopt.planning._options import PlannerOptions

#: the clearance cost falls to zero over this many length units beyond the radius
FALLOFF_UNITS = 3.0


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
    cell_units : bool, optional
        Count the clearance cost's fall-off in cells, not length units (a footprint
        robot's disc models, whose fits count in cells). Default False.

    Notes
    -----
    The lazy builds hold a lock, so caches may be read from several threads.
    """

    def __init__(
        self,
        grid: OccupancyGrid,
        costmap: Costmap | None,
        options: PlannerOptions,
        *,
        cell_units: bool = False,
    ):
        check_memory(grid.shape, options)  # a map too large is refused before any work
        self.cell_units = cell_units
        self.grid = grid
        self.costmap = costmap
        self.options = options
        self._lock = threading.RLock()
        self._inflated: OccupancyGrid | None = None
        self._cost: np.ndarray | None = None
        self._landmarks: astar.Landmarks | None = None
        self._components: np.ndarray | None = None
        self._coarse: astar.CoarseGrid | None = None
        self._discs: dict[float, PlannerCaches] = {}

    @property
    def inflated(self) -> OccupancyGrid:
        """The grid the robot centre moves in (computed once per map)."""
        with self._lock:
            if self._inflated is None:
                self._inflated = self.grid.with_occupied(self._inflate(self.grid))
            return self._inflated

    @property
    def components(self) -> np.ndarray:
        """Labels of the search's reachable sets on the inflated grid (computed once per map).

        ``components[iy, ix]`` is 0 on an occupied cell of :attr:`inflated` and ``k >= 1``
        on a free one, the same ``k`` exactly for the free cells the search can go between
        (:func:`component_labels`: the 4-connected components of the free cells). Read-only
        int32, shape ``grid.shape``. :meth:`update` keeps them up to date (updated in the
        changed box, :func:`update_labels`, or dropped and labelled again here), so after
        a map change the numbers may differ from a fresh labelling's: compare labels, not
        numbers.
        """
        with self._lock:
            if self._components is None:
                self._components = component_labels(self.inflated.occupied)
            return self._components

    @property
    def built_components(self) -> np.ndarray | None:
        """The component labels if a query has built them (``None`` otherwise; builds nothing)."""
        return self._components

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
                cost.flags.writeable = False  # shared with the landmarks and the blocks
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

    @property
    def coarse(self) -> astar.CoarseGrid:
        """Blocks of the inflated grid and search cost for the coarse-to-fine search.

        Blocks of :meth:`PlannerOptions.search_block_cells` cells, built on first use
        (:func:`astar.build_coarse_grid`) and kept up to date by :meth:`update`.
        """
        with self._lock:
            if self._coarse is None:
                k = self.options.search_block_cells(self.grid.resolution)
                self._coarse = astar.build_coarse_grid(self.inflated, k, self.search_cost)
            return self._coarse

    @property
    def built_coarse(self) -> astar.CoarseGrid | None:
        """The coarse-to-fine blocks if a search has built them (``None`` otherwise)."""
        return self._coarse

    def disc(self, options: PlannerOptions) -> PlannerCaches:
        """Return (and keep) the caches of a disc model with ``options`` on this map."""
        radius = options.robot.radius
        with self._lock:
            if radius not in self._discs:
                # a footprint's fits count in cells (Smoother.fit), and so does its search
                self._discs[radius] = PlannerCaches(
                    self.grid, self.costmap, options, cell_units=True
                )
            return self._discs[radius]

    def _inflate(self, grid: OccupancyGrid) -> np.ndarray:
        o = self.options
        occ = astar.inflate(grid, o.robot.radius, metric="square", outside_occupied=True)
        out = occ.occupied
        if o.inflation == "paper":
            out = out | astar.avoidance_area(grid, o.w_cells, border=True).occupied
        return out

    def _clearance_cost(self, grid: OccupancyGrid, outside: bool = True) -> np.ndarray:
        """Return the clearance cost of ``grid`` (zeros unless the search uses it).

        ``outside=False``: of ``grid``'s cells alone, no outside wall (:meth:`_cost_alone`).
        """
        cost = np.zeros(grid.shape)
        if self.options.search in ("clearance", "costmap+clearance") and (
            outside or grid.occupied.any()
        ):
            cost += astar.clearance_cost(
                grid,
                self.options.robot.radius,
                falloff_cells=(
                    FALLOFF_UNITS
                    if self.cell_units
                    else falloff_cells(self.options, grid.resolution)
                ),
                outside_occupied=outside,
            )
        return cost

    def _inflate_alone(self, grid: OccupancyGrid) -> np.ndarray:
        """:meth:`_inflate` (``inflation="exact"``) of ``grid``'s cells alone, no outside wall."""
        return astar.inflate(grid, self.options.robot.radius, metric="square").occupied

    def _cost_alone(self, grid: OccupancyGrid) -> np.ndarray:
        """:meth:`_clearance_cost` of ``grid``'s cells alone, no outside wall (no costmap)."""
        return self._clearance_cost(grid, outside=False)

    def derived(self, grid: OccupancyGrid) -> PlannerCaches:
        """Return the caches of a changed map of the same frame, leaving these untouched.

        The new caches start from what these have built (the inflated grid, the clearance
        cost, the component labels, the coarse blocks, the landmarks: values that
        :meth:`update` replaces rather than changes) and are then updated to ``grid``
        (:meth:`update`: recomputed only where the change reaches). The occupied blocks the
        smoother's clearance searches on the raw map are derived from this map's where it
        has them (:func:`trajopt.geometry.derive_blocks`). A footprint robot's disc
        models are derived the same way. A re-route plans on such a map (the movers' swept
        regions marked, :func:`trajopt.moving.reroute`).

        Parameters
        ----------
        grid : astar.OccupancyGrid
            The changed map (same shape, resolution and origin, else everything is rebuilt;
            on a costmap's planner the caches are built afresh, the costmap's graded cost
            being part of the search cost).
        """
        if self.costmap is not None:
            return PlannerCaches(grid, self.costmap, self.options, cell_units=self.cell_units)
        with self._lock:
            out = PlannerCaches.__new__(PlannerCaches)
            out.cell_units = self.cell_units
            out.grid = self.grid
            out.costmap = None
            out.options = self.options
            out._lock = threading.RLock()
            out._inflated = self._inflated
            out._cost = self._cost
            out._landmarks = self._landmarks
            out._components = self._components
            out._coarse = self._coarse
            out._discs = {}
            change = out.update(grid)
            if not change["reset"]:  # the raw map's clearance blocks, from this map's
                derive_blocks(grid.occupied, self.grid.occupied, change["window"])
            out._discs = {r: d.derived(grid) for r, d in self._discs.items()}
            return out

    def inflated_window(self, grid: OccupancyGrid, window: tuple[int, int, int, int]) -> np.ndarray:
        """Return the inflated grid of ``grid`` (a map of the same frame) in ``window`` only.

        The values :attr:`inflated` would hold for ``grid`` in the cell box ``window``
        ``(x0, x1, y0, y1)`` (inclusive, inside the grid), computed from ``grid`` cut to the
        box grown by :func:`change_reach` (as :meth:`update` patches it): bool, shape
        ``(y1 - y0 + 1, x1 - x0 + 1)``, ``True`` where the robot centre may not go.
        """
        reach = change_reach(self.options, grid.resolution)[0]
        return np.array(_window_values(grid, window, reach, self._inflate))

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
                check_memory(grid.shape, self.options)
                self.grid, self._inflated, self._cost = grid, None, None
                self._components = None
                self._coarse = None
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
            near = _grow(box, r_cells, grid.shape)  # where the inflated grid may change
            # a change that only blocks cells (a re-route's marks), exact inflation: computed
            # from the blocked cells alone and merged (_blocked_patch)
            blocking = self.options.inflation == "exact" and bool(grid.occupied.flat[changed].all())
            if self._inflated is not None:
                occ = np.array(self._inflated.occupied)
                if blocking:
                    part, vals = _blocked_patch(grid, old, box, r_cells, self._inflate_alone)
                    occ[part] |= vals
                else:
                    _patch(occ, grid, near, r_cells, self._inflate)
                if self._components is not None:
                    self._components = update_labels(
                        self._components, self._inflated.occupied, occ, near, r_cells
                    )
                self._inflated = grid.with_occupied(occ)
            if self._cost is not None:
                cost = np.array(self._cost)
                if blocking:
                    part, vals = _blocked_patch(grid, old, box, reach_cost, self._cost_alone)
                    np.maximum(cost[part], vals, out=cost[part])
                else:
                    _patch(cost, grid, window, reach_cost, self._clearance_cost)
                cost.flags.writeable = False  # shared with the landmarks
                self._cost = cost
            if self._coarse is not None:  # built from both, so both were built
                self._coarse = self._coarse.update(self._inflated, self._cost, window)
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


def component_labels(occupied: np.ndarray) -> np.ndarray:
    """Label the sets of free cells that :func:`astar.find_path` can go between.

    The planner's search (:func:`astar.find_path` with its defaults: 8-connected, no corner
    cutting, a finite cost per cell) joins two free cells exactly when they lie in the
    same **4-connected component** of the free cells. Proof: a straight step is a
    4-connected step; a diagonal step from ``a`` to ``b`` needs both orthogonal cells it
    passes between free, so ``a``, one of them, ``b`` is a 4-connected walk; and every
    4-connected step is a legal straight step.

    The cells are labelled by a compiled two-pass union-find
    (:func:`trajopt.planning._label_kernel.label_kernel`: about 0.1 ms on a 384 x 384 map).
    This gives the same labels as ``scipy.ndimage.label(~occupied)`` (4-connected
    structure, components numbered by their first cell in row-major order) without
    importing :mod:`scipy.ndimage`, whose import would cost a process's first plan about
    0.1 s.

    Parameters
    ----------
    occupied : array_like of bool, shape (ny, nx)
        Occupancy of a grid (``occupied[iy, ix]``), e.g. an inflated grid's.

    Returns
    -------
    ndarray of int32, shape (ny, nx)
        0 on occupied cells; ``1 .. n`` on free cells, one label per component. Read-only.

    Examples
    --------
    >>> occ = np.array([[0, 1, 0], [1, 0, 0]], dtype=bool)  # touching at a corner only
    >>> component_labels(occ).tolist()
    [[1, 0, 2], [0, 2, 2]]
    """
    occ = np.ascontiguousarray(occupied, dtype=np.bool_)
    if occ.flags.writeable:  # one compiled signature, a grid's own read-only cells': a view
        occ = occ.view()  # (a writable array, as the derived caches' box, compiled another:
        occ.flags.writeable = False  # 4 s inside a process's first re-route on a fresh cache)
    out = label_kernel(occ)
    out.flags.writeable = False
    return out


def update_labels(
    labels: np.ndarray,
    old_occupied: np.ndarray,
    occupied: np.ndarray,
    window: tuple[int, int, int, int],
    margin: int,
) -> np.ndarray | None:
    """Component labels after a change of the grid inside ``window``, from local labellings.

    ``labels`` are :func:`component_labels` of ``old_occupied``; ``occupied`` equals it
    outside ``window`` (``(x0, x1, y0, y1)`` cells, inclusive). The box ``B`` (``window``
    grown by ``margin >= 1`` cells) is labelled on its own before and after the change. When
    the cells free both before and after join the same local components before and after
    (one to one) and every local component after the change holds such a cell, the global
    partition is the old one with the blocked cells removed and each freed cell joined to
    the component of its local component. Proof: a path between free cells leaves and
    enters ``B`` at cells of its edge, which the change (inside ``window``) left free, so a
    path's stretch inside ``B`` joins two cells of one local component before the change,
    hence after it, and the other way round; a freed cell's neighbours are in ``B``.
    Otherwise (a component may split or merge, or a new one appears) returns ``None``:
    label the whole grid again.

    A change that frees no cell (a re-route's marks, :meth:`PlannerCaches.derived`) needs
    the box labelled after the change only: cells joined after the change were joined before
    (a path of free cells after is one before), so each local component lies in one old
    component; when no two local components lie in the same old one, the partition is the
    old one with the blocked cells removed (a path's stretch inside ``B`` joins two cells of
    its edge, free after, of one old component, hence of one local component).

    Returns
    -------
    ndarray of int32 or None
        Read-only labels of ``occupied`` (the same partition as :func:`component_labels`;
        the numbers may leave gaps), or ``None``.
    """
    x0, x1, y0, y1 = _grow(window, max(1, margin), labels.shape)
    box = (slice(y0, y1 + 1), slice(x0, x1 + 1))
    after = component_labels(occupied[box])
    if not np.any(old_occupied[box] > occupied[box]):  # no cell freed
        return _blocked_only(labels, after, box)
    before = component_labels(old_occupied[box])
    both = (before > 0) & (after > 0)  # free before and after
    a, b = after[both], before[both]
    n_after, n_before = int(after.max()), int(before.max())
    pa, pb = np.divmod(np.unique(a.astype(np.int64) * (n_before + 1) + b), n_before + 1)
    if (
        pa.size != n_after  # a local component of freed cells only, or a merge
        or np.unique(pa).size != n_after
        or np.unique(pb).size != n_after  # a local component cut in two
    ):
        return None
    lut = np.zeros(n_after + 1, dtype=np.int32)
    lut[a] = labels[box][both]  # one old label per local component (checked above)
    out = np.array(labels)
    out[box] = lut[after]
    out.flags.writeable = False
    return out


def _blocked_only(
    labels: np.ndarray, after: np.ndarray, box: tuple[slice, slice]
) -> np.ndarray | None:
    """:func:`update_labels` for a change that frees no cell, from the box's labels ``after`` it.

    Each local component takes the old label of its cells (one per component, as no cell was
    freed); ``None`` when two local components take the same one (the change may have cut
    an old component in two).
    """
    free = after > 0
    n_after = int(after.max())
    lut = np.zeros(n_after + 1, dtype=np.int32)
    lut[after[free]] = labels[box][free]
    if np.unique(lut[1:]).size != n_after:
        return None
    out = np.array(labels)
    out[box] = lut[after]
    out.flags.writeable = False
    return out


def falloff_cells(options: PlannerOptions, resolution: float) -> float:
    """Return the clearance cost's fall-off (cells): :data:`FALLOFF_UNITS` length units.

    The length unit is :func:`~trajopt.geometry.length_unit` of the map and the robot: the
    cell side, or ``radius / 4`` on finer maps, so that the search keeps the same distance
    from walls (in metres) whatever the resolution.
    """
    return FALLOFF_UNITS * length_unit(resolution, options.robot.radius) / resolution


def change_reach(options: PlannerOptions, resolution: float) -> tuple[int, int]:
    """Cells a changed cell can reach: ``(inflated grid, search cost)``.

    The inflated grid changes within the robot radius (plus the avoidance area with
    ``inflation="paper"``) of a changed cell, plus 2 cells of rounding; the search cost
    within that plus the clearance cost's fall-off (:func:`falloff_cells`), rounded up.
    """
    r_cells = int(math.ceil(options.robot.radius / resolution)) + 2
    if options.inflation == "paper":
        r_cells += options.w_cells + 1
    return r_cells, r_cells + int(math.ceil(falloff_cells(options, resolution))) + 2


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
    target[y0 : y1 + 1, x0 : x1 + 1] = _window_values(grid, window, reach, compute)


def _blocked_patch(
    grid: OccupancyGrid, old: OccupancyGrid, box, reach: int, compute
) -> tuple[tuple[slice, slice], np.ndarray]:
    """Return the cells and ``compute``'s values of the cells ``grid`` blocks that ``old`` did not.

    For a change that only blocks cells, all inside the cell box ``box``: ``compute`` runs
    on the map cut to ``box`` grown by ``reach`` with those cells alone occupied (no
    outside wall), and returns the cut (``(rows, columns)`` slices) and its values. The
    inflated grid is a union of discs round the occupied cells, so the new one is the old one
    or this; the clearance cost is a non-increasing function of the distance to the nearest
    occupied cell (:func:`astar.clearance_cost`), so the new one is the larger of the old
    one and this, which is 0 farther than ``reach`` from these cells.
    """
    x0, x1, y0, y1 = _grow(box, reach, grid.shape)
    part = (slice(y0, y1 + 1), slice(x0, x1 + 1))
    res = grid.resolution
    ox, oy = grid.origin
    alone = np.asarray(grid.occupied[part]) & ~np.asarray(old.occupied[part])
    return part, compute(OccupancyGrid(alone, res, (ox + x0 * res, oy + y0 * res)))


def _window_values(grid: OccupancyGrid, window, reach: int, compute) -> np.ndarray:
    """Return ``compute``'s per-cell values of ``grid`` in ``window``, as :func:`_patch` sets them."""
    x0, x1, y0, y1 = window
    cx0, cx1, cy0, cy1 = _grow(window, reach, grid.shape)
    res = grid.resolution
    ox, oy = grid.origin
    sub = OccupancyGrid(
        grid.occupied[cy0 : cy1 + 1, cx0 : cx1 + 1], res, (ox + cx0 * res, oy + cy0 * res)
    )
    vals = compute(sub)
    return vals[y0 - cy0 : y1 - cy0 + 1, x0 - cx0 : x1 - cx0 + 1]
