"""Tests of trajopt.planning: car-like robots (``Robot(drive="ackermann")``) end to end through ``trajopt.plan``.

Hand-built scenes (a goal straight behind the start, a three-point turn in a dead end
narrower than ``2 R``, a forward-only U-turn round a block, parallel parking into a slot 1.3
car lengths long as a disc and as a 0.88 x 0.4 m body, body cars into bays, a full-size car
into a perpendicular bay backwards and forwards), each checked independently of the planner: end poses, curvature by
circles through three dense points, clearance by brute force against the raw grid, motion
along the heading by finite differences, rest at every cusp; then bad input.
"""

from __future__ import annotations

import dataclasses
import json
import math
import time

import numpy as np
import pytest

import astar
import trajopt
import trajopt.planning._car_fit as car_fit
from tests.reference import square_clearance, three_point_curvature
from trajopt.errors import InvalidInputError, NoPathError

TWO_PI = 2.0 * math.pi


def walled(width: float, height: float, res: float) -> np.ndarray:
    """Occupancy (ny, nx) of a ``width x height`` m room with a one-cell wall round it."""
    occ = np.zeros((round(height / res), round(width / res)), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    return occ


def behind_scene():
    res = 0.05
    grid = astar.OccupancyGrid(walled(8.0, 4.0, res), res)
    robot = trajopt.Robot(drive="ackermann", min_turning_radius=0.5, v_max_reverse=0.3)
    return grid, robot, (4.0, 2.0), (2.5, 2.0), 0.0, 0.0


def three_point_scene():
    # a closed corridor 1.1 m wide (free) for R = 0.6 m: narrower than 2 R
    res = 0.05
    grid = astar.OccupancyGrid(walled(4.1, 1.2, res), res)
    robot = trajopt.Robot(
        drive="ackermann", min_turning_radius=0.6, wheelbase=0.4, steer_rate_max=1.0
    )
    return grid, robot, (1.5, 0.6), (1.6, 0.6), 0.0, math.pi


def uturn_scene():
    res = 0.05
    occ = walled(6.0, 4.0, res)
    occ[round(1.7 / res) : round(2.3 / res), : round(3.5 / res)] = True  # the block
    grid = astar.OccupancyGrid(occ, res)
    robot = trajopt.Robot(drive="ackermann", min_turning_radius=0.5, reverse=False)
    return grid, robot, (1.0, 1.0), (1.0, 3.0), 0.0, math.pi


CAR_RADIUS = 0.2  # half the car's width
CAR_LENGTH = 4.4 * CAR_RADIUS  # a car 2.2 times as long as it is wide
SLOT = 1.3 * CAR_LENGTH


def parking_scene():
    res = 0.025
    occ = walled(5.0, 1.8, res)
    occ[: round(0.65 / res), :] = True  # the kerb side: parked cars ...
    occ[round(0.1 / res) : round(0.65 / res), round(2.0 / res) : round((2.0 + SLOT) / res)] = False
    grid = astar.OccupancyGrid(occ, res)
    robot = trajopt.Robot(
        radius=CAR_RADIUS, drive="ackermann", min_turning_radius=0.5, wheelbase=0.35
    )
    return grid, robot, (1.0, 1.1), (2.0 + SLOT / 2.0, 0.33), 0.0, 0.0


BAY_WIDTH = 0.45  # m: a 0.3 m wide car with 7.5 cm each side


def bay_grid() -> astar.OccupancyGrid:
    """A 5 x 3 m yard whose lower third is solid but for one bay, 0.45 m wide and 0.9 m deep."""
    res = 0.05
    occ = walled(5.0, 3.0, res)
    occ[: round(1.0 / res), :] = True
    occ[round(0.1 / res) : round(1.0 / res), round(2.0 / res) : round((2.0 + BAY_WIDTH) / res)] = (
        False
    )
    return astar.OccupancyGrid(occ, res)


def body_car(**kw) -> trajopt.Robot:
    """A rectangular car 0.6 x 0.3 m, its rear axle (the reference point) 0.1 m from the back."""
    return trajopt.Robot.rectangle(
        0.6, 0.3, rear_offset=0.1, drive="ackermann", min_turning_radius=0.6, **kw
    )


def bay_reverse_scene():
    # backed into the bay: the rear axle 0.2 m above the bay's floor, facing out
    return bay_grid(), body_car(wheelbase=0.4), (1.0, 2.0), (2.225, 0.3), 0.0, math.pi / 2


def bay_forward_scene():
    # driven nose first into the bay
    return bay_grid(), body_car(), (1.0, 2.0), (2.225, 0.65), 0.0, -math.pi / 2


def three_point_body_scene():
    # the dead end of three_point_scene (1.1 m wide, narrower than 2 R = 1.2 m), a body car
    grid, *_ = three_point_scene()
    robot = trajopt.Robot.rectangle(
        0.5, 0.3, rear_offset=0.1, drive="ackermann", min_turning_radius=0.6, wheelbase=0.4
    )
    return grid, robot, (1.5, 0.6), (1.6, 0.6), 0.0, math.pi


# a 0.88 x 0.4 m car (rear axle 0.18 m from its back, R = 0.5 m) backed into the parking
# scene's slot, 1.3 of its lengths long: the body, not a disc
PARK_CAR = (CAR_LENGTH, 2.0 * CAR_RADIUS, 0.18)


def parallel_body_scene():
    grid, *_ = parking_scene()
    length, width, rear = PARK_CAR
    robot = trajopt.Robot.rectangle(
        length,
        width,
        rear_offset=rear,
        drive=trajopt.Ackermann(min_turning_radius=0.5, wheelbase=0.35),
    )
    goal = (2.0 + 0.5 * (SLOT - length) + rear, 0.1 + 0.5 * 0.55)
    return grid, robot, (1.0, 1.1), goal, 0.0, 0.0


# a full-size car of the public parking cases: 4.69 x 1.94 m, rear axle 0.96 m from its back,
# wheelbase 2.8 m, R = 3.0 m; a perpendicular bay 1.3 car widths wide off a 5.5 m aisle, 0.1 m
# cells
FULL_CAR = (4.69, 1.94, 0.96)
FULL_BAY = 1.3 * FULL_CAR[1]


def full_bay_grid() -> astar.OccupancyGrid:
    """A 22 x 11 m yard: parked cars 5.2 m deep below a 5.5 m aisle, one bay free at x = 9 m."""
    res = 0.1
    occ = walled(22.0, 11.0, res)
    occ[: round(5.3 / res), :] = True
    occ[1 : round(5.3 / res), round(9.0 / res) : round((9.0 + FULL_BAY) / res)] = False
    return astar.OccupancyGrid(occ, res)


def full_car() -> trajopt.Robot:
    length, width, rear = FULL_CAR
    return trajopt.Robot.rectangle(
        length,
        width,
        rear_offset=rear,
        drive=trajopt.Ackermann(min_turning_radius=3.0, wheelbase=2.8),
    )


def full_bay_reverse_scene():
    # backed in, facing out of the bay: its rear edge 0.3 m from the bay's end
    _, _, rear = FULL_CAR
    x = 9.0 + 0.5 * FULL_BAY
    return full_bay_grid(), full_car(), (3.0, 8.05), (x, 0.4 + rear), 0.0, math.pi / 2


def full_bay_forward_scene():
    # driven nose first: its front edge 0.3 m from the bay's end
    length, _, rear = FULL_CAR
    x = 9.0 + 0.5 * FULL_BAY
    return full_bay_grid(), full_car(), (3.0, 8.05), (x, 0.4 + length - rear), 0.0, -math.pi / 2


SCENES = {
    "behind": behind_scene,
    "three_point": three_point_scene,
    "uturn": uturn_scene,
    "parking": parking_scene,
    "bay_reverse": bay_reverse_scene,
    "bay_forward": bay_forward_scene,
    "three_point_body": three_point_body_scene,
    "parallel_body": parallel_body_scene,
    "full_bay_reverse": full_bay_reverse_scene,
    "full_bay_forward": full_bay_forward_scene,
}


@pytest.fixture(scope="module")
def planned():
    out = {}
    for name, make in SCENES.items():
        grid, robot, start, goal, h0, h1 = make()
        t0 = time.perf_counter()
        traj = trajopt.plan(grid, start, goal, robot, start_heading=h0, goal_heading=h1)
        out[name] = (grid, robot, start, goal, h0, h1, traj, time.perf_counter() - t0)
    return out


def _angle_diff(a, b):
    return np.abs(np.remainder(np.asarray(a) - b + math.pi, TWO_PI) - math.pi)


def _drives(traj):
    """The pieces of a car's chain that move (not its steering at rest)."""
    return [p for p in traj.pieces if not p.steering_at_rest]


def _dense_points(traj, spacing):
    """Points every ``spacing`` m of arc length along each drive's curve (and its ends)."""
    out = []
    for piece in _drives(traj):
        n = max(3, math.ceil(piece.length / spacing) + 1)
        s = np.linspace(0.0, piece.length, n)
        out.append(np.asarray(piece.path(piece.path.u_at_s(s))))
    return out


@pytest.mark.parametrize("name", list(SCENES))
def test_end_poses_exact(planned, name):
    grid, robot, start, goal, h0, h1, traj, _ = planned[name]
    assert isinstance(traj, trajopt.TrajectoryChain)
    ends = traj.sample(np.array([0.0, traj.duration]))
    np.testing.assert_allclose([ends.x[0], ends.y[0]], start, atol=1e-9)
    np.testing.assert_allclose([ends.x[1], ends.y[1]], goal, atol=1e-9)
    assert _angle_diff(ends.theta[0], h0) < 1e-6
    assert _angle_diff(ends.theta[1], h1) < 1e-6
    np.testing.assert_array_equal(ends.v, [0.0, 0.0])


@pytest.mark.parametrize("name", list(SCENES))
def test_curvature_within_one_over_r(planned, name):
    _, robot, *_, traj, _ = planned[name]
    kmax = 1.0 / robot.drive.min_turning_radius
    for pts in _dense_points(traj, 0.002):
        k = three_point_curvature(pts)
        assert k.max() <= kmax * (1.0 + 1e-6), (k.max(), kmax)


def _body_hits(grid, vertices, x, y, th, spacing=0.005):
    """Poses whose body meets an occupied cell (or leaves the map), by brute force.

    The body is the convex polygon ``vertices`` (robot frame, m) turned by ``th`` and moved
    to ``(x, y)``. It meets a square iff a point of its boundary lies in the square or the
    square lies inside it (then so does its centre): the boundary is sampled every
    ``spacing`` m and looked up in the grid, and every occupied cell's centre within the
    body's circumscribed radius plus a cell of the pose is tested against the polygon's
    half-planes.
    """
    v = np.asarray(vertices, dtype=float)
    nxt = np.roll(v, -1, axis=0)
    edge = nxt - v
    n = np.maximum(1, np.ceil(np.hypot(*edge.T) / spacing).astype(int))
    boundary = np.vstack(
        [v[i] + np.linspace(0, 1, n[i], endpoint=False)[:, None] * edge[i] for i in range(len(v))]
    )
    area2 = np.sum(v[:, 0] * nxt[:, 1] - nxt[:, 0] * v[:, 1])
    normal = np.column_stack([edge[:, 1], -edge[:, 0]]) * np.sign(area2)  # outward
    offset = np.sum(normal * v, axis=1)
    occ = np.asarray(grid.occupied)
    ny, nx = occ.shape
    ox, oy = grid.origin
    res = grid.resolution
    reach = float(np.hypot(v[:, 0], v[:, 1]).max()) + res
    x, y, th = (np.asarray(a, dtype=float) for a in (x, y, th))
    cy, cx = np.nonzero(occ)
    cx, cy = ox + (cx + 0.5) * res, oy + (cy + 0.5) * res  # the occupied cells' centres
    pad = np.ones((ny + 2, nx + 2), dtype=bool)  # the grid in a ring of occupied cells
    pad[1:-1, 1:-1] = occ
    pad = pad.ravel()
    hits = np.zeros(len(x), dtype=bool)
    # a chunk of poses at a time, as (poses, points) arrays; a boundary point's cell (jx, jy),
    # clipped to the ring outside the grid, is pad[jy + 1, jx + 1]
    for k in range(0, len(x), 64):
        xk, yk = x[k : k + 64, None], y[k : k + 64, None]
        c, s_ = np.cos(th[k : k + 64, None]), np.sin(th[k : k + 64, None])
        jx = np.floor((c * boundary[:, 0] - s_ * boundary[:, 1] + xk - ox) / res)
        jy = np.floor((s_ * boundary[:, 0] + c * boundary[:, 1] + yk - oy) / res)
        np.clip(jx, -1, nx, out=jx)
        np.clip(jy, -1, ny, out=jy)
        jy += 1
        jy *= nx + 2
        jy += jx + 1
        hit = pad[jy.astype(np.intp)].any(axis=1)
        # the occupied cells in reach of the chunk's box (no centre farther lies inside a body)
        near = (cx >= xk.min() - reach) & (cx <= xk.max() + reach)
        near &= (cy >= yk.min() - reach) & (cy <= yk.max() + reach)
        dx, dy = cx[near] - xk, cy[near] - yk
        lx, ly = dx * c + dy * s_, dx * -s_ + dy * c  # into the body frame
        inside = np.ones(lx.shape, dtype=bool)
        for (n0, n1), off in zip(normal, offset, strict=True):
            inside &= lx * n0 + ly * n1 <= off
        hits[k : k + 64] = hit | inside.any(axis=1)
    return hits


@pytest.mark.parametrize("name", list(SCENES))
def test_clearance_against_raw_grid(planned, name):
    grid, robot, *_, traj, _ = planned[name]
    if robot.footprint is None:
        for pts in _dense_points(traj, 0.002):
            clr = square_clearance(grid, pts, reach=robot.radius + 0.1)
            assert clr.min() >= robot.radius - 1e-9, clr.min()
        return
    # the body along the trajectory, every 2 mm of arc length at most (|v| <= v_max)
    v_top = max(robot.v_max, robot.drive.v_max_reverse or 0.0)
    smp = traj.sample(np.linspace(0.0, traj.duration, int(traj.duration * v_top / 0.002) + 2))
    assert np.abs(np.diff(smp.s)).max() <= 0.002 + 1e-9
    hits = _body_hits(grid, robot.footprint.vertices, smp.x, smp.y, smp.theta)
    assert not hits.any(), np.column_stack([smp.t, smp.x, smp.y, smp.theta])[hits][:3]


@pytest.mark.parametrize("name", list(SCENES))
def test_moves_along_its_heading_and_rests_at_cusps(planned, name):
    _, robot, *_, traj, _ = planned[name]
    dt = 1e-4
    t = np.linspace(dt, traj.duration - dt, 3001)
    smp = traj.sample(t)
    before, after = traj.sample(t - dt), traj.sample(t + dt)
    vel = np.stack([(after.x - before.x), (after.y - before.y)], axis=1) / (2.0 * dt)
    along = np.stack([smp.v * np.cos(smp.theta), smp.v * np.sin(smp.theta)], axis=1)
    np.testing.assert_allclose(vel, along, atol=2e-3)
    # the body's curvature is omega / v, and the direction is the sign of v
    moving = np.abs(smp.v) > 1e-3
    np.testing.assert_allclose(smp.kappa[moving], smp.omega[moving] / smp.v[moving], rtol=1e-9)
    assert np.all(smp.v * smp.direction >= -1e-12)
    # v = 0 at every join; a join flips the direction (a cusp) unless it splits a stretch
    joins = traj.piece_times[1:-1]
    at = traj.sample(joins)
    np.testing.assert_array_equal(at.v, np.zeros(len(joins)))
    dirs = [p.direction for p in _drives(traj)]
    segs = traj.steps.segments
    drives = traj.steps.drives
    assert len(drives) == len(_drives(traj))
    assert [i for g in drives for i in g] == list(range(len(segs)))
    # a piece starts at a cusp, or at a join the car rests at (curvatures that differ)
    joined = [segs[g[0]].joined for g in drives]
    flips = [a != b for a, b in zip(dirs[:-1], dirs[1:], strict=True)]
    assert flips == [not j for j in joined[1:]]
    assert all(segs[i].joined for g in drives for i in g[1:])  # driven through
    assert traj.stats["car"]["rests"] == sum(joined[1:])
    assert traj.stats["car"]["cusps"] == sum(flips)
    # the heading is continuous: no jump between dense samples
    assert np.abs(np.diff(smp.theta)).max() < 0.05


def test_goal_behind_reverses_with_theta_the_tangent_plus_pi(planned):
    _, robot, _, _, _, _, traj, _ = planned["behind"]
    smp = traj.sample(np.linspace(0.0, traj.duration, 2001))
    assert np.all(smp.v <= 0.0) and smp.v.min() < -0.1
    assert np.all(smp.direction == -1)
    assert -smp.v.min() <= robot.drive.v_max_reverse * (1.0 + 1e-9)
    # travel direction from finite differences is the body's heading plus pi
    mid = slice(100, -100)
    dx, dy = np.diff(smp.x)[mid], np.diff(smp.y)[mid]
    tangent = np.arctan2(dy, dx)
    assert _angle_diff(tangent, smp.theta[:-1][mid] + math.pi).max() < 1e-3


def test_three_point_turn_has_cusps(planned):
    _, robot, *_, traj, _ = planned["three_point"]
    assert traj.stats["car"]["cusps"] >= 1
    assert -1 in [p.direction for p in _drives(traj)]
    smp = traj.sample(np.linspace(0.0, traj.duration, 4001))
    assert smp.v.min() < 0.0 < smp.v.max()
    # the steering angle is atan(wheelbase * kappa); its rate holds steer_rate_max within
    # each piece (at a cusp the car steers at rest, a piece of its own): the cap table's
    # caps are rigorous bounds, so on 40 001 samples per piece the rate, and its finite
    # differences, stay within the limit
    np.testing.assert_allclose(smp.steer, np.arctan(robot.drive.wheelbase * smp.kappa), atol=1e-12)
    for i in range(len(traj.pieces)):  # the drives and the steering at rest between them
        t0, t1 = traj.piece_times[i], traj.piece_times[i + 1]
        tt = np.linspace(t0 + 1e-6, t1 - 1e-6, 40001)
        at = traj.sample(tt)
        assert np.abs(at.steer_rate).max() <= robot.drive.steer_rate_max * (1 + 1e-9)
        rate = np.abs(np.diff(at.steer)) / np.diff(tt)
        assert rate.max() <= robot.drive.steer_rate_max * (1 + 1e-6), (i, rate.max())


STEER_RATE = 1.0  # rad/s


def steered_car(robot):
    """The scene's car with a wheelbase (its own, else 0.8 R) and a steering-rate limit."""
    wb = robot.drive.wheelbase or 0.8 * robot.drive.min_turning_radius
    drive = dataclasses.replace(robot.drive, wheelbase=wb, steer_rate_max=STEER_RATE)
    return dataclasses.replace(robot, drive=drive)


@pytest.fixture(scope="module")
def steered():
    """Every scene planned by its car with a steering-rate limit; the start steering is 0,
    and for the odd scenes 0.3 of the largest angle with a goal steering of -0.5 of it."""
    out = {}
    for k, (name, make) in enumerate(SCENES.items()):
        grid, robot, start, goal, h0, h1 = make()
        car = steered_car(robot)
        top = math.atan(car.drive.wheelbase / car.drive.min_turning_radius)
        ends = {"start_steer": 0.3 * top, "goal_steer": -0.5 * top} if k % 2 else {}
        traj = trajopt.Planner(grid, car).plan(
            start, goal, start_heading=h0, goal_heading=h1, **ends
        )
        out[name] = (car, ends, traj)
    return out


def geometric_steer(traj, t, wheelbase):
    """The steering angle ``atan(L kappa_body)`` at chain times ``t``, from the geometry.

    While a drive plays, the curvature of its own curve at the arc length it has reached
    (the body's: negated backwards), not the samples' ``kappa`` nor ``steer_rate``; while
    the car stands, the steering at rest's angle (its sampled curvature, the one place the
    steering is not seen in the path).
    """
    out = np.empty(len(t))
    times = traj.piece_times
    k = np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(traj.pieces) - 1)
    for i in np.unique(k):
        m = k == i
        piece, tau = traj.pieces[i], t[m] - times[i]
        if piece.steering_at_rest:
            kappa = np.asarray(piece.sample(tau).kappa)
        else:
            s = piece.motion(tau)[0]
            kappa = piece.direction * np.asarray(piece.path.curvature(piece.path.u_at_s(s)))
        out[m] = np.arctan(wheelbase * kappa)
    return out


