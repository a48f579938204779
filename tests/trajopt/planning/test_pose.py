"""Tests of trajopt.planning: pose to pose (issue 33): a differential drive's end headings are met exactly.

References: the clearance of dense samples by brute force over the occupied squares
(:func:`tests.reference.square_clearance`), the turn limits derived by hand from the robot's
fields (:func:`tests.reference.turn_limits_by_hand`) and checked on finite differences of
the sampled heading, and the footprint's collision by point sampling
(:func:`tests.reference.footprint_collides`).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import astar
import trajopt
from tests.reference import footprint_collides, square_clearance, turn_limits_by_hand
from trajopt.analysis.metrics import trajectory_metrics
from trajopt.motion import TrajectoryChain, TurnInPlace

ROBOT = trajopt.Robot(radius=0.15)


def _wrap(a: float) -> float:
    return math.remainder(float(a), 2.0 * math.pi)


def check_pose_plan(traj, grid, robot, start, goal, h0, h1) -> None:
    """Ends, headings, clearance and every piece's limits of a pose-to-pose plan."""
    ends = traj.sample(np.array([0.0, traj.duration]))
    assert (float(ends.x[0]), float(ends.y[0])) == pytest.approx(start, abs=1e-12)
    assert (float(ends.x[1]), float(ends.y[1])) == pytest.approx(goal, abs=1e-12)
    assert abs(_wrap(ends.theta[0] - h0)) <= 1e-9
    assert abs(_wrap(ends.theta[1] - h1)) <= 1e-9
    smp = traj.sample(np.linspace(0.0, traj.duration, 4000))
    assert square_clearance(grid, np.c_[smp.x, smp.y]).min() >= robot.radius - 1e-9
    pieces = traj.pieces if isinstance(traj, TrajectoryChain) else (traj,)
    w_lim, alpha_lim, _ = turn_limits_by_hand(robot)
    for p in pieces:
        if isinstance(p, TurnInPlace):
            t = np.arange(0.0, p.duration, 1e-3)
            s = p.sample(t)
            assert np.all(s.v == 0.0)
            rate = np.diff(s.theta) / np.diff(t)
            assert np.abs(rate).max() <= w_lim * (1 + 1e-6) + 1e-9
            assert np.abs(np.diff(rate) / 1e-3).max() <= alpha_lim * (1 + 1e-3) + 1e-6
        else:
            assert trajectory_metrics(p, robot)["within_limits"]
    if isinstance(traj, TrajectoryChain):  # at rest at every join, heading continuous
        for tj in traj.piece_times[1:-1]:
            a = traj.sample(np.array([tj - 1e-9, tj + 1e-9]))
            assert np.all(np.abs(a.v) <= 1e-6)
            assert abs(a.theta[1] - a.theta[0]) <= 1e-6


