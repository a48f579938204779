"""Tests of astar.hybrid_shortcut: fewer cusps, never a dearer path, never a blocked word.

The reference is written here: each piece re-integrated in closed form with numpy, the
search's cost (backwards length times the reverse penalty, arcs times ``1 + turn_penalty``,
a cusp cost per change of direction) summed by hand, and every new piece's reference point
sampled every 0.01 cells against the free cells (the plain mode's guarantee). The footprint
mode's bodies are checked by brute force on whole searches in ``test_hybrid_footprint.py``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from astar.hybrid import find_pose_path
from astar.hybrid_modes import kernel_collision
from astar.hybrid_options import HybridCollision
from astar.hybrid_shortcut import shorten_cusps

WEIGHTS = (2.0, 4.0, 1.05)  # reverse penalty, cusp cost (cells), 1 + turn penalty


def _end(p):
    """A piece's end pose, in closed form."""
    x, y, th, k, s = p
    if k == 0.0:
        return x + s * math.cos(th), y + s * math.sin(th), th
    return x + (math.sin(th + k * s) - math.sin(th)) / k, y - (math.cos(th + k * s) - math.cos(th)) / k, th + k * s  # fmt: skip


def _chain(start, moves):
    """Pieces from ``start`` driving ``moves`` = [(curvature, signed length), ...]."""
    out, pose = [], start
    for k, s in moves:
        out.append([*pose, k, s])
        pose = _end(out[-1])
    return np.array(out), pose


def _cusps(pieces):
    d = np.sign(pieces[:, 4])
    return int(np.count_nonzero(d[1:] != d[:-1]))


def _cost(pieces):
    rev, cusp, arc = WEIGHTS
    s, k = pieces[:, 4], pieces[:, 3]
    w = np.where(s < 0, rev, 1.0) * np.where(k != 0, arc, 1.0)
    return float(np.sum(np.abs(s) * w) + cusp * _cusps(pieces))


def _plain(free):
    free8 = np.ascontiguousarray(free, dtype=np.uint8)
    return free8, kernel_collision(HybridCollision(), free8, 0.2, ())


def _dense(p, ds=0.01):
    x, y, th, k, s = p
    q = np.linspace(0.0, s, max(2, int(abs(s) / ds) + 2))
    if k == 0.0:
        return np.column_stack([x + q * math.cos(th), y + q * math.sin(th)])
    return np.column_stack(
        [x + (np.sin(th + k * q) - math.sin(th)) / k, y - (np.cos(th + k * q) - math.cos(th)) / k]
    )


def test_back_and_fill_in_the_open_becomes_one_straight_drive():
    """Forwards 10, backwards 3, forwards 10 along a line: the word is 17 forwards, no cusp."""
    free, kc = _plain(np.ones((40, 60), bool))
    pieces, end = _chain((20.0, 20.0, 0.0), [(0.0, 10.0), (0.0, -3.0), (0.0, 10.0)])
    out = shorten_cusps(free, pieces, end, 5.0, WEIGHTS, kc, 0.5)
    assert out is not None
    poses, directions, segments, new, replaced, _ = out
    assert replaced == 1 and len(segments) == 1 and np.all(directions == 1)
    np.testing.assert_allclose(new[:, 4].sum(), 17.0, atol=1e-9)
    np.testing.assert_allclose(poses[0], (20.0, 20.0, 0.0), atol=1e-12)
    np.testing.assert_allclose(poses[-1], (37.0, 20.0, 0.0), atol=1e-9)
    assert np.all(np.hypot(*np.diff(poses[:, :2], axis=0).T) <= 0.5 + 1e-9)


def test_nothing_cheaper_leaves_the_path_as_it_is():
    """One straight drive and one clean reverse-S: no stretch with a cusp has a cheaper word."""
    free, kc = _plain(np.ones((40, 60), bool))
    pieces, end = _chain((20.0, 20.0, 0.0), [(0.0, 10.0)])
    assert shorten_cusps(free, pieces, end, 5.0, WEIGHTS, kc, 0.5) is None
    # forwards then backwards to a pose behind and beside: the cusp is needed
    pieces, end = _chain((20.0, 20.0, 0.0), [(0.0, 6.0), (0.2, -4.0), (-0.2, -4.0)])
    out = shorten_cusps(free, pieces, end, 5.0, WEIGHTS, kc, 0.5)
    if out is not None:  # a cheaper word may exist; it must then keep the one cusp at most
        assert _cusps(out[3]) <= 1 and _cost(out[3]) < _cost(pieces)


