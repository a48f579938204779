"""The smoother's problem in cell units.

Targets, knots, the objective's band, the control-point bounds and region rows, and one
attempt's QP.

Positions and parameters are divided by the grid resolution, so one set of weights and
tolerances serves every map.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from trajopt.corridor import CLEARANCE_TOL_M, Corridor, PolygonCorridor
from trajopt.errors import InvalidInputError
from trajopt.smoother._basis import (
    band_gram,
    band_rhs,
    basis_derivs,
    bucket_size,
    find_spans,
    smoothness_band,
)
from trajopt.validation import point

if TYPE_CHECKING:
    from trajopt.smoother._options import Smoother


#: Heading rows at the top of every constraint matrix (:func:`heading_rows`: the start and goal
#: tangents, two rows each, and the start curvature).
N_HEADING_ROWS = 5


class EmptyBoundsError(Exception):
    """The regions of some control point's spans do not intersect (the attempt fails)."""


def _end_point(name: str, value: Any, default: np.ndarray) -> np.ndarray:
    if value is None:
        return np.array(default, dtype=float)
    return point(name, value)


@dataclass(slots=True)
class Problem:
    """One fit in cell units.

    Targets at parameters ``u``, per-region bounds (``lo``, ``hi``: the box, or a polygon's
    bounding box; ``dlo``, ``dhi``: the bounds of ``x + y`` and ``x - y``) and, for polygon
    corridors, each region's half-planes ``rows`` (``(A, b)`` with ``A @ c <= b``, cells).
    """

    targets: np.ndarray
    u: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    dlo: np.ndarray
    dhi: np.ndarray
    trans: np.ndarray
    overlap: np.ndarray
    start: np.ndarray
    goal: np.ndarray
    start_dir: np.ndarray | None
    goal_dir: np.ndarray | None
    res: float = 1.0
    rows: list[tuple[np.ndarray, np.ndarray]] | None = None
    taut: bool = False
    start_kappa: float | None = None  # curvature at the start (1/cell), with start_dir


@dataclass(slots=True)
class QPData:
    """The convex problem of one attempt (cell units, padded to ``nb``)."""

    full: np.ndarray  # Hessian upper band, shape (p + 1, nb)
    g: np.ndarray  # linear term, shape (2 nb,)
    n: int
    nb: int
    lbx: np.ndarray
    ubx: np.ndarray
    heading: np.ndarray  # heading rows, shape (N_HEADING_ROWS = 5, 2 nb)
    lba: np.ndarray  # bounds of the heading and region rows, shape (5 + k nb,)
    uba: np.ndarray
    k: int = 2  # region rows per control point
    region_coef: np.ndarray | None = None  # their (a_x, a_y), shape (nb, k, 2); None: x +- y


@dataclass(slots=True)
class Assembly:
    """One attempt's problem on its knots: the QP and what the attempt needs around it.

    Attributes
    ----------
    qp : QPData
    knots : ndarray, shape (n + p + 1,)
        Clamped knots (cells).
    span_box : ndarray of int, shape (n - p,)
        Corridor region of every span.
    lo, hi : ndarray, shape (n, 2)
        Control-point bounds (cells).
    point_rows : tuple or None
        Polygon corridors: ``(coef (nb, k, 2), lb (nb, k), ub (nb, k))`` of every point's
        region rows; ``None`` for boxes.
    x0 : ndarray, shape (2 nb,)
        Starting point: the targets projected to the bounds, by parameter.
    const : float
        Constant term of the objective (its value at ``z = 0``).
    start_alpha : float or None
        With a start curvature, the fixed ``|c_1 - c_0|`` (cells).
    """

    qp: QPData
    knots: np.ndarray
    span_box: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    point_rows: tuple | None
    x0: np.ndarray
    const: float
    start_alpha: float | None = None


def _sd(xy: np.ndarray) -> np.ndarray:
    """``(x + y, x - y)`` of a point."""
    return np.array([xy[0] + xy[1], xy[0] - xy[1]])


#: the 45-degree rows are imposed this far (cells) inside their bounds, so that solver
#: tolerances never put a control point outside its region
_DIAG_MARGIN = 1e-6


