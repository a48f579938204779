"""When points are within disc movers' limits: closed-form time windows, and a pair filter.

A disc mover's centre is linear in time on each piece of its track between waypoint times
(:func:`mover_pieces`), and so is its limit (its radius, growing, plus what the robot
keeps), so the times a point is within the limit are one interval per piece, the roots of
a quadratic (:func:`inside_times`, :func:`disc_windows`). Most pairs of a piece and a
point never come that close: :func:`near_pairs` (and :func:`close_pairs` for pairs chosen
otherwise) keeps only those whose distance can come under the limit, an exact filter.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from trajopt.moving._obstacle import MovingObstacle
from trajopt.moving._st_kernels import (
    close_kernel,
    disc_windows_kernel,
    inside_times_kernel,
    mover_pieces_kernel,
    near_pairs_kernel,
    track_knots_kernel,
)

#: Consecutive points per box of :func:`near_pairs`'s first test.
BOX = 16
#: :func:`near_pairs` keeps the pairs within this much (m) of the limit (against rounding).
NEAR_SLACK = 1e-6


def near_pairs(
    pts: np.ndarray,
    pieces: np.ndarray,
    limit: float,
    band: tuple[np.ndarray, np.ndarray] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Return ``(piece, point)``: the pairs whose distance can come under the limit.

    A piece of a track (a row of :func:`mover_pieces`, ``limit`` added to its ``r``) moves
    its centre along the segment from ``c(u)`` to ``c(w)``, and its limit is at most
    ``R = r + max(g, 0) (w - u)`` over it. A point farther than ``R`` from that segment is
    farther than the limit from the centre at every instant of the piece, so it has no
    window there: every pair left out is at least ``R + NEAR_SLACK`` apart (an exact filter,
    checked by brute force in the tests). First the points are boxed in runs of
    :data:`BOX` (consecutive path points are near each other) and each piece's segment box,
    grown by ``R``, against those boxes; then each remaining pair's point-to-segment distance
    (compiled: :func:`._st_kernels.near_pairs_kernel`).

    Parameters
    ----------
    pts : ndarray, shape (n, 2)
        Points (m).
    pieces : ndarray, shape (p, 9)
        Rows ``(mover, u, w, x, y, vx, vy, r, g)`` (:func:`mover_pieces`); ``w`` may be
        ``inf`` for a piece that stands still.
    limit : float
        Added to every row's ``r`` (m).
    band : (ndarray, ndarray), optional
        Per point, shape (n,) each: only the times (s) from ``band[0]`` to ``band[1]``
        matter; a piece whose span ``[u, w]`` misses them is left out for that point too.

    Returns
    -------
    piece, point : ndarray of int, shape (q,)
    """
    n, p = pts.shape[0], pieces.shape[0]
    if n == 0 or p == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    a, b, reach = _swept(pieces, limit)
    none = np.zeros(n)
    b_lo, b_hi = (none, none) if band is None else band
    return near_pairs_kernel(
        np.ascontiguousarray(pts, dtype=np.float64),
        np.ascontiguousarray(a, dtype=np.float64),
        np.ascontiguousarray(b, dtype=np.float64),
        np.ascontiguousarray(reach, dtype=np.float64),
        np.ascontiguousarray(pieces[:, 1], dtype=np.float64),
        np.ascontiguousarray(pieces[:, 2], dtype=np.float64),
        np.ascontiguousarray(b_lo, dtype=np.float64),
        np.ascontiguousarray(b_hi, dtype=np.float64),
        band is not None,
        BOX,
    )


