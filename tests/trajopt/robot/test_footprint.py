"""Tests of trajopt.robot: oriented footprints: the polygon, its swept bound, the certificate, and whole plans.

References are brute force and independent of :mod:`trajopt.robot._footprint`: dense rotations
of the footprint for the swept bound, dense tangent samples for the heading intervals,
and a point-sampling collision check (points inside the posed footprint against the
occupied squares) for the certificate and the plans.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import astar
import trajopt
from tests.reference import footprint_collides, inside_convex
from trajopt.errors import InvalidInputError
from trajopt.geometry._bspline import BSplineCurve, clamped_uniform_knots
from trajopt.robot._footprint import (
    Footprint,
    certify_footprint,
    convex_hull,
    span_heading_intervals,
)


# ------------------------------------------------------------------ the polygon
def test_rectangle_by_hand():
    fp = Footprint.rectangle(0.6, 0.4, rear_offset=0.15)
    np.testing.assert_allclose(
        fp.vertices, [[-0.15, -0.2], [0.45, -0.2], [0.45, 0.2], [-0.15, 0.2]]
    )
    assert fp.inscribed_radius == pytest.approx(0.15)  # the rear edge
    assert fp.circumscribed_radius == pytest.approx(math.hypot(0.45, 0.2))
    np.testing.assert_allclose(fp.at(1.0, 2.0, math.pi / 2)[1], [1.2, 2.45])
    r = trajopt.Robot.rectangle(0.6, 0.4, 0.15, v_max=0.8)
    assert r.radius == pytest.approx(fp.circumscribed_radius) and r.v_max == 0.8
    assert r.inscribed_radius == pytest.approx(0.15)
    assert r.to_dict()["footprint"] == fp.to_list()


@pytest.mark.parametrize(
    ("vertices", "match"),
    [
        ([[0.1, 0.1], [0.2, 0.1]], "at least 3 vertices"),
        ([[1, 0], [0, 1], [-1, 0], [0.2, 0.1], [0, -1]], "convex"),  # a dent
        ([[1, 1], [-1, -1], [1, -1], [-1, 1]], "convex|self-intersecting"),  # a bow-tie
        ([[0.2, 0.1], [0.5, 0.1], [0.5, 0.4], [0.2, 0.4]], "rotation centre"),
        ([[-0.2, 0.0], [0.2, 0.0], [0.2, 0.3], [-0.2, 0.3]], "rotation centre"),  # on an edge
        ([[-0.2, -0.1], [0.2, -0.1], [math.nan, 0.1]], "finite"),
        ([[-0.2, -0.1], [0.0, -0.1], [0.2, -0.1], [0.0, 0.2]], "collinear|convex"),
    ],
)
def test_bad_footprints(vertices, match):
    with pytest.raises(InvalidInputError, match=match):
        Footprint(np.array(vertices, dtype=float))


def test_robot_footprint_rules():
    with pytest.raises(InvalidInputError, match="contradicts the footprint"):
        trajopt.Robot(radius=0.3, footprint=Footprint.rectangle(0.6, 0.4))
    with pytest.raises(InvalidInputError, match="rear_offset"):
        trajopt.Robot.rectangle(0.6, 0.4, rear_offset=0.7)
    r = trajopt.Robot(footprint=[[-0.1, -0.1], [0.3, -0.1], [0.3, 0.1], [-0.1, 0.1]])
    assert isinstance(r.footprint, Footprint) and r.radius == pytest.approx(math.hypot(0.3, 0.1))


# ------------------------------------------------------------------ swept bound
@settings(max_examples=40, deadline=None)
@given(st.floats(-4.0, 4.0), st.floats(0.0, 7.0), st.integers(0, 2))
def test_swept_hull_contains_every_rotation(lo, span, which):
    fp = [
        Footprint.rectangle(0.6, 0.4, 0.15),
        Footprint.rectangle(0.3, 0.3),
        Footprint(np.array([[0.4, 0.0], [-0.1, 0.25], [-0.2, -0.2]])),
    ][which]
    hull = fp.swept_hull(lo, lo + span)
    pts = np.vstack([fp.at(0.0, 0.0, t) for t in np.linspace(lo, lo + span, 721)])
    assert inside_convex(hull, pts, tol=1e-12).all()
    # and not loose: within 10 % of the brute-force hull's area for spans up to 45 degrees
    if span <= math.pi / 4:

        def area(p):
            return 0.5 * abs(
                np.dot(p[:, 0], np.roll(p[:, 1], -1)) - np.dot(np.roll(p[:, 0], -1), p[:, 1])
            )

        assert area(hull) <= 1.1 * area(convex_hull(pts)) + 1e-12


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**31 - 1))
def test_span_heading_intervals_hold_the_tangent(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(5, 12))
    c = np.cumsum(rng.normal(size=(n, 2)) * [1.0, 0.4] + [1.0, 0.0], axis=0)
    curve = BSplineCurve(clamped_uniform_knots(n, 3), c, 3)
    heads = span_heading_intervals(curve.t, curve.c, 3)
    for j, (lo, hi) in enumerate(heads):
        a, b = curve.t[3 + j], curve.t[4 + j]
        if b <= a:
            continue
        d = curve(np.linspace(a, b, 200), 1)
        th = np.arctan2(d[:, 1], d[:, 0])
        rel = np.remainder(th - lo + 1e-9, 2 * math.pi) - 1e-9  # the tight ends: round-off
        assert np.all(rel <= (hi - lo) + 1e-9) or hi - lo >= 2 * math.pi - 1e-9


# ------------------------------------------------------------------ certificate
@pytest.fixture(scope="module")
def door():
    res = 0.02
    occ = np.zeros((150, 200), bool)
    occ[:, 100:104] = True
    occ[60:85, 100:104] = False  # a 0.5 m door in a 8 cm wall
    return astar.OccupancyGrid(occ, res)


def test_certificate_is_sound_and_catches_a_collision(door):
    fp = Footprint.rectangle(0.7, 0.4)
    straight = np.column_stack([np.linspace(0.8, 3.2, 8), np.full(8, 1.45)])
    good = BSplineCurve(clamped_uniform_knots(8, 3, (0.0, 2.4)), straight, 3)
    cert = certify_footprint(good, fp, door)
    assert cert.ok and cert.min_margin_m == pytest.approx(0.05, abs=1e-6)
    u = np.linspace(0.0, 2.4, 500)
    xy = good(u)
    assert not footprint_collides(door, fp, xy[:, 0], xy[:, 1], np.zeros(len(u)))
    low = straight + [0.0, -0.12]  # 12 cm off the door's axis: the body hits the jamb
    bad = BSplineCurve(clamped_uniform_knots(8, 3, (0.0, 2.4)), low, 3)
    cert = certify_footprint(bad, fp, door)
    assert not cert.ok and cert.min_margin_m == 0.0
    xy = bad(u)
    assert footprint_collides(door, fp, xy[:, 0], xy[:, 1], np.zeros(len(u)))


# ------------------------------------------------------------------ plans
def test_rectangle_through_a_door_its_circumscribed_disc_cannot_pass(door):
    robot = trajopt.Robot.rectangle(0.7, 0.4, track_width=0.3, wheel_v_max=0.6)
    assert 2 * robot.circumscribed_radius > 0.5 > 0.4 + 2 * door.resolution
    with pytest.raises(trajopt.NoPathError):
        trajopt.plan(door, (0.8, 1.45), (3.2, 1.45), trajopt.Robot(radius=robot.radius))
    traj = trajopt.plan(door, (0.8, 1.45), (3.2, 1.45), robot)
    assert traj.robot is robot
    fpst = traj.stats["footprint"]
    assert fpst["disc_radius_m"] == pytest.approx(robot.inscribed_radius)
    assert fpst["min_margin_m"] > 0.0
    smp = traj.sample(np.linspace(0.0, traj.duration, 3000))
    assert not footprint_collides(door, robot.footprint, smp.x, smp.y, smp.theta)
    from trajopt.analysis.metrics import trajectory_metrics

    assert trajectory_metrics(traj, robot)["within_limits"]


def test_footprint_replan_splices(door):
    robot = trajopt.Robot.rectangle(0.7, 0.4, track_width=0.3, wheel_v_max=0.6)
    planner = trajopt.Planner(door, robot)
    traj = planner.plan((0.8, 1.45), (3.2, 1.45))
    new = planner.replan(traj, 1.0, latency=0.0)
    a, b = traj.state_at(1.0), new.state_at(0.0)
    assert max(abs(a.x - b.x), abs(a.y - b.y), abs(a.theta - b.theta), abs(a.v - b.v)) < 1e-6
    smp = new.sample(np.linspace(0.0, new.duration, 2000))
    assert not footprint_collides(door, robot.footprint, smp.x, smp.y, smp.theta)


@settings(max_examples=6, deadline=None)
@given(st.integers(0, 2**31 - 1))
def test_random_scenes_never_collide(seed):
    rng = np.random.default_rng(seed)
    occ = rng.random((60, 90)) < 0.03
    occ = np.asarray(astar.inflate(astar.OccupancyGrid(occ, 0.05), 0.05).occupied)
    grid = astar.OccupancyGrid(occ, 0.05)
    robot = trajopt.Robot.rectangle(float(rng.uniform(0.3, 0.5)), 0.24)
    free = np.argwhere(
        ~astar.inflate(
            grid, robot.circumscribed_radius + 0.05, metric="square", outside_occupied=True
        ).occupied
    )
    if len(free) < 2:
        return
    a, b = free[0], free[-1]
    try:
        traj = trajopt.plan(grid, grid.cell_to_world(a[::-1]), grid.cell_to_world(b[::-1]), robot)
    except (trajopt.NoPathError, trajopt.SmoothingError, trajopt.TimingError):
        return  # a typed refusal is allowed; a collision is not
    if traj.stats.get("fallback"):
        return
    smp = traj.sample(np.linspace(0.0, traj.duration, 1500))
    assert not footprint_collides(grid, robot.footprint, smp.x, smp.y, smp.theta)


# ------------------------------------------------------------------ against polygons
def polygon_scene(seed):
    """A 4 x 3 m map of random convex and non-convex polygons, rasterised at 0.1 m."""
    rng = np.random.default_rng(seed)
    polys = []
    for _ in range(6):
        c = rng.uniform((0.3, 0.3), (3.7, 2.7))
        k = int(rng.integers(3, 7))
        ang = (np.arange(k) + rng.uniform(0.2, 0.8, k)) * (2 * np.pi / k)
        r = rng.uniform(0.1, 0.45, k)  # a star: convex or not
        polys.append(c + np.column_stack([r * np.cos(ang), r * np.sin(ang)]))
    return astar.OccupancyGrid.from_polygons(polys, 0.1, (0.0, 0.0, 4.0, 3.0))


def sampled_clearance(grid, fp, curve, n=1500):
    """Least distance of the posed footprint to the polygons and the map's outside (shapely)."""
    shapely = pytest.importorskip("shapely")
    from shapely.geometry import Polygon, box

    u = np.linspace(*curve.domain, n)
    xy, d = curve(u), curve(u, 1)
    th = np.arctan2(d[:, 1], d[:, 0])
    obst = shapely.union_all([Polygon(p) for p in grid.polygons])
    outside = box(-1.0, -1.0, 5.0, 4.0).difference(box(0.0, 0.0, 4.0, 3.0))
    v = np.asarray(fp.vertices)
    c, s = np.cos(th)[:, None], np.sin(th)[:, None]
    x, y = xy[:, :1], xy[:, 1:]
    bodies = shapely.polygons(
        np.stack([x + c * v[:, 0] - s * v[:, 1], y + s * v[:, 0] + c * v[:, 1]], axis=-1)
    )  # the body at every pose, shape (n,)
    return float(min(shapely.distance(bodies, obst).min(), shapely.distance(bodies, outside).min()))


