"""Brake, turn in place, go: the re-plan of a moving robot that cannot go on smoothly.

A re-plan from a moving state needs a curve that starts with the robot's heading and
curvature and that the robot can follow at its speed. When the new goal lies behind the
robot, or the way ahead is blocked, no such curve may fit in the free space. Then
:meth:`~trajopt._planner.Planner.replan` falls back on what a driver would do
(:func:`brake_turn_go`):

1. **Brake on the old path.** From the splice state ``(s, v, a)`` the time-optimal
   jerk-limited stop (jerk ``-j``, then ``a = -a_max`` while needed, then ``+j`` until
   ``v = a = 0``; :func:`trajopt.timing._greedy.brake_times`) along the old curve. That stop
   is the lowest continuation of the state in the ``(s, v)`` plane, so it stays under the
   speed cap wherever the old trajectory did; it must end on the old path. The old curve was
   certified collision-free on the map it was planned on; if the map changed since, the
   braking piece is checked against the newly occupied cells (at samples ``ds`` apart, each at
   least ``radius + ds / 2`` from them: the distance to the cells is 1-Lipschitz along the
   path), and a robot that cannot stop before one is a :class:`~trajopt.errors.TimingError`.
2. **Turn in place** (:func:`trajopt.timing._stop_and_turn.turn_in_place`) to the heading the
   new plan starts with: a disc turns within its own footprint. (An omnidirectional base
   needs no turn: its plan from rest starts with the heading it stopped with.)
3. **Go**: a plan from rest at the stop point with a free start heading
   (:meth:`~trajopt._planner.Planner.plan`; the planner's fallback applies). If that plan
   fails (e.g. the stop lies in the goal's cell) and the goal, goal heading and end speed
   are the old trajectory's, the old path's rest is driven instead, timed from rest and
   checked against new obstacles like the stop; a stop at the old path's end is the end.

The result is a :class:`~trajopt.motion._chain.TrajectoryChain`; ``stats["replan"]``
says ``"braked: <why the smooth re-plan failed>"``, ``stats["brake_m"]``,
``stats["brake_s"]``, ``stats["turn_rad"]`` and ``stats["turn_s"]`` describe the stop.

An omnidirectional base driving an :class:`~trajopt.motion.OmniTrajectory` (its body's
orientation apart from its direction of travel) brakes and goes without a turn in place
(:func:`_brake_go_omni`): while the translation brakes on the old path, the body's yaw rate
is brought to rest as fast as the yaw limits allow
(:func:`trajopt.timing._orientation.stop_orientation`; the stop piece is an
``OmniTrajectory``, or a :class:`~trajopt.motion._chain.TurnInPlace` when the translation
is at rest already), and the plan from rest starts its orientation where that left it
(``start_heading``), turning to the goal heading while it drives. Position, orientation,
speed, acceleration and yaw rate are continuous at every join; ``stats["turn_rad"]`` and
``stats["turn_s"]`` are then the angle and time of the yaw stop.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from astar.grid import OccupancyGrid
from trajopt.errors import TimingError, TrajoptError
from trajopt.geometry import CurveSegment, points_clearance
from trajopt.motion import OmniTrajectory, PlanResult, Trajectory, TrajectoryChain
from trajopt.planning import (
    CarSteps,
    PlannerCaches,
    PlannerOptions,
    PlanRequest,
    PlanSteps,
    WarmStart,
    run_query,
)
from trajopt.replan._keep import target_change
from trajopt.replan._omni import turn_piece
from trajopt.robot import Robot
from trajopt.timing import (
    advance,
    brake_times,
    orient,
    stop_orientation,
    time_parameterize,
    turn_in_place,
    turn_limits,
    yaw_stop,
)


def brake_on_path(traj: Trajectory, ts: float) -> Trajectory | None:
    """Return the time-optimal jerk-limited stop from the state at ``ts``, on the path.

    Parameters
    ----------
    traj : Trajectory
        The trajectory driven.
    ts : float
        The splice time (s), in ``[0, duration]``.

    Returns
    -------
    Trajectory or None
        The stop (its path a :class:`~trajopt.geometry._curve.CurveSegment` of ``traj.path``, time 0
        at ``ts``), or ``None`` when the state is at rest already.

    Raises
    ------
    TimingError
        The stop does not end on the path (the trajectory ends moving), or the state
        decelerates too hard to end at rest without reversing.
    """
    robot = traj.robot
    s0, v0, a0, _ = (float(x) for x in traj.motion(ts))
    if v0 <= 0.0 and a0 <= 0.0:
        return None
    j = robot.j_max
    t1, t2, t3, _ = brake_times(v0, a0, 0.0, j, robot.a_max)
    rows, s, v, a, t = [], 0.0, v0, a0, 0.0
    for jerk, d in ((-j, t1), (0.0, t2), (j, t3)):
        if d > 0.0:
            rows.append((t, s, v, a, jerk))
            s, v, a = advance(s, v, a, jerk, d)
            t += d
    if v < -1e-9:  # a state decelerating too hard to end at rest without reversing
        raise TimingError(
            f"the robot at {v0:.6g} m/s with a = {a0:.6g} m/s^2 cannot stop without reversing "
            f"under the jerk limit {j} m/s^3"
        )
    if s0 + s > traj.length + 1e-9:
        raise TimingError(
            f"the robot at {v0:.6g} m/s cannot stop on the path: it needs {s:.6g} m, "
            f"{traj.length - s0:.6g} m are left"
        )
    s_end = min(s0 + s, traj.length)
    u0, u1 = (float(u) for u in traj._u_at_s(np.array([s0, s_end])))
    if not u1 > u0:
        return None
    gs = traj.theta_grid_s
    inside = (gs > s0) & (gs < s_end)
    ends = traj.sample(np.array([ts]))
    theta0 = float(ends.theta[0])
    th1 = float(traj.path.heading(u1))
    ref = theta0 if not inside.any() else float(traj.theta_grid[inside][-1])
    theta1 = th1 + 2.0 * math.pi * round((ref - th1) / (2.0 * math.pi))
    ph = np.array(rows)
    u_grid = traj.u_grid
    if u_grid.shape[0]:
        u_grid = np.concatenate([[u0], u_grid[inside], [u1]])
    return Trajectory(
        path=CurveSegment(traj.path, u0, u1),
        robot=robot,
        phase_t=ph[:, 0],
        phase_s=ph[:, 1],
        phase_v=ph[:, 2],
        phase_a=ph[:, 3],
        phase_j=ph[:, 4],
        duration=t,
        v_start=v0,
        v_end=0.0,
        stats={},
        theta_grid_s=np.concatenate([[0.0], gs[inside] - s0, [s_end - s0]]),
        theta_grid=np.concatenate([[theta0], traj.theta_grid[inside], [theta1]]),
        u_grid=u_grid,
    )


def brake_turn_go(
    options: PlannerOptions,
    caches: PlannerCaches,
    trajectory: PlanResult,
    ts: float,
    goal: Sequence[float],
    *,
    goal_heading: float | None,
    v_end: float,
    error: TrajoptError,
    previous: PlanSteps | None = None,
) -> TrajectoryChain:
    """Return the re-plan that brakes, turns in place and goes (module docstring).

    Parameters
    ----------
    options : PlannerOptions
        The re-planning planner's options.
    caches : PlannerCaches
        Its caches, with the current map.
    trajectory : Trajectory, OmniTrajectory or TrajectoryChain
        The trajectory driven; a chain is braked on the piece playing at ``ts`` (a turn in
        place playing then is finished first). An omnidirectional base's
        :class:`~trajopt.motion.OmniTrajectory` stops its yaw rate while it brakes and
        goes without a turn in place (module docstring).
    ts : float
        The splice time on its clock (s).
    goal : sequence of float, shape (2,)
        The goal (m).
    goal_heading : float or None
        Exact heading at the goal (rad).
    v_end : float
        Speed at the goal (m/s).
    error : TrajoptError
        Why the smooth re-plan failed: re-raised when braking cannot apply (a footprint
        robot, a trajectory that is not a smooth :class:`~trajopt.Trajectory`).
    previous : PlanSteps or None, optional
        The old plan's steps: the plan from rest keeps their polygon corridor's regions
        along the rest of the path the two share (:mod:`trajopt.corridor._polygons.reuse`).

    Raises
    ------
    TimingError
        The robot cannot stop on the old path, or not before a new obstacle.
    TrajoptError
        The plan from rest fails (its own error, with a note on the stop).
    """
    traj, t_in = trajectory.playing(ts)  # a chain's piece; its earlier pieces are past
    robot = options.robot
    if robot.footprint is None and traj.own_orientation:
        target = (goal, goal_heading, v_end)
        return _brake_go_omni(options, caches, trajectory, ts, target, error, previous)
    if robot.footprint is not None or not (traj.single_curve or traj.turning):
        raise error
    pieces: list[Any] = []
    starts: list[float] = []
    brake = None
    if traj.turning:  # turning at rest: the turn is finished first
        if t_in < traj.duration:
            pieces.append(traj)
            starts.append(t_in)
        stop = traj.sample(np.array([traj.duration]))
    else:
        brake = brake_on_path(traj, t_in)
        if brake is not None:
            steps = getattr(traj, "steps", None) or getattr(trajectory, "steps", None)
            check_new_obstacles(robot, caches.grid, steps, brake)
            pieces.append(brake)
            starts.append(0.0)
            stop = brake.sample(np.array([brake.duration]))
        else:
            stop = traj.sample(np.array([t_in]))
    p_stop = (float(stop.x[0]), float(stop.y[0]))
    try:
        # an omni base turns while it drives: its plan starts at the heading it stops with
        h0 = float(stop.theta[0]) if robot.drive.orients_body else None
        request = PlanRequest(
            p_stop, goal, start_heading=h0, goal_heading=goal_heading, v_end=v_end
        )
        out = run_query(options, caches, request, WarmStart(None, previous))
    except TrajoptError as exc:
        rest = None
        if brake is not None:
            rest = _resume(options, caches.grid, traj, brake, goal, goal_heading, v_end)
        if rest is None:
            exc.args = (
                f"{exc.args[0]} (planned from rest after braking to a stop at "
                f"{p_stop} m, since {error})",
            ) + exc.args[1:]
            raise
        stats = dict(
            traj.stats,
            replan=f"braked: {type(error).__name__}: {error}; the old "
            f"path resumed from rest ({type(exc).__name__} from the stop)",
            brake_m=float(brake.length),
            brake_s=brake.duration,
            turn_rad=0.0,
            turn_s=0.0,
        )
        return TrajectoryChain(tuple(pieces + rest), robot, stats, traj.steps)
    first = out.sample(np.array([0.0]))
    turn = turn_in_place(p_stop, float(stop.theta[0]), float(first.theta[0]), robot)
    if turn.duration > 0.0:
        pieces.append(turn)
        starts.append(0.0)
    pieces.append(out)
    starts.append(0.0)
    stats = dict(out.stats)
    stats.update(
        replan=f"braked: {type(error).__name__}: {error}",
        brake_m=0.0 if brake is None else float(brake.length),
        brake_s=0.0 if brake is None else brake.duration,
        turn_rad=float(turn.stats["turn_rad"]),
        turn_s=turn.duration,
    )
    return TrajectoryChain(tuple(pieces), robot, stats, out.steps, tuple(starts))


def _brake_go_omni(
    options: PlannerOptions,
    caches: PlannerCaches,
    trajectory: PlanResult,
    ts: float,
    target: tuple[Sequence[float], float | None, float],
    error: TrajoptError,
    previous: PlanSteps | None,
) -> TrajectoryChain:
    """Brake an omnidirectional base, stop its yaw rate, and go (module docstring).

    ``trajectory`` plays an :class:`OmniTrajectory` at ``ts`` (itself, or a chain's piece);
    ``target`` is ``(goal, goal_heading, v_end)``. When the plan from rest fails and the
    target is the old one, the old path's rest is driven from the stop (timed from rest) with
    the orientation turned to the old end orientation, as :func:`brake_turn_go` does.
    """
    goal, goal_heading, v_end = target
    robot = options.robot
    traj, t_in = trajectory.playing(ts)
    start = trajectory.orientation_at(ts)
    if start is None:  # pragma: no cover - brake_turn_go sends only a body that turns
        raise error
    translation = traj.translation
    brake = None
    if t_in < translation.duration:
        brake = brake_on_path(translation, t_in)
    pieces: list[Any] = []
    if brake is not None:  # the translation brakes; the yaw rate stops beside it
        steps = translation.steps or traj.steps or getattr(trajectory, "steps", None)
        check_new_obstacles(robot, caches.grid, steps, brake)
        stop = stop_orientation(
            brake, robot, start.theta, omega_start=start.omega, alpha_start=start.alpha
        )
        end = brake.sample(np.array([brake.duration]))
        theta_stop, t_stop = stop.theta_end, stop.turn_duration
        pieces.append(stop)
    else:  # standing: only the yaw rate stops
        end = translation.sample(np.array([min(t_in, translation.duration)]))
        rows, t_stop = yaw_stop(start.omega, start.alpha, turn_limits(robot))
        theta_stop = start.theta
        if rows.shape[0]:
            turn = turn_piece((end.x[0], end.y[0]), start.theta, rows, t_stop, robot)
            theta_stop = start.theta + turn.turn_rad
            pieces.append(turn)
    p_stop = (float(end.x[0]), float(end.y[0]))
    braked = f"braked: {type(error).__name__}: {error}"
    stop_stats = {
        "brake_m": 0.0 if brake is None else float(brake.length),
        "brake_s": 0.0 if brake is None else brake.duration,
        "turn_rad": float(theta_stop - start.theta),
        "turn_s": float(t_stop),
    }
    try:
        request = PlanRequest(
            p_stop, goal, start_heading=theta_stop, goal_heading=goal_heading, v_end=v_end
        )
        out = run_query(options, caches, request, WarmStart(None, previous))
    except TrajoptError as exc:
        rest = _resume_omni(options, caches.grid, traj, brake, theta_stop, p_stop, target)
        if rest is None or not pieces + rest:  # nothing to drive: the stop is the goal
            exc.args = (
                f"{exc.args[0]} (planned from rest after braking to a stop at "
                f"{p_stop} m, since {error})",
            ) + exc.args[1:]
            raise
        stats = dict(
            traj.stats,
            replan=f"{braked}; the old path resumed from rest ({type(exc).__name__} from the stop)",
            **stop_stats,
        )
        return TrajectoryChain(tuple(pieces + rest), robot, stats, traj.steps)
    pieces.append(out)
    stats = dict(out.stats, replan=braked, **stop_stats)
    return TrajectoryChain(tuple(pieces), robot, stats, out.steps)


def _resume_omni(
    options: PlannerOptions,
    grid: OccupancyGrid,
    traj: OmniTrajectory,
    brake: Trajectory | None,
    theta_stop: float,
    p_stop: tuple[float, float],
    target: tuple[Sequence[float], float | None, float],
) -> list[PlanResult] | None:
    """Return the old motion's rest from the stop, from rest, if the target is the old one.

    The translation's rest is :func:`_resume`'s; the orientation turns from ``theta_stop``
    (rad) to the old end orientation beside it (:func:`~trajopt.timing.orient`), or in
    place when the stop is the path's end. ``None`` when the goal, goal heading or end speed
    differ, or when the robot stood still mid-path (nothing to resume from).
    """
    goal, goal_heading, v_end = target
    if traj.steps is None or target_change(traj, goal, None, v_end):
        return None
    if goal_heading is not None and (
        abs(math.remainder(float(goal_heading) - traj.theta_end, 2.0 * math.pi)) > 1e-9
    ):
        return None
    robot = options.robot
    if brake is None:
        tr = traj.translation
        stop = tr.sample(np.array([tr.duration]))
        if math.hypot(float(stop.x[0]) - p_stop[0], float(stop.y[0]) - p_stop[1]) > 1e-9:
            return None
        rest: list[Trajectory] | None = []
    else:
        rest = _resume(options, grid, traj.translation, brake, goal, None, v_end)
    if rest is None:
        return None
    if rest:
        return [orient(rest[0], robot, theta_stop, traj.theta_end)]
    turn = turn_in_place(p_stop, theta_stop, traj.theta_end, robot)
    return [turn] if turn.duration > 0.0 else []


def _resume(
    options: PlannerOptions,
    grid: OccupancyGrid,
    traj: Trajectory,
    brake: Trajectory,
    goal: Sequence[float],
    goal_heading: float | None,
    v_end: float,
) -> list[Trajectory] | None:
    """Return the old path's rest from the stop, timed from rest, if the goal is the old one.

    ``[]`` when the stop is the old path's end; ``None`` when the goal, goal heading or end
    speed differ from the old trajectory's. A map change is checked as for the braking.
    """
    steps = traj.steps
    if steps is None or target_change(traj, goal, goal_heading, v_end):
        return None
    u_stop, u_end = brake.path.domain[1], traj.path.domain[1]
    if not u_stop < u_end:
        return []
    rest = time_parameterize(
        CurveSegment(traj.path, u_stop, u_end),
        options.robot,
        v_end=v_end,
        dt=options.timing_dt,
        speed_limits=options.speed_limits,
    )
    check_new_obstacles(options.robot, grid, steps, rest)
    return [rest]


def check_new_obstacles(
    robot: Robot, grid: OccupancyGrid, steps: PlanSteps | CarSteps | None, brake: Trajectory
) -> None:
    """Raise :class:`TimingError` if a cell occupied since ``steps`` was planned is in reach.

    ``brake``: a piece driven on the old path (the stop, or the old path's resumed rest).
    """
    old = getattr(steps, "raw_grid", None)
    if old is grid:
        return
    fresh = np.asarray(grid.occupied)
    if isinstance(old, OccupancyGrid) and old.occupied.shape == fresh.shape:
        fresh = fresh & ~np.asarray(old.occupied)
    if not fresh.any():
        return
    ds = grid.resolution / 8.0
    n = max(2, int(math.ceil(brake.length / ds)) + 1)
    s = np.linspace(0.0, brake.length, n)
    xy = np.asarray(brake.path(brake._u_at_s(s)))
    need = robot.radius + 0.5 * (s[1] - s[0])
    clear = points_clearance(xy, OccupancyGrid(fresh, grid.resolution, grid.origin), 2.0 * need)
    k = int(np.argmin(clear))
    if clear[k] < need:
        raise TimingError(
            f"the robot cannot stop before an obstacle: braking on its path it comes "
            f"{clear[k]:.4g} m from a newly occupied cell at {xy[k].round(4).tolist()} m "
            f"(needs {robot.radius} m)"
        )
