"""Plain fits of A* points: the chapter's baselines.

Two families, both returning objects that follow :class:`trajopt.curve.ParametricCurve`
(position, derivatives, heading, curvature, arc length, dense sampling):

* **Polynomial** ``y = f(x)`` of order ``m`` (:func:`fit_polynomial`), as the chapter fits
  the A* points, with its three fitting methods: ``'least_squares'``, ``'lar'`` (least
  absolute residual, solved exactly as a linear programme with
  :func:`scipy.optimize.linprog`) and ``'bisquare'`` (iteratively reweighted least squares
  as MATLAB's ``robustfit``: Tukey bisquare weights with ``c = 4.685`` on leverage-adjusted
  residuals ``r_i / sqrt(1 - h_i)``, scaled by ``MAD / 0.6745`` with the MAD taken about
  zero after dropping the ``p - 1`` smallest, stopping at a relative change below
  ``tol = 1e-4``; see :func:`fit_polynomial`). Its weakness is kept honest: a path that goes back
  in x, or has a vertical step, is not a function ``y = f(x)``; the fit is still computed
  when x has a spread, but the result carries ``valid=False`` and a ``reason``. When x has
  no spread at all (a vertical path) no function exists and ``curve`` is ``None``.
  :func:`fit_polynomial_parametric` is the improvement the chapter does not make: ``x(u)``
  and ``y(u)`` fitted separately against a chord-length (or other) parameter ``u``; it
  handles any path shape.
* **B-spline** least-squares fit (:func:`fit_bspline`): clamped, degree ``k``, ``n_ctrl``
  control points on uniform interior knots, data parameters ``'uniform'``, ``'chord'`` or
  ``'centripetal'``, solved by :func:`scipy.interpolate.make_lsq_spline`. It minimises the
  chapter's equation (3), ``sum_i w_i |C(u_i) - Q_i|^2``; the end points are *not* forced
  onto the data (as in the chapter's Table 2). A system the data cannot determine (the
  Schoenberg-Whitney condition fails, or the collocation matrix is numerically singular,
  condition number above :data:`BSPLINE_COND_MAX`) raises :class:`InvalidInputError`
  instead of returning a diverged curve.

Parameter sweeps as the chapter's Tables 1 and 2 (:func:`sweep_polynomial`: 3 methods x 10
orders; :func:`sweep_bspline`: 3 parameterisations x 4 degrees x 42 control-point counts =
504) rank every combination by the MSE of equation (3) at the fitted parameters; the
``kwargs`` of the best record are reused unchanged on other targets.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.polynomial import chebyshev as _cheb

from trajopt.bspline import BSplineCurve, clamped_uniform_knots
from trajopt.curve import ParametricCurve
from trajopt.errors import IllPosedFitError, InvalidInputError

__all__ = [
    "FIT_METHODS",
    "PARAMETERIZATIONS",
    "BSPLINE_COND_MAX",
    "PolynomialCurve",
    "ParametricPolynomialCurve",
    "PolynomialFit",
    "FittedBSpline",
    "SweepRecord",
    "fit_polynomial",
    "fit_polynomial_parametric",
    "fit_bspline",
    "curve_parameters",
    "sweep_polynomial",
    "sweep_bspline",
]

logger = logging.getLogger(__name__)


FitMethod = Literal["least_squares", "lar", "bisquare"]
Parameterization = Literal["uniform", "chord", "centripetal"]

FIT_METHODS: tuple[str, ...] = ("least_squares", "lar", "bisquare")
PARAMETERIZATIONS: tuple[str, ...] = ("uniform", "chord", "centripetal")

#: Tukey bisquare tuning constant (95% efficiency for Gaussian residuals).
BISQUARE_C = 4.685
#: ``MAD / 0.6745`` estimates the standard deviation of Gaussian residuals (MATLAB's value
#: of the normal quartile ``Phi^-1(3/4) = 0.67449``).
_MAD_NORMAL = 0.6745
#: Largest 2-norm condition number of the B-spline collocation matrix ``A_ji = B_i(u_j)``
#: that :func:`fit_bspline` accepts; above it the matrix counts as numerically singular.
#: The A* points are cell centres: they locate a path to half a cell, a relative accuracy
#: of ``1e-4`` or coarser for paths of up to a few thousand cells. With ``cond(A) > 1e4``
#: that uncertainty alone can change the control points by more than their own size (the
#: least-squares error bound is ``cond(A)`` times the relative data error): ``A`` is rank
#: deficient at the data's accuracy (its numerical rank with ``rcond = 1e-4``, as
#: :func:`numpy.linalg.lstsq` counts it, is below ``n_ctrl``). Well-posed designs of every
#: allowed degree stay far below (dense uniform sites: about 2 for degree 1, 5 for degree
#: 3, 100-850 for degree 9; the paper scene's sweeps at most 21). Below the threshold a
#: near-interpolating fit can still swing away from the data between the points (on random
#: 38-40-point staircases the largest excursion was roughly 0.1-0.3 cond cells); the
#: comparison's Hausdorff and clearance metrics show that.
BSPLINE_COND_MAX = 1e4
#: Default polynomial orders of the sweep (Table 1: 3 methods x 10 orders).
SWEEP_ORDERS: tuple[int, ...] = tuple(range(1, 11))
#: Default B-spline degrees and control-point counts of the sweep (Table 2: 3 x 4 x 42).
SWEEP_DEGREES: tuple[int, ...] = (2, 3, 4, 5)
SWEEP_N_CTRL: tuple[int, ...] = tuple(range(6, 48))


# ============================================================================ curves
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
        return max(self.order, 1)

    @property
    def domain(self) -> tuple[float, float]:
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
        return max(self.order, 1)

    @property
    def domain(self) -> tuple[float, float]:
        return (0.0, 1.0)

    def __call__(self, u: np.ndarray | float, nu: int = 0) -> np.ndarray:
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
    """A :class:`~trajopt.bspline.BSplineCurve` fitted to data, with its fit record.

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


