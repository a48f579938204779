"""A predicted moving obstacle: a disc or a convex polygon on a piecewise-linear track.

Time is the trajectory's clock: seconds from the plan's ``t = 0``. Between two waypoints the
obstacle's reference point and heading move linearly in time; before its first time it stands
at its first waypoint, after its last time it stays where it was last (the safe reading of a
stopped or lost track). Its shape is the set of points within ``radius(t)`` of the convex hull
of its vertices (a disc: one vertex at its reference point), where
``radius(t) = radius + growth * min(max(t, 0), t_last)``: the radius grows with the prediction
time up to the last waypoint and keeps that value afterwards.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from trajopt.errors import InvalidInputError
from trajopt.validation import readonly


def _fail(name: str, field: str, value: object, rule: str) -> InvalidInputError:
    return InvalidInputError(f"moving obstacle {name!r}: {field} must {rule}, got {value!r}")


def _nonneg(name: str, field: str, value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        raise _fail(name, field, value, "be a finite number >= 0 (m or m/s)")
    x = float(value)
    if not (math.isfinite(x) and x >= 0.0):
        raise _fail(name, field, value, "be a finite number >= 0 (m or m/s)")
    return x


def _convex_ccw(name: str, vertices: object) -> np.ndarray:
    """Return the polygon's vertices counter-clockwise, shape (m, 2); refuse a non-convex one."""
    try:
        v = np.array(vertices, dtype=float)
    except (TypeError, ValueError):
        raise _fail(name, "vertices", vertices, "be an array of shape (m, 2), m >= 3") from None
    if v.ndim != 2 or v.shape[1] != 2 or v.shape[0] < 3 or not np.all(np.isfinite(v)):
        raise _fail(name, "vertices", vertices, "be finite, of shape (m, 2) with m >= 3")
    d1 = np.roll(v, -1, axis=0) - v
    d2 = np.roll(d1, -1, axis=0)
    cross = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    scale = float(np.max(np.abs(v - v.mean(axis=0)))) or 1.0
    tol = 1e-12 * scale * scale
    area2 = float(np.sum(v[:, 0] * np.roll(v[:, 1], -1) - np.roll(v[:, 0], -1) * v[:, 1]))
    if np.min(np.hypot(d1[:, 0], d1[:, 1])) <= 1e-12 * scale or abs(area2) <= tol:
        raise _fail(
            name, "vertices", v.tolist(), "span a polygon of positive area (no repeated vertex)"
        )
    sign = 1.0 if area2 > 0 else -1.0
    # convex and simple: every turn has the orientation's sign and the edges turn once round
    turn = np.arctan2(cross, np.sum(d1 * d2, axis=1))
    if np.any(sign * cross < -tol) or abs(abs(float(np.sum(turn))) - 2.0 * math.pi) > 1e-6:
        raise _fail(name, "vertices", v.tolist(), "be a convex polygon (vertices in order)")
    return v if sign > 0 else v[::-1].copy()


