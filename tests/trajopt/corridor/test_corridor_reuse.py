"""Tests of trajopt.corridor: a re-plan's polygon corridor keeps the old regions along the path the two share.

References: the exact polygon-to-map distance of :func:`trajopt.geometry._clearance.polygon_clearance`
(separating axes and vertex-edge distances, not the corridor's own certificate kernels) for
every region on the *current* map, point-in-region tests for the chain, the old corridor's
own regions for the kept ones, and the independent KD-tree clearance of
:mod:`trajopt.metrics` for the re-planned trajectory.
"""

from __future__ import annotations

import numpy as np
import pytest

import trajopt
from trajopt.analysis.metrics import point_clearance
from trajopt.corridor import CLEARANCE_TOL_M, build_polygon_corridor
from trajopt.corridor._polygons.reuse import corridor_with_rest, shared_suffix
from trajopt.geometry._clearance import polygon_clearance
from trajopt.replan._keep import remaining_grid_path

ROBOT = trajopt.Robot()


@pytest.fixture(scope="module")
def old(scene):
    """``(planner, trajectory, new_points)``: a plan SP -> B and the path from 1 s on."""
    planner = trajopt.Planner(scene.grid, ROBOT)
    traj = planner.plan(scene.start, scene.goal("B"))
    state = traj.state_at(1.0)
    cell = scene.grid.world_to_cell(state.position)
    path = remaining_grid_path(planner.options, planner.caches, traj.steps, cell)
    centres = np.asarray(scene.grid.cell_to_world(np.asarray(path.cells)), dtype=float)
    points = np.vstack([state.position, centres[1:-1], traj.steps.corridor.input_path[-1]])
    return planner, traj, points


def _check_corridor(cor, points, grid, radius):
    """Every region certified on ``grid`` (independently) and the chain closed."""
    for k, reg in enumerate(cor.regions):
        assert polygon_clearance(reg, grid) >= radius - CLEARANCE_TOL_M, k
        assert np.all(reg.contains(cor.path[k : k + 2], tol=1e-9)), k
    for k in range(len(cor.regions) - 1):  # consecutive regions share their path vertex
        assert cor.regions[k + 1].contains(cor.path[k + 1][None], tol=1e-9)[0], k
    assert np.array_equal(cor.path[0], points[0]) and np.array_equal(cor.path[-1], points[-1])
    assert np.array_equal(cor.input_path, points)
    # each path vertex is its input point, moved by at most a cell's diagonal when centred
    gap = np.hypot(*(cor.path - points[cor.source_index]).T)
    assert gap.max() <= np.sqrt(2.0) * grid.resolution + 1e-12
    assert np.all(np.diff(cor.transitions_m) > 0)


def test_shared_suffix():
    a = np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [3.0, 3.0]])
    b = np.array([[9.0, 9.0], [2.0, 2.0], [3.0, 3.0]])
    assert shared_suffix(a, b) == 2
    assert shared_suffix(a, a) == 4
    assert shared_suffix(a, b[:1]) == 0
    assert shared_suffix(a, np.zeros((0, 2))) == 0


def test_the_old_regions_along_the_shared_rest_are_kept(old, scene):
    planner, traj, points = old
    prev = traj.steps.corridor
    out = corridor_with_rest(scene.grid, points, ROBOT.radius, prev, scene.grid)
    assert out is not None
    cor, kept = out
    assert 1 <= kept < len(cor.regions)
    for a, b in zip(cor.regions[-kept:], prev.regions[-kept:], strict=True):
        assert np.array_equal(a.A, b.A) and np.array_equal(a.b, b.b)
        assert np.array_equal(a.vertices, b.vertices)
    assert np.array_equal(cor.path[-kept - 1 :], prev.path[-kept - 1 :])
    _check_corridor(cor, points, scene.grid, ROBOT.radius)
    # deterministic
    again, kept_again = corridor_with_rest(scene.grid, points, ROBOT.radius, prev, scene.grid)
    assert kept_again == kept
    assert np.array_equal(again.path, cor.path)
    assert np.array_equal(again.transitions_m, cor.transitions_m)


def test_a_region_an_added_cell_comes_near_is_grown_again(old, scene):
    planner, traj, points = old
    prev = traj.steps.corridor
    _, kept = corridor_with_rest(scene.grid, points, ROBOT.radius, prev, scene.grid)
    grid = scene.grid
    occ = np.asarray(grid.occupied)
    free = np.argwhere(~occ)[:, ::-1]  # (ix, iy)
    centres = np.asarray(grid.cell_to_world(free), dtype=float)
    # distance of each free cell's centre to the new path's points and vertices
    near_path = np.min(np.hypot(*(centres[:, None, :] - points[None]).transpose(2, 0, 1)), axis=1)
    m = len(prev.regions)
    for k in range(m - kept, m - 1):  # a kept region, not the last
        reg = prev.regions[k]
        lo, hi = reg.vertices.min(axis=0), reg.vertices.max(axis=0)
        inside = np.all((centres >= lo - ROBOT.radius) & (centres <= hi + ROBOT.radius), axis=1)
        for i in np.nonzero(inside & (near_path > ROBOT.radius + 3 * grid.resolution))[0]:
            o = occ.copy()
            o[free[i, 1], free[i, 0]] = True
            updated = grid.with_occupied(o)
            if polygon_clearance(reg, updated) < ROBOT.radius - CLEARANCE_TOL_M:
                break
        else:
            continue
        break
    else:
        pytest.fail("no free cell that only a kept region comes near")
    out = corridor_with_rest(updated, points, ROBOT.radius, prev, grid)
    assert out is not None
    cor, kept_now = out
    assert kept_now <= m - 1 - k  # region k and all before it are grown again
    _check_corridor(cor, points, updated, ROBOT.radius)