# ============================================================================ records
@dataclass(frozen=True, slots=True)
class PolynomialFit:
    """Result of :func:`fit_polynomial` or :func:`fit_polynomial_parametric`.

    Attributes
    ----------
    curve : PolynomialCurve or ParametricPolynomialCurve or None
        The fitted curve; ``None`` only when no function ``y = f(x)`` exists at all (the
        data's x spread is below ``1e-9`` of its extent, i.e. a vertical path).
    method : str
        Fitting method.
    order : int
        Polynomial order ``m``.
    valid : bool
        ``False`` when the data is not a function of the fitted variable (x goes back or
        repeats: a vertical step or section) or no curve exists; see ``reason``.
    reason : str
        Why the fit is invalid (empty when valid).
    params : ndarray, shape (n,)
        Fitted parameter of each data point: ``u_i = direction * x_i`` for ``y = f(x)``,
        ``u_i`` in [0, 1] for the parametric fit (read-only).
    residuals : ndarray, shape (n, 2)
        ``curve(params) - points`` (m); for ``y = f(x)`` only the y column is non-zero.
    weights : ndarray, shape (n,)
        Final weights (user weights times the bisquare weights of the last iteration;
        0 for the points the bisquare fit rejects as outliers).
    mse : float
        ``mean_i |residual_i|^2`` (m^2): equation (3) at the fitted parameters with unit
        weights; ``inf`` when ``curve`` is ``None``.
    iterations : int
        Reweighting iterations (0 for least squares and LAR).
    converged : bool
        Whether the iteration met ``tol`` (always ``True`` for least squares and LAR).
    n_backtracks : int
        Number of consecutive point pairs whose x does not advance in the path's direction.
    """

    curve: PolynomialCurve | ParametricPolynomialCurve | None
    method: str
    order: int
    valid: bool
    reason: str
    params: np.ndarray
    residuals: np.ndarray
    weights: np.ndarray
    mse: float
    iterations: int = 0
    converged: bool = True
    n_backtracks: int = 0

    def __post_init__(self) -> None:
        for name in ("params", "residuals", "weights"):
            a = np.array(getattr(self, name), dtype=float)
            a.flags.writeable = False
            object.__setattr__(self, name, a)


