"""Tests of astar's ALT landmarks: their distances, exact searches with them, and the refusals.

References: scipy's Dijkstra on the explicit step graph (``tests/reference.py``).
"""

from __future__ import annotations

import numpy as np
import pytest

import astar
import trajopt
from astar import InvalidInputError, OccupancyGrid, build_landmarks, clearance_cost, find_path
from tests.reference import check_path, dijkstra_costs


def rooms(seed: int, ny: int = 48, nx: int = 64) -> np.ndarray:
    """Walls with doors and scattered blocks, plus a sealed pocket (a second region)."""
    rng = np.random.default_rng(seed)
    occ = rng.random((ny, nx)) < 0.05
    for x in range(10, nx - 5, 14):
        occ[:, x] = True
        for _ in range(2):
            y = rng.integers(1, ny - 2)
            occ[y : y + 2, x] = False
    occ[2:8, 2:8] = True
    occ[3:7, 3:7] = False  # a pocket no landmark reaches
    return occ


@pytest.mark.parametrize("connectivity, corner_cutting", [(8, False), (8, True), (4, False)])
@pytest.mark.parametrize("seed", [0, 1])
def test_distances_and_searches_match_dijkstra(seed, connectivity, corner_cutting):
    occ = rooms(seed)
    grid = OccupancyGrid(occ, 0.05)
    cost = clearance_cost(grid, 0.05)
    lms = build_landmarks(grid, cost, 4, connectivity=connectivity, corner_cutting=corner_cutting)
    assert lms.k == 4 and not lms.distances.flags.writeable
    ny, nx = occ.shape
    for (ix, iy), row in zip(lms.cells, lms.distances, strict=True):
        ref = dijkstra_costs(occ, (ix, iy), connectivity, corner_cutting, cost)
        got = row.reshape(ny + 2, nx + 2)[1:-1, 1:-1]
        np.testing.assert_allclose(got, ref, rtol=1e-12)  # inf where unreachable, both
    rng = np.random.default_rng(seed + 10)
    free = np.argwhere(~occ)
    for _ in range(12):
        a, b = free[rng.integers(len(free), size=2)]
        s, g = (int(a[1]), int(a[0])), (int(b[1]), int(b[0]))
        ref = dijkstra_costs(occ, s, connectivity, corner_cutting, cost)[g[1], g[0]]
        kw = {"connectivity": connectivity, "corner_cutting": corner_cutting}
        if not np.isfinite(ref):
            with pytest.raises(astar.NoPathError):
                find_path(grid, s, g, landmarks=lms, **kw)
            continue
        p = find_path(grid, s, g, landmarks=lms, **kw)
        assert p.cost == pytest.approx(ref, rel=1e-12)
        check_path(p, occ, s, g, connectivity, corner_cutting, cost)


