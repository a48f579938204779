"""Tests of trajopt.timing._orientation: an omni base's orientation beside its drive.

References: the yaw limits by hand (``tests.reference.turn_limits_by_hand``), ruckig called
directly for the time-optimal turn (``ruckig_rest_to_rest_duration``), the independent
producer ``turn_in_place`` for the same turn at rest, finite differences of the sampled
orientation on 1 ms samples for the limits, and the shortest signed angle by hand. A
turning start (``omega_start``, ``alpha_start``): ruckig called directly and unscaled for
the time-optimal duration, forward differences at the start, and the hand formula of a yaw
stop from a constant rate.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.cases import line
from tests.reference import ruckig_rest_to_rest_duration, turn_limits_by_hand
from trajopt.errors import InvalidInputError, TimingError
from trajopt.motion import OmniTrajectory
from trajopt.robot._robot import Robot
from trajopt.timing import orient, time_parameterize, turn_in_place
from trajopt.timing._orientation import stop_orientation

OMNI = Robot(drive="omni")
PLAIN_OMNI = Robot(drive="omni", track_width=None, wheel_v_max=None, radius=0.3)
MS = 1e-3


def _wrap(x):
    return np.remainder(np.asarray(x) + math.pi, 2.0 * math.pi) - math.pi


def _translation(length: float, robot: Robot = OMNI):
    return time_parameterize(line(length, direction=0.7), robot)


def check_orientation(traj: OmniTrajectory, robot: Robot, start: float, goal: float):
    """Ends, limits on 1 ms samples (finite differences) and the translation's samples."""
    w_lim, al_lim, z_lim = turn_limits_by_hand(robot)
    t = np.append(np.arange(0.0, traj.duration, MS), traj.duration)
    smp = traj.sample(t)
    th = np.asarray(smp.theta)
    # the ends: the start heading, the goal modulo 2 pi, by the shortest signed angle
    assert th[0] == start
    assert abs(_wrap(th[-1] - goal)) <= 1e-9
    assert abs(th[-1] - start) <= math.pi + 1e-12
    assert traj.theta_end == th[-1]
    # at rest in orientation rate and acceleration at both ends
    th_ends, w_ends, al_ends, _ = traj.orientation(np.array([0.0, traj.duration]))
    assert np.all(w_ends == 0.0) and np.all(al_ends == 0.0)
    # limits from finite differences of the sampled orientation (the last step is shorter)
    th, h = th[:-1], MS
    rtol = 1e-6
    rate = np.diff(th) / h
    acc = np.diff(th, 2) / h**2
    jerk = np.diff(th, 3) / h**3
    assert np.all(np.abs(rate) <= w_lim * (1 + rtol) + 1e-9), np.abs(rate).max()
    assert np.all(np.abs(acc) <= al_lim * (1 + rtol) + 1e-6), np.abs(acc).max()
    assert np.all(np.abs(jerk) <= z_lim * (1 + rtol) + 1e-3), np.abs(jerk).max()
    assert np.all(np.abs(smp.omega) <= w_lim * (1 + 1e-9))
    # the translation is the translation's: equal samples up to its end, then its end point
    tr = traj.translation
    inside = t <= tr.duration
    ref = tr.sample(t[inside])
    for name in ("x", "y", "v", "a", "jerk", "s", "kappa"):
        np.testing.assert_array_equal(getattr(smp, name)[inside], getattr(ref, name))
    end = tr.sample(tr.duration)
    assert np.all(smp.x[~inside] == end.x) and np.all(smp.y[~inside] == end.y)
    assert np.all(smp.v[~inside] == 0.0)
    return smp


