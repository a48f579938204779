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

**Structure.** :class:`Planner` and :func:`plan` hold no planning logic: they validate
their settings into one :class:`~trajopt.planning._options.PlannerOptions`, keep the map's
:class:`~trajopt.planning._caches.PlannerCaches`, and hand both, with the request, to
:func:`~trajopt.planning._runner.run_query` (which runs the stages above, or a footprint
robot's disc ladder) or to :func:`~trajopt.replan.replan_from`.

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
import threading
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

import astar
from astar.costmap import Costmap
from astar.grid import OccupancyGrid
from trajopt.errors import InvalidInputError
from trajopt.motion import PlanResult
from trajopt.moving import MovingObstacle, check_movers
from trajopt.planning import (
    CorridorKind,
    Fallback,
    Inflation,
    PlannerCaches,
    PlannerOptions,
    PlanRequest,
    PlanSteps,
    Search,
    SearchMode,
    plan_among_movers,
    plan_from_stop,
    run_query,
)
from trajopt.replan import BRAKE_AFTER_S, record_marked, replan_from, retime_replan
from trajopt.robot import Robot, State
from trajopt.smoother import Smoother
from trajopt.timing import SpeedLimits
from trajopt.validation import nonnegative

__all__ = [
    "plan",
    "Planner",
    "PlannerOptions",
    "PlanSteps",
    "Inflation",
    "Search",
    "Fallback",
    "PlanResult",
]


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
    options : PlannerOptions, optional
        Every setting (``robot`` included) as one value, e.g. to build several planners,
        or :func:`plan` calls, alike; the keywords must then stay at their defaults.
    **settings
        The planner's settings by name: the fields of :class:`PlannerOptions` (each one's
        meaning, type, default and rule are documented there and only there), e.g.
        ``Planner(grid, robot, corridor="boxes", timing_dt=0.05)``.

    Raises
    ------
    TypeError
        A keyword that is not a setting (the message lists the settings).
    InvalidInputError
        A setting of the wrong type or outside its range (:class:`PlannerOptions`), one
        that does not fit the map (a costmap search on an occupancy grid, speed-limit
        zones off the map), or ``options`` together with a keyword not at its default.

    Notes
    -----
    A planner may be shared between threads: queries are serialised by a lock (the CasADi
    solvers it reuses keep per-call work memory).
    """

    def __init__(
        self,
        grid: OccupancyGrid | Costmap,
        robot: Robot | None = None,
        *,
        options: PlannerOptions | None = None,
        **settings: Any,
    ) -> None:
        settings["robot"] = robot
        self._init(grid, PlannerOptions.from_keywords(options, settings, caller="trajopt.Planner"))

    def _init(self, grid: OccupancyGrid | Costmap, settings: PlannerOptions) -> None:
        options, raw, costmap = settings.for_map(grid)
        self.options = options
        self.caches = PlannerCaches(raw, costmap, options)
        self._lock = threading.RLock()
        self._latencies: collections.deque[float] = collections.deque(maxlen=32)

    # ------------------------------------------------------------- settings
    @property
    def grid(self) -> OccupancyGrid:
        """The raw map (the latest one given to :meth:`update_map` or :meth:`replan`)."""
        return self.caches.grid

    @property
    def costmap(self) -> Costmap | None:
        """The costmap the planner was built from (``None`` for an occupancy grid)."""
        return self.caches.costmap

    @property
    def robot(self) -> Robot:
        """The robot planned for."""
        return self.options.robot

    @property
    def smoother(self) -> Smoother:
        """The smoother's options."""
        return self.options.smoother

    @property
    def inflation(self) -> Inflation:
        """``"exact"`` or ``"paper"``."""
        return self.options.inflation

    @property
    def w_cells(self) -> int:
        """``W`` of ``inflation="paper"`` (cells)."""
        return self.options.w_cells

    @property
    def search(self) -> Search:
        """The A* cost in use."""
        return self.options.search

    @property
    def corridor(self) -> CorridorKind:
        """The corridor kind tried first."""
        return self.options.corridor

    @property
    def fallback(self) -> Fallback | None:
        """The opt-in fallback (``None`` or ``"stop_and_turn"``)."""
        return self.options.fallback

    @property
    def timing_dt(self) -> float:
        """Step of the timing's forward greedy (s)."""
        return self.options.timing_dt

    @property
    def costmap_weight(self) -> float:
        """Weight of a costmap's graded cost in the search."""
        return self.options.costmap_weight

    @property
    def speed_limits(self) -> SpeedLimits | None:
        """The speed-limit zones, if any."""
        return self.options.speed_limits

    @property
    def landmarks(self) -> int:
        """Number of ALT landmarks of the searches with a cost (0: none)."""
        return self.options.landmarks

    @property
    def search_mode(self) -> SearchMode:
        """``"auto"``, ``"exact"`` or ``"coarse"`` (the coarse-to-fine search)."""
        return self.options.search_mode

    @property
    def search_bound(self) -> float:
        """The largest suboptimality a coarse-to-fine search may return."""
        return self.options.search_bound

    # -------------------------------------------------------------- caches
    @property
    def inflated_grid(self) -> OccupancyGrid:
        """The grid the robot centre moves in (computed once per map)."""
        return self.caches.inflated

    @property
    def search_cost(self) -> np.ndarray | None:
        """Per-cell A* cost (``None`` for ``search="shortest"``), computed once per map."""
        return self.caches.search_cost

    @property
    def search_landmarks(self) -> astar.Landmarks | None:
        """ALT landmarks of the inflated grid and search cost (``None`` without), built once."""
        return self.caches.landmarks

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
        with self._lock:
            return self.caches.update(grid)

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
        start_steer: float = 0.0,
        goal_steer: float | None = None,
        moving_obstacles: Sequence[MovingObstacle] | None = None,
        mover_margin: float = 0.0,
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
        start_steer : float
            A car's steering angle at the start (rad, default 0: wheels straight). A car
            with a ``wheelbase`` and a ``steer_rate_max`` steers at rest from it onto its
            first drive (a :class:`~trajopt.motion.SteerInPlace` piece); other robots refuse
            any other value.
        goal_steer : float, optional
            A car's steering angle at the goal (rad), steered to at rest after its last
            drive; default: the last drive's.
        moving_obstacles : sequence of MovingObstacle, optional
            Predicted movers (:class:`trajopt.MovingObstacle`, times from this plan's
            ``t = 0``). ``None`` or empty: the plan as without them. Otherwise the static
            plan is re-timed along its path on one clock (:func:`trajopt.moving.retime_chain`:
            rests at the start and at stops on the way; a differential drive's turns in
            place and a car's steering at rest as rests, a car's drives between cusps each
            from rest to rest, an omni orientation rebuilt on the re-timed translation) and
            certified at every instant until the last prediction ends. When no re-timing
            along the path avoids a mover, another route is planned on the map with the
            movers' swept regions marked, or the robot waits at a safe place
            (:func:`trajopt.moving.reroute`; the steps of a plan made on a marked map
            record the planner's map: :class:`trajopt.replan.MarkedSteps`, which a re-plan
            keeps by). ``stats["moving"]``: ``route``
            (``"retimed"``, ``"rerouted"`` or ``"waited"``), ``plan`` in words, the
            certificate and the wall times. From a moving start (``v_start > 0``) the
            static plan is re-timed as :meth:`replan` re-times its rest
            (:func:`trajopt.replan.retime_replan`, the splice at ``t = 0``): its curve
            from the moving state, else a brake along the path to a stop and a plan on from
            there (``route`` ``"stopped: ..."``). Refused with
            :class:`~trajopt.errors.InvalidInputError`: the stop-and-turn fallback's
            polyline.
        mover_margin : float
            Extra distance to every mover (m), >= 0 (checked even without movers).

        Returns
        -------
        Trajectory or StopAndTurnTrajectory
            With ``trajectory.steps`` (:class:`PlanSteps`) and per-stage wall times in
            ``trajectory.stats["stages_s"]``. A :class:`~trajopt.motion._stop_and_turn.StopAndTurnTrajectory`
            (``stats["fallback"] == "stop_and_turn"``) only with the planner's ``fallback``
            option, when the smoother or the timing failed. With movers, the plan's own kind
            re-timed (a :class:`~trajopt.motion.TrajectoryChain` keeps its pieces, an
            :class:`~trajopt.motion.OmniTrajectory` its orientation), or a re-route's plan; a
            wait at a safe place is one :class:`~trajopt.motion.TrajectoryChain` of both legs.

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
        BlockedError
            A mover blocks the way: no re-timing along the path avoids it and no re-route
            tried does (the mover and the time named, each re-route's reason appended).
        """
        movers = check_movers(moving_obstacles)
        margin = nonnegative("mover_margin", mover_margin, "m")
        request = PlanRequest(
            start,
            goal,
            start_heading,
            goal_heading,
            v_start,
            v_end,
            start_steer=start_steer,
            goal_steer=goal_steer,
        )
        with self._lock:
            t0 = time.perf_counter()
            if movers and request.v_start != 0.0:  # moving: re-timed as a re-plan's rest
                out = run_query(self.options, self.caches, request)
                out = retime_replan(out, movers, margin, 0.0, self._from_stop(out.steps, margin))
            elif movers:
                out = plan_among_movers(movers, margin, self.options, self.caches, request)
                out = record_marked(out, self.caches.grid, self.caches.inflated)
            else:
                out = run_query(self.options, self.caches, request)
            self._latencies.append(time.perf_counter() - t0)
            return out

    def _from_stop(self, steps: Any, margin: float) -> Callable[..., PlanResult]:
        """Return the plan from a stop to ``steps``' goal that a blocked re-timing goes on by.

        ``from_stop(position, heading, steer, movers, along=None)``
        (:data:`trajopt.replan` ``FromStop``): a plan from rest at the stop, for the movers
        seen from it, as :meth:`plan`'s with movers (:func:`trajopt.planning.plan_from_stop`).
        """

        def from_stop(
            p: tuple[float, float],
            heading: float,
            steer: float,
            seen: Sequence[MovingObstacle],
            along: Any = None,
        ) -> PlanResult:
            if steps is None:
                raise InvalidInputError("the plan has no steps: no goal to go on to")
            request = PlanRequest(
                p,
                tuple(steps.goal),
                start_heading=heading,
                goal_heading=steps.goal_heading,
                start_steer=steer,
                goal_steer=getattr(steps, "goal_steer", None),
            )
            out = plan_from_stop(tuple(seen), margin, self.options, self.caches, request, along)
            return record_marked(out, self.caches.grid, self.caches.inflated)

        return from_stop

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
        moving_obstacles: Sequence[MovingObstacle] | None = None,
        mover_margin: float = 0.0,
    ) -> PlanResult:
        """Re-plan from a trajectory being driven, splicing at ``t + latency``.

        The new trajectory starts at ``trajectory.state_at(t + latency)``: the same
        position, heading, curvature, speed and acceleration (a C2 splice), so a robot can
        switch to it at that time without a jump. Its ``stats["splice_time_s"]`` is the
        splice time on the old trajectory's clock, ``stats["latency_s"]`` the latency used,
        ``stats["replan"]`` ``"kept"``, ``"planned: <why the rest was not kept>"`` or
        ``"braked: <why no smooth plan>"``.

        What it keeps of the old trajectory, what it reuses and when it brakes instead:
        :mod:`trajopt.replan._replan`. A car-like robot (an :class:`~trajopt.drive.Ackermann` drive) is never
        turned in place: its rest is kept while clear, else it brakes along the segment it
        is driving, in its direction of travel, and a car plan (which may reverse) starts
        from the stopped pose (:mod:`trajopt.replan._car`); ``goal_heading`` is required
        with a new goal, and ``v_end`` must be 0.

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
        moving_obstacles : sequence of MovingObstacle, optional
            Predicted movers, their times on ``trajectory``'s clock (the clock of ``t``;
            for a plan of :meth:`plan`, seconds from its start). ``None`` or empty: the
            re-plan as without them. Otherwise the re-plan's result is re-timed for them
            (:func:`trajopt.replan.retime_replan`): one curve from the splice state; a
            chain after its part that ends in a stop (the brake), on one clock
            (:func:`trajopt.moving.retime_chain`). When only the predictions changed, the
            kept rest keeps its path and only its timing changes, a re-routed plan's too
            (kept by the static map its movers' marks were drawn on,
            :class:`trajopt.replan.MarkedSteps`). When no re-timing avoids
            the movers, the robot brakes to a stop and plans on from there as :meth:`plan`
            does with movers (re-timed, else re-routed or a wait at a safe place; when the
            path followed is proved blocked, the re-route's candidates first and the static
            plan from the stop last: :func:`trajopt.planning.plan_from_stop`). The
            result is certified whole; its ``t = 0`` is the splice ``ts = t + latency`` of
            that clock; ``stats["moving"]`` holds the re-timing (``plan``, ``certificate``,
            ``time_s``), ``route`` (``"retimed"`` or ``"stopped: <plan's route>"``),
            ``clock_offset_s`` (``ts``: a mover time ``T`` is ``T - ts`` on the result's
            clock, which the predictions of a later re-plan of the result use) and
            ``replan`` (what was kept or planned).
        mover_margin : float
            Extra distance to every mover (m), >= 0 (checked even without movers).

        Raises
        ------
        InvalidInputError
            ``t + latency`` outside ``[0, duration]``, a negative latency, no goal given
            for a trajectory without ``steps``; with movers, ``v_end > 0`` or a mover over
            the robot at the splice.
        TimingError, SmoothingError, NoPathError
            As :meth:`plan`; ``TimingError``: it must brake and cannot stop in time.
        BlockedError
            A mover blocks the rest of the way: no re-timing of the re-plan avoids it and no
            plan from a stop does either, or it meets the robot while it stops (named, its
            time on the movers' clock).
        """
        movers = check_movers(moving_obstacles)
        margin = nonnegative("mover_margin", mover_margin, "m")
        with self._lock:
            t0 = time.perf_counter()
            lat = self.latency_s if latency is None else latency
            out = replan_from(
                self.options,
                self.caches,
                trajectory,
                t,
                goal,
                grid,
                latency=lat,
                goal_heading=goal_heading,
                v_end=v_end,
                reuse=reuse,
                brake_after_s=brake_after_s,
            )
            if movers:
                ts = float(out.stats["splice_time_s"])
                out = retime_replan(out, movers, margin, ts, self._from_stop(out.steps, margin))
            self._latencies.append(time.perf_counter() - t0)
            return out


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
    start_steer: float = 0.0,
    goal_steer: float | None = None,
    moving_obstacles: Sequence[MovingObstacle] | None = None,
    mover_margin: float = 0.0,
    options: PlannerOptions | None = None,
    **settings: Any,
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
    start_steer, goal_steer : float
        A car's steering angles at the ends (rad; see :meth:`Planner.plan`).
    moving_obstacles : sequence of MovingObstacle, optional
        Predicted movers; ``mover_margin`` (m) the extra distance to them (see
        :meth:`Planner.plan`).
    options : PlannerOptions, optional
        Every setting (``robot`` included) as one value (see :class:`Planner`).
    **settings
        The planner's settings by name, as for :class:`Planner`: the fields of
        :class:`PlannerOptions`, each documented there with its default (e.g.
        ``corridor="boxes"``, ``timing_dt=0.05``, ``fallback="stop_and_turn"``). Each
        call builds its caches for its one query: ``landmarks`` then cost more than the
        search they shorten (they pay off across the queries of one :class:`Planner`).

    Returns
    -------
    Trajectory or StopAndTurnTrajectory
        ``trajectory.steps`` holds every intermediate result (:class:`PlanSteps`); the
        second type only with ``fallback="stop_and_turn"`` (``stats["fallback"]``).

    Raises
    ------
    TypeError
        A keyword that is neither a setting nor one of the query's (the message lists the
        settings).
    InvalidInputError, NoPathError, SmoothingError, TimingError
        As :class:`Planner` and :meth:`Planner.plan`.

    Examples
    --------
    >>> import trajopt
    >>> scene = trajopt.scenes.paper()
    >>> traj = trajopt.plan(scene.grid, scene.start, scene.goal("A"))  # doctest: +SKIP
    >>> traj.duration  # doctest: +SKIP
    """
    settings["robot"] = robot
    planner = Planner(
        grid, options=PlannerOptions.from_keywords(options, settings, caller="trajopt.plan")
    )
    # the movers' keywords go on only when given: without them the call is today's
    moving = (
        {}
        if moving_obstacles is None and mover_margin == 0.0
        else {
            "moving_obstacles": moving_obstacles,
            "mover_margin": mover_margin,
        }
    )
    return planner.plan(
        start,
        goal,
        start_heading=start_heading,
        goal_heading=goal_heading,
        v_start=v_start,
        v_end=v_end,
        start_steer=start_steer,
        goal_steer=goal_steer,
        **moving,
    )
