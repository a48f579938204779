"""Tests of trajopt.timing: the timing's compiled paths against their NumPy references and independent samples.

* ``trajopt.timing._cap_kernel``: the per-interval Bernstein bound equals
  ``curvature_bound.kappa_bound`` (the NumPy reference) within 1e-12, the grid bounds equal
  ``interval_kappa_max`` and cover densely sampled ``|kappa|``, and the node tables equal the
  curve's own ``u_at_s``, curvature and heading.
  The unrolled bound of a cubic piece (``cap_cubic.bound_cubic``) equals the general loops
  bit for bit.
* ``trajopt.timing._greedy``: repeating cruise steps gives the same phases as testing every
  step, also when its buffers fill up.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import trajopt.timing._cap_kernel as cap_kernel
import trajopt.timing._greedy as greedy
from tests.reference import dense_kappa_max_per_interval
from trajopt.geometry._bspline import BSplineCurve, clamped_uniform_knots
from trajopt.geometry._curvature_bound import interval_kappa_max, kappa_bound
from trajopt.robot._robot import Robot
from trajopt.timing._cap_table import T_MIN

ROBOT = Robot()
SETTINGS = settings(
    max_examples=15,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)
POINTS = st.lists(
    st.tuples(st.floats(-2, 2), st.floats(-2, 2)), min_size=4, max_size=10, unique=True
)


def _curve(pts, degree: int) -> BSplineCurve:
    p = np.asarray(pts, dtype=float)
    assume(len(p) > degree and np.min(np.hypot(*np.diff(p, axis=0).T)) > 0.2)
    c = BSplineCurve(clamped_uniform_knots(len(p), degree), p, degree)
    sp = c.speed(np.linspace(*c.domain, 2001))
    assume(np.min(sp) > 0.05 * np.max(sp))
    return c


def _fact(k: int) -> float:
    return float(math.factorial(k))


@SETTINGS
@given(pts=POINTS, degree=st.sampled_from([2, 3, 4, 5]), seed=st.integers(0, 2**31 - 1))
def test_compiled_bound_equals_the_numpy_reference(pts, degree, seed):
    c = _curve(pts, degree)
    rng = np.random.default_rng(seed)
    bp = c.breakpoints()
    piece = rng.integers(0, len(bp) - 1, 20)
    lo, hi = bp[piece], bp[piece + 1]
    f = np.sort(rng.uniform(0.0, 1.0, (2, 20)), axis=0)
    a, b = lo + f[0] * (hi - lo), lo + f[1] * (hi - lo)
    keep = b - a > 1e-6 * (hi - lo)
    a, b = a[keep], b[keep]
    ref = kappa_bound(c, a, b, degree)
    p2b, shift = cap_kernel.matrices(degree)
    X, S, V = cap_kernel.workspace(degree)
    for i in range(a.size):
        h, mid = b[i] - a[i], 0.5 * (a[i] + b[i])
        gam = np.stack(
            [c(np.array([mid]), k + 1)[0] * h ** (k + 1) / _fact(k) for k in range(degree)]
        )
        got = cap_kernel.bound_from_taylor(gam, 0, 0.0, p2b, shift, X, S, V)
        assert got == ref[i] or abs(got - ref[i]) <= 1e-12 * ref[i]
        # and it bounds |kappa| sampled densely on the interval
        u = np.linspace(a[i], b[i], 201)
        assert np.abs(c.curvature(u)).max() <= got * (1 + 1e-9)


@SETTINGS
@given(pts=POINTS, degree=st.sampled_from([2, 3, 5]))
def test_compiled_tables_equal_the_reference_and_cover_samples(pts, degree):
    c = _curve(pts, degree)
    n = 400
    h = c.length / n
    s = np.linspace(0.0, c.length, n + 1)
    tab = cap_kernel.polynomial_tables(c, ROBOT, s, degree)
    assert tab is not None
    ref = interval_kappa_max(c, h, n, degree, ROBOT.speed_cap)
    np.testing.assert_allclose(tab.kmax, ref, rtol=1e-12, atol=0.0)
    np.testing.assert_array_equal(tab.cap, ROBOT.speed_cap(tab.kmax))
    np.testing.assert_array_equal(tab.end_caps, ROBOT.speed_cap(tab.kappa[[0, 1, n - 1, n]]))
    u = c.u_at_s(s, exact=False)
    u[0], u[-1] = c.domain
    np.testing.assert_allclose(tab.u, u, rtol=0.0, atol=1e-12 * (c.domain[1] - c.domain[0]))
    np.testing.assert_allclose(tab.kappa, c.curvature(u), rtol=1e-9, atol=1e-9)
    # the heading is unwrapped from its first value, whose branch is a convention: a tangent
    # along -x may start at +pi or -pi (the sign of a zero y component); the two tables may
    # differ by one constant multiple of 2 pi
    ref_theta = np.unwrap(c.heading(u))
    turns = np.round((tab.theta[0] - ref_theta[0]) / (2 * np.pi))
    np.testing.assert_allclose(tab.theta - 2 * np.pi * turns, ref_theta, rtol=0.0, atol=1e-9)
    # rigorous: never below a dense sample (up to the trapezoid rule's arc-length error,
    # which can move a sample into the neighbouring interval)
    dense = dense_kappa_max_per_interval(c, h, n)
    k = tab.kmax
    nb = np.maximum(k, np.maximum(np.r_[k[1:], 0.0], np.r_[0.0, k[:-1]]))
    assert np.all(dense <= nb * (1 + 1e-9) + 1e-12)


def test_compiled_tables_at_zero_speed_ends():
    # P0 = P1 with P2 on their line: a finite limit; P0 = P1 with a turn: unbounded
    finite = np.array([[0.0, 0.0], [0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 1.0], [4.0, 1.0]])
    turns = np.array([[0.0, 0.0], [0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [2.0, 2.0]])
    for pts in (finite, turns):
        c = BSplineCurve(clamped_uniform_knots(len(pts), 3), pts, 3)
        n = 200
        s = np.linspace(0.0, c.length, n + 1)
        tab = cap_kernel.polynomial_tables(c, ROBOT, s, 3)
        ref = interval_kappa_max(c, c.length / n, n, 3, ROBOT.speed_cap)
        assert np.array_equal(np.isinf(tab.kmax), np.isinf(ref))
        fin = np.isfinite(ref)
        np.testing.assert_allclose(tab.kmax[fin], ref[fin], rtol=1e-12)
        # the heading at the zero-speed start is the tangent's limit (the curve's own rule)
        assert math.isclose(
            tab.theta[0], float(c.heading(np.array([c.domain[0]]))[0]), abs_tol=1e-12
        )


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), scale=st.sampled_from([1e-3, 1.0, 1e3]))
def test_unrolled_cubic_bound_equals_the_general_loops(seed, scale):
    rng = np.random.default_rng(seed)
    p2b, shift = cap_kernel.matrices(3)
    X, S, V = cap_kernel.workspace(3)
    for _ in range(50):
        w = np.sort(rng.uniform(0.0, 5.0, 4))
        coef = rng.normal(size=(3, 3, 2)) * scale
        if rng.random() < 0.2:
            coef[:, 2, :] = 0.0  # a quadratic
        piece = int(rng.integers(0, 3))
        a = w[piece] + (w[piece + 1] - w[piece]) * rng.uniform(0.0, 0.5)
        b = a + (w[piece + 1] - a) * rng.uniform(0.01, 1.0)
        got_gam, ref_gam = np.empty((3, 2)), np.empty((3, 2))
        args = (coef, 3, piece, w, a, b, 0, 1.0, p2b, shift, X, S, V)
        got = cap_kernel._evaluate(*args, got_gam, True, True)
        ref = cap_kernel._evaluate(*args, ref_gam, True, False)
        assert got == ref
        np.testing.assert_array_equal(got_gam, ref_gam)


def test_compiled_speed_cap_is_robots():
    k = np.r_[0.0, np.logspace(-6, 4, 200), -3.0, np.inf, np.nan]
    for robot in (ROBOT, Robot(track_width=None, wheel_v_max=None)):
        tw = 0.0 if robot.track_width is None else robot.track_width
        wv = math.inf if robot.wheel_v_max is None else robot.wheel_v_max
        lim = np.array([robot.v_max, robot.a_lat_max, robot.omega_max, tw, wv])
        got = np.array([cap_kernel.speed_cap(x, lim) for x in k])
        np.testing.assert_array_equal(got, robot.speed_cap(k))


@settings(max_examples=25, deadline=None)
@given(
    levels=st.lists(st.floats(0.05, 0.5), min_size=1, max_size=6),
    widths=st.lists(st.integers(1, 2000), min_size=6, max_size=6),
    v_end=st.sampled_from([0.0, 0.04]),
)
def test_cruise_steps_give_the_same_phases(levels, widths, v_end):
    # a piecewise-constant cap (plateaus of equal values, as on straight stretches)
    ci = np.concatenate([np.full(w, lv) for lv, w in zip(levels, widths, strict=False)])
    n = ci.size
    assume(n >= 64)
    h = 0.0025
    length = n * h
    stt, lg = greedy.build_table(ci)
    is_min = np.zeros(n, bool)
    is_min[1:-1] = (ci[1:-1] < ci[:-2]) & (ci[1:-1] <= ci[2:])
    min_s = np.flatnonzero(is_min) * h
    min_v = ci[is_min]
    cap = greedy.CapArrays(stt, lg, h, length, min_s, min_v)
    lim = greedy.GreedyLimits(0.0, 0.0, v_end, 0.5, 2.0, 0.02, 9, T_MIN, 10**6, True)
    fast = greedy.greedy(cap, lim, 0)
    slow = greedy.greedy(cap, lim._replace(cruise=False), 0)
    assert fast[2] == slow[2]
    np.testing.assert_array_equal(fast[0], slow[0])
    np.testing.assert_array_equal(fast[1], slow[1])
    # buffers too small at first: the greedy runs again with more room, same phases
    for cruise, ref in ((True, fast), (False, slow)):
        small = greedy.greedy(cap, lim._replace(cruise=cruise), 8)
        assert small[2] == ref[2]
        np.testing.assert_array_equal(small[0], ref[0])
        np.testing.assert_array_equal(small[1], ref[1])


def test_kernel_options_follow_what_numba_knows(monkeypatch):
    from numba.core import cpu

    import trajopt.timing._kernel_options as kernel_options

    assert kernel_options._no_refcount() == {"_nrt": False}  # this numba knows the option
    monkeypatch.setattr(cpu, "CPUTargetOptions", type("Bare", (), {}))
    assert kernel_options._no_refcount() == {}  # a numba without it: plain kernels
