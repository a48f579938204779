"""When points are within movers' limits, for any mover shape: sampled time windows with a Lipschitz pad.

A mover's shape (a convex polygon rounded by its radius, or a disc) moves rigidly: on each
piece of its track between waypoint times its reference point moves at a constant velocity
``v``, its heading turns at a constant rate ``w`` and its radius grows at ``g``, so every
point of the shape moves at most ``|v| + R |w|`` (``R`` the farthest vertex from the reference
point) and the distance from a fixed point to the shape, minus the radius, changes at most at
``lip = |v| + R |w| + g`` (m/s). With ``f(t)`` that distance minus the radius and the limit,
``f(t_k) = f_k`` proves ``f > 0`` on ``(t_k - f_k / lip, t_k + f_k / lip)`` and ``f < 0`` on the
same interval when ``f_k < 0``. :meth:`ShapeTracks.windows` steps through time by
``max(|f_k| / lip, step)`` and reports as a violation window every stretch that no sample
proves safe: sufficient (every ``t`` with ``f(t) < 0`` is inside a window), and tight to about
``step`` at each end (the march is compiled: :func:`._polygon_march.windows_kernel`). A
piece that does not grow and turns by little (its shape turned to one heading within
``lip step / 2`` of the true one) is not marched: its window is one interval in closed form,
with that turn as a pad. Only the times at which the point is within the shape's bounding disc
(radius ``R`` plus the rounding) plus the limit are sampled: those are closed-form
(:func:`._disc_windows.inside_times`), an exact filter.

:class:`ShapeWindows` puts these windows at the fine nodes of a path, for
:func:`._tighten.tighten` (the robot a disc; movers of any shape); the launch that decides
the wait at the start is refined from the motion's own points, in the launch itself.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from trajopt.moving._disc_windows import close_pairs, near_pairs
from trajopt.moving._obstacle import MovingObstacle
from trajopt.moving._polygon_march import (
    PolygonPieces,
    launch_refine_kernel,
    pieces_of,
    refine_samples_kernel,
    windows_kernel,
)
from trajopt.moving._st_kernels import disc_windows_kernel
from trajopt.moving._st_search import Piece
from trajopt.moving._tighten import (
    POINT_PAD,
    FineWindows,
    blocked_launches,
    near_times,
    pieces_meeting,
    sweep,
)

#: The least time step (s) of the fine nodes' windows.
NODE_STEP = 1e-2
#: The least time step (s) of the windows of a rest's point.
FINE_STEP = 5e-4
#: Each window's ends are widened by this much (s), against rounding.
EPS_W = 1e-9
#: The launch steps (s) of the refinement's levels (:meth:`ShapeWindows._exact`).
LAUNCH_STEPS = (1e-2, 1e-3, 1e-4)
#: The spacing (s) of the motion's own points in the refinement (:meth:`ShapeWindows._exact`).
REFINE_TAU = 1e-3
#: Every how many fine nodes :func:`launch_floor` tests.
FLOOR_EVERY = 8


class ShapeTracks(PolygonPieces):
    """The movers' tracks as linear pieces with headings, for :meth:`windows` (module docstring).

    :class:`._polygon_march.PolygonPieces` (its attributes) with the march of :meth:`windows`.

    Parameters
    ----------
    movers : sequence of MovingObstacle
        Any shapes (a disc is a polygon of one vertex at its reference point).
    """

    @classmethod
    def of(cls, movers: Sequence[MovingObstacle]) -> ShapeTracks:
        """Return the tracks of ``movers``, their pieces shared with a recent march (:func:`._polygon_march.pieces_of`)."""
        out = cls.__new__(cls)
        vars(out).update(vars(pieces_of(movers)))
        return out

    def windows(
        self,
        pts: np.ndarray,
        limit: float,
        step: float,
        band: tuple[np.ndarray, np.ndarray] | None = None,
        owner: np.ndarray | None = None,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Return windows (s) that hold every time a point is closer to a mover than ``limit``.

        Sufficient, not exact (module docstring): open intervals ``(lo, hi)`` whose union holds
        every ``t`` in the band at which a point's distance to a mover's shape is under
        ``limit`` plus its radius, each end within about ``step`` (s) of the exact one.

        Parameters
        ----------
        pts : ndarray, shape (n, 2)
            Points (m).
        limit : float
            The distance to keep besides a mover's radius (m).
        step : float
            The least time step (s) between samples.
        band : (ndarray, ndarray), optional
            Per point, shape (n,) each: only the times (s) from ``band[0]`` to ``band[1]``
            matter (``band[1]`` may be ``inf``); default all times from 0.
        owner : ndarray of int, shape (n,), optional
            Test point ``i`` against mover ``owner[i]`` only (then ``band`` is needed).

        Returns
        -------
        mover, point : ndarray of int, shape (r,)
        lo, hi : ndarray, shape (r,)
            Open time intervals (s); ``hi = inf`` for one that lasts.
        """
        if owner is None:
            seg, pi = near_pairs(pts, self.bound, limit, band)
        else:
            seg, pi = pieces_meeting(self.bound, owner, band[0], band[1])
            keep = close_pairs(pts, self.bound, limit, seg, pi)
            seg, pi = seg[keep], pi[keep]
        pts = np.ascontiguousarray(pts, dtype=np.float64)
        seg, pi = seg.astype(np.int64), pi.astype(np.int64)
        # the times inside the bounding disc, within the piece's span (compiled: the floats
        # of inside_times, then numpy.nan_to_num and the clip)
        a, b = disc_windows_kernel(pts, self.bound, float(limit), seg, pi)
        if band is not None:
            a = np.maximum(a, band[0][pi])
            b = np.minimum(b, band[1][pi])
        keep = a < b
        seg, pi, a, b = seg[keep], pi[keep], a[keep], b[keep]
        idx, lo, hi = windows_kernel(
            pts,
            seg,
            pi,
            a,
            b,
            self.rows,
            self.who,
            self.head0,
            self.turn,
            self.lip,
            self.reach[self.who],
            float(limit),
            self.verts,
            self.edges,
            self.poly,
            float(step),
            EPS_W,
        )
        who = self.pieces[seg[idx], 0].astype(np.int64)
        return who, pi[idx].astype(np.int64), lo, hi


