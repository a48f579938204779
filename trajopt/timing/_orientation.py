"""The orientation of an omnidirectional base: a jerk-limited yaw profile beside the drive.

An omnidirectional robot (``Robot(drive=trajopt.Omni())``) follows its path whatever way it faces;
:func:`orient` gives it an orientation of its own, from a start to a goal heading, turned
while it drives:

* one **1-DoF ruckig profile** of the orientation by the shortest signed angle (``+pi``
  for an exact half turn), under the yaw limits of
  :func:`trajopt.timing._stop_and_turn.turn_limits` (yaw rate, yaw acceleration and yaw
  jerk), computed with ruckig's position interface (never ``intermediate_positions``). It
  ends at rest; it starts at rest too, or, for a re-plan that continues a turning body,
  with the yaw rate and acceleration the body has (``omega_start``, ``alpha_start``);
* **synchronised** with the translation of duration ``T``: ruckig's ``minimum_duration``
  is ``T``, so a turn that fits takes exactly ``T`` (and ends with the drive); a turn whose
  time-optimal duration ``T_rot`` is longer takes ``T_rot``, the robot standing at the
  path's end (``v = 0``) while it finishes turning. Only then does the motion last longer
  than the drive.

The profile is solved for a turn of 1 with every limit (and the start's rate and
acceleration) divided by the angle, then scaled back: the same profile (durations are
invariant under that scaling), with ruckig's absolute position tolerance (about 1e-8) made
relative, so even a turn of 1e-10 rad ends within a few 1e-16 of its angle. A start that
turns is scaled by the larger of the angle and the distance its rate carries it before it
can stop, so a start turning at the goal (an angle of 0) is solved too.

:func:`stop_orientation` is the other profile a re-plan needs: the time-optimal stop of a
turning body's yaw rate (ruckig's velocity interface), beside a translation that brakes.
"""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np

from trajopt.errors import InvalidInputError, TimingError
from trajopt.motion import OmniTrajectory, Trajectory
from trajopt.robot import Robot
from trajopt.timing._stop_and_turn import turn_limits
from trajopt.validation import number

#: A turn below this (rad) is no turn: the orientation stays at its start.
MIN_TURN_RAD = 1e-12
#: A turn this close to the drive's duration (relative, s) is taken to end with it.
_SYNC_RTOL = 1e-12
#: Relative slack on a turning start's yaw limits (the rounding of a sampled profile).
_START_RTOL = 1e-9
#: Translation limits :func:`orient` compares with the robot's.
_TRANSLATION_LIMITS = ("v_max", "a_max", "j_max", "a_lat_max")


