"""A timed trajectory along a planar curve: ``t -> (x, y, theta, v, omega, a, jerk, ...)``.

The motion along arc length ``s(t)`` is a chain of constant-jerk phases (the pieces of the
ruckig profiles and greedy steps made by :func:`trajopt.time_parameterize`). Each phase is
stored as its start time and start state ``(s, v, a)`` plus its jerk, so sampling any
number of times is a vectorised ``searchsorted`` and a cubic polynomial: no per-sample call
into ruckig. Pose, heading and curvature then come from the curve at ``u = u_at_s(s)``.
"""

from __future__ import annotations

import csv
import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar, NamedTuple

import numpy as np

from astar.files import atomic_write
from trajopt.errors import InvalidInputError
from trajopt.geometry import ParametricCurve
from trajopt.motion._phase_motion import phase_motion
from trajopt.motion._samples import (
    SAMPLE_UNITS,
    CarSample,
    TrajectorySample,
    make_sample,
)
from trajopt.robot import Robot, State
from trajopt.validation import number, readonly


class Orientation(NamedTuple):
    """A body's orientation (rad), yaw rate (rad/s) and yaw acceleration (rad/s^2)."""

    theta: float
    omega: float
    alpha: float


class SampledExport:
    """The sampling, file export and shape shared by every timed trajectory of :mod:`trajopt`.

    A subclass provides ``duration`` (s), ``sample(t)`` returning a
    :class:`TrajectorySample` and ``to_dict(dt)``; the helpers below give it
    ``sample_uniform``, ``to_poses`` and the writers ``to_json``, ``to_csv`` and
    ``to_mcap`` (atomic writes, each naming the frame of its poses). What a re-plan asks
    of a motion it answers itself: :meth:`playing` (the piece at a time),
    :meth:`orientation_at` and :meth:`translation_state`, and the flags
    :attr:`single_curve`, :attr:`turning`, :attr:`steering_at_rest`, :attr:`polyline` and
    :attr:`own_orientation`.
    """

    __slots__ = ()

    #: One timed curve (a :class:`Trajectory`): it can be cut, kept and braked along.
    single_curve: ClassVar[bool] = False
    #: A rotation at rest (a turn in place).
    turning: ClassVar[bool] = False
    #: A car's steering at rest (the steering angle changes, nothing else moves).
    steering_at_rest: ClassVar[bool] = False
    #: Straight segments with turns in place at rest between them (no smooth curve).
    polyline: ClassVar[bool] = False
    #: The body's orientation is a motion of its own, beside the translation (omni).
    own_orientation: ClassVar[bool] = False

    def playing(self, t: float) -> tuple[SampledExport, float]:
        """Return the motion playing at time ``t`` (s) and the time in it: itself here."""
        return self, t

    def plan_at(self, t: float) -> tuple[SampledExport, float]:
        """Return the plan a re-plan at ``t`` (s) continues, and the time in it: itself here."""
        return self, t

    def orientation_at(self, t: float) -> Orientation | None:
        """Return the body's own orientation at ``t`` (s), or ``None`` (it faces its travel)."""
        return None

    def translation_state(self, t: float) -> State:
        """Return the moving state a re-plan continues at ``t`` (s): :meth:`state_at` here."""
        return self.state_at(t)  # type: ignore[attr-defined]

    def sample_uniform(self, dt: float) -> TrajectorySample:
        """Sample every ``dt`` seconds from 0, plus the end time ``duration``.

        Parameters
        ----------
        dt : float
            Time step (s), > 0.
        """
        if not (isinstance(dt, (int, float)) and math.isfinite(dt) and dt > 0):
            raise InvalidInputError(f"dt must be a finite number > 0 s, got {dt!r}")
        duration = self.duration  # type: ignore[attr-defined]
        n = int(math.floor(duration / dt + 1e-9))
        t = np.arange(n + 1) * dt
        if t[-1] < duration - 1e-12:
            t = np.append(t, duration)
        else:
            t[-1] = min(t[-1], duration)
        return self.sample(t)  # type: ignore[attr-defined]

    def to_json(self, path: str | os.PathLike, dt: float = 0.01, *, frame_id: str = "map") -> Path:
        """Write :meth:`to_dict` as JSON (atomically: temp file + rename); returns the path.

        The top-level ``frame_id`` names the frame of ``x``, ``y`` and ``theta``.
        """
        frame = _frame_id(frame_id)
        out = {"frame_id": frame, **self.to_dict(dt)}  # type: ignore[attr-defined]
        return _atomic_write(Path(path), json.dumps(out, indent=1))

    def to_csv(self, path: str | os.PathLike, dt: float = 0.01, *, frame_id: str = "map") -> Path:
        """Write samples every ``dt`` seconds as CSV (atomically); returns the path.

        The first line is the header: one column per sampled quantity (``t``, ``x``, ``y``,
        ``theta``, ``v``, ``omega``, ``a``, ``jerk``, ``a_lat``, ``kappa``, ``s``, then
        ``v_left``, ``v_right`` for a differential drive with a track width, or ``course``,
        ``vx``, ``vy``, ``v_body_x``, ``v_body_y`` for an omnidirectional motion), each named
        with its unit in brackets, e.g. ``t [s]``, ``v [m/s]``. The pose columns (and the
        world-frame ``course``, ``vx``, ``vy``) also name their frame in parentheses:
        ``x [m] (map)``, ``y [m] (map)``, ``theta [rad] (map)``. Every other
        line is one sample, all numbers, so the file reads with no options:
        ``pandas.read_csv(path)`` keeps these column names, and
        ``numpy.genfromtxt(path, delimiter=",", names=True)`` gives a structured array whose
        field names drop the brackets and other punctuation and put ``_`` for spaces
        (``t_s``, ``x_m_map``, ``theta_rad_map``, ``v_ms``, ``a_ms2``).

        Parameters
        ----------
        path : str or os.PathLike
            Output file; missing parent folders are created.
        dt : float
            Time step (s), > 0; the end time ``duration`` is always the last row.
        frame_id : str
            Frame of ``x``, ``y`` and ``theta`` (default ``"map"``). It goes into the header,
            so it may not contain ``,``, ``"``, ``#``, ``(``, ``)`` or control characters.

        Raises
        ------
        InvalidInputError
            ``dt`` is not a finite number > 0, or ``frame_id`` is not a non-empty one-line
            string that a CSV header can carry.
        """
        frame = _csv_frame_id(frame_id)
        smp = self.sample_uniform(dt).as_dict()
        names = list(smp)
        import io

        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow([_csv_column(n, frame) for n in names])
        cols = np.column_stack([np.asarray(smp[n]) for n in names])
        for row in cols:
            w.writerow([repr(float(x)) for x in row])
        return _atomic_write(Path(path), buf.getvalue())

    def state_at(self, t: float) -> State:
        """Return the robot's :class:`~trajopt.robot._state.State` at time ``t`` (s).

        Position, heading, signed curvature, speed and tangential acceleration of the
        trajectory at ``t``, which must lie in ``[0, duration]``: the start of a re-plan
        (:meth:`trajopt.Planner.replan`).

        Raises
        ------
        InvalidInputError
            ``t`` is not a number in ``[0, duration]``.
        """
        duration = float(self.duration)  # type: ignore[attr-defined]
        tt = number("t", t, unit="s", lo=0.0, hi=duration)
        smp = self.sample(np.array([tt]))  # type: ignore[attr-defined]
        return State(
            x=float(smp.x[0]),
            y=float(smp.y[0]),
            theta=float(smp.theta[0]),
            kappa=float(smp.kappa[0]),
            v=max(0.0, float(smp.v[0])),
            a=float(smp.a[0]),
        )

    def to_poses(self, dt: float = 0.01) -> np.ndarray:
        """Poses every ``dt`` seconds in the shape of ``nav_msgs/Path``, without ROS.

        Parameters
        ----------
        dt : float
            Time step (s), > 0; the end time is always included.

        Returns
        -------
        ndarray, structured, shape (n,)
            Records ``(t, x, y, qz, qw)`` of float64: time (s), position (m) and the
            heading as a unit quaternion about z (``qz = sin(theta/2)``,
            ``qw = cos(theta/2)``).
        """
        smp = self.sample_uniform(dt)
        out = np.empty(len(smp.t), dtype=POSE_DTYPE)
        half = 0.5 * np.asarray(smp.theta)
        out["t"], out["x"], out["y"] = smp.t, smp.x, smp.y
        out["qz"], out["qw"] = np.sin(half), np.cos(half)
        return out

    def to_mcap(
        self,
        path: str | os.PathLike,
        dt: float = 0.01,
        *,
        frame_id: str = "map",
        child_frame_id: str = "base_link",
        start_time: float = 0.0,
        movers: Any = None,
        movers_dt: float | None = None,
    ) -> Path:
        """Write a ROS 2 MCAP file: maps, path, corridor, stamped poses and twists.

        See :func:`trajopt.motion._mcap.write_mcap` (topics, types, frames and stamps);
        ``movers`` (predicted :class:`trajopt.MovingObstacle`) adds their markers, every
        ``movers_dt`` seconds (default ``dt``).
        """
        from trajopt.motion._mcap import write_mcap

        return write_mcap(
            self,
            path,
            dt=dt,
            frame_id=frame_id,
            child_frame_id=child_frame_id,
            start_time=start_time,
            movers=movers,
            movers_dt=movers_dt,
        )


