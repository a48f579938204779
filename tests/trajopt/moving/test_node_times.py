"""Tests of trajopt.moving: a grid node's forbidden and resting times (compiled).

:func:`column_kernel` must equal :meth:`STGrid.column` (the numpy painting) and the dense grid
:attr:`STGrid.blocked`; :func:`rest_kernel` must equal the running maxima of the arrival and
forbidden steps (the numpy form) and a brute force over every step and every earlier
arrival, on random runs and random arrivals.
"""

from __future__ import annotations

import numpy as np

from trajopt.moving._node_times import column_kernel, rest_kernel
from trajopt.moving._st_grid import FOREVER, STGrid


def _random_grid(rng: np.random.Generator, n: int, kk: int) -> STGrid:
    """Random runs as st_grid makes them: ``0 <= lo <= hi < kk``, ``FOREVER`` at the last step."""
    r = int(rng.integers(0, 4 * n))
    col = rng.integers(0, n, r)
    lo = rng.integers(0, kk, r)
    hi = np.minimum(lo + rng.integers(0, kk // 3 + 1, r), kk - 1)
    hi = np.where(hi >= kk - 1, FOREVER, hi)
    owner = rng.integers(0, 3, r)
    s = np.linspace(0.0, 1.0, n)
    t = np.arange(kk) * 0.1
    return STGrid(s, t, float(s[1]), 0.1, col, lo, hi, owner)


def _rest_numpy(arrive: np.ndarray, blocked: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    idx = np.arange(arrive.shape[0])
    last_arr = np.maximum.accumulate(np.where(arrive, idx, -1))
    last_blk = np.maximum.accumulate(np.where(blocked, idx, -1))
    return (last_arr >= 0) & (last_arr > last_blk), last_arr


def test_column_kernel_equals_the_painting_and_the_dense_grid():
    rng = np.random.default_rng(3)
    for _ in range(60):
        n, kk = int(rng.integers(2, 12)), int(rng.integers(2, 40))
        g = _random_grid(rng, n, kk)
        ptr, _, lo, hi = (np.asarray(x, dtype=np.int64) for x in g.merged)
        for i in range(n):
            col = column_kernel(ptr, lo, hi, kk, i)
            assert col.dtype == np.bool_
            assert np.array_equal(col, g.column(i))
            assert np.array_equal(col, g.blocked[:, i])


def test_rest_kernel_equals_the_numpy_form_and_a_brute_force():
    rng = np.random.default_rng(4)
    for _ in range(200):
        kk = int(rng.integers(1, 30))
        arrive = rng.random(kk) < rng.random()
        blocked = rng.random(kk) < rng.random()
        rest, since = rest_kernel(arrive, blocked)
        ref_rest, ref_since = _rest_numpy(arrive, blocked)
        assert np.array_equal(rest, ref_rest)
        assert np.array_equal(since, ref_since)
        for k in range(kk):  # brute force: the latest arrival a <= k, free on a..k
            arrivals = [a for a in range(k + 1) if arrive[a]]
            a = arrivals[-1] if arrivals else -1
            assert since[k] == a
            assert rest[k] == (a >= 0 and not blocked[a : k + 1].any())
