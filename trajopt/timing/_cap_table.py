"""The timing's speed cap along the arc length: one lower bound per grid interval.

:func:`build_cap_table` tabulates ``cap(s) = Robot.speed_cap(kappa(s))`` (with speed-limit
zones, and a car-like robot's steering-rate cap of :mod:`trajopt.timing._steer_cap`, as
more caps) on a uniform arc-length grid of spacing 2.5 mm (at most :data:`MAX_INTERVALS` intervals: a
curve longer than 41 m gets ``length / MAX_INTERVALS``), each value a
lower bound of the cap over its whole interval (rigorous for curves with a
``polynomial_degree``: the method of :func:`trajopt.geometry._curvature_bound.interval_kappa_max`,
compiled with the grid's ``u(s)`` and heading in :mod:`trajopt.timing._cap_kernel` for the
library's curves; sampled with refinement otherwise). The :class:`CapTable` record carries
the values, their sparse table for O(1) range minima, and the cap's local minima that the
greedy slows down for; :attr:`CapTable.arrays` is the part the compiled greedy reads.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

import trajopt.timing._greedy as greedy
from trajopt.errors import TimingError
from trajopt.geometry import (
    STILL_SPEED_RATIO,
    ParametricCurve,
    interval_kappa_max,
    signed_curvature,
)
from trajopt.robot import Robot
from trajopt.timing._cap_kernel import polynomial_tables
from trajopt.timing._speed_limits import SpeedLimits
from trajopt.timing._steer_cap import steer_caps

GRID_SPACING = 0.0025  # m, arc-length spacing of the cap table
MIN_INTERVALS = 64
#: Most intervals of a cap table: past 41 m of curve the spacing grows with the length. Each
#: interval's cap bounds the whole interval, so the caps hold at any spacing; a coarser
#: table is only more conservative inside an interval. On a 125 m car path (2.5 m robot) the
#: timing took 10 ms at 50 000 intervals and 4 ms at 2^14, with the same duration.
MAX_INTERVALS = 16_384
REFINE = 16  # inner samples of a grid interval around a sharp curvature peak
GOLDEN_STEPS = 30  # golden-section steps locating a peak between those samples (0.618^30)
CAP_MARGIN = 1e-4  # relative margin below the speed cap
T_MIN = 1e-4  # s, finest bisection of a piece in the cap test


@dataclass(frozen=True)
class CapTable:
    """The speed cap per arc-length interval and what the timing stages query on it.

    Attributes
    ----------
    ci : ndarray, shape (n,)
        Cap of interval ``[i h, (i + 1) h]`` (m/s): a lower bound over the interval, less a
        relative margin of ``CAP_MARGIN`` (boundary speeds may use the cap itself).
    h : float
        Grid spacing (m); ``n h = length``.
    length : float
        Arc length of the curve (m).
    st, lg : ndarray
        Sparse table of ``ci`` for O(1) range minima (:func:`greedy.build_table`).
    min_s, min_v : ndarray
        Arc lengths (m) and caps (m/s) of the cap's local minima.
    s_nodes, u_nodes : ndarray, shape (n + 1,)
        Grid nodes in arc length (m) and curve parameter.
    theta : ndarray, shape (n + 1,)
        Unwrapped heading at the nodes (rad).
    """

    ci: np.ndarray
    h: float
    length: float
    st: np.ndarray
    lg: np.ndarray
    min_s: np.ndarray
    min_v: np.ndarray
    s_nodes: np.ndarray
    u_nodes: np.ndarray
    theta: np.ndarray

    @property
    def n(self) -> int:
        """Number of intervals."""
        return int(self.ci.shape[0])

    @property
    def arrays(self) -> greedy.CapArrays:
        """The kernels' view of the table (:class:`~trajopt.timing._greedy.CapArrays`)."""
        return greedy.CapArrays(
            self.st, self.lg, float(self.h), float(self.length), self.min_s, self.min_v
        )

    @property
    def vtop(self) -> float:
        """The highest cap (m/s)."""
        return float(self.ci.max())

    def range_min(self, s_a: float, s_b: float) -> float:
        """Lowest cap over the intervals meeting ``[s_a, s_b]`` (m/s)."""
        return float(greedy.range_min(self.st, self.lg, self.h, s_a, s_b))

    def rows_ok(self, rows: np.ndarray) -> bool:
        """Whether constant-jerk rows ``(t0, s0, v0, a0, jerk, duration)`` stay under the cap.

        Exact on the table's grid.
        """
        return bool(
            greedy.rows_ok(self.st, self.lg, self.h, self.length, np.ascontiguousarray(rows), T_MIN)
        )