@pytest.mark.parametrize("name", list(SCENES))
def test_steering_rate_holds_across_every_join(steered, name):
    """|d steer / dt| <= steer_rate_max everywhere, the joins included, by finite differences
    of the geometric steering angle; the car steers at rest at every join where the angle
    differs, and starts (and ends, when asked) with the steering angle asked for."""
    car, ends, traj = steered[name]
    wb = car.drive.wheelbase
    dt = 5e-4
    t = np.concatenate([np.arange(0.0, traj.duration, dt), [traj.duration]])
    t = np.unique(np.concatenate([t, traj.piece_times]))  # every join exactly
    delta = geometric_steer(traj, t, wb)
    rate = np.abs(np.diff(delta)) / np.diff(t)
    assert rate.max() <= STEER_RATE * (1.0 + 1e-6), (name, rate.max(), t[np.argmax(rate)])
    assert delta[0] == pytest.approx(ends.get("start_steer", 0.0), abs=1e-9)
    if "goal_steer" in ends:
        assert delta[-1] == pytest.approx(ends["goal_steer"], abs=1e-9)
    # at rest while steering: v = 0, the pose still, steer_rate the profile's
    for i, piece in enumerate(traj.pieces):
        if piece.steering_at_rest:
            tt = np.linspace(traj.piece_times[i], traj.piece_times[i + 1], 50)
            smp = traj.sample(tt)
            assert np.all(smp.v == 0.0) and np.ptp(smp.x) == 0.0 and np.ptp(smp.theta) == 0.0
            assert np.abs(smp.steer_rate[:-1]).max() == pytest.approx(STEER_RATE)
    kinds = [d["at"] for d in traj.stats["car"]["steer_at_rest"]]
    assert len(kinds) == sum(p.steering_at_rest for p in traj.pieces)
    assert kinds.count("cusp") <= traj.stats["car"]["cusps"]


