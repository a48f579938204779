"""Pose-to-pose plans of a car-like robot (``Robot(drive=trajopt.Ackermann(...))``).

A car faces its direction of travel (or its reverse), turns no tighter than its
``min_turning_radius`` ``R`` and cannot turn in place, so :func:`plan_car` plans in
(x, y, heading):

1. **Search** (:mod:`trajopt.planning._car_tries`). :func:`astar.find_pose_path`
   (Hybrid-A* with Reeds-Shepp shots, or Dubins shots when ``robot.drive.reverse`` is False) from
   the start pose to the goal pose, on the raw map inflated by the robot radius plus a
   margin, with a turning radius a little above ``R``; gentler or tighter radii and the grid
   inflated by the radius alone are the further tries, all within one budget of
   expansions (wall-clock limits only as safety nets); ``stats["car"]["tries"]`` lists
   them, ``stats["car"]["expansions"]`` counts their expansions.
2. **Segments** (:mod:`trajopt.planning._car_fit`). The path is split at its cusps (where
   the direction of travel flips; the heading is continuous there, the tangent flips by
   ``pi``). Each segment is fitted as an ordinary curve in the direction of travel in a
   certified polygon corridor, with the curvature bound ``1/R``, exact end points and exact
   end travel headings; a stretch that turns much and fits in no whole curve is fitted in
   pieces, each starting with the previous piece's end curvature where it can, and one that no
   fit fits is halved at its middle pose (twice at most). Every curve is the smoother's certified curve and
   its sampled curvature must be within ``1/R``; nothing else is returned. The smoother's
   budget per fit is capped at :data:`SEGMENT_BUDGET_S`.
3. **Timing.** Each drive (the segments between two stops: :func:`drive_groups`; the pieces
   of a stretch whose curves meet with the same curvature are driven through, their curves
   joined into one) is timed along its arc length from rest to rest
   (:func:`trajopt.time_parameterize`: ``v = 0`` at the ends and at every cusp), backwards
   ones with ``v_max_reverse`` as the speed limit, with the robot's curvature caps and,
   with ``steer_rate_max``, the steering-rate cap (:mod:`trajopt.timing._steer_cap`).

The result is a :class:`~trajopt.motion.TrajectoryChain` of one
:class:`~trajopt.motion.Trajectory` per drive (``direction`` ``+1`` or ``-1``), even for a
single one: its samples carry the signed ``v``, the body's ``theta`` (continuous across
cusps) and ``kappa``, ``direction`` and, with a ``wheelbase``, ``steer`` and ``steer_rate``.
Curvature (hence steering) is continuous within a drive (each B-spline is C2, and the
pieces driven through meet with the same curvature, where only the steering rate may
change); at a cusp (or a join where the curvatures differ, ``stats["car"]["rests"]``)
the car is at rest and steers there: with a ``wheelbase`` and a ``steer_rate_max`` a
:class:`~trajopt.motion.SteerInPlace` piece turns the steering angle at its rate limit
wherever it differs between two drives, and before the first drive from the request's
``start_steer`` (default 0) and after the last to its ``goal_steer`` when given
(:func:`with_steering`); without them the steering is not modelled. The chain checks
position, heading, speed, acceleration and yaw rate at every join (all continuous: the car
is at rest). Its ``steps`` are a :class:`CarSteps`.

A car with a :class:`~trajopt.robot.Footprint` (``Robot.rectangle(..., drive=trajopt.Ackermann(...))``;
the footprint's origin is the point the plan moves, e.g. the rear axle's centre) is planned
with its body facing its heading, forwards or backwards: its end poses must hold the body
clear of the map (:func:`~trajopt.planning._footprint_ladder.check_end_poses`); the search
runs in the footprint mode of :func:`astar.find_pose_path` (every pose of its arcs keeps the
oriented body off the raw map, the centre grid inflated by the inscribed radius only as a
necessary condition); each segment's corridor keeps the inscribed radius and its curve must
also pass the footprint certificate, with the body along the curve's tangent forwards and
turned by ``pi`` backwards (:func:`~trajopt.planning._car_fit.body_along`).

**Polygons.** On a grid that keeps the polygons it was rasterised from
(:attr:`astar.OccupancyGrid.polygons`, from :meth:`astar.OccupancyGrid.from_polygons`), a car
with a body is planned against the polygons, the cells only a conservative pre-filter: its
end poses (:func:`~trajopt.planning._footprint_ladder.check_end_poses` with ``polygons``),
the search's footprint tests (:attr:`astar.HybridCollision.raw_polygons`) and the band of
its centre grid (:func:`~trajopt.planning._car_tries.polygon_band`), and the fits of the
segments near them (the smoother on a finer raster of them,
:func:`~trajopt.planning._car_fit.fine_window`, the footprint certificate exact against the
polygons: :func:`trajopt.robot.certify_footprint`); it searches cells of at least ``R /``
:data:`SEARCH_CELLS_PER_RADIUS` (:func:`search_cells`). The guarantee is then that the body
is clear of the polygons at every instant; on a grid without polygons, of the occupied
cells, and such plans are the same as without this mode.

**Frame.** Nothing in a plan depends on where the map's origin is: the ends are checked in
the map's frame, then the search, the fits and the timing run in the map-local frame (the
grid's origin subtracted, so coordinates are at most the map's size), and the result is
moved back: each drive's curve is a :class:`~trajopt.geometry.ShiftedCurve` of its local
curve (positions moved, heading and curvature the local curve's), the steering at rest and
the steps' poses moved. Far from the origin (x near ``4.5e9`` m, where float64 positions
are only about ``1e-6`` m apart) the fits' end tangents stay exact, so the chain joins with
the same heading to the last bits; only the positions are rounded, to that spacing. With
the origin at ``(0, 0)`` nothing is moved. Messages of the search and fits then name
poses in the local frame (and say so).

Not supported (refused with :class:`~trajopt.errors.InvalidInputError`): a moving start or
end speeds other than 0, missing end headings, and the chapter's ``inflation="paper"``.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from astar.grid import OccupancyGrid
from trajopt.errors import InvalidInputError, TrajoptError
from trajopt.geometry import ShiftedCurve, concatenate
from trajopt.motion import Trajectory, TrajectoryChain, steer_in_place
from trajopt.planning._caches import PlannerCaches
from trajopt.planning._car_escape import escape_and_fit, escape_applies
from trajopt.planning._car_fit import CarSegment
from trajopt.planning._car_tries import search_and_fit
from trajopt.planning._ends import check_endpoint
from trajopt.planning._footprint_ladder import check_end_poses
from trajopt.planning._options import PlannerOptions, PlanRequest
from trajopt.planning._query import StageTimer
from trajopt.robot import Robot, State
from trajopt.smoother import SmoothPath
from trajopt.timing import time_parameterize
from trajopt.validation import point

#: Cap (s) on the smoother's time budget per segment fit.
SEGMENT_BUDGET_S = 2.0
#: Largest relative difference of the curvatures at a join the car drives through
#: (:func:`drive_groups`): a piece fitted with the previous piece's end curvature matches
#: it to 1e-10 or so; a piece fitted without it rests at the join.
JOIN_KAPPA_TOL = 1e-6


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
        The grid searched (:func:`~trajopt.planning._car_tries.car_search_grid`).
    pose_path : astar.PosePath
        The Hybrid-A* path (cells; :meth:`astar.PosePath.to_world`).
    poses : ndarray, shape (n, 3)
        Its poses in world units ``(x, y, heading)`` (m, m, rad).
    segments : tuple of CarSegment
        One per stretch between cusps, or per piece of a stretch fitted in pieces
        (:attr:`~trajopt.planning._car_fit.CarSegment.joined`).
    drives : tuple of tuple of int
        The segments timed as each piece of the chain (:func:`drive_groups`), in order.
    start, goal : tuple of float
        The end points (m).
    start_heading, goal_heading : float
        The end headings (rad).
    start_steer : float
        The steering angle at the start (rad).
    goal_steer : float or None
        The steering angle asked for at the goal (rad), or ``None``.
    origin : tuple of float
        The map's origin (m): :attr:`segments` (their corridors and curves) are in the
        map-local frame, this offset subtracted (:attr:`corridor` adds it back); the rest is
        in the map's frame.
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
    drives: tuple
    start: tuple[float, float]
    goal: tuple[float, float]
    start_heading: float
    goal_heading: float
    stages_s: dict[str, float]
    search_turning_radius: float
    start_steer: float = 0.0
    goal_steer: float | None = None
    origin: tuple[float, float] = (0.0, 0.0)

    @property
    def corridor(self) -> CarCorridor:
        """Every segment's regions (:class:`CarCorridor`), in the map's frame."""
        regions = tuple(r for s in self.segments for r in s.corridor.regions)
        if self.origin != (0.0, 0.0):
            # the certified local regions moved; not validated again (far from the origin a
            # thin polygon's float64 area may round to 0)
            o = np.asarray(self.origin, dtype=float)
            regions = tuple(
                type(r)._construct_fast(r.A, r.b + r.A @ o, r.vertices + o, r.degenerate)
                for r in regions
            )
        return CarCorridor(regions)

    @property
    def smooth_path(self) -> SmoothPath:
        """The first segment's curve (each segment's is in :attr:`segments`; map-local)."""
        return self.segments[0].smooth_path


def plan_car(
    options: PlannerOptions, caches: PlannerCaches, request: PlanRequest
) -> TrajectoryChain:
    """Plan one query of a car-like robot (module docstring).

    Parameters
    ----------
    options : PlannerOptions
        Resolved for the map of ``caches``; ``options.robot.drive`` an :class:`~trajopt.drive.Ackermann`.
    caches : PlannerCaches
        The map.
    request : PlanRequest
        Start and goal points (m) with both headings (rad), at rest (a :class:`State`
        start at rest counts as its position and heading).

    Returns
    -------
    TrajectoryChain
        One :class:`~trajopt.motion.Trajectory` per drive (between cusps, and at the
        joins of a stretch fitted in pieces whose curvatures differ), each from rest to
        rest, and the steering at rest between them (:func:`with_steering`).

    Raises
    ------
    InvalidInputError
        ``inflation="paper"``, a heading missing, a moving start or an end speed other than
        0, an end point off the map or too close to an obstacle (a footprint: its body at
        the end pose meets an obstacle), or one blocked on the search grid.
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
    world = caches.grid
    p0w, p1w, h0, h1 = _ends(options, world, request)  # checked in the map's frame
    # everything else in the map-local frame (module docstring, "Frame")
    origin = np.asarray(world.origin, dtype=float)
    local = bool(np.any(origin != 0.0))
    grid = world.moved_to((0.0, 0.0)) if local else world  # its polygons moved with it
    grid = search_cells(robot, grid)
    p0, p1 = (p0w - origin, p1w - origin) if local else (p0w, p1w)
    res = grid.resolution
    start = _to_cells(grid, p0, h0)
    goal = _to_cells(grid, p1, h1)
    kmax = 1.0 / robot.drive.min_turning_radius
    sm = options.smoother
    sm = dataclasses.replace(
        sm,
        kappa_max=kmax if sm.kappa_max is None else min(sm.kappa_max, kmax),
        time_budget_s=min(sm.time_budget_s, SEGMENT_BUDGET_S),
    )
    try:
        last_try = escape_and_fit if escape_applies(robot, grid) else None
        found = search_and_fit(options, grid, (start, goal), (p0w, p1w), sm, timer, last_try)
    except TrajoptError as exc:
        if local and exc.args:
            exc.args = (
                f"{exc.args[0]} (poses in m in the map-local frame, the map's origin "
                f"{world.origin} m subtracted)",
            ) + exc.args[1:]
        raise
    search_grid, path, radius_cells = found.search_grid, found.path, found.radius_cells
    poses, segments, tries = found.poses, found.segments, found.tries
    drives = drive_groups(segments)
    zones = options.speed_limits
    timing = options  # the zones moved into the local frame with the curves
    if local and zones is not None:
        z0 = (zones.origin[0] - origin[0], zones.origin[1] - origin[1])
        timing = dataclasses.replace(options, speed_limits=dataclasses.replace(zones, origin=z0))
    moves: list[Trajectory] = []
    for group in drives:
        with timer.stage("timing"):
            moves.append(_time_drive(timing, [segments[i] for i in group]))
    if local:  # back in the map's frame: positions moved, the local curves' geometry kept
        moves = [
            dataclasses.replace(m, path=ShiftedCurve(m.path, origin), speed_limits=zones)
            for m in moves
        ]
        search_grid = OccupancyGrid(search_grid.occupied, search_grid.resolution, world.origin)
        poses = poses + np.array([origin[0], origin[1], 0.0])
    pieces, steered = with_steering(robot, moves, request.start_steer, request.goal_steer)
    stages = timer.finish()
    steps = CarSteps(
        raw_grid=world,
        inflated_grid=search_grid,
        pose_path=path,
        poses=poses,
        segments=tuple(segments),
        drives=tuple(drives),
        start=(float(p0w[0]), float(p0w[1])),
        goal=(float(p1w[0]), float(p1w[1])),
        start_heading=h0,
        goal_heading=h1,
        stages_s=stages,
        search_turning_radius=radius_cells * res,
        start_steer=request.start_steer,
        goal_steer=request.goal_steer,
        origin=(float(origin[0]), float(origin[1])),
    )
    stats: dict[str, Any] = {
        "stages_s": dict(stages),
        "car": {
            "segments": len(segments),
            "cusps": int(path.cusps),
            "directions": [s.direction for s in segments],
            "joins": sum(s.joined for s in segments),
            "rests": len(drives) - 1 - int(path.cusps),
            "reverse_length_m": float(path.reverse_length * res),
            "search_length_m": float(path.length * res),
            "search_turning_radius_m": radius_cells * res,
            "tries": tries,
            "expansions": found.expansions,
            "corridors": [s.corridor_kind for s in segments],
            "steer_at_rest": steered,
            "search": dict(path.stats),
        },
        "inflation": options.inflation,
    }
    return TrajectoryChain(tuple(pieces), robot, stats, steps)


