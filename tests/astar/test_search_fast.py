"""Tests of the fast search paths of astar.find_path: jump point search (8-connected, no corner
cutting, no cost) against Dijkstra on structured grids, the unpadded cost array of the weighted
search and its radix heap on long searches, and cost validation of single bad cells.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from astar import InvalidInputError, NoPathError, OccupancyGrid, clearance_cost, find_path
from tests.reference import check_path, dijkstra_costs


@st.composite
def structured_grids(draw):
    """Grids with rectangles, walls with gaps and scattered cells (forced neighbours)."""
    ny = draw(st.integers(1, 22))
    nx = draw(st.integers(1, 22))
    rng = np.random.default_rng(draw(st.integers(0, 2**31)))
    occ = rng.random((ny, nx)) < draw(st.floats(0.0, 0.2))
    for _ in range(draw(st.integers(0, 6))):
        x0, y0 = rng.integers(0, nx), rng.integers(0, ny)
        occ[y0 : y0 + rng.integers(1, 7), x0 : x0 + rng.integers(1, 7)] = True
    for _ in range(draw(st.integers(0, 3))):
        if rng.random() < 0.5:
            occ[rng.integers(0, ny), :] = True
        else:
            occ[:, rng.integers(0, nx)] = True
    occ &= rng.random((ny, nx)) < 0.9  # gaps in the walls
    return occ, rng


@settings(max_examples=120, deadline=None)
@given(prob=structured_grids())
def test_jump_point_search_matches_dijkstra(prob):
    """Every free goal from one start: optimal length, legal steps, no path exactly when none."""
    occ, rng = prob
    free = np.argwhere(~occ)
    if len(free) == 0:
        return
    s = free[rng.integers(len(free))]
    start = (int(s[1]), int(s[0]))
    ref = dijkstra_costs(occ, start, 8, False)
    grid = OccupancyGrid(occ, 1.0)
    for t in free[rng.permutation(len(free))[:12]]:
        goal = (int(t[1]), int(t[0]))
        want = ref[goal[1], goal[0]]
        if math.isinf(want):
            with pytest.raises(NoPathError, match="jump points expanded"):
                find_path(grid, start, goal)
            continue
        path = find_path(grid, start, goal)
        assert path.length == pytest.approx(want, rel=1e-9, abs=1e-12)
        assert path.cost == path.length
        check_path(path, occ, start, goal, 8, False)
        assert find_path(grid, start, goal) == path


def test_jump_point_search_open_grid_and_corridor():
    grid = OccupancyGrid(np.zeros((40, 60), bool), 1.0)
    p = find_path(grid, (1, 2), (58, 37))
    assert p.length == pytest.approx(22 + 35 * math.sqrt(2.0), rel=1e-14)
    assert len(p) == 58  # every cell of the unrolled path, not only the jump points
    assert p.expanded < 10  # jump points, far fewer than the cells
    occ = np.ones((3, 30), bool)
    occ[1, :] = False
    p = find_path(OccupancyGrid(occ, 1.0), (0, 1), (29, 1))
    assert p.cells[:, 0].tolist() == list(range(30)) and p.length == 29.0


@pytest.mark.parametrize("layout", ["F", "slice"])
def test_weighted_search_non_contiguous_cost(layout):
    rng = np.random.default_rng(3)
    occ = rng.random((15, 17)) < 0.2
    occ[0, 0] = occ[14, 16] = False
    cost = rng.random((15, 17)) * 2.0
    ref = dijkstra_costs(occ, (0, 0), 8, False, cost)[14, 16]
    given_cost = np.asfortranarray(cost) if layout == "F" else np.repeat(cost, 2, axis=1)[:, ::2]
    assert not given_cost.flags.c_contiguous
    grid = OccupancyGrid(occ, 1.0)
    if math.isinf(ref):
        pytest.skip("unreachable draw")
    p = find_path(grid, (0, 0), (16, 14), cost=given_cost)
    assert p.cost == pytest.approx(ref, rel=1e-12)
    check_path(p, occ, (0, 0), (16, 14), 8, False, cost)


@pytest.mark.parametrize(
    "bad, pattern", [(np.nan, "finite"), (np.inf, "finite"), (-np.inf, "finite"), (-0.5, ">= 0")]
)
def test_one_bad_cost_cell_rejected(bad, pattern):
    grid = OccupancyGrid(np.zeros((4, 5), bool), 1.0)
    cost = np.zeros((4, 5))
    cost[2, 3] = bad
    with pytest.raises(InvalidInputError, match=pattern):
        find_path(grid, (0, 0), (4, 3), cost=cost)


@pytest.mark.parametrize("x", [0, 1, 2, 3, 255, 256, 2**32 - 1, 2**32, 2**52 + 7, 2**63, 2**64 - 1])
def test_radix_bit_length(x):
    from astar.weighted_kernel import bit_length

    assert bit_length(np.uint64(x)) == int(x).bit_length()


@pytest.mark.parametrize("connectivity, corner_cutting", [(8, False), (8, True), (4, False)])
def test_radix_heap_search_on_a_large_clearance_cost(connectivity, corner_cutting):
    """Long searches (many bucket redistributions) stay optimal against scipy's Dijkstra."""
    rng = np.random.default_rng(11)
    occ = rng.random((70, 90)) < 0.12
    occ[0, 0] = occ[69, 89] = False
    grid = OccupancyGrid(occ, 0.05)
    cost = clearance_cost(grid, 0.05)
    ref = dijkstra_costs(occ, (0, 0), connectivity, corner_cutting, cost)
    reach = np.argwhere(np.isfinite(ref))
    goals = [tuple(c[::-1]) for c in reach[np.argsort(-ref[np.isfinite(ref)])[:3]]]
    for goal in goals:
        p = find_path(
            grid, (0, 0), goal, cost=cost, connectivity=connectivity, corner_cutting=corner_cutting
        )
        assert p.cost == pytest.approx(ref[goal[1], goal[0]], rel=1e-12)
        check_path(p, occ, (0, 0), goal, connectivity, corner_cutting, cost)
