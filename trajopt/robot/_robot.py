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
* ``"ackermann"`` (car-like: a turning radius, reversing) is not supported yet; it is
  refused with a clear error.
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
Drive = Literal["differential", "omni"]
DRIVES = ("differential", "omni")


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
    drive : {"differential", "omni"}
        How the base moves (module docstring): a differential drive faces its direction of
        travel and turns in place at rest; an omnidirectional base turns independently of
        it. Default ``"differential"``.

    Raises
    ------
    InvalidInputError
        A limit is not a finite number > 0, only one of ``track_width`` and
        ``wheel_v_max`` is given, a bad footprint (non-convex, self-intersecting, fewer than
        3 vertices, the origin not inside, NaN), a radius contradicting it, or an unknown
        ``drive`` (``"ackermann"`` included: not supported yet).
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

    def __post_init__(self) -> None:
        if self.drive == "ackermann":
            raise InvalidInputError(
                "Robot.drive='ackermann' (a car-like robot: turning radius, reversing) is not "
                f"supported yet; use one of {DRIVES}"
            )
        if not (isinstance(self.drive, str) and self.drive in DRIVES):
            raise InvalidInputError(f"Robot.drive must be one of {DRIVES}, got {self.drive!r}")
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
