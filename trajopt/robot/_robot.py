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

The drive (``drive``) is a record that owns its fields (:mod:`trajopt.drive`):
:class:`~trajopt.drive.Differential` (the default: faces its direction of travel, turns in
place at rest), :class:`~trajopt.drive.Omni` (turns its body independently of the direction
of travel) or :class:`~trajopt.drive.Ackermann` (a car: a turning radius, cusps where it
reverses). The strings ``"differential"``, ``"omni"`` and ``"ackermann"`` are accepted as
shorthands, a car's fields then given beside the string
(``Robot(drive="ackermann", min_turning_radius=0.5)``); they are refused with the other
drives. ``robot.drive`` is always the record.
"""

from __future__ import annotations

import dataclasses
import inspect
import math
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from trajopt.drive import CAR_FIELDS, Differential, Drive, as_drive, speed_cap
from trajopt.errors import InvalidInputError
from trajopt.robot._footprint import Footprint
from trajopt.validation import positive

#: The chapter robot's footprint radius (m): half of its 0.33 m width.
DEFAULT_RADIUS = 0.165
#: A drive's string shorthand (:func:`trajopt.drive.as_drive`).
DriveName = Literal["differential", "omni", "ackermann"]


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
    drive : Drive or {"differential", "omni", "ackermann"}
        How the base moves (module docstring): :class:`~trajopt.drive.Differential` (the
        default), :class:`~trajopt.drive.Omni` or :class:`~trajopt.drive.Ackermann`, or
        its name as a shorthand. The attribute is always the record. With the shorthand
        ``drive="ackermann"`` the keywords ``min_turning_radius`` (required), ``reverse``,
        ``wheelbase``, ``v_max_reverse`` and ``steer_rate_max`` are the fields of
        :class:`~trajopt.drive.Ackermann`, which the robot passes on to it; they are not
        attributes of the robot (``robot.drive`` holds them).

    Raises
    ------
    InvalidInputError
        A limit is not a finite number > 0, only one of ``track_width`` and
        ``wheel_v_max`` is given, a bad footprint (non-convex, self-intersecting, fewer than
        3 vertices, the origin not inside, NaN), a radius contradicting it, or an unknown
        ``drive`` (the message lists the drives); with ``drive="ackermann"``:
        ``min_turning_radius`` missing, not finite or <= 0, ``wheelbase``,
        ``v_max_reverse`` or ``steer_rate_max`` not finite or <= 0, ``reverse`` not a bool,
        ``steer_rate_max`` without ``wheelbase``; any of those fields given with another
        drive or beside a drive record.
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
    drive: Drive = Differential()  # noqa: RUF009 - a frozen record

    def __post_init__(self) -> None:
        object.__setattr__(self, "drive", as_drive(self.drive))
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
        with the terms the drive applies (:meth:`trajopt.drive.Drive.speed_terms`; the
        same numbers the timing's cap kernel receives): the wheel term only when
        ``track_width`` is set, and an omnidirectional base, which turns its body
        independently of the path, only ``min(v_max, sqrt(a_lat_max/|k|))``. ``k = 0``
        gives ``v_max``; an infinite or NaN curvature gives 0.

        Parameters
        ----------
        kappa : float or array_like, any shape
            Signed curvature (1/m).

        Returns
        -------
        float or ndarray, shape of ``kappa``
        """
        return speed_cap(self.drive.speed_terms(self), kappa)

    def to_dict(self) -> dict[str, Any]:
        """Return the fields as a plain dict (SI units: m, m/s, m/s^2, m/s^3, rad/s).

        ``drive`` is the drive's name and its own fields follow it (a car's), so that
        ``Robot(**robot.to_dict())`` rebuilds the robot.
        """
        out = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        out["footprint"] = None if self.footprint is None else self.footprint.to_list()
        out["drive"] = self.drive.name
        out.update(self.drive.fields())  # a car's fields after its drive
        return out


def _with_car_shorthand(cls: type[Robot]) -> None:
    """Let ``cls(drive="ackermann", min_turning_radius=...)`` pass a car's fields to its drive.

    The generated ``__init__`` takes the robot's own fields; this one also takes the car's
    fields as keywords (:data:`trajopt.drive.CAR_FIELDS`) and turns them, with the ``drive``
    string, into the :class:`~trajopt.drive.Ackermann` record (:func:`~trajopt.drive.as_drive`:
    refused beside another drive). A read of such a field on the robot says where it lives.
    """
    generated = cls.__init__
    names = [f.name for f in dataclasses.fields(cls) if f.init]
    at = names.index("drive")

    def __init__(self: Robot, *args: Any, **kwargs: Any) -> None:
        car = {k: kwargs.pop(k) for k in CAR_FIELDS if k in kwargs}
        if car:
            if len(args) > at:
                args = (*args[:at], as_drive(args[at], car), *args[at + 1 :])
            else:
                kwargs["drive"] = as_drive(kwargs.get("drive", Differential.name), car)
        generated(self, *args, **kwargs)

    sig = inspect.signature(generated)
    car_params = [
        inspect.Parameter(k, inspect.Parameter.KEYWORD_ONLY, default=v)
        for k, v in CAR_FIELDS.items()
    ]
    __init__.__signature__ = sig.replace(parameters=[*sig.parameters.values(), *car_params])
    __init__.__doc__ = generated.__doc__
    cls.__init__ = __init__

    def moved(name: str) -> property:
        def get(self: Robot) -> Any:
            raise AttributeError(
                f"Robot.{name}: a car's fields belong to its drive, read robot.drive.{name} "
                f"(robot.drive is {self.drive!r})"
            )

        return property(get, doc=f"Not a robot field: ``robot.drive.{name}`` (a car's).")

    for name in CAR_FIELDS:
        setattr(cls, name, moved(name))


_with_car_shorthand(Robot)


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
