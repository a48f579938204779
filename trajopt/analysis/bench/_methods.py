"""The benchmark's methods and how one query becomes one row per method.

Every method gets the same :class:`QueryContext` (the raw map, the robot radius, the
inflated grid and the *reference*: the octile-shortest A* path on the inflated grid, cell
centres in metres) and returns a :class:`MethodOutput`. :func:`evaluate_query` then scores
every output with the same independent metrics, :func:`trajopt.metrics.path_metrics`
against the raw map (cells outside the map occupied) and the reference, so a method's
collision is a value in its row, never a crash. Expected planning failures (the typed
errors of :mod:`trajopt` and :mod:`astar`, and a peer finding no solution) are rows too:
``ok = False`` and ``failure`` the error's type.

Methods (:data:`METHODS`):

* ``trajopt``: :class:`trajopt.Planner` with its defaults (clearance-aware search, polygon
  corridor, ruckig timing);
* ``trajopt-shortest``: ``search="shortest"``;
* ``trajopt-kappa``: curvature-bounded, ``Smoother(kappa_max=1 / (2 radius))``;
* ``trajopt-fallback``: ``fallback="stop_and_turn"`` (``fallback_used`` says when it
  served);
* ``trajopt-ackermann``, ``trajopt-ackermann-forward`` (family ``"car"``, not in
  :data:`DEFAULT_METHODS`): a car-like robot, ``Robot(radius, drive="ackermann",
  min_turning_radius=CAR_RADIUS_FACTOR * radius, reverse=True / False)``, planned pose to
  pose with the query's end headings (:attr:`QueryContext.start_heading`); scored by the
  car metrics of :mod:`~trajopt.analysis.bench._car` too (cusps, reverse length, curvature
  against ``1/R`` per stretch between cusps, motion along the heading, end headings, rest at
  cusps), and ``rests``, the stops between cusps (``stats["car"]["rests"]``);
* ``astar``: the reference polyline itself;
* ``bspline-fit``, ``polynomial-fit``: the chapter's plain fits of the reference, as
  :func:`trajopt.compare` runs them (``"B-spline fit"``, ``"polynomial fit"``);
* peers (optional, :mod:`trajopt.analysis.bench._peers`): ``ompl-rrtstar``, ``ompl-bitstar``,
  ``pmp-bspline``, ``pmp-cubic``; and the car peers ``ompl-reedsshepp``, ``ompl-dubins``
  (family ``"car-peer"``).

A worker process keeps the context of the last maps it saw (:func:`map_context`), so a
chunk of queries on one map loads and inflates the map once; :func:`warm_up` pays a
process's one-time costs (imports, numba kernel loads, solver plugins) before a run's clock
starts.
"""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from trajopt.analysis.bench._records import MethodOutput, PeerFailure
from trajopt.errors import BenchmarkError

#: Stage names of :class:`trajopt.Planner` copied into ``stage_<name>_s`` columns.
STAGES = ("inflate", "search", "corridor", "smooth", "timing", "fallback", "total")
#: Timed-trajectory columns (from :func:`trajopt.metrics.trajectory_metrics`).
TIMED = ("duration_s", "ratio_v", "ratio_a", "ratio_jerk", "ratio_omega", "ratio_a_lat")
#: Minimum turning radius of the car methods, as a multiple of the robot radius (issue 36:
#: ``R = 2 x radius``).
CAR_RADIUS_FACTOR = 2.0
#: Families of the methods that plan poses of a car-like robot.
CAR_FAMILIES = ("car", "car-peer")


