"""The convex corridor QP of the smoother.

Cached ``casadi.conic`` builds (on the constraint layouts of
:mod:`~trajopt.smoother._layout`), the direct piqp solve over a working set,
and one call that solves the QP.

Everything works in cell units on ``nb`` padded control points (solvers are built once per
padded size and cached for the process).
"""

from __future__ import annotations

import functools
import logging
import time
from typing import TYPE_CHECKING

import numpy as np

from trajopt.smoother._layout import ConstraintLayout, constraint_layout
from trajopt.smoother._nlp import ipopt_info, qp_ipopt, qp_parameters
from trajopt.smoother._problem import QPData
from trajopt.smoother._solver_builds import LOCK, is_built
from trajopt.smoother._status import SolveInfo, SolveStatus

if TYPE_CHECKING:
    from trajopt.smoother._options import Smoother

logger = logging.getLogger(__name__)


def _band_pattern(nb: int, p: int):
    """CCS (row, col) of the symmetric band |i - j| <= p of an nb x nb matrix."""
    rows, cols = [], []
    for c in range(nb):
        r = np.arange(max(0, c - p), min(nb, c + p + 1))
        rows.append(r)
        cols.append(np.full(len(r), c))
    return np.concatenate(rows), np.concatenate(cols)


@functools.lru_cache(maxsize=64)
def qp_layout(nb: int, p: int):
    """Sparsity of the two-block banded Hessian.

    Sparsity of the two-block banded Hessian (x block then y block) and the index map from CCS
    non-zeros to ``(band offset, band column)``.
    """
    import casadi as ca

    r, c = _band_pattern(nb, p)
    rows = np.concatenate([r, r + nb])
    cols = np.concatenate([c, c + nb])
    order = np.lexsort((rows, cols))
    rows, cols = rows[order], cols[order]
    colind = np.concatenate([[0], np.cumsum(np.bincount(cols, minlength=2 * nb))])
    sp_h = ca.Sparsity(2 * nb, 2 * nb, colind.tolist(), rows.tolist())
    rr, cc = rows % nb, cols % nb
    d = np.abs(cc - rr)
    col = np.minimum(rr, cc)
    return sp_h, d, col


def h_nonzeros(band: np.ndarray, nb: int, p: int) -> np.ndarray:
    """CCS non-zeros of ``blockdiag(Hb, Hb)`` for the upper band ``band`` of ``Hb``."""
    _, d, col = qp_layout(nb, p)
    return band[d, col]


@functools.lru_cache(maxsize=128)
def qp_solver(nb: int, p: int, solver: str, m: int, verbose: bool, k: int = 2):
    """Return a ``casadi.conic`` QP ``min 1/2 z'Hz + g'z, lbx <= z <= ubx, lba <= A z <= uba``.

    A ``casadi.conic`` QP ``min 1/2 z'Hz + g'z, lbx <= z <= ubx, lba <= A z <= uba`` with the
    banded two-block Hessian and :func:`constraint_layout` ``(nb, p, m, k)``; built once per
    ``(nb, p, solver, m, k)``.
    """
    import casadi as ca

    sp_h = qp_layout(nb, p)[0]
    layout = constraint_layout(nb, p, m, k)
    sp_a = layout.sparsity
    if m:  # slack columns: no Hessian entries
        extra = layout.n_samples
        colind = list(sp_h.colind()) + [sp_h.nnz()] * extra
        sp_h = ca.Sparsity(2 * nb + extra, 2 * nb + extra, colind, list(sp_h.row()))
    if solver == "osqp":
        opts = {
            "osqp": {
                "verbose": verbose,
                "eps_abs": 1e-7,
                "eps_rel": 1e-7,
                "max_iter": 20000,
                "polish": True,
            },
            "warm_start_primal": True,
            "error_on_fail": False,
        }
    elif solver == "piqp":
        opts = {"piqp": {"verbose": verbose}, "error_on_fail": False}
    else:  # pragma: no cover - validated by the caller
        raise ValueError(f"unknown QP solver {solver!r}")
    if not verbose:
        opts["print_time"] = False
        opts["print_problem"] = False
    with LOCK:
        return ca.conic(f"smoother_qp_{m}_{k}", solver, {"h": sp_h, "a": sp_a}, opts)


