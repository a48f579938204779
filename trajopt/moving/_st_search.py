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

from trajopt.moving._st_grid import NEVER_STEP, STGrid, visits

#: Evenly spaced stops tried besides the start, the goal and the fronts of the forbidden regions.
N_EVEN_STOPS = 10
#: The fronts of the forbidden regions are rounded back to multiples of this many nodes.
STOP_LATTICE = 5


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

    def nodes(self, grid: STGrid) -> np.ndarray:
        """Return the grid node (index) of the drive at each grid step from its start, shape (m,)."""
        key = (grid.dt, grid.ds, grid.s.shape[0])
        if key not in self.memo:
            n = int(math.ceil(self.duration / grid.dt - 1e-9))
            self.memo[key] = grid.index(self.s_at(np.arange(n + 1) * grid.dt))
        return self.memo[key]

    def visits(self, grid: STGrid) -> tuple[int, np.ndarray, np.ndarray]:
        """Return :func:`._st_grid.visits` of :meth:`nodes` (kept on the piece)."""
        key = ("visits", grid.dt, grid.ds, grid.s.shape[0])
        if key not in self.memo:
            self.memo[key] = visits(self.nodes(grid))
        return self.memo[key]

    def s_at(self, t: np.ndarray) -> np.ndarray:
        """Return the arc length (m) at the drive's times ``t`` (s), clipped to its ends."""
        tt = np.minimum(np.maximum(t, 0.0), self.duration)
        rows = self.rows
        k = np.maximum(np.searchsorted(rows[:, 0], tt, side="right") - 1, 0)
        tau = tt - rows[k, 0]
        s = rows[k, 1] + tau * (rows[k, 2] + tau * (0.5 * rows[k, 3] + tau * rows[k, 4] / 6.0))
        s = np.minimum(np.maximum(s, self.s0), self.s1)
        return np.where(tt >= self.duration, self.s1, s)


def fill_visits(pieces: Sequence[Piece], grid: STGrid) -> None:
    """Compute :meth:`Piece.nodes` and :meth:`Piece.visits` of several drives at once (kept on each).

    The drives' rows are put one after another on a clock that gives each drive its own
    span (drive ``i`` at ``i T``, ``T`` a power of two above every duration), so that one
    search finds the row of every grid step of every drive.
    """
    key = (grid.dt, grid.ds, grid.s.shape[0])
    todo = [pc for pc in pieces if key not in pc.memo]
    if not todo:
        return
    dt = grid.dt
    dur = np.array([pc.duration for pc in todo])
    steps = np.ceil(dur / dt - 1e-9).astype(np.int64) + 1
    span = 2.0 ** math.ceil(math.log2(float(np.max(dur)) + 2.0))
    rows = np.concatenate([pc.rows for pc in todo])
    per = np.array([pc.rows.shape[0] for pc in todo])
    first_row = np.cumsum(per) - per
    who = np.repeat(np.arange(len(todo)), steps)
    t = (np.arange(int(steps.sum())) - np.repeat(np.cumsum(steps) - steps, steps)) * dt
    tt = np.minimum(t, dur[who])
    clock = np.repeat(np.arange(len(todo)), per) * span + rows[:, 0]
    k = np.searchsorted(clock, who * span + tt, side="right") - 1
    k = np.maximum(k, first_row[who])
    tau = tt - rows[k, 0]
    s = rows[k, 1] + tau * (rows[k, 2] + tau * (0.5 * rows[k, 3] + tau * rows[k, 4] / 6.0))
    s0 = np.array([pc.s0 for pc in todo])[who]
    s1 = np.array([pc.s1 for pc in todo])[who]
    s = np.where(tt >= dur[who], s1, np.minimum(np.maximum(s, s0), s1))
    idx = grid.index(s)
    # the visits of every drive at once (:func:`._st_grid.visits`): each drive's nodes are
    # non-decreasing, so a node's first and last steps are where its run of steps starts
    # and ends
    ends = np.cumsum(steps)
    starts = ends - steps
    i0 = idx[starts]
    size = idx[ends - 1] - i0 + 1
    base = np.cumsum(size) - size
    rel = idx - i0[who] + base[who]
    j = np.arange(idx.shape[0]) - starts[who]
    run_start = np.ones(idx.shape[0], dtype=bool)
    run_start[1:] = (idx[1:] != idx[:-1]) | (who[1:] != who[:-1])
    run_end = np.roll(run_start, -1)
    run_end[-1] = True
    first = np.full(int(size.sum()), NEVER_STEP)
    last = np.full(int(size.sum()), -NEVER_STEP)
    first[rel[run_start]] = j[run_start]
    last[rel[run_end]] = j[run_end]
    for i, pc in enumerate(todo):
        pc.memo[key] = idx[starts[i] : ends[i]]
        sl = slice(int(base[i]), int(base[i] + size[i]))
        pc.memo[("visits", *key)] = (int(i0[i]), first[sl], last[sl])


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


