"""The chapter's comparison methods.

The chapter's comparison methods (A*, A* + avoidance area, the polynomial and B-spline fits) and
the proposed method, registered in the order the table shows them.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

from trajopt.analysis.comparison._records import ComparisonContext, MethodResult
from trajopt.analysis.comparison._registry import register_method

#: Polynomial-fit parameters used when ``poly`` is not given: the best of
#: :func:`trajopt.fits.sweep_polynomial` on the paper scene's target A (Table 1 analogue).
DEFAULT_POLY: Mapping[str, Any] = MappingProxyType({"method": "least_squares", "order": 10})
#: B-spline parameters used when ``bspline`` is not given (see :data:`DEFAULT_POLY`;
#: from :func:`trajopt.fits.sweep_bspline` on target A, Table 2 analogue).
DEFAULT_BSPLINE: Mapping[str, Any] = MappingProxyType(
    {"parameterization": "chord", "degree": 2, "n_ctrl": 43}
)


def _method_astar_raw(ctx: ComparisonContext) -> MethodResult:
    return MethodResult(ctx.points(ctx.path_raw), runtime_s=ctx.timings.get("astar_raw"))


def _method_astar_avoid(ctx: ComparisonContext) -> MethodResult:
    return MethodResult(ctx.reference, runtime_s=ctx.timings.get("astar_avoid"))


def _method_polynomial(ctx: ComparisonContext) -> MethodResult:
    from trajopt.analysis.fits import fit_polynomial

    opts = {**DEFAULT_POLY, **ctx.options_for("polynomial fit")}
    order = opts.pop("order")
    n = len(ctx.reference)
    if isinstance(order, int) and n < order + 1:
        return MethodResult(None, False, f"order {order} needs {order + 1} points, path has {n}")
    fit = fit_polynomial(ctx.reference, order, **opts)
    note = f"{fit.method}, order {fit.order}"
    if not fit.valid:
        note += f"; {fit.reason}"
    return MethodResult(fit.curve, fit.valid, note, extras={"fit_mse_m2": fit.mse})


def _method_polynomial_parametric(ctx: ComparisonContext) -> MethodResult:
    from trajopt.analysis.fits import fit_polynomial_parametric

    opts = {**DEFAULT_POLY, **ctx.options_for("polynomial fit (parametric)")}
    order = opts.pop("order")
    n = len(ctx.reference)
    if isinstance(order, int) and n < order + 1:
        return MethodResult(None, False, f"order {order} needs {order + 1} points, path has {n}")
    fit = fit_polynomial_parametric(ctx.reference, order, **opts)
    note = f"{fit.method}, order {fit.order}" + (f"; {fit.reason}" if fit.reason else "")
    return MethodResult(fit.curve, fit.valid, note, extras={"fit_mse_m2": fit.mse})


def _method_bspline(ctx: ComparisonContext) -> MethodResult:
    from trajopt.analysis.fits import fit_bspline
    from trajopt.errors import IllPosedFitError

    opts = {**DEFAULT_BSPLINE, **ctx.options_for("B-spline fit")}
    ref = ctx.reference
    n_distinct = len(ref)
    note = ""
    n_ctrl = opts.get("n_ctrl")
    if isinstance(n_ctrl, int) and n_ctrl > n_distinct:
        k = opts.get("degree", 3)
        opts["n_ctrl"] = max(n_distinct, (k if isinstance(k, int) else 3) + 1)
        note = f"n_ctrl reduced from {n_ctrl} to {opts['n_ctrl']} (path has {n_distinct} points); "
    if n_distinct < 2:
        return MethodResult(None, False, "path has a single point")
    try:
        curve = fit_bspline(ref, **opts)
    except IllPosedFitError as exc:  # the data cannot determine this fit: no curve to rank
        return MethodResult(None, False, note + str(exc))
    note += (
        f"{curve.parameterization}, degree {curve.k}, {curve.c.shape[0]} control points; "
        "end points not exact (start_error_*/end_error_* columns)"
    )
    return MethodResult(curve, True, note, extras={"fit_mse_m2": curve.mse})


register_method("A*", _method_astar_raw)
register_method("A* + avoidance area", _method_astar_avoid)
register_method("polynomial fit", _method_polynomial)
register_method("B-spline fit", _method_bspline)
register_method("polynomial fit (parametric)", _method_polynomial_parametric, default=False)
register_method("proposed", "trajopt.analysis.comparison._proposed:proposed_method")
