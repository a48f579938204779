"""Compiled kernels of the footprint certificate: heading cones, swept hulls, span margins.

:func:`span_margins` runs the whole per-span check of
:func:`trajopt.robot._footprint.certify_footprint` in one call: the hodograph's heading cone of a
Bezier piece, the footprint swept over it (:func:`swept_hull`), the Minkowski sum with the
piece's control points, its exact clearance from the obstacle index, and the halvings of a
piece that is not clear. Units are whatever the caller passes (the certificate uses cells).
:func:`span_margins_polygons` is the same check against obstacle polygons (exact
convex-polygon-to-polygon distances, :func:`astar.body_polygons.body_distance`) and the
outside of a rectangle, for maps that know the polygons their cells were rasterised from.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from astar.body_polygons import body_distance
from trajopt.geometry import monotone_chain, poly_clearance, sort_xy
from trajopt.kernel_cache import watch_compiles

TWO_PI = 2.0 * math.pi


watch_compiles()  # a first compilation logs one notice (trajopt.kernel_cache)


@njit(cache=True)
def cone(d):  # pragma: no cover - compiled
    """Return the heading interval ``(lo, hi)`` (rad) spanned by direction vectors ``d`` (m, 2).

    Vectors shorter than 1e-15 are ignored. The whole circle (``hi - lo = 2 pi``) when the
    rest do not fit in an open half-plane, or none is left.
    """
    ref = 0.0
    lo = hi = 0.0
    seen = False
    for i in range(d.shape[0]):
        if math.hypot(d[i, 0], d[i, 1]) <= 1e-15:
            continue
        ang = math.atan2(d[i, 1], d[i, 0])
        if not seen:
            ref = ang
            seen = True
        x = ang - ref + math.pi
        rel = x - TWO_PI * math.floor(x / TWO_PI) - math.pi
        lo = min(lo, rel)
        hi = max(hi, rel)
    if not seen:
        return -math.pi, math.pi
    if hi - lo >= math.pi - 1e-12:
        return ref - math.pi, ref + math.pi
    return ref + lo, ref + hi


@njit(cache=True)
def hull_of(pts, n):  # pragma: no cover - compiled
    """Return the convex hull of the first ``n`` rows of ``pts`` (m, 2), counter-clockwise.

    ``pts[:n]`` is sorted in place by ``(x, y)`` (:func:`~trajopt.geometry._convex_hull.sort_xy`).
    """
    sort_xy(pts, n)
    h, k = monotone_chain(pts, n, 0.0)
    m = max(k - 1, 1)
    out = np.empty((m, 2))
    for i in range(m):
        out[i, 0] = pts[h[i], 0]
        out[i, 1] = pts[h[i], 1]
    return out


@njit(cache=True)
def swept_hull(rho, phi, lo, hi, max_arc):  # pragma: no cover - compiled
    """Return a convex polygon holding the footprint rotated by every angle in ``[lo, hi]``.

    The footprint's vertices in polar form (``rho``, ``phi``); each vertex's arc is bounded
    by its outer tangent polygon: arc points every ``step <= max_arc`` and the tangent
    intersections between them (at ``rho / cos(step / 2)``). A span of ``2 pi`` or more
    covers the whole circle.
    """
    span = min(hi - lo, TWO_PI)
    n = max(1, math.ceil(span / max_arc - 1e-12))
    step = span / n
    grow = 1.0 / math.cos(0.5 * step) if step > 0 else 1.0
    nv = rho.shape[0]
    per = 2 * n + 1 if step > 0 else n + 1
    pts = np.empty((nv * per, 2))
    m = np.int64(0)  # not a literal 0: one compiled signature of hull_of
    for i in range(nv):
        for a in range(n + 1):
            ang = phi[i] + lo + step * a
            pts[m, 0] = rho[i] * math.cos(ang)
            pts[m, 1] = rho[i] * math.sin(ang)
            m += 1
        if step > 0:
            for a in range(n):
                ang = phi[i] + lo + step * (a + 0.5)
                pts[m, 0] = rho[i] * grow * math.cos(ang)
                pts[m, 1] = rho[i] * grow * math.sin(ang)
                m += 1
    return hull_of(pts, m)


@njit(cache=True)
def _piece_bound(bez, rho, phi, max_arc):  # pragma: no cover - compiled
    """Return the convex bound (counter-clockwise) of the footprint over one Bezier piece."""
    p1 = bez.shape[0]
    lo, hi = cone(bez[1:] - bez[:-1])
    sw = swept_hull(rho, phi, lo, hi, max_arc)
    ns = sw.shape[0]
    pts = np.empty((p1 * ns, 2))
    for i in range(p1):
        for j in range(ns):
            pts[i * ns + j, 0] = bez[i, 0] + sw[j, 0]
            pts[i * ns + j, 1] = bez[i, 1] + sw[j, 1]
    return hull_of(pts, p1 * ns)


@njit(cache=True)
def _piece_margin(bez, rho, phi, max_arc, cap, rects, meta, bstart, bids, stamp, buf):
    """Clearance of one Bezier piece's bound (its control hull plus the swept footprint)."""  # noqa: D401
    poly = _piece_bound(bez, rho, phi, max_arc)
    return poly_clearance(poly, poly.shape[0], cap, rects, meta, bstart, bids, stamp, buf)


