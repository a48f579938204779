"""The smoother's certificate.

Every guarantee of a fitted curve, checked independently of the optimiser that produced it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from trajopt.corridor import CLEARANCE_TOL_M, Corridor, PolygonCorridor
from trajopt.geometry import BSplineCurve, min_points_clearance

#: heading continuity in the certificate: the tangent may turn at most this much between
#: consecutive dense samples (rad; an eighth of a cell apart by default, so only a near-cusp,
#: with a radius of curvature of a fraction of a cell, comes close), and the speed
#: ``|C'(u)|`` must stay above this fraction of its mean
_MAX_HEADING_STEP = math.pi / 8
_MIN_SPEED_RATIO = 1e-2


@dataclass(frozen=True, slots=True)
class Certificate:
    """Evidence that a smoothed curve keeps every guarantee.

    Attributes
    ----------
    span_box : ndarray of int, shape (n_spans,)
        Corridor box holding each span's control points.
    control_points_in_boxes : bool
        Every span's control points lie in its corridor region: its box (exact comparison)
        or its polygon (``A @ c <= b + CLEARANCE_TOL_M``).
    endpoint_error_m : float
        ``max(|C(u0) - start|, |C(u1) - goal|)`` (m).
    radius_m : float or None
        Clearance that was checked (m).
    min_clearance_m : float or None
        Smallest distance from a dense sample of the curve to an occupied square of the raw
        map (outside the map counts as occupied); exact below ``radius_m + 2`` cells,
        otherwise reported as that search window. ``None`` without a raw map.
    n_samples : int
        Number of dense samples (spacing <= one length unit / 8 along ``u``).
    kappa_max_sampled : float
        Largest ``|curvature|`` on the dense samples (1/m).
    kappa_bound : float or None
        The requested bound (1/m).
    min_speed_ratio : float
        Smallest ``|C'(u)|`` over the samples divided by the mean (1 = uniform speed);
        heading continuity requires at least 0.01.
    max_heading_step_rad : float
        Largest heading change between consecutive samples (rad); heading continuity
        requires at most pi / 8 (a larger turn within an eighth of a cell is a near-cusp).
    ok : bool
        All checks passed.
    failures : tuple of str
        Names of the failed checks.
    """

    span_box: np.ndarray
    control_points_in_boxes: bool
    endpoint_error_m: float
    radius_m: float | None
    min_clearance_m: float | None
    n_samples: int
    kappa_max_sampled: float
    kappa_bound: float | None
    min_speed_ratio: float
    max_heading_step_rad: float
    ok: bool
    failures: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        sb = np.array(self.span_box, dtype=np.int64)
        sb.flags.writeable = False
        object.__setattr__(self, "span_box", sb)


def certify(
    curve: BSplineCurve,
    corridor: Corridor,
    span_box: np.ndarray,
    *,
    start: np.ndarray,
    goal: np.ndarray,
    raw_grid: Any = None,
    radius: float | None = None,
    kappa_bound: float | None = None,
    samples_per_cell: int = 8,
    unit_m: float | None = None,
) -> Certificate:
    """Check every guarantee of a smoothed curve (see :class:`Certificate`).

    The dense samples are ``samples_per_cell`` per ``unit_m`` (m; default the corridor's
    length unit) of the parameter ``u`` (arc length along the path).
    """
    failures: list[str] = []
    k = curve.k
    c = curve.c
    ns = len(c) - k
    inside = True
    if isinstance(corridor, PolygonCorridor):
        # span j lies in the convex hull of c_j .. c_{j+k}: all of them in its polygon
        # (the spans of a region are consecutive: check its points once)
        sb = np.asarray(span_box)
        for r in np.unique(sb):
            js = np.flatnonzero(sb == r)
            reg = corridor.regions[int(r)]
            pts = c[int(js[0]) : int(js[-1]) + k + 1]
            inside &= bool(np.all(reg.contains(pts, tol=CLEARANCE_TOL_M)))
    else:
        lo = corridor.lower[span_box]
        hi = corridor.upper[span_box]
        dlo = corridor.diag_lower[span_box]
        dhi = corridor.diag_upper[span_box]
        for off in range(k + 1):
            cp = c[off : off + ns]
            sd = np.column_stack([cp[:, 0] + cp[:, 1], cp[:, 0] - cp[:, 1]])
            inside &= bool(np.all((cp >= lo) & (cp <= hi) & (sd >= dlo) & (sd <= dhi)))
    if not inside:
        failures.append("control_points_in_boxes")
    u0, u1 = curve.domain
    ends = curve(np.array([u0, u1]))
    end_err = float(max(np.hypot(*(ends[0] - start)), np.hypot(*(ends[1] - goal))))
    if end_err > 1e-9:
        failures.append("endpoints")
    res = corridor.unit_m if unit_m is None else float(unit_m)
    m = max(2, int(math.ceil((u1 - u0) / res * samples_per_cell)) + 1)
    u = np.linspace(u0, u1, m)
    xy = curve(u)
    d1 = curve(u, 1)
    d2 = curve(u, 2)
    sp = np.hypot(d1[:, 0], d1[:, 1])
    mean_sp = float(np.mean(sp)) if m else 0.0
    min_ratio = float(sp.min() / mean_sp) if mean_sp > 0 else 0.0
    cross = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        kap = np.where(sp > 0, np.abs(cross) / sp**3, np.inf)
    kmax_s = float(np.max(kap))
    hd = np.arctan2(d1[:, 1], d1[:, 0])
    step = np.abs(np.angle(np.exp(1j * np.diff(hd)))) if m > 1 else np.zeros(1)
    max_step = float(step.max()) if step.size else 0.0
    if min_ratio < _MIN_SPEED_RATIO or max_step > _MAX_HEADING_STEP:
        failures.append("heading_continuity")
    if kappa_bound is not None and not kmax_s <= kappa_bound * (1 + 1e-6):
        failures.append("curvature_bound")
    min_clear = None
    if raw_grid is not None and radius is not None:
        window = radius + 2 * float(raw_grid.resolution)
        min_clear = min_points_clearance(xy, raw_grid, window)
        if min_clear < radius - 1e-9:
            failures.append("clearance")
    return Certificate(
        span_box=span_box,
        control_points_in_boxes=inside,
        endpoint_error_m=end_err,
        radius_m=radius,
        min_clearance_m=min_clear,
        n_samples=m,
        kappa_max_sampled=kmax_s,
        kappa_bound=kappa_bound,
        min_speed_ratio=min_ratio,
        max_heading_step_rad=max_step,
        ok=not failures,
        failures=tuple(failures),
    )
