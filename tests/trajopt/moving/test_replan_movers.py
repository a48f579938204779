"""Tests of trajopt.moving through Planner.replan: re-timing the spliced trajectory for new predictions, or stopping and re-routing.

References: the old trajectory's own state at the splice (continuity), the re-plan without the
keyword (an empty list is identical; the brake of a chain sampled against the re-plan without
movers), and an independent slack computed here on the movers' own clock (the re-plan's
samples at ``tau`` against each mover at ``ts + tau``, its radius from its fields) on 1 ms
samples, plus reference.py's dense samples, brute force and ``check_trajectory`` (1 ms
samples with the Lipschitz bound, the static map's clearance) on the shifted movers. On a
hand-built loop of two corridors, a re-plan whose kept rest is proved blocked stops and
re-routes from the stop with the re-route's leg as its only plan (hand check: the cart stands
on the rest before the robot, at most ``v_max`` from the splice, can be past it), and is
continuous at the splice and at the stop; the static plan from the stop is still tried when
no candidate works (its reference: the plan among the movers from the stop); the quick proofs
from a moving start against a hand-derived reach and against certified re-timings.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import trajopt
import trajopt.planning
from tests.trajopt.moving.reference import brute_min, check_trajectory, dense_min
from tests.trajopt.moving.scenes import RES, loop_occupancy
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


def _loop():
    """Two 1 m corridors (y = 1 and y = 4) joined at both ends, a niche at x = 6 (5 cm cells)."""
    from astar.grid import OccupancyGrid

    return OccupancyGrid(loop_occupancy(), RES, (0.0, 0.0))


@pytest.fixture(scope="module")
def loop_drive():
    grid = _loop()
    planner = trajopt.Planner(grid, trajopt.Robot())
    traj = planner.plan((1.0, 1.0), (11.0, 1.0))
    assert np.max(traj.sample(np.linspace(0, traj.duration, 200)).y) < 1.5  # the short way
    return grid, planner, traj


def _mover_planning():
    """The module of :func:`trajopt.planning.plan_from_stop` (its names are patched here)."""
    import sys

    return sys.modules[trajopt.planning.plan_from_stop.__module__]


def _count_plans(monkeypatch):
    """Count the static plans the planner's mover code asks for (re-route legs included)."""
    where = _mover_planning()
    calls = []
    real = where.run_query

    def counted(*args, **kwargs):
        calls.append(args[-1])
        return real(*args, **kwargs)

    monkeypatch.setattr(where, "run_query", counted)
    return calls


def test_a_cart_parked_ahead_re_routes_from_the_stop_without_a_second_static_plan(
    loop_drive, monkeypatch
):
    """The kept rest is proved blocked from the moving state; the stop follows that path, so the
    re-route's first candidate is planned at once (one plan, not the static plan first)."""
    grid, planner, traj = loop_drive
    t, ts = 2.0, 2.0 + LATENCY
    cart = trajopt.MovingObstacle.from_waypoints(
        [0.0, 3.0], [(6.0, 2.0), (6.0, 1.0)], radius=0.25, name="cart"
    )
    # by hand: the cart stands on the rest (y = 1) from t = 3, and the robot, at most v_max
    # from the splice on, is still short of it then: no timing along this path gets past
    at = traj.state_at(ts)
    rob = traj.robot
    reach = at.x + rob.v_max * (3.0 - ts)
    assert reach < 6.0 - 0.25 - rob.radius and abs(at.y - 1.0) < 0.05
    calls = _count_plans(monkeypatch)
    new = planner.replan(traj, t, latency=LATENCY, moving_obstacles=[cart])
    moving = new.stats["moving"]
    assert moving["route"] == "stopped: rerouted" and "'cart'" in moving["blocked"]
    assert "stands on the path" in moving["blocked"]  # the quick proof, not a failed search
    assert [c["what"] for c in moving["reroute"]] == ["around every mover's final place"]
    assert len(calls) == 1  # the re-route's leg only: no static plan from the stop
    _check_splice_and_stop(traj, new, ts, [cart], grid)


