"""Tests of trajopt.geometry: BSplineCurve against scipy and closed forms."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import BSpline, make_lsq_spline

from trajopt.errors import InvalidInputError
from trajopt.geometry import ParametricCurve
from trajopt.geometry._bspline import BSplineCurve, clamped_uniform_knots, concatenate


def _curve(n=8, k=3, seed=0):
    rng = np.random.default_rng(seed)
    return BSplineCurve(clamped_uniform_knots(n, k, (0.0, 2.0)), rng.normal(size=(n, 2)), k)


def test_matches_scipy_per_axis():
    c = _curve()
    u = np.linspace(0, 2, 37)
    for nu in range(4):
        for axis in range(2):
            ref = BSpline(c.t, c.c[:, axis], c.k)(u, nu)
            np.testing.assert_allclose(c(u, nu)[:, axis], ref, atol=1e-12)


@pytest.mark.parametrize("k", range(1, 7))
def test_de_boor_matches_scipy_with_repeated_knots(k):
    # degrees 1-6, a doubled interior knot, every derivative order up to k + 1, at random
    # parameters and at every knot (where the k-th derivative jumps: both take the right limit)
    rng = np.random.default_rng(k)
    n = k + 6
    t = clamped_uniform_knots(n, k, (0.3, 2.0))
    t[k + 2] = t[k + 1]
    c = BSplineCurve(t, rng.normal(size=(n, 2)), k)
    u = np.concatenate([rng.uniform(0.3, 2.0, 200), t[k : n + 1]])
    for nu in range(k + 2):
        ref = (
            np.stack([BSpline(t, c.c[:, a], k)(u, nu) for a in range(2)], axis=1)
            if nu <= k
            else 0.0
        )
        np.testing.assert_allclose(
            c(u, nu), np.broadcast_to(ref, (u.size, 2)), rtol=1e-12, atol=1e-10
        )
    for nu in range(1, k):
        ref = BSpline(t, c.c, k).derivative(nu)
        np.testing.assert_allclose(c.derivative(nu)(u), ref(u), rtol=1e-12, atol=1e-10)
    assert c(1.0).shape == (2,) and c(np.ones((3, 4)), 1).shape == (3, 4, 2)
    outside = np.array([-5.0, 0.29, 2.01, 7.0])  # clamped to the domain, as np.clip would
    ref = np.stack([BSpline(t, c.c[:, a], k)(np.clip(outside, 0.3, 2.0)) for a in range(2)], 1)
    np.testing.assert_allclose(c(outside), ref, rtol=1e-12, atol=1e-12)
    assert np.all(np.isnan(c(np.array([np.nan]), 1)))


def test_clamped_endpoints_and_derivative():
    c = _curve()
    np.testing.assert_allclose(c(0.0), c.c[0], atol=1e-14)
    np.testing.assert_allclose(c(2.0), c.c[-1], atol=1e-14)
    d = c.derivative()
    u = np.linspace(0, 2, 11)
    np.testing.assert_allclose(d(u), c(u, 1), atol=1e-12)
    assert d.k == 2


def test_convex_hull_of_spans():
    c = _curve(n=12, seed=3)
    u = np.linspace(0, 2, 2001)
    span = c.span_of(u)
    p = c(u)
    for j in np.unique(span):
        pts = c.c[j : j + c.k + 1]
        sel = p[span == j]
        assert np.all(sel >= pts.min(0) - 1e-12) and np.all(sel <= pts.max(0) + 1e-12)


def test_circle_fit_curvature():
    r = 2.0
    th = np.linspace(0, np.pi, 300)
    xy = np.c_[r * np.cos(th), r * np.sin(th)]
    t = clamped_uniform_knots(20, 3, (0, np.pi))
    c = BSplineCurve.from_scipy(make_lsq_spline(th, xy, t, 3))
    assert c.length == pytest.approx(np.pi * r, rel=1e-5)
    np.testing.assert_allclose(c.curvature(np.linspace(0.3, 2.8, 9)), 1 / r, rtol=5e-3)


@pytest.mark.parametrize(
    ("t", "c", "k", "match"),
    [
        (np.arange(8.0), np.zeros((3, 2)), 3, "at least k \\+ 1"),
        (np.arange(7.0), np.zeros((4, 2)), 3, "need n \\+ k \\+ 1 = 8 knots"),
        (np.arange(8.0)[::-1], np.zeros((4, 2)), 3, "non-decreasing"),
        (np.arange(8.0), np.zeros((4, 3)), 3, "shape \\(n, 2\\)"),
        (np.arange(8.0), np.full((4, 2), np.nan), 3, "finite"),
        (np.arange(8.0), np.zeros((4, 2)), 0, "degree k must be >= 1"),
    ],
)
def test_invalid(t, c, k, match):
    with pytest.raises(InvalidInputError, match=match):
        BSplineCurve(t, c, k)


def test_concatenate_traces_each_curve_on_its_stretch():
    """Three clamped cubics end to end: on each stretch the joined curve is that curve (scipy's
    BSpline of it, shifted), its length the sum, its knot multiplicity 3 at the joins."""
    rng = np.random.default_rng(7)
    curves, start = [], rng.random(2)
    for n, dom in [(6, (0.0, 2.0)), (4, (5.0, 5.5)), (8, (-1.0, 3.0))]:
        c = rng.random((n, 2)) * 3.0
        c[0] = start
        curves.append(BSplineCurve(clamped_uniform_knots(n, 3, dom), c, 3))
        start = c[-1]
    joined = concatenate(curves)
    offset = 0.0
    for cv in curves:
        a, b = cv.domain
        u = np.linspace(a, b, 97)
        ref = BSpline(np.asarray(cv.t), np.asarray(cv.c), 3)(u)
        np.testing.assert_allclose(joined(u - a + offset), ref, atol=1e-12)
        offset += b - a
    assert joined.domain == (0.0, pytest.approx(offset))
    assert joined.length == pytest.approx(sum(cv.length for cv in curves), rel=1e-12)
    joins = np.cumsum([cv.domain[1] - cv.domain[0] for cv in curves])[:-1]
    for u in joins:
        assert np.count_nonzero(np.isclose(joined.t, u)) == 3


def test_concatenate_refuses_gaps_and_mixed_degrees():
    a = BSplineCurve(clamped_uniform_knots(4, 3), np.arange(8.0).reshape(4, 2), 3)
    b = BSplineCurve(clamped_uniform_knots(4, 3), np.arange(8.0).reshape(4, 2) + 1.0, 3)
    with pytest.raises(InvalidInputError, match="starts .* m from where curve 0 ends"):
        concatenate([a, b])
    c = BSplineCurve(clamped_uniform_knots(3, 2), np.arange(6.0).reshape(3, 2) + 6.0, 2)
    with pytest.raises(InvalidInputError, match="degree 2"):
        concatenate([a, c])
    with pytest.raises(InvalidInputError, match="at least one curve"):
        concatenate([])


def _quad_length(c, u0, u1):
    """Arc length (m) of ``c`` between ``u0`` and ``u1`` by adaptive quadrature (scipy)."""
    from scipy.integrate import quad

    def speed(u):
        return float(np.hypot(*c(np.array([u]), 1)[0]))

    inner = [b for b in c.breakpoints() if u0 < b < u1]
    edges = [u0, *inner, u1]
    return sum(
        quad(speed, a, b, epsabs=1e-14, epsrel=1e-13)[0]
        for a, b in zip(edges[:-1], edges[1:], strict=True)
    )


@pytest.mark.parametrize("seed", range(3))
def test_refine_u_at_s_meets_the_quadrature_arc_length(seed):
    # the compiled Newton steps from guesses 1e-3 of the domain off: the arc length to the
    # result (scipy's adaptive quadrature, not the curve's table) is the target within 1e-10 m
    c = _curve(n=9, seed=seed)
    rng = np.random.default_rng(seed)
    s = np.sort(rng.uniform(0.0, c.length, 40))
    u_true = c.u_at_s(s)
    guess = np.clip(u_true + rng.uniform(-2e-3, 2e-3, s.shape), 0.0, 2.0)
    u = c.refine_u_at_s(s, guess)
    lo = c.domain[0]
    got = np.array([_quad_length(c, lo, x) for x in u])
    np.testing.assert_allclose(got, s, rtol=0.0, atol=1e-10)
    assert np.all((u >= 0.0) & (u <= 2.0))


def test_refine_u_at_s_compiled_matches_the_vectorised_steps():
    # the same steps as ParametricCurve's numpy version (within 1e-12 of the domain: the
    # quadrature's weighted sum may round differently in the last bit on another BLAS),
    # at the ends and at the interior knots too
    c = _curve(n=12, k=3, seed=5)
    rng = np.random.default_rng(5)
    s = np.concatenate([[0.0, c.length], c.s_at_u(c.breakpoints()), rng.uniform(0, c.length, 60)])
    guess = np.clip(c.u_at_s(s, exact=False) + rng.normal(0, 1e-4, s.shape), 0.0, 2.0)
    ref = ParametricCurve.refine_u_at_s(c, s, guess)
    np.testing.assert_allclose(c.refine_u_at_s(s, guess), ref, rtol=0.0, atol=1e-12)
    assert not np.shares_memory(c.refine_u_at_s(s, guess), guess)
