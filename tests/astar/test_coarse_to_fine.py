"""Tests of astar.find_path_coarse_to_fine: a proven bound against scipy's Dijkstra, its fallbacks,
the blocks' update and its refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import astar
from astar import (
    InvalidInputError,
    NoPathError,
    OccupancyGrid,
    build_coarse_grid,
    find_path,
    find_path_coarse_to_fine,
)
from astar.coarse_to_fine import lower_bound
from tests.reference import check_path, dijkstra_costs

BLOCK_ARRAYS = ("free_any", "open_east", "open_north", "cost_mean", "cost_min", "near_min")


@st.composite
def problems(draw):
    ny = draw(st.integers(2, 40))
    nx = draw(st.integers(2, 40))
    density = draw(st.floats(0.0, 0.4))
    rng = np.random.default_rng(draw(st.integers(0, 2**31)))
    occ = rng.random((ny, nx)) < density
    if draw(st.booleans()):  # walls with gaps: detours longer than the octile distance
        for x in range(3, nx - 1, 7):
            occ[:, x] = True
            occ[rng.integers(ny), x] = False
    free = np.argwhere(~occ)
    assume(len(free) >= 2)
    s = free[draw(st.integers(0, len(free) - 1))]
    t = free[draw(st.integers(0, len(free) - 1))]
    weighted = draw(st.booleans())
    cost = rng.random(occ.shape) * 3.0 * (rng.random(occ.shape) < 0.7) if weighted else None
    block = draw(st.integers(1, 6))
    return occ, (int(s[1]), int(s[0])), (int(t[1]), int(t[0])), cost, block


@settings(max_examples=150, deadline=None)
@given(prob=problems(), band=st.integers(0, 2))
def test_bound_holds_against_dijkstra(prob, band):
    """LB <= optimum <= cost <= bound * optimum, the path is legal; bound 1 is exact."""
    occ, start, goal, cost, block = prob
    grid = OccupancyGrid(occ, 0.1)
    coarse = build_coarse_grid(grid, block, cost)
    best = dijkstra_costs(occ, start, 8, False, cost)[goal[1], goal[0]]
    if math.isinf(best):
        with pytest.raises(NoPathError):
            find_path_coarse_to_fine(coarse, start, goal, band_blocks=band)
        return
    lb = lower_bound(coarse, start, goal)
    assert lb <= best * (1 + 1e-12) + 1e-12
    found = find_path_coarse_to_fine(coarse, start, goal, band_blocks=band)
    check_path(found.path, occ, start, goal, 8, False, cost)
    assert found.path.cost >= best * (1 - 1e-12) - 1e-12
    assert found.path.cost <= found.bound * best * (1 + 1e-9) + 1e-9
    assert found.bound >= 1.0 and found.lower_bound <= best * (1 + 1e-12) + 1e-12
    if found.mode == "coarse":
        assert found.fallback is None and found.bound == found.band_bound
    exact = find_path_coarse_to_fine(coarse, start, goal, max_bound=1.0, band_blocks=band)
    assert exact.path.cost == pytest.approx(best, rel=1e-9, abs=1e-12)


def test_lower_bound_on_an_open_grid_is_the_octile_distance():
    grid = OccupancyGrid(np.zeros((30, 50), bool), 0.1)
    coarse = build_coarse_grid(grid, 4)
    found = find_path_coarse_to_fine(coarse, (1, 2), (45, 27))
    octile = 44 - 25 + 25 * math.sqrt(2.0)
    assert found.path.cost == pytest.approx(octile)
    assert found.lower_bound == pytest.approx(octile) and found.bound == pytest.approx(1.0)


def _split_block_grid() -> tuple[OccupancyGrid, tuple[int, int], tuple[int, int]]:
    """Blocks of 3: the bottom middle block is cut in two by a wall along its middle column,
    whose sides are both open, so the blocks' A* goes straight through it."""
    occ = np.zeros((6, 9), bool)
    occ[0:3, 4] = True
    return OccupancyGrid(occ, 0.1), (0, 1), (8, 1)


def test_band_without_a_path_falls_back_to_the_exact_search():
    grid, start, goal = _split_block_grid()
    coarse = build_coarse_grid(grid, 3)
    found = find_path_coarse_to_fine(coarse, start, goal, band_blocks=0)
    assert found.mode == "exact" and found.fallback == "band"
    assert found.path == find_path(grid, start, goal)
    assert found.bound == 1.0 and found.lower_bound == found.path.cost
    # a band of one more block holds the detour
    wide = find_path_coarse_to_fine(coarse, start, goal, band_blocks=1)
    assert wide.mode == "coarse" and wide.path.cost == pytest.approx(found.path.cost)


def test_bound_over_the_maximum_runs_the_exact_search():
    rng = np.random.default_rng(3)
    occ = rng.random((40, 40)) < 0.12
    occ[20, 20] = occ[1, 1] = occ[38, 38] = False
    cost = rng.random(occ.shape) * 2.0
    grid = OccupancyGrid(occ, 0.1)
    coarse = build_coarse_grid(grid, 4, cost)
    start, goal = (1, 1), (38, 38)
    loose = find_path_coarse_to_fine(coarse, start, goal)
    assert loose.mode == "coarse" and loose.bound > 1.0
    strict = find_path_coarse_to_fine(coarse, start, goal, max_bound=loose.bound * 0.999)
    assert strict.mode == "exact" and strict.fallback == "bound"
    assert strict.band_bound == pytest.approx(loose.bound)
    assert strict.path == find_path(grid, start, goal, cost=cost)


