"""Tests of trajopt.planning through the public API: bad input everywhere (issue 7, section 3): typed errors naming the field, value and rule."""

from __future__ import annotations

import math

import numpy as np
import pytest

import astar
import trajopt
from trajopt.errors import InvalidInputError

ROBOT = trajopt.Robot(radius=0.12)


def door_grid() -> astar.OccupancyGrid:
    occ = np.zeros((40, 60), bool)
    occ[:, 30] = True
    occ[16:28, 30] = False
    return astar.OccupancyGrid(occ, 0.05, (0.0, 0.0))


@pytest.mark.parametrize(
    ("start", "match"),
    [
        ((math.nan, 0.3), r"start must be finite, got \[nan, 0.3\]"),
        ((0.4, -math.inf), r"start must be finite, got \[0.4, -inf\]"),
        (("a", "b"), "start must be two numbers"),
        ([[0.4, 0.3]], "start must be two numbers"),
        ((0.4, 0.3, 0.0), "start must be two numbers"),
        (None, "start must be two numbers"),
        ((-0.1, 0.3), r"outside the map \[0.0, 3.0\] x \[0.0, 2.0\]"),
        ((1.52, 0.3), r"occupied cell \(30, 5\) of the map"),
        # inside the avoidance area: the message gives the clearance found and the radius
        ((1.44, 0.3), r"0.06 m from the nearest obstacle.*radius 0.12 m"),
        ((0.05, 1.0), r"0.05 m from the nearest obstacle \(or the map edge\).*radius 0.12 m"),
    ],
)
def test_bad_start(start, match) -> None:
    with pytest.raises(InvalidInputError, match=match):
        trajopt.plan(door_grid(), start, (2.6, 1.6), ROBOT)


def test_start_equals_goal_and_same_cell() -> None:
    with pytest.raises(InvalidInputError, match=r"same cell \(8, 6\)"):
        trajopt.plan(door_grid(), (0.42, 0.32), (0.42, 0.32), ROBOT)


def test_goal_blocked_by_paper_inflation_names_cell_and_clearance() -> None:
    with pytest.raises(
        InvalidInputError,
        match=r"goal .* cell \(\d+, \d+\), which is blocked.*"
        r"radius 0.12 m.*clearance of the cell centre",
    ):
        trajopt.plan(door_grid(), (0.4, 0.3), (1.32, 0.3), ROBOT, inflation="paper")


@pytest.mark.parametrize(
    ("shape", "match"),
    [
        ((0, 5), "must not be empty"),
        ((5, 0), "must not be empty"),
        ((3,), "2-D"),
        ((2, 2, 2), "2-D"),
    ],
)
def test_zero_size_and_wrong_shape_maps(shape, match) -> None:
    with pytest.raises(astar.InvalidInputError, match=match):
        astar.OccupancyGrid(np.zeros(shape, bool), 0.05)


@pytest.mark.parametrize(
    ("occ", "match"),
    [
        (np.array([["a", "b"]]), "dtype"),
        (np.array([[0.5, 1.0]]), "0/1"),
        (np.array([[np.nan, 0.0]]), "NaN"),
        (np.array([[2, 0]]), "found 2"),
    ],
)
def test_wrong_dtype_maps(occ, match) -> None:
    with pytest.raises(astar.InvalidInputError, match=match):
        astar.OccupancyGrid(occ, 0.05)


@pytest.mark.parametrize(
    ("grid", "robot", "kwargs", "match"),
    [
        (
            np.zeros((4, 4), bool),
            None,
            {},
            "grid must be an astar.OccupancyGrid or astar.Costmap, got ndarray",
        ),
        ("door", {"radius": 0.1}, {}, "robot must be a trajopt.Robot, got dict"),
        ("door", None, {"timing_dt": 0.0}, r"timing_dt must be a number in \(0, 0.5\]"),
        ("door", None, {"timing_dt": math.nan}, "timing_dt"),
        ("door", None, {"timing_dt": "0.02"}, "timing_dt"),
        ("door", None, {"w_cells": 2.5}, "w_cells must be an integer >= 0, got 2.5"),
        ("door", None, {"w_cells": True}, "w_cells"),
    ],
)
def test_bad_planner_arguments(grid, robot, kwargs, match) -> None:
    grid = door_grid() if isinstance(grid, str) else grid
    with pytest.raises(InvalidInputError, match=match):
        trajopt.Planner(grid, robot, **kwargs)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"radius": 0.0}, r"Robot.radius must be finite and > 0, got 0.0"),
        ({"v_max": -1.0}, r"Robot.v_max must be finite and > 0, got -1.0"),
        ({"a_max": math.inf}, "Robot.a_max must be finite"),
        ({"j_max": math.nan}, "Robot.j_max must be finite"),
        ({"omega_max": "fast"}, "Robot.omega_max must be a number, got 'fast'"),
        ({"a_lat_max": True}, "Robot.a_lat_max must be a number, got True"),
        ({"radius": np.array([0.1, 0.2])}, "Robot.radius"),
        ({"track_width": 0.3, "wheel_v_max": None}, "given together"),
        ({"track_width": -0.3}, "Robot.track_width must be finite and > 0"),
    ],
)
def test_bad_robot(kwargs, match) -> None:
    with pytest.raises(InvalidInputError, match=match):
        trajopt.Robot(**kwargs)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"degree": 7}, "degree must be an integer in 3..5, got 7"),
        ({"kappa_max": -1.0}, "kappa_max"),
        ({"kappa_max": math.inf}, "kappa_max"),
        ({"qp_solver": "gurobi"}, "qp_solver must be one of"),
        ({"time_budget_s": 0.0}, "time_budget_s"),
        ({"max_attempts": 0}, "max_attempts must be an integer >= 1, got 0"),
    ],
)
def test_bad_smoother(kwargs, match) -> None:
    with pytest.raises(InvalidInputError, match=match):
        trajopt.Smoother(**kwargs)


def test_bad_time_parameterize_arguments() -> None:
    line = trajopt.plan(door_grid(), (0.4, 0.3), (1.2, 0.3), ROBOT).path
    for kwargs, match in [
        ({"v_start": math.nan}, "v_start"),
        ({"v_end": -1.0}, "v_end"),
        ({"dt": 0.0}, r"dt must be a number in \(0, 0.5\]"),
        ({"dt": 2.0}, "dt"),
    ]:
        with pytest.raises(InvalidInputError, match=match):
            trajopt.time_parameterize(line, ROBOT, **kwargs)
    with pytest.raises(InvalidInputError, match="curve must be a ParametricCurve"):
        trajopt.time_parameterize(np.zeros((5, 2)), ROBOT)
    with pytest.raises(InvalidInputError, match="robot must be a trajopt.Robot"):
        trajopt.time_parameterize(line, {"v_max": 1.0})


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"start_heading": math.nan}, "start_heading"),
        ({"goal_heading": "north"}, "goal_heading"),
        ({"v_start": -0.1}, "v_start"),
        ({"v_end": math.inf}, "v_end"),
    ],
)
def test_bad_query_options(kwargs, match) -> None:
    with pytest.raises(InvalidInputError, match=match):
        trajopt.plan(door_grid(), (0.4, 0.3), (2.6, 1.6), ROBOT, **kwargs)