class AtRestEnds(SampledExport):
    """A :class:`SampledExport` that starts and ends at rest (stop-and-turn moves, turns)."""

    __slots__ = ()

    @property
    def v_start(self) -> float:
        """Speed at the start: always 0 (m/s)."""
        return 0.0

    @property
    def v_end(self) -> float:
        """Speed at the end: always 0 (m/s)."""
        return 0.0


#: The record of :meth:`Trajectory.to_poses`.
POSE_DTYPE = np.dtype([("t", "f8"), ("x", "f8"), ("y", "f8"), ("qz", "f8"), ("qw", "f8")])


def _frame_id(value: object) -> str:
    if not isinstance(value, str) or not value or "\n" in value:
        raise InvalidInputError(f"frame_id must be a non-empty one-line string, got {value!r}")
    return value


# Sampled quantities whose CSV column names the frame (the pose, and the direction of
# travel and velocity of an omnidirectional motion, in that frame).
_CSV_POSE_COLUMNS: tuple[str, ...] = ("x", "y", "theta", "course", "vx", "vy")

# Characters a ``frame_id`` may not contain in a CSV header: the delimiter, the quote,
# numpy's comment mark, the parentheses around the frame.
_CSV_FRAME_FORBIDDEN = frozenset(',"#()')


def _csv_column(name: str, frame_id: str) -> str:
    """Return the CSV header of the sampled quantity ``name``.

    ``"<name> [<unit>]"`` with the unit from :data:`SAMPLE_UNITS`, followed by
    ``" (<frame_id>)"`` for the pose columns ``x``, ``y`` and ``theta`` (and the world-frame
    ``course``, ``vx`` and ``vy`` of an omnidirectional motion).
    """
    head = f"{name} [{SAMPLE_UNITS[name]}]"
    return f"{head} ({frame_id})" if name in _CSV_POSE_COLUMNS else head


