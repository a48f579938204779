"""The motion along the path of a chain of constant-jerk phases, compiled: ``t -> (s, v, a, jerk)``."""

from __future__ import annotations

import numpy as np
from numba import njit

from trajopt.kernel_cache import watch_compiles

watch_compiles()  # a first compilation logs one notice (trajopt.kernel_cache)


@njit(cache=True)
def phase_motion(pt, ps, pv, pa, pj, duration, length, v_end, t):  # pragma: no cover - compiled
    """Return ``(s, v, a, jerk)`` at times ``t`` (s) of constant-jerk phases (``Trajectory.motion``).

    Times are clipped to ``[0, duration]``; phase ``k`` is the last with ``pt[k] <= t``
    (the first before ``pt[0]``); within it ``s = ps + tau (pv + tau (pa / 2 + tau pj / 6))``,
    ``v = pv + tau (pa + pj tau / 2)``, ``a = pa + pj tau`` with ``tau = t - pt[k]``. ``s`` is
    clipped to ``[0, length]`` and a speed in ``(-1e-9, 0)`` (rounding) is 0; at and after
    ``duration`` the state is exactly ``(length, v_end, 0, 0)``. NaN times give NaN
    ``s, v, a`` (and the last phase's jerk).

    Parameters
    ----------
    pt, ps, pv, pa, pj : ndarray, shape (p,)
        Start time (s), arc length (m), speed (m/s), acceleration (m/s^2) of each phase and
        its jerk (m/s^3); ``pt`` non-decreasing.
    duration, length, v_end : float
        End time (s), path length (m), end speed (m/s).
    t : ndarray, shape (n,)
        Times (s).

    Returns
    -------
    s, v, a, jerk : ndarray, shape (n,)
    """
    n = t.shape[0]
    p = pt.shape[0]
    s = np.empty(n)
    v = np.empty(n)
    a = np.empty(n)
    jerk = np.empty(n)
    for q in range(n):
        tt = t[q]
        if tt < 0.0:
            tt = 0.0
        elif tt > duration:
            tt = duration
        if tt != tt:
            k = p - 1
        else:
            k = min(max(np.searchsorted(pt, tt, side="right") - 1, 0), p - 1)
        if tt >= duration:
            s[q], v[q], a[q], jerk[q] = length, v_end, 0.0, 0.0
            continue
        tau = tt - pt[k]
        j = pj[k]
        a0 = pa[k]
        v0 = pv[k]
        sq = ps[k] + tau * (v0 + tau * (0.5 * a0 + tau * j / 6.0))
        vq = v0 + tau * (a0 + 0.5 * j * tau)
        s[q] = min(max(sq, 0.0), length) if sq == sq else sq
        v[q] = 0.0 if (vq < 0.0 and vq > -1e-9) else vq
        a[q] = a0 + j * tau
        jerk[q] = j
    return s, v, a, jerk
