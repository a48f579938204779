"""What a drive answers: the :class:`Drive` protocol and the speed-cap terms it hands the timing.

A robot's drive is chosen once, as a value (:class:`~trajopt.drive.Differential`,
:class:`~trajopt.drive.Omni`, :class:`~trajopt.drive.Ackermann`), and every stage that used
to ask "which drive is this?" asks the value instead: the speed rule the timing applies
(:meth:`Drive.speed_terms`, one rule as numbers), an extra steering-rate cap
(:attr:`Drive.steering`), the fields its samples carry (:meth:`Drive.sample_fields`), whether
it turns in place or turns its body while it drives, its label in files and on the command
line, and the plans and re-plans it composes from the shared stages (:meth:`Drive.plan`,
:meth:`Drive.replan`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, ClassVar, NamedTuple, Protocol, runtime_checkable

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from trajopt.motion import PlanResult
    from trajopt.planning import PlannerCaches, PlannerOptions, PlanRequest, WarmStart
    from trajopt.robot import Robot


class SpeedTerms(NamedTuple):
    """The terms of a drive's curvature-dependent speed cap, as numbers (SI units).

    ``cap(kappa) = min(v_max, sqrt(a_lat_max / |k|), omega_max / |k|,
    wheel_v_max / (1 + |k| track_width / 2))``; a term that does not apply is ``inf``
    (``omega_max``, ``wheel_v_max``) or 0 (``track_width``). The timing's compiled cap
    kernel receives :meth:`as_array`; :func:`speed_cap` evaluates the same rule in NumPy.
    """

    v_max: float
    a_lat_max: float
    omega_max: float
    track_width: float
    wheel_v_max: float

    def as_array(self) -> np.ndarray:
        """Return the terms as the float64 vector ``[v_max, a_lat, omega, track, wheel]``."""
        return np.array(self, dtype=float)


def speed_cap(terms: SpeedTerms, kappa: np.ndarray | float) -> np.ndarray | float:
    """Return the speed cap (m/s) of ``terms`` at signed curvatures ``kappa`` (1/m).

    ``k = 0`` gives ``v_max``; an infinite or NaN curvature gives 0.

    Parameters
    ----------
    terms : SpeedTerms
        The drive's terms (:meth:`Drive.speed_terms`).
    kappa : float or array_like, any shape
        Signed curvature (1/m).

    Returns
    -------
    float or ndarray, shape of ``kappa``
    """
    k = np.abs(np.asarray(kappa, dtype=float))
    k = np.where(np.isnan(k), np.inf, k)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        cap = np.minimum(terms.v_max, np.sqrt(terms.a_lat_max / k))
        if math.isfinite(terms.omega_max):
            cap = np.minimum(cap, terms.omega_max / k)
        if terms.track_width > 0.0:
            cap = np.minimum(cap, terms.wheel_v_max / (1.0 + 0.5 * terms.track_width * k))
    cap = np.where(np.isinf(k), 0.0, cap)
    if cap.ndim == 0:
        return float(cap)
    return cap


class Steering(NamedTuple):
    """A car's steering geometry: wheelbase ``L`` (m) and steering-rate limit (rad/s or None)."""

    wheelbase: float
    rate_max: float | None


@runtime_checkable
class Drive(Protocol):
    """How a robot's base moves: the questions the stages ask of it.

    Implemented by :class:`~trajopt.drive.Differential`, :class:`~trajopt.drive.Omni` and
    :class:`~trajopt.drive.Ackermann` (frozen, validated records). A fourth drive is a new
    record that answers these; no stage names a drive.
    """

    #: The drive's label in files (MCAP metadata, ``Robot.to_dict``) and on the command line.
    name: ClassVar[str]
    #: Whether the robot can turn in place at rest (a required heading can be met by turning).
    turns_in_place: ClassVar[bool]
    #: Whether the body's orientation is its own motion, independent of the travel direction.
    orients_body: ClassVar[bool]
    #: Whether it drives backwards too: its samples carry the direction and signed speeds.
    signed_speed: ClassVar[bool]

    def speed_terms(self, robot: Robot) -> SpeedTerms:
        """Return the speed-cap terms of ``robot`` with this drive (:class:`SpeedTerms`)."""
        ...

    @property
    def steering(self) -> Steering | None:
        """The steering geometry whose rate the timing caps, or ``None``."""
        ...

    def sample_fields(
        self, robot: Robot, arrays: dict[str, np.ndarray], dkappa_dt: np.ndarray | None
    ) -> None:
        """Add this drive's fields to a sample's ``arrays`` (in place; wheel speeds, steering)."""
        ...

    def fields(self) -> dict[str, Any]:
        """Return the drive's own fields, for :meth:`trajopt.Robot.to_dict` (SI units)."""
        ...

    def plan(
        self,
        options: PlannerOptions,
        caches: PlannerCaches,
        request: PlanRequest,
        warm: WarmStart | None,
    ) -> PlanResult:
        """Plan one query with the stages this drive composes."""
        ...

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
        """Re-plan from ``trajectory``'s state at ``ts`` (s) to ``goal`` (m)."""
        ...
