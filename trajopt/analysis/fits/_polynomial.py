"""Polynomial fits of path points.

``y = f(x)`` as the chapter fits them, and the parametric ``x(u), y(u)`` that handles any path
shape.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.polynomial import chebyshev as _cheb

import trajopt.validation as validation
from trajopt.analysis.fits._bspline_fit import PARAMETERIZATIONS, Parameterization, curve_parameters
from trajopt.analysis.fits._curves import ParametricPolynomialCurve, PolynomialCurve
from trajopt.analysis.fits._records import PolynomialFit
from trajopt.analysis.fits._robust import FIT_METHODS, FitMethod, solve
from trajopt.errors import InvalidInputError


def fit_polynomial(
    points: np.ndarray,
    order: int,
    *,
    method: FitMethod = "least_squares",
    weights: np.ndarray | None = None,
    tol: float = 1e-4,
    max_iter: int = 50,
) -> PolynomialFit:
    """Fit ``y = f(x)`` of order ``order`` to path points, as the chapter does.

    Parameters
    ----------
    points : array_like, shape (n, 2)
        Path points in metres (e.g. A* cell centres), in path order.
    order : int
        Polynomial order ``m`` (1..30); needs ``n >= m + 1``.
    method : {'least_squares', 'lar', 'bisquare'}
        Least squares; least absolute residual (exact, linear programme); bisquare
        (robust iteratively reweighted least squares, the recipe of MATLAB's
        ``robustfit``): starting from least squares, every iteration takes the residuals
        ``r_i``, adjusts them for leverage, ``r_adj_i = r_i / sqrt(1 - h_i)`` (``h_i``:
        diagonal of the hat matrix of the weighted design, at most 0.9999), estimates the
        scale ``s = MAD / 0.6745`` where ``MAD`` is the median of ``|r_adj_i|`` about
        **zero** over the points with positive weight after dropping the ``p - 1``
        smallest (``p = order + 1``; never below ``1e-6 * std(y)``), and refits with
        weights ``w_i (1 - u_i^2)^2`` for ``|u_i| < 1`` (else 0), ``u_i = r_adj_i / (4.685
        s)``. Without outliers it is close to least squares (95 % Gaussian efficiency).
    weights : array_like, shape (n,), optional
        Non-negative per-point weights on the residuals (``w_i`` on ``r_i^2`` for least
        squares and bisquare, on ``|r_i|`` for LAR).
    tol : float
        Bisquare stops when the fitted values change by less than ``tol`` times their
        magnitude (default 1e-4, the chapter's tolerance).
    max_iter : int
        Bisquare iteration cap; a fit that has not met ``tol`` by then (a redescending
        weight function can cycle between two weight patterns) is returned with
        ``converged=False`` and ``valid=False``.

    Returns
    -------
    PolynomialFit
        ``valid=False`` with a ``reason`` when x is not strictly monotone along the path
        (a backward or vertical step); ``curve`` is then still the fit of the data (which
        is what the chapter's method produces) unless x has no spread (``curve=None``).
        Never raises for the shape of the path; raises :class:`InvalidInputError` for bad
        arguments.
    """
    p = validation.points("points", points)
    m = validation.integer("order", order, 1, 30)
    method = validation.choice("method", method, FIT_METHODS)
    tol_f = validation.positive("tol", tol)
    max_it = validation.integer("max_iter", max_iter, 1)
    n = len(p)
    if n < m + 1:
        raise InvalidInputError(f"order {m} needs at least order + 1 = {m + 1} points, got {n}")
    w = validation.weights("weights", weights, n, positive=False)
    x, y = p[:, 0], p[:, 1]
    extent = max(float(np.ptp(x)), float(np.ptp(y)), 1e-300)
    lo, hi = float(x.min()), float(x.max())
    if x[-1] != x[0]:
        x_end = float(x[-1])
    else:  # a closed excursion in x: run towards the farther extreme
        x_end = hi if hi - x[0] >= x[0] - lo else lo
    direction = 1.0 if x_end >= x[0] else -1.0
    dx = direction * np.diff(x)
    n_back = int(np.count_nonzero(dx <= 0))
    if np.ptp(x) <= 1e-9 * extent:
        reason = "x has no spread (vertical path): y = f(x) does not exist"
        return PolynomialFit(
            curve=None,
            method=method,
            order=m,
            valid=False,
            reason=reason,
            params=direction * x,
            residuals=np.full((n, 2), np.nan),
            weights=w,
            mse=math.inf,
            n_backtracks=n_back,
        )
    reasons = []
    if x[-1] == x[0]:
        reasons.append("path starts and ends at the same x")
    if n_back:
        reasons.append(
            f"not a function y = f(x): {n_back} of {n - 1} steps go back in x or are vertical"
        )
    distinct = len(np.unique(x[w > 0]))
    if distinct < m + 1:
        reasons.append(f"only {distinct} distinct x values for order {m} (needs {m + 1})")
    t = (2.0 * x - (lo + hi)) / (hi - lo)
    vand = _cheb.chebvander(t, m)
    coef, robust, iters, conv = solve(vand, y[:, None], w, method, tol_f, max_it)
    series = _cheb.Chebyshev(coef[:, 0], domain=[lo, hi])
    curve = PolynomialCurve(series, float(x[0]), x_end)
    fitted = series(x)
    res = np.stack([np.zeros(n), fitted - y], axis=1)
    if not conv:
        reasons.append(f"bisquare did not converge in {max_it} iterations (tol {tol_f:g})")
    return PolynomialFit(
        curve=curve,
        method=method,
        order=m,
        valid=not reasons,
        reason="; ".join(reasons),
        params=direction * x,
        residuals=res,
        weights=w * robust,
        mse=float(np.mean(np.sum(res * res, axis=1))),
        iterations=iters,
        converged=conv,
        n_backtracks=n_back,
    )


def fit_polynomial_parametric(
    points: np.ndarray,
    order: int,
    *,
    method: FitMethod = "least_squares",
    parameterization: Parameterization = "chord",
    weights: np.ndarray | None = None,
    tol: float = 1e-4,
    max_iter: int = 50,
) -> PolynomialFit:
    """Fit ``x(u)`` and ``y(u)`` as polynomials of order ``order`` (improvement, any shape).

    Parameters are those of :func:`fit_polynomial` plus ``parameterization`` (how the data
    parameters ``u_i`` in [0, 1] are chosen, see :func:`curve_parameters`). LAR minimises
    ``sum w_i (|r_x| + |r_y|)``; bisquare weights use the Euclidean residual.

    Returns
    -------
    PolynomialFit
        With a :class:`ParametricPolynomialCurve`; ``valid`` is ``True`` unless the
        bisquare iteration did not converge.
    """
    p = validation.points("points", points)
    m = validation.integer("order", order, 1, 30)
    method = validation.choice("method", method, FIT_METHODS)
    parameterization = validation.choice("parameterization", parameterization, PARAMETERIZATIONS)
    tol_f = validation.positive("tol", tol)
    max_it = validation.integer("max_iter", max_iter, 1)
    n = len(p)
    if n < m + 1:
        raise InvalidInputError(f"order {m} needs at least order + 1 = {m + 1} points, got {n}")
    w = validation.weights("weights", weights, n, positive=False)
    u = curve_parameters(p, parameterization)
    vand = _cheb.chebvander(2.0 * u - 1.0, m)
    coef, robust, iters, conv = solve(vand, p, w, method, tol_f, max_it)
    curve = ParametricPolynomialCurve(coef)
    res = vand @ coef - p
    reason = "" if conv else f"bisquare did not converge in {max_it} iterations (tol {tol_f:g})"
    return PolynomialFit(
        curve=curve,
        method=method,
        order=m,
        valid=conv,
        reason=reason,
        params=u,
        residuals=res,
        weights=w * robust,
        mse=float(np.mean(np.sum(res * res, axis=1))),
        iterations=iters,
        converged=conv,
    )
