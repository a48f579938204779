"""Pose-to-pose plans of a differential drive: required end headings, met by turning in place.

A differential drive can turn where it stands, so a start or goal heading that no certified
curve can leave (arrive) along is met by a turn in place at that end. With ``start_heading``
or ``goal_heading`` given (and the robot at rest at that end), :func:`plan_pose` decides
among candidates by total duration, turn time included:

* **turn, drive, turn**: the curve planned with the heading left free at each end where the
  robot may turn (the plan of :func:`~trajopt.planning._disc.plan_disc` without those
  headings), and a rest-to-rest turn in place (:func:`trajopt.timing.turn_in_place`) from
  the given heading onto the curve's and from the curve's onto the given one. It exists
  whenever the free curve does, and is the reference the others must beat.
* **pinned**: the curve with the given headings as its end tangents (the smoother's exact
  end headings), tried only where the turn it saves is at most :data:`PIN_TRY_RAD` (a curve
  that must leave far off the corridor's direction rarely exists and is slower than a turn
  when it does), on the free plan's grid path and corridor regions (no second search) and
  with the smoother's budget capped at :data:`PIN_BUDGET_S`, so that a heading no curve can
  take costs little. An end that is pinned needs no turn; the other end still turns.

When the free candidate is the opt-in stop-and-turn fallback, its polyline is driven again
with the requested end headings (it turns in place at its ends itself). Otherwise the
result is a :class:`~trajopt.motion.TrajectoryChain` of the turns and the curve when a
turn is needed (continuous in position and heading, at rest at every join, each piece
within its limits), else the curve itself. ``stats["pose"]`` records the candidates'
durations and the one chosen.

A footprint robot turns in place only where the footprint swept over the turn is certified
clear: the turn is cut into pieces of at most :data:`TURN_PIECE_RAD`, each bounded by the
convex hull of the footprint swept over it (:meth:`~trajopt.robot.Footprint.swept_hull`),
whose exact clearance from the raw map must be positive. Where no candidate remains, the
query is refused with a :class:`~trajopt.errors.SmoothingError` naming the end, the heading
and the reasons.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from astar.grid import OccupancyGrid
from trajopt.errors import SmoothingError, TimingError
from trajopt.motion import PlanResult, StopAndTurnTrajectory, TrajectoryChain
from trajopt.planning._footprint_ladder import check_end_poses
from trajopt.planning._options import PlannerOptions, PlanRequest
from trajopt.planning._query import WarmStart
from trajopt.robot import Footprint, Robot, State, polygons_clearance
from trajopt.timing import stop_and_turn, turn_in_place

#: A pinned end heading is tried only when the turn it would save is at most this (rad).
PIN_TRY_RAD = 0.8
#: Cap on the smoother's time budget for a pinned candidate (s).
PIN_BUDGET_S = 0.25
#: A footprint's turn in place is certified in pieces of at most this angle (rad).
TURN_PIECE_RAD = math.pi / 8


def needs_pose_plan(request: PlanRequest) -> bool:
    """Whether :func:`plan_pose` applies: a base that turns in place, at an end it may turn."""
    return bool(_turn_ends(at_rest(request)))


def at_rest(request: PlanRequest) -> PlanRequest:
    """Return the request with a start :class:`State` at rest as a point and a heading.

    A robot standing still (``v = a = 0``) may turn in place before it drives; a moving one
    must leave along its heading (the request is returned unchanged).
    """
    s = request.start
    given = request.start_heading is not None or request.v_start != 0.0  # the stages refuse
    if isinstance(s, State) and s.v == 0.0 and s.a == 0.0 and not given:
        return dataclasses.replace(request, start=s.position, start_heading=s.theta)
    return request


def _turn_ends(request: PlanRequest) -> list[str]:
    """Return the ends with a given heading where the robot rests, so it may turn there."""
    ends = []
    if (
        request.start_heading is not None
        and request.v_start == 0.0
        and not isinstance(request.start, State)
    ):
        ends.append("start")
    if request.goal_heading is not None and request.v_end == 0.0:
        ends.append("goal")
    return ends


def plan_pose(
    options: PlannerOptions,
    grid: OccupancyGrid,
    request: PlanRequest,
    plan: Callable[[PlanRequest, WarmStart | None, float | None], PlanResult],
    warm: WarmStart | None = None,
) -> PlanResult:
    """Plan a query whose given end headings may be met by turning in place (module doc).

    Parameters
    ----------
    options : PlannerOptions
        The planner's options (a differential drive).
    grid : astar.OccupancyGrid
        The raw map (the turns of a footprint robot are certified against it).
    request : PlanRequest
        The query; :func:`needs_pose_plan` holds for it.
    plan : callable
        ``plan(request, warm, budget_s) -> trajectory``: the planner's query for a request
        (a disc's stages or a footprint's ladder), raising its typed errors.
    warm : WarmStart, optional
        A re-plan's warm start, for the free candidate.

    Returns
    -------
    Trajectory, StopAndTurnTrajectory or TrajectoryChain
        Starting at ``start_heading`` and ending at ``goal_heading`` (modulo ``2 pi``).

    Raises
    ------
    NoPathError, InvalidInputError, SmoothingError, TimingError
        The free candidate's errors; ``SmoothingError`` when a footprint cannot turn at an
        end and no curve leaves (arrives) along the given heading.
    """
    t_start = time.perf_counter()
    robot = options.robot
    request = at_rest(request)
    if robot.footprint is not None:  # a pose the footprint cannot take is refused first
        check_end_poses(robot.footprint, grid, request)
    turn_ends = _turn_ends(request)
    free_request = dataclasses.replace(
        request,
        start_heading=None if "start" in turn_ends else request.start_heading,
        goal_heading=None if "goal" in turn_ends else request.goal_heading,
    )
    free = plan(free_request, warm, None)
    if free.polyline:  # the fallback turns at its ends itself
        return _with_headings(free, robot, options, request)
    first = free.sample(np.array([0.0, free.duration]))
    curve_heading = {"start": float(first.theta[0]), "goal": float(first.theta[1])}
    given = {"start": request.start_heading, "goal": request.goal_heading}
    delta = {e: abs(_angle(given[e] - curve_heading[e])) for e in turn_ends}

    reasons: list[str] = []
    candidates: dict[str, Any] = {}
    blocked = {
        e: _turn_blocked(robot, grid, free, e, given[e], curve_heading[e]) for e in turn_ends
    }
    if not any(blocked.values()):
        candidates["turn"] = _chain(robot, free, turn_ends, given, curve_heading)
    else:
        reasons += [f"{e}: {why}" for e, why in blocked.items() if why]

    pin = [e for e in turn_ends if delta[e] > 1e-9 and (delta[e] <= PIN_TRY_RAD or blocked[e])]
    if pin:
        pinned_request = dataclasses.replace(
            free_request,
            start_heading=request.start_heading if "start" in pin else free_request.start_heading,
            goal_heading=request.goal_heading if "goal" in pin else free_request.goal_heading,
        )
        steps = getattr(free, "steps", None)
        pin_warm = None if steps is None else WarmStart(steps.grid_path, steps)
        try:
            pinned = plan(pinned_request, pin_warm, PIN_BUDGET_S)
        except (SmoothingError, TimingError) as exc:
            reasons.append(f"no curve with the {' and '.join(pin)} heading pinned: {exc}")
        else:
            rest = [e for e in turn_ends if e not in pin]
            ends = pinned.sample(np.array([0.0, pinned.duration]))
            pinned_heading = {"start": float(ends.theta[0]), "goal": float(ends.theta[1])}
            stuck = {
                e: _turn_blocked(robot, grid, pinned, e, given[e], pinned_heading[e]) for e in rest
            }
            if any(stuck.values()):
                reasons += [f"{e}: {why}" for e, why in stuck.items() if why]
            else:
                candidates["pinned"] = _chain(robot, pinned, rest, given, pinned_heading)
    if not candidates:
        where = "; ".join(
            f"{e} heading {given[e]:.6g} rad at {_end_point(free, e)} m" for e in turn_ends
        )
        raise SmoothingError(
            f"{where}: the footprint cannot turn in place there and no certified curve "
            f"leaves (arrives) along it ({'; '.join(reasons)})",
            {"pose_failures": reasons},
        )
    chosen = min(candidates, key=lambda k: candidates[k].duration)
    out = candidates[chosen]
    steps = getattr(out, "steps", None)
    if steps is not None:  # the headings asked for, not the free curve's
        steps = dataclasses.replace(
            steps, start_heading=request.start_heading, goal_heading=request.goal_heading
        )
    stats = dict(out.stats)
    # the stages are the chosen candidate's; the total is the whole query's
    stats["stages_s"] = dict(stats.get("stages_s", {}), total=time.perf_counter() - t_start)
    stats["pose"] = {
        "chosen": chosen,
        "durations_s": {k: float(v.duration) for k, v in candidates.items()},
        "turn_start_rad": _turn_of(out, 0),
        "turn_goal_rad": _turn_of(out, -1),
        "free_heading_rad": curve_heading,
        "rejected": reasons,
    }
    return dataclasses.replace(out, stats=stats, steps=steps)


def _with_headings(
    free: StopAndTurnTrajectory, robot: Robot, options: PlannerOptions, request: PlanRequest
) -> StopAndTurnTrajectory:
    """Return the fallback's polyline driven again with the requested end headings."""
    out = stop_and_turn(
        free.vertices,
        robot,
        start_heading=request.start_heading,
        goal_heading=request.goal_heading,
        speed_limits=options.speed_limits,
    )
    steps = free.steps
    if steps is not None:
        steps = dataclasses.replace(
            steps, start_heading=request.start_heading, goal_heading=request.goal_heading
        )
    return dataclasses.replace(out, stats=dict(free.stats), steps=steps)


