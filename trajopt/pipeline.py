"""One call from map to timed trajectory: :func:`plan`, and :class:`Planner` for many queries.

Stages (each timed in ``Trajectory.stats["stages_s"]``):

1. **inflate**: ``astar.inflate(grid, r, metric="square", outside_occupied=True)`` (the
   grid the corridor certifies against; GUIDE section 6). ``inflation="paper"`` adds the
   chapter's avoidance area (``W`` rounds of 8-neighbour marking, ``W = round(width/res)``)
   on top, so the result is never less safe than the certified inflation.
2. **search**: octile A* on the inflated grid; by default (``search="clearance"``) with
   the soft clearance cost of :func:`astar.clearance_cost`, which keeps paths off the walls;
   ``search="shortest"`` is the plain shortest path.
3. **corridor**: with ``corridor="polygons"`` (default, exact inflation)
   :func:`trajopt.polygon_corridor.build_polygon_corridor` around the polyline *exact start
   -> A* cell centres -> exact goal*; otherwise, and wherever the polygon corridor cannot be
   built or the fit in it fails, :func:`trajopt.build_corridor` (boxes). When the exact
   start or goal is not a cell centre, the end box is widened to contain it after an exact
   box-to-obstacle clearance check. ``stats["corridor"]`` names the corridor of the result;
   ``stages_s["corridor"]`` adds up the corridors built.
4. **smooth**: :class:`trajopt.Smoother` (certified clearance ``>= radius`` from the raw
   map, exact endpoints, continuous heading; the taut objective in polygons, the fidelity
   objective in boxes). **Witness rescue**: when the smoother has a
   curvature bound and fails along the A* path, the planner looks for a curvature-bounded
   path with :func:`trajopt.feasibility.curvature_witness` (first one keeping a cell more
   than the radius, then one with the exact radius), rebuilds the corridor around
   the grid path that follows it (:func:`trajopt.feasibility.witness_grid_path`) and fits
   again. Both tries share the smoother's ``time_budget_s``; ``stats["smoother"]["rescue"]``
   is ``"witness"`` when the second try gave the curve (``None`` otherwise), and
   ``steps.grid_path`` / ``steps.corridor`` are then the ones along the witness.
5. **timing**: :func:`trajopt.time_parameterize`.

The returned :class:`~trajopt.trajectory.Trajectory` carries every intermediate result in
``trajectory.steps`` (a :class:`PlanSteps`).

**Fallback** (opt-in, ``fallback="stop_and_turn"``). When the smoother raises
:class:`~trajopt.errors.SmoothingError` (after its own refinements), or the timing raises
:class:`~trajopt.errors.TimingError` on the smooth curve, and both end speeds are 0, the
planner returns a :class:`~trajopt.fallback.StopAndTurnTrajectory` instead: the polyline
*exact start -> centres of the A* path cells -> exact goal*, driven straight with a
rest-to-rest profile per segment and turning in place at rest at every corner (a
differential drive can do this; see :mod:`trajopt.fallback`). The A* moves between
adjacent free cells of the square-metric inflated grid without corner cutting keep the
centre at clearance ``>= radius``; the planner does not rely on that argument but checks the
polyline's exact distance to the raw map's obstacle squares (cells outside the map count
as occupied) and re-raises the original error if it is below the radius. The trajectory's
``stats`` hold ``fallback = "stop_and_turn"``, ``fallback_error`` (the exception's type),
``fallback_reason`` (its message) and ``fallback_min_clearance_m``; ``steps.smooth_path``
is ``None``. With ``v_start`` or ``v_end`` not 0 the original error is raised: a
stop-and-turn motion starts and ends at rest, so it could not honour those speeds.
"""

from __future__ import annotations

import dataclasses
import logging
import math
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

