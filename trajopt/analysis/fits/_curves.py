"""The curves the plain fits return: polynomials as planar curves, and the fitted B-spline.

All follow :class:`trajopt.geometry._curve.ParametricCurve` (position, derivatives, heading,
curvature, arc length, dense sampling).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.polynomial import chebyshev as _cheb

from trajopt.errors import InvalidInputError
from trajopt.geometry import BSplineCurve, ParametricCurve


class PolynomialCurve(ParametricCurve):
    """A polynomial ``y = f(x)`` seen as a planar curve, parameter ``u = direction * x``.

    ``direction`` is +1 when the fitted path runs towards larger x and -1 otherwise, so
    that ``u`` always increases from the path's start to its end; for the usual +1 case
    ``u = x`` (metres).

    Parameters
    ----------
    series : numpy.polynomial.Chebyshev
        ``f`` as a Chebyshev series whose ``domain`` is the data's x range (m -> m).
    x_start, x_end : float
        x of the first and last fitted point (m), ``x_start != x_end``.
    """

    __slots__ = ("series", "x_start", "x_end", "direction", "_derivs", "_arc_cache")

    def __init__(self, series: _cheb.Chebyshev, x_start: float, x_end: float) -> None:
        if not (math.isfinite(x_start) and math.isfinite(x_end)) or x_start == x_end:
            raise InvalidInputError(
                f"x_start and x_end must be finite and differ, got {x_start!r}, {x_end!r}"
            )
        self.series = series
        self.x_start = float(x_start)
        self.x_end = float(x_end)
        self.direction = 1.0 if x_end > x_start else -1.0
        self._derivs: dict[int, _cheb.Chebyshev] = {0: series}

    @property
    def order(self) -> int:
        """Polynomial order ``m``."""
        return int(self.series.degree())

    @property
    def polynomial_degree(self) -> int:
        """Degree of the polynomial pieces (the curvature bound uses it)."""
        return max(self.order, 1)

    @property
    def domain(self) -> tuple[float, float]:
        """Parameter interval ``(u0, u1)`` of the curve."""
        return (self.direction * self.x_start, self.direction * self.x_end)

    def f(self, x: np.ndarray | float, nu: int = 0) -> np.ndarray:
        """``f^(nu)(x)`` (``nu``-th derivative w.r.t. x), vectorised."""
        d = self._derivs.get(nu)
        if d is None:
            d = self.series.deriv(nu)
            self._derivs[nu] = d
        return d(np.asarray(x, dtype=float))

    def __call__(self, u: np.ndarray | float, nu: int = 0) -> np.ndarray:
        """``(x, f(x))`` or its ``nu``-th derivative w.r.t. ``u``; shape ``u.shape + (2,)``."""
        lo, hi = self.domain
        uu = np.clip(np.asarray(u, dtype=float), lo, hi)
        x = self.direction * uu
        if nu == 0:
            return np.stack([x, self.f(x)], axis=-1)
        xd = np.full_like(x, self.direction if nu == 1 else 0.0)
        return np.stack([xd, self.direction**nu * self.f(x, nu)], axis=-1)

    def __repr__(self) -> str:
        return f"PolynomialCurve(order={self.order}, x=[{self.x_start:g}, {self.x_end:g}])"


class ParametricPolynomialCurve(ParametricCurve):
    """Polynomials ``x(u), y(u)`` on ``u in [0, 1]`` (Chebyshev series, metres).

    Parameters
    ----------
    coef : array_like, shape (m + 1, 2)
        Chebyshev coefficients of ``x`` and ``y`` in the variable ``2u - 1``.
    """

    __slots__ = ("coef", "_derivs", "_arc_cache")

    def __init__(self, coef: np.ndarray) -> None:
        c = np.array(coef, dtype=float)
        if c.ndim != 2 or c.shape[1] != 2 or c.shape[0] < 1:
            raise InvalidInputError(f"coef must have shape (m + 1, 2), got {c.shape}")
        c.flags.writeable = False
        self.coef = c
        self._derivs: dict[int, np.ndarray] = {0: c}

    @property
    def order(self) -> int:
        """Polynomial order ``m``."""
        return int(self.coef.shape[0] - 1)

    @property
    def polynomial_degree(self) -> int:
        """Degree of the polynomial pieces (the curvature bound uses it)."""
        return max(self.order, 1)

    @property
    def domain(self) -> tuple[float, float]:
        """Parameter interval ``(u0, u1)`` of the curve."""
        return (0.0, 1.0)

    def __call__(self, u: np.ndarray | float, nu: int = 0) -> np.ndarray:
        """Evaluate the ``nu``-th derivative at ``u``, shape ``(..., 2)``."""
        uu = np.clip(np.asarray(u, dtype=float), 0.0, 1.0)
        c = self._derivs.get(nu)
        if c is None:
            # d/du = 2 d/dt for t = 2u - 1
            c = _cheb.chebder(self.coef, nu, scl=2.0, axis=0) if nu <= self.order else None
            if c is None:
                c = np.zeros((1, 2))
            self._derivs[nu] = c
        t = 2.0 * uu - 1.0
        return np.moveaxis(_cheb.chebval(t, c), 0, -1)

    def __repr__(self) -> str:
        return f"ParametricPolynomialCurve(order={self.order})"


class FittedBSpline(BSplineCurve):
    """A :class:`~trajopt.geometry._bspline.BSplineCurve` fitted to data, with its fit record.

    Attributes
    ----------
    params : ndarray, shape (n,)
        Parameter ``u_i`` of every data point (read-only), in ``[0, 1]``.
    residuals : ndarray, shape (n, 2)
        ``C(u_i) - Q_i`` (m, read-only).
    mse : float
        Equation (3) with unit weights divided by ``n``: ``mean_i |C(u_i) - Q_i|^2`` (m^2).
    parameterization : str
        ``'uniform'``, ``'chord'`` or ``'centripetal'``.
    """

    __slots__ = ("params", "residuals", "mse", "parameterization")

    def __repr__(self) -> str:
        return (
            f"FittedBSpline(k={self.k}, n_ctrl={self.c.shape[0]}, "
            f"parameterization={self.parameterization!r}, mse={self.mse:.3g})"
        )
