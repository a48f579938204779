"""Polygon obstacles: their checks and their conservative, exact rasterisation.

A polygon is a simple (non-self-intersecting) ring of vertices in world metres, convex or
not, given without its closing vertex or with it (a last vertex equal to the first is
dropped). :func:`rasterize_polygons` marks every cell whose *closed* square meets a polygon
(its interior or its boundary), decided exactly rather than by sampling: a square meets a
simple polygon iff one of the polygon's edges meets the square, or the square lies inside
the polygon (then so does its centre), and a polygon inside the square has its edges in it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numba import njit

from astar.errors import InvalidInputError
from astar.validation import positive_float, short_repr

#: Points within this many cells of a square count as touching it (so that a polygon edge
#: lying on a grid line, up to rounding, marks the cells on both sides: conservative).
TOUCH_CELLS = 1e-9


def check_polygon(index: int, value: object) -> np.ndarray:
    """Return polygon ``index`` as a float array ``(k, 2)`` (m), checked.

    Parameters
    ----------
    index : int
        Its position in the ``polygons`` argument (named in errors).
    value : array_like, shape (k, 2)
        Vertices in world metres, in either orientation; a closing vertex equal to the
        first is dropped.

    Returns
    -------
    ndarray of float, shape (k, 2)
        The vertices, counter-clockwise, without a closing vertex.

    Raises
    ------
    InvalidInputError
        Not an array of shape ``(k, 2)``; a coordinate not finite; two consecutive
        vertices equal; fewer than 3 distinct vertices; zero area; two edges that cross or
        touch other than at their shared vertex (self-intersecting).
    """
    field = f"polygons[{index}]"
    try:
        v = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(
            f"{field} must be an array of (x, y) vertices in m, got {short_repr(value)}"
        ) from exc
    if v.ndim != 2 or v.shape[1] != 2:
        raise InvalidInputError(
            f"{field} must have shape (k, 2) (x, y vertices in m), got {v.shape}"
        )
    if not np.all(np.isfinite(v)):
        bad = int(np.flatnonzero(~np.all(np.isfinite(v), axis=1))[0])
        raise InvalidInputError(
            f"{field} vertices must be finite, got vertex {bad} = {v[bad].tolist()}"
        )
    if len(v) >= 2 and np.array_equal(v[0], v[-1]):
        v = v[:-1]  # the closing vertex
    if len(np.unique(v, axis=0)) < 3:
        raise InvalidInputError(
            f"{field} needs at least 3 distinct vertices (a polygon), got "
            f"{len(np.unique(v, axis=0))}: {v.tolist()}"
        )
    nxt = np.roll(v, -1, axis=0)
    same = np.flatnonzero(np.all(v == nxt, axis=1))
    if len(same):
        i = int(same[0])
        raise InvalidInputError(
            f"{field} repeats a vertex: vertices {i} and {(i + 1) % len(v)} are both "
            f"{v[i].tolist()} (consecutive vertices must differ)"
        )
    crossing = _self_intersection(v)
    if crossing is not None:
        i, j = crossing
        raise InvalidInputError(
            f"{field} is self-intersecting: edge {i} ({v[i].tolist()} -> "
            f"{v[(i + 1) % len(v)].tolist()}) meets edge {j} ({v[j].tolist()} -> "
            f"{v[(j + 1) % len(v)].tolist()}); a polygon must be a simple ring"
        )
    # the area relative to the polygon's size: zero (or rounding noise) is refused
    rel = v - v.mean(axis=0)
    rnxt = np.roll(rel, -1, axis=0)
    area = 0.5 * float(np.sum(rel[:, 0] * rnxt[:, 1] - rnxt[:, 0] * rel[:, 1]))
    scale = float(np.max(np.abs(rel))) ** 2
    if abs(area) <= 1e-12 * scale:
        raise InvalidInputError(f"{field} must have a non-zero area, got area {area:g} m^2")
    v = v if area > 0 else v[::-1].copy()
    v.flags.writeable = False
    return v


def _orient(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Sign of the turn ``a -> b -> c`` (+1 left, -1 right, 0 collinear), broadcast."""
    cross = (b[..., 0] - a[..., 0]) * (c[..., 1] - a[..., 1]) - (b[..., 1] - a[..., 1]) * (
        c[..., 0] - a[..., 0]
    )
    return np.sign(cross)


