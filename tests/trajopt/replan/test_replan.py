"""Tests of trajopt.replan: re-planning from a moving robot: the state, the C2 splice, map updates.

References: the old trajectory's own samples at the splice (continuity), the B-spline
derivative formulas evaluated independently by ``BSplineCurve`` (start curvature), a
whole-map recomputation (incremental map updates) and the independent KD-tree clearance
of :mod:`trajopt.metrics`.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import astar
import trajopt
from trajopt.analysis.metrics import point_clearance, trajectory_metrics
from trajopt.errors import InvalidInputError, SmoothingError, TimingError
from trajopt.robot._state import State

ROBOT = trajopt.Robot()


def jumps(a: State, b: State) -> dict[str, float]:
    """Absolute differences of two states, per field (heading wrapped)."""
    return {
        "position": math.hypot(a.x - b.x, a.y - b.y),
        "heading": abs(math.remainder(a.theta - b.theta, 2 * math.pi)),
        "kappa": abs(a.kappa - b.kappa),
        "v": abs(a.v - b.v),
        "a": abs(a.a - b.a),
    }


def test_state_validation():
    s = State(1.0, 2.0, 0.5, kappa=-0.2, v=0.3, a=-0.1)
    assert s.position == (1.0, 2.0) and math.isclose(s.omega, -0.06)
    with pytest.raises(InvalidInputError, match="State.x"):
        State(float("nan"), 0.0, 0.0)
    with pytest.raises(InvalidInputError, match=r"State.v must be finite and >= 0"):
        State(0.0, 0.0, 0.0, v=-0.1)
    with pytest.raises(InvalidInputError, match="State.theta must be a number"):
        State(0.0, 0.0, "north")


def test_state_at_is_the_sample(driven):
    _, traj = driven
    for t in (0.0, 1.234, traj.duration / 2, traj.duration):
        s = traj.state_at(t)
        smp = traj.sample(np.array([t]))
        assert (s.x, s.y, s.theta, s.kappa, s.v, s.a) == pytest.approx(
            (smp.x[0], smp.y[0], smp.theta[0], smp.kappa[0], smp.v[0], smp.a[0]), abs=1e-12
        )
    for bad in (-0.1, traj.duration + 0.1, float("nan")):
        with pytest.raises(InvalidInputError, match="t must be"):
            traj.state_at(bad)


@pytest.mark.parametrize("kappa", [-1.5, 0.0, 0.4, 2.0])
def test_start_curvature_is_exact(scene, kappa):
    g = scene.grid
    inflated = astar.inflate(g, ROBOT.radius, metric="square", outside_occupied=True)
    c0, c1 = g.world_to_cell(scene.start), g.world_to_cell(scene.goal("A"))
    path = astar.find_path(inflated, tuple(c0), tuple(c1))
    pts = np.vstack([scene.start, g.cell_to_world(np.asarray(path.cells))[1:-1], scene.goal("A")])
    corridor = trajopt.build_polygon_corridor(g, pts, ROBOT.radius)
    sp = trajopt.Smoother().fit(
        path,
        corridor,
        raw_grid=g,
        radius=ROBOT.radius,
        start=scene.start,
        goal=scene.goal("A"),
        start_heading=0.3,
        start_curvature=kappa,
    )
    assert sp.certificate.ok
    # the curvature from the spline's own derivatives (BSplineCurve), not from the rows
    d1 = sp.curve(np.array([0.0]), 1)[0]
    d2 = sp.curve(np.array([0.0]), 2)[0]
    k0 = (d1[0] * d2[1] - d1[1] * d2[0]) / np.hypot(*d1) ** 3
    assert k0 == pytest.approx(kappa, abs=1e-9)
    assert math.atan2(d1[1], d1[0]) == pytest.approx(0.3, abs=1e-12)
    with pytest.raises(InvalidInputError, match="start_curvature needs start_heading"):
        trajopt.Smoother().fit(path, corridor, start_curvature=kappa)


@pytest.mark.parametrize(("v0", "a0"), [(0.3, 0.2), (0.3, -0.3), (0.45, 0.4), (0.0, 0.3)])
def test_timing_starts_from_a_moving_state(driven, v0, a0):
    _, traj = driven
    timed = trajopt.time_parameterize(traj.path, ROBOT, v_start=v0, a_start=a0)
    s0 = timed.state_at(0.0)
    assert (s0.v, s0.a) == pytest.approx((v0, a0), abs=1e-12)
    assert trajectory_metrics(timed, ROBOT)["within_limits"]
    with pytest.raises(InvalidInputError, match="a_start"):
        trajopt.time_parameterize(traj.path, ROBOT, v_start=v0, a_start=2 * ROBOT.a_max)


def _check_splice(old, new) -> None:
    ts = new.stats["splice_time_s"]
    d = jumps(old.state_at(ts), new.state_at(0.0))
    assert max(d.values()) < 1e-6, d
    # the executed motion: the old trajectory up to the splice, then the new one, both
    # within every limit on dense samples
    assert trajectory_metrics(new, ROBOT)["within_limits"]


@pytest.mark.parametrize("reuse", [True, False])
@pytest.mark.parametrize("t", [0.0, 0.7, 2.0, 4.5, 6.5])
def test_replan_same_goal_splices_c2(driven, t, reuse):
    planner, traj = driven
    new = planner.replan(traj, t, latency=0.05, reuse=reuse)
    assert new.stats["splice_time_s"] == pytest.approx(t + 0.05)
    assert new.stats["replan"] == ("kept" if reuse else "planned: reuse=False")
    _check_splice(traj, new)
    assert new.steps.goal == traj.steps.goal


@settings(max_examples=6, deadline=None)
@given(st.floats(0.0, 1.0))
def test_replan_splice_property(driven, frac):
    planner, traj = driven
    t = frac * (traj.duration - 1.0)
    try:
        new = planner.replan(traj, t, latency=0.0, reuse=False)
    except (SmoothingError, TimingError):  # a typed refusal is allowed, a jump is not
        return
    _check_splice(traj, new)


def test_replan_to_a_new_goal(driven, scene):
    planner, traj = driven
    new = planner.replan(traj, 1.0, goal=scene.goal("B"), latency=0.0)
    _check_splice(traj, new)
    assert new.steps.goal == tuple(scene.goal("B"))


def test_state_above_its_cap_is_refused(scene):
    planner = trajopt.Planner(scene.grid, ROBOT)
    fast_turn = State(scene.start[0], scene.start[1], 0.0, kappa=4.0, v=0.45)
    with pytest.raises(TimingError, match="exceeds the speed cap|above the speed cap"):
        planner.plan(fast_turn, scene.goal("A"))


def test_braking_first_when_the_cap_requires_it():
    from trajopt.geometry._bspline import BSplineCurve, clamped_uniform_knots

    # a 90-degree bend 0.5 m ahead, entered from 0.45 m/s: its cap is far lower
    c = np.array([(0, 0), (0.3, 0), (0.5, 0), (0.6, 0.1), (0.6, 0.3), (0.6, 0.6)], float)
    bend = BSplineCurve(clamped_uniform_knots(len(c), 3), c, 3)
    u = np.linspace(*bend.domain, 2001)
    cap_min = float(np.min(ROBOT.speed_cap(bend.curvature(u))))
    assert cap_min < 0.3
    timed = trajopt.time_parameterize(bend, ROBOT, v_start=0.45, a_start=0.3)
    smp = timed.sample(np.linspace(0.0, timed.duration, 4000))
    assert smp.a[0] == pytest.approx(0.3) and smp.a.min() < 0.0  # it brakes
    assert smp.v.max() > 0.45  # after the positive start acceleration
    assert trajectory_metrics(timed, ROBOT)["within_limits"]


def test_replan_after_a_map_update_that_blocks_the_old_path(scene):
    planner = trajopt.Planner(scene.grid, ROBOT)
    old = planner.plan(scene.start, scene.goal("A"))
    smp = old.sample(np.linspace(0.0, old.duration, 400))
    i = 330  # near the end: there is room to swerve after the splice
    cx, cy = scene.grid.world_to_cell((smp.x[i], smp.y[i]))
    occ = np.array(scene.grid.occupied)
    occ[cy - 2 : cy + 3, cx - 2 : cx + 3] = True
    updated = scene.grid.with_occupied(occ)
    old_xy = np.column_stack([smp.x, smp.y])
    assert point_clearance(old_xy, updated, border_occupied=True).min() < ROBOT.radius
    new = planner.replan(old, 1.0, grid=updated, latency=0.0)
    _check_splice(old, new)
    new_smp = new.sample_uniform(0.005)
    clr = point_clearance(np.column_stack([new_smp.x, new_smp.y]), updated, border_occupied=True)
    assert clr.min() >= ROBOT.radius - 1e-6
    assert new.steps.raw_grid == updated


def test_replan_is_deterministic(scene):
    outs = []
    for _ in range(2):
        planner = trajopt.Planner(scene.grid, ROBOT)
        traj = planner.plan(scene.start, scene.goal("C"))
        new = planner.replan(traj, 2.5, latency=0.1, reuse=False)
        outs.append((np.asarray(new.path.control_points), new.phase_t, new.phase_v))
    for a, b in zip(outs[0], outs[1], strict=True):
        assert np.array_equal(a, b)


def test_bad_replan_inputs(driven, scene):
    planner, traj = driven
    with pytest.raises(InvalidInputError, match="t must be"):
        planner.replan(traj, -1.0)
    with pytest.raises(InvalidInputError, match="past the trajectory's end"):
        planner.replan(traj, traj.duration - 0.01, latency=0.5)
    with pytest.raises(InvalidInputError, match="latency must be finite and >= 0"):
        planner.replan(traj, 1.0, latency=-0.1)
    with pytest.raises(InvalidInputError, match="outside the map"):
        planner.plan(State(-1.0, 0.5, 0.0), scene.goal("A"))
    with pytest.raises(InvalidInputError, match="leave start_heading"):
        planner.plan(State(*scene.start, 0.0), scene.goal("A"), start_heading=0.1)
    loose = trajopt.time_parameterize(traj.path, ROBOT)  # no steps: no goal to keep
    with pytest.raises(InvalidInputError, match="goal is required"):
        planner.replan(loose, 1.0, latency=0.0)


@settings(max_examples=10, deadline=None)
@given(st.integers(0, 2**31 - 1))
def test_incremental_map_update_equals_a_full_recomputation(seed):
    rng = np.random.default_rng(seed)
    grid = astar.OccupancyGrid(rng.random((50, 70)) < 0.05, 0.05, (1.0, -2.0))
    inflation = ("exact", "paper")[seed % 2]
    planner = trajopt.Planner(grid, trajopt.Robot(radius=0.12), inflation=inflation)
    _ = planner.inflated_grid, planner.search_cost
    occ = np.array(grid.occupied)
    x, y = int(rng.integers(0, 70)), int(rng.integers(0, 50))
    occ[max(0, y - 3) : y + 2, max(0, x - 2) : x + 3] = bool(rng.random() < 0.5)
    updated = grid.with_occupied(occ)
    info = planner.update_map(updated)
    full = trajopt.Planner(updated, trajopt.Robot(radius=0.12), inflation=inflation)
    assert np.array_equal(planner.inflated_grid.occupied, full.inflated_grid.occupied)
    assert np.array_equal(planner.search_cost, full.search_cost)
    assert info["reset"] is False
