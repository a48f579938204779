"""Bounds of a path over arc-length ranges, kept per path geometry: curvature and boxes.

:func:`kappa_table` bounds the curvature on arc-length intervals (Bernstein bounds on the
polynomial pieces), :class:`PathBoxes` the points over arc-length ranges; both are kept for
the last few paths (:func:`kappa_table_of`, :func:`path_boxes_of`), found again by the
object or by its geometry (:func:`geometry_key`): a re-plan's kept rest is a new curve object
of the same geometry. :class:`RangeMax` answers maxima over index ranges. The look-ups the
certificate makes per interval are compiled, :class:`RangeMax`'s query inside them:
:func:`boxes_kernel` (:meth:`PathBoxes.box`) and :func:`arc_kappa_kernel` (the curvature
bound over an arc).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import njit

from trajopt.geometry import kappa_bound
from trajopt.kernel_cache import watch_compiles

watch_compiles()  # a first compilation logs one notice (trajopt.kernel_cache)


def kappa_table(curve: Any) -> tuple[np.ndarray, np.ndarray]:
    """Return ``(s_edges, k)``: rigorous |curvature| bounds (1/m) ``k[i]`` on ``[s_edges[i], s_edges[i+1]]`` (m).

    Bernstein bounds (:func:`trajopt.geometry.kappa_bound`) on each polynomial piece, split
    in 8 or 64 where a piece's bound is infinite; ``([0, L], [inf])`` when there is none (a
    curve without a polynomial degree, a polyline with corners).
    """
    length = float(curve.length)
    none = (np.array([0.0, length]), np.array([math.inf]))
    deg = getattr(curve, "polynomial_degree", None)
    if deg is None:
        return none
    br = np.asarray(curve.breakpoints(), dtype=float)
    if br.shape[0] < 2:
        return none
    if deg < 2:  # straight pieces: no curvature inside, corners between them
        return (np.array([0.0, length]), np.zeros(1)) if br.shape[0] == 2 else none
    a, b = br[:-1], br[1:]
    keep = b > a
    a, b = a[keep], b[keep]
    k, e = np.full(1, math.inf), np.stack([a, b], axis=1)
    for split in (1, 8, 64):  # the Bernstein bound tightens on shorter intervals
        e = a[:, None] + (b - a)[:, None] * np.linspace(0.0, 1.0, split + 1)[None, :]
        try:
            k = kappa_bound(curve, e[:, :-1].ravel(), e[:, 1:].ravel(), int(deg))
        except (ValueError, FloatingPointError, ZeroDivisionError):
            return none
        if np.all(np.isfinite(k)):
            break
    u = np.append(e[:, :-1].ravel(), e[-1, -1])
    s_edges = np.asarray(curve.s_at_u(u), dtype=float)
    s_edges[0], s_edges[-1] = 0.0, length
    return np.maximum.accumulate(s_edges), np.asarray(k, dtype=float)


def geometry_key(path: Any) -> tuple[Any, ...]:
    """Return a key equal for two paths of the same geometry and parameter.

    A B-spline (or a path holding one as ``curve``, :class:`trajopt.smoother.SmoothPath`):
    its degree, knots and control points, byte for byte (a re-plan that keeps its rest cuts a
    new curve object of the same geometry at the same splice). Any other path: its identity
    (whoever keeps the key keeps the path too, so that the identity is not reused).
    """
    curve = getattr(path, "curve", path)
    knots, ctrl, deg = (getattr(curve, name, None) for name in ("t", "c", "k"))
    if isinstance(knots, np.ndarray) and isinstance(ctrl, np.ndarray) and isinstance(deg, int):
        return (type(path), type(curve), deg, knots.tobytes(), ctrl.shape, ctrl.tobytes())
    return (id(path),)


#: The curvature tables of the last curves certified (curve, its key, table), most recent last.
_KAPPA_TABLES: list[tuple[Any, tuple[Any, ...], tuple[np.ndarray, np.ndarray]]] = []
_KAPPA_KEPT = 4


def kappa_table_of(curve: Any) -> tuple[np.ndarray, np.ndarray]:
    """Return :func:`kappa_table` of ``curve``, reused for the last few curves.

    Found by the object, else by its geometry (:func:`geometry_key`, its domain and length):
    a re-plan's kept rest is a new curve object of the same geometry.
    """
    return _kept(_KAPPA_TABLES, curve, kappa_table)


def _kept(cache: list, curve: Any, build: Any) -> Any:
    """Return ``build(curve)`` from ``cache`` (found by the object, else by its geometry).

    ``cache`` holds ``(curve, key, value)`` with the last used last; a miss builds the value
    and keeps the :data:`_KAPPA_KEPT` most recent. A hit by geometry keeps ``curve`` as the
    entry's object (the next look-up of the same object is found by identity, without its
    key: a re-plan's curve is looked up several times).
    """
    for i, (c, _, value) in enumerate(cache):
        if c is curve:
            cache.append(cache.pop(i))
            return value
    dom = getattr(curve, "domain", None)
    key = (geometry_key(curve), None if dom is None else tuple(map(float, dom)), curve.length)
    for i, (_, k, value) in enumerate(cache):
        if k == key:
            cache.pop(i)
            cache.append((curve, k, value))
            return value
    value = build(curve)
    cache.append((curve, key, value))
    del cache[:-_KAPPA_KEPT]
    return value


def kappa_max(curve: Any) -> float:
    """Return a rigorous bound of the curve's |curvature| (1/m), ``inf`` when none is available."""
    return float(np.max(kappa_table_of(curve)[1]))


