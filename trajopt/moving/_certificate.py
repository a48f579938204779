"""The continuous-time certificate of a timed trajectory against predicted moving obstacles.

:func:`certify_movers` decides, for every instant ``t`` of ``[0, T]`` with
``T = max(duration, last prediction time)`` (the robot stands at its goal after
``duration``), whether the distance between the robot's centre and each mover's shape is at
least ``robot.radius + radius(t) + margin``, by interval bounds over time (theorem in
docs/concepts.md, "Moving obstacles"):

* the robot's centre is ``P(t) = C(s(t))`` with ``C`` parametrised by arc length
  (``|C'| = 1``) and ``s`` non-decreasing, so on ``[t0, t1]`` with midpoint ``tm``,
  ``|P(t) - P(tm)| <= rho_P = max(s(tm) - s(t0), s(t1) - s(tm))``;
* a mover is linear in time between its waypoints (the intervals are cut at its times), so
  every point of its shape moves by at most ``rho_M = (|c'| + reach |h'|) h`` in ``|t - tm| <= h``,
  and the shape's rounding is at most ``radius(t1)`` (it only grows);
* the distance from a point to a convex set is 1-Lipschitz in the point and in the set's
  Hausdorff distance: ``dist(t) >= dist(tm) - rho_P - rho_M`` (a first-order bound);
* for a disc mover, second order: ``P(t) - M(t) = D + w (t - tm) + E`` with ``D`` and ``w``
  the relative position and velocity at ``tm`` and ``|E| <= (kappa_max V^2 + A) h^2 / 2``
  (``|P''| = |C'' v^2 + C' a| <= kappa v^2 + |a|``, the mover's own second derivative is 0),
  so ``dist(t) >= min_{|tau| <= h} |D + w tau| - |E|``.

A robot with a :class:`~trajopt.robot.Footprint` (convex, turned by the heading) is its
polygon: the distance between two convex polygons (separating axes, then vertex to edge) at
``tm``, less the footprint's motion ``rho_P + R dtheta`` (``R`` its farthest vertex, ``dtheta
<= kappa_max rho_P`` the tangent's turn along the arc, at most ``pi``) and the mover's; the
bound of its circumscribed disc is taken too, and alone while it turns in place. First order
only.

A :class:`trajopt.TrajectoryChain` is certified piece by piece on its clock: a curve as above,
a motion at rest (a turn in place) as a robot standing still (``rho_P = 0``).

An interval whose bound clears the limit (within ``tol``) is accepted; one whose midpoint
is closer than the limit by more than ``tol / 2`` is a proven violation (a witness);
otherwise it is split in :data:`SPLIT` equal parts (disc movers; polygon movers in
:data:`POLYGON_SPLIT`): a level of splitting costs one evaluation of the robot whatever its
size, so fewer, wider levels. The splitting ends: once the bound's loss is below ``tol / 2`` an interval is
either accepted or a witness. Before that, a disc mover's interval whose box of the robot's
positions (:class:`._path_bounds.PathBoxes`) is farther from the box of the mover's centre than the largest
limit is accepted at once, the gap less the limit its bound. The polygon movers are bisected
together, each as it would be alone (the same intervals, bounds and verdict), the robot
evaluated once per distinct interval; a first interval whose box gap bounds its first bound
from below by at least 0 is accepted without its evaluation, which is made only when that
bound could be the least slack reported (so that the slack is the same as evaluating it).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from trajopt.errors import InvalidInputError
from trajopt.moving._bisection_bounds import disc_robot_bounds_kernel
from trajopt.moving._disc_windows import track_knots
from trajopt.moving._mover_segments import mover_table
from trajopt.moving._obstacle import MovingObstacle
from trajopt.moving._polygon_distance import point_polygon_kernel
from trajopt.moving._robot_windows import robot_windows

#: Bisection budget (intervals evaluated per mover) before the certificate gives up undecided.
MAX_INTERVALS = 400_000
#: Initial time step of the interval cover (s).
COVER_DT = 0.5
#: Parts an undecided interval is split in (disc movers).
SPLIT = 4
#: Parts an undecided interval of a polygon mover is split in.
POLYGON_SPLIT = 8


@dataclass(frozen=True, slots=True)
class MoverCertificate:
    """The verdict of :func:`certify_movers`.

    Attributes
    ----------
    ok : bool
        Proven: at every instant of ``[0, horizon]`` every mover's distance is at least its
        limit minus ``tol``.
    verdict : {"clear", "violated", "undecided"}
        ``"violated"``: ``witness_t`` is an instant where a mover is closer than its limit by
        more than ``tol / 2``; ``"undecided"``: the bisection budget ran out.
    slack : float
        Proven lower bound (m) of ``distance - limit`` over all instants and movers when
        ``ok`` (can be down to ``-tol``), else the worst sampled slack.
    mover : str
        Name of the mover of the smallest slack (or of the witness).
    witness_t : float
        Time (s) of the smallest sampled slack (the witness when violated).
    horizon : float
        The end of the certified time range (s).
    tol : float
        The tolerance (m).
    intervals : int
        Number of time intervals evaluated.
    """

    ok: bool
    verdict: str
    slack: float
    mover: str
    witness_t: float
    horizon: float
    tol: float
    intervals: int

    def summary(self) -> dict[str, Any]:
        """Return the verdict as ``stats["moving"]["certificate"]`` holds it (plain values)."""
        return {
            "ok": self.ok,
            "slack_m": self.slack,
            "mover": self.mover,
            "horizon_s": self.horizon,
            "intervals": self.intervals,
        }


def second_order_lower(d: np.ndarray, rel: np.ndarray, h: float, c2: np.ndarray) -> np.ndarray:
    """Lower bound (m) of the centres' distance over ``|tau| <= h`` about each interval's middle.

    ``d`` (n, 2): the robot's centre minus the mover's at the middles (m); ``rel`` (n, 2):
    their relative velocity (m/s); ``c2`` (n,): the bound on the robot's acceleration (m/s²).
    The distance of ``d + rel tau`` minimised over ``tau`` in ``[-h, h]`` (closed form), minus
    ``c2 h² / 2`` (the robot's deviation from its tangent) and a rounding allowance of 1e-12 m.
    """
    rr = np.sum(rel * rel, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        tau = np.where(rr > 0.0, -np.sum(d * rel, axis=1) / rr, 0.0)
    tau = np.clip(tau, -h, h)
    near = d + tau[:, None] * rel
    return np.hypot(near[:, 0], near[:, 1]) - 0.5 * c2 * h * h - 1e-12


def point_polygon_distance(p: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Distance (m) from points ``p`` (n, 2) to convex CCW polygons ``w`` (n, m, 2); 0 inside (compiled: :func:`~trajopt.moving._polygon_distance.point_polygon_kernel`)."""
    return point_polygon_kernel(
        np.ascontiguousarray(p, dtype=np.float64), np.ascontiguousarray(w, dtype=np.float64)
    )


def convex_distance(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Return the signed distance (m) of convex CCW polygons ``a`` (n, ma, 2) and ``b`` (n, mb, 2).

    Separated polygons: their distance (closest at a vertex of one and an edge of the other).
    Overlapping ones: minus the penetration depth, the shortest translation that separates
    them, found along the edge normals of both (separating axes; a polygon of one vertex is a
    point and has none). This signed distance is 1-Lipschitz in the Hausdorff distance of
    either polygon (it is the signed distance of the origin to ``b - a``).
    """
    separated = np.zeros(a.shape[0], dtype=bool)
    depth = np.full(a.shape[0], np.inf)
    for p, q in ((a, b), (b, a)):
        if p.shape[1] < 3:
            continue
        e = np.roll(p, -1, axis=1) - p
        normal = np.stack([e[..., 1], -e[..., 0]], axis=-1)  # outward for CCW
        normal /= np.maximum(np.linalg.norm(normal, axis=-1, keepdims=True), 1e-300)
        proj_q = np.einsum("nevk,nek->nev", q[:, None, :, :] - p[:, :, None, :], normal)
        proj_p = np.einsum("nevk,nek->nev", p[:, None, :, :] - p[:, :, None, :], normal)
        gap = np.min(proj_q, axis=2)  # > 0: this edge's line separates them
        separated |= np.any(gap > 0.0, axis=1)
        through = np.minimum(-gap, np.max(proj_q, axis=2) - np.min(proj_p, axis=2))
        depth = np.minimum(depth, np.min(through, axis=1))
    d = np.full(a.shape[0], np.inf)
    for p, q in ((a, b), (b, a)):
        for i in range(p.shape[1]):
            d = np.minimum(d, point_polygon_distance(p[:, i], q))
    return np.where(separated | ~np.isfinite(depth), d, -depth)


def shape_at(mover: MovingObstacle, t: np.ndarray) -> np.ndarray:
    """Return the mover's polygon (vertices in the world) at times ``t``, shape (n, m, 2)."""
    c, h = mover.pose_at(t)
    v = mover.shape_vertices
    ch, sh = np.cos(h)[:, None], np.sin(h)[:, None]
    x = c[:, 0:1] + ch * v[None, :, 0] - sh * v[None, :, 1]
    y = c[:, 1:2] + sh * v[None, :, 0] + ch * v[None, :, 1]
    return np.stack([x, y], axis=-1)


def ccw(v: np.ndarray) -> np.ndarray:
    """Return the polygon ``v`` (m, 2) counter-clockwise."""
    area2 = float(np.sum(v[:, 0] * np.roll(v[:, 1], -1) - np.roll(v[:, 0], -1) * v[:, 1]))
    return v if area2 > 0.0 else v[::-1].copy()


def check_movers(movers: Sequence[MovingObstacle] | None) -> tuple[MovingObstacle, ...]:
    """Return ``movers`` as a tuple, refusing anything but :class:`MovingObstacle` values."""
    if movers is None:
        return ()
    if isinstance(movers, MovingObstacle):
        raise InvalidInputError(
            "moving_obstacles must be a sequence of MovingObstacle, got one obstacle"
        )
    out = tuple(movers)
    for i, m in enumerate(out):
        if not isinstance(m, MovingObstacle):
            raise InvalidInputError(
                f"moving_obstacles[{i}] must be a trajopt.MovingObstacle, got {type(m).__name__}"
            )
    return out


def certify_movers(
    traj: Any,
    movers: Sequence[MovingObstacle],
    *,
    margin: float = 0.0,
    tol: float = 1e-6,
    robot_radius: float | None = None,
) -> MoverCertificate:
    """Certify a timed disc robot against moving obstacles at every instant (module docstring).

    Parameters
    ----------
    traj : trajopt.Trajectory or trajopt.TrajectoryChain
        One timed curve (its ``motion`` is ``s(t)``, its ``sample`` the pose), or a chain of
        such curves and motions at rest (turns in place, a car's steering at rest: a disc
        robot stands still during them).
    movers : sequence of MovingObstacle
        The predictions, in the trajectory's clock.
    margin : float
        Extra distance (m), >= 0.
    tol : float
        Tolerance (m), > 0: ``ok`` proves every distance >= limit - ``tol``.
    robot_radius : float, optional
        Certify a disc of this radius (m) instead of the robot; default the robot's own
        shape: its footprint when it has one, else the disc of ``traj.robot.radius``.

    Returns
    -------
    MoverCertificate
    """
    movers = check_movers(movers)
    if not (isinstance(margin, (int, float)) and math.isfinite(margin) and margin >= 0.0):
        raise InvalidInputError(f"margin must be a finite number >= 0 m, got {margin!r}")
    if not (isinstance(tol, (int, float)) and math.isfinite(tol) and tol > 0.0):
        raise InvalidInputError(f"tol must be a finite number > 0 m, got {tol!r}")
    if not hasattr(traj, "robot") or not hasattr(traj, "duration"):
        raise InvalidInputError(
            f"trajectory must be a trajopt.Trajectory or TrajectoryChain, got {type(traj).__name__}"
        )
    windows = robot_windows(traj)
    r_rob = float(traj.robot.radius if robot_radius is None else robot_radius)
    footprint = traj.robot.footprint if robot_radius is None else None
    body = None if footprint is None else ccw(np.asarray(footprint.vertices, dtype=float))
    horizon = max([float(traj.duration)] + [m.t_last for m in movers])
    if not movers:
        return MoverCertificate(True, "clear", math.inf, "", 0.0, horizon, tol, 0)
    model, a_last, _ = windows[-1]
    windows[-1] = (model, a_last, horizon)  # the robot then stands at the goal
    extra = margin if body is not None else r_rob + margin
    discs = [m for m in movers if m.vertices is None]
    polygons = [m for m in movers if m.vertices is not None]
    best = (math.inf, "", 0.0)
    total = 0
    pending = []  # the polygon movers' bisections, their far intervals not yet evaluated
    for model, a, b in windows:
        if discs and b > a:
            verdict, slack, who, wt, count = _certify_discs(model, discs, a, b, extra, tol, body)
            total += count
            if verdict != "clear":
                return MoverCertificate(False, verdict, slack, who, wt, horizon, tol, total)
            best = min(best, (slack, who, wt))
        ones = polygons if b > a else list(movers)
        bisection = _Bisection(model, ones, a, b, extra, tol, body)
        for mover, (verdict, slack, wt, count) in zip(ones, bisection.results, strict=False):
            total += count
            if verdict != "clear":
                return MoverCertificate(False, verdict, slack, mover.name, wt, horizon, tol, total)
        pending.append((ones, bisection))
    # the far intervals whose bound may be the least slack (or equal to it), evaluated
    below = min([best[0]] + [float(np.min(bs.proven, initial=math.inf)) for _, bs in pending])
    for ones, bisection in pending:
        for mover, (slack, wt) in zip(ones, bisection.resolve(below), strict=False):
            best = min(best, (slack, mover.name, wt))
    return MoverCertificate(True, "clear", best[0], best[1], best[2], horizon, tol, total)


def _group_starts(keys: np.ndarray) -> np.ndarray:
    """Return the indices where a run of equal ``keys`` starts, shape (groups,) (0 first)."""
    new = np.empty(keys.shape[0], dtype=bool)
    new[:1] = True
    np.not_equal(keys[1:], keys[:-1], out=new[1:])
    return np.flatnonzero(new)


def _cover(a: float, b: float, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Intervals ``(t0, t1)`` (s) of at most :data:`COVER_DT` covering ``[a, b]``, cut at ``times``."""
    knots = np.unique(np.concatenate([[a, b], times[(times > a) & (times < b)]]))
    if knots.shape[0] < 2:  # a zero-length window: one instant
        return np.full(1, a), np.full(1, a)
    n = np.maximum(1, np.ceil(np.diff(knots) / COVER_DT).astype(np.int64))
    k = np.repeat(np.arange(n.shape[0]), n)
    j = np.arange(k.shape[0]) - np.repeat(np.cumsum(n) - n, n)
    width = np.diff(knots)[k] / n[k]
    t0 = knots[k] + j * width
    t1 = np.where(j == n[k] - 1, knots[k + 1], t0 + width)
    return t0, t1


def _covers(
    a: float, b: float, movers: Sequence[MovingObstacle]
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every mover's :func:`_cover` of ``[a, b]``, all at once: ``(t0, t1, mover index)``.

    The same intervals as :func:`_cover`, bit for bit, each mover's in order of time, the
    movers in order.
    """
    if not b > a:
        covers = [_cover(a, b, m.times) for m in movers]
        t0 = np.concatenate([c[0] for c in covers])
        t1 = np.concatenate([c[1] for c in covers])
        return t0, t1, np.repeat(np.arange(len(movers)), [c[0].shape[0] for c in covers])
    inner = [m.times[(m.times > a) & (m.times < b)] for m in movers]
    knots = np.concatenate([np.concatenate([[a], t, [b]]) for t in inner])
    own = np.repeat(np.arange(len(movers)), [t.shape[0] + 2 for t in inner])
    seg = np.flatnonzero(own[1:] == own[:-1])  # consecutive knots of one mover
    lo, gap = knots[seg], knots[seg + 1] - knots[seg]
    n = np.maximum(1, np.ceil(gap / COVER_DT).astype(np.int64))
    k = np.repeat(np.arange(seg.shape[0]), n)
    j = np.arange(k.shape[0]) - np.repeat(np.cumsum(n) - n, n)
    width = gap[k] / n[k]
    t0 = lo[k] + j * width
    t1 = np.where(j == n[k] - 1, knots[seg + 1][k], t0 + width)
    return t0, t1, own[seg][k]


def _certify_discs(
    model: Any,
    movers: Sequence[MovingObstacle],
    a: float,
    b: float,
    extra: float,
    tol: float,
    body: np.ndarray | None,
) -> tuple[str, float, str, float, int]:
    """Split the intervals of ``[a, b]`` for all disc movers at once (in :data:`SPLIT` parts).

    The same bounds as :func:`_certify_each`, in :data:`SPLIT` parts: each interval keeps
    its mover's index and the line ``A + V t`` its centre follows on the waypoint segment
    holding it; the robot is evaluated once per distinct interval. Returns ``(verdict,
    slack, mover name, time, intervals)``.
    """
    # each mover's knots: a, its times strictly inside, b; its centre there (numpy.interp's)
    ow, kn, pos = track_knots(movers, a, b)
    first = np.array([float(m.times[0]) for m in movers])[ow]
    last = np.array([m.t_last for m in movers])[ow]
    # segments between consecutive knots of one mover: its centre is A + V t there
    seg = np.flatnonzero(ow[1:] == ow[:-1])
    u, w = kn[seg], kn[seg + 1]
    moving = (u >= first[seg]) & (w <= last[seg]) & (w > u)
    with np.errstate(divide="ignore", invalid="ignore"):
        v_seg = np.where(moving[:, None], (pos[seg + 1] - pos[seg]) / (w - u)[:, None], 0.0)
    a_seg = pos[seg] - v_seg * u[:, None]
    n = np.maximum(1, np.ceil((w - u) / COVER_DT).astype(np.int64))
    k = np.repeat(np.arange(seg.shape[0]), n)
    i = np.arange(k.shape[0]) - np.repeat(np.cumsum(n) - n, n)
    width = (w - u)[k] / n[k]
    t0 = u[k] + i * width
    t1 = np.where(i == n[k] - 1, w[k], t0 + width)
    mj, vel, anchor = ow[seg][k], v_seg[k], a_seg[k]
    rad0 = np.array([m.radius for m in movers])[mj]
    grow = np.array([m.growth for m in movers])[mj]
    t_last = np.array([max(m.t_last, 0.0) for m in movers])[mj]
    reach_b = 0.0 if body is None else float(np.max(np.hypot(body[:, 0], body[:, 1])))
    proven, proven_t, proven_j = math.inf, 0.0, 0
    count, budget = t0.size, MAX_INTERVALS * len(movers)
    # far apart: the robot's box during the interval (its reference point; a footprint lies
    # within reach_b of it) against the box of the mover's centre there, whose gap less the
    # largest limit is a lower bound of the slack
    rx0, rx1, ry0, ry1 = model.box(t0, t1)
    c0, c1 = anchor + vel * t0[:, None], anchor + vel * t1[:, None]
    gx = np.maximum(
        np.maximum(np.minimum(c0[:, 0], c1[:, 0]) - rx1, rx0 - np.maximum(c0[:, 0], c1[:, 0])), 0.0
    )
    gy = np.maximum(
        np.maximum(np.minimum(c0[:, 1], c1[:, 1]) - ry1, ry0 - np.maximum(c0[:, 1], c1[:, 1])), 0.0
    )
    lower = np.hypot(gx, gy) - reach_b - (extra + rad0 + grow * np.clip(t1, 0.0, t_last))
    far = lower >= 0.0
    if np.any(far):
        i = int(np.argmin(np.where(far, lower, np.inf)))
        proven, proven_t, proven_j = float(lower[i]), float(0.5 * (t0[i] + t1[i])), int(mj[i])
        near = ~far
        t0, t1, mj, vel, anchor = t0[near], t1[near], mj[near], vel[near], anchor[near]
        rad0, grow, t_last = rad0[near], grow[near], t_last[near]
    first_level = True
    while t0.size:
        if not first_level:
            count += t0.size
        first_level = False
        count += t0.size
        if count > budget:
            return "undecided", proven, movers[proven_j].name, proven_t, count
        tm = 0.5 * (t0 + t1)
        h = 0.5 * (t1 - t0)
        # the robot once per distinct interval (the movers share the cover and its halves)
        uniq, inv = np.unique(t0 + 1j * t1, return_inverse=True)
        inv = inv.reshape(-1)
        u0, u1 = uniq.real, uniq.imag
        p, rho_p, v_rob = (x[inv] for x in model.at(u0, 0.5 * (u0 + u1), u1))
        theta, turn = model.theta[inv], model.turn[inv]
        c2 = np.broadcast_to(model.c2_local, u0.shape)[inv]
        centre = anchor + vel * tm[:, None]
        speed_m = np.hypot(vel[:, 0], vel[:, 1])
        rho_m = speed_m * h
        lim_mid = extra + rad0 + grow * np.clip(tm, 0.0, t_last)
        lim_hi = extra + rad0 + grow * np.clip(t1, 0.0, t_last)
        d = p - centre
        dist_m = np.hypot(d[:, 0], d[:, 1])
        lower = dist_m - rho_p - rho_m - lim_hi
        if body is not None:  # the footprint: exact at tm, its vertices move rho_P + R turn
            c, sn = np.cos(theta)[:, None], np.sin(theta)[:, None]
            poly = np.stack(
                [
                    p[:, 0:1] + c * body[None, :, 0] - sn * body[None, :, 1],
                    p[:, 1:2] + sn * body[None, :, 0] + c * body[None, :, 1],
                ],
                axis=-1,
            )
            dist_m = convex_distance(poly, centre[:, None, :])
            lower_poly = dist_m - rho_p - reach_b * turn - rho_m - lim_hi
            lower = np.maximum(lower - reach_b, lower_poly)  # or its circumscribed disc
        else:
            # second order: min over |tau| <= h of |D + w tau|, minus the curvature term
            lower2 = second_order_lower(d, v_rob - vel, h, c2) - lim_hi
            lower = np.fmax(lower, lower2)  # an unbounded curvature gives -inf or nan
        slack_mid = dist_m - lim_mid
        bad = slack_mid < -0.5 * tol
        if np.any(bad):
            i = int(np.argmin(np.where(bad, slack_mid, np.inf)))
            return "violated", float(slack_mid[i]), movers[mj[i]].name, float(tm[i]), count
        done = lower >= -tol
        if np.any(done):
            i = int(np.argmin(np.where(done, lower, np.inf)))
            if lower[i] < proven:
                proven, proven_t, proven_j = float(lower[i]), float(tm[i]), int(mj[i])
        # each undecided interval in SPLIT equal parts (a level costs one evaluation of the
        # robot, whatever its size: fewer, wider levels)
        split = np.repeat(np.flatnonzero(~done), SPLIT)
        part = np.tile(np.arange(SPLIT), split.shape[0] // SPLIT)
        a, width = t0[split], (t1 - t0)[split]
        t1 = np.where(part == SPLIT - 1, t1[split], a + width * ((part + 1) / SPLIT))
        t0 = np.where(part == 0, a, a + width * (part / SPLIT))
        mj, vel, anchor = mj[split], vel[split], anchor[split]
        rad0, grow, t_last = rad0[split], grow[split], t_last[split]
    return "clear", proven, movers[proven_j].name if movers else "", proven_t, count


class _Bisection:
    """Bisect each mover's cover of ``[a, b]``: ``results``, ``(verdict, slack, time, intervals)`` per mover.

    Each mover's intervals are split in :data:`POLYGON_SPLIT` equal parts until decided
    (first order; second order for a disc mover and a disc robot), in the order one mover
    at a time would take them (its own intervals: the undecided ones' first parts, then
    their second parts, ...), so that its
    verdict, slack, time and count do not depend on the other movers. All movers advance
    together: the robot is evaluated once per distinct interval of a level, the movers'
    poses and rates are gathered from :class:`._mover_segments.MoverSegments`; a disc robot's
    bounds are compiled (:func:`._bisection_bounds.disc_robot_bounds_kernel`), a footprint's
    are arrays. The movers after the first one
    not clear are not certified (:func:`certify_movers` stops there): the list ends at it.
    ``body``: the robot's convex footprint (robot frame, CCW, shape (m, 2)), or ``None`` for
    a disc (whose radius is in ``extra``).

    Far first intervals are set aside unevaluated: the gap between the box of the robot's
    positions (the motion model's ``box_rho``) and the box of the mover's reference point (its
    positions at both ends: it moves on a line), less the mover's reach, the robot's
    ``rho_P`` bound (its arc), the mover's ``rho_M``, the limit at the end, the footprint's
    reach and 1e-6 m against rounding, is a lower bound ``cheap`` of the interval's first
    bound. Where ``cheap >= 0`` the interval is accepted at the first level (no violation
    there, no parts), so only its bound, the mover's slack if it is the least, is missing:
    :meth:`resolve` evaluates it when ``cheap`` is not above a known slack. A clear mover's
    ``results`` slack is that of the intervals evaluated until then.
    """

    def __init__(
        self,
        model: Any,
        movers: Sequence[MovingObstacle],
        a: float,
        b: float,
        extra: float,
        tol: float,
        body: np.ndarray | None,
    ) -> None:
        nm = len(movers)
        self.model, self.extra, self.body, self.nm = model, extra, body, nm
        self.results: list[tuple[str, float, float, int]] = []
        self.proven = np.zeros(0)
        if nm == 0:
            return
        t0, t1, mj = _covers(a, b, movers)
        table = mover_table(movers)
        self.seg = seg = table.seg
        # an interval never straddles its mover's times: its midpoint is on the segment of its
        # start, or on the next one when it falls on the next time (``searchsorted`` right)
        g0 = seg.row(mj, t0)
        self.reach, self.rad0, self.grow = table.reach, table.rad0, table.grow
        self.t_last, self.disc, self.sizes = table.t_last, table.disc, table.sizes
        self.verts, self.columns, self.padded = table.verts, table.columns, table.padded
        self.reach_b = 0.0 if body is None else float(np.max(np.hypot(body[:, 0], body[:, 1])))
        # each first interval's place in its mover's cover (ties go to the first)
        pos = np.arange(mj.shape[0]) - np.searchsorted(mj, mj, side="left")
        cheap = self._cheap(t0, t1, mj, g0)
        far = cheap >= 0.0
        self.far = (t0[far], t1[far], mj[far], g0[far], pos[far], cheap[far])
        near = ~far
        t0, t1, mj, g0, pos = t0[near], t1[near], mj[near], g0[near], pos[near]
        proven = np.full(nm, math.inf)
        proven_t = np.zeros(nm)
        proven_key = np.full((nm, 2), np.iinfo(np.int64).max)  # (level, place) of the least
        counts = np.bincount(self.far[2], minlength=nm).astype(np.int64)
        result: list[tuple[str, float, float, int] | None] = [None] * nm
        stop = nm  # the first mover not clear (those after it are not certified)
        level = 0
        while t0.size or level == 0:
            counts += np.bincount(mj, minlength=nm)
            over = np.flatnonzero(counts[:stop] > MAX_INTERVALS)
            if over.size:
                j = int(over[0])
                result[j] = ("undecided", math.inf, 0.0, int(counts[j]))
                stop = j
                keep = mj < stop
                t0, t1, mj, g0, pos = t0[keep], t1[keep], mj[keep], g0[keep], pos[keep]
            if not t0.size:
                break
            lower, slack_mid, tm = self._bounds(t0, t1, mj, g0)
            bad = slack_mid < -0.5 * tol
            if np.any(bad):
                # each mover's first smallest witness (its intervals are contiguous, in order)
                order = np.lexsort((np.arange(bad.size), np.where(bad, slack_mid, np.inf), mj))
                first = order[_group_starts(mj[order])]
                for i in first[bad[first]]:
                    j = int(mj[i])
                    if j < stop:
                        result[j] = ("violated", float(slack_mid[i]), float(tm[i]), int(counts[j]))
                        stop = j
            done = lower >= -tol
            if np.any(done):
                order = np.lexsort((np.arange(done.size), np.where(done, lower, np.inf), mj))
                first = order[_group_starts(mj[order])]
                i = first[done[first]]
                j = mj[i]
                better = lower[i] < proven[j]
                i, j = i[better], j[better]
                proven[j], proven_t[j] = lower[i], tm[i]
                proven_key[j, 0] = level
                proven_key[j, 1] = pos[i] if level == 0 else 0
            split = ~done & (mj < stop)
            a0, b0, j0, gg = t0[split], t1[split], mj[split], g0[split]
            # each mover's first parts in order, then its second parts, ... (as one mover
            # alone); the parts meet at the same floats (a + width k / POLYGON_SPLIT)
            n, width = POLYGON_SPLIT, b0 - a0
            cuts = [a0] + [a0 + width * (k / n) for k in range(1, n)] + [b0]
            jj = np.concatenate([j0] * n)
            order = np.argsort(jj, kind="stable")
            t0 = np.concatenate(cuts[:-1])[order]
            t1 = np.concatenate(cuts[1:])[order]
            mj = jj[order]
            g0 = np.concatenate([gg] * n)[order]
            pos = np.zeros(t0.shape[0], dtype=np.int64)
            level += 1
        self.proven, self.proven_t, self.proven_key = proven, proven_t, proven_key
        self.stop = stop
        for j in range(stop + 1 if stop < nm else nm):
            res = result[j]
            if res is None:
                res = ("clear", float(proven[j]), float(proven_t[j]), int(counts[j]))
            elif res[0] == "undecided":  # its slack: the least bound so far, far ones too
                self.resolve(float(proven[j]), only=j)
                res = ("undecided", float(self.proven[j]), float(self.proven_t[j]), res[3])
            self.results.append(res)

    def _cheap(self, t0: np.ndarray, t1: np.ndarray, mj: np.ndarray, g0: np.ndarray) -> np.ndarray:
        """Return a lower bound (m) of each first interval's bound (class docstring)."""
        seg = self.seg
        x0, x1, y0, y1, rho_up = self.model.box_rho(t0, t1)
        c0, c1 = seg.at(g0, t0), seg.at(g0, t1)
        gx = np.maximum(
            np.maximum(np.minimum(c0[:, 0], c1[:, 0]) - x1, x0 - np.maximum(c0[:, 0], c1[:, 0])),
            0.0,
        )
        gy = np.maximum(
            np.maximum(np.minimum(c0[:, 1], c1[:, 1]) - y1, y0 - np.maximum(c0[:, 1], c1[:, 1])),
            0.0,
        )
        tm = 0.5 * (t0 + t1)
        g = g0 + (tm >= seg.next[g0])
        vel, w = seg.vel[g], seg.turn[g]
        rho_m = (np.hypot(vel[:, 0], vel[:, 1]) + self.reach[mj] * np.abs(w)) * (0.5 * (t1 - t0))
        lim_hi = self.extra + (self.rad0[mj] + self.grow[mj] * np.clip(t1, 0.0, self.t_last[mj]))
        gap = np.hypot(gx, gy) - self.reach[mj] - self.reach_b
        return gap - rho_up - rho_m - lim_hi - 1e-6

    def _bounds(
        self, t0: np.ndarray, t1: np.ndarray, mj: np.ndarray, g0: np.ndarray
    ) -> tuple[np.ndarray, ...]:
        """Return each interval's lower bound of the slack, slack at the middle and middle."""
        model, seg, body, extra = self.model, self.seg, self.body, self.extra
        reach_b, sizes = self.reach_b, self.sizes
        tm = 0.5 * (t0 + t1)
        h = 0.5 * (t1 - t0)
        uniq, inv = np.unique(t0 + 1j * t1, return_inverse=True)
        inv = inv.reshape(-1)
        u0, u1 = uniq.real, uniq.imag
        p, rho_p, v_rob = (x[inv] for x in model.at(u0, 0.5 * (u0 + u1), u1))
        g = g0 + (tm >= seg.next[g0])
        pose = seg.at(g, tm)
        if body is None:  # compiled (a disc robot: no footprint, second order for disc movers)
            c2 = np.broadcast_to(model.c2_local, u0.shape)[inv]
            lower, slack_mid = disc_robot_bounds_kernel(
                *(np.ascontiguousarray(x) for x in (t1, tm, h, mj, g, p, rho_p, v_rob, c2, pose)),
                np.cos(pose[:, 2]),
                np.sin(pose[:, 2]),
                seg.vel,
                seg.turn,
                self.columns,
                self.padded,
                float(extra),
            )
            return lower, slack_mid, tm
        # the footprint: exact at tm, its vertices move rho_P + R turn
        w = seg.turn[g]
        rho_m = (np.hypot(seg.vel[g, 0], seg.vel[g, 1]) + self.reach[mj] * np.abs(w)) * h
        t_last = self.t_last[mj]
        lim_mid = extra + (self.rad0[mj] + self.grow[mj] * np.clip(tm, 0.0, t_last))
        lim_hi = extra + (self.rad0[mj] + self.grow[mj] * np.clip(t1, 0.0, t_last))
        dist_m = np.empty(tm.shape[0])
        theta, turn = model.theta[inv], model.turn[inv]
        c, sn = np.cos(theta)[:, None], np.sin(theta)[:, None]
        poly = np.stack(
            [
                p[:, 0:1] + c * body[None, :, 0] - sn * body[None, :, 1],
                p[:, 1:2] + sn * body[None, :, 0] + c * body[None, :, 1],
            ],
            axis=-1,
        )
        dist_c = np.empty(tm.shape[0])
        for size in np.unique(sizes[mj]):
            sel = sizes[mj] == size
            v = self.verts[int(size)][mj[sel]]
            ps = pose[sel]
            ch, sh = np.cos(ps[:, 2])[:, None], np.sin(ps[:, 2])[:, None]
            x = ps[:, 0:1] + ch * v[:, :, 0] - sh * v[:, :, 1]
            y = ps[:, 1:2] + sh * v[:, :, 0] + ch * v[:, :, 1]
            shape = np.stack([x, y], axis=-1)
            dist_c[sel] = point_polygon_distance(p[sel], shape)
            dist_m[sel] = convex_distance(poly[sel], shape)
        lower = dist_c - rho_p - rho_m - lim_hi
        lower_poly = dist_m - rho_p - reach_b * turn - rho_m - lim_hi
        lower = np.maximum(lower - reach_b, lower_poly)  # or its circumscribed disc
        return lower, dist_m - lim_mid, tm

    def resolve(self, below: float, only: int | None = None) -> list[tuple[float, float]]:
        """Evaluate the far intervals whose ``cheap`` is at most ``below``; return ``(slack, time)`` per mover.

        A far interval not evaluated has a bound above ``below``: it is not a slack at most
        ``below``. ``only``: that mover's far intervals alone.
        """
        if self.nm == 0:
            return []
        t0, t1, mj, g0, pos, cheap = self.far
        pick = (cheap <= below) & (mj <= self.stop)
        if only is not None:
            pick &= mj == only
        if np.any(pick):
            t0, t1, mj, g0, pos = t0[pick], t1[pick], mj[pick], g0[pick], pos[pick]
            self.far = tuple(x[~pick] for x in self.far)
            lower, _, tm = self._bounds(t0, t1, mj, g0)
            # each mover's least (first place on a tie), against its least so far
            order = np.lexsort((pos, lower, mj))
            first = order[_group_starts(mj[order])]
            for i in first:
                j = int(mj[i])
                if (lower[i], 0, pos[i]) < (self.proven[j], *self.proven_key[j]):
                    self.proven[j], self.proven_t[j] = lower[i], tm[i]
                    self.proven_key[j] = (0, pos[i])
        return [(float(self.proven[j]), float(self.proven_t[j])) for j in range(self.nm)]
