"""An omnidirectional motion: a timed translation along a curve, and an orientation of its own.

An omnidirectional base (``Robot(drive="omni")``: mecanum or omni wheels) moves along its
path whatever way its body faces. :class:`OmniTrajectory` pairs

* the **translation**: a :class:`~trajopt.motion._trajectory.Trajectory` along the path
  (duration ``T``), timed under the omni speed cap (:meth:`Robot.speed_cap`), and
* the **orientation**: a jerk-limited 1-DoF profile of the body's yaw, ending at rest (and
  starting at rest, or, in a re-plan, with the yaw rate and acceleration the body had),
  stored as constant-jerk rows (duration ``T_rot``),

built by :func:`trajopt.timing.orient`. The motion lasts ``max(T, T_rot)``: when the turn
takes longer than the drive, the robot stands at the path's end (``v = 0``) while it
finishes turning.

Sampling conventions (:class:`~trajopt.motion._samples.OmniSample`):

* ``theta`` is the **orientation** of the body (rad, continuous and unwrapped) and ``omega``
  its rate ``d theta / dt`` (rad/s): what the base turns by. The pose of :meth:`to_poses`
  and of the CSV/JSON/MCAP exports is ``(x, y, theta)``.
* ``course`` is the **direction of travel**, the path's tangent (rad, continuous and
  unwrapped; at rest, the tangent where the robot stands); ``vx, vy = v (cos, sin)(course)``
  is the world-frame velocity and ``(v_body_x, v_body_y)`` the same velocity in the body
  frame (rotated by ``-theta``): what an omni base is commanded with.
* ``v``, ``a``, ``jerk``, ``s``, ``kappa`` (the path's curvature) and ``a_lat = kappa v^2``
  (the centripetal acceleration) describe the translation along the path.
* No wheel speeds (``v_left``, ``v_right`` are those of a differential drive).

For times ``t > T`` the translation holds its end: ``s = length``, ``v = a = jerk = 0``.

A re-plan that keeps the rest of the motion cuts it with :meth:`OmniTrajectory.after`: the
orientation's phases from the cut on, shifted in time, beside the translation's rest.

MCAP (:meth:`~trajopt.motion._trajectory.SampledExport.to_mcap`): ``/plan`` and ``/pose``
carry the orientation; ``/twist`` is written by :func:`trajopt.motion._mcap.write_mcap` as
for every trajectory, ``linear.x = v`` (the speed along the path, not ``v_body_x``),
``linear.y = 0`` and ``angular.z = omega``: it is not yet the body-frame velocity.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from trajopt.errors import InvalidInputError
from trajopt.motion._samples import OmniSample
from trajopt.motion._trajectory import Orientation, SampledExport, Trajectory, export_dict
from trajopt.robot import Robot, State
from trajopt.validation import number, readonly

#: Units of the orientation rows' columns ``(t0, theta, omega, alpha, zeta)``.
ORIENTATION_UNITS: dict[str, str] = {
    "t": "s",
    "theta": "rad",
    "omega": "rad/s",
    "alpha": "rad/s^2",
    "zeta": "rad/s^3",
}


@dataclass(frozen=True, slots=True)
class OmniTrajectory(SampledExport):
    """A translation along a curve with an independent, jerk-limited orientation.

    Built by :func:`trajopt.timing.orient`; the constructor checks shapes and consistency
    only. It offers the public interface of :class:`trajopt.Trajectory` (``duration``,
    ``length``, ``path``, ``v_start``, ``v_end``, ``sample``, ``sample_uniform``,
    ``motion``, ``state_at``, ``to_dict``, ``to_json``, ``to_csv``, ``to_poses``,
    ``to_mcap``, ``stats``, ``steps``); see the module docstring for what the samples mean.

    Parameters
    ----------
    translation : Trajectory
        The timed motion along the path (duration ``T``, s). When the orientation outlasts
        it, it must end at rest (``v_end == 0``).
    robot : Robot
        The limits held (an omnidirectional robot).
    rows : array_like, shape (p, 5)
        The orientation's constant-jerk phases ``(t0, theta, omega, alpha, zeta)``: start
        time (s, ``rows[0, 0] == 0``, non-decreasing), orientation (rad, unwrapped), rate
        (rad/s), acceleration (rad/s^2) at that start, and the jerk during the phase
        (rad/s^3). ``p == 0`` for a constant orientation.
    turn_duration : float
        End time of the orientation profile ``T_rot`` (s), ``>= rows[-1, 0]``; from then on
        the orientation is exactly ``theta_end`` at rest.
    theta_start, theta_end : float
        Orientation at the start and at the end (rad); equal when ``p == 0``.
    stats : dict
        The translation's statistics and ``orientation`` (turn, durations, limits).
    steps : object, optional
        The planner's intermediate results (``trajopt.planning.PlanSteps``), else ``None``.

    Attributes
    ----------
    duration : float
        ``max(T, T_rot)`` (s).

    Raises
    ------
    InvalidInputError
        Not a :class:`Trajectory` or :class:`Robot`, rows of the wrong shape, unordered or
        non-finite, a ``turn_duration`` before the last row, non-finite headings, or an
        orientation that outlasts a translation ending in motion.
    """

    own_orientation: ClassVar[bool] = True

    translation: Trajectory
    robot: Robot
    rows: np.ndarray
    turn_duration: float
    theta_start: float
    theta_end: float
    stats: dict[str, Any] = field(default_factory=dict)
    steps: Any = None
    duration: float = field(init=False)

    def __post_init__(self) -> None:
        if not isinstance(self.translation, Trajectory):
            raise InvalidInputError(
                f"translation must be a trajopt.Trajectory, got {type(self.translation).__name__}"
            )
        if not isinstance(self.robot, Robot):
            raise InvalidInputError(
                f"robot must be a trajopt.Robot, got {type(self.robot).__name__}"
            )
        rows = readonly(self.rows)
        if rows.size == 0:  # no turn: (0, 5) whatever the empty shape given
            rows = readonly(np.zeros((0, 5)))
        if rows.ndim != 2 or rows.shape[1] != 5 or not np.all(np.isfinite(rows)):
            raise InvalidInputError(
                f"rows must be a finite array of shape (p, 5), got shape {rows.shape}"
            )
        if rows.shape[0] and (rows[0, 0] != 0.0 or np.any(np.diff(rows[:, 0]) < 0.0)):
            raise InvalidInputError(
                "rows[:, 0] (phase start times) must start at 0 and not decrease"
            )
        object.__setattr__(self, "rows", rows)
        last = float(rows[-1, 0]) if rows.shape[0] else 0.0
        t_rot = number("turn_duration", self.turn_duration, unit="s", lo=last)
        object.__setattr__(self, "turn_duration", t_rot)
        h0 = number("theta_start", self.theta_start, unit="rad")
        h1 = number("theta_end", self.theta_end, unit="rad")
        if rows.shape[0] == 0 and h1 != h0:
            raise InvalidInputError(
                f"theta_end {h1!r} must equal theta_start {h0!r} without orientation rows"
            )
        object.__setattr__(self, "theta_start", h0)
        object.__setattr__(self, "theta_end", h1)
        t_drive = self.translation.duration
        if t_rot > t_drive and self.translation.v_end != 0.0:
            raise InvalidInputError(
                f"the orientation ends at {t_rot:.6g} s, after the translation ({t_drive:.6g} s), "
                f"which ends moving at v_end = {self.translation.v_end!r} m/s: the robot cannot "
                "stand at the end while it finishes turning"
            )
        object.__setattr__(self, "duration", max(t_drive, t_rot))

    # ------------------------------------------------------------------ basic
    @property
    def path(self) -> Any:
        """The curve driven: the translation's ``path`` (a ``ParametricCurve``)."""
        return self.translation.path

    @property
    def length(self) -> float:
        """Arc length of the path (m)."""
        return self.translation.length

    @property
    def v_start(self) -> float:
        """Speed along the path at the start (m/s)."""
        return self.translation.v_start

    @property
    def v_end(self) -> float:
        """Speed along the path at the end (m/s); 0 when the turn outlasts the drive."""
        return self.translation.v_end

    @property
    def turn_rad(self) -> float:
        """The signed angle the orientation turns, ``theta_end - theta_start`` (rad)."""
        return self.theta_end - self.theta_start

    @property
    def n_phases(self) -> int:
        """Number of constant-jerk phases of the orientation."""
        return int(self.rows.shape[0])

    def motion(self, t: np.ndarray | float) -> tuple[np.ndarray, ...]:
        """Return the translation along the path: ``(s, v, a, jerk)`` at times ``t`` (s).

        Each of the shape of ``t`` (m, m/s, m/s^2, m/s^3); times are clipped to
        ``[0, duration]``, and past the translation's own duration the state is its end
        ``(length, v_end, 0, 0)``.
        """
        tt = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        return self.translation.motion(tt)

    def orientation_at(self, t: float) -> Orientation:
        """Return the body's orientation, yaw rate and yaw acceleration at ``t`` (s)."""
        theta, omega, alpha, _ = (float(x) for x in self.orientation(t))
        return Orientation(theta, omega, alpha)

    def orientation(self, t: np.ndarray | float) -> tuple[np.ndarray, ...]:
        """Return the orientation: ``(theta, omega, alpha, zeta)`` at times ``t`` (s).

        Parameters
        ----------
        t : float or array_like, any shape
            Times (s); clipped to ``[0, duration]``.

        Returns
        -------
        tuple of ndarray, each of the shape of ``t``
            Orientation (rad, unwrapped), its rate (rad/s), acceleration (rad/s^2) and jerk
            (rad/s^3); at and after ``turn_duration`` exactly ``(theta_end, 0, 0, 0)``.
        """
        tt = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        rows = self.rows
        if rows.shape[0] == 0:
            zero = np.zeros_like(tt)
            return zero + self.theta_end, zero, zero.copy(), zero.copy()
        k = np.clip(np.searchsorted(rows[:, 0], tt, side="right") - 1, 0, rows.shape[0] - 1)
        tau = tt - rows[k, 0]
        th0, w0, al0, z = rows[k, 1], rows[k, 2], rows[k, 3], rows[k, 4]
        th = th0 + tau * (w0 + tau * (0.5 * al0 + tau * z / 6.0))
        w = w0 + tau * (al0 + 0.5 * z * tau)
        al = al0 + z * tau
        end = tt >= self.turn_duration
        return (
            np.where(end, self.theta_end, th),
            np.where(end, 0.0, w),
            np.where(end, 0.0, al),
            np.where(end, 0.0, z),
        )

    def sample(self, t: np.ndarray | float) -> OmniSample:
        """Evaluate the motion at times ``t`` (vectorised).

        Parameters
        ----------
        t : float or array_like, any shape
            Times (s); clipped to ``[0, duration]``.

        Returns
        -------
        OmniSample
            Read-only arrays of the shape of ``t``: ``theta``/``omega`` the orientation and
            its rate, ``course``, ``vx``, ``vy``, ``v_body_x``, ``v_body_y`` set, no wheel
            speeds (module docstring).
        """
        tt = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        tr = self.translation.sample(tt)
        theta, omega, _, _ = self.orientation(tt)
        v = np.asarray(tr.v)
        course = np.asarray(tr.theta)
        vx, vy = v * np.cos(course), v * np.sin(course)
        c, s = np.cos(theta), np.sin(theta)
        arrays = {
            "t": tt,
            "x": tr.x,
            "y": tr.y,
            "theta": theta,
            "v": v,
            "omega": omega,
            "a": tr.a,
            "jerk": tr.jerk,
            "a_lat": tr.a_lat,
            "kappa": tr.kappa,
            "s": tr.s,
            "course": course,
            "vx": vx,
            "vy": vy,
            "v_body_x": c * vx + s * vy,
            "v_body_y": c * vy - s * vx,
        }
        return OmniSample(**{k: readonly(x) for k, x in arrays.items()})

    def after(self, t: float, translation: Trajectory) -> OmniTrajectory:
        """Return the motion from time ``t`` (s) on, its clock starting at 0 there.

        The orientation's constant-jerk phases after ``t`` are kept as they are, shifted by
        ``t``; the phase holding ``t`` starts at ``t`` with the orientation's state there
        (angle, rate, acceleration), so the samples are this trajectory's, shifted in time
        (to rounding). The translation's rest is the caller's (a re-plan cuts and certifies
        it again: :func:`trajopt.replan._keep.keep_rest`).

        Parameters
        ----------
        t : float
            The cut (s), in ``[0, T)``: the translation is still driving.
        translation : Trajectory
            ``self.translation`` from ``t`` on (duration ``T - t`` to 1e-9 s).

        Returns
        -------
        OmniTrajectory
            Of duration ``max(T, T_rot) - t``, with this trajectory's ``stats`` and
            ``steps``; ``theta_start`` is the orientation at ``t``, ``theta_end`` this one's.

        Raises
        ------
        InvalidInputError
            ``t`` not in ``[0, T)``, or ``translation`` not a :class:`Trajectory` of that
            duration.
        """
        t_drive = self.translation.duration
        tt = number("t", t, unit="s", lo=0.0)
        if not tt < t_drive:
            raise InvalidInputError(
                f"t must lie before the translation's end ({t_drive:.6g} s) to cut it, got {tt!r}"
            )
        if (
            not isinstance(translation, Trajectory)
            or abs(translation.duration - (t_drive - tt)) > 1e-9
        ):
            what = (
                f"duration {translation.duration!r} s"
                if isinstance(translation, Trajectory)
                else type(translation).__name__
            )
            raise InvalidInputError(
                f"translation must be this translation from t = {tt!r} s on (a Trajectory of "
                f"duration {t_drive - tt!r} s), got {what}"
            )
        rows, t_rot = self.orientation_after(tt)
        theta = float(rows[0, 1]) if rows.shape[0] else self.theta_end
        return OmniTrajectory(
            translation=translation,
            robot=self.robot,
            rows=rows,
            turn_duration=t_rot,
            theta_start=theta,
            theta_end=self.theta_end,
            stats=dict(self.stats),
            steps=self.steps,
        )

    def orientation_after(self, t: float) -> tuple[np.ndarray, float]:
        """Return the orientation's profile from time ``t`` (s) on, its clock starting there.

        Parameters
        ----------
        t : float
            The cut (s), in ``[0, duration]``.

        Returns
        -------
        (ndarray, float)
            The rows ``(t0, theta, omega, alpha, zeta)`` after ``t`` (the first one starts
            at 0 with the orientation's state at ``t``, the others are this profile's,
            shifted by ``t``; shape ``(0, 5)`` once the turn is over) and the time left to
            turn (s, ``max(0, turn_duration - t)``).

        Raises
        ------
        InvalidInputError
            ``t`` is not a number in ``[0, duration]``.
        """
        tt = number("t", t, unit="s", lo=0.0, hi=self.duration)
        rows, t_rot = self.rows, self.turn_duration - tt
        if rows.shape[0] == 0 or t_rot <= 0.0:
            return np.zeros((0, 5)), 0.0
        theta, omega, alpha, _ = (float(x) for x in self.orientation(tt))
        k = int(np.searchsorted(rows[:, 0], tt, side="right")) - 1
        later = rows[k + 1 :].copy()
        later[:, 0] -= tt
        return np.vstack([[0.0, theta, omega, alpha, rows[k, 4]], later]), float(t_rot)

    def state_at(self, t: float) -> State:
        """Return the translation's :class:`~trajopt.robot._state.State` at time ``t`` (s).

        A :class:`State` describes the motion along the path (what a re-plan continues):
        its ``theta`` is the **direction of travel** (``course``), not the orientation,
        with the path's curvature, the speed and the tangential acceleration. The
        orientation at ``t`` is :meth:`orientation`.

        Raises
        ------
        InvalidInputError
            ``t`` is not a number in ``[0, duration]``.
        """
        tt = number("t", t, unit="s", lo=0.0, hi=self.duration)
        return self.translation.state_at(min(tt, self.translation.duration))

    # ------------------------------------------------------------------ export
    def to_dict(self, dt: float = 0.01) -> dict[str, Any]:
        """Return a JSON-ready description: units, robot, stats, the exact phases and samples.

        The layout of :meth:`Trajectory.to_dict`, with ``translation`` (its duration and
        phases ``t``, ``s``, ``v``, ``a``, ``jerk``) and ``orientation`` (its start and end,
        duration and rows ``t``, ``theta``, ``omega``, ``alpha``, ``zeta``) in place of
        ``phases``.

        Parameters
        ----------
        dt : float
            Sample spacing (s) of the ``samples`` table.
        """
        tr = self.translation
        translation = {
            "duration": tr.duration,
            "phases": {
                "units": {"t": "s", "s": "m", "v": "m/s", "a": "m/s^2", "jerk": "m/s^3"},
                "t": tr.phase_t.tolist(),
                "s": tr.phase_s.tolist(),
                "v": tr.phase_v.tolist(),
                "a": tr.phase_a.tolist(),
                "jerk": tr.phase_j.tolist(),
            },
        }
        orientation = {
            "theta_start": self.theta_start,
            "theta_end": self.theta_end,
            "duration": self.turn_duration,
            "phases": {
                "units": dict(ORIENTATION_UNITS),
                **{k: self.rows[:, i].tolist() for i, k in enumerate(ORIENTATION_UNITS)},
            },
        }
        extra = {"translation": translation, "orientation": orientation}
        return export_dict(self, "trajopt.OmniTrajectory", dt, extra)

    def __repr__(self) -> str:
        return (
            f"OmniTrajectory(duration={self.duration:.4g} s, length={self.length:.4g} m, "
            f"turn={self.turn_rad:.4g} rad in {self.turn_duration:.4g} s)"
        )