import astar
from astar.grid import OccupancyGrid
from trajopt.corridor import Box, Corridor, build_corridor
from trajopt.errors import InvalidInputError, NoPathError, SmoothingError, TimingError
from trajopt.fallback import StopAndTurnTrajectory, polyline_clearance, stop_and_turn
from trajopt.feasibility import curvature_witness, witness_grid_path
from trajopt.polygon_corridor import PolygonCorridor, build_polygon_corridor
from trajopt.robot import Robot
from trajopt.smoother import Smoother, SmoothPath
from trajopt.timing import time_parameterize
from trajopt.trajectory import Trajectory

__all__ = ["plan", "Planner", "PlanSteps", "Inflation", "Search", "Fallback", "PlanResult"]

logger = logging.getLogger(__name__)

Inflation = Literal["exact", "paper"]
Search = Literal["clearance", "shortest"]
Fallback = Literal["stop_and_turn"]
CorridorKind = Literal["polygons", "boxes"]
#: What :meth:`Planner.plan` returns: a smooth trajectory, or the stop-and-turn fallback.
PlanResult = Trajectory | StopAndTurnTrajectory
_INFLATIONS = ("exact", "paper")
_SEARCHES = ("clearance", "shortest")
_FALLBACKS = (None, "stop_and_turn")
_CORRIDORS = ("polygons", "boxes")


@dataclass(frozen=True, slots=True)
class PlanSteps:
    """Every intermediate result of one :meth:`Planner.plan` query.

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
    """

    raw_grid: OccupancyGrid
    inflated_grid: OccupancyGrid
    grid_path: Any
    corridor: PolygonCorridor | Corridor
    smooth_path: SmoothPath | None
    start: tuple[float, float]
    goal: tuple[float, float]
    stages_s: dict[str, float]


