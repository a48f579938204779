"""Tests of astar.distance_transform: exact integer squared distances under both metrics.

References: brute force over all pairs of cells in exact integers, written from the metric's
definition (centre to centre; centre to the nearest point of a closed unit square), and
``scipy.ndimage.distance_transform_edt`` (on the grid, or on the grid refined by two for the
square metric) on grids too large for brute force.
"""

from __future__ import annotations

import numpy as np
import pytest

from astar.distance_transform import UNREACHED, squared_distances
from tests.reference import brute_squared, scipy_distance_cells


def _random_grids(seed: int, count: int, max_side: int):
    rng = np.random.default_rng(seed)
    for _ in range(count):
        ny, nx = (int(v) for v in rng.integers(1, max_side + 1, 2))
        occ = rng.random((ny, nx)) < rng.choice([0.005, 0.03, 0.2, 0.7])
        occ[rng.integers(ny), rng.integers(nx)] = True
        yield occ


@pytest.mark.parametrize("metric", ["centre", "square"])
def test_matches_brute_force_exactly(metric):
    for occ in _random_grids(1, 150, 18):
        np.testing.assert_array_equal(squared_distances(occ, metric), brute_squared(occ, metric))


@pytest.mark.parametrize("metric", ["centre", "square"])
def test_matches_scipy_on_larger_grids(metric):
    for occ in _random_grids(2, 12, 160):
        d2 = squared_distances(occ, metric)
        d = np.sqrt(d2) if metric == "centre" else np.sqrt(d2) * 0.5
        np.testing.assert_array_equal(d, scipy_distance_cells(occ, metric))


@pytest.mark.parametrize("metric", ["centre", "square"])
def test_ties_and_collinear_sites(metric):
    # obstacles on a regular lattice: every free cell is equidistant to several of them
    occ = np.zeros((21, 33), dtype=bool)
    occ[::4, ::4] = True
    np.testing.assert_array_equal(squared_distances(occ, metric), brute_squared(occ, metric))
    # a full row and a full column
    occ = np.zeros((9, 11), dtype=bool)
    occ[4, :] = True
    occ[:, 0] = True
    np.testing.assert_array_equal(squared_distances(occ, metric), brute_squared(occ, metric))


def test_hand_values():
    occ = np.zeros((1, 5), dtype=bool)
    occ[0, 0] = True
    # centres 0..4 cells away; squares: the near edge is k - 1/2 away, so (2k - 1)^2 quarters
    np.testing.assert_array_equal(squared_distances(occ, "centre")[0], [0, 1, 4, 9, 16])
    np.testing.assert_array_equal(squared_distances(occ, "square")[0], [0, 1, 9, 25, 49])
    occ = np.zeros((3, 3), dtype=bool)
    occ[0, 0] = True
    # the far corner: centre (2, 2) away -> 8; nearest square corner (1.5, 1.5) -> 4 * 4.5 = 18
    assert squared_distances(occ, "centre")[2, 2] == 8
    assert squared_distances(occ, "square")[2, 2] == 18


@pytest.mark.parametrize("metric", ["centre", "square"])
def test_empty_and_full_grids(metric):
    assert (squared_distances(np.zeros((4, 6), dtype=bool), metric) == UNREACHED).all()
    assert (squared_distances(np.ones((4, 6), dtype=bool), metric) == 0).all()


def test_accepts_other_dtypes_and_layouts():
    occ = np.zeros((7, 5), dtype=np.uint8)
    occ[3, 1] = 1
    ref = brute_squared(occ.astype(bool), "centre")
    np.testing.assert_array_equal(squared_distances(occ, "centre"), ref)
    np.testing.assert_array_equal(squared_distances(occ.T.copy().T, "centre"), ref)
    np.testing.assert_array_equal(squared_distances(np.asfortranarray(occ.T), "centre"), ref.T)


def test_rejects_bad_input():
    with pytest.raises(ValueError, match="metric must be"):
        squared_distances(np.zeros((2, 2), dtype=bool), "manhattan")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="2-D"):
        squared_distances(np.zeros(4, dtype=bool), "centre")
