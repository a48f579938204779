"""Private: B-spline basis evaluation, the banded least-squares/smoothness QP data, and
cached CasADi solvers (a ``casadi.conic`` QP and an IPOPT curvature-bounded NLP) built once
per padded problem size.

Everything here works in *cell units* (positions and parameters divided by the grid
resolution), so one set of weights and tolerances serves every map.
"""

from __future__ import annotations

import functools
import logging
import threading
from dataclasses import dataclass

import numpy as np

logger = logging.getLogger(__name__)

#: padded problem sizes, about 12 % apart (the padded variables and sample rows cost solver
#: time, each new size costs a solver build of a few ms)
_SIZES = (16, 20, 24, 28, 32, 36, 40, 44, 48, 56, 64, 72, 80, 88, 96, 104, 112, 128, 144, 160,
          176, 192, 216, 240, 272, 304, 336, 376, 416, 464, 512, 576, 640, 720, 800, 896, 1024)


def bucket_size(n: int) -> int:
    """Padded number of control points for ``n`` (sizes repeat so solvers can be cached)."""
    for s in _SIZES:
        if n <= s:
            return s
    return int(256 * np.ceil(n / 256))


# ---------------------------------------------------------------------- basis
def basis_derivs(t: np.ndarray, p: int, span: np.ndarray, u: np.ndarray, nu: int) -> np.ndarray:
    """``nu``-th derivatives of the ``p + 1`` B-splines of degree ``p`` that are non-zero on
    span ``span`` (control points ``span .. span + p``), evaluated at ``u``.

    Parameters
    ----------
    t : ndarray, shape (n + p + 1,)
        Clamped knots.
    p : int
        Degree.
    span : ndarray of int, shape (M,)
        Span index ``j`` (knot interval ``[t[j + p], t[j + p + 1]]``) of each point.
    u : ndarray, shape (M,)
        Parameters (inside or on the boundary of their spans).
    nu : int
        Derivative order (0 .. p).

    Returns
    -------
    ndarray, shape (M, p + 1)
    """
    k = np.asarray(span, dtype=np.int64) + p  # knot interval index
    u = np.asarray(u, dtype=float)
    m = len(u)
    q0 = p - nu
    # degree-q0 non-zero basis values N_{k-q0 .. k, q0}(u) by Cox-de Boor
    vals = np.ones((m, 1))
    for q in range(1, q0 + 1):
        new = np.zeros((m, q + 1))
        for a in range(q + 1):
            i = k - q + a  # basis index
            if a >= 1:  # N_{i, q-1} is vals[:, a-1]
                den = t[i + q] - t[i]
                with np.errstate(divide="ignore", invalid="ignore"):
                    w = np.where(den > 0, (u - t[i]) / np.where(den > 0, den, 1.0), 0.0)
                new[:, a] += w * vals[:, a - 1]
            if a <= q - 1:  # N_{i+1, q-1} is vals[:, a]
                den = t[i + q + 1] - t[i + 1]
                with np.errstate(divide="ignore", invalid="ignore"):
                    w = np.where(den > 0, (t[i + q + 1] - u) / np.where(den > 0, den, 1.0), 0.0)
                new[:, a] += w * vals[:, a]
        vals = new
    # raise to degree p through the derivative recurrence
    for q in range(q0 + 1, p + 1):
        new = np.zeros((m, q + 1))
        for a in range(q + 1):
            i = k - q + a
            if a >= 1:
                den = t[i + q] - t[i]
                new[:, a] += (
                    np.where(den > 0, q / np.where(den > 0, den, 1.0), 0.0) * vals[:, a - 1]
                )
            if a <= q - 1:
                den = t[i + q + 1] - t[i + 1]
                new[:, a] -= np.where(den > 0, q / np.where(den > 0, den, 1.0), 0.0) * vals[:, a]
        vals = new
    return vals


def find_spans(t: np.ndarray, p: int, n: int, u: np.ndarray) -> np.ndarray:
    """Span index (0 .. n - p - 1) holding each parameter ``u``."""
    j = np.searchsorted(t, u, side="right") - 1
    return np.clip(j, p, n - 1) - p


