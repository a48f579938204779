"""Trajectories played one after another, and the motions at rest that join two of them.

A re-plan that cannot continue smoothly from a moving robot brakes along the old path, turns
in place and drives a plan from rest (:mod:`trajopt.replan._brake`). Its result is a
:class:`TrajectoryChain` of those pieces: one timed motion with the interface of
:class:`trajopt.Trajectory` (``duration``, ``length``, ``sample``, ``state_at``,
``to_dict`` and the writers), whose pieces join without a jump in position, heading, speed,
acceleration or yaw rate (checked when the chain is built).

:class:`TurnInPlace` is a rest-to-rest rotation about the robot's centre under the limits of
:func:`trajopt.timing._stop_and_turn.turn_limits`, sampled with the conventions of the stop-and-turn
fallback: ``v = a = jerk = kappa = a_lat = 0`` and ``omega = d theta / dt``.

:class:`SteerInPlace` is a car's steering at rest (at a cusp, at the start, at the goal):
the steering angle turned from ``delta0`` to ``delta1`` at the constant rate
``steer_rate_max``, its samples telling the truth (``v = omega = 0``, ``theta`` constant,
``steer`` and ``steer_rate`` from the profile, ``kappa = tan(steer) / wheelbase``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from trajopt.errors import InvalidInputError
from trajopt.motion._samples import TrajectorySample, make_sample
from trajopt.motion._trajectory import AtRestEnds, Orientation, SampledExport, export_dict
from trajopt.robot import Robot, State
from trajopt.validation import readonly

#: Largest jump (SI units) between two consecutive pieces of a chain.
JOIN_TOL = 1e-6
_BASE = ("t", "x", "y", "theta", "v", "omega", "a", "jerk", "a_lat", "kappa", "s")
#: Optional sample fields a chain passes on when its pieces carry them (a car-like robot's
#: direction of travel and steering); the wheel speeds are recomputed by ``make_sample``.
_CARRIED = ("direction", "steer", "steer_rate")


@dataclass(frozen=True, slots=True)
class TurnInPlace(AtRestEnds):
    """A rest-to-rest turn about the robot's centre (built by :func:`turn_in_place`).

    Parameters
    ----------
    position : ndarray, shape (2,)
        Where the robot turns (m).
    theta0 : float
        Heading at the start (rad).
    sign : float
        ``+1`` (counter-clockwise) or ``-1``.
    rows : ndarray, shape (p, 5)
        The turned angle's constant-jerk phases ``(duration, q0, dq0, ddq0, jerk)`` (s, rad,
        rad/s, rad/s^2, rad/s^3), from ``q = 0`` at rest to ``q = |turn|`` at rest.
    robot : Robot
        The limits held.
    stats : dict
        ``turn_rad`` (signed) and ``duration_s``.
    """

    turning: ClassVar[bool] = True

    position: np.ndarray
    theta0: float
    sign: float
    rows: np.ndarray
    robot: Robot
    stats: dict[str, Any] = field(default_factory=dict)
    steps: Any = None
    duration: float = field(init=False)
    _t: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "position", readonly(np.asarray(self.position, dtype=float)))
        object.__setattr__(self, "rows", readonly(np.asarray(self.rows, dtype=float)))
        t = np.concatenate([[0.0], np.cumsum(self.rows[:, 0])])
        object.__setattr__(self, "_t", readonly(t))
        object.__setattr__(self, "duration", float(t[-1]))

    @property
    def length(self) -> float:
        """Distance travelled: 0 (m)."""
        return 0.0

    @property
    def turn_rad(self) -> float:
        """The signed angle turned (rad)."""
        q = self.rows[-1]
        d = q[0]
        return float(self.sign * (q[1] + d * (q[2] + d * (0.5 * q[3] + d * q[4] / 6.0))))

    def sample(self, t: np.ndarray | float) -> TrajectorySample:
        """Evaluate the turn at times ``t`` (s, clipped to ``[0, duration]``; vectorised)."""
        tt = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        if self.rows.shape[0] == 0:
            q = dq = np.zeros_like(tt)
        else:
            k = np.clip(np.searchsorted(self._t, tt, side="right") - 1, 0, len(self.rows) - 1)
            tau = tt - self._t[k]
            _, q0, v0, a0, j = self.rows[k].T
            q = q0 + tau * (v0 + tau * (0.5 * a0 + tau * j / 6.0))
            dq = v0 + tau * (a0 + 0.5 * j * tau)
            end = tt >= self.duration
            q = np.where(end, abs(self.turn_rad), q)
            dq = np.where(end, 0.0, dq)
        zero = np.zeros_like(tt)
        return make_sample(
            self.robot,
            t=tt,
            x=zero + self.position[0],
            y=zero + self.position[1],
            theta=self.theta0 + self.sign * q,
            v=zero,
            omega=self.sign * dq,
            a=zero,
            jerk=zero,
            a_lat=zero,
            kappa=zero,
            s=zero,
        )

    def to_dict(self, dt: float = 0.01) -> dict[str, Any]:
        """Return a JSON-ready description (the layout of :meth:`Trajectory.to_dict`)."""
        turn = {
            "x": float(self.position[0]),
            "y": float(self.position[1]),
            "theta0": self.theta0,
            "turn_rad": self.turn_rad,
        }
        return export_dict(self, "trajopt.TurnInPlace", dt, {"turn": turn})

    def __repr__(self) -> str:
        return f"TurnInPlace(turn={self.turn_rad:.4g} rad, duration={self.duration:.4g} s)"


@dataclass(frozen=True, slots=True)
class SteerInPlace(AtRestEnds):
    """A car's steering at rest, the angle turned at a constant rate (:func:`steer_in_place`).

    The car stands at ``position`` with the body's heading ``theta``; the steering angle
    runs linearly in time from ``delta0`` to ``delta1`` at ``rate``, so
    ``duration = |delta1 - delta0| / rate``. The car has no steering acceleration limit
    (:class:`~trajopt.drive.Ackermann` has none): the rate steps from 0 to ``rate`` at the
    start and back at the end, as it may at rest.

    Parameters
    ----------
    position : ndarray, shape (2,)
        Where the car stands (m).
    theta : float
        The body's heading (rad).
    delta0, delta1 : float
        Steering angle at the start and at the end (rad), within ``(-pi/2, pi/2)``.
    rate : float
        Steering rate (rad/s, > 0): the car's ``steer_rate_max``.
    wheelbase : float
        ``L`` (m): the sampled curvature is ``tan(steer) / L``.
    direction : {1, -1}
        The direction of travel its samples carry (that of the drive it prepares, or of the
        one before it at the goal).
    robot : Robot
        The car.
    stats : dict
        ``steer_rad`` (signed change) and ``duration_s``.

    Raises
    ------
    InvalidInputError
        A non-finite angle or position, an angle outside ``(-pi/2, pi/2)``, a rate or a
        wheelbase not finite and > 0, a direction other than 1 or -1.
    """

    steering_at_rest: ClassVar[bool] = True

    position: np.ndarray
    theta: float
    delta0: float
    delta1: float
    rate: float
    wheelbase: float
    direction: int
    robot: Robot
    stats: dict[str, Any] = field(default_factory=dict)
    steps: Any = None
    duration: float = field(init=False)

    def __post_init__(self) -> None:
        pos = np.asarray(self.position, dtype=float)
        if pos.shape != (2,) or not np.all(np.isfinite(pos)):
            raise InvalidInputError(f"position must be 2 finite numbers (m), got {self.position!r}")
        object.__setattr__(self, "position", readonly(pos))
        for name, unit in (("theta", "rad"), ("delta0", "rad"), ("delta1", "rad")):
            v = float(getattr(self, name))
            if not math.isfinite(v):
                raise InvalidInputError(f"{name} must be finite ({unit}), got {v!r}")
            object.__setattr__(self, name, v)
        for name in ("delta0", "delta1"):
            if not abs(getattr(self, name)) < 0.5 * math.pi:
                raise InvalidInputError(
                    f"{name} must lie in (-pi/2, pi/2) rad (a steering angle), "
                    f"got {getattr(self, name)!r}"
                )
        for name, unit in (("rate", "rad/s"), ("wheelbase", "m")):
            v = float(getattr(self, name))
            if not (math.isfinite(v) and v > 0.0):
                raise InvalidInputError(f"{name} must be finite and > 0 ({unit}), got {v!r}")
            object.__setattr__(self, name, v)
        if self.direction not in (1, -1) or isinstance(self.direction, bool):
            raise InvalidInputError(f"direction must be 1 or -1, got {self.direction!r}")
        object.__setattr__(self, "direction", int(self.direction))
        object.__setattr__(self, "duration", abs(self.delta1 - self.delta0) / self.rate)

    @property
    def length(self) -> float:
        """Distance travelled: 0 (m)."""
        return 0.0

    @property
    def steer_rad(self) -> float:
        """The signed change of the steering angle (rad)."""
        return self.delta1 - self.delta0

    def steer(self, t: np.ndarray | float) -> np.ndarray:
        """Return the steering angle (rad) at times ``t`` (s, clipped to ``[0, duration]``)."""
        tt = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        sign = math.copysign(1.0, self.delta1 - self.delta0)
        return np.where(tt >= self.duration, self.delta1, self.delta0 + sign * self.rate * tt)

    def sample(self, t: np.ndarray | float) -> TrajectorySample:
        """Evaluate the steering at rest at times ``t`` (s, clipped to ``[0, duration]``).

        ``steer_rate`` is ``+-rate`` before the end and 0 at the end itself.
        """
        tt = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        delta = self.steer(tt)
        sign = math.copysign(1.0, self.delta1 - self.delta0)
        zero = np.zeros_like(tt)
        return make_sample(
            self.robot,
            t=tt,
            x=zero + self.position[0],
            y=zero + self.position[1],
            theta=zero + self.theta,
            v=zero,
            omega=zero,
            a=zero,
            jerk=zero,
            a_lat=zero,
            kappa=np.tan(delta) / self.wheelbase,
            s=zero,
            direction=zero + float(self.direction),
            steer_rate=np.where(tt >= self.duration, 0.0, sign * self.rate),
        )

    def to_dict(self, dt: float = 0.01) -> dict[str, Any]:
        """Return a JSON-ready description (the layout of :meth:`Trajectory.to_dict`)."""
        steer = {
            "x": float(self.position[0]),
            "y": float(self.position[1]),
            "theta": self.theta,
            "delta0": self.delta0,
            "delta1": self.delta1,
            "rate": self.rate,
        }
        return export_dict(self, "trajopt.SteerInPlace", dt, {"steer": steer})

    def __repr__(self) -> str:
        return f"SteerInPlace(steer={self.steer_rad:.4g} rad, duration={self.duration:.4g} s)"


def steer_in_place(
    robot: Robot, position: np.ndarray, theta: float, delta0: float, delta1: float, direction: int
) -> SteerInPlace:
    """Return the car's steering at rest from ``delta0`` to ``delta1`` (rad) at its limit.

    Parameters
    ----------
    robot : Robot
        A car whose drive has a ``wheelbase`` and a ``steer_rate_max`` (rad/s).
    position : ndarray, shape (2,)
        Where it stands (m).
    theta : float
        The body's heading (rad).
    delta0, delta1 : float
        Steering angles (rad).
    direction : {1, -1}
        The direction of travel the samples carry.

    Raises
    ------
    InvalidInputError
        The robot's drive has no steering-rate limit (the steering is then not modelled).
    """
    steering = robot.drive.steering
    if steering is None or steering.rate_max is None:
        raise InvalidInputError(
            "a steering at rest needs a car with a wheelbase and a steer_rate_max, "
            f"got drive={robot.drive!r}"
        )
    d = float(delta1) - float(delta0)
    return SteerInPlace(
        position,
        theta,
        delta0,
        delta1,
        steering.rate_max,
        steering.wheelbase,
        direction,
        robot,
        {"steer_rad": d, "duration_s": abs(d) / steering.rate_max},
    )


@dataclass(frozen=True, slots=True)
class TrajectoryChain(SampledExport):
    """Timed trajectories played one after another, as one trajectory.

    Piece ``i`` is played from its own time ``starts[i]`` to its end; the chain's heading is
    kept continuous (each piece's heading is shifted by a multiple of ``2 pi``) and its arc
    length ``s`` runs on from piece to piece.

    Parameters
    ----------
    pieces : tuple
        Timed trajectories (each with ``duration``, ``sample``, ``v_end``), at least one.
    robot : Robot
        The limits every piece holds.
    stats : dict
        The planner's statistics (a re-plan's ``replan``, ``brake_*`` and ``turn_*``
        entries, and those of the last piece).
    steps : object, optional
        The last piece's ``trajopt._planner.PlanSteps`` (its goal is the chain's).
    starts : tuple of float, optional
        Time (s) within each piece where it starts playing; default all 0.

    Raises
    ------
    InvalidInputError
        No piece, a start outside its piece, or two pieces that do not join (position,
        heading modulo ``2 pi``, speed, acceleration or yaw rate differ by more than
        ``JOIN_TOL``).
    """

    pieces: tuple
    robot: Robot
    stats: dict[str, Any] = field(default_factory=dict)
    steps: Any = None
    starts: tuple = ()
    duration: float = field(init=False)
    length: float = field(init=False)
    _t: np.ndarray = field(init=False, repr=False)
    _theta_shift: np.ndarray = field(init=False, repr=False)
    _s_shift: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        pieces = tuple(self.pieces)
        if not pieces:
            raise InvalidInputError("a TrajectoryChain needs at least one piece")
        starts = tuple(float(x) for x in self.starts) or (0.0,) * len(pieces)
        if len(starts) != len(pieces):
            raise InvalidInputError(
                f"starts needs one time per piece ({len(pieces)}), got {len(starts)}"
            )
        spans, th_shift, s_shift, prev = [], [0.0], [0.0], None
        for i, (p, t0) in enumerate(zip(pieces, starts, strict=True)):
            if not 0.0 <= t0 <= p.duration:
                raise InvalidInputError(
                    f"starts[{i}] = {t0!r} s must lie in [0, {p.duration}] s (piece {i}'s duration)"
                )
            spans.append(p.duration - t0)
            b = p.sample(np.array([t0, p.duration]))
            first, last = _at(b, 0), _at(b, 1)
            if prev is not None:  # prev: the previous piece's end, its heading shifted
                shift = 2.0 * math.pi * round((prev["theta"] - first["theta"]) / (2.0 * math.pi))
                _check_join(i, prev, first, shift)
                th_shift.append(shift)
                s_shift.append(s_shift[-1] + prev["s"] - prev["s0"])
            prev = dict(last, s0=first["s"], theta=last["theta"] + th_shift[-1])
        object.__setattr__(self, "pieces", pieces)
        object.__setattr__(self, "starts", starts)
        t = np.concatenate([[0.0], np.cumsum(spans)])
        object.__setattr__(self, "_t", readonly(t))
        object.__setattr__(self, "duration", float(t[-1]))
        object.__setattr__(self, "_theta_shift", readonly(th_shift))
        object.__setattr__(self, "_s_shift", readonly(s_shift))
        object.__setattr__(self, "length", float(s_shift[-1] + prev["s"] - prev["s0"]))

    @property
    def v_start(self) -> float:
        """Speed at the start (m/s)."""
        return float(self.pieces[0].sample(self.starts[0]).v)

    @property
    def v_end(self) -> float:
        """Speed at the end (m/s): the last piece's."""
        return float(self.pieces[-1].v_end)

    @property
    def piece_times(self) -> np.ndarray:
        """Start time of each piece on the chain's clock, and the end, shape (n + 1,) (s)."""
        return self._t

    def piece_at(self, t: float) -> tuple[int, float]:
        """``(i, tau)``: the piece playing at chain time ``t`` (s) and the time in it (s).

        At a join the later piece is returned (at its start); at the end, the last piece.
        """
        tt = min(max(float(t), 0.0), self.duration)
        i = int(np.searchsorted(self._t, tt, side="right")) - 1
        i = min(max(i, 0), len(self.pieces) - 1)
        while i < len(self.pieces) - 1 and tt >= self._t[i + 1]:
            i += 1
        if tt >= self.duration:  # the end exactly (no rounding)
            return i, float(self.pieces[i].duration)
        return i, tt - float(self._t[i]) + self.starts[i]

    def playing(self, t: float) -> tuple[SampledExport, float]:
        """Return the piece playing at chain time ``t`` (s) and the time in it (:meth:`piece_at`)."""
        i, tau = self.piece_at(t)
        return self.pieces[i], tau

    def plan_at(self, t: float) -> tuple[SampledExport, float]:
        """Return the plan a re-plan at ``t`` (s) continues, and the time in it.

        The chain's last piece (its plan from rest) while it plays, unless it is a turn in
        place or a steering at rest; else the chain itself.
        """
        i, tau = self.piece_at(t)
        last = self.pieces[i]
        if i == len(self.pieces) - 1 and not (last.turning or last.steering_at_rest):
            return last, tau
        return self, t

    def orientation_at(self, t: float) -> Orientation | None:
        """Return the body's own orientation at ``t`` (s) when the piece playing has one.

        The angle is the chain's (continuous across its pieces); ``None`` when the piece
        faces its direction of travel.
        """
        piece, tau = self.playing(t)
        own = piece.orientation_at(tau)
        if own is None:
            return None
        theta = float(self.sample(np.array([t])).theta[0])
        return Orientation(theta, own.omega, own.alpha)

    def translation_state(self, t: float) -> State:
        """Return the state a re-plan continues at ``t`` (s).

        The translation's of a piece whose body turns on its own (its direction of travel,
        not the body's angle), else :meth:`state_at`.
        """
        piece, tau = self.playing(t)
        if piece.own_orientation:
            return piece.translation_state(tau)
        return self.state_at(t)

    def after(self, t: float) -> TrajectoryChain:
        """Return the chain from time ``t`` (s) on, with its clock starting at 0 there."""
        i, tau = self.piece_at(t)
        return TrajectoryChain(
            self.pieces[i:], self.robot, dict(self.stats), self.steps, (tau,) + self.starts[i + 1 :]
        )

    def sample(self, t: np.ndarray | float) -> TrajectorySample:
        """Evaluate the chain at times ``t`` (s, clipped to ``[0, duration]``; vectorised)."""
        tt = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        flat = tt.reshape(-1)
        k = np.clip(np.searchsorted(self._t, flat, side="right") - 1, 0, len(self.pieces) - 1)
        out = {n: np.empty(flat.shape) for n in _BASE}
        for i in np.unique(k):
            m = k == i
            p, t0 = self.pieces[i], self.starts[i]
            local = flat[m] - self._t[i] + t0
            local[flat[m] >= self._t[i + 1]] = p.duration  # its end exactly (no rounding)
            smp = p.sample(np.concatenate([local, [t0]]))
            for n in _CARRIED:
                if getattr(smp, n, None) is not None:
                    out.setdefault(n, np.zeros(flat.shape))[m] = getattr(smp, n)[:-1]
            for n in _BASE[1:]:
                out[n][m] = getattr(smp, n)[:-1]
            out["theta"][m] += self._theta_shift[i]
            out["s"][m] += self._s_shift[i] - smp.s[-1]
        out["t"] = flat
        out.pop("steer", None)  # make_sample computes it from kappa
        return make_sample(self.robot, **{n: x.reshape(tt.shape) for n, x in out.items()})

    def to_dict(self, dt: float = 0.01) -> dict[str, Any]:
        """Return a JSON-ready description (the layout of :meth:`Trajectory.to_dict`).

        ``pieces`` lists each piece's type, its start time on the chain's clock (s) and its
        played duration (s).
        """
        pieces = [
            {
                "type": type(p).__name__,
                "t0": float(self._t[i]),
                "duration": float(self._t[i + 1] - self._t[i]),
            }
            for i, p in enumerate(self.pieces)
        ]
        return export_dict(self, "trajopt.TrajectoryChain", dt, {"pieces": pieces})

    def __repr__(self) -> str:
        kinds = ", ".join(type(p).__name__ for p in self.pieces)
        return (
            f"TrajectoryChain(duration={self.duration:.4g} s, length={self.length:.4g} m, "
            f"pieces=[{kinds}])"
        )


def _at(smp: TrajectorySample, i: int) -> dict[str, float]:
    return {n: float(getattr(smp, n)[i]) for n in ("x", "y", "theta", "v", "a", "omega", "s")}


def _check_join(i: int, end: dict[str, float], start: dict[str, float], shift: float) -> None:
    jumps = {
        "position (m)": math.hypot(end["x"] - start["x"], end["y"] - start["y"]),
        "heading (rad)": abs(end["theta"] - start["theta"] - shift),
        "speed (m/s)": abs(end["v"] - start["v"]),
        "acceleration (m/s^2)": abs(end["a"] - start["a"]),
        "yaw rate (rad/s)": abs(end["omega"] - start["omega"]),
    }
    bad = {k: v for k, v in jumps.items() if not v <= JOIN_TOL}
    if bad:
        what = ", ".join(f"{k} {v:.3g}" for k, v in bad.items())
        raise InvalidInputError(
            f"pieces {i - 1} and {i} do not join: jumps of {what} (allowed {JOIN_TOL})"
        )
