"""Tests of trajopt.moving.retime_chain through Planner.plan: cars, and an omni orientation.

A car's chain (drives between cusps, forwards and backwards, steering at rest at the cusps)
is re-timed on one clock: a mover crossing where the car will be is let pass, the car rests
(``v = 0``) at every cusp, reverses under its ``v_max_reverse``, holds its steering rate, and
1 ms samples and the brute force (the references) find no violation; a cone parked on its
path is driven round. An omni base with its own orientation keeps its orientation profile
within the yaw limits, from the same start to the same end orientation.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import trajopt
import trajopt.moving
from tests.trajopt.moving.reference import brute_min, dense_min
from tests.trajopt.planning.test_car import behind_scene, three_point_scene, uturn_scene
from trajopt.timing import turn_limits


def _crossing_at(plan, t_c, name="walker", radius=0.05, reach=0.9):
    """A mover crossing the plan's position at ``t_c`` (s), north to south, at 0.3 m/s."""
    smp = plan.sample(np.array([t_c]))
    p = np.array([smp.x[0], smp.y[0]])
    return trajopt.MovingObstacle.from_waypoints(
        [t_c - reach / 0.3, t_c + reach / 0.3],
        [p + (0.0, reach), p - (0.0, reach)],
        radius=radius,
        name=name,
    )


def _checked(out, movers, margin=0.0):
    assert trajopt.certify_movers(out, movers, margin=margin).ok
    assert out.stats["moving"]["certificate"]["ok"]
    assert dense_min(out, movers, margin=margin)[0] >= -1e-6
    assert brute_min(out, movers, margin=margin) >= -1e-6


@pytest.fixture(scope="module")
def cars():
    """The three-point turn (cusps, steering at rest) and the goal behind (reversing)."""
    out = {}
    for make in (three_point_scene, behind_scene):
        grid, robot, start, goal, h0, h1 = make()
        planner = trajopt.Planner(grid, robot)
        base = planner.plan(start, goal, start_heading=h0, goal_heading=h1)
        out[make.__name__] = (planner, robot, start, goal, h0, h1, base)
    return out


@pytest.mark.parametrize("name", ["three_point_scene", "behind_scene"])
def test_a_car_lets_a_crossing_mover_pass(cars, name):
    planner, robot, start, goal, h0, h1, base = cars[name]
    mover = _crossing_at(base, 0.5 * base.duration)
    assert not trajopt.certify_movers(base, [mover]).ok
    out = planner.plan(start, goal, start_heading=h0, goal_heading=h1, moving_obstacles=[mover])
    _checked(out, [mover])
    assert out.stats["moving"]["route"] == "retimed"
    kinds = [(type(p).__name__, getattr(p, "direction", 0)) for p in out.pieces]
    assert kinds == [(type(p).__name__, getattr(p, "direction", 0)) for p in base.pieces]
    for a, b in zip(out.pieces, base.pieces, strict=True):  # the same curves, re-timed
        if a.single_curve:
            assert np.array_equal(a.path.curve.c, b.path.curve.c)
    # at rest at every join (the cusps and the steering at rest), limits held everywhere
    at_joins = out.sample(out.piece_times)
    assert np.all(at_joins.v == 0.0)
    t = np.linspace(0.0, out.duration, 10001)
    smp = out.sample(t)
    v_back = robot.drive.v_max_backwards(robot)
    assert smp.v.max() <= robot.v_max * (1 + 1e-9)
    assert -smp.v.min() <= v_back * (1 + 1e-9)
    assert np.abs(smp.a).max() <= robot.a_max * (1 + 1e-6)
    if robot.drive.steer_rate_max is not None:
        for i in range(len(out.pieces)):
            tt = np.linspace(out.piece_times[i] + 1e-6, out.piece_times[i + 1] - 1e-6, 5001)
            at = out.sample(tt)
            rate = np.abs(np.diff(at.steer)) / np.diff(tt)
            assert rate.max() <= robot.drive.steer_rate_max * (1 + 1e-6)
    end = out.sample(np.array([out.duration]))
    assert math.hypot(end.x[0] - goal[0], end.y[0] - goal[1]) < 1e-6


