"""Path and trajectory metrics: one set for every method in the comparison.

:func:`path_metrics` scores any :class:`~trajopt.geometry._curve.ParametricCurve` (B-spline,
polynomial, smoother output) or a polyline (an ``(n, 2)`` array in metres, a
:class:`~trajopt.geometry._curve.PolylineCurve`, or an :class:`astar.GridPath` converted with the
grid) against the raw map and the A* reference path. :func:`trajectory_metrics` adds the
peaks of a timed trajectory against the robot's limits.

Definitions (``Q_i``, ``i = 1..N``: reference A* points in metres; ``C``: the curve,
sampled every ``sample_spacing`` metres of arc length, polyline vertices always included):

* ``mse_m2``: the chapter's equation (3) divided by ``N``, ``mean_i |C(u_i) - Q_i|^2``. The
  correspondence ``u_i`` is, by default, the **nearest point** of the curve to ``Q_i``
  (exact distance to the sampled polyline of the curve; the chord error of a smooth
  curve is ``~ kappa ds^2 / 8``). This is the same rule for every method, including
  polylines and curves that were not fitted to ``Q``; it is never larger than the value
  at the parameters a fit used. Pass ``params`` to evaluate at given parameters instead.
* ``start_error_x_m`` ... ``end_error_y_m``: ``|C(u_0) - Q_1|`` and ``|C(u_1) - Q_N|`` per axis.
* ``hausdorff_m``: symmetric Hausdorff distance between the sampled curve and the
  reference polyline (each side: exact distance from samples to the other polyline;
  exact up to ``sample_spacing / 2``).
* ``min_clearance_m``: minimum over the samples of the exact Euclidean distance to the
  nearest occupied cell of the **raw** grid, cells taken as closed squares (0 inside one).
  Cells outside the map are free unless ``border_occupied``.
* ``collision``: ``min_clearance_m < radius`` (with a 1e-9 m tolerance).
* ``length_m``, ``length_ratio`` (to the reference polyline's length).
* ``max_curvature_1pm``, ``rms_curvature_1pm = sqrt(int kappa^2 ds / L)``,
  ``int_sq_curvature_1pm = int kappa^2 ds`` (trapezoid over the samples). A polyline has its
  curvature concentrated at the vertices; it is scored with the discrete curvature
  ``theta_j / l_j`` (turn angle over half the sum of the adjacent segment lengths) and
  ``int kappa^2 ds = sum_j theta_j^2 / l_j``.
* ``max_heading_jump_rad``: the largest change of heading between consecutive samples
  ``sample_spacing`` apart (a 45-degree A* corner scores 0.785 rad; a C2 curve scores about
  ``max |kappa| * sample_spacing``).

A timed trajectory given as the path (a :class:`~trajopt.Trajectory`, a
:class:`~trajopt.motion.TrajectoryChain` with turns in place, a stop-and-turn trajectory) is
scored along the path it drives (:func:`trajectory_path`).

Turns in place
--------------
A differential drive meets a required end heading by turning where it stands: the pieces
of a :class:`~trajopt.motion.TrajectoryChain` (and the corners of the stop-and-turn
fallback) where ``v = 0`` while ``omega != 0`` (``kappa = a_lat = 0`` there). Such a turn
is held to the turn limits of :func:`trajopt.timing.turn_limits` (yaw rate, yaw
acceleration and yaw jerk of the wheels turning on the spot), not to the driving rule
``omega = kappa v``: :func:`trajectory_metrics` checks the samples standing still
(``|v| <=`` :data:`STANDING_V`) against them, the yaw acceleration and jerk from the
finite differences of the sampled ``omega``. An omnidirectional motion (samples with a
``course``, the direction of travel, beside ``theta``, the orientation) turns its body by a
profile under the same limits while it drives: all its samples are checked against them.
:func:`turns_in_place` lists the turns in place.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from trajopt.analysis._distances import (
    distance_to_polyline,
    hausdorff_distance,
    min_clearance,
    point_clearance,
    polyline_hausdorff,
)
from trajopt.errors import InvalidInputError
from trajopt.geometry import ParametricCurve, PolylineCurve

__all__ = [
    "PathMetrics",
    "path_metrics",
    "trajectory_metrics",
    "point_clearance",
    "min_clearance",
    "distance_to_polyline",
    "hausdorff_distance",
    "polyline_hausdorff",
    "heading_jumps",
    "trajectory_path",
    "TurnSpan",
    "turns_in_place",
    "STANDING_V",
]

#: Default arc-length spacing of the samples (m).
DEFAULT_SAMPLE_SPACING = 0.005
_COLLISION_TOL = 1e-9
#: Most samples taken along one path; beyond it the spacing grows (and is reported).
_MAX_SAMPLES = 20_000
#: A sample whose speed is at most this (m/s) stands still: a turn in place when it yaws.
STANDING_V = 1e-9
#: Yaw rate (rad/s) above which a standing sample turns.
_TURNING_OMEGA = 1e-9


@dataclass(frozen=True, slots=True)
class PathMetrics:
    """Geometric scores of one path (see the module docstring for the definitions).

    Attributes
    ----------
    mse_m2 : float
        Mean squared deviation from the reference points (m^2).
    start_error_x_m, start_error_y_m, end_error_x_m, end_error_y_m : float
        Absolute end-point errors per axis (m).
    hausdorff_m : float
        Symmetric Hausdorff distance to the reference polyline (m).
    min_clearance_m : float
        Smallest distance from the path to an occupied square of the raw grid (m).
    collision : bool
        ``min_clearance_m < radius``.
    length_m : float
        Arc length (m).
    length_ratio : float
        ``length_m`` over the reference polyline's length.
    max_curvature_1pm, rms_curvature_1pm : float
        Largest and root-mean-square curvature (1/m).
    int_sq_curvature_1pm : float
        ``int kappa^2 ds`` (1/m).
    max_heading_jump_rad : float
        Largest heading change between consecutive samples (rad).
    sample_spacing_m : float
        Arc-length spacing of the samples (m).
    n_samples : int
        Number of samples used.
    """

    mse_m2: float
    start_error_x_m: float
    start_error_y_m: float
    end_error_x_m: float
    end_error_y_m: float
    hausdorff_m: float
    min_clearance_m: float
    collision: bool
    length_m: float
    length_ratio: float
    max_curvature_1pm: float
    rms_curvature_1pm: float
    int_sq_curvature_1pm: float
    max_heading_jump_rad: float
    sample_spacing_m: float
    n_samples: int

    def as_dict(self) -> dict[str, Any]:
        """Return the metrics as a plain ``dict`` (field order)."""
        return asdict(self)

    @classmethod
    def nan(cls, sample_spacing: float = math.nan) -> PathMetrics:
        """Return a record of NaNs (``collision=False``): for a method that produced no path."""
        vals: dict[str, Any] = {f: math.nan for f in cls.__dataclass_fields__}
        vals.update(collision=False, sample_spacing_m=sample_spacing, n_samples=0)
        return cls(**vals)


# ============================================================================ inputs
def _points_of(obj: object, grid: Any, name: str) -> np.ndarray:
    """World points (m) of an (n, 2) array, a PolylineCurve or a GridPath (needs grid)."""
    if isinstance(obj, PolylineCurve):
        return np.asarray(obj.points, dtype=float)
    if hasattr(obj, "cells"):
        if grid is None:
            raise InvalidInputError(f"{name}: converting a GridPath to metres needs the grid")
        return np.asarray(grid.cell_to_world(np.asarray(obj.cells)), dtype=float)
    p = np.asarray(obj, dtype=float)
    if p.ndim != 2 or p.shape[1] != 2 or len(p) < 1:
        raise InvalidInputError(f"{name} must be points of shape (n, 2) in metres, got {p.shape}")
    if not np.all(np.isfinite(p)):
        raise InvalidInputError(f"{name} must be finite")
    return p


def _as_curve(path: object, grid: Any) -> ParametricCurve:
    if isinstance(path, ParametricCurve):
        return path
    if all(hasattr(path, a) for a in ("domain", "sample", "heading", "curvature", "length")):
        return path  # type: ignore[return-value]  # duck-typed ParametricCurve
    if hasattr(path, "duration") and hasattr(path, "sample"):  # a timed trajectory
        return _as_curve(trajectory_path(path), grid)
    return PolylineCurve(_points_of(path, grid, "path"))


#: Time step (s) of the polyline :func:`trajectory_path` samples when no piece's path serves.
_PATH_DT = 0.002


def trajectory_path(traj: Any) -> Any:
    """Return the path a timed trajectory drives along (metres).

    Parameters
    ----------
    traj : Trajectory, TrajectoryChain or StopAndTurnTrajectory
        Anything with ``duration`` (s) and ``sample(t)`` returning ``x, y`` (m); its
        ``path`` is used when it has one.

    Returns
    -------
    ParametricCurve or PolylineCurve
        ``traj.path`` when set (a :class:`~trajopt.Trajectory`'s curve, the stop-and-turn
        polyline); for a chain whose only moving piece is played whole (a pose-to-pose plan:
        turns in place and one curve), that piece's path. Otherwise the polyline of the
        positions sampled every 2 ms (points that do not move dropped; a trajectory that
        never moves gives a polyline of length 0 at its point).
    """
    path = getattr(traj, "path", None)
    if path is not None:
        return path
    pieces = getattr(traj, "pieces", None)
    if pieces:
        starts = tuple(getattr(traj, "starts", ())) or (0.0,) * len(pieces)
        moving = [(p, t0) for p, t0 in zip(pieces, starts, strict=True) if float(p.length) > 0.0]
        if len(moving) == 1 and moving[0][1] == 0.0:
            return trajectory_path(moving[0][0])
    duration = float(traj.duration)
    n = max(2, min(int(math.ceil(duration / _PATH_DT)) + 1, 50 * _MAX_SAMPLES))
    smp = traj.sample(np.linspace(0.0, duration, n))
    xy = np.column_stack([np.asarray(smp.x, dtype=float), np.asarray(smp.y, dtype=float)])
    keep = np.concatenate([[True], np.hypot(*np.diff(xy, axis=0).T) > 1e-9])
    return PolylineCurve(xy[keep])


# ============================================================================ geometry
def _trapezoid(y: np.ndarray, x: np.ndarray) -> float:
    return float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(x)))


def heading_jumps(headings: np.ndarray) -> np.ndarray:
    """Absolute heading change between consecutive samples, wrapped to [0, pi] (rad)."""
    h = np.asarray(headings, dtype=float)
    d = np.diff(h)
    return np.abs((d + np.pi) % (2.0 * np.pi) - np.pi)


def _polyline_curvature(v: np.ndarray) -> tuple[float, float]:
    """Discrete ``(max kappa, int kappa^2 ds)`` of a polyline (turn angle / local length)."""
    if len(v) < 3:
        return 0.0, 0.0
    seg = np.diff(v, axis=0)
    lens = np.hypot(seg[:, 0], seg[:, 1])
    turn = heading_jumps(np.arctan2(seg[:, 1], seg[:, 0]))
    local = 0.5 * (lens[:-1] + lens[1:])
    kappa = turn / local
    return float(kappa.max()), float(np.sum(turn * turn / local))


# ============================================================================ path metrics
def path_metrics(
    path: object,
    *,
    grid: Any,
    reference: object,
    radius: float,
    sample_spacing: float = DEFAULT_SAMPLE_SPACING,
    params: np.ndarray | None = None,
    border_occupied: bool = False,
) -> PathMetrics:
    """Score a curve or polyline against the raw map and the A* reference.

    Parameters
    ----------
    path : ParametricCurve or array_like (n, 2) or PolylineCurve or astar.GridPath
        The path to score (metres; a GridPath is converted with ``grid``).
    grid : astar.OccupancyGrid
        The raw map (clearance is measured to its occupied squares).
    reference : array_like (N, 2) or PolylineCurve or astar.GridPath
        The A* reference points ``Q_i`` (metres), in path order.
    radius : float
        Robot radius (m, >= 0): the collision threshold on the clearance.
    sample_spacing : float
        Arc-length spacing of the samples (m, > 0), also the spacing of the heading jumps.
    params : array_like, shape (N,), optional
        Curve parameters ``u_i`` matching the reference points: the MSE is then equation
        (3) at these parameters instead of at the nearest points.
    border_occupied : bool
        Count the outside of the map as occupied for the clearance.

    Returns
    -------
    PathMetrics
    """
    try:
        ds = float(sample_spacing)
        r = float(radius)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(
            f"sample_spacing and radius must be numbers, got {sample_spacing!r}, {radius!r}"
        ) from exc
    if not (math.isfinite(ds) and ds > 0):
        raise InvalidInputError(f"sample_spacing must be finite and > 0 m, got {ds!r}")
    if not (math.isfinite(r) and r >= 0):
        raise InvalidInputError(f"radius must be finite and >= 0 m, got {r!r}")
    if grid is None or not hasattr(grid, "occupied"):
        raise InvalidInputError(f"grid must be an astar.OccupancyGrid, got {type(grid).__name__}")
    ref = _points_of(reference, grid, "reference")
    curve = _as_curve(path, grid)
    is_poly = isinstance(curve, PolylineCurve)

    length = float(curve.length)
    if not math.isfinite(length):
        raise InvalidInputError(f"path length must be finite, got {length!r} m")
    if length / ds > _MAX_SAMPLES:
        # a wildly oscillating fit (e.g. y = f(x) across a vertical stretch) would need
        # billions of samples; coarsen the spacing (reported in sample_spacing_m)
        ds = length / _MAX_SAMPLES
    smp = curve.sample(ds=ds)
    xy = np.asarray(smp.xy, dtype=float)
    geom = np.vstack([xy, curve.points]) if is_poly else xy
    length = float(curve.length)

    # MSE (equation (3) / N)
    if params is not None:
        u = np.asarray(params, dtype=float)
        if u.shape != (len(ref),):
            raise InvalidInputError(
                f"params must have shape ({len(ref)},) (one per reference point), got {u.shape}"
            )
        dev = np.asarray(curve(u), dtype=float) - ref
        mse = float(np.mean(np.sum(dev * dev, axis=1)))
    else:
        line = curve.points if is_poly else xy
        mse = float(np.mean(distance_to_polyline(ref, line) ** 2))

    lo, hi = curve.domain
    p0 = np.asarray(curve(lo), dtype=float).reshape(2)
    p1 = np.asarray(curve(hi), dtype=float).reshape(2)
    e0 = np.abs(p0 - ref[0])
    e1 = np.abs(p1 - ref[-1])

    curve_line = curve.points if is_poly else xy
    haus = polyline_hausdorff(curve_line, ref, spacing=ds)

    clear = min_clearance(geom, grid, border_occupied=border_occupied)
    ref_len = float(np.sum(np.hypot(*np.diff(ref, axis=0).T))) if len(ref) > 1 else 0.0

    if is_poly:
        kmax, k2 = _polyline_curvature(np.asarray(curve.points))
    else:
        k = np.abs(np.asarray(smp.curvature, dtype=float))
        kmax = float(np.max(k)) if len(k) else 0.0
        k2 = float(_trapezoid(k * k, smp.s)) if len(k) > 1 else 0.0
    rms = math.sqrt(k2 / length) if length > 0 and math.isfinite(k2) else math.nan
    jumps = heading_jumps(np.asarray(curve.heading(smp.u), dtype=float))
    return PathMetrics(
        mse_m2=mse,
        start_error_x_m=float(e0[0]),
        start_error_y_m=float(e0[1]),
        end_error_x_m=float(e1[0]),
        end_error_y_m=float(e1[1]),
        hausdorff_m=haus,
        min_clearance_m=clear,
        collision=bool(clear < r - _COLLISION_TOL),
        length_m=length,
        length_ratio=length / ref_len if ref_len > 0 else math.nan,
        max_curvature_1pm=kmax,
        rms_curvature_1pm=rms,
        int_sq_curvature_1pm=k2,
        max_heading_jump_rad=float(jumps.max()) if len(jumps) else 0.0,
        sample_spacing_m=ds,
        n_samples=int(len(xy)),
    )


# ============================================================================ trajectories
_TRAJ_QUANTITIES = (
    # (sample field, robot limit attribute, key stem, unit suffix)
    ("v", "v_max", "v", "mps"),
    ("a", "a_max", "a", "mps2"),
    ("jerk", "j_max", "jerk", "mps3"),
    ("omega", "omega_max", "omega", "radps"),
    ("a_lat", "a_lat_max", "a_lat", "mps2"),
)
#: The turn-in-place quantities: (key stem, unit suffix), in the order of ``turn_limits``.
_TURN_QUANTITIES = (("turn_omega", "radps"), ("turn_alpha", "radps2"), ("turn_zeta", "radps3"))


def _field(rec: Any, name: str) -> np.ndarray | None:
    try:
        val = rec[name]
    except (KeyError, IndexError, TypeError):
        val = getattr(rec, name, None)
    return None if val is None else np.asarray(val, dtype=float)


def _needed(rec: Any, name: str) -> np.ndarray:
    vals = _field(rec, name)
    if vals is None:
        raise InvalidInputError(f"the trajectory's samples have no {name!r}")
    return vals


def _turn_limits(robot: Any) -> tuple[float, float, float]:
    """``trajopt.timing.turn_limits(robot)``; NaNs for a robot without the fields they need."""
    from trajopt.timing import turn_limits

    try:
        return tuple(float(x) for x in turn_limits(robot))  # type: ignore[return-value]
    except (AttributeError, TypeError, ValueError, ZeroDivisionError):
        return (math.nan,) * 3


def _turn_peaks(t: np.ndarray, rec: Any) -> list[float]:
    """Peak |yaw rate|, |yaw acceleration| and |yaw jerk| of the turning samples.

    The turning samples are those standing still, or every sample when the samples carry a
    ``course`` (an omnidirectional motion, whose ``omega`` is its orientation's rate). The
    yaw acceleration is the difference quotient of ``omega`` over each step whose two
    samples turn, the yaw jerk the second difference over three (the grid is uniform). On a
    jerk-limited turn (``omega`` continuously differentiable) these are averages of the true
    values over the step, so they never exceed the true peaks.
    """
    v, omega = _field(rec, "v"), _field(rec, "omega")
    if v is None or omega is None or not v.size:
        return [0.0, 0.0, 0.0]
    v = np.broadcast_to(v, t.shape)
    omega = np.broadcast_to(omega, t.shape)
    if _field(rec, "course") is not None:
        turning = np.ones(t.shape, bool)
    else:
        turning = np.abs(v) <= STANDING_V
    peaks = [float(np.max(np.abs(omega[turning]), initial=0.0))]
    h = float(t[1] - t[0]) if len(t) > 1 else 0.0
    if h <= 0.0:
        return peaks + [0.0, 0.0]
    both = turning[1:] & turning[:-1]
    alpha = np.diff(omega) / h
    peaks.append(float(np.max(np.abs(alpha[both]), initial=0.0)))
    three = both[1:] & both[:-1]
    zeta = np.diff(alpha) / h
    peaks.append(float(np.max(np.abs(zeta[three]), initial=0.0)))
    return peaks


def trajectory_metrics(
    traj: Any, robot: Any, *, dt: float = 0.005, tol: float = 1e-6
) -> dict[str, Any]:
    """Duration and peak |v|, |a|, |jerk|, |omega|, |a_lat| of a timed trajectory, and its turns.

    Parameters
    ----------
    traj : Trajectory or TrajectoryChain
        Anything with ``duration`` (s) and ``sample(t)`` returning a mapping or record of
        named arrays (``t, x, y, theta, v, omega, a, jerk, a_lat, kappa, s``): a
        :class:`~trajopt.Trajectory`, a :class:`~trajopt.motion.TrajectoryChain` with turns
        in place, a stop-and-turn trajectory.
    robot : Robot
        Anything with ``v_max, a_max, j_max, omega_max, a_lat_max`` (a missing or ``None``
        limit gives a NaN ratio and is not checked); the turns are checked against
        :func:`trajopt.timing.turn_limits` of it.
    dt : float
        Sampling step (s, > 0); the end time is always sampled.
    tol : float
        Relative tolerance of ``within_limits``.

    Returns
    -------
    dict
        ``duration_s``, ``sample_dt_s``, and for each quantity ``q`` in ``v, a, jerk,
        omega, a_lat``: ``peak_q_<unit>``, ``limit_q_<unit>`` and ``ratio_q`` (peak over
        limit; ``a_lat`` falls back to ``v^2 kappa`` when the samples lack it). The turns
        (module docstring: the samples standing still, or all of an omnidirectional motion's)
        add ``turn_omega`` (yaw rate, rad/s), ``turn_alpha`` (yaw acceleration, rad/s^2)
        and ``turn_zeta`` (yaw jerk, rad/s^3), each with ``peak_``, ``limit_`` (from
        :func:`trajopt.timing.turn_limits`; NaN, not checked, for a robot without the
        fields it needs) and ``ratio_`` keys; the peaks are 0 when the trajectory never
        turns on the spot. ``within_limits``: every ratio <= 1 + tol.
    """
    try:
        step = float(dt)
        duration = float(traj.duration)
    except (TypeError, ValueError, AttributeError) as exc:
        raise InvalidInputError(f"traj needs a numeric duration and dt a number: {exc}") from exc
    if not (math.isfinite(step) and step > 0):
        raise InvalidInputError(f"dt must be finite and > 0 s, got {step!r}")
    if not (math.isfinite(duration) and duration >= 0):
        raise InvalidInputError(f"traj.duration must be finite and >= 0 s, got {duration!r}")
    n = max(2, int(math.ceil(duration / step)) + 1)
    t = np.linspace(0.0, duration, n)
    rec = traj.sample(t)
    out: dict[str, Any] = {"duration_s": duration, "sample_dt_s": duration / (n - 1)}
    ok = True

    def record(stem: str, unit: str, peak: float, lim: float) -> None:
        nonlocal ok
        ratio = peak / lim if lim > 0 else math.nan
        out[f"peak_{stem}_{unit}"] = peak
        out[f"limit_{stem}_{unit}"] = lim
        out[f"ratio_{stem}"] = ratio
        if math.isfinite(ratio) and ratio > 1.0 + tol:
            ok = False

    for fld, lim_name, stem, unit in _TRAJ_QUANTITIES:
        vals = _field(rec, fld)
        if vals is None and fld == "a_lat":
            v, kap = _field(rec, "v"), _field(rec, "kappa")
            vals = None if v is None or kap is None else v * v * kap
        peak = float(np.max(np.abs(vals))) if vals is not None and vals.size else math.nan
        lim = getattr(robot, lim_name, None)
        record(stem, unit, peak, math.nan if lim is None else float(lim))
    peaks = _turn_peaks(t, rec)
    for (stem, unit), peak, lim in zip(_TURN_QUANTITIES, peaks, _turn_limits(robot), strict=True):
        record(stem, unit, peak, lim)
    out["within_limits"] = ok
    return out


@dataclass(frozen=True, slots=True)
class TurnSpan:
    """One turn in place found by :func:`turns_in_place` (times to the sampling step).

    Attributes
    ----------
    t0, t1 : float
        First and last sample of the turn (s): the robot stands still from ``t0`` to ``t1``
        and yaws in between.
    x, y : float
        Where it turns (m).
    theta0, theta1 : float
        Heading at ``t0`` and ``t1`` (rad, as sampled: continuous, not wrapped).
    """

    t0: float
    t1: float
    x: float
    y: float
    theta0: float
    theta1: float

    @property
    def turn_rad(self) -> float:
        """The signed angle turned, ``theta1 - theta0`` (rad)."""
        return self.theta1 - self.theta0


def turns_in_place(traj: Any, *, dt: float = 0.01) -> list[TurnSpan]:
    """Return the turns in place of a timed trajectory, in time order.

    A turn is a run of consecutive samples standing still (``|v| <=`` :data:`STANDING_V`)
    in which the robot yaws (``|omega| > 1e-9`` rad/s at one of them): the turns in place of
    a :class:`~trajopt.motion.TrajectoryChain` and the corners of the stop-and-turn
    fallback. Turns one after another at the same spot are one span.

    Parameters
    ----------
    traj : Trajectory or TrajectoryChain
        Anything with ``duration`` (s) and ``sample(t)`` returning ``t``-aligned arrays
        ``x, y, theta, v, omega``.
    dt : float
        Sampling step (s, finite, > 0; at most 1e6 samples); a turn shorter than it may be
        missed, and the span's ends are within it of the turn's.

    Returns
    -------
    list of TurnSpan
    """
    try:
        step = float(dt)
        duration = float(traj.duration)
    except (TypeError, ValueError, AttributeError) as exc:
        raise InvalidInputError(f"traj needs a numeric duration and dt a number: {exc}") from exc
    if not (math.isfinite(step) and step > 0):
        raise InvalidInputError(f"dt must be finite and > 0 s, got {step!r}")
    if not (math.isfinite(duration) and duration >= 0):
        raise InvalidInputError(f"traj.duration must be finite and >= 0 s, got {duration!r}")
    if duration / step > 1e6:
        raise InvalidInputError(
            f"dt={step!r} s gives more than 1e6 samples over {duration:.6g} s; use a larger dt"
        )
    n = max(2, int(math.ceil(duration / step)) + 1)
    t = np.linspace(0.0, duration, n)
    smp = traj.sample(t)
    x, y, theta, v, omega = (
        np.broadcast_to(_needed(smp, k), t.shape) for k in ("x", "y", "theta", "v", "omega")
    )
    still = np.abs(v) <= STANDING_V
    edges = np.flatnonzero(np.diff(np.concatenate([[0], still.astype(np.int8), [0]])))
    spans = []
    for i0, i1 in zip(edges[::2], edges[1::2] - 1, strict=True):
        if np.any(np.abs(omega[i0 : i1 + 1]) > _TURNING_OMEGA):
            spans.append(
                TurnSpan(
                    float(t[i0]),
                    float(t[i1]),
                    float(x[i0]),
                    float(y[i0]),
                    float(theta[i0]),
                    float(theta[i1]),
                )
            )
    return spans
