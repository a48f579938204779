"""Tests of trajopt.moving: the certificate's filter of far intervals: the boxes of a path over arc ranges.

Every point of the path over an arc-length range, sampled densely (the path's own
``u_at_s``), must lie in the box :class:`PathBoxes` gives for that range; and a certificate
over movers most of which are far from the robot (the filter's case) must agree with the
dense samples and the brute force of the reference.
"""

from __future__ import annotations

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.trajopt.moving.reference import brute_min, dense_min
from trajopt.geometry import BSplineCurve, PolylineCurve, clamped_uniform_knots
from trajopt.moving import MovingObstacle, certify_movers
from trajopt.moving._path_bounds import PathBoxes, RangeMax
from trajopt.robot import Robot
from trajopt.timing import time_parameterize

ROBOT = Robot(v_max=0.8, a_max=0.8, j_max=3.0)


def _wiggle(ys, length):
    n = len(ys) + 2
    x = np.linspace(0.0, length, n)
    y = np.concatenate([[0.0], ys, [0.0]])
    return BSplineCurve(clamped_uniform_knots(n, 3), np.column_stack([x, y]), 3)


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.lists(st.floats(-2.0, 2.0), min_size=3, max_size=8),
    st.floats(1.0, 30.0),
    st.booleans(),
    st.lists(st.tuples(st.floats(0.0, 1.0), st.floats(0.0, 0.2)), min_size=1, max_size=6),
)
def test_the_box_of_an_arc_range_holds_every_point_of_it(ys, length, polyline, ranges):
    if polyline:
        pts = np.column_stack([np.linspace(0.0, length, len(ys) + 2), [0.0, *ys, 0.0]])
        path = PolylineCurve(pts)
    else:
        path = _wiggle(ys, length)
    boxes = PathBoxes(path)
    total = float(path.length)
    for f0, df in ranges:
        s0 = f0 * total
        s1 = min(total, s0 + df * total)
        s = np.linspace(s0, s1, 400)
        p = np.asarray(path(path.u_at_s(s)))
        x0, x1, y0, y1 = (float(v[0]) for v in boxes.box(np.array([s0]), np.array([s1])))
        assert np.all(p[:, 0] >= x0) and np.all(p[:, 0] <= x1)
        assert np.all(p[:, 1] >= y0) and np.all(p[:, 1] <= y1)


@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(0, 10_000))
def test_the_certificate_with_far_movers_agrees_with_the_brute_force(seed):
    rng = np.random.default_rng(seed)
    traj = time_parameterize(_wiggle(rng.uniform(-1.0, 1.0, 4), 6.0), ROBOT)
    movers = []
    for j in range(8):  # tracks of several pieces: seven away from the path, one anywhere
        times = np.sort(rng.uniform(0.0, 9.0, 6)) + np.arange(6) * 1e-3
        side = np.full((6, 1), rng.choice([-1.0, 1.0]) if j else 1.0)
        low, high = ([-2.0, 2.2], [8.0, 5.0]) if j else ([-1.0, -2.0], [7.0, 2.0])
        pos = rng.uniform(low, high, size=(6, 2)) * np.hstack([np.ones((6, 1)), side])
        movers.append(
            MovingObstacle.from_waypoints(
                times, pos, radius=float(rng.uniform(0.05, 0.3)), name=f"m{j}"
            )
        )
    cert = certify_movers(traj, movers, margin=0.05)
    lowest = min(dense_min(traj, movers, margin=0.05)[0], brute_min(traj, movers, margin=0.05))
    if cert.ok:
        assert lowest >= -cert.tol
        assert cert.slack <= lowest + 1e-9  # a lower bound of the true slack
    else:
        assert cert.verdict == "violated" and lowest < -0.5 * cert.tol


