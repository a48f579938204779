"""Independent references shared by the tests (a helper module, not a test module).

Every brute-force, dense-sampling, Dijkstra or third-party reference a test compares the
library with lives here, so that a reader finds them in one place and no test module
imports another. Each is deliberately naive (all pairs, plain Dijkstra, dense samples,
enumeration) or delegates to an independent implementation (scipy, ruckig), so that it is
obviously right and shares no code with the library it checks; where a reference reads a
library value (a curve's evaluation, a polygon's half-planes), its docstring says which
and why that does not make it circular. Units are in each function's docstring: grids are
:class:`astar.OccupancyGrid` values (``occupied[iy, ix]``, row 0 at the bottom) or plain
boolean arrays in cells; cells are ``(ix, iy)``.
"""

from __future__ import annotations

import heapq
import itertools
import math
from typing import TYPE_CHECKING, Any

import numpy as np
import pytest
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

import astar

if TYPE_CHECKING:
    from trajopt.geometry._bspline import BSplineCurve
    from trajopt.robot._footprint import Footprint
    from trajopt.robot._robot import Robot

__all__ = [
    "INFLATION_TOL",
    "boundary_samples",
    "brute_distance",
    "brute_force_schoenberg_whitney",
    "brute_inflate",
    "brute_inflate_square",
    "brute_polygon_clearance",
    "brute_squared",
    "cell_square_clearance",
    "chapter_avoidance",
    "check_path",
    "closed_form_duration",
    "control_point_swing",
    "dense_kappa_max_per_interval",
    "dijkstra_costs",
    "dijkstra_path",
    "footprint_collides",
    "footprint_points",
    "grid_path_cost",
    "inside_convex",
    "integrate_jerk",
    "interior_samples",
    "legal_step",
    "nav2_inflation",
    "nav2_translate",
    "point_square_distance",
    "polyline_samples",
    "reachable_cells",
    "ruckig_profile",
    "ruckig_rest_to_rest_duration",
    "sampled_rect_clearance",
    "scipy_distance_cells",
    "square_clearance",
    "step_graph",
    "three_point_curvature",
    "turn_limits_by_hand",
    "v_limit_by_hand",
]

SQRT2 = math.sqrt(2.0)


# ------------------------------------------------------------------ clearance to squares
def square_clearance(
    grid: astar.OccupancyGrid, pts: np.ndarray, reach: float = math.inf
) -> np.ndarray:
    """Distance (m) from each point to the nearest occupied square or the map's outside.

    Brute force over the occupied cells that touch a free cell (the nearest point of the
    occupied set to a point in free space lies on such a cell); a point inside an occupied
    cell has clearance 0. With a finite ``reach`` (m), each chunk of points only looks at
    the cells within ``reach`` of the chunk's bounding box: values ``<= reach`` are exact,
    larger ones are only known to exceed ``reach``.

    Parameters
    ----------
    grid : astar.OccupancyGrid
    pts : array_like, shape (n, 2)
        World points (m).
    reach : float
        Search reach (m); ``inf`` (default) for exact values everywhere.

    Returns
    -------
    ndarray, shape (n,)
        Clearance (m), 0 inside an occupied cell or outside the map.
    """
    pts = np.asarray(pts, dtype=float).reshape(-1, 2)
    if not math.isinf(reach):
        return _square_clearance_within(grid, pts, reach)
    # exact everywhere: a value found within a reach is exact (the nearest square is one of
    # those looked at), so look near first and further only for the points not settled yet
    out = np.empty(len(pts))
    todo = np.arange(len(pts))
    step = 8.0 * grid.resolution
    far = math.hypot(grid.width, grid.height)
    while len(todo):
        if step >= far:
            out[todo] = _square_clearance_within(grid, pts[todo], math.inf)
            break
        got = _square_clearance_within(grid, pts[todo], step)
        done = got <= step
        out[todo[done]] = got[done]
        todo = todo[~done]
        step *= 4.0
    return out


def _square_clearance_within(grid: astar.OccupancyGrid, pts: np.ndarray, reach: float):
    """:func:`square_clearance` with a reach, by brute force over the cells within it."""
    res = grid.resolution
    ox, oy = grid.origin
    occ = grid.occupied
    padded = np.pad(occ, 1, constant_values=True)
    free_nb = np.zeros_like(occ)
    for dy, dx in ((0, 1), (2, 1), (1, 0), (1, 2)):
        free_nb |= ~padded[dy : dy + occ.shape[0], dx : dx + occ.shape[1]]
    iy, ix = np.nonzero(occ & free_nb)
    x0, y0 = ox + ix * res, oy + iy * res
    px, py = pts[:, 0], pts[:, 1]
    edge = np.minimum.reduce([px - ox, py - oy, ox + grid.width - px, oy + grid.height - py])
    out = np.maximum(edge, 0.0)
    chunk = 256
    for k in range(0, len(pts), chunk):
        qx, qy = px[k : k + chunk], py[k : k + chunk]
        near = (
            (x0 + res >= qx.min() - reach)
            & (x0 <= qx.max() + reach)
            & (y0 + res >= qy.min() - reach)
            & (y0 <= qy.max() + reach)
        )
        if not near.any():
            continue
        cx, cy = x0[near], y0[near]
        dx = np.maximum(0.0, np.maximum(cx - qx[:, None], qx[:, None] - (cx + res)))
        dy = np.maximum(0.0, np.maximum(cy - qy[:, None], qy[:, None] - (cy + res)))
        out[k : k + chunk] = np.minimum(out[k : k + chunk], np.hypot(dx, dy).min(axis=1))
    fx = np.floor((px - ox) / res)
    fy = np.floor((py - oy) / res)
    inside = (fx >= 0) & (fx < grid.nx) & (fy >= 0) & (fy < grid.ny)  # False for NaN
    on_obstacle = np.zeros(len(pts), bool)
    on_obstacle[inside] = occ[fy[inside].astype(np.int64), fx[inside].astype(np.int64)]
    out[on_obstacle] = 0.0
    return out


