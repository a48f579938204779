"""Tests of trajopt.moving's (s, t) search against the loop it replaced (one drive at a time).

The search sets the arrivals of a stop's drives to all later stops at once and picks the
drives worth timing by one vectorised bound; the reference below is the former loop, which
tested and set them one drive at a time. On random crossings of a straight path and on a
curved one, every search that ``retime_for_movers`` runs (spied on; its grid, drives and
bounds) must give the same schedule, arrival and words as the reference. A drive's arc
lengths at its times (compiled) are the array expression's, bit for bit, and integrate its
jerk.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest

import trajopt.moving._retime as retime_module
from trajopt.errors import BlockedError, InvalidInputError
from trajopt.geometry import PolylineCurve
from trajopt.moving import MovingObstacle, retime_for_movers
from trajopt.moving._st_grid import STGrid
from trajopt.moving._st_search import (
    Piece,
    describe,
    fill_visits,
    least_times,
    parts_of,
    search,
    stop_points,
)
from trajopt.robot import Robot
from trajopt.timing import time_parameterize

ROBOT = Robot(v_max=0.6, a_max=0.6, j_max=2.0)


def _rest_closure(arrive: np.ndarray, blocked_col: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Resting times after the arrivals ``arrive`` while the node stays free; each one's arrival."""
    idx = np.arange(arrive.shape[0])
    last_arr = np.maximum.accumulate(np.where(arrive, idx, -1))
    last_blk = np.maximum.accumulate(np.where(blocked_col, idx, -1))
    return (last_arr >= 0) & (last_arr > last_blk), last_arr


def _search_before(
    grid: STGrid,
    drive: Callable[[float, float], Piece | None],
    v_top: float,
    a_top: float,
    k_min: int = 0,
    j_top: float = math.inf,
    launch: Callable[[float], Piece | None] | None = None,
    brake_at: float | None = None,
) -> tuple[list[tuple[float, Piece | None, float]], float, str] | None:
    """The loop before the stops' batches were set at once (the reference)."""
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


def _same(a, b):
    if a is None or b is None:
        return a is None and b is None
    (pa, ta, la), (pb, tb, lb) = a, b
    if ta != tb or la != lb or len(pa) != len(pb):
        return False
    for (t0, p0, s0), (t1, p1, s1) in zip(pa, pb, strict=True):
        if t0 != t1 or s0 != s1 or (p0 is None) != (p1 is None):
            return False
        if p0 is not None and not (p0.duration == p1.duration and np.array_equal(p0.rows, p1.rows)):
            return False
    return True


@pytest.fixture
def spy(monkeypatch):
    calls = []

    def both(*args, **kwargs):
        got = search(*args, **kwargs)
        calls.append(_same(got, _search_before(*args, **kwargs)))
        return got

    monkeypatch.setattr(retime_module, "search", both)
    return calls


def _crossings(rng, n, length):
    movers = []
    for i in range(n):
        x, y = rng.uniform(0.5, length - 0.5), rng.choice([-1.0, 1.0]) * rng.uniform(1.0, 3.0)
        v = (rng.uniform(-0.4, 0.4), -np.sign(y) * rng.uniform(0.2, 0.5))
        t0 = rng.uniform(0.0, 4.0)
        movers.append(
            MovingObstacle.from_waypoints(
                [t0, t0 + 15.0],
                [(x, y), (x + 15.0 * v[0], y + 15.0 * v[1])],
                radius=rng.uniform(0.1, 0.4),
                name=f"m{i}",
            )
        )
    return movers


