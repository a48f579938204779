"""Near time-optimal, jerk-limited time parameterisation of a curve along its arc length.

:func:`time_parameterize` times a 1-DoF motion ``s(t)`` from ``s = 0`` to ``s = L`` under

* ``|a| <= a_max``, ``|jerk| <= j_max``, ``v >= 0`` (``s`` never decreases), and
* the curvature-dependent speed cap ``v <= cap(s) = Robot.speed_cap(kappa(s))``, i.e.
  ``v <= v_max``, lateral acceleration ``|kappa| v^2 <= a_lat_max``, yaw rate
  ``|kappa| v <= omega_max`` and wheel speeds ``v (1 + |kappa| w/2) <= wheel_v_max``.

ruckig (community edition, 1-DoF, no ``intermediate_positions``: that option sends the
problem to a cloud service) holds the first group; the cap is held by the design below.

Method
------
1. **Cap table.** One value per interval of a uniform arc-length grid (spacing <= 2.5 mm):
   a lower bound of the cap over the interval, times ``1 - 1e-4``; speeds up to
   ``max(v_start, v_end)`` may use the cap without that factor so that boundary speeds
   equal to the cap are allowed. For a curve with a ``polynomial_degree`` (every curve of
   the library) the bound is rigorous whatever the width of a curvature peak:
   :func:`trajopt.curvature_bound.interval_kappa_max` bounds ``|kappa|`` on the curve's
   polynomial pieces by Bernstein coefficients, bisects them until the bound is tight
   (0.1 % of the cap) or harmless, and maps each piece to the intervals its exact arc-length
   range touches. Any other curve is sampled: an interval gets the smaller cap at its ends
   minus a second-difference bound on a convex dip, and is resampled at 16 inner points
   (with a golden-section search next to the lowest) where that dip is large, or where the
   heading turned across it or a second-difference bound on ``|kappa|`` says the curvature
   may peak inside. A sparse table answers "minimum cap over ``[s_a, s_b]``" in O(1).
2. **Forward greedy** (compiled with numba). Steps of ``dt`` (20 ms) with a constant jerk
   ``u`` from ``{j, 0.75 j, ..., -j}`` plus the ``u`` that zeroes ``a`` (clamped at
   ``+-a_max``). A step is *safe* when the step and its **stop profile** (the time-optimal
   jerk-limited brake to ``v = 0``, ``a = 0``: closed form, the lowest continuation in the
   ``(s, v)`` plane) stay under the cap and the state can still reach ``(L, v_end)``. The
   cap test is exact on the grid: a constant-jerk piece passes when its speed maximum
   (including the interior peak ``v + a^2/(2|u|)``) is below the minimum cap over the
   ``s``-range it covers, otherwise it is bisected in time (down to 0.1 ms). A safe step
   also passes the *target* test when, for every local minimum of the cap within its stop
   distance, the time-optimal slow-down to that speed (with ``a = 0``) ends before it. The
   greedy takes the largest ``u`` passing both, else the largest safe one, else follows its
   own (safe) stop profile; at rest it only considers ``u > 0`` (a zero jerk there would idle
   forever). When only the end condition blocks it, one ruckig position call to
   ``(L, v_end, 0)`` finishes the motion, its ``max_velocity`` the lowest cap ahead (or the
   state's own peak speed when that call breaks the cap).
3. **Compress.** Knots at the greedy's speed minima (states with ``a = 0``); between two
   knots one ruckig position call with ``max_velocity`` = the greedy's peak speed there
   (the greedy is feasible for that problem, so ruckig's time-optimal answer is never
   slower). A section whose ruckig profile breaks the cap is split at the greedy step
   nearest its mid-time (up to 6 levels), else the greedy's own phases are kept.

The result is a chain of constant-jerk phases (:class:`trajopt.Trajectory`). Limits hold on
dense samples: ``a`` and ``jerk`` exactly (ruckig and the greedy both clamp), the speed cap
by construction of the table for polynomial curves (relative 1e-4 margin), and up to the
sampling's resolution for other curves. On the benchmark paths the durations are within a few percent of TOPP-RA's
jerk-free time-optimal answer (``benchmarks/bench_timing.py``).
"""

