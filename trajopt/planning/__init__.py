"""One planning query, from map and ends to a timed trajectory (the stages' driver).

Internal: users call :func:`trajopt.plan` and :class:`trajopt.Planner`. The package holds
the query record and its intermediate results (:class:`PlanSteps`), the corridor fit with
its witness rescue, the opt-in fallback and the footprint robots' disc ladder.
"""

from trajopt.planning._query import PlanSteps

__all__ = [
    "PlanSteps",
]