#: Turning radius of a car with a body, in cells of the grid it searches, below which
#: :func:`search_cells` keeps the map's cells as they are.
SEARCH_CELLS_PER_RADIUS = 30.0


def search_cells(robot: Robot, grid: OccupancyGrid) -> OccupancyGrid:
    """Return the grid a car with a body plans on: ``grid``, or its polygons' coarser cells.

    Where ``grid`` knows the polygons it was rasterised from
    (:attr:`astar.OccupancyGrid.polygons`) the body is tested exactly against them and the
    cells are only a conservative pre-filter, so their size need not follow the map's: a
    map finer than :data:`SEARCH_CELLS_PER_RADIUS` cells per turning radius is planned on
    ``grid.coarsen(k)`` (cells ``k`` times larger, at most that fine; the polygons kept), so
    that the search's states and primitives follow the car rather than the raster. A grid
    without polygons, or a disc car, is returned as it is.
    """
    if robot.footprint is None or grid.polygons is None:
        return grid
    k = int(
        math.floor(
            robot.drive.min_turning_radius / SEARCH_CELLS_PER_RADIUS / grid.resolution + 1e-9
        )
    )
    return grid.coarsen(k) if k > 1 else grid


#: Smallest change of the steering angle (rad) a car steers at rest for: below it the
#: drives meet as they are (a rate of at most 1e-12 rad per sample interval).
STEER_AT_REST_MIN_RAD = 1e-12