def test_steering_at_rest_refusals():
    grid, robot, start, goal, h0, h1 = behind_scene()
    top = math.atan(0.4 / 0.5)
    car = steered_car(
        dataclasses.replace(robot, drive=dataclasses.replace(robot.drive, wheelbase=0.4))
    )
    with pytest.raises(InvalidInputError, match=r"start_steer=0.9 rad exceeds .* largest steering"):
        trajopt.plan(grid, start, goal, car, start_heading=h0, goal_heading=h1, start_steer=0.9)
    assert top < 0.9
    with pytest.raises(
        InvalidInputError, match=r"goal_steer=0.1 rad: a steering angle needs a car"
    ):
        trajopt.plan(grid, start, goal, robot, start_heading=h0, goal_heading=h1, goal_steer=0.1)
    with pytest.raises(InvalidInputError, match="start_steer must be finite"):
        trajopt.plan(
            grid, start, goal, car, start_heading=h0, goal_heading=h1, start_steer=math.nan
        )
    disc = trajopt.Robot()
    with pytest.raises(InvalidInputError, match="start_steer=0.2 rad: a steering angle needs"):
        trajopt.plan(grid, start, goal, disc, start_steer=0.2)


def test_without_a_steering_rate_limit_the_steering_is_not_modelled(planned):
    # the parking car has a wheelbase and no steer_rate_max: no steering at rest
    *_, traj, _ = planned["parking"]
    assert not any(p.steering_at_rest for p in traj.pieces)
    assert traj.stats["car"]["steer_at_rest"] == []


