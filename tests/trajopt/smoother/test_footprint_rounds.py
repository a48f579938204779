"""Tests of trajopt.smoother: the footprint in the optimiser: compiled certificate kernels, the SCP rows, whole fits.

References: brute force (minimal arcs of sorted angles, scipy's convex hull, dense poses of
the footprint with exact polygon clearances, a point-sampling collision check), a finite
difference check of the heading linearisation against directly posed corners, and the
classic bound for a rectangle turning a right-angled corner between two halls of width
``a``: it passes when ``L <= 2 (a sqrt(2) - W)`` (length ``L``, width ``W``).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial import ConvexHull

import astar
import trajopt
import trajopt.robot._footprint_kernels as footprint_kernels
from tests.reference import footprint_collides
from trajopt.corridor import build_polygon_corridor
from trajopt.planning._disc import plan_disc
from trajopt.planning._options import PlanRequest
from trajopt.robot._footprint import MAX_ARC_RAD, Footprint, polygons_clearance
from trajopt.smoother import Smoother
from trajopt.smoother._footprint_scp import FootprintSCP, corners_cells
from trajopt.smoother._problem import assemble, build_problem
from trajopt.smoother._qp import solve_qp


# ------------------------------------------------------------------ kernels
@pytest.mark.parametrize("seed", range(8))
def test_cone_is_the_smallest_arc_or_the_circle(seed):
    rng = np.random.default_rng(seed)
    centre = rng.uniform(-math.pi, math.pi)
    width = rng.uniform(0.0, 2.0 * math.pi) if seed % 2 else rng.uniform(0.0, 2.5)
    ang = centre + rng.uniform(-0.5, 0.5, size=6) * width
    d = np.column_stack([np.cos(ang), np.sin(ang)]) * rng.uniform(0.5, 2.0, size=(6, 1))
    lo, hi = footprint_kernels.cone(d)
    a = np.sort(np.remainder(ang, 2 * math.pi))
    gaps = np.diff(np.concatenate([a, [a[0] + 2 * math.pi]]))
    smallest = 2 * math.pi - gaps.max()  # the smallest arc holding every direction
    if smallest >= math.pi:
        assert hi - lo == pytest.approx(2 * math.pi)
    else:
        assert hi - lo == pytest.approx(smallest, abs=1e-12)
        rel = np.remainder(ang - lo, 2 * math.pi)
        assert np.all((rel <= hi - lo + 1e-12) | (rel >= 2 * math.pi - 1e-12))


@pytest.mark.parametrize("seed", range(6))
def test_hull_matches_scipy(seed):
    rng = np.random.default_rng(seed)
    pts = rng.normal(size=(40, 2))
    pts[:5] = pts[5]  # repeated points
    hull = footprint_kernels.hull_of(pts.copy(), len(pts))
    ref = pts[ConvexHull(pts).vertices]
    assert {tuple(np.round(p, 12)) for p in hull} == {tuple(np.round(p, 12)) for p in ref}
    e = np.roll(hull, -1, axis=0) - hull
    cross = e[:, 0] * np.roll(e, -1, axis=0)[:, 1] - e[:, 1] * np.roll(e, -1, axis=0)[:, 0]
    assert np.all(cross > 0)  # counter-clockwise, no collinear corner


@pytest.mark.parametrize("seed", range(6))
def test_span_margins_bound_dense_poses(seed):
    """A piece's margin never exceeds the exact clearance of the footprint posed along it."""
    rng = np.random.default_rng(seed)
    res = 0.05
    occ = rng.random((60, 60)) < 0.04
    grid = astar.OccupancyGrid(occ, res)
    fp = Footprint.rectangle(0.5, 0.3)
    bez = rng.uniform(0.8, 2.2, size=(1, 4, 2))
    from trajopt.geometry._clearance import grid_cells
    from trajopt.geometry._obstacle_index import ObstacleIndex

    occ_c, r, ox, oy = grid_cells(grid)
    idx = ObstacleIndex(occ_c, 0, 60, 0, 60)
    rho, phi = fp.polar
    cap = 10.0
    margins, heads = footprint_kernels.span_margins(
        (bez - [ox, oy]) / r, rho / r, phi, MAX_ARC_RAD, cap, 1e-9, 4, *idx.args
    )
    t = np.linspace(0.0, 1.0, 400)[:, None]
    b = bez[0]
    xy = (1 - t) ** 3 * b[0] + 3 * (1 - t) ** 2 * t * b[1] + 3 * (1 - t) * t**2 * b[2] + t**3 * b[3]
    dxy = 3 * (
        (1 - t) ** 2 * (b[1] - b[0]) + 2 * (1 - t) * t * (b[2] - b[1]) + t**2 * (b[3] - b[2])
    )
    theta = np.arctan2(dxy[:, 1], dxy[:, 0])
    dense = polygons_clearance(
        [fp.at(x, y, th) for (x, y), th in zip(xy, theta, strict=True)], grid, cap * r
    )
    assert margins[0] * r <= dense.min() + 1e-9
    rel = np.remainder(theta - heads[0, 0], 2 * math.pi)
    assert np.all((rel <= heads[0, 1] - heads[0, 0] + 1e-9) | (rel >= 2 * math.pi - 1e-9))


