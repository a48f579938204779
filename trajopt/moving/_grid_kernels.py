"""The compiled loops of the ``(s, t)`` grid's dense form and of its reachability sweep.

:func:`dense_kernel` paints the runs of :class:`._st_grid.STGrid` into its dense grids (the
forbidden nodes, and the first mover forbidding each: the least mover index among the runs
over it); :func:`sweep_kernel` is the loop of :func:`._st_grid.reachable` over the grid
times. Integer and boolean arithmetic only: the same answers as the array forms.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from trajopt.kernel_cache import watch_compiles

watch_compiles()  # a first compilation logs one notice (trajopt.kernel_cache)


@njit(cache=True)
def dense_kernel(kk, n, col, lo, hi, owner):  # pragma: no cover - compiled
    """Return ``(blocked, who)``, shape (kk, n): the runs painted, the least owner winning.

    Parameters
    ----------
    kk, n : int
        Grid times and nodes.
    col, lo, hi, owner : ndarray of int64, shape (r,)
        Each run's node, first and last time index (inclusive; ``hi`` beyond the grid is cut
        at its last time) and mover.

    Returns
    -------
    blocked : ndarray of bool, shape (kk, n)
    who : ndarray of int16, shape (kk, n)
        -1 where free.
    """
    blocked = np.zeros((kk, n), dtype=np.bool_)
    who = np.full((kk, n), -1, dtype=np.int16)
    for r in range(col.shape[0]):
        i, j = col[r], owner[r]
        for k in range(max(lo[r], 0), min(hi[r], kk - 1) + 1):
            blocked[k, i] = True
            if who[k, i] < 0 or j < who[k, i]:
                who[k, i] = j
    return blocked, who


@njit(cache=True)
def sweep_kernel(fb, s, s_up, bounded, half, m, k_static):  # pragma: no cover - compiled
    """Return ``(ok, k, i)`` of :func:`._st_grid.reachable` (its docstring).

    Parameters
    ----------
    fb : ndarray of bool, shape (K, n)
        The forbidden nodes.
    s : ndarray, shape (n,)
        The nodes (m).
    s_up : ndarray, shape (K,)
        The bound of ``s(t_k)`` (m), used when ``bounded``.
    half : float
        Half the node spacing (m).
    m : int
        The most nodes the robot moves on per grid step.
    k_static : int
        After this time index a step that leaves the reachable nodes as they were ends the
        sweep (a fixed point).
    """
    kk, n = fb.shape
    reach = np.zeros(n, dtype=np.bool_)
    nxt = np.zeros(n, dtype=np.bool_)
    reach[0] = not fb[0, 0]
    last_i = 0
    if not reach[0]:
        return False, 0, 0
    for k in range(1, kk):
        lastr = -(10**9)
        any_next = False
        same = True
        top = -1
        for i in range(n):
            if reach[i]:
                lastr = i
            ok = (not fb[k, i]) and (i - lastr <= m)
            if bounded and not (s[i] <= s_up[k] + half):
                ok = False
            nxt[i] = ok
            if ok:
                any_next = True
                top = i
            if ok != reach[i]:
                same = False
        if not any_next:
            return False, k, last_i
        if k > k_static and same:
            break
        reach[:] = nxt
        last_i = top
    return reach[n - 1], kk - 1, last_i
