"""The robot's motion on the time windows of the moving-obstacle certificate.

:func:`robot_windows` cuts a timed trajectory (a :class:`trajopt.Trajectory` or a chain of
them and motions at rest) into windows, each with its motion model: :class:`CurveMotion`
(a timed curve: its position, the bound ``rho_P`` of its motion over an interval, its turn
and curvature bounds, boxes of its positions) or :class:`StillMotion` (standing still,
turning in place). :func:`trajopt.moving.certify_movers` bounds the distances with them.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from trajopt.errors import InvalidInputError
from trajopt.geometry import BSplineCurve
from trajopt.moving._path_bounds import arc_kappa_kernel, kappa_ranges_of, path_boxes_of
from trajopt.smoother import SmoothPath


def profile_bounds(traj: Any) -> tuple[float, float]:
    """``(V, A)``: bounds of the speed (m/s) and |acceleration| (m/s^2) of ``s(t)`` over its phases."""
    pt, pv, pa, pj = traj.phase_t, traj.phase_v, traj.phase_a, traj.phase_j
    dur = np.append(np.diff(pt), traj.duration - pt[-1]).clip(0.0)
    a_end = pa + pj * dur
    v_end = pv + dur * (pa + 0.5 * pj * dur)
    with np.errstate(divide="ignore", invalid="ignore"):
        tau = np.where(pj != 0.0, -pa / pj, -1.0)
    inner = (tau > 0.0) & (tau < dur)
    v_peak = np.where(inner, pv + tau * (pa + 0.5 * pj * tau), 0.0)
    vmax = float(np.max(np.abs(np.concatenate([pv, v_end, v_peak, [traj.v_end]]))))
    amax = float(np.max(np.abs(np.concatenate([pa, a_end]))))
    return vmax, amax


def spline_of(path: Any) -> BSplineCurve | None:
    """Return the B-spline ``path`` evaluates unchanged (itself, a smooth path's curve), else ``None``."""
    if type(path) is BSplineCurve:
        return path
    if isinstance(path, SmoothPath) and type(path.curve) is BSplineCurve:
        return path.curve
    return None


class CurveMotion:
    """The robot on one timed curve, played from global time ``offset`` on its own clock.

    On a B-spline driven forwards with its arc-length table (the planner's trajectories),
    :meth:`at` evaluates the arc lengths at an interval's ends and middle in one compiled call
    (:meth:`trajopt.Trajectory.motion`) and the pose at the middles in another
    (:meth:`trajopt.geometry.BSplineCurve.pose_at_s`): the floats of
    :meth:`trajopt.Trajectory.pose`. Otherwise :meth:`at` calls ``pose``.
    """

    def __init__(self, traj: Any, offset: float) -> None:
        self.traj, self.offset = traj, float(offset)
        spline = spline_of(traj.path)
        reverse = traj.robot.drive.signed_speed and traj.direction < 0
        self.spline = None if reverse or traj.u_grid.shape[0] < 2 else spline
        self.vmax, self.amax = profile_bounds(traj)
        # the heading turns at most kappa per metre: bounds per arc-length interval
        # its maxima over index ranges (kept with the path's table)
        self.s_edges, k_top, self.kmax = kappa_ranges_of(traj.path)
        self.c2 = k_top * self.vmax**2 + self.amax  # |P''| (m/s^2), inf if unknown

    def s_at(self, t: np.ndarray) -> np.ndarray:
        """Return the arc length (m) at the curve's own times ``t`` (s): ``traj.motion``'s ``s``.

        ``t`` clipped to ``[0, duration]``, ``s`` to ``[0, length]``, exactly ``length`` from
        ``duration`` on (compiled, one loop: :meth:`trajopt.Trajectory.motion`).
        """
        return self.traj.motion(t)[0]

    def s_ends(self, t0: np.ndarray, t1: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Return :meth:`s_at` at the global times ``t0`` and ``t1`` (s), shape (n,) each: one call."""
        n = t0.shape[0]
        s = self.s_at(np.concatenate([t0, t1]) - self.offset)
        return s[:n], s[n:]

    def box(self, t0: np.ndarray, t1: np.ndarray) -> tuple[np.ndarray, ...]:
        """Return ``(x_min, x_max, y_min, y_max)`` (m): a box holding the robot's reference point during ``[t0, t1]``."""
        s0, s1 = self.s_ends(t0, t1)
        return path_boxes_of(self.traj.path).box(s0, s1)

    def box_rho(self, t0: np.ndarray, t1: np.ndarray) -> tuple[np.ndarray, ...]:
        """Return :meth:`box` and a bound (m) of :meth:`at`'s ``rho_P``: the arc ``s(t1) - s(t0)``."""
        s0, s1 = self.s_ends(t0, t1)
        x0, x1, y0, y1 = path_boxes_of(self.traj.path).box(s0, s1)
        return x0, x1, y0, y1, (s1 - s0).clip(0.0) * (1.0 + 1e-9) + 1e-12

    def at(self, t0: np.ndarray, tm: np.ndarray, t1: np.ndarray) -> tuple[np.ndarray, ...]:
        """Return the position (m), shape (n, 2), its bound ``rho_P`` (m) and velocity (m/s) at ``tm``."""
        tr, off, spline = self.traj, self.offset, self.spline
        if spline is not None:
            n = t0.shape[0]
            s, v, _, _ = tr.motion(np.concatenate([t0, t1, tm]) - off)
            s0, s1, sm, v = s[:n], s[n : 2 * n], s[2 * n :], v[2 * n :]
            p, th, _ = spline.pose_at_s(sm, tr.theta_grid_s, tr.u_grid)
        else:
            s0, s1 = self.s_ends(t0, t1)
            x, y, th, sm, v = tr.pose(tm - off)
            p = np.stack([x, y], axis=-1)
        rho = np.maximum(sm - s0, s1 - sm).clip(0.0) * (1.0 + 1e-9) + 1e-12
        kap = arc_kappa_kernel(self.s_edges, self.kmax, s0, s1)  # |kappa| on [s0, s1] (1/m)
        self.theta, self.turn = th, np.minimum(kap * rho, math.pi)
        self.c2_local = kap * self.vmax**2 + self.amax
        vel = np.empty((th.shape[0], 2))
        np.multiply(v, np.cos(th), out=vel[:, 0])
        np.multiply(v, np.sin(th), out=vel[:, 1])
        return p, rho, vel


class StillMotion:
    """The robot standing still, played from global time ``offset`` (a turn in place).

    Its position is fixed; its heading is sampled but not bounded between samples (a
    footprint counts by its circumscribed disc there).
    """

    c2 = 0.0
    c2_local = 0.0

    def __init__(self, piece: Any, offset: float) -> None:
        self.piece, self.offset = piece, float(offset)
        smp = piece.sample(np.array([0.0]))
        self.point = np.array([smp.x[0], smp.y[0]], dtype=float)

    def box(self, t0: np.ndarray, t1: np.ndarray) -> tuple[np.ndarray, ...]:
        """Return ``(x_min, x_max, y_min, y_max)`` (m): the point where it stands, for each interval."""
        x, y = (np.full(t0.shape, float(c)) for c in self.point)
        return x, x, y, y

    def box_rho(self, t0: np.ndarray, t1: np.ndarray) -> tuple[np.ndarray, ...]:
        """Return :meth:`box` and a zero bound of ``rho_P`` (m)."""
        return (*self.box(t0, t1), np.zeros(t0.shape))

    def at(self, t0: np.ndarray, tm: np.ndarray, t1: np.ndarray) -> tuple[np.ndarray, ...]:
        """Return the position (m), shape (n, 2), a zero bound and a zero velocity."""
        n = tm.shape[0]
        self.theta = np.asarray(self.piece.sample(tm - self.offset).theta, dtype=float)
        self.turn = np.full(n, math.pi)
        return np.broadcast_to(self.point, (n, 2)), np.zeros(n), np.zeros((n, 2))


def robot_windows(traj: Any) -> list[tuple[Any, float, float]]:
    """Return ``(motion model, t0, t1)`` (s) covering the trajectory's time, in order."""
    if getattr(traj, "single_curve", False):
        for name in ("motion", "sample", "duration", "robot", "phase_t", "phase_v", "path"):
            if not hasattr(traj, name):
                raise InvalidInputError(f"trajectory must be a trajopt.Trajectory (no {name!r})")
        return [(CurveMotion(traj, 0.0), 0.0, float(traj.duration))]
    pieces = getattr(traj, "pieces", None)
    if pieces is None or not hasattr(traj, "piece_times"):
        raise InvalidInputError(
            "trajectory must be a trajopt.Trajectory or a TrajectoryChain of curves and motions "
            f"at rest, got {type(traj).__name__}"
        )
    out = []
    times = np.asarray(traj.piece_times, dtype=float)
    for i, pc in enumerate(pieces):
        a, b = float(times[i]), float(times[i + 1])
        if pc.single_curve:
            out.append((CurveMotion(pc, a - float(traj.starts[i])), a, b))
        elif pc.turning or pc.steering_at_rest:
            out.append((StillMotion(pc, a - float(traj.starts[i])), a, b))
        else:
            raise InvalidInputError(
                f"the certificate covers curves and motions at rest, got a {type(pc).__name__} "
                f"(piece {i})"
            )
    return out