class Planner:
    """Plans timed trajectories on one map, caching what repeated queries share.

    The inflated grid and the clearance cost are computed once per planner; the smoother's
    built CasADi solvers are cached per problem size for the whole process.

    Parameters
    ----------
    grid : astar.OccupancyGrid
        The raw map.
    robot : Robot, optional
        Size and limits; default ``Robot()`` (the chapter's robot).
    inflation : {"exact", "paper"}
        ``"exact"``: obstacles grown by ``robot.radius`` (square metric, certified).
        ``"paper"``: the chapter's avoidance area of ``w_cells`` rounds on top of it.
    w_cells : int, optional
        ``W`` for ``inflation="paper"``; default ``round(robot.width / resolution)`` (11 on
        the paper scene).
    search : {"clearance", "shortest"}
        A* cost: clearance-aware (default) or plain shortest path.
    smoother : Smoother, optional
        Smoother options (e.g. ``Smoother(kappa_max=...)``); default ``Smoother()``.
    timing_dt : float
        Step of the timing's forward greedy (s).
    fallback : {None, "stop_and_turn"}
        ``None`` (default): smoother and timing failures raise. ``"stop_and_turn"``: when
        they fail and both end speeds are 0, return a
        :class:`~trajopt.fallback.StopAndTurnTrajectory` along the A* polyline, checked
        against the raw map (module docstring); ``stats["fallback"]`` says so.
    corridor : {"polygons", "boxes"}
        ``"polygons"`` (default): convex polygons grown around the A* path in continuous
        space (:func:`~trajopt.polygon_corridor.build_polygon_corridor`), with the taut
        objective; where the polygon corridor cannot be built or the fit in it fails, the
        box corridor is tried next (``stats["corridor"]`` names the one used).
        ``"boxes"``: axis-aligned boxes of free cells only (:func:`build_corridor`). With
        ``inflation="paper"`` the corridor is always boxes (the polygons keep the radius
        from the raw map, not from the chapter's avoidance area).

    Notes
    -----
    A planner may be shared between threads: queries are serialised by a lock (the CasADi
    solvers it reuses keep per-call work memory).
    """

    def __init__(
        self,
        grid: OccupancyGrid,
        robot: Robot | None = None,
        *,
        inflation: Inflation = "exact",
        w_cells: int | None = None,
        search: Search = "clearance",
        smoother: Smoother | None = None,
        timing_dt: float = 0.02,
        fallback: Fallback | None = None,
        corridor: CorridorKind = "polygons",
    ) -> None:
        if not isinstance(grid, OccupancyGrid):
            raise InvalidInputError(
                f"grid must be an astar.OccupancyGrid, got {type(grid).__name__}"
            )
        robot = Robot() if robot is None else robot
        if not isinstance(robot, Robot):
            raise InvalidInputError(f"robot must be a trajopt.Robot, got {type(robot).__name__}")
        if inflation not in _INFLATIONS:
            raise InvalidInputError(f"inflation must be one of {_INFLATIONS}, got {inflation!r}")
        if search not in _SEARCHES:
            raise InvalidInputError(f"search must be one of {_SEARCHES}, got {search!r}")
        if not (fallback is None or (isinstance(fallback, str) and fallback in _FALLBACKS)):
            raise InvalidInputError(f"fallback must be one of {_FALLBACKS}, got {fallback!r}")
        if not (isinstance(corridor, str) and corridor in _CORRIDORS):
            raise InvalidInputError(f"corridor must be one of {_CORRIDORS}, got {corridor!r}")
        if w_cells is None:
            w_cells = max(1, round(robot.width / grid.resolution))
        if isinstance(w_cells, bool) or not isinstance(w_cells, (int, np.integer)) or w_cells < 0:
            raise InvalidInputError(f"w_cells must be an integer >= 0, got {w_cells!r}")
        if (
            isinstance(timing_dt, bool)
            or not isinstance(timing_dt, (int, float, np.integer, np.floating))
            or not 0.0 < float(timing_dt) <= 0.5
        ):
            raise InvalidInputError(f"timing_dt must be a number in (0, 0.5] s, got {timing_dt!r}")
        smoother = Smoother() if smoother is None else smoother
        if not isinstance(smoother, Smoother):
            raise InvalidInputError(
                f"smoother must be a trajopt.Smoother, got {type(smoother).__name__}"
            )
        self.grid = grid
        self.robot = robot
        self.inflation: Inflation = inflation
        self.w_cells = int(w_cells)
        self.search: Search = search
        self.smoother = smoother
        self.timing_dt = float(timing_dt)
        self.fallback: Fallback | None = fallback
        self.corridor: CorridorKind = corridor
        self._lock = threading.RLock()
        self._inflated: OccupancyGrid | None = None
        self._cost: np.ndarray | None = None

    # -------------------------------------------------------------- caches
    @property
    def inflated_grid(self) -> OccupancyGrid:
        """The grid the robot centre moves in (computed once)."""
        with self._lock:
            if self._inflated is None:
                g = astar.inflate(
                    self.grid, self.robot.radius, metric="square", outside_occupied=True
                )
                if self.inflation == "paper":
                    area = astar.avoidance_area(self.grid, self.w_cells, border=True)
                    g = self.grid.with_occupied(g.occupied | area.occupied)
                self._inflated = g
            return self._inflated

    @property
    def search_cost(self) -> np.ndarray | None:
        """Per-cell A* cost (``None`` for ``search="shortest"``), computed once."""
        if self.search == "shortest":
            return None
        with self._lock:
            if self._cost is None:
                self._cost = astar.clearance_cost(
                    self.grid, self.robot.radius, outside_occupied=True
                )
            return self._cost

    # ---------------------------------------------------------------- query
    def plan(
        self,
        start: Sequence[float],
        goal: Sequence[float],
        *,
        start_heading: float | None = None,
        goal_heading: float | None = None,
        v_start: float = 0.0,
        v_end: float = 0.0,
    ) -> PlanResult:
        """Plan a timed trajectory from ``start`` to ``goal`` (world metres).

        Parameters
        ----------
        start, goal : sequence of float, shape (2,)
            End points ``(x, y)`` in metres.
        start_heading, goal_heading : float, optional
            Exact headings at the ends (rad).
        v_start, v_end : float
            Speeds at the ends (m/s).

        Returns
        -------
        Trajectory or StopAndTurnTrajectory
            With ``trajectory.steps`` (:class:`PlanSteps`) and per-stage wall times in
            ``trajectory.stats["stages_s"]``. A :class:`~trajopt.fallback.StopAndTurnTrajectory`
            (``stats["fallback"] == "stop_and_turn"``) only with the planner's ``fallback``
            option, when the smoother or the timing failed.

        Raises
        ------
        InvalidInputError
            Non-finite or malformed points, a point outside the map, on an obstacle or
            closer to one than the robot radius (the message gives the clearance found),
            start and goal in the same cell.
        NoPathError
            The goal cannot be reached on the inflated grid.
        SmoothingError, TimingError
            From the smoother or the timing (with their statistics); with the fallback
            enabled, only when ``v_start`` or ``v_end`` is not 0 or the A* polyline fails
            its clearance check.
        """
        with self._lock:
            return self._plan(start, goal, start_heading, goal_heading, v_start, v_end)

    def _plan(self, start, goal, start_heading, goal_heading, v_start, v_end) -> PlanResult:
        t0 = time.perf_counter()
        stages: dict[str, float] = {}
        p0 = _point("start", start)
        p1 = _point("goal", goal)
        c0 = self._check_endpoint("start", p0)
        c1 = self._check_endpoint("goal", p1)
        t = time.perf_counter()
        inflated = self.inflated_grid
        stages["inflate"] = time.perf_counter() - t
        for name, p, c in (("start", p0, c0), ("goal", p1, c1)):
            if inflated.occupied[c[1], c[0]]:
                raise InvalidInputError(
                    f"{name} {p.tolist()} m lies in cell {_cell(c)}, which is blocked by the "
                    f"inflation={self.inflation!r} avoidance area (robot radius "
                    f"{self.robot.radius} m); clearance of the cell centre "
                    f"{_clearance_of(self.grid, self.grid.cell_to_world(c)):.4g} m"
                )
        if tuple(c0) == tuple(c1):
            raise InvalidInputError(
                f"start {p0.tolist()} m and goal {p1.tolist()} m lie in the same cell "
                f"{_cell(c0)}; the planner needs them at least one cell apart"
            )
        t = time.perf_counter()
        cost = self.search_cost
        try:
            path = astar.find_path(inflated, tuple(c0), tuple(c1), cost=cost)
        except astar.NoPathError as exc:
            raise NoPathError(
                f"no path from start {p0.tolist()} m to goal {p1.tolist()} m for a robot of "
                f"radius {self.robot.radius} m (inflation={self.inflation!r}): {exc}"
            ) from exc
        stages["search"] = time.perf_counter() - t
        t = time.perf_counter()
        smooth = None
        rescue = None
        corridor = None
        try:
            try:
                corridor, smooth = self._corridor_fit(
                    self.smoother, inflated, path, p0, p1, start_heading, goal_heading, stages
                )
            except SmoothingError as exc:
                found = self._witness_rescue(exc, inflated, p0, p1, start_heading, goal_heading, t)
                if found is None:
                    raise
                path, corridor, smooth = found
                rescue = "witness"
            stages["smooth"] = time.perf_counter() - t - stages.get("corridor", 0.0)
            t = time.perf_counter()
            traj = time_parameterize(
                smooth, self.robot, v_start=v_start, v_end=v_end, dt=self.timing_dt
            )
            stages["timing"] = time.perf_counter() - t
        except (SmoothingError, TimingError) as exc:
            stages["smooth" if smooth is None else "timing"] = time.perf_counter() - t
            if self.fallback is None or v_start != 0.0 or v_end != 0.0:
                raise
            if corridor is None:
                corridor = self._box_corridor(inflated, path, p0, p1)
            return self._fallback(
                exc, path, inflated, corridor, p0, p1, start_heading, goal_heading, stages, t0
            )
        stages["total"] = time.perf_counter() - t0
        steps = PlanSteps(
            raw_grid=self.grid,
            inflated_grid=inflated,
            grid_path=path,
            corridor=corridor,
            smooth_path=smooth,
            start=(float(p0[0]), float(p0[1])),
            goal=(float(p1[0]), float(p1[1])),
            stages_s=stages,
        )
        stats = dict(traj.stats)
        stats["stages_s"] = dict(stages)
        stats["inflation"] = self.inflation
        stats["search"] = self.search
        stats["smoother"] = dict(smooth.stats)
        stats["smoother"]["rescue"] = rescue
        stats["corridor"] = "polygons" if isinstance(corridor, PolygonCorridor) else "boxes"
        return dataclasses.replace(traj, stats=stats, steps=steps)

    def _corridor_fit(self, smoother, inflated, path, p0, p1, start_heading, goal_heading,
                      stages=None):
        """Build the corridor and fit in it: polygons first (when chosen), then boxes.

        Returns ``(corridor, smooth_path)``; raises the box fit's ``SmoothingError`` (or
        ``InvalidInputError``) when every corridor failed. ``stages["corridor"]`` adds up
        the corridor builds (s)."""
        t_start = time.perf_counter()
        kinds = ["boxes"]
        if self.corridor == "polygons" and self.inflation == "exact":
            kinds.insert(0, "polygons")
        for i, kind in enumerate(kinds):
            last = i == len(kinds) - 1
            t = time.perf_counter()
            try:
                if kind == "polygons":
                    corridor = self._polygon_corridor(path, p0, p1)
                else:
                    corridor = self._box_corridor(inflated, path, p0, p1)
            except InvalidInputError as exc:
                if last:
                    raise
                logger.debug("%s corridor not built (%s); trying the next kind", kind, exc)
                continue
            finally:
                if stages is not None:
                    stages["corridor"] = stages.get("corridor", 0.0) + time.perf_counter() - t
            left = smoother.time_budget_s - (time.perf_counter() - t_start)
            try:
                if left <= 0:
                    raise SmoothingError("time budget exhausted before the box corridor", {})
                sm = smoother if i == 0 else dataclasses.replace(smoother, time_budget_s=left)
                return corridor, self._fit(sm, path, corridor, p0, p1, start_heading,
                                           goal_heading)
            except SmoothingError as exc:
                if last:
                    raise
                logger.debug("fit in the %s corridor failed (%s); trying the next kind",
                             kind, exc)
        raise AssertionError("unreachable")  # pragma: no cover

    def _polygon_corridor(self, path: Any, p0: np.ndarray, p1: np.ndarray) -> PolygonCorridor:
        """Polygons around the A* path, from the exact start to the exact goal."""
        centres = np.asarray(self.grid.cell_to_world(np.asarray(path.cells)), dtype=float)
        points = np.vstack([p0, centres.reshape(-1, 2)[1:-1], p1])
        return build_polygon_corridor(self.grid, points, self.robot.radius)

    def _box_corridor(self, inflated: OccupancyGrid, path: Any, p0: np.ndarray, p1: np.ndarray):
        # bridges (45-degree regions certified against the raw map) across diagonal gaps;
        # not with the chapter's avoidance area, which the curve must not enter either
        bridge_map = self.grid if self.inflation == "exact" else None
        corridor = build_corridor(inflated, path, radius=self.robot.radius, raw_grid=bridge_map)
        return _widen_end_boxes(corridor, self.grid, p0, p1, self.robot.radius)

    def _fit(self, smoother: Smoother, path, corridor, p0, p1, start_heading, goal_heading):
        return smoother.fit(
            path,
            corridor,
            raw_grid=self.grid,
            radius=self.robot.radius,
            start=p0,
            goal=p1,
            start_heading=start_heading,
            goal_heading=goal_heading,
        )

    def _witness_rescue(self, exc, inflated, p0, p1, start_heading, goal_heading, t_start):
        """The second try of a curvature-bounded fit, along a witness; ``None`` if none.

        A witness that keeps one cell more than the radius is tried first (its grid path
        stays off the inflated grid's edges, so the corridor has room to turn; its search
        is capped at 1 s), then one with the exact radius.
        """
        sm = self.smoother
        if sm.kappa_max is None:
            return None
        radius = self.robot.radius
        for margin, cap_s in ((self.grid.resolution, 1.0), (0.0, math.inf)):
            left = sm.time_budget_s - (time.perf_counter() - t_start)
            if left <= 0:
                return None
            witness = curvature_witness(
                self.grid, radius + margin, p0, p1, sm.kappa_max, time_limit_s=min(left, cap_s)
            )
            cells = None if witness is None else witness_grid_path(witness, inflated)
            if cells is None or len(cells) < 2:
                continue
            steps = np.abs(np.diff(cells, axis=0)).sum(axis=1)
            length = float(np.sum(np.where(steps == 2, np.sqrt(2.0), 1.0)))
            path = astar.GridPath(cells=cells, length=length, cost=length, expanded=0)
            left = sm.time_budget_s - (time.perf_counter() - t_start)
            if left <= 0:
                return None
            try:
                corridor, smooth = self._corridor_fit(
                    dataclasses.replace(sm, time_budget_s=left),
                    inflated, path, p0, p1, start_heading, goal_heading,
                )
            except (SmoothingError, InvalidInputError) as exc2:
                logger.debug("witness rescue (margin %g m) failed after %s: %s", margin, exc, exc2)
                continue
            return path, corridor, smooth
        return None

    def _fallback(
        self, exc, path, inflated, corridor, p0, p1, start_heading, goal_heading, stages, t0
    ) -> StopAndTurnTrajectory:
        """The stop-and-turn trajectory along the A* polyline, or ``exc`` re-raised."""
        t = time.perf_counter()
        grid = self.grid
        centres = np.asarray(grid.cell_to_world(np.asarray(path.cells)), dtype=float)
        points = np.vstack([p0, centres.reshape(-1, 2), p1])
        radius = self.robot.radius
        window = radius + 2.0 * float(grid.resolution)
        clearance = polyline_clearance(points, grid, window_m=window, outside_occupied=True)
        if clearance < radius - 1e-9:
            logger.warning(
                "stop_and_turn fallback rejected: the A* polyline comes %.6g m from an "
                "obstacle (radius %.6g m)",
                clearance,
                radius,
            )
            raise exc
        traj = stop_and_turn(
            points, self.robot, start_heading=start_heading, goal_heading=goal_heading
        )
        stages["fallback"] = time.perf_counter() - t
        stages["total"] = time.perf_counter() - t0
        logger.info("smoother/timing failed (%s); returned the stop_and_turn fallback", exc)
        steps = PlanSteps(
            raw_grid=grid,
            inflated_grid=inflated,
            grid_path=path,
            corridor=corridor,
            smooth_path=None,
            start=(float(p0[0]), float(p0[1])),
            goal=(float(p1[0]), float(p1[1])),
            stages_s=stages,
        )
        stats = dict(traj.stats)
        stats["fallback_error"] = type(exc).__name__
        stats["fallback_reason"] = str(exc)
        stats["fallback_min_clearance_m"] = float(clearance)
        stats["stages_s"] = dict(stages)
        stats["inflation"] = self.inflation
        stats["search"] = self.search
        if isinstance(exc, SmoothingError):
            stats["smoother"] = dict(exc.stats)
        return dataclasses.replace(traj, stats=stats, steps=steps)

    def _check_endpoint(self, name: str, p: np.ndarray) -> np.ndarray:
        grid = self.grid
        c = grid.world_to_cell(p)
        if not grid.in_bounds(c):
            ox, oy = grid.origin
            raise InvalidInputError(
                f"{name} {p.tolist()} m is outside the map "
                f"[{ox}, {ox + grid.width}] x [{oy}, {oy + grid.height}] m"
            )
        if grid.occupied[c[1], c[0]]:
            raise InvalidInputError(
                f"{name} {p.tolist()} m lies on an occupied cell {_cell(c)} of the map"
            )
        clr = _clearance_of(grid, p)
        if clr < self.robot.radius:
            raise InvalidInputError(
                f"{name} {p.tolist()} m is {clr:.4g} m from the nearest obstacle (or the map "
                f"edge); the robot needs at least its radius {self.robot.radius} m"
            )
        return c


