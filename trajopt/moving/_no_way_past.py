"""A quick proof that no re-timing along the path gets past the movers: :func:`no_way_past`.

A re-timing keeps the path and changes only ``s(t)``: from ``s = 0`` at ``t = 0``,
non-decreasing, with speed at most ``V`` (the robot's top speed, forwards or backwards) and
``s(t)`` at most the bound :func:`~trajopt.moving._st_grid.reach_bound` of a motion from the
plan's start state (from rest; ``V t`` from a moving start, the rest of a trajectory being
driven, which also holds every motion that brakes to a stop on the path and goes on from there). This proof
drops everything else (the acceleration and the path's curvature caps between grid times,
what lies between two nodes) and sweeps, node by node along the path, the times such an
``s(t)`` can be at each node of the *necessary* ``(s, t)`` grid (:func:`~trajopt.moving.st_grid`
with ``sufficient=False``, in closed form for disc movers): node ``j`` can be entered at
``t_k`` from a node ``i``, ``j - m <= i < j`` (``m = ceil(V dt / ds) + 1``), where the robot
can be at ``t_{k-1}``, when it is free then and not beyond ``reach_bound(t_k) + ds/2``; the
robot then may stay until the node's free interval ends. A truly safe motion's nearest node at
every grid time is free on the necessary grid (deflated by ``ds/2``) and moves at most ``m``
nodes a step, so it stays inside the swept times; the path is blocked when the goal node has
none (a mover coming head-on leaves no way past). The grid's last time is after every mover's
last change, so its last row holds for ever, and the cost is that of the nodes and the
movers' windows at them, not of the time horizon. When no mover ever comes to the start node
and none stays on the path, the robot may wait at the start until every mover has left the
path and then drive: the sweep is skipped (nothing to prove).

The robot is its inscribed disc (inside a footprint, so a footprint is at least as close),
and a plan of several pieces is its curves end to end (rests and turns in place add no
distance, see :func:`~trajopt.moving.parked_on_path`). The proof only ever claims "blocked";
when the goal node is reachable the ``(s, t)`` search of :func:`~trajopt.moving.retime_chain`
decides.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from trajopt.errors import BlockedError
from trajopt.moving._mover_places import MoverPlaces
from trajopt.moving._obstacle import MovingObstacle
from trajopt.moving._parked import path_curves
from trajopt.moving._reach_kernel import reach_kernel
from trajopt.moving._st_grid import FOREVER, STGrid, grid_nodes, reach_bound, st_grid

#: Arc-length spacing (m) of the necessary grid's nodes.
PROOF_DS = 0.04
#: Time step (s) of the necessary grid.
PROOF_DT = 0.05
#: Arc-length spacing (m) of the path points, and time step (s) of the mover samples, that
#: :func:`meets_head_on` compares.
HEAD_ON_DS = 0.25
HEAD_ON_DT = 0.25
#: Arc length (m) a mover must go back along the path, near it, for :func:`meets_head_on`,
#: coming to within as much of the path's start.
HEAD_ON_RUN = 0.5
#: The reach bounds from rest kept (:func:`_grid_reach_bound`), one per ``(dt, speed,
#: a_max, j_max)``.
_REACH_KEPT = 8
_REACH: dict[tuple[float, float, float, float], np.ndarray] = {}


def _points(curves: list[Any], s: np.ndarray) -> np.ndarray:
    """Points (m), shape (n, 2), at arc lengths ``s`` (m) along the curves end to end."""
    ends = np.cumsum([float(c.length) for c in curves])
    which = np.minimum(np.searchsorted(ends, s, side="left"), len(curves) - 1)
    out = np.empty((s.shape[0], 2))
    start = 0.0
    for j, c in enumerate(curves):
        sel = which == j
        if sel.any():
            local = np.clip(s[sel] - start, 0.0, float(c.length))
            out[sel] = np.asarray(c.path(c.path.u_at_s(local)), dtype=float).reshape(-1, 2)
        start = float(ends[j])
    return out


def reachable_times(grid: STGrid, speed: float, s_up: np.ndarray) -> list[list[tuple[int, float]]]:
    """Return, for each node, the time-index intervals a relaxed ``s(t)`` can be there (module docstring).

    Node by node: node ``j`` can be entered at ``t_k`` from a node ``i``, ``j - m <= i < j``
    (``m = ceil(speed dt / ds) + 1``), where the robot can be at ``t_{k-1}``, when ``j`` is
    free at ``t_k`` and within ``s_up[k] + ds/2``, and the robot then stays there until the
    free interval ends: each node's reachable times are a few intervals, the tails of its free
    ones. Once ``m`` nodes in a row are never reachable, no node after them is (each is
    entered only from the ``m`` before it): the sweep stops there.

    Parameters
    ----------
    grid : STGrid
        A necessary grid whose last time is after every mover's last change (the rows are the
        same after it, for ever).
    speed : float
        The speed bound (m/s).
    s_up : ndarray, shape (K,)
        A non-decreasing upper bound (m) of ``s(t_k)``, at least the path's length at the
        last time.

    Returns
    -------
    list of list of (int, float)
        ``reach[j]``: the intervals ``[a, b]`` of time indices (``b`` inf: for ever); empty
        when the node is never reachable.
    """
    rptr, ra, rb = _reach_arrays(grid, speed, s_up)
    a = ra.astype(np.int64).tolist()
    b = [math.inf if math.isinf(v) else int(v) for v in rb.tolist()]
    pairs = list(zip(a, b, strict=True))
    bounds = rptr.tolist()
    return [pairs[bounds[j] : bounds[j + 1]] for j in range(len(bounds) - 1)]


def _reach_arrays(
    grid: STGrid, speed: float, s_up: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`reachable_times` as flat arrays (:func:`._reach_kernel.reach_kernel`'s)."""
    n = grid.s.shape[0]
    m = int(math.ceil(speed * grid.dt / grid.ds)) + 1
    k_cap = np.searchsorted(s_up + 0.5 * grid.ds, grid.s, side="left").astype(np.int64)
    return reach_kernel(
        n,
        m,
        k_cap,
        np.ascontiguousarray(grid.ptr, dtype=np.int64),
        np.ascontiguousarray(grid.lo, dtype=np.int64),
        np.ascontiguousarray(grid.hi, dtype=np.int64),
        FOREVER,
    )


