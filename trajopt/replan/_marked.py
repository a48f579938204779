"""The record a re-routed plan carries: the static map its movers' marks were drawn on.

A plan re-routed around predicted movers (:func:`trajopt.moving.reroute`) is searched,
fitted and certified on a *marked* map: the planner's map with the movers' swept regions
added as occupied cells. Its :class:`~trajopt.planning.PlanSteps` hold that map
(``raw_grid``, ``inflated_grid``), so a later re-plan that compared it with the planner's
map would see the marks as "cells freed" and never keep the rest of the detour. The planner
records on such a plan which static map the marks were drawn on (:func:`record_marked`:
:class:`MarkedSteps`), and the re-plan's keep rules (:mod:`trajopt.replan._keep`) compare the
map of the re-plan with that static map (:func:`planned_on`): the marks stand for the old
predictions, which the re-plan's re-timing replaces by the new ones.
"""

from __future__ import annotations

import dataclasses
from typing import Any

from astar.grid import OccupancyGrid
from trajopt.planning import CarSteps, PlanSteps


@dataclasses.dataclass(frozen=True, slots=True)
class MarkedSteps(PlanSteps):
    """The steps of a plan made on a map with movers' swept regions marked.

    :class:`~trajopt.planning.PlanSteps` (``raw_grid`` and ``inflated_grid`` the marked map
    its grid path and corridor were made on), and the static map the marks were drawn on.

    Attributes
    ----------
    static_grid : astar.OccupancyGrid
        The planner's map the marks were added to (same shape, resolution and origin).
    static_inflated : astar.OccupancyGrid
        Its inflated grid (the search's graph on it).
    """

    static_grid: OccupancyGrid | None = None
    static_inflated: OccupancyGrid | None = None


@dataclasses.dataclass(frozen=True, slots=True)
class MarkedCarSteps(CarSteps):
    """The steps of a car's plan made on a map with movers' swept regions marked.

    :class:`~trajopt.planning.CarSteps` (``raw_grid`` the marked map, ``inflated_grid`` the
    car's search grid of it), and the static map the marks were drawn on. The car's search
    grid of the static map is not kept: a re-plan derives it
    (:func:`~trajopt.planning.car_search_grid`) only when its map differs from this one.

    Attributes
    ----------
    static_grid : astar.OccupancyGrid
        The planner's map the marks were added to (same shape, resolution and origin).
    """

    static_grid: OccupancyGrid | None = None


def planned_on(steps: Any) -> tuple[Any, Any]:
    """Return the static map a plan's steps were made on, and its inflated grid.

    A :class:`MarkedSteps`' ``static_grid`` and ``static_inflated``; a
    :class:`MarkedCarSteps`' ``static_grid`` and ``None`` (its search grid is derived where
    needed); otherwise the steps' ``raw_grid`` and ``inflated_grid`` (``None`` where the
    steps have none).
    """
    if isinstance(steps, MarkedSteps):
        return steps.static_grid, steps.static_inflated
    if isinstance(steps, MarkedCarSteps):
        return steps.static_grid, None
    return getattr(steps, "raw_grid", None), getattr(steps, "inflated_grid", None)


def record_marked(out: Any, grid: OccupancyGrid, inflated: OccupancyGrid) -> Any:
    """Return a fresh plan with every step made on another map than ``grid`` recorded as marked.

    ``out`` must come from a plan among movers made just now on the planner whose map is
    ``grid`` (inflated: ``inflated``): every :class:`~trajopt.planning.PlanSteps` in it (its
    own, its pieces', an omni base's translation's) whose ``raw_grid`` is not ``grid`` was
    then made on a map derived from ``grid`` with movers' regions marked, and becomes a
    :class:`MarkedSteps` naming ``grid``; a car's :class:`~trajopt.planning.CarSteps` so
    made becomes a :class:`MarkedCarSteps`. Steps already marked and pieces without steps
    are left as they are; ``out`` itself when nothing changes.

    Parameters
    ----------
    out : PlanResult
        The plan (a Trajectory, TrajectoryChain, OmniTrajectory, ...).
    grid : astar.OccupancyGrid
        The planner's map when ``out`` was planned.
    inflated : astar.OccupancyGrid
        Its inflated grid.
    """
    changes: dict[str, Any] = {}
    steps = getattr(out, "steps", None)
    if (
        type(steps) is PlanSteps
        and steps.raw_grid is not grid
        and steps.raw_grid.occupied.shape == grid.occupied.shape
    ):
        fields = {f.name: getattr(steps, f.name) for f in dataclasses.fields(PlanSteps)}
        changes["steps"] = MarkedSteps(**fields, static_grid=grid, static_inflated=inflated)
    elif (
        type(steps) is CarSteps
        and steps.raw_grid is not grid
        and steps.raw_grid.occupied.shape == grid.occupied.shape
    ):
        fields = {f.name: getattr(steps, f.name) for f in dataclasses.fields(CarSteps)}
        changes["steps"] = MarkedCarSteps(**fields, static_grid=grid)
    pieces = getattr(out, "pieces", None)
    if pieces is not None:
        new = tuple(record_marked(p, grid, inflated) for p in pieces)
        if any(a is not b for a, b in zip(new, pieces, strict=True)):
            changes["pieces"] = new
    translation = getattr(out, "translation", None)
    if translation is not None:
        new_translation = record_marked(translation, grid, inflated)
        if new_translation is not translation:
            changes["translation"] = new_translation
    return dataclasses.replace(out, **changes) if changes else out
