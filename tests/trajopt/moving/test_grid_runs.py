"""Tests of trajopt.moving: the grid's runs grouped by node and merged per node (compiled).

:func:`runs_kernel` must give the arrays of the numpy form it replaced (a stable argsort by
node; a stable argsort by node and first step, the running end and ``maximum.reduceat``),
and its merged runs must paint exactly the steps the runs paint one by one (brute force),
disjoint and not touching, on random runs with many overlaps and ties.
"""

from __future__ import annotations

import numpy as np

from trajopt.moving._grid_runs import runs_kernel
from trajopt.moving._st_grid import FOREVER


def _numpy_form(n, kk, col, lo, hi, owner):
    order = np.argsort(col, kind="stable")
    lo, hi, owner = lo[order], hi[order], owner[order]
    counts = np.bincount(col, minlength=n)
    ptr = np.concatenate([[0], np.cumsum(counts)])
    col = np.repeat(np.arange(n), counts)
    order = np.argsort(col * (kk + 1) + lo, kind="stable")
    c, m_lo, m_hi = col[order], lo[order], hi[order]
    top = np.int64(FOREVER)
    ends = np.maximum.accumulate(c * (2 * top) + np.minimum(m_hi, top)) - c * (2 * top)
    new = np.ones(c.shape[0], dtype=bool)
    new[1:] = (c[1:] != c[:-1]) | (m_lo[1:] > ends[:-1] + 1)
    first = np.flatnonzero(new)
    m_hi = np.maximum.reduceat(m_hi, first) if first.size else m_hi[first]
    c, m_lo = c[first], m_lo[first]
    m_ptr = np.concatenate([[0], np.cumsum(np.bincount(c, minlength=n))])
    return ptr, col, lo, hi, owner, m_ptr, c, m_lo, m_hi


def _random_runs(rng, n, kk):
    r = int(rng.integers(0, 5 * n))
    col = rng.integers(0, n, r)
    lo = rng.integers(0, kk, r)
    hi = np.minimum(lo + rng.integers(0, kk // 2 + 1, r), kk - 1)
    hi = np.where(hi >= kk - 1, FOREVER, hi)
    owner = rng.integers(0, 4, r)
    return col, lo, hi, owner


def test_runs_kernel_equals_the_numpy_form():
    rng = np.random.default_rng(11)
    for _ in range(300):
        n, kk = int(rng.integers(2, 15)), int(rng.integers(2, 30))
        runs = _random_runs(rng, n, kk)
        got = runs_kernel(n, *runs)
        want = _numpy_form(n, kk, *runs)
        for g, w in zip(got, want, strict=True):
            assert g.dtype == np.int64
            assert np.array_equal(g, w)


def test_merged_runs_paint_the_steps_of_the_runs():
    rng = np.random.default_rng(12)
    for _ in range(300):
        n, kk = int(rng.integers(2, 10)), int(rng.integers(2, 25))
        col, lo, hi, owner = _random_runs(rng, n, kk)
        ptr, s_col, s_lo, s_hi, s_owner, m_ptr, m_col, m_lo, m_hi = runs_kernel(
            n, col, lo, hi, owner
        )
        # grouped: each node's runs, in the order given
        for i in range(n):
            mine = np.flatnonzero(col == i)
            sl = slice(ptr[i], ptr[i + 1])
            assert np.array_equal(s_lo[sl], lo[mine]) and np.array_equal(s_hi[sl], hi[mine])
            assert np.array_equal(s_owner[sl], owner[mine]) and np.all(s_col[sl] == i)
        # merged: the same painted steps (FOREVER painted to the end), disjoint, not touching
        for i in range(n):
            want = np.zeros(kk + 1, dtype=bool)
            for q in np.flatnonzero(col == i):
                want[lo[q] : min(hi[q], kk) + 1] = True
            got = np.zeros(kk + 1, dtype=bool)
            sl = slice(m_ptr[i], m_ptr[i + 1])
            for a, b in zip(m_lo[sl], m_hi[sl], strict=True):
                assert not got[a : min(b, kk) + 1].any()
                got[a : min(b, kk) + 1] = True
            assert np.array_equal(got, want)
            assert np.all(m_col[sl] == i)
            assert np.all(m_lo[sl][1:] > m_hi[sl][:-1] + 1)
