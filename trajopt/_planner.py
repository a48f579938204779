"""One call from map to timed trajectory: :func:`plan`, and :class:`Planner` for many queries.

Stages (each timed in ``Trajectory.stats["stages_s"]``):

1. **inflate**: ``astar.inflate(grid, r, metric="square", outside_occupied=True)`` (the
   grid the corridor certifies against; ``docs/concepts.md``). ``inflation="paper"`` adds the
   chapter's avoidance area (``W`` rounds of 8-neighbour marking, ``W`` from
   :func:`trajopt.robot._robot.avoidance_width`)
   on top, so the result is never less safe than the certified inflation.
2. **search**: octile A* on the inflated grid; by default (``search="clearance"``) with
   the soft clearance cost of :func:`astar.clearance_cost`, which keeps paths off the walls;
   ``search="shortest"`` is the plain shortest path. A costmap given as the map
   (:class:`astar.Costmap`) is searched with its graded cost (``search="costmap"``, or
   ``"costmap+clearance"`` for both); its obstacle cells are what is inflated above.
3. **corridor**: with ``corridor="polygons"`` (default, exact inflation)
   :func:`trajopt.corridor.build_polygon_corridor` around the polyline *exact start
   -> A* cell centres -> exact goal* (a re-plan keeps the old corridor's regions along the
   rest of the path the two share: ``stats["corridor_regions_kept"]``); otherwise, and
   wherever the polygon corridor cannot be built or the fit in it fails,
   :func:`trajopt.build_corridor` (boxes), its end boxes widened to the exact start and
   goal after an exact clearance check. ``stats["corridor"]`` names the result's corridor.
4. **smooth**: :class:`trajopt.Smoother` (certified clearance ``>= radius`` from the raw
   map, exact endpoints, continuous heading; the taut objective in polygons, the fidelity
   objective in boxes). **Witness rescue**: when the smoother has a
   curvature bound and fails along the A* path, the planner looks for a curvature-bounded
   path with :func:`trajopt.planning._feasibility.curvature_witness` (first one keeping a cell more
   than the radius, then one with the exact radius), rebuilds the corridor around
   the grid path that follows it (:func:`trajopt.planning._feasibility.witness_grid_path`) and fits
   again. Both tries share the smoother's ``time_budget_s``; ``stats["smoother"]["rescue"]``
   is ``"witness"`` when the second try gave the curve (``None`` otherwise), and
   ``steps.grid_path`` / ``steps.corridor`` are then the ones along the witness.
5. **timing**: :func:`trajopt.time_parameterize`, with the planner's speed-limit zones
   (:class:`~trajopt.timing._speed_limits.SpeedLimits`) when it has them.

The :class:`~trajopt.motion._trajectory.Trajectory` carries every stage's result in ``.steps``.

**Fallback** (opt-in, ``fallback="stop_and_turn"``). When the smoother raises
:class:`~trajopt.errors.SmoothingError` (after its own refinements), or the timing raises
:class:`~trajopt.errors.TimingError` on the smooth curve, and both end speeds are 0, the
planner returns a :class:`~trajopt.motion._stop_and_turn.StopAndTurnTrajectory` instead: the polyline
*exact start -> centres of the A* path cells -> exact goal*, driven straight with a
rest-to-rest profile per segment and turning in place at rest at every corner (a
differential drive can do this; see :mod:`trajopt.timing._stop_and_turn`). The A* moves between
adjacent free cells of the square-metric inflated grid without corner cutting keep the
centre at clearance ``>= radius``; the planner still checks the polyline's exact distance to
the raw map (the outside counts as occupied) and re-raises the error below the radius.
``stats``: ``fallback = "stop_and_turn"``, ``fallback_error`` (the exception's type),
``fallback_reason`` (its message), ``fallback_min_clearance_m``; no ``steps.smooth_path``. With an end speed not 0 the error is raised (the fallback is rest to rest).
"""

from __future__ import annotations

import collections
import dataclasses
import threading
import time
from collections.abc import Sequence
from typing import Any, Literal

import numpy as np