def orient(
    translation: Trajectory,
    robot: Robot,
    theta_start: float,
    theta_goal: float,
    *,
    omega_start: float = 0.0,
    alpha_start: float = 0.0,
) -> OmniTrajectory:
    """Give an omnidirectional translation its own orientation profile.

    Parameters
    ----------
    translation : Trajectory
        The timed motion along the path (duration ``T``, s), e.g. from
        :func:`trajopt.time_parameterize` with the same ``robot``; its robot's translation
        limits (``v_max``, ``a_max``, ``j_max``, ``a_lat_max``) may not exceed ``robot``'s.
        When the turn does not fit in ``T`` it must end at rest (``v_end == 0``).
    robot : Robot
        An omnidirectional robot (``drive="omni"``); the orientation holds
        ``turn_limits(robot)`` (yaw rate rad/s, yaw acceleration rad/s^2, yaw jerk rad/s^3).
    theta_start, theta_goal : float
        Orientation at the start and the orientation asked at the end (rad). The profile
        turns by the shortest signed angle ``remainder(theta_goal - theta_start, 2 pi)``
        and ends at ``theta_start`` plus that angle (``theta_goal`` modulo ``2 pi``).
    omega_start, alpha_start : float, optional
        Yaw rate (rad/s) and yaw acceleration (rad/s^2) of the orientation at the start:
        a re-plan continues a body that is turning (default 0, at rest). Within the yaw
        limits: ``|omega_start| <= omega_lim``, ``|alpha_start| <= alpha_lim`` and
        ``|omega_start + alpha_start |alpha_start| / (2 zeta_lim)| <= omega_lim`` (the
        rate the acceleration carries it to before the jerk limit can undo it), each to a
        relative 1e-9 for the rounding of a sampled profile. The profile may then overshoot
        ``theta_goal`` and come back.

    Returns
    -------
    OmniTrajectory
        Lasts ``max(T, T_rot)`` (s); the orientation starts with ``omega_start`` and
        ``alpha_start`` and ends at rest (rate and acceleration 0). ``stats`` holds the
        translation's statistics and ``orientation``: ``turn_rad`` (signed), ``turn_s`` (the
        profile's duration), ``turn_min_s`` (its time-optimal duration), ``translation_s``
        (``T``), ``hold_s`` (time standing at the end to finish turning), ``synchronized``
        (the turn fits in ``T``), ``omega_start``, ``alpha_start``, ``limits`` and
        ``compute_s``.

    Raises
    ------
    InvalidInputError
        ``translation`` not a :class:`Trajectory`, ``robot`` not an omnidirectional
        :class:`Robot`, a translation timed with higher limits than ``robot``'s, a
        heading that is not a finite number, or a start rate or acceleration that is not
        finite or not within the yaw limits (the message names the field, the value and
        the rule).
    TimingError
        The turn outlasts a translation that ends moving (the robot cannot stand to finish
        it), or ruckig finds no profile (only for absurd magnitudes).

    Examples
    --------
    >>> from trajopt import Robot
    >>> from trajopt.geometry import BSplineCurve
    >>> from trajopt.timing import orient, time_parameterize
    >>> robot = Robot(drive="omni")
    >>> curve = BSplineCurve([0, 0, 0, 0, 1, 1, 1, 1], [(0, 0), (1, 0), (2, 0), (3, 0)], 3)
    >>> traj = orient(time_parameterize(curve, robot), robot, 0.0, 1.5)
    >>> traj.duration == traj.translation.duration, float(traj.sample(traj.duration).theta)
    (True, 1.5)
    """
    t_start = time.perf_counter()
    _check(translation, robot)
    h0 = number("theta_start", theta_start, unit="rad")
    h1 = number("theta_goal", theta_goal, unit="rad")
    limits = turn_limits(robot)
    w0, a0 = start_rates(omega_start, alpha_start, limits)
    delta = math.remainder(h1 - h0, 2.0 * math.pi)
    t_drive = translation.duration
    w_lim, al_lim, z_lim = limits

    if abs(delta) <= MIN_TURN_RAD and w0 == 0.0 and a0 == 0.0:
        rows, t_rot, t_min, h_end = np.zeros((0, 5)), 0.0, 0.0, h0
    else:
        if abs(delta) <= MIN_TURN_RAD:
            delta = 0.0  # a turning start at its goal: it stops and comes back
        sgn = -1.0 if delta < 0 or (delta == 0.0 and w0 < 0) else 1.0
        rows, t_rot, t_min = _turn_rows(abs(delta), sgn * w0, sgn * a0, limits, t_drive)
        rows[:, 1] = h0 + sgn * rows[:, 1]
        rows[:, 2:] = sgn * rows[:, 2:] + 0.0  # no -0.0 in the exports
        rows[0, 2:4] = (w0, a0)  # exactly the start's, whatever the mirroring rounded
        h_end = h0 + delta
        if t_rot <= t_drive * (1.0 + _SYNC_RTOL) + _SYNC_RTOL:
            t_rot = min(t_rot, t_drive)
    if t_rot > t_drive and translation.v_end != 0.0:
        raise TimingError(
            f"the turn of {delta:.6g} rad takes {t_rot:.6g} s under the yaw limits, longer "
            f"than the translation ({t_drive:.6g} s), which ends moving at v_end = "
            f"{translation.v_end!r} m/s: the robot cannot stand at the end to finish it"
        )
    return _omni(
        translation,
        robot,
        rows,
        (h0, h_end),
        (t_rot, t_min),
        (w0, a0),
        (w_lim, al_lim, z_lim),
        t_start,
    )


