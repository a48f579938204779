"""Tests of trajopt.moving: re-timing along the path (wait, stop, pass before) and BlockedError.

Every returned trajectory is certified and checked against 1 ms samples and the brute force;
its speed profile is continuous and keeps the robot's limits.
"""

from __future__ import annotations

import time

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.trajopt.moving.reference import (
    brute_min,
    check_trajectory,
    dense_min,
    mover_rate,
    positions,
    slack_at,
)
from trajopt.errors import BlockedError, InvalidInputError
from trajopt.geometry import PolylineCurve
from trajopt.moving import MovingObstacle, certify_movers, retime_for_movers
from trajopt.robot import Robot
from trajopt.timing import time_parameterize

ROBOT = Robot(v_max=0.6, a_max=0.6, j_max=2.0)


@pytest.fixture(scope="module")
def line6():
    return time_parameterize(PolylineCurve(np.array([[0.0, 0.0], [6.0, 0.0]])), ROBOT)


def _check(traj, movers, static):
    """Certified, clear on 1 ms samples and by brute force, same path, continuous limits."""
    assert traj.path is static.path
    cert = certify_movers(traj, movers)
    assert cert.ok
    assert dense_min(traj, movers)[0] >= -1e-6
    assert brute_min(traj, movers) >= -1e-6
    t = np.arange(0.0, traj.duration, 1e-3)
    s, v, a, j = traj.motion(t)
    assert np.all(np.diff(s) >= -1e-12) and np.all(v >= -1e-9)
    assert np.max(np.abs(np.diff(v))) < ROBOT.a_max * 1e-3 * 1.01  # no speed jump
    assert np.max(np.abs(np.diff(a))) < ROBOT.j_max * 1e-3 * 1.01  # no acceleration jump
    assert np.max(v) <= ROBOT.v_max * (1 + 1e-9) and np.max(np.abs(a)) <= ROBOT.a_max * (1 + 1e-9)
    assert traj.motion(traj.duration)[0] == pytest.approx(static.length)


def test_a_clear_trajectory_is_kept(line6):
    late = MovingObstacle.constant_velocity((3.0, -3.0), (0.0, 0.2), radius=0.3, horizon=10.0)
    assert late.position_at(10.0)[1] < -0.9
    out = retime_for_movers(line6, [late])
    assert out.stats["moving"]["plan"] == "as planned" and "moving" not in line6.stats
    assert np.array_equal(out.phase_t, line6.phase_t) and out.duration == line6.duration


def test_the_robot_waits_for_a_crossing_mover(line6):
    # crosses x = 3 at t ~ 6.7 s, when the static plan is there
    m = MovingObstacle.constant_velocity(
        (3.0, -2.0), (0.0, 0.3), radius=0.3, horizon=20.0, name="walker"
    )
    assert not certify_movers(line6, [m]).ok
    out = retime_for_movers(line6, [m])
    _check(out, [m], line6)
    assert out.duration > line6.duration
    assert out.stats["moving"]["certificate"]["ok"]
    assert "wait" in out.stats["moving"]["plan"]


def test_the_robot_leaves_the_start_then_stops_to_let_a_mover_pass(line6):
    # one mover crosses x = 4.5 at t ~ 8.6 s, when the static plan is there; another runs over
    # the start from t ~ 2 s: waiting at the start until the first has passed (~2 s) is
    # unsafe, so the robot drives, stops short of x = 4.5 and waits
    cross = MovingObstacle.constant_velocity(
        (4.5, -3.0), (0.0, 0.35), radius=0.3, horizon=24.0, name="cross"
    )
    sweep = MovingObstacle.constant_velocity(
        (0.0, -1.5), (0.0, 0.5), radius=0.3, horizon=24.0, name="sweep"
    )
    assert not certify_movers(line6, [cross]).ok and certify_movers(line6, [sweep]).ok
    out = retime_for_movers(line6, [cross, sweep])
    _check(out, [cross, sweep], line6)
    assert "stop at" in out.stats["moving"]["plan"]
    s_stop = float(out.stats["moving"]["plan"].split("s = ")[1].split(" m")[0])
    assert 0.5 < s_stop < 4.5


