"""Re-planning a car-like robot (``Robot(drive="ackermann")``): keep, or brake and plan anew.

A car cannot turn in place, and its plans (:func:`trajopt.planning._car.plan_car`) run from
rest to rest with cusps where the direction of travel flips; the trajectory being driven is a
:class:`~trajopt.motion.TrajectoryChain` of one :class:`~trajopt.motion.Trajectory` per
segment (``direction`` ``+1`` or ``-1``). :func:`replan_car` takes, at the splice time, the
first of:

1. **Keep** (``reuse=True``): when the goal, the goal heading and the end speed are the old
   ones, the rest of the chain (cut at the splice, :meth:`TrajectoryChain.after`) is the
   answer if the map did not change, or if it changed without freeing a cell of the car's
   search grid (a freed cell may open a better route) and every point of the rest keeps the
   robot radius from the cells occupied since the plan. The rest was clear of the old map
   (each segment's certificate; a braking piece was checked the same way when it was made),
   so it is checked only against the new cells, on samples ``ds`` apart along its arc length,
   each at least ``radius + ds / 2`` from them (the distance to a set of cells is
   1-Lipschitz along the path). ``stats["replan"] == "kept"``.
2. **Brake along the current segment and plan from rest**: from the splice state
   ``(s, v, a)`` on the segment playing then, the time-optimal jerk-limited stop along that
   segment's own curve, in its direction of travel
   (:func:`~trajopt.replan._brake.brake_on_path`; forwards or backwards, the speed keeps its
   sign and falls monotonically to 0). The curve is the old, certified one; against a changed
   map the stop is checked as the kept rest is, and a car that cannot stop before a new
   obstacle is a :class:`~trajopt.errors.TimingError`. From the stopped pose (its position
   and the *body's* heading, not the travel tangent) a new car plan runs to the goal pose
   (Hybrid-A*, segments, certified curves, timing: it may reverse and have cusps). The two
   join at rest (``v = a = 0``) with the same position, heading and steering angle (the
   new plan starts with the steering angle where the car stopped, and steers at rest from
   it where it has a ``wheelbase`` and a ``steer_rate_max``; a splice while the car steers
   at rest, a :class:`~trajopt.motion.SteerInPlace`, stops the steering there); the car
   never turns in place. The old plan's ``goal_steer`` is kept for the same goal pose. A car already at rest at the splice (at the start, at a cusp, or at the end of a
   brake) plans from its pose directly. ``stats["replan"]`` is ``"braked: <why not kept>"``
   (or ``"planned: <why not kept>"`` at rest) and ``stats["brake_m"]``,
   ``stats["brake_s"]`` describe the stop (``turn_rad`` and ``turn_s`` are 0).

There is no smooth re-plan from the moving state (the car's pipeline plans from rest). A goal
no path reaches from the stop is a :class:`~trajopt.errors.NoPathError` that says where the
car stopped; so is a stop too close to a new obstacle to start a search from (blocked on the
search grid, which keeps the radius plus a margin).
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Sequence

import numpy as np

from astar.grid import OccupancyGrid
from trajopt.errors import InvalidInputError, NoPathError, TrajoptError
from trajopt.geometry import points_clearance
from trajopt.motion import PlanResult, SteerInPlace, Trajectory, TrajectoryChain
from trajopt.planning import (
    CarSteps,
    PlannerCaches,
    PlannerOptions,
    PlanRequest,
    car_search_grid,
    check_endpoint,
    run_query,
)
from trajopt.replan._brake import brake_on_path, check_new_obstacles
from trajopt.replan._keep import target_change
from trajopt.replan._marked import MarkedCarSteps, planned_on
from trajopt.validation import point


def replan_car(
    options: PlannerOptions,
    caches: PlannerCaches,
    trajectory: PlanResult,
    ts: float,
    goal: Sequence[float],
    *,
    goal_heading: float | None,
    v_end: float,
    reuse: bool,
) -> TrajectoryChain:
    """Return a car-like robot's re-plan from ``trajectory`` at ``ts`` (module docstring).

    Parameters
    ----------
    options : PlannerOptions
        The re-planning planner's options (``options.robot.drive == "ackermann"``).
    caches : PlannerCaches
        Its caches, with the current map.
    trajectory : TrajectoryChain
        The car's trajectory being driven: a plan of this planner's robot (a chain of
        :class:`~trajopt.motion.Trajectory` pieces with :class:`CarSteps`), or an
        earlier re-plan of one.
    ts : float
        The splice time on its clock (s), in ``[0, duration]``.
    goal : sequence of float, shape (2,)
        The goal (m).
    goal_heading : float or None
        The goal heading (rad); ``None`` only when ``goal`` is the old goal (then the old
        heading).
    v_end : float
        Speed at the goal (m/s): 0 (a car plans to rest).
    reuse : bool
        ``False``: never keep the rest (always brake, or plan from rest).

    Returns
    -------
    TrajectoryChain
        Time 0 at the splice; the kept rest, or the stop (if moving) then the new plan's
        segments; samples are :class:`~trajopt.motion.CarSample`.

    Raises
    ------
    InvalidInputError
        ``trajectory`` is not a car plan of this robot; ``v_end`` is not 0; no goal
        heading for a new goal; the goal off the map or too close to an obstacle.
    TimingError
        The car cannot stop on its segment before a new obstacle.
    NoPathError, SmoothingError
        No plan from the stopped pose (the message says where the car stopped and why it
        re-planned).
    """
    t0 = time.perf_counter()
    robot = options.robot
    steps = _check_trajectory(options, trajectory)
    if v_end != 0.0:
        raise InvalidInputError(
            f"v_end must be 0 for a car-like robot (drive='ackermann'), which plans to rest; "
            f"got {v_end!r}"
        )
    p_goal = point("goal", goal)
    if goal_heading is None:
        if tuple(p_goal.tolist()) != tuple(steps.goal):
            raise InvalidInputError(
                "goal_heading (rad) is required with a new goal for a car-like robot "
                f"(drive='ackermann'): goal {p_goal.tolist()} m differs from the old goal "
                f"{list(steps.goal)} m"
            )
        goal_heading = steps.goal_heading
    goal_heading = float(goal_heading)
    if not math.isfinite(goal_heading):
        raise InvalidInputError(f"goal_heading must be finite (rad), got {goal_heading!r}")
    why = "reuse=False"
    if reuse:
        kept, why = _keep(options, caches, trajectory, steps, ts, p_goal, goal_heading)
        if kept is not None:
            elapsed = time.perf_counter() - t0
            stats = dict(kept.stats, stages_s={"keep": elapsed, "total": elapsed})
            return dataclasses.replace(kept, stats=stats)
    search_grid = car_search_grid(robot, caches.grid)
    _check_end(options, caches.grid, search_grid, "goal", p_goal)
    i, tau = trajectory.piece_at(ts)
    piece = trajectory.pieces[i]
    brake = None if piece.steering_at_rest else _brake(piece, tau)
    pieces: list[Trajectory] = []
    if brake is not None:
        check_new_obstacles(robot, caches.grid, steps, brake)
        pieces.append(brake)
        stop = brake.sample(np.array([brake.duration]))
    else:
        stop = piece.sample(np.array([tau]))
    p_stop = (float(stop.x[0]), float(stop.y[0]))
    h_stop = float(stop.theta[0])
    # the steering angle where the car stands (it may be steering at rest): the new plan's
    steer_stop = 0.0 if getattr(stop, "steer", None) is None else float(stop.steer[0])
    same_goal = (tuple(p_goal.tolist()), goal_heading) == (tuple(steps.goal), steps.goal_heading)
    goal_steer = steps.goal_steer if same_goal else None
    if brake is None and _at_pose(p_stop, h_stop, p_goal, goal_heading):
        # standing at the goal pose already: nothing to drive (a rest of duration 0), or the
        # rest of the steering at rest being played there
        stats = dict(trajectory.stats, replan=f"planned: {why}; at the goal pose")
        stats.update(brake_m=0.0, brake_s=0.0, turn_rad=0.0, turn_s=0.0)
        if piece.steering_at_rest and tau < piece.duration:
            return TrajectoryChain((piece,), robot, stats, steps, (tau,))
        last = piece if tau >= piece.duration or i == 0 else trajectory.pieces[i - 1]
        return TrajectoryChain((last,), robot, stats, steps, (last.duration,))
    request = PlanRequest(
        p_stop,
        p_goal,
        start_heading=h_stop,
        goal_heading=goal_heading,
        start_steer=steer_stop,
        goal_steer=goal_steer,
    )
    where = (
        f"from rest at pose ({p_stop[0]:.6g} m, {p_stop[1]:.6g} m, {h_stop:.6g} rad)"
        + (f" after braking {brake.length:.4g} m" if brake is not None else "")
        + f", re-planned since {why}"
    )
    try:
        _check_end(options, caches.grid, search_grid, "start", np.array(p_stop))
    except InvalidInputError as exc:  # not the caller's input: where the car had to stop
        raise NoPathError(f"no plan {where}: {exc}") from exc
    try:
        out = run_query(options, caches, request)
    except TrajoptError as exc:
        exc.args = (f"{exc.args[0]} (planned {where})",) + exc.args[1:]
        raise
    pieces.extend(out.pieces)
    stats = dict(out.stats)
    stats.update(
        replan=f"{'braked' if brake is not None else 'planned'}: {why}",
        brake_m=0.0 if brake is None else float(brake.length),
        brake_s=0.0 if brake is None else float(brake.duration),
        turn_rad=0.0,
        turn_s=0.0,
    )
    stages = dict(stats.get("stages_s", {}))
    stages["replan_total"] = time.perf_counter() - t0
    stats["stages_s"] = stages
    return TrajectoryChain(tuple(pieces), robot, stats, out.steps)


def _at_pose(p: tuple[float, float], h: float, goal: np.ndarray, goal_heading: float) -> bool:
    """Whether the pose ``(p, h)`` is the goal pose (1e-9 m, 1e-9 rad modulo ``2 pi``)."""
    return (
        math.hypot(p[0] - float(goal[0]), p[1] - float(goal[1])) <= 1e-9
        and abs(math.remainder(h - goal_heading, 2.0 * math.pi)) <= 1e-9
    )


def _check_trajectory(options: PlannerOptions, trajectory: PlanResult) -> CarSteps:
    """Return the car plan's steps, or refuse a trajectory a car cannot be re-planned from."""
    robot = options.robot
    steps = getattr(trajectory, "steps", None)
    if (
        not isinstance(trajectory, TrajectoryChain)
        or not isinstance(steps, CarSteps)
        or not all(isinstance(p, Trajectory | SteerInPlace) for p in trajectory.pieces)
    ):
        raise InvalidInputError(
            "replan of a car-like robot (drive='ackermann') needs the trajectory of a car "
            "plan (a TrajectoryChain of Trajectory segments and SteerInPlace pieces with "
            "CarSteps, as Planner.plan returns for this robot), got "
            f"{type(trajectory).__name__}"
        )
    if trajectory.robot != robot:
        raise InvalidInputError(
            f"trajectory was planned for another robot ({trajectory.robot!r}); this planner's "
            f"robot is {robot!r}"
        )
    return steps