@pytest.mark.parametrize(
    "corners", [[[0.0, 0.0], [8.0, 0.0]], [[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [7.0, 4.5]]]
)
def test_the_search_equals_the_one_drive_at_a_time_loop(spy, corners):
    static = time_parameterize(PolylineCurve(np.array(corners)), ROBOT)
    rng = np.random.default_rng(46)
    for _ in range(40):
        if len(spy) >= 8:
            break
        try:
            retime_for_movers(static, _crossings(rng, int(rng.integers(2, 7)), static.length))
        except (BlockedError, InvalidInputError):
            pass
    assert len(spy) >= 8 and all(spy)


@pytest.mark.parametrize("v0, a0", [(0.3, 0.0), (0.5, -0.2), (0.1, 0.4)])
def test_the_search_from_a_moving_start_equals_the_loop(spy, v0, a0):
    line = PolylineCurve(np.array([[0.0, 0.0], [8.0, 0.0]]))
    rolling = time_parameterize(line, ROBOT, v_start=v0, a_start=a0)
    rng = np.random.default_rng(int(10 * v0))
    for _ in range(30):
        if len(spy) >= 4:
            break
        try:
            retime_for_movers(rolling, _crossings(rng, int(rng.integers(2, 6)), rolling.length))
        except (BlockedError, InvalidInputError):
            pass
    assert len(spy) >= 4 and all(spy)


def _s_at_array(piece: Piece, t: np.ndarray) -> np.ndarray:
    """The drive's arc lengths at ``t`` as one array expression (numpy's clipping and search)."""
    tt = np.minimum(np.maximum(t, 0.0), piece.duration)
    rows = piece.rows
    k = np.maximum(np.searchsorted(rows[:, 0], tt, side="right") - 1, 0)
    tau = tt - rows[k, 0]
    s = rows[k, 1] + tau * (rows[k, 2] + tau * (0.5 * rows[k, 3] + tau * rows[k, 4] / 6.0))
    s = np.minimum(np.maximum(s, piece.s0), piece.s1)
    return np.where(tt >= piece.duration, piece.s1, s)


def test_a_drives_compiled_arc_lengths_are_the_array_expressions_and_integrate_its_jerk():
    rng = np.random.default_rng(5)
    for trial in range(300):
        p = int(rng.integers(1, 9))
        t0 = np.sort(rng.uniform(0.0, 5.0, p))
        t0[0] = 0.0
        if trial % 3 == 0 and p > 2:
            t0[2] = t0[1]  # a phase of zero duration
        rows = np.column_stack([t0, np.cumsum(rng.uniform(0.0, 1.0, p)), *rng.normal(size=(3, p))])
        duration = float(t0[-1] + rng.uniform(0.0, 2.0))
        piece = Piece(rows, duration, float(rows[0, 1]), float(rows[-1, 1] + rng.uniform(0, 1)))
        t = np.concatenate(
            [rng.uniform(-1.0, duration + 1.0, 200), t0, [duration, -0.0, 2.0 * duration]]
        )
        assert piece.s_at(t).tobytes() == _s_at_array(piece, t).tobytes()
        assert piece.s_at(t.reshape(-1, 1)).shape == (t.shape[0], 1)
        assert piece.s_at(t[::2]).tobytes() == _s_at_array(piece, t[::2]).tobytes()
    # a drive of the path's timing: its arc lengths integrate its jerk (dense Euler steps)
    traj = time_parameterize(PolylineCurve(np.array([[0.0, 0.0], [3.0, 0.0]])), ROBOT)
    rows = np.column_stack([traj.phase_t, traj.phase_s, traj.phase_v, traj.phase_a, traj.phase_j])
    piece = Piece(rows, float(traj.duration), 0.0, float(traj.length))
    dt = 1e-5
    t = np.arange(0.0, traj.duration, dt)
    jerk = traj.phase_j[np.searchsorted(traj.phase_t, t, side="right") - 1]
    a = np.concatenate([[0.0], np.cumsum(jerk * dt)])[:-1]
    v = np.concatenate([[0.0], np.cumsum(a * dt)])[:-1]
    s = np.concatenate([[0.0], np.cumsum(v * dt)])[:-1]
    assert np.max(np.abs(piece.s_at(t) - s)) < 1e-3
    assert piece.s_at(np.array([traj.duration]))[0] == traj.length
