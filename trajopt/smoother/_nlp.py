"""IPOPT problems of the smoother (its ``"ipopt"`` solver options and the polish).

The convex QP (:func:`qp_ipopt`), the exact curvature-bounded NLP (:func:`curvature_nlp`) and
the whole problem (:func:`smoother_nlp`: the QP objective and rows, optionally the exact
curvature rows and the exact cost term of :mod:`~trajopt.smoother._nlp_cost`), built with
CasADi once per problem shape (padded control points ``nb``, degree ``p``, region rows per
point ``k``, and the cost window) and re-solved with parameters: the objective's band and
linear term, the non-zeros of the constraint rows of
:func:`~trajopt.smoother._layout.constraint_layout` (heading rows and the region rows of a box
or a polygon corridor), the basis values at the samples and quadrature points.
"""

from __future__ import annotations

import functools
import time
from typing import TYPE_CHECKING

import numpy as np

from trajopt.smoother._basis import CURV_SAMPLES, curvature_samples
from trajopt.smoother._layout import constraint_layout
from trajopt.smoother._problem import QPData
from trajopt.smoother._solver_builds import LOCK, is_built
from trajopt.smoother._status import SolveInfo, SolveStatus

if TYPE_CHECKING:
    from trajopt.smoother._nlp_cost import CostWindow, WindowedCost
    from trajopt.smoother._options import Smoother


@functools.lru_cache(maxsize=32)
def qp_ipopt(nb: int, p: int, k: int, verbose: bool):
    """Return the corridor QP (no sample rows) as an IPOPT problem, built once per shape.

    The rows are those of :func:`~trajopt.smoother._layout.constraint_layout` ``(nb, p, 0, k)``
    (heading rows, then ``k`` region rows per control point: the diagonal rows of a box
    corridor, the half-planes of a polygon corridor), ``lba <= A z <= uba``, with ``A``'s
    sparsity fixed and its non-zeros a parameter.

    Parameters
    ----------
    nb, p, k : int
        Padded control points, degree and region rows per control point.
    verbose : bool
        IPOPT's output.

    Returns
    -------
    casadi.Function
        An ``nlpsol`` with parameters ``[h band ((p+1) nb), g (2 nb), A non-zeros (CCS)]``
        (:func:`qp_parameters`).
    """
    import casadi as ca

    z = ca.SX.sym("z", 2 * nb)
    hb = ca.SX.sym("hb", (p + 1) * nb)
    g = ca.SX.sym("g", 2 * nb)
    amat, anz = _rows_matrix(nb, p, k)
    nlp = {
        "x": z,
        "p": ca.vertcat(hb, g, anz),
        "f": _band_quadratic(z, hb, nb, p) + ca.dot(g, z),
        "g": ca.mtimes(amat, z),
    }
    with LOCK:
        return ca.nlpsol(f"smoother_qp_ipopt_{k}", "ipopt", nlp, _ipopt_opts(verbose))


def _rows_matrix(nb: int, p: int, k: int):
    """Symbolic ``A`` of :func:`constraint_layout` ``(nb, p, 0, k)`` and its non-zeros."""
    import casadi as ca

    sp = constraint_layout(nb, p, 0, k).sparsity
    anz = ca.SX.sym("a", sp.nnz())
    return ca.SX(sp, anz), anz


def row_values(qp: QPData, p: int) -> np.ndarray:
    """CCS non-zeros of the rows ``A`` of ``qp`` (:func:`_rows_matrix`'s parameter)."""
    layout = constraint_layout(qp.nb, p, 0, qp.k)
    return layout.nonzeros(layout.values(qp.heading, None, qp.region_coef))


def qp_parameters(qp: QPData, p: int) -> np.ndarray:
    """Parameter vector of :func:`qp_ipopt` for ``qp``."""
    return np.concatenate([qp.full.ravel(), qp.g, row_values(qp, p)])