def _chain(
    robot: Robot,
    curve: PlanResult,
    ends: list[str],
    given: dict[str, float | None],
    heading: dict[str, float],
) -> TrajectoryChain:
    """Return the curve with turns in place at ``ends`` from/onto the given headings."""
    pieces: list[PlanResult] = []
    if "start" in ends:
        p0 = _end_point(curve, "start", exact=True)
        turn = turn_in_place(p0, float(given["start"]), heading["start"], robot)
        if turn.duration > 0.0:
            pieces.append(turn)
    pieces.append(curve)
    if "goal" in ends:
        p1 = _end_point(curve, "goal", exact=True)
        turn = turn_in_place(p1, heading["goal"], float(given["goal"]), robot)
        if turn.duration > 0.0:
            pieces.append(turn)
    if len(pieces) == 1:
        return curve
    stats = dict(curve.stats)
    return TrajectoryChain(tuple(pieces), robot, stats, getattr(curve, "steps", None))


def _turn_of(traj: PlanResult, i: int) -> float:
    """Signed turn (rad) of the chain's first (``i = 0``) or last (``-1``) piece, else 0."""
    pieces = getattr(traj, "pieces", ())
    if pieces and pieces[i].turning:
        return float(pieces[i].turn_rad)
    return 0.0


def _turn_blocked(
    robot: Robot, grid: OccupancyGrid, curve: PlanResult, end: str, given: float, heading: float
) -> str:
    """Why the robot cannot turn between ``given`` and ``heading`` at the curve's end ('' if it can)."""
    fp = robot.footprint
    d = _angle(heading - given) if end == "start" else _angle(given - heading)
    if fp is None or abs(d) <= 1e-12:
        return ""  # a disc is clear at its centre in every heading
    lo = given if end == "start" else heading
    if turn_clear(fp, grid, _end_point(curve, end, exact=True), lo, d):
        return ""
    return (
        f"the footprint cannot turn in place at {_end_point(curve, end)} m from {lo:.6g} rad "
        f"by {d:.6g} rad"
    )


