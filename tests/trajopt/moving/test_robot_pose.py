"""Tests of trajopt.moving: the certificate's robot model on a B-spline (CurveMotion.at, two compiled calls).

Its arc lengths, positions, headings and speeds are Trajectory.motion's and Trajectory.pose's
bit for bit (the calls it replaces); a trajectory off that road (no B-spline) is evaluated by
``pose`` itself.
"""

from __future__ import annotations

import numpy as np
import pytest

from trajopt.geometry import BSplineCurve, PolylineCurve, clamped_uniform_knots
from trajopt.moving._robot_windows import CurveMotion
from trajopt.robot import Robot
from trajopt.timing import time_parameterize

ROBOT = Robot(v_max=0.8, a_max=0.8, j_max=3.0)


def _traj(seed: int):
    rng = np.random.default_rng(seed)
    x = np.linspace(0.0, 4.0, 8)
    y = np.concatenate([[0.0, 0.0], rng.uniform(-0.6, 0.6, 4), [0.0, 0.0]])
    return time_parameterize(
        BSplineCurve(clamped_uniform_knots(8, 3), np.column_stack([x, y]), 3), ROBOT
    )


def _intervals(duration: float, offset: float, seed: int):
    rng = np.random.default_rng(seed)
    t0 = np.concatenate([rng.uniform(-0.2, duration + 0.2, 60), [0.0, duration]]) + offset
    t1 = t0 + rng.uniform(0.0, 0.4, t0.shape[0])
    return t0, 0.5 * (t0 + t1), t1


@pytest.mark.parametrize(("seed", "offset"), [(0, 0.0), (1, 2.5)])
def test_curve_motion_on_a_spline_is_motion_and_pose_bit_for_bit(seed, offset):
    traj = _traj(seed)
    model = CurveMotion(traj, offset)
    assert model.spline is not None  # the compiled road
    t0, tm, t1 = _intervals(traj.duration, offset, seed)
    p, rho, vel = model.at(t0, tm, t1)
    s0, s1 = (traj.motion(t - offset)[0] for t in (t0, t1))
    x, y, th, sm, v = traj.pose(tm - offset)
    assert np.array_equal(p, np.stack([x, y], axis=-1))
    assert np.array_equal(model.theta, th)
    assert np.array_equal(vel, np.stack([v * np.cos(th), v * np.sin(th)], axis=-1))
    assert np.array_equal(rho, np.maximum(sm - s0, s1 - sm).clip(0.0) * (1.0 + 1e-9) + 1e-12)


def test_curve_motion_off_the_spline_road_uses_pose():
    traj = time_parameterize(PolylineCurve(np.array([[0.0, 0.0], [2.0, 0.0], [3.0, 1.0]])), ROBOT)
    model = CurveMotion(traj, 0.0)
    assert model.spline is None
    t0, tm, t1 = _intervals(traj.duration, 0.0, 3)
    p, _, _ = model.at(t0, tm, t1)
    x, y, th, _, _ = traj.pose(tm)
    assert np.array_equal(p, np.stack([x, y], axis=-1)) and np.array_equal(model.theta, th)
