"""Tests of trajopt.planning: omnidirectional bases (issue 33): the orientation turns while the base drives.

References: the footprint's collision by point sampling
(:func:`tests.reference.footprint_collides`), the turn limits by hand
(:func:`tests.reference.turn_limits_by_hand`) on finite differences of the sampled
orientation, and the body-frame velocity as the world velocity rotated by hand.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import trajopt
from tests.cases import door_grid
from tests.reference import footprint_collides, square_clearance, turn_limits_by_hand
from trajopt.motion import OmniTrajectory

START, GOAL = (0.4, 1.1), (2.6, 1.1)  # either side of door_grid's door (x = 1.5 m)


def _wrap(a):
    return np.remainder(np.asarray(a, dtype=float) + math.pi, 2.0 * math.pi) - math.pi


def test_an_omni_rectangle_crabs_sideways_through_a_door():
    robot = trajopt.Robot.rectangle(0.45, 0.2, drive="omni")  # 0.45 m long, across the door
    grid = door_grid()
    side = math.pi / 2  # the long axis across the direction of travel
    traj = trajopt.Planner(grid, robot).plan(START, GOAL, start_heading=side, goal_heading=side)
    assert isinstance(traj, OmniTrajectory)
    smp = traj.sample(np.linspace(0.0, traj.duration, 3000))
    assert np.abs(_wrap(smp.theta - side)).max() <= 1e-9  # the body never turns
    assert not footprint_collides(grid, robot.footprint, smp.x, smp.y, smp.theta)
    assert square_clearance(grid, np.c_[smp.x, smp.y]).min() >= robot.radius - 1e-9
    # it crabs: the body-frame velocity is the world velocity rotated by -theta (by hand)
    c, s = np.cos(smp.theta), np.sin(smp.theta)
    np.testing.assert_allclose(smp.v_body_x, c * smp.vx + s * smp.vy, atol=1e-12)
    np.testing.assert_allclose(smp.v_body_y, -s * smp.vx + c * smp.vy, atol=1e-12)
    fast = smp.v > 0.5 * smp.v.max()
    assert np.all(np.abs(smp.v_body_y[fast]) > 0.9 * smp.v[fast])  # mostly sideways


def test_the_orientation_turns_while_driving_within_its_limits():
    robot = trajopt.Robot(drive="omni")
    grid = door_grid()
    planner = trajopt.Planner(grid, robot)
    free = planner.plan(START, GOAL)
    traj = planner.plan(START, GOAL, start_heading=math.pi, goal_heading=-math.pi / 2)
    assert traj.duration == free.duration  # the turn fits in the travel time
    ends = traj.sample(np.array([0.0, traj.duration]))
    assert abs(_wrap(ends.theta[0] - math.pi)) <= 1e-9
    assert abs(_wrap(ends.theta[1] + math.pi / 2)) <= 1e-9
    t = np.arange(0.0, traj.duration, 1e-3)
    smp = traj.sample(t)
    np.testing.assert_allclose(smp.x, free.sample(t).x, atol=1e-12)
    rate = np.diff(smp.theta) / 1e-3
    w, alpha, _ = turn_limits_by_hand(robot)
    assert np.abs(rate).max() <= w * (1 + 1e-6)
    assert np.abs(np.diff(rate) / 1e-3).max() <= alpha * (1 + 1e-3) + 1e-6


def test_without_headings_an_omni_plan_is_its_translation():
    robot = trajopt.Robot(drive="omni")
    traj = trajopt.Planner(door_grid(), robot).plan(START, GOAL)
    assert isinstance(traj, trajopt.Trajectory)


@pytest.mark.parametrize("bad", [math.nan, "up"])
def test_bad_omni_headings_are_refused(bad):
    robot = trajopt.Robot(drive="omni")
    with pytest.raises(trajopt.InvalidInputError, match="start_heading"):
        trajopt.plan(door_grid(), START, GOAL, robot, start_heading=bad)
