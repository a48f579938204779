"""Tests of trajopt.replan: re-planning a first plan that was re-routed around a mover, with new predictions.

The scene: two 1 m corridors (y = 1 and y = 4) joined at both ends; a cart that parks on the
short corridor at (6, 1) from t = 3 s makes the first plan from (1, 1) to (11, 1) take the
long way round (y = 4), planned on the map with the cart's swept region marked.

References: the first plan's own curve, sampled every millimetre (the kept detour's points
must lie on it, and its start must be the first plan's state at the splice: position,
heading, speed, acceleration), hand-shifted predictions on the result's clock with
reference.py's independent check (1 ms samples plus the Lipschitz bound, the static map's
clearance), dense samples and brute force, and hand-made map changes (a cell occupied next to
the detour, a pocket freed in a wall far from it) whose verdict is known by construction.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import trajopt
from astar.grid import OccupancyGrid
from tests.trajopt.moving.reference import brute_min, check_trajectory, dense_min
from tests.trajopt.moving.scenes import RES, loop_occupancy
from trajopt.replan._keep import keep_rest

LATENCY = 0.05
MARGIN = 0.05
START, GOAL = (1.0, 1.0), (11.0, 1.0)


def _cart(x=6.0, y_park=1.0, t_park=3.0):
    return trajopt.MovingObstacle.from_waypoints(
        [0.0, t_park], [(x, 2.0), (x, y_park)], radius=0.25, name="cart"
    )


def _on_clock(m, t0):
    """A mover (no growth) seen from ``t0`` (s) of its clock: times ``- t0``, cut at 0."""
    times = np.asarray(m.times, dtype=float) - t0
    if times[-1] <= 0.0:
        return trajopt.MovingObstacle.from_waypoints([0.0], [m.positions[-1]], radius=m.radius)
    later = times > 0.0
    p0 = [np.interp(0.0, times, m.positions[:, i]) for i in (0, 1)]
    t = np.r_[0.0, times[later]]
    p = np.vstack([p0, m.positions[later]])
    return trajopt.MovingObstacle.from_waypoints(t, p, radius=m.radius, name=m.name)


@pytest.fixture(scope="module", params=["differential", "omni"])
def rerouted(request):
    """A planner on the loop and its first plan, re-routed the long way round the cart."""
    grid = OccupancyGrid(loop_occupancy(), RES, (0.0, 0.0))
    planner = trajopt.Planner(grid, trajopt.Robot(drive=request.param))
    headings = {"start_heading": -0.5, "goal_heading": 1.0} if request.param == "omni" else {}
    first = planner.plan(START, GOAL, moving_obstacles=[_cart()], mover_margin=MARGIN, **headings)
    assert first.stats["moving"]["route"] == "rerouted"
    assert np.max(first.sample(np.linspace(0.0, first.duration, 400)).y) > 3.5  # the long way
    return grid, planner, first


def _translation(traj):
    return getattr(traj, "translation", traj)


def _check(first, out, ts, movers, grid):
    """Splice continuity and the independent checks against the movers on the result's clock."""
    a, b = first.translation_state(ts), out.translation_state(0.0)  # the course for omni
    assert math.hypot(a.x - b.x, a.y - b.y) < 1e-9
    assert abs(math.remainder(a.theta - b.theta, 2 * math.pi)) < 1e-9
    assert abs(a.v - b.v) < 1e-9 and abs(a.a - b.a) < 1e-9
    body = first.orientation_at(ts)
    if body is not None:  # an omni base's own orientation: its rate and acceleration too
        for x, y in zip(body, out.orientation_at(0.0), strict=True):
            assert abs(x - y) < 1e-9
    seen = [_on_clock(m, ts) for m in movers]
    assert out.stats["moving"]["certificate"]["ok"]
    assert check_trajectory(out, seen, margin=MARGIN, grid=grid).ok
    assert dense_min(out, seen, margin=MARGIN)[0] >= -1e-6
    assert brute_min(out, seen, margin=MARGIN) >= -1e-6


def _on_first_curve(first, out):
    """Largest distance (m) from the kept path's points to the first plan's curve (1 mm samples)."""
    tr0, tr1 = _translation(first), _translation(out)
    s0 = np.linspace(0.0, float(tr0.length), int(float(tr0.length) / 1e-3) + 1)
    ref = np.asarray(tr0.path(tr0.path.u_at_s(s0)), dtype=float)
    s1 = np.linspace(0.0, float(tr1.length), 300)
    pts = np.asarray(tr1.path(tr1.path.u_at_s(s1)), dtype=float)
    worst = 0.0
    for p in pts:
        worst = max(worst, float(np.min(np.hypot(ref[:, 0] - p[0], ref[:, 1] - p[1]))))
    return worst


def test_the_first_plan_records_the_static_map_it_was_marked_from(rerouted):
    grid, planner, first = rerouted
    for steps in (first.steps, _translation(first).steps):
        assert isinstance(steps, trajopt.replan.MarkedSteps)
        assert steps.static_grid is planner.grid
        # the marked map: the static map plus the cart's marks, nothing freed
        assert np.all(steps.raw_grid.occupied >= grid.occupied)
        assert np.any(steps.raw_grid.occupied & ~grid.occupied)


