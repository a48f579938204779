"""Witnesses that a moving-obstacle scenario has a safe answer (issue 46), independent of trajopt.moving.

* :func:`waiting_witness`: rest at the start while it is safe, then drive the static plan,
  planned again with the movers' final discs as obstacles when the static path passes
  closer to one of them than allowed. The earliest such wait (on a 10 ms grid) is found on
  samples with a Lipschitz margin, then the whole motion is checked by
  :func:`tests.trajopt.moving.reference.check_motion` (1 ms samples plus the interval bound,
  the static map included). A real motion of the robot: its timing is the planner's own.
* :func:`grid_optimum`: the earliest arrival along the static path found by a brute-force
  search of the ``(s, t, v)`` lattice. Its dynamics model: constant acceleration in
  ``{-a_max, 0, +a_max}`` over each step ``dt``, ``0 <= v <= v_max`` with the speed
  capped by the path's curvature (``v^2 |kappa| <= a_lat_max``, ``v |kappa| <=
  omega_max``, and for a differential drive ``v (1 + |kappa| track / 2) <=
  wheel_v_max``) at the lattice points; no jerk limit, so it is a relaxation of the
  robot's jerk-limited motion. ``s`` moves in units of ``a_max dt^2 / 2`` (0.625 mm for
  ``a_max = 0.5``, ``dt = 0.05``: every step lands on the lattice exactly). A lattice point
  is free when the robot's centre on the path keeps ``robot radius + mover radius(t) +
  margin + (v_max + mover speed) dt / 2 + 1 cm`` from every mover (the added distance
  covers the motion between two lattice times and the 2 cm path samples the movers are
  tested on), so the lattice motion is clear at every instant. The goal is reached at rest
  within 1 cm of the path's end, at a time after which the goal stays clear.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

import astar
import trajopt
from benchmarks.moving_cases import PathTrack
from tests.trajopt.moving.reference import check_motion, mover_rate, positions, slack_at

TOL = 1e-6


@dataclass(frozen=True)
class WaitingWitness:
    """Rest ``wait`` s at the start, then drive ``traj``; arrival at ``wait + traj.duration``."""

    wait: float
    traj: object
    replanned: bool

    @property
    def arrival(self) -> float:
        return self.wait + float(self.traj.duration)

    def where(self, t):
        return positions(self.traj, np.clip(np.asarray(t, dtype=float) - self.wait, 0.0, None))


def final_discs(movers, margin: float):
    """``(centre, radius)`` of every mover at its last prediction, ``margin`` added (m)."""
    out = []
    for m in movers:
        reach = 0.0 if m.vertices is None else float(np.max(np.hypot(*np.asarray(m.vertices).T)))
        r = m.radius + m.growth * max(float(m.times[-1]), 0.0) + reach + margin
        out.append((np.asarray(m.positions[-1], dtype=float), r))
    return out


def with_discs(grid: astar.OccupancyGrid, discs) -> astar.OccupancyGrid:
    """``grid`` with every cell whose square comes within a disc's radius marked occupied."""
    occ = grid.occupied.copy()
    res, (ox, oy) = grid.resolution, grid.origin
    iy, ix = np.mgrid[0 : occ.shape[0], 0 : occ.shape[1]]
    cx, cy = ox + (ix + 0.5) * res, oy + (iy + 0.5) * res
    for c, r in discs:
        dx = np.maximum(np.abs(cx - c[0]) - 0.5 * res, 0.0)
        dy = np.maximum(np.abs(cy - c[1]) - 0.5 * res, 0.0)
        occ |= np.hypot(dx, dy) <= r + 1e-9
    return astar.OccupancyGrid(occ, res, grid.origin)


def _path_clear_of(track: PathTrack, discs, radius: float) -> bool:
    """Whether the path keeps ``radius`` from every disc (its 5 ms points, spacing bounded)."""
    gap = float(np.max(np.hypot(*np.diff(track.p, axis=0).T), initial=0.0))
    for c, r in discs:
        if np.min(np.hypot(*(track.p - c).T)) - radius - r < 0.5 * gap + TOL:
            return False
    return True


