"""Re-time a trajectory along its fixed path so that predicted movers pass (or are passed).

:func:`retime_for_movers` keeps the path and changes only ``s(t)``:

1. if the trajectory as it is passes :func:`certify_movers`, it is returned unchanged (the
   time-optimal timing passes before, or never meets, every mover);
2. the movers' forbidden regions of the ``(s, t)`` plane on a grid (:mod:`._st_grid`). A sweep
   of the nodes a non-decreasing ``s(t)`` with ``v <= v_max`` can occupy on the *necessary*
   grid decides that the movers block the path: :class:`BlockedError` naming the mover in
   front of the robot and the time;
3. a search over a family of jerk-limited profiles on the *sufficient* grid
   (:mod:`._st_search`): rest at the start, drive (time-optimally,
   :func:`trajopt.time_parameterize` on the path's piece, rest to rest) to a stop, rest
   there, ..., drive to the goal and stand there; a dynamic programme over the stops finds
   the earliest arrival;
4. the chosen profile becomes one :class:`trajopt.Trajectory` on the same path (its rests are
   phases of zero speed) and is certified by :func:`certify_movers`; a failed certificate
   (the grid's inflation is a proof for the grid, so only numerical slips) retries with a
   finer time step.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from trajopt.errors import BlockedError, InvalidInputError, TimingError
from trajopt.geometry import CurveSegment
from trajopt.motion import Trajectory, TrajectoryChain
from trajopt.moving._certificate import (
    ccw,
    certify_movers,
    check_movers,
    convex_distance,
    kappa_max,
    shape_at,
)
from trajopt.moving._obstacle import MovingObstacle
from trajopt.moving._st_grid import STGrid, reach_bound, reachable, st_grid
from trajopt.moving._st_search import Piece, compose, search
from trajopt.timing import time_parameterize


def _piece_of(tr: Any, s0: float, s1: float) -> Piece:
    rows = np.column_stack([tr.phase_t, tr.phase_s + s0, tr.phase_v, tr.phase_a, tr.phase_j])
    return Piece(rows, float(tr.duration), s0, s1)


def _drives(traj: Trajectory) -> Callable[[float, float], Piece | None]:
    """Return ``drive(s0, s1)``: the path's piece timed from rest to rest (cached)."""
    path, robot, length = traj.path, traj.robot, float(traj.length)
    u_lo, u_hi = path.domain
    cache: dict[tuple[float, float], Piece | None] = {(0.0, length): _piece_of(traj, 0.0, length)}

    def drive(s0: float, s1: float) -> Piece | None:
        key = (s0, s1)
        if key not in cache:
            ua = u_lo if s0 <= 0.0 else float(path.u_at_s(s0))
            ub = u_hi if s1 >= length else float(path.u_at_s(s1))
            try:
                tr = time_parameterize(CurveSegment(path, ua, ub), robot)
            except (TimingError, InvalidInputError, ValueError):
                cache[key] = None
            else:
                cache[key] = _piece_of(tr, s0, s1)
        return cache[key]

    return drive


def _robot_shape(traj: Trajectory, margin: float) -> tuple[float, np.ndarray | None, float]:
    """Return ``(limit, body, stretch)`` for the grids (:func:`st_grid`).

    A disc robot: its radius plus the margin. A footprint robot: the margin, its CCW polygon
    and ``1 + R kappa_max``; on a path with no curvature bound, its circumscribed disc.
    """
    fp = traj.robot.footprint
    if fp is None:
        return float(traj.robot.radius) + margin, None, 1.0
    body = ccw(np.asarray(fp.vertices, dtype=float))
    reach = float(np.max(np.hypot(body[:, 0], body[:, 1])))
    kappa = kappa_max(traj.path)
    if not math.isfinite(kappa):
        return reach + margin, None, 1.0
    return margin, body, 1.0 + reach * kappa


