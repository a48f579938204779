"""Tests of trajopt.analysis.scenes (``trajopt.scenes.paper()``): the chapter's setting and the properties it promises."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from astar.inflation import avoidance_area, inflate
from astar.search import find_path
from trajopt.analysis import scenes
from trajopt.errors import InvalidInputError


@pytest.fixture(scope="module")
def scene() -> scenes.Scene:
    return scenes.paper()


@pytest.fixture(scope="module")
def grids(scene: scenes.Scene) -> dict:
    g = scene.grid
    return {
        "avoidance W=11": avoidance_area(g, scene.w_cells, border=True),
        "inflate centre": inflate(g, scene.robot_radius, metric="centre"),
        "inflate square": inflate(g, scene.robot_radius, metric="square"),
    }


def test_paper_scene_values(scene: scenes.Scene) -> None:
    g = scene.grid
    assert g.shape == (150, 150) and g.resolution == 0.03 and g.origin == (0.0, 0.0)
    assert scene.robot_width == 0.33 and scene.robot_radius == pytest.approx(0.165)
    assert scene.w_cells == 11 == round(scene.robot_width / g.resolution)
    assert scene.target_names == ("A", "B", "C", "D")
    x, y = scene.start
    assert x < 1.0 and y < 1.0  # SP near the lower-left corner
    assert scene.goal("D") == scene.targets["D"]
    assert scene.start_cell == tuple(g.world_to_cell(scene.start))


def test_scene_is_frozen(scene: scenes.Scene) -> None:
    with pytest.raises(dataclasses.FrozenInstanceError):
        scene.start = (0.0, 0.0)  # type: ignore[misc]
    with pytest.raises(TypeError):
        scene.targets["E"] = (1.0, 1.0)  # type: ignore[index]
    assert not scene.grid.occupied.flags.writeable
    with pytest.raises(InvalidInputError, match="target name"):
        scene.goal("E")


def test_obstacles_are_the_documented_squares(scene: scenes.Scene) -> None:
    occ = scene.grid.occupied
    expected = np.zeros_like(occ)
    for x0, y0, side in scene.obstacles:
        i0, j0, n = round(x0 / 0.03), round(y0 / 0.03), round(side / 0.03)
        expected[j0 : j0 + n, i0 : i0 + n] = True
        assert side >= 0.6  # square obstacles, at least 20 cells wide
    np.testing.assert_array_equal(occ, expected)
    assert len(scene.obstacles) >= 4


def test_start_and_targets_free_and_reachable(scene: scenes.Scene, grids: dict) -> None:
    for label, g in grids.items():
        assert g.is_free(scene.start_cell), label
        for name in scene.target_names:
            cell = scene.goal_cell(name)
            assert g.is_free(cell), (label, name)
            path = find_path(g, scene.start_cell, cell)
            assert tuple(path.cells[-1]) == cell


def _avoid_path(scene: scenes.Scene, grids: dict, name: str) -> np.ndarray:
    path = find_path(grids["avoidance W=11"], scene.start_cell, scene.goal_cell(name))
    return np.asarray(path.cells)


def test_target_a_needs_no_tight_turns_and_is_x_monotone(scene, grids) -> None:
    cells = _avoid_path(scene, grids, "A")
    steps = np.diff(cells, axis=0)
    assert np.all(steps[:, 0] > 0)  # y = f(x) works on A
    heading = np.arctan2(steps[:, 1], steps[:, 0])
    turns = np.abs(np.diff(heading))
    assert turns.max() <= np.pi / 4 + 1e-12


def test_targets_b_c_close_to_obstacles(scene: scenes.Scene) -> None:
    for name in ("B", "C"):
        x, y = scene.goal(name)
        gaps = [
            np.hypot(max(0, x0 - x, x - x0 - s), max(0, y0 - y, y - y0 - s))
            for x0, y0, s in scene.obstacles
        ]
        assert min(gaps) < 0.6, name  # within 0.6 m of an obstacle square


def test_target_d_has_a_vertical_section_and_a_sharp_turn(scene, grids) -> None:
    cells = _avoid_path(scene, grids, "D")
    steps = np.diff(cells, axis=0)
    vertical = (steps[:, 0] == 0) & (steps[:, 1] != 0)
    run = max(len(r) for r in "".join("1" if v else "0" for v in vertical).split("0"))
    assert run * 0.03 >= 1.0  # at least a metre straight up
    # the heading turns by at least 90 degrees within 10 steps after the climb
    heading = np.unwrap(np.arctan2(steps[:, 1], steps[:, 0]))
    assert np.max(np.abs(heading[10:] - heading[:-10])) >= np.pi / 2 - 1e-12


def test_scene_validation() -> None:
    g = scenes.paper().grid
    with pytest.raises(InvalidInputError, match="robot_width"):
        scenes.Scene("x", g, (0.5, 0.5), {"A": (1, 1)}, robot_width=0.0, w_cells=1)
    with pytest.raises(InvalidInputError, match="start"):
        scenes.Scene("x", g, (0.5,), {"A": (1, 1)}, robot_width=0.3, w_cells=1)
    with pytest.raises(InvalidInputError, match="w_cells"):
        scenes.Scene("x", g, (0.5, 0.5), {}, robot_width=0.3, w_cells=-1)
    with pytest.raises(InvalidInputError, match="grid"):
        scenes.Scene("x", np.zeros((3, 3)), (0.5, 0.5), {}, robot_width=0.3, w_cells=1)
