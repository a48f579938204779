"""Re-time a whole plan for movers on one clock: curves, motions at rest, an omni orientation.

:func:`retime_chain` covers every plan from rest that the planner returns for a differential,
omnidirectional or car-like robot (not the stop-and-turn fallback's polyline):

* a :class:`trajopt.Trajectory`: :func:`~trajopt.moving.retime_for_movers`;
* a :class:`trajopt.TrajectoryChain` of curves from rest to rest and motions at rest (a
  differential drive's turns in place, a car's steering at rest at its cusps and ends; a car's
  drives between cusps, forwards or backwards): the pieces are re-timed **in order on one
  clock**. A curve starting at chain time ``t_c`` is re-timed against the movers seen from
  ``t_c`` (:func:`shift_clock`), resting at its start at least as long as the motions at rest
  just before it last (``not_before``; they are played during that rest, so ``v = 0`` at every
  cusp); a backwards drive with the car's ``v_max_reverse``. A curve that another follows
  need only keep clear until it ends (the rest after it is the next curve's start, which that
  curve's re-timing certifies): it is re-timed against the predictions ended there
  (:func:`truncate`); the last curve with the robot standing at the goal until the last
  prediction ends. When a later curve is then blocked (leaving early led into a trap), the
  pieces are re-timed again with every curve standing at its end until the last prediction
  ends. The pieces are re-timed one after another (greedy: safe, not complete). A chain
  that passes its certificate (:func:`~trajopt.moving.certify_movers`) as it is stays as it
  is; otherwise the proofs of the result are the curves' own certificates, which for a disc
  robot cover every instant (a leg's until it ends, the next curve's from there, its rest at
  the start and the motions at rest before it included, the last one's until the last
  prediction ends), so the re-timed chain is not certified again; a footprint robot's is,
  whole, since the body sweeps more while it turns in place than at rest. The chain's failed
  certificate is its one curve's (after a rest as long as the motions at rest before it) for
  a disc robot's chain of one curve, and is handed to that curve's re-timing;
* an :class:`trajopt.OmniTrajectory` (an omni base's own orientation): its translation is
  re-timed as the robot's circumscribed disc (the body may face any way), and the orientation
  profile is built again on the re-timed translation (:func:`trajopt.timing.orient`, from the
  same start orientation to the same end orientation, within the yaw limits): the body turns
  while the base drives or rests, the turn never outlasting what it would alone.

:func:`retime_plan` is the narrower form for a plan of one curve with turns in place at its
ends (a differential drive's pose-to-pose plan): the curve re-timed with a rest as long as
the turns before it, the whole chain certified.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Sequence
from typing import Any

import numpy as np

from trajopt.errors import BlockedError, InvalidInputError
from trajopt.motion import Trajectory, TrajectoryChain
from trajopt.moving._certificate import MoverCertificate, certify_movers
from trajopt.moving._obstacle import MovingObstacle
from trajopt.moving._retime import retime_for_movers
from trajopt.timing import orient


def shift_clock(mover: MovingObstacle, t0: float) -> MovingObstacle:
    """Return ``mover`` seen on a clock whose ``0`` is ``t0`` (s) of its own.

    Its waypoint times move by ``-t0``; its radius becomes the radius it has at ``t0`` (its
    growth up to then), so ``radius_at`` agrees with the original's at every ``t >= 0`` of the
    new clock.
    """
    t_last = max(mover.t_last, 0.0)
    grown = mover.radius + mover.growth * min(max(float(t0), 0.0), t_last)
    times = mover.times - float(t0)
    if (
        math.isfinite(grown)
        and bool(np.all(np.isfinite(times)))
        and bool(np.all(np.diff(times) > 0.0))
    ):
        return _moved(mover, times, grown)
    return MovingObstacle(  # validated: a rounding that breaks the times is refused by name
        times=times,
        positions=mover.positions,
        headings=mover.headings,
        radius=grown,
        growth=mover.growth,
        vertices=mover.vertices,
        name=mover.name,
    )


def _moved(
    mover: MovingObstacle,
    times: np.ndarray,
    radius: float,
    positions: np.ndarray | None = None,
    headings: np.ndarray | None = None,
) -> MovingObstacle:
    """Return ``mover`` with new waypoint times and radius (and track), its shape and name shared.

    An internal constructor (as scipy's ``BSpline.construct_fast``): ``times`` (s, shape
    (k,), strictly increasing and finite), ``radius`` (m, finite, >= 0), ``positions`` (m,
    shape (k, 2), finite) and ``headings`` (rad, shape (k,), finite) are the caller's to
    check (default: the mover's own); the shape, growth and name are the mover's, already
    validated.
    """
    out = object.__new__(MovingObstacle)
    fields = [times, mover.positions if positions is None else positions]
    fields.append(mover.headings if headings is None else headings)
    times, positions, headings = (np.array(x, dtype=float) for x in fields)
    for x in (times, positions, headings):
        x.setflags(write=False)
    for name, value in (
        ("times", times),
        ("positions", positions),
        ("headings", headings),
        ("radius", float(radius)),
        ("growth", mover.growth),
        ("vertices", mover.vertices),
        ("name", mover.name),
    ):
        object.__setattr__(out, name, value)
    return out


def truncate(mover: MovingObstacle, t_end: float) -> MovingObstacle:
    """Return ``mover`` with its prediction ended at ``t_end`` (s): it stands there afterwards.

    Equal to ``mover`` at every ``t <= t_end`` (position, heading and radius); a re-timing
    that ends by ``t_end`` and is certified against it is certified against ``mover`` over
    ``[0, t_end]``.
    """
    if t_end >= mover.t_last:
        return mover
    keep = mover.times < t_end
    c, h = mover.pose_at(np.array([t_end]))
    times = np.append(mover.times[keep], t_end)
    positions = np.concatenate([mover.positions[keep], c])
    headings = np.append(mover.headings[keep], h)
    if math.isfinite(t_end) and bool(np.all(np.isfinite(positions))):
        return _moved(mover, times, mover.radius, positions, headings)
    return MovingObstacle(
        times=times,
        positions=positions,
        headings=headings,
        radius=mover.radius,
        growth=mover.growth,
        vertices=mover.vertices,
        name=mover.name,
    )


def flat_pieces(plan: Any) -> list[Any]:
    """Return a plan's pieces in order (nested chains opened): curves and motions at rest.

    Raises
    ------
    InvalidInputError
        A piece that is neither (the stop-and-turn fallback's polyline, an omni orientation
        inside a chain) or a chain that starts inside a piece.
    """
    if plan.single_curve or plan.turning or plan.steering_at_rest:
        return [plan]
    pieces = getattr(plan, "pieces", None)
    if pieces is None:
        raise InvalidInputError(
            "moving obstacles are covered for curves, turns in place, a car's steering at rest "
            f"and an omni orientation, got a {type(plan).__name__}"
        )
    if any(plan.starts):
        raise InvalidInputError(
            "moving obstacles: a chain that starts inside a piece is not covered"
        )
    return [q for p in pieces for q in flat_pieces(p)]


def _retime_curve(
    curve: Trajectory,
    movers: Sequence[MovingObstacle],
    margin: float,
    not_before: float,
    as_is: MoverCertificate | None = None,
) -> Trajectory:
    """Re-time one curve from rest to rest; a car's backwards drive under ``v_max_reverse``.

    ``as_is``: the certificate of the curve as it is after the rest ``not_before``, when the
    caller has it (:func:`retime_for_movers`' ``certificate``).
    """
    robot = curve.robot
    backwards = getattr(robot.drive, "v_max_backwards", None)
    limits = robot
    if curve.direction < 0 and backwards is not None and backwards(robot) != robot.v_max:
        limits = dataclasses.replace(robot, v_max=backwards(robot))
    kw = {"margin": margin, "not_before": not_before, "certificate": as_is}
    if limits is robot:
        return retime_for_movers(curve, movers, **kw)
    out = retime_for_movers(dataclasses.replace(curve, robot=limits), movers, **kw)
    return dataclasses.replace(out, robot=robot)


#: Tries of :func:`_retime_leg` with the predictions ended at a later time each.
LEG_TRIES = 3


def _retime_leg(
    curve: Trajectory, movers: Sequence[MovingObstacle], margin: float, not_before: float
) -> Trajectory:
    """Re-time a curve that another curve follows: it must keep clear only until it ends.

    The robot then rests there as the next curve's start, which that curve's re-timing
    certifies. So the curve is re-timed against the predictions ended at ``t_end``
    (:func:`truncate`), first the curve's own end as planned; a re-timing that ends by
    ``t_end`` holds against the true predictions until it ends. One that ends later is tried
    again with ``t_end`` at its end (:data:`LEG_TRIES` in all); then the curve is re-timed
    against the whole predictions (standing at its end until the last one ends).
    """
    t_end = not_before + float(curve.duration)
    for _ in range(LEG_TRIES):
        cut = [truncate(m, t_end) for m in movers]
        try:
            out = _retime_curve(curve, cut, margin, not_before)
        except BlockedError:
            out = None
        if out is not None and out.duration <= t_end:
            return out
        t_end = max(2.0 * t_end, float(out.duration) if out is not None else 0.0)
    return _retime_curve(curve, movers, margin, not_before)


def retime_chain(plan: Any, movers: Sequence[MovingObstacle], *, margin: float = 0.0) -> Any:
    """Re-time a plan from rest for the movers, on one clock (module docstring).

    Parameters
    ----------
    plan : Trajectory, TrajectoryChain or OmniTrajectory
        A plan from rest to rest: one curve, or curves and motions at rest, or an omni
        translation with its orientation.
    movers : sequence of MovingObstacle
        The predictions (seconds from the plan's ``t = 0``).
    margin : float
        Extra distance to every mover (m), >= 0.

    Returns
    -------
    Trajectory, TrajectoryChain or OmniTrajectory
        Of the plan's kind (a chain keeps its pieces in order), certified at every instant
        until the last prediction ends. ``stats["moving"]``: ``plan`` (each curve's re-timing
        in words, ``"; "``-joined_certificates), ``certificate`` (:func:`certify_movers`' summary: of
        the plan as it is, or of the re-timed chain, a disc robot's as its curves'
        certificates :func:`joined_certificates`) and ``time_s``.

    Raises
    ------
    BlockedError
        A curve cannot be re-timed around a mover (:func:`retime_for_movers`), or the chain
        as a whole fails its certificate.
    InvalidInputError
        A plan not covered (the stop-and-turn fallback's polyline), a moving start, a mover
        overlapping the robot at ``t = 0``.
    """
    t_all = time.perf_counter()
    if plan.own_orientation:
        return _retime_omni(plan, movers, margin, t_all)
    if plan.single_curve:
        return retime_for_movers(plan, movers, margin=margin)
    pieces = flat_pieces(plan)
    cert = certify_movers(plan, movers, margin=margin)
    if cert.ok:  # as planned: every piece clear of every mover, standing at the goal too
        stats = dict(plan.stats)
        stats["moving"] = {
            "plan": "as planned",
            "certificate": cert.summary(),
            "time_s": time.perf_counter() - t_all,
        }
        return dataclasses.replace(plan, stats=stats)
    # one curve after motions at rest, a disc robot: the chain's certificate is the curve's
    # after a rest as long as they last (a disc stands still while it turns or steers)
    one = sum(p.single_curve for p in pieces) == 1 and plan.robot.footprint is None
    try:
        chain, labels, certs = _in_order(
            plan, pieces, movers, margin, early=True, as_is=cert if one else None
        )
    except BlockedError:  # leaving early led into a trap: every leg stands at its end till the last
        chain, labels, certs = _in_order(plan, pieces, movers, margin, early=False)
    if plan.robot.footprint is None:  # the curves' certificates cover the disc at every instant
        summary = joined_certificates(certs)
    else:  # a footprint sweeps more while it turns in place than its rests: the whole chain
        whole = certify_movers(chain, movers, margin=margin)
        if not whole.ok:
            raise BlockedError(
                f"moving obstacle {whole.mover!r} meets the robot near "
                f"t = {whole.witness_t:.3f} s while it stands still in the re-timed chain "
                f"({whole.verdict})",
                mover=whole.mover,
                t=whole.witness_t,
            )
        summary = whole.summary()
    chain.stats["moving"] = {
        "plan": "; ".join(labels) if labels else "as planned",
        "certificate": summary,
        "time_s": time.perf_counter() - t_all,
    }
    return chain


def joined_certificates(certs: Sequence[tuple[float, dict[str, Any]]]) -> dict[str, Any]:
    """Return one certificate summary of parts certified on their own, one after another.

    ``certs``: ``(t0, summary)`` pairs, each part's certificate summary
    (:meth:`MoverCertificate.summary`) on a clock that starts at ``t0`` (s) of the whole. The
    parts' certificates together must cover every instant of the whole (the caller's
    argument); the result has the smallest slack and its mover, the latest end of a
    certified range on the whole's clock and the intervals of all.
    """
    worst = min(certs, key=lambda c: c[1]["slack_m"])[1]
    return {
        "ok": all(bool(c["ok"]) for _, c in certs),
        "slack_m": worst["slack_m"],
        "mover": worst["mover"],
        "horizon_s": max(t0 + float(c["horizon_s"]) for t0, c in certs),
        "intervals": sum(int(c["intervals"]) for _, c in certs),
    }


def _in_order(
    plan: Any,
    pieces: list[Any],
    movers: Sequence[MovingObstacle],
    margin: float,
    early: bool,
    as_is: MoverCertificate | None = None,
) -> tuple[TrajectoryChain, list[str], list[tuple[float, dict[str, Any]]]]:
    """Re-time the curves in order on one clock; ``early``: each leg clear only until it ends.

    With ``early`` a curve that another follows is re-timed by :func:`_retime_leg` (it may
    leave its start as soon as it is clear until its end); without, as the last one (standing
    at its end until the last prediction ends: it never arrives where a mover will still come,
    which a later curve could not escape). ``as_is``: the chain's failed certificate, handed
    to the re-timing of its one curve as that curve's own (a disc robot's chain of one curve).
    Returns the chain, each curve's plan in words and each curve's certificate summary with
    the chain time where its clock starts. For a disc robot those certificates cover every
    instant: a leg's until it ends (:func:`_retime_leg`), the next curve's from there (its
    rest at the start, the motions at rest before it, included), the last curve's until the
    last prediction ends, standing at the goal (the motions at rest after it included).
    """
    last = max(i for i, p in enumerate(pieces) if p.single_curve)
    out: list[Any] = []
    starts: list[float] = []
    labels: list[str] = []
    certs: list[tuple[float, dict[str, Any]]] = []
    pending: list[Any] = []
    t_cur = lead = 0.0
    for i, piece in enumerate(pieces):
        if not piece.single_curve:
            pending.append(piece)
            lead += float(piece.duration)
            continue
        seen = [shift_clock(m, t_cur) for m in movers] if t_cur > 0.0 else list(movers)
        curve = (
            _retime_leg(piece, seen, margin, lead)
            if early and i != last
            else _retime_curve(piece, seen, margin, lead, as_is)
        )
        labels.append(str(curve.stats["moving"]["plan"]))
        certs.append((t_cur, curve.stats["moving"]["certificate"]))
        out += pending
        starts += [0.0] * len(pending)
        out.append(curve)
        starts.append(lead)
        t_cur += float(curve.duration)
        pending, lead = [], 0.0
    out += pending
    starts += [0.0] * len(pending)
    chain = TrajectoryChain(tuple(out), plan.robot, dict(plan.stats), plan.steps, tuple(starts))
    return chain, labels, certs


def _retime_omni(plan: Any, movers: Sequence[MovingObstacle], margin: float, t_all: float) -> Any:
    """Re-time an omni translation as its circumscribed disc and orient it again."""
    tr = plan.translation
    robot = plan.robot
    disc = dataclasses.replace(tr.robot, footprint=None) if tr.robot.footprint else tr.robot
    moved = retime_for_movers(dataclasses.replace(tr, robot=disc), movers, margin=margin)
    moved = dataclasses.replace(moved, robot=tr.robot)
    out = orient(moved, robot, plan.theta_start, plan.theta_end)
    cert = certify_movers(moved, movers, margin=margin, robot_radius=float(robot.radius))
    if not cert.ok:  # the re-timing certified the same disc; only a numerical slip lands here
        raise BlockedError(
            f"moving obstacle {cert.mover!r} meets the re-timed omni translation near "
            f"t = {cert.witness_t:.3f} s ({cert.verdict})",
            mover=cert.mover,
            t=cert.witness_t,
        )
    stats = dict(out.stats)
    stats["moving"] = {
        "plan": str(moved.stats["moving"]["plan"]),
        "certificate": cert.summary(),
        "time_s": time.perf_counter() - t_all,
    }
    return dataclasses.replace(out, stats=stats, steps=plan.steps)


def retime_plan(plan: Any, movers: Sequence[MovingObstacle], *, margin: float = 0.0) -> Any:
    """Re-time a plan for movers: one curve, or turns in place, one curve, turns in place.

    A :class:`trajopt.Trajectory` goes to :func:`retime_for_movers`. A
    :class:`trajopt.TrajectoryChain` of turns in place at the start, one curve and turns in
    place at the goal (a differential drive's pose-to-pose plan) keeps its turns: the robot
    stands at the start while it turns (``not_before`` = their duration), and at the goal
    while it turns there (the certificate covers standing at the goal). The result's pieces
    are the old turns and the re-timed curve, on one clock with the movers'.

    Parameters
    ----------
    plan : Trajectory or TrajectoryChain
        A disc robot's plan from rest to rest.
    movers : sequence of MovingObstacle
        The predictions (seconds from the plan's ``t = 0``).
    margin : float
        Extra distance to every mover (m), >= 0.

    Returns
    -------
    Trajectory or TrajectoryChain
        Of the plan's kind, certified (:func:`certify_movers`); ``stats["moving"]`` as in
        :func:`retime_for_movers`.

    Raises
    ------
    BlockedError
        As :func:`retime_for_movers`; or a footprint turning in place meets a mover (the
        whole chain is certified).
    InvalidInputError
        Any other plan (a chain of several curves, a car's steering, an omni orientation).
    """
    if plan.single_curve:
        return retime_for_movers(plan, movers, margin=margin)
    pieces = tuple(getattr(plan, "pieces", ()))
    curves = [i for i, p in enumerate(pieces) if p.single_curve]
    if len(curves) != 1 or not all(p.turning for p in pieces if not p.single_curve):
        raise InvalidInputError(
            "moving obstacles are covered for one curve with turns in place at its ends, got "
            f"{type(plan).__name__} of {[type(p).__name__ for p in pieces]}"
        )
    if any(plan.starts):
        raise InvalidInputError(
            "moving obstacles: a chain that starts inside a piece is not covered"
        )
    i = curves[0]
    lead = float(sum(p.duration for p in pieces[:i]))
    curve = retime_for_movers(pieces[i], movers, margin=margin, not_before=lead)
    starts = [0.0] * len(pieces)
    starts[i] = lead
    stats = dict(plan.stats)
    stats["moving"] = dict(curve.stats["moving"])
    out = TrajectoryChain(
        pieces=(*pieces[:i], curve, *pieces[i + 1 :]),
        robot=plan.robot,
        stats=stats,
        steps=plan.steps,
        starts=tuple(starts),
    )
    # the chain's own certificate: a footprint sweeps more while it turns in place than the
    # curve's rests at its end headings
    cert = certify_movers(out, movers, margin=margin)
    if not cert.ok:
        raise BlockedError(
            f"moving obstacle {cert.mover!r} meets the robot turning in place near "
            f"t = {cert.witness_t:.3f} s ({cert.verdict})",
            mover=cert.mover,
            t=cert.witness_t,
        )
    stats["moving"]["certificate"] = cert.summary()
    return out
