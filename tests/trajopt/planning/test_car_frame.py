"""Tests of trajopt.planning: a car's plan does not depend on where the map's origin is (issue 45, part 5).

A full-size car (4.69 x 1.94 m, wheelbase 2.8 m, R = 3.0 m, the rear axle as reference)
backs into bays off an aisle on a 0.1 m grid: far from the origin (x near
4.5e9 m, where float64 positions are about 1e-6 m apart) fits made in the map's frame had end
tangents off by up to 3.5e-6 rad, and the chain refused the planner's own joins ("pieces 1
and 2 do not join: jumps of heading"). Planned in the map-local frame, every join is exact
to rounding; and the same case shifted by 4.5e9 m gives the same trajectory, shifted: the
positions to their float64 spacing, everything else to the last bit. Then the structural
refusals a car's plan makes before (or instead of) spending its search budget.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import astar
import trajopt
from tests.trajopt.planning.test_car import bay_reverse_scene, parking_scene, three_point_scene

FAR = (4.5e9, -(2.0**20))  # m: exactly representable, as are the shifted test points

CAR = trajopt.Robot.rectangle(
    4.69,
    1.94,
    rear_offset=0.93,
    v_max=2.5,
    a_max=1.0,
    drive=trajopt.Ackermann(min_turning_radius=3.0, wheelbase=2.8, steer_rate_max=0.5),
)


def aisle_yard(aisle: float, bay: float, origin=(0.0, 0.0), res: float = 0.1):
    """A 24 m yard: a row of parked cars 5.5 m deep below an aisle, with one bay at x = 10 m."""
    occ = np.zeros((round((8.0 + aisle) / res), round(24.0 / res)), bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    occ[: round(5.5 / res), :] = True
    occ[round(0.2 / res) : round(5.5 / res), round(10.0 / res) : round((10.0 + bay) / res)] = False
    return astar.OccupancyGrid(occ, res, origin)


# (aisle, bay width, start, start heading, goal y, goal heading): backed in from the aisle,
# with a cusp (cases that plan in well under a second: the search has a time budget)
CASES = {
    "back_in": (5.12, 2.62, (17.5, 8.15), 3.28, 1.3, math.pi / 2),
    "back_in_short": (6.58, 2.45, (10.71, 8.42), -0.119, 1.3, math.pi / 2),
}


def lattice(p):
    """``p`` on the float64 lattice of the far frame (multiples of 2**-20 m): shifted exactly."""
    return tuple(round(v * 2**20) / 2**20 for v in p)


def join_jumps(traj):
    """Heading (rad) and position (m) jumps between consecutive pieces, from their samples."""
    out = []
    for a, b in zip(traj.pieces[:-1], traj.pieces[1:], strict=True):
        ea, sb = a.sample(np.array([a.duration])), b.sample(np.array([0.0]))
        dth = abs(math.remainder(float(ea.theta[0] - sb.theta[0]), 2.0 * math.pi))
        out.append((dth, math.hypot(ea.x[0] - sb.x[0], ea.y[0] - sb.y[0])))
    return np.array(out).reshape(-1, 2)


@pytest.mark.parametrize("origin", [(0.0, 0.0), FAR])
@pytest.mark.parametrize("name", list(CASES))
def test_a_large_cars_joins_pass_wherever_the_origin_is(name, origin):
    aisle, bay, start, h0, gy, h1 = CASES[name]
    grid = aisle_yard(aisle, bay, origin)
    o = np.asarray(origin)
    goal = (10.0 + bay / 2.0, gy)
    traj = trajopt.Planner(grid, CAR).plan(
        tuple(np.add(lattice(start), o)),
        tuple(np.add(lattice(goal), o)),
        start_heading=h0,
        goal_heading=h1,
    )
    assert traj.stats["car"]["cusps"] >= 1
    jumps = join_jumps(traj)
    assert jumps[:, 0].max() <= 1e-12, jumps  # the chain allows 1e-6; these are exact
    assert jumps[:, 1].max() == 0.0
    # the fits' end tangents are the search poses' headings (forwards; + pi backwards)
    for seg in traj.steps.segments:
        path, turn = seg.smooth_path, 0.0 if seg.direction > 0 else math.pi
        ends = np.asarray(path.heading(np.array(path.domain)))
        want = traj.steps.poses[[seg.first, seg.last], 2] + turn
        assert np.abs(np.remainder(ends - want + math.pi, 2 * math.pi) - math.pi).max() < 1e-12


def _shifted(grid, d):
    return astar.OccupancyGrid(grid.occupied, grid.resolution, tuple(np.add(grid.origin, d)))


@pytest.mark.parametrize("scene", [three_point_scene, parking_scene, bay_reverse_scene])
def test_the_same_case_shifted_far_gives_the_same_trajectory_shifted(scene):
    grid, robot, start, goal, h0, h1 = scene()
    start, goal = lattice(start), lattice(goal)
    near = trajopt.plan(grid, start, goal, robot, start_heading=h0, goal_heading=h1)
    far = trajopt.plan(
        _shifted(grid, FAR),
        tuple(np.add(start, FAR)),
        tuple(np.add(goal, FAR)),
        robot,
        start_heading=h0,
        goal_heading=h1,
    )
    assert far.duration == near.duration
    t = np.linspace(0.0, near.duration, 3001)
    a, b = near.sample(t), far.sample(t)
    assert np.abs(b.x - FAR[0] - a.x).max() <= 1e-6  # float64 spacing at 4.5e9 m: 9.5e-7
    assert np.abs(b.y - FAR[1] - a.y).max() <= 1e-6
    for f in ("theta", "v", "a", "omega", "kappa", "s", "direction"):
        np.testing.assert_array_equal(getattr(b, f), getattr(a, f), err_msg=f)
    assert far.steps.origin == FAR and near.steps.origin == (0.0, 0.0)
    np.testing.assert_allclose(np.subtract(far.steps.goal, FAR), near.steps.goal, atol=1e-6)
    # the corridor is handed back in the map's frame
    va = np.vstack([r.vertices for r in near.steps.corridor.regions])
    vb = np.vstack([r.vertices for r in far.steps.corridor.regions])
    np.testing.assert_allclose(vb - FAR, va, atol=2e-6)


def test_a_shifted_curve_moves_positions_and_keeps_the_geometry():
    from trajopt.geometry import BSplineCurve, ShiftedCurve, clamped_uniform_knots

    pts = np.array([[0.0, 0.0], [1.0, 0.2], [2.0, 1.5], [2.5, 3.0], [4.0, 3.2]])
    curve = BSplineCurve(clamped_uniform_knots(len(pts), 3, (0.0, 5.0)), pts, 3)
    moved = ShiftedCurve(curve, FAR)
    u = np.linspace(0.0, 5.0, 101)
    np.testing.assert_array_equal(moved(u), curve(u) + np.asarray(FAR))
    for f in ("heading", "curvature", "speed", "s_at_u", "curvature_rate"):
        np.testing.assert_array_equal(getattr(moved, f)(u), getattr(curve, f)(u), err_msg=f)
    assert moved.length == curve.length and moved.domain == curve.domain
    np.testing.assert_array_equal(
        moved.u_at_s(np.array([0.5, 2.0])), curve.u_at_s(np.array([0.5, 2.0]))
    )


# ------------------------------------------------------------ structural refusals, fast
def _split_room():
    """A 6 x 4 m room cut in two by a wall at x = 3 m."""
    from tests.trajopt.planning.test_car import walled

    occ = walled(6.0, 4.0, 0.05)
    occ[:, 60] = True
    return astar.OccupancyGrid(occ, 0.05)


@pytest.mark.parametrize("body", [False, True])
def test_start_and_goal_apart_are_refused_at_once(body):
    """Start and goal in different components of the car's search grid: a NoPathError that
    names both poses and says why, in well under the search's budget (the search's own
    component test, ``disconnected``, ends each try at once)."""
    import time

    from tests.trajopt.planning.test_car import body_car
    from trajopt.errors import NoPathError

    robot = (
        body_car(wheelbase=0.4)
        if body
        else trajopt.Robot(radius=0.15, drive="ackermann", min_turning_radius=0.5)
    )
    planner = trajopt.Planner(_split_room(), robot)
    elapsed = []
    for _ in range(3):  # the first pays for loading the compiled search
        t0 = time.perf_counter()
        with pytest.raises(
            NoPathError, match=r"pose \(1.5 m, 2 m, 0 rad\) to pose \(4.5 m"
        ) as info:
            planner.plan((1.5, 2.0), (4.5, 2.0), start_heading=0.0, goal_heading=0.0)
        elapsed.append(time.perf_counter() - t0)
    assert "disconnected" in str(info.value)
    assert min(elapsed[1:]) < 0.05, elapsed  # the best warm run: the machine is shared


def test_a_goal_pose_the_body_cannot_stand_at_is_refused_at_once():
    import time

    from tests.trajopt.planning.test_car import bay_grid, body_car
    from trajopt.errors import InvalidInputError

    planner = trajopt.Planner(bay_grid(), body_car())
    t0 = time.perf_counter()
    with pytest.raises(InvalidInputError, match=r"goal pose \(2.225, 0.3\) m, heading 0 rad"):
        planner.plan((1.0, 2.0), (2.225, 0.3), start_heading=0.0, goal_heading=0.0)
    assert time.perf_counter() - t0 < 0.05
