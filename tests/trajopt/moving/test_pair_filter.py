"""Tests of trajopt.moving's pair filter of the closed-form windows (``near_pairs``) against brute force.

A pair of a piece of a mover's track and a point that the filter leaves out must be farther
than the piece's limit at every instant of the piece: checked on dense samples of the
piece's centre and limit (written out here from the piece's row). The windows computed on
the kept pairs must be exactly those computed on every pair. The merged spans of the
tightening's refinement must cover exactly the union of the spans, per mover. The pieces of
the tracks, built for all movers at once, must be exactly those written out mover by mover
with ``numpy.interp`` (waypoints before, at and after ``t = 0``), and so must the knots of
any range and the centres there (:func:`track_knots`). The compiled closed form of the times a
point is inside a mover's limit must give the floats of the same closed form written with
numpy, degenerate cases (no relative motion, a limit growing as fast as the mover moves, a
zero limit) included (the grid built on it is checked against the distances at every node and
grid time in test_st_grid, the re-timings on it against 1 ms samples in test_retime); so must
the compiled point-to-segment test of the pair filter, and the compiled filter whole the
numpy form's pairs, in its order. The launch sweep of the rests'
shortening (compiled, a bucket sort) must give the least launch inside none of the intervals,
found by brute force over the candidate launches, and the numpy form's answer.
"""

from __future__ import annotations

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from trajopt.moving import MovingObstacle
from trajopt.moving._disc_windows import (
    close_pairs,
    disc_windows,
    inside_times,
    mover_pieces,
    near_pairs,
    track_knots,
)
from trajopt.moving._tighten import EPS_L, merged_spans, sweep, sweep_numpy


def _movers(rng, n):
    out = []
    for j in range(n):
        k = int(rng.integers(1, 6))
        times = np.sort(rng.uniform(-1.0, 12.0, size=k)) + np.arange(k) * 1e-3
        pos = rng.uniform(-3.0, 3.0, size=(k, 2))
        out.append(
            MovingObstacle.from_waypoints(
                times,
                pos,
                radius=float(rng.uniform(0.05, 0.5)),
                growth=float(rng.choice([0.0, 0.0, rng.uniform(0.0, 0.3)])),
                name=f"m{j}",
            )
        )
    return out


def _points(rng, n):
    # a wiggly polyline sampled densely, as path nodes are
    steps = rng.normal(scale=0.05, size=(n, 2)) + np.array([0.03, 0.0])
    return np.cumsum(steps, axis=0) + rng.uniform(-2.0, 0.0, size=2)


def _min_gap(pts, row, limit):
    """Least ``|point - centre(t)| - limit(t)`` over 2001 samples of the piece (brute force)."""
    u, w = row[1], row[2]
    w_end = u + 50.0 if not np.isfinite(w) else w
    tau = np.linspace(0.0, w_end - u, 2001)
    cx, cy = row[3] + row[5] * tau, row[4] + row[6] * tau
    lim = row[7] + limit + row[8] * tau
    d = np.hypot(pts[:, None, 0] - cx[None, :], pts[:, None, 1] - cy[None, :]) - lim[None, :]
    return d.min(axis=1)


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(0, 10_000), st.integers(1, 6), st.integers(1, 90))
def test_a_left_out_pair_never_comes_under_the_limit(seed, n_movers, n_points):
    rng = np.random.default_rng(seed)
    movers = _movers(rng, n_movers)
    pts = _points(rng, n_points)
    limit = float(rng.uniform(0.0, 0.4))
    pieces = mover_pieces(movers, 0.25)
    seg, pi = near_pairs(pts, pieces, limit)
    kept = np.zeros((pieces.shape[0], pts.shape[0]), bool)
    kept[seg, pi] = True
    assert np.unique(seg * pts.shape[0] + pi).shape[0] == seg.shape[0]  # no pair twice
    for p in range(pieces.shape[0]):
        gap = _min_gap(pts, pieces[p], limit)
        left_out = ~kept[p]
        assert np.all(gap[left_out] > 0.0), (p, gap[left_out].min())


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(0, 10_000), st.integers(1, 6), st.integers(1, 90))
def test_windows_on_the_kept_pairs_equal_those_on_every_pair(seed, n_movers, n_points):
    rng = np.random.default_rng(seed)
    movers = _movers(rng, n_movers)
    pts = _points(rng, n_points)
    limit = float(rng.uniform(0.0, 0.4))
    pieces = mover_pieces(movers, 0.25)
    every = np.ones((n_movers, n_points), bool)
    got = disc_windows(pts, pieces, limit)
    want = disc_windows(pts, pieces, limit, near=every)

    def key(w):
        who, pt, lo, hi = w
        order = np.lexsort((hi, lo, pt, who))
        return who[order], pt[order], lo[order], hi[order]

    for a, b in zip(key(got), key(want), strict=True):
        assert np.array_equal(a, b)


