"""Plans of an omnidirectional base: the path of a disc, the orientation turned while driving.

An omni base (``Robot(drive=trajopt.Omni())``) moves in any direction whatever its orientation. The
path is planned as for a disc of the robot's radius (with a footprint: its circumscribed
disc, which holds the footprint in every orientation, so the path is clear whatever the
orientation does), with free headings; the orientation is then its own jerk-limited profile
from the start heading to the goal heading (:func:`trajopt.timing.orient`), synchronised
with the translation, so the total duration grows only when the turn cannot fit in the
travel time. With no heading given the plan is the translation alone (its orientation is
its direction of travel, as a differential drive's).

A re-plan continues the orientation of a body that turns: the request's ``start_heading``
is the orientation at the splice (for a moving :class:`~trajopt.robot.State` start too,
whose ``theta`` is the direction of travel the path continues), and ``start_omega`` and
``start_alpha`` its yaw rate and acceleration there, where the orientation profile starts.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from trajopt.errors import TimingError
from trajopt.motion import PlanResult
from trajopt.planning._caches import PlannerCaches
from trajopt.planning._disc import plan_disc
from trajopt.planning._options import PlannerOptions, PlanRequest
from trajopt.planning._query import PlanSteps, WarmStart
from trajopt.timing import orient, stop_and_turn


def plan_omni(
    options: PlannerOptions,
    caches: PlannerCaches,
    request: PlanRequest,
    warm: WarmStart | None = None,
) -> PlanResult:
    """Plan one query for an omnidirectional base (module docstring).

    Parameters
    ----------
    options : PlannerOptions
        The planner's options (``options.robot.drive`` an :class:`~trajopt.drive.Omni`).
    caches : PlannerCaches
        The map's caches.
    request : PlanRequest
        The query; a :class:`~trajopt.robot.State` start continues its direction of travel
        (its ``theta``), and its orientation profile starts at ``start_heading`` (default: that
        direction) with the yaw rate ``start_omega`` and acceleration ``start_alpha``.
    warm : WarmStart, optional
        A re-plan's warm start.

    Returns
    -------
    Trajectory, OmniTrajectory or StopAndTurnTrajectory
        An :class:`~trajopt.motion.OmniTrajectory` when a heading or a start yaw rate or
        acceleration is given.

    Raises
    ------
    InvalidInputError
        As :func:`~trajopt.planning._disc.plan_disc`, and a start yaw rate or acceleration
        beyond the yaw limits (:func:`~trajopt.timing.orient`).
    TimingError
        As :func:`~trajopt.planning._disc.plan_disc`; the stop-and-turn fallback's plan from
        a body that turns (the fallback starts at rest).
    """
    h0, h1 = request.start_heading, request.goal_heading
    w0, a0 = request.start_omega, request.start_alpha
    # the path leaves and arrives along its own directions (a moving State's included)
    free = dataclasses.replace(
        request, start_heading=None, goal_heading=None, start_omega=0.0, start_alpha=0.0
    )
    translation = plan_disc(options, caches, free, warm)
    if h0 is None and h1 is None and w0 == 0.0 and a0 == 0.0:
        return translation
    if translation.polyline:  # the fallback turns at its ends
        if w0 != 0.0 or a0 != 0.0:
            raise TimingError(
                f"the stop-and-turn fallback starts at rest, but the body turns at the start "
                f"(start_omega={w0!r} rad/s, start_alpha={a0!r} rad/s^2)"
            )
        out = stop_and_turn(translation.vertices, options.robot, start_heading=h0,
                            goal_heading=h1, speed_limits=options.speed_limits)  # fmt: skip
        return dataclasses.replace(out, stats=dict(translation.stats),
                                   steps=_asked(translation.steps, request))  # fmt: skip
    ends = translation.sample(np.array([0.0, translation.duration]))
    theta0 = float(ends.theta[0]) if h0 is None else h0
    theta1 = float(ends.theta[1]) if h1 is None else h1
    out = orient(translation, options.robot, theta0, theta1, omega_start=w0, alpha_start=a0)
    return dataclasses.replace(out, steps=_asked(translation.steps, request))


def _asked(steps: PlanSteps | None, request: PlanRequest) -> PlanSteps | None:
    """Return ``steps`` recording the headings the request asked for."""
    if steps is None:
        return None
    return dataclasses.replace(
        steps, start_heading=request.start_heading, goal_heading=request.goal_heading
    )
