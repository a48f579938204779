"""Distances the metrics measure: to a polyline, between polylines, to the map's obstacles.

Internal to :mod:`trajopt.analysis.metrics`, which exports the public functions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from trajopt.errors import InvalidInputError


def distance_to_polyline(points: np.ndarray, vertices: np.ndarray) -> np.ndarray:
    """Exact Euclidean distance from each point to a polyline.

    Parameters
    ----------
    points : array_like, shape (n, 2)
    vertices : array_like, shape (m, 2)
        Polyline vertices (m >= 1), in order.

    Returns
    -------
    ndarray, shape (n,)

    Notes
    -----
    A KD-tree gives the nearest vertex distance ``d0``; the nearest point of the polyline
    lies on a segment with an end vertex within ``d0 + max segment length``, so only the
    segments around those vertices are measured.
    """
    from scipy.spatial import cKDTree

    p = np.asarray(points, dtype=float).reshape(-1, 2)
    v = np.asarray(vertices, dtype=float).reshape(-1, 2)
    tree = cKDTree(v)
    d0, _ = tree.query(p)
    if len(v) < 2 or len(p) == 0:
        return d0
    seg = np.diff(v, axis=0)
    lmax = float(np.max(np.hypot(seg[:, 0], seg[:, 1])))
    pid, vid = _neighbours_within(tree, p, d0 + lmax + 1e-12)
    # segments on both sides of every candidate vertex
    sid = np.concatenate([vid - 1, vid])
    pid = np.concatenate([pid, pid])
    ok = (sid >= 0) & (sid < len(v) - 1)
    sid, pid = sid[ok], pid[ok]
    a = v[sid]
    d = seg[sid]
    w = p[pid] - a
    dd = np.sum(d * d, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(dd > 0, np.sum(w * d, axis=1) / dd, 0.0)
    t = np.clip(t, 0.0, 1.0)
    dist = np.hypot(*(w - t[:, None] * d).T)
    out = d0.copy()
    np.minimum.at(out, pid, dist)
    return out


def _neighbours_within(tree: Any, p: np.ndarray, radius: np.ndarray, k: int = 32):
    """All (point index, tree index) pairs with distance <= radius[i], vectorised.

    Queries the ``k`` nearest first (one array call); points whose ``k``-th neighbour is
    still inside their radius are completed with a ball query.
    """
    k = min(k, tree.n)
    radius = np.asarray(radius, dtype=float)
    dist, idx = tree.query(p, k=k, distance_upper_bound=float(radius.max()))
    dist, idx = dist.reshape(len(p), k), idx.reshape(len(p), k)
    inside = dist <= radius[:, None]
    full = np.nonzero(inside[:, -1])[0] if k < tree.n else np.empty(0, np.int64)
    inside[full] = False
    pid = [np.nonzero(inside)[0]]
    vid = [idx[inside]]
    if len(full):
        lists = tree.query_ball_point(p[full], radius[full])
        counts = np.fromiter((len(x) for x in lists), dtype=np.int64, count=len(lists))
        pid.append(np.repeat(full, counts))
        vid.append(np.concatenate([np.asarray(x, dtype=np.int64) for x in lists]))
    return np.concatenate(pid), np.concatenate(vid)


def hausdorff_distance(a: np.ndarray, b: np.ndarray) -> float:
    """Symmetric Hausdorff distance between two finite point sets (m), by KD-trees.

    Parameters
    ----------
    a : array_like, shape (n, 2)
    b : array_like, shape (m, 2)
    """
    from scipy.spatial import cKDTree

    pa = np.asarray(a, dtype=float).reshape(-1, 2)
    pb = np.asarray(b, dtype=float).reshape(-1, 2)
    if len(pa) == 0 or len(pb) == 0:
        raise InvalidInputError("hausdorff_distance needs two non-empty point sets")
    dab = cKDTree(pb).query(pa)[0].max()
    dba = cKDTree(pa).query(pb)[0].max()
    return float(max(dab, dba))


def densify(vertices: np.ndarray, spacing: float) -> np.ndarray:
    """Polyline vertices plus points every ``<= spacing`` along each segment."""
    v = np.asarray(vertices, dtype=float)
    if len(v) < 2:
        return v
    seg = np.diff(v, axis=0)
    n = np.maximum(1, np.ceil(np.hypot(seg[:, 0], seg[:, 1]) / spacing).astype(int))
    idx = np.repeat(np.arange(len(seg)), n)
    first = np.concatenate([[0], np.cumsum(n)[:-1]])
    t = (np.arange(int(n.sum())) - first[idx]) / n[idx]
    return np.vstack([v[idx] + t[:, None] * seg[idx], v[-1:]])


def polyline_hausdorff(a: np.ndarray, b: np.ndarray, *, spacing: float) -> float:
    """Symmetric Hausdorff distance between two polylines (m).

    Each polyline is densified every ``spacing`` metres and the exact distance from those
    points to the other polyline is taken, so the result is exact up to ``spacing / 2``
    (and exact when the extreme deviation is at a vertex).
    """
    return float(max(_directed_polyline(a, b, spacing), _directed_polyline(b, a, spacing)))


#: :func:`_directed_polyline` first measures every this-many-th point of the densified path.
_COARSE_STEP = 8


def _directed_polyline(a: np.ndarray, b: np.ndarray, spacing: float) -> float:
    """``max_{p in densified a} dist(p, polyline b)``; exact distances only where needed.

    ``d0``, the distance to the nearest point of ``b`` densified every ``spacing``, is at
    least the exact distance and at most it plus ``spacing / 2``; so only the points with
    ``d0`` within ``spacing / 2`` of a point's lower bound can hold the maximum, and the
    exact distance (:func:`distance_to_polyline`, whose value at a point does not depend
    on the other points) is taken for those only. ``d0`` is measured first at every
    ``_COARSE_STEP``-th point: it is 1-Lipschitz, so ``d0`` at a neighbour plus the
    distance to it bounds the points in between, and only those whose bound reaches the
    coarse lower bound are measured. Every point that can hold the maximum is measured
    exactly, so the result is the maximum over all the densified points, bit for bit.
    """
    from scipy.spatial import cKDTree

    pa, pb = densify(a, spacing), densify(b, spacing)
    tree = cKDTree(pb)
    slack = 1e-9  # m; far above the rounding of the bounds (~1e-15 m)
    n = len(pa)
    cand = np.arange(n)
    if n > 4 * _COARSE_STEP:
        ci = np.unique(np.append(np.arange(0, n, _COARSE_STEP), n - 1))
        dc = tree.query(pa[ci])[0]
        low = float(np.max(dc)) - 0.5 * spacing  # the maximum is at least this
        k = np.clip(np.searchsorted(ci, cand, side="right") - 1, 0, len(ci) - 2)
        lo, hi = ci[k], ci[k + 1]
        bound = np.minimum(
            dc[k] + np.hypot(*(pa - pa[lo]).T), dc[k + 1] + np.hypot(*(pa - pa[hi]).T)
        )  # >= d0 at every point
        cand = cand[bound >= low - slack]
    d0 = tree.query(pa[cand])[0]  # >= the exact distance, and <= it + spacing / 2
    keep = cand[d0 >= d0.max() - 0.5 * spacing - slack]  # only these can hold the maximum
    return float(distance_to_polyline(pa[keep], b).max())


@dataclass(frozen=True, slots=True)
class _Obstacles:
    """The occupied squares of a grid that can be nearest to a point, and a KD-tree of them.

    Only occupied cells with a free 8-neighbour or on the map edge can be nearest.
    ``tree`` is ``None`` when nothing is occupied.
    """

    centres: np.ndarray
    tree: Any
    res: float
    ox: float
    oy: float
    nx: int
    ny: int


#: The last few grids' obstacle trees, each with the grid it was built from (compared with
#: ``is``, so a cached entry can never belong to another grid).
_OBSTACLES: list[tuple[Any, _Obstacles]] = []
_OBSTACLES_KEPT = 4


def _obstacles(grid: Any) -> _Obstacles:
    """Build (or fetch) the :class:`_Obstacles` of a grid.

    An :class:`astar.OccupancyGrid` is immutable (its ``occupied`` is a read-only copy), so
    its tree is kept for the next call: a benchmark scores every method's path of every
    query against the same map. Other grid-like objects are rebuilt on every call.
    """
    from astar.grid import OccupancyGrid

    cacheable = type(grid) is OccupancyGrid
    if cacheable:
        for g, obs in _OBSTACLES:
            if g is grid:
                return obs
    from scipy.ndimage import binary_erosion
    from scipy.spatial import cKDTree

    occ = np.asarray(grid.occupied, dtype=bool)
    res = float(grid.resolution)
    ox, oy = (float(v) for v in grid.origin)
    ny, nx = occ.shape
    if occ.any():
        interior = binary_erosion(occ, structure=np.ones((3, 3), bool), border_value=0)
        iy, ix = np.nonzero(occ & ~interior)
        centres = np.column_stack([ox + (ix + 0.5) * res, oy + (iy + 0.5) * res])
        tree = cKDTree(centres)
    else:
        centres, tree = np.empty((0, 2)), None
    obs = _Obstacles(centres, tree, res, ox, oy, nx, ny)
    if cacheable:
        _OBSTACLES.insert(0, (grid, obs))
        del _OBSTACLES[_OBSTACLES_KEPT:]
    return obs


def _square_distance(p: np.ndarray, obs: _Obstacles, d0: np.ndarray) -> np.ndarray:
    """Exact distance from each point to the nearest obstacle square.

    ``d0`` is each point's distance to the nearest obstacle centre: the nearest square
    has its centre within ``d0 + res / sqrt(2)``, so the exact point-to-square distance
    ``hypot(max(0, |dx| - res/2), max(0, |dy| - res/2))`` is evaluated for those only. A
    point's value depends on that point alone (not on the others passed with it).
    """
    out = np.full(len(p), np.inf)
    if obs.tree is None or not len(p):
        return out
    res, centres = obs.res, obs.centres
    pid, cid = _neighbours_within(obs.tree, p, d0 + res * math.sqrt(0.5) + 1e-12)
    dx = np.maximum(0.0, np.abs(p[pid, 0] - centres[cid, 0]) - 0.5 * res)
    dy = np.maximum(0.0, np.abs(p[pid, 1] - centres[cid, 1]) - 0.5 * res)
    np.minimum.at(out, pid, np.hypot(dx, dy))
    return out


def _border_distance(p: np.ndarray, obs: _Obstacles) -> np.ndarray:
    """Distance from each point to the outside of the map (0 outside it)."""
    edge = np.minimum.reduce(
        [
            p[:, 0] - obs.ox,
            obs.ox + obs.nx * obs.res - p[:, 0],
            p[:, 1] - obs.oy,
            obs.oy + obs.ny * obs.res - p[:, 1],
        ]
    )
    return np.maximum(edge, 0.0)


def point_clearance(points: np.ndarray, grid: Any, *, border_occupied: bool = False) -> np.ndarray:
    """Exact distance (m) from each point to the nearest occupied cell, cells as squares.

    Parameters
    ----------
    points : array_like, shape (n, 2)
        World points in metres.
    grid : astar.OccupancyGrid
        The raw map.
    border_occupied : bool
        Treat everything outside the map as occupied (distance to the map edge counts).

    Returns
    -------
    ndarray, shape (n,)
        0 for points inside an occupied cell (or outside the map when
        ``border_occupied``); ``inf`` when nothing is occupied.

    Notes
    -----
    Only occupied cells with a free 8-neighbour or on the map edge can be nearest. A
    KD-tree over their centres gives the nearest centre distance ``d0``; the nearest square
    has its centre within ``d0 + res / sqrt(2)``, so the exact point-to-square distance
    ``hypot(max(0, |dx| - res/2), max(0, |dy| - res/2))`` is evaluated for those only.
    The tree of an :class:`astar.OccupancyGrid` is kept for the next calls (the last few
    grids).
    """
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    obs = _obstacles(grid)
    if obs.tree is not None and len(p):
        out = _square_distance(p, obs, obs.tree.query(p)[0])
    else:
        out = np.full(len(p), np.inf)
    if border_occupied:
        out = np.minimum(out, _border_distance(p, obs))
    return out


def min_clearance(points: np.ndarray, grid: Any, *, border_occupied: bool = False) -> float:
    """``point_clearance(points, grid, border_occupied=...).min()``, bit for bit, faster.

    The distance to a square is at most the distance ``d0`` to its centre and at least
    ``d0 - res / sqrt(2)``. So the minimum is at most ``m = min(d0)`` (with the border
    distance), and only the points whose lower bound is within ``m`` (plus a rounding
    slack) can hold it: the exact distances are evaluated for those points only, exactly
    as :func:`point_clearance` evaluates them.

    Parameters
    ----------
    points : array_like, shape (n, 2), n >= 1
    grid : astar.OccupancyGrid
    border_occupied : bool

    Returns
    -------
    float
        ``inf`` when nothing is occupied (and the border is not).
    """
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    if not len(p):
        raise InvalidInputError("min_clearance needs at least one point")
    obs = _obstacles(grid)
    edge = _border_distance(p, obs) if border_occupied else np.full(len(p), np.inf)
    if obs.tree is None:
        return float(edge.min())
    d0 = obs.tree.query(p)[0]
    upper = float(np.minimum(d0, edge).min())  # the answer is at most this
    lower = np.minimum(d0 - obs.res * math.sqrt(0.5), edge)  # each point's is at least this
    keep = np.nonzero(lower <= upper + 1e-9 * (1.0 + abs(upper)))[0]
    exact = _square_distance(p[keep], obs, d0[keep])
    return float(np.minimum(exact, edge[keep]).min())