@settings(max_examples=40, deadline=None)
@given(
    st.lists(
        st.tuples(st.integers(0, 3), st.integers(0, 40), st.integers(0, 15)),
        min_size=1,
        max_size=30,
    )
)
def test_merged_spans_are_the_union_of_each_owners_spans(spans):
    owner = np.array([o for o, _, _ in spans], dtype=np.int64)
    a = np.array([x * 0.25 for _, x, _ in spans])
    b = a + np.array([d * 0.25 for _, _, d in spans])
    ma, mb, mo = merged_spans(a, b, owner)
    grid = np.arange(0.0, 14.0, 0.125)  # multiples of the ends' step and between them
    for o in np.unique(owner):
        sel = owner == o
        want = np.any((grid[:, None] >= a[sel]) & (grid[:, None] <= b[sel]), axis=1)
        got_sel = mo == o
        got = np.any((grid[:, None] >= ma[got_sel]) & (grid[:, None] <= mb[got_sel]), axis=1)
        assert np.array_equal(got, want)
        # disjoint and in order: each merged span starts after the previous one ended
        assert np.all(ma[got_sel][1:] > mb[got_sel][:-1])


def _pieces_one_by_one(movers, limit):
    """The rows of :func:`mover_pieces` written out mover by mover (``numpy.interp``)."""
    out = []
    for j, m in enumerate(movers):
        tk = m.times
        t_end = max(float(tk[-1]), 0.0) + 1.0
        knots = np.concatenate([[0.0], tk[(tk > 0.0) & (tk < t_end)], [t_end]])
        u, w = knots[:-1], knots[1:]
        mid = 0.5 * (u + w)
        px = np.interp(knots, tk, m.positions[:, 0])
        py = np.interp(knots, tk, m.positions[:, 1])
        inside = (mid > tk[0]) & (mid < tk[-1])
        span = w - u
        out.append(
            np.column_stack(
                [
                    np.full(u.shape, float(j)),
                    u,
                    np.where(w >= t_end, np.inf, w),
                    px[:-1],
                    py[:-1],
                    np.where(inside, np.diff(px) / span, 0.0),
                    np.where(inside, np.diff(py) / span, 0.0),
                    limit + m.radius + m.growth * np.clip(u, 0.0, max(m.t_last, 0.0)),
                    np.where(mid < m.t_last, m.growth, 0.0),
                ]
            )
        )
    return np.concatenate(out)


def _tracks(rng, n_movers):
    movers = []
    for j in range(n_movers):
        k = int(rng.integers(1, 7))
        times = np.cumsum(rng.uniform(0.05, 2.0, size=k)) + rng.choice([-4.0, -0.5, 0.0, 0.3])
        if k > 1 and rng.random() < 0.3:  # a waypoint exactly at t = 0
            times = times - times[rng.integers(k)]
        movers.append(
            MovingObstacle.from_waypoints(
                times,
                rng.uniform(-3.0, 3.0, size=(k, 2)),
                radius=float(rng.uniform(0.0, 0.5)),
                growth=float(rng.choice([0.0, rng.uniform(0.0, 0.2)])),
                name=f"m{j}",
            )
        )
    return movers


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**31 - 1), n_movers=st.integers(1, 6))
def test_the_pieces_of_all_movers_at_once_equal_those_one_by_one(seed, n_movers):
    rng = np.random.default_rng(seed)
    movers = _tracks(rng, n_movers)
    limit = float(rng.uniform(0.0, 0.3))
    np.testing.assert_array_equal(mover_pieces(movers, limit), _pieces_one_by_one(movers, limit))


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**31 - 1), n_movers=st.integers(1, 6))
def test_the_knots_of_a_range_equal_numpy_interp_mover_by_mover(seed, n_movers):
    rng = np.random.default_rng(seed)
    movers = _tracks(rng, n_movers)
    times = np.concatenate([m.times for m in movers])
    a = float(rng.choice([rng.uniform(-5.0, 8.0), rng.choice(times)]))  # at a waypoint, too
    b = a + float(rng.choice([rng.uniform(0.0, 6.0), 0.0]))
    if rng.random() < 0.3:  # one range per mover
        a = a + rng.uniform(0.0, 1.0, size=n_movers)
        b = a + rng.uniform(0.0, 4.0, size=n_movers)
    owner, knots, centre = track_knots(movers, a, b)
    aa, bb = np.broadcast_to(a, (n_movers,)), np.broadcast_to(b, (n_movers,))
    for j, m in enumerate(movers):
        tk = m.times
        kn = np.concatenate([[aa[j]], tk[(tk > aa[j]) & (tk < bb[j])], [bb[j]]])
        mine = owner == j
        np.testing.assert_array_equal(knots[mine], kn)
        for c in range(2):
            np.testing.assert_array_equal(centre[mine, c], np.interp(kn, tk, m.positions[:, c]))


