"""A cost field in the smoother's objective (a costmap's graded cost, a preference layer).

The objective gains ``s * w * integral cost(C(u)) |C'(u)| du``: the cost per unit of length
travelled, in cell units (``C`` in cells, ``u`` the arc-length-like parameter in cells). In
the taut objective ``s = 2 * taut_length_weight``, the marginal of its length term
``taut_length_weight * integral |C'|^2`` per cell of length at unit speed, so that the
objective trades length for cost as the A* search does (``length * (1 + w * cost)``); in
the fidelity objective ``s = 1``. The cell values are smoothed by a Gaussian of
:data:`SIGMA` cells (the inflation band's edges become slopes that the linearised rounds
see) and interpolated bilinearly between cell centres; the integral is a Gauss-Legendre quadrature (:data:`N_GAUSS` points per
knot span). The QP and SCP paths minimise it by sequential QP rounds that linearise it
around the current iterate (:func:`cost_rounds`); the corridor rows stay hard constraints in
every round, so the clearance certificate is the one of the QP without the term.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from trajopt.errors import InvalidInputError
from trajopt.smoother._basis import band_quadratic, basis_derivs, find_spans

if TYPE_CHECKING:
    from trajopt.smoother._options import Smoother
    from trajopt.smoother._problem import QPData
    from trajopt.smoother._status import SolveInfo

#: Gauss-Legendre points per knot span of the cost quadrature
N_GAUSS = 4
#: most sequential QP rounds of the linearised cost term
MAX_ROUNDS = 8
#: the rounds stop when a round lowers the objective by less than this fraction
ROUND_TOL = 1e-2
#: first proximal weight (per control point coordinate, cell units) of the damped rounds
RHO0 = 1.0
#: standard deviation (cells) of the Gaussian smoothing of the cell costs before the
#: interpolation: the inflation band's edges become slopes the linearised rounds can follow
SIGMA = 1.0

# the last read-only cost array seen and its validated, smoothed copy
_CACHE: dict[str, Any] = {}


@dataclass(frozen=True, slots=True)
class CostField:
    """A validated per-cell cost and its weight.

    Attributes
    ----------
    cost : ndarray of float64, shape (ny, nx)
        Per-cell cost in ``[0, 1]`` (row 0 at the bottom, as the raw grid).
    weight : float
        ``w`` of the objective's cost term (dimensionless, >= 0).
    resolution : float
        Cell size (m), the raw grid's.
    origin : ndarray, shape (2,)
        The raw grid's lower-left corner (m).
    """

    cost: np.ndarray
    weight: float
    resolution: float
    origin: np.ndarray

    def at(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Bilinear cost between cell centres and its gradient.

        Parameters
        ----------
        xy : ndarray, shape (M, 2)
            World points (m).

        Returns
        -------
        value : ndarray, shape (M,)
            Interpolated cost (clamped to the outermost cell centres).
        grad : ndarray, shape (M, 2)
            Its gradient (1/m); zero across a clamped coordinate.
        """
        ny, nx = self.cost.shape
        f = (np.asarray(xy, dtype=float) - self.origin) / self.resolution - 0.5
        out = []
        for ax, size in ((0, nx), (1, ny)):
            fa = f[:, ax]
            i = np.clip(np.floor(fa), 0, max(size - 2, 0)).astype(np.int64)
            t = fa - i
            inside = (t >= 0.0) & (t <= 1.0) & (size > 1)
            out.append((i, np.clip(t, 0.0, 1.0), inside))
        (ix, tx, inx), (iy, ty, iny) = out
        ix1 = np.minimum(ix + 1, nx - 1)
        iy1 = np.minimum(iy + 1, ny - 1)
        c = self.cost
        c00, c10 = c[iy, ix], c[iy, ix1]
        c01, c11 = c[iy1, ix], c[iy1, ix1]
        v = (1 - ty) * ((1 - tx) * c00 + tx * c10) + ty * ((1 - tx) * c01 + tx * c11)
        gx = ((1 - ty) * (c10 - c00) + ty * (c11 - c01)) * inx
        gy = ((1 - tx) * (c01 - c00) + tx * (c11 - c10)) * iny
        return v, np.column_stack([gx, gy]) / self.resolution


