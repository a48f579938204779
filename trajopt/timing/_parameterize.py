"""The timing's entry point, :func:`time_parameterize`.

Validate, then the cap table, the forward greedy, the finish and the compress stages (method in
:mod:`trajopt.timing`).
"""

from __future__ import annotations

import logging
import math
import threading
import time
from typing import Any

import numpy as np

import trajopt.timing._greedy as greedy
from trajopt.errors import InvalidInputError, TimingError
from trajopt.geometry import ParametricCurve
from trajopt.motion import Trajectory
from trajopt.robot import Robot
from trajopt.timing._cap_table import T_MIN, CapTable, build_cap_table
from trajopt.timing._compress import compress, finish
from trajopt.timing._ruckig_profile import RuckigProfile
from trajopt.timing._speed_limits import SpeedLimits
from trajopt.validation import nonnegative, number

_log = logging.getLogger("trajopt.timing")

N_CAND = 9  # jerk candidates j, 0.75 j, ..., -j

_RUCKIG = threading.local()  # one RuckigProfile per thread and (a_max, j_max)


def _ruckig(amax: float, jmax: float) -> RuckigProfile:
    """Return the calling thread's :class:`RuckigProfile` for these limits (built once)."""
    cache = getattr(_RUCKIG, "profiles", None)
    if cache is None:
        cache = _RUCKIG.profiles = {}
    rk = cache.get((amax, jmax))
    if rk is None:
        if len(cache) > 16:
            cache.clear()
        rk = cache[(amax, jmax)] = RuckigProfile(amax, jmax)
    return rk