def plan(
    grid: OccupancyGrid,
    start: Sequence[float],
    goal: Sequence[float],
    robot: Robot | None = None,
    *,
    start_heading: float | None = None,
    goal_heading: float | None = None,
    v_start: float = 0.0,
    v_end: float = 0.0,
    inflation: Inflation = "exact",
    search: Search = "clearance",
    smoother: Smoother | None = None,
    w_cells: int | None = None,
    fallback: Fallback | None = None,
    corridor: CorridorKind = "polygons",
) -> PlanResult:
    """Plan a timed, collision-free, smooth trajectory in one call.

    Runs inflate -> A* -> corridor -> smoother -> timing (module docstring). For repeated
    queries on one map use :class:`Planner`, which caches the inflated grid.

    Parameters
    ----------
    grid : astar.OccupancyGrid
        Raw map.
    start, goal : sequence of float, shape (2,)
        End points ``(x, y)`` in world metres.
    robot : Robot, optional
        Size and limits; default ``Robot()``.
    start_heading, goal_heading : float, optional
        Exact headings at the ends (rad).
    v_start, v_end : float
        Speeds at the ends (m/s).
    inflation, search, smoother, w_cells, corridor
        See :class:`Planner`.
    fallback : {None, "stop_and_turn"}
        Opt-in fallback when the smoother or the timing fails (see :class:`Planner` and the
        module docstring); default ``None``: the failure raises.

    Returns
    -------
    Trajectory or StopAndTurnTrajectory
        ``trajectory.steps`` holds every intermediate result (:class:`PlanSteps`); the
        second type only with ``fallback="stop_and_turn"`` (``stats["fallback"]``).

    Examples
    --------
    >>> import trajopt
    >>> scene = trajopt.scenes.paper()
    >>> traj = trajopt.plan(scene.grid, scene.start, scene.goal("A"))  # doctest: +SKIP
    >>> traj.duration  # doctest: +SKIP
    """
    planner = Planner(
        grid,
        robot,
        inflation=inflation,
        search=search,
        smoother=smoother,
        w_cells=w_cells,
        fallback=fallback,
        corridor=corridor,
    )
    return planner.plan(
        start,
        goal,
        start_heading=start_heading,
        goal_heading=goal_heading,
        v_start=v_start,
        v_end=v_end,
    )