def test_landmarks_cut_the_expansions_of_long_searches():
    occ = rooms(3, 80, 120)
    grid = OccupancyGrid(occ, 0.05)
    cost = clearance_cost(grid, 0.05)
    lms = build_landmarks(grid, cost, 6)
    free = np.argwhere(~occ)
    left = free[free[:, 1] < 10]
    right = free[free[:, 1] > 105]
    start = (int(left[len(left) // 2][1]), int(left[len(left) // 2][0]))
    plain = alt = 0
    for c in right[:: max(1, len(right) // 8)][:8]:
        goal = (int(c[1]), int(c[0]))
        try:
            p = find_path(grid, start, goal, cost=cost)
        except astar.NoPathError:
            continue
        q = find_path(grid, start, goal, landmarks=lms)
        assert q.cost == pytest.approx(p.cost, rel=1e-12)
        plain += p.expanded
        alt += q.expanded
    assert plain > 0 and alt < 0.7 * plain


def test_refusals():
    occ = rooms(0)
    grid = OccupancyGrid(occ, 0.05)
    cost = clearance_cost(grid, 0.05)
    lms = build_landmarks(grid, cost, 2)
    other = OccupancyGrid(np.zeros_like(occ), 0.05)
    with pytest.raises(InvalidInputError, match="another grid"):
        find_path(other, (20, 20), (30, 30), landmarks=lms)
    with pytest.raises(InvalidInputError, match="landmarks.cost"):
        find_path(grid, (20, 20), (30, 30), cost=cost, landmarks=lms)
    with pytest.raises(InvalidInputError, match="connectivity=8"):
        find_path(grid, (20, 20), (30, 30), connectivity=4, landmarks=lms)
    with pytest.raises(InvalidInputError, match="astar.Landmarks"):
        find_path(grid, (20, 20), (30, 30), landmarks="six")
    with pytest.raises(InvalidInputError, match="k must be"):
        build_landmarks(grid, cost, 0)
    with pytest.raises(InvalidInputError, match="no free cell"):
        full = OccupancyGrid(np.ones((4, 4), bool), 1.0)
        build_landmarks(full, np.zeros((4, 4)), 2)
    with pytest.raises(InvalidInputError, match="landmarks must be"):
        trajopt.Planner(grid, trajopt.Robot(radius=0.05), landmarks=-1)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_rebased_landmarks_stay_exact_after_obstacles_are_added(seed):
    occ = rooms(seed)
    grid = OccupancyGrid(occ, 0.05)
    lms = build_landmarks(grid, clearance_cost(grid, 0.05), 4)
    rng = np.random.default_rng(seed + 20)
    occ2 = occ.copy()
    for _ in range(6):  # blocks that cut paths and raise the clearance cost around them
        y, x = rng.integers(0, 44), rng.integers(0, 60)
        occ2[y : y + 4, x : x + 4] = True
    grid2 = OccupancyGrid(occ2, 0.05)
    cost2 = clearance_cost(grid2, 0.05)
    moved = lms.rebase(grid2, cost2)
    assert moved.distances is lms.distances and moved.grid is grid2
    free = np.argwhere(~occ2)
    for _ in range(15):
        a, b = free[rng.integers(len(free), size=2)]
        s, g = (int(a[1]), int(a[0])), (int(b[1]), int(b[0]))
        ref = dijkstra_costs(occ2, s, 8, False, cost2)[g[1], g[0]]
        if not np.isfinite(ref):
            with pytest.raises(astar.NoPathError):
                find_path(grid2, s, g, landmarks=moved)
            continue
        p = find_path(grid2, s, g, landmarks=moved)
        assert p.cost == pytest.approx(ref, rel=1e-12)
        check_path(p, occ2, s, g, 8, False, cost2)


def test_rebase_refuses_freed_cells_and_lowered_costs():
    occ = rooms(0)
    grid = OccupancyGrid(occ, 0.05)
    cost = clearance_cost(grid, 0.05)
    lms = build_landmarks(grid, cost, 2)
    opened = occ.copy()
    opened[:, 10] = False
    with pytest.raises(InvalidInputError, match=r"\d+ cells freed, 0 costs lowered"):
        lms.rebase(OccupancyGrid(opened, 0.05), cost)
    cheaper = cost.copy()
    cheaper[cheaper > 0] *= 0.5
    with pytest.raises(InvalidInputError, match=r"0 cells freed, \d+ costs lowered"):
        lms.rebase(grid, cheaper)
    with pytest.raises(InvalidInputError, match="shape"):
        lms.rebase(OccupancyGrid(occ[:-1], 0.05), cost[:-1])
    # a window holding the freed column still sees it; NaN costs in it are refused
    with pytest.raises(InvalidInputError, match=r"\d+ cells freed"):
        lms.rebase(OccupancyGrid(opened, 0.05), cost, window=(8, 12, 0, 47))
    bad = cost.copy()
    bad[5, 9] = np.nan
    with pytest.raises(InvalidInputError, match="finite and >= 0"):
        lms.rebase(grid, bad, window=(8, 12, 0, 47))


def test_planner_with_landmarks_plans_the_same_through_map_updates():
    occ = np.zeros((60, 90), bool)
    occ[:, 40:42] = True
    occ[20:26, 40:42] = False
    occ[30:40, 60:70] = True
    grid = OccupancyGrid(occ, 0.05)
    robot = trajopt.Robot(radius=0.1)
    a, b = (0.5, 0.5), (4.0, 2.5)
    plain = trajopt.Planner(grid, robot).plan(a, b)
    planner = trajopt.Planner(grid, robot, landmarks=4)
    with_lm = planner.plan(a, b)
    assert planner.caches.built_landmarks is not None and planner.caches.built_landmarks.k == 4
    assert with_lm.steps.grid_path.cost == pytest.approx(plain.steps.grid_path.cost, rel=1e-12)
    built = planner.caches.built_landmarks.distances
    # obstacles added: the landmarks are carried over, the search stays exact
    occ2 = occ.copy()
    occ2[40:50, 10:20] = True
    occ2[18:22, 30:34] = True  # near the door: the path's clearance cost rises
    assert planner.update_map(OccupancyGrid(occ2, 0.05))["landmarks"] == "rebased"
    assert planner.caches.built_landmarks.distances is built
    again = planner.plan(a, b)
    fresh = trajopt.Planner(OccupancyGrid(occ2, 0.05), robot).plan(a, b)
    assert again.steps.grid_path.cost == pytest.approx(fresh.steps.grid_path.cost, rel=1e-12)
    # a cell freed: dropped, and built again by the next search
    assert planner.update_map(OccupancyGrid(occ, 0.05))["landmarks"] == "dropped"
    assert planner.caches.built_landmarks is None
    back = planner.plan(a, b)
    assert back.steps.grid_path.cost == pytest.approx(plain.steps.grid_path.cost, rel=1e-12)
    assert (
        planner.caches.built_landmarks is not None
        and planner.caches.built_landmarks.distances is not built
    )