from __future__ import annotations

import logging
import math
import time
from typing import Any

import numpy as np

from trajopt.curvature_bound import interval_kappa_max
from trajopt.curve import _STILL, ParametricCurve, _signed_curvature
from trajopt.errors import InvalidInputError, TimingError
from trajopt.robot import Robot
from trajopt.speed_limits import SpeedLimits
from trajopt.trajectory import Trajectory

__all__ = ["time_parameterize"]

_log = logging.getLogger(__name__)

_GRID_SPACING = 0.0025  # m, arc-length spacing of the cap table
_MIN_INTERVALS = 64
_MAX_INTERVALS = 200_000
_REFINE = 16  # inner samples of a grid interval around a sharp curvature peak
_GOLDEN_STEPS = 30  # golden-section steps locating a peak between those samples (0.618^30)
_CAP_MARGIN = 1e-4  # relative margin below the speed cap
_N_CAND = 9  # jerk candidates j, 0.75 j, ..., -j
_T_MIN = 1e-4  # s, finest bisection of a piece in the cap test
_MAX_SPLIT_DEPTH = 6
_MIN_SPLIT_STEPS = 6  # split a failed section only when it spans at least this many steps
_RUCKIG_V_MARGIN = 1e-9  # m/s added to ruckig's max_velocity