import astar
from astar.costmap import Costmap
from astar.grid import OccupancyGrid
from trajopt._validation import integer, point
from trajopt.corridor import PolygonCorridor
from trajopt.errors import InvalidInputError, NoPathError, SmoothingError, TimingError
from trajopt.geometry._clearance import polygon_clearance
from trajopt.motion._chain import TrajectoryChain
from trajopt.motion._stop_and_turn import StopAndTurnTrajectory
from trajopt.motion._trajectory import Trajectory
from trajopt.planning._caches import update_caches
from trajopt.planning._corridor_fit import fit_in_corridor, witness_rescue
from trajopt.planning._fallback import polyline_fallback
from trajopt.planning._footprint_ladder import plan_with_footprint
from trajopt.planning._query import PlanQuery, PlanSteps
from trajopt.replan._replan import BRAKE_AFTER_S, replan_from, smooth_for_speed
from trajopt.robot._robot import Robot, avoidance_width
from trajopt.robot._state import State
from trajopt.smoother import Smoother, SmoothPath
from trajopt.timing import time_parameterize
from trajopt.timing._speed_limits import SpeedLimits, check_overlap

Inflation = Literal["exact", "paper"]
Search = Literal["clearance", "shortest", "costmap", "costmap+clearance"]
Fallback = Literal["stop_and_turn"]
CorridorKind = Literal["polygons", "boxes"]
#: What :meth:`Planner.plan` returns: a smooth trajectory, or the stop-and-turn fallback.
PlanResult = Trajectory | StopAndTurnTrajectory
_INFLATIONS = ("exact", "paper")
_SEARCHES = ("clearance", "shortest", "costmap", "costmap+clearance")
_FALLBACKS = (None, "stop_and_turn")
_CORRIDORS = ("polygons", "boxes")


