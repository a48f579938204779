"""A planar parametric curve: the protocol every path in :mod:`trajopt` follows.

Subclasses provide :attr:`domain` and ``__call__(u, nu)``; this base class derives the
geometry from them: heading, signed curvature, arc length and the arc-length lookup
``u_at_s``, and dense sampling. B-spline fits, polynomial fits and the smoother's output
all share it, so metrics and the time parameterisation accept any of them.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import NamedTuple

import numpy as np
from numpy.polynomial.legendre import leggauss

GL_X, GL_W = leggauss(5)  # 5-point Gauss-Legendre nodes on [-1, 1], weights
STILL_SPEED_RATIO = 1e-9  # |c'| below this fraction of the mean parametric speed counts as zero


class CurveSamples(NamedTuple):
    """Dense samples of a curve (all arrays of shape ``(m,)`` except ``xy``).

    Attributes
    ----------
    u : parameter values
    s : arc length from the start of the domain (m)
    xy : positions, shape (m, 2) (m)
    heading : tangent direction, unwrapped (rad)
    curvature : signed curvature (1/m)
    """

    u: np.ndarray
    s: np.ndarray
    xy: np.ndarray
    heading: np.ndarray
    curvature: np.ndarray


class ParametricCurve(ABC):
    """Abstract planar curve ``u -> (x(u), y(u))`` on ``domain = (u0, u1)``.

    Subclasses implement :attr:`domain` and :meth:`__call__`. Arc-length quantities are
    computed once, lazily, by 5-point Gauss-Legendre quadrature on a fine partition of
    the domain (``breakpoints`` refined ``_ARC_SUBDIVISIONS`` times, and bisected further
    where the quadrature has not converged, next to near-cusps) and a cubic Hermite model of
    ``s(u)`` between the nodes.
    """

    _ARC_SUBDIVISIONS = 16

    @property
    @abstractmethod
    def domain(self) -> tuple[float, float]:
        """``(u0, u1)``: the parameter interval."""

    @abstractmethod
    def __call__(self, u: np.ndarray | float, nu: int = 0) -> np.ndarray:
        """Position (``nu = 0``) or ``nu``-th derivative w.r.t. ``u``, shape ``(..., 2)``."""

    def breakpoints(self) -> np.ndarray:
        """Parameter values where the curve may lose smoothness (default: the ends)."""
        return np.asarray(self.domain, dtype=float)

    @property
    def polynomial_degree(self) -> int | None:
        """Degree ``p`` when the curve is a polynomial.

        Degree ``p`` when the curve is a polynomial of degree ``<= p`` between consecutive
        :meth:`breakpoints`, else ``None`` (the default for a subclass).

        The timing bounds the curvature of such curves exactly (:mod:`trajopt.geometry._curvature_bound`)
        and samples any other curve.
        """
        return None

    # --------------------------------------------------------------- geometry
    def heading(self, u: np.ndarray | float) -> np.ndarray:
        """Tangent direction ``atan2(y', x')`` in (-pi, pi] (rad), shape of ``u``.

        Where the parametric speed vanishes (``|c'|`` below ``1e-9`` of the mean parametric
        speed ``length / (u1 - u0)``, e.g. at the ends of a Bezier chain whose first two
        control points coincide) the heading is the limit of the tangent direction: the
        direction of the first non-vanishing derivative ``c^(k)`` (``k = 2 .. 6``), taken
        towards larger ``u`` and, at the end of the domain, from below (``(-1)^(k-1) c^(k)``).
        """
        uu = np.asarray(u, dtype=float)
        d = self(uu, 1)
        theta = np.arctan2(d[..., 1], d[..., 0])
        still = np.hypot(d[..., 0], d[..., 1]) <= STILL_SPEED_RATIO * self.mean_speed()
        if np.any(still):
            theta = np.where(still, self._limit_heading(uu, theta), theta)
        return theta

    def mean_speed(self) -> float:
        """Return the mean parametric speed ``length / (u1 - u0)`` (m per unit of ``u``; 0 for an empty domain).

        A tangent shorter than ``STILL_SPEED_RATIO`` times it counts as zero speed (where
        :meth:`heading` takes the limit direction).
        """
        lo, hi = self.domain
        return self.length / (hi - lo) if hi > lo else 0.0

    def _limit_heading(self, u: np.ndarray, theta: np.ndarray) -> np.ndarray:
        """Tangent direction at zero-speed parameters ``u`` from higher derivatives."""
        lo, hi = self.domain
        uu = np.clip(u, lo, hi)
        span = hi - lo
        floor = STILL_SPEED_RATIO * self.mean_speed()
        out = np.array(theta, dtype=float, copy=True)
        todo = np.ones(uu.shape, dtype=bool)
        for k in range(2, 7):
            dk = np.asarray(self(uu, k), dtype=float)
            sign = np.where(uu >= hi, (-1.0) ** (k - 1), 1.0)
            big = todo & (np.hypot(dk[..., 0], dk[..., 1]) * span ** (k - 1) > floor)
            out = np.where(big, np.arctan2(sign * dk[..., 1], sign * dk[..., 0]), out)
            todo &= ~big
            if not np.any(todo):
                break
        return out

    def speed(self, u: np.ndarray | float) -> np.ndarray:
        """Parametric speed ``|c'(u)|`` (m per unit of ``u``)."""
        d = self(u, 1)
        return np.hypot(d[..., 0], d[..., 1])

    def curvature(self, u: np.ndarray | float) -> np.ndarray:
        """Signed curvature ``(x'y'' - y'x'') / |c'|^3`` (1/m); ``inf`` where ``c' = 0``."""
        return signed_curvature(self(u, 1), self(u, 2))

    def curvature_rate(self, u: np.ndarray | float) -> np.ndarray:
        """Return ``d kappa / ds``, the signed curvature's derivative along the arc length (1/m^2).

        ``(d kappa / du) / |c'|``, where ``d kappa / du = (c' x c''') / |c'|^3
        - 3 (c' x c'') (c' . c'') / |c'|^5`` (``x`` the planar cross product); needs the
        third derivative (a cubic B-spline is C2, its third derivative is taken on the side
        ``__call__`` takes at a knot).
        """
        d1, d2, d3 = self(u, 1), self(u, 2), self(u, 3)
        x1, y1 = d1[..., 0], d1[..., 1]
        sp2 = x1 * x1 + y1 * y1
        cross2 = x1 * d2[..., 1] - y1 * d2[..., 0]
        cross3 = x1 * d3[..., 1] - y1 * d3[..., 0]
        dot12 = x1 * d2[..., 0] + y1 * d2[..., 1]
        with np.errstate(divide="ignore", invalid="ignore"):
            return (cross3 * sp2 - 3.0 * cross2 * dot12) / (sp2 * sp2 * sp2)

    # ------------------------------------------------------------- arc length
    def _arc_table(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        table = getattr(self, "_arc_cache", None)
        if table is None:
            bp = np.unique(np.clip(self.breakpoints(), *self.domain))
            m = self._ARC_SUBDIVISIONS
            # m nodes per piece (as np.linspace(a, b, m, endpoint=False): i * step + a)
            step = (bp[1:] - bp[:-1]) / m
            fine = np.concatenate(
                [(np.arange(m)[None, :] * step[:, None] + bp[:-1, None]).ravel(), bp[-1:]]
            )
            fine, seg = self._refined_partition(fine)
            s_nodes = np.concatenate([[0.0], np.cumsum(seg)])
            v_nodes = self.speed(fine)
            table = (fine, s_nodes, v_nodes)
            object.__setattr__(self, "_arc_cache", table)
        return table

    def _refined_partition(self, nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Bisect the intervals.

        Bisect the intervals of ``nodes`` where the quadrature of ``|c'|`` on the two halves
        differs from that on the whole by more than ``1e-13`` of the curve's length (a
        near-cusp, where the speed has a sharp minimum), up to 12 times; returns the nodes and
        the length of every interval.
        """
        a, b = nodes[:-1], nodes[1:]
        seg = self._gl(a, b)
        total = max(float(seg.sum()), 1e-300)
        for _ in range(12):
            mid = 0.5 * (a + b)
            left, right = self._gl(a, mid), self._gl(mid, b)
            bad = np.abs(left + right - seg) > 1e-13 * total
            if not np.any(bad):
                break
            # replace every bad interval by its halves (kept in order)
            a = np.concatenate([a[~bad], a[bad], mid[bad]])
            b = np.concatenate([b[~bad], mid[bad], b[bad]])
            seg = np.concatenate([seg[~bad], left[bad], right[bad]])
            order = np.argsort(a, kind="stable")
            a, b, seg = a[order], b[order], seg[order]
        return np.concatenate([a, b[-1:]]), seg

    def _gl(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        half = 0.5 * (b - a)
        q = (0.5 * (a + b))[:, None] + half[:, None] * GL_X[None, :]
        return half * (self.speed(q) @ GL_W)

    @property
    def length(self) -> float:
        """Arc length of the whole curve (m)."""
        return float(self._arc_table()[1][-1])

    def s_at_u(self, u: np.ndarray | float) -> np.ndarray:
        """Arc length from the start to parameter ``u`` (m), vectorised.

        Gauss-Legendre quadrature from the nearest table node below ``u``.
        """
        nodes, s_nodes, _ = self._arc_table()
        uu = np.clip(np.asarray(u, dtype=float), nodes[0], nodes[-1])
        i = np.clip(np.searchsorted(nodes, uu, side="right") - 1, 0, len(nodes) - 2)
        return s_nodes[i] + self._partial_length(nodes[i], uu)

    def _partial_length(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        half = 0.5 * (b - a)
        mid = 0.5 * (a + b)
        q = mid[..., None] + half[..., None] * GL_X
        return half * (self.speed(q) @ GL_W)

    def u_at_s(self, s: np.ndarray | float, *, exact: bool = True) -> np.ndarray:
        """Parameter at arc length ``s`` (m) from the start, vectorised.

        ``s`` is clipped to ``[0, length]``. Newton steps on a cubic Hermite model of
        ``s(u)`` (the arc-length table's nodes and speeds) give a first answer; with
        ``exact=True`` safeguarded Newton steps on the quadrature refine it to about 1e-12 m
        on smooth curves. ``exact=False`` skips that refinement (no curve evaluation; the cubic
        model's error, O(spacing^4): ~3e-7 m with 6 cm table spacing on a parabola,
        ~1e-8 m on the smoother's B-splines).
        """
        nodes, s_nodes, v_nodes = self._arc_table()
        ss = np.clip(np.asarray(s, dtype=float), 0.0, s_nodes[-1])
        i = np.clip(np.searchsorted(s_nodes, ss, side="right") - 1, 0, len(nodes) - 2)
        ds = s_nodes[i + 1] - s_nodes[i]
        with np.errstate(divide="ignore", invalid="ignore"):
            frac = np.where(ds > 0, (ss - s_nodes[i]) / ds, 0.0)
        lo, hi = nodes[i], nodes[i + 1]
        u = lo + frac * (hi - lo)
        for _ in range(3):  # Newton on the Hermite model (cheap), then on the quadrature
            f = _hermite(nodes, s_nodes, v_nodes, i, u) - ss
            df = _hermite_d(nodes, s_nodes, v_nodes, i, u)
            with np.errstate(divide="ignore", invalid="ignore"):
                step = np.where(df > 0, f / df, 0.0)
            u = np.clip(u - step, lo, hi)
        for _ in range(2 if exact else 0):
            f = s_nodes[i] + self._partial_length(lo, u) - ss
            df = self.speed(u)
            with np.errstate(divide="ignore", invalid="ignore"):
                step = np.where(df > 0, f / df, 0.0)
            u = np.clip(u - step, lo, hi)
        return u

    def refine_u_at_s(self, s: np.ndarray, u: np.ndarray) -> np.ndarray:
        """Refine first guesses ``u`` of the parameters at arc lengths ``s`` (m) by Newton steps.

        Newton steps on :meth:`s_at_u` (the quadrature), each point repeated (at most 6 steps)
        while its last step moved it by more than 1e-9 of the domain: Newton converges
        quadratically, so after a step below that the next would be ~1e-16 of the domain.
        A good first guess (a dense table's) needs one or two steps; near a sharp curvature
        peak a table's guess can be 1e-5 of the domain off and needs more.

        Parameters
        ----------
        s : ndarray, shape (n,)
            Arc lengths (m) from the start.
        u : ndarray, shape (n,)
            First guesses of the parameters (in the domain).

        Returns
        -------
        ndarray, shape (n,)
            The refined parameters, clipped to :attr:`domain` (a new array).
        """
        u = np.array(u, dtype=float)
        ss = np.broadcast_to(np.asarray(s, dtype=float), u.shape)
        lo, hi = self.domain
        todo = np.ones(u.shape, dtype=bool)  # only points whose last step moved go on
        for _ in range(6):
            uu = u[todo]
            sp = np.asarray(self.speed(uu))
            err = np.asarray(self.s_at_u(uu)) - ss[todo]
            with np.errstate(divide="ignore", invalid="ignore"):
                step = np.where(sp > 0, err / sp, 0.0)
            u[todo] = np.clip(uu - step, lo, hi)
            moving = np.abs(step) > 1e-9 * (hi - lo)
            if not np.any(moving):
                break
            todo[todo] = moving
        return u

    # ---------------------------------------------------------------- sampling
    def sample(self, n: int | None = None, *, ds: float | None = None) -> CurveSamples:
        """Sample equally spaced in arc length.

        Parameters
        ----------
        n : int, optional
            Number of samples (>= 2). Default 200 when ``ds`` is not given.
        ds : float, optional
            Maximum spacing in metres; overrides ``n``.
        """
        length = self.length
        if ds is not None:
            if not ds > 0:
                raise ValueError(f"ds must be > 0 m, got {ds!r}")
            n = max(2, int(np.ceil(length / ds)) + 1)
        elif n is None:
            n = 200
        if n < 2:
            raise ValueError(f"n must be >= 2, got {n}")
        s = np.linspace(0.0, length, n)
        u = self.u_at_s(s)
        return CurveSamples(
            u=u,
            s=s,
            xy=self(u),
            heading=np.unwrap(self.heading(u)),
            curvature=self.curvature(u),
        )


def signed_curvature(d1: np.ndarray, d2: np.ndarray) -> np.ndarray:
    """``(x'y'' - y'x'') / |c'|^3`` from first and second derivatives (..., 2); inf at c' = 0."""
    cross = d1[..., 0] * d2[..., 1] - d1[..., 1] * d2[..., 0]
    sp3 = np.hypot(d1[..., 0], d1[..., 1]) ** 3
    with np.errstate(divide="ignore", invalid="ignore"):
        k = cross / sp3
    return np.where(sp3 > 0, k, np.inf)


def _hermite(nodes, s_nodes, v_nodes, i, u):
    h = nodes[i + 1] - nodes[i]
    t = np.where(h > 0, (u - nodes[i]) / np.where(h > 0, h, 1.0), 0.0)
    t2, t3 = t * t, t * t * t
    return (
        (2 * t3 - 3 * t2 + 1) * s_nodes[i]
        + (t3 - 2 * t2 + t) * h * v_nodes[i]
        + (-2 * t3 + 3 * t2) * s_nodes[i + 1]
        + (t3 - t2) * h * v_nodes[i + 1]
    )


def _hermite_d(nodes, s_nodes, v_nodes, i, u):
    h = nodes[i + 1] - nodes[i]
    hs = np.where(h > 0, h, 1.0)
    t = np.where(h > 0, (u - nodes[i]) / hs, 0.0)
    t2 = t * t
    return (
        (6 * t2 - 6 * t) * s_nodes[i] / hs
        + (3 * t2 - 4 * t + 1) * v_nodes[i]
        + (-6 * t2 + 6 * t) * s_nodes[i + 1] / hs
        + (3 * t2 - 2 * t) * v_nodes[i + 1]
    )


class PolylineCurve(ParametricCurve):
    """A polyline as a curve, parameterised by arc length (``u = s``).

    Its heading is piecewise constant and its curvature is zero between vertices (the
    turns are concentrated at the vertices); metrics use the vertex turn angles to score
    heading jumps. Used for raw A* paths.

    Parameters
    ----------
    points : array_like, shape (m, 2)
        Vertices in metres; consecutive duplicates are removed.
    """

    __slots__ = ("points", "_s", "_arc_cache")

    def __init__(self, points: np.ndarray) -> None:
        p = np.asarray(points, dtype=float)
        if p.ndim != 2 or p.shape[1] != 2 or len(p) < 1:
            raise ValueError(f"points must have shape (m, 2) with m >= 1, got {p.shape}")
        keep = np.ones(len(p), bool)
        keep[1:] = np.any(np.diff(p, axis=0) != 0, axis=1)
        p = p[keep]
        if len(p) == 1:
            p = np.vstack([p, p])
        p.flags.writeable = False
        self.points = p
        s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(p, axis=0).T))])
        s.flags.writeable = False
        self._s = s

    @property
    def domain(self) -> tuple[float, float]:
        """Parameter interval ``(u0, u1)`` of the curve."""
        return (0.0, float(self._s[-1]))

    def breakpoints(self) -> np.ndarray:
        """Return the parameters where the polynomial pieces meet (with the ends)."""
        return self._s.copy()

    @property
    def polynomial_degree(self) -> int:
        """Degree of the polynomial pieces (the curvature bound uses it)."""
        return 1

    @property
    def length(self) -> float:
        """Arc length (m)."""
        return float(self._s[-1])

    def s_at_u(self, u):
        """Return the arc length (m) at parameters ``u``."""
        return np.clip(np.asarray(u, dtype=float), 0.0, self.length)

    def u_at_s(self, s):
        """Return the parameters at arc lengths ``s`` (m)."""
        return np.clip(np.asarray(s, dtype=float), 0.0, self.length)

    def __call__(self, u, nu: int = 0) -> np.ndarray:
        """Evaluate the ``nu``-th derivative at ``u``, shape ``(..., 2)``."""
        uu = np.clip(np.asarray(u, dtype=float), 0.0, self.length)
        seg = np.clip(np.searchsorted(self._s, uu, side="right") - 1, 0, len(self.points) - 2)
        d = self.points[seg + 1] - self.points[seg]
        h = (self._s[seg + 1] - self._s[seg])[..., None]
        unit = np.where(h > 0, d / np.where(h > 0, h, 1.0), 0.0)
        if nu == 0:
            return self.points[seg] + unit * (uu[..., None] - self._s[seg][..., None])
        if nu == 1:
            return unit
        return np.zeros(uu.shape + (2,))


class CurveSegment(ParametricCurve):
    """The part of a curve between two of its parameters, evaluated exactly.

    Nothing is refitted or cut: the segment evaluates ``curve`` itself (same parameter,
    same derivatives) on ``[u0, u1]``, so its points are the curve's to the last bit. The
    re-plan's braking piece follows the old path this way
    (:mod:`trajopt.replan._brake`).

    Parameters
    ----------
    curve : ParametricCurve
        The whole curve.
    u0, u1 : float
        The segment's parameter interval, ``curve.domain[0] <= u0 < u1 <= curve.domain[1]``.
    """

    __slots__ = ("curve", "_domain", "_arc_cache")

    def __init__(self, curve: ParametricCurve, u0: float, u1: float) -> None:
        lo, hi = curve.domain
        u0, u1 = float(u0), float(u1)
        if not lo <= u0 < u1 <= hi:
            raise ValueError(f"need {lo} <= u0 < u1 <= {hi}, got u0={u0!r}, u1={u1!r}")
        self.curve = curve
        self._domain = (u0, u1)

    @property
    def domain(self) -> tuple[float, float]:
        """``(u0, u1)``: the segment's interval of the curve's parameter."""
        return self._domain

    def breakpoints(self) -> np.ndarray:
        """Return the curve's breakpoints inside the segment, with its ends."""
        u0, u1 = self._domain
        bp = np.asarray(self.curve.breakpoints(), dtype=float)
        return np.unique(np.concatenate([[u0, u1], bp[(bp > u0) & (bp < u1)]]))

    @property
    def polynomial_degree(self) -> int | None:
        """The curve's own (:attr:`ParametricCurve.polynomial_degree`)."""
        return self.curve.polynomial_degree

    def __call__(self, u: np.ndarray | float, nu: int = 0) -> np.ndarray:
        """Evaluate the curve's ``nu``-th derivative at ``u`` clipped to the segment."""
        return self.curve(np.clip(np.asarray(u, dtype=float), *self._domain), nu)


class ShiftedCurve(ParametricCurve):
    """A curve moved by a constant offset, its geometry the curve's own to the last bit.

    Positions are ``curve(u) + offset``; derivatives, hence heading, curvature, speed and
    arc length, are the curve's (not recomputed from the moved positions). A plan made in
    a map-local frame (its origin subtracted) is handed back in the map's frame this way:
    far from the origin (x near ``4.5e9`` m, where float64 positions are only ``1e-6`` m
    apart) the headings and curvatures stay those of the local curve.

    Parameters
    ----------
    curve : ParametricCurve
        The curve in its own frame.
    offset : array_like, shape (2,)
        Added to every position (m).
    """

    __slots__ = ("curve", "offset", "_arc_cache")

    def __init__(self, curve: ParametricCurve, offset: np.ndarray) -> None:
        self.curve = curve
        off = np.array(offset, dtype=float).reshape(2)
        off.flags.writeable = False
        self.offset = off

    @property
    def domain(self) -> tuple[float, float]:
        """The curve's parameter interval."""
        return self.curve.domain

    def breakpoints(self) -> np.ndarray:
        """Return the curve's breakpoints."""
        return self.curve.breakpoints()

    @property
    def polynomial_degree(self) -> int | None:
        """The curve's own (:attr:`ParametricCurve.polynomial_degree`)."""
        return self.curve.polynomial_degree

    def _arc_table(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return self.curve._arc_table()

    def __call__(self, u: np.ndarray | float, nu: int = 0) -> np.ndarray:
        """Position (moved by ``offset``) or the curve's ``nu``-th derivative at ``u``."""
        out = self.curve(u, nu)
        return out + self.offset if nu == 0 else out
