"""IPOPT problems of the smoother (``qp_solver="ipopt"``, ``curvature_solver="ipopt"``).

The convex QP and the exact curvature-bounded NLP, built with CasADi once per padded size.
"""

from __future__ import annotations

import functools
import time
from typing import TYPE_CHECKING

import numpy as np

from trajopt.smoother._basis import CURV_SAMPLES, curvature_samples
from trajopt.smoother._problem import N_HEADING_ROWS, QPData
from trajopt.smoother._solver_builds import LOCK, is_built
from trajopt.smoother._status import SolveInfo, SolveStatus

if TYPE_CHECKING:
    from trajopt.smoother._options import Smoother


@functools.lru_cache(maxsize=32)
def qp_ipopt(nb: int, p: int, verbose: bool):
    """Return the same convex problem (no sample rows) solved by IPOPT (fallback / reference).

    Parameters ``[h band (p+1)*nb, g (2nb), heading rows (4*2nb)]``.
    """
    import casadi as ca

    z = ca.SX.sym("z", 2 * nb)
    hb = ca.SX.sym("hb", (p + 1) * nb)
    g = ca.SX.sym("g", 2 * nb)
    a = ca.SX.sym("a", N_HEADING_ROWS * 2 * nb)
    f = _band_quadratic(z, hb, nb, p) + ca.dot(g, z)
    amat = ca.reshape(a, N_HEADING_ROWS, 2 * nb)
    nlp = {
        "x": z,
        "p": ca.vertcat(hb, g, a),
        "f": f,
        "g": ca.vertcat(ca.mtimes(amat, z), _diag_rows(z, nb)),
    }
    with LOCK:
        return ca.nlpsol("smoother_qp_ipopt", "ipopt", nlp, _ipopt_opts(verbose))


def _diag_rows(z, nb: int):
    """``[x_0 + y_0, x_0 - y_0, x_1 + y_1, ...]`` (the layout's diagonal rows)."""
    import casadi as ca

    x, y = z[:nb], z[nb:]
    return ca.reshape(ca.horzcat(x + y, x - y).T, 2 * nb, 1)


def _band_quadratic(z, hb, nb: int, p: int):
    import casadi as ca

    x, y = z[:nb], z[nb:]
    f = 0
    for d in range(p + 1):
        w = 0.5 if d == 0 else 1.0
        h = hb[d * nb : d * nb + nb - d]
        f = f + w * (ca.dot(h, x[: nb - d] * x[d:]) + ca.dot(h, y[: nb - d] * y[d:]))
    return f


def _ipopt_opts(verbose: bool) -> dict:
    return {
        "ipopt": {
            "print_level": 5 if verbose else 0,
            "sb": "yes",
            "max_iter": 300,
            "tol": 1e-8,
            "acceptable_tol": 1e-6,
            "mu_strategy": "adaptive",
            "bound_relax_factor": 0.0,
            "honor_original_bounds": "yes",
        },
        "print_time": verbose,
        "error_on_fail": False,
    }


