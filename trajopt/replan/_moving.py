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
place, a car's drives between cusps, an omni orientation). Whatever is returned has one
complete proof (:func:`trajopt.certify_movers` against the shifted movers, over its whole
clock and the standing at the goal until the last prediction ends), made once: one curve's
certificate as it is comes first (kept as planned when it passes: no other proof runs), and a
re-timed curve's is the certificate :func:`trajopt.retime_for_movers` made of it; a chain's
is its tail's from :func:`~trajopt.moving.retime_chain` (from the head's end on) joined with
the head's against the movers ended where the head stops (:func:`trajopt.moving.truncate`;
none when the head plays for no time). An omni base's own orientation from the moving state
has its translation certified as it is, else re-timed, as the circumscribed disc, its
orientation profile kept as it is in time (:func:`_retimed_omni`); when blocked, its
translation brakes along its path with the yaw rate stopped beside it
(:func:`trajopt.timing.stop_orientation`), certified as its translation's disc.

**When the re-timing is blocked** (``BlockedError``, and the caller gives ``from_stop``):
the robot stops, since it is moving at the splice. One curve from the moving state is braked
along its path (:func:`~trajopt.replan._brake.brake_on_path`; an omni base's own orientation
has its yaw rate stopped beside the brake); a chain keeps its head, which ends at rest. From the stopped pose ``from_stop`` plans on to the goal for the movers seen
from the stop, as :meth:`~trajopt._planner.Planner.plan` does with movers (the static plan
re-timed, else re-routed around the blocking mover's swept region, or a wait at a safe
place: :func:`trajopt.moving.reroute`). The stop and that plan are certified as one chain
against the shifted movers: the plan on by its own certificate (against the movers seen from
the stop), the stop by one against the movers ended where it stops
(:func:`trajopt.moving.truncate`). ``stats["moving"]["route"]`` is ``"retimed"`` or ``"stopped: <route>"``.
``BlockedError`` (the mover named, its time on the movers' clock) when no stop applies, no
plan from the stop works or the robot meets a mover while it stops.

**A path proved blocked** (:func:`blocked_along`): the quick proofs on what must be re-timed
(one curve from the moving state that fails its certificate as it is, whose reach bound
``v_max t`` holds every motion along its path, a brake to a stop on it and any motion from rest after
it included; a chain's tail, a plan from rest after the head) show that nothing along the path
followed gets past the movers from the stop on. :func:`trajopt.moving.parked_on_path` runs
before the re-timing (a mover that parks on the rest: no search), and so does
:func:`trajopt.moving.no_way_past` when a mover drives along the path against it
(:func:`trajopt.moving.meets_head_on`, a cheap screen: the re-timing's search would likely fail
after it); otherwise ``no_way_past`` runs after the re-timing fails. The proof is handed to
``from_stop`` (:class:`Along`: the proof and the path's points from the stop), which then tries
the re-route's candidates at once and the static plan from the stop last: that plan is a new
search from a point of the path followed, to the same goal on the same map, so it usually takes
the path's rest again (blocked), but it may leave it (another grid path, smoothing or start
heading), so it is tried rather than dropped.
"""

from __future__ import annotations

import dataclasses
import functools
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from trajopt.errors import BlockedError, InvalidInputError, TrajoptError
from trajopt.motion import PlanResult, TrajectoryChain
from trajopt.moving import (
    MovingObstacle,
    certify_movers,
    joined_certificates,
    meets_head_on,
    no_way_past,
    over_start,
    parked_on_path,
    retime_chain,
    retime_for_movers,
    shift_clock,
    truncate,
)
from trajopt.replan._brake import brake_on_path
from trajopt.timing import stop_orientation


def retime_replan(
    out: PlanResult,
    movers: Sequence[MovingObstacle],
    margin: float,
    ts: float,
    from_stop: FromStop | None = None,
) -> PlanResult:
    """Re-time a re-plan's result for the movers, or stop and go on another way (module docstring).

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
    from_stop : callable, optional
        ``from_stop(position, heading, steer, movers)`` (:data:`FromStop`): a plan from rest
        at a stop to the goal for the movers seen from the stop (re-timed, else re-routed,
        certified), or a ``TrajoptError``; ``None``: no re-route (``BlockedError`` as the
        re-timing raised it).

    Returns
    -------
    Trajectory or other PlanResult
        ``out`` re-timed (or ``out`` itself, certified), or stopped and re-routed, with
        ``stats["moving"]``: the re-timing's ``plan``, ``certificate`` and ``time_s``,
        ``route`` (``"retimed"``, or ``"stopped: <route>"``: braked to a stop and planned on
        from there, ``<route>`` that plan's ``"retimed"``, ``"rerouted"`` or ``"waited"``),
        plus ``clock_offset_s`` (``ts``) and ``replan`` (what the re-plan did before:
        ``stats["replan"]``).

    Raises
    ------
    BlockedError
        No re-timing along the result's path avoids a mover and no way on from a stop does
        either, or the part played before the stop meets a mover (the mover is named; its
        ``t`` is on the movers' clock).
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
    head_on: list[bool] = []

    @functools.cache
    def seen_from(t0: float) -> tuple[MovingObstacle, ...]:
        # the movers seen from t0 of their clock, made once per t0: the quick proofs and a
        # chain's tail's re-timing see the same objects, whose table the certificate keeps
        return tuple(shift_clock(m, t0) for m in movers)

    def head_on_proof(plan: Any, seen: Sequence[MovingObstacle], margin: float) -> Any:
        head_on.append(meets_head_on(plan, seen, margin))
        return no_way_past(plan, seen, margin) if head_on[-1] else None

    as_is = None  # one curve from the moving state: its certificate as it is comes first
    if out.single_curve and out.direction == 1:
        as_is = certify_movers(out, shifted, margin=margin)
    proof = None
    if as_is is None or not as_is.ok:  # the proofs only for a path that must be re-timed
        proof = blocked_along(out, seen_from, margin, ts, shifted, (parked_on_path, head_on_proof))
    try:
        if proof is not None:
            raise proof
        timed, moving = _retimed(out, seen_from, margin, ts, shifted, as_is)
        moving["route"] = "retimed"
    except BlockedError as exc:
        if from_stop is None:
            raise
        if proof is None and not any(head_on):  # is the path followed blocked from the stop on?
            proof = blocked_along(out, seen_from, margin, ts, shifted, (no_way_past,))
        timed, moving = _stop_and_go_on(
            out, movers, margin, ts, shifted, from_stop, exc, along=proof
        )
    moving.update(
        time_s=time.perf_counter() - t0,
        clock_offset_s=float(ts),
        replan=out.stats.get("replan"),
    )
    return dataclasses.replace(timed, stats=dict(timed.stats, moving=moving))


def _retimed(
    out: PlanResult,
    seen_from: Callable[[float], Sequence[MovingObstacle]],
    margin: float,
    ts: float,
    shifted: Sequence[MovingObstacle],
    as_is: Any = None,
) -> tuple[PlanResult, dict[str, Any]]:
    """Re-time the result along its own path (module docstring); ``BlockedError`` if not.

    One proof of what is returned, at every instant until the last prediction ends: one
    curve's certificate from :func:`trajopt.retime_for_movers` (``as_is``, the certificate
    of the curve as it is when the caller has it, is not computed again); a chain's tail's
    from :func:`trajopt.moving.retime_chain` (against the movers seen from the head's end)
    with the head's own against the movers ended where it stops (:func:`_joined_head`); a
    chain with no tail, its certificate whole.
    """
    if out.single_curve and out.direction == 1:
        try:
            timed = retime_for_movers(out, shifted, margin=margin, certificate=as_is)
        except BlockedError as exc:  # its time back on the movers' clock
            raise _on_movers_clock(exc, ts) from exc
        return timed, dict(timed.stats["moving"])
    if getattr(out, "translation", None) is not None and getattr(out, "pieces", None) is None:
        return _retimed_omni(out, margin, ts, shifted)
    head, tail = split_at_rest(out)
    if tail:
        timed, moving = _retime_tail(out, head, tail, seen_from, margin, ts, shifted)
        moving["certificate"] = _joined_head(
            head, float(moving["head_s"]), moving.pop("tail_certificate"), out, shifted, margin
        )
        return timed, moving
    cert = certify_movers(out, shifted, margin=margin)
    if not cert.ok:
        raise BlockedError(
            f"moving obstacle {cert.mover!r} meets the re-plan ({type(out).__name__}, "
            f"{out.stats.get('replan', '')}) at t = {cert.witness_t + ts:.3f} s of the "
            "movers' clock (it does not stop on the way: only what follows a stop is re-timed)",
            mover=cert.mover,
            t=cert.witness_t + ts,
        )
    return out, {"plan": "as planned", "certificate": cert.summary()}


def _retimed_omni(
    out: Any, margin: float, ts: float, shifted: Sequence[MovingObstacle]
) -> tuple[PlanResult, dict[str, Any]]:
    """Re-time an omni base's own orientation from the moving state along its path.

    The translation (from the splice state) is certified as it is, else re-timed
    (:func:`trajopt.retime_for_movers`), as the robot's circumscribed disc (the body may
    face any way); the orientation profile is kept as it is in time (its angle, rate and
    acceleration at the splice, its yaw limits: it does not depend on the translation's
    timing, and a translation that ends at rest may end before or after it). A base with a
    footprint is only certified as it is: its clearance from the static map holds for the
    planned pairs of position and orientation, which a re-timing would change.
    ``BlockedError`` (its time on the movers' clock) when no re-timing avoids the movers.
    """
    tr = out.translation
    radius = float(out.robot.radius)
    as_is = certify_movers(tr, shifted, margin=margin, robot_radius=radius)
    if as_is.ok:
        return out, {"plan": "as planned", "certificate": as_is.summary()}
    if out.robot.footprint is not None:
        raise BlockedError(
            f"moving obstacle {as_is.mover!r} meets the re-plan (an omni base with a "
            f"footprint, from the moving state: not re-timed) at "
            f"t = {as_is.witness_t + ts:.3f} s of the movers' clock",
            mover=as_is.mover,
            t=as_is.witness_t + ts,
        )
    try:
        moved = retime_for_movers(tr, shifted, margin=margin)
    except BlockedError as exc:
        raise _on_movers_clock(exc, ts) from exc
    moved = dataclasses.replace(moved, steps=tr.steps)
    cert = certify_movers(moved, shifted, margin=margin, robot_radius=radius)
    if not cert.ok:  # the re-timing certified the same disc; only a numerical slip lands here
        raise BlockedError(
            f"moving obstacle {cert.mover!r} meets the re-timed omni translation at "
            f"t = {cert.witness_t + ts:.3f} s of the movers' clock ({cert.verdict})",
            mover=cert.mover,
            t=cert.witness_t + ts,
        )
    timed = dataclasses.replace(out, translation=moved)
    return timed, {"plan": str(moved.stats["moving"]["plan"]), "certificate": cert.summary()}


def _joined_head(
    head: list[tuple[Any, float]],
    t_head: float,
    rest: dict[str, Any],
    out: PlanResult,
    shifted: Sequence[MovingObstacle],
    margin: float,
) -> dict[str, Any]:
    """Return the certificate summary of a head and the re-timed plan after it, as one.

    ``rest`` is that plan's certificate summary, against the movers seen from the head's end
    ``t_head`` (s): it covers every instant from there on. The head, when it plays for a
    while, is certified here against ``shifted`` ended at ``t_head``
    (:func:`trajopt.moving.truncate`: equal to them until then). ``BlockedError`` (its time
    on the re-plan's clock) when the head meets a mover.
    """
    if t_head <= 0.0:
        return dict(rest)
    cert = _head_certificate(head, t_head, out.robot, shifted, margin)
    if not cert.ok:
        raise BlockedError(
            f"moving obstacle {cert.mover!r} meets the re-plan ({type(out).__name__}, "
            f"{out.stats.get('replan', '')}) at t = {cert.witness_t:.3f} s after the splice "
            "(before it stops: only what follows a stop is re-timed)",
            mover=cert.mover,
            t=cert.witness_t,
        )
    return joined_certificates([(0.0, cert.summary()), (t_head, rest)])


def _head_certificate(
    head: list[tuple[Any, float]],
    t_head: float,
    robot: Any,
    shifted: Sequence[MovingObstacle],
    margin: float,
) -> Any:
    """Return the certificate of the head played as it is against ``shifted`` ended at ``t_head``.

    An omni base's piece with its own orientation (its brake, the yaw rate stopped beside
    it) is certified as its translation, the circumscribed disc (the body may face any way):
    where its orientation outlasts the translation the base stands still, which the
    translation's certificate covers when the piece ends the head (the robot stands at its
    end until the movers, ended at ``t_head``, last), or when the two end together.
    """
    last = len(head) - 1
    disc = False
    pieces = []
    for i, (p, t_in) in enumerate(head):
        tr = getattr(p, "translation", None)
        if (
            tr is not None
            and t_in < float(tr.duration)
            and (i == last or float(p.duration) - float(tr.duration) <= 1e-12)
        ):
            p, disc = tr, True
        pieces.append(p)
    played_head = (
        pieces[0]
        if len(head) == 1 and head[0][1] == 0.0
        else TrajectoryChain(tuple(pieces), robot, {}, None, tuple(t for _, t in head))
    )
    return certify_movers(
        played_head,
        [truncate(m, t_head) for m in shifted],
        margin=margin,
        robot_radius=float(robot.radius) if disc else None,
    )


def blocked_along(
    out: PlanResult,
    seen_from: Callable[[float], Sequence[MovingObstacle]],
    margin: float,
    ts: float,
    shifted: Sequence[MovingObstacle],
    proofs: Sequence[Callable[..., BlockedError | None]],
) -> BlockedError | None:
    """Return a proof that the path the robot follows is blocked from where it stops, or ``None``.

    The quick ``proofs`` (:func:`trajopt.moving.parked_on_path`,
    :func:`trajopt.moving.no_way_past`) on what :func:`_retimed` re-times: one curve from the
    moving state against ``shifted`` (their reach bound from a moving start, ``v_max t``, holds
    every motion along the path, those that brake to a stop on it and go on from rest
    included), or a chain's tail, a plan from rest after the head, against the movers seen
    from the head's end (``seen_from(t0)``: the movers seen from ``t0`` of their clock, the
    objects its re-timing is given too). Either way nothing along that path from the stop gets past. Its time
    is on the movers' clock; ``None`` when they find nothing or a mover is within the robot's
    circumscribed radius of the start at ``t = 0`` (the re-timing decides, or refuses that as
    bad input).
    """
    if out.single_curve and out.direction == 1:
        plan, t0, seen = out, ts, shifted
    else:
        head, tail = split_at_rest(out)
        if not tail:
            return None
        t_head = sum(float(p.duration) - t_in for p, t_in in head)
        plan = tail[0] if len(tail) == 1 else TrajectoryChain(tuple(tail), out.robot, {}, None)
        t0 = ts + t_head
        seen = seen_from(t0)
    start = plan.sample(np.array([0.0]))
    if over_start((float(start.x[0]), float(start.y[0])), seen, float(out.robot.radius) + margin):
        return None  # a mover over the robot (its circumscribed disc): the re-timing refuses it
    for prove in proofs:
        proof = prove(plan, seen, margin)
        if proof is not None:
            return _on_movers_clock(proof, t0)
    return None


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
    if getattr(out, "pieces", None) is None:
        return [(out, 0.0)], []
    pieces, starts = played(out)
    head: list[tuple[Any, float]] = []
    for i, (piece, t_in) in enumerate(zip(pieces, starts, strict=True)):
        whole = getattr(piece, "pieces", None) is None  # a nested chain is not split
        if t_in == 0.0 and float(piece.v_start) == 0.0 and whole:
            return head, pieces[i:]
        head.append((piece, t_in))
    return head, []


def played(plan: Any) -> tuple[list[Any], list[float]]:
    """Return a plan's pieces and the time within each where it starts playing (one piece: itself)."""
    pieces = getattr(plan, "pieces", None)
    if pieces is None:
        return [plan], [0.0]
    return list(pieces), [float(t) for t in (plan.starts or (0.0,) * len(pieces))]


def _retime_tail(
    out: TrajectoryChain,
    head: list[tuple[Any, float]],
    tail: list[Any],
    seen_from: Callable[[float], Sequence[MovingObstacle]],
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
    seen = seen_from(ts + t_head)
    try:
        timed = retime_chain(plan, seen, margin=margin)
    except BlockedError as exc:
        raise _on_movers_clock(exc, ts + t_head) from exc
    rest, rest_starts = played(timed)
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
        "tail_certificate": timed.stats["moving"]["certificate"],
    }
    return chain, moving


#: ``from_stop(position, heading, steer, movers, along)``: a plan from rest at ``position``
#: (m, shape (2,)) with ``heading`` (rad) and a car's ``steer`` (rad) to the re-plan's goal,
#: re-timed for ``movers`` (seen from the stop), else re-routed around them, certified;
#: raises ``TrajoptError`` otherwise. ``along``: ``None``, or the path being followed from
#: the stop (:class:`Along`), proved blocked: the re-route's candidates come first, the static
#: plan from the stop last.
FromStop = Callable[..., PlanResult]


@dataclasses.dataclass(frozen=True)
class Along:
    """The path the robot follows, from where it stops, proved blocked for the movers.

    Attributes
    ----------
    blocked : BlockedError
        The proof (:func:`blocked_along`), its time on the clock seen from the stop (s).
    points : ndarray, shape (n, 2)
        Points (m) of that path from the stop to the goal, at most 10 cm apart.
    """

    blocked: BlockedError
    points: np.ndarray


def _stop_and_go_on(
    out: PlanResult,
    movers: Sequence[MovingObstacle],
    margin: float,
    ts: float,
    shifted: Sequence[MovingObstacle],
    from_stop: FromStop,
    blocked: BlockedError,
    *,
    along: BlockedError | None = None,
) -> tuple[PlanResult, dict[str, Any]]:
    """Brake to a stop (or keep the head that ends in one) and plan on from the stop.

    One curve from the moving state is braked along its path
    (:func:`~trajopt.replan._brake.brake_on_path`, time-optimal and jerk-limited; an omni
    base's own orientation with its yaw rate stopped beside it, :func:`_omni_stop`); a chain
    keeps its head (:func:`split_at_rest`), which ends at rest. From the stop ``from_stop``
    plans on for the movers seen from there (``ts`` plus the stop's time), told the path
    followed from the stop (:class:`Along`) when ``along`` proves it blocked
    (:func:`blocked_along`); the head and that plan are certified as one chain against
    ``shifted`` (:func:`_whole_certificate`).
    ``BlockedError`` (the mover named, its time on the movers' clock) when no stop applies,
    no plan from the stop works or the head meets a mover.
    """
    head: list[tuple[Any, float]] = []
    if getattr(out, "pieces", None) is not None:
        head, tail = split_at_rest(out)
        if not tail:
            raise blocked
        stop = tail[0].sample(np.array([0.0]))
        ahead = tail
    elif out.single_curve and out.direction == 1:
        try:
            brake = brake_on_path(out, 0.0)
        except TrajoptError as exc:  # no stop on the path: nowhere to plan on from
            raise blocked from exc
        if brake is not None:
            head.append((brake, 0.0))
        stop = (brake or out).sample(np.array([brake.duration if brake else 0.0]))
        ahead = [out]
    elif getattr(out, "translation", None) is not None:  # an omni base's own orientation
        stopped = _omni_stop(out, blocked)
        if stopped is not None:
            head.append((stopped, 0.0))
        stop = (stopped or out).sample(np.array([stopped.duration if stopped else 0.0]))
        ahead = [out]
    else:
        raise blocked
    t_head = sum(float(p.duration) - t_in for p, t_in in head)
    seen = [shift_clock(m, ts + t_head) for m in movers]
    steer = getattr(stop, "steer", None)
    p_stop = (float(stop.x[0]), float(stop.y[0]))
    told = None
    if along is not None:
        t_stop = max(along.t - ts - t_head, 0.0)  # on the clock seen from the stop
        told = Along(BlockedError(str(along), mover=along.mover, t=t_stop), _points(ahead, p_stop))
    try:
        rest = from_stop(
            p_stop,
            float(stop.theta[0]),
            0.0 if steer is None else float(steer[0]),
            seen,
            told,
        )
    except TrajoptError as exc:
        mover, t = blocked.mover, blocked.t
        if isinstance(exc, BlockedError) and exc.mover is not None and exc.t is not None:
            mover, t = exc.mover, exc.t + ts + t_head
        raise BlockedError(
            f"{blocked}; stopped at ({p_stop[0]:.3f}, {p_stop[1]:.3f}) m after "
            f"{t_head:.3f} s, no way on from there: {type(exc).__name__}: {exc}",
            mover=mover,
            t=t,
        ) from exc
    pieces, starts = played(rest)
    stats = dict(rest.stats, replan=out.stats.get("replan"))
    for key in ("splice_time_s", "latency_s"):
        if key in out.stats:
            stats[key] = out.stats[key]
    whole = TrajectoryChain(
        tuple([p for p, _ in head] + pieces),
        out.robot,
        stats,
        rest.steps,
        tuple([t for _, t in head] + starts),
    )
    done = rest.stats["moving"]
    moving = {
        "plan": f"stopped in {t_head:.3f} s, then: {done.get('plan')}",
        "route": f"stopped: {done.get('route', 'retimed')}",
        "blocked": str(blocked),
        "head_s": t_head,
        "certificate": _whole_certificate(whole, head, t_head, done, shifted, margin, blocked, ts),
    }
    for key in ("reroute", "reroute_time_s"):
        if key in done:
            moving[key] = done[key]
    return whole, moving


def _omni_stop(out: Any, blocked: BlockedError) -> Any:
    """Return an omni base's stop from the splice: its brake with the yaw rate stopped beside it.

    The translation brakes along its path (:func:`~trajopt.replan._brake.brake_on_path`) and
    the orientation goes on from its angle, rate and acceleration at the splice to rest
    (:func:`trajopt.timing.stop_orientation`): an :class:`~trajopt.motion.OmniTrajectory`,
    or ``None`` when the base is at rest and not turning at the splice. ``blocked`` is raised
    when there is no such stop (no stop on the path, a body turning while the base stands, a
    base with a footprint: its clearance from the static map holds for the planned pairs of
    position and orientation only).
    """
    if out.robot.footprint is not None:
        raise blocked
    start = out.orientation_at(0.0)
    try:
        brake = brake_on_path(out.translation, 0.0)
    except TrajoptError as exc:  # no stop on the path: nowhere to plan on from
        raise blocked from exc
    if brake is None:
        if start.omega != 0.0 or start.alpha != 0.0:
            raise blocked
        return None
    try:
        return stop_orientation(
            brake, out.robot, start.theta, omega_start=start.omega, alpha_start=start.alpha
        )
    except TrajoptError as exc:
        raise blocked from exc


def _whole_certificate(
    whole: TrajectoryChain,
    head: list[tuple[Any, float]],
    t_head: float,
    done: dict[str, Any],
    shifted: Sequence[MovingObstacle],
    margin: float,
    blocked: BlockedError,
    ts: float,
) -> dict[str, Any]:
    """Return the certificate summary of the stop and the plan on from it, as one chain.

    The plan from the stop was certified against the movers seen from the stop
    (``done["certificate"]``: from ``t_head`` (s) on, the robot standing at the goal after
    it arrives); the head is certified here against the movers ended at ``t_head``
    (:func:`trajopt.moving.truncate`: equal to them until then), which covers it up to the
    stop. Together they cover the whole at every instant. A plan on with no certificate of
    its own is certified with the head, whole. ``BlockedError`` when the robot meets a mover.
    """
    rest = done.get("certificate")
    own = rest is not None and bool(rest.get("ok"))
    if not own:
        cert = certify_movers(whole, shifted, margin=margin)
    elif head:
        cert = _head_certificate(head, t_head, whole.robot, shifted, margin)
    else:
        return dict(rest)
    if not cert.ok:
        raise BlockedError(
            f"{blocked}; moving obstacle {cert.mover!r} meets the robot at "
            f"t = {cert.witness_t + ts:.3f} s of the movers' clock while it stops",
            mover=cert.mover,
            t=cert.witness_t + ts,
        ) from blocked
    if not own:
        return cert.summary()
    return joined_certificates([(0.0, cert.summary()), (t_head, rest)])


def _points(pieces: Sequence[Any], p_stop: tuple[float, float]) -> np.ndarray:
    """Return points of the pieces' curves end to end from the stop on, at most 10 cm apart.

    The points (m, shape (n, 2)) start with the stop; turns in place add none, an omni base's
    own orientation its translation's curve; the points before the one nearest the stop (the
    part braked over) are dropped.
    """
    pts = [np.asarray(p_stop, dtype=float).reshape(1, 2)]
    for piece in pieces:
        p = getattr(piece, "translation", piece)  # an omni base's own orientation: its curve
        if getattr(p, "pieces", None) is not None:
            pts.append(_points(p.pieces, p_stop))
        elif p.single_curve and float(p.length) > 0.0:
            s = np.linspace(0.0, float(p.length), int(np.ceil(float(p.length) / 0.1)) + 1)
            pts.append(np.asarray(p.path(p.path.u_at_s(s)), dtype=float).reshape(-1, 2))
    out = np.concatenate(pts)
    if out.shape[0] == 1:  # no curve ahead: the stop alone
        return out
    near = int(np.argmin(np.hypot(out[1:, 0] - p_stop[0], out[1:, 1] - p_stop[1]))) + 1
    return np.concatenate([out[:1], out[near:]])
