"""The distance from points to convex polygons, compiled (the certificate's bounds)."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from trajopt.kernel_cache import watch_compiles

watch_compiles()  # a first compilation logs one notice (trajopt.kernel_cache)


@njit(cache=True)
def point_edge(px, py, ax, ay, bx, by):  # pragma: no cover - compiled
    """Return the distance (m) from ``(px, py)`` to the edge ``a -> b`` and whether it is on its left.

    The closest point of the segment: the projection's parameter clipped to ``[0, 1]``, the
    edge's squared length floored at 1e-300; "on its left" includes on the edge's line (a
    cross product ``>= 0``; ``False`` for NaN). The step every convex-polygon distance
    loop of the certificate takes per edge (:func:`point_polygon_kernel`,
    :func:`trajopt.moving._bisection_bounds.disc_robot_bounds_kernel`).
    """
    ex, ey = bx - ax, by - ay
    qx, qy = px - ax, py - ay
    ee = max(ex * ex + ey * ey, 1e-300)
    lam = min(max((qx * ex + qy * ey) / ee, 0.0), 1.0)
    return math.hypot(qx - lam * ex, qy - lam * ey), ex * qy - ey * qx >= 0.0


@njit(cache=True)
def point_polygon_kernel(p, w):  # pragma: no cover - compiled
    """Return the distance (m) from each point ``p[i]`` to the convex CCW polygon ``w[i]``; 0 inside.

    The least distance to the polygon's edges (each the closest point of the segment: the
    projection's parameter clipped to ``[0, 1]``, edge lengths floored at 1e-300), and 0
    where the point is on the left of (or on) every edge. A polygon of one vertex is a point.

    Parameters
    ----------
    p : ndarray, shape (n, 2)
        Points (m).
    w : ndarray, shape (n, m, 2)
        Polygons (m), counter-clockwise.

    Returns
    -------
    ndarray, shape (n,)
    """
    n, m = w.shape[0], w.shape[1]
    out = np.empty(n)
    for i in range(n):
        px, py = p[i, 0], p[i, 1]
        if m == 1:
            out[i] = math.hypot(px - w[i, 0, 0], py - w[i, 0, 1])
            continue
        dist = math.inf
        inside = True
        for k in range(m):
            k1 = k + 1 if k + 1 < m else 0
            r, left = point_edge(px, py, w[i, k, 0], w[i, k, 1], w[i, k1, 0], w[i, k1, 1])
            if r < dist:
                dist = r
            if not left:
                inside = False
        out[i] = 0.0 if inside else dist
    return out