def polyline_samples(pts: np.ndarray, spacing: float) -> np.ndarray:
    """Points every ``spacing`` m (at most) along the polyline ``pts`` (m, shape (n, 2)),
    both ends included; shape (m, 2)."""
    dense = [pts[:1]]
    for a, b in zip(pts[:-1], pts[1:], strict=True):
        n = max(1, int(np.ceil(np.hypot(*(b - a)) / spacing)))
        dense.append(a + (b - a) * (np.arange(1, n + 1) / n)[:, None])
    return np.vstack(dense)


# ------------------------------------------------------------------ inflation and search
def brute_inflate_square(occ: np.ndarray, radius_cells: float) -> np.ndarray:
    """Blocked where the cell centre is closer than ``radius_cells`` to an occupied cell
    taken as a unit square, or to the outside of the map (brute force over all pairs)."""
    ny, nx = occ.shape
    pad = int(math.ceil(radius_cells)) + 1
    big = np.ones((ny + 2 * pad, nx + 2 * pad), bool)
    big[pad:-pad, pad:-pad] = occ
    oy, ox = np.nonzero(big)
    oy = oy - pad
    ox = ox - pad
    out = np.zeros_like(occ)
    for iy in range(ny):
        for ix in range(nx):
            cx, cy = ix + 0.5, iy + 0.5
            dx = np.maximum(0, np.maximum(ox - cx, cx - (ox + 1)))
            dy = np.maximum(0, np.maximum(oy - cy, cy - (oy + 1)))
            out[iy, ix] = bool(np.any(np.hypot(dx, dy) < radius_cells))
    return out


def dijkstra_path(free: np.ndarray, start: tuple[int, int], goal: tuple[int, int]) -> np.ndarray:
    """Octile shortest path (no corner cutting) by plain Dijkstra; cells ``(ix, iy)``."""
    ny, nx = free.shape
    dist = {start: 0.0}
    prev: dict = {}
    pq = [(0.0, start)]
    moves = [(dx, dy) for dx in (-1, 0, 1) for dy in (-1, 0, 1) if dx or dy]
    while pq:
        d, c = heapq.heappop(pq)
        if c == goal:
            break
        if d > dist.get(c, math.inf):
            continue
        for dx, dy in moves:
            x, y = c[0] + dx, c[1] + dy
            if not (0 <= x < nx and 0 <= y < ny) or not free[y, x]:
                continue
            if dx and dy and not (free[c[1], x] and free[y, c[0]]):
                continue
            nd = d + (math.sqrt(2) if dx and dy else 1.0)
            if nd < dist.get((x, y), math.inf) - 1e-12:
                dist[(x, y)] = nd
                prev[(x, y)] = c
                heapq.heappush(pq, (nd, (x, y)))
    if goal not in dist:
        raise ValueError("unreachable")
    out = [goal]
    while out[-1] != start:
        out.append(prev[out[-1]])
    return np.array(out[::-1], dtype=np.int64)


# ------------------------------------------------------------ scipy's distance transform
def scipy_distance_cells(occ: np.ndarray, metric: str) -> np.ndarray:
    """Distance in cells from each cell centre to the nearest occupied cell, by scipy.

    ``"centre"``: :func:`scipy.ndimage.distance_transform_edt` of the free cells.
    ``"square"``: the same on the grid refined by two, each occupied cell dilated to its
    closed square (its centre, corners and edge midpoints on the half-cell lattice, where
    the nearest point of a square to a cell centre always lies), sampled at the centres.
    """
    from scipy import ndimage

    if metric == "centre":
        return ndimage.distance_transform_edt(~occ)
    ny, nx = occ.shape
    fine = np.zeros((2 * ny + 1, 2 * nx + 1), dtype=bool)
    fine[1::2, 1::2] = occ
    fine = ndimage.maximum_filter(fine, size=3, mode="constant", cval=False)
    return ndimage.distance_transform_edt(~fine)[1::2, 1::2] * 0.5