# ------------------------------------------------------------------ helpers
def _point(name: str, value: Any) -> np.ndarray:
    try:
        p = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(
            f"{name} must be two numbers (x, y) in metres, got {value!r}"
        ) from exc
    if p.shape != (2,):
        raise InvalidInputError(f"{name} must be two numbers (x, y) in metres, got {value!r}")
    if not np.all(np.isfinite(p)):
        raise InvalidInputError(f"{name} must be finite, got {p.tolist()}")
    return p


def _cell(c: np.ndarray) -> tuple[int, int]:
    """A cell ``(ix, iy)`` as plain ints (for messages)."""
    return (int(c[0]), int(c[1]))


def _box_clearance(grid: OccupancyGrid, lo: np.ndarray, hi: np.ndarray) -> float:
    """Exact distance (m) from the box ``[lo, hi]`` to the nearest occupied square or the
    map's outside (which counts as occupied)."""
    ox, oy = grid.origin
    res = grid.resolution
    edge = min(lo[0] - ox, lo[1] - oy, ox + grid.width - hi[0], oy + grid.height - hi[1])
    if edge <= 0:
        return 0.0
    reach = edge  # nothing farther than the map edge matters
    c_lo = np.floor((lo - reach - (ox, oy)) / res).astype(int)
    c_hi = np.floor((hi + reach - (ox, oy)) / res).astype(int)
    x0, y0 = max(c_lo[0], 0), max(c_lo[1], 0)
    x1, y1 = min(c_hi[0], grid.nx - 1), min(c_hi[1], grid.ny - 1)
    iy, ix = np.nonzero(grid.occupied[y0 : y1 + 1, x0 : x1 + 1])
    if ix.size == 0:
        return float(edge)
    sx0 = ox + (ix + x0) * res
    sy0 = oy + (iy + y0) * res
    dx = np.maximum(0.0, np.maximum(sx0 - hi[0], lo[0] - (sx0 + res)))
    dy = np.maximum(0.0, np.maximum(sy0 - hi[1], lo[1] - (sy0 + res)))
    return float(min(edge, np.hypot(dx, dy).min()))


