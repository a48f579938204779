"""The three drives as frozen, validated records: :class:`Differential`, :class:`Omni`, :class:`Ackermann`.

Each record owns its fields and answers the :class:`~trajopt.drive.Drive` protocol. Their
kinematic answers (speed-cap terms, steering, sample fields) need nothing above
:mod:`trajopt.drive`; their :meth:`plan` and :meth:`replan` compose the shared stages
through the :mod:`trajopt.planning` and :mod:`trajopt.replan` faces, which are imported
when a plan is asked for (they sit above the robot, which holds its drive).

The strings ``"differential"``, ``"omni"`` and ``"ackermann"`` stay accepted wherever a drive
is (:func:`as_drive`), with the car's fields given beside the string to ``Robot``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from trajopt.drive._protocol import Drive, SpeedTerms, Steering
from trajopt.errors import InvalidInputError
from trajopt.validation import positive

if TYPE_CHECKING:  # pragma: no cover
    from trajopt.motion import PlanResult
    from trajopt.planning import PlannerCaches, PlannerOptions, PlanRequest, WarmStart
    from trajopt.robot import Robot


def _wheel_speeds(robot: Robot, arrays: dict[str, np.ndarray]) -> None:
    """Add ``v_left``/``v_right`` = ``v -+ omega * track_width / 2`` when there is a track."""
    if robot.track_width is not None:
        half = 0.5 * robot.track_width
        arrays["v_left"] = arrays["v"] - arrays["omega"] * half
        arrays["v_right"] = arrays["v"] + arrays["omega"] * half


def _turning_terms(robot: Robot) -> SpeedTerms:
    """Speed-cap terms of a base that faces its direction of travel (yaw and wheel terms)."""
    tw = 0.0 if robot.track_width is None else float(robot.track_width)
    wv = np.inf if robot.wheel_v_max is None else float(robot.wheel_v_max)
    return SpeedTerms(robot.v_max, robot.a_lat_max, float(robot.omega_max), tw, wv)


class _Planned:
    """The plan and re-plan of a drive that plans through the disc stages (not a car)."""

    def replan(
        self,
        options: PlannerOptions,
        caches: PlannerCaches,
        trajectory: PlanResult,
        ts: float,
        goal: Sequence[float],
        *,
        goal_heading: float | None,
        v_end: float,
        reuse: bool,
        brake_after_s: float | None,
    ) -> PlanResult:
        """Keep the rest, plan from the moving state, or brake, turn and go (:mod:`trajopt.replan`)."""
        from trajopt.replan import replan_moving

        return replan_moving(
            options,
            caches,
            trajectory,
            ts,
            goal,
            goal_heading=goal_heading,
            v_end=v_end,
            reuse=reuse,
            brake_after_s=brake_after_s,
        )


@dataclass(frozen=True, slots=True)
class Differential(_Planned):
    """A differential drive: it faces its direction of travel and turns in place at rest.

    A required start or goal heading is met by turning in place there when no curve can
    leave (arrive) along it, or where that is faster. The speed cap holds the yaw rate
    ``|kappa| v <= omega_max`` and, with a track width, the wheel speeds (:class:`trajopt.Robot`).
    """

    name: ClassVar[str] = "differential"
    turns_in_place: ClassVar[bool] = True
    orients_body: ClassVar[bool] = False
    signed_speed: ClassVar[bool] = False

    def speed_terms(self, robot: Robot) -> SpeedTerms:
        """Every term: speed, lateral acceleration, yaw rate and the wheels (with a track)."""
        return _turning_terms(robot)

    @property
    def steering(self) -> None:
        """No steering geometry."""
        return None

    def sample_fields(
        self, robot: Robot, arrays: dict[str, np.ndarray], dkappa_dt: np.ndarray | None
    ) -> None:
        """Add the wheel speeds (with a track width)."""
        _wheel_speeds(robot, arrays)

    def fields(self) -> dict[str, Any]:
        """No fields of its own."""
        return {}

    def plan(
        self,
        options: PlannerOptions,
        caches: PlannerCaches,
        request: PlanRequest,
        warm: WarmStart | None,
    ) -> PlanResult:
        """Plan with the disc (or footprint ladder) stages; pose to pose with turns in place."""
        from trajopt.planning import plan_turning

        return plan_turning(options, caches, request, warm)


@dataclass(frozen=True, slots=True)
class Omni(_Planned):
    """An omnidirectional base (mecanum or omni wheels): its orientation is its own motion.

    The path is planned as for a disc (with a footprint: its circumscribed disc, which holds
    it in every orientation) and the orientation is its own jerk-limited profile turned
    while driving (:func:`trajopt.timing.orient`). ``Robot.omega_max`` bounds the yaw rate
    of that profile, not the speed along a curve, and the wheel terms of a differential
    drive do not apply to its speed cap.
    """

    name: ClassVar[str] = "omni"
    turns_in_place: ClassVar[bool] = True
    orients_body: ClassVar[bool] = True
    signed_speed: ClassVar[bool] = False

    def speed_terms(self, robot: Robot) -> SpeedTerms:
        """Speed and lateral acceleration only (no yaw-rate or wheel term)."""
        return SpeedTerms(robot.v_max, robot.a_lat_max, np.inf, 0.0, np.inf)

    @property
    def steering(self) -> None:
        """No steering geometry."""
        return None

    def sample_fields(
        self, robot: Robot, arrays: dict[str, np.ndarray], dkappa_dt: np.ndarray | None
    ) -> None:
        """Nothing: the path's samples carry no wheel speeds (the body turns on its own)."""

    def fields(self) -> dict[str, Any]:
        """No fields of its own."""
        return {}

    def plan(
        self,
        options: PlannerOptions,
        caches: PlannerCaches,
        request: PlanRequest,
        warm: WarmStart | None,
    ) -> PlanResult:
        """Plan the disc's path with free headings, then the orientation turned while driving."""
        from trajopt.planning import plan_omni

        return plan_omni(options, caches, request, warm)