@pytest.mark.parametrize("seed", range(4))
def test_polygon_certificate_is_sound_against_dense_poses(seed):
    """A map with polygons is certified against them: never a pass where a pose meets one."""
    grid = polygon_scene(seed)
    rng = np.random.default_rng(100 + seed)
    fp = Footprint.rectangle(0.4, 0.2)
    passed = failed = 0
    for _ in range(10):
        # a short random walk of control points: some curves pass, some graze or cross
        turn = np.cumsum(rng.uniform(-0.5, 0.5, 6)) + rng.uniform(0.0, 2 * np.pi)
        steps = 0.12 * np.column_stack([np.cos(turn), np.sin(turn)])
        ctrl = rng.uniform((0.6, 0.6), (3.4, 2.4)) + np.cumsum(steps, axis=0)
        curve = BSplineCurve(clamped_uniform_knots(6, 3, (0.0, 1.0)), ctrl, 3)
        cert = certify_footprint(curve, fp, grid)
        true = sampled_clearance(grid, fp, curve)
        # every span's margin bounds the clearance of the poses sampled in it from below
        assert cert.min_margin_m <= true + 1e-9
        if cert.ok:
            passed += 1
            assert true > 0.0
        else:
            failed += 1
    assert passed and failed  # both outcomes were exercised


