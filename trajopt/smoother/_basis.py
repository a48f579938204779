"""B-spline basis maths of the smoother, in cell units.

Basis derivatives, the banded Gram and smoothness matrices, the padded problem sizes, and the
value of the banded quadratic.

Everything here is NumPy; the solvers that use these arrays are in
:mod:`trajopt.smoother._qp`, :mod:`trajopt.smoother._scp` and :mod:`trajopt.smoother._nlp`.
"""

from __future__ import annotations

import functools

import numpy as np

#: curvature samples per span (its start and interior points; the last span also its end)
CURV_SAMPLES = 4

#: padded problem sizes, about 12 % apart (the padded variables and sample rows cost solver
#: time, each new size costs a solver build of a few ms)
_SIZES = (
    16,
    20,
    24,
    28,
    32,
    36,
    40,
    44,
    48,
    56,
    64,
    72,
    80,
    88,
    96,
    104,
    112,
    128,
    144,
    160,
    176,
    192,
    216,
    240,
    272,
    304,
    336,
    376,
    416,
    464,
    512,
    576,
    640,
    720,
    800,
    896,
    1024,
)


def bucket_size(n: int) -> int:
    """Return the padded number of control points for ``n`` (sizes repeat so solvers can be cached)."""
    for s in _SIZES:
        if n <= s:
            return s
    return int(256 * np.ceil(n / 256))


def basis_derivs(t: np.ndarray, p: int, span: np.ndarray, u: np.ndarray, nu: int) -> np.ndarray:
    """``nu``-th derivatives.

    ``nu``-th derivatives of the ``p + 1`` B-splines of degree ``p`` that are non-zero on span
    ``span`` (control points ``span .. span + p``), evaluated at ``u``.

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
    """Upper band of ``sum_r w_r b_r b_r^T`` for rows ``b_r``.

    Upper band of ``sum_r w_r b_r b_r^T`` for rows ``b_r`` with ``p + 1`` consecutive non-zeros
    ``vals[r]`` starting at column ``span[r]``: ``band[d, i] = M[i, i + d]``.
    """
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


@functools.lru_cache(maxsize=16)
def gauss_legendre(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights on ``[-1, 1]``, read-only, computed once per ``n``.

    numpy's ``leggauss`` solves an eigenproblem, a quarter of a millisecond each call.
    """
    x, w = np.polynomial.legendre.leggauss(n)
    x.flags.writeable = False
    w.flags.writeable = False
    return x, w


def smoothness_band(t: np.ndarray, p: int, n: int, order: int) -> np.ndarray:
    """Upper band of ``S[i, j] = integral B_i^(order)(u) B_j^(order)(u) du``.

    Upper band of ``S[i, j] = integral B_i^(order)(u) B_j^(order)(u) du`` (exact, by
    Gauss-Legendre quadrature on every non-empty span).
    """
    nq = max(1, p - order + 1)
    gx, gw = gauss_legendre(nq)
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


def band_quadratic(full: np.ndarray, g: np.ndarray, z: np.ndarray, const: float = 0.0) -> float:
    """``1/2 z' H z + g' z + const`` for the two-block banded Hessian ``H``.

    Parameters
    ----------
    full : ndarray, shape (p + 1, nb)
        Upper band of one coordinate block (``full[d, i] = H[i, i + d]``).
    g : ndarray, shape (2 nb,)
        Linear term (x block, then y block).
    z : ndarray, shape (2 nb,)
        Control points ``[x_0 .. x_{nb-1}, y_0 .. y_{nb-1}]`` (cells).
    const : float
        Constant term.
    """
    nb = full.shape[1]
    x, y = z[:nb], z[nb : 2 * nb]
    f = float(g @ z[: 2 * nb]) + const
    for d in range(full.shape[0]):
        w = 0.5 if d == 0 else 1.0
        f += w * float(full[d, : nb - d] @ (x[: nb - d] * x[d:] + y[: nb - d] * y[d:]))
    return f


def curvature_samples(
    t: np.ndarray, p: int, n: int, nb: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Span index and first/second basis derivatives at ``CURV_SAMPLES`` points per span.

    :func:`sample_bases` with orders 1 and 2.
    """
    span, (B1, B2) = sample_bases(t, p, n, nb, (1, 2))
    return span, B1, B2


def sample_bases(
    t: np.ndarray, p: int, n: int, nb: int, orders: tuple[int, ...]
) -> tuple[np.ndarray, list[np.ndarray]]:
    """Span index and basis derivatives of ``orders`` at ``CURV_SAMPLES`` points per span.

    Padded to ``nb - p`` spans (zero rows). A span is sampled at its start and at evenly
    spaced interior points; its end is the next span's start (``C``, ``C'`` and ``C''`` are
    continuous at the simple interior knots, so a sample there would repeat a row). The
    last span spreads its samples from its start to its end, so the curve's end is sampled
    too.

    Returns
    -------
    span : ndarray of int, shape ((n - p) CURV_SAMPLES,)
    bases : list of ndarray, shape ((nb - p) CURV_SAMPLES, p + 1) each
    """
    ms = CURV_SAMPLES
    ns = n - p
    fr = np.tile(np.arange(ms) / ms, (ns, 1))
    fr[-1] = np.linspace(0.0, 1.0, ms)
    a = t[p : p + ns]
    b = t[p + 1 : p + ns + 1]
    span = np.repeat(np.arange(ns), ms)
    uu = (a[:, None] + (b - a)[:, None] * fr).ravel()
    S = (nb - p) * ms
    out = []
    for nu in orders:
        B = np.zeros((S, p + 1))
        B[: ns * ms] = basis_derivs(t, p, span, uu, nu)
        out.append(B)
    return span, out