#: The fields only a car-like robot takes, and their "unset" values.
CAR_FIELDS: dict[str, Any] = {
    "min_turning_radius": None,
    "reverse": True,
    "wheelbase": None,
    "v_max_reverse": None,
    "steer_rate_max": None,
}


def car_fields(owner: str, given: dict[str, Any]) -> dict[str, Any]:
    """Return a car's fields checked (``owner`` names them in errors: ``"Robot"``, ...)."""
    radius = given.get("min_turning_radius")
    wheelbase = given.get("wheelbase")
    if radius is None:
        raise InvalidInputError(
            f"{owner}.min_turning_radius is required with drive='ackermann' (a car-like "
            "robot's minimum turning radius, finite and > 0 m), got None"
            + ("" if wheelbase is None else f" (with wheelbase={wheelbase!r} m)")
        )
    reverse = given.get("reverse", True)
    if not isinstance(reverse, bool | np.bool_):
        raise InvalidInputError(f"{owner}.reverse must be True or False, got {reverse!r}")
    out: dict[str, Any] = {
        "min_turning_radius": positive(f"{owner}.min_turning_radius", radius, "m"),
        "reverse": bool(reverse),
    }
    for name, unit in (("wheelbase", "m"), ("v_max_reverse", "m/s"), ("steer_rate_max", "rad/s")):
        value = given.get(name)
        out[name] = None if value is None else positive(f"{owner}.{name}", value, unit)
    if out["steer_rate_max"] is not None and out["wheelbase"] is None:
        raise InvalidInputError(
            f"{owner}.steer_rate_max={out['steer_rate_max']!r} rad/s needs a wheelbase (the "
            "steering angle is atan(wheelbase * kappa)), got wheelbase=None"
        )
    return out


