"""Parameter sweeps of the plain fits, as the chapter's Tables 1 and 2.

Every combination ranked by the MSE of equation (3) at the fitted parameters.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

import numpy as np

import trajopt.validation as validation
from trajopt.analysis.fits._bspline_fit import (
    PARAMETERIZATIONS,
    allowed_message,
    curve_parameters,
    dedup,
    design_problem,
    ill_posed_message,
    swing_problem,
)
from trajopt.analysis.fits._polynomial import fit_polynomial
from trajopt.analysis.fits._records import SweepRecord
from trajopt.analysis.fits._robust import FIT_METHODS
from trajopt.errors import InvalidInputError
from trajopt.geometry import clamped_uniform_knots

#: Default polynomial orders of the sweep (Table 1: 3 methods x 10 orders).
SWEEP_ORDERS: tuple[int, ...] = tuple(range(1, 11))
#: Default B-spline degrees and control-point counts of the sweep (Table 2: 3 x 4 x 42).
SWEEP_DEGREES: tuple[int, ...] = (2, 3, 4, 5)
SWEEP_N_CTRL: tuple[int, ...] = tuple(range(6, 48))


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
    p = validation.points("points", points)
    methods = [validation.choice("method", m, FIT_METHODS) for m in methods]
    orders = [validation.integer("order", o, 1, 30) for o in orders]
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
    computed once per parameterisation and the fits reuse them. Combinations the data
    cannot support appear last, ``valid=False`` with ``mse = inf`` and the reason, instead
    of being ranked by the MSE of a diverged or swinging curve: ``n_ctrl < degree + 1``,
    more control points than points, and every check of :func:`fit_bspline` (the
    Schoenberg-Whitney condition, a numerically singular collocation matrix, and a solution
    with a control point more than :data:`~trajopt.fits.BSPLINE_SWING_MAX` data extents
    outside the data's bounding box). For those checks the reason is the message
    :func:`fit_bspline` raises, including how many control points the data allow (the
    largest count below ``n_ctrl`` that passes every check), so the ``kwargs`` of every
    valid record, the best one included, fit with :func:`fit_bspline` without raising.

    Returns
    -------
    list of SweepRecord
        Best first; ``records[0].kwargs`` is
        ``{'parameterization': ..., 'degree': ..., 'n_ctrl': ...}``.
    """
    p0 = validation.points("points", points)
    kinds = [validation.choice("parameterization", k, PARAMETERIZATIONS) for k in parameterizations]
    degs = [validation.integer("degree", k, 1, 9) for k in degrees]
    ncs = [validation.integer("n_ctrl", n, 2) for n in n_ctrls]
    w0 = validation.weights("weights", weights, len(p0), positive=True)
    p, w = dedup(p0, w0)
    from scipy.interpolate import make_lsq_spline

    sw = np.sqrt(w)
    knots = {(k, nc): clamped_uniform_knots(nc, k) for k in degs for nc in ncs if nc >= k + 1}
    out = []
    for kind in kinds:
        u = curve_parameters(p, kind)
        for k in degs:
            # control-point count -> passes every check of fit_bspline, shared by the
            # records' "allow at most" counts
            memo: dict[int, bool] = {}
            for nc in ncs:
                params = {"parameterization": kind, "degree": k, "n_ctrl": nc}
                if nc < k + 1 or nc > len(p):
                    why = f"n_ctrl {nc} outside [degree + 1, points] = [{k + 1}, {len(p)}]"
                    if nc > len(p):
                        allowed = allowed_message(u, k, len(p) + 1, points=p, weights=w, memo=memo)
                        why += f"; {allowed}"
                    out.append(SweepRecord("bspline", params, math.inf, False, why))
                    continue
                memo[nc] = False  # until every check below has passed
                problem = design_problem(u, knots[k, nc], k)
                if problem:
                    why = ill_posed_message(problem, k, nc, kind, u, points=p, weights=w, memo=memo)
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
                problem = swing_problem(p, spl.c)
                if problem:
                    why = ill_posed_message(problem, k, nc, kind, u, points=p, weights=w, memo=memo)
                    out.append(SweepRecord("bspline", params, math.inf, False, why))
                    continue
                memo[nc] = True
                out.append(SweepRecord("bspline", params, mse, True, ""))
    return _rank(out)