def test_a_car_drives_round_a_parked_cone():
    grid, robot, start, goal, h0, h1 = uturn_scene()
    planner = trajopt.Planner(grid, robot)
    base = planner.plan(start, goal, start_heading=h0, goal_heading=h1)
    smp = base.sample(np.array([0.5 * base.duration]))
    cone = trajopt.MovingObstacle.from_waypoints(
        [0.0], [(smp.x[0], smp.y[0])], radius=0.1, name="cone"
    )
    out = planner.plan(start, goal, start_heading=h0, goal_heading=h1, moving_obstacles=[cone])
    assert out.stats["moving"]["route"] == "rerouted"
    _checked(out, [cone])
    assert all(p.direction == 1 for p in out.pieces if p.single_curve)  # reverse=False held


@pytest.fixture(scope="module")
def omni_planner(scene):
    return trajopt.Planner(scene.grid, trajopt.Robot.rectangle(0.3, 0.2, 0.15, drive="omni"))


def test_an_omni_orientation_follows_the_re_timed_translation(scene, omni_planner):
    base = omni_planner.plan(scene.start, scene.goal("A"), start_heading=0.3, goal_heading=2.0)
    assert base.own_orientation
    mover = _crossing_at(base.translation, 0.5 * base.translation.duration, radius=0.2)
    out = omni_planner.plan(
        scene.start,
        scene.goal("A"),
        start_heading=0.3,
        goal_heading=2.0,
        moving_obstacles=[mover],
        mover_margin=0.03,
    )
    assert out.own_orientation and out.stats["moving"]["route"] == "retimed"
    assert np.array_equal(out.path.curve.c, base.path.curve.c)
    assert out.translation.duration > base.translation.duration
    # the robot's circumscribed disc keeps its distance (the body may face any way)
    assert dense_min(out, [mover], margin=0.03)[0] >= -1e-6
    assert brute_min(out, [mover], margin=0.03) >= -1e-6
    t = np.linspace(0.0, out.duration, 40001)
    smp = out.sample(t)
    assert smp.theta[0] == pytest.approx(0.3, abs=1e-9)
    assert math.remainder(smp.theta[-1] - 2.0, 2.0 * math.pi) == pytest.approx(0.0, abs=1e-9)
    w_lim, a_lim, _ = turn_limits(out.robot)
    assert np.abs(smp.omega).max() <= w_lim * (1 + 1e-6)
    assert np.abs(np.diff(smp.omega) / np.diff(t)).max() <= a_lim * (1 + 1e-3)
    assert np.abs(np.diff(smp.theta)).max() <= w_lim * (t[1] - t[0]) * (1 + 1e-6)


def test_a_car_need_not_stand_at_a_cusp_it_has_left(cars):
    """A mover crossing the first cusp after the car has left it costs no time."""
    planner, _, start, goal, h0, h1, base = cars["three_point_scene"]
    j = next(k for k, p in enumerate(base.pieces) if p.single_curve)
    cusp = base.sample(np.array([base.piece_times[j + 1]]))
    p = np.array([cusp.x[0], cusp.y[0]])
    t_late = base.duration + 3.0
    late = trajopt.MovingObstacle.from_waypoints(
        [t_late - 3.0, t_late + 3.0], [p - (0.0, 1.5), p + (0.0, 1.5)], radius=0.1, name="late"
    )
    early = _crossing_at(base, 0.5 * (base.piece_times[j] + base.piece_times[j + 1]))
    alone = planner.plan(start, goal, start_heading=h0, goal_heading=h1, moving_obstacles=[early])
    both = planner.plan(
        start, goal, start_heading=h0, goal_heading=h1, moving_obstacles=[early, late]
    )
    assert alone.duration > base.duration
    assert both.duration == pytest.approx(alone.duration, abs=1e-9)
    _checked(both, [early, late])


