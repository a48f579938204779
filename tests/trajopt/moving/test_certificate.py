"""Tests of trajopt.moving: the continuous-time certificate against dense sampling and a brute force.

The certificate must never pass a case where the 1 ms samples or the brute force (a bounded
scalar minimisation around each sampled local minimum) find the robot closer than the limit by
more than its tolerance, must pass every case the brute force finds clear by a margin, and its
witness of a violation must be a real one.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from tests.trajopt.moving.reference import brute_min, dense_min, slack
from trajopt.errors import InvalidInputError, TimingError
from trajopt.geometry import BSplineCurve, PolylineCurve, clamped_uniform_knots
from trajopt.moving import MovingObstacle, certify_movers
from trajopt.robot import Robot
from trajopt.timing import time_parameterize

ROBOT = Robot(v_max=0.8, a_max=0.8, j_max=3.0)
SQUARE = [(-0.3, -0.2), (0.3, -0.2), (0.3, 0.2), (-0.3, 0.2)]


@pytest.fixture(scope="module")
def line():
    return time_parameterize(PolylineCurve(np.array([[0.0, 0.0], [4.0, 0.0]])), ROBOT)


def _curve(ys, length):
    n = len(ys) + 2
    x = np.linspace(0.0, length, n)
    y = np.concatenate([[0.0], ys, [0.0]])
    y[1] = 0.0  # a straight start and end: no curvature at the ends
    return BSplineCurve(clamped_uniform_knots(n, 3), np.column_stack([x, y]), 3)


@st.composite
def cases(draw):
    ys = draw(st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=5))
    length = draw(st.floats(2.0, 5.0))
    movers = []
    for i in range(draw(st.integers(1, 2))):
        t_a = draw(st.floats(0.0, 6.0))
        p = np.array([draw(st.floats(-1.0, length + 1.0)), draw(st.floats(-2.0, 2.0))])
        v = np.array([draw(st.floats(-0.8, 0.8)), draw(st.floats(-0.8, 0.8))])
        radius = draw(st.floats(0.0, 0.4))
        growth = draw(st.sampled_from([0.0, 0.0, 0.02]))
        poly = draw(st.booleans())
        turn = draw(st.floats(-1.0, 1.0)) if poly else 0.0
        movers.append(
            MovingObstacle.from_waypoints(
                [t_a, t_a + 3.0, t_a + 6.0],
                [p, p + 3.0 * v, p + 3.0 * v + 3.0 * v[::-1]],
                radius=radius,
                growth=growth,
                headings=[0.0, turn, 2 * turn],
                vertices=SQUARE if poly else None,
                name=f"m{i}",
            )
        )
    return ys, length, movers


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(cases())
def test_never_passes_a_violation_and_passes_clear_cases(case):
    ys, length, movers = case
    try:
        traj = time_parameterize(_curve(ys, length), ROBOT)
    except TimingError:
        assume(False)
    cert = certify_movers(traj, movers, tol=1e-6)
    truth = min(brute_min(traj, movers), dense_min(traj, movers, dt=2e-3)[0])
    assert cert.verdict in ("clear", "violated")
    if cert.ok:
        assert truth >= -1e-6 - 1e-9
        assert cert.slack <= truth + 1e-9  # a lower bound of the true smallest slack
    else:
        m = next(m for m in movers if m.name == cert.mover)
        assert slack(traj, m, cert.witness_t)[0] < -0.5e-6 + 1e-12
    if truth > 1e-4:
        assert cert.ok


@pytest.mark.parametrize("offset", [0.0, 1e-3, -1e-3, -2e-6])
def test_a_grazing_mover_touches_at_the_limit(line, offset):
    """A mover crossing the robot's line so that the closest approach is limit + offset."""
    t_c = 3.0
    p = np.array([float(line.motion(t_c)[0]), 0.0])
    v_rob = float(line.motion(t_c)[1])
    # moving with the robot along x at its speed at t_c and across it: closest at t_c
    r = 0.25
    d = ROBOT.radius + r + offset
    vel = np.array([v_rob, 0.0])
    mover = MovingObstacle.from_waypoints(
        [t_c - 0.5, t_c, t_c + 0.5],
        [p + (0.0, d + 0.5) - 0.5 * vel, p + (0.0, d), p + (0.0, d + 0.5) + 0.5 * vel],
        radius=r,
    )
    cert = certify_movers(line, [mover], tol=1e-6)
    assert brute_min(line, [mover]) == pytest.approx(offset, abs=1e-9)
    assert dense_min(line, [mover])[0] == pytest.approx(offset, abs=1e-9)
    assert cert.ok == (offset >= 0.0)  # touching is allowed, 2 micrometres closer is not
    if cert.ok:
        assert -1e-6 <= cert.slack <= offset + 1e-9
    else:
        assert slack(line, mover, cert.witness_t)[0] < -0.5e-6


