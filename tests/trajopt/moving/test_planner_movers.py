"""Tests of trajopt.moving: Planner.plan with moving_obstacles (disc robots, differential and omni).

An empty list gives today's plan bit for bit; a mover crossing the planned path is let pass
(the same path, re-timed, certified and checked on 1 ms samples and by brute force); what is
not covered is refused with a typed error; a moving start is re-timed from its speed.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import trajopt
from tests.trajopt.moving.reference import brute_min, dense_min, slack
from trajopt.errors import BlockedError, InvalidInputError


@pytest.fixture(scope="module")
def planned(scene):
    planner = trajopt.Planner(scene.grid, trajopt.Robot())
    return planner, planner.plan(scene.start, scene.goal("A"))


def _same(a, b):
    for name in ("phase_t", "phase_s", "phase_v", "phase_a", "phase_j"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert a.duration == b.duration
    assert np.array_equal(a.path.curve.c, b.path.curve.c)


def test_no_movers_is_todays_plan(scene, planned):
    planner, base = planned
    for movers in (None, []):
        _same(planner.plan(scene.start, scene.goal("A"), moving_obstacles=movers), base)
    assert "moving" not in base.stats


def _crossing(traj, name="walker", speed=0.4):
    """A mover crossing the planned path at its middle, at the time the robot is there."""
    t_c = 0.5 * traj.duration
    smp = traj.sample(np.array([t_c]))
    p = np.array([smp.x[0], smp.y[0]])
    n = np.array([-math.sin(smp.theta[0]), math.cos(smp.theta[0])])
    return trajopt.MovingObstacle.from_waypoints(
        [t_c - 4.0, t_c + 4.0], [p - 4.0 * speed * n, p + 4.0 * speed * n], radius=0.2, name=name
    )


@pytest.mark.parametrize("drive", [trajopt.Differential(), trajopt.Omni()])
def test_a_crossing_mover_is_let_pass_on_the_same_path(scene, drive):
    planner = trajopt.Planner(scene.grid, trajopt.Robot(drive=drive))
    base = planner.plan(scene.start, scene.goal("A"))
    mover = _crossing(base)
    assert not trajopt.certify_movers(base, [mover]).ok
    out = planner.plan(scene.start, scene.goal("A"), moving_obstacles=[mover], mover_margin=0.05)
    assert np.array_equal(out.path.curve.c, base.path.curve.c)
    assert out.stats["moving"]["certificate"]["ok"]
    assert trajopt.certify_movers(out, [mover], margin=0.05).ok
    assert dense_min(out, [mover], margin=0.05)[0] >= -1e-6
    assert brute_min(out, [mover], margin=0.05) >= -1e-6
    assert out.duration > base.duration


def test_a_mover_parked_on_the_path_blocks_it_and_is_driven_round(scene, planned):
    planner, base = planned
    smp = base.sample(np.array([0.5 * base.duration]))
    parked = trajopt.MovingObstacle.from_waypoints(
        [0.0], [(smp.x[0], smp.y[0])], radius=0.2, name="cart"
    )
    with pytest.raises(BlockedError, match="'cart'"):
        trajopt.retime_for_movers(base, [parked])
    out = planner.plan(scene.start, scene.goal("A"), moving_obstacles=[parked])
    assert out.stats["moving"]["route"] == "rerouted"
    assert dense_min(out, [parked])[0] >= -1e-6


def _speed_from_positions(traj, dt=1e-3):
    """Speed (m/s) between 1 ms samples, from the positions alone, shape (n - 1,)."""
    t = np.arange(0.0, traj.duration, dt)
    smp = traj.sample(t)
    return np.hypot(np.diff(smp.x), np.diff(smp.y)) / dt


@pytest.mark.parametrize("kind", ["crossing", "parked"])
def test_a_moving_start_is_re_timed_from_its_speed(scene, kind):
    """From v_start > 0: a crossing mover is let pass by braking on the path, a parked one
    is driven round after a stop; both keep the start state and the speed limit."""
    planner = trajopt.Planner(scene.grid, trajopt.Robot())
    base = planner.plan(scene.start, scene.goal("A"), v_start=0.2)
    mover = _crossing(base)
    if kind == "parked":
        smp = base.sample(np.array([0.5 * base.duration]))
        mover = trajopt.MovingObstacle.from_waypoints(
            [0.0], [(smp.x[0], smp.y[0])], radius=0.2, name="cart"
        )
    assert dense_min(base, [mover], margin=0.05)[0] < 0.0  # the static plan meets it
    out = planner.plan(
        scene.start, scene.goal("A"), v_start=0.2, moving_obstacles=[mover], mover_margin=0.05
    )
    route = out.stats["moving"]["route"]
    assert route == "retimed" if kind == "crossing" else route.startswith("stopped: ")
    s0 = out.sample(np.array([0.0]))
    assert (s0.x[0], s0.y[0]) == pytest.approx(scene.start, abs=1e-9)
    assert s0.v[0] == pytest.approx(0.2, abs=1e-9) and out.v_start == 0.2
    assert dense_min(out, [mover], margin=0.05)[0] >= -1e-6
    assert brute_min(out, [mover], margin=0.05) >= -1e-6
    assert _speed_from_positions(out).max() <= trajopt.Robot().v_max * (1 + 1e-6)


def test_queries_not_covered_are_refused(scene, planned):
    planner, base = planned
    with pytest.raises(InvalidInputError, match="MovingObstacle"):
        planner.plan(scene.start, scene.goal("A"), moving_obstacles=[(1.0, 2.0)])


def test_the_re_timing_holds_the_speed_limit_zones(scene):
    g = scene.grid
    ny, nx = np.asarray(g.occupied).shape
    half = np.zeros((ny, nx), dtype=int)
    half[:, : nx // 2] = 50  # the left half at 50 % of v_max
    zones = trajopt.SpeedLimits.from_mask(half, g.resolution, tuple(g.origin), type="percentage")
    robot = trajopt.Robot()
    planner = trajopt.Planner(g, robot, speed_limits=zones)
    base = planner.plan(scene.start, scene.goal("A"))
    mover = _crossing(base)
    out = planner.plan(scene.start, scene.goal("A"), moving_obstacles=[mover], mover_margin=0.05)
    assert out.stats["moving"]["plan"] != "as planned"  # re-timed, not the plan as it was
    assert dense_min(out, [mover], margin=0.05)[0] >= -1e-6
    smp = out.sample(np.linspace(0.0, out.duration, 20001))
    xy = np.column_stack([smp.x, smp.y])
    cap = zones.cap_at(xy, robot.v_max)  # each sample's zone, independently of the timing
    assert np.any(cap < robot.v_max) and np.any(np.abs(smp.v) > 0.26)
    assert np.all(np.abs(smp.v) <= cap + 1e-6)


@pytest.mark.parametrize("closer", [0.0, 1e-3])
def test_a_parked_mover_grazing_the_path(scene, planned, closer):
    """Touching at the limit keeps today's plan; a millimetre closer blocks the path."""
    planner, base = planned
    path = base.path
    s = np.linspace(0.0, base.length, 40001)
    pts = np.asarray(path(path.u_at_s(s)))
    # beside the middle of the path, 0.6 m off its normal, on the side its curve turns away from
    i = s.shape[0] // 2
    smp = base.sample(np.array([0.5 * base.duration]))
    normal = np.array([-math.sin(smp.theta[0]), math.cos(smp.theta[0])])
    side = -1.0 if smp.kappa[0] > 0 else 1.0
    p = pts[i] + side * 0.6 * normal
    d = np.hypot(*(pts - p).T)
    j = int(np.argmin(d))
    from scipy.optimize import minimize_scalar

    lo, hi = s[max(j - 1, 0)], s[min(j + 1, s.shape[0] - 1)]
    res = minimize_scalar(
        lambda x: float(np.hypot(*(np.asarray(path(path.u_at_s(x))) - p))),
        bounds=(lo, hi),
        method="bounded",
        options={"xatol": 1e-12},
    )
    radius = float(res.fun) - base.robot.radius + closer
    mover = trajopt.MovingObstacle.from_waypoints([0.0], [p], radius=radius, name="post")
    assert brute_min(base, [mover]) == pytest.approx(-closer, abs=1e-7)
    if closer == 0.0:
        out = planner.plan(scene.start, scene.goal("A"), moving_obstacles=[mover])
        _same(out, base)
        assert out.stats["moving"]["plan"] == "as planned"
        assert -1e-6 <= out.stats["moving"]["certificate"]["slack_m"] <= 1e-7
    else:
        with pytest.raises(BlockedError, match="'post'"):
            trajopt.retime_for_movers(base, [mover])
        out = planner.plan(scene.start, scene.goal("A"), moving_obstacles=[mover])
        assert out.stats["moving"]["route"] == "rerouted"
        assert dense_min(out, [mover])[0] >= -1e-6


