"""The compiled node-by-node sweep of :func:`trajopt.moving.reachable_times`: :func:`reach_kernel`.

The same steps as the list form it replaced, on flat arrays: each node's free time-index
intervals from its forbidden runs (sorted by their first index), and the tails of those an
interval of one of the ``m`` nodes before it enters one step later.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from trajopt.kernel_cache import watch_compiles

watch_compiles()  # a first compilation logs one notice (trajopt.kernel_cache)


@njit(cache=True)
def reach_kernel(n, m, k_cap, ptr, lo, hi, forever):  # pragma: no cover - compiled
    """Return ``(rptr, ra, rb)``: node ``j``'s reachable intervals ``[ra[i], rb[i]]``, ``i`` in ``rptr[j]:rptr[j + 1]``.

    Parameters
    ----------
    n, m : int
        The nodes, and how many nodes before a node it can be entered from.
    k_cap : ndarray of int64, shape (n,)
        The first time index node ``j`` is within the reach bound.
    ptr, lo, hi : ndarray of int64
        The forbidden runs of node ``j``, ``ptr[j]:ptr[j + 1]``: time indices ``[lo, hi]``
        (``hi >= forever``: for ever).
    forever : int
        :data:`trajopt.moving._st_grid.FOREVER`.

    Returns
    -------
    rptr : ndarray of int64, shape (n + 1,)
    ra, rb : ndarray of float64
        Time indices (``rb`` inf: for ever).
    """
    cap = 4 * n + 16
    ra = np.empty(cap)
    rb = np.empty(cap)
    rptr = np.zeros(n + 1, dtype=np.int64)
    most = 1
    for j in range(n):
        most = max(most, ptr[j + 1] - ptr[j] + 1)
    fa = np.empty(most)
    fb = np.empty(most)
    count = 0
    for j in range(n):
        if j >= m and rptr[j] == rptr[j - m]:  # no way into j, nor into any node after it
            for k in range(j + 1, n + 1):
                rptr[k] = count
            break
        a0, a1 = ptr[j], ptr[j + 1]
        order = np.argsort(lo[a0:a1], kind="mergesort")
        nf = 0
        at = 0 if j == 0 else k_cap[j]
        done = False
        r = 0
        while r < order.shape[0]:  # runs sorted by (lo, hi): a tie of lo takes the larger hi
            q = a0 + order[r]
            top = hi[q]
            while r + 1 < order.shape[0] and lo[a0 + order[r + 1]] == lo[q]:
                r += 1
                top = max(top, hi[a0 + order[r]])
            if lo[q] > at:
                fa[nf] = at
                fb[nf] = lo[q] - 1
                nf += 1
            at = max(at, top + 1)
            if at >= forever:
                done = True
                break
            r += 1
        if not done:
            fa[nf] = at
            fb[nf] = math.inf
            nf += 1
        if count + nf > cap:  # room for this node's intervals
            cap = 2 * (count + nf)
            na = np.empty(cap)
            nb = np.empty(cap)
            na[:count] = ra[:count]
            nb[:count] = rb[:count]
            ra, rb = na, nb
        if j == 0:
            if nf > 0 and fa[0] == 0:
                ra[count] = fa[0]
                rb[count] = fb[0]
                count += 1
            rptr[1] = count
            continue
        c0, c1 = rptr[max(0, j - m)], rptr[j]
        for f in range(nf):
            a, b = fa[f], fb[f]
            e = math.inf
            for i in range(c0, c1):
                p, q2 = ra[i] + 1.0, rb[i] + 1.0
                if p <= b and q2 >= a:
                    e = min(e, max(a, p))
            if e < math.inf:
                ra[count] = e
                rb[count] = b
                count += 1
        rptr[j + 1] = count
    return rptr, ra[:count], rb[:count]
