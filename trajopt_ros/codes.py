"""Failure reasons of a request and their error codes in each action interface.

A failure is first named (:func:`reason_of`: one of :data:`REASONS`, from the exception's
type), then coded per interface: :data:`PLAN_TRAJECTORY` (this package's action, one code
per reason), :data:`COMPUTE_PATH_TO_POSE` and :data:`SMOOTH_PATH` (Nav2's codes; reasons
Nav2 has no code for become its ``UNKNOWN``, the message keeps the detail).
"""

from __future__ import annotations

import astar.errors
import trajopt.errors
from trajopt_ros.errors import RequestError

__all__ = [
    "REASONS",
    "reason_of",
    "PLAN_TRAJECTORY",
    "COMPUTE_PATH_TO_POSE",
    "SMOOTH_PATH",
    "code_for",
]

#: Every failure reason, in the order of the codes of ``PlanTrajectory``.
REASONS = (
    "none",
    "unknown",
    "no_map",
    "frame_mismatch",
    "invalid_pose",
    "no_odometry",
    "start_outside_map",
    "goal_outside_map",
    "start_occupied",
    "goal_occupied",
    "invalid_input",
    "no_path",
    "smoothing_failed",
    "timing_failed",
    "canceled",
    "preempted",
)

#: ``trajopt_ros_interfaces/action/PlanTrajectory`` result codes by reason.
PLAN_TRAJECTORY: dict[str, int] = {"none": 0} | {
    r: 899 + i for i, r in enumerate(REASONS) if r != "none"
}

#: ``nav2_msgs/action/ComputePathToPose`` result codes by reason.
COMPUTE_PATH_TO_POSE: dict[str, int] = {
    "none": 0,
    "unknown": 200,
    "invalid_planner": 201,
    "frame_mismatch": 202,  # TF_ERROR
    "start_outside_map": 203,
    "goal_outside_map": 204,
    "start_occupied": 205,
    "goal_occupied": 206,
    "no_path": 208,  # NO_VALID_PATH
    "smoothing_failed": 208,
    "timing_failed": 208,
}

#: ``nav2_msgs/action/SmoothPath`` result codes by reason.
SMOOTH_PATH: dict[str, int] = {
    "none": 0,
    "unknown": 500,
    "invalid_smoother": 501,
    "timeout": 502,  # max_smoothing_duration reached
    "in_collision": 503,  # SMOOTHED_PATH_IN_COLLISION
    "no_path": 504,  # FAILED_TO_SMOOTH_PATH
    "smoothing_failed": 504,
    "timing_failed": 504,
    "start_occupied": 504,
    "goal_occupied": 504,
    "frame_mismatch": 505,  # INVALID_PATH
    "invalid_pose": 505,
    "start_outside_map": 505,
    "goal_outside_map": 505,
    "invalid_input": 505,
}


def reason_of(exc: BaseException) -> str:
    """Name the failure an exception stands for (one of :data:`REASONS`).

    Parameters
    ----------
    exc : BaseException
        A :class:`~trajopt_ros.errors.RequestError` (its ``reason``), or an error of
        :mod:`trajopt` / :mod:`astar`.

    Returns
    -------
    str
    """
    if isinstance(exc, RequestError):
        return exc.reason
    if isinstance(exc, astar.errors.NoPathError):  # trajopt's NoPathError derives from it
        return "no_path"
    if isinstance(exc, trajopt.errors.SmoothingError):
        return "smoothing_failed"
    if isinstance(exc, trajopt.errors.TimingError):
        return "timing_failed"
    if isinstance(exc, astar.errors.InvalidInputError):
        return "invalid_input"
    return "unknown"


def code_for(table: dict[str, int], reason: str) -> int:
    """Return the code of ``reason`` in ``table``, or the table's ``unknown`` code."""
    return table.get(reason, table["unknown"])
