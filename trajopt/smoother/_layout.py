"""The sparsity layout of the smoother's constraint matrix (:class:`ConstraintLayout`).

Shared by the QP solvers (:mod:`~trajopt.smoother._qp`), the SCP and the IPOPT problems
(:mod:`~trajopt.smoother._nlp`): the rows of the heading constraints, of every control
point's region and of the curvature samples, in cell units on ``nb`` padded control points.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any

import numpy as np

from trajopt.smoother._problem import N_HEADING_ROWS


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
        return casadi_sparsity(self.nb, self.p, self.m, self.k)

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
def casadi_sparsity(nb: int, p: int, m: int, k: int) -> Any:
    """Return the ``casadi.Sparsity`` of :func:`constraint_layout` ``(nb, p, m, k)``'s ``A``."""
    import casadi as ca

    layout = constraint_layout(nb, p, m, k)
    sp, mapping = ca.Sparsity.triplet(
        layout.n_rows, layout.n_cols, layout.trip_rows.tolist(), layout.trip_cols.tolist(), False
    )
    if not np.array_equal(np.asarray(mapping), layout.nz_from_triplet):  # pragma: no cover
        raise AssertionError("casadi's CCS order differs from the layout's")
    return sp
