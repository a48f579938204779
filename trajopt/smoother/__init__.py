"""The proposed smoother: a corridor-constrained B-spline fit, certified collision-free.

:class:`Smoother` fits a clamped B-spline ``C(u) = sum_i c_i B_i(u)`` (parameter ``u`` =
arc length along the path) to path points ``p_r`` at their arc lengths ``u_r``:

    minimise   lam * sum_r |C(u_r) - p_r|^2  +  w * integral |C^(m)(u)|^2 du
               + ell * integral |C'(u)|^2 du                                     (length units)
    subject to c_0 = start, c_{n-1} = goal,
               c_i in the intersection of the corridor regions of every span it touches,
               optional: c_1 on the start-heading ray, c_{n-2} on the reverse goal ray,
               optional: |kappa| <= kappa_max at dense samples (with a speed floor).

With the *fidelity* objective (default in a box corridor) ``p_r`` are the A* cell centres,
``lam = 1`` and ``ell = 0``: the chapter's least-squares fidelity (equation (3)) plus the
knot-aware integrated squared ``m``-th derivative (exact Gram matrix of the derivative
basis). With the *taut* objective (default in a :class:`~trajopt.corridor.
PolygonCorridor`) ``p_r`` are the corridor's path sampled once per length unit, ``lam`` is small
and the length term pulls the curve taut. Positions and parameters are divided by the
corridor's length unit first (:func:`~trajopt.geometry.length_unit`: the cell side, or a
quarter of the robot's radius on maps whose cells are finer; a footprint's fit counts in
cells), so the default weights work on every map and a fine map costs no more than a
coarse one.

The corridor constraint uses the convex-hull property: span ``j`` lies in the convex hull
of ``c_j .. c_{j+p}``; with all of them inside the span's region the whole continuous span
is inside it. Knots are graded so that every region holds at least ``p`` spans (then no
control point touches more than two consecutive regions, which always intersect), so each
control point is bounded by one intersection: variable bounds for the axis-aligned boxes
plus two rows ``x + y`` and ``x - y`` for the 45-degree *bridges* the corridor places in
diagonal gaps, or the half-planes of its (at most two) polygons in a polygon corridor.
The convex problem is a sparse banded QP solved by piqp (by default): through
``casadi.conic`` in a box corridor, directly in a polygon corridor (its rows per point
vary). The curvature-bounded problem is solved by sequential convex programming
(``curvature_solver="scp"``, the default) or by IPOPT on the exact non-convex problem,
warm-started from the QP (``curvature_solver="ipopt"``), in box and polygon corridors alike.
A cost field's term is minimised by QP rounds on its convex models, or exactly by IPOPT with
an IPOPT solver; ``refine="ipopt"`` polishes the fast result by IPOPT on the whole problem.
Solvers are built once per problem shape (padded size, degree, rows per point) and cached.

Every result is verified (:class:`Certificate`) before it is returned: control points in
their regions, exact endpoints, dense-sample clearance against the raw map, no cusp, and the
curvature bound. On failure the knots are refined; when that is exhausted
:class:`~trajopt.errors.SmoothingError` is raised with the solver statistics.

Modules: :mod:`~trajopt.smoother._options` (the :class:`Smoother` options),
:mod:`~trajopt.smoother._attempts` (the attempt loop), :mod:`~trajopt.smoother._problem`
(problem assembly in length units), :mod:`~trajopt.smoother._basis` (B-spline basis maths),
:mod:`~trajopt.smoother._qp` (the convex QP and its solver cache),
:mod:`~trajopt.smoother._scp` (the curvature bound by SCP), :mod:`~trajopt.smoother._nlp`
(IPOPT), :mod:`~trajopt.smoother._solver_builds` (the lock and the record of the solver
builds both share), :mod:`~trajopt.smoother._certificate` and
:mod:`~trajopt.smoother._status` (solve statuses and the statistics).
"""

from trajopt.smoother._certificate import Certificate, certify
from trajopt.smoother._footprint_rounds import END_HEADINGS, end_headings
from trajopt.smoother._options import CurvatureSolver, Objective, QPSolver, Smoother
from trajopt.smoother._path import SmoothPath
from trajopt.smoother._problem import graded_knots
from trajopt.smoother._status import SolveInfo, SolveStatus

__all__ = [
    "Certificate",
    "CurvatureSolver",
    "END_HEADINGS",
    "Objective",
    "QPSolver",
    "SmoothPath",
    "Smoother",
    "SolveInfo",
    "SolveStatus",
    "certify",
    "end_headings",
    "graded_knots",
]