@functools.lru_cache(maxsize=64)
def upper_band_triplets(nb: int, p: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Upper triangle of the two-block banded Hessian.

    Rows, columns, and the ``(band offset, band column)`` of each entry's value.
    """
    r, c = _band_pattern(nb, p)
    up = r <= c
    r, c = r[up], c[up]
    rows = np.concatenate([r, r + nb])
    cols = np.concatenate([c, c + nb])
    return rows, cols, np.concatenate([c - r, c - r]), np.concatenate([r, r])


def solve_working_set(
    full: np.ndarray,
    g: np.ndarray,
    layout: ConstraintLayout,
    trip: np.ndarray,
    lbx: np.ndarray,
    ubx: np.ndarray,
    lba: np.ndarray,
    uba: np.ndarray,
    active: np.ndarray,
    slack_penalty: float,
) -> tuple[np.ndarray, float, bool, str, int]:
    """One QP of the sequential convex programme with only the ``active`` curvature samples.

    One QP of the sequential convex programme with only the ``active`` curvature samples, solved
    by piqp directly (the rows of the other samples and their slacks are left out: the problem's
    sparsity changes with the working set, which a ``casadi.conic`` fixes at build time). With
    ``m = 0`` (no samples) it is the corridor QP itself; rows with only zero coefficients or no
    finite bound are left out too (the padded region rows of a polygon corridor).

    Parameters
    ----------
    full : ndarray, shape (p + 1, nb)
        Upper band of the per-coordinate Hessian.
    g : ndarray, shape (2 nb,)
        Linear term of the control points.
    layout : ConstraintLayout
        :func:`constraint_layout` ``(nb, p, m)`` with ``m > 0``.
    trip : ndarray
        Its triplet values (:meth:`ConstraintLayout.values`).
    lbx, ubx : ndarray, shape (2 nb + S,)
        Variable bounds, slacks last.
    lba, uba : ndarray, shape (layout.n_rows,)
        Row bounds (infinite allowed).
    active : ndarray of bool, shape (S,)
        The samples whose rows (and slack) enter the problem.
    slack_penalty : float
        Linear cost of each slack.

    Returns
    -------
    z : ndarray, shape (2 nb,)
        The control points (zeros on failure).
    cost : float
        The objective ``1/2 z'Hz + g'z + penalty * sum(slacks)`` at the solution.
    success : bool
    status : str
    iterations : int
    """
    import piqp

    solver = piqp.SparseSolver()
    solver.settings.verbose = False
    solver.setup(
        *working_set_matrices(full, g, layout, trip, lbx, ubx, lba, uba, active, slack_penalty)
    )
    return piqp_result(solver, 2 * layout.nb)


#: piqp's tolerances for the SCP's QPs (:class:`WorkingSetSolver`), looser than its defaults
#: (``1e-8`` absolute, ``1e-9`` relative): each QP is a local model whose step the SCP then
#: measures on the true constraints, and the certificate checks the final curve.
SCP_QP_TOLERANCES = {
    "eps_abs": 1e-6,
    "eps_rel": 1e-7,
    "eps_duality_gap_abs": 1e-6,
    "eps_duality_gap_rel": 1e-7,
}


class WorkingSetSolver:
    """:func:`solve_working_set` for the successive QPs of one sequential convex programme.

    The SCP's QPs share the Hessian, the corridor rows and, while the working set and the
    rows' nonzero pattern stay the same, the sparsity of the constraint matrix. The first
    call (and a call whose pattern changed) sets piqp up as :func:`solve_working_set` does;
    the others reuse the set-up solver, giving only the new values to piqp's ``update`` (its
    symbolic factorisation and the Hessian are kept), which skips rebuilding the sparse
    matrices and refactoring symbolically: about a third of an SCP iteration's time on
    car segments of 30-40 control points.
    """

    def __init__(self) -> None:
        self.solver = None
        self.sel: np.ndarray | None = None  # the triplets the set-up solver holds
        self.order: np.ndarray | None = None  # their positions in its CSC data
        self.G = None

    def __call__(
        self,
        full: np.ndarray,
        g: np.ndarray,
        layout: ConstraintLayout,
        trip: np.ndarray,
        lbx: np.ndarray,
        ubx: np.ndarray,
        lba: np.ndarray,
        uba: np.ndarray,
        active: np.ndarray,
        slack_penalty: float,
    ) -> tuple[np.ndarray, float, bool, str, int]:
        """Solve as :func:`solve_working_set` (same arguments and result)."""
        keep_row, keep_col, sel = _working_set_selection(layout, trip, lba, uba, active)
        if self.solver is not None and np.array_equal(sel, self.sel):
            G = self.G
            G.data[:] = trip[sel][self.order]
            lo_r, hi_r = layout.implied_range(trip, lbx, ubx, select=sel)
            c = np.concatenate([g, np.full(int(active.sum()), slack_penalty)])
            self.solver.update(
                c=c,
                G=G,
                h_l=np.maximum(lba, lo_r - 1.0)[keep_row],
                h_u=np.minimum(uba, hi_r + 1.0)[keep_row],
                x_l=lbx[keep_col],
                x_u=ubx[keep_col],
            )
            return piqp_result(self.solver, 2 * layout.nb)
        import piqp
        import scipy.sparse as sps

        args = working_set_matrices(
            full, g, layout, trip, lbx, ubx, lba, uba, active, slack_penalty
        )
        G = args[4]
        # the CSC position of each selected triplet: the matrix rebuilt from their ranks
        n_sel = int(sel.sum())
        new_row = np.cumsum(keep_row) - 1
        new_col = np.cumsum(keep_col) - 1
        rank = sps.csc_matrix(
            (
                np.arange(1, n_sel + 1, dtype=float),
                (new_row[layout.trip_rows[sel]], new_col[layout.trip_cols[sel]]),
            ),
            shape=G.shape,
        )
        if rank.nnz != n_sel or not np.array_equal(rank.indices, G.indices):
            self.solver = None  # duplicate triplets: no reuse (every call sets up)
            return solve_working_set(
                full, g, layout, trip, lbx, ubx, lba, uba, active, slack_penalty
            )
        self.order = rank.data.astype(np.int64) - 1
        self.sel, self.G = sel, G
        self.solver = piqp.SparseSolver()
        self.solver.settings.verbose = False
        for name, value in SCP_QP_TOLERANCES.items():
            setattr(self.solver.settings, name, value)
        self.solver.setup(*args)
        return piqp_result(self.solver, 2 * layout.nb)


def _working_set_selection(
    layout: ConstraintLayout,
    trip: np.ndarray,
    lba: np.ndarray,
    uba: np.ndarray,
    active: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return the kept rows, the kept columns and the selected triplets of a working set."""
    n_fixed = layout.sample_row0
    keep_row = np.ones(layout.n_rows, dtype=bool)
    keep_row[n_fixed:] = np.repeat(active, 3)
    keep_row &= np.isfinite(lba) | np.isfinite(uba)
    keep_col = np.concatenate([np.ones(2 * layout.nb, dtype=bool), active])
    sel = keep_row[layout.trip_rows] & keep_col[layout.trip_cols] & (trip != 0.0)
    return keep_row, keep_col, sel