def _clearance_of(grid: OccupancyGrid, p: np.ndarray) -> float:
    p = np.asarray(p, dtype=float)
    return _box_clearance(grid, p, p)


def _widen_end_boxes(
    corridor: Corridor, raw: OccupancyGrid, p0: np.ndarray, p1: np.ndarray, radius: float
) -> Corridor:
    """Widen the first/last box to hold the exact start/goal, after an exact clearance check."""
    boxes = list(corridor.boxes)
    changed = False
    for name, idx, p in (("start", 0, p0), ("goal", len(boxes) - 1, p1)):
        b = boxes[idx]
        if b.contains(p):
            continue
        lo = np.minimum([b.xmin, b.ymin], p)
        hi = np.maximum([b.xmax, b.ymax], p)
        clr = _box_clearance(raw, lo, hi)
        if clr < radius:
            raise InvalidInputError(
                f"{name} {p.tolist()} m cannot join the corridor with clearance {radius} m: "
                f"the box joining it to the path comes {clr:.4g} m from an obstacle; move it "
                "towards free space or onto the centre of its cell"
            )
        boxes[idx] = Box(
            xmin=float(lo[0]),
            xmax=float(hi[0]),
            ymin=float(lo[1]),
            ymax=float(hi[1]),
            ix0=b.ix0,
            ix1=b.ix1,
            iy0=b.iy0,
            iy1=b.iy1,
        )
        changed = True
    if not changed:
        return corridor
    return dataclasses.replace(corridor, boxes=tuple(boxes))


