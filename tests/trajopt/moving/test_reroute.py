"""Tests of trajopt.moving.reroute through Planner.plan: another route, or a wait at a safe place.

Hand-built maps (5 cm cells): a corridor with a side bay (a head-on mover: the robot, differential or
omni with its own orientation, must yield in the bay), a loop of two corridors (a cart stops on the short one: the robot goes
round by the long one) and a plain corridor (a cart drives into it and stops: no way,
BlockedError naming the cart); the order of the candidates when the blocked path is given. Every returned plan is checked by the independent references (1 ms samples, brute
force) and its samples against the map's occupied squares.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import trajopt
import trajopt.moving
from astar.grid import OccupancyGrid
from tests.trajopt.moving.reference import (
    brute_min,
    check_motion,
    check_trajectory,
    dense_min,
    positions,
    slack_at,
)
from tests.trajopt.moving.scenes import RES, loop_occupancy, rooms_occupancy
from trajopt.errors import BlockedError
from trajopt.moving._swept_kernel import square_segment_distance


def _grid(shape, rooms):
    return OccupancyGrid(rooms_occupancy(shape, rooms), RES, (0.0, 0.0))


def _static_clearance(traj, grid, dt=0.02):
    """Smallest distance (m) from the sampled centre to an occupied cell's square."""
    t = np.append(np.arange(0.0, traj.duration, dt), traj.duration)
    smp = traj.sample(t)
    p = np.stack([smp.x, smp.y], axis=1)
    occ = np.asarray(grid.occupied)
    free = ~occ
    # occupied cells with a free 4-neighbour: the squares a free point is closest to
    edge = occ & (
        np.roll(free, 1, 0) | np.roll(free, -1, 0) | np.roll(free, 1, 1) | np.roll(free, -1, 1)
    )
    iy, ix = np.nonzero(edge)
    lo = np.stack([ix, iy], axis=1) * RES
    best = np.inf
    for a in range(0, p.shape[0], 200):
        q = p[a : a + 200, None, :]
        d = np.maximum(np.maximum(lo[None] - q, q - (lo[None] + RES)), 0.0)
        best = min(best, float(np.min(np.hypot(d[..., 0], d[..., 1]))))
    return best


def _check(out, movers, grid, margin):
    assert trajopt.certify_movers(out, movers, margin=margin).ok
    assert out.stats["moving"]["certificate"]["ok"]
    assert dense_min(out, movers, margin=margin)[0] >= -1e-6
    assert brute_min(out, movers, margin=margin) >= -1e-6
    assert _static_clearance(out, grid) >= out.robot.radius - 1e-6


@pytest.fixture(scope="module")
def bay():
    """A 1 m corridor along y = 2 with a bay on its north side at x = 5.5-6.5."""
    return _grid((80, 240), [(0.5, 11.5, 1.5, 2.5), (5.5, 6.5, 2.5, 3.6)])


@pytest.mark.parametrize(
    ("drive", "headings"),
    [("differential", {}), ("omni", {"start_heading": -0.5, "goal_heading": 1.0})],
)
def test_head_on_in_a_corridor_yields_in_the_bay(bay, drive, headings):
    grid = bay
    planner = trajopt.Planner(grid, trajopt.Robot(drive=drive))
    start, goal = (1.0, 2.0), (11.0, 2.0)
    base = planner.plan(start, goal)
    forklift = trajopt.MovingObstacle.constant_velocity(
        (13.0, 2.0), (-0.5, 0.0), radius=0.2, horizon=30.0, name="forklift"
    )
    with pytest.raises(BlockedError):  # no re-timing along the corridor lets it pass
        trajopt.retime_for_movers(base, [forklift], margin=0.02)
    out = planner.plan(start, goal, moving_obstacles=[forklift], mover_margin=0.02, **headings)
    assert out.stats["moving"]["route"] == "waited"
    if headings:  # an omni base's orientation: its own, from the start's to the goal's
        assert all(p.own_orientation for p in out.pieces)
        ends = out.sample(np.array([0.0, out.duration])).theta
        np.testing.assert_allclose(ends, [-0.5, 1.0], atol=1e-9)
        assert out.stats["moving"]["certificate"]["ok"]
        assert dense_min(out, [forklift], margin=0.02)[0] >= -1e-6
        assert brute_min(out, [forklift], margin=0.02) >= -1e-6
        assert _static_clearance(out, grid) >= out.robot.radius - 1e-6
    else:
        _check(out, [forklift], grid, 0.02)
    # the robot stands aside at the bay (north of the corridor) when the forklift passes it;
    # it leaves as soon as the forklift lets it, so then it may already be on its way out
    t_pass = (13.0 - 6.0) / 0.5
    smp = out.sample(np.array([t_pass]))
    assert smp.y[0] > 2.0 + 0.2 and 5.5 < smp.x[0] < 6.5
    end = out.sample(np.array([out.duration]))
    assert np.hypot(end.x[0] - goal[0], end.y[0] - goal[1]) < 1e-6


def test_detours_that_keep_clear_of_the_blocked_path_go_last(bay):
    """A forklift that ends far behind the start: its final place leaves the corridor open, so
    with the blocked path given that detour is tried after those round the forklift's track;
    without it the order is the module's (every plan fails here: only the order is read)."""
    grid = bay
    robot = trajopt.Robot()
    forklift = trajopt.MovingObstacle.from_waypoints(
        [0.0, 15.0, 30.0], [(13.0, 2.0), (5.5, 2.0), (0.8, 1.8)], radius=0.2, name="forklift"
    )
    p0, p1 = np.array([3.0, 2.0]), np.array([11.0, 2.0])
    path = np.stack([np.linspace(3.0, 11.0, 161), np.full(161, 2.0)], axis=1)
    blocked = BlockedError("blocked (test)", mover="forklift", t=5.0)
    asked = []

    def plan_leg(marked, a, b, heading, goal_heading=None, start_steer=0.0):
        asked.append(np.asarray(marked.occupied).sum())
        raise trajopt.errors.NoPathError("no plan (test)")

    def order(**kw):
        with pytest.raises(BlockedError) as info:
            trajopt.moving.reroute(
                p0, p1, robot, [forklift], 0.02, blocked, grid=grid,
                free=lambda: np.zeros(grid.shape, dtype=bool), plan_leg=plan_leg, **kw,
            )  # fmt: skip
        text = str(info.value)
        names = ["around every mover's final place", "around 'forklift':", "from t = 5.000 s"]
        return sorted(names, key=text.index)

    assert order() == [
        "around every mover's final place",
        "around 'forklift':",
        "from t = 5.000 s",
    ]
    # by hand: the final place (0.8, 1.8) is 2.2 m behind the start, the path runs east of it
    assert math.dist((0.8, 1.8), p0) > robot.radius + 0.2 + 0.02 + robot.radius + 3 * RES
    assert order(path=path) == [
        "around 'forklift':",
        "from t = 5.000 s",
        "around every mover's final place",
    ]


