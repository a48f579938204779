"""Independent references for the tests of trajopt.moving: dense sampling and a brute force."""

from __future__ import annotations

import numpy as np
from scipy.optimize import minimize_scalar


def slack(traj, mover, t, margin=0.0):
    """Distance minus limit (m) at times ``t`` (s), from the trajectory's own samples.

    A disc mover's centre distance, or a convex polygon's (vertices rotated and shifted, the
    point-to-polygon distance written out here again, 0 inside).
    """
    t = np.atleast_1d(np.asarray(t, dtype=float))
    smp = traj.sample(t)
    p = np.stack([np.asarray(smp.x), np.asarray(smp.y)], axis=-1)
    c = np.stack([np.interp(t, mover.times, mover.positions[:, i]) for i in (0, 1)], axis=-1)
    h = np.interp(t, mover.times, mover.headings)
    rad = mover.radius + mover.growth * np.clip(t, 0.0, mover.times[-1])
    limit = traj.robot.radius + rad + margin
    if mover.vertices is None:
        return np.hypot(*(p - c).T) - limit
    ch, sh = np.cos(h)[:, None], np.sin(h)[:, None]
    vx, vy = mover.vertices[:, 0][None], mover.vertices[:, 1][None]
    w = np.stack([c[:, :1] + ch * vx - sh * vy, c[:, 1:] + sh * vx + ch * vy], axis=-1)
    e = np.roll(w, -1, axis=1) - w  # edges, (n, m, 2)
    q = p[:, None, :] - w
    lam = np.clip(np.sum(q * e, axis=2) / np.sum(e * e, axis=2), 0.0, 1.0)
    foot = q - lam[..., None] * e
    dist = np.min(np.hypot(foot[..., 0], foot[..., 1]), axis=1)
    inside = np.all(e[..., 0] * q[..., 1] - e[..., 1] * q[..., 0] >= 0.0, axis=1)
    return np.where(inside, 0.0, dist) - limit


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
    """The brute force: 10 ms samples, then a bounded scalar minimisation around every local minimum."""
    end = horizon(traj, movers)
    t = np.append(np.arange(0.0, end, dt), end)
    best = np.inf
    for m in movers:
        sl = slack(traj, m, t, margin)
        idx = np.flatnonzero((sl <= np.roll(sl, 1)) & (sl <= np.roll(sl, -1)))
        for i in idx[np.argsort(sl[idx])[:8]]:
            lo, hi = max(0.0, t[i] - dt), min(end, t[i] + dt)
            r = minimize_scalar(
                lambda x, m=m: float(slack(traj, m, x, margin)[0]),
                bounds=(lo, hi),
                method="bounded",
                options={"xatol": 1e-9},
            )
            best = min(best, float(r.fun), float(sl[i]))
        best = min(best, float(sl.min()))
    return best
