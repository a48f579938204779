"""Tests of trajopt.geometry: the exact clearances of :mod:`trajopt.geometry._clearance` against brute force."""

from __future__ import annotations

import math

import numpy as np
import pytest

import astar
from tests.reference import square_clearance
from trajopt.geometry._clearance import min_points_clearance


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
