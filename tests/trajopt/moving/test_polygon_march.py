"""Tests of trajopt.moving's polygon runs: the Lipschitz march against the exact test at every grid time.

The reference measures, with shapely, the distance of every point to every mover's polygon
at every grid time (the mover's pose by np.interp of its waypoints, its radius from its
fields) and forbids a point where that is under the limit; the runs must forbid exactly
those, except within 1e-6 m of the limit (rounding). The movers turn, grow, start late and
stand after their last waypoint, and the points lie near and far from their tracks, so the
march both strides over many grid times and steps one at a time.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import shapely
from shapely.geometry import Polygon

from trajopt.moving import MovingObstacle
from trajopt.moving._polygon_march import (
    FROZEN_PAD,
    PolygonPieces,
    _signed_distance,
    float_arange,
    launch_bound_kernel,
    launch_min_kernel,
    polygon_runs,
    refine_samples_kernel,
)


def _random_movers(rng, n):
    out = []
    for i in range(n):
        k = int(rng.integers(1, 5))
        times = np.cumsum(rng.uniform(0.5, 3.0, k)) - rng.uniform(0.0, 1.5)
        pos = rng.uniform(-1.0, 4.0, (k, 2))
        heads = np.cumsum(rng.uniform(-1.5, 1.5, k))
        if i % 3 == 2:
            verts = [(0.0, -0.3), (0.5, 0.2), (-0.2, 0.3)]
        else:
            hl, hw = rng.uniform(0.2, 0.6), rng.uniform(0.15, 0.35)
            verts = [(-hl, -hw), (hl, -hw), (hl, hw), (-hl, hw)]
        out.append(
            MovingObstacle.from_waypoints(
                times,
                pos,
                radius=float(rng.uniform(0.0, 0.1)),
                growth=float(rng.choice([0.0, 0.05])),
                headings=heads,
                vertices=verts,
            )
        )
    return out


def _dense(pts, movers, lim0, t):
    """The exact test at every point and grid time, shape (K, n) per mover, and where it is within 1e-6 m of the limit."""
    hits, near = [], []
    for m, l0 in zip(movers, lim0, strict=True):
        assert m.vertices is not None
        hit = np.zeros((t.shape[0], pts.shape[0]), bool)
        edge = np.zeros_like(hit)
        for k, tk in enumerate(t):
            x = np.interp(tk, m.times, m.positions[:, 0])
            y = np.interp(tk, m.times, m.positions[:, 1])
            h = np.interp(tk, m.times, m.headings)
            c, sn = np.cos(h), np.sin(h)
            shape = Polygon(np.array([x, y]) + m.vertices @ np.array([[c, sn], [-sn, c]]))
            lim = l0 + m.radius + m.growth * min(max(tk, 0.0), m.t_last)
            d = shapely.distance(shape, shapely.points(pts))
            hit[k] = d < lim
            edge[k] = np.abs(d - lim) < 1e-6
        hits.append(hit)
        near.append(edge)
    return hits, near


def _painted(runs, n_movers, kk, n):
    node, lo, hi, owner = runs
    out = np.zeros((n_movers, kk, n), bool)
    for i, a, b, j in zip(node, lo, hi, owner, strict=True):
        out[j, a : b + 1, i] = True
    return out


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("sufficient", [True, False])
def test_the_march_forbids_exactly_the_points_the_exact_test_does(seed, sufficient):
    rng = np.random.default_rng(seed)
    movers = _random_movers(rng, 3)
    pts = np.column_stack([np.linspace(-1.0, 4.5, 70), 1.0 + np.sin(np.linspace(0.0, 4.0, 70))])
    lim0 = rng.uniform(0.1, 0.4, len(movers))
    t = np.arange(160) * 0.05  # past every mover's last waypoint: they stand
    runs = polygon_runs(pts, movers, range(len(movers)), lim0, t, sufficient)
    got = _painted(runs, len(movers), t.shape[0], pts.shape[0])
    ref, near = _dense(pts, movers, lim0, t)
    for j in range(len(movers)):
        assert not np.any((got[j] != ref[j]) & ~near[j])
    assert any(r.any() for r in ref) and any((~r).any() for r in ref)


@pytest.mark.parametrize("sufficient", [True, False])
def test_translating_and_slowly_turning_movers_solved_in_closed_form(sufficient):
    """Pieces that only translate: exactly the exact test's grid times; a slow turn (within
    ``FROZEN_PAD``): more of them on a sufficient grid, fewer on a necessary one, only within
    the turn's pad of the limit; a faster one marched (exact)."""
    rng = np.random.default_rng(11)
    movers, pads = [], []
    for i, turn in enumerate((0.0, 0.0, 0.0015, 0.02)):
        times = np.array([0.0, 1.5, 3.0, 5.5])
        verts = [(-0.45, -0.25), (0.45, -0.25), (0.45, 0.25), (-0.45, 0.25)]
        if i == 1:
            verts = [(0.0, -0.3), (0.5, 0.2), (-0.2, 0.3)]
        heads = rng.uniform(-3.0, 3.0) + turn * times
        movers.append(
            MovingObstacle.from_waypoints(
                times, rng.uniform(-1.0, 4.0, (4, 2)), radius=0.05, headings=heads, vertices=verts
            )
        )
        reach = float(np.max(np.hypot(*np.array(verts).T)))
        pads.append(min(reach * turn * 2.5 / 2, FROZEN_PAD))  # the longest piece: 2.5 s
    assert 0.0 < pads[2] < FROZEN_PAD and reach * 0.02 * 2.5 / 2 > 10 * FROZEN_PAD
    pts = np.column_stack([np.linspace(-1.0, 4.5, 24), 1.0 + np.sin(np.linspace(0.0, 4.0, 24))])
    lim0 = np.full(len(movers), 0.3)
    t = np.arange(2400) * 0.0025  # fine: the pad moves some grid times
    got = _painted(
        polygon_runs(pts, movers, range(len(movers)), lim0, t, sufficient),
        len(movers),
        t.shape[0],
        pts.shape[0],
    )
    for j, m in enumerate(movers):
        # the reference again, with the limit moved by twice the pad the safe way (the
        # turned shape is within the pad of the true one, and the limit moved by it)
        for sign in (0.0, 2.0):
            l0 = [0.3 + sign * pads[j] * (1.0 if sufficient else -1.0)]
            ref, near = _dense(pts, [m], l0, t)
            if sign == 0.0:
                inner = ref[0]
            else:
                outer = ref[0]
        if sufficient:
            assert not np.any(inner & ~got[j] & ~near[0])  # every forbidden time, and ...
            assert not np.any(got[j] & ~outer & ~near[0])  # ... none farther than the pad
        else:
            assert not np.any(got[j] & ~inner & ~near[0])
            assert not np.any(outer & ~got[j] & ~near[0])
        assert inner.any()


