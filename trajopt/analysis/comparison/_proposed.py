"""The proposed method as a row of :func:`trajopt.compare` (registered as ``"proposed"``)."""

from __future__ import annotations

import time
from typing import Any

from trajopt.robot import Robot

#: The timed metrics every proposed row carries (``trajectory_metrics`` keys).
_TIMED = ("duration_s", "ratio_v", "ratio_a", "ratio_jerk", "ratio_omega", "ratio_a_lat")
#: Added when the plan turned in place (yaw rate and acceleration against the turn limits).
_TURN_TIMED = ("ratio_turn_omega", "ratio_turn_alpha")


def proposed_method(ctx: Any) -> Any:
    """Return the proposed method as a :func:`trajopt.compare` row (registered as ``"proposed"``).

    Plans with :class:`Planner` on ``ctx.grid`` for a :class:`Robot` of radius
    ``ctx.robot_radius`` (default limits; options ``robot``, ``inflation``, ``search`` and
    ``smoother`` may be given through ``compare(..., options={"proposed": {...}})``, and
    ``start_heading`` / ``goal_heading`` (rad) for a pose-to-pose plan) and adds the timed
    metrics of :func:`trajopt.metrics.trajectory_metrics` as extra columns. A plan that
    turns in place (a :class:`~trajopt.motion.TrajectoryChain`) is scored along the curve
    it drives (:func:`trajopt.metrics.trajectory_path`); its turns (or an omnidirectional
    base's orientation turned while driving) add the columns ``ratio_turn_omega`` and
    ``ratio_turn_alpha`` (against :func:`trajopt.timing.turn_limits`) and are named in the
    note.
    """
    from trajopt.analysis.comparison import MethodResult
    from trajopt.analysis.metrics import trajectory_metrics, trajectory_path

    opts = ctx.options_for("proposed")
    robot = opts.pop("robot", None) or Robot(radius=ctx.robot_radius)
    headings = {k: opts.pop(k, None) for k in ("start_heading", "goal_heading")}
    t0 = time.perf_counter()
    from trajopt import Planner

    traj = Planner(ctx.grid, robot, **opts).plan(ctx.start, ctx.goal, **headings)
    runtime = time.perf_counter() - t0
    timed = trajectory_metrics(traj, robot)
    pose = traj.stats.get("pose") or {}
    turns = {e: float(pose.get(f"turn_{e}_rad", 0.0)) for e in ("start", "goal")}
    turned = {e: a for e, a in turns.items() if a != 0.0}
    body = float((traj.stats.get("orientation") or {}).get("turn_rad", 0.0))  # an omni base's
    keys = _TIMED + (_TURN_TIMED if turned or body else ())
    extras = {k: timed[k] for k in keys if k in timed}
    attempts = traj.stats.get("smoother", {}).get("attempts")
    note = f"duration {traj.duration:.3g} s"
    if attempts:
        note += f", smoother attempts {attempts if isinstance(attempts, int) else len(attempts)}"
    if turned:
        note += ", turns in place " + ", ".join(f"{e} {a:+.3g} rad" for e, a in turned.items())
    if body:
        note += f", orientation turned {body:+.3g} rad"
    return MethodResult(trajectory_path(traj), True, note, runtime_s=runtime, extras=extras)
