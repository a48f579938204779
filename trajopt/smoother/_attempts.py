"""The smoother's attempt loop: solve on graded knots, certify, refine or retry.

Each attempt solves the QP on knots of longest span ``h`` (then, with a curvature bound,
the SCP or IPOPT), puts the end control points exactly on their heading rays, and checks
the curve with :func:`~trajopt.smoother._certificate.certify`. A failed certificate halves
``h`` (at most ``max_attempts`` knot vectors); when only the curvature bound broke, between
the samples and by at most ``retry_max_excess``, the same knots are solved once more, warm
started, with the sampled bound tightened by the excess found. With a robot footprint the
curve must also pass :func:`~trajopt.robot._footprint.certify_footprint`; when only that fails, an
end heading may be pinned or the same knots solved again by the footprint SCP
(:mod:`~trajopt.smoother._footprint_rounds`) before refining.
"""

from __future__ import annotations

import dataclasses
import functools
import logging
import math
import time
from typing import TYPE_CHECKING, Any

import numpy as np

from trajopt.corridor import Corridor, PolygonCorridor
from trajopt.errors import InvalidInputError, SmoothingError
from trajopt.geometry import BSplineCurve
from trajopt.robot import Footprint
from trajopt.smoother._basis import band_quadratic, bucket_size
from trajopt.smoother._certificate import certify
from trajopt.smoother._cost import (
    CostField,
    CostTerm,
    cost_field,
    cost_rounds,
    cost_scale,
    linearised,
)
from trajopt.smoother._footprint_rounds import FootprintRounds, footprint_scp
from trajopt.smoother._nlp import solve_curvature_ipopt
from trajopt.smoother._nlp_solve import cost_ipopt, ipopt_cost, refine_ipopt
from trajopt.smoother._path import SmoothPath
from trajopt.smoother._problem import (
    N_HEADING_ROWS,
    EmptyBoundsError,
    Problem,
    QPData,
    assemble,
    build_problem,
    graded_knots,
    objective,
    project_heading,
)
from trajopt.smoother._qp import RoundSolver, solve_qp, warm_imports
from trajopt.smoother._scp import CurvatureSCP
from trajopt.smoother._status import AttemptRecord, SolveInfo, SolveStatus, summarize
from trajopt.validation import heading, number

if TYPE_CHECKING:
    from trajopt.smoother._options import Smoother

logger = logging.getLogger(__name__)

#: a warm-started retry after the certificate found the curvature bound broken between the
#: samples tightens the sampled bound by the excess found times this factor ...
MARGIN_RETRY = 0.98
#: ... only when the dense samples exceed the bound by at most this factor (else refine)
RETRY_MAX_EXCESS = 1.1
#: initial SCP trust region (cells): from the QP solution (half the SCP's largest region:
#: the QP's curve, free of the bound, is far from the bound's curve where it cuts a corner;
#: on the car queries of ``benchmarks/bench_car.py`` 4 cells took 4-17 % fewer SCP
#: iterations than 1 cell, and 8 more on some), and on a warm-started retry
#: (already close to a solution: a large first step there can leave for a worse local one)
TRUST_COLD = 4.0
TRUST_WARM = 0.25


class AttemptFailed(Exception):
    """One attempt produced no curve (the message says why)."""