# ------------------------------------------------------------------ grid search
def legal_step(occ, a, b, connectivity, corner_cutting):
    """Whether the move a -> b (cells (ix, iy)) is legal under the documented rules.

    Written from :func:`astar.find_path`'s documented move rules (both cells free and
    inside the map; 4- or 8-connected; a diagonal needs both side cells free unless corner
    cutting is allowed), not from its code.
    """
    ny, nx = occ.shape
    (ax, ay), (bx, by) = a, b
    dx, dy = bx - ax, by - ay
    if not (0 <= bx < nx and 0 <= by < ny) or occ[by, bx] or occ[ay, ax]:
        return False
    if (abs(dx), abs(dy)) in ((1, 0), (0, 1)):
        return True
    if connectivity == 4 or (abs(dx), abs(dy)) != (1, 1):
        return False
    return corner_cutting or (not occ[ay, ax + dx] and not occ[ay + dy, ax])


def reachable_cells(occ, start, connectivity=8, corner_cutting=False) -> set[tuple[int, int]]:
    """Every cell a search can reach from ``start``, by breadth-first search.

    Moves are :func:`legal_step` (the documented rules of :func:`astar.find_path`: with the
    defaults, 8-connected without corner cutting); ``occ`` is a boolean array
    ``occ[iy, ix]``, cells are ``(ix, iy)`` and ``start`` must be free. Returns the set of
    cells reached, ``start`` included.
    """
    moves = [(1, 0), (-1, 0), (0, 1), (0, -1)]
    if connectivity == 8:
        moves += [(1, 1), (1, -1), (-1, 1), (-1, -1)]
    start = (int(start[0]), int(start[1]))
    assert not occ[start[1], start[0]], "start must be free"
    seen = {start}
    frontier = [start]
    while frontier:
        nxt = []
        for ax, ay in frontier:
            for dx, dy in moves:
                b = (ax + dx, ay + dy)
                if b not in seen and legal_step(occ, (ax, ay), b, connectivity, corner_cutting):
                    seen.add(b)
                    nxt.append(b)
        frontier = nxt
    return seen


def dijkstra_costs(occ, start, connectivity, corner_cutting, cost=None):
    """Cheapest cost from ``start`` to every cell by scipy's Dijkstra on an explicit graph.

    The graph has one edge per :func:`legal_step` (length 1 or sqrt 2, times
    ``1 + (cost_a + cost_b) / 2`` with a per-cell ``cost``); scipy's
    :func:`scipy.sparse.csgraph.dijkstra` solves it, so neither the search, its heuristic
    nor its landmarks are involved. Returns shape ``(ny, nx)``, ``inf`` where unreachable.
    The graph of a grid (and cost) is built once and reused for every start.
    """
    ny, nx = occ.shape
    graph = step_graph(occ, connectivity, corner_cutting, cost)
    d = dijkstra(graph, indices=start[1] * nx + start[0])
    return d.reshape(ny, nx)


#: The last graphs :func:`dijkstra_costs` built, by the bytes of what defines them.
_GRAPHS: dict[tuple, csr_matrix] = {}


def step_graph(occ, connectivity, corner_cutting, cost=None) -> csr_matrix:
    """The explicit graph of :func:`dijkstra_costs`: an edge of weight ``w`` from cell index
    ``iy * nx + ix`` per legal move (cached: tests ask many starts per grid)."""
    occ = np.asarray(occ)
    key = (
        occ.shape,
        occ.dtype.str,
        occ.tobytes(),
        connectivity,
        bool(corner_cutting),
        None if cost is None else np.asarray(cost, dtype=float).tobytes(),
    )
    graph = _GRAPHS.get(key)
    if graph is not None:
        return graph
    ny, nx = occ.shape
    # the moves of legal_step, each for every cell at once: the cells a = (ix, iy) whose
    # move b = a + (dx, dy) stays in the map, as slices of the grid ("a" rows and columns,
    # "b" rows and columns); tests/astar/test_search.py checks it is legal_step's
    free = ~occ.astype(bool)
    index = np.arange(ny * nx).reshape(ny, nx)
    rows, cols, w = [], [], []
    moves = [(1, 0), (-1, 0), (0, 1), (0, -1)]
    if connectivity == 8:
        moves += [(1, 1), (1, -1), (-1, 1), (-1, -1)]
    for dx, dy in moves:
        ay, ax = slice(max(0, -dy), ny - max(0, dy)), slice(max(0, -dx), nx - max(0, dx))
        by, bx = slice(max(0, dy), ny - max(0, -dy)), slice(max(0, dx), nx - max(0, -dx))
        ok = free[ay, ax] & free[by, bx]
        if dx and dy and not corner_cutting:  # both side cells free
            ok &= free[ay, bx] & free[by, ax]
        step = np.full(ok.shape, SQRT2 if dx and dy else 1.0)
        if cost is not None:
            step *= 1.0 + 0.5 * (cost[ay, ax] + cost[by, bx])
        rows.append(index[ay, ax][ok])
        cols.append(index[by, bx][ok])
        w.append(step[ok])
    rows, cols, w = np.concatenate(rows), np.concatenate(cols), np.concatenate(w)
    graph = csr_matrix((w, (rows, cols)), shape=(nx * ny, nx * ny))
    if len(_GRAPHS) >= 8:
        _GRAPHS.pop(next(iter(_GRAPHS)))
    _GRAPHS[key] = graph
    return graph


