"""Bounds on the curvature (and its rate) of a piecewise-polynomial curve over intervals.

The timing needs the largest ``|kappa|`` over every arc-length interval of its cap table,
however narrow a curvature peak is. Sampling cannot promise that (a near-cusp of a B-spline
puts a peak of 70 1/m inside a millimetre); a bound can. On an interval ``[a, b]`` inside
one polynomial piece of degree ``p``, write the curve in the local variable
``t = (u - a)/(b - a)`` in ``[0, 1]``. Its velocity ``V(t) = c_t`` is a polynomial of degree
``p - 1``, and so are

* ``X(t) = V x V'`` (degree ``2p - 3``), the numerator of the signed curvature, and
* ``S(t) = |V|^2`` (degree ``2p - 2``),

with ``kappa = X / S^(3/2)`` (invariant under the change of variable). A polynomial on
``[0, 1]`` lies between the smallest and the largest of its Bernstein coefficients, so

    ``|kappa(t)| <= max_i |X_i| / (min_i S_i)^(3/2)``  whenever ``min_i S_i > 0``

is a rigorous bound. Bernstein ranges converge to the true range as ``O((b - a)^2)``, so
bisecting an interval whose bound is loose (its speed cap more than ``rtol`` below the cap of
the largest sampled curvature) makes it tight; bisection stops at a fixed depth, and the
bound stays rigorous whatever the depth.

Zero parametric speed at an end of the curve (Bezier chains whose first two control points
coincide) makes ``min S = 0``. There ``V = t g(t)`` and ``kappa = (g x g') / (t |g|^3)``; when
``g x g'`` vanishes at ``t = 0`` (the curvature has a finite limit, e.g. the third control
point on the line of the first two) the quotient ``q = (g x g')/t`` gives the bound
``max |q_i| / (min |g|^2_i)^(3/2)``. Control points collinear only up to round-off leave a
residue ``Y0 = (g x g')(0)`` whose term ``Y0 / (t |g|^3)`` matters only on a tip of at most
``1e-6`` m next to the end (``1e-3`` of the larger of the bound and the curvature from which the
speed cap binds, ``k_free``): the bound leaves that tip out; a larger tip means the curve turns
at the zero-speed end, and the bound is ``inf``. A zero speed is one below ``1e-9`` of the
mean parametric speed (control points that coincide up to round-off).
"""

from __future__ import annotations

from collections.abc import Callable
from math import comb

import numpy as np

#: A parametric speed (or a velocity polynomial's value at ``t = 0``) below this fraction of
#: the mean parametric speed (of the polynomial's largest coefficient) counts as zero.
ZERO_SPEED_RATIO = 1e-9
#: Bisections of one interval at most.
MAX_DEPTH = 30
#: Intervals evaluated by the refinement at most (per call).
MAX_WORK = 400_000
#: Arc length (m) next to a zero-speed end that the bound may leave out, at most.
TIP_M = 1e-6
#: Share of ``max(bound, k_free)`` (relative) the tip term may reach where the bound holds;
#: the bound is raised by this share.
TIP_RTOL = 1e-3


