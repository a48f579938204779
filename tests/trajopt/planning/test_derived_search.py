"""Tests of trajopt.planning: the searches on a re-route's marked map (:meth:`PlannerCaches.derived`).

Marks only block cells, so the planner's ALT landmarks, computed on its own map, stay exact
lower bounds on the marked one: the derived caches carry them over rebased (the same distance
table, not built again), and the coarse-to-fine blocks are recomputed only where the marks
reach. Checked against independent references: the cheapest cost by scipy's Dijkstra on the
explicit step graph of the marked map's inflated grid and clearance cost
(``tests.reference.dijkstra_costs``), and blocks built afresh on the marked map.
"""

from __future__ import annotations

import numpy as np
import pytest

import astar
import trajopt
from tests.reference import dijkstra_costs
from trajopt.planning._caches import PlannerCaches


def test_marked_map_search_keeps_the_landmarks_and_is_optimal():
    """A planner with landmarks plans, then cells are marked: the derived caches hold the
    rebased landmarks and their search's cost is Dijkstra's on the marked map."""
    rng = np.random.default_rng(11)
    occ = rng.random((40, 56)) < 0.01
    occ[:, 27:29] = True
    occ[15:22, 27:29] = False  # a door in a wall
    grid = astar.OccupancyGrid(occ, 0.05)
    robot = trajopt.Robot(radius=0.08)
    planner = trajopt.Planner(grid, robot, landmarks=4)
    a, b = (0.3, 0.3), (2.5, 1.7)
    static = planner.plan(a, b).steps.grid_path
    cells = static.cells
    caches = planner.caches
    lms = caches.built_landmarks
    assert lms is not None
    marked = occ.copy()
    mx, my = cells[len(cells) // 3]
    marked[my - 1 : my + 2, mx - 1 : mx + 2] = True  # a mover's final place on the path
    new = astar.OccupancyGrid(marked, 0.05)
    derived = caches.derived(new)
    assert derived.built_landmarks is not None
    assert derived.built_landmarks.distances is lms.distances  # rebased, not built again
    s, g = (tuple(int(v) for v in new.world_to_cell(p)) for p in (a, b))
    path = astar.find_path(derived.inflated, s, g, landmarks=derived.landmarks)
    want = dijkstra_costs(derived.inflated.occupied, s, 8, False, derived.search_cost)[g[1], g[0]]
    assert path.cost == pytest.approx(float(want), rel=1e-12)
    assert path.cost > static.cost  # the marks lie on the static path: a detour
    fresh = PlannerCaches(new, None, caches.options)  # and the same map as a fresh build's
    np.testing.assert_array_equal(derived.inflated.occupied, fresh.inflated.occupied)
    np.testing.assert_allclose(derived.search_cost, fresh.search_cost, atol=1e-12)


def test_marked_map_keeps_the_coarse_blocks_updated():
    """The coarse-to-fine blocks built by a coarse search are carried to the marked map,
    recomputed where the marks reach: equal to blocks built afresh on it."""
    rng = np.random.default_rng(12)
    occ = rng.random((48, 64)) < 0.03
    grid = astar.OccupancyGrid(occ, 0.05)
    planner = trajopt.Planner(grid, trajopt.Robot(radius=0.08), search_mode="coarse")
    planner.plan((0.3, 0.3), (2.9, 2.1))
    caches = planner.caches
    assert caches.built_coarse is not None
    marked = occ.copy()
    marked[20:26, 30:36] = True
    derived = caches.derived(astar.OccupancyGrid(marked, 0.05))
    got = derived.built_coarse
    assert got is not None and got is not caches.built_coarse
    want = astar.build_coarse_grid(derived.inflated, got.block, derived.search_cost)
    for name in ("free_any", "open_east", "open_north", "cost_mean", "cost_min", "near_min"):
        np.testing.assert_allclose(getattr(got, name), getattr(want, name), atol=1e-12)
