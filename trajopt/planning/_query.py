"""One planning query as a record.

What was asked, what each stage produced, how long each stage took; and :class:`PlanSteps`, the
intermediate results a trajectory carries.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from astar.grid import OccupancyGrid
from trajopt.corridor import Corridor, PolygonCorridor


class StageTimer:
    """Wall time per stage (s), accumulated over every entry into the stage."""

    def __init__(self) -> None:
        self.t0 = time.perf_counter()
        self.stages: dict[str, float] = {}

    @contextmanager
    def stage(self, name: str) -> Iterator[None]:
        """Time the block (also when it raises) and add it to ``stages[name]``."""
        t = time.perf_counter()
        try:
            yield
        finally:
            self.stages[name] = self.stages.get(name, 0.0) + time.perf_counter() - t

    def elapsed(self) -> float:
        """Seconds since the query started."""
        return time.perf_counter() - self.t0

    def finish(self) -> dict[str, float]:
        """Record ``total`` and return the stages."""
        self.stages["total"] = self.elapsed()
        return self.stages


@dataclass
class PlanQuery:
    """A validated query and what the stages have produced so far.

    Attributes
    ----------
    start, goal : ndarray, shape (2,)
        Exact end points (m).
    start_cell, goal_cell : ndarray of int, shape (2,)
        Their cells ``(ix, iy)``.
    start_heading, goal_heading : float or None
        Exact end headings (rad).
    start_curvature : float or None
        Exact start curvature (1/m), from a :class:`~trajopt.robot._state.State`.
    v_start, v_end : float
        End speeds (m/s).
    a_start : float
        Start acceleration (m/s^2), from a :class:`~trajopt.robot._state.State`.
    inflated : OccupancyGrid or None
        The grid the robot centre moves in.
    path : astar.GridPath or None
        The grid path the corridor is built around (after a witness rescue, the path along
        the witness).
    corridor : PolygonCorridor or Corridor or None
        The corridor of the smooth path (or of the fallback's polyline).
    rescue : str or None
        ``"witness"`` when the curve came from the witness rescue.
    previous : PlanSteps or None
        A re-plan's old steps: the polygon corridor may keep their regions along the rest
        of the path it shares with them (:mod:`trajopt.corridor._polygons.reuse`).
    regions_kept : int
        How many regions of the result's polygon corridor are ``previous``'s.
    footprint : Footprint or None
        The footprint the smoother must also certify (a footprint robot's disc model).
    cost : astar.Costmap or None
        On a costmap searched by its cost: the costmap, whose normalised cost the smoother
        minimises with ``costmap_weight``.
    timer : StageTimer
    """

    start: np.ndarray
    goal: np.ndarray
    start_cell: np.ndarray
    goal_cell: np.ndarray
    start_heading: float | None = None
    goal_heading: float | None = None
    start_curvature: float | None = None
    v_start: float = 0.0
    v_end: float = 0.0
    a_start: float = 0.0
    inflated: OccupancyGrid | None = None
    path: Any = None
    corridor: PolygonCorridor | Corridor | None = None
    rescue: str | None = None
    previous: PlanSteps | None = None
    regions_kept: int = 0
    footprint: Any = None
    cost: Any = None  # the costmap whose graded cost the smoother minimises (or None)
    timer: StageTimer = field(default_factory=StageTimer)


@dataclass(frozen=True, slots=True)
class WarmStart:
    """What a re-plan hands the plan from the moving state (:mod:`trajopt.replan._replan`).

    Attributes
    ----------
    grid_path : astar.GridPath or None
        Used instead of a search when its end cells are the query's.
    previous : PlanSteps or None
        The re-planned trajectory's steps (:attr:`PlanQuery.previous`).
    """

    grid_path: Any = None
    previous: PlanSteps | None = None


@dataclass(frozen=True, slots=True)
class PlanSteps:
    """Every intermediate result of one :meth:`~trajopt._planner.Planner.plan` query.

    Attributes
    ----------
    raw_grid : astar.OccupancyGrid
        The map as given.
    inflated_grid : astar.OccupancyGrid
        The grid the robot centre moves in.
    grid_path : astar.GridPath
        The A* path on ``inflated_grid`` (after a witness rescue, the grid path along the
        witness: ``expanded`` 0, ``cost`` its length).
    corridor : PolygonCorridor or Corridor
        The corridor the smooth path was fitted in: convex polygons around the path
        (``corridor="polygons"``), or free boxes (end boxes widened to the exact
        start/goal) with ``corridor="boxes"`` or where the polygons failed.
    smooth_path : SmoothPath or None
        The certified B-spline; ``None`` when the planner returned the stop-and-turn
        fallback (the trajectory's ``path`` is then the polyline it drives).
    start, goal : tuple of float
        The query's end points (m).
    stages_s : dict of str to float
        Wall time of each stage (s): ``inflate``, ``search``, ``corridor``, ``smooth``,
        ``timing``, ``total``. ``inflate`` is ~0 when the planner's cache served it. With
        the fallback: ``fallback`` (checking and timing the polyline) and no ``timing``
        unless the timing was the stage that failed.
    start_heading, goal_heading : float or None
        The headings the query asked for at its ends (rad; ``None``: free). A re-plan to
        the same goal keeps ``goal_heading``.
    """

    raw_grid: OccupancyGrid
    inflated_grid: OccupancyGrid
    grid_path: Any
    corridor: PolygonCorridor | Corridor
    smooth_path: Any
    start: tuple[float, float]
    goal: tuple[float, float]
    stages_s: dict[str, float]
    start_heading: float | None = None
    goal_heading: float | None = None