def _keep(
    options: PlannerOptions,
    caches: PlannerCaches,
    chain: TrajectoryChain,
    steps: CarSteps,
    ts: float,
    goal: np.ndarray,
    goal_heading: float,
) -> tuple[TrajectoryChain | None, str]:
    """Return the chain's rest from ``ts`` if a re-plan may keep it, and why not if not."""
    why = target_change(chain, goal, goal_heading, 0.0)
    if why:
        return None, why
    # a plan re-routed round movers was made on a map with their regions marked: the marks
    # stood for the old predictions, which the re-plan's re-timing replaces; the static map
    # they were drawn on is what the rest relies on
    old, _ = planned_on(steps)
    new = caches.grid
    rest = chain.after(ts)
    if old is not new:
        if (old.shape, old.resolution, old.origin) != (new.shape, new.resolution, new.origin):
            return None, "map of another shape"
        search_grid = car_search_grid(options.robot, new)
        old_search = (
            car_search_grid(options.robot, old)
            if isinstance(steps, MarkedCarSteps)
            else steps.inflated_grid
        )
        if np.any(np.asarray(old_search.occupied) & ~np.asarray(search_grid.occupied)):
            return None, "cells freed"
        fresh = np.asarray(new.occupied) & ~np.asarray(old.occupied)
        if fresh.any():
            grid = OccupancyGrid(fresh, new.resolution, new.origin)
            for piece, t_from in zip(rest.pieces, rest.starts, strict=True):
                if piece.steering_at_rest:  # standing where a drive starts or ends
                    continue
                if not _clear(options.robot.radius, grid, piece, t_from):
                    return None, "cells blocked near the rest of the path"
        steps = dataclasses.replace(steps, raw_grid=new, inflated_grid=search_grid)
        if isinstance(steps, MarkedCarSteps):
            steps = dataclasses.replace(steps, static_grid=new)
    stats = dict(rest.stats, replan="kept")
    return dataclasses.replace(rest, stats=stats, steps=steps), "kept"