@dataclass(frozen=True, slots=True)
class Ackermann:
    """A car-like robot (forklifts, tuggers, carts): it turns no tighter than a radius.

    It faces its direction of travel (forwards, or backwards when ``reverse``) and cannot
    turn in place. Plans are Hybrid-A* paths (:func:`astar.find_pose_path`) split at their
    cusps, each segment a certified curve with ``|kappa| <= 1 / min_turning_radius``, timed
    from rest to rest. The yaw-rate, lateral-acceleration and (rear) wheel-speed caps of a
    differential drive apply as they are.

    Parameters
    ----------
    min_turning_radius : float
        ``R`` (m), finite and > 0: the path's curvature is at most ``1 / R``.
    reverse : bool
        Whether it may drive backwards (default True, Reeds-Shepp); False: forwards only
        (Dubins).
    wheelbase : float, optional
        ``L`` (m, > 0): samples then carry the steering angle ``atan(L kappa)`` and its rate.
    v_max_reverse : float, optional
        Speed limit backwards (m/s, > 0); ``None`` is the robot's ``v_max``.
    steer_rate_max : float, optional
        Steering-angle rate limit (rad/s, > 0), held by the timing as a speed cap
        (:meth:`steer_speed_cap`); needs ``wheelbase``.

    Raises
    ------
    InvalidInputError
        ``min_turning_radius`` missing, not finite or <= 0; ``wheelbase``,
        ``v_max_reverse`` or ``steer_rate_max`` not finite or <= 0; ``reverse`` not a bool;
        ``steer_rate_max`` without ``wheelbase``.
    """

    min_turning_radius: float | None = None
    reverse: bool = True
    wheelbase: float | None = None
    v_max_reverse: float | None = None
    steer_rate_max: float | None = None

    name: ClassVar[str] = "ackermann"
    turns_in_place: ClassVar[bool] = False
    orients_body: ClassVar[bool] = False
    signed_speed: ClassVar[bool] = True

    def __post_init__(self) -> None:
        checked = car_fields(type(self).__name__, {k: getattr(self, k) for k in CAR_FIELDS})
        for k, v in checked.items():
            object.__setattr__(self, k, v)

    def speed_terms(self, robot: Robot) -> SpeedTerms:
        """As a differential drive's: speed, lateral acceleration, yaw rate, rear wheels."""
        return _turning_terms(robot)

    @property
    def steering(self) -> Steering | None:
        """The wheelbase and the steering-rate limit, or ``None`` without a wheelbase."""
        if self.wheelbase is None:
            return None
        return Steering(float(self.wheelbase), self.steer_rate_max)

    def v_max_backwards(self, robot: Robot) -> float:
        """Speed limit backwards (m/s): ``v_max_reverse``, or ``robot.v_max`` when unset."""
        return robot.v_max if self.v_max_reverse is None else float(self.v_max_reverse)

    def steer_speed_cap(
        self, kappa: np.ndarray | float, dkappa_ds: np.ndarray | float
    ) -> np.ndarray | float:
        """Speed limit (m/s) that holds the steering-angle rate.

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

    def sample_fields(
        self, robot: Robot, arrays: dict[str, np.ndarray], dkappa_dt: np.ndarray | None
    ) -> None:
        """Add the steering angle and its rate (with a wheelbase) and the rear wheels' speeds."""
        if self.wheelbase is not None:
            lk = self.wheelbase * arrays["kappa"]
            arrays["steer"] = np.arctan(lk)
            if dkappa_dt is not None and "steer_rate" not in arrays:
                arrays["steer_rate"] = self.wheelbase * dkappa_dt / (1.0 + lk * lk)
        _wheel_speeds(robot, arrays)

    def fields(self) -> dict[str, Any]:
        """Return the car's fields by name (m, m/s, rad/s)."""
        return {k: getattr(self, k) for k in CAR_FIELDS}

    def plan(
        self,
        options: PlannerOptions,
        caches: PlannerCaches,
        request: PlanRequest,
        warm: WarmStart | None,
    ) -> PlanResult:
        """Hybrid-A*, split at its cusps, a certified fit and a timing per segment."""
        from trajopt.planning import plan_car

        return plan_car(options, caches, request)

    def replan(
        self,
        options: PlannerOptions,
        caches: PlannerCaches,
        trajectory: PlanResult,
        ts: float,
        goal: Sequence[float],
        *,
        goal_heading: float | None,
        v_end: float,
        reuse: bool,
        brake_after_s: float | None,
    ) -> PlanResult:
        """Keep the rest, or brake along the segment it drives and plan from the stopped pose."""
        from trajopt.replan import replan_car

        return replan_car(
            options,
            caches,
            trajectory,
            ts,
            goal,
            goal_heading=goal_heading,
            v_end=v_end,
            reuse=reuse,
        )


#: The drives by their string shorthand.
DRIVES: dict[str, type] = {d.name: d for d in (Differential, Omni, Ackermann)}


def as_drive(value: Any, car: dict[str, Any] | None = None, owner: str = "Robot") -> Any:
    """Return the drive record for ``value``: a record as it is, or a string shorthand.

    Parameters
    ----------
    value : Drive or {"differential", "omni", "ackermann"}
        A drive record, or its name.
    car : dict, optional
        The car's fields given beside a string (``Robot(drive="ackermann",
        min_turning_radius=...)``) or beside an :class:`Ackermann` record (they replace its
        own, as ``dataclasses.replace(robot, reverse=False)`` does); refused with another
        drive.
    owner : str
        Who the fields belong to, for error messages.

    Raises
    ------
    InvalidInputError
        An unknown drive (the message lists the drives), car fields with another drive or
        beside a drive record, or a bad car field.
    """
    car = {} if car is None else car
    given = {k: v for k, v in car.items() if v is not CAR_FIELDS[k] and v != CAR_FIELDS[k]}
    what = ", ".join(f"{k}={v!r}" for k, v in given.items())
    if isinstance(value, str) and value in DRIVES:
        if value == Ackermann.name:
            return Ackermann(**car_fields(owner, car))
        if given:
            raise InvalidInputError(
                f"{owner}: {what} apply only to a car-like robot (drive='ackermann'), "
                f"got drive={value!r}"
            )
        return DRIVES[value]()
    if isinstance(value, Ackermann):  # dataclasses.replace(robot, reverse=...) lands here
        return dataclasses.replace(value, **car) if car else value
    if not isinstance(value, str | type) and isinstance(value, Drive):
        if given:
            raise InvalidInputError(
                f"{owner}: {what} are a car's fields: give them to trajopt.Ackermann(...), "
                f"not beside drive={value!r}"
            )
        return value
    records = "" if isinstance(value, str) else " or a drive record (trajopt.Differential(), ...)"
    raise InvalidInputError(f"{owner}.drive must be one of {tuple(DRIVES)}{records}, got {value!r}")