def _rest_closure(arrive: np.ndarray, blocked_col: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Resting times after the arrivals ``arrive`` while the node stays free; each one's arrival."""
    idx = np.arange(arrive.shape[0])
    last_arr = np.maximum.accumulate(np.where(arrive, idx, -1))
    last_blk = np.maximum.accumulate(np.where(blocked_col, idx, -1))
    return (last_arr >= 0) & (last_arr > last_blk), last_arr


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
    goal_col = grid.column(int(nodes[-1]))
    last_goal = int(np.max(np.flatnonzero(goal_col))) if goal_col.any() else -1
    # arrivals[w][k]: the robot comes to rest at stop w at t_k; parent (stop, start index, piece)
    arrivals = [np.zeros(kk, dtype=bool) for _ in range(w_n)]
    parent_w = np.full((w_n, kk), -1, dtype=np.int64)
    parent_k = np.full((w_n, kk), -1, dtype=np.int64)
    parent_p = np.full((w_n, kk), -1, dtype=np.int64)
    pieces: list[Piece] = []
    start_col = grid.column(int(nodes[0]))
    arrivals[0][0] = not start_col[0]
    resting: list[tuple[np.ndarray, np.ndarray]] = []
    best: tuple[float, int, int, Piece] | None = None  # (arrival, from stop, start index, drive)
    for w in range(w_n - 1):
        col = start_col if w == 0 else grid.column(int(nodes[w]))
        rest, since = _rest_closure(arrivals[w], col)
        if w == 0 and moving:  # no rest: the launch leaves at t = 0
            rest = np.zeros(kk, dtype=bool)
            rest[0] = arrivals[0][0]
            since = np.zeros(kk, dtype=np.int64)
        resting.append((rest, since))
        if w == 0:
            rest = rest & (steps >= (0 if moving else k_min))
        if not rest.any():
            continue
        first = int(np.argmax(rest))
        batch: list[tuple[int, Piece]] = []  # the drives to stops, tested together
        for v in [w_n - 1, *range(w + 1, w_n - 1)]:  # the goal first: a bound for the rest
            if moving and w == 0:  # from a speed: at least the distance at the top speed
                lower = (stops[v] - stops[0]) / v_top + lt[v, w_n - 1]
            else:
                lower = first * dt + lt[w, v] + lt[v, w_n - 1]
            # an arrival comes after the goal's last forbidden time, less a step
            lower = max(lower, last_goal * dt)
            if best is not None and lower >= best[0]:
                continue
            piece = launch(stops[v]) if moving and w == 0 else drive(stops[w], stops[v])
            if piece is None:
                continue
            if v < w_n - 1:
                batch.append((v, piece))
                continue
            n = piece.nodes(grid).shape[0] - 1
            ok = ~grid.blocked_starts_many([piece.visits(grid)])[0] & rest
            ok &= steps + n > last_goal
            if ok.any():
                k = int(np.argmax(ok))
                t_arr = k * dt + piece.duration
                if best is None or t_arr < best[0]:
                    best = (t_arr, w, k, piece)
        fill_visits([pc for _, pc in batch], grid)
        bad = grid.blocked_starts_many([pc.visits(grid) for _, pc in batch])
        for (v, piece), bad_v in zip(batch, bad, strict=True):
            n = piece.nodes(grid).shape[0] - 1
            ok = ~bad_v & rest
            ks = np.flatnonzero(ok[: max(0, kk - n)])
            new = ks[~arrivals[v][ks + n]]
            if new.size:
                arrivals[v][new + n] = True
                parent_w[v, new + n] = w
                parent_k[v, new + n] = new
                parent_p[v, new + n] = len(pieces)
                pieces.append(piece)
    if best is None:
        return None
    t_arr, w, k, piece = best
    chain: list[tuple[int, Piece]] = [(k, piece)]
    while w > 0:
        k_arr = int(resting[w][1][k])
        w, k, piece = (
            int(parent_w[w, k_arr]),
            int(parent_k[w, k_arr]),
            pieces[parent_p[w, k_arr]],
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