def test_a_wall_keeps_the_detour():
    """The straight word would cross a wall the path drives round: it is not taken."""
    occ = np.zeros((40, 60), bool)
    occ[14:26, 30] = True  # a wall across the line y = 20 at x = 30
    free, kc = _plain(~occ)
    # round the wall's top end (y 27): up, along, down, with a needless back-and-fill
    moves = [(0.0, 4.0), (0.2, 7.853981633974483), (-0.2, 7.853981633974483), (0.0, 2.0),
             (0.0, -1.0), (0.0, 3.0), (-0.2, 7.853981633974483), (0.2, 7.853981633974483)]  # fmt: skip
    pieces, end = _chain((15.0, 20.0, 0.0), moves)
    pts = np.vstack([_dense(p) for p in pieces])
    ij = np.floor(pts + 0.5).astype(int)
    assert free[ij[:, 1], ij[:, 0]].all()  # the input path itself is clear
    out = shorten_cusps(free, pieces, end, 5.0, WEIGHTS, kc, 0.5)
    assert out is not None
    new = out[3]
    pts = np.vstack([_dense(p) for p in new])
    ij = np.floor(pts + 0.5).astype(int)
    assert free[ij[:, 1], ij[:, 0]].all()
    assert _cusps(new) < _cusps(pieces) and _cost(new) < _cost(pieces)
    assert pts[:, 1].max() > 26.0  # still round the wall's end


@pytest.mark.parametrize("seed", range(12))
def test_random_paths_never_get_dearer_more_cusped_or_blocked(seed):
    """Random back-and-fill paths on random maps (the cells the path crosses cleared): the
    output joins up in closed form, ends at the same pose, has no more cusps and no higher
    cost, and keeps its reference point on free cells (dense samples)."""
    rng = np.random.default_rng(seed)
    occ = rng.random((50, 70)) < 0.06
    moves = [(float(rng.choice([-0.2, 0.0, 0.2])), float(rng.uniform(1.0, 5.0) * rng.choice([-1, 1])))
             for _ in range(int(rng.integers(3, 9)))]  # fmt: skip
    pieces, end = _chain((35.0, 25.0, float(rng.uniform(-3, 3))), moves)
    ij = np.floor(np.vstack([_dense(p) for p in pieces]) + 0.5).astype(int)
    occ[ij[:, 1], ij[:, 0]] = False  # the input path is clear
    free, kc = _plain(~occ)
    out = shorten_cusps(free, pieces, end, 5.0, WEIGHTS, kc, 0.5)
    if out is None:
        return
    poses, directions, segments, new, replaced, tests = out
    assert replaced >= 1 and tests >= replaced
    for a, b in zip(new[:-1], new[1:], strict=True):  # joined: each piece starts where one ends
        np.testing.assert_allclose(_end(a), b[:3], atol=1e-7)
    np.testing.assert_allclose(_end(new[-1])[:2], end[:2], atol=1e-7)
    assert abs(math.remainder(_end(new[-1])[2] - end[2], 2 * math.pi)) < 1e-7
    np.testing.assert_allclose(new[0, :3], pieces[0, :3], atol=1e-12)
    assert _cusps(new) <= _cusps(pieces) and _cost(new) <= _cost(pieces) + 1e-9
    assert len(segments) == _cusps(new) + 1
    ij = np.floor(np.vstack([_dense(p) for p in new]) + 0.5).astype(int)
    inside = (ij[:, 0] >= 0) & (ij[:, 0] < 70) & (ij[:, 1] >= 0) & (ij[:, 1] < 50)
    assert inside.all() and free[ij[:, 1], ij[:, 0]].all()
    # the poses follow the pieces: headings continuous, directions those of the pieces
    assert np.all(np.abs(np.diff(poses[:, 2])) <= 0.5 * 0.2 + 1e-9)
    assert set(np.unique(directions)) <= {-1, 1}


def test_the_search_reports_its_shortcuts():
    """A search whose path backs and fills gets fewer cusps, and its stats say how many."""
    free = np.ones((40, 60), bool)
    p = find_pose_path(free, (10.0, 20.0, 0.0), (14.0, 24.0, math.pi), turning_radius=5.0)
    sc = p.stats["shortcut"]
    assert p.cusps <= sc["cusps_before"] and sc["replaced"] >= 0
    assert p.stats["shortcut_s"] >= 0.0
    fwd = find_pose_path(
        free, (10.0, 20.0, 0.0), (40.0, 24.0, 0.0), turning_radius=5.0, reverse=False
    )
    assert "shortcut" not in fwd.stats  # forwards only: no cusp to remove