def working_set_matrices(
    full: np.ndarray,
    g: np.ndarray,
    layout: ConstraintLayout,
    trip: np.ndarray,
    lbx: np.ndarray,
    ubx: np.ndarray,
    lba: np.ndarray,
    uba: np.ndarray,
    active: np.ndarray,
    slack_penalty: float,
) -> tuple:
    """Return piqp's ``setup`` arguments for :func:`solve_working_set`'s problem.

    ``(P, c, A, b, G, h_l, h_u, x_l, x_u)``.

    The arguments are :func:`solve_working_set`'s; no equality block (``A``, ``b`` are
    ``None``): the fixed rows enter ``G`` with equal bounds.
    """
    import scipy.sparse as sps

    keep_row, keep_col, sel = _working_set_selection(layout, trip, lba, uba, active)
    new_row = np.cumsum(keep_row) - 1
    new_col = np.cumsum(keep_col) - 1
    n_cols = int(keep_col.sum())
    A = sps.csc_matrix(
        (trip[sel], (new_row[layout.trip_rows[sel]], new_col[layout.trip_cols[sel]])),
        shape=(int(keep_row.sum()), n_cols),
    )
    P = band_hessian(full, n_cols)
    c = np.concatenate([g, np.full(int(active.sum()), slack_penalty)])
    # large finite row bounds hurt piqp's conditioning: bound each row by its range
    # (every triplet of a kept row is selected: its columns are kept, zeros add nothing)
    lo_r, hi_r = layout.implied_range(trip, lbx, ubx, select=sel)
    h_l = np.maximum(lba, lo_r - 1.0)[keep_row]
    h_u = np.minimum(uba, hi_r + 1.0)[keep_row]
    return P, c, None, None, A, h_l, h_u, lbx[keep_col], ubx[keep_col]


def band_hessian(full: np.ndarray, n_cols: int):
    """Upper triangle of ``blockdiag(Hb, Hb)`` (CSC, ``n_cols`` square) from the band ``full``.

    Every band entry is stored (zeros included), so the pattern depends only on the shape:
    piqp's ``update`` needs the pattern of its ``setup``.
    """
    import scipy.sparse as sps

    p1, nb = full.shape
    indptr, indices, d, col = _band_csc(nb, p1 - 1, n_cols)
    return sps.csc_matrix((full[d, col], indices, indptr), shape=(n_cols, n_cols))