def _overlap_at_start(traj: Any, movers: Sequence[MovingObstacle], margin: float) -> None:
    smp = traj.sample(np.zeros(1))
    p0 = np.array([[smp.x[0], smp.y[0]]], dtype=float)
    robot: np.ndarray = p0[:, None, :]
    fp = traj.robot.footprint
    if fp is not None:
        v = ccw(np.asarray(fp.vertices, dtype=float))
        c, sn = math.cos(float(smp.theta[0])), math.sin(float(smp.theta[0]))
        robot = (p0 + v @ np.array([[c, sn], [-sn, c]]))[None]
    for m in movers:
        d = float(convex_distance(robot, shape_at(m, np.zeros(1)))[0])
        need = margin + float(m.radius_at(0.0)) + (traj.robot.radius if fp is None else 0.0)
        if d < need:
            raise InvalidInputError(
                f"moving obstacle {m.name!r} overlaps the robot at t = 0: distance {d:.6g} m "
                f"< {need:.6g} m (robot, its radius and the margin)"
            )


def _blocked(grid: STGrid, movers: Sequence[MovingObstacle], robot: Any) -> None:
    speed = float(robot.v_max)
    s_up = reach_bound(grid.t, speed, float(robot.a_max), float(robot.j_max))
    ok, k, i = reachable(grid, speed, s_up)
    if ok:
        return
    row = grid.who[k]
    ahead = np.flatnonzero(row[i:] >= 0)
    j = int(row[i + ahead[0]]) if ahead.size else int(np.max(grid.who[k]))
    j = max(j, 0)
    name = movers[j].name
    t = float(grid.t[k])
    what = "stays on the path" if k == grid.t.shape[0] - 1 else "leaves no way past"
    raise BlockedError(
        f"moving obstacle {name!r} blocks the path: from t = {t:.3f} s it {what} "
        f"(robot at s <= {grid.s[i]:.3f} m of {grid.s[-1]:.3f} m; no motion along the path "
        f"under v_max={speed:.3g} m/s and the acceleration limits gets past)",
        mover=name,
        t=t,
    )


