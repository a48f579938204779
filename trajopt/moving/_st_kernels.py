"""The compiled kernels of the ``(s, t)`` search: a drive's blocked starts and a stop's arrivals.

A non-decreasing motion along the path (a drive) is at node ``i0 + i`` exactly at the steps
``first[i]..last[i]`` after its start (:func:`._st_grid.visits`); a forbidden run
``[lo, hi]`` of that node (the grid's merged runs, :attr:`._st_grid.STGrid.merged`) then
blocks the starts ``lo - last[i]..hi - first[i]``. :func:`blocked_starts_kernel` paints
those ranges for one drive (a difference array, then its running sum);
:func:`arrive_kernel` does it for every drive of a batch from one stop and sets, where the
robot rests at the stop at ``t_k``, the drive is not blocked there and its stop has no
arrival at ``t_(k + n)`` yet, that arrival and its parent (the dynamic programme of
:func:`._st_search.search`). Integer arithmetic only: the same answers as the numpy forms
(:meth:`._st_grid.STGrid.blocked_starts_many`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from trajopt.kernel_cache import watch_compiles

watch_compiles()  # a first compilation logs one notice (trajopt.kernel_cache)


@njit(cache=True)
def _paint(ptr, m_lo, m_hi, i0, first, last, diff):  # pragma: no cover - compiled
    kk = diff.shape[0] - 1
    diff[:] = 0
    for i in range(first.shape[0]):
        f, la = first[i], last[i]
        if f > la:  # a node passed between grid steps
            continue
        node = i0 + i
        for r in range(ptr[node], ptr[node + 1]):
            lo = max(m_lo[r] - la, 0)
            hi = min(m_hi[r] - f, kk - 1)
            if lo <= hi:
                diff[lo] += 1
                diff[hi + 1] -= 1


@njit(cache=True)
def blocked_starts_kernel(ptr, m_lo, m_hi, kk, i0, first, last):  # pragma: no cover - compiled
    """Return ``bad`` (bool, shape (kk,)): the drive of visits ``(i0, first, last)`` leaving at step ``k`` meets a run.

    Parameters
    ----------
    ptr, m_lo, m_hi : ndarray of int64
        The grid's merged runs (``ptr`` (n + 1,) per node; ``m_lo``, ``m_hi`` (q,) steps).
    kk : int
        Grid times.
    i0 : int
        The drive's first node.
    first, last : ndarray of int64, shape (m,)
        The steps the drive is at node ``i0 + i`` (empty when ``first > last``).
    """
    diff = np.zeros(kk + 1, dtype=np.int64)
    _paint(ptr, m_lo, m_hi, i0, first, last, diff)
    bad = np.zeros(kk, dtype=np.bool_)
    run = 0
    for k in range(kk):
        run += diff[k]
        bad[k] = run > 0
    return bad


@njit(cache=True)
def arrive_kernel(
    ptr, m_lo, m_hi, rest, i0s, base, size, first, last, ns, vs, w, p0, arrivals, parent
):  # pragma: no cover - compiled
    """Set the arrivals of a batch of drives from stop ``w`` (in place).

    Parameters
    ----------
    ptr, m_lo, m_hi : ndarray of int64
        The grid's merged runs.
    rest : ndarray of bool, shape (kk,)
        The robot rests at stop ``w`` at step ``k`` (and may leave then).
    i0s, base, size : ndarray of int64, shape (d,)
        Drive ``j``'s first node and its visits' slice ``base[j]:base[j] + size[j]`` of
        ``first`` and ``last`` (int64).
    ns, vs : ndarray of int64, shape (d,)
        Drive ``j`` takes ``ns[j]`` steps and ends at stop ``vs[j]`` (distinct stops).
    w, p0 : int
        The stop left; drive ``j``'s index in the search's list of drives is ``p0 + j``.
    arrivals : ndarray of bool, shape (stops, kk)
        Set where a drive arrives first.
    parent : ndarray of int64, shape (3, stops, kk)
        The stop left, the step left and the drive's index of each arrival set.
    """
    kk = rest.shape[0]
    diff = np.zeros(kk + 1, dtype=np.int64)
    for j in range(i0s.shape[0]):
        b = base[j]
        _paint(ptr, m_lo, m_hi, i0s[j], first[b : b + size[j]], last[b : b + size[j]], diff)
        n, v = ns[j], vs[j]
        run = 0
        for k in range(kk - n if kk > n else 0):
            run += diff[k]
            if run <= 0 and rest[k] and not arrivals[v, k + n]:
                arrivals[v, k + n] = True
                parent[0, v, k + n] = w
                parent[1, v, k + n] = k
                parent[2, v, k + n] = p0 + j


@njit(cache=True)
def drive_nodes_kernel(rows, duration, s0, s1, dt, ds, n_nodes, never):  # pragma: no cover
    """Return a drive's node at each grid step and its visits ``(idx, first, last)``.

    Parameters
    ----------
    rows : ndarray, shape (p, 5)
        The drive's phases ``(t, s, v, a, j)`` from its start (s, m, m/s, m/s², m/s³).
    duration, s0, s1 : float
        Its duration (s) and ends (m).
    dt, ds : float
        The grid's spacings (s, m).
    n_nodes : int
        The grid's nodes.
    never : int
        The step of a node passed between grid steps (``first = never``, ``last = -never``).

    Returns
    -------
    idx : ndarray of int64, shape (m + 1,)
        The nearest node at steps ``0..m``, ``m = ceil(duration / dt - 1e-9)`` (clipped to
        the drive's end: :meth:`._st_search.Piece.s_at`).
    first, last : ndarray of int64, shape (idx[-1] - idx[0] + 1,)
        The steps the drive is at node ``idx[0] + i``.
    """
    m = int(np.ceil(duration / dt - 1e-9))
    idx = np.empty(m + 1, dtype=np.int64)
    p = rows.shape[0]
    r = 0
    for j in range(m + 1):
        tt = min(max(j * dt, 0.0), duration)
        while r + 1 < p and rows[r + 1, 0] <= tt:
            r += 1
        if tt >= duration:
            s = s1
        else:
            tau = tt - rows[r, 0]
            s = rows[r, 1] + tau * (rows[r, 2] + tau * (0.5 * rows[r, 3] + tau * rows[r, 4] / 6.0))
            s = min(max(s, s0), s1)
        i = np.rint(s / ds)
        idx[j] = int(min(max(i, 0.0), n_nodes - 1.0))
    i0 = idx[0]
    size = idx[m] - i0 + 1
    first = np.full(size, never, dtype=np.int64)
    last = np.full(size, -never, dtype=np.int64)
    for j in range(m + 1):
        q = idx[j] - i0
        if first[q] == never:
            first[q] = j
        last[q] = j
    return idx, first, last
