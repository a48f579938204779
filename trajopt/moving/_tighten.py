"""Shorten the rests of a re-timed schedule to the earliest launches the movers allow.

The ``(s, t)`` grid search (:mod:`._st_search`) decides on a time step ``dt`` and pads every
mover by what can happen between grid times, so its waits end up to ``dt`` plus that pad
too late. :func:`tighten` then moves each drive of the schedule (with everything after it)
as early as the movers allow, the first drive first (the wait at the start), then the ones
leaving a stop, without changing the drives themselves: only rests get shorter.

**The earliest launch of a shifted tail.** For a disc robot and disc movers it is found
exactly in time. Fine nodes ``s_i`` along the path (spacing ``h``, at most
:data:`FINE_DS`): while ``|s - s_i| <= h/2`` the robot centre is within ``h/2`` of
``C(s_i)``, so it keeps its limit when ``C(s_i)`` keeps the limit plus ``h/2``, whose
violation times are the closed-form windows of :func:`._st_grid.disc_windows`. A motion
starting at ``L`` occupies node ``i`` during ``[L + a, L + b]`` (``[a, b]`` from dense
samples of the drives, widened to the samples around it, the rests' and the goal's standing
exactly); it meets a window ``(lo, hi)`` iff ``lo - b < L < hi - a``. The earliest ``L`` of
the allowed range outside all of these intervals is the launch. The fine test is
sufficient, and :func:`trajopt.certify_movers` decides on the result: the caller keeps the
untightened schedule when it fails. Other shapes (a footprint robot, a polygon mover)
bisect the wait at the start over certificates (:func:`bisect_start`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from trajopt.moving._obstacle import MovingObstacle
from trajopt.moving._st_grid import disc_windows
from trajopt.moving._st_search import Piece

#: The fine nodes' largest spacing (m): the robot's share of the pad is half of it.
FINE_DS = 0.005
#: Time step (s) of the drives' samples that bound when the robot is near a node.
SAMPLE_DT = 2e-3
#: A launch is placed this far (s) past the end of a forbidden interval.
EPS_L = 1e-6
#: Bisection steps of :func:`bisect_start`.
BISECT_STEPS = 5

#: A schedule: ``(launch time (s), drive)`` in order; the robot rests between the drives
#: (and at the start before the first, at the goal after the last).
Schedule = list[tuple[float, Piece]]


class FineWindows:
    """The movers' violation windows at the fine nodes of a path (module docstring).

    Parameters
    ----------
    s : ndarray, shape (n,)
        Fine nodes (m), evenly spaced ``h`` apart from 0 to the path's length.
    pts : ndarray, shape (n, 2)
        The path's points there (m).
    movers : sequence of MovingObstacle
        Disc movers.
    limit : float
        Robot radius plus margin (m).
    near : ndarray of bool, shape (movers, n), optional
        The nodes each mover can come near (a filter); default all.
    """

    def __init__(
        self,
        s: np.ndarray,
        pts: np.ndarray,
        movers: Sequence[MovingObstacle],
        limit: float,
        near: np.ndarray | None = None,
    ) -> None:
        self.s, self.h = s, float(s[1] - s[0])
        sel = None if near is None else [np.flatnonzero(row) for row in near]
        node, lo, hi = disc_windows(pts, movers, limit + 0.5 * self.h, sel)
        order = np.argsort(node, kind="stable")
        node, self.lo, self.hi = node[order], lo[order], hi[order]
        counts = np.bincount(node, minlength=s.shape[0])
        self.ptr = np.concatenate([[0], np.cumsum(counts)])

    def node_range(self, s0: float, s1: float, every: bool = False) -> np.ndarray:
        """Return the fine nodes within ``h/2`` of ``[s0, s1]`` (m) that have windows (or all)."""
        h = self.h
        i0 = max(int(math.floor((s0 - 0.5 * h) / h + 1e-9)), 0)
        i1 = min(int(math.ceil((s1 + 0.5 * h) / h - 1e-9)), self.s.shape[0] - 1)
        idx = np.arange(i0, i1 + 1)
        idx = idx[np.abs(np.clip(self.s[idx], s0, s1) - self.s[idx]) <= 0.5 * h + 1e-12]
        return idx if every else idx[self.ptr[idx + 1] > self.ptr[idx]]

    def drive_occupancy(self, piece: Piece) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Return ``(node, a, b)``: the drive is within ``h/2`` of node ``s_i`` only in ``[a, b]`` (s).

        From samples every :data:`SAMPLE_DT` of ``s(t)`` (non-decreasing): from the last
        sample before it comes within ``h/2`` to the first after it leaves. Kept on the piece.
        """
        key = ("fine", self.h, self.s.shape[0])
        if key not in piece.memo:
            idx = self.node_range(piece.s0, piece.s1, every=True)
            n = int(math.ceil(piece.duration / SAMPLE_DT))
            t = np.append(np.arange(n) * SAMPLE_DT, piece.duration)
            s = piece.s_at(t)
            h = 0.5 * self.h
            enter = np.clip(np.searchsorted(s, self.s[idx] - h, side="left") - 1, 0, t.size - 1)
            leave = np.clip(np.searchsorted(s, self.s[idx] + h, side="right"), 0, t.size - 1)
            piece.memo[key] = (idx, t[enter], t[leave])
        idx, a, b = piece.memo[key]
        has = self.ptr[idx + 1] > self.ptr[idx]
        return idx[has], a[has], b[has]

    def earliest(
        self, occupancy: Sequence[tuple[np.ndarray, np.ndarray, np.ndarray]], lo: float, hi: float
    ) -> float | None:
        """Return the earliest launch ``L`` in ``[lo, hi]`` (s) meeting no window, or ``None``.

        ``occupancy``: ``(node, a, b)`` arrays, the motion near node ``i`` during
        ``[L + a, L + b]``.
        """
        node = np.concatenate([o[0] for o in occupancy])
        a = np.concatenate([o[1] for o in occupancy])
        b = np.concatenate([o[2] for o in occupancy])
        counts = self.ptr[node + 1] - self.ptr[node]
        total = int(counts.sum())
        if total == 0:
            return lo
        which = np.repeat(np.arange(node.shape[0]), counts)
        first = np.repeat(self.ptr[node], counts)
        run = first + np.arange(total) - np.repeat(np.cumsum(counts) - counts, counts)
        f_lo = self.lo[run] - b[which]
        f_hi = self.hi[run] - a[which]
        keep = f_hi > lo
        f_lo, f_hi = f_lo[keep], f_hi[keep]
        order = np.argsort(f_lo, kind="stable")
        f_lo, f_hi = f_lo[order], f_hi[order]
        cur = lo
        # the first interval that starts after everything before it (and lo) has ended
        reach = np.maximum(np.maximum.accumulate(f_hi) + EPS_L, lo)
        prev = np.concatenate([[lo], reach[:-1]])
        gap = np.flatnonzero(f_lo >= prev)
        cur = float(prev[gap[0]]) if gap.size else float(reach[-1]) if reach.size else lo
        return cur if cur <= hi else None