def test_nothing_is_kept_without_a_shared_rest_or_on_another_geometry(old, scene):
    planner, traj, points = old
    prev = traj.steps.corridor
    grid = scene.grid
    assert corridor_with_rest(grid, points, ROBOT.radius + 0.01, prev, grid) is None
    other_goal = points.copy()
    other_goal[-1] += 0.01
    assert corridor_with_rest(grid, other_goal, ROBOT.radius, prev, grid) is None
    bigger = trajopt.scenes.paper().grid
    moved = type(bigger)(np.asarray(bigger.occupied), bigger.resolution, (0.5, 0.0))
    assert corridor_with_rest(moved, points, ROBOT.radius, prev, grid) is None
    # a path that shares only the goal and the cell before it: no region to keep
    two = np.vstack([points[-3] + [0.0, 0.0], points[-2:]])
    assert corridor_with_rest(grid, two, ROBOT.radius, prev, grid) is None


def test_replans_keep_regions_and_stay_clear(scene):
    planner = trajopt.Planner(scene.grid, ROBOT)
    traj = planner.plan(scene.start, scene.goal("B"))
    assert traj.stats["corridor_regions_kept"] == 0
    new = planner.replan(traj, 1.0, latency=0.0, reuse=False)
    assert new.stats["corridor_regions_kept"] == 0  # reuse=False plans everything anew
    same = planner.replan(traj, 1.0, latency=0.0)  # the rest kept: its whole corridor too
    assert same.stats["replan"] == "kept"
    assert same.stats["corridor_regions_kept"] == len(traj.steps.corridor.regions)
    # a block beside the path ahead: the rest is not kept, the regions past the block
    # (along the rest the new path shares) are
    cells = np.asarray(traj.steps.grid_path.cells)
    kept_any = 0
    for frac, d in ((0.5, 10), (0.5, -10), (0.6, -10), (0.6, -8)):
        occ = np.array(scene.grid.occupied)
        ahead = cells[int(frac * len(cells))]
        occ[ahead[1] + d, ahead[0]] = True
        updated = scene.grid.with_occupied(occ)
        planner.update_map(scene.grid)
        new = planner.replan(traj, 1.0, grid=updated, latency=0.0)
        assert new.stats["replan"].startswith("planned")
        kept_any += new.stats["corridor_regions_kept"] > 0
        cor = new.steps.corridor
        for k, reg in enumerate(cor.regions):
            assert polygon_clearance(reg, updated) >= ROBOT.radius - CLEARANCE_TOL_M, k
        smp = new.sample_uniform(0.005)
        clr = point_clearance(np.column_stack([smp.x, smp.y]), updated, border_occupied=True)
        assert clr.min() >= ROBOT.radius - 1e-6
        # the same path's corridor built from scratch has about as many regions
        fresh = build_polygon_corridor(updated, cor.input_path, ROBOT.radius)
        assert abs(len(fresh.regions) - len(cor.regions)) <= 2
    assert kept_any >= 2


def test_the_plan_from_rest_after_braking_keeps_regions_too(scene):
    planner = trajopt.Planner(scene.grid, ROBOT)
    traj = planner.plan(scene.start, scene.goal("C"))
    # a 3 x 3 block on the path 15 cells ahead of the robot at 2 s: no smooth curve leaves
    # the moving state, so the robot brakes, turns and goes along a path that meets the
    # old one again behind the block
    cells = np.asarray(traj.steps.grid_path.cells)
    here = np.asarray(scene.grid.world_to_cell(traj.state_at(2.0).position))
    c = cells[int(np.argmin(np.hypot(*(cells - here).T))) + 15]
    occ = np.array(scene.grid.occupied)
    occ[c[1] - 1 : c[1] + 2, c[0] - 1 : c[0] + 2] = True
    updated = scene.grid.with_occupied(occ)
    for reuse in (True, False):
        planner.update_map(scene.grid)
        new = planner.replan(traj, 2.0, grid=updated, latency=0.0, reuse=reuse)
        assert new.stats["replan"].startswith("braked")
        go = new.pieces[-1]
        assert new.stats["corridor_regions_kept"] == go.stats["corridor_regions_kept"]
        assert (go.stats["corridor_regions_kept"] > 0) == reuse
        for k, reg in enumerate(go.steps.corridor.regions):
            assert polygon_clearance(reg, updated) >= ROBOT.radius - CLEARANCE_TOL_M, k
        smp = new.sample_uniform(0.005)
        clr = point_clearance(np.column_stack([smp.x, smp.y]), updated, border_occupied=True)
        assert clr.min() >= ROBOT.radius - 1e-6
