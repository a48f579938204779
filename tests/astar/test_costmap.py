"""Tests of astar's costmaps (astar.costmap): conventions, Nav2's translation table, files, and planning on a costmap.

The references (``tests/reference.py``) are independent of :mod:`astar.costmap`: Nav2's
published translation (``1 + floor(97 (c - 1) / 251)``) and inflation-layer formula are
re-written from their definitions, and distances come from
:func:`scipy.ndimage.distance_transform_edt`.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from PIL import Image

import astar
from astar.costmap import Costmap, from_costmap, load_costmap
from astar.errors import InvalidInputError, MapFormatError
from tests.reference import grid_path_cost, nav2_inflation, nav2_translate


def test_costmap_2d_classes_and_cost():
    v = np.array([[0, 1, 126, 252], [253, 254, 255, 0]], np.uint8)
    cm = from_costmap(v, 0.05, (1.0, 2.0), convention="costmap_2d")
    assert isinstance(cm, Costmap)
    np.testing.assert_array_equal(
        cm.grid.occupied, [[False, False, False, False], [False, True, True, False]]
    )
    np.testing.assert_allclose(cm.cost[0], [0.0, 1 / 252, 0.5, 1.0])
    np.testing.assert_allclose(cm.cost[1], [1.0, 1.0, 1.0, 0.0])
    assert cm.grid.resolution == 0.05 and cm.grid.origin == (1.0, 2.0)
    both = from_costmap(
        v, 0.05, convention="costmap_2d", inscribed_occupied=True, unknown_occupied=False
    )
    np.testing.assert_array_equal(both.grid.occupied[1], [True, True, False, False])


def test_occupancy_grid_convention_matches_costmap_2d_to_one_bucket():
    c = np.arange(256).reshape(16, 16)
    a = from_costmap(c.astype(np.uint8), 0.1, convention="costmap_2d")
    b = from_costmap(nav2_translate(c).astype(np.int8), 0.1, convention="occupancy_grid")
    np.testing.assert_array_equal(a.grid.occupied, b.grid.occupied)
    graded = c <= 252
    assert np.max(np.abs(a.cost[graded] - b.cost[graded])) <= 3 / 252 + 1e-12
    # the normalised cost never exceeds that of the value it came from (lower end of its bucket)
    assert np.all(b.cost[graded] <= a.cost[graded] + 1e-12)
    # and the translation of that lower end gives back the published value
    c_low = np.rint(b.cost * 252).astype(np.int64)
    np.testing.assert_array_equal(nav2_translate(c_low)[graded], nav2_translate(c)[graded])


@pytest.mark.parametrize(
    ("values", "convention", "match"),
    [
        (np.array([[0, 101]]), "occupancy_grid", r"values\[0, 1\] = 101 is outside"),
        (np.array([[-2, 0]]), "occupancy_grid", r"values\[0, 0\] = -2"),
        (np.array([[0, 256]]), "costmap_2d", r"values\[0, 1\] = 256"),
        (np.array([[0, -1]], np.int8), "costmap_2d", r"view\(np.uint8\)"),
        (np.array([[0.5, 1.0]]), "costmap_2d", "must hold integers"),
        (np.zeros((2, 2)), "costmap", "convention must be one of"),
        (np.zeros(4), "costmap_2d", "2-D"),
    ],
)
def test_bad_values(values, convention, match):
    with pytest.raises(InvalidInputError, match=match):
        from_costmap(values, 0.05, convention=convention)


def test_convention_is_required_and_weight_is_checked():
    with pytest.raises(TypeError):
        from_costmap(np.zeros((2, 2)), 0.05)  # type: ignore[call-arg]
    cm = from_costmap(np.zeros((2, 2), np.uint8), 0.05, convention="costmap_2d")
    with pytest.raises(InvalidInputError, match="weight"):
        cm.search_cost(-1.0)
    with pytest.raises(InvalidInputError, match="resolution"):
        from_costmap(np.zeros((2, 2), np.uint8), 0.0, convention="costmap_2d")


def _save_raw_costmap(tmp_path, og: np.ndarray, res: float, origin) -> str:
    """Write an OccupancyGrid-valued costmap as Nav2's map saver does in ``raw`` mode:
    grey = value for 0..100, 255 for unknown, top image row = last grid row."""
    pix = np.where(og < 0, 255, og).astype(np.uint8)[::-1]
    Image.fromarray(pix, mode="L").save(tmp_path / "costmap.pgm")
    (tmp_path / "costmap.yaml").write_text(
        "image: costmap.pgm\nmode: raw\n"
        f"resolution: {res}\norigin: [{origin[0]}, {origin[1]}, 0.0]\n"
        "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.25\n"
    )
    return str(tmp_path / "costmap.yaml")


def test_load_costmap_round_trip(tmp_path):
    rng = np.random.default_rng(7)
    c = rng.integers(0, 256, size=(9, 13))
    og = nav2_translate(c)
    cm = load_costmap(_save_raw_costmap(tmp_path, og, 0.05, (-1.0, 2.5)))
    assert cm.convention == "occupancy_grid"
    np.testing.assert_array_equal(cm.values, og)
    ref = from_costmap(og, 0.05, (-1.0, 2.5), convention="occupancy_grid")
    np.testing.assert_array_equal(cm.cost, ref.cost)
    np.testing.assert_array_equal(cm.grid.occupied, ref.grid.occupied)
    assert cm.grid.origin == (-1.0, 2.5)


def test_load_costmap_errors(tmp_path):
    with pytest.raises(MapFormatError, match="does not exist"):
        load_costmap(tmp_path / "missing.yaml")
    (tmp_path / "c.png").write_bytes(b"")
    with pytest.raises(MapFormatError, match="expected a map_server YAML"):
        load_costmap(tmp_path / "c.png")


def test_plans_on_a_nav2_costmap_avoid_cost_and_keep_the_certificate(shared_data):
    import trajopt
    from trajopt.analysis.metrics import point_clearance

    g = astar.load_map(shared_data / "ros" / "turtlebot3_world.yaml")
    c = nav2_inflation(g.occupied, g.resolution, r_ins=0.15, r_inf=0.6, k=3.0)
    cm = from_costmap(nav2_translate(c), g.resolution, g.origin, convention="occupancy_grid")
    robot = trajopt.Robot(radius=0.15)
    p_cost = trajopt.Planner(cm, robot)
    p_short = trajopt.Planner(cm, robot, search="shortest")
    assert p_cost.search == "costmap"
    queries = [
        ((-1.55, -0.55), (1.6, 0.5)),
        ((-0.5, -1.9), (0.55, 1.85)),
        ((-2.0, 0.4), (1.9, -0.6)),
        ((-1.1, 1.6), (1.05, -1.65)),
    ]
    means_cost, means_short = [], []
    weighted = cm.search_cost(2.0)
    for start, goal in queries:
        ta = p_cost.plan(start, goal)
        tb = p_short.plan(start, goal)
        # the costmap search is optimal for its own objective
        obj_a = grid_path_cost(ta.steps.grid_path.cells, weighted)
        obj_b = grid_path_cost(tb.steps.grid_path.cells, weighted)
        assert obj_a <= obj_b + 1e-9
        for t, out in ((ta, means_cost), (tb, means_short)):
            smp = t.sample_uniform(0.01)
            xy = np.column_stack([smp.x, smp.y])
            cell = g.world_to_cell(xy)
            out.append(float(cm.cost[cell[:, 1], cell[:, 0]].mean()))
            # the certificate is the same as on the plain map: clearance >= radius from
            # the lethal cells (independent KD-tree check, map border as occupied)
            clr = point_clearance(xy, cm.grid, border_occupied=True)
            assert clr.min() >= robot.radius - 1e-6
    assert np.mean(means_cost) < np.mean(means_short)
    assert sum(a < b for a, b in zip(means_cost, means_short, strict=True)) >= 3


def test_costmap_search_modes_need_a_costmap(shared_data):
    import trajopt

    g = astar.load_map(shared_data / "ros" / "turtlebot3_world.yaml")
    with pytest.raises(trajopt.InvalidInputError, match="needs the grid to be an astar.Costmap"):
        trajopt.Planner(g, search="costmap")
    cm = from_costmap(np.where(g.occupied, 254, 0), g.resolution, g.origin, convention="costmap_2d")
    both = trajopt.Planner(cm, trajopt.Robot(radius=0.15), search="costmap+clearance")
    ref = astar.clearance_cost(g, 0.15, outside_occupied=True) + cm.search_cost(2.0)
    np.testing.assert_allclose(both.search_cost, ref)
    assert math.isclose(both.costmap_weight, 2.0)
