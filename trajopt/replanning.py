"""Re-planning from a moving robot.

The splice of :meth:`~trajopt.pipeline.Planner.replan`, and the second fit a fast start
needs.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import Any

from astar.grid import OccupancyGrid
from trajopt.corridor_fit import fit_in_corridor
from trajopt.errors import InvalidInputError, SmoothingError, TimingError
from trajopt.plan_query import PlanQuery
from trajopt.replan_keep import BLOCKED_NEAR, keep_rest, remaining_grid_path
from trajopt.smoother import SmoothPath
from trajopt.validation import nonnegative, number

__all__ = ["replan_from", "smooth_for_speed"]


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
) -> Any:
    """Return :meth:`~trajopt.pipeline.Planner.replan`'s trajectory (see there)."""
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
                "goal is required: the trajectory has no steps (it was not planned by a "
                "Planner)"
            )
        goal = steps.goal
    if grid is not None:
        planner.update_map(grid)
    out, why = None, "reuse=False"
    if reuse:
        out, why = keep_rest(planner, trajectory, ts, goal, goal_heading=goal_heading,
                             v_end=v_end)  # fmt: skip
    if out is None:
        state = trajectory.state_at(ts)
        path = None
        if why == BLOCKED_NEAR:  # the map changed near the rest, maybe not along its path
            path = remaining_grid_path(planner, trajectory.steps,
                                       planner.grid.world_to_cell(state.position))  # fmt: skip
        out = planner._query(state, goal, None, goal_heading, 0.0, v_end, path)
    stats = dict(out.stats)
    stats["replan"] = "kept" if why == "kept" else f"planned: {why}"
    stats["splice_time_s"] = ts
    stats["latency_s"] = lat
    return dataclasses.replace(out, stats=stats)



def smooth_for_speed(planner: Any, q: PlanQuery) -> SmoothPath:
    """Fit again with a curvature bound the start speed can follow.

    A moving start whose speed cannot be brought under the cap of the first curve
    (too sharp a turn too soon) gets a second fit bounded by the curvature whose cap
    is that speed (``Robot.speed_cap``), a little tighter; the state's own curvature
    must already be within it.

    Raises
    ------
    TimingError
        The state is above the cap at its own curvature.
    SmoothingError
        No curve within that bound (the message says why the bound was imposed).
    """
    r = planner.robot
    # the speed rises by a^2 / (2 j) before a positive acceleration can be undone
    v = q.v_start + max(q.a_start, 0.0) ** 2 / (2.0 * r.j_max)
    bounds = [r.a_lat_max / (v * v), r.omega_max / v]
    if r.track_width is not None and r.wheel_v_max is not None and v < r.wheel_v_max:
        bounds.append((r.wheel_v_max / v - 1.0) * 2.0 / r.track_width)
    k_speed = 0.95 * min(bounds)
    k0 = abs(q.start_curvature or 0.0)
    if k0 > k_speed:
        raise TimingError(
            f"the start state moves at {v:.6g} m/s on curvature {k0:.6g} 1/m: above the "
            f"speed cap there ({float(r.speed_cap(k0)):.6g} m/s)"
        )
    kmax = k_speed if planner.smoother.kappa_max is None else min(k_speed, planner.smoother.kappa_max)
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
