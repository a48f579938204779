"""A cost field in the smoother's objective (a costmap's graded cost, a preference layer).

The objective gains ``s * w * integral cost(C(u)) |C'(u)| du``: the cost per unit of length
travelled, in cell units (``C`` in cells, ``u`` the arc-length-like parameter in cells), with
``s`` from :func:`cost_scale` (in the taut objective a multiple of the price of one more cell
of length, so that ``w`` trades cost against length as the A* search's ``length * (1 + w
cost)`` does; 1 in the fidelity objective). The cell values are smoothed by a Gaussian of
:data:`SIGMA` cells (the inflation band's edges become slopes that the rounds see) and
interpolated bilinearly between cell centres; the integral is a Gauss-Legendre quadrature
(:data:`N_GAUSS` points per knot span), evaluated with its gradient and a convex model of its
Hessian by the compiled :func:`~trajopt.smoother._cost_kernels.cost_term_kernel`. The QP and
SCP paths minimise it by sequential QP rounds on that model with a line search
(:func:`cost_rounds`; the attempt's first QP already holds the model around the path); the
corridor rows stay hard constraints in every round, so the clearance certificate is the one
of the QP without the term.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from trajopt.errors import InvalidInputError
from trajopt.smoother._basis import band_quadratic, basis_derivs, find_spans, gauss_legendre
from trajopt.smoother._cost_kernels import cost_term

if TYPE_CHECKING:
    from trajopt.smoother._options import Smoother
    from trajopt.smoother._problem import QPData
    from trajopt.smoother._status import SolveInfo

#: Gauss-Legendre points per knot span of the cost quadrature
N_GAUSS = 4
#: most sequential QP rounds of the linearised cost term
MAX_ROUNDS = 8
#: the rounds stop when a round's decrease of the objective is less than this fraction of
#: the decrease of all rounds so far
ROUND_TOL = 0.1
#: first proximal weight (per control point coordinate, cell units) of the rounds' model
RHO0 = 1e-1
#: the proximal weight is never halved below this
RHO_MIN = 1e-3
#: halvings of the step the line search tries before a round is retried with more damping
LINE_SEARCH_STEPS = 4
#: fraction of the model's predicted decrease a step must achieve
ARMIJO = 1e-4
#: standard deviation (cells) of the Gaussian smoothing of the cell costs before the
#: interpolation: the inflation band's edges become slopes the linearised rounds can follow
SIGMA = 1.0

#: the smoother's price of cost relative to the search's: a cell of cost weighs this many
#: cells of taut length (see :func:`cost_scale`)
BEND_FACTOR = 4.0

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


def cost_scale(options: Smoother, taut: bool) -> float:
    """``s``, the factor of the weight in the cost term (see the module docstring).

    With the taut objective, ``s = BEND_FACTOR * 2 * taut_length_weight``: ``2 *
    taut_length_weight`` is the price of one more cell of length at unit speed, so that
    with :data:`BEND_FACTOR` 1 the weight would trade cost against length exactly as the
    costmap search does (``length * (1 + w cost)``). The smoother's curve also pays for
    bending, which a grid path does not: at equal prices it cuts back through the band the
    search went round. :data:`BEND_FACTOR` = 4 is the factor at which, on Nav2-style
    inflation costmaps of the shared ROS maps at the default weight 2, the trajectory's mean
    cost stays within 5 % of its A* path's (``benchmarks/bench_costmap_smoother.py``). With
    the fidelity objective (no length term), ``s = 1``.

    Parameters
    ----------
    options : Smoother
    taut : bool
        Whether the attempt uses the taut objective.

    Returns
    -------
    float
    """
    return BEND_FACTOR * 2.0 * options.taut_length_weight if taut else 1.0


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
    last_mean : float
        The mean cost per unit length of the curve :meth:`evaluate` saw last.
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
    last_mean: float = 0.0

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
        xg, wg = gauss_legendre(N_GAUSS)
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
            ``s * w * sum_q wq cost(C(u_q)) |C'(u_q)|`` (cells of length times cost).
        grad : ndarray, shape (2 nb,)
            Its gradient (zero on the padded variables).
        """
        value, grad, _ = self.evaluate(z, with_model=False)
        return value, grad

    def model_band(self, z: np.ndarray) -> np.ndarray:
        """Upper band of a convex, isotropic model of the term's Hessian at ``z``.

        ``s * w * sum_q wq |C'_q| kappa_q B_q B_q^T`` per coordinate, with ``kappa_q`` the
        non-negative part of the largest eigenvalue of the cost's Hessian at the quadrature
        point. The bilinear interpolant is linear along each axis inside a cell, so its own
        second derivatives vanish; the Hessian is the central difference of its gradient
        over one cell either side (the field's curvature at the scale of a cell). This is
        the second-order part of the term along the direction the cost curves most,
        without the (small, indefinite) terms of ``|C'|``; the rounds add it to the QP's
        Hessian so that a step follows the cost's curvature instead of a fixed damping.

        Parameters
        ----------
        z : ndarray, shape (2 nb,)
            Control points (cells).

        Returns
        -------
        ndarray, shape (p + 1, nb)
            ``band[d, j] = H[j, j + d]`` of the per-coordinate block (cell units).
        """
        return self.evaluate(z, with_model=True)[2]

    def evaluate(
        self, z: np.ndarray, with_model: bool = True
    ) -> tuple[float, np.ndarray, np.ndarray | None]:
        """Return the value, gradient and (``with_model``) model band in one pass.

        See :meth:`value_grad` and :meth:`model_band`; the compiled
        :func:`~trajopt.smoother._cost_kernels.cost_term_kernel` does the work.
        """
        nb, n = self.nb, self.n
        f = self.field
        c = np.column_stack([z[:n], z[nb : nb + n]])
        a = (self.origin - f.origin) / f.resolution - 0.5
        value, length, g, band = cost_term(
            f.cost, a, f.resolution / self.res, c, self.span, self.b0, self.b1, self.wq, with_model
        )
        self.last_mean = value / max(length, 1e-12)
        factor = self.scale * f.weight
        grad = np.zeros(2 * nb)
        grad[:n], grad[nb : nb + n] = factor * g[:, 0], factor * g[:, 1]
        if band is not None:
            band = factor * np.pad(band, ((0, 0), (0, nb - n)))
        return factor * value, grad, band

    def mean_cost(self, z: np.ndarray) -> float:
        """Return the curve's mean cost per unit length (without the weight)."""
        self.evaluate(z, with_model=False)
        return self.last_mean


