"""The orientation of an omnidirectional base: a jerk-limited yaw profile beside the drive.

An omnidirectional robot (``Robot(drive="omni")``) follows its path whatever way it faces;
:func:`orient` gives it an orientation of its own, from a start to a goal heading, turned
while it drives:

* one **rest-to-rest 1-DoF ruckig profile** of the orientation by the shortest signed
  angle (``+pi`` for an exact half turn), under the yaw limits of
  :func:`trajopt.timing._stop_and_turn.turn_limits` (yaw rate, yaw acceleration and yaw
  jerk), computed with ruckig's position interface (never ``intermediate_positions``);
* **synchronised** with the translation of duration ``T``: ruckig's ``minimum_duration``
  is ``T``, so a turn that fits takes exactly ``T`` (and ends with the drive); a turn whose
  time-optimal duration ``T_rot`` is longer takes ``T_rot``, the robot standing at the
  path's end (``v = 0``) while it finishes turning. Only then does the motion last longer
  than the drive.

The profile is solved for a turn of 1 with every limit divided by the angle, then scaled
back: the same profile (durations are invariant under that scaling), with ruckig's absolute
position tolerance (about 1e-8) made relative, so even a turn of 1e-10 rad ends within a few
1e-16 of its angle.
"""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np

from trajopt._validation import number
from trajopt.errors import InvalidInputError, TimingError
from trajopt.motion._omni import OmniTrajectory
from trajopt.motion._trajectory import Trajectory
from trajopt.robot._robot import Robot
from trajopt.timing._stop_and_turn import turn_limits

#: A turn below this (rad) is no turn: the orientation stays at its start.
MIN_TURN_RAD = 1e-12
#: A turn this close to the drive's duration (relative, s) is taken to end with it.
_SYNC_RTOL = 1e-12
#: Translation limits :func:`orient` compares with the robot's.
_TRANSLATION_LIMITS = ("v_max", "a_max", "j_max", "a_lat_max")


