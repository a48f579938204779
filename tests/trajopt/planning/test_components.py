"""Tests of trajopt.planning: fast refusals (issue 33, part 4): component labels of the inflated grid.

The labels (:attr:`PlannerCaches.components`) are checked against a brute-force
breadth-first search with the search's own move rules (``tests.reference.reachable_cells``)
and against ``scipy.ndimage.label``; then the planner's refusal of unconnected ends (before
any search, for a disc and for a footprint robot) and the labels' upkeep by
``update_map``.
"""

from __future__ import annotations

import time

import numpy as np
import pytest
from scipy import ndimage

import astar
import trajopt
from tests.reference import reachable_cells
from trajopt.errors import NoPathError
from trajopt.planning import _disc
from trajopt.planning._caches import PlannerCaches, component_labels, update_labels

ROBOT = trajopt.Robot(radius=0.12)


def random_grid(rng: np.random.Generator, ny: int, nx: int, density: float) -> np.ndarray:
    """Random occupancy, half of the time with walls and diagonal corner contacts."""
    occ = rng.random((ny, nx)) < density
    if rng.random() < 0.5:  # checkerboard patches: cells touching only at corners
        iy, ix = np.mgrid[0:ny, 0:nx]
        patch = (rng.random((ny, nx)) < 0.3) & ((ix + iy) % 2 == 0)
        occ = np.where(patch, (ix + iy) % 4 == 0, occ)
    return occ


# ------------------------------------------------------------------ labels
@pytest.mark.parametrize("seed", range(12))
def test_labels_are_exactly_the_search_reachable_sets(seed):
    rng = np.random.default_rng(seed)
    for _ in range(6):
        ny, nx = (int(v) for v in rng.integers(1, 18, size=2))
        occ = random_grid(rng, ny, nx, float(rng.uniform(0.0, 0.7)))
        labels = component_labels(occ)
        assert labels.dtype == np.int32 and labels.shape == occ.shape
        assert not labels.flags.writeable
        assert np.all((labels == 0) == occ)
        free = [(int(x), int(y)) for y, x in np.argwhere(~occ)]
        if free:  # labels 1 .. n, each used
            assert set(np.unique(labels[~occ])) == set(range(1, labels.max() + 1))
        done: set[tuple[int, int]] = set()
        for c in free:
            if c in done:
                continue
            reach = reachable_cells(occ, c)  # 8-connected, no corner cutting
            same = {(int(x), int(y)) for y, x in np.argwhere(labels == labels[c[1], c[0]])}
            assert reach == same, (occ.astype(int), c)
            assert reach == reachable_cells(occ, c, connectivity=4)  # the one-line proof
            done |= reach


@pytest.mark.parametrize("seed", range(4))
def test_labels_equal_scipy_ndimage_label(seed):
    rng = np.random.default_rng(100 + seed)
    for ny, nx in ((1, 1), (1, 40), (40, 1), (57, 91), (200, 130)):
        occ = random_grid(rng, ny, nx, float(rng.uniform(0.0, 0.8)))
        ref, _ = ndimage.label(~occ)  # default 2-D structure: 4-connected
        np.testing.assert_array_equal(component_labels(occ), ref)
    assert np.all(component_labels(np.ones((5, 7), bool)) == 0)
    assert np.all(component_labels(np.zeros((5, 7), bool)) == 1)


@pytest.mark.parametrize("seed", range(4))
def test_find_path_fails_exactly_between_components(seed):
    """The claim against the search itself: jump points, the cost kernel, landmarks."""
    rng = np.random.default_rng(200 + seed)
    occ = random_grid(rng, 40, 50, 0.42)
    grid = astar.OccupancyGrid(occ, 1.0)
    labels = component_labels(occ)
    cost = rng.random(occ.shape)
    lms = astar.build_landmarks(grid, cost, 2)
    free = np.argwhere(~occ)
    for _ in range(60):
        (ay, ax), (by, bx) = free[rng.integers(len(free), size=2)]
        same = labels[ay, ax] == labels[by, bx]
        for kw in ({}, {"cost": cost}, {"landmarks": lms}):
            try:
                astar.find_path(grid, (int(ax), int(ay)), (int(bx), int(by)), **kw)
                found = True
            except astar.NoPathError:
                found = False
            assert found == same, kw