def interval_kappa_max(
    curve,
    h: float,
    n: int,
    degree: int,
    speed_cap: Callable[[np.ndarray], np.ndarray],
    *,
    rtol: float = 1e-3,
) -> np.ndarray:
    """Upper bound on ``|kappa|`` over each arc-length interval ``[i h, (i + 1) h]``.

    The curve's polynomial pieces are bisected in ``u`` (top down) while a piece's bound
    exceeds the curvature from which the speed cap binds and the piece is either longer
    than ``h`` or loose (its cap more than ``rtol`` below the cap of the largest curvature
    sampled in it). Each final piece's bound goes to every grid interval its exact
    arc-length range touches (``curve.s_at_u``), so the table is rigorous whatever the
    accuracy of the grid's ``u(s)`` lookup.

    Parameters
    ----------
    curve : ParametricCurve
        A polynomial of degree ``<= degree`` between consecutive ``curve.breakpoints()``;
        ``curve(u, nu)`` gives derivatives up to ``degree``.
    h : float
        Grid spacing in arc length (m).
    n : int
        Number of grid intervals (``n h`` is the curve's length).
    degree : int
        Polynomial degree of the pieces (>= 1).
    speed_cap : callable
        ``|kappa| (1/m) -> speed cap (m/s)``, non-increasing (``Robot.speed_cap``).
    rtol : float
        Relative tightness asked of the cap (default 1e-3).

    Returns
    -------
    ndarray, shape (n,)
        ``max |kappa|`` bounds (1/m); ``inf`` where the curvature is unbounded.
    """
    lo, hi = (float(x) for x in curve.domain)
    bp = np.asarray(curve.breakpoints(), dtype=float)
    w = np.union1d([lo, hi], bp[(bp > lo) & (bp < hi)])
    a, b = w[:-1], w[1:]
    keep = b > a
    a, b = a[keep], b[keep]
    sa, sb = _s_at(curve, a), _s_at(curve, b)

    # zero parametric speed at an end of the domain: expand from that end
    sp_scale = curve.length / (hi - lo)
    v_ends = np.hypot(*np.asarray(curve(np.array([lo, hi]), 1), dtype=float).T)
    flip = np.zeros(a.shape, dtype=np.int8)  # +1: zero speed at a, -1: at b
    if v_ends[0] <= ZERO_SPEED_RATIO * sp_scale:
        flip[0] = 1
    if v_ends[1] <= ZERO_SPEED_RATIO * sp_scale and flip[-1] == 0:
        flip[-1] = -1

    k_free = _free_curvature(speed_cap)
    k_b = kappa_bound(curve, a, b, degree, flip, k_free)
    k_s = _sampled_kappa(curve, a, b)
    split = _to_split(k_b, k_s, sb - sa, h, k_free, speed_cap, rtol)
    work = a.size
    done = [(a[~split], b[~split], sa[~split], sb[~split], np.maximum(k_b, k_s)[~split])]
    for _ in range(MAX_DEPTH):
        if not np.any(split) or work >= MAX_WORK:
            break
        la, lb, lf, lsa, lsb = a[split], b[split], flip[split], sa[split], sb[split]
        mid = 0.5 * (la + lb)
        smid = _s_at(curve, mid)
        a = np.concatenate([la, mid])
        b = np.concatenate([mid, lb])
        sa = np.concatenate([lsa, smid])
        sb = np.concatenate([smid, lsb])
        flip = np.concatenate([np.where(lf == 1, 1, 0), np.where(lf == -1, -1, 0)]).astype(np.int8)
        k_b = kappa_bound(curve, a, b, degree, flip, k_free)
        k_s = _sampled_kappa(curve, a, b)
        work += a.size
        split = _to_split(k_b, k_s, sb - sa, h, k_free, speed_cap, rtol)
        done.append((a[~split], b[~split], sa[~split], sb[~split], np.maximum(k_b, k_s)[~split]))
    if np.any(split):  # out of depth or work: keep the (rigorous) bounds as they are
        done.append((a[split], b[split], sa[split], sb[split], np.maximum(k_b, k_s)[split]))
    s_a = np.concatenate([d[2] for d in done])
    s_b = np.concatenate([d[3] for d in done])
    k = np.concatenate([d[4] for d in done])
    return _to_grid(s_a, s_b, k, h, n, np.maximum, 0.0)


def _to_grid(s_a, s_b, values, h: float, n: int, ufunc, fill: float) -> np.ndarray:
    """Spread each piece's value over the grid intervals its arc-length range touches.

    Interval ``[i h, (i + 1) h]`` combines the values of every piece ``[s_a, s_b]`` that
    touches it by ``ufunc`` (``np.maximum`` or ``np.minimum``), starting from ``fill``.
    """
    i_a = np.clip((s_a / h).astype(np.int64), 0, n - 1)
    i_b = np.clip((s_b / h).astype(np.int64), 0, n - 1)
    count = i_b - i_a + 1
    idx = np.repeat(i_a, count) + (
        np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
    )
    out = np.full(n, fill)
    ufunc.at(out, idx, np.repeat(values, count))
    return out