def diag_row_bounds(dlo: np.ndarray, dhi: np.ndarray, nb: int):
    """Bounds of the rows ``x_i + y_i``, ``x_i - y_i`` (interleaved), padded to ``nb``."""
    n = len(dlo)
    lb = np.full((nb, 2), -np.inf)
    ub = np.full((nb, 2), np.inf)
    lo = dlo + _DIAG_MARGIN
    hi = dhi - _DIAG_MARGIN
    thin = lo > hi  # only for finite bounds: -inf + m > inf - m never holds
    mid = 0.5 * (dlo[thin] + dhi[thin])
    lo[thin] = mid
    hi[thin] = mid
    lb[:n], ub[:n] = lo, hi
    return lb.ravel(), ub.ravel()


#: polygon rows are imposed this far (cells) inside their half-planes, so that solver
#: tolerances never put a control point outside its region
_POLY_MARGIN = 1e-6
#: a polygon's bounding box (a redundant bound on its control points; its rows are exact)
#: is widened by this much (cells): its vertices are computed, and a box that ends a
#: rounding error short of a degenerate neighbour's line would leave the two no common point
_BOX_PAD = 1e-9
#: region rows per control point are padded to one of these counts (cached solvers)
_K_SIZES = (4, 8, 12, 16, 24, 32, 48, 64)