def test_head_on_in_a_corridor_is_blocked_fast(line6):
    m = MovingObstacle.constant_velocity(
        (6.5, 0.0), (-0.4, 0.0), radius=0.3, horizon=30.0, name="forklift"
    )
    t0 = time.perf_counter()
    with pytest.raises(BlockedError) as err:
        retime_for_movers(line6, [m])
    assert time.perf_counter() - t0 < 0.5
    assert err.value.mover == "forklift" and "'forklift'" in str(err.value)
    # the forklift reaches the robot's start (s = 0) at about (6.5 - 0.465) / 0.4 s
    assert 0.0 < err.value.t <= (6.5 - 0.465) / 0.4 + 0.1


def test_a_mover_that_stops_on_the_path_blocks(line6):
    m = MovingObstacle.from_waypoints(
        [0.0, 4.0], [(3.0, -2.0), (3.0, 0.0)], radius=0.3, name="parked"
    )
    with pytest.raises(BlockedError, match="parked"):
        retime_for_movers(line6, [m])


def test_a_mover_on_the_robot_at_the_start_is_refused(line6):
    m = MovingObstacle.constant_velocity(
        (0.2, 0.1), (0.0, 1.0), radius=0.3, horizon=5.0, name="toe"
    )
    with pytest.raises(InvalidInputError, match="'toe' overlaps the robot at t = 0"):
        retime_for_movers(line6, [m])


@pytest.mark.parametrize("gap", [-1e-3, 1e-3])
def test_the_quick_filter_of_the_start_overlap_keeps_the_near_mover(line6, gap):
    # among far movers (some mid-segment at t = 0, some growing), a cart whose edge is `gap`
    # from the robot's disc at t = 0 (its place interpolated between waypoints before and
    # after 0): refused exactly when it overlaps (the distance by hand: the edge at x - 0.45)
    from trajopt.moving import _retime

    rng = np.random.default_rng(5)
    far = [
        MovingObstacle.from_waypoints(
            [-1.0 - j, 2.0, 5.0],
            rng.uniform(4.0, 9.0, (3, 2)),
            radius=0.2,
            growth=0.05 * j,
            vertices=CART if j % 2 else None,
            name=f"far{j}",
        )
        for j in range(8)
    ]
    x = 0.45 + 0.05 + float(ROBOT.radius) + gap  # the cart's centre at t = 0 (m)
    near = MovingObstacle.from_waypoints(
        [-1.0, 1.0], [(x - 0.5, 0.0), (x + 0.5, 0.0)], radius=0.05, vertices=CART, name="near"
    )
    movers = [*far[:4], near, *far[4:]]
    if gap < 0.0:
        with pytest.raises(InvalidInputError, match="'near' overlaps the robot at t = 0"):
            _retime._overlap_at_start(line6, movers, 0.0)
    else:
        _retime._overlap_at_start(line6, movers, 0.0)
    _retime._overlap_at_start(line6, [], 0.0)  # no movers: nothing to refuse