class ShapeWindows(FineWindows):
    """The movers' violation windows at the fine nodes of a path, movers of any shape.

    :class:`._tighten.FineWindows` with the windows of :meth:`ShapeTracks.windows` (every
    :data:`NODE_STEP` at the nodes, :data:`FINE_STEP` at a rest's point) in place of the disc
    movers' closed-form ones, and the refinement of the wait at the start found in the
    launch (:meth:`_exact`); parameters as there.
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
        self.tracks = ShapeTracks.of(movers)
        self.pieces = self.tracks.bound
        # each mover's largest piece bound (m/s) and its pieces' rows, for the refinement
        self.lip_m = np.zeros(len(self.movers))
        np.maximum.at(self.lip_m, self.tracks.who, self.tracks.lip)
        self.starts = np.searchsorted(self.tracks.who, np.arange(len(self.movers) + 1))
        if band is None:
            band = (np.zeros(s.shape), np.full(s.shape, np.inf))
        owner, node, lo, hi = self.tracks.windows(pts, limit + 0.5 * self.h, NODE_STEP, band)
        order = np.argsort(node, kind="stable")
        node, self.lo, self.hi, self.owner = node[order], lo[order], hi[order], owner[order]
        counts = np.bincount(node, minlength=s.shape[0])
        self.ptr = np.concatenate([[0], np.cumsum(counts)])

    def fetch_points(self, places: Sequence[float]) -> None:
        """Make the windows of the path's points at ``places`` (m) not kept yet, in one march.

        The points' windows are those :meth:`point_windows` makes one at a time, the same
        floats: each pair of a point and a piece of a track is marched on its own, and the
        pairs of one point keep their order (by piece, then time).
        """
        if self.where is None:
            return
        new = [s for s in dict.fromkeys(places) if s not in self._points]
        if len(new) < 2:
            return
        pts = self.where(np.array(new, dtype=float))
        _, pi, lo, hi = self.tracks.windows(pts, self.limit + POINT_PAD, FINE_STEP)
        order = np.argsort(pi, kind="stable")
        pi, lo, hi = pi[order], lo[order], hi[order]
        ptr = np.concatenate([[0], np.cumsum(np.bincount(pi, minlength=len(new)))])
        for k, s in enumerate(new):
            self._points[s] = (lo[ptr[k] : ptr[k + 1]], hi[ptr[k] : ptr[k + 1]])

    def point_windows(self, s: float) -> tuple[np.ndarray, np.ndarray]:
        """Return the windows (s) of the path's point at ``s`` (m), the limit plus 0.1 mm (kept by ``s``)."""
        if s not in self._points:
            if self.where is None:
                i = int(np.clip(np.rint(s / self.h), 0, self.s.shape[0] - 1))
                run = slice(int(self.ptr[i]), int(self.ptr[i + 1]))
                lo, hi = self.lo[run], self.hi[run]
            else:
                pt = self.where(np.array([s]))
                _, _, lo, hi = self.tracks.windows(pt, self.limit + POINT_PAD, FINE_STEP)
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
        """Return open intervals (s) holding every launch in ``[lo, hi]`` at which the motion may meet the movers.

        As :meth:`._tighten.FineWindows._exact` (during ``[a_j, b_j]``, s from the launch,
        against mover ``owner_j``), found in the launch instead: the motion's own points
        every :data:`REFINE_TAU` (s) give a lower bound ``G(L)`` of its clearance at launch
        ``L`` (their distance to the shape at ``L + tau``, minus the radius and the limit,
        minus ``(V + lip) REFINE_TAU / 2`` for the instants between them), and ``G`` changes
        at most at ``lip`` (m/s) with ``L``, so ``G(L) > 0`` proves the launches within
        ``G(L) / lip`` of ``L`` safe. ``G`` is evaluated on :data:`LAUNCH_STEPS` (s), each
        level around the earliest launch the one before proved; everything not proved is
        returned. The points that keep more than ``lip`` times the range at its middle are
        left out (they are clear at every launch in it).
        """
        # compiled in two steps around the path's points (the numpy form's floats):
        # the merged spans' sample times, then the levels and the complement
        tau, who = refine_samples_kernel(
            np.ascontiguousarray(a, dtype=np.float64),
            np.ascontiguousarray(b, dtype=np.float64),
            np.ascontiguousarray(owner, dtype=np.int64),
            REFINE_TAU,
        )
        pts = np.ascontiguousarray(self.where(s_of(tau)), dtype=np.float64)
        tr = self.tracks
        return launch_refine_kernel(
            tau,
            who,
            pts,
            self.lip_m,
            float(self.speed),
            float(self.limit),
            REFINE_TAU,
            float(lo),
            float(hi),
            np.array(LAUNCH_STEPS),
            tr.rows,
            self.starts,
            tr.head0,
            tr.turn,
            tr.lip,
            tr.verts,
            tr.edges,
            tr.poly,
        )