@dataclass
class MapContext:
    """Per-map state a worker builds once: the map, the inflated grid, the planners.

    Attributes
    ----------
    grid : astar.OccupancyGrid
        The raw map.
    radius : float
        Robot radius (m).
    inflated : astar.OccupancyGrid
        ``astar.inflate(grid, radius, metric="square", outside_occupied=True)``.
    planners : dict
        :class:`trajopt.Planner` per trajopt variant, built on first use.
    """

    grid: Any
    radius: float
    inflated: Any
    planners: dict[str, Any] = field(default_factory=dict)

    @property
    def turning_radius(self) -> float:
        """Minimum turning radius of the car methods: ``CAR_RADIUS_FACTOR * radius`` (m)."""
        return CAR_RADIUS_FACTOR * self.radius

    @property
    def sample_spacing(self) -> float:
        """Arc-length spacing of the metric samples: 0.05 cell (m)."""
        return 0.05 * float(self.grid.resolution)

    def planner(self, variant: str) -> Any:
        """Return the planner of a trajopt variant (built once per map)."""
        if variant not in self.planners:
            from trajopt import Planner
            from trajopt.robot import Robot
            from trajopt.smoother import Smoother

            if variant.startswith("trajopt-ackermann"):
                car = Robot(
                    radius=self.radius,
                    drive="ackermann",
                    min_turning_radius=self.turning_radius,
                    reverse=variant == "trajopt-ackermann",
                )
                self.planners[variant] = Planner(self.grid, car)
                return self.planners[variant]
            robot = Robot(radius=self.radius)
            kwargs: dict[str, Any] = {
                "trajopt": {},
                "trajopt-shortest": {"search": "shortest"},
                "trajopt-kappa": {"smoother": Smoother(kappa_max=1.0 / (2.0 * self.radius))},
                "trajopt-fallback": {"fallback": "stop_and_turn"},
            }[variant]
            self.planners[variant] = Planner(self.grid, robot, **kwargs)
        return self.planners[variant]


@functools.lru_cache(maxsize=4)
def map_context(map_path: str, radius: float) -> MapContext:
    """Load and inflate a map once per process (the last 4 maps are kept)."""
    import astar

    grid = astar.load_map(map_path)
    inflated = astar.inflate(grid, radius, metric="square", outside_occupied=True)
    return MapContext(grid, float(radius), inflated)


@dataclass(frozen=True, slots=True)
class QueryContext:
    """One query as every method sees it.

    Attributes
    ----------
    map : MapContext
    start_cell, goal_cell : tuple of int
        Cells ``(ix, iy)``.
    start, goal : ndarray, shape (2,)
        Their centres (m).
    reference_path : astar.GridPath
        Octile-shortest A* on ``map.inflated``.
    reference : ndarray, shape (n, 2)
        Its cell centres (m).
    start_heading, goal_heading : float
        End headings (rad) for the car methods (NaN: none given; the car methods then
        draw them with :func:`~trajopt.analysis.bench._suites.draw_headings`).
    """

    map: MapContext
    start_cell: tuple[int, int]
    goal_cell: tuple[int, int]
    start: np.ndarray
    goal: np.ndarray
    reference_path: Any
    reference: np.ndarray
    start_heading: float = math.nan
    goal_heading: float = math.nan

    @property
    def headings(self) -> tuple[float, float]:
        """``(start_heading, goal_heading)`` (rad); both must be finite for the car methods.

        Raises
        ------
        BenchmarkError
            A heading is NaN or infinite.
        """
        h = (float(self.start_heading), float(self.goal_heading))
        if not all(math.isfinite(v) for v in h):
            raise BenchmarkError(
                f"a car method needs finite start and goal headings (rad), got {h}: give the "
                "queries headings (bench.with_headings) or pass headings to evaluate_query"
            )
        return h

    def comparison_context(self) -> Any:
        """Return the context of one query for the plain fits.

        A :class:`trajopt.comparison.ComparisonContext` whose avoidance area is the inflated
        grid and whose reference is this query's reference (for the plain fits).
        """
        from trajopt.analysis.comparison import ComparisonContext

        m = self.map
        return ComparisonContext(
            grid=m.grid,
            start=tuple(float(v) for v in self.start),  # type: ignore[arg-type]
            goal=tuple(float(v) for v in self.goal),  # type: ignore[arg-type]
            start_cell=self.start_cell,
            goal_cell=self.goal_cell,
            robot_radius=m.radius,
            w_cells=0,
            border_occupied=True,
            avoidance=m.inflated,
            inflated=m.inflated,
            path_raw=self.reference_path,
            path_avoid=self.reference_path,
            reference=self.reference,
        )


MethodFn = Callable[[QueryContext], MethodOutput]


@dataclass(frozen=True, slots=True)
class MethodSpec:
    """A registered benchmark method.

    Attributes
    ----------
    name : str
    family : {"trajopt", "fit", "peer"}
    fn : callable
        ``fn(QueryContext) -> MethodOutput``.
    requires : tuple of str
        Modules that must import (peers); checked before a run starts.
    """

    name: str
    family: str
    fn: MethodFn
    requires: tuple[str, ...] = ()


