"""Tests of :mod:`trajopt.corridor` against brute force on hand-built and random grids.

The references (brute-force square inflation, an octile Dijkstra, a sampled rectangle
clearance) are independent of :mod:`astar` and live in ``tests/reference.py``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from astar.grid import OccupancyGrid
from tests.cases import l_shaped_grid
from tests.reference import brute_inflate_square, dijkstra_path, sampled_rect_clearance
from trajopt.corridor import Box, Corridor, build_corridor
from trajopt.errors import InvalidInputError


# ---------------------------------------------------------------- checks
def assert_corridor_valid(corr: Corridor, free: np.ndarray, cells: np.ndarray, res: float, origin):
    """Every box free (brute force), consecutive boxes overlap, the path is covered."""
    ox, oy = origin
    for b in corr.boxes:
        assert free[b.iy0 : b.iy1 + 1, b.ix0 : b.ix1 + 1].all()
        assert b.xmin == pytest.approx(ox + (b.ix0 + 0.5) * res)
        assert b.ymax == pytest.approx(oy + (b.iy1 + 0.5) * res)
    for a, b in zip(corr.boxes[:-1], corr.boxes[1:], strict=True):
        assert max(a.ix0, b.ix0) <= min(a.ix1, b.ix1) and max(a.iy0, b.iy0) <= min(a.iy1, b.iy1)
    covered = np.zeros(len(cells), bool)
    for k, (b, (i0, i1)) in enumerate(zip(corr.boxes, corr.path_ranges, strict=True)):
        assert b.contains_cells(cells[i0 : i1 + 1]).all()
        covered[i0 : i1 + 1] = True
        if k:
            assert i0 <= corr.path_ranges[k - 1][1]  # shares path cells with its predecessor
    assert covered.all()
    pts = np.asarray(origin) + (cells + 0.5) * res
    assert corr.contains(pts).all()
    assert np.all(np.diff(corr.transitions_m) > 0)
    assert np.all(corr.transitions_m >= corr.overlap_start_m - 1e-12)
    assert np.all(corr.transitions_m <= corr.overlap_end_m + 1e-12)


# --------------------------------------------------------------------- tests
def test_l_shaped_corridor_valid_and_deterministic():
    occ = l_shaped_grid()
    infl = brute_inflate_square(occ, 1.5)
    grid = OccupancyGrid(infl, 0.1, (-1.0, 2.0))
    cells = dijkstra_path(~infl, (5, 6), (23, 24))
    c1 = build_corridor(grid, cells, radius=0.15)
    c2 = build_corridor(grid, cells, radius=0.15)
    assert_corridor_valid(c1, ~infl, cells, 0.1, (-1.0, 2.0))
    assert c1.boxes == c2.boxes
    assert np.array_equal(c1.transitions_m, c2.transitions_m)
    assert c1.radius == 0.15
    assert all(b.cells_x <= 32 and b.cells_y <= 32 for b in c1.boxes)


def test_max_side_cells_bounds_boxes():
    free = np.ones((60, 80), bool)
    cells = np.array([(x, 30) for x in range(2, 78)], dtype=np.int64)
    corr = build_corridor(OccupancyGrid(~free, 1.0), cells, max_side_cells=8)
    assert len(corr) >= 76 // 8
    assert all(b.cells_x <= 8 and b.cells_y <= 8 for b in corr.boxes)
    assert_corridor_valid(corr, free, cells, 1.0, (0.0, 0.0))


def test_single_cell_path_and_box_helpers():
    free = np.ones((5, 5), bool)
    corr = build_corridor(OccupancyGrid(~free, 0.5), np.array([[2, 2]]))
    assert len(corr) == 1 and corr.length_m == 0.0
    b = Box(0.0, 1.0, 0.0, 2.0, 0, 2, 0, 4)
    assert b.contains(np.array([[0.5, 1.0], [1.5, 1.0]])).tolist() == [True, False]


def test_rejects_blocked_or_broken_paths():
    occ = np.zeros((5, 5), bool)
    occ[2, 2] = True
    grid = OccupancyGrid(occ, 1.0)
    with pytest.raises(InvalidInputError, match="blocked"):
        build_corridor(grid, np.array([[1, 2], [2, 2], [3, 2]]))
    with pytest.raises(InvalidInputError, match="8-neighbour"):
        build_corridor(grid, np.array([[0, 0], [2, 0]]))
    with pytest.raises(InvalidInputError, match="outside"):
        build_corridor(grid, np.array([[0, 0], [-1, 0]]))
    with pytest.raises(InvalidInputError, match="max_side_cells"):
        build_corridor(grid, np.array([[0, 0]]), max_side_cells=1)


def test_corner_cutting_path_is_rejected_with_the_step_named():
    # two blocked cells touching at a corner; the diagonal step (4,4)->(5,5) passes between
    # them, so no free box holds both cells
    occ = np.zeros((10, 10), bool)
    occ[4, 5] = occ[5, 4] = True
    grid = OccupancyGrid(occ, 1.0)
    cells = np.array([[k, k] for k in range(2, 8)])
    with pytest.raises(InvalidInputError, match=r"step 2 from \[4, 4\] to \[5, 5\] cuts a corner"):
        build_corridor(grid, cells)
    # the same path without the blocked corner is fine
    corridor = build_corridor(OccupancyGrid(np.zeros((10, 10), bool), 1.0), cells)
    assert corridor.contains(corridor.path_points).all()


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10_000), density=st.floats(0.05, 0.3))
def test_random_grids_brute_force(seed, density):
    rng = np.random.default_rng(seed)
    occ = rng.random((24, 28)) < density
    free = ~occ
    ys, xs = np.nonzero(free)
    if len(xs) < 2:
        return
    i, j = rng.choice(len(xs), 2, replace=False)
    try:
        cells = dijkstra_path(free, (int(xs[i]), int(ys[i])), (int(xs[j]), int(ys[j])))
    except ValueError:
        return
    corr = build_corridor(OccupancyGrid(occ, 0.25, (1.0, -2.0)), cells, max_side_cells=6)
    assert_corridor_valid(corr, free, cells, 0.25, (1.0, -2.0))


# ------------------------------------------------------------------- bridges
def test_rotated_rect_clearance_matches_sampling():
    from trajopt.corridor import rotated_rect_clearance

    rng = np.random.default_rng(3)
    hits = 0
    for _ in range(300):
        s0, d0 = rng.uniform(-5, 5, 2)
        sd = (s0, s0 + rng.uniform(0, 4), d0, d0 + rng.uniform(0, 4))
        squares = rng.integers(-6, 6, size=(int(rng.integers(1, 6)), 2)).astype(float)
        exact = rotated_rect_clearance(sd, squares)
        sampled, spacing = sampled_rect_clearance(sd, squares)
        assert exact <= sampled + 1e-12
        assert sampled <= exact + spacing + 1e-12
        hits += exact == 0.0
    assert 20 < hits < 280  # both outcomes exercised
    assert rotated_rect_clearance((0, 1, 0, 1), np.empty((0, 2))) == math.inf


def diagonal_gap_grid() -> np.ndarray:
    """Two blocks whose corners leave a gap that is only open along the diagonal once the
    obstacles are inflated by 2.5 cells."""
    n = 40
    yy, xx = np.mgrid[0:n, 0:n]
    return ((xx <= 16) & (yy >= 21)) | ((xx >= 22) & (yy <= 15))


def test_bridge_across_a_diagonal_gap_is_certified_and_lets_the_curve_flow():
    import astar
    from trajopt.errors import SmoothingError
    from trajopt.smoother import Smoother

    raw = OccupancyGrid(diagonal_gap_grid(), resolution=0.1, origin=(-1.0, 2.0))
    r = 0.25
    infl = astar.inflate(raw, r, metric="square", outside_occupied=True)
    path = astar.find_path(infl, (5, 5), (35, 35))
    plain = build_corridor(infl, path, radius=r)
    bridged = build_corridor(infl, path, radius=r, raw_grid=raw)
    assert not any(b.is_diagonal for b in plain.boxes)
    bridges = [b for b in bridged.boxes if b.is_diagonal]
    assert len(bridges) == 1
    # the bridge keeps the clearance: dense samples of it against every occupied square
    occ = np.pad(raw.occupied, 3, constant_values=True)  # the outside counts as occupied
    oy, ox = np.nonzero(occ)
    squares = np.column_stack([ox - 3, oy - 3]).astype(float)
    dg = bridges[0].diagonal
    ox0, oy0 = raw.origin
    sd_cells = (
        (dg[0] - ox0 - oy0) / 0.1,
        (dg[1] - ox0 - oy0) / 0.1,
        (dg[2] - ox0 + oy0) / 0.1,
        (dg[3] - ox0 + oy0) / 0.1,
    )
    sampled, _ = sampled_rect_clearance(sd_cells, squares)
    assert sampled >= r / 0.1 - 1e-9
    # its vertices satisfy its own containment test, and the chain still covers the path
    assert np.all(bridges[0].contains(bridges[0].vertices(), tol=1e-12))
    assert np.all(bridged.contains(bridged.path_points, tol=1e-9))
    # without the bridge the boxes meet at a point and the curve cannot keep its speed
    try:
        sp_plain = Smoother().fit(path, plain, raw_grid=raw)
        assert sp_plain.certificate.min_speed_ratio < 0.05
    except SmoothingError:
        pass
    sp = Smoother().fit(path, bridged, raw_grid=raw)
    assert sp.certificate.ok
    assert sp.certificate.min_speed_ratio > 0.3
    assert sp.certificate.min_clearance_m >= r - 1e-9


def test_raw_grid_must_match_and_needs_radius():
    import astar

    raw = OccupancyGrid(diagonal_gap_grid(), resolution=0.1)
    infl = astar.inflate(raw, 0.25, metric="square", outside_occupied=True)
    path = astar.find_path(infl, (5, 5), (35, 35))
    with pytest.raises(InvalidInputError, match="radius"):
        build_corridor(infl, path, raw_grid=raw)
    other = OccupancyGrid(diagonal_gap_grid(), resolution=0.2)
    with pytest.raises(InvalidInputError, match="raw_grid"):
        build_corridor(infl, path, radius=0.25, raw_grid=other)


def test_diagonal_box_containment():
    b = Box(0.0, 2.0, 0.0, 2.0, 0, 1, 0, 1, diagonal=(1.0, 3.0, -1.0, 1.0))
    pts = np.array([[1.0, 1.0], [0.1, 0.1], [1.9, 1.9], [0.5, 1.5], [0.0, 1.0]])
    # x + y in [1, 3] and x - y in [-1, 1]
    assert b.contains(pts).tolist() == [True, False, False, True, True]
    assert b.is_diagonal and not Box(0.0, 1.0, 0.0, 1.0, 0, 1, 0, 1).is_diagonal
    v = b.vertices()
    assert v.shape == (4, 2)
    np.testing.assert_allclose(
        sorted(map(tuple, v)), [(0.0, 1.0), (1.0, 0.0), (1.0, 2.0), (2.0, 1.0)]
    )