def test_the_runs_carry_the_grids_mover_index_and_leave_out_pieces_before_after():
    """``owners`` name the runs; ``after`` drops only the pieces that end before it."""
    rng = np.random.default_rng(5)
    movers = _random_movers(rng, 2)
    pts = np.column_stack([np.linspace(-1.0, 4.5, 50), np.full(50, 1.5)])
    lim0 = np.array([0.3, 0.3])
    t = np.arange(140) * 0.05
    full = polygon_runs(pts, movers, [4, 7], lim0, t, True)
    assert set(np.unique(full[3])) <= {4, 7}
    after = np.linspace(0.0, 5.0, 50)
    part = polygon_runs(pts, movers, [4, 7], lim0, t, True, after)
    a = _painted((full[0], full[1], full[2], full[3] - 4), 4, t.shape[0], 50)
    b = _painted((part[0], part[1], part[2], part[3] - 4), 4, t.shape[0], 50)
    late = t[:, None] >= after[None, :]
    assert np.array_equal(a & late, b & late)
    assert not np.any(b & ~a)


def test_a_standing_mover_is_decided_by_one_test_and_lasts_to_the_last_time():
    """A mover with one waypoint stands from t = 0: a node inside its limit is forbidden at
    every grid time (one run to the last index), one outside never."""
    box = [(-0.5, -0.2), (0.5, -0.2), (0.5, 0.2), (-0.5, 0.2)]
    m = MovingObstacle.from_waypoints([0.0], [(0.0, 0.0)], radius=0.05, vertices=box)
    pts = np.array([[0.0, 0.5], [0.0, 0.6], [0.8, 0.0]])  # 0.3, 0.4, 0.3 m from the box
    node, lo, hi, _ = polygon_runs(pts, [m], [0], np.array([0.3]), np.arange(50) * 0.1, True)
    # limits 0.35 m: the first and the last are inside, the middle one outside
    assert sorted(node.tolist()) == [0, 2]
    assert np.all(lo == 0) and np.all(hi == 49)


