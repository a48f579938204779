"""Tests of trajopt.replan: brake, turn in place, go: the re-plan of a moving robot that cannot go on smoothly.

References: the hand formula of a jerk-limited stop from cruise (time ``v/a + a/j``,
distance ``v T / 2`` by the profile's point symmetry), the old trajectory's own speed at the
same arc length (the stop is its lowest continuation), finite differences and a trapezoid
integral of 1 ms samples (limits, continuity, the angle turned), and the independent KD-tree
clearance of :mod:`trajopt.metrics`.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import trapezoid

import trajopt
import trajopt.replan._replan as replan_module
from trajopt.analysis.metrics import point_clearance, trajectory_metrics
from trajopt.errors import InvalidInputError, SmoothingError, TimingError
from trajopt.geometry._bspline import BSplineCurve, clamped_uniform_knots
from trajopt.motion._chain import TrajectoryChain, TurnInPlace
from trajopt.motion._trajectory import Trajectory
from trajopt.replan._brake import brake_on_path
from trajopt.timing._stop_and_turn import turn_in_place, turn_limits

ROBOT = trajopt.Robot()


def _jump(a, b) -> float:
    return max(
        math.hypot(a.x - b.x, a.y - b.y),
        abs(math.remainder(a.theta - b.theta, math.tau)),
        abs(a.kappa - b.kappa),
        abs(a.v - b.v),
        abs(a.a - b.a),
    )


def _check_motion(traj, robot=ROBOT, dt=1e-3):
    """Limits and continuity of ``traj`` on ``dt`` samples, by finite differences."""
    smp = traj.sample(np.arange(0.0, traj.duration, dt))
    assert trajectory_metrics(traj, robot)["within_limits"]
    assert np.all(smp.v >= -1e-12) and np.abs(smp.a).max() <= robot.a_max * (1 + 1e-9)
    step = np.hypot(np.diff(smp.x), np.diff(smp.y))
    assert step.max() <= robot.v_max * dt * (1 + 1e-6) + 1e-12  # no jump in position
    w_lim = max(robot.omega_max, turn_limits(robot)[0])
    assert np.abs(np.diff(smp.theta)).max() <= w_lim * dt * (1 + 1e-6) + 1e-12  # nor heading
    assert np.abs(np.diff(smp.v)).max() <= robot.a_max * dt * (1 + 1e-6)
    assert np.all(np.diff(smp.s) >= -1e-12)
    return smp


def test_stop_from_cruise_matches_the_hand_formula():
    line = BSplineCurve(
        clamped_uniform_knots(6, 3), np.column_stack([np.linspace(0, 3, 6), np.zeros(6)]), 3
    )
    traj = trajopt.time_parameterize(line, ROBOT)
    ts = 0.5 * traj.duration
    s0, v0, a0, _ = (float(x) for x in traj.motion(ts))
    assert abs(a0) < 1e-12 and v0 > 0.49  # cruising
    brake = brake_on_path(traj, ts)
    total = v0 / ROBOT.a_max + ROBOT.a_max / ROBOT.j_max
    assert brake.duration == pytest.approx(total, rel=1e-12)
    assert brake.length == pytest.approx(0.5 * v0 * total, rel=1e-9)
    end = brake.sample(np.array([0.0, brake.duration]))
    assert end.x[0] == pytest.approx(s0, abs=1e-12) and end.v[-1] == 0.0
    assert end.x[1] == pytest.approx(s0 + 0.5 * v0 * total, rel=1e-9)
    assert brake_on_path(traj, 0.0) is None  # at rest: nothing to brake


@pytest.mark.parametrize("frac", np.linspace(0.05, 0.9, 12))
def test_the_stop_is_the_lowest_continuation(driven, frac):
    _, traj = driven
    ts = frac * traj.duration
    brake = brake_on_path(traj, ts)
    smp = brake.sample(np.linspace(0.0, brake.duration, 400))
    old = traj.sample(np.linspace(ts, traj.duration, 20000))
    s0 = float(traj.motion(ts)[0])
    v_old = np.interp(s0 + smp.s, old.s, old.v)
    assert np.all(smp.v <= v_old + 1e-6)
    # the stop follows the old path exactly
    ref = traj.path(traj._u_at_s(s0 + smp.s))
    assert np.abs(np.column_stack([smp.x, smp.y]) - ref).max() < 1e-9
    _check_motion(brake)


def test_turn_in_place():
    turn = turn_in_place((1.0, 2.0), 3.0, -3.0, ROBOT)  # shortest way: +0.283 rad across pi
    want = math.remainder(-6.0, math.tau)
    assert turn.turn_rad == pytest.approx(want, abs=1e-12)
    t = np.linspace(0.0, turn.duration, 20001)
    smp = turn.sample(t)
    assert np.all(smp.x == 1.0) and np.all(smp.y == 2.0) and np.all(smp.v == 0.0)
    assert smp.theta[-1] - smp.theta[0] == pytest.approx(want, abs=1e-12)
    assert trapezoid(smp.omega, t) == pytest.approx(want, rel=1e-6)
    w, al, _ = turn_limits(ROBOT)
    assert np.abs(smp.omega).max() <= w * (1 + 1e-9)
    assert np.abs(np.diff(smp.omega) / np.diff(t)).max() <= al * (1 + 1e-6)
    assert smp.omega[0] == 0.0 and smp.omega[-1] == 0.0
    assert turn_in_place((0, 0), 1.0, 1.0 + math.tau, ROBOT).duration == 0.0


def test_replan_to_a_goal_behind_brakes_turns_and_goes(driven, scene):
    planner, traj = driven
    new = planner.replan(traj, 1.0, goal=scene.start, latency=0.0)
    assert isinstance(new, TrajectoryChain)
    assert new.stats["replan"].startswith("braked: ")
    assert [type(p) for p in new.pieces] == [Trajectory, TurnInPlace, Trajectory]
    assert _jump(traj.state_at(1.0), new.state_at(0.0)) < 1e-9
    assert abs(new.stats["turn_rad"]) > 1.0 and new.stats["brake_m"] > 0.0
    smp = _check_motion(new)
    end = new.state_at(new.duration)
    assert math.hypot(end.x - scene.start[0], end.y - scene.start[1]) < 1e-9 and end.v == 0.0
    assert new.length == pytest.approx(sum(float(getattr(p, "length", 0.0)) for p in new.pieces))
    clr = point_clearance(np.column_stack([smp.x, smp.y]), scene.grid, border_occupied=True)
    assert clr.min() >= ROBOT.radius - 1e-6
    t_turn = new.piece_times[1:3]  # the turn: at rest, heading changing
    mid = new.sample(np.linspace(*t_turn, 50))
    assert np.all(mid.v == 0.0) and np.ptp(mid.x) == 0.0
    assert new.to_dict(0.1)["pieces"][1]["type"] == "TurnInPlace"


def test_replan_from_a_chain(driven, scene):
    planner, traj = driven
    chain = planner.replan(traj, 1.0, goal=scene.start, latency=0.0)
    t_brake = 0.5 * chain.piece_times[1]
    kept = planner.replan(chain, t_brake, latency=0.0)  # same goal and map: the rest
    assert kept.stats["replan"] == "kept"
    t = np.linspace(0.0, kept.duration, 300)
    a, b = kept.sample(t), chain.sample(t + t_brake)
    for name in ("x", "y", "theta", "v", "a", "omega"):
        assert np.abs(getattr(a, name) - getattr(b, name)).max() < 1e-9, name
    # mid-turn to a new goal: the turn is finished first (the yaw rate goes on)
    t_turn = float(np.mean(chain.piece_times[1:3]))
    other = planner.replan(chain, t_turn, goal=scene.goal("D"), latency=0.0)
    assert other.sample(0.0).omega == pytest.approx(chain.sample(t_turn).omega, abs=1e-12)
    assert other.stats["replan"].startswith("braked: ")
    _check_motion(other)
    assert other.steps.goal == tuple(scene.goal("D"))
    # while the plan from rest plays, that plan is re-planned like any other
    t_go = chain.piece_times[2] + 1.0
    go = planner.replan(chain, t_go, latency=0.0)
    assert isinstance(go, Trajectory) and go.stats["replan"] == "kept"
    assert _jump(chain.state_at(t_go), go.state_at(0.0)) < 1e-9


def test_a_stop_in_the_goal_cell_drives_the_old_path_on(driven, scene):
    planner, traj = driven
    # a smoother that cannot fit (no time) makes every re-plan brake: the stop falls short
    # of the goal, or is the goal, and the old path is driven on to it
    failing = trajopt.Planner(scene.grid, ROBOT, smoother=trajopt.Smoother(time_budget_s=1e-9))
    for who, dt in ((failing, 0.1), (failing, 0.3), (planner, 0.1), (planner, 0.3)):
        ts = traj.duration - dt
        new = who.replan(traj, ts, latency=0.0, reuse=False)
        if who is failing:
            assert "braked" in new.stats["replan"]
        assert _jump(traj.state_at(ts), new.state_at(0.0)) < 1e-9
        end, goal = new.state_at(new.duration), traj.state_at(traj.duration)
        assert math.hypot(end.x - goal.x, end.y - goal.y) < 1e-9 and end.v == 0.0
        _check_motion(new)


def test_without_braking_the_error_is_raised(scene):
    planner = trajopt.Planner(scene.grid, ROBOT, smoother=trajopt.Smoother(time_budget_s=0.3))
    traj = planner.plan(scene.start, scene.goal("A"))
    with pytest.raises(SmoothingError):
        planner.replan(traj, 1.0, goal=scene.start, latency=0.0, brake_after_s=None)
    with pytest.raises(InvalidInputError, match="brake_after_s"):
        planner.replan(traj, 1.0, goal=scene.start, latency=0.0, brake_after_s=-1.0)


def test_a_robot_that_cannot_stop_before_a_new_obstacle(scene):
    planner = trajopt.Planner(scene.grid, ROBOT)
    traj = planner.plan(scene.start, scene.goal("A"))
    s0 = float(traj.motion(2.0)[0])
    ahead = traj.path(traj._u_at_s(np.array(s0 + 0.1)))  # well within the stopping distance
    cx, cy = scene.grid.world_to_cell(ahead)
    occ = np.array(scene.grid.occupied)
    occ[cy - 1 : cy + 2, cx - 1 : cx + 2] = True
    with pytest.raises(TimingError, match="cannot stop before an obstacle"):
        planner.replan(traj, 2.0, grid=scene.grid.with_occupied(occ), latency=0.0)


def test_chain_rejects_pieces_that_do_not_join(driven):
    _, traj = driven
    turn = turn_in_place((0.0, 0.0), 0.0, 1.0, ROBOT)
    with pytest.raises(InvalidInputError, match="do not join"):
        TrajectoryChain((traj, turn), ROBOT)
    with pytest.raises(InvalidInputError, match="at least one piece"):
        TrajectoryChain((), ROBOT)
    with pytest.raises(InvalidInputError, match="one time per piece"):
        TrajectoryChain((traj,), ROBOT, starts=(0.0, 1.0))
    with pytest.raises(InvalidInputError, match=r"starts\[0\]"):
        TrajectoryChain((traj,), ROBOT, starts=(traj.duration + 1.0,))


def test_a_box_qp_out_of_reach_is_a_typed_failure(shared_data):
    # a moving start whose heading row the boxes' variable bounds cannot reach: piqp through
    # casadi.conic rejected the clipped rows (lower above upper) with a RuntimeError
    import astar
    from trajopt.robot._state import State

    grid = astar.load_map(shared_data / "ros" / "turtlebot3_world.yaml")
    planner = trajopt.Planner(
        grid, trajopt.Robot(radius=0.2), smoother=trajopt.Smoother(time_budget_s=0.5)
    )
    s = State(x=0.527907, y=-0.326162, theta=-1.62805, kappa=-0.112344, v=0.218226, a=-0.5)
    with pytest.raises(SmoothingError, match="primal infeasible"):
        planner.plan(s, (0.675, 1.525))


def test_a_state_that_would_reverse_to_stop_is_refused():
    # v = 0.01 m/s at a = -0.5 m/s^2: ramping a back to 0 at j = 2 m/s^3 takes 0.25 s, in
    # which the speed falls by 0.5 * 0.25 - 0.5 * 2 * 0.25^2 = 0.0625 m/s > 0.01 m/s
    line = BSplineCurve(
        clamped_uniform_knots(4, 3), np.column_stack([np.linspace(0, 1, 4), np.zeros(4)]), 3
    )
    traj = Trajectory(
        path=line,
        robot=ROBOT,
        phase_t=[0.0],
        phase_s=[0.0],
        phase_v=[0.01],
        phase_a=[-0.5],
        phase_j=[0.0],
        duration=0.01,
        v_start=0.01,
        v_end=0.0,
    )
    with pytest.raises(TimingError, match="without reversing"):
        brake_on_path(traj, 0.0)


@pytest.mark.parametrize("footprint", [False, True])
def test_the_smoothing_cap_applies_only_to_robots_that_brake(scene, monkeypatch, footprint):
    robot = trajopt.Robot.rectangle(length=0.3, width=0.2) if footprint else ROBOT
    planner = trajopt.Planner(scene.grid, robot)
    traj = planner.plan(scene.start, scene.goal("A"))
    budgets = []
    real = replan_module.run_query

    def spy(options, caches, request, warm=None, budget_s=None):
        budgets.append(options.with_budget(budget_s).smoother.time_budget_s)
        return real(options, caches, request, warm, budget_s)

    monkeypatch.setattr(replan_module, "run_query", spy)
    planner.replan(traj, 1.0, goal=scene.goal("B"), latency=0.0, brake_after_s=0.05)
    assert budgets[0] == (planner.smoother.time_budget_s if footprint else 0.05)
    assert planner.smoother.time_budget_s == trajopt.Smoother().time_budget_s  # unchanged