def test_narrow_passage_is_found():
    """A door one cell wide, narrower than a block: the blocks' side connections carry it."""
    occ = np.zeros((40, 40), bool)
    occ[:, 20] = True
    occ[13, 20] = False
    grid = OccupancyGrid(occ, 0.1)
    coarse = build_coarse_grid(grid, 8)
    found = find_path_coarse_to_fine(coarse, (2, 30), (37, 3))
    best = dijkstra_costs(occ, (2, 30), 8, False)[3, 37]
    assert found.mode == "coarse" and found.path.cost <= found.bound * best + 1e-9


def _same_blocks(a, b, rows=slice(None), cols=slice(None)) -> bool:
    return all(
        np.array_equal(getattr(a, n)[rows, cols], getattr(b, n)[rows, cols]) for n in BLOCK_ARRAYS
    )


def test_update_recomputes_only_the_window():
    rng = np.random.default_rng(5)
    occ = rng.random((60, 80)) < 0.2
    cost = rng.random(occ.shape)
    old = build_coarse_grid(OccupancyGrid(occ, 0.1), 4, cost)
    new_occ, new_cost = occ.copy(), cost.copy()
    new_occ[5:9, 6:10] = ~new_occ[5:9, 6:10]  # near the origin: blocks (1-2, 1-2)
    new_cost[5:9, 6:10] += 1.0
    new_occ[50:54, 70:74] = True  # far away: blocks (12-13, 17-18)
    new_cost[50:54, 70:74] += 1.0
    new_grid = OccupancyGrid(new_occ, 0.1)
    fresh = build_coarse_grid(new_grid, 4, new_cost)
    # told about the first change only: its blocks are new, the far ones untouched (stale)
    part = old.update(new_grid, new_cost, (6, 9, 5, 8))
    assert _same_blocks(part, fresh, slice(0, 6), slice(0, 6))
    assert _same_blocks(part, old, slice(10, None), slice(15, None))
    assert not _same_blocks(part, fresh, slice(10, None), slice(15, None))
    # told about both: equal to a fresh build everywhere
    full = part.update(new_grid, new_cost, (70, 73, 50, 53))
    assert _same_blocks(full, fresh)
    assert full.grid is new_grid and full.block == 4
    assert old.update(new_grid, new_cost, (0, 79, 0, 59)).cost_mean.tolist() == (
        fresh.cost_mean.tolist()
    )


def test_values_are_read_only_and_cost_is_not_copied():
    cost = np.ones((10, 12))
    cost.flags.writeable = False
    coarse = build_coarse_grid(OccupancyGrid(np.zeros((10, 12), bool), 0.1), 5, cost)
    assert coarse.cost is cost and coarse.shape == (2, 3)
    for name in BLOCK_ARRAYS:
        with pytest.raises(ValueError):
            getattr(coarse, name)[0, 0] = 0
    writable = np.ones((10, 12))
    assert build_coarse_grid(coarse.grid, 5, writable).cost is not writable


@pytest.fixture(scope="module")
def small():
    grid = OccupancyGrid(np.zeros((10, 12), bool), 0.1)
    return grid, build_coarse_grid(grid, 3)


@pytest.mark.parametrize(
    ("kw", "pattern"),
    [
        ({"max_bound": 0.99}, r"max_bound must be >= 1"),
        ({"max_bound": math.nan}, r"max_bound must be >= 1"),
        ({"max_bound": "1.5"}, r"max_bound must be a number"),
        ({"max_bound": True}, r"max_bound must be a number"),
        ({"band_blocks": -1}, r"band_blocks must be an integer >= 0"),
        ({"band_blocks": 1.5}, r"band_blocks must be an integer >= 0"),
    ],
)
def test_bad_search_options(small, kw, pattern):
    _, coarse = small
    with pytest.raises(InvalidInputError, match=pattern):
        find_path_coarse_to_fine(coarse, (0, 0), (5, 5), **kw)


def test_bad_inputs(small):
    grid, coarse = small
    with pytest.raises(InvalidInputError, match="coarse must be an astar.CoarseGrid"):
        find_path_coarse_to_fine(grid, (0, 0), (5, 5))
    with pytest.raises(InvalidInputError, match=r"goal cell \(50, 5\) is outside"):
        find_path_coarse_to_fine(coarse, (0, 0), (50, 5))
    for block in (0, -2, 2.0, True):
        with pytest.raises(InvalidInputError, match="block must be an integer >= 1"):
            build_coarse_grid(grid, block)
    with pytest.raises(InvalidInputError, match="cost must have the grid's shape"):
        build_coarse_grid(grid, 2, np.ones((3, 3)))
    with pytest.raises(InvalidInputError, match="cost must be >= 0"):
        build_coarse_grid(grid, 2, -np.ones(grid.shape))
    with pytest.raises(InvalidInputError, match="keep the coarse view's shape"):
        coarse.update(OccupancyGrid(np.zeros((4, 4), bool), 0.1), None, (0, 1, 0, 1))
    with pytest.raises(InvalidInputError, match="cost must be given exactly when"):
        coarse.update(grid, np.ones(grid.shape), (0, 1, 0, 1))
    with pytest.raises(InvalidInputError, match=r"window \(x0, x1, y0, y1\) = \(0, 12, 0, 1\)"):
        coarse.update(grid, None, (0, 12, 0, 1))
    with pytest.raises(InvalidInputError, match="window must be"):
        coarse.update(grid, None, "abcd")


def test_exported():
    assert astar.find_path_coarse_to_fine is find_path_coarse_to_fine
    assert {"CoarseGrid", "CoarsePath", "build_coarse_grid"} <= set(astar.__all__)