def turn_clear(
    fp: Footprint, grid: OccupancyGrid, xy: ArrayLike, theta0: float, turn: float
) -> bool:
    """Whether the footprint turning in place at ``xy`` by ``turn`` (rad) from ``theta0`` is clear.

    Certified: the turn is cut into pieces of at most :data:`TURN_PIECE_RAD`; the convex
    hull of the footprint swept over each piece contains every pose of that piece, and each
    hull must keep a positive exact clearance from the raw map (outside counts occupied).
    """
    lo, hi = sorted((theta0, theta0 + turn))
    n = max(1, math.ceil((hi - lo) / TURN_PIECE_RAD))
    edges = np.linspace(lo, hi, n + 1)
    x, y = float(xy[0]), float(xy[1])
    hulls = [
        fp.swept_hull(a, b) + np.array([x, y]) for a, b in zip(edges[:-1], edges[1:], strict=True)
    ]
    clr = polygons_clearance(hulls, grid, grid.resolution)
    return bool(np.all(clr > 0.0))


def _end_point(traj: PlanResult, end: str, exact: bool = False) -> tuple[float, float]:
    """Return the start or end point (m), rounded to 1 um for messages unless ``exact``."""
    smp = traj.sample(np.array([0.0 if end == "start" else traj.duration]))
    x, y = float(smp.x[0]), float(smp.y[0])
    return (x, y) if exact else (round(x, 6), round(y, 6))


def _angle(a: float) -> float:
    """Return ``a`` wrapped to ``[-pi, pi]`` (rad)."""
    return math.remainder(float(a), 2.0 * math.pi)