def test_following_at_the_limit_is_proven_fast(line):
    """A mover alongside the robot at exactly the limit: the second-order bound closes it."""
    m = MovingObstacle.constant_velocity(
        (0.0, ROBOT.radius + 0.2), (0.2, 0.0), radius=0.2, horizon=15.0
    )
    cert = certify_movers(line, [m])
    assert cert.ok and cert.intervals < 5000
    closer = MovingObstacle.constant_velocity(
        (0.0, ROBOT.radius + 0.199), (0.2, 0.0), radius=0.2, horizon=15.0
    )
    bad = certify_movers(line, [closer])
    assert bad.verdict == "violated" and slack(line, closer, bad.witness_t)[0] < 0.0


def test_standing_at_the_goal_until_the_prediction_ends(line):
    """Arriving before a mover runs over the goal is not safe."""
    late = MovingObstacle.constant_velocity((4.0, -3.0), (0.0, 0.3), radius=0.2, horizon=20.0)
    cert = certify_movers(line, [late])
    assert late.position_at(10.0)[1] == pytest.approx(0.0) and line.duration < 10.0
    assert not cert.ok and cert.witness_t > line.duration
    assert cert.horizon == 20.0


def test_polygon_mover_and_margin(line):
    box = MovingObstacle.from_waypoints([0.0], [(2.0, 0.8)], radius=0.0, vertices=SQUARE)
    gap = 0.6 - ROBOT.radius  # the box's lower edge is at y = 0.6
    assert certify_movers(line, [box], margin=gap - 1e-3).ok
    assert not certify_movers(line, [box], margin=gap + 1e-3).ok


def test_bad_arguments(line):
    m = MovingObstacle.constant_velocity((0, 5), (0, 0), radius=0.1, horizon=1.0)
    with pytest.raises(InvalidInputError, match="margin"):
        certify_movers(line, [m], margin=-1.0)
    with pytest.raises(InvalidInputError, match="moving_obstacles"):
        certify_movers(line, m)
    with pytest.raises(InvalidInputError, match="Trajectory"):
        certify_movers("traj", [m])
    assert certify_movers(line, []).ok and math.isinf(certify_movers(line, []).slack)


def test_mover_segments_are_numpy_interp_bit_for_bit():
    """Poses and rates gathered for several movers equal numpy.interp and the waypoint slopes."""
    from trajopt.moving._mover_segments import mover_table

    rng = np.random.default_rng(3)
    movers = [
        MovingObstacle.from_waypoints(
            np.cumsum(rng.uniform(0.1, 2.0, n)) - 1.0,
            rng.normal(size=(n, 2)),
            radius=0.1,
            headings=rng.normal(size=n),
            vertices=SQUARE if n % 2 else None,
        )
        for n in (1, 2, 3, 6)
    ]
    seg = mover_table(movers).seg  # read-only, as the certificate's (one compiled signature)
    for j, m in enumerate(movers):
        t = np.concatenate([m.times, rng.uniform(-2.0, 12.0, 200), [m.times[-1] + 1.0]])
        g = seg.row(np.full(t.shape, j), t)
        pose = seg.at(g, t)
        c, h = m.pose_at(t)
        assert np.array_equal(pose[:, :2], c) and np.array_equal(pose[:, 2], h)
        k = np.searchsorted(m.times, t, side="right") - 1
        inside = (k >= 0) & (k < m.times.shape[0] - 1)
        kk = np.clip(k, 0, max(m.times.shape[0] - 2, 0))
        if m.times.shape[0] >= 2:
            dt = m.times[kk + 1] - m.times[kk]
            vel = (m.positions[kk + 1] - m.positions[kk]) / dt[:, None]
            assert np.array_equal(seg.vel[g], np.where(inside[:, None], vel, 0.0))
        else:
            assert not np.any(seg.vel[g]) and not np.any(seg.turn[g])
    # all movers at once, interleaved (the compiled rows and poses, one loop)
    j = rng.integers(0, len(movers), 300)
    t = rng.uniform(-2.0, 12.0, 300)
    g = seg.row(j, t)
    for jj, m in enumerate(movers):
        sel = j == jj
        assert np.array_equal(g[sel], seg.row(np.full(int(sel.sum()), jj), t[sel]))
        c, h = m.pose_at(t[sel])
        assert np.array_equal(seg.at(g, t)[sel], np.column_stack([c, h]))