# ================================================================== trajopt variants
def _trajopt(variant: str) -> MethodFn:
    def run(q: QueryContext) -> MethodOutput:
        from trajopt.analysis.metrics import trajectory_metrics

        planner = q.map.planner(variant)
        t0 = time.perf_counter()
        traj = planner.plan(q.start, q.goal)
        runtime = time.perf_counter() - t0
        stats = traj.stats
        stages = stats.get("stages_s", {})
        t1 = time.perf_counter()
        timed = trajectory_metrics(traj, planner.robot)
        score = time.perf_counter() - t1
        extras: dict[str, Any] = {k: float(timed[k]) for k in TIMED if k in timed}
        extras.update({f"stage_{k}_s": float(stages[k]) for k in STAGES if k in stages})
        extras["fallback_used"] = bool(stats.get("fallback"))
        extras["corridor"] = str(stats.get("corridor", ""))
        note = ""
        if stats.get("fallback"):
            note = f"fallback after {stats.get('fallback_error')}: {stats.get('fallback_reason')}"
        return MethodOutput(traj.path, True, note, extras, runtime, score)

    return run


def _car(variant: str) -> MethodFn:
    def run(q: QueryContext) -> MethodOutput:
        from trajopt.analysis.bench._car import chain_metrics
        from trajopt.analysis.metrics import trajectory_metrics

        h0, h1 = q.headings
        planner = q.map.planner(variant)
        t0 = time.perf_counter()
        traj = planner.plan(q.start, q.goal, start_heading=h0, goal_heading=h1)
        runtime = time.perf_counter() - t0
        stats = traj.stats
        stages = stats.get("stages_s", {})
        search = stats.get("car", {}).get("search", {})
        t1 = time.perf_counter()
        kmax = 1.0 / planner.robot.drive.min_turning_radius
        poly, extras = chain_metrics(traj, kmax, (h0, h1), q.map.sample_spacing)
        timed = trajectory_metrics(traj, planner.robot)
        score = time.perf_counter() - t1
        extras.update({k: float(timed[k]) for k in TIMED if k in timed})
        extras["duration_s"] = float(traj.duration)
        extras.update({f"stage_{k}_s": float(stages[k]) for k in STAGES if k in stages})
        extras["hybrid_search_s"] = float(search.get("search_s", math.nan))
        extras["hybrid_heuristic_s"] = float(search.get("heuristic_s", math.nan))
        extras["corridor"] = ",".join(stats.get("car", {}).get("corridors", []))
        extras["rests"] = int(stats.get("car", {}).get("rests", -1))
        return MethodOutput(poly, True, f"{len(traj.pieces)} segment(s)", extras, runtime, score)

    return run


# ======================================================================== baselines
def _astar(q: QueryContext) -> MethodOutput:
    return MethodOutput(q.reference, True, "reference polyline", runtime_s=0.0)


def _compare_method(name: str) -> MethodFn:
    def run(q: QueryContext) -> MethodOutput:
        from trajopt.analysis.comparison import MethodResult, resolve_method

        fn = resolve_method(name)
        t0 = time.perf_counter()
        out = fn(q.comparison_context())
        runtime = time.perf_counter() - t0
        if not isinstance(out, MethodResult):
            out = MethodResult(out)
        extras = {k: v for k, v in dict(out.extras).items() if k == "fit_mse_m2"}
        rt = out.runtime_s if out.runtime_s is not None else runtime
        return MethodOutput(out.path, bool(out.valid), out.note, extras, rt)

    return run


def _peer(name: str) -> MethodFn:
    def run(q: QueryContext) -> MethodOutput:
        from trajopt.analysis.bench._peers import run as run_peer

        return run_peer(name, q, METHODS[name].requires)

    return run


METHODS: dict[str, MethodSpec] = {
    s.name: s
    for s in (
        MethodSpec("trajopt", "trajopt", _trajopt("trajopt")),
        MethodSpec("trajopt-shortest", "trajopt", _trajopt("trajopt-shortest")),
        MethodSpec("trajopt-kappa", "trajopt", _trajopt("trajopt-kappa")),
        MethodSpec("trajopt-fallback", "trajopt", _trajopt("trajopt-fallback")),
        MethodSpec("astar", "fit", _astar),
        MethodSpec("bspline-fit", "fit", _compare_method("B-spline fit")),
        MethodSpec("polynomial-fit", "fit", _compare_method("polynomial fit")),
        MethodSpec("ompl-rrtstar", "peer", _peer("ompl-rrtstar"), ("ompl",)),
        MethodSpec("ompl-bitstar", "peer", _peer("ompl-bitstar"), ("ompl",)),
        MethodSpec("pmp-bspline", "peer", _peer("pmp-bspline"), ("python_motion_planning",)),
        MethodSpec("pmp-cubic", "peer", _peer("pmp-cubic"), ("python_motion_planning",)),
        MethodSpec("trajopt-ackermann", "car", _car("trajopt-ackermann")),
        MethodSpec("trajopt-ackermann-forward", "car", _car("trajopt-ackermann-forward")),
        MethodSpec("ompl-reedsshepp", "car-peer", _peer("ompl-reedsshepp"), ("ompl",)),
        MethodSpec("ompl-dubins", "car-peer", _peer("ompl-dubins"), ("ompl",)),
    )
}
#: What runs when no methods are given: every method that needs no optional package, but
#: the car methods (they plan poses: ``methods=[..., "trajopt-ackermann"]`` names them).
DEFAULT_METHODS: tuple[str, ...] = tuple(
    n for n, s in METHODS.items() if s.family not in ("peer", *CAR_FAMILIES)
)