# ------------------------------------------------------------------ refusals
def two_rooms(gap_cells: int = 0) -> astar.OccupancyGrid:
    """60 x 40 cells of 5 cm, a wall at x = 1.5 m with a door of ``gap_cells`` cells."""
    occ = np.zeros((40, 60), bool)
    occ[:, 30] = True
    if gap_cells:
        occ[20 - gap_cells // 2 : 20 - gap_cells // 2 + gap_cells, 30] = False
    return astar.OccupancyGrid(occ, 0.05)


def no_search(monkeypatch) -> None:
    def fail(*args, **kwargs):
        raise AssertionError("the search ran")

    monkeypatch.setattr(_disc.astar, "find_path", fail)


def test_unconnected_ends_are_refused_before_the_search(monkeypatch):
    grid = two_rooms()
    planner = trajopt.Planner(grid, ROBOT)
    assert planner.caches.built_components is None
    no_search(monkeypatch)
    with pytest.raises(NoPathError) as ei:
        planner.plan((0.4, 0.3), (2.6, 1.6))
    msg = str(ei.value)
    assert "no path from start [0.4, 0.3] m to goal [2.6, 1.6] m" in msg
    assert "radius 0.12 m" in msg and "not connected for this robot radius" in msg
    assert isinstance(ei.value, astar.NoPathError)
    labels = planner.caches.built_components
    assert labels is not None and labels.max() == 2


def test_door_connects_a_small_disc_and_refuses_a_large_one(monkeypatch):
    grid = two_rooms(gap_cells=8)  # 0.4 m door
    small = trajopt.Planner(grid, trajopt.Robot(radius=0.12))
    traj = small.plan((0.4, 0.3), (2.6, 1.6))
    assert traj.stats["grid_path"] == "searched"
    big = trajopt.Planner(grid, trajopt.Robot(radius=0.25))
    no_search(monkeypatch)
    with pytest.raises(NoPathError, match="not connected for this robot radius"):
        big.plan((0.4, 0.3), (2.6, 1.6))


def test_footprint_robot_refused_by_its_inscribed_disc(monkeypatch):
    grid = two_rooms()
    robot = trajopt.Robot.rectangle(0.3, 0.2)
    no_search(monkeypatch)
    t0 = time.perf_counter()
    with pytest.raises(NoPathError, match="inscribed disc: no path .* not connected"):
        trajopt.Planner(grid, robot).plan((0.4, 0.6), (2.6, 1.4))
    assert time.perf_counter() - t0 < 5.0  # no smoother ran (its budget alone is 5 s)


def test_refusal_is_fast_on_a_large_map():
    occ = np.zeros((1200, 1200), bool)
    occ[:, 600] = True  # two halves of 0.72 M cells each
    grid = astar.OccupancyGrid(occ, 0.05)
    planner = trajopt.Planner(grid, trajopt.Robot(radius=0.2))
    with pytest.raises(NoPathError):
        planner.plan((1.0, 1.0), (50.0, 50.0))  # builds the labels
    t0 = time.perf_counter()
    for _ in range(5):
        with pytest.raises(NoPathError, match="not connected"):
            planner.plan((1.0, 1.0 + _), (50.0, 50.0))
    assert (time.perf_counter() - t0) / 5 < 0.1


# ------------------------------------------------------------------ upkeep
def assert_same_partition(a: np.ndarray, b: np.ndarray) -> None:
    """Two labellings with the same 0 cells and the same sets of equal labels."""
    np.testing.assert_array_equal(a == 0, b == 0)
    pairs = np.unique(np.stack([a[a > 0], b[b > 0]]), axis=1)
    assert np.unique(pairs[0]).size == np.unique(pairs[1]).size == pairs.shape[1]


def test_update_map_keeps_updates_relabels_and_resets():
    grid = two_rooms(gap_cells=8)
    planner = trajopt.Planner(grid, ROBOT)
    caches = planner.caches
    planner.plan((0.4, 0.3), (2.6, 1.6))
    first = caches.built_components
    assert first is not None and first.max() == 1
    # no change: kept
    planner.update_map(astar.OccupancyGrid(np.array(grid.occupied), 0.05))
    assert caches.built_components is first
    # a block in the open: updated in the changed box, not labelled again
    occ = np.array(grid.occupied)
    occ[2:10, 40:50] = True  # y in [0.1, 0.5] m, x in [2.0, 2.5] m
    planner.update_map(astar.OccupancyGrid(occ, 0.05))
    labels = caches.built_components
    assert labels is not None and labels is not first
    assert_same_partition(labels, component_labels(caches.inflated.occupied))
    # close the door: a component splits; dropped, labelled again, refused at once
    occ2 = occ.copy()
    occ2[:, 30] = True
    planner.update_map(astar.OccupancyGrid(occ2, 0.05))
    assert caches.built_components is None
    with pytest.raises(NoPathError, match="not connected"):
        planner.plan((0.4, 0.3), (2.6, 1.6))
    assert caches.components.max() == 2
    # open it again: two components merge; dropped, and the query plans
    planner.update_map(astar.OccupancyGrid(occ, 0.05))
    assert caches.built_components is None
    planner.plan((0.4, 0.3), (2.6, 1.6))
    assert caches.components.max() == 1
    # another shape: reset
    planner.update_map(astar.OccupancyGrid(np.zeros((30, 30), bool), 0.05))
    assert caches.built_components is None


@pytest.mark.parametrize("seed", range(6))
def test_labels_after_random_updates_equal_fresh_labels(seed):
    """Blocks added and removed at random: the kept labels against a fresh labelling."""
    rng = np.random.default_rng(300 + seed)
    occ = rng.random((50, 70)) < 0.06
    opts = trajopt.Planner(astar.OccupancyGrid(occ, 0.05), ROBOT).caches.options
    caches = PlannerCaches(astar.OccupancyGrid(occ, 0.05), None, opts)
    caches.components  # noqa: B018 - build
    local = 0
    for _ in range(25):
        y, x = (int(v) for v in rng.integers(0, [47, 67]))
        h, w = (int(v) for v in rng.integers(1, 4, size=2))
        occ = occ.copy()
        occ[y : y + h, x : x + w] = rng.random() < 0.6
        grid = astar.OccupancyGrid(occ, 0.05)
        caches.update(grid)
        local += caches.built_components is not None
        fresh = PlannerCaches(grid, None, opts)
        np.testing.assert_array_equal(caches.inflated.occupied, fresh.inflated.occupied)
        assert_same_partition(caches.components, fresh.components)
    assert local > 0  # the local update ran


def test_update_labels_against_bfs():
    """:func:`update_labels` on small random grids and changes, against the brute force."""
    local = 0
    for seed in range(60):
        rng = np.random.default_rng(400 + seed)
        ny, nx = (int(v) for v in rng.integers(4, 16, size=2))
        old = random_grid(rng, ny, nx, float(rng.uniform(0.1, 0.6)))
        x0, y0 = int(rng.integers(0, nx)), int(rng.integers(0, ny))
        x1 = min(nx - 1, x0 + int(rng.integers(0, 4)))
        y1 = min(ny - 1, y0 + int(rng.integers(0, 4)))
        new = old.copy()
        new[y0 : y1 + 1, x0 : x1 + 1] = rng.random((y1 - y0 + 1, x1 - x0 + 1)) < 0.5
        window = (x0, x1, y0, y1)
        out = update_labels(component_labels(old), old, new, window, int(rng.integers(1, 4)))
        if out is None:  # a split, a merge or a new component: labelled again
            continue
        local += 1
        assert not out.flags.writeable and out.dtype == np.int32
        assert np.all((out == 0) == new)
        done: set[tuple[int, int]] = set()
        for iy, ix in np.argwhere(~new):
            if (ix, iy) in done:  # the moves are symmetric: its reach is one already checked
                continue
            reach = reachable_cells(new, (ix, iy))
            same = {(int(x), int(y)) for y, x in np.argwhere(out == out[iy, ix])}
            assert reach == same, seed
            done |= reach
    assert local >= 10


@pytest.mark.parametrize("seed", range(8))
def test_an_end_shut_in_by_marks_is_one_no_search_leaves(seed):
    """``shut_in`` (a re-route's refusal of a marked map) against fresh caches of the marked
    map: whenever it says an end is shut in, the fresh labels put start and goal in different
    components; a ring of marks round the start without a gap is seen, one with a wide gap
    is not."""
    from trajopt.planning._moving import shut_in

    rng = np.random.default_rng(seed)
    occ = random_grid(rng, 70, 90, 0.02)
    grid = astar.OccupancyGrid(occ, 0.05, (0.0, 0.0))
    planner = trajopt.Planner(grid, ROBOT)
    caches = planner.caches
    free = np.argwhere(~np.asarray(caches.inflated.occupied))
    (sy, sx), (gy, gx) = free[rng.integers(len(free), size=2)]
    start, goal = grid.cell_to_world(np.array([[sx, sy], [gx, gy]]))
    iy, ix = np.mgrid[0:70, 0:90]
    r = np.hypot(ix - sx, iy - sy)
    for gap, inner in ((0.0, 6.0), (1.2, 6.0), (0.0, 9.0), (0.3, 7.0)):
        ring = (r >= inner) & (r <= inner + 2.0)
        if gap:  # no marks within the gap's angle
            angle = np.abs(np.arctan2(iy - sy, ix - sx) - rng.uniform(-3, 3))
            ring &= np.minimum(angle, 2 * np.pi - angle) > gap
        marked = grid.with_occupied(occ | ring)
        said = shut_in(caches, marked, start, goal)
        labels = PlannerCaches(marked, None, planner.options).components
        joined = labels[sy, sx] > 0 and labels[sy, sx] == labels[gy, gx]
        if said:
            assert not joined
        if gap == 0.0 and labels[sy, sx] > 0 and r[gy, gx] > inner + 3.0:
            assert said  # a full ring shuts the start in
        if gap >= 1.2 and joined:
            assert not said


def test_the_kernel_gets_read_only_cells_whatever_it_is_given(monkeypatch):
    """``component_labels`` hands its compiled kernel a read-only array, from writable cells
    too (as a derived caches' box is): one compiled signature, the one a plan's own read-only
    inflated grid compiles (a writable array compiled a second one, about 4 s inside a
    process's first re-route on a fresh cache). The labels are the same either way."""
    import trajopt.planning._caches as caches_module

    seen = []
    kernel = caches_module.label_kernel

    def spy(occ):
        seen.append(occ.flags.writeable)
        return kernel(occ)

    monkeypatch.setattr(caches_module, "label_kernel", spy)
    occ = np.array([[0, 1, 0], [1, 0, 0]], dtype=bool)
    frozen = occ.copy()
    frozen.flags.writeable = False
    a, b = component_labels(occ), component_labels(frozen)
    c = component_labels(np.ones((4, 5), dtype=bool)[1:3, 1:4] & False)  # a slice's copy
    assert seen == [False, False, False] and occ.flags.writeable  # the caller's array kept
    assert a.tolist() == b.tolist() == [[1, 0, 2], [0, 2, 2]] and c.tolist() == [[1] * 3] * 2
