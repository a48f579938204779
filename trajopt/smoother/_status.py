"""What a smoother solve reports.

A typed status, one record per solver call and per attempt, and the ``stats`` dictionary derived
from them in one place.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field
from typing import Any

import numpy as np


class SolveStatus(enum.Enum):
    """Outcome of one solver call (``SolveInfo.status``)."""

    #: a convex QP solved to the solver's tolerance
    SOLVED = "solved"
    #: no solve: the control points of an earlier attempt were reused (a warm retry)
    WARM_START = "warm start"
    #: the SCP met the sampled curvature and speed bounds and stopped on a convergence test
    CONVERGED = "converged"
    #: the QP solution already met the sampled bounds (no SCP iteration needed)
    FEASIBLE_AT_QP = "feasible at the QP solution"
    #: the bounds hold, but the SCP stopped for another reason (``detail`` says which)
    FEASIBLE = "feasible"
    #: the SCP ended with the sampled bound broken (stalled or out of iterations)
    NOT_CONVERGED = "not converged"
    #: the SCP's trust region shrank to nothing with the bound broken
    TRUST_REGION_COLLAPSED = "trust region collapsed"
    #: the time budget ran out with the bound broken
    TIME_BUDGET = "time budget exceeded"
    #: IPOPT needed more than the time left
    OVER_BUDGET = "over budget"
    #: the solver reported a failure (``detail`` holds its own status)
    SOLVER_FAILED = "solver failed"

    @property
    def ok(self) -> bool:
        """Whether the call produced a usable solution."""
        return self in _OK


_OK = {
    SolveStatus.SOLVED,
    SolveStatus.WARM_START,
    SolveStatus.CONVERGED,
    SolveStatus.FEASIBLE_AT_QP,
    SolveStatus.FEASIBLE,
}


@dataclass(slots=True)
class SolveInfo:
    """One solver call of an attempt: the QP, the SCP or the IPOPT NLP.

    Attributes
    ----------
    solver : str
        ``"piqp"``, ``"osqp"``, ``"ipopt"``, ``"scp"`` or ``"warm"``.
    status : SolveStatus
    detail : str
        The solver's own status text (reported as ``stats["status"]``).
    iterations : int
    solve_time_s, solve_cpu_s, build_time_s : float
        Wall and CPU time of the solve, and the time spent building a solver (s).
    cost : float
        Objective at the solution (``nan`` when the solver does not report it).
    z : ndarray, shape (2 nb,) or None
        The solution (control points, cells); not part of the statistics.
    extra : dict
        Solver-specific statistics (e.g. ``n_samples`` of an SCP QP).
    """

    solver: str
    status: SolveStatus
    detail: str
    iterations: int = 0
    solve_time_s: float = 0.0
    solve_cpu_s: float = 0.0
    build_time_s: float = 0.0
    cost: float = float("nan")
    z: np.ndarray | None = None
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def success(self) -> bool:
        """``status.ok``."""
        return self.status.ok

    def to_stats(self) -> dict[str, Any]:
        """Return the call's statistics as a plain dict (no arrays)."""
        out: dict[str, Any] = {
            "solver": self.solver,
            "cost": self.cost,
            "success": self.success,
            "status": self.detail,
            "status_code": self.status.value,
            "iterations": self.iterations,
            "solve_time_s": self.solve_time_s,
            "solve_cpu_s": self.solve_cpu_s,
            "build_time_s": self.build_time_s,
        }
        out.update(self.extra)
        return out


@dataclass(slots=True)
class AttemptRecord:
    """One attempt of :meth:`Smoother.fit` (one knot vector, or a warm retry on it)."""

    attempt: int
    span_cells: float
    kappa_margin: float | None = None
    n_control_points: int = 0
    padded_size: int = 0
    qp: SolveInfo | None = None
    nlp: SolveInfo | None = None
    cost: float | None = None
    failure: str | None = None
    certificate_ok: bool | None = None
    footprint_margin_m: float | None = None
    cost_rounds: dict[str, Any] | None = None  # the cost field's QP rounds (_cost.cost_rounds)

    @property
    def last(self) -> SolveInfo | None:
        """The call that decided the attempt: the NLP when there was one, else the QP."""
        return self.nlp if self.nlp is not None else self.qp

    def to_stats(self) -> dict[str, Any]:
        """Return the attempt as a plain dict (``attempt_log`` entries of ``stats``)."""
        out: dict[str, Any] = {"attempt": self.attempt, "span_cells": self.span_cells}
        if self.kappa_margin is not None:
            out["kappa_margin"] = self.kappa_margin
        if self.qp is not None:
            calls = [c for c in (self.qp, self.nlp) if c is not None]
            last = calls[-1]
            out.update(
                n_control_points=self.n_control_points,
                padded_size=self.padded_size,
                qp=self.qp.to_stats(),
                solver="+".join(c.solver for c in calls),
                status=last.detail,
                status_code=last.status.value,
                iterations=sum(c.iterations for c in calls),
                solve_time_s=sum(c.solve_time_s for c in calls),
                build_time_s=sum(c.build_time_s for c in calls),
            )
            if self.nlp is not None:
                out["nlp"] = self.nlp.to_stats()
            if self.cost_rounds is not None:
                out["cost_rounds"] = dict(self.cost_rounds)
        if self.cost is not None:
            out["cost"] = self.cost
        if self.failure is not None:
            out["failure"] = self.failure
        if self.certificate_ok is not None:
            out["certificate_ok"] = self.certificate_ok
        if self.footprint_margin_m is not None:
            out["footprint_margin_m"] = self.footprint_margin_m
        return out


def summarize(attempts: list[AttemptRecord], total_s: float, *, success: bool) -> dict[str, Any]:
    """``SmoothPath.stats`` (and ``SmoothingError.stats``) from the attempt records.

    Keys: ``success``, ``status`` (the last solver's text), ``status_code`` (its
    :class:`SolveStatus` value), ``solver``, ``iterations``, ``solve_time_s`` and
    ``build_time_s`` (summed over attempts), ``total_time_s``, ``cost``, ``attempts`` (the
    count), ``n_control_points``, ``padded_size`` and ``attempt_log`` (one dict per
    attempt, :meth:`AttemptRecord.to_stats`).
    """
    log = [a.to_stats() for a in attempts]
    last = log[-1] if log else {}
    return {
        "success": success,
        "status": last.get("status", "not run"),
        "status_code": last.get("status_code", ""),
        "solver": last.get("solver", ""),
        "iterations": last.get("iterations", 0),
        "solve_time_s": float(sum(a.get("solve_time_s", 0.0) for a in log)),
        "build_time_s": float(sum(a.get("build_time_s", 0.0) for a in log)),
        "total_time_s": total_s,
        "cost": last.get("cost", float("nan")),
        "attempts": len(log),
        "n_control_points": last.get("n_control_points", 0),
        "padded_size": last.get("padded_size", 0),
        "attempt_log": log,
    }