@functools.lru_cache(maxsize=64)
def _band_csc(nb: int, p: int, n_cols: int) -> tuple[np.ndarray, ...]:
    """CSC ``indptr``, ``indices`` of :func:`band_hessian` and each entry's band position."""
    import scipy.sparse as sps

    hr, hc, hd, hcol = upper_band_triplets(nb, p)
    m = sps.csc_matrix((np.arange(1, len(hr) + 1, dtype=float), (hr, hc)), shape=(n_cols, n_cols))
    order = m.data.astype(np.int64) - 1
    return m.indptr.copy(), m.indices.copy(), hd[order], hcol[order]


def piqp_result(solver, n_z: int) -> tuple[np.ndarray, float, bool, str, int]:
    """``(z, cost, success, status, iterations)`` of a piqp ``solve`` (``z`` its first ``n_z``)."""
    import piqp

    status = solver.solve()
    x = np.asarray(solver.result.x, dtype=float)
    success = status == piqp.PIQP_SOLVED and bool(np.all(np.isfinite(x)))
    z = x[:n_z] if success else np.zeros(n_z)
    cost = float(solver.result.info.primal_obj) if success else float("nan")
    return z, cost, success, str(status), int(solver.result.info.iter)


class RoundSolver:
    """:func:`solve_qp` for a sequence of QPs that differ only in Hessian and linear term.

    The sequential rounds of the cost term (:func:`~trajopt.smoother._cost.cost_rounds`)
    solve the attempt's QP again and again with a new Hessian band and linear term and the
    same rows and bounds. On a polygon corridor with piqp, the first call sets piqp up and
    later calls only ``update`` ``P`` and ``c`` (piqp keeps its symbolic factorisation and
    the constraint matrix); otherwise every call is :func:`solve_qp`.

    Parameters
    ----------
    base : QPData
        The attempt's QP: the rows and bounds every call shares.
    """

    def __init__(self, base: QPData) -> None:
        self.base = base
        self.solver = None
        self.n_cols = 0

    def __call__(self, options: Smoother, qp: QPData, x0: np.ndarray | None = None) -> SolveInfo:
        """Solve ``qp`` (``base`` with another ``full`` and ``g``); see :func:`solve_qp`."""
        if options.qp_solver != "piqp" or qp.region_coef is None:
            return solve_qp(options, qp, x0)
        ts = time.perf_counter()
        tc = time.process_time()
        if self.solver is None:
            import piqp

            b = self.base
            layout = constraint_layout(b.nb, options.degree, 0, b.k)
            trip = layout.values(b.heading, None, b.region_coef)
            args = working_set_matrices(
                qp.full, qp.g, layout, trip, b.lbx, b.ubx, b.lba, b.uba, np.zeros(0, bool), 0.0
            )
            self.n_cols = args[0].shape[0]
            self.solver = piqp.SparseSolver()
            self.solver.settings.verbose = False
            self.solver.setup(*args)
        else:
            self.solver.update(P=band_hessian(qp.full, self.n_cols), c=qp.g)
        z, *result = piqp_result(self.solver, 2 * qp.nb)
        return piqp_info(z, result, ts, tc)


def piqp_info(z: np.ndarray, result: tuple, t_wall: float, t_cpu: float) -> SolveInfo:
    """Return the :class:`SolveInfo` of a direct piqp solve.

    The :class:`SolveInfo` of a direct piqp solve from :func:`solve_working_set`'s ``(cost,
    success, status, iterations)`` and the wall and CPU clocks at its start.
    """
    cost, success, status, iters = result
    return SolveInfo(
        solver="piqp",
        status=SolveStatus.SOLVED if success else SolveStatus.SOLVER_FAILED,
        detail=status,
        iterations=iters,
        solve_time_s=time.perf_counter() - t_wall,
        solve_cpu_s=time.process_time() - t_cpu,
        build_time_s=0.0,
        cost=cost,
        z=z,
    )


_WARM: list[str] = []  # what warm_imports has loaded: "casadi", "piqp"


def warm_imports(casadi: bool = True) -> None:
    """Load the heavy modules and the certificate's compiled kernel once per process.

    piqp and scipy (and casadi when ``casadi``: the fits that go through ``casadi.conic`` or
    IPOPT) are imported and the clearance kernel is loaded (or compiled) before a fit starts
    its clock, so that neither counts against its budget.
    """
    if casadi and "casadi" not in _WARM:
        import casadi as ca  # noqa: F401

        _WARM.append("casadi")
    if "piqp" in _WARM:
        return
    import piqp  # noqa: F401
    import scipy.sparse  # noqa: F401

    from astar.grid import OccupancyGrid
    from trajopt.geometry import points_clearance

    points_clearance(np.zeros((1, 2)), OccupancyGrid(np.zeros((2, 2), bool), 1.0), 1.0)
    _WARM.append("piqp")