def test_a_car_waits_at_a_safe_place_with_a_heading():
    """A car (no turn in place) meets a forklift head-on in a corridor with a side room: it
    swerves into the room where they meet (the detour round where it may meet the forklift)
    or pulls aside facing on, waits, and drives on (the two legs join in position, heading
    and steering); either way it is out of the forklift's lane when they pass."""
    grid = _grid((120, 240), [(0.5, 11.5, 1.4, 2.6), (4.5, 8.5, 2.6, 5.0)])
    robot = trajopt.Robot(
        drive="ackermann", min_turning_radius=0.6, radius=0.2, wheelbase=0.3, steer_rate_max=1.0
    )
    planner = trajopt.Planner(grid, robot)
    start, goal = (1.0, 2.0), (11.0, 2.0)
    forklift = trajopt.MovingObstacle.constant_velocity(
        (13.0, 2.0), (-0.5, 0.0), radius=0.2, horizon=30.0, name="forklift"
    )
    out = planner.plan(
        start, goal, start_heading=0.0, goal_heading=0.0, moving_obstacles=[forklift],
        mover_margin=0.02,
    )  # fmt: skip
    route = out.stats["moving"]["route"]
    assert route in ("rerouted", "waited")
    last = out.stats["moving"]["reroute"][-1]
    assert last["result"] == "ok" and ("heading" in last["what"]) == (route == "waited")
    _check(out, [forklift], grid, 0.02)
    dt = 1e-3
    smp = out.sample(np.append(np.arange(0.0, out.duration, dt), out.duration))
    step = np.hypot(np.diff(smp.x), np.diff(smp.y))
    assert np.max(step) <= robot.v_max * dt * (1 + 1e-6) + 1e-9  # no jump at the join
    assert np.max(np.abs(np.diff(np.unwrap(smp.theta)))) < 0.01  # |omega| dt, no jump
    assert np.max(np.abs(np.diff(smp.steer))) <= 1.0 * dt + 1e-9  # steer_rate_max dt
    for k, (p, h) in ((0, (start, 0.0)), (-1, (goal, 0.0))):
        assert math.dist((smp.x[k], smp.y[k]), p) < 1e-6
        assert abs(math.remainder(smp.theta[k] - h, 2 * math.pi)) < 1e-6
    # when they pass (the forklift at the car's x) the car is out of the forklift's lane
    # (y <= 2.2, plus the car's radius and the margin)
    t = smp.t
    fx = forklift.position_at(t)[:, 0]
    k = int(np.argmin(np.abs(fx - smp.x)))
    assert smp.y[k] > 2.0 + 0.2 + 0.2 + 0.02
    if route == "waited":  # it stood still on the way, aside
        rest = (smp.v == 0.0) & (t > 1.0) & (t < out.duration - 1.0)
        assert rest.any() and np.all(smp.y[rest] > 2.0 + 0.2 + 0.2 + 0.02)


def test_car_headings_face_on_then_along_the_way_in():
    place, p0, p1 = np.array([0.0, 0.0]), np.array([-1.0, 0.0]), np.array([0.0, 2.0])
    assert trajopt.moving.car_headings(place, p0, p1) == pytest.approx([math.pi / 2, 0.0])
    # both agree (on the straight line from the start to the goal): one heading
    assert trajopt.moving.car_headings(place, p0, np.array([3.0, 0.0])) == [0.0]


@pytest.fixture(scope="module")
def loop():
    """Two 1 m corridors (y = 1 and y = 4) joined at both ends, and a niche at x = 6."""
    grid = OccupancyGrid(loop_occupancy(), RES, (0.0, 0.0))
    return grid, trajopt.Planner(grid, trajopt.Robot())


def test_a_cart_that_stops_on_the_path_is_driven_round(loop):
    grid, planner = loop
    start, goal = (1.0, 1.0), (11.0, 1.0)
    base = planner.plan(start, goal)
    assert np.max(base.sample(np.linspace(0, base.duration, 200)).y) < 1.5  # the short way
    cart = trajopt.MovingObstacle.from_waypoints(
        [0.0, 3.0], [(6.0, 2.0), (6.0, 1.0)], radius=0.25, name="cart"
    )
    out = planner.plan(start, goal, moving_obstacles=[cart], mover_margin=0.05)
    assert out.stats["moving"]["route"] == "rerouted"
    assert out.stats["moving"]["reroute"][-1]["result"] == "ok"
    _check(out, [cart], grid, 0.05)
    assert np.max(out.sample(np.linspace(0, out.duration, 400)).y) > 3.5  # the long way
    # the cart stays: once it stands, the robot keeps its distance at every later instant too
    assert out.stats["moving"]["certificate"]["horizon_s"] >= 3.0


def test_a_cart_that_stops_in_the_only_corridor_blocks():
    grid = _grid((60, 240), [(0.5, 11.5, 1.0, 2.0)])
    planner = trajopt.Planner(grid, trajopt.Robot())
    cart = trajopt.MovingObstacle.from_waypoints(
        [0.0, 4.0], [(9.0, 1.5), (6.0, 1.5)], radius=0.25, name="cart"
    )
    with pytest.raises(BlockedError, match="'cart'") as info:
        planner.plan((1.0, 1.5), (11.0, 1.5), moving_obstacles=[cart])
    assert info.value.mover == "cart" and info.value.t >= 0.0
    assert "no re-route either" in str(info.value)


def test_a_walker_that_ends_on_the_goal_blocks_every_route(loop):
    """Head-on in the short corridor, then back to the goal and standing there: the long way
    round ends where it stands too, so no route is planned."""
    _, planner = loop
    start, goal = (1.0, 1.0), (11.0, 1.0)
    walker = trajopt.MovingObstacle.from_waypoints(
        [0.0, 8.0, 16.0], [(11.0, 1.0), (3.0, 1.0), (11.0, 1.0)], radius=0.2, name="walker"
    )
    with pytest.raises(BlockedError, match="stands on the goal") as info:
        planner.plan(start, goal, moving_obstacles=[walker], mover_margin=0.02)
    assert info.value.mover == "walker"
    # by hand: the robot standing at the goal and the walker's last place overlap
    assert math.dist(goal, walker.positions[-1]) < trajopt.Robot().radius + 0.2
    beside = trajopt.MovingObstacle.from_waypoints([0.0], [(11.0, 1.6)], radius=0.2)
    r = trajopt.Robot().inscribed_radius + 0.02
    assert trajopt.moving.goal_taken([beside], np.array(goal), r) is None  # 0.6 > 0.185 + 0.2
    assert trajopt.moving.goal_taken([walker], np.array(goal), r) is walker


def test_a_mover_that_has_passed_needs_no_reroute(loop):
    """Re-timing comes first: a mover the robot can wait for is waited for on the same path."""
    _, planner = loop
    start, goal = (1.0, 1.0), (11.0, 1.0)
    base = planner.plan(start, goal)
    cart = trajopt.MovingObstacle.from_waypoints(
        [0.0, 6.0, 9.0], [(6.0, 2.0), (6.0, 1.0), (6.0, 2.0)], radius=0.25, name="cart"
    )
    out = planner.plan(start, goal, moving_obstacles=[cart])
    assert out.stats["moving"]["route"] == "retimed"
    assert np.array_equal(out.path.curve.c, base.path.curve.c)


def _after_timing(planner, start, goal, movers, margin):
    """The plan among movers with every proof on the timed static plan (no early proof)."""
    from trajopt.planning import PlanRequest, plan_for_movers, run_query

    request = PlanRequest(start, goal)
    static = run_query(planner.options, planner.caches, request)
    return plan_for_movers(static, tuple(movers), margin, planner.options, planner.caches, request)


