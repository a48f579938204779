"""Tests of trajopt.planning (trajopt.plan / Planner): end-to-end guarantees checked by independent brute force."""

from __future__ import annotations

import threading

import numpy as np
import pytest

import astar
import trajopt
from tests.cases import door_grid
from tests.reference import square_clearance
from trajopt.errors import InvalidInputError, NoPathError

ROBOT = trajopt.Robot(radius=0.12)


def check_guarantees(grid, traj, robot, start, goal):
    t = np.linspace(0.0, traj.duration, 4000)
    smp = traj.sample(t)
    pts = np.c_[smp.x, smp.y]
    assert square_clearance(grid, pts).min() >= robot.radius - 1e-9
    np.testing.assert_allclose(pts[0], start, atol=1e-9)
    np.testing.assert_allclose(pts[-1], goal, atol=1e-9)
    assert np.all(np.diff(smp.s) >= -1e-12)
    assert np.max(np.abs(np.diff(smp.theta))) < 0.05  # continuous heading at 4000 samples
    tol = 1e-3
    assert np.all(smp.v <= robot.v_max * (1 + tol))
    assert np.all(np.abs(smp.a) <= robot.a_max * (1 + tol))
    assert np.all(np.abs(smp.jerk) <= robot.j_max * (1 + tol))
    assert np.all(np.abs(smp.a_lat) <= robot.a_lat_max * (1 + tol))
    assert np.all(np.abs(smp.omega) <= robot.omega_max * (1 + tol))


def test_plan_through_door_holds_every_guarantee():
    grid = door_grid()
    start, goal = (0.4, 0.3), (2.6, 1.6)
    traj = trajopt.plan(grid, start, goal, ROBOT)
    check_guarantees(grid, traj, ROBOT, start, goal)
    steps = traj.steps
    assert steps.inflated_grid.occupied.sum() > grid.occupied.sum()
    assert set(steps.stages_s) >= {"inflate", "search", "corridor", "smooth", "timing", "total"}
    assert traj.stats["stages_s"] == steps.stages_s
    assert steps.smooth_path.certificate.ok


def test_paper_scene_targets():
    scene = trajopt.scenes.paper()
    robot = trajopt.Robot(radius=scene.robot_radius)
    planner = trajopt.Planner(scene.grid, robot)
    for name in scene.target_names:
        traj = planner.plan(scene.start, scene.goal(name))
        check_guarantees(scene.grid, traj, robot, scene.start, scene.goal(name))


def test_planner_is_deterministic_and_matches_plan():
    grid = door_grid()
    a = trajopt.Planner(grid, ROBOT).plan((0.4, 0.3), (2.6, 1.6))
    b = trajopt.plan(grid, (0.4, 0.3), (2.6, 1.6), ROBOT)
    np.testing.assert_array_equal(a.path.control_points, b.path.control_points)
    assert a.duration == b.duration


def test_planner_shared_between_threads():
    grid = door_grid()
    planner = trajopt.Planner(grid, ROBOT)
    goals = [(2.6, 1.6), (2.8, 0.3), (2.0, 1.8), (0.4, 1.6)]
    serial = [planner.plan((0.4, 0.3), g).duration for g in goals]
    out: dict[int, float] = {}

    def work(i):
        out[i] = planner.plan((0.4, 0.3), goals[i]).duration

    threads = [threading.Thread(target=work, args=(i,)) for i in range(len(goals))]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    # same answers; the QP warm start depends on the previous solve, so allow ~1 ulp noise
    np.testing.assert_allclose([out[i] for i in range(len(goals))], serial, rtol=1e-9)


def test_paper_inflation_contains_exact():
    scene = trajopt.scenes.paper()
    robot = trajopt.Robot(radius=scene.robot_radius)
    exact = trajopt.Planner(scene.grid, robot).inflated_grid
    paper = trajopt.Planner(scene.grid, robot, inflation="paper").inflated_grid
    assert np.all(paper.occupied >= exact.occupied)
    assert paper.occupied.sum() > exact.occupied.sum()


@pytest.mark.parametrize(
    ("start", "match"),
    [
        ((np.nan, 0.3), "start must be finite"),
        ((5.0, 0.3), "outside the map"),
        ((1.52, 0.3), "occupied cell"),
        ((1.40, 0.3), "from the nearest obstacle"),
        ((0.05, 0.3), "from the nearest obstacle"),
        ((0.4,), "two numbers"),
        ((0.43, 0.27), "same cell"),
    ],
)
def test_bad_endpoints(start, match):
    with pytest.raises(InvalidInputError, match=match):
        trajopt.plan(door_grid(), start, (0.4, 0.3), ROBOT)


def test_unreachable_goal():
    occ = np.zeros((40, 60), bool)
    occ[:, 30] = True
    grid = astar.OccupancyGrid(occ, 0.05)
    with pytest.raises(NoPathError, match="no path"):
        trajopt.plan(grid, (0.4, 0.3), (2.6, 1.6), ROBOT)
    assert issubclass(NoPathError, astar.NoPathError)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"inflation": "disk"}, "inflation must be one of"),
        ({"search": "fast"}, "search must be one of"),
        ({"w_cells": -1}, "w_cells must be an integer"),
        ({"smoother": "osqp"}, "smoother must be a trajopt.Smoother"),
    ],
)
def test_bad_options(kwargs, match):
    with pytest.raises(InvalidInputError, match=match):
        trajopt.Planner(door_grid(), ROBOT, **kwargs)
