"""Tests of trajopt.geometry: ParametricCurve geometry against closed forms (circle, line, polyline)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from trajopt.geometry._curve import ParametricCurve, PolylineCurve


class Arc(ParametricCurve):
    """Exact circle arc of radius r: (r cos u, r sin u), u in [0, span]."""

    def __init__(self, r: float, span: float) -> None:
        self.r, self.span = r, span

    @property
    def domain(self):
        return (0.0, self.span)

    def __call__(self, u, nu=0):
        u = np.asarray(u, dtype=float)
        r = self.r
        if nu == 0:
            return np.stack([r * np.cos(u), r * np.sin(u)], -1)
        if nu == 1:
            return np.stack([-r * np.sin(u), r * np.cos(u)], -1)
        if nu == 2:
            return np.stack([-r * np.cos(u), -r * np.sin(u)], -1)
        raise NotImplementedError


class Parabola(ParametricCurve):
    """(u, u^2) on [0, 1]: arc length has a closed form."""

    @property
    def domain(self):
        return (0.0, 1.0)

    def __call__(self, u, nu=0):
        u = np.asarray(u, dtype=float)
        if nu == 0:
            return np.stack([u, u * u], -1)
        if nu == 1:
            return np.stack([np.ones_like(u), 2 * u], -1)
        return np.stack([np.zeros_like(u), np.full_like(u, 2.0)], -1)


def _parabola_length(u):
    # integral of sqrt(1 + 4u^2) du from 0 to u (hand derivation)
    w = 2 * u
    return 0.25 * (w * np.sqrt(1 + w * w) + np.arcsinh(w))


def test_arc_length_curvature_heading():
    arc = Arc(1.7, 3.0)
    assert arc.length == pytest.approx(1.7 * 3.0, rel=1e-12)
    u = np.linspace(0, 3, 11)
    np.testing.assert_allclose(arc.curvature(u), 1 / 1.7, rtol=1e-12)
    samples = arc.sample(50)
    np.testing.assert_allclose(samples.heading, samples.u + np.pi / 2, atol=1e-9)
    np.testing.assert_allclose(samples.s, samples.u * 1.7, atol=1e-9)
    assert arc.mean_speed() == pytest.approx(1.7, rel=1e-12)  # |c'(u)| = r everywhere
    assert Parabola().mean_speed() == pytest.approx(_parabola_length(1.0), rel=1e-9)


@settings(max_examples=50, deadline=None)
@given(st.floats(0.0, 1.0))
def test_parabola_arc_length_and_inverse(u):
    p = Parabola()
    assert float(p.s_at_u(u)) == pytest.approx(_parabola_length(u), abs=1e-10)
    assert float(p.u_at_s(_parabola_length(u))) == pytest.approx(u, abs=1e-9)


def test_u_at_s_table_model_is_accurate():
    # exact=False (Hermite model of the arc-length table only) against the closed form:
    # 16 table intervals on a 1.48 m curve give ~3e-7 m (the model's error is O(spacing^4))
    p = Parabola()
    s = np.linspace(0.0, p.length, 4001)
    u = p.u_at_s(s, exact=False)
    assert np.max(np.abs(_parabola_length(u) - s)) < 1e-6
    assert np.all(np.diff(u) >= 0)


def test_u_at_s_clips_and_is_monotone():
    p = Parabola()
    s = np.linspace(-1, p.length + 1, 101)
    u = p.u_at_s(s)
    assert u[0] == 0.0 and u[-1] == 1.0
    assert np.all(np.diff(u) >= 0)


def test_sample_spacing():
    p = Parabola()
    smp = p.sample(ds=0.01)
    assert np.diff(smp.s).max() <= 0.01 + 1e-12
    seg = np.hypot(*np.diff(smp.xy, axis=0).T)
    np.testing.assert_allclose(seg, np.diff(smp.s), rtol=1e-3)
    with pytest.raises(ValueError, match="ds must be > 0"):
        p.sample(ds=0.0)


def test_polyline_curve():
    pts = np.array([[0, 0], [1, 0], [1, 0], [1, 2]], float)
    c = PolylineCurve(pts)
    assert c.length == pytest.approx(3.0)
    np.testing.assert_allclose(c(np.array([0.5, 2.0])), [[0.5, 0], [1, 1]])
    np.testing.assert_allclose(c.heading(np.array([0.5, 2.0])), [0, np.pi / 2])
    np.testing.assert_allclose(c.curvature(np.array([0.5, 2.0])), 0.0)
