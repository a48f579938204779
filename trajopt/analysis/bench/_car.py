"""Metrics of car-like plans (poses, cusps, reversing), shared by trajopt's car methods and OMPL's.

Every car method of the benchmark (``trajopt-ackermann``, ``trajopt-ackermann-forward``,
``ompl-reedsshepp``, ``ompl-dubins``) is scored by the same independent checks, computed here
from points on the method's output only (never from the planner's own certificates):

* **curvature**: circles through three consecutive dense points (spacing
  :data:`CURVATURE_SPACING_CELLS` cells of arc length), within each stretch between cusps (a
  cusp is no curvature), against ``1 / R``: ``curvature_violations`` counts the points above
  ``(1 + KAPPA_TOL) / R``; ``kappa_over_kmax`` is the largest ``kappa R``;
* **cusps and reversing**: ``cusps`` (changes of the direction of travel) and
  ``reverse_length_m`` (arc length driven backwards);
* **motion along the heading**: ``heading_motion_error_rad``, the largest angle between a
  displacement (consecutive samples) and the body heading at its middle, or its reverse when
  the car drives backwards (the sign of the signed speed for trajopt, of the displacement
  along the heading for OMPL, whose path has no speed);
* **headings exact**: ``end_heading_error_rad``, the larger wrapped difference between the
  path's end headings and the query's;
* **rest at cusps** (timed plans only): ``cusp_speed_max_mps``, the largest ``|v|`` at the
  joins of the chain (both sides).

The clearance, length and collision columns are :func:`trajopt.metrics.path_metrics` of the
dense polyline (:func:`chain_polyline`), like every other method's.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

#: Arc-length spacing of the curvature check's points (cells).
CURVATURE_SPACING_CELLS = 0.05
#: Relative tolerance of the curvature check (a point above ``(1 + KAPPA_TOL) / R`` violates).
KAPPA_TOL = 1e-6
#: Time step of the motion-along-the-heading check of timed plans (s).
MOTION_DT_S = 0.01


def three_point_curvature(p: np.ndarray) -> np.ndarray:
    """Curvature of the circle through each three consecutive points (1/m).

    Parameters
    ----------
    p : ndarray, shape (n, 2)
        Points (m), n >= 3 (fewer: an empty result).

    Returns
    -------
    ndarray, shape (n - 2,)
        ``2 |(b - a) x (c - a)| / (|b - a| |c - b| |c - a|)``; 0 where two points coincide.
    """
    p = np.asarray(p, dtype=float)
    if len(p) < 3:
        return np.zeros(0)
    a, b, c = p[:-2], p[1:-1], p[2:]
    ab, bc, ac = b - a, c - b, c - a
    cross = np.abs(ab[:, 0] * ac[:, 1] - ab[:, 1] * ac[:, 0])
    den = np.hypot(*ab.T) * np.hypot(*bc.T) * np.hypot(*ac.T)
    with np.errstate(divide="ignore", invalid="ignore"):
        k = np.where(den > 0.0, 2.0 * cross / np.where(den > 0.0, den, 1.0), 0.0)
    return k


def wrap(a: np.ndarray | float) -> np.ndarray:
    """Angles wrapped to ``[-pi, pi)`` (rad)."""
    return np.remainder(np.asarray(a, dtype=float) + math.pi, 2.0 * math.pi) - math.pi


def curvature_stats(segments: list[np.ndarray], kmax: float) -> dict[str, Any]:
    """Three-point curvature over stretches between cusps.

    Parameters
    ----------
    segments : list of ndarray, shape (n_i, 2)
        Dense points (m) of each stretch, in order along it.
    kmax : float
        ``1 / R`` (1/m).

    Returns
    -------
    dict
        ``max_curvature_1pm``, ``rms_curvature_1pm`` (over the points), ``int_sq_curvature_1pm``
        (``sum kappa^2 ds``, 1/m), ``kappa_over_kmax``, ``curvature_violations``,
        ``max_heading_jump_rad`` (largest turn between consecutive chords of a stretch).
    """
    ks, ws, jumps = [], [], [0.0]
    for pts in segments:
        k = three_point_curvature(pts)
        if len(k):
            ks.append(k)
            d = np.hypot(*np.diff(pts, axis=0).T)
            ws.append(0.5 * (d[:-1] + d[1:]))
            ang = np.arctan2(*np.diff(pts, axis=0)[:, ::-1].T)
            jumps.append(float(np.max(np.abs(wrap(np.diff(ang))))))
    k = np.concatenate(ks) if ks else np.zeros(1)
    w = np.concatenate(ws) if ws else np.zeros(1)
    kmx = float(k.max())
    return {
        "max_curvature_1pm": kmx,
        "rms_curvature_1pm": float(np.sqrt(np.mean(k**2))),
        "int_sq_curvature_1pm": float(np.sum(k**2 * w)),
        "kappa_over_kmax": kmx / kmax,
        "curvature_violations": int(np.count_nonzero(k > kmax * (1.0 + KAPPA_TOL))),
        "max_heading_jump_rad": max(jumps),
    }


def motion_error(xy: np.ndarray, theta: np.ndarray, sign: np.ndarray) -> float:
    """Largest angle between each displacement and the heading at its middle (rad).

    Parameters
    ----------
    xy : ndarray, shape (n, 2)
        Positions (m) in time (or path) order.
    theta : ndarray, shape (n,)
        Body headings (rad) at those positions.
    sign : ndarray, shape (n - 1,)
        Direction of travel of each displacement: ``+1`` forwards, ``-1`` backwards (then the
        displacement must point along ``theta + pi``), ``0``: taken from the displacement.

    Returns
    -------
    float
        0 when no displacement is longer than ``1e-12`` m.
    """
    d = np.diff(np.asarray(xy, dtype=float), axis=0)
    th = np.asarray(theta, dtype=float)
    mid = th[:-1] + 0.5 * wrap(th[1:] - th[:-1])
    along = d[:, 0] * np.cos(mid) + d[:, 1] * np.sin(mid)
    sgn = np.where(np.asarray(sign) != 0, np.sign(sign), np.sign(along))
    moving = np.hypot(*d.T) > 1e-12
    if not moving.any():
        return 0.0
    ang = np.arctan2(d[:, 1], d[:, 0]) - mid - np.where(sgn < 0, math.pi, 0.0)
    return float(np.max(np.abs(wrap(ang[moving]))))


def chain_polyline(chain: Any, spacing: float) -> list[np.ndarray]:
    """Dense points of each piece of a :class:`~trajopt.motion.TrajectoryChain` (m).

    Points every ``spacing`` m of arc length (at most) along each piece's curve, its ends
    included; a piece's curve runs in its direction of travel. A car's steering at rest
    (:class:`~trajopt.motion.SteerInPlace`) has no curve and is left out.

    Returns
    -------
    list of ndarray, shape (n_i, 2)
    """
    out = []
    for piece in chain.pieces:
        if piece.steering_at_rest:  # standing still: no curve
            continue
        n = max(3, math.ceil(piece.length / spacing) + 1)
        s = np.linspace(0.0, piece.length, n)
        out.append(np.asarray(piece.path(piece.path.u_at_s(s)), dtype=float))
    return out


def chain_metrics(
    chain: Any, kmax: float, headings: tuple[float, float], spacing: float
) -> tuple[np.ndarray, dict[str, Any]]:
    """Score a car's timed plan (module docstring).

    Parameters
    ----------
    chain : TrajectoryChain
        One piece per stretch between cusps, each with ``direction``.
    kmax : float
        ``1 / R`` (1/m).
    headings : tuple of float
        The query's start and goal headings (rad).
    spacing : float
        Arc-length spacing of the curvature check (m).

    Returns
    -------
    polyline : ndarray, shape (n, 2)
        The pieces' dense points joined (m), for :func:`~trajopt.metrics.path_metrics`.
    extras : dict
        The car columns and the per-stretch curvature columns.
    """
    segs = chain_polyline(chain, spacing)
    poly = np.vstack([segs[0]] + [s[1:] for s in segs[1:]])
    out = curvature_stats(segs, kmax)
    dirs = [int(getattr(p, "direction", 1) or 1) for p in chain.pieces]
    out["cusps"] = int(sum(a != b for a, b in zip(dirs[:-1], dirs[1:], strict=True)))
    out["reverse_length_m"] = float(
        sum(p.length for p, d in zip(chain.pieces, dirs, strict=True) if d < 0)
    )
    n = max(3, math.ceil(chain.duration / MOTION_DT_S) + 1)
    smp = chain.sample(np.linspace(0.0, chain.duration, n))
    xy = np.column_stack([smp.x, smp.y])
    v = np.asarray(smp.v, dtype=float)
    out["heading_motion_error_rad"] = motion_error(xy, smp.theta, np.sign(v[:-1] + v[1:]))
    ends = chain.sample(np.array([0.0, chain.duration]))
    out["end_heading_error_rad"] = float(
        np.max(np.abs(wrap(np.asarray(ends.theta) - np.asarray(headings))))
    )
    joins = np.asarray(chain.piece_times, dtype=float)[1:-1]
    if len(joins):
        eps = 1e-9 * max(1.0, chain.duration)
        at = chain.sample(np.concatenate([joins, np.maximum(joins - eps, 0.0)]))
        out["cusp_speed_max_mps"] = float(np.max(np.abs(at.v)))
    else:
        out["cusp_speed_max_mps"] = 0.0
    return poly, out


def pose_path_metrics(
    xy: np.ndarray, yaw: np.ndarray, kmax: float, headings: tuple[float, float]
) -> dict[str, Any]:
    """Score an untimed path of poses (OMPL's interpolated Reeds-Shepp/Dubins states).

    Parameters
    ----------
    xy : ndarray, shape (n, 2)
        Dense positions (m) along the path.
    yaw : ndarray, shape (n,)
        Body headings (rad).
    kmax : float
        ``1 / R`` (1/m).
    headings : tuple of float
        The query's start and goal headings (rad).

    Returns
    -------
    dict
        The car columns (``cusp_speed_max_mps`` NaN: the path is not timed).
    """
    xy = np.asarray(xy, dtype=float)
    yaw = np.asarray(yaw, dtype=float)
    d = np.diff(xy, axis=0)
    mid = yaw[:-1] + 0.5 * wrap(yaw[1:] - yaw[:-1])
    along = d[:, 0] * np.cos(mid) + d[:, 1] * np.sin(mid)
    moving = np.abs(along) > 1e-12
    sgn = np.sign(along)
    # stretches between cusps: runs of one sign of the displacement along the heading. A cusp
    # lies between two samples (the interpolation need not hit it): the two displacements
    # next to a change of sign may straddle it, so neither belongs to a stretch (nor to the
    # motion check): a path sampled across its cusp is no curvature.
    segs, cusps, start, last = [], 0, 0, 0.0
    keep = np.ones(len(d), dtype=bool)
    prev = -1
    for i in np.flatnonzero(moving):
        if last != 0.0 and sgn[i] != last:
            segs.append(xy[start : prev + 1])
            keep[[prev, i]] = False
            start = i + 1
            cusps += 1
        last, prev = sgn[i], i
    segs.append(xy[start:])
    out = curvature_stats([s for s in segs if len(s) >= 3], kmax)
    out["cusps"] = cusps
    out["reverse_length_m"] = float(np.sum(np.hypot(*d[along < 0].T))) if len(d) else 0.0
    idx = np.flatnonzero(keep)
    err = 0.0
    for run in np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1):  # runs of kept displacements
        if len(run):
            sl = slice(run[0], run[-1] + 2)
            err = max(err, motion_error(xy[sl], yaw[sl], np.zeros(len(run))))
    out["heading_motion_error_rad"] = err
    out["end_heading_error_rad"] = float(
        np.max(np.abs(wrap(yaw[[0, -1]] - np.asarray(headings, dtype=float))))
    )
    out["cusp_speed_max_mps"] = math.nan
    return out