# ------------------------------------------------------------------ hand cases
@pytest.mark.parametrize(
    "start,goal,turn",
    [
        (0.3, 1.5, 1.2),
        (3.0, -3.0, 2 * math.pi - 6.0),  # across +-pi: +0.283 rad, not -6
        (-2.0, 2.5, 4.5 - 2 * math.pi),  # -1.783 rad
        (10.0, 10.0 + 7 * math.pi - 0.5, math.pi - 0.5),  # goal given 3.5 turns away
        (0.0, 3.0, 3.0),
    ],
)
def test_a_turn_that_fits_ends_with_the_drive(start, goal, turn):
    translation = _translation(3.0)  # 7.25 s
    traj = orient(translation, OMNI, start, goal)
    assert traj.duration == translation.duration
    assert traj.turn_rad == pytest.approx(turn, abs=1e-12)
    check_orientation(traj, OMNI, start, goal)
    st_ = traj.stats["orientation"]
    assert st_["synchronized"] and st_["hold_s"] == 0.0
    w, al, z = turn_limits_by_hand(OMNI)
    assert st_["turn_min_s"] == pytest.approx(
        ruckig_rest_to_rest_duration(abs(turn), w, al, z), rel=1e-9
    )
    assert st_["turn_min_s"] < translation.duration


@pytest.mark.parametrize("robot", [OMNI, PLAIN_OMNI])
@pytest.mark.parametrize("start,goal", [(0.0, 3.0), (1.0, 1.0 - math.pi), (-0.2, 2.6)])
def test_a_turn_longer_than_the_drive_takes_its_own_time(robot, start, goal):
    translation = _translation(0.1, robot)
    traj = orient(translation, robot, start, goal)
    turn = math.remainder(goal - start, 2 * math.pi)
    # two independent references: the turn in place producer and ruckig called directly
    alone = turn_in_place((0.0, 0.0), start, goal, robot).duration
    direct = ruckig_rest_to_rest_duration(abs(turn), *turn_limits_by_hand(robot))
    assert traj.duration == pytest.approx(alone, rel=1e-9)
    assert traj.duration == pytest.approx(direct, rel=1e-9)
    assert traj.duration > translation.duration
    smp = check_orientation(traj, robot, start, goal)
    assert np.any(smp.t > translation.duration)
    st_ = traj.stats["orientation"]
    assert not st_["synchronized"]
    assert st_["hold_s"] == pytest.approx(traj.duration - translation.duration, abs=1e-12)


def test_turn_that_exactly_fits_and_tiny_turns():
    translation = _translation(3.0)
    w, al, z = turn_limits_by_hand(OMNI)
    # a turn whose time-optimal duration is the drive's, and turns of 1e-10 rad and none
    for goal in (1e-10, -1e-10, 0.0, 2 * math.pi, math.pi):
        traj = orient(translation, OMNI, 0.0, goal)
        check_orientation(traj, OMNI, 0.0, goal)
        assert traj.duration == translation.duration
    assert orient(translation, OMNI, 0.0, 2 * math.pi).n_phases == 0
    assert orient(translation, OMNI, 0.0, 1e-10).theta_end == 1e-10
    # a drive as long as the shortest turn of 2 rad: that turn takes it, no hold
    t_turn = ruckig_rest_to_rest_duration(2.0, w, al, z)
    short = _translation(0.1)
    lo, hi = 0.01, 3.0
    for _ in range(60):  # the line length whose drive lasts t_turn (bisection)
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if _translation(mid).duration < t_turn else (lo, mid)
    near = _translation(hi)
    traj = orient(near, OMNI, 0.0, 2.0)
    assert traj.duration == pytest.approx(max(near.duration, t_turn), rel=1e-9)
    check_orientation(traj, OMNI, 0.0, 2.0)
    assert short.duration < t_turn