def _band_matvec(band: np.ndarray, z: np.ndarray) -> np.ndarray:
    """``blockdiag(Hb, Hb) @ z`` for the symmetric upper band ``band`` of ``Hb``."""
    nb = band.shape[1]
    out = np.zeros_like(z)
    for blk in (slice(0, nb), slice(nb, 2 * nb)):
        v = z[blk]
        o = band[0] * v
        for d in range(1, band.shape[0]):
            o[: nb - d] += band[d, : nb - d] * v[d:]
            o[d:] += band[d, : nb - d] * v[: nb - d]
        out[blk] = o
    return out


def linearised(
    qp: QPData,
    term: CostTerm,
    z: np.ndarray,
    rho: float = RHO0,
    grad: np.ndarray | None = None,
    model: np.ndarray | None = None,
) -> QPData:
    """Return the QP plus the rounds' convex model of the cost term around ``z``.

    The model: the term's gradient at ``z``, the curvature :meth:`CostTerm.model_band` and
    a proximal ``rho/2 |. - z|^2`` (its constant dropped); the rows and bounds are ``qp``'s.

    Parameters
    ----------
    qp : QPData
    term : CostTerm
    z : ndarray, shape (2 nb,)
        Linearisation point (cells); need not be feasible.
    rho : float
        Proximal weight (cell units).
    grad : ndarray, shape (2 nb,), optional
        The term's gradient at ``z`` when the caller has it.
    model : ndarray, shape (p + 1, nb), optional
        Its :meth:`CostTerm.model_band` at ``z`` when the caller has it (not modified).

    Returns
    -------
    QPData
        ``qp`` with the model's Hessian band added to ``full`` and its linear part to ``g``.
    """
    if grad is None or model is None:
        _, grad, model = term.evaluate(z)
    model = model.copy()
    model[0, : qp.n] += rho
    return replace(qp, full=qp.full + model, g=qp.g + grad - _band_matvec(model, z))