def build_cap_table(
    curve: ParametricCurve,
    robot: Robot,
    length: float,
    v_start: float,
    v_end: float,
    speed_limits: SpeedLimits | None = None,
) -> CapTable:
    """Return the :class:`CapTable` of ``curve`` for ``robot``.

    Raises
    ------
    TimingError
        A boundary speed above the cap there, an unbounded curvature (cusp) or a cap of
        about 0 somewhere.
    """
    n_int = min(max(math.ceil(length / GRID_SPACING), MIN_INTERVALS), MAX_INTERVALS)
    h = length / n_int
    s_nodes = np.arange(n_int + 1, dtype=float) * h  # np.linspace(0.0, length, n_int + 1)
    s_nodes[-1] = length
    degree = getattr(curve, "polynomial_degree", None)
    fast = (
        None
        if degree is None
        else polynomial_tables(curve, robot, s_nodes, int(degree), node_kappa=False)
    )
    if fast is not None:  # the compiled path: node tables and bounds in one call
        u_nodes, kappa, theta, kmax, ci, raw_kappa = fast
        ends = np.array([0, 1, n_int - 1, n_int])
    else:
        u_nodes = _table_u_at_s(curve, s_nodes)
        u_nodes[0], u_nodes[-1] = curve.domain
        kappa, theta = _curvature_heading(curve, u_nodes)
        theta = np.unwrap(theta)
        ends = np.arange(n_int + 1)
        raw_kappa = np.asarray(robot.speed_cap(kappa), dtype=float)
    raw = raw_kappa  # the cap at the nodes (all of them, or only the first and last two)
    zone = None
    if speed_limits is not None:
        zone = _zone_caps(curve, u_nodes, h, speed_limits, robot.v_max)
        raw = np.minimum(raw, np.minimum(np.r_[zone[0], zone], np.r_[zone, zone[-1]])[ends])
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
    if fast is None and degree is not None:
        kmax = interval_kappa_max(curve, h, n_int, int(degree), robot.speed_cap)
        ci = np.asarray(robot.speed_cap(kmax), dtype=float)
    elif fast is None:
        ci = _interval_caps(raw_kappa, curve, robot, s_nodes, kappa, theta)
    if degree is not None and not np.all(np.isfinite(kmax)):
        i_inf = int(np.flatnonzero(~np.isfinite(kmax))[0])
        raise TimingError(
            f"the curvature is unbounded at s={i_inf * h:.6g} m (the parametric speed "
            f"vanishes there: a cusp, or a zero-speed end where the curve turns): the "
            f"speed cap is 0"
        )
    if zone is not None:
        ci = np.minimum(ci, zone)
    steering = robot.drive.steering
    if steering is not None and steering.rate_max is not None:
        ci = np.minimum(ci, steer_caps(curve, robot, u_nodes, h, degree))
    # ci = max(ci (1 - margin), min(ci, max(v_start, v_end))), the ends at least the
    # boundary speeds (up to the cap at the end nodes), its sparse table and local minima
    ci = np.array(ci, dtype=float)  # a fresh array: changed in place
    i_low, _, st, lg, idx = greedy.finish_caps(
        ci,
        1.0 - CAP_MARGIN,
        max(v_start, v_end),
        min(v_start, raw[0], raw[1]),
        min(v_end, raw[-1], raw[-2]),
    )
    if not ci[i_low] > 1e-6:
        if np.isnan(kappa[i_low]):  # the compiled path keeps the end nodes only
            kappa = np.asarray(curve.curvature(u_nodes), dtype=float)
        raise TimingError(
            f"the speed cap is {ci[i_low]:.3g} m/s at s={i_low * h:.6g} m (curvature "
            f"{kappa[i_low]:.6g} 1/m): the curve has a cusp or a turn the robot cannot follow"
        )
    min_s = idx * h
    min_v = ci[idx]
    return CapTable(
        ci=ci,
        h=h,
        length=length,
        st=st,
        lg=lg,
        min_s=min_s,
        min_v=min_v,
        s_nodes=s_nodes,
        u_nodes=u_nodes,
        theta=theta,
    )


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
    """Signed curvature.

    Signed curvature (1/m) and heading (rad) at ``u``, sharing one first-derivative evaluation
    when the curve uses the base class's formulas.
    """
    base = ParametricCurve
    if type(curve).curvature is base.curvature and type(curve).heading is base.heading:
        d1 = np.asarray(curve(u, 1), dtype=float)
        kappa = signed_curvature(d1, np.asarray(curve(u, 2), dtype=float))
        theta = np.arctan2(d1[:, 1], d1[:, 0])
        still = np.hypot(d1[:, 0], d1[:, 1]) <= STILL_SPEED_RATIO * curve.mean_speed()
        if np.any(still):  # zero parametric speed: the limit of the tangent direction
            theta[still] = curve.heading(u[still])
        return kappa, theta
    return (
        np.asarray(curve.curvature(u), dtype=float),
        np.asarray(curve.heading(u), dtype=float),
    )


def _interval_caps(
    raw: np.ndarray,
    curve,
    robot: Robot,
    s_nodes: np.ndarray,
    kappa: np.ndarray,
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
        m = REFINE
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
    """Lowest cap found by golden-section search next to each row's lowest sample.

    The search covers the two fine steps around that sample; all rows are searched at once.
    Returns shape (k,).
    """
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
    for _ in range(GOLDEN_STEPS):
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
