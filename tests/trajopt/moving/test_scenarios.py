"""Tests of trajopt.moving on scenarios: Planner.plan with movers, judged by independent checks.

Each kind of :mod:`benchmarks.moving_cases` on the paper scene: the returned plan passes
:func:`tests.trajopt.moving.reference.check_trajectory` (1 ms samples over the trajectory and
the standing at the goal, plus the Lipschitz bound between them, the map's squares
included), or the planner raises :class:`BlockedError` where
:func:`benchmarks.moving_witness.path_blocked` proves that no motion along the path exists; a
mover stopping on the path blocks it (proven) and is driven round.
Random movers on random small grids never give a violation, only typed errors; a mover that
exactly grazes the planned motion is touched, one a millimetre closer is avoided.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import astar
import trajopt
from benchmarks.moving_cases import KINDS, make_movers
from benchmarks.moving_witness import path_blocked
from tests.trajopt.moving.reference import brute_min, check_trajectory
from trajopt.errors import BlockedError, TrajoptError

MARGIN = 0.05


@pytest.fixture(scope="module")
def paper(scene):
    planner = trajopt.Planner(scene.grid, trajopt.Robot())
    return planner, planner.plan(scene.start, scene.goal("A"))


@pytest.mark.parametrize("kind", [*KINDS, "mixed"])
def test_each_kind_is_certified_or_proven_blocked(scene, paper, kind):
    planner, static = paper
    movers = make_movers(static, kind, 2, seed=KINDS.index(kind) if kind in KINDS else 9)
    assert len(movers) == 2
    _certified_or_proven_blocked(scene, planner, static, movers)


def _certified_or_proven_blocked(scene, planner, static, movers):
    """Plan SP -> A with ``movers``: the plan passes the independent check and is no faster
    than the static one, or the refusal is proven by the relaxation along the static path."""
    try:
        out = planner.plan(
            scene.start, scene.goal("A"), moving_obstacles=movers, mover_margin=MARGIN
        )
    except BlockedError:
        assert path_blocked(static, movers, MARGIN, ds=0.02, dt=0.02)
        return
    chk = check_trajectory(out, movers, margin=MARGIN, grid=scene.grid)
    assert chk.ok, chk
    assert out.duration >= static.duration - 1e-9


@pytest.mark.parametrize("kind", ["crossing", "head-on", "overtaking", "stopping"])
def test_carts_of_each_kind_are_certified_or_proven_blocked(scene, paper, kind):
    """Cart-shaped movers (convex rectangles turning with their motion): the plan passes the
    independent check, written with its own point-to-polygon distance, or the refusal is
    proven by the relaxation."""
    planner, static = paper
    movers = make_movers(static, kind, 2, seed=20 + KINDS.index(kind), shape="polygon")
    assert len(movers) == 2 and all(m.vertices is not None for m in movers)
    assert brute_min(static, movers, margin=MARGIN) < 0.0  # the static plan meets a cart
    _certified_or_proven_blocked(scene, planner, static, movers)


def test_a_mover_stopping_on_the_path_is_proven_blocked_and_driven_round(scene, paper):
    planner, static = paper
    movers = make_movers(static, "stopping", 1, seed=1)
    with pytest.raises(BlockedError, match="'stopping-0'"):
        trajopt.retime_for_movers(static, movers, margin=MARGIN)
    assert path_blocked(static, movers, MARGIN, ds=0.02, dt=0.02)
    out = planner.plan(scene.start, scene.goal("A"), moving_obstacles=movers, mover_margin=MARGIN)
    assert out.stats["moving"]["route"] in ("rerouted", "waited")
    chk = check_trajectory(out, movers, margin=MARGIN, grid=scene.grid)
    assert chk.ok, chk


def _room(seed: int) -> astar.OccupancyGrid:
    """A 4 x 3 m room of 10 cm cells with two random blocks, seeded."""
    rng = np.random.default_rng(seed)
    occ = np.zeros((30, 40), bool)
    occ[[0, -1], :] = True
    occ[:, [0, -1]] = True
    for _ in range(2):
        x, y = rng.integers(8, 30), rng.integers(4, 22)
        occ[y : y + rng.integers(2, 6), x : x + rng.integers(2, 6)] = True
    occ[:, :7] &= False
    occ[[0, -1], :7] = True
    occ[:, 0] = True
    return astar.OccupancyGrid(occ, 0.1)


@settings(max_examples=10, deadline=None, suppress_health_check=list(HealthCheck))
@given(
    st.integers(0, 10_000),
    st.lists(
        st.tuples(
            st.floats(0.05, 0.95),
            st.floats(-1.5, 1.5),
            st.floats(-math.pi, math.pi),
            st.floats(0.3, 1.5),
            st.floats(0.05, 0.4),
            st.floats(1.5, 5.0),
            st.sampled_from([0.0, 0.0, 0.02]),
        ),
        min_size=1,
        max_size=4,
    ),
)
def test_random_movers_never_give_a_violation(seed, specs):
    """Movers crossing the static plan at a random point near the time the robot is there,
    from any direction, going on for 1.5-5 m past it, then standing; some of them growing."""
    grid = _room(seed)
    planner = trajopt.Planner(grid, trajopt.Robot())
    try:
        static = planner.plan((0.35, 1.5), (3.5, 1.5))
    except TrajoptError:
        return
    movers = []
    for i, (frac, off, ang, speed, radius, on, growth) in enumerate(specs):
        t_c = frac * static.duration
        smp = static.sample(np.array([t_c]))
        v = speed * np.array([math.cos(ang), math.sin(ang)])
        t_m = max(t_c + off, 0.0)
        start = np.array([smp.x[0], smp.y[0]]) - t_m * v
        # not on the robot at t = 0 (that is refused, tested elsewhere)
        assume(math.dist(start, (0.35, 1.5)) > static.robot.radius + radius + MARGIN + 0.05)
        movers.append(
            trajopt.MovingObstacle.constant_velocity(
                start, v, radius=radius, horizon=t_m + on / speed, growth=growth, name=f"m{i}"
            )
        )
    try:
        out = planner.plan((0.35, 1.5), (3.5, 1.5), moving_obstacles=movers, mover_margin=MARGIN)
    except TrajoptError:
        return  # typed: blocked
    chk = check_trajectory(out, movers, margin=MARGIN, grid=grid)
    assert chk.ok, chk


@pytest.mark.parametrize("closer", [0.0, 1e-3])
def test_a_crossing_mover_grazing_the_motion(scene, paper, closer):
    """A mover crossing ahead of the robot whose closest approach to the planned motion is
    exactly the limit: the plan stays as it is; a millimetre closer: never that plan."""
    planner, static = paper
    t_c = 0.5 * static.duration
    smp = static.sample(np.array([t_c]))
    p = np.array([smp.x[0], smp.y[0]])
    ahead = np.array([math.cos(smp.theta[0]), math.sin(smp.theta[0])])
    normal = np.array([-ahead[1], ahead[0]])
    # crossing 0.7 m ahead of where the robot is at t_c, at 0.4 m/s, radius 0 for now
    centre = p + 0.7 * ahead
    probe = trajopt.MovingObstacle.from_waypoints(
        [t_c - 5.0, t_c + 5.0], [centre - 2.0 * normal, centre + 2.0 * normal], radius=0.0
    )
    gap = brute_min(static, [probe], margin=MARGIN)  # distance - robot radius - margin
    assert gap > 0.1
    radius = gap + closer
    mover = trajopt.MovingObstacle.from_waypoints(
        probe.times, probe.positions, radius=radius, name="grazer"
    )
    assert brute_min(static, [mover], margin=MARGIN) == pytest.approx(-closer, abs=1e-7)
    # the independent check agrees on the static plan: touching passes, closer is caught
    assert check_trajectory(static, [mover], margin=MARGIN).ok == (closer == 0.0)
    if closer == 0.0:
        out = planner.plan(
            scene.start, scene.goal("A"), moving_obstacles=[mover], mover_margin=MARGIN
        )
        assert out.duration == static.duration
        assert check_trajectory(out, [mover], margin=MARGIN, grid=scene.grid).ok
        return
    try:
        out = planner.plan(
            scene.start, scene.goal("A"), moving_obstacles=[mover], mover_margin=MARGIN
        )
    except BlockedError:
        assert path_blocked(static, [mover], MARGIN, ds=0.02, dt=0.02)
        return
    assert out.duration > static.duration
    chk = check_trajectory(out, [mover], margin=MARGIN, grid=scene.grid)
    assert chk.ok and chk.mover_slack >= -1e-6
    # the relaxation behind path_blocked lets a certified motion along the path through
    assert not path_blocked(static, [mover], MARGIN, ds=0.02, dt=0.02)


@settings(max_examples=15, deadline=None, suppress_health_check=list(HealthCheck))
@given(
    st.floats(0.0, 1.0),
    st.floats(-math.pi, math.pi),
    st.floats(0.3, 1.5),
    st.floats(-0.3, 0.3),
    st.sampled_from([0.0, 0.03]),
)
def test_the_check_agrees_with_the_brute_force(paper, frac, angle, speed, miss, growth):
    """The independent check against the brute force of the reference (10 ms samples and a
    bounded minimisation round every local minimum) on the static plan and a straight mover."""
    _, static = paper
    t_c = frac * static.duration
    smp = static.sample(np.array([t_c]))
    v = speed * np.array([math.cos(angle), math.sin(angle)])
    p = np.array([smp.x[0], smp.y[0]]) + miss * np.array([-v[1], v[0]]) / speed
    t0 = max(t_c - 4.0, 0.0)
    mover = trajopt.MovingObstacle.from_waypoints(
        [t0, t_c + 4.0], [p - (t_c - t0) * v, p + 4.0 * v], radius=0.1, growth=growth
    )
    chk = check_trajectory(static, [mover], margin=MARGIN)
    truth = brute_min(static, [mover], margin=MARGIN)
    assert chk.mover_slack >= truth - 1e-9  # samples never see closer than the minimum
    if chk.ok:
        assert truth >= -1e-6
    if truth < -1e-5:
        assert not chk.ok  # a sample below, or a bound that cannot be closed
    if truth > 1e-5:
        assert chk.ok
