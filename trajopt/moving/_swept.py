"""The region a predicted mover sweeps over a time interval, marked on an occupancy grid.

A re-route (:mod:`._reroute`) plans a new path that keeps off where a mover will be: the cells
its shape covers at some instant of ``[t0, t1]``, grown by a distance (the margin: the planner
inflates the marked map by the robot's radius as it inflates any map). The shape is bounded by
its circumscribed disc (its reference point's farthest vertex plus its rounding, the rounding
taken at ``t1``, where it is largest); the reference point moves linearly between waypoints,
so over a waypoint segment the discs sweep a capsule. A cell is marked when its square meets
the grown capsule (the exact distance from the capsule's segment to the square, at most its
radius): the marked cells cover the swept region, never less, and no cell the capsule misses
(a route round the marks keeps as close to the mover as the grid allows).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from astar.grid import OccupancyGrid
from trajopt.moving._obstacle import MovingObstacle
from trajopt.moving._swept_kernel import capsule_kernel


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
    a, b, radius = _capsules(mover, t0, t1, grow)
    return _capsule_mask(_frame(grid, box), a, b, radius)


def _frame(
    grid: OccupancyGrid, box: tuple[int, int, int, int] | None
) -> tuple[float, float, float, int, int]:
    """Return ``(ox, oy, res, nx, ny)`` of ``grid``, or of its cell ``box`` as a grid of its own."""
    res = float(grid.resolution)
    ox, oy = (float(v) for v in grid.origin)
    ny, nx = grid.shape
    if box is not None:  # the box as a grid of its own: the same cell centres
        bx0, bx1, by0, by1 = (int(v) for v in box)
        ox, oy = ox + bx0 * res, oy + by0 * res
        ny, nx = by1 - by0 + 1, bx1 - bx0 + 1
    return ox, oy, res, nx, ny


def reached_swept_mask(
    grid: OccupancyGrid,
    mover: MovingObstacle,
    t0: float,
    t1: float,
    grow: float,
    origin: np.ndarray,
    speed: float,
    slack: float,
    late: tuple[float, float] = (0.0, 0.0),
    box: tuple[int, int, int, int] | None = None,
) -> np.ndarray:
    """Return the cells the mover covers in ``[t0, t1]`` at a time a robot could be near them.

    :func:`swept_mask` less what the mover covers only before a robot could come. A robot
    that leaves ``origin`` (m) at ``t = 0`` and drives at most ``speed`` (m/s) is nowhere
    farther than ``speed * t`` from it at time ``t``. A cell is marked when the mover's
    shape, grown by ``grow`` (m), meets its square at some time ``t`` in ``[t0, t1]`` (s;
    when ``t1`` is the prediction's last time or later, at any time from ``t0`` on: the mover
    stands at its last place for ever) with ``speed * t >= |c - origin| - slack`` for a point
    ``c`` of the cell: the cells the mover covers only before any robot centre within
    ``slack`` (m) of them could have got there are left free. With ``slack`` the robot's
    radius (the distance the planner inflates the marked map by), a plan on the marked map
    keeps the robot off the mover at every time the robot could be there at all: a robot
    centre ``y`` meets the grown shape at ``z`` only where ``|y - z| <= slack``, so it comes
    there no sooner than ``(|z - origin| - slack) / speed``.

    With ``late = (factor, extra)``, ``factor > 0``, a cell is also left free when the mover
    first covers it (on each segment that covers it) only after ``factor * (|c - origin| +
    slack) / speed + extra`` (s): a guess that the robot has passed it by then, not a bound
    (a plan on that map is to be re-timed and certified).

    Over a waypoint segment of the track, the mover's bounding disc (:func:`swept_mask`)
    covers a cell's centre while its reference point is within the disc's radius of it: an
    interval of the segment whose ends give the first and last times of that segment the
    cell is covered, exactly; the cell is marked when that interval meets the times above on
    some segment (after the track, the last place covers its cells for ever).

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
    late : (float, float)
        ``(factor, extra)`` (1, s) as above; ``factor <= 0``: no such rule.
    box : (int, int, int, int), optional
        As :func:`swept_mask`'s: only the cells of this box of ``grid``.

    Returns
    -------
    ndarray of bool, shape (ny, nx)
        ``mask[iy, ix]``: the cell may hold the grown mover when a robot could be near it;
        a subset of :func:`swept_mask` over ``[t0, t1]`` (with ``box``, of the box's shape).
    """
    t0, t1 = float(t0), float(t1)
    reach = (np.asarray(origin, dtype=float).reshape(2), float(speed), float(slack))
    return _reached(_frame(grid, box), mover, t0, t1, _capsules(mover, t0, t1, grow), reach, late)


def _reached(
    frame: tuple[float, float, float, int, int],
    mover: MovingObstacle,
    t0: float,
    t1: float,
    caps: tuple[np.ndarray, np.ndarray, float],
    reach: tuple[np.ndarray, float, float],
    late: tuple[float, float],
) -> np.ndarray:
    """:func:`reached_swept_mask` on ``frame`` (:func:`_frame`'s) from the region's capsules.

    ``caps``: :func:`_capsules` of the mover over ``[t0, t1]`` (its track's segments, whose
    ends are its places at ``t0``, its waypoint times between and ``t1``, and the radius).
    """
    a, b, radius = caps
    times = mover.times
    knots = np.concatenate([[t0], times[(times > t0) & (times < t1)], [t1] if t1 > t0 else []])
    pts = np.vstack([a, b[-1:]]) if knots.shape[0] > 1 else a  # the track at the knots
    a = np.vstack([pts[:-1], pts[-1:]])  # each segment, then the last place for ever
    b = np.vstack([pts[1:], pts[-1:]])
    last = math.inf if t1 >= mover.t_last else t1
    spans = (np.append(knots[:-1], knots[-1]), np.append(knots[1:], last))
    return _capsule_mask(frame, a, b, radius, spans, reach, late)


def _capsule_mask(
    frame: tuple[float, float, float, int, int],
    a: np.ndarray,
    b: np.ndarray,
    radius: float,
    spans: tuple[np.ndarray, np.ndarray] | None = None,
    reach: tuple[np.ndarray, float, float] | None = None,
    late: tuple[float, float] = (0.0, 0.0),
) -> np.ndarray:
    """Return the cells whose square comes within ``radius`` (m) of a segment ``[a_i, b_i]`` (m).

    ``frame``: ``(ox, oy, res, nx, ny)``, the cells' origin (m), size (m) and count. With
    ``spans`` (``(t_a, t_b)``, s, each shape (k,): the times a point moving linearly is at
    ``a_i`` and ``b_i``; ``t_b`` infinite for a point standing at ``a_i = b_i`` for ever) and
    ``reach`` (``origin`` m, ``speed`` m/s, ``slack`` m), a segment marks only the cells with
    ``|centre - origin| - slack - res / sqrt(2) <= speed * t``, ``t`` the last time in
    ``[t_a, t_b]`` the point is within ``radius + res / sqrt(2)`` of the centre (no earlier
    than the last time it is within ``radius`` of the square), and with ``late``
    (``(factor, extra)``, ``factor > 0``) whose first such time is at most ``factor *
    (|centre - origin| + slack + res / sqrt(2)) / speed + extra`` (:func:`reached_swept_mask`).
    """
    ox, oy, res, nx, ny = frame
    a = np.ascontiguousarray(a, dtype=np.float64).reshape(-1, 2)
    b = np.ascontiguousarray(b, dtype=np.float64).reshape(-1, 2)
    timed = spans is not None and reach is not None
    if timed:
        ta = np.ascontiguousarray(spans[0], dtype=np.float64)
        tb = np.ascontiguousarray(spans[1], dtype=np.float64)
        origin = np.ascontiguousarray(reach[0], dtype=np.float64).reshape(2)
        speed, slack = float(reach[1]), float(reach[2])
    else:
        ta = tb = np.zeros(a.shape[0])
        origin, speed, slack = np.zeros(2), 0.0, 0.0
    return capsule_kernel(
        float(ox), float(oy), float(res), int(nx), int(ny), a, b, float(radius), ta, tb, origin,
        speed, slack, timed, late[0], late[1],
    )  # fmt: skip


def _capsules(
    mover: MovingObstacle, t0: float, t1: float, grow: float
) -> tuple[np.ndarray, np.ndarray, float]:
    """Return the track's segment ends ``a``, ``b`` (m, shape (k, 2)) and the capsules' radius (m).

    A cell's square meets the grown swept region when it comes within the radius of a
    segment ``[a_i, b_i]`` (its centre within the radius plus half the cell's diagonal).
    """
    reach = float(np.max(np.hypot(*mover.shape_vertices.T)))
    radius = reach + float(mover.radius_at(t1)) + float(grow)
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

    The same test on the given cells only (bool, shape (n,)): the compiled loop runs on the
    cells' bounding box as a grid of its own (the same cell centres), where it visits only
    the capsules' own boxes, far cheaper than the whole grid's mask.
    """
    c = np.asarray(cells, dtype=np.int64).reshape(-1, 2)
    if c.shape[0] == 0:
        return np.zeros(0, dtype=bool)
    x0, y0 = (int(v) for v in c.min(axis=0))
    x1, y1 = (int(v) for v in c.max(axis=0))
    a, b, radius = _capsules(mover, t0, t1, grow)
    mask = _capsule_mask(_frame(grid, (x0, x1, y0, y1)), a, b, radius)
    return mask[c[:, 1] - y0, c[:, 0] - x0]


def mark_swept(
    grid: OccupancyGrid,
    regions: Sequence[tuple[MovingObstacle, float, float]],
    grow: float,
    keep: Sequence[tuple[np.ndarray, float]] = (),
    reach: tuple[np.ndarray, float, float] | None = None,
    late: tuple[float, float] = (0.0, 0.0),
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
    late : (float, float)
        With ``reach``: :func:`reached_swept_mask`'s ``late``.

    Returns
    -------
    astar.OccupancyGrid or None
        The marked map (same shape, resolution and origin).
    """
    res = float(grid.resolution)
    caps = [_capsules(mover, t0, t1, grow) for mover, t0, t1 in regions]
    if _all_kept(caps, res, keep):
        return None  # every capsule inside a kept disc: no cell to add
    box = _cells_of(grid, caps)
    if box is None:
        return None  # every capsule off the map
    bx0, bx1, by0, by1 = box
    add = np.zeros((by1 - by0 + 1, bx1 - bx0 + 1), dtype=bool)
    frame = _frame(grid, box)
    for (mover, t0, t1), cap in zip(regions, caps, strict=True):
        if reach is None:
            add |= _capsule_mask(frame, *cap)
        else:
            origin, speed, slack = reach
            timed = (np.asarray(origin, dtype=float).reshape(2), float(speed), float(slack))
            add |= _reached(frame, mover, float(t0), float(t1), cap, timed, late)
    ox, oy = (float(v) for v in grid.origin)
    for p, r in keep:
        ix0 = max(bx0, int(math.floor((float(p[0]) - r - ox) / res)))
        ix1 = min(bx1, int(math.floor((float(p[0]) + r - ox) / res)))
        iy0 = max(by0, int(math.floor((float(p[1]) - r - oy) / res)))
        iy1 = min(by1, int(math.floor((float(p[1]) + r - oy) / res)))
        if ix0 > ix1 or iy0 > iy1:
            continue
        cx = ox + (np.arange(ix0, ix1 + 1) + 0.5) * res
        cy = oy + (np.arange(iy0, iy1 + 1) + 0.5) * res
        near = np.hypot(cx[None, :] - float(p[0]), cy[:, None] - float(p[1])) <= r
        add[iy0 - by0 : iy1 - by0 + 1, ix0 - bx0 : ix1 - bx0 + 1] &= ~near
    occ = np.asarray(grid.occupied)
    part = (slice(by0, by1 + 1), slice(bx0, bx1 + 1))
    new = add & ~occ[part]
    if not new.any():
        return None
    out = np.array(occ)
    out[part] |= new
    return grid.with_occupied(out)


def _cells_of(
    grid: OccupancyGrid, caps: Sequence[tuple[np.ndarray, np.ndarray, float]]
) -> tuple[int, int, int, int] | None:
    """Return the cell box ``(ix0, ix1, iy0, iy1)`` of every cell the capsules can mark.

    The capsules are :func:`_capsules`' ends and radius; the box is cut to the grid, ``None``
    when nothing of it is left.
    """
    res = float(grid.resolution)
    ox, oy = (float(v) for v in grid.origin)
    ny, nx = grid.shape
    half_diag = res * math.sqrt(0.5)
    lo = np.min(
        [np.minimum(a.min(axis=0), b.min(axis=0)) - r - half_diag for a, b, r in caps], axis=0
    )
    hi = np.max(
        [np.maximum(a.max(axis=0), b.max(axis=0)) + r + half_diag for a, b, r in caps], axis=0
    )
    ix0 = max(0, int(math.floor((float(lo[0]) - ox) / res)))
    ix1 = min(nx - 1, int(math.floor((float(hi[0]) - ox) / res)))
    iy0 = max(0, int(math.floor((float(lo[1]) - oy) / res)))
    iy1 = min(ny - 1, int(math.floor((float(hi[1]) - oy) / res)))
    if ix0 > ix1 or iy0 > iy1:
        return None
    return ix0, ix1, iy0, iy1


def _all_kept(
    caps: Sequence[tuple[np.ndarray, np.ndarray, float]],
    res: float,
    keep: Sequence[tuple[np.ndarray, float]],
) -> bool:
    """Whether every capsule of the regions lies in one kept disc (its cells all stay free).

    ``caps``: :func:`_capsules`' ends and radius of each region. A marked cell's centre is
    within the capsule's radius plus half the cell's diagonal of its segment; a segment whose
    ends are within a kept disc's radius less that of its centre keeps every such centre in
    the disc (a disc is convex), whose cells :func:`mark_swept` leaves as they are.
    """
    if not keep:
        return False
    for a, b, radius in caps:
        radius += res * math.sqrt(0.5)
        ends = np.vstack([a, b])
        if not any(
            np.all(np.hypot(*(ends - np.asarray(p, dtype=float)).T) <= r - radius) for p, r in keep
        ):
            return False
    return True