def test_polygon_certificate_passes_where_the_cells_do_not():
    """A body 3 cm from a polygon on a 0.1 m raster: the cells close the way, the polygon does not."""
    wall = np.array([[0.0, 1.0], [4.0, 1.0], [4.0, 1.3], [0.0, 1.3]])
    grid = astar.OccupancyGrid.from_polygons([wall], 0.1, (0.0, 0.0, 4.0, 3.0))
    fp = Footprint.rectangle(0.4, 0.2)
    y = 1.3 + 0.1 + 0.03  # the body's side 3 cm above the wall
    line = np.column_stack([np.linspace(0.5, 3.5, 6), np.full(6, y)])
    curve = BSplineCurve(clamped_uniform_knots(6, 3, (0.0, 1.0)), line, 3)
    cert = certify_footprint(curve, fp, grid)
    assert cert.ok and cert.min_margin_m == pytest.approx(0.03, abs=1e-9)
    cells = certify_footprint(curve, fp, astar.OccupancyGrid(grid.occupied, grid.resolution))
    assert not cells.ok
    low = line - [0.0, 0.05]  # 2 cm into the wall
    bad = BSplineCurve(clamped_uniform_knots(6, 3, (0.0, 1.0)), low, 3)
    assert not certify_footprint(bad, fp, grid).ok
    assert sampled_clearance(grid, fp, bad, 200) == 0.0