def test_forward_only_uturn_never_reverses(planned):
    _, robot, *_, traj, _ = planned["uturn"]
    assert not robot.drive.reverse
    smp = traj.sample(np.linspace(0.0, traj.duration, 2001))
    assert np.all(smp.v >= 0.0) and np.all(smp.direction == 1)
    assert traj.stats["car"]["cusps"] == 0
    assert smp.x.max() > 3.5  # round the block's end (x = 3.5 m)


def test_parallel_parking_ends_in_the_slot(planned):
    grid, robot, *_, traj, _ = planned["parking"]
    assert SLOT / CAR_LENGTH == pytest.approx(1.3)
    smp = traj.sample(np.linspace(0.0, traj.duration, 2001))
    assert smp.v.min() < 0.0  # it backs in
    np.testing.assert_allclose(smp.steer, np.arctan(robot.drive.wheelbase * smp.kappa), atol=1e-12)


def test_plans_are_quick(planned):
    # warm (the first scene paid numba's load): a few hundred ms each at most
    for name, (*_, seconds) in list(planned.items())[1:]:
        assert seconds < 3.0, (name, seconds)


def test_exports_carry_direction(planned, tmp_path):
    *_, traj, _ = planned["three_point"]
    d = traj.to_dict(0.05)
    assert set(d["samples"]["direction"]) == {-1.0, 1.0}
    assert d["units"]["steer"] == "rad"
    json.dumps(d)
    path = traj.to_csv(tmp_path / "car.csv", 0.05)
    header = path.read_text().splitlines()[0]
    assert "direction [1]" in header and "steer [rad]" in header


