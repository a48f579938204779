"""Tests of trajopt.moving.no_way_past: the quick proof that no re-timing gets past the movers.

Checked against the re-timing's own search (which must find no way either whenever the proof
claims one is blocked) on random movers crossing the path, and against re-timings written out
here: the static plan started after any delay (0-30 s) and played at a slower pace meets the
mover on 5 ms samples. Movers coming head-on along the path are claimed; a mover that crosses
the path once and leaves is not (a wait lets it pass). The node-by-node sweep
(``reachable_times``) gives exactly the times of a brute-force time-step sweep of the dense grid.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import trajopt
import trajopt.moving
from tests.trajopt.moving.reference import Delayed, dense_min
from trajopt.errors import BlockedError, InvalidInputError

#: A run that lasts (trajopt.moving.STGrid).
FOREVER = 1 << 40


@pytest.fixture(scope="module")
def base(scene):
    return trajopt.Planner(scene.grid, trajopt.Robot()).plan(scene.start, scene.goal("A"))


def _head_on(base, speed, radius=0.2):
    s = np.linspace(0.0, base.length, 60)
    pts = np.asarray(base.path(base.path.u_at_s(s)))[::-1]
    t = (base.length - s[::-1]) / speed
    return trajopt.MovingObstacle.from_waypoints(t, pts, radius=radius, name="walker")


@pytest.mark.parametrize("speed", [0.2, 0.5, 1.5])
def test_head_on_is_claimed_and_the_search_agrees(base, speed):
    mover = _head_on(base, speed)
    proof = trajopt.moving.no_way_past(base, [mover], 0.02)
    assert isinstance(proof, BlockedError) and proof.mover == "walker"
    with pytest.raises(BlockedError):
        trajopt.retime_for_movers(base, [mover], margin=0.02)
    for delay in (0.0, 2.0, 10.0, 30.0):
        for pace in (1.0, 0.5):
            assert dense_min(Delayed(base, delay, pace), [mover], dt=5e-3)[0] < 0.0


def test_a_crossing_mover_that_leaves_is_not_claimed(base):
    smp = base.sample(np.array([0.5 * base.duration]))
    p = np.array([smp.x[0], smp.y[0]])
    n = np.array([-math.sin(smp.theta[0]), math.cos(smp.theta[0])])
    mover = trajopt.MovingObstacle.from_waypoints(
        [0.0, 8.0], [p - 2.0 * n, p + 2.0 * n], radius=0.2, name="crosser"
    )
    assert trajopt.moving.no_way_past(base, [mover]) is None
    trajopt.retime_for_movers(base, [mover])  # a wait lets it pass: no BlockedError


def test_a_claim_is_never_wrong(base):
    # movers on straight runs crossing the path at random places, angles, speeds and times
    rng = np.random.default_rng(7)
    claims = unclaimed = 0
    for _ in range(40):
        smp = base.sample(np.array([rng.uniform(0.05, 1.0) * base.duration]))
        p = np.array([smp.x[0], smp.y[0]])
        angle, run, duration = (
            rng.uniform(0, 2 * math.pi),
            rng.uniform(0.5, 6),
            rng.uniform(0.5, 15),
        )
        when, radius = rng.uniform(), rng.uniform(0.05, 0.4)
        d = np.array([math.cos(angle), math.sin(angle)])
        mover = trajopt.MovingObstacle.from_waypoints(
            [0.0, duration], [p - d * run * when, p + d * run * (1.0 - when)], radius=radius
        )
        try:
            trajopt.retime_for_movers(base, [mover])
            blocked = False
        except InvalidInputError:  # over the robot at t = 0: refused
            continue
        except BlockedError:
            blocked = True
        proof = trajopt.moving.no_way_past(base, [mover])
        if proof is None:
            unclaimed += 1
            continue
        claims += 1
        assert blocked, f"claimed blocked, but a certified re-timing exists: {proof}"
        for delay in (0.0, 3.0, 10.0, 30.0):
            for pace in (1.0, 0.5):
                assert dense_min(Delayed(base, delay, pace), [mover], dt=5e-3)[0] < 0.0
    assert claims >= 5 and unclaimed >= 5, (claims, unclaimed)


def test_a_polygon_head_on_is_claimed(base):
    s = np.linspace(0.0, base.length, 30)
    pts = np.asarray(base.path(base.path.u_at_s(s)))[::-1]
    t = (base.length - s[::-1]) / 0.5
    square = np.array([(-0.15, -0.15), (0.15, -0.15), (0.15, 0.15), (-0.15, 0.15)])
    mover = trajopt.MovingObstacle.from_waypoints(t, pts, radius=0.0, vertices=square, name="box")
    proof = trajopt.moving.no_way_past(base, [mover], ds=0.05, dt=0.1)
    assert isinstance(proof, BlockedError) and proof.mover == "box"
    with pytest.raises(BlockedError):
        trajopt.retime_for_movers(base, [mover])


@pytest.mark.parametrize("seed", range(6))
def test_the_node_sweep_equals_a_time_step_sweep(seed):
    """On random forbidden runs, the times the node sweep gives each node are exactly those of
    a brute-force sweep over the dense grid, time step by time step (the grid's last row
    repeated until nothing changes)."""
    rng = np.random.default_rng(seed)
    n, kk, ds, dt, speed = 40, 60, 0.04, 0.05, 0.5
    r = int(rng.integers(20, 60))
    col = rng.integers(0, n, r)
    lo = rng.integers(0, kk, r)
    hi = np.minimum(lo + rng.integers(0, 15, r), kk - 1)
    hi = np.where(hi >= kk - 1, FOREVER, hi)
    if seed < 3:  # a wall across the path from some time on: often blocked
        col = np.concatenate([col, np.arange(15, 20)])
        lo = np.concatenate([lo, np.full(5, 10 + 5 * seed)])
        hi = np.concatenate([hi, np.full(5, FOREVER)])
    grid = trajopt.moving.STGrid(
        np.arange(n) * ds, np.arange(kk) * dt, ds, dt, col, lo, hi, np.zeros(col.shape[0], int)
    )
    s_up = np.minimum(np.arange(kk) * dt * speed * 1.5, (n - 1) * ds)
    s_up[-1] = (n - 1) * ds
    reach = trajopt.moving.reachable_times(grid, speed, s_up)
    # brute force
    extra = 3 * n
    blocked = np.zeros((kk + extra, n), dtype=bool)
    for c, a, b in zip(col, lo, hi, strict=True):
        blocked[a : (kk + extra if b >= FOREVER else b + 1), c] = True
    cap = np.concatenate([s_up, np.full(extra, s_up[-1])]) + 0.5 * ds
    m = int(np.ceil(speed * dt / ds)) + 1
    now = np.zeros(n, dtype=bool)
    now[0] = not blocked[0, 0]
    seen = [now]
    for k in range(1, kk + extra):
        nxt = np.zeros(n, dtype=bool)
        for j in range(n):
            lo_i = max(0, j - m)
            nxt[j] = (not blocked[k, j]) and j * ds <= cap[k] and bool(now[lo_i : j + 1].any())
        now = nxt
        seen.append(now)
    seen = np.array(seen)  # (kk + extra, n)
    for j in range(n):
        got = np.zeros(kk + extra, dtype=bool)
        for a, b in reach[j]:
            got[a : (kk + extra if b == np.inf else int(b) + 1)] = True
        assert np.array_equal(got, seen[:, j]), j


@pytest.mark.parametrize("speed", [0.2, 0.5, 1.5])
def test_the_head_on_screen_sees_a_walker_along_the_path_and_not_a_crossing(base, speed):
    """``meets_head_on``: a walker that drives the path backwards is seen (whatever its speed);
    one that drives it forwards (behind the robot) or crosses it once is not."""
    assert trajopt.moving.meets_head_on(base, [_head_on(base, speed)], 0.02)
    s = np.linspace(0.0, base.length, 60)
    pts = np.asarray(base.path(base.path.u_at_s(s)))
    follower = trajopt.MovingObstacle.from_waypoints(s / speed + 1.0, pts, radius=0.2)
    assert not trajopt.moving.meets_head_on(base, [follower], 0.02)
    smp = base.sample(np.array([0.5 * base.duration]))
    p = np.array([smp.x[0], smp.y[0]])
    n = np.array([-math.sin(smp.theta[0]), math.cos(smp.theta[0])])
    crosser = trajopt.MovingObstacle.from_waypoints(
        [0.0, 8.0], [p - 2.0 * n, p + 2.0 * n], radius=0.2
    )
    assert not trajopt.moving.meets_head_on(base, [crosser], 0.02)


def test_kept_reach_bound_equals_a_fresh_one():
    """The proof's kept reach bound: bit for bit the bound of the grid's own times, any order."""
    from trajopt.moving._no_way_past import _grid_reach_bound
    from trajopt.moving._st_grid import reach_bound

    for kk in [3, 400, 17, 1200, 2, 401, 5000, 999]:
        for dt, v, a, j in ((0.05, 0.5, 1.0, 5.0), (0.1, 0.7, 0.4, 2.0)):
            got = _grid_reach_bound(kk, dt, v, a, j)
            t = np.arange(kk) * dt
            assert got.shape == (kk,) and not got.flags.writeable
            np.testing.assert_array_equal(got, reach_bound(t, v, a, j))
    # against the limits by hand: at least the left sums of v(t) = min(v_max, a(t) integrated)
    t = np.arange(300) * 0.05
    got = _grid_reach_bound(300, 0.05, 0.5, 1.0, 5.0)
    t1 = 0.2  # a_max / j_max
    v = np.minimum(0.5, np.where(t <= t1, 2.5 * t * t, 0.1 + (t - t1)))
    assert np.all(np.diff(got) >= 0.0)
    assert np.all(got + 1e-12 >= np.concatenate([[0.0], np.cumsum(v[:-1] * 0.05)]))
    assert np.all(got <= 0.5 * t + 1e-3)  # never beyond top speed (plus a 1 ms step)