@pytest.mark.parametrize("t", [1.0, 8.0])
def test_shifted_predictions_keep_the_detour_and_re_time_it(rerouted, t):
    grid, planner, first = rerouted
    ts = t + LATENCY
    # the cart parks 0.3 s later and 5 cm to the side; a walker crosses the long corridor
    # where the robot passes it (so the kept rest must be re-timed, not kept as it is)
    t_c = float(np.argmin(np.hypot(*(np.stack(_xy(first)) - [[6.0], [4.0]])))) / 1999
    t_c *= float(first.duration)
    walker = trajopt.MovingObstacle.from_waypoints(
        [t_c - 3.0, t_c + 3.0], [(6.0, 5.5), (6.0, 2.5)], radius=0.2, name="walker"
    )
    movers = [_cart(x=6.05, t_park=3.3), walker]
    out = planner.replan(first, t, latency=LATENCY, moving_obstacles=movers, mover_margin=MARGIN)
    assert out.stats["replan"] == "kept"
    assert out.stats["moving"]["route"] == "retimed"
    assert out.stats["moving"]["plan"] != "as planned"  # the walker made it wait
    assert _on_first_curve(first, out) < 2e-3  # the detour's geometry, not a new path
    end = out.sample(np.array([out.duration]))
    assert math.hypot(end.x[0] - GOAL[0], end.y[0] - GOAL[1]) < 1e-6
    _check(first, out, ts, movers, grid)
    # a re-plan of the re-plan compares with the same static map
    assert out.steps.static_grid is planner.grid


def _xy(traj):
    smp = traj.sample(np.linspace(0.0, traj.duration, 2000))
    return smp.x, smp.y


def test_the_same_static_map_given_again_keeps_the_detour(rerouted):
    """A map update equal to the static map: the cart's marks are not counted as freed cells."""
    grid, planner, first = rerouted
    same = OccupancyGrid(loop_occupancy(), RES, (0.0, 0.0))
    try:
        out = planner.replan(
            first, 1.0, grid=same, latency=LATENCY, moving_obstacles=[_cart(t_park=3.2)],
            mover_margin=MARGIN,
        )  # fmt: skip
    finally:
        planner.update_map(grid)
    assert out.stats["replan"] == "kept"
    assert _on_first_curve(first, out) < 2e-3


@pytest.mark.parametrize(
    ("change", "why"),
    [
        # 10 x 5 cm occupied against the detour's corridor wall, beside its path
        ((slice(89, 90), slice(118, 120)), "cells blocked near the rest of the path"),
        # a 0.6 m x 0.6 m pocket freed in the wall between the corridors, far from the detour
        ((slice(40, 52), slice(60, 72)), "cells freed"),
    ],
)
def test_a_static_map_changed_where_it_matters_is_not_kept(rerouted, change, why):
    grid, planner, first = rerouted
    occ = loop_occupancy()
    rows, cols = change
    occ[rows, cols] = not occ[rows, cols].all()  # occupy free cells, or free a walled block
    changed = OccupancyGrid(occ, RES, (0.0, 0.0))
    movers = [_cart(t_park=3.2)]
    try:
        planner.update_map(changed)
        tr = _translation(first)  # the keep rule's own reason, on the changed map
        _, reason = keep_rest(
            planner.options, planner.caches, tr, 1.0 + LATENCY, None, goal_heading=None, v_end=0.0
        )
        assert reason == why
        out = planner.replan(
            first, 1.0, latency=LATENCY, moving_obstacles=movers, mover_margin=MARGIN
        )
    finally:
        planner.update_map(grid)
    assert out.stats["moving"]["replan"] != "kept"
    assert out.stats["moving"]["certificate"]["ok"]
    seen = [_on_clock(m, 1.0 + LATENCY) for m in movers]
    assert check_trajectory(out, seen, margin=MARGIN, grid=changed).ok


def test_predictions_that_block_the_kept_detour_stop_and_go_the_short_way(rerouted):
    """The cart now parks on the detour: the kept rest is proved blocked, so the robot stops
    and plans on from the stop (the short way, free now), as for a kept plain path (an omni
    base braking with its yaw rate stopped beside it)."""
    grid, planner, first = rerouted
    t, ts = 1.0, 1.0 + LATENCY
    movers = [_cart(y_park=4.0)]
    out = planner.replan(first, t, latency=LATENCY, moving_obstacles=movers, mover_margin=MARGIN)
    moving = out.stats["moving"]
    assert moving["replan"] == "kept"
    # the proof that the detour is blocked hands the differential drive's stop to the
    # re-route's candidates; the omni base's (no quick proof for its own orientation) plans
    # on from the stop statically, re-timed: the short way, now free
    assert moving["route"] in ("stopped: rerouted", "stopped: retimed")
    assert "'cart'" in moving["blocked"]
    tail = out.sample(np.linspace(moving["head_s"], out.duration, 400))
    assert np.max(tail.y) < 3.0  # the short way from the stop, not the blocked detour
    # that chain re-planned while it brakes, the same predictions on its clock: its rest is
    # kept (planned on the static map, or marked from it), re-timed from the stop on
    seen = [_on_clock(m, ts) for m in movers]
    again = planner.replan(out, 0.5, latency=LATENCY, moving_obstacles=seen, mover_margin=MARGIN)
    assert again.stats["moving"]["replan"] == "kept"
    _check(out, again, 0.5 + LATENCY, seen, grid)
    _check(first, out, ts, movers, grid)


