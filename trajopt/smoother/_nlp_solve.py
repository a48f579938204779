"""The IPOPT stages of an attempt: the exact cost term, and the polish of a fast result.

* With a cost field and ``qp_solver="ipopt"`` (or ``curvature_solver="ipopt"`` and a
  curvature bound), :func:`cost_ipopt` minimises the objective with the exact cost term
  (:mod:`~trajopt.smoother._nlp_cost`) by IPOPT, warm started from the QP solution, in place
  of the QP path's linearised rounds (and, with ``curvature_solver="ipopt"``, with the exact
  curvature rows: the whole problem at once).
* ``Smoother(refine="ipopt")``: :func:`refine_ipopt` solves the whole problem of the attempt
  (its objective, the exact cost term when a cost is given, the exact curvature rows when
  ``kappa_max`` is set, the same corridor and heading rows) by IPOPT, warm started from the
  fast QP/SCP result, and offers the result only when IPOPT succeeds and the objective is not
  higher than at the fast result; the caller keeps it only when it is certified too.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

import numpy as np

from trajopt.smoother._cost import CostTerm
from trajopt.smoother._nlp import solve_nlp
from trajopt.smoother._nlp_cost import WindowedCost, windowed
from trajopt.smoother._problem import Problem, QPData
from trajopt.smoother._status import SolveInfo

if TYPE_CHECKING:
    from trajopt.smoother._options import Smoother


def ipopt_cost(options: Smoother) -> bool:
    """Return whether IPOPT, not the QP rounds, minimises the cost term under ``options``."""
    curv_ipopt = options.kappa_max is not None and options.curvature_solver == "ipopt"
    return options.qp_solver == "ipopt" or curv_ipopt


def whole_problem_by_ipopt(options: Smoother) -> bool:
    """Return whether the fast path already solves the whole problem with IPOPT.

    Then a polish has nothing to add (the cost term, when given, is in IPOPT's problem
    whenever :func:`ipopt_cost` holds).
    """
    if options.kappa_max is not None:
        return options.curvature_solver == "ipopt"
    return options.qp_solver == "ipopt"


def on_window(term: CostTerm, prob: Problem) -> WindowedCost:
    """Return ``term`` on the window of the corridor's regions (their bounding box, cells)."""
    return windowed(term, prob.lo.min(axis=0), prob.hi.max(axis=0))


def cost_ipopt(
    options: Smoother,
    qp: QPData,
    t: np.ndarray,
    z: np.ndarray,
    term: CostTerm,
    prob: Problem,
    margin: float,
    remaining: float,
) -> tuple[np.ndarray, np.ndarray, dict, SolveInfo]:
    """Minimise the objective with the exact cost term by IPOPT from ``z`` (cells).

    With ``curvature_solver="ipopt"`` and a curvature bound, the curvature rows
    (``margin * kappa_max`` at the samples) are in the same problem.

    Parameters
    ----------
    options : Smoother
    qp : QPData
        The attempt's convex problem.
    t : ndarray
        Knots (cells).
    z : ndarray, shape (2 nb,)
        The QP solution (cells).
    term : CostTerm
        The cost term on ``t``.
    prob : Problem
        The fit (its regions give the cost window).
    margin : float
        Factor on ``kappa_max`` at the curvature samples.
    remaining : float
        Time left (s).

    Returns
    -------
    z : ndarray, shape (2 nb,)
        IPOPT's point clipped to the bounds (``z`` unchanged when IPOPT failed).
    g_lin : ndarray, shape (2 nb,)
        ``qp.g`` plus the cost term's gradient there (the linear term of a later SCP).
    stats : dict
        ``rounds`` and ``accepted`` (0: no QP rounds), ``mean_cost`` before and after.
    info : SolveInfo
        IPOPT's record; the caller fails the attempt when it is not a success.
    """
    kw = {}
    if options.kappa_max is not None and options.curvature_solver == "ipopt":
        kw = {"kmax": options.kappa_max * prob.res, "margin": margin}
    info, _ = solve_nlp(options, qp, t, z, remaining, cost=on_window(term, prob), **kw)
    stats = {"rounds": 0, "accepted": 0, "mean_cost_qp": term.mean_cost(z)}
    if info.success:
        z = np.clip(info.z, qp.lbx, qp.ubx)
    val, grad = term.value_grad(z)
    stats.update(cost_term=val, mean_cost=term.mean_cost(z))
    return z, qp.g + grad, stats, info


def refine_ipopt(
    options: Smoother,
    qp: QPData,
    t: np.ndarray,
    z: np.ndarray,
    term: CostTerm | None,
    prob: Problem,
    margin: float,
    remaining: float,
    const: float = 0.0,
) -> tuple[np.ndarray | None, dict]:
    """Polish the fast result ``z`` (cells) by IPOPT on the whole problem.

    Parameters
    ----------
    options : Smoother
    qp : QPData
        The attempt's convex problem (its ``g`` without the cost gradient).
    t : ndarray
        Knots (cells).
    z : ndarray, shape (2 nb,)
        The fast path's result (cells), the warm start.
    term : CostTerm or None
        The cost term, if any.
    prob : Problem
    margin : float
        Factor on ``kappa_max`` at the curvature samples (the fast path's).
    remaining : float
        Time left (s).
    const : float
        The objective's constant (added to the reported objectives).

    Returns
    -------
    z : ndarray or None
        IPOPT's point when it succeeded with an objective not above the fast result's, else
        ``None``.
    stats : dict
        ``status`` ("improved", "not better", "failed" or "skipped"), ``ipopt_status``,
        ``iterations``, ``objective_before``, ``objective_after`` (the problem's objective,
        cell units), ``time_s``; ``reason`` when skipped.
    """
    t0 = time.perf_counter()
    if whole_problem_by_ipopt(options):
        return None, {"status": "skipped", "reason": "the fast path already solved it by IPOPT"}
    kw = {}
    if options.kappa_max is not None:
        kw = {"kmax": options.kappa_max * prob.res, "margin": margin}
    if term is not None:
        kw["cost"] = on_window(term, prob)
    info, f0 = solve_nlp(options, qp, t, z, remaining, **kw)
    stats = {
        "ipopt_status": info.detail,
        "iterations": info.iterations,
        "objective_before": f0 + const,
        "objective_after": info.cost + const,
        "build_time_s": info.build_time_s,
    }
    out = None
    if not info.success:
        stats["status"] = "failed"
    elif not info.cost <= f0:
        stats["status"] = "not better"
    else:
        stats["status"] = "improved"
        out = np.clip(info.z, qp.lbx, qp.ubx)
    stats["time_s"] = time.perf_counter() - t0
    return out, stats
