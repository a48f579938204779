"""Tests of trajopt.planning's component labels' update for a change that frees no cell (a
re-route's marks).

:func:`update_labels` labels only the box after such a change, and the derived caches patch the
inflated grid and the clearance cost from the blocked cells alone; the labels are checked against
a brute-force breadth-first search with the search's own move rules
(``tests.reference.reachable_cells``), and the marked map's derived caches (and the raw
map's clearance blocks derived for it) against caches built afresh for it.
"""

from __future__ import annotations

import numpy as np
import pytest

import astar
import trajopt
from tests.reference import reachable_cells
from trajopt.geometry._clearance import _BLOCKS, occupied_blocks
from trajopt.planning._caches import PlannerCaches, component_labels, update_labels


def random_grid(rng: np.random.Generator, ny: int, nx: int, density: float) -> np.ndarray:
    """Random occupancy with a few walls (long thin runs that a mark can cut)."""
    occ = rng.random((ny, nx)) < density
    for _ in range(int(rng.integers(0, 3))):
        if rng.random() < 0.5:
            occ[int(rng.integers(0, ny)), :] = True
        else:
            occ[:, int(rng.integers(0, nx))] = True
        occ[int(rng.integers(0, ny)), int(rng.integers(0, nx))] = False  # a door, maybe
    return occ


def test_blocking_only_changes_against_bfs():
    """Random changes that only block cells: labels kept where the box settles it, exact."""
    local = refused = 0
    for seed in range(50):
        rng = np.random.default_rng(900 + seed)
        ny, nx = (int(v) for v in rng.integers(4, 16, size=2))
        old = random_grid(rng, ny, nx, float(rng.uniform(0.0, 0.5)))
        x0, y0 = int(rng.integers(0, nx)), int(rng.integers(0, ny))
        x1 = min(nx - 1, x0 + int(rng.integers(0, 5)))
        y1 = min(ny - 1, y0 + int(rng.integers(0, 5)))
        new = old.copy()
        new[y0 : y1 + 1, x0 : x1 + 1] |= rng.random((y1 - y0 + 1, x1 - x0 + 1)) < 0.5
        out = update_labels(component_labels(old), old, new, (x0, x1, y0, y1), 1)
        if out is None:
            refused += 1
            continue
        local += 1
        assert not out.flags.writeable and out.dtype == np.int32
        assert np.all((out == 0) == new)
        for iy, ix in np.argwhere(~new):
            reach = reachable_cells(new, (ix, iy))
            same = {(int(x), int(y)) for y, x in np.argwhere(out == out[iy, ix])}
            assert reach == same, seed
    assert local >= 20 and refused >= 1  # both ways taken


def test_a_cut_corridor_is_labelled_again():
    """A mark across a corridor splits its component: the box alone cannot tell, ``None``."""
    old = np.ones((5, 20), dtype=bool)
    old[2, :] = False  # one corridor, one component
    new = old.copy()
    new[2, 9] = True
    assert update_labels(component_labels(old), old, new, (9, 9, 2, 2), 1) is None


@pytest.mark.parametrize("inflation", ["exact", "paper"])
def test_derived_caches_of_a_marked_map_equal_fresh_ones(inflation):
    """Marks (cells blocked only, some at the map's edge) on a map: the derived caches (the
    inflated grid and the clearance cost from the marks alone with ``"exact"``) equal caches
    built afresh."""
    rng = np.random.default_rng(5)
    occ = rng.random((60, 80)) < 0.03
    grid = astar.OccupancyGrid(occ, 0.05, (0.0, 0.0))
    planner = trajopt.Planner(grid, trajopt.Robot(radius=0.12), inflation=inflation)
    caches = planner.caches
    assert caches.components is not None and caches.search_cost is not None  # built
    occupied_blocks(
        caches.grid.occupied
    )  # the raw map's clearance blocks kept (as a fit keeps them)
    for k in range(6):
        marked = occ.copy()
        x0, y0 = int(rng.integers(0, 70)), int(rng.integers(0, 50))
        marked[y0 : y0 + 3 + k, x0 : x0 + 10] = True
        new = astar.OccupancyGrid(marked, 0.05, (0.0, 0.0))
        derived = caches.derived(new)
        fresh = PlannerCaches(new, None, caches.options)
        np.testing.assert_array_equal(derived.inflated.occupied, fresh.inflated.occupied)
        np.testing.assert_allclose(derived.search_cost, fresh.search_cost, atol=1e-12)
        a, b = derived.components, fresh.components
        np.testing.assert_array_equal(a == 0, b == 0)
        pairs = np.unique(np.stack([a[a > 0], b[b > 0]]), axis=1)
        assert np.unique(pairs[0]).size == np.unique(pairs[1]).size == pairs.shape[1]
        assert _BLOCKS[id(new.occupied)][0] is new.occupied  # derived: kept, not built
        fresh_occ = np.array(marked)  # a fresh array: its blocks built from its cells
        fresh_occ.flags.writeable = False
        np.testing.assert_array_equal(occupied_blocks(new.occupied), occupied_blocks(fresh_occ))