# ------------------------------------------------------------------ bad input
@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"drive": "ackermann"}, "min_turning_radius is required"),
        (
            {"drive": "ackermann", "min_turning_radius": 0.0},
            r"min_turning_radius must be finite and > 0",
        ),
        (
            {"drive": "ackermann", "min_turning_radius": -1.0},
            r"must be finite and > 0 \(m\), got -1",
        ),
        (
            {"drive": "ackermann", "min_turning_radius": math.inf},
            "min_turning_radius must be finite",
        ),
        (
            {"drive": "ackermann", "min_turning_radius": math.nan},
            "min_turning_radius must be finite",
        ),
        (
            {"drive": "ackermann", "wheelbase": 0.3},
            r"min_turning_radius is required .*wheelbase=0.3",
        ),
        ({"wheelbase": 0.3}, r"wheelbase=0.3 apply only to a car-like robot .*'differential'"),
        ({"drive": "omni", "min_turning_radius": 1.0}, "apply only to a car-like robot"),
        ({"reverse": False}, "reverse=False apply only to a car-like robot"),
        (
            {"drive": "ackermann", "min_turning_radius": 1.0, "v_max_reverse": 0.0},
            r"v_max_reverse must be finite and > 0 \(m/s\), got 0",
        ),
        (
            {"drive": "ackermann", "min_turning_radius": 1.0, "wheelbase": -0.1},
            r"wheelbase must be finite and > 0 \(m\)",
        ),
        (
            {"drive": "ackermann", "min_turning_radius": 1.0, "steer_rate_max": 1.0},
            "steer_rate_max=1.0 rad/s needs a wheelbase",
        ),
        ({"drive": "ackermann", "min_turning_radius": 1.0, "reverse": 1}, "reverse must be True"),
    ],
)
def test_robot_car_fields_bad_input(kwargs, match):
    with pytest.raises(InvalidInputError, match=match):
        trajopt.Robot(**kwargs)