def no_way_past(
    plan: Any,
    movers: Sequence[MovingObstacle],
    margin: float = 0.0,
    *,
    ds: float = PROOF_DS,
    dt: float = PROOF_DT,
) -> BlockedError | None:
    """Return a :class:`BlockedError` when no re-timing along the plan's path avoids the movers.

    Parameters
    ----------
    plan : PlanResult
        A plan (one curve, a chain, an omni translation), from rest or moving (its
        ``v_start``, m/s).
    movers : sequence of MovingObstacle
        The predictions (the plan's clock).
    margin : float
        Extra distance (m).
    ds, dt : float
        The necessary grid's spacings (m, s); any values give a proof, finer ones a
        stronger one.

    Returns
    -------
    BlockedError or None
        The error (the mover that leaves no way past, the time) to raise, or ``None`` when
        this proof finds nothing (the path may still be blocked).
    """
    curves = path_curves(plan)
    if not curves or not movers:
        return None
    robot = plan.robot
    length = float(sum(float(c.length) for c in curves))
    if length <= 0.0:
        return None
    back = getattr(robot.drive, "v_max_backwards", None)
    v0 = abs(float(getattr(plan, "v_start", 0.0)))
    v_top = max(float(robot.v_max), float(back(robot)) if back is not None else 0.0, v0)
    a_max, j_max = float(robot.a_max), float(robot.j_max)
    t_last = max(max(float(m.t_last) for m in movers), 0.0)
    t_goal = length / v_top + v_top / a_max + a_max / j_max  # reach_bound passes L by then
    horizon = t_last + t_goal + 4.0 * dt
    s, ds_used = grid_nodes(length, ds)
    limit = float(robot.inscribed_radius) + float(margin)
    grid = st_grid(
        None,
        length,
        movers,
        limit,
        ds=ds,
        dt=dt,
        horizon=horizon,
        speed=v_top,
        sufficient=False,
        points=_points(curves, s),
    )
    if grid.ptr[1] == 0 and not np.any(grid.hi >= FOREVER):
        return None  # waiting at the start until every mover has left the path gets past
    if v0 > 0.0:
        s_up = reach_bound(grid.t, v_top, a_max, j_max, v0)
    else:
        s_up = _grid_reach_bound(grid.t.shape[0], grid.dt, v_top, a_max, j_max)
    if s_up[-1] + 0.5 * grid.ds < length:  # the grid must outlast the bound's reaching the goal
        return None
    rptr, _, rb = _reach_arrays(grid, v_top, s_up)
    if rptr[-1] > rptr[-2]:
        return None
    held = np.flatnonzero(np.diff(rptr) > 0)  # the nodes with a reachable time
    i = int(held[-1]) if held.size else 0
    last = float(np.max(rb[rptr[i] : rptr[i + 1]])) if held.size else 0.0
    k = int(min(last + 1, grid.t.shape[0] - 1))
    a, b = int(grid.ptr[i]), int(grid.ptr[-1])
    live = (grid.lo[a:b] <= k) & (grid.hi[a:b] >= k)  # runs at or after the robot's place then
    j = int(grid.owner[a:b][live][0]) if live.any() else int(grid.owner[0])
    t = float(grid.t[k])
    return BlockedError(
        f"moving obstacle {movers[j].name!r} blocks the path: from t = {t:.3f} s it leaves no "
        f"way past (robot at s <= {grid.s[i]:.3f} m of {length:.3f} m; no motion along the "
        f"path under v_max={v_top:.3g} m/s and the acceleration limits gets past)",
        mover=movers[j].name,
        t=t,
    )