def _on_segment(a: np.ndarray, b: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Whether ``p`` (collinear with ``a b``) lies in the segment's bounding box, broadcast."""
    return (
        (np.minimum(a[..., 0], b[..., 0]) <= p[..., 0])
        & (p[..., 0] <= np.maximum(a[..., 0], b[..., 0]))
        & (np.minimum(a[..., 1], b[..., 1]) <= p[..., 1])
        & (p[..., 1] <= np.maximum(a[..., 1], b[..., 1]))
    )


def segments_meet(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Whether closed segments ``a b`` and ``c d`` share a point (touching counts), broadcast.

    Parameters
    ----------
    a, b, c, d : ndarray, shape (..., 2)
        End points (m).

    Returns
    -------
    ndarray of bool, shape (...)
    """
    o1, o2 = _orient(a, b, c), _orient(a, b, d)
    o3, o4 = _orient(c, d, a), _orient(c, d, b)
    proper = (o1 * o2 < 0) & (o3 * o4 < 0)
    touch = (
        ((o1 == 0) & _on_segment(a, b, c))
        | ((o2 == 0) & _on_segment(a, b, d))
        | ((o3 == 0) & _on_segment(c, d, a))
        | ((o4 == 0) & _on_segment(c, d, b))
    )
    return proper | touch


def _self_intersection(v: np.ndarray) -> tuple[int, int] | None:
    """Return the first pair of edges ``(i, j)`` of the ring ``v`` that meet improperly, or None.

    Edges that are not neighbours must not meet at all; neighbours share exactly their
    common vertex (they must not fold back over each other).
    """
    k = len(v)
    a, b = v, np.roll(v, -1, axis=0)
    i, j = np.triu_indices(k, 1)
    meet = segments_meet(a[i], b[i], a[j], b[j])
    neighbours = (j == i + 1) | ((i == 0) & (j == k - 1))
    # neighbours i, i+1 share b[i] == a[i+1]: they fold back iff the far end of one lies
    # on the other (collinear and overlapping beyond the shared vertex)
    ii, jj = np.where(j == i + 1, i, j), np.where(j == i + 1, j, i)  # ii's end is jj's start
    fold = (_orient(a[ii], b[ii], b[jj]) == 0) & (
        _on_segment(a[ii], b[ii], b[jj]) | _on_segment(a[jj], b[jj], a[ii])
    )
    bad = np.where(neighbours, fold, meet)
    if k == 3:
        bad[:] = False  # three distinct non-collinear vertices: always a simple triangle
    hits = np.flatnonzero(bad)
    if not len(hits):
        return None
    return int(i[hits[0]]), int(j[hits[0]])


def check_bounds(value: object) -> tuple[float, float, float, float]:
    """Return ``bounds`` as ``(xmin, ymin, xmax, ymax)`` (m), checked.

    Raises
    ------
    InvalidInputError
        Not four numbers, a value not finite, or ``xmax <= xmin`` / ``ymax <= ymin``
        (an empty box).
    """
    try:
        b = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(
            f"bounds must be (xmin, ymin, xmax, ymax) in m, got {short_repr(value)}"
        ) from exc
    if b.shape != (4,):
        raise InvalidInputError(
            f"bounds must be (xmin, ymin, xmax, ymax) in m, got shape {b.shape}: {short_repr(value)}"
        )
    if not np.all(np.isfinite(b)):
        raise InvalidInputError(f"bounds must be finite, got {b.tolist()}")
    xmin, ymin, xmax, ymax = (float(x) for x in b)
    if not (xmax > xmin and ymax > ymin):
        raise InvalidInputError(
            f"bounds must enclose an area (xmax > xmin and ymax > ymin), got {b.tolist()}"
        )
    return xmin, ymin, xmax, ymax


def grid_shape(bounds: tuple[float, float, float, float], resolution: float) -> tuple[int, int]:
    """Rows and columns ``(ny, nx)`` of cells of side ``resolution`` (m) covering ``bounds``.

    A count that is a whole number up to rounding (1e-9 cells) is not rounded up.
    """
    xmin, ymin, xmax, ymax = bounds
    fx, fy = (xmax - xmin) / resolution, (ymax - ymin) / resolution
    nx = max(1, math.ceil(fx - 1e-9 * max(1.0, fx)))
    ny = max(1, math.ceil(fy - 1e-9 * max(1.0, fy)))
    return ny, nx


@njit(cache=True, nogil=True)
def _edges_kernel(
    occ: np.ndarray, g: np.ndarray, eps: float
) -> None:  # pragma: no cover - compiled
    """Mark the cells whose closed square meets an edge of the ring ``g`` (in cells)."""
    ny, nx = occ.shape
    k = g.shape[0]
    for i in range(k):
        j = i + 1 if i + 1 < k else 0
        x0, y0, x1, y1 = g[i, 0], g[i, 1], g[j, 0], g[j, 1]
        lo, hi = min(x0, x1), max(x0, x1)
        c0 = max(0, math.ceil(lo - eps) - 1)
        c1 = min(nx - 1, math.floor(hi + eps))
        for c in range(c0, c1 + 1):
            if x1 == x0:
                ylo, yhi = min(y0, y1), max(y0, y1)
            else:
                xa = min(max(float(c), lo), hi)
                xb = min(max(c + 1.0, lo), hi)
                t = (y1 - y0) / (x1 - x0)
                ya, yb = y0 + (xa - x0) * t, y0 + (xb - x0) * t
                ylo, yhi = min(ya, yb), max(ya, yb)
            r0 = max(0, math.ceil(ylo - eps) - 1)
            r1 = min(ny - 1, math.floor(yhi + eps))
            for r in range(r0, r1 + 1):
                occ[r, c] = True


@njit(cache=True, nogil=True)
def _interior_kernel(occ: np.ndarray, g: np.ndarray) -> None:  # pragma: no cover - compiled
    """Mark the cells whose centre lies inside the ring ``g`` (in cells; even-odd rows)."""
    ny, nx = occ.shape
    k = g.shape[0]
    r0 = max(0, math.floor(g[:, 1].min() - 0.5))
    r1 = min(ny - 1, math.ceil(g[:, 1].max() - 0.5))
    xs = np.empty(k)
    for r in range(r0, r1 + 1):
        y = r + 0.5  # the centres' y, in cells
        m = 0
        for i in range(k):
            j = i + 1 if i + 1 < k else 0
            ya, yb = g[i, 1], g[j, 1]
            if (ya <= y) != (yb <= y):  # half-open: a vertex on the line counts once
                xs[m] = g[i, 0] + (y - ya) * (g[j, 0] - g[i, 0]) / (yb - ya)
                m += 1
        row = np.sort(xs[:m])
        for p in range(0, m - 1, 2):
            # centres c + 0.5 in [row[p], row[p + 1]]
            c0 = max(0, math.ceil(row[p] - 0.5))
            c1 = min(nx - 1, math.floor(row[p + 1] - 0.5))
            for c in range(c0, c1 + 1):
                occ[r, c] = True


def _mark_edges(occ: np.ndarray, v: np.ndarray, origin: tuple[float, float], res: float) -> None:
    """Mark the cells whose closed square meets an edge of the ring ``v`` (exact, clipped).

    Column by column: the part of the edge over the column's closed x-range spans a
    y-interval; the closed squares of that column meeting the interval are marked (compiled:
    a window of a parking map holds tens of polygons and is rasterised once per fit).
    """
    _edges_kernel(occ, (v - origin) / res, TOUCH_CELLS)


def _mark_interior(occ: np.ndarray, v: np.ndarray, origin: tuple[float, float], res: float) -> None:
    """Mark the cells whose centre lies inside the ring ``v`` (even-odd scan lines).

    A cell that no edge meets lies wholly inside or wholly outside the polygon, so its
    centre decides; a cell some edge meets is already marked.
    """
    _interior_kernel(occ, (v - origin) / res)


def rasterize_polygons(
    polygons: Sequence[object], resolution: object, bounds: object
) -> tuple[np.ndarray, float, tuple[float, float], tuple[np.ndarray, ...]]:
    """Occupancy of the cells (closed squares) that the polygons meet, with its frame.

    Parameters
    ----------
    polygons : sequence of array_like, shape (k, 2)
        Simple polygons in world metres (see :func:`check_polygon`).
    resolution : float
        Cell side (m, > 0, finite).
    bounds : tuple of float
        ``(xmin, ymin, xmax, ymax)`` (m): the map's extent; ``(xmin, ymin)`` is the
        origin and the last row and column reach ``xmax`` / ``ymax`` or just beyond.

    Returns
    -------
    occupied : ndarray of bool, shape (ny, nx)
    resolution : float
    origin : tuple of float
        ``(xmin, ymin)``.
    rings : tuple of ndarray, shape (k, 2)
        The checked polygons (:func:`check_polygon`: read-only, counter-clockwise).

    Raises
    ------
    InvalidInputError
        As :func:`check_polygon` and :func:`check_bounds`; ``resolution`` not finite or
        ``<= 0``; ``polygons`` not a sequence.
    """
    res = positive_float("resolution", resolution)
    box = check_bounds(bounds)
    if isinstance(polygons, (str, bytes)) or not isinstance(polygons, Sequence | np.ndarray):
        raise InvalidInputError(
            f"polygons must be a sequence of (k, 2) vertex arrays in m, got {short_repr(polygons)}"
        )
    rings = tuple(check_polygon(i, p) for i, p in enumerate(polygons))
    return rasterize_rings(rings, res, box)


def rasterize_rings(
    rings: tuple[np.ndarray, ...], resolution: float, bounds: tuple[float, float, float, float]
) -> tuple[np.ndarray, float, tuple[float, float], tuple[np.ndarray, ...]]:
    """Rasterise rings :func:`check_polygon` has already checked (no checks repeated).

    For a finer raster of a map's own polygons over a window
    (:meth:`astar.OccupancyGrid.polygon_window`): the rings come from :func:`check_polygon`,
    ``resolution`` is a positive finite float and ``bounds`` a box of
    :func:`check_bounds`; anything else is the caller's error.
    """
    res = float(resolution)
    box = bounds
    ny, nx = grid_shape(box, res)
    occ = np.zeros((ny, nx), dtype=bool)
    origin = np.array([box[0], box[1]])
    # a polygon whose box lies a cell or more outside the grid marks nothing (a window of a
    # larger map: the fits' fine rasters)
    x_hi, y_hi = box[0] + (nx + 1) * res, box[1] + (ny + 1) * res
    x_lo, y_lo = box[0] - res, box[1] - res
    for v in rings:
        if (
            v[:, 0].min() > x_hi
            or v[:, 0].max() < x_lo
            or v[:, 1].min() > y_hi
            or v[:, 1].max() < y_lo
        ):
            continue
        _mark_edges(occ, v, origin, res)
        _mark_interior(occ, v, origin, res)
    return occ, res, (box[0], box[1]), rings