def test_other_drives_keep_their_dict():
    assert set(trajopt.Robot().to_dict()) == {
        "radius", "v_max", "a_max", "j_max", "a_lat_max", "omega_max", "track_width",
        "wheel_v_max", "footprint", "drive",
    }  # fmt: skip
    car = trajopt.Robot(drive="ackermann", min_turning_radius=1.0).to_dict()
    assert car["min_turning_radius"] == 1.0 and car["reverse"] is True


@pytest.mark.parametrize(
    ("headings", "match"),
    [
        ({}, "needs both end headings .*start_heading and goal_heading are None"),
        ({"start_heading": 0.0}, "goal_heading is None"),
        ({"goal_heading": 0.0}, "start_heading is None"),
    ],
)
def test_car_query_needs_headings(headings, match):
    grid, robot, start, goal, *_ = behind_scene()
    with pytest.raises(InvalidInputError, match=match):
        trajopt.plan(grid, start, goal, robot, **headings)


def test_the_body_checker_sees_a_collision():
    # the reference itself: the body across the bay's side wall, and wholly round one cell
    grid = bay_grid()
    car = body_car()
    hits = _body_hits(grid, car.footprint.vertices, [2.225, 2.1, 1.0], [0.3, 0.3, 2.0], [0.0] * 3)
    assert hits.tolist() == [True, True, False]
    occ = np.zeros((40, 40), bool)
    occ[20, 20] = True  # one cell, inside the body at (1.0, 1.0) m
    inner = _body_hits(astar.OccupancyGrid(occ, 0.05), car.footprint.vertices, [1.0], [1.0], [0.3])
    assert inner.tolist() == [True]


@pytest.mark.parametrize("name", ["bay_reverse", "bay_forward"])
def test_a_body_parks_where_its_circumscribed_disc_cannot(planned, name):
    grid, robot, start, goal, h0, h1, traj, _ = planned[name]
    assert 2.0 * robot.circumscribed_radius > BAY_WIDTH  # the disc does not fit the bay
    disc = trajopt.Robot(
        radius=robot.circumscribed_radius, drive="ackermann", min_turning_radius=0.6
    )
    with pytest.raises(InvalidInputError, match="goal .* from the nearest obstacle"):
        trajopt.plan(grid, start, goal, disc, start_heading=h0, goal_heading=h1)
    smp = traj.sample(np.linspace(0.0, traj.duration, 2001))
    backwards = name == "bay_reverse"
    assert (smp.v.min() < 0.0) == backwards  # backed in, or driven in nose first


def test_a_body_backs_into_a_parallel_slot_1_3_lengths_long(planned):
    """The 0.88 x 0.4 m body (not a disc) into the parking scene's slot, 1.3 of its lengths
    long: the search from the slot (``search_from="auto"``) pulls it out, reversed; the
    body check above finds no contact, and it enters the slot backwards."""
    grid, robot, start, goal, h0, h1, traj, _ = planned["parallel_body"]
    assert robot.footprint is not None and SLOT / PARK_CAR[0] == pytest.approx(1.3)
    search = traj.stats["car"]["search"]
    assert search["footprint"] is True and search["search_from"] == "goal"
    smp = traj.sample(np.linspace(0.0, traj.duration, 4001))
    below = np.nonzero(smp.y < 0.65)[0]  # the rear axle crosses the parked cars' line
    assert smp.v[below[0] - 1] < 0.0  # backwards
    np.testing.assert_allclose(smp.steer, np.arctan(robot.drive.wheelbase * smp.kappa), atol=1e-12)


@pytest.mark.parametrize("name", ["full_bay_reverse", "full_bay_forward"])
def test_a_full_size_car_parks_in_a_perpendicular_bay(planned, name):
    """The 4.69 x 1.94 m car (R = 3 m) into a bay 1.3 of its widths wide off a 5.5 m aisle,
    backed in or nose first (the last drive's direction), in well under a second."""
    grid, robot, start, goal, h0, h1, traj, seconds = planned[name]
    assert FULL_BAY / FULL_CAR[1] == pytest.approx(1.3)
    assert traj.pieces[-1].direction == (-1 if name == "full_bay_reverse" else 1)
    assert traj.stats["car"]["search"]["footprint"] is True
    assert seconds < 1.0, seconds