# ------------------------------------------------------------------ properties
ANGLE = st.floats(-20.0, 20.0, allow_nan=False)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(start=ANGLE, goal=ANGLE, length=st.sampled_from([0.05, 0.4, 1.5]))
def test_random_headings_hold_every_limit(start, goal, length):
    translation = _translation(length)
    traj = orient(translation, OMNI, start, goal)
    check_orientation(traj, OMNI, start, goal)
    turn = math.remainder(goal - start, 2 * math.pi)
    if abs(turn) > 1e-12:
        t_turn = ruckig_rest_to_rest_duration(abs(turn), *turn_limits_by_hand(OMNI))
        assert traj.duration == pytest.approx(max(translation.duration, t_turn), rel=1e-9)
    else:
        assert traj.duration == translation.duration


def test_body_frame_velocity_and_exports(tmp_path):
    pd = pytest.importorskip("pandas")
    traj = orient(_translation(1.5), OMNI, -1.0, 1.0)
    smp = traj.sample(np.linspace(0.0, traj.duration, 501))
    # hand: a line of direction 0.7 seen from a body turned by theta
    np.testing.assert_allclose(smp.course, 0.7, atol=1e-12)
    np.testing.assert_allclose(smp.v_body_x, smp.v * np.cos(0.7 - smp.theta), atol=1e-12)
    np.testing.assert_allclose(smp.v_body_y, smp.v * np.sin(0.7 - smp.theta), atol=1e-12)
    df = pd.read_csv(traj.to_csv(tmp_path / "o.csv", dt=0.05))
    assert df.columns[-5:].tolist() == [
        "course [rad] (map)",
        "vx [m/s] (map)",
        "vy [m/s] (map)",
        "v_body_x [m/s]",
        "v_body_y [m/s]",
    ]
    assert df["theta [rad] (map)"].iloc[0] == -1.0 and df["theta [rad] (map)"].iloc[-1] == 1.0
    assert traj.to_dict(0.5)["stats"]["orientation"]["turn_rad"] == 2.0


# ------------------------------------------------------------------ bad input
@pytest.mark.parametrize(
    "field,value", [("theta_start", math.nan), ("theta_goal", math.inf), ("theta_goal", "1")]
)
def test_non_finite_headings_are_refused(field, value):
    kwargs = {"theta_start": 0.0, "theta_goal": 1.0, field: value}
    with pytest.raises(InvalidInputError, match=rf"{field}.*{value!r}".replace("'", "'?")):
        orient(_translation(1.0), OMNI, **kwargs)


def test_bad_robot_and_translation_are_refused():
    translation = _translation(1.0)
    with pytest.raises(InvalidInputError, match="drive.*'differential'"):
        orient(translation, Robot(), 0.0, 1.0)
    with pytest.raises(InvalidInputError, match="Trajectory"):
        orient(turn_in_place((0, 0), 0.0, 1.0, OMNI), OMNI, 0.0, 1.0)
    with pytest.raises(InvalidInputError, match="robot"):
        orient(translation, None, 0.0, 1.0)
    fast = _translation(1.0, Robot(drive="omni", v_max=0.8))
    with pytest.raises(InvalidInputError, match="v_max=0.8"):
        orient(fast, OMNI, 0.0, 1.0)
    # a differential timing of the same limits holds the omni cap (it is lower): accepted
    slow = _translation(1.0, Robot())
    assert orient(slow, OMNI, 0.0, 1.0).duration == slow.duration


def test_a_turn_that_outlasts_a_moving_end_is_a_timing_error():
    moving = time_parameterize(line(0.1), OMNI, v_end=0.1)
    with pytest.raises(TimingError, match="v_end"):
        orient(moving, OMNI, 0.0, 3.0)
    assert orient(moving, OMNI, 0.0, 0.05).duration == moving.duration  # a turn that fits


# ------------------------------------------------------------------ a turning start
def _ruckig_from(d: float, w0: float, a0: float, limits) -> float:
    """Reference: ruckig called directly, unscaled, for the turn 0 -> d from (w0, a0)."""
    from ruckig import InputParameter, Result, Ruckig
    from ruckig import Trajectory as RuckigTrajectory

    w, al, z = limits
    inp = InputParameter(1)
    inp.current_position, inp.current_velocity, inp.current_acceleration = [0.0], [w0], [a0]
    inp.target_position, inp.target_velocity, inp.target_acceleration = [d], [0.0], [0.0]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [w], [al], [z]
    traj = RuckigTrajectory(1)
    assert Ruckig(1).calculate(inp, traj) == Result.Working
    return float(traj.duration)