@pytest.fixture(scope="module")
def car_rerouted():
    """A car on the loop and its first plan, re-routed the long way round the cart."""
    grid = OccupancyGrid(loop_occupancy(), RES, (0.0, 0.0))
    robot = trajopt.Robot(
        drive="ackermann", min_turning_radius=0.6, radius=0.2, wheelbase=0.3, steer_rate_max=1.0
    )
    planner = trajopt.Planner(grid, robot)
    first = planner.plan(
        START, GOAL, start_heading=0.0, goal_heading=0.0, moving_obstacles=[_cart()],
        mover_margin=MARGIN,
    )  # fmt: skip
    assert first.stats["moving"]["route"] == "rerouted"
    assert np.max(first.sample(np.linspace(0.0, first.duration, 400)).y) > 3.5  # the long way
    return grid, planner, first


def _car_continuity(first, out, ts):
    """Pose, speed, acceleration and steering of ``out`` at 0 are ``first``'s at ``ts``."""
    a, b = first.sample(np.array([ts])), out.sample(np.array([0.0]))
    assert math.hypot(a.x[0] - b.x[0], a.y[0] - b.y[0]) < 1e-9
    assert abs(math.remainder(a.theta[0] - b.theta[0], 2 * math.pi)) < 1e-9
    assert abs(a.v[0] - b.v[0]) < 1e-9 and abs(a.a[0] - b.a[0]) < 1e-9
    assert abs(a.steer[0] - b.steer[0]) < 1e-9


def _on_chain(first, out):
    """Largest distance (m) from ``out``'s positions to ``first``'s (1 mm samples of its path)."""
    ref = first.sample(np.linspace(0.0, first.duration, int(first.length / 1e-3) + 1))
    pts = out.sample(np.linspace(0.0, out.duration, 300))
    return max(
        float(np.min(np.hypot(ref.x - x, ref.y - y))) for x, y in zip(pts.x, pts.y, strict=True)
    )


def test_a_car_keeps_its_re_routed_rest_with_shifted_predictions(car_rerouted):
    """The car's marked steps name the static map; shifted predictions keep the detour."""
    grid, planner, first = car_rerouted
    assert isinstance(first.steps, trajopt.replan.MarkedCarSteps)
    assert first.steps.static_grid is planner.grid
    assert np.all(first.steps.raw_grid.occupied >= grid.occupied)
    assert np.any(first.steps.raw_grid.occupied & ~grid.occupied)
    t = 2.0
    ts = t + LATENCY
    movers = [_cart(x=6.05, t_park=3.3)]
    out = planner.replan(first, t, latency=LATENCY, moving_obstacles=movers, mover_margin=MARGIN)
    assert out.stats["replan"] == "kept"
    assert out.stats["moving"]["route"] == "retimed"
    assert _on_chain(first, out) < 2e-3  # the detour's geometry, not a new path
    _car_continuity(first, out, ts)
    seen = [_on_clock(m, ts) for m in movers]
    assert out.stats["moving"]["certificate"]["ok"]
    assert check_trajectory(out, seen, margin=MARGIN, grid=grid).ok
    assert brute_min(out, seen, margin=MARGIN) >= -1e-6


def test_a_car_does_not_keep_its_re_routed_rest_when_the_static_map_changed(car_rerouted):
    """The cell holding the point 0.1 m beside the detour's path occupied (closer than the
    car's radius): planned anew, certified against the changed map."""
    grid, planner, first = car_rerouted
    smp = first.sample(np.linspace(0.0, first.duration, 4000))
    k = int(np.argmin(np.hypot(smp.x - 6.0, smp.y - 4.0)))  # where the detour passes x = 6
    assert abs(smp.x[k] - 6.0) < 0.05 and smp.y[k] > 3.5
    occ = loop_occupancy()
    occ[int((smp.y[k] + 0.1) / RES), int(smp.x[k] / RES)] = True
    changed = OccupancyGrid(occ, RES, (0.0, 0.0))
    movers = [_cart(t_park=3.2)]
    try:
        out = planner.replan(
            first, 2.0, grid=changed, latency=LATENCY, moving_obstacles=movers,
            mover_margin=MARGIN,
        )  # fmt: skip
    finally:
        planner.update_map(grid)
    assert out.stats["replan"].startswith(("braked: ", "planned: "))
    assert out.stats["moving"]["certificate"]["ok"]
    seen = [_on_clock(m, 2.0 + LATENCY) for m in movers]
    assert check_trajectory(out, seen, margin=MARGIN, grid=changed).ok
