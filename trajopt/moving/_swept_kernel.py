"""The compiled loop that marks a mover's swept region on a grid: :func:`capsule_kernel`.

:func:`trajopt.moving.swept_mask` and :func:`trajopt.moving.reached_swept_mask` mark the
cells whose square comes within a radius of a segment of the mover's track (its capsules);
this kernel visits each segment's bounding box of cells once: a cell whose centre is within
the radius is marked, one whose centre is farther than the radius plus half the cell's
diagonal is not, and one between is decided by the exact distance from the segment to the
cell's square (:func:`square_segment_distance`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from trajopt.kernel_cache import watch_compiles

watch_compiles()  # a first compilation logs one notice (trajopt.kernel_cache)


@njit(cache=True, inline="always")
def square_segment_distance(cx, cy, h, ax, ay, bx, by):  # pragma: no cover - compiled
    """Return the distance (m) from the segment ``[a, b]`` (m) to the square of centre ``c``.

    The square is axis-aligned with half side ``h`` (m). 0 when they meet (the segment
    clipped to the square's slabs is not empty); else two disjoint convex sets are closest at
    a vertex of one of them: the nearer of the segment's ends to the square and the square's
    corners to the segment.
    """
    px, py, qx, qy = ax - cx, ay - cy, bx - cx, by - cy
    dx, dy = qx - px, qy - py
    lo, hi = 0.0, 1.0
    if dx == 0.0:
        if abs(px) > h:
            hi = -1.0
    else:
        t1, t2 = (-h - px) / dx, (h - px) / dx
        lo, hi = max(lo, min(t1, t2)), min(hi, max(t1, t2))
    if dy == 0.0:
        if abs(py) > h:
            hi = -1.0
    else:
        t1, t2 = (-h - py) / dy, (h - py) / dy
        lo, hi = max(lo, min(t1, t2)), min(hi, max(t1, t2))
    if lo <= hi:
        return 0.0
    best = min(
        math.hypot(max(abs(px) - h, 0.0), max(abs(py) - h, 0.0)),
        math.hypot(max(abs(qx) - h, 0.0), max(abs(qy) - h, 0.0)),
    )
    dd = dx * dx + dy * dy
    for sx in (-h, h):
        for sy in (-h, h):
            lam = 0.0
            if dd > 0.0:
                lam = min(max(((sx - px) * dx + (sy - py) * dy) / dd, 0.0), 1.0)
            best = min(best, math.hypot(sx - px - lam * dx, sy - py - lam * dy))
    return best


@njit(cache=True)
def capsule_kernel(
    ox, oy, res, nx, ny, a, b, radius, ta, tb, origin, speed, slack, timed, late_factor, late_s
):  # pragma: no cover - compiled
    """Return the cells (bool, shape (ny, nx)) whose square comes within ``radius`` of a segment.

    Parameters
    ----------
    ox, oy, res : float
        The cells' origin (m) and size (m): cell ``(ix, iy)`` has its centre at
        ``(ox + (ix + 0.5) res, oy + (iy + 0.5) res)``.
    nx, ny : int
        The cell counts.
    a, b : ndarray, shape (k, 2)
        The segments' ends (m).
    radius : float
        The capsules' radius (m): a cell is marked when its square (side ``res``) comes
        within it of a segment.
    ta, tb : ndarray, shape (k,)
        With ``timed``: the times (s) a point moving linearly along segment ``i`` is at
        ``a_i`` and at ``b_i`` (``tb`` inf: it stands at ``a_i = b_i`` for ever).
    origin : ndarray, shape (2,)
        With ``timed``: where the robot starts (m).
    speed, slack : float
        With ``timed``: the robot's top speed (m/s) and a distance (m).
    timed : bool
        Mark a hit cell only when ``|centre - origin| - slack - res / sqrt(2) <= speed * t``,
        ``t`` the last time in ``[ta_i, tb_i]`` the point is within ``radius + res / sqrt(2)``
        of the centre (no later than the last time it is within ``radius`` of the square).
    late_factor, late_s : float
        With ``timed`` and ``late_factor > 0``: also only when the first such time (no later
        than the first time within ``radius`` of the square) is at most ``late_factor
        (|centre - origin| + slack + res / sqrt(2)) / speed + late_s`` (s).

    Returns
    -------
    ndarray of bool, shape (ny, nx)
    """
    mask = np.zeros((ny, nx), dtype=np.bool_)
    half_diag = res * math.sqrt(0.5)
    outer = radius + half_diag  # no centre farther than this has its square within radius
    r2, outer2 = radius * radius, outer * outer
    for i in range(a.shape[0]):
        ax, ay, bx, by = a[i, 0], a[i, 1], b[i, 0], b[i, 1]
        ix0 = max(0, int(math.floor((min(ax, bx) - outer - ox) / res)))
        ix1 = min(nx - 1, int(math.floor((max(ax, bx) + outer - ox) / res)))
        iy0 = max(0, int(math.floor((min(ay, by) - outer - oy) / res)))
        iy1 = min(ny - 1, int(math.floor((max(ay, by) + outer - oy) / res)))
        dx, dy = bx - ax, by - ay
        dd = dx * dx + dy * dy
        inv = 1.0 / dd if dd > 0.0 else 0.0
        forever = math.isinf(tb[i])
        for iy in range(iy0, iy1 + 1):
            cy = oy + (iy + 0.5) * res
            py = cy - ay
            for ix in range(ix0, ix1 + 1):
                if mask[iy, ix]:  # marked by an earlier segment
                    continue
                cx = ox + (ix + 0.5) * res
                px = cx - ax
                along = (px * dx + py * dy) * inv
                lam = min(max(along, 0.0), 1.0)
                ex, ey = px - lam * dx, py - lam * dy
                dc2 = ex * ex + ey * ey
                if dc2 > outer2:
                    continue
                if timed:  # the times the point is within outer of the centre: cheap first
                    root = 0.0
                    if dd > 0.0:
                        off = (px * dy - py * dx) ** 2 * inv
                        root = math.sqrt(max(outer2 - off, 0.0) * inv)
                    last = math.inf
                    if not forever:
                        mu = min(1.0, along + root) if dd > 0.0 else 1.0
                        last = ta[i] + mu * (tb[i] - ta[i])
                    dist = math.hypot(cx - origin[0], cy - origin[1])
                    if dist - slack - half_diag > speed * last:
                        continue
                    if late_factor > 0.0:
                        first = ta[i]
                        if not forever and dd > 0.0:
                            first = ta[i] + max(0.0, along - root) * (tb[i] - ta[i])
                        if first > late_factor * (dist + slack + half_diag) / speed + late_s:
                            continue
                if dc2 > r2 and (
                    square_segment_distance(cx, cy, 0.5 * res, ax, ay, bx, by) > radius
                ):
                    continue
                mask[iy, ix] = True
    return mask
