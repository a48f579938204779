"""Stop-and-turn: drive a polyline straight, turning in place at rest at every corner.

The opt-in fallback of :class:`trajopt.Planner` (``fallback="stop_and_turn"``) for queries
the smoother cannot solve (typically one-cell passages of the inflated grid): the A*
polyline is driven by a differential drive as

* one **rest-to-rest straight move per segment**: a time-optimal, jerk-limited 1-DoF
  profile along the segment computed by ruckig (position interface, never
  ``intermediate_positions``) with ``|v| <= min(v_max, wheel_v_max)`` (the speed cap
  :meth:`Robot.speed_cap` at curvature 0), ``|a| <= a_max`` and ``|jerk| <= j_max``;
* one **rest-to-rest turn in place** at every corner (and at the start and the end when
  ``start_heading`` / ``goal_heading`` are given), a ruckig profile of the heading by the
  shortest signed angle (``+pi`` for an exact U-turn), with

  - ``|omega| <= omega_max`` and, with a ``track_width``, ``|omega| <= wheel_v_max / h``,
  - ``|d omega/dt| <= a_max / h`` and ``|d^2 omega/dt^2| <= j_max / h``,

  where ``h = track_width / 2`` (``h = radius`` when the robot has no ``track_width``).
  ``h`` times an angular quantity is the tangential motion of a wheel (or of the
  footprint's rim) during the turn, so the wheels never move faster, accelerate harder or
  jerk more than the translation limits allow.

The heading is continuous and unwrapped; it is constant on every segment and changes only
while the robot is at rest. Consecutive points closer than 1e-9 m and vertices where the
path goes straight on (turn below 1e-12 rad) are dropped before planning.

Sampling conventions (:class:`~trajopt.motion._samples.TrajectorySample`): ``v``, ``a``,
``jerk`` and ``s`` describe the motion along the path (``s`` is the distance travelled, it
never decreases); ``omega`` is ``d theta / dt``. **``kappa`` is 0 everywhere**: the path is
straight between its vertices, and at a vertex the robot turns at rest, where the curvature
``omega / v`` is undefined; a finite convention keeps the CSV/JSON writers and
:mod:`trajopt.metrics` working (``a_lat = kappa v^2 = 0`` as well). The wheel speeds are
``v -+ omega * track_width / 2``, which is right both on segments and during turns.
"""

from __future__ import annotations

import logging
import math
import time
from typing import Any

import numpy as np

from trajopt.errors import InvalidInputError, TimingError
from trajopt.geometry import PolylineCurve
from trajopt.motion import StopAndTurnTrajectory, TurnInPlace
from trajopt.robot import Robot
from trajopt.timing._speed_limits import SpeedLimits
from trajopt.validation import heading, short_repr

logger = logging.getLogger(__name__)

#: Consecutive points closer than this are merged (m).
MIN_SEGMENT_M = 1e-9
#: A vertex whose turn angle is below this (rad) is dropped (the path goes straight on).
MIN_TURN_RAD = 1e-12
_MAX_POINTS = 1_000_000


# ====================================================================== limits
def turn_limits(robot: Robot) -> tuple[float, float, float]:
    """Limits of a turn in place: ``(omega_lim, alpha_lim, zeta_lim)``.

    Parameters
    ----------
    robot : Robot

    Returns
    -------
    tuple of float
        Yaw rate (rad/s) ``min(omega_max, wheel_v_max / h)``, yaw acceleration (rad/s^2)
        ``a_max / h`` and yaw jerk (rad/s^3) ``j_max / h``, with ``h = track_width / 2``
        (``h = radius`` when the robot has no ``track_width``; then the wheel term is absent).
    """
    if robot.track_width is not None:
        half = 0.5 * robot.track_width
        omega = min(robot.omega_max, robot.wheel_v_max / half)  # type: ignore[operator]
    else:
        half = robot.radius
        omega = robot.omega_max
    return float(omega), robot.a_max / half, robot.j_max / half


# ====================================================================== ruckig
class RestToRest:
    """Rest-to-rest 1-DoF ruckig position problems ``0 -> d`` (d > 0) under fixed limits.

    The timing's ruckig wrapper without its velocity margin; the straight moves and turns
    of :func:`stop_and_turn` and the turns of :class:`trajopt.motion._chain.TurnInPlace`.

    Parameters
    ----------
    vmax, amax, jmax : float
        Limits of the motion's speed, acceleration and jerk (its units per s, s^2, s^3).
    """

    def __init__(self, vmax: float, amax: float, jmax: float) -> None:
        from trajopt.timing._ruckig_profile import RuckigProfile

        self.vmax = vmax
        self.rk = RuckigProfile(amax, jmax)

    def solve(self, d: float) -> np.ndarray:
        """Rows ``(duration, q0, dq0, ddq0, jerk)`` of the profile's non-empty phases."""
        rows = self.rk.solve((0.0, 0.0, 0.0), (d, 0.0, 0.0), self.vmax, v_margin=0.0)
        if rows is None:
            raise TimingError(f"ruckig found no rest-to-rest move of {d!r}")
        return rows[:, [5, 1, 2, 3, 4]]