class PathBoxes:
    """Boxes that hold a path's points over arc-length ranges (a filter of far intervals).

    The path at ``n`` evenly spaced parameters ``u_k`` (about 2 cm of arc apart): its points
    ``P_k`` and their arc lengths ``s_k = path.s_at_u(u_k)`` (the function the trajectory's
    ``s`` is defined by). A point of arc length ``s`` with ``s_k <= s <= s_{k+1}`` is within
    ``(s_{k+1} - s_k) / 2`` of ``P_k`` or ``P_{k+1}`` (an arc is no shorter than its chord),
    so the box of the samples from the last ``s_k <= s0`` to the first ``s_k >= s1``, grown by
    the largest half gap (plus 1 um against rounding), holds the path over ``[s0, s1]``.
    """

    def __init__(self, path: Any) -> None:
        lo, hi = (float(x) for x in path.domain)
        n = int(min(4096, max(64, math.ceil(float(path.length) / 0.02) + 1)))
        u = np.linspace(lo, hi, n)
        pts = np.asarray(path(u), dtype=float)
        self.s = np.maximum.accumulate(np.asarray(path.s_at_u(u), dtype=float))
        self.pad = 0.5 * float(np.max(np.diff(self.s), initial=0.0)) + 1e-6
        self.ranges = RangeMax(np.stack([-pts[:, 0], pts[:, 0], -pts[:, 1], pts[:, 1]], axis=1))

    def box(self, s0: np.ndarray, s1: np.ndarray) -> tuple[np.ndarray, ...]:
        """Return ``(x_min, x_max, y_min, y_max)`` (m) of the path over ``[s0, s1]`` (m), elementwise.

        ``s0``, ``s1`` of shape (n,); compiled (:func:`boxes_kernel`).
        """
        out = boxes_kernel(
            self.s,
            self.ranges.table,
            self.pad,
            np.ascontiguousarray(s0, dtype=np.float64),
            np.ascontiguousarray(s1, dtype=np.float64),
        )
        return out[0], out[1], out[2], out[3]


#: The path boxes of the last curves certified (curve, its key, boxes), most recent last.
_BOXES: list[tuple[Any, tuple[Any, ...], PathBoxes]] = []
_KAPPA_RANGES: list[tuple[Any, tuple[Any, ...], tuple[np.ndarray, float, np.ndarray]]] = []


def path_boxes_of(curve: Any) -> PathBoxes:
    """Return :class:`PathBoxes` of ``curve``, reused as :func:`kappa_table_of` reuses its tables."""
    return _kept(_BOXES, curve, PathBoxes)


def kappa_ranges_of(curve: Any) -> tuple[np.ndarray, float, np.ndarray]:
    """Return ``(s_edges, k_top, table)``: :func:`kappa_table_of`, its largest value and its :class:`RangeMax` table.

    ``table`` of shape (levels, n, 1) (:func:`arc_kappa_kernel`'s form); reused as
    :func:`kappa_table_of` reuses its tables.
    """
    return _kept(_KAPPA_RANGES, curve, _kappa_ranges)


def _kappa_ranges(curve: Any) -> tuple[np.ndarray, float, np.ndarray]:
    s_edges, k = kappa_table_of(curve)
    return s_edges, float(np.max(k)), RangeMax(k).table[:, :, None]