def _grid_reach_bound(kk: int, dt: float, speed: float, a_max: float, j_max: float) -> np.ndarray:
    """Return :func:`~trajopt.moving._st_grid.reach_bound` from rest at ``np.arange(kk) * dt`` (s).

    The same values (m, shape (kk,), read-only), kept per ``(dt, speed, a_max, j_max)``
    (the last :data:`_REACH_KEPT`): the bound's 1 ms sums run from ``t = 0``, so the bound
    at the first ``kk`` grid times is the first ``kk`` values of a longer grid's, which is
    computed once (at least twice as long as the one it replaces) instead of once per proof.
    """
    key = (float(dt), float(speed), float(a_max), float(j_max))
    kept = _REACH.get(key)
    if kept is None or kept.shape[0] < kk:
        n = max(kk, 0 if kept is None else 2 * kept.shape[0])
        kept = reach_bound(np.arange(n) * dt, speed, a_max, j_max)
        kept.setflags(write=False)
        _REACH.pop(key, None)
        while len(_REACH) >= _REACH_KEPT:
            _REACH.pop(next(iter(_REACH)))
        _REACH[key] = kept
    return kept[:kk]


def meets_head_on(plan: Any, movers: Sequence[MovingObstacle], margin: float = 0.0) -> bool:
    """Whether a mover drives along the plan's path against it: a cheap screen for :func:`no_way_past`.

    Each mover's reference point every :data:`HEAD_ON_DT` s over ``[0, t_last]`` is compared
    with the path's points every :data:`HEAD_ON_DS` m: a sample is near the path when it is
    within the robot's inscribed radius, the margin, the mover's circumscribed radius and
    half the point spacing of a path point. The mover meets the path head-on when the arc
    length of the nearest path point goes back by :data:`HEAD_ON_RUN` m or more from one
    near sample to a later one that is within :data:`HEAD_ON_RUN` m of the path's start:
    it comes along the path all the way to where the robot is (one that leaves the path
    before, the robot may wait out at the start). Only movers that come within that of the
    start, moving against the robot's heading there (within 60 degrees), are compared: the
    screen costs little when none does. It decides nothing by itself: it tells the caller
    that the proof, a few milliseconds, is worth running before a re-timing's search, whose
    failure costs more.

    Parameters
    ----------
    plan : PlanResult
        A plan (one curve, a chain, an omni translation).
    movers : sequence of MovingObstacle
        The predictions (the plan's clock).
    margin : float
        Extra distance (m).

    Returns
    -------
    bool
    """
    curves = path_curves(plan)
    if not curves or not movers:
        return False
    length = float(sum(float(c.length) for c in curves))
    if length < HEAD_ON_RUN:
        return False
    limit = float(plan.robot.inscribed_radius) + float(margin) + 0.5 * HEAD_ON_DS
    at = plan.sample(np.zeros(1))
    p0 = np.array([float(at.x[0]), float(at.y[0])])
    ahead = np.array([math.cos(float(at.theta[0])), math.sin(float(at.theta[0]))])
    # each mover's farthest vertex plus its last radius (radius_at(t_last)'s floats), all at once
    places = MoverPlaces(movers)
    reaches = places.reach + (places.rad0 + places.grow * places.t_last)
    gaps = _track_distances(movers, p0)
    idx = np.flatnonzero(~(gaps > limit + reaches + HEAD_ON_RUN))
    if not idx.size:
        return False  # none comes near the path's start
    # the others' reference points every HEAD_ON_DT s, all at once (numpy.interp's floats)
    times = [np.append(np.arange(0.0, t_end, HEAD_ON_DT), t_end) for t_end in places.t_last[idx]]
    count = np.array([t.shape[0] for t in times])
    first = np.cumsum(count) - count
    t_all = np.concatenate(times)
    owner = np.repeat(idx, count)
    p_all = places.at(owner, t_all)
    v = np.diff(p_all, axis=0)  # a step within a mover where the owners on both ends agree
    close = np.hypot(*(p_all[1:] - p0).T) <= (limit + reaches[owner[1:]]) + HEAD_ON_RUN
    against = v[:, 0] * ahead[0] + v[:, 1] * ahead[1] < -0.5 * np.hypot(*v.T)
    coming = close & against & (owner[1:] == owner[:-1])
    pts = s = None
    for q in np.flatnonzero(np.bincount(owner[1:][coming], minlength=len(movers))[idx]).tolist():
        # it comes near the start against the robot's heading (the others only across or with it)
        reach, t = float(reaches[idx[q]]), times[q]
        p = p_all[first[q] : first[q] + count[q]]
        if pts is None:
            s = np.linspace(0.0, length, int(math.ceil(length / HEAD_ON_DS)) + 1)
            pts = _points(curves, s)
        d = np.hypot(p[:, None, 0] - pts[None, :, 0], p[:, None, 1] - pts[None, :, 1])
        nearest = np.argmin(d, axis=1)
        near = d[np.arange(t.shape[0]), nearest] <= limit + reach
        if np.count_nonzero(near) < 2:
            continue
        sn = s[nearest[near]]
        back = np.maximum.accumulate(sn)[:-1] - sn[1:]
        if np.any((back >= HEAD_ON_RUN) & (sn[1:] <= HEAD_ON_RUN)):
            return True
    return False


def _track_distances(movers: Sequence[MovingObstacle], p: np.ndarray) -> np.ndarray:
    """Distances (m) from ``p`` (m) to each mover's waypoint polyline (all its waypoints).

    At most the distance to its track over ``[0, t_last]`` (a part of that polyline).
    """
    a = np.concatenate([m.positions[:-1] if len(m.positions) > 1 else m.positions for m in movers])
    b = np.concatenate([m.positions[1:] if len(m.positions) > 1 else m.positions for m in movers])
    owner = np.repeat(np.arange(len(movers)), [max(len(m.positions) - 1, 1) for m in movers])
    d = b - a
    dd = np.einsum("ij,ij->i", d, d)
    with np.errstate(divide="ignore", invalid="ignore"):
        lam = np.where(dd > 0.0, np.clip(((p - a) * d).sum(axis=1) / dd, 0.0, 1.0), 0.0)
    dist = np.hypot(*(a + lam[:, None] * d - p).T)
    out = np.full(len(movers), np.inf)
    np.minimum.at(out, owner, dist)
    return out
