"""Tests of trajopt.moving: the compiled steps of the rests' shortening, against brute force.

The launches at which a motion's stays near the fine nodes meet their windows
(:func:`blocked_launches`) against a double loop; the times a schedule launched earlier can be
near each node (:func:`pass_band`) against the drives' samples walked one node at a time.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from trajopt.geometry import PolylineCurve
from trajopt.moving._st_search import Piece
from trajopt.moving._tighten import band_samples, blocked_launches, pass_band
from trajopt.robot import Robot
from trajopt.timing import time_parameterize


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


def _band_brute(s, h, latest, t_from):
    """Each node's entry and exit walked sample by sample, schedule by schedule."""
    lo, hi = np.full(s.shape, np.inf), np.full(s.shape, -np.inf)
    for sched in latest:
        rows = []  # (running arc length, time as launched, time back to back)
        top, t = -np.inf, min(t_from, sched[0][0])
        for launch, pc in sched:
            tau, s_pc = band_samples(pc)
            for x, y in zip(tau, s_pc, strict=True):
                top = max(top, y)
                rows.append((top, launch + x, t + x))
            t += pc.duration
        end = sched[-1][0] + sched[-1][1].duration
        for i, node in enumerate(s):
            out = [late for top, late, _ in rows if top >= node + 0.5 * h]
            hi[i] = max(hi[i], out[0] if out else end)
            before = [early for top, _, early in rows if top < node - 0.5 * h]  # a prefix
            lo[i] = min(lo[i], before[-1] if before else min(t_from, sched[0][0]))
    return lo, hi


def _drive(s0, s1):
    """A drive from rest to rest from ``s0`` to ``s1`` (m) along a straight line."""
    robot = Robot(v_max=0.6, a_max=0.6, j_max=2.0)
    traj = time_parameterize(PolylineCurve(np.array([[0.0, 0.0], [s1 - s0, 0.0]])), robot)
    rows = np.column_stack([traj.phase_t, traj.phase_s, traj.phase_v, traj.phase_a, traj.phase_j])
    rows[:, 1] += s0
    return Piece(rows, float(traj.duration), s0, s1)


def test_the_pass_band_equals_the_samples_walked_node_by_node():
    # two schedules (one of two drives with a rest, one whole drive): the band of every
    # node equals, float for float, the sample-by-sample walk of its definition
    first, second, whole = _drive(0.0, 1.2), _drive(1.2, 3.0), _drive(0.0, 3.0)
    latest = [[(1.7, first), (1.7 + first.duration + 0.8, second)], [(3.9, whole)]]
    s = np.linspace(0.0, 3.0, 151)
    h = float(s[1] - s[0])
    shuffled = np.random.default_rng(1).permutation(s)  # nodes out of order, too
    for t_from, nodes in ((0.4, s), (2.5, s), (0.4, shuffled)):
        lo, hi = pass_band(nodes, h, latest, t_from)
        want_lo, want_hi = _band_brute(nodes, h, latest, t_from)
        assert np.array_equal(lo, want_lo) and np.array_equal(hi, want_hi)
        assert np.all(lo <= hi)
