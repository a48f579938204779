"""The exact distance of a convex body (a car's footprint) to polygon obstacles.

The car planner tests its body against the polygons a grid was rasterised from
(:attr:`astar.OccupancyGrid.polygons`) where the grid's cells, a conservative cover of them,
do not clear it: :func:`body_distance` is compiled (numba) for the search's kernel, and
:func:`bodies_distance` is its vectorised face for poses given in world metres.

The distance between a convex polygon ``B`` and a simple polygon ``P`` (convex or not) is 0
when they meet (an edge of one crosses or touches an edge of the other, or one contains a
vertex of the other: then, with no edges meeting, one lies inside the other); otherwise it is
attained between a vertex of one and an edge of the other.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numba import njit

__all__ = [
    "PackedPolygons",
    "bodies_distance",
    "body_distance",
    "pack_polygons",
    "points_distance",
]

#: The packed polygons: edges ``(m, 4)`` (``x0, y0, x1, y1``), ``starts`` ``(p + 1,)`` (the
#: edges of polygon ``j`` are ``starts[j]:starts[j + 1]``) and boxes ``(p, 4)``
#: (``xmin, ymin, xmax, ymax``), all float64 except ``starts`` (int64).
PackedPolygons = tuple[np.ndarray, np.ndarray, np.ndarray]


def pack_polygons(
    rings: Sequence[np.ndarray] | None,
    shift: tuple[float, float] = (0.0, 0.0),
    scale: float = 1.0,
) -> PackedPolygons:
    """Return polygons as the arrays :func:`body_distance` reads.

    Parameters
    ----------
    rings : sequence of ndarray, shape (k, 2), or None
        Simple polygons (m), e.g. :attr:`astar.OccupancyGrid.polygons`; ``None``: none.
    shift : tuple of float, optional
        Subtracted from every vertex before scaling (m).
    scale : float, optional
        Every vertex is divided by it (e.g. the cell side, for coordinates in cells).

    Returns
    -------
    PackedPolygons
        ``(edges, starts, boxes)``; with no polygon, ``(0, 4)``, ``[0]`` and ``(0, 4)``.
    """
    rings = () if rings is None else tuple(rings)
    edges, boxes, starts = [], [], [0]
    d = np.asarray(shift, dtype=float)
    for v in rings:
        g = (np.asarray(v, dtype=float) - d) / float(scale)
        edges.append(np.hstack([g, np.roll(g, -1, axis=0)]))
        boxes.append([g[:, 0].min(), g[:, 1].min(), g[:, 0].max(), g[:, 1].max()])
        starts.append(starts[-1] + len(g))
    e = np.ascontiguousarray(np.vstack(edges)) if edges else np.zeros((0, 4))
    b = np.ascontiguousarray(np.array(boxes, dtype=float).reshape(-1, 4))
    return e, np.asarray(starts, dtype=np.int64), b


@njit(cache=True, inline="always")
def _orient(ax, ay, bx, by, cx, cy):  # pragma: no cover - compiled
    v = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
    return 1 if v > 0.0 else (-1 if v < 0.0 else 0)


@njit(cache=True, inline="always")
def _within(ax, ay, bx, by, px, py):  # pragma: no cover - compiled
    return min(ax, bx) <= px <= max(ax, bx) and min(ay, by) <= py <= max(ay, by)


@njit(cache=True)
def _meet(ax, ay, bx, by, cx, cy, dx, dy):  # pragma: no cover - compiled
    """Whether closed segments ``ab`` and ``cd`` share a point (touching counts)."""
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
def _point_seg_sq(px, py, ax, ay, bx, by):  # pragma: no cover - compiled
    ex = bx - ax
    ey = by - ay
    ee = ex * ex + ey * ey
    t = 0.0 if ee == 0.0 else min(max(((px - ax) * ex + (py - ay) * ey) / ee, 0.0), 1.0)
    ux = ax + t * ex - px
    uy = ay + t * ey - py
    return ux * ux + uy * uy


@njit(cache=True)
def body_distance(edges, starts, boxes, body, cap):  # pragma: no cover - compiled
    """Return the distance of a convex body to the polygons, capped at ``cap``.

    Parameters
    ----------
    edges, starts, boxes : ndarray
        :func:`pack_polygons`.
    body : ndarray of float64, shape (k, 2)
        The body's vertices where it stands, counter-clockwise (same units as ``edges``).
    cap : float
        Polygons whose box lies farther than ``cap`` from the body's box are skipped; the
        result is ``min(distance, cap)`` (``inf``: no cap).

    Returns
    -------
    float
        0 when the body meets a polygon (touching counts), else the least distance to a
        polygon within the cap, else ``cap``.
    """
    k = body.shape[0]
    bminx = body[:, 0].min()
    bmaxx = body[:, 0].max()
    bminy = body[:, 1].min()
    bmaxy = body[:, 1].max()
    best = cap
    for j in range(boxes.shape[0]):
        gx = max(boxes[j, 0] - bmaxx, bminx - boxes[j, 2], 0.0)
        gy = max(boxes[j, 1] - bmaxy, bminy - boxes[j, 3], 0.0)
        if math.sqrt(gx * gx + gy * gy) >= best:
            continue
        e0 = starts[j]
        e1 = starts[j + 1]
        d2 = best * best
        for e in range(e0, e1):
            cx = edges[e, 0]
            cy = edges[e, 1]
            dx = edges[e, 2]
            dy = edges[e, 3]
            for i in range(k):
                i1 = i + 1 if i + 1 < k else 0
                ax = body[i, 0]
                ay = body[i, 1]
                bx = body[i1, 0]
                by = body[i1, 1]
                if _meet(ax, ay, bx, by, cx, cy, dx, dy):
                    return 0.0
                d2 = min(
                    d2,
                    _point_seg_sq(ax, ay, cx, cy, dx, dy),
                    _point_seg_sq(cx, cy, ax, ay, bx, by),
                )
        # no edges meet: the body inside the polygon (even-odd of a body vertex), or a
        # polygon vertex inside the convex body
        px = body[0, 0]
        py = body[0, 1]
        inside = False
        for e in range(e0, e1):
            ya = edges[e, 1]
            yb = edges[e, 3]
            if (ya > py) != (yb > py):
                xa = edges[e, 0]
                xb = edges[e, 2]
                if px < xa + (py - ya) * (xb - xa) / (yb - ya):
                    inside = not inside
        if inside:
            return 0.0
        qx = edges[e0, 0]
        qy = edges[e0, 1]
        inb = True
        for i in range(k):
            i1 = i + 1 if i + 1 < k else 0
            if _orient(body[i, 0], body[i, 1], body[i1, 0], body[i1, 1], qx, qy) < 0:
                inb = False
                break
        if inb:
            return 0.0
        best = min(best, math.sqrt(d2))
    return best


@njit(cache=True)
def _poses_distance(edges, starts, boxes, fp, poses, cap):  # pragma: no cover - compiled
    n = poses.shape[0]
    k = fp.shape[0]
    out = np.empty(n)
    body = np.empty((k, 2))
    for p in range(n):
        c = math.cos(poses[p, 2])
        s = math.sin(poses[p, 2])
        for i in range(k):
            body[i, 0] = poses[p, 0] + c * fp[i, 0] - s * fp[i, 1]
            body[i, 1] = poses[p, 1] + s * fp[i, 0] + c * fp[i, 1]
        out[p] = body_distance(edges, starts, boxes, body, cap)
    return out


def bodies_distance(
    footprint: np.ndarray,
    poses: np.ndarray,
    polygons: Sequence[np.ndarray],
    cap: float = math.inf,
) -> np.ndarray:
    """Distance (m) of a convex footprint at each pose to the polygons, capped at ``cap``.

    Parameters
    ----------
    footprint : ndarray, shape (k, 2)
        Convex body vertices in the robot frame (m), in either orientation.
    poses : ndarray, shape (n, 3)
        ``(x, y, theta)`` (m, m, rad): the body turned by ``theta`` and moved to ``(x, y)``.
    polygons : sequence of ndarray, shape (k, 2)
        Simple polygons (m).
    cap : float, optional
        As :func:`body_distance`.

    Returns
    -------
    ndarray, shape (n,)
        0 where the body meets a polygon (touching counts).
    """
    packed = pack_polygons(polygons)
    fp = np.ascontiguousarray(footprint, dtype=float)
    x, y = fp[:, 0], fp[:, 1]
    if float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)) < 0.0:
        fp = np.ascontiguousarray(fp[::-1])  # counter-clockwise
    q = np.ascontiguousarray(np.asarray(poses, dtype=float).reshape(-1, 3))
    return _poses_distance(*packed, fp, q, float(cap))


def points_distance(points: np.ndarray, polygons: Sequence[np.ndarray]) -> np.ndarray:
    """Distance (m) of each point to the nearest polygon (0 inside or on one).

    Parameters
    ----------
    points : ndarray, shape (n, 2)
        World points (m).
    polygons : sequence of ndarray, shape (k, 2)
        Simple polygons (m).

    Returns
    -------
    ndarray, shape (n,)
        ``inf`` for every point when there is no polygon.
    """
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    out = np.full(len(p), np.inf)
    for v in polygons:
        a = np.asarray(v, dtype=float)
        b = np.roll(a, -1, axis=0)
        e = b - a
        ee = np.maximum(np.sum(e * e, axis=1), 1e-300)
        rel = p[:, None, :] - a[None, :, :]
        t = np.clip(np.sum(rel * e[None], axis=2) / ee[None], 0.0, 1.0)
        d = np.sqrt(np.min(np.sum((rel - t[..., None] * e[None]) ** 2, axis=2), axis=1))
        ya, yb = a[None, :, 1], b[None, :, 1]
        py = p[:, 1:2]
        crosses = (ya > py) != (yb > py)
        with np.errstate(divide="ignore", invalid="ignore"):
            xs = a[None, :, 0] + (py - ya) * (b[None, :, 0] - a[None, :, 0]) / (yb - ya)
        inside = (np.sum(crosses & (p[:, 0:1] < xs), axis=1) % 2) == 1
        out = np.minimum(out, np.where(inside, 0.0, d))
    return out
