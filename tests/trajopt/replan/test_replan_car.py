"""Tests of trajopt.replan: re-planning a car-like robot (``Robot(drive="ackermann")``): keep, or brake and plan anew.

Checked independently of the planner: the braking piece's points against a dense polyline of
the old curve (point-to-segment distances), the end pose against the goal, curvature by
circles through three dense points (:func:`tests.reference.three_point_curvature`),
clearance by brute force against the updated raw grid
(:func:`tests.reference.square_clearance`), and "no turn in place" by finite differences of
the samples: the heading changes by at most the distance moved over ``R`` (so never while
the car stands).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import astar
import trajopt
import trajopt.planning._car_fit as car_fit
from tests.reference import square_clearance, three_point_curvature
from trajopt.errors import InvalidInputError, NoPathError, TimingError

RES = 0.05
TWO_PI = 2.0 * math.pi


def walled(width: float, height: float) -> np.ndarray:
    """Occupancy (ny, nx) of a ``width x height`` m room with a one-cell wall round it."""
    occ = np.zeros((round(height / RES), round(width / RES)), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    return occ


def with_block(occ: np.ndarray, x0: float, x1: float, y0: float, y1: float) -> astar.OccupancyGrid:
    """The map ``occ`` with the box ``[x0, x1] x [y0, y1]`` m occupied (a new obstacle)."""
    out = occ.copy()
    out[round(y0 / RES) : round(y1 / RES), round(x0 / RES) : round(x1 / RES)] = True
    return astar.OccupancyGrid(out, RES)


CAR = trajopt.Robot(drive="ackermann", min_turning_radius=0.5, wheelbase=0.3, v_max_reverse=0.3)


def forward_scene():
    """Driving forwards along a room; a block appears on the way, ahead of the car."""
    occ = walled(8.0, 4.0)
    planner = trajopt.Planner(astar.OccupancyGrid(occ, RES), CAR)
    goal = (7.0, 2.0)
    traj = planner.plan((1.0, 2.0), goal, start_heading=0.0, goal_heading=0.0)
    new = with_block(occ, 4.5, 4.9, 1.6, 2.4)
    return planner, traj, new, goal, 0.0, 3.0


def reverse_scene():
    """Backing 4 m straight to a goal behind; a block appears on the way."""
    occ = walled(8.0, 5.0)
    planner = trajopt.Planner(astar.OccupancyGrid(occ, RES), CAR)
    goal = (1.5, 2.5)
    traj = planner.plan((5.5, 2.5), goal, start_heading=0.0, goal_heading=0.0)
    new = with_block(occ, 2.9, 3.2, 2.3, 2.7)
    return planner, traj, new, goal, 0.0, 4.0


@pytest.fixture(scope="module")
def forward():
    planner, traj, new, goal, h1, ts = forward_scene()
    out = planner.replan(traj, ts, grid=new, latency=0.0)
    return traj, out, new, goal, h1, ts


@pytest.fixture(scope="module")
def reverse():
    planner, traj, new, goal, h1, ts = reverse_scene()
    out = planner.replan(traj, ts, grid=new, latency=0.0)
    return traj, out, new, goal, h1, ts


def _angle_diff(a, b):
    return np.abs(np.remainder(np.asarray(a) - b + math.pi, TWO_PI) - math.pi)


def _dense(piece, spacing=0.002):
    n = max(3, math.ceil(piece.length / spacing) + 1)
    return np.asarray(piece.path(piece.path.u_at_s(np.linspace(0.0, piece.length, n))))


def _polyline_distance(pts: np.ndarray, line: np.ndarray) -> np.ndarray:
    """Distance from each point to the polyline ``line`` (brute force over its segments)."""
    a, b = line[:-1], line[1:]
    ab = b - a
    out = np.empty(len(pts))
    for k, p in enumerate(pts):
        w = np.clip(np.sum((p - a) * ab, axis=1) / np.sum(ab * ab, axis=1), 0.0, 1.0)
        out[k] = np.hypot(*(a + w[:, None] * ab - p).T).min()
    return out


def _check_new_plan(out, grid, goal, h1, robot=CAR):
    """End pose exact, curvature within 1/R, clear of ``grid``, no turn in place."""
    end = out.sample(np.array([out.duration]))
    np.testing.assert_allclose([end.x[0], end.y[0]], goal, atol=1e-9)
    assert _angle_diff(end.theta[0], h1) < 1e-6
    assert abs(end.v[0]) <= 1e-12  # at rest (a cubic phase ends at 0 up to round-off)
    kmax = 1.0 / robot.drive.min_turning_radius
    for piece in out.pieces:
        pts = _dense(piece)
        assert three_point_curvature(pts).max() <= kmax * (1.0 + 1e-6)
        clr = square_clearance(grid, pts, reach=robot.radius + 0.1)
        assert clr.min() >= robot.radius - 1e-9, clr.min()
    _check_no_turn_in_place(out, robot)


def _check_no_turn_in_place(out, robot=CAR):
    dt = 1e-3
    t = np.arange(0.0, out.duration, dt)
    smp = out.sample(t)
    # sampled: the yaw rate is zero wherever the speed is (up to rounding: |omega| = |v kappa|
    # <= |v| / R)
    still = np.abs(smp.v) <= 1e-9
    bound = 1e-9 * max(1.0, 1.0 / robot.drive.min_turning_radius)
    assert np.abs(smp.omega[still]).max(initial=0.0) <= bound
    # by finite differences: the heading turns by at most the distance moved over R
    moved = np.hypot(np.diff(smp.x), np.diff(smp.y))
    turned = _angle_diff(smp.theta[1:], smp.theta[:-1])
    assert np.all(turned <= moved / robot.drive.min_turning_radius * (1.0 + 1e-3) + 1e-9)
    # and it moves along its heading, forwards or backwards
    assert np.all(smp.v * smp.direction >= -1e-12)


def _check_splice(traj, out, ts):
    old = traj.sample(np.array([ts]))
    new = out.sample(np.array([0.0]))
    for f in ("x", "y", "v", "a", "omega", "direction"):
        np.testing.assert_allclose(getattr(new, f), getattr(old, f), atol=1e-9)
    assert _angle_diff(new.theta[0], old.theta[0]) < 1e-9


def _check_brake(traj, out, ts, direction):
    """The first piece brakes along the old curve, keeping the direction, v monotone to 0."""
    brake = out.pieces[0]
    assert out.stats["replan"].startswith("braked: cells blocked")
    assert brake.direction == direction
    i, _ = traj.piece_at(ts)
    line = _dense(traj.pieces[i], 0.001)
    t = np.linspace(0.0, brake.duration, 400)
    smp = brake.sample(t)
    pts = np.column_stack([smp.x, smp.y])
    assert _polyline_distance(pts, line).max() < 1e-6
    assert np.all(smp.direction == direction)
    v = smp.v * direction  # the speed along the direction of travel
    assert np.all(np.diff(v) <= 1e-12) and v[0] > 0.1 and v[-1] == 0.0
    assert out.stats["brake_m"] == pytest.approx(brake.length)
    # the new plan starts where the brake ends, at rest, with the body's heading
    assert out.pieces[1].sample(np.array([0.0])).v[0] == 0.0
    j = out.piece_times[1]
    at = out.sample(np.array([j - 1e-9, j]))
    assert abs(at.v[0]) < 1e-6 and at.v[1] == 0.0


def test_forward_rebrakes_along_the_old_curve_and_plans_round_the_block(forward):
    traj, out, new, goal, h1, ts = forward
    assert traj.sample(np.array([ts])).v[0] > 0.1
    assert isinstance(out, trajopt.TrajectoryChain)
    _check_splice(traj, out, ts)
    _check_brake(traj, out, ts, +1)
    _check_new_plan(out, new, goal, h1)
    assert out.stats["splice_time_s"] == ts


def test_reverse_brakes_backwards_and_plans_from_the_body_heading(reverse):
    traj, out, new, goal, h1, ts = reverse
    assert traj.sample(np.array([ts])).v[0] < -0.1  # backing up
    _check_splice(traj, out, ts)
    _check_brake(traj, out, ts, -1)
    _check_new_plan(out, new, goal, h1)
    # the stop's heading is the body's (about 0 here), not the travel tangent (about pi)
    stop = out.pieces[0].sample(np.array([out.pieces[0].duration]))
    assert _angle_diff(stop.theta[0], 0.0) < 1e-6


def test_at_rest_plans_from_its_pose_without_braking():
    planner, traj, new, goal, h1, _ = forward_scene()
    out = planner.replan(traj, 0.0, grid=new, latency=0.0)
    assert out.stats["replan"].startswith("planned: cells blocked")
    assert out.stats["brake_m"] == 0.0 and out.stats["turn_s"] == 0.0
    _check_splice(traj, out, 0.0)
    _check_new_plan(out, new, goal, h1)


def test_at_a_cusp_plans_from_the_cusp_pose():
    occ = walled(4.1, 1.2)
    grid = astar.OccupancyGrid(occ, RES)
    robot = trajopt.Robot(drive="ackermann", min_turning_radius=0.6, wheelbase=0.4)
    planner = trajopt.Planner(grid, robot)
    traj = planner.plan((1.5, 0.6), (1.6, 0.6), start_heading=0.0, goal_heading=math.pi)
    assert len(traj.pieces) >= 2
    tc = float(traj.piece_times[1])
    out = planner.replan(traj, tc, latency=0.0, reuse=False)
    assert out.stats["replan"] == "planned: reuse=False"
    _check_splice(traj, out, tc)
    _check_new_plan(out, grid, (1.6, 0.6), math.pi, robot)


def test_a_rest_still_clear_is_kept():
    planner, traj, _, goal, h1, ts = forward_scene()
    occ = np.asarray(planner.grid.occupied)
    far = with_block(occ, 6.5, 7.0, 0.3, 0.6)  # a corner far from the path
    out = planner.replan(traj, ts, grid=far, latency=0.0)
    assert out.stats["replan"] == "kept"
    assert out.duration == pytest.approx(traj.duration - ts, abs=1e-12)
    t = np.linspace(0.0, out.duration, 501)
    a, b = out.sample(t), traj.sample(t + ts)
    for f in ("x", "y", "theta", "v", "a", "omega", "kappa", "direction"):
        np.testing.assert_allclose(getattr(a, f), getattr(b, f), atol=1e-9, err_msg=f)
    # the kept rest remembers the map it was checked on: a second re-plan keeps it again
    again = planner.replan(out, 1.0, latency=0.0)
    assert again.stats["replan"] == "kept"
    # the same map, re-planned without reuse, brakes and plans anew
    fresh = planner.replan(traj, ts, latency=0.0, reuse=False)
    assert fresh.stats["replan"] == "braked: reuse=False"
    _check_new_plan(fresh, far, goal, h1)


def test_a_replan_of_a_replan_keeps_the_braking_chain(forward):
    traj, out, new, goal, h1, _ = forward
    planner = trajopt.Planner(new, CAR)
    again = planner.replan(out, 0.2, latency=0.0)
    assert again.stats["replan"] == "kept"
    assert again.duration == pytest.approx(out.duration - 0.2, abs=1e-12)
    # during the brake, a new goal: it brakes on along the braking piece, then plans
    other = planner.replan(out, 0.2, (6.5, 3.0), goal_heading=math.pi / 2, latency=0.0)
    assert other.stats["replan"] == "braked: new goal"
    _check_new_plan(other, new, (6.5, 3.0), math.pi / 2)


def test_the_other_drives_keep_their_replan():
    # a differential robot's replan is unchanged by the car's branch: it plans smoothly
    grid = astar.OccupancyGrid(walled(8.0, 4.0), RES)
    planner = trajopt.Planner(grid, trajopt.Robot())
    traj = planner.plan((1.0, 2.0), (7.0, 2.0))
    out = planner.replan(traj, 2.0, latency=0.0, reuse=False)
    assert out.stats["replan"] == "planned: reuse=False"


# ------------------------------------------------------------------ bad input
def test_bad_inputs_are_typed(forward):
    traj, _, new, *_ = forward
    planner = trajopt.Planner(new, CAR)
    with pytest.raises(InvalidInputError, match="v_end must be 0 for a car-like robot"):
        planner.replan(traj, 1.0, v_end=0.2, latency=0.0)
    with pytest.raises(InvalidInputError, match="goal_heading .* is required with a new goal"):
        planner.replan(traj, 1.0, (6.0, 3.0), latency=0.0)
    with pytest.raises(InvalidInputError, match="goal_heading must be finite"):
        planner.replan(traj, 1.0, (6.0, 3.0), goal_heading=math.nan, latency=0.0)
    with pytest.raises(InvalidInputError, match="past the trajectory's end"):
        planner.replan(traj, traj.duration, latency=0.5)
    with pytest.raises(InvalidInputError, match="goal .* outside the map"):
        planner.replan(traj, 1.0, (9.0, 2.0), goal_heading=0.0, latency=0.0)
    diff = trajopt.Planner(new, trajopt.Robot()).plan((1.0, 1.0), (3.0, 1.0))
    with pytest.raises(InvalidInputError, match="needs the trajectory of a car plan"):
        planner.replan(diff, 1.0, (3.0, 1.0), goal_heading=0.0, latency=0.0)
    other = trajopt.Planner(new, trajopt.Robot(drive="ackermann", min_turning_radius=0.8))
    with pytest.raises(InvalidInputError, match="planned for another robot"):
        other.replan(traj, 1.0, latency=0.0)


def test_a_block_too_close_to_stop_before_is_a_timing_error():
    planner, traj, _, *_ = forward_scene()
    ts = 3.0
    x = float(traj.sample(np.array([ts])).x[0])
    occ = np.asarray(planner.grid.occupied)
    near = with_block(occ, x + 0.25, x + 0.5, 1.8, 2.2)  # closer than the braking distance
    with pytest.raises(TimingError, match="cannot stop before an obstacle"):
        planner.replan(traj, ts, grid=near, latency=0.0)


def test_a_goal_walled_in_is_a_no_path_error_saying_where_the_car_stopped():
    planner, traj, _, *_ = forward_scene()
    occ = np.asarray(planner.grid.occupied).copy()
    # a ring round the goal (7, 2): the goal stays clear, nothing reaches it
    occ[round(1.2 / RES) : round(2.8 / RES), round(6.2 / RES)] = True
    occ[round(1.2 / RES), round(6.2 / RES) :] = True
    occ[round(2.8 / RES), round(6.2 / RES) :] = True
    with pytest.raises(NoPathError, match=r"planned from rest at pose .* after braking"):
        planner.replan(traj, 3.0, grid=astar.OccupancyGrid(occ, RES), latency=0.0)


def test_at_the_goal_pose_nothing_is_left_to_drive():
    planner, traj, new, goal, h1, _ = forward_scene()
    for kw in ({}, {"reuse": False}, {"grid": new}):
        out = planner.replan(traj, traj.duration, latency=0.0, **kw)
        assert out.duration == 0.0 and out.length == 0.0
        end = out.sample(np.array([0.0]))
        np.testing.assert_allclose([end.x[0], end.y[0]], goal, atol=1e-9)
        assert _angle_diff(end.theta[0], h1) < 1e-9 and end.v[0] == 0.0


def test_forward_only_car_brakes_and_plans_forwards():
    occ = walled(8.0, 4.0)
    robot = trajopt.Robot(drive="ackermann", min_turning_radius=0.5, reverse=False)
    planner = trajopt.Planner(astar.OccupancyGrid(occ, RES), robot)
    traj = planner.plan((1.0, 2.0), (7.0, 2.0), start_heading=0.0, goal_heading=0.0)
    new = with_block(occ, 4.5, 4.9, 1.6, 2.4)
    out = planner.replan(traj, 3.0, grid=new, latency=0.0)
    _check_brake(traj, out, 3.0, +1)
    _check_new_plan(out, new, (7.0, 2.0), 0.0, robot)
    smp = out.sample(np.linspace(0.0, out.duration, 2001))
    assert np.all(smp.v >= 0.0) and np.all(smp.direction == 1)


def test_inside_a_stretch_fitted_in_pieces_brakes_on_its_piece(monkeypatch):
    """A forward-only loop fitted in pieces (the whole fits tried first are skipped, as when
    they fail) and driven through as one drive: a re-plan in the middle of the second piece
    brakes along the drive's curve (across the next join if need be) and plans on from
    rest."""
    monkeypatch.setattr(car_fit, "WHOLE_FIRST", ())
    grid = astar.OccupancyGrid(walled(4.0, 4.0), RES)
    robot = trajopt.Robot(radius=0.1, drive="ackermann", min_turning_radius=0.4, reverse=False)
    planner = trajopt.Planner(grid, robot)
    goal = (1.95, 2.0)
    traj = planner.plan((2.0, 2.0), goal, start_heading=-2.83, goal_heading=1.7)
    segs = traj.steps.segments
    assert segs[1].joined is True and traj.steps.drives[0][:2] == (0, 1)
    drive = traj.pieces[0]
    t = np.linspace(0.0, drive.duration, 20001)
    s_mid = segs[0].smooth_path.length + 0.5 * segs[1].smooth_path.length
    ts = float(np.interp(s_mid, drive.sample(t).s, t))  # the middle of the second piece
    out = planner.replan(traj, ts, latency=0.0, reuse=False)
    assert out.stats["replan"] == "braked: reuse=False" and out.stats["brake_m"] > 0.0
    _check_splice(traj, out, ts)
    _check_new_plan(out, grid, goal, 1.7, robot)


def test_a_body_car_brakes_and_plans_on_with_its_body_clear():
    """A rectangular car backing into a bay (``tests/trajopt/planning/test_car.py``),
    re-planned half-way without reuse: it brakes, plans on from rest, ends in the bay, and
    the brute-force body check finds no contact along the spliced chain."""
    from tests.trajopt.planning.test_car import _body_hits, bay_grid, body_car

    grid, car = bay_grid(), body_car(wheelbase=0.4)
    planner = trajopt.Planner(grid, car)
    goal = (2.225, 0.3)
    traj = planner.plan((1.0, 2.0), goal, start_heading=0.0, goal_heading=math.pi / 2)
    ts = 0.5 * traj.duration
    out = planner.replan(traj, ts, latency=0.0, reuse=False)
    assert out.stats["replan"] == "braked: reuse=False"
    _check_splice(traj, out, ts)
    smp = out.sample(np.linspace(0.0, out.duration, int(out.duration / 0.002) + 2))
    assert not _body_hits(grid, car.footprint.vertices, smp.x, smp.y, smp.theta).any()
    np.testing.assert_allclose([smp.x[-1], smp.y[-1]], goal, atol=1e-9)


@pytest.mark.parametrize("where", ["start", "cusp", "goal", "keep"])
def test_spliced_while_steering_at_rest(where):
    """A car with a steering-rate limit steers at rest at its start, cusps and goal (a
    :class:`trajopt.SteerInPlace`); a re-plan spliced half-way through one stands where it
    is and starts from the steering angle reached there: the steering angle (from the
    curvature) is continuous at the splice and its rate holds the limit on the whole re-plan,
    by finite differences."""
    occ = walled(4.1, 1.2)
    grid = astar.OccupancyGrid(occ, RES)
    robot = trajopt.Robot(
        drive="ackermann", min_turning_radius=0.6, wheelbase=0.4, steer_rate_max=1.0
    )
    planner = trajopt.Planner(grid, robot)
    traj = planner.plan(
        (1.5, 0.6), (1.6, 0.6), start_heading=0.0, goal_heading=math.pi, goal_steer=0.3
    )
    at = [d["at"] for d in traj.stats["car"]["steer_at_rest"]]
    assert at[0] == "start" and "cusp" in at and at[-1] == "goal"
    steering = [i for i, p in enumerate(traj.pieces) if p.steering_at_rest]
    i = {"start": steering[0], "cusp": steering[1], "goal": steering[-1], "keep": steering[1]}[
        where
    ]
    ts = float(0.5 * (traj.piece_times[i] + traj.piece_times[i + 1]))
    out = planner.replan(traj, ts, latency=0.0, reuse=where == "keep")
    why = {"keep": "kept", "goal": "planned: reuse=False; at the goal pose"}
    assert out.stats["replan"] == why.get(where, "planned: reuse=False")
    _check_splice(traj, out, ts)
    old, new = traj.sample(np.array([ts])), out.sample(np.array([0.0]))
    assert new.steer[0] == pytest.approx(old.steer[0], abs=1e-12)
    assert out.pieces[0].steering_at_rest  # it finishes steering where it stands
    end = out.sample(np.array([out.duration]))
    np.testing.assert_allclose([end.x[0], end.y[0]], (1.6, 0.6), atol=1e-9)
    assert end.steer[0] == pytest.approx(0.3, abs=1e-12)  # the old goal_steer is kept
    t = np.unique(np.concatenate([np.arange(0.0, out.duration, 5e-4), out.piece_times]))
    smp = out.sample(t)
    delta = np.arctan(robot.drive.wheelbase * np.asarray(smp.kappa))
    assert (np.abs(np.diff(delta)) / np.diff(t)).max() <= 1.0 * (1.0 + 1e-6)
    _check_no_turn_in_place(out, robot)