def test_mover_table_is_kept_for_the_same_movers_only():
    """The same mover objects in the same order get the kept table (read-only, its fields
    each mover's own); other objects or another order get a new one; and a certificate
    against the kept table is the one against a fresh copy of the movers."""
    from trajopt.moving._mover_segments import mover_table

    rng = np.random.default_rng(4)
    movers = [
        MovingObstacle.from_waypoints(
            [0.0, 2.0 + i],
            rng.normal(size=(2, 2)),
            radius=0.1 * i,
            growth=0.01 * i,
            headings=[0.0, 0.5],
            vertices=SQUARE if i % 2 else None,
        )
        for i in range(4)
    ]
    table = mover_table(movers)
    assert mover_table(tuple(movers)) is table
    assert mover_table(movers[::-1]) is not table
    copies = [
        MovingObstacle.from_waypoints(
            m.times,
            m.positions,
            radius=m.radius,
            growth=m.growth,
            headings=m.headings,
            vertices=m.vertices,
        )
        for m in movers
    ]
    assert mover_table(copies) is not table
    assert not table.reach.flags.writeable and not table.seg.vel.flags.writeable
    for j, m in enumerate(movers):
        assert table.reach[j] == np.max(np.hypot(*m.shape_vertices.T))
        assert table.rad0[j] == m.radius and table.grow[j] == m.growth
        assert table.sizes[j] == m.shape_vertices.shape[0]
        assert np.array_equal(table.verts[int(table.sizes[j])][j], m.shape_vertices)
    traj = time_parameterize(_curve([0.6, -0.5, 0.4], 4.0), ROBOT)
    kept, fresh = certify_movers(traj, movers), certify_movers(traj, copies)
    assert kept == fresh


def test_movers_together_as_each_alone():
    """The verdict of several movers is the first failing one's alone, else the least slack.

    The movers share their first and last times (the same horizon, so the same covers).
    """
    traj = time_parameterize(_curve([0.6, -0.5, 0.4], 4.0), ROBOT)
    rng = np.random.default_rng(5)
    for _ in range(6):
        movers = []
        for i in range(5):
            t_a = float(rng.uniform(0.5, 8.0))
            p = rng.uniform([-1.0, -2.0], [5.0, 2.0])
            v = rng.uniform(-0.6, 0.6, 2)
            movers.append(
                MovingObstacle.from_waypoints(
                    [0.0, t_a, 12.0],
                    [p, p + t_a * v, p + t_a * v + (12.0 - t_a) * v[::-1]],
                    radius=float(rng.uniform(0.0, 0.2)),
                    headings=[0.0, 0.5, 1.0],
                    vertices=SQUARE if i % 3 else None,
                    name=f"m{i}",
                )
            )
        polys = [m for m in movers if m.vertices is not None]
        alone = [certify_movers(traj, [m]) for m in polys]
        together = certify_movers(traj, polys)
        failing = [c for c in alone if not c.ok]
        if failing:
            assert together.verdict == failing[0].verdict
            assert (together.mover, together.slack, together.witness_t) == (
                failing[0].mover,
                failing[0].slack,
                failing[0].witness_t,
            )
        else:
            least = min(alone, key=lambda c: (c.slack, c.mover, c.witness_t))
            assert together.ok and together.slack == least.slack
            assert together.intervals == sum(c.intervals for c in alone)


def test_far_intervals_set_aside_change_nothing(monkeypatch):
    """Setting far intervals aside gives the certificate of evaluating every interval."""
    from trajopt.moving import _certificate

    traj = time_parameterize(_curve([0.8, -0.6, 0.5], 5.0), ROBOT)
    rng = np.random.default_rng(11)
    cases = []
    for _ in range(8):
        movers = []
        for i in range(4):
            p = rng.uniform([-2.0, -3.0], [7.0, 3.0])
            v = rng.uniform(-0.5, 0.5, 2)
            t_a = float(rng.uniform(0.5, 9.0))
            movers.append(
                MovingObstacle.from_waypoints(
                    [0.0, t_a, 12.0],
                    [p, p + t_a * v, p + t_a * v + (12.0 - t_a) * v[::-1]],
                    radius=float(rng.uniform(0.0, 0.2)),
                    headings=[0.0, 0.7, 1.4],
                    vertices=SQUARE,
                    name=f"m{i}",
                )
            )
        cases.append(movers)
    fast = [certify_movers(traj, m) for m in cases]
    monkeypatch.setattr(_certificate, "MAX_INTERVALS", 30)  # some give up undecided
    fast_short = [certify_movers(traj, m) for m in cases]
    monkeypatch.setattr(
        _certificate._Bisection, "_cheap", lambda self, t0, *_: np.full(t0.shape, -np.inf)
    )
    every_short = [certify_movers(traj, m) for m in cases]
    monkeypatch.setattr(_certificate, "MAX_INTERVALS", 400_000)
    every = [certify_movers(traj, m) for m in cases]
    assert fast == every
    assert {c.verdict for c in every} == {"clear", "violated"}
    assert fast_short == every_short
    assert "undecided" in {c.verdict for c in every_short}