def _feasible(w0: float, a0: float, limits) -> bool:
    w, al, z = limits
    return abs(w0) <= w and abs(a0) <= al and abs(w0 + a0 * abs(a0) / (2 * z)) <= w


def check_turning_start(traj: OmniTrajectory, robot: Robot, start, goal, w0, a0):
    """A profile from (start, w0, a0): its start by finite differences, its end, its limits."""
    w_lim, al_lim, z_lim = turn_limits_by_hand(robot)
    th0, om0, al0, _ = traj.orientation(0.0)
    assert (float(th0), float(om0), float(al0)) == (start, w0, a0)
    # the start's rate and acceleration by forward differences of the sampled angle:
    # theta(h) = start + w0 h + a0 h^2 / 2 + zeta h^3 / 6 with |zeta| <= zeta_lim
    h = 1e-4
    th = np.asarray(traj.orientation(np.array([0.0, h, 2 * h]))[0])
    assert abs((th[1] - th[0]) / h - w0) <= abs(a0) * h / 2 + z_lim * h**2 / 6 + 1e-9
    assert abs((th[2] - 2 * th[1] + th[0]) / h**2 - a0) <= z_lim * h + 1e-6
    # the end: the goal (modulo 2 pi), at rest, reached without a jump at turn_duration
    t_end = traj.turn_duration
    assert abs(_wrap(traj.theta_end - goal)) <= 1e-9
    assert abs(traj.theta_end - start) <= math.pi + 1e-12
    before = np.asarray(traj.orientation(np.array([max(0.0, t_end - 1e-7)]))[0])[0]
    assert abs(before - traj.theta_end) <= w_lim * 1e-7 + 1e-12
    _, w_end, al_end, _ = traj.orientation(traj.duration)
    assert w_end == 0.0 and al_end == 0.0
    # the limits on 1 ms samples (finite differences)
    t = np.arange(0.0, traj.duration, MS)
    th = np.asarray(traj.sample(t).theta)
    assert np.abs(np.diff(th) / MS).max() <= w_lim * (1 + 1e-6) + 1e-9
    if th.size > 2:
        assert np.abs(np.diff(th, 2) / MS**2).max() <= al_lim * (1 + 1e-6) + 1e-6
    if th.size > 3:
        assert np.abs(np.diff(th, 3) / MS**3).max() <= z_lim * (1 + 1e-6) + 1e-3


