"""Tests of trajopt.moving's sampled windows for movers of any shape, against dense sampling.

The windows must hold every instant a point is closer to a mover than the limit (checked on
1 ms samples of the reference's own distance, :func:`tests.trajopt.moving.reference.slack_at`),
and stay near such instants: every covered sample is within what the mover can close in two
steps of the limit.
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.trajopt.moving.reference import mover_rate, slack_at
from trajopt.geometry import PolylineCurve
from trajopt.moving import MovingObstacle
from trajopt.moving._shape_windows import NODE_STEP, ShapeTracks, ShapeWindows, launch_floor
from trajopt.moving._st_search import Piece
from trajopt.robot import Robot
from trajopt.timing import time_parameterize

CART = [(-0.45, -0.25), (0.45, -0.25), (0.45, 0.25), (-0.45, 0.25)]
TRI = [(-0.3, -0.2), (0.4, 0.0), (-0.3, 0.2)]


def _movers(rng):
    out = []
    for i, verts in enumerate((CART, TRI, None, CART)):
        t = np.concatenate([[0.0], np.sort(rng.uniform(0.5, 7.0, 2))])
        out.append(
            MovingObstacle.from_waypoints(
                t,
                rng.uniform(-1.5, 1.5, (3, 2)),
                radius=0.05 + 0.1 * (verts is None),
                headings=rng.uniform(-3.0, 3.0, 3),
                growth=0.03 * (i % 2),
                vertices=verts,
                name=f"m{i}",
            )
        )
    return out


def _covered(who, pi, lo, hi, j, i, t):
    cov = np.zeros(t.shape, dtype=bool)
    sel = (who == j) & (pi == i)
    for a, b in zip(lo[sel], hi[sel], strict=True):
        cov |= (t > a) & (t < b)
    return cov


@pytest.mark.parametrize("seed", [0])
def test_windows_hold_every_violation_and_stay_near_them(seed):
    rng = np.random.default_rng(seed)
    movers = _movers(rng)
    pts = rng.uniform(-1.8, 1.8, (24, 2))
    limit = 0.25
    who, pi, lo, hi = ShapeTracks(movers).windows(pts, limit, NODE_STEP)
    t = np.arange(0.0, 10.0, 1e-3)  # the movers stand still after 7 s
    hits = 0
    for j, m in enumerate(movers):
        rate = mover_rate(m)
        for i in range(pts.shape[0]):
            f = slack_at(np.repeat(pts[i : i + 1], t.size, 0), m, t, limit)
            cov = _covered(who, pi, lo, hi, j, i, t)
            assert not np.any((f < 0.0) & ~cov), (j, i)
            assert np.all(f[cov] <= 2.0 * rate * NODE_STEP + 1e-9), (j, i)
            hits += int(np.any(f < 0.0))
    assert hits >= 6  # the case exercises the windows


def test_translating_shapes_get_exact_windows_and_slow_turns_near_ones():
    # carts that only translate (constant headings), one that turns slowly, a disc, and one
    # that stands after its last waypoint: the windows (closed form, no march) must hold
    # every violation of 0.5 ms samples and cover only samples within the turn's pad
    rng = np.random.default_rng(7)
    movers = []
    for i, (verts, turn) in enumerate(((CART, 0.0), (TRI, 0.0), (CART, 0.02), (None, 0.0))):
        t = np.array([0.0, 2.0, 4.5])
        h0 = rng.uniform(-3.0, 3.0)
        movers.append(
            MovingObstacle.from_waypoints(
                t,
                rng.uniform(-1.5, 1.5, (3, 2)),
                radius=0.05,
                headings=h0 + turn * t,
                vertices=verts,
                name=f"m{i}",
            )
        )
    pts = rng.uniform(-1.8, 1.8, (30, 2))
    limit = 0.3
    who, pi, lo, hi = ShapeTracks(movers).windows(pts, limit, NODE_STEP)
    t = np.arange(0.0, 6.0, 5e-4)
    hits = 0
    for j, m in enumerate(movers):
        # the pad of a turning piece: its reach, its turn rate and half the piece's 2.5 s
        reach = 0.0 if m.vertices is None else float(np.max(np.hypot(*np.asarray(CART).T)))
        pad = reach * 0.02 * 1.25 if j == 2 else 0.0
        rate = mover_rate(m)
        for i in range(pts.shape[0]):
            f = slack_at(np.repeat(pts[i : i + 1], t.size, 0), m, t, limit)
            cov = _covered(who, pi, lo, hi, j, i, t)
            assert not np.any((f < 0.0) & ~cov), (j, i)
            assert np.all(f[cov] <= 2.0 * pad + rate * 5e-4 + 1e-8), (j, i, float(f[cov].max()))
            hits += int(np.any(f < 0.0))
    assert hits >= 10
    # and after the last waypoint a standing shape: one window to the end of time or none
    assert np.all((hi < 4.5 + 1e-6) | (hi > 1e300))


def test_band_and_owner_restrict_the_windows():
    rng = np.random.default_rng(3)
    movers = _movers(rng)
    pts = rng.uniform(-1.5, 1.5, (30, 2))
    tracks = ShapeTracks(movers)
    band = (rng.uniform(0.0, 4.0, 30), rng.uniform(4.0, 8.0, 30))
    owner = rng.integers(0, len(movers), 30)
    who, pi, lo, hi = tracks.windows(pts, 0.2, 5e-4, band, owner)
    assert np.all(who == owner[pi])
    t = np.arange(0.0, 9.0, 1e-3)
    for i in range(pts.shape[0]):
        m = movers[owner[i]]
        f = slack_at(np.repeat(pts[i : i + 1], t.size, 0), m, t, 0.2)
        inside = (t >= band[0][i]) & (t <= band[1][i])
        cov = _covered(who, pi, lo, hi, owner[i], i, t)
        assert not np.any((f < 0.0) & inside & ~cov), i
        assert np.all(f[cov] <= 2.0 * mover_rate(m) * 5e-4 + 1e-9), i


def test_a_standing_shape_gives_one_lasting_window():
    cart = MovingObstacle.from_waypoints([0.0], [(1.0, 0.0)], radius=0.0, vertices=CART)
    who, pi, lo, hi = ShapeTracks([cart]).windows(np.array([[0.0, 0.0], [3.0, 0.0]]), 0.6, 0.01)
    # the first point is 0.55 m from the cart's edge, the second 1.55 m
    assert who.tolist() == [0] and pi.tolist() == [0]
    assert lo[0] <= 0.0 and hi[0] > 1e300  # for ever


def test_the_launches_left_by_the_refinement_are_clear():
    # a straight 6 m drive; two turning carts cross it. Every launch in [lo, hi] outside the
    # returned intervals must keep the limit on 1 ms samples of the motion (the reference's
    # own distance), and some of them must be left
    robot = Robot(v_max=0.6, a_max=0.6, j_max=2.0)
    traj = time_parameterize(PolylineCurve(np.array([[0.0, 0.0], [6.0, 0.0]])), robot)
    carts = [
        MovingObstacle.from_waypoints(
            [0.0, 14.0],
            [(x, -3.0), (x + 1.0, 4.0)],
            radius=0.05,
            headings=[1.2, 1.6],
            vertices=CART,
            name=f"cart{i}",
        )
        for i, x in enumerate((1.5, 3.5))
    ]
    limit = robot.radius
    s = np.linspace(0.0, 6.0, 601)

    def where(s_at):
        return np.column_stack([s_at, np.zeros_like(s_at)])

    fine = ShapeWindows(s, where(s), carts, limit, where=where, speed=robot.v_max)
    dur = float(traj.duration)
    a, b = np.array([0.0, 0.0]), np.array([dur, dur])
    lo, hi = 3.75, 4.0  # the first clear launch is near 3.9 s
    w_lo, w_hi = fine._exact(a, b, np.array([0, 1]), lambda t: traj.motion(t)[0], lo, hi)
    tau = np.arange(0.0, dur, 2e-3)
    p = where(traj.motion(tau)[0])
    left, clear = [], []
    for launch in np.arange(lo, hi, 1e-2):
        gap = min(float(np.min(slack_at(p, m, tau + launch, limit))) for m in carts)
        if gap >= 0.0:
            clear.append(launch)
        if not np.any((w_lo < launch) & (launch < w_hi)):
            left.append(launch)
            assert gap >= -1e-9, launch
    # sufficient, and tight: the first launch left within 10 ms of the first clear one
    assert left and clear and left[0] <= clear[0] + 0.01


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_the_launch_floor_is_no_later_than_the_fine_windows_earliest_launch(seed):
    # carts cross a straight 6 m drive: the floor from every 8th node's windows must be no
    # later than the least launch the windows at every fine node allow (the same drive,
    # also as a block of two drives with a stop between them), and above the range's start
    rng = np.random.default_rng(seed)
    robot = Robot(v_max=0.6, a_max=0.6, j_max=2.0)
    line = PolylineCurve(np.array([[0.0, 0.0], [6.0, 0.0]]))
    whole = time_parameterize(line, robot)
    rows = np.column_stack(
        [whole.phase_t, whole.phase_s, whole.phase_v, whole.phase_a, whole.phase_j]
    )
    drive = Piece(rows, float(whole.duration), 0.0, 6.0)
    half = time_parameterize(PolylineCurve(np.array([[0.0, 0.0], [3.0, 0.0]])), robot)
    rows = np.column_stack([half.phase_t, half.phase_s, half.phase_v, half.phase_a, half.phase_j])
    first = Piece(rows, float(half.duration), 0.0, 3.0)
    second = Piece(rows + np.array([0.0, 3.0, 0.0, 0.0, 0.0]), float(half.duration), 3.0, 6.0)
    carts = [
        MovingObstacle.from_waypoints(
            [0.0, 20.0],
            [(x, -4.0 - rng.uniform(0.0, 2.0)), (x + rng.uniform(-1, 1), 5.0)],
            radius=0.05,
            headings=[1.4, 1.4 + rng.uniform(-0.3, 0.3)],
            vertices=CART,
            name=f"cart{i}",
        )
        for i, x in enumerate(rng.uniform(0.5, 5.5, 3))
    ]
    s = np.linspace(0.0, 6.0, 601)
    pts = np.column_stack([s, np.zeros_like(s)])
    band = (np.full(s.shape, -1.0), np.full(s.shape, 60.0))
    limit = robot.radius
    fine = ShapeWindows(s, pts, carts, limit, band)
    for sched in ([(0.0, drive)], [(0.0, first), (half.duration + 1.5, second)]):
        occupancy = []
        for t_j, pc in sched:
            node, a, b = fine.drive_occupancy(pc)
            occupancy.append((node, a + t_j, b + t_j))
        earliest = fine.earliest(occupancy, 0.0, 40.0)
        floor = launch_floor(s, pts, carts, limit, band, [sched], 0.0)
        assert earliest is not None and floor <= earliest + 1e-9, (floor, earliest)
        assert floor >= earliest - 1.0 or earliest < 1.0, (floor, earliest)  # and near it


def test_the_points_fetched_together_get_the_windows_of_one_at_a_time():
    # the rests' points of a path past turning carts (and a standing one): the windows
    # fetched in one march equal, float for float, those made point by point, and hold
    # every 1 ms sample at which the point is within the limit (the reference's distance)
    rng = np.random.default_rng(3)
    movers = _movers(rng)
    limit = 0.3

    def where(s_at):
        s_at = np.asarray(s_at, dtype=float)
        return np.column_stack([s_at - 1.5, 0.4 * np.sin(s_at)])

    s = np.linspace(0.0, 3.0, 301)
    places = [0.0, 0.7, 1.2, 1.2, 2.05, 3.0]
    together = ShapeWindows(s, where(s), movers, limit, where=where, speed=0.6)
    together.fetch_points(places)
    alone = ShapeWindows(s, where(s), movers, limit, where=where, speed=0.6)
    t = np.arange(0.0, 9.0, 1e-3)
    hit = 0
    for x in places:
        lo, hi = together.point_windows(x)
        one_lo, one_hi = alone.point_windows(x)
        assert np.array_equal(lo, one_lo) and np.array_equal(hi, one_hi)
        near = np.zeros(t.shape, dtype=bool)
        for m in movers:
            near |= slack_at(where(np.full(t.shape, x)), m, t, limit) < 0.0
        cov = np.zeros(t.shape, dtype=bool)
        for a, b in zip(lo, hi, strict=True):
            cov |= (t > a) & (t < b)
        assert not np.any(near & ~cov)
        hit += int(near.any())
    assert hit >= 2  # some of the points do meet the movers