def time_parameterize(
    curve: ParametricCurve,
    robot: Robot | None = None,
    *,
    v_start: float = 0.0,
    v_end: float = 0.0,
    dt: float = 0.02,
    speed_limits: SpeedLimits | None = None,
) -> Trajectory:
    """Time a curve with a near time-optimal, jerk-limited speed profile.

    Parameters
    ----------
    curve : ParametricCurve
        The path (``length``, ``u_at_s``, ``curvature``, ``heading``, ``__call__``).
    robot : Robot, optional
        Limits; default ``Robot()`` (the chapter's robot).
    v_start, v_end : float
        Speed at ``s = 0`` and at ``s = L`` (m/s), >= 0; the acceleration is 0 at both ends.
    dt : float
        Step of the forward greedy (s), in ``(0, 0.5]``.
    speed_limits : SpeedLimits, optional
        Speed-limit zones (:mod:`trajopt.speed_limits`): the speed is capped by the limit of
        the zone under the robot's centre, one more cap in the cap table (each interval
        takes the lowest limit of the mask cells the curve can touch in it).

    Returns
    -------
    Trajectory
        Starts at ``s = 0`` with ``v_start``, ends exactly at ``s = L`` with ``v_end``; its
        ``stats`` hold wall times per stage (s) and counts.

    Raises
    ------
    InvalidInputError
        Wrong types, non-finite or negative speeds, a bad ``dt``, a curve without length.
    TimingError
        A boundary speed is above the speed cap there, the path is too short to change from
        ``v_start`` to ``v_end``, the cap is ~0 somewhere (a cusp), or ``v_start`` cannot be
        brought under the cap ahead.
    """
    t_all = time.perf_counter()
    if robot is None:
        robot = Robot()
    if not isinstance(robot, Robot):
        raise InvalidInputError(f"robot must be a trajopt.Robot, got {type(robot).__name__}")
    for name in ("domain", "length", "s_at_u", "u_at_s", "speed", "curvature", "heading"):
        if not hasattr(curve, name) or not callable(curve):
            raise InvalidInputError(
                f"curve must be a ParametricCurve (needs {name!r} and __call__), "
                f"got {type(curve).__name__}"
            )
    v_start = _speed("v_start", v_start)
    v_end = _speed("v_end", v_end)
    if not (isinstance(dt, (int, float)) and math.isfinite(dt) and 0.0 < dt <= 0.5):
        raise InvalidInputError(f"dt must be a number in (0, 0.5] s, got {dt!r}")
    if speed_limits is not None and not isinstance(speed_limits, SpeedLimits):
        raise InvalidInputError(
            f"speed_limits must be a trajopt.SpeedLimits, got {type(speed_limits).__name__}"
        )
    length = float(curve.length)
    if not (math.isfinite(length) and length > 0.0):
        raise InvalidInputError(f"curve.length must be finite and > 0 m, got {length!r}")

    from trajopt import _greedy as g

    amax, jmax = robot.a_max, robot.j_max
    stats: dict[str, Any] = {}

    # ---------------------------------------------------------------- 1. cap table
    t0 = time.perf_counter()
    n_int = int(np.clip(math.ceil(length / _GRID_SPACING), _MIN_INTERVALS, _MAX_INTERVALS))
    h = length / n_int
    s_nodes = np.linspace(0.0, length, n_int + 1)
    u_nodes = _table_u_at_s(curve, s_nodes)
    u_nodes[0], u_nodes[-1] = curve.domain
    kappa, theta = _curvature_heading(curve, u_nodes)
    theta = np.unwrap(theta)
    raw_kappa = np.asarray(robot.speed_cap(kappa), dtype=float)
    raw = raw_kappa
    zone = None
    if speed_limits is not None:
        zone = _zone_caps(curve, u_nodes, h, speed_limits, robot.v_max)
        raw = np.minimum(raw, np.minimum(np.r_[zone[0], zone], np.r_[zone, zone[-1]]))
    cap0 = float(raw[0])
    cap1 = float(raw[-1])
    if v_start > cap0 * (1.0 + 1e-12):
        raise TimingError(
            f"v_start={v_start:.6g} m/s exceeds the speed cap {cap0:.6g} m/s at s=0 "
            f"(curvature {kappa[0]:.6g} 1/m{_zone_note(zone, 0)})"
        )
    if v_end > cap1 * (1.0 + 1e-12):
        raise TimingError(
            f"v_end={v_end:.6g} m/s exceeds the speed cap {cap1:.6g} m/s at s=L={length:.6g} m "
            f"(curvature {kappa[-1]:.6g} 1/m{_zone_note(zone, -1)})"
        )
    degree = getattr(curve, "polynomial_degree", None)
    if degree is not None:
        kmax = interval_kappa_max(curve, h, n_int, int(degree), robot.speed_cap)
        ci = np.asarray(robot.speed_cap(kmax), dtype=float)
        if not np.all(np.isfinite(kmax)):
            i_inf = int(np.flatnonzero(~np.isfinite(kmax))[0])
            raise TimingError(
                f"the curvature is unbounded at s={i_inf * h:.6g} m (the parametric speed "
                f"vanishes there: a cusp, or a zero-speed end where the curve turns): the "
                f"speed cap is 0"
            )
    else:
        ci = _interval_caps(raw_kappa, curve, robot, s_nodes, kappa, theta)
    if zone is not None:
        ci = np.minimum(ci, zone)
    v_bound = max(v_start, v_end)
    ci = np.maximum(ci * (1.0 - _CAP_MARGIN), np.minimum(ci, v_bound))
    ci[0] = max(ci[0], min(v_start, raw[0], raw[1]))
    ci[-1] = max(ci[-1], min(v_end, raw[-1], raw[-2]))
    i_low = int(np.argmin(ci))
    if not ci[i_low] > 1e-6:
        raise TimingError(
            f"the speed cap is {ci[i_low]:.3g} m/s at s={i_low * h:.6g} m (curvature "
            f"{kappa[i_low]:.6g} 1/m): the curve has a cusp or a turn the robot cannot follow"
        )
    d_change = _change_distance(v_start, v_end, jmax, amax)
    if d_change > length * (1.0 + 1e-9):
        raise TimingError(
            f"cannot change speed from v_start={v_start:.6g} m/s to v_end={v_end:.6g} m/s "
            f"within the path length {length:.6g} m: needs {d_change:.6g} m with "
            f"a_max={amax:.6g} m/s^2, j_max={jmax:.6g} m/s^3"
        )
    st, lg = g.build_table(ci)
    vtop = float(ci.max())
    is_min = np.zeros(n_int, bool)
    if n_int > 2:
        is_min[1:-1] = (ci[1:-1] < ci[:-2]) & (ci[1:-1] <= ci[2:]) & (ci[1:-1] < vtop)
    idx = np.flatnonzero(is_min)
    min_s = idx * h
    min_v = ci[idx]
    stats["timing_cap_table_s"] = time.perf_counter() - t0

    # ---------------------------------------------------------------- 2. greedy
    t0 = time.perf_counter()
    t_lower = length / vtop
    max_steps = int(min(5e6, 100.0 * (t_lower + 10.0 * (vtop / amax + amax / jmax)) / dt + 1000))
    phases, bounds, status = g.greedy(
        st, lg, h, length, min_s, min_v, v_start, v_end, amax, jmax, float(dt), _N_CAND,
        _T_MIN, max_steps,
    )  # fmt: skip
    stats["timing_greedy_s"] = time.perf_counter() - t0
    if status == g.START_INFEASIBLE:
        raise TimingError(
            f"v_start={v_start:.6g} m/s cannot be brought under the speed cap ahead (minimum "
            f"{ci[: max(1, int(v_start**2 / amax / h) + 2)].min():.6g} m/s near the start) "
            f"with a_max={amax:.6g} m/s^2, j_max={jmax:.6g} m/s^3"
        )
    if status == g.STUCK:
        raise TimingError(
            f"the timing stopped at rest before the end (s={bounds[-1, 1]:.6g} m of "
            f"{length:.6g} m): no motion stays under the speed cap"
        )
    if status != g.OK_FINISH:
        raise TimingError(f"the greedy timing did not finish within {max_steps} steps")

    # ---------------------------------------------------------------- 3. finish
    t0 = time.perf_counter()
    rk = _Ruckig(amax, jmax)
    fin = _finish(rk, g, st, lg, h, length, phases, bounds, v_end, jmax, amax)
    if fin is None:
        raise TimingError(
            f"cannot end at s=L={length:.6g} m with v_end={v_end:.6g} m/s under the speed cap "
            f"(cap near the end {ci[-1]:.6g} m/s)"
        )
    phases, bounds = fin
    stats["timing_finish_s"] = time.perf_counter() - t0
    greedy_duration = float(bounds[-1, 0])

    # ---------------------------------------------------------------- 4. compress
    t0 = time.perf_counter()
    chain = _compress(rk, g, st, lg, h, length, ci, phases, bounds)
    stats["timing_compress_s"] = time.perf_counter() - t0

    rows = np.vstack(chain)  # (t0, s0, v0, a0, jerk, duration)
    duration = float(rows[-1, 0] + rows[-1, 5])
    keep = rows[:, 5] > 0.0
    keep[0] = True
    rows = rows[keep]
    ph_s = np.clip(np.maximum.accumulate(rows[:, 1]), 0.0, length)
    stats["timing_total_s"] = time.perf_counter() - t_all
    stats.update(
        timing_greedy_duration=greedy_duration,
        timing_duration=duration,
        timing_phases=int(rows.shape[0]),
        timing_sections=len(chain),
        timing_grid_intervals=n_int,
    )
    _log.debug("time_parameterize: %s", stats)
    return Trajectory(
        path=curve,
        robot=robot,
        phase_t=rows[:, 0],
        phase_s=ph_s,
        phase_v=rows[:, 2],
        phase_a=rows[:, 3],
        phase_j=rows[:, 4],
        duration=duration,
        v_start=v_start,
        v_end=v_end,
        stats=stats,
        theta_grid_s=s_nodes,
        theta_grid=theta,
        u_grid=u_nodes,
    )


