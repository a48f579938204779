"""Pose-to-pose plans of a car-like robot (``Robot(drive="ackermann")``).

A car faces its direction of travel (or its reverse), turns no tighter than its
``min_turning_radius`` ``R`` and cannot turn in place, so :func:`plan_car` plans in
(x, y, heading):

1. **Search.** :func:`astar.find_pose_path` (Hybrid-A* with Reeds-Shepp shots, or Dubins
   shots when ``robot.reverse`` is False) from the start pose to the goal pose, on the raw
   map inflated by the robot radius plus :data:`SEARCH_MARGIN_CELLS` (so that every point of
   a free cell, not only its centre, keeps the radius: the search's poses lie anywhere in
   their cells), with a turning radius :data:`SEARCH_RADIUS_FACTORS` times ``R``: the
   first factor leaves the smoother room (a segment turning at exactly ``1/R`` between
   fixed end poses admits no other curve, and a B-spline is no circle); when a segment of
   its path has no certified fit, the search runs again with gentler arcs (the second
   factor); when the search finds no path, with 1.05 ``R`` and then ``R`` itself (larger
   factors are then skipped), their fits with the smoother's ``kappa_margin`` raised to
   :data:`TIGHT_KAPPA_MARGIN` (a turn at nearly full lock, e.g. a start facing a wall with
   just the room to turn; the certificate's dense curvature check still holds them to
   ``1/R``). When an end point is blocked on that grid, or the margin disconnects the
   poses or leaves no path, the same tries run on the map inflated by the radius alone
   (the other planners' grid): end points near walls and passages the margin closes. There
   only the cell centres keep the radius, so that search runs in its exact mode
   (:func:`astar.find_pose_path` ``raw_grid``, ``clearance``): the chords between its
   poses keep the radius from the raw map exactly, as the corridor requires (a pose
   anywhere in a free cell could come up to half a cell's diagonal closer). The
   tries share :data:`CAR_BUDGET_S`; ``stats["car"]["tries"]`` lists them.
2. **Segments.** The path is split at its cusps (where the direction of travel flips; the
   heading is continuous there, the tangent flips by ``pi``). Each segment is fitted as an
   ordinary curve in the direction of travel: a certified polygon corridor grown around
   its poses (:func:`~trajopt.corridor.build_polygon_corridor`), then the planner's
   smoother with ``kappa_max = min(its own, 1/R)``, exact end points, exact end travel
   headings (the body heading forwards, heading ``+ pi`` backwards) and the search path's
   start curvature (:func:`_fit_segment`); then without that curvature; then from its end
   to its start with the path's curvature at the end, the curve then turned round (the
   smoother takes a start curvature, not a goal one). Where those fail, it is fitted again
   in polygons grown around the poses themselves without centring (the
   witness corridor of :func:`~trajopt.planning._corridor_fit.witness_corridor`). A
   stretch that turns by more than :data:`SPLIT_TURN_RAD` and that neither the first nor
   the reversed fit fits is fitted in pieces spanning at most :data:`PIECE_TURN_RAD` of
   heading each (before the other whole fits), each starting with the previous piece's
   end curvature; the car rests at each join as at a cusp (:attr:`CarSegment.joined`).
   Every curve is the smoother's certified curve (convex-hull clearance certificate per
   segment) and its sampled curvature (the certificate's dense samples) must be within
   ``1/R``; nothing else is returned.
3. **Timing.** Each segment is timed along its arc length from rest to rest
   (:func:`trajopt.time_parameterize`: ``v = 0`` at the ends and at every cusp), backwards
   segments with ``v_max_reverse`` as the speed limit, with the robot's curvature caps and,
   with ``steer_rate_max``, the steering-rate cap (:mod:`trajopt.timing._steer_cap`).

The result is a :class:`~trajopt.motion.TrajectoryChain` of one
:class:`~trajopt.motion.Trajectory` per segment (``direction`` ``+1`` or ``-1``), even for a
single segment: its samples carry the signed ``v``, the body's ``theta`` (continuous across
cusps) and ``kappa``, ``direction`` and, with a ``wheelbase``, ``steer`` and ``steer_rate``.
Curvature (hence steering) is continuous within a segment (the B-spline is C2); at a cusp
the car is at rest and may steer while stopped (the chain checks position, heading, speed,
acceleration and yaw rate there, not the curvature). Its ``steps`` are a :class:`CarSteps`.

Not supported (refused with :class:`~trajopt.errors.InvalidInputError`): a footprint (plan
with its circumscribed disc radius), a moving start or end speeds other than 0, missing end
headings, and the chapter's ``inflation="paper"``.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

import astar
from astar.grid import OccupancyGrid
from trajopt._validation import point
from trajopt.corridor import PolygonCorridor, build_polygon_corridor
from trajopt.errors import InvalidInputError, NoPathError, SmoothingError
from trajopt.geometry._bspline import BSplineCurve
from trajopt.motion._chain import TrajectoryChain
from trajopt.motion._trajectory import Trajectory
from trajopt.planning._caches import PlannerCaches
from trajopt.planning._corridor_fit import witness_corridor
from trajopt.planning._disc import check_endpoint
from trajopt.planning._options import PlannerOptions, PlanRequest
from trajopt.planning._query import StageTimer
from trajopt.robot._robot import Robot
from trajopt.robot._state import State
from trajopt.smoother import SmoothPath
from trajopt.timing import time_parameterize

#: Extra inflation (cells) of the search grid beyond the robot radius: half a cell's
#: diagonal (any point of a free cell keeps the radius) plus slack for the chords between
#: the search's poses (at most half a cell apart).
SEARCH_MARGIN_CELLS = 0.5 * math.sqrt(2.0) + 0.05
#: Turning radii of the search, as multiples of ``min_turning_radius``, tried in order
#: (module docstring: a factor above one that failed to search is skipped afterwards).
SEARCH_RADIUS_FACTORS = (1.15, 1.5, 1.05, 1.0)
#: Search radius factors at or below this fit with :data:`TIGHT_KAPPA_MARGIN`.
TIGHT_FACTOR = 1.05
#: The smoother's ``kappa_margin`` (bound at its collocation samples, as a fraction of
#: ``1/R``) for the fits of a path searched at :data:`TIGHT_FACTOR` ``R`` or less: with the
#: default 0.9 a curve cannot follow an arc of 1.02-1.05 ``R`` (held-out depot #5, forward
#: only, a start facing a wall), with 0.99 it does.
TIGHT_KAPPA_MARGIN = 0.99
#: Time (s) after which no further try (search and fits) of a car's plan starts.
CAR_BUDGET_S = 6.0
#: Relative tolerance of the curvature check of each fitted segment.
KAPPA_TOL = 1e-6
#: Cap (s) on the smoother's time budget per segment fit.
SEGMENT_BUDGET_S = 2.0
#: Cap (s) on the Hybrid-A* search's time budget per try.
SEARCH_BUDGET_S = 2.0
#: A stretch between cusps that turns by more than this (rad, the sum of its heading changes)
#: and whose first fits fail is fitted in pieces (:func:`split_points`): one B-spline round
#: a loop of the search's forward-only shots (4.7-6.6 rad on the held-out failures) left the
#: curvature SCP without a step (its trust region collapsed), where its thirds fitted at
#: once. Only after whole fits failed (:data:`WHOLE_FIRST`): the car rests at each join,
#: and long paths turn by tens of radians in small steps.
SPLIT_TURN_RAD = math.pi
#: The fits (:func:`_fit_segment` ``tries``) of a stretch that may be split, tried before its
#: pieces: with the search path's start curvature, and from the end with its end curvature.
#: The others (without a start curvature, the witness corridor) come after the pieces: a
#: failing whole fit of a long loop costs 0.4-1.9 s, its pieces 0.01-0.03 s each.
WHOLE_FIRST = (0, 2)
#: Largest turn (rad) of each piece of a split stretch.
PIECE_TURN_RAD = 0.6 * math.pi
#: Slack (m) of the search's exact clearance on the radius grid: a quarter of the corridor's
#: tolerance (``trajopt.corridor`` accepts points ``1e-9`` m closer than the radius), so that
#: an end point exactly at the radius from a wall (a cell centre) may leave it.
EXACT_TOL_M = 0.25e-9


@dataclass(frozen=True, slots=True)
class CarSegment:
    """One segment of a car's plan between cusps.

    Attributes
    ----------
    direction : int
        ``+1`` forwards, ``-1`` backwards.
    first, last : int
        Pose indices (into :attr:`CarSteps.poses`) of its ends.
    corridor : PolygonCorridor
        The certified corridor it was fitted in.
    smooth_path : SmoothPath
        The certified curve in the direction of travel (its certificate included).
    corridor_kind : str
        ``"polygons"`` (grown around the centred poses), ``"reversed"`` (the same, fitted
        from the segment's end with its curvature there, then turned round) or ``"witness"``
        (around the poses themselves, the last try).
    joined : bool
        Whether it continues the previous segment in the same direction of travel (a stretch
        between cusps that turns by more than :data:`SPLIT_TURN_RAD` and that its first
        whole fits miss is fitted in pieces; the car rests at each join, as at a cusp). Its curve then starts with the previous
        curve's end curvature where that fit succeeds (``"polygons"``).
    """

    direction: int
    first: int
    last: int
    corridor: PolygonCorridor
    smooth_path: SmoothPath
    corridor_kind: str
    joined: bool = False


@dataclass(frozen=True, slots=True)
class CarCorridor:
    """The regions of every segment's corridor, in order (what the MCAP writer draws)."""

    regions: tuple


@dataclass(frozen=True, slots=True)
class CarSteps:
    """What each stage of a car's plan produced (``trajectory.steps``).

    Attributes
    ----------
    raw_grid : astar.OccupancyGrid
        The map.
    inflated_grid : astar.OccupancyGrid
        The grid searched (radius plus :data:`SEARCH_MARGIN_CELLS` cells).
    pose_path : astar.PosePath
        The Hybrid-A* path (cells; :meth:`astar.PosePath.to_world`).
    poses : ndarray, shape (n, 3)
        Its poses in world units ``(x, y, heading)`` (m, m, rad).
    segments : tuple of CarSegment
        One per stretch between cusps, or per piece of a stretch fitted in pieces
        (:attr:`CarSegment.joined`).
    start, goal : tuple of float
        The end points (m).
    start_heading, goal_heading : float
        The end headings (rad).
    stages_s : dict
        Wall time per stage (s): ``inflate``, ``search``, ``corridor``, ``smooth``,
        ``timing``, ``total``.
    search_turning_radius : float
        The turning radius the path was found with (m).
    """

    raw_grid: OccupancyGrid
    inflated_grid: OccupancyGrid
    pose_path: Any
    poses: np.ndarray
    segments: tuple
    start: tuple[float, float]
    goal: tuple[float, float]
    start_heading: float
    goal_heading: float
    stages_s: dict[str, float]
    search_turning_radius: float

    @property
    def corridor(self) -> CarCorridor:
        """Every segment's regions (:class:`CarCorridor`)."""
        return CarCorridor(tuple(r for s in self.segments for r in s.corridor.regions))

    @property
    def smooth_path(self) -> SmoothPath:
        """The first segment's curve (each segment's is in :attr:`segments`)."""
        return self.segments[0].smooth_path


def plan_car(options: PlannerOptions, caches: PlannerCaches, request: PlanRequest) -> Any:
    """Plan one query of a car-like robot (module docstring).

    Parameters
    ----------
    options : PlannerOptions
        Resolved for the map of ``caches``; ``options.robot.drive == "ackermann"``.
    caches : PlannerCaches
        The map.
    request : PlanRequest
        Start and goal points (m) with both headings (rad), at rest (a :class:`State`
        start at rest counts as its position and heading).

    Returns
    -------
    TrajectoryChain
        One :class:`~trajopt.motion.Trajectory` per segment (between cusps, and at the
        joins of a stretch fitted in pieces), each from rest to rest.

    Raises
    ------
    InvalidInputError
        A footprint, ``inflation="paper"``, a heading missing, a moving start or an end
        speed other than 0, an end point off the map or too close to an obstacle, or one
        blocked on the search grid.
    NoPathError
        No path joins the poses (an :class:`astar.NoPosePathError` as its cause; with
        ``reverse=False`` the message says that a forward-only path was asked for).
    SmoothingError
        A segment has no certified curve within the curvature bound.
    TimingError
        A segment cannot be timed.
    """
    timer = StageTimer()
    robot = options.robot
    grid = caches.grid
    p0, p1, h0, h1 = _ends(options, grid, request)
    res = grid.resolution
    start = _to_cells(grid, p0, h0)
    goal = _to_cells(grid, p1, h1)
    kmax = 1.0 / robot.min_turning_radius
    sm = options.smoother
    sm = dataclasses.replace(
        sm,
        kappa_max=kmax if sm.kappa_max is None else min(sm.kappa_max, kmax),
        time_budget_s=min(sm.time_budget_s, SEGMENT_BUDGET_S),
    )
    sm_tight = dataclasses.replace(sm, kappa_margin=max(sm.kappa_margin, TIGHT_KAPPA_MARGIN))
    t_end = time.perf_counter() + CAR_BUDGET_S
    tries: list[str] = []
    failures: list[Exception] = []
    found = None
    for margin in (True, False):
        with timer.stage("inflate"):
            search_grid = car_search_grid(robot, grid, margin=margin)
        blocked = _blocked_end(
            robot, search_grid, margin, (("start", start, p0), ("goal", goal, p1))
        )
        if blocked is not None:
            tries.append(f"{_grid_name(margin)}: {blocked}")
            failures.append(InvalidInputError(blocked))
            continue
        largest = math.inf
        for factor in SEARCH_RADIUS_FACTORS:
            if factor > largest or time.perf_counter() > t_end:
                continue
            r_cells = factor * robot.min_turning_radius / res
            try:
                with timer.stage("search"):
                    path = astar.find_pose_path(
                        search_grid,
                        start,
                        goal,
                        turning_radius=r_cells,
                        reverse=robot.reverse,
                        time_budget=max(0.05, min(SEARCH_BUDGET_S, t_end - time.perf_counter())),
                        **_exact_clearance(robot, grid, margin),
                    )
            except astar.NoPosePathError as exc:
                tries.append(f"{_grid_name(margin)}, {factor:g} R: no path ({exc.reason})")
                failures.append(exc)
                if exc.reason == "disconnected":
                    break
                largest = min(largest, factor)
                continue
            poses = path.to_world(grid)
            try:
                segments = []
                for a, b in np.asarray(path.segments):
                    segments.extend(
                        _fit_run(
                            options,
                            grid,
                            sm if factor > TIGHT_FACTOR else sm_tight,
                            poses,
                            (int(a), int(b)),
                            int(path.directions[b]),
                            _start_curvature(path, int(a), res),
                            timer,
                        )
                    )
            except SmoothingError as exc:
                tries.append(f"{_grid_name(margin)}, {factor:g} R: a segment has no fit")
                failures.append(exc)
                continue
            tries.append(f"{_grid_name(margin)}, {factor:g} R: planned")
            found = (search_grid, path, r_cells, poses, segments)
            break
        if found is not None:
            break
    if found is None:
        raise _failure(robot, grid, start, goal, tries, failures)
    search_grid, path, radius_cells, poses, segments = found
    pieces: list[Trajectory] = []
    for seg in segments:
        with timer.stage("timing"):
            pieces.append(_time_segment(options, seg))
    stages = timer.finish()
    steps = CarSteps(
        raw_grid=grid,
        inflated_grid=search_grid,
        pose_path=path,
        poses=poses,
        segments=tuple(segments),
        start=(float(p0[0]), float(p0[1])),
        goal=(float(p1[0]), float(p1[1])),
        start_heading=h0,
        goal_heading=h1,
        stages_s=stages,
        search_turning_radius=radius_cells * res,
    )
    stats: dict[str, Any] = {
        "stages_s": dict(stages),
        "car": {
            "segments": len(segments),
            "cusps": int(path.cusps),
            "directions": [s.direction for s in segments],
            "joins": sum(s.joined for s in segments),
            "reverse_length_m": float(path.reverse_length * res),
            "search_length_m": float(path.length * res),
            "search_turning_radius_m": radius_cells * res,
            "tries": tries,
            "corridors": [s.corridor_kind for s in segments],
            "search": dict(path.stats),
        },
        "inflation": options.inflation,
    }
    return TrajectoryChain(tuple(pieces), robot, stats, steps)


def car_search_grid(robot: Robot, grid: OccupancyGrid, margin: bool = True) -> OccupancyGrid:
    """Return the grid a car's search runs on: ``grid`` inflated by the radius plus a margin.

    Parameters
    ----------
    robot : Robot
        The car (its ``radius``, m).
    grid : astar.OccupancyGrid
        The raw map.
    margin : bool, optional
        False: the radius alone (the second grid the search tries; module docstring).

    Returns
    -------
    astar.OccupancyGrid
        ``grid`` with every cell within ``robot.radius`` plus :data:`SEARCH_MARGIN_CELLS`
        cells (without ``margin``: within ``robot.radius``) of an occupied square (or of the
        outside) occupied.
    """
    r = robot.radius + (SEARCH_MARGIN_CELLS * grid.resolution if margin else 0.0)
    return grid.with_occupied(
        astar.inflate(grid, r, metric="square", outside_occupied=True).occupied
    )


def _exact_clearance(robot: Robot, grid: OccupancyGrid, margin: bool) -> dict[str, Any]:
    """Return the search's exact-mode arguments on the radius grid (none on the margin grid).

    On the grid inflated by the radius alone only the cell centres keep the radius; the
    search's exact mode (:func:`astar.find_pose_path` ``clearance``) makes the polyline of
    its poses keep it too, as the corridor requires, to within :data:`EXACT_TOL_M`.
    """
    if margin:
        return {}
    r_cells = robot.radius / grid.resolution - EXACT_TOL_M / grid.resolution
    return {"raw_grid": grid, "clearance": r_cells}


def _grid_name(margin: bool) -> str:
    return "radius + margin grid" if margin else "radius grid"


def _blocked_end(robot: Robot, search_grid: OccupancyGrid, margin: bool, ends: Any) -> str | None:
    """Return why an end point's cell is blocked on ``search_grid``, or None."""
    for name, c, p in ends:
        ix, iy = int(math.floor(c[0] + 0.5)), int(math.floor(c[1] + 0.5))
        if search_grid.occupied[iy, ix]:
            extra = f" plus {SEARCH_MARGIN_CELLS:.3g} cells" if margin else ""
            return (
                f"{name} {p.tolist()} m lies in cell ({ix}, {iy}), blocked on the car's search "
                f"grid (robot radius {robot.radius} m{extra}); move it towards free space"
            )
    return None


def _failure(
    robot: Robot,
    grid: OccupancyGrid,
    start: Any,
    goal: Any,
    tries: list[str],
    failures: list[Exception],
) -> Exception:
    """Return the error of a car's plan that no try completed (module docstring)."""
    fits = [f for f in failures if isinstance(f, SmoothingError)]
    searches = [f for f in failures if isinstance(f, astar.NoPosePathError)]
    summary = "; ".join(tries)
    if fits:  # a path was found, and no curve fits it
        return SmoothingError(f"{fits[-1]} (tries: {summary})", {"car_tries": tries})
    if searches:
        last = searches[-1]
        mode = (
            "forwards and backwards"
            if robot.reverse
            else "forwards only (reverse=False): no forward-only path was found; a goal only "
            "reachable backwards needs reverse=True"
        )
        err = NoPathError(
            f"no path of a car-like robot (turning radius {robot.min_turning_radius} m, radius "
            f"{robot.radius} m) driving {mode}, from pose {_pose_m(start, grid)} to pose "
            f"{_pose_m(goal, grid)} ({last.reason}): {last} (tries: {summary})"
        )
        err.__cause__ = last
        return err
    return failures[-1]


def _ends(
    options: PlannerOptions, grid: OccupancyGrid, request: PlanRequest
) -> tuple[np.ndarray, np.ndarray, float, float]:
    """Return the checked end points (m) and headings (rad) of a car's query."""
    robot = options.robot
    if robot.footprint is not None:
        raise InvalidInputError(
            "Robot(drive='ackermann') with a footprint is not supported yet: plan with a disc "
            f"(radius={robot.circumscribed_radius:.6g} m, the footprint's circumscribed disc)"
        )
    if options.inflation != "exact":
        raise InvalidInputError(
            f"inflation={options.inflation!r} is not supported for drive='ackermann'; use 'exact'"
        )
    start, h0 = request.start, request.start_heading
    if isinstance(start, State):
        if start.v != 0.0 or start.a != 0.0 or h0 is not None:
            raise InvalidInputError(
                "a car-like robot (drive='ackermann') plans from rest: start must be a point "
                f"with start_heading, or a State at rest, got a State with v={start.v!r}, "
                f"a={start.a!r}"
            )
        start, h0 = start.position, start.theta
    if request.v_start != 0.0 or request.v_end != 0.0:
        raise InvalidInputError(
            "a car-like robot (drive='ackermann') plans from rest to rest: v_start and v_end "
            f"must be 0, got v_start={request.v_start!r}, v_end={request.v_end!r}"
        )
    missing = [
        n for n, h in (("start_heading", h0), ("goal_heading", request.goal_heading)) if h is None
    ]
    if missing:
        raise InvalidInputError(
            f"a car-like robot (drive='ackermann') needs both end headings (rad): "
            f"{' and '.join(missing)} {'is' if len(missing) == 1 else 'are'} None"
        )
    p0 = point("start", start)
    p1 = point("goal", request.goal)
    check_endpoint(options, grid, "start", p0)
    check_endpoint(options, grid, "goal", p1)
    return p0, p1, float(h0), float(request.goal_heading)


def _to_cells(grid: OccupancyGrid, p: np.ndarray, heading: float) -> tuple[float, float, float]:
    """Return a world pose as the search's cell pose (``world = origin + (xy + 0.5) res``)."""
    xy = (np.asarray(p, dtype=float) - np.asarray(grid.origin, dtype=float)) / grid.resolution
    return float(xy[0] - 0.5), float(xy[1] - 0.5), float(heading)


def _pose_m(c: Any, grid: OccupancyGrid) -> str:
    x = grid.origin[0] + (c[0] + 0.5) * grid.resolution
    y = grid.origin[1] + (c[1] + 0.5) * grid.resolution
    return f"({x:.6g} m, {y:.6g} m, {c[2]:.6g} rad)"


def _start_curvature(path: Any, first: int, res: float) -> float:
    """Return the curvature (1/m) the search's path starts pose ``first`` with.

    Signed along the direction of travel: a backwards arc of body curvature ``k`` traces,
    in its direction of travel, a curve of curvature ``-k``.
    """
    xy = np.asarray(path.poses[first, :2])
    pieces = np.asarray(path.pieces)
    i = int(np.argmin(np.hypot(*(pieces[:, :2] - xy).T)))
    k, length = float(pieces[i, 3]), float(pieces[i, 4])
    return (k if length >= 0.0 else -k) / res


def split_points(headings: np.ndarray, first: int, last: int) -> list[int]:
    """Return the pose indices where a stretch between cusps is cut into pieces.

    ``[first, last]`` (no cut) when the stretch turns (the sum of ``|d heading|``) by at most
    :data:`SPLIT_TURN_RAD`; else greedy pieces, each as long as its headings span (largest
    minus smallest unwrapped heading) at most :data:`PIECE_TURN_RAD` and it has at least
    two poses: a loop is cut every ``PIECE_TURN_RAD`` of turn, a path that wiggles about
    one direction is not cut.

    Parameters
    ----------
    headings : ndarray, shape (m,)
        Unwrapped headings (rad) of the search path's poses.
    first, last : int
        Pose indices of the stretch's ends.

    Returns
    -------
    list of int
        Increasing indices from ``first`` to ``last``.
    """
    th = np.asarray(headings[first : last + 1], dtype=float)
    if float(np.abs(np.diff(th)).sum()) <= SPLIT_TURN_RAD or last - first < 4:
        return [first, last]
    cuts = [first]
    lo = hi = float(th[0])
    for k in range(1, len(th)):
        lo, hi = min(lo, th[k]), max(hi, th[k])
        if hi - lo > PIECE_TURN_RAD and k - 1 - (cuts[-1] - first) >= 2:
            cuts.append(first + k - 1)
            lo, hi = min(th[k - 1], th[k]), max(th[k - 1], th[k])
    if last - cuts[-1] < 2 and len(cuts) > 1:
        cuts.pop()  # a last piece of one step joins the one before
    cuts.append(last)
    return cuts


def _end_curvature(path: SmoothPath) -> float:
    """Return a fitted curve's signed curvature (1/m) at its end, along its direction."""
    return float(np.asarray(path.curvature(np.array([path.domain[1]])), dtype=float)[-1])


def _fit_run(
    options: PlannerOptions,
    grid: OccupancyGrid,
    smoother: Any,
    poses: np.ndarray,
    ends: tuple[int, int],
    direction: int,
    kappa0: float,
    timer: StageTimer,
) -> list[CarSegment]:
    """Fit a stretch between cusps (module docstring, step 2).

    As one segment (:func:`_fit_segment`: first its fits with the search path's end
    curvatures, :data:`WHOLE_FIRST`); when those fail and the stretch turns by more than
    :data:`SPLIT_TURN_RAD`, in pieces (:func:`split_points`), each piece starting with the
    previous curve's end curvature (the car rests at each join); then the whole stretch's
    other fits.
    """
    args = (options, grid, smoother, poses)
    cuts = split_points(np.asarray(poses[:, 2]), *ends)
    if len(cuts) == 2:
        return [_fit_segment(*args, ends, direction, kappa0, timer)]
    try:
        return [_fit_segment(*args, ends, direction, kappa0, timer, tries=WHOLE_FIRST)]
    except SmoothingError as exc:
        whole = exc
    out: list[CarSegment] = []
    k_start = kappa0
    try:
        for a, b in zip(cuts[:-1], cuts[1:], strict=True):
            seg = _fit_segment(*args, (a, b), direction, k_start, timer)
            out.append(dataclasses.replace(seg, joined=bool(out)))
            k_start = _end_curvature(seg.smooth_path)
        return out
    except SmoothingError as exc:
        pieces = exc
    rest = tuple(i for i in range(4) if i not in WHOLE_FIRST)
    try:
        return [_fit_segment(*args, ends, direction, kappa0, timer, tries=rest)]
    except SmoothingError as exc:
        raise SmoothingError(
            f"{whole}; in {len(cuts) - 1} pieces: {pieces}; then {exc}", exc.stats
        ) from exc


def _fit_segment(
    options: PlannerOptions,
    grid: OccupancyGrid,
    smoother: Any,
    poses: np.ndarray,
    ends: tuple[int, int],
    direction: int,
    kappa0: float,
    timer: StageTimer,
    tries: tuple[int, ...] = (0, 1, 2, 3),
) -> CarSegment:
    """Fit one segment in the direction of travel (module docstring, step 2).

    ``ends``: its first and last pose indices; ``kappa0``: the search path's curvature at
    its start (1/m, along the direction of travel), the first fit's start curvature (the
    car may steer while at rest, so the curve may start bending as the search's arc does; a
    curve made to leave straight along a pose pinned against a wall can need a near-cusp).
    """
    first, last = ends
    radius = options.robot.radius
    pts = np.ascontiguousarray(poses[first : last + 1, :2])
    turn = 0.0 if direction > 0 else math.pi
    h0, h1 = float(poses[first, 2] + turn), float(poses[last, 2] + turn)
    kmax = 1.0 / options.robot.min_turning_radius
    errors: list[str] = []
    corridor = None
    # the end's curvature along the direction of travel, from the last two poses (on an arc)
    d_end = float(np.hypot(*(pts[-1] - pts[-2]))) if len(pts) > 1 else 0.0
    k_end = (float(poses[last, 2] - poses[last - 1, 2]) / d_end) if d_end > 0.0 else 0.0
    every = (("polygons", kappa0), ("polygons", None), ("reversed", -k_end), ("witness", None))
    for kind, k_start in (every[i] for i in tries):
        # "reversed": the segment fitted from its end to its start, starting with the end's
        # curvature (the smoother takes a start curvature, not a goal one), then turned round
        p_fit = pts[::-1].copy() if kind == "reversed" else pts
        hs, hg = (h1 + math.pi, h0 + math.pi) if kind == "reversed" else (h0, h1)
        try:
            with timer.stage("corridor"):
                if kind == "witness":
                    corridor = witness_corridor(grid, radius, _dense(pts, grid.resolution))
                elif kind == "reversed":
                    corridor = build_polygon_corridor(grid, p_fit, radius)
                elif corridor is None:  # the two polygon fits share one corridor
                    corridor = build_polygon_corridor(grid, pts, radius)
            with timer.stage("smooth"):
                smooth = smoother.fit(
                    p_fit,
                    corridor,
                    raw_grid=grid,
                    radius=radius,
                    start=p_fit[0],
                    goal=p_fit[-1],
                    start_heading=hs,
                    goal_heading=hg,
                    start_curvature=k_start,
                )
        except (SmoothingError, InvalidInputError) as exc:
            errors.append(f"{kind}{'' if k_start is None else ' (start curvature)'}: {exc}")
            continue
        cert = smooth.certificate
        if cert is None or not cert.ok or cert.kappa_max_sampled > kmax * (1.0 + KAPPA_TOL):
            k = None if cert is None else cert.kappa_max_sampled
            errors.append(f"{kind}: not certified within 1/R (kappa {k})")
            continue
        if kind == "reversed":
            smooth = turned_round(smooth)
        return CarSegment(direction, first, last, corridor, smooth, kind)
    where = "forwards" if direction > 0 else "backwards"
    raise SmoothingError(
        f"no certified curve with curvature <= 1/R = {kmax:.6g} 1/m for the {where} segment "
        f"from ({pts[0, 0]:.6g}, {pts[0, 1]:.6g}) m to ({pts[-1, 0]:.6g}, {pts[-1, 1]:.6g}) "
        f"m: {'; '.join(errors)}",
        {"car_segment_failures": errors},
    )


def turned_round(path: SmoothPath) -> SmoothPath:
    """Return ``path`` traversed from its end to its start (the same certified curve).

    ``C'(u) = C(t_0 + t_N - u)``: the knots mirrored and the control points reversed give
    the same point set, spans and convex hulls, so the certificate (clearance, curvature
    magnitude, speed) holds as it is; ``stats["turned_round"]`` marks it.
    """
    c = path.curve
    t = np.asarray(c.t, dtype=float)
    curve = BSplineCurve((t[0] + t[-1]) - t[::-1], np.asarray(c.c)[::-1], c.k)
    return dataclasses.replace(path, curve=curve, stats=dict(path.stats, turned_round=True))


def _dense(pts: np.ndarray, res: float) -> np.ndarray:
    """Return the poses' polyline resampled at most an eighth of a cell apart (m)."""
    d = np.hypot(*np.diff(pts, axis=0).T)
    out = [pts[:1]]
    for i, di in enumerate(d):
        n = max(1, math.ceil(di / (res / 8.0)))
        f = (np.arange(1, n + 1) / n)[:, None]
        out.append(pts[i] + f * (pts[i + 1] - pts[i]))
    return np.vstack(out)


def _time_segment(options: PlannerOptions, seg: CarSegment) -> Trajectory:
    """Time a segment from rest to rest; backwards with ``v_max_reverse`` (module doc)."""
    robot = options.robot
    limits = robot
    if seg.direction < 0 and robot.v_max_backwards != robot.v_max:
        limits = dataclasses.replace(robot, v_max=robot.v_max_backwards)
    traj = time_parameterize(
        seg.smooth_path,
        limits,
        v_start=0.0,
        v_end=0.0,
        dt=options.timing_dt,
        speed_limits=options.speed_limits,
    )
    return dataclasses.replace(traj, robot=robot, direction=seg.direction)
