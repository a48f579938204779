"""Exact clearance to occupied squares: the distance the whole certificate rests on.

One rule everywhere: an occupied cell ``(ix, iy)`` is the *closed* square
``[ix, ix + 1] x [iy, iy + 1]`` in cell units (``[ox + ix res, ox + (ix + 1) res] x ...``
in metres), and, unless a caller says otherwise, everything outside the map counts as
occupied. Distances are exact (no sampling of the obstacles): point, segment and convex
polygon to axis-aligned rectangle, with the separating-axis theorem deciding contact.

Layers:

* **kernels** (numba, cell units): :func:`point_rect_distance`,
  :func:`point_segment_distance`, :func:`segment_meets_rect`,
  :func:`segment_rect_distance`, :func:`polygon_rect_closest`, :func:`border_distance`,
  :func:`merge_rects` (occupied cells as rectangles; :func:`window_rects` calls it on a
  window of the map), :func:`polygon_rects_distance`,
  :func:`point_square_dist2` and :func:`segment_squares_distance` (scans of the cells
  around a point or a segment);
* **metres** (NumPy in, float out): :func:`points_clearance` (the smoother's certificate),
  :func:`polyline_clearance` (the stop-and-turn fallback), :func:`polygon_clearance` (the
  corridor regions, the planner's start/goal and end-box checks) and :func:`box_clearance`.

Users: :mod:`trajopt.corridor` and its kernels, :mod:`trajopt.corridor` (45-degree
bridges), :mod:`trajopt.smoother` (certificate), :mod:`trajopt.planning._feasibility` (witness
search), :mod:`trajopt.timing._stop_and_turn` and :mod:`trajopt._planner`. :mod:`trajopt.metrics` keeps
a deliberately independent check (a KD-tree over sampled obstacle boundaries) so that the
library's own answers can be tested against something that shares no code with them.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import njit

from trajopt.errors import InvalidInputError
from trajopt.kernel_cache import watch_compiles

watch_compiles()  # a first compilation logs one notice (trajopt.kernel_cache)


# ================================================================= kernels (cell units)
@njit(cache=True, inline="always")
def point_rect_distance(px, py, x0, y0, x1, y1):  # pragma: no cover - compiled
    """Distance from a point to a closed axis-aligned rectangle (0 inside)."""
    gx = max(x0 - px, 0.0, px - x1)
    gy = max(y0 - py, 0.0, py - y1)
    return math.sqrt(gx * gx + gy * gy)


@njit(cache=True, inline="always")
def point_segment_distance(px, py, ax, ay, bx, by):  # pragma: no cover - compiled
    """Distance from a point to a segment, and the parameter of the closest point."""
    dx = bx - ax
    dy = by - ay
    ll = dx * dx + dy * dy
    t = 0.0
    if ll > 0.0:
        t = ((px - ax) * dx + (py - ay) * dy) / ll
        t = min(1.0, max(0.0, t))
    cx = ax + t * dx - px
    cy = ay + t * dy - py
    return math.sqrt(cx * cx + cy * cy), t


@njit(cache=True)
def segment_meets_rect(ax, ay, bx, by, x0, y0, x1, y1):  # pragma: no cover - compiled
    """Whether a closed segment meets a closed rectangle (Liang-Barsky)."""
    dx = bx - ax
    dy = by - ay
    t0 = 0.0
    t1 = 1.0
    for k in range(4):
        if k == 0:
            p, q = -dx, ax - x0
        elif k == 1:
            p, q = dx, x1 - ax
        elif k == 2:
            p, q = -dy, ay - y0
        else:
            p, q = dy, y1 - ay
        if p == 0.0:
            if q < 0.0:
                return False
        else:
            t = q / p
            if p < 0.0:
                t0 = max(t0, t)
            else:
                t1 = min(t1, t)
    return t0 <= t1


@njit(cache=True)
def segment_rect_distance(ax, ay, bx, by, x0, y0, x1, y1):  # pragma: no cover - compiled
    """Exact distance between a segment and a rectangle (0 when they meet)."""
    if segment_meets_rect(ax, ay, bx, by, x0, y0, x1, y1):
        return 0.0
    d = min(
        point_rect_distance(ax, ay, x0, y0, x1, y1), point_rect_distance(bx, by, x0, y0, x1, y1)
    )
    for c in range(4):
        cx = x0 if (c == 0 or c == 3) else x1
        cy = y0 if c < 2 else y1
        e, _ = point_segment_distance(cx, cy, ax, ay, bx, by)
        d = min(d, e)
    return d


@njit(cache=True)
def polygon_rect_closest(v, nv, x0, y0, x1, y1):  # pragma: no cover - compiled
    """Exact distance between a convex polygon.

    Exact distance between a convex polygon (``v[:nv]``, any orientation; 1 or 2 vertices for a
    point or a segment) and a rectangle, with a closest pair.

    Returns ``(d, px, py, qx, qy)``: ``p`` on the polygon, ``q`` on the rectangle; ``d = 0``
    (and ``p = q = nan``) when they meet, decided by the separating-axis theorem over the
    polygon's edge normals and the two coordinate axes.
    """
    nan = np.nan
    vxmin = v[0, 0]
    vxmax = v[0, 0]
    vymin = v[0, 1]
    vymax = v[0, 1]
    for i in range(1, nv):
        vxmin = min(vxmin, v[i, 0])
        vxmax = max(vxmax, v[i, 0])
        vymin = min(vymin, v[i, 1])
        vymax = max(vymax, v[i, 1])
    sep = vxmax < x0 or vxmin > x1 or vymax < y0 or vymin > y1
    if not sep and nv >= 2:
        for i in range(nv):
            j = (i + 1) % nv
            ex = v[j, 0] - v[i, 0]
            ey = v[j, 1] - v[i, 1]
            if ex == 0.0 and ey == 0.0:
                continue
            nx_ = ey
            ny_ = -ex
            pmax = -np.inf
            pmin = np.inf
            for k in range(nv):
                s = nx_ * v[k, 0] + ny_ * v[k, 1]
                pmax = max(pmax, s)
                pmin = min(pmin, s)
            rmin = np.inf
            rmax = -np.inf
            for c in range(4):
                cx = x0 if (c == 0 or c == 3) else x1
                cy = y0 if c < 2 else y1
                s = nx_ * cx + ny_ * cy
                rmin = min(rmin, s)
                rmax = max(rmax, s)
            if rmin > pmax or rmax < pmin:
                sep = True
                break
    if not sep:
        return 0.0, nan, nan, nan, nan
    best = np.inf
    bpx = bpy = bqx = bqy = nan
    for i in range(nv):
        px = v[i, 0]
        py = v[i, 1]
        qx = min(max(px, x0), x1)
        qy = min(max(py, y0), y1)
        d = math.sqrt((px - qx) ** 2 + (py - qy) ** 2)
        if d < best:
            best = d
            bpx, bpy, bqx, bqy = px, py, qx, qy
    if nv >= 2:
        for c in range(4):
            cx = x0 if (c == 0 or c == 3) else x1
            cy = y0 if c < 2 else y1
            for i in range(nv):
                j = (i + 1) % nv
                d, t = point_segment_distance(cx, cy, v[i, 0], v[i, 1], v[j, 0], v[j, 1])
                if d < best:
                    best = d
                    bpx = v[i, 0] + t * (v[j, 0] - v[i, 0])
                    bpy = v[i, 1] + t * (v[j, 1] - v[i, 1])
                    bqx, bqy = cx, cy
    return best, bpx, bpy, bqx, bqy


@njit(cache=True, inline="always")
def border_distance(px, py, nx, ny):  # pragma: no cover - compiled
    """Distance from a point to the outside of the map ``[0, nx] x [0, ny]`` (0 outside)."""
    return max(0.0, min(px, nx - px, py, ny - py))


@njit(cache=True)
def merge_rects(occ, x_off, y_off):  # pragma: no cover - compiled
    """Occupied cells of ``occ`` (window of the map, ``occ[iy, ix]``) as rectangles.

    Runs of occupied cells along each row are merged with the identical run of the row
    below when there is one. Returns ``(R, 4)`` float64 ``(x0, y0, x1, y1)``, offset by
    ``(x_off, y_off)`` cells.
    """
    h, w = occ.shape
    runs = 0  # an upper bound of the rectangle count (growing arrays in the loop is slow)
    for y in range(h):
        inside = False
        for x in range(w):
            if occ[y, x] and not inside:
                runs += 1
            inside = occ[y, x]
    rx0 = np.empty(runs, np.int64)
    ry0 = np.empty(runs, np.int64)
    rx1 = np.empty(runs, np.int64)
    ry1 = np.empty(runs, np.int64)
    n = 0
    prev = np.full(w + 1, -1, np.int64)
    cur = np.full(w + 1, -1, np.int64)
    for y in range(h):
        x = 0
        while x < w:
            if not occ[y, x]:
                x += 1
                continue
            x0 = x
            while x < w and occ[y, x]:
                x += 1
            rid = prev[x0]
            if rid >= 0 and rx1[rid] == x and ry1[rid] == y:
                ry1[rid] = y + 1
            else:
                rx0[n] = x0
                ry0[n] = y
                rx1[n] = x
                ry1[n] = y + 1
                rid = n
                n += 1
            cur[x0] = rid
        tmp = prev
        prev = cur
        cur = tmp
        cur[:] = -1
    out = np.empty((n, 4), np.float64)
    for i in range(n):
        out[i, 0] = rx0[i] + x_off
        out[i, 1] = ry0[i] + y_off
        out[i, 2] = rx1[i] + x_off
        out[i, 3] = ry1[i] + y_off
    return out


def window_rects(occ: np.ndarray, x0: int, x1: int, y0: int, y1: int) -> np.ndarray:
    """Occupied cells of the window ``occ[y0:y1, x0:x1]`` as rectangles, in map cells.

    Returns :func:`merge_rects`'s ``(R, 4)`` float64 ``(x0, y0, x1, y1)``. The window is
    passed read-only whether or not it had to be copied, so the kernel has one compiled
    signature (each signature is a cache load in a fresh process).
    """
    window = np.ascontiguousarray(occ[y0:y1, x0:x1], dtype=np.bool_)
    if window.flags.writeable:
        window = window.view()
        window.flags.writeable = False
    return merge_rects(window, x0, y0)


@njit(cache=True)
def polygon_rects_distance(v, nv, rects):  # pragma: no cover - compiled
    """Exact distance from a convex polygon ``v[:nv]`` to the nearest of ``rects``.

    ``inf`` when ``rects`` is empty.
    """
    best = np.inf
    for i in range(rects.shape[0]):
        d, _, _, _, _ = polygon_rect_closest(
            v, nv, rects[i, 0], rects[i, 1], rects[i, 2], rects[i, 3]
        )
        if d < best:
            best = d
            if best == 0.0:
                break
    return best


@njit(cache=True)
def point_square_dist2(px, py, occ, w, best):  # pragma: no cover - compiled
    """``min(best, d^2)``.

    ``d`` the distance (cells) from ``(px, py)`` to the nearest occupied unit square within
    ``w`` cells of its cell (outside the grid is occupied).
    """
    ny, nx = occ.shape
    cx = int(math.floor(px))
    cy = int(math.floor(py))
    for gy in range(cy - w, cy + w + 1):
        dy = max(0.0, max(gy - py, py - (gy + 1)))
        if dy * dy >= best:
            continue
        for gx in range(cx - w, cx + w + 1):
            if 0 <= gx < nx and 0 <= gy < ny and not occ[gy, gx]:
                continue
            dx = max(0.0, max(gx - px, px - (gx + 1)))
            d2 = dx * dx + dy * dy
            if d2 < best:
                best = d2
    return best


@njit(cache=True)
def _points_clearance_kernel(q, occ, w, cap):  # pragma: no cover - compiled
    out = np.empty(q.shape[0])
    for k in range(q.shape[0]):
        out[k] = math.sqrt(point_square_dist2(q[k, 0], q[k, 1], occ, w, cap * cap))
    return out


@njit(cache=True)
def block_dist2(px, py, occ, blk, bs, best):  # pragma: no cover - compiled
    """``min(best, d^2)``: ``d`` (cells) from ``(px, py)`` to the nearest occupied square.

    Only squares closer than ``sqrt(best)`` matter. The map's outside counts as occupied
    (its distance is the border distance). ``blk[by, bx]``: whether the ``bs x bs`` block
    of cells holds an occupied one; blocks are visited in rings around the point's block
    until a ring lies beyond ``sqrt(best)``, and only occupied blocks' cells are measured.
    """
    ny, nx = occ.shape
    nby, nbx = blk.shape
    b = max(0.0, min(px, nx - px, py, ny - py))
    if b * b < best:
        best = b * b
    cbx = int(math.floor(px / bs))
    cby = int(math.floor(py / bs))
    j = 0
    while True:
        near = (j - 1) * bs  # the least distance to a block of ring j
        if j > 0 and near > 0 and near * near >= best:
            break
        if cbx - j < 0 and cby - j < 0 and cbx + j >= nbx and cby + j >= nby:
            break
        for by in range(cby - j, cby + j + 1):
            if by < 0 or by >= nby:
                continue
            edge = by == cby - j or by == cby + j
            step = 1 if edge else 2 * j
            bx = cbx - j
            while bx <= cbx + j:
                if 0 <= bx < nbx and blk[by, bx]:
                    for gy in range(by * bs, min(ny, (by + 1) * bs)):
                        dy = max(0.0, max(gy - py, py - (gy + 1)))
                        if dy * dy >= best:
                            continue
                        for gx in range(bx * bs, min(nx, (bx + 1) * bs)):
                            if not occ[gy, gx]:
                                continue
                            dx = max(0.0, max(gx - px, px - (gx + 1)))
                            d2 = dx * dx + dy * dy
                            if d2 < best:
                                best = d2
                bx += step if step > 0 else 1
        j += 1
    return best


@njit(cache=True)
def _min_clearance_kernel(q, occ, blk, bs, cap):  # pragma: no cover - compiled
    """Exact ``min_k min(d_k, cap)`` over the points ``q`` (cells), skipping what cannot win.

    ``d_k`` is 1-Lipschitz along the polyline of the points: a point ``s`` (cells) after one
    whose capped distance ``d`` was computed (``d`` is a lower bound of its distance) is at
    least ``d - s`` away, so while that bound is not below the least distance so far the
    point cannot lower it and is not searched.
    """
    best = cap
    lb = -1.0
    for k in range(q.shape[0]):
        if k > 0:
            lb -= math.hypot(q[k, 0] - q[k - 1, 0], q[k, 1] - q[k - 1, 1])
            if lb >= best:
                continue
        d = math.sqrt(block_dist2(q[k, 0], q[k, 1], occ, blk, bs, cap * cap))
        lb = d
        if d < best:
            best = d
    return best


#: side (cells) of the occupancy blocks of :func:`min_points_clearance`
CLEARANCE_BLOCK = 8
#: the blocks of the last few maps, by the identity of their occupancy array
_BLOCKS: dict[int, tuple[np.ndarray, np.ndarray]] = {}


def occupied_blocks(occ: np.ndarray, bs: int = CLEARANCE_BLOCK) -> np.ndarray:
    """Return which ``bs x bs`` blocks of ``occ`` hold an occupied cell.

    Cached per array when ``occ`` is read-only (an :class:`astar.OccupancyGrid`'s is), so
    that it cannot change under the cache.
    """
    return per_map(_BLOCKS, occ, lambda: _blocks_of(occ, bs))


def _blocks_of(occ: np.ndarray, bs: int) -> np.ndarray:
    """Which ``bs x bs`` blocks of ``occ`` hold an occupied cell (the last ones cut by its edge)."""
    ny, nx = occ.shape
    by, bx = -(-ny // bs), -(-nx // bs)
    pad = np.zeros((by * bs, bx * bs), dtype=bool)
    pad[:ny, :nx] = occ
    return np.ascontiguousarray(pad.reshape(by, bs, bx, bs).any(axis=(1, 3)))


def derive_blocks(
    occ: np.ndarray, base: np.ndarray, window: tuple[int, int, int, int] | None
) -> None:
    """Keep the blocks of :func:`occupied_blocks` for ``occ`` made from those kept for ``base``.

    ``occ`` equals ``base`` (same shape) outside the cell box ``window`` ``(x0, x1, y0, y1)``
    (inclusive; ``None``: everywhere), as a map derived from a planner's with cells marked
    (:meth:`trajopt.planning.PlannerCaches.derived`). A block holds an occupied cell of
    ``occ`` exactly as it does of ``base`` unless it meets the window, so ``base``'s blocks
    are copied and those meeting the window computed again from ``occ``: the same values as
    :func:`occupied_blocks` of ``occ`` computed afresh, for the cost of the window's blocks.
    Does nothing unless ``base``'s blocks are kept and ``occ`` is read-only (and so kept);
    counts as a use of ``base``'s (:func:`per_map`).
    """
    bs = CLEARANCE_BLOCK
    hit = _BLOCKS.get(id(base))
    if hit is None or hit[0] is not base or occ.shape != base.shape or occ.flags.writeable:
        return
    _BLOCKS[id(base)] = _BLOCKS.pop(id(base))  # a use: the unchanged map's are evicted last
    blk = np.array(hit[1])
    if window is not None:
        x0, x1, y0, y1 = window
        bx0, by0 = x0 // bs, y0 // bs
        part = occ[by0 * bs : (y1 // bs + 1) * bs, bx0 * bs : (x1 // bs + 1) * bs]
        sub = _blocks_of(part, bs)
        blk[by0 : by0 + sub.shape[0], bx0 : bx0 + sub.shape[1]] = sub
    per_map(_BLOCKS, occ, lambda: blk)


def per_map(cache: dict, occ: np.ndarray, build: Any) -> Any:
    """Return ``build()`` for the occupancy array ``occ``, kept in ``cache`` by its identity.

    Kept only for a read-only ``occ`` (an :class:`astar.OccupancyGrid`'s is), so that it
    cannot change under the cache; the 4 arrays used last are kept (a hit counts as a use,
    so a planner's own map stays while maps derived from it for one query come and go),
    each held by the cache so that its identity is not reused.
    """
    key = id(occ)
    hit = cache.get(key)
    if hit is not None and hit[0] is occ:
        cache.pop(key, None)  # the most recently used last: evicted last
        cache[key] = hit
        return hit[1]
    value = build()
    if occ.flags.writeable:
        return value
    if len(cache) >= 4:
        cache.pop(next(iter(cache)))
    cache[key] = (occ, value)
    return value


@njit(cache=True)
def segment_squares_distance(ax, ay, bx, by, occ, w, cap, outside_occupied):  # pragma: no cover
    """Exact distance (cells, capped at ``cap``).

    Exact distance (cells, capped at ``cap``) from a segment to the occupied unit squares among
    the cells within ``w`` of the cell of its midpoint (and, with ``outside_occupied``, the
    cells outside the grid).
    """
    ny, nx = occ.shape
    mx = int(math.floor(0.5 * (ax + bx)))
    my = int(math.floor(0.5 * (ay + by)))
    best = cap
    for gy in range(my - w, my + w + 1):
        for gx in range(mx - w, mx + w + 1):
            inside = 0 <= gx < nx and 0 <= gy < ny
            if inside:
                if not occ[gy, gx]:
                    continue
            elif not outside_occupied:
                continue
            d = segment_rect_distance(ax, ay, bx, by, float(gx), float(gy), gx + 1.0, gy + 1.0)
            if d < best:
                best = d
    return best


@njit(cache=True)
def _polyline_kernel(q, occ, cap, outside_occupied):  # pragma: no cover - compiled
    """Least :func:`segment_squares_distance` over the pieces.

    Least :func:`segment_squares_distance` over the pieces (at most one cell long) of the
    polyline ``q`` (cells).
    """
    w = int(math.ceil(cap)) + 2
    best = cap
    for i in range(q.shape[0] - 1):
        dx = q[i + 1, 0] - q[i, 0]
        dy = q[i + 1, 1] - q[i, 1]
        n = max(1, int(math.ceil(math.sqrt(dx * dx + dy * dy))))
        for k in range(n):
            ax = q[i, 0] + dx * (k / n)
            ay = q[i, 1] + dy * (k / n)
            bx = q[i, 0] + dx * ((k + 1) / n)
            by = q[i, 1] + dy * ((k + 1) / n)
            d = segment_squares_distance(ax, ay, bx, by, occ, w, best, outside_occupied)
            if d < best:
                best = d
    return best


# ================================================================= metres
def grid_cells(grid: Any) -> tuple[np.ndarray, float, float, float]:
    """``(occupied, resolution, ox, oy)`` of a grid.

    The one place that reads a map's cell geometry for the distances here.

    Raises
    ------
    InvalidInputError
        ``grid`` is not an occupancy grid (no 2-D ``occupied``, ``resolution``, ``origin``).
    """
    try:
        occ = np.ascontiguousarray(grid.occupied, dtype=np.bool_)
        res = float(grid.resolution)
        ox, oy = (float(v) for v in grid.origin)
    except (AttributeError, TypeError, ValueError) as exc:
        raise InvalidInputError(
            f"raw_grid must be an astar.OccupancyGrid, got {type(grid).__name__}"
        ) from exc
    if occ.ndim != 2:
        raise InvalidInputError(f"raw_grid.occupied must be 2-D, got shape {occ.shape}")
    return occ, res, ox, oy


def points_clearance(points: np.ndarray, grid: Any, window_m: float) -> np.ndarray:
    """Distance (m) from each point to the nearest occupied square of ``grid``.

    Distance (m) from each point to the nearest occupied square of ``grid`` (the outside of the
    map counts as occupied), searched within ``window_m``: points with nothing occupied that
    close get ``window_m``.

    Parameters
    ----------
    points : array_like, shape (M, 2)
        World points (m).
    grid : astar.OccupancyGrid
        The raw map.
    window_m : float
        Search distance (m), > 0.

    Returns
    -------
    ndarray, shape (M,)
    """
    occ, res, ox, oy = grid_cells(grid)
    q = (np.asarray(points, dtype=float).reshape(-1, 2) - [ox, oy]) / res
    w = int(math.ceil(window_m / res)) + 1
    out = _points_clearance_kernel(np.ascontiguousarray(q), occ, w, float(window_m) / res)
    return np.minimum(out * res, window_m)


def min_points_clearance(points: np.ndarray, grid: Any, window_m: float) -> float:
    """Least :func:`points_clearance` of a dense sequence of points (m), exactly.

    Equal to ``points_clearance(points, grid, window_m).min()``, found faster: consecutive
    points are close, and a point cannot be nearer an obstacle than the previous point's
    distance minus the step between them, so most points of a sequence that stays clear
    are never searched. A searched point visits blocks of :data:`CLEARANCE_BLOCK` cells in
    rings around it and measures only the cells of occupied blocks, so its cost follows
    the obstacles near it, not the cell count. The search itself reaches ``2 window_m``
    (the points' lower bounds then start higher, and more of them are skipped); the result
    is capped at ``window_m``.

    Parameters
    ----------
    points : array_like, shape (M, 2)
        World points (m), in order along a curve (any order is correct; an ordered dense
        sequence is fast).
    grid : astar.OccupancyGrid
        The raw map (outside occupied).
    window_m : float
        Cap (m), > 0.

    Returns
    -------
    float
        ``min(window_m, least distance)`` (m).
    """
    occ, res, ox, oy = grid_cells(grid)
    q = (np.asarray(points, dtype=float).reshape(-1, 2) - [ox, oy]) / res
    if len(q) == 0:
        return float(window_m)
    reach = 2.0 * float(window_m) / res
    blk = occupied_blocks(occ)
    best = _min_clearance_kernel(np.ascontiguousarray(q), occ, blk, CLEARANCE_BLOCK, reach)
    return min(best * res, float(window_m))


def polyline_clearance(
    points: Any, raw_grid: Any, *, window_m: float, outside_occupied: bool = True
) -> float:
    """Exact distance (m) from a polyline to the nearest occupied square of a grid.

    Every segment is cut into pieces no longer than one cell; for each piece the exact
    segment-to-square distance (0 when they meet) is taken over the occupied cells (and,
    with ``outside_occupied``, the cells outside the map) within ``window_m`` of it.

    Parameters
    ----------
    points : array_like, shape (n, 2)
        Vertices (m), n >= 1.
    raw_grid : astar.OccupancyGrid
        The map, obstacles as closed squares of side ``resolution``.
    window_m : float
        Search distance (m); the result is capped at it (nothing occupied that close).
    outside_occupied : bool
        Count the cells outside the map as occupied.

    Returns
    -------
    float
        ``min(clearance, window_m)`` (m).
    """
    occ, res, ox, oy = grid_cells(raw_grid)
    q = (np.asarray(points, dtype=float).reshape(-1, 2) - [ox, oy]) / res
    if len(q) == 1:
        q = np.vstack([q, q])
    cap = float(window_m) / res
    best = _polyline_kernel(np.ascontiguousarray(q), occ, cap, bool(outside_occupied))
    return min(best, cap) * res


def polygon_clearance(polygon: Any, raw_grid: Any) -> float:
    """Exact distance (m) from a convex polygon to a raw map's obstacles.

    Parameters
    ----------
    polygon : ConvexPolygon or array_like, shape (k, 2)
        A region (anything with ``vertices``), or its vertices (m) in order around it
        (``k = 1`` a point, ``k = 2`` a segment).
    raw_grid : astar.OccupancyGrid
        The raw map: occupied cells are closed squares; the outside of the map counts as
        occupied.

    Returns
    -------
    float
        ``0`` when the polygon meets an occupied square or leaves the map; otherwise the
        smallest distance to an occupied square or to the map's boundary: for each square
        decided by the separating-axis theorem and measured as the minimum of the
        vertex-to-edge distances both ways (two disjoint convex polygons are closest at a
        vertex of one of them).
    """
    occ, res, ox, oy = grid_cells(raw_grid)
    v = np.asarray(getattr(polygon, "vertices", polygon), dtype=float)
    if v.ndim != 2 or v.shape[1] != 2 or v.shape[0] < 1 or not np.all(np.isfinite(v)):
        raise InvalidInputError(f"polygon vertices must be finite, shape (k, 2); got {v.shape}")
    vc = np.ascontiguousarray((v - np.array([ox, oy])) / res)
    ny, nx = occ.shape
    border = float(
        max(0.0, min(vc[:, 0].min(), nx - vc[:, 0].max(), vc[:, 1].min(), ny - vc[:, 1].max()))
    )
    if border == 0.0:
        return 0.0
    x0, x1 = vc[:, 0].min(), vc[:, 0].max()
    y0, y1 = vc[:, 1].min(), vc[:, 1].max()
    pad = 2.0
    while True:
        wx0, wx1 = max(0, int(math.floor(x0 - pad))), min(nx, int(math.ceil(x1 + pad)))
        wy0, wy1 = max(0, int(math.floor(y0 - pad))), min(ny, int(math.ceil(y1 + pad)))
        rects = window_rects(occ, wx0, wx1, wy0, wy1)
        best = min(border, polygon_rects_distance(vc, len(vc), rects) if len(rects) else math.inf)
        whole = wx0 == 0 and wy0 == 0 and wx1 == nx and wy1 == ny
        if best <= pad or whole:
            return best * res
        pad = max(4.0 * pad, best)


def box_clearance(grid: Any, lo: np.ndarray, hi: np.ndarray) -> float:
    """Exact distance (m) from the axis-aligned box ``[lo, hi]``.

    Exact distance (m) from the axis-aligned box ``[lo, hi]`` (a point when ``lo == hi``) to the
    nearest occupied square or the outside of the map.
    """
    lo = np.asarray(lo, dtype=float)
    hi = np.asarray(hi, dtype=float)
    if np.array_equal(lo, hi):
        return polygon_clearance(lo.reshape(1, 2), grid)
    corners = np.array([[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]])
    return polygon_clearance(corners, grid)