@njit(cache=True)
def _halve(cur, stack, top, work):  # pragma: no cover - compiled
    """Split the Bezier piece ``cur`` at 1/2 (de Casteljau): left half to ``stack[top]``, right half to ``stack[top + 1]``."""
    p1 = cur.shape[0]
    for r in range(p1):  # element copies: no shape-mismatch error code
        work[r, 0] = cur[r, 0]
        work[r, 1] = cur[r, 1]
    for r in range(p1):
        for c in range(2):
            stack[top, r, c] = work[0, c]
            stack[top + 1, p1 - 1 - r, c] = work[p1 - 1 - r, c]
        for i in range(p1 - 1 - r):
            for c in range(2):
                work[i, c] = 0.5 * (work[i, c] + work[i + 1, c])


@njit(cache=True)
def span_margins(
    bez, rho, phi, max_arc, cap, tol, max_depth, rects, meta, bstart, bids, stamp, buf
):  # pragma: no cover - compiled
    """Return every piece's margin and heading interval.

    Parameters
    ----------
    bez : ndarray, shape (m, p + 1, 2)
        Bezier control points of the pieces, relative to the map's origin.
    rho, phi : ndarray, shape (k,)
        The footprint's vertices in polar form (same length unit as ``bez``; rad).
    max_arc : float
        Largest arc piece of :func:`swept_hull` (rad).
    cap : float
        Clearances beyond it are reported as ``cap``.
    tol : float
        A piece whose margin exceeds it is clear; otherwise it is halved (de Casteljau),
        down to ``max_depth`` halvings, and the margin is the smallest of its leaves.
    rects, meta, bstart, bids, stamp, buf
        The obstacle index (:class:`trajopt.geometry._obstacle_index.ObstacleIndex`).

    Returns
    -------
    margins : ndarray, shape (m,)
    heads : ndarray, shape (m, 2)
        The heading interval (rad) of each whole piece's hodograph.
    """
    m, p1 = bez.shape[0], bez.shape[1]
    margins = np.empty(m)
    heads = np.empty((m, 2))
    stack = np.empty((max_depth + 2, p1, 2))
    depth = np.empty(max_depth + 2, dtype=np.int64)
    work = np.empty((p1, 2))
    for s in range(m):
        lo, hi = cone(bez[s, 1:] - bez[s, :-1])
        heads[s, 0], heads[s, 1] = lo, hi
        for r in range(p1):  # element copies here and below: no shape-mismatch error code
            stack[0, r, 0] = bez[s, r, 0]
            stack[0, r, 1] = bez[s, r, 1]
        depth[0] = 0
        top = 1
        worst = np.inf
        while top > 0:
            top -= 1
            cur = stack[top].copy()
            d = depth[top]
            g = _piece_margin(cur, rho, phi, max_arc, cap, rects, meta, bstart, bids, stamp, buf)
            if g > tol or d == max_depth:
                worst = min(worst, g)
                continue
            _halve(cur, stack, top, work)
            depth[top] = depth[top + 1] = d + 1
            top += 2
        margins[s] = worst
    return margins, heads


@njit(cache=True)
def _piece_margin_polygons(bez, rho, phi, max_arc, cap, edges, starts, boxes, box):
    """Clearance of one piece's bound from the polygons and the outside of ``box``."""  # noqa: D401
    poly = _piece_bound(bez, rho, phi, max_arc)
    g = cap
    for i in range(poly.shape[0]):  # the outside of the box: a vertex's room to each side
        x = poly[i, 0]
        y = poly[i, 1]
        g = min(g, x - box[0], box[2] - x, y - box[1], box[3] - y)
    if g <= 0.0:
        return 0.0
    return min(g, body_distance(edges, starts, boxes, poly, g))


@njit(cache=True)
def span_margins_polygons(
    bez, rho, phi, max_arc, cap, tol, max_depth, edges, starts, boxes, box
):  # pragma: no cover - compiled
    """Return every piece's margin and heading interval against polygons.

    As :func:`span_margins`, the obstacles being the polygons ``edges, starts, boxes``
    (:func:`astar.body_polygons.pack_polygons`, in the units of ``bez``) and the outside of
    ``box`` (``xmin, ymin, xmax, ymax``): a piece's margin is the exact distance of its
    bound (the Minkowski sum of its control points' hull and the swept footprint, convex)
    to the nearest polygon (0 when they meet, touching counts) or to the box's boundary (0
    when a vertex of the bound leaves the box), capped at ``cap``.
    """
    m, p1 = bez.shape[0], bez.shape[1]
    margins = np.empty(m)
    heads = np.empty((m, 2))
    stack = np.empty((max_depth + 2, p1, 2))
    depth = np.empty(max_depth + 2, dtype=np.int64)
    work = np.empty((p1, 2))
    for s in range(m):
        lo, hi = cone(bez[s, 1:] - bez[s, :-1])
        heads[s, 0], heads[s, 1] = lo, hi
        for r in range(p1):
            stack[0, r, 0] = bez[s, r, 0]
            stack[0, r, 1] = bez[s, r, 1]
        depth[0] = 0
        top = 1
        worst = np.inf
        while top > 0:
            top -= 1
            cur = stack[top].copy()
            d = depth[top]
            g = _piece_margin_polygons(cur, rho, phi, max_arc, cap, edges, starts, boxes, box)
            if g > tol or d == max_depth:
                worst = min(worst, g)
                continue
            _halve(cur, stack, top, work)
            depth[top] = depth[top + 1] = d + 1
            top += 2
        margins[s] = worst
    return margins, heads
