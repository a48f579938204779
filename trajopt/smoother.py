"""The proposed smoother: a corridor-constrained B-spline fit, certified collision-free.

:class:`Smoother` fits a clamped B-spline ``C(u) = sum_i c_i B_i(u)`` (parameter ``u`` =
arc length along the path) to path points ``p_r`` at their arc lengths ``u_r``:

    minimise   lam * sum_r |C(u_r) - p_r|^2  +  w * integral |C^(m)(u)|^2 du
               + ell * integral |C'(u)|^2 du                                     (cell units)
    subject to c_0 = start, c_{n-1} = goal,
               c_i in the intersection of the corridor regions of every span it touches,
               optional: c_1 on the start-heading ray, c_{n-2} on the reverse goal ray,
               optional: |kappa| <= kappa_max at dense samples (with a speed floor).

With the *fidelity* objective (default in a box corridor) ``p_r`` are the A* cell centres,
``lam = 1`` and ``ell = 0``: the chapter's least-squares fidelity (equation (3)) plus the
knot-aware integrated squared ``m``-th derivative (exact Gram matrix of the derivative
basis). With the *taut* objective (default in a :class:`~trajopt.polygon_corridor.
PolygonCorridor`) ``p_r`` are the corridor's path sampled once per cell, ``lam`` is small
and the length term pulls the curve taut. Positions and parameters are divided by the grid
resolution first, so the default weights work on every map.

The corridor constraint uses the convex-hull property: span ``j`` lies in the convex hull
of ``c_j .. c_{j+p}``; with all of them inside the span's region the whole continuous span
is inside it. Knots are graded so that every region holds at least ``p`` spans (then no
control point touches more than two consecutive regions, which always intersect), so each
control point is bounded by one intersection: variable bounds for the axis-aligned boxes
plus two rows ``x + y`` and ``x - y`` for the 45-degree *bridges* the corridor places in
diagonal gaps, or the half-planes of its (at most two) polygons in a polygon corridor.
The convex problem is a sparse banded QP solved by piqp (by default): through
``casadi.conic`` in a box corridor, directly in a polygon corridor (its rows per point
vary). The curvature-bounded problem is solved by sequential convex programming (a few
QPs with the bound linearised at the current iterate, l1-penalised slacks and a trust
region, solved by piqp directly over a working set of the samples near the bound;
``curvature_solver="scp"``, the default) or by IPOPT on the exact non-convex
problem, warm-started from the QP (``curvature_solver="ipopt"``). Solvers are built once
per padded size and cached.

Every result is verified (:class:`Certificate`) before it is returned: control points in
their regions, exact endpoints, dense-sample clearance against the raw map, no cusp, and the
curvature bound. On failure the knots are refined; when that is exhausted
:class:`~trajopt.errors.SmoothingError` is raised with the solver statistics.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from trajopt import _qp
from trajopt.bspline import BSplineCurve
from trajopt.clearance import points_clearance
from trajopt.corridor import Corridor
from trajopt.curve import ParametricCurve
from trajopt.errors import InvalidInputError, SmoothingError
from trajopt.polygon_corridor import CLEARANCE_TOL_M, PolygonCorridor

__all__ = ["Smoother", "SmoothPath", "Certificate"]

logger = logging.getLogger(__name__)

QPSolver = Literal["osqp", "piqp", "ipopt"]
_QP_SOLVERS = ("osqp", "piqp", "ipopt")
CurvatureSolver = Literal["scp", "ipopt"]
_CURVATURE_SOLVERS = ("scp", "ipopt")
_OBJECTIVES = ("auto", "fidelity", "taut")
Objective = Literal["auto", "fidelity", "taut"]


# ----------------------------------------------------------------------- values
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
        Number of dense samples (spacing <= resolution / 8 along ``u``).
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


@dataclass(frozen=True, slots=True, eq=False)
class SmoothPath(ParametricCurve):
    """A certified smooth path: a :class:`~trajopt.bspline.BSplineCurve` plus evidence.

    The :class:`~trajopt.curve.ParametricCurve` interface (``__call__(u, nu)``, ``heading``,
    ``curvature``, ``length``, ``u_at_s``, ``sample``) delegates to :attr:`curve`; ``u`` is
    in metres (arc length of the A* polyline) and positions are world metres.

    Attributes
    ----------
    curve : BSplineCurve
        The clamped B-spline in world coordinates.
    stats : dict
        Solver statistics: ``status``, ``success``, ``solver``, ``iterations``,
        ``solve_time_s`` (solver calls), ``build_time_s`` (solvers built in this call),
        ``total_time_s``, ``cost``, ``attempts``, ``n_control_points``, ``padded_size``.
    certificate : Certificate
    """

    curve: BSplineCurve
    stats: dict[str, Any] = field(default_factory=dict)
    certificate: Certificate | None = None

    @property
    def domain(self) -> tuple[float, float]:
        return self.curve.domain

    def __call__(self, u: np.ndarray | float, nu: int = 0) -> np.ndarray:
        return self.curve(u, nu)

    def breakpoints(self) -> np.ndarray:
        return self.curve.breakpoints()

    def _arc_table(self):
        return self.curve._arc_table()

    @property
    def control_points(self) -> np.ndarray:
        """Control points, shape (n, 2) (m, read-only)."""
        return self.curve.c

    @property
    def knots(self) -> np.ndarray:
        """Knot vector, shape (n + k + 1,) (m, read-only)."""
        return self.curve.t

    @property
    def degree(self) -> int:
        return self.curve.k

    @property
    def polynomial_degree(self) -> int:
        return self.curve.k


# --------------------------------------------------------------------- smoother
@dataclass(frozen=True, slots=True)
class Smoother:
    """Corridor-constrained B-spline smoother (options validated on construction).

    Parameters
    ----------
    degree : int, optional
        Spline degree, 3 to 5. Default 3 (C2 curve: continuous curvature).
    smoothness_weight : float, optional
        ``w`` of the integrated squared derivative, in cell units (>= 0). Default 50.
    smoothness_order : int, optional
        Derivative order ``m`` of the smoothness term, 1 .. degree - 1. Default 2.
    span_cells : float, optional
        Longest knot span in cells (the grading shortens spans near box transitions).
        Default 4.
    kappa_max : float or None, optional
        Curvature bound (1/m); ``None`` (default) for the QP only.
    kappa_margin : float, optional
        The bound imposed at the collocation samples is ``kappa_margin * kappa_max`` (0, 1]
        so that it also holds between them. Default 0.9.
    speed_floor : float, optional
        With a curvature bound, ``|C'(u)| >= speed_floor`` at the samples (cells per cell of
        ``u``; 1 is the A* polyline's speed). Prevents cusps. Default 0.2.
    qp_solver : {"piqp", "osqp", "ipopt"}, optional
        Solver of the convex problem. Default "piqp" (an interior-point method: steady
        iteration counts, and no state kept between calls, so results are reproducible
        bit for bit; osqp warm-starts its duals from the previous call).
    curvature_solver : {"scp", "ipopt"}, optional
        How the curvature-bounded problem is solved. ``"scp"`` (default): sequential
        convex programming, a few piqp QPs in which the bound is linearised
        conservatively around the previous iterate's tangents, inside a trust region
        (from 64 control points up, only the samples near the bound, and their
        neighbours, enter the QPs; the step's acceptance still checks every sample).
        ``"ipopt"``: the exact non-convex problem by IPOPT, warm started from the QP
        (slower by one to two orders of magnitude; see ``docs/benchmarks.md``).
    scp_iterations : int, optional
        Most SCP iterations. Default 25.
    time_budget_s : float, optional
        Wall-time budget per :meth:`fit` call (s); exceeded -> ``SmoothingError``.
        Default 5 (the first call of a new size also builds its solvers).
    max_attempts : int, optional
        Knot refinements (span length halved each time) before giving up. Default 3. When
        the certificate finds only the curvature bound broken (between the samples) and
        by at most 10 %, the same knots are first solved once more, warm started, with
        the sampled bound tightened by the excess found.
    samples_per_cell : int, optional
        Certificate sampling density along ``u`` (samples per cell). Default 8.
    objective : {"auto", "fidelity", "taut"}, optional
        ``"fidelity"``: least squares to the path points plus the smoothness term (the
        chapter's fit, regularised). ``"taut"``: the smoothness term plus a length term
        ``taut_length_weight * integral |C'|^2`` (shortest at constant speed: a straight,
        evenly paced line) with the path points only as a weak regulariser
        (``taut_fidelity_weight`` each), so the curve is pulled taut inside the corridor
        instead of towards a staircase of cells. ``"auto"`` (default): ``"taut"`` in a
        polygon corridor, ``"fidelity"`` in a box corridor.
    taut_fidelity_weight : float, optional
        Weight of each path point in the taut objective (>= 0). Default 0.02.
    taut_length_weight : float, optional
        Weight of the length term in the taut objective (>= 0), in cell units. Default 2.
    verbose : bool, optional
        Let the solvers print. Default False.
    """

    degree: int = 3
    smoothness_weight: float = 50.0
    smoothness_order: int = 2
    span_cells: float = 4.0
    kappa_max: float | None = None
    kappa_margin: float = 0.9
    speed_floor: float = 0.2
    qp_solver: QPSolver = "piqp"
    curvature_solver: CurvatureSolver = "scp"
    scp_iterations: int = 25
    time_budget_s: float = 5.0
    max_attempts: int = 3
    samples_per_cell: int = 8
    objective: Objective = "auto"
    taut_fidelity_weight: float = 0.02
    taut_length_weight: float = 2.0
    verbose: bool = False

    def __post_init__(self) -> None:
        if not isinstance(self.degree, (int, np.integer)) or not 3 <= self.degree <= 5:
            raise InvalidInputError(f"degree must be an integer in 3..5, got {self.degree!r}")
        _check_float("smoothness_weight", self.smoothness_weight, lo=0.0)
        if (
            not isinstance(self.smoothness_order, (int, np.integer))
            or not 1 <= self.smoothness_order <= self.degree - 1
        ):
            raise InvalidInputError(
                f"smoothness_order must be an integer in 1..degree-1 = 1..{self.degree - 1}, "
                f"got {self.smoothness_order!r}"
            )
        _check_float("span_cells", self.span_cells, lo=0.5)
        if self.kappa_max is not None:
            _check_float("kappa_max", self.kappa_max, lo=0.0, strict=True)
        _check_float("kappa_margin", self.kappa_margin, lo=0.0, strict=True)
        if self.kappa_margin > 1:
            raise InvalidInputError(f"kappa_margin must be in (0, 1], got {self.kappa_margin!r}")
        _check_float("speed_floor", self.speed_floor, lo=0.0)
        if self.qp_solver not in _QP_SOLVERS:
            raise InvalidInputError(
                f"qp_solver must be one of {_QP_SOLVERS}, got {self.qp_solver!r}"
            )
        if self.curvature_solver not in _CURVATURE_SOLVERS:
            raise InvalidInputError(
                f"curvature_solver must be one of {_CURVATURE_SOLVERS}, "
                f"got {self.curvature_solver!r}"
            )
        if not isinstance(self.scp_iterations, (int, np.integer)) or self.scp_iterations < 1:
            raise InvalidInputError(
                f"scp_iterations must be an integer >= 1, got {self.scp_iterations!r}"
            )
        _check_float("time_budget_s", self.time_budget_s, lo=0.0, strict=True)
        if not isinstance(self.max_attempts, (int, np.integer)) or self.max_attempts < 1:
            raise InvalidInputError(
                f"max_attempts must be an integer >= 1, got {self.max_attempts!r}"
            )
        if not isinstance(self.samples_per_cell, (int, np.integer)) or self.samples_per_cell < 2:
            raise InvalidInputError(
                f"samples_per_cell must be an integer >= 2, got {self.samples_per_cell!r}"
            )
        if self.objective not in _OBJECTIVES:
            raise InvalidInputError(
                f"objective must be one of {_OBJECTIVES}, got {self.objective!r}"
            )
        _check_float("taut_fidelity_weight", self.taut_fidelity_weight, lo=0.0)
        _check_float("taut_length_weight", self.taut_length_weight, lo=0.0)

    # ----------------------------------------------------------------- public
    def fit(
        self,
        grid_path_or_points: Any,
        corridor: Corridor | PolygonCorridor,
        *,
        raw_grid: Any = None,
        radius: float | None = None,
        start: np.ndarray | tuple[float, float] | None = None,
        goal: np.ndarray | tuple[float, float] | None = None,
        start_heading: float | None = None,
        goal_heading: float | None = None,
    ) -> SmoothPath:
        """Fit a certified smooth path inside ``corridor``.

        Parameters
        ----------
        grid_path_or_points : astar.GridPath or array_like, shape (n, 2)
            The A* path (a GridPath or an *integer* array of cells ``(ix, iy)``: the cell
            centres are the fidelity targets) or float target points in world metres, one
            per path cell of ``corridor`` (``None``: the corridor's path). Not used with a
            polygon corridor, whose own (centred, simplified) path gives the targets.
        corridor : Corridor or PolygonCorridor
            From :func:`~trajopt.corridor.build_corridor` on the same path, or from
            :func:`~trajopt.polygon_corridor.build_polygon_corridor`.
        raw_grid : astar.OccupancyGrid, optional
            The raw (not inflated) map; when given, the certificate checks the clearance by
            dense sampling (point-to-square distance, outside the map counts as occupied).
        radius : float, optional
            Clearance to certify (m); default ``corridor.radius``.
        start, goal : array_like, shape (2,), optional
            Exact end points (m); default the first and last path points. Each must lie in
            its end region.
        start_heading, goal_heading : float, optional
            Exact tangent directions (rad) at the ends.

        Returns
        -------
        SmoothPath

        Raises
        ------
        InvalidInputError
            Malformed input (message names the field, value and rule).
        SmoothingError
            No curve meeting every guarantee within ``max_attempts`` refinements or the time
            budget; ``.stats`` holds the statistics of every attempt.
        """
        _warm_imports()  # one-off module imports do not count against the time budget
        t_call = time.perf_counter()
        polygons = isinstance(corridor, PolygonCorridor)
        if not (polygons or isinstance(corridor, Corridor)):
            raise InvalidInputError(
                f"corridor must be a Corridor or a PolygonCorridor, got {type(corridor).__name__}"
            )
        if polygons and "ipopt" in (self.qp_solver, self.curvature_solver):
            raise InvalidInputError(
                "qp_solver='ipopt' and curvature_solver='ipopt' take box corridors only; a "
                "PolygonCorridor is solved by piqp or osqp (and the SCP)"
            )
        res = corridor.resolution
        origin = np.asarray(corridor.origin, dtype=float)
        rad = corridor.radius if radius is None else float(radius)
        if radius is not None and not (math.isfinite(rad) and rad >= 0):
            raise InvalidInputError(f"radius must be finite and >= 0 m, got {radius!r}")
        if raw_grid is not None and rad is None:
            raise InvalidInputError("radius is required (or corridor.radius) with raw_grid")
        hs = _heading("start_heading", start_heading)
        hg = _heading("goal_heading", goal_heading)
        if corridor.length_m <= 0:
            raise InvalidInputError("the corridor's path has zero length (start == goal)")
        taut = self.objective == "taut" or (self.objective == "auto" and polygons)
        if polygons:
            targets, u_m = _polygon_targets(corridor)
            p0 = _point("start", start, corridor.path[0])
            p1 = _point("goal", goal, corridor.path[-1])
            for name, pt, k in (("start", p0, 0), ("goal", p1, len(corridor.regions) - 1)):
                reg = corridor.regions[k]
                if not bool(reg.contains(pt[None, :], tol=CLEARANCE_TOL_M)[0]):
                    raise InvalidInputError(
                        f"{name} {pt.tolist()} m must lie in the corridor's region {k} "
                        f"(vertices {np.round(reg.vertices, 6).tolist()} m)"
                    )
            rows, lo_r, hi_r = _region_rows(corridor, origin, res)
            prob = _Problem(
                targets=(targets - origin) / res,
                u=u_m / res,
                lo=lo_r,
                hi=hi_r,
                dlo=np.full((len(rows), 2), -np.inf),
                dhi=np.full((len(rows), 2), np.inf),
                trans=corridor.transitions_m / res,
                overlap=(corridor.overlap_s[:, 1] - corridor.overlap_s[:, 0]) / res,
                start=(p0 - origin) / res,
                goal=(p1 - origin) / res,
                start_dir=None if hs is None else np.array([math.cos(hs), math.sin(hs)]),
                goal_dir=None if hg is None else np.array([math.cos(hg), math.sin(hg)]),
                res=res,
                rows=rows,
                taut=taut,
            )
        else:
            targets = _targets(grid_path_or_points, corridor)
            p0 = _point("start", start, targets[0])
            p1 = _point("goal", goal, targets[-1])
            b0, b1 = corridor.boxes[0], corridor.boxes[-1]
            if not b0.contains(p0):
                raise InvalidInputError(f"start {p0.tolist()} m must lie in the first box {b0}")
            if not b1.contains(p1):
                raise InvalidInputError(f"goal {p1.tolist()} m must lie in the last box {b1}")
            prob = _Problem(
                targets=(targets - origin) / res,
                u=corridor.path_s / res,
                lo=(corridor.lower - origin) / res,
                hi=(corridor.upper - origin) / res,
                dlo=(corridor.diag_lower - _sd(origin)) / res,
                dhi=(corridor.diag_upper - _sd(origin)) / res,
                trans=corridor.transitions_m / res,
                overlap=(corridor.overlap_end_m - corridor.overlap_start_m) / res,
                start=(p0 - origin) / res,
                goal=(p1 - origin) / res,
                start_dir=None if hs is None else np.array([math.cos(hs), math.sin(hs)]),
                goal_dir=None if hg is None else np.array([math.cos(hg), math.sin(hg)]),
                res=res,
                taut=taut,
            )
        attempts: list[dict[str, Any]] = []
        h = float(self.span_cells)
        margin = self.kappa_margin
        warm = None  # control points (cells) of a retry on the same knots
        spans_tried = 0
        while spans_tried < int(self.max_attempts):
            remaining = self.time_budget_s - (time.perf_counter() - t_call)
            if remaining <= 0:
                break
            st: dict[str, Any] = {"attempt": len(attempts) + 1, "span_cells": h}
            if warm is not None:
                st["kappa_margin"] = margin
            attempts.append(st)
            try:
                c_cells, t_cells, span_box, st2 = self._solve(prob, h, remaining, margin, warm)
            except _AttemptFailed as exc:
                st.update(exc.stats)
                st["failure"] = str(exc)
                h, margin, warm = max(0.5, h / 2), self.kappa_margin, None
                spans_tried += 1
                continue
            st.update(st2)
            c = origin + res * c_cells
            c[0] = p0
            c[-1] = p1
            curve = BSplineCurve(t_cells * res, c, self.degree)
            cert = certify(
                curve,
                corridor,
                span_box,
                start=p0,
                goal=p1,
                raw_grid=raw_grid,
                radius=rad,
                kappa_bound=self.kappa_max,
                samples_per_cell=self.samples_per_cell,
            )
            st["certificate_ok"] = cert.ok
            if cert.ok:
                stats = _summary(attempts, time.perf_counter() - t_call, success=True)
                return SmoothPath(curve=curve, stats=stats, certificate=cert)
            st["failure"] = "certificate: " + ", ".join(cert.failures)
            logger.debug("attempt %d failed its certificate: %s", len(attempts), cert.failures)
            if (
                warm is None
                and self.kappa_max is not None
                and cert.failures == ("curvature_bound",)
                and 0 < cert.kappa_max_sampled <= _RETRY_MAX_EXCESS * self.kappa_max
            ):
                # the bound broke between the samples only, and by a little: the same knots
                # again, warm started, with the sampled bound tightened by the excess found
                # (cheaper than a refinement, which doubles the problem; a larger excess
                # tightens the bound at many samples at once, and the warm start is then no
                # better than a cold one)
                logger.debug("dense max kappa %.4g x the bound: same knots again",
                             cert.kappa_max_sampled / self.kappa_max)
                margin *= _MARGIN_RETRY * self.kappa_max / cert.kappa_max_sampled
                warm = c_cells
                continue
            h, margin, warm = max(0.5, h / 2), self.kappa_margin, None
            spans_tried += 1
        stats = _summary(attempts, time.perf_counter() - t_call, success=False)
        last = attempts[-1].get("failure", "time budget exhausted") if attempts else "no attempt"
        raise SmoothingError(
            f"no certified curve after {len(attempts)} attempt(s) "
            f"(time_budget_s={self.time_budget_s}): {last}",
            stats,
        )

    def fit_free(self, points: np.ndarray, u: np.ndarray, knots: np.ndarray) -> BSplineCurve:
        """The same objective with *no* constraints (no corridor, free ends, no bound).

        A reference and test hook: with ``smoothness_weight = 0`` it is the least-squares
        spline of ``points`` at parameters ``u`` on ``knots`` (as
        :func:`scipy.interpolate.make_lsq_spline`). No guarantee of any kind.

        Parameters
        ----------
        points : array_like, shape (N, 2)
        u : array_like, shape (N,)
            Non-decreasing parameters inside the knot domain.
        knots : array_like, shape (n + k + 1,)
            Clamped knots.
        """
        pts = np.asarray(points, dtype=float)
        uu = np.asarray(u, dtype=float)
        t = np.asarray(knots, dtype=float)
        p = self.degree
        n = len(t) - p - 1
        if pts.ndim != 2 or pts.shape[1] != 2 or uu.shape != (len(pts),):
            raise InvalidInputError(
                f"points must have shape (N, 2) and u shape (N,), got {pts.shape} and {uu.shape}"
            )
        if n < p + 1:
            raise InvalidInputError(f"need at least {2 * p + 2} knots for degree {p}, got {len(t)}")
        band, g, _ = _objective(pts, uu, t, p, n, self.smoothness_weight, self.smoothness_order)
        nb = _qp.bucket_size(n)
        full = np.zeros((p + 1, nb))
        full[:, :n] = band[:, :n]
        full[0, n:] = 1.0
        lbx = np.full(2 * nb, -np.inf)
        ubx = np.full(2 * nb, np.inf)
        lbx[n:nb] = ubx[n:nb] = lbx[nb + n :] = ubx[nb + n :] = 0.0
        n_rows = _qp.N_HEADING_ROWS + 2 * nb
        qp = _QPData(full=full, g=g, n=n, nb=nb, lbx=lbx, ubx=ubx,
                     heading=np.zeros((_qp.N_HEADING_ROWS, 2 * nb)),
                     lba=np.full(n_rows, -np.inf), uba=np.full(n_rows, np.inf))
        z, info = self._solve_qp(qp, 60.0)
        if not info["success"]:
            raise SmoothingError(f"unconstrained fit failed: {info['status']}", info)
        return BSplineCurve(t, np.column_stack([z[:n], z[nb : nb + n]]), p)

    # ---------------------------------------------------------------- internal
    def _solve(self, prob: _Problem, h: float, remaining: float, margin: float,
               warm: np.ndarray | None = None):
        """One attempt on the knots of span ``h`` (cells): the QP, then with a curvature
        bound the SCP (sampled bound ``margin * kappa_max``). ``warm``: control points (cells)
        of an earlier attempt on the same knots; the SCP then starts from them instead of
        the QP solution."""
        t_enter = time.perf_counter()
        p = self.degree
        t, span_box = graded_knots(prob.u[-1], prob.trans, prob.overlap, p, h)
        n = len(t) - p - 1
        nb = _qp.bucket_size(n)
        # control-point bounds: intersection of the regions of the spans each one touches
        lo = np.full((n, 2), -np.inf)
        hi = np.full((n, 2), np.inf)
        dlo = np.full((n, 2), -np.inf)
        dhi = np.full((n, 2), np.inf)
        for off in range(p + 1):
            idx = np.arange(len(span_box)) + off
            lo[idx] = np.maximum(lo[idx], prob.lo[span_box])
            hi[idx] = np.minimum(hi[idx], prob.hi[span_box])
            dlo[idx] = np.maximum(dlo[idx], prob.dlo[span_box])
            dhi[idx] = np.minimum(dhi[idx], prob.dhi[span_box])
        if np.any(lo > hi) or np.any(dlo > dhi):
            raise _AttemptFailed("empty control-point bound (regions do not intersect)", {})
        lo[0] = hi[0] = prob.start
        lo[-1] = hi[-1] = prob.goal
        dlo[[0, -1]] = -np.inf  # the fixed ends were checked against their regions
        dhi[[0, -1]] = np.inf
        if prob.taut:
            band, g, const = _objective(
                prob.targets, prob.u, t, p, n, self.smoothness_weight, self.smoothness_order,
                fidelity=self.taut_fidelity_weight, length=self.taut_length_weight,
            )  # fmt: skip
        else:
            band, g, const = _objective(
                prob.targets, prob.u, t, p, n, self.smoothness_weight, self.smoothness_order
            )
        band[0] += 1e-9 * (1.0 + band[0].max())  # keeps the Hessian definite
        full = np.zeros((p + 1, nb))
        full[:, :n] = band[:, :n]
        full[0, n:] = 1.0  # padded variables: fixed at 0 by their bounds
        lbx = np.zeros(2 * nb)
        ubx = np.zeros(2 * nb)
        lbx[:n], lbx[nb : nb + n] = lo[:, 0], lo[:, 1]
        ubx[:n], ubx[nb : nb + n] = hi[:, 0], hi[:, 1]
        heading, lba, uba = _heading_rows(prob, n, nb)
        point_rows = None
        if prob.rows is None:
            k_rows, coef = 2, None
            rlb, rub = _diag_row_bounds(dlo, dhi, nb)
        else:
            k_rows, coef, rlb, rub = _point_rows(prob.rows, span_box, n, p, lo, hi, nb)
            point_rows = (coef, rlb.reshape(nb, k_rows), rub.reshape(nb, k_rows))
        lba = np.concatenate([lba, rlb])
        uba = np.concatenate([uba, rub])
        x0 = np.zeros(2 * nb)
        # warm start: the targets projected to the bounds, by parameter
        cs = np.concatenate([[0.0], np.cumsum(t)])
        greville = (cs[p + 1 : n + p + 1] - cs[1 : n + 1]) / p  # mean of t[i+1 .. i+p]
        for d in range(2):
            guess = np.interp(greville, prob.u, prob.targets[:, d])
            x0[d * nb : d * nb + n] = np.clip(
                guess, lbx[d * nb : d * nb + n], ubx[d * nb : d * nb + n]
            )
        qp = _QPData(full=full, g=g, n=n, nb=nb, lbx=lbx, ubx=ubx, heading=heading,
                     lba=lba, uba=uba, k=k_rows, region_coef=coef)
        if warm is None:
            z, info = self._solve_qp(qp, remaining, x0=x0)
        else:
            z = x0.copy()
            z[:n], z[nb : nb + n] = warm[:, 0], warm[:, 1]
            info = {"solver": "warm", "cost": float("nan"), "success": True,
                    "status": "warm start", "iterations": 0, "solve_time_s": 0.0,
                    "solve_cpu_s": 0.0, "build_time_s": 0.0}
        stats = {
            "n_control_points": n,
            "padded_size": nb,
            "qp": info,
            "solver": info["solver"],
            "status": info["status"],
            "iterations": info["iterations"],
            "solve_time_s": info["solve_time_s"],
            "build_time_s": info["build_time_s"],
        }
        if not info["success"]:
            raise _AttemptFailed(f"QP solver {info['solver']}: {info['status']}", stats)
        z = np.clip(z, lbx, ubx)
        if self.kappa_max is not None:
            kmax_cells = self.kappa_max * prob.res
            remaining -= time.perf_counter() - t_enter  # what the QP stage left
            if self.curvature_solver == "scp":
                z, cinfo = self._solve_curvature_scp(
                    qp, t, z, kmax_cells, remaining, margin, const,
                    trust=_TRUST_WARM if warm is not None else _TRUST_COLD,
                )
            else:
                z, cinfo = self._solve_curvature_ipopt(qp, t, z, kmax_cells, remaining, margin)
            stats["nlp"] = cinfo
            stats["solver"] = info["solver"] + "+" + cinfo["solver"]
            stats["status"] = cinfo["status"]
            stats["iterations"] = info["iterations"] + cinfo["iterations"]
            stats["solve_time_s"] = info["solve_time_s"] + cinfo["solve_time_s"]
            stats["build_time_s"] = info["build_time_s"] + cinfo["build_time_s"]
            if not cinfo["success"]:
                raise _AttemptFailed(
                    f"curvature bound ({cinfo['solver']}): {cinfo['status']}", stats
                )
            z = np.clip(z, lbx, ubx)
        c = np.column_stack([z[:n], z[nb : nb + n]])
        _project_heading(c, prob, lo, hi, point_rows)
        zx, zy = c[:, 0], c[:, 1]
        cost = 0.0
        for d in range(p + 1):
            w = 0.5 if d == 0 else 1.0
            cost += w * float(band[d, : n - d] @ (zx[: n - d] * zx[d:] + zy[: n - d] * zy[d:]))
        cost += float(g[:n] @ zx + g[nb : nb + n] @ zy) + const
        stats["cost"] = cost
        return c, t, span_box, stats

    def _solve_qp(self, qp: _QPData, remaining: float, x0=None):
        """One solve of the corridor QP (no curvature rows) by ``self.qp_solver``."""
        p = self.degree
        nb = qp.nb
        solver_name = self.qp_solver
        lbx, ubx, lba, uba = qp.lbx, qp.ubx, qp.lba, qp.uba
        if x0 is None:
            x0 = np.zeros(2 * nb)
        ts = time.perf_counter()
        tc = time.process_time()
        if solver_name == "piqp" and qp.region_coef is not None:
            # polygon rows: piqp directly, without the rows a point does not use (a
            # casadi.conic keeps every padded row of its fixed sparsity)
            layout = _qp.constraint_layout(nb, p, 0, qp.k)
            trip = layout.values(qp.heading, None, qp.region_coef)
            z, *result = _qp.solve_working_set(
                qp.full, qp.g, layout, trip, lbx, ubx, lba, uba, np.zeros(0, bool), 0.0
            )
            return z, _piqp_info(result, ts, tc)
        tb = time.perf_counter()
        built = _is_cached(f"{solver_name}-0-{qp.k}", nb, p, self.verbose)
        if solver_name == "ipopt":
            solver = _qp.qp_ipopt(nb, p, self.verbose)
        else:
            solver = _qp.qp_solver(nb, p, solver_name, 0, self.verbose, qp.k)
        build = 0.0 if built else time.perf_counter() - tb
        ts = time.perf_counter()
        tc = time.process_time()
        if solver_name == "ipopt":
            par = np.concatenate([qp.full.ravel(), qp.g, qp.heading.ravel(order="F")])
            out = solver(x0=x0, p=par, lbx=lbx, ubx=ubx, lbg=lba, ubg=uba)
        else:
            import casadi as ca

            layout = _qp.constraint_layout(nb, p, 0, qp.k)
            hnz = _qp.h_nonzeros(qp.full, nb, p)
            trip = layout.values(qp.heading, None, qp.region_coef)
            if solver_name == "piqp":
                # piqp warns about (and drops) infinite rows, and large finite ones hurt
                # its conditioning: bound every row by its range over the variable bounds
                lo_r, hi_r = layout.implied_range(trip, lbx, ubx)
                lba = np.maximum(lba, lo_r - 1.0)
                uba = np.minimum(uba, hi_r + 1.0)
            hval = ca.DM(solver.sparsity_in("h"), hnz)
            aval = ca.DM(layout.sparsity, layout.nonzeros(trip))
            out = solver(h=hval, g=qp.g, a=aval, lbx=lbx, ubx=ubx, lba=lba, uba=uba, x0=x0)
        solve = time.perf_counter() - ts
        cpu = time.process_time() - tc
        st = solver.stats()
        z = np.asarray(out["x"], dtype=float).ravel()[: 2 * nb]
        success = bool(st.get("success", False)) and bool(np.all(np.isfinite(z)))
        info = {
            "solver": solver_name,
            "cost": float(out["cost"]) if "cost" in out else float("nan"),
            "success": success,
            "status": str(st.get("return_status", st.get("unified_return_status", ""))),
            "iterations": int(st.get("iter_count", st.get("iter", 0)) or 0),
            "solve_time_s": solve,
            "solve_cpu_s": cpu,
            "build_time_s": build,
        }
        return z, info

    def _solve_scp_qp(self, qp: _QPData, layout, vals, lba, uba, lbx, ubx, work):
        """One SCP QP over the working set ``work`` (bool per sample) of curvature samples,
        by :func:`_qp.solve_working_set`; ``vals`` holds every sample's row coefficients."""
        S = layout.n_samples
        trip = layout.values(qp.heading, vals, qp.region_coef)
        lbx_s = np.concatenate([lbx, np.zeros(S)])
        ubx_s = np.concatenate([ubx, np.full(S, _SLACK_MAX)])
        ts = time.perf_counter()
        tc = time.process_time()
        z, *result = _qp.solve_working_set(
            qp.full, qp.g, layout, trip, lbx_s, ubx_s, lba, uba, work, _SLACK_PENALTY
        )
        info = _piqp_info(result, ts, tc)
        info["n_samples"] = int(work.sum())
        return z, info

    def _curvature_samples(self, t: np.ndarray, n: int, nb: int):
        """Span index and first/second basis derivatives at ``CURV_SAMPLES`` points per
        span, padded to ``nb - p`` spans.

        A span is sampled at its start and at evenly spaced interior points; its end is the
        next span's start (``C'`` and ``C''`` are continuous at the simple interior knots, so
        a sample there would repeat a row). The last span spreads its samples from its start
        to its end, so the curve's end is sampled too.
        """
        p = self.degree
        ms = _qp.CURV_SAMPLES
        ns = n - p
        fr = np.tile(np.arange(ms) / ms, (ns, 1))
        fr[-1] = np.linspace(0.0, 1.0, ms)
        a = t[p : p + ns]
        b = t[p + 1 : p + ns + 1]
        span = np.repeat(np.arange(ns), ms)
        uu = (a[:, None] + (b - a)[:, None] * fr).ravel()
        S = (nb - p) * ms
        B1 = np.zeros((S, p + 1))
        B2 = np.zeros((S, p + 1))
        B1[: ns * ms] = _qp.basis_derivs(t, p, span, uu, 1)
        B2[: ns * ms] = _qp.basis_derivs(t, p, span, uu, 2)
        return span, B1, B2

    def _solve_curvature_scp(self, qp: _QPData, t, z0, kmax, remaining, margin, const=0.0,
                             trust=1.0):
        """Sequential convex programming for ``|kappa| <= kappa_margin * kmax`` and
        ``|C'| >= speed_floor`` at the samples (``margin`` replaces ``kappa_margin``).

        With the current iterate's unit tangent ``T_r``, normal ``N_r`` and speed ``v_r`` at
        sample ``r``, each QP imposes ``T_r . C'(u_r) >= floor`` (which implies
        ``|C'| >= floor``) and ``|N_r . C''(u_r)| <= kb (2 v_r (T_r . C') - v_r^2)``: since
        ``s^2 >= 2 v s - v^2`` this is a conservative form of ``|N . C''| <= kb |C'|^2``,
        the curvature bound when ``C'`` is along ``T``. Every row has an l1-penalised slack,
        so each QP is feasible; a trust region on the control points is grown or shrunk by
        the ratio of actual to predicted decrease of the merit ``objective + penalty *
        violation`` (it starts at ``trust`` cells; steps that do not decrease the merit are
        rejected, and the region shrinks to at most half the rejected step). Iterations stop
        once the sampled bound holds (within ``_SAMPLE_SLACK``) and either the merit stalls,
        or the objective comes within ``_SCP_RTOL`` (relative) of the model's optimum, or
        the model predicts a relative decrease below ``_SCP_RTOL`` of the merit or (its
        optimum inside the trust region) of the objective. They give up when the bound
        is still broken and the merit fell by less than ``_SCP_RTOL`` over
        ``_SCP_STALL_WINDOW`` iterations (a local minimum of the penalty: the caller
        refines the knots). The caller's certificate then checks the result on dense
        samples.
        """
        p = self.degree
        n, nb = qp.n, qp.nb
        ms = _qp.CURV_SAMPLES
        S = (nb - p) * ms
        ns_real = (n - p) * ms
        span, B1, B2 = self._curvature_samples(t, n, nb)
        B1, B2 = B1[:ns_real], B2[:ns_real]
        idx = span[:, None] + np.arange(p + 1)[None, :]
        kb = margin * kmax
        floor = self.speed_floor
        layout = _qp.constraint_layout(nb, p, ms, qp.k)
        n_fixed = layout.sample_row0
        lba = np.full(n_fixed + 3 * S, -np.inf)
        uba = np.full(n_fixed + 3 * S, np.inf)
        lba[:n_fixed] = qp.lba
        uba[:n_fixed] = qp.uba
        vals = np.zeros((S, 3, 2 * (p + 1)))
        rows = n_fixed + 3 * np.arange(ns_real)
        # the working set: samples near either bound at some iterate so far, with the
        # samples of the neighbouring spans (the others' rows are left out of the QPs; the
        # merit, and so the step acceptance, still counts every sample)
        work = np.zeros(S, dtype=bool)
        if n < _WS_MIN_POINTS:  # small: every sample (a cheap QP; fewer iterations)
            work[:ns_real] = True
        kernel = np.ones(2 * ms + 1, dtype=bool)

        def near_active(kap_, sp_):
            near = (kap_ > _WS_KAPPA * kb) | (sp_ < _WS_SPEED * floor)
            return np.convolve(near, kernel, mode="same") > 0
        full = qp.full

        def quad(zz):  # the objective itself (>= 0), constant included
            x, y = zz[:nb], zz[nb:]
            f = float(qp.g @ zz) + const
            for d in range(p + 1):
                w = 0.5 if d == 0 else 1.0
                f += w * float(full[d, : nb - d] @ (x[: nb - d] * x[d:] + y[: nb - d] * y[d:]))
            return f

        def measure(zz):
            X = zz[:nb][idx]
            Y = zz[nb:][idx]
            d1 = np.column_stack([(B1 * X).sum(1), (B1 * Y).sum(1)])
            d2 = np.column_stack([(B2 * X).sum(1), (B2 * Y).sum(1)])
            derivs[0], derivs[1] = d1, d2
            sp = np.hypot(d1[:, 0], d1[:, 1])
            cross = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
            spc = np.maximum(sp, 1e-12)
            kap = np.abs(cross) / spc**3
            viol = np.maximum(0.0, np.abs(cross) / spc - kb * sp**2) + np.maximum(0.0, floor - sp)
            ok = bool(kap.max() <= kb * _SAMPLE_SLACK and sp.min() >= floor / _SAMPLE_SLACK)
            merit = quad(zz) + _SLACK_PENALTY * float(viol.sum())
            return d1, sp, kap, ok, merit

        derivs: list[np.ndarray] = [np.empty(0), np.empty(0)]

        delta = float(trust)  # trust region (cells)
        z = z0.copy()
        d1, sp, kap, ok, merit = measure(z)
        d2 = derivs[1]
        q_cur = quad(z)
        history = [merit]  # the merit after each iteration
        t0 = time.perf_counter()
        build = solve = 0.0
        iters = 0
        status = "feasible at the QP solution" if ok else "not converged"
        for it in range(int(self.scp_iterations)):
            if time.perf_counter() - t0 > remaining:
                status = "time budget exceeded"
                break
            # c = X / v - kb v^2 (X = d1 x d2, v = |d1|) and its mirror -X / v - kb v^2,
            # linearised: X / v to first order, -kb v^2 by its tangent plane (an upper
            # bound, so that part is conservative)
            v = np.maximum(sp, 1e-9)
            T = d1 / v[:, None]
            N = np.column_stack([-T[:, 1], T[:, 0]])
            X = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
            gx1 = d2[:, 1] / v - X * d1[:, 0] / v**3  # d(X/v)/d(d1)
            gy1 = -d2[:, 0] / v - X * d1[:, 1] / v**3
            kx = -2 * kb * d1[:, 0]  # d(-kb v^2)/d(d1)
            ky = -2 * kb * d1[:, 1]
            for row, sgn in ((0, 1.0), (1, -1.0)):
                ax_ = sgn * gx1 + kx
                ay_ = sgn * gy1 + ky
                bx_ = sgn * N[:, 0]
                by_ = sgn * N[:, 1]
                vals[:ns_real, row, : p + 1] = B1 * ax_[:, None] + B2 * bx_[:, None]
                vals[:ns_real, row, p + 1 :] = B1 * ay_[:, None] + B2 * by_[:, None]
                # value at the iterate: sgn X / v - kb v^2; row(z_k) = the linear part
                lin_k = ax_ * d1[:, 0] + ay_ * d1[:, 1] + bx_ * d2[:, 0] + by_ * d2[:, 1]
                uba[rows + row] = lin_k - (sgn * X / v - kb * sp**2)
            vals[:ns_real, 2, : p + 1] = B1 * T[:, 0:1]
            vals[:ns_real, 2, p + 1 :] = B1 * T[:, 1:2]
            lba[rows + 2] = floor
            lbx = np.maximum(qp.lbx, z - delta)
            ubx = np.minimum(qp.ubx, z + delta)
            work[:ns_real] |= near_active(kap, sp)
            znew, info = self._solve_scp_qp(qp, layout, vals, lba, uba, lbx, ubx, work)
            iters += 1
            build += info["build_time_s"]
            solve += info["solve_time_s"]
            if not info["success"]:
                status = f"SCP iteration {it + 1}: {info['solver']} {info['status']}"
                break
            znew = np.clip(znew, lbx, ubx)
            step = float(np.max(np.abs(znew - z)))
            predicted = merit - (info["cost"] + const)
            d2_old = d2
            d1n, spn, kapn, okn, meritn = measure(znew)
            d2 = derivs[1]
            work[:ns_real] |= near_active(kapn, spn)  # samples the step moved near the bounds
            actual = merit - meritn
            tol = 1e-9 * (1.0 + abs(merit))
            logger.debug(
                "SCP %d: %.1f ms (cpu %.1f ms, %d it, %d samples), step %.3g (trust %.3g), "
                "max kappa/bound %.4g, min speed %.3g, merit %.6g -> %.6g (predicted %.6g)",
                it + 1, 1e3 * info["solve_time_s"], 1e3 * info["solve_cpu_s"],
                info["iterations"], info["n_samples"], step, delta, kapn.max() / kb,
                spn.min(), merit, meritn, merit - predicted,
            )
            if predicted <= tol:  # no decrease predicted: a stationary point of the model
                status = "converged" if ok else "stalled"
                break
            if ok and predicted <= _SCP_RTOL * (1.0 + abs(merit)):
                # the bound holds and even the model's best step would lower the merit by
                # less than the tolerance: stop at the current iterate
                status = "converged"
                break
            interior = step < 0.99 * delta  # the model's optimum lies inside the region
            if ok and interior and q_cur - quad(znew) <= _SCP_RTOL * (1.0 + q_cur):
                # the bound holds (within the sample slack) and the model's optimum, inside
                # the trust region, lowers the objective itself by less than the tolerance:
                # what is left to gain is the penalty on violations inside that slack
                status = "converged"
                break
            ratio = actual / predicted
            if ratio >= 0.1:  # accept
                model = merit - predicted  # the model's optimum around the old iterate
                z, d1, sp, kap, ok, merit = znew, d1n, spn, kapn, okn, meritn
                q_cur = quad(z)
                if ratio > 0.5 and step >= 0.99 * delta:
                    delta = min(2 * delta, 8.0)
                elif ratio < 0.25:
                    delta *= 0.5
                rtol = _SCP_RTOL * (1.0 + abs(merit))
                # (the objective, not the merit, against the model's optimum: the penalty
                # left is on violations inside the sample slack)
                if ok and (actual <= rtol or (interior and step < 0.05) or q_cur - model <= rtol):
                    status = "converged"
                    break
            else:  # reject; the next region is smaller than the rejected step
                delta = min(0.25 * delta, 0.5 * step)
                d2 = d2_old
            if delta < 1e-3:
                status = "converged" if ok else "trust region collapsed"
                break
            history.append(merit)
            if (
                not ok
                and len(history) > _SCP_STALL_WINDOW
                and history[-1 - _SCP_STALL_WINDOW] - merit <= _SCP_RTOL * (1.0 + abs(merit))
            ):
                # the bound still broken and the merit flat over the window: a local
                # minimum of the penalty (the caller refines the knots)
                status = "stalled"
                break
        success = ok
        if success and status not in ("converged", "feasible at the QP solution"):
            status = "feasible (" + status + ")"
        if not success and status in ("not converged", "converged", "stalled"):
            status = (
                f"not converged after {iters} iterations (sampled max kappa "
                f"{kap.max() / kmax:.3g} x the bound, min speed {sp.min():.3g})"
            )
        info = {
            "solver": "scp",
            "success": success,
            "status": status,
            "iterations": iters,
            "solve_time_s": solve,
            "build_time_s": build,
        }
        return z, info

    def _solve_curvature_ipopt(self, qp: _QPData, t, z0, kmax, remaining, margin):
        p = self.degree
        n, nb = qp.n, qp.nb
        ms = _qp.CURV_SAMPLES
        _, B1, B2 = self._curvature_samples(t, n, nb)
        par = np.concatenate(
            [
                qp.full.ravel(),
                qp.g,
                qp.heading.ravel(order="F"),
                B1.ravel(order="F"),
                B2.ravel(order="F"),
                [(margin * kmax) ** 2],
            ]
        )
        S = (nb - p) * ms
        lbg = np.concatenate([qp.lba, np.full(S, -np.inf), np.full(S, -np.inf)])
        ubg = np.concatenate([qp.uba, np.zeros(S), np.full(S, np.inf)])
        off = len(qp.lba) + S
        lbg[off : off + (n - p) * ms] = self.speed_floor**2
        tb = time.perf_counter()
        built = _is_cached("curv", nb, p, self.verbose)
        solver = _qp.curvature_nlp(nb, p, self.verbose)
        build = 0.0 if built else time.perf_counter() - tb
        left = max(0.05, remaining - build - 0.02)
        ts = time.perf_counter()
        out = solver(x0=z0, p=par, lbx=qp.lbx, ubx=qp.ubx, lbg=lbg, ubg=ubg)
        solve = time.perf_counter() - ts
        st = solver.stats()
        z = np.asarray(out["x"], dtype=float).ravel()
        success = bool(st.get("success", False)) and bool(np.all(np.isfinite(z)))
        if solve > left:
            success = False
        info = {
            "solver": "ipopt",
            "success": success,
            "status": str(st.get("return_status", ""))
            + ("" if solve <= left else " (over budget)"),
            "iterations": int(st.get("iter_count", 0) or 0),
            "solve_time_s": solve,
            "build_time_s": build,
        }
        return z, info


# ----------------------------------------------------------------- internals
class _AttemptFailed(Exception):
    def __init__(self, message: str, stats: dict[str, Any]) -> None:
        super().__init__(message)
        self.stats = stats


@dataclass(slots=True)
class _Problem:
    """One fit in cell units: targets at parameters ``u``, per-region bounds (``lo``,
    ``hi``: the box, or a polygon's bounding box; ``dlo``, ``dhi``: the bounds of ``x + y``
    and ``x - y``) and, for polygon corridors, each region's half-planes ``rows``
    (``(A, b)`` with ``A @ c <= b``, cells)."""

    targets: np.ndarray
    u: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    dlo: np.ndarray
    dhi: np.ndarray
    trans: np.ndarray
    overlap: np.ndarray
    start: np.ndarray
    goal: np.ndarray
    start_dir: np.ndarray | None
    goal_dir: np.ndarray | None
    res: float = 1.0
    rows: list[tuple[np.ndarray, np.ndarray]] | None = None
    taut: bool = False


@dataclass(slots=True)
class _QPData:
    """The convex problem of one attempt (cell units, padded to ``nb``)."""

    full: np.ndarray  # Hessian upper band, shape (p + 1, nb)
    g: np.ndarray  # linear term, shape (2 nb,)
    n: int
    nb: int
    lbx: np.ndarray
    ubx: np.ndarray
    heading: np.ndarray  # heading rows, shape (4, 2 nb)
    lba: np.ndarray  # bounds of the heading and region rows, shape (4 + k nb,)
    uba: np.ndarray
    k: int = 2  # region rows per control point
    region_coef: np.ndarray | None = None  # their (a_x, a_y), shape (nb, k, 2); None: x +- y


def _sd(xy: np.ndarray) -> np.ndarray:
    """``(x + y, x - y)`` of a point."""
    return np.array([xy[0] + xy[1], xy[0] - xy[1]])


#: the SCP accepts sampled curvature up to this factor over ``kappa_margin * kappa_max``
#: (and speeds down to the floor over it): the margin leaves room, and the certificate
#: checks the true bound on dense samples
_SAMPLE_SLACK = 1.01

#: a warm-started retry after the certificate found the curvature bound broken between the
#: samples tightens the sampled bound by the excess found times this factor
_MARGIN_RETRY = 0.98

#: ... only when the dense samples exceed the bound by at most this factor (else refine)
_RETRY_MAX_EXCESS = 1.1

#: initial SCP trust region (cells): from the QP solution, and on a warm-started retry
#: (already close to a solution: a large first step there can leave for a worse local one)
_TRUST_COLD = 1.0
_TRUST_WARM = 0.25

#: largest SCP slack (keeps every row's range finite for the interior-point solver)
_SLACK_MAX = 1e3

#: heading continuity in the certificate: the tangent may turn at most this much between
#: consecutive dense samples (rad; an eighth of a cell apart by default, so only a near-cusp,
#: with a radius of curvature of a fraction of a cell, comes close), and the speed
#: ``|C'(u)|`` must stay above this fraction of its mean
_MAX_HEADING_STEP = math.pi / 8
_MIN_SPEED_RATIO = 1e-2

#: the SCP stops once the bound holds and an accepted step lowers the merit by less than
#: this fraction (or moves no control point by 0.05 cell inside the trust region, or
#: brings the objective within this fraction of the model's optimum), or the model
#: predicts a smaller decrease of the merit, or (its optimum inside the trust region) of
#: the objective
_SCP_RTOL = 1e-2

#: the SCP gives up (the caller refines) when the bound is still broken and the merit fell
#: by less than ``_SCP_RTOL`` (relative) over this many iterations
_SCP_STALL_WINDOW = 3

#: the SCP's QPs carry the rows of the samples whose curvature exceeds this fraction of the
#: sampled bound, or whose speed is below this multiple of the floor, at any iterate so far
#: (and those of the neighbouring spans)
_WS_KAPPA = 0.5
_WS_SPEED = 2.0
#: ... when the curve has at least this many control points (below, every sample)
_WS_MIN_POINTS = 64

#: l1 penalty on the SCP slacks (cell units); large against the objective's multipliers
_SLACK_PENALTY = 1e4

#: the 45-degree rows are imposed this far (cells) inside their bounds, so that solver
#: tolerances never put a control point outside its region
_DIAG_MARGIN = 1e-6


def _diag_row_bounds(dlo: np.ndarray, dhi: np.ndarray, nb: int):
    """Bounds of the rows ``x_i + y_i``, ``x_i - y_i`` (interleaved), padded to ``nb``."""
    n = len(dlo)
    lb = np.full((nb, 2), -np.inf)
    ub = np.full((nb, 2), np.inf)
    lo = dlo + _DIAG_MARGIN
    hi = dhi - _DIAG_MARGIN
    thin = lo > hi  # only for finite bounds: -inf + m > inf - m never holds
    mid = 0.5 * (dlo[thin] + dhi[thin])
    lo[thin] = mid
    hi[thin] = mid
    lb[:n], ub[:n] = lo, hi
    return lb.ravel(), ub.ravel()


#: polygon rows are imposed this far (cells) inside their half-planes, so that solver
#: tolerances never put a control point outside its region
_POLY_MARGIN = 1e-6
#: region rows per control point are padded to one of these counts (cached solvers)
_K_SIZES = (4, 8, 12, 16, 24, 32, 48, 64)


def _polygon_targets(corridor: PolygonCorridor) -> tuple[np.ndarray, np.ndarray]:
    """The corridor's path sampled about once per cell: points (m) and their arc lengths."""
    res = corridor.resolution
    s_v = np.asarray(corridor.path_s, dtype=float)
    pts = np.asarray(corridor.path, dtype=float)
    s = np.unique(np.concatenate([np.arange(0.0, s_v[-1], res), s_v]))
    xy = np.column_stack([np.interp(s, s_v, pts[:, 0]), np.interp(s, s_v, pts[:, 1])])
    return xy, s


def _region_rows(corridor: PolygonCorridor, origin: np.ndarray, res: float):
    """Each region's rows ``lo <= A c <= hi`` in cells (``A`` (q, 2), ``lo``, ``hi``
    (q,)), ``_POLY_MARGIN`` inside, and the regions' bounding boxes (cells, (m, 2) each).

    A degenerate region's line (its first two, opposite rows) becomes one two-sided row."""
    out = []
    lo_b = np.empty((len(corridor.regions), 2))
    hi_b = np.empty((len(corridor.regions), 2))
    for k, reg in enumerate(corridor.regions):
        A = np.asarray(reg.A, dtype=float)
        b = (np.asarray(reg.b, dtype=float) - A @ origin) / res
        v = (np.asarray(reg.vertices, dtype=float) - origin) / res
        lo_b[k], hi_b[k] = v.min(axis=0), v.max(axis=0)
        if reg.degenerate:
            mid = 0.5 * (b[0] - b[1])
            rows_a = np.vstack([A[:1], A[2:]])
            rlo = np.concatenate([[mid], np.full(len(A) - 2, -np.inf)])
            rhi = np.concatenate([[mid], b[2:] - _POLY_MARGIN])
        else:
            rows_a = A
            rlo = np.full(len(A), -np.inf)
            rhi = b - _POLY_MARGIN
        out.append((rows_a, rlo, rhi))
    return out, lo_b, hi_b


def _point_rows(rows, span_box, n: int, p: int, lo: np.ndarray, hi: np.ndarray, nb: int):
    """The region rows of every control point, padded to ``k`` per point.

    A point gets the rows of the regions of the spans it touches, less those that its
    variable bounds ``lo``, ``hi`` (cells, shape (n, 2)) already imply (the row's largest
    value over that box is within its bound); the fixed end points get none (they were
    checked against their regions). Span regions never decrease along the curve and a point
    touches at most two of them (the knots give every region at least ``p`` spans), so the
    regions of point ``i`` are those of its first and last span.

    Returns ``(k, coef (nb, k, 2), lb (nb k,), ub (nb k,))`` in the layout's order; unused
    rows have zero coefficients and infinite bounds.
    """
    m = len(rows)
    q = max(len(r[1]) for r in rows)
    A = np.zeros((m + 1, q, 2))  # region m: no rows (the fixed end points)
    rlo = np.full((m + 1, q), -np.inf)
    rhi = np.full((m + 1, q), np.inf)
    for r, (a, lo_r, hi_r) in enumerate(rows):
        A[r, : len(lo_r)] = a
        rlo[r, : len(lo_r)] = lo_r
        rhi[r, : len(lo_r)] = hi_r
    ns = len(span_box)
    i = np.arange(n)
    r0 = np.asarray(span_box)[np.clip(i - p, 0, ns - 1)]
    r1 = np.asarray(span_box)[np.clip(i, 0, ns - 1)]
    r1 = np.where(r1 == r0, m, r1)
    r0[[0, -1]] = m
    r1[[0, -1]] = m
    ca = np.concatenate([A[r0], A[r1]], axis=1)  # (n, 2q, 2)
    clo = np.concatenate([rlo[r0], rlo[r1]], axis=1)
    chi = np.concatenate([rhi[r0], rhi[r1]], axis=1)
    top = np.maximum(ca[..., 0] * lo[:, :1], ca[..., 0] * hi[:, :1]) + np.maximum(
        ca[..., 1] * lo[:, 1:], ca[..., 1] * hi[:, 1:]
    )
    keep = ((top > chi) | np.isfinite(clo)) & (np.isfinite(chi) | np.isfinite(clo))
    most = int(keep.sum(axis=1).max(initial=0))
    k = next((s for s in _K_SIZES if s >= most), int(8 * math.ceil(most / 8)))
    w = min(k, 2 * q)
    order = np.argsort(~keep, axis=1, kind="stable")[:, :w]  # kept rows first
    kept = np.take_along_axis(keep, order, axis=1)
    coef = np.zeros((nb, k, 2))
    lb = np.full((nb, k), -np.inf)
    ub = np.full((nb, k), np.inf)
    coef[:n, :w] = np.where(kept[..., None], np.take_along_axis(ca, order[..., None], axis=1), 0.0)
    lb[:n, :w] = np.where(kept, np.take_along_axis(clo, order, axis=1), -np.inf)
    ub[:n, :w] = np.where(kept, np.take_along_axis(chi, order, axis=1), np.inf)
    return k, coef, lb.ravel(), ub.ravel()


def _piqp_info(result, t_wall: float, t_cpu: float) -> dict[str, Any]:
    """Statistics of a direct piqp solve from :func:`_qp.solve_working_set`'s
    ``(cost, success, status, iterations)`` and the wall and CPU clocks at its start."""
    cost, success, status, iters = result
    return {
        "solver": "piqp",
        "cost": cost,
        "success": success,
        "status": status,
        "iterations": iters,
        "solve_time_s": time.perf_counter() - t_wall,
        "solve_cpu_s": time.process_time() - t_cpu,
        "build_time_s": 0.0,
    }


_BUILT: set[tuple] = set()


def _warm_imports() -> None:
    """Import the lazily loaded heavy modules (casadi, scipy.interpolate) once."""
    import casadi  # noqa: F401
    import piqp  # noqa: F401
    import scipy.interpolate  # noqa: F401
    import scipy.sparse  # noqa: F401


def _is_cached(kind: str, nb: int, p: int, verbose: bool) -> bool:
    key = (kind, nb, p, verbose)
    if key in _BUILT:
        return True
    _BUILT.add(key)
    return False


def _check_float(name: str, value: Any, *, lo: float, strict: bool = False) -> None:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InvalidInputError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(v) or v < lo or (strict and v == lo):
        rule = f"> {lo}" if strict else f">= {lo}"
        raise InvalidInputError(f"{name} must be finite and {rule}, got {value!r}")


def _point(name: str, value: Any, default: np.ndarray) -> np.ndarray:
    if value is None:
        return np.array(default, dtype=float)
    p = np.asarray(value, dtype=float)
    if p.shape != (2,) or not np.all(np.isfinite(p)):
        raise InvalidInputError(f"{name} must be a finite (x, y) in metres, got {value!r}")
    return p.copy()


def _heading(name: str, value: Any) -> float | None:
    if value is None:
        return None
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InvalidInputError(f"{name} must be an angle in radians, got {value!r}") from None
    if not math.isfinite(v):
        raise InvalidInputError(f"{name} must be finite, got {value!r}")
    return v


def _targets(src: Any, corridor: Corridor) -> np.ndarray:
    if src is None:
        return np.array(corridor.path_points)
    cells = getattr(src, "cells", None)
    if cells is None and np.issubdtype(np.asarray(src).dtype, np.integer):
        cells = src  # an integer array is a list of cells (ix, iy)
    if cells is not None:
        c = np.asarray(cells, dtype=float)
        pts = np.asarray(corridor.origin) + (c + 0.5) * corridor.resolution
    else:
        pts = np.asarray(src, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 2 or not np.all(np.isfinite(pts)):
        raise InvalidInputError(
            f"grid_path_or_points must be finite with shape (n, 2), got {pts.shape}"
        )
    if len(pts) != len(corridor.path_points):
        raise InvalidInputError(
            f"grid_path_or_points has {len(pts)} points but the corridor was built on a path "
            f"of {len(corridor.path_points)} cells; they must match"
        )
    return pts


def graded_knots(
    length: float, trans: np.ndarray, overlap: np.ndarray, p: int, h: float
) -> tuple[np.ndarray, np.ndarray]:
    """Clamped knots on ``[0, length]`` (cells) graded towards the box transitions.

    Every transition is a knot; inside box ``k`` the span length at ``x`` is
    ``min(h, d + 0.5 * distance to the nearest transition)`` with
    ``d = clip(overlap / (p - 1), 0.5, h)`` of that transition, and each box gets at least
    ``p`` spans. Returns the knots (shape ``(n + p + 1,)``) and the box of every span.
    """
    edges = np.concatenate([[0.0], trans, [length]])
    d_tr = np.clip(overlap / max(p - 1, 1), 0.5, h)
    bps: list[np.ndarray] = []
    boxes: list[np.ndarray] = []
    for k in range(len(edges) - 1):
        a, b = edges[k], edges[k + 1]
        dl = d_tr[k - 1] if k > 0 else None
        dr = d_tr[k] if k < len(trans) else None

        def step(x: float, a=a, b=b, dl=dl, dr=dr) -> float:
            s = h
            if dl is not None:
                s = min(s, dl + 0.5 * (x - a))
            if dr is not None:
                s = min(s, dr + 0.5 * (b - x))
            return max(s, 1e-3)

        pos = [a]
        x = a
        while True:
            s = step(x)
            rest = b - x
            if rest <= s * 1.25:
                break
            if rest <= 2 * s:
                x = x + 0.5 * rest
                pos.append(x)
                break
            x += s
            pos.append(x)
        pos.append(b)
        arr = np.array(pos)
        if len(arr) - 1 < p:
            arr = np.linspace(a, b, p + 1)
        bps.append(arr[:-1])
        boxes.append(np.full(len(arr) - 1, k))
    bp = np.concatenate(bps + [[length]])
    t = np.concatenate([np.full(p, 0.0), bp, np.full(p, length)])
    return t, np.concatenate(boxes).astype(np.int64)


def _objective(pts, u, t, p, n, weight, order, *, fidelity=1.0, length=0.0):
    """Upper band of ``H`` (one coordinate block), ``g`` (2n: x then y, padded layout
    resolved later) and the constant, for ``1/2 z'Hz + g'z + const`` =
    ``fidelity * sum |C(u_r) - p_r|^2 + weight * integral |C^(order)|^2
    + length * integral |C'|^2``."""
    span = _qp.find_spans(t, p, n, u)
    vals = _qp.basis_derivs(t, p, span, u, 0)
    band = 2.0 * fidelity * _qp.band_gram(span, vals, np.ones(len(u)), n)
    if weight > 0:
        band += 2.0 * weight * _qp.smoothness_band(t, p, n, order)
    if length > 0:
        band += 2.0 * length * _qp.smoothness_band(t, p, n, 1)
    rhs = fidelity * _qp.band_rhs(span, vals, pts, n)
    g = np.zeros(2 * n)
    nb = _qp.bucket_size(n)
    g = np.zeros(2 * nb)
    g[:n] = -2.0 * rhs[:, 0]
    g[nb : nb + n] = -2.0 * rhs[:, 1]
    const = fidelity * float(np.sum(pts * pts))
    return band, g, const


def _heading_rows(prob: _Problem, n: int, nb: int):
    amat = np.zeros((4, 2 * nb))
    lba = np.full(4, -np.inf)
    uba = np.full(4, np.inf)
    eps = 1e-3  # cells: keeps c_1 != c_0 so the end heading is defined
    if prob.start_dir is not None:
        dx, dy = prob.start_dir
        # cross(d, c1 - c0) = 0 ; dot(d, c1 - c0) >= eps
        amat[0, 1], amat[0, nb + 1] = -dy, dx
        lba[0] = uba[0] = -dy * prob.start[0] + dx * prob.start[1]
        amat[1, 1], amat[1, nb + 1] = dx, dy
        lba[1] = dx * prob.start[0] + dy * prob.start[1] + eps
    if prob.goal_dir is not None:
        dx, dy = prob.goal_dir
        j = n - 2
        amat[2, j], amat[2, nb + j] = -dy, dx
        lba[2] = uba[2] = -dy * prob.goal[0] + dx * prob.goal[1]
        # dot(d, goal - c_{n-2}) >= eps
        amat[3, j], amat[3, nb + j] = dx, dy
        uba[3] = dx * prob.goal[0] + dy * prob.goal[1] - eps
    return amat, lba, uba


def _project_heading(
    c: np.ndarray, prob: _Problem, lo: np.ndarray, hi: np.ndarray, point_rows=None
) -> None:
    """Put ``c_1`` (``c_{n-2}``) exactly on the start (reversed goal) heading ray, inside
    its bounds (and its region rows ``lo <= A c <= hi`` in a polygon corridor), at least
    ``1e-3`` cells from the end point when the bounds allow it."""
    ends = []
    if prob.start_dir is not None:
        ends.append((1, prob.start, prob.start_dir))
    if prob.goal_dir is not None:
        ends.append((len(c) - 2, prob.goal, -prob.goal_dir))
    for idx, end, d in ends:
        a_lo, a_hi = 0.0, np.inf
        for ax in range(2):
            if abs(d[ax]) > 1e-15:
                t1 = (lo[idx, ax] - end[ax]) / d[ax]
                t2 = (hi[idx, ax] - end[ax]) / d[ax]
                a_lo = max(a_lo, min(t1, t2))
                a_hi = min(a_hi, max(t1, t2))
        if point_rows is not None:  # A (end + a d) in [rlo, rhi]
            A, rlo, rhi = (x[idx] for x in point_rows)
            ad = A @ d
            ae = A @ end
            for q in range(len(ad)):
                if abs(ad[q]) > 1e-15:
                    t1 = (rlo[q] - ae[q]) / ad[q]
                    t2 = (rhi[q] - ae[q]) / ad[q]
                    a_lo = max(a_lo, min(t1, t2))
                    a_hi = min(a_hi, max(t1, t2))
        a = float(np.dot(c[idx] - end, d))
        a = min(max(a, a_lo, min(1e-3, a_hi)), a_hi)
        c[idx] = np.clip(end + a * d, lo[idx], hi[idx])


def _summary(attempts: list[dict[str, Any]], total: float, *, success: bool) -> dict[str, Any]:
    last = attempts[-1] if attempts else {}
    return {
        "success": success,
        "status": last.get("status", "not run"),
        "solver": last.get("solver", ""),
        "iterations": last.get("iterations", 0),
        "solve_time_s": float(sum(a.get("solve_time_s", 0.0) for a in attempts)),
        "build_time_s": float(sum(a.get("build_time_s", 0.0) for a in attempts)),
        "total_time_s": total,
        "cost": last.get("cost", float("nan")),
        "attempts": len(attempts),
        "n_control_points": last.get("n_control_points", 0),
        "padded_size": last.get("padded_size", 0),
        "attempt_log": [dict(a) for a in attempts],
    }


# -------------------------------------------------------------------- certify
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
) -> Certificate:
    """Check every guarantee of a smoothed curve (see :class:`Certificate`)."""
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
    res = corridor.resolution
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
        min_clear = float(points_clearance(xy, raw_grid, window).min())
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