def check_path(path, occ, start, goal, connectivity, corner_cutting, cost=None):
    """Every step legal, ends right, reported length and cost equal the recomputed ones.

    Asserts (pytest) that ``path`` (an :class:`astar.GridPath`) runs from ``start`` to
    ``goal`` by :func:`legal_step` moves only, and that its ``length`` and ``cost`` equal
    the sums recomputed here step by step (the same objective as :func:`dijkstra_costs`).
    """
    cells = path.cells
    assert cells.dtype == np.int64 and cells.ndim == 2 and cells.shape[1] == 2
    assert tuple(cells[0]) == tuple(start) and tuple(cells[-1]) == tuple(goal)
    length = total = 0.0
    for a, b in zip(cells[:-1], cells[1:], strict=True):
        assert legal_step(occ, tuple(a), tuple(b), connectivity, corner_cutting), (a, b)
        step = SQRT2 if abs(a - b).sum() == 2 else 1.0
        length += step
        if cost is not None:
            step *= 1.0 + 0.5 * (cost[a[1], a[0]] + cost[b[1], b[0]])
        total += step
    assert path.length == pytest.approx(length, rel=1e-12, abs=1e-12)
    assert path.cost == pytest.approx(total if cost is not None else length, rel=1e-12, abs=1e-12)


def grid_path_cost(cells: Any, cost: np.ndarray) -> float:
    """The search's objective of a path of cells, recomputed: the sum over its steps of the
    step's length (cells) times one plus the mean cost of its two cells.

    Plain arithmetic on the cells (shape (n, 2), ``(ix, iy)``) and the per-cell ``cost``
    (shape (ny, nx)); it does not read the path's own ``cost`` or the search's code.
    """
    cells = np.asarray(cells)
    c = cost[cells[:, 1], cells[:, 0]]
    steps = np.hypot(*np.diff(cells, axis=0).T)
    return float(np.sum(steps * (1.0 + 0.5 * (c[:-1] + c[1:]))))


# ------------------------------------------------------------------ distances and inflation
#: :func:`astar.inflation.inflate`'s documented tolerance: distances within this relative
#: tolerance of the radius equal it.
INFLATION_TOL = 1e-9


def _centres(shape):
    ny, nx = shape
    iy, ix = np.mgrid[0:ny, 0:nx]
    return ix.ravel().astype(float), iy.ravel().astype(float)


def brute_distance(occ, metric, outside):
    """Distance in cells from every cell centre to the nearest obstacle (all pairs).

    ``metric`` ``"centre"``: to the nearest occupied cell's centre; ``"square"``: to the
    nearest point of an occupied cell's unit square. With ``outside``, the region outside
    the map counts as an obstacle. Written from the definitions over all pairs of cells,
    independent of the row decomposition and the refined-lattice transform of
    :mod:`astar.inflation`.
    """
    ny, nx = occ.shape
    x, y = _centres(occ.shape)
    oy, ox = np.nonzero(occ)
    d = np.full(x.shape, np.inf)
    if ox.size:
        dx = np.abs(x[:, None] - ox[None, :])
        dy = np.abs(y[:, None] - oy[None, :])
        if metric == "square":
            dx = np.maximum(0.0, dx - 0.5)
            dy = np.maximum(0.0, dy - 0.5)
        d = np.sqrt(dx**2 + dy**2).min(axis=1)
    if outside:
        if metric == "centre":  # nearest centre of a cell outside the map
            b = np.minimum.reduce([x + 1, nx - x, y + 1, ny - y])
        else:  # nearest point of the region outside the map rectangle
            b = np.minimum.reduce([x + 0.5, nx - x - 0.5, y + 0.5, ny - y - 0.5])
        d = np.minimum(d, b)
    return d.reshape(occ.shape)


def brute_inflate(occ, r_cells, metric, outside):
    """Cells blocked by inflating ``occ`` by ``r_cells`` under ``metric`` (see
    :func:`brute_distance`): ``"centre"`` blocks at distance ``<= r``, ``"square"`` below
    ``r``, both up to :data:`INFLATION_TOL`; occupied cells stay blocked."""
    d = brute_distance(occ, metric, outside)
    # compare squared distances (integers, or quarter-integers for squares) with r^2
    if metric == "centre":
        out = d**2 <= r_cells**2 * (1 + INFLATION_TOL)
    else:
        out = d**2 < r_cells**2 * (1 - INFLATION_TOL)
    return out | occ