@pytest.mark.parametrize(
    "start,goal,w0,a0",
    [
        (0.0, 1.5, 0.8, 0.0),  # turning towards the goal
        (0.0, 1.5, -0.8, 0.0),  # turning away from it: it stops and comes back
        (1.0, 1.0, 1.2, -1.0),  # turning at its goal: overshoots and returns
        (2.0, -2.5, 1.4, 0.2),  # across +-pi, near the rate limit
        (-1.0, 2.0, 0.0, 3.0),  # accelerating from a standstill
        (0.3, 0.3 + 1e-10, 1e-6, 0.0),  # a tiny turn, a tiny rate
    ],
)
def test_a_turning_start_continues_its_rate(start, goal, w0, a0):
    limits = turn_limits_by_hand(OMNI)
    assert _feasible(w0, a0, limits)
    for length in (0.05, 1.5):  # a turn that outlasts the drive, one that fits in it
        translation = _translation(length)
        traj = orient(translation, OMNI, start, goal, omega_start=w0, alpha_start=a0)
        check_turning_start(traj, OMNI, start, goal, w0, a0)
        turn = math.remainder(goal - start, 2 * math.pi)
        t_opt = _ruckig_from(turn, w0, a0, limits)
        st_ = traj.stats["orientation"]
        assert st_["turn_min_s"] == pytest.approx(t_opt, rel=1e-9, abs=1e-12)
        assert traj.duration == pytest.approx(max(translation.duration, t_opt), rel=1e-9)
        assert (st_["omega_start"], st_["alpha_start"]) == (w0, a0)
        # the translation is untouched
        t = np.linspace(0.0, translation.duration, 97)
        np.testing.assert_array_equal(traj.sample(t).x, translation.sample(t).x)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    start=ANGLE,
    goal=ANGLE,
    w_frac=st.floats(-1.0, 1.0),
    a_frac=st.floats(-1.0, 1.0),
    length=st.sampled_from([0.05, 0.4, 1.5]),
)
def test_random_turning_starts_hold_every_limit(start, goal, w_frac, a_frac, length):
    limits = turn_limits_by_hand(OMNI)
    w0, a0 = w_frac * limits[0], a_frac * limits[1]
    if not _feasible(w0, a0, limits):
        a0 = 0.0
    traj = orient(_translation(length), OMNI, start, goal, omega_start=w0, alpha_start=a0)
    check_turning_start(traj, OMNI, start, goal, w0, a0)


@pytest.mark.parametrize(
    "kwargs,match",
    [
        ({"omega_start": math.nan}, r"omega_start must be finite.*nan"),
        ({"omega_start": "1"}, r"omega_start must be a number.*'1'"),
        ({"alpha_start": math.inf}, r"alpha_start must be finite.*inf"),
        ({"omega_start": 1.6}, r"omega_start.*\|omega_start\| <= 1\.5 rad/s, got 1\.6"),
        ({"omega_start": -1.6}, r"omega_start.*<= 1\.5.*got -1\.6"),
        ({"alpha_start": 3.6}, r"alpha_start.*\|alpha_start\| <= 3\.57143 rad/s\^2, got 3\.6"),
        # within each limit, but the acceleration carries the rate past its limit
        ({"omega_start": 1.4, "alpha_start": 2.0}, r"omega_start \+ alpha_start.*1\.54.*1\.4"),
    ],
)
def test_bad_turning_starts_are_refused(kwargs, match):
    assert turn_limits_by_hand(OMNI)[:2] == pytest.approx((1.5, 3.571428571428571))
    with pytest.raises(InvalidInputError, match=match):
        orient(_translation(1.0), OMNI, 0.0, 1.0, **kwargs)
    with pytest.raises(InvalidInputError, match=match):
        stop_orientation(_translation(1.0), OMNI, 0.0, **{"omega_start": 0.5, **kwargs})


@pytest.mark.parametrize("w0", [0.1, 0.9, -1.5])
def test_the_yaw_stop_matches_the_hand_formula(w0):
    w_lim, al_lim, z_lim = turn_limits_by_hand(OMNI)
    translation = _translation(0.4)
    traj = stop_orientation(translation, OMNI, 0.5, omega_start=w0)
    # hand: from (w0, 0) to rest, jerk -z then (if needed) -alpha_lim then +z; the rate is
    # point-symmetric about the middle, so the angle is w0 t / 2
    w = abs(w0)
    t = w / al_lim + al_lim / z_lim if w >= al_lim**2 / z_lim else 2 * math.sqrt(w / z_lim)
    assert traj.turn_duration == pytest.approx(t, rel=1e-12)
    assert traj.theta_end == pytest.approx(0.5 + w0 * t / 2, abs=1e-12)
    check_turning_start(traj, OMNI, 0.5, traj.theta_end, w0, 0.0)
    assert traj.duration == max(translation.duration, traj.turn_duration)
    assert traj.stats["orientation"]["stop"]
    at_rest = stop_orientation(translation, OMNI, 0.5, omega_start=0.0)
    assert at_rest.n_phases == 0 and at_rest.theta_end == 0.5
