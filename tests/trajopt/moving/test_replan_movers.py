"""Tests of trajopt.moving through Planner.replan: re-timing the spliced trajectory for new predictions, or stopping and re-routing.

References: the old trajectory's own state at the splice (continuity), the re-plan without the
keyword (an empty list is identical; the brake of a chain sampled against the re-plan without
movers), and an independent slack computed here on the movers' own clock (the re-plan's
samples at ``tau`` against each mover at ``ts + tau``, its radius from its fields) on 1 ms
samples, plus reference.py's dense samples, brute force and ``check_trajectory`` (1 ms
samples with the Lipschitz bound, the static map's clearance) on the shifted movers.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import trajopt
from tests.trajopt.moving.reference import brute_min, check_trajectory, dense_min
from tests.trajopt.replan.test_replan_car import forward_scene
from trajopt.errors import BlockedError

LATENCY = 0.05


def _same(a, b):
    for name in ("phase_t", "phase_s", "phase_v", "phase_a", "phase_j"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert a.duration == b.duration and a.v_start == b.v_start
    assert np.array_equal(a.path.curve.c, b.path.curve.c)
    assert a.stats["replan"] == b.stats["replan"]


def _slack_on_movers_clock(new, movers, ts, margin=0.0, dt=1e-3):
    """Smallest slack (m) over 1 ms samples, each mover evaluated on its own clock at ts + tau."""
    end = max([new.duration] + [m.t_last - ts for m in movers])
    tau = np.append(np.arange(0.0, end, dt), end)
    smp = new.sample(tau)
    worst = math.inf
    for m in movers:
        t = ts + tau
        c = np.stack([np.interp(t, m.times, m.positions[:, i]) for i in (0, 1)], axis=-1)
        rad = m.radius + m.growth * np.clip(t, 0.0, m.t_last)
        d = np.hypot(smp.x - c[:, 0], smp.y - c[:, 1]) - rad - new.robot.radius - margin
        worst = min(worst, float(d.min()))
    return worst


def _crossing(traj, t_c, name="walker", speed=0.4, growth=0.0):
    """A mover crossing the path at the point the trajectory reaches at ``t_c``, at ``t_c``."""
    smp = traj.sample(np.array([t_c]))
    p = np.array([smp.x[0], smp.y[0]])
    n = np.array([-math.sin(smp.theta[0]), math.cos(smp.theta[0])])
    return trajopt.MovingObstacle.from_waypoints(
        [t_c - 4.0, t_c + 4.0],
        [p - 4.0 * speed * n, p + 4.0 * speed * n],
        radius=0.2,
        growth=growth,
        name=name,
    )


@pytest.mark.parametrize("t", [0.0, 1.5, 4.0])
def test_no_movers_is_todays_replan(driven, t):
    planner, traj = driven
    base = planner.replan(traj, t, latency=LATENCY)
    for movers in (None, []):
        _same(planner.replan(traj, t, latency=LATENCY, moving_obstacles=movers), base)
    assert "moving" not in base.stats


@pytest.mark.parametrize("growth", [0.0, 0.02])
@pytest.mark.parametrize("t", [1.0, 3.0])
def test_new_predictions_re_time_the_kept_rest(driven, t, growth):
    planner, traj = driven
    ts = t + LATENCY
    static = planner.replan(traj, t, latency=LATENCY)
    assert static.stats["replan"] == "kept"
    # on the plan's clock: a mover crossing the rest of the path when the robot gets there
    mover = _crossing(traj, ts + 0.5 * (traj.duration - ts), growth=growth)
    assert _slack_on_movers_clock(static, [mover], ts) < 0.0  # the kept rest would hit it
    new = planner.replan(traj, t, latency=LATENCY, moving_obstacles=[mover], mover_margin=0.05)
    moving = new.stats["moving"]
    assert new.stats["replan"] == "kept" and moving["replan"] == "kept"
    assert moving["clock_offset_s"] == pytest.approx(ts) and moving["certificate"]["ok"]
    assert moving["plan"] != "as planned" and new.duration > static.duration
    # the same path: the kept rest, only re-timed
    assert new.path is static.path or np.array_equal(new.path.curve.c, static.path.curve.c)
    assert new.motion(new.duration)[0] == pytest.approx(static.length)
    # the splice: position, heading, speed and acceleration of the old trajectory at ts
    a, b = traj.state_at(ts), new.state_at(0.0)
    assert math.hypot(a.x - b.x, a.y - b.y) < 1e-9
    assert abs(math.remainder(a.theta - b.theta, 2 * math.pi)) < 1e-9
    assert abs(a.v - b.v) < 1e-9 and abs(a.a - b.a) < 1e-9
    # clear at every instant: 1 ms samples on the movers' clock, and the brute force
    assert _slack_on_movers_clock(new, [mover], ts, margin=0.05) >= -1e-6
    shifted = [trajopt.moving.shift_clock(mover, ts)]
    assert brute_min(new, shifted, margin=0.05) >= -1e-6
    t_s = np.arange(0.0, new.duration, 1e-3)
    _, v, acc, _ = new.motion(t_s)
    rob = new.robot
    assert np.max(np.abs(np.diff(v))) < rob.a_max * 1e-3 * 1.01
    assert np.max(np.abs(np.diff(acc))) < rob.j_max * 1e-3 * 1.01


def test_a_mover_far_away_keeps_the_rest_as_it_is(driven):
    planner, traj = driven
    far = trajopt.MovingObstacle.constant_velocity((50.0, 50.0), (0.1, 0.0), radius=0.3, horizon=5)
    base = planner.replan(traj, 1.0, latency=LATENCY)
    new = planner.replan(traj, 1.0, latency=LATENCY, moving_obstacles=[far])
    assert new.stats["moving"]["plan"] == "as planned"
    for name in ("phase_t", "phase_s", "phase_v", "phase_a", "phase_j"):
        assert np.array_equal(getattr(new, name), getattr(base, name))


def test_a_mover_parked_on_the_rest_stops_and_re_routes(driven, scene):
    planner, traj = driven
    ts = 1.0 + LATENCY
    smp = traj.sample(np.array([0.5 * (ts + traj.duration)]))
    parked = trajopt.MovingObstacle.from_waypoints(
        [0.0], [(smp.x[0], smp.y[0])], radius=0.2, name="cart"
    )
    shifted = [trajopt.moving.shift_clock(parked, ts)]
    static = planner.replan(traj, 1.0, latency=LATENCY)
    assert dense_min(static, shifted)[0] < 0.0  # the kept rest runs into the cart
    new = planner.replan(traj, 1.0, latency=LATENCY, moving_obstacles=[parked])
    moving = new.stats["moving"]
    assert moving["route"].startswith("stopped: ") and "'cart'" in moving["blocked"]
    assert moving["certificate"]["ok"] and new.stats["replan"] == "kept"
    _splice_equal(traj, new, ts)
    # braked to a stop on the old path, then on another way to the same goal
    stop = new.state_at(moving["head_s"])
    assert stop.v == 0.0 and stop.a == pytest.approx(0.0, abs=1e-9)
    end = new.state_at(new.duration)
    assert math.hypot(end.x - traj.steps.goal[0], end.y - traj.steps.goal[1]) < 1e-9
    # clear of the cart and of the map at every instant: the independent check
    assert _slack_on_movers_clock(new, [parked], ts) >= -1e-6
    check = check_trajectory(new, shifted, grid=scene.grid)
    assert check.ok and check.static_slack >= -1e-6
    t = np.arange(0.0, new.duration, 1e-3)
    assert np.abs(new.sample(t).v).max() <= new.robot.v_max * (1 + 1e-9)


def test_a_mover_parked_on_the_goal_blocks_every_way(driven):
    planner, traj = driven
    ts = 1.0 + LATENCY
    goal = traj.steps.goal
    parked = trajopt.MovingObstacle.from_waypoints([0.0], [goal], radius=0.2, name="cart")
    with pytest.raises(BlockedError, match="'cart'") as err:
        planner.replan(traj, 1.0, latency=LATENCY, moving_obstacles=[parked])
    assert err.value.mover == "cart" and err.value.t >= ts
    assert "no way on from there" in str(err.value)


def test_a_new_goal_is_planned_then_re_timed(driven, scene):
    planner, traj = driven
    ts = 1.0 + LATENCY
    static = planner.replan(traj, 1.0, goal=scene.goal("B"), latency=LATENCY)
    assert static.stats["replan"].startswith("planned")
    # crossing the new plan's middle when it is there, on the driven plan's clock
    m = _crossing(static, 0.5 * static.duration)
    mover = trajopt.MovingObstacle.from_waypoints(
        m.times + ts, m.positions, radius=m.radius, name="walker"
    )
    assert _slack_on_movers_clock(static, [mover], ts) < 0.0
    new = planner.replan(traj, 1.0, goal=scene.goal("B"), latency=LATENCY, moving_obstacles=[mover])
    assert new.stats["moving"]["replan"] == static.stats["replan"]
    assert np.array_equal(new.path.curve.c, static.path.curve.c)
    a, b = traj.state_at(ts), new.state_at(0.0)
    assert math.hypot(a.x - b.x, a.y - b.y) < 1e-9 and abs(a.v - b.v) < 1e-9
    assert abs(a.a - b.a) < 1e-9
    assert _slack_on_movers_clock(new, [mover], ts) >= -1e-6


def _splice_equal(traj, new, ts):
    a, b = traj.state_at(ts), new.state_at(0.0)
    assert math.hypot(a.x - b.x, a.y - b.y) < 1e-9
    assert abs(math.remainder(a.theta - b.theta, 2 * math.pi)) < 1e-9
    assert abs(a.v - b.v) < 1e-9 and abs(a.a - b.a) < 1e-9


def test_a_brake_turn_go_is_re_timed_after_the_stop(driven, scene):
    planner, traj = driven
    ts = 1.0 + LATENCY
    static = planner.replan(traj, 1.0, goal=scene.goal("D"), latency=LATENCY)
    assert [type(p) for p in static.pieces] == [
        trajopt.Trajectory,
        trajopt.TurnInPlace,
        trajopt.Trajectory,
    ]
    # crossing the go piece's middle when it is there, on the driven plan's clock
    t_go = float(static.piece_times[2])
    m = _crossing(static, 0.5 * (t_go + static.duration))
    mover = trajopt.MovingObstacle.from_waypoints(
        m.times + ts, m.positions, radius=m.radius, name="walker"
    )
    shifted = [trajopt.moving.shift_clock(mover, ts)]
    assert dense_min(static, shifted)[0] < 0.0  # the chain as planned would hit it
    new = planner.replan(traj, 1.0, goal=scene.goal("D"), latency=LATENCY, moving_obstacles=[mover])
    moving = new.stats["moving"]
    assert moving["certificate"]["ok"] and moving["plan"].startswith("kept")
    assert new.duration > static.duration
    # the brake is kept as it is (the robot cannot be re-timed before it stops)
    brake = static.pieces[0]
    assert moving["head_s"] == pytest.approx(brake.duration)
    assert new.pieces[0].duration == brake.duration
    t = np.linspace(0.0, brake.duration, 200)
    a, b = new.sample(t), static.sample(t)
    for name in ("x", "y", "theta", "v", "a"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    # the same turn and path after it, only later
    assert np.array_equal(new.pieces[-1].path.curve.c, static.pieces[-1].path.curve.c)
    _splice_equal(traj, new, ts)
    # clear at every instant: 1 ms samples on the movers' clock, the independent check
    assert _slack_on_movers_clock(new, [mover], ts) >= -1e-6
    assert dense_min(new, shifted)[0] >= -1e-6
    assert check_trajectory(new, shifted).ok


def test_a_brake_turn_go_blocked_after_its_stop_re_routes_from_the_stop(driven, scene):
    planner, traj = driven
    ts = 1.0 + LATENCY
    static = planner.replan(traj, 1.0, goal=scene.goal("D"), latency=LATENCY)
    t_go = float(static.piece_times[2])
    smp = static.sample(np.array([0.5 * (t_go + static.duration)]))
    parked = trajopt.MovingObstacle.from_waypoints(
        [0.0], [(smp.x[0], smp.y[0])], radius=0.2, name="cart"
    )
    shifted = [trajopt.moving.shift_clock(parked, ts)]
    assert dense_min(static, shifted)[0] < 0.0
    new = planner.replan(
        traj, 1.0, goal=scene.goal("D"), latency=LATENCY, moving_obstacles=[parked]
    )
    moving = new.stats["moving"]
    assert moving["route"] == "stopped: rerouted" and moving["certificate"]["ok"]
    # the brake kept as planned, the robot at rest where it ends
    brake = static.pieces[0]
    assert moving["head_s"] == pytest.approx(brake.duration)
    t = np.linspace(0.0, brake.duration, 200)
    a, b = new.sample(t), static.sample(t)
    for name in ("x", "y", "theta", "v", "a"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    _splice_equal(traj, new, ts)
    end = new.state_at(new.duration)
    assert math.hypot(end.x - scene.goal("D")[0], end.y - scene.goal("D")[1]) < 1e-9
    assert _slack_on_movers_clock(new, [parked], ts) >= -1e-6
    check = check_trajectory(new, shifted, grid=scene.grid)
    assert check.ok and check.static_slack >= -1e-6


def test_a_car_braked_and_planned_from_the_stop_is_re_timed():
    planner, traj, grid, goal, _, t = forward_scene()
    ts = t + LATENCY
    static = planner.replan(traj, t, grid=grid, latency=LATENCY)
    assert static.stats["replan"].startswith("braked")
    t_stop = float(static.piece_times[1])  # the brake's end: the car plan from rest follows
    m = _crossing(static, 0.5 * (t_stop + static.duration))
    mover = trajopt.MovingObstacle.from_waypoints(
        m.times + ts, m.positions, radius=m.radius, name="walker"
    )
    shifted = [trajopt.moving.shift_clock(mover, ts)]
    assert dense_min(static, shifted)[0] < 0.0
    new = planner.replan(traj, t, grid=grid, latency=LATENCY, moving_obstacles=[mover])
    moving = new.stats["moving"]
    assert moving["route"] == "retimed" and moving["plan"].startswith("kept")
    assert moving["head_s"] == pytest.approx(t_stop) and new.duration > static.duration
    _splice_equal(traj, new, ts)
    end = new.state_at(new.duration)
    assert math.hypot(end.x - goal[0], end.y - goal[1]) < 1e-6 and end.v == 0.0
    assert _slack_on_movers_clock(new, [mover], ts) >= -1e-6
    check = check_trajectory(new, shifted, grid=grid)
    assert check.ok and check.static_slack >= -1e-6
