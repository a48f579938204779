"""A plan among predicted movers: the static plan re-timed, or re-routed when blocked.

:func:`plan_for_movers` turns a static plan of :func:`~trajopt.planning.run_query` into one
certified against the movers (:mod:`trajopt.moving`), planning the re-route's legs with the
same options on caches derived from the planner's. :meth:`trajopt.Planner.plan` and
:meth:`trajopt.Planner.replan` call it.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from astar.grid import OccupancyGrid
from trajopt.errors import BlockedError, InvalidInputError
from trajopt.motion import PlanResult
from trajopt.moving import (
    MovingObstacle,
    no_way_past,
    parked_on_path,
    reroute,
    retime_chain,
)
from trajopt.planning._caches import PlannerCaches
from trajopt.planning._options import PlannerOptions, PlanRequest
from trajopt.planning._runner import run_query


def plan_for_movers(
    out: PlanResult,
    movers: tuple[MovingObstacle, ...],
    margin: float,
    options: PlannerOptions,
    caches: PlannerCaches,
    request: PlanRequest,
) -> PlanResult:
    """Re-time a plan for movers, or re-route it (:meth:`trajopt.Planner.plan`); refuse what is not covered.

    The static plan is re-timed on one clock (:func:`trajopt.moving.retime_chain`), unless a
    mover parked on its path provably blocks it (:func:`trajopt.moving.parked_on_path`) or no
    re-timing provably gets past the movers (:func:`trajopt.moving.no_way_past`); when
    it is blocked, :func:`trajopt.moving.reroute` plans other routes on the map with the movers'
    swept regions marked (each leg planned by :func:`~trajopt.planning.run_query` with the
    planner's options, on caches derived from the planner's for the marked map).
    """
    if out.v_start != 0.0:
        raise InvalidInputError(
            "moving_obstacles are covered for a plan from rest; this query gave a "
            f"{type(out).__name__} with v_start={out.v_start} m/s"
        )
    if out.polyline:
        raise InvalidInputError(
            "moving_obstacles are not covered for the stop-and-turn fallback's polyline "
            f"(stats['fallback'] = {out.stats.get('fallback')!r}): plan without the fallback"
        )
    blocked = parked_on_path(out, movers, margin)  # quick proofs, before the search's
    if blocked is None:
        blocked = no_way_past(out, movers, margin)
    if blocked is None:
        try:
            kept = retime_chain(out, movers, margin=margin)
        except BlockedError as exc:
            blocked = exc
        else:
            kept.stats["moving"]["route"] = "retimed"
            return kept

    def free() -> np.ndarray:  # where the centre may stand, in the start's part of the map
        inflated = np.asarray(caches.inflated.occupied)
        smp = out.sample(np.array([0.0]))
        ix, iy = (int(c) for c in caches.grid.world_to_cell((float(smp.x[0]), float(smp.y[0]))))
        labels = caches.components
        return ~inflated & (labels == labels[iy, ix]) if labels[iy, ix] > 0 else ~inflated

    def plan_leg(
        grid: OccupancyGrid,
        p0: np.ndarray | None,
        p1: np.ndarray | None,
        heading: float | None,
    ) -> PlanResult:
        leg = request
        if p0 is not None:
            leg = dataclasses.replace(
                leg, start=(float(p0[0]), float(p0[1])), start_heading=heading
            )
        if p1 is not None:
            leg = dataclasses.replace(
                leg, goal=(float(p1[0]), float(p1[1])), goal_heading=None, goal_steer=None
            )
        return run_query(options, caches.derived(grid), leg)

    return reroute(out, movers, margin, blocked, grid=caches.grid, free=free, plan_leg=plan_leg)