def test_a_turning_polygon_mover_is_let_pass(line6):
    cart = MovingObstacle.from_waypoints(
        [0.0, 12.0],
        [(3.0, -2.4), (3.0, 3.6)],
        radius=0.05,
        headings=[0.0, 1.5],
        vertices=[(-0.4, -0.25), (0.4, -0.25), (0.4, 0.25), (-0.4, 0.25)],
        name="cart",
    )
    assert not certify_movers(line6, [cart]).ok
    out = retime_for_movers(line6, [cart], margin=0.02)
    assert certify_movers(out, [cart], margin=0.02).ok
    assert dense_min(out, [cart], margin=0.02)[0] >= -1e-6
    assert brute_min(out, [cart], margin=0.02) >= -1e-6


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.lists(
        st.tuples(
            st.floats(0.5, 5.5), st.floats(-3.0, 3.0), st.floats(-0.5, 0.5), st.floats(0.1, 0.4)
        ),
        min_size=1,
        max_size=3,
    )
)
def test_random_crossings_are_certified_or_typed_errors(line6, specs):
    movers = [
        MovingObstacle.constant_velocity(
            (x, y), (vx, -np.sign(y) * 0.4), radius=r, horizon=15.0, name=f"m{i}"
        )
        for i, (x, y, vx, r) in enumerate(specs)
    ]
    try:
        out = retime_for_movers(line6, movers)
    except (BlockedError, InvalidInputError):
        return
    assert certify_movers(out, movers).ok
    assert dense_min(out, movers)[0] >= -1e-6


def _wait_witness(static, movers, h=0.01, dt=0.005):
    """Earliest wait ``w`` on a grid of ``h`` (s) after which driving ``static`` as it is stays clear.

    Brute force, written here again: the robot rests at the start until ``w``, drives
    ``static``'s own timing, then stands at the goal; the distance to every mover minus the
    limit, on samples every ``dt`` (s), must be at least what the robot and the mover can
    close in ``dt / 2`` (a sound bound between samples). Waits up to the last prediction (the
    movers stand after it). Returns the arrival ``w + duration`` (s), or ``None``.
    """
    robot_v = float(static.robot.v_max)
    limit = float(static.robot.radius)
    big_t = float(static.duration)
    tau = np.append(np.arange(0.0, big_t, dt), big_t)
    p = positions(static, tau)
    t_last = max(float(m.times[-1]) for m in movers)
    tt = np.arange(0.0, t_last + big_t + 1.0, dt)
    start_bad, goal_bad = np.zeros(tt.size, bool), np.zeros(tt.size, bool)
    for m in movers:
        u = mover_rate(m)
        start_bad |= slack_at(np.repeat(p[:1], tt.size, 0), m, tt, limit) < u * dt / 2
        goal_bad |= slack_at(np.repeat(p[-1:], tt.size, 0), m, tt, limit) < u * dt / 2
    # the last prediction is over by tt[-1]: a mover over the goal then stays there
    if goal_bad[-1]:
        return None
    t_start_bad = tt[np.argmax(start_bad)] if start_bad.any() else np.inf
    t_goal_bad = tt[np.flatnonzero(goal_bad)[-1]] if goal_bad.any() else -np.inf
    for w in np.arange(0.0, t_last + h, h):
        if w + dt / 2 >= t_start_bad:  # the start is no longer safe to rest at
            return None
        if w + big_t <= t_goal_bad + dt / 2:
            continue
        if all(
            np.all(slack_at(p, m, tau + w, limit) >= (robot_v + mover_rate(m)) * dt / 2)
            for m in movers
        ):
            return w + big_t
    return None


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.lists(
        st.tuples(
            st.floats(0.8, 5.2),  # where it crosses the line (m)
            st.floats(0.5, 12.0),  # when (s)
            st.floats(0.3, 1.5),  # its speed (m/s)
            st.floats(0.5, 2.6),  # its direction against the line (rad)
            st.floats(0.1, 0.4),  # its radius (m)
        ),
        min_size=1,
        max_size=3,
    )
)
def test_never_later_than_a_brute_force_wait_at_the_start(line6, spec):
    movers = []
    for i, (x, tc, v, ang, r) in enumerate(spec):
        vel = v * np.array([np.cos(ang), np.sin(ang)])
        start = np.array([x, 0.0]) - vel * tc
        m = MovingObstacle.constant_velocity(start, vel, radius=r, horizon=tc + 6.0, name=f"m{i}")
        if np.hypot(*start) < r + ROBOT.radius + 0.05:
            return  # over the robot at t = 0: a typed error, tested elsewhere
        movers.append(m)
    witness = _wait_witness(line6, movers)
    try:
        out = retime_for_movers(line6, movers)
    except BlockedError:
        assert witness is None
        return
    cert = certify_movers(out, movers)
    assert cert.ok and dense_min(out, movers)[0] >= -1e-6
    if witness is not None:
        assert out.duration <= witness + 1e-9