def _same_plan(a, b):
    assert type(a) is type(b)
    assert a.stats["moving"]["route"] == b.stats["moving"]["route"]
    assert a.stats["moving"]["plan"] == b.stats["moving"]["plan"]
    assert a.duration == b.duration
    t = np.linspace(0.0, a.duration, 301)
    sa, sb = a.sample(t), b.sample(t)
    for f in ("x", "y", "theta", "v"):
        assert np.array_equal(getattr(sa, f), getattr(sb, f)), f


@pytest.mark.parametrize("kind", ["stops", "head-on", "passes"])
def test_proofs_before_the_timing_give_the_plan_of_the_proofs_after_it(loop, kind):
    """A blocked static curve is re-routed without its timing, to the same plan as before."""
    grid, planner = loop
    start, goal = (1.0, 1.0), (11.0, 1.0)
    planner.plan(start, goal)  # the caches built, as for both plans below
    movers = {
        "stops": [
            trajopt.MovingObstacle.from_waypoints(
                [0.0, 3.0], [(6.0, 2.0), (6.0, 1.0)], radius=0.25, name="cart"
            )
        ],
        "head-on": [
            trajopt.MovingObstacle.from_waypoints(
                [0.0, 20.0], [(11.0, 1.0), (1.0, 1.0)], radius=0.2, name="walker"
            )
        ],
        "passes": [
            trajopt.MovingObstacle.from_waypoints(
                [0.0, 6.0, 9.0], [(6.0, 2.0), (6.0, 1.0), (6.0, 2.0)], radius=0.25, name="cart"
            )
        ],
    }[kind]
    early = planner.plan(start, goal, moving_obstacles=movers, mover_margin=0.02)
    late = _after_timing(planner, start, goal, movers, 0.02)
    _same_plan(early, late)
    if kind == "passes":
        assert early.stats["moving"]["route"] == "retimed"
        assert "blocked_before_timing" not in early.stats["moving"]
    else:  # the screen of the grid path found it: neither fitted nor timed
        assert early.stats["moving"]["route"] == "rerouted"
        assert early.stats["moving"]["blocked_before_timing"] is True
        assert early.stats["moving"]["blocked_on_grid_path"] is True
        assert late.stats["moving"]["blocked_before_timing"] is False
        _check(early, movers, grid, 0.02)


def test_check_grid_path_sees_the_search_grid_path(loop):
    """``PlanRequest.check_grid_path``: called once, before the fit, on the grid path's cell
    centres with the exact ends in place of their cells'."""
    from trajopt.planning import PlanRequest, run_query

    grid, planner = loop
    start, goal = (1.01, 0.98), (11.0, 1.02)
    seen = []
    request = PlanRequest(start, goal, check_grid_path=seen.append)
    out = run_query(planner.options, planner.caches, request)
    assert len(seen) == 1 and request == PlanRequest(start, goal)
    cells = np.asarray(out.steps.grid_path.cells)
    centres = (cells + 0.5) * RES  # origin (0, 0)
    assert seen[0].shape == centres.shape
    assert np.allclose(seen[0][1:-1], centres[1:-1], atol=1e-12)
    assert np.array_equal(seen[0][0], start) and np.array_equal(seen[0][-1], goal)
    order = []
    request = PlanRequest(
        start, goal, check_grid_path=lambda p: order.append("grid"), check_curve=order.append
    )
    run_query(planner.options, planner.caches, request)
    assert order[0] == "grid" and len(order) == 2

    class Stop(Exception):
        pass

    def refuse(points):
        raise Stop

    with pytest.raises(Stop):
        run_query(planner.options, planner.caches, PlanRequest(start, goal, check_grid_path=refuse))


def test_the_grid_path_screen_faces_along_the_path_not_its_first_step():
    """The screen's robot faces the grid path's point ``GRID_HEADING_M`` along it (here worked
    out by hand), not its first step: a grid path whose first step goes north before it runs
    east, a walker coming west along it to the start; facing the first step, the head-on
    screen misses the walker (it comes across that heading), facing along the path it sees
    it, and the sweep on the grid path then finds it blocked."""
    import types

    import trajopt.planning._moving as among

    xs = np.arange(1.05, 5.0 + 1e-9, 0.05)
    points = np.vstack([[1.0, 1.0], [1.0, 1.05], np.stack([xs, np.full_like(xs, 1.05)], axis=1)])
    robot = trajopt.Robot()
    plan = among._GridCurve(among._Polyline(points), robot)
    at = plan.sample(np.zeros(1))
    assert among.GRID_HEADING_M == 0.25
    # 0.05 m north, then 0.20 m east: the point (1.20, 1.05)
    assert math.isclose(float(at.theta[0]), math.atan2(0.05, 0.20), abs_tol=1e-12)
    assert (float(at.x[0]), float(at.y[0])) == (1.0, 1.0)
    walker = trajopt.MovingObstacle.from_waypoints(
        [0.0, 8.0], [(5.0, 1.05), (1.0, 1.05)], radius=0.2, name="walker"
    )
    north = types.SimpleNamespace(
        path=plan.path, robot=robot, own_orientation=False, single_curve=True,
        length=plan.length, sample=lambda t: types.SimpleNamespace(
            x=at.x, y=at.y, theta=np.array([math.pi / 2])
        ),
    )  # fmt: skip
    assert not trajopt.moving.meets_head_on(north, [walker], 0.02)
    assert trajopt.moving.meets_head_on(plan, [walker], 0.02)
    with pytest.raises(among._GridBlocked) as found:
        among._GridScreen((walker,), 0.02, robot)(points)
    assert found.value.blocked.mover == "walker"


def test_a_grid_path_screen_that_finds_no_re_route_plans_as_without_it(loop, monkeypatch):
    """When no re-route from the screen's finding works, the query is planned as without the
    screen: here the finding is made up (the cart passes; a re-timing waits for it), and the
    re-route from it is refused, so the plan is the re-timed static plan all the same."""
    import trajopt.planning._moving as among

    grid, planner = loop
    start, goal = (1.0, 1.0), (11.0, 1.0)
    cart = trajopt.MovingObstacle.from_waypoints(
        [0.0, 6.0, 9.0], [(6.0, 2.0), (6.0, 1.0), (6.0, 2.0)], radius=0.25, name="cart"
    )
    calls = []

    def wrong(self, points):
        calls.append(points.shape)
        raise among._GridBlocked(BlockedError("made up", mover="cart", t=1.0), 10.0)

    def refused(blocked, *args):
        calls.append("reroute")
        raise BlockedError("no re-route", mover="cart", t=1.0)

    monkeypatch.setattr(among._GridScreen, "__call__", wrong)
    monkeypatch.setattr(among, "_reroute_early", refused)
    out = planner.plan(start, goal, moving_obstacles=[cart], mover_margin=0.02)
    assert calls[1] == "reroute" and len(calls) == 2  # the second query runs without the screen
    monkeypatch.undo()
    _same_plan(out, _after_timing(planner, start, goal, [cart], 0.02))
    assert out.stats["moving"]["route"] == "retimed"
    _check(out, [cart], grid, 0.02)


