"""Re-planning from a moving robot: :meth:`~trajopt._planner.Planner.replan`.

A re-plan starts at the old trajectory's state at the splice time (position, heading,
curvature, speed and acceleration: a C2 splice) and takes the first of these that applies:

* **Keep** (``reuse=True``, the default): the rest of the old trajectory, cut at the splice
  and certified again, when the goal, goal heading and end speed are the old ones and the
  map changed nowhere near it (:mod:`trajopt.replan._keep`). ``stats["replan"] == "kept"``.
* **Plan** from the moving state (:meth:`~trajopt._planner.Planner.plan`), with the
  smoother's time budget capped at ``brake_after_s``. When the map changed near the rest
  but beyond the search cost's reach of its grid path, the plan takes the rest of the old
  grid path, joined from the state's cell, instead of searching (``stats["grid_path"]``
  ``"reused"``, else ``"searched"``). The polygon corridor keeps the old regions along the
  rest of the path the two share, unless ``reuse=False`` (:mod:`trajopt.corridor._polygons.reuse`;
  ``stats["corridor_regions_kept"]``). ``stats["replan"] == "planned: <why not kept>"``.
* **Brake, turn in place and go** when that plan fails (:mod:`trajopt.replan._brake`): a
  :class:`~trajopt.motion._chain.TrajectoryChain`, ``stats["replan"] == "braked: ..."``;
  its plan from rest keeps corridor regions the same way.

A chain is re-planned like any trajectory: while its last piece (the plan from rest) plays,
that piece is; before, the chain's rest is kept when the map, goal, goal heading and end
speed are unchanged, and a turn in place playing at the splice is finished first.

An omnidirectional base's :class:`~trajopt.motion.OmniTrajectory` is re-planned with its
orientation continued (:mod:`trajopt.replan._omni`): the plan from the moving state starts
its orientation at the body's angle, yaw rate and yaw acceleration at the splice
(``start_heading``, ``start_omega``, ``start_alpha``), the kept rest keeps the rest of the
orientation profile (:func:`~trajopt.replan._keep.keep_omni`), and a braking re-plan stops
the yaw rate while it brakes. A plain :class:`~trajopt.Trajectory` of an omni base faces its
direction of travel; re-planned to a goal heading, its orientation starts with the
direction of travel's rate and acceleration when they are within the yaw limits.

A car-like robot (``drive="ackermann"``) is re-planned by :mod:`trajopt.replan._car`: it
never turns in place and plans only from rest, so it keeps the rest, or brakes along the
segment it drives (in its direction of travel) and plans a car path from the stopped pose.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import NamedTuple

from astar.grid import OccupancyGrid
from trajopt.errors import InvalidInputError, SmoothingError, TimingError, TrajoptError
from trajopt.motion import PlanResult, TrajectoryChain
from trajopt.planning import (
    PlannerCaches,
    PlannerOptions,
    PlanRequest,
    WarmStart,
    check_endpoint,
    run_query,
)
from trajopt.replan._brake import brake_turn_go
from trajopt.replan._keep import (
    BLOCKED_NEAR,
    keep_omni,
    keep_rest,
    remaining_grid_path,
    target_change,
)
from trajopt.replan._marked import planned_on
from trajopt.replan._omni import course_orientation
from trajopt.validation import nonnegative, number, point

#: Default smoothing time (s) after which a re-plan from a moving state brakes instead.
BRAKE_AFTER_S = 0.1
#: Why a re-plan planned anew when the caller asked for no reuse.
NO_REUSE = "reuse=False"


def replan_from(
    options: PlannerOptions,
    caches: PlannerCaches,
    trajectory: PlanResult,
    t: float,
    goal: Sequence[float] | None,
    grid: OccupancyGrid | None,
    *,
    latency: float,
    goal_heading: float | None,
    v_end: float,
    reuse: bool = True,
    brake_after_s: float | None = BRAKE_AFTER_S,
) -> PlanResult:
    """Return :meth:`~trajopt._planner.Planner.replan`'s trajectory (see there).

    The robot's drive re-plans (:meth:`trajopt.drive.Drive.replan`): :func:`replan_moving`
    for a base that turns in place, :func:`~trajopt.replan._car.replan_car` for a car.

    ``options`` and ``caches`` are the planner's; ``latency`` (s) is the splice's lead
    (the planner passes its recent median when the caller gives none); ``grid``, an
    updated map, is applied to ``caches`` first (:meth:`PlannerCaches.update`).
    """
    lat = nonnegative("latency", latency, "s")
    t_now = number("t", t, unit="s", lo=0.0, hi=float(trajectory.duration))
    ts = t_now + lat
    if ts > trajectory.duration:
        raise InvalidInputError(
            f"t + latency = {t_now:.6g} + {lat:.6g} s is past the trajectory's end "
            f"({trajectory.duration:.6g} s): nothing is left to splice onto"
        )
    if goal is None:
        steps = getattr(trajectory, "steps", None)
        if steps is None:
            raise InvalidInputError(
                "goal is required: the trajectory has no steps (it was not planned by a Planner)"
            )
        goal = steps.goal
        if goal_heading is None:  # the same goal: the same heading there
            goal_heading = getattr(steps, "goal_heading", None)
    if brake_after_s is not None:
        brake_after_s = number("brake_after_s", brake_after_s, unit="s", lo=0.0, strict=True)
    if grid is not None:
        caches.update(grid)
    out = options.robot.drive.replan(
        options,
        caches,
        trajectory,
        ts,
        goal,
        goal_heading=goal_heading,
        v_end=v_end,
        reuse=reuse,
        brake_after_s=brake_after_s,
    )
    return dataclasses.replace(out, stats=dict(out.stats, splice_time_s=ts, latency_s=lat))


def replan_moving(
    options: PlannerOptions,
    caches: PlannerCaches,
    trajectory: PlanResult,
    ts: float,
    goal: Sequence[float],
    *,
    goal_heading: float | None,
    v_end: float,
    reuse: bool = True,
    brake_after_s: float | None = BRAKE_AFTER_S,
) -> PlanResult:
    """Keep the rest, plan from the moving state at ``ts``, or brake, turn and go.

    The re-plan of a base that turns in place (a differential drive, an omnidirectional
    base; module docstring); ``stats["replan"]`` says which was done. The arguments are
    :func:`replan_from`'s, checked.
    """
    out, why = None, NO_REUSE
    piece, t_piece = trajectory.plan_at(ts)  # a chain's last plan while it plays
    if reuse and piece is trajectory and trajectory.playing(ts)[0] is not trajectory:
        # a chain, before its last plan: keep the chain's rest
        out, why = _keep_chain(caches.grid, trajectory, ts, goal, goal_heading, v_end)
    elif reuse:
        keep = keep_omni if piece.own_orientation else keep_rest
        out, why = keep(
            options, caches, piece, t_piece, goal, goal_heading=goal_heading, v_end=v_end
        )
    if out is None:
        target = _Target(goal, goal_heading, v_end)
        out = _plan_or_brake(options, caches, trajectory, ts, piece, target, why, brake_after_s)
    stats = dict(out.stats)
    if why == "kept":
        stats["replan"] = "kept"
    elif not str(stats.get("replan", "")).startswith("braked"):
        stats["replan"] = f"planned: {why}"
    return dataclasses.replace(out, stats=stats)


class _Target(NamedTuple):
    """Where a re-plan goes: the goal (m), its heading (rad) and the end speed (m/s)."""

    goal: Sequence[float]
    goal_heading: float | None
    v_end: float


def _keep_chain(
    grid: OccupancyGrid,
    chain: TrajectoryChain,
    ts: float,
    goal: Sequence[float],
    goal_heading: float | None,
    v_end: float,
) -> tuple[TrajectoryChain | None, str]:
    """Return the rest of a brake-turn-go chain from ``ts`` if nothing it relies on changed."""
    steps = chain.steps
    if steps is None or grid is not planned_on(steps)[0]:  # a re-route's: its static map
        return None, "the map changed"
    why = target_change(chain, goal, goal_heading, v_end)  # a chain has no path: no heading
    return (None, why) if why else (chain.after(ts), "kept")


def _plan_or_brake(
    options: PlannerOptions,
    caches: PlannerCaches,
    trajectory: PlanResult,
    ts: float,
    piece: PlanResult,
    target: _Target,
    why: str,
    brake_after_s: float | None,
) -> PlanResult:
    """Plan from the state at ``ts``; brake, turn and go when that fails (:func:`replan_from`).

    The plan from the moving state gets the smoother's time budget capped at
    ``brake_after_s``: a re-plan must be quick, and a state no curve can leave smoothly
    exhausts the whole budget before it fails. Its smoothing and timing errors, and the
    input errors of its start (e.g. a state already in the goal's cell), lead to braking;
    an invalid goal is raised as such. A footprint robot, which does not brake this way,
    keeps the whole budget.
    """
    goal, goal_heading, v_end = target
    previous = None if why == NO_REUSE else getattr(piece, "steps", None)

    def brake(error: TrajoptError) -> TrajectoryChain:
        return brake_turn_go(
            options,
            caches,
            trajectory,
            ts,
            goal,
            goal_heading=goal_heading,
            v_end=v_end,
            error=error,
            previous=previous,
        )

    playing, tau = piece.playing(ts)
    if playing is not piece and playing.turning and tau < playing.duration:  # a chain's turn
        return brake(TimingError("the robot is turning in place at the splice"))
    state = trajectory.translation_state(ts)
    path = None
    if why == BLOCKED_NEAR:  # the map changed near the rest, maybe not along its path
        path = remaining_grid_path(
            options, caches, piece.steps, caches.grid.world_to_cell(state.position)
        )
    warm = WarmStart(path, previous)
    body = trajectory.orientation_at(ts)  # an omni base's orientation goes on
    if body is None and goal_heading is not None:
        body = course_orientation(trajectory, ts, options.robot)
    request = PlanRequest(state, goal, goal_heading=goal_heading, v_end=v_end)
    if body is not None:
        request = dataclasses.replace(
            request, start_heading=body.theta, start_omega=body.omega, start_alpha=body.alpha
        )
    if brake_after_s is None or options.robot.footprint is not None:  # no brake to fall on
        return run_query(options, caches, request, warm)
    try:
        return run_query(options, caches, request, warm, budget_s=brake_after_s)
    except (SmoothingError, TimingError) as exc:
        error: TrajoptError = exc
    except InvalidInputError as exc:  # the goal's own error, else the moving start's
        check_endpoint(options, caches.grid, "goal", point("goal", goal))
        error = exc
    return brake(error)
