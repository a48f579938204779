"""Planar convex hulls: Andrew's monotone chain, compiled, for the footprint and the corridor."""

from __future__ import annotations

import numpy as np
from numba import njit

from trajopt.kernel_cache import watch_compiles


def convex_hull(points: np.ndarray) -> np.ndarray:
    """Return the convex hull of ``points`` (shape (m, 2)), counter-clockwise."""
    p = np.unique(np.asarray(points, dtype=float).reshape(-1, 2), axis=0)  # sorted by x, y
    if len(p) <= 2:
        return p
    h, k = monotone_chain(np.ascontiguousarray(p), len(p), 0.0)
    return p[h[: k - 1]]


watch_compiles()  # a first compilation logs one notice (trajopt.kernel_cache)


@njit(cache=True)
def monotone_chain(p, n, tol):  # pragma: no cover - compiled
    """Hull of the first ``n`` points of ``p``, sorted by ``(x, y)``, counter-clockwise.

    A point is dropped while the turn it makes with the last two hull points is ``<= tol``
    (``0``: collinear points go; a small positive ``tol`` also drops near-collinear ones).
    Returns ``(indices, k)``: ``indices[:k]`` are the hull's points in order, the last one
    repeating the first (``k`` counts it).
    """
    h = np.empty(2 * n + 1, dtype=np.int64)
    k = 0
    for i in range(n):
        while k >= 2 and _turn(p, h[k - 2], h[k - 1], i) <= tol:
            k -= 1
        h[k] = i
        k += 1
    lo = k + 1
    for i in range(n - 2, -1, -1):
        while k >= lo and _turn(p, h[k - 2], h[k - 1], i) <= tol:
            k -= 1
        h[k] = i
        k += 1
    return h, k


@njit(cache=True)
def sort_xy(p, n):  # pragma: no cover - compiled
    """Sort the first ``n`` rows of ``p`` (m, 2) in place by ``(x, y)``.

    Insertion sort: the point sets of the callers are a few hundred at most.
    """
    for i in range(1, n):
        x = p[i, 0]
        y = p[i, 1]
        j = i - 1
        while j >= 0 and (p[j, 0] > x or (p[j, 0] == x and p[j, 1] > y)):
            p[j + 1, 0] = p[j, 0]
            p[j + 1, 1] = p[j, 1]
            j -= 1
        p[j + 1, 0] = x
        p[j + 1, 1] = y


@njit(cache=True, inline="always")
def _turn(p, a, b, c):  # pragma: no cover - compiled
    """Cross product ``(p[b] - p[a]) x (p[c] - p[a])``: > 0 for a left turn."""
    return (p[b, 0] - p[a, 0]) * (p[c, 1] - p[a, 1]) - (p[b, 1] - p[a, 1]) * (p[c, 0] - p[a, 0])