def test_the_launch_bound_is_the_clearance_at_the_launch_plus_tau():
    """Each point against its mover at ``launch + tau``: shapely's distance minus the
    mover's radius (growing) minus the pad."""
    rng = np.random.default_rng(3)
    movers = _random_movers(rng, 3)
    tracks = PolygonPieces(movers)
    q = 40
    pts = rng.uniform(-1.0, 4.0, (q, 2))
    tau = rng.uniform(0.0, 2.0, q)
    mover = rng.integers(0, 3, q)
    pad = rng.uniform(0.0, 0.2, q)
    launch = np.array([0.0, 0.7, 3.3, 9.0])
    starts = np.searchsorted(tracks.who, np.arange(len(movers) + 1))
    got = launch_bound_kernel(
        launch,
        tau,
        mover,
        pts,
        pad,
        tracks.rows,
        starts,
        tracks.head0,
        tracks.turn,
        tracks.verts,
        tracks.edges,
        tracks.poly,
    )
    for li, lt in enumerate(launch):
        for r in range(q):
            m, t = movers[mover[r]], lt + tau[r]
            x = np.interp(t, m.times, m.positions[:, 0])
            y = np.interp(t, m.times, m.positions[:, 1])
            h = np.interp(t, m.times, m.headings)
            c, sn = np.cos(h), np.sin(h)
            shape = Polygon(np.array([x, y]) + m.vertices @ np.array([[c, sn], [-sn, c]]))
            want = shapely.distance(shape, shapely.points(pts[r])) - m.radius_at(t) - pad[r]
            assert got[li, r] == pytest.approx(want, abs=1e-9)