def chapter_avoidance(occ, w, border):
    """The chapter's loop, literally: W rounds of 'mark cells next to a full cell as full'.

    Cell by cell, as the chapter writes it (``border``: cells next to the map's edge fill
    too), independent of :func:`astar.inflation.avoidance_area`'s dilation.
    """
    ny, nx = occ.shape
    full = occ.copy()
    for _ in range(w):
        new = full.copy()
        for iy in range(ny):
            for ix in range(nx):
                for dy in (-1, 0, 1):
                    for dx in (-1, 0, 1):
                        jy, jx = iy + dy, ix + dx
                        inside = 0 <= jy < ny and 0 <= jx < nx
                        if (inside and full[jy, jx]) or (not inside and border):
                            new[iy, ix] = True
        full = new
    return full


def brute_squared(occ: np.ndarray, metric: str) -> np.ndarray:
    """All-pairs minimum, in cells^2 (centre) or quarter cells^2 (square), as int64.

    Exact integers from the metric's definition (centre to centre; centre to the nearest
    point of a closed unit square, offsets doubled), over all pairs of cells: independent
    of :mod:`astar.distance_transform`'s separable transform. Cells with no obstacle get
    :data:`astar.distance_transform.UNREACHED`.
    """
    from astar.distance_transform import UNREACHED

    ny, nx = occ.shape
    iy, ix = np.mgrid[0:ny, 0:nx]
    oy, ox = np.nonzero(occ)
    if ox.size == 0:
        return np.full(occ.shape, UNREACHED, dtype=np.int64)
    dx = np.abs(ix.ravel()[:, None] - ox[None, :]).astype(np.int64)
    dy = np.abs(iy.ravel()[:, None] - oy[None, :]).astype(np.int64)
    if metric == "centre":
        d2 = dx * dx + dy * dy
    else:  # nearest point of the square [c - 1/2, c + 1/2]: offset max(|k| - 1/2, 0), doubled
        ax = np.maximum(2 * dx - 1, 0)
        ay = np.maximum(2 * dy - 1, 0)
        d2 = ax * ax + ay * ay
    return d2.min(axis=1).reshape(occ.shape)


def nav2_translate(c: np.ndarray) -> np.ndarray:
    """costmap_2d uint8 -> nav_msgs/OccupancyGrid int8, as Nav2's publisher does.

    Nav2's published translation table re-written from its definition
    (``1 + floor(97 (c - 1) / 251)``, 0 free, 99 inscribed, 100 lethal, -1 unknown), not
    from :mod:`astar.costmap`.
    """
    c = np.asarray(c, dtype=np.int64)
    out = 1 + (97 * (c - 1)) // 251
    out = np.where(c == 0, 0, out)
    out = np.where(c == 253, 99, out)
    out = np.where(c == 254, 100, out)
    return np.where(c == 255, -1, out)


def nav2_inflation(occupied: np.ndarray, res: float, r_ins: float, r_inf: float, k: float):
    """costmap_2d values of a static + inflation layer (Nav2's formulas).

    Nav2's inflation-layer formula (254 lethal, 253 within the inscribed radius ``r_ins``,
    ``floor(252 exp(-k (d - r_ins)))`` up to ``r_inf``, 0 beyond; m) with distances ``d``
    from :func:`scipy.ndimage.distance_transform_edt`, independent of :mod:`astar`.
    """
    from scipy import ndimage

    d = ndimage.distance_transform_edt(~occupied) * res
    c = np.zeros(occupied.shape, np.int64)
    band = (d > r_ins) & (d <= r_inf)
    c[band] = np.floor(252.0 * np.exp(-k * (d[band] - r_ins))).astype(np.int64)
    c[d <= r_ins] = 253
    c[occupied] = 254
    return c


# ------------------------------------------------------------------ clearance (more)
def cell_square_clearance(pts, occ, res, origin):
    """Distance (m) from each point (shape (n, 2)) to the nearest occupied cell's square,
    the map's outside not counted (``inf`` on an empty grid).

    All pairs of points and occupied cells (cell ``(ix, iy)`` spans ``origin + [ix, ix + 1]
    res`` by ``origin + [iy, iy + 1] res``), independent of :mod:`trajopt.analysis.metrics`'
    obstacle index.
    """
    iy, ix = np.nonzero(occ)
    cx = origin[0] + (ix + 0.5) * res
    cy = origin[1] + (iy + 0.5) * res
    dx = np.maximum(0, np.abs(pts[:, None, 0] - cx[None]) - 0.5 * res)
    dy = np.maximum(0, np.abs(pts[:, None, 1] - cy[None]) - 0.5 * res)
    return np.hypot(dx, dy).min(axis=1) if len(cx) else np.full(len(pts), np.inf)


def point_square_distance(p: np.ndarray, grid: astar.OccupancyGrid) -> float:
    """Brute force: distance (m) from a point to every occupied square and to the map edge.

    For a grid with its origin at ``(0, 0)``: all occupied squares and the four edges,
    independent of the planner's clearance checks.
    """
    res = grid.resolution
    iy, ix = np.nonzero(grid.occupied)
    lo = np.stack([ix, iy], axis=1) * res
    d = np.maximum(np.maximum(lo - p, p - (lo + res)), 0.0)
    edge = min(p[0], p[1], grid.occupied.shape[1] * res - p[0], grid.occupied.shape[0] * res - p[1])
    return float(min(np.sqrt((d**2).sum(axis=1)).min(), edge))


