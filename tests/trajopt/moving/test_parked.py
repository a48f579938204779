"""Tests of trajopt.moving.parked_on_path: the quick proof that a parked mover blocks the path.

Checked against the re-timing's own search (which must find no way either) and against
re-timings written out here: the static plan started after any delay (0-30 s) and played at
any slower pace (half to full speed) meets the mover on 1 ms samples. Movers parked beside the
path, or parked only after the robot can be past them, are not claimed.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import trajopt
import trajopt.moving
from tests.trajopt.moving.reference import Delayed, dense_min
from trajopt.errors import BlockedError


@pytest.fixture(scope="module")
def base(scene):
    return trajopt.Planner(scene.grid, trajopt.Robot()).plan(scene.start, scene.goal("A"))


def test_settle_time():
    m = trajopt.MovingObstacle.from_waypoints(
        [0.0, 2.0, 3.0, 5.0], [(0, 0), (1, 0), (1, 0), (1, 0)], radius=0.1
    )
    assert trajopt.moving.settle_time(m) == 2.0
    still = trajopt.MovingObstacle.from_waypoints([1.0, 4.0], [(1, 0), (1, 0)], radius=0.1)
    assert trajopt.moving.settle_time(still) == -math.inf


@settings(max_examples=12, deadline=None, suppress_health_check=list(HealthCheck))
@given(st.floats(0.1, 0.95), st.floats(-0.5, 0.5), st.floats(0.0, 20.0), st.floats(0.05, 0.3))
def test_a_proof_is_never_wrong(base, frac, side, t_stop, radius):
    smp = base.sample(np.array([frac * base.duration]))
    p = np.array([smp.x[0], smp.y[0]])
    n = np.array([-math.sin(smp.theta[0]), math.cos(smp.theta[0])])
    mover = trajopt.MovingObstacle.from_waypoints(
        [0.0, t_stop + 1e-3], [p + 2.0 * n, p + side * n], radius=radius, name="cart"
    )
    if dense_min(base, [mover], dt=0.05)[0] < -1.0:  # over the robot at t = 0: refused elsewhere
        return
    proof = trajopt.moving.parked_on_path(base, [mover])
    if proof is None:
        return
    assert isinstance(proof, BlockedError) and proof.mover == "cart"
    with pytest.raises(BlockedError):
        trajopt.retime_for_movers(base, [mover])
    for delay in (0.0, 3.0, 10.0, 30.0):
        for pace in (1.0, 0.5):
            assert dense_min(Delayed(base, delay, pace), [mover], dt=5e-3)[0] < 0.0


def test_parked_beside_or_late_is_not_claimed(base):
    smp = base.sample(np.array([0.5 * base.duration]))
    p = np.array([smp.x[0], smp.y[0]])
    n = np.array([-math.sin(smp.theta[0]), math.cos(smp.theta[0])])
    beside = trajopt.MovingObstacle.from_waypoints([0.0], [p + 0.6 * n], radius=0.2)
    assert trajopt.moving.parked_on_path(base, [beside]) is None
    # on the path, but only from a time the robot may be past it (it then stands at the goal)
    late = trajopt.MovingObstacle.from_waypoints(
        [0.0, base.duration + 5.0], [p + 3.0 * n, p], radius=0.2
    )
    assert trajopt.moving.parked_on_path(base, [late]) is None
    early = trajopt.MovingObstacle.from_waypoints([0.0, 1.0], [p + 3.0 * n, p], radius=0.2)
    assert trajopt.moving.parked_on_path(base, [early]).t == 1.0
