"""Oriented robot footprints: a convex polygon in the robot frame and what it sweeps.

A :class:`Footprint` is a convex polygon in the robot frame (x forward, y left, metres),
the rotation centre at the origin, which must lie strictly inside it. Its
:attr:`~Footprint.inscribed_radius` (the largest disc about the origin inside it) and
:attr:`~Footprint.circumscribed_radius` (the smallest disc about the origin containing it)
bracket the disc models of the robot.

The certificate of a footprint robot needs the set the footprint covers while its heading
stays in an interval ``[theta_lo, theta_hi]``: :meth:`Footprint.swept_hull` returns a
convex polygon containing it, exactly, by bounding each vertex's arc by its outer tangent
polygon (arc endpoints and the tangent intersections of pieces of at most 45 degrees):
every rotated footprint is the convex hull of its rotated vertices, which lie on those arcs.
:func:`span_heading_intervals` bounds the tangent direction of every span of a B-spline by
its hodograph (the derivative's control points span a cone that holds the tangent).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

import trajopt.robot._footprint_kernels as footprint_kernels
from trajopt.errors import InvalidInputError
from trajopt.geometry import convex_hull, derivative_control_points
from trajopt.validation import positive, short_repr

MAX_ARC_RAD = math.pi / 4  # arc pieces of at most 45 degrees: apex at 1 / cos(22.5 deg) = 1.082 r


@dataclass(frozen=True)
class Footprint:
    """A convex robot footprint (robot frame, metres).

    Parameters
    ----------
    vertices : array_like, shape (k, 2)
        Corners in order around the polygon (either direction; stored counter-clockwise),
        ``k >= 3``; the rotation centre (origin) strictly inside.

    Raises
    ------
    InvalidInputError
        Fewer than 3 vertices, non-finite values, repeated or collinear corners, a
        non-convex or self-intersecting polygon, the origin not strictly inside.
    """

    vertices: np.ndarray

    def __post_init__(self) -> None:
        try:
            v = np.array(self.vertices, dtype=float)
        except (TypeError, ValueError):
            raise InvalidInputError(
                f"footprint vertices must be an array of shape (k, 2) in metres, got "
                f"{short_repr(self.vertices)}"
            ) from None
        if v.ndim != 2 or v.shape[1] != 2 or v.shape[0] < 3:
            raise InvalidInputError(
                f"footprint must have at least 3 vertices, shape (k, 2), got {v.shape}"
            )
        if not np.all(np.isfinite(v)):
            raise InvalidInputError("footprint vertices must be finite (found NaN or inf)")
        area = _signed_area(v)
        if area < 0:
            v = v[::-1].copy()
        e = np.roll(v, -1, axis=0) - v
        cross = e[:, 0] * np.roll(e, -1, axis=0)[:, 1] - e[:, 1] * np.roll(e, -1, axis=0)[:, 0]
        scale = max(float(np.max(np.abs(v))), 1e-12)
        if np.any(np.hypot(e[:, 0], e[:, 1]) <= 1e-12 * scale):
            raise InvalidInputError("footprint has repeated vertices")
        if np.any(cross <= 1e-12 * scale * scale):
            raise InvalidInputError(
                "footprint must be a convex polygon without collinear corners (every turn "
                "the same way); got a non-convex or self-intersecting one"
            )
        turning = np.sum(np.arctan2(cross, np.einsum("ij,ij->i", e, np.roll(e, -1, axis=0))))
        if abs(turning - 2 * math.pi) > 1e-6:
            raise InvalidInputError(
                "footprint must be a simple convex polygon; its edges wind "
                f"{turning / (2 * math.pi):.3g} times around (self-intersecting)"
            )
        d = _edge_distances(v)
        if np.any(d <= 0.0):
            raise InvalidInputError(
                "footprint must contain the rotation centre (0, 0) strictly inside; "
                f"it is {'on' if np.min(d) == 0 else 'outside'} edge {int(np.argmin(d))}"
            )
        v.flags.writeable = False
        object.__setattr__(self, "vertices", v)

    # ------------------------------------------------------------- constructors
    @classmethod
    def rectangle(cls, length: float, width: float, rear_offset: float | None = None) -> Footprint:
        """Return a ``length`` x ``width`` rectangle (m), x forward.

        ``rear_offset`` is the distance (m) from the rotation centre back to the rear edge,
        so the body spans x in ``[-rear_offset, length - rear_offset]`` and y in
        ``[-width / 2, width / 2]``; default ``length / 2`` (centred).
        """
        ln = positive("length", length, "m")
        wd = positive("width", width, "m")
        rear = 0.5 * ln if rear_offset is None else float(rear_offset)
        if not (math.isfinite(rear) and 0.0 < rear < ln):
            raise InvalidInputError(
                f"rear_offset must be in (0, length) = (0, {ln:g}) m so that the rotation "
                f"centre is inside the body, got {rear_offset!r}"
            )
        x0, x1, y = -rear, ln - rear, 0.5 * wd
        return cls(np.array([[x0, -y], [x1, -y], [x1, y], [x0, y]]))

    # --------------------------------------------------------------- geometry
    @property
    def inscribed_radius(self) -> float:
        """Largest disc about the rotation centre inside the footprint (m)."""
        return float(np.min(_edge_distances(self.vertices)))

    @property
    def circumscribed_radius(self) -> float:
        """Smallest disc about the rotation centre containing the footprint (m)."""
        return float(np.max(np.hypot(self.vertices[:, 0], self.vertices[:, 1])))

    @property
    def polar(self) -> tuple[np.ndarray, np.ndarray]:
        """The vertices in polar form: distances (m) and angles (rad), shape (k,) each."""
        v = self.vertices
        return np.hypot(v[:, 0], v[:, 1]), np.arctan2(v[:, 1], v[:, 0])

    def at(self, x: float, y: float, theta: float) -> np.ndarray:
        """Return the corners in the world at pose ``(x, y, theta)``, shape (k, 2) (m)."""
        c, s = math.cos(theta), math.sin(theta)
        v = self.vertices
        return np.column_stack([x + c * v[:, 0] - s * v[:, 1], y + s * v[:, 0] + c * v[:, 1]])

    def swept_hull(self, theta_lo: float, theta_hi: float) -> np.ndarray:
        """Return a convex polygon containing the footprint swept over a heading interval.

        Every rotation of the footprint about the origin by an angle in ``[theta_lo,
        theta_hi]`` (rad) lies inside the returned polygon, shape (m, 2), counter-clockwise.
        A span of ``2 pi`` or more gives a polygon around the circumscribed disc.
        """
        lo, hi = float(theta_lo), float(theta_hi)
        if not (math.isfinite(lo) and math.isfinite(hi)) or hi < lo:
            raise InvalidInputError(
                f"need finite theta_lo <= theta_hi (rad), got {theta_lo!r}, {theta_hi!r}"
            )
        rho, phi = self.polar
        return footprint_kernels.swept_hull(rho, phi, lo, hi, MAX_ARC_RAD)

    def to_list(self) -> list[list[float]]:
        """Return the vertices as a list of ``[x, y]`` (m)."""
        return self.vertices.tolist()


def span_heading_intervals(knots: np.ndarray, control_points: np.ndarray, degree: int):
    """Bound the tangent direction of every span of a clamped B-spline.

    The derivative is a B-spline of degree ``p - 1`` with control points
    ``Q_i = p (c_{i+1} - c_i) / (t_{i+p+1} - t_{i+1})``; on span ``j`` it is a convex
    combination of ``Q_j .. Q_{j+p-1}``, so the tangent direction lies in the cone those
    span. When the cone's directions all lie within a half-plane the interval is tight
    around them; otherwise the span gets the whole circle (``hi - lo = 2 pi``).

    Parameters
    ----------
    knots : ndarray, shape (n + p + 1,)
    control_points : ndarray, shape (n, 2)
    degree : int

    Returns
    -------
    ndarray, shape (n - p, 2)
        ``(theta_lo, theta_hi)`` per span (rad), ``theta_lo <= theta_hi``.
    """
    t = np.asarray(knots, dtype=float)
    c = np.asarray(control_points, dtype=float)
    p = int(degree)
    n = len(c)
    q = derivative_control_points(t, c, p)[1]
    out = np.empty((n - p, 2))
    for j in range(n - p):
        out[j] = footprint_kernels.cone(np.ascontiguousarray(q[j : j + p]))
    return out


def minkowski_sum(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Return the convex hull of ``{x + y : x in a, y in b}`` for point sets ``a`` and ``b``."""
    a = np.asarray(a, dtype=float).reshape(-1, 2)
    b = np.asarray(b, dtype=float).reshape(-1, 2)
    return convex_hull((a[:, None, :] + b[None, :, :]).reshape(-1, 2))