def room(nx: int = 80, ny: int = 60, res: float = 0.05) -> np.ndarray:
    occ = np.zeros((ny, nx), bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    return occ


def test_a_start_facing_a_wall_turns_in_place_first():
    occ = room()
    grid = astar.OccupancyGrid(occ, 0.05)
    start, goal = (3.6, 1.5), (0.6, 1.5)  # 0.3 m from the right wall, the goal to the left
    h0, h1 = 0.0, math.pi  # facing the wall; arriving facing on
    traj = trajopt.Planner(grid, ROBOT).plan(start, goal, start_heading=h0, goal_heading=h1)
    check_pose_plan(traj, grid, ROBOT, start, goal, h0, h1)
    assert isinstance(traj, TrajectoryChain) and isinstance(traj.pieces[0], TurnInPlace)
    assert abs(traj.pieces[0].turn_rad) == pytest.approx(math.pi, abs=0.3)


def test_facing_away_in_a_corridor_one_robot_wide():
    res = 0.05
    occ = np.ones((20, 100), bool)
    occ[8:13, 1:99] = False  # 0.25 m wide: one robot of radius 0.1 m, on the middle row only
    grid = astar.OccupancyGrid(occ, res)
    robot = trajopt.Robot(radius=0.1)
    start, goal = (1.025, 0.525), (4.025, 0.525)
    traj = trajopt.Planner(grid, robot).plan(start, goal, start_heading=math.pi, goal_heading=0.0)
    check_pose_plan(traj, grid, robot, start, goal, math.pi, 0.0)
    assert isinstance(traj.pieces[0], TurnInPlace)
    assert abs(traj.pieces[0].turn_rad) == pytest.approx(math.pi, abs=1e-3)


def test_a_goal_heading_out_of_a_dead_end_turns_at_the_goal():
    occ = room()
    occ[20:40, 50:79] = True
    occ[27:33, 50:78] = False  # a dead end 0.3 m wide entered from the left
    grid = astar.OccupancyGrid(occ, 0.05)
    robot = trajopt.Robot(radius=0.12)
    start, goal = (0.8, 1.5), (3.7, 1.5)
    traj = trajopt.Planner(grid, robot).plan(start, goal, goal_heading=math.pi)
    check_pose_plan(traj, grid, robot, start, goal, traj.sample(0.0).theta, math.pi)
    assert isinstance(traj.pieces[-1], TurnInPlace)
    assert abs(traj.pieces[-1].turn_rad) == pytest.approx(math.pi, abs=0.2)


def test_small_heading_changes_are_curves_not_turns():
    grid = astar.OccupancyGrid(room(), 0.05)
    start, goal = (0.6, 1.5), (3.4, 1.5)
    traj = trajopt.Planner(grid, ROBOT).plan(start, goal, start_heading=0.2, goal_heading=-0.2)
    check_pose_plan(traj, grid, ROBOT, start, goal, 0.2, -0.2)
    assert not isinstance(traj, TrajectoryChain)  # the pinned curve is faster than turning
    pose = traj.stats["pose"]
    assert (
        pose["chosen"] == "pinned" and pose["durations_s"]["pinned"] < pose["durations_s"]["turn"]
    )


def corridor(width_m: float, res: float = 0.02):
    occ = np.ones((60, 300), bool)
    rows = int(round(width_m / res))
    y0 = 30 - rows // 2
    occ[y0 : y0 + rows, 2:298] = False
    return astar.OccupancyGrid(occ, res), (1.5, 0.6), (4.5, 0.6)


def test_a_rectangle_that_cannot_turn_in_a_narrow_corridor_is_refused():
    robot = trajopt.Robot.rectangle(0.5, 0.2)  # circumscribed radius 0.27 m
    grid, start, goal = corridor(0.3)
    planner = trajopt.Planner(grid, robot)
    with pytest.raises(trajopt.SmoothingError, match="start heading 3.14159 rad") as err:
        planner.plan(start, goal, start_heading=math.pi, goal_heading=0.0)
    assert "cannot turn in place" in str(err.value)


def test_the_same_rectangle_turns_in_a_wide_corridor():
    robot = trajopt.Robot.rectangle(0.5, 0.2)
    grid, start, goal = corridor(0.7)
    traj = trajopt.Planner(grid, robot).plan(start, goal, start_heading=math.pi, goal_heading=0.0)
    ends = traj.sample(np.array([0.0, traj.duration]))
    assert abs(_wrap(ends.theta[0] - math.pi)) <= 1e-9 and abs(_wrap(ends.theta[1])) <= 1e-9
    assert isinstance(traj.pieces[0], TurnInPlace)
    smp = traj.sample(np.linspace(0.0, traj.duration, 3000))
    assert not footprint_collides(grid, robot.footprint, smp.x, smp.y, smp.theta)


def test_a_replan_to_the_same_goal_keeps_its_heading():
    grid = astar.OccupancyGrid(room(), 0.05)
    start, goal = (0.6, 0.6), (3.4, 2.2)
    planner = trajopt.Planner(grid, ROBOT)
    traj = planner.plan(start, goal, start_heading=math.pi, goal_heading=-math.pi / 2)
    new = planner.replan(traj, 0.5 * traj.duration, latency=0.0, reuse=False)
    end = new.sample(np.array([new.duration]))
    assert abs(_wrap(end.theta[0] + math.pi / 2)) <= 1e-9
    assert new.steps.goal_heading == -math.pi / 2


def test_bad_headings_are_refused():
    grid = astar.OccupancyGrid(room(), 0.05)
    for bad in (math.nan, math.inf, "east"):
        with pytest.raises(trajopt.InvalidInputError, match="goal_heading"):
            trajopt.plan(grid, (0.6, 0.6), (3.4, 2.2), ROBOT, goal_heading=bad)


@pytest.mark.parametrize("seed", range(12))
def test_random_headings_on_random_grids(seed):
    rng = np.random.default_rng(seed)
    occ = room(60, 50)
    for _ in range(6):  # random blocks
        x, y = rng.integers(5, 50), rng.integers(5, 40)
        occ[y : y + rng.integers(2, 8), x : x + rng.integers(2, 8)] = True
    grid = astar.OccupancyGrid(occ, 0.05)
    free = np.argwhere(~occ)
    pts = []
    while len(pts) < 2:
        iy, ix = free[rng.integers(len(free))]
        p = grid.cell_to_world(np.array([ix, iy]))
        if square_clearance(grid, np.asarray(p, float).reshape(1, 2))[0] >= 2 * ROBOT.radius:
            if not pts or math.dist(pts[0], p) > 0.5:
                pts.append((float(p[0]), float(p[1])))
    h0, h1 = rng.uniform(-math.pi, math.pi, 2)
    try:
        traj = trajopt.Planner(grid, ROBOT).plan(pts[0], pts[1], start_heading=h0, goal_heading=h1)
    except trajopt.NoPathError:
        pytest.skip("the random blocks cut the two points apart")
    check_pose_plan(traj, grid, ROBOT, pts[0], pts[1], h0, h1)