def waiting_witness(grid, static, start, goal, movers, margin: float, *, h: float = 0.01):
    """The earliest wait-then-drive motion (module docstring), or ``None`` when none exists.

    Parameters
    ----------
    grid : astar.OccupancyGrid
        The static map.
    static : Trajectory
        The static plan from ``start`` to ``goal``.
    start, goal : sequence of float, shape (2,)
        The query (m).
    movers : sequence of MovingObstacle
    margin : float
        The mover margin (m).
    h : float
        The grid of waits (s).

    Returns
    -------
    WaitingWitness or None
        ``None`` when the final discs cover the start or the goal or cut them apart, or no
        wait keeps the motion clear (one ends at the latest when a mover reaches the start
        or ``h`` after every prediction has ended).
    """
    robot = static.robot
    discs = final_discs(movers, margin)
    traj, replanned = static, False
    if not _path_clear_of(PathTrack(static), discs, robot.radius):
        try:
            traj = trajopt.Planner(with_discs(grid, discs), robot).plan(start, goal)
        except trajopt.TrajoptError:
            return None
        replanned = True
    T = float(traj.duration)
    K = int(math.ceil(T / h))
    p = positions(traj, np.arange(K + 1) * h)
    last = max([0.0] + [float(m.times[-1]) for m in movers])
    J = int(math.ceil(max(last, 0.0) / h)) + 1  # waits 0 .. J h
    tg = np.arange(J + K + 2) * h
    limit = robot.radius + margin
    start_bad = np.zeros(tg.size, bool)
    goal_bad = np.zeros(tg.size, bool)
    drive_slack = []
    for m in movers:
        rate = mover_rate(m)
        start_bad |= slack_at(np.repeat(p[:1], tg.size, 0), m, tg, limit) < rate * h / 2 + TOL
        goal_bad |= slack_at(np.repeat(p[-1:], tg.size, 0), m, tg, limit) < rate * h / 2 + TOL
        drive_slack.append((m, (robot.v_max + robot.a_max * h + rate) * h / 2 + TOL))
    first_start_bad = int(np.argmax(start_bad)) if start_bad.any() else tg.size
    last_goal_bad = int(np.flatnonzero(goal_bad)[-1]) if goal_bad.any() else -1
    tk = np.arange(K + 1) * h
    for j in range(max(0, last_goal_bad - K + 1), min(J, first_start_bad - 1) + 1):
        if all(np.all(slack_at(p, m, tk + j * h, limit) >= need) for m, need in drive_slack):
            w = WaitingWitness(j * h, traj, replanned)
            chk = check_motion(
                w.where,
                w.arrival,
                movers,
                radius=robot.radius,
                speed=robot.v_max + robot.a_max * 1e-3,
                margin=margin,
                grid=grid,
            )
            if chk.ok:
                return w
    return None


def _speed_cap(static, track: PathTrack) -> np.ndarray:
    """The curvature's speed cap (m/s) at the track's points (module docstring)."""
    robot = static.robot
    kappa = np.maximum(np.abs(np.asarray(static.sample(track.t).kappa, dtype=float)), 1e-12)
    cap = np.minimum(robot.v_max, np.sqrt(robot.a_lat_max / kappa))
    cap = np.minimum(cap, robot.omega_max / kappa)
    if isinstance(robot.drive, trajopt.Differential):
        cap = np.minimum(cap, robot.wheel_v_max / (1.0 + 0.5 * kappa * robot.track_width))
    return cap