def sampled_rect_clearance(sd, squares, m=81):
    """Min distance from points sampled on a 45-degree rectangle (interior and boundary)
    to axis-aligned unit squares: an upper bound on the exact distance, within the
    sampling spacing.

    ``sd = (smin, smax, dmin, dmax)`` bounds the rectangle in the rotated coordinates
    ``s = x + y``, ``d = x - y``; ``squares`` (shape (k, 2)) are the squares' lower-left
    corners. An ``m`` x ``m`` grid of samples against all squares, independent of
    :func:`trajopt.corridor.rotated_rect_clearance`'s exact distance. Returns
    ``(distance, spacing)``.
    """
    smin, smax, dmin, dmax = sd
    s, d = np.meshgrid(np.linspace(smin, smax, m), np.linspace(dmin, dmax, m))
    px, py = ((s + d) / 2).ravel(), ((s - d) / 2).ravel()
    qx, qy = squares[:, 0], squares[:, 1]
    gx = np.maximum(0, np.maximum(qx[None] - px[:, None], px[:, None] - (qx[None] + 1)))
    gy = np.maximum(0, np.maximum(qy[None] - py[:, None], py[:, None] - (qy[None] + 1)))
    spacing = max(smax - smin, dmax - dmin) / (m - 1) / math.sqrt(2)
    return float(np.hypot(gx, gy).min()), spacing


def boundary_samples(v: np.ndarray, spacing: float) -> np.ndarray:
    """Vertices and points every ``spacing`` (at most) along the closed boundary."""
    out = [v]
    k = len(v)
    for i in range(k if k > 2 else k - 1):
        a, b = v[i], v[(i + 1) % k]
        n = max(2, int(math.ceil(np.hypot(*(b - a)) / spacing)) + 1)
        t = np.linspace(0.0, 1.0, n)[:, None]
        out.append(a + t * (b - a))
    return np.vstack(out)


def interior_samples(poly: Any, spacing: float) -> np.ndarray:
    """Grid points at ``spacing`` inside the polygon (plus its vertices).

    ``poly`` has ``vertices`` and ``contains`` (a :class:`trajopt.corridor.ConvexPolygon`):
    only its half-plane test ``A p <= b`` selects the samples.
    """
    v = poly.vertices
    lo, hi = v.min(axis=0), v.max(axis=0)
    xs = np.arange(lo[0], hi[0] + spacing, spacing)
    ys = np.arange(lo[1], hi[1] + spacing, spacing)
    g = np.stack(np.meshgrid(xs, ys), axis=-1).reshape(-1, 2)
    return np.vstack([v, g[poly.contains(g)]])


def _edge_normals(v: np.ndarray) -> np.ndarray:
    e = np.roll(v, -1, axis=0) - v
    n = np.column_stack([e[:, 1], -e[:, 0]])
    return n / np.hypot(n[:, 0], n[:, 1])[:, None]


def brute_polygon_clearance(v: np.ndarray, grid: astar.OccupancyGrid, spacing: float) -> float:
    """Dense-sampling estimate of a convex polygon's clearance: the boundary sampled every
    ``spacing`` (the nearest point of a disjoint square lies on the boundary), 0 when an
    interior sample falls in an occupied square or outside the map.

    ``v`` (shape (k, 2), counter-clockwise, m). The distances come from
    :func:`square_clearance`; the interior test builds its half-planes here from the edge
    normals (a :class:`trajopt.corridor.ConvexPolygon` only holds them), so nothing of
    :func:`trajopt.geometry._clearance.polygon_clearance` is used.
    """
    from trajopt.corridor import ConvexPolygon

    d = float(square_clearance(grid, boundary_samples(v, spacing)).min())
    if len(v) >= 3:
        poly = ConvexPolygon(
            A=_edge_normals(v), b=np.einsum("ij,ij->i", _edge_normals(v), v), vertices=v
        )
        inner = interior_samples(poly, spacing)
        if np.any(square_clearance(grid, inner) == 0.0):
            return 0.0
    return d


# ------------------------------------------------------------------ footprints
def inside_convex(poly: np.ndarray, pts: np.ndarray, tol: float = 1e-12) -> np.ndarray:
    """Whether each point (shape (n, 2)) lies in the counter-clockwise convex polygon
    ``poly`` (shape (k, 2)), within ``tol``: every edge's cross product, by hand."""
    e = np.roll(poly, -1, axis=0) - poly
    c = e[None, :, 0] * (pts[:, None, 1] - poly[None, :, 1]) - e[None, :, 1] * (
        pts[:, None, 0] - poly[None, :, 0]
    )
    return np.all(c >= -tol, axis=1)