@pytest.mark.parametrize("m", [1, 3, 4, 7])
def test_point_polygon_distance_against_dense_edges_and_matplotlib(m):
    # random convex CCW polygons (m vertices on circles) and points near them: the distance
    # against the least over 2001 samples of every edge (within the sampling's half-step),
    # 0 exactly inside (matplotlib's point-in-polygon, shrunk by 1e-9 m to avoid the edges)
    from matplotlib.path import Path

    from trajopt.moving._certificate import point_polygon_distance

    rng = np.random.default_rng(m)
    n = 60
    ang = np.sort(rng.uniform(0.0, 2.0 * math.pi, (n, m)), axis=1)
    rad = rng.uniform(0.2, 1.0, (n, 1))
    w = np.stack([rad * np.cos(ang), rad * np.sin(ang)], axis=-1) + rng.normal(size=(n, 1, 2))
    p = rng.normal(size=(n, 2))
    got = point_polygon_distance(p, w)
    lam = np.linspace(0.0, 1.0, 2001)
    n_inside = 0
    for i in range(n):
        a, b = w[i], np.roll(w[i], -1, axis=0)
        pts = (a[:, None, :] + lam[None, :, None] * (b - a)[:, None, :]).reshape(-1, 2)
        ref = float(np.min(np.hypot(*(pts - p[i]).T)))
        step = float(np.max(np.hypot(*(b - a).T))) / 2000.0
        inside = m >= 3 and Path(w[i]).contains_point(p[i], radius=-1e-9)
        n_inside += inside
        if inside:
            assert got[i] == 0.0
        else:
            assert ref - 0.5 * step - 1e-12 <= got[i] <= ref + 1e-12
    assert m < 3 or 0 < n_inside < n


def _numpy_disc_robot_bounds(bis, t0, t1, mj, g0):
    """The bisection's bounds for a disc robot as arrays (the form the kernel replaced)."""
    from trajopt.moving._certificate import point_polygon_distance, second_order_lower

    model, seg, extra = bis.model, bis.seg, bis.extra
    tm, h = 0.5 * (t0 + t1), 0.5 * (t1 - t0)
    uniq, inv = np.unique(t0 + 1j * t1, return_inverse=True)
    inv = inv.reshape(-1)
    u0, u1 = uniq.real, uniq.imag
    p, rho_p, v_rob = (x[inv] for x in model.at(u0, 0.5 * (u0 + u1), u1))
    g = g0 + (tm >= seg.next[g0])
    vel, w = seg.vel[g], seg.turn[g]
    pose = seg.at(g, tm)
    rho_m = (np.hypot(vel[:, 0], vel[:, 1]) + bis.reach[mj] * np.abs(w)) * h
    t_last = bis.t_last[mj]
    lim_mid = extra + (bis.rad0[mj] + bis.grow[mj] * np.clip(tm, 0.0, t_last))
    lim_hi = extra + (bis.rad0[mj] + bis.grow[mj] * np.clip(t1, 0.0, t_last))
    dist = np.empty(tm.shape[0])
    for size in np.unique(bis.sizes[mj]):
        sel = bis.sizes[mj] == size
        v = bis.verts[int(size)][mj[sel]]
        ps = pose[sel]
        ch, sh = np.cos(ps[:, 2])[:, None], np.sin(ps[:, 2])[:, None]
        x = ps[:, 0:1] + ch * v[:, :, 0] - sh * v[:, :, 1]
        y = ps[:, 1:2] + sh * v[:, :, 0] + ch * v[:, :, 1]
        dist[sel] = point_polygon_distance(p[sel], np.stack([x, y], axis=-1))
    lower = dist - rho_p - rho_m - lim_hi
    dm = bis.disc[mj]
    if np.any(dm):
        d = p[dm] - pose[dm, :2]
        c2 = np.broadcast_to(model.c2_local, u0.shape)[inv][dm]
        lower2 = second_order_lower(d, v_rob[dm] - vel[dm], h[dm], c2) - lim_hi[dm]
        lower[dm] = np.fmax(lower[dm], lower2)
    return lower, dist - lim_mid, tm


