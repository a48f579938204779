"""The robot's size and motion limits, and the curvature-dependent speed limit they imply.

The default :class:`Robot` is the chapter's robot, the National Instruments Robotics
Starter Kit 2.0 ("DaNI"), a two-wheel differential drive 0.33 m wide (so the footprint
radius used for obstacle inflation is 0.165 m). The kinematic limits are not published by
the vendor; the defaults are plausible, conservative values for its 12 V geared motors
and 10 cm wheels:

========================  =========  =========================================================
field                     default    meaning
========================  =========  =========================================================
``radius``                0.165 m    footprint radius (half of the 0.33 m width)
``v_max``                 0.5 m/s    forward speed
``a_max``                 0.5 m/s^2  tangential acceleration (both signs)
``j_max``                 2.0 m/s^3  tangential jerk (both signs)
``a_lat_max``             0.5 m/s^2  lateral (centripetal) acceleration ``kappa * v^2``
``omega_max``             1.5 rad/s  yaw rate ``kappa * v``
``track_width``           0.28 m     distance between the two drive wheels
``wheel_v_max``           0.6 m/s    speed of either wheel ``v * (1 +- kappa * track_width/2)``
``drive``                 differential  how the base moves (below)
========================  =========  =========================================================

Drive types (``drive``):

* ``"differential"`` (the default): the robot faces its direction of travel; it can turn in
  place at rest, so a required start or goal heading is met by turning there when no curve
  can leave (arrive) along it.
* ``"omni"`` (mecanum or omni-wheel bases): the orientation is independent of the direction
  of travel. The path is planned as for a disc (with a footprint: its circumscribed disc,
  which holds it in every orientation) and the orientation is its own jerk-limited profile,
  turned while driving. ``omega_max`` bounds the yaw rate of that profile and not the
  speed along a curve, and the wheel terms (``track_width``, ``wheel_v_max``) of a
  differential drive do not apply to its speed cap.
* ``"ackermann"`` (car-like: forklifts, tuggers, carts): it faces its direction of travel
  (forwards, or backwards when ``reverse``), cannot turn in place and turns no tighter than
  ``min_turning_radius`` (required). Plans are Hybrid-A* paths (:func:`astar.find_pose_path`)
  split at their cusps, each segment a certified curve with ``|kappa| <= 1 / R``, timed from
  rest to rest (:mod:`trajopt.planning._car`). Its own fields:

  =======================  =========  ======================================================
  field                    default    meaning
  =======================  =========  ======================================================
  ``min_turning_radius``   (required) ``R`` (m): the path's curvature is at most ``1/R``
  ``reverse``              True       may drive backwards (Reeds-Shepp); False: forwards
                                      only (Dubins)
  ``wheelbase``            None       ``L`` (m): samples then carry the steering angle
                                      ``atan(L kappa)``
  ``v_max_reverse``        None       backwards speed limit (m/s); ``None`` is ``v_max``
  ``steer_rate_max``       None       steering-angle rate limit (rad/s), needs ``wheelbase``;
                                      held by the timing (:meth:`Robot.steer_speed_cap`)
  =======================  =========  ======================================================

  These fields are refused with the other drives. The yaw-rate, lateral-acceleration and
  (rear) wheel-speed caps of a differential drive apply as they are.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from trajopt._validation import positive
from trajopt.errors import InvalidInputError
from trajopt.robot._footprint import Footprint

#: The chapter robot's footprint radius (m): half of its 0.33 m width.
DEFAULT_RADIUS = 0.165
#: How a robot's base moves (:class:`Robot`'s ``drive``).
Drive = Literal["differential", "omni", "ackermann"]
DRIVES = ("differential", "omni", "ackermann")
#: The fields only a car-like robot (``drive="ackermann"``) takes, and their "unset" values.
CAR_FIELDS = {
    "min_turning_radius": None,
    "reverse": True,
    "wheelbase": None,
    "v_max_reverse": None,
    "steer_rate_max": None,
}


@dataclass(frozen=True, slots=True)
class Robot:
    """Size and motion limits of a planar mobile robot (all SI units).

    Parameters
    ----------
    radius : float, optional
        Footprint radius (m) of a disc robot, used to inflate obstacles; default 0.165. With
        a ``footprint`` it becomes the footprint's circumscribed radius (leave it at its
        default; another value is an error): every stage that models the robot as a disc
        then keeps the whole footprint clear.
    v_max : float
        Maximum forward speed (m/s).
    a_max : float
        Maximum tangential acceleration and deceleration (m/s^2).
    j_max : float
        Maximum tangential jerk (m/s^3).
    a_lat_max : float
        Maximum lateral acceleration ``|kappa| v^2`` (m/s^2).
    omega_max : float
        Maximum yaw rate ``|kappa| v`` (rad/s).
    track_width : float or None
        Distance between the drive wheels of a differential drive (m); give it together
        with ``wheel_v_max`` or leave both ``None``.
    wheel_v_max : float or None
        Maximum speed of either wheel (m/s).
    footprint : Footprint or array_like, shape (k, 2), optional
        A convex footprint in the robot frame (x forward, metres, the rotation centre at
        the origin, strictly inside); see :meth:`rectangle`.
    drive : {"differential", "omni", "ackermann"}
        How the base moves (module docstring): a differential drive faces its direction of
        travel and turns in place at rest; an omnidirectional base turns independently of
        it; a car-like robot (``"ackermann"``) faces its direction of travel (or its reverse)
        and turns no tighter than ``min_turning_radius``. Default ``"differential"``.
    min_turning_radius : float or None
        A car-like robot's minimum turning radius ``R`` (m), finite and > 0; required with
        ``drive="ackermann"``, refused with the other drives.
    reverse : bool
        Whether a car-like robot may drive backwards (default True); ``False`` gives
        forward-only (Dubins) plans.
    wheelbase : float or None
        A car-like robot's wheelbase ``L`` (m, > 0): samples then carry the steering angle
        ``atan(L kappa)`` (rad) and its rate.
    v_max_reverse : float or None
        A car-like robot's speed limit backwards (m/s, > 0); ``None`` is ``v_max``.
    steer_rate_max : float or None
        A car-like robot's steering-angle rate limit (rad/s, > 0), held by the timing as a
        speed cap (:meth:`steer_speed_cap`); needs ``wheelbase``.

    Raises
    ------
    InvalidInputError
        A limit is not a finite number > 0, only one of ``track_width`` and
        ``wheel_v_max`` is given, a bad footprint (non-convex, self-intersecting, fewer than
        3 vertices, the origin not inside, NaN), a radius contradicting it, or an unknown
        ``drive``; with ``drive="ackermann"``: ``min_turning_radius`` missing, not finite
        or <= 0, ``wheelbase``, ``v_max_reverse`` or ``steer_rate_max`` not finite or <= 0,
        ``reverse`` not a bool, ``steer_rate_max`` without ``wheelbase``; any of those
        fields given with another drive.
    """

    radius: float = 0.165
    v_max: float = 0.5
    a_max: float = 0.5
    j_max: float = 2.0
    a_lat_max: float = 0.5
    omega_max: float = 1.5
    track_width: float | None = 0.28
    wheel_v_max: float | None = 0.6
    footprint: Footprint | None = None
    drive: Drive = "differential"
    min_turning_radius: float | None = None
    reverse: bool = True
    wheelbase: float | None = None
    v_max_reverse: float | None = None
    steer_rate_max: float | None = None

    def __post_init__(self) -> None:
        if not (isinstance(self.drive, str) and self.drive in DRIVES):
            raise InvalidInputError(f"Robot.drive must be one of {DRIVES}, got {self.drive!r}")
        self._check_car_fields()
        fp = self.footprint
        if fp is not None and not isinstance(fp, Footprint):
            try:
                fp = Footprint(np.asarray(fp, dtype=float))
            except (TypeError, ValueError) as exc:
                raise InvalidInputError(f"Robot.footprint: {exc}") from None
            object.__setattr__(self, "footprint", fp)
        if fp is not None:
            r_c = fp.circumscribed_radius
            given = self.radius != DEFAULT_RADIUS  # the default stands for "unset"
            if given and abs(float(self.radius) - r_c) > 1e-12 * max(1.0, r_c):
                raise InvalidInputError(
                    f"Robot.radius={self.radius!r} contradicts the footprint, whose "
                    f"circumscribed radius is {r_c:.6g} m; leave radius unset with a footprint"
                )
            object.__setattr__(self, "radius", r_c)
        for name in ("radius", "v_max", "a_max", "j_max", "a_lat_max", "omega_max"):
            object.__setattr__(self, name, _positive(name, getattr(self, name)))
        if (self.track_width is None) != (self.wheel_v_max is None):
            raise InvalidInputError(
                "track_width and wheel_v_max must be given together or both be None, got "
                f"track_width={self.track_width!r}, wheel_v_max={self.wheel_v_max!r}"
            )
        if self.track_width is not None:
            object.__setattr__(self, "track_width", _positive("track_width", self.track_width))
            object.__setattr__(self, "wheel_v_max", _positive("wheel_v_max", self.wheel_v_max))

    def _check_car_fields(self) -> None:
        """Validate the fields of a car-like robot (and refuse them with another drive)."""
        if self.drive != "ackermann":
            given = {
                k: getattr(self, k)
                for k, unset in CAR_FIELDS.items()
                if getattr(self, k) is not unset and getattr(self, k) != unset
            }
            if given:
                what = ", ".join(f"{k}={v!r}" for k, v in given.items())
                raise InvalidInputError(
                    f"Robot: {what} apply only to a car-like robot (drive='ackermann'), "
                    f"got drive={self.drive!r}"
                )
            return
        if self.min_turning_radius is None:
            raise InvalidInputError(
                "Robot.min_turning_radius is required with drive='ackermann' (a car-like "
                "robot's minimum turning radius, finite and > 0 m), got None"
                + ("" if self.wheelbase is None else f" (with wheelbase={self.wheelbase!r} m)")
            )
        if not isinstance(self.reverse, bool | np.bool_):
            raise InvalidInputError(f"Robot.reverse must be True or False, got {self.reverse!r}")
        object.__setattr__(self, "reverse", bool(self.reverse))
        object.__setattr__(
            self,
            "min_turning_radius",
            positive("Robot.min_turning_radius", self.min_turning_radius, "m"),
        )
        for name, unit in (
            ("wheelbase", "m"),
            ("v_max_reverse", "m/s"),
            ("steer_rate_max", "rad/s"),
        ):
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, positive(f"Robot.{name}", value, unit))
        if self.steer_rate_max is not None and self.wheelbase is None:
            raise InvalidInputError(
                f"Robot.steer_rate_max={self.steer_rate_max!r} rad/s needs a wheelbase (the "
                "steering angle is atan(wheelbase * kappa)), got wheelbase=None"
            )

    @property
    def v_max_backwards(self) -> float:
        """Speed limit backwards (m/s): ``v_max_reverse``, or ``v_max`` when it is unset."""
        return self.v_max if self.v_max_reverse is None else float(self.v_max_reverse)

    def steer_speed_cap(
        self, kappa: np.ndarray | float, dkappa_ds: np.ndarray | float
    ) -> np.ndarray | float:
        """Speed limit (m/s) that holds the steering-angle rate of a car-like robot.

        The steering angle is ``delta = atan(L kappa)`` (``L`` the wheelbase), so its rate
        along a path is ``d delta / dt = L (d kappa / ds) v / (1 + (L kappa)^2)``, and
        ``|d delta / dt| <= steer_rate_max`` holds exactly when
        ``v <= steer_rate_max (1 + (L kappa)^2) / (L |d kappa / ds|)``. Infinite where
        ``d kappa / ds = 0`` or without a steering-rate limit.

        Parameters
        ----------
        kappa, dkappa_ds : float or array_like, broadcastable
            Curvature (1/m) and its derivative along the arc length (1/m^2).

        Returns
        -------
        float or ndarray, the broadcast shape
        """
        k = np.asarray(kappa, dtype=float)
        dk = np.abs(np.asarray(dkappa_ds, dtype=float))
        if self.steer_rate_max is None or self.wheelbase is None:
            cap = np.full(np.broadcast(k, dk).shape, np.inf)
        else:
            wb = self.wheelbase
            with np.errstate(divide="ignore", invalid="ignore"):
                cap = self.steer_rate_max * (1.0 + (wb * k) ** 2) / (wb * dk)
            cap = np.where(np.isnan(cap), 0.0, cap)
        return float(cap) if cap.ndim == 0 else cap

    @classmethod
    def rectangle(
        cls, length: float, width: float, rear_offset: float | None = None, **limits: Any
    ) -> Robot:
        """Return a robot with a rectangular footprint (:meth:`Footprint.rectangle`).

        ``rear_offset`` is the distance (m) from the rotation centre back to the rear edge
        (default ``length / 2``); ``limits`` are the other fields (``v_max``, ...).
        """
        return cls(footprint=Footprint.rectangle(length, width, rear_offset), **limits)

    @property
    def width(self) -> float:
        """Footprint diameter ``2 * radius`` (m): the disc every planner stage keeps clear."""
        return 2.0 * self.radius

    @property
    def inscribed_radius(self) -> float:
        """Largest disc about the rotation centre inside the footprint (m)."""
        return self.radius if self.footprint is None else self.footprint.inscribed_radius

    @property
    def circumscribed_radius(self) -> float:
        """Smallest disc about the rotation centre containing the footprint (m)."""
        return self.radius if self.footprint is None else self.footprint.circumscribed_radius

    def speed_cap(self, kappa: np.ndarray | float) -> np.ndarray | float:
        """Curvature-dependent speed limit (m/s).

        ``min(v_max, sqrt(a_lat_max/|k|), omega_max/|k|, wheel_v_max/(1 + |k| track_width/2))``
        (the wheel term only when ``track_width`` is set). An omnidirectional base
        (``drive="omni"``) turns its body independently of the path, so only
        ``min(v_max, sqrt(a_lat_max/|k|))`` applies to it. ``k = 0`` gives ``v_max``; an
        infinite or NaN curvature gives 0.

        Parameters
        ----------
        kappa : float or array_like, any shape
            Signed curvature (1/m).

        Returns
        -------
        float or ndarray, shape of ``kappa``
        """
        k = np.abs(np.asarray(kappa, dtype=float))
        k = np.where(np.isnan(k), np.inf, k)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            cap = np.minimum(self.v_max, np.sqrt(self.a_lat_max / k))
            if self.drive == "omni":
                cap = np.where(np.isinf(k), 0.0, cap)
                return float(cap) if cap.ndim == 0 else cap
            cap = np.minimum(cap, self.omega_max / k)
            if self.track_width is not None:
                cap = np.minimum(cap, self.wheel_v_max / (1.0 + 0.5 * self.track_width * k))
        cap = np.where(np.isinf(k), 0.0, cap)
        if cap.ndim == 0:
            return float(cap)
        return cap

    def to_dict(self) -> dict[str, Any]:
        """Return the fields as a plain dict (SI units: m, m/s, m/s^2, m/s^3, rad/s)."""
        out = {k: getattr(self, k) for k in self.__dataclass_fields__}
        if self.drive != "ackermann":  # the car's fields only for a car (older files unchanged)
            for k in CAR_FIELDS:
                del out[k]
        out["footprint"] = None if self.footprint is None else self.footprint.to_list()
        return out


def _positive(name: str, value: Any) -> float:
    return positive(f"Robot.{name}", value)


def avoidance_width(width_m: float, resolution_m: float) -> int:
    """Return the chapter's avoidance-area width ``W`` in cells.

    The fewest whole cells that cover the robot's width (``ceil(width / resolution)``, with a
    1e-9 tolerance for round-off so that 0.33 m on 0.03 m cells is 11), and at least 1.

    Parameters
    ----------
    width_m : float
        Robot width (m), > 0.
    resolution_m : float
        Cell size (m), > 0.
    """
    w = positive("width_m", width_m, "m")
    res = positive("resolution_m", resolution_m, "m")
    return max(1, math.ceil(w / res - 1e-9))