def polygon_targets(corridor: PolygonCorridor, unit_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Return the corridor's path sampled once per ``unit_m``: points (m), arc lengths (m)."""
    res = unit_m
    s_v = np.asarray(corridor.path_s, dtype=float)
    pts = np.asarray(corridor.path, dtype=float)
    s = np.unique(np.concatenate([np.arange(0.0, s_v[-1], res), s_v]))
    xy = np.column_stack([np.interp(s, s_v, pts[:, 0]), np.interp(s, s_v, pts[:, 1])])
    return xy, s


def region_rows(corridor: PolygonCorridor, origin: np.ndarray, res: float):
    """Each region's rows ``lo <= A c <= hi`` in cells.

    Each region's rows ``lo <= A c <= hi`` in cells (``A`` (q, 2), ``lo``, ``hi`` (q,)),
    ``_POLY_MARGIN`` inside, and the regions' bounding boxes (cells, (m, 2) each; a
    polygon's widened by ``_BOX_PAD``).

    A degenerate region's line (its first two, opposite rows) becomes one two-sided row.
    """
    out = []
    lo_b = np.empty((len(corridor.regions), 2))
    hi_b = np.empty((len(corridor.regions), 2))
    for k, reg in enumerate(corridor.regions):
        A = np.asarray(reg.A, dtype=float)
        b = (np.asarray(reg.b, dtype=float) - A @ origin) / res
        v = (np.asarray(reg.vertices, dtype=float) - origin) / res
        pad = 0.0 if reg.degenerate else _BOX_PAD
        lo_b[k], hi_b[k] = v.min(axis=0) - pad, v.max(axis=0) + pad
        if reg.degenerate:
            mid = 0.5 * (b[0] - b[1])
            rows_a = np.vstack([A[:1], A[2:]])
            rlo = np.concatenate([[mid], np.full(len(A) - 2, -np.inf)])
            rhi = np.concatenate([[mid], b[2:] - _POLY_MARGIN])
        else:
            rows_a = A
            rlo = np.full(len(A), -np.inf)
            rhi = b - _POLY_MARGIN
        out.append((rows_a, rlo, rhi))
    return out, lo_b, hi_b


def point_rows(rows, span_box, n: int, p: int, lo: np.ndarray, hi: np.ndarray, nb: int):
    """Return the region rows of every control point, padded to ``k`` per point.

    A point gets the rows of the regions of the spans it touches, less those that its
    variable bounds ``lo``, ``hi`` (cells, shape (n, 2)) already imply (the row's largest
    value over that box is within its bound); the fixed end points get none (they were
    checked against their regions). Span regions never decrease along the curve and a point
    touches at most two of them (the knots give every region at least ``p`` spans), so the
    regions of point ``i`` are those of its first and last span. A point held on a
    degenerate region's line (its two-sided row) gets its one-sided rows without the
    ``_POLY_MARGIN`` shrink: a neighbouring polygon's edge often lies on that very line,
    and shrunk it would leave the two regions no common point.

    Returns ``(k, coef (nb, k, 2), lb (nb k,), ub (nb k,))`` in the layout's order; unused
    rows have zero coefficients and infinite bounds.
    """
    m = len(rows)
    q = max(len(r[1]) for r in rows)
    A = np.zeros((m + 1, q, 2))  # region m: no rows (the fixed end points)
    rlo = np.full((m + 1, q), -np.inf)
    rhi = np.full((m + 1, q), np.inf)
    for r, (a, lo_r, hi_r) in enumerate(rows):
        A[r, : len(lo_r)] = a
        rlo[r, : len(lo_r)] = lo_r
        rhi[r, : len(lo_r)] = hi_r
    ns = len(span_box)
    i = np.arange(n)
    r0 = np.asarray(span_box)[np.clip(i - p, 0, ns - 1)]
    r1 = np.asarray(span_box)[np.clip(i, 0, ns - 1)]
    r1 = np.where(r1 == r0, m, r1)
    r0[[0, -1]] = m
    r1[[0, -1]] = m
    ca = np.concatenate([A[r0], A[r1]], axis=1)  # (n, 2q, 2)
    clo = np.concatenate([rlo[r0], rlo[r1]], axis=1)
    chi = np.concatenate([rhi[r0], rhi[r1]], axis=1)
    # a point on a degenerate region's line: its other region's edge along that line
    # (tangent to the same obstacles) must not be moved inside, or the two never meet
    degenerate = np.isfinite(rlo).any(axis=1)
    on_line = (degenerate[r0] | degenerate[r1])[:, None] & np.isinf(clo) & np.isfinite(chi)
    chi = np.where(on_line, chi + _POLY_MARGIN, chi)
    top = np.maximum(ca[..., 0] * lo[:, :1], ca[..., 0] * hi[:, :1]) + np.maximum(
        ca[..., 1] * lo[:, 1:], ca[..., 1] * hi[:, 1:]
    )
    keep = ((top > chi) | np.isfinite(clo)) & (np.isfinite(chi) | np.isfinite(clo))
    most = int(keep.sum(axis=1).max(initial=0))
    k = next((s for s in _K_SIZES if s >= most), int(8 * math.ceil(most / 8)))
    w = min(k, 2 * q)
    order = np.argsort(~keep, axis=1, kind="stable")[:, :w]  # kept rows first
    kept = np.take_along_axis(keep, order, axis=1)
    coef = np.zeros((nb, k, 2))
    lb = np.full((nb, k), -np.inf)
    ub = np.full((nb, k), np.inf)
    coef[:n, :w] = np.where(kept[..., None], np.take_along_axis(ca, order[..., None], axis=1), 0.0)
    lb[:n, :w] = np.where(kept, np.take_along_axis(clo, order, axis=1), -np.inf)
    ub[:n, :w] = np.where(kept, np.take_along_axis(chi, order, axis=1), np.inf)
    return k, coef, lb.ravel(), ub.ravel()


def box_targets(src: Any, corridor: Corridor) -> np.ndarray:
    """Return the fidelity targets (m) of a box corridor: ``src`` cells' centres or points."""
    if src is None:
        return np.array(corridor.path_points)
    cells = getattr(src, "cells", None)
    if cells is None and np.issubdtype(np.asarray(src).dtype, np.integer):
        cells = src  # an integer array is a list of cells (ix, iy)
    if cells is not None:
        c = np.asarray(cells, dtype=float)
        pts = np.asarray(corridor.origin) + (c + 0.5) * corridor.resolution
    else:
        pts = np.asarray(src, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 2 or not np.all(np.isfinite(pts)):
        raise InvalidInputError(
            f"grid_path_or_points must be finite with shape (n, 2), got {pts.shape}"
        )
    if len(pts) != len(corridor.path_points):
        raise InvalidInputError(
            f"grid_path_or_points has {len(pts)} points but the corridor was built on a path "
            f"of {len(corridor.path_points)} cells; they must match"
        )
    return pts


def graded_knots(
    length: float, trans: np.ndarray, overlap: np.ndarray, p: int, h: float
) -> tuple[np.ndarray, np.ndarray]:
    """Clamped knots on ``[0, length]`` (cells) graded towards the box transitions.

    Every transition is a knot; inside box ``k`` the span length at ``x`` is
    ``min(h, d + 0.5 * distance to the nearest transition)`` with
    ``d = clip(overlap / (p - 1), 0.5, h)`` of that transition, and each box gets at least
    ``p`` spans. Returns the knots (shape ``(n + p + 1,)``) and the box of every span.
    """
    edges = np.concatenate([[0.0], trans, [length]])
    d_tr = np.clip(overlap / max(p - 1, 1), 0.5, h)
    bps: list[np.ndarray] = []
    boxes: list[np.ndarray] = []
    for k in range(len(edges) - 1):
        a, b = edges[k], edges[k + 1]
        dl = d_tr[k - 1] if k > 0 else None
        dr = d_tr[k] if k < len(trans) else None

        def step(x: float, a=a, b=b, dl=dl, dr=dr) -> float:
            s = h
            if dl is not None:
                s = min(s, dl + 0.5 * (x - a))
            if dr is not None:
                s = min(s, dr + 0.5 * (b - x))
            return max(s, 1e-3)

        pos = [a]
        x = a
        while True:
            s = step(x)
            rest = b - x
            if rest <= s * 1.25:
                break
            if rest <= 2 * s:
                x = x + 0.5 * rest
                pos.append(x)
                break
            x += s
            pos.append(x)
        pos.append(b)
        arr = np.array(pos)
        if len(arr) - 1 < p:
            arr = np.linspace(a, b, p + 1)
        bps.append(arr[:-1])
        boxes.append(np.full(len(arr) - 1, k))
    bp = np.concatenate(bps + [[length]])
    t = np.concatenate([np.full(p, 0.0), bp, np.full(p, length)])
    return t, np.concatenate(boxes).astype(np.int64)


def objective(pts, u, t, p, n, weight, order, *, fidelity=1.0, length=0.0):
    """Upper band of ``H``.

    Upper band of ``H`` (one coordinate block), ``g`` (2n: x then y, padded layout resolved
    later) and the constant, for ``1/2 z'Hz + g'z + const`` = ``fidelity * sum |C(u_r) - p_r|^2
    + weight * integral |C^(order)|^2 + length * integral |C'|^2``.
    """
    span = find_spans(t, p, n, u)
    vals = basis_derivs(t, p, span, u, 0)
    band = 2.0 * fidelity * band_gram(span, vals, np.ones(len(u)), n)
    if weight > 0:
        band += 2.0 * weight * smoothness_band(t, p, n, order)
    if length > 0:
        band += 2.0 * length * smoothness_band(t, p, n, 1)
    rhs = fidelity * band_rhs(span, vals, pts, n)
    nb = bucket_size(n)
    g = np.zeros(2 * nb)
    g[:n] = -2.0 * rhs[:, 0]
    g[nb : nb + n] = -2.0 * rhs[:, 1]
    const = fidelity * float(np.sum(pts * pts))
    return band, g, const


def heading_rows(prob: Problem, n: int, nb: int, alpha: float | None = None):
    """Return the end-condition rows ``(A (N_HEADING_ROWS, 2 nb), lba, uba)``.

    Rows 0-1: ``c_1`` on the start-heading ray (``cross(d, c_1 - c_0) = 0``,
    ``dot(d, c_1 - c_0) >= 1e-3``, or ``= alpha`` with a start curvature); rows 2-3: the
    same for ``c_{n-2}`` and the goal heading; row 4: the start curvature
    (:func:`start_curvature_row`), unused rows with infinite bounds.
    """
    amat = np.zeros((N_HEADING_ROWS, 2 * nb))
    lba = np.full(N_HEADING_ROWS, -np.inf)
    uba = np.full(N_HEADING_ROWS, np.inf)
    eps = 1e-3  # cells: keeps c_1 != c_0 so the end heading is defined
    if prob.start_dir is not None:
        dx, dy = prob.start_dir
        # cross(d, c1 - c0) = 0 ; dot(d, c1 - c0) >= eps (= alpha with a start curvature)
        amat[0, 1], amat[0, nb + 1] = -dy, dx
        lba[0] = uba[0] = -dy * prob.start[0] + dx * prob.start[1]
        amat[1, 1], amat[1, nb + 1] = dx, dy
        lba[1] = dx * prob.start[0] + dy * prob.start[1] + eps
        if alpha is not None:
            lba[1] = uba[1] = dx * prob.start[0] + dy * prob.start[1] + alpha
    if prob.goal_dir is not None:
        dx, dy = prob.goal_dir
        j = n - 2
        amat[2, j], amat[2, nb + j] = -dy, dx
        lba[2] = uba[2] = -dy * prob.goal[0] + dx * prob.goal[1]
        # dot(d, goal - c_{n-2}) >= eps
        amat[3, j], amat[3, nb + j] = dx, dy
        uba[3] = dx * prob.goal[0] + dy * prob.goal[1] - eps
    return amat, lba, uba


def start_alpha(
    prob: Problem, t: np.ndarray, p: int, lo: np.ndarray, hi: np.ndarray, rows: tuple | None
) -> float | None:
    """Return the fixed ``|c_1 - c_0|`` (cells) of a fit with a start curvature, else None.

    ``t[p + 1] / p``: the parametric speed ``|C'(0)| = p |c_1 - c_0| / t[p + 1]`` is then 1,
    as for the arc-length parameter; at most half the room along the heading ray inside
    ``c_1``'s bounds (and region rows).
    """
    if prob.start_kappa is None or prob.start_dir is None:
        return None
    d = prob.start_dir
    room = np.inf
    for ax in range(2):
        if d[ax] > 1e-15:
            room = min(room, (hi[1, ax] - prob.start[ax]) / d[ax])
        elif d[ax] < -1e-15:
            room = min(room, (lo[1, ax] - prob.start[ax]) / d[ax])
    if rows is not None:
        A, _, rhi = (x[1] for x in rows)
        ad = A @ d
        slack = rhi - A @ prob.start
        pos = ad > 1e-15
        if np.any(pos):
            room = min(room, float(np.min(slack[pos] / ad[pos])))
    alpha = float(t[p + 1]) / p
    if np.isfinite(room) and room > 0.0:
        alpha = min(alpha, 0.5 * room)
    return alpha


def start_curvature_row(
    prob: Problem,
    t: np.ndarray,
    p: int,
    nb: int,
    alpha: float,
    amat: np.ndarray,
    lba: np.ndarray,
    uba: np.ndarray,
) -> None:
    """Fill row 4: the curvature at ``u = 0`` equals ``prob.start_kappa`` (1/cell).

    For clamped knots ``C'(0) = p (c_1 - c_0) / t_{p+1}`` and ``C''(0) =
    p (p - 1) / t_{p+1} ((c_2 - c_1) / t_{p+2} - (c_1 - c_0) / t_{p+1})``, so with
    ``c_1 - c_0 = alpha d`` (``|d| = 1``) the curvature is ``(p - 1) t_{p+1} /
    (p t_{p+2}) cross(d, c_2 - c_1) / alpha^2``: fixing ``alpha`` makes it linear in
    ``c_2``.
    """
    dx, dy = prob.start_dir
    k_rhs = prob.start_kappa * alpha * alpha * p * float(t[p + 2]) / ((p - 1) * float(t[p + 1]))
    # cross(d, c2 - c1) = -dy (x2 - x1) + dx (y2 - y1)
    amat[4, 2], amat[4, nb + 2] = -dy, dx
    amat[4, 1], amat[4, nb + 1] = dy, -dx
    lba[4] = uba[4] = k_rhs


def project_heading(
    c: np.ndarray,
    prob: Problem,
    lo: np.ndarray,
    hi: np.ndarray,
    point_rows=None,
    alpha: float | None = None,
) -> None:
    """Put ``c_1`` and ``c_{n-2}`` exactly on their heading rays.

    ``c_1`` (``c_{n-2}``) goes on the start (reversed goal) heading ray, inside its bounds
    (and its region rows ``lo <= A c <= hi`` in a polygon corridor), at least ``1e-3`` cells
    from the end point when the bounds allow it; with a start curvature ``c_1`` is exactly
    ``alpha`` cells along the start ray.
    """
    ends = []
    if prob.start_dir is not None:
        ends.append((1, prob.start, prob.start_dir))
    if prob.goal_dir is not None:
        ends.append((len(c) - 2, prob.goal, -prob.goal_dir))
    for idx, end, d in ends:
        if idx == 1 and alpha is not None:
            c[idx] = end + alpha * d
            continue
        a_lo, a_hi = 0.0, np.inf
        for ax in range(2):
            if abs(d[ax]) > 1e-15:
                t1 = (lo[idx, ax] - end[ax]) / d[ax]
                t2 = (hi[idx, ax] - end[ax]) / d[ax]
                a_lo = max(a_lo, min(t1, t2))
                a_hi = min(a_hi, max(t1, t2))
        if point_rows is not None:  # A (end + a d) in [rlo, rhi]
            A, rlo, rhi = (x[idx] for x in point_rows)
            ad = A @ d
            ae = A @ end
            for q in range(len(ad)):
                if abs(ad[q]) > 1e-15:
                    t1 = (rlo[q] - ae[q]) / ad[q]
                    t2 = (rhi[q] - ae[q]) / ad[q]
                    a_lo = max(a_lo, min(t1, t2))
                    a_hi = min(a_hi, max(t1, t2))
        a = float(np.dot(c[idx] - end, d))
        a = min(max(a, a_lo, min(1e-3, a_hi)), a_hi)
        c[idx] = np.clip(end + a * d, lo[idx], hi[idx])


def build_problem(
    options: Smoother,
    grid_path_or_points: Any,
    corridor: Corridor | PolygonCorridor,
    *,
    start: Any,
    goal: Any,
    hs: float | None,
    hg: float | None,
    start_kappa: float | None = None,
    unit_m: float | None = None,
) -> tuple[Problem, np.ndarray, np.ndarray]:
    """Return the fit in length units (``Problem.res``), and the exact end points (m).

    Parameters
    ----------
    options : Smoother
        ``objective`` decides the targets' role (taut or fidelity).
    grid_path_or_points, corridor, start, goal
        As in :meth:`Smoother.fit`.
    hs, hg : float or None
        Validated start and goal headings (rad).
    start_kappa : float or None
        Validated start curvature (1/m), with ``hs``.
    unit_m : float or None
        The length unit (m) the problem counts in; ``None``: ``corridor.unit_m``.

    Raises
    ------
    InvalidInputError
        An end point outside its end region, or targets that do not match the corridor.
    """
    polygons = isinstance(corridor, PolygonCorridor)
    res = corridor.unit_m if unit_m is None else float(unit_m)
    origin = np.asarray(corridor.origin, dtype=float)
    taut = options.objective == "taut" or (options.objective == "auto" and polygons)
    if polygons:
        targets, u_m = polygon_targets(corridor, res)
        p0 = _end_point("start", start, corridor.path[0])
        p1 = _end_point("goal", goal, corridor.path[-1])
        for name, pt, k in (("start", p0, 0), ("goal", p1, len(corridor.regions) - 1)):
            reg = corridor.regions[k]
            if not bool(reg.contains(pt[None, :], tol=CLEARANCE_TOL_M)[0]):
                raise InvalidInputError(
                    f"{name} {pt.tolist()} m must lie in the corridor's region {k} "
                    f"(vertices {np.round(reg.vertices, 6).tolist()} m)"
                )
        rows, lo_r, hi_r = region_rows(corridor, origin, res)
        prob = Problem(
            targets=(targets - origin) / res,
            u=u_m / res,
            lo=lo_r,
            hi=hi_r,
            dlo=np.full((len(rows), 2), -np.inf),
            dhi=np.full((len(rows), 2), np.inf),
            trans=corridor.transitions_m / res,
            overlap=(corridor.overlap_s[:, 1] - corridor.overlap_s[:, 0]) / res,
            start=(p0 - origin) / res,
            goal=(p1 - origin) / res,
            start_dir=None if hs is None else np.array([math.cos(hs), math.sin(hs)]),
            goal_dir=None if hg is None else np.array([math.cos(hg), math.sin(hg)]),
            res=res,
            rows=rows,
            taut=taut,
            start_kappa=None if start_kappa is None else start_kappa * res,
        )
    else:
        targets = box_targets(grid_path_or_points, corridor)
        p0 = _end_point("start", start, targets[0])
        p1 = _end_point("goal", goal, targets[-1])
        b0, b1 = corridor.boxes[0], corridor.boxes[-1]
        if not b0.contains(p0):
            raise InvalidInputError(f"start {p0.tolist()} m must lie in the first box {b0}")
        if not b1.contains(p1):
            raise InvalidInputError(f"goal {p1.tolist()} m must lie in the last box {b1}")
        prob = Problem(
            targets=(targets - origin) / res,
            u=corridor.path_s / res,
            lo=(corridor.lower - origin) / res,
            hi=(corridor.upper - origin) / res,
            dlo=(corridor.diag_lower - _sd(origin)) / res,
            dhi=(corridor.diag_upper - _sd(origin)) / res,
            trans=corridor.transitions_m / res,
            overlap=(corridor.overlap_end_m - corridor.overlap_start_m) / res,
            start=(p0 - origin) / res,
            goal=(p1 - origin) / res,
            start_dir=None if hs is None else np.array([math.cos(hs), math.sin(hs)]),
            goal_dir=None if hg is None else np.array([math.cos(hg), math.sin(hg)]),
            res=res,
            taut=taut,
            start_kappa=None if start_kappa is None else start_kappa * res,
        )
    return prob, p0, p1


def assemble(options: Smoother, prob: Problem, h: float) -> Assembly:
    """Return the QP of one attempt on the knots of longest span ``h`` (cells).

    Control-point bounds are the intersection of the regions of the spans each point
    touches; the fixed end points get theirs from the exact ends.

    Raises
    ------
    EmptyBoundsError
        The regions of some point's spans do not intersect.
    """
    p = options.degree
    t, span_box = graded_knots(prob.u[-1], prob.trans, prob.overlap, p, h)
    n = len(t) - p - 1
    nb = bucket_size(n)
    # control-point bounds: intersection of the regions of the spans each one touches
    lo = np.full((n, 2), -np.inf)
    hi = np.full((n, 2), np.inf)
    dlo = np.full((n, 2), -np.inf)
    dhi = np.full((n, 2), np.inf)
    for off in range(p + 1):
        idx = np.arange(len(span_box)) + off
        lo[idx] = np.maximum(lo[idx], prob.lo[span_box])
        hi[idx] = np.minimum(hi[idx], prob.hi[span_box])
        dlo[idx] = np.maximum(dlo[idx], prob.dlo[span_box])
        dhi[idx] = np.minimum(dhi[idx], prob.dhi[span_box])
    if np.any(lo > hi) or np.any(dlo > dhi):
        raise EmptyBoundsError("empty control-point bound (regions do not intersect)")
    lo[0] = hi[0] = prob.start
    lo[-1] = hi[-1] = prob.goal
    dlo[[0, -1]] = -np.inf  # the fixed ends were checked against their regions
    dhi[[0, -1]] = np.inf
    if prob.taut:
        band, g, const = objective(
            prob.targets,
            prob.u,
            t,
            p,
            n,
            options.smoothness_weight,
            options.smoothness_order,
            fidelity=options.taut_fidelity_weight,
            length=options.taut_length_weight,
        )
    else:
        band, g, const = objective(
            prob.targets, prob.u, t, p, n, options.smoothness_weight, options.smoothness_order
        )
    band[0] += 1e-9 * (1.0 + band[0].max())  # keeps the Hessian definite
    full = np.zeros((p + 1, nb))
    full[:, :n] = band[:, :n]
    full[0, n:] = 1.0  # padded variables: fixed at 0 by their bounds
    lbx = np.zeros(2 * nb)
    ubx = np.zeros(2 * nb)
    lbx[:n], lbx[nb : nb + n] = lo[:, 0], lo[:, 1]
    ubx[:n], ubx[nb : nb + n] = hi[:, 0], hi[:, 1]
    rows_of_points = None
    if prob.rows is None:
        k_rows, coef = 2, None
        rlb, rub = diag_row_bounds(dlo, dhi, nb)
    else:
        k_rows, coef, rlb, rub = point_rows(prob.rows, span_box, n, p, lo, hi, nb)
        rows_of_points = (coef, rlb.reshape(nb, k_rows), rub.reshape(nb, k_rows))
    alpha = start_alpha(prob, t, p, lo, hi, rows_of_points)
    heading, lba, uba = heading_rows(prob, n, nb, alpha)
    if alpha is not None:
        start_curvature_row(prob, t, p, nb, alpha, heading, lba, uba)
    lba = np.concatenate([lba, rlb])
    uba = np.concatenate([uba, rub])
    x0 = np.zeros(2 * nb)
    # warm start: the targets projected to the bounds, by parameter
    cs = np.concatenate([[0.0], np.cumsum(t)])
    greville = (cs[p + 1 : n + p + 1] - cs[1 : n + 1]) / p  # mean of t[i+1 .. i+p]
    for d in range(2):
        guess = np.interp(greville, prob.u, prob.targets[:, d])
        x0[d * nb : d * nb + n] = np.clip(guess, lbx[d * nb : d * nb + n], ubx[d * nb : d * nb + n])
    qp = QPData(
        full=full,
        g=g,
        n=n,
        nb=nb,
        lbx=lbx,
        ubx=ubx,
        heading=heading,
        lba=lba,
        uba=uba,
        k=k_rows,
        region_coef=coef,
    )
    return Assembly(
        qp=qp,
        knots=t,
        span_box=span_box,
        lo=lo,
        hi=hi,
        point_rows=rows_of_points,
        x0=x0,
        const=const,
        start_alpha=alpha,
    )