def band_gram(span: np.ndarray, vals: np.ndarray, weights: np.ndarray, n: int) -> np.ndarray:
    """Upper band of ``sum_r w_r b_r b_r^T`` for rows ``b_r`` with ``p + 1`` consecutive
    non-zeros ``vals[r]`` starting at column ``span[r]``: ``band[d, i] = M[i, i + d]``."""
    p = vals.shape[1] - 1
    band = np.zeros((p + 1, n))
    for a in range(p + 1):
        for b in range(a, p + 1):
            band[b - a] += np.bincount(
                span + a, weights=weights * vals[:, a] * vals[:, b], minlength=n
            )
    return band


def band_rhs(span: np.ndarray, vals: np.ndarray, rhs: np.ndarray, n: int) -> np.ndarray:
    """``B^T rhs`` for the row-banded matrix of :func:`band_gram`; ``rhs`` shape (M, d)."""
    out = np.zeros((n, rhs.shape[1]))
    for a in range(vals.shape[1]):
        for dim in range(rhs.shape[1]):
            out[:, dim] += np.bincount(span + a, weights=vals[:, a] * rhs[:, dim], minlength=n)
    return out


def smoothness_band(t: np.ndarray, p: int, n: int, order: int) -> np.ndarray:
    """Upper band of ``S[i, j] = integral B_i^(order)(u) B_j^(order)(u) du`` (exact, by
    Gauss-Legendre quadrature on every non-empty span)."""
    nq = max(1, p - order + 1)
    gx, gw = np.polynomial.legendre.leggauss(nq)
    a = t[p:n]
    b = t[p + 1 : n + 1]
    half = 0.5 * (b - a)
    keep = half > 0
    spans = np.nonzero(keep)[0]
    uq = (0.5 * (a + b))[keep][:, None] + half[keep][:, None] * gx[None, :]
    wq = half[keep][:, None] * gw[None, :]
    span_q = np.repeat(spans, nq)
    vals = basis_derivs(t, p, span_q, uq.ravel(), order)
    return band_gram(span_q, vals, wq.ravel(), n)


# -------------------------------------------------------------------- solvers
_LOCK = threading.Lock()


def _band_pattern(nb: int, p: int):
    """CCS (row, col) of the symmetric band |i - j| <= p of an nb x nb matrix."""
    rows, cols = [], []
    for c in range(nb):
        r = np.arange(max(0, c - p), min(nb, c + p + 1))
        rows.append(r)
        cols.append(np.full(len(r), c))
    return np.concatenate(rows), np.concatenate(cols)


#: heading rows at the top of every constraint matrix (start/goal tangent; see smoother)
N_HEADING_ROWS = 4


