"""The compiled tables of the ``(s, t)`` grid's runs: grouped by node, and merged per node.

:class:`._st_grid.STGrid` keeps its runs grouped by node (``ptr``) and, for the search, the
runs of all movers of each node merged (:attr:`._st_grid.STGrid.merged`). :func:`runs_kernel`
builds both in one pass over the runs: a counting sort by node (stable: a node's runs in
the order given, as ``numpy.argsort(..., kind="stable")``), then per node an insertion sort
by first step (stable) and one walk that joins overlapping or adjacent runs. Integer
arithmetic only: the same arrays as the numpy form.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from trajopt.kernel_cache import watch_compiles

watch_compiles()  # a first compilation logs one notice (trajopt.kernel_cache)


@njit(cache=True)
def runs_kernel(n, col, lo, hi, owner):  # pragma: no cover - compiled
    """Return the runs grouped by node and merged per node.

    Parameters
    ----------
    n : int
        Nodes.
    col, lo, hi, owner : ndarray of int64, shape (r,)
        Each run's node (``0 <= col < n``), first and last step (inclusive, ``lo >= 0``) and
        mover.

    Returns
    -------
    ptr : ndarray of int64, shape (n + 1,)
        Node ``i``'s runs are ``ptr[i]:ptr[i + 1]`` of the next four.
    s_col, s_lo, s_hi, s_owner : ndarray of int64, shape (r,)
        The runs grouped by node, each node's in the order given.
    m_ptr : ndarray of int64, shape (n + 1,)
        Node ``i``'s merged runs are ``m_ptr[i]:m_ptr[i + 1]`` of the next three.
    m_col, m_lo, m_hi : ndarray of int64, shape (q,)
        The merged runs, in order of node and first step: each the union of a node's runs
        that overlap or touch (a run starting at most one step after the latest end so far).
    """
    r = col.shape[0]
    ptr = np.zeros(n + 1, dtype=np.int64)
    for q in range(r):
        ptr[col[q] + 1] += 1
    for i in range(n):
        ptr[i + 1] += ptr[i]
    fill = ptr[:-1].copy()
    s_col = np.empty(r, dtype=np.int64)
    s_lo = np.empty(r, dtype=np.int64)
    s_hi = np.empty(r, dtype=np.int64)
    s_owner = np.empty(r, dtype=np.int64)
    for q in range(r):
        p = fill[col[q]]
        fill[col[q]] += 1
        s_col[p], s_lo[p], s_hi[p], s_owner[p] = col[q], lo[q], hi[q], owner[q]
    m_ptr = np.zeros(n + 1, dtype=np.int64)
    m_col = np.empty(r, dtype=np.int64)
    m_lo = np.empty(r, dtype=np.int64)
    m_hi = np.empty(r, dtype=np.int64)
    order = np.empty(r, dtype=np.int64)
    q = 0
    for i in range(n):
        a, b = ptr[i], ptr[i + 1]
        for p in range(a, b):  # insertion sort by first step, stable
            x = p
            while x > a and s_lo[order[x - 1]] > s_lo[p]:
                order[x] = order[x - 1]
                x -= 1
            order[x] = p
        end = np.int64(0)
        for p in range(a, b):
            u = order[p]
            if p > a and s_lo[u] <= end + 1:  # joins the merged run open
                if s_hi[u] > m_hi[q - 1]:
                    m_hi[q - 1] = s_hi[u]
            else:
                m_col[q], m_lo[q], m_hi[q] = i, s_lo[u], s_hi[u]
                q += 1
            if p == a or s_hi[u] > end:
                end = s_hi[u]
        m_ptr[i + 1] = q
    return (
        ptr,
        s_col,
        s_lo,
        s_hi,
        s_owner,
        m_ptr,
        m_col[:q].copy(),
        m_lo[:q].copy(),
        m_hi[:q].copy(),
    )