def fit(
    options: Smoother,
    grid_path_or_points: Any,
    corridor: Corridor | PolygonCorridor,
    *,
    raw_grid: Any = None,
    radius: float | None = None,
    start: Any = None,
    goal: Any = None,
    start_heading: float | None = None,
    goal_heading: float | None = None,
    start_curvature: float | None = None,
    footprint: Footprint | None = None,
    cost: Any = None,
    cost_weight: float = 2.0,
) -> SmoothPath:
    """:meth:`Smoother.fit` (see there)."""
    polygons = isinstance(corridor, PolygonCorridor)
    # one-off module imports do not count against the time budget; polygon QPs go to piqp
    # directly, the others (and every IPOPT problem) through casadi
    ipopt = "ipopt" in (options.qp_solver, options.curvature_solver)
    warm_imports(casadi=not polygons or options.qp_solver != "piqp" or ipopt)
    t_call = time.perf_counter()
    if not (polygons or isinstance(corridor, Corridor)):
        raise InvalidInputError(
            f"corridor must be a Corridor or a PolygonCorridor, got {type(corridor).__name__}"
        )
    # the length unit of the fit: the corridor's, but the footprint rounds count in cells
    # (their corner rows are linearised within a trust region of TRUST_CELLS, tuned on
    # cells: at coarser units their steps overshoot the rectangle's turns)
    res = corridor.resolution if footprint is not None else corridor.unit_m
    rad = corridor.radius if radius is None else float(radius)
    if radius is not None and not (math.isfinite(rad) and rad >= 0):
        raise InvalidInputError(f"radius must be finite and >= 0 m, got {radius!r}")
    if raw_grid is not None and rad is None:
        raise InvalidInputError("radius is required (or corridor.radius) with raw_grid")
    if footprint is not None and not isinstance(footprint, Footprint):
        raise InvalidInputError(f"footprint must be a Footprint, got {type(footprint).__name__}")
    if footprint is not None and raw_grid is None:
        raise InvalidInputError("footprint needs raw_grid (its certificate checks the raw map)")
    hs = heading("start_heading", start_heading)
    hg = heading("goal_heading", goal_heading)
    ks = None
    if start_curvature is not None:
        ks = number("start_curvature", start_curvature, unit="1/m")
        if hs is None:
            raise InvalidInputError("start_curvature needs start_heading (the tangent it bends)")
    field = cost_field(cost, cost_weight, raw_grid)
    cost_at = None if field is None else (field, np.asarray(corridor.origin, dtype=float))
    if corridor.length_m <= 0:
        raise InvalidInputError("the corridor's path has zero length (start == goal)")
    prob, p0, p1 = build_problem(
        options,
        grid_path_or_points,
        corridor,
        start=start,
        goal=goal,
        hs=hs,
        hg=hg,
        start_kappa=ks,
        unit_m=res,
    )
    attempts: list[AttemptRecord] = []
    h = float(options.span_cells)
    margin = options.kappa_margin
    warm = None  # control points (cells) of a retry on the same knots
    fp = None if footprint is None else FootprintRounds(footprint, raw_grid, res, hs, hg)
    spans_tried = 0
    cold: list[tuple[np.ndarray, np.ndarray]] = []  # knots of the cold attempts on ``prob``
    while spans_tried < int(options.max_attempts):
        remaining = options.time_budget_s - (time.perf_counter() - t_call)
        if remaining <= 0:
            break
        if warm is None:
            knots = graded_knots(prob.u[-1], prob.trans, prob.overlap, options.degree, h)
            if any(_same_knots(knots, k) for k in cold):
                # a refinement that leaves the knots as they were (a short stretch: each box
                # keeps its ``degree`` spans at any span length) would repeat a failed
                # attempt exactly (the solvers are deterministic): the next span length
                h = max(0.5, h / 2)
                spans_tried += 1
                continue
            cold.append(knots)
        rec = AttemptRecord(
            attempt=len(attempts) + 1, span_cells=h, kappa_margin=None if warm is None else margin
        )
        attempts.append(rec)
        refined = None if options.refine is None else {}
        try:
            c_cells, t_cells, span_box = solve_attempt(
                options, prob, h, remaining, margin, warm, rec, cost_at, refined
            )
        except AttemptFailed as exc:
            rec.failure = str(exc)
            h, margin, warm = max(0.5, h / 2), options.kappa_margin, None
            spans_tried += 1
            continue
        check = functools.partial(_check, options, corridor, res, raw_grid, rad, fp, (p0, p1))
        curve, cert, fcert = check(c_cells, t_cells, span_box)
        rec.certificate_ok = cert.ok
        if fcert is not None and not fcert.ok:  # the disc is clear, the footprint is not
            rec.failure = (
                f"footprint certificate: span {fcert.worst_span}, margin {fcert.min_margin_m:.3g} m"
            )
            if fp.pin(fcert, c_cells, (p0, p1)):
                try:
                    prob, p0, p1 = build_problem(
                        options,
                        grid_path_or_points,
                        corridor,
                        start=start,
                        goal=goal,
                        hs=fp.start_heading,
                        hg=fp.goal_heading,
                        start_kappa=ks,
                        unit_m=res,
                    )
                    margin, warm = options.kappa_margin, None
                    cold.clear()  # a new problem: its attempts are new
                    continue
                except InvalidInputError as exc:  # the pinned heading leaves its region
                    logger.debug("footprint: end heading not pinned (%s)", exc)
                    fp.unpin()
            if polygons and options.kappa_max is None:
                found = footprint_scp(
                    options, prob, h, c_cells, fcert, fp, rad / res, check, cost_at
                )
                if found is not None:
                    curve, cert, fcert = found
                    rec.failure = None
                    if refined is not None:  # the polish was of the curve replaced here
                        refined.pop("c", None)
                        refined["stats"] = {
                            "status": "skipped",
                            "reason": "the footprint rounds replaced the fast result",
                        }
        if fcert is not None:
            rec.footprint_margin_m = fcert.min_margin_m
        if cert.ok and (fcert is None or fcert.ok):
            if refined is not None:
                curve, cert, fcert = _polished(
                    refined, check, (curve, cert, fcert), t_cells, span_box
                )
                if refined["stats"].get("kept"):
                    rec.cost = refined["cost"]
                    if rec.cost_rounds is not None:  # the term at the polished curve
                        rec.cost_rounds = dict(
                            rec.cost_rounds,
                            cost_term=refined["cost_term"],
                            mean_cost=refined["mean_cost"],
                        )
            stats = summarize(attempts, time.perf_counter() - t_call, success=True)
            if refined is not None:
                stats["refine"] = refined["stats"]
            if rec.cost_rounds is not None:
                stats["cost_rounds"] = dict(rec.cost_rounds)
            if fp is not None:
                stats.update(footprint_certificate_s=fp.time_s, footprint_rounds=fp.rounds)
            return SmoothPath(
                curve=curve, stats=stats, certificate=cert, footprint_certificate=fcert
            )
        if cert.ok:  # the footprint still fails: refine the knots
            h, margin, warm = max(0.5, h / 2), options.kappa_margin, None
            spans_tried += 1
            continue
        rec.failure = "certificate: " + ", ".join(cert.failures)
        logger.debug("attempt %d failed its certificate: %s", len(attempts), cert.failures)
        kmax = options.kappa_max
        if (
            warm is None
            and kmax is not None
            and cert.failures == ("curvature_bound",)
            and 0 < cert.kappa_max_sampled <= RETRY_MAX_EXCESS * kmax
        ):
            # the bound broke between the samples only, and by a little: the same knots
            # again, warm started, with the sampled bound tightened by the excess found
            # (cheaper than a refinement, which doubles the problem; a larger excess
            # tightens the bound at many samples at once, and the warm start is then no
            # better than a cold one)
            logger.debug(
                "dense max kappa %.4g x the bound: same knots again", cert.kappa_max_sampled / kmax
            )
            margin *= MARGIN_RETRY * kmax / cert.kappa_max_sampled
            warm = c_cells
            continue
        h, margin, warm = max(0.5, h / 2), options.kappa_margin, None
        spans_tried += 1
    stats = summarize(attempts, time.perf_counter() - t_call, success=False)
    last = attempts[-1].failure or "time budget exhausted" if attempts else "no attempt"
    raise SmoothingError(
        f"no certified curve after {len(attempts)} attempt(s) "
        f"(time_budget_s={options.time_budget_s}): {last}",
        stats,
    )


