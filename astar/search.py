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
immutable).

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
import threading
from collections import OrderedDict
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numba import njit

from astar import validation
from astar.errors import InvalidInputError, NoPathError
from astar.grid import OccupancyGrid

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


# --------------------------------------------------------------------------- the kernel
@njit(cache=True, inline="always")
def _heap_pop(hf, hg, hn, size):  # pragma: no cover - compiled
    """Pop the heap's root: returns ``(node, f, new size)``."""
    u = hn[0]
    fcur = hf[0]
    size -= 1
    if size > 0:
        lf = hf[size]
        lg = hg[size]
        ln = hn[size]
        i = 0
        while True:
            c = 2 * i + 1
            if c >= size:
                break
            if c + 1 < size and (hf[c + 1] < hf[c] or (hf[c + 1] == hf[c] and hg[c + 1] > hg[c])):
                c += 1
            if hf[c] < lf or (hf[c] == lf and hg[c] > lg):
                hf[i] = hf[c]
                hg[i] = hg[c]
                hn[i] = hn[c]
                i = c
            else:
                break
        hf[i] = lf
        hg[i] = lg
        hn[i] = ln
    return u, fcur, size


@njit(cache=True, inline="always")
def _stack_push(stk, ssize, scap, v):  # pragma: no cover - compiled
    """Push ``v`` on the stack of nodes whose f equals the current minimum (grown x2)."""
    if ssize == scap:
        scap *= 2
        ns = np.empty(scap, dtype=np.int32)
        ns[:ssize] = stk[:ssize]
        stk = ns
    stk[ssize] = v
    return stk, ssize + 1, scap


@njit(cache=True, inline="always")
def _heap_push(hf, hg, hn, size, cap, fnew, gnew, v):  # pragma: no cover - compiled
    """Push ``(f, g, node)`` on the binary heap (ties: larger ``g`` first; grown x2)."""
    if size == cap:
        cap *= 2
        nf = np.empty(cap, dtype=np.float64)
        ng = np.empty(cap, dtype=np.float64)
        nn = np.empty(cap, dtype=np.int32)
        nf[:size] = hf[:size]
        ng[:size] = hg[:size]
        nn[:size] = hn[:size]
        hf = nf
        hg = ng
        hn = nn
    i = size
    size += 1
    while i > 0:
        p = (i - 1) >> 1
        if fnew < hf[p] or (fnew == hf[p] and gnew > hg[p]):
            hf[i] = hf[p]
            hg[i] = hg[p]
            hn[i] = hn[p]
            i = p
        else:
            break
    hf[i] = fnew
    hg[i] = gnew
    hn[i] = v
    return hf, hg, hn, size, cap


