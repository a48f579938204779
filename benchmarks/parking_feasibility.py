"""Whether a parking case is feasible at all: connectivity of the car's free configuration space.

A Reeds-Shepp car (forwards and backwards, curvature at most ``1 / R``) is small-time locally
controllable (its control set is symmetric and its vector fields satisfy the Lie algebra
rank condition: Laumond's result, by Chow's theorem), so a collision-free car path from the
start to the goal exists if and only if both lie in the same path-connected component of
the *open* free configuration space ``C_free`` in ``(x, y, theta)`` (``theta`` periodic).
Feasibility is therefore a connectivity question, independent of any planner, and this
module decides it on a grid of cells, conservatively both ways.

**The grid.** Cells are closed boxes ``[x, x + h] x [y, y + h] x [theta, theta + h_theta]``
of the rear-axle pose over a region (the map's bounds by default), ``theta`` over
``[-pi, pi)`` with the first and last cells adjacent. Within a cell every point of the body
moves at most ``L = sqrt(hx**2 + hy**2) / 2 + (h_theta / 2) * r_far`` from where it is at
the cell's centre pose (``r_far``: the body point farthest from the reference point; a
turn by ``a`` moves a point at radius ``r`` by the chord ``2 r sin(a / 2) <= r a``).

**The signed distance** ``s(q)`` at a pose (:func:`signed_distance`, compiled, exact up to
rounding): the body's distance to the obstacle polygons when it meets none (``s > 0``);
otherwise ``-p``, where ``p >= 0`` is a lower bound on how deep the two sets interpenetrate:
the deepest point of a polygon's boundary inside the body (an exact 1-D linear programme
along each polygon edge against the body's edge lines), and the deepest point of the body's
boundary inside a polygon (the same, exact, for a convex polygon; a non-convex one is
sampled along the body's edges at most ``L`` apart, which only lowers the bound). If a point
at depth ``p`` inside one set is a material point of the body, a ball of radius ``p`` round
it lies in the obstacle; if it is an obstacle point, a ball of radius ``p`` round it lies in
the body, and the body's image of that ball still contains it after any motion moving body
points less than ``p``. Either way every pose that moves body points less than ``p``
collides, so:

* ``s(centre) > L``: the whole closed cell lies in ``C_free`` (every body point stays more
  than ``s - L > 0`` from every polygon). Such cells are *inner* cells;
* ``s(centre) < -L``: no pose of the cell is free. Every other cell *may meet* ``C_free``.

Cells are classified by recursive halving of blocks of cells: a block whose centre decides
it (``s > L_block`` or ``s < -L_block``, ``L_block`` the bound of the whole block) is decided
for all its cells at once, otherwise it is split, down to single cells.

**Inner fill (proves feasible).** Two face-adjacent closed cells share a face, so the union
of a 6-connected set of inner cells is path-connected, and it lies in ``C_free``. The start
pose ``q`` (free, ``s(q) = d > 0``) reaches every pose of the convex set ``{p : |xy(p) -
xy(q)| + |theta(p) - theta(q)| r_far < d}`` along a straight segment that stays in
``C_free`` (every body point moves less than ``d`` along it); an inner cell meeting that set
(its nearest point, the pose clamped to the box, is in it) is a *seed* of the start, and
likewise of the goal. If a seed of the start and a seed of the goal are 6-connected through
inner cells, a collision-free path of poses exists (start -> clamped point -> cell centres
-> clamped point -> goal), and by small-time local controllability a car path (a sequence
of Reeds-Shepp arcs with cusps, not the cell path itself) exists within ``C_free`` too.

**Outer fill (proves infeasible).** Every pose of a collision-free path lies in a cell
that may meet ``C_free``. Two closed cells intersect iff they are 26-adjacent (share at
least a corner, with the theta wrap), so the unions of the 26-connected components of
may-meet cells are pairwise disjoint closed sets; a path is connected, so it stays in one
of them. Poses outside the region are lumped into one more component, adjacent to every
may-meet cell on the region's x or y faces (so a region smaller than the map stays sound).
If the start's and the goal's cells are in different components, no path exists.

Otherwise the answer is *unknown* at that resolution, and the grid is refined (cells halved
in x, y and theta, up to ``refine`` times) over a box round the *smaller* end's component
(:func:`feasibility`): there, the coarse inner cells of the other end's component count as
the other end (a fine cell inside one of them intersects it, and two intersecting closed
subsets of ``C_free`` that are each path-connected have a path-connected union), and the
outer fill treats the outside of the box as one component, as above.

Not decided here: anything about the car's own paths. A feasible verdict says that a
collision-free *pose* path exists, hence (small-time local controllability) a car path of
Reeds-Shepp arcs with cusps within any neighbourhood of it; it may need very many cusps
where the free space is a thin tube.

Run: ``python benchmarks/parking_feasibility.py [--car full|small] [--limit 40] [--seed 0]
[--resolution 0.1] [--refine 2] [--cases 9,full-perpendicular-forwards-1] [--json out.json]``
(``--resolution``: level 0's cell side in m, 0.1 m times the car's scale by default; the
heading cells balance it, :func:`theta_bins_for`). The suite's verdicts for seed 0 are
kept in ``benchmarks/parking_feasibility_full.json`` and ``..._small.json`` (read by
``bench_parking.py --feasibility``).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numba import njit
from scipy import ndimage
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

if __package__:  # imported as benchmarks.parking_feasibility (the tests): one parking_cases
    from . import parking_cases as pc
else:  # run as a script, or imported next to parking_cases (bench_parking.py)
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import parking_cases as pc

VERDICTS = ("feasible", "infeasible", "unknown")
_TOL = 1e-9  # relative slack on the cell bound L: rounding never decides a cell


# ---------------------------------------------------------------------------- geometry kernels


@njit(cache=True)
def _maxmin(c, d, m):  # pragma: no cover - compiled
    """``max_{t in [0, 1]} min_{i < m} (c[i] + d[i] t)``: a 1-D linear programme, exactly.

    The maximum of a concave piecewise-linear function lies at an end of the interval or
    where two of its lines cross.
    """
    best = -math.inf
    for q in range(-2, m * m):
        if q == -2:
            t = 0.0
        elif q == -1:
            t = 1.0
        else:
            i, j = q // m, q % m
            if j <= i or d[i] == d[j]:
                continue
            t = (c[j] - c[i]) / (d[i] - d[j])
            if not (0.0 < t < 1.0):
                continue
        v = math.inf
        for k in range(m):
            v = min(v, c[k] + d[k] * t)
        best = max(best, v)
    return best


@njit(cache=True, inline="always")
def _orient(ax, ay, bx, by, cx, cy):  # pragma: no cover - compiled
    v = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
    return 1 if v > 0.0 else (-1 if v < 0.0 else 0)


@njit(cache=True, inline="always")
def _within(ax, ay, bx, by, px, py):  # pragma: no cover - compiled
    return min(ax, bx) <= px <= max(ax, bx) and min(ay, by) <= py <= max(ay, by)


@njit(cache=True)
def _meet(ax, ay, bx, by, cx, cy, dx, dy):  # pragma: no cover - compiled
    """Closed segments ``ab`` and ``cd`` share a point (touching counts)."""
    o1 = _orient(ax, ay, bx, by, cx, cy)
    o2 = _orient(ax, ay, bx, by, dx, dy)
    o3 = _orient(cx, cy, dx, dy, ax, ay)
    o4 = _orient(cx, cy, dx, dy, bx, by)
    if o1 * o2 < 0 and o3 * o4 < 0:
        return True
    return (
        (o1 == 0 and _within(ax, ay, bx, by, cx, cy))
        or (o2 == 0 and _within(ax, ay, bx, by, dx, dy))
        or (o3 == 0 and _within(cx, cy, dx, dy, ax, ay))
        or (o4 == 0 and _within(cx, cy, dx, dy, bx, by))
    )


@njit(cache=True, inline="always")
def _seg_dist2(px, py, ax, ay, bx, by):  # pragma: no cover - compiled
    ex = bx - ax
    ey = by - ay
    ee = ex * ex + ey * ey
    t = 0.0 if ee == 0.0 else min(max(((px - ax) * ex + (py - ay) * ey) / ee, 0.0), 1.0)
    ux = ax + t * ex - px
    uy = ay + t * ey - py
    return ux * ux + uy * uy


@njit(cache=True)
def _inside(verts, a, b, px, py):  # pragma: no cover - compiled
    """Point ``(px, py)`` strictly inside polygon ``verts[a:b]`` (even-odd)."""
    m = b - a
    ins = False
    for e in range(m):
        x0, y0 = verts[a + e, 0], verts[a + e, 1]
        x1, y1 = verts[a + (e + 1) % m, 0], verts[a + (e + 1) % m, 1]
        if (y0 > py) != (y1 > py):
            if px < x0 + (py - y0) * (x1 - x0) / (y1 - y0):
                ins = not ins
    return ins


@njit(cache=True)
def _poly_gap(verts, a, b, bx, by, cap):  # pragma: no cover - compiled
    """Distance of the convex body ``(bx, by)`` to polygon ``verts[a:b]``; -1 when they meet."""
    m = b - a
    k = bx.shape[0]
    d2 = cap * cap
    for e in range(m):
        cx, cy = verts[a + e, 0], verts[a + e, 1]
        dx, dy = verts[a + (e + 1) % m, 0], verts[a + (e + 1) % m, 1]
        for i in range(k):
            i1 = (i + 1) % k
            if _meet(bx[i], by[i], bx[i1], by[i1], cx, cy, dx, dy):
                return -1.0
            d2 = min(
                d2,
                _seg_dist2(bx[i], by[i], cx, cy, dx, dy),
                _seg_dist2(cx, cy, bx[i], by[i], bx[i1], by[i1]),
            )
    # no boundaries meet: the body inside the polygon, or the polygon inside the body
    if _inside(verts, a, b, bx[0], by[0]):
        return -1.0
    vx, vy = verts[a, 0], verts[a, 1]
    allin = True
    for i in range(k):
        i1 = (i + 1) % k
        if (bx[i1] - bx[i]) * (vy - by[i]) - (by[i1] - by[i]) * (vx - bx[i]) < 0.0:
            allin = False
            break
    if allin:
        return -1.0
    return math.sqrt(d2)


@njit(cache=True)
def _poly_depth(verts, a, b, sign, convex, bx, by, sigma, cb, db):  # pragma: no cover
    """A lower bound on how deep the convex body and polygon ``verts[a:b]`` interpenetrate.

    The deepest point of the polygon's boundary inside the body, and of the body's boundary
    inside the polygon (exact for a convex polygon, sampled at most ``sigma`` apart along
    the body's edges otherwise); ``sign`` is +1 for a counter-clockwise polygon, -1 else.
    ``cb``, ``db``: scratch of length >= max(k, polygon edges).
    """
    m = b - a
    k = bx.shape[0]
    best = 0.0
    # polygon edges against the body's edge lines (inward unit normals, counter-clockwise body)
    for e in range(m):
        px, py = verts[a + e, 0], verts[a + e, 1]
        qx, qy = verts[a + (e + 1) % m, 0], verts[a + (e + 1) % m, 1]
        for i in range(k):
            i1 = (i + 1) % k
            ex, ey = bx[i1] - bx[i], by[i1] - by[i]
            ln = math.hypot(ex, ey)
            nx, ny = -ey / ln, ex / ln
            cb[i] = nx * (px - bx[i]) + ny * (py - by[i])
            db[i] = nx * (qx - px) + ny * (qy - py)
        best = max(best, _maxmin(cb, db, k))
    # body edges inside the polygon
    for i in range(k):
        i1 = (i + 1) % k
        ax, ay, ex, ey = bx[i], by[i], bx[i1] - bx[i], by[i1] - by[i]
        if convex:
            for e in range(m):
                px, py = verts[a + e, 0], verts[a + e, 1]
                qx, qy = verts[a + (e + 1) % m, 0], verts[a + (e + 1) % m, 1]
                ln = math.hypot(qx - px, qy - py)
                if ln == 0.0:
                    cb[e], db[e] = math.inf, 0.0
                    continue
                nx, ny = -sign * (qy - py) / ln, sign * (qx - px) / ln
                cb[e] = nx * (ax - px) + ny * (ay - py)
                db[e] = nx * ex + ny * ey
            best = max(best, _maxmin(cb, db, m))
        else:
            n = max(1, int(math.ceil(math.hypot(ex, ey) / sigma)))
            for s in range(n + 1):
                t = s / n
                x, y = ax + t * ex, ay + t * ey
                if _inside(verts, a, b, x, y):
                    d2 = math.inf
                    for e in range(m):
                        px, py = verts[a + e, 0], verts[a + e, 1]
                        qx, qy = verts[a + (e + 1) % m, 0], verts[a + (e + 1) % m, 1]
                        d2 = min(d2, _seg_dist2(x, y, px, py, qx, qy))
                    best = max(best, math.sqrt(d2))
    return best


@njit(cache=True)
def _signed(verts, starts, boxes, sign, convex, fp, x, y, th, cap, deep, bx, by, cb, db):
    """Signed distance of the body at pose ``(x, y, th)`` (module docstring).

    Returns the distance (capped at ``cap``) when the body meets no polygon, else ``-p``
    with ``p`` the depth bound; stops early once ``p > deep`` (the answer is then ``< -deep``).
    """
    k = fp.shape[0]
    c, s = math.cos(th), math.sin(th)
    for i in range(k):
        bx[i] = x + c * fp[i, 0] - s * fp[i, 1]
        by[i] = y + s * fp[i, 0] + c * fp[i, 1]
    x0, x1, y0, y1 = bx.min(), bx.max(), by.min(), by.max()
    clear = cap
    hit = False
    pen = 0.0
    sigma = max(deep, 1e-3) if deep < math.inf else 0.01  # sampling of non-convex polygons
    for j in range(boxes.shape[0]):
        gx = max(boxes[j, 0] - x1, x0 - boxes[j, 2], 0.0)
        gy = max(boxes[j, 1] - y1, y0 - boxes[j, 3], 0.0)
        g = math.sqrt(gx * gx + gy * gy)
        if g > 0.0 and (hit or g >= clear):
            continue
        d = _poly_gap(verts, starts[j], starts[j + 1], bx, by, clear)
        if d < 0.0:
            hit = True
            pen = max(
                pen,
                _poly_depth(
                    verts, starts[j], starts[j + 1], sign[j], convex[j], bx, by, sigma, cb, db
                ),
            )
            if pen > deep:
                return -pen
        elif not hit:
            clear = min(clear, d)
    return -pen if hit else clear


@njit(cache=True)
def _signed_many(verts, starts, boxes, sign, convex, fp, poses, out):  # pragma: no cover
    k = fp.shape[0]
    m = max(k, int(np.max(starts[1:] - starts[:-1])) if starts.shape[0] > 1 else k)
    bx, by, cb, db = np.empty(k), np.empty(k), np.empty(m), np.empty(m)
    for p in range(poses.shape[0]):
        out[p] = _signed(
            verts,
            starts,
            boxes,
            sign,
            convex,
            fp,
            poses[p, 0],
            poses[p, 1],
            poses[p, 2],
            math.inf,
            math.inf,
            bx,
            by,
            cb,
            db,
        )


@njit(cache=True)
def _classify(verts, starts, boxes, sign, convex, fp, r_far, grid, block, inner, may):
    """Mark ``inner`` (cell wholly free) and ``may`` (cell may meet C_free).

    ``grid`` = ``(x0, y0, th0, hx, hy, ht)``: the low corner and cell sides. Blocks of
    ``block`` cells a side are decided at their centre when the centre's signed distance
    exceeds the block's bound, else halved, down to single cells. Returns the evaluations.
    """
    x0, y0, t0, hx, hy, ht = grid[0], grid[1], grid[2], grid[3], grid[4], grid[5]
    nx, ny, nt = inner.shape
    k = fp.shape[0]
    m = max(k, int(np.max(starts[1:] - starts[:-1])) if starts.shape[0] > 1 else k)
    bx, by, cb, db = np.empty(k), np.empty(k), np.empty(m), np.empty(m)
    stack = np.empty((4096, 6), dtype=np.int64)
    evals = 0
    for bi in range(0, nx, block):
        for bj in range(0, ny, block):
            for bk in range(0, nt, block):
                top = 0
                stack[0, 0], stack[0, 1] = bi, min(bi + block, nx)
                stack[0, 2], stack[0, 3] = bj, min(bj + block, ny)
                stack[0, 4], stack[0, 5] = bk, min(bk + block, nt)
                top = 1
                while top > 0:
                    top -= 1
                    i0, i1, j0, j1, k0, k1 = stack[top]
                    ex = 0.5 * (i1 - i0) * hx
                    ey = 0.5 * (j1 - j0) * hy
                    et = 0.5 * (k1 - k0) * ht
                    L = (math.sqrt(ex * ex + ey * ey) + et * r_far) * (1.0 + 1e-9) + 1e-12
                    s = _signed(
                        verts,
                        starts,
                        boxes,
                        sign,
                        convex,
                        fp,
                        x0 + 0.5 * (i0 + i1) * hx,
                        y0 + 0.5 * (j0 + j1) * hy,
                        t0 + 0.5 * (k0 + k1) * ht,
                        2.0 * L,
                        L,
                        bx,
                        by,
                        cb,
                        db,
                    )
                    evals += 1
                    if s > L:
                        inner[i0:i1, j0:j1, k0:k1] = 1
                        may[i0:i1, j0:j1, k0:k1] = 1
                    elif s < -L:
                        pass
                    elif i1 - i0 == 1 and j1 - j0 == 1 and k1 - k0 == 1:
                        may[i0, j0, k0] = 1
                    else:
                        im = (i0 + i1 + 1) // 2 if i1 - i0 > 1 else i1
                        jm = (j0 + j1 + 1) // 2 if j1 - j0 > 1 else j1
                        km = (k0 + k1 + 1) // 2 if k1 - k0 > 1 else k1
                        for a0, a1 in ((i0, im), (im, i1)):
                            if a0 >= a1:
                                continue
                            for b0, b1 in ((j0, jm), (jm, j1)):
                                if b0 >= b1:
                                    continue
                                for c0, c1 in ((k0, km), (km, k1)):
                                    if c0 >= c1:
                                        continue
                                    stack[top, 0], stack[top, 1] = a0, a1
                                    stack[top, 2], stack[top, 3] = b0, b1
                                    stack[top, 4], stack[top, 5] = c0, c1
                                    top += 1
    return evals


@njit(cache=True)
def _bfs(inner, seeds, goals):  # pragma: no cover - compiled
    """Shortest 6-connected path (theta wraps) through ``inner`` from any seed to any goal cell.

    ``seeds``, ``goals``: flat cell indices. Returns the flat indices, seed first (empty: none).
    """
    nx, ny, nt = inner.shape
    n = nx * ny * nt
    flat = inner.ravel()
    parent = np.full(n, -2, dtype=np.int32)
    is_goal = np.zeros(n, dtype=np.bool_)
    for g in goals:
        is_goal[g] = True
    queue = np.empty(n, dtype=np.int32)
    head, tail = 0, 0
    for s in seeds:
        if parent[s] == -2:
            parent[s] = -1
            queue[tail] = s
            tail += 1
    end = -1
    while head < tail:
        c = queue[head]
        head += 1
        if is_goal[c]:
            end = c
            break
        i = c // (ny * nt)
        j = (c // nt) % ny
        k = c % nt
        for di, dj, dk in ((1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)):
            a, b = i + di, j + dj
            if a < 0 or a >= nx or b < 0 or b >= ny:
                continue
            kk = (k + dk) % nt
            q = (a * ny + b) * nt + kk
            if flat[q] and parent[q] == -2:
                parent[q] = c
                queue[tail] = q
                tail += 1
    if end < 0:
        return np.empty(0, dtype=np.int64)
    path = [end]
    while parent[path[-1]] >= 0:
        path.append(parent[path[-1]])
    out = np.empty(len(path), dtype=np.int64)
    for i in range(len(path)):
        out[i] = path[len(path) - 1 - i]
    return out


# ---------------------------------------------------------------------------- Python faces


@dataclass(frozen=True)
class _Scene:
    verts: np.ndarray
    starts: np.ndarray
    boxes: np.ndarray
    sign: np.ndarray
    convex: np.ndarray
    fp: np.ndarray
    r_far: float


def _scene(body: np.ndarray, polygons: Sequence[np.ndarray]) -> _Scene:
    fp = np.ascontiguousarray(np.asarray(body, dtype=float).reshape(-1, 2))
    if fp.shape[0] < 3:
        raise ValueError(f"body: need >= 3 vertices of a convex polygon, got shape {fp.shape}")
    area2 = float(np.sum(fp[:, 0] * np.roll(fp[:, 1], -1) - np.roll(fp[:, 0], -1) * fp[:, 1]))
    if area2 < 0.0:
        fp = np.ascontiguousarray(fp[::-1])
    e = np.roll(fp, -1, axis=0) - fp
    e2 = np.roll(e, -1, axis=0)
    if np.any(e[:, 0] * e2[:, 1] - e[:, 1] * e2[:, 0] < -1e-12):
        raise ValueError("body: the polygon must be convex")
    polys = [np.asarray(p, dtype=float).reshape(-1, 2) for p in polygons]
    verts = np.ascontiguousarray(np.vstack(polys)) if polys else np.zeros((0, 2))
    starts = np.r_[0, np.cumsum([len(p) for p in polys])].astype(np.int64)
    boxes = np.array(
        [[p[:, 0].min(), p[:, 1].min(), p[:, 0].max(), p[:, 1].max()] for p in polys], dtype=float
    ).reshape(-1, 4)
    sign = np.empty(len(polys))
    convex = np.empty(len(polys), dtype=np.bool_)
    for j, p in enumerate(polys):
        a2 = float(np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1]))
        sign[j] = 1.0 if a2 > 0 else -1.0
        d = np.roll(p, -1, axis=0) - p
        d2 = np.roll(d, -1, axis=0)
        cross = sign[j] * (d[:, 0] * d2[:, 1] - d[:, 1] * d2[:, 0])
        convex[j] = bool(np.all(cross >= 0.0))
    r_far = float(np.max(np.hypot(fp[:, 0], fp[:, 1])))
    return _Scene(verts, starts, np.ascontiguousarray(boxes), sign, convex, fp, r_far)


def signed_distance(
    body: np.ndarray, poses: np.ndarray, polygons: Sequence[np.ndarray]
) -> np.ndarray:
    """Signed distance of a convex body at each pose to the polygons (module docstring).

    Parameters
    ----------
    body : ndarray, shape (k, 2)
        Convex body in the reference frame (m), either orientation.
    poses : ndarray, shape (n, 3)
        ``(x, y, theta)`` of the reference point (m, m, rad).
    polygons : sequence of ndarray, shape (m_i, 2)
        Simple obstacle polygons (m), convex or not, either orientation.

    Returns
    -------
    ndarray, shape (n,)
        The distance (m) when the body meets no polygon (``inf`` with none); when it meets
        one (touching counts), ``-p`` with ``0 <= p`` a lower bound on the depth: no pose
        moving every body point less than ``p`` from this one is free (a non-convex
        polygon's part of the bound samples the body's edges 1 cm apart).
    """
    sc = _scene(body, polygons)
    q = np.ascontiguousarray(np.asarray(poses, dtype=float).reshape(-1, 3))
    out = np.empty(len(q))
    _signed_many(sc.verts, sc.starts, sc.boxes, sc.sign, sc.convex, sc.fp, q, out)
    return out


@dataclass
class Verdict:
    """The answer for one query.

    ``verdict``: ``feasible`` / ``infeasible`` / ``unknown``; ``resolution`` the cell side
    (m) and ``theta_bins`` the heading cells of the last grid tried; ``seconds`` the wall
    time of all levels; ``cells`` and ``evaluations`` of the last level; ``witness`` the
    poses ``(n, 3)`` of a collision-free pose path (start, cell centres, goal) when
    feasible; ``witness_clear`` whether the exact checker of :mod:`parking_cases` finds it
    clear at poses whose body corners move <= 1 cm apart (None: not checked); ``levels``
    ``(resolution, theta_bins, verdict, seconds)`` per level.
    """

    verdict: str
    resolution: float
    theta_bins: int
    seconds: float
    cells: int
    evaluations: int
    witness: np.ndarray | None = None
    witness_clear: bool | None = None
    levels: list = field(default_factory=list)


def theta_bins_for(body: np.ndarray, resolution: float) -> int:
    """Heading cells (even) whose turn moves the body's far point as much as the xy cell does.

    ``h_theta * r_far <= sqrt(2) * resolution``: the two terms of the cell bound balance.
    """
    fp = np.asarray(body, dtype=float)
    r_far = float(np.max(np.hypot(fp[:, 0], fp[:, 1])))
    n = math.ceil(2.0 * math.pi * r_far / (math.sqrt(2.0) * resolution))
    return int(n + (n % 2))


def _labels(mask: np.ndarray, full: bool, sink: bool) -> tuple[np.ndarray, np.ndarray]:
    """Components of ``mask`` (6- or 26-connected, theta wrapping; optional outside sink).

    Returns the label array (0 outside the mask) and the component of each label.
    """
    structure = ndimage.generate_binary_structure(3, 3 if full else 1)
    lab, n = ndimage.label(mask, structure=structure)
    rows, cols = [], []
    a, b = lab[:, :, 0], lab[:, :, -1]
    if mask.shape[2] > 1:
        if full:
            pad = np.pad(b, 1)
            for di in (-1, 0, 1):
                for dj in (-1, 0, 1):
                    bb = pad[1 + di : 1 + di + b.shape[0], 1 + dj : 1 + dj + b.shape[1]]
                    sel = (a > 0) & (bb > 0)
                    rows.append(a[sel])
                    cols.append(bb[sel])
        else:
            sel = (a > 0) & (b > 0)
            rows.append(a[sel])
            cols.append(b[sel])
    if sink:  # label n + 1: everything outside the region
        face = np.unique(
            np.concatenate([lab[0].ravel(), lab[-1].ravel(), lab[:, 0].ravel(), lab[:, -1].ravel()])
        )
        face = face[face > 0]
        rows.append(face)
        cols.append(np.full(len(face), n + 1))
    r = np.concatenate(rows) if rows else np.zeros(0, dtype=np.int64)
    c = np.concatenate(cols) if cols else np.zeros(0, dtype=np.int64)
    g = coo_matrix((np.ones(len(r)), (r, c)), shape=(n + 2, n + 2))
    _, comp = connected_components(g, directed=False)
    return lab, comp


def _seeds(pose, d: float, grid, shape, inner, r_far: float) -> list[int]:
    """Inner cells within the free ball of a pose (module docstring): flat indices."""
    x0, y0, t0, hx, hy, ht = grid
    nx, ny, nt = shape
    x, y, th = pose
    i, j = int(math.floor((x - x0) / hx)), int(math.floor((y - y0) / hy))
    k = int(math.floor((th - t0) / ht))
    out = []
    for a in range(i - 1, i + 2):
        for b in range(j - 1, j + 2):
            if not (0 <= a < nx and 0 <= b < ny):
                continue
            for c in range(k - 1, k + 2):
                cc = c % nt
                if not inner[a, b, cc]:
                    continue
                lo = np.array([x0 + a * hx, y0 + b * hy, t0 + c * ht])
                q = np.clip([x, y, th], lo, lo + (hx, hy, ht))
                if math.hypot(q[0] - x, q[1] - y) + abs(q[2] - th) * r_far < d / (1.0 + _TOL):
                    out.append((a * ny + b) * nt + cc)
    return out


def _cell_of(pose, grid, shape) -> tuple[int, int, int] | None:
    x0, y0, t0, hx, hy, ht = grid
    nx, ny, nt = shape
    i = int(math.floor((pose[0] - x0) / hx))
    j = int(math.floor((pose[1] - y0) / hy))
    k = int(math.floor((math.remainder(pose[2], 2 * math.pi) - t0) / ht)) % nt
    if 0 <= i < nx and 0 <= j < ny:
        return i, j, k
    return None


def _wrap_pose(pose) -> tuple[float, float, float]:
    return float(pose[0]), float(pose[1]), float(math.remainder(pose[2], 2 * math.pi))


def _fill(sc: _Scene, a, b, da: float, db: float, grid, shape, block: int, target=None) -> dict:
    """One grid: classify its cells, then the inner fill and, if that fails, the outer fill.

    ``a``, ``b``: the end poses (wrapped), ``da``, ``db`` their signed distances (> 0);
    ``grid`` = ``(x0, y0, -pi, h, h, h_theta)``; ``target``: optional bool mask of inner
    cells already known to be connected to ``b`` (a finer grid's view of a coarser grid's
    component), seeds of ``b`` too. Returns a dict: ``verdict``, ``inner``, ``lab``,
    ``comp``, ``a_seeds``, ``b_seeds``, ``path`` (flat cells from an ``a`` seed to a ``b``
    seed, or None), ``evaluations``.
    """
    inner = np.zeros(shape, dtype=np.uint8)
    may = np.zeros(shape, dtype=np.uint8)
    evals = _classify(
        sc.verts,
        sc.starts,
        sc.boxes,
        sc.sign,
        sc.convex,
        sc.fp,
        sc.r_far,
        np.array(grid, dtype=float),
        int(block),
        inner,
        may,
    )
    out = dict(inner=inner, evaluations=int(evals), path=None)
    lab, comp = _labels(inner.astype(bool), full=False, sink=False)
    out.update(lab=lab, comp=comp)
    a_seeds = np.array(_seeds(a, da, grid, shape, inner, sc.r_far), dtype=np.int64)
    b_seeds = np.array(_seeds(b, db, grid, shape, inner, sc.r_far), dtype=np.int64)
    if target is not None:
        b_seeds = np.union1d(b_seeds, np.flatnonzero(target.ravel() & inner.ravel().astype(bool)))
    out.update(a_seeds=a_seeds, b_seeds=b_seeds)
    flat = lab.ravel()
    if np.intersect1d(comp[flat[a_seeds]], comp[flat[b_seeds]]).size:
        out["path"] = _bfs(inner, a_seeds, b_seeds)
        out["verdict"] = "feasible"
        return out
    # the outer fill
    lab2, comp2 = _labels(may.astype(bool), full=True, sink=True)
    ca, cb = _cell_of(a, grid, shape), _cell_of(b, grid, shape)
    ka = comp2[lab2[ca]] if ca is not None else comp2[-1]
    kb = comp2[lab2[cb]] if cb is not None else comp2[-1]
    out["verdict"] = "infeasible" if ka != kb else "unknown"
    return out


def _centres(path, grid, shape) -> np.ndarray:
    x0, y0, t0, hx, hy, ht = grid
    nx, ny, nt = shape
    i, j, k = path // (ny * nt), (path // nt) % ny, path % nt
    return np.column_stack([x0 + (i + 0.5) * hx, y0 + (j + 0.5) * hy, t0 + (k + 0.5) * ht])


def _clamped(pose, centre, grid) -> np.ndarray:
    """The pose (heading turned next to the centre's) and its nearest point of the cell."""
    _, _, _, hx, hy, ht = grid
    th = centre[2] + math.remainder(pose[2] - centre[2], 2 * math.pi)
    lo = centre - (0.5 * hx, 0.5 * hy, 0.5 * ht)
    q = np.clip([pose[0], pose[1], th], lo, lo + (hx, hy, ht))
    return np.array([[pose[0], pose[1], th], q])


def _unwrap(poses: np.ndarray) -> np.ndarray:
    out = poses.copy()
    out[:, 2] = np.unwrap(out[:, 2])
    return out


def densify(poses: np.ndarray, body: np.ndarray, step: float = 0.01) -> np.ndarray:
    """Straight-line interpolation of a pose path so that no body point moves > ``step`` m.

    Consecutive poses are joined by straight segments in ``(x, y, theta)`` (headings as
    given: unwrap them first); a segment moves body points at most ``|dxy| + |dtheta|
    r_far``.
    """
    fp = np.asarray(body, dtype=float)
    r_far = float(np.max(np.hypot(fp[:, 0], fp[:, 1])))
    out = [poses[:1]]
    for a, b in zip(poses[:-1], poses[1:], strict=True):
        move = math.hypot(b[0] - a[0], b[1] - a[1]) + abs(b[2] - a[2]) * r_far
        n = max(1, math.ceil(move / step))
        t = np.linspace(0.0, 1.0, n + 1)[1:, None]
        out.append(a + t * (b - a))
    return np.vstack(out)


def _grid(region, h: float, nt: int):
    x0, y0, x1, y1 = (float(v) for v in region)
    nx = max(1, math.ceil((x1 - x0) / h - 1e-9))
    ny = max(1, math.ceil((y1 - y0) / h - 1e-9))
    return (x0, y0, -math.pi, h, h, 2 * math.pi / nt), (nx, ny, int(nt))


def feasibility(
    body: np.ndarray,
    polygons: Sequence[np.ndarray],
    start,
    goal,
    region: tuple[float, float, float, float],
    resolution: float,
    theta_bins: int | None = None,
    refine: int = 2,
    check_witness: bool = True,
    block: int = 8,
) -> Verdict:
    """Decide whether a path from ``start`` to ``goal`` exists (module docstring).

    Level 0: the inner and outer fills over ``region`` at ``resolution`` and ``theta_bins``
    heading cells (default :func:`theta_bins_for`). While unknown, level ``k`` (up to
    ``refine``) halves the cells again over a box round the *smaller* end's component of
    the previous level (its cells' xy box, grown by ``r_far / 2**(k - 1)``, the body's
    far-point radius; full headings), aligned to level 0's cells. There the level-0 inner
    cells of the other end's component (each sub-cell of one is wholly free too) count as
    the other end: reaching one proves the path (the union of two intersecting closed
    cells in ``C_free`` is path-connected). The outer fill there treats everything outside
    the box as one component, so a separated small end proves infeasibility as before.

    A feasible answer carries a witness pose path (start, clamped point, cell centres,
    ..., goal; consecutive poses joined by straight segments in ``(x, y, theta)`` stay in
    ``C_free``), checked by :func:`parking_cases.body_overlaps` at poses whose body points
    move <= 1 cm apart when ``check_witness``.

    Parameters
    ----------
    body : ndarray, shape (k, 2)
        Convex body in the reference frame (m).
    polygons : sequence of ndarray, shape (m_i, 2)
        Obstacle polygons (m).
    start, goal : tuple of float
        ``(x, y, theta)`` (m, m, rad).
    region : tuple of float
        ``(xmin, ymin, xmax, ymax)`` (m) of the reference point (widened to whole cells);
        outside it, one more component adjacent to the region's x and y faces.
    resolution : float
        Level 0's cell side (m).
    theta_bins : int, optional
        Level 0's heading cells over ``[-pi, pi)``.
    refine : int, optional
        Refinement levels after level 0 (>= 0).
    check_witness : bool, optional
        Check a feasible answer's witness exactly.
    block : int, optional
        Side (cells) of the blocks classified by recursive halving.

    Returns
    -------
    Verdict
        Resolution and heading cells of the last level tried; ``seconds`` over all levels.
    """
    if not (resolution > 0 and math.isfinite(resolution)):
        raise ValueError(f"resolution: must be a positive finite number of m, got {resolution!r}")
    if refine < 0:
        raise ValueError(f"refine: must be >= 0, got {refine!r}")
    nt0 = int(theta_bins or theta_bins_for(body, resolution))
    if nt0 < 1:
        raise ValueError(f"theta_bins: must be >= 1, got {theta_bins!r}")
    t_start = time.perf_counter()
    sc = _scene(body, polygons)
    start, goal = _wrap_pose(start), _wrap_pose(goal)
    ds, dg = signed_distance(sc.fp, np.array([start, goal]), polygons)
    grid0, shape0 = _grid(region, resolution, nt0)
    levels = []

    def verdict(name, grid, shape, evals, witness=None):
        v = Verdict(
            name,
            resolution=grid[3],
            theta_bins=shape[2],
            seconds=time.perf_counter() - t_start,
            cells=int(np.prod(shape)),
            evaluations=evals,
            witness=witness,
            levels=levels,
        )
        if witness is not None and check_witness:
            dense = densify(witness, sc.fp, 0.01)
            v.witness_clear = not bool(pc.body_overlaps(sc.fp, dense, polygons).any())
        return v

    if ds <= 0.0 or dg <= 0.0:  # an end pose outside the open C_free: no path at all
        return verdict("infeasible", grid0, shape0, 0)
    t0 = time.perf_counter()
    L0 = _fill(sc, start, goal, ds, dg, grid0, shape0, block)
    levels.append((resolution, nt0, L0["verdict"], time.perf_counter() - t0))
    if L0["verdict"] != "unknown":
        w = None
        if L0["path"] is not None:
            c = _centres(L0["path"], grid0, shape0)
            w = _unwrap(
                np.vstack([_clamped(start, c[0], grid0), c, _clamped(goal, c[-1], grid0)[::-1]])
            )
        return verdict(L0["verdict"], grid0, shape0, L0["evaluations"], w)
    flat0 = L0["lab"].ravel()
    comp0 = L0["comp"]
    inner0 = L0["inner"].astype(bool)
    comp_cells = np.where(inner0, comp0[L0["lab"]], -1)
    sizes = np.bincount(comp_cells[inner0].ravel(), minlength=len(comp0))
    ends = {
        "start": (start, ds, set(comp0[flat0[L0["a_seeds"]]].tolist())),
        "goal": (goal, dg, set(comp0[flat0[L0["b_seeds"]]].tolist())),
    }
    small = min(ends, key=lambda e: sum(int(sizes[k]) for k in ends[e][2]))
    other = "goal" if small == "start" else "start"
    a, da, _ = ends[small]
    b, db, b_ids = ends[other]
    target0 = np.isin(comp_cells, list(b_ids)) if b_ids else np.zeros_like(inner0)
    # the small end's cells at the previous level, in world coordinates
    prev_cells = np.argwhere(np.isin(comp_cells, list(ends[small][2])))
    prev_grid = grid0
    x0, y0, _, h0, _, _ = grid0
    v_last = (grid0, shape0, L0["evaluations"])
    for k in range(1, refine + 1):
        f = 2**k
        margin = sc.r_far / 2 ** (k - 1)
        ph = prev_grid[3]
        if len(prev_cells):
            lo = prev_cells[:, :2].min(axis=0) * ph + (prev_grid[0], prev_grid[1])
            hi = (prev_cells[:, :2].max(axis=0) + 1) * ph + (prev_grid[0], prev_grid[1])
        else:
            lo = hi = np.array(a[:2])
        i_lo = max(0, math.floor((lo[0] - margin - x0) / h0))
        j_lo = max(0, math.floor((lo[1] - margin - y0) / h0))
        i_hi = min(shape0[0], math.ceil((hi[0] + margin - x0) / h0))
        j_hi = min(shape0[1], math.ceil((hi[1] + margin - y0) / h0))
        grid = (x0 + i_lo * h0, y0 + j_lo * h0, -math.pi, h0 / f, h0 / f, 2 * math.pi / (nt0 * f))
        shape = ((i_hi - i_lo) * f, (j_hi - j_lo) * f, nt0 * f)
        target = target0[i_lo:i_hi, j_lo:j_hi, :]
        for ax in range(3):
            target = np.repeat(target, f, axis=ax)
        t0 = time.perf_counter()
        Lk = _fill(sc, a, b, da, db, grid, shape, block, target=target)
        del target
        levels.append((grid[3], shape[2], Lk["verdict"], time.perf_counter() - t0))
        v_last = (grid, shape, Lk["evaluations"])
        if Lk["verdict"] == "infeasible":
            return verdict("infeasible", *v_last)
        if Lk["verdict"] == "feasible":
            fine = _centres(Lk["path"], grid, shape)
            # the last fine cell lies in a level-0 inner cell of the other end's component
            last = Lk["path"][-1]
            ny, nt = shape[1], shape[2]
            ci = i_lo + (last // (ny * nt)) // f
            cj = j_lo + ((last // nt) % ny) // f
            ck = (last % nt) // f
            c0 = (ci * shape0[1] + cj) * shape0[2] + ck
            coarse = _centres(
                _bfs(
                    L0["inner"],
                    np.array([c0], dtype=np.int64),
                    L0["b_seeds" if small == "start" else "a_seeds"],
                ),
                grid0,
                shape0,
            )
            if _cell_of(b, grid, shape) is not None and Lk["path"][-1] in set(
                _seeds(b, db, grid, shape, Lk["inner"], sc.r_far)
            ):
                tail = [fine, _clamped(b, fine[-1], grid)[::-1]]
            else:
                tail = [fine, coarse, _clamped(b, coarse[-1], grid0)[::-1]]
            w = _unwrap(np.vstack([_clamped(a, fine[0], grid), *tail]))
            if small == "goal":
                w = w[::-1]
            return verdict("feasible", *v_last, witness=w)
        lab, comp = Lk["lab"], Lk["comp"]
        ids = np.unique(comp[lab.ravel()[Lk["a_seeds"]]])
        innerk = Lk["inner"].astype(bool)
        prev_cells = np.argwhere(innerk & np.isin(np.where(innerk, comp[lab], -1), ids))
        prev_grid = grid
        del Lk
    return verdict("unknown", *v_last)


def case_feasibility(
    case: pc.ParkingCase,
    resolution: float | None = None,
    refine: int = 2,
    theta_bins: int | None = None,
) -> Verdict:
    """:func:`feasibility` of a suite case over its map's bounds (0.1 m x the car's scale)."""
    h = 0.1 * case.car.scale if resolution is None else resolution
    return feasibility(
        case.car.body(),
        case.polygons,
        case.start,
        case.goal,
        case.bounds,
        h,
        theta_bins=theta_bins,
        refine=refine,
    )


def main(argv: list[str] | None = None) -> int:
    """Decide the suite's cases (module docstring) and print a verdict table."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--car", choices=sorted(pc.CARS), default="full")
    ap.add_argument("--limit", type=int, default=40)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--resolution", type=float, default=None, help="cell side (m)")
    ap.add_argument("--theta-bins", type=int, default=None)
    ap.add_argument("--refine", type=int, default=2, help="refinements while unknown")
    ap.add_argument("--cases", type=str, default=None, help="indices or case ids, comma-separated")
    ap.add_argument("--json", type=Path, default=None, help="write the verdicts here")
    args = ap.parse_args(argv)
    car = pc.CARS[args.car]
    cases = pc.make_cases(car, args.limit, args.seed)
    if args.cases:
        picks = [w.strip() for w in args.cases.split(",") if w.strip()]
        cases = [c for i, c in enumerate(cases) if str(i) in picks or c.case_id in picks]
    rows = []
    print(f"{'case':<34}{'size':>6}{'aisle':>6}  {'verdict':<11}{'cell m':>8}{'bins':>6}{'s':>7}")
    for case in cases:
        v = case_feasibility(case, args.resolution, args.refine, args.theta_bins)
        note = ""
        if v.witness is not None:
            note = f"  witness {len(v.witness)} poses, exact check {'clear' if v.witness_clear else 'OVERLAPS'}"
        print(
            f"{case.case_id:<34}{case.size:>6.2f}{case.aisle:>6.1f}  {v.verdict:<11}"
            f"{v.resolution:>8.3f}{v.theta_bins:>6d}{v.seconds:>7.1f}{note}",
            flush=True,
        )
        rows.append(
            dict(
                case_id=case.case_id,
                start=list(case.start),
                goal=list(case.goal),
                size=case.size,
                verdict=v.verdict,
                resolution=v.resolution,
                theta_bins=v.theta_bins,
                seconds=round(v.seconds, 2),
                witness_clear=v.witness_clear,
                levels=v.levels,
            )
        )
    counts = {k: sum(r["verdict"] == k for r in rows) for k in VERDICTS}
    print(", ".join(f"{counts[k]} {k}" for k in VERDICTS))
    if args.json is not None:
        args.json.write_text(json.dumps(rows, indent=1) + "\n")
        print(f"verdicts: {args.json}")
    return 0


if __name__ == "__main__":
    # run the kernels as benchmarks.parking_feasibility whatever the entry point: numba's
    # cache of a kernel calling another names the module it was compiled in
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from benchmarks import parking_feasibility as canonical

    raise SystemExit(canonical.main())
