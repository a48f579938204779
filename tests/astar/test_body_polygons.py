"""Tests of astar.body_polygons and OccupancyGrid.polygons: the exact body-to-polygon distance.

References: a brute force by dense point sampling of the body (its boundary and interior 2 mm
apart, its interior 1 cm apart) and of the polygons' boundaries, with an even-odd test of each sample written here,
on random convex bodies against random simple polygons (convex or not); hand-built poses
whose answer is known (touching, 1 cm apart, containment either way).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial import cKDTree

import astar
from astar.body_polygons import pack_polygons

SPACING = 0.002  # m, the brute force's sampling


def star(rng: np.random.Generator, centre: np.ndarray, n: int) -> np.ndarray:
    """A random simple polygon: ``n`` vertices at increasing angles round ``centre``."""
    a = np.sort(rng.uniform(0.0, 2.0 * math.pi, n))
    r = rng.uniform(0.2, 1.2, n)
    return centre + np.column_stack([r * np.cos(a), r * np.sin(a)])


def convex_body(rng: np.random.Generator) -> np.ndarray:
    """A random convex body about its reference point (counter-clockwise)."""
    a = np.sort(rng.uniform(0.0, 2.0 * math.pi, rng.integers(3, 7)))
    r = rng.uniform(0.3, 1.0)
    return np.column_stack([r * np.cos(a), r * np.sin(a)]) + rng.uniform(-0.2, 0.2, 2)


def ring_points(v: np.ndarray, step: float) -> np.ndarray:
    """Points along the closed ring ``v`` at most ``step`` apart (its vertices included)."""
    out = []
    for a, b in zip(v, np.roll(v, -1, axis=0), strict=True):
        n = max(1, math.ceil(np.hypot(*(b - a)) / step))
        out.append(a + (np.arange(n) / n)[:, None] * (b - a))
    return np.vstack(out)


def even_odd(points: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Whether each point lies inside the ring ``v`` (even-odd crossings of a ray to +x)."""
    inside = np.zeros(len(points), bool)
    for a, b in zip(v, np.roll(v, -1, axis=0), strict=True):
        crosses = (a[1] > points[:, 1]) != (b[1] > points[:, 1])
        with np.errstate(divide="ignore", invalid="ignore"):
            x = a[0] + (points[:, 1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1])
        inside ^= crosses & (points[:, 0] < x)
    return inside


def brute(body: np.ndarray, polys: list[np.ndarray]) -> tuple[bool, float]:
    """(overlap, distance) by dense sampling: the body's boundary or interior samples inside
    a polygon, or a polygon's boundary samples inside the body, overlap; else the least
    distance between the boundary samples (within the sampling step of the true one)."""
    edge = ring_points(body, SPACING)
    lo, hi = body.min(axis=0), body.max(axis=0)
    gx, gy = np.meshgrid(np.arange(lo[0], hi[0], 0.01), np.arange(lo[1], hi[1], 0.01))
    grid = np.column_stack([gx.ravel(), gy.ravel()])
    inner = grid[even_odd(grid, body)]
    pts = np.vstack([edge, inner])
    best = math.inf
    for v in polys:
        if even_odd(pts, v).any():
            return True, 0.0
        rim = ring_points(v, SPACING)
        if even_odd(rim, body).any():
            return True, 0.0
        best = min(best, float(cKDTree(rim).query(edge)[0].min()))
    return False, best


def test_distance_agrees_with_dense_sampling_on_random_shapes():
    rng = np.random.default_rng(7)
    checked = overlaps = 0
    for _ in range(60):
        body_ref = convex_body(rng)
        polys = [star(rng, rng.uniform(-1.5, 1.5, 2), int(rng.integers(3, 9))) for _ in range(3)]
        pose = np.array([[*rng.uniform(-1.0, 1.0, 2), rng.uniform(-math.pi, math.pi)]])
        c, s = math.cos(pose[0, 2]), math.sin(pose[0, 2])
        body = pose[0, :2] + body_ref @ np.array([[c, s], [-s, c]])
        got = float(astar.bodies_distance(body_ref, pose, polys)[0])
        hit, d = brute(body, polys)
        if not hit and d < 2 * SPACING:
            continue  # too close to call by sampling
        checked += 1
        overlaps += hit
        if hit:
            assert got == 0.0
        else:
            # the sampled distance is an upper bound within the sampling step
            assert got > 0.0 and got <= d + 1e-12 and got >= d - SPACING
    assert checked >= 50 and 10 <= overlaps <= checked - 10