def test_a_path_of_the_same_geometry_re_times_as_when_cold():
    # a re-plan that keeps its rest hands over a new curve object of the same geometry: the
    # re-timing reuses the old path's tables and must give what a cold re-timing gives
    from trajopt.geometry import BSplineCurve
    from trajopt.moving import _retime

    t = np.array([0.0, 0.0, 0.0, 0.0, 2.0, 4.0, 6.0, 6.0, 6.0, 6.0])
    c = np.array([[0.0, 0.0], [1.0, 0.2], [2.5, -0.2], [3.5, 0.3], [5.0, 0.0], [6.0, 0.1]])
    m = MovingObstacle.constant_velocity(
        (3.0, -2.0), (0.0, 0.35), radius=0.3, horizon=25.0, name="walker"
    )
    first = time_parameterize(BSplineCurve(t, c, 3), ROBOT)
    assert not certify_movers(first, [m]).ok
    warm_up = retime_for_movers(first, [m])
    again = time_parameterize(BSplineCurve(t.copy(), c.copy(), 3), ROBOT)
    assert again.path is not first.path
    warm = retime_for_movers(again, [m])
    _retime._TABLES.clear()
    cold = retime_for_movers(again, [m])
    assert warm.path is again.path and certify_movers(warm, [m]).ok
    for name in ("phase_t", "phase_s", "phase_v", "phase_a", "phase_j"):
        assert np.array_equal(getattr(warm, name), getattr(cold, name))
        assert np.array_equal(getattr(warm, name), getattr(warm_up, name))
    assert dense_min(warm, [m])[0] >= -1e-6


def test_a_re_timed_trajectory_re_timed_again_cold_as_when_its_plan_came_first():
    # a re-plan hands over a re-timing (with rests) to re-time for new predictions: its own
    # timing is not the path's one drive, so a cold re-timing of it gives what a re-timing
    # whose tables the plan made first gives
    from trajopt.geometry import BSplineCurve
    from trajopt.moving import _retime

    t = np.array([0.0, 0.0, 0.0, 0.0, 2.0, 4.0, 6.0, 6.0, 6.0, 6.0])
    c = np.array([[0.0, 0.0], [1.0, 0.2], [2.5, -0.2], [3.5, 0.3], [5.0, 0.0], [6.0, 0.1]])
    m = MovingObstacle.constant_velocity(
        (3.0, -2.0), (0.0, 0.35), radius=0.3, horizon=25.0, name="walker"
    )
    plan = time_parameterize(BSplineCurve(t, c, 3), ROBOT)
    timed = retime_for_movers(plan, [m])
    assert "wait" in timed.stats["moving"]["plan"]
    later = MovingObstacle.constant_velocity(
        (3.0, -2.4), (0.0, 0.35), radius=0.3, horizon=25.0, name="walker"
    )
    warm = retime_for_movers(timed, [later])
    _retime._TABLES.clear()
    cold = retime_for_movers(timed, [later])
    assert cold.duration == warm.duration and certify_movers(cold, [later]).ok
    for name in ("phase_t", "phase_s", "phase_v", "phase_a", "phase_j"):
        assert np.array_equal(getattr(warm, name), getattr(cold, name))
    # the cold tables' one drive (0, L): the path timed from rest, the plan's own timing
    tb = _retime._TABLES[-1]
    own = tb.drives[(0.0, tb.length)]
    assert own.duration == plan.duration
    phases = np.column_stack([plan.phase_t, plan.phase_s, plan.phase_v, plan.phase_a])
    assert np.array_equal(own.rows[:, :4], phases)