@pytest.mark.parametrize("seed", range(6))
def test_the_least_launch_bound_is_the_minimum_over_the_points(seed):
    """The pruned minimum per launch equals, bit for bit, the minimum over the points of the
    full table (:func:`launch_bound_kernel`, itself checked against shapely above) where
    that is positive, and is one point's clearance of zero or less where it is not: on
    launches a step apart (the refinement's grids) and jumping back and forth, with points
    along a drive (many nearly as close as the least) and scattered ones."""
    rng = np.random.default_rng(seed)
    movers = _random_movers(rng, 4)
    tracks = PolygonPieces(movers)
    q = 120
    along = np.column_stack([np.linspace(-1.0, 4.0, q // 2), np.full(q // 2, 1.5)])
    pts = np.vstack([along, rng.uniform(-1.0, 4.0, (q - q // 2, 2))])
    tau = np.concatenate([np.linspace(0.0, 2.0, q // 2), rng.uniform(0.0, 3.0, q - q // 2)])
    mover = rng.integers(0, 4, q)
    pad = rng.uniform(0.0, 0.2, q)
    starts = np.searchsorted(tracks.who, np.arange(len(movers) + 1))
    seen = []
    args = (tracks.rows, starts, tracks.head0, tracks.turn)
    shape = (tracks.verts, tracks.edges, tracks.poly)
    launches = (np.arange(0.0, 4.0, 1e-2), np.arange(1.3, 1.5, 1e-3), rng.uniform(-0.5, 8.0, 50))
    # the pads as drawn (most launches not proved) and 0.6 m less (many proved)
    for launch, off in itertools.product((*launches, np.zeros(0)), (0.0, 0.6)):
        want = launch_bound_kernel(launch, tau, mover, pts, pad - off, *args, *shape)
        got = launch_min_kernel(launch, tau, mover, pts, pad - off, *args, tracks.lip, *shape)
        least = np.min(want, axis=1, initial=np.inf)
        proved = least > 0.0
        assert np.array_equal(got[proved], least[proved])
        # not proved: one point's clearance of zero or less (the least is not needed)
        assert np.all(got[~proved] <= 0.0)
        assert all(g in row for g, row in zip(got[~proved], want[~proved], strict=True))
        seen += [int(proved.sum()), int((~proved).sum())]
    assert sum(seen[0::2]) > 0 and sum(seen[1::2]) > 0  # both kinds of launch are tested
    none = launch_min_kernel(
        np.arange(3.0), tau[:0], mover[:0], pts[:0], pad[:0], *args, tracks.lip, *shape
    )
    assert np.all(none == np.inf)


def _foot_at(pts, heading, body):
    c, sn = np.cos(heading)[:, None], np.sin(heading)[:, None]
    return np.stack(
        [
            pts[:, 0:1] + c * body[None, :, 0] - sn * body[None, :, 1],
            pts[:, 1:2] + sn * body[None, :, 0] + c * body[None, :, 1],
        ],
        axis=-1,
    )


@pytest.mark.parametrize("sufficient", [True, False])
def test_a_footprint_is_marched_against_polygons_and_discs_as_shapely_measures(sufficient):
    """A footprint robot (a rectangle turned along the points) against turning polygons and a
    disc mover: forbidden exactly where shapely's polygon-to-polygon distance is under the
    limit (the limits positive: an overlap counts as distance 0)."""
    rng = np.random.default_rng(11)
    movers = _random_movers(rng, 2) + [
        MovingObstacle.from_waypoints([0.5, 5.0], [(0.0, 1.0), (4.0, 1.5)], radius=0.2)
    ]
    body = np.array([[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2], [-0.3, 0.2]])
    pts = np.column_stack([np.linspace(-1.0, 4.5, 50), 1.0 + np.sin(np.linspace(0.0, 4.0, 50))])
    heading = np.linspace(0.0, 2.0, 50)
    polys = _foot_at(pts, heading, body)
    lim0 = np.array([0.05, 0.1, 0.02])
    t = np.arange(120) * 0.05
    runs = polygon_runs(pts, movers, range(3), lim0, t, sufficient, None, polys)
    got = _painted(runs, 3, t.shape[0], pts.shape[0])
    feet = [Polygon(p) for p in polys]
    hits = 0
    for j, m in enumerate(movers):
        ref = np.zeros((t.shape[0], pts.shape[0]), bool)
        near = np.zeros_like(ref)
        for k, tk in enumerate(t):
            x = np.interp(tk, m.times, m.positions[:, 0])
            y = np.interp(tk, m.times, m.positions[:, 1])
            h = np.interp(tk, m.times, m.headings)
            c, sn = np.cos(h), np.sin(h)
            v = m.shape_vertices
            if v.shape[0] == 1:
                shape = shapely.points([x, y])
            else:
                shape = Polygon(np.array([x, y]) + v @ np.array([[c, sn], [-sn, c]]))
            lim = lim0[j] + m.radius + m.growth * min(max(tk, 0.0), m.t_last)
            d = shapely.distance(shape, feet)
            ref[k] = d < lim
            near[k] = np.abs(d - lim) < 1e-6
        hits += int(ref.any())
        assert not np.any((got[j] != ref) & ~near)
    assert hits >= 2


def test_the_signed_distance_of_overlapping_polygons_is_minus_their_penetration_depth():
    """Against the Minkowski difference measured by shapely: the origin's distance to the
    boundary of the hull of ``a_i - b_j`` (inside: minus it), for overlapping and separate pairs."""
    rng = np.random.default_rng(2)
    for _ in range(60):
        a = shapely.convex_hull(shapely.multipoints(rng.uniform(-1.0, 1.0, (6, 2))))
        b = shapely.convex_hull(
            shapely.multipoints(rng.uniform(-1.0, 1.0, (5, 2)) + rng.uniform(-1.5, 1.5, 2))
        )
        pa = np.asarray(a.exterior.coords)[:-1]
        pb = np.asarray(b.exterior.coords)[:-1]
        pa, pb = pa[::-1].copy(), pb[::-1].copy()  # shapely's hulls are clockwise
        diff = shapely.convex_hull(
            shapely.multipoints((pa[:, None, :] - pb[None, :, :]).reshape(-1, 2))
        )
        origin = shapely.points([0.0, 0.0])
        gap = shapely.distance(diff.exterior, origin)
        want = -gap if diff.contains(origin) else gap
        got = _signed_distance(pa, pa.shape[0], pb, pb.shape[0])
        assert got == pytest.approx(want, abs=1e-9)


@pytest.mark.parametrize("seed", range(4))
def test_pieces_headings_are_numpy_interp_of_each_mover(seed):
    """Each piece's start heading and turn rate are those of ``numpy.interp`` on its own
    mover's waypoints (bit for bit): pieces from 0 (inside a segment or before the first
    time), at the waypoint times and the standing after the last (turn 0)."""
    rng = np.random.default_rng(100 + seed)
    movers = _random_movers(rng, 7)
    tracks = PolygonPieces(movers)
    who = tracks.pieces[:, 0].astype(np.int64)
    u, w = tracks.pieces[:, 1], tracks.pieces[:, 2]
    for j, m in enumerate(movers):
        mine = who == j
        for ui, wi, h0, turn in zip(
            u[mine], w[mine], tracks.head0[mine], tracks.turn[mine], strict=True
        ):
            h_u = np.interp(ui, m.times, m.headings)
            assert h0 == h_u
            if np.isfinite(wi):
                assert turn == (np.interp(wi, m.times, m.headings) - h_u) / (wi - ui)
            else:
                assert turn == 0.0


def test_float_arange_is_numpy_arange():
    # the refinement's launch grids: numpy.arange's values, bit for bit, for the starts,
    # stops and steps it uses (a stop half a step past the end), empty ranges included
    rng = np.random.default_rng(11)
    for _ in range(3000):
        start = float(rng.uniform(-5.0, 40.0))
        step = float(rng.choice([1e-2, 1e-3, 1e-4, 0.37]))
        stop = start + float(rng.uniform(-0.02, 0.4)) + 0.5 * step
        assert np.array_equal(float_arange(start, stop, step), np.arange(start, stop, step))


def test_the_refinement_samples_cover_each_owners_spans():
    # random spans of three owners (some touching, some nested, some of zero length): the
    # samples of an owner lie in its spans, start and end each union of them, and are at
    # most dt apart inside one (brute force on a fine grid of the union)
    rng = np.random.default_rng(5)
    dt = 1e-3
    for _ in range(30):
        q = int(rng.integers(1, 12))
        a = np.round(rng.uniform(0.0, 0.3, q), 3)  # on a grid: touching ends happen
        b = a + np.round(rng.choice([0.0, 0.004, 0.02, 0.05], q), 3)
        owner = rng.integers(0, 3, q)
        tau, who = refine_samples_kernel(a, b, owner, dt)
        for o in np.unique(owner):
            mine = tau[who == o]
            sa, sb = a[owner == o], b[owner == o]
            inside = (mine[:, None] >= sa[None, :] - 1e-12) & (mine[:, None] <= sb[None, :] + 1e-12)
            assert inside.any(axis=1).all()
            # the union's pieces (brute force: sort, join overlapping or touching spans)
            order = np.argsort(sa, kind="stable")
            parts = []
            for x, y in zip(sa[order], sb[order], strict=True):
                if parts and x <= parts[-1][1]:
                    parts[-1][1] = max(parts[-1][1], y)
                else:
                    parts.append([x, y])
            for x, y in parts:
                run = mine[(mine >= x) & (mine <= y)]
                assert run[0] == x and run[-1] == y
                assert np.all(np.diff(run) <= dt * (1 + 1e-9) + 1e-15)
            assert mine.shape[0] == sum(max(int(np.ceil((y - x) / dt)), 1) + 1 for x, y in parts)