@pytest.mark.parametrize("headings", [{"goal_heading": 3.0}, {"start_heading": 3.0}])
def test_turns_in_place_are_rests_of_the_re_timed_chain(scene, planned, headings):
    planner, _ = planned
    base = planner.plan(scene.start, scene.goal("A"), **headings)
    assert not base.single_curve  # a turn in place at one end
    curve = next(p for p in base.pieces if p.single_curve)
    lead = sum(p.duration for p in base.pieces[: base.pieces.index(curve)])
    # the mover crosses the curve's middle when the robot is there, on the chain's clock
    mover = _crossing(curve)
    mover = trajopt.MovingObstacle.from_waypoints(
        mover.times + lead, mover.positions, radius=mover.radius, name="walker"
    )
    bad = trajopt.certify_movers(base, [mover])  # the chain itself: its turn is a rest
    assert bad.verdict == "violated" and slack(base, mover, bad.witness_t)[0] < 0.0
    out = planner.plan(scene.start, scene.goal("A"), moving_obstacles=[mover], **headings)
    assert trajopt.certify_movers(out, [mover]).ok
    assert [type(p).__name__ for p in out.pieces] == [type(p).__name__ for p in base.pieces]
    assert out.duration > base.duration and out.stats["moving"]["certificate"]["ok"]
    # the chain's own samples, independently of the certificate: every 1 ms, and brute force
    assert dense_min(out, [mover])[0] >= -1e-6
    assert brute_min(out, [mover]) >= -1e-6
    t = np.arange(0.0, out.duration, 1e-3)
    smp = out.sample(t)
    assert np.max(np.abs(np.diff(smp.v))) < 1e-3 and np.max(np.abs(np.diff(smp.theta))) < 1e-2


