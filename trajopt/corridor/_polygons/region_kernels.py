"""Compiled kernels that grow the polygon corridor's regions.

They work in cell units and compute the chain's geometry: clipping, region growth around
each path segment, the path interval inside each region, the overlaps, and the regions'
exact clearance.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from trajopt.corridor._polygons.path_kernels import seed_points
from trajopt.geometry import (
    gather,
    point_segment_distance,
    poly_clearance,
    polygon_rect_closest,
    segment_rect_distance,
)
from trajopt.kernel_cache import watch_compiles

watch_compiles()  # a first compilation logs one notice (trajopt.kernel_cache)


@njit(cache=True)
def _clip(v, lab, nv, a0, a1, b, label, ov, olab):  # pragma: no cover - compiled
    """Clip the labelled convex polygon ``v[:nv]``.

    Clip the labelled convex polygon ``v[:nv]`` (``lab[i]`` = row of edge i -> i + 1) by ``a . p
    <= b``; the new edge gets ``label``. Returns the new vertex count.
    """
    m = 0
    for i in range(nv):
        j = (i + 1) % nv
        si = a0 * v[i, 0] + a1 * v[i, 1] - b
        sj = a0 * v[j, 0] + a1 * v[j, 1] - b
        if si <= 0.0:
            ov[m, 0] = v[i, 0]
            ov[m, 1] = v[i, 1]
            olab[m] = lab[i]
            m += 1
            if sj > 0.0:
                t = si / (si - sj)
                ov[m, 0] = v[i, 0] + t * (v[j, 0] - v[i, 0])
                ov[m, 1] = v[i, 1] + t * (v[j, 1] - v[i, 1])
                olab[m] = label
                m += 1
        elif sj <= 0.0:
            t = si / (si - sj)
            ov[m, 0] = v[i, 0] + t * (v[j, 0] - v[i, 0])
            ov[m, 1] = v[i, 1] + t * (v[j, 1] - v[i, 1])
            olab[m] = lab[i]
            m += 1
    return m


@njit(cache=True)
def _tidy(v, lab, nv):  # pragma: no cover - compiled
    """Drop repeated vertices and straight-angle vertices in place; returns the count."""
    changed = True
    while changed and nv >= 2:
        changed = False
        for i in range(nv):
            j = (i + 1) % nv
            if abs(v[i, 0] - v[j, 0]) <= 1e-12 and abs(v[i, 1] - v[j, 1]) <= 1e-12:
                # zero-length edge i: remove vertex i (vertex j keeps its own edge)
                for k in range(i, nv - 1):
                    v[k, 0] = v[k + 1, 0]
                    v[k, 1] = v[k + 1, 1]
                    lab[k] = lab[k + 1]
                nv -= 1
                changed = True
                break
        if changed or nv < 3:
            continue
        for i in range(nv):
            h = (i - 1) % nv
            j = (i + 1) % nv
            cr = (v[i, 0] - v[h, 0]) * (v[j, 1] - v[i, 1]) - (v[i, 1] - v[h, 1]) * (
                v[j, 0] - v[i, 0]
            )
            if abs(cr) <= 1e-14:
                # straight angle at i: the merged edge h -> j keeps edge h's row
                for k in range(i, nv - 1):
                    v[k, 0] = v[k + 1, 0]
                    v[k, 1] = v[k + 1, 1]
                    lab[k] = lab[k + 1]
                nv -= 1
                changed = True
                break
    return nv


@njit(cache=True)
def _area(v, nv):  # pragma: no cover - compiled
    s = 0.0
    for i in range(nv):
        j = (i + 1) % nv
        s += v[i, 0] * v[j, 1] - v[j, 0] * v[i, 1]
    return 0.5 * s


@njit(cache=True)
def grow_region(
    seed,
    ns,
    p0x,
    p0y,
    p1x,
    p1y,
    ext,
    r,
    margin,
    rects,
    meta,
    bstart,
    bids,
    stamp,
    buf,
    out_h,
    out_v,
):  # pragma: no cover
    """Grow one convex region around a seed hull (segment-ellipse method).

    Obstacle rectangles near the window (the seed's bounding box plus ``margin``, inside
    the map shrunk by ``r``) are taken in order of their distance to the seed segment's
    midpoint in the metric of an ellipse around the segment; each one not yet excluded adds
    the half-plane tangent to its ``r``-dilation, with the normal of the ellipse's level
    set at the rectangle's nearest point, or, when that cuts the seed, the direction of the
    closest pair between the seed hull and the rectangle. Every rectangle the new
    half-plane keeps ``r`` away is dropped. The window's rows close the region.

    Returns ``(nv, status)``: ``status`` 0 = a polygon of ``nv`` vertices
    (``out_v``, counter-clockwise, ``out_h[i] = (a_x, a_y, b)`` the row of edge
    ``i -> i + 1``), 1 = degenerate (no interior), 2 = the seed meets an obstacle's
    dilation (no half-plane can separate them), 3 = the region lost a seed point.
    """
    nx = meta[5]
    ny = meta[6]
    sx0 = sy0 = np.inf
    sx1 = sy1 = -np.inf
    for i in range(ns):
        sx0 = min(sx0, seed[i, 0])
        sx1 = max(sx1, seed[i, 0])
        sy0 = min(sy0, seed[i, 1])
        sy1 = max(sy1, seed[i, 1])
    wx0 = min(max(sx0 - margin, r), sx0)
    wx1 = max(min(sx1 + margin, nx - r), sx1)
    wy0 = min(max(sy0 - margin, r), sy0)
    wy1 = max(min(sy1 + margin, ny - r), sy1)
    n = gather(wx0 - r, wx1 + r, wy0 - r, wy1 + r, rects, meta, bstart, bids, stamp, buf)
    cand = np.empty(n, np.int64)
    m = 0
    for k in range(n):
        i = buf[k]
        gx = max(rects[i, 0] - wx1, 0.0, wx0 - rects[i, 2])
        gy = max(rects[i, 1] - wy1, 0.0, wy0 - rects[i, 3])
        if gx * gx + gy * gy <= r * r:
            cand[m] = i
            m += 1
    # the ellipse around the seed segment
    cx = 0.5 * (p0x + p1x)
    cy = 0.5 * (p0y + p1y)
    ll = math.sqrt((p1x - p0x) ** 2 + (p1y - p0y) ** 2)
    if ll > 0.0:
        ux = (p1x - p0x) / ll
        uy = (p1y - p0y) / ll
    else:
        ux = 1.0
        uy = 0.0
    vx = -uy
    vy = ux
    cseed = np.inf
    for k in range(m):
        i = cand[k]
        cseed = min(
            cseed,
            segment_rect_distance(
                p0x, p0y, p1x, p1y, rects[i, 0], rects[i, 1], rects[i, 2], rects[i, 3]
            ),
        )
    a1 = 0.5 * ll + ext + 0.5
    a2 = min(a1, max(0.5, cseed))
    md = np.empty(m)
    qq = np.empty((m, 2))
    quad = np.empty((4, 2))
    for k in range(m):
        i = cand[k]
        for c in range(4):
            xx = rects[i, 0] if (c == 0 or c == 3) else rects[i, 2]
            yy = rects[i, 1] if c < 2 else rects[i, 3]
            quad[c, 0] = ((xx - cx) * ux + (yy - cy) * uy) / a1
            quad[c, 1] = ((xx - cx) * vx + (yy - cy) * vy) / a2
        # origin inside the (convex, consistently oriented) quadrilateral?
        pos = 0
        neg = 0
        for c in range(4):
            d = (c + 1) % 4
            cr = quad[c, 0] * quad[d, 1] - quad[c, 1] * quad[d, 0]
            if cr > 0:
                pos += 1
            elif cr < 0:
                neg += 1
        if pos == 0 or neg == 0:
            md[k] = 0.0
            qq[k, 0] = 0.0
            qq[k, 1] = 0.0
            continue
        best = np.inf
        for c in range(4):
            d = (c + 1) % 4
            e, t = point_segment_distance(0.0, 0.0, quad[c, 0], quad[c, 1], quad[d, 0], quad[d, 1])
            if e < best:
                best = e
                qq[k, 0] = quad[c, 0] + t * (quad[d, 0] - quad[c, 0])
                qq[k, 1] = quad[c, 1] + t * (quad[d, 1] - quad[c, 1])
        md[k] = best
    order = np.argsort(md)
    active = np.ones(m, np.bool_)
    h = np.empty((4 + m, 3))
    h[0, 0], h[0, 1], h[0, 2] = 0.0, -1.0, -wy0
    h[1, 0], h[1, 1], h[1, 2] = 1.0, 0.0, wx1
    h[2, 0], h[2, 1], h[2, 2] = 0.0, 1.0, wy1
    h[3, 0], h[3, 1], h[3, 2] = -1.0, 0.0, -wx0
    nh = 4
    for oi in range(m):
        k = order[oi]
        if not active[k]:
            continue
        i = cand[k]
        x0, y0, x1, y1 = rects[i, 0], rects[i, 1], rects[i, 2], rects[i, 3]
        ok = False
        ax = ay = b = 0.0
        if md[k] > 0.0:
            gx = qq[k, 0] / a1 * ux + qq[k, 1] / a2 * vx
            gy = qq[k, 0] / a1 * uy + qq[k, 1] / a2 * vy
            gn = math.sqrt(gx * gx + gy * gy)
            if gn > 0.0:
                ax = gx / gn
                ay = gy / gn
                b = min(ax * x0, ax * x1) + min(ay * y0, ay * y1) - r
                ok = True
                for s in range(ns):
                    if ax * seed[s, 0] + ay * seed[s, 1] > b:
                        ok = False
                        break
        if not ok:
            d, px, py, qx, qy = polygon_rect_closest(seed, ns, x0, y0, x1, y1)
            if not d > 0.0:
                return 0, 2
            ax = (qx - px) / d
            ay = (qy - py) / d
            b = min(ax * x0, ax * x1) + min(ay * y0, ay * y1) - r
        h[nh, 0] = ax
        h[nh, 1] = ay
        h[nh, 2] = b
        nh += 1
        active[k] = False
        for oj in range(oi + 1, m):
            kk = order[oj]
            if not active[kk]:
                continue
            j = cand[kk]
            lo = (
                min(ax * rects[j, 0], ax * rects[j, 2])
                + min(ay * rects[j, 1], ay * rects[j, 3])
                - r
            )
            if lo >= b:
                active[kk] = False
    # clip the window box by the obstacle rows
    cap = nh + 8
    va = np.empty((cap, 2))
    la = np.empty(cap, np.int64)
    vb = np.empty((cap, 2))
    lb = np.empty(cap, np.int64)
    va[0, 0], va[0, 1] = wx0, wy0
    va[1, 0], va[1, 1] = wx1, wy0
    va[2, 0], va[2, 1] = wx1, wy1
    va[3, 0], va[3, 1] = wx0, wy1
    la[0], la[1], la[2], la[3] = 0, 1, 2, 3
    nv = np.int64(4)  # not a literal 4: one compiled signature of _clip
    for row in range(4, nh):
        nv = _clip(va, la, nv, h[row, 0], h[row, 1], h[row, 2], row, vb, lb)
        va, vb = vb, va
        la, lb = lb, la
        if nv == 0:
            break
    nv = _tidy(va, la, nv)
    if nv < 3 or _area(va, nv) <= 1e-9:
        return 0, 1
    for i in range(nv):
        out_v[i, 0] = va[i, 0]
        out_v[i, 1] = va[i, 1]
        out_h[i, 0] = h[la[i], 0]
        out_h[i, 1] = h[la[i], 1]
        out_h[i, 2] = h[la[i], 2]
    # the seed must lie in the region (it does by construction, up to rounding)
    for s in range(ns):
        for i in range(nv):
            if out_h[i, 0] * seed[s, 0] + out_h[i, 1] * seed[s, 1] - out_h[i, 2] > 1e-9:
                return nv, 3
    return nv, 0


@njit(cache=True)
def grow_all(p, e, r, margin, kmax, rects, meta, bstart, bids, stamp, buf):  # pragma: no cover
    """Grow the region of every segment ``p[k] -> p[k + 1]`` of the seed polyline.

    Returns ``(H, V, nv, status)``: rows ``H[k, :nv[k]]`` and vertices ``V[k, :nv[k]]``
    (``kmax`` slots each; status as :func:`grow_region`, 4 = more than ``kmax`` sides).
    """
    m = p.shape[0] - 1
    hh = np.zeros((m, kmax, 3))
    vv = np.zeros((m, kmax, 2))
    nvs = np.zeros(m, np.int64)
    status = np.zeros(m, np.int64)
    seed = np.empty((8, 2))
    oh = np.empty((4 + rects.shape[0] + 8, 3))
    ov = np.empty((4 + rects.shape[0] + 8, 2))
    for k in range(m):
        ns = seed_points(p, e, k, seed)
        ext = max(e[k], e[k + 1])
        nv, st = grow_region(
            seed,
            ns,
            p[k, 0],
            p[k, 1],
            p[k + 1, 0],
            p[k + 1, 1],
            ext,
            r,
            margin,
            rects,
            meta,
            bstart,
            bids,
            stamp,
            buf,
            oh,
            ov,
        )
        if st == 0 and nv > kmax:
            st = 4
        status[k] = st
        if st == 0:
            nvs[k] = nv
            for i in range(nv):  # element copies: no shape-mismatch error code to compile
                for c in range(3):
                    hh[k, i, c] = oh[i, c]
                vv[k, i, 0] = ov[i, 0]
                vv[k, i, 1] = ov[i, 1]
    return hh, vv, nvs, status


@njit(cache=True)
def clip_convex(v, nv, rows, nrows, tol):  # pragma: no cover - compiled
    """Vertices of the convex polygon ``v[:nv]``.

    Vertices of the convex polygon ``v[:nv]`` (or segment, point) clipped by ``rows[i] = (a_x,
    a_y, b)`` with ``a . p <= b + tol``, and for each vertex the row its outgoing edge lies on
    (``-1`` = an edge of ``v``). Returns ``(V, labels, count)``.
    """
    cap = nv + nrows + 4
    va = np.empty((cap, 2))
    la = np.full(cap, -1, np.int64)
    vb = np.empty((cap, 2))
    lb = np.empty(cap, np.int64)
    for i in range(nv):  # element copies: no shape-mismatch error code to compile
        va[i, 0] = v[i, 0]
        va[i, 1] = v[i, 1]
    n = nv
    for i in range(nrows):
        n = _clip(va, la, n, rows[i, 0], rows[i, 1], rows[i, 2] + tol, i, vb, lb)
        va, vb = vb, va
        la, lb = lb, la
        if n == 0:
            break
    n = _tidy(va, la, n)
    return va[:n].copy(), la[:n].copy(), n


@njit(cache=True)
def _seg_inside(rows, nrows, p, i, tol):  # pragma: no cover - compiled
    """Parameter interval ``(t0, t1)`` of segment ``p[i] -> p[i + 1]`` inside the rows.

    ``t0 > t1`` when the segment misses them.
    """
    ax, ay = p[i, 0], p[i, 1]
    dx = p[i + 1, 0] - ax
    dy = p[i + 1, 1] - ay
    t0 = 0.0
    t1 = 1.0
    for j in range(nrows):
        num = rows[j, 2] + tol - rows[j, 0] * ax - rows[j, 1] * ay
        den = rows[j, 0] * dx + rows[j, 1] * dy
        if den == 0.0:
            if num < 0.0:
                return 1.0, 0.0
        elif den > 0.0:
            t1 = min(t1, num / den)
        else:
            t0 = max(t0, num / den)
    return t0, t1


@njit(cache=True)
def polyline_interval(rows, nrows, p, s, s_lo, s_hi, tol):  # pragma: no cover - compiled
    """Return the largest arc-length interval ``[lo, hi]`` of the polyline ``p``.

    The largest arc-length interval ``[lo, hi]`` of the polyline ``p`` (vertex arc lengths
    ``s``) that contains ``[s_lo, s_hi]`` and stays in ``{a . x <= b + tol}``; ``(nan, nan)``
    when ``[s_lo, s_hi]`` itself is not inside.
    """
    n = p.shape[0]
    eps = 1e-12 * max(1.0, s[n - 1])
    i_lo = 0
    while i_lo < n - 2 and s[i_lo + 1] <= s_lo:
        i_lo += 1
    i_hi = i_lo
    while i_hi < n - 2 and s[i_hi + 1] < s_hi:
        i_hi += 1
    for i in range(i_lo, i_hi + 1):
        t0, t1 = _seg_inside(rows, nrows, p, i, tol)
        if t0 > t1:
            return np.nan, np.nan
        a = s[i] + t0 * (s[i + 1] - s[i])
        b = s[i] + t1 * (s[i + 1] - s[i])
        if a > max(s_lo, s[i]) + eps or b < min(s_hi, s[i + 1]) - eps:
            return np.nan, np.nan
    t0, t1 = _seg_inside(rows, nrows, p, i_lo, tol)
    lo = s[i_lo] + t0 * (s[i_lo + 1] - s[i_lo])
    i = i_lo - 1
    while t0 <= 0.0 and i >= 0:
        t0, t1 = _seg_inside(rows, nrows, p, i, tol)
        if t1 < 1.0 or t0 > t1:
            break
        lo = s[i] + t0 * (s[i + 1] - s[i])
        i -= 1
    t0, t1 = _seg_inside(rows, nrows, p, i_hi, tol)
    hi = s[i_hi] + t1 * (s[i_hi + 1] - s[i_hi])
    i = i_hi + 1
    while t1 >= 1.0 and i < n - 1:
        t0, t1 = _seg_inside(rows, nrows, p, i, tol)
        if t0 > 0.0 or t0 > t1:
            break
        hi = s[i] + t1 * (s[i + 1] - s[i])
        i += 1
    return lo, hi


@njit(cache=True)
def chain_geometry(hm, vm, nrow, nvert, degen, p, s, tol):  # pragma: no cover - compiled
    """Path intervals and overlaps of a chain of regions (world units).

    ``hm[k, :nrow[k]]`` are region ``k``'s rows ``(a_x, a_y, b)`` (for a polygon with
    interior, row ``i`` is the edge ``vm[k, i] -> vm[k, i + 1]``), ``vm[k, :nvert[k]]`` its
    vertices. Returns ``(region_s, overlap_s, ov_v, ov_h, ov_n)``: each region's largest
    interval of the polyline ``p`` (arc lengths ``s``) around its own segment ``k``; each
    consecutive pair's largest interval around their shared vertex ``k + 1`` (``nan`` when
    a required piece is outside); and the pair's intersection, clipped exactly: ``ov_n[k]``
    vertices ``ov_v[k]`` with the row of each outgoing edge ``ov_h[k]`` (rows only
    meaningful when both regions have interior).
    """
    m = hm.shape[0]
    kmax = hm.shape[1]
    region_s = np.empty((m, 2))
    overlap_s = np.empty((max(m - 1, 0), 2))
    cap = 2 * kmax + 4
    ov_v = np.zeros((max(m - 1, 0), cap, 2))
    ov_h = np.zeros((max(m - 1, 0), cap, 3))
    ov_n = np.zeros(max(m - 1, 0), np.int64)
    both = np.empty((2 * kmax, 3))
    for k in range(m):
        lo, hi = polyline_interval(hm[k], nrow[k], p, s, s[k], s[k + 1], tol)
        region_s[k, 0] = lo
        region_s[k, 1] = hi
    va = np.empty((cap, 2))
    la = np.empty(cap, np.int64)
    vb = np.empty((cap, 2))
    lb = np.empty(cap, np.int64)
    for k in range(m - 1):
        n1 = nrow[k]
        n2 = nrow[k + 1]
        for i in range(n1):  # element copies: no shape-mismatch error code to compile
            for c in range(3):
                both[i, c] = hm[k, i, c]
        for i in range(n2):
            for c in range(3):
                both[n1 + i, c] = hm[k + 1, i, c]
        lo, hi = polyline_interval(both, n1 + n2, p, s, s[k + 1], s[k + 1], tol)
        overlap_s[k, 0] = lo
        overlap_s[k, 1] = hi
        nv = nvert[k]
        for i in range(nv):
            va[i, 0] = vm[k, i, 0]
            va[i, 1] = vm[k, i, 1]
            la[i] = -(i + 1)
        for j in range(n2):
            nv = _clip(va, la, nv, hm[k + 1, j, 0], hm[k + 1, j, 1], hm[k + 1, j, 2], j, vb, lb)
            va, vb = vb, va
            la, lb = lb, la
            if nv == 0:
                break
        nv = _tidy(va, la, nv)
        ov_n[k] = nv
        for i in range(nv):
            ov_v[k, i, 0] = va[i, 0]
            ov_v[k, i, 1] = va[i, 1]
            if degen[k] or degen[k + 1]:
                continue
            if la[i] >= 0:
                for c in range(3):
                    ov_h[k, i, c] = hm[k + 1, la[i], c]
            else:
                for c in range(3):
                    ov_h[k, i, c] = hm[k, -la[i] - 1, c]
    return region_s, overlap_s, ov_v, ov_h, ov_n


@njit(cache=True)
def certify_all(vv, nv, cap, rects, meta, bstart, bids, stamp, buf):  # pragma: no cover
    """Exact clearance (capped at ``cap``) of every region ``vv[k, :nv[k]]``."""
    m = vv.shape[0]
    out = np.empty(m)
    for k in range(m):
        out[k] = poly_clearance(vv[k], nv[k], cap, rects, meta, bstart, bids, stamp, buf)
    return out