def cost_field(cost: Any, weight: Any, raw_grid: Any) -> CostField | None:
    """Validate ``Smoother.fit``'s ``cost`` and ``cost_weight`` against the raw grid.

    Parameters
    ----------
    cost : astar.Costmap, array_like of shape (ny, nx), or None
        A costmap (its normalised :attr:`~astar.Costmap.cost`; its grid must have the raw
        grid's shape, resolution and origin) or per-cell costs in ``[0, 1]`` of the raw
        grid's shape.
    weight : float
        Finite, >= 0.
    raw_grid : astar.OccupancyGrid or None
        Required with a cost.

    Returns
    -------
    CostField or None
        ``None`` without a cost, or with weight 0 (the term vanishes).

    Raises
    ------
    InvalidInputError
        Names the field, the value and the rule.
    """
    if isinstance(weight, bool) or not isinstance(weight, int | float | np.number):
        raise InvalidInputError(f"cost_weight must be a number >= 0, got {weight!r}")
    w = float(weight)
    if not math.isfinite(w) or w < 0.0:
        raise InvalidInputError(f"cost_weight must be finite and >= 0 (dimensionless), got {w!r}")
    if cost is None:
        return None
    if raw_grid is None:
        raise InvalidInputError("cost needs raw_grid (the map whose cells it grades)")
    grid = getattr(cost, "grid", None)
    if grid is not None and hasattr(cost, "cost"):  # an astar.Costmap
        if not math.isclose(grid.resolution, raw_grid.resolution, rel_tol=1e-9):
            raise InvalidInputError(
                f"cost: the costmap's resolution {grid.resolution!r} m must equal the raw "
                f"grid's {raw_grid.resolution!r} m"
            )
        if not np.allclose(grid.origin, raw_grid.origin, rtol=0.0, atol=1e-9):
            raise InvalidInputError(
                f"cost: the costmap's origin {tuple(grid.origin)} m must equal the raw "
                f"grid's {tuple(raw_grid.origin)} m"
            )
        cost = cost.cost
    src = cost
    if (
        _CACHE.get("src") is src
        and _CACHE.get("sigma") == SIGMA
        and src.shape == tuple(raw_grid.shape)
        and not src.flags.writeable
    ):
        arr = _CACHE["arr"]  # the same read-only array (a Costmap's cost): validated, smoothed
    else:
        arr = _validated(cost, raw_grid)
        if isinstance(src, np.ndarray) and not src.flags.writeable and src.base is None:
            _CACHE.update(src=src, sigma=SIGMA, arr=arr)
    if w == 0.0:
        return None
    return CostField(
        cost=arr,
        weight=w,
        resolution=float(raw_grid.resolution),
        origin=np.asarray(raw_grid.origin, dtype=float),
    )


def _validated(cost: Any, raw_grid: Any) -> np.ndarray:
    """Return the per-cell costs checked (shape, finite, in [0, 1]), smoothed, read-only."""
    try:
        arr = np.asarray(cost, dtype=float)
    except (TypeError, ValueError):
        raise InvalidInputError(
            f"cost must be a numeric array of shape {raw_grid.shape}, got {type(cost).__name__}"
        ) from None
    if arr.shape != tuple(raw_grid.shape):
        raise InvalidInputError(
            f"cost must have the raw grid's shape {tuple(raw_grid.shape)} (ny, nx), got {arr.shape}"
        )
    bad = ~np.isfinite(arr)
    if np.any(bad):
        iy, ix = np.argwhere(bad)[0]
        raise InvalidInputError(
            f"cost must be finite, got {arr[iy, ix]!r} at cell (ix={ix}, iy={iy})"
        )
    if arr.size and (arr.min() < 0.0 or arr.max() > 1.0):
        v = arr.min() if arr.min() < 0.0 else arr.max()
        raise InvalidInputError(f"cost must be normalised to [0, 1], got {float(v)!r}")
    arr = np.array(arr, dtype=float)
    if SIGMA > 0:
        from scipy import ndimage

        arr = ndimage.gaussian_filter(arr, SIGMA, mode="nearest")
    arr.setflags(write=False)
    return arr