@pytest.fixture(scope="module")
def chain(scene, planned):
    planner, _ = planned
    return planner.plan(scene.start, scene.goal("A"), start_heading=3.0, goal_heading=3.0)


@settings(max_examples=15, deadline=None, suppress_health_check=list(HealthCheck))
@given(
    st.floats(0.0, 1.0),
    st.floats(-math.pi, math.pi),
    st.floats(0.1, 1.2),
    st.floats(0.05, 0.4),
    st.floats(-0.4, 0.4),
)
def test_the_chain_certificate_against_dense_samples(chain, frac, angle, speed, radius, miss):
    """Random straight movers passing a random point of a turn-drive-turn chain."""
    assert [p.turning for p in chain.pieces] == [True, False, True]
    t_c = frac * chain.duration
    smp = chain.sample(np.array([t_c]))
    v = speed * np.array([math.cos(angle), math.sin(angle)])
    p = np.array([smp.x[0], smp.y[0]]) + miss * np.array([-v[1], v[0]]) / speed
    mover = trajopt.MovingObstacle.from_waypoints(
        [t_c - 5.0, t_c + 5.0], [p - 5.0 * v, p + 5.0 * v], radius=radius
    )
    cert = trajopt.certify_movers(chain, [mover])
    truth = min(dense_min(chain, [mover], dt=2e-3)[0], brute_min(chain, [mover]))
    if cert.ok:
        assert truth >= -1e-6
    else:
        assert slack(chain, mover, cert.witness_t)[0] < -0.5e-6
    if truth > 1e-4:
        assert cert.ok
