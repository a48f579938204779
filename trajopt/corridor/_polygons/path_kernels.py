"""Compiled kernels that prepare the polygon corridor's path (cell units).

Clearances of its points and segments, centring it away from walls, simplifying it, and the
extensions of its junctions.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from trajopt.geometry import monotone_chain, point_nearest, poly_clearance, seg_clearance, sort_xy
from trajopt.kernel_cache import watch_compiles

watch_compiles()  # a first compilation logs one notice (trajopt.kernel_cache)


@njit(cache=True)
def hull4(pts, n, out):  # pragma: no cover - compiled
    """Convex hull (counter-clockwise, no collinear points) of ``pts[:n]``.

    For ``n <= 8`` points, written into ``out``; returns its vertex count (1 for a point, 2
    for a segment).
    """
    p = np.empty((n, 2))
    for i in range(n):
        p[i, 0] = pts[i, 0]
        p[i, 1] = pts[i, 1]
    sort_xy(p, n)
    idx, k = monotone_chain(p, n, 1e-12)
    k -= 1  # the last point repeats the first
    # drop duplicates (a point or a segment)
    m = 0
    for i in range(max(k, 1)):
        qx = p[idx[i], 0]
        qy = p[idx[i], 1]
        if m > 0 and abs(qx - out[m - 1, 0]) <= 1e-12 and abs(qy - out[m - 1, 1]) <= 1e-12:
            continue
        out[m, 0] = qx  # element copies: no shape-mismatch error code to compile
        out[m, 1] = qy
        m += 1
    if (
        m > 1
        and abs(out[m - 1, 0] - out[0, 0]) <= 1e-12
        and abs(out[m - 1, 1] - out[0, 1]) <= 1e-12
    ):
        m -= 1
    return m


@njit(cache=True)
def path_clearances(p, cap, rects, meta, bstart, bids, stamp, buf):  # pragma: no cover
    """Clearance (capped) of every path point and every segment ``p[i] -> p[i + 1]``."""
    n = p.shape[0]
    pc = np.empty(n)
    sc = np.empty(max(n - 1, 0))
    for i in range(n):
        pc[i], _, _ = point_nearest(p[i, 0], p[i, 1], cap, rects, meta, bstart, bids, stamp, buf)
    for i in range(n - 1):
        sc[i] = seg_clearance(
            p[i, 0], p[i, 1], p[i + 1, 0], p[i + 1, 1], cap, rects, meta, bstart, bids, stamp, buf
        )
    return pc, sc


@njit(cache=True)
def centre_path(
    p, r, push, trigger, passes, rects, meta, bstart, bids, stamp, buf
):  # pragma: no cover
    """Push interior path points away from their nearest obstacle (at most ``push``).

    A point whose clearance is below ``r + trigger`` moves along the direction away from
    its nearest obstacle point by the step in ``(push, push/2, push/4)`` that raises its
    clearance most, provided both segments to its neighbours keep at least
    ``min(r, their clearance before)``. The end points never move.
    """
    q = p.copy()
    n = q.shape[0]
    cap = r + trigger + push + 1.0
    for _ in range(passes):
        for i in range(1, n - 1):
            d0, ox, oy = point_nearest(
                q[i, 0], q[i, 1], r + trigger, rects, meta, bstart, bids, stamp, buf
            )
            if d0 >= r + trigger or d0 <= 0.0:
                continue
            gx = (q[i, 0] - ox) / d0
            gy = (q[i, 1] - oy) / d0
            s_prev = seg_clearance(
                q[i - 1, 0],
                q[i - 1, 1],
                q[i, 0],
                q[i, 1],
                r + 1.0,
                rects,
                meta,
                bstart,
                bids,
                stamp,
                buf,
            )
            s_next = seg_clearance(
                q[i, 0],
                q[i, 1],
                q[i + 1, 0],
                q[i + 1, 1],
                r + 1.0,
                rects,
                meta,
                bstart,
                bids,
                stamp,
                buf,
            )
            need_prev = min(r, s_prev)
            need_next = min(r, s_next)
            best = d0 + 1e-6
            bx = q[i, 0]
            by = q[i, 1]
            moved = False
            step = push
            for _k in range(3):
                cx = q[i, 0] + step * gx
                cy = q[i, 1] + step * gy
                step *= 0.5
                dc, _, _ = point_nearest(cx, cy, cap, rects, meta, bstart, bids, stamp, buf)
                if dc <= best:
                    continue
                if (
                    seg_clearance(
                        q[i - 1, 0],
                        q[i - 1, 1],
                        cx,
                        cy,
                        need_prev + 1e-3,
                        rects,
                        meta,
                        bstart,
                        bids,
                        stamp,
                        buf,
                    )
                    < need_prev
                ):
                    continue
                if (
                    seg_clearance(
                        cx,
                        cy,
                        q[i + 1, 0],
                        q[i + 1, 1],
                        need_next + 1e-3,
                        rects,
                        meta,
                        bstart,
                        bids,
                        stamp,
                        buf,
                    )
                    < need_next
                ):
                    continue
                best = dc
                bx = cx
                by = cy
                moved = True
            if moved:
                q[i, 0] = bx
                q[i, 1] = by
    return q


@njit(cache=True)
def simplify_path(
    p, pc, sc, r, slack, open_c, max_len, rects, meta, bstart, bids, stamp, buf
):  # pragma: no cover
    """Greedy simplification: indices of the kept points (first and last included).

    From each kept point the segment is extended to the farthest later point such that the
    direct segment keeps a clearance of at least
    ``max(min(floor, r + open_c) - slack, min(floor, r))``, where ``floor`` is the smallest
    clearance of the points and segments it replaces, and is at most ``max_len`` long.
    """
    n = p.shape[0]
    keep = np.empty(n, np.int64)
    m = 0
    keep[m] = 0
    m += 1
    i = 0
    while i < n - 1:
        j = i + 1
        floor = min(pc[i], pc[j], sc[i])
        while j + 1 < n:
            dx = p[j + 1, 0] - p[i, 0]
            dy = p[j + 1, 1] - p[i, 1]
            if dx * dx + dy * dy > max_len * max_len:
                break
            f2 = min(floor, pc[j + 1], sc[j])
            thr = max(min(f2, r + open_c) - slack, min(f2, r))
            c = seg_clearance(
                p[i, 0],
                p[i, 1],
                p[j + 1, 0],
                p[j + 1, 1],
                thr + 1e-3,
                rects,
                meta,
                bstart,
                bids,
                stamp,
                buf,
            )
            if c < thr:
                break
            j += 1
            floor = f2
        keep[m] = j
        m += 1
        i = j
    return keep[:m].copy()


@njit(cache=True)
def seed_points(p, e, k, out):  # pragma: no cover - compiled
    """Seed points of region ``k``.

    Its segment plus ``e[k]`` of the previous segment and ``e[k + 1]`` of the next one; returns
    the hull's vertex count (into ``out``).
    """
    pts = np.empty((4, 2))
    n = 0
    ax, ay = p[k, 0], p[k, 1]
    bx, by = p[k + 1, 0], p[k + 1, 1]
    if e[k] > 0.0:
        dx = p[k - 1, 0] - ax
        dy = p[k - 1, 1] - ay
        ll = math.sqrt(dx * dx + dy * dy)
        pts[n, 0] = ax + e[k] * dx / ll
        pts[n, 1] = ay + e[k] * dy / ll
        n += 1
    pts[n, 0] = ax
    pts[n, 1] = ay
    n += 1
    pts[n, 0] = bx
    pts[n, 1] = by
    n += 1
    if e[k + 1] > 0.0:
        dx = p[k + 2, 0] - bx
        dy = p[k + 2, 1] - by
        ll = math.sqrt(dx * dx + dy * dy)
        pts[n, 0] = bx + e[k + 1] * dx / ll
        pts[n, 1] = by + e[k + 1] * dy / ll
        n += 1
    return hull4(pts, n, out)


@njit(cache=True)
def junction_extensions(p, ext, r, tol, rects, meta, bstart, bids, stamp, buf):  # pragma: no cover
    """How far (cells) each region's seed reaches into its neighbours' segments.

    ``e[j]`` (``j`` = interior vertex) starts at ``min(ext, 0.45 * both segment lengths)``
    and is halved (then zeroed) while a seed hull that uses it comes closer than
    ``min(r, segment clearance) - tol`` to an obstacle.
    """
    m = p.shape[0] - 1
    e = np.zeros(m + 1)
    seglen = np.empty(m)
    for k in range(m):
        seglen[k] = math.sqrt((p[k + 1, 0] - p[k, 0]) ** 2 + (p[k + 1, 1] - p[k, 1]) ** 2)
    for j in range(1, m):
        e[j] = min(ext, 0.45 * seglen[j - 1], 0.45 * seglen[j])
    hull = np.empty((8, 2))
    for k in range(m):
        need = (
            min(
                r,
                seg_clearance(
                    p[k, 0],
                    p[k, 1],
                    p[k + 1, 0],
                    p[k + 1, 1],
                    r + 1.0,
                    rects,
                    meta,
                    bstart,
                    bids,
                    stamp,
                    buf,
                ),
            )
            - tol
        )
        for attempt in range(6):
            if e[k] == 0.0 and e[k + 1] == 0.0:
                break
            nh = seed_points(p, e, k, hull)
            if poly_clearance(hull, nh, r + 1.0, rects, meta, bstart, bids, stamp, buf) >= need:
                break
            if attempt == 4:
                e[k] = 0.0
                e[k + 1] = 0.0
            else:
                e[k] *= 0.5
                e[k + 1] *= 0.5
    return e