def start_rates(
    omega: float, alpha: float, limits: tuple[float, float, float]
) -> tuple[float, float]:
    """Return a turning start's yaw rate and acceleration, checked against the yaw limits.

    Parameters
    ----------
    omega, alpha : float
        Yaw rate (rad/s) and yaw acceleration (rad/s^2), named ``omega_start`` and
        ``alpha_start`` in the messages.
    limits : tuple of float
        ``(omega_lim, alpha_lim, zeta_lim)`` of :func:`~trajopt.timing._stop_and_turn.turn_limits`.

    Returns
    -------
    (float, float)
        ``omega`` and ``alpha`` as floats (``-0.0`` made ``0.0``).

    Raises
    ------
    InvalidInputError
        Not a finite number, or beyond a limit by more than a relative 1e-9 (the rules of
        :func:`orient`); the message names the field, the value and the rule.
    """
    w_lim, al_lim, z_lim = limits
    w = number("omega_start", omega, unit="rad/s") + 0.0
    al = number("alpha_start", alpha, unit="rad/s^2") + 0.0
    slack = 1.0 + _START_RTOL
    if abs(w) > w_lim * slack:
        raise InvalidInputError(
            f"omega_start must lie within the yaw rate limit, |omega_start| <= {w_lim:.6g} "
            f"rad/s, got {w!r}"
        )
    if abs(al) > al_lim * slack:
        raise InvalidInputError(
            f"alpha_start must lie within the yaw acceleration limit, |alpha_start| <= "
            f"{al_lim:.6g} rad/s^2, got {al!r}"
        )
    peak = w + al * abs(al) / (2.0 * z_lim)
    if abs(peak) > w_lim * slack:
        raise InvalidInputError(
            f"omega_start + alpha_start |alpha_start| / (2 zeta_lim) must lie within the yaw "
            f"rate limit {w_lim:.6g} rad/s (zeta_lim = {z_lim:.6g} rad/s^3: the rate the "
            f"acceleration reaches before the jerk limit undoes it), got {peak!r} from "
            f"omega_start={w!r}, alpha_start={al!r}"
        )
    return w, al


def stop_orientation(
    translation: Trajectory,
    robot: Robot,
    theta_start: float,
    *,
    omega_start: float,
    alpha_start: float = 0.0,
) -> OmniTrajectory:
    """Stop a turning body's yaw rate, time-optimally, beside a translation (a re-plan's brake).

    Parameters
    ----------
    translation : Trajectory
        The timed motion along the path (as :func:`orient`'s), e.g. a stop on the path.
    robot : Robot
        An omnidirectional robot; the stop holds ``turn_limits(robot)``.
    theta_start : float
        Orientation at the start (rad).
    omega_start, alpha_start : float
        Yaw rate (rad/s) and acceleration (rad/s^2) at the start, within the yaw limits
        (the rules of :func:`orient`).

    Returns
    -------
    OmniTrajectory
        The orientation from ``(theta_start, omega_start, alpha_start)`` to rest as soon as
        the yaw jerk and acceleration limits allow (ruckig's velocity interface); it ends
        wherever that leaves it (``theta_end``). Lasts ``max(T, T_stop)``; ``stats``: the
        translation's and ``orientation`` (as :func:`orient`'s, ``stop`` true).

    Raises
    ------
    InvalidInputError
        As :func:`orient`.
    TimingError
        The stop outlasts a translation that ends moving, or ruckig finds no profile.
    """
    t_start = time.perf_counter()
    _check(translation, robot)
    h0 = number("theta_start", theta_start, unit="rad")
    limits = turn_limits(robot)
    w0, a0 = start_rates(omega_start, alpha_start, limits)
    rows, t_rot = yaw_stop(w0, a0, limits)
    h_end = h0
    if rows.shape[0]:
        rows[:, 1] += h0
        t, q, v, a, j = rows[-1]
        d = t_rot - t
        h_end = float(q + d * (v + d * (0.5 * a + d * j / 6.0)))
    t_drive = translation.duration
    if t_rot > t_drive and translation.v_end != 0.0:
        raise TimingError(
            f"the yaw stop takes {t_rot:.6g} s, longer than the translation "
            f"({t_drive:.6g} s), which ends moving at v_end = {translation.v_end!r} m/s"
        )
    return _omni(
        translation, robot, rows, (h0, h_end), (t_rot, t_rot), (w0, a0), limits, t_start, stop=True
    )