def with_steering(
    robot: Robot, drives: list[Trajectory], start_steer: float, goal_steer: float | None
) -> tuple[list, list[dict[str, float]]]:
    """Return a car's chain pieces: its drives with the steering at rest between them.

    The steering angle of a drive is ``atan(wheelbase * kappa)`` of its body's curvature,
    continuous within it; at its ends the car is at rest. Where the steering angle at the
    end of one drive differs from the start of the next (a cusp, or a rest inside a stretch
    fitted in pieces), before the first drive (from ``start_steer``) and after the last
    (to ``goal_steer`` when given), a :class:`~trajopt.motion.SteerInPlace` turns it at
    ``steer_rate_max`` (changes above :data:`STEER_AT_REST_MIN_RAD`). Only for a car with
    a ``wheelbase`` and a ``steer_rate_max``: without them the steering is not modelled
    and the drives are returned as they are.

    Parameters
    ----------
    robot : Robot
        The car.
    drives : list of Trajectory
        Its drives, each from rest to rest, in order.
    start_steer : float
        Steering angle at the start (rad).
    goal_steer : float or None
        Steering angle asked for at the goal (rad), or ``None``.

    Returns
    -------
    pieces : list
        The drives and the steering at rest between them, in order.
    steered : list of dict
        Per steering at rest: ``at`` (``"start"``, ``"cusp"``, ``"rest"`` or ``"goal"``),
        ``steer_rad`` (signed change) and ``duration_s``.
    """
    steering = robot.drive.steering
    if steering is None or steering.rate_max is None:
        return list(drives), []
    pieces: list = []
    steered: list[dict[str, float]] = []

    def steer(smp: Any, k: int, delta0: float, delta1: float, direction: int, at: str) -> None:
        if abs(delta1 - delta0) <= STEER_AT_REST_MIN_RAD:
            return
        p = np.array([float(smp.x[k]), float(smp.y[k])])
        piece = steer_in_place(robot, p, float(smp.theta[k]), delta0, delta1, direction)
        pieces.append(piece)
        steered.append({"at": at, "steer_rad": piece.steer_rad, "duration_s": piece.duration})

    delta = float(start_steer)
    for i, drive in enumerate(drives):
        ends = drive.sample(np.array([0.0, drive.duration]))
        first = float(np.arctan(steering.wheelbase * ends.kappa[0]))
        at = (
            "start"
            if i == 0
            else ("cusp" if drive.direction != drives[i - 1].direction else "rest")
        )
        steer(ends, 0, delta, first, drive.direction, at)
        pieces.append(drive)
        delta = float(np.arctan(steering.wheelbase * ends.kappa[1]))
        last = ends
    if goal_steer is not None:
        steer(last, 1, delta, float(goal_steer), drives[-1].direction, "goal")
    return pieces, steered