@dataclass(frozen=True, slots=True)
class SweepRecord:
    """One combination of a parameter sweep.

    Attributes
    ----------
    kind : str
        ``'polynomial'`` or ``'bspline'``.
    params : dict
        Keyword arguments that reproduce the fit (``method``/``order`` or
        ``parameterization``/``degree``/``n_ctrl``); pass as ``**record.kwargs``.
    mse : float
        Equation (3) at the fitted parameters (m^2); ``inf`` when the fit failed.
    valid : bool
        Fit usable (a polynomial fit of non-function data is ``False``).
    reason : str
        Why not valid or why it failed.
    rank : int
        1-based rank by MSE within the sweep (valid fits before invalid ones).
    """

    kind: str
    params: dict[str, Any] = field(default_factory=dict)
    mse: float = math.inf
    valid: bool = True
    reason: str = ""
    rank: int = 0

    @property
    def kwargs(self) -> dict[str, Any]:
        """A fresh copy of :attr:`params` for ``fit_*(points, **kwargs)``."""
        return dict(self.params)

    def as_dict(self) -> dict[str, Any]:
        """Flat dict: ``kind``, every parameter, ``mse``, ``valid``, ``reason``, ``rank``."""
        return {
            "kind": self.kind,
            **self.params,
            "mse": self.mse,
            "valid": self.valid,
            "reason": self.reason,
            "rank": self.rank,
        }


# ============================================================================ validation
def _as_points(points: object, *, min_points: int = 2) -> np.ndarray:
    p = np.asarray(points, dtype=float) if not hasattr(points, "cells") else None
    if p is None:
        raise InvalidInputError(
            "points must be world coordinates (m), shape (n, 2); convert a GridPath with "
            "grid.cell_to_world(path.cells)"
        )
    if p.ndim != 2 or p.shape[1] != 2:
        raise InvalidInputError(f"points must have shape (n, 2), got {p.shape}")
    if len(p) < min_points:
        raise InvalidInputError(f"points must hold at least {min_points} points, got {len(p)}")
    if not np.all(np.isfinite(p)):
        raise InvalidInputError("points must be finite")
    return p


def _as_weights(weights: object, n: int, *, positive: bool) -> np.ndarray:
    if weights is None:
        return np.ones(n)
    w = np.asarray(weights, dtype=float)
    if w.shape != (n,):
        raise InvalidInputError(f"weights must have shape ({n},) (one per point), got {w.shape}")
    if not np.all(np.isfinite(w)):
        raise InvalidInputError("weights must be finite")
    if positive and np.any(w <= 0):
        raise InvalidInputError(f"weights must be > 0, got min {w.min()!r}")
    if np.any(w < 0):
        raise InvalidInputError(f"weights must be >= 0, got min {w.min()!r}")
    if not np.any(w > 0):
        raise InvalidInputError("weights must not all be zero")
    return w


def _check_choice(value: object, name: str, choices: Sequence[str]) -> str:
    if not isinstance(value, str) or value not in choices:
        raise InvalidInputError(f"{name} must be one of {list(choices)}, got {value!r}")
    return value


def _check_int(value: object, name: str, lo: int, hi: int | None = None) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise InvalidInputError(f"{name} must be an integer, got {value!r}")
    v = int(value)
    if v < lo or (hi is not None and v > hi):
        rule = f">= {lo}" if hi is None else f"in [{lo}, {hi}]"
        raise InvalidInputError(f"{name} must be {rule}, got {v}")
    return v


def _check_tol(tol: object, max_iter: object) -> tuple[float, int]:
    try:
        t = float(tol)  # type: ignore[arg-type]
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(f"tol must be a number, got {tol!r}") from exc
    if not (math.isfinite(t) and t > 0):
        raise InvalidInputError(f"tol must be finite and > 0, got {t!r}")
    return t, _check_int(max_iter, "max_iter", 1)