@settings(max_examples=40, deadline=None)
@given(st.integers(1, 300), st.integers(1, 3), st.integers(0, 2**32 - 1))
def test_range_maxima_are_the_maxima_of_the_ranges(n, cols, seed):
    rng = np.random.default_rng(seed)
    values = rng.normal(size=(n, cols)) if cols > 1 else rng.normal(size=n)
    i0 = rng.integers(0, n, 200)
    i1 = np.minimum(i0 + rng.integers(0, n, 200), n - 1)
    got = RangeMax(values)(i0, i1)
    want = np.array([values[a : b + 1].max(axis=0) for a, b in zip(i0, i1, strict=True)])
    assert np.array_equal(got, want)


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.floats(-2.0, 2.0), min_size=3, max_size=8), st.floats(1.0, 30.0))
def test_compiled_boxes_and_arc_curvature_are_the_arrays_bit_for_bit(ys, length):
    from trajopt.moving._path_bounds import arc_kappa_kernel, kappa_table

    path = _wiggle(ys, length)
    total = float(path.length)
    rng = np.random.default_rng(len(ys))
    s0 = np.concatenate([rng.uniform(-0.1, 1.1, 300) * total, [0.0, total, -1.0]])
    s1 = np.minimum(s0 + rng.uniform(0.0, 0.3, s0.shape[0]) * total, total + 0.5)
    # the boxes: the array form of PathBoxes.box
    boxes = PathBoxes(path)
    last = boxes.s.shape[0] - 1
    i0 = np.clip(np.searchsorted(boxes.s, s0, side="right") - 1, 0, last)
    i1 = np.maximum(np.clip(np.searchsorted(boxes.s, s1, side="left"), 0, last), i0)
    x0, x1, y0, y1 = boxes.ranges(i0, i1).T
    want = (-x0 - boxes.pad, x1 + boxes.pad, -y0 - boxes.pad, y1 + boxes.pad)
    for got, ref in zip(boxes.box(s0, s1), want, strict=True):
        assert np.array_equal(got, ref)
    # the curvature bound over an arc: the array form, and above |kappa| sampled on the arc
    edges, k = kappa_table(path)
    rm = RangeMax(k)
    last = edges.shape[0] - 2
    i0 = np.clip(np.searchsorted(edges, s0, side="right") - 1, 0, last)
    i1 = np.clip(np.searchsorted(edges, s1, side="left") - 1, 0, last)
    want = rm(i0, np.maximum(i0, i1))
    got = arc_kappa_kernel(edges, rm.table[:, :, None], s0, s1)
    assert np.array_equal(got, want)
    for a, b, bound in zip(s0[:40], s1[:40], got[:40], strict=True):
        s = np.linspace(max(a, 0.0), min(b, total), 50)
        kappa = np.abs(np.asarray(path.curvature(path.u_at_s(s))))
        assert np.all(kappa <= bound * (1.0 + 1e-9) + 1e-12)


def test_compiled_range_maxima_of_infinite_and_nan_values_are_numpys():
    from trajopt.moving._path_bounds import arc_kappa_kernel

    values = np.array([1.0, -np.inf, np.inf, np.nan, 0.0, -0.0, 2.0])
    rm = RangeMax(values)
    edges = np.arange(8.0)
    i0, i1 = (x.ravel() for x in np.meshgrid(np.arange(7), np.arange(7)))
    got = arc_kappa_kernel(edges, rm.table[:, :, None], i0 + 0.5, i1 + 0.5)
    assert np.array_equal(got, rm(i0, np.maximum(i0, i1)), equal_nan=True)


def test_kept_curvature_ranges_are_the_tables_and_the_dense_curvature_bound():
    from trajopt.moving._path_bounds import arc_kappa_kernel, kappa_ranges_of, kappa_table

    curve = _wiggle([0.8, -1.2, 0.5, 1.0], 6.0)
    edges, k_top, table = kappa_ranges_of(curve)
    ref_edges, k = kappa_table(curve)
    assert np.array_equal(edges, ref_edges)
    assert k_top == float(np.max(k))
    assert np.array_equal(table, RangeMax(k).table[:, :, None])
    assert kappa_ranges_of(curve)[2] is table  # kept: the next look-up builds nothing
    # the bound of an arc range is at least the curvature sampled densely in it
    s = np.linspace(0.0, curve.length, 4001)
    kap = np.abs(np.asarray(curve.curvature(curve.u_at_s(s)), dtype=float))
    rng = np.random.default_rng(5)
    for _ in range(30):
        a, b = np.sort(rng.uniform(0.0, curve.length, 2))
        got = arc_kappa_kernel(edges, table, np.array([a]), np.array([b]))[0]
        inside = (s >= a) & (s <= b)
        assert not inside.any() or got >= np.max(kap[inside]) - 1e-9
