"""Planar B-spline curves ``(t, c, k)`` evaluated with de Boor's algorithm."""

from __future__ import annotations

import math

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

from trajopt.errors import InvalidInputError
from trajopt.geometry._curve import GL_W, GL_X, STILL_SPEED_RATIO, ParametricCurve
from trajopt.kernel_cache import watch_compiles


class BSplineCurve(ParametricCurve):
    """A planar B-spline ``C(u) = sum_i c_i B_{i,k}(u)``.

    Parameters
    ----------
    t : array_like, shape (n + k + 1,)
        Non-decreasing knots.
    c : array_like, shape (n, 2)
        Control points in metres.
    k : int
        Degree (>= 1).

    Notes
    -----
    The curve is defined on ``[t[k], t[n]]``; parameters outside are clipped. For a
    clamped knot vector (first and last knot repeated ``k + 1`` times) the curve starts at
    ``c[0]`` and ends at ``c[-1]``, and span ``j`` (``t[k+j] <= u < t[k+j+1]``) lies in the
    convex hull of ``c[j:j+k+1]``.
    """

    __slots__ = ("t", "c", "k", "_derivatives", "_arc_cache")

    def __init__(self, t: np.ndarray, c: np.ndarray, k: int) -> None:
        t = np.array(t, dtype=float)
        c = np.array(c, dtype=float)
        k = int(k)
        if k < 1:
            raise InvalidInputError(f"degree k must be >= 1, got {k}")
        if c.ndim != 2 or c.shape[1] != 2:
            raise InvalidInputError(f"control points c must have shape (n, 2), got {c.shape}")
        n = c.shape[0]
        if n < k + 1:
            raise InvalidInputError(f"need at least k + 1 = {k + 1} control points, got {n}")
        if t.shape != (n + k + 1,):
            raise InvalidInputError(
                f"need n + k + 1 = {n + k + 1} knots for {n} control points of degree {k}, "
                f"got {t.shape[0] if t.ndim == 1 else t.shape}"
            )
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(c))):
            raise InvalidInputError("knots and control points must be finite")
        if np.any(np.diff(t) < 0):
            raise InvalidInputError("knots t must be non-decreasing")
        if not t[n] > t[k]:
            raise InvalidInputError(f"empty domain: t[k]={t[k]} must be < t[n]={t[n]}")
        t.flags.writeable = False
        c.flags.writeable = False
        self.t, self.c, self.k = t, c, k
        self._derivatives: dict[int, tuple[np.ndarray, np.ndarray]] = {0: (t, c)}

    @classmethod
    def from_scipy(cls, spline) -> BSplineCurve:
        """Wrap a :class:`scipy.interpolate.BSpline` whose coefficients have shape (n, 2)."""
        n = len(spline.t) - spline.k - 1
        return cls(spline.t, np.asarray(spline.c)[:n], spline.k)

    @property
    def control_points(self) -> np.ndarray:
        """Control points, shape (n, 2) (read-only view)."""
        return self.c

    @property
    def domain(self) -> tuple[float, float]:
        """Parameter interval ``(u0, u1)`` of the curve."""
        n = self.c.shape[0]
        return (float(self.t[self.k]), float(self.t[n]))

    def breakpoints(self) -> np.ndarray:
        """Return the parameters where the polynomial pieces meet (with the ends)."""
        n = self.c.shape[0]
        return np.unique(self.t[self.k : n + 1])

    @property
    def polynomial_degree(self) -> int:
        """Degree of the polynomial pieces (the curvature bound uses it)."""
        return self.k

    def __call__(self, u: np.ndarray | float, nu: int = 0) -> np.ndarray:
        """Position or ``nu``-th derivative at ``u``; shape ``u.shape + (2,)``."""
        uu = np.asarray(u, dtype=np.float64)
        if nu > self.k:
            return np.zeros(uu.shape + (2,))
        t, c = self._derivative_coefficients(nu)  # float64, contiguous
        flat = np.ascontiguousarray(uu.reshape(-1))
        return de_boor(t, c, self.k - nu, flat).reshape(uu.shape + (2,))

    def refine_u_at_s(self, s: np.ndarray, u: np.ndarray) -> np.ndarray:
        """Refine first guesses ``u`` at arc lengths ``s`` (m): :meth:`ParametricCurve.refine_u_at_s`, compiled.

        The same Newton steps, point by point in one compiled loop (:func:`arc_newton`).

        Parameters
        ----------
        s : ndarray, shape (n,)
            Arc lengths (m) from the start.
        u : ndarray, shape (n,)
            First guesses of the parameters.

        Returns
        -------
        ndarray, shape (n,)
            The refined parameters, clipped to :attr:`domain` (a new array).
        """
        nodes, s_nodes, _ = self._arc_table()
        t1, c1 = self._derivative_coefficients(1)
        lo, hi = self.domain
        out = np.array(u, dtype=np.float64)
        ss = np.ascontiguousarray(np.broadcast_to(np.asarray(s, dtype=np.float64), out.shape))
        arc_newton(t1, c1, self.k - 1, nodes, s_nodes, ss, out, lo, hi, GL_X, GL_W)
        return out

    def pose_at_s(
        self, s: np.ndarray, grid_s: np.ndarray, grid_u: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Return the positions (m) and headings (rad) at arc lengths ``s`` (m), and their parameters.

        The parameter at each ``s``: ``numpy.interp`` of the table ``(grid_s, grid_u)`` (a
        first guess), refined by :meth:`refine_u_at_s`'s Newton steps; the position and the
        tangent by de Boor's algorithm; all in one compiled call (:func:`arc_pose`), the same
        floats as those calls one after another. The heading is :meth:`heading`'s
        (``numpy.arctan2`` of the tangent, the limit direction where the tangent vanishes).

        Parameters
        ----------
        s : ndarray, shape (n,)
            Arc lengths (m) from the start.
        grid_s, grid_u : ndarray, shape (g,)
            A table of arc lengths (m, non-decreasing) and the parameters at them, ``g >= 2``
            (a :class:`trajopt.Trajectory`'s ``theta_grid_s`` and ``u_grid``).

        Returns
        -------
        xy : ndarray, shape (n, 2)
            Positions (m).
        theta : ndarray, shape (n,)
            Headings (rad), in (-pi, pi].
        u : ndarray, shape (n,)
            Parameters, in :attr:`domain`.

        Raises
        ------
        InvalidInputError
            ``grid_s`` and ``grid_u`` not of one shape (g,) with ``g >= 2``.
        """
        gs = np.ascontiguousarray(grid_s, dtype=np.float64)
        gu = np.ascontiguousarray(grid_u, dtype=np.float64)
        if gs.ndim != 1 or gs.shape != gu.shape or gs.shape[0] < 2:
            raise InvalidInputError(
                f"grid_s and grid_u must have one shape (g,) with g >= 2, got {gs.shape} and "
                f"{gu.shape}"
            )
        nodes, s_nodes, _ = self._arc_table()
        t1, c1 = self._derivative_coefficients(1)
        ss = np.ascontiguousarray(np.asarray(s, dtype=np.float64).reshape(-1))
        lo, hi = self.domain
        out = arc_pose(
            self.t, self.c, self.k, t1, c1, nodes, s_nodes, gs, gu, lo, hi, GL_X, GL_W, ss
        )
        return out[:, 0:2], self._heading_of(out[:, 4], out[:, 2], out[:, 3]), out[:, 4]

    def _heading_of(self, u: np.ndarray, dx: np.ndarray, dy: np.ndarray) -> np.ndarray:
        """Return :meth:`heading` at ``u`` given the tangent ``(dx, dy)`` there (m per unit of ``u``), shape (n,).

        ``numpy.arctan2(dy, dx)`` (not the compiled ``atan2``: numpy's may differ in the last
        bit), the limit direction where the tangent vanishes: the same floats as
        :meth:`heading`.
        """
        theta = np.arctan2(dy, dx)
        still = np.hypot(dx, dy) <= STILL_SPEED_RATIO * self.mean_speed()
        if np.any(still):
            theta = np.where(still, self._limit_heading(u, theta), theta)
        return theta

    def derivative(self, nu: int = 1) -> BSplineCurve:
        """Return the ``nu``-th derivative as a new B-spline of degree ``k - nu``."""
        if not 1 <= nu < self.k:
            raise InvalidInputError(f"nu must be in [1, k-1] = [1, {self.k - 1}], got {nu}")
        t, c = self._derivative_coefficients(nu)
        return BSplineCurve(t, c, self.k - nu)

    def _derivative_coefficients(self, nu: int) -> tuple[np.ndarray, np.ndarray]:
        """Knots and control points of the ``nu``-th derivative (cached)."""
        if nu not in self._derivatives:
            t, c = self._derivative_coefficients(nu - 1)
            td, cd = derivative_control_points(t, c, self.k - nu + 1)
            # read-only like the curve's own: one compiled signature of the evaluator for all
            td.flags.writeable = False
            cd.flags.writeable = False
            self._derivatives[nu] = td, cd
        return self._derivatives[nu]

    def tail(self, u0: float) -> BSplineCurve:
        """Return the curve on ``[u0, t[n]]`` as a clamped B-spline of its own (exact).

        ``u0`` is inserted as a knot until it has multiplicity ``k`` (Boehm's insertion,
        which leaves the curve unchanged); the control points from the one at ``C(u0)`` on
        are the tail's. Each new control point is a convex combination of the control
        points of the span holding ``u0``, so it lies in every convex set holding them. The
        derivatives' coefficients are cut the same way from this curve's own, so they stay
        accurate when ``u0`` lies a hair before a knot (differences of the tail's control
        points over so short a first span would not).

        Parameters
        ----------
        u0 : float
            Start of the tail, in ``[t[k], t[n])`` (the curve's parameter, unchanged).

        Raises
        ------
        InvalidInputError
            ``u0`` outside ``[t[k], t[n])``.
        """
        lo, hi = self.domain
        u0 = float(u0)
        if not lo <= u0 < hi:
            raise InvalidInputError(f"u0 must lie in the domain [{lo}, {hi}), got {u0!r}")
        if u0 == lo:
            return self
        out = BSplineCurve(*_tail_coefficients(self.t, self.c, self.k, u0), self.k)
        for nu in range(1, self.k + 1):
            out._derivatives[nu] = _tail_coefficients(
                *self._derivative_coefficients(nu), self.k - nu, u0
            )
        return out

    def span_of(self, u: np.ndarray | float) -> np.ndarray:
        """Index ``j`` of the non-empty span holding ``u`` (control points ``c[j:j+k+1]``)."""
        n = self.c.shape[0]
        uu = np.clip(np.asarray(u, dtype=float), *self.domain)
        j = np.searchsorted(self.t, uu, side="right") - 1
        return np.clip(j, self.k, n - 1) - self.k

    def __repr__(self) -> str:
        return f"BSplineCurve(k={self.k}, n={self.c.shape[0]}, domain={self.domain})"


def concatenate(curves: list[BSplineCurve], tol_m: float = 1e-9) -> BSplineCurve:
    """Return one B-spline that traces ``curves`` one after the other.

    Each curve must be clamped, of the same degree ``k``, and start where the previous one
    ends (within ``tol_m``, metres). The result has a knot of multiplicity ``k`` at each
    join, the later curve's knots shifted to start there, and the curves' control points
    with each shared end point once: on either side of a join it is exactly the curve it
    came from (with that multiplicity the two sides share no basis function but the one
    at the join, which is 1 there). It is continuous; its derivatives are whatever the
    curves' are at the joins (a parameter speed may jump; heading and curvature are
    continuous where the curves' are).

    Raises
    ------
    InvalidInputError
        No curve, degrees that differ, a curve that is not clamped, or a gap at a join.
    """
    if not curves:
        raise InvalidInputError("concatenate needs at least one curve")
    k = curves[0].k
    knots = [np.asarray(curves[0].t)]
    points = [np.asarray(curves[0].c)]
    for i, cv in enumerate(curves):
        t = np.asarray(cv.t)
        if cv.k != k:
            raise InvalidInputError(f"curve {i} has degree {cv.k}, curve 0 degree {k}")
        if np.any(t[: k + 1] != t[0]) or np.any(t[-k - 1 :] != t[-1]):
            raise InvalidInputError(f"curve {i} is not clamped (its end knots differ)")
        if i == 0:
            continue
        gap = float(np.hypot(*(np.asarray(cv.c[0]) - points[-1][-1])))
        if gap > tol_m:
            raise InvalidInputError(
                f"curve {i} starts {gap:.3g} m from where curve {i - 1} ends (tol_m={tol_m})"
            )
        shift = knots[-1][-1] - t[0]
        knots[-1] = knots[-1][:-1]  # the join keeps k copies
        knots.append(t[k + 1 :] + shift)
        points.append(np.asarray(cv.c)[1:])
    return BSplineCurve(np.concatenate(knots), np.concatenate(points), k)


def _tail_coefficients(t: np.ndarray, c: np.ndarray, k: int, u0: float):
    """Knots and control points of the spline ``(t, c, k)`` (``k >= 0``) cut to ``[u0, ...]``.

    Boehm's insertion of ``u0`` up to multiplicity ``k``; the tail starts with ``u0``
    repeated ``k + 1`` times.
    """
    t, c = np.array(t, dtype=float), np.array(c, dtype=float)
    for _ in range(max(0, k - int(np.count_nonzero(t == u0)))):
        m = int(np.searchsorted(t, u0, side="right")) - 1  # t[m] <= u0 < t[m + 1]
        i = np.arange(m - k + 1, m + 1)
        alpha = ((u0 - t[i]) / (t[i + k] - t[i]))[:, None]
        mixed = (1.0 - alpha) * c[i - 1] + alpha * c[i]
        c = np.concatenate([c[: m - k + 1], mixed, c[m:]])
        t = np.insert(t, m + 1, u0)
    m = int(np.searchsorted(t, u0, side="right")) - 1  # the span [u0, next knot)
    tt, cc = np.concatenate([[u0], t[m - k + 1 :]]), np.ascontiguousarray(c[m - k :])
    tt.flags.writeable = False
    cc.flags.writeable = False
    return tt, cc


def derivative_control_points(
    t: np.ndarray, c: np.ndarray, k: int
) -> tuple[np.ndarray, np.ndarray]:
    """Return the knots and control points of the derivative of the spline ``(t, c, k)``.

    The derivative is a B-spline of degree ``k - 1`` on the knots ``t[1:-1]`` with control
    points ``Q_i = k (c_{i+1} - c_i) / (t_{i+k+1} - t_{i+1})`` (``0`` where that knot
    interval is empty).

    Parameters
    ----------
    t : ndarray, shape (n + k + 1,)
    c : ndarray, shape (n, d)
    k : int
        Degree (>= 1).

    Returns
    -------
    knots : ndarray, shape (n + k - 1,)
    control_points : ndarray, shape (n - 1, d)
    """
    n = len(c)
    den = t[k + 1 : n + k] - t[1:n]
    q = np.zeros((n - 1, c.shape[1]))
    ok = den > 0
    q[ok] = k * np.diff(c, axis=0)[ok] / den[ok, None]
    return t[1:-1], q


watch_compiles()  # a first compilation logs one notice (trajopt.kernel_cache)


@intrinsic
def _fma(typingctx, a, b, c):  # pragma: no cover - compiled
    """Return ``a * b + c`` rounded once (LLVM's ``llvm.fma.f64``)."""
    sig = types.float64(types.float64, types.float64, types.float64)

    def codegen(context, builder, signature, args):
        d = ir.DoubleType()
        fn = builder.module.declare_intrinsic("llvm.fma", [d], ir.FunctionType(d, [d, d, d]))
        return builder.call(fn, args)

    return sig, codegen


@njit(cache=True)
def _speed_at(t, c, k, x, d):  # pragma: no cover - compiled
    """Return ``|C(x)|`` of the planar spline ``(t, c, k)`` (de Boor's algorithm as :func:`de_boor`; ``d``: scratch, shape (k + 1, 2))."""
    n = c.shape[0]
    x = min(max(x, t[k]), t[n])
    j = np.searchsorted(t, x, side="right") - 1
    j = min(max(j, k), n - 1)
    for i in range(k + 1):
        d[i, 0] = c[j - k + i, 0]
        d[i, 1] = c[j - k + i, 1]
    for r in range(1, k + 1):
        for i in range(k, r - 1, -1):
            left = t[j - k + i]
            alpha = (x - left) / (t[j + 1 + i - r] - left)
            d[i, 0] = (1.0 - alpha) * d[i - 1, 0] + alpha * d[i, 0]
            d[i, 1] = (1.0 - alpha) * d[i - 1, 1] + alpha * d[i, 1]
    return math.hypot(d[k, 0], d[k, 1])


@njit(cache=True)
def arc_newton(t1, c1, k1, nodes, s_nodes, s, u, lo, hi, gl_x, gl_w):  # pragma: no cover - compiled
    """Refine the parameters ``u`` (in place) at arc lengths ``s`` by Newton steps on the quadrature.

    Each point: up to 6 steps ``u -= (s(u) - s) / |C'(u)|`` clipped to ``[lo, hi]``, stopping
    after a step of at most ``1e-9 (hi - lo)`` (NaN where ``s`` or the guess is NaN); ``s(u)`` is the arc-length table's node below
    ``u`` plus 5-point Gauss-Legendre quadrature of ``|C'|`` from it (as
    :meth:`ParametricCurve.s_at_u`). The same arithmetic as the vectorised
    :meth:`ParametricCurve.refine_u_at_s`; the quadrature's weighted sum is taken in the
    order numpy's matrix product takes it on OpenBLAS's AVX-512 kernel (bit-identical
    there; elsewhere the two can differ in the last bit).

    Parameters
    ----------
    t1 : ndarray, shape (m + k1 + 1,)
        Knots of the curve's derivative ``C'``.
    c1 : ndarray, shape (m, 2)
        Its control points (m per unit of ``u``).
    k1 : int
        Its degree (the curve's minus one).
    nodes, s_nodes : ndarray, shape (q,)
        The arc-length table: parameters and arc lengths (m) at them.
    s : ndarray, shape (n,)
        Target arc lengths (m).
    u : ndarray, shape (n,)
        First guesses, overwritten by the refined parameters.
    lo, hi : float
        The domain.
    gl_x, gl_w : ndarray, shape (5,)
        Gauss-Legendre nodes on ``[-1, 1]`` and weights.
    """
    d = np.empty((k1 + 1, 2))
    v = np.empty(5)
    tol = 1e-9 * (hi - lo)
    last = nodes.shape[0] - 2
    for q in range(u.shape[0]):
        x = u[q]
        if not (x == x and s[q] == s[q]):
            u[q] = np.nan
            continue
        for _ in range(6):
            sp = _speed_at(t1, c1, k1, x, d)
            uu = min(max(x, nodes[0]), nodes[-1])
            i = min(max(np.searchsorted(nodes, uu, side="right") - 1, 0), last)
            a = nodes[i]
            half = 0.5 * (uu - a)
            mid = 0.5 * (a + uu)
            for g in range(5):
                v[g] = _speed_at(t1, c1, k1, mid + half * gl_x[g], d)
            acc = (v[0] * gl_w[0] + v[2] * gl_w[2]) + (v[1] * gl_w[1] + v[3] * gl_w[3])
            err = (s_nodes[i] + half * _fma(v[4], gl_w[4], acc)) - s[q]
            step = err / sp if sp > 0 else 0.0
            x = min(max(x - step, lo), hi)
            if not abs(step) > tol:
                break
        u[q] = x


@njit(cache=True)
def de_boor(t, c, k, u):  # pragma: no cover - compiled
    """Evaluate the spline ``(t, c, k)`` with de Boor's algorithm.

    Parameters
    ----------
    t : ndarray of float64, shape (n + k + 1,)
        Non-decreasing knots (contiguous, as every array here: the function is compiled).
    c : ndarray, shape (n, d)
        Control points.
    k : int
        Degree (>= 0).
    u : ndarray, shape (m,)
        Parameters; those outside the domain ``[t[k], t[n]]`` are clamped to it (the last
        span is closed on the right).

    Returns
    -------
    ndarray, shape (m, d)
        NaN rows where ``u`` is NaN.
    """
    n, dim = c.shape
    out = np.empty((u.shape[0], dim))
    d = np.empty((k + 1, dim))
    lo = t[k]
    hi = t[n]
    for q in range(u.shape[0]):
        x = u[q]
        if not x == x:
            out[q, :] = np.nan
            continue
        x = min(max(x, lo), hi)
        j = np.searchsorted(t, x, side="right") - 1
        j = min(max(j, k), n - 1)
        for i in range(k + 1):
            for a in range(dim):
                d[i, a] = c[j - k + i, a]
        for r in range(1, k + 1):
            for i in range(k, r - 1, -1):
                left = t[j - k + i]
                alpha = (x - left) / (t[j + 1 + i - r] - left)
                for a in range(dim):
                    d[i, a] = (1.0 - alpha) * d[i - 1, a] + alpha * d[i, a]
        for a in range(dim):
            out[q, a] = d[k, a]
    return out


@njit(cache=True)
def arc_pose(
    t, c, k, t1, c1, nodes, s_nodes, grid_s, grid_u, lo, hi, gl_x, gl_w, s
):  # pragma: no cover - compiled
    """Return the position, tangent and parameter of the spline ``(t, c, k)`` at arc lengths ``s``.

    Each parameter: ``numpy.interp(s, grid_s, grid_u)`` (its floats: the table's value at
    or beyond its ends and at its nodes, else ``slope (s - s_j) + u_j``, then
    ``slope (s - s_{j+1}) + u_{j+1}`` if that is NaN, then ``u_j`` if the two values
    are equal), refined by :func:`arc_newton`; the position and the tangent by
    :func:`de_boor` on the spline and on its derivative ``(t1, c1, k - 1)``. The same floats
    as ``numpy.interp``, :meth:`BSplineCurve.refine_u_at_s` and :meth:`BSplineCurve.__call__`
    one after another.

    Parameters
    ----------
    t, c, k : ndarray, ndarray, int
        The spline: knots, shape (n + k + 1,); control points (m), shape (n, 2); degree.
    t1, c1 : ndarray
        Its derivative's knots and control points (m per unit of ``u``).
    nodes, s_nodes : ndarray, shape (q,)
        Its arc-length table (parameters, arc lengths in m).
    grid_s, grid_u : ndarray, shape (g,)
        The first guesses' table (arc lengths in m, non-decreasing; parameters), ``g >= 2``.
    lo, hi : float
        The domain.
    gl_x, gl_w : ndarray, shape (5,)
        Gauss-Legendre nodes on ``[-1, 1]`` and weights.
    s : ndarray, shape (m,)
        Arc lengths (m).

    Returns
    -------
    ndarray, shape (m, 5)
        ``x, y`` (m), ``x', y'`` (m per unit of ``u``) and ``u`` per row (NaN where ``s`` is NaN).
    """
    m = s.shape[0]
    g = grid_s.shape[0]
    u = np.empty(m)
    for q in range(m):
        x = s[q]
        if x != x:
            u[q] = x
            continue
        if x < grid_s[0]:
            u[q] = grid_u[0]
            continue
        if x > grid_s[g - 1]:
            u[q] = grid_u[g - 1]
            continue
        j = np.searchsorted(grid_s, x, side="right") - 1
        if j >= g - 1 or grid_s[j] == x:
            u[q] = grid_u[j]
            continue
        slope = (grid_u[j + 1] - grid_u[j]) / (grid_s[j + 1] - grid_s[j])
        r = slope * (x - grid_s[j]) + grid_u[j]
        if r != r:
            r = slope * (x - grid_s[j + 1]) + grid_u[j + 1]
            if r != r and grid_u[j] == grid_u[j + 1]:
                r = grid_u[j]
        u[q] = r
    arc_newton(t1, c1, k - 1, nodes, s_nodes, s, u, lo, hi, gl_x, gl_w)
    xy = de_boor(t, c, k, u)
    d = de_boor(t1, c1, k - 1, u)
    out = np.empty((m, 5))
    for q in range(m):
        out[q, 0] = xy[q, 0]
        out[q, 1] = xy[q, 1]
        out[q, 2] = d[q, 0]
        out[q, 3] = d[q, 1]
        out[q, 4] = u[q]
    return out


def clamped_uniform_knots(n: int, k: int, domain: tuple[float, float] = (0.0, 1.0)) -> np.ndarray:
    """Clamped knot vector with uniform interior knots.

    Parameters
    ----------
    n : int
        Number of control points (>= k + 1).
    k : int
        Degree.
    domain : tuple of float
        ``(u0, u1)``.

    Returns
    -------
    ndarray, shape (n + k + 1,)
    """
    if n < k + 1:
        raise InvalidInputError(f"need n >= k + 1 = {k + 1} control points, got {n}")
    a, b = domain
    interior = np.linspace(a, b, n - k + 1)
    return np.concatenate([np.full(k, a), interior, np.full(k, b)])
