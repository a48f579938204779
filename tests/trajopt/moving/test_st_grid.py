"""Tests of trajopt.moving's (s, t) grid: the closed-form runs against distances at every node.

The reference evaluates the distance of every node of the path to every disc mover at every
grid time, written out here (node points from the path, the mover's track by np.interp, its
radius from its fields); the grid's runs must forbid exactly those nodes, except within 1e-6 m
of the limit (rounding). The runs' queries (a drive's blocked start times, a node's column)
are checked against the dense grid, and the reachability sweep's early stop against a full
sweep. Polygon movers (a point robot and a footprint robot) are checked the same way against
distances from shapely.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from shapely.geometry import Point, Polygon

from trajopt.geometry import CurveSegment, PolylineCurve
from trajopt.moving import MovingObstacle, reachable, st_grid
from trajopt.moving._st_grid import visits
from trajopt.moving._st_kernels import arrive_kernel, blocked_starts_kernel
from trajopt.moving._st_search import Piece, fill_visits
from trajopt.robot import Robot
from trajopt.timing import time_parameterize

PATH = PolylineCurve(np.array([[0.0, 0.0], [3.0, 0.0], [5.0, 2.0]]))
LIMIT, DS, DT, V = 0.2, 0.02, 0.05, 0.5


def _movers():
    return [
        MovingObstacle.constant_velocity((1.0, -2.0), (0.1, 0.5), radius=0.3, horizon=12.0),
        # a waypoint track starting late, growing
        MovingObstacle.from_waypoints(
            [1.0, 4.0, 9.0], [(4.0, -1.0), (3.5, 1.5), (2.0, 0.5)], radius=0.2, growth=0.05
        ),
        # standing still and growing faster than it moves (the quadratic's a < 0)
        MovingObstacle.from_waypoints([2.5], [(2.0, 0.6)], radius=0.1, growth=0.3),
        MovingObstacle.from_waypoints(
            [0.0, 30.0], [(4.5, 0.5), (5.5, 0.5)], radius=0.1, growth=0.2
        ),
    ]


def _dense(grid, movers, sufficient):
    pts = np.asarray(PATH(PATH.u_at_s(grid.s)))
    ref = np.zeros((grid.t.shape[0], grid.s.shape[0]), bool)
    near = np.zeros_like(ref)
    for m in movers:
        if sufficient:
            pad = 0.5 * (grid.ds + DT * V) + 0.5 * DT * (m.shape_speed_max() + m.growth)
        else:
            pad = -0.5 * grid.ds
        c = np.stack([np.interp(grid.t, m.times, m.positions[:, i]) for i in (0, 1)], axis=-1)
        d = np.hypot(pts[None, :, 0] - c[:, None, 0], pts[None, :, 1] - c[:, None, 1])
        lim = LIMIT + m.radius + m.growth * np.clip(grid.t, 0.0, m.t_last) + pad
        ref |= d < lim[:, None]
        near |= np.abs(d - lim[:, None]) < 1e-6
    return ref, near


@pytest.mark.parametrize("sufficient", [True, False])
def test_closed_form_runs_match_the_distances(sufficient):
    movers = _movers()
    g = st_grid(
        PATH,
        PATH.length,
        movers,
        LIMIT,
        ds=DS,
        dt=DT,
        horizon=20.0,
        speed=V,
        sufficient=sufficient,
    )
    ref, near = _dense(g, movers, sufficient)
    assert ref.any()
    assert not np.any((g.blocked != ref) & ~near)
    for i in (0, 57, g.s.shape[0] - 1):
        assert np.array_equal(g.column(i), g.blocked[:, i])


def _carts():
    box = [(-0.4, -0.25), (0.4, -0.25), (0.4, 0.25), (-0.4, 0.25)]
    tri = [(0.0, -0.3), (0.5, 0.2), (-0.2, 0.3)]
    return [
        # turning while it crosses the first leg, then standing on the second
        MovingObstacle.from_waypoints(
            [0.0, 3.0, 6.0],
            [(1.5, -1.5), (1.8, 0.2), (4.2, 1.0)],
            radius=0.05,
            headings=[0.3, 1.6, 2.4],
            vertices=box,
            name="cart",
        ),
        MovingObstacle.from_waypoints(
            [2.0, 9.0], [(6.0, 3.5), (3.0, 0.3)], radius=0.0, headings=[0.0, -2.0], vertices=tri
        ),
        MovingObstacle.constant_velocity((0.5, 2.0), (0.0, -0.3), radius=0.1, horizon=10.0),
    ]


@pytest.mark.parametrize(("sufficient", "body"), [(True, False), (False, False), (True, True)])
def test_polygon_runs_match_shapely_distances(sufficient, body):
    """Polygon movers (and a disc among them) against a point robot or a footprint robot: the
    grid forbids exactly the nodes whose shapely distance at the grid time is below the limit."""
    movers = _carts()
    foot = np.array([[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2], [-0.3, 0.2]]) if body else None
    limit = 0.05 if body else LIMIT
    stretch, dt = (1.5 if body else 1.0), 0.1
    g = st_grid(
        PATH,
        PATH.length,
        movers,
        limit,
        ds=0.05,
        dt=dt,
        horizon=12.0,
        speed=V,
        sufficient=sufficient,
        body=foot,
        stretch=stretch,
    )
    u = PATH.u_at_s(g.s)
    pts = np.asarray(PATH(u))
    heading = np.asarray(PATH.heading(u))
    robots = []
    for p, h in zip(pts, heading, strict=True):
        if foot is None:
            robots.append(Point(p))
        else:
            c, sn = np.cos(h), np.sin(h)
            robots.append(Polygon(p + foot @ np.array([[c, sn], [-sn, c]])))
    ref = np.zeros(g.blocked.shape, bool)
    near = np.zeros_like(ref)
    for m in movers:
        if sufficient:
            pad = 0.5 * (g.ds + dt * V) * stretch + 0.5 * dt * (m.shape_speed_max() + m.growth)
        else:
            pad = -0.5 * g.ds * stretch
        for k, tk in enumerate(g.t):
            x = np.interp(tk, m.times, m.positions[:, 0])
            y = np.interp(tk, m.times, m.positions[:, 1])
            h = np.interp(tk, m.times, m.headings)
            if m.vertices is None:
                shape = Point(x, y)
            else:
                c, sn = np.cos(h), np.sin(h)
                shape = Polygon(np.array([x, y]) + m.vertices @ np.array([[c, sn], [-sn, c]]))
            lim = limit + m.radius + m.growth * min(max(tk, 0.0), m.t_last) + pad
            d = np.array([shape.distance(r) for r in robots])
            ref[k] |= d < lim
            near[k] |= np.abs(d - lim) < 1e-6
    assert ref.any() and (~ref).any()
    assert not np.any((g.blocked != ref) & ~near)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.integers(0, 200),
    st.lists(st.integers(0, 3), min_size=1, max_size=60),
)
def test_blocked_starts_against_the_dense_grid(first, steps):
    g = st_grid(
        PATH,
        PATH.length,
        _movers(),
        LIMIT,
        ds=DS,
        dt=DT,
        horizon=20.0,
        speed=V,
        sufficient=True,
    )
    n = g.s.shape[0]
    kk = g.t.shape[0]
    dense = g.blocked

    def want(idx):
        out = np.zeros(kk, bool)
        for k in range(kk):
            for j, i in enumerate(idx):
                # after the grid's last time a node stays as it was then
                if dense[min(k + j, kk - 1), i]:
                    out[k] = True
                    break
        return out

    forward = np.minimum(first + np.cumsum(steps), n - 1)
    # a motion along the path (non-decreasing nodes) and one that is not
    for idx in (forward, forward[::-1]):
        assert np.array_equal(g.blocked_starts(idx), want(idx))
    # several motions along the path at once
    others = [forward, np.minimum(forward + 7, n - 1), forward[: max(1, len(forward) // 2)]]
    many = g.blocked_starts_many([visits(idx) for idx in others])
    for idx, row in zip(others, many, strict=True):
        assert np.array_equal(row, want(idx))
    # the compiled kernels of the search: one drive's blocked starts, and a batch's arrivals
    # (from a stop where the robot rests at the even steps) where those starts are free
    ptr, _, m_lo, m_hi = (np.asarray(x, dtype=np.int64) for x in g.merged)
    for idx in others:
        assert np.array_equal(blocked_starts_kernel(ptr, m_lo, m_hi, kk, *visits(idx)), want(idx))
    vis = [visits(idx) for idx in others]
    size = np.array([x[1].shape[0] for x in vis], dtype=np.int64)
    ns = np.array([len(idx) - 1 for idx in others], dtype=np.int64)
    rest = np.arange(kk) % 2 == 0
    arrivals = np.zeros((4, kk), bool)
    parent = np.full((3, 4, kk), -1, dtype=np.int64)
    args = [np.array([x[0] for x in vis], dtype=np.int64), np.cumsum(size) - size, size]
    args += [np.concatenate([x[1] for x in vis]), np.concatenate([x[2] for x in vis])]
    vs = np.array([1, 2, 3], dtype=np.int64)
    arrive_kernel(ptr, m_lo, m_hi, rest, *args, ns, vs, 0, 5, arrivals, parent)
    for j, idx in enumerate(others):
        n, v = len(idx) - 1, vs[j]
        ks = np.flatnonzero(rest & ~want(idx))
        ks = ks[ks + n < kk]
        assert np.array_equal(np.flatnonzero(arrivals[v]), ks + n)
        assert np.all(parent[0, v, ks + n] == 0) and np.all(parent[2, v, ks + n] == 5 + j)
        assert np.array_equal(parent[1, v, ks + n], ks)


def _full_sweep(grid, speed):
    fb = grid.blocked
    kk, n = fb.shape
    m = int(np.ceil(speed * grid.dt / grid.ds)) + 1
    idx = np.arange(n)
    reach = np.zeros(n, bool)
    reach[0] = not fb[0, 0]
    for k in range(1, kk):
        lastr = np.maximum.accumulate(np.where(reach, idx, -(10**9)))
        reach = ~fb[k] & (idx - lastr <= m)
        if not reach.any():
            return False
    return bool(reach[-1])


@pytest.mark.parametrize("radius", [0.15, 0.3])
def test_the_sweep_stops_at_its_fixed_point_with_the_full_answer(radius):
    # parked 0.4 m beside the path from t = 0: blocking iff 0.4 < LIMIT + radius - ds/2
    parked = MovingObstacle.from_waypoints([0.0], [(2.0, -0.4)], radius=radius, name="parked")
    g = st_grid(
        PATH,
        PATH.length,
        [parked],
        LIMIT,
        ds=DS,
        dt=DT,
        horizon=40.0,
        speed=V,
        sufficient=False,
    )
    assert reachable(g, V)[0] == _full_sweep(g, V)
    assert reachable(g, V)[0] == (0.4 >= LIMIT + radius - 0.5 * g.ds)


def test_the_visits_of_several_drives_at_once_equal_each_drives_own():
    g = st_grid(
        PATH, PATH.length, _movers(), LIMIT, ds=DS, dt=DT, horizon=20.0, speed=V, sufficient=True
    )
    robot = Robot(v_max=V, a_max=0.5, j_max=2.0)
    pieces, reference = [], []
    for u0, u1 in ((0.0, 0.3), (0.2, 1.0), (0.5, 0.55), (0.0, 1.0)):
        lo, hi = PATH.domain
        a, b = lo + u0 * (hi - lo), lo + u1 * (hi - lo)
        tr = time_parameterize(CurveSegment(PATH, a, b), robot)
        s0 = float(PATH.s_at_u(a))
        rows = np.column_stack([tr.phase_t, tr.phase_s + s0, tr.phase_v, tr.phase_a, tr.phase_j])
        pc = Piece(rows, float(tr.duration), s0, s0 + float(tr.length))
        n = int(np.ceil(pc.duration / DT - 1e-9))
        reference.append(g.index(pc.s_at(np.arange(n + 1) * DT)))  # the drive alone
        pieces.append(pc)
    fill_visits(pieces, g)
    for pc, want in zip(pieces, reference, strict=True):
        assert np.array_equal(pc.nodes(g), want)
        i0, first, last = pc.visits(g)
        w0, w_first, w_last = visits(want)  # the drive's own visits
        assert i0 == w0 and np.array_equal(first, w_first) and np.array_equal(last, w_last)
        for j, i in enumerate(want):  # at node i at step j: within its range of steps
            assert first[i - i0] <= j <= last[i - i0]


@pytest.mark.parametrize("leave", [0.0, 1.5])
def test_a_grid_that_leaves_out_the_times_before_the_robot_can_come_is_the_same_after(leave):
    args = dict(ds=DS, dt=DT, horizon=20.0, speed=V, sufficient=True)
    full = st_grid(PATH, PATH.length, _movers(), LIMIT, **args)
    part = st_grid(PATH, PATH.length, _movers(), LIMIT, leave=leave, **args)
    # the robot is nearest to node i at t_k only if t_k >= leave + (s_i - ds/2) / V
    reach = full.t[:, None] >= leave + np.maximum(full.s[None, :] - 0.5 * full.ds, 0.0) / V
    assert np.array_equal(part.blocked & reach, full.blocked & reach)
    assert not np.any(part.blocked & ~full.blocked)  # only runs left out, never added
    assert np.any(full.blocked & ~reach)  # the case leaves something out
