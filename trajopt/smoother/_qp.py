"""The convex corridor QP of the smoother.

Constraint layouts, cached ``casadi.conic`` builds, the direct piqp solve over a working set,
and one call that solves the QP.

Everything works in cell units on ``nb`` padded control points (solvers are built once per
padded size and cached for the process).
"""

from __future__ import annotations

import functools
import logging
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from trajopt.smoother._nlp import ipopt_info, qp_ipopt, qp_parameters
from trajopt.smoother._problem import N_HEADING_ROWS, QPData
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


@dataclass(frozen=True)
class ConstraintLayout:
    """Rows of the linear constraints ``lba <= A z <= uba`` for ``nb`` padded control points.

    Rows of the linear constraints ``lba <= A z <= uba`` for ``nb`` padded control points (``z =
    [x_0..x_{nb-1}, y_0..y_{nb-1}]``, then with ``m > 0`` one slack per curvature sample), ``m``
    curvature samples per span and ``k`` region rows per control point.

    Rows, in order: the :data:`N_HEADING_ROWS` heading rows (dense); for every control
    point ``i`` its ``k`` region rows ``a_x x_i + a_y y_i`` (box corridors: ``k = 2``, the
    rows ``x_i + y_i`` and ``x_i - y_i`` of the 45-degree bounds of bridge regions;
    polygon corridors: the half-planes of the regions of the point's spans, unused rows
    with zero coefficients and infinite bounds); then, for every sample ``r`` (``S = (nb - p) * m``, span ``r // m``), the
    rows ``curvature+``, ``curvature-`` and ``speed`` of the sequential convex programme
    (each over the ``2 (p + 1)`` coordinates of the span's control points and the sample's
    slack, with coefficients -1, -1 and +1: an exact l1 penalty keeps every QP feasible).
    """

    nb: int
    p: int
    m: int
    k: int
    n_rows: int
    n_cols: int
    #: CCS non-zero k takes triplet value ``nz_from_triplet[k]``
    nz_from_triplet: np.ndarray
    n_triplets: int
    #: row and column of every triplet
    trip_rows: np.ndarray
    trip_cols: np.ndarray

    @property
    def n_samples(self) -> int:
        """Number of curvature samples ``S``."""
        return (self.nb - self.p) * self.m

    @property
    def sparsity(self) -> Any:
        """The ``casadi.Sparsity`` of ``A`` (for the ``casadi.conic`` solves; built once)."""
        return _casadi_sparsity(self.nb, self.p, self.m, self.k)

    @property
    def sample_row0(self) -> int:
        """Index of the first sample row."""
        return N_HEADING_ROWS + self.k * self.nb

    def values(
        self,
        heading: np.ndarray,
        sample_vals: np.ndarray | None = None,
        region_coef: np.ndarray | None = None,
    ) -> np.ndarray:
        """Triplet values of ``A`` from the dense heading rows.

        Triplet values of ``A`` from the dense heading rows (4, 2nb), the sample rows'
        coefficients (S, 3, 2 (p + 1)): ``[x_j..x_{j+p}, y_j..y_{j+p}]`` per row, and the region
        rows' coefficients ``(a_x, a_y)`` (nb, k, 2) (default, for ``k = 2``: the rows ``x + y``
        and ``x - y``).
        """
        nb = self.nb
        trip = np.empty(self.n_triplets)
        k = N_HEADING_ROWS * 2 * nb
        trip[:k] = heading.ravel()
        if region_coef is None:
            if self.k != 2:
                raise ValueError(f"region_coef is required for k = {self.k} region rows")
            region_coef = np.broadcast_to(np.array([[1.0, 1.0], [1.0, -1.0]]), (nb, 2, 2))
        trip[k : k + 2 * self.k * nb] = np.asarray(region_coef, dtype=float).ravel()
        k += 2 * self.k * nb
        if self.m:
            rows = trip[k:].reshape(self.n_samples, 3, 2 * (self.p + 1) + 1)
            rows[:, :, :-1] = 0.0 if sample_vals is None else sample_vals
            rows[:, :, -1] = (-1.0, -1.0, 1.0)  # slack: relaxes each row towards feasible
        return trip

    def nonzeros(self, trip: np.ndarray) -> np.ndarray:
        """CCS non-zeros from triplet values (:meth:`values`)."""
        return trip[self.nz_from_triplet]

    def implied_range(
        self, trip: np.ndarray, lbx: np.ndarray, ubx: np.ndarray, select: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """Range of every row ``A z`` over the variable bounds (interval arithmetic).

        ``select`` (bool per triplet): only those triplets (rows with none get 0).
        """
        rows, cols = self.trip_rows, self.trip_cols
        if select is not None:
            trip, rows, cols = trip[select], rows[select], cols[select]
        lo_v = lbx[cols]
        hi_v = ubx[cols]
        with np.errstate(invalid="ignore"):
            a = np.where(trip >= 0, trip * lo_v, trip * hi_v)
            b = np.where(trip >= 0, trip * hi_v, trip * lo_v)
        a[trip == 0] = 0.0
        b[trip == 0] = 0.0
        lo = np.bincount(rows, weights=a, minlength=self.n_rows)
        hi = np.bincount(rows, weights=b, minlength=self.n_rows)
        return lo, hi


@functools.lru_cache(maxsize=128)
def constraint_layout(nb: int, p: int, m: int, k: int = 2) -> ConstraintLayout:
    """Return the :class:`ConstraintLayout` for ``nb`` padded control points.

    The :class:`ConstraintLayout` for ``nb`` padded control points, degree ``p``, ``m``
    curvature samples per span (0: no sample rows) and ``k`` region rows per control point.
    """
    rows: list[np.ndarray] = []
    cols: list[np.ndarray] = []
    cols2 = np.arange(2 * nb)
    for r in range(N_HEADING_ROWS):
        rows.append(np.full(2 * nb, r))
        cols.append(cols2)
    i = np.arange(nb)
    # region row j of point i: row N_HEADING_ROWS + k i + j, columns x_i and y_i
    r0 = N_HEADING_ROWS + k * i[:, None] + np.arange(k)[None, :]
    rows.append(np.repeat(r0.ravel(), 2))
    cols.append(np.column_stack([np.repeat(i, k), np.repeat(nb + i, k)]).ravel())
    n_rows = N_HEADING_ROWS + k * nb
    n_cols = 2 * nb
    if m:
        S = (nb - p) * m
        span = np.arange(S) // m
        base = n_rows + 3 * np.arange(S)
        # per row: the span's x and y coordinates, then the sample's slack column
        cc = np.concatenate(
            [
                span[:, None] + np.arange(p + 1),
                nb + span[:, None] + np.arange(p + 1),
                2 * nb + np.arange(S)[:, None],
            ],
            axis=1,
        )
        rr = base[:, None, None] + np.arange(3)[None, :, None]
        w = 2 * (p + 1) + 1
        rows.append(np.broadcast_to(rr, (S, 3, w)).ravel())
        cols.append(np.broadcast_to(cc[:, None, :], (S, 3, w)).ravel())
        n_rows += 3 * S
        n_cols += S
    rows_a = np.concatenate(rows).astype(np.int64)
    cols_a = np.concatenate(cols).astype(np.int64)
    # compressed column storage: the triplets (all distinct) by column, then row
    return ConstraintLayout(
        nb=nb,
        p=p,
        m=m,
        k=k,
        n_rows=n_rows,
        n_cols=n_cols,
        nz_from_triplet=np.lexsort((rows_a, cols_a)).astype(np.int64),
        n_triplets=len(rows_a),
        trip_rows=rows_a,
        trip_cols=cols_a,
    )


@functools.lru_cache(maxsize=128)
def _casadi_sparsity(nb: int, p: int, m: int, k: int) -> Any:
    """Return the ``casadi.Sparsity`` of :func:`constraint_layout` ``(nb, p, m, k)``'s ``A``."""
    import casadi as ca

    layout = constraint_layout(nb, p, m, k)
    sp, mapping = ca.Sparsity.triplet(
        layout.n_rows, layout.n_cols, layout.trip_rows.tolist(), layout.trip_cols.tolist(), False
    )
    if not np.array_equal(np.asarray(mapping), layout.nz_from_triplet):  # pragma: no cover
        raise AssertionError("casadi's CCS order differs from the layout's")
    return sp


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
    import scipy.sparse as sps

    nb, p = layout.nb, layout.p
    n_fixed = layout.sample_row0
    keep_row = np.ones(layout.n_rows, dtype=bool)
    keep_row[n_fixed:] = np.repeat(active, 3)
    keep_row &= np.isfinite(lba) | np.isfinite(uba)
    keep_col = np.concatenate([np.ones(2 * nb, dtype=bool), active])
    sel = keep_row[layout.trip_rows] & keep_col[layout.trip_cols] & (trip != 0.0)
    new_row = np.cumsum(keep_row) - 1
    new_col = np.cumsum(keep_col) - 1
    n_cols = int(keep_col.sum())
    A = sps.csc_matrix(
        (trip[sel], (new_row[layout.trip_rows[sel]], new_col[layout.trip_cols[sel]])),
        shape=(int(keep_row.sum()), n_cols),
    )
    hr, hc, hd, hcol = upper_band_triplets(nb, p)
    P = sps.csc_matrix((full[hd, hcol], (hr, hc)), shape=(n_cols, n_cols))
    c = np.concatenate([g, np.full(int(active.sum()), slack_penalty)])
    # large finite row bounds hurt piqp's conditioning: bound each row by its range
    # (every triplet of a kept row is selected: its columns are kept, zeros add nothing)
    lo_r, hi_r = layout.implied_range(trip, lbx, ubx, select=sel)
    h_l = np.maximum(lba, lo_r - 1.0)[keep_row]
    h_u = np.minimum(uba, hi_r + 1.0)[keep_row]
    solver = piqp.SparseSolver()
    solver.settings.verbose = False
    solver.setup(P, c, None, None, A, h_l, h_u, lbx[keep_col], ubx[keep_col])
    status = solver.solve()
    x = np.asarray(solver.result.x, dtype=float)
    success = status == piqp.PIQP_SOLVED and bool(np.all(np.isfinite(x)))
    z = x[: 2 * nb] if success else np.zeros(2 * nb)
    cost = float(solver.result.info.primal_obj) if success else float("nan")
    return z, cost, success, str(status), int(solver.result.info.iter)


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
    from trajopt.geometry._clearance import points_clearance

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
