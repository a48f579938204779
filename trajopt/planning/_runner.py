"""The one query runner every entry point calls: :func:`run_query`.

:func:`trajopt.plan`, :meth:`trajopt.Planner.plan`, a re-plan from a moving state, the plan
from rest after braking, and the benchmark's planner methods all plan through it, with
their options, the map's caches, the request, a re-plan's warm start and a time budget as
explicit inputs.
"""

from __future__ import annotations

from trajopt.motion import PlanResult
from trajopt.planning._caches import PlannerCaches
from trajopt.planning._disc import plan_disc
from trajopt.planning._ends import check_steer
from trajopt.planning._footprint_ladder import plan_with_footprint
from trajopt.planning._options import PlannerOptions, PlanRequest
from trajopt.planning._pose import needs_pose_plan, plan_pose
from trajopt.planning._query import WarmStart


def run_query(
    options: PlannerOptions,
    caches: PlannerCaches,
    request: PlanRequest,
    warm: WarmStart | None = None,
    budget_s: float | None = None,
) -> PlanResult:
    """Plan one query with the stages the robot's drive composes (:meth:`Drive.plan`).

    A differential drive plans a disc robot's stages or a footprint robot's disc ladder,
    pose to pose with turns in place where they are faster or where no curve leaves along
    a given heading (:func:`plan_turning`); an omnidirectional base plans the path of its
    (circumscribed) disc and turns its orientation while it drives
    (:func:`~trajopt.planning._omni.plan_omni`); a car-like robot plans pose to pose with a
    turning radius and cusps (:func:`~trajopt.planning._car.plan_car`; no warm start).

    Parameters
    ----------
    options : PlannerOptions
        Resolved for the map of ``caches`` (:meth:`PlannerOptions.for_map`).
    caches : PlannerCaches
        The map and what queries on it share.
    request : PlanRequest
        The ends, headings and speeds (and a car's steering angles, checked against the
        robot first: :func:`~trajopt.planning._ends.check_steer`).
    warm : WarmStart, optional
        A re-plan's grid path and old steps (a disc robot's; a footprint robot's ladder
        plans each rung afresh).
    budget_s : float, optional
        Cap on the smoother's time budget (s) for this query (a re-plan's, which brakes
        rather than wait).

    Returns
    -------
    PlanResult
        See :meth:`trajopt.Planner.plan`.
    """
    check_steer(options.robot, request)
    options = options.with_budget(budget_s)
    return options.robot.drive.plan(options, caches, request, warm)


def plan_turning(
    options: PlannerOptions,
    caches: PlannerCaches,
    request: PlanRequest,
    warm: WarmStart | None = None,
) -> PlanResult:
    """Plan for a base that faces its direction of travel and turns in place at rest.

    Pose to pose (:func:`~trajopt.planning._pose.plan_pose`) where a heading is given at
    an end where the robot rests, else :func:`plan_free`.
    """
    if needs_pose_plan(request):

        def plan(req: PlanRequest, w: WarmStart | None, b: float | None) -> PlanResult:
            return plan_free(options.with_budget(b), caches, req, w)

        return plan_pose(options, caches.grid, request, plan, warm)
    return plan_free(options, caches, request, warm)


def plan_free(
    options: PlannerOptions,
    caches: PlannerCaches,
    request: PlanRequest,
    warm: WarmStart | None = None,
) -> PlanResult:
    """Run a disc robot's stages, or a footprint robot's disc ladder (which starts afresh)."""
    if options.robot.footprint is not None:
        return plan_with_footprint(options, caches, request)
    return plan_disc(options, caches, request, warm)