@functools.lru_cache(maxsize=16)
def curvature_nlp(nb: int, p: int, verbose: bool):
    """IPOPT problem: the QP objective, the heading and diagonal rows, and per sample ``r``.

    IPOPT problem: the QP objective, the heading and diagonal rows, and per sample ``r``
    (``CURV_SAMPLES`` per span, span ``j`` touching control points ``j .. j + p``)

    ``cross_r^2 - kmax^2 * speed2_r^3 <= 0`` and ``speed2_r >= floor_r^2`` (via ``lbg``),

    with ``cross = x'y'' - y'x''`` and ``speed2 = x'^2 + y'^2`` from basis-derivative values
    passed as parameters. Parameters: ``[hb, g, a, b1 (S*(p+1)), b2 (S*(p+1)), kmax^2]``.
    Constraint order: 4 heading rows, ``2 nb`` diagonal rows, then ``S`` curvature rows,
    then ``S`` speed rows.
    """
    import casadi as ca

    ns = nb - p
    S = ns * CURV_SAMPLES
    z = ca.SX.sym("z", 2 * nb)
    hb = ca.SX.sym("hb", (p + 1) * nb)
    g = ca.SX.sym("g", 2 * nb)
    a = ca.SX.sym("a", N_HEADING_ROWS * 2 * nb)
    b1 = ca.SX.sym("b1", S * (p + 1))
    b2 = ca.SX.sym("b2", S * (p + 1))
    k2 = ca.SX.sym("k2")
    x, y = z[:nb], z[nb:]
    f = _band_quadratic(z, hb, nb, p) + ca.dot(g, z)
    amat = ca.reshape(a, N_HEADING_ROWS, 2 * nb)
    span = np.repeat(np.arange(ns), CURV_SAMPLES)
    B1 = ca.reshape(b1, S, p + 1)
    B2 = ca.reshape(b2, S, p + 1)
    dx = 0
    dy = 0
    ddx = 0
    ddy = 0
    for c in range(p + 1):
        idx = (span + c).tolist()
        dx = dx + B1[:, c] * x[idx]
        dy = dy + B1[:, c] * y[idx]
        ddx = ddx + B2[:, c] * x[idx]
        ddy = ddy + B2[:, c] * y[idx]
    cross = dx * ddy - dy * ddx
    sp2 = dx * dx + dy * dy
    gcurv = cross * cross - k2 * sp2 * sp2 * sp2
    nlp = {
        "x": z,
        "p": ca.vertcat(hb, g, a, b1, b2, k2),
        "f": f,
        "g": ca.vertcat(ca.mtimes(amat, z), _diag_rows(z, nb), gcurv, sp2),
    }
    with LOCK:
        return ca.nlpsol("smoother_curv", "ipopt", nlp, _ipopt_opts(verbose))


def solve_curvature_ipopt(
    options: Smoother,
    qp: QPData,
    t: np.ndarray,
    z0: np.ndarray,
    kmax: float,
    remaining: float,
    margin: float,
) -> SolveInfo:
    """Return the curvature-bounded problem by IPOPT, warm started at ``z0`` (cells).

    ``|kappa| <= margin * kmax`` (1/cell) and ``|C'| >= options.speed_floor`` at
    :data:`~trajopt.smoother._basis.CURV_SAMPLES` samples per span; a solve longer than the
    ``remaining`` budget (s) is a failure.
    """
    p = options.degree
    n, nb = qp.n, qp.nb
    ms = CURV_SAMPLES
    _, B1, B2 = curvature_samples(t, p, n, nb)
    par = np.concatenate(
        [
            qp.full.ravel(),
            qp.g,
            qp.heading.ravel(order="F"),
            B1.ravel(order="F"),
            B2.ravel(order="F"),
            [(margin * kmax) ** 2],
        ]
    )
    S = (nb - p) * ms
    lbg = np.concatenate([qp.lba, np.full(S, -np.inf), np.full(S, -np.inf)])
    ubg = np.concatenate([qp.uba, np.zeros(S), np.full(S, np.inf)])
    off = len(qp.lba) + S
    lbg[off : off + (n - p) * ms] = options.speed_floor**2
    tb = time.perf_counter()
    built = is_built("curv", nb, p, options.verbose)
    solver = curvature_nlp(nb, p, options.verbose)
    build = 0.0 if built else time.perf_counter() - tb
    left = max(0.05, remaining - build - 0.02)
    ts = time.perf_counter()
    out = solver(x0=z0, p=par, lbx=qp.lbx, ubx=qp.ubx, lbg=lbg, ubg=ubg)
    solve = time.perf_counter() - ts
    st = solver.stats()
    z = np.asarray(out["x"], dtype=float).ravel()
    finite = bool(st.get("success", False)) and bool(np.all(np.isfinite(z)))
    if solve > left:
        status = SolveStatus.OVER_BUDGET
    else:
        status = SolveStatus.SOLVED if finite else SolveStatus.SOLVER_FAILED
    return SolveInfo(
        solver="ipopt",
        status=status,
        detail=str(st.get("return_status", "")) + ("" if solve <= left else " (over budget)"),
        iterations=int(st.get("iter_count", 0) or 0),
        solve_time_s=solve,
        build_time_s=build,
        z=z,
    )
