"""The curvature bound by sequential convex programming (``curvature_solver="scp"``).

:class:`CurvatureSCP` imposes ``|kappa| <= margin * kmax`` and ``|C'| >= speed_floor`` at
:data:`~trajopt.smoother._basis.CURV_SAMPLES` samples per span by a few piqp QPs.

With the current iterate's unit tangent ``T_r``, normal ``N_r`` and speed ``v_r`` at sample
``r``, each QP imposes ``T_r . C'(u_r) >= floor`` (which implies ``|C'| >= floor``) and
``|N_r . C''(u_r)| <= kb (2 v_r (T_r . C') - v_r^2)``: since ``s^2 >= 2 v s - v^2`` this is
a conservative form of ``|N . C''| <= kb |C'|^2``, the curvature bound when ``C'`` is along
``T``. Every row has an l1-penalised slack, so each QP is feasible; a trust region on the
control points is grown or shrunk by the ratio of actual to predicted decrease of the merit
``objective + penalty * violation`` (it starts at ``trust`` cells; steps that do not
decrease the merit are rejected, and the region shrinks to at most half the rejected step).
Iterations stop once the sampled bound holds (within ``sample_slack``) and either the merit
stalls, or the objective comes within ``rtol`` (relative) of the model's optimum, or the
model predicts a relative decrease below ``rtol`` of the merit or (its optimum inside the
trust region) of the objective. They give up when the bound is still broken and the merit
fell by less than ``rtol`` over ``stall_window`` iterations (a local minimum of the
penalty: the caller refines the knots). The caller's certificate then checks the result
on dense samples.

From ``ws_min_points`` control points up, only the samples near either bound at some
iterate so far (curvature above ``ws_kappa`` of the sampled bound, or speed below
``ws_speed`` times the floor), with those of the neighbouring spans, enter the QPs (the
*working set*); the merit, and so the step acceptance, still counts every sample.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from trajopt.smoother._basis import CURV_SAMPLES, band_quadratic, curvature_samples
from trajopt.smoother._layout import constraint_layout
from trajopt.smoother._problem import QPData
from trajopt.smoother._qp import WorkingSetSolver, piqp_info
from trajopt.smoother._status import SolveInfo, SolveStatus

if TYPE_CHECKING:
    from trajopt.smoother._options import Smoother

logger = logging.getLogger(__name__)


@dataclass(frozen=True, slots=True)
class SCPSettings:
    """Tolerances of :class:`CurvatureSCP` (cell units).

    Attributes
    ----------
    sample_slack : float
        The sampled curvature may exceed ``margin * kmax`` (and the speed fall below the
        floor) by this factor: the margin leaves room, and the certificate checks the true
        bound on dense samples.
    slack_max : float
        Largest slack (keeps every row's range finite for the interior-point solver).
    slack_penalty : float
        l1 penalty on the slacks; large against the objective's multipliers.
    rtol : float
        Relative tolerance of the stopping tests (module docstring).
    stall_window : int
        Iterations over which a broken bound with a flat merit counts as a stall.
    ws_kappa, ws_speed : float
        Working-set thresholds: curvature above ``ws_kappa`` of the sampled bound, speed
        below ``ws_speed`` times the floor.
    ws_min_points : int
        Below this many control points every sample is in every QP.
    """

    sample_slack: float = 1.01
    slack_max: float = 1e3
    slack_penalty: float = 1e4
    rtol: float = 1e-2
    stall_window: int = 3
    ws_kappa: float = 0.5
    ws_speed: float = 2.0
    ws_min_points: int = 64


@dataclass(slots=True)
class _Iterate:
    """Control points ``z`` and what the samples say about them."""

    z: np.ndarray
    d1: np.ndarray  # C' at the samples, shape (S, 2)
    d2: np.ndarray  # C''
    sp: np.ndarray  # |C'|
    kap: np.ndarray  # |kappa|
    ok: bool  # both sampled bounds hold (within the sample slack)
    merit: float  # objective + penalty * violation


class CurvatureSCP:
    """One curvature-bounded solve on fixed knots (module docstring).

    Parameters
    ----------
    options : Smoother
        ``degree``, ``speed_floor`` and ``scp_iterations`` are used.
    qp : QPData
        The attempt's convex problem.
    knots : ndarray
        Clamped knots (cells).
    kmax : float
        Curvature bound (1/cell).
    margin : float
        Fraction of ``kmax`` imposed at the samples.
    const : float
        Constant of the objective (so that the merit is the objective's true value).
    settings : SCPSettings, optional
    """

    def __init__(
        self,
        options: Smoother,
        qp: QPData,
        knots: np.ndarray,
        kmax: float,
        margin: float,
        const: float = 0.0,
        settings: SCPSettings | None = None,
    ) -> None:
        self.set = SCPSettings() if settings is None else settings
        self.options = options
        self.qp = qp
        self.kmax = kmax
        self.const = const
        p = self.p = options.degree
        n, nb = qp.n, qp.nb
        ms = CURV_SAMPLES
        self.S = (nb - p) * ms
        self.ns_real = (n - p) * ms
        span, B1, B2 = curvature_samples(knots, p, n, nb)
        self.B1, self.B2 = B1[: self.ns_real], B2[: self.ns_real]
        self.idx = span[:, None] + np.arange(p + 1)[None, :]
        self.kb = margin * kmax
        self.floor = options.speed_floor
        self.layout = constraint_layout(nb, p, ms, qp.k)
        n_fixed = self.layout.sample_row0
        self.lba = np.full(n_fixed + 3 * self.S, -np.inf)
        self.uba = np.full(n_fixed + 3 * self.S, np.inf)
        self.lba[:n_fixed] = qp.lba
        self.uba[:n_fixed] = qp.uba
        self.vals = np.zeros((self.S, 3, 2 * (p + 1)))
        self.rows = n_fixed + 3 * np.arange(self.ns_real)
        self.work = np.zeros(self.S, dtype=bool)
        if n < self.set.ws_min_points:  # small: every sample (a cheap QP; fewer iterations)
            self.work[: self.ns_real] = True
        self.kernel = np.ones(2 * ms + 1, dtype=bool)
        self.solve_working_set = WorkingSetSolver()

    # ------------------------------------------------------------------ pieces
    def objective(self, z: np.ndarray) -> float:
        """Return the QP objective (>= 0), constant included."""
        return band_quadratic(self.qp.full, self.qp.g, z, self.const)

    def measure(self, z: np.ndarray) -> _Iterate:
        """Return the derivatives, speeds, curvatures, feasibility and merit at the samples."""
        nb = self.qp.nb
        X = z[:nb][self.idx]
        Y = z[nb:][self.idx]
        B1, B2 = self.B1, self.B2
        d1 = np.column_stack([(B1 * X).sum(1), (B1 * Y).sum(1)])
        d2 = np.column_stack([(B2 * X).sum(1), (B2 * Y).sum(1)])
        sp = np.hypot(d1[:, 0], d1[:, 1])
        cross = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
        spc = np.maximum(sp, 1e-12)
        kap = np.abs(cross) / spc**3
        kb, floor, slack = self.kb, self.floor, self.set.sample_slack
        viol = np.maximum(0.0, np.abs(cross) / spc - kb * sp**2) + np.maximum(0.0, floor - sp)
        ok = bool(kap.max() <= kb * slack and sp.min() >= floor / slack)
        merit = self.objective(z) + self.set.slack_penalty * float(viol.sum())
        return _Iterate(z, d1, d2, sp, kap, ok, merit)

    def near_active(self, it: _Iterate) -> np.ndarray:
        """Sample near either bound, with their neighbouring spans' samples."""
        near = (it.kap > self.set.ws_kappa * self.kb) | (it.sp < self.set.ws_speed * self.floor)
        return np.convolve(near, self.kernel, mode="same") > 0

    def linearise(self, it: _Iterate) -> None:
        """Rows of the QP around the iterate ``it`` (``vals``, ``lba``, ``uba``).

        ``c = X / v - kb v^2`` (``X = d1 x d2``, ``v = |d1|``) and its mirror
        ``-X / v - kb v^2``, linearised: ``X / v`` to first order, ``-kb v^2`` by its
        tangent plane (an upper bound, so that part is conservative).
        """
        p, ns, kb = self.p, self.ns_real, self.kb
        B1, B2, vals = self.B1, self.B2, self.vals
        d1, d2, sp = it.d1, it.d2, it.sp
        v = np.maximum(sp, 1e-9)
        T = d1 / v[:, None]
        N = np.column_stack([-T[:, 1], T[:, 0]])
        X = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
        gx1 = d2[:, 1] / v - X * d1[:, 0] / v**3  # d(X/v)/d(d1)
        gy1 = -d2[:, 0] / v - X * d1[:, 1] / v**3
        kx = -2 * kb * d1[:, 0]  # d(-kb v^2)/d(d1)
        ky = -2 * kb * d1[:, 1]
        for row, sgn in ((0, 1.0), (1, -1.0)):
            ax_ = sgn * gx1 + kx
            ay_ = sgn * gy1 + ky
            bx_ = sgn * N[:, 0]
            by_ = sgn * N[:, 1]
            vals[:ns, row, : p + 1] = B1 * ax_[:, None] + B2 * bx_[:, None]
            vals[:ns, row, p + 1 :] = B1 * ay_[:, None] + B2 * by_[:, None]
            # value at the iterate: sgn X / v - kb v^2; row(z_k) = the linear part
            lin_k = ax_ * d1[:, 0] + ay_ * d1[:, 1] + bx_ * d2[:, 0] + by_ * d2[:, 1]
            self.uba[self.rows + row] = lin_k - (sgn * X / v - kb * sp**2)
        vals[:ns, 2, : p + 1] = B1 * T[:, 0:1]
        vals[:ns, 2, p + 1 :] = B1 * T[:, 1:2]
        self.lba[self.rows + 2] = self.floor

    def solve_qp(self, lbx: np.ndarray, ubx: np.ndarray) -> SolveInfo:
        """One SCP QP over the working set, by piqp directly."""
        qp, S = self.qp, self.S
        trip = self.layout.values(qp.heading, self.vals, qp.region_coef)
        lbx_s = np.concatenate([lbx, np.zeros(S)])
        ubx_s = np.concatenate([ubx, np.full(S, self.set.slack_max)])
        ts = time.perf_counter()
        tc = time.process_time()
        z, *result = self.solve_working_set(
            qp.full,
            qp.g,
            self.layout,
            trip,
            lbx_s,
            ubx_s,
            self.lba,
            self.uba,
            self.work,
            self.set.slack_penalty,
        )
        info = piqp_info(z, result, ts, tc)
        info.extra["n_samples"] = int(self.work.sum())
        return info

    # ------------------------------------------------------------------- solve
    def run(self, z0: np.ndarray, remaining: float, trust: float = 1.0) -> SolveInfo:
        """Iterate from ``z0``.

        Iterate from ``z0`` (cells) within ``remaining`` seconds, trust region ``trust`` cells
        at first; the returned info's ``z`` is the last accepted iterate.
        """
        st = self.set
        ns = self.ns_real
        delta = float(trust)  # trust region (cells)
        cur = self.measure(z0.copy())
        q_cur = self.objective(cur.z)
        history = [cur.merit]  # the merit after each iteration
        t0 = time.perf_counter()
        build = solve = 0.0
        iters = 0
        status = "feasible at the QP solution" if cur.ok else "not converged"
        for it in range(int(self.options.scp_iterations)):
            if time.perf_counter() - t0 > remaining:
                status = "time budget exceeded"
                break
            self.linearise(cur)
            lbx = np.maximum(self.qp.lbx, cur.z - delta)
            ubx = np.minimum(self.qp.ubx, cur.z + delta)
            self.work[:ns] |= self.near_active(cur)
            info = self.solve_qp(lbx, ubx)
            iters += 1
            build += info.build_time_s
            solve += info.solve_time_s
            if not info.success:
                status = f"SCP iteration {it + 1}: {info.solver} {info.detail}"
                break
            znew = np.clip(info.z, lbx, ubx)
            step = float(np.max(np.abs(znew - cur.z)))
            predicted = cur.merit - (info.cost + self.const)
            new = self.measure(znew)
            self.work[:ns] |= self.near_active(new)  # samples the step moved near the bounds
            actual = cur.merit - new.merit
            tol = 1e-9 * (1.0 + abs(cur.merit))
            logger.debug(
                "SCP %d: %.1f ms (cpu %.1f ms, %d it, %d samples), step %.3g (trust %.3g), "
                "max kappa/bound %.4g, min speed %.3g, merit %.6g -> %.6g (predicted %.6g)",
                it + 1,
                1e3 * info.solve_time_s,
                1e3 * info.solve_cpu_s,
                info.iterations,
                info.extra["n_samples"],
                step,
                delta,
                new.kap.max() / self.kb,
                new.sp.min(),
                cur.merit,
                new.merit,
                cur.merit - predicted,
            )
            if predicted <= tol:  # no decrease predicted: a stationary point of the model
                status = "converged" if cur.ok else "stalled"
                break
            if cur.ok and predicted <= st.rtol * (1.0 + abs(cur.merit)):
                # the bound holds and even the model's best step would lower the merit by
                # less than the tolerance: stop at the current iterate
                status = "converged"
                break
            interior = step < 0.99 * delta  # the model's optimum lies inside the region
            if cur.ok and interior and q_cur - self.objective(znew) <= st.rtol * (1.0 + q_cur):
                # the bound holds (within the sample slack) and the model's optimum, inside
                # the trust region, lowers the objective itself by less than the tolerance:
                # what is left to gain is the penalty on violations inside that slack
                status = "converged"
                break
            ratio = actual / predicted
            if ratio >= 0.1:  # accept
                model = cur.merit - predicted  # the model's optimum around the old iterate
                cur = new
                q_cur = self.objective(cur.z)
                if ratio > 0.5 and step >= 0.99 * delta:
                    delta = min(2 * delta, 8.0)
                elif ratio < 0.25:
                    delta *= 0.5
                rtol = st.rtol * (1.0 + abs(cur.merit))
                # (the objective, not the merit, against the model's optimum: the penalty
                # left is on violations inside the sample slack)
                if cur.ok and (
                    actual <= rtol or (interior and step < 0.05) or q_cur - model <= rtol
                ):
                    status = "converged"
                    break
            else:  # reject; the next region is smaller than the rejected step
                delta = min(0.25 * delta, 0.5 * step)
            if delta < 1e-3:
                status = "converged" if cur.ok else "trust region collapsed"
                break
            history.append(cur.merit)
            if (
                not cur.ok
                and len(history) > st.stall_window
                and history[-1 - st.stall_window] - cur.merit <= st.rtol * (1.0 + abs(cur.merit))
            ):
                # the bound still broken and the merit flat over the window: a local
                # minimum of the penalty (the caller refines the knots)
                status = "stalled"
                break
        code, detail = self._outcome(cur, status, iters)
        return SolveInfo(
            solver="scp",
            status=code,
            detail=detail,
            iterations=iters,
            solve_time_s=solve,
            build_time_s=build,
            z=cur.z,
        )

    def _outcome(self, cur: _Iterate, status: str, iters: int) -> tuple[SolveStatus, str]:
        if cur.ok:
            if status == "converged":
                return SolveStatus.CONVERGED, status
            if status == "feasible at the QP solution":
                return SolveStatus.FEASIBLE_AT_QP, status
            return SolveStatus.FEASIBLE, "feasible (" + status + ")"
        if status in ("not converged", "converged", "stalled"):
            return SolveStatus.NOT_CONVERGED, (
                f"not converged after {iters} iterations (sampled max kappa "
                f"{cur.kap.max() / self.kmax:.3g} x the bound, min speed {cur.sp.min():.3g})"
            )
        if status == "time budget exceeded":
            return SolveStatus.TIME_BUDGET, status
        if status == "trust region collapsed":
            return SolveStatus.TRUST_REGION_COLLAPSED, status
        return SolveStatus.SOLVER_FAILED, status