def ipopt_info(solver, out: dict, solve: float, cpu: float, build: float, left: float):
    """Return the :class:`SolveInfo` of an IPOPT solve (its status and iteration count).

    A solve that IPOPT does not report as successful (``Solve_Succeeded`` or
    ``Solved_To_Acceptable_Level``), a non-finite solution or one longer than ``left``
    seconds is a failure; ``detail`` is IPOPT's return status.
    """
    st = solver.stats()
    z = np.asarray(out["x"], dtype=float).ravel()
    finite = bool(st.get("success", False)) and bool(np.all(np.isfinite(z)))
    iters = int(st.get("iter_count", 0) or 0)
    detail = str(st.get("return_status", ""))
    if solve > left:
        status = SolveStatus.OVER_BUDGET
        detail += " (over budget)"
    else:
        status = SolveStatus.SOLVED if finite else SolveStatus.SOLVER_FAILED
    return SolveInfo(
        solver="ipopt",
        status=status,
        detail=detail,
        iterations=iters,
        solve_time_s=solve,
        solve_cpu_s=cpu,
        build_time_s=build,
        cost=float(out["f"]) if "f" in out else float("nan"),
        z=z,
    )


def _band_quadratic(z, hb, nb: int, p: int):
    import casadi as ca

    x, y = z[:nb], z[nb:]
    f = 0
    for d in range(p + 1):
        w = 0.5 if d == 0 else 1.0
        h = hb[d * nb : d * nb + nb - d]
        f = f + w * (ca.dot(h, x[: nb - d] * x[d:]) + ca.dot(h, y[: nb - d] * y[d:]))
    return f


def _curvature_rows(z, nb: int, p: int):
    """Symbolic curvature and speed rows of :func:`curvature_nlp` and their parameters.

    Returns ``(b1, b2, k2), (cross^2 - k2 speed2^3, speed2)`` at ``CURV_SAMPLES`` samples
    per span of the ``nb`` padded control points ``z``.
    """
    import casadi as ca

    ns = nb - p
    S = ns * CURV_SAMPLES
    b1 = ca.SX.sym("b1", S * (p + 1))
    b2 = ca.SX.sym("b2", S * (p + 1))
    k2 = ca.SX.sym("k2")
    x, y = z[:nb], z[nb:]
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
    return (b1, b2, k2), (cross * cross - k2 * sp2 * sp2 * sp2, sp2)


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
            # the rows are imposed 1e-6 cells inside the regions: a solution IPOPT accepts
            # must not leave them by more (its defaults allow 1e-4 and 1e-2 cells)
            "constr_viol_tol": 1e-7,
            "acceptable_constr_viol_tol": 1e-7,
        },
        "print_time": verbose,
        "error_on_fail": False,
    }


@functools.lru_cache(maxsize=16)
def curvature_nlp(nb: int, p: int, k: int, verbose: bool):
    """Return the exact curvature-bounded problem as an IPOPT problem, built once per shape.

    The QP objective, the rows of :func:`qp_ipopt` (``lba <= A z <= uba``, ``A``'s non-zeros a
    parameter: box or polygon corridors alike) and per sample ``r`` (``CURV_SAMPLES`` per
    span, span ``j`` touching control points ``j .. j + p``)
    ``cross_r^2 - kmax^2 * speed2_r^3 <= 0`` and ``speed2_r >= floor_r^2`` (via ``lbg``),
    with ``cross = x'y'' - y'x''`` and ``speed2 = x'^2 + y'^2`` from basis-derivative values
    passed as parameters.

    Parameters
    ----------
    nb, p, k : int
        Padded control points, degree and region rows per control point.
    verbose : bool
        IPOPT's output.

    Returns
    -------
    casadi.Function
        An ``nlpsol`` with parameters ``[hb, g, A non-zeros, b1 (S (p+1)), b2 (S (p+1)),
        kmax^2]``; constraints: the ``5 + k nb`` rows, then ``S`` curvature rows, then ``S``
        speed rows.
    """
    import casadi as ca

    z = ca.SX.sym("z", 2 * nb)
    hb = ca.SX.sym("hb", (p + 1) * nb)
    g = ca.SX.sym("g", 2 * nb)
    amat, anz = _rows_matrix(nb, p, k)
    f = _band_quadratic(z, hb, nb, p) + ca.dot(g, z)
    (b1, b2, k2), (gcurv, sp2) = _curvature_rows(z, nb, p)
    nlp = {
        "x": z,
        "p": ca.vertcat(hb, g, anz, b1, b2, k2),
        "f": f,
        "g": ca.vertcat(ca.mtimes(amat, z), gcurv, sp2),
    }
    with LOCK:
        return ca.nlpsol(f"smoother_curv_{k}", "ipopt", nlp, _ipopt_opts(verbose))