def _s_at(curve, u: np.ndarray) -> np.ndarray:
    return np.asarray(curve.s_at_u(u), dtype=float)


def _to_split(k_b, k_s, ds, h, k_free, speed_cap, rtol) -> np.ndarray:
    """Pieces to bisect.

    The cap binds somewhere, and the piece spans more than one grid interval or its bound is
    loose.
    """
    binds = k_b > k_free
    return binds & ((ds > h) | _loose(k_b, k_s, speed_cap, rtol))


def _free_curvature(speed_cap) -> float:
    """Largest curvature (1/m) on a log grid at which the cap still equals its value at 0."""
    k = np.logspace(-9, 6, 151)
    cap = np.asarray(speed_cap(k), dtype=float)
    free = k[cap >= float(speed_cap(0.0))]
    return float(free[-1]) if free.size else 0.0


def _loose(bound, ref, speed_cap, rtol) -> np.ndarray:
    cap_b = np.asarray(speed_cap(bound), dtype=float)
    cap_r = np.asarray(speed_cap(ref), dtype=float)
    return cap_b < cap_r * (1.0 - rtol)


def _sampled_kappa(curve, a, b) -> np.ndarray:
    """``|kappa|`` at three interior points of each interval.

    ``|kappa|`` at three interior points of each interval (a hundredth of the way in from either
    end, and the middle): a lower bound of its maximum there. Interior points keep every sample
    on the interval's own polynomial piece (at a knot a curve reports the next piece's
    curvature, and a zero-speed end has none).
    """
    u = np.stack([a + 0.01 * (b - a), 0.5 * (a + b), b - 0.01 * (b - a)])
    d1 = np.asarray(curve(u, 1), dtype=float)
    d2 = np.asarray(curve(u, 2), dtype=float)
    cross = d1[..., 0] * d2[..., 1] - d1[..., 1] * d2[..., 0]
    sp3 = np.hypot(d1[..., 0], d1[..., 1]) ** 3
    with np.errstate(divide="ignore", invalid="ignore"):
        k = np.abs(cross) / sp3
    k = np.where(sp3 > 0, k, np.inf)
    return k.max(axis=0)


def kappa_bound(
    curve, a: np.ndarray, b: np.ndarray, degree: int, flip=None, k_free: float = 0.0
) -> np.ndarray:
    """Rigorous upper bound on ``|kappa|`` over each ``[a_i, b_i]`` (inside one piece).

    Parameters
    ----------
    curve : ParametricCurve
        Polynomial of degree ``<= degree`` on each ``[a_i, b_i]``.
    a, b : ndarray, shape (m,)
        Interval ends, ``a < b``.
    degree : int
        Polynomial degree ``p`` (>= 1).
    flip : ndarray of int, shape (m,), optional
        ``1`` where the parametric speed vanishes at ``a``, ``-1`` where it vanishes at
        ``b``, ``0`` elsewhere.
    k_free : float
        Curvature (1/m) below which the speed cap does not bind: the scale of the tip rule
        at a zero-speed end.

    Returns
    -------
    ndarray, shape (m,)
        Bounds (1/m); ``inf`` where the speed may vanish inside, or the curvature is
        unbounded at a zero-speed end.
    """
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    m = a.size
    p = int(degree)
    if m == 0:
        return np.zeros(0)
    if p < 2:
        return np.zeros(m)
    if flip is None:
        flip = np.zeros(m, dtype=np.int8)
    V = _velocity(curve, a, b, p, flip == -1)  # (zero speed, if any, at t = 0)
    out = _plain_bound(V)
    ends = np.flatnonzero(flip != 0)
    if ends.size:
        out[ends] = _zero_speed_bound(V[ends], k_free)
    return out