CART = [(-0.45, -0.25), (0.45, -0.25), (0.45, 0.25), (-0.45, 0.25)]


@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.lists(
        st.tuples(
            st.floats(0.8, 5.2),  # where it crosses the line (m)
            st.floats(0.5, 12.0),  # when (s)
            st.floats(0.3, 1.5),  # its speed (m/s)
            st.floats(0.5, 2.6),  # its direction against the line (rad)
            st.floats(-0.3, 0.3),  # its turn rate (rad/s)
        ),
        min_size=1,
        max_size=3,
    )
)
def test_polygon_movers_never_later_than_a_brute_force_wait_at_the_start(line6, spec):
    # carts (rounded rectangles, turning) crossing the line: the tightened plan against the
    # brute-force wait-then-drive witness and the independent check
    movers = []
    for i, (x, tc, v, ang, w) in enumerate(spec):
        vel = v * np.array([np.cos(ang), np.sin(ang)])
        t_end = tc + 6.0
        pos = [np.array([x, 0.0]) - vel * tc, np.array([x, 0.0]) + vel * 6.0]
        m = MovingObstacle.from_waypoints(
            [0.0, t_end],
            pos,
            radius=0.05,
            headings=[ang - w * tc, ang + w * 6.0],
            vertices=CART,
            name=f"cart{i}",
        )
        if slack_at(np.zeros((1, 2)), m, 0.0, ROBOT.radius + 0.05)[0] < 0.0:
            return  # over the robot at t = 0: a typed error, tested elsewhere
        movers.append(m)
    witness = _wait_witness(line6, movers)
    try:
        out = retime_for_movers(line6, movers)
    except BlockedError:
        assert witness is None
        return
    assert certify_movers(out, movers).ok
    assert check_trajectory(out, movers).ok
    if witness is not None:
        assert out.duration <= witness + 1e-9


def test_the_fine_windows_band_holds_every_earlier_launch(line6):
    """The band of :func:`pass_band` holds the robot near each node for any earlier launches.

    A schedule of three drives with rests; random launches moved earlier (never before
    ``t_from``, never into the drive before): every 0.1 ms sample of the motion within
    ``h/2`` of a node lies in the node's band (brute force on the motion's own samples).
    """
    from trajopt.moving._retime import _tables
    from trajopt.moving._tighten import pass_band

    tables = _tables(line6)
    cuts = [0.0, 1.5, 3.5, 6.0]
    drives = [tables.drive(a, b) for a, b in zip(cuts[:-1], cuts[1:], strict=True)]
    schedule, t = [], 2.0
    for pc in drives:
        schedule.append((t, pc))
        t += pc.duration + 1.5
    t_from, h = 0.5, 0.01
    s = np.linspace(0.0, 6.0, 601)
    lo, hi = pass_band(s, h, [schedule], t_from)
    rng = np.random.default_rng(3)
    for trial in range(20):
        launches, prev_end = [], t_from
        for t_k, pc in schedule:  # the first trial: the schedule as it is
            launch = rng.uniform(prev_end, t_k) if trial else t_k
            launches.append(launch)
            prev_end = launch + pc.duration
        tau = np.arange(t_from, prev_end + 0.5, 1e-4)
        pos = np.zeros(tau.shape)
        for launch, (_, pc) in zip(launches, schedule, strict=True):
            pos = np.where(tau >= launch, pc.s_at(tau - launch), pos)
        assert np.all(np.diff(pos) >= 0.0)
        # the samples near node i: from the first at s_i - h/2 to the last at s_i + h/2
        first = np.searchsorted(pos, s - 0.5 * h, side="left")
        last = np.searchsorted(pos, s + 0.5 * h, side="right") - 1
        assert np.all(tau[first] >= lo - 1e-12)
        inside = s + 0.5 * h < 6.0  # the nodes the robot leaves (at the goal: the rests' test)
        assert np.all(tau[last][inside] <= hi[inside] + 1e-12)
