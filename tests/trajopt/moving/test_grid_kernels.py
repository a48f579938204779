"""Tests of the (s, t) grid's compiled loops against plain references written out here.

Random runs (nodes, time ranges, movers; some reaching past the grid's last time) are painted
run by run in Python (the least mover index winning a node), and the reachability sweep is
run in full over every grid time, without the early stop at a fixed point, in numpy.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from trajopt.moving._grid_kernels import dense_kernel, sweep_kernel
from trajopt.moving._st_grid import FOREVER, STGrid, reachable


def _random_grid(rng, kk=60, n=40, runs=50):
    col = rng.integers(0, n, runs)
    lo = rng.integers(0, kk, runs)
    hi = lo + rng.integers(0, 15, runs)
    hi = np.where(hi >= kk - 1, FOREVER, hi)
    owner = rng.integers(0, 4, runs)
    s = np.linspace(0.0, 0.02 * (n - 1), n)
    t = np.arange(kk) * 0.05
    return STGrid(s, t, 0.02, 0.05, col, lo, hi, owner), (col, lo, hi, owner)


def _full_sweep(blocked, s, ds, speed, dt, s_up):
    """Every grid time: ``(ok, k, i)`` as :func:`reachable` defines them."""
    kk, n = blocked.shape
    m = int(math.ceil(speed * dt / ds)) + 1
    reach = np.zeros(n, bool)
    reach[0] = not blocked[0, 0]
    if not reach[0]:
        return False, 0, 0
    last = 0
    for k in range(1, kk):
        nxt = np.zeros(n, bool)
        for i in range(n):
            ok = not blocked[k, i] and any(reach[max(i - m, 0) : i + 1])
            if s_up is not None:
                ok = ok and s[i] <= s_up[k] + 0.5 * ds
            nxt[i] = ok
        if not nxt.any():
            return False, k, last
        reach = nxt
        last = int(np.flatnonzero(reach).max())
    return bool(reach[-1]), kk - 1, last


@pytest.mark.parametrize("seed", range(6))
def test_the_dense_grid_paints_every_run_with_the_least_mover(seed):
    rng = np.random.default_rng(seed)
    g, (col, lo, hi, owner) = _random_grid(rng)
    kk, n = g.t.shape[0], g.s.shape[0]
    want_b = np.zeros((kk, n), bool)
    want_w = np.full((kk, n), -1)
    for i, a, b, j in zip(col, lo, hi, owner, strict=True):
        for k in range(a, min(b, kk - 1) + 1):
            want_b[k, i] = True
            want_w[k, i] = j if want_w[k, i] < 0 else min(want_w[k, i], j)
    blocked, who = dense_kernel(kk, n, col, lo, hi, owner)
    assert np.array_equal(blocked, want_b) and np.array_equal(who, want_w)
    assert np.array_equal(g.blocked, want_b) and np.array_equal(g.who, want_w)


@pytest.mark.parametrize("seed", range(12))
def test_the_sweep_gives_the_full_sweeps_answer(seed):
    rng = np.random.default_rng(100 + seed)
    g, _ = _random_grid(rng, runs=int(rng.integers(5, 400)))
    speed = float(rng.choice([0.2, 0.5, 1.0]))
    s_up = None if seed % 2 else np.cumsum(np.full(g.t.shape[0], speed * 0.05 * 0.7))
    want = _full_sweep(g.blocked, g.s, g.ds, speed, g.dt, s_up)
    assert reachable(g, speed, s_up) == want


def test_the_sweep_kernel_stops_where_nothing_is_reachable():
    """A wall over every node from step 5: nothing reachable there, the robot stopped at the
    furthest node it reached by step 4."""
    fb = np.zeros((10, 20), bool)
    fb[5:] = True
    s = np.arange(20) * 0.1
    ok, k, i = sweep_kernel(fb, s, np.zeros(10), False, 0.05, 2, 9)
    assert (ok, k, i) == (False, 5, 8)  # two nodes a step: 2, 4, 6, 8 by step 4
