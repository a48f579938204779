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
:func:`smooth_for_speed` is the second fit a fast start needs.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import Any

from astar.grid import OccupancyGrid
from trajopt._validation import nonnegative, number, point
from trajopt.errors import InvalidInputError, SmoothingError, TimingError
from trajopt.motion._chain import TrajectoryChain, TurnInPlace
from trajopt.planning._corridor_fit import fit_in_corridor
from trajopt.planning._query import PlanQuery, WarmStart
from trajopt.replan._brake import brake_turn_go
from trajopt.replan._keep import BLOCKED_NEAR, keep_rest, remaining_grid_path, target_change
from trajopt.smoother import SmoothPath

#: Default smoothing time (s) after which a re-plan from a moving state brakes instead.
BRAKE_AFTER_S = 0.1
#: Why a re-plan planned anew when the caller asked for no reuse.
NO_REUSE = "reuse=False"


def replan_from(
    planner: Any,
    trajectory: Any,
    t: float,
    goal: Sequence[float] | None,
    grid: OccupancyGrid | None,
    *,
    latency: float | None,
    goal_heading: float | None,
    v_end: float,
    reuse: bool = True,
    brake_after_s: float | None = BRAKE_AFTER_S,
) -> Any:
    """Return :meth:`~trajopt._planner.Planner.replan`'s trajectory (see there)."""
    lat = planner.latency_s if latency is None else nonnegative("latency", latency, "s")
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
    if brake_after_s is not None:
        brake_after_s = number("brake_after_s", brake_after_s, unit="s", lo=0.0, strict=True)
    if grid is not None:
        planner.update_map(grid)
    out, why = None, NO_REUSE
    piece, t_piece = trajectory, ts
    if isinstance(trajectory, TrajectoryChain):
        i, t_piece = trajectory.piece_at(ts)
        if i == len(trajectory.pieces) - 1:  # driving the chain's last plan: re-plan that
            piece = trajectory.pieces[i]
    if reuse and piece is trajectory and isinstance(trajectory, TrajectoryChain):
        out, why = _keep_chain(planner, trajectory, ts, goal, goal_heading, v_end)
    elif reuse:
        out, why = keep_rest(planner, piece, t_piece, goal, goal_heading=goal_heading,
                             v_end=v_end)  # fmt: skip
    if out is None:
        out = _plan_or_brake(planner, trajectory, ts, piece, goal, goal_heading, v_end, why,
                             brake_after_s)  # fmt: skip
    stats = dict(out.stats)
    if why == "kept":
        stats["replan"] = "kept"
    elif not str(stats.get("replan", "")).startswith("braked"):
        stats["replan"] = f"planned: {why}"
    stats["splice_time_s"] = ts
    stats["latency_s"] = lat
    return dataclasses.replace(out, stats=stats)


def _keep_chain(planner, chain, ts, goal, goal_heading, v_end) -> tuple[Any, str]:
    """Return the rest of a brake-turn-go chain from ``ts`` if nothing it relies on changed."""
    steps = chain.steps
    if steps is None or planner.grid is not steps.raw_grid:
        return None, "the map changed"
    why = target_change(chain, goal, goal_heading, v_end)  # a chain has no path: no heading
    return (None, why) if why else (chain.after(ts), "kept")


