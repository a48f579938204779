"""The movers' forbidden regions of the ``(s, t)`` plane along a fixed path, on a grid.

Nodes ``s_i = i ds`` along the path (the last one at ``L``) and times ``t_k = k dt``. A node
``(k, i)`` is forbidden when the robot centre at ``C(s_i)`` is closer to a mover at ``t_k``
than the limit ``robot radius + mover radius(t_k) + margin`` plus an ``inflation`` (m):

* the **sufficient** grid inflates by ``ds/2 + (V + u) dt/2 + growth dt/2`` (``V`` the robot's
  speed bound, ``u`` the mover's shape speed bound): a profile whose nearest node at every
  grid time is free keeps the limit at every instant in between (the robot is within
  ``ds/2 + V dt/2`` of that node, the mover's shape within ``u dt/2`` of its place at ``t_k``);
* the **necessary** grid deflates by ``ds/2``: a forbidden node is forbidden for every ``s``
  within ``ds/2`` of it at that instant, so a profile through it is truly unsafe.

The grid is stored as *runs*: for every node, the intervals of time indices during which it
is forbidden (and by which mover). A disc mover against a disc robot gives them in closed
form: on each piece of its track between waypoint times its centre ``c(t)`` and radius are
linear in ``t``, so ``|C(s_i) - c(t)| - lim(t)`` is convex in ``t`` and its negative set is
one interval, the roots of a quadratic; the node is forbidden exactly at the grid times inside
it (widened by 1 ns on the sufficient grid, narrowed on the necessary one, against rounding).
A polygon mover against a disc robot: each pair of a piece of its track and a node is
marched through the grid times (:mod:`._polygon_march`): an exact test at a grid time decides
every grid time within its clearance over the mover's speed bound, so the runs are those of
the exact test at every grid time (the limit moved by 1 nm the safe way, against rounding);
a piece that does not grow and turns the shape by at most
:data:`._polygon_march.FROZEN_PAD` is solved in closed form instead, its turn a pad moved
the safe way (a sufficient grid forbids a few more grid times, a necessary one a few fewer).
A footprint robot is marched the same way against every mover (discs too), with the signed
distance of its polygon at the node and the mover's.

A footprint robot is its convex polygon at each node, turned by the path's heading there; it
moves at most ``(1 + R kappa_max)`` per metre of arc, so the robot's share of both pads is
multiplied by that ``stretch``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from trajopt.moving._disc_windows import inside_times, near_pairs
from trajopt.moving._grid_kernels import dense_kernel, sweep_kernel
from trajopt.moving._grid_runs import runs_kernel
from trajopt.moving._mover_segments import kept_table
from trajopt.moving._obstacle import MovingObstacle
from trajopt.moving._polygon_march import polygon_runs

#: A run's end index standing for "until after the grid's last time" (the movers then stand).
FOREVER = 1 << 40
#: Widening (sufficient) or narrowing (necessary) of the closed-form intervals (s).
EPS_T = 1e-9
#: A step offset that empties a run's range of blocked starts (beyond ``FOREVER``).
NEVER_STEP = 1 << 50


class STGrid:
    """Forbidden nodes of the ``(s, t)`` plane, as runs of time indices per node.

    Attributes
    ----------
    s : ndarray, shape (n,)
        Arc-length nodes (m), ``s[0] = 0``, ``s[-1] = L``.
    t : ndarray, shape (K,)
        Times (s), ``t[k] = k dt``.
    ds, dt : float
        Spacings (m, s).
    ptr : ndarray of int, shape (n + 1,)
        The runs of node ``i`` are ``ptr[i]:ptr[i + 1]``.
    lo, hi : ndarray of int, shape (r,)
        First and last forbidden time index of each run (inclusive); ``hi == FOREVER`` when
        the run reaches the grid's last time (the node stays forbidden after it).
    owner : ndarray of int, shape (r,)
        Index of the mover of each run.
    col : ndarray of int, shape (r,)
        The node of each run.
    """

    def __init__(
        self,
        s: np.ndarray,
        t: np.ndarray,
        ds: float,
        dt: float,
        col: np.ndarray,
        lo: np.ndarray,
        hi: np.ndarray,
        owner: np.ndarray,
    ) -> None:
        self.s, self.t, self.ds, self.dt = s, t, float(ds), float(dt)
        # grouped by node and merged per node in one compiled pass (trajopt.moving._grid_runs)
        out = runs_kernel(
            s.shape[0], *(np.ascontiguousarray(x, dtype=np.int64) for x in (col, lo, hi, owner))
        )
        self.ptr, self.col, self.lo, self.hi, self.owner = out[:5]
        self._merged: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] = out[5:]
        self._dense: tuple[np.ndarray, np.ndarray] | None = None

    def index(self, s: np.ndarray) -> np.ndarray:
        """Nearest node index of arc lengths ``s`` (m)."""
        return np.clip(np.rint(np.asarray(s) / self.ds), 0, self.s.shape[0] - 1).astype(np.int64)

    @property
    def busy(self) -> np.ndarray:
        """Nodes forbidden at some time, bool, shape (n,)."""
        return np.diff(self.ptr) > 0

    def column(self, i: int) -> np.ndarray:
        """Forbidden times of node ``i``, bool, shape (K,)."""
        ptr, _, lo, hi = self.merged
        a, b = int(ptr[i]), int(ptr[i + 1])
        return self._paint(lo[a:b], hi[a:b])

    @property
    def merged(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The runs of all movers merged per node: ``(ptr, col, lo, hi)``.

        The same forbidden nodes as the runs of each mover, with overlapping or adjacent runs
        of a node (of any movers: a mover's runs at a node are split where its track's pieces
        meet) made one; ``ptr`` of shape (n + 1,), the others (q,), in order of node and time.
        """
        return self._merged

    def _paint(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        kk = self.t.shape[0]
        lo = np.maximum(lo, 0)
        hi = np.minimum(hi, kk - 1)
        keep = lo <= hi
        diff = np.bincount(lo[keep], minlength=kk)
        diff[:kk] -= np.bincount(hi[keep] + 1, minlength=kk + 1)[:kk]
        return np.cumsum(diff[:kk]) > 0

    def blocked_starts(self, idx: np.ndarray) -> np.ndarray:
        """Return ``bad[k]``: a motion at node ``idx[j]`` at time index ``k + j`` meets a run.

        Parameters
        ----------
        idx : ndarray of int, shape (m,)
            The node of the motion at each grid step after its start.

        Returns
        -------
        ndarray of bool, shape (K,)
        """
        idx = np.asarray(idx, dtype=np.int64)
        if idx.size and np.all(idx[1:] >= idx[:-1]):
            return self.blocked_starts_many([visits(idx)])[0]
        ptr, _, m_lo, m_hi = self.merged
        counts = ptr[idx + 1] - ptr[idx]
        total = int(counts.sum())
        if total == 0:
            return np.zeros(self.t.shape[0], dtype=bool)
        step = np.repeat(np.arange(idx.shape[0]), counts)
        first = np.repeat(ptr[idx], counts)
        run = first + np.arange(total) - np.repeat(np.cumsum(counts) - counts, counts)
        return self._paint(m_lo[run] - step, m_hi[run] - step)

    def blocked_starts_many(
        self, motions: Sequence[tuple[int, np.ndarray, np.ndarray]]
    ) -> np.ndarray:
        """Return :meth:`blocked_starts` of several motions along the path at once, shape (d, K).

        Parameters
        ----------
        motions : sequence of (int, ndarray, ndarray)
            Each motion's :func:`visits`: a non-decreasing motion is at node ``i0 + i``
            exactly at the steps ``first[i]..last[i]``, so a run ``[lo, hi]`` of that node
            blocks the starts ``lo - last[i]..hi - first[i]``; the runs of the nodes it
            spans are one slice of the merged runs (a node passed between grid times has an
            empty range of steps).
        """
        kk = self.t.shape[0]
        d = len(motions)
        if d == 0:
            return np.zeros((0, kk), dtype=bool)
        ptr, m_col, m_lo, m_hi = self.merged
        i0 = np.array([m[0] for m in motions], dtype=np.int64)
        size = np.array([m[1].shape[0] for m in motions], dtype=np.int64)
        base = np.cumsum(size) - size
        first = np.concatenate([m[1] for m in motions])
        last = np.concatenate([m[2] for m in motions])
        a, b = ptr[i0], ptr[i0 + size]
        cnt = b - a
        total = int(cnt.sum())
        who = np.repeat(np.arange(d), cnt)
        run = np.repeat(a - np.cumsum(cnt) + cnt, cnt) + np.arange(total)
        col = m_col[run] - i0[who] + base[who]
        lo = np.maximum(m_lo[run] - last[col], 0)
        hi = np.minimum(m_hi[run] - first[col], kk - 1)
        keep = lo <= hi
        w = who[keep] * (kk + 1)
        diff = np.bincount(w + lo[keep], minlength=d * (kk + 1))
        diff -= np.bincount(w + hi[keep] + 1, minlength=d * (kk + 1))
        return np.cumsum(diff.reshape(d, kk + 1), axis=1)[:, :kk] > 0

    def _dense_grid(self) -> tuple[np.ndarray, np.ndarray]:
        if self._dense is None:
            self._dense = dense_kernel(
                self.t.shape[0],
                self.s.shape[0],
                self.col.astype(np.int64),
                self.lo.astype(np.int64),
                self.hi.astype(np.int64),
                self.owner.astype(np.int64),
            )
        return self._dense

    @property
    def blocked(self) -> np.ndarray:
        """Forbidden nodes, bool, shape (K, n) (built on first use)."""
        return self._dense_grid()[0]

    @property
    def who(self) -> np.ndarray:
        """Index of the first mover forbidding each node, -1 where free, shape (K, n)."""
        return self._dense_grid()[1]


def visits(idx: np.ndarray) -> tuple[int, np.ndarray, np.ndarray]:
    """Return ``(i0, first, last)``: a motion at the non-decreasing nodes ``idx`` is at node ``i0 + i`` at the steps ``first[i]..last[i]``.

    ``idx``: the node at each grid step (shape (m,)); ``first``, ``last`` (shape
    ``(idx[-1] - idx[0] + 1,)``) are empty ranges (``first > last``) for the nodes it passes
    between grid steps.
    """
    idx = np.asarray(idx, dtype=np.int64)
    i0, i1 = int(idx[0]), int(idx[-1])
    change = np.flatnonzero(idx[1:] != idx[:-1])
    nodes = np.append(idx[change], i1) - i0
    first = np.full(i1 - i0 + 1, NEVER_STEP)
    last = np.full(i1 - i0 + 1, -NEVER_STEP)
    first[nodes] = np.append(0, change + 1)
    last[nodes] = np.append(change, idx.shape[0] - 1)
    return i0, first, last


def path_points(path: object, s: np.ndarray) -> np.ndarray:
    """Points of ``path`` at arc lengths ``s`` (m), shape (n, 2)."""
    return np.asarray(path(path.u_at_s(s)), dtype=float)  # type: ignore[operator, attr-defined]


def st_grid(
    path: object,
    length: float,
    movers: Sequence[MovingObstacle],
    limit: float,
    *,
    ds: float,
    dt: float,
    horizon: float,
    speed: float,
    sufficient: bool,
    body: np.ndarray | None = None,
    stretch: float = 1.0,
    points: np.ndarray | None = None,
    leave: float | None = None,
) -> STGrid:
    """Build the forbidden grid (module docstring).

    Parameters
    ----------
    path : ParametricCurve
        The path, arc length ``length`` (m).
    movers : sequence of MovingObstacle
    limit : float
        Robot radius plus margin (m), or the margin alone with a ``body``; each mover adds
        its radius.
    ds, dt : float
        Requested spacings (m, s); ``ds`` is adjusted to divide ``length``.
    horizon : float
        Last time (s) of the grid.
    speed : float
        The robot's speed bound ``V`` (m/s).
    sufficient : bool
        Inflate (a safe under-approximation of the free space) or deflate (a necessary one).
    body : ndarray, shape (m, 2), optional
        The robot's convex footprint (robot frame, CCW, m), turned by the path's heading at
        each node; ``None``: a disc robot.
    stretch : float
        With a ``body``: ``1 + R kappa_max`` (``R`` its farthest vertex), the bound of how far
        the footprint moves per metre of arc length; the pads scale the robot's share by it.
    points : ndarray, shape (n, 2), optional
        The path's points at the nodes (m), when the caller has them (:func:`grid_nodes`).
    leave : float, optional
        The robot leaves ``s = 0`` no earlier than this (s) and drives at most ``speed``: it
        cannot be nearest to node ``s_i`` before ``leave + (s_i - ds/2) / speed``, and a
        mover's pieces of track that end a grid step before that are not solved for the
        node (their runs could not meet the robot). Default: all times.

    Returns
    -------
    STGrid
    """
    s, ds = grid_nodes(length, ds)
    kk = max(2, int(math.ceil(horizon / dt)) + 1)
    t = np.arange(kk) * dt
    pts = path_points(path, s) if points is None else points
    polys = None
    if body is not None:
        th = np.asarray(path.heading(path.u_at_s(s)), dtype=float)  # type: ignore[attr-defined]
        c, sn = np.cos(th)[:, None], np.sin(th)[:, None]
        polys = np.stack(
            [
                pts[:, 0:1] + c * body[None, :, 0] - sn * body[None, :, 1],
                pts[:, 1:2] + sn * body[None, :, 0] + c * body[None, :, 1],
            ],
            axis=-1,
        )
    else:
        stretch = 1.0
    runs: list[tuple[np.ndarray, ...]] = []
    discs: list[tuple[int, MovingObstacle, float]] = []
    shapes: list[tuple[int, MovingObstacle, float]] = []
    table = kept_table(movers) if sufficient else None  # the certificate's, when kept
    for j, m in enumerate(movers):
        if sufficient:
            u = m.shape_speed_max() if table is None else float(table.shape_speed[j])
            pad = 0.5 * (ds + dt * speed) * stretch + 0.5 * dt * (u + m.growth)
        else:
            pad = -0.5 * ds * stretch
        if polys is None and m.vertices is None:
            discs.append((j, m, pad))
        else:
            shapes.append((j, m, pad))
    after = None
    if leave is not None:
        after = leave + np.maximum(s - 0.5 * ds, 0.0) / speed - dt
    if discs:
        runs.append(_disc_runs(pts, discs, limit, t, sufficient, after))
    if shapes:
        j_of, shape_movers, pads = zip(*shapes, strict=True)
        lim0 = limit + np.asarray(pads, dtype=float)
        runs.append(polygon_runs(pts, shape_movers, j_of, lim0, t, sufficient, after, polys))
    if runs:
        col, lo, hi, owner = (np.concatenate(x) for x in zip(*runs, strict=True))
    else:
        col = lo = hi = owner = np.zeros(0, dtype=np.int64)
    hi = np.where(hi >= kk - 1, FOREVER, hi)
    return STGrid(s, t, ds, float(dt), col, lo, hi, owner)


def grid_nodes(length: float, ds: float) -> tuple[np.ndarray, float]:
    """Return the nodes (m), shape (n,), of a path of ``length`` (m) for a requested ``ds``, and the spacing used."""
    n = max(2, int(math.ceil(length / ds)) + 1)
    s = np.linspace(0.0, length, n)
    return s, float(s[1] - s[0])


def _disc_runs(
    pts: np.ndarray,
    discs: list[tuple[int, MovingObstacle, float]],
    limit: float,
    t: np.ndarray,
    sufficient: bool,
    after: np.ndarray | None = None,
) -> tuple[np.ndarray, ...]:
    """Return the runs of disc movers against a disc robot, in closed form (module docstring).

    ``after``: per node (s), shape (n,), the runs before it are not needed (the pieces of
    track that end before it are left out for that node).

    Only the pairs of a track's piece and a node that :func:`._disc_windows.near_pairs` keeps are solved:
    the others are farther apart than the piece's largest limit at every instant of it.
    """
    dt, t_end = float(t[1] - t[0]), float(t[-1])
    rows = []  # (mover, u, w, centre at u, velocity, radius + limit + pad at u, growth)
    for j, m, pad in discs:
        tk = m.times
        knots = np.concatenate([[0.0], tk[(tk > 0.0) & (tk < t_end)], [t_end]])
        u, w = knots[:-1], knots[1:]
        mid = 0.5 * (u + w)
        px, py = np.interp(knots, tk, m.positions[:, 0]), np.interp(knots, tk, m.positions[:, 1])
        inside = (mid > tk[0]) & (mid < tk[-1])
        span = w - u
        vx = np.where(inside, np.diff(px) / span, 0.0)
        vy = np.where(inside, np.diff(py) / span, 0.0)
        grow = np.where(mid < m.t_last, m.growth, 0.0)
        r_u = limit + pad + m.radius + m.growth * np.clip(u, 0.0, max(m.t_last, 0.0))
        rows.append(
            np.column_stack([np.full(u.shape, j), u, w, px[:-1], py[:-1], vx, vy, r_u, grow])
        )
    arr = np.concatenate(rows)
    band = None if after is None else (after, np.full(after.shape, np.inf))
    seg, pi = near_pairs(pts, arr, 0.0, band)
    r = arr[seg]
    owner = r[:, 0].astype(np.int64)
    u, w = r[:, 1], r[:, 2]
    t_lo, t_hi = inside_times(
        pts[pi, 0] - r[:, 3], pts[pi, 1] - r[:, 4], r[:, 5], r[:, 6], r[:, 7], r[:, 8]
    )
    big = np.inf
    eps = EPS_T if sufficient else -EPS_T
    ta = u + np.nan_to_num(t_lo, nan=big, posinf=big, neginf=-big) - eps
    tb = u + np.nan_to_num(t_hi, nan=-big, posinf=big, neginf=-big) + eps
    k_lo = np.maximum(np.ceil(u / dt - 1e-9), np.floor(np.clip(ta, -1.0, t_end + dt) / dt) + 1)
    k_hi = np.minimum(np.floor(w / dt + 1e-9), np.ceil(np.clip(tb, -dt, t_end + dt) / dt) - 1)
    keep = k_lo <= k_hi
    return (
        pi[keep].astype(np.int64),
        k_lo[keep].astype(np.int64),
        k_hi[keep].astype(np.int64),
        owner[keep],
    )


def reach_bound(
    t: np.ndarray, v_max: float, a_max: float, j_max: float, v0: float = 0.0
) -> np.ndarray:
    """Return an upper bound (m) of ``s(t)`` for any motion under the limits, at ``t`` (s).

    From rest: ``a <= min(a_max, j_max t)``, so ``v <= min(v_max, integral of that)``, and
    ``s`` is at most the integral of this increasing bound, taken as an upper Riemann sum on
    1 ms steps. From a speed ``v0 > 0`` (m/s): ``max(v_max, v0) t``.
    """
    t = np.asarray(t, dtype=float)
    if v0 > 0.0:
        return max(v_max, v0) * t
    h = 1e-3
    tt = np.arange(0.0, float(np.max(t, initial=0.0)) + 2.0 * h, h)
    t1 = a_max / j_max
    vel = np.where(tt <= t1, 0.5 * j_max * tt * tt, 0.5 * a_max * t1 + a_max * (tt - t1))
    vel = np.minimum(v_max, vel)
    s = np.concatenate([[0.0], np.cumsum(vel[1:] * h)])  # right sums of an increasing bound
    k = np.minimum(np.ceil(t / h - 1e-12).astype(np.int64), tt.shape[0] - 1)
    return s[k]


def reachable(grid: STGrid, speed: float, s_up: np.ndarray | None = None) -> tuple[bool, int, int]:
    """Sweep the nodes a non-decreasing ``s(t)`` with speed ``<= speed`` can occupy.

    A relaxation: from node ``i`` at ``t_k`` the robot may be at any free node ``j`` with
    ``i <= j <= i + m`` at ``t_{k+1}`` (``m = ceil(speed dt / ds) + 1``), whatever lies between,
    and (given ``s_up``, shape (K,), an upper bound of ``s(t_k)`` in m) not beyond
    ``s_up[k] + ds/2``.

    Once the grid's rows no longer change (after the last run starts or ends) and neither
    does the bound, a step that leaves the reachable nodes as they were is a fixed point:
    the sweep stops there with the answer of the last time. The sweep is a compiled loop
    (:func:`._grid_kernels.sweep_kernel`).

    Returns
    -------
    ok : bool
        The goal node is reachable at the last time.
    k : int
        The first time index where nothing is reachable (or the last one).
    i : int
        The furthest reachable node before that (the place where the robot is stopped).
    """
    fb = grid.blocked
    kk = fb.shape[0]
    ends = np.concatenate([grid.lo, np.where(grid.hi >= FOREVER, 0, grid.hi + 1), [0]])
    k_static = int(np.max(ends))
    if s_up is not None:
        k_static = max(k_static, int(np.searchsorted(s_up, grid.s[-1] + 0.5 * grid.ds)))
    m = int(math.ceil(speed * grid.dt / grid.ds)) + 1
    bounded = s_up is not None
    up = np.asarray(s_up, dtype=float) if bounded else np.zeros(kk)
    ok, k, i = sweep_kernel(fb, grid.s, up, bounded, 0.5 * grid.ds, m, k_static)
    return bool(ok), int(k), int(i)
