"""Landmarks for A* with a cost (ALT): exact lower bounds from precomputed distances.

For a landmark cell ``L`` with costs ``d(L, .)`` to every cell, the triangle inequality gives
``d(v, goal) >= |d(L, goal) - d(L, v)|`` on an undirected graph; the search's step costs
are symmetric (``length (1 + (cost[a] + cost[b]) / 2)``), so this bound is admissible and
consistent, and so is its maximum over landmarks and the octile distance. On large maps it
cuts the expansions of a long search several times (Goldberg and Harrelson's ALT).

:func:`build_landmarks` picks ``k`` landmarks in the largest connected region of free cells
by farthest-point selection (each the cell farthest, by cost, from those chosen so far; the
first the one farthest from that region's first cell in row-major order), one
single-source search each; cells of other regions get no bound from them. The result is
tied to the grid, cost and step rule it was built for: :func:`astar.find_path` refuses it
for any other. After a map update that only adds obstacles and raises costs,
:meth:`Landmarks.rebase` carries it over without a new search.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from astar import validation
from astar.errors import InvalidInputError
from astar.grid import OccupancyGrid, check_grid
from astar.search_workspace import LOCK, padded_free, workspace

__all__ = ["Landmarks", "build_landmarks"]


@dataclass(frozen=True, eq=False)
class Landmarks:
    """Landmark distances for one grid, cost and step rule (build with :func:`build_landmarks`).

    Attributes
    ----------
    grid : OccupancyGrid
        The grid they were built on (the one searched, e.g. the inflated grid).
    cost : ndarray of float64, shape (ny, nx)
        The per-cell cost, a read-only copy: ``find_path`` searches with it.
    cells : ndarray of int64, shape (k, 2)
        The landmarks ``(ix, iy)``.
    distances : ndarray of float64, shape (k, (ny + 2) (nx + 2))
        Cost from each landmark to every cell, on the search's padded flat layout
        (``inf``: unreachable).
    connectivity : int
    corner_cutting : bool
    """

    grid: OccupancyGrid
    cost: np.ndarray
    cells: np.ndarray
    distances: np.ndarray
    connectivity: int
    corner_cutting: bool

    @property
    def k(self) -> int:
        """Number of landmarks."""
        return int(self.cells.shape[0])

    def rebase(
        self, grid: OccupancyGrid, cost: object, window: tuple[int, int, int, int] | None = None
    ) -> Landmarks:
        """Return these landmarks for a grid and cost that only got harder to cross.

        When every cell occupied in :attr:`grid` is still occupied in ``grid`` and no cell's
        cost fell, every path of the new graph is a path of the old one at no lower cost, so
        the old distances ``d`` are lower bounds of the new ones ``d'``; then
        ``|d(L, goal) - d(L, v)| <= d(v, goal) <= d'(v, goal)`` and the bound stays
        admissible and consistent: the search stays exact, only less sharp. The distances
        are shared, not copied (no new search runs).

        Parameters
        ----------
        grid : OccupancyGrid
            The updated grid (same shape).
        cost : array_like of float, shape (ny, nx)
            Its per-cell cost, finite and ``>= self.cost`` everywhere. A read-only
            C-contiguous float64 array is kept as it is (the caller must not change it).
        window : tuple of int, optional
            ``(x0, x1, y0, y1)`` cells, inclusive: the caller knows that outside it ``grid``
            and ``cost`` equal the landmarks' (as :meth:`trajopt.Planner.update_map`
            reports), so only the window is checked. Default: the whole grid.

        Raises
        ------
        InvalidInputError
            Another shape, a cost not finite and ``>= 0``, a cell freed or a cost lowered
            (the message counts them): the bounds may then overestimate, so build new
            landmarks.
        """
        grid = check_grid(grid)
        if grid.shape != self.grid.shape:
            raise InvalidInputError(
                f"grid has shape {grid.shape}, the landmarks' grid {self.grid.shape}"
            )
        c = np.asarray(cost, dtype=np.float64)
        if c.shape != grid.shape:
            raise InvalidInputError(f"cost must have the grid's shape {grid.shape}, got {c.shape}")
        win = np.s_[:, :]
        if window is not None:
            x0, x1, y0, y1 = (int(v) for v in window)
            win = np.s_[y0 : y1 + 1, x0 : x1 + 1]
        part = c[win]
        if part.size and not (math.isfinite(float(part.max())) and float(part.min()) >= 0.0):
            raise InvalidInputError("cost must be finite and >= 0 everywhere")
        old_occ, new_occ = np.asarray(self.grid.occupied)[win], np.asarray(grid.occupied)[win]
        freed = int(np.count_nonzero(old_occ & ~new_occ))
        lowered = int(np.count_nonzero(part < self.cost[win]))
        if freed or lowered:
            raise InvalidInputError(
                f"the landmarks' bounds hold only where no cell was freed and no cost fell: "
                f"{freed} cells freed, {lowered} costs lowered; build new landmarks"
            )
        if c.flags.writeable or not c.flags.c_contiguous:
            c = np.array(c, order="C")
            c.flags.writeable = False
        return Landmarks(
            grid=grid,
            cost=c,
            cells=self.cells,
            distances=self.distances,
            connectivity=self.connectivity,
            corner_cutting=self.corner_cutting,
        )


def build_landmarks(
    grid: OccupancyGrid,
    cost: object,
    k: int = 6,
    *,
    connectivity: int = 8,
    corner_cutting: bool = False,
) -> Landmarks:
    """Return ``k`` landmarks for searches on ``grid`` with ``cost`` (module docstring).

    Parameters
    ----------
    grid : OccupancyGrid
        The grid to search (its free cells are the graph).
    cost : array_like of float, shape (ny, nx)
        Per-cell cost, finite and ``>= 0`` (as :func:`astar.find_path`'s ``cost``).
    k : int, optional
        Number of landmarks, ``1 <= k <= 64``; fewer when the region has fewer cells.
        Memory: ``8 k (ny + 2) (nx + 2)`` bytes; time: ``k + 1`` searches of the region.
    connectivity, corner_cutting
        The step rule of the searches it will serve (as in :func:`astar.find_path`).

    Raises
    ------
    InvalidInputError
        Bad grid, cost, ``k`` or step rule; a grid without a free cell.
    """
    from scipy import ndimage

    from astar.weighted_kernel import weighted_kernel

    grid = check_grid(grid)
    if isinstance(k, bool) or not isinstance(k, int | np.integer) or not 1 <= int(k) <= 64:
        raise InvalidInputError(f"k must be an integer in [1, 64] (landmarks), got {k!r}")
    if isinstance(connectivity, bool) or connectivity not in (4, 8):
        raise InvalidInputError(f"connectivity must be 4 or 8, got {connectivity!r}")
    c = np.array(validation.cell_costs(cost, grid), dtype=np.float64, order="C")
    c.flags.writeable = False
    # connected regions: 4-connected unless diagonal steps may cut corners
    eight = connectivity == 8 and bool(corner_cutting)
    structure = np.ones((3, 3)) if eight else None
    labels, m = ndimage.label(~np.asarray(grid.occupied), structure=structure)
    if m == 0:
        raise InvalidInputError("the grid has no free cell to put a landmark on")
    largest = int(np.argmax(np.bincount(labels.ravel())[1:])) + 1
    iy0, ix0 = np.argwhere(labels == largest)[0]
    width = grid.nx + 2
    with LOCK:
        free = padded_free(grid.occupied)
        ws = workspace(free.shape[0])

        def tree(source: int) -> np.ndarray:
            gen = ws.next_gen()
            weighted_kernel(
                free,
                width,
                source,
                -1,
                connectivity == 8,
                bool(corner_cutting),
                c.ravel(),
                ws.rec,
                ws.recf,
                gen,
                np.zeros((0, 1)),
                np.zeros(0),
            )
            return np.where(ws.rec[0::4] == gen + 1, ws.recf[1::2], np.inf)

        nearest = tree(int((iy0 + 1) * width + ix0 + 1))  # cost to the nearest chosen cell
        rows, cells = [], []
        for _ in range(int(k)):
            reach = np.where(np.isfinite(nearest), nearest, -1.0)
            v = int(np.argmax(reach))
            if reach[v] <= 0.0 and rows:
                break  # every cell of the region is a landmark already
            rows.append(tree(v))
            iy, ix = divmod(v, width)
            cells.append((ix - 1, iy - 1))
            nearest = rows[0] if len(rows) == 1 else np.minimum(nearest, rows[-1])
    dist = np.array(rows)
    dist.flags.writeable = False
    cells_a = np.array(cells, dtype=np.int64)
    cells_a.flags.writeable = False
    return Landmarks(
        grid=grid,
        cost=c,
        cells=cells_a,
        distances=dist,
        connectivity=int(connectivity),
        corner_cutting=bool(corner_cutting),
    )
