"""Tests of trajopt.replan: what a re-plan keeps: the exact B-spline tail and the rest of the driven trajectory.

References: scipy's ``BSpline`` (the tail's values and derivatives), scipy's Delaunay
triangulation (the tail's new control points lie in the hull of the cut span's), the old
trajectory's own samples (the kept rest is the same motion), and the independent KD-tree
clearance of :mod:`trajopt.metrics` (the kept rest on an updated map).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import ndimage
from scipy.interpolate import BSpline
from scipy.spatial import Delaunay

import trajopt
from tests.reference import dijkstra_costs, grid_path_cost
from trajopt.analysis.metrics import point_clearance, trajectory_metrics
from trajopt.errors import InvalidInputError
from trajopt.geometry._bspline import BSplineCurve, clamped_uniform_knots

ROBOT = trajopt.Robot()


def _random_curve(k: int, seed: int) -> BSplineCurve:
    rng = np.random.default_rng(seed)
    n = 14
    c = rng.normal(size=(n, 2)) * 0.4 + np.array([30.0, 20.0])  # world-sized coordinates
    return BSplineCurve(clamped_uniform_knots(n, k, (0.0, 2.6)), c, k)


@pytest.mark.parametrize("k", [2, 3, 4, 5])
@pytest.mark.parametrize("where", ["interior", "on a knot", "a hair before a knot", "start"])
def test_tail_is_the_same_curve(k, where):
    curve = _random_curve(k, seed=k)
    knot = float(curve.t[k + 5])
    u0 = {
        "interior": 1.234567,
        "on a knot": knot,
        "a hair before a knot": knot - 1e-10,
        "start": 0.0,
    }[where]
    tail = curve.tail(u0)
    assert tail.domain == (u0, 2.6)
    u = np.linspace(u0, 2.6, 301)
    ref = BSpline(curve.t, curve.c, k)
    for nu in range(k + 1):
        want = ref.derivative(nu)(u) if nu else ref(u)
        scale = max(1.0, float(np.abs(want).max()))
        assert np.abs(tail(u, nu) - want).max() <= 1e-11 * scale, nu
    assert np.abs(tail.c[0] - ref(u0)).max() < 1e-12  # clamped: it starts on C(u0)
    assert tail.curvature(u0) == pytest.approx(curve.curvature(u0), rel=1e-9, abs=1e-9)


@pytest.mark.parametrize("k", [2, 3, 5])
def test_tail_control_points_lie_in_the_cut_span_hull(k):
    curve = _random_curve(k, seed=10 + k)
    u0 = 1.111
    j = int(curve.span_of(u0))
    hull = Delaunay(curve.c[j : j + k + 1])
    tail = curve.tail(u0)
    assert np.all(hull.find_simplex(tail.c[:k], tol=1e-12) >= 0)
    # the rest are the old control points after the span
    assert np.array_equal(tail.c[k:], curve.c[j + k :])


def test_tail_refuses_a_start_outside_the_domain():
    curve = _random_curve(3, seed=0)
    for u0 in (-0.1, 2.6, math.nan):
        with pytest.raises(InvalidInputError, match="u0 must lie in the domain"):
            curve.tail(u0)


def _same_motion(old, new, ts: float) -> None:
    """``new`` is ``old`` from ``ts`` on: on 1 ms samples, every quantity agrees."""
    assert new.duration == pytest.approx(old.duration - ts, abs=1e-12)
    t = np.arange(0.0, new.duration, 1e-3)
    a, b = old.sample(t + ts), new.sample(t)
    for name in ("x", "y", "theta", "kappa", "v", "a"):
        assert np.abs(getattr(a, name) - getattr(b, name)).max() < 1e-9, name
    # the jerk is piecewise constant: only a sample straddling a phase switch may differ
    assert np.mean(a.jerk != b.jerk) < 2e-3
    assert np.allclose(b.s, a.s - a.s[0], atol=1e-9)


@pytest.mark.parametrize("ts", [0.0, 0.4, 1.7, 3.3])
def test_same_goal_same_map_keeps_the_rest(driven, ts):
    planner, traj = driven
    new = planner.replan(traj, ts, latency=0.0)
    assert new.stats["replan"] == "kept"
    assert set(new.stats["stages_s"]) == {"keep", "total"}
    _same_motion(traj, new, ts)
    assert new.steps.smooth_path.certificate.ok
    assert trajectory_metrics(new, ROBOT)["within_limits"]


def test_a_kept_rest_is_kept_again(driven):
    planner, traj = driven
    first = planner.replan(traj, 1.0, latency=0.0)
    second = planner.replan(first, 0.8, latency=0.0)
    assert second.stats["replan"] == "kept"
    _same_motion(traj, second, 1.8)


def test_what_is_not_kept(driven, scene):
    planner, traj = driven
    cases = {
        "new goal": dict(goal=scene.goal("C")),
        "new end speed": dict(v_end=0.1),
        "new goal heading": dict(goal_heading=float(traj.state_at(traj.duration).theta) + 0.3),
        "reuse=False": dict(reuse=False),
    }
    for why, kwargs in cases.items():
        try:
            new = planner.replan(traj, 1.0, latency=0.0, **kwargs)
        except trajopt.TrajoptError:
            continue  # a typed refusal of the new query is fine; being kept is not
        assert new.stats["replan"] == f"planned: {why}"
    # the goal heading it already has is no change
    same = planner.replan(
        traj, 1.0, latency=0.0, goal_heading=float(traj.state_at(traj.duration).theta)
    )
    assert same.stats["replan"] == "kept"


def _edit(grid, cells, value: bool):
    occ = np.array(grid.occupied)
    for cx, cy in cells:
        occ[cy, cx] = value
    return grid.with_occupied(occ)


def test_map_updates_far_from_the_rest_keep_it_near_ones_do_not(scene):
    grid = scene.grid
    planner = trajopt.Planner(grid, ROBOT)
    traj = planner.plan(scene.start, scene.goal("B"))
    smp = traj.sample(np.linspace(0.0, traj.duration, 300))
    on_path = np.asarray(grid.world_to_cell(np.column_stack([smp.x, smp.y])))  # (ix, iy)
    free = np.argwhere(~np.asarray(grid.occupied))[:, ::-1]  # (ix, iy)
    gap = np.min(np.hypot(*(free[:, None, :] - on_path[None, :, :]).transpose(2, 0, 1)), axis=1)
    far = _edit(grid, [tuple(free[int(np.argmax(gap))])], True)
    assert gap.max() * grid.resolution > 1.0  # over a metre from the path
    kept = planner.replan(traj, 1.0, grid=far, latency=0.0)
    assert kept.stats["replan"] == "kept"
    smp = kept.sample_uniform(0.005)
    clr = point_clearance(np.column_stack([smp.x, smp.y]), far, border_occupied=True)
    assert clr.min() >= ROBOT.radius - 1e-6
    assert kept.steps.raw_grid is far

    # a free cell blocked 7-9 cells beside the path ahead (not on it): re-planned
    ahead = np.asarray(grid.world_to_cell(kept.state_at(0.7 * kept.duration).position))
    near_cell = next(
        tuple(ahead + (0, d))
        for d in (7, 8, 9, -7, -8, -9)
        if not far.occupied[ahead[1] + d, ahead[0]]
    )
    near = _edit(far, [near_cell], True)
    new = planner.replan(kept, 0.5, grid=near, latency=0.0)
    assert new.stats["replan"] == "planned: cells blocked near the rest of the path"

    # a raw cell freed inside an obstacle (still inflated) adds nothing: kept
    labels, _ = ndimage.label(np.asarray(near.occupied))
    biggest = np.argwhere(labels == np.argmax(np.bincount(labels.ravel())[1:]) + 1)
    inside = tuple(np.median(biggest, axis=0).astype(int)[::-1])  # (ix, iy) in its middle
    assert near.occupied[inside[1], inside[0]]
    hollow = _edit(near, [inside], False)
    same = planner.replan(new, 0.5, grid=hollow, latency=0.0)
    assert same.stats["replan"] == "kept"
    # a whole obstacle removed opens cells to the search: re-planned
    opened = _edit(hollow, [tuple(c[::-1]) for c in biggest], False)
    again = planner.replan(same, 0.5, grid=opened, latency=0.0)
    assert again.stats["replan"] == "planned: cells freed"


def test_footprint_robots_and_fallbacks_are_planned_anew(scene):
    rect = trajopt.Robot.rectangle(length=0.3, width=0.2)
    planner = trajopt.Planner(scene.grid, rect)
    traj = planner.plan(scene.start, scene.goal("A"))
    new = planner.replan(traj, 1.0, latency=0.0)
    assert new.stats["replan"] == "planned: footprint robot"


def test_a_block_near_the_rest_but_off_its_grid_path_reuses_the_path(scene):
    from trajopt.planning._caches import change_reach

    grid = scene.grid
    planner = trajopt.Planner(grid, ROBOT)
    traj = planner.plan(scene.start, scene.goal("B"))
    old_cells = np.asarray(traj.steps.grid_path.cells)
    _, reach = change_reach(planner, grid.resolution)
    # a free cell just beyond the cost's reach of every path cell, but near the corridor
    free = np.argwhere(~np.asarray(grid.occupied))[:, ::-1]
    cheb = np.max(np.abs(free[:, None, :] - old_cells[None]), axis=2).min(axis=1)
    candidates = free[(cheb > reach + 1) & (cheb <= reach + 3)]
    for cell in candidates:
        updated = _edit(grid, [tuple(cell)], True)
        new = planner.replan(traj, 1.0, grid=updated, latency=0.0)
        planner.update_map(grid)
        if new.stats["replan"] == "planned: cells blocked near the rest of the path":
            break
    else:
        pytest.fail("no candidate cell near the corridor")
    assert new.stats["grid_path"] == "reused"
    cells = np.asarray(new.steps.grid_path.cells)
    # the old path's rest, joined from the new start: and still a least-cost path from its
    # first cell on the updated map (scipy's Dijkstra on the inflated grid)
    k = next(j for j in range(len(cells)) if tuple(cells[j]) in {tuple(c) for c in old_cells})
    rest = cells[k:]
    assert np.array_equal(rest, old_cells[-len(rest) :])
    planner.update_map(updated)
    occ = np.asarray(planner.inflated_grid.occupied)
    ref = dijkstra_costs(occ, tuple(rest[0]), 8, False, planner.search_cost)
    goal = tuple(rest[-1])
    assert grid_path_cost(rest, planner.search_cost) == pytest.approx(
        ref[goal[1], goal[0]], rel=1e-9
    )
    assert new.steps.grid_path.cost == pytest.approx(grid_path_cost(cells, planner.search_cost))
    smp = new.sample_uniform(0.005)
    clr = point_clearance(np.column_stack([smp.x, smp.y]), updated, border_occupied=True)
    assert clr.min() >= ROBOT.radius - 1e-6
    # a block on the path ahead: searched again
    ahead = old_cells[int(0.8 * len(old_cells))]
    blocked = _edit(updated, [tuple(ahead)], True)
    again = planner.replan(traj, 1.0, grid=blocked, latency=0.0)
    assert again.stats["grid_path"] == "searched"


def test_box_corridors_keep_the_rest_too(scene):
    planner = trajopt.Planner(scene.grid, ROBOT, corridor="boxes")
    traj = planner.plan(scene.start, scene.goal("C"))
    assert traj.stats["corridor"] == "boxes"
    new = planner.replan(traj, 2.0, latency=0.0)
    assert new.stats["replan"] == "kept"
    assert new.steps.smooth_path.certificate.ok
    _same_motion(traj, new, 2.0)
