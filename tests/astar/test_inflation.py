"""Tests of astar.inflation: exact disks, clearance fields, the chapter's square dilation.

References are brute force over all pairs of cells (written from the definitions, independent of
the row decomposition and of the refined-lattice transform used by the code) and
``scipy.ndimage.distance_transform_edt`` on a larger grid.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import ndimage

from astar import InvalidInputError, OccupancyGrid
from astar.inflation import avoidance_area, clearance, clearance_cost, inflate
from tests.reference import INFLATION_TOL, brute_distance, brute_inflate, chapter_avoidance

TOL = INFLATION_TOL  # documented: distances within this relative tolerance of the radius equal it

grids = st.tuples(
    st.integers(1, 12), st.integers(1, 12), st.floats(0.0, 0.4), st.integers(0, 2**31)
).map(lambda t: np.random.default_rng(t[3]).random((t[0], t[1])) < t[2])

# radii in cells: arbitrary floats and exact boundary values sqrt(k) and sqrt(k)/2 + 1/2
radii = st.one_of(
    st.floats(0.0, 6.0),
    st.integers(0, 40).map(math.sqrt),
    st.integers(0, 40).map(lambda k: math.sqrt(k) / 2.0),
)


# ----------------------------------------------------------------------------- inflate
@settings(max_examples=80, deadline=None)
@given(
    occ=grids,
    r=radii,
    res=st.sampled_from([1.0, 0.05, 0.03, 0.1]),
    metric=st.sampled_from(["centre", "square"]),
    outside=st.booleans(),
)
def test_inflate_matches_brute_force(occ, r, res, metric, outside):
    g = OccupancyGrid(occ, resolution=res, origin=(1.0, -2.0))
    out = inflate(g, r * res, metric=metric, outside_occupied=outside)
    ref = brute_inflate(occ, (r * res) / res, metric, outside)
    np.testing.assert_array_equal(out.occupied, ref)
    assert out.resolution == res and out.origin == (1.0, -2.0)
    assert np.all(out.occupied[occ])


def test_inflate_exact_boundary_decimal_resolution():
    # 0.3 / 0.03 == 10.000000000000002 in floating point: cells exactly 10 cells away (0, 10),
    # (6, 8), (8, 6) are blocked, (7, 8) at sqrt(113) is not.
    occ = np.zeros((41, 41), bool)
    occ[20, 20] = True
    out = inflate(OccupancyGrid(occ, 0.03), 0.3).occupied
    for dx, dy in [(0, 10), (10, 0), (6, 8), (8, 6), (-6, -8)]:
        assert out[20 + dy, 20 + dx]
    for dx, dy in [(0, 11), (7, 8), (8, 7), (9, 5)]:
        assert not out[20 + dy, 20 + dx]
    assert out.sum() == sum(
        1 for dx in range(-10, 11) for dy in range(-10, 11) if dx * dx + dy * dy <= 100
    )


def test_inflate_square_metric_is_strict_and_half_cell_larger():
    occ = np.zeros((21, 21), bool)
    occ[10, 10] = True
    g = OccupancyGrid(occ, 1.0)
    # at r = 2 cells the square metric reaches (2, 0) (distance 1.5) but not (3, 0) (2.5) and
    # not (2, 2) (distance hypot(1.5, 1.5) = 2.12); the diagonal (1, 2) has hypot(.5, 1.5) < 2
    sq = inflate(g, 2.0, metric="square").occupied
    assert sq[10, 12] and not sq[10, 13] and sq[12, 11] and not sq[12, 12]
    # exactly on the boundary: (3, 0) is at distance 2.5, not blocked at r = 2.5 (strict)
    assert not inflate(g, 2.5, metric="square").occupied[10, 13]
    assert inflate(g, 2.5 + 1e-6, metric="square").occupied[10, 13]


def test_inflate_large_grid_matches_edt_threshold():
    rng = np.random.default_rng(7)
    occ = rng.random((300, 260)) < 0.002
    g = OccupancyGrid(occ, 0.05)
    for r_cells in (0.0, 1.0, 4.5, 7.3, 12.0):
        d = ndimage.distance_transform_edt(~occ)
        ref = d**2 <= r_cells**2 * (1 + TOL)
        np.testing.assert_array_equal(inflate(g, r_cells * 0.05).occupied, ref)


def test_inflate_zero_radius_and_empty_grid():
    occ = np.zeros((5, 6), bool)
    occ[2, 3] = True
    g = OccupancyGrid(occ, 0.1)
    np.testing.assert_array_equal(inflate(g, 0.0).occupied, occ)
    np.testing.assert_array_equal(inflate(g, 0.0, metric="square").occupied, occ)
    empty = OccupancyGrid(np.zeros((4, 4), bool), 0.1)
    assert not inflate(empty, 1.0).occupied.any()
    # everything outside occupied: the border ring is blocked even without obstacles
    ring = inflate(empty, 0.1, outside_occupied=True).occupied
    assert ring[0].all() and ring[-1].all() and ring[:, 0].all() and not ring[1:-1, 1:-1].any()


def test_inflate_result_is_read_only_grid():
    g = OccupancyGrid(np.eye(4, dtype=bool), 1.0)
    out = inflate(g, 1.0)
    assert isinstance(out, OccupancyGrid)
    with pytest.raises(ValueError):
        out.occupied[0, 1] = True


@pytest.mark.parametrize("radius", [-0.1, math.nan, math.inf, "a", None, True])
def test_inflate_rejects_bad_radius(radius):
    g = OccupancyGrid(np.zeros((3, 3), bool), 1.0)
    with pytest.raises(InvalidInputError, match="radius"):
        inflate(g, radius)


@pytest.mark.parametrize("metric", ["center", "disk", "", None, 1])
def test_inflate_rejects_unknown_metric(metric):
    g = OccupancyGrid(np.zeros((3, 3), bool), 1.0)
    with pytest.raises(InvalidInputError, match="metric"):
        inflate(g, 1.0, metric=metric)
    with pytest.raises(InvalidInputError, match="metric"):
        clearance(g, metric=metric)


def test_inflate_rejects_non_grid():
    with pytest.raises(InvalidInputError, match="OccupancyGrid"):
        inflate(np.zeros((3, 3), bool), 1.0)


# ----------------------------------------------------------------------------- clearance
@settings(max_examples=60, deadline=None)
@given(
    occ=grids,
    res=st.sampled_from([1.0, 0.05]),
    metric=st.sampled_from(["centre", "square"]),
    outside=st.booleans(),
)
def test_clearance_matches_brute_force(occ, res, metric, outside):
    g = OccupancyGrid(occ, res)
    d = clearance(g, metric=metric, outside_occupied=outside)
    ref = brute_distance(occ, metric, outside) * res
    assert d.shape == occ.shape and d.dtype == np.float64
    np.testing.assert_allclose(d, ref, rtol=1e-12, atol=0)
    assert np.all(d[occ] == 0)


def test_clearance_without_obstacles_is_inf():
    g = OccupancyGrid(np.zeros((3, 5), bool), 0.5)
    assert np.all(np.isinf(clearance(g)))
    assert np.all(np.isinf(clearance(g, metric="square")))


@settings(max_examples=40, deadline=None)
@given(occ=grids, r=st.floats(0.0, 5.0), metric=st.sampled_from(["centre", "square"]))
def test_inflate_agrees_with_clearance_threshold(occ, r, metric):
    # documented relation: centre blocks clearance <= r, square blocks clearance < r
    g = OccupancyGrid(occ, 1.0)
    d = clearance(g, metric=metric)
    blocked = inflate(g, r, metric=metric).occupied
    inside = d**2 <= r**2 * (1 + TOL) if metric == "centre" else d**2 < r**2 * (1 - TOL)
    np.testing.assert_array_equal(blocked, inside | occ)


# ----------------------------------------------------------------------------- avoidance area
@settings(max_examples=40, deadline=None)
@given(occ=grids, w=st.integers(0, 4), border=st.booleans())
def test_avoidance_area_matches_chapter_loop(occ, w, border):
    g = OccupancyGrid(occ, 0.1)
    out = avoidance_area(g, w, border=border)
    np.testing.assert_array_equal(out.occupied, chapter_avoidance(occ, w, border))


def test_avoidance_area_is_a_square_not_a_disk():
    occ = np.zeros((11, 11), bool)
    occ[5, 5] = True
    g = OccupancyGrid(occ, 1.0)
    sq = avoidance_area(g, 3, border=False).occupied
    assert sq.sum() == 49 and sq[2, 2] and sq[8, 8]
    disk = inflate(g, 3.0).occupied
    assert not disk[2, 2] and disk.sum() < 49


@pytest.mark.parametrize("w", [-1, 1.5, "2", True, None])
def test_avoidance_area_rejects_bad_w(w):
    g = OccupancyGrid(np.zeros((3, 3), bool), 1.0)
    with pytest.raises(InvalidInputError, match="w_cells"):
        avoidance_area(g, w)


# ----------------------------------------------------------------------------- clearance cost
@settings(max_examples=30, deadline=None)
@given(
    occ=grids,
    r=st.floats(0.0, 3.0),
    falloff=st.floats(0.5, 5.0),
    weight=st.floats(0.0, 4.0),
    res=st.sampled_from([1.0, 0.05]),
)
def test_clearance_cost_formula(occ, r, falloff, weight, res):
    g = OccupancyGrid(occ, res)
    c = clearance_cost(g, r * res, falloff_cells=falloff, weight=weight)
    d = brute_distance(occ, "square", False)  # cells, to obstacle squares
    with np.errstate(invalid="ignore"):
        ref = np.where(np.isinf(d), 0.0, weight * np.maximum(0.0, 1.0 - (d - r) / falloff))
    np.testing.assert_allclose(c, ref, rtol=1e-9, atol=1e-12)
    assert np.all(np.isfinite(c)) and np.all(c >= 0)


def test_clearance_cost_shape_of_profile():
    occ = np.zeros((1, 20), bool)
    occ[0, 0] = True
    c = clearance_cost(OccupancyGrid(occ, 0.1), 0.2, falloff_cells=3.0, weight=2.0)[0]
    # distance to the obstacle square of cell ix is ix - 0.5 cells; r = 2 cells
    expected = [2.0 * max(0.0, 1.0 - ((ix - 0.5 if ix else 0.0) - 2.0) / 3.0) for ix in range(20)]
    np.testing.assert_allclose(c, expected, rtol=1e-12)
    assert c[6] == 0.0 and c[5] > 0.0  # zero from r + falloff = 5 cells out


@pytest.mark.parametrize(
    "kw, field",
    [
        ({"falloff_cells": 0.0}, "falloff_cells"),
        ({"weight": -1.0}, "weight"),
        ({"falloff_cells": math.nan}, "falloff_cells"),
    ],
)
def test_clearance_cost_rejects_bad_parameters(kw, field):
    g = OccupancyGrid(np.zeros((3, 3), bool), 1.0)
    with pytest.raises(InvalidInputError, match=field):
        clearance_cost(g, 1.0, **kw)
    with pytest.raises(InvalidInputError, match="radius"):
        clearance_cost(g, -1.0)
