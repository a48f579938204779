"""Tests of astar.grid.OccupancyGrid: validation, immutability, cell/world conversions."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from astar import InvalidInputError, OccupancyGrid


def _grid(ny: int = 3, nx: int = 4, res: float = 0.5, origin=(1.0, -2.0)) -> OccupancyGrid:
    occ = np.zeros((ny, nx), bool)
    occ[0, 0] = True  # bottom-left cell
    occ[ny - 1, nx - 1] = True  # top-right cell
    return OccupancyGrid(occ, res, origin)


# ---------------------------------------------------------------- construction
def test_sizes_and_properties() -> None:
    g = _grid()
    assert (g.ny, g.nx) == g.shape == (3, 4)
    assert g.width == 2.0 and g.height == 1.5
    assert g.resolution == 0.5 and g.origin == (1.0, -2.0)
    assert isinstance(g.resolution, float) and all(isinstance(v, float) for v in g.origin)
    assert g.free.tolist() == (~g.occupied).tolist()
    assert "nx=4" in repr(g) and "occupied_cells=2" in repr(g)


def test_accepts_int_and_float_zero_one() -> None:
    a = np.array([[0, 1], [1, 0]])
    for arr in (a, a.astype(np.uint8), a.astype(float), a.tolist()):
        g = OccupancyGrid(arr, 1)
        assert g.occupied.dtype == bool and g.occupied.tolist() == a.astype(bool).tolist()


def test_arrays_are_copied_and_read_only() -> None:
    src = np.zeros((2, 3), bool)
    g = OccupancyGrid(src, 1.0)
    src[0, 0] = True
    assert not g.occupied[0, 0]  # a copy, not a view
    with pytest.raises(ValueError):
        g.occupied[0, 0] = True
    with pytest.raises(ValueError):
        g.free[0, 0] = False
    with pytest.raises(dataclasses.FrozenInstanceError):
        g.resolution = 2.0  # type: ignore[misc]
    fast = OccupancyGrid._construct_fast(np.ones((2, 2), bool), 0.1, (0, 0))
    with pytest.raises(ValueError):
        fast.occupied[0, 0] = False
    assert fast == OccupancyGrid(np.ones((2, 2), bool), 0.1)


@pytest.mark.parametrize(
    ("occupied", "rule"),
    [
        (np.zeros(4, bool), "2-D"),
        (np.zeros((2, 2, 2), bool), "2-D"),
        (np.zeros((0, 3), bool), "empty"),
        (np.zeros((3, 0), bool), "empty"),
        (np.array([[0.0, np.nan]]), "NaN"),
        (np.array([[0.0, np.inf]]), "NaN or infinity"),
        (np.array([[0, 2]]), "only 0/1"),
        (np.array([[0.5, 1.0]]), "only 0/1"),
        (np.array([[-1, 0]]), "only 0/1"),
        (np.array([["a", "b"]]), "dtype"),
        (np.array([[None, 1]], dtype=object), "dtype"),
    ],
)
def test_rejects_bad_occupancy(occupied, rule: str) -> None:
    with pytest.raises(InvalidInputError, match=rule):
        OccupancyGrid(occupied, 1.0)


@pytest.mark.parametrize("res", [0.0, -0.1, math.nan, math.inf, "x", None])
def test_rejects_bad_resolution(res) -> None:
    with pytest.raises(InvalidInputError, match="resolution"):
        OccupancyGrid(np.zeros((2, 2), bool), res)


@pytest.mark.parametrize("origin", [(0.0,), (0.0, 1.0, 2.0), (0.0, math.nan), (math.inf, 0), 5])
def test_rejects_bad_origin(origin) -> None:
    with pytest.raises(InvalidInputError, match="origin"):
        OccupancyGrid(np.zeros((2, 2), bool), 1.0, origin)


def test_errors_are_value_errors() -> None:
    with pytest.raises(ValueError):
        OccupancyGrid(np.zeros((2, 2)), -1.0)


def test_with_occupied_and_equality() -> None:
    g = _grid()
    h = g.with_occupied(np.ones(g.shape, bool))
    assert h.resolution == g.resolution and h.origin == g.origin and h.occupied.all()
    with pytest.raises(InvalidInputError):
        g.with_occupied(np.full(g.shape, 3))
    assert g == _grid() and g != h
    assert g != _grid(res=0.25) and g != _grid(origin=(0.0, 0.0)) and g != _grid(ny=4)
    assert g != "grid"
    with pytest.raises(TypeError):
        hash(g)


# ---------------------------------------------------------------- conversions
def test_cell_to_world_centres_by_hand() -> None:
    g = _grid()  # origin (1, -2), 0.5 m cells
    assert g.cell_to_world((0, 0)).tolist() == [1.25, -1.75]
    assert g.cell_to_world([[3, 2], [1, 0]]).tolist() == [[2.75, -0.75], [1.75, -1.75]]
    assert g.cell_to_world(np.zeros((2, 5, 2), int)).shape == (2, 5, 2)


def test_world_to_cell_half_open_cells() -> None:
    g = _grid()
    # the lower-left corner belongs to the cell, the upper-right edge to the next one
    assert g.world_to_cell((1.0, -2.0)).tolist() == [0, 0]
    assert g.world_to_cell((1.5, -1.5)).tolist() == [1, 1]
    assert g.world_to_cell((1.4999, -1.5001)).tolist() == [0, 0]
    # outside the map: negative or too large indices, not clipped
    assert g.world_to_cell((0.9, -2.1)).tolist() == [-1, -1]
    assert g.world_to_cell((3.0, -0.5)).tolist() == [4, 3]
    assert g.world_to_cell(np.zeros((3, 2))).dtype == np.int64


def test_conversion_shape_and_value_errors() -> None:
    g = _grid()
    for fn in (g.world_to_cell, g.cell_to_world, g.in_bounds):
        with pytest.raises(InvalidInputError, match=r"\(\.\.\., 2\)"):
            fn((1.0, 2.0, 3.0))
    with pytest.raises(InvalidInputError, match="finite"):
        g.world_to_cell((math.nan, 0.0))


@settings(max_examples=100, deadline=None)
@given(
    ix=st.integers(-50, 50),
    iy=st.integers(-50, 50),
    res=st.floats(1e-3, 1e3),
    ox=st.floats(-1e4, 1e4),
    oy=st.floats(-1e4, 1e4),
    fx=st.floats(0.01, 0.99),
    fy=st.floats(0.01, 0.99),
)
def test_world_cell_round_trip(ix, iy, res, ox, oy, fx, fy) -> None:
    g = OccupancyGrid(np.zeros((2, 2), bool), res, (ox, oy))
    assert g.world_to_cell(g.cell_to_world((ix, iy))).tolist() == [ix, iy]
    # any point strictly inside the cell maps to it
    p = (ox + (ix + fx) * res, oy + (iy + fy) * res)
    assert g.world_to_cell(p).tolist() == [ix, iy]


def test_in_bounds_and_is_free() -> None:
    g = _grid()  # 4 x 3 cells, occupied (0, 0) and (3, 2)
    assert g.in_bounds((0, 0)) is True and g.in_bounds((3, 2)) is True
    assert g.in_bounds((4, 0)) is False and g.in_bounds((0, 3)) is False
    assert g.in_bounds((-1, 0)) is False
    cells = np.array([[0, 0], [1, 0], [3, 2], [4, 2], [-1, -1], [2, 1]])
    assert g.in_bounds(cells).tolist() == [True, True, True, False, False, True]
    assert g.is_free(cells).tolist() == [False, True, False, False, False, True]
    assert g.is_free((1, 0)) is True and g.is_free((0, 0)) is False
    assert g.is_free((100, -100)) is False
    assert g.is_free(cells.reshape(2, 3, 2)).shape == (2, 3)


def test_indexing_is_iy_ix_bottom_row_zero() -> None:
    occ = np.zeros((3, 5), bool)
    occ[2, 4] = True  # row iy = 2 (top), column ix = 4 (right)
    g = OccupancyGrid(occ, 1.0)
    assert g.is_free((2, 4)) is False  # (ix=2, iy=4) lies outside the 5 x 3 grid
    assert g.in_bounds((2, 4)) is False
    assert g.is_free((4, 2)) is False
    # world point in the top-right cell
    assert g.world_to_cell((4.5, 2.5)).tolist() == [4, 2]


@settings(max_examples=60, deadline=None)
@given(
    shape=st.tuples(st.integers(1, 6), st.integers(1, 6)),
    seed=st.integers(0, 2**32 - 1),
    cells=st.lists(st.tuples(st.integers(-3, 8), st.integers(-3, 8)), min_size=1, max_size=20),
)
def test_is_free_matches_brute_force(shape, seed, cells) -> None:
    occ = np.random.default_rng(seed).random(shape) < 0.5
    g = OccupancyGrid(occ, 1.0)
    ny, nx = shape
    expected = [0 <= ix < nx and 0 <= iy < ny and not occ[iy, ix] for ix, iy in cells]
    assert g.is_free(np.array(cells)).tolist() == expected
    assert [g.is_free(c) for c in cells] == expected


def test_split_keeps_the_occupied_area_and_every_world_point_s_state() -> None:
    """Every world point lies in an occupied cell of the split iff it did before."""
    rng = np.random.default_rng(3)
    g = OccupancyGrid(rng.random((7, 9)) < 0.3, 0.2, (-1.0, 0.5))
    for k in (1, 2, 3):
        s = g.split(k)
        assert s.shape == (7 * k, 9 * k) and s.origin == g.origin
        assert s.resolution == pytest.approx(0.2 / k)
        assert s.occupied.sum() == k * k * g.occupied.sum()
        pts = rng.uniform([-1.0, 0.5], [-1.0 + 1.8, 0.5 + 1.4], size=(500, 2))
        a, b = g.world_to_cell(pts), s.world_to_cell(pts)
        assert np.array_equal(g.occupied[a[:, 1], a[:, 0]], s.occupied[b[:, 1], b[:, 0]])
    assert g.split(1) is g
    for bad in (0, -2, 1.5, True):
        with pytest.raises(InvalidInputError, match="k must"):
            g.split(bad)


def test_coarsen_is_conservative_and_undoes_split() -> None:
    """Every occupied square lies in an occupied coarse square; coarsen(split(k)) is the map."""
    rng = np.random.default_rng(5)
    g = OccupancyGrid(rng.random((11, 13)) < 0.15, 0.05, (0.3, -0.2))
    assert np.array_equal(g.split(3).coarsen(3).occupied, g.occupied)
    for k in (1, 2, 4):
        c = g.coarsen(k)
        assert c.shape == (-(-11 // k), -(-13 // k)) and c.resolution == pytest.approx(0.05 * k)
        iy, ix = np.nonzero(g.occupied)
        centres = g.cell_to_world(np.column_stack([ix, iy]))
        cells = c.world_to_cell(centres)
        assert c.occupied[cells[:, 1], cells[:, 0]].all()
        # a coarse cell is free only if all its fine cells inside the map are free
        for cy, cx in zip(*np.nonzero(~c.occupied), strict=True):
            assert not g.occupied[cy * k : (cy + 1) * k, cx * k : (cx + 1) * k].any()
    assert g.coarsen(1) is g
    with pytest.raises(InvalidInputError, match="k must"):
        g.coarsen(0)
