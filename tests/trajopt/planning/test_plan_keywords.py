"""Tests of trajopt.planning: trajopt.plan takes every option of trajopt.Planner and passes it through unchanged."""

from __future__ import annotations

import dataclasses
import inspect
import math

import numpy as np
import pytest

import astar
import trajopt
from tests.cases import door_grid
from trajopt.errors import InvalidInputError

ROBOT = trajopt.Robot(radius=0.12)
START, GOAL = (0.4, 0.3), (2.6, 1.6)


@pytest.fixture(scope="module")
def grid():
    return door_grid()


def _same(a, b) -> None:
    np.testing.assert_array_equal(a.path.control_points, b.path.control_points)
    assert a.duration == b.duration
    t = np.linspace(0.0, a.duration, 200)
    np.testing.assert_array_equal(np.asarray(a.sample(t)), np.asarray(b.sample(t)))


def test_plan_has_every_keyword_of_planner():
    """Every option of ``Planner.__init__`` (besides the map and the robot) is a keyword of
    ``plan`` with the same default and annotation, so the two cannot drift apart silently."""
    ours = inspect.signature(trajopt.plan).parameters
    theirs = inspect.signature(trajopt.Planner.__init__).parameters
    options = [n for n in theirs if n not in {"self", "grid", "robot"}]
    assert "timing_dt" in options and "landmarks" in options
    missing = [n for n in options if n not in ours]
    assert not missing, f"trajopt.plan lacks Planner options {missing}"
    for name in options:
        assert ours[name].kind is inspect.Parameter.KEYWORD_ONLY, name
        assert ours[name].default == theirs[name].default, name
        assert ours[name].annotation == theirs[name].annotation, name
    assert list(ours)[:4] == ["grid", "start", "goal", "robot"]


def test_plan_timing_dt_is_the_planners(grid):
    a = trajopt.plan(grid, START, GOAL, ROBOT, timing_dt=0.05)
    b = trajopt.Planner(grid, ROBOT, timing_dt=0.05).plan(START, GOAL)
    _same(a, b)
    assert a.stats["timing_greedy_duration"] == b.stats["timing_greedy_duration"]
    # the step reaches the timing: the greedy's own duration depends on it
    default = trajopt.plan(grid, START, GOAL, ROBOT)
    assert a.stats["timing_greedy_duration"] != default.stats["timing_greedy_duration"]


def test_plan_landmarks_are_the_planners(grid, monkeypatch):
    built: list[int] = []
    real = astar.build_landmarks

    def spy(g, cost, k=6, **kw):
        built.append(k)
        return real(g, cost, k, **kw)

    monkeypatch.setattr(astar, "build_landmarks", spy)
    a = trajopt.plan(grid, START, GOAL, ROBOT, landmarks=3)
    assert built == [3]  # the search of plan(...) used three landmarks
    b = trajopt.Planner(grid, ROBOT, landmarks=3).plan(START, GOAL)
    assert built == [3, 3]
    _same(a, b)
    _same(a, trajopt.plan(grid, START, GOAL, ROBOT))  # exact either way
    assert built == [3, 3]


@pytest.mark.parametrize(
    "kwargs",
    [
        {"timing_dt": 0.0},
        {"timing_dt": 0.6},
        {"timing_dt": math.nan},
        {"timing_dt": True},
        {"timing_dt": "0.02"},
        {"landmarks": -1},
        {"landmarks": 65},
        {"landmarks": 2.5},
        {"landmarks": True},
    ],
)
def test_plan_refuses_what_the_planner_refuses(grid, kwargs):
    with pytest.raises(InvalidInputError) as theirs:
        trajopt.Planner(grid, ROBOT, **kwargs)
    with pytest.raises(InvalidInputError) as ours:
        trajopt.plan(grid, START, GOAL, ROBOT, **kwargs)
    assert type(ours.value) is type(theirs.value)
    assert str(ours.value) == str(theirs.value)
    assert next(iter(kwargs)) in str(ours.value)


def test_planner_keywords_are_the_options_fields():
    """``Planner`` and ``plan`` take each setting of ``PlannerOptions`` by the same name, with
    the field's own default (a factory default shows as ``None``), and ``options`` itself."""
    fields = {f.name: f for f in dataclasses.fields(trajopt.PlannerOptions)}
    params = inspect.signature(trajopt.Planner.__init__).parameters
    keywords = [n for n in params if n not in {"self", "grid", "options"}]
    assert sorted(keywords) == sorted(fields)
    for name in keywords:
        f = fields[name]
        default = None if f.default is dataclasses.MISSING else f.default
        assert params[name].default == default, name
    assert "options" in inspect.signature(trajopt.plan).parameters


def test_options_give_the_keywords_plan(grid):
    opts = trajopt.PlannerOptions(robot=ROBOT, timing_dt=0.05, corridor="boxes")
    a = trajopt.plan(grid, START, GOAL, options=opts)
    b = trajopt.plan(grid, START, GOAL, ROBOT, timing_dt=0.05, corridor="boxes")
    c = trajopt.Planner(grid, options=opts).plan(START, GOAL)
    t = np.linspace(0.0, a.duration, 200)
    for other in (b, c):
        assert other.duration == a.duration
        np.testing.assert_array_equal(np.asarray(a.sample(t)), np.asarray(other.sample(t)))


@pytest.mark.parametrize("extra", [{"corridor": "boxes"}, {"timing_dt": 0.05}])
def test_options_and_keywords_together_are_refused(grid, extra):
    opts = trajopt.PlannerOptions(robot=ROBOT)
    with pytest.raises(InvalidInputError, match="either as options or as keywords"):
        trajopt.plan(grid, START, GOAL, options=opts, **extra)
    with pytest.raises(InvalidInputError, match="not both: got options and robot"):
        trajopt.Planner(grid, ROBOT, options=opts)
    with pytest.raises(InvalidInputError, match="options must be a trajopt.PlannerOptions"):
        trajopt.Planner(grid, options={"corridor": "boxes"})