@functools.lru_cache(maxsize=64)
def qp_layout(nb: int, p: int):
    """Sparsity of the two-block banded Hessian (x block then y block) and the index map
    from CCS non-zeros to ``(band offset, band column)``."""
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
    """Rows of the linear constraints ``lba <= A z <= uba`` for ``nb`` padded control
    points (``z = [x_0..x_{nb-1}, y_0..y_{nb-1}]``, then with ``m > 0`` one slack per
    curvature sample), ``m`` curvature samples per span and ``k`` region rows per control
    point.

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
    sparsity: object
    #: CCS non-zero k takes triplet value ``nz_from_triplet[k]``
    nz_from_triplet: np.ndarray
    n_triplets: int
    #: row and column of every triplet
    trip_rows: np.ndarray
    trip_cols: np.ndarray

    @property
    def n_samples(self) -> int:
        return (self.nb - self.p) * self.m

    @property
    def sample_row0(self) -> int:
        return N_HEADING_ROWS + self.k * self.nb

    def values(
        self,
        heading: np.ndarray,
        sample_vals: np.ndarray | None = None,
        region_coef: np.ndarray | None = None,
    ) -> np.ndarray:
        """Triplet values of ``A`` from the dense heading rows (4, 2nb), the sample rows'
        coefficients (S, 3, 2 (p + 1)): ``[x_j..x_{j+p}, y_j..y_{j+p}]`` per row, and the
        region rows' coefficients ``(a_x, a_y)`` (nb, k, 2) (default, for ``k = 2``: the
        rows ``x + y`` and ``x - y``)."""
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
        """Range of every row ``A z`` over the variable bounds (interval arithmetic);
        ``select`` (bool per triplet): only those triplets (rows with none get 0)."""
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
    """The :class:`ConstraintLayout` for ``nb`` padded control points, degree ``p``, ``m``
    curvature samples per span (0: no sample rows) and ``k`` region rows per control point."""
    import casadi as ca

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
            [span[:, None] + np.arange(p + 1), nb + span[:, None] + np.arange(p + 1),
             2 * nb + np.arange(S)[:, None]],
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
    sp, mapping = ca.Sparsity.triplet(n_rows, n_cols, rows_a.tolist(), cols_a.tolist(), False)
    return ConstraintLayout(
        nb=nb,
        p=p,
        m=m,
        k=k,
        n_rows=n_rows,
        sparsity=sp,
        nz_from_triplet=np.asarray(mapping, dtype=np.int64),
        n_triplets=len(rows_a),
        trip_rows=rows_a,
        trip_cols=cols_a,
    )


@functools.lru_cache(maxsize=128)
def qp_solver(nb: int, p: int, solver: str, m: int, verbose: bool, k: int = 2):
    """A ``casadi.conic`` QP ``min 1/2 z'Hz + g'z, lbx <= z <= ubx, lba <= A z <= uba``
    with the banded two-block Hessian and :func:`constraint_layout` ``(nb, p, m, k)``;
    built once per ``(nb, p, solver, m, k)``."""
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
    with _LOCK:
        return ca.conic(f"smoother_qp_{m}_{k}", solver, {"h": sp_h, "a": sp_a}, opts)


@functools.lru_cache(maxsize=32)
def qp_ipopt(nb: int, p: int, verbose: bool):
    """The same convex problem (no sample rows) solved by IPOPT (fallback / reference);
    parameters ``[h band (p+1)*nb, g (2nb), heading rows (4*2nb)]``."""
    import casadi as ca

    z = ca.SX.sym("z", 2 * nb)
    hb = ca.SX.sym("hb", (p + 1) * nb)
    g = ca.SX.sym("g", 2 * nb)
    a = ca.SX.sym("a", N_HEADING_ROWS * 2 * nb)
    f = _band_quadratic(z, hb, nb, p) + ca.dot(g, z)
    amat = ca.reshape(a, N_HEADING_ROWS, 2 * nb)
    nlp = {"x": z, "p": ca.vertcat(hb, g, a), "f": f,
           "g": ca.vertcat(ca.mtimes(amat, z), _diag_rows(z, nb))}
    with _LOCK:
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


#: curvature samples per span (its start and interior points; the last span also its end)
CURV_SAMPLES = 4


@functools.lru_cache(maxsize=16)
def curvature_nlp(nb: int, p: int, verbose: bool):
    """IPOPT problem: the QP objective, the heading and diagonal rows, and per sample ``r``
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
    with _LOCK:
        return ca.nlpsol("smoother_curv", "ipopt", nlp, _ipopt_opts(verbose))


@functools.lru_cache(maxsize=64)
def upper_band_triplets(nb: int, p: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Upper triangle of the two-block banded Hessian: rows, columns, and the ``(band
    offset, band column)`` of each entry's value."""
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
    """One QP of the sequential convex programme with only the ``active`` curvature
    samples, solved by piqp directly (the rows of the other samples and their slacks are
    left out: the problem's sparsity changes with the working set, which a
    ``casadi.conic`` fixes at build time). With ``m = 0`` (no samples) it is the corridor
    QP itself; rows with only zero coefficients or no finite bound are left out too (the
    padded region rows of a polygon corridor).

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
