"""Corridors of convex polygons grown around a path in continuous space.

A :class:`PolygonCorridor` is a chain of convex polygons (:class:`ConvexPolygon`, world
metres, half-planes ``A @ p <= b``) that covers a path and keeps a clearance ``radius``
from the *raw* map: from every occupied cell taken as a closed square and from the outside
of the map. Unlike the axis-aligned boxes of :mod:`trajopt.corridor`, the polygons are not
made of cells: in a diagonal street they are long rotated regions, and consecutive ones
overlap along a stretch of the path rather than in a sliver.

Contract for certified clearance
--------------------------------
The set of robot centres that touch an occupied square ``Q`` is ``Q`` dilated by a disk of
radius ``r`` (a rounded square). A half-plane ``a . p <= b`` with ``|a| = 1`` keeps every
point at least ``r`` from ``Q`` exactly when ``b <= min over Q's four corners of a . c - r``.
Every obstacle row of a polygon is built with equality there, so every polygon keeps
``r`` from every square by construction. :func:`build_polygon_corridor` does not rely on
that: it *certifies* every region after growing it with the exact distance from the
polygon to every occupied square within reach and to the outside of the map
(:func:`polygon_clearance` computes the same distance for any polygon), and raises rather
than return a region closer than ``radius - CLEARANCE_TOL_M``.

Growth (segment-ellipse method)
-------------------------------
1. **Path preparation.** The path points (cell centres of an A* path, or world points) are
   checked: every point and every segment between consecutive points must keep ``radius``
   from the raw map. Interior points closer than ``radius + centre_trigger_cells`` to an
   obstacle are then pushed away from their nearest obstacle point (two passes; each move
   is the step of ``centre_cells``, half or a quarter of it that raises the point's
   clearance most, and is kept only when both adjacent segments keep ``radius``), because
   an A* path hugs the inflated walls and a seed touching a dilated obstacle cannot grow
   past it. The path is then simplified greedily: a segment replaces the points it skips
   only if it keeps at least the clearance of the points and segments it replaces (capped
   at ``radius + open_cells``, less ``simplify_slack_cells``, never below ``radius``) and
   is at most ``max_segment_cells`` long. The result is the corridor's ``path``.
2. **Seeds.** Region ``k`` is grown around segment ``k`` of that path, extended by up to
   ``overlap_cells`` into the previous and next segments (the extension is halved, then
   dropped, while the seed's convex hull comes closer than ``radius`` to an obstacle).
   Consecutive regions both contain the extension around their shared vertex, so they
   overlap along at least that stretch of the path.
3. **Half-planes.** The obstacle rectangles (maximal runs of occupied cells merged across
   rows) near the seed are taken in order of their distance from the seed segment's
   midpoint in the metric of an ellipse centred there: semi-axis ``L / 2 + e + 0.5`` cells
   along the segment (``L`` its length, ``e`` its larger seed extension) and ``min(that,
   max(0.5, c))`` across, ``c`` the segment's distance to the nearest rectangle (cells).
   Each rectangle not yet excluded adds the half-plane tangent to its ``r``-dilation whose
   normal is the ellipse's gradient at the rectangle's nearest point; when that line would
   cut the seed, the normal is the direction of the closest pair between the seed hull and
   the rectangle instead (a separating direction, which exists since the seed keeps
   ``radius``). Every rectangle the new half-plane already keeps ``r`` away is dropped. A
   window (the seed's bounding box grown by ``margin_cells``, inside the map shrunk by
   ``r``) closes the region.

Degenerate regions
------------------
Where the free space of the robot centre has no interior (a passage exactly ``2 r``
wide, a door exactly ``2 r`` wide), the half-planes leave a segment (the clipped polygon
has fewer than 3 vertices or an area of at most 1e-9 square cells). Such a region is kept
as a *degenerate* :class:`ConvexPolygon`: its ``vertices`` are the two ends of its seed
segment, its first two rows state the segment's line as two opposite inequalities and
the other two are end caps (:attr:`ConvexPolygon.line` gives the line as one equality,
which a QP should use instead of the two opposite rows). Its overlaps with its neighbours
may be a single point (the shared path vertex).
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from trajopt import _polygon_kernels as _k
from trajopt.clearance import grid_cells, merge_rects, polygon_clearance
from trajopt.errors import InvalidInputError, SmoothingError

__all__ = [
    "CLEARANCE_TOL_M",
    "ConvexPolygon",
    "PolygonCorridor",
    "build_polygon_corridor",
    "polygon_clearance",
]

logger = logging.getLogger(__name__)

#: Absolute tolerance (m) of every clearance check of this module: a region is certified
#: when its exact clearance is at least ``radius - CLEARANCE_TOL_M``. Obstacle rows are
#: tangent to the dilated squares, so a region touches ``radius`` exactly there; the
#: tolerance only absorbs floating-point rounding (about 1e-13 m on maps of a few
#: thousand cells).
CLEARANCE_TOL_M = 1e-9

#: Slack (m) of the path-in-region tests: absorbs the rounding of points that lie on a
#: region's boundary (a seed touching a dilated obstacle, a segment along a row).
_ROUND_M = 1e-2 * CLEARANCE_TOL_M
_BUCKET_CELLS = 8
_MAX_SIDES = 256


def _readonly(a: Any, dtype: Any) -> np.ndarray:
    out = np.array(a, dtype=dtype, copy=True)
    out.flags.writeable = False
    return out


# ---------------------------------------------------------------- the polygon value
@dataclass(frozen=True, slots=True)
class ConvexPolygon:
    """A convex region of the plane in world metres: ``{p : A @ p <= b}``.

    Attributes
    ----------
    A : ndarray of float, shape (m, 2)
        Outward unit normals of the half-planes (rows of norm 1). For a polygon grown by
        :func:`build_polygon_corridor`, row ``i`` holds the edge from ``vertices[i]`` to
        ``vertices[i + 1]``.
    b : ndarray of float, shape (m,)
        Offsets (m).
    vertices : ndarray of float, shape (k, 2)
        Corners (m), counter-clockwise; ``k >= 3`` for a polygon with interior. A
        degenerate region has ``k = 2`` (a segment) or ``k = 1`` (a point).
    degenerate : bool
        Whether the region has no interior (module docstring, *Degenerate regions*).

    Notes
    -----
    ``vertices`` and ``{A @ p <= b}`` describe the same set up to floating-point rounding
    of the vertices (far below :data:`CLEARANCE_TOL_M`). Arrays are copied and made
    read-only.
    """

    A: np.ndarray
    b: np.ndarray
    vertices: np.ndarray
    degenerate: bool = False

    def __post_init__(self) -> None:
        a = np.array(self.A, dtype=float, copy=True)
        b = np.array(self.b, dtype=float, copy=True)
        v = np.array(self.vertices, dtype=float, copy=True)
        if a.ndim != 2 or a.shape[1] != 2 or a.shape[0] < 1:
            raise InvalidInputError(f"A must have shape (m, 2) with m >= 1, got {a.shape}")
        if b.shape != (a.shape[0],):
            raise InvalidInputError(f"b must have shape ({a.shape[0]},) to match A, got {b.shape}")
        if v.ndim != 2 or v.shape[1] != 2 or v.shape[0] < 1:
            raise InvalidInputError(f"vertices must have shape (k, 2) with k >= 1, got {v.shape}")
        if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b)) and np.all(np.isfinite(v))):
            raise InvalidInputError("A, b and vertices must be finite")
        norms = np.hypot(a[:, 0], a[:, 1])
        if np.any(np.abs(norms - 1.0) > 1e-9):
            i = int(np.argmax(np.abs(norms - 1.0)))
            raise InvalidInputError(f"rows of A must have norm 1; row {i} has norm {norms[i]:.6g}")
        if not self.degenerate:
            if v.shape[0] < 3:
                raise InvalidInputError(
                    f"a non-degenerate polygon needs >= 3 vertices, got {v.shape[0]}"
                )
            if _shoelace(v) <= 0.0:
                raise InvalidInputError("vertices must be counter-clockwise with positive area")
        elif v.shape[0] > 2:
            raise InvalidInputError(
                f"a degenerate region has 1 or 2 vertices (a point or a segment), got {v.shape[0]}"
            )
        for name, arr in (("A", a), ("b", b), ("vertices", v)):
            arr.flags.writeable = False
            object.__setattr__(self, name, arr)
        object.__setattr__(self, "degenerate", bool(self.degenerate))

    @classmethod
    def _construct_fast(
        cls, A: np.ndarray, b: np.ndarray, vertices: np.ndarray, degenerate: bool = False
    ) -> ConvexPolygon:
        """Build without validation (internal: fresh float arrays of the right shapes)."""
        self = object.__new__(cls)
        for name, arr in (("A", A), ("b", b), ("vertices", vertices)):
            arr = np.ascontiguousarray(arr, dtype=float)
            arr.flags.writeable = False
            object.__setattr__(self, name, arr)
        object.__setattr__(self, "degenerate", bool(degenerate))
        return self

    @property
    def n_sides(self) -> int:
        """Number of half-plane rows ``m``."""
        return int(self.A.shape[0])

    @property
    def area(self) -> float:
        """Area (m^2); 0 for a degenerate region."""
        if self.degenerate:
            return 0.0
        return _shoelace(self.vertices)

    @property
    def line(self) -> tuple[np.ndarray, float] | None:
        """For a degenerate segment, its line as ``(a, c)``: the region lies on
        ``a @ p == c`` (``a`` = ``A[0]``, shape (2,)); ``None`` otherwise."""
        if not self.degenerate or self.vertices.shape[0] != 2:
            return None
        return self.A[0].copy(), float(self.b[0])

    def contains(self, points: Any, tol: float = 0.0) -> np.ndarray:
        """Whether world points lie in the region.

        Parameters
        ----------
        points : array_like, shape (..., 2)
            World points (m).
        tol : float, optional
            Slack (m) on every row: ``A @ p <= b + tol``.

        Returns
        -------
        ndarray of bool, shape (...)
        """
        p = np.asarray(points, dtype=float)
        s = p @ self.A.T - self.b
        return np.all(s <= tol, axis=-1)

    def intersection(self, other: ConvexPolygon, tol: float = 0.0) -> ConvexPolygon:
        """The intersection of two regions (a region; degenerate when it has no interior).

        Parameters
        ----------
        other : ConvexPolygon
        tol : float, optional
            Slack (m) added to ``other``'s rows when clipping (default 0: the exact
            intersection; regions that touch give a degenerate one).

        Returns
        -------
        ConvexPolygon

        Raises
        ------
        InvalidInputError
            When the regions do not meet.
        """
        out = _intersect(self, other, tol)
        if out is None:
            raise InvalidInputError("the two regions do not intersect")
        return out


def _shoelace(v: np.ndarray) -> float:
    x, y = v[:, 0], v[:, 1]
    return 0.5 * float(
        x[:-1] @ y[1:] - x[1:] @ y[:-1] + x[-1] * y[0] - x[0] * y[-1]
    )


def _point_region(p: np.ndarray) -> ConvexPolygon:
    a = np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]])
    b = np.array([p[0], -p[0], p[1], -p[1]])
    return ConvexPolygon._construct_fast(a, b, np.array([p], dtype=float), True)


def _segment_region(p: np.ndarray, q: np.ndarray) -> ConvexPolygon:
    """Degenerate region: rows 0 and 1 the line through ``p`` and ``q``, 2 and 3 the caps."""
    d = q - p
    ln = math.hypot(d[0], d[1])
    if ln == 0.0:
        return _point_region(p)
    u = d / ln
    n = np.array([-u[1], u[0]])
    a = np.array([n, -n, u, -u])
    b = np.array([n @ p, -(n @ p), u @ q, -(u @ p)])
    return ConvexPolygon._construct_fast(a, b, np.array([p, q], dtype=float), True)


def _degenerate_from(v: np.ndarray) -> ConvexPolygon:
    """A point or segment region spanning vertices ``v`` (shape (n, 2), n >= 1) that lie
    on one line (or at one point)."""
    if len(v) == 1:
        return _point_region(v[0])
    d = np.hypot(*(v[:, None, :] - v[None, :, :]).transpose(2, 0, 1))
    i, j = np.unravel_index(int(np.argmax(d)), d.shape)
    if d[i, j] == 0.0:
        return _point_region(v[0])
    return _segment_region(v[min(i, j)], v[max(i, j)])


def _intersect(p1: ConvexPolygon, p2: ConvexPolygon, tol: float) -> ConvexPolygon | None:
    rows = np.column_stack([p2.A, p2.b])
    v, lab, n = _k.clip_convex(
        np.ascontiguousarray(p1.vertices), p1.vertices.shape[0], rows, rows.shape[0], tol
    )
    if n == 0:
        return None
    if n >= 3 and not p1.degenerate and _shoelace(v) > 1e-18:
        a = np.empty((n, 2))
        b = np.empty(n)
        for i in range(n):
            if lab[i] >= 0:
                a[i], b[i] = p2.A[lab[i]], p2.b[lab[i]]
            else:  # an edge of p1: its row is the one the edge's two ends lie on
                w = np.vstack([v[i], v[(i + 1) % n]])
                res = np.abs(w @ p1.A.T - p1.b).max(axis=0)
                j = int(np.argmin(res))
                a[i], b[i] = p1.A[j], p1.b[j]
        return ConvexPolygon._construct_fast(a, b, v, False)
    return _degenerate_from(v)


# ---------------------------------------------------------------- the corridor value
@dataclass(frozen=True, slots=True)
class PolygonCorridor:
    """A chain of overlapping convex regions covering a path, certified against a raw map.

    Region ``k`` was grown around segment ``k`` of ``path`` (vertices ``k`` and ``k + 1``)
    and contains it.

    Attributes
    ----------
    regions : tuple of ConvexPolygon, length m
        The regions (world metres), in path order.
    path : ndarray of float, shape (m + 1, 2)
        The polyline the regions were grown around (m): the input path, centred and
        simplified (module docstring). Its first and last points are the input's.
    path_s : ndarray of float, shape (m + 1,)
        Arc length (m) of each ``path`` vertex.
    source_index : ndarray of int64, shape (m + 1,)
        Index into ``input_path`` of the point each ``path`` vertex came from (interior
        vertices moved by at most ``centre_cells`` when centred).
    input_path : ndarray of float, shape (N, 2)
        The path as given (m): cell centres for a grid path.
    region_s : ndarray of float, shape (m, 2)
        For each region the largest arc-length interval ``[lo, hi]`` (m) of ``path`` inside
        it that contains its own segment.
    region_index : ndarray of int64, shape (m, 2)
        The ``path`` vertices ``first..last`` (inclusive) inside that interval.
    transitions_m : ndarray of float, shape (m - 1,)
        Arc length (m) where region ``k`` hands over to region ``k + 1``: a point of
        ``path`` inside both, in the overlap interval around their shared vertex (its
        midpoint, limited to between the midpoints of the two segments); increasing.
    transition_points : ndarray of float, shape (m - 1, 2)
        The path points (m) at ``transitions_m``.
    overlap_s : ndarray of float, shape (m - 1, 2)
        The largest arc-length interval (m) of ``path`` inside both region ``k`` and
        region ``k + 1`` that contains their shared vertex.
    overlaps : tuple of ConvexPolygon, length m - 1
        ``regions[k] & regions[k + 1]`` (degenerate where they meet in a segment or a point).
    clearance_m : ndarray of float, shape (m,)
        The certified clearance of each region (m): its exact distance to the raw map's
        occupied squares and the outside of the map, capped at ``radius + resolution``.
    radius : float
        The clearance (m) every region keeps (within :data:`CLEARANCE_TOL_M`).
    resolution : float
        Cell side of the map (m).
    origin : tuple of float
        Map origin (m).
    """

    regions: tuple[ConvexPolygon, ...]
    path: np.ndarray
    path_s: np.ndarray
    source_index: np.ndarray
    input_path: np.ndarray
    region_s: np.ndarray
    region_index: np.ndarray
    transitions_m: np.ndarray
    transition_points: np.ndarray
    overlap_s: np.ndarray
    overlaps: tuple[ConvexPolygon, ...]
    clearance_m: np.ndarray
    radius: float
    resolution: float
    origin: tuple[float, float]
    _all_a: np.ndarray = field(init=False, repr=False, compare=False)
    _all_b: np.ndarray = field(init=False, repr=False, compare=False)
    _owner: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "regions", tuple(self.regions))
        object.__setattr__(self, "overlaps", tuple(self.overlaps))
        m = len(self.regions)
        if m < 1:
            raise InvalidInputError("a polygon corridor needs at least one region")
        if len(self.overlaps) != m - 1:
            raise InvalidInputError(f"need {m - 1} overlaps for {m} regions, got {len(self.overlaps)}")
        for name in ("path", "input_path", "transition_points"):
            object.__setattr__(self, name, _readonly(getattr(self, name), float).reshape(-1, 2))
        for name in ("path_s", "transitions_m", "clearance_m"):
            object.__setattr__(self, name, _readonly(getattr(self, name), float).reshape(-1))
        object.__setattr__(self, "region_s", _readonly(self.region_s, float).reshape(-1, 2))
        object.__setattr__(self, "overlap_s", _readonly(self.overlap_s, float).reshape(-1, 2))
        object.__setattr__(self, "source_index", _readonly(self.source_index, np.int64).reshape(-1))
        object.__setattr__(
            self, "region_index", _readonly(self.region_index, np.int64).reshape(-1, 2)
        )
        object.__setattr__(self, "radius", float(self.radius))
        object.__setattr__(self, "resolution", float(self.resolution))
        object.__setattr__(self, "origin", (float(self.origin[0]), float(self.origin[1])))
        all_a = np.concatenate([r.A for r in self.regions])
        all_b = np.concatenate([r.b for r in self.regions])
        owner = np.repeat(np.arange(m), [r.n_sides for r in self.regions])
        for arr in (all_a, all_b, owner):
            arr.flags.writeable = False
        object.__setattr__(self, "_all_a", all_a)
        object.__setattr__(self, "_all_b", all_b)
        object.__setattr__(self, "_owner", owner)

    def __len__(self) -> int:
        return len(self.regions)

    @property
    def length_m(self) -> float:
        """Length of ``path`` (m)."""
        return float(self.path_s[-1])

    @property
    def overlap_areas(self) -> np.ndarray:
        """Area (m^2) of each overlap, shape (m - 1,)."""
        return np.array([o.area for o in self.overlaps], dtype=float)

    @property
    def overlap_lengths_m(self) -> np.ndarray:
        """Length (m) of path inside each overlap interval, shape (m - 1,)."""
        return self.overlap_s[:, 1] - self.overlap_s[:, 0]

    def contains(self, points: Any, tol: float = 0.0) -> np.ndarray:
        """Whether each world point (shape ``(..., 2)``, m) lies in at least one region
        (``tol`` m of slack on every row)."""
        p = np.asarray(points, dtype=float)
        flat = p.reshape(-1, 2)
        viol = flat @ self._all_a.T - self._all_b > tol  # (n, rows)
        m = len(self.regions)
        bad = np.zeros((flat.shape[0], m), dtype=bool)
        for k in range(m):
            bad[:, k] = viol[:, self._owner == k].any(axis=1)
        return (~bad).any(axis=1).reshape(p.shape[:-1])

    def region_of(self, s_m: Any) -> np.ndarray:
        """Index of the region whose share of ``path`` holds arc length ``s_m`` (m)."""
        return np.searchsorted(self.transitions_m, np.asarray(s_m, dtype=float), side="right")


# ---------------------------------------------------------------- obstacle index
class _Index:
    """Obstacle rectangles of a map window (cell units) with a bucket grid."""

    __slots__ = ("rects", "meta", "bstart", "bids", "stamp", "buf")

    def __init__(self, occ: np.ndarray, x0: int, x1: int, y0: int, y1: int) -> None:
        ny, nx = occ.shape
        x0, y0 = max(0, x0), max(0, y0)
        x1, y1 = min(nx, x1), min(ny, y1)
        if x1 <= x0 or y1 <= y0:
            rects = np.zeros((0, 4))
            x0, y0, x1, y1 = 0, 0, 1, 1
        else:
            rects = merge_rects(np.ascontiguousarray(occ[y0:y1, x0:x1]), x0, y0)
        bs = _BUCKET_CELLS
        nbx = max(1, -(-(x1 - x0) // bs))
        nby = max(1, -(-(y1 - y0) // bs))
        self.rects = rects
        self.meta = np.array([x0, y0, bs, nbx, nby, nx, ny], dtype=np.int64)
        self.bstart, self.bids = _k.build_buckets(rects, x0, y0, bs, nbx, nby)
        self.stamp = np.zeros(len(rects) + 1, dtype=np.int64)
        self.buf = np.empty(max(1, len(rects)), dtype=np.int64)

    @property
    def args(self) -> tuple:
        return (self.rects, self.meta, self.bstart, self.bids, self.stamp, self.buf)


# ---------------------------------------------------------------- helpers
def _path_points(path: Any, res: float, ox: float, oy: float) -> np.ndarray:
    """World points (m) of a GridPath / integer cells (cell centres) or float points."""
    cells = getattr(path, "cells", None)
    arr = np.asarray(path if cells is None else cells)
    if arr.ndim != 2 or arr.shape[1] != 2 or arr.shape[0] < 1:
        raise InvalidInputError(f"path must have shape (n, 2) with n >= 1, got {arr.shape}")
    if np.issubdtype(arr.dtype, np.integer):
        c = arr.astype(float)
        return np.column_stack([ox + (c[:, 0] + 0.5) * res, oy + (c[:, 1] + 0.5) * res])
    if not np.issubdtype(arr.dtype, np.floating):
        raise InvalidInputError(
            f"path must hold integer cells (ix, iy) or float world points (m), got {arr.dtype}"
        )
    p = arr.astype(float)
    if not np.all(np.isfinite(p)):
        raise InvalidInputError("path points must be finite")
    return p


def _point_name(i: int, n: int) -> str:
    if i == 0:
        return "start"
    if i == n - 1:
        return "goal"
    return f"path point {i}"


def _check_option(value: float, name: str, lo: float, strict: bool) -> float:
    v = float(value)
    ok = math.isfinite(v) and (v > lo if strict else v >= lo)
    if not ok:
        raise InvalidInputError(f"{name} must be finite and {'>' if strict else '>='} {lo}, got {value!r}")
    return v


# ---------------------------------------------------------------- the builder
def build_polygon_corridor(
    raw_grid: Any,
    path: Any,
    radius: float,
    *,
    margin_cells: float = 16.0,
    max_segment_cells: float = 20.0,
    overlap_cells: float = 4.0,
    centre_cells: float = 1.0,
    centre_trigger_cells: float = 2.0,
    simplify_slack_cells: float = 0.3,
    open_cells: float = 2.0,
) -> PolygonCorridor:
    """Grow a chain of certified convex polygons around a path (module docstring).

    Parameters
    ----------
    raw_grid : astar.OccupancyGrid
        The *raw* map (obstacles not inflated); the outside of the map counts as occupied.
    path : astar.GridPath or array_like, shape (n, 2)
        Integer cells ``(ix, iy)`` (a ``GridPath`` or an integer array; their cell centres
        are used), or float world points (m), from start to goal. Every point and every
        segment between consecutive points must keep ``radius`` from the raw map: an A*
        path on ``astar.inflate(raw_grid, radius, metric="square", outside_occupied=True)``
        does.
    radius : float
        Clearance (m) every region keeps from the raw map (finite, ``> 0``: at 0 the
        certificate could not tell touching an obstacle from overlapping it).
    margin_cells : float, optional
        How far (cells) a region may reach beyond its seed's bounding box (> 0). Default 16.
    max_segment_cells : float, optional
        Longest segment (cells) of the simplified path, hence of a region's seed (> 0).
        Default 20.
    overlap_cells : float, optional
        How far (cells) each seed reaches into the neighbouring segments, so that
        consecutive regions share at least twice this much path where obstacles allow
        (>= 0). Default 4.
    centre_cells : float, optional
        Largest push (cells) of an interior path point away from its nearest obstacle
        (>= 0; 0 disables centring). Default 1.
    centre_trigger_cells : float, optional
        Only points closer than ``radius`` plus this (cells) to an obstacle are pushed
        (>= 0). Default 2.
    simplify_slack_cells : float, optional
        Clearance (cells) a simplified segment may lose against the points it replaces,
        never going below ``radius`` (>= 0). Default 0.3.
    open_cells : float, optional
        Clearance beyond ``radius`` plus this (cells) counts as open space when simplifying
        (>= 0). Default 2.

    Returns
    -------
    PolygonCorridor
        Every region certified: exact clearance ``>= radius - CLEARANCE_TOL_M``.

    Raises
    ------
    InvalidInputError
        A path point outside the map; a start, goal or path point, or a path segment,
        closer than ``radius`` to an occupied square or the outside of the map (a radius
        larger than the free space there, or a gap narrower than ``2 radius``); fewer
        than two distinct path points; an option out of range. The message names the
        point, its clearance and the rule.
    SmoothingError
        A region failed its certificate or lost its seed (a bug: the construction
        prevents both; the corridor is never returned then).

    Notes
    -----
    Deterministic. Costs grow with the path length and the number of obstacle
    rectangles within ``margin_cells`` of it; see ``benchmarks/bench_polygon_corridor.py``.
    """
    occ, res, ox, oy = grid_cells(raw_grid)
    r = _check_option(radius, "radius", 0.0, strict=True)
    margin = _check_option(margin_cells, "margin_cells", 0.0, strict=True)
    max_len = _check_option(max_segment_cells, "max_segment_cells", 0.0, strict=True)
    ext = _check_option(overlap_cells, "overlap_cells", 0.0, strict=False)
    push = _check_option(centre_cells, "centre_cells", 0.0, strict=False)
    trigger = _check_option(centre_trigger_cells, "centre_trigger_cells", 0.0, strict=False)
    slack = _check_option(simplify_slack_cells, "simplify_slack_cells", 0.0, strict=False)
    open_c = _check_option(open_cells, "open_cells", 0.0, strict=False)
    ny, nx = occ.shape
    pts_m = _path_points(path, res, ox, oy)
    n_in = len(pts_m)
    r_c = r / res
    tol_c = CLEARANCE_TOL_M / res
    pc_ = (pts_m - np.array([ox, oy])) / res  # cell units
    outside = (pc_[:, 0] < 0) | (pc_[:, 0] > nx) | (pc_[:, 1] < 0) | (pc_[:, 1] > ny)
    if outside.any():
        i = int(np.nonzero(outside)[0][0])
        raise InvalidInputError(
            f"{_point_name(i, n_in)} {pts_m[i].tolist()} m lies outside the map "
            f"[{ox}, {ox + nx * res}] x [{oy}, {oy + ny * res}] m"
        )
    # drop repeated points, remembering where each kept one came from
    keep_in = np.concatenate([[True], np.any(np.diff(pc_, axis=0) != 0.0, axis=1)])
    src = np.nonzero(keep_in)[0]
    p = np.ascontiguousarray(pc_[src])
    if len(p) < 2:
        raise InvalidInputError(
            f"path needs at least two distinct points, got {len(p)} ({n_in} given)"
        )
    reach = margin + r_c + push + ext + 3.0
    idx = _Index(
        occ,
        int(math.floor(p[:, 0].min() - reach)),
        int(math.ceil(p[:, 0].max() + reach)) + 1,
        int(math.floor(p[:, 1].min() - reach)),
        int(math.ceil(p[:, 1].max() + reach)) + 1,
    )
    args = idx.args
    cap = r_c + open_c + 2.0
    pcl, scl = _k.path_clearances(p, cap, *args)
    _check_path_clearance(pts_m, src, pcl, scl, r_c, tol_c, res)
    # centre, then simplify
    if push > 0.0 and len(p) > 2:
        p = _k.centre_path(p, r_c, push, trigger, 2, *args)
        pcl, scl = _k.path_clearances(p, cap, *args)
    keep = _k.simplify_path(p, pcl, scl, r_c, slack, open_c, max_len, *args)
    seed = np.ascontiguousarray(p[keep])
    seed_src = src[keep]
    e = _k.junction_extensions(seed, ext, r_c, tol_c, *args)
    kmax = int(min(4 + len(idx.rects), _MAX_SIDES))
    hh, vv, nvs, status = _k.grow_all(seed, e, r_c, margin, kmax, *args)
    m = len(seed) - 1
    bad = np.nonzero(status >= 2)[0]
    if len(bad):
        k, st = int(bad[0]), int(status[bad[0]])
        why = {
            2: "its seed meets an obstacle's dilation",
            3: "it lost a seed point",
            4: f"it needs more than {kmax} sides",
        }[st]
        raise SmoothingError(
            f"region {k} around path segment {seed_src[k]}..{seed_src[k + 1]} could not be "
            f"grown: {why}",
            {"region": k, "status": st},
        )
    degen = status == 1
    for k in np.nonzero(degen)[0]:  # no interior: the seed segment itself
        vv[k, :2] = seed[k : k + 2]
        nvs[k] = 2
    # the certificate: exact clearance of every region (cell units)
    clear_c = _k.certify_all(vv, nvs, r_c + 1.0, *args)
    bad = np.nonzero(clear_c < r_c - tol_c)[0]
    if len(bad):
        k = int(bad[0])
        raise SmoothingError(
            f"region {k} failed its certificate: clearance {clear_c[k] * res:.9g} m < radius "
            f"{r} m - {CLEARANCE_TOL_M:g} m",
            {"region": k, "clearance_m": float(clear_c[k] * res)},
        )
    clear = clear_c * res
    # to world metres
    o = np.array([ox, oy])
    vm = o + res * vv
    hm = hh.copy()
    hm[:, :, 2] = res * hh[:, :, 2] + hh[:, :, :2] @ o
    nrow = nvs.copy()
    regions: list[ConvexPolygon] = []
    for k in range(m):
        if degen[k]:
            reg = _segment_region(vm[k, 0], vm[k, 1])
            nrow[k] = reg.n_sides
            hm[k, : nrow[k], :2] = reg.A
            hm[k, : nrow[k], 2] = reg.b
        else:
            n = nvs[k]
            reg = ConvexPolygon._construct_fast(hm[k, :n, :2], hm[k, :n, 2], vm[k, :n], False)
        regions.append(reg)
    path_m = o + res * seed
    path_m[0], path_m[-1] = pts_m[src[0]], pts_m[src[-1]]
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(path_m, axis=0).T))])
    region_s, overlap_s, ov_v, ov_h, ov_n = _k.chain_geometry(
        hm, vm, nrow, nvs, degen, path_m, s, _ROUND_M
    )
    bad = np.nonzero(~np.isfinite(region_s[:, 0]))[0]
    if len(bad):
        raise SmoothingError(
            f"region {int(bad[0])} does not contain its path segment", {"region": int(bad[0])}
        )
    bad = np.nonzero(~np.isfinite(overlap_s[:, 0]))[0]
    if len(bad):
        k = int(bad[0])
        raise SmoothingError(
            f"regions {k} and {k + 1} do not both contain their shared path vertex",
            {"region": k},
        )
    region_index = np.column_stack(
        [np.searchsorted(s, region_s[:, 0] - 1e-12, side="left"),
         np.searchsorted(s, region_s[:, 1] + 1e-12, side="right") - 1]
    )
    overlaps: list[ConvexPolygon] = []
    for k in range(m - 1):
        n = int(ov_n[k])
        v = ov_v[k, :n]
        if n >= 3 and not (degen[k] or degen[k + 1]) and _shoelace(v) > 0.0:
            ov = ConvexPolygon._construct_fast(ov_h[k, :n, :2], ov_h[k, :n, 2], v, False)
        elif n == 0:  # only touching at their shared path vertex (within rounding)
            ov = _point_region(path_m[k + 1])
        else:
            ov = _degenerate_from(v)
        overlaps.append(ov)
    lo, hi = overlap_s[:, 0], overlap_s[:, 1]
    trans = 0.5 * (
        np.maximum(lo, 0.5 * (s[:-2] + s[1:-1])) + np.minimum(hi, 0.5 * (s[1:-1] + s[2:]))
    )
    trans_pts = np.column_stack(
        [np.interp(trans, s, path_m[:, 0]), np.interp(trans, s, path_m[:, 1])]
    ).reshape(-1, 2)
    logger.debug(
        "polygon corridor: %d regions for %d path points (%d obstacle rectangles)",
        m, n_in, len(idx.rects),
    )
    return PolygonCorridor(
        regions=tuple(regions),
        path=path_m,
        path_s=s,
        source_index=seed_src,
        input_path=pts_m,
        region_s=region_s,
        region_index=region_index,
        transitions_m=trans,
        transition_points=trans_pts,
        overlap_s=overlap_s,
        overlaps=tuple(overlaps),
        clearance_m=clear,
        radius=r,
        resolution=res,
        origin=(ox, oy),
    )


def _check_path_clearance(
    pts_m: np.ndarray,
    src: np.ndarray,
    pcl: np.ndarray,
    scl: np.ndarray,
    r_c: float,
    tol_c: float,
    res: float,
) -> None:
    """Raise for the first point, then segment, closer than ``r`` to the raw map (``src``
    maps the de-duplicated points, whose clearances ``pcl``/``scl`` are in cells, to the
    input points ``pts_m``)."""
    n_in = len(pts_m)
    bad = np.nonzero(pcl < r_c - tol_c)[0]
    if len(bad):
        # the end points first: a radius larger than the free space there
        last = len(pcl) - 1
        i = sorted(bad.tolist(), key=lambda j: (j not in (0, last), j))[0]
        j = int(src[i])
        raise InvalidInputError(
            f"{_point_name(j, n_in)} {pts_m[j].tolist()} m has clearance {pcl[i] * res:.6g} m, "
            f"less than the radius {r_c * res:.6g} m: every path point must keep the radius "
            "from every occupied cell (a square) and from the outside of the map"
        )
    bad = np.nonzero(scl < r_c - tol_c)[0]
    if len(bad):
        i = int(bad[0])
        a, b = int(src[i]), int(src[i + 1])
        raise InvalidInputError(
            f"path segment from point {a} {pts_m[a].tolist()} m to point {b} "
            f"{pts_m[b].tolist()} m has clearance {scl[i] * res:.6g} m, less than the radius "
            f"{r_c * res:.6g} m: it passes a gap narrower than 2 * radius = "
            f"{2 * r_c * res:.6g} m; search the path on "
            "astar.inflate(raw_grid, radius, metric='square', outside_occupied=True)"
        )