def solve_qp(options: Smoother, qp: QPData, x0: np.ndarray | None = None) -> SolveInfo:
    """One solve of the corridor QP (no curvature rows) by ``options.qp_solver``.

    Parameters
    ----------
    options : Smoother
        ``degree``, ``qp_solver`` and ``verbose`` are used.
    qp : QPData
        The problem (cell units, padded).
    x0 : ndarray, shape (2 nb,), optional
        Starting point of solvers that take one.

    Returns
    -------
    SolveInfo
        With the solution ``z`` (shape (2 nb,)).
    """
    p = options.degree
    nb = qp.nb
    solver_name = options.qp_solver
    lbx, ubx, lba, uba = qp.lbx, qp.ubx, qp.lba, qp.uba
    if x0 is None:
        x0 = np.zeros(2 * nb)
    ts = time.perf_counter()
    tc = time.process_time()
    if solver_name == "piqp" and qp.region_coef is not None:
        # polygon rows: piqp directly, without the rows a point does not use (a
        # casadi.conic keeps every padded row of its fixed sparsity)
        layout = constraint_layout(nb, p, 0, qp.k)
        trip = layout.values(qp.heading, None, qp.region_coef)
        z, *result = solve_working_set(
            qp.full, qp.g, layout, trip, lbx, ubx, lba, uba, np.zeros(0, bool), 0.0
        )
        return piqp_info(z, result, ts, tc)
    tb = time.perf_counter()
    built = is_built(f"{solver_name}-0-{qp.k}", nb, p, options.verbose)
    if solver_name == "ipopt":
        # the layout's rows (box or polygon corridor) with their non-zeros as parameters
        solver = qp_ipopt(nb, p, qp.k, options.verbose)
        build = 0.0 if built else time.perf_counter() - tb
        ts = time.perf_counter()
        tc = time.process_time()
        out = solver(x0=x0, p=qp_parameters(qp, p), lbx=lbx, ubx=ubx, lbg=lba, ubg=uba)
        info = ipopt_info(
            solver, out, time.perf_counter() - ts, time.process_time() - tc, build, np.inf
        )
        info.z = info.z[: 2 * nb]
        return info
    solver = qp_solver(nb, p, solver_name, 0, options.verbose, qp.k)
    build = 0.0 if built else time.perf_counter() - tb
    ts = time.perf_counter()
    tc = time.process_time()
    import casadi as ca

    layout = constraint_layout(nb, p, 0, qp.k)
    hnz = h_nonzeros(qp.full, nb, p)
    trip = layout.values(qp.heading, None, qp.region_coef)
    if solver_name == "piqp":
        # piqp warns about (and drops) infinite rows, and large finite ones hurt
        # its conditioning: bound every row by its range over the variable bounds
        lo_r, hi_r = layout.implied_range(trip, lbx, ubx)
        lba = np.maximum(lba, lo_r - 1.0)
        uba = np.minimum(uba, hi_r + 1.0)
        gap = lba - uba
        if np.any(gap > 0.0):  # a row out of reach of the variable bounds
            i = int(np.argmax(gap))
            return SolveInfo(
                solver=solver_name,
                status=SolveStatus.SOLVER_FAILED,
                detail=f"primal infeasible: row {i} is out of reach of the variable bounds",
                build_time_s=build,
                z=np.full(2 * nb, np.nan),
            )
    hval = ca.DM(solver.sparsity_in("h"), hnz)
    aval = ca.DM(layout.sparsity, layout.nonzeros(trip))
    out = solver(h=hval, g=qp.g, a=aval, lbx=lbx, ubx=ubx, lba=lba, uba=uba, x0=x0)
    solve = time.perf_counter() - ts
    cpu = time.process_time() - tc
    st = solver.stats()
    z = np.asarray(out["x"], dtype=float).ravel()[: 2 * nb]
    success = bool(st.get("success", False)) and bool(np.all(np.isfinite(z)))
    return SolveInfo(
        solver=solver_name,
        status=SolveStatus.SOLVED if success else SolveStatus.SOLVER_FAILED,
        detail=str(st.get("return_status", st.get("unified_return_status", ""))),
        iterations=int(st.get("iter_count", st.get("iter", 0)) or 0),
        solve_time_s=solve,
        solve_cpu_s=cpu,
        build_time_s=build,
        cost=float(out["cost"]) if "cost" in out else float("nan"),
        z=z,
    )