def footprint_points(fp: Footprint, n: int = 12) -> np.ndarray:
    """Points filling the footprint (robot frame): its boundary and a grid inside.

    Only the footprint's ``vertices`` are read; ``n`` samples per edge and an ``n`` x ``n``
    grid over the bounding box, kept where :func:`inside_convex`.
    """
    v = fp.vertices
    edges = [
        v[i] + np.linspace(0, 1, n)[:, None] * (v[(i + 1) % len(v)] - v[i]) for i in range(len(v))
    ]
    lo, hi = v.min(axis=0), v.max(axis=0)
    gx, gy = np.meshgrid(np.linspace(lo[0], hi[0], n), np.linspace(lo[1], hi[1], n))
    grid = np.column_stack([gx.ravel(), gy.ravel()])
    return np.vstack(edges + [grid[inside_convex(v, grid)]])


def footprint_collides(grid: astar.OccupancyGrid, fp: Footprint, x, y, theta) -> bool:
    """Brute force: does any sampled point of the posed footprint lie in an occupied square
    or outside the map?

    Poses ``(x, y, theta)`` (m, rad; scalars or arrays); the :func:`footprint_points`
    rotated and moved to each pose and looked up cell by cell in ``grid``. Independent of
    the swept hulls, cones and certificate of :mod:`trajopt.robot._footprint`.
    """
    pts = footprint_points(fp)
    out = []
    for xi, yi, ti in zip(np.atleast_1d(x), np.atleast_1d(y), np.atleast_1d(theta), strict=True):
        c, s = math.cos(ti), math.sin(ti)
        w = np.column_stack(
            [xi + c * pts[:, 0] - s * pts[:, 1], yi + s * pts[:, 0] + c * pts[:, 1]]
        )
        out.append(w)
    w = np.vstack(out)
    q = (w - np.asarray(grid.origin)) / grid.resolution
    ix, iy = np.floor(q[:, 0]).astype(int), np.floor(q[:, 1]).astype(int)
    ny, nx = grid.shape
    outside = (ix < 0) | (iy < 0) | (ix >= nx) | (iy >= ny)
    if outside.any():
        return True
    return bool(grid.occupied[iy, ix].any())


# ------------------------------------------------------------------ curvature
def dense_kappa_max_per_interval(c: BSplineCurve, h: float, n: int) -> np.ndarray:
    """Largest |kappa| per arc-length interval from 100 001 samples, arc length by the
    trapezoid rule on the same samples (independent of the library's quadrature).

    Interval ``i`` covers arc length ``[i h, (i + 1) h)`` (the last one takes the rest),
    ``n`` intervals. It reads the curve's own speed and curvature at the samples (what is
    checked is the bound over an interval, not the evaluation), but none of
    :mod:`trajopt.geometry._curvature_bound`'s Bernstein bounds or its ``u_at_s``.
    """
    from scipy.integrate import cumulative_trapezoid

    u = np.linspace(*c.domain, 100_001)
    s = cumulative_trapezoid(c.speed(u), u, initial=0.0)
    k = np.abs(c.curvature(u))
    i = np.clip((s / h).astype(int), 0, n - 1)
    out = np.zeros(n)
    np.maximum.at(out, i, k)
    return out


def three_point_curvature(p: np.ndarray) -> np.ndarray:
    """Curvature of the circle through consecutive point triples (hand formula).

    ``2 |cross| / (|ab| |bc| |ca|)`` for each triple of rows of ``p`` (shape (n, 2)):
    shape (n - 2,), 1/m. Needs no curve at all.
    """
    a, b, c = p[:-2], p[1:-1], p[2:]
    ab = np.hypot(*(b - a).T)
    bc = np.hypot(*(c - b).T)
    ca = np.hypot(*(a - c).T)
    cross = (b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0]
    return 2.0 * np.abs(cross) / (ab * bc * ca)


# ------------------------------------------------------------------ timing
def ruckig_rest_to_rest_duration(d: float, vmax: float, amax: float, jmax: float) -> float:
    """ruckig's rest-to-rest duration for a 1-DoF move of length ``d`` (direct call).

    ruckig (a separate time-optimal trajectory generator) with speed, acceleration and jerk
    limits, at rest at both ends; the library's stop-and-turn producer does not call it.
    """
    from ruckig import InputParameter, Ruckig, Trajectory

    inp = InputParameter(1)
    inp.current_position = [0.0]
    inp.target_position = [d]
    inp.max_velocity = [vmax]
    inp.max_acceleration = [amax]
    inp.max_jerk = [jmax]
    traj = Trajectory(1)
    Ruckig(1).calculate(inp, traj)
    return float(traj.duration)


def ruckig_profile(length, v0, v1, robot: Robot, v_max):
    """ruckig's time-optimal 1-DoF profile over ``length`` (m) from speed ``v0`` to ``v1``
    (m/s), under ``v_max`` and the robot's ``a_max`` and ``j_max``, at zero acceleration at
    both ends: ``(duration, ruckig trajectory)``. ruckig is an independent generator; the
    library's timing does not call it.
    """
    from ruckig import InputParameter, Result, Ruckig
    from ruckig import Trajectory as RT

    inp = InputParameter(1)
    inp.current_position, inp.current_velocity, inp.current_acceleration = [0.0], [v0], [0.0]
    inp.target_position, inp.target_velocity, inp.target_acceleration = [length], [v1], [0.0]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [v_max], [robot.a_max], [robot.j_max]
    tr = RT(1)
    assert Ruckig(1).calculate(inp, tr) == Result.Working
    return tr.duration, tr


