"""What every plan and re-plan returns: the :class:`PlanResult` protocol.

:class:`~trajopt.motion.Trajectory` (one curve), :class:`~trajopt.motion.TrajectoryChain`
(pieces joined at rest: turns in place, cusps), :class:`~trajopt.motion.OmniTrajectory`
(a path and a body orientation) and :class:`~trajopt.motion.StopAndTurnTrajectory` (the
fallback) all satisfy it, so a caller reads any plan the same way.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Protocol, runtime_checkable

import numpy as np

from trajopt.robot import Robot, State


@runtime_checkable
class PlanResult(Protocol):
    """A timed trajectory as a plan returns it.

    Attributes
    ----------
    duration : float
        Total time (s).
    robot : Robot
        The robot it was planned for.
    stats : dict
        What the planner measured and chose (stage times in s, the corridor, ...).
    steps : object or None
        The intermediate results of the plan (:class:`trajopt.planning.PlanSteps` or a
        car's steps), ``None`` for a trajectory built by hand.
    """

    @property
    def duration(self) -> float:
        """Total time (s)."""
        ...

    @property
    def robot(self) -> Robot:
        """The robot."""
        ...

    @property
    def stats(self) -> dict[str, Any]:
        """The plan's statistics."""
        ...

    @property
    def steps(self) -> Any:
        """The plan's intermediate results."""
        ...

    def sample(self, t: np.ndarray | float) -> Any:
        """Return samples at times ``t`` (s): a sample record whose arrays have the shape of ``t``."""
        ...

    def sample_uniform(self, dt: float) -> Any:
        """Return samples every ``dt`` seconds from 0, plus the end time."""
        ...

    def state_at(self, t: float) -> State:
        """Return the moving state at time ``t`` (s)."""
        ...

    def to_dict(self, dt: float = 0.01) -> dict[str, Any]:
        """Return samples every ``dt`` seconds and the plan's description as plain values."""
        ...

    def to_json(self, path: str | os.PathLike, dt: float = 0.01, *, frame_id: str = "map") -> Path:
        """Write :meth:`to_dict` as JSON."""
        ...

    def to_csv(self, path: str | os.PathLike, dt: float = 0.01, *, frame_id: str = "map") -> Path:
        """Write samples as CSV."""
        ...

    def to_mcap(
        self,
        path: str | os.PathLike,
        dt: float = 0.01,
        *,
        frame_id: str = "map",
        child_frame_id: str = "base_link",
        start_time: float = 0.0,
        movers: Any = None,
        movers_dt: float | None = None,
    ) -> Path:
        """Write a ROS 2 MCAP file (with ``movers``: their markers)."""
        ...
