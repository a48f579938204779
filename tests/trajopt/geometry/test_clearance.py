"""Tests of trajopt.geometry: the exact clearances of :mod:`trajopt.geometry._clearance` against brute force."""

from __future__ import annotations

import math

import numpy as np
import pytest

import astar
from tests.reference import square_clearance
from trajopt.geometry import derive_blocks
from trajopt.geometry._clearance import (
    _BLOCKS,
    CLEARANCE_BLOCK,
    min_points_clearance,
    occupied_blocks,
    per_map,
)


@pytest.mark.parametrize("seed", range(40))
def test_min_points_clearance_is_the_least_brute_force_distance(seed: int) -> None:
    """Dense curves through random maps: the least capped distance, exactly."""
    rng = np.random.default_rng(seed)
    ny, nx = rng.integers(8, 40, size=2)
    occ = rng.random((ny, nx)) < rng.uniform(0.0, 0.25)
    grid = astar.OccupancyGrid(occ, float(rng.uniform(0.02, 0.3)), (1.5, -0.7))
    lo = np.array(grid.origin)
    hi = lo + [grid.width, grid.height]
    p0, p1, p2 = rng.uniform(lo, hi, size=(3, 2))
    t = np.linspace(0.0, 1.0, int(rng.integers(1, 300)))[:, None]
    pts = (1 - t) ** 2 * p0 + 2 * t * (1 - t) * p1 + t**2 * p2  # a quadratic Bezier
    window = float(rng.uniform(0.5, 6.0)) * grid.resolution
    want = float(np.minimum(square_clearance(grid, pts), window).min())
    assert min_points_clearance(pts, grid, window) == pytest.approx(want, abs=1e-12)


def test_min_points_clearance_skips_nothing_it_needs_in_any_order() -> None:
    """Unordered points (large jumps between them) still give the exact least distance."""
    rng = np.random.default_rng(7)
    occ = rng.random((30, 30)) < 0.1
    grid = astar.OccupancyGrid(occ, 0.1)
    pts = rng.uniform(0.0, 3.0, size=(500, 2))
    want = float(np.minimum(square_clearance(grid, pts), 0.35).min())
    assert min_points_clearance(pts, grid, 0.35) == pytest.approx(want, abs=1e-12)
    assert min_points_clearance(np.zeros((0, 2)), grid, 0.35) == 0.35
    assert math.isfinite(min_points_clearance(pts[:1], grid, 0.35))


def test_per_map_keeps_the_maps_used_last():
    """The cache keeps the 4 arrays used last: a map used between others is never rebuilt.

    Reference: a count of the builds per array, by hand: one per array while it stays among
    the last 4 used, one more after it fell out.
    """
    cache: dict = {}
    builds: dict[int, int] = {}

    def use(k, arr):
        def build():
            builds[k] = builds.get(k, 0) + 1
            return k

        assert per_map(cache, arr, build) == k

    arrays = []
    for _ in range(8):
        a = np.zeros((2, 2), dtype=bool)
        a.flags.writeable = False
        arrays.append(a)
    own = arrays[0]
    for k in range(1, 8):  # the planner's own map used between maps derived for one query
        use(0, own)
        use(k, arrays[k])
    assert builds[0] == 1 and all(builds[k] == 1 for k in range(1, 8))
    assert len(cache) == 4
    use(1, arrays[1])  # fell out long ago: built again
    assert builds[1] == 2
    writable = np.zeros((2, 2), dtype=bool)  # never kept: it could change under the cache
    use(9, writable)
    use(9, writable)
    assert builds[9] == 2 and all(v[0] is not writable for v in cache.values())


def brute_blocks(occ: np.ndarray, bs: int) -> np.ndarray:
    """Whether each ``bs x bs`` block holds an occupied cell, by a loop over the blocks."""
    ny, nx = occ.shape
    out = np.zeros((-(-ny // bs), -(-nx // bs)), dtype=bool)
    for by in range(out.shape[0]):
        for bx in range(out.shape[1]):
            out[by, bx] = bool(occ[by * bs : (by + 1) * bs, bx * bs : (bx + 1) * bs].any())
    return out


@pytest.mark.parametrize("seed", range(12))
def test_derive_blocks_equals_the_blocks_of_the_changed_map(seed: int) -> None:
    """A map changed in a window (cells blocked and freed): its blocks derived from the
    unchanged map's are the blocks of a loop over its own cells, and are what
    :func:`occupied_blocks` then returns for it."""
    rng = np.random.default_rng(seed)
    ny, nx = (int(v) for v in rng.integers(5, 70, size=2))
    base = rng.random((ny, nx)) < rng.uniform(0.0, 0.05)
    base.flags.writeable = False
    occupied_blocks(base)  # kept for the unchanged map
    x0, x1 = sorted(int(v) for v in rng.integers(0, nx, size=2))
    y0, y1 = sorted(int(v) for v in rng.integers(0, ny, size=2))
    occ = np.array(base)
    occ[y0 : y1 + 1, x0 : x1 + 1] = rng.random((y1 - y0 + 1, x1 - x0 + 1)) < 0.3
    occ.flags.writeable = False
    derive_blocks(occ, base, (x0, x1, y0, y1))
    assert _BLOCKS[id(occ)][0] is occ  # kept: occupied_blocks builds nothing for it
    got = occupied_blocks(occ)
    assert got.dtype == np.bool_ and np.array_equal(got, brute_blocks(occ, CLEARANCE_BLOCK))
    same = np.array(base)  # no window: a map equal to the unchanged one
    same.flags.writeable = False
    derive_blocks(same, base, None)
    assert np.array_equal(occupied_blocks(same), brute_blocks(base, CLEARANCE_BLOCK))


def test_derive_blocks_needs_the_unchanged_maps_blocks_and_a_read_only_map() -> None:
    """Nothing kept without the unchanged map's blocks, or for a writable (changeable) map."""
    base = np.zeros((20, 20), dtype=bool)
    base.flags.writeable = False
    occ = np.array(base)
    occ[3, 4] = True
    occ.flags.writeable = False
    derive_blocks(occ, base, (4, 4, 3, 3))  # base's blocks never built
    assert id(occ) not in _BLOCKS
    occupied_blocks(base)
    writable = np.array(occ)
    derive_blocks(writable, base, (4, 4, 3, 3))
    assert id(writable) not in _BLOCKS
    assert np.array_equal(occupied_blocks(occ), brute_blocks(occ, CLEARANCE_BLOCK))
