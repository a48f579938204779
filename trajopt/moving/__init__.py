"""Moving obstacles: predictions, the continuous-time certificate, re-timing along a path.

* :class:`MovingObstacle`: a disc or convex polygon on a piecewise-linear predicted track;
* :func:`certify_movers` (:class:`MoverCertificate`): a proof, by interval bounds over time,
  that a timed trajectory keeps its distance from every mover at every instant;
* :func:`retime_for_movers`: the same path re-timed (rests at the start and at stops on the way) so
  that the movers pass, certified; :class:`trajopt.errors.BlockedError` when no speed
  profile along the path avoids them;
* :func:`retime_plan`: the same for a plan with turns in place at its ends;
* :func:`st_grid`, :class:`STGrid`: the movers' forbidden regions of the ``(s, t)`` plane.
"""

from trajopt.moving._certificate import MoverCertificate, certify_movers, check_movers
from trajopt.moving._obstacle import MovingObstacle
from trajopt.moving._retime import retime_for_movers, retime_plan
from trajopt.moving._st_grid import STGrid, reachable, st_grid

__all__ = [
    "MoverCertificate",
    "MovingObstacle",
    "STGrid",
    "certify_movers",
    "check_movers",
    "reachable",
    "retime_for_movers",
    "retime_plan",
    "st_grid",
]
