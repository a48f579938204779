"""The polygon corridor's obstacle index.

The occupied cells of a map window merged into rectangles (cell units), a bucket grid over them,
and the exact distance queries of a point, a segment or a polygon to every obstacle (the
rectangles and the outside of the map).

The *index* passed to the kernels is the tuple ``(rects, meta, bstart, bids, stamp,
buf)`` of :attr:`ObstacleIndex.args`: ``meta`` holds ``[gx0, gy0, bucket, nbx, nby, nx,
ny]`` (ints), ``stamp`` (length ``R + 1``, its last entry the current tick) de-duplicates
rectangles listed in several buckets and ``buf`` (length ``R``) receives the gathered ids.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from trajopt.geometry._clearance import (
    border_distance,
    per_map,
    polygon_rect_closest,
    segment_rect_distance,
    window_rects,
)
from trajopt.kernel_cache import watch_compiles

BUCKET_CELLS = 8


watch_compiles()  # a first compilation logs one notice (trajopt.kernel_cache)


@njit(cache=True)
def _bucket_range(rect, gx0, gy0, bsize, nbx, nby):  # pragma: no cover - compiled
    """Bucket index ranges ``(bx0, bx1, by0, by1)`` (inclusive) that a rectangle meets."""
    bx0 = max(0, int(math.floor((rect[0] - gx0) / bsize)))
    bx1 = min(nbx - 1, int(math.floor((rect[2] - gx0) / bsize)))
    by0 = max(0, int(math.floor((rect[1] - gy0) / bsize)))
    by1 = min(nby - 1, int(math.floor((rect[3] - gy0) / bsize)))
    return bx0, bx1, by0, by1


@njit(cache=True)
def build_buckets(rects, gx0, gy0, bsize, nbx, nby):  # pragma: no cover - compiled
    """CSR lists ``(bstart, bids)`` of the rectangles meeting each ``bsize`` bucket."""
    nb = nbx * nby
    counts = np.zeros(nb + 1, np.int64)
    nr = rects.shape[0]
    for i in range(nr):
        bx0, bx1, by0, by1 = _bucket_range(rects[i], gx0, gy0, bsize, nbx, nby)
        for by in range(by0, by1 + 1):
            for bx in range(bx0, bx1 + 1):
                counts[by * nbx + bx + 1] += 1
    for b in range(nb):
        counts[b + 1] += counts[b]
    bids = np.empty(counts[nb], np.int64)
    fill = counts[:nb].copy()
    for i in range(nr):
        bx0, bx1, by0, by1 = _bucket_range(rects[i], gx0, gy0, bsize, nbx, nby)
        for by in range(by0, by1 + 1):
            for bx in range(bx0, bx1 + 1):
                b = by * nbx + bx
                bids[fill[b]] = i
                fill[b] += 1
    return counts, bids


@njit(cache=True)
def gather(qx0, qx1, qy0, qy1, rects, meta, bstart, bids, stamp, buf):  # pragma: no cover
    """Ids of the rectangles meeting the closed box ``[qx0, qx1] x [qy0, qy1]`` into ``buf``.

    Returns their count.
    """
    gx0 = meta[0]
    gy0 = meta[1]
    bs = meta[2]
    nbx = meta[3]
    nby = meta[4]
    bx0 = max(0, int(math.floor((qx0 - gx0) / bs)))
    bx1 = min(nbx - 1, int(math.floor((qx1 - gx0) / bs)))
    by0 = max(0, int(math.floor((qy0 - gy0) / bs)))
    by1 = min(nby - 1, int(math.floor((qy1 - gy0) / bs)))
    if bx0 > bx1 or by0 > by1:
        return 0
    nt = stamp.shape[0] - 1
    stamp[nt] += 1
    tick = stamp[nt]
    n = 0
    for by in range(by0, by1 + 1):
        for bx in range(bx0, bx1 + 1):
            b = by * nbx + bx
            for k in range(bstart[b], bstart[b + 1]):
                i = bids[k]
                if stamp[i] == tick:
                    continue
                stamp[i] = tick
                if (
                    rects[i, 0] <= qx1
                    and rects[i, 2] >= qx0
                    and rects[i, 1] <= qy1
                    and rects[i, 3] >= qy0
                ):
                    buf[n] = i
                    n += 1
    return n


@njit(cache=True)
def point_nearest(px, py, cap, rects, meta, bstart, bids, stamp, buf):  # pragma: no cover
    """Distance (capped at ``cap``) from a point to the nearest obstacle.

    Distance (capped at ``cap``) from a point to the nearest obstacle (rectangle or the outside
    of the map) and the nearest obstacle point (``nan`` when none is within ``cap``).
    """
    nx = meta[5]
    ny = meta[6]
    best = cap
    qx = np.nan
    qy = np.nan
    for k in range(4):
        if k == 0:
            d, cx, cy = px, 0.0, py
        elif k == 1:
            d, cx, cy = nx - px, float(nx), py
        elif k == 2:
            d, cx, cy = py, px, 0.0
        else:
            d, cx, cy = ny - py, px, float(ny)
        d = max(d, 0.0)
        if d < best:
            best, qx, qy = d, cx, cy
    n = gather(px - cap, px + cap, py - cap, py + cap, rects, meta, bstart, bids, stamp, buf)
    for k in range(n):
        i = buf[k]
        cx = min(max(px, rects[i, 0]), rects[i, 2])
        cy = min(max(py, rects[i, 1]), rects[i, 3])
        d = math.sqrt((px - cx) ** 2 + (py - cy) ** 2)
        if d < best:
            best, qx, qy = d, cx, cy
    return best, qx, qy


@njit(cache=True)
def seg_clearance(ax, ay, bx, by, cap, rects, meta, bstart, bids, stamp, buf):  # pragma: no cover
    """Exact distance (capped at ``cap``) from a segment to every obstacle."""
    nx = meta[5]
    ny = meta[6]
    best = min(cap, border_distance(ax, ay, nx, ny), border_distance(bx, by, nx, ny))
    n = gather(
        min(ax, bx) - best,
        max(ax, bx) + best,
        min(ay, by) - best,
        max(ay, by) + best,
        rects,
        meta,
        bstart,
        bids,
        stamp,
        buf,
    )
    for k in range(n):
        i = buf[k]
        d = segment_rect_distance(
            ax, ay, bx, by, rects[i, 0], rects[i, 1], rects[i, 2], rects[i, 3]
        )
        if d < best:
            best = d
    return best


@njit(cache=True)
def poly_clearance(v, nv, cap, rects, meta, bstart, bids, stamp, buf):  # pragma: no cover
    """Exact distance (capped at ``cap``) from a convex polygon ``v[:nv]`` to every obstacle.

    The outside of the map (nearest vertex) and every rectangle.
    """
    nx = meta[5]
    ny = meta[6]
    best = cap
    xmin = ymin = np.inf
    xmax = ymax = -np.inf
    for i in range(nv):
        best = min(best, border_distance(v[i, 0], v[i, 1], nx, ny))
        xmin = min(xmin, v[i, 0])
        xmax = max(xmax, v[i, 0])
        ymin = min(ymin, v[i, 1])
        ymax = max(ymax, v[i, 1])
    n = gather(
        xmin - best, xmax + best, ymin - best, ymax + best, rects, meta, bstart, bids, stamp, buf
    )
    for k in range(n):
        i = buf[k]
        d, _, _, _, _ = polygon_rect_closest(
            v, nv, rects[i, 0], rects[i, 1], rects[i, 2], rects[i, 3]
        )
        if d < best:
            best = d
    return best


#: the whole-map rectangles of the last few maps, by the identity of their occupancy array
_MAP_RECTS: dict[int, tuple[np.ndarray, np.ndarray]] = {}


def map_rects(occ: np.ndarray) -> np.ndarray:
    """Return the occupied cells of the whole map as rectangles, ``(R, 4)`` (cached per array).

    :func:`~trajopt.geometry._clearance.merge_rects` of the whole map, kept for a
    read-only array (the arrays of :class:`astar.OccupancyGrid` are), so it cannot change
    under the cache.
    """
    return per_map(_MAP_RECTS, occ, lambda: window_rects(occ, 0, occ.shape[1], 0, occ.shape[0]))


class ObstacleIndex:
    """Obstacle rectangles of a map window (cell units) with a bucket grid.

    Parameters
    ----------
    occ : ndarray of bool, shape (ny, nx)
        The raw map's occupancy.
    x0, x1, y0, y1 : int
        The window (cells, ends exclusive), clipped to the map.
    bucket_cells : int, optional
        Side of the buckets (cells). Default :data:`BUCKET_CELLS`.
    whole_map : bool, optional
        Take the rectangles of the whole map's decomposition (:func:`map_rects`, computed
        once per map) that meet the window, instead of decomposing the window's cells:
        the same obstacles, found in time that follows the rectangles, not the window's
        cells. Default False.
    """

    __slots__ = ("rects", "meta", "bstart", "bids", "stamp", "buf")

    def __init__(
        self,
        occ: np.ndarray,
        x0: int,
        x1: int,
        y0: int,
        y1: int,
        *,
        bucket_cells: int = BUCKET_CELLS,
        whole_map: bool = False,
    ) -> None:
        ny, nx = occ.shape
        x0, y0 = max(0, x0), max(0, y0)
        x1, y1 = min(nx, x1), min(ny, y1)
        if x1 <= x0 or y1 <= y0:
            rects = np.zeros((0, 4))
            x0, y0, x1, y1 = 0, 0, 1, 1
        elif whole_map:
            allr = map_rects(occ)
            meet = (allr[:, 2] > x0) & (allr[:, 0] < x1) & (allr[:, 3] > y0) & (allr[:, 1] < y1)
            rects = np.ascontiguousarray(allr[meet])
        else:
            rects = window_rects(occ, x0, x1, y0, y1)
        bs = int(bucket_cells)
        nbx = max(1, -(-(x1 - x0) // bs))
        nby = max(1, -(-(y1 - y0) // bs))
        self.rects = rects
        self.meta = np.array([x0, y0, bs, nbx, nby, nx, ny], dtype=np.int64)
        self.bstart, self.bids = build_buckets(rects, x0, y0, bs, nbx, nby)
        self.stamp = np.zeros(len(rects) + 1, dtype=np.int64)
        self.buf = np.empty(max(1, len(rects)), dtype=np.int64)

    @property
    def args(self) -> tuple:
        """The tuple the kernels take: ``(rects, meta, bstart, bids, stamp, buf)``."""
        return (self.rects, self.meta, self.bstart, self.bids, self.stamp, self.buf)
