"""Side-by-side comparison of path methods on one grid/start/goal (the chapter's Section 5).

:func:`compare` builds a shared :class:`ComparisonContext` once (raw grid, the chapter's
avoidance area, the exact inflation by the robot radius, the A* paths on the raw grid and
on the avoidance area), runs each registered *method* on it, scores every result with
:func:`trajopt.metrics.path_metrics` against the avoidance-area A* path, and returns a
:class:`ComparisonTable`.

Built-in methods (the chapter's four, in this order):

* ``'A*'``: traditional A* on the raw grid (cell centres as a polyline);
* ``'A* + avoidance area'``: A* on :func:`astar.avoidance_area` (``W = w_cells``);
* ``'polynomial fit'``: :func:`trajopt.fits.fit_polynomial` ``y = f(x)`` of the latter;
* ``'B-spline fit'``: :func:`trajopt.fits.fit_bspline` of the latter (a least-squares
  fit: as in the chapter's Table 2 its end points are not exact, see the
  ``start_error_x_m`` ... ``end_error_y_m`` columns; parameters the data cannot support,
  where the Schoenberg-Whitney condition fails, the system is numerically singular or the
  solution swings more than :data:`~trajopt.fits.BSPLINE_SWING_MAX` data extents outside
  the data's bounding box, give a row with ``valid=False``, no curve and the reason as
  ``note``);

and the proposed method, ``'proposed'``: :func:`trajopt.plan` (certified corridor smoother
and ruckig timing; its own clearance-aware A* path), with the timed metrics as extra
columns (``duration_s``, ``ratio_v``, ...). ``options={"proposed": {"start_heading": h0,
"goal_heading": h1}}`` plans it pose to pose: a differential drive may then turn in place
at an end (a :class:`~trajopt.motion.TrajectoryChain`), the row scores the curve it drives,
and its turns are checked against the turn limits (``ratio_turn_omega``,
``ratio_turn_alpha``).

``'polynomial fit (parametric)'`` is registered too but is not run by default.

Modules: :mod:`~trajopt.analysis.comparison._records` (context and result),
:mod:`~trajopt.analysis.comparison._registry`, :mod:`~trajopt.analysis.comparison._builtin_methods`,
:mod:`~trajopt.analysis.comparison._table` and :mod:`~trajopt.analysis.comparison._run` (:func:`compare`);
every public name is imported here.

Adding a method
---------------
A method is a callable ``fn(ctx: ComparisonContext) -> curve | points | MethodResult``:
return any :class:`~trajopt.geometry._curve.ParametricCurve`, an ``(n, 2)`` array of points in
metres (scored as a polyline), or a :class:`MethodResult` to also set ``valid``/``note``.
Its options arrive as ``ctx.options_for(name)`` (from ``compare(..., options={name: {...}})``).
Register it with one line, without touching the other methods::

    register_method("proposed", "trajopt.analysis.comparison._proposed:proposed_method")   # lazy "module:attr"
    # or, in any module:  @register_method("proposed")  def _run(ctx): ...

Registered methods with ``default=True`` (the default) run when ``methods`` is ``None``, in
registration order. A method that raises :class:`~trajopt.errors.NoPathError`,
:class:`~trajopt.errors.SmoothingError` or :class:`~trajopt.errors.TimingError` (or their
:mod:`astar` counterparts) gets a row with ``valid=False``, NaN metrics and the error as
``note``; any other exception propagates.
"""

from trajopt.analysis.comparison._builtin_methods import DEFAULT_BSPLINE, DEFAULT_POLY
from trajopt.analysis.comparison._records import ComparisonContext, MethodFn, MethodResult
from trajopt.analysis.comparison._registry import (
    register_method,
    registered_methods,
    resolve_method,
    unregister_method,
)
from trajopt.analysis.comparison._run import compare
from trajopt.analysis.comparison._table import ComparisonTable

__all__ = [
    "compare",
    "ComparisonTable",
    "ComparisonContext",
    "MethodFn",
    "MethodResult",
    "register_method",
    "unregister_method",
    "registered_methods",
    "resolve_method",
    "DEFAULT_POLY",
    "DEFAULT_BSPLINE",
]
