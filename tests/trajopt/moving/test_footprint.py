"""Tests of trajopt.moving: the certificate of a footprint robot (a convex polygon that turns).

The reference is independent: shapely's exact polygon distances of the robot's footprint,
placed by the trajectory's own samples, to each mover's shape, on 1 ms samples, and a brute
force (a bounded scalar minimisation around every sampled local minimum).
"""

from __future__ import annotations

import numpy as np
import shapely
from hypothesis import HealthCheck, assume, given, settings
from scipy.optimize import minimize_scalar

import trajopt
from tests.trajopt.moving.test_certificate import SQUARE, _curve, cases
from trajopt.errors import TimingError
from trajopt.geometry import PolylineCurve
from trajopt.moving import MovingObstacle, certify_movers
from trajopt.robot import Footprint, Robot
from trajopt.timing import time_parameterize

BODY = [(-0.2, -0.15), (0.35, -0.15), (0.35, 0.15), (-0.2, 0.15)]
ROBOT = Robot(v_max=0.8, a_max=0.8, j_max=3.0, footprint=Footprint(vertices=BODY))


def _slack(traj, mover, t, margin=0.0):
    t = np.atleast_1d(np.asarray(t, dtype=float))
    smp = traj.sample(t)
    c, s = np.cos(smp.theta)[:, None], np.sin(smp.theta)[:, None]
    b = np.asarray(traj.robot.footprint.vertices)
    robot = shapely.polygons(
        np.stack(
            [
                smp.x[:, None] + c * b[:, 0] - s * b[:, 1],
                smp.y[:, None] + s * b[:, 0] + c * b[:, 1],
            ],
            axis=-1,
        )
    )
    pos, head = mover.pose_at(t)
    if mover.vertices is None:
        other = shapely.points(pos)
    else:
        v = mover.vertices
        ch, sh = np.cos(head)[:, None], np.sin(head)[:, None]
        other = shapely.polygons(
            np.stack(
                [
                    pos[:, :1] + ch * v[:, 0] - sh * v[:, 1],
                    pos[:, 1:] + sh * v[:, 0] + ch * v[:, 1],
                ],
                axis=-1,
            )
        )
    d = shapely.distance(robot, other)
    # an overlap counts below zero (touching is zero): a point deep inside by its depth, two
    # polygons by the square root of their common area (a sign, not a depth)
    if mover.vertices is None:
        inside = shapely.contains_properly(robot, other)
        d = np.where(inside, -shapely.distance(shapely.boundary(robot), other), d)
    else:
        area = shapely.area(shapely.intersection(robot, other))
        d = np.where(area > 1e-14, -np.sqrt(area), d)
    return d - mover.radius_at(t) - margin


def _truth(traj, movers, margin=0.0):
    end = max([traj.duration] + [m.t_last for m in movers])
    t = np.append(np.arange(0.0, end, 1e-3), end)
    best = np.inf
    for m in movers:
        sl = _slack(traj, m, t, margin)
        best = min(best, float(sl.min()))
        coarse = sl[::10]
        tc = t[::10]
        idx = np.flatnonzero((coarse <= np.roll(coarse, 1)) & (coarse <= np.roll(coarse, -1)))
        for i in idx[np.argsort(coarse[idx])[:4]]:
            r = minimize_scalar(
                lambda x, m=m: float(_slack(traj, m, x, margin)[0]),
                bounds=(max(0.0, tc[i] - 0.01), min(end, tc[i] + 0.01)),
                method="bounded",
                options={"xatol": 1e-9},
            )
            best = min(best, float(r.fun))
    return best


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(cases())
def test_footprint_never_passes_a_violation(case):
    ys, length, movers = case
    try:
        traj = time_parameterize(_curve(ys, length), ROBOT)
    except TimingError:
        assume(False)
    cert = certify_movers(traj, movers)
    truth = _truth(traj, movers)
    assert cert.verdict in ("clear", "violated")
    if cert.ok:
        assert truth >= -1e-6
    else:
        m = next(m for m in movers if m.name == cert.mover)
        assert _slack(traj, m, cert.witness_t)[0] < -0.5e-6 + 1e-12
    if truth > 1e-3:
        assert cert.ok


def test_the_footprint_not_its_disc_counts():
    """A box beside the line: clear of the footprint's long side, inside its circumscribed disc."""
    line = time_parameterize(PolylineCurve(np.array([[0.0, 0.0], [4.0, 0.0]])), ROBOT)
    box = MovingObstacle.from_waypoints([0.0], [(2.0, 0.6)], radius=0.0, vertices=SQUARE)
    gap = 0.6 - 0.2 - 0.15  # the box's lower edge to the footprint's upper side
    assert 0.4 - ROBOT.footprint.circumscribed_radius < gap - 1e-3  # the disc is closer
    ok = certify_movers(line, [box], margin=gap - 1e-3)
    assert ok.ok and -1e-6 <= ok.slack <= 1e-3 + 1e-9  # a lower bound of the true 1 mm
    assert not certify_movers(line, [box], margin=gap + 1e-3).ok
    # the disc model of the same robot is refused at once
    disc = ROBOT.footprint.circumscribed_radius
    assert not certify_movers(line, [box], margin=gap - 1e-3, robot_radius=disc).ok


def test_a_footprint_robot_lets_a_mover_pass(scene):
    robot = Robot(
        footprint=Footprint(vertices=[(-0.12, -0.1), (0.2, -0.1), (0.2, 0.1), (-0.12, 0.1)])
    )
    planner = trajopt.Planner(scene.grid, robot)
    base = planner.plan(scene.start, scene.goal("A"))
    t_c = 0.5 * base.duration
    smp = base.sample(np.array([t_c]))
    p = np.array([smp.x[0], smp.y[0]])
    n = np.array([-np.sin(smp.theta[0]), np.cos(smp.theta[0])])
    cart = MovingObstacle.from_waypoints(
        [t_c - 4.0, t_c + 4.0],
        [p - 1.6 * n, p + 1.6 * n],
        radius=0.02,
        vertices=SQUARE,
        name="cart",
    )
    assert not certify_movers(base, [cart]).ok
    out = planner.plan(scene.start, scene.goal("A"), moving_obstacles=[cart], mover_margin=0.02)
    assert out.stats["moving"]["certificate"]["ok"] and out.duration > base.duration
    assert certify_movers(out, [cart], margin=0.02).ok
    assert _truth(out, [cart], margin=0.02) >= -1e-6