# ------------------------------------------------------------------ the SCP rows
def l_halls(width: float, res: float = 0.02):
    """Two halls of ``width`` (m) meeting at a right angle; start in one, goal in the other."""
    occ = np.ones((200, 200), bool)
    w = int(round(width / res))
    occ[20 : 20 + w, 20:180] = False
    occ[20:180, 180 - w : 180] = False
    grid = astar.OccupancyGrid(occ, res)
    return grid, (1.3, (20 + w / 2) * res), ((180 - w / 2) * res, 2.7)


def test_corner_rows_are_first_order_in_the_control_points():
    """The linearised corner rows match directly posed corners up to second order."""
    grid, s, g = l_halls(0.7)
    fp = Footprint.rectangle(0.7, 0.4)
    r = fp.inscribed_radius
    path = np.array([s, (g[0], s[1]), g])
    pts = np.vstack([np.linspace(path[0], path[1], 40), np.linspace(path[1], path[2], 30)[1:]])
    # a footprint fit counts in cells (as the planner and Smoother.fit do)
    corridor = build_polygon_corridor(grid, pts, r, unit_m=grid.resolution)
    options = Smoother()
    prob, _, _ = build_problem(
        options, None, corridor, start=s, goal=g, hs=None, hg=None, unit_m=grid.resolution
    )
    asm = assemble(options, prob, 4.0)
    z = solve_qp(options, asm.qp, x0=asm.x0).z
    res, p, n, nb = grid.resolution, options.degree, asm.qp.n, asm.qp.nb
    scp = FootprintSCP(asm, prob, corners_cells(fp, res), r / res, p, 0.2)
    scp.activate(np.ones(n - p, dtype=bool))
    scp.linearise(z)
    rng = np.random.default_rng(0)
    knots = asm.knots

    def posed(zz):
        """Corners posed on the curve of ``zz`` at the samples, from the curve itself."""
        c = np.column_stack([zz[:n], zz[nb : nb + n]])
        curve = trajopt.geometry._bspline.BSplineCurve(knots, c, p)
        u = np.concatenate(
            [np.linspace(knots[p + j], knots[p + j + 1], 5)[:4] for j in range(n - p)]
        )
        u[-4:] = np.linspace(knots[n - 1], knots[n], 4)  # the last span reaches its end
        xy, d = curve(u), curve(u, 1)
        th = np.arctan2(d[:, 1], d[:, 0])
        F = fp.vertices / res
        return xy[:, None, :] + np.stack(
            [
                np.cos(th)[:, None] * F[:, 0] - np.sin(th)[:, None] * F[:, 1],
                np.sin(th)[:, None] * F[:, 0] + np.cos(th)[:, None] * F[:, 1],
            ],
            axis=2,
        )

    W0 = posed(z)
    errors = []
    for step in (1e-2, 1e-3):
        dz = np.zeros_like(z)
        dz[:n], dz[nb : nb + n] = rng.normal(size=n), rng.normal(size=n)
        dz *= step
        W1 = posed(z + dz)
        worst = 0.0
        for j in range(2):
            q, k = scp.pairs[:, j, 0], scp.pairs[:, j, 1]
            a = scp.A[np.arange(scp.ns), q]
            exact = np.einsum("sd,sd->s", a, W1[np.arange(scp.ns), k])
            exact0 = np.einsum("sd,sd->s", a, W0[np.arange(scp.ns), k])
            X, Y = (z + dz)[:nb][scp.idx], (z + dz)[nb:][scp.idx]
            X0, Y0 = z[:nb][scp.idx], z[nb:][scp.idx]
            lin = (scp.vals[: scp.ns, j, : p + 1] * (X - X0)).sum(1) + (
                scp.vals[: scp.ns, j, p + 1 :] * (Y - Y0)
            ).sum(1)
            worst = max(worst, float(np.max(np.abs(exact - exact0 - lin))))
        errors.append(worst)
    # second order: a tenth of the step leaves about a hundredth of the error (first-order
    # terms cancel); a wrong first-order term would leave a tenth
    assert errors[1] < 0.03 * errors[0] and errors[1] < 1e-3


# ------------------------------------------------------------------ whole plans
def test_scp_turns_a_rectangle_between_two_halls():
    """0.56 m halls: 0.7 x 0.4 passes (L <= 2 (a sqrt 2 - W) = 0.784); the SCP does it."""
    robot = trajopt.Robot.rectangle(0.7, 0.4)
    assert 0.7 <= 2 * (0.56 * math.sqrt(2) - 0.4)
    grid, s, g = l_halls(0.56)
    planner = trajopt.Planner(grid, robot)
    # the disc model alone: its curve is not clear for the footprint
    disc = planner.options.disc(robot.inscribed_radius, last=False)
    curve = plan_disc(disc, planner.caches.disc(disc), PlanRequest(s, g)).path
    assert not trajopt.robot._footprint.certify_footprint(curve, robot.footprint, grid).ok
    traj = planner.plan(s, g)
    fst = traj.stats["footprint"]
    assert fst["rounds"] >= 1 and fst["rejected"] == [] and fst["min_margin_m"] > 0
    smp = traj.sample(np.linspace(0.0, traj.duration, 3000))
    assert not footprint_collides(grid, robot.footprint, smp.x, smp.y, smp.theta)