def grid_optimum(static, movers, margin: float, *, dt: float = 0.05, extra: float = 5.0):
    """The lattice search's earliest arrival (s) along ``static``'s path, or ``None`` (module docstring).

    Parameters
    ----------
    static : Trajectory
        The static plan: its path, robot and limits.
    movers : sequence of MovingObstacle
    margin : float
        The mover margin (m).
    dt : float
        The lattice's time step (s).
    extra : float
        The search ends at ``last prediction + 2 static duration + extra`` (s).

    Returns
    -------
    float or None
        The arrival time (s); ``None`` when no lattice motion gets through in that time.
    """
    robot = static.robot
    a, vmax = float(robot.a_max), float(robot.v_max)
    q = 0.5 * a * dt * dt
    K = int(math.floor(vmax / (a * dt) + 1e-9))
    track = PathTrack(static)
    S = int(math.floor(track.length / q))
    n_s = np.arange(S + 1) * q
    cap = np.interp(n_s, track.s, _speed_cap(static, track))
    kcap = np.floor(cap / (a * dt) + 1e-9).astype(int)
    speed_ok = np.arange(K + 1)[:, None] <= kcap[None, :]
    c = 0.02
    coarse = track.point(np.arange(int(math.ceil(track.length / c)) + 1) * c)
    to_coarse = np.minimum(np.rint(n_s / c).astype(int), coarse.shape[0] - 1)
    limit = robot.radius + margin
    needs = [(m, (vmax + mover_rate(m)) * dt / 2 + 0.5 * c + TOL) for m in movers]
    last = max([0.0] + [float(m.times[-1]) for m in movers])
    goal = track.point(track.length)[None]
    tf = np.arange(0.0, last + 2e-3, 1e-3)
    goal_bad = np.zeros(tf.size, bool)
    for m in movers:
        goal_bad |= slack_at(np.repeat(goal, tf.size, 0), m, tf, limit) < mover_rate(m) * 5e-4 + TOL
    goal_free_after = float(tf[np.flatnonzero(goal_bad)[-1]]) if goal_bad.any() else -1.0
    near_goal = S - int(round(0.01 / q))
    R = np.zeros((K + 1, S + 1), bool)
    R[0, 0] = True
    steps = int(math.ceil((max(last, 0.0) + 2.0 * float(static.duration) + extra) / dt))
    for j in range(steps):
        t1 = (j + 1) * dt
        new = np.zeros_like(R)
        lo = int(np.argmax(R.any(axis=0)))
        for k in range(K + 1):
            row = R[k, lo:]
            if not row.any():
                continue
            for k2 in (k - 1, k, k + 1):
                if 0 <= k2 <= K:
                    sh = k + k2
                    if sh == 0:
                        new[k2, lo:] |= row
                    elif lo + sh <= S:
                        new[k2, lo + sh :] |= row[: S + 1 - lo - sh]
        new &= speed_ok
        blocked = np.zeros(coarse.shape[0], bool)
        tt = np.full(coarse.shape[0], t1)
        for m, need in needs:
            blocked |= slack_at(coarse, m, tt, limit) < need
        new &= ~blocked[to_coarse][None, :]
        R = new
        if not R.any():
            return None
        if t1 > goal_free_after and R[0, near_goal:].any():
            return t1
    return None


def path_blocked(static, movers, margin: float, *, ds: float = 0.01, dt: float = 0.01) -> bool:
    """Whether no motion along ``static``'s path gets the robot to its goal clear of the movers.

    A proof by a relaxation: any non-decreasing ``s(t)`` with ``ds/dt <= v_max`` that starts
    at rest at ``t = 0`` and stays within the reach of a robot accelerating at ``a_max``
    (``s(t) <= a_max t^2 / 2`` until ``v_max``, then ``v_max`` on; a jerk limit only lowers
    it); no other limit. The path is cut into cells of
    ``ds``; at each time ``j dt`` the robot's cell is one whose centre is not closer to a
    mover than ``limit - ds / 2 - 10 um`` (else every point of the cell collides: the path's
    point is 1-Lipschitz in arc length; 10 um covers the polyline of the track), and from one
    time to the next the cell index grows by at most ``floor(v_max dt / ds) + 1``. The goal's
    cell must be reached after the last sampled time the goal itself collides. The sweep runs
    until every prediction has ended and the robot could have driven the whole path again
    (after the last prediction nothing moves, so nothing new becomes reachable).

    Returns
    -------
    bool
        ``True`` only when no such motion exists (so no motion of the real robot along the
        path does); ``False`` when the relaxation gets through.
    """
    robot = static.robot
    vmax, amax = float(robot.v_max), float(robot.a_max)
    track = PathTrack(static)
    n = int(math.floor(track.length / ds)) + 1
    centres = track.point(np.minimum((np.arange(n) + 0.5) * ds, track.length))
    goal = track.point(track.length)[None]
    limit = robot.radius + margin
    step = int(math.floor(vmax * dt / ds)) + 1
    last = max([0.0] + [float(m.times[-1]) for m in movers])
    steps = int(math.ceil((last + track.length / vmax + 1.0) / dt))
    reach = np.zeros(n, bool)
    reach[0] = True
    goal_hit = -1.0
    for j in range(1, steps + 1):
        t = j * dt
        tt = np.full(n, t)
        csum = np.r_[0, np.cumsum(reach)]
        lo = np.maximum(np.arange(n) - step, 0)
        new = csum[np.arange(n) + 1] - csum[lo] > 0
        t_up = vmax / amax
        s_up = 0.5 * amax * t * t if t < t_up else 0.5 * vmax * t_up + vmax * (t - t_up)
        new[int(math.floor(s_up / ds)) + 1 :] = False
        for m in movers:
            new &= slack_at(centres, m, tt, limit) >= -(0.5 * ds + 1e-5)
            if slack_at(goal, m, np.full(1, t), limit)[0] < 0.0:
                goal_hit = t
        reach = new
        if not reach.any():
            return True
        if reach[-1] and t > goal_hit and t > last:
            return False
    return True
