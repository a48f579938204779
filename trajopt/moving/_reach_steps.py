"""The reach bound from rest on its 1 ms steps, kept: :func:`reach_from_rest`.

:func:`~trajopt.moving._st_grid.reach_bound` from rest sums the bound of the speed on 1 ms
steps from ``t = 0`` up to the latest time asked (a cumulative sum of some ten thousand steps
for a mover that stands still after ten seconds). The sums do not depend on how far they go:
the steps to a later time start with the steps to an earlier one, the same floats. So the
sums are kept per ``(v_max, a_max, j_max)``, as long as the latest time asked, and a bound
at any times is read from them.
"""

from __future__ import annotations

import math

import numpy as np

#: The step (s) of :func:`~trajopt.moving._st_grid.reach_bound`'s sums.
STEP = 1e-3
#: The sums kept, one per ``(v_max, a_max, j_max)`` (the last this many).
_KEPT = 8
_SUMS: dict[tuple[float, float, float], np.ndarray] = {}


def reach_from_rest(t: np.ndarray, v_max: float, a_max: float, j_max: float) -> np.ndarray:
    """Return :func:`~trajopt.moving._st_grid.reach_bound` from rest at ``t`` (s), the same floats.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Times (s), at least 0, finite.
    v_max, a_max, j_max : float
        The limits (m/s, m/s^2, m/s^3).

    Returns
    -------
    ndarray, shape (n,)
        The bound (m) of ``s(t)`` of a motion from rest.
    """
    t = np.asarray(t, dtype=float)
    t_top = float(np.max(t, initial=0.0))
    # reach_bound's step count: numpy.arange(0, t_top + 2 STEP, STEP)'s length
    count = int(math.ceil((t_top + 2.0 * STEP) / STEP))
    key = (float(v_max), float(a_max), float(j_max))
    sums = _SUMS.get(key)
    if sums is None or sums.shape[0] < count:
        # reach_bound's sums up to a later time (at least twice as far as those it replaces)
        t_long = max(t_top, 0.0 if sums is None else 2.0 * sums.shape[0] * STEP)
        sums = _sums(t_long, *key)
        sums.setflags(write=False)
        _SUMS.pop(key, None)
        while len(_SUMS) >= _KEPT:
            _SUMS.pop(next(iter(_SUMS)))
        _SUMS[key] = sums
    k = np.minimum(np.ceil(t / STEP - 1e-12).astype(np.int64), count - 1)
    return sums[k]


def _sums(t_top: float, v_max: float, a_max: float, j_max: float) -> np.ndarray:
    """Return the upper sums (m) of :func:`~trajopt.moving._st_grid.reach_bound` from rest to ``t_top`` (s).

    Its code, step for step: ``numpy.arange`` gives the ``i``-th step ``i STEP`` whatever
    its end, so the sums up to an earlier time are the first of these.
    """
    tt = np.arange(0.0, t_top + 2.0 * STEP, STEP)
    t1 = a_max / j_max
    vel = np.where(tt <= t1, 0.5 * j_max * tt * tt, 0.5 * a_max * t1 + a_max * (tt - t1))
    vel = np.minimum(v_max, vel)
    return np.concatenate([[0.0], np.cumsum(vel[1:] * STEP)])