def test_a_turn_the_rectangle_cannot_make_is_refused():
    robot = trajopt.Robot.rectangle(0.7, 0.4)
    assert 0.7 > 2 * (0.5 * math.sqrt(2) - 0.4)
    grid, s, g = l_halls(0.5)
    with pytest.raises(trajopt.SmoothingError):
        trajopt.Planner(grid, robot).plan(s, g)


def test_a_start_along_a_wall_pins_its_heading():
    """0.3 m from a wall the rectangle stands only at headings near the wall's direction."""
    res = 0.02
    occ = np.zeros((200, 200), bool)
    occ[:5, :] = True
    grid = astar.OccupancyGrid(occ, res)
    robot = trajopt.Robot.rectangle(0.7, 0.4)
    start, goal = (0.6, 0.4), (3.5, 3.5)
    toward_goal = math.atan2(goal[1] - start[1], goal[0] - start[0])
    assert polygons_clearance([robot.footprint.at(*start, toward_goal)], grid, 0.1)[0] == 0.0
    traj = trajopt.Planner(grid, robot).plan(start, goal)
    assert traj.stats["footprint"]["rounds"] >= 1
    theta0 = float(traj.sample(np.array([0.0])).theta[0])
    assert math.isclose(
        theta0 / (2 * math.pi / 72), round(theta0 / (2 * math.pi / 72)), abs_tol=1e-6
    )
    smp = traj.sample(np.linspace(0.0, traj.duration, 3000))
    assert not footprint_collides(grid, robot.footprint, smp.x, smp.y, smp.theta)


def test_end_poses_and_paths_refused_with_their_reason():
    res = 0.02
    occ = np.zeros((100, 200), bool)
    occ[:, 98:102] = True  # a wall with no door
    occ[0:50, 20:24] = True  # a stub from the bottom edge, x in [0.40, 0.48] m
    grid = astar.OccupancyGrid(occ, res)
    robot = trajopt.Robot.rectangle(0.7, 0.4)
    planner = trajopt.Planner(grid, robot)
    with pytest.raises(trajopt.NoPathError, match="inscribed disc"):
        planner.plan((1.0, 1.0), (3.0, 1.0))
    # 0.25 m from the wall stub on the left and 0.25 m from the map's bottom edge: the
    # rectangle fits at no heading there (its half-diagonal is 0.40 m)
    with pytest.raises(trajopt.InvalidInputError, match="start .* every|start .* each"):
        planner.plan((0.73, 0.25), (1.5, 1.0))
    with pytest.raises(trajopt.InvalidInputError, match="goal pose .* heading"):
        planner.plan((1.0, 1.0), (1.5, 0.25), goal_heading=math.pi / 2)


def test_scp_round_with_a_cost_field_trades_towards_lower_cost():
    """A round that minimises the cost term's model ends lower on a cost ramp than a blind one."""
    from trajopt.smoother._cost import CostTerm, cost_field, linearised

    grid, s, g = l_halls(0.7)
    fp = Footprint.rectangle(0.7, 0.4)
    r = fp.inscribed_radius
    pts = np.vstack([np.linspace(s, (g[0], s[1]), 40), np.linspace((g[0], s[1]), g, 30)[1:]])
    # a footprint fit counts in cells (as the planner and Smoother.fit do)
    corridor = build_polygon_corridor(grid, pts, r, unit_m=grid.resolution)
    options = Smoother()
    prob, _, _ = build_problem(
        options, None, corridor, start=s, goal=g, hs=None, hg=None, unit_m=grid.resolution
    )
    asm = assemble(options, prob, 4.0)
    z = solve_qp(options, asm.qp, x0=asm.x0).z
    res, p, n = grid.resolution, options.degree, asm.qp.n
    yy, xx = np.mgrid[0:200, 0:200]
    ramp = np.clip(1.0 - (xx - yy + 200) / 400.0, 0.0, 1.0)  # cheaper towards the outer walls
    term = CostTerm.on_knots(
        cost_field(ramp, 5.0, grid), np.asarray(corridor.origin), res, asm.knots, p, asm.qp.nb, 8
    )
    scp = FootprintSCP(asm, prob, corners_cells(fp, res), r / res, p, 0.2)
    scp.activate(np.ones(n - p, dtype=bool))
    scp.linearise(z)
    blind, _ = scp.solve(z, 2.0)
    aware, _ = scp.solve(z, 2.0, linearised(asm.qp, term, z))
    assert blind is not None and aware is not None
    assert term.value_grad(aware)[0] < term.value_grad(blind)[0] - 1e-3 * abs(
        term.value_grad(blind)[0]
    )