@njit(cache=True)
def _astar_kernel(
    free,  # uint8 [H*W], padded with a blocked ring
    width,  # W = nx + 2
    start,  # padded flat index
    goal,
    conn8,  # bool
    cut,  # corner cutting allowed
    weighted,  # bool: use `cost`
    cost,  # float64 [ny*nx], unpadded (ignored unless weighted)
    rec,  # int32 [4*H*W] per-cell record: stamp, parent, straight steps, diagonal steps
    recf,  # float64 view of rec: recf[2 * v + 1] is the cost so far (weighted)
    gen,  # this search's stamp; gen + 1 marks closed
):  # pragma: no cover - numba
    sqrt2 = 1.4142135623730951
    w = width
    gx = goal % w
    gy = goal // w

    # neighbour table: E, W, N, S, then NE, NW, SE, SW
    ndir = 8 if conn8 else 4
    ddx = np.array([1, -1, 0, 0, 1, -1, 1, -1], dtype=np.int32)
    ddy = np.array([0, 0, 1, -1, 1, 1, -1, -1], dtype=np.int32)

    cap = 1024
    hf = np.empty(cap, dtype=np.float64)
    hg = np.empty(cap, dtype=np.float64)
    hn = np.empty(cap, dtype=np.int32)
    size = 0

    closed = gen + 1
    rec[4 * start] = gen
    rec[4 * start + 2] = 0
    rec[4 * start + 3] = 0
    rec[4 * start + 1] = -1
    recf[2 * start + 1] = 0.0
    sx = start % w
    sy = start // w
    ax = abs(sx - gx)
    ay = abs(sy - gy)
    if conn8:
        h0 = max(ax, ay) - min(ax, ay) + min(ax, ay) * sqrt2
    else:
        h0 = float(ax + ay)
    hf[0] = h0
    hg[0] = 0.0
    hn[0] = start
    size = 1

    # a node pushed with f equal to the f being expanded is minimal (consistent heuristic):
    # it bypasses the heap on a LIFO stack, which is popped first
    scap = 256
    stk = np.empty(scap, dtype=np.int32)
    ssize = 0
    fcur = h0

    expanded = 0
    found = False
    fr = np.zeros(8, dtype=np.bool_)
    while size > 0 or ssize > 0:
        if ssize > 0:
            ssize -= 1
            u = stk[ssize]
        else:
            # ---- pop the heap's root
            u, fcur, size = _heap_pop(hf, hg, hn, size)
        if rec[4 * u] == closed:
            continue  # stale entry (lazy deletion)
        rec[4 * u] = closed
        expanded += 1
        if u == goal:
            found = True
            break
        ux = u % w
        uy = u // w
        gu = recf[2 * u + 1]
        # unpadded cell index of a padded index v in row vy: v - 2 * vy - (w - 1)
        cu = cost[u - 2 * uy - (w - 1)] if weighted else 0.0
        gau = rec[4 * u + 2]
        gbu = rec[4 * u + 3]
        for k in range(4):
            fr[k] = free[u + ddy[k] * w + ddx[k]] != 0
        for k in range(ndir):
            dx = ddx[k]
            dy = ddy[k]
            v = u + dy * w + dx
            if k < 4:
                if not fr[k]:
                    continue
            else:
                if free[v] == 0:
                    continue
                if not cut:
                    # both orthogonal neighbours: (dx, 0) is E/W = k 0/1, (0, dy) is N/S = k 2/3
                    if not fr[0 if dx > 0 else 1] or not fr[2 if dy > 0 else 3]:
                        continue
            r4 = 4 * v
            sv = rec[r4]
            if sv == closed:
                continue
            vx = ux + dx
            vy = uy + dy
            ax = abs(vx - gx)
            ay = abs(vy - gy)
            if weighted:
                step = 1.0 if k < 4 else sqrt2
                gnew = gu + step * (1.0 + 0.5 * (cu + cost[v - 2 * vy - (w - 1)]))
                if sv == gen and gnew >= recf[2 * v + 1]:
                    continue
                recf[2 * v + 1] = gnew
                if conn8:
                    hv = max(ax, ay) - min(ax, ay) + min(ax, ay) * sqrt2
                else:
                    hv = float(ax + ay)
                fnew = gnew + hv
            else:
                na = gau + (1 if k < 4 else 0)
                nb = gbu + (0 if k < 4 else 1)
                gnew = na + nb * sqrt2
                if sv == gen and gnew >= rec[r4 + 2] + rec[r4 + 3] * sqrt2:
                    continue
                rec[r4 + 2] = na
                rec[r4 + 3] = nb
                if conn8:
                    mn = min(ax, ay)
                    fnew = (na + max(ax, ay) - mn) + (nb + mn) * sqrt2
                else:
                    fnew = (na + ax + ay) + nb * sqrt2
            rec[r4] = gen
            rec[r4 + 1] = u
            if fnew == fcur:
                stk, ssize, scap = _stack_push(stk, ssize, scap, v)
                continue
            # ---- push (sift up)
            hf, hg, hn, size, cap = _heap_push(hf, hg, hn, size, cap, fnew, gnew, v)

    if not found:
        return False, np.empty(0, dtype=np.int64), expanded, 0.0, 0, 0
    n = 1
    v = goal
    while v != start:
        v = rec[4 * v + 1]
        n += 1
    path = np.empty(n, dtype=np.int64)
    v = goal
    for i in range(n - 1, -1, -1):
        path[i] = v
        if i > 0:
            v = rec[4 * v + 1]
    if weighted:
        return True, path, expanded, recf[2 * goal + 1], 0, 0
    return True, path, expanded, 0.0, rec[4 * goal + 2], rec[4 * goal + 3]


