"""Compiled kernel of the smoother's cost term: value, gradient and convex model in one pass.

The sequential rounds of :func:`trajopt.smoother._cost.cost_rounds` evaluate the cost term
several times per round on a few hundred quadrature points; in NumPy each evaluation is a
dozen array passes with their temporaries (the bilinear lookup, the basis contractions and
the scatter of the gradient onto the control points), which cost as much as the round's QP.
One loop over the points does it all without temporaries. The field's values and gradients
are :meth:`trajopt.smoother._cost.CostField.at`'s exactly (the same clamping at the grid's
edge), and the model's curvature is :meth:`~trajopt.smoother._cost.CostField.curvature`'s.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def _bilinear(cost, fx, fy):  # pragma: no cover - compiled
    """Value and gradient (per grid cell) at grid coordinates ``(fx, fy)`` (cell centres at k)."""
    ny, nx = cost.shape
    ix = min(max(math.floor(fx), 0), max(nx - 2, 0))
    iy = min(max(math.floor(fy), 0), max(ny - 2, 0))
    tx = fx - ix
    ty = fy - iy
    inx = 1.0 if (tx >= 0.0 and tx <= 1.0 and nx > 1) else 0.0
    iny = 1.0 if (ty >= 0.0 and ty <= 1.0 and ny > 1) else 0.0
    tx = min(max(tx, 0.0), 1.0)
    ty = min(max(ty, 0.0), 1.0)
    ix1 = min(ix + 1, nx - 1)
    iy1 = min(iy + 1, ny - 1)
    c00 = cost[iy, ix]
    c10 = cost[iy, ix1]
    c01 = cost[iy1, ix]
    c11 = cost[iy1, ix1]
    v = (1 - ty) * ((1 - tx) * c00 + tx * c10) + ty * ((1 - tx) * c01 + tx * c11)
    gx = ((1 - ty) * (c10 - c00) + ty * (c11 - c01)) * inx
    gy = ((1 - tx) * (c01 - c00) + tx * (c11 - c10)) * iny
    return v, gx, gy


@njit(cache=True)
def cost_term_kernel(
    cost, a0, a1, k, c, span, b0, b1, wq, grad, band, with_model
):  # pragma: no cover - compiled
    """Evaluate ``sum_q wq[q] cost(C(u_q)) |C'(u_q)|`` with its gradient (and model band).

    Parameters
    ----------
    cost : ndarray of float64, shape (ny, nx)
        The field's (smoothed) cell values.
    a0, a1 : float
        Grid coordinates (cells, cell centres at integers) of the control points' origin.
    k : float
        Control-point cells per grid cell (the two resolutions' ratio).
    c : ndarray of float64, shape (n, 2)
        Control points (control-point cells).
    span : ndarray of int64, shape (Q,)
        Knot span of every quadrature point.
    b0, b1 : ndarray of float64, shape (Q, p + 1)
        Basis values and first derivatives there.
    wq : ndarray of float64, shape (Q,)
        Quadrature weights times the term's factor.
    grad : ndarray of float64, shape (n, 2)
        Zeroed; receives the gradient (per control-point cell).
    band : ndarray of float64, shape (p + 1, n)
        Zeroed; with ``with_model`` receives the model's Hessian band
        ``sum_q wq |C'| kappa_q B B^T`` (``band[d, j] = H[j, j + d]``).
    with_model : bool

    Returns
    -------
    value : float
        The term's value.
    length : float
        ``sum_q wq[q] |C'(u_q)|`` (the weighted length: ``value / length`` is the mean cost).
    """
    nq, p1 = b0.shape
    value = 0.0
    length = 0.0
    for q in range(nq):
        s = span[q]
        px = 0.0
        py = 0.0
        dx = 0.0
        dy = 0.0
        for j in range(p1):
            px += b0[q, j] * c[s + j, 0]
            py += b0[q, j] * c[s + j, 1]
            dx += b1[q, j] * c[s + j, 0]
            dy += b1[q, j] * c[s + j, 1]
        fx = a0 + px / k
        fy = a1 + py / k
        v, gx, gy = _bilinear(cost, fx, fy)
        gx /= k  # per control-point cell
        gy /= k
        speed = math.hypot(dx, dy)
        w = wq[q]
        value += w * v * speed
        length += w * speed
        inv = 1.0 / max(speed, 1e-12)
        ux = dx * inv
        uy = dy * inv
        for j in range(p1):
            grad[s + j, 0] += w * (speed * b0[q, j] * gx + v * b1[q, j] * ux)
            grad[s + j, 1] += w * (speed * b0[q, j] * gy + v * b1[q, j] * uy)
        if with_model:
            _, gxp, gyp0 = _bilinear(cost, fx + 1.0, fy)
            _, gxm, gym0 = _bilinear(cost, fx - 1.0, fy)
            _, gxp1, gyp = _bilinear(cost, fx, fy + 1.0)
            _, gxm1, gym = _bilinear(cost, fx, fy - 1.0)
            hxx = 0.5 * (gxp - gxm)
            hyy = 0.5 * (gyp - gym)
            hxy = 0.25 * ((gyp0 - gym0) + (gxp1 - gxm1))
            lam = 0.5 * (hxx + hyy) + math.sqrt((0.5 * (hxx - hyy)) ** 2 + hxy * hxy)
            if lam > 0.0:
                m = w * speed * lam / (k * k)
                for a in range(p1):
                    for b in range(a, p1):
                        band[b - a, s + a] += m * b0[q, a] * b0[q, b]
    return value, length


def cost_term(
    cost: np.ndarray,
    a: np.ndarray,
    k: float,
    c: np.ndarray,
    span: np.ndarray,
    b0: np.ndarray,
    b1: np.ndarray,
    wq: np.ndarray,
    with_model: bool,
) -> tuple[float, float, np.ndarray, np.ndarray | None]:
    """Call :func:`cost_term_kernel`.

    Returns the value, the weighted length, the gradient (n, 2) and the band (or None).
    """
    n = c.shape[0]
    grad = np.zeros((n, 2))
    band = np.zeros((b0.shape[1], n) if with_model else (1, 1))
    value, length = cost_term_kernel(
        cost, float(a[0]), float(a[1]), float(k), c, span, b0, b1, wq, grad, band, with_model
    )
    return value, length, grad, band if with_model else None