def _ends(
    options: PlannerOptions, grid: OccupancyGrid, request: PlanRequest
) -> tuple[np.ndarray, np.ndarray, float, float]:
    """Return the checked end points (m) and headings (rad) of a car's query."""
    robot = options.robot
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
    h0, h1 = float(h0), float(request.goal_heading)
    if robot.footprint is not None:
        ends = dataclasses.replace(request, start=p0, start_heading=h0, goal=p1, goal_heading=h1)
        check_end_poses(robot.footprint, grid, ends, polygons=True)
    # a body checked against the map's polygons holds its inscribed disc clear of them:
    # only the map's extent is checked (its cells may touch the disc)
    exact = robot.footprint is not None and grid.polygons is not None
    radius = 0.0 if exact else robot.inscribed_radius
    for name, p in (("start", p0), ("goal", p1)):
        if exact:
            c = grid.world_to_cell(p)
            if not grid.in_bounds(c):
                check_endpoint(options, grid, name, p, radius)  # raises: off the map
        else:
            check_endpoint(options, grid, name, p, radius)
    return p0, p1, h0, h1


def _to_cells(grid: OccupancyGrid, p: np.ndarray, heading: float) -> tuple[float, float, float]:
    """Return a world pose as the search's cell pose (``world = origin + (xy + 0.5) res``)."""
    xy = (np.asarray(p, dtype=float) - np.asarray(grid.origin, dtype=float)) / grid.resolution
    return float(xy[0] - 0.5), float(xy[1] - 0.5), float(heading)


