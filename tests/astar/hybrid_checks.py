"""Independent checks of Hybrid-A* pose paths, shared by the astar search tests.

``check_path`` (the grid, the ends, the joins, the curvature, the direction rules),
``check_footprint_path`` (the body against the raw map's squares at dense poses, by brute
force), ``polyline_clearance`` (the exact mode's chords) and the footprints and grids they
use; the tests of ``astar.hybrid``, its footprint mode and its search from the goal call them.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import astar
from astar.hybrid import PosePath

TOL = 1e-9  # cells: rounding of the closed forms

SMALL = np.array([[-0.5, -0.5], [1.5, -0.5], [1.5, 0.5], [-0.5, 0.5]])  # 2 x 1, origin at the rear
REAR = np.array([[-0.5, -1.0], [3.5, -1.0], [3.5, 1.0], [-0.5, 1.0]])  # origin at the rear


def wrap(a):
    return (np.asarray(a) + np.pi) % (2 * np.pi) - np.pi


def inflated(occ: np.ndarray, r: float) -> np.ndarray:
    """Free cells whose centre keeps ``r`` from every occupied square (and the outside)."""
    g = astar.OccupancyGrid(occ, 1.0)
    return ~astar.inflate(g, r, metric="square", outside_occupied=True).occupied


def dense_poses(p: PosePath, spacing: float = 0.01) -> np.ndarray:
    """Poses ``(x, y, heading)`` along the exact pieces, at most ``spacing`` apart (own closed form)."""
    out = [p.pieces[0, :3][None, :]]
    x, y, th = p.pieces[0, :3]
    for px, py, pth, k, s in p.pieces:
        assert math.hypot(px - x, py - y) < 1e-9 and abs(wrap(pth - th)) < 1e-9
        m = max(1, math.ceil(abs(s) / spacing))
        t = s * np.arange(1, m + 1) / m
        if k == 0.0:
            q = np.column_stack([px + t * math.cos(pth), py + t * math.sin(pth), np.full(m, pth)])
        else:
            a = pth + k * t
            q = np.column_stack(
                [px + (np.sin(a) - math.sin(pth)) / k, py - (np.cos(a) - math.cos(pth)) / k, a]
            )
        out.append(q)
        x, y, th = q[-1]
    return np.concatenate(out)


def body_points(
    poly: np.ndarray, spacing: float = 0.01, inner: float = 0.1
) -> tuple[np.ndarray, np.ndarray]:
    """Boundary samples ``spacing`` apart and interior grid points ``inner`` apart (robot frame).

    The interior grid only has to catch an occupied square lying wholly inside the body (any
    other square that meets the body meets its boundary): a closed unit square contains a
    point of any grid of spacing < 1, so 0.1 is plenty.
    """
    poly = np.asarray(poly, float)
    edges = []
    for a, b in zip(poly, np.roll(poly, -1, axis=0), strict=True):
        m = max(1, math.ceil(np.hypot(*(b - a)) / spacing))
        edges.append(a + (b - a) * (np.arange(m) / m)[:, None])
    boundary = np.concatenate(edges)
    lo, hi = poly.min(axis=0), poly.max(axis=0)
    gx, gy = np.meshgrid(np.arange(lo[0], hi[0], inner), np.arange(lo[1], hi[1], inner))
    pts = np.column_stack([gx.ravel(), gy.ravel()])
    # inside: on the inner side of every edge (either orientation)
    e = np.roll(poly, -1, axis=0) - poly
    cross = e[:, 0][None] * (pts[:, 1][:, None] - poly[:, 1][None]) - e[:, 1][None] * (
        pts[:, 0][:, None] - poly[:, 0][None]
    )
    inside = np.all(cross >= 0, axis=1) | np.all(cross <= 0, axis=1)
    return boundary, pts[inside]


def square_distance(pts: np.ndarray, occ: np.ndarray, cells=None) -> np.ndarray:
    """Distance (cells) from each point to the nearest occupied square or the grid's outside.

    ``cells``: ``(ix, iy)`` arrays of the occupied cells to consider (default: all).
    """
    ny, nx = occ.shape
    iy, ix = np.nonzero(occ) if cells is None else (cells[1], cells[0])
    out = np.minimum.reduce(
        [pts[:, 0] + 0.5, nx - 0.5 - pts[:, 0], pts[:, 1] + 0.5, ny - 0.5 - pts[:, 1]]
    )
    out = np.maximum(out, 0.0)
    for j in range(0, len(ix), 256):
        dx = np.maximum(np.abs(pts[:, 0][:, None] - ix[j : j + 256][None]) - 0.5, 0.0)
        dy = np.maximum(np.abs(pts[:, 1][:, None] - iy[j : j + 256][None]) - 0.5, 0.0)
        out = np.minimum(out, np.hypot(dx, dy).min(axis=1))
    return out


def body_collisions(
    poses: np.ndarray, poly: np.ndarray, occ: np.ndarray, margin: float = 0.0
) -> np.ndarray:
    """Indices of the poses whose body meets an occupied square or leaves the grid.

    A pose is tested point by point when its centre is within ``rho + margin + 0.02`` of an
    obstacle or the outside (farther, no body point can be: every point lies within ``rho``
    of the centre). No point may lie in an occupied square or outside the grid; with
    ``margin > 0`` the boundary points must also keep more than ``margin`` (less ``TOL``)
    from the squares and the outside.
    """
    ny, nx = occ.shape
    boundary, interior = body_points(poly)
    rho = float(np.hypot(poly[:, 0], poly[:, 1]).max())
    near = np.nonzero(square_distance(poses[:, :2], occ) <= rho + margin + 0.02)[0]
    pad = np.ones((ny + 2, nx + 2), bool)
    pad[1:-1, 1:-1] = occ
    oy, ox = np.nonzero(occ)
    px, py = np.concatenate([boundary, interior]).T
    flat = pad.ravel()
    hit = np.zeros(len(near), bool)
    # the near poses' bodies, a chunk of poses at a time as (poses, points) arrays; a point's
    # square (ix, iy), clipped to the pad's ring outside the grid, is pad[iy + 1, ix + 1]
    for j in range(0, len(near), 64):
        x, y, th = poses[near[j : j + 64]].T
        c, s = np.cos(th)[:, None], np.sin(th)[:, None]
        wx = c * px - s * py + x[:, None] + 0.5
        wy = s * px + c * py + y[:, None] + 0.5
        np.clip(np.floor(wx, out=wx), -1, nx, out=wx)
        np.clip(np.floor(wy, out=wy), -1, ny, out=wy)
        hit[j : j + 64] = flat[((wy + 1) * (nx + 2) + wx + 1).astype(np.intp)].any(axis=1)
    if margin > 0.0:
        for n in np.nonzero(~hit)[0]:
            x, y, th = poses[near[n]]
            c, s = math.cos(th), math.sin(th)
            b = boundary @ np.array([[c, s], [-s, c]]) + (x, y)
            reach = rho + margin + 1.0
            k = (np.abs(ox - x) <= reach) & (np.abs(oy - y) <= reach)
            hit[n] = bool((square_distance(b, occ, (ox[k], oy[k])) <= margin - TOL).any())
    return near[hit].astype(int)


def check_footprint_path(p, occ, poly, start, goal, margin=0.0):
    poses = dense_poses(p)
    np.testing.assert_allclose(poses[0], start, atol=1e-12)
    assert math.hypot(poses[-1, 0] - goal[0], poses[-1, 1] - goal[1]) < 1e-9
    assert abs(wrap(poses[-1, 2] - goal[2])) < 1e-9
    assert p.poses[-1, 0] == goal[0] and p.poses[-1, 1] == goal[1]
    assert p.stats["footprint"] is True and p.stats["footprint_margin"] == margin
    bad = body_collisions(poses, poly, occ, margin)
    assert len(bad) == 0, f"the body collides at {poses[bad[:3]].tolist()}"


def check_path(p: PosePath, free: np.ndarray, start, goal, radius: float) -> None:
    """Independent checks of a returned path against the grid and the car's rules."""
    free = np.asarray(free, bool)
    ny, nx = free.shape
    pc = p.pieces
    assert pc.shape[1] == 5 and pc.shape[0] >= 1
    # curvature of every piece within 1/R; no empty pieces
    assert np.all(np.abs(pc[:, 3]) <= 1.0 / radius * (1 + 1e-12))
    assert np.all(pc[:, 4] != 0.0)
    # dense resampling of the pieces (0.01 cells), by a midpoint integration of our own
    pts = []
    x, y, th = pc[0, :3]
    assert np.allclose([x, y], start[:2], atol=1e-12) and abs(wrap(th - start[2])) < 1e-12
    for px, py, pth, k, s in pc:
        # each piece starts where the previous one ended
        assert math.hypot(px - x, py - y) < 1e-9 and abs(wrap(pth - th)) < 1e-9
        m = max(1, int(abs(s) / 0.01))
        ds = s / m
        # the chord of each step: length 2 sin(k ds / 2) / k along the mid-step heading
        chord = ds if k == 0 else 2.0 * math.sin(0.5 * k * ds) / k
        # the m steps added up one after another (cumsum is sequential), from the piece's start
        ths = np.cumsum(np.concatenate([[pth], np.full(m, k * ds)]))
        thm = ths[:-1] + 0.5 * k * ds
        xs = np.cumsum(np.concatenate([[px], chord * np.cos(thm)]))[1:]
        ys = np.cumsum(np.concatenate([[py], chord * np.sin(thm)]))[1:]
        x, y, th = xs[-1], ys[-1], ths[-1]
        pts.append(np.column_stack([xs, ys]))
    pts = np.concatenate(pts)
    ix = np.floor(pts[:, 0] + 0.5).astype(int)
    iy = np.floor(pts[:, 1] + 0.5).astype(int)
    inside = (ix >= 0) & (ix < nx) & (iy >= 0) & (iy < ny)
    assert inside.all(), "the path leaves the grid"
    assert free[iy, ix].all(), f"collision at {pts[~free[iy, ix]][:3].tolist()}"
    # the integration lands on the goal; the returned end pose is the goal exactly
    assert math.hypot(x - goal[0], y - goal[1]) < 1e-9 and abs(wrap(th - goal[2])) < 1e-9
    assert p.poses[-1, 0] == goal[0] and p.poses[-1, 1] == goal[1]
    assert abs(wrap(p.poses[-1, 2] - goal[2])) < 1e-12
    assert np.all(p.poses[0] == np.asarray(start, float))
    # poses: motion along the heading (forwards or backwards as `directions` says)
    d = np.diff(p.poses[:, :2], axis=0)
    step = np.hypot(d[:, 0], d[:, 1])
    mid = p.poses[:-1, 2] + 0.5 * np.diff(p.poses[:, 2])
    along = d[:, 0] * np.cos(mid) + d[:, 1] * np.sin(mid)
    assert np.all(np.sign(along[step > 1e-9]) == p.directions[1:][step > 1e-9])
    assert np.allclose(np.abs(along), step, rtol=1e-6, atol=1e-9)
    # curvature from the poses: a chord c of an arc of radius >= R turns by <= 2 asin(c / 2R)
    turn = np.abs(np.diff(p.poses[:, 2]))
    assert np.all(turn <= 2 * np.arcsin(np.minimum(1.0, step / (2 * radius))) * (1 + 1e-9) + 1e-12)
    # segments: contiguous, shared cusp poses, one direction each, flips between them
    seg = p.segments
    assert seg[0, 0] == 0 and seg[-1, 1] == len(p) - 1
    assert np.all(seg[1:, 0] == seg[:-1, 1])
    for a, b in seg:
        assert len(set(p.directions[a + 1 : b + 1].tolist())) == 1
    dirs = [p.directions[b] for _, b in seg]
    assert all(u != v for u, v in zip(dirs[:-1], dirs[1:], strict=True))
    assert p.cusps == len(seg) - 1 == int(np.count_nonzero(np.diff(np.sign(pc[:, 4]))))
    assert p.length == pytest.approx(np.abs(pc[:, 4]).sum())
    assert p.reverse_length == pytest.approx(-pc[pc[:, 4] < 0, 4].sum())


def world(occ: np.ndarray) -> astar.OccupancyGrid:
    """The raw grid with cell ``(ix, iy)``'s centre at the world point ``(ix, iy)``."""
    return astar.OccupancyGrid(occ, 1.0, (-0.5, -0.5))


def polyline_clearance(grid, poses, spacing=0.01):
    from tests.reference import polyline_samples, square_clearance

    return square_clearance(grid, polyline_samples(np.asarray(poses)[:, :2], spacing)).min()