def test_a_blocked_corridor_raises_as_without_the_screen(monkeypatch):
    """The screen finds the only corridor blocked, no re-route works: the query is planned again
    and raises the error the plan without the screen raises."""
    import trajopt.planning._moving as among

    found = []
    early_reroute = among._reroute_early

    def spy(blocked, *args):
        found.append(blocked.mover)
        return early_reroute(blocked, *args)

    monkeypatch.setattr(among, "_reroute_early", spy)
    grid = _grid((60, 240), [(0.5, 11.5, 1.0, 2.0)])
    planner = trajopt.Planner(grid, trajopt.Robot())
    cart = trajopt.MovingObstacle.from_waypoints(
        [0.0, 4.0], [(9.0, 1.5), (6.0, 1.5)], radius=0.25, name="cart"
    )
    start, goal = (1.0, 1.5), (11.0, 1.5)
    with pytest.raises(BlockedError) as early:
        planner.plan(start, goal, moving_obstacles=[cart], mover_margin=0.02)
    with pytest.raises(BlockedError) as late:
        _after_timing(planner, start, goal, [cart], 0.02)
    assert found == ["cart"]  # the screen found it
    assert str(early.value) == str(late.value)
    assert (early.value.mover, early.value.t) == (late.value.mover, late.value.t)


def test_check_curve_sees_the_curve_the_plan_is_timed_on(loop):
    """``PlanRequest.check_curve``: called once, on the returned plan's path, before timing."""
    from trajopt.planning import PlanRequest, run_query

    _, planner = loop
    seen = []
    request = PlanRequest((1.0, 1.0), (11.0, 1.0), check_curve=seen.append)
    out = run_query(planner.options, planner.caches, request)
    assert len(seen) == 1 and seen[0] is out.path
    assert request == PlanRequest((1.0, 1.0), (11.0, 1.0))  # not part of the equality

    class Stop(Exception):
        pass

    def refuse(curve):
        raise Stop

    with pytest.raises(Stop):
        run_query(
            planner.options,
            planner.caches,
            PlanRequest((1.0, 1.0), (11.0, 1.0), check_curve=refuse),
        )


def test_derived_caches_equal_fresh_caches_and_leave_the_planner_alone(loop):
    """A re-route's caches: built from the planner's, equal to a fresh build of the marked map."""
    grid, planner = loop
    planner.plan((1.0, 1.0), (11.0, 1.0))  # builds the inflated grid, cost, components
    caches = planner.caches
    before = (np.array(caches.inflated.occupied), np.array(caches.search_cost))
    cart = trajopt.MovingObstacle.from_waypoints([0.0], [(6.0, 1.0)], radius=0.25, name="cart")
    marked = trajopt.moving.mark_swept(grid, [(cart, 0.0, 0.0)], 0.05)
    derived = caches.derived(marked)
    fresh = type(caches)(marked, None, caches.options)
    assert np.array_equal(derived.inflated.occupied, fresh.inflated.occupied)
    assert np.allclose(derived.search_cost, fresh.search_cost, rtol=0, atol=1e-12)
    a, b = derived.components, fresh.components
    pairs = np.unique(np.stack([a.ravel(), b.ravel()]), axis=1)  # the same partition
    assert np.unique(pairs[0]).size == pairs.shape[1] == np.unique(pairs[1]).size
    assert np.array_equal(caches.inflated.occupied, before[0])
    assert np.array_equal(caches.search_cost, before[1])
    assert caches.grid is grid


def test_swept_mask_covers_the_shape_at_dense_times():
    """Every cell a disc or polygon mover touches at 1 ms samples is marked (and not far more)."""
    grid = _grid((60, 80), [(0.0, 4.0, 0.0, 3.0)])
    poly = trajopt.MovingObstacle.from_waypoints(
        [0.0, 2.0, 3.0],
        [(0.5, 0.5), (2.5, 1.5), (3.0, 2.5)],
        radius=0.05,
        headings=[0.0, 1.0, 2.5],
        vertices=[(-0.2, -0.1), (0.3, -0.1), (0.3, 0.1), (-0.2, 0.1)],
        growth=0.02,
    )
    mask = trajopt.moving.swept_mask(grid, poly, 0.5, 2.5, 0.1)
    t = np.linspace(0.5, 2.5, 2001)
    c, h = poly.pose_at(t)
    v = poly.vertices
    # points of the grown shape: its vertices and the circle of radius rounding + grow round them
    ang = np.linspace(0.0, 2.0 * np.pi, 16, endpoint=False)
    r = (poly.radius_at(t) + 0.1)[:, None, None]
    world = c[:, None, :] + np.stack(
        [np.cos(h)[:, None] * v[:, 0] - np.sin(h)[:, None] * v[:, 1],
         np.sin(h)[:, None] * v[:, 0] + np.cos(h)[:, None] * v[:, 1]], axis=-1
    )  # fmt: skip
    pts = (world[:, :, None, :] + r[..., None] * np.stack([np.cos(ang), np.sin(ang)], -1)).reshape(
        -1, 2
    )
    cells = grid.world_to_cell(pts)
    inside = (cells[:, 0] >= 0) & (cells[:, 0] < 80) & (cells[:, 1] >= 0) & (cells[:, 1] < 60)
    assert mask[cells[inside, 1], cells[inside, 0]].all()
    assert not mask[0:4, 70:80].any()  # far from the track


def _square_distance(c, h, pts):
    """Distances (m) from points ``pts`` (shape (k, 2)) to the squares of centres ``c`` (shape
    (..., 2)) and half side ``h``: the nearest over the points, written out here."""
    best = np.full(c.shape[:-1], np.inf)
    for p in pts:
        dx = np.maximum(np.abs(c[..., 0] - p[0]) - h, 0.0)
        dy = np.maximum(np.abs(c[..., 1] - p[1]) - h, 0.0)
        best = np.minimum(best, np.hypot(dx, dy))
    return best


def _dense_track(pts, step):
    """The polyline through ``pts`` sampled every ``step`` (m) or closer, ends included."""
    out = [pts[:1]]
    for a, b in zip(pts[:-1], pts[1:], strict=True):
        n = max(1, int(np.ceil(np.hypot(*(b - a)) / step)))
        out.append(a + np.linspace(0.0, 1.0, n + 1)[1:, None] * (b - a))
    return np.vstack(out)


@pytest.mark.parametrize("t0, t1", [(0.0, 4.0), (1.3, 1.3), (2.2, 9.0)])
def test_swept_mask_is_the_cells_whose_square_comes_near_the_track(t0, t1):
    """The marked cells are those whose square comes within the grown radius of the track
    polyline (brute force over every cell, partly off the map, the track sampled every
    0.5 mm: equal but for cells within that sampling of the boundary)."""
    grid = _grid((50, 70), [])
    m = trajopt.MovingObstacle.from_waypoints(
        [0.0, 1.0, 2.5, 4.0], [(-0.3, 0.4), (1.2, 1.9), (3.1, 1.0), (3.1, 2.6)], radius=0.15
    )
    mask = trajopt.moving.swept_mask(grid, m, t0, t1, 0.05)
    res = float(grid.resolution)
    radius = 0.15 + 0.05
    iy, ix = np.mgrid[0:50, 0:70]
    c = np.asarray(grid.origin) + (np.stack([ix, iy], -1) + 0.5) * res  # (50, 70, 2)
    ts = np.concatenate([[t0], m.times[(m.times > t0) & (m.times < t1)], [t1]])
    step = 5e-4
    best = _square_distance(c, 0.5 * res, _dense_track(m.position_at(ts), step))
    expect = best <= radius
    differ = mask != expect
    assert np.all(np.abs(best[differ] - radius) <= 0.5 * step + 1e-9)
    assert expect.sum() > 20
    cells = np.stack([ix.ravel(), iy.ravel()], axis=1)
    asked = trajopt.moving.swept_cells(grid, m, t0, t1, 0.05, cells)  # the same test, cell by cell
    assert np.array_equal(asked, mask.ravel())


