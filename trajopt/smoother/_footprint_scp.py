"""The footprint in the optimiser: vertex rows linearised in the heading, solved as an SCP.

A disc-certified curve whose oriented footprint meets an obstacle
(:func:`trajopt.robot._footprint.certify_footprint`) is solved again on the same knots with, at the
:data:`~trajopt.smoother._basis.CURV_SAMPLES` samples per span of the failing spans (and
``p`` spans on either side, accumulated over the rounds), rows that keep the footprint's
corners inside the sample's region pushed out by the disc radius ``r`` the region was built
for: for a corner ``f`` (robot frame) and a region half-plane ``a . x <= b``,

    a . (C(u) + R(theta(u)) f) <= b + r,

linearised around the current curve in the position ``C(u)`` (exact: it is linear in the
control points) and in the heading ``theta(u) = atan2(C'(u))``:
``delta theta = N . C'(u) / |C'(u)|`` (``N`` the unit normal, so ``N . C' = 0`` at the
current curve) and ``R(theta + delta) f = R(theta) f + delta R(theta + pi / 2) f``. Each
sample keeps its two most violated (corner, half-plane) pairs and the speed floor of the
curvature SCP (``T . C' >= floor``), each with an l1-penalised slack, so every QP is
feasible; each round moves the control points by at most a trust region. The footprint certificate, not these rows, decides: each round's
curve is certified (disc and footprint) and the rows are re-linearised around it.

The rows use the corridor's regions (their union need not hold the footprint where it turns
between two regions); ``b + r`` are the region's obstacle-tangent lines for the regions'
own half-planes.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from trajopt.smoother._basis import CURV_SAMPLES, sample_bases
from trajopt.smoother._layout import constraint_layout
from trajopt.smoother._problem import N_HEADING_ROWS, Assembly, Problem, QPData
from trajopt.smoother._qp import solve_working_set

#: (corner, half-plane) rows per sample
ROWS_PER_SAMPLE = 2
#: l1 penalty on a row's slack (cells), large against the objective's multipliers
SLACK_PENALTY = 1e4
#: largest slack (cells): keeps every row's range finite for the interior-point solver
SLACK_MAX = 1e3
#: the corner rows keep this far (cells) inside the pushed-out half-planes: room for the
#: certificate's bound (the control hull plus the swept footprint) around the samples
ROW_MARGIN_CELLS = 0.5
#: the speed row keeps ``T . C'`` at least this fraction of the current speed (hard row)
SPEED_KEEP = 0.75


class FootprintSCP:
    """The footprint rows of one knot vector (module docstring).

    Parameters
    ----------
    asm : Assembly
        The attempt's problem on these knots (its QP, knots and span regions).
    prob : Problem
        The fit's problem (polygon corridor: ``rows`` set).
    corners : ndarray, shape (K, 2)
        The footprint's corners in the robot frame (cells).
    r_cells : float
        The disc radius the corridor's regions were built for (cells).
    degree : int
    speed_floor : float
        Every sample also keeps ``T . C'(u) >= speed_floor`` (``T`` the current unit
        tangent), as in the curvature SCP: the curve cannot slow to a cusp, where the
        heading's linearisation fails.
    """

    def __init__(
        self,
        asm: Assembly,
        prob: Problem,
        corners: np.ndarray,
        r_cells: float,
        degree: int,
        speed_floor: float,
    ) -> None:
        qp = asm.qp
        n, nb, p = qp.n, qp.nb, int(degree)
        self.asm, self.p, self.F = asm, p, np.asarray(corners, dtype=float)
        self.floor = float(speed_floor)
        self.layout = constraint_layout(nb, p, CURV_SAMPLES, qp.k)
        span, (B0, B1) = sample_bases(asm.knots, p, n, nb, (0, 1))
        ns = self.ns = len(span)
        self.span = span
        self.B0, self.B1 = B0[:ns], B1[:ns]
        self.idx = span[:, None] + np.arange(p + 1)[None, :]
        # every region's one-sided half-planes, pushed out by r (the obstacle-tangent lines)
        q = max(len(r[1]) for r in prob.rows)
        A = np.zeros((len(prob.rows), q, 2))
        hi = np.full((len(prob.rows), q), np.inf)
        for k, (a, lo_r, hi_r) in enumerate(prob.rows):
            one = np.flatnonzero(~np.isfinite(lo_r))
            A[k, one] = a[one]
            hi[k, one] = hi_r[one] + r_cells - ROW_MARGIN_CELLS
        region = np.asarray(asm.span_box)[span]
        self.A, self.hi = A[region], hi[region]  # (ns, q, 2), (ns, q)
        S = self.layout.n_samples
        n_fixed = self.layout.sample_row0
        self.lba = np.full(n_fixed + 3 * S, -np.inf)
        self.uba = np.full(n_fixed + 3 * S, np.inf)
        self.lba[:n_fixed] = qp.lba
        self.uba[:n_fixed] = qp.uba
        self.rows = n_fixed + 3 * np.arange(ns)
        self.vals = np.zeros((S, 3, 2 * (p + 1)))
        self.work = np.zeros(S, dtype=bool)
        #: per sample and row: the (region row, corner) pair of the last linearisation
        self.pairs = np.zeros((ns, ROWS_PER_SAMPLE, 2), dtype=np.int64)

    def activate(self, spans: np.ndarray) -> None:
        """Add the samples of the spans marked in ``spans`` (bool, shape (n - p,))."""
        self.work[: self.ns] |= np.asarray(spans, dtype=bool)[self.span]

    def linearise(self, z: np.ndarray) -> None:
        """Set the rows around the control points ``z`` (cells, ``[x..., y...]`` padded)."""
        nb, p, ns, F = self.asm.qp.nb, self.p, self.ns, self.F
        X, Y = z[:nb][self.idx], z[nb:][self.idx]
        C = np.column_stack([(self.B0 * X).sum(1), (self.B0 * Y).sum(1)])
        D = np.column_stack([(self.B1 * X).sum(1), (self.B1 * Y).sum(1)])
        v = np.maximum(np.hypot(D[:, 0], D[:, 1]), 1e-9)
        T = D / v[:, None]
        N = np.column_stack([-T[:, 1], T[:, 0]])
        RF = np.stack(
            [T[:, :1] * F[:, 0] - T[:, 1:] * F[:, 1], T[:, 1:] * F[:, 0] + T[:, :1] * F[:, 1]],
            axis=2,
        )
        RpF = np.stack([-RF[..., 1], RF[..., 0]], axis=2)  # R(theta + pi/2) f
        W = C[:, None, :] + RF  # posed corners (ns, K, 2)
        with np.errstate(invalid="ignore"):
            g = np.einsum("sqd,skd->sqk", self.A, W) - self.hi[:, :, None]
        K = len(F)
        flat = np.where(np.isfinite(g), g, -np.inf).reshape(ns, -1)
        order = np.argsort(-flat, axis=1, kind="stable")[:, :ROWS_PER_SAMPLE]
        s = np.arange(ns)
        for j in range(ROWS_PER_SAMPLE):
            qi, ki = np.divmod(order[:, j], K)
            self.pairs[:, j, 0], self.pairs[:, j, 1] = qi, ki
            a = self.A[s, qi]
            beta = np.einsum("sd,sd->s", a, RpF[s, ki]) / v
            self.vals[:ns, j, : p + 1] = self.B0 * a[:, :1] + self.B1 * (beta * N[:, 0])[:, None]
            self.vals[:ns, j, p + 1 :] = self.B0 * a[:, 1:] + self.B1 * (beta * N[:, 1])[:, None]
            ub = self.hi[s, qi] - np.einsum("sd,sd->s", a, RF[s, ki])
            self.uba[self.rows + j] = np.where(np.isfinite(flat[s, order[:, j]]), ub, np.inf)
        self.vals[:ns, 2, : p + 1] = self.B1 * T[:, :1]
        self.vals[:ns, 2, p + 1 :] = self.B1 * T[:, 1:]
        self.lba[self.rows + 2] = np.maximum(self.floor, SPEED_KEEP * v)

    def solve(
        self, z: np.ndarray, trust: float = np.inf, objective: QPData | None = None
    ) -> tuple[np.ndarray | None, str]:
        """One QP from ``z``, each coordinate within ``trust`` cells of it.

        ``objective``: the QP whose ``full`` and ``g`` are minimised (default the attempt's;
        with a cost field, :func:`~trajopt.smoother._cost.linearised` of it at ``z``); the
        rows and bounds are always the attempt's. Returns the new control points (``None``
        on failure) and the solver's status.
        """
        qp, S = self.asm.qp, self.layout.n_samples
        obj = qp if objective is None else objective
        trip = self.layout.values(qp.heading, self.vals, qp.region_coef)
        n_fixed = self.layout.sample_row0 - N_HEADING_ROWS  # triplets of the fixed rows / 2
        rows = trip[2 * (N_HEADING_ROWS * qp.nb + n_fixed) :].reshape(S, 3, -1)
        rows[:, 2, -1] = 0.0  # the speed row is hard: no slack
        lo = np.minimum(np.maximum(qp.lbx, z - trust), qp.ubx)
        hi = np.maximum(np.minimum(qp.ubx, z + trust), qp.lbx)
        lbx = np.concatenate([lo, np.zeros(S)])
        ubx = np.concatenate([hi, np.full(S, SLACK_MAX)])
        znew, _, ok, status, _ = solve_working_set(
            obj.full,
            obj.g,
            self.layout,
            trip,
            lbx,
            ubx,
            self.lba,
            self.uba,
            self.work,
            SLACK_PENALTY,
        )
        return (np.clip(znew, qp.lbx, qp.ubx) if ok else None), status


def corners_cells(footprint: Any, res: float) -> np.ndarray:
    """Return the footprint's corners in cells, shape (K, 2)."""
    return np.asarray(footprint.vertices, dtype=float) / res