def retime_for_movers(
    traj: Trajectory,
    movers: Sequence[MovingObstacle],
    *,
    margin: float = 0.0,
    dt: float = 0.05,
    ds: float = 0.02,
    not_before: float = 0.0,
) -> Trajectory:
    """Re-time ``traj`` along its path so that it keeps clear of the movers (module docstring).

    Parameters
    ----------
    traj : Trajectory
        A disc robot's timed curve from rest to rest (``v_start = v_end = 0``).
    movers : sequence of MovingObstacle
        The predictions (seconds from the trajectory's ``t = 0``).
    margin : float
        Extra distance to every mover (m), >= 0.
    dt, ds : float
        The ``(s, t)`` grid's spacings (s, m).
    not_before : float
        The robot rests at the start until this time (s), >= 0 (a turn in place there):
        the result starts with a rest at least that long.

    Returns
    -------
    Trajectory
        ``traj``'s motion when it is already clear, else the same path re-timed with rests
        (a new value either way; ``traj`` is not changed). ``stats["moving"]`` holds the
        certificate, the plan (``"as planned"`` or ``"wait 1.250 s at the start, stop at
        s = 2.100 m until t = 7.800 s"``) and the wall time (s). Its certificate
        (:func:`certify_movers`) holds at every instant until the last prediction ends.

    Raises
    ------
    BlockedError
        No non-decreasing ``s(t)`` with speed ``<= v_max`` avoids a mover within the grid's
        horizon (the mover and the time are named), or no profile of the family does.
    InvalidInputError
        A mover overlaps the robot at ``t = 0``; a trajectory that does not start and end at
        rest; bad spacings.
    """
    t_all = time.perf_counter()
    movers = check_movers(movers)
    if not isinstance(traj, Trajectory):
        raise InvalidInputError(f"traj must be a trajopt.Trajectory, got {type(traj).__name__}")
    if traj.v_start != 0.0 or traj.v_end != 0.0 or traj.phase_a[0] != 0.0:
        raise InvalidInputError(
            "retime_for_movers needs a trajectory from rest to rest, got "
            f"v_start={traj.v_start!r} m/s, v_end={traj.v_end!r} m/s"
        )
    if not (isinstance(margin, (int, float)) and math.isfinite(margin) and margin >= 0.0):
        raise InvalidInputError(f"margin must be a finite number >= 0 m, got {margin!r}")
    for name, val in (("dt", dt), ("ds", ds)):
        if not (isinstance(val, (int, float)) and math.isfinite(val) and val > 0.0):
            raise InvalidInputError(f"{name} must be a finite number > 0, got {val!r}")
    if not (isinstance(not_before, (int, float)) and math.isfinite(not_before) and not_before >= 0):
        raise InvalidInputError(f"not_before must be a finite number >= 0 s, got {not_before!r}")
    limit, body, stretch = _robot_shape(traj, float(margin))
    _overlap_at_start(traj, movers, float(margin))
    path, length, robot = traj.path, float(traj.length), traj.robot
    if not_before > 0.0:  # the plan as it is, after the rest
        whole = _piece_of(traj, 0.0, length)
        rows, duration = compose([(0.0, None, 0.0), (float(not_before), whole, 0.0)], length)
        traj = _timed(traj, rows, duration)
    cert = certify_movers(traj, movers, margin=margin)
    if cert.ok:
        return _with_stats(traj, cert, "as planned", t_all)
    vmax = float(robot.v_max)
    t_last = max(m.t_last for m in movers)
    horizon = max(t_last, 0.0) + 2.0 * traj.duration + 2.0
    nec = st_grid(
        path,
        length,
        movers,
        limit,
        ds=ds,
        dt=dt,
        horizon=horizon,
        speed=vmax,
        sufficient=False,
        body=body,
        stretch=stretch,
    )
    _blocked(nec, movers, robot)
    step = float(dt)
    drives = _drives(traj)
    for _ in range(3):
        grid = st_grid(
            path,
            length,
            movers,
            limit,
            ds=ds,
            dt=step,
            horizon=horizon,
            speed=vmax,
            sufficient=True,
            body=body,
            stretch=stretch,
        )
        k_min = int(math.ceil(not_before / step - 1e-9))
        found = search(grid, drives, vmax, float(robot.a_max), k_min)
        if found is None:
            break
        parts, _, label = found
        rows, duration = compose(parts, length)
        out = _timed(traj, rows, duration)
        cert = certify_movers(out, movers, margin=margin)
        if cert.ok:
            return _with_stats(out, cert, label, t_all)
        step *= 0.5
    first = cert.mover or movers[0].name
    raise BlockedError(
        f"no re-timing along the path (rests at the start and at stops) avoids moving "
        f"obstacle {first!r} (near t = {cert.witness_t:.3f} s) within {horizon:.3g} s",
        mover=first,
        t=cert.witness_t,
    )


def _timed(traj: Trajectory, rows: np.ndarray, duration: float) -> Trajectory:
    """Return ``traj``'s path with the phase rows ``(t, s, v, a, j)``, shape (p, 5), from rest to rest."""
    return Trajectory(
        path=traj.path,
        robot=traj.robot,
        phase_t=rows[:, 0],
        phase_s=rows[:, 1],
        phase_v=rows[:, 2],
        phase_a=rows[:, 3],
        phase_j=rows[:, 4],
        duration=duration,
        v_start=0.0,
        v_end=0.0,
        stats=dict(traj.stats),
        theta_grid_s=traj.theta_grid_s,
        theta_grid=traj.theta_grid,
        u_grid=traj.u_grid,
        steps=traj.steps,
        direction=traj.direction,
    )


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
    stats["moving"]["certificate"] = _cert_stats(cert)
    return out


def _cert_stats(cert: Any) -> dict[str, Any]:
    """Return the certificate's summary for ``stats["moving"]``."""
    return {
        "ok": cert.ok,
        "slack_m": cert.slack,
        "mover": cert.mover,
        "horizon_s": cert.horizon,
        "intervals": cert.intervals,
    }


def _with_stats(traj: Trajectory, cert: Any, label: str, t_all: float) -> Trajectory:
    """Return ``traj`` as a new value whose ``stats["moving"]`` describes the re-timing."""
    stats = dict(traj.stats)
    stats["moving"] = {
        "plan": label,
        "certificate": _cert_stats(cert),
        "time_s": time.perf_counter() - t_all,
    }
    return dataclasses.replace(traj, stats=stats)
