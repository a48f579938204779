"""Moving obstacles: predictions, the continuous-time certificate, re-timing along a path.

* :class:`MovingObstacle`: a disc or convex polygon on a piecewise-linear predicted track;
* :func:`certify_movers` (:class:`MoverCertificate`): a proof, by interval bounds over time,
  that a timed trajectory keeps its distance from every mover at every instant;
* :func:`retime_for_movers`: the same path re-timed (rests at the start and at stops on the way) so
  that the movers pass, certified; :class:`trajopt.errors.BlockedError` when no speed
  profile along the path avoids them;
* :func:`retime_plan`: the same for a plan with turns in place at its ends;
* :func:`retime_chain`: any plan from rest on one clock (curves, turns in place, a car's
  drives between cusps and steering at rest, an omni orientation); :func:`shift_clock`;
  :func:`joined_certificates`: one certificate summary of parts certified one after another;
* :func:`parked_on_path`: a quick proof that a mover parked on the path blocks it
  (:func:`over_start`: whether a mover is over a point at ``t = 0``);
  :func:`no_way_past`: a quick proof that no re-timing along the path gets past the movers
  (:func:`reachable_times`: its sweep of the necessary grid, node by node;
  :func:`meets_head_on`: a cheap screen for when it is worth running first);
* :func:`reroute`: another route, or a wait at a safe place, when no re-timing along the
  path avoids the movers (:func:`around_final_places`: its first route, also tried when the
  re-timing waits and a mover ends beside the path; :func:`goal_taken`: none when a mover
  ends standing on the goal;
  :func:`car_headings`: how a car stands at a safe place; :func:`safe_places`: where it
  waits); :func:`swept_mask`,
  :func:`mark_swept`: a mover's swept region on a grid (:func:`swept_cells`: on given cells;
  :func:`reached_swept_mask`: only where a robot could meet the mover);
* :func:`st_grid`, :class:`STGrid`: the movers' forbidden regions of the ``(s, t)`` plane;
* :func:`load_movers`, :func:`save_movers` (:func:`movers_from_data`,
  :func:`movers_to_data`): predicted movers in a JSON or YAML file.
"""

from trajopt.moving._certificate import MoverCertificate, certify_movers, check_movers
from trajopt.moving._chain import (
    joined_certificates,
    retime_chain,
    retime_plan,
    shift_clock,
    truncate,
)
from trajopt.moving._mover_file import load_movers, movers_from_data, movers_to_data, save_movers
from trajopt.moving._no_way_past import meets_head_on, no_way_past, reachable_times
from trajopt.moving._obstacle import MovingObstacle
from trajopt.moving._parked import over_start, parked_on_path, settle_time
from trajopt.moving._reroute import (
    N_SAFE_PLACES,
    SAFE_PLACE_SPACING,
    around_final_places,
    car_headings,
    goal_taken,
    reroute,
    safe_places,
)
from trajopt.moving._retime import retime_for_movers
from trajopt.moving._st_grid import STGrid, reachable, st_grid
from trajopt.moving._swept import mark_swept, reached_swept_mask, swept_cells, swept_mask

__all__ = [
    "N_SAFE_PLACES",
    "SAFE_PLACE_SPACING",
    "MoverCertificate",
    "MovingObstacle",
    "STGrid",
    "around_final_places",
    "car_headings",
    "certify_movers",
    "check_movers",
    "goal_taken",
    "joined_certificates",
    "load_movers",
    "mark_swept",
    "meets_head_on",
    "movers_from_data",
    "movers_to_data",
    "no_way_past",
    "over_start",
    "parked_on_path",
    "reachable",
    "reachable_times",
    "reached_swept_mask",
    "reroute",
    "save_movers",
    "retime_chain",
    "retime_for_movers",
    "retime_plan",
    "safe_places",
    "settle_time",
    "shift_clock",
    "st_grid",
    "swept_cells",
    "swept_mask",
    "truncate",
]