# ====================================================================== builder
def stop_and_turn(
    points: Any,
    robot: Robot | None = None,
    *,
    start_heading: float | None = None,
    goal_heading: float | None = None,
    speed_limits: SpeedLimits | None = None,
) -> StopAndTurnTrajectory:
    """Drive a polyline with rest-to-rest straight moves and turns in place.

    Parameters
    ----------
    points : array_like, shape (n, 2)
        Vertices in metres, in order; at least two distinct points. Points closer than
        1e-9 m to the previous one and vertices where the path goes straight on are dropped.
    robot : Robot, optional
        Limits; default ``Robot()``. The turn limits are :func:`turn_limits`.
    start_heading, goal_heading : float, optional
        Headings (rad) at the start and at the end; when given, the robot first turns in
        place from ``start_heading`` to the first segment's direction, and at the end from
        the last segment's direction to ``goal_heading`` (shortest signed angles). Without
        them the motion starts and ends along the first and last segment.
    speed_limits : SpeedLimits, optional
        Speed-limit zones (:mod:`trajopt.timing._speed_limits`): each straight move keeps under the
        lowest limit of the mask cells meeting its segment's bounding box.

    Returns
    -------
    StopAndTurnTrajectory
        Starts at ``points[0]``, ends exactly at ``points[-1]`` at rest; ``stats`` holds
        ``fallback = "stop_and_turn"``, ``n_segments``, ``n_turns``, ``turn_total_rad``
        (sum of absolute turns), ``drive_time_s``, ``turn_time_s`` and ``compute_s``.

    Raises
    ------
    InvalidInputError
        ``points`` not of shape (n, 2) with n >= 2, non-finite, spanning no length;
        ``robot`` not a :class:`Robot`; a heading that is not a finite number.
    TimingError
        ruckig rejects a move (only for absurd magnitudes, e.g. coordinates near 1e300).

    Examples
    --------
    >>> from trajopt.timing._stop_and_turn import stop_and_turn
    >>> traj = stop_and_turn([(0, 0), (1, 0), (1, 1)])
    >>> round(traj.length, 6), traj.stats["n_turns"]
    (2.0, 1)
    """
    t_start = time.perf_counter()
    robot = Robot() if robot is None else robot
    if not isinstance(robot, Robot):
        raise InvalidInputError(f"robot must be a trajopt.Robot, got {type(robot).__name__}")
    pts = _clean_points(points)
    h0 = heading("start_heading", start_heading)
    h1 = heading("goal_heading", goal_heading)

    d = np.diff(pts, axis=0)
    seg_len = np.hypot(d[:, 0], d[:, 1])
    dirs = np.arctan2(d[:, 1], d[:, 0])
    n_seg = len(seg_len)

    # unwrapped segment headings, turning by the shortest signed angle
    theta0 = float(dirs[0]) if h0 is None else h0
    seg_theta = np.empty(n_seg)
    prev = theta0
    for k in range(n_seg):
        prev = prev + math.remainder(float(dirs[k]) - prev, 2.0 * math.pi)
        seg_theta[k] = prev
    theta_end = float(seg_theta[-1])
    if h1 is not None:
        theta_end = theta_end + math.remainder(h1 - theta_end, 2.0 * math.pi)

    if speed_limits is not None and not isinstance(speed_limits, SpeedLimits):
        raise InvalidInputError(
            f"speed_limits must be a trajopt.SpeedLimits, got {type(speed_limits).__name__}"
        )
    v_straight = float(robot.speed_cap(0.0))
    seg_vmax = np.full(n_seg, v_straight)
    if speed_limits is not None:
        lo = np.minimum(pts[:-1], pts[1:])
        hi = np.maximum(pts[:-1], pts[1:])
        seg_vmax = np.minimum(seg_vmax, speed_limits.box_caps(lo, hi, robot.v_max))
    drives: dict[float, RestToRest] = {}
    w_lim, al_lim, z_lim = turn_limits(robot)
    turn = RestToRest(w_lim, al_lim, z_lim)

    blocks: list[np.ndarray] = []  # rows (dur, seg, sigma, v, a, j, theta, omega, alpha, zeta)
    n_turns = 0
    drive_time = turn_time = turn_total = 0.0

    def add_turn(th_from: float, th_to: float, seg: int, sigma: float) -> None:
        nonlocal n_turns, turn_time, turn_total
        delta = th_to - th_from
        if delta == 0.0:
            return
        rows = turn.solve(abs(delta))
        sgn = 1.0 if delta > 0 else -1.0
        out = np.zeros((len(rows), 10))
        out[:, 0] = rows[:, 0]
        out[:, 1] = seg
        out[:, 2] = sigma
        out[:, 6] = th_from + sgn * rows[:, 1]
        out[:, 7:10] = sgn * rows[:, 2:5] + 0.0  # no -0.0 in the exports
        blocks.append(out)
        n_turns += 1
        turn_time += float(rows[:, 0].sum())
        turn_total += abs(delta)

    add_turn(theta0, float(seg_theta[0]), 0, 0.0)
    for k in range(n_seg):
        if k > 0:
            add_turn(float(seg_theta[k - 1]), float(seg_theta[k]), k, 0.0)
        vk = float(seg_vmax[k])
        if vk not in drives:
            drives[vk] = RestToRest(vk, robot.a_max, robot.j_max)
        rows = drives[vk].solve(float(seg_len[k]))
        out = np.zeros((len(rows), 10))
        out[:, 0] = rows[:, 0]
        out[:, 1] = k
        out[:, 2:6] = rows[:, 1:5]
        out[:, 6] = seg_theta[k]
        blocks.append(out)
        drive_time += float(rows[:, 0].sum())
    add_turn(float(seg_theta[-1]), theta_end, n_seg - 1, float(seg_len[-1]))

    table = np.vstack(blocks)
    dur = table[:, 0]
    phase_t = np.concatenate([[0.0], np.cumsum(dur[:-1])])
    duration = float(phase_t[-1] + dur[-1])
    stats: dict[str, Any] = {
        "fallback": "stop_and_turn",
        "n_segments": int(n_seg),
        "n_turns": int(n_turns),
        "turn_total_rad": float(turn_total),
        "drive_time_s": float(drive_time),
        "turn_time_s": float(turn_time),
        "turn_limits": {"omega": w_lim, "alpha": al_lim, "zeta": z_lim},
        "compute_s": time.perf_counter() - t_start,
    }
    return StopAndTurnTrajectory(
        path=PolylineCurve(pts),
        robot=robot,
        phase_t=phase_t,
        phase_seg=table[:, 1].astype(np.int64),
        phase_sigma=table[:, 2],
        phase_v=table[:, 3],
        phase_a=table[:, 4],
        phase_j=table[:, 5],
        phase_theta=table[:, 6],
        phase_omega=table[:, 7],
        phase_alpha=table[:, 8],
        phase_zeta=table[:, 9],
        duration=duration,
        theta_end=theta_end,
        stats=stats,
    )


