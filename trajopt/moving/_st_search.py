"""The fastest way through the ``(s, t)`` grid by rest-to-rest drives between stops.

The profiles searched: the robot rests at the start, drives time-optimally (the jerk-limited
timing of the path's piece, rest to rest) to a stop, rests there, drives on to a later stop,
..., and finally to the goal, where it stands. Stops are the path's start and end, the node in
front of each forbidden region and evenly spaced ones. A dynamic programme over the stops in
order of arc length keeps, for every stop and grid time, whether the robot can be resting
there then (and how it got there): a drive from stop ``a`` starting at ``t_k`` is allowed when
its nearest node at every grid time is free on the sufficient grid (:mod:`._st_grid`), a rest
while its node stays free. The earliest exact arrival at the goal, with the goal free from then
on, wins. One drive from the start to the goal after a wait is the special case ``pass after``;
no wait is ``pass before``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from numba import njit

from trajopt.kernel_cache import watch_compiles
from trajopt.moving._node_times import column_kernel, rest_kernel
from trajopt.moving._st_grid import NEVER_STEP, STGrid
from trajopt.moving._st_kernels import (
    arrive_kernel,
    blocked_starts_kernel,
    drive_nodes_kernel,
)

#: Evenly spaced stops tried besides the start, the goal and the fronts of the forbidden regions.
N_EVEN_STOPS = 10
#: The fronts of the forbidden regions are rounded back to multiples of this many nodes.
STOP_LATTICE = 5

watch_compiles()  # a first compilation logs one notice (trajopt.kernel_cache)


@dataclass(frozen=True, slots=True)
class Piece:
    """Phases ``(t, s, v, a, j)``, shape (p, 5), of a rest-to-rest drive over ``[s0, s1]`` (m).

    Times from the drive's own start (s); ``duration`` (s).
    """

    rows: np.ndarray
    duration: float
    s0: float
    s1: float
    memo: dict = field(default_factory=dict, compare=False, repr=False)

    def walk(self, grid: STGrid) -> tuple[np.ndarray, int, int, np.ndarray, np.ndarray]:
        """Return ``(nodes, steps, i0, first, last)``: :meth:`nodes`, its steps and :meth:`visits`.

        Computed once per grid spacing and kept on the piece (one look-up for the search's
        batches).
        """
        key = (grid.dt, grid.ds, grid.s.shape[0])
        got = self.memo.get(key)
        if got is None:
            idx, first, last = drive_nodes_kernel(
                np.ascontiguousarray(self.rows, dtype=float),
                float(self.duration),
                float(self.s0),
                float(self.s1),
                float(grid.dt),
                float(grid.ds),
                key[2],
                NEVER_STEP,
            )
            got = (idx, idx.shape[0] - 1, int(idx[0]), first, last)
            self.memo[key] = got
        return got

    def nodes(self, grid: STGrid) -> np.ndarray:
        """Return the grid node (index) of the drive at each grid step from its start, shape (m,).

        The nearest node of :meth:`s_at` at the steps ``0, dt, ..., ceil(duration / dt) dt``
        (compiled: :func:`._st_kernels.drive_nodes_kernel`); kept on the piece with
        :meth:`visits` (:meth:`walk`).
        """
        return self.walk(grid)[0]

    def visits(self, grid: STGrid) -> tuple[int, np.ndarray, np.ndarray]:
        """Return :func:`._st_grid.visits` of :meth:`nodes` (kept on the piece)."""
        _, _, i0, first, last = self.walk(grid)
        return i0, first, last

    def s_at(self, t: np.ndarray) -> np.ndarray:
        """Return the arc length (m) at the drive's times ``t`` (s), clipped to its ends.

        Compiled (:func:`piece_s_kernel`); ``t`` of any shape, the result of its shape.
        """
        tt = np.asarray(t, dtype=np.float64)
        out = piece_s_kernel(
            _plain(self.rows),
            float(self.duration),
            float(self.s0),
            float(self.s1),
            _plain(tt).reshape(-1),
        )
        return out.reshape(tt.shape)


def _plain(x: np.ndarray) -> np.ndarray:
    """Return ``x`` as a writable C-contiguous float64 array (one compiled signature per rank)."""
    if x.dtype == np.float64 and x.flags.c_contiguous and x.flags.writeable:
        return x
    return np.array(x, dtype=np.float64, order="C")


@njit(cache=True)
def piece_s_kernel(rows, duration, s0, s1, t):  # pragma: no cover - compiled
    """Return a drive's arc length (m) at its own times ``t`` (s), clipped to its ends.

    Parameters
    ----------
    rows : ndarray, shape (p, 5)
        The drive's phases ``(t, s, v, a, j)`` from its start (s, m, m/s, m/s², m/s³),
        ``t`` non-decreasing.
    duration, s0, s1 : float
        Its duration (s) and ends (m).
    t : ndarray, shape (n,)
        The times (s), clipped to ``[0, duration]``.

    Returns
    -------
    ndarray, shape (n,)
        The phase holding each time (the last whose start is at or before it, the first
        before the first start) evaluated in Horner form, clipped to ``[s0, s1]``; ``s1``
        from ``duration`` on. The same floats as the array expression (``numpy.maximum``'s
        and ``numpy.minimum``'s clipping, ``numpy.searchsorted(..., side="right") - 1``).
    """
    n = t.shape[0]
    p = rows.shape[0]
    out = np.empty(n)
    for q in range(n):
        tt = t[q]
        if not (tt >= 0.0 or tt != tt):  # numpy.maximum(t, 0.0)
            tt = 0.0
        if not (tt <= duration or tt != tt):  # numpy.minimum(., duration)
            tt = duration
        lo, hi = 0, p  # the first phase starting after tt: searchsorted, side="right"
        while lo < hi:
            mid = (lo + hi) // 2
            if tt < rows[mid, 0]:
                hi = mid
            else:
                lo = mid + 1
        k = max(lo - 1, 0)
        tau = tt - rows[k, 0]
        s = rows[k, 1] + tau * (rows[k, 2] + tau * (0.5 * rows[k, 3] + tau * rows[k, 4] / 6.0))
        if not (s >= s0 or s != s):
            s = s0
        if not (s <= s1 or s != s):
            s = s1
        out[q] = s1 if tt >= duration else s
    return out


def fill_visits(pieces: Sequence[Piece], grid: STGrid) -> None:
    """Compute :meth:`Piece.nodes` and :meth:`Piece.visits` of several drives (kept on each)."""
    for pc in pieces:
        pc.nodes(grid)


def stop_points(grid: STGrid, extra: Sequence[float] = ()) -> list[float]:
    """Return the stops (m): start, the node in front of each forbidden region, even ones, goal.

    ``extra``: more stops (m), e.g. where a moving robot comes to rest braking at once.
    """
    length = float(grid.s[-1])
    cols = grid.busy
    fronts = np.flatnonzero(cols[1:] & ~cols[:-1])  # the last free node before a forbidden run
    # on a lattice of STOP_LATTICE nodes (rounded back, still in front): new predictions
    # often give the same stops, whose drives are then cached
    lattice = np.unique((fronts // STOP_LATTICE) * STOP_LATTICE)
    inner = [float(grid.s[i]) for i in lattice] + [float(x) for x in extra]
    inner += np.linspace(0.0, length, N_EVEN_STOPS + 2)[1:-1].tolist()
    gap = 2.0 * grid.ds
    keep: list[float] = []
    for p in sorted(inner):
        if gap < p < length - gap and (not keep or p - keep[-1] > gap):
            keep.append(p)
    return [0.0, *keep, length]


def least_time(d: float, v_top: float, a_top: float, j_top: float = math.inf) -> float:
    """Return the least time (s) of a rest-to-rest drive over ``d`` (m) under the limits.

    The jerk-limited S-curve (with ``j_top = inf``: bang-bang), a lower bound of any drive
    along a path whose speed cap is at most ``v_top``.
    """
    if d <= 0.0:
        return 0.0
    if not math.isfinite(j_top):
        if d <= v_top * v_top / a_top:
            return 2.0 * math.sqrt(d / a_top)
        return d / v_top + v_top / a_top

    def ramp(v: float) -> tuple[float, float]:  # time and distance from rest to v
        if v <= a_top * a_top / j_top:
            t = 2.0 * math.sqrt(v / j_top)
        else:
            t = v / a_top + a_top / j_top
        return t, 0.5 * v * t

    t_up, d_up = ramp(v_top)
    if 2.0 * d_up <= d:
        return 2.0 * t_up + (d - 2.0 * d_up) / v_top
    # the peak speed v < v_top: 2 d_up(v) = d
    a, j = a_top, j_top
    v = 0.5 * a * (-a / j + math.sqrt(a * a / (j * j) + 4.0 * d / a))
    if v < a * a / j:  # no phase at a_top: 2 v sqrt(v / j) = d
        v = (0.5 * d) ** (2.0 / 3.0) * j ** (1.0 / 3.0)
    return 2.0 * ramp(min(v, v_top))[0]


def least_times(d: np.ndarray, v_top: float, a_top: float, j_top: float) -> np.ndarray:
    """Return :func:`least_time` of every distance in ``d`` (m), vectorised (s)."""
    d = np.maximum(np.asarray(d, dtype=float), 0.0)
    if not math.isfinite(j_top):
        return np.where(
            d <= v_top * v_top / a_top,
            2.0 * np.sqrt(d / a_top),
            d / v_top + v_top / a_top,
        )
    a, j = a_top, j_top

    def ramp_t(v: np.ndarray) -> np.ndarray:
        return np.where(v <= a * a / j, 2.0 * np.sqrt(v / j), v / a + a / j)

    t_up = float(ramp_t(np.array(v_top)))
    d_up = 0.5 * v_top * t_up
    v = 0.5 * a * (-a / j + np.sqrt(a * a / (j * j) + 4.0 * d / a))
    v = np.where(v < a * a / j, (0.5 * d) ** (2.0 / 3.0) * j ** (1.0 / 3.0), v)
    short = 2.0 * ramp_t(np.minimum(v, v_top))
    return np.where(2.0 * d_up <= d, 2.0 * t_up + (d - 2.0 * d_up) / v_top, short)


def search(
    grid: STGrid,
    drive: Callable[[float, float], Piece | None],
    v_top: float,
    a_top: float,
    k_min: int = 0,
    j_top: float = math.inf,
    launch: Callable[[float], Piece | None] | None = None,
    brake_at: float | None = None,
) -> tuple[list[tuple[float, Piece | None, float]], float, str] | None:
    """Return the earliest arrival's schedule (module docstring), or ``None``.

    Parameters
    ----------
    grid : STGrid
        The sufficient grid.
    drive : callable
        ``drive(s0, s1)``: the rest-to-rest drive over ``[s0, s1]`` (m), ``None`` when it
        cannot be timed.
    v_top, a_top : float
        The robot's top speed (m/s) and acceleration (m/s^2): a drive whose
        :func:`least_time` bound cannot beat the best arrival is not timed.
    k_min : int
        The first grid time at which the robot may leave the start (it rests there before:
        a turn in place).
    j_top : float
        The robot's jerk limit (m/s^3), for the same bound; default none.
    launch : callable, optional
        A robot moving at ``t = 0``: ``launch(s1)`` is its motion from its state at ``s = 0``
        to rest at ``s1`` (m) (``None`` when it cannot stop there). It cannot rest at the
        start: its first drive is a launch, at ``t = 0``.
    brake_at : float, optional
        With ``launch``: where it comes to rest braking at once (m), one more stop.

    Returns
    -------
    parts : list of (float, Piece or None, float)
        ``(start time (s), drive, or None for a rest, the rest's arc length (m))``, in order.
    arrival : float
        The arrival time at the goal (s).
    label : str
        The plan in words (its waits and stops).
    """
    dt = grid.dt
    kk = grid.t.shape[0]
    moving = launch is not None
    stops = stop_points(grid, () if brake_at is None else (brake_at,))
    nodes = grid.index(np.asarray(stops))
    w_n = len(stops)
    sa = np.asarray(stops)
    steps = np.arange(kk)
    lt = least_times(sa[None, :] - sa[:, None], v_top, a_top, j_top)  # lt[w, v]: w -> v
    ptr, _, m_lo, m_hi = (np.asarray(x, dtype=np.int64) for x in grid.merged)
    goal_col = column_kernel(ptr, m_lo, m_hi, kk, int(nodes[-1]))
    last_goal = int(np.max(np.flatnonzero(goal_col))) if goal_col.any() else -1
    # arrivals[w, k]: the robot comes to rest at stop w at t_k; parent (stop, start index, piece)
    arrivals = np.zeros((w_n, kk), dtype=bool)
    parent = np.full((3, w_n, kk), -1, dtype=np.int64)  # (stop, start index, drive) of each
    pieces: list[Piece] = []
    start_col = column_kernel(ptr, m_lo, m_hi, kk, int(nodes[0]))
    arrivals[0, 0] = not start_col[0]
    resting: list[tuple[np.ndarray, np.ndarray]] = []
    best: tuple[float, int, int, Piece] | None = None  # (arrival, from stop, start index, drive)
    goal = w_n - 1
    for w in range(goal):
        col = start_col if w == 0 else column_kernel(ptr, m_lo, m_hi, kk, int(nodes[w]))
        rest, since = rest_kernel(arrivals[w], col)  # compiled (trajopt.moving._node_times)
        if w == 0 and moving:  # no rest: the launch leaves at t = 0
            rest = np.zeros(kk, dtype=bool)
            rest[0] = arrivals[0, 0]
            since = np.zeros(kk, dtype=np.int64)
        resting.append((rest, since))
        if w == 0:
            rest = rest & (steps >= (0 if moving else k_min))
        if not rest.any():
            continue
        first = int(np.argmax(rest))
        # a bound on the arrival through each later stop: a drive that cannot beat the best
        # arrival is not timed; an arrival comes after the goal's last forbidden time, less
        # a step
        if moving and w == 0:  # from a speed: at least the distance at the top speed
            lower = (sa[w + 1 :] - sa[0]) / v_top + lt[w + 1 :, goal]
        else:
            lower = first * dt + lt[w, w + 1 :] + lt[w + 1 :, goal]
        lower = np.maximum(lower, last_goal * dt)
        # the goal first: its arrival bounds the drives to the other stops
        if best is None or lower[-1] < best[0]:
            piece = launch(stops[goal]) if moving and w == 0 else drive(stops[w], stops[goal])
            if piece is not None:
                _, n, i0, first_v, last_v = piece.walk(grid)
                ok = ~blocked_starts_kernel(ptr, m_lo, m_hi, kk, i0, first_v, last_v) & rest
                ok &= steps + n > last_goal
                if ok.any():
                    k = int(np.argmax(ok))
                    t_arr = k * dt + piece.duration
                    if best is None or t_arr < best[0]:
                        best = (t_arr, w, k, piece)
        cand = range(w + 1, goal)
        if best is not None:
            cand = (w + 1 + np.flatnonzero(lower[:-1] < best[0])).tolist()
        vs: list[int] = []
        batch: list[Piece] = []  # the drives to stops, tested together
        for v in cand:
            piece = launch(stops[v]) if moving and w == 0 else drive(stops[w], stops[v])
            if piece is not None:
                vs.append(v)
                batch.append(piece)
        if not batch:
            continue
        # the drive to stop v leaving at t_k arrives at t_(k + n) (the drives of one batch go
        # to distinct stops): blocked starts and arrivals in one compiled pass
        walks = [pc.walk(grid) for pc in batch]
        size = np.array([x[3].shape[0] for x in walks], dtype=np.int64)
        arrive_kernel(
            ptr,
            m_lo,
            m_hi,
            rest,
            np.array([x[2] for x in walks], dtype=np.int64),
            np.cumsum(size) - size,
            size,
            np.concatenate([x[3] for x in walks]),
            np.concatenate([x[4] for x in walks]),
            np.array([x[1] for x in walks], dtype=np.int64),
            np.array(vs, dtype=np.int64),
            w,
            len(pieces),
            arrivals,
            parent,
        )
        pieces.extend(batch)
    if best is None:
        return None
    t_arr, w, k, piece = best
    chain: list[tuple[int, Piece]] = [(k, piece)]
    while w > 0:
        k_arr = int(resting[w][1][k])
        w, k, piece = (
            int(parent[0, w, k_arr]),
            int(parent[1, w, k_arr]),
            pieces[parent[2, w, k_arr]],
        )
        chain.append((k, piece))
    chain.reverse()
    schedule = [(k * dt, pc) for k, pc in chain]
    return parts_of(schedule, moving), t_arr, describe(schedule, moving, stops[-1])


def parts_of(
    schedule: Sequence[tuple[float, Piece]], moving: bool
) -> list[tuple[float, Piece | None, float]]:
    """Return :func:`search`'s ``parts`` of drives launched at the given times (s).

    The robot rests before each launch (at the start only when not ``moving``: a moving
    robot's first drive leaves at ``t = 0``) and, after the last drive, at the goal.
    """
    parts: list[tuple[float, Piece | None, float]] = [] if moving else [(0.0, None, 0.0)]
    for t0, pc in schedule:
        parts.append((t0, pc, pc.s0))
        parts.append((t0 + pc.duration, None, pc.s1))
    parts.pop()  # the goal's rest is the trajectory's end
    return parts


def describe(schedule: Sequence[tuple[float, Piece]], moving: bool, length: float) -> str:
    """Return the plan of drives launched at the given times (s) in words (its waits and stops)."""
    words = [] if moving else [f"wait {schedule[0][0]:.3f} s at the start"]
    for i, (t0, pc) in enumerate(schedule):
        if moving and i == 0:
            words.append(
                "drive on to the goal" if pc.s1 >= length else f"brake to s = {pc.s1:.3f} m"
            )
        elif pc.s0 > 0.0:
            words.append(f"stop at s = {pc.s0:.3f} m until t = {t0:.3f} s")
    return ", ".join(words)


def compose(
    parts: list[tuple[float, Piece | None, float]], length: float
) -> tuple[np.ndarray, float]:
    """Return the phase rows, shape (p, 5), of a schedule from :func:`search`, and its duration (s)."""
    rows = []
    t_end = 0.0
    for t0, pc, s_rest in parts:
        if pc is None:
            rows.append(np.array([[t0, s_rest, 0.0, 0.0, 0.0]]))
            continue
        r = pc.rows.copy()
        r[:, 0] += t0
        rows.append(r)
        t_end = t0 + pc.duration
    out = np.concatenate(rows)
    keep = np.append(np.diff(out[:, 0]) > 0.0, True)  # a zero-length rest goes
    keep[0] = True
    out = out[keep]
    out[:, 1] = np.clip(np.maximum.accumulate(out[:, 1]), 0.0, length)
    return out, t_end