def check_methods(methods: object) -> tuple[str, ...]:
    """Validate a list of method names (and that the peers among them can import).

    Raises
    ------
    BenchmarkError
        An empty list, an unknown or repeated name.
    PeerUnavailableError
        A peer whose package is not installed.
    """
    if isinstance(methods, str):
        methods = [m for m in methods.split(",") if m]
    names = tuple(methods)  # type: ignore[arg-type]
    if not names:
        raise BenchmarkError("methods must name at least one method")
    for m in names:
        if m not in METHODS:
            raise BenchmarkError(f"method {m!r} is unknown; known methods: {list(METHODS)}")
    if len(set(names)) != len(names):
        raise BenchmarkError(f"methods must not repeat a name, got {list(names)}")
    from trajopt.analysis.bench._peers import require

    for m in names:
        for mod in METHODS[m].requires:
            require(mod, m)
    return names


# ======================================================================== evaluation
_SOFT: tuple[type[BaseException], ...] | None = None


def _soft_errors() -> tuple[type[BaseException], ...]:
    global _SOFT
    if _SOFT is None:
        import astar
        from trajopt.errors import TrajoptError

        _SOFT = (TrajoptError, astar.AstarError, PeerFailure)
    return _SOFT


def _nan_metrics(spacing: float) -> dict[str, Any]:
    from trajopt.analysis.metrics import PathMetrics

    return PathMetrics.nan(spacing).as_dict()


