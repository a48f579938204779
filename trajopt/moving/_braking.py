"""The shortest jerk-limited stop, and a trajectory's phase state without its path.

:func:`braking_distance` is where a robot moving at ``(v, a)`` comes to rest braking at once
(the re-timing's one more stop from a moving start, and the test of whether it can still
stop in front of a stop); :func:`state_at` is ``(s, v, a)`` of a trajectory's phases.
"""

from __future__ import annotations

import numpy as np

from trajopt.motion import Trajectory


def state_at(traj: Trajectory, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return ``(s, v, a)`` of ``traj``'s phases at times ``t`` in ``[0, duration]`` (s).

    ``traj.motion`` without its clipping to the path's length (which costs an arc-length
    evaluation of the path per call).
    """
    pt = traj.phase_t
    k = np.clip(np.searchsorted(pt, t, side="right") - 1, 0, pt.shape[0] - 1)
    tau = t - pt[k]
    j, a0, v0 = traj.phase_j[k], traj.phase_a[k], traj.phase_v[k]
    s = traj.phase_s[k] + tau * (v0 + tau * (0.5 * a0 + tau * j / 6.0))
    return s, np.maximum(v0 + tau * (a0 + 0.5 * j * tau), 0.0), a0 + j * tau


def braking_distance(
    v0: np.ndarray | float, a0: np.ndarray | float, a_max: float, j_max: float
) -> np.ndarray:
    """Return the distance (m) a robot at speed ``v0`` (m/s), acceleration ``a0`` needs to stop.

    The shortest jerk-limited stop: the acceleration goes at ``-j_max`` to ``-a_p`` (held
    there when ``a_p = a_max``), then at ``+j_max`` back to 0, with ``a_p`` such that the
    speed ends at 0 (``a_p^2 = j_max v0 + a0^2 / 2`` without the hold); from a state already
    braking hard enough (``a0 < 0``, ``a0^2 / (2 j_max) >= v0``), only the last ramp.
    Vectorised over ``v0`` and ``a0``.
    """
    v0 = np.asarray(v0, dtype=float)
    a0 = np.asarray(a0, dtype=float)
    jj = j_max
    ramp_only = (a0 < 0.0) & (a0 * a0 / (2.0 * jj) >= v0)
    a_p = np.sqrt(np.maximum(jj * v0 + 0.5 * a0 * a0, 0.0))
    hold = np.where(
        a_p > a_max, np.maximum(0.0, (v0 + a0 * a0 / (2.0 * jj) - a_max * a_max / jj) / a_max), 0.0
    )
    a_p = np.minimum(a_p, a_max)
    t1 = np.where(ramp_only, 0.0, (a0 + a_p) / jj)
    t3 = np.where(ramp_only, -a0 / jj, a_p / jj)
    hold = np.where(ramp_only, 0.0, hold)
    a_hold = np.where(ramp_only, a0, -a_p)
    s, v, a = np.zeros_like(v0), v0, a0
    for tau, j in ((t1, -jj), (hold, 0.0), (t3, jj)):
        aa = np.where(j == 0.0, a_hold, a) if j == 0.0 else a
        s = s + tau * (v + tau * (0.5 * aa + tau * j / 6.0))
        v = v + tau * (aa + 0.5 * j * tau)
        a = aa + j * tau
    return np.maximum(s, 0.0)
