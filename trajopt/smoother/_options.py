"""The :class:`Smoother` options.

The :class:`Smoother` options (a frozen dataclass, validated on construction) and its two entry
points; the work is done by :mod:`trajopt.smoother._attempts`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from trajopt.corridor import Corridor, PolygonCorridor
from trajopt.geometry import BSplineCurve
from trajopt.robot import Footprint
from trajopt.smoother._path import SmoothPath
from trajopt.validation import choice, integer, number

QPSolver = Literal["osqp", "piqp", "ipopt"]
_QP_SOLVERS = ("osqp", "piqp", "ipopt")
CurvatureSolver = Literal["scp", "ipopt"]
_CURVATURE_SOLVERS = ("scp", "ipopt")
_OBJECTIVES = ("auto", "fidelity", "taut")
Refine = Literal["ipopt"]
_REFINES = (None, "ipopt")
Objective = Literal["auto", "fidelity", "taut"]


@dataclass(frozen=True, slots=True)
class Smoother:
    """Corridor-constrained B-spline smoother (options validated on construction).

    Parameters
    ----------
    degree : int, optional
        Spline degree, 3 to 5. Default 3 (C2 curve: continuous curvature).
    smoothness_weight : float, optional
        ``w`` of the integrated squared derivative, in length units (>= 0). Default 50.
        The length unit is the corridor's (:func:`~trajopt.geometry.length_unit`): the
        cell side, or ``radius / 4`` on maps whose cells are finer (a footprint's fit
        counts in cells); "cells" below means this unit.
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
        bit for bit; osqp warm-starts its duals from the previous call). ``"ipopt"``
        solves the same problem with IPOPT (CasADi ``nlpsol``, built once per problem
        shape), in box and polygon corridors.
    curvature_solver : {"scp", "ipopt"}, optional
        How the curvature-bounded problem is solved. ``"scp"`` (default): sequential
        convex programming, a few piqp QPs in which the bound is linearised
        conservatively around the previous iterate's tangents, inside a trust region
        (from 64 control points up, only the samples near the bound, and their
        neighbours, enter the QPs; the step's acceptance still checks every sample).
        ``"ipopt"``: the exact non-convex problem by IPOPT, warm started from the QP, in
        box and polygon corridors (about 3x the SCP's smoothing time on the shared
        queries, with durations within 0.1 %; see ``docs/benchmarks.md``).
    scp_iterations : int, optional
        Most SCP iterations. Default 25.
    time_budget_s : float, optional
        Wall-time budget per :meth:`fit` call (s); exceeded -> ``SmoothingError``.
        Default 5 (the first call of a new size also builds its solvers).
    max_attempts : int, optional
        Knot refinements (span length halved each time) before giving up. Default 3. A
        refinement that leaves the knots as they were (a short curve: each box keeps at
        least ``degree`` spans) is skipped: it would repeat the failed attempt. When
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
    refine : {None, "ipopt"}, optional
        ``"ipopt"``: after the fast path (the QP, the cost rounds, the SCP), each attempt's
        result is polished by IPOPT on the same problem (the objective with the exact cost
        term when a cost is given, the exact curvature bound when ``kappa_max`` is set, the
        same corridor rows and end conditions; module :mod:`trajopt.smoother._nlp_solve`),
        warm started from it. The polished curve is kept only when IPOPT succeeds, its
        objective is not higher and it passes the certificates; otherwise the fast result
        is kept. ``stats["refine"]`` says which and why (IPOPT's status and iteration
        count, the objective before and after, the time). Nothing to polish when IPOPT
        already solved the whole problem (``qp_solver="ipopt"`` without a bound,
        ``curvature_solver="ipopt"`` with one). Default ``None``.
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
    refine: Refine | None = None
    verbose: bool = False

    def __post_init__(self) -> None:
        integer("degree", self.degree, 3, 5)
        number("smoothness_weight", self.smoothness_weight, lo=0.0)
        integer("smoothness_order", self.smoothness_order, 1, self.degree - 1)
        number("span_cells", self.span_cells, lo=0.5)
        if self.kappa_max is not None:
            number("kappa_max", self.kappa_max, unit="1/m", lo=0.0, strict=True)
        number("kappa_margin", self.kappa_margin, lo=0.0, strict=True, hi=1.0)
        number("speed_floor", self.speed_floor, lo=0.0)
        choice("qp_solver", self.qp_solver, _QP_SOLVERS)
        choice("curvature_solver", self.curvature_solver, _CURVATURE_SOLVERS)
        integer("scp_iterations", self.scp_iterations, 1)
        number("time_budget_s", self.time_budget_s, unit="s", lo=0.0, strict=True)
        integer("max_attempts", self.max_attempts, 1)
        integer("samples_per_cell", self.samples_per_cell, 2)
        choice("objective", self.objective, _OBJECTIVES)
        number("taut_fidelity_weight", self.taut_fidelity_weight, lo=0.0)
        number("taut_length_weight", self.taut_length_weight, lo=0.0)
        choice("refine", self.refine, _REFINES)

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
        start_curvature: float | None = None,
        footprint: Footprint | None = None,
        cost: Any = None,
        cost_weight: float = 2.0,
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
            :func:`~trajopt.corridor.build_polygon_corridor`.
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
        start_curvature : float, optional
            Exact signed curvature (1/m) at the start, with ``start_heading`` (a re-plan
            from a moving robot continues its curvature). ``|c_1 - c_0|`` is then fixed
            (module :mod:`trajopt.smoother._problem`, :func:`start_alpha`), which makes the
            curvature linear in ``c_2``.
        footprint : Footprint, optional
            The robot's oriented footprint (needs ``raw_grid``): the curve must also pass
            :func:`~trajopt.robot._footprint.certify_footprint` (the footprint along the tangent,
            clear of the raw map). A curve that fails it gets the footprint rounds of
            :mod:`~trajopt.smoother._footprint_rounds` (a pinned end heading; in a polygon
            corridor without a curvature bound, the footprint SCP); then the knots are
            refined.
        cost : astar.Costmap or array_like, shape (ny, nx), optional
            A cost field over the raw grid's cells (needs ``raw_grid``): a costmap (its
            normalised :attr:`~astar.Costmap.cost`; its grid must have the raw grid's shape,
            resolution and origin) or per-cell costs in ``[0, 1]``, row 0 at the bottom. The
            objective then gains ``s * cost_weight * integral cost(C(u)) |C'(u)| du`` (cost
            per unit length, cell units; the cells' values blurred by a Gaussian of one cell
            and interpolated bilinearly between their centres; ``s = 4 * 2 *
            taut_length_weight`` with the taut objective, four times the price of one more
            cell of length, since the curve also pays for bending where the costmap search
            pays only for length; 1 with the fidelity objective), minimised by sequential QP
            rounds on a convex model of the term around the current iterate, with a line
            search (module :mod:`trajopt.smoother._cost`); the corridor rows stay hard
            constraints and the certificate is unchanged. With
            ``qp_solver="ipopt"`` (or ``curvature_solver="ipopt"`` and ``kappa_max``) IPOPT
            minimises the term exactly instead, the cell values' cubic B-spline in place of
            the bilinear interpolation (module :mod:`trajopt.smoother._nlp_cost`).
            ``stats["cost_rounds"]`` reports the rounds and the curve's mean cost.
        cost_weight : float, optional
            ``w`` of the cost term (dimensionless, finite, >= 0; 0 drops the term). Default
            2 (the planner's ``costmap_weight``).

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
        from trajopt.smoother._attempts import fit

        return fit(
            self,
            grid_path_or_points,
            corridor,
            raw_grid=raw_grid,
            radius=radius,
            start=start,
            goal=goal,
            start_heading=start_heading,
            goal_heading=goal_heading,
            start_curvature=start_curvature,
            footprint=footprint,
            cost=cost,
            cost_weight=cost_weight,
        )

    def fit_free(self, points: np.ndarray, u: np.ndarray, knots: np.ndarray) -> BSplineCurve:
        """Return the same objective with *no* constraints (no corridor, free ends, no bound).

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
        from trajopt.smoother._attempts import fit_free

        return fit_free(self, points, u, knots)
