"""The state of a moving robot: where a re-plan starts.

A :class:`State` is what :meth:`Trajectory.state_at` returns and what :func:`trajopt.plan`
and :meth:`Planner.plan` accept as ``start``: the new trajectory then starts at its
position with its heading and curvature (the curve is C2 at the splice) and its timing
starts at its speed and acceleration.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from trajopt.validation import nonnegative, number


@dataclass(frozen=True, slots=True)
class State:
    """A planar robot state, SI units.

    Parameters
    ----------
    x, y : float
        Position (m).
    theta : float
        Heading (rad), the direction of motion.
    kappa : float, optional
        Signed curvature of the path there (1/m; positive turns left). Default 0.
    v : float, optional
        Speed along the path (m/s), >= 0. Default 0.
    a : float, optional
        Tangential acceleration (m/s^2). Default 0.

    Raises
    ------
    InvalidInputError
        A non-finite value or a negative speed (the message names the field).
    """

    x: float
    y: float
    theta: float
    kappa: float = 0.0
    v: float = 0.0
    a: float = 0.0

    def __post_init__(self) -> None:
        for name in ("x", "y", "theta", "kappa", "a"):
            object.__setattr__(self, name, number(f"State.{name}", getattr(self, name)))
        object.__setattr__(self, "v", nonnegative("State.v", self.v, "m/s"))

    @property
    def position(self) -> tuple[float, float]:
        """``(x, y)`` (m)."""
        return (self.x, self.y)

    @property
    def omega(self) -> float:
        """Yaw rate ``kappa * v`` (rad/s)."""
        return self.kappa * self.v

    def __repr__(self) -> str:
        return (
            f"State(x={self.x:.6g}, y={self.y:.6g}, theta={self.theta:.6g}, "
            f"kappa={self.kappa:.6g}, v={self.v:.6g}, a={self.a:.6g})"
        )


def wrap_angle(theta: float) -> float:
    """Return ``theta`` wrapped to ``(-pi, pi]`` (rad)."""
    w = math.remainder(theta, 2.0 * math.pi)
    return math.pi if w == -math.pi else w