@settings(max_examples=30, deadline=None)
@given(
    seg=st.lists(st.floats(-0.3, 0.3), min_size=4, max_size=4),
    h=st.floats(0.005, 0.1),
)
def test_square_segment_distance_against_dense_samples(seg, h):
    """The segment-to-square distance (compiled) is the smallest distance of the segment's
    dense samples to the square (0 when one is inside), within the sampling."""
    a, b = np.array(seg[:2]), np.array(seg[2:])
    c = np.array([[0.0, 0.0], [0.03, -0.05], [-0.2, 0.1]])
    step = 1e-4
    want = _square_distance(c, h, _dense_track(np.stack([a, b]), step))
    got = np.array([square_segment_distance(*ci, h, *a, *b) for ci in c])
    assert np.all(got <= want + 1e-12) and np.all(got >= want - 0.5 * step - 1e-12)


def test_a_detour_whose_grid_path_follows_the_blocked_path_goes_after_the_waits(bay):
    """With a ``sketch``, the detour round the forklift's final place (clear of the blocked
    path) is drawn first: when its grid path follows the blocked path it is tried after the
    waits at safe places; when it goes another way, before them (every plan fails here: only
    the order is read)."""
    grid = bay
    robot = trajopt.Robot()
    forklift = trajopt.MovingObstacle.from_waypoints(
        [0.0, 15.0, 30.0], [(13.0, 2.0), (5.5, 2.0), (0.8, 1.8)], radius=0.2, name="forklift"
    )
    p0, p1 = np.array([3.0, 2.0]), np.array([11.0, 2.0])
    path = np.stack([np.linspace(3.0, 11.0, 161), np.full(161, 2.0)], axis=1)
    blocked = BlockedError("blocked (test)", mover="forklift", t=5.0)
    drawn = []

    def plan_leg(marked, a, b, heading, goal_heading=None, start_steer=0.0):
        raise trajopt.errors.NoPathError("no plan (test)")

    def order(way):
        def sketch(marked, a=None, b=None):
            drawn.append(int(np.asarray(marked.occupied).sum()))
            return way

        with pytest.raises(BlockedError) as info:
            trajopt.moving.reroute(
                p0, p1, robot, [forklift], 0.02, blocked, grid=grid,
                free=lambda: ~np.asarray(grid.occupied), plan_leg=plan_leg, path=path,
                sketch=sketch,
            )  # fmt: skip
        text = str(info.value)
        names = ["around every mover's final place", "wait at"]
        assert all(n in text for n in names), text
        return sorted(names, key=text.index)

    assert order(path[::4]) == ["wait at", "around every mover's final place"]
    assert drawn and drawn[0] > int(np.asarray(grid.occupied).sum())  # on the marked map
    north = np.array([[3.0, 2.0], [6.0, 3.3], [11.0, 2.0]])  # 1.3 m off the path at the bay
    assert order(north) == ["around every mover's final place", "wait at"]


@pytest.mark.parametrize("seed", range(4))
def test_safe_places_are_the_cheapest_clear_cells_spaced_apart(seed):
    """``safe_places`` against its definition written out over every cell: the free cells that
    keep the clearance from every swept region, in order of detour (ties by row, then column),
    each the first at least the spacing from those taken before it."""
    rng = np.random.default_rng(seed)
    grid = _grid((80, 120), [(0.3, 5.7, 0.3, 3.7)])
    free = ~np.asarray(grid.occupied)
    free[rng.random(free.shape) < 0.3] = False
    movers = [
        trajopt.MovingObstacle.from_waypoints(
            [0.0, 3.0, 6.0], rng.uniform((0.5, 0.5), (5.5, 3.5), (3, 2)), radius=0.2
        )
        for _ in range(2)
    ]
    p0, p1 = rng.uniform((0.5, 0.5), (5.5, 3.5), (2, 2))
    got = trajopt.moving.safe_places(grid, free, movers, 0.3, p0, p1, 6.0)
    unsafe = np.zeros(grid.shape, dtype=bool)
    for m in movers:
        unsafe |= trajopt.moving.swept_mask(grid, m, 0.0, 6.0, 0.3)
    iy, ix = np.nonzero(free & ~unsafe)
    pts = np.stack([ix, iy], axis=1) * RES + 0.5 * RES
    cost = np.hypot(*(pts - p0).T) + np.hypot(*(pts - p1).T)
    want = []
    for i in np.argsort(cost, kind="stable"):
        if all(math.dist(pts[i], q) >= trajopt.moving.SAFE_PLACE_SPACING for q in want):
            want.append(pts[i])
            if len(want) == trajopt.moving.N_SAFE_PLACES:
                break
    assert len(got) == len(want) == trajopt.moving.N_SAFE_PLACES
    for g, w in zip(got, want, strict=True):
        assert np.allclose(g, w, atol=1e-12)


@settings(max_examples=6, deadline=None, suppress_health_check=list(HealthCheck))
@given(
    st.lists(
        st.tuples(
            st.floats(1.0, 11.0),
            st.sampled_from([1.0, 4.0]),
            st.floats(0.0, 15.0),
            st.floats(-0.6, 0.6),
            st.floats(0.1, 0.35),
        ),
        min_size=1,
        max_size=3,
    )
)
def test_random_movers_on_the_loop_never_violate(loop, movers):
    """Movers that walk along a corridor and stop: a certified plan, or a typed BlockedError."""
    grid, planner = loop
    obs = [
        trajopt.MovingObstacle.from_waypoints(
            [t0, t0 + 4.0], [(x, y), (x + 4.0 * v, y)], radius=r, name=f"m{i}"
        )
        for i, (x, y, t0, v, r) in enumerate(movers)
    ]
    if any(
        np.hypot(m.positions[0, 0] - 1.0, m.positions[0, 1] - 1.0) < m.radius + 0.2 for m in obs
    ):
        return  # a mover on the robot at t = 0 is refused (InvalidInputError), not planned
    try:
        out = planner.plan((1.0, 1.0), (11.0, 1.0), moving_obstacles=obs, mover_margin=0.02)
    except BlockedError as exc:
        assert exc.mover in {m.name for m in obs}
        return
    assert dense_min(out, obs, dt=2e-3, margin=0.02)[0] >= -1e-6
    assert _static_clearance(out, grid, dt=0.02) >= out.robot.radius - 1e-6


