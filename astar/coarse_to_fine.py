"""Coarse-to-fine A* with a reported suboptimality bound: :class:`CoarseGrid` and its search.

A long search on a fine grid (millions of cells) closes most of the cells between start and
goal. :func:`find_path_coarse_to_fine` searches a coarse view of the grid first and then the
fine grid only in a band around the coarse path; it returns the band path with a proven
bound ``cost / lower_bound`` on its suboptimality, and falls back to the exact search
(:func:`astar.find_path`) when the coarse view has no path, the band holds none, or the
bound exceeds the one asked for.

The coarse view (:class:`CoarseGrid`, built by :func:`build_coarse_grid`) cuts the fine grid
into blocks of ``k x k`` cells (``k = block``; the blocks of the last row and column may
stick out of the grid, their outside cells counting as occupied) and keeps per block:

* ``open_east``, ``open_north``: a free fine cell of the block has a free neighbour across
  its east (north) side. On these side connections an A* over the blocks (a diagonal step
  needs one of its two L-shaped pairs of straight steps), a step between blocks ``A`` and
  ``B`` costing its octile length times ``1 + (C[A] + C[B]) / 2`` with ``C`` = ``cost_mean``,
  the mean fine cost of the block's free cells, finds the coarse path. It passes where
  the fine grid passes, also through passages narrower than a block (requiring whole free
  blocks, as a first version did, lost most doors of an office map); a block whose free
  cells are split may make the band hold no fine path, and then the exact search runs.
* ``free_any``: some fine cell of the block is free (the *optimistic* view), and
  ``near_min``, ``m(B)``: the smallest fine cost over the free cells of the 3 x 3 blocks
  around ``B``. They give the lower bound below.

**Lower bound.** Let a fine path take ``S`` steps ``p_0 .. p_S`` and cut it into chunks of
``k`` steps starting at ``p_0, p_k, .., p_Jk`` (``J = floor(S / k)``). The cells of chunk
``j`` are within ``k`` cells (Chebyshev) of ``p_jk``, so inside the 3 x 3 blocks around its
block ``B_j``; each of its steps costs its length (``>= 1``) times ``1 +`` the mean cost of
two free cells there, so at least ``1 + m(B_j)``, and the chunk at least ``k (1 + m(B_j))``.
``B_{j+1}`` is within one block of ``B_j`` (moving ``k`` cells changes a block index by at
most one) and both hold a free cell. So the blocks ``B_0 .. B_J`` are a walk in the graph of
the ``free_any`` blocks, 8-connected with corner cutting, whose steps cost
``1 + min(m(A), m(B))``, and ``k`` times the walk's cost is at most the cost of the first
``J k`` fine steps. The remaining ``S - J k < k`` steps end at the goal, so ``B_J`` lies
within one block of the goal's block ``G``, and each of them costs ``>= 1 + m(B_J)`` and
moves one cell at most: they cost at least ``r(B_J) (1 + m(B_J))``, with ``r(T)`` the
fewest Chebyshev cells from a cell of ``T`` to the goal. Hence the cost of every fine path,
the optimal one included, is at least

    ``LB = k * min over T within one block of G of (D(T) + r(T) (1 + m(T)) / k)``

where ``D(T)`` is the coarse distance from the start's block to ``T``; and also at least the
octile distance from start to goal (every step costs at least its length). The larger of the
two is the lower bound reported; ``bound = cost(band path) / LB >= cost / optimum``.
The coarse distance runs as an A* on the blocks with the consistent heuristic
``max(0, Chebyshev blocks to G - 1)`` (every coarse step costs at least 1).

The fine search in the band has :func:`astar.find_path`'s step rule and cost model and its
tie rule (among equal ``f`` the larger ``g``), with a sharper heuristic: the larger of the
octile distance and the coarse cost to the goal (a Dijkstra over the band's blocks),
interpolated between block centres and taken 1.1 times, so that the search closes about
two cells per path cell instead of the whole band. It is not admissible, and need not be:
the bound above is computed afterwards. It runs on a copy of the padded free mask in which
only the band's cells are free: the copy lives across searches, all blocked, and a search
sets and clears the band's cells only, so its cost follows the band, not the grid. :meth:`CoarseGrid.update` recomputes the blocks
a change of the fine grid touches and keeps the rest.
"""

from __future__ import annotations

import math
import time
from collections import OrderedDict
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numba import njit

from astar import validation
from astar.errors import InvalidInputError
from astar.grid import OccupancyGrid, check_grid
from astar.search import GridPath, find_path
from astar.search_kernels import heap_pop, heap_push, unroll_path
from astar.search_workspace import LOCK, padded_free, workspace
from astar.weighted_kernel import read_only

__all__ = [
    "CoarseGrid",
    "CoarsePath",
    "build_coarse_grid",
    "find_path_coarse_to_fine",
    "lower_bound",
]

_SQRT2 = math.sqrt(2.0)
Fallback = Literal["no_coarse_path", "band", "bound"]


