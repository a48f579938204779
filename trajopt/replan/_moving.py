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
:func:`trajopt.retime_for_movers`: milliseconds, no new path. A chain (brake, turn and go; a
car's brake and plan from the stopped pose; the rest of such a chain) is split where it
first starts a piece at rest (:func:`split_at_rest`): the head before it (a brake from the
splice state, the end of a turn in place playing at the splice) is played as it is, since
the robot is committed to it until it stops; the tail, a plan from rest, is re-timed by
:func:`trajopt.moving.retime_chain` on the movers' clock seen from the head's end (turns in
place, a car's drives between cusps, an omni orientation). Whatever is returned is certified
whole (:func:`trajopt.certify_movers` against the shifted movers); a result with no piece
from rest after its head (an omni base's own orientation from the moving state) is only
certified. ``BlockedError`` from the re-timing or the certificate propagates (its time on
the movers' clock).
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Sequence
from typing import Any

from trajopt.errors import BlockedError, InvalidInputError
from trajopt.motion import PlanResult, TrajectoryChain
from trajopt.moving import (
    MovingObstacle,
    certify_movers,
    retime_chain,
    retime_for_movers,
    shift_clock,
)


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
            raise _on_movers_clock(exc, ts) from exc
        moving = dict(timed.stats["moving"])
    else:
        head, tail = split_at_rest(out)
        if tail:
            timed, moving = _retime_tail(out, head, tail, movers, margin, ts, shifted)
        else:
            timed, moving = out, {"plan": "as planned"}
        cert = certify_movers(timed, shifted, margin=margin)
        if not cert.ok:
            raise BlockedError(
                f"moving obstacle {cert.mover!r} meets the re-plan ({type(out).__name__}, "
                f"{out.stats.get('replan', '')}) at t = {cert.witness_t + ts:.3f} s of the "
                f"movers' clock ({'before it stops' if tail else 'it does not stop on the way'}"
                ": only what follows a stop is re-timed)",
                mover=cert.mover,
                t=cert.witness_t + ts,
            )
        moving["certificate"] = {
            "ok": cert.ok,
            "slack_m": cert.slack,
            "mover": cert.mover,
            "horizon_s": cert.horizon,
            "intervals": cert.intervals,
        }
    moving.update(
        time_s=time.perf_counter() - t0,
        clock_offset_s=float(ts),
        replan=out.stats.get("replan"),
    )
    return dataclasses.replace(timed, stats=dict(timed.stats, moving=moving))


def _on_movers_clock(exc: BlockedError, t0: float) -> BlockedError:
    """``exc`` with its time ``t0`` later: from the result's clock to the movers' clock."""
    return BlockedError(
        f"{exc} (times from the splice, at t = {t0:.3f} s of the movers' clock)",
        mover=exc.mover,
        t=exc.t + t0,
    )


def split_at_rest(out: PlanResult) -> tuple[list[tuple[Any, float]], list[Any]]:
    """Split a re-plan's result where it first starts a piece at rest, from there on whole.

    Returns the head, ``(piece, start)`` pairs played as they are (a brake from the splice
    state, the end of a turn in place playing at the splice: the robot is committed to them),
    and the tail, the pieces that follow, each played whole from rest (empty when the result
    does not start a piece at rest after its head: one curve from the moving state, an omni
    base's own orientation).
    """
    if not isinstance(out, TrajectoryChain):
        return [(out, 0.0)], []
    starts = out.starts or (0.0,) * len(out.pieces)
    head: list[tuple[Any, float]] = []
    for i, (piece, t_in) in enumerate(zip(out.pieces, starts, strict=True)):
        if t_in == 0.0 and float(piece.v_start) == 0.0 and not isinstance(piece, TrajectoryChain):
            return head, list(out.pieces[i:])
        head.append((piece, float(t_in)))
    return head, []


def _retime_tail(
    out: TrajectoryChain,
    head: list[tuple[Any, float]],
    tail: list[Any],
    movers: Sequence[MovingObstacle],
    margin: float,
    ts: float,
    shifted: Sequence[MovingObstacle],
) -> tuple[TrajectoryChain, dict[str, Any]]:
    """Re-time the pieces that follow the head on the clock where the head ends.

    The tail, a plan from rest, is re-timed by :func:`trajopt.moving.retime_chain` against
    the movers seen from the head's end (``ts`` plus the head's duration on the movers'
    clock); the head stays as it is. ``BlockedError`` is given the movers' clock.
    """
    t_head = sum(float(p.duration) - t_in for p, t_in in head)
    plan = (
        tail[0]
        if len(tail) == 1
        else TrajectoryChain(tuple(tail), out.robot, dict(out.stats), out.steps)
    )
    seen = [shift_clock(m, ts + t_head) for m in movers]
    try:
        timed = retime_chain(plan, seen, margin=margin)
    except BlockedError as exc:
        raise _on_movers_clock(exc, ts + t_head) from exc
    if isinstance(timed, TrajectoryChain):
        rest = list(timed.pieces)
        rest_starts = list(timed.starts or (0.0,) * len(timed.pieces))
    else:
        rest, rest_starts = [timed], [0.0]
    chain = TrajectoryChain(
        tuple([p for p, _ in head] + rest),
        out.robot,
        dict(out.stats),
        out.steps,
        tuple([t for _, t in head] + rest_starts),
    )
    moving = {
        "plan": f"kept {t_head:.3f} s to a stop, then: {timed.stats['moving']['plan']}",
        "head_s": t_head,
    }
    return chain, moving
