"""The records of the plain fits: one polynomial fit, one combination of a sweep."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from trajopt.analysis.fits._curves import ParametricPolynomialCurve, PolynomialCurve


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