@dataclass(slots=True)
class CostTerm:
    """``w * sum_q wq cost(C(u_q)) |C'(u_q)|`` on one attempt's knots (cell units).

    Attributes
    ----------
    field : CostField
    origin : ndarray, shape (2,)
        World position (m) of the cell-unit origin (the corridor's).
    res : float
        Cell size (m).
    n, nb, p : int
        Control points, padded count, degree.
    span : ndarray of int, shape (Q,)
        Span of every quadrature point.
    b0, b1 : ndarray, shape (Q, p + 1)
        Basis values and first derivatives there.
    wq : ndarray, shape (Q,)
        Quadrature weights (cells).
    scale : float
        ``s``, the factor of ``w`` (see the module docstring).
    """

    field: CostField
    origin: np.ndarray
    res: float
    n: int
    nb: int
    p: int
    span: np.ndarray
    b0: np.ndarray
    b1: np.ndarray
    wq: np.ndarray
    scale: float = 1.0

    @classmethod
    def on_knots(
        cls,
        field: CostField,
        origin: np.ndarray,
        res: float,
        t: np.ndarray,
        p: int,
        nb: int,
        scale: float = 1.0,
    ) -> CostTerm:
        """Quadrature of the knots ``t`` (cells, clamped, degree ``p``); ``scale`` multiplies w."""
        n = len(t) - p - 1
        brk = np.unique(t)
        a, b = brk[:-1], brk[1:]
        xg, wg = np.polynomial.legendre.leggauss(N_GAUSS)
        u = (0.5 * (a + b)[:, None] + 0.5 * (b - a)[:, None] * xg[None, :]).ravel()
        wq = (0.5 * (b - a)[:, None] * wg[None, :]).ravel()
        span = find_spans(t, p, n, u)
        return cls(
            field=field,
            origin=np.asarray(origin, dtype=float),
            res=float(res),
            n=n,
            nb=nb,
            p=p,
            span=span,
            b0=basis_derivs(t, p, span, u, 0),
            b1=basis_derivs(t, p, span, u, 1),
            wq=wq,
            scale=float(scale),
        )

    def value_grad(self, z: np.ndarray) -> tuple[float, np.ndarray]:
        """Return the term and its gradient at the control points ``z``.

        Parameters
        ----------
        z : ndarray, shape (2 nb,)
            ``[x_0 .. x_{nb-1}, y_0 .. y_{nb-1}]`` (cells).

        Returns
        -------
        value : float
            ``w * sum_q wq cost(C(u_q)) |C'(u_q)|`` (cells of length times cost).
        grad : ndarray, shape (2 nb,)
            Its gradient (zero on the padded variables).
        """
        nb, n, p = self.nb, self.n, self.p
        c = np.column_stack([z[:n], z[nb : nb + n]])
        idx = self.span[:, None] + np.arange(p + 1)[None, :]  # (Q, p + 1)
        cq = c[idx]  # (Q, p + 1, 2)
        pos = np.einsum("qk,qkd->qd", self.b0, cq)
        der = np.einsum("qk,qkd->qd", self.b1, cq)
        val, grad_m = self.field.at(self.origin + self.res * pos)
        grad_c = grad_m * self.res  # per cell
        speed = np.hypot(der[:, 0], der[:, 1])
        w = self.scale * self.field.weight * self.wq
        value = float(np.sum(w * val * speed))
        unit = der / np.maximum(speed, 1e-12)[:, None]
        # d/dc_k: w (grad cost . B_k) |C'| + w cost (C'/|C'|) B'_k
        gq = (w * speed)[:, None, None] * self.b0[:, :, None] * grad_c[:, None, :]
        gq += (w * val)[:, None, None] * self.b1[:, :, None] * unit[:, None, :]
        g = np.zeros((n, 2))
        np.add.at(g, idx.ravel(), gq.reshape(-1, 2))
        out = np.zeros(2 * nb)
        out[:n], out[nb : nb + n] = g[:, 0], g[:, 1]
        return value, out

    def mean_cost(self, z: np.ndarray) -> float:
        """Return the curve's mean cost per unit length (without the weight)."""
        nb, n, p = self.nb, self.n, self.p
        c = np.column_stack([z[:n], z[nb : nb + n]])
        idx = self.span[:, None] + np.arange(p + 1)[None, :]
        pos = np.einsum("qk,qkd->qd", self.b0, c[idx])
        der = np.einsum("qk,qkd->qd", self.b1, c[idx])
        val, _ = self.field.at(self.origin + self.res * pos)
        speed = np.hypot(der[:, 0], der[:, 1]) * self.wq
        return float(np.sum(val * speed) / max(np.sum(speed), 1e-12))


