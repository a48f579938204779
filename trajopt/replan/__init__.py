"""Re-planning from a trajectory being driven: keep, re-plan, or brake, turn in place and go.

Internal: users call :meth:`trajopt.Planner.replan`.
"""

from trajopt.replan._replan import BRAKE_AFTER_S, replan_from

__all__ = [
    "BRAKE_AFTER_S",
    "replan_from",
]
