"""Tests of trajopt.planning: the parking suite's exact body checker (``benchmarks/parking_cases.py``) and parking plans.

The checker is tested on hand-built poses whose answer is known (a corner 1 cm into a parked
car, 1 cm clear of it, touching it; the body inside a polygon and a polygon inside the body;
the notch of a non-convex kerb) and against shapely on random poses; its dense sampling
keeps every body corner within 1 cm between poses. The suite's cases hold the ranges of
issue 45. Then scenes the planner parks today, each checked by the exact checker against
the polygons (not the grid): the small delivery car (0.9 x 0.5 m, R = 0.6 m) on a 5 cm grid
from ``astar.OccupancyGrid.from_polygons``, into a perpendicular bay 1.4 car widths wide,
forwards and backwards, and a bay 1.25 car widths wide backwards; the full-size car (4.69 x
1.94 m, R = 3 m) on a 0.1 m grid into two cases of the seeded suite.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import astar
import trajopt
import trajopt.planning._car as car_module
from benchmarks import parking_cases as pc

SMALL = pc.CARS["small"]
FULL = pc.CARS["full"]


def test_cars_are_the_issues_cars():
    assert (FULL.length, FULL.width, FULL.rear_offset) == (4.69, 1.94, 0.96)
    assert (FULL.turning_radius, FULL.wheelbase) == (3.0, 2.8)
    assert (SMALL.length, SMALL.width, SMALL.turning_radius) == (0.9, 0.5, 0.6)
    robot = FULL.robot()
    np.testing.assert_allclose(robot.footprint.vertices, FULL.body())
    assert robot.drive.min_turning_radius == 3.0 and robot.drive.wheelbase == 2.8
    # the body is counter-clockwise around the rear axle, 0.96 m ahead of the rear bumper
    b = FULL.body()
    assert b[:, 0].min() == -0.96 and b[:, 0].max() == pytest.approx(4.69 - 0.96)
    area2 = np.sum(b[:, 0] * np.roll(b[:, 1], -1) - np.roll(b[:, 0], -1) * b[:, 1])
    assert area2 > 0


# ------------------------------------------------------------------ the checker by hand

PARKED = pc.rect(3.0, 0.0, 0.9, 0.5)  # a parked small car, x in [2.55, 3.45], y in [-0.25, 0.25]
FRONT = SMALL.length - SMALL.rear_offset  # rear axle to front bumper (m)


@pytest.mark.parametrize(
    ("gap", "overlaps"),
    [(0.01, False), (1e-6, False), (0.0, True), (-1e-6, True), (-0.01, True)],
)
def test_front_bumper_against_a_parked_car(gap, overlaps):
    # facing +x, the front bumper gap m short of the parked car's rear (x = 2.55)
    pose = np.array([[2.55 - gap - FRONT, 0.1, 0.0]])
    assert pc.body_overlaps(SMALL.body(), pose, [PARKED])[0] == overlaps


def test_a_turned_corner_into_a_parked_car():
    # turned by -30 degrees, the front-left corner leads: put it 1 cm into (or short of) the
    # middle of the parked car's rear edge (x = 2.55); both edges at that corner fall back
    th = math.radians(-30.0)
    corner = np.array([FRONT, 0.25])
    rot = np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]])
    for depth, want in ((0.01, True), (1e-9, True), (-0.01, False)):
        xy = np.array([2.55 + depth, 0.0]) - rot @ corner
        pose = np.array([[*xy, th]])
        assert pc.body_overlaps(SMALL.body(), pose, [PARKED])[0] == want
        clr = pc.body_clearance(SMALL.body(), pose, [PARKED])[0]
        assert clr == (0.0 if want else pytest.approx(0.01, abs=1e-9))


def test_containment_either_way_is_an_overlap():
    big = pc.rect(0.0, 0.0, 10.0, 10.0)  # the body wholly inside: no edges meet
    tiny = np.array([(0.1, -0.05), (0.2, -0.05), (0.15, 0.05)])  # wholly inside the body
    pose = np.array([[0.0, 0.0, 0.3]])
    assert pc.body_overlaps(SMALL.body(), pose, [big])[0]
    assert pc.body_overlaps(SMALL.body(), pose, [tiny])[0]
    # and the body in the hole of nothing: clear of a polygon far away
    assert not pc.body_overlaps(SMALL.body(), pose, [tiny + 5.0])[0]


def test_the_notch_of_a_non_convex_kerb_is_free():
    u = pc._u_kerb(-1.0, 1.0, -1.0, 1.0, 0.2)  # a U round [-1, 1]^2, open at the top
    inside = np.array([[-0.2, 0.0, 0.0], [0.0, -0.3, math.pi / 2], [0.0, 0.8, 1.0]])
    assert not pc.body_overlaps(SMALL.body(), inside, [u]).any()
    across = np.array([[0.5, 0.0, 0.0], [0.0, -0.9, 0.0]])  # through an arm, the bottom
    assert pc.body_overlaps(SMALL.body(), across, [u]).all()


def test_checker_agrees_with_shapely_on_random_poses():
    shapely = pytest.importorskip("shapely")
    from shapely.geometry import Polygon

    rng = np.random.default_rng(3)
    for case in pc.make_cases(SMALL, 6, seed=5):
        x0, y0, x1, y1 = case.bounds
        poses = np.column_stack(
            [rng.uniform(x0, x1, 800), rng.uniform(y0, y1, 800), rng.uniform(-4, 4, 800)]
        )
        mine = pc.body_overlaps(SMALL.body(), poses, case.polygons)
        union = shapely.union_all([Polygon(p) for p in case.polygons])
        ref = [union.intersects(Polygon(b)) for b in pc.body_at(SMALL.body(), poses)]
        np.testing.assert_array_equal(mine, ref)
        assert 0.05 < mine.mean() < 0.95  # both answers occur


def test_the_checkers_kernels_are_cached_on_disk():
    """The kernels are compiled once per checkout, not once per session (a compile is
    seconds): numba names its cache files after the source file, not the module, so the
    benchmark's ``parking_cases`` and the tests' ``benchmarks.parking_cases`` share them.
    The shapely test above checks what the kernels compute."""
    from numba.core.caching import NullCache

    for kernel in (pc._seg_meet, pc._overlaps_kernel):
        assert not isinstance(kernel._cache, NullCache), kernel


# ------------------------------------------------------------------ the suite


@pytest.mark.parametrize("car", [FULL, SMALL], ids=["full", "small"])
def test_cases_hold_the_issues_ranges(car):
    cases = pc.make_cases(car, 18, seed=1)
    assert [c.category for c in cases[:6]] == [
        "parallel",
        "parallel",
        "perpendicular",
        "perpendicular",
        "angled",
        "angled",
    ]
    s = car.length / 4.69
    for c in cases:
        assert 4.0 * s <= c.aisle <= 7.0 * s
        if c.category == "parallel":
            assert 1.2 <= c.size <= 1.6 and c.angle == 0.0
        else:
            assert 1.15 <= c.size <= 1.4
            assert c.angle == 90.0 if c.category == "perpendicular" else 45.0 <= c.angle <= 60.0
        poses = np.array([c.start, c.goal])
        assert not pc.body_overlaps(car.body(), poses, c.polygons).any()
        # every polygon is a valid obstacle, and the grid holds the goal's surroundings
        grid = c.grid(0.1)
        assert grid.resolution == 0.1 and grid.occupied.any()
        if c.category != "parallel":
            gh = c.goal[2] % (2 * math.pi)
            into = (c.entry == "forwards") == (math.sin(gh) < 0)  # bays lie below the aisle
            assert into
    again = pc.make_cases(car, 18, seed=1)
    assert [c.start for c in again] == [c.start for c in cases]
    assert [c.start for c in pc.make_cases(car, 18, seed=2)] != [c.start for c in cases]


def test_bays_have_their_free_width():
    # the neighbours' facing sides are size * car width apart, measured across the bay
    for c in pc.make_cases(FULL, 12, seed=4):
        if c.category == "parallel":
            continue
        gh = c.goal[2]
        along = np.array([math.cos(gh), math.sin(gh)])
        across = np.array([-along[1], along[0]])
        goal_body = pc.body_at(FULL.body(), np.array([c.goal]))[0]
        centre = goal_body.mean(axis=0)
        lo, hi = (goal_body @ along).min(), (goal_body @ along).max()
        # the parked cars beside the bay: rectangles that overlap the goal body along its axis
        cars = [
            p
            for p in c.polygons
            if len(p) == 4 and (p @ along).max() > lo and (p @ along).min() < hi
        ]
        side = [(p - centre) @ across for p in cars]
        left = max(t.max() for t in side if t.max() < 0)
        right = min(t.min() for t in side if t.min() > 0)
        assert right - left == pytest.approx(c.size * FULL.width, abs=1e-9)


def test_a_parallel_slot_has_a_reverse_s_witness():
    # the first full-size case, a slot 1.45 car lengths long: one reverse S (two arcs at R)
    # enters it clear of every polygon; rebuilt here and checked pose by pose
    case = pc.make_cases(FULL, 1, seed=0)[0]
    assert case.category == "parallel" and 1.4 < case.size < 1.5
    d, phi = pc.reverse_s_entry(case)
    R, side = FULL.turning_radius, 1.0 if math.cos(case.goal[2]) > 0 else -1.0
    back = pc.arc_poses(case.goal, 0.0, d, -1, 0.004)
    a1 = pc.arc_poses(tuple(back[-1]), side / R, R * phi, +1, 0.004)
    a2 = pc.arc_poses(tuple(a1[-1]), -side / R, R * phi, +1, 0.004)
    poses = np.vstack([back, a1, a2])
    check = pc.check_poses(FULL.body(), poses, case.polygons)
    assert check.overlaps == 0 and check.max_corner_step <= 0.01
    assert a2[-1, 1] - case.goal[1] == pytest.approx(2 * R * (1 - math.cos(phi)), abs=1e-9)
    with pytest.raises(ValueError, match="parallel"):
        pc.reverse_s_entry(pc.make_cases(FULL, 3, seed=0)[2])


# ------------------------------------------------------------------ plans, checked exactly


def bay_scene(size: float, entry: str):
    """A perpendicular bay ``size`` small-car widths wide below an aisle 1.2 m wide.

    Three parked cars each side (0.15 m apart), a U-shaped kerb round the lot, a wall on
    top; the start in the aisle 1.6 m to the left facing +x, the goal centred in the bay.
    """
    ln, wd = SMALL.length, SMALL.width
    free = size * wd
    cars = [
        pc.rect(s * (0.5 * free + 0.5 * wd + k * (wd + 0.15)), -0.05 - 0.5 * ln, wd, ln)
        for s in (-1.0, 1.0)
        for k in range(3)
    ]
    back = -0.08 - ln - 0.1
    polys = [*cars, pc._u_kerb(-3.0, 3.0, back, 1.2, 0.1)]
    polys.append(np.array([(-3.1, 1.2), (3.1, 1.2), (3.1, 1.3), (-3.1, 1.3)]))
    centre_y = -0.08 - 0.5 * ln
    off = 0.5 * ln - SMALL.rear_offset  # rear axle to the body's centre
    heading = -math.pi / 2 if entry == "forwards" else math.pi / 2
    goal = (0.0, centre_y - off * math.sin(heading), heading)
    return polys, (-3.1, back - 0.1, 3.1, 1.3), (-1.6, 0.6, 0.0), goal


SCENES = [(1.4, "forwards"), (1.4, "backwards"), (1.25, "backwards")]


@pytest.fixture(scope="module")
def parked():
    robot = SMALL.robot()
    out = {}
    for size, entry in SCENES:
        polys, bounds, start, goal = bay_scene(size, entry)
        grid = astar.OccupancyGrid.from_polygons(polys, 0.05, bounds)
        traj = trajopt.plan(
            grid, start[:2], goal[:2], robot, start_heading=start[2], goal_heading=goal[2]
        )
        out[size, entry] = (polys, start, goal, traj)
    return out


@pytest.mark.parametrize(("size", "entry"), SCENES)
def test_small_car_parks_in_a_bay_with_no_overlap(parked, size, entry):
    polys, start, goal, traj = parked[size, entry]
    t, poses = pc.trajectory_poses(traj, SMALL.body())
    # dense: no corner moves more than 1 cm between poses
    corners = pc.body_at(SMALL.body(), poses)
    assert np.hypot(*np.moveaxis(np.diff(corners, axis=0), -1, 0)).max() <= 0.01
    np.testing.assert_allclose(poses[0], start, atol=1e-6)
    np.testing.assert_allclose(poses[-1, :2], goal[:2], atol=1e-6)
    assert abs(math.remainder(poses[-1, 2] - goal[2], 2 * math.pi)) < 1e-6
    check = pc.check_poses(SMALL.body(), poses, polys)
    assert check.overlaps == 0 and check.min_clearance > 0.0
    # the body ends between its neighbours, below the aisle
    end = pc.body_at(SMALL.body(), poses[-1:])[0]
    assert end[:, 1].max() < 0.0 and np.abs(end[:, 0]).max() <= 0.5 * size * SMALL.width


def test_checker_finds_an_obstacle_put_on_the_path(parked):
    polys, start, goal, traj = parked[1.4, "backwards"]
    _, poses = pc.trajectory_poses(traj, SMALL.body())
    mid = poses[len(poses) // 2]
    pebble = pc.rect(mid[0], mid[1], 0.02, 0.02)  # 2 cm square under the rear axle
    check = pc.check_poses(SMALL.body(), poses, [*polys, pebble])
    assert check.overlaps > 0 and check.min_clearance == 0.0


@pytest.mark.parametrize(
    ("category", "entry", "index"),
    # an angled bay 1.16 car widths wide whose goal body keeps less than the first grid's
    # slack from a rasterised cell (refused before the slack was refined), and a parallel
    # slot 1.40 car lengths long entered forwards (4.7 s before the parking costs, when it
    # planned at all)
    [("angled", "backwards", 2), ("parallel", "forwards", 1)],
)
def test_full_size_car_parks_a_suite_case_with_no_overlap(category, entry, index):
    """Two cases of the seeded suite (``bench_parking.py``), full-size car at 0.1 m: the
    plan ends exactly at the goal and the exact polygon check finds no overlap."""
    case = pc.make_case(FULL, category, entry, 0, index)
    traj = trajopt.plan(
        case.grid(0.1),
        case.start[:2],
        case.goal[:2],
        FULL.robot(),
        start_heading=case.start[2],
        goal_heading=case.goal[2],
    )
    _, poses = pc.trajectory_poses(traj, FULL.body())
    np.testing.assert_allclose(poses[0], case.start, atol=1e-6)
    np.testing.assert_allclose(poses[-1, :2], case.goal[:2], atol=1e-6)
    assert abs(math.remainder(poses[-1, 2] - case.goal[2], 2 * math.pi)) < 1e-6
    check = pc.check_poses(FULL.body(), poses, case.polygons)
    assert check.overlaps == 0 and check.min_clearance > 0.0


def test_full_size_car_fits_a_backwards_segment_in_halves():
    """A perpendicular bay 1.40 car widths wide entered backwards (suite case
    ``full-perpendicular-backwards-4``): no single certified curve fits the backwards
    segment into the bay (the body's certificate keeps no margin near the slot, or the
    curvature SCP does not converge), its halves at the search's middle pose do. The car
    rests at the join; the exact polygon check finds no overlap, and finite differences of
    the geometric steering angle keep the steering rate at every join."""
    from tests.trajopt.planning.test_car import geometric_steer

    case = pc.make_case(FULL, "perpendicular", "backwards", 0, 4)
    robot = FULL.robot()
    traj = trajopt.plan(
        case.grid(0.1),
        case.start[:2],
        case.goal[:2],
        robot,
        start_heading=case.start[2],
        goal_heading=case.goal[2],
    )
    car = traj.stats["car"]
    assert car["segments"] > car["cusps"] + 1 and car["joins"] >= 1
    _, poses = pc.trajectory_poses(traj, FULL.body())
    np.testing.assert_allclose(poses[-1, :2], case.goal[:2], atol=1e-6)
    check = pc.check_poses(FULL.body(), poses, case.polygons)
    assert check.overlaps == 0 and check.min_clearance > 0.0
    t = np.unique(np.concatenate([np.arange(0.0, traj.duration, 2e-3), traj.piece_times]))
    delta = geometric_steer(traj, t, FULL.wheelbase)
    rate = np.abs(np.diff(delta)) / np.diff(t)
    assert rate.max() <= robot.drive.steering.rate_max * (1.0 + 1e-6)


# ------------------------------------------------------- the polygons inside the planner


def parallel_scene(size: float, aisle: float = 4.5):
    """A parallel slot ``size`` full-size car lengths long, the kerb 0.2 m below it.

    Two parked cars each side (1 m apart), an aisle ``aisle`` m wide above, a U-shaped kerb
    round the street and a wall on top; the start in the aisle behind the slot facing +x
    (drive past, back in), the goal centred in the slot facing +x. The scene is moved by
    (0.053, 0.047) m so that no polygon edge lies on a 0.1 m grid line: the conservative
    cells reach up to a cell beyond the cars.
    """
    ln, wd = FULL.length, FULL.width
    slot = size * ln
    cy = 0.2 + 0.5 * wd  # the parked cars' centre line; the kerb's top at y = 0
    cars = [
        pc.rect(s * (0.5 * slot + 0.5 * ln + k * (ln + 1.0)), cy, ln, wd)
        for s in (-1.0, 1.0)
        for k in range(2)
    ]
    top = 0.2 + wd + aisle
    x0, x1 = -0.5 * slot - 2 * ln - 3.0, 0.5 * slot + 2 * ln + 3.0
    wall = np.array(
        [(x0 - 0.2, top), (x1 + 0.2, top), (x1 + 0.2, top + 0.2), (x0 - 0.2, top + 0.2)]
    )
    d = np.array([0.053, 0.047])
    polys = [p + d for p in (*cars, pc._u_kerb(x0, x1, 0.0, top, 0.2), wall)]
    goal = (-0.5 * ln + FULL.rear_offset + d[0], cy + d[1], 0.0)
    start = (-0.5 * slot - ln + d[0], cy + wd + 0.5 * aisle - 0.3 + d[1], 0.0)
    return polys, (x0 - 0.3, -0.3, x1 + 0.3, top + 0.3), start, goal


@pytest.fixture(scope="module")
def slot_1_3():
    """The parallel slot of 1.3 car lengths (:func:`parallel_scene`) planned at 0.1 m."""
    polys, bounds, start, goal = parallel_scene(1.3)
    grid = astar.OccupancyGrid.from_polygons(polys, 0.1, bounds)
    traj = trajopt.plan(
        grid, start[:2], goal[:2], FULL.robot(), start_heading=start[2], goal_heading=goal[2]
    )
    return polys, bounds, start, goal, traj


def test_full_size_car_backs_into_a_parallel_slot_of_1_3_car_lengths(slot_1_3):
    """Issue 45: a parallel slot 1.3 car lengths long entered backwards (the start behind
    the slot), at 0.1 m, planned on the grid from ``from_polygons`` and clear of the
    polygons by the exact check at 1 cm of corner travel."""
    polys, _, start, goal, traj = slot_1_3
    assert traj.stats["car"]["cusps"] >= 1 and traj.stats["car"]["reverse_length_m"] > 1.0
    t, poses = pc.trajectory_poses(traj, FULL.body())
    corners = pc.body_at(FULL.body(), poses)
    assert np.hypot(*np.moveaxis(np.diff(corners, axis=0), -1, 0)).max() <= 0.01
    np.testing.assert_allclose(poses[0], start, atol=1e-6)
    np.testing.assert_allclose(poses[-1, :2], goal[:2], atol=1e-6)
    assert abs(math.remainder(poses[-1, 2] - goal[2], 2 * math.pi)) < 1e-6
    check = pc.check_poses(FULL.body(), poses, polys)
    assert check.overlaps == 0 and check.min_clearance > 0.0
    # the body ends in the slot, below the parked cars' tops
    end = pc.body_at(FULL.body(), poses[-1:])[0]
    assert end[:, 1].max() < polys[0][:, 1].max() + 1e-9


def test_end_pose_clear_of_the_polygons_but_touching_a_cell_is_planned():
    """The small car into a bay 1.15 car widths wide, nose first, on a 5 cm grid: its body
    at the goal is 3.75 cm from each neighbour, closer than a cell, so it meets the
    conservative cells; it is planned (not refused), and clear of the polygons at 1 cm of
    corner travel. The same grid without its polygons refuses the goal."""
    from trajopt.robot import polygons_clearance

    polys, bounds, start, goal = bay_scene(1.15, "forwards")
    grid = astar.OccupancyGrid.from_polygons(polys, 0.05, bounds)
    robot = SMALL.robot()
    assert polygons_clearance([robot.footprint.at(*goal)], grid, 0.05)[0] == 0.0
    traj = trajopt.plan(
        grid, start[:2], goal[:2], robot, start_heading=start[2], goal_heading=goal[2]
    )
    _, poses = pc.trajectory_poses(traj, SMALL.body())
    np.testing.assert_allclose(poses[-1, :2], goal[:2], atol=1e-6)
    check = pc.check_poses(SMALL.body(), poses, polys)
    assert check.overlaps == 0 and check.min_clearance > 0.0
    with pytest.raises(trajopt.InvalidInputError, match="goal pose"):
        trajopt.plan(
            grid.with_occupied(grid.occupied),
            start[:2],
            goal[:2],
            robot,
            start_heading=start[2],
            goal_heading=goal[2],
        )


def test_polygons_move_with_a_far_away_origin(slot_1_3):
    """The slot of 1.3 car lengths shifted by (4.5e9, -1.5e9) m: the map's polygons move into
    the planner's local frame with its cells (``OccupancyGrid.moved_to``), and the plan is the
    same trajectory, shifted, to 1e-6 m plus the rounding of coordinates that large."""
    polys, bounds, start, goal, near = slot_1_3
    d = np.array([4.5e9, -1.5e9])
    box = (bounds[0] + d[0], bounds[1] + d[1], bounds[2] + d[0], bounds[3] + d[1])
    grid = astar.OccupancyGrid.from_polygons([p + d for p in polys], 0.1, box)
    far = trajopt.plan(
        grid,
        np.asarray(start[:2]) + d,
        np.asarray(goal[:2]) + d,
        FULL.robot(),
        start_heading=start[2],
        goal_heading=goal[2],
    )
    # float64 holds coordinates near 4.5e9 m to ulp(4.5e9) = 9.5e-7 m only: the shifted start
    # and every world sample are rounded by up to half of it, which the plan carries on
    ulp = float(np.spacing(np.abs(d).max()))
    assert far.duration == pytest.approx(near.duration, rel=1e-7)
    t = np.linspace(0.0, near.duration, 400)
    a, b = near.sample(t), far.sample(t)
    np.testing.assert_allclose(
        np.column_stack([b.x - d[0], b.y - d[1]]), np.column_stack([a.x, a.y]), atol=1e-6 + 2 * ulp
    )
    np.testing.assert_allclose(b.theta, a.theta, atol=1e-6)


def test_tight_search_runs_only_after_every_ordinary_search_exhausted(monkeypatch):
    """The bay of 1.20 car widths entered nose first off a 4.3 m aisle (suite case
    perpendicular-forwards-1): every ordinary search exhausts its states, then the tight
    searches (finer states and primitives near the ends) run and exhaust theirs too; a case
    the ordinary tries plan never runs them. (The escape, the last try, plans the case in
    about 10 s: ``benchmarks/bench_parking.py``; here it is left out.)"""
    monkeypatch.setattr(car_module, "escape_applies", lambda robot, grid: False)
    case = pc.make_case(FULL, "perpendicular", "forwards", 0, 1)
    with pytest.raises(trajopt.NoPathError, match="exhausted") as err:
        trajopt.plan(
            case.grid(0.1),
            case.start[:2],
            case.goal[:2],
            FULL.robot(),
            start_heading=case.start[2],
            goal_heading=case.goal[2],
        )
    tries = str(err.value).split("(tries: ")[-1]
    ordinary = [t for t in tries.split("; ") if "radius grid," in t and "tight" not in t]
    tight = [t for t in tries.split("; ") if "tight" in t]
    assert len(ordinary) == 3 and all("exhausted" in t for t in ordinary)
    assert len(tight) == 2 and all("exhausted" in t for t in tight)
    assert tries.index(tight[0]) > tries.index(ordinary[-1])
    easy = pc.make_case(FULL, "perpendicular", "backwards", 0, 1)
    traj = trajopt.plan(
        easy.grid(0.1),
        easy.start[:2],
        easy.goal[:2],
        FULL.robot(),
        start_heading=easy.start[2],
        goal_heading=easy.goal[2],
    )
    assert not any("tight" in t for t in traj.stats["car"]["tries"])