def cost_rounds(
    options: Smoother,
    qp: QPData,
    term: CostTerm,
    z: np.ndarray,
    const: float,
    deadline: float,
    solve: Any,
) -> tuple[np.ndarray, np.ndarray, dict]:
    """Sequential QP rounds on ``1/2 z'Hz + g'z + const + cost(z)``.

    Each round minimises, inside the same corridor rows and bounds, the QP plus a convex
    quadratic model of the cost term around the current iterate ``z_k``: its value and
    gradient there, and the curvature of :meth:`CostTerm.model_band` plus a proximal
    ``rho/2 |z - z_k|^2``. The feasible set is convex, so every point between ``z_k`` and
    the round's solution is feasible: a backtracking line search along that step accepts
    the first point that lowers the true objective by a fraction of the model's predicted
    decrease; when none does, ``rho`` is quadrupled and the round retried (after an
    accepted full step it is halved). The rounds stop when one lowers the objective by
    less than :data:`ROUND_TOL` of what all rounds so far lowered it, at
    :data:`MAX_ROUNDS` or at ``deadline``;
    a curve on which the cost is flat (zero gradient) takes no round.

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
        ``rounds`` (QP solves), ``accepted``, ``cost_term`` (at ``z``), ``mean_cost`` before
        and after.
    """
    val, grad, model = term.evaluate(z)
    f = f0 = band_quadratic(qp.full, qp.g, z, const) + val
    mean = term.last_mean
    stats = {"rounds": 0, "accepted": 0, "mean_cost_qp": mean}
    rho = RHO0
    if not np.any(grad):
        stats.update(cost_term=val, mean_cost=stats["mean_cost_qp"])
        return z, qp.g + grad, stats
    for _ in range(MAX_ROUNDS):
        if time.perf_counter() > deadline:
            break
        stats["rounds"] += 1
        lin_qp = linearised(qp, term, z, rho, grad, model)
        info: SolveInfo = solve(options, lin_qp, z)
        if not info.success:
            rho *= 4.0
            continue
        step = np.clip(info.z, qp.lbx, qp.ubx) - z
        # the model's decrease: -(grad + H z_k + g)'d - 1/2 d'(H + M)d >= 0 at its minimum
        lin = float((qp.g + grad + _band_matvec(qp.full, z)) @ step)
        quad = band_quadratic(lin_qp.full, np.zeros_like(step), step)
        pred = -(lin + quad)
        accepted = False
        t = 1.0
        for _ls in range(LINE_SEARCH_STEPS):
            zn = z + t * step
            vn, gn, mn = term.evaluate(zn)
            fn = band_quadratic(qp.full, qp.g, zn, const) + vn
            if fn < f - ARMIJO * t * max(pred, 0.0):
                accepted = True
                break
            t *= 0.5
        if not accepted:
            rho *= 4.0
            continue
        stats["accepted"] += 1
        done = f - fn <= ROUND_TOL * (f0 - fn)
        z, val, grad, model, f, mean = zn, vn, gn, mn, fn, term.last_mean
        if t == 1.0:
            rho = max(0.5 * rho, RHO_MIN)
        if done:
            break
    stats.update(cost_term=val, mean_cost=mean)
    return z, qp.g + grad, stats
