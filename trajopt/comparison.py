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
  where the Schoenberg-Whitney condition fails or the system is numerically singular, give
  a row with ``valid=False``, no curve and the reason as ``note``);

and the proposed method, ``'proposed'``: :func:`trajopt.plan` (certified corridor smoother
and ruckig timing; its own clearance-aware A* path), with the timed metrics as extra
columns (``duration_s``, ``ratio_v``, ...).

``'polynomial fit (parametric)'`` is registered too but is not run by default.

Adding a method
---------------
A method is a callable ``fn(ctx: ComparisonContext) -> curve | points | MethodResult``:
return any :class:`~trajopt.curve.ParametricCurve`, an ``(n, 2)`` array of points in
metres (scored as a polyline), or a :class:`MethodResult` to also set ``valid``/``note``.
Its options arrive as ``ctx.options_for(name)`` (from ``compare(..., options={name: {...}})``).
Register it with one line, without touching the other methods::

    register_method("proposed", "trajopt.pipeline:compare_method")   # lazy "module:attr"
    # or, in any module:  @register_method("proposed")  def _run(ctx): ...

Registered methods with ``default=True`` (the default) run when ``methods`` is ``None``, in
registration order. A method that raises :class:`~trajopt.errors.NoPathError`,
:class:`~trajopt.errors.SmoothingError` or :class:`~trajopt.errors.TimingError` (or their
:mod:`astar` counterparts) gets a row with ``valid=False``, NaN metrics and the error as
``note``; any other exception propagates.
"""

from __future__ import annotations

import csv
import importlib
import logging
import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

import astar.errors as _astar_errors
from astar.grid import OccupancyGrid
from trajopt.errors import InvalidInputError, NoPathError, SmoothingError, TimingError
from trajopt.metrics import DEFAULT_SAMPLE_SPACING, PathMetrics, path_metrics

__all__ = [
    "compare",
    "ComparisonTable",
    "ComparisonContext",
    "MethodResult",
    "register_method",
    "unregister_method",
    "registered_methods",
    "resolve_method",
    "DEFAULT_POLY",
    "DEFAULT_BSPLINE",
]

logger = logging.getLogger(__name__)

#: Polynomial-fit parameters used when ``poly`` is not given: the best of
#: :func:`trajopt.fits.sweep_polynomial` on the paper scene's target A (Table 1 analogue).
DEFAULT_POLY: Mapping[str, Any] = MappingProxyType({"method": "least_squares", "order": 10})
#: B-spline parameters used when ``bspline`` is not given (see :data:`DEFAULT_POLY`;
#: from :func:`trajopt.fits.sweep_bspline` on target A, Table 2 analogue).
DEFAULT_BSPLINE: Mapping[str, Any] = MappingProxyType(
    {"parameterization": "chord", "degree": 2, "n_ctrl": 43}
)

_SOFT_ERRORS = (
    NoPathError,
    SmoothingError,
    TimingError,
    _astar_errors.NoPathError,
)


# ============================================================================ records
@dataclass(frozen=True, slots=True)
class MethodResult:
    """What a method returns when it has more to say than the path.

    Attributes
    ----------
    path : ParametricCurve or ndarray (n, 2) or None
        The path (metres); ``None`` when the method produced none (metrics are NaN).
    valid : bool
        ``False`` when the method's own validity test failed (shown in the table).
    note : str
        Free text for the table (why invalid, parameters used, ...).
    runtime_s : float or None
        Overrides the measured wall time (e.g. the A* rows report the search time).
    extras : Mapping[str, Any]
        Extra columns for this row (e.g. ``fit_mse_m2``: equation (3) at the parameters
        the fit used); other rows show them empty.
    """

    path: Any
    valid: bool = True
    note: str = ""
    runtime_s: float | None = None
    extras: Mapping[str, Any] = field(default_factory=dict)


@dataclass(frozen=True, slots=True)
class ComparisonContext:
    """Everything the methods share, computed once per :func:`compare` call.

    Attributes
    ----------
    grid : astar.OccupancyGrid
        The raw map.
    start, goal : tuple of float
        World points (m).
    start_cell, goal_cell : tuple of int
        Their cells ``(ix, iy)``.
    robot_radius : float
        Robot radius (m).
    w_cells : int
        Avoidance-area width ``W`` (cells).
    border_occupied : bool
        Whether the map border counts as an obstacle (avoidance area, inflation, clearance).
    avoidance : astar.OccupancyGrid
        :func:`astar.avoidance_area` of ``grid`` with ``W = w_cells``.
    inflated : astar.OccupancyGrid
        :func:`astar.inflation` of ``grid`` by ``robot_radius`` with ``metric="square"``.
    path_raw, path_avoid : astar.GridPath
        A* on the raw grid and on the avoidance area.
    reference : ndarray, shape (n, 2)
        Cell centres of ``path_avoid`` (m): what the fits fit and the metrics compare to.
    options : Mapping[str, Mapping[str, Any]]
        Per-method options (read with :meth:`options_for`).
    timings : Mapping[str, float]
        Wall times (s) of the shared steps (``'astar_raw'``, ``'astar_avoid'``, ...).
    """

    grid: OccupancyGrid
    start: tuple[float, float]
    goal: tuple[float, float]
    start_cell: tuple[int, int]
    goal_cell: tuple[int, int]
    robot_radius: float
    w_cells: int
    border_occupied: bool
    avoidance: OccupancyGrid
    inflated: OccupancyGrid
    path_raw: Any
    path_avoid: Any
    reference: np.ndarray
    options: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)
    timings: Mapping[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        ref = np.array(self.reference, dtype=float)
        ref.flags.writeable = False
        object.__setattr__(self, "reference", ref)
        opts = {str(k): MappingProxyType(dict(v)) for k, v in dict(self.options).items()}
        object.__setattr__(self, "options", MappingProxyType(opts))
        object.__setattr__(self, "timings", MappingProxyType(dict(self.timings)))

    def options_for(self, name: str) -> dict[str, Any]:
        """A fresh dict of the options given for method ``name`` (empty when none)."""
        return dict(self.options.get(name, {}))

    def points(self, grid_path: Any) -> np.ndarray:
        """Cell centres (m) of an :class:`astar.GridPath`, shape (n, 2)."""
        return self.grid.cell_to_world(np.asarray(grid_path.cells))


MethodFn = Callable[[ComparisonContext], Any]


@dataclass(frozen=True, slots=True)
class _Spec:
    target: MethodFn | str
    default: bool

    def resolve(self) -> MethodFn:
        if callable(self.target):
            return self.target
        module, _, attr = self.target.partition(":")
        fn = getattr(importlib.import_module(module), attr)
        if not callable(fn):
            raise InvalidInputError(f"method target {self.target!r} is not callable")
        return fn


_REGISTRY: dict[str, _Spec] = {}


def register_method(
    name: str,
    fn: MethodFn | str | None = None,
    *,
    default: bool = True,
    replace: bool = False,
) -> Any:
    """Register a comparison method (usable as a decorator when ``fn`` is omitted).

    Parameters
    ----------
    name : str
        Row name in the table (non-empty, unique unless ``replace``).
    fn : callable or str, optional
        ``fn(ctx) -> curve | points | MethodResult``, or ``"module:attr"`` imported lazily
        at the first run (keeps ``import trajopt.comparison`` light and free of cycles).
    default : bool
        Run it when :func:`compare` gets ``methods=None``.
    replace : bool
        Allow overwriting an existing registration.

    Returns
    -------
    The function (or the decorator when ``fn`` is None).
    """
    if not isinstance(name, str) or not name:
        raise InvalidInputError(f"method name must be a non-empty string, got {name!r}")

    def _add(target: MethodFn | str) -> MethodFn | str:
        if not (callable(target) or (isinstance(target, str) and ":" in target)):
            raise InvalidInputError(
                f"method {name!r} must be a callable or a 'module:attr' string, got {target!r}"
            )
        if name in _REGISTRY and not replace:
            raise InvalidInputError(
                f"method {name!r} is already registered (pass replace=True to overwrite)"
            )
        _REGISTRY[name] = _Spec(target, bool(default))
        return target

    if fn is None:
        return _add
    return _add(fn)


def unregister_method(name: str) -> None:
    """Remove a registered method (:class:`InvalidInputError` when unknown)."""
    if name not in _REGISTRY:
        raise InvalidInputError(f"method {name!r} is not registered; known: {list(_REGISTRY)}")
    del _REGISTRY[name]


def registered_methods(*, default_only: bool = False) -> tuple[str, ...]:
    """Names of the registered methods in registration order."""
    return tuple(n for n, s in _REGISTRY.items() if s.default or not default_only)


def resolve_method(name: str) -> MethodFn:
    """The callable of a registered method (imported now if registered as "module:attr").

    Raises
    ------
    InvalidInputError
        ``name`` is not registered.
    """
    if name not in _REGISTRY:
        raise InvalidInputError(f"method {name!r} is not registered; known: {list(_REGISTRY)}")
    return _REGISTRY[name].resolve()


# ============================================================================ built-ins
def _method_astar_raw(ctx: ComparisonContext) -> MethodResult:
    return MethodResult(ctx.points(ctx.path_raw), runtime_s=ctx.timings.get("astar_raw"))


def _method_astar_avoid(ctx: ComparisonContext) -> MethodResult:
    return MethodResult(ctx.reference, runtime_s=ctx.timings.get("astar_avoid"))


def _method_polynomial(ctx: ComparisonContext) -> MethodResult:
    from trajopt.fits import fit_polynomial

    opts = {**DEFAULT_POLY, **ctx.options_for("polynomial fit")}
    order = opts.pop("order")
    n = len(ctx.reference)
    if isinstance(order, int) and n < order + 1:
        return MethodResult(None, False, f"order {order} needs {order + 1} points, path has {n}")
    fit = fit_polynomial(ctx.reference, order, **opts)
    note = f"{fit.method}, order {fit.order}"
    if not fit.valid:
        note += f"; {fit.reason}"
    return MethodResult(fit.curve, fit.valid, note, extras={"fit_mse_m2": fit.mse})


def _method_polynomial_parametric(ctx: ComparisonContext) -> MethodResult:
    from trajopt.fits import fit_polynomial_parametric

    opts = {**DEFAULT_POLY, **ctx.options_for("polynomial fit (parametric)")}
    order = opts.pop("order")
    n = len(ctx.reference)
    if isinstance(order, int) and n < order + 1:
        return MethodResult(None, False, f"order {order} needs {order + 1} points, path has {n}")
    fit = fit_polynomial_parametric(ctx.reference, order, **opts)
    note = f"{fit.method}, order {fit.order}" + (f"; {fit.reason}" if fit.reason else "")
    return MethodResult(fit.curve, fit.valid, note, extras={"fit_mse_m2": fit.mse})


def _method_bspline(ctx: ComparisonContext) -> MethodResult:
    from trajopt.errors import IllPosedFitError
    from trajopt.fits import fit_bspline

    opts = {**DEFAULT_BSPLINE, **ctx.options_for("B-spline fit")}
    ref = ctx.reference
    n_distinct = len(ref)
    note = ""
    n_ctrl = opts.get("n_ctrl")
    if isinstance(n_ctrl, int) and n_ctrl > n_distinct:
        k = opts.get("degree", 3)
        opts["n_ctrl"] = max(n_distinct, (k if isinstance(k, int) else 3) + 1)
        note = f"n_ctrl reduced from {n_ctrl} to {opts['n_ctrl']} (path has {n_distinct} points); "
    if n_distinct < 2:
        return MethodResult(None, False, "path has a single point")
    try:
        curve = fit_bspline(ref, **opts)
    except IllPosedFitError as exc:  # the data cannot determine this fit: no curve to rank
        return MethodResult(None, False, note + str(exc))
    note += (
        f"{curve.parameterization}, degree {curve.k}, {curve.c.shape[0]} control points; "
        "end points not exact (start_error_*/end_error_* columns)"
    )
    return MethodResult(curve, True, note, extras={"fit_mse_m2": curve.mse})


register_method("A*", _method_astar_raw)
register_method("A* + avoidance area", _method_astar_avoid)
register_method("polynomial fit", _method_polynomial)
register_method("B-spline fit", _method_bspline)
register_method("polynomial fit (parametric)", _method_polynomial_parametric, default=False)
register_method("proposed", "trajopt.pipeline:compare_method")


# ============================================================================ table
_FLOAT_FMT = "{:.4g}"


def _fmt(v: Any) -> str:
    if isinstance(v, (bool, np.bool_)):
        return "yes" if v else "no"
    if isinstance(v, (float, np.floating)):
        return "nan" if math.isnan(v) else _FLOAT_FMT.format(float(v))
    if v is None:
        return ""
    return str(v)


@dataclass(frozen=True, slots=True)
class ComparisonTable:
    """Rows of metrics, one per method.

    Attributes
    ----------
    rows : tuple of Mapping
        One read-only mapping per method: ``method``, ``valid``, every
        :class:`~trajopt.metrics.PathMetrics` field, ``runtime_s`` and ``note``.
    meta : Mapping
        The inputs: ``start``, ``goal`` (m), ``robot_radius`` (m), ``w_cells``,
        ``border_occupied``, ``sample_spacing_m``, ``options``.
    paths : Mapping
        Method name -> the path object it produced (curve or points), for plotting; not
        part of equality.
    """

    rows: tuple[Mapping[str, Any], ...]
    meta: Mapping[str, Any] = field(default_factory=dict)
    paths: Mapping[str, Any] = field(default_factory=dict, compare=False, repr=False)

    def __post_init__(self) -> None:
        rows = tuple(MappingProxyType(dict(r)) for r in self.rows)
        object.__setattr__(self, "rows", rows)
        object.__setattr__(self, "meta", MappingProxyType(dict(self.meta)))
        object.__setattr__(self, "paths", MappingProxyType(dict(self.paths)))

    @property
    def columns(self) -> tuple[str, ...]:
        """Column names in order (union over rows, first-seen order)."""
        cols: dict[str, None] = {}
        for r in self.rows:
            cols.update(dict.fromkeys(r))
        return tuple(cols)

    @property
    def methods(self) -> tuple[str, ...]:
        """Method names in row order."""
        return tuple(str(r["method"]) for r in self.rows)

    def row(self, method: str) -> Mapping[str, Any]:
        """The row of ``method`` (:class:`InvalidInputError` when absent)."""
        for r in self.rows:
            if r["method"] == method:
                return r
        raise InvalidInputError(f"method must be one of {list(self.methods)}, got {method!r}")

    def __len__(self) -> int:
        return len(self.rows)

    def to_records(self) -> list[dict[str, Any]]:
        """A list of plain dicts, one per method (fresh copies)."""
        return [dict(r) for r in self.rows]

    def to_text(self, *, transpose: bool = True, columns: Sequence[str] | None = None) -> str:
        """An aligned plain-text table.

        Parameters
        ----------
        transpose : bool
            ``True`` (default, used by ``str()``): one line per metric, one column per
            method (readable for many metrics), notes listed below the table. ``False``:
            one line per method.
        columns : sequence of str, optional
            Columns to show (default all; ``note`` is always last).
        """
        cols = [c for c in (columns or self.columns) if c != "method"]
        if "note" in cols:
            cols = [c for c in cols if c != "note"] + ["note"]
        notes: list[str] = []
        if transpose:
            if "note" in cols:
                cols.remove("note")
                notes = [f"  {r['method']}: {r['note']}" for r in self.rows if r.get("note")]
            header = ["metric", *self.methods]
            body = [[c, *(_fmt(r.get(c)) for r in self.rows)] for c in cols]
        else:
            header = ["method", *cols]
            body = [[str(r["method"]), *(_fmt(r.get(c)) for c in cols)] for r in self.rows]
        table = [header, *body]
        widths = [max(len(line[i]) for line in table) for i in range(len(header))]
        lines = []
        for j, line in enumerate(table):
            cells = [
                line[i].ljust(widths[i]) if i == 0 else line[i].rjust(widths[i])
                for i in range(len(line))
            ]
            lines.append("  ".join(cells).rstrip())
            if j == 0:
                lines.append("  ".join("-" * w for w in widths))
        if notes:
            lines += ["notes:", *notes]
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.to_text()

    def to_markdown(self) -> str:
        """A GitHub-flavoured Markdown table, one row per method."""
        cols = list(self.columns)

        def esc(s: str) -> str:
            return s.replace("|", "\\|")

        out = ["| " + " | ".join(esc(c) for c in cols) + " |"]
        out.append("|" + "|".join("---" for _ in cols) + "|")
        for r in self.rows:
            out.append("| " + " | ".join(esc(_fmt(r.get(c))) for c in cols) + " |")
        return "\n".join(out)

    def to_csv(self, path: str | Path) -> Path:
        """Write the records as CSV (header = columns); returns the path written."""
        p = Path(path)
        with p.open("w", newline="", encoding="utf-8") as fh:
            writer = csv.DictWriter(fh, fieldnames=list(self.columns))
            writer.writeheader()
            for r in self.rows:
                writer.writerow(dict(r))
        return p

    def to_dataframe(self) -> Any:
        """A :class:`pandas.DataFrame` indexed by method (pandas imported here)."""
        try:
            import pandas as pd
        except ImportError as exc:
            raise ImportError(
                "ComparisonTable.to_dataframe needs pandas, which is not installed "
                "(pip install pandas); use to_records() for plain dicts"
            ) from exc
        return pd.DataFrame.from_records(self.to_records()).set_index("method")


# ============================================================================ compare
def _xy(value: object, name: str) -> tuple[float, float]:
    try:
        x, y = (float(v) for v in value)  # type: ignore[union-attr]
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(
            f"{name} must be two numbers (x, y) in metres, got {value!r}"
        ) from exc
    if not (math.isfinite(x) and math.isfinite(y)):
        raise InvalidInputError(f"{name} must be finite, got ({x}, {y})")
    return x, y


def _search(grid: OccupancyGrid, s: tuple[int, int], g: tuple[int, int], what: str) -> Any:
    try:
        from astar.search import find_path

        return find_path(grid, s, g)
    except _astar_errors.NoPathError as exc:
        raise NoPathError(f"no path from {s} to {g} on the {what}: {exc}") from exc
    except _astar_errors.InvalidInputError as exc:
        if isinstance(exc, InvalidInputError):
            raise
        raise InvalidInputError(f"A* on the {what}: {exc}") from exc


def _resolve_methods(
    methods: Sequence[str] | Mapping[str, MethodFn | str] | None,
) -> list[tuple[str, MethodFn]]:
    if methods is None:
        return [(n, _REGISTRY[n].resolve()) for n in registered_methods(default_only=True)]
    if isinstance(methods, Mapping):
        out = []
        for name, fn in methods.items():
            spec = _Spec(fn, True)
            if not (callable(fn) or (isinstance(fn, str) and ":" in fn)):
                raise InvalidInputError(
                    f"methods[{name!r}] must be a callable or 'module:attr', got {fn!r}"
                )
            out.append((str(name), spec.resolve()))
        return out
    if isinstance(methods, str):
        methods = [methods]
    out = []
    for name in methods:
        if name not in _REGISTRY:
            raise InvalidInputError(f"method {name!r} is not registered; known: {list(_REGISTRY)}")
        out.append((name, _REGISTRY[name].resolve()))
    return out


def compare(
    grid: OccupancyGrid,
    start: tuple[float, float],
    goal: tuple[float, float],
    *,
    robot_radius: float = 0.165,
    w_cells: int | None = None,
    poly: Mapping[str, Any] | None = None,
    bspline: Mapping[str, Any] | None = None,
    methods: Sequence[str] | Mapping[str, MethodFn | str] | None = None,
    options: Mapping[str, Mapping[str, Any]] | None = None,
    sample_spacing: float = DEFAULT_SAMPLE_SPACING,
    border_occupied: bool = True,
) -> ComparisonTable:
    """Run the chapter's methods (and any registered ones) and tabulate the metrics.

    Parameters
    ----------
    grid : astar.OccupancyGrid
        The raw map.
    start, goal : tuple of float
        World points ``(x, y)`` in metres.
    robot_radius : float
        Robot radius (m, > 0): collision threshold of the clearance.
    w_cells : int, optional
        Avoidance-area width ``W`` in cells; default ``ceil(2 * robot_radius / resolution)``
        (the robot width in cells, as the chapter's ``W = 11`` for 0.33 m at 0.03 m).
    poly : Mapping, optional
        Keyword arguments of :func:`trajopt.fits.fit_polynomial` (``order``, ``method``,
        ``weights``, ``tol``); missing keys come from :data:`DEFAULT_POLY`.
    bspline : Mapping, optional
        Keyword arguments of :func:`trajopt.fits.fit_bspline` (``degree``, ``n_ctrl``,
        ``parameterization``); missing keys from :data:`DEFAULT_BSPLINE`. ``n_ctrl`` is
        reduced to the number of path points when the path is shorter; when the data cannot
        determine the fit (Schoenberg-Whitney fails or the collocation matrix is
        numerically singular, typically for such a square system) the row is
        ``valid=False`` without a curve, and its note says how many control points the
        data allow.
    methods : sequence of str or Mapping[str, callable], optional
        Registered method names to run (default: every registered default method), or a
        mapping name -> method callable for one-off methods.
    options : Mapping[str, Mapping], optional
        Per-method options by name (``poly``/``bspline`` fill the built-in entries).
    sample_spacing : float
        Arc-length spacing of the metric samples (m).
    border_occupied : bool
        The map border counts as an obstacle (avoidance area, inflation and clearance), as
        in the chapter. Default ``True``.

    Returns
    -------
    ComparisonTable

    Raises
    ------
    InvalidInputError
        Bad arguments, or start/goal outside the map or blocked in the avoidance area.
    NoPathError
        No path in the avoidance area (or the raw grid).
    """
    if not isinstance(grid, OccupancyGrid):
        raise InvalidInputError(f"grid must be an astar.OccupancyGrid, got {type(grid).__name__}")
    s_xy, g_xy = _xy(start, "start"), _xy(goal, "goal")
    try:
        radius = float(robot_radius)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(f"robot_radius must be a number, got {robot_radius!r}") from exc
    if not (math.isfinite(radius) and radius > 0):
        raise InvalidInputError(f"robot_radius must be finite and > 0 m, got {radius!r}")
    if w_cells is None:
        w = int(math.ceil(2.0 * radius / grid.resolution - 1e-9))
    elif isinstance(w_cells, bool) or not isinstance(w_cells, (int, np.integer)) or w_cells < 0:
        raise InvalidInputError(f"w_cells must be an integer >= 0 or None, got {w_cells!r}")
    else:
        w = int(w_cells)
    s_cell = tuple(int(v) for v in grid.world_to_cell(s_xy))
    g_cell = tuple(int(v) for v in grid.world_to_cell(g_xy))
    for name, cell, xy in (("start", s_cell, s_xy), ("goal", g_cell, g_xy)):
        if not grid.in_bounds(cell):
            raise InvalidInputError(f"{name} {xy} m is outside the map (cell {cell})")
    opts: dict[str, Mapping[str, Any]] = {k: dict(v) for k, v in dict(options or {}).items()}
    if poly is not None:
        opts["polynomial fit"] = {**opts.get("polynomial fit", {}), **dict(poly)}
        opts.setdefault("polynomial fit (parametric)", dict(opts["polynomial fit"]))
    if bspline is not None:
        opts["B-spline fit"] = {**opts.get("B-spline fit", {}), **dict(bspline)}
    runs = _resolve_methods(methods)

    timings: dict[str, float] = {}
    # direct imports: the package attribute ``astar.inflation`` can be the submodule
    from astar.inflation import avoidance_area, inflate

    t0 = time.perf_counter()
    avoid = avoidance_area(grid, w, border=border_occupied)
    inflated = inflate(grid, radius, metric="square", outside_occupied=border_occupied)
    timings["grids"] = time.perf_counter() - t0
    for name, cell, xy in (("start", s_cell, s_xy), ("goal", g_cell, g_xy)):
        if not avoid.is_free(cell):
            raise InvalidInputError(
                f"{name} {xy} m (cell {cell}) is blocked in the avoidance area (W = {w} "
                "cells): it is too close to an obstacle or the border"
            )
    t0 = time.perf_counter()
    path_raw = _search(grid, s_cell, g_cell, "raw grid")
    timings["astar_raw"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    path_avoid = _search(avoid, s_cell, g_cell, f"avoidance area (W = {w})")
    timings["astar_avoid"] = time.perf_counter() - t0
    ctx = ComparisonContext(
        grid=grid,
        start=s_xy,
        goal=g_xy,
        start_cell=s_cell,  # type: ignore[arg-type]
        goal_cell=g_cell,  # type: ignore[arg-type]
        robot_radius=radius,
        w_cells=w,
        border_occupied=bool(border_occupied),
        avoidance=avoid,
        inflated=inflated,
        path_raw=path_raw,
        path_avoid=path_avoid,
        reference=grid.cell_to_world(path_avoid.cells),
        options=opts,
        timings=timings,
    )

    rows, paths = [], {}
    for name, fn in runs:
        t0 = time.perf_counter()
        try:
            out = fn(ctx)
        except _SOFT_ERRORS as exc:
            logger.warning("compare: method %r failed: %s", name, exc)
            out = MethodResult(None, False, f"{type(exc).__name__}: {exc}")
        elapsed = time.perf_counter() - t0
        if not isinstance(out, MethodResult):
            out = MethodResult(out)
        runtime = out.runtime_s if out.runtime_s is not None else elapsed
        if out.path is None:
            metrics = PathMetrics.nan(sample_spacing)
        else:
            metrics = path_metrics(
                out.path,
                grid=grid,
                reference=ctx.reference,
                radius=radius,
                sample_spacing=sample_spacing,
                border_occupied=border_occupied,
            )
        paths[name] = out.path
        rows.append(
            {
                "method": name,
                "valid": bool(out.valid),
                **metrics.as_dict(),
                "fit_mse_m2": math.nan,
                **dict(out.extras),
                "runtime_s": float(runtime),
                "note": out.note,
            }
        )
    meta = {
        "start": s_xy,
        "goal": g_xy,
        "start_cell": s_cell,
        "goal_cell": g_cell,
        "robot_radius": radius,
        "w_cells": w,
        "border_occupied": bool(border_occupied),
        "sample_spacing_m": float(sample_spacing),
        "options": opts,
        "reference": "A* + avoidance area (cell centres)",
    }
    return ComparisonTable(rows=tuple(rows), meta=meta, paths=paths)
