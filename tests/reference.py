"""Independent brute-force references shared by the tests (a helper module, not a test module).

Each is deliberately naive (all pairs, plain Dijkstra) so that it is obviously right and
shares no code with the library it checks. Units are in each function's docstring: grids
are :class:`astar.OccupancyGrid` values (``occupied[iy, ix]``, row 0 at the bottom) or
plain boolean arrays in cells.
"""

from __future__ import annotations

import heapq
import math

import numpy as np

import astar

__all__ = [
    "brute_inflate_square",
    "dijkstra_path",
    "polyline_samples",
    "scipy_distance_cells",
    "square_clearance",
]


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
            (x0 + res >= qx.min() - reach) & (x0 <= qx.max() + reach)
            & (y0 + res >= qy.min() - reach) & (y0 <= qy.max() + reach)
        )  # fmt: skip
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