def yaw_stop(
    omega: float, alpha: float, limits: tuple[float, float, float]
) -> tuple[np.ndarray, float]:
    """Stop a yaw rate ``omega`` (rad/s) and acceleration ``alpha`` (rad/s^2) time-optimally.

    Parameters
    ----------
    omega, alpha : float
        The start's rate and acceleration (within ``limits``; :func:`start_rates`).
    limits : tuple of float
        ``(omega_lim, alpha_lim, zeta_lim)`` (rad/s, rad/s^2, rad/s^3).

    Returns
    -------
    (ndarray, float)
        The rows ``(t0, q, dq, ddq, jerk)`` of its non-empty constant-jerk phases, the angle
        ``q`` from 0 (shape ``(p, 5)``, ``p == 0`` at rest), and its duration (s); at the
        end the rate and acceleration are 0.

    Raises
    ------
    TimingError
        Ruckig finds no profile.
    """
    if omega == 0.0 and alpha == 0.0:
        return np.zeros((0, 5)), 0.0
    from ruckig import ControlInterface, InputParameter

    w, al, z = limits
    inp = InputParameter(1)
    inp.control_interface = ControlInterface.Velocity
    inp.current_position, inp.current_velocity = [0.0], [float(omega)]
    inp.current_acceleration = [float(alpha)]
    inp.target_velocity, inp.target_acceleration = [0.0], [0.0]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [w], [al], [z]
    traj = _solve(inp, f"yaw stop from {omega!r} rad/s")
    rows = _profile_rows(traj, float(omega), float(alpha), 1.0)
    return rows, float(traj.duration)


def _check(translation: Any, robot: Any) -> None:
    """Raise :class:`InvalidInputError` unless ``robot`` may orient ``translation``."""
    if not isinstance(translation, Trajectory):
        raise InvalidInputError(
            f"translation must be a trajopt.Trajectory, got {type(translation).__name__}"
        )
    if not isinstance(robot, Robot):
        raise InvalidInputError(f"robot must be a trajopt.Robot, got {type(robot).__name__}")
    if not robot.drive.orients_body:
        raise InvalidInputError(
            "orient needs an omnidirectional robot: Robot.drive must be 'omni', got "
            f"{robot.drive.name!r} (a differential drive faces its direction of travel)"
        )
    for name in _TRANSLATION_LIMITS:
        have, allowed = getattr(translation.robot, name), getattr(robot, name)
        if have > allowed:
            raise InvalidInputError(
                f"translation was timed with {name}={have!r}, above the robot's {name}="
                f"{allowed!r}: time it with this robot"
            )


def _reach(w0: float, a0: float, limits: tuple[float, float, float]) -> float:
    """Return a scale (rad) of how far a start turning at ``w0``, ``a0`` goes on.

    ``w0`` (rad/s) and ``a0`` (rad/s^2): ``(|w0| + |a0| t) t`` with ``t = |w0| /
    alpha_lim + alpha_lim / zeta_lim + |a0| / zeta_lim`` (s), of the order of the time to
    stop: only the conditioning of the scaled problem depends on it (module docstring).
    """
    _, al, z = limits
    t = abs(w0) / al + al / z + abs(a0) / z
    return (abs(w0) + abs(a0) * t) * t


