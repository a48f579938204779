"""One planning query, from map and ends to a timed trajectory (the stages' driver).

Internal: users call :func:`trajopt.plan` and :class:`trajopt.Planner`. The package holds
the query record and its intermediate results (:class:`PlanSteps`), the options and the
map's caches, the one query runner (:func:`run_query`) and the stages the drives compose:
a disc's or a footprint's plan (:func:`plan_free`), pose to pose with turns in place
(:func:`plan_turning`), an omnidirectional base's (:func:`plan_omni`) and a car's
(:func:`plan_car`); a plan among predicted movers, re-timed or re-routed
(:func:`plan_among_movers`, :func:`plan_for_movers`; from a re-plan's stop,
:func:`plan_from_stop`).
"""

from trajopt.planning._caches import PlannerCaches, change_reach
from trajopt.planning._car import CarSteps, plan_car
from trajopt.planning._car_tries import car_search_grid
from trajopt.planning._ends import check_endpoint
from trajopt.planning._feasibility import curvature_witness
from trajopt.planning._moving import plan_among_movers, plan_for_movers, plan_from_stop
from trajopt.planning._omni import plan_omni
from trajopt.planning._options import (
    CorridorKind,
    Fallback,
    Inflation,
    PlannerOptions,
    PlanRequest,
    Search,
    SearchMode,
)
from trajopt.planning._query import PlanSteps, WarmStart
from trajopt.planning._runner import plan_free, plan_turning, run_query

__all__ = [
    "plan_among_movers",
    "plan_from_stop",
    "plan_for_movers",
    "CarSteps",
    "CorridorKind",
    "Fallback",
    "Inflation",
    "PlanRequest",
    "PlanSteps",
    "PlannerCaches",
    "PlannerOptions",
    "Search",
    "SearchMode",
    "WarmStart",
    "car_search_grid",
    "change_reach",
    "check_endpoint",
    "curvature_witness",
    "plan_car",
    "plan_free",
    "plan_omni",
    "plan_turning",
    "run_query",
]
