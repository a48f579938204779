"""Tests of trajopt.planning: trajopt.plan and trajopt.Planner take the fields of trajopt.PlannerOptions as keywords, unchanged."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import astar
import trajopt
from tests.cases import door_grid
from trajopt.errors import InvalidInputError
from trajopt.planning._options import SETTINGS

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


#: A value other than the default for each setting (``speed_limits`` needs zones on the map:
#: its default stands in); the test below checks that this covers every field.
SAMPLE = {
    "robot": ROBOT,
    "inflation": "paper",
    "w_cells": 3,
    "search": "shortest",
    "smoother": trajopt.Smoother(kappa_max=2.0),
    "timing_dt": 0.05,
    "fallback": "stop_and_turn",
    "corridor": "boxes",
    "costmap_weight": 3.0,
    "speed_limits": None,
    "landmarks": 2,
    "search_mode": "exact",
    "search_bound": 2.0,
}


class _Stop(Exception):
    pass


def test_plan_and_planner_take_every_field_of_the_options(grid, monkeypatch):
    """The settings are the fields of ``PlannerOptions``, by name, in ``Planner`` and ``plan``
    alike: each keyword gives the options ``PlannerOptions`` makes of it."""
    names = [f.name for f in dataclasses.fields(trajopt.PlannerOptions)]
    assert sorted(SAMPLE) == sorted(names)
    assert SETTINGS == tuple(names)
    for name, value in SAMPLE.items():
        want = trajopt.PlannerOptions(**{name: value}).for_map(grid)[0]
        assert trajopt.Planner(grid, **{name: value}).options == want, name
    want = trajopt.PlannerOptions(**SAMPLE).for_map(grid)[0]
    rest = {k: v for k, v in SAMPLE.items() if k != "robot"}
    assert trajopt.Planner(grid, ROBOT, **rest).options == want
    assert trajopt.Planner(grid, options=trajopt.PlannerOptions(**SAMPLE)).options == want

    seen = []
    real = trajopt._planner.Planner

    class Spy(real):
        def plan(self, *args, **kwargs):
            seen.append((self.options, args, kwargs))
            raise _Stop

    monkeypatch.setattr(trajopt._planner, "Planner", Spy)
    with pytest.raises(_Stop):
        trajopt.plan(grid, START, GOAL, ROBOT, start_heading=0.5, v_end=0.0, **rest)
    options, args, kwargs = seen[-1]
    assert options == want and args == (START, GOAL)
    assert kwargs == {
        "start_heading": 0.5,
        "goal_heading": None,
        "v_start": 0.0,
        "v_end": 0.0,
        "start_steer": 0.0,
        "goal_steer": None,
    }


@pytest.mark.parametrize("call", ["Planner", "plan"])
def test_an_unknown_keyword_is_named_with_the_settings(grid, call):
    """A keyword that is no setting: a TypeError naming it and listing every setting."""
    with pytest.raises(TypeError) as err:
        if call == "Planner":
            trajopt.Planner(grid, ROBOT, timing_step=0.05)
        else:
            trajopt.plan(grid, START, GOAL, ROBOT, timing_step=0.05, start_heding=1.0)
    message = str(err.value)
    assert f"trajopt.{call}() got " in message and "'timing_step'" in message
    assert call == "Planner" or "'start_heding'" in message
    for f in dataclasses.fields(trajopt.PlannerOptions):
        assert f.name in message.rpartition("are: ")[2], f.name


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
    with pytest.raises(InvalidInputError, match="got options and robot, corridor, landmarks$"):
        trajopt.Planner(grid, ROBOT, options=opts, landmarks=2, corridor="boxes")


def test_options_with_keywords_at_their_defaults_are_taken(grid):
    """With ``options``, a keyword given at its field's default (``None`` for a default
    factory) is no conflict: the options are used as given."""
    opts = trajopt.PlannerOptions(robot=ROBOT, corridor="boxes")
    at_defaults = {
        f.name: (None if f.default is dataclasses.MISSING else f.default)
        for f in dataclasses.fields(trajopt.PlannerOptions)
        if f.name != "robot"
    }
    planner = trajopt.Planner(grid, None, options=opts, **at_defaults)
    assert planner.options == opts.for_map(grid)[0]
