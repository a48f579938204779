"""The movers' forbidden regions of the ``(s, t)`` plane along a fixed path, on a grid.

Nodes ``s_i = i ds`` along the path (the last one at ``L``) and times ``t_k = k dt``. A node
``(k, i)`` is forbidden when the robot centre at ``C(s_i)`` is closer to a mover at ``t_k``
than the limit ``robot radius + mover radius(t_k) + margin`` plus an ``inflation`` (m):

* the **sufficient** grid inflates by ``ds/2 + (V + u) dt/2 + growth dt/2`` (``V`` the robot's
  speed bound, ``u`` the mover's shape speed bound): a profile whose nearest node at every
  grid time is free keeps the limit at every instant in between (the robot is within
  ``ds/2 + V dt/2`` of that node, the mover's shape within ``u dt/2`` of its place at ``t_k``);
* the **necessary** grid deflates by ``ds/2``: a forbidden node is forbidden for every ``s``
  within ``ds/2`` of it at that instant, so a profile through it is truly unsafe.

A footprint robot is its convex polygon at each node, turned by the path's heading there; it
moves at most ``(1 + R kappa_max)`` per metre of arc, so the robot's share of both pads is
multiplied by that ``stretch``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from trajopt.moving._certificate import convex_distance, point_polygon_distance, shape_at
from trajopt.moving._obstacle import MovingObstacle


@dataclass(frozen=True, slots=True)
class STGrid:
    """Forbidden nodes of the ``(s, t)`` plane.

    Attributes
    ----------
    s : ndarray, shape (n,)
        Arc-length nodes (m), ``s[0] = 0``, ``s[-1] = L``.
    t : ndarray, shape (K,)
        Times (s), ``t[k] = k dt``.
    ds, dt : float
        Spacings (m, s).
    blocked : ndarray of bool, shape (K, n)
        Forbidden nodes.
    who : ndarray of int, shape (K, n)
        Index of the first mover forbidding each node, -1 where free.
    """

    s: np.ndarray
    t: np.ndarray
    ds: float
    dt: float
    blocked: np.ndarray
    who: np.ndarray

    def index(self, s: np.ndarray) -> np.ndarray:
        """Nearest node index of arc lengths ``s`` (m)."""
        return np.clip(np.rint(np.asarray(s) / self.ds), 0, self.s.shape[0] - 1).astype(np.int64)


def path_points(path: object, s: np.ndarray) -> np.ndarray:
    """Points of ``path`` at arc lengths ``s`` (m), shape (n, 2)."""
    return np.asarray(path(path.u_at_s(s)), dtype=float)  # type: ignore[operator, attr-defined]


def st_grid(
    path: object,
    length: float,
    movers: Sequence[MovingObstacle],
    limit: float,
    *,
    ds: float,
    dt: float,
    horizon: float,
    speed: float,
    sufficient: bool,
    body: np.ndarray | None = None,
    stretch: float = 1.0,
) -> STGrid:
    """Build the forbidden grid (module docstring).

    Parameters
    ----------
    path : ParametricCurve
        The path, arc length ``length`` (m).
    movers : sequence of MovingObstacle
    limit : float
        Robot radius plus margin (m), or the margin alone with a ``body``; each mover adds
        its radius.
    ds, dt : float
        Requested spacings (m, s); ``ds`` is adjusted to divide ``length``.
    horizon : float
        Last time (s) of the grid.
    speed : float
        The robot's speed bound ``V`` (m/s).
    sufficient : bool
        Inflate (a safe under-approximation of the free space) or deflate (a necessary one).
    body : ndarray, shape (m, 2), optional
        The robot's convex footprint (robot frame, CCW, m), turned by the path's heading at
        each node; ``None``: a disc robot.
    stretch : float
        With a ``body``: ``1 + R kappa_max`` (``R`` its farthest vertex), the bound of how far
        the footprint moves per metre of arc length; the pads scale the robot's share by it.

    Returns
    -------
    STGrid
    """
    n = max(2, int(math.ceil(length / ds)) + 1)
    s = np.linspace(0.0, length, n)
    ds = float(s[1] - s[0])
    kk = max(2, int(math.ceil(horizon / dt)) + 1)
    t = np.arange(kk) * dt
    pts = path_points(path, s)
    polys = None
    if body is not None:
        th = np.asarray(path.heading(path.u_at_s(s)), dtype=float)  # type: ignore[attr-defined]
        c, sn = np.cos(th)[:, None], np.sin(th)[:, None]
        polys = np.stack(
            [
                pts[:, 0:1] + c * body[None, :, 0] - sn * body[None, :, 1],
                pts[:, 1:2] + sn * body[None, :, 0] + c * body[None, :, 1],
            ],
            axis=-1,
        )
    else:
        stretch = 1.0
    blocked = np.zeros((kk, n), dtype=bool)
    who = np.full((kk, n), -1, dtype=np.int16)
    for j, m in enumerate(movers):
        if sufficient:
            pad = 0.5 * (ds + dt * speed) * stretch + 0.5 * dt * (m.shape_speed_max() + m.growth)
        else:
            pad = -0.5 * ds * stretch
        lim = limit + m.radius_at(t) + pad  # (K,)
        hit = np.zeros((kk, n), dtype=bool)
        if polys is not None:
            shapes = shape_at(m, t)
            for k in range(kk):
                w = np.broadcast_to(shapes[k], (n, *shapes[k].shape))
                hit[k] = convex_distance(polys, w) < lim[k]
        elif m.vertices is None:
            c = m.position_at(t)
            for a in range(0, kk, 256):
                b = min(kk, a + 256)
                d = np.hypot(pts[None, :, 0] - c[a:b, None, 0], pts[None, :, 1] - c[a:b, None, 1])
                hit[a:b] = d < lim[a:b, None]
        else:
            shapes = shape_at(m, t)  # (K, m, 2)
            for k in range(kk):
                w = np.broadcast_to(shapes[k], (n, *shapes[k].shape))
                hit[k] = point_polygon_distance(pts, w) < lim[k]
        who[hit & ~blocked] = j
        blocked |= hit
    return STGrid(s=s, t=t, ds=ds, dt=float(dt), blocked=blocked, who=who)


def reach_bound(t: np.ndarray, v_max: float, a_max: float, j_max: float) -> np.ndarray:
    """Return an upper bound (m) of ``s(t)`` for any motion from rest under the limits, at ``t`` (s).

    ``a <= min(a_max, j_max t)``, so ``v <= min(v_max, integral of that)``, and ``s`` is at
    most the integral of this increasing bound, taken as an upper Riemann sum on 1 ms steps.
    """
    t = np.asarray(t, dtype=float)
    h = 1e-3
    tt = np.arange(0.0, float(np.max(t, initial=0.0)) + 2.0 * h, h)
    t1 = a_max / j_max
    vel = np.where(tt <= t1, 0.5 * j_max * tt * tt, 0.5 * a_max * t1 + a_max * (tt - t1))
    vel = np.minimum(v_max, vel)
    s = np.concatenate([[0.0], np.cumsum(vel[1:] * h)])  # right sums of an increasing bound
    k = np.minimum(np.ceil(t / h - 1e-12).astype(np.int64), tt.shape[0] - 1)
    return s[k]


def reachable(grid: STGrid, speed: float, s_up: np.ndarray | None = None) -> tuple[bool, int, int]:
    """Sweep the nodes a non-decreasing ``s(t)`` with speed ``<= speed`` can occupy.

    A relaxation: from node ``i`` at ``t_k`` the robot may be at any free node ``j`` with
    ``i <= j <= i + m`` at ``t_{k+1}`` (``m = ceil(speed dt / ds) + 1``), whatever lies between,
    and (given ``s_up``, shape (K,), an upper bound of ``s(t_k)`` in m) not beyond
    ``s_up[k] + ds/2``.

    Returns
    -------
    ok : bool
        The goal node is reachable at the last time.
    k : int
        The first time index where nothing is reachable (or the last one).
    i : int
        The furthest reachable node before that (the place where the robot is stopped).
    """
    fb = grid.blocked
    kk, n = fb.shape
    m = int(math.ceil(speed * grid.dt / grid.ds)) + 1
    idx = np.arange(n)
    reach = np.zeros(n, dtype=bool)
    reach[0] = not fb[0, 0]
    last_i = 0
    if not reach[0]:
        return False, 0, 0
    for k in range(1, kk):
        lastr = np.maximum.accumulate(np.where(reach, idx, -(10**9)))
        nxt = ~fb[k] & (idx - lastr <= m)
        if s_up is not None:
            nxt &= grid.s <= s_up[k] + 0.5 * grid.ds
        if not nxt.any():
            return False, k, last_i
        reach = nxt
        last_i = int(np.max(np.flatnonzero(reach)))
    return bool(reach[-1]), kk - 1, last_i
