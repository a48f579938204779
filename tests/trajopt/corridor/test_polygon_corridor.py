"""Tests of :mod:`trajopt.corridor` against brute force.

The references (``tests/reference.py``) are independent of the module: exact
point-to-square distances to every occupied cell of the raw map (and to the outside of the
map) computed naively with numpy over all cells, evaluated on dense samples of each
polygon's boundary and interior.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import astar
from astar.grid import OccupancyGrid
from tests.cases import square_inflated, staircase_passage
from tests.reference import boundary_samples, brute_polygon_clearance, square_clearance
from trajopt.analysis import scenes
from trajopt.corridor import (
    CLEARANCE_TOL_M,
    ConvexPolygon,
    PolygonCorridor,
    build_corridor,
    build_polygon_corridor,
)
from trajopt.corridor._polygons.build import (
    GrownRegions,
    PolygonOptions,
    assemble_corridor,
    grow_regions,
)
from trajopt.errors import InvalidInputError
from trajopt.geometry._clearance import polygon_clearance


# ---------------------------------------------------------------- checks
def assert_corridor_certified(corr: PolygonCorridor, grid: OccupancyGrid, radius: float) -> None:
    """Every region keeps ``radius`` on dense samples (brute force), covers its own path
    segment, and consecutive regions share the transition point and their overlap."""
    res = grid.resolution
    tol = CLEARANCE_TOL_M
    centres = np.column_stack(np.nonzero(grid.occupied)[::-1]) * res + res / 2 + grid.origin
    for k, reg in enumerate(corr.regions):
        # the distance from a convex region to a square it does not contain is attained
        # on the region's boundary: sample it densely, and check no occupied cell lies
        # inside (its centre would)
        samples = boundary_samples(reg.vertices, res / 8)
        assert reg.contains(samples, tol=1e-9).all()
        c = square_clearance(grid, samples, reach=radius + 2 * res)
        assert c.min() >= radius - tol, (k, c.min(), radius)
        assert not reg.contains(centres).any()
        assert corr.clearance_m[k] >= radius - tol
        # its own path segment, and the whole arc-length interval it claims
        seg = corr.path[k : k + 2]
        assert reg.contains(seg, tol=1e-9).all()
        lo, hi = corr.region_s[k]
        assert lo <= corr.path_s[k] + 1e-12 and hi >= corr.path_s[k + 1] - 1e-12
        s = np.linspace(lo, hi, 25)
        pts = np.column_stack(
            [np.interp(s, corr.path_s, corr.path[:, 0]), np.interp(s, corr.path_s, corr.path[:, 1])]
        )
        assert reg.contains(pts, tol=1e-9).all()
        a, b = corr.region_index[k]
        assert a <= k and b >= k + 1
        assert reg.contains(corr.path[a : b + 1], tol=1e-9).all()
    t = corr.transitions_m
    assert np.all(np.diff(t) > 0) and (len(t) == 0 or (t[0] > 0 and t[-1] < corr.length_m))
    for k in range(len(corr) - 1):
        p = corr.transition_points[k]
        assert corr.regions[k].contains(p, tol=1e-9)
        assert corr.regions[k + 1].contains(p, tol=1e-9)
        lo, hi = corr.overlap_s[k]
        assert lo <= t[k] <= hi
        assert lo <= corr.path_s[k + 1] <= hi
        s = np.linspace(lo, hi, 15)
        pts = np.column_stack(
            [np.interp(s, corr.path_s, corr.path[:, 0]), np.interp(s, corr.path_s, corr.path[:, 1])]
        )
        assert corr.regions[k].contains(pts, tol=1e-9).all()
        assert corr.regions[k + 1].contains(pts, tol=1e-9).all()
        ov = corr.overlaps[k]
        assert corr.regions[k].contains(ov.vertices, tol=1e-9).all()
        assert corr.regions[k + 1].contains(ov.vertices, tol=1e-9).all()
    # end points are the input's
    np.testing.assert_array_equal(corr.path[0], corr.input_path[0])
    np.testing.assert_array_equal(corr.path[-1], corr.input_path[-1])


# ---------------------------------------------------------------- random grids
@st.composite
def random_scene(draw):
    nx = draw(st.integers(14, 30))
    ny = draw(st.integers(14, 30))
    seed = draw(st.integers(0, 2**31 - 1))
    rng = np.random.default_rng(seed)
    occ = np.zeros((ny, nx), dtype=bool)
    for _ in range(draw(st.integers(0, 7))):
        w, h = rng.integers(1, 6, size=2)
        x, y = rng.integers(0, nx), rng.integers(0, ny)
        occ[y : y + h, x : x + w] = True
    occ |= rng.random((ny, nx)) < draw(st.sampled_from([0.0, 0.02, 0.05]))
    res = draw(st.sampled_from([0.05, 0.1, 0.25]))
    origin = (draw(st.sampled_from([0.0, -1.3, 2.75])), draw(st.sampled_from([0.0, 0.6, -3.1])))
    radius = draw(st.sampled_from([0.1, 0.5, 1.0, 1.5, 2.0, 2.5])) * res
    return OccupancyGrid(occ, res, origin), radius, seed, draw(st.booleans())


@settings(derandomize=True, deadline=None, max_examples=40)
@given(random_scene())
def test_random_grids_certified_against_brute_force(scene) -> None:
    grid, radius, seed, as_points = scene
    infl = square_inflated(grid, radius)
    ys, xs = np.nonzero(~infl.occupied)
    assume(len(xs) >= 2)
    rng = np.random.default_rng(seed)
    i, j = rng.choice(len(xs), 2, replace=False)
    try:
        path = astar.find_path(infl, (int(xs[i]), int(ys[i])), (int(xs[j]), int(ys[j])))
    except astar.NoPathError:
        assume(False)
    # the cells, or their centres as world points (m)
    corr = build_polygon_corridor(grid, path.to_world(grid) if as_points else path, radius)
    assert_corridor_certified(corr, grid, radius)
    # the polygon certificate agrees with the public clearance function
    for k, reg in enumerate(corr.regions):
        c = polygon_clearance(reg, grid)
        assert c >= radius - CLEARANCE_TOL_M
        assert min(c, radius + grid.resolution) == pytest.approx(corr.clearance_m[k], abs=1e-9)


@settings(derandomize=True, deadline=None, max_examples=60)
@given(
    st.integers(0, 2**31 - 1),
    st.integers(1, 6),
    st.sampled_from([0.0, 0.03, 0.1]),
)
def test_polygon_clearance_matches_dense_sampling(seed, k, density) -> None:
    rng = np.random.default_rng(seed)
    n = 12
    occ = rng.random((n, n)) < density
    occ[rng.integers(0, n), rng.integers(0, n)] = True
    grid = OccupancyGrid(occ, 0.5, (1.0, -2.0))
    centre = rng.uniform([1.5, -1.5], [6.5, 3.5])
    pts = centre + rng.normal(scale=rng.uniform(0.05, 1.5), size=(k + 2, 2))
    if k == 1:
        v = pts[:1]
    elif k == 2:
        v = pts[:2]
    else:
        from scipy.spatial import ConvexHull

        try:
            v = pts[ConvexHull(pts).vertices]  # counter-clockwise
        except Exception:
            assume(False)
    exact = polygon_clearance(v, grid)
    h = 0.5 / 40
    est = brute_polygon_clearance(v, grid, h)
    assert exact <= est + 1e-12
    assert est <= exact + h


# ---------------------------------------------------------------- hand cases
def wall_gap_cells(occ: np.ndarray, angle_deg: float) -> float:
    """Smallest distance (cells) between an occupied square on one side of the strip and
    one on the other (brute force)."""
    n = occ.shape[0]
    th = math.radians(angle_deg)
    iy, ix = np.nonzero(occ)
    d = -math.sin(th) * (ix + 0.5 - n / 2) + math.cos(th) * (iy + 0.5 - n / 2)
    a = np.column_stack([ix[d > 0], iy[d > 0]])
    b = np.column_stack([ix[d < 0], iy[d < 0]])
    gx = np.maximum(0, np.abs(a[:, None, 0] - b[None, :, 0]) - 1)
    gy = np.maximum(0, np.abs(a[:, None, 1] - b[None, :, 1]) - 1)
    return float(np.hypot(gx, gy).min())


@pytest.mark.parametrize(
    ("angle", "extra"), [(45, 2.0), (45, 3.0), (30, 1.0), (30, 2.0), (30, 3.0)]
)
def test_staircase_passage_gets_long_rotated_regions(angle, extra) -> None:
    res, r_cells = 0.05, 2.5
    radius = r_cells * res
    occ = staircase_passage(angle, 2 * r_cells + extra)
    gap = wall_gap_cells(occ, angle)
    assert 2 * r_cells + 1 <= gap <= 2 * r_cells + 3.5  # free width 2r + 1 .. 2r + 3(.5)
    grid = OccupancyGrid(occ, res)
    infl = square_inflated(grid, radius)
    th = math.radians(angle)
    ys, xs = np.nonzero(~infl.occupied)
    proj = (xs + 0.5 - 30) * math.cos(th) + (ys + 0.5 - 30) * math.sin(th)
    ia = int(np.argmin(np.abs(proj + 20)))
    ib = int(np.argmin(np.abs(proj - 20)))
    path = astar.find_path(infl, (int(xs[ia]), int(ys[ia])), (int(xs[ib]), int(ys[ib])))
    corr = build_polygon_corridor(grid, path, radius)
    assert_corridor_certified(corr, grid, radius)
    boxes = build_corridor(infl, path, radius=radius)
    box_area = max((b.xmax - b.xmin) * (b.ymax - b.ymin) for b in boxes.boxes)
    box_overlap = float(np.max(boxes.overlap_end_m - boxes.overlap_start_m))
    # a handful of long rotated regions instead of a staircase of tiny boxes
    assert len(corr) <= 5 < len(boxes)
    areas = np.array([g.area for g in corr.regions])
    assert np.median(areas) >= 5 * box_area
    # consecutive regions share a real stretch of path (>= 3 cells), longer than any
    # box overlap, and a region of positive area
    assert corr.overlap_lengths_m.min() >= max(3 * res, 1.5 * box_overlap)
    assert corr.overlap_areas.min() > 0.5 * res * res
    # each region is long along the passage: its path share is most of its seed segment
    lengths = corr.region_s[:, 1] - corr.region_s[:, 0]
    assert np.max(lengths) >= 20 * res


def test_diagonal_door() -> None:
    """A thick 45-degree staircase wall with a door 2r + 2 cells wide, crossed at right
    angles to the wall: certified, and one region reaches through the door."""
    res, r_cells = 0.1, 2.5
    radius = r_cells * res
    n = 50
    iy, ix = np.mgrid[0:n, 0:n]
    d = (ix - iy).astype(float)  # wall along x - y = 0, 3 cells thick
    along = (ix + iy).astype(float)
    occ = (np.abs(d) <= 1) & ~(np.abs(along - n) <= 5)  # door: 11 cells along the wall
    grid = OccupancyGrid(occ, res)
    infl = square_inflated(grid, radius)
    path = astar.find_path(infl, (32, 18), (18, 32))
    corr = build_polygon_corridor(grid, path, radius)
    assert_corridor_certified(corr, grid, radius)
    door_centre = np.array([n / 2, n / 2]) * res
    owners = [k for k, g in enumerate(corr.regions) if g.contains(door_centre, tol=1e-9)]
    assert owners
    # the region through the door extends at least 3 cells to both sides of the wall
    g = corr.regions[owners[0]]
    normal = np.array([1.0, -1.0]) / math.sqrt(2)
    reach = g.vertices @ normal - door_centre @ normal
    assert reach.max() >= 3 * res and reach.min() <= -3 * res


@pytest.mark.parametrize("target", ["A", "B", "C", "D"])
@pytest.mark.parametrize("search", ["clearance", "shortest"])
def test_paper_scene_certified(target, search) -> None:
    scene = scenes.paper()
    grid, radius = scene.grid, scene.robot_radius
    infl = square_inflated(grid, radius)
    cost = (
        astar.clearance_cost(grid, radius, outside_occupied=True) if search == "clearance" else None
    )
    path = astar.find_path(infl, scene.start_cell, scene.goal_cell(target), cost=cost)
    corr = build_polygon_corridor(grid, path, radius)
    assert_corridor_certified(corr, grid, radius)
    assert corr.overlap_lengths_m.min() >= 2 * grid.resolution


def test_world_points_with_exact_end_points() -> None:
    scene = scenes.paper()
    grid, radius = scene.grid, scene.robot_radius
    path = astar.find_path(square_inflated(grid, radius), scene.start_cell, scene.goal_cell("D"))
    pts = path.to_world(grid)
    pts[0], pts[-1] = scene.start, scene.goal("D")
    corr = build_polygon_corridor(grid, pts, radius)
    assert_corridor_certified(corr, grid, radius)
    np.testing.assert_array_equal(corr.path[0], scene.start)
    np.testing.assert_array_equal(corr.path[-1], scene.goal("D"))
    assert np.all(np.diff(corr.source_index) > 0)
    assert corr.source_index[0] == 0 and corr.source_index[-1] == len(pts) - 1


# ---------------------------------------------------------------- degenerate passages
def test_passage_exactly_2r_wide_gives_a_degenerate_region() -> None:
    res, r_cells = 0.1, 2.5
    radius = r_cells * res
    occ = np.ones((20, 40), dtype=bool)
    occ[8:13, :] = False  # 5 free rows: the centre row keeps exactly r from both walls
    occ[2:18, :8] = False  # rooms at both ends
    occ[2:18, 32:] = False
    grid = OccupancyGrid(occ, res)
    infl = square_inflated(grid, radius)
    path = astar.find_path(infl, (5, 10), (35, 10))
    corr = build_polygon_corridor(grid, path, radius)
    assert_corridor_certified(corr, grid, radius)
    degen = [g for g in corr.regions if g.degenerate]
    assert degen
    for g in degen:
        assert g.area == 0.0 and len(g.vertices) == 2
        a, c = g.line
        np.testing.assert_allclose(g.vertices @ a, c, atol=1e-12)
        assert abs(g.vertices[0, 1] - 1.05) < 1e-9  # on the passage's centre line y = 1.05
        assert polygon_clearance(g, grid) >= radius - CLEARANCE_TOL_M


# ---------------------------------------------------------------- bad input
def _room(n: int = 20, res: float = 0.1) -> OccupancyGrid:
    occ = np.zeros((n, n), dtype=bool)
    occ[8:12, 8:12] = True
    return OccupancyGrid(occ, res)


def test_radius_larger_than_free_space_at_start_and_goal() -> None:
    grid = _room()
    with pytest.raises(
        InvalidInputError, match=r"start \[0\.15, 0\.15\] m has clearance 0\.15 m.*radius 0\.25"
    ):
        build_polygon_corridor(grid, np.array([[0.15, 0.15], [1.0, 0.4]]), 0.25)
    with pytest.raises(
        InvalidInputError, match=r"goal \[0\.75, 0\.75\] m has clearance 0\.0707107 m"
    ):
        build_polygon_corridor(grid, np.array([[0.5, 0.5], [0.75, 0.75]]), 0.3)


def test_points_outside_the_map() -> None:
    grid = _room()
    with pytest.raises(InvalidInputError, match=r"start \[-0\.5, 1\.0\] m lies outside the map"):
        build_polygon_corridor(grid, np.array([[-0.5, 1.0], [1.0, 1.0]]), 0.1)
    with pytest.raises(InvalidInputError, match="goal .* lies outside the map"):
        build_polygon_corridor(grid, np.array([[0.5, 0.5], [0.5, 2.5]]), 0.1)
    with pytest.raises(InvalidInputError, match="outside the map"):
        build_polygon_corridor(grid, np.array([[5, 5], [25, 5]]), 0.1)  # cells


def test_path_through_a_gap_narrower_than_2r() -> None:
    res = 0.1
    occ = np.zeros((20, 30), dtype=bool)
    occ[:, 14:16] = True
    occ[9:12, 14:16] = False  # a 3-cell gap: 0.3 m < 2 r = 0.5 m
    grid = OccupancyGrid(occ, res)
    path = astar.find_path(astar.inflate(grid, 0.1, metric="square"), (5, 10), (25, 10))
    with pytest.raises(
        InvalidInputError,
        match=r"path point \d+ .* m has clearance 0\.\d+ m, less than the radius 0\.25 m",
    ):
        build_polygon_corridor(grid, path, 0.25)
    # a straight segment across the wall with free end points: the segment rule
    with pytest.raises(
        InvalidInputError, match=r"path segment .* narrower than 2 \* radius = 0\.2 m"
    ):
        build_polygon_corridor(grid, np.array([[0.5, 0.5], [2.5, 0.5]]), 0.1)


def test_bad_arguments() -> None:
    grid = _room()
    pts = np.array([[0.5, 0.5], [1.5, 0.5]])
    with pytest.raises(InvalidInputError, match="radius must be finite and > 0"):
        build_polygon_corridor(grid, pts, 0.0)
    with pytest.raises(InvalidInputError, match="margin_cells must be finite and > 0"):
        build_polygon_corridor(grid, pts, 0.1, margin_cells=0)
    with pytest.raises(InvalidInputError, match="at least two distinct points"):
        build_polygon_corridor(grid, np.array([[0.5, 0.5], [0.5, 0.5]]), 0.1)
    with pytest.raises(InvalidInputError, match=r"shape \(n, 2\)"):
        build_polygon_corridor(grid, np.zeros((3, 3)), 0.1)
    with pytest.raises(InvalidInputError, match="OccupancyGrid"):
        build_polygon_corridor(np.zeros((4, 4)), pts, 0.1)


def test_polygon_options_are_checked_on_construction() -> None:
    opts = PolygonOptions(margin_cells=3, open_cells=np.float32(1.5))
    assert opts == PolygonOptions(margin_cells=3.0, open_cells=1.5)
    assert all(type(v) is float for v in dataclasses.astuple(opts))
    assert dataclasses.astuple(PolygonOptions()) == (16.0, 20.0, 4.0, 1.0, 2.0, 0.3, 2.0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        opts.margin_cells = 1.0  # type: ignore[misc]
    for bad in (
        {"margin_cells": 0.0},
        {"max_segment_cells": -1.0},
        {"overlap_cells": -0.5},
        {"centre_cells": math.nan},
        {"centre_trigger_cells": math.inf},
        {"simplify_slack_cells": "0.3"},
        {"open_cells": True},
    ):
        (name,) = bad
        with pytest.raises(InvalidInputError, match=name):
            PolygonOptions(**bad)
    with pytest.raises(InvalidInputError, match="PolygonOptions"):
        grow_regions(_room(), np.array([[0.5, 0.5], [1.5, 0.5]]), 0.1, {"margin_cells": 3.0})


def test_grown_regions_assemble_into_the_built_corridor() -> None:
    grid = _room()
    pts = np.array([[0.25, 0.25], [1.65, 0.35], [1.75, 1.75]])
    grown = grow_regions(grid, pts, 0.1, PolygonOptions(centre_cells=0.0))
    assert isinstance(grown, GrownRegions)
    m = len(grown.regions)
    assert grown.hm.shape[0] == grown.vm.shape[0] == m
    assert grown.path_m.shape == (m + 1, 2) and grown.clear_m.shape == (m,)
    built = build_polygon_corridor(grid, pts, 0.1, centre_cells=0.0)
    assembled = assemble_corridor(grown)
    np.testing.assert_array_equal(assembled.path, built.path)
    np.testing.assert_array_equal(assembled.transitions_m, built.transitions_m)
    for a, b in zip(assembled.regions, built.regions, strict=True):
        np.testing.assert_array_equal(a.vertices, b.vertices)


# ---------------------------------------------------------------- the value
def test_convex_polygon_value() -> None:
    v = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    a = np.array([[0.0, -1.0], [1.0, 0.0], [0.0, 1.0], [-1.0, 0.0]])
    b = np.array([0.0, 1.0, 1.0, 0.0])
    sq = ConvexPolygon(A=a, b=b, vertices=v)
    assert sq.area == pytest.approx(1.0) and sq.n_sides == 4 and sq.line is None
    assert sq.contains([[0.5, 0.5], [1.0, 1.0], [1.1, 0.5]]).tolist() == [True, True, False]
    assert sq.contains([1.05, 0.5], tol=0.1)
    with pytest.raises(ValueError):
        sq.A[0, 0] = 2.0
    a[0, 0] = 5.0  # the value holds a copy
    assert sq.A[0, 0] == 0.0
    shifted = ConvexPolygon(A=sq.A, b=sq.b + np.array([-0.5, 0.5, 0.5, -0.5]), vertices=v + 0.5)
    ov = sq.intersection(shifted)
    assert ov.area == pytest.approx(0.25)
    assert ov.contains(ov.vertices, tol=1e-12).all()
    touching = ConvexPolygon(
        A=sq.A, b=sq.b + np.array([0.0, 1.0, 0.0, -1.0]), vertices=v + [1.0, 0.0]
    )
    edge = sq.intersection(touching)
    assert edge.degenerate and edge.area == 0.0 and len(edge.vertices) == 2
    far = ConvexPolygon(A=sq.A, b=sq.b + np.array([0.0, 5.0, 0.0, -5.0]), vertices=v + [5.0, 0.0])
    with pytest.raises(InvalidInputError, match="do not intersect"):
        sq.intersection(far)
    with pytest.raises(InvalidInputError, match="norm 1"):
        ConvexPolygon(A=2 * sq.A, b=b, vertices=v)
    with pytest.raises(InvalidInputError, match="counter-clockwise"):
        ConvexPolygon(A=sq.A, b=b, vertices=v[::-1])
    with pytest.raises(InvalidInputError, match="b must have shape"):
        ConvexPolygon(A=sq.A, b=b[:3], vertices=v)