def closed_form_duration(d: float, v: float, a: float, j: float) -> float:
    """Time-optimal rest-to-rest time under |v|, |a|, |jerk| limits (textbook cases).

    The ramp from rest to speed ``w`` takes ``w/a + a/j`` if ``a`` is reached, else
    ``2 sqrt(w/j)``, and covers ``w * T/2`` (the ramp is point-symmetric); two ramps and a
    cruise at ``v`` if there is room, else two ramps to the peak speed found by bisection.
    """

    def ramp(w: float) -> float:
        return w / a + a / j if w >= a * a / j else 2.0 * math.sqrt(w / j)

    if v * ramp(v) <= d:
        return 2.0 * ramp(v) + (d - v * ramp(v)) / v
    lo, hi = 0.0, v
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if mid * ramp(mid) < d else (lo, mid)
    return 2.0 * ramp(0.5 * (lo + hi))


def turn_limits_by_hand(robot: Robot) -> tuple[float, float, float]:
    """A turn in place's rate, angular acceleration and angular jerk limits, by hand.

    The wheels (or the disc's rim) are ``half`` a track width (or the radius) from the
    centre: ``omega <= min(omega_max, wheel_v_max / half)``, ``alpha <= a_max / half``,
    ``zeta <= j_max / half`` (rad/s, rad/s^2, rad/s^3); from the robot's fields, not from
    :func:`trajopt.timing._stop_and_turn.turn_limits`.
    """
    half = robot.track_width / 2 if robot.track_width is not None else robot.radius
    w = robot.omega_max
    if robot.track_width is not None:
        w = min(w, robot.wheel_v_max / half)
    return w, robot.a_max / half, robot.j_max / half


def v_limit_by_hand(robot: Robot) -> float:
    """A straight leg's speed limit (m/s), by hand: ``v_max``, or the wheels' limit if lower."""
    return min(robot.v_max, robot.wheel_v_max or math.inf)


def integrate_jerk(d, j, dt=2.0**-13):
    """Reference: integrate the jerk signal numerically (no polynomial formulas). ``dt``
    divides every phase duration, so the jerk is constant on each step: ``a`` and ``v`` are
    exact (trapezoid on linear ``a``), ``s`` is within ~1e-9 m (trapezoid on quadratic ``v``).

    Phases of durations ``d`` (s) and jerks ``j`` (m/s^3), from rest at ``s = 0``; returns
    ``(t, s, v, a)`` on the steps. Independent of :class:`trajopt.Trajectory`'s phase
    polynomials.
    """
    n = int(round(d.sum() / dt))
    t = np.arange(n + 1) * dt
    edges = np.concatenate([[0.0], np.cumsum(d)])
    mid = t[:-1] + dt / 2
    jerk = j[np.clip(np.searchsorted(edges, mid, side="right") - 1, 0, len(d) - 1)]
    a = np.concatenate([[0.0], np.cumsum(jerk * dt)])
    v = np.concatenate([[0.0], np.cumsum(0.5 * (a[1:] + a[:-1]) * dt)])
    s = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * dt)])
    return t, s, v, a


# ------------------------------------------------------------------ fits
def brute_force_schoenberg_whitney(a: np.ndarray, u: np.ndarray) -> bool:
    """Some strictly increasing sites u_(j_0) < ... with B_i(u_(j_i)) != 0 (by enumeration).

    ``a`` (shape (m, n)) is the collocation matrix ``B_i(u_j)`` at the sorted sites ``u``
    (shape (m,)); every choice of ``n`` of the ``m`` rows is tried, independent of
    :func:`trajopt.analysis.fits._bspline_fit.schoenberg_whitney_matches`' greedy matching.
    """
    m, n = a.shape
    for rows in itertools.combinations(range(m), n):
        if np.all(np.diff(u[list(rows)]) > 0) and all(a[j, i] != 0 for i, j in enumerate(rows)):
            return True
    return False


def control_point_swing(p: np.ndarray, c: np.ndarray) -> float:
    """Largest distance of a control point from the data's bounding box over its longer side
    (the nearest point of the box by clipping).

    ``p`` the data (shape (m, 2)), ``c`` the control points (shape (n, 2)): the quantity
    the B-spline fit compares with ``BSPLINE_SWING_MAX``, recomputed by hand.
    """
    lo, hi = p.min(axis=0), p.max(axis=0)
    return float(np.linalg.norm(c - np.clip(c, lo, hi), axis=1).max() / np.max(hi - lo))


def dense_mean_cost(curve, cost, grid) -> float:
    """Mean cell cost per metre on 20000 samples (nearest cell: no interpolation)."""
    a, b = curve.domain
    pts = curve(np.linspace(a, b, 20001))
    mid = 0.5 * (pts[1:] + pts[:-1])
    d = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    ix = np.floor(mid / grid.resolution).astype(int)
    return float(np.sum(cost[ix[:, 1], ix[:, 0]] * d) / np.sum(d))