@pytest.mark.parametrize("seed", [0, 4])  # seed 0 with waits, 4 with a BlockedError
def test_the_grid_path_screen_changes_no_plan_on_random_movers(loop, monkeypatch, seed):
    """The screen against the plan without it (the screen made a no-op), on random movers of
    the loop: a cart that drives in and stops near the short corridor, a walker coming
    along it head-on, a mover that crosses it and leaves. Each query gives the same outcome
    and, where a plan is returned, the same plan (the screen decides only when the static
    plan is fitted)."""
    import trajopt.planning._moving as among

    _, planner = loop
    rng = np.random.default_rng(seed)
    start, goal = (1.0, 1.0), (11.0, 1.0)
    scenes = []
    for _ in range(3):
        x = float(rng.uniform(3.0, 9.0))
        off = float(rng.choice([0.0, rng.uniform(0.3, 0.6)]))
        scenes.append(
            trajopt.MovingObstacle.from_waypoints(
                [0.0, float(rng.uniform(1.0, 4.0))], [(x, 2.0), (x, 1.0 + off)], radius=0.25,
                name="cart",
            )
        )  # fmt: skip
        scenes.append(
            trajopt.MovingObstacle.from_waypoints(
                [0.0, float(rng.uniform(12.0, 24.0))], [(11.0, 1.0 + off), (1.0, 1.0 + off)],
                radius=float(rng.uniform(0.1, 0.25)), name="walker",
            )
        )  # fmt: skip
        scenes.append(
            trajopt.MovingObstacle.from_waypoints(
                [0.0, 4.0, 8.0], [(x, 2.2), (x, 1.0), (x, 0.2)], radius=0.2, name="crossing"
            )
        )

    def outcome(mover):
        try:
            return planner.plan(start, goal, moving_obstacles=[mover], mover_margin=0.02)
        except BlockedError as exc:
            return exc

    with_screen = [outcome(m) for m in scenes]
    monkeypatch.setattr(among._GridScreen, "__call__", lambda self, points: None)
    without = [outcome(m) for m in scenes]
    monkeypatch.undo()
    early = [
        not isinstance(a, BlockedError) and a.stats["moving"].get("blocked_on_grid_path")
        for a in with_screen
    ]
    assert any(early) and not all(early)  # the screen found some, not all
    for a, b in zip(with_screen, without, strict=True):
        if isinstance(b, BlockedError):
            assert isinstance(a, BlockedError) and str(a) == str(b)
            continue
        _same_plan(a, b)  # certified: the tests above check such plans independently
        assert a.stats["moving"]["certificate"]["ok"]


def test_reached_swept_mask_on_a_head_on_walker_by_hand():
    """A walker from x = 10 m to x = 0 along y = 1 at 0.5 m/s, a robot from (0, 1) at 0.5 m/s:
    the walker's disc (radius ``R`` with the grow and half a cell's diagonal) last covers the
    centre at x when it is at ``x - R``, at ``t = (10 - x + R) / 0.5``; the robot can be within
    ``slack`` of the cell by ``(x - slack - h) / 0.5`` (``h`` half a cell's diagonal): the cells
    on the line are marked from the start up to ``x = (10 + R + slack + h) / 2`` and, past the
    walker's end, all those its last place covers; none beyond."""
    grid = _grid((40, 240), [])
    walker = trajopt.MovingObstacle.from_waypoints(
        [0.0, 20.0], [(10.0, 1.0), (0.0, 1.0)], radius=0.2, name="walker"
    )
    grow, slack = 0.03, 0.165
    h = RES * math.sqrt(0.5)
    big_r = 0.2 + grow + h
    mask = trajopt.moving.reached_swept_mask(
        grid, walker, 0.0, walker.t_last, grow, np.array([0.0, 1.0]), 0.5, slack
    )
    whole = trajopt.moving.swept_mask(grid, walker, 0.0, walker.t_last, grow)
    assert not np.any(mask & ~whole)  # a part of the whole swept region
    row = round((1.0 - 0.5 * RES) / RES)  # cell centres at y = 0.975 m: 0.025 m off the track
    x = (np.arange(grid.shape[1]) + 0.5) * RES
    off = 1.0 - (row + 0.5) * RES
    reach_r = math.sqrt(big_r**2 - off**2)  # the walker covers the centre within this along x
    edge = (10.0 + reach_r + slack + h) / 2.0
    expect = (x <= edge) & (x <= 10.0 + reach_r)
    away = np.abs(x - edge) > 1e-9
    assert np.array_equal(mask[row][away], expect[away])
    assert mask[row][x < 1.0].all() and not mask[row][x > edge + RES].any()
    # and with the late rule (1.5, 2 s): also free where it first covers the centre (at
    # (10 - x - r) / 0.5) after 1.5 (x + slack + h) / 0.5 + 2: before x = (18 - 2 r - 3 (slack +
    # h)) / 5
    late = trajopt.moving.reached_swept_mask(
        grid, walker, 0.0, walker.t_last, grow, np.array([0.0, 1.0]), 0.5, slack, (1.5, 2.0)
    )
    lower = (18.0 - 2.0 * reach_r - 3.0 * (slack + h)) / 5.0
    away &= np.abs(x - lower) > 1e-9
    assert np.array_equal(late[row][away], (expect & (x >= lower))[away])
    assert late[row][(x > lower + RES) & (x < edge - RES)].all() and not late[row][x < 2.5].any()
    # a walker standing at x = 9 m for ever (after t = 2 s): marked where it stands, whenever
    stands = trajopt.MovingObstacle.from_waypoints(
        [0.0, 2.0], [(10.0, 1.0), (9.0, 1.0)], radius=0.2, name="stands"
    )
    mask = trajopt.moving.reached_swept_mask(
        grid, stands, 0.0, stands.t_last, grow, np.array([0.0, 1.0]), 0.5, slack
    )
    near9 = np.abs(x - 9.0) < reach_r - 1e-9
    assert mask[row][near9].all() and not mask[row][x > 9.0 + reach_r + 1e-9].any()
    # over [0, 1] s only (not to its end): the walker is at x >= 9.5, out of the robot's reach
    assert not trajopt.moving.reached_swept_mask(
        grid, stands, 0.0, 1.0, grow, np.array([0.0, 1.0]), 0.5, slack
    ).any()


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 10_000))
def test_reached_swept_mask_holds_every_meeting_at_dense_times(seed):
    """Brute force over 4 ms samples of random tracks (a stop on the way, growth, a polygon):
    every cell whose square the mover's bounding disc meets at a time ``t`` with ``speed t >=
    |c - o| - slack - h`` is marked; every marked cell's centre is within the disc's radius
    plus ``h`` at such a time, within the samples' spacing (a mover moves at most ``v dt``
    between two); with the late rule, only at times up to its guess of when the robot has
    passed."""
    rng = np.random.default_rng(seed)
    grid = _grid((50, 70), [])
    times = np.cumsum(rng.uniform(0.3, 1.5, 5)) - 0.5
    pos = rng.uniform([0.0, 0.0], [3.5, 2.5], (5, 2))
    pos[2] = pos[1]  # a stop on the way
    mover = trajopt.MovingObstacle.from_waypoints(
        times, pos, radius=0.05, growth=0.02, headings=rng.uniform(-3, 3, 5),
        vertices=[(-0.2, -0.1), (0.2, -0.1), (0.2, 0.1), (-0.2, 0.1)], name="cart",
    )  # fmt: skip
    origin, speed, slack, grow = rng.uniform([0.0, 0.0], [3.5, 2.5]), 0.5, 0.15, 0.02
    t0, t1 = (float(times[0]), float(times[-1]) + 1.0) if seed % 2 else (0.4, float(times[3]))
    late = (1.5, 2.0) if seed % 4 >= 2 else (0.0, 0.0)
    mask = trajopt.moving.reached_swept_mask(grid, mover, t0, t1, grow, origin, speed, slack, late)
    h = RES * math.sqrt(0.5)
    big_r = 0.0 + np.hypot(0.2, 0.1) + float(mover.radius_at(t1)) + grow + h
    dt = 0.004
    t_end = min(t1, mover.t_last)
    t = np.append(np.arange(t0, t_end, dt), t_end)
    p = mover.position_at(t)
    iy, ix = np.mgrid[0:50, 0:70]
    c = (np.stack([ix, iy], -1).reshape(-1, 2) + 0.5) * RES
    far = np.hypot(*(c - origin).T) - slack - h
    d = np.hypot(c[:, None, 0] - p[None, :, 0], c[:, None, 1] - p[None, :, 1])
    ub = np.full(c.shape[0], np.inf)
    if late[0] > 0.0:  # the guess of when the robot has passed: first covered later, free
        ub = late[0] * (np.hypot(*(c - origin).T) + slack + h) / speed + late[1]
    dx = np.maximum(np.abs(c[:, None, 0] - p[None, :, 0]) - 0.5 * RES, 0.0)
    dy = np.maximum(np.abs(c[:, None, 1] - p[None, :, 1]) - 0.5 * RES, 0.0)
    hit = np.hypot(dx, dy) <= big_r - h  # the disc meets the cell's square
    seen = np.any(hit & (speed * t[None, :] >= far[:, None]) & (t[None, :] <= ub[:, None]), axis=1)
    v = float(mover.speed_max())
    near = np.any(
        (d <= big_r + v * dt)
        & (speed * (t[None, :] + dt) >= far[:, None])
        & (t[None, :] - dt <= ub[:, None]),
        axis=1,
    )
    if t1 >= mover.t_last:  # it stands at its last place for ever: any time is late enough
        seen |= hit[:, -1] & (ub >= t_end)
        near |= (d[:, -1] <= big_r + 1e-9) & (ub >= t_end - 1e-9)
    flat = mask.ravel()
    assert np.all(flat[seen])  # every sampled meeting is marked
    assert not np.any(flat & ~near)  # and nothing that no sample comes close to