# --------------------------------------------------------------------- helpers
def _speed(name: str, value: Any) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InvalidInputError(f"{name} must be a number (m/s), got {value!r}") from None
    if not math.isfinite(x) or x < 0.0:
        raise InvalidInputError(f"{name} must be finite and >= 0 m/s, got {value!r}")
    return x


def _zone_caps(
    curve: ParametricCurve, u_nodes: np.ndarray, h: float, limits: SpeedLimits, v_max: float
) -> np.ndarray:
    """Lowest zone limit (m/s) per cap-table interval, shape ``(n,)``.

    The piece of the curve between two nodes ``h`` apart in arc length lies within ``h/2``
    of one of them, so it lies in the box around the two nodes grown by ``h/2`` (plus 1e-6 m
    for the table's ``u(s)`` error); the interval takes the lowest limit of every mask cell
    meeting that box.
    """
    xy = np.asarray(curve(u_nodes), dtype=float)
    grow = 0.5 * h + 1e-6
    lo = np.minimum(xy[:-1], xy[1:]) - grow
    hi = np.maximum(xy[:-1], xy[1:]) + grow
    return limits.box_caps(lo, hi, v_max)


def _zone_note(zone: np.ndarray | None, i: int) -> str:
    if zone is None or not np.isfinite(zone[i]):
        return ""
    return f"; speed-limit zone {float(zone[i]):.6g} m/s"


