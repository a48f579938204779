"""The cap table's compiled path for piecewise-polynomial curves (numba).

:func:`polynomial_tables` does in two compiled calls what :func:`trajopt.timing.build_cap_table`
needs from a curve with a ``polynomial_degree`` whose arc length is the base class's
(:class:`~trajopt.geometry._curve.ParametricCurve`, e.g. every B-spline of the library):

* the grid's ``u(s)`` by the base class's cubic Hermite model of the arc-length table
  (``u_at_s(s, exact=False)``), the heading and the signed curvature at the grid nodes;
* the rigorous Bernstein bound on ``|kappa|`` over every grid interval, the method of
  :func:`trajopt.geometry._curvature_bound.interval_kappa_max` (same bisection rule, depth and work
  limits, zero-speed-end rule and interval mapping through the exact arc length
  ``s_at_u``, 5-point Gauss-Legendre from the table node below).

The curve enters through the Taylor coefficients of its velocity at the middle of each
polynomial piece (``degree`` calls ``curve(mid, k)``); every later value, at a node, at a
Gauss-Legendre point or on a bisected interval, is that piece's polynomial (exact up to
round-off, as the curve's own evaluation is). The NumPy functions of
:mod:`trajopt.geometry._curvature_bound` stay the reference (``tests/trajopt/geometry/test_curvature_bound.py``
compares the two) and the path for other curves and speed caps.
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import NamedTuple

import numpy as np
from numba import njit

from trajopt.geometry import (
    MAX_DEPTH,
    MAX_WORK,
    STILL_SPEED_RATIO,
    TIP_M,
    TIP_RTOL,
    ZERO_SPEED_RATIO,
    ParametricCurve,
)
from trajopt.kernel_cache import watch_compiles
from trajopt.robot import Robot
from trajopt.timing._cap_cubic import bound_cubic
from trajopt.timing._kernel_options import NO_REFCOUNT

_K_GRID = np.logspace(-9, 6, 151)  # the curvature grid of curvature_bound._free_curvature
_GL_X, _GL_W = np.polynomial.legendre.leggauss(5)


class PolynomialTables(NamedTuple):
    """What the cap table needs from a piecewise-polynomial curve.

    Attributes
    ----------
    u : ndarray, shape (n + 1,)
        Curve parameter at the grid nodes (the ends are the domain's).
    kappa : ndarray, shape (n + 1,)
        Signed curvature at the nodes (1/m; ``inf`` where the parametric speed is 0; nan
        except at the nodes ``0, 1, n - 1, n`` when asked without ``node_kappa``).
    theta : ndarray, shape (n + 1,)
        Unwrapped heading at the nodes (rad).
    kmax : ndarray, shape (n,)
        Rigorous upper bound on ``|kappa|`` over each grid interval (1/m; ``inf`` where
        unbounded).
    cap : ndarray, shape (n,)
        ``Robot.speed_cap(kmax)`` (m/s).
    end_caps : ndarray, shape (4,)
        ``Robot.speed_cap(kappa)`` at the nodes ``0, 1, n - 1, n`` (m/s).
    """

    u: np.ndarray
    kappa: np.ndarray
    theta: np.ndarray
    kmax: np.ndarray
    cap: np.ndarray
    end_caps: np.ndarray


def polynomial_tables(
    curve: ParametricCurve,
    robot: Robot,
    s_grid: np.ndarray,
    degree: int,
    *,
    rtol: float = 1e-3,
    node_kappa: bool = True,
) -> PolynomialTables | None:
    """Grid tables and curvature bounds of ``curve`` on the arc-length grid ``s_grid``.

    Parameters
    ----------
    curve : ParametricCurve
        A polynomial of degree ``<= degree`` between consecutive ``breakpoints()``.
    robot : Robot
        Its ``speed_cap`` decides where the bound is refined (as ``interval_kappa_max``).
    s_grid : ndarray, shape (n + 1,)
        Uniform grid ``0, h, ..., n h = length`` (m).
    degree : int
        Polynomial degree of the pieces.
    rtol : float
        Relative tightness asked of the cap (``interval_kappa_max``'s ``rtol``).
    node_kappa : bool
        Whether ``kappa`` holds the curvature at every node; if False, only at the nodes
        ``0, 1, n - 1, n`` (the others are nan), which is all that ``end_caps`` needs.

    Returns
    -------
    PolynomialTables or None
        None when the compiled path does not apply: a degree below 2, a curve with its own
        ``u_at_s``/``s_at_u``/``speed`` or a robot with its own ``speed_cap`` (the caller
        then uses the NumPy path).
    """
    base = ParametricCurve
    kind = type(curve)
    if (
        degree < 2
        or kind.u_at_s is not base.u_at_s
        or kind.s_at_u is not base.s_at_u
        or kind.speed is not base.speed
        or kind.curvature is not base.curvature
        or kind.heading is not base.heading
        or type(robot).speed_cap is not Robot.speed_cap
    ):
        return None
    lo, hi = (float(x) for x in curve.domain)
    bp = np.asarray(curve.breakpoints(), dtype=float)
    inner = bp[(bp > lo) & (bp < hi)]
    if inner.size > 1 and not np.all(inner[1:] > inner[:-1]):
        w = np.union1d([lo, hi], inner)  # sorted, without repeats
    else:  # the usual case, already so: the same array, without union1d's sort
        w = np.concatenate(([lo], inner, [hi]))
    mid = 0.5 * (w[:-1] + w[1:])
    half = 0.5 * (w[1:] - w[:-1])
    coef = np.empty((mid.size, degree, 2))
    scale = np.ones_like(half)
    for k in range(degree):  # c'(u) = sum_k coef[:, k] x^k with x = (u - mid) / half
        coef[:, k, :] = np.asarray(curve(mid, k + 1), dtype=float) * scale[:, None]
        scale = scale * half / (k + 1)
    nodes, s_nodes, v_nodes = curve._arc_table()
    limits = robot.drive.speed_terms(robot).as_array()  # the rule Robot.speed_cap applies
    s_grid = np.ascontiguousarray(s_grid, dtype=float)
    h = float(s_grid[-1]) / (s_grid.size - 1)
    u, kappa, theta, still, end_caps = _node_tables(
        w,
        coef,
        nodes,
        s_nodes,
        v_nodes,
        s_grid,
        STILL_SPEED_RATIO * curve.mean_speed(),
        limits,
        bool(node_kappa),
    )
    p2b, shift = matrices(degree)
    X, S, V = workspace(degree)
    kmax, cap = _interval_bounds(
        w,
        coef,
        nodes,
        s_nodes,
        h,
        s_grid.size - 1,
        ZERO_SPEED_RATIO * curve.length / (hi - lo),
        limits,
        _K_GRID,
        _GL_X,
        _GL_W,
        float(rtol),
        p2b,
        shift,
        X,
        S,
        V,
        True,
    )
    if still:  # zero parametric speed at a node: the limit of the tangent direction
        raw = np.asarray(curve(u, 1), dtype=float)
        th = np.arctan2(raw[:, 1], raw[:, 0])
        mask = np.hypot(raw[:, 0], raw[:, 1]) <= STILL_SPEED_RATIO * curve.mean_speed()
        th[mask] = curve.heading(u[mask])
        theta = np.unwrap(th)
    return PolynomialTables(u=u, kappa=kappa, theta=theta, kmax=kmax, cap=cap, end_caps=end_caps)


watch_compiles()  # a first compilation logs one notice (trajopt.kernel_cache)


@njit(cache=True, **NO_REFCOUNT)
def speed_cap(k, limits):  # pragma: no cover - compiled
    """``Robot.speed_cap`` of ``|k|`` (1/m) for ``limits = (v_max, a_lat, omega, tw, wv)``.

    The same operations as the NumPy method (``tw = 0`` stands for no wheel limit).
    """
    k = abs(k)
    if k != k or k == np.inf:
        return 0.0
    cap = limits[0]
    if k > 0.0:
        cap = min(cap, math.sqrt(limits[1] / k))
        cap = min(cap, limits[2] / k)
    if limits[3] > 0.0:
        cap = min(cap, limits[4] / (1.0 + 0.5 * limits[3] * k))
    return cap


@njit(cache=True, **NO_REFCOUNT)
def _poly_d1(coef, i, x):  # pragma: no cover - compiled
    """Velocity ``c'`` of piece ``i`` at ``x = (u - mid) / half``: ``(vx, vy)``."""
    p = coef.shape[1]
    vx = coef[i, p - 1, 0]
    vy = coef[i, p - 1, 1]
    for k in range(p - 2, -1, -1):
        vx = vx * x + coef[i, k, 0]
        vy = vy * x + coef[i, k, 1]
    return vx, vy


@njit(cache=True, **NO_REFCOUNT)
def _poly_d2(coef, i, x, half):  # pragma: no cover - compiled
    """Acceleration ``c''`` of piece ``i`` at ``x``: ``(ax, ay)``."""
    p = coef.shape[1]
    ax = 0.0
    ay = 0.0
    for k in range(p - 1, 0, -1):
        ax = ax * x + k * coef[i, k, 0]
        ay = ay * x + k * coef[i, k, 1]
    return ax / half, ay / half


@njit(cache=True, **NO_REFCOUNT)
def _s_at_u(u, piece, w, coef, nodes, s_nodes, gl_x, gl_w):  # pragma: no cover - compiled
    """``ParametricCurve.s_at_u`` (m) at ``u`` inside polynomial piece ``piece``."""
    nn = nodes.shape[0]
    uu = min(max(u, nodes[0]), nodes[nn - 1])
    i = np.searchsorted(nodes, uu, side="right") - 1
    i = min(max(i, 0), nn - 2)
    a = nodes[i]
    half = 0.5 * (uu - a)
    mid = 0.5 * (a + uu)
    pm = 0.5 * (w[piece] + w[piece + 1])
    ph = 0.5 * (w[piece + 1] - w[piece])
    acc = 0.0
    for q in range(gl_x.shape[0]):
        vx, vy = _poly_d1(coef, piece, (mid + half * gl_x[q] - pm) / ph)
        acc += math.hypot(vx, vy) * gl_w[q]
    return s_nodes[i] + half * acc


@njit(cache=True, **NO_REFCOUNT)
def _bernstein_max_abs(P, off, n_coef, p2b):  # pragma: no cover - compiled
    """Largest ``|b_i|`` of the Bernstein coefficients of ``P[off:off + n_coef]``.

    ``b_i = sum_{k <= i} C(i, k) / C(n, k) P_k`` on ``[0, 1]``, ``n = n_coef - 1``
    (``p2b[n, i, k]`` holds the factors).
    """
    n = n_coef - 1
    best = 0.0
    for i in range(n + 1):
        b = 0.0
        for k in range(i + 1):
            b += p2b[n, i, k] * P[off + k]
        b = abs(b)
        if b > best:
            best = b
    return best


@njit(cache=True, **NO_REFCOUNT)
def _bernstein_min(P, off, n_coef, p2b):  # pragma: no cover - compiled
    """Smallest ``b_i`` of the Bernstein coefficients of ``P[off:off + n_coef]`` (as above)."""
    n = n_coef - 1
    best = np.inf
    for i in range(n + 1):
        b = 0.0
        for k in range(i + 1):
            b += p2b[n, i, k] * P[off + k]
        if b < best:
            best = b
    return best


@njit(cache=True, **NO_REFCOUNT)
def _cross_and_norm(V, m, X, S):  # pragma: no cover - compiled
    """``X = V x V'`` and ``S = |V|^2`` (power basis) of the ``m`` coefficients ``V[:m]``.

    Each coefficient is summed in the order of ``curvature_bound._mul`` (products of
    ascending index of the left factor; ``X`` the difference and ``S`` the sum of the two
    products). Returns the numbers of coefficients of ``X`` and ``S``.
    """
    for r in range(X.shape[0]):
        X[r] = 0.0
        S[r] = 0.0
    for k in range(2 * m - 1):
        s0 = 0.0
        s1 = 0.0
        for r in range(max(0, k - m + 1), min(m - 1, k) + 1):
            s0 += V[r, 0] * V[k - r, 0]
            s1 += V[r, 1] * V[k - r, 1]
        S[k] = s0 + s1
    for k in range(2 * m - 2):  # V' has the m - 1 coefficients (q + 1) V[q + 1]
        t0 = 0.0
        t1 = 0.0
        for r in range(max(0, k - m + 2), min(m - 1, k) + 1):
            q = k - r
            t0 += V[r, 0] * (V[q + 1, 1] * (q + 1))
            t1 += V[r, 1] * (V[q + 1, 0] * (q + 1))
        X[k] = t0 - t1
    return max(2 * m - 2, 1), 2 * m - 1


def _binomials(n: int) -> np.ndarray:
    """Pascal's triangle ``C(i, k)`` for ``i, k <= n`` (float, exact), by its additions."""
    out = np.zeros((n + 1, n + 1))
    for i in range(n + 1):
        out[i, 0] = 1.0
        for k in range(1, i + 1):
            out[i, k] = out[i - 1, k - 1] + (out[i - 1, k] if k <= i - 1 else 0.0)
    return out


@lru_cache(maxsize=8)
def matrices(p: int) -> tuple[np.ndarray, np.ndarray]:
    """Constant matrices of :func:`bound_from_taylor` for degree ``p`` (read-only, cached).

    Bernstein factors ``p2b[n, i, k] = C(i, k) / C(n, k)`` (``n <= 2 p``) and the maps
    ``shift[0, i, k]``, ``shift[1, i, k]`` of coefficients in ``tau = t - 1/2`` to powers of
    ``t`` and of ``1 - t`` (``curvature_bound._shift_matrices``). Every entry is a ratio of
    exact integers or an integer times a power of two, so these NumPy loops give the values
    the compiled ones gave, bit for bit.
    """
    comb = _binomials(2 * p + 2)
    nm = 2 * p + 1
    p2b = np.zeros((nm, nm, nm))
    for n in range(nm):
        for i in range(n + 1):
            for k in range(i + 1):
                p2b[n, i, k] = comb[i, k] / comb[n, k]
    shift = np.zeros((2, p, p))
    for k in range(p):
        for i in range(k + 1):
            shift[0, i, k] = comb[k, i] * (-0.5) ** (k - i)
            shift[1, i, k] = comb[k, i] * 0.5 ** (k - i) * (-1.0) ** i
    p2b.flags.writeable = False
    shift.flags.writeable = False
    return p2b, shift


def workspace(p: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Work arrays ``X``, ``S``, ``V`` of :func:`bound_from_taylor` for degree ``p``."""
    return np.empty(2 * p + 2), np.empty(2 * p + 2), np.empty((p, 2))


def bound_from_taylor(
    gam: np.ndarray,
    flip: int,
    k_free: float,
    p2b: np.ndarray,
    shift: np.ndarray,
    X: np.ndarray,
    S: np.ndarray,
    V: np.ndarray,
) -> float:
    """Bernstein bound on ``|kappa|`` from the Taylor coefficients ``gam`` (p, 2) of ``c_t``.

    ``gam[k]`` multiplies ``(t - 1/2)^k`` on the local ``t`` in ``[0, 1]``; ``flip`` is 1
    (zero speed at ``t = 0``), -1 (at ``t = 1``) or 0. ``p2b``, ``shift`` come from
    :func:`matrices`; ``X``, ``S``, ``V`` are work arrays (:func:`workspace`).
    The arithmetic of :func:`trajopt.geometry._curvature_bound.kappa_bound`, by the compiled
    :func:`_evaluate` on one piece.
    """
    p = gam.shape[0]
    coef = np.empty((1, p, 2))  # one piece on [-1, 1]: the interval [-1/2, 1/2] keeps gam as is
    coef[0] = gam
    work = np.empty((p, 2))
    w = np.array([-1.0, 1.0])
    return float(
        _evaluate(
            coef,
            p,
            0,
            w,
            -0.5,
            0.5,
            int(flip),
            float(k_free),
            p2b,
            shift,
            X,
            S,
            V,
            work,
            True,
            True,
        )
    )


@njit(cache=True, **NO_REFCOUNT)
def _zero_start(V, p):  # pragma: no cover - compiled
    """Whether the velocity at ``t = 0`` is zero (below ``ZERO_SPEED_RATIO`` of its largest)."""
    scale = 0.0
    for i in range(p):
        for d in range(2):
            scale = max(scale, abs(V[i, d]))
    return p >= 2 and math.hypot(V[0, 0], V[0, 1]) <= ZERO_SPEED_RATIO * scale


@njit(cache=True, **NO_REFCOUNT)
def _taylor(coef, p, piece, w, a, b, gam):  # pragma: no cover - compiled
    """Taylor coefficients ``gam`` (p, 2) of ``c_t`` about the middle of ``[a, b]``."""
    pm = 0.5 * (w[piece] + w[piece + 1])
    ph = 0.5 * (w[piece + 1] - w[piece])
    hh = b - a
    x0 = (0.5 * (a + b) - pm) / ph
    r = hh / ph
    for d in range(2):
        for k in range(p):
            gam[k, d] = coef[piece, k, d]
        for i in range(p):  # Taylor shift to x0
            for k in range(p - 2, i - 1, -1):
                gam[k, d] += x0 * gam[k + 1, d]
        f = hh
        for k in range(p):
            gam[k, d] *= f
            f *= r


@njit(cache=True, **NO_REFCOUNT)
def _sampled(gam, p):  # pragma: no cover - compiled
    """``|kappa|`` at ``t = 0.01, 0.5, 0.99`` from ``gam`` (their largest; inf at zero speed)."""
    best = 0.0
    for tau in (-0.49, 0.0, 0.49):
        vx = 0.0
        vy = 0.0
        ax = 0.0
        ay = 0.0
        for k in range(p - 1, -1, -1):
            if k >= 1:
                ax = ax * tau + k * gam[k, 0]
                ay = ay * tau + k * gam[k, 1]
            vx = vx * tau + gam[k, 0]
            vy = vy * tau + gam[k, 1]
        sp = math.sqrt(vx * vx + vy * vy)
        sp3 = sp * sp * sp
        if not sp3 > 0.0:
            return np.inf
        best = max(best, abs(vx * ay - vy * ax) / sp3)
    return best


@njit(cache=True)
def _node_tables(
    w, coef, nodes, s_nodes, v_nodes, s_grid, still_speed, limits, node_kappa
):  # pragma: no cover - compiled
    """Node tables of :func:`polynomial_tables`: ``u``, ``kappa``, ``theta``, ``still``, ``end_caps``."""
    n = s_grid.shape[0] - 1
    m = w.shape[0] - 1
    nn = nodes.shape[0]
    # --- u(s) on the grid: the base class's Hermite model of s(u) on each node interval
    # (a cubic in t = (u - lo) / (hi - lo)), three Newton steps from linear interpolation
    u = np.empty(n + 1)
    i = 0
    ic = -1
    s0 = c1 = c2 = c3 = lo = hn = 0.0
    for q in range(n + 1):
        ss = min(max(s_grid[q], 0.0), s_nodes[nn - 1])
        while i + 1 < nn and s_nodes[i + 1] <= ss:
            i += 1
        if min(i, nn - 2) != ic:
            ic = min(i, nn - 2)
            s0 = s_nodes[ic]
            d = s_nodes[ic + 1] - s0
            lo = nodes[ic]
            hn = nodes[ic + 1] - lo
            c1 = hn * v_nodes[ic]
            e1 = hn * v_nodes[ic + 1]
            c2 = 3.0 * d - 2.0 * c1 - e1
            c3 = -2.0 * d + c1 + e1
            inv_d = 1.0 / d if d > 0 else 0.0
        t = (ss - s0) * inv_d
        if hn > 0:
            for _ in range(3):
                f = (s0 - ss) + t * (c1 + t * (c2 + t * c3))
                df = c1 + t * (2.0 * c2 + 3.0 * c3 * t)
                if df > 0:
                    t = min(max(t - f / df, 0.0), 1.0)
        u[q] = lo + t * hn
    u[0] = w[0]
    u[n] = w[m]
    # --- curvature and heading at the nodes (u is non-decreasing: a moving piece index)
    kappa = np.empty(n + 1)
    theta = np.empty(n + 1)
    still = False
    j = 0
    for q in range(n + 1):
        uq = u[q]
        while j + 1 < m and w[j + 1] <= uq:
            j += 1
        while j > 0 and w[j] > uq:
            j -= 1
        pm = 0.5 * (w[j] + w[j + 1])
        ph = 0.5 * (w[j + 1] - w[j])
        x = (uq - pm) / ph
        vx, vy = _poly_d1(coef, j, x)
        sp = math.sqrt(vx * vx + vy * vy)
        if node_kappa or q <= 1 or q >= n - 1:
            ax, ay = _poly_d2(coef, j, x, ph)
            sp3 = sp * sp * sp
            kappa[q] = (vx * ay - vy * ax) / sp3 if sp3 > 0 else np.inf
        else:
            kappa[q] = np.nan
        theta[q] = math.atan2(vy, vx)
        if sp <= still_speed:
            still = True
    corr = 0.0  # np.unwrap
    prev = theta[0]
    for q in range(1, n + 1):
        raw = theta[q]
        dd = raw - prev
        if abs(dd) >= math.pi:
            dm = (dd + math.pi) % (2.0 * math.pi) - math.pi
            if dm == -math.pi and dd > 0:
                dm = math.pi
            corr += dm - dd
        theta[q] = raw + corr
        prev = raw
    end_caps = np.empty(4)  # the cap at the nodes 0, 1, n - 1 and n
    for q, node in enumerate((0, 1, n - 1, n)):
        end_caps[q] = speed_cap(kappa[node], limits)
    return u, kappa, theta, still, end_caps


@njit(cache=True, **NO_REFCOUNT)
def _evaluate(
    coef, p, piece, w, a, b, flip, k_free, p2b, shift, X, S, V, gam, taylor, unrolled
):  # pragma: no cover - compiled
    """Bound on ``|kappa|`` (1/m) on ``[a, b]`` inside polynomial piece ``piece``.

    ``gam`` receives the Taylor coefficients of ``c_t`` (:func:`_taylor`; the caller samples
    ``|kappa|`` from them with :func:`_sampled` where it needs that; ``taylor=False``: the
    caller filled ``gam`` for this interval already); the bound is that of
    :func:`bound_from_taylor`. A cubic piece without a zero-speed end goes to
    :func:`trajopt.timing._cap_cubic.bound_cubic` (the same operations unrolled) unless
    ``unrolled`` is False. The helpers are compiled functions of their own, called with one
    signature each (LLVM inlines them into this one); numba's own inlining of them took
    longer to compile than all of them together.
    """
    if p == 3 and flip == 0 and unrolled:  # the common case, unrolled (same operations)
        return bound_cubic(coef, piece, w, a, b, gam)
    if taylor:
        _taylor(coef, p, piece, w, a, b, gam)
    if p < 2:
        return 0.0
    sh = 1 if flip == -1 else 0  # powers of t, or of 1 - t (zero speed at t = 1)
    zero = np.int64(0)  # a run-time 0, not a literal: one compiled signature of each callee
    for i in range(p):
        for d in range(2):
            acc = 0.0
            for k in range(i, p):
                acc += shift[sh, i, k] * gam[k, d]
            V[i, d] = acc
    if flip == 0 or not _zero_start(V, p):
        nx, ns = _cross_and_norm(V, p, X, S)
        bx = _bernstein_max_abs(X, zero, nx, p2b)
        bs = _bernstein_min(S, zero, ns, p2b)
        if bx == 0.0:
            return 0.0
        if not bs > 0.0:
            return np.inf
        return bx / (bs * math.sqrt(bs))
    # V = t g: bound on g (see curvature_bound._zero_speed_bound)
    m = p - 1
    if m < 2:
        return 0.0
    for i in range(m):
        V[i, 0] = V[i + 1, 0]
        V[i, 1] = V[i + 1, 1]
    gsum = 0.0
    for i in range(m):
        gsum += abs(V[i, 0]) + abs(V[i, 1])
    nx, ns = _cross_and_norm(V, m, X, S)
    s_min = _bernstein_min(S, zero, ns, p2b)
    y0 = X[0]
    base = _bernstein_max_abs(X, zero + 1, nx - 1, p2b)
    if s_min > 0.0:
        base = base / (s_min * math.sqrt(s_min))
    else:
        base = np.inf
    if y0 == 0.0:
        return base
    if not s_min > 0.0:
        return np.inf
    k_ref = max(base, k_free)
    t0 = abs(y0) / (TIP_RTOL * k_ref * (s_min * math.sqrt(s_min)))
    if t0 * t0 * gsum <= TIP_M:
        return max(base, 0.0) * (1.0 + TIP_RTOL)
    return np.inf


@njit(cache=True)
def _interval_bounds(
    w,
    coef,
    nodes,
    s_nodes,
    h,
    n,
    zero_speed,
    limits,
    k_grid,
    gl_x,
    gl_w,
    rtol,
    p2b,
    shift,
    X,
    S,
    V,
    unrolled,
):  # pragma: no cover - compiled
    """``interval_kappa_max`` on the pieces' polynomials: ``(kmax, cap)`` per grid interval.

    ``kmax`` (1/m) bounds ``|kappa|`` over each interval and ``cap`` is its
    :func:`speed_cap`; ``p2b``, ``shift`` from :func:`matrices`, ``X``, ``S``, ``V`` from
    :func:`workspace`, ``unrolled`` as :func:`_evaluate`'s.
    """
    m = w.shape[0] - 1
    p = coef.shape[1]
    gam = np.empty((p, 2))
    cap0 = speed_cap(0.0, limits)
    k_free = 0.0
    for k in k_grid:
        if speed_cap(k, limits) >= cap0:
            k_free = k
    # zero parametric speed at an end of the domain
    flip = np.zeros(m, np.int64)
    vx, vy = _poly_d1(coef, np.int64(0), -1.0)  # np.int64: no literal-0 signature
    if math.hypot(vx, vy) <= zero_speed:
        flip[0] = 1
    vx, vy = _poly_d1(coef, m - 1, 1.0)
    if math.hypot(vx, vy) <= zero_speed and flip[m - 1] == 0:
        flip[m - 1] = -1
    la = w[:-1].copy()
    lb = w[1:].copy()
    lpc = np.arange(m)
    lsa = np.empty(m)
    lsb = np.empty(m)
    for i in range(m):
        lsa[i] = _s_at_u(la[i], i, w, coef, nodes, s_nodes, gl_x, gl_w)
        lsb[i] = _s_at_u(lb[i], i, w, coef, nodes, s_nodes, gl_x, gl_w)
    kmax = np.zeros(n)
    work = m
    for depth in range(MAX_DEPTH + 1):
        cnt = la.shape[0]
        split = np.zeros(cnt, np.bool_)
        kb = np.empty(cnt)
        n_split = 0
        final = work >= MAX_WORK or depth == MAX_DEPTH  # every bound is kept as it is
        for i in range(cnt):
            wide = lsb[i] - lsa[i] > h and not final
            taylor = True  # whether _evaluate computes gam (False: it holds this interval's)
            if wide and flip[i] == 0:
                # a sampled curvature above k_free: the bound (>= every value) binds as
                # well, and a wide piece binding is split whatever its bound
                _taylor(coef, p, lpc[i], w, la[i], lb[i], gam)
                if _sampled(gam, p) > k_free * (1.0 + 1e-9):
                    split[i] = True
                    n_split += 1
                    continue
                taylor = False
            k_b = _evaluate(
                coef,
                p,
                lpc[i],
                w,
                la[i],
                lb[i],
                flip[i],
                k_free,
                p2b,
                shift,
                X,
                S,
                V,
                gam,
                taylor,
                unrolled,
            )
            if k_b > k_free and wide:  # split: no sample needed
                split[i] = True
                n_split += 1
                continue
            k_s = _sampled(gam, p)  # the Taylor coefficients _evaluate left in gam
            kb[i] = max(k_b, k_s)
            if k_b > k_free and speed_cap(k_b, limits) < speed_cap(k_s, limits) * (1.0 - rtol):
                split[i] = True
                n_split += 1
        last = n_split == 0 or final
        for i in range(cnt):
            if split[i] and not last:
                continue
            ia = min(max(int(lsa[i] / h), 0), n - 1)
            ib = min(max(int(lsb[i] / h), 0), n - 1)
            for q in range(ia, ib + 1):
                if kb[i] > kmax[q]:
                    kmax[q] = kb[i]
        if last:
            break
        na = np.empty(2 * n_split)
        nb = np.empty(2 * n_split)
        nsa = np.empty(2 * n_split)
        nsb = np.empty(2 * n_split)
        npc = np.empty(2 * n_split, np.int64)
        nfl = np.zeros(2 * n_split, np.int64)
        r = 0
        for i in range(cnt):
            if not split[i]:
                continue
            mid = 0.5 * (la[i] + lb[i])
            ia = min(max(int(lsa[i] / h), 0), n - 1)
            if lsb[i] - lsa[i] <= h and ia == min(max(int(lsb[i] / h), 0), n - 1):
                # within one grid interval and no wider than h: every value in
                # [lsa, lsb] maps the halves (and their halves) as the exact one would
                smid = 0.5 * (lsa[i] + lsb[i])
            else:
                smid = _s_at_u(mid, lpc[i], w, coef, nodes, s_nodes, gl_x, gl_w)
            na[r], nb[r], nsa[r], nsb[r], npc[r] = la[i], mid, lsa[i], smid, lpc[i]
            nfl[r] = 1 if flip[i] == 1 else 0
            q = n_split + r
            na[q], nb[q], nsa[q], nsb[q], npc[q] = mid, lb[i], smid, lsb[i], lpc[i]
            nfl[q] = -1 if flip[i] == -1 else 0
            r += 1
        la, lb, lsa, lsb, lpc, flip = na, nb, nsa, nsb, npc, nfl
        work += la.shape[0]
    cap = np.empty(n)
    for q in range(n):
        cap[q] = speed_cap(kmax[q], limits)
    return kmax, cap