def cost_rounds(
    options: Smoother,
    qp: QPData,
    term: CostTerm,
    z: np.ndarray,
    const: float,
    deadline: float,
    solve: Any,
) -> tuple[np.ndarray, np.ndarray, dict]:
    """Damped sequential QP rounds on ``1/2 z'Hz + g'z + const + cost(z)``.

    Each round adds the cost term's gradient at the current iterate ``z_k`` to ``g`` and a
    proximal term ``rho/2 |z - z_k|^2`` (a damped Gauss-Newton step inside the same
    corridor rows and bounds); a round is accepted only when it lowers the true objective
    (else ``rho`` is quadrupled and the round retried; after an accepted round it is halved).

    Parameters
    ----------
    options : Smoother
    qp : QPData
        The attempt's QP (not modified).
    term : CostTerm
    z : ndarray, shape (2 nb,)
        Starting iterate (the QP solution, cells).
    const : float
        The QP objective's constant.
    deadline : float
        ``time.perf_counter()`` value after which no new round starts.
    solve : callable
        ``solve(options, qp, x0) -> SolveInfo`` (:func:`~trajopt.smoother._qp.solve_qp`).

    Returns
    -------
    z : ndarray, shape (2 nb,)
        The last accepted iterate.
    g_lin : ndarray, shape (2 nb,)
        ``g`` plus the cost gradient at ``z`` (the linear term a later curvature stage
        minimises).
    stats : dict
        ``rounds``, ``accepted``, ``cost_term`` (at ``z``), ``mean_cost`` before and after.
    """
    nb, n = qp.nb, qp.n
    val, grad = term.value_grad(z)
    f = band_quadratic(qp.full, qp.g, z, const) + val
    stats = {"rounds": 0, "accepted": 0, "mean_cost_qp": term.mean_cost(z)}
    rho = RHO0
    for _ in range(MAX_ROUNDS):
        if time.perf_counter() > deadline:
            break
        stats["rounds"] += 1
        full = qp.full.copy()
        full[0, :n] += rho
        g = qp.g + grad
        g[:n] -= rho * z[:n]
        g[nb : nb + n] -= rho * z[nb : nb + n]
        info: SolveInfo = solve(options, replace(qp, full=full, g=g), z)
        if not info.success:
            rho *= 4.0
            continue
        zn = np.clip(info.z, qp.lbx, qp.ubx)
        vn, gn = term.value_grad(zn)
        fn = band_quadratic(qp.full, qp.g, zn, const) + vn
        if fn >= f:
            rho *= 4.0
            continue
        stats["accepted"] += 1
        done = f - fn <= ROUND_TOL * max(abs(f), 1e-9)
        z, val, grad, f = zn, vn, gn, fn
        rho = max(0.5 * rho, 1e-3)
        if done:
            break
    stats.update(cost_term=val, mean_cost=term.mean_cost(z))
    return z, qp.g + grad, stats