def test_touching_near_and_containment():
    body = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    at = np.array([[0.0, 0.0, 0.0]])
    square = np.array([[1.0, 0.2], [2.0, 0.2], [2.0, 0.8], [1.0, 0.8]])
    assert astar.bodies_distance(body, at, [square])[0] == 0.0  # touching counts
    assert astar.bodies_distance(body, at, [square + (0.01, 0.0)])[0] == pytest.approx(0.01)
    big = np.array([[-5.0, -5.0], [5.0, -5.0], [5.0, 5.0], [-5.0, 5.0]])
    assert astar.bodies_distance(body, at, [big])[0] == 0.0  # the body inside
    tiny = np.array([[0.4, 0.4], [0.6, 0.4], [0.5, 0.6]])
    assert astar.bodies_distance(body, at, [tiny])[0] == 0.0  # a polygon inside the body
    # a notch: the body in the mouth of a U, 5 cm from each arm and from its bottom
    u = np.array(
        [[-1.0, -1.0], [2.0, -1.0], [2.0, 2.0], [1.05, 2.0], [1.05, -0.05], [-0.05, -0.05],
         [-0.05, 2.0], [-1.0, 2.0]]
    )  # fmt: skip
    assert astar.bodies_distance(body, at, [u])[0] == pytest.approx(0.05)
    # either orientation of the body, a capped distance
    assert astar.bodies_distance(body[::-1], at, [u])[0] == pytest.approx(0.05)
    assert astar.bodies_distance(body, at, [u], cap=0.02)[0] == 0.02


def test_points_distance_agrees_with_sampling():
    rng = np.random.default_rng(3)
    polys = [star(rng, np.array([0.0, 0.0]), 7), star(rng, np.array([2.0, 0.5]), 5)]
    pts = rng.uniform(-1.5, 3.5, (300, 2))
    got = astar.points_distance(pts, polys)
    rims = np.vstack([ring_points(v, 0.001) for v in polys])
    inside = np.any([even_odd(pts, v) for v in polys], axis=0)
    ref = np.hypot(*(pts[:, None, :] - rims[None, :, :]).transpose(2, 0, 1)).min(axis=1)
    assert np.all(got[inside] == 0.0)
    np.testing.assert_allclose(got[~inside], ref[~inside], atol=0.001)
    assert np.all(got[~inside] <= ref[~inside] + 1e-12)


def test_grid_keeps_its_polygons_where_the_cells_still_cover_them():
    tri = [(0.23, 0.21), (0.61, 0.22), (0.4, 0.63)]
    g = astar.OccupancyGrid.from_polygons([tri], 0.1, (0.0, 0.0, 1.0, 1.0))
    assert len(g.polygons) == 1 and not g.polygons[0].flags.writeable
    for kept in (g.split(2), g.coarsen(3)):
        assert kept.polygons is g.polygons
    moved = g.moved_to((5.0, -2.0))
    np.testing.assert_allclose(moved.polygons[0], g.polygons[0] + (5.0, -2.0))
    assert moved.occupied is g.occupied or np.array_equal(moved.occupied, g.occupied)
    assert g.with_occupied(g.occupied).polygons is None  # new occupancy: dropped
    assert astar.OccupancyGrid(g.occupied, 0.1).polygons is None
    assert g == g.with_occupied(g.occupied)  # equality ignores them
    # every polygon point lies in an occupied square of each grid that keeps them
    pts = np.vstack([np.asarray(tri)] + [np.asarray(tri).mean(axis=0)[None]])
    for h in (g, g.split(2), g.coarsen(3), moved):
        cells = h.world_to_cell(pts - np.asarray(g.origin) + np.asarray(h.origin))
        assert h.occupied[cells[:, 1], cells[:, 0]].all()


def test_packed_polygons_in_cells():
    v = np.array([[1.0, 1.0], [2.0, 1.0], [1.5, 2.0]])
    edges, starts, boxes = pack_polygons([v], (0.5, 0.5), 0.5)
    np.testing.assert_allclose(edges[0], [1.0, 1.0, 3.0, 1.0])
    assert starts.tolist() == [0, 3]
    np.testing.assert_allclose(boxes[0], [1.0, 1.0, 3.0, 3.0])
    e, s, b = pack_polygons(None)
    assert e.shape == (0, 4) and s.tolist() == [0] and b.shape == (0, 4)
