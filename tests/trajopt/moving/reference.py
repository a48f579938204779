"""Independent references for the tests and the benchmark of trajopt.moving.

Dense sampling, a brute force, and :func:`check_motion`: a proof by sampling plus a Lipschitz
bound that a timed motion keeps its distance from the movers and its clearance from the map,
written from the movers' waypoints and the map's squares, not from trajopt.moving's code.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from tests.reference import square_clearance


def mover_pose(mover, t):
    """Centre (m, shape (n, 2)) and heading (rad, shape (n,)) of ``mover`` at times ``t`` (s).

    Linear between its waypoints; before the first and after the last it stays where it is.
    """
    t = np.atleast_1d(np.asarray(t, dtype=float))
    c = np.stack([np.interp(t, mover.times, mover.positions[:, i]) for i in (0, 1)], axis=-1)
    return c, np.interp(t, mover.times, mover.headings)


def slack_at(p, mover, t, limit):
    """Distance minus ``limit + radius(t)`` (m) between points ``p`` (shape (n, 2)) and ``mover`` at ``t``.

    A disc mover's centre distance, or a convex polygon's (vertices rotated and shifted, the
    point-to-polygon distance written out here again, 0 inside).
    """
    t = np.atleast_1d(np.asarray(t, dtype=float))
    c, h = mover_pose(mover, t)
    rad = mover.radius + mover.growth * np.clip(t, 0.0, mover.times[-1])
    if mover.vertices is None:
        return np.hypot(*(p - c).T) - limit - rad
    ch, sh = np.cos(h)[:, None], np.sin(h)[:, None]
    vx, vy = mover.vertices[:, 0][None], mover.vertices[:, 1][None]
    w = np.stack([c[:, :1] + ch * vx - sh * vy, c[:, 1:] + sh * vx + ch * vy], axis=-1)
    e = np.roll(w, -1, axis=1) - w  # edges, (n, m, 2)
    q = p[:, None, :] - w
    lam = np.clip(np.sum(q * e, axis=2) / np.sum(e * e, axis=2), 0.0, 1.0)
    foot = q - lam[..., None] * e
    dist = np.min(np.hypot(foot[..., 0], foot[..., 1]), axis=1)
    inside = np.all(e[..., 0] * q[..., 1] - e[..., 1] * q[..., 0] >= 0.0, axis=1)
    return np.where(inside, 0.0, dist) - limit - rad


def positions(traj, t):
    """The robot's centre (m, shape (n, 2)) at times ``t`` (s), from the trajectory's own samples."""
    smp = traj.sample(np.atleast_1d(np.asarray(t, dtype=float)))
    return np.stack([np.asarray(smp.x), np.asarray(smp.y)], axis=-1)


def slack(traj, mover, t, margin=0.0):
    """Distance minus limit (m) at times ``t`` (s), from the trajectory's own samples."""
    return slack_at(positions(traj, t), mover, t, traj.robot.radius + margin)


def horizon(traj, movers):
    return max([traj.duration] + [float(m.times[-1]) for m in movers])


def dense_min(traj, movers, dt=1e-3, margin=0.0):
    """Smallest slack over 1 ms samples of ``[0, horizon]`` (m) and its time (s)."""
    t = np.append(np.arange(0.0, horizon(traj, movers), dt), horizon(traj, movers))
    best = (np.inf, 0.0)
    for m in movers:
        sl = slack(traj, m, t, margin)
        i = int(np.argmin(sl))
        best = min(best, (float(sl[i]), float(t[i])))
    return best


def brute_min(traj, movers, dt=1e-2, margin=0.0):
    """The brute force: 10 ms samples, then the bracket (+-10 ms) of each of the 8 lowest
    local minima refined: 17 samples across it, narrowed to the lowest one's neighbours, until
    the bracket is under 1 ns wide."""
    end = horizon(traj, movers)
    t = np.append(np.arange(0.0, end, dt), end)
    best = np.inf
    for m in movers:
        sl = slack(traj, m, t, margin)
        idx = np.flatnonzero((sl <= np.roll(sl, 1)) & (sl <= np.roll(sl, -1)))
        idx = idx[np.argsort(sl[idx])[:8]]
        lo, hi = np.maximum(0.0, t[idx] - dt), np.minimum(end, t[idx] + dt)
        while len(idx) and np.max(hi - lo) > 1e-9:  # all the brackets at once, times sorted
            u = (lo[:, None] + (hi - lo)[:, None] * np.linspace(0.0, 1.0, 17)).ravel()
            order = np.argsort(u)
            v = np.empty_like(u)
            v[order] = slack(traj, m, u[order], margin)
            u, v = u.reshape(-1, 17), v.reshape(-1, 17)
            best = min(best, float(v.min()))
            c = u[np.arange(len(u)), np.argmin(v, axis=1)]
            step = (hi - lo) / 16
            lo, hi = np.maximum(lo, c - step), np.minimum(hi, c + step)
        best = min(best, float(sl.min()))
    return best


# ------------------------------------------------------------------ the independent check
def mover_rate(mover):
    """A bound (m/s) on how fast any point of ``mover``'s shape moves or its rounding grows.

    From its waypoints: the largest segment speed, plus the farthest vertex times the largest
    turn rate (a polygon), plus the growth of its radius.
    """
    dt = np.diff(mover.times)
    if dt.size == 0:
        return float(mover.growth)
    speed = np.hypot(*np.diff(mover.positions, axis=0).T) / dt
    rate = float(speed.max())
    if mover.vertices is not None:
        reach = float(np.max(np.hypot(*np.asarray(mover.vertices).T)))
        rate += reach * float(np.max(np.abs(np.diff(mover.headings)) / dt))
    return rate + float(mover.growth)


