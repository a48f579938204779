"""Planar B-spline curves ``(t, c, k)`` evaluated through :class:`scipy.interpolate.BSpline`."""

from __future__ import annotations

import numpy as np

from trajopt.curve import ParametricCurve
from trajopt.errors import InvalidInputError

__all__ = ["BSplineCurve", "clamped_uniform_knots"]


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

    __slots__ = ("t", "c", "k", "_spline", "_arc_cache")

    def __init__(self, t: np.ndarray, c: np.ndarray, k: int) -> None:
        from scipy.interpolate import BSpline

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
        self._spline = BSpline(t, c, k, extrapolate=True)

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
        lo, hi = self.domain
        uu = np.clip(np.asarray(u, dtype=float), lo, hi)
        if nu > self.k:
            return np.zeros(uu.shape + (2,))
        return self._spline(uu, nu)

    def derivative(self, nu: int = 1) -> BSplineCurve:
        """Return the ``nu``-th derivative as a new B-spline of degree ``k - nu``."""
        if not 1 <= nu < self.k:
            raise InvalidInputError(f"nu must be in [1, k-1] = [1, {self.k - 1}], got {nu}")
        return BSplineCurve.from_scipy(self._spline.derivative(nu))

    def span_of(self, u: np.ndarray | float) -> np.ndarray:
        """Index ``j`` of the non-empty span holding ``u`` (control points ``c[j:j+k+1]``)."""
        n = self.c.shape[0]
        uu = np.clip(np.asarray(u, dtype=float), *self.domain)
        j = np.searchsorted(self.t, uu, side="right") - 1
        return np.clip(j, self.k, n - 1) - self.k

    def __repr__(self) -> str:
        return f"BSplineCurve(k={self.k}, n={self.c.shape[0]}, domain={self.domain})"


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