class RangeMax:
    """Maxima of ``values`` over index ranges in O(1) (a sparse table).

    ``values`` of shape (n,) or (n, c) (``c`` columns answered at once). Level ``j`` holds
    the maxima of the windows of ``2^j`` values, padded with ``-inf`` to ``n`` rows, so that
    a query is one gather from the (levels, n, ...) table.
    """

    def __init__(self, values: np.ndarray) -> None:
        v = np.asarray(values, dtype=float)
        n = v.shape[0]
        levels = 1 + (int(math.floor(math.log2(n))) if n > 0 else 0)
        self.table = np.full((levels, *v.shape), -np.inf)
        self.table[0] = v
        for j in range(1, levels):
            w = 2 ** (j - 1)
            prev = self.table[j - 1]
            np.maximum(
                prev[: n - 2 * w + 1], prev[w : n - w + 1], out=self.table[j, : n - 2 * w + 1]
            )

    def __call__(self, i0: np.ndarray, i1: np.ndarray) -> np.ndarray:
        """Return the maximum over ``values[i0 : i1 + 1]`` (``i0 <= i1``), elementwise.

        Shape ``i0.shape`` (plus the columns of a 2-D ``values``). The array form of the
        compiled look-ups' query (:func:`boxes_kernel`, :func:`arc_kappa_kernel`).
        """
        n = i1 - i0 + 1
        lev = np.floor(np.log2(np.maximum(n, 1))).astype(np.int64)
        tb = self.table
        return np.maximum(tb[lev, i0], tb[lev, i1 - (1 << lev) + 1])


@njit(cache=True)
def _range_max(table, i0, i1, k):  # pragma: no cover - compiled
    """Return the maximum of column ``k`` over rows ``i0 .. i1`` of a :class:`RangeMax` table (levels, n, c).

    :meth:`RangeMax.__call__`'s query, the same float (``numpy.maximum``'s choice, NaN too).
    """
    span = i1 - i0 + 1
    lev = 0
    while (2 << lev) <= span:  # floor(log2(max(span, 1)))
        lev += 1
    x = table[lev, i0, k]
    y = table[lev, i1 - (1 << lev) + 1, k]
    if x != x or y != y:  # numpy.maximum: NaN wins
        return x + y
    return x if x >= y else y


@njit(cache=True)
def boxes_kernel(s, table, pad, s0, s1):  # pragma: no cover - compiled
    """Return :meth:`PathBoxes.box` of the arcs ``[s0, s1]`` (m): rows x_min, x_max, y_min, y_max.

    Parameters
    ----------
    s : ndarray, shape (k,)
        The samples' arc lengths (m), non-decreasing.
    table : ndarray, shape (levels, k, 4)
        The :class:`RangeMax` table of the samples' ``(-x, x, -y, y)`` (m).
    pad : float
        The boxes' growth (m).
    s0, s1 : ndarray, shape (n,)
        The arcs' ends (m).

    Returns
    -------
    ndarray, shape (4, n)
        The boxes (m): the samples from the last at or before ``s0`` to the first at or
        after ``s1``, their extremes grown by ``pad``.
    """
    n = s0.shape[0]
    last = s.shape[0] - 1
    out = np.empty((4, n))
    for q in range(n):
        i0 = min(max(np.searchsorted(s, s0[q], side="right") - 1, 0), last)
        i1 = max(min(max(np.searchsorted(s, s1[q], side="left"), 0), last), i0)
        out[0, q] = -_range_max(table, i0, i1, 0) - pad
        out[1, q] = _range_max(table, i0, i1, 1) + pad
        out[2, q] = -_range_max(table, i0, i1, 2) - pad
        out[3, q] = _range_max(table, i0, i1, 3) + pad
    return out


@njit(cache=True)
def arc_kappa_kernel(s_edges, table, s0, s1):  # pragma: no cover - compiled
    """Return the bound (1/m) of ``|kappa|`` on each arc ``[s0, s1]`` (m) from :func:`kappa_table`.

    Parameters
    ----------
    s_edges : ndarray, shape (k + 1,)
        The table's interval edges (m).
    table : ndarray, shape (levels, k, 1)
        The :class:`RangeMax` table of its bounds (1/m).
    s0, s1 : ndarray, shape (n,)
        The arcs' ends (m).

    Returns
    -------
    ndarray, shape (n,)
        The largest bound of the intervals from the one holding ``s0`` (the later one on an
        edge) to the one holding ``s1`` (the earlier one on an edge).
    """
    n = s0.shape[0]
    last = s_edges.shape[0] - 2
    out = np.empty(n)
    for q in range(n):
        i0 = min(max(np.searchsorted(s_edges, s0[q], side="right") - 1, 0), last)
        i1 = min(max(np.searchsorted(s_edges, s1[q], side="left") - 1, 0), last)
        out[q] = _range_max(table, i0, max(i0, i1), 0)
    return out