def test_a_walker_head_on_in_a_room_is_passed_with_a_side_step():
    """A walker drives the straight way between the robot's ends backwards at the robot's top
    speed: the detour round where the robot may meet it keeps the straight way but for a side
    step where they meet (at x = 6 m by hand: both at 0.5 m/s from 10 m apart), so the robot
    arrives within 5 % of the static plan's time (a way round its whole track is longer)."""
    grid = _grid((80, 240), [(0.5, 11.5, 0.5, 3.5)])
    planner = trajopt.Planner(grid, trajopt.Robot())
    start, goal = (1.0, 2.0), (11.0, 2.0)
    base = planner.plan(start, goal)
    walker = trajopt.MovingObstacle.from_waypoints(
        [0.0, 20.0], [goal, start], radius=0.2, name="walker"
    )
    out = planner.plan(start, goal, moving_obstacles=[walker], mover_margin=0.02)
    mv = out.stats["moving"]
    assert mv["route"] == "rerouted"
    assert mv["reroute"][-1]["what"] == "around 'walker' where the robot may meet it"
    _check(out, [walker], grid, 0.02)
    assert out.length <= 1.05 * base.length and out.duration <= 1.05 * base.duration
    t = np.linspace(0.0, out.duration, 2001)
    smp = out.sample(t)
    gap = np.abs(walker.position_at(t)[:, 0] - smp.x)
    k = int(np.argmin(gap))  # they pass: the robot beside the walker's line
    assert abs(smp.y[k] - 2.0) >= 0.165 + 0.2 + 0.02 - 1e-6 and 5.0 < smp.x[k] < 7.0
    assert np.max(np.abs(smp.y - 2.0)) < 1.0  # a side step, not a way round


@pytest.mark.parametrize("seed", range(8))
def test_mark_swept_adds_no_cell_exactly_when_the_kept_discs_hold_the_region(seed):
    """``mark_swept`` answers ``None`` (no cell added) exactly when the swept region's cells,
    less those whose centre is in a kept disc, are all occupied already (brute force over
    the cells with :func:`swept_mask`); its shortcut for regions inside a kept disc agrees."""
    rng = np.random.default_rng(seed)
    grid = _grid((60, 80), [(0.0, 4.0, 0.0, 3.0)])
    p = rng.uniform([1.0, 1.0], [3.0, 2.0])
    r = float(rng.uniform(0.3, 0.6))
    end = p + rng.uniform(-0.25, 0.25, 2)  # stands near the kept point
    mover = trajopt.MovingObstacle.from_waypoints(
        [0.0, 1.0], [p + rng.uniform(-0.3, 0.3, 2), end], radius=0.1, name="m"
    )
    for t0, t1 in ((1.0, 1.0), (0.0, 1.0)):
        got = trajopt.moving.mark_swept(grid, [(mover, t0, t1)], 0.02, [(p, r)])
        add = trajopt.moving.swept_mask(grid, mover, t0, t1, 0.02)
        iy, ix = np.mgrid[0:60, 0:80]
        c = (np.stack([ix, iy], -1) + 0.5) * RES
        add &= np.hypot(c[..., 0] - p[0], c[..., 1] - p[1]) > r
        add &= ~np.asarray(grid.occupied)
        assert (got is None) == (not add.any())
        if got is not None:
            assert np.array_equal(np.asarray(got.occupied), np.asarray(grid.occupied) | add)


def _with_final_discs(grid, movers, margin, slack=0.0):
    """``grid`` with every cell marked whose square comes within a mover's final disc (its
    last place, radius plus growth until then, farthest vertex and ``margin``) plus
    ``slack`` (m) of its centre: the waiting witness's map (``slack`` 0), written here."""
    occ = np.array(grid.occupied)
    iy, ix = np.mgrid[0 : occ.shape[0], 0 : occ.shape[1]]
    c = np.asarray(grid.origin) + (np.stack([ix, iy], -1) + 0.5) * grid.resolution
    for m in movers:
        reach = 0.0 if m.vertices is None else float(np.max(np.hypot(*np.asarray(m.vertices).T)))
        r = m.radius + m.growth * max(float(m.times[-1]), 0.0) + reach + margin
        occ |= _square_distance(c, 0.5 * grid.resolution, m.positions[-1:]) <= r + slack
    return OccupancyGrid(occ, grid.resolution, grid.origin)


