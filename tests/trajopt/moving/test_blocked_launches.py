"""Tests of trajopt.moving: the launches at which a motion's stays near the fine nodes meet their windows, against a brute-force loop."""

from __future__ import annotations

import math

import numpy as np
import pytest

from trajopt.moving._tighten import blocked_launches


def _brute(node, a, b, ptr, lo, hi, after):
    out = []
    for j in range(node.shape[0]):
        for r in range(int(ptr[node[j]]), int(ptr[node[j] + 1])):
            if hi[r] - a[j] > after:
                out.append((lo[r] - b[j], hi[r] - a[j], j, r))
    return out


@pytest.mark.parametrize("after", [-math.inf, 0.0, 2.5])
def test_blocked_launches_are_every_stay_against_every_window_of_its_node(after):
    # 40 nodes with 0 to 4 windows each (some lasting: hi = inf), 60 stays (nodes repeated,
    # some without windows): every (stay, window) pair ending after ``after``, in order
    rng = np.random.default_rng(7)
    counts = rng.integers(0, 5, 40)
    ptr = np.concatenate([[0], np.cumsum(counts)])
    lo = rng.uniform(0.0, 8.0, int(ptr[-1]))
    hi = lo + rng.uniform(0.0, 2.0, lo.shape)
    hi[rng.random(hi.shape) < 0.1] = np.inf
    node = rng.integers(0, 40, 60)
    a = rng.uniform(0.0, 5.0, 60)
    b = a + rng.uniform(0.0, 1.0, 60)
    f_lo, f_hi, which, run = blocked_launches(node, a, b, ptr, lo, hi, after)
    want = _brute(node, a, b, ptr, lo, hi, after)
    assert len(want) > 0 and len(want) == f_lo.shape[0]
    assert np.array_equal(f_lo, [w[0] for w in want])
    assert np.array_equal(f_hi, [w[1] for w in want])
    assert np.array_equal(which, [w[2] for w in want])
    assert np.array_equal(run, [w[3] for w in want])
    # the launches of an interval meet the window: at a launch inside, the stay overlaps it
    for x0, x1, j, r in want[:20]:
        if math.isfinite(x1):
            launch = 0.5 * (x0 + x1)
            assert launch + b[j] > lo[r] and launch + a[j] < hi[r]


def test_no_stays_no_launches():
    got = blocked_launches(
        np.zeros(0, dtype=np.int64),
        np.zeros(0),
        np.zeros(0),
        np.array([0, 2]),
        np.ones(2),
        np.ones(2),
    )
    assert all(x.shape == (0,) for x in got)
