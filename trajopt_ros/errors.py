"""The exceptions of :mod:`trajopt_ros` (none of them needs ROS to be imported)."""

from __future__ import annotations

__all__ = ["TrajoptRosError", "ParameterError", "InterfaceBuildError", "RequestError"]


class TrajoptRosError(Exception):
    """Base class of every exception raised by :mod:`trajopt_ros`."""


class ParameterError(TrajoptRosError, ValueError):
    """A node parameter breaks a rule (the message names the parameter, value and rule)."""


class InterfaceBuildError(TrajoptRosError):
    """The interface packages could not be built (the message ends with the build log)."""


class RequestError(TrajoptRosError, ValueError):
    """A request or message cannot be planned (a frame, pose or map breaks a rule).

    Attributes
    ----------
    reason : str
        The failure's name: one of :data:`trajopt_ros.codes.REASONS` (``"no_map"``,
        ``"frame_mismatch"``, ``"invalid_pose"``, ...), or one that only Nav2's actions
        have a code for (``"invalid_planner"``, ``"invalid_smoother"``, ``"in_collision"``,
        ``"timeout"``).
    """

    def __init__(self, reason: str, message: str) -> None:
        super().__init__(message)
        self.reason = reason