def _waiting_witness(grid, robot, start, goal, movers, margin, static=None):
    """The earliest arrival (s) of: rest at the start for a multiple of 10 ms, then drive the
    plan round the movers' final discs (:func:`_with_final_discs`), as the reference
    (:func:`~tests.trajopt.moving.reference.check_motion`) proves clear; and that plan.
    Given the ``static`` plan, it is driven instead when its centre, sampled every 5 ms, keeps
    the robot's radius plus half the samples' spacing from every final disc."""
    traj = static
    if static is not None:
        t = np.append(np.arange(0.0, static.duration, 5e-3), static.duration)
        p = positions(static, t)
        gap = float(np.max(np.hypot(*np.diff(p, axis=0).T)))
        for m in movers:
            reach = 0.0 if m.vertices is None else float(np.max(np.hypot(*m.vertices.T)))
            r = m.radius + m.growth * max(float(m.times[-1]), 0.0) + reach + margin
            d = np.hypot(*(p - m.positions[-1]).T)
            if np.min(d) - robot.radius - r < 0.5 * gap + 1e-6:
                traj = None  # the static path passes too close to a final disc
    if traj is None:
        traj = trajopt.Planner(_with_final_discs(grid, movers, margin), robot).plan(start, goal)
    h = 0.01
    tk = np.append(np.arange(0.0, traj.duration, h), traj.duration)
    p = positions(traj, tk)
    t_end = tk[-1] + max(float(m.times[-1]) for m in movers) + 1.0
    for j in range(2000):
        wait = h * j
        # a quick necessary screen on the samples (a Lipschitz pad), then the reference
        ahead = np.arange(tk[-1] + wait, t_end, h)
        if not all(
            np.all(slack_at(p, m, tk + wait, robot.radius + margin) >= -1e-6)
            and np.all(slack_at(p[-1:], m, ahead, robot.radius + margin) >= -1e-6)
            for m in movers
        ):
            continue

        def where(t, wait=wait):
            return positions(traj, np.clip(np.asarray(t) - wait, 0.0, None))

        chk = check_motion(
            where, wait + traj.duration, movers, radius=robot.radius,
            speed=robot.v_max + robot.a_max * 1e-3, margin=margin, grid=grid,
        )  # fmt: skip
        if chk.ok:
            return wait + float(traj.duration), traj
    raise AssertionError("no wait found")


@pytest.mark.parametrize("drive", ["differential", "omni"])
def test_a_cart_stopping_on_the_path_is_passed_no_later_than_the_waiting_witness(drive):
    """A cart drives in from the side and stops on the straight way of a room: the re-route
    arrives no later than the waiting witness (rest at the start while needed, then the plan
    round the cart's final disc; found here with the reference), and passes the reference
    check. The map of that witness is the one round the cart's final place: a marking of
    every cell whose centre is within the disc's radius plus half a cell's diagonal (the
    marking before this one) gives a route that arrives strictly later than the witness."""
    grid = _grid((80, 180), [(0.5, 8.5, 0.5, 3.5)])
    robot = trajopt.Robot(radius=0.2, drive=drive)
    start, goal, margin = (1.0, 2.0), (8.0, 2.0), 0.05
    cart = trajopt.MovingObstacle.from_waypoints(
        [0.0, 2.0], [(4.0, 3.2), (4.0, 2.0)], radius=0.27, name="cart"
    )
    out = trajopt.Planner(grid, robot).plan(
        start, goal, moving_obstacles=[cart], mover_margin=margin
    )
    assert out.stats["moving"]["route"] == "rerouted"
    chk = check_trajectory(out, [cart], margin=margin, grid=grid)
    assert chk.ok
    witness, _ = _waiting_witness(grid, robot, start, goal, [cart], margin)
    assert out.duration <= witness + 1e-6
    wider = _with_final_discs(grid, [cart], margin, slack=0.5 * RES * math.sqrt(2.0))
    assert trajopt.Planner(wider, robot).plan(start, goal).duration > witness + 1e-3


@pytest.mark.parametrize(
    ("x", "side", "off", "t0", "t1"), [(4.48, 1, 0.84, 4.08, 8.15), (5.18, -1, 0.82, 6.72, 9.78)]
)
def test_a_cart_ending_beside_the_path_is_passed_no_later_than_the_waiting_witness(
    x, side, off, t0, t1
):
    """A cart (1 x 0.5 m) crosses the straight way of a room and stops beside it, clear of
    the path but within its bounding disc's reach: the re-timing along the static path waits
    for it and arrives later than the waiting witness (rest at the start, then the route round
    the cart's final disc), so the route round the final places is tried too and the earlier
    arrival kept: no later than the witness, certified and passing the reference check."""
    grid = _grid((80, 180), [(0.5, 8.5, 0.5, 3.5)])
    robot = trajopt.Robot(radius=0.2)
    planner = trajopt.Planner(grid, robot)
    start, goal, margin = (1.0, 2.0), (8.0, 2.0), 0.05
    box = [(-0.5, -0.25), (0.5, -0.25), (0.5, 0.25), (-0.5, 0.25)]
    cart = trajopt.MovingObstacle.from_waypoints(
        [t0, t1], [(x, 2.0 - 1.5 * side), (x, 2.0 + off * side)], radius=0.05,
        vertices=box, headings=[0.5 * math.pi, 0.5 * math.pi], name="cart",
    )  # fmt: skip
    static = planner.plan(start, goal)
    witness, _ = _waiting_witness(grid, robot, start, goal, [cart], margin, static)
    along = trajopt.moving.retime_chain(static, [cart], margin=margin)
    assert along.duration > witness + 1e-3  # the static path's re-timing alone: later
    out = planner.plan(start, goal, moving_obstacles=[cart], mover_margin=margin)
    mv = out.stats["moving"]
    assert mv["route"] == "rerouted" and mv["final_places"]["result"].startswith("ok")
    assert out.duration <= witness + 1e-6
    assert check_trajectory(out, [cart], margin=margin, grid=grid).ok


def test_marks_where_the_robot_may_meet_are_the_reached_masks_outside_the_kept_discs():
    """``mark_swept`` with ``reach``: the map's cells, plus each region's
    ``reached_swept_mask`` (a mask of the whole grid, checked by hand above) outside the kept
    discs (centres within their radius); ``None`` when that adds nothing. Random tracks, times
    before the first waypoint and after the last, a mover of one waypoint."""
    rng = np.random.default_rng(7)
    grid = _grid((60, 80), [(0.5, 3.5, 0.5, 2.5)])
    x = (np.arange(grid.shape[1]) + 0.5) * RES
    y = (np.arange(grid.shape[0]) + 0.5) * RES
    origin = np.array([0.8, 1.5])
    keep = [(origin, 0.3), (np.array([3.2, 1.5]), 0.25)]
    kept = np.zeros(grid.shape, dtype=bool)
    for p, r in keep:
        kept |= np.hypot(x[None, :] - p[0], y[:, None] - p[1]) <= r
    for k in range(12):
        n = 1 if k == 0 else int(rng.integers(2, 8))
        times = np.cumsum(rng.uniform(0.2, 1.0, n)) - 0.5
        pts = np.array([2.0, 1.5]) + np.cumsum(rng.normal(0.0, 0.4, (n, 2)), axis=0)
        m = trajopt.moving.MovingObstacle.from_waypoints(times, pts, radius=0.15, name="m")
        t0 = float(rng.uniform(times[0] - 1.0, times[-1]))
        t1 = float(rng.uniform(t0, times[-1] + 1.0))
        for late in ((0.0, 0.0), (1.5, 2.0)):
            reach = (origin, 0.5, 0.165)
            got = trajopt.moving.mark_swept(grid, [(m, t0, t1)], 0.02, keep, reach, late)
            add = trajopt.moving.reached_swept_mask(grid, m, t0, t1, 0.02, *reach, late) & ~kept
            want = np.asarray(grid.occupied) | add
            if np.array_equal(want, np.asarray(grid.occupied)):
                assert got is None
            else:
                assert np.array_equal(got.occupied, want)