def compare_method(ctx: Any) -> Any:
    """The proposed method as a :func:`trajopt.compare` row (registered as ``"proposed"``).

    Plans with :class:`Planner` on ``ctx.grid`` for a :class:`Robot` of radius
    ``ctx.robot_radius`` (default limits; options ``robot``, ``inflation``, ``search`` and
    ``smoother`` may be given through ``compare(..., options={"proposed": {...}})``) and
    adds the timed metrics of :func:`trajopt.metrics.trajectory_metrics` as extra columns.
    """
    from trajopt.comparison import MethodResult
    from trajopt.metrics import trajectory_metrics

    opts = ctx.options_for("proposed")
    robot = opts.pop("robot", None) or Robot(radius=ctx.robot_radius)
    t0 = time.perf_counter()
    traj = Planner(ctx.grid, robot, **opts).plan(ctx.start, ctx.goal)
    runtime = time.perf_counter() - t0
    timed = trajectory_metrics(traj, robot)
    extras = {
        k: timed[k]
        for k in ("duration_s", "ratio_v", "ratio_a", "ratio_jerk", "ratio_omega", "ratio_a_lat")
        if k in timed
    }
    attempts = traj.stats.get("smoother", {}).get("attempts")
    note = f"duration {traj.duration:.3g} s"
    if attempts:
        note += f", smoother attempts {attempts if isinstance(attempts, int) else len(attempts)}"
    return MethodResult(traj.path, True, note, runtime_s=runtime, extras=extras)
