"""The records of sampled motion: what a trajectory's ``sample`` returns, and their units.

:class:`TrajectorySample` (a differential drive's or a disc's motion), :class:`CarSample`
(a car-like robot's: signed speed, direction of travel, steering) and :class:`OmniSample`
(an omnidirectional base's: course and body velocities), built by :func:`make_sample`.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from trajopt.robot import Robot
from trajopt.validation import readonly

#: Unit of every sampled quantity.
SAMPLE_UNITS: dict[str, str] = {
    "t": "s",
    "x": "m",
    "y": "m",
    "theta": "rad",
    "v": "m/s",
    "omega": "rad/s",
    "a": "m/s^2",
    "jerk": "m/s^3",
    "a_lat": "m/s^2",
    "kappa": "1/m",
    "s": "m",
    "v_left": "m/s",
    "v_right": "m/s",
    "course": "rad",
    "vx": "m/s",
    "vy": "m/s",
    "v_body_x": "m/s",
    "v_body_y": "m/s",
    "direction": "1",
    "steer": "rad",
    "steer_rate": "rad/s",
}


class TrajectorySample(NamedTuple):
    """Samples of a :class:`Trajectory`; every array has the shape of the query times.

    The wheel speeds are optional (``None`` without a differential drive's track width;
    :meth:`as_dict` and the exports leave them out). An omnidirectional motion's samples are
    an :class:`OmniSample`.

    Attributes
    ----------
    t : time (s), clipped to ``[0, duration]``
    x, y : position (m)
    theta : heading from the curve's tangent, continuous and unwrapped (rad); for an
        omnidirectional motion the orientation of the body, independent of the path
    v : speed along the path ``ds/dt`` (m/s)
    omega : yaw rate ``kappa * v`` (rad/s); ``d theta / dt`` in turns and for an
        omnidirectional motion
    a : tangential acceleration (m/s^2)
    jerk : tangential jerk (m/s^3)
    a_lat : signed lateral acceleration ``kappa * v^2`` (m/s^2)
    kappa : signed curvature (1/m)
    s : arc length travelled (m)
    v_left, v_right : wheel speeds ``v * (1 -+ kappa * track_width / 2)`` (m/s), or ``None``
        when the robot has no ``track_width`` or is omnidirectional
    """

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    theta: np.ndarray
    v: np.ndarray
    omega: np.ndarray
    a: np.ndarray
    jerk: np.ndarray
    a_lat: np.ndarray
    kappa: np.ndarray
    s: np.ndarray
    v_left: np.ndarray | None = None
    v_right: np.ndarray | None = None

    def as_dict(self) -> dict[str, np.ndarray]:
        """Return the arrays by name (the optional fields only when present)."""
        return {k: v for k, v in self._asdict().items() if v is not None}


class CarSample(NamedTuple):
    """Samples of a car-like robot's motion (``Robot(drive="ackermann")``).

    The fields of :class:`TrajectorySample`, then the direction of travel and the steering.
    Backwards (``direction = -1``) ``v``, ``a`` and ``jerk`` are signed (``v <= 0``),
    ``theta`` is the body's orientation (the path's tangent ``+ pi``), ``kappa`` the body's
    signed curvature ``omega / v`` and ``a_lat = omega * v``; the velocity is
    ``v * (cos theta, sin theta)`` in both directions; ``s`` is the distance travelled.

    Attributes
    ----------
    t, x, y, theta, v, omega, a, jerk, a_lat, kappa, s, v_left, v_right
        As :class:`TrajectorySample` (the wheel speeds are the rear wheels').
    direction : ``+1`` forwards, ``-1`` backwards
    steer : steering angle ``atan(wheelbase * kappa)`` (rad), or ``None`` without a
        ``wheelbase``
    steer_rate : its rate ``d steer / dt`` (rad/s), or ``None`` without a ``wheelbase``
    """

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    theta: np.ndarray
    v: np.ndarray
    omega: np.ndarray
    a: np.ndarray
    jerk: np.ndarray
    a_lat: np.ndarray
    kappa: np.ndarray
    s: np.ndarray
    v_left: np.ndarray | None = None
    v_right: np.ndarray | None = None
    direction: np.ndarray | None = None
    steer: np.ndarray | None = None
    steer_rate: np.ndarray | None = None

    def as_dict(self) -> dict[str, np.ndarray]:
        """Return the arrays by name (the optional fields only when present)."""
        return {k: v for k, v in self._asdict().items() if v is not None}


class OmniSample(NamedTuple):
    """Samples of an :class:`~trajopt.motion.OmniTrajectory` (omnidirectional base).

    The fields of :class:`TrajectorySample` (``theta`` is the body's orientation and
    ``omega`` its rate; no wheel speeds), then the direction of travel and the velocities.

    Attributes
    ----------
    t, x, y, theta, v, omega, a, jerk, a_lat, kappa, s
        As :class:`TrajectorySample`.
    course : direction of travel, the path's tangent, continuous and unwrapped (rad)
    vx, vy : world-frame velocity ``v * (cos, sin)(course)`` (m/s)
    v_body_x, v_body_y : body-frame velocity, ``(vx, vy)`` rotated by ``-theta`` (m/s): what
        an omnidirectional base is commanded with
    """

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    theta: np.ndarray
    v: np.ndarray
    omega: np.ndarray
    a: np.ndarray
    jerk: np.ndarray
    a_lat: np.ndarray
    kappa: np.ndarray
    s: np.ndarray
    course: np.ndarray
    vx: np.ndarray
    vy: np.ndarray
    v_body_x: np.ndarray
    v_body_y: np.ndarray

    def as_dict(self) -> dict[str, np.ndarray]:
        """Return the arrays by name."""
        return dict(self._asdict())


def make_sample(robot: Robot, **arrays: np.ndarray) -> TrajectorySample | CarSample:
    """Return a :class:`TrajectorySample` (:class:`CarSample` for a car) of read-only ``arrays``.

    ``arrays`` holds ``t``, ``x``, ``y``, ``theta``, ``v``, ``omega``, ``a``, ``jerk``,
    ``a_lat``, ``kappa`` and ``s`` (and may hold the other optional fields of
    :class:`TrajectorySample`); the wheel speeds ``v -+ omega * track_width / 2`` are added
    when the robot is a differential drive (or a car-like robot: its rear wheels) with a
    track width, and a car-like robot's steering angle ``atan(wheelbase * kappa)`` when it
    has a wheelbase (with ``steer_rate``, given as ``dkappa_dt``: ``d kappa / dt`` (1/(m s))).
    """
    robot.drive.sample_fields(robot, arrays, arrays.pop("dkappa_dt", None))
    kind = CarSample if robot.drive.signed_speed else TrajectorySample
    return kind(**{k: readonly(x) for k, x in arrays.items()})