class Planner:
    """Plans timed trajectories on one map, caching what repeated queries share.

    The inflated grid and the clearance cost are computed once per planner; the smoother's
    built CasADi solvers are cached per problem size for the whole process.

    Parameters
    ----------
    grid : astar.OccupancyGrid or astar.Costmap
        The raw map, or a costmap (:func:`astar.load_costmap`, :func:`astar.from_costmap`):
        its obstacle cells are the map (inflated and certified against as any map) and its
        graded cost feeds the search (``search="costmap"``, the default for a costmap).
    robot : Robot, optional
        Size and limits; default ``Robot()`` (the chapter's robot).
    inflation : {"exact", "paper"}
        ``"exact"``: obstacles grown by ``robot.radius`` (square metric, certified).
        ``"paper"``: the chapter's avoidance area of ``w_cells`` rounds on top of it.
    w_cells : int, optional
        ``W`` for ``inflation="paper"``; default :func:`~trajopt.robot._robot.avoidance_width`
        (11 on the paper scene).
    search : {"clearance", "shortest", "costmap", "costmap+clearance"}, optional
        A* cost: clearance-aware (:func:`astar.clearance_cost`; the default for an
        occupancy grid), plain shortest path, the costmap's graded cost
        (:meth:`astar.Costmap.search_cost` with ``costmap_weight``; the default for a
        costmap) or the sum of both. The costmap modes need ``grid`` to be a costmap.
    costmap_weight : float, optional
        ``weight`` of :meth:`astar.Costmap.search_cost` (default 2: a step through the
        costliest graded cells costs three times its length).
    speed_limits : SpeedLimits, optional
        Speed-limit zones (:func:`trajopt.load_speed_mask`): the timing caps the speed by the
        zone under the robot's centre (and the stop-and-turn fallback by the zones its
        segments cross). The mask is looked up in world coordinates with its own resolution
        and origin; a mask that does not overlap the map at all is refused.
    landmarks : int, optional
        ALT landmarks for the searches with a cost (:func:`astar.build_landmarks`; 0, the
        default: none). Exact either way; on large maps they cut a long search several
        times, for a one-time cost on the first query after each map (about 0.1 s per
        landmark per million cells; :meth:`update_map` keeps them through changes that only
        add obstacles) and ``8 landmarks`` bytes per cell.
    smoother : Smoother, optional
        Smoother options (e.g. ``Smoother(kappa_max=...)``); default ``Smoother()``.
    timing_dt : float
        Step of the timing's forward greedy (s).
    fallback : {None, "stop_and_turn"}
        ``None`` (default): smoother and timing failures raise. ``"stop_and_turn"``: when
        they fail and both end speeds are 0, return a
        :class:`~trajopt.motion._stop_and_turn.StopAndTurnTrajectory` along the A* polyline, checked
        against the raw map (module docstring); ``stats["fallback"]`` says so.
    corridor : {"polygons", "boxes"}
        ``"polygons"`` (default): convex polygons grown around the A* path in continuous
        space (:func:`~trajopt.corridor.build_polygon_corridor`), with the taut
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
        search: Search | None = None,
        smoother: Smoother | None = None,
        timing_dt: float = 0.02,
        fallback: Fallback | None = None,
        corridor: CorridorKind = "polygons",
        costmap_weight: float = 2.0,
        speed_limits: SpeedLimits | None = None,
        landmarks: int = 0,
    ) -> None:
        costmap: Costmap | None = None
        if isinstance(grid, Costmap):
            costmap, grid = grid, grid.grid
        if not isinstance(grid, OccupancyGrid):
            raise InvalidInputError(
                f"grid must be an astar.OccupancyGrid or astar.Costmap, got {type(grid).__name__}"
            )
        if search is None:
            search = "clearance" if costmap is None else "costmap"
        robot = Robot() if robot is None else robot
        if not isinstance(robot, Robot):
            raise InvalidInputError(f"robot must be a trajopt.Robot, got {type(robot).__name__}")
        if inflation not in _INFLATIONS:
            raise InvalidInputError(f"inflation must be one of {_INFLATIONS}, got {inflation!r}")
        if search not in _SEARCHES:
            raise InvalidInputError(f"search must be one of {_SEARCHES}, got {search!r}")
        if search.startswith("costmap") and costmap is None:
            raise InvalidInputError(
                f"search={search!r} needs the grid to be an astar.Costmap "
                "(astar.load_costmap / astar.from_costmap), got an OccupancyGrid"
            )
        if costmap is not None:
            costmap.search_cost(costmap_weight)  # validates the weight
        if speed_limits is not None:
            check_overlap(speed_limits, grid)
        if not (fallback is None or (isinstance(fallback, str) and fallback in _FALLBACKS)):
            raise InvalidInputError(f"fallback must be one of {_FALLBACKS}, got {fallback!r}")
        if not (isinstance(corridor, str) and corridor in _CORRIDORS):
            raise InvalidInputError(f"corridor must be one of {_CORRIDORS}, got {corridor!r}")
        landmarks = integer("landmarks", landmarks, 0, 64)
        if w_cells is None:
            w_cells = avoidance_width(robot.width, grid.resolution)
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
        self.costmap = costmap
        self.costmap_weight = float(costmap_weight)
        self.speed_limits = speed_limits
        self.landmarks = int(landmarks)
        self._landmarks: astar.Landmarks | None = None  # built on the first search that uses them
        self._lock = threading.RLock()
        self._latencies: collections.deque[float] = collections.deque(maxlen=32)
        self._inflated: OccupancyGrid | None = None
        self._cost: np.ndarray | None = None
        self._disc_planners: dict[float, Planner] = {}  # footprint robots: the disc models
        #: optional ``(planner, query) -> (grid path, inflated grid)`` run after the search
        #: (a footprint robot's oriented check of the grid path)
        self.path_check: Any = None
        #: a footprint robot's disc model: the footprint its smoother must also certify
        self.smoothing_footprint: Any = None

    # -------------------------------------------------------------- caches
    @property
    def inflated_grid(self) -> OccupancyGrid:
        """The grid the robot centre moves in (computed once per map)."""
        with self._lock:
            if self._inflated is None:
                self._inflated = self.grid.with_occupied(self._inflate(self.grid))
            return self._inflated

    @property
    def search_cost(self) -> np.ndarray | None:
        """Per-cell A* cost (``None`` for ``search="shortest"``), computed once per map."""
        if self.search == "shortest":
            return None
        with self._lock:
            if self._cost is None:
                cost = self._clearance_cost(self.grid)
                if self.costmap is not None and self.search.startswith("costmap"):
                    cost += self.costmap.search_cost(self.costmap_weight)
                self._cost = cost
            return self._cost

    @property
    def search_landmarks(self) -> astar.Landmarks | None:
        """ALT landmarks of the inflated grid and search cost (``None`` without), built once."""
        if self.landmarks == 0 or self.search == "shortest":
            return None
        with self._lock:
            if self._landmarks is None:
                self._landmarks = astar.build_landmarks(self.inflated_grid, self.search_cost,
                                                        self.landmarks)  # fmt: skip
            return self._landmarks

    def _inflate(self, grid: OccupancyGrid) -> np.ndarray:
        occ = astar.inflate(grid, self.robot.radius, metric="square", outside_occupied=True)
        out = occ.occupied
        if self.inflation == "paper":
            out = out | astar.avoidance_area(grid, self.w_cells, border=True).occupied
        return out

    def _clearance_cost(self, grid: OccupancyGrid) -> np.ndarray:
        cost = np.zeros(grid.shape)
        if self.search in ("clearance", "costmap+clearance"):
            cost += astar.clearance_cost(grid, self.robot.radius, outside_occupied=True)
        return cost

    def update_map(self, grid: OccupancyGrid) -> dict[str, Any]:
        """Replace the raw map, recomputing the caches only where the change reaches.

        The inflated grid and the clearance cost depend on the map only within the robot
        radius (plus the avoidance area and the cost's fall-off) of each cell, so they are
        recomputed in the box around the changed cells grown by that reach (on a window
        grown once more, whose made-up outside then cannot reach the box); everything else
        is kept. A map of another shape, resolution or origin resets the caches. Search
        landmarks, if any, are kept when the change only adds obstacles (their bounds stay
        exact lower bounds, :meth:`astar.Landmarks.rebase`) and dropped otherwise (the next
        search builds them again).

        Parameters
        ----------
        grid : astar.OccupancyGrid
            The updated raw map.

        Returns
        -------
        dict
            ``changed_cells`` and ``window`` (``(x0, x1, y0, y1)`` cells, inclusive, or
            ``None``) of the recomputed box; ``reset`` when the caches were dropped;
            ``landmarks``: ``"kept"``, ``"rebased"``, ``"dropped"`` or ``None`` (none built).

        Raises
        ------
        InvalidInputError
            ``grid`` is not an OccupancyGrid, or the planner plans on a costmap (make a new
            :class:`Planner` from the new costmap).
        """
        return update_caches(self, grid)

    # ---------------------------------------------------------------- query
    def plan(
        self,
        start: Sequence[float] | State,
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
        start : sequence of float, shape (2,), or State
            Start point ``(x, y)`` in metres, or a moving robot's :class:`~trajopt.robot._state.State`:
            the curve then starts at its position with its heading and curvature (C2 at the
            splice) and the timing at its speed and acceleration (``start_heading`` and
            ``v_start`` must then be left at their defaults).
        goal : sequence of float, shape (2,)
            End point ``(x, y)`` in metres.
        start_heading, goal_heading : float, optional
            Exact headings at the ends (rad).
        v_start, v_end : float
            Speeds at the ends (m/s).

        Returns
        -------
        Trajectory or StopAndTurnTrajectory
            With ``trajectory.steps`` (:class:`PlanSteps`) and per-stage wall times in
            ``trajectory.stats["stages_s"]``. A :class:`~trajopt.motion._stop_and_turn.StopAndTurnTrajectory`
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
        return self._query(start, goal, start_heading, goal_heading, v_start, v_end, None)

    def _query(self, start, goal, start_heading, goal_heading, v_start, v_end, warm):
        """:meth:`plan`, with a re-plan's :class:`~trajopt.planning._query.WarmStart` (or ``None``)."""
        with self._lock:
            t0 = time.perf_counter()
            if self.robot.footprint is not None:
                out = plan_with_footprint(self, start, goal, start_heading=start_heading,
                                          goal_heading=goal_heading, v_start=v_start,
                                          v_end=v_end)  # fmt: skip
            else:
                out = self._plan(start, goal, start_heading, goal_heading, v_start, v_end,
                                 warm)  # fmt: skip
            self._latencies.append(time.perf_counter() - t0)
            return out

    @property
    def latency_s(self) -> float:
        """Median wall time (s) of this planner's recent queries (0 before the first)."""
        with self._lock:
            return float(np.median(self._latencies)) if self._latencies else 0.0

    def replan(
        self,
        trajectory: PlanResult,
        t: float,
        goal: Sequence[float] | None = None,
        grid: OccupancyGrid | None = None,
        *,
        latency: float | None = None,
        goal_heading: float | None = None,
        v_end: float = 0.0,
        reuse: bool = True,
        brake_after_s: float | None = BRAKE_AFTER_S,
    ) -> PlanResult | TrajectoryChain:
        """Re-plan from a trajectory being driven, splicing at ``t + latency``.

        The new trajectory starts at ``trajectory.state_at(t + latency)``: the same
        position, heading, curvature, speed and acceleration (a C2 splice), so a robot can
        switch to it at that time without a jump. Its ``stats["splice_time_s"]`` is the
        splice time on the old trajectory's clock, ``stats["latency_s"]`` the latency used,
        ``stats["replan"]`` ``"kept"``, ``"planned: <why the rest was not kept>"`` or
        ``"braked: <why no smooth plan>"``.

        What it keeps of the old trajectory, what it reuses and when it brakes instead:
        :mod:`trajopt.replan._replan`.

        Parameters
        ----------
        trajectory : Trajectory, StopAndTurnTrajectory or TrajectoryChain
            The trajectory being driven.
        t : float
            Its current time (s).
        goal : sequence of float, shape (2,), optional
            A new goal (m); default the old one (``trajectory.steps.goal``).
        grid : astar.OccupancyGrid, optional
            An updated map; it becomes the planner's map (:meth:`update_map`, which
            recomputes the caches only where the change reaches).
        latency : float, optional
            Time (s) the re-plan is expected to take: the splice is that far ahead. Default
            :attr:`latency_s`, the median of this planner's recent queries.
        goal_heading : float, optional
            Exact heading at the goal (rad).
        v_end : float, optional
            Speed at the goal (m/s).
        reuse : bool, optional
            ``False``: plan anew from the state, keeping nothing of the old plan.
        brake_after_s : float or None, optional
            Smoothing time (s) before the robot brakes instead; ``None``: never brake.

        Raises
        ------
        InvalidInputError
            ``t + latency`` outside ``[0, duration]``, a negative latency, no goal given
            for a trajectory without ``steps``.
        TimingError, SmoothingError, NoPathError
            As :meth:`plan`; ``TimingError``: it must brake and cannot stop in time.
        """
        with self._lock:
            return replan_from(self, trajectory, t, goal, grid, latency=latency,
                               goal_heading=goal_heading, v_end=v_end, reuse=reuse,
                               brake_after_s=brake_after_s)  # fmt: skip

    def _plan(self, start, goal, start_heading, goal_heading, v_start, v_end,
              warm=None) -> PlanResult:  # fmt: skip
        kappa0 = None
        a0 = 0.0
        if isinstance(start, State):
            if start_heading is not None or v_start != 0.0:
                raise InvalidInputError(
                    "start is a State: its theta and v are the start heading and speed; "
                    f"leave start_heading (got {start_heading!r}) and v_start (got "
                    f"{v_start!r}) at their defaults"
                )
            start_heading, kappa0, v_start, a0 = start.theta, start.kappa, start.v, start.a
            start = start.position
        p0 = point("start", start)
        p1 = point("goal", goal)
        q = PlanQuery(
            start=p0,
            goal=p1,
            start_cell=self._check_endpoint("start", p0),
            goal_cell=self._check_endpoint("goal", p1),
            start_heading=start_heading,
            goal_heading=goal_heading,
            start_curvature=kappa0,
            v_start=v_start,
            v_end=v_end,
            a_start=a0,
            previous=None if warm is None else warm.previous,
        )
        with q.timer.stage("inflate"):
            q.inflated = self.inflated_grid
        self._check_reachable_ends(q)
        ends = [q.start_cell, q.goal_cell]
        grid_path = None if warm is None else warm.grid_path
        reused = grid_path is not None and np.array_equal(grid_path.cells[[0, -1]], ends)
        with q.timer.stage("search"):
            q.path = grid_path if reused else self._search(q)
            if self.path_check is not None:
                q.path, q.inflated = self.path_check(self, q)
        smooth = None
        try:
            smooth = self._smooth(q)
            try:
                traj = self._time(q, smooth)
            except TimingError:
                if v_start <= 0.0:
                    raise
                smooth = smooth_for_speed(self, q)
                traj = self._time(q, smooth)
        except (SmoothingError, TimingError) as exc:
            if self.fallback is None or v_start != 0.0 or v_end != 0.0 or q.a_start != 0.0:
                raise
            return self._fallback(q, exc)
        smoother_stats = dict(smooth.stats)
        smoother_stats["rescue"] = q.rescue
        kind = "polygons" if isinstance(q.corridor, PolygonCorridor) else "boxes"
        return self._result(q, traj, smooth, smoother=smoother_stats, corridor=kind,
                            grid_path="reused" if reused else "searched",
                            corridor_regions_kept=q.regions_kept)  # fmt: skip

    def _search(self, q: PlanQuery) -> astar.GridPath:
        """Return the A* path of the query on the inflated grid (typed error without one)."""
        try:
            lms = self.search_landmarks
            return astar.find_path(
                q.inflated, _cell(q.start_cell), _cell(q.goal_cell),
                cost=self.search_cost if lms is None else None, landmarks=lms,
            )  # fmt: skip
        except astar.NoPathError as exc:
            raise NoPathError(
                f"no path from start {q.start.tolist()} m to goal {q.goal.tolist()} m for a "
                f"robot of radius {self.robot.radius} m (inflation={self.inflation!r}): {exc}"
            ) from exc

    def _time(self, q: PlanQuery, smooth: SmoothPath) -> Trajectory:
        with q.timer.stage("timing"):
            return time_parameterize(smooth, self.robot, v_start=q.v_start, v_end=q.v_end,
                                     dt=self.timing_dt, speed_limits=self.speed_limits,
                                     a_start=q.a_start)  # fmt: skip

    def _smooth(self, q: PlanQuery) -> SmoothPath:
        """Return the corridor and the certified curve.

        The corridor and the certified curve (``q.path``, ``q.corridor``), with the witness
        rescue of a curvature-bounded fit.
        """
        t_start = time.perf_counter()
        try:
            q.corridor, smooth = fit_in_corridor(self, q, q.path, self.smoother)
        except SmoothingError as exc:
            q.path, q.corridor, smooth = witness_rescue(self, q, exc, t_start)
            q.rescue = "witness"
        return smooth

    def _check_reachable_ends(self, q: PlanQuery) -> None:
        for name, p, c in (("start", q.start, q.start_cell), ("goal", q.goal, q.goal_cell)):
            if q.inflated.occupied[c[1], c[0]]:
                raise InvalidInputError(
                    f"{name} {p.tolist()} m lies in cell {_cell(c)}, which is blocked by the "
                    f"inflation={self.inflation!r} avoidance area (robot radius "
                    f"{self.robot.radius} m); clearance of the cell centre "
                    f"{_point_clearance(self.grid, self.grid.cell_to_world(c)):.4g} m"
                )
        if tuple(q.start_cell) == tuple(q.goal_cell):
            raise InvalidInputError(
                f"start {q.start.tolist()} m and goal {q.goal.tolist()} m lie in the same cell "
                f"{_cell(q.start_cell)}; the planner needs them at least one cell apart"
            )

    def _result(self, q: PlanQuery, traj: Any, smooth: SmoothPath | None, **extra: Any) -> Any:
        """Return the one place that attaches :class:`PlanSteps` and the planner's statistics."""
        stages = q.timer.finish()
        steps = PlanSteps(
            raw_grid=self.grid,
            inflated_grid=q.inflated,
            grid_path=q.path,
            corridor=q.corridor,
            smooth_path=smooth,
            start=(float(q.start[0]), float(q.start[1])),
            goal=(float(q.goal[0]), float(q.goal[1])),
            stages_s=stages,
        )
        stats = dict(traj.stats)
        stats.update(extra)
        stats["stages_s"] = dict(stages)
        stats["inflation"] = self.inflation
        stats["search"] = self.search
        return dataclasses.replace(traj, stats=stats, steps=steps)

    def _fallback(self, q: PlanQuery, exc: Exception) -> StopAndTurnTrajectory:
        """Return the stop-and-turn trajectory along the A* polyline, or ``exc`` re-raised."""
        with q.timer.stage("fallback"):
            traj, extra = polyline_fallback(self, q, exc)
        return self._result(q, traj, None, **extra)

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
        clr = _point_clearance(grid, p)
        if clr < self.robot.radius:
            raise InvalidInputError(
                f"{name} {p.tolist()} m is {clr:.4g} m from the nearest obstacle (or the map "
                f"edge); the robot needs at least its radius {self.robot.radius} m"
            )
        return c


def plan(
    grid: OccupancyGrid | Costmap,
    start: Sequence[float],
    goal: Sequence[float],
    robot: Robot | None = None,
    *,
    start_heading: float | None = None,
    goal_heading: float | None = None,
    v_start: float = 0.0,
    v_end: float = 0.0,
    inflation: Inflation = "exact",
    search: Search | None = None,
    smoother: Smoother | None = None,
    w_cells: int | None = None,
    fallback: Fallback | None = None,
    corridor: CorridorKind = "polygons",
    costmap_weight: float = 2.0,
    speed_limits: SpeedLimits | None = None,
    timing_dt: float = 0.02,
    landmarks: int = 0,
) -> PlanResult:
    """Plan a timed, collision-free, smooth trajectory in one call.

    Runs inflate -> A* -> corridor -> smoother -> timing (module docstring). For repeated
    queries on one map use :class:`Planner`, which caches the inflated grid.

    Parameters
    ----------
    grid : astar.OccupancyGrid or astar.Costmap
        Raw map, or a costmap (see :class:`Planner`).
    start, goal : sequence of float, shape (2,)
        End points ``(x, y)`` in world metres.
    robot : Robot, optional
        Size and limits; default ``Robot()``.
    start_heading, goal_heading : float, optional
        Exact headings at the ends (rad).
    v_start, v_end : float
        Speeds at the ends (m/s).
    inflation, search, smoother, w_cells, corridor, costmap_weight, speed_limits
        See :class:`Planner`.
    timing_dt : float
        Step of the timing's forward greedy (s), in (0, 0.5]; default 0.02 (see
        :class:`Planner`).
    landmarks : int, optional
        ALT landmarks for the searches with a cost (:func:`astar.build_landmarks`), 0-64;
        0, the default: none (see :class:`Planner`). Exact either way. Each call builds
        them for its one query (``landmarks + 1`` searches of the whole map), which costs
        more than the search they shorten; they pay off across the queries of one
        :class:`Planner`.
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
        costmap_weight=costmap_weight,
        speed_limits=speed_limits,
        timing_dt=timing_dt,
        landmarks=landmarks,
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
def _cell(c: np.ndarray) -> tuple[int, int]:
    """Return a cell ``(ix, iy)`` as plain ints (for messages)."""
    return (int(c[0]), int(c[1]))


def _point_clearance(grid: OccupancyGrid, p: np.ndarray) -> float:
    """Exact clearance (m) of a world point from the raw map (outside occupied)."""
    return polygon_clearance(np.asarray(p, dtype=float).reshape(1, 2), grid)
