"""A quick proof that a mover parked on the path blocks it: :func:`parked_on_path`.

A mover whose prediction ends standing still (its last waypoints equal) stays there for ever
(:class:`~trajopt.moving.MovingObstacle`). If, from the time ``t_stop`` it stands, its shape is
closer than the limit to some point ``C(s*)`` of the path, and no motion from the plan's start
state under the robot's limits can be beyond ``s*`` by ``t_stop`` (``s* > reach(t_stop)``, the
bound :func:`~trajopt.moving._st_grid.reach_bound` of ``s(t)``: from rest, or ``v_max t`` from
a moving start, the rest of a trajectory being driven), then every re-timing of the path
passes ``C(s*)`` (or stands there, at the goal) after ``t_stop``, closer than the limit: no
re-timing avoids it. The robot is taken as its inscribed disc (inside a footprint, so a
footprint is at least as close), the limit at ``t_stop`` (the radius only grows), and the
distance is exact at the sampled points (one point suffices). A plan of several pieces is its
curves end to end (rests and turns in place add no distance, so the reach bound holds for the
arc length summed over the pieces).

It decides in a few milliseconds what the ``(s, t)`` re-timing decides after its search fails;
the planner tries it first and re-routes at once (:func:`~trajopt.moving.reroute`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from trajopt.errors import BlockedError
from trajopt.geometry import BSplineCurve
from trajopt.moving._certificate import point_polygon_distance, shape_at
from trajopt.moving._mover_places import TABLE_FROM, MoverPlaces
from trajopt.moving._mover_segments import kept_table
from trajopt.moving._obstacle import MovingObstacle
from trajopt.moving._reach_steps import reach_from_rest
from trajopt.moving._st_grid import reach_bound

#: Arc-length spacing (m) of the path points checked.
PARKED_DS = 0.02
#: Arc-length spacing (m) of the points that screen the movers first: a mover whose final
#: shape's bounding disc (about its reference point) none of them comes within the limit plus
#: half this of is nowhere within the limit of the path; the fine points are evaluated only
#: within this much arc of a screening point that one comes that close to.
SCREEN_DS = 0.25
#: Distance (m) a mover's bound must clear the path's discs (:func:`span_discs`) by, beyond
#: the screen's, to be left out without its points: far above the rounding of the bounds.
SPAN_SLACK = 1e-9


def settle_time(mover: MovingObstacle) -> float:
    """Return the time (s) from which the mover stands still for ever (its pose no longer changes).

    The first time of the run of last waypoints equal to the last one (position and heading);
    ``-inf`` for a mover that never moves.
    """
    p, h = mover.positions, mover.headings
    k = p.shape[0] - 1
    while k > 0 and np.array_equal(p[k - 1], p[-1]) and h[k - 1] == h[-1]:
        k -= 1
    return -np.inf if k == 0 else float(mover.times[k])


def path_curves(plan: Any) -> list[Any]:
    """Return the curves of a plan end to end (one curve, a chain's curves, an omni translation)."""
    if plan.own_orientation:
        return [plan.translation]
    if plan.single_curve:
        return [plan]
    out = []
    for p in getattr(plan, "pieces", ()):
        out += path_curves(p) if (p.single_curve or getattr(p, "pieces", None) is not None) else []
    return out


def parked_on_path(
    plan: Any, movers: Sequence[MovingObstacle], margin: float = 0.0
) -> BlockedError | None:
    """Return a :class:`BlockedError` when a parked mover provably blocks the plan's path.

    Parameters
    ----------
    plan : PlanResult
        A plan (one curve, a chain, an omni translation), from rest or moving (its
        ``v_start``, m/s).
    movers : sequence of MovingObstacle
        The predictions (the plan's clock).
    margin : float
        Extra distance (m).

    Returns
    -------
    BlockedError or None
        The error (the mover, the time it stands from, the point of the path) to raise, or
        ``None`` when this proof finds nothing (the path may still be blocked).
    """
    curves = path_curves(plan)
    if not curves or not movers:
        return None
    robot = plan.robot
    back = getattr(robot.drive, "v_max_backwards", None)
    v0 = abs(float(getattr(plan, "v_start", 0.0)))
    v_top = max(float(robot.v_max), float(back(robot)) if back is not None else 0.0, v0)
    t_stops = np.array([max(settle_time(m), 0.0) for m in movers])
    if v0 > 0.0:
        reaches = reach_bound(t_stops, v_top, robot.a_max, robot.j_max, v0)
    else:
        reaches = reach_from_rest(t_stops, v_top, float(robot.a_max), float(robot.j_max))
    length = sum(float(c.length) for c in curves)
    if float(np.min(reaches)) >= length:
        return None  # the robot may be past the whole path before any mover stands still
    # every mover at once: its place when it stands (numpy.interp's), the limit (its radius
    # then: radius_at's floats) and the bound of its shape about that place (its farthest
    # vertex)
    places = MoverPlaces(movers)
    centre = places.at(np.arange(len(movers)), t_stops)
    limits = float(robot.inscribed_radius) + places.radius_at(t_stops) + margin
    live = reaches < length  # else no point of the path lies beyond it
    discs = span_discs(curves)
    if discs is not None:  # the movers whose shape is nowhere near the path's discs: no hit
        cen, rad = discs
        gap = np.min(
            np.hypot(centre[:, None, 0] - cen[None, :, 0], centre[:, None, 1] - cen[None, :, 1])
            - rad[None, :],
            axis=1,
        )
        live &= ~(gap - places.reach > limits + 0.5 * SCREEN_DS + SPAN_SLACK)
    if not live.any():
        return None
    coarse, s_coarse, off = _path_points(curves, SCREEN_DS)
    d = (
        np.hypot(coarse[None, :, 0] - centre[:, 0:1], coarse[None, :, 1] - centre[:, 1:2])
        - places.reach[:, None]
    )
    hits = d < (limits + 0.5 * SCREEN_DS)[:, None]  # a point between is nearer than ds/2 to one
    hits &= live[:, None]
    # the movers whose final shape's bounding disc comes near some coarse point
    rows = np.flatnonzero(hits.any(axis=1))
    if not rows.size:
        return None
    close = hits.any(axis=0)
    near = [(movers[j], float(t_stops[j]), float(reaches[j]), float(limits[j])) for j in rows]
    # the fine points within SCREEN_DS of arc of a close coarse point: no other can be near
    p, s_cum, off = _path_points(curves, PARKED_DS, s_coarse[close], SCREEN_DS)
    for m, t_stop, reach, limit in near:
        shape = shape_at(m, np.array([t_stop]))
        d = point_polygon_distance(p, np.broadcast_to(shape, (p.shape[0], *shape.shape[1:])))
        hit = (d < limit) & (s_cum > reach)
        if hit.any():
            i = int(np.argmax(hit))
            return BlockedError(
                f"moving obstacle {m.name!r} stands on the path from t = {t_stop:.3f} s "
                f"(at s = {s_cum[i]:.3f} m of {off:.3f} m, {d[i]:.3f} m < {limit:.3f} m), "
                f"before the robot can get past it (at most {reach:.3f} m along by then under "
                f"v_max={v_top:.3g} m/s and the acceleration limits)",
                mover=m.name,
                t=t_stop,
            )
    return None


def span_discs(curves: list[Any]) -> tuple[np.ndarray, np.ndarray] | None:
    """Return discs that hold the curves' paths: centres (m, shape (n, 2)) and radii (m, shape (n,)).

    A B-spline of degree ``k`` over its domain is, on each knot span, a convex combination of
    ``k + 1`` consecutive control points: it lies in their convex hull, inside the disc about
    their mean through the farthest of them. One disc per ``k + 1`` consecutive control
    points of each curve. ``None`` when a curve's path is not a B-spline (a
    :class:`~trajopt.geometry.BSplineCurve`, or a :class:`~trajopt.smoother.SmoothPath` of
    one).
    """
    # loaded by then (the plans' paths come from it), not with this module
    from trajopt.smoother import SmoothPath

    cen, rad = [], []
    for c in curves:
        path = c.path
        spline = path if isinstance(path, BSplineCurve) else None
        if isinstance(path, SmoothPath) and isinstance(path.curve, BSplineCurve):
            spline = path.curve
        if spline is None:
            return None
        k = int(spline.k)
        pts = np.asarray(spline.c, dtype=float)
        win = np.lib.stride_tricks.sliding_window_view(pts, (k + 1, 2))[:, 0]
        mid = win.mean(axis=1)
        cen.append(mid)
        rad.append(
            np.max(np.hypot(win[..., 0] - mid[:, None, 0], win[..., 1] - mid[:, None, 1]), axis=1)
        )
    return np.concatenate(cen), np.concatenate(rad)


def _path_points(
    curves: list[Any], ds: float, around: np.ndarray | None = None, within: float = 0.0
) -> tuple[np.ndarray, np.ndarray, float]:
    """Return points at most ``ds`` (m) apart along the curves end to end.

    The points (m, shape (n, 2)), their arc lengths (m, shape (n,)) and the total length (m).
    Given ``around`` (arc lengths, m), only the points within ``within`` (m) of arc of one of
    them (the same points as without it, the others left out).
    """
    pts, s_all, off = [], [], 0.0
    for c in curves:
        n = max(2, int(np.ceil(c.length / ds)) + 1)
        s = np.linspace(0.0, c.length, n)
        if around is not None:
            k = np.searchsorted(around, s + off)  # the nearest of around on either side
            lo = np.abs(s + off - around[np.maximum(k - 1, 0)])
            hi = np.abs(around[np.minimum(k, around.shape[0] - 1)] - (s + off))
            s = s[np.minimum(lo, hi) <= within]
        if s.shape[0]:
            pts.append(np.asarray(c.path(c.path.u_at_s(s)), dtype=float).reshape(-1, 2))
            s_all.append(s + off)
        off += float(c.length)
    if not pts:
        return np.zeros((0, 2)), np.zeros(0), off
    return np.concatenate(pts), np.concatenate(s_all), off


def over_start(start: np.ndarray, movers: Sequence[MovingObstacle], limit: float) -> bool:
    """Whether a mover is closer than ``limit`` plus its radius (m) to ``start`` (m) at ``t = 0``."""
    p = np.asarray(start, dtype=float).reshape(1, 2)
    if not movers:
        return False
    # the far movers first, all at once: their places at t = 0 (numpy.interp's) less their
    # farthest vertex and radius then are beyond the limit (by more than rounding) for the
    # most; the distance to the shape is at least that
    # (a few movers with no kept table: each measured, the screen would cost more)
    gap = np.zeros(len(movers))
    if len(movers) >= TABLE_FROM or kept_table(movers) is not None:
        places = MoverPlaces(movers)
        centre = places.at(np.arange(len(movers)), gap)
        gap = np.hypot(*(centre - p[0]).T) - places.reach - places.rad0 - limit
    for m in (m for m, g in zip(movers, gap.tolist(), strict=True) if not g > 1e-9):
        d = float(point_polygon_distance(p, shape_at(m, np.array([0.0])))[0])
        if d < limit + float(m.radius_at(0.0)):
            return True
    return False