def _same_knots(a: tuple[np.ndarray, np.ndarray], b: tuple[np.ndarray, np.ndarray]) -> bool:
    """Whether two ``(knots, span_box)`` pairs of :func:`graded_knots` are identical."""
    return all(x.shape == y.shape and bool(np.array_equal(x, y)) for x, y in zip(a, b, strict=True))


def _polished(
    refined: dict, check: Any, fast: tuple, t_cells: np.ndarray, span_box: np.ndarray
) -> tuple:
    """Return the IPOPT polish's curve and certificates when it passes them, else ``fast``.

    ``refined``: :func:`solve_attempt`'s polish (its ``"stats"`` get the outcome);
    ``check``: :func:`_check` of the fit; ``fast``: the fast result's ``(curve, certificate,
    footprint certificate)``, both certified.
    """
    st = refined["stats"]
    if "c" not in refined:
        st["kept"] = False
        return fast
    t0 = time.perf_counter()
    got = check(refined["c"], t_cells, span_box)
    st["certificate_s"] = time.perf_counter() - t0
    st["kept"] = bool(got[1].ok and (got[2] is None or got[2].ok))
    if not st["kept"]:
        st["status"] = "not certified"
        return fast
    return got


def _check(
    options: Smoother,
    corridor: Corridor | PolygonCorridor,
    res: float,
    raw_grid: Any,
    radius: float,
    fp: FootprintRounds | None,
    ends: tuple,
    c_cells: np.ndarray,
    t_cells: np.ndarray,
    span_box: np.ndarray,
) -> tuple:
    """Return the curve of ``c_cells`` (length units ``res``, m) and its certificates.

    ``(curve, certificate, footprint certificate)``: the last only with a footprint
    (``fp``, :class:`~trajopt.smoother._footprint_rounds.FootprintRounds`) and when the first
    passes, else ``None``. ``ends``: the exact end points (m).
    """
    c = np.asarray(corridor.origin, dtype=float) + res * c_cells
    c[0], c[-1] = ends
    curve = BSplineCurve(t_cells * res, c, options.degree)
    cert = certify(
        curve,
        corridor,
        span_box,
        start=ends[0],
        goal=ends[1],
        raw_grid=raw_grid,
        radius=radius,
        kappa_bound=options.kappa_max,
        samples_per_cell=options.samples_per_cell,
        unit_m=res,
    )
    return curve, cert, (fp.certify(curve) if (cert.ok and fp is not None) else None)