# --------------------------------------------------------------------------- jump point search
@njit(cache=True)
def _jump_straight(free, n, d, p, goal):  # pragma: no cover - numba
    """Walk from ``n`` by ``d`` to the next jump point (``-1`` if blocked first)."""
    # p is the perpendicular offset (1 or the row width); a cell is a jump point when a side
    # cell is free while the side cell one step back is blocked (a forced neighbour)
    while True:
        n += d
        if free[n] == 0:
            return -1
        if n == goal:
            return n
        b = n - d
        if (free[n + p] != 0 and free[b + p] == 0) or (free[n - p] != 0 and free[b - p] == 0):
            return n


@njit(cache=True)
def _jump_diag(free, n, dh, dv, w, goal):  # pragma: no cover - numba
    """Walk diagonally from ``n`` by ``dh + dv`` to the next jump point (``-1`` if none)."""
    while True:
        # no corner cutting: both orthogonal cells of the step must be free
        if free[n + dh] == 0 or free[n + dv] == 0:
            return -1
        n += dh + dv
        if free[n] == 0:
            return -1
        if n == goal:
            return n
        if _jump_straight(free, n, dh, w, goal) >= 0 or _jump_straight(free, n, dv, 1, goal) >= 0:
            return n


@njit(cache=True)
def _jps_kernel(free, width, start, goal, rec, gen):  # pragma: no cover - numba
    """Jump point search: 8-connected, no corner cutting, octile costs (exact, integer pairs).

    Same record layout and result tuple as :func:`_astar_kernel` (``rec`` holds the jump
    points only; the path between two jump points is a straight or diagonal segment).
    """
    sqrt2 = 1.4142135623730951
    w = width
    gx = goal % w
    gy = goal // w

    cap = 256
    hf = np.empty(cap, dtype=np.float64)
    hg = np.empty(cap, dtype=np.float64)
    hn = np.empty(cap, dtype=np.int32)

    closed = gen + 1
    rec[4 * start] = gen
    rec[4 * start + 2] = 0
    rec[4 * start + 3] = 0
    rec[4 * start + 1] = -1
    ax = abs(start % w - gx)
    ay = abs(start // w - gy)
    h0 = max(ax, ay) - min(ax, ay) + min(ax, ay) * sqrt2
    hf[0] = h0
    hg[0] = 0.0
    hn[0] = start
    size = 1

    scap = 64
    stk = np.empty(scap, dtype=np.int32)
    ssize = 0
    fcur = h0

    succ = np.empty(8, dtype=np.int64)
    # the 8 directions as (horizontal offset, vertical offset), straight ones first
    sdh = np.array([1, -1, 0, 0, 1, -1, 1, -1], dtype=np.int64)
    sdv = np.array([0, 0, w, -w, w, w, -w, -w], dtype=np.int64)

    expanded = 0
    found = False
    while size > 0 or ssize > 0:
        if ssize > 0:
            ssize -= 1
            u = stk[ssize]
        else:
            u, fcur, size = _heap_pop(hf, hg, hn, size)
        if rec[4 * u] == closed:
            continue
        rec[4 * u] = closed
        expanded += 1
        if u == goal:
            found = True
            break
        ux = u % w
        uy = u // w
        gau = rec[4 * u + 2]
        gbu = rec[4 * u + 3]
        pu = rec[4 * u + 1]

        # ---- successors: jump points in the pruned directions
        ns = 0
        if pu < 0:
            for k in range(8):
                dh = sdh[k]
                dv = sdv[k]
                if k < 4:
                    if free[u + dh + dv] != 0:
                        v = _jump_straight(free, u, dh + dv, 1 if dh == 0 else w, goal)
                        if v >= 0:
                            succ[ns] = v
                            ns += 1
                else:
                    v = _jump_diag(free, u, dh, dv, w, goal)
                    if v >= 0:
                        succ[ns] = v
                        ns += 1
        else:
            px = pu % w
            py = pu // w
            sx = 1 if ux > px else (-1 if ux < px else 0)
            sy = 1 if uy > py else (-1 if uy < py else 0)
            dh = sx
            dv = sy * w
            if sx != 0 and sy != 0:
                if free[u + dh] != 0:
                    v = _jump_straight(free, u, dh, w, goal)
                    if v >= 0:
                        succ[ns] = v
                        ns += 1
                if free[u + dv] != 0:
                    v = _jump_straight(free, u, dv, 1, goal)
                    if v >= 0:
                        succ[ns] = v
                        ns += 1
                v = _jump_diag(free, u, dh, dv, w, goal)
                if v >= 0:
                    succ[ns] = v
                    ns += 1
            else:
                d = dh + dv  # the direction of travel
                p = w if sy == 0 else 1  # perpendicular offset
                if free[u + d] != 0:
                    v = _jump_straight(free, u, d, p, goal)
                    if v >= 0:
                        succ[ns] = v
                        ns += 1
                for q in (p, -p):
                    if free[u + q] != 0 and free[u - d + q] == 0:
                        # forced: turn to the side, straight or diagonally forward
                        v = _jump_straight(free, u, q, w + 1 - p, goal)
                        if v >= 0:
                            succ[ns] = v
                            ns += 1
                        if sy == 0:
                            v = _jump_diag(free, u, d, q, w, goal)
                        else:
                            v = _jump_diag(free, u, q, d, w, goal)
                        if v >= 0:
                            succ[ns] = v
                            ns += 1

        for j in range(ns):
            v = succ[j]
            r4 = 4 * v
            sv = rec[r4]
            if sv == closed:
                continue
            vx = v % w
            vy = v // w
            ddx = abs(vx - ux)
            ddy = abs(vy - uy)
            if ddx != 0 and ddy != 0:
                na = gau
                nb = gbu + ddx
            else:
                na = gau + ddx + ddy
                nb = gbu
            gnew = na + nb * sqrt2
            if sv == gen and gnew >= rec[r4 + 2] + rec[r4 + 3] * sqrt2:
                continue
            rec[r4] = gen
            rec[r4 + 2] = na
            rec[r4 + 3] = nb
            rec[r4 + 1] = u
            ax = abs(vx - gx)
            ay = abs(vy - gy)
            mn = min(ax, ay)
            fnew = (na + max(ax, ay) - mn) + (nb + mn) * sqrt2
            if fnew == fcur:
                stk, ssize, scap = _stack_push(stk, ssize, scap, v)
                continue
            hf, hg, hn, size, cap = _heap_push(hf, hg, hn, size, cap, fnew, gnew, v)

    if not found:
        return False, np.empty(0, dtype=np.int64), expanded, 0.0, 0, 0
    # ---- unroll the jump points into cells (each hop is a straight or diagonal segment)
    n = 1
    v = goal
    while v != start:
        pv = rec[4 * v + 1]
        n += max(abs(v % w - pv % w), abs(v // w - pv // w))
        v = pv
    path = np.empty(n, dtype=np.int64)
    i = n - 1
    path[i] = goal
    v = goal
    while v != start:
        pv = rec[4 * v + 1]
        vx = v % w
        vy = v // w
        sx = 1 if pv % w > vx else (-1 if pv % w < vx else 0)
        sy = 1 if pv // w > vy else (-1 if pv // w < vy else 0)
        step = sx + sy * w
        c = v
        while c != pv:
            c += step
            i -= 1
            path[i] = c
        v = pv
    return True, path, expanded, 0.0, rec[4 * goal + 2], rec[4 * goal + 3]


# --------------------------------------------------------------------------- caches
class _Workspace:
    """Work buffers of one padded size, reused between searches (guarded by a lock)."""

    __slots__ = ("gen", "rec", "recf")

    def __init__(self, n: int) -> None:
        # one cache line touch per cell: [stamp, parent, straight steps, diagonal steps]; the
        # two step counts double as the float64 cost so far of the weighted search (recf)
        self.rec = np.zeros(4 * n, dtype=np.int32)
        self.recf = self.rec.view(np.float64)
        self.gen = 1

    def next_gen(self) -> int:
        self.gen += 2
        if self.gen >= 2**31 - 4:
            self.rec[0::4] = 0
            self.gen = 1
        return self.gen


_LOCK = threading.Lock()
_WORKSPACES: OrderedDict[int, _Workspace] = OrderedDict()
_PADDED: OrderedDict[int, tuple[np.ndarray, np.ndarray]] = OrderedDict()
_CACHE_SIZE = 4
_EMPTY_COST = np.zeros(1, dtype=np.float64)


def _workspace(n: int) -> _Workspace:
    ws = _WORKSPACES.get(n)
    if ws is None:
        ws = _Workspace(n)
        _WORKSPACES[n] = ws
        while len(_WORKSPACES) > _CACHE_SIZE:
            _WORKSPACES.popitem(last=False)
    else:
        _WORKSPACES.move_to_end(n)
    return ws


def _padded_free(occupied: np.ndarray) -> np.ndarray:
    """Flat uint8 free mask of ``occupied`` with a blocked one-cell ring (cached by identity)."""
    key = id(occupied)
    hit = _PADDED.get(key)
    if hit is not None and hit[0] is occupied:
        _PADDED.move_to_end(key)
        return hit[1]
    ny, nx = occupied.shape
    free = np.zeros((ny + 2, nx + 2), dtype=np.uint8)
    free[1:-1, 1:-1] = ~occupied
    flat = free.ravel()
    flat.flags.writeable = False
    # keep a reference to `occupied` so its id cannot be reused while cached
    _PADDED[key] = (occupied, flat)
    while len(_PADDED) > _CACHE_SIZE:
        _PADDED.popitem(last=False)
    return flat


# --------------------------------------------------------------------------- public API
def find_path(
    grid: OccupancyGrid,
    start: tuple[int, int],
    goal: tuple[int, int],
    *,
    connectivity: Literal[4, 8] = 8,
    corner_cutting: bool = False,
    cost: np.ndarray | None = None,
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
    then by insertion order. It is not thread-parallel: concurrent calls are serialised.

    Examples
    --------
    >>> import numpy as np
    >>> g = OccupancyGrid(np.zeros((3, 4), bool), resolution=1.0)
    >>> p = find_path(g, (0, 0), (3, 2))
    >>> p.cells.tolist(), round(p.length, 6)
    ([[0, 0], [1, 1], [2, 2], [3, 2]], 3.828427)
    """
    grid = validation.grid(grid)
    if isinstance(connectivity, bool) or connectivity not in (4, 8):
        raise InvalidInputError(f"connectivity must be 4 or 8, got {connectivity!r}")
    sx, sy = validation.cell("start", start, grid)
    gx, gy = validation.cell("goal", goal, grid)
    weighted = cost is not None
    if weighted:
        cflat = np.ascontiguousarray(validation.cell_costs(cost, grid)).ravel()
    else:
        cflat = _EMPTY_COST
    width = grid.nx + 2
    s = (sy + 1) * width + sx + 1
    t = (gy + 1) * width + gx + 1
    # jump point search for the plain shortest path under the Moving AI rules
    jps = connectivity == 8 and not corner_cutting and not weighted
    with _LOCK:
        free = _padded_free(grid.occupied)
        ws = _workspace(free.shape[0])
        gen = ws.next_gen()
        if jps:
            found, path, expanded, gcost, na, nb = _jps_kernel(free, width, s, t, ws.rec, gen)
        else:
            found, path, expanded, gcost, na, nb = _astar_kernel(
                free,
                width,
                s,
                t,
                connectivity == 8,
                bool(corner_cutting),
                weighted,
                cflat,
                ws.rec,
                ws.recf,
                gen,
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
