"""What a re-plan of an omnidirectional base continues: the body's orientation at the splice.

An omnidirectional base (``Robot(drive="omni")``) carries two motions
(:class:`~trajopt.motion.OmniTrajectory`): the translation along its path, which a re-plan
continues from its :class:`~trajopt.robot.State` (``theta`` is the direction of travel), and
the orientation of the body, which it continues from the angle, yaw rate and yaw
acceleration at the splice (:meth:`~trajopt.motion.TrajectoryChain.orientation_at`; the request's ``start_heading``,
``start_omega`` and ``start_alpha``). These helpers read both from the trajectory being
driven, whatever it is (an :class:`~trajopt.motion.OmniTrajectory`, a chain of a braking
re-plan, a plain :class:`~trajopt.Trajectory` whose orientation is its direction of
travel), and give a turn at rest that does not start at rest as a
:class:`~trajopt.motion._chain.TurnInPlace` (:func:`turn_piece`).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from trajopt.errors import InvalidInputError
from trajopt.motion import Orientation, PlanResult, Trajectory, TurnInPlace
from trajopt.robot import Robot
from trajopt.timing import start_rates, turn_limits


def course_orientation(trajectory: PlanResult, ts: float, robot: Robot) -> Orientation | None:
    """Return the orientation of an omni base driving a plain :class:`Trajectory` at ``ts``.

    Without its own orientation the body faces its direction of travel: the angle is the
    path's tangent ``theta``, the yaw rate ``kappa v`` and the yaw acceleration
    ``d(kappa v)/dt = kappa a + v^2 dkappa/ds``. ``None`` unless ``trajectory`` is a plain
    :class:`Trajectory` of an omnidirectional ``robot``, or when that rate and acceleration
    are beyond the yaw limits (a translation is not timed under them): a re-plan then
    starts its orientation at rest (a jump in yaw rate, as before omni re-plans continued
    it).
    """
    if not robot.drive.orients_body or not trajectory.single_curve:
        return None
    smp = trajectory.sample(np.array([ts]))
    theta, kappa = float(smp.theta[0]), float(smp.kappa[0])
    v, a = float(smp.v[0]), float(smp.a[0])
    omega = kappa * v
    alpha = kappa * a + v * v * _dkappa_ds(trajectory, float(smp.s[0]))
    try:
        omega, alpha = start_rates(omega, alpha, turn_limits(robot))
    except InvalidInputError:
        return None
    return Orientation(theta, omega, alpha)


def _dkappa_ds(trajectory: Trajectory, s: float) -> float:
    """Return the derivative of the path's signed curvature by arc length at ``s`` (1/m^2)."""
    path = trajectory.path
    u = float(trajectory._u_at_s(np.array(s)))
    d1, d2, d3 = (np.asarray(path(u, nu), dtype=float).reshape(2) for nu in (1, 2, 3))
    speed = math.hypot(d1[0], d1[1])
    if not speed > 0.0:
        return 0.0
    c12 = d1[0] * d2[1] - d1[1] * d2[0]
    c13 = d1[0] * d3[1] - d1[1] * d3[0]
    dk_du = c13 / speed**3 - 3.0 * c12 * float(d1 @ d2) / speed**5
    return dk_du / speed


def turn_piece(
    position: ArrayLike, theta: float, rows: np.ndarray, duration: float, robot: Robot
) -> TurnInPlace:
    """Return a turn at rest following orientation ``rows`` as a :class:`TurnInPlace`.

    Parameters
    ----------
    position : array_like, shape (2,)
        Where the robot stands (m).
    theta : float
        The orientation at the start (rad).
    rows : ndarray, shape (p, 5)
        The orientation's phases ``(t0, q, dq, ddq, jerk)`` from ``t0 = 0`` (s, rad, rad/s,
        rad/s^2, rad/s^3), ``q`` the angle (rad; its offset is ignored: the turn starts at
        ``theta``); they may start turning, and end at rest at ``duration``.
    duration : float
        The end of the last phase (s).
    robot : Robot
        The limits held.
    """
    rows = np.asarray(rows, dtype=float)
    dur = np.diff(np.append(rows[:, 0], duration))
    keep = dur > 0.0
    q = rows[:, 1] - rows[0, 1]
    last = rows[-1]
    d = dur[-1]
    q_end = float(q[-1] + d * (last[2] + d * (0.5 * last[3] + d * last[4] / 6.0)))
    sign = 1.0 if q_end >= 0.0 else -1.0
    turn = np.column_stack([dur, sign * q, sign * rows[:, 2], sign * rows[:, 3], sign * rows[:, 4]])
    return TurnInPlace(
        position=np.asarray(position, dtype=float),
        theta0=float(theta),
        sign=sign,
        rows=turn[keep] + 0.0,
        robot=robot,
        stats={"turn_rad": q_end},
    )
