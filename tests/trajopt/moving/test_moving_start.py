"""Tests of trajopt.moving: re-timing from a moving start (speed and acceleration at t = 0).

The re-timed trajectory starts in the given state (it cannot rest at once: it drives on, or
brakes to a stop and waits there), keeps the path and the limits, and is checked against
1 ms samples and the brute force of tests/trajopt/moving/reference.py.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.trajopt.moving.reference import brute_min, dense_min
from trajopt.errors import BlockedError, InvalidInputError
from trajopt.geometry import PolylineCurve
from trajopt.moving import MovingObstacle, certify_movers, retime_for_movers
from trajopt.robot import Robot
from trajopt.timing import time_parameterize

ROBOT = Robot(v_max=0.6, a_max=0.6, j_max=2.0)
LINE = PolylineCurve(np.array([[0.0, 0.0], [6.0, 0.0]]))


@pytest.fixture(scope="module", params=[(0.5, 0.0), (0.3, 0.4), (0.55, -0.3)])
def rolling(request):
    v0, a0 = request.param
    return time_parameterize(LINE, ROBOT, v_start=v0, a_start=a0)


def _check(out, movers, static):
    """Same path and start state, certified, clear on 1 ms samples and by brute force, limits."""
    assert out.path is static.path
    assert out.v_start == static.v_start and out.phase_a[0] == static.phase_a[0]
    assert certify_movers(out, movers).ok
    assert dense_min(out, movers)[0] >= -1e-6
    assert brute_min(out, movers) >= -1e-6
    t = np.arange(0.0, out.duration, 1e-3)
    s, v, a, _ = out.motion(t)
    assert v[0] == pytest.approx(static.v_start) and a[0] == pytest.approx(static.phase_a[0])
    assert np.all(np.diff(s) >= -1e-12) and np.all(v >= -1e-9)
    assert np.max(np.abs(np.diff(v))) < ROBOT.a_max * 1e-3 * 1.01  # no speed jump
    assert np.max(np.abs(np.diff(a))) < ROBOT.j_max * 1e-3 * 1.01  # no acceleration jump
    assert np.max(v) <= ROBOT.v_max * (1 + 1e-9) and np.max(np.abs(a)) <= ROBOT.a_max * (1 + 1e-9)
    assert out.motion(out.duration)[0] == pytest.approx(static.length)
    assert out.motion(out.duration)[1] == 0.0


def _crossing_at(traj, x, name="walker", speed=0.3, late=0.0):
    """A mover crossing the line at ``x`` when the static timing is there (plus ``late`` s)."""
    t_x = float(
        np.interp(
            x,
            traj.motion(np.linspace(0, traj.duration, 2001))[0],
            np.linspace(0, traj.duration, 2001),
        )
    )
    t_x += late
    return MovingObstacle.constant_velocity(
        (x, -speed * t_x), (0.0, speed), radius=0.3, horizon=t_x + 20.0, name=name
    )


def test_a_clear_moving_start_is_kept(rolling):
    far = MovingObstacle.constant_velocity((3.0, 5.0), (0.0, 0.2), radius=0.3, horizon=10.0)
    out = retime_for_movers(rolling, [far])
    assert out.stats["moving"]["plan"] == "as planned"
    assert np.array_equal(out.phase_t, rolling.phase_t)


def test_the_moving_robot_brakes_and_lets_a_slow_mover_pass(rolling):
    m = _crossing_at(rolling, 2.5, speed=0.15)
    assert not certify_movers(rolling, [m]).ok
    out = retime_for_movers(rolling, [m])
    _check(out, [m], rolling)
    assert out.duration > rolling.duration
    label = out.stats["moving"]["plan"]
    assert label.startswith("brake to s = ") or "stop at" in label
    # it stood still somewhere before the mover's lane while the mover crossed
    t = np.arange(0.0, out.duration, 1e-3)
    s, v, _, _ = out.motion(t)
    assert np.any(v == 0.0) and np.max(s[v == 0.0][s[v == 0.0] < 6.0]) < 2.5


def test_the_moving_robot_drives_on_past_a_late_mover(rolling):
    # the mover comes later than the static timing, but a slower robot would meet it: the
    # start state is kept and the robot passes first (the plan as it is, certified)
    m = _crossing_at(rolling, 3.0, late=3.0)
    out = retime_for_movers(rolling, [m])
    _check(out, [m], rolling)


def test_a_mover_the_robot_cannot_stop_for_blocks():
    # a cart 0.8 m ahead (limit 0.165 + 0.3 m) leaves the path sideways after 5 s: a robot at
    # rest waits for it; at 0.6 m/s the robot needs 0.39 m to stop (more than 0.335 m), and
    # cannot pass first
    assert ROBOT.radius == 0.165
    cart = MovingObstacle.from_waypoints(
        [0.0, 5.0, 8.0], [(0.8, 0.0), (0.8, 0.0), (0.8, 3.0)], radius=0.3, name="cart"
    )
    still = time_parameterize(LINE, ROBOT)
    _check(retime_for_movers(still, [cart]), [cart], still)
    fast = time_parameterize(LINE, ROBOT, v_start=0.6, a_start=0.0)
    with pytest.raises(BlockedError, match="'cart'"):
        retime_for_movers(fast, [cart])


def test_a_rest_before_a_moving_start_is_refused(rolling):
    m = _crossing_at(rolling, 2.5)
    with pytest.raises(InvalidInputError, match="not_before must be 0"):
        retime_for_movers(rolling, [m], not_before=1.0)


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.floats(0.05, 0.6),
    st.floats(-0.5, 0.5),
    st.lists(
        st.tuples(st.floats(1.0, 5.5), st.floats(0.1, 0.6), st.floats(-2.0, 4.0)),
        min_size=1,
        max_size=3,
    ),
)
def test_random_moving_starts_are_certified_or_typed_errors(v0, a0, specs):
    try:
        traj = time_parameterize(LINE, ROBOT, v_start=v0, a_start=a0)
    except Exception:  # a state the timing cannot start from: not this test's subject
        return
    movers = [
        _crossing_at(traj, x, name=f"m{i}", speed=sp, late=late)
        for i, (x, sp, late) in enumerate(specs)
    ]
    try:
        out = retime_for_movers(traj, movers)
    except (BlockedError, InvalidInputError):
        return
    _check(out, movers, traj)
