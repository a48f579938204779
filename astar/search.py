"""Octile-optimal A* on occupancy grids, compiled with numba.

:func:`find_path` searches the 8-connected (or 4-connected) grid graph of the free cells of an
:class:`~astar.grid.OccupancyGrid`:

* a straight step costs 1 (cell), a diagonal step ``sqrt(2)``;
* without corner cutting (the default, the Moving AI benchmark rule) a diagonal step needs both
  orthogonal neighbours it passes between to be free; with ``corner_cutting=True`` a diagonal step
  only needs its target cell free;
* with a per-cell ``cost`` array (clearance-aware search, :func:`astar.clearance_cost`) a step
  costs its length times ``1 + (cost[a] + cost[b]) / 2`` for its two cells ``a``, ``b``.

The heuristic is the octile distance (Manhattan for ``connectivity=4``), which is admissible and
consistent for both cost models (the step costs are never below their length), so with a closed
set the first expansion of the goal is optimal.

Implementation notes
--------------------
The kernel works on a flat ``uint8`` copy of the grid padded with one ring of blocked cells (no
bounds checks in the loop), with ``int32`` indices, precomputed neighbour offsets, a binary heap
on arrays with lazy deletion (a node pushed with the same ``f`` as the node being expanded is
already minimal, so it bypasses the heap on a stack), and work buffers reused between calls (a generation stamp marks
which cells the current search has touched, so nothing is cleared per call). Without ``cost`` the
cost-so-far of a cell is kept as two integers -- its numbers of straight and diagonal steps --
so equal costs compare exactly equal and ties are broken exactly: among equal ``f = g + h`` the
deeper node (larger ``g``) is expanded first, then the earlier pushed one. The search is
therefore deterministic. The padded grid of the last few grids searched is cached (grids are
immutable); the caches, the buffers and the lock that serialises the searches live in
:mod:`astar.search_workspace`, shared with :func:`astar.build_landmarks`.

With a ``cost`` the keys are floats that rarely tie and the open list is a radix heap on their
bit patterns (:mod:`astar.weighted_kernel`): exact, monotone, several times faster than the
binary heap on long searches; among equal ``f`` the last pushed node is expanded first.

The plain shortest path under the Moving AI rules (``connectivity=8``, no corner cutting, no
``cost``) runs jump point search (Harabor and Grastien's pruning for grids without corner
cutting: straight jumps stop at forced neighbours, diagonal jumps stop where a straight jump
from them finds a jump point, diagonal moves have no forced neighbours) on the same exact
integer-pair costs and tie-breaking; only jump points enter the open list (``expanded`` counts
them) and the segments between them are unrolled into cells. The other modes run plain A*.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from astar import validation
from astar.errors import InvalidInputError, NoPathError
from astar.grid import OccupancyGrid, check_grid
from astar.landmarks import Landmarks
from astar.search_kernels import astar_kernel, jps_kernel
from astar.search_workspace import LOCK, padded_free, workspace
from astar.weighted_kernel import weighted_kernel

__all__ = ["GridPath", "find_path"]

logger = logging.getLogger(__name__)

_SQRT2 = math.sqrt(2.0)


# --------------------------------------------------------------------------- result value
@dataclass(frozen=True, slots=True, eq=False)
class GridPath:
    """A path of grid cells found by :func:`find_path`.

    Parameters
    ----------
    cells : array_like of int, shape (n, 2)
        Cells ``(ix, iy)`` from start to goal, both included (``n >= 1``). Copied to a read-only
        ``int64`` array.
    length : float
        Length in cells: 1 per straight step, ``sqrt(2)`` per diagonal step.
    cost : float
        The cost the search minimised: equal to ``length`` without a cost grid, otherwise the sum
        of ``step length * (1 + mean cost of the step's two cells)``.
    expanded : int
        Number of nodes the search closed (popped from the open list), the goal included.
    """

    cells: np.ndarray
    length: float
    cost: float
    expanded: int

    def __post_init__(self) -> None:
        c = np.array(self.cells, dtype=np.int64, copy=True)
        if c.ndim != 2 or c.shape[1] != 2 or c.shape[0] < 1:
            raise InvalidInputError(f"cells must have shape (n, 2) with n >= 1, got {c.shape}")
        c.flags.writeable = False
        object.__setattr__(self, "cells", c)
        object.__setattr__(self, "length", float(self.length))
        object.__setattr__(self, "cost", float(self.cost))
        object.__setattr__(self, "expanded", int(self.expanded))

    def __len__(self) -> int:
        """Return the number of cells ``n``."""
        return int(self.cells.shape[0])

    def to_world(self, grid: OccupancyGrid) -> np.ndarray:
        """World coordinates of the cell centres along the path.

        Parameters
        ----------
        grid : OccupancyGrid
            The grid the path was found on (its resolution and origin are used).

        Returns
        -------
        ndarray of float64, shape (n, 2)
            ``(x, y)`` in metres.
        """
        return grid.cell_to_world(self.cells)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, GridPath):
            return NotImplemented
        return (
            self.length == other.length
            and self.cost == other.cost
            and self.expanded == other.expanded
            and bool(np.array_equal(self.cells, other.cells))
        )

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return (
            f"GridPath(n={len(self)}, start={tuple(self.cells[0].tolist())}, "
            f"goal={tuple(self.cells[-1].tolist())}, length={self.length:.6g}, "
            f"cost={self.cost:.6g}, expanded={self.expanded})"
        )


# --------------------------------------------------------------------------- constants
_EMPTY_COST = np.zeros(1, dtype=np.float64)
_NO_LANDMARKS = (np.zeros((0, 1)), np.zeros(0))


def _check_landmarks(
    landmarks: object, grid: OccupancyGrid, cost: object, connectivity: int, corner_cutting: bool
) -> np.ndarray:
    """Return the landmarks' cost after checking that they serve this search."""
    if not isinstance(landmarks, Landmarks):
        raise InvalidInputError(
            f"landmarks must be an astar.Landmarks (astar.build_landmarks), got "
            f"{type(landmarks).__name__}"
        )
    if landmarks.grid is not grid and not (
        landmarks.grid.shape == grid.shape
        and np.array_equal(landmarks.grid.occupied, grid.occupied)
    ):
        raise InvalidInputError(
            "landmarks were built for another grid (their bounds hold there only)"
        )
    if cost is not None and cost is not landmarks.cost:
        raise InvalidInputError(
            "with landmarks, pass no cost (or landmarks.cost): their bounds hold for that cost only"
        )
    if (connectivity, bool(corner_cutting)) != (landmarks.connectivity, landmarks.corner_cutting):
        raise InvalidInputError(
            f"landmarks were built for connectivity={landmarks.connectivity}, "
            f"corner_cutting={landmarks.corner_cutting}; got {connectivity}, {bool(corner_cutting)}"
        )
    return landmarks.cost


# --------------------------------------------------------------------------- public API
def find_path(
    grid: OccupancyGrid,
    start: tuple[int, int],
    goal: tuple[int, int],
    *,
    connectivity: Literal[4, 8] = 8,
    corner_cutting: bool = False,
    cost: np.ndarray | None = None,
    landmarks: Landmarks | None = None,
) -> GridPath:
    """Shortest (or cheapest) path of free cells from ``start`` to ``goal`` by A*.

    Parameters
    ----------
    grid : OccupancyGrid
        The grid to search, shape ``(ny, nx)``; usually already inflated
        (:func:`astar.inflation`). Occupied cells are never entered.
    start, goal : tuple of int
        Cells ``(ix, iy)`` (x first; row ``iy = 0`` at the bottom), inside the grid and free.
    connectivity : {8, 4}, optional
        8 (default): straight and diagonal steps, octile heuristic. 4: straight steps only,
        Manhattan heuristic.
    corner_cutting : bool, optional
        ``False`` (default, the Moving AI rule): a diagonal step needs both orthogonal
        neighbours it passes between to be free. ``True``: a diagonal step only needs its target
        free (it may pass between two blocked cells touching at a corner).
    cost : array_like of float, shape (ny, nx), optional
        Per-cell traversal cost (finite, ``>= 0``, dimensionless), e.g. from
        :func:`astar.clearance_cost`. A step then costs its length times
        ``1 + (cost[a] + cost[b]) / 2`` for its two cells; the heuristic is unchanged (still
        admissible and consistent), so the path is optimal for that cost.
    landmarks : Landmarks, optional
        From :func:`astar.build_landmarks` on this ``grid``: the search uses their cost (pass
        no ``cost``, or that same ``landmarks.cost``) and their lower bounds as well as the
        octile distance (ALT), which is still exact and expands far fewer cells on long
        searches. Refused for another grid, cost or step rule.

    Returns
    -------
    GridPath
        ``cells`` (int64, shape ``(n, 2)``, start and goal included), ``length`` (cells),
        ``cost`` (equal to ``length`` without ``cost``) and ``expanded``. With
        ``start == goal`` the path is that one cell, of length 0.

    Raises
    ------
    InvalidInputError
        ``grid`` is not an :class:`OccupancyGrid`; ``start`` or ``goal`` is not two integers,
        lies outside the grid or on an occupied cell (the message names which, the cell and
        why); ``connectivity`` is not 4 or 8; ``cost`` has the wrong shape or holds negative or
        non-finite values.
    NoPathError
        No path of free cells joins ``start`` and ``goal``.

    Notes
    -----
    The search is deterministic: ties in ``f`` are broken towards the larger cost-so-far,
    then by insertion order (with ``cost``: the last pushed first). It is not
    thread-parallel: concurrent calls are serialised.

    Examples
    --------
    >>> import numpy as np
    >>> g = OccupancyGrid(np.zeros((3, 4), bool), resolution=1.0)
    >>> p = find_path(g, (0, 0), (3, 2))
    >>> p.cells.tolist(), round(p.length, 6)
    ([[0, 0], [1, 1], [2, 2], [3, 2]], 3.828427)
    """
    grid = check_grid(grid)
    if isinstance(connectivity, bool) or connectivity not in (4, 8):
        raise InvalidInputError(f"connectivity must be 4 or 8, got {connectivity!r}")
    sx, sy = validation.cell("start", start, grid)
    gx, gy = validation.cell("goal", goal, grid)
    lm, lg = _NO_LANDMARKS
    if landmarks is not None:
        cost = _check_landmarks(landmarks, grid, cost, connectivity, corner_cutting)
        cflat = cost.ravel()  # validated when the landmarks were built
    elif cost is not None:
        cflat = np.ascontiguousarray(validation.cell_costs(cost, grid)).ravel()
    else:
        cflat = _EMPTY_COST
    weighted = cost is not None
    width = grid.nx + 2
    s = (sy + 1) * width + sx + 1
    t = (gy + 1) * width + gx + 1
    if landmarks is not None:
        lm = landmarks.distances
        lg = np.ascontiguousarray(lm[:, t])
    # jump point search for the plain shortest path under the Moving AI rules
    jps = connectivity == 8 and not corner_cutting and not weighted
    with LOCK:
        free = padded_free(grid.occupied)
        ws = workspace(free.shape[0])
        gen = ws.next_gen()
        if weighted:
            found, path, expanded, gcost, na, nb = weighted_kernel(
                free,
                width,
                s,
                t,
                connectivity == 8,
                bool(corner_cutting),
                cflat,
                ws.rec,
                ws.recf,
                gen,
                lm,
                lg,
            )
        elif jps:
            found, path, expanded, gcost, na, nb = jps_kernel(free, width, s, t, ws.rec, gen)
        else:
            found, path, expanded, gcost, na, nb = astar_kernel(
                free, width, s, t, connectivity == 8, bool(corner_cutting), ws.rec, gen
            )
    if not found:
        raise NoPathError(
            f"no path from start ({sx}, {sy}) to goal ({gx}, {gy}) on the "
            f"{grid.nx} x {grid.ny} grid (connectivity={connectivity}, "
            f"corner_cutting={bool(corner_cutting)}); the search exhausted every cell reachable "
            f"from start ({expanded} {'jump points' if jps else 'cells'} expanded)"
        )
    iy, ix = np.divmod(path, width)
    cells = np.stack([ix - 1, iy - 1], axis=1)
    if weighted:
        steps = np.abs(np.diff(cells, axis=0)).sum(axis=1)
        nb = int(np.count_nonzero(steps == 2))
        na = int(steps.shape[0] - nb)
        length = na + nb * _SQRT2
        total = float(gcost)
    else:
        length = int(na) + int(nb) * _SQRT2
        total = length
    logger.debug(
        "find_path (%d, %d) -> (%d, %d): %d cells, length %.6g, expanded %d",
        sx,
        sy,
        gx,
        gy,
        cells.shape[0],
        length,
        expanded,
    )
    return GridPath(cells, length, total, expanded)