def _turn_rows(
    d: float, w0: float, a0: float, limits: tuple[float, float, float], t_sync: float
) -> tuple[np.ndarray, float, float]:
    """Solve the turn ``0 -> d`` (rad, d >= 0) from rate ``w0``, acceleration ``a0``, to rest.

    The turn lasts at least ``t_sync`` (s) when a profile of that duration exists (else the
    time-optimal one is kept). Returns the rows ``(t0, q, dq, ddq, jerk)`` of its non-empty
    phases (s, rad, rad/s, rad/s^2, rad/s^3), its duration (s) and its time-optimal duration
    (s). Solved with every quantity divided by a scale (``d`` from rest; module docstring)
    and scaled back; a turning start whose motion is so small beside the limits that ruckig
    fails on the scaled problem is solved unscaled. From rest the turn never backs up; from
    a turning start it may overshoot and come back.
    """
    at_rest = w0 == 0.0 and a0 == 0.0
    scales = [d] if at_rest else [max(d, _reach(w0, a0, limits)), 1.0]
    what = f"turn of {d!r} rad"
    for i, scale in enumerate(scales):
        inp = _turn_input(d, w0, a0, limits, scale)
        try:
            best = _solve(inp, what)
        except TimingError:
            if i + 1 == len(scales):
                raise
            continue  # a start whose motion is tiny beside the limits: try unscaled
        break
    t_min = float(best.duration)
    if t_sync > t_min:  # the time-optimal turn fits: stretch it to the drive's duration
        inp.minimum_duration = t_sync
        try:
            best = _solve(inp, what)
        except TimingError:
            if at_rest:  # a rest-to-rest turn of any duration exists
                raise
    rows = _land(_profile_rows(best, w0, a0, scale), float(best.duration), d)
    return rows, float(best.duration), t_min


def _turn_input(
    d: float, w0: float, a0: float, limits: tuple[float, float, float], scale: float
) -> Any:
    """Return ruckig's input of the turn ``0 -> d`` from ``(w0, a0)``, divided by ``scale``."""
    from ruckig import InputParameter

    w, al, z = limits
    at_rest = w0 == 0.0 and a0 == 0.0
    inp = InputParameter(1)
    inp.current_position = [0.0]
    inp.current_velocity, inp.current_acceleration = [w0 / scale], [a0 / scale]
    inp.target_position = [1.0 if at_rest else d / scale]
    inp.target_velocity, inp.target_acceleration = [0.0], [0.0]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [w / scale], [al / scale], [z / scale]
    inp.min_velocity = [0.0 if at_rest else -w / scale]  # from rest it never backs up
    return inp


def _solve(inp: Any, what: str) -> Any:
    """Run ruckig on ``inp`` (one degree of freedom); raise :class:`TimingError` if it fails."""
    from ruckig import Result, Ruckig, RuckigError
    from ruckig import Trajectory as RuckigTrajectory

    traj = RuckigTrajectory(1)
    try:
        res = Ruckig(1).calculate(inp, traj)
    except (RuntimeError, RuckigError) as exc:
        raise TimingError(f"ruckig found no {what}: {exc}") from None
    if res not in (Result.Working, Result.Finished):
        raise TimingError(f"ruckig found no {what} (result {res})")
    return traj


def _profile_rows(traj: Any, w0: float, a0: float, scale: float) -> np.ndarray:
    """Return the rows ``(t0, q, dq, ddq, jerk)`` of a 1-DoF ruckig trajectory, scaled back.

    Its brake pre-phases (when the start needs them) and its phases, with the jerks times
    ``scale``, integrated from ``q = 0`` at the exact start ``(w0, a0)`` (rad/s, rad/s^2);
    phases of zero duration are left out.
    """
    prof = traj.profiles[0][0]
    durations = np.array([*prof.brake.t, *prof.t], dtype=float)  # brake first
    jerks = np.array([*prof.brake.j, *prof.j], dtype=float) * scale
    keep = durations > 0.0
    return _integrate(durations[keep], jerks[keep], w0, a0)


