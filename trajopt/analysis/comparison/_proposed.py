"""The proposed method as a row of :func:`trajopt.compare` (registered as ``"proposed"``)."""

from __future__ import annotations

import time
from typing import Any

from trajopt.robot._robot import Robot


def proposed_method(ctx: Any) -> Any:
    """Return the proposed method as a :func:`trajopt.compare` row (registered as ``"proposed"``).

    Plans with :class:`Planner` on ``ctx.grid`` for a :class:`Robot` of radius
    ``ctx.robot_radius`` (default limits; options ``robot``, ``inflation``, ``search`` and
    ``smoother`` may be given through ``compare(..., options={"proposed": {...}})``) and
    adds the timed metrics of :func:`trajopt.metrics.trajectory_metrics` as extra columns.
    """
    from trajopt.analysis.comparison import MethodResult
    from trajopt.analysis.metrics import trajectory_metrics

    opts = ctx.options_for("proposed")
    robot = opts.pop("robot", None) or Robot(radius=ctx.robot_radius)
    t0 = time.perf_counter()
    from trajopt._planner import Planner

    traj = Planner(ctx.grid, robot, **opts).plan(ctx.start, ctx.goal)
    runtime = time.perf_counter() - t0
    timed = trajectory_metrics(traj, robot)
    extras = {
        k: timed[k]
        for k in ("duration_s", "ratio_v", "ratio_a", "ratio_jerk", "ratio_omega", "ratio_a_lat")
        if k in timed
    }
    attempts = traj.stats.get("smoother", {}).get("attempts")
    note = f"duration {traj.duration:.3g} s"
    if attempts:
        note += f", smoother attempts {attempts if isinstance(attempts, int) else len(attempts)}"
    return MethodResult(traj.path, True, note, runtime_s=runtime, extras=extras)