def _csv_frame_id(value: object) -> str:
    frame = _frame_id(value)
    bad = sorted({c for c in frame if c in _CSV_FRAME_FORBIDDEN or not c.isprintable()})
    if bad:
        raise InvalidInputError(
            f"frame_id {frame!r} contains {''.join(bad)!r}: a CSV header's frame may not "
            "contain ',', '\"', '#', '(', ')' or control characters"
        )
    return frame


def export_dict(traj: Any, fmt: str, dt: float, extra: dict[str, Any]) -> dict[str, Any]:
    """Return the ``to_dict`` layout shared by the trajectory classes.

    A header (format, units, duration, length, end speeds, robot, stats), then ``extra``, then
    the ``samples``.
    """
    smp = traj.sample_uniform(dt).as_dict()
    units = {k: u for k, u in SAMPLE_UNITS.items() if k in smp}
    out: dict[str, Any] = {
        "format": fmt,
        "units": units,
        "duration": traj.duration,
        "duration_unit": "s",
        "length": traj.length,
        "length_unit": "m",
        "v_start": traj.v_start,
        "v_end": traj.v_end,
        "robot": traj.robot.to_dict(),
        "stats": _jsonable(traj.stats),
    }
    out.update(extra)
    out["samples"] = {k: np.asarray(x).tolist() for k, x in smp.items()}
    return out


