"""The polygon corridor's values: :class:`ConvexPolygon` and :class:`PolygonCorridor`."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from trajopt.corridor._polygons.region_kernels import clip_convex
from trajopt.errors import InvalidInputError
from trajopt.validation import readonly

#: Absolute tolerance (m) of every clearance check of this module: a region is certified
#: when its exact clearance is at least ``radius - CLEARANCE_TOL_M``. Obstacle rows are
#: tangent to the dilated squares, so a region touches ``radius`` exactly there; the
#: tolerance only absorbs floating-point rounding (about 1e-13 m on maps of a few
#: thousand cells).
CLEARANCE_TOL_M = 1e-9

#: Slack (m) of the path-in-region tests: absorbs the rounding of points that lie on a
#: region's boundary (a seed touching a dilated obstacle, a segment along a row).
ROUND_M = 1e-2 * CLEARANCE_TOL_M


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
            if shoelace(v) <= 0.0:
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
        return shoelace(self.vertices)

    @property
    def line(self) -> tuple[np.ndarray, float] | None:
        """For a degenerate segment, its line as ``(a, c)``.

        The region lies on ``a @ p == c`` (``a`` = ``A[0]``, shape (2,)); ``None`` otherwise.
        """
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
        """Return the intersection of two regions (a region; degenerate when it has no interior).

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


def shoelace(v: np.ndarray) -> float:
    """Return the signed area of the polygon ``v`` (counter-clockwise positive)."""
    x, y = v[:, 0], v[:, 1]
    return 0.5 * float(x[:-1] @ y[1:] - x[1:] @ y[:-1] + x[-1] * y[0] - x[0] * y[-1])


def point_region(p: np.ndarray) -> ConvexPolygon:
    """Return the degenerate region holding only the point ``p``."""
    a = np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]])
    b = np.array([p[0], -p[0], p[1], -p[1]])
    return ConvexPolygon._construct_fast(a, b, np.array([p], dtype=float), True)


def segment_region(p: np.ndarray, q: np.ndarray) -> ConvexPolygon:
    """Degenerate region: rows 0 and 1 the line through ``p`` and ``q``, 2 and 3 the caps."""
    d = q - p
    ln = math.hypot(d[0], d[1])
    if ln == 0.0:
        return point_region(p)
    u = d / ln
    n = np.array([-u[1], u[0]])
    a = np.array([n, -n, u, -u])
    b = np.array([n @ p, -(n @ p), u @ q, -(u @ p)])
    return ConvexPolygon._construct_fast(a, b, np.array([p, q], dtype=float), True)


def degenerate_from(v: np.ndarray) -> ConvexPolygon:
    """Return a point or segment region spanning vertices ``v``.

    A point or segment region spanning vertices ``v`` (shape (n, 2), n >= 1) that lie on one
    line (or at one point).
    """
    if len(v) == 1:
        return point_region(v[0])
    d = np.hypot(*(v[:, None, :] - v[None, :, :]).transpose(2, 0, 1))
    i, j = np.unravel_index(int(np.argmax(d)), d.shape)
    if d[i, j] == 0.0:
        return point_region(v[0])
    return segment_region(v[min(i, j)], v[max(i, j)])


def _intersect(p1: ConvexPolygon, p2: ConvexPolygon, tol: float) -> ConvexPolygon | None:
    rows = np.column_stack([p2.A, p2.b])
    v, lab, n = clip_convex(
        np.ascontiguousarray(p1.vertices), p1.vertices.shape[0], rows, rows.shape[0], tol
    )
    if n == 0:
        return None
    if n >= 3 and not p1.degenerate and shoelace(v) > 1e-18:
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
    return degenerate_from(v)


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
    unit_m : float or None
        The length unit the corridor was built in and the smoother counts in (m;
        :func:`~trajopt.geometry.length_unit`); ``None``: the cell side.
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
    unit_m: float | None = None
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
            raise InvalidInputError(
                f"need {m - 1} overlaps for {m} regions, got {len(self.overlaps)}"
            )
        for name in ("path", "input_path", "transition_points"):
            object.__setattr__(self, name, readonly(getattr(self, name), float).reshape(-1, 2))
        for name in ("path_s", "transitions_m", "clearance_m"):
            object.__setattr__(self, name, readonly(getattr(self, name), float).reshape(-1))
        object.__setattr__(self, "region_s", readonly(self.region_s, float).reshape(-1, 2))
        object.__setattr__(self, "overlap_s", readonly(self.overlap_s, float).reshape(-1, 2))
        object.__setattr__(self, "source_index", readonly(self.source_index, np.int64).reshape(-1))
        object.__setattr__(
            self, "region_index", readonly(self.region_index, np.int64).reshape(-1, 2)
        )
        object.__setattr__(self, "radius", float(self.radius))
        object.__setattr__(self, "resolution", float(self.resolution))
        object.__setattr__(self, "origin", (float(self.origin[0]), float(self.origin[1])))
        unit = self.resolution if self.unit_m is None else float(self.unit_m)
        if not (math.isfinite(unit) and unit >= self.resolution * (1 - 1e-12)):
            raise InvalidInputError(
                f"unit_m must be finite and >= the resolution {self.resolution!r} m, "
                f"got {self.unit_m!r}"
            )
        object.__setattr__(self, "unit_m", unit)
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
        """Whether each world point.

        Whether each world point (shape ``(..., 2)``, m) lies in at least one region (``tol`` m
        of slack on every row).
        """
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
