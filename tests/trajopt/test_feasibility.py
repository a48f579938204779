"""The curvature-feasibility witness: checked by brute force, and against hand-made maps
where the answer is known (a wide room: feasible; a narrow L-bend: no curve can turn)."""

from __future__ import annotations

import numpy as np
import pytest

import astar
from tests.trajopt.test_pipeline import brute_clearance
from trajopt import Smoother, build_corridor
from trajopt.errors import InvalidInputError, SmoothingError
from trajopt.feasibility import curvature_witness


def _three_point_curvature(p: np.ndarray) -> np.ndarray:
    """Curvature of the circle through consecutive point triples (hand formula)."""
    a, b, c = p[:-2], p[1:-1], p[2:]
    ab = np.hypot(*(b - a).T)
    bc = np.hypot(*(c - b).T)
    ca = np.hypot(*(a - c).T)
    cross = (b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0]
    return 2.0 * np.abs(cross) / (ab * bc * ca)


def test_open_room_witness_holds_every_promise():
    occ = np.zeros((40, 50), dtype=bool)
    occ[15:25, 20:24] = True  # a pillar between start and goal
    grid = astar.OccupancyGrid(occ, 0.1)
    radius, kmax = 0.25, 1.0 / 0.5
    start, goal = np.array([0.6, 2.0]), np.array([4.4, 2.05])
    w = curvature_witness(grid, radius, start, goal, kmax)
    assert w is not None
    np.testing.assert_array_equal(w[0], start)
    np.testing.assert_array_equal(w[-1], goal)
    step = np.hypot(*np.diff(w, axis=0).T)
    assert step.max() <= 0.1 / 8 + 1e-12
    assert brute_clearance(grid, w).min() >= radius - 1e-9
    keep = np.concatenate([[True], step > 1e-12])  # drop the repeated junction points
    kappa = _three_point_curvature(w[keep])
    assert np.nanmax(kappa) <= kmax * (1 + 1e-6)


def _l_bend(width_cells: int) -> astar.OccupancyGrid:
    """A free L-shaped channel ``width_cells`` wide in a 32 x 32 block (1 m cells)."""
    occ = np.ones((32, 32), dtype=bool)
    occ[3 : 3 + width_cells, 3:29] = False  # horizontal leg along the bottom
    occ[3:29, 29 - width_cells : 29] = False  # vertical leg up the right side
    return astar.OccupancyGrid(occ, 1.0)


def test_narrow_l_bend_has_no_witness_and_the_smoother_agrees():
    # a 6-cell channel and radius 2.5 leave a 1-cell wide centre band: a turning radius of
    # 6.67 cells does not get round its corner (the search runs out of lattice states), and
    # the smoother fails as well
    grid = _l_bend(6)
    radius, kmax = 2.5, 0.15
    start, goal = np.array([8.5, 6.0]), np.array([26.0, 22.5])
    assert curvature_witness(grid, radius, start, goal, kmax, time_limit_s=20) is None
    infl = astar.inflate(grid, radius, metric="square", outside_occupied=True)
    a, b = tuple(grid.world_to_cell(start)), tuple(grid.world_to_cell(goal))
    path = astar.find_path(infl, a, b)
    corr = build_corridor(infl, path, radius=radius, raw_grid=grid)
    with pytest.raises(SmoothingError):
        Smoother(kappa_max=kmax, time_budget_s=2.0).fit(
            path, corr, raw_grid=grid, radius=radius, start=start, goal=goal
        )
    # a tighter turn fits in the same channel: the witness finds it
    w = curvature_witness(grid, radius, start, goal, 1.0)
    assert w is not None and brute_clearance(grid, w).min() >= radius - 1e-9


def test_wide_l_bend_is_feasible():
    grid = _l_bend(16)  # 11-cell wide centre band: room for a 5-cell turning radius
    w = curvature_witness(grid, 2.5, np.array([8.5, 11.0]), np.array([21.0, 24.5]), 0.2)
    assert w is not None and brute_clearance(grid, w).min() >= 2.5 - 1e-9


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"radius": -1.0}, "radius"),
        ({"kappa_max": 0.0}, "kappa_max"),
        ({"kappa_max": float("nan")}, "kappa_max"),
        ({"n_headings": 4}, "n_headings"),
    ],
)
def test_bad_input(kwargs, match):
    grid = astar.OccupancyGrid(np.zeros((10, 10), dtype=bool), 0.1)
    args = {"radius": 0.1, "kappa_max": 1.0, **kwargs}
    with pytest.raises(InvalidInputError, match=match):
        curvature_witness(grid, args.pop("radius"), (0.3, 0.3), (0.7, 0.7), **args)


def test_blocked_end_point_gives_none():
    grid = astar.OccupancyGrid(np.zeros((10, 10), dtype=bool), 0.1)
    assert curvature_witness(grid, 0.2, (0.1, 0.5), (0.5, 0.5), 1.0) is None  # near the edge
