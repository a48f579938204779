"""Tests of trajopt.planning: the planner's memory estimate and the up-front refusal of maps too large for it."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

import astar
import trajopt
from trajopt.planning import _memory
from trajopt.planning._options import PlannerOptions


def rooms(n: int) -> astar.OccupancyGrid:
    """An ``n x n`` map at 2 cm of walls with doors (long searches), deterministic."""
    occ = np.zeros((n, n), bool)
    occ[[0, -1], :] = occ[:, [0, -1]] = True
    for i in range(n // 8, n, n // 4):
        occ[:, i : i + 3] = True
        occ[(i * 7) % (n - 40) + 20 : (i * 7) % (n - 40) + 40, i : i + 3] = False
    return astar.OccupancyGrid(occ, 0.02)


def test_a_map_larger_than_the_memory_left_is_refused_at_once(monkeypatch) -> None:
    monkeypatch.setattr(_memory, "available_memory", lambda: 2**30)
    grid = astar.OccupancyGrid(np.zeros((6000, 5000), bool), 0.01)
    with pytest.raises(trajopt.InvalidInputError) as err:
        trajopt.Planner(grid, trajopt.Robot(radius=0.2), landmarks=2)
    msg = str(err.value)
    assert "5000 x 6000 = 30,000,000 cells" in msg and "1.00 GiB available" in msg
    assert "grid.coarsen(2)" in msg and "landmarks=0" in msg and 'search="shortest"' in msg
    # the knob works: a quarter of the cells fits
    est = _memory.estimate_memory(grid.coarsen(2).shape, PlannerOptions(landmarks=0))
    assert est.total < 2**30
    trajopt.Planner(grid.coarsen(2), trajopt.Robot(radius=0.2))
    # an unknown amount of memory refuses nothing
    monkeypatch.setattr(_memory, "available_memory", lambda: None)
    trajopt.Planner(grid, trajopt.Robot(radius=0.2))


def test_update_map_to_a_larger_shape_is_checked_too(monkeypatch) -> None:
    planner = trajopt.Planner(astar.OccupancyGrid(np.zeros((50, 50), bool), 0.05))
    monkeypatch.setattr(_memory, "available_memory", lambda: 2**28)
    with pytest.raises(trajopt.InvalidInputError, match="GiB available"):
        planner.update_map(astar.OccupancyGrid(np.zeros((5000, 5000), bool), 0.05))


def test_the_estimate_covers_what_a_new_planner_allocates() -> None:
    """Traced peak of a new planner's plans on a 1 M-cell map <= the per-cell estimate."""
    grid = rooms(1000)
    queries = [((0.5, 0.5), (19.5, 19.5)), ((19.5, 0.5), (0.5, 19.0)), ((0.5, 10.0), (19.5, 9.0))]
    for search in ("clearance", "shortest"):
        trajopt.Planner(grid, trajopt.Robot(radius=0.1), search=search).plan(*queries[0])
        tracemalloc.start()
        try:
            planner = trajopt.Planner(grid, trajopt.Robot(radius=0.1), search=search)
            for q in queries:
                planner.plan(*q)
            peak = tracemalloc.get_traced_memory()[1]
        finally:
            tracemalloc.stop()
        est = _memory.estimate_memory(grid.shape, planner.options)
        assert peak <= est.total - _memory.BASE_BYTES, (search, peak / est.cells)
