"""Timed motions as values: what the planner returns and what a robot drives.

* :class:`Trajectory`: a timed smooth curve (built by :func:`trajopt.time_parameterize`);
* :class:`StopAndTurnTrajectory`: a polyline driven straight with turns in place at rest
  (built by :func:`trajopt.stop_and_turn`);
* :class:`TurnInPlace` and :class:`TrajectoryChain`: a rotation at rest, and motions played
  one after another (a braking re-plan);
* :class:`SteerInPlace` (built by :func:`steer_in_place`): a car's steering at rest, at its
  cusps and ends;
* :class:`OmniTrajectory`: an omnidirectional base's translation with an orientation of its
  own (built by :func:`trajopt.timing.orient`);
* :class:`PlanResult`: the protocol every plan and re-plan satisfies;
* :class:`TrajectorySample`, :class:`OmniSample` and :class:`CarSample` (a car-like
  robot's signed speed, direction of travel and steering), and the ROS 2 MCAP writer and reader.
"""

from trajopt.motion._chain import SteerInPlace, TrajectoryChain, TurnInPlace, steer_in_place
from trajopt.motion._mcap import McapContents, McapExportError, read_mcap, write_mcap
from trajopt.motion._omni import OmniTrajectory
from trajopt.motion._result import PlanResult
from trajopt.motion._samples import CarSample, OmniSample, TrajectorySample
from trajopt.motion._stop_and_turn import StopAndTurnTrajectory
from trajopt.motion._trajectory import Orientation, Trajectory

__all__ = [
    "CarSample",
    "McapContents",
    "McapExportError",
    "OmniSample",
    "OmniTrajectory",
    "Orientation",
    "PlanResult",
    "SteerInPlace",
    "StopAndTurnTrajectory",
    "Trajectory",
    "TrajectoryChain",
    "TrajectorySample",
    "TurnInPlace",
    "read_mcap",
    "steer_in_place",
    "write_mcap",
]