@dataclass(frozen=True, slots=True)
class MovingObstacle:
    """A predicted moving obstacle (validated, immutable).

    Build it with :meth:`constant_velocity` or :meth:`from_waypoints`; the constructor
    validates every field the same way.

    Parameters
    ----------
    times : array_like, shape (k,)
        Waypoint times (s, the trajectory's clock), finite and strictly increasing, k >= 1.
    positions : array_like, shape (k, 2)
        The reference point at each time (m, world frame).
    headings : array_like, shape (k,)
        The heading at each time (rad; interpolated linearly, not wrapped: give unwrapped
        values). Only a polygon's shape turns with it.
    radius : float
        The disc's radius, or the rounding added around a polygon (m), >= 0.
    growth : float
        Growth of the radius with prediction time (m/s), >= 0 (uncertainty).
    vertices : array_like, shape (m, 2), optional
        A convex polygon in the obstacle's own frame (m; rotated by the heading, then shifted
        to the reference point). ``None`` (default): a disc of ``radius``.
    name : str
        Named in errors and certificates.
    """

    times: np.ndarray
    positions: np.ndarray
    headings: np.ndarray
    radius: float = 0.0
    growth: float = 0.0
    vertices: np.ndarray | None = None
    name: str = "mover"

    def __post_init__(self) -> None:
        name = self.name
        if not isinstance(name, str) or not name:
            raise InvalidInputError(
                f"moving obstacle name must be a non-empty string, got {name!r}"
            )
        try:
            t = np.array(self.times, dtype=float).reshape(-1)
            p = np.array(self.positions, dtype=float)
            h = np.array(self.headings, dtype=float).reshape(-1)
        except (TypeError, ValueError) as exc:
            raise _fail(name, "times/positions/headings", str(exc), "be numeric arrays") from None
        if t.shape[0] < 1 or not np.all(np.isfinite(t)):
            raise _fail(name, "times", self.times, "be finite, at least one value (s)")
        if t.shape[0] > 1 and np.any(np.diff(t) <= 0.0):
            raise _fail(name, "times", self.times, "be strictly increasing (s)")
        if p.shape != (t.shape[0], 2) or not np.all(np.isfinite(p)):
            raise _fail(
                name, "positions", self.positions, f"be finite of shape ({t.shape[0]}, 2) (m)"
            )
        if h.shape != t.shape or not np.all(np.isfinite(h)):
            raise _fail(
                name, "headings", self.headings, f"be finite of shape ({t.shape[0]},) (rad)"
            )
        object.__setattr__(self, "times", readonly(t))
        object.__setattr__(self, "positions", readonly(p))
        object.__setattr__(self, "headings", readonly(h))
        object.__setattr__(self, "radius", _nonneg(name, "radius", self.radius))
        object.__setattr__(self, "growth", _nonneg(name, "growth", self.growth))
        if self.vertices is not None:
            object.__setattr__(self, "vertices", readonly(_convex_ccw(name, self.vertices)))

    # ---------------------------------------------------------------- constructors
    @classmethod
    def constant_velocity(
        cls,
        position: Sequence[float],
        velocity: Sequence[float],
        *,
        radius: float,
        horizon: float,
        growth: float = 0.0,
        heading: float | None = None,
        vertices: Sequence[Sequence[float]] | None = None,
        name: str = "mover",
    ) -> MovingObstacle:
        """Build a mover at ``position`` at ``t = 0`` moving with ``velocity`` until ``horizon``.

        Parameters
        ----------
        position, velocity : sequence of float, shape (2,)
            Position at ``t = 0`` (m) and constant velocity (m/s).
        radius : float
            Disc radius (or a polygon's rounding) (m), >= 0.
        horizon : float
            Prediction end (s), > 0; afterwards the mover stays where it was.
        growth : float
            Radius growth (m/s), >= 0.
        heading : float, optional
            Constant heading (rad); default the direction of ``velocity`` (0 at rest).
        vertices : array_like, shape (m, 2), optional
            A convex polygon in the mover's frame (m).
        name : str
            The mover's name.
        """
        if (
            isinstance(horizon, bool)
            or not isinstance(horizon, (int, float))
            or not (math.isfinite(horizon) and horizon > 0.0)
        ):
            raise _fail(name, "horizon", horizon, "be a finite number > 0 (s)")
        try:
            p0 = np.array(position, dtype=float).reshape(2)
            v = np.array(velocity, dtype=float).reshape(2)
        except (TypeError, ValueError):
            raise _fail(
                name, "position/velocity", (position, velocity), "be pairs of numbers"
            ) from None
        if not np.all(np.isfinite(v)):
            raise _fail(name, "velocity", velocity, "be finite (m/s)")
        if heading is None:
            heading = math.atan2(v[1], v[0]) if np.any(v != 0.0) else 0.0
        return cls(
            times=np.array([0.0, float(horizon)]),
            positions=np.stack([p0, p0 + v * float(horizon)]),
            headings=np.array([heading, heading], dtype=float),
            radius=radius,
            growth=growth,
            vertices=None if vertices is None else np.asarray(vertices, dtype=float),
            name=name,
        )

    @classmethod
    def from_waypoints(
        cls,
        times: Sequence[float],
        positions: Sequence[Sequence[float]],
        *,
        radius: float,
        headings: Sequence[float] | None = None,
        growth: float = 0.0,
        vertices: Sequence[Sequence[float]] | None = None,
        name: str = "mover",
    ) -> MovingObstacle:
        """Build a mover through ``positions`` at ``times`` (linear between waypoints).

        Parameters
        ----------
        times : sequence of float, shape (k,)
            Strictly increasing times (s).
        positions : array_like, shape (k, 2)
            Reference points (m).
        radius : float
            Disc radius (or a polygon's rounding) (m), >= 0.
        headings : sequence of float, shape (k,), optional
            Headings (rad, unwrapped); default 0.
        growth : float
            Radius growth (m/s), >= 0.
        vertices : array_like, shape (m, 2), optional
            A convex polygon in the mover's frame (m).
        name : str
            The mover's name.
        """
        t = np.asarray(times, dtype=float).reshape(-1)
        h = np.zeros(t.shape) if headings is None else headings
        return cls(
            times=t,
            positions=positions,
            headings=h,
            radius=radius,
            growth=growth,
            vertices=None if vertices is None else np.asarray(vertices, dtype=float),
            name=name,
        )

    # ---------------------------------------------------------------- queries
    @property
    def t_last(self) -> float:
        """The last prediction time (s)."""
        return float(self.times[-1])

    @property
    def shape_vertices(self) -> np.ndarray:
        """The convex shape's vertices in the mover's frame, shape (m, 2) (one point for a disc)."""
        return np.zeros((1, 2)) if self.vertices is None else self.vertices

    def radius_at(self, t: np.ndarray | float) -> np.ndarray:
        """Return the radius (m) at times ``t`` (s): ``radius + growth * clip(t, 0, t_last)``."""
        tt = np.clip(np.asarray(t, dtype=float), 0.0, max(self.t_last, 0.0))
        return self.radius + self.growth * tt

    def pose_at(self, t: np.ndarray | float) -> tuple[np.ndarray, np.ndarray]:
        """Return the reference point (m), shape (..., 2), and heading (rad), shape (...), at times ``t`` (s)."""
        tt = np.asarray(t, dtype=float)
        x = np.interp(tt, self.times, self.positions[:, 0])
        y = np.interp(tt, self.times, self.positions[:, 1])
        return np.stack([x, y], axis=-1), np.interp(tt, self.times, self.headings)

    def position_at(self, t: np.ndarray | float) -> np.ndarray:
        """Return the reference point (m), shape (..., 2), at times ``t`` (s)."""
        return self.pose_at(t)[0]

    def speed_max(self) -> float:
        """Return the largest speed of the reference point over the prediction (m/s)."""
        if self.times.shape[0] < 2:
            return 0.0
        d = np.diff(self.positions, axis=0)
        return float(np.max(np.hypot(d[:, 0], d[:, 1]) / np.diff(self.times)))

    def shape_speed_max(self) -> float:
        """Return a bound of the speed of every point of the shape (m/s): centre plus turn times reach."""
        if self.times.shape[0] < 2:
            return 0.0
        d = np.diff(self.positions, axis=0)
        dt = np.diff(self.times)
        reach = float(np.max(np.hypot(*self.shape_vertices.T)))
        w = np.abs(np.diff(self.headings)) / dt
        return float(np.max(np.hypot(d[:, 0], d[:, 1]) / dt + reach * w))

    def __repr__(self) -> str:
        kind = "disc" if self.vertices is None else f"polygon({self.vertices.shape[0]})"
        return (
            f"MovingObstacle({self.name!r}, {kind}, radius={self.radius:.4g} m, "
            f"t=[{self.times[0]:.4g}, {self.t_last:.4g}] s)"
        )