# ============================================================================ solvers
def _wls(v: np.ndarray, y: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Weighted least squares ``min sum_i w_i |y_i - V_i c|^2``; ``y`` shape (n, d)."""
    sw = np.sqrt(w)[:, None]
    coef, *_ = np.linalg.lstsq(sw * v, sw * y, rcond=None)
    return coef


def _lar(v: np.ndarray, y: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Least absolute residual ``min sum_i w_i |y_i - V_i c|`` per column, as an LP."""
    from scipy.optimize import linprog
    from scipy.sparse import csr_array, hstack, identity, vstack

    n, p = v.shape
    keep = w > 0
    vk, wk = v[keep], w[keep]
    nk = len(wk)
    eye = identity(nk, format="csr")
    vs = csr_array(vk)
    # variables [c (free, p), t (>= 0, nk)]:  V c - t <= y,  -V c - t <= -y
    a_ub = vstack([hstack([vs, -eye]), hstack([-vs, -eye])]).tocsr()
    cost = np.concatenate([np.zeros(p), wk])
    bounds = [(None, None)] * p + [(0, None)] * nk
    out = np.empty((p, y.shape[1]))
    for j in range(y.shape[1]):
        yk = y[keep, j]
        res = linprog(
            cost, A_ub=a_ub, b_ub=np.concatenate([yk, -yk]), bounds=bounds, method="highs"
        )
        if res.status != 0:
            logger.warning("LAR linear programme: %s; falling back to least squares", res.message)
            out[:, j] = _wls(v, y[:, [j]], w)[:, 0]
        else:
            out[:, j] = res.x[:p]
    return out


def _bisquare(
    v: np.ndarray,
    y: np.ndarray,
    w: np.ndarray,
    tol: float,
    max_iter: int,
    *,
    leverage: bool = True,
) -> tuple[np.ndarray, np.ndarray, int, bool]:
    """Robust IRLS with Tukey bisquare weights, as MATLAB's ``robustfit`` (``'bisquare'``).

    Starting from the (user-weighted) least-squares fit, each iteration computes

    * residuals ``r_i = y_i - V_i c`` (the Euclidean norm of the row when ``y`` has
      several columns), adjusted for leverage: ``r_adj_i = r_i / sqrt(1 - h_i)``, with
      ``h_i`` the diagonal of the hat matrix of the weighted design ``sqrt(w) V`` (fixed,
      clipped to 0.9999);
    * the scale ``s = max(MAD / 0.6745, s_min)``: ``MAD`` is the median of ``|r_adj_i|``
      (about **zero**, not about the median) over the points with ``w_i > 0`` after
      dropping the ``p - 1`` smallest (``p`` = number of coefficients), as ``robustfit``'s
      ``madsigma``; ``s_min = 1e-6`` times the largest standard deviation of a ``y``
      column (1 when that is 0) keeps an exact fit from dividing by zero;
    * Tukey weights ``b_i = (1 - u_i^2)^2`` for ``|u_i| < 1``, else 0, with
      ``u_i = r_adj_i / (c s)`` and ``c = BISQUARE_C = 4.685``;
    * the weighted least-squares fit with weights ``w_i b_i``;

    and stops when the fitted values move by at most ``tol`` times their largest
    magnitude. ``leverage=False`` (private, for tests) uses ``r_adj_i = r_i``.
    """
    p = v.shape[1]
    coef = _wls(v, y, w)
    active = w > 0
    if leverage:
        # leverages of the weighted design (fixed, as in the usual robust-fit recipe)
        q, _ = np.linalg.qr(np.sqrt(w)[:, None] * v)
        h = np.clip(np.sum(q * q, axis=1), 0.0, 0.9999)
        adj = 1.0 / np.sqrt(1.0 - h)
    else:
        adj = np.ones(len(y))
    spread = float(np.max(np.std(y[active], axis=0)))
    s_min = 1e-6 * spread if spread > 0 else 1.0
    n_drop = min(p, int(np.count_nonzero(active))) - 1
    robust = np.ones(len(y))
    for it in range(1, max_iter + 1):
        fit = v @ coef
        r = y - fit
        r_adj = (np.linalg.norm(r, axis=1) if r.shape[1] > 1 else r[:, 0]) * adj
        mad = float(np.median(np.sort(np.abs(r_adj[active]))[n_drop:]))
        s = max(mad / _MAD_NORMAL, s_min)
        uu = r_adj / (BISQUARE_C * s)
        robust = np.where(np.abs(uu) < 1.0, (1.0 - uu * uu) ** 2, 0.0)
        ww = w * robust
        if np.count_nonzero(ww > 0) < p:
            logger.warning("bisquare: fewer positive weights than coefficients; stopping")
            return coef, robust, it, False
        new = _wls(v, y, ww)
        change = float(np.max(np.abs(v @ (new - coef))))
        coef = new
        if change <= tol * max(float(np.max(np.abs(fit))), 1e-12):
            return coef, robust, it, True
    return coef, robust, max_iter, False


def _solve(
    v: np.ndarray, y: np.ndarray, w: np.ndarray, method: str, tol: float, max_iter: int
) -> tuple[np.ndarray, np.ndarray, int, bool]:
    if method == "least_squares":
        return _wls(v, y, w), np.ones(len(y)), 0, True
    if method == "lar":
        return _lar(v, y, w), np.ones(len(y)), 0, True
    return _bisquare(v, y, w, tol, max_iter)


# ============================================================================ polynomial
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
    p = _as_points(points)
    m = _check_int(order, "order", 1, 30)
    method = _check_choice(method, "method", FIT_METHODS)
    tol_f, max_it = _check_tol(tol, max_iter)
    n = len(p)
    if n < m + 1:
        raise InvalidInputError(f"order {m} needs at least order + 1 = {m + 1} points, got {n}")
    w = _as_weights(weights, n, positive=False)
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
    coef, robust, iters, conv = _solve(vand, y[:, None], w, method, tol_f, max_it)
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
    p = _as_points(points)
    m = _check_int(order, "order", 1, 30)
    method = _check_choice(method, "method", FIT_METHODS)
    parameterization = _check_choice(parameterization, "parameterization", PARAMETERIZATIONS)
    tol_f, max_it = _check_tol(tol, max_iter)
    n = len(p)
    if n < m + 1:
        raise InvalidInputError(f"order {m} needs at least order + 1 = {m + 1} points, got {n}")
    w = _as_weights(weights, n, positive=False)
    u = curve_parameters(p, parameterization)
    vand = _cheb.chebvander(2.0 * u - 1.0, m)
    coef, robust, iters, conv = _solve(vand, p, w, method, tol_f, max_it)
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


# ============================================================================ B-spline
def curve_parameters(points: np.ndarray, parameterization: Parameterization) -> np.ndarray:
    """Data parameters ``u_i`` in [0, 1] for a point sequence.

    Parameters
    ----------
    points : array_like, shape (n, 2)
    parameterization : {'uniform', 'chord', 'centripetal'}
        Equally spaced; cumulative chord length ``|Q_i - Q_{i-1}|``; cumulative
        ``|Q_i - Q_{i-1}|^(1/2)``.

    Returns
    -------
    ndarray, shape (n,)
        Non-decreasing, ``u_0 = 0``, ``u_{n-1} = 1`` (uniform when all points coincide).
    """
    p = _as_points(points)
    kind = _check_choice(parameterization, "parameterization", PARAMETERIZATIONS)
    n = len(p)
    if kind == "uniform":
        return np.linspace(0.0, 1.0, n)
    d = np.hypot(*np.diff(p, axis=0).T)
    if kind == "centripetal":
        d = np.sqrt(d)
    total = float(d.sum())
    if total <= 0:
        return np.linspace(0.0, 1.0, n)
    u = np.concatenate([[0.0], np.cumsum(d)]) / total
    u[-1] = 1.0
    return u


def _dedup(p: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    keep = np.ones(len(p), bool)
    keep[1:] = np.any(np.diff(p, axis=0) != 0, axis=1)
    return p[keep], w[keep]


def _schoenberg_whitney_matches(u: np.ndarray, t: np.ndarray, k: int) -> int:
    """How many B-splines a strictly increasing subsequence of the sites ``u`` can serve.

    Greedy matching: basis function ``B_i`` (``i = 0, 1, ...``) takes the first site after
    the previous one with ``B_i(u_j) != 0``, i.e. ``t_i < u_j < t_{i+k+1}``, the interval
    closed on the left where ``t_i`` is a ``(k + 1)``-fold knot (the clamped start, where
    ``B_0 = 1``) and on the right for the last function at the last knot (the clamped end,
    where ``B_{n-1} = 1``; the last interval is closed). Both ends of the supports are
    non-decreasing in ``i``, so taking the earliest admissible site is optimal: the
    condition holds iff all ``n = len(t) - k - 1`` functions are matched. ``u`` must be
    non-decreasing.
    """
    n = len(t) - k - 1
    m = len(u)
    j = -1  # index of the last site used
    for i in range(n):
        lo, hi = t[i], t[i + k + 1]
        left_closed = t[i] == t[i + k] < hi
        right_closed = i == n - 1 and t[i + 1] == hi
        start = j + 1
        if j >= 0:  # strictly increasing sites
            start = max(start, int(np.searchsorted(u, u[j], side="right")))
        start = max(start, int(np.searchsorted(u, lo, side="left" if left_closed else "right")))
        if start >= m or not (u[start] < hi or (right_closed and u[start] == hi)):
            return i
        j = start
    return n


def _collocation_cond(u: np.ndarray, t: np.ndarray, k: int) -> float:
    """2-norm condition number of ``A_ji = B_i(u_j)``, from the banded Gram matrix.

    ``cond(A) = sqrt(lambda_max / lambda_min)`` of ``A^T A`` (bandwidth ``k``); the squaring
    is harmless up to ``cond(A) ~ 1e7``, far above :data:`BSPLINE_COND_MAX`. ``inf`` when
    ``A^T A`` is not numerically positive definite.
    """
    from scipy.interpolate import BSpline
    from scipy.linalg import LinAlgError, eigvals_banded

    a = BSpline.design_matrix(u, t, k).tocsc()
    g = (a.T @ a).toarray()
    n = g.shape[0]
    band = np.zeros((k + 1, n))
    for d in range(min(k + 1, n)):
        band[d, : n - d] = np.diagonal(g, -d)
    try:
        lam = eigvals_banded(band, lower=True)
    except (LinAlgError, ValueError):
        return math.inf
    lo, hi = float(lam[0]), float(lam[-1])
    return math.sqrt(hi / lo) if lo > 0 and hi > 0 else math.inf


def _design_problem(u: np.ndarray, t: np.ndarray, k: int) -> str:
    """Why the least-squares B-spline on knots ``t`` is ill-posed at sites ``u`` ('' if not)."""
    n = len(t) - k - 1
    matched = _schoenberg_whitney_matches(u, t, k)
    if matched < n:
        return (
            f"the Schoenberg-Whitney condition fails: there are no strictly increasing data "
            f"parameters u_(j_i) with t_i < u_(j_i) < t_(i+k+1) for i = 0..{n - 1} (matching "
            f"each control point to the earliest admissible site runs out at i = {matched}), "
            f"so the least-squares system is singular"
        )
    cond = _collocation_cond(u, t, k)
    if not cond <= BSPLINE_COND_MAX:
        return (
            f"the collocation matrix is numerically singular: cond_2 = {cond:.3g} > "
            f"BSPLINE_COND_MAX = {BSPLINE_COND_MAX:g}, so the control points are not "
            f"determined by the data (they would diverge)"
        )
    return ""


def _supported_n_ctrl(u: np.ndarray, k: int, below: int) -> int:
    """Largest ``n_ctrl < below`` (clamped uniform knots) the sites support; 0 if none."""
    for n in range(min(below - 1, len(u)), k, -1):
        if not _design_problem(u, clamped_uniform_knots(n, k), k):
            return n
    return 0


def _allowed(u: np.ndarray, k: int, below: int) -> str:
    best = _supported_n_ctrl(u, k, below)
    if best:
        return f"these data allow at most {best} control points for degree {k}"
    return f"these data allow no control-point count for degree {k} (tried {k + 1}-{below - 1})"


def _ill_posed_message(
    reason: str, k: int, n_ctrl: int, parameterization: str, u: np.ndarray
) -> str:
    return (
        f"least-squares B-spline with degree {k}, n_ctrl {n_ctrl} (clamped uniform knots) "
        f"and {parameterization} parameters of {len(u)} distinct points: {reason}; "
        f"{_allowed(u, k, n_ctrl)}"
    )


def fit_bspline(
    points: np.ndarray,
    *,
    degree: int = 3,
    n_ctrl: int = 20,
    parameterization: Parameterization = "chord",
    weights: np.ndarray | None = None,
) -> FittedBSpline:
    """Least-squares clamped B-spline through path points (the chapter's equation (3)).

    Minimises ``sum_i w_i |C(u_i) - Q_i|^2`` over the control points with
    :func:`scipy.interpolate.make_lsq_spline`, on clamped uniform knots ``t`` over
    ``[0, 1]``. Consecutive duplicate points are dropped first.

    The end points are **not** exact: as in the chapter's Table 2, the curve starts and
    ends near, not at, the first and last point (on the paper scene's A* paths a few
    hundredths of a cell for the sweep's best fit, up to several cells with few control
    points). The chapter tabulates these start and end errors in x and y;
    :func:`trajopt.metrics.path_metrics` and :func:`trajopt.compare` report them as
    ``start_error_x_m``, ``start_error_y_m``, ``end_error_x_m`` and ``end_error_y_m``.

    Before solving, the system is checked, and an ill-posed one raises instead of
    returning a diverged curve:

    * **Schoenberg-Whitney**, exactly for these knots and data parameters: the design
      matrix ``A_ji = B_i(u_j)`` has full column rank iff there are data parameters
      ``u_(j_0) < u_(j_1) < ... < u_(j_(n_ctrl-1))`` with ``B_i(u_(j_i)) != 0``, i.e.
      ``t_i < u_(j_i) < t_(i+k+1)``, the first basis function also taking ``u = 0`` and
      the last ``u = 1`` (the clamped ends, where they equal 1). Matching every control
      point, in order, to the earliest admissible parameter after the previous one finds
      such a sequence whenever one exists (the supports' ends increase with ``i``).
    * **Conditioning**: the 2-norm condition number of ``A`` must not exceed
      :data:`BSPLINE_COND_MAX` (``1e4``); above it ``A`` is numerically singular at the
      accuracy of A* points and the control points would diverge.

    Both fail typically when ``n_ctrl`` is close to the number of points (a square or
    nearly square system whose data parameters fall outside or near the ends of the basis
    functions' supports).

    Parameters
    ----------
    points : array_like, shape (n, 2)
        Path points in metres, in path order.
    degree : int
        ``k`` in 1..9.
    n_ctrl : int
        Number of control points, ``k + 1 <= n_ctrl <= n`` (distinct points).
    parameterization : {'uniform', 'chord', 'centripetal'}
        How the data parameters ``u_i`` are chosen (:func:`curve_parameters`).
    weights : array_like, shape (n,), optional
        Positive weights ``w_i`` on the squared residuals.

    Returns
    -------
    FittedBSpline
        A :class:`~trajopt.bspline.BSplineCurve` on ``u in [0, 1]`` carrying ``params``,
        ``residuals``, ``mse`` and ``parameterization``.

    Raises
    ------
    InvalidInputError
        Bad arguments; or the data cannot determine the fit: more control points than
        distinct points, the Schoenberg-Whitney condition fails, or ``cond(A) >
        BSPLINE_COND_MAX``. The message names the condition, the degree, ``n_ctrl``, the
        parameterisation and the number of points, and says how many control points the
        data allow (the largest count below ``n_ctrl`` that passes both checks).
    """
    p = _as_points(points)
    k = _check_int(degree, "degree", 1, 9)
    parameterization = _check_choice(parameterization, "parameterization", PARAMETERIZATIONS)
    w = _as_weights(weights, len(p), positive=True)
    p, w = _dedup(p, w)
    n_c = _check_int(n_ctrl, "n_ctrl", k + 1)
    u = curve_parameters(p, parameterization)
    if n_c > len(p):
        raise IllPosedFitError(
            f"n_ctrl must be <= the number of distinct points ({len(p)}), got {n_c}; "
            f"{_allowed(u, k, len(p) + 1)} ({parameterization} parameters)"
        )
    t = clamped_uniform_knots(n_c, k)
    problem = _design_problem(u, t, k)
    if problem:
        raise IllPosedFitError(_ill_posed_message(problem, k, n_c, parameterization, u))
    return _lsq(p, u, t, k, w, parameterization)


def _lsq(
    p: np.ndarray, u: np.ndarray, t: np.ndarray, k: int, w: np.ndarray, parameterization: str
) -> FittedBSpline:
    from scipy.interpolate import make_lsq_spline

    try:
        spl = make_lsq_spline(u, p, t, k=k, w=np.sqrt(w), check_finite=False)
    except (ValueError, np.linalg.LinAlgError) as exc:
        raise IllPosedFitError(
            f"least-squares B-spline with degree {k} and {len(t) - k - 1} control points "
            f"is not defined for these {len(p)} points ({parameterization} parameters): {exc}"
        ) from exc
    c = np.asarray(spl.c)
    if not np.all(np.isfinite(c)):  # not expected after the checks of fit_bspline
        raise IllPosedFitError(
            f"least-squares B-spline with degree {k} and {len(c)} control points is singular "
            f"for these {len(p)} points (Schoenberg-Whitney condition)"
        )
    curve = FittedBSpline(t, c, k)
    res = np.asarray(spl(u)) - p
    res.flags.writeable = False
    uu = u.copy()
    uu.flags.writeable = False
    curve.params = uu
    curve.residuals = res
    curve.mse = float(np.mean(np.sum(res * res, axis=1)))
    curve.parameterization = parameterization
    return curve


# ============================================================================ sweeps
def _rank(records: list[SweepRecord]) -> list[SweepRecord]:
    def key(r: SweepRecord) -> tuple[int, float]:
        bad = not (r.valid and math.isfinite(r.mse))
        return (int(bad), r.mse if math.isfinite(r.mse) else math.inf)

    ordered = sorted(records, key=key)
    return [
        SweepRecord(r.kind, r.params, r.mse, r.valid, r.reason, i + 1)
        for i, r in enumerate(ordered)
    ]


def sweep_polynomial(
    points: np.ndarray,
    *,
    methods: Iterable[str] = FIT_METHODS,
    orders: Iterable[int] = SWEEP_ORDERS,
    weights: np.ndarray | None = None,
    tol: float = 1e-4,
) -> list[SweepRecord]:
    """Every ``(method, order)`` of :func:`fit_polynomial`, ranked by MSE (Table 1).

    Returns
    -------
    list of SweepRecord
        Best first; ``records[0].kwargs`` is ``{'method': ..., 'order': ...}``. Orders the
        data cannot support (``n < m + 1``) appear last with ``mse = inf``.
    """
    p = _as_points(points)
    methods = [_check_choice(m, "method", FIT_METHODS) for m in methods]
    orders = [_check_int(o, "order", 1, 30) for o in orders]
    out = []
    for meth in methods:
        for m in orders:
            params = {"method": meth, "order": m}
            try:
                fit = fit_polynomial(p, m, method=meth, weights=weights, tol=tol)
            except InvalidInputError as exc:
                out.append(SweepRecord("polynomial", params, math.inf, False, str(exc)))
                continue
            out.append(SweepRecord("polynomial", params, fit.mse, fit.valid, fit.reason))
    return _rank(out)


def sweep_bspline(
    points: np.ndarray,
    *,
    parameterizations: Iterable[str] = PARAMETERIZATIONS,
    degrees: Iterable[int] = SWEEP_DEGREES,
    n_ctrls: Iterable[int] = SWEEP_N_CTRL,
    weights: np.ndarray | None = None,
) -> list[SweepRecord]:
    """Every ``(parameterization, degree, n_ctrl)`` of :func:`fit_bspline`, ranked by MSE.

    The default grid is 3 x 4 x 42 = 504 combinations (Table 2). Data parameters are
    computed once per parameterisation and the fits reuse them; combinations the data
    cannot support (``n_ctrl < degree + 1``, more control points than points, the
    Schoenberg-Whitney condition failing or a numerically singular collocation matrix, as
    :func:`fit_bspline` checks) appear last, ``valid=False`` with ``mse = inf`` and the
    reason (which says how many control points the data allow), instead of being ranked
    by the MSE of a diverged curve.

    Returns
    -------
    list of SweepRecord
        Best first; ``records[0].kwargs`` is
        ``{'parameterization': ..., 'degree': ..., 'n_ctrl': ...}``.
    """
    p0 = _as_points(points)
    kinds = [_check_choice(k, "parameterization", PARAMETERIZATIONS) for k in parameterizations]
    degs = [_check_int(k, "degree", 1, 9) for k in degrees]
    ncs = [_check_int(n, "n_ctrl", 2) for n in n_ctrls]
    w0 = _as_weights(weights, len(p0), positive=True)
    p, w = _dedup(p0, w0)
    from scipy.interpolate import make_lsq_spline

    sw = np.sqrt(w)
    knots = {(k, nc): clamped_uniform_knots(nc, k) for k in degs for nc in ncs if nc >= k + 1}
    out = []
    for kind in kinds:
        u = curve_parameters(p, kind)
        for k in degs:
            for nc in ncs:
                params = {"parameterization": kind, "degree": k, "n_ctrl": nc}
                if nc < k + 1 or nc > len(p):
                    why = f"n_ctrl {nc} outside [degree + 1, points] = [{k + 1}, {len(p)}]"
                    if nc > len(p):
                        why += f"; {_allowed(u, k, len(p) + 1)}"
                    out.append(SweepRecord("bspline", params, math.inf, False, why))
                    continue
                problem = _design_problem(u, knots[k, nc], k)
                if problem:
                    why = _ill_posed_message(problem, k, nc, kind, u)
                    out.append(SweepRecord("bspline", params, math.inf, False, why))
                    continue
                try:
                    spl = make_lsq_spline(u, p, knots[k, nc], k=k, w=sw, check_finite=False)
                    res = spl(u) - p
                    mse = float(np.mean(np.sum(res * res, axis=1)))
                except (ValueError, np.linalg.LinAlgError) as exc:
                    out.append(SweepRecord("bspline", params, math.inf, False, str(exc)))
                    continue
                if not math.isfinite(mse):
                    why = "singular least-squares system (Schoenberg-Whitney condition)"
                    out.append(SweepRecord("bspline", params, math.inf, False, why))
                    continue
                out.append(SweepRecord("bspline", params, mse, True, ""))
    return _rank(out)
