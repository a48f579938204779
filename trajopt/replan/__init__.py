"""Re-planning from a trajectory being driven: keep, re-plan, or brake, turn in place and go.

Internal: users call :meth:`trajopt.Planner.replan`. :func:`replan_from` checks the splice
and asks the robot's drive to re-plan: :func:`replan_moving` for a base that turns in place,
:func:`replan_car` for a car. With predicted movers, :func:`retime_replan` re-times the
result for them (:mod:`trajopt.replan._moving`), or stops and goes on from the stop (told
the path followed when it is proved blocked: :class:`Along`). A plan re-routed on a map
with movers' regions marked records the static map the marks were drawn on
(:func:`record_marked`, :class:`MarkedSteps`, a car's :class:`MarkedCarSteps`): a re-plan
keeps its rest by that map.
"""

from trajopt.replan._car import replan_car
from trajopt.replan._marked import MarkedCarSteps, MarkedSteps, planned_on, record_marked
from trajopt.replan._moving import Along, retime_replan
from trajopt.replan._replan import BRAKE_AFTER_S, replan_from, replan_moving

__all__ = [
    "Along",
    "BRAKE_AFTER_S",
    "MarkedCarSteps",
    "MarkedSteps",
    "planned_on",
    "record_marked",
    "replan_car",
    "replan_from",
    "replan_moving",
    "retime_replan",
]