def _clean_points(points: Any) -> np.ndarray:
    """Return validated ``(n, 2)`` float vertices without short segments and straight-on vertices."""
    try:
        p = np.array(points, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(
            f"points must be an array of shape (n, 2) in metres, got {short_repr(points)}"
        ) from exc
    if p.ndim != 2 or p.shape[1] != 2 or not 2 <= p.shape[0] <= _MAX_POINTS:
        raise InvalidInputError(
            f"points must have shape (n, 2) with 2 <= n <= {_MAX_POINTS}, got {p.shape}"
        )
    bad = ~np.isfinite(p).all(axis=1)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise InvalidInputError(f"points must be finite, got points[{i}] = {p[i].tolist()}")
    keep = [0]
    for i in range(1, len(p)):
        if math.hypot(*(p[i] - p[keep[-1]])) >= MIN_SEGMENT_M:
            keep.append(i)
    if len(keep) < 2:
        raise InvalidInputError(
            f"points must span a length: all {len(p)} points lie within {MIN_SEGMENT_M} m "
            f"of {p[0].tolist()}"
        )
    if keep[-1] != len(p) - 1:  # end exactly at the last point
        keep[-1] = len(p) - 1
        if len(keep) > 2 and math.hypot(*(p[keep[-1]] - p[keep[-2]])) < MIN_SEGMENT_M:
            del keep[-2]
    q = p[keep]
    # drop vertices where the path goes straight on (no turn)
    out = [q[0]]
    for i in range(1, len(q) - 1):
        a = q[i] - out[-1]
        b = q[i + 1] - q[i]
        turn = math.atan2(a[0] * b[1] - a[1] * b[0], a[0] * b[0] + a[1] * b[1])
        if abs(turn) >= MIN_TURN_RAD:
            out.append(q[i])
    out.append(q[-1])
    return np.array(out)


def turn_in_place(position: Any, theta_from: float, theta_to: float, robot: Robot) -> TurnInPlace:
    """Turn at rest from ``theta_from`` to ``theta_to`` by the shortest signed angle.

    Time-optimal and jerk-limited under :func:`trajopt.timing._stop_and_turn.turn_limits` (yaw rate,
    acceleration and jerk whose wheel motions stay within the translation limits), computed
    by ruckig.

    Parameters
    ----------
    position : array_like, shape (2,)
        Where the robot stands (m).
    theta_from, theta_to : float
        Headings (rad); the turn ends at ``theta_from`` plus the shortest signed angle to
        ``theta_to``.
    robot : Robot

    Returns
    -------
    TurnInPlace
        Of zero duration when the headings agree (within 1e-12 rad).
    """
    d = math.remainder(float(theta_to) - float(theta_from), 2.0 * math.pi)
    rows = np.zeros((0, 5))
    if abs(d) > 1e-12:
        rows = RestToRest(*turn_limits(robot)).solve(abs(d))
    return TurnInPlace(
        position=np.asarray(position, dtype=float),
        theta0=float(theta_from),
        sign=1.0 if d >= 0 else -1.0,
        rows=rows,
        robot=robot,
        stats={"turn_rad": d},
    )