def solve_curvature_ipopt(
    options: Smoother,
    qp: QPData,
    t: np.ndarray,
    z0: np.ndarray,
    kmax: float,
    remaining: float,
    margin: float,
) -> SolveInfo:
    """Return the curvature-bounded problem solved by IPOPT, warm started at ``z0`` (cells).

    ``|kappa| <= margin * kmax`` (1/cell) and ``|C'| >= options.speed_floor`` at
    :data:`~trajopt.smoother._basis.CURV_SAMPLES` samples per span, within the rows of ``qp``
    (box or polygon corridor); a solve longer than the ``remaining`` budget (s) is a failure.

    Parameters
    ----------
    options : Smoother
        ``degree``, ``speed_floor`` and ``verbose`` are used.
    qp : QPData
        The attempt's convex problem (cell units, padded).
    t : ndarray
        Knots (cells).
    z0 : ndarray, shape (2 nb,)
        Starting point (the QP's or an earlier attempt's solution).
    kmax : float
        Curvature bound (1/cell).
    remaining : float
        Time left (s).
    margin : float
        Factor on ``kmax`` at the samples.

    Returns
    -------
    SolveInfo
        ``detail`` is IPOPT's return status, ``iterations`` its iteration count.
    """
    p = options.degree
    n, nb = qp.n, qp.nb
    ms = CURV_SAMPLES
    _, B1, B2 = curvature_samples(t, p, n, nb)
    par = np.concatenate(
        [
            qp.full.ravel(),
            qp.g,
            row_values(qp, p),
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
    built = is_built(f"curv-{qp.k}", nb, p, options.verbose)
    solver = curvature_nlp(nb, p, qp.k, options.verbose)
    build = 0.0 if built else time.perf_counter() - tb
    left = max(0.05, remaining - build - 0.02)
    ts = time.perf_counter()
    tc = time.process_time()
    out = solver(x0=z0, p=par, lbx=qp.lbx, ubx=qp.ubx, lbg=lbg, ubg=ubg)
    solve = time.perf_counter() - ts
    return ipopt_info(solver, out, solve, time.process_time() - tc, build, left)


@functools.lru_cache(maxsize=16)
def smoother_nlp(
    nb: int,
    p: int,
    k: int,
    curvature: bool,
    window: CostWindow | None,
    verbose: bool,
):
    """Return the smoother's whole problem as an IPOPT problem, built once per shape.

    The QP objective and rows of :func:`qp_ipopt`; with ``curvature`` the curvature and
    speed rows of :func:`curvature_nlp`; with a cost ``window``
    (:mod:`~trajopt.smoother._nlp_cost`) the cost term
    ``sum_q wq_q cost(P_q) sqrt(x'_q^2 + y'_q^2 + EPS)`` at ``Q = N_GAUSS (nb - p)``
    quadrature points (point ``q`` on span ``q // N_GAUSS``), ``P_q`` the curve point in the
    window's local coordinates and ``cost`` the window's cubic B-spline (its coefficients
    constants of the problem: one build per window).

    Parameters
    ----------
    nb, p, k : int
        Padded control points, degree and region rows per control point.
    curvature : bool
        Add the curvature-bound rows.
    window : CostWindow or None
        The cost window, or ``None`` without a cost term.
    verbose : bool
        IPOPT's output.

    Returns
    -------
    casadi.Function
        An ``nlpsol`` with parameters (in this order) ``[hb, g, A non-zeros]``, with
        ``curvature`` ``[b1, b2, kmax^2]`` (as :func:`curvature_nlp`), with a window
        ``[qb0 (Q (p+1)), qb1 (Q (p+1)), s w wq (Q), offset (2)]``; constraints: the
        ``5 + k nb`` rows, then with ``curvature`` ``S`` curvature rows and ``S`` speed rows.
    """
    import casadi as ca

    from trajopt.smoother._nlp_cost import EPS, N_GAUSS, spline_function

    z = ca.SX.sym("z", 2 * nb)
    hb = ca.SX.sym("hb", (p + 1) * nb)
    g = ca.SX.sym("g", 2 * nb)
    amat, anz = _rows_matrix(nb, p, k)
    f = _band_quadratic(z, hb, nb, p) + ca.dot(g, z)
    par = [hb, g, anz]
    rows = [ca.mtimes(amat, z)]
    if curvature:
        cpar, crows = _curvature_rows(z, nb, p)
        par += list(cpar)
        rows += list(crows)
    name = f"smoother_nlp_{k}_{int(curvature)}"
    if window is not None:
        Q = N_GAUSS * (nb - p)
        qb0 = ca.SX.sym("qb0", Q * (p + 1))
        qb1 = ca.SX.sym("qb1", Q * (p + 1))
        wq = ca.SX.sym("wq", Q)
        off = ca.SX.sym("off", 2)
        B0 = ca.reshape(qb0, Q, p + 1)
        B1 = ca.reshape(qb1, Q, p + 1)
        span = np.repeat(np.arange(nb - p), N_GAUSS)
        x, y = z[:nb], z[nb:]
        px, py, dx, dy = off[0], off[1], 0, 0
        for c in range(p + 1):
            idx = (span + c).tolist()
            px = px + B0[:, c] * x[idx]
            py = py + B0[:, c] * y[idx]
            dx = dx + B1[:, c] * x[idx]
            dy = dy + B1[:, c] * y[idx]
        spline = spline_function(window)
        # call nodes (never inlined): the spline is an MX function of constant coefficients
        vals = ca.vertcat(
            *[spline.call([ca.vertcat(px[q], py[q])], False, True)[0] for q in range(Q)]
        )
        f = f + ca.dot(wq * vals, ca.sqrt(dx * dx + dy * dy + EPS))
        par += [qb0, qb1, wq, off]
        name += f"_{window.shape[0]}x{window.shape[1]}"
    nlp = {"x": z, "p": ca.vertcat(*par), "f": f, "g": ca.vertcat(*rows)}
    with LOCK:
        return ca.nlpsol(name, "ipopt", nlp, _ipopt_opts(verbose))


def solve_nlp(
    options: Smoother,
    qp: QPData,
    t: np.ndarray,
    z0: np.ndarray,
    remaining: float,
    *,
    kmax: float | None = None,
    margin: float = 1.0,
    cost: WindowedCost | None = None,
) -> tuple[SolveInfo, float]:
    """Return the whole problem (:func:`smoother_nlp`) solved by IPOPT from ``z0`` (cells).

    Parameters
    ----------
    options : Smoother
        ``degree``, ``speed_floor`` and ``verbose`` are used.
    qp : QPData
        The attempt's convex problem (cell units, padded): objective and rows.
    t : ndarray
        Knots (cells).
    z0 : ndarray, shape (2 nb,)
        Starting point (cells).
    remaining : float
        Time left (s); a longer solve is a failure.
    kmax : float or None
        Curvature bound (1/cell), imposed as ``margin * kmax`` at the samples; ``None``: no
        curvature rows.
    margin : float
        Factor on ``kmax``.
    cost : WindowedCost or None
        The cost term on its window (:func:`~trajopt.smoother._nlp_cost.windowed`).

    Returns
    -------
    info : SolveInfo
        ``cost`` is the objective at IPOPT's point (without ``qp``'s constant), ``detail``
        IPOPT's return status, ``iterations`` its iteration count.
    start_objective : float
        The same objective at ``z0``.
    """
    p = options.degree
    n, nb = qp.n, qp.nb
    par = [qp.full.ravel(), qp.g, row_values(qp, p)]
    lbg, ubg = [qp.lba], [qp.uba]
    if kmax is not None:
        ms = CURV_SAMPLES
        _, B1, B2 = curvature_samples(t, p, n, nb)
        par += [B1.ravel(order="F"), B2.ravel(order="F"), [(margin * kmax) ** 2]]
        S = (nb - p) * ms
        low = np.full(S, -np.inf)
        low[: (n - p) * ms] = options.speed_floor**2
        lbg += [np.full(S, -np.inf), low]
        ubg += [np.zeros(S), np.full(S, np.inf)]
    win = None
    if cost is not None:
        par += cost.parameters()
        win = cost.window
    par_v = np.concatenate([np.ravel(a) for a in par])
    tb = time.perf_counter()
    key = f"nlp-{qp.k}-{kmax is not None}-{None if win is None else hash(win)}"
    built = is_built(key, nb, p, options.verbose)
    solver = smoother_nlp(nb, p, qp.k, kmax is not None, win, options.verbose)
    build = 0.0 if built else time.perf_counter() - tb
    f0 = float(solver.get_function("nlp_f")(z0, par_v))
    left = max(0.05, remaining - build - 0.02)
    ts = time.perf_counter()
    tc = time.process_time()
    out = solver(
        x0=z0,
        p=par_v,
        lbx=qp.lbx,
        ubx=qp.ubx,
        lbg=np.concatenate(lbg),
        ubg=np.concatenate(ubg),
    )
    solve = time.perf_counter() - ts
    return ipopt_info(solver, out, solve, time.process_time() - tc, build, left), f0
