"""The stop-and-turn trajectory: a polyline driven straight, turning in place at rest.

Built by :func:`trajopt.timing.stop_and_turn` (the producer; its limits are described there).

Sampling conventions (:class:`~trajopt.motion._samples.TrajectorySample`): ``v``, ``a``,
``jerk`` and ``s`` describe the motion along the path (``s`` is the distance travelled, it
never decreases); ``omega`` is ``d theta / dt``. **``kappa`` is 0 everywhere**: the path is
straight between its vertices, and at a vertex the robot turns at rest, where the curvature
``omega / v`` is undefined; a finite convention keeps the CSV/JSON writers and
:mod:`trajopt.metrics` working (``a_lat = kappa v^2 = 0`` as well). The wheel speeds are
``v -+ omega * track_width / 2``, which is right both on segments and during turns.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from trajopt.errors import InvalidInputError
from trajopt.geometry import PolylineCurve
from trajopt.motion._samples import TrajectorySample, make_sample
from trajopt.motion._trajectory import AtRestEnds, export_dict
from trajopt.robot import Robot
from trajopt.validation import readonly


# ====================================================================== trajectory
@dataclass(frozen=True, slots=True)
class StopAndTurnTrajectory(AtRestEnds):
    """A polyline driven with stops and turns in place (see the module docstring).

    Built by :func:`stop_and_turn` (or by :class:`trajopt.Planner` with
    ``fallback="stop_and_turn"``); the constructor is internal and checks shapes only.
    It offers the public interface of :class:`trajopt.Trajectory`: ``duration``,
    ``length``, ``sample``, ``sample_uniform``, ``motion``, ``to_dict``, ``to_json``,
    ``to_csv``, ``stats``, ``steps``, ``path``, ``robot``, ``v_start``, ``v_end``.

    Parameters
    ----------
    path : PolylineCurve
        The polyline driven (vertices ``path.points``, shape (n, 2), m), after dropping
        zero-length segments and straight-on vertices.
    robot : Robot
        The limits held.
    phase_t : array_like, shape (p,)
        Start time of each constant-jerk phase (s), non-decreasing, ``phase_t[0] == 0``.
    phase_seg : array_like of int, shape (p,)
        Segment of each phase: the robot is on segment ``k`` (from vertex ``k`` to
        ``k + 1``) at in-segment distance ``sigma``.
    phase_sigma, phase_v, phase_a, phase_j : array_like, shape (p,)
        Start state along the segment (m, m/s, m/s^2) and jerk (m/s^3) of each phase; all
        zero but ``sigma`` (0 or the segment's length) during a turn.
    phase_theta, phase_omega, phase_alpha, phase_zeta : array_like, shape (p,)
        Start heading (rad, unwrapped), yaw rate (rad/s), yaw acceleration (rad/s^2) and yaw
        jerk (rad/s^3) of each phase; all zero but ``theta`` while driving.
    duration : float
        End time (s).
    theta_end : float
        Heading at the end (rad, unwrapped).
    stats : dict
        ``fallback = "stop_and_turn"``, counts and durations; the planner adds the reason.
    steps : object, optional
        ``trajopt._planner.PlanSteps`` when planned by :class:`trajopt.Planner`
        (its ``smooth_path`` is ``None``).
    """

    polyline: ClassVar[bool] = True

    path: PolylineCurve
    robot: Robot
    phase_t: np.ndarray
    phase_seg: np.ndarray
    phase_sigma: np.ndarray
    phase_v: np.ndarray
    phase_a: np.ndarray
    phase_j: np.ndarray
    phase_theta: np.ndarray
    phase_omega: np.ndarray
    phase_alpha: np.ndarray
    phase_zeta: np.ndarray
    duration: float
    theta_end: float
    stats: dict[str, Any] = field(default_factory=dict)
    steps: Any = None
    _seg_s: np.ndarray = field(init=False, repr=False, compare=False)
    _seg_len: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        names = (
            "phase_t",
            "phase_sigma",
            "phase_v",
            "phase_a",
            "phase_j",
            "phase_theta",
            "phase_omega",
            "phase_alpha",
            "phase_zeta",
        )
        shape = np.shape(self.phase_t)
        for n in names:
            arr = readonly(getattr(self, n))
            if arr.ndim != 1 or arr.shape != shape or arr.shape[0] < 1:
                raise InvalidInputError(
                    f"{n} must have shape (p,) with p >= 1 like phase_t {shape}, got {arr.shape}"
                )
            object.__setattr__(self, n, arr)
        seg = np.array(self.phase_seg, dtype=np.int64)
        pts = self.path.points
        if seg.shape != shape or (seg.size and (seg.min() < 0 or seg.max() > len(pts) - 2)):
            raise InvalidInputError(
                f"phase_seg must have shape {shape} with segment indices in 0..{len(pts) - 2}"
            )
        seg.flags.writeable = False
        object.__setattr__(self, "phase_seg", seg)
        object.__setattr__(self, "duration", float(self.duration))
        object.__setattr__(self, "theta_end", float(self.theta_end))
        seg_len = np.hypot(*np.diff(pts, axis=0).T)
        seg_s = np.concatenate([[0.0], np.cumsum(seg_len)])
        object.__setattr__(self, "_seg_s", readonly(seg_s))
        object.__setattr__(self, "_seg_len", readonly(seg_len))

    # ------------------------------------------------------------------ basic
    @property
    def vertices(self) -> np.ndarray:
        """The polyline's vertices, shape (n, 2) (m): ``path.points``."""
        return self.path.points

    @property
    def length(self) -> float:
        """Length of the polyline (m)."""
        return float(self._seg_s[-1])

    @property
    def n_phases(self) -> int:
        """Number of constant-jerk phases (translations and turns)."""
        return int(self.phase_t.shape[0])

    def _phase(self, t: np.ndarray | float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        tt = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        k = np.searchsorted(self.phase_t, tt, side="right") - 1
        k = np.clip(k, 0, self.phase_t.shape[0] - 1)
        return tt, k, tt - self.phase_t[k]

    def _translation(self, k: np.ndarray, tau: np.ndarray, end: np.ndarray):
        seg = self.phase_seg[k]
        j = self.phase_j[k]
        a0 = self.phase_a[k]
        v0 = self.phase_v[k]
        sig = self.phase_sigma[k] + tau * (v0 + tau * (0.5 * a0 + tau * j / 6.0))
        sig = np.clip(sig, 0.0, self._seg_len[seg])
        v = v0 + tau * (a0 + 0.5 * j * tau)
        a = a0 + j * tau
        sig = np.where(end, self._seg_len[seg], sig)
        v = np.where(end, 0.0, np.maximum(v, 0.0))
        a = np.where(end, 0.0, a)
        j = np.where(end, 0.0, j)
        return seg, sig, v, a, j

    def motion(self, t: np.ndarray | float) -> tuple[np.ndarray, ...]:
        """Return the motion along the path: ``(s, v, a, jerk)`` at times ``t`` (s).

        Times are clipped to ``[0, duration]``; at and after ``duration`` the state is exactly
        ``(length, 0, 0, 0)``. During a turn ``v = a = jerk = 0``.
        """
        tt, k, tau = self._phase(t)
        end = tt >= self.duration
        seg, sig, v, a, j = self._translation(k, tau, end)
        return self._seg_s[seg] + sig, v, a, j

    def heading_motion(self, t: np.ndarray | float) -> tuple[np.ndarray, ...]:
        """Return the heading: ``(theta, omega, alpha, zeta)`` at times ``t`` (s).

        Heading (rad, unwrapped), yaw rate (rad/s), yaw acceleration (rad/s^2) and yaw jerk
        (rad/s^3); ``omega = alpha = zeta = 0`` while driving. At and after ``duration``:
        exactly ``(theta_end, 0, 0, 0)``.
        """
        tt, k, tau = self._phase(t)
        end = tt >= self.duration
        return self._heading(k, tau, end)

    def _heading(self, k: np.ndarray, tau: np.ndarray, end: np.ndarray):
        z = self.phase_zeta[k]
        al0 = self.phase_alpha[k]
        w0 = self.phase_omega[k]
        th = self.phase_theta[k] + tau * (w0 + tau * (0.5 * al0 + tau * z / 6.0))
        w = w0 + tau * (al0 + 0.5 * z * tau)
        al = al0 + z * tau
        th = np.where(end, self.theta_end, th)
        w = np.where(end, 0.0, w)
        al = np.where(end, 0.0, al)
        z = np.where(end, 0.0, z)
        return th, w, al, z

    def sample(self, t: np.ndarray | float) -> TrajectorySample:
        """Evaluate the trajectory at times ``t`` (vectorised).

        Parameters
        ----------
        t : float or array_like, any shape
            Times (s); clipped to ``[0, duration]``.

        Returns
        -------
        TrajectorySample
            Read-only arrays of the shape of ``t``; ``kappa = a_lat = 0`` (module docstring).
        """
        tt, k, tau = self._phase(t)
        end = tt >= self.duration
        seg, sig, v, a, j = self._translation(k, tau, end)
        theta, omega, _, _ = self._heading(k, tau, end)
        pts = self.path.points
        f = (sig / self._seg_len[seg])[..., None]
        xy = (1.0 - f) * pts[seg] + f * pts[seg + 1]
        zero = np.zeros_like(tt)
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
            a_lat=zero,
            kappa=zero,
            s=self._seg_s[seg] + sig,
        )

    # ------------------------------------------------------------------ export
    def to_dict(self, dt: float = 0.01) -> dict[str, Any]:
        """Return a JSON-ready description: units, robot, stats, vertices, exact phases, samples.

        Parameters
        ----------
        dt : float
            Sample spacing (s) of the ``samples`` table.
        """
        phases = {
            "units": {
                "t": "s",
                "segment": "index",
                "sigma": "m",
                "v": "m/s",
                "a": "m/s^2",
                "jerk": "m/s^3",
                "theta": "rad",
                "omega": "rad/s",
                "alpha": "rad/s^2",
                "zeta": "rad/s^3",
            },
            "t": self.phase_t.tolist(),
            "segment": self.phase_seg.tolist(),
            "sigma": self.phase_sigma.tolist(),
            "v": self.phase_v.tolist(),
            "a": self.phase_a.tolist(),
            "jerk": self.phase_j.tolist(),
            "theta": self.phase_theta.tolist(),
            "omega": self.phase_omega.tolist(),
            "alpha": self.phase_alpha.tolist(),
            "zeta": self.phase_zeta.tolist(),
        }
        extra = {
            "vertices": {"unit": "m", "xy": self.vertices.tolist()},
            "theta_end": self.theta_end,
            "phases": phases,
        }
        return export_dict(self, "trajopt.StopAndTurnTrajectory", dt, extra)

    def __repr__(self) -> str:
        return (
            f"StopAndTurnTrajectory(duration={self.duration:.4g} s, length={self.length:.4g} m, "
            f"vertices={len(self.vertices)}, turns={self.stats.get('n_turns', '?')})"
        )