def time_parameterize(
    curve: ParametricCurve,
    robot: Robot | None = None,
    *,
    v_start: float = 0.0,
    v_end: float = 0.0,
    dt: float = 0.02,
    speed_limits: SpeedLimits | None = None,
    a_start: float = 0.0,
    cap_table: CapTable | None = None,
) -> Trajectory:
    """Time a curve with a near time-optimal, jerk-limited speed profile.

    Parameters
    ----------
    curve : ParametricCurve
        The path (``length``, ``u_at_s``, ``curvature``, ``heading``, ``__call__``).
    robot : Robot, optional
        Limits; default ``Robot()`` (the chapter's robot).
    v_start, v_end : float
        Speed at ``s = 0`` and at ``s = L`` (m/s), >= 0.
    dt : float
        Step of the forward greedy (s), in ``(0, 0.5]``.
    speed_limits : SpeedLimits, optional
        Speed-limit zones (:mod:`trajopt.timing._speed_limits`): the speed is capped by the limit of
        the zone under the robot's centre, one more cap in the cap table (each interval
        takes the lowest limit of the mask cells the curve can touch in it).
    a_start : float
        Tangential acceleration at ``s = 0`` (m/s^2), ``|a_start| <= a_max`` (a moving
        robot's state); the acceleration at ``s = L`` is 0. The profile starts from
        ``(v_start, a_start)`` under the jerk limit and brakes first where the cap ahead
        requires it.
    cap_table : CapTable, optional
        The curve's cap table when the caller has it: :func:`build_cap_table` of this
        ``curve``, ``robot``, ``curve.length``, ``v_start``, ``v_end`` and ``speed_limits``
        (the same arguments; the table is then not built again, and the result is the same
        as without it). Default: built here.

    Returns
    -------
    Trajectory
        Starts at ``s = 0`` with ``v_start``, ends exactly at ``s = L`` with ``v_end``; its
        ``stats`` hold wall times per stage (s) and counts.

    Raises
    ------
    InvalidInputError
        Wrong types, non-finite or negative speeds, a bad ``dt``, a curve without length, a
        ``cap_table`` that is not a :class:`CapTable` or not of the curve's length.
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
    v_start = nonnegative("v_start", v_start, "m/s")
    a_start = number("a_start", a_start, unit="m/s^2", lo=-robot.a_max, hi=robot.a_max)
    v_end = nonnegative("v_end", v_end, "m/s")
    if not (isinstance(dt, (int, float)) and math.isfinite(dt) and 0.0 < dt <= 0.5):
        raise InvalidInputError(f"dt must be a number in (0, 0.5] s, got {dt!r}")
    if speed_limits is not None and not isinstance(speed_limits, SpeedLimits):
        raise InvalidInputError(
            f"speed_limits must be a trajopt.SpeedLimits, got {type(speed_limits).__name__}"
        )
    length = float(curve.length)
    if not (math.isfinite(length) and length > 0.0):
        raise InvalidInputError(f"curve.length must be finite and > 0 m, got {length!r}")

    if cap_table is not None:
        if not isinstance(cap_table, CapTable):
            raise InvalidInputError(
                f"cap_table must be a trajopt.timing.CapTable, got {type(cap_table).__name__}"
            )
        if cap_table.length != length:
            raise InvalidInputError(
                f"cap_table.length must be the curve's length {length!r} m, got "
                f"{cap_table.length!r} m (a table of another curve)"
            )

    amax, jmax = robot.a_max, robot.j_max
    stats: dict[str, Any] = {}

    # ---------------------------------------------------------------- 1. cap table
    t0 = time.perf_counter()
    if cap_table is None:
        table = build_cap_table(curve, robot, length, v_start, v_end, speed_limits)
    else:
        table = cap_table
    d_change = _change_distance(v_start, v_end, jmax, amax) if a_start == 0.0 else 0.0
    if d_change > length * (1.0 + 1e-9):
        raise TimingError(
            f"cannot change speed from v_start={v_start:.6g} m/s to v_end={v_end:.6g} m/s "
            f"within the path length {length:.6g} m: needs {d_change:.6g} m with "
            f"a_max={amax:.6g} m/s^2, j_max={jmax:.6g} m/s^3"
        )
    stats["timing_cap_table_s"] = time.perf_counter() - t0

    # ---------------------------------------------------------------- 2. greedy
    t0 = time.perf_counter()
    phases, bounds = _run_greedy(table, v_start, a_start, v_end, amax, jmax, float(dt))
    stats["timing_greedy_s"] = time.perf_counter() - t0

    # ---------------------------------------------------------------- 3. finish
    t0 = time.perf_counter()
    rk = _ruckig(amax, jmax)
    fin = finish(rk, table, phases, bounds, v_end, jmax)
    if fin is None:
        raise TimingError(
            f"cannot end at s=L={length:.6g} m with v_end={v_end:.6g} m/s under the speed cap "
            f"(cap near the end {table.ci[-1]:.6g} m/s)"
        )
    phases, bounds = fin
    stats["timing_finish_s"] = time.perf_counter() - t0
    greedy_duration = float(bounds[-1, 0])

    # ---------------------------------------------------------------- 4. compress
    t0 = time.perf_counter()
    rows, n_sections = compress(rk, table, phases, bounds)  # (t0, s0, v0, a0, jerk, duration)
    stats["timing_compress_s"] = time.perf_counter() - t0

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
        timing_sections=n_sections,
        timing_grid_intervals=table.n,
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
        theta_grid_s=table.s_nodes,
        theta_grid=table.theta,
        u_grid=table.u_nodes,
        speed_limits=speed_limits,
    )


def _run_greedy(
    table: CapTable,
    v_start: float,
    a_start: float,
    v_end: float,
    amax: float,
    jmax: float,
    dt: float,
) -> tuple[np.ndarray, np.ndarray]:
    """Return the forward greedy's phases and bounds; its failures as :class:`TimingError`."""
    length, h, ci = table.length, table.h, table.ci
    vtop = table.vtop
    t_lower = length / vtop
    max_steps = int(min(5e6, 100.0 * (t_lower + 10.0 * (vtop / amax + amax / jmax)) / dt + 1000))
    limits = greedy.GreedyLimits(
        v0=float(v_start),
        a0=float(a_start),
        v_end=float(v_end),
        amax=float(amax),
        j=float(jmax),
        dt=float(dt),
        ncand=N_CAND,
        tmin=T_MIN,
        max_steps=max_steps,
        cruise=True,
    )
    phases, bounds, status = greedy.greedy(table.arrays, limits, 0)
    if status == greedy.START_INFEASIBLE:
        raise TimingError(
            f"v_start={v_start:.6g} m/s, a_start={a_start:.6g} m/s^2 cannot be brought under "
            f"the speed cap ahead (minimum "
            f"{ci[: max(1, int(v_start**2 / amax / h) + 2)].min():.6g} m/s near the start) "
            f"with a_max={amax:.6g} m/s^2, j_max={jmax:.6g} m/s^3"
        )
    if status == greedy.STUCK:
        raise TimingError(
            f"the timing stopped at rest before the end (s={bounds[-1, 1]:.6g} m of "
            f"{length:.6g} m): no motion stays under the speed cap"
        )
    if status != greedy.OK_FINISH:
        raise TimingError(f"the greedy timing did not finish within {max_steps} steps")
    return phases, bounds


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