def test_three_point_turn_of_a_body_has_cusps(planned):
    _, robot, *_, traj, _ = planned["three_point_body"]
    assert robot.footprint is not None and traj.stats["car"]["cusps"] >= 1
    assert traj.stats["car"]["search"]["footprint"] is True


def test_a_body_car_refuses_an_end_pose_its_footprint_does_not_fit():
    grid = bay_grid()
    with pytest.raises(InvalidInputError, match=r"goal pose .*the footprint meets an obstacle"):
        trajopt.plan(
            grid, (1.0, 2.0), (2.225, 0.3), body_car(), start_heading=0.0, goal_heading=0.0
        )


def test_forward_only_goal_behind_is_a_typed_no_path_error_fast():
    res = 0.05
    grid = astar.OccupancyGrid(walled(4.0, 0.6, res), res)  # a corridor too narrow to turn
    robot = trajopt.Robot(drive="ackermann", min_turning_radius=0.5, reverse=False)
    t0 = time.perf_counter()
    with pytest.raises(NoPathError, match=r"forwards only \(reverse=False\)") as info:
        trajopt.plan(grid, (3.0, 0.3), (1.0, 0.3), robot, start_heading=0.0, goal_heading=0.0)
    assert time.perf_counter() - t0 < 1.0
    assert "reverse=True" in str(info.value)
    # the same query with reversing allowed is planned, backwards
    back = dataclasses.replace(robot, reverse=True)
    traj = trajopt.plan(grid, (3.0, 0.3), (1.0, 0.3), back, start_heading=0.0, goal_heading=0.0)
    assert traj.sample(traj.duration / 2).v < 0.0


def test_replan_of_a_car_on_the_same_map_keeps_its_rest(planned):
    # re-planning a car: tests/trajopt/replan/test_replan_car.py
    grid, robot, start, goal, h0, h1, traj, _ = planned["three_point"]
    planner = trajopt.Planner(grid, robot)
    out = planner.replan(traj, traj.duration / 3, latency=0.0)
    assert out.stats["replan"] == "kept"
    assert out.duration == pytest.approx(traj.duration * 2 / 3, abs=1e-9)


def test_a_curve_turned_round_is_the_same_curve_backwards():
    """The reversed fit's curve: the same points in the opposite order, tangents flipped."""
    from trajopt.geometry._bspline import BSplineCurve, clamped_uniform_knots
    from trajopt.planning._car_fit import turned_round
    from trajopt.smoother import SmoothPath

    pts = np.array([[0.0, 0.0], [1.0, 0.2], [2.0, 1.5], [2.5, 3.0], [4.0, 3.2], [5.0, 2.0]])
    curve = BSplineCurve(clamped_uniform_knots(len(pts), 3, (0.0, 7.0)), pts, 3)
    path = SmoothPath(curve, {"cost": 1.0})
    back = turned_round(path)
    u = np.linspace(0.0, 7.0, 301)
    np.testing.assert_allclose(back(u), path(7.0 - u), atol=1e-12)
    np.testing.assert_allclose(back(u, 1), -path(7.0 - u, 1), atol=1e-12)
    np.testing.assert_allclose(back.curvature(u), -path.curvature(7.0 - u), atol=1e-9)
    assert back.length == pytest.approx(path.length, rel=1e-12)
    assert back.stats["turned_round"] and back.certificate is path.certificate


def test_split_points_cut_loops_not_wiggles():
    """Cuts of a stretch that turns much: each piece's headings span at most the limit."""
    from trajopt.planning._car_fit import PIECE_TURN_RAD, SPLIT_TURN_RAD, split_points

    straight = np.zeros(50)
    assert split_points(straight, 0, 49) == [0, 49]
    bend = np.linspace(0.0, 0.99 * SPLIT_TURN_RAD, 60)  # below the threshold: whole
    assert split_points(bend, 0, 59) == [0, 59]
    wiggle = 0.3 * np.sin(np.arange(200) * 0.7)  # turns by far more than pi in all
    assert np.abs(np.diff(wiggle)).sum() > 5.0 * SPLIT_TURN_RAD
    assert split_points(wiggle, 0, 199) == [0, 199]
    loop = np.concatenate([np.zeros(10), np.linspace(0.0, -TWO_PI, 101), np.full(10, -TWO_PI)])
    cuts = split_points(loop, 3, len(loop) - 2)
    assert cuts[0] == 3 and cuts[-1] == len(loop) - 2
    assert len(cuts) - 1 == math.ceil(TWO_PI / PIECE_TURN_RAD)
    for a, b in zip(cuts[:-1], cuts[1:], strict=True):
        assert b - a >= 2
        assert np.ptp(loop[a : b + 1]) <= PIECE_TURN_RAD + 1e-12


