"""Fixtures of the re-planning tests: the paper scene and a planner driving SP -> A on it."""

from __future__ import annotations

import pytest

import trajopt


@pytest.fixture(scope="module")
def scene():
    return trajopt.scenes.paper()


@pytest.fixture(scope="module")
def driven(scene):
    """``(planner, trajectory)``: a default robot's plan SP -> A."""
    planner = trajopt.Planner(scene.grid, trajopt.Robot())
    return planner, planner.plan(scene.start, scene.goal("A"))