def drive_groups(segments: list[CarSegment]) -> list[tuple[int, ...]]:
    """Return the segments the car drives through without stopping, as index groups.

    A segment that continues the previous one (:attr:`CarSegment.joined`, a stretch fitted
    in pieces) joins its group when its curve starts with the previous curve's end
    curvature (to :data:`JOIN_KAPPA_TOL`, relative to the larger of the two, or of 1e-9
    1/m): the two curves then meet with the same point, heading and curvature, so
    the car drives through the join (one piece of the chain, timed along both). Otherwise
    the car rests there, as at a cusp.
    """
    groups: list[list[int]] = []
    for i, seg in enumerate(segments):
        if groups and seg.joined and _same_curvature(segments[i - 1], seg):
            groups[-1].append(i)
        else:
            groups.append([i])
    return [tuple(g) for g in groups]


def _same_curvature(a: CarSegment, b: CarSegment) -> bool:
    """Whether ``b``'s curve starts with the curvature ``a``'s ends with (drive_groups)."""
    pa, pb = a.smooth_path, b.smooth_path
    ka = float(np.asarray(pa.curvature(np.array([pa.domain[1]])))[0])
    kb = float(np.asarray(pb.curvature(np.array([pb.domain[0]])))[0])
    return abs(ka - kb) <= JOIN_KAPPA_TOL * max(abs(ka), abs(kb), 1e-9)


def _time_drive(options: PlannerOptions, segs: list[CarSegment]) -> Trajectory:
    """Time segments driven through (one curve: :func:`drive_groups`) from rest to rest.

    Backwards with ``v_max_reverse`` (module docstring). Several segments are timed along
    their curves joined into one (:func:`~trajopt.geometry._bspline.concatenate`).
    """
    robot = options.robot
    seg = segs[0]
    path = seg.smooth_path
    if len(segs) > 1:
        path = concatenate([s.smooth_path.curve for s in segs])
    limits = robot
    if seg.direction < 0 and robot.drive.v_max_backwards(robot) != robot.v_max:
        limits = dataclasses.replace(robot, v_max=robot.drive.v_max_backwards(robot))
    traj = time_parameterize(
        path,
        limits,
        v_start=0.0,
        v_end=0.0,
        dt=options.timing_dt,
        speed_limits=options.speed_limits,
    )
    return dataclasses.replace(traj, robot=robot, direction=seg.direction)