def _integrate(durations: np.ndarray, jerks: np.ndarray, w0: float, a0: float) -> np.ndarray:
    """Return the rows ``(t0, q, dq, ddq, jerk)`` of constant-jerk phases from ``(0, w0, a0)``."""
    rows = []
    t = q = 0.0
    v, a = w0, a0
    for ti, j in zip(durations.tolist(), jerks.tolist(), strict=True):
        rows.append((t, q, v, a, j))
        q += ti * (v + ti * (0.5 * a + ti * j / 6.0))
        v += ti * (a + 0.5 * j * ti)
        a += j * ti
        t += ti
    return np.array(rows, dtype=float).reshape(-1, 5)


def _land(rows: np.ndarray, duration: float, target: float) -> np.ndarray:
    """Return ``rows`` ending exactly (to rounding) at ``target`` (rad) at rest.

    Ruckig holds the end position to about 1e-8 of the problem's scale, which a turning
    start can leave visible (a jump of a few 1e-9 rad where the orientation becomes
    ``theta_end``). The end state is linear in the phases' jerks at fixed durations, so the
    smallest change of the jerks (least norm) that moves the end to ``(target, 0, 0)`` is
    added and the phases integrated again: a relative change of the order of the error
    (the limits hold to that order).
    """
    if rows.shape[0] == 0:
        return rows
    t0 = rows[:, 0]
    dur = np.diff(np.append(t0, duration))
    rest = duration - t0 - dur  # time after each phase (s)
    w0, a0, jerks = float(rows[0, 2]), float(rows[0, 3]), rows[:, 4]
    m = np.vstack(
        [dur**3 / 6.0 + dur**2 * rest / 2.0 + dur * rest**2 / 2.0, dur**2 / 2.0 + dur * rest, dur]
    )
    free = np.array([w0 * duration + a0 * duration**2 / 2.0, w0 + a0 * duration, a0])
    err = np.array([target, 0.0, 0.0]) - (free + m @ jerks)
    if np.abs(err).max() <= 1e-14 * max(1.0, abs(target)):
        return rows
    fix = np.linalg.lstsq(m, err, rcond=None)[0]
    return _integrate(dur, jerks + fix, w0, a0)


def _omni(
    translation: Trajectory,
    robot: Robot,
    rows: np.ndarray,
    headings: tuple[float, float],
    times: tuple[float, float],
    start: tuple[float, float],
    limits: tuple[float, float, float],
    t_start: float,
    *,
    stop: bool = False,
) -> OmniTrajectory:
    """Return the :class:`OmniTrajectory` of an orientation profile, with its statistics.

    ``headings`` are the orientation at the start and the end (rad), ``times`` the profile's
    duration and its time-optimal duration (s), ``start`` the starting yaw rate and
    acceleration (rad/s, rad/s^2), ``limits`` the yaw limits, ``t_start`` when the
    computation began (``time.perf_counter``), ``stop`` whether the profile is a yaw stop.
    """
    h0, h_end = headings
    t_rot, t_min = times
    t_drive = translation.duration
    w_lim, al_lim, z_lim = limits
    orientation: dict[str, Any] = {
        "turn_rad": float(h_end - h0),
        "turn_s": float(t_rot),
        "turn_min_s": float(t_min),
        "translation_s": float(t_drive),
        "hold_s": float(max(0.0, t_rot - t_drive)),
        "synchronized": bool(t_rot <= t_drive),
        "omega_start": start[0],
        "alpha_start": start[1],
    }
    if stop:
        orientation["stop"] = True
    orientation["limits"] = {"omega": w_lim, "alpha": al_lim, "zeta": z_lim}
    orientation["compute_s"] = time.perf_counter() - t_start
    stats: dict[str, Any] = dict(translation.stats)
    stats["orientation"] = orientation
    return OmniTrajectory(
        translation=translation,
        robot=robot,
        rows=rows,
        turn_duration=t_rot,
        theta_start=h0,
        theta_end=h_end,
        stats=stats,
        steps=translation.steps,
    )
