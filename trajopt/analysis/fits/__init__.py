"""Plain fits of A* points: the chapter's baselines.

Modules: :mod:`~trajopt.analysis.fits._curves` (the returned curves), :mod:`~trajopt.analysis.fits._records`,
:mod:`~trajopt.analysis.fits._robust` (least squares, LAR, bisquare), :mod:`~trajopt.analysis.fits._polynomial`,
:mod:`~trajopt.analysis.fits._bspline_fit` and :mod:`~trajopt.analysis.fits._sweeps`; the names listed in
``__all__`` here are imported from them (the building blocks of the checks and messages,
such as :func:`~trajopt.analysis.fits._bspline_fit.design_problem`, stay in their modules).

Two families, both returning objects that follow :class:`trajopt.geometry._curve.ParametricCurve`
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
  condition number above :data:`BSPLINE_COND_MAX`) raises
  :class:`~trajopt.errors.IllPosedFitError` (an :class:`~trajopt.errors.InvalidInputError`)
  instead of returning a diverged curve, and so does a solution that swings: a control
  point more than :data:`BSPLINE_SWING_MAX` times the data's extent outside the data's
  bounding box (:func:`swing_problem`), where the curve interpolates the points and swings
  between them.

Parameter sweeps as the chapter's Tables 1 and 2 (:func:`sweep_polynomial`: 3 methods x 10
orders; :func:`sweep_bspline`: 3 parameterisations x 4 degrees x 42 control-point counts =
504) rank every combination by the MSE of equation (3) at the fitted parameters, the
combinations that fail a check of :func:`fit_bspline` last as invalid; the ``kwargs`` of
the best record are reused unchanged on other targets.
"""

from trajopt.analysis.fits._bspline_fit import (
    BSPLINE_COND_MAX,
    BSPLINE_SWING_MAX,
    PARAMETERIZATIONS,
    Parameterization,
    curve_parameters,
    fit_bspline,
    swing_problem,
)
from trajopt.analysis.fits._curves import FittedBSpline, ParametricPolynomialCurve, PolynomialCurve
from trajopt.analysis.fits._polynomial import fit_polynomial, fit_polynomial_parametric
from trajopt.analysis.fits._records import PolynomialFit, SweepRecord
from trajopt.analysis.fits._robust import BISQUARE_C, FIT_METHODS, FitMethod
from trajopt.analysis.fits._sweeps import (
    SWEEP_DEGREES,
    SWEEP_N_CTRL,
    SWEEP_ORDERS,
    sweep_bspline,
    sweep_polynomial,
)

__all__ = [
    "BISQUARE_C",
    "BSPLINE_COND_MAX",
    "BSPLINE_SWING_MAX",
    "FIT_METHODS",
    "PARAMETERIZATIONS",
    "SWEEP_DEGREES",
    "SWEEP_N_CTRL",
    "SWEEP_ORDERS",
    "FitMethod",
    "FittedBSpline",
    "ParametricPolynomialCurve",
    "Parameterization",
    "PolynomialCurve",
    "PolynomialFit",
    "SweepRecord",
    "curve_parameters",
    "fit_bspline",
    "fit_polynomial",
    "fit_polynomial_parametric",
    "sweep_bspline",
    "sweep_polynomial",
    "swing_problem",
]