def _velocity(curve, a: np.ndarray, b: np.ndarray, p: int, rev: np.ndarray | None = None):
    """Velocity polynomials ``V`` (m, p, 2) of ``curve`` on ``[a_i, b_i]`` in ``t`` in [0, 1].

    Coefficients of the powers of ``t = (u - a) / (b - a)`` (of ``1 - t`` where ``rev``).
    """
    h = b - a
    mid = 0.5 * (a + b)
    # Taylor coefficients of c_t in tau = t - 1/2: gamma_k = h^(k+1) c^(k+1)(mid) / k!
    gam = np.empty((a.size, p, 2))
    for k in range(p):
        gam[:, k, :] = (
            np.asarray(curve(mid, k + 1), dtype=float) * (h ** (k + 1) / _fact(k))[:, None]
        )
    fwd, bwd = _shift_matrices(p)
    V = np.einsum("ik,mkd->mid", fwd, gam)
    if rev is not None and np.any(rev):
        V[rev] = np.einsum("ik,mkd->mid", bwd, gam[rev])
    return V


def curvature_rate_bounds(
    curve, a: np.ndarray, b: np.ndarray, degree: int
) -> tuple[np.ndarray, np.ndarray]:
    """Rigorous bounds on ``|kappa|`` from below and ``|d kappa / ds|`` from above.

    On each ``[a_i, b_i]`` inside one polynomial piece of degree ``degree``, with ``X = V x
    V'`` and ``S = |V|^2`` (module docstring), ``kappa = X / S^(3/2)`` and ``d kappa / ds =
    (d kappa / dt) / |V| = N / S^3`` with ``N = X' S - 3/2 X S'``. Bernstein ranges give
    ``|d kappa / ds| <= max |B(N)| / (min B(S))^3`` and, where ``B(X)`` keeps one sign,
    ``|kappa| >= min |B(X)| / (max B(S))^(3/2)`` (else 0).

    Returns
    -------
    kappa_lo, rate_hi : ndarray, shape (m,)
        1/m and 1/m^2; ``rate_hi`` is ``inf`` where the parametric speed may vanish.
    """
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    p = int(degree)
    if a.size == 0 or p < 2:
        return np.zeros(a.size), np.zeros(a.size)
    V = _velocity(curve, a, b, p)
    dV = _deriv(V)
    X = _mul(V[..., 0], dV[..., 1]) - _mul(V[..., 1], dV[..., 0])
    S = _mul(V[..., 0], V[..., 0]) + _mul(V[..., 1], V[..., 1])
    N = _mul(_deriv(X), S) - 1.5 * _mul(X, _deriv(S))
    bs = _bernstein(S)
    bx = _bernstein(X)
    s_lo, s_hi = bs.min(axis=1), bs.max(axis=1)
    n_hi = np.abs(_bernstein(N)).max(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        rate = np.where(s_lo > 0.0, n_hi / np.maximum(s_lo, 0.0) ** 3, np.inf)
        rate = np.where(n_hi == 0.0, 0.0, rate)
        one_sign = (bx.min(axis=1) > 0.0) | (bx.max(axis=1) < 0.0)
        k_lo = np.where(one_sign, np.abs(bx).min(axis=1) / s_hi**1.5, 0.0)
    return k_lo, rate


def interval_steer_cap(
    curve,
    h: float,
    n: int,
    degree: int,
    cap_of: Callable[[np.ndarray, np.ndarray], np.ndarray],
    v_free: float,
    *,
    rtol: float = 1e-2,
) -> np.ndarray:
    """Lower bound on a cap ``cap_of(|kappa|, |d kappa / ds|)`` over each ``[i h, (i + 1) h]``.

    ``cap_of`` must grow with ``|kappa|`` and fall with ``|d kappa / ds|`` (the steering-rate
    cap, :meth:`trajopt.drive.Ackermann.steer_speed_cap`): the bounds of
    :func:`curvature_rate_bounds` then bound it from below. As :func:`interval_kappa_max`,
    the curve's polynomial pieces are bisected (top down) while a piece's cap is below
    ``v_free`` (it may bind) and the piece spans more than ``h`` of arc length or its cap is
    more than ``rtol`` below the lowest exact cap at three interior points; each final
    piece's cap goes to every grid interval its exact arc-length range touches. Where the
    parametric speed may vanish the bound is infinite and the sampled cap is used instead
    (the library's curves never stop inside; a zero-speed end of another curve does).

    Returns
    -------
    ndarray, shape (n,)
        Caps (m/s), ``inf`` where the curvature does not change.
    """
    lo, hi = (float(x) for x in curve.domain)
    bp = np.asarray(curve.breakpoints(), dtype=float)
    w = np.union1d([lo, hi], bp[(bp > lo) & (bp < hi)])
    a, b = w[:-1], w[1:]
    keep = b > a
    a, b = a[keep], b[keep]
    sa, sb = _s_at(curve, a), _s_at(curve, b)

    def caps(a, b):
        k_lo, rate = curvature_rate_bounds(curve, a, b, degree)
        u = np.stack([a + 0.01 * (b - a), 0.5 * (a + b), b - 0.01 * (b - a)])
        sampled = np.asarray(
            cap_of(np.abs(curve.curvature(u)), np.abs(curve.curvature_rate(u))), dtype=float
        ).min(axis=0)
        bound = np.asarray(cap_of(k_lo, rate), dtype=float)
        return np.where(np.isfinite(rate), bound, sampled), sampled

    c_b, c_s = caps(a, b)
    split = (c_b < v_free) & ((sb - sa > h) | (c_b < c_s * (1.0 - rtol)))
    work = a.size
    done = [(sa[~split], sb[~split], c_b[~split])]
    for _ in range(MAX_DEPTH):
        if not np.any(split) or work >= MAX_WORK:
            break
        la, lb, lsa, lsb = a[split], b[split], sa[split], sb[split]
        mid = 0.5 * (la + lb)
        smid = _s_at(curve, mid)
        a, b = np.concatenate([la, mid]), np.concatenate([mid, lb])
        sa, sb = np.concatenate([lsa, smid]), np.concatenate([smid, lsb])
        c_b, c_s = caps(a, b)
        work += a.size
        split = (c_b < v_free) & ((sb - sa > h) | (c_b < c_s * (1.0 - rtol)))
        done.append((sa[~split], sb[~split], c_b[~split]))
    if np.any(split):  # out of depth or work: the (rigorous) caps as they are
        done.append((sa[split], sb[split], c_b[split]))
    s_a = np.concatenate([d[0] for d in done])
    s_b = np.concatenate([d[1] for d in done])
    c = np.concatenate([d[2] for d in done])
    return _to_grid(s_a, s_b, c, h, n, np.minimum, np.inf)


def _plain_bound(V: np.ndarray) -> np.ndarray:
    dV = _deriv(V)
    X = _mul(V[..., 0], dV[..., 1]) - _mul(V[..., 1], dV[..., 0])
    S = _mul(V[..., 0], V[..., 0]) + _mul(V[..., 1], V[..., 1])
    return _ratio_bound(X, S)


def _zero_speed_bound(V: np.ndarray, k_free: float) -> np.ndarray:
    """Bound for velocity polynomials whose value at ``t = 0`` is (numerically) zero.

    ``V = t g`` gives ``kappa = Y0 / (t |g|^3) + q / |g|^3`` with ``Y = g x g'``,
    ``Y0 = Y(0)`` and ``q = (Y - Y0) / t``. The bound ``B = max |q| / min |g|^3`` holds where
    the first term is below ``TIP_RTOL * max(B, k_free)``, i.e. for ``t >= t0``; the tip
    ``[0, t0]`` is left out when its arc length (at most ``t0^2 sum |g_i|``) is below ``TIP_M``
    metres, otherwise the curvature counts as unbounded (``inf``).
    """
    out = np.full(V.shape[0], np.inf)
    scale = np.abs(V).max(axis=(1, 2))
    v0 = np.hypot(V[:, 0, 0], V[:, 0, 1])
    ok = (v0 <= ZERO_SPEED_RATIO * scale) & (V.shape[1] >= 2)
    if np.any(~ok):
        out[~ok] = _plain_bound(V[~ok])
    if not np.any(ok):
        return out
    g = V[ok, 1:, :]  # V = t g
    if g.shape[1] < 2:  # g constant: a straight line
        out[ok] = 0.0
        return out
    dg = _deriv(g)
    Y = _mul(g[..., 0], dg[..., 1]) - _mul(g[..., 1], dg[..., 0])
    S = _mul(g[..., 0], g[..., 0]) + _mul(g[..., 1], g[..., 1])
    s_min = _bernstein(S).min(axis=1)
    q = Y[:, 1:]
    base = np.abs(_bernstein(q)).max(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        base = np.where(s_min > 0.0, base / np.maximum(s_min, 0.0) ** 1.5, np.inf)
        k_ref = np.maximum(base, k_free)
        t0 = np.abs(Y[:, 0]) / (TIP_RTOL * k_ref * np.maximum(s_min, 0.0) ** 1.5)
    tip = t0 * t0 * np.abs(g).sum(axis=(1, 2))
    res = np.where((s_min > 0.0) & (tip <= TIP_M), np.maximum(base, 0.0) * (1.0 + TIP_RTOL), np.inf)
    res = np.where(Y[:, 0] == 0.0, base, res)
    out[ok] = res
    return out


def _ratio_bound(X: np.ndarray, S: np.ndarray) -> np.ndarray:
    """``max |B(X)| / min B(S)^1.5`` over Bernstein coefficients, ``inf`` if ``min B(S) <= 0``."""
    bx = np.abs(_bernstein(X)).max(axis=1)
    bs = _bernstein(S).min(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = bx / np.maximum(bs, 0.0) ** 1.5
    r = np.where(bs > 0.0, r, np.inf)
    return np.where(bx == 0.0, 0.0, r)


def _deriv(P: np.ndarray) -> np.ndarray:
    """Return the derivative of power-basis polynomials ``P[:, i, ...]`` (coefficient of ``t^i``)."""
    n = P.shape[1]
    if n == 1:
        return np.zeros_like(P)
    k = np.arange(1, n, dtype=float).reshape((1, n - 1) + (1,) * (P.ndim - 2))
    return P[:, 1:] * k


def _mul(P: np.ndarray, Q: np.ndarray) -> np.ndarray:
    """Product of scalar power-basis polynomials, shapes (m, i) x (m, j) -> (m, i + j - 1)."""
    m, i = P.shape
    j = Q.shape[1]
    out = np.zeros((m, i + j - 1))
    for r in range(i):
        out[:, r : r + j] += P[:, r : r + 1] * Q
    return out


def _bernstein(P: np.ndarray) -> np.ndarray:
    """Bernstein coefficients on ``[0, 1]`` of power-basis polynomials ``P`` (m, n + 1)."""
    return P @ _power_to_bernstein(P.shape[1] - 1).T


_CACHE: dict[tuple[str, int], np.ndarray] = {}


def _power_to_bernstein(n: int) -> np.ndarray:
    """``M`` with ``b = M @ alpha``: ``b_i = sum_{k <= i} C(i, k) / C(n, k) alpha_k``."""
    key = ("p2b", n)
    M = _CACHE.get(key)
    if M is None:
        M = np.zeros((n + 1, n + 1))
        for i in range(n + 1):
            for k in range(i + 1):
                M[i, k] = comb(i, k) / comb(n, k)
        _CACHE[key] = M
    return M


def _shift_matrices(p: int) -> tuple[np.ndarray, np.ndarray]:
    """Map of coefficients in ``tau = t - 1/2`` to powers of ``t`` and of ``1 - t``."""
    key = ("shift", p)
    M = _CACHE.get(key)
    if M is None:
        fwd = np.zeros((p, p))
        bwd = np.zeros((p, p))
        for k in range(p):  # tau^k = (t - 1/2)^k = (1/2 - t')^k with t' = 1 - t
            for i in range(k + 1):
                fwd[i, k] = comb(k, i) * (-0.5) ** (k - i)
                bwd[i, k] = comb(k, i) * 0.5 ** (k - i) * (-1.0) ** i
        M = np.stack([fwd, bwd])
        _CACHE[key] = M
    return M[0], M[1]


def _fact(k: int) -> float:
    out = 1.0
    for i in range(2, k + 1):
        out *= i
    return out
