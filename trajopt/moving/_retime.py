"""Re-time a trajectory along its fixed path so that predicted movers pass (or are passed).

:func:`retime_for_movers` keeps the path and changes only ``s(t)``:

1. if the trajectory as it is passes :func:`certify_movers`, it is returned unchanged (the
   time-optimal timing passes before, or never meets, every mover);
2. the movers' forbidden regions of the ``(s, t)`` plane on a grid (:mod:`._st_grid`). A sweep
   of the nodes a non-decreasing ``s(t)`` with ``v <= v_max`` can occupy on the *necessary*
   grid decides that the movers block the path: :class:`BlockedError` naming the mover in
   front of the robot and the time;
3. a search over a family of jerk-limited profiles on the *sufficient* grid: wait at the start
   for ``k0 dt``, drive (time-optimally, :func:`trajopt.time_parameterize` on the path's
   piece) to a stop point ``s_w`` at rest, wait there, drive on to the goal and stand there.
   The stop points are the path's start, the node in front of each mover's forbidden region
   and a few evenly spaced ones; for each the earliest start and the earliest departure from
   ``s_w`` come from prefix tests on the grid; the earliest arrival wins;
4. the chosen profile becomes one :class:`trajopt.Trajectory` on the same path (its rests are
   phases of zero speed) and is certified by :func:`certify_movers`; a failed certificate
   (the grid's inflation is a proof for the grid, so only numerical slips) retries with a
   finer time step.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from trajopt.errors import BlockedError, InvalidInputError, TimingError
from trajopt.geometry import CurveSegment
from trajopt.motion import Trajectory
from trajopt.moving._certificate import (
    certify_movers,
    check_movers,
    point_polygon_distance,
    shape_at,
)
from trajopt.moving._obstacle import MovingObstacle
from trajopt.moving._st_grid import STGrid, reachable, st_grid
from trajopt.timing import time_parameterize

#: Evenly spaced stop points tried besides the start and the fronts of the forbidden regions.
N_EVEN_STOPS = 6


@dataclass(frozen=True, slots=True)
class _Piece:
    """Phases ``(t, s, v, a, j)`` of a rest-to-rest motion along ``[s0, s1]``, from its own ``t = 0``."""

    rows: np.ndarray  # (p, 5)
    duration: float
    s0: float
    s1: float

    def s_at(self, t: np.ndarray) -> np.ndarray:
        tt = np.clip(t, 0.0, self.duration)
        k = np.clip(
            np.searchsorted(self.rows[:, 0], tt, side="right") - 1, 0, self.rows.shape[0] - 1
        )
        tau = tt - self.rows[k, 0]
        r = self.rows[k]
        s = r[:, 1] + tau * (r[:, 2] + tau * (0.5 * r[:, 3] + tau * r[:, 4] / 6.0))
        return np.where(tt >= self.duration, self.s1, np.clip(s, self.s0, self.s1))


def _piece_of(tr: Any, s0: float) -> _Piece:
    rows = np.column_stack([tr.phase_t, tr.phase_s + s0, tr.phase_v, tr.phase_a, tr.phase_j])
    return _Piece(rows, float(tr.duration), s0, s0 + float(tr.length))


def _overlap_at_start(traj: Any, movers: Sequence[MovingObstacle], limit: float) -> None:
    p0 = np.asarray(traj.path(traj.path.domain[0]), dtype=float).reshape(1, 2)
    for m in movers:
        d = float(point_polygon_distance(p0, shape_at(m, np.zeros(1)))[0])
        need = limit + float(m.radius_at(0.0))
        if d < need:
            raise InvalidInputError(
                f"moving obstacle {m.name!r} overlaps the robot at t = 0: distance {d:.6g} m "
                f"< {need:.6g} m (robot radius + its radius + margin)"
            )


def _blocked(grid: STGrid, movers: Sequence[MovingObstacle], speed: float) -> None:
    ok, k, i = reachable(grid, speed)
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
        f"(robot at s <= {grid.s[i]:.3f} m of {grid.s[-1]:.3f} m, any speed up to {speed:.3g} m/s)",
        mover=name,
        t=t,
    )


def _ok_starts(grid: STGrid, idx: np.ndarray) -> np.ndarray:
    """``ok[k]``: the profile whose grid samples are nodes ``idx`` is free when it starts at ``t_k``."""
    fb = grid.blocked
    kk = fb.shape[0]
    pad = np.concatenate([fb, np.repeat(fb[-1:], idx.shape[0], axis=0)])
    ok = np.ones(kk, dtype=bool)
    for j, i in enumerate(idx):
        ok &= ~pad[j : j + kk, i]
    return ok


def _next_true(a: np.ndarray) -> np.ndarray:
    """``out[k]``: the smallest ``k' >= k`` with ``a[k']``, else ``len(a)``."""
    n = a.shape[0]
    v = np.where(a, np.arange(n), n)
    return np.minimum.accumulate(v[::-1])[::-1]


def _best(grid: STGrid, pa: _Piece | None, pb: _Piece) -> tuple[float, int, int] | None:
    """Earliest ``(arrival, k0, k2)`` of: rest at 0 until ``t_k0``, ``pa``, rest until ``t_k2``, ``pb``."""
    fb, dt = grid.blocked, grid.dt
    kk = fb.shape[0]
    goal_col = fb[:, -1]
    last_goal = int(np.max(np.flatnonzero(goal_col))) if goal_col.any() else -1
    nb = int(math.ceil(pb.duration / dt - 1e-9))
    okb = _ok_starts(grid, grid.index(pb.s_at(np.arange(nb + 1) * dt)))
    okb &= np.arange(kk) + nb > last_goal
    start_free = ~np.logical_or.accumulate(fb[:, 0])
    if pa is None:  # start delay only
        k = np.flatnonzero(okb & start_free)
        return None if not k.size else (int(k[0]) * dt + pb.duration, int(k[0]), int(k[0]))
    na = int(math.ceil(pa.duration / dt - 1e-9))
    oka = _ok_starts(grid, grid.index(pa.s_at(np.arange(na + 1) * dt))) & start_free
    iw = int(grid.index(np.array([pa.s1]))[0])
    next_b = _next_true(okb)
    next_w_block = _next_true(fb[:, iw])
    k0 = np.flatnonzero(oka[: max(0, kk - na)])
    if not k0.size:
        return None
    k1 = k0 + na
    k2 = next_b[k1]
    good = (k2 < kk) & (k2 < next_w_block[k1])
    if not good.any():
        return None
    c = int(np.argmin(np.where(good, k2, np.iinfo(np.int64).max)))
    return int(k2[c]) * dt + pb.duration, int(k0[c]), int(k2[c])


def _compose(
    pieces: list[tuple[float, _Piece | None, float]], length: float
) -> tuple[np.ndarray, float]:
    """Phase rows from ``(start time, piece or None for a rest, rest s)`` in order; and the duration."""
    rows = []
    t_end = 0.0
    for t0, pc, s_rest in pieces:
        if pc is None:
            rows.append(np.array([[t0, s_rest, 0.0, 0.0, 0.0]]))
            t_end = t0
            continue
        r = pc.rows.copy()
        r[:, 0] += t0
        rows.append(r)
        t_end = t0 + pc.duration
    out = np.concatenate(rows)
    # drop zero-length rests (a rest row followed by a row at the same time)
    keep = np.append(np.diff(out[:, 0]) > 0.0, True)
    keep[0] = True
    out = out[keep]
    out[:, 1] = np.clip(np.maximum.accumulate(out[:, 1]), 0.0, length)
    return out, t_end


def retime_for_movers(
    traj: Trajectory,
    movers: Sequence[MovingObstacle],
    *,
    margin: float = 0.0,
    dt: float = 0.05,
    ds: float = 0.02,
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

    Returns
    -------
    Trajectory
        ``traj`` itself when it is already clear, else the same path re-timed with rests;
        ``stats["moving"]`` holds the certificate, the plan (``"as planned"`` or
        ``"wait k0 s, stop at s_w m until t2 s"``) and the wall time (s). Its certificate
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
    limit = float(traj.robot.radius) + float(margin)
    _overlap_at_start(traj, movers, limit)
    cert = certify_movers(traj, movers, margin=margin)
    if cert.ok:
        return _with_stats(traj, cert, "as planned", t_all)
    path, length, robot = traj.path, float(traj.length), traj.robot
    vmax = float(robot.v_max)
    t_last = max(m.t_last for m in movers)
    horizon = max(t_last, 0.0) + 2.0 * traj.duration + 2.0
    nec = st_grid(
        path, length, movers, limit, ds=ds, dt=dt, horizon=horizon, speed=vmax, sufficient=False
    )
    _blocked(nec, movers, vmax)
    step = float(dt)
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
        )
        found = _search(traj, grid, movers)
        if found is None:
            break
        rows, duration, label = found
        out = Trajectory(
            path=path,
            robot=robot,
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
        cert = certify_movers(out, movers, margin=margin)
        if cert.ok:
            return _with_stats(out, cert, label, t_all)
        step *= 0.5
    first = cert.mover or movers[0].name
    raise BlockedError(
        f"no re-timing along the path (waits at the start and at one stop) avoids moving "
        f"obstacle {first!r} (near t = {cert.witness_t:.3f} s) within {horizon:.3g} s",
        mover=first,
        t=cert.witness_t,
    )


def _stop_points(grid: STGrid, length: float) -> list[float]:
    """Return the nodes in front of each forbidden region, and evenly spaced ones, inside ``(0, L)``."""
    cols = grid.blocked.any(axis=0)
    fronts = np.flatnonzero(cols[1:] & ~cols[:-1])  # last free node before a forbidden run
    pts = [float(grid.s[i]) for i in fronts]
    pts += np.linspace(0.0, length, N_EVEN_STOPS + 2)[1:-1].tolist()
    lo, hi = 0.05 * length, length - 0.05 * length
    return sorted({round(p, 9) for p in pts if lo < p < hi})


def _search(
    traj: Trajectory, grid: STGrid, movers: Sequence[MovingObstacle]
) -> tuple[np.ndarray, float, str] | None:
    """Return the earliest arrival of the family (module docstring): phase rows, duration, label."""
    length = float(traj.length)
    path = traj.path
    whole = _piece_of(traj, 0.0)
    best = _best(grid, None, whole)
    choice: tuple[float, int, int, _Piece | None, _Piece] | None = None
    if best is not None:
        choice = (best[0], best[1], best[2], None, whole)
    u_lo, u_hi = path.domain
    for sw in _stop_points(grid, length):
        if choice is not None and choice[0] <= traj.duration + 1e-9:
            break
        uw = float(path.u_at_s(sw))
        try:
            ta = time_parameterize(CurveSegment(path, u_lo, uw), traj.robot)
            tb = time_parameterize(CurveSegment(path, uw, u_hi), traj.robot)
        except (TimingError, InvalidInputError, ValueError):
            continue
        pa, pb = _piece_of(ta, 0.0), _piece_of(tb, sw)
        pa = _Piece(pa.rows, pa.duration, 0.0, sw)
        pb = _Piece(pb.rows, pb.duration, sw, length)
        got = _best(grid, pa, pb)
        if got is not None and (choice is None or got[0] < choice[0]):
            choice = (got[0], got[1], got[2], pa, pb)
    if choice is None:
        return None
    _, k0, k2, pa, pb = choice
    dt = grid.dt
    if pa is None:
        parts = [(0.0, None, 0.0), (k0 * dt, pb, 0.0)]
        label = f"wait {k0 * dt:.3f} s at the start"
    else:
        parts = [
            (0.0, None, 0.0),
            (k0 * dt, pa, 0.0),
            (k0 * dt + pa.duration, None, pa.s1),
            (k2 * dt, pb, 0.0),
        ]
        label = f"wait {k0 * dt:.3f} s, stop at s = {pa.s1:.3f} m until t = {k2 * dt:.3f} s"
    rows, duration = _compose(parts, length)
    return rows, duration, label


def _with_stats(traj: Trajectory, cert: Any, label: str, t_all: float) -> Trajectory:
    traj.stats["moving"] = {
        "plan": label,
        "certificate": {
            "ok": cert.ok,
            "slack_m": cert.slack,
            "mover": cert.mover,
            "horizon_s": cert.horizon,
            "intervals": cert.intervals,
        },
        "time_s": time.perf_counter() - t_all,
    }
    return traj
