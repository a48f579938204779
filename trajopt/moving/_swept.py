"""The region a predicted mover sweeps over a time interval, marked on an occupancy grid.

A re-route (:mod:`._reroute`) plans a new path that keeps off where a mover will be: the cells
its shape covers at some instant of ``[t0, t1]``, grown by a distance (the margin: the planner
inflates the marked map by the robot's radius as it inflates any map). The shape is bounded by
its circumscribed disc (its reference point's farthest vertex plus its rounding, the rounding
taken at ``t1``, where it is largest); the reference point moves linearly between waypoints,
so over a waypoint segment the discs sweep a capsule. A cell is marked when its square meets
the grown capsule (its centre within the capsule's radius plus half the cell's diagonal): the
marked cells cover the swept region, never less.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from astar.grid import OccupancyGrid
from trajopt.moving._obstacle import MovingObstacle


def track(mover: MovingObstacle, t0: float, t1: float) -> np.ndarray:
    """Return the reference point's polyline over ``[t0, t1]`` (s), shape (k, 2) (m), k >= 1."""
    inner = [t for t in mover.times.tolist() if t0 < t < t1]
    times = np.asarray([t0, *inner, t1] if t1 > t0 else [t0], dtype=float)
    return mover.position_at(times)


def swept_mask(
    grid: OccupancyGrid,
    mover: MovingObstacle,
    t0: float,
    t1: float,
    grow: float,
    box: tuple[int, int, int, int] | None = None,
) -> np.ndarray:
    """Return the cells the mover's shape, grown by ``grow`` (m), covers at some ``t`` in ``[t0, t1]``.

    Parameters
    ----------
    grid : astar.OccupancyGrid
        The map whose cells are marked (its shape, resolution and origin).
    mover : MovingObstacle
        The prediction (after its last time it stands where it was last).
    t0, t1 : float
        The time interval (s), ``t0 <= t1``.
    grow : float
        Distance added around the shape (m), >= 0.
    box : (int, int, int, int), optional
        ``(ix0, ix1, iy0, iy1)``: only the cells of this box of ``grid`` (bounds included,
        inside the grid) are returned; ``None``: the whole grid.

    Returns
    -------
    ndarray of bool, shape (ny, nx)
        ``mask[iy, ix]``: the cell's square meets the grown swept region (with ``box``, shape
        ``(iy1 - iy0 + 1, ix1 - ix0 + 1)``, its cell ``(ix0, iy0)`` first).
    """
    res = float(grid.resolution)
    ox, oy = (float(v) for v in grid.origin)
    ny, nx = grid.shape
    if box is not None:  # the box as a grid of its own: the same cell centres
        bx0, bx1, by0, by1 = (int(v) for v in box)
        ox, oy = ox + bx0 * res, oy + by0 * res
        ny, nx = by1 - by0 + 1, bx1 - bx0 + 1
    a, b, radius = _capsules(mover, t0, t1, grow, res)
    return _capsule_mask((ox, oy, res, nx, ny), a, b, radius)


#: The pieces of a mover's track :func:`reached_swept_mask` tests one by one are at most
#: this many seconds long (each marks where the mover is during it only if a robot could be
#: there by its end).
REACH_PIECE_S = 0.25