def _signed_area(v: np.ndarray) -> float:
    x, y = v[:, 0], v[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def _edge_distances(v: np.ndarray) -> np.ndarray:
    """Signed distance from the origin to each edge's line (positive inside, CCW ``v``)."""
    e = np.roll(v, -1, axis=0) - v
    length = np.hypot(e[:, 0], e[:, 1])
    # inward normal of a CCW edge is (-ey, ex); distance of the origin = n . (0 - v)
    return (-e[:, 1] * (-v[:, 0]) + e[:, 0] * (-v[:, 1])) / length


@dataclass(frozen=True)
class FootprintCertificate:
    """Evidence that a footprint swept along a B-spline keeps clear of a raw map.

    Attributes
    ----------
    ok : bool
        Every span's bound is clear of every occupied square and of the outside of the map.
    margins_m : ndarray, shape (n_spans,)
        Exact clearance (m) of each span's bounding polygon (0 when it touches or overlaps).
    heading_intervals : ndarray, shape (n_spans, 2)
        The heading interval (rad) each span's bound was built for.
    worst_span : int
        The span with the smallest margin.
    """

    ok: bool
    margins_m: np.ndarray
    heading_intervals: np.ndarray
    worst_span: int

    @property
    def min_margin_m(self) -> float:
        """Smallest span margin (m)."""
        return float(self.margins_m.min()) if self.margins_m.size else math.inf


def certify_footprint(
    curve: Any, footprint: Footprint, raw_grid: Any, *, tol_m: float = 1e-9, max_depth: int = 4
) -> FootprintCertificate:
    """Check that ``footprint``, oriented along ``curve``, never meets an obstacle.

    Each polynomial piece (span) of the curve is written in Bezier form; a Bezier piece lies
    in the convex hull of its control points, and its tangent direction in the cone of its
    hodograph's control points (the differences of consecutive control points), so the
    footprint over the piece lies in the Minkowski sum of that hull and
    :meth:`Footprint.swept_hull` of the cone's heading interval. The piece passes when that
    polygon's exact distance to the raw map's occupied squares and to the outside of the
    map (the polygon corridor's obstacle index: exact convex-polygon-to-rectangle
    distances) exceeds ``tol_m``; a piece that does not is split in two (de Casteljau), up
    to ``max_depth`` times, which tightens both bounds. The check is independent of the
    optimiser that produced the curve; margins are reported up to the circumscribed radius
    plus two cells. A map that knows the polygons its cells were rasterised from
    (:attr:`astar.OccupancyGrid.polygons`: its occupied squares a conservative cover of
    them) is checked against the polygons themselves instead of the squares (exact
    distances of the convex bound to each polygon, convex or not, and to the map's
    outside), the same bound, a tighter obstacle set.

    Parameters
    ----------
    curve : BSplineCurve or SmoothPath
        Anything with ``domain``, ``breakpoints()``, ``k`` (or ``degree``) and derivatives
        ``curve(u, nu)`` (a :class:`~trajopt.smoother.SmoothPath` is unwrapped), in world
        metres.
    footprint : Footprint
    raw_grid : astar.OccupancyGrid
    tol_m : float, optional
        Smallest clearance counted as clear (m).
    max_depth : int, optional
        Most halvings of a span.

    Returns
    -------
    FootprintCertificate
        Per span: the smallest margin over its final pieces, and the heading interval of
        its whole hodograph.
    """
    from trajopt.geometry import ObstacleIndex, grid_cells

    spline = getattr(curve, "curve", curve)
    pieces = _bezier_spans(spline)
    occ, res, ox, oy = grid_cells(raw_grid)
    origin = np.array([ox, oy])
    cap = footprint.circumscribed_radius / res + 2.0  # beyond it the exact value is moot
    rho, phi = footprint.polar
    bez = (pieces - origin) / res
    polygons = getattr(raw_grid, "polygons", None)
    if polygons is not None:  # the obstacles themselves, exactly (docstring)
        from astar.body_polygons import pack_polygons

        packed = pack_polygons(polygons, (ox, oy), res)
        box = np.array([0.0, 0.0, raw_grid.width / res, raw_grid.height / res])
        m_cells, heads = footprint_kernels.span_margins_polygons(
            np.ascontiguousarray(bez),
            rho / res,
            phi,
            MAX_ARC_RAD,
            cap,
            tol_m / res,
            int(max_depth),
            *packed,
            box,
        )
        return _certificate(m_cells * res, heads, tol_m)
    allp = pieces.reshape(-1, 2) if len(pieces) else np.zeros((1, 2))
    reach = int(math.ceil(cap + footprint.circumscribed_radius / res)) + 2
    q = (allp - origin) / res
    idx = ObstacleIndex(
        occ,
        int(math.floor(q[:, 0].min())) - reach,
        int(math.ceil(q[:, 0].max())) + reach,
        int(math.floor(q[:, 1].min())) - reach,
        int(math.ceil(q[:, 1].max())) + reach,
    )

    m_cells, heads = footprint_kernels.span_margins(
        np.ascontiguousarray(bez),
        rho / res,
        phi,
        MAX_ARC_RAD,
        cap,
        tol_m / res,
        int(max_depth),
        *idx.args,
    )
    return _certificate(m_cells * res, heads, tol_m)


def _certificate(margins: np.ndarray, heads: np.ndarray, tol_m: float) -> FootprintCertificate:
    """Return the certificate of per-span ``margins`` (m) and heading intervals (rad)."""
    worst_span = int(np.argmin(margins)) if margins.size else 0
    return FootprintCertificate(
        ok=bool(np.all(margins > tol_m)),
        margins_m=margins,
        heading_intervals=heads,
        worst_span=worst_span,
    )


def polygons_clearance(polygons: list[np.ndarray], raw_grid: Any, cap_m: float) -> np.ndarray:
    """Return the exact clearance (m, capped at ``cap_m``) of convex polygons from a map.

    One obstacle index (the polygon corridor's: occupied cells merged into rectangles,
    bucketed) serves all the polygons; the outside of the map counts as occupied.

    Parameters
    ----------
    polygons : list of ndarray, shape (k, 2) each
        Convex polygons in world metres.
    raw_grid : astar.OccupancyGrid
    cap_m : float
        Distances beyond this are reported as ``cap_m`` (m).

    Returns
    -------
    ndarray, shape (len(polygons),)
    """
    from trajopt.geometry import ObstacleIndex, grid_cells, poly_clearance

    out = np.empty(len(polygons))
    if not polygons:
        return out
    occ, res, ox, oy = grid_cells(raw_grid)
    origin = np.array([ox, oy])
    cells = [(np.asarray(p, dtype=float) - origin) / res for p in polygons]
    allp = np.vstack(cells)
    cap = float(cap_m) / res
    reach = int(math.ceil(cap)) + 2
    idx = ObstacleIndex(
        occ,
        int(math.floor(allp[:, 0].min())) - reach,
        int(math.ceil(allp[:, 0].max())) + reach,
        int(math.floor(allp[:, 1].min())) - reach,
        int(math.ceil(allp[:, 1].max())) + reach,
    )
    for j, poly in enumerate(cells):
        v = np.ascontiguousarray(poly)
        out[j] = poly_clearance(v, len(v), cap, *idx.args) * res
    return out


def _bezier_spans(spline: Any) -> np.ndarray:
    """Return the Bezier control points of each polynomial piece, shape (m, p + 1, 2).

    From the derivatives at the pieces' starts: the power-basis coefficients
    ``f^(j)(a) (b - a)^j / j!`` give ``b_i = sum_{j <= i} C(i, j) / C(p, j) coef_j``.
    """
    p = int(getattr(spline, "k", getattr(spline, "degree", 3)))
    lo, hi = (float(x) for x in spline.domain)
    bp = np.asarray(spline.breakpoints(), dtype=float)
    w = np.union1d([lo, hi], bp[(bp > lo) & (bp < hi)])
    a, h = w[:-1], np.diff(w)
    a, h = a[h > 0], h[h > 0]
    coef = np.stack(
        [
            np.asarray(spline(a, j), dtype=float).reshape(len(a), 2)
            * (h**j / math.factorial(j))[:, None]
            for j in range(p + 1)
        ],
        axis=1,
    )
    mix = np.array(
        [
            [math.comb(i, j) / math.comb(p, j) if j <= i else 0.0 for j in range(p + 1)]
            for i in range(p + 1)
        ]
    )
    return np.einsum("ij,mjd->mid", mix, coef)