@pytest.mark.parametrize("pieces", [False, True])
def test_forward_only_loop_is_fitted_in_pieces(pieces, monkeypatch):
    """A goal a cell beside the start, turned by about 3 pi / 2 (held-out AR0046SR #0): the
    forward-only path is a loop of about 6.6 rad. Fitted whole where a curve fits it, or
    (``pieces``: the whole fits tried first skipped, as when they fail) in pieces, each
    starting with the previous one's end curvature, driven through as one piece of the
    chain: the speed stays above 0 and the curvature is continuous at the joins; every
    piece certified either way."""
    if pieces:
        monkeypatch.setattr(car_fit, "WHOLE_FIRST", ())
    res = 0.05
    grid = astar.OccupancyGrid(walled(4.0, 4.0, res), res)
    robot = trajopt.Robot(radius=0.1, drive="ackermann", min_turning_radius=0.4, reverse=False)
    start, goal, h0, h1 = (2.0, 2.0), (1.95, 2.0), -2.83, 1.7
    traj = trajopt.Planner(grid, robot).plan(start, goal, start_heading=h0, goal_heading=h1)
    assert traj.stats["car"]["tries"] == ["radius + margin grid, 1.15 R: planned"]
    joined = [s.joined for s in traj.steps.segments]
    assert joined[0] is False and (sum(joined) >= 2 if pieces else True)
    assert all(p.direction == 1 for p in _drives(traj))
    ends = traj.sample(np.array([0.0, traj.duration]))
    np.testing.assert_allclose([ends.x, ends.y], np.transpose([start, goal]), atol=1e-9)
    assert _angle_diff(ends.theta[0], h0) < 1e-6 and _angle_diff(ends.theta[1], h1) < 1e-6
    np.testing.assert_array_equal(traj.sample(traj.piece_times).v, 0.0)
    if pieces:  # one drive through the joins: moving at each, the curvature continuous
        assert len(traj.pieces) == 1 and traj.stats["car"]["rests"] == 0
        ends_s = np.cumsum([s.smooth_path.length for s in traj.steps.segments])[:-1]
        drive = traj.pieces[0]
        t = np.linspace(0.0, drive.duration, 20001)
        at = np.interp(ends_s, drive.sample(t).s, t)  # the times at the joins
        for tj in at:
            near = drive.sample(np.array([tj - 1e-4, tj + 1e-4]))
            assert near.v.min() > 0.05
            assert abs(near.kappa[1] - near.kappa[0]) < 1e-2  # continuous (over 2e-4 s)
    kmax = 1.0 / robot.drive.min_turning_radius
    for pts in _dense_points(traj, 0.002):
        assert three_point_curvature(pts).max() <= kmax * (1.0 + 1e-6)
        assert square_clearance(grid, pts, reach=0.2).min() >= robot.radius - 1e-9
    # the heading is continuous across the joins
    smp = traj.sample(np.linspace(0.0, traj.duration, 4001))
    assert np.abs(np.diff(smp.theta)).max() < 0.05


def test_start_facing_a_wall_with_room_only_for_full_lock():
    """Forward only, the start heading 114 degrees down towards a wall with room for a turn
    of radius 1.05 R but not 1.15 R (held-out depot #5): the tight search radius fits with
    the smoother's collocation margin raised (0.9 of 1/R cannot follow that arc); the
    curve still keeps 1/R (three-point check) and the radius (brute force)."""
    from trajopt.planning import _car_tries

    res, R, h0 = 0.05, 0.4, -1.9935
    grid = astar.OccupancyGrid(walled(6.0, 3.0, res), res)
    robot = trajopt.Robot(radius=0.1, drive="ackermann", min_turning_radius=R, reverse=False)
    drop = R * (1.0 - math.cos(math.pi + h0))  # how far a turn of radius R drops to west
    start, goal = (4.0, 0.15 + 1.075 * drop), (1.0, 0.4)
    traj = trajopt.Planner(grid, robot).plan(start, goal, start_heading=h0, goal_heading=math.pi)
    tries = traj.stats["car"]["tries"]
    assert tries[-1] == f"radius grid, {_car_tries.TIGHT_FACTOR:g} R: planned", tries
    assert "radius grid, 1.15 R: no path (exhausted)" in tries
    ends = traj.sample(np.array([0.0, traj.duration]))
    np.testing.assert_allclose([ends.x, ends.y], np.transpose([start, goal]), atol=1e-9)
    kmax = 1.0 / R
    for pts in _dense_points(traj, 0.002):
        assert three_point_curvature(pts).max() <= kmax * (1.0 + 1e-6)
        assert square_clearance(grid, pts, reach=0.2).min() >= robot.radius - 1e-9


def test_speed_limit_zones_hold_in_the_map_frame_far_from_the_origin():
    # the car plans in the map-local frame; the zones (world frame) must cap the speed where
    # they lie in the world: each 1 ms sample's speed against its zone's cap, computed here
    grid0, robot, p0, p1, h0, h1 = behind_scene()
    off = np.array([1000.0, -500.0])
    grid = astar.OccupancyGrid(grid0.occupied, grid0.resolution, tuple(off))
    ny, nx = np.asarray(grid.occupied).shape
    mask = np.zeros((ny, nx), dtype=int)
    mask[:, : nx // 2] = 40  # the western half at 40 % of v_max
    zones = trajopt.SpeedLimits.from_mask(mask, grid.resolution, tuple(off), type="percentage")
    traj = trajopt.plan(
        grid, tuple(off + p0), tuple(off + p1), robot=robot, start_heading=h0,
        goal_heading=h1, speed_limits=zones,
    )  # fmt: skip
    smp = traj.sample(np.arange(0.0, traj.duration, 1e-3))
    cap = zones.cap_at(np.column_stack([smp.x, smp.y]), robot.v_max)
    assert np.any(cap < robot.v_max) and np.any(np.isinf(cap))  # both halves driven
    assert np.all(np.abs(smp.v) <= cap + 1e-6)