def reached_swept_mask(
    grid: OccupancyGrid,
    mover: MovingObstacle,
    t0: float,
    t1: float,
    grow: float,
    origin: np.ndarray,
    speed: float,
    slack: float,
) -> np.ndarray:
    """Return the cells the mover covers in ``[t0, t1]`` at a time a robot could be near them.

    :func:`swept_mask` less what the mover covers only before a robot could come. A robot that leaves ``origin`` (m) at ``t = 0`` and drives at most ``speed`` (m/s) is
    nowhere farther than ``speed * t`` from it at time ``t``. A cell is marked when the
    mover's shape, grown by ``grow`` (m), meets its square at some time ``t`` in ``[t0, t1]``
    (s; when ``t1`` is the prediction's last time or later, at any time from ``t0`` on: the
    mover stands at its last place for ever) with
    ``speed * t >= |c - origin| - slack`` for a point ``c`` of the cell: the cells the mover
    covers only before any robot centre within ``slack`` (m) of them could have got there
    are left free. With ``slack`` the robot's radius (the distance the planner inflates the
    marked map by), a plan on the marked map keeps the robot off the mover at every time
    the robot could be there at all: a robot centre ``y`` meets the grown shape at ``z``
    only where ``|y - z| <= slack``, so it comes there no sooner than
    ``(|z - origin| - slack) / speed``.

    The track is cut into pieces of at most :data:`REACH_PIECE_S` seconds (and at its
    waypoints); a piece marks the cells its capsule (:func:`swept_mask`) covers that a robot
    could reach by the piece's end, the last place (for ever) every cell it covers.

    Parameters
    ----------
    grid : astar.OccupancyGrid
        The map whose cells are marked (its shape, resolution and origin).
    mover : MovingObstacle
        The prediction.
    t0, t1 : float
        The time interval (s), ``t0 <= t1``.
    grow : float
        Distance added around the shape (m), >= 0.
    origin : ndarray, shape (2,)
        Where the robot is at ``t = 0`` (m).
    speed : float
        The robot's largest speed (m/s), > 0.
    slack : float
        Distance (m), >= 0: as above.

    Returns
    -------
    ndarray of bool, shape (ny, nx)
        ``mask[iy, ix]``: the cell may hold the grown mover when a robot could be near it;
        a subset of :func:`swept_mask` over ``[t0, t1]``.
    """
    res = float(grid.resolution)
    ox, oy = (float(v) for v in grid.origin)
    ny, nx = grid.shape
    t0, t1 = float(t0), float(t1)
    inner = [t for t in mover.times.tolist() if t0 < t < t1]
    knots = [t0, *inner, t1] if t1 > t0 else [t0]
    times = [t0]
    for lo, hi in zip(knots[:-1], knots[1:], strict=True):
        k = max(1, math.ceil((hi - lo) / REACH_PIECE_S))
        times += np.linspace(lo, hi, k + 1)[1:].tolist()
    times_arr = np.asarray(times, dtype=float)
    pts = mover.position_at(times_arr)
    a = np.vstack([pts[:-1], pts[-1:]])  # each piece, then the last place for ever
    b = np.vstack([pts[1:], pts[-1:]])
    last = math.inf if t1 >= mover.t_last else t1
    late = np.append(times_arr[1:], last)  # when each piece ends
    radius = _capsules(mover, t0, t1, grow, res)[2]
    reach = (np.asarray(origin, dtype=float).reshape(2), float(speed), float(slack))
    return _capsule_mask((ox, oy, res, nx, ny), a, b, radius, late, reach)


def _capsule_mask(
    frame: tuple[float, float, float, int, int],
    a: np.ndarray,
    b: np.ndarray,
    radius: float,
    late: np.ndarray | None = None,
    reach: tuple[np.ndarray, float, float] | None = None,
) -> np.ndarray:
    """Return the cells whose centre is within ``radius`` (m) of a segment ``[a_i, b_i]`` (m).

    ``frame``: ``(ox, oy, res, nx, ny)``, the cells' origin (m), size (m) and count. With
    ``late`` (s, shape (k,)) and ``reach`` (``origin`` m, ``speed`` m/s, ``slack`` m), a
    segment marks only the cells with ``|centre - origin| - slack - res / sqrt(2) <= speed *
    late_i`` (:func:`reached_swept_mask`).
    """
    ox, oy, res, nx, ny = frame
    mask = np.zeros((ny, nx), dtype=bool)
    lo = np.minimum(a, b) - radius
    hi = np.maximum(a, b) + radius
    ix0 = np.maximum(0, np.floor((lo[:, 0] - ox) / res).astype(np.int64))
    ix1 = np.minimum(nx - 1, np.floor((hi[:, 0] - ox) / res).astype(np.int64))
    iy0 = np.maximum(0, np.floor((lo[:, 1] - oy) / res).astype(np.int64))
    iy1 = np.minimum(ny - 1, np.floor((hi[:, 1] - oy) / res).astype(np.int64))
    w = np.maximum(ix1 - ix0 + 1, 0)
    h = np.maximum(iy1 - iy0 + 1, 0)
    count = w * h  # the cells of each segment's box, all segments at once
    if not count.any():
        return mask
    seg = np.repeat(np.arange(count.shape[0]), count)
    k = np.arange(seg.shape[0]) - np.repeat(np.cumsum(count) - count, count)
    ix = ix0[seg] + k % w[seg]
    iy = iy0[seg] + k // w[seg]
    cx = ox + (ix + 0.5) * res
    cy = oy + (iy + 0.5) * res
    px = cx - a[seg, 0]
    py = cy - a[seg, 1]
    d = b - a
    dd = np.einsum("ij,ij->i", d, d)
    with np.errstate(divide="ignore", invalid="ignore"):
        lam = np.where(
            dd[seg] > 0.0, np.clip((px * d[seg, 0] + py * d[seg, 1]) / dd[seg], 0.0, 1.0), 0.0
        )
    dist = np.hypot(px - lam * d[seg, 0], py - lam * d[seg, 1])
    hit = dist <= radius
    if late is not None and reach is not None:
        origin, speed, slack = reach
        far = np.hypot(cx - origin[0], cy - origin[1]) - slack - res * math.sqrt(0.5)
        hit &= far <= speed * late[seg]
    mask[iy[hit], ix[hit]] = True
    return mask


