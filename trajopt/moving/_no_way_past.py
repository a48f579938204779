"""A quick proof that no re-timing along the path gets past the movers: :func:`no_way_past`.

A re-timing keeps the path and changes only ``s(t)``: from rest at ``s = 0``, non-decreasing,
with speed at most ``V`` (the robot's top speed, forwards or backwards) and ``s(t)`` at most
the bound :func:`~trajopt.moving._st_grid.reach_bound` of a motion from rest. This proof
drops everything else (the acceleration and the path's curvature caps between grid times,
what lies between two nodes) and sweeps the nodes such an ``s(t)`` can occupy on the
*necessary* ``(s, t)`` grid (:func:`~trajopt.moving.st_grid` with ``sufficient=False``, in
closed form for disc movers): from node ``i`` at ``t_k`` the robot may be at any free node
``j``, ``i <= j <= i + ceil(V dt / ds) + 1``, at ``t_{k+1}``, not beyond
``reach_bound(t_{k+1}) + ds/2``. A truly safe motion's nearest node at every grid time is
free on the necessary grid (deflated by ``ds/2``), so it stays inside the swept set; the path
is blocked when the set empties at some grid time (a mover coming head-on leaves no way
past), or when, after the movers stop changing and the reach bound passes the goal, one step
leaves the set as it was without the goal in it (a fixed point: no later time helps).

The robot is its inscribed disc (inside a footprint, so a footprint is at least as close),
and a plan of several pieces is its curves end to end (rests and turns in place add no
distance, see :func:`~trajopt.moving.parked_on_path`). The proof gives up (returns ``None``)
as soon as the goal node is reachable: it only ever claims "blocked", and the ``(s, t)``
search of :func:`~trajopt.moving.retime_chain` decides the rest.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from trajopt.errors import BlockedError
from trajopt.moving._obstacle import MovingObstacle
from trajopt.moving._parked import path_curves
from trajopt.moving._st_grid import FOREVER, STGrid, grid_nodes, reach_bound, st_grid

#: Arc-length spacing (m) of the necessary grid's nodes.
PROOF_DS = 0.04
#: Time step (s) of the necessary grid.
PROOF_DT = 0.05


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


def _dense(grid: STGrid) -> np.ndarray:
    """Return the necessary grid's forbidden nodes, bool, shape (K, n), from its runs at once."""
    kk, n = grid.t.shape[0], grid.s.shape[0]
    col = np.repeat(np.arange(n), np.diff(grid.ptr))
    diff = np.zeros((kk + 1, n), dtype=np.int32)
    lo = np.clip(grid.lo, 0, kk)
    hi = np.minimum(grid.hi, kk - 1) + 1
    np.add.at(diff, (lo, col), 1)
    np.add.at(diff, (hi, col), -1)
    return np.cumsum(diff[:kk], axis=0) > 0


def sweep(
    grid: STGrid, speed: float, s_up: np.ndarray, k_static: int
) -> tuple[bool | None, int, int]:
    """Sweep the nodes a non-decreasing ``s(t)`` with speed ``<= speed`` can occupy (module docstring).

    Parameters
    ----------
    grid : STGrid
        A necessary grid.
    speed : float
        The speed bound (m/s).
    s_up : ndarray, shape (K,)
        An upper bound (m) of ``s(t_k)``.
    k_static : int
        A time index after which neither the grid's rows nor the bound change.

    Returns
    -------
    blocked : bool or None
        ``True`` when no such ``s(t)`` reaches the goal, ``None`` when the goal node is
        reachable at some grid time or the grid ends first (nothing proven).
    k : int
        The time index where the set emptied or became fixed.
    i : int
        The furthest reachable node before that (m's node index).
    """
    fb = _dense(grid)
    kk, n = fb.shape
    m = int(math.ceil(speed * grid.dt / grid.ds)) + 1
    idx = np.arange(n)
    reach = np.zeros(n, dtype=bool)
    reach[0] = not fb[0, 0]
    if not reach[0]:
        return True, 0, 0
    cap = np.searchsorted(grid.s, s_up + 0.5 * grid.ds, side="right")  # nodes allowed at t_k
    last_i = 0
    for k in range(1, kk):
        lastr = np.maximum.accumulate(np.where(reach, idx, -(10**9)))
        nxt = ~fb[k] & (idx - lastr <= m)
        nxt[int(cap[k]) :] = False
        if not nxt.any():
            return True, k, last_i
        if nxt[-1]:
            return None, k, n - 1
        if k > k_static and np.array_equal(nxt, reach):
            return True, k, last_i
        reach = nxt
        last_i = int(np.max(np.flatnonzero(reach)))
    return None, kk - 1, last_i


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
        A plan from rest (one curve, a chain, an omni translation).
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
    v_top = max(float(robot.v_max), float(back(robot)) if back is not None else 0.0)
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
    s_up = reach_bound(grid.t, v_top, a_max, j_max)
    ends = np.concatenate([grid.lo, np.where(grid.hi >= FOREVER, 0, grid.hi + 1), [0]])
    k_static = max(int(np.max(ends)), int(np.searchsorted(s_up, length + 0.5 * ds_used)))
    blocked, k, i = sweep(grid, v_top, s_up, k_static)
    if not blocked:
        return None
    a, b = int(grid.ptr[i]), int(grid.ptr[-1])
    live = (grid.lo[a:b] <= k) & (grid.hi[a:b] >= k)  # runs at or after the robot's place then
    j = int(grid.owner[a:b][live][0]) if live.any() else 0
    t = float(grid.t[k])
    what = "leaves no way past" if k < k_static else "stays on the path"
    return BlockedError(
        f"moving obstacle {movers[j].name!r} blocks the path: from t = {t:.3f} s it {what} "
        f"(robot at s <= {grid.s[i]:.3f} m of {length:.3f} m; no motion along the path under "
        f"v_max={v_top:.3g} m/s and the acceleration limits gets past)",
        mover=movers[j].name,
        t=t,
    )