# --------------------------------------------------------------------------- kernels
@njit(cache=True)
def _reduce_blocks(
    occ, cost, has_cost, k, bx0, bx1, by0, by1, free_any, open_e, open_n, cmean, cmin
):
    """Fill the per-block arrays for blocks ``[by0, by1] x [bx0, bx1]`` (inclusive).

    ``occ`` bool ``(ny, nx)``; ``cost`` float64 ``(ny, nx)`` (read when ``has_cost``). Cells
    outside the grid count as occupied.
    """
    ny, nx = occ.shape
    for by in range(by0, by1 + 1):
        for bx in range(bx0, bx1 + 1):
            n_free = 0
            total = 0.0
            lo = np.inf
            ys, ye = by * k, min((by + 1) * k, ny)
            xs, xe = bx * k, min((bx + 1) * k, nx)
            for y in range(ys, ye):
                for x in range(xs, xe):
                    if not occ[y, x]:
                        n_free += 1
                        c = cost[y, x] if has_cost else 0.0
                        total += c
                        if c < lo:
                            lo = c
            free_any[by, bx] = n_free > 0
            cmean[by, bx] = total / n_free if n_free > 0 else 0.0
            cmin[by, bx] = lo
            east = False
            x = xe - 1
            if xe == (bx + 1) * k and xe < nx:
                for y in range(ys, ye):
                    if not occ[y, x] and not occ[y, x + 1]:
                        east = True
                        break
            open_e[by, bx] = east
            north = False
            y = ye - 1
            if ye == (by + 1) * k and ye < ny:
                for x in range(xs, xe):
                    if not occ[y, x] and not occ[y + 1, x]:
                        north = True
                        break
            open_n[by, bx] = north


@njit(cache=True, inline="always")
def _side_open(open_e, open_n, by, bx, dy, dx):
    """Whether the side of block ``(by, bx)`` towards ``(dy, dx)`` (one of them 0) is open."""
    if dx > 0:
        return open_e[by, bx]
    if dx < 0:
        return open_e[by, bx - 1]
    if dy > 0:
        return open_n[by, bx]
    return open_n[by - 1, bx]


@njit(cache=True, inline="always")
def _block_step(free_any, open_e, open_n, uy, ux, dy, dx):
    """Length of the coarse step from block ``(uy, ux)`` by ``(dy, dx)`` (0: not allowed).

    A straight step needs the shared side open (a free fine cell on each side of it); a
    diagonal step needs one of its two L-shaped pairs of straight steps.
    """
    nby, nbx = free_any.shape
    vy = uy + dy
    vx = ux + dx
    if vy < 0 or vy >= nby or vx < 0 or vx >= nbx or not free_any[vy, vx]:
        return 0.0
    if dy == 0 or dx == 0:
        return 1.0 if _side_open(open_e, open_n, uy, ux, dy, dx) else 0.0
    via_x = free_any[uy, vx] and _side_open(open_e, open_n, uy, ux, 0, dx)
    via_x = via_x and _side_open(open_e, open_n, uy, vx, dy, 0)
    via_y = free_any[vy, ux] and _side_open(open_e, open_n, uy, ux, dy, 0)
    via_y = via_y and _side_open(open_e, open_n, vy, ux, 0, dx)
    return 1.4142135623730951 if (via_x or via_y) else 0.0


@njit(cache=True)
def _coarse_search(free_any, open_e, open_n, cmean, s, g, mask):
    """Search the blocks from flat block ``s``: A* to ``g``, or (``g < 0``) Dijkstra.

    A step between blocks ``A`` and ``B`` (:func:`_block_step`) costs its octile length
    times ``1 + (cmean[A] + cmean[B]) / 2``; the A* heuristic is the octile distance in
    blocks. With ``g < 0`` only blocks with ``mask != 0`` are entered and every one
    reachable is closed. Returns ``(dist, parent)``, flat over the blocks (``inf`` and -1
    where not reached); ``dist[g]`` is finite when ``g`` was reached.
    """
    nby, nbx = free_any.shape
    n = nby * nbx
    sqrt2 = 1.4142135623730951
    dist = np.full(n, np.inf)
    parent = np.full(n, -1, dtype=np.int64)
    closed = np.zeros(n, dtype=np.bool_)
    g_by = g // nbx if g >= 0 else 0
    g_bx = g - g_by * nbx if g >= 0 else 0
    dist[s] = 0.0
    cap = 1024
    hf = np.empty(cap, dtype=np.float64)
    hg = np.empty(cap, dtype=np.float64)
    hn = np.empty(cap, dtype=np.int32)
    hf[0], hg[0], hn[0] = 0.0, 0.0, s
    size = 1
    while size > 0:
        u, _, size = heap_pop(hf, hg, hn, size)
        if closed[u]:
            continue
        closed[u] = True
        if u == g:
            break
        uy = u // nbx
        ux = u - uy * nbx
        du = dist[u]
        cu = cmean[uy, ux]
        for dy in range(-1, 2):
            for dx in range(-1, 2):
                if dy == 0 and dx == 0:
                    continue
                step = _block_step(free_any, open_e, open_n, uy, ux, dy, dx)
                if step == 0.0:
                    continue
                vy = uy + dy
                vx = ux + dx
                v = vy * nbx + vx
                if closed[v] or (g < 0 and mask[vy, vx] == 0):
                    continue
                dv = du + step * (1.0 + 0.5 * (cu + cmean[vy, vx]))
                if dv < dist[v]:
                    dist[v] = dv
                    parent[v] = u
                    hv = 0.0
                    if g >= 0:
                        ay = abs(vy - g_by)
                        ax = abs(vx - g_bx)
                        hv = max(ax, ay) - min(ax, ay) + min(ax, ay) * sqrt2
                    hf, hg, hn, size, cap = heap_push(hf, hg, hn, size, cap, dv + hv, dv, v)
    return dist, parent