def _plan_or_brake(planner, trajectory, ts, piece, goal, goal_heading, v_end, why,
                   brake_after_s):  # fmt: skip
    """Plan from the state at ``ts``; brake, turn and go when that fails (:func:`replan_from`).

    The plan from the moving state gets the smoother's time budget capped at
    ``brake_after_s``: a re-plan must be quick, and a state no curve can leave smoothly
    exhausts the whole budget before it fails. Its smoothing and timing errors, and the
    input errors of its start (e.g. a state already in the goal's cell), lead to braking;
    an invalid goal is raised as such. A footprint robot, which does not brake this way,
    keeps the whole budget.
    """
    previous = None if why == NO_REUSE else getattr(piece, "steps", None)
    if isinstance(piece, TrajectoryChain):
        i, tau = piece.piece_at(ts)
        if isinstance(piece.pieces[i], TurnInPlace) and tau < piece.pieces[i].duration:
            error = TimingError("the robot is turning in place at the splice")
            return brake_turn_go(planner, trajectory, ts, goal, goal_heading=goal_heading,
                                 v_end=v_end, error=error, previous=previous)  # fmt: skip
    state = trajectory.state_at(ts)
    path = None
    if why == BLOCKED_NEAR:  # the map changed near the rest, maybe not along its path
        path = remaining_grid_path(planner, piece.steps,
                                   planner.grid.world_to_cell(state.position))  # fmt: skip
    warm = WarmStart(path, previous)
    if brake_after_s is None or planner.robot.footprint is not None:  # no brake to fall on
        return planner._query(state, goal, None, goal_heading, 0.0, v_end, warm)
    smoother = planner.smoother
    planner.smoother = dataclasses.replace(
        smoother, time_budget_s=min(smoother.time_budget_s, brake_after_s)
    )
    try:
        return planner._query(state, goal, None, goal_heading, 0.0, v_end, warm)
    except (SmoothingError, TimingError) as exc:
        error = exc
    except InvalidInputError as exc:  # the goal's own error, else the moving start's
        planner._check_endpoint("goal", point("goal", goal))
        error = exc
    finally:
        planner.smoother = smoother
    return brake_turn_go(planner, trajectory, ts, goal, goal_heading=goal_heading,
                         v_end=v_end, error=error, previous=previous)  # fmt: skip


def smooth_for_speed(planner: Any, q: PlanQuery) -> SmoothPath:
    """Fit again with a curvature bound the start speed can follow.

    A moving start whose speed cannot be brought under the cap of the first curve
    (too sharp a turn too soon) gets a second fit bounded by the curvature whose cap
    is that speed (``Robot.speed_cap``), 5 % tighter but never below the state's own
    curvature, which must already be within it.

    Raises
    ------
    TimingError
        The state's speed plus ``a^2 / (2 j)`` (its peak before a positive acceleration
        can be undone) is above the cap at its own curvature.
    SmoothingError
        No curve within that bound (the message says why the bound was imposed).
    """
    r = planner.robot
    # the speed rises by a^2 / (2 j) before a positive acceleration can be undone
    v = q.v_start + max(q.a_start, 0.0) ** 2 / (2.0 * r.j_max)
    bounds = [r.a_lat_max / (v * v), r.omega_max / v]
    if r.track_width is not None and r.wheel_v_max is not None and v < r.wheel_v_max:
        bounds.append((r.wheel_v_max / v - 1.0) * 2.0 / r.track_width)
    k0 = abs(q.start_curvature or 0.0)
    if k0 > min(bounds):
        raise TimingError(
            f"the start state reaches {v:.6g} m/s on curvature {k0:.6g} 1/m (its speed "
            f"{q.v_start:.6g} m/s plus a^2 / (2 j)): above the speed cap there "
            f"({float(r.speed_cap(k0)):.6g} m/s)"
        )
    # a little below the cap, but never below the state's own curvature
    k_speed = max(0.95 * min(bounds), k0)
    kmax = (
        k_speed if planner.smoother.kappa_max is None else min(k_speed, planner.smoother.kappa_max)
    )
    sm = dataclasses.replace(planner.smoother, kappa_max=kmax)
    try:
        q.corridor, smooth = fit_in_corridor(planner, q, q.path, sm)
    except SmoothingError as exc:
        raise SmoothingError(
            f"the start state moves at {v:.6g} m/s: no curve from it turns gently enough "
            f"(curvature <= {kmax:.6g} 1/m) to slow down under the speed cap in time: {exc}",
            exc.stats,
        ) from exc
    q.rescue = "speed"
    return smooth
