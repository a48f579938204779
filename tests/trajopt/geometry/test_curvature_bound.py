"""Tests of trajopt.geometry._curvature_bound against hand derivations and dense sampling."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from tests.reference import dense_kappa_max_per_interval
from trajopt.geometry._bspline import BSplineCurve, clamped_uniform_knots
from trajopt.geometry._curvature_bound import (
    curvature_rate_bounds,
    interval_kappa_max,
    interval_steer_cap,
    kappa_bound,
)
from trajopt.robot._robot import Robot

ROBOT = Robot(
    v_max=0.5,
    a_max=0.5,
    j_max=2.0,
    a_lat_max=0.5,
    omega_max=1.5,
    track_width=None,
    wheel_v_max=None,
)


def parabola() -> BSplineCurve:
    """``c(u) = (u, u^2)`` on ``[-1, 1]``: a quadratic Bezier, ``kappa = 2 / (1 + 4u^2)^1.5``."""
    t = np.array([-1.0, -1.0, -1.0, 1.0, 1.0, 1.0])
    return BSplineCurve(t, np.array([[-1.0, 1.0], [0.0, -1.0], [1.0, 1.0]]), 2)


def parabola_kappa(u):
    return 2.0 / (1.0 + 4.0 * np.asarray(u) ** 2) ** 1.5


@pytest.mark.parametrize("a,b", [(-0.1, 0.1), (0.2, 0.3), (-1.0, -0.5), (0.0, 1.0)])
def test_parabola_bound_holds_and_tightens(a, b):
    # |kappa| peaks at u = 0 (2 1/m) and falls off monotonically in |u|
    exact = parabola_kappa(0.0 if a <= 0.0 <= b else min(abs(a), abs(b)))
    c = parabola()
    k = float(kappa_bound(c, np.array([a]), np.array([b]), 2)[0])
    assert k >= exact * (1 - 1e-12)
    # on 2^10 pieces the largest bound is within 1e-4 of the exact maximum
    e = np.linspace(a, b, 1025)
    kk = kappa_bound(c, e[:-1], e[1:], 2)
    assert np.all(
        kk
        >= parabola_kappa(np.where(e[:-1] * e[1:] <= 0, 0.0, np.minimum(abs(e[:-1]), abs(e[1:]))))
        * (1 - 1e-12)
    )
    assert kk.max() == pytest.approx(exact, rel=1e-4)


@settings(
    max_examples=12,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)
@given(
    pts=st.lists(
        st.tuples(st.floats(-2, 2), st.floats(-2, 2)), min_size=4, max_size=9, unique=True
    ),
    degree=st.sampled_from([2, 3, 5]),
)
def test_grid_bounds_cover_dense_samples(pts, degree):
    p = np.asarray(pts, dtype=float)
    assume(len(p) > degree and np.min(np.hypot(*np.diff(p, axis=0).T)) > 0.2)
    c = BSplineCurve(clamped_uniform_knots(len(p), degree), p, degree)
    sp = c.speed(np.linspace(*c.domain, 2001))
    assume(np.min(sp) > 0.05 * np.max(sp))
    n = 400
    h = c.length / n
    kmax = interval_kappa_max(c, h, n, degree, ROBOT.speed_cap)
    dense = dense_kappa_max_per_interval(c, h, n)
    # a rigorous bound: never below a sample (up to the trapezoid rule's arc-length error,
    # which can move a sample into the neighbouring interval)
    nb = np.maximum(kmax, np.maximum(np.r_[kmax[1:], 0.0], np.r_[0.0, kmax[:-1]]))
    assert np.all(dense <= nb * (1 + 1e-9) + 1e-12)
    # and a tight one where it matters: the cap of the bound within 0.2 % of the sampled cap
    cap_b = ROBOT.speed_cap(kmax)
    cap_d = ROBOT.speed_cap(
        np.maximum(dense, np.maximum(np.r_[dense[1:], 0.0], np.r_[0.0, dense[:-1]]))
    )
    assert np.all(cap_b >= cap_d * (1 - 2e-3) - 1e-12)


def test_zero_speed_end_with_collinear_points_has_its_finite_limit():
    # P0 = P1, P2 and P3 on one line through P0: the curvature tends to a finite limit
    p = np.array([[0.0, 0.0], [0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 1.0], [4.0, 1.0]])
    c = BSplineCurve(clamped_uniform_knots(len(p), 3), p, 3)
    n = 200
    kmax = interval_kappa_max(c, c.length / n, n, 3, ROBOT.speed_cap)
    assert np.all(np.isfinite(kmax))
    u = np.linspace(*c.domain, 200_001)[1:]
    assert kmax.max() >= np.abs(c.curvature(u)).max() * (1 - 1e-9)


def test_zero_speed_end_that_turns_is_unbounded():
    p = np.array([[0.0, 0.0], [0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [2.0, 2.0]])
    c = BSplineCurve(clamped_uniform_knots(len(p), 3), p, 3)
    n = 100
    kmax = interval_kappa_max(c, c.length / n, n, 3, ROBOT.speed_cap)
    assert np.isinf(kmax[0]) and np.all(np.isfinite(kmax[1:]))


def test_a_cusp_is_unbounded():
    # x = u^2, y = u^3 on [-1, 1]: c'(0) = 0 and the curve turns back on itself
    t = np.array([-1.0] * 4 + [1.0] * 4)
    # power basis (u^2, u^3) as a cubic Bezier on [-1, 1]
    ctrl = np.array([[1.0, -1.0], [-1.0 / 3.0, 1.0], [-1.0 / 3.0, -1.0], [1.0, 1.0]])
    c = BSplineCurve(t, ctrl, 3)
    assert np.allclose(c(np.array([0.5]))[0], [0.25, 0.125])
    n = 100
    kmax = interval_kappa_max(c, c.length / n, n, 3, ROBOT.speed_cap)
    assert np.isinf(kmax).sum() >= 1


def _scipy_kappa_rate(curve, u):
    """``|kappa|`` and ``|d kappa / ds|`` from scipy's BSpline derivatives (by hand:
    ``kappa = x'y'' - y'x'' / |c'|^3``, ``d kappa / ds = (X' S - 1.5 X S') / S^3``)."""
    from scipy.interpolate import BSpline

    sp = BSpline(np.asarray(curve.t), np.asarray(curve.c), curve.k)
    d1, d2, d3 = (sp.derivative(k)(u) for k in (1, 2, 3))
    X = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    dX = d1[:, 0] * d3[:, 1] - d1[:, 1] * d3[:, 0]
    S = (d1**2).sum(axis=1)
    dS = 2.0 * (d1 * d2).sum(axis=1)
    return np.abs(X) / S**1.5, np.abs(dX * S - 1.5 * X * dS) / S**3


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(0, 10_000))
def test_curvature_rate_bounds_hold_on_dense_samples(seed):
    """On random sub-intervals of the pieces of random cubics, ``|d kappa / ds|`` never exceeds
    the bound and ``|kappa|`` never falls below it (scipy's derivatives, 201 points each)."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(4, 9))
    curve = BSplineCurve(clamped_uniform_knots(n, 3, (0.0, 2.0)), rng.random((n, 2)) * 4.0, 3)
    bp = np.unique(curve.t)
    j = rng.integers(0, len(bp) - 1, size=30)
    lo, w = bp[j], bp[j + 1] - bp[j]
    f = np.sort(rng.random((30, 2)), axis=1)
    a, b = lo + f[:, 0] * w, lo + np.maximum(f[:, 1], f[:, 0] + 1e-3) * w
    b = np.minimum(b, lo + w)
    k_lo, rate = curvature_rate_bounds(curve, a, b, 3)
    for i in range(30):
        u = np.linspace(a[i], b[i], 201)
        k, r = _scipy_kappa_rate(curve, u)
        assert np.all(r <= rate[i] * (1 + 1e-9) + 1e-12), (i, r.max(), rate[i])
        assert np.all(k >= k_lo[i] * (1 - 1e-9) - 1e-12), (i, k.min(), k_lo[i])


def test_interval_steer_cap_is_below_the_exact_cap_everywhere():
    """The steering-rate cap per grid interval against the exact pointwise cap at about 100
    points of every interval (scipy's derivatives; the arc length by scipy's cumulative
    Simpson rule on 400 001 points; points within 1e-7 m of an interval's end left out), on
    a wiggly cubic: never above, and where it binds within 5 % of the sampled minimum over
    the interval and its neighbours."""
    from scipy.integrate import cumulative_simpson
    from scipy.interpolate import BSpline

    car = Robot(drive="ackermann", min_turning_radius=0.2, wheelbase=0.3, steer_rate_max=0.4)
    rng = np.random.default_rng(3)
    curve = BSplineCurve(clamped_uniform_knots(9, 3, (0.0, 1.0)), rng.random((9, 2)) * 2.0, 3)
    n = 400
    h = curve.length / n
    cap = interval_steer_cap(curve, h, n, 3, car.drive.steer_speed_cap, car.v_max)
    sp = BSpline(np.asarray(curve.t), np.asarray(curve.c), 3).derivative()
    u = np.linspace(*curve.domain, 400_001)
    s = cumulative_simpson(np.hypot(*sp(u).T), x=u, initial=0.0)
    k, r = _scipy_kappa_rate(curve, u)
    exact = car.drive.steer_speed_cap(k, r)
    i = np.clip((s / h).astype(int), 0, n - 1)
    inner = np.abs(s - np.round(s / h) * h) > 1e-7
    lowest = np.full(n, np.inf)
    np.minimum.at(lowest, i[inner], exact[inner])
    assert np.all(cap <= lowest * (1 + 1e-9)), np.max(cap / lowest)
    # tight up to the neighbouring intervals (a bisected piece touching two intervals gives
    # both its bound)
    near = np.minimum(lowest, np.minimum(np.r_[np.inf, lowest[:-1]], np.r_[lowest[1:], np.inf]))
    binds = lowest < car.v_max
    assert binds.sum() > 50
    assert np.all(cap[binds] >= 0.95 * near[binds]), np.min(cap[binds] / near[binds])