def _inside_numpy(dx, dy, vx, vy, rr, g):
    """The closed form of ``inside_times`` written with numpy arrays (the reference)."""
    dx, dy, vx, vy, rr, g = np.broadcast_arrays(dx, dy, vx, vy, rr, g)
    a = vx * vx + vy * vy - g * g
    b = -2.0 * (dx * vx + dy * vy + rr * g)
    c = dx * dx + dy * dy - rr * rr
    with np.errstate(divide="ignore", invalid="ignore"):
        disc = b * b - 4.0 * a * c
        two = disc > 0
        sq = np.sqrt(np.maximum(disc, 0.0))
        q = -0.5 * (b + np.where(b > 0, sq, -sq))
        r1, r2 = q / a, c / q
        up = a > 0
        t_lo = np.where(two, np.where(up, np.minimum(r1, r2), np.maximum(r1, r2)), 0.0)
        t_lo = np.where(two, t_lo, np.where(up, np.inf, -np.inf))
        t_hi = np.where(up, np.where(two, np.maximum(r1, r2), -np.inf), np.inf)
        flat = np.abs(a) <= 1e-12
        lin = -c / b
        t_lo = np.where(flat, np.where(b < 0, lin, -np.inf), t_lo)
        t_hi = np.where(
            flat, np.where(b > 0, lin, np.where((b == 0) & (c >= 0), -np.inf, np.inf)), t_hi
        )
        t_lo = np.where(g > 0, np.maximum(t_lo, -rr / g), t_lo)
        t_lo = np.where((g > 0) | (rr > 0), t_lo, np.inf)
    return t_lo, t_hi


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**31 - 1))
def test_the_compiled_inside_times_equal_the_numpy_closed_form(seed):
    rng = np.random.default_rng(seed)
    n = 400

    def some(lo, hi, *special):
        x = rng.uniform(lo, hi, n)
        pick = rng.random(n) < 0.25
        return np.where(pick, rng.choice(np.array(special, dtype=float), n), x)

    dx, dy = some(-3.0, 3.0, 0.0, 0.5), some(-3.0, 3.0, 0.0, -1.0)
    vx, vy = some(-2.0, 2.0, 0.0, 1.0), some(-2.0, 2.0, 0.0, 0.3)
    rr = some(0.0, 1.0, 0.0, 0.4)
    g = np.where(rng.random(n) < 0.5, 0.0, rng.uniform(0.0, 2.0, n))
    g = np.where(rng.random(n) < 0.15, np.hypot(vx, vy), g)  # a = 0: linear
    got = inside_times(dx, dy, vx, vy, rr, g)
    want = _inside_numpy(dx, dy, vx, vy, rr, g)
    for x, y in zip(got, want, strict=True):
        np.testing.assert_array_equal(x, y)


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**31 - 1), n_movers=st.integers(1, 5))
def test_the_compiled_segment_test_equals_the_numpy_form(seed, n_movers):
    rng = np.random.default_rng(seed)
    pieces = mover_pieces(_tracks(rng, n_movers), 0.0)
    pts = _points(rng, 200)
    limit = float(rng.uniform(0.0, 0.3))
    seg = rng.integers(0, pieces.shape[0], 3000)
    point = rng.integers(0, pts.shape[0], 3000)
    # the numpy form: each piece's swept segment, the reach its limit at most plus the slack
    span = pieces[:, 2] - pieces[:, 1]
    still = (pieces[:, 5] == 0.0) & (pieces[:, 6] == 0.0)
    a = pieces[:, 3:5]
    b = a + pieces[:, 5:7] * np.where(still, 0.0, span)[:, None]
    with np.errstate(invalid="ignore"):
        grow = np.where(pieces[:, 8] > 0.0, pieces[:, 8] * span, 0.0)
    reach = pieces[:, 7] + limit + grow + 1e-6
    d = b - a
    dd = np.sum(d * d, axis=1)
    with np.errstate(divide="ignore"):
        inv = np.where(dd > 0.0, 1.0 / dd, 0.0)
    q = pts[point] - a[seg]
    f = np.clip(np.sum(q * d[seg], axis=1) * inv[seg], 0.0, 1.0)
    q = q - f[:, None] * d[seg]
    want = ~(q[:, 0] * q[:, 0] + q[:, 1] * q[:, 1] >= reach[seg] ** 2)
    np.testing.assert_array_equal(close_pairs(pts, pieces, limit, seg, point), want)


