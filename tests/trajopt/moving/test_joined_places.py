"""Tests of trajopt.moving's safe places a wait keeps: those joined to the goal once the
movers stand still.

``_joined_at_last`` labels the free cells less the movers' final shapes with the planner's
labelling (``label=component_labels``, as :meth:`trajopt.Planner.plan` passes it) or with
:func:`scipy.ndimage.label` (``label=None``); both are checked against a brute-force
breadth-first search with the search's own move rules (``tests.reference.reachable_cells``).
"""

from __future__ import annotations

import numpy as np
import pytest

import trajopt
from astar.grid import OccupancyGrid
from tests.reference import reachable_cells
from trajopt.moving._reroute import _joined_at_last
from trajopt.moving._swept import swept_mask
from trajopt.planning._caches import component_labels

RES = 0.1


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("label", [component_labels, None], ids=["planner", "ndimage"])
def test_joined_places_against_bfs(seed, label):
    """A wall with a door or two and movers that end in or near the doors: a place is kept
    exactly when the breadth-first search from the goal reaches it."""
    rng = np.random.default_rng(seed)
    ny, nx = 24, 30
    occ = rng.random((ny, nx)) < 0.05
    occ[:, 15] = True  # a wall, doors in it
    doors = rng.choice(np.arange(2, ny - 2), size=int(rng.integers(1, 3)), replace=False)
    occ[doors, 15] = False
    grid = OccupancyGrid(occ, RES, (0.0, 0.0))
    movers = [
        trajopt.MovingObstacle.from_waypoints(
            [0.0, 2.0],
            [rng.uniform((0.2, 0.2), (2.8, 2.2)), (1.55, (int(d) + 0.5) * RES)],
            radius=0.05,
        )
        for d in doors[: int(rng.integers(1, doors.size + 1))]
    ]
    free = ~occ
    places = [
        np.array([(ix + 0.5) * RES, (iy + 0.5) * RES])
        for iy, ix in np.argwhere(free)[rng.choice(int(free.sum()), size=12, replace=False)]
    ]
    goal = np.array([2.85, 1.15])
    gx, gy = int(goal[0] / RES), int(goal[1] / RES)
    open_ = free.copy()
    for m in movers:
        open_ &= ~swept_mask(grid, m, m.t_last, m.t_last, 0.1)
    reach = reachable_cells(~open_, (gx, gy)) if open_[gy, gx] else set()
    want = [p for p in places if (int(p[0] / RES), int(p[1] / RES)) in reach]
    got = _joined_at_last(grid, free, movers, 0.1, places, goal, label)
    assert [tuple(p) for p in got] == [tuple(p) for p in want]
