"""Re-planning with predicted moving obstacles: the spliced trajectory re-timed for the movers.

:meth:`~trajopt._planner.Planner.replan` with ``moving_obstacles`` first re-plans as without
them (:func:`~trajopt.replan._replan.replan_from`: keep the rest, plan from the moving state,
or brake, turn and go), then hands the result to :func:`retime_replan`.

**Clocks.** The movers' times are on the clock of the trajectory being re-planned: seconds
from its ``t = 0``, the clock of the ``t`` given to ``replan`` (for a plan of
:meth:`~trajopt._planner.Planner.plan`, the plan's start). The re-plan's result starts at the
splice ``ts = t + latency`` on that clock: its own time ``tau`` is ``ts + tau`` there. The
movers are shifted to the result's clock (:func:`trajopt.moving.shift_clock`: times ``- ts``; a radius
that grows with the prediction time keeps its value at every instant), and the result's
``stats["moving"]["clock_offset_s"]`` is ``ts``. Predictions for a later re-plan of the
result are on the result's clock.

**What is re-timed.** A result of one curve that ends at rest (the kept rest when only the
predictions changed, or a plan from the moving state to a new goal or on a new map) keeps its
path and is re-timed from its start state (speed and acceleration at the splice) by
:func:`trajopt.retime_for_movers`: milliseconds, no new path. Any other result (a brake, turn
and go chain, an omni base's own orientation, a car's plan) is certified as it is
(:func:`trajopt.certify_movers`). ``BlockedError`` from either propagates: a re-route around
the blocking mover belongs where it is raised (module :mod:`trajopt.moving`'s re-routing).
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Sequence

from trajopt.errors import BlockedError, InvalidInputError
from trajopt.motion import PlanResult
from trajopt.moving import MovingObstacle, certify_movers, retime_for_movers, shift_clock


def retime_replan(
    out: PlanResult,
    movers: Sequence[MovingObstacle],
    margin: float,
    ts: float,
) -> PlanResult:
    """Re-time a re-plan's result for the movers (module docstring).

    Parameters
    ----------
    out : Trajectory, StopAndTurnTrajectory or TrajectoryChain
        The re-plan's result, its ``t = 0`` at the splice.
    movers : sequence of MovingObstacle
        The predictions on the re-planned trajectory's clock (non-empty, checked).
    margin : float
        Extra distance to every mover (m), >= 0.
    ts : float
        The splice time on that clock (s).

    Returns
    -------
    Trajectory or other PlanResult
        ``out`` re-timed (or ``out`` itself, certified), with ``stats["moving"]``: the
        re-timing's ``plan``, ``certificate`` and ``time_s``, plus ``clock_offset_s`` (``ts``)
        and ``replan`` (what the re-plan did before: ``stats["replan"]``).

    Raises
    ------
    BlockedError
        No re-timing along the result's path avoids a mover, or a result that is not
        re-timed fails the certificate (the mover is named; its ``t`` is on the movers'
        clock).
    InvalidInputError
        A mover overlaps the robot at the splice; an end speed ``v_end > 0``.
    """
    t0 = time.perf_counter()
    shifted = tuple(shift_clock(m, ts) for m in movers)
    if out.v_end != 0.0:
        raise InvalidInputError(
            f"moving_obstacles need a goal at rest (the robot then stands there while the "
            f"predictions last), got v_end={out.v_end!r} m/s"
        )
    if out.single_curve and out.direction == 1:
        try:
            timed = retime_for_movers(out, shifted, margin=margin)
        except BlockedError as exc:  # its time back on the movers' clock
            raise BlockedError(
                f"{exc} (times from the splice, at t = {ts:.3f} s of the movers' clock)",
                mover=exc.mover,
                t=exc.t + ts,
            ) from exc
        moving = dict(timed.stats["moving"])
    else:
        cert = certify_movers(out, shifted, margin=margin)
        if not cert.ok:
            raise BlockedError(
                f"moving obstacle {cert.mover!r} meets the re-plan ({type(out).__name__}, "
                f"{out.stats.get('replan', '')}) at t = {cert.witness_t + ts:.3f} s of the "
                "movers' clock, and only a single curve ending at rest is re-timed",
                mover=cert.mover,
                t=cert.witness_t + ts,
            )
        timed = out
        moving = {
            "plan": "as planned",
            "certificate": {
                "ok": cert.ok,
                "slack_m": cert.slack,
                "mover": cert.mover,
                "horizon_s": cert.horizon,
                "intervals": cert.intervals,
            },
        }
    moving.update(
        time_s=time.perf_counter() - t0,
        clock_offset_s=float(ts),
        replan=out.stats.get("replan"),
    )
    return dataclasses.replace(timed, stats=dict(timed.stats, moving=moving))