def _capsules(
    mover: MovingObstacle, t0: float, t1: float, grow: float, res: float
) -> tuple[np.ndarray, np.ndarray, float]:
    """Return the track's segment ends ``a``, ``b`` (m, shape (k, 2)) and the capsules' radius (m).

    A cell's square meets the grown swept region when its centre is within the radius of a
    segment ``[a_i, b_i]``.
    """
    reach = float(np.max(np.hypot(*mover.shape_vertices.T)))
    radius = reach + float(mover.radius_at(t1)) + float(grow) + res * math.sqrt(0.5)
    pts = track(mover, float(t0), float(t1))
    a = pts[:-1] if pts.shape[0] > 1 else pts
    b = pts[1:] if pts.shape[0] > 1 else pts
    return a, b, radius


def swept_cells(
    grid: OccupancyGrid,
    mover: MovingObstacle,
    t0: float,
    t1: float,
    grow: float,
    cells: np.ndarray,
) -> np.ndarray:
    """Return whether each of ``cells`` (``(ix, iy)``, shape (n, 2)) is in :func:`swept_mask`.

    The same test on the given cells only (bool, shape (n,)): a cell far cheaper to ask
    about than the whole grid's mask.
    """
    res = float(grid.resolution)
    ox, oy = (float(v) for v in grid.origin)
    c = np.asarray(cells, dtype=np.int64).reshape(-1, 2)
    a, b, radius = _capsules(mover, t0, t1, grow, res)
    px = (ox + (c[:, 0, None] + 0.5) * res) - a[None, :, 0]
    py = (oy + (c[:, 1, None] + 0.5) * res) - a[None, :, 1]
    d = b - a
    dd = np.einsum("ij,ij->i", d, d)[None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        lam = np.where(
            dd > 0.0, np.clip((px * d[None, :, 0] + py * d[None, :, 1]) / dd, 0.0, 1.0), 0.0
        )
    dist = np.hypot(px - lam * d[None, :, 0], py - lam * d[None, :, 1])
    return np.any(dist <= radius, axis=1)


def mark_swept(
    grid: OccupancyGrid,
    regions: Sequence[tuple[MovingObstacle, float, float]],
    grow: float,
    keep: Sequence[tuple[np.ndarray, float]] = (),
    reach: tuple[np.ndarray, float, float] | None = None,
) -> OccupancyGrid | None:
    """Return ``grid`` with the swept regions marked occupied, or ``None`` when none adds a cell.

    Parameters
    ----------
    grid : astar.OccupancyGrid
        The raw map.
    regions : sequence of (MovingObstacle, float, float)
        Each mover and its time interval ``[t0, t1]`` (s).
    grow : float
        Distance added around each shape (m): the margin to the movers.
    keep : sequence of (ndarray, float)
        Points (m, shape (2,)) and radii (m) whose cells stay as in ``grid`` (the robot's
        start and goal, which a plan must be able to stand on).
    reach : (ndarray, float, float), optional
        ``(origin, speed, slack)`` (m, m/s, m): each region marked only where a robot from
        ``origin`` could be near the mover (:func:`reached_swept_mask`); ``None``: the
        whole swept regions (:func:`swept_mask`).

    Returns
    -------
    astar.OccupancyGrid or None
        The marked map (same shape, resolution and origin).
    """
    add = np.zeros(grid.shape, dtype=bool)
    for mover, t0, t1 in regions:
        if reach is None:
            add |= swept_mask(grid, mover, t0, t1, grow)
        else:
            add |= reached_swept_mask(grid, mover, t0, t1, grow, *reach)
    res = float(grid.resolution)
    ox, oy = (float(v) for v in grid.origin)
    ny, nx = grid.shape
    for p, r in keep:
        ix0 = max(0, int(math.floor((float(p[0]) - r - ox) / res)))
        ix1 = min(nx - 1, int(math.floor((float(p[0]) + r - ox) / res)))
        iy0 = max(0, int(math.floor((float(p[1]) - r - oy) / res)))
        iy1 = min(ny - 1, int(math.floor((float(p[1]) + r - oy) / res)))
        if ix0 > ix1 or iy0 > iy1:
            continue
        cx = ox + (np.arange(ix0, ix1 + 1) + 0.5) * res
        cy = oy + (np.arange(iy0, iy1 + 1) + 0.5) * res
        near = np.hypot(cx[None, :] - float(p[0]), cy[:, None] - float(p[1])) <= r
        add[iy0 : iy1 + 1, ix0 : ix1 + 1] &= ~near
    occ = np.asarray(grid.occupied)
    new = add & ~occ
    if not new.any():
        return None
    return grid.with_occupied(occ | new)