def _clear(radius: float, fresh: OccupancyGrid, piece: Trajectory, t_from: float) -> bool:
    """Whether ``piece`` from ``t_from`` keeps ``radius`` from the cells of ``fresh``.

    Samples ``ds`` (at most an eighth of a cell) apart along the arc length, each at least
    ``radius + ds / 2`` from those cells; the outside of the map does not count (the old
    plan kept it).
    """
    s0 = float(piece.motion(t_from)[0])
    length = piece.length - s0
    ds = fresh.resolution / 8.0
    n = max(2, math.ceil(length / ds) + 1)
    s = np.linspace(s0, piece.length, n)
    xy = np.asarray(piece.path(piece.path.u_at_s(s)))
    need = radius + 0.5 * (s[1] - s[0])
    # pad the grid by a free border so that the outside is not counted as occupied
    pad = math.ceil(2.0 * need / fresh.resolution) + 1
    occ = np.pad(np.asarray(fresh.occupied), pad)
    origin = (
        fresh.origin[0] - pad * fresh.resolution,
        fresh.origin[1] - pad * fresh.resolution,
    )
    padded = OccupancyGrid(occ, fresh.resolution, origin)
    return bool(points_clearance(xy, padded, 2.0 * need).min() >= need)


def _brake(piece: Trajectory, tau: float) -> Trajectory | None:
    """Return the stop along ``piece``'s curve from its state at ``tau``, in its direction.

    ``None`` at rest. The stop is timed in the direction of travel (``piece`` read
    forwards) and carries the piece's ``direction``, so that its samples are the body's
    (signed speed, heading the tangent plus ``pi`` backwards).
    """
    forwards = dataclasses.replace(piece, direction=1)
    brake = brake_on_path(forwards, tau)
    if brake is None:
        return None
    return dataclasses.replace(brake, direction=piece.direction)


def _check_end(
    options: PlannerOptions,
    grid: OccupancyGrid,
    search_grid: OccupancyGrid,
    name: str,
    p: np.ndarray,
) -> None:
    """Refuse an end point off the map, too close to an obstacle or blocked on the search grid.

    The checks :func:`~trajopt.planning._car.plan_car` makes of its ends, made here first so
    that the re-plan can tell the caller's goal from the pose where the car stopped.
    """
    check_endpoint(options, grid, name, p, options.robot.inscribed_radius)
    ix, iy = (int(c) for c in grid.world_to_cell(p))
    if search_grid.occupied[iy, ix]:
        raise InvalidInputError(
            f"{name} {p.tolist()} m lies in cell ({ix}, {iy}), blocked on the car's search "
            f"grid (robot radius {options.robot.inscribed_radius} m plus a margin); move it towards "
            "free space"
        )