def _near_pairs_numpy(pts, pieces, limit, band=None):
    """The pair filter in numpy (the form the compiled one replaced): boxes of 16 points,
    each piece's grown segment box against them (and the boxes' time bands), then each
    pair's point-to-segment test and its own band."""
    n = pts.shape[0]
    span = pieces[:, 2] - pieces[:, 1]
    still = (pieces[:, 5] == 0.0) & (pieces[:, 6] == 0.0)
    a = pieces[:, 3:5]
    b = a + pieces[:, 5:7] * np.where(still, 0.0, span)[:, None]
    with np.errstate(invalid="ignore"):
        grow = np.where(pieces[:, 8] > 0.0, pieces[:, 8] * span, 0.0)
    reach = pieces[:, 7] + limit + grow + 1e-6
    starts = np.arange(0, n, 16)
    lo = np.minimum.reduceat(pts, starts, axis=0)
    hi = np.maximum.reduceat(pts, starts, axis=0)
    p_lo = np.minimum(a, b) - reach[:, None]
    p_hi = np.maximum(a, b) + reach[:, None]
    hit = (
        (p_lo[:, None, 0] <= hi[None, :, 0])
        & (p_hi[:, None, 0] >= lo[None, :, 0])
        & (p_lo[:, None, 1] <= hi[None, :, 1])
        & (p_hi[:, None, 1] >= lo[None, :, 1])
    )
    if band is not None:
        b_lo = np.minimum.reduceat(band[0], starts)
        b_hi = np.maximum.reduceat(band[1], starts)
        hit &= (pieces[:, 1, None] <= b_hi[None, :]) & (pieces[:, 2, None] >= b_lo[None, :])
    seg, box = np.nonzero(hit)
    first = starts[box]
    cnt = np.minimum(first + 16, n) - first
    seg = np.repeat(seg, cnt)
    point = np.repeat(first - np.cumsum(cnt) + cnt, cnt) + np.arange(int(cnt.sum()))
    keep = close_pairs(pts, pieces, limit, seg, point)
    if band is not None:
        keep &= (pieces[seg, 1] <= band[1][point]) & (pieces[seg, 2] >= band[0][point])
    return seg[keep], point[keep]


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(0, 2**31 - 1), st.integers(1, 6), st.integers(1, 150))
def test_the_compiled_pair_filter_equals_the_numpy_form(seed, n_movers, n_points):
    """The same pairs in the same order, with and without time bands (some infinite), on
    tracks whose last pieces stand for ever."""
    rng = np.random.default_rng(seed)
    pieces = mover_pieces(_movers(rng, n_movers), float(rng.uniform(0.0, 0.3)))
    pts = _points(rng, n_points)
    limit = float(rng.uniform(0.0, 0.4))
    b_lo = rng.uniform(-1.0, 10.0, n_points)
    b_hi = np.where(rng.random(n_points) < 0.3, np.inf, b_lo + rng.uniform(0.0, 5.0, n_points))
    for band in (None, (b_lo, b_hi)):
        got = near_pairs(pts, pieces, limit, band)
        want = _near_pairs_numpy(pts, pieces, limit, band)
        for x, y in zip(got, want, strict=True):
            np.testing.assert_array_equal(x, y)


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**31 - 1), n=st.integers(0, 120))
def test_the_launch_sweep_is_the_least_free_launch(seed, n):
    rng = np.random.default_rng(seed)
    f_lo = rng.uniform(-2.0, 10.0, n)
    if rng.random() < 0.5:
        f_lo = np.round(f_lo, 1)  # ties
    f_hi = f_lo + rng.exponential(0.4, n)
    if n and rng.random() < 0.3:  # a rest at the goal: from -inf
        f_lo[rng.integers(n)] = -np.inf
    if n and rng.random() < 0.3:  # a window that lasts
        f_hi[rng.integers(n)] = np.finfo(float).max
    lo = float(rng.choice([0.0, rng.uniform(-1.0, 5.0)]))
    got = sweep(f_lo, f_hi, lo)
    # brute force: the least candidate (lo, or an interval's end plus EPS_L) that no interval
    # ending after lo holds (open intervals, each extended by EPS_L)
    keep = f_hi > lo
    lo_k, end = f_lo[keep], f_hi[keep] + EPS_L
    cands = np.sort(np.append(end[end >= lo], lo))
    free = [c for c in cands if not np.any((lo_k < c) & (c < end))]
    assert got == free[0]
    assert got == sweep_numpy(f_lo, f_hi, lo)