def launch_floor(
    s: np.ndarray,
    pts: np.ndarray,
    movers: Sequence[MovingObstacle],
    limit: float,
    band: tuple[np.ndarray, np.ndarray],
    schedules: Sequence[Sequence[tuple[float, Piece]]],
    lo: float,
) -> float:
    """Return the least launch (s) at or after ``lo`` that any of ``schedules`` may take: a floor.

    The windows of :class:`ShapeWindows` at every :data:`FLOOR_EVERY`-th fine node only
    (the same limit ``limit + h/2``, step and ``band``), and a schedule's drives' times near
    those nodes (:func:`._tighten.near_times`), the schedule launched as a block (its
    drives' launches moved together): a launch the windows at every node allow is allowed
    by these, so the least launch from ``lo`` these allow (:func:`._tighten.sweep`) is no
    later than the least the fine windows allow the schedule; the least over the schedules.

    Parameters
    ----------
    s, pts : ndarray, shape (n,), (n, 2)
        The fine nodes (m) and the path's points there (m).
    movers : sequence of MovingObstacle
    limit : float
        Robot radius plus margin (m).
    band : (ndarray, ndarray)
        Per fine node, shape (n,) each: the times (s) its windows are made for.
    schedules : sequence of list of (float, Piece)
        Launch times (s) and drives, each schedule from the start.
    lo : float
        The earliest launch (s).
    """
    h = float(s[1] - s[0])
    sub = np.arange(0, s.shape[0], FLOOR_EVERY)
    tracks = ShapeTracks.of(movers)
    _, node, w_lo, w_hi = tracks.windows(
        pts[sub], limit + 0.5 * h, NODE_STEP, (band[0][sub], band[1][sub])
    )
    order = np.argsort(node, kind="stable")
    node, w_lo, w_hi = node[order], w_lo[order], w_hi[order]
    ptr = np.concatenate([[0], np.cumsum(np.bincount(node, minlength=sub.shape[0]))])
    floor = np.inf
    for sched in schedules:
        f_lo, f_hi = [np.zeros(0)], [np.zeros(0)]
        for t_j, pc in sched:
            idx, a, b = near_times(pc, s, h)
            mine = idx % FLOOR_EVERY == 0
            off = t_j - sched[0][0]
            x_lo, x_hi, _, _ = blocked_launches(
                idx[mine] // FLOOR_EVERY, a[mine] + off, b[mine] + off, ptr, w_lo, w_hi, lo
            )
            f_lo.append(x_lo)
            f_hi.append(x_hi)
        floor = min(floor, sweep(np.concatenate(f_lo), np.concatenate(f_hi), lo))
    return float(floor)
