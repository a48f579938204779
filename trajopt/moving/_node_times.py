"""The compiled forbidden and resting times of one node of the ``(s, t)`` grid.

A node's forbidden times are its merged runs (:attr:`._st_grid.STGrid.merged`: ``[lo, hi]``
step ranges, ``hi`` possibly beyond the grid's last step) painted on the grid's steps:
:func:`column_kernel`, the bool array of :meth:`._st_grid.STGrid.column`. The robot can rest
at a stop's node at step ``k`` when it arrived there at some step ``a <= k`` and the node is
free at every step ``a..k``: :func:`rest_kernel`, the running maxima of the arrival and
forbidden steps of :func:`._st_search.search`'s dynamic programme in one loop. Integer and
bool arithmetic only: the same answers as the numpy forms.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from trajopt.kernel_cache import watch_compiles

watch_compiles()  # a first compilation logs one notice (trajopt.kernel_cache)


@njit(cache=True)
def column_kernel(ptr, m_lo, m_hi, kk, i):  # pragma: no cover - compiled
    """Return the forbidden steps of node ``i``, bool, shape (kk,).

    Parameters
    ----------
    ptr, m_lo, m_hi : ndarray of int64
        The grid's merged runs (``ptr`` (n + 1,) per node; ``m_lo``, ``m_hi`` (q,) first and
        last step of each run, inclusive, clipped here to ``[0, kk - 1]``).
    kk : int
        Grid times.
    i : int
        The node.
    """
    col = np.zeros(kk, dtype=np.bool_)
    for r in range(ptr[i], ptr[i + 1]):
        for k in range(max(m_lo[r], 0), min(m_hi[r], kk - 1) + 1):
            col[k] = True
    return col


@njit(cache=True)
def rest_kernel(arrive, blocked):  # pragma: no cover - compiled
    """Return ``(rest, since)``: the steps the robot can rest at a node, and its arrival for each.

    Parameters
    ----------
    arrive : ndarray of bool, shape (kk,)
        The robot comes to rest at the node at these steps.
    blocked : ndarray of bool, shape (kk,)
        The node's forbidden steps.

    Returns
    -------
    rest : ndarray of bool, shape (kk,)
        The latest arrival at or before step ``k`` exists and no forbidden step lies in
        ``(arrival, k]`` nor at the arrival itself.
    since : ndarray of int64, shape (kk,)
        That latest arrival's step, -1 before the first.
    """
    kk = arrive.shape[0]
    rest = np.zeros(kk, dtype=np.bool_)
    since = np.empty(kk, dtype=np.int64)
    last_arr, last_blk = -1, -1
    for k in range(kk):
        if arrive[k]:
            last_arr = k
        if blocked[k]:
            last_blk = k
        rest[k] = last_arr >= 0 and last_arr > last_blk
        since[k] = last_arr
    return rest, since
