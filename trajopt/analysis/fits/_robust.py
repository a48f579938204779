"""The regression solvers behind the polynomial fits.

Weighted least squares, least absolute residual (a linear programme) and Tukey bisquare (robust
IRLS, as MATLAB's ``robustfit``).

Each takes a design matrix ``V`` of shape ``(n, p)``, data ``y`` of shape ``(n, d)`` and
weights ``w`` of shape ``(n,)``, and returns coefficients of shape ``(p, d)``.
"""

from __future__ import annotations

import logging
from typing import Literal

import numpy as np

logger = logging.getLogger(__name__)

FitMethod = Literal["least_squares", "lar", "bisquare"]
FIT_METHODS: tuple[str, ...] = ("least_squares", "lar", "bisquare")

#: Tukey bisquare tuning constant (95% efficiency for Gaussian residuals).
BISQUARE_C = 4.685
#: ``MAD / 0.6745`` estimates the standard deviation of Gaussian residuals (MATLAB's value
#: of the normal quartile ``Phi^-1(3/4) = 0.67449``).
_MAD_NORMAL = 0.6745


def wls(v: np.ndarray, y: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Weighted least squares ``min sum_i w_i |y_i - V_i c|^2``; ``y`` shape (n, d)."""
    sw = np.sqrt(w)[:, None]
    coef, *_ = np.linalg.lstsq(sw * v, sw * y, rcond=None)
    return coef


def lar(v: np.ndarray, y: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Least absolute residual ``min sum_i w_i |y_i - V_i c|`` per column, as an LP."""
    from scipy.optimize import linprog
    from scipy.sparse import csr_array, hstack, identity, vstack

    n, p = v.shape
    keep = w > 0
    vk, wk = v[keep], w[keep]
    nk = len(wk)
    eye = identity(nk, format="csr")
    vs = csr_array(vk)
    # variables [c (free, p), t (>= 0, nk)]:  V c - t <= y,  -V c - t <= -y
    a_ub = vstack([hstack([vs, -eye]), hstack([-vs, -eye])]).tocsr()
    cost = np.concatenate([np.zeros(p), wk])
    bounds = [(None, None)] * p + [(0, None)] * nk
    out = np.empty((p, y.shape[1]))
    for j in range(y.shape[1]):
        yk = y[keep, j]
        res = linprog(
            cost, A_ub=a_ub, b_ub=np.concatenate([yk, -yk]), bounds=bounds, method="highs"
        )
        if res.status != 0:
            logger.warning("LAR linear programme: %s; falling back to least squares", res.message)
            out[:, j] = wls(v, y[:, [j]], w)[:, 0]
        else:
            out[:, j] = res.x[:p]
    return out


def bisquare(
    v: np.ndarray,
    y: np.ndarray,
    w: np.ndarray,
    tol: float,
    max_iter: int,
    *,
    leverage: bool = True,
) -> tuple[np.ndarray, np.ndarray, int, bool]:
    """Robust IRLS with Tukey bisquare weights, as MATLAB's ``robustfit`` (``'bisquare'``).

    Starting from the (user-weighted) least-squares fit, each iteration computes

    * residuals ``r_i = y_i - V_i c`` (the Euclidean norm of the row when ``y`` has
      several columns), adjusted for leverage: ``r_adj_i = r_i / sqrt(1 - h_i)``, with
      ``h_i`` the diagonal of the hat matrix of the weighted design ``sqrt(w) V`` (fixed,
      clipped to 0.9999);
    * the scale ``s = max(MAD / 0.6745, s_min)``: ``MAD`` is the median of ``|r_adj_i|``
      (about **zero**, not about the median) over the points with ``w_i > 0`` after
      dropping the ``p - 1`` smallest (``p`` = number of coefficients), as ``robustfit``'s
      ``madsigma``; ``s_min = 1e-6`` times the largest standard deviation of a ``y``
      column (1 when that is 0) keeps an exact fit from dividing by zero;
    * Tukey weights ``b_i = (1 - u_i^2)^2`` for ``|u_i| < 1``, else 0, with
      ``u_i = r_adj_i / (c s)`` and ``c = BISQUARE_C = 4.685``;
    * the weighted least-squares fit with weights ``w_i b_i``;

    and stops when the fitted values move by at most ``tol`` times their largest
    magnitude. ``leverage=False`` (private, for tests) uses ``r_adj_i = r_i``.
    """
    p = v.shape[1]
    coef = wls(v, y, w)
    active = w > 0
    if leverage:
        # leverages of the weighted design (fixed, as in the usual robust-fit recipe)
        q, _ = np.linalg.qr(np.sqrt(w)[:, None] * v)
        h = np.clip(np.sum(q * q, axis=1), 0.0, 0.9999)
        adj = 1.0 / np.sqrt(1.0 - h)
    else:
        adj = np.ones(len(y))
    spread = float(np.max(np.std(y[active], axis=0)))
    s_min = 1e-6 * spread if spread > 0 else 1.0
    n_drop = min(p, int(np.count_nonzero(active))) - 1
    robust = np.ones(len(y))
    for it in range(1, max_iter + 1):
        fit = v @ coef
        r = y - fit
        r_adj = (np.linalg.norm(r, axis=1) if r.shape[1] > 1 else r[:, 0]) * adj
        mad = float(np.median(np.sort(np.abs(r_adj[active]))[n_drop:]))
        s = max(mad / _MAD_NORMAL, s_min)
        uu = r_adj / (BISQUARE_C * s)
        robust = np.where(np.abs(uu) < 1.0, (1.0 - uu * uu) ** 2, 0.0)
        ww = w * robust
        if np.count_nonzero(ww > 0) < p:
            logger.warning("bisquare: fewer positive weights than coefficients; stopping")
            return coef, robust, it, False
        new = wls(v, y, ww)
        change = float(np.max(np.abs(v @ (new - coef))))
        coef = new
        if change <= tol * max(float(np.max(np.abs(fit))), 1e-12):
            return coef, robust, it, True
    return coef, robust, max_iter, False


def solve(
    v: np.ndarray, y: np.ndarray, w: np.ndarray, method: str, tol: float, max_iter: int
) -> tuple[np.ndarray, np.ndarray, int, bool]:
    """Fit with ``method`` (one of :data:`FIT_METHODS`).

    Returns
    -------
    coef : ndarray, shape (p, d)
    robust : ndarray, shape (n,)
        The bisquare weights of the last iteration (ones for the other methods).
    iterations : int
        Reweighting iterations (0 for least squares and LAR).
    converged : bool
    """
    if method == "least_squares":
        return wls(v, y, w), np.ones(len(y)), 0, True
    if method == "lar":
        return lar(v, y, w), np.ones(len(y)), 0, True
    return bisquare(v, y, w, tol, max_iter)