def _table_u_at_s(curve: ParametricCurve, s: np.ndarray) -> np.ndarray:
    """``u`` at dense arc lengths ``s`` for the cap table.

    For the library's curves (the base class's ``u_at_s``) the cubic Hermite model of the
    arc-length table is enough (about 1e-8 m here, no curve evaluation); any other curve
    answers with its own ``u_at_s``.
    """
    if type(curve).u_at_s is ParametricCurve.u_at_s:
        return np.asarray(curve.u_at_s(s, exact=False), dtype=float)
    return np.asarray(curve.u_at_s(s), dtype=float)


def _curvature_heading(curve: ParametricCurve, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Signed curvature (1/m) and heading (rad) at ``u``, sharing one first-derivative
    evaluation when the curve uses the base class's formulas."""
    base = ParametricCurve
    if type(curve).curvature is base.curvature and type(curve).heading is base.heading:
        d1 = np.asarray(curve(u, 1), dtype=float)
        kappa = _signed_curvature(d1, np.asarray(curve(u, 2), dtype=float))
        theta = np.arctan2(d1[:, 1], d1[:, 0])
        still = np.hypot(d1[:, 0], d1[:, 1]) <= _STILL * curve._mean_speed()
        if np.any(still):  # zero parametric speed: the limit of the tangent direction
            theta[still] = curve.heading(u[still])
        return kappa, theta
    return (
        np.asarray(curve.curvature(u), dtype=float),
        np.asarray(curve.heading(u), dtype=float),
    )


def _interval_caps(
    raw: np.ndarray, curve, robot: Robot, s_nodes: np.ndarray, kappa: np.ndarray,
    theta: np.ndarray,
) -> np.ndarray:
    """Cap per grid interval (shape (n,)) from the cap at the ``n + 1`` nodes.

    An interval gets the smaller of its end values minus ``d2/8``, with ``d2`` the largest
    positive second difference at its ends: the most a convex dip between the nodes can go
    below them. The interval is resampled at 16 inner points (and the same bound applied on
    the finer grid) where that correction exceeds 1e-4 of the value, and also where the
    curvature itself may peak inside it while the cap at both ends is flat (``v_max``): its
    second-difference bound on ``|kappa|``, or the heading turned across the interval over
    its length, exceeds ``|kappa|`` at both ends (unwrapped ``theta``, rad).
    """
    ci = np.minimum(raw[:-1], raw[1:])
    dip = _dip(raw)
    h = np.diff(s_nodes)
    ak = np.abs(kappa)
    k_end = np.maximum(ak[:-1], ak[1:])
    d2k = np.zeros_like(ak)
    d2k[1:-1] = 2.0 * ak[1:-1] - ak[:-2] - ak[2:]  # > 0 at a peak of |kappa|
    k_bump = np.maximum(0.0, np.maximum(d2k[:-1], d2k[1:])) / 8.0
    turned = np.abs(np.diff(theta)) / np.maximum(h, 1e-300)
    k_inner = np.maximum(k_end + k_bump, turned)
    peak = (k_inner > k_end * (1.0 + 1e-6)) & (
        np.asarray(robot.speed_cap(k_inner), dtype=float) < ci
    )
    bad = np.flatnonzero((dip > 1e-4 * ci) | peak)
    if bad.size:
        m = _REFINE
        frac = np.arange(m + 1) / m
        s_sub = s_nodes[bad, None] + (s_nodes[bad + 1] - s_nodes[bad])[:, None] * frac[None, :]
        u_sub = _table_u_at_s(curve, s_sub.ravel())
        cap_sub = np.asarray(robot.speed_cap(curve.curvature(u_sub)), dtype=float).reshape(
            s_sub.shape
        )
        cap_sub[:, 0] = raw[bad]
        cap_sub[:, -1] = raw[bad + 1]
        d2 = np.zeros_like(cap_sub)
        d2[:, 1:-1] = cap_sub[:, :-2] - 2.0 * cap_sub[:, 1:-1] + cap_sub[:, 2:]
        fine_dip = np.maximum(d2.max(axis=1), 0.0) / 8.0
        # at the two ends the coarse second difference, scaled to the fine spacing
        end_dip = np.maximum(dip[bad], 0.0) / (m * m)
        # a curvature peak narrower than the fine spacing (a near-cusp of the curve) can dip
        # below the samples by more than that bound: locate the lowest cap next to the
        # lowest sample by a golden-section search
        low = np.minimum(cap_sub.min(axis=1), _golden_min_cap(curve, robot, s_sub, cap_sub))
        ci[bad] = low - np.maximum(fine_dip, end_dip)
    else:
        ci = ci - dip
    if bad.size:
        ok = np.ones(ci.shape, bool)
        ok[bad] = False
        ci[ok] -= dip[ok]
    return np.maximum(ci, 0.0)


def _golden_min_cap(curve, robot: Robot, s_sub: np.ndarray, cap_sub: np.ndarray) -> np.ndarray:
    """Lowest cap found by golden-section search in the two fine steps around each row's
    lowest sample (shape (k,)); all rows are searched at once."""
    k = np.argmin(cap_sub, axis=1)
    rows = np.arange(len(k))
    last = s_sub.shape[1] - 1
    a = s_sub[rows, np.maximum(k - 1, 0)]
    b = s_sub[rows, np.minimum(k + 1, last)]
    ratio = (math.sqrt(5.0) - 1.0) / 2.0

    def cap_at(s: np.ndarray) -> np.ndarray:
        u = _table_u_at_s(curve, s)
        return np.asarray(robot.speed_cap(curve.curvature(u)), dtype=float)

    x1 = b - ratio * (b - a)
    x2 = a + ratio * (b - a)
    f1, f2 = cap_at(x1), cap_at(x2)
    best = np.minimum(f1, f2)
    for _ in range(_GOLDEN_STEPS):
        left = f1 < f2  # the minimum lies in [a, x2]
        b = np.where(left, x2, b)
        a = np.where(left, a, x1)
        x_new = np.where(left, b - ratio * (b - a), a + ratio * (b - a))
        f_new = cap_at(x_new)
        x1, x2 = np.where(left, x_new, x2), np.where(left, x1, x_new)
        f1, f2 = np.where(left, f_new, f2), np.where(left, f1, f_new)
        best = np.minimum(best, f_new)
    return best


def _dip(raw: np.ndarray) -> np.ndarray:
    d2 = np.zeros_like(raw)
    d2[1:-1] = raw[:-2] - 2.0 * raw[1:-1] + raw[2:]
    return np.maximum(0.0, np.maximum(d2[:-1], d2[1:])) / 8.0


def _change_distance(v0: float, v1: float, j: float, amax: float) -> float:
    """Shortest distance to change speed between ``v0`` and ``v1`` with ``a = 0`` at both ends."""
    lo, hi = min(v0, v1), max(v0, v1)
    dv = hi - lo
    if dv <= 0.0:
        return 0.0
    ap = math.sqrt(j * dv)
    if ap <= amax:
        t = 2.0 * ap / j
    else:
        t = 2.0 * amax / j + (dv - amax * amax / j) / amax
    return 0.5 * (lo + hi) * t  # the speed profile is point-symmetric about its midpoint


class _Ruckig:
    """One reusable 1-DoF ruckig position problem (no intermediate_positions, ever)."""

    def __init__(self, amax: float, jmax: float) -> None:
        from ruckig import InputParameter, Result, Ruckig, RuckigError, Trajectory

        self.inp = InputParameter(1)
        self.otg = Ruckig(1)
        self.traj = Trajectory(1)
        self.ok = (Result.Working, Result.Finished)
        self.errors = (RuntimeError, RuckigError)
        self.inp.max_acceleration = [amax]
        self.inp.max_jerk = [jmax]
        self.inp.min_velocity = [0.0]

    def solve(
        self, state0, state1, vmax: float, *, v_margin: float = _RUCKIG_V_MARGIN
    ) -> np.ndarray | None:
        """Rows ``(t0, s0, v0, a0, jerk, duration)`` from ``state0`` to ``state1`` or None.

        ``max_velocity`` is ``max(vmax, v0, v1) + v_margin`` (m/s)."""
        inp = self.inp
        s0, v0, a0 = state0
        s1, v1, a1 = state1
        inp.current_position = [s0]
        inp.current_velocity = [v0]
        inp.current_acceleration = [a0]
        inp.target_position = [s1]
        inp.target_velocity = [v1]
        inp.target_acceleration = [a1]
        inp.max_velocity = [max(vmax, v0, v1) + v_margin]
        try:
            res = self.otg.calculate(inp, self.traj)
        except self.errors:  # ruckig rejects some target states (e.g. a != 0 near v limit)
            return None
        if res not in self.ok:
            return None
        prof = self.traj.profiles[0][0]
        if prof.accel.duration > 1e-15:
            return None
        rows = []
        t = 0.0
        b = prof.brake
        if b.duration > 0.0:
            for i in range(2):
                if b.t[i] > 0.0:
                    rows.append((t, b.p[i], b.v[i], b.a[i], b.j[i], b.t[i]))
                    t += b.t[i]
        pt, pj, pp, pv, pa = prof.t, prof.j, prof.p, prof.v, prof.a
        for i in range(7):
            if pt[i] > 0.0:
                rows.append((t, pp[i], pv[i], pa[i], pj[i], pt[i]))
                t += pt[i]
        if not rows:
            return None
        out = np.array(rows)
        out[:, 0] = np.concatenate([[0.0], np.cumsum(out[:-1, 5])])
        return out


def _rows_from_greedy(phases: np.ndarray, i0: int, i1: int, t_end: float) -> np.ndarray:
    """Greedy phases ``i0:i1`` as rows ``(t0, s0, v0, a0, jerk, duration)``."""
    ph = phases[i0:i1]
    t_next = np.append(ph[1:, 0], t_end)
    return np.column_stack([ph[:, :5], t_next - ph[:, 0]])


def _rows_ok(g, st, lg, h, length, rows: np.ndarray) -> bool:
    """Rows ``(t0, s0, v0, a0, jerk, duration)`` all under the speed cap (exact on the grid)."""
    return bool(g.rows_ok(st, lg, h, length, np.ascontiguousarray(rows), _T_MIN))


def _finish(rk, g, st, lg, h, length, phases, bounds, v_end, jmax, amax):
    """Append one ruckig position call to ``(L, v_end, 0)``; back off a few steps if needed.

    Returns ``(phases, bounds)`` with ``phases`` rows ``(t0, s0, v0, a0, jerk)`` and ``bounds``
    rows ``(t, s, v, a, phase_index)``, the last bound being the end state; or None.
    """
    target = (length, v_end, 0.0)
    nb = bounds.shape[0]
    for back in range(min(nb, 25)):
        ib = nb - 1 - back
        t_b, s_b, v_b, a_b, p_b = bounds[ib]
        if s_b > length:
            continue
        v_pk = v_b + (a_b * a_b / (2.0 * jmax) if a_b > 0 else 0.0)
        # the lowest cap ahead bounds a profile that holds the cap everywhere; the state's
        # own peak speed is the fallback (from rest that peak is 0: never the only bound)
        v_room = float(g.range_min(st, lg, h, s_b, length))
        rows = None
        for vmax in dict.fromkeys((max(v_room, v_pk, v_end), max(v_pk, v_end))):
            rows = rk.solve((s_b, v_b, a_b), target, vmax)
            if rows is not None and _rows_ok(g, st, lg, h, length, rows):
                break
            rows = None
        if rows is None:
            continue
        rows = rows.copy()
        rows[:, 0] += t_b
        new_ph = np.vstack([phases[: int(p_b)], rows[:, :5]])
        t_end = t_b + float(rows[:, 5].sum())
        new_b = np.vstack([bounds[: ib + 1], [[t_end, length, v_end, 0.0, new_ph.shape[0]]]])
        return new_ph, new_b
    return None


def _compress(rk, g, st, lg, h, length, ci, phases, bounds) -> list[np.ndarray]:
    """Replace the greedy between its speed minima by ruckig's time-optimal sections."""
    nb = bounds.shape[0]
    v, a = bounds[:, 2], bounds[:, 3]
    vm, vc, vp = v[:-2], v[1:-1], v[2:]
    inner = (a[1:-1] == 0.0) & (vc <= vm) & (vc <= vp) & ~((vm == vc) & (vc == vp))
    knots = [0, *(np.flatnonzero(inner) + 1).tolist(), nb - 1]
    t_next = np.append(phases[1:, 0], bounds[-1, 0])
    peaks = g.phase_peaks(phases, t_next)
    ph_index = bounds[:, 4].astype(np.int64)
    n_ci = ci.shape[0]
    chain: list[np.ndarray] = []
    t_out = 0.0
    budget = [3 * len(knots) + 32]  # ruckig calls; the greedy answer is kept beyond it

    def greedy_rows(i0: int, i1: int) -> np.ndarray:
        return _rows_from_greedy(phases, ph_index[i0], ph_index[i1], float(bounds[i1, 0]))

    def fits(rows, g_dur: float) -> bool:
        return (
            rows is not None
            and float(rows[:, 5].sum()) <= g_dur
            and _rows_ok(g, st, lg, h, length, rows)
        )

    def solve(i0: int, i1: int, depth: int) -> list[np.ndarray]:
        p0, p1 = ph_index[i0], ph_index[i1]
        if p1 <= p0:
            return []
        if i1 - i0 < 2 or budget[0] <= 0:
            return [greedy_rows(i0, i1)]
        budget[0] -= 1
        g_dur = float(bounds[i1, 0] - bounds[i0, 0])
        st0 = (bounds[i0, 1], bounds[i0, 2], bounds[i0, 3])
        st1 = (bounds[i1, 1], bounds[i1, 2], bounds[i1, 3])
        peak = float(peaks[p0:p1].max())
        i_a = min(int(st0[0] / h), n_ci - 1)
        i_b = min(int(st1[0] / h), n_ci - 1)
        top = float(ci[i_a : i_b + 1].max())
        if top > peak * (1.0 + 1e-6):
            # first try the highest cap in the section: better than the greedy's peak if it fits
            rows = rk.solve(st0, st1, top)
            if fits(rows, g_dur):
                return [rows]
        rows = rk.solve(st0, st1, peak)
        if fits(rows, g_dur):
            return [rows]
        if i1 - i0 >= _MIN_SPLIT_STEPS and depth < _MAX_SPLIT_DEPTH:
            t_mid = 0.5 * (bounds[i0, 0] + bounds[i1, 0])
            im = int(np.clip(np.searchsorted(bounds[:, 0], t_mid), i0 + 1, i1 - 1))
            return solve(i0, im, depth + 1) + solve(im, i1, depth + 1)
        return [greedy_rows(i0, i1)]

    for k0, k1 in zip(knots[:-1], knots[1:], strict=True):
        for rows in solve(k0, k1, 0):
            r = rows.copy()
            r[:, 0] = r[:, 0] - r[0, 0] + t_out
            t_out = float(r[-1, 0] + r[-1, 5])
            chain.append(r)
    return chain