@dataclass(frozen=True)
class MotionCheck:
    """The verdict of :func:`check_motion` (slacks in m, times in s).

    ``violated``: a sample closer than allowed (by more than ``tol``); ``proven``: every
    instant of ``[0, horizon]`` is shown clear (within ``tol``) by the samples and the
    Lipschitz bound; ``speed_ok``: the samples move no faster than the speed bound used.
    """

    mover_slack: float
    mover_t: float
    mover_name: str | None
    static_slack: float
    static_t: float
    violated: bool
    proven: bool
    speed_ok: bool
    horizon: float
    samples: int

    @property
    def ok(self) -> bool:
        return self.proven and self.speed_ok and not self.violated


def _proven(f: Callable[[np.ndarray], np.ndarray], t, v, rate, tol, budget=200_000):
    """Whether ``f >= -tol`` on ``[t[0], t[-1]]`` from its values ``v`` at ``t`` and its Lipschitz ``rate``.

    On ``[a, b]``: ``f >= (f(a) + f(b)) / 2 - rate (b - a) / 2``; intervals where that bound
    falls below ``-tol`` are halved (new samples) until it holds, a sample is below ``-tol``
    (returns ``False``) or the budget of new samples is spent (``False``).
    """
    a, b, fa, fb = t[:-1], t[1:], v[:-1], v[1:]
    used = 0
    while True:
        bad = 0.5 * (fa + fb) - 0.5 * rate * (b - a) < -tol
        if not bad.any():
            return True
        a, b, fa, fb = a[bad], b[bad], fa[bad], fb[bad]
        m = 0.5 * (a + b)
        used += m.size
        if used > budget or np.any(b - a < 1e-12):
            return False
        fm = f(m)
        if np.any(fm < -tol):
            return False
        a, b, fa, fb = np.r_[a, m], np.r_[m, b], np.r_[fa, fm], np.r_[fm, fb]


def check_motion(
    where: Callable[[np.ndarray], np.ndarray],
    end: float,
    movers: Sequence,
    *,
    radius: float,
    speed: float,
    margin: float = 0.0,
    grid=None,
    dt: float = 1e-3,
    tol: float = 1e-6,
) -> MotionCheck:
    """Check a disc robot's timed motion against movers and the map at every instant.

    Parameters
    ----------
    where : callable
        ``where(t)``: the robot's centre (m, shape (n, 2)) at times ``t`` (s, shape (n,)); it
        must stand at its goal after ``end``.
    end : float
        The motion's duration (s).
    movers : sequence of MovingObstacle
        Predictions on the motion's clock.
    radius, speed : float
        The robot's radius (m) and a bound on its speed (m/s, checked on the samples).
    margin : float
        Extra distance to every mover (m).
    grid : astar.OccupancyGrid, optional
        The static map: the clearance ``>= radius`` to its occupied squares and its edge.
    dt : float
        Sample step (s).
    tol : float
        Tolerance (m).

    Returns
    -------
    MotionCheck
        Over ``[0, max(end, last prediction time)]``: the samples every ``dt`` and, between
        them, the Lipschitz bound (the robot's ``speed`` plus the mover's
        :func:`mover_rate`; ``speed`` alone for the map) with halving where it is not enough.
    """
    last = max([float(end)] + [float(m.times[-1]) for m in movers])
    t = np.append(np.arange(0.0, last, dt), last)
    p = where(t)
    step = np.hypot(*np.diff(p, axis=0).T)
    speed_ok = bool(np.all(step <= speed * np.diff(t) + 1e-9))
    best, best_t, best_name, violated, proven = math.inf, 0.0, None, False, True
    for m in movers:
        limit = radius + margin

        def f(tt, m=m, limit=limit):
            return slack_at(where(tt), m, tt, limit)

        v = slack_at(p, m, t, limit)
        i = int(np.argmin(v))
        if v[i] < best:
            best, best_t, best_name = float(v[i]), float(t[i]), m.name
        violated |= bool(v[i] < -tol)
        proven &= _proven(f, t, v, speed + mover_rate(m), tol)
    st_best, st_t = math.inf, 0.0
    if grid is not None:
        reach = radius + 0.5

        def g(tt):
            return square_clearance(grid, where(tt), reach) - radius

        v = g(t)
        i = int(np.argmin(v))
        st_best, st_t = float(v[i]), float(t[i])
        violated |= bool(v[i] < -tol)
        proven &= _proven(g, t, v, speed, tol)
    return MotionCheck(
        best,
        best_t,
        best_name,
        st_best,
        st_t,
        violated,
        proven and not violated,
        speed_ok,
        last,
        int(t.size),
    )


def check_trajectory(traj, movers, *, margin=0.0, grid=None, dt=1e-3, tol=1e-6) -> MotionCheck:
    """:func:`check_motion` of a planned trajectory (its samples; its robot's radius and ``v_max``).

    The speed bound is ``v_max + a_max dt`` (between two samples the speed can exceed the
    sampled ones by at most ``a_max dt / 2``).
    """
    robot = traj.robot
    return check_motion(
        lambda tt: positions(traj, tt),
        float(traj.duration),
        movers,
        radius=float(robot.radius),
        speed=float(robot.v_max) + float(robot.a_max) * dt,
        margin=margin,
        grid=grid,
        dt=dt,
        tol=tol,
    )


class Delayed:
    """The plan started after ``delay`` (s) and played ``pace`` times as fast (a re-timing)."""

    def __init__(self, traj, delay, pace):
        self.traj, self.delay, self.pace, self.robot = traj, delay, pace, traj.robot
        self.duration = delay + traj.duration / pace

    def sample(self, t):
        return self.traj.sample(np.clip((np.asarray(t) - self.delay) * self.pace, 0.0, None))