def test_truncate_agrees_until_its_end():
    m = trajopt.MovingObstacle.from_waypoints(
        [0.5, 2.0, 4.0], [(0, 0), (1, 2), (3, 1)], radius=0.1, growth=0.05, headings=[0, 1, 3]
    )
    for t_end in (0.2, 0.5, 1.3, 3.9, 5.0):
        cut = trajopt.moving.truncate(m, t_end)
        t = np.linspace(-1.0, t_end, 301)
        for a, b in zip(cut.pose_at(t), m.pose_at(t), strict=True):
            np.testing.assert_allclose(a, b, atol=1e-12)
        np.testing.assert_allclose(cut.radius_at(t), m.radius_at(t), atol=1e-12)
        later = cut.pose_at(np.array([t_end, t_end + 7.0]))[0]
        np.testing.assert_allclose(later[0], later[1], atol=0)


def test_shift_clock_is_the_same_prediction():
    m = trajopt.MovingObstacle.from_waypoints(
        [0.5, 2.0, 4.0], [(0, 0), (1, 2), (3, 1)], radius=0.1, growth=0.05, headings=[0, 1, 3]
    )
    for t0 in (0.0, 1.0, 3.0, 4.5, 6.0, 8.0):
        sh = trajopt.moving.shift_clock(m, t0)
        tau = np.linspace(0.0, 8.0, 401)
        for a, b in zip(sh.pose_at(tau), m.pose_at(tau + t0), strict=True):
            np.testing.assert_allclose(a, b, atol=1e-12)
        np.testing.assert_allclose(sh.radius_at(tau), m.radius_at(tau + t0), atol=1e-12)


def test_a_disc_chain_of_two_curves_is_proved_by_its_curves(scene, driven):
    """Two curves with turns in place between, a disc robot: re-timed, clear at every instant.

    The re-timed chain's proof is its curves' certificates (no certificate of the whole); the
    independent references (1 ms samples, brute force) and the whole chain's certificate
    agree that it keeps clear, and the joined summary covers the chain until the last
    prediction ends.
    """
    planner, _ = driven
    a, b, c = scene.start, scene.goal("A"), scene.goal("B")
    first = planner.plan(a, b, goal_heading=0.0)
    second = planner.plan(b, c, start_heading=0.0)
    pieces = tuple(q for p in (first, second) for q in getattr(p, "pieces", (p,)))
    plan = trajopt.TrajectoryChain(pieces, first.robot, {}, None)
    curves = [p for p in pieces if p.single_curve]
    assert len(curves) == 2
    # crossing the second curve's middle when it is there, the first curve's end before
    t2 = float(plan.duration) - 0.5 * float(curves[-1].duration)
    walker = _crossing_at(plan, t2, name="walker", radius=0.15)
    assert dense_min(plan, [walker])[0] < 0.0  # the chain as planned would hit it
    out = trajopt.moving.retime_chain(plan, [walker])
    assert out.duration > plan.duration
    _checked(out, [walker])
    cert = out.stats["moving"]["certificate"]
    assert cert["horizon_s"] >= max(float(out.duration), float(walker.t_last)) - 1e-9


def test_joined_certificates_by_hand():
    """The worst slack and its mover, the latest end on the whole's clock, all intervals."""
    a = {"ok": True, "slack_m": 0.3, "mover": "a", "horizon_s": 4.0, "intervals": 10}
    b = {"ok": True, "slack_m": 0.1, "mover": "b", "horizon_s": 2.5, "intervals": 7}
    got = trajopt.moving.joined_certificates([(0.0, a), (3.0, b)])
    assert got == {"ok": True, "slack_m": 0.1, "mover": "b", "horizon_s": 5.5, "intervals": 17}
    bad = dict(b, ok=False)
    assert not trajopt.moving.joined_certificates([(0.0, a), (3.0, bad)])["ok"]