def tail_occupancy(
    fine: FineWindows, schedule: Schedule, k: int, length: float
) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Return the occupancy of ``schedule[k:]`` and the standing at the goal, from its launch."""
    t0 = schedule[k][0]
    out = []
    for j in range(k, len(schedule)):
        tj, pc = schedule[j]
        node, a, b = fine.drive_occupancy(pc)
        out.append((node, a + (tj - t0), b + (tj - t0)))
        end = tj + pc.duration - t0
        nxt = schedule[j + 1][0] - t0 if j + 1 < len(schedule) else math.inf
        if nxt > end or nxt == math.inf:
            idx = fine.node_range(pc.s1, pc.s1)
            out.append((idx, np.full(idx.shape, end), np.full(idx.shape, nxt)))
    return out


def tighten(fine: FineWindows, schedule: Schedule, first: float, length: float) -> Schedule:
    """Return ``schedule`` with every rest as short as the fine windows allow (module docstring).

    Parameters
    ----------
    fine : FineWindows
    schedule : list of (float, Piece)
        Launch times (s) and drives; the robot rests before each launch.
    first : float
        The earliest launch of the first drive (s): the end of a rest that must stay (a
        turn in place), or ``inf`` when the first drive's launch is fixed (a moving start).
    length : float
        The path's length (m).

    Returns
    -------
    list of (float, Piece)
        The same drives, launched earlier where possible (never later).
    """
    out = list(schedule)
    for k in range(len(out)):
        lo = first if k == 0 else out[k - 1][0] + out[k - 1][1].duration
        t_k = out[k][0]
        if not lo < t_k:
            continue
        best = fine.earliest(tail_occupancy(fine, out, k, length), lo, t_k)
        if best is not None and best < t_k:
            shift = t_k - best
            out[k:] = [(t - shift, pc) for t, pc in out[k:]]
    return out


def bisect_start(
    ok: Callable[[float], bool], lo: float, hi: float, steps: int = BISECT_STEPS
) -> float:
    """Return a launch in ``[lo, hi]`` (s) that ``ok`` accepts, as early as bisection finds.

    ``hi`` is accepted (the untightened schedule); each step tests the middle of the bracket
    between the last refused launch and the last accepted one.
    """
    if ok(lo):
        return lo
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        if ok(mid):
            hi = mid
        else:
            lo = mid
    return hi
