"""Tests of trajopt.planning: plans that do not depend on the map's resolution: a map and its cells split k x k."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree

import astar
import trajopt
from trajopt.corridor import build_polygon_corridor
from trajopt.geometry import length_unit

RADIUS = 0.2


def two_walls(split: int = 1) -> astar.OccupancyGrid:
    """A 5 x 3 m room at 5 cm with two staggered walls; every cell split ``split`` x ``split``."""
    occ = np.zeros((60, 100), bool)
    occ[0:35, 30:36] = True
    occ[25:60, 62:68] = True
    occ[[0, -1], :] = True
    occ[:, [0, -1]] = True
    occ = np.repeat(np.repeat(occ, split, axis=0), split, axis=1)
    return astar.OccupancyGrid(occ, 0.05 / split)


def hausdorff(a: np.ndarray, b: np.ndarray) -> float:
    """Symmetric Hausdorff distance (m) between two dense point sets (scipy's k-d tree)."""
    return float(max(cKDTree(a).query(b)[0].max(), cKDTree(b).query(a)[0].max()))


def dense(curve, n: int = 4000) -> np.ndarray:
    return curve(np.linspace(*curve.domain, n))


QUERIES = [((0.5, 0.5), (4.5, 2.5)), ((0.5, 2.5), (4.6, 0.4)), ((1.0, 1.0), (4.0, 2.2))]


def test_the_length_unit_is_the_cell_unless_cells_are_finer_than_a_quarter_radius() -> None:
    assert length_unit(0.05, 0.2) == 0.05
    assert length_unit(0.1, 0.2) == 0.1
    assert length_unit(0.025, 0.2) == pytest.approx(0.05)
    assert length_unit(0.01, 0.2) == pytest.approx(0.05)
    assert length_unit(0.01, None) == 0.01
    coarse = build_polygon_corridor(two_walls(1), np.array([[0.5, 0.5], [1.0, 0.5]]), RADIUS)
    fine = build_polygon_corridor(two_walls(3), np.array([[0.5, 0.5], [1.0, 0.5]]), RADIUS)
    assert coarse.unit_m == 0.05 and fine.unit_m == pytest.approx(0.05)


@pytest.mark.parametrize("query", QUERIES)
def test_the_same_path_on_a_map_and_its_split_gives_the_same_curve(query) -> None:
    """Corridor and smoother count in metres: the same points give curves within 2 mm."""
    path = trajopt.Planner(two_walls(1), trajopt.Robot(radius=RADIUS)).plan(*query)
    pts = np.asarray(path.steps.corridor.input_path)
    curves = []
    for split in (1, 2):
        grid = two_walls(split)
        corridor = build_polygon_corridor(grid, pts, RADIUS)
        sp = trajopt.Smoother().fit(
            pts, corridor, raw_grid=grid, radius=RADIUS, start=query[0], goal=query[1]
        )
        assert sp.certificate.ok and sp.certificate.min_clearance_m >= RADIUS - 1e-9
        curves.append(sp.curve)
    assert len(curves[0].c) == len(curves[1].c)  # the same knots, in metres
    assert hausdorff(dense(curves[0]), dense(curves[1])) < 2e-3


@pytest.mark.parametrize("query", QUERIES)
def test_the_same_query_on_a_map_and_its_split_takes_the_same_time(query) -> None:
    """The whole plan (its own search on each map): durations within 1 %, both certified."""
    out = []
    for split in (1, 2, 3):
        tr = trajopt.Planner(two_walls(split), trajopt.Robot(radius=RADIUS)).plan(*query)
        cert = tr.steps.smooth_path.certificate
        assert cert.ok and cert.min_clearance_m >= RADIUS - 1e-9
        out.append(tr)
    for tr in out[1:]:
        assert tr.duration == pytest.approx(out[0].duration, rel=0.01)
        # the searches on the finer lattices take slightly different routes: the curves
        # stay within a few centimetres, not millimetres
        assert (
            hausdorff(dense(tr.steps.smooth_path.curve), dense(out[0].steps.smooth_path.curve))
            < 0.1
        )