@dataclass(frozen=True, slots=True)
class Trajectory(SampledExport):
    """A jerk-limited timed motion along a curve.

    Built by :func:`trajopt.time_parameterize`; the constructor checks shapes only.

    Parameters
    ----------
    path : ParametricCurve
        The curve followed (e.g. the smoother's ``SmoothPath``).
    robot : Robot
        The limits the timing holds.
    phase_t : array_like, shape (p,)
        Start time of each constant-jerk phase (s); ``phase_t[0] == 0``, non-decreasing.
    phase_s, phase_v, phase_a : array_like, shape (p,)
        Arc length (m), speed (m/s) and acceleration (m/s^2) at the start of each phase.
    phase_j : array_like, shape (p,)
        Jerk during each phase (m/s^3).
    duration : float
        End time (s); the motion ends at ``s = path.length`` with speed ``v_end``.
    v_start, v_end : float
        Speeds at the start and at the end (m/s).
    stats : dict
        Per-stage wall times (s) and counts; the pipeline may add its own entries.
    theta_grid_s, theta_grid : array_like, shape (g,)
        A dense table of the unwrapped heading (rad) against arc length (m), the reference
        that makes sampled headings continuous.
    u_grid : array_like, shape (g,) or (0,)
        Curve parameter at ``theta_grid_s``: a table that speeds up the arc-length lookup.
    steps : object, optional
        The pipeline's intermediate results (``trajopt._planner.PlanSteps``) when planned by
        :func:`trajopt.plan`, else ``None``.
    direction : {1, -1}
        Direction of travel along ``path`` of a car-like robot's body: ``+1`` (default)
        forwards; ``-1`` backwards: the robot's rear leads, so the samples have
        ``v = -ds/dt <= 0`` (and ``a``, ``jerk`` negated), ``theta`` = the path's tangent
        ``+ pi`` (the body's orientation; shifted by a multiple of ``2 pi`` so that it
        starts in ``[-pi, pi]``), ``kappa`` = minus the path's curvature (the body's
        ``omega / v``; ``omega`` is the tangent's turn rate, unchanged) and
        ``a_lat = omega * v``. The phases (``phase_*``) and ``s`` stay the unsigned motion
        along the path (distance travelled). Samples of a car-like robot
        (``drive="ackermann"``) carry ``direction`` (and the steering angle with a
        wheelbase).
    speed_limits : trajopt.SpeedLimits, optional
        The speed-limit zones the timing holds besides the robot's limits (``None``: none),
        kept so that a re-timing of the same path (:mod:`trajopt.moving`) holds them too.
    """

    single_curve: ClassVar[bool] = True

    path: ParametricCurve
    robot: Robot
    phase_t: np.ndarray
    phase_s: np.ndarray
    phase_v: np.ndarray
    phase_a: np.ndarray
    phase_j: np.ndarray
    duration: float
    v_start: float
    v_end: float
    stats: dict[str, Any] = field(default_factory=dict)
    theta_grid_s: np.ndarray = field(default_factory=lambda: readonly([]))
    theta_grid: np.ndarray = field(default_factory=lambda: readonly([]))
    u_grid: np.ndarray = field(default_factory=lambda: readonly([]))
    steps: Any = None
    direction: int = 1
    speed_limits: Any = None

    def __post_init__(self) -> None:
        if self.direction not in (1, -1) or isinstance(self.direction, bool):
            raise InvalidInputError(f"direction must be 1 or -1, got {self.direction!r}")
        object.__setattr__(self, "direction", int(self.direction))
        names = ("phase_t", "phase_s", "phase_v", "phase_a", "phase_j")
        arrays = [readonly(getattr(self, n)) for n in names]
        p = arrays[0].shape
        for n, arr in zip(names, arrays, strict=True):
            if arr.ndim != 1 or arr.shape != p or p[0] < 1:
                raise InvalidInputError(
                    f"{n} must have shape (p,) with p >= 1 like phase_t {p}, got {arr.shape}"
                )
            object.__setattr__(self, n, arr)
        if not math.isfinite(self.duration) or self.duration < arrays[0][-1]:
            raise InvalidInputError(
                f"duration must be finite and >= the last phase start {arrays[0][-1]}, "
                f"got {self.duration!r}"
            )
        object.__setattr__(self, "duration", float(self.duration))
        gs, gt = readonly(self.theta_grid_s), readonly(self.theta_grid)
        if gs.shape != gt.shape or gs.ndim != 1:
            raise InvalidInputError(
                f"theta_grid_s and theta_grid must have equal shapes (g,), got {gs.shape}, "
                f"{gt.shape}"
            )
        object.__setattr__(self, "theta_grid_s", gs)
        object.__setattr__(self, "theta_grid", gt)
        ug = readonly(self.u_grid)
        if ug.shape[0] and ug.shape != gs.shape:
            raise InvalidInputError(
                f"u_grid must be empty or have the shape of theta_grid_s {gs.shape}, got {ug.shape}"
            )
        object.__setattr__(self, "u_grid", ug)

    # ------------------------------------------------------------------ basic
    @property
    def length(self) -> float:
        """Arc length of the path (m)."""
        return float(self.path.length)

    @property
    def n_phases(self) -> int:
        """Number of constant-jerk phases."""
        return int(self.phase_t.shape[0])

    def motion(self, t: np.ndarray | float) -> tuple[np.ndarray, ...]:
        """Return the motion along the path only: ``(s, v, a, jerk)`` at times ``t`` (s).

        Times are clipped to ``[0, duration]``; at and after ``duration`` the state is exactly
        ``(length, v_end, 0, 0)`` (compiled: :func:`~trajopt.motion._phase_motion.phase_motion`).
        """
        tt = np.asarray(t, dtype=np.float64)
        out = phase_motion(
            self.phase_t,
            self.phase_s,
            self.phase_v,
            self.phase_a,
            self.phase_j,
            self.duration,
            self.length,
            float(self.v_end),
            np.ascontiguousarray(tt.reshape(-1)),
        )
        return tuple(x.reshape(tt.shape) for x in out)

    def _u_at_s(self, s: np.ndarray) -> np.ndarray:
        """Curve parameter at arc length ``s``.

        The dense ``u_grid`` table's guess refined by ``path.refine_u_at_s`` (Newton steps
        on the quadrature; compiled for a B-spline). Falls back to ``path.u_at_s`` without
        a table.
        """
        path = self.path
        if self.u_grid.shape[0] < 2:
            return np.asarray(path.u_at_s(s))
        u = np.array(np.interp(s, self.theta_grid_s, self.u_grid), dtype=float)
        ss = np.broadcast_to(np.asarray(s, dtype=float), u.shape)
        return path.refine_u_at_s(ss.reshape(-1), u.reshape(-1)).reshape(u.shape)

    def sample(self, t: np.ndarray | float) -> TrajectorySample | CarSample:
        """Evaluate the trajectory at times ``t`` (vectorised; a car's is a :class:`CarSample`).

        Parameters
        ----------
        t : float or array_like, any shape
            Times (s); clipped to ``[0, duration]``.

        Returns
        -------
        TrajectorySample
            Read-only arrays of the shape of ``t`` (see :class:`TrajectorySample`).
        """
        tt = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        s, v, a, j = self.motion(tt)
        path = self.path
        u = self._u_at_s(s)
        xy = np.asarray(path(u))
        raw = np.asarray(path.heading(u))
        kappa = np.asarray(path.curvature(u))
        if self.theta_grid_s.shape[0] >= 2:
            ref = np.interp(s, self.theta_grid_s, self.theta_grid)
            theta = raw + 2.0 * np.pi * np.round((ref - raw) / (2.0 * np.pi))
        else:
            theta = raw
        omega = kappa * v
        extra: dict[str, np.ndarray] = {}
        if self.robot.drive.signed_speed:
            d = float(self.direction)
            extra["direction"] = np.full(np.shape(v), d)
            if self.robot.drive.steering is not None:  # d kappa_body / dt = d dkappa/ds ds/dt
                extra["dkappa_dt"] = np.asarray(path.curvature_rate(u)) * v
            if d < 0.0:  # the body's quantities (class docstring)
                v, a, j, kappa = -v, -a, -j, -kappa
                theta = theta + self._reverse_shift()
        return make_sample(
            self.robot,
            t=tt,
            x=xy[..., 0],
            y=xy[..., 1],
            theta=theta,
            v=v,
            omega=omega,
            a=a,
            jerk=j,
            a_lat=omega * v,
            kappa=kappa,
            s=s,
            **extra,
        )

    def pose(self, t: np.ndarray) -> tuple[np.ndarray, ...]:
        """Return ``(x, y, theta, s, v)`` at times ``t`` (s): the pose and motion only.

        The same position (m), arc length (m) and speed (m/s, the body's: negative when
        driving in reverse) as :meth:`sample`; the heading (rad, the body's) is the path's
        tangent angle without :meth:`sample`'s continuous unwrapping (it differs from
        ``sample(t).theta`` by a multiple of ``2 pi``). No curvature, rates or sample object:
        a light evaluation for many times at once (the moving obstacles' certificate).

        Parameters
        ----------
        t : ndarray, shape (n,)
            Times (s); clipped to ``[0, duration]``.

        Returns
        -------
        x, y, theta, s, v : ndarray, shape (n,)
        """
        tt = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        s, v, _, _ = self.motion(tt)
        u = self._u_at_s(s)
        xy = np.asarray(self.path(u))
        theta = np.asarray(self.path.heading(u), dtype=float)
        if self.robot.drive.signed_speed and float(self.direction) < 0.0:
            v, theta = -v, theta + self._reverse_shift()
        return xy[..., 0], xy[..., 1], theta, s, v

    def _reverse_shift(self) -> float:
        """Return ``pi`` plus the multiple of ``2 pi`` that puts the body's start heading in ``[-pi, pi]``."""
        t0 = (
            float(self.theta_grid[0])
            if self.theta_grid.shape[0]
            else float(np.asarray(self.path.heading(self.path.domain[0])))
        )
        return math.pi - 2.0 * math.pi * round((t0 + math.pi) / (2.0 * math.pi))

    # ------------------------------------------------------------------ export
    def to_dict(self, dt: float = 0.01) -> dict[str, Any]:
        """Return a JSON-ready description: units, robot, stats, the exact phases and samples.

        Parameters
        ----------
        dt : float
            Sample spacing (s) of the ``samples`` table.
        """
        phases = {
            "units": {"t": "s", "s": "m", "v": "m/s", "a": "m/s^2", "jerk": "m/s^3"},
            "t": self.phase_t.tolist(),
            "s": self.phase_s.tolist(),
            "v": self.phase_v.tolist(),
            "a": self.phase_a.tolist(),
            "jerk": self.phase_j.tolist(),
        }
        extra: dict[str, Any] = {"phases": phases}
        if self.direction != 1:
            extra["direction"] = self.direction
        return export_dict(self, "trajopt.Trajectory", dt, extra)

    def __repr__(self) -> str:
        return (
            f"Trajectory(duration={self.duration:.4g} s, length={self.length:.4g} m, "
            f"phases={self.n_phases})"
        )


def _jsonable(x: Any) -> Any:
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, (str, int, float, bool)) or x is None:
        return x
    return repr(x)


def _atomic_write(path: Path, text: str) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)

    def write(tmp: Path) -> None:
        with open(tmp, "w", encoding="utf-8", newline="") as f:
            f.write(text)

    return atomic_write(path, write)