def _check_splice_and_stop(traj, new, ts, movers, grid):
    """Continuity at the splice and at the stop; the independent checks on the movers' clock."""
    _splice_equal(traj, new, ts)
    h = new.stats["moving"]["head_s"]
    a, b = new.sample(np.array([h - 1e-9])), new.sample(np.array([h + 1e-9]))
    assert math.hypot(a.x[0] - b.x[0], a.y[0] - b.y[0]) < 1e-6
    assert abs(math.remainder(a.theta[0] - b.theta[0], 2 * math.pi)) < 1e-6
    assert abs(a.v[0]) < 1e-6 and abs(b.v[0]) < 1e-6
    assert abs(a.a[0]) < 1e-6 and abs(b.a[0]) < 1e-6
    smp = new.sample(np.arange(0.0, new.duration, 1e-3))
    rob = new.robot
    assert np.max(np.abs(np.diff(smp.v))) < rob.a_max * 1e-3 * 1.01  # no jump in speed
    assert np.max(np.abs(np.diff(smp.a))) < rob.j_max * 1e-3 * 1.01  # nor in acceleration
    step = np.hypot(np.diff(smp.x), np.diff(smp.y))
    assert np.max(step) <= rob.v_max * 1e-3 * 1.01  # nor in position
    shifted = [trajopt.moving.shift_clock(m, ts) for m in movers]
    assert new.stats["moving"]["certificate"]["ok"]
    assert _slack_on_movers_clock(new, movers, ts) >= -1e-6
    assert dense_min(new, shifted)[0] >= -1e-6
    assert brute_min(new, shifted) >= -1e-6
    check = check_trajectory(new, shifted, grid=grid)
    assert check.ok and check.static_slack >= -1e-6


def test_a_walker_head_on_re_routes_from_the_stop(loop_drive):
    """A walker comes down the short corridor towards the robot (from t = 6 s) and stays at its
    west end: the robot stops, waits in the niche while it passes, then drives on. The way
    back round the long corridor (the detour round where it may meet the walker) is kept
    aside as too long, and the wait arrives sooner."""
    grid, planner, traj = loop_drive
    t, ts = 4.0, 4.0 + LATENCY
    walker = trajopt.MovingObstacle.from_waypoints(
        [6.0, 26.0], [(11.0, 1.0), (1.0, 1.0)], radius=0.2, name="walker"
    )
    new = planner.replan(traj, t, latency=LATENCY, moving_obstacles=[walker], mover_margin=0.02)
    moving = new.stats["moving"]
    assert moving["route"] == "stopped: waited" and "'walker'" in moving["blocked"]
    assert "no way past" in moving["blocked"]  # proved on the kept rest from the moving state
    first = moving["reroute"][0]
    assert "may meet" in first["what"] and first["result"].startswith("ok, kept")
    end = new.state_at(new.duration)
    assert math.hypot(end.x - 11.0, end.y - 1.0) < 1e-9
    _check_splice_and_stop(traj, new, ts, [walker], grid)