@pytest.mark.parametrize("seed", range(3))
def test_compiled_disc_robot_bounds_are_the_arrays_and_bound_dense_samples(seed):
    """The bisection's compiled bounds for a disc robot (polygons of 3 and 4 vertices and
    disc movers, turning, growing, before, between and after their times) equal the array
    form they replaced, bit for bit, on random intervals; each is below the slack sampled
    every 1 ms over its interval, and the middle's is the reference's slack there."""
    from trajopt.moving._certificate import _Bisection
    from trajopt.moving._robot_windows import robot_windows

    rng = np.random.default_rng(40 + seed)
    traj = time_parameterize(_curve([0.6, -0.5, 0.4], 4.0), ROBOT)
    tri = [(0.0, -0.3), (0.5, 0.2), (-0.2, 0.3)]
    movers = []
    for i in range(6):
        t_a = float(rng.uniform(0.5, 6.0))
        p = rng.uniform([-1.0, -1.5], [5.0, 1.5])
        v = rng.uniform(-0.6, 0.6, 2)
        movers.append(
            MovingObstacle.from_waypoints(
                [1.0, t_a + 1.0, 9.0],
                [p, p + t_a * v, p + t_a * v + (8.0 - t_a) * v[::-1]],
                radius=float(rng.uniform(0.0, 0.2)),
                growth=float(rng.choice([0.0, 0.03])),
                headings=[0.0, float(rng.uniform(-1.5, 1.5)), 1.0] if i % 3 else None,
                vertices=(SQUARE if i % 3 == 1 else tri) if i % 3 else None,
                name=f"m{i}",
            )
        )
    margin = 0.05
    model, a, b = robot_windows(traj)[0]
    bis = _Bisection(model, movers, a, b, ROBOT.radius + margin, 1e-6, None)
    n = 300
    t0 = rng.uniform(-0.5, 10.0, n)
    t1 = t0 + rng.choice([1e-3, 0.05, 0.5], n) * rng.uniform(0.0, 1.0, n)
    t1[:10] = t0[:10]  # instants
    mj = rng.integers(0, len(movers), n)
    for i in range(n):  # within one waypoint segment of its mover (as the bisection's)
        later = movers[mj[i]].times[movers[mj[i]].times > t0[i]]
        t1[i] = min(t1[i], later[0]) if later.size else t1[i]
    g0 = bis.seg.row(mj, t0)
    got = bis._bounds(t0, t1, mj, g0)
    want = _numpy_disc_robot_bounds(bis, t0, t1, mj, g0)
    for x, y in zip(got, want, strict=True):
        assert np.array_equal(x, y)
    lower, slack_mid, tm = got
    for i in range(n):
        ts = np.linspace(t0[i], t1[i], max(2, int((t1[i] - t0[i]) / 1e-3) + 2))
        true = slack(traj, movers[mj[i]], ts, margin=margin)
        assert lower[i] <= np.min(true) + 1e-9
        mid = slack(traj, movers[mj[i]], np.array([tm[i]]), margin=margin)[0]
        assert slack_mid[i] == pytest.approx(mid, abs=1e-9)


def test_curve_motion_arc_length_is_the_phase_polynomials_bit_for_bit():
    # the robot's s(t) in the certificate (compiled, one loop) against the phase polynomials
    # in numpy, at times before the start, on the phase starts, inside and after the end
    from trajopt.moving._robot_windows import robot_windows

    traj = time_parameterize(_curve([0.0, 0.4, -0.3, 0.2, 0.0], 4.0), ROBOT)
    model = robot_windows(traj)[0][0]
    pt, ps, pv, pa, pj = traj.phase_t, traj.phase_s, traj.phase_v, traj.phase_a, traj.phase_j
    dur, length = traj.duration, float(traj.length)
    t = np.concatenate([[-1.0, 0.0], pt, np.linspace(-0.5, dur + 0.5, 2001), [dur, dur + 3.0]])
    tt = np.clip(t, 0.0, dur)
    k = np.clip(np.searchsorted(pt, tt, side="right") - 1, 0, pt.shape[0] - 1)
    tau = tt - pt[k]
    s = ps[k] + tau * (pv[k] + tau * (0.5 * pa[k] + tau * pj[k] / 6.0))
    ref = np.where(tt >= dur, length, np.clip(s, 0.0, length))
    assert np.array_equal(model.s_at(t), ref)
    s0, s1 = model.s_ends(t[::-1].copy(), t)
    assert np.array_equal(s0, ref[::-1]) and np.array_equal(s1, ref)
