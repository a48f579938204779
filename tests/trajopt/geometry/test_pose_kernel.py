"""Tests of trajopt.geometry: BSplineCurve.pose_at_s (compiled: trajopt.geometry.arc_pose).

Bit for bit against the calls it replaces one after another (numpy.interp of the table,
refine_u_at_s, the curve and its heading), and against independent references: scipy's
BSpline at the returned parameters, the arc length of a dense polyline of scipy's points, the
heading of dense chords.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import BSpline

from trajopt.errors import InvalidInputError
from trajopt.geometry import BSplineCurve, clamped_uniform_knots


def _spline(seed: int, k: int = 3, n: int = 9) -> BSplineCurve:
    rng = np.random.default_rng(seed)
    x = np.cumsum(rng.uniform(0.3, 1.0, n))
    y = rng.uniform(-1.0, 1.0, n)
    return BSplineCurve(clamped_uniform_knots(n, k, (0.0, 3.0)), np.column_stack([x, y]), k)


def _table(curve: BSplineCurve, m: int = 200) -> tuple[np.ndarray, np.ndarray]:
    u = np.linspace(*curve.domain, m)
    return np.asarray(curve.s_at_u(u)), u


def _queries(curve: BSplineCurve, seed: int) -> np.ndarray:
    grid_s, _ = _table(curve)
    rng = np.random.default_rng(seed)
    inner = rng.uniform(0.0, curve.length, 300)
    # the table's own nodes, its ends, beyond them, and NaN
    return np.concatenate([inner, grid_s[::17], [0.0, curve.length, -0.5, curve.length + 1.0]])


@pytest.mark.parametrize(("seed", "k"), [(0, 3), (1, 3), (2, 2), (3, 5)])
def test_pose_at_s_is_the_calls_it_replaces_bit_for_bit(seed, k):
    curve = _spline(seed, k)
    grid_s, grid_u = _table(curve)
    s = _queries(curve, seed)
    xy, theta, u = curve.pose_at_s(s, grid_s, grid_u)
    u_ref = curve.refine_u_at_s(s, np.interp(s, grid_s, grid_u))
    assert np.array_equal(u, u_ref)
    assert np.array_equal(xy, curve(u_ref))
    assert np.array_equal(theta, curve.heading(u_ref))


@pytest.mark.parametrize("seed", [0, 1, 4])
def test_pose_at_s_against_scipy_and_dense_sampling(seed):
    curve = _spline(seed)
    grid_s, grid_u = _table(curve, 50)  # a coarse table: Newton does the work
    ref = BSpline(curve.t, curve.c, curve.k)
    s = np.random.default_rng(seed).uniform(0.0, curve.length, 200)
    xy, theta, u = curve.pose_at_s(s, grid_s, grid_u)
    assert np.allclose(xy, ref(u), rtol=0.0, atol=1e-12)
    # the arc length to u of a dense polyline of scipy's points (chord error ~1e-9 m)
    fine = np.linspace(*curve.domain, 400_001)
    pts = ref(fine)
    arc = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(pts, axis=0).T))])
    assert np.allclose(np.interp(u, fine, arc), s, rtol=0.0, atol=1e-7)
    # the heading: the direction of a short chord about each point
    d = ref(np.minimum(u + 1e-6, curve.domain[1])) - ref(np.maximum(u - 1e-6, curve.domain[0]))
    chord = np.arctan2(d[:, 1], d[:, 0])
    assert np.max(np.abs(np.angle(np.exp(1j * (theta - chord))))) < 1e-5


def test_heading_where_the_tangent_vanishes_is_the_limit_direction():
    # the first two control points coincide: C'(u0) = 0, the curve leaves towards c[2]
    c = np.array([[0.0, 0.0], [0.0, 0.0], [1.0, 1.0], [2.0, 1.0], [3.0, 0.0]])
    curve = BSplineCurve(clamped_uniform_knots(5, 3), c, 3)
    grid_s, grid_u = _table(curve)
    s = np.array([0.0, 1e-3, 0.5 * curve.length])
    _, theta, u = curve.pose_at_s(s, grid_s, grid_u)
    assert np.array_equal(theta, curve.heading(u))
    assert theta[0] == pytest.approx(np.pi / 4, abs=1e-12)  # towards c[2] - c[0]


def test_nan_arc_lengths_give_nan_and_bad_tables_are_refused():
    curve = _spline(0)
    grid_s, grid_u = _table(curve)
    xy, theta, u = curve.pose_at_s(np.array([np.nan, 1.0]), grid_s, grid_u)
    assert np.isnan(u[0]) and np.all(np.isnan(xy[0])) and np.isnan(theta[0])
    assert np.all(np.isfinite(xy[1]))
    with pytest.raises(InvalidInputError, match="grid_s and grid_u"):
        curve.pose_at_s(np.array([1.0]), grid_s, grid_u[:-1])
    with pytest.raises(InvalidInputError, match="g >= 2"):
        curve.pose_at_s(np.array([1.0]), grid_s[:1], grid_u[:1])
