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
violation times are the closed-form windows of :func:`._disc_windows.disc_windows`. A motion
starting at ``L`` occupies node ``i`` during ``[L + a, L + b]`` (``[a, b]`` from dense
samples of the drives, widened to the samples around it); it meets a window ``(lo, hi)``
iff ``lo - b < L < hi - a``. The rests and the standing at the goal are tested at the
path's point itself (:meth:`FineWindows.point_windows`). The earliest ``L`` of the allowed
range outside all of these intervals is the launch; for the wait at the start (the one the
waiting witness of the benchmarks is measured by), the intervals that decide it are then
computed again from the motion's own points on samples every :data:`REFINE_DT`
(:meth:`FineWindows.earliest`); the waits at stops keep the fine nodes' answer (cheaper). The test is sufficient, and :func:`trajopt.certify_movers`
decides on the result: the caller keeps the untightened schedule when it fails. Polygon
movers (with a disc robot) use the same machinery with sampled windows
(:class:`._shape_windows.ShapeWindows`); a footprint robot bisects the wait at the start
over certificates (:func:`bisect_start`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from trajopt.moving._disc_windows import close_pairs, disc_windows, mover_pieces, near_pairs
from trajopt.moving._obstacle import MovingObstacle
from trajopt.moving._st_kernels import blocked_launches_kernel, least_free_kernel, pass_band_kernel
from trajopt.moving._st_search import Piece

#: The fine nodes' largest spacing (m): the robot's share of the pad is half of it.
FINE_DS = 0.01
#: Time step (s) of the drives' samples that bound when the robot is near a node.
SAMPLE_DT = 2e-3
#: A launch is placed this far (s) past the end of a forbidden interval.
EPS_L = 1e-6
#: The refinement's time step (s) and how far before the launch (s) a deciding interval ends.
REFINE_DT = 2.5e-4
REFINE_S = 0.04
#: The refinement is exact for the launches this long (s) before the launch it refines; the
#: replaced intervals stay as they were for the earlier ones.
REFINE_SPAN = 0.25
#: The pad (m) of a rest's point against the path's evaluation (its arc length interpolated).
POINT_PAD = 1e-4
#: Bisection steps of :func:`bisect_start`.
BISECT_STEPS = 5
#: Time step (s) of the samples of the motions that bound the fine windows' band (:func:`pass_band`).
BAND_DT = 0.01

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
    band : (ndarray, ndarray), optional
        Per node, shape (n,) each: the times (s) between which the motions asked about can
        be within ``h/2`` of it (their launches, samples and refinement included); windows
        of the pieces of the tracks outside them are left out. Default: all times.
    where : callable, optional
        ``where(s)``: the path's points (m), shape (m, 2), at arc lengths ``s`` (m), shape
        (m,); with it, :meth:`earliest` refines the windows that decide the launch.
    speed : float
        The robot's speed bound (m/s), for the refinement's samples.
    """

    def __init__(
        self,
        s: np.ndarray,
        pts: np.ndarray,
        movers: Sequence[MovingObstacle],
        limit: float,
        band: tuple[np.ndarray, np.ndarray] | None = None,
        where: Callable[[np.ndarray], np.ndarray] | None = None,
        speed: float = 0.0,
    ) -> None:
        self.s, self.h = s, float(s[1] - s[0])
        self.movers, self.limit, self.where, self.speed = list(movers), limit, where, speed
        self._points: dict[float, tuple[np.ndarray, np.ndarray]] = {}
        self.pieces = mover_pieces(movers, limit)
        pairs = near_pairs(pts, self.pieces, 0.5 * self.h, band)
        owner, node, lo, hi = disc_windows(pts, self.pieces, 0.5 * self.h, pairs=pairs)
        order = np.argsort(node, kind="stable")
        node, self.lo, self.hi, self.owner = node[order], lo[order], hi[order], owner[order]
        counts = np.bincount(node, minlength=s.shape[0])
        self.ptr = np.concatenate([[0], np.cumsum(counts)])

    def drive_occupancy(self, piece: Piece) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Return ``(node, a, b)``: the drive is within ``h/2`` of node ``s_i`` only in ``[a, b]`` (s).

        From samples every :data:`SAMPLE_DT` of ``s(t)`` (non-decreasing): from the last
        sample before it comes within ``h/2`` to the first after it leaves. Kept on the piece.
        """
        idx, a, b = near_times(piece, self.s, self.h)
        has = self.ptr[idx + 1] > self.ptr[idx]
        return idx[has], a[has], b[has]

    def earliest(
        self,
        occupancy: Sequence[tuple[np.ndarray, np.ndarray, np.ndarray]],
        lo: float,
        hi: float,
        s_of: Callable[[np.ndarray], np.ndarray] | None = None,
        rests: Sequence[tuple[float, float, float]] = (),
    ) -> float | None:
        """Return the earliest launch ``L`` in ``[lo, hi]`` (s) meeting no window, or ``None``.

        ``occupancy``: ``(node, a, b)`` arrays, the motion near node ``i`` during
        ``[L + a, L + b]``. With ``s_of`` (the motion's arc length (m) at its times from the
        launch, s) and the path's points (``where``), the intervals that decide ``L`` (those
        ending within :data:`REFINE_S` before it) are replaced by the exact ones of the
        motion's own points on samples every :data:`REFINE_DT` (the robot's share of the pad
        ``speed REFINE_DT / 2`` instead of ``h / 2`` and the drive samples), twice: for the
        launches up to :data:`REFINE_SPAN` before it (the replaced intervals, cut there, stay
        for the earlier ones).
        ``rests``: ``(s, a, b)``, the motion at rest at ``s`` (m) during ``[L + a, L + b]``,
        against the exact windows of the path's point there (:meth:`point_windows`).
        """
        r_lo, r_hi = [np.zeros(0)], [np.zeros(0)]
        self.fetch_points([s_r for s_r, _, _ in rests])
        for s_r, a_r, b_r in rests:
            w_lo, w_hi = self.point_windows(s_r)
            r_lo.append(w_lo - b_r)
            r_hi.append(w_hi - a_r)
        rest_lo, rest_hi = np.concatenate(r_lo), np.concatenate(r_hi)
        node = np.concatenate([o[0] for o in occupancy])
        a = np.concatenate([o[1] for o in occupancy])
        b = np.concatenate([o[2] for o in occupancy])
        f_lo, f_hi, which, run = blocked_launches(node, a, b, self.ptr, self.lo, self.hi, lo)
        span_a, span_b, owner = a[which], b[which], self.owner[run]
        cur = sweep(np.append(f_lo, rest_lo), np.append(f_hi, rest_hi), lo)
        if s_of is None or self.where is None:
            return cur if cur <= hi else None
        extra_lo, extra_hi = rest_lo, rest_hi
        for _ in range(2):
            if cur > hi:
                break
            bind = (f_hi >= cur - REFINE_S) & (f_lo < cur)
            if not bind.any():
                break
            # exact for the launches in [lo_x, cur]; below lo_x the replaced intervals stay
            lo_x = max(lo, cur - REFINE_SPAN)
            x_lo, x_hi = self._exact(span_a[bind], span_b[bind], owner[bind], s_of, lo_x, cur)
            below = bind & (f_lo < lo_x)
            x_lo = np.concatenate([x_lo, f_lo[below]])
            x_hi = np.concatenate([x_hi, np.minimum(f_hi[below], lo_x)])
            f_lo, f_hi = f_lo[~bind], f_hi[~bind]
            span_a, span_b, owner = span_a[~bind], span_b[~bind], owner[~bind]
            extra_lo, extra_hi = np.append(extra_lo, x_lo), np.append(extra_hi, x_hi)
            new = sweep(np.append(f_lo, extra_lo), np.append(f_hi, extra_hi), lo)
            if new >= cur:
                break
            cur = new
        return cur if cur <= hi else None

    def fetch_points(self, places: Sequence[float]) -> None:
        """Make the windows of the path's points at ``places`` (m) that are not kept yet (:meth:`point_windows`).

        One at a time here (disc movers' windows are closed-form); movers of other shapes
        make them all in one march (:meth:`._shape_windows.ShapeWindows.fetch_points`).
        """
        for s in places:
            self.point_windows(s)

    def point_windows(self, s: float) -> tuple[np.ndarray, np.ndarray]:
        """Return the windows (s) of the path's point at ``s`` (m): exact, the limit plus 0.1 mm.

        Kept by ``s`` (a rest's place); the point is the path's at ``s`` (``where``), else
        the nearest fine node's with the pad ``h/2``.
        """
        if s not in self._points:
            if self.where is None:
                i = int(np.clip(np.rint(s / self.h), 0, self.s.shape[0] - 1))
                run = slice(int(self.ptr[i]), int(self.ptr[i + 1]))
                lo, hi = self.lo[run], self.hi[run]
            else:
                pt = self.where(np.array([s]))
                _, _, lo, hi = disc_windows(pt, self.pieces, POINT_PAD)
            self._points[s] = (lo, hi)
        return self._points[s]

    def _exact(
        self,
        a: np.ndarray,
        b: np.ndarray,
        owner: np.ndarray,
        s_of: Callable[[np.ndarray], np.ndarray],
        lo: float,
        hi: float,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Return the launches (open intervals, s) at which the motion meets the movers.

        During ``[a_j, b_j]`` (s from the launch) against mover ``owner_j``, from the motion's
        own points every :data:`REFINE_DT` (s); complete for launches in ``[lo, hi]`` (s)
        (only the pieces of the tracks those launches can meet in time, and whose segment
        comes within the limit of the point, :func:`._disc_windows.close_pairs`, are solved).
        The spans of one mover are merged first (neighbouring nodes' spans overlap, and a
        node has a window per piece of a track), each merged span sampled once.
        """
        a, b, owner = merged_spans(a, b, owner)
        n = np.maximum(np.ceil((b - a) / REFINE_DT).astype(np.int64), 1) + 1
        idx = np.repeat(np.arange(a.shape[0]), n)
        step = np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n)
        tau = np.minimum(a[idx] + step * REFINE_DT, b[idx])
        pts = self.where(s_of(tau))
        pad = 0.5 * REFINE_DT
        seg, item = pieces_meeting(self.pieces, owner[idx], tau + lo - pad, tau + hi + pad)
        near = close_pairs(pts, self.pieces, self.speed * pad, seg, item)
        pairs = (seg[near], item[near])
        _, pi, w_lo, w_hi = disc_windows(pts, self.pieces, self.speed * pad, pairs=pairs)
        return w_lo - tau[pi] - pad, w_hi - tau[pi] + pad


def near_times(piece: Piece, s: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return ``(node, a, b)``: the drive is within ``h/2`` of node ``s[node]`` (m) only in ``[a, b]`` (s).

    Every node within ``h/2`` of the drive's span (nodes ``s``, spacing ``h``, from 0), from
    samples every :data:`SAMPLE_DT` of ``s(t)`` (non-decreasing): from the last sample before
    it comes within ``h/2`` to the first after it leaves. Kept on the piece.
    """
    key = ("fine", h, s.shape[0])
    if key not in piece.memo:
        i0 = max(int(math.floor((piece.s0 - 0.5 * h) / h + 1e-9)), 0)
        i1 = min(int(math.ceil((piece.s1 + 0.5 * h) / h - 1e-9)), s.shape[0] - 1)
        idx = np.arange(i0, i1 + 1)
        idx = idx[np.abs(np.clip(s[idx], piece.s0, piece.s1) - s[idx]) <= 0.5 * h + 1e-12]
        n = int(math.ceil(piece.duration / SAMPLE_DT))
        t = np.append(np.arange(n) * SAMPLE_DT, piece.duration)
        at = piece.s_at(t)
        enter = np.clip(np.searchsorted(at, s[idx] - 0.5 * h, side="left") - 1, 0, t.size - 1)
        leave = np.clip(np.searchsorted(at, s[idx] + 0.5 * h, side="right"), 0, t.size - 1)
        piece.memo[key] = (idx, t[enter], t[leave])
    return piece.memo[key]


def blocked_launches(
    node: np.ndarray,
    a: np.ndarray,
    b: np.ndarray,
    ptr: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    after: float = -math.inf,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Return the launches ``(lo_w - b, hi_w - a)`` (s) at which a motion meets a node's window.

    The motion is near node ``node[j]`` during ``[L + a[j], L + b[j]]``; the windows of node
    ``i`` are ``(lo, hi)[ptr[i]:ptr[i + 1]]``. Only the intervals ending after ``after``
    (s) are returned (an interval ending at or before the earliest launch asked about blocks
    none). Also returns, per interval, its ``j`` and its window's index. Compiled
    (:func:`._st_kernels.blocked_launches_kernel`).
    """
    return blocked_launches_kernel(
        np.ascontiguousarray(node, dtype=np.int64),
        np.ascontiguousarray(a, dtype=np.float64),
        np.ascontiguousarray(b, dtype=np.float64),
        np.ascontiguousarray(ptr, dtype=np.int64),
        np.ascontiguousarray(lo, dtype=np.float64),
        np.ascontiguousarray(hi, dtype=np.float64),
        float(after),
    )


def merged_spans(
    a: np.ndarray, b: np.ndarray, owner: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return the union of the spans ``[a_j, b_j]`` (s) of each ``owner``, as ``(a, b, owner)``.

    Sorted by owner, then time; overlapping or touching spans of one owner become one.
    """
    if a.size == 0:
        return a, b, owner
    order = np.lexsort((a, owner))
    a, b, owner = a[order], b[order], owner[order]
    big = 2.0 * (float(np.max(np.abs(b))) + float(np.max(np.abs(a))) + 1.0)
    key = owner * big + b  # a cumulative maximum that restarts with each owner
    ends = np.maximum.accumulate(key) - owner * big
    new = np.ones(a.shape[0], dtype=bool)
    new[1:] = (owner[1:] != owner[:-1]) | (a[1:] > ends[:-1])
    first = np.flatnonzero(new)
    return a[first], np.maximum.reduceat(b, first), owner[first]


def pieces_meeting(
    pieces: np.ndarray, owner: np.ndarray, t_lo: np.ndarray, t_hi: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Return ``(piece, item)``: the pieces of mover ``owner[i]`` whose span meets ``[t_lo[i], t_hi[i]]``.

    ``pieces`` from :func:`._disc_windows.mover_pieces` (in order of mover and time); ``t_hi`` may
    be ``inf``.
    """
    who = pieces[:, 0].astype(np.int64)
    m = int(who[-1]) + 1 if who.size else 0
    nseg = np.bincount(who, minlength=m)
    seg0 = np.cumsum(nseg) - nseg
    big = 4.0 * (float(np.max(pieces[:, 1], initial=0.0)) + 10.0)
    cap = 0.5 * big
    lo_t = np.clip(t_lo, -cap, cap)
    hi_t = np.clip(t_hi, -cap, cap)
    a = np.searchsorted(who * big + np.minimum(pieces[:, 2], cap), owner * big + lo_t)
    b = np.searchsorted(who * big + pieces[:, 1], owner * big + hi_t, side="right")
    a = np.maximum(a, seg0[owner])
    b = np.minimum(b, seg0[owner] + nseg[owner])
    cnt = np.maximum(b - a, 0)
    item = np.repeat(np.arange(owner.shape[0]), cnt)
    seg = np.repeat(a, cnt) + np.arange(int(cnt.sum())) - np.repeat(np.cumsum(cnt) - cnt, cnt)
    return seg, item


def sweep(f_lo: np.ndarray, f_hi: np.ndarray, lo: float) -> float:
    """Return the least ``L >= lo`` (s) inside none of the open intervals ``(f_lo, f_hi)``.

    The intervals ending after ``lo``, in order of start: the first one that starts at or
    after everything before it (and ``lo``) has ended, plus :data:`EPS_L`, leaves that launch
    free. Compiled with a bucket sort (:func:`._st_kernels.least_free_kernel`, linear in the
    intervals); the numpy form (:func:`sweep_numpy`) where a start is NaN.
    """
    out = least_free_kernel(
        np.ascontiguousarray(f_lo, dtype=float),
        np.ascontiguousarray(f_hi, dtype=float),
        float(lo),
        EPS_L,
    )
    return float(out) if not math.isnan(out) else sweep_numpy(f_lo, f_hi, lo)


def sweep_numpy(f_lo: np.ndarray, f_hi: np.ndarray, lo: float) -> float:
    """:func:`sweep` with numpy: the intervals sorted by start, then the running end."""
    keep = f_hi > lo
    f_lo, f_hi = f_lo[keep], f_hi[keep]
    if f_lo.size == 0:
        return lo
    order = np.argsort(f_lo, kind="stable")
    f_lo, f_hi = f_lo[order], f_hi[order]
    # the first interval that starts after everything before it (and lo) has ended
    reach = np.maximum(np.maximum.accumulate(f_hi) + EPS_L, lo)
    prev = np.concatenate([[lo], reach[:-1]])
    gap = np.flatnonzero(f_lo >= prev)
    return float(prev[gap[0]]) if gap.size else float(reach[-1])


def tail_s(schedule: Schedule, k: int) -> Callable[[np.ndarray], np.ndarray]:
    """Return ``s(tau)`` (m) of ``schedule[k:]`` at times ``tau`` (s) from its launch."""
    t0 = schedule[k][0]
    offs = np.array([t - t0 for t, _ in schedule[k:]])
    pieces = [pc for _, pc in schedule[k:]]

    def s_of(tau: np.ndarray) -> np.ndarray:
        if len(pieces) == 1:  # one drive (the same floats as picking its times out)
            return np.asarray(pieces[0].s_at(tau - offs[0]), dtype=float)
        j = np.clip(np.searchsorted(offs, tau, side="right") - 1, 0, len(pieces) - 1)
        out = np.empty(tau.shape)
        for i in np.unique(j):
            m = j == i
            out[m] = pieces[i].s_at(tau[m] - offs[i])  # after its end: at rest there
        return out

    return s_of


def pass_band(
    s: np.ndarray, h: float, latest: Sequence[Schedule], t_from: float
) -> tuple[np.ndarray, np.ndarray]:
    """Return when (s) the schedules can be within ``h/2`` of the nodes ``s`` (m), launched earlier.

    Each schedule of ``latest`` (drives moving forward, launched at the latest) may have
    its launches moved earlier but not before ``t_from`` (s) nor into each other. Each drive
    is sampled every :data:`BAND_DT` from its launch to its end (rests need none: the robot
    stands at a drive's end until the next launch). The robot leaves the band
    ``[s_i - h/2, s_i + h/2]`` no later than the schedule as it is does (its first sample at
    or past ``s_i + h/2``; at its arrival for the nodes that reach the goal's), and enters it
    no earlier than the drives back to back from ``min(t_from, first launch)`` do (their last
    sample before ``s_i - h/2``). Returns ``(lo, hi)``, shape (n,) each: the least of the
    entries, the greatest of the exits (no schedules: all times).
    """
    if not latest:
        return np.full(s.shape, -np.inf), np.full(s.shape, np.inf)
    lo = np.full(s.shape, np.inf)
    hi = np.full(s.shape, -np.inf)
    nodes = np.ascontiguousarray(s, dtype=np.float64)
    for sched in latest:
        taus, s_t, launch, pack = [], [], [], []
        t = min(t_from, sched[0][0])
        for t_j, pc in sched:
            tau, s_pc = band_samples(pc)
            taus.append(tau)
            s_t.append(s_pc)
            launch.append(t_j)
            pack.append(t)
            t += pc.duration
        first = np.concatenate([[0], np.cumsum([x.shape[0] for x in taus])]).astype(np.int64)
        # compiled: the numpy form's running maximum, searches and sums (the same floats)
        pass_band_kernel(
            nodes,
            0.5 * h,
            np.concatenate(taus),
            np.concatenate(s_t).astype(np.float64),
            first,
            np.array(launch, dtype=np.float64),
            np.array(pack, dtype=np.float64),
            float(sched[-1][0] + sched[-1][1].duration),
            float(min(t_from, sched[0][0])),
            lo,
            hi,
        )
    return lo, hi


def band_samples(piece: Piece) -> tuple[np.ndarray, np.ndarray]:
    """Return a drive's times every :data:`BAND_DT` (s) from 0 to its end and its arc length (m) there.

    Kept on the piece (:func:`pass_band` asks again when the launch floor moves its start).
    """
    key = ("band", BAND_DT)
    if key not in piece.memo:
        tau = np.append(np.arange(0.0, piece.duration, BAND_DT), piece.duration)
        piece.memo[key] = (tau, piece.s_at(tau))
    return piece.memo[key]


def tail_occupancy(
    fine: FineWindows, schedule: Schedule, k: int
) -> tuple[list[tuple[np.ndarray, np.ndarray, np.ndarray]], list[tuple[float, float, float]]]:
    """Return the occupancy of ``schedule[k:]`` and the standing at the goal, from its launch.

    The drives' ``(node, a, b)`` arrays (:meth:`FineWindows.drive_occupancy`) and the rests'
    ``(s, a, b)``: at rest at ``s`` (m) during ``[a, b]`` (s), ``b = inf`` at the goal.
    """
    t0 = schedule[k][0]
    drives, rests = [], []
    for j in range(k, len(schedule)):
        tj, pc = schedule[j]
        node, a, b = fine.drive_occupancy(pc)
        drives.append((node, a + (tj - t0), b + (tj - t0)))
        end = tj + pc.duration - t0
        nxt = schedule[j + 1][0] - t0 if j + 1 < len(schedule) else math.inf
        if nxt > end:
            rests.append((pc.s1, end, nxt))
    return drives, rests


def tighten(fine: FineWindows, schedule: Schedule, first: float) -> Schedule:
    """Return ``schedule`` with every rest as short as the fine windows allow (module docstring).

    Parameters
    ----------
    fine : FineWindows
    schedule : list of (float, Piece)
        Launch times (s) and drives; the robot rests before each launch.
    first : float
        The earliest launch of the first drive (s): the end of a rest that must stay (a
        turn in place), or ``inf`` when the first drive's launch is fixed (a moving start).

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
        drives, rests = tail_occupancy(fine, out, k)
        best = fine.earliest(drives, lo, t_k, tail_s(out, k) if k == 0 else None, rests)
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