def evaluate_query(
    mctx: MapContext,
    start: tuple[int, int],
    goal: tuple[int, int],
    methods: tuple[str, ...],
    *,
    headings: tuple[float, float] | None = None,
) -> list[dict[str, Any]]:
    """Run ``methods`` on one query and score them: one dict per method, in order.

    Each dict holds ``method``, ``ok``, ``valid``, ``failure`` (the error type, ``""``
    when ok), ``note``, every :class:`trajopt.metrics.PathMetrics` field, ``runtime_s``,
    ``reference_search_s``, ``score_s`` (the time spent scoring this method's output:
    :func:`~trajopt.metrics.path_metrics` and, for the trajopt variants,
    :func:`~trajopt.metrics.trajectory_metrics`) and what the method adds
    (``duration_s``, ``stage_*_s``, ...).
    When the reference search fails (an end point blocked for the radius, or no path),
    every method gets that failure: the query is infeasible for the robot.

    ``headings`` (rad) are the start and goal headings the car methods plan with (default:
    none; a car method then fails with :class:`~trajopt.errors.BenchmarkError`). The car
    methods' rows add ``start_heading_rad``, ``goal_heading_rad``, ``turning_radius_m`` and
    the car columns of :mod:`~trajopt.analysis.bench._car`; their per-stretch curvature
    columns replace those of the joined polyline (a cusp is no curvature).
    """
    import astar
    from trajopt.analysis.metrics import path_metrics

    soft = _soft_errors()
    spacing = mctx.sample_spacing
    t0 = time.perf_counter()
    ref_error: BaseException | None = None
    qctx = None
    try:
        for nm, c in (("start", start), ("goal", goal)):
            if not mctx.inflated.is_free(c):
                raise astar.InvalidInputError(
                    f"{nm} cell {tuple(c)} is blocked on the grid inflated by the radius "
                    f"{mctx.radius} m"
                )
        ref_path = astar.find_path(mctx.inflated, tuple(start), tuple(goal))
        ref = mctx.grid.cell_to_world(np.asarray(ref_path.cells))
        qctx = QueryContext(
            mctx,
            tuple(start),
            tuple(goal),
            mctx.grid.cell_to_world(start),  # type: ignore[arg-type]
            mctx.grid.cell_to_world(goal),
            ref_path,
            np.asarray(ref, dtype=float),
            *((math.nan, math.nan) if headings is None else (float(v) for v in headings)),
        )
    except soft as exc:
        ref_error = exc
    ref_s = time.perf_counter() - t0
    rows: list[dict[str, Any]] = []
    for name in methods:
        row: dict[str, Any] = {"method": name, "reference_search_s": ref_s}
        if METHODS[name].family in CAR_FAMILIES:
            row["turning_radius_m"] = mctx.turning_radius
            if headings is not None:
                row["start_heading_rad"], row["goal_heading_rad"] = (float(v) for v in headings)
        if qctx is None:
            row.update(
                ok=False,
                valid=False,
                failure=type(ref_error).__name__,
                note=f"reference A*: {ref_error}",
                runtime_s=math.nan,
                **_nan_metrics(spacing),
            )
            rows.append(row)
            continue
        t1 = time.perf_counter()
        try:
            out = METHODS[name].fn(qctx)
        except soft as exc:
            row.update(
                ok=False,
                valid=False,
                failure=type(exc).__name__,
                note=str(exc),
                runtime_s=time.perf_counter() - t1,
                **_nan_metrics(spacing),
            )
            stats = getattr(exc, "stats", None)
            if isinstance(stats, dict) and isinstance(stats.get("stages_s"), dict):
                row.update(
                    {f"stage_{k}_s": float(v) for k, v in stats["stages_s"].items() if k in STAGES}
                )
            rows.append(row)
            continue
        runtime = out.runtime_s if out.runtime_s is not None else time.perf_counter() - t1
        t2 = time.perf_counter()
        if out.path is None:
            metrics = _nan_metrics(spacing)
        else:
            metrics = path_metrics(
                out.path,
                grid=mctx.grid,
                reference=qctx.reference,
                radius=mctx.radius,
                sample_spacing=spacing,
                border_occupied=True,
            ).as_dict()
        score = float(out.score_s) + (time.perf_counter() - t2)
        ok = bool(out.valid and out.path is not None)
        row.update(
            ok=ok,
            valid=bool(out.valid),
            failure="" if ok else "InvalidResult",
            note=out.note,
            runtime_s=float(runtime),
            score_s=score,
        )
        row.update(metrics)
        row.update(dict(out.extras))  # a method's own columns replace the generic ones
        rows.append(row)
    return rows


def warm_up(methods: object = None) -> float:
    """Pay a process's one-time costs: plan and score one small query with every method.

    The first query of a fresh process spends most of its time on costs no later query
    pays (imports of numba, SciPy and CasADi, numba kernels loaded from the disk cache,
    CasADi's solver plugins, the metrics' SciPy modules:
    ``python benchmarks/bench_first_call.py``). This runs :func:`evaluate_query` with every
    method but the peers on the small built-in map of :func:`trajopt.analysis.scenes.warm_up_map`
    (a wall with a gap), so those costs are paid here; the peers' modules are imported
    only (a peer run takes its whole time budget). :func:`trajopt.bench.run` calls it on
    every worker before its clock starts.

    What it cannot pay ahead: loading and inflating the benchmark's own maps, and the
    solver builds of problem sizes first met on them (the curvature-bounded smoother
    builds an IPOPT problem per new size).

    Parameters
    ----------
    methods : sequence of str or comma-separated str, optional
        Default :data:`DEFAULT_METHODS`.

    Returns
    -------
    float
        Wall time (s).
    """
    t0 = time.perf_counter()
    import importlib

    import astar
    from trajopt import Planner
    from trajopt.analysis.scenes import warm_up_map

    names = check_methods(DEFAULT_METHODS if methods is None else methods)
    planner = Planner(astar.OccupancyGrid(np.zeros((2, 2), dtype=bool), 1.0))
    grid, start, goal = warm_up_map(planner)
    radius = float(planner.robot.radius)
    inflated = astar.inflate(grid, radius, metric="square", outside_occupied=True)
    mctx = MapContext(grid, radius, inflated)
    cells = [tuple(int(v) for v in grid.world_to_cell(p)) for p in (start, goal)]
    local = tuple(m for m in names if METHODS[m].family != "peer")
    if local:
        evaluate_query(mctx, cells[0], cells[1], local, headings=(0.0, 0.0))  # type: ignore[arg-type]
    for m in names:
        for mod in METHODS[m].requires:
            importlib.import_module(mod)
    return time.perf_counter() - t0