@njit(cache=True)
def _trace(parent, s, g):
    """Return the flat indices from ``s`` to ``g`` along ``parent``."""
    m = 1
    v = g
    while v != s:
        v = parent[v]
        m += 1
    out = np.empty(m, dtype=np.int64)
    v = g
    for i in range(m - 1, -1, -1):
        out[i] = v
        v = parent[v]
    return out


@njit(cache=True)
def _band_kernel(free, width, start, goal, cost, has_cost, rec, recf, gen, field, k):
    """Run A* on the padded ``free`` mask, the heuristic read from ``field`` (block centres).

    The step rule and cost are :func:`astar.find_path`'s (8-connected, no corner cutting,
    ``length (1 + (cost[a] + cost[b]) / 2)``); ``field`` float64 ``(nby, nbx)`` is an
    estimate of the cost from each block's centre to the goal (``inf`` outside the band).
    The heuristic of a cell is the larger of the octile distance and the bilinear
    interpolation of ``field`` at the cell (the own block's value where a neighbour is
    ``inf``); it need not be admissible (the caller bounds the result: the field is the
    coarse cost to the goal times :data:`_GREED`). Among equal ``f``
    the larger ``g`` is expanded first. Returns ``(found, path, expanded, cost)``.
    """
    sqrt2 = 1.4142135623730951
    w = width
    gx = goal % w - 1
    gy = goal // w - 1
    nby, nbx = field.shape
    ddx = np.array([1, -1, 0, 0, 1, -1, 1, -1], dtype=np.int64)
    ddy = np.array([0, 0, 1, -1, 1, 1, -1, -1], dtype=np.int64)
    closed = gen + 1
    rec[4 * start] = gen
    rec[4 * start + 1] = -1
    recf[2 * start + 1] = 0.0
    cap = 1024
    hf = np.empty(cap, dtype=np.float64)
    hg = np.empty(cap, dtype=np.float64)
    hn = np.empty(cap, dtype=np.int32)
    hf[0], hg[0], hn[0] = 0.0, 0.0, start
    size = 1
    expanded = 0
    found = False
    fr = np.zeros(4, dtype=np.bool_)
    while size > 0:
        u, _, size = heap_pop(hf, hg, hn, size)
        if rec[4 * u] == closed:
            continue
        rec[4 * u] = closed
        expanded += 1
        if u == goal:
            found = True
            break
        uy = u // w
        gu = recf[2 * u + 1]
        cu = cost[u - 2 * uy - (w - 1)] if has_cost else 0.0
        for q in range(4):
            fr[q] = free[u + ddy[q] * w + ddx[q]] != 0
        for q in range(8):
            dx = ddx[q]
            dy = ddy[q]
            v = u + dy * w + dx
            if q < 4:
                if not fr[q]:
                    continue
            else:
                if free[v] == 0 or not fr[0 if dx > 0 else 1] or not fr[2 if dy > 0 else 3]:
                    continue
            if rec[4 * v] == closed:
                continue
            vy = uy + dy
            step = 1.0 if q < 4 else sqrt2
            cv = cost[v - 2 * vy - (w - 1)] if has_cost else 0.0
            gnew = gu + step * (1.0 + 0.5 * (cu + cv))
            if rec[4 * v] == gen and gnew >= recf[2 * v + 1]:
                continue
            recf[2 * v + 1] = gnew
            rec[4 * v] = gen
            rec[4 * v + 1] = u
            cx = v % w - 1
            cy = vy - 1
            ax = abs(cx - gx)
            ay = abs(cy - gy)
            hv = max(ax, ay) - min(ax, ay) + min(ax, ay) * sqrt2
            fx = (cx + 0.5) / k - 0.5
            fy = (cy + 0.5) / k - 0.5
            bx0 = min(max(int(np.floor(fx)), 0), nbx - 1)
            by0 = min(max(int(np.floor(fy)), 0), nby - 1)
            bx1 = min(bx0 + 1, nbx - 1)
            by1 = min(by0 + 1, nby - 1)
            tx = min(max(fx - bx0, 0.0), 1.0)
            ty = min(max(fy - by0, 0.0), 1.0)
            f00 = field[by0, bx0]
            f01 = field[by0, bx1]
            f10 = field[by1, bx0]
            f11 = field[by1, bx1]
            if f00 < np.inf and f01 < np.inf and f10 < np.inf and f11 < np.inf:
                est = (1 - ty) * ((1 - tx) * f00 + tx * f01) + ty * ((1 - tx) * f10 + tx * f11)
            else:
                est = field[cy // k, cx // k]
            if est > hv and est < np.inf:
                hv = est
            hf, hg, hn, size, cap = heap_push(hf, hg, hn, size, cap, gnew + hv, gnew, v)
    if not found:
        return False, np.empty(0, dtype=np.int64), expanded, 0.0
    return True, unroll_path(rec, start, goal), expanded, recf[2 * goal + 1]


@njit(cache=True)
def _near_min(cmin, by0, by1, bx0, bx1, out):
    """``out[B] = min of cmin over the 3 x 3 blocks around B``, for B in the given range."""
    nby, nbx = cmin.shape
    for by in range(by0, by1 + 1):
        for bx in range(bx0, bx1 + 1):
            m = np.inf
            for y in range(max(0, by - 1), min(nby, by + 2)):
                for x in range(max(0, bx - 1), min(nbx, bx + 2)):
                    if cmin[y, x] < m:
                        m = cmin[y, x]
            out[by, bx] = m


@njit(cache=True)
def _paint_band(dst, src, width, ny, nx, k, blocks_y, blocks_x, clear):
    """Copy (or, with ``clear``, zero) the padded free mask on the fine cells of the blocks."""
    for i in range(blocks_y.shape[0]):
        y0 = blocks_y[i] * k
        x0 = blocks_x[i] * k
        y1 = min(y0 + k, ny)
        x1 = min(x0 + k, nx)
        for y in range(y0, y1):
            row = (y + 1) * width + 1
            for x in range(x0, x1):
                dst[row + x] = 0 if clear else src[row + x]


@njit(cache=True)
def _dilate_path(path, nby, nbx, d, band):
    """Mark in ``band`` (uint8 ``(nby, nbx)``) the blocks within ``d`` of the path's blocks."""
    for i in range(path.shape[0]):
        by = path[i] // nbx
        bx = path[i] % nbx
        for y in range(max(0, by - d), min(nby, by + d + 1)):
            for x in range(max(0, bx - d), min(nbx, bx + d + 1)):
                band[y, x] = 1


@njit(cache=True)
def _coarse_distance(free_any, near_min, s_by, s_bx, g_by, g_bx, rem):
    """Least walk cost ``min_T D(T) + rem_T`` from block ``s`` to a block ``T`` next to ``g``.

    ``free_any`` bool ``(nby, nbx)``, ``near_min`` float64 ``(nby, nbx)``; steps go to the 8
    neighbours (corner cutting allowed) among the ``free_any`` blocks and cost
    ``1 + min(m(A), m(B))``; ``rem`` float64 ``(3, 3)``: the extra cost of ending at the
    block ``g + (dy - 1, dx - 1)`` (``inf``: not an end). A* with the heuristic
    ``max(0, Chebyshev distance to g - 1)``. Returns ``(distance, expanded)``; ``inf``
    when no end is reachable.
    """
    nby, nbx = free_any.shape
    n = nby * nbx
    dist = np.full(n, np.inf)
    closed = np.zeros(n, dtype=np.bool_)
    s = s_by * nbx + s_bx
    dist[s] = 0.0
    h0 = max(0, max(abs(s_by - g_by), abs(s_bx - g_bx)) - 1)
    cap = 1024
    hf = np.empty(cap, dtype=np.float64)
    hg = np.empty(cap, dtype=np.float64)
    hn = np.empty(cap, dtype=np.int32)
    hf[0], hg[0], hn[0] = float(h0), 0.0, s
    size = 1
    best = np.inf
    expanded = 0
    while size > 0:
        u, f, size = heap_pop(hf, hg, hn, size)
        if f >= best:
            break
        if closed[u]:
            continue
        closed[u] = True
        expanded += 1
        uy = u // nbx
        ux = u - uy * nbx
        du = dist[u]
        ey = uy - g_by + 1
        ex = ux - g_bx + 1
        if 0 <= ey <= 2 and 0 <= ex <= 2:
            end = du + rem[ey, ex]
            if end < best:
                best = end
        mu = near_min[uy, ux]
        for dy in range(-1, 2):
            vy = uy + dy
            if vy < 0 or vy >= nby:
                continue
            for dx in range(-1, 2):
                vx = ux + dx
                if (dy == 0 and dx == 0) or vx < 0 or vx >= nbx or not free_any[vy, vx]:
                    continue
                v = vy * nbx + vx
                if closed[v]:
                    continue
                mv = near_min[vy, vx]
                dv = du + 1.0 + (mu if mu < mv else mv)
                if dv < dist[v]:
                    dist[v] = dv
                    hv = max(0, max(abs(vy - g_by), abs(vx - g_bx)) - 1)
                    hf, hg, hn, size, cap = heap_push(hf, hg, hn, size, cap, dv + hv, dv, v)
    return best, expanded


# --------------------------------------------------------------------------- the coarse view
@dataclass(frozen=True, slots=True, eq=False)
class CoarseGrid:
    """Blocks of ``block x block`` fine cells of a grid and cost (module docstring).

    Build with :func:`build_coarse_grid`; the constructor does not check its inputs.

    Attributes
    ----------
    grid : OccupancyGrid
        The fine grid searched (usually inflated), shape ``(ny, nx)``.
    cost : ndarray of float64, shape (ny, nx), or None
        The fine per-cell cost (read-only), or ``None`` for the plain shortest path.
    block : int
        ``k``, fine cells per block side (``>= 1``).
    free_any : ndarray of bool, shape (nby, nbx)
        Some fine cell of the block is free (``nby = ceil(ny / k)``, ``nbx = ceil(nx / k)``).
    open_east, open_north : ndarray of bool, shape (nby, nbx)
        The block's east (north) side is open: some free fine cell of the block has a free
        neighbour across it in the next block east (north).
    cost_mean : ndarray of float64, shape (nby, nbx)
        Mean fine cost of the block's free cells (0 without a cost or free cell).
    cost_min : ndarray of float64, shape (nby, nbx)
        Smallest fine cost of the block's free cells (``inf`` without a free cell).
    near_min : ndarray of float64, shape (nby, nbx)
        ``m(B)``: the smallest ``cost_min`` over the 3 x 3 blocks around each block.
    """

    grid: OccupancyGrid
    cost: np.ndarray | None
    block: int
    free_any: np.ndarray
    open_east: np.ndarray
    open_north: np.ndarray
    cost_mean: np.ndarray
    cost_min: np.ndarray
    near_min: np.ndarray

    def __post_init__(self) -> None:
        for name in _BLOCK_ARRAYS + ("near_min",):
            getattr(self, name).flags.writeable = False

    @property
    def shape(self) -> tuple[int, int]:
        """``(nby, nbx)``: the number of block rows and columns."""
        return self.free_any.shape  # type: ignore[return-value]

    def block_of(self, cell: tuple[int, int]) -> tuple[int, int]:
        """Return the block ``(bx, by)`` holding fine cell ``(ix, iy)``."""
        return (int(cell[0]) // self.block, int(cell[1]) // self.block)

    def update(
        self, grid: OccupancyGrid, cost: np.ndarray | None, window: tuple[int, int, int, int]
    ) -> CoarseGrid:
        """Return the view of a changed grid, recomputing only the blocks the change touches.

        Parameters
        ----------
        grid : OccupancyGrid
            The new fine grid, of this view's shape; equal to the old one outside ``window``.
        cost : array_like of float, shape (ny, nx), or None
            The new fine cost (``None`` exactly when this view has none); equal to the old
            one outside ``window``.
        window : tuple of int
            ``(x0, x1, y0, y1)``, fine cells, inclusive: where grid or cost may differ.

        Returns
        -------
        CoarseGrid
            The blocks meeting ``window`` recomputed (``near_min`` one block further), the
            others copied from this view: equal to :func:`build_coarse_grid` on the new grid
            when nothing changed outside ``window``.

        Raises
        ------
        InvalidInputError
            ``grid`` of another shape, a cost given or left out unlike this view's, or a
            ``window`` that is not four integers inside the grid with ``x0 <= x1``,
            ``y0 <= y1``.
        """
        grid = check_grid(grid)
        if grid.shape != self.grid.shape:
            raise InvalidInputError(
                f"grid must keep the coarse view's shape {self.grid.shape}, got {grid.shape}"
            )
        if (cost is None) != (self.cost is None):
            raise InvalidInputError(
                "cost must be given exactly when the coarse view was built with one "
                f"(built {'with' if self.cost is not None else 'without'} a cost)"
            )
        c = None if cost is None else _read_only_costs(cost, grid)
        try:
            x0, x1, y0, y1 = (int(v) for v in window)
        except (TypeError, ValueError) as exc:
            raise InvalidInputError(
                f"window must be (x0, x1, y0, y1) cells, got {window!r}"
            ) from exc
        ny, nx = grid.shape
        if not (0 <= x0 <= x1 < nx and 0 <= y0 <= y1 < ny):
            raise InvalidInputError(
                f"window (x0, x1, y0, y1) = {(x0, x1, y0, y1)} must satisfy "
                f"0 <= x0 <= x1 < {nx} and 0 <= y0 <= y1 < {ny}"
            )
        k = self.block
        arrays = [np.array(getattr(self, name)) for name in _BLOCK_ARRAYS]
        # a block's east and north sides read the first fine column and row of the next
        # block: the blocks west and south of the window are recomputed too
        bx0, bx1 = max(0, x0 // k - 1), x1 // k
        by0, by1 = max(0, y0 // k - 1), y1 // k
        _reduce_blocks(
            grid.occupied, _EMPTY2 if c is None else c, c is not None, k, bx0, bx1, by0, by1,
            *arrays,
        )  # fmt: skip
        near = np.array(self.near_min)
        nby, nbx = near.shape
        _near_min(
            arrays[4], max(0, by0 - 1), min(nby - 1, by1 + 1), max(0, bx0 - 1),
            min(nbx - 1, bx1 + 1), near,
        )  # fmt: skip
        return CoarseGrid(grid, c, k, *arrays, near)


_EMPTY2 = np.zeros((1, 1))
_BLOCK_ARRAYS = ("free_any", "open_east", "open_north", "cost_mean", "cost_min")


def _read_only_costs(cost: object, grid: OccupancyGrid) -> np.ndarray:
    """Return ``cost`` checked, as a read-only C-contiguous float64 array (a copy if needed).

    A read-only C-contiguous float64 array is kept as is (no copy); anything else is copied.
    """
    c = validation.cell_costs(cost, grid)
    if c.flags.writeable or not c.flags.c_contiguous:
        c = np.array(c, dtype=np.float64, order="C")
        c.flags.writeable = False
    return c


def build_coarse_grid(
    grid: OccupancyGrid, block: int, cost: np.ndarray | None = None
) -> CoarseGrid:
    """Cut a grid (and its cost) into blocks for :func:`find_path_coarse_to_fine`.

    Parameters
    ----------
    grid : OccupancyGrid
        The fine grid to search, shape ``(ny, nx)`` (usually inflated).
    block : int
        ``k``, fine cells per block side, ``>= 1``.
    cost : array_like of float, shape (ny, nx), optional
        Per-cell cost as for :func:`astar.find_path` (finite, ``>= 0``); ``None``: the plain
        shortest path. A read-only C-contiguous float64 array is kept as is (no copy);
        anything else is copied.

    Returns
    -------
    CoarseGrid
        ``ceil(ny / k) x ceil(nx / k)`` blocks.

    Raises
    ------
    InvalidInputError
        ``grid`` not an :class:`OccupancyGrid`, ``block`` not an integer ``>= 1``, or a
        ``cost`` of another shape or with negative or non-finite values.

    Examples
    --------
    >>> import numpy as np
    >>> g = OccupancyGrid(np.zeros((5, 8), bool), resolution=0.1)
    >>> build_coarse_grid(g, 4).shape
    (2, 2)
    """
    grid = check_grid(grid)
    if isinstance(block, bool) or not isinstance(block, (int, np.integer)) or block < 1:
        raise InvalidInputError(f"block must be an integer >= 1 (cells per side), got {block!r}")
    k = int(block)
    c = None if cost is None else _read_only_costs(cost, grid)
    ny, nx = grid.shape
    nby, nbx = -(-ny // k), -(-nx // k)
    arrays = [np.zeros((nby, nbx), dtype=bool) for _ in range(3)]
    arrays += [np.zeros((nby, nbx)), np.zeros((nby, nbx))]
    _reduce_blocks(
        grid.occupied, _EMPTY2 if c is None else c, c is not None, k, 0, nbx - 1, 0, nby - 1,
        *arrays,
    )  # fmt: skip
    near = np.zeros((nby, nbx))
    _near_min(arrays[4], 0, nby - 1, 0, nbx - 1, near)
    return CoarseGrid(grid, c, k, *arrays, near)


# --------------------------------------------------------------------------- the search
@dataclass(frozen=True, slots=True, eq=False)
class CoarsePath:
    """What :func:`find_path_coarse_to_fine` found, with its suboptimality bound.

    Attributes
    ----------
    path : GridPath
        The fine path (its ``cost`` is the cost minimised; ``expanded`` counts the fine
        search's closed cells, of the last fine search run).
    lower_bound : float
        A proven lower bound of the optimal cost (module docstring); the path's own cost
        after an exact search.
    bound : float
        ``path.cost / lower_bound`` (``>= 1``; 1 after an exact search): the path costs at most
        ``bound`` times the optimum.
    mode : {"coarse", "exact"}
        ``"coarse"``: the band path; ``"exact"``: :func:`astar.find_path` ran.
    fallback : {None, "no_coarse_path", "band", "bound"}
        Why the exact search ran: the conservative coarse view had no path (a passage
        narrower than a block), the band held no fine path, or the bound exceeded
        ``max_bound``; ``None`` when the band path was kept.
    band_bound : float
        The band path's bound when it was computed (``nan`` otherwise): after a
        ``"bound"`` fallback, the bound that was refused.
    block : int
        Fine cells per block side.
    band_cells : int
        Fine cells of the band (0 when no band was searched).
    times_s : dict of str to float
        Wall times (s) of ``"coarse"``, ``"band"``, ``"lower_bound"`` and ``"exact"``
        (those that ran).
    """

    path: GridPath
    lower_bound: float
    bound: float
    mode: Literal["coarse", "exact"]
    fallback: Fallback | None
    band_bound: float
    block: int
    band_cells: int
    times_s: dict[str, float]


def find_path_coarse_to_fine(
    coarse: CoarseGrid,
    start: tuple[int, int],
    goal: tuple[int, int],
    *,
    max_bound: float = math.inf,
    band_blocks: int = 2,
) -> CoarsePath:
    """Cheapest path up to a proven factor: a coarse A*, then A* in a band around its path.

    Parameters
    ----------
    coarse : CoarseGrid
        The blocked view of the grid and cost to search (:func:`build_coarse_grid`).
    start, goal : tuple of int
        Fine cells ``(ix, iy)``, inside the grid and free.
    max_bound : float, optional
        The largest suboptimality accepted, ``>= 1`` (default ``inf``: any). When the band
        path's proven bound exceeds it, the exact search runs instead, so the returned path
        costs at most ``max_bound`` times the optimum.
    band_blocks : int, optional
        Blocks added on every side of the coarse path's blocks to form the band (``>= 0``,
        default 2).

    Returns
    -------
    CoarsePath
        The path, its lower bound and bound, the mode run and any fallback.

    Raises
    ------
    InvalidInputError
        ``coarse`` not a :class:`CoarseGrid`; ``start`` or ``goal`` outside the grid or
        blocked; ``max_bound`` not a number ``>= 1``; ``band_blocks`` not an integer ``>= 0``.
    NoPathError
        No path joins ``start`` and ``goal`` (from the exact search).

    Notes
    -----
    The steps are 8-connected without corner cutting, as :func:`astar.find_path`'s defaults,
    with ``cost=coarse.cost``; the exact fallback is that call.
    """
    if not isinstance(coarse, CoarseGrid):
        raise InvalidInputError(
            f"coarse must be an astar.CoarseGrid (astar.build_coarse_grid), got "
            f"{type(coarse).__name__}"
        )
    grid = coarse.grid
    sx, sy = validation.cell("start", start, grid)
    gx, gy = validation.cell("goal", goal, grid)
    mb = max_bound
    if isinstance(mb, bool) or not isinstance(mb, (int, float, np.integer, np.floating)):
        raise InvalidInputError(f"max_bound must be a number >= 1, got {mb!r}")
    mb = float(mb)
    if not mb >= 1.0:  # NaN too
        raise InvalidInputError(
            f"max_bound must be >= 1 (a path costs at least the optimum), got {mb!r}"
        )
    if isinstance(band_blocks, bool) or not isinstance(band_blocks, (int, np.integer)):
        raise InvalidInputError(f"band_blocks must be an integer >= 0, got {band_blocks!r}")
    if band_blocks < 0:
        raise InvalidInputError(f"band_blocks must be an integer >= 0, got {band_blocks!r}")
    k = coarse.block
    times: dict[str, float] = {}
    t0 = time.perf_counter()
    nby, nbx = coarse.shape
    sb = (sy // k, sx // k)
    gb = (gy // k, gx // k)
    s_blk, g_blk = sb[0] * nbx + sb[1], gb[0] * nbx + gb[1]
    arrays = (coarse.free_any, coarse.open_east, coarse.open_north, coarse.cost_mean)
    dist, parent = _coarse_search(*arrays, s_blk, g_blk, _NO_MASK)
    times["coarse"] = time.perf_counter() - t0
    if not dist[g_blk] < math.inf:
        return _exact(coarse, (sx, sy), (gx, gy), "no_coarse_path", math.nan, 0, times)
    cpath = _trace(parent, s_blk, g_blk)
    band = np.zeros((nby, nbx), dtype=np.uint8)
    _dilate_path(cpath, nby, nbx, int(band_blocks), band)
    bys, bxs = np.nonzero(band)
    t0 = time.perf_counter()
    # the heuristic of the band search: the coarse cost from each band block to the goal
    to_goal, _ = _coarse_search(*arrays, g_blk, -1, band)
    field = (_GREED * k * to_goal).reshape(nby, nbx)
    path = _band_search(coarse, (sx, sy), (gx, gy), bys, bxs, field)
    times["band"] = time.perf_counter() - t0
    n_band = int(bys.size) * k * k
    if path is None:
        return _exact(coarse, (sx, sy), (gx, gy), "band", math.nan, n_band, times)
    t0 = time.perf_counter()
    lb = lower_bound(coarse, (sx, sy), (gx, gy))
    times["lower_bound"] = time.perf_counter() - t0
    bound = max(1.0, path.cost / lb) if lb > 0.0 else (1.0 if path.cost == 0.0 else math.inf)
    if bound > mb:
        return _exact(coarse, (sx, sy), (gx, gy), "bound", bound, n_band, times)
    return CoarsePath(path, lb, bound, "coarse", None, bound, k, n_band, times)


_NO_LM = np.zeros((0, 1))
#: The band search's heuristic is the coarse cost to the goal times this: on the willow map
#: split to 1.7 cm it cut the closed cells from about 13 to 2 per path cell (1.0 -> 1.1) and
#: left the cost within 1 % of the optimum; 1.25 cost 4 %. The bound is checked afterwards.
_GREED = 1.1
_NO_MASK = np.zeros((1, 1), dtype=np.uint8)
_NO_LG = np.zeros(0)
_BANDS: OrderedDict[int, np.ndarray] = OrderedDict()


def _band_buffer(n: int) -> np.ndarray:
    """Return an all-blocked padded mask of ``n`` cells, kept across searches (under LOCK)."""
    buf = _BANDS.get(n)
    if buf is None:
        buf = np.zeros(n, dtype=np.uint8)
        _BANDS[n] = buf
        while len(_BANDS) > 2:
            _BANDS.popitem(last=False)
    else:
        _BANDS.move_to_end(n)
    return buf


def _band_search(
    coarse: CoarseGrid,
    start: tuple[int, int],
    goal: tuple[int, int],
    bys: np.ndarray,
    bxs: np.ndarray,
    field: np.ndarray,
) -> GridPath | None:
    """Run the fine A* in the band's blocks (``None`` when the band holds no path)."""
    grid = coarse.grid
    ny, nx = grid.shape
    width = nx + 2
    k = coarse.block
    s = (start[1] + 1) * width + start[0] + 1
    t = (goal[1] + 1) * width + goal[0] + 1
    with LOCK:
        src = padded_free(grid.occupied)
        buf = _band_buffer(src.shape[0])
        _paint_band(buf, src, width, ny, nx, k, bys, bxs, False)
        try:
            ws = workspace(src.shape[0])
            has_cost = coarse.cost is not None
            found, path, expanded, gcost = _band_kernel(
                read_only(buf), width, s, t, coarse.cost.ravel() if has_cost else _NO_LG,
                has_cost, ws.rec, ws.recf, ws.next_gen(), field, k,
            )  # fmt: skip
        finally:
            _paint_band(buf, src, width, ny, nx, k, bys, bxs, True)
    if not found:
        return None
    iy, ix = np.divmod(path, width)
    cells = np.stack([ix - 1, iy - 1], axis=1)
    steps = np.abs(np.diff(cells, axis=0)).sum(axis=1)
    nb = int(np.count_nonzero(steps == 2))
    na = int(steps.shape[0] - nb)
    length = na + nb * _SQRT2
    return GridPath(cells, length, float(gcost) if coarse.cost is not None else length, expanded)


def lower_bound(coarse: CoarseGrid, start: tuple[int, int], goal: tuple[int, int]) -> float:
    """Return a lower bound of the cheapest fine path's cost from ``start`` to ``goal``.

    The larger of the octile distance and ``k`` times the coarse distance of the module
    docstring (``inf`` when the optimistic view joins no block next to the goal's: then no
    fine path exists). Cells are ``(ix, iy)``, assumed valid (not checked).
    """
    sx, sy = start
    gx, gy = goal
    k = coarse.block
    ax, ay = abs(sx - gx), abs(sy - gy)
    octile = max(ax, ay) - min(ax, ay) + min(ax, ay) * _SQRT2
    gby, gbx = gy // k, gx // k
    nby, nbx = coarse.shape
    rem = np.full((3, 3), np.inf)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            by, bx = gby + dy, gbx + dx
            if not (0 <= by < nby and 0 <= bx < nbx) or not coarse.free_any[by, bx]:
                continue
            # fewest Chebyshev cells from a cell of block (bx, by) to the goal cell
            rx = max(0, bx * k - gx, gx - (bx * k + k - 1))
            ry = max(0, by * k - gy, gy - (by * k + k - 1))
            rem[dy + 1, dx + 1] = max(rx, ry) * (1.0 + coarse.near_min[by, bx]) / k
    d, _ = _coarse_distance(coarse.free_any, coarse.near_min, sy // k, sx // k, gby, gbx, rem)
    return max(octile, k * d)


def _exact(
    coarse: CoarseGrid,
    start: tuple[int, int],
    goal: tuple[int, int],
    why: Fallback,
    band_bound: float,
    band_cells: int,
    times: dict[str, float],
) -> CoarsePath:
    t0 = time.perf_counter()
    try:
        path = find_path(coarse.grid, start, goal, cost=coarse.cost)
    finally:
        times["exact"] = time.perf_counter() - t0
    return CoarsePath(
        path, path.cost, 1.0, "exact", why, band_bound, coarse.block, band_cells, times
    )
