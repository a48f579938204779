"""Tests of trajopt.planning: Planner search_mode / search_bound: exact as before, coarse-to-fine within its bound,
the blocks kept through update_map, bad settings refused."""

from __future__ import annotations

import numpy as np
import pytest

import astar
import trajopt
from tests.cases import door_grid
from tests.reference import dijkstra_costs
from trajopt.errors import InvalidInputError
from trajopt.planning._options import PlannerOptions

ROBOT = trajopt.Robot(radius=0.12)
START, GOAL = (0.4, 0.3), (2.6, 1.6)


@pytest.fixture(scope="module")
def grid():
    return door_grid()


def _cells(planner, p):
    c = planner.grid.world_to_cell(np.asarray(p, float))
    return (int(c[0]), int(c[1]))


def test_exact_and_auto_on_a_small_map_are_find_path(grid):
    """``"exact"`` is astar.find_path on the inflated grid and cost; ``"auto"`` on a small
    map is the same search (the defaults plan as before)."""
    for mode in ("exact", "auto"):
        planner = trajopt.Planner(grid, ROBOT, search_mode=mode)
        traj = planner.plan(START, GOAL)
        ref = astar.find_path(
            planner.inflated_grid,
            _cells(planner, START),
            _cells(planner, GOAL),
            cost=planner.search_cost,
        )
        assert traj.steps.grid_path == ref
        info = traj.stats["search_info"]
        assert info["mode"] == "exact" and info["requested"] == mode and info["bound"] == 1.0
        assert planner.caches.built_coarse is None


def test_coarse_mode_is_within_its_bound(grid):
    planner = trajopt.Planner(grid, ROBOT, search_mode="coarse", search_bound=2.0)
    traj = planner.plan(START, GOAL)
    info = traj.stats["search_info"]
    s, g = _cells(planner, START), _cells(planner, GOAL)
    best = dijkstra_costs(planner.inflated_grid.occupied, s, 8, False, planner.search_cost)[
        g[1], g[0]
    ]
    k = planner.options.search_block_cells(grid.resolution)
    assert info["requested"] == "coarse" and info["block_cells"] == k
    assert info["block_m"] == pytest.approx(k * grid.resolution)
    assert 1.0 <= info["bound"] <= 2.0
    assert info["lower_bound"] <= best * (1 + 1e-12)
    assert traj.steps.grid_path.cost <= info["bound"] * best * (1 + 1e-12)
    assert info["cost"] == traj.steps.grid_path.cost
    assert info["mode"] == "coarse" or info["fallback"] is not None
    # search_bound=1 makes it exact
    strict = trajopt.Planner(grid, ROBOT, search_mode="coarse", search_bound=1.0)
    path = strict.plan(START, GOAL).steps.grid_path
    assert path.cost == pytest.approx(best, rel=1e-9)


def test_block_follows_the_robot_radius_not_the_cells():
    o = PlannerOptions(robot=trajopt.Robot(radius=0.3))
    assert o.search_block_cells(0.03) == 10 and o.search_block_cells(0.015) == 20
    assert o.search_block_cells(0.5) == 2  # at least two cells


def test_update_map_keeps_the_blocks_outside_the_change(grid):
    planner = trajopt.Planner(grid, ROBOT, search_mode="coarse")
    planner.plan(START, GOAL)
    before = planner.caches.built_coarse
    assert before is not None
    occ = np.array(grid.occupied)
    occ[35:38, 55:58] = True  # a box in the top right corner
    report = planner.update_map(grid.with_occupied(occ))
    after = planner.caches.built_coarse
    assert after is not None and after is not before  # updated, not dropped
    k = after.block
    fresh = astar.build_coarse_grid(planner.inflated_grid, k, planner.search_cost)
    for name in ("free_any", "open_east", "open_north", "cost_mean", "cost_min", "near_min"):
        np.testing.assert_array_equal(getattr(after, name), getattr(fresh, name), err_msg=name)
    x0, x1, y0, y1 = report["window"]
    # blocks left of the window (and of its west neighbour) are the old ones, untouched
    cols = slice(0, max(0, x0 // k - 1))
    np.testing.assert_array_equal(after.cost_mean[:, cols], before.cost_mean[:, cols])
    assert planner.plan(START, GOAL).stats["search_info"]["requested"] == "coarse"


@pytest.mark.parametrize(
    ("kw", "pattern"),
    [
        ({"search_mode": "fast"}, r"search_mode must be one of \('auto', 'exact', 'coarse'\)"),
        ({"search_mode": None}, r"search_mode must be one of"),
        ({"search_bound": 0.9}, r"search_bound must be a number >= 1"),
        ({"search_bound": float("nan")}, r"search_bound must be a number >= 1"),
        ({"search_bound": "2"}, r"search_bound must be a number >= 1"),
    ],
)
def test_bad_search_settings(grid, kw, pattern):
    with pytest.raises(InvalidInputError, match=pattern):
        trajopt.Planner(grid, ROBOT, **kw)
    with pytest.raises(InvalidInputError, match=pattern):
        PlannerOptions(**kw)
