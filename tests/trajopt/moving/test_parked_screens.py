"""Tests of trajopt.moving: the all-movers screens of the quick proofs (trajopt.moving.parked_on_path, over_start,
meets_head_on) and the kept reach bound from rest.

Each against a brute force written here: every mover, every path point at the proof's spacing,
the distances from tests/trajopt/moving/reference.py (written from the waypoints), without the
screens that leave out the far movers; random movers (discs and rectangles, growing or not,
parked at random times on, beside or far from the path, walking back along it) among others.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import trajopt
import trajopt.moving
from tests.trajopt.moving.reference import slack_at
from trajopt.moving._no_way_past import HEAD_ON_DS, HEAD_ON_DT, HEAD_ON_RUN
from trajopt.moving._parked import PARKED_DS
from trajopt.moving._reach_steps import reach_from_rest
from trajopt.moving._st_grid import reach_bound


@pytest.fixture(scope="module")
def base(scene):
    return trajopt.Planner(scene.grid, trajopt.Robot()).plan(scene.start, scene.goal("A"))


def _at(base, s):
    """Path points (m, shape (n, 2)) at arc lengths ``s`` (m)."""
    return np.asarray(base.path(base.path.u_at_s(s)), dtype=float).reshape(-1, 2)


def _movers(base, rng, n=10):
    """Random movers about the path: parked on it, beside it, far off, walking back along it."""
    out = []
    for j in range(n):
        kind = rng.integers(4)
        s_at = rng.uniform(0.0, base.length)
        p = _at(base, np.array([s_at]))[0]
        off = rng.normal(size=2) * (0.3 if kind < 2 else 4.0)
        t_stop = float(rng.uniform(0.0, 25.0))
        rect = None
        if rng.random() < 0.5:
            a, b = rng.uniform(0.05, 0.4, 2)
            rect = [(-a, -b), (a, -b), (a, b), (-a, b)]
        growth = float(rng.choice([0.0, 0.02]))
        if kind == 3:  # walks back along the path towards its start
            s = np.linspace(s_at, 0.0, 6)
            times = np.linspace(0.0, t_stop + 1.0, 6)
            pos = _at(base, s) + off * 0.05
        else:
            times, pos = [0.0, t_stop + 1e-3], [p + rng.normal(size=2) * 3.0, p + off]
        out.append(
            trajopt.MovingObstacle.from_waypoints(
                times,
                pos,
                radius=float(rng.uniform(0.02, 0.3)),
                headings=rng.uniform(-3, 3, len(times)),
                growth=growth,
                vertices=rect,
                name=f"m{j}",
            )
        )
    return out


def test_reach_from_rest_equals_reach_bound():
    rng = np.random.default_rng(3)
    for i in range(200):
        v, a, j = (0.5, 1.0, 5.0) if i % 2 else tuple(rng.uniform([0.1, 0.1, 0.5], [2, 3, 20]))
        t = rng.uniform(0.0, rng.uniform(0.0, 30.0), rng.integers(1, 12))
        on_step = rng.random(t.shape) < 0.3
        t[on_step] = rng.integers(0, 30000, t.shape)[on_step] * 1e-3
        t[rng.random(t.shape) < 0.1] = 0.0
        np.testing.assert_array_equal(reach_from_rest(t, v, a, j), reach_bound(t, v, a, j))


def _parked_brute(base, movers, margin):
    robot = base.robot
    n = max(2, int(np.ceil(base.length / PARKED_DS)) + 1)
    s = np.linspace(0.0, base.length, n)
    p = _at(base, s)
    for m in movers:
        t_stop = max(trajopt.moving.settle_time(m), 0.0)
        reach = float(reach_bound(np.array([t_stop]), robot.v_max, robot.a_max, robot.j_max)[0])
        slack = slack_at(p, m, t_stop, robot.inscribed_radius + margin)
        if np.any((slack < 0.0) & (s > reach)):
            return m.name, t_stop
    return None


@pytest.mark.parametrize("seed", range(4))
def test_parked_on_path_equals_every_mover_at_every_point(base, seed):
    rng = np.random.default_rng(seed)
    claims = 0
    for i in range(12):
        movers = _movers(base, rng, n=2 if i % 3 == 0 else 10)  # few: read one by one
        margin = float(rng.choice([0.0, 0.05]))
        proof = trajopt.moving.parked_on_path(base, movers, margin)
        want = _parked_brute(base, movers, margin)
        assert (None if proof is None else (proof.mover, proof.t)) == want
        claims += want is not None
    assert 0 < claims < 12  # both verdicts seen


@pytest.mark.parametrize("seed", range(3))
def test_over_start_equals_every_mover(base, seed):
    rng = np.random.default_rng(10 + seed)
    start = _at(base, np.zeros(1))[0]
    seen = set()
    for i in range(20):
        movers = _movers(base, rng, n=1 if i % 2 else 6)
        # one more mover just inside or just outside the limit (1 mm)
        limit = float(rng.uniform(0.1, 0.4))
        inside = bool(rng.random() < 0.5)
        d = limit + 0.1 + (-1e-3 if inside else 1e-3)
        movers.append(trajopt.MovingObstacle.from_waypoints([0.0], [start + (d, 0.0)], radius=0.1))
        want = any(bool(slack_at(start[None], m, 0.0, limit)[0] < 0.0) for m in movers)
        assert trajopt.moving.over_start(start, movers, limit) == want
        assert want or not inside
        seen.add(want)
    assert seen == {True, False}


def _head_on_brute(base, movers, margin):
    s = np.linspace(0.0, base.length, int(math.ceil(base.length / HEAD_ON_DS)) + 1)
    pts = _at(base, s)
    smp = base.sample(np.zeros(1))
    p0 = pts[0]
    ahead = np.array([math.cos(smp.theta[0]), math.sin(smp.theta[0])])
    limit = base.robot.inscribed_radius + margin + 0.5 * HEAD_ON_DS
    for m in movers:  # every mover, no screen on its track
        reach = np.max(np.hypot(*m.shape_vertices.T)) + m.radius + m.growth * max(m.t_last, 0)
        t_end = max(m.t_last, 0.0)
        t = np.append(np.arange(0.0, t_end, HEAD_ON_DT), t_end)
        p = np.stack([np.interp(t, m.times, m.positions[:, i]) for i in (0, 1)], axis=-1)
        v = np.diff(p, axis=0)
        close = np.hypot(*(p[1:] - p0).T) <= limit + reach + HEAD_ON_RUN
        if not np.any(close & (v @ ahead < -0.5 * np.hypot(*v.T))):
            continue
        d = np.hypot(*(p[:, None, :] - pts[None]).transpose(2, 0, 1))
        near = d.min(axis=1) <= limit + reach
        sn = s[np.argmin(d, axis=1)[near]]
        if sn.shape[0] >= 2:
            back = np.maximum.accumulate(sn)[:-1] - sn[1:]
            if np.any((back >= HEAD_ON_RUN) & (sn[1:] <= HEAD_ON_RUN)):
                return True
    return False


def test_meets_head_on_equals_every_mover(base):
    rng = np.random.default_rng(7)
    seen = set()
    for i in range(30):
        movers = _movers(base, rng, n=2 if i % 2 else 6)
        want = _head_on_brute(base, movers, 0.0)
        assert trajopt.moving.meets_head_on(base, movers, 0.0) == want
        seen.add(want)
    assert seen == {True, False}


def test_span_discs_hold_the_path(base):
    from trajopt.moving._parked import path_curves, span_discs

    cen, rad = span_discs(path_curves(base))
    lo, hi = base.path.domain
    p = np.asarray(base.path(np.linspace(lo, hi, 20001)), dtype=float)
    d = np.hypot(p[:, None, 0] - cen[None, :, 0], p[:, None, 1] - cen[None, :, 1]) - rad[None]
    assert np.all(np.min(d, axis=1) <= 1e-12)  # every sample inside some disc
    assert np.max(rad) < 0.5 * base.length  # and the discs are local, not one about it all


def test_mover_places_read_one_by_one_or_from_the_table_are_numpy_interps(base):
    from trajopt.moving._mover_places import MoverPlaces
    from trajopt.moving._mover_segments import mover_table

    rng = np.random.default_rng(5)
    for n in (2, 3):  # below TABLE_FROM: read one by one, then from the table once it is kept
        movers = _movers(base, rng, n=n)
        j = np.repeat(np.arange(n), 7)
        t = rng.uniform(-2.0, 40.0, j.shape[0])
        want = np.concatenate([m.position_at(t[j == i]) for i, m in enumerate(movers)])
        one_by_one = MoverPlaces(movers)
        assert one_by_one.table is None
        np.testing.assert_array_equal(one_by_one.at(j, t), want)
        mover_table(movers)
        kept = MoverPlaces(movers)
        assert kept.table is not None
        np.testing.assert_array_equal(kept.at(j, t), want)
        for name in ("reach", "rad0", "grow", "t_last"):
            np.testing.assert_array_equal(getattr(one_by_one, name), getattr(kept, name))
