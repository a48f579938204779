"""Tests of astar: ``astar.OccupancyGrid.from_polygons``: conservative, exact rasterisation of polygons.

Checked against independent references: shapely's exact polygon-vs-box intersection (every
cell, closed squares), dense point sampling of the polygons (every sampled point's cell must
be occupied), hand-built cases with known answers (a sliver that misses every cell centre,
a U whose notch stays free, a polygon inside one cell); hypothesis properties (union of
polygons is the union of grids, orientation and a closing vertex change nothing); bad input
refused with typed errors naming the field.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import astar
from astar.errors import InvalidInputError

shapely = pytest.importorskip("shapely")
from shapely.geometry import Polygon, box  # noqa: E402


def shapely_reference(polygons, res, bounds, shape):
    """Occupied cells by shapely: the closed cell square intersects a polygon."""
    ny, nx = shape
    xmin, ymin = bounds[0], bounds[1]
    polys = [Polygon(p) for p in polygons]
    occ = np.zeros(shape, dtype=bool)
    dist = np.full(shape, np.inf)
    for iy in range(ny):
        for ix in range(nx):
            sq = box(xmin + ix * res, ymin + iy * res, xmin + (ix + 1) * res, ymin + (iy + 1) * res)
            occ[iy, ix] = any(p.intersects(sq) for p in polys)
            dist[iy, ix] = min(p.distance(sq) for p in polys)
    return occ, dist


def assert_matches_shapely(polygons, res, bounds):
    grid = astar.OccupancyGrid.from_polygons(polygons, res, bounds)
    ref, dist = shapely_reference(polygons, res, bounds, grid.shape)
    missing = ref & ~grid.occupied
    assert not missing.any(), np.argwhere(missing)[:5]  # conservative
    extra = grid.occupied & ~ref
    # extra cells only where a polygon touches the square up to rounding
    assert np.all(dist[extra] <= 1e-8 * res), dist[extra].max()
    return grid


def star(rng, centre, r_lo, r_hi, k):
    """A simple (star-shaped, usually non-convex) polygon of ``k`` vertices."""
    # one vertex per sector of 2 pi / k: consecutive angles differ by less than pi
    ang = (np.arange(k) + rng.uniform(0.3, 0.7, k)) * (2 * math.pi / k)
    r = rng.uniform(r_lo, r_hi, k)
    return np.column_stack([centre[0] + r * np.cos(ang), centre[1] + r * np.sin(ang)])


# ------------------------------------------------------------------ hand-built exact cases


def test_triangle_by_hand():
    g = astar.OccupancyGrid.from_polygons([[(0.2, 0.2), (0.6, 0.2), (0.4, 0.6)]], 0.5, (0, 0, 1, 1))
    # the right edge is at x = 0.45 where y = 0.5: the top-right cell is untouched
    assert g.occupied.tolist() == [[True, True], [True, False]]
    assert g.origin == (0.0, 0.0) and g.resolution == 0.5 and g.shape == (2, 2)


def test_thin_sliver_misses_every_centre_yet_marks_its_cells():
    # a needle 1 mm thick along y = 0.31 from x = 0.05 to 0.95: no cell centre (y = 0.25,
    # 0.35) lies in it, no vertex is in the middle cells; the exact test marks row 3 only
    needle = [(0.05, 0.3095), (0.95, 0.3095), (0.95, 0.3105), (0.05, 0.3105)]
    g = astar.OccupancyGrid.from_polygons([needle], 0.1, (0.0, 0.0, 1.0, 1.0))
    want = np.zeros((10, 10), bool)
    want[3, 0:10] = True
    np.testing.assert_array_equal(g.occupied, want)


def test_non_convex_u_keeps_its_notch_free():
    # a U (kerb round a slot): outer 0..3 x 0..2, notch 1..2 x 0.5..2
    u = [(0, 0), (3, 0), (3, 2), (2, 2), (2, 0.5), (1, 0.5), (1, 2), (0, 2)]
    g = assert_matches_shapely([u], 0.25, (-0.5, -0.5, 3.5, 2.5))
    # the notch's inner cells (x in (1, 2), y in (0.5, 2)) are free, cells on its walls are not
    cx = (np.arange(g.nx) + 0.5) * 0.25 - 0.5
    cy = (np.arange(g.ny) + 0.5) * 0.25 - 0.5
    inner = (np.abs(cx - 1.5) < 0.3)[None, :] & ((cy > 0.9) & (cy < 1.9))[:, None]
    assert not g.occupied[inner].any()
    assert g.occupied[np.argmin(np.abs(cy - 1.0)), np.argmin(np.abs(cx - 1.125))]  # wall x = 1


def test_polygon_inside_one_cell_marks_that_cell():
    tri = [(0.52, 0.52), (0.58, 0.53), (0.55, 0.58)]
    g = astar.OccupancyGrid.from_polygons([tri], 0.1, (0.0, 0.0, 1.0, 1.0))
    assert np.argwhere(g.occupied).tolist() == [[5, 5]]


def test_edges_on_grid_lines_mark_both_sides():
    # closed squares: a square whose sides lie on grid lines touches the ring of cells round it
    sq = [(0.25, 0.25), (0.75, 0.25), (0.75, 0.75), (0.25, 0.75)]
    g = astar.OccupancyGrid.from_polygons([sq], 0.25, (0.0, 0.0, 1.0, 1.0))
    assert g.occupied.all()
    g = astar.OccupancyGrid.from_polygons([sq], 0.25, (0.0, 0.0, 1.5, 1.5))
    assert g.occupied[:4, :4].all() and not g.occupied[4:, :].any() and not g.occupied[:, 4:].any()


def test_outside_bounds_is_ignored_and_the_extent_is_rounded_up():
    g = astar.OccupancyGrid.from_polygons([[(5, 5), (6, 5), (6, 6)]], 0.3, (0.0, 0.0, 1.0, 0.9))
    assert g.shape == (3, 4) and not g.occupied.any()  # 0.9 / 0.3 = 3 up to rounding
    assert g.origin == (0.0, 0.0)


# ------------------------------------------------------------------ references


@pytest.mark.parametrize("seed", range(6))
def test_random_polygons_match_shapely(seed):
    rng = np.random.default_rng(seed)
    res = [0.1, 0.05, 0.13][seed % 3]
    polys = [
        star(rng, rng.uniform(0.3, 1.7, 2), 0.05, 0.6, int(rng.integers(3, 12))) for _ in range(3)
    ]
    # a rotated rectangle (a parked car) too
    th = rng.uniform(0, math.pi)
    c, s = math.cos(th), math.sin(th)
    rect = np.array([[-0.4, -0.2], [0.4, -0.2], [0.4, 0.2], [-0.4, 0.2]]) @ [[c, s], [-s, c]] + 1.0
    assert_matches_shapely([*polys, rect], res, (-0.1, -0.2, 2.1, 2.05))


def dense_points(poly, step):
    """Points inside and on the boundary of ``poly``, ``step`` m apart (brute force)."""
    p = Polygon(poly)
    x0, y0, x1, y1 = p.bounds
    xs, ys = np.meshgrid(np.arange(x0, x1 + step, step), np.arange(y0, y1 + step, step))
    pts = np.column_stack([xs.ravel(), ys.ravel()])
    inside = shapely.contains_xy(p, pts[:, 0], pts[:, 1])
    v = np.asarray(poly, float)
    w = np.roll(v, -1, axis=0)
    edge = [v[i] + np.linspace(0, 1, 200)[:, None] * (w[i] - v[i]) for i in range(len(v))]
    return np.vstack([pts[inside], *edge])


def sample_points_strategy():
    return st.tuples(
        st.integers(0, 2**31 - 1),
        st.integers(3, 10),
        st.sampled_from([0.05, 0.1, 0.2, 0.0625]),
    )


@settings(max_examples=40, deadline=None)
@given(sample_points_strategy())
def test_dense_samples_lie_in_occupied_cells(params):
    seed, k, res = params
    rng = np.random.default_rng(seed)
    poly = star(rng, rng.uniform(0.5, 1.5, 2), 0.02, 0.5, k)
    bounds = (0.0, 0.0, 2.0, 2.0)
    g = astar.OccupancyGrid.from_polygons([poly], res, bounds)
    pts = dense_points(poly, res / 7.0)
    cells = np.floor(pts / res).astype(int)
    ok = (cells[:, 0] < g.nx) & (cells[:, 1] < g.ny) & (cells >= 0).all(axis=1)
    assert g.occupied[cells[ok, 1], cells[ok, 0]].all()
    # and a point on a grid line occupies the cells on both sides (closed squares)
    on = np.isclose(pts / res, np.round(pts / res), atol=0, rtol=0)
    left = cells - on.astype(int)
    ok = (left >= 0).all(axis=1) & (left[:, 0] < g.nx) & (left[:, 1] < g.ny)
    assert g.occupied[left[ok, 1], left[ok, 0]].all()


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**31 - 1))
def test_union_orientation_and_closing_vertex_change_nothing(seed):
    rng = np.random.default_rng(seed)
    polys = [
        star(rng, rng.uniform(0.3, 1.7, 2), 0.05, 0.5, int(rng.integers(3, 9))) for _ in range(3)
    ]
    bounds, res = (0.0, 0.0, 2.0, 2.0), 0.07
    both = astar.OccupancyGrid.from_polygons(polys, res, bounds).occupied
    each = [astar.OccupancyGrid.from_polygons([p], res, bounds).occupied for p in polys]
    np.testing.assert_array_equal(both, np.logical_or.reduce(each))
    flipped = [p[::-1] for p in polys]
    closed = [np.vstack([p, p[:1]]) for p in polys]
    np.testing.assert_array_equal(
        astar.OccupancyGrid.from_polygons(flipped, res, bounds).occupied, both
    )
    np.testing.assert_array_equal(astar.from_polygons(closed, res, bounds).occupied, both)


@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(st.integers(0, 4), st.integers(0, 4)), min_size=3, max_size=7))
def test_simple_ring_check_agrees_with_shapely(vertices):
    # small integer vertices: many collinear, touching and crossing cases
    v = np.array(vertices, float)
    if np.array_equal(v[0], v[-1]):
        v = v[:-1]  # a closing vertex is dropped (by both)
    ring = shapely.geometry.LinearRing(v) if len(np.unique(v, axis=0)) >= 3 else None
    repeated = np.any(np.all(v == np.roll(v, -1, axis=0), axis=1))
    want = ring is not None and not repeated and ring.is_simple and Polygon(v).area > 0
    try:
        astar.OccupancyGrid.from_polygons([v], 1.0, (0, 0, 4, 4))
    except InvalidInputError:
        got = False
    else:
        got = True
    assert got == want, v.tolist()


def test_grid_is_a_validated_read_only_value():
    g = astar.from_polygons([[(0, 0), (1, 0), (0, 1)]], 0.5, (0, 0, 1, 1))
    assert isinstance(g, astar.OccupancyGrid)
    assert g == astar.OccupancyGrid(g.occupied.copy(), 0.5, (0.0, 0.0))
    assert not g.occupied.flags.writeable


# ------------------------------------------------------------------ bad input


TRI = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)]
BOUNDS = (0.0, 0.0, 2.0, 2.0)


@pytest.mark.parametrize(
    ("polygons", "words"),
    [
        ([[(0, 0), (1, 1), (1, 0), (0, 1)]], ["polygons[0]", "self-intersecting"]),  # a bow-tie
        ([TRI, [(0, 0), (2, 0), (2, 1), (1, 0), (0, 1)]], ["polygons[1]", "self-intersecting"]),
        ([[(0, 0), (2, 0), (1, 0), (1, 1)]], ["polygons[0]", "self-intersecting"]),  # folds back
        ([[(0, 0), (1, 0), (1, 0), (0, 1)]], ["polygons[0]", "repeats a vertex", "[1.0, 0.0]"]),
        ([[(0, 0), (1, 0), (0, 0)]], ["polygons[0]", "3 distinct"]),
        ([[(0, 0), (1, 1), (2, 2)]], ["polygons[0]", "non-zero area"]),
        ([[(0, 0), (1, 0)]], ["polygons[0]", "3 distinct"]),
        ([[(0, 0), (math.nan, 0), (0, 1)]], ["polygons[0]", "finite", "vertex 1"]),
        ([[(0, 0), (math.inf, 0), (0, 1)]], ["polygons[0]", "finite"]),
        ([[0, 1, 2]], ["polygons[0]", "shape (k, 2)"]),
        ([[("a", 1), (2, 3), (4, 5)]], ["polygons[0]"]),
        ("abc", ["polygons", "sequence"]),
        (None, ["polygons", "sequence"]),
    ],
)
def test_bad_polygons_refused(polygons, words):
    with pytest.raises(InvalidInputError) as err:
        astar.OccupancyGrid.from_polygons(polygons, 0.1, BOUNDS)
    for w in words:
        assert w in str(err.value), (w, str(err.value))


@pytest.mark.parametrize(
    ("bounds", "words"),
    [
        ((0, 0, 0, 1), ["bounds", "enclose an area", "xmax > xmin"]),
        ((0, 1, 1, 0.5), ["bounds", "enclose an area"]),
        ((0, 0, math.inf, 1), ["bounds", "finite", "inf"]),
        ((0, math.nan, 1, 1), ["bounds", "finite"]),
        ((0, 0, 1), ["bounds", "(xmin, ymin, xmax, ymax)"]),
        ("abcd", ["bounds"]),
    ],
)
def test_bad_bounds_refused(bounds, words):
    with pytest.raises(InvalidInputError) as err:
        astar.OccupancyGrid.from_polygons([TRI], 0.1, bounds)
    for w in words:
        assert w in str(err.value), (w, str(err.value))


@pytest.mark.parametrize("res", [0.0, -0.1, math.nan, math.inf, "x", True])
def test_bad_resolution_refused(res):
    with pytest.raises(InvalidInputError, match="resolution"):
        astar.OccupancyGrid.from_polygons([TRI], res, BOUNDS)


def test_an_empty_list_is_an_empty_map():
    g = astar.OccupancyGrid.from_polygons([], 0.5, BOUNDS)
    assert g.shape == (4, 4) and not g.occupied.any()


@pytest.mark.parametrize("seed", range(4))
def test_a_polygon_window_matches_shapely_on_its_cells(seed):
    """A finer window of a map's own polygons is the conservative raster of that window."""
    rng = np.random.default_rng(100 + seed)
    polys = [
        star(rng, rng.uniform(0.3, 1.7, 2), 0.05, 0.6, int(rng.integers(3, 12))) for _ in range(4)
    ]
    grid = astar.OccupancyGrid.from_polygons(polys, 0.1, (-0.1, -0.2, 2.1, 2.05))
    lo = rng.uniform(-0.1, 1.0, 2)
    bounds = (float(lo[0]), float(lo[1]), float(lo[0] + 0.9), float(lo[1] + 0.7))
    res = [0.025, 0.0125, 0.05, 0.02][seed]
    window = grid.polygon_window(res, bounds)
    assert window.polygons is grid.polygons
    assert window.origin == (bounds[0], bounds[1]) and window.resolution == res
    ref, dist = shapely_reference(polys, res, bounds, window.shape)
    assert not (ref & ~window.occupied).any()  # conservative
    extra = window.occupied & ~ref
    assert np.all(dist[extra] <= 1e-8 * res)  # extra cells only where touching up to rounding
    again = astar.OccupancyGrid.from_polygons(polys, res, bounds)
    np.testing.assert_array_equal(window.occupied, again.occupied)


def test_a_polygon_window_needs_a_grid_made_from_polygons():
    grid = astar.OccupancyGrid(np.zeros((4, 4), dtype=bool), 0.1)
    with pytest.raises(InvalidInputError, match="polygons are None"):
        grid.polygon_window(0.05, (0.0, 0.0, 0.2, 0.2))
    made = astar.OccupancyGrid.from_polygons(
        [[(0.1, 0.1), (0.3, 0.1), (0.2, 0.3)]], 0.1, (0, 0, 1, 1)
    )
    with pytest.raises(InvalidInputError, match="resolution"):
        made.polygon_window(-0.05, (0.0, 0.0, 0.2, 0.2))
    with pytest.raises(InvalidInputError, match="bounds"):
        made.polygon_window(0.05, (0.0, 0.0, -0.2, 0.2))