def test_the_static_plan_from_the_stop_is_still_tried_when_no_candidate_works(
    loop_drive, monkeypatch
):
    """The static plan from the stop is a new search: it may leave the followed path, so it is
    tried last (re-timed) when every re-route candidate fails, and then equals the plan among
    the movers from the stop that re-times it (the reference)."""
    from trajopt.planning import PlanRequest
    from trajopt.replan import Along

    grid, planner, traj = loop_drive
    where = _mover_planning()

    def nothing(*args, **kwargs):
        raise BlockedError("no candidate (test)", mover="x", t=0.0)

    monkeypatch.setattr(where, "_reroute", nothing)
    start, heading = (2.0, 1.0), 0.0
    passer = trajopt.MovingObstacle.from_waypoints(
        [0.0, 2.0], [(6.0, 2.0), (6.0, 2.2)], radius=0.2, name="passer"
    )  # stays in the niche: a re-timing of the way along y = 1 passes it
    along = Along(BlockedError("claimed (test)", mover="passer", t=0.0), np.zeros((1, 2)))
    request = PlanRequest(start, (11.0, 1.0), start_heading=heading)
    out = where.plan_from_stop((passer,), 0.0, planner.options, planner.caches, request, along)
    ref = planner.plan(start, (11.0, 1.0), start_heading=heading, moving_obstacles=[passer])
    assert out.stats["moving"]["route"] == "retimed" == ref.stats["moving"]["route"]
    tt = np.linspace(0.0, ref.duration, 300)
    a, b = out.sample(tt), ref.sample(tt)
    for name in ("x", "y", "theta", "v"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    # and with nothing that works either, the reasons of both are given
    blocker = trajopt.MovingObstacle.from_waypoints([0.0], [(6.0, 1.0)], radius=0.2, name="c")
    with pytest.raises(BlockedError, match="the static plan from the stop"):
        where.plan_from_stop((blocker,), 0.0, planner.options, planner.caches, request, along)
    # but a mover standing on the goal for ever ends every plan: no static plan is tried
    on_goal = trajopt.MovingObstacle.from_waypoints([0.0], [(11.0, 1.0)], radius=0.2, name="g")
    calls = _count_plans(monkeypatch)
    with pytest.raises(BlockedError, match="no candidate") as info:
        where.plan_from_stop((on_goal,), 0.0, planner.options, planner.caches, request, along)
    assert "static plan" not in str(info.value) and not calls


def test_parked_proof_from_a_moving_start_uses_its_speed():
    """Hand derivation: from rest the robot covers at most ``a_max t^2 / 2`` by ``t_stop``; from
    a cruise at ``v0`` it can be ``v0 t_stop`` along. A cart that parks between the two (a limit
    clear of both) may be passed from the cruise: no proof; from rest it is proved blocking."""
    from astar.grid import OccupancyGrid

    occ = np.ones((40, 400), dtype=bool)
    occ[10:30, 10:390] = False
    grid = OccupancyGrid(occ, RES, (0.0, 0.0))
    planner = trajopt.Planner(grid, trajopt.Robot(a_max=0.1))
    traj = planner.plan((1.0, 1.0), (19.0, 1.0))
    rest = planner.replan(traj, 8.0, latency=0.0)  # cruising by then
    rob = rest.robot
    v0 = float(rest.v_start)
    assert v0 > 0.45 and abs(rest.state_at(0.0).a) < 1e-9
    t_stop = 4.0
    from_rest = 0.5 * rob.a_max * (t_stop + 0.01) ** 2  # v <= a_max t from rest (1 ms sums)
    limit = rob.inscribed_radius + 0.1  # the cart's radius
    assert from_rest + limit + 0.1 < v0 * t_stop - limit - 0.1
    s_park = v0 * t_stop - limit - 0.1  # the cruise is past it (by more than the limit) then
    x0 = rest.state_at(0.0).x
    cart = trajopt.MovingObstacle.from_waypoints(
        [0.0, t_stop], [(x0 + s_park, 1.8), (x0 + s_park, 1.0)], radius=0.1, name="cart"
    )
    assert trajopt.moving.parked_on_path(rest, [cart]) is None
    # the same path from rest: its reach by t_stop is short of the cart by more than the limit
    from_stop = planner.plan((x0, 1.0), (19.0, 1.0))
    blocked = trajopt.moving.parked_on_path(from_stop, [cart])
    assert blocked is not None and blocked.mover == "cart" and blocked.t == t_stop


def test_quick_proofs_from_a_moving_start_never_refuse_a_certified_re_timing(driven):
    """Soundness on seeded random movers about the kept rest (moving at the splice): when the
    re-timing from the moving state finds a motion the certificate and 1 ms samples pass, the
    proofs must not call the path blocked."""
    planner, traj = driven
    rest = planner.replan(traj, 1.0, latency=0.0)
    assert rest.v_start > 0.0
    rng = np.random.default_rng(7)
    found = claimed = 0
    for _ in range(30):
        smp = rest.sample(np.array([rng.uniform(0.3, 0.9) * rest.duration]))
        p = np.array([smp.x[0], smp.y[0]])
        heading = rng.uniform(-math.pi, math.pi)
        d = np.array([math.cos(heading), math.sin(heading)])
        t_c, speed = rng.uniform(1.0, 8.0), rng.uniform(0.2, 0.6)
        stop = rng.random() < 0.4  # some stop on the path
        times = [t_c - 3.0, t_c] if stop else [t_c - 3.0, t_c + 3.0]
        pts = [p - 3.0 * speed * d, p] if stop else [p - 3.0 * speed * d, p + 3.0 * speed * d]
        mover = trajopt.MovingObstacle.from_waypoints(times, pts, radius=0.2, name="m")
        proof = trajopt.moving.parked_on_path(rest, [mover]) or trajopt.moving.no_way_past(
            rest, [mover]
        )
        claimed += proof is not None
        try:
            timed = trajopt.retime_for_movers(rest, [mover])
        except (BlockedError, trajopt.errors.InvalidInputError):
            continue
        found += 1
        assert dense_min(timed, [mover])[0] >= -1e-6
        assert proof is None, proof
    assert found >= 5 and claimed >= 3, (found, claimed)  # both kinds met


def test_a_mover_over_the_robot_at_the_splice_is_refused_not_proved(driven):
    """A cart parked where the robot is at the splice: bad input (InvalidInputError), as the
    re-timing says, not a proof that the path is blocked."""
    planner, traj = driven
    ts = 1.0 + LATENCY
    at = traj.state_at(ts)
    cart = trajopt.MovingObstacle.from_waypoints([0.0], [(at.x, at.y)], radius=0.2, name="cart")
    assert trajopt.moving.parked_on_path(
        planner.replan(traj, 1.0, latency=LATENCY), [trajopt.moving.shift_clock(cart, ts)]
    )  # the proof alone would call it blocked
    with pytest.raises(trajopt.errors.InvalidInputError, match="overlaps"):
        planner.replan(traj, 1.0, latency=LATENCY, moving_obstacles=[cart])
