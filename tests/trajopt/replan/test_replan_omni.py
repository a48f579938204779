"""Tests of trajopt.replan: re-planning an omnidirectional base: the body's orientation goes on across the splice.

References: the old trajectory's own samples (the splice, and the kept rest shifted in
time), the yaw limits by hand (``tests.reference.turn_limits_by_hand``) on finite
differences of 1 ms samples, central differences of the old yaw rate for the yaw
acceleration a plain trajectory's direction of travel has, and the goal heading asked.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import trajopt
from tests.reference import turn_limits_by_hand
from trajopt.errors import InvalidInputError, TimingError
from trajopt.motion import OmniTrajectory
from trajopt.motion._chain import TrajectoryChain, TurnInPlace
from trajopt.planning._options import PlanRequest
from trajopt.replan._brake import brake_turn_go

ROBOT = trajopt.Robot(drive="omni")
H0, H1 = 0.3, 2.5  # start and goal orientation of the driven plan: it turns all the way
MS = 1e-3


def _wrap(a):
    return np.remainder(np.asarray(a, dtype=float) + math.pi, 2.0 * math.pi) - math.pi


@pytest.fixture(scope="module")
def omni(scene):
    """``(planner, trajectory)``: an omni base SP -> A turning from H0 to H1 as it drives."""
    planner = trajopt.Planner(scene.grid, ROBOT)
    traj = planner.plan(scene.start, scene.goal("A"), start_heading=H0, goal_heading=H1)
    assert isinstance(traj, OmniTrajectory) and traj.stats["orientation"]["synchronized"]
    return planner, traj


@pytest.fixture(scope="module")
def standing(scene):
    """``(planner, trajectory)``: a short move whose turn outlasts it (the robot stands)."""
    planner = trajopt.Planner(scene.grid, ROBOT)
    goal = (scene.start[0] + 0.15, scene.start[1])
    traj = planner.plan(scene.start, goal, start_heading=0.0, goal_heading=3.0)
    assert traj.stats["orientation"]["hold_s"] > 0.5
    return planner, traj


def _alpha(traj, t: float) -> float:
    """The yaw acceleration of an omni piece (a chain's piece at ``t``), else by differences.

    The differences assume one constant-jerk phase over ``[t, t + 2e-4]`` s.
    """
    if isinstance(traj, TrajectoryChain):
        i, t = traj.piece_at(t)
        traj = traj.pieces[i]
    if isinstance(traj, OmniTrajectory):
        return float(traj.orientation(t)[2])
    h = 1e-4  # second-order forward difference: exact for a yaw rate quadratic in t
    w = traj.sample(np.array([t, t + h, t + 2 * h])).omega
    return float((-3.0 * w[0] + 4.0 * w[1] - w[2]) / (2.0 * h))


def _check_splice(old, ts: float, new, tol: float = 1e-9) -> None:
    """Position, orientation, yaw rate and acceleration, speed and acceleration go on."""
    a, b = old.sample(np.array([ts])), new.sample(np.array([0.0]))
    for name in ("x", "y", "theta", "omega", "v", "a"):
        assert abs(float(getattr(a, name)[0]) - float(getattr(b, name)[0])) <= tol, name
    if isinstance(old, OmniTrajectory):  # the orientation's own state, exactly
        th, w, al, _ = (float(x) for x in old.orientation(ts))
        assert float(b.theta[0]) == th and float(b.omega[0]) == w
        assert _alpha(new, 0.0) == pytest.approx(al, abs=1e-12)


def _check_motion(traj, robot=ROBOT) -> None:
    """On 1 ms samples: every join continuous, the yaw and translation limits held."""
    w_lim, al_lim, z_lim = turn_limits_by_hand(robot)
    t = np.arange(0.0, traj.duration, MS)
    smp = traj.sample(t)
    th = np.asarray(smp.theta)
    rate = np.diff(th) / MS
    assert np.abs(rate).max() <= w_lim * (1 + 1e-6) + 1e-9
    assert np.abs(np.diff(th, 2) / MS**2).max() <= al_lim * (1 + 1e-6) + 1e-6
    assert np.abs(np.diff(th, 3) / MS**3).max() <= z_lim * (1 + 1e-6) + 1e-3
    assert np.abs(smp.omega).max() <= w_lim * (1 + 1e-9)
    # no jump anywhere: neighbouring samples differ by at most a step at the limits
    step = np.hypot(np.diff(smp.x), np.diff(smp.y))
    assert step.max() <= robot.v_max * MS * (1 + 1e-6)
    assert np.abs(np.diff(smp.omega)).max() <= al_lim * MS * (1 + 1e-6)
    assert np.abs(np.diff(smp.v)).max() <= robot.a_max * MS * (1 + 1e-6)
    assert np.abs(smp.v).max() <= robot.v_max * (1 + 1e-9)
    if isinstance(traj, TrajectoryChain):  # each join, from either side
        for tj in traj.piece_times[1:-1]:
            ab = traj.sample(np.array([tj - 1e-9, tj]))
            for name in ("x", "y", "theta", "omega", "v", "a"):
                assert abs(np.diff(getattr(ab, name))[0]) <= 1e-6, (name, tj)


# ------------------------------------------------------------------ plan from the state
@pytest.mark.parametrize("ts", [0.5, 2.0, 5.0])
def test_a_plan_from_the_moving_state_continues_the_orientation(omni, ts):
    planner, traj = omni
    omega = float(traj.orientation(ts)[1])
    assert abs(omega) > 0.05  # the body turns at the splice: a rest start would jump
    new = planner.replan(traj, ts, latency=0.0, reuse=False)
    assert isinstance(new, OmniTrajectory)
    assert new.stats["replan"] == "planned: reuse=False"
    _check_splice(traj, ts, new)
    # the goal heading is kept: the old plan's, exactly (modulo 2 pi)
    assert abs(_wrap(new.theta_end - H1)) <= 1e-9
    assert abs(_wrap(new.sample(new.duration).theta - H1)) <= 1e-9
    assert new.steps.goal_heading == H1
    _check_motion(new)


def test_a_new_goal_heading_or_goal_is_planned_from_the_orientation(omni, scene):
    planner, traj = omni
    new = planner.replan(traj, 1.5, latency=0.0, goal_heading=-1.0)
    assert new.stats["replan"] == "planned: new goal heading"
    _check_splice(traj, 1.5, new)
    assert abs(_wrap(new.theta_end + 1.0)) <= 1e-9
    _check_motion(new)
    other = planner.replan(traj, 1.5, goal=scene.goal("B"), goal_heading=1.0, latency=0.0)
    assert other.stats["replan"] == "planned: new goal"
    _check_splice(traj, 1.5, other)
    assert abs(_wrap(other.theta_end - 1.0)) <= 1e-9
    end = other.sample(other.duration)
    assert math.hypot(end.x - scene.goal("B")[0], end.y - scene.goal("B")[1]) < 1e-9


# ------------------------------------------------------------------ keep
def _same_motion(old, new, ts: float) -> None:
    """``new`` is ``old`` from ``ts`` on: every sampled quantity on 1 ms samples."""
    assert new.duration == pytest.approx(old.duration - ts, abs=1e-9)
    t = np.arange(0.0, new.duration, MS)
    a, b = old.sample(t + ts), new.sample(t)
    for name in ("x", "y", "theta", "omega", "v", "a"):
        assert np.abs(getattr(a, name) - getattr(b, name)).max() < 1e-9, name
    if isinstance(new, OmniTrajectory) and isinstance(old, OmniTrajectory):
        for name in ("kappa", "course", "v_body_x", "v_body_y"):
            assert np.abs(getattr(a, name) - getattr(b, name)).max() < 1e-9, name
        alpha_old = np.asarray(old.orientation(t + ts)[2])
        assert np.abs(alpha_old - np.asarray(new.orientation(t)[2])).max() < 1e-9


@pytest.mark.parametrize("ts", [0.0, 1.7, 4.0])
def test_the_kept_rest_is_the_old_motion_shifted(omni, ts):
    planner, traj = omni
    new = planner.replan(traj, ts, latency=0.0)
    assert isinstance(new, OmniTrajectory) and new.stats["replan"] == "kept"
    _same_motion(traj, new, ts)
    assert new.steps.goal_heading == H1 and new.steps.smooth_path.certificate.ok
    assert new.stats["orientation"] == traj.stats["orientation"]
    again = planner.replan(new, 1.0, latency=0.0)  # kept again
    assert again.stats["replan"] == "kept"
    _same_motion(traj, again, ts + 1.0)
    # the same heading given (another turn of 2 pi) is no change either
    same = planner.replan(traj, ts, latency=0.0, goal_heading=H1 - 2 * math.pi)
    assert same.stats["replan"] == "kept"


def test_a_turn_outlasting_the_drive_is_kept_while_standing(standing):
    planner, traj = standing
    t_drive = traj.translation.duration
    driving = planner.replan(traj, 0.5 * t_drive, latency=0.0)
    assert isinstance(driving, OmniTrajectory) and driving.stats["replan"] == "kept"
    _same_motion(traj, driving, 0.5 * t_drive)
    ts = t_drive + 0.3  # standing at the goal, still turning
    assert abs(float(traj.orientation(ts)[1])) > 0.1
    kept = planner.replan(traj, ts, latency=0.0)
    assert isinstance(kept, TrajectoryChain) and kept.stats["replan"] == "kept"
    assert [type(p) for p in kept.pieces] == [TurnInPlace]
    _same_motion(traj, kept, ts)
    assert abs(_wrap(kept.sample(kept.duration).theta - 3.0)) <= 1e-9
    _check_motion(kept)


# ------------------------------------------------------------------ brake, stop the yaw, go
@pytest.mark.parametrize("goal_heading", [None, -2.0])
def test_braking_keeps_the_orientation_continuous(omni, scene, goal_heading):
    planner, traj = omni
    ts = 1.0
    new = planner.replan(traj, ts, goal=scene.start, goal_heading=goal_heading, latency=0.0)
    assert isinstance(new, TrajectoryChain)
    assert new.stats["replan"].startswith("braked: ")
    assert [type(p) for p in new.pieces] == [OmniTrajectory, OmniTrajectory]
    assert new.stats["brake_m"] > 0.0 and new.stats["turn_s"] > 0.0
    _check_splice(traj, ts, new)
    _check_motion(new)
    stop, go = new.pieces
    # the yaw rate is at rest where the plan from rest starts, at the stop's orientation
    assert stop.orientation(stop.duration)[1] == 0.0
    assert go.theta_start == stop.theta_end
    assert new.stats["turn_rad"] == pytest.approx(stop.theta_end - traj.orientation(ts)[0])
    end = new.sample(new.duration)
    assert math.hypot(end.x - scene.start[0], end.y - scene.start[1]) < 1e-9
    if goal_heading is not None:
        assert abs(_wrap(end.theta - goal_heading)) <= 1e-9


def test_a_braking_chain_is_replanned_with_its_orientation(omni, scene):
    planner, traj = omni
    chain = planner.replan(traj, 1.0, goal=scene.start, goal_heading=-2.0, latency=0.0)
    t_brake = 0.5 * chain.piece_times[1]
    kept = planner.replan(chain, t_brake, latency=0.0)  # same goal, heading and map
    assert kept.stats["replan"] == "kept"
    _same_motion(chain, kept, t_brake)
    # mid-brake to a new goal: planned from the braking piece's state and orientation
    other = planner.replan(chain, t_brake, goal=scene.goal("D"), latency=0.0)
    _check_splice(chain, t_brake, other)
    assert _alpha(other, 0.0) == pytest.approx(_alpha(chain, t_brake), abs=1e-12)
    _check_motion(other)
    # while the plan from rest plays, that plan is re-planned like any other
    t_go = chain.piece_times[1] + 1.0
    go = planner.replan(chain, t_go, latency=0.0)
    assert isinstance(go, OmniTrajectory) and go.stats["replan"] == "kept"
    _same_motion(chain, go, t_go)
    anew = planner.replan(chain, t_go, latency=0.0, goal=scene.goal("A"))
    _check_splice(chain, t_go, anew)
    # a new goal without a heading: the orientation ends along the path's end
    last = anew.pieces[-1] if isinstance(anew, TrajectoryChain) else anew
    course = float(last.sample(last.duration).course)
    assert abs(_wrap(last.theta_end - course)) <= 1e-9
    _check_motion(anew)


def test_standing_and_turning_stops_only_the_yaw(standing, scene):
    planner, traj = standing
    ts = traj.translation.duration + 0.3
    new = brake_turn_go(
        planner.options,
        planner.caches,
        traj,
        ts,
        scene.goal("A"),
        goal_heading=1.0,
        v_end=0.0,
        error=TimingError("a test"),
    )
    assert [type(p) for p in new.pieces] == [TurnInPlace, OmniTrajectory]
    assert new.stats["brake_m"] == 0.0 and new.stats["turn_s"] > 0.0
    _check_splice(traj, ts, new)
    _check_motion(new)
    assert abs(_wrap(new.sample(new.duration).theta - 1.0)) <= 1e-9


def test_a_failing_plan_from_the_stop_resumes_the_old_motion(standing):
    planner, traj = standing
    ts = traj.translation.duration + 0.3  # standing at the goal: no plan from there
    new = planner.replan(traj, ts, latency=0.0, reuse=False)
    assert "the old path resumed" in new.stats["replan"]
    _check_splice(traj, ts, new)
    _check_motion(new)
    assert abs(_wrap(new.sample(new.duration).theta - 3.0)) <= 1e-9


# ------------------------------------------------------------------ a plain trajectory
def test_a_plain_omni_trajectory_replanned_to_a_heading_continues_its_yaw_rate(scene):
    planner = trajopt.Planner(scene.grid, ROBOT)
    plain = planner.plan(scene.start, scene.goal("A"))
    assert type(plain) is trajopt.Trajectory  # no heading: it faces its direction of travel
    for ts in (1.0, 3.0):
        new = planner.replan(plain, ts, latency=0.0, goal_heading=1.0)
        assert isinstance(new, OmniTrajectory)
        th, w, al, _ = (float(x) for x in new.orientation(0.0))
        old = plain.sample(np.array([ts - 1e-4, ts, ts + 1e-4]))
        assert th == float(old.theta[1]) and w == pytest.approx(float(old.omega[1]), abs=1e-12)
        # reference: the central difference of the old yaw rate kappa v
        assert al == pytest.approx(float(old.omega[2] - old.omega[0]) / 2e-4, abs=1e-6)
        assert abs(_wrap(new.theta_end - 1.0)) <= 1e-9
        _check_motion(new)
    # without a goal heading the re-plan faces its direction of travel too
    assert type(planner.replan(plain, 1.0, latency=0.0, reuse=False)) is trajopt.Trajectory


def test_a_plain_omni_trajectory_brakes_and_goes_without_turning_in_place(scene):
    planner = trajopt.Planner(scene.grid, ROBOT)
    plain = planner.plan(scene.start, scene.goal("A"))
    new = planner.replan(plain, 1.0, goal=scene.start, latency=0.0)
    assert new.stats["replan"].startswith("braked: ")
    assert [type(p) for p in new.pieces] == [trajopt.Trajectory, OmniTrajectory]
    assert new.stats["turn_s"] == 0.0
    _check_splice(plain, 1.0, new)
    brake, go = new.pieces
    # the plan from rest starts facing the way the stop ended, turning while it drives
    assert go.theta_start == float(brake.sample(brake.duration).theta)
    _check_motion(go)
    t = np.arange(0.0, new.duration, MS)  # no jump at the join
    smp = new.sample(t)
    assert np.hypot(np.diff(smp.x), np.diff(smp.y)).max() <= ROBOT.v_max * MS * (1 + 1e-6)
    w_lim = turn_limits_by_hand(ROBOT)[0]
    assert np.abs(np.diff(np.asarray(smp.theta))).max() <= w_lim * MS * (1 + 1e-6)


@pytest.mark.parametrize("field", ["start_omega", "start_alpha"])
@pytest.mark.parametrize("value", [math.nan, math.inf, "fast"])
def test_bad_start_rates_are_refused(field, value):
    with pytest.raises(InvalidInputError, match=rf"{field} must be"):
        PlanRequest((0.0, 0.0), (1.0, 1.0), **{field: value})
