"""Tests of astar.reeds_shepp: Reeds-Shepp and Dubins shortest paths against OMPL and against brute force."""

from __future__ import annotations

import math

import numpy as np
import pytest

from astar import InvalidInputError
from astar.reeds_shepp import CarPath, dubins_path, reeds_shepp_path

N_PAIRS = 1000


def _wrap(a):
    return (np.asarray(a) + np.pi) % (2 * np.pi) - np.pi


def _pairs(seed: int, n: int = N_PAIRS) -> np.ndarray:
    """Random start/goal pairs, shape (n, 6); a tenth of them close together (the hard cases)."""
    rng = np.random.default_rng(seed)
    lo = np.array([-8.0, -8.0, -np.pi])
    s = rng.uniform(lo, -lo, (n, 3))
    g = rng.uniform(lo, -lo, (n, 3))
    near = rng.random(n) < 0.1
    g[near, :2] = s[near, :2] + rng.uniform(-1.5, 1.5, (int(near.sum()), 2))
    return np.hstack([s, g])


def _end_error(p: CarPath) -> float:
    poses, _ = p.sample(0.05)
    g = np.asarray(p.goal)
    return float(np.hypot(*(poses[-1, :2] - g[:2])) + abs(_wrap(poses[-1, 2] - g[2])))


def _walk(kinds, lens, radius):
    """End pose of a word from the origin by fine Euler steps (independent of the kernel)."""
    x = y = th = 0.0
    for k, s in zip(kinds, lens, strict=True):
        m = max(1, int(abs(s) / 1e-4))
        ds = s / m
        # the m steps' headings, added up one step after another (cumsum is sequential)
        ths = np.cumsum(np.concatenate([[th], np.full(m, k / radius * ds)]))
        # midpoint rule on the heading: exact for straight segments, O(ds^2) on arcs
        thm = ths[:-1] + 0.5 * k / radius * ds
        x = float(np.cumsum(np.concatenate([[x], ds * np.cos(thm)]))[-1])
        y = float(np.cumsum(np.concatenate([[y], ds * np.sin(thm)]))[-1])
        th = float(ths[-1])
    return x, y, th


@pytest.mark.parametrize("radius", [0.5, 1.0, 3.7])
def test_lengths_match_ompl(radius):
    ob = pytest.importorskip("ompl.base", reason="OMPL (pip install ompl) is the reference")
    rs = ob.ReedsSheppStateSpace(radius)
    du = ob.DubinsStateSpace(radius)
    a, b = rs.allocState(), rs.allocState()
    c, d = du.allocState(), du.allocState()
    worst_rs = worst_du = 0.0
    for row in _pairs(int(radius * 10)):
        for st, v in ((a, row[:3]), (b, row[3:]), (c, row[:3]), (d, row[3:])):
            st.setX(float(v[0]))
            st.setY(float(v[1]))
            st.setYaw(float(v[2]))
        worst_rs = max(
            worst_rs, abs(reeds_shepp_path(row[:3], row[3:], radius).length - rs.distance(a, b))
        )
        worst_du = max(
            worst_du, abs(dubins_path(row[:3], row[3:], radius).length - du.distance(c, d))
        )
    assert worst_rs < 1e-9 * radius * 100
    assert worst_du < 1e-9 * radius * 100


@pytest.mark.parametrize("reverse", [True, False])
def test_word_reaches_goal_and_is_a_car_path(reverse):
    radius = 1.3
    fn = reeds_shepp_path if reverse else dubins_path
    for row in _pairs(7, 500):
        p = fn(row[:3], row[3:], radius)
        assert _end_error(p) < 1e-9
        assert set(p.kinds) <= set("LSR") and len(p.kinds) <= 5
        assert np.all(np.abs(p.curvatures) <= 1 / radius + 1e-15)
        assert math.isclose(p.length, np.abs(p.lengths).sum())
        if reverse:
            assert p.cusps <= 2
        else:
            assert np.all(p.lengths >= 0) and p.cusps == 0
    # an independent integration of a few words lands on the goal too
    for row in _pairs(8, 5):
        p = fn(row[:3], row[3:], radius)
        k = [{"L": 1, "S": 0, "R": -1}[c] for c in p.kinds]
        x, y, th = _walk(k, p.lengths, radius)
        c, s = math.cos(row[2]), math.sin(row[2])
        gx, gy = row[0] + c * x - s * y, row[1] + s * x + c * y
        assert math.hypot(gx - row[3], gy - row[4]) < 1e-3
        assert abs(_wrap(row[2] + th - row[5])) < 1e-6


@pytest.mark.parametrize("reverse", [True, False])
def test_no_random_word_is_shorter(reverse):
    """Brute force: every sampled word (up to 5 segments, any kinds, cusps when reversing)
    is a feasible path to its own end pose, so the shortest path there is no longer."""
    rng = np.random.default_rng(3 if reverse else 4)
    radius = 1.0
    fn = reeds_shepp_path if reverse else dubins_path
    for _ in range(1500):
        n = int(rng.integers(1, 6))
        kinds = rng.integers(-1, 2, n)
        lens = rng.uniform(0.0, 4.0, n) * (rng.choice([-1.0, 1.0], n) if reverse else 1.0)
        start = rng.uniform(-3, 3, 3)
        p = CarPath(tuple(start), tuple(start), radius, "".join("RSL"[k + 1] for k in kinds), lens)
        poses, _ = p.sample(0.5)
        end = poses[-1].copy()
        assert fn(start, end, radius).length <= np.abs(lens).sum() + 1e-9


def test_special_cases():
    # straight behind: one backward segment of the distance
    p = reeds_shepp_path(
        (1.0, 2.0, 0.5), (1.0 - 3 * math.cos(0.5), 2.0 - 3 * math.sin(0.5), 0.5), 2.0
    )
    assert math.isclose(p.length, 3.0) and p.cusps == 0 and p.directions[p.lengths != 0][0] == -1
    # same pose: length 0
    assert reeds_shepp_path((0, 0, 1), (0, 0, 1), 1.0).length == pytest.approx(0.0, abs=1e-12)
    # Dubins straight behind: must turn round, at least 2 pi R in arcs... longer than 2 R pi
    d = dubins_path((0, 0, 0), (-1, 0, 0), 1.0)
    assert d.length > 2 * math.pi and d.cusps == 0
    # Reeds-Shepp is symmetric in start and goal; Dubins is not in general
    rng = np.random.default_rng(5)
    for row in rng.uniform(-4, 4, (200, 6)):
        a = reeds_shepp_path(row[:3], row[3:], 1.5).length
        b = reeds_shepp_path(row[3:], row[:3], 1.5).length
        assert a == pytest.approx(b, abs=1e-9)
    # scale: lengths scale with R
    assert reeds_shepp_path((0, 0, 0), (2, 2, 1), 2.0).length == pytest.approx(
        2 * reeds_shepp_path((0, 0, 0), (1, 1, 1), 1.0).length
    )


@pytest.mark.parametrize("radius", [0.0, -1.0, math.nan, math.inf, "one", True])
def test_bad_radius(radius):
    with pytest.raises(InvalidInputError, match="turning_radius"):
        reeds_shepp_path((0, 0, 0), (1, 0, 0), radius)


@pytest.mark.parametrize("pose", [(0, 0), (0, 0, math.nan), "abc", (0, 0, 0, 0)])
def test_bad_pose(pose):
    with pytest.raises(InvalidInputError, match="goal"):
        dubins_path((0, 0, 0), pose, 1.0)
    with pytest.raises(InvalidInputError, match="step"):
        dubins_path((0, 0, 0), (1, 1, 1), 1.0).sample(0.0)