def inside_times(
    dx: np.ndarray, dy: np.ndarray, vx: np.ndarray, vy: np.ndarray, rr: np.ndarray, g: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Return the times ``(t_lo, t_hi)`` (s, from a piece's start) a point is inside a mover's limit.

    The point at ``D = (dx, dy)`` from the mover's centre at the piece's start, the centre
    moving at ``V = (vx, vy)`` (m/s), the limit ``rr + g tau`` (m): ``|D - V tau| < rr + g tau``
    on the open interval ``(t_lo, t_hi)`` (``t_lo > t_hi`` or infinite ends when empty or
    unbounded; NaN where undefined). Broadcasts. The roots of the quadratic
    ``|D - V tau|^2 - (rr + g tau)^2`` as ``q / a`` and ``c / q`` with
    ``q = -(b + sign(b) sqrt(b^2 - 4 a c)) / 2`` (no cancellation), the linear root where
    ``|a| <= 1e-12``, and ``t_lo >= -rr / g`` where the limit grows (it must be positive);
    compiled per pair (:func:`._st_kernels.inside_times_kernel`).
    """
    dx, dy, vx, vy, rr, g = np.broadcast_arrays(dx, dy, vx, vy, rr, g)
    shape = dx.shape
    flat = [np.ascontiguousarray(x, dtype=float).reshape(-1) for x in (dx, dy, vx, vy, rr, g)]
    t_lo, t_hi = inside_times_kernel(*flat)
    return t_lo.reshape(shape), t_hi.reshape(shape)


def close_pairs(
    pts: np.ndarray, pieces: np.ndarray, limit: float, seg: np.ndarray, point: np.ndarray
) -> np.ndarray:
    """Return which pairs ``(pieces[seg], pts[point])`` :func:`near_pairs` would keep (bool).

    The point-to-segment test alone (the docstring of :func:`near_pairs`), for pairs
    chosen otherwise (e.g. by time).
    """
    a, b, reach = _swept(pieces, limit)
    return _close(pts, a, b, reach, seg, point)


def _swept(pieces: np.ndarray, limit: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return each piece's segment ends ``a, b`` (m), shape (p, 2), and its reach (m), shape (p,)."""
    span = pieces[:, 2] - pieces[:, 1]
    still = (pieces[:, 5] == 0.0) & (pieces[:, 6] == 0.0)
    run = np.where(still, 0.0, span)  # a standing piece may last forever
    a = pieces[:, 3:5]
    b = a + pieces[:, 5:7] * run[:, None]
    with np.errstate(invalid="ignore"):
        grow = np.where(pieces[:, 8] > 0.0, pieces[:, 8] * span, 0.0)
    return a, b, pieces[:, 7] + limit + grow + NEAR_SLACK


def _close(
    pts: np.ndarray,
    a: np.ndarray,
    b: np.ndarray,
    reach: np.ndarray,
    seg: np.ndarray,
    point: np.ndarray,
) -> np.ndarray:
    """Return whether point ``point[i]`` is within ``reach[seg[i]]`` of segment ``seg[i]`` (bool).

    The distance to the segment (the projection's parameter clipped to ``[0, 1]``) against
    the reach; a NaN or infinite distance is kept. Compiled
    (:func:`._st_kernels.close_kernel`).
    """
    return close_kernel(
        np.ascontiguousarray(pts, dtype=float),
        np.ascontiguousarray(a, dtype=float),
        np.ascontiguousarray(b, dtype=float),
        np.ascontiguousarray(reach, dtype=float),
        np.ascontiguousarray(seg, dtype=np.int64),
        np.ascontiguousarray(point, dtype=np.int64),
    )


def disc_windows(
    pts: np.ndarray,
    movers: Sequence[MovingObstacle] | np.ndarray,
    limit: float,
    near: np.ndarray | None = None,
    pairs: tuple[np.ndarray, np.ndarray] | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Return when points are closer to disc movers than ``limit`` plus their radius.

    Exact (closed form, module docstring) over each mover's whole prediction and after it
    (the mover stands where it was last, forever).

    Parameters
    ----------
    pts : ndarray, shape (n, 2)
        Points (m).
    movers : sequence of MovingObstacle, or ndarray
        Disc movers, or their pieces from :func:`mover_pieces` (with a limit in; ``limit``
        is then added to it).
    limit : float
        The distance to keep besides a mover's radius (m).
    near : ndarray of bool, shape (movers, n), optional
        Which points to test against each mover; default the pairs of a piece and a point
        that :func:`near_pairs` keeps (the others have no window).
    pairs : (ndarray of int, ndarray of int), optional
        Instead: which piece (row of the pieces) to test against which point.

    Returns
    -------
    mover, point : ndarray of int, shape (r,)
        The mover and the point of each window.
    lo, hi : ndarray, shape (r,)
        The open time interval (s) of each window; ``hi`` is the largest float for one that
        lasts (``numpy.nan_to_num`` of an infinite end).
    """
    rows = movers if isinstance(movers, np.ndarray) else mover_pieces(movers, 0.0)
    who = rows[:, 0].astype(np.int64)
    if pairs is not None:
        seg, pi = pairs
    elif near is None:
        seg, pi = near_pairs(pts, rows, limit)
    else:
        seg, pi = np.nonzero(near[who])
    # inside_times of each pair, clipped to its piece's span (compiled: the same floats)
    lo, hi = disc_windows_kernel(
        np.ascontiguousarray(pts, dtype=float),
        np.ascontiguousarray(rows, dtype=float),
        float(limit),
        np.ascontiguousarray(seg, dtype=np.int64),
        np.ascontiguousarray(pi, dtype=np.int64),
    )
    keep = lo < hi
    return who[seg[keep]], pi[keep].astype(np.int64), lo[keep], hi[keep]


def track_knots(
    movers: Sequence[MovingObstacle], a: float | np.ndarray, b: float | np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return every mover's knots on ``[a, b]`` and its centre there, all movers at once.

    A mover's knots are ``a``, its waypoint times strictly between ``a`` and ``b``, and
    ``b`` (``a < b``); its centre at them is what ``numpy.interp`` gives, bit for bit: a
    waypoint at its time, the first or last waypoint outside the times, else
    ``slope (t - t_k) + p_k`` on the waypoints' segment (compiled:
    :func:`._st_kernels.track_knots_kernel`).

    Parameters
    ----------
    movers : sequence of MovingObstacle
        At least one.
    a, b : float or ndarray, shape (movers,)
        The range (s), one for all movers or one each.

    Returns
    -------
    owner : ndarray of int, shape (k,)
        The mover of each knot (movers in order, each one's knots in order of time).
    knots : ndarray, shape (k,)
        The knots (s).
    centre : ndarray, shape (k, 2)
        The centre (m) at each knot.
    """
    m = len(movers)
    n_j, tk, pos = _waypoints(movers)
    a = np.ascontiguousarray(np.broadcast_to(np.asarray(a, dtype=float), (m,)))
    b = np.ascontiguousarray(np.broadcast_to(np.asarray(b, dtype=float), (m,)))
    return track_knots_kernel(n_j, tk, pos, a, b)


def _waypoints(movers: Sequence[MovingObstacle]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return each mover's number of waypoints, and their times (s) and positions (m) one mover after another."""
    n_j = np.array([mv.times.shape[0] for mv in movers], dtype=np.int64)
    tk = np.ascontiguousarray(np.concatenate([mv.times for mv in movers]), dtype=np.float64)
    pos = np.ascontiguousarray(np.concatenate([mv.positions for mv in movers]), dtype=np.float64)
    return n_j, tk, pos


def mover_pieces(movers: Sequence[MovingObstacle], limit: float) -> np.ndarray:
    """Return the linear pieces of disc movers' tracks, shape (p, 9), for :func:`disc_windows`.

    Rows ``(mover, u, w, x, y, vx, vy, r, g)``: from ``u`` to ``w`` (s; ``w = inf`` for the
    last, the mover standing) the centre moves from ``(x, y)`` at ``(vx, vy)`` (m, m/s) and
    ``limit`` plus the radius is ``r + g (t - u)`` (m). A mover's knots are ``0``, its times
    after 0 and ``t_end = max(t_last, 0) + 1`` (:func:`track_knots`). Compiled
    (:func:`._st_kernels.mover_pieces_kernel`).
    """
    if len(movers) == 0:
        return np.zeros((0, 9))
    n_j, tk, pos = _waypoints(movers)
    return mover_pieces_kernel(
        n_j,
        tk,
        pos,
        np.array([m.t_last for m in movers], dtype=np.float64),
        np.array([m.radius for m in movers], dtype=np.float64),
        np.array([m.growth for m in movers], dtype=np.float64),
        float(limit),
    )