def solve_attempt(
    options: Smoother,
    prob: Problem,
    h: float,
    remaining: float,
    margin: float,
    warm: np.ndarray | None,
    rec: AttemptRecord,
    cost_at: tuple[CostField, np.ndarray] | None = None,
    refined: dict | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One attempt on the knots of span ``h`` (cells).

    The QP, then with a cost field (``cost_at``: the field and the corridor's origin, m) the
    damped QP rounds of the linearised cost term (:func:`~trajopt.smoother._cost.cost_rounds`;
    on a warm retry from the warm control points), then with a
    curvature bound the SCP or IPOPT (sampled bound ``margin * kappa_max``; the SCP's linear
    term then holds the cost gradient at the rounds' result).
    ``warm``: control points (cells) of an earlier attempt on the same knots; the curvature
    solver then starts from them instead of the QP solution. With IPOPT as the QP solver (or
    the curvature solver, with a bound) the cost term is IPOPT's exact one instead of the
    rounds' (:func:`~trajopt.smoother._nlp_solve.cost_ipopt`). ``refined``: a dict that
    receives the IPOPT polish of the result (:func:`~trajopt.smoother._nlp_solve.refine_ipopt`;
    ``"stats"``, and ``"c"``, its control points in cells, when it is offered). Fills ``rec``;
    returns the control points (cells, shape (n, 2)), the knots (cells) and every span's
    region.

    Raises
    ------
    AttemptFailed
        Empty bounds, or a solver failure (``rec`` holds the solver records).
    """
    t_enter = time.perf_counter()
    t_budget = t_enter + remaining  # the attempt's deadline
    try:
        asm = assemble(options, prob, h)
    except EmptyBoundsError as exc:
        raise AttemptFailed(str(exc)) from None
    qp, t = asm.qp, asm.knots
    n, nb = qp.n, qp.nb
    term = None
    if cost_at is not None:
        scale = cost_scale(options, prob.taut)
        term = CostTerm.on_knots(cost_at[0], cost_at[1], prob.res, t, options.degree, nb, scale)
    rounds = RoundSolver(qp)
    if warm is None and term is not None and not ipopt_cost(options):
        # the first QP holds the cost term linearised around the path's targets (the rounds'
        # model there), so that the rounds start from a cost-aware curve
        info = rounds(options, linearised(qp, term, asm.x0), asm.x0)
    elif warm is None:
        info = solve_qp(options, qp, x0=asm.x0)
    else:
        z = asm.x0.copy()
        z[:n], z[nb : nb + n] = warm[:, 0], warm[:, 1]
        info = SolveInfo(solver="warm", status=SolveStatus.WARM_START, detail="warm start", z=z)
    rec.n_control_points, rec.padded_size, rec.qp = n, nb, info
    if not info.success:
        raise AttemptFailed(f"QP solver {info.solver}: {_failure(info)}")
    z = np.clip(info.z, qp.lbx, qp.ubx)
    const = asm.const
    qp_curv, nlp_done = qp, False
    if term is not None:
        if ipopt_cost(options):  # IPOPT minimises the exact term (with its curvature rows)
            left = remaining - (time.perf_counter() - t_enter)
            z, g_lin, rec.cost_rounds, rec.nlp = cost_ipopt(
                options, qp, t, z, term, prob, margin, left
            )
            if not rec.nlp.success:
                raise AttemptFailed(f"cost term (ipopt): {_failure(rec.nlp)}")
            nlp_done = options.kappa_max is not None
        else:
            deadline = t_enter + remaining
            z, g_lin, rec.cost_rounds = cost_rounds(options, qp, term, z, const, deadline, rounds)
        qp_curv = dataclasses.replace(qp, g=g_lin)
    if options.kappa_max is not None and not nlp_done:
        kmax_cells = options.kappa_max * prob.res
        remaining -= time.perf_counter() - t_enter  # what the QP stage left
        if options.curvature_solver == "scp":
            scp = CurvatureSCP(options, qp_curv, t, kmax_cells, margin, const)
            cinfo = scp.run(z, remaining, trust=TRUST_WARM if warm is not None else TRUST_COLD)
        else:
            cinfo = solve_curvature_ipopt(options, qp, t, z, kmax_cells, remaining, margin)
        rec.nlp = cinfo
        if not cinfo.success:
            raise AttemptFailed(f"curvature bound ({cinfo.solver}): {_failure(cinfo)}")
        z = np.clip(cinfo.z, qp.lbx, qp.ubx)
    if refined is not None:  # Smoother(refine="ipopt"): the polish, offered to the caller
        left = t_budget - time.perf_counter()
        zr, refined["stats"] = refine_ipopt(options, qp, t, z, term, prob, margin, left, const)
        if zr is not None:
            cr = refined["c"] = np.column_stack([zr[:n], zr[nb : nb + n]])
            project_heading(cr, prob, asm.lo, asm.hi, asm.point_rows, asm.start_alpha)
            zr = np.zeros(2 * nb)
            zr[:n], zr[nb : nb + n] = cr[:, 0], cr[:, 1]
            refined["cost"] = band_quadratic(qp.full, qp.g, zr, const)
            if term is not None:
                refined["cost_term"] = term.value_grad(zr)[0]
                refined["mean_cost"] = term.mean_cost(zr)
    c = np.column_stack([z[:n], z[nb : nb + n]])
    project_heading(c, prob, asm.lo, asm.hi, asm.point_rows, asm.start_alpha)
    zc = np.zeros(2 * nb)
    zc[:n], zc[nb : nb + n] = c[:, 0], c[:, 1]
    rec.cost = band_quadratic(qp.full, qp.g, zc, const)
    return c, t, asm.span_box


def _failure(info: SolveInfo) -> str:
    """Return what a failed solver call reports: its status (and IPOPT's iteration count)."""
    if info.solver == "ipopt":
        return f"IPOPT status {info.detail!r} after {info.iterations} iteration(s)"
    return info.detail


def fit_free(options: Smoother, points: Any, u: Any, knots: Any) -> BSplineCurve:
    """:meth:`Smoother.fit_free` (see there)."""
    pts = np.asarray(points, dtype=float)
    uu = np.asarray(u, dtype=float)
    t = np.asarray(knots, dtype=float)
    p = options.degree
    n = len(t) - p - 1
    if pts.ndim != 2 or pts.shape[1] != 2 or uu.shape != (len(pts),):
        raise InvalidInputError(
            f"points must have shape (N, 2) and u shape (N,), got {pts.shape} and {uu.shape}"
        )
    if n < p + 1:
        raise InvalidInputError(f"need at least {2 * p + 2} knots for degree {p}, got {len(t)}")
    band, g, _ = objective(pts, uu, t, p, n, options.smoothness_weight, options.smoothness_order)
    nb = bucket_size(n)
    full = np.zeros((p + 1, nb))
    full[:, :n] = band[:, :n]
    full[0, n:] = 1.0
    lbx = np.full(2 * nb, -np.inf)
    ubx = np.full(2 * nb, np.inf)
    lbx[n:nb] = ubx[n:nb] = lbx[nb + n :] = ubx[nb + n :] = 0.0
    n_rows = N_HEADING_ROWS + 2 * nb
    qp = QPData(
        full=full,
        g=g,
        n=n,
        nb=nb,
        lbx=lbx,
        ubx=ubx,
        heading=np.zeros((N_HEADING_ROWS, 2 * nb)),
        lba=np.full(n_rows, -np.inf),
        uba=np.full(n_rows, np.inf),
    )
    info = solve_qp(options, qp)
    if not info.success:
        raise SmoothingError(f"unconstrained fit failed: {info.detail}", info.to_stats())
    z = info.z
    return BSplineCurve(t, np.column_stack([z[:n], z[nb : nb + n]]), p)