def orient(
    translation: Trajectory, robot: Robot, theta_start: float, theta_goal: float
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

    Returns
    -------
    OmniTrajectory
        Lasts ``max(T, T_rot)`` (s); the orientation starts and ends at rest (rate and
        acceleration 0). ``stats`` holds the translation's statistics and
        ``orientation``: ``turn_rad`` (signed), ``turn_s`` (the profile's duration),
        ``turn_min_s`` (its time-optimal duration), ``translation_s`` (``T``), ``hold_s``
        (time standing at the end to finish turning), ``synchronized`` (the turn fits in
        ``T``), ``limits`` and ``compute_s``.

    Raises
    ------
    InvalidInputError
        ``translation`` not a :class:`Trajectory`, ``robot`` not an omnidirectional
        :class:`Robot`, a translation timed with higher limits than ``robot``'s, or a
        heading that is not a finite number (the message names the field and the value).
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
    if not isinstance(translation, Trajectory):
        raise InvalidInputError(
            f"translation must be a trajopt.Trajectory, got {type(translation).__name__}"
        )
    if not isinstance(robot, Robot):
        raise InvalidInputError(f"robot must be a trajopt.Robot, got {type(robot).__name__}")
    if robot.drive != "omni":
        raise InvalidInputError(
            "orient needs an omnidirectional robot: Robot.drive must be 'omni', got "
            f"{robot.drive!r} (a differential drive faces its direction of travel)"
        )
    for name in _TRANSLATION_LIMITS:
        have, allowed = getattr(translation.robot, name), getattr(robot, name)
        if have > allowed:
            raise InvalidInputError(
                f"translation was timed with {name}={have!r}, above the robot's {name}="
                f"{allowed!r}: time it with this robot"
            )
    h0 = number("theta_start", theta_start, unit="rad")
    h1 = number("theta_goal", theta_goal, unit="rad")
    delta = math.remainder(h1 - h0, 2.0 * math.pi)
    t_drive = translation.duration
    w_lim, al_lim, z_lim = turn_limits(robot)

    if abs(delta) <= MIN_TURN_RAD:
        rows, t_rot, t_min, h_end = np.zeros((0, 5)), 0.0, 0.0, h0
    else:
        rows, t_rot, t_min = _turn_rows(abs(delta), (w_lim, al_lim, z_lim), t_drive)
        sgn = 1.0 if delta > 0 else -1.0
        rows[:, 1] = h0 + sgn * rows[:, 1]
        rows[:, 2:] = sgn * rows[:, 2:] + 0.0  # no -0.0 in the exports
        h_end = h0 + delta
        if t_rot <= t_drive * (1.0 + _SYNC_RTOL) + _SYNC_RTOL:
            t_rot = min(t_rot, t_drive)
    if t_rot > t_drive and translation.v_end != 0.0:
        raise TimingError(
            f"the turn of {delta:.6g} rad takes {t_rot:.6g} s under the yaw limits, longer "
            f"than the translation ({t_drive:.6g} s), which ends moving at v_end = "
            f"{translation.v_end!r} m/s: the robot cannot stand at the end to finish it"
        )
    stats: dict[str, Any] = dict(translation.stats)
    stats["orientation"] = {
        "turn_rad": float(h_end - h0),
        "turn_s": float(t_rot),
        "turn_min_s": float(t_min),
        "translation_s": float(t_drive),
        "hold_s": float(max(0.0, t_rot - t_drive)),
        "synchronized": bool(t_rot <= t_drive),
        "limits": {"omega": w_lim, "alpha": al_lim, "zeta": z_lim},
        "compute_s": time.perf_counter() - t_start,
    }
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


def _turn_rows(
    d: float, limits: tuple[float, float, float], t_sync: float
) -> tuple[np.ndarray, float, float]:
    """Solve the rest-to-rest turn ``0 -> d`` (rad, d > 0) lasting at least ``t_sync`` (s).

    Returns the rows ``(t0, q, dq, ddq, jerk)`` of its non-empty phases (s, rad, rad/s,
    rad/s^2, rad/s^3), its duration (s) and its time-optimal duration (s). Solved for a
    turn of 1 with the limits divided by ``d`` (module docstring) and scaled back.
    """
    from ruckig import InputParameter, Result, Ruckig, RuckigError
    from ruckig import Trajectory as RuckigTrajectory

    w, al, z = limits
    inp = InputParameter(1)
    inp.current_position, inp.current_velocity, inp.current_acceleration = [0.0], [0.0], [0.0]
    inp.target_position, inp.target_velocity, inp.target_acceleration = [1.0], [0.0], [0.0]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [w / d], [al / d], [z / d]
    inp.min_velocity = [0.0]  # the turn never backs up
    otg = Ruckig(1)
    out = []
    for minimum in (None, t_sync):
        if minimum is not None:
            if minimum <= out[0].duration:  # the time-optimal turn does not fit: keep it
                break
            inp.minimum_duration = minimum
        traj = RuckigTrajectory(1)
        try:
            res = otg.calculate(inp, traj)
        except (RuntimeError, RuckigError) as exc:
            raise TimingError(f"ruckig found no turn of {d!r} rad: {exc}") from None
        if res not in (Result.Working, Result.Finished):
            raise TimingError(f"ruckig found no turn of {d!r} rad (result {res})")
        out.append(traj)
    t_min = float(out[0].duration)
    traj = out[-1]
    prof = traj.profiles[0][0]
    rows = []
    t = q = v = a = 0.0
    for ti, j in zip(prof.t, prof.j, strict=True):
        if ti > 0.0:
            rows.append((t, q, v, a, j))
            q += ti * (v + ti * (0.5 * a + ti * j / 6.0))
            v += ti * (a + 0.5 * j * ti)
            a += j * ti
            t += ti
    return np.array(rows, dtype=float) * [1.0, d, d, d, d], float(traj.duration), t_min
