"""Warm-up: compile the kernels once per environment, pay a process's start costs once.

Two one-time costs stand before a fast plan:

* **Once per environment** (fresh clone, venv, container, CI runner): numba compiles the
  compiled kernels of astar and trajopt into its disk cache, about 50 s of CPU.
  :func:`warm_up` first compiles every kernel that is not cached yet, by running the
  :data:`EXERCISES` (small searches, plans, timings, a fallback and a comparison that between
  them call every kernel with the argument types the library uses) in two worker processes
  (:func:`compile_kernels`, which hands the exercises to
  :func:`trajopt.kernel_cache.run_exercises`; each worker is this module run as
  ``python -m trajopt.warmup --worker``, serving :data:`EXERCISES`). ``trajopt warm-up``
  does the same from a shell, e.g. in a container build or a CI cache step.
* **Once per process**: importing numba, SciPy and CasADi, initialising numba's compiler
  context, loading each compiled kernel from numba's disk cache and loading the CasADi
  solver plugins (``python benchmarks/bench_first_call.py`` prints the split). A robot
  program that calls :func:`warm_up` at start-up, before its first goal arrives, pays them
  there; the first real plan then costs about what a warm one does.

With a planner, the warm-up then plans one query on a small built-in map (a wall with a
gap, so the search, the corridor, the smoother and the timing all run) with the planner's
own settings: its robot (or footprint), search mode, corridor kind, smoother options, timing
step and fallback, so the kernels loaded are the ones its queries use. The map and its
resolution are scaled to the robot, so the warm-up takes the same short time for any
robot size. Two paths stay unloaded: the stop-and-turn fallback, which only a failed
smoother or timing runs, may load kernels of its own the first time it is used; and
speed-limit zones are not copied (their lookup is plain NumPy). Without a planner, every
kernel of the library is loaded (:func:`trajopt.kernel_cache.load_kernels`) and the
default planner plans the query.
"""

from __future__ import annotations

import contextlib
import logging
import math
import sys
import time
from collections.abc import Callable, Sequence

import numpy as np

import trajopt.kernel_cache as kernel_cache
from astar.costmap import from_costmap
from astar.grid import OccupancyGrid
from trajopt._planner import Planner
from trajopt.analysis.scenes import WARM_UP_CELLS, warm_up_map
from trajopt.errors import InvalidInputError
from trajopt.kernel_cache import CompileReport, Exercise

_log = logging.getLogger(__name__)


def warm_up(planner: Planner | None = None) -> float:
    """Compile what is not compiled yet, then load what a plan needs, before the first query.

    Parameters
    ----------
    planner : Planner, optional
        The planner whose settings the warm-up copies (robot, search mode, corridor,
        smoother, timing step, fallback); its map and caches are not touched. Default: every
        kernel of the library is loaded and a planner with :func:`~trajopt.plan`'s defaults
        plans the warm-up query.

    Returns
    -------
    float
        Wall time the warm-up took (s).

    Raises
    ------
    InvalidInputError
        ``planner`` is not a :class:`Planner`.
    TrajoptError
        The warm-up query failed (it should not: the map is built for the robot; the
        error says which stage).

    Notes
    -----
    The compilation runs only when some kernel has nothing in numba's disk cache
    (:func:`trajopt.kernel_cache.cold_kernels`), in two worker processes
    (:func:`compile_kernels`); an exercise that fails there is logged and its kernels compile
    on first use instead.
    """
    t0 = time.perf_counter()
    if planner is not None and not isinstance(planner, Planner):
        raise InvalidInputError(f"planner must be a trajopt.Planner, got {type(planner).__name__}")
    report = compile_kernels()
    for name, error in report.failed.items():
        _log.warning(
            "warm_up: exercise %r failed (its kernels compile on first use): %s", name, error
        )
    if planner is None:
        for name, exercise in EXERCISES.items():
            if name not in report.failed:
                exercise.run()  # loads the kernels with the library's own calls
        kernel_cache.load_kernels()  # and the ones only other kernels call
        planner = _default_planner()
    _plan_like(planner)
    return time.perf_counter() - t0


def _default_planner() -> Planner:
    return Planner(OccupancyGrid(np.zeros((2, 2), dtype=bool), 1.0))


def _plan_like(planner: Planner) -> None:
    """Plan the warm-up query of ``planner`` with a copy of it (its caches stay as they are)."""
    grid, start, goal = warm_up_map(planner)
    search_map: OccupancyGrid | object = grid
    if planner.costmap is not None:
        values = np.zeros(grid.occupied.shape, dtype=np.uint8)
        values[:, : WARM_UP_CELLS // 4] = 100  # a graded band for the costmap's cost term
        values[grid.occupied] = 254  # lethal
        search_map = from_costmap(values, grid.resolution, grid.origin, convention="costmap_2d")
    copy = Planner(
        search_map,
        planner.robot,
        inflation=planner.inflation,
        search=planner.search,
        smoother=planner.smoother,
        timing_dt=planner.timing_dt,
        fallback=planner.fallback,
        corridor=planner.corridor,
        costmap_weight=planner.costmap_weight,
        landmarks=planner.landmarks,
    )
    copy.plan(start, goal)


# ------------------------------------------------------------------------------ exercises
def _default_query() -> tuple[Planner, tuple[float, float], tuple[float, float]]:
    grid, start, goal = warm_up_map(_default_planner())
    return Planner(grid), start, goal


def _around_the_wall(planner: Planner, start, goal) -> np.ndarray:
    """Return a polyline (m) from ``start`` over the warm-up map's wall to ``goal``."""
    side = planner.grid.occupied.shape[1] * planner.grid.resolution
    return np.array([start, [start[0], 0.85 * side], [goal[0], 0.85 * side], goal])


def _exercise_timing() -> None:
    """Time a cubic B-spline (an S-bend) from rest and between moving states; evaluate poses (at times, at arc lengths)."""
    from trajopt.geometry import BSplineCurve, clamped_uniform_knots
    from trajopt.robot import Robot
    from trajopt.timing import time_parameterize

    pts = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 1.0], [3.0, 1.0], [4.0, 0.0], [5.0, 0.0]])
    curve = BSplineCurve(clamped_uniform_knots(len(pts), 3, (0.0, 6.0)), pts, 3)
    robot = Robot()
    traj = time_parameterize(curve, robot)
    time_parameterize(curve, robot, v_start=0.05, v_end=0.05)
    traj.pose(np.linspace(0.0, traj.duration, 5))  # the arc-length inversion (arc_newton)
    # the poses at arc lengths in one call (arc_pose: the certificate's robot on a B-spline)
    curve.pose_at_s(
        traj.motion(np.linspace(0.0, traj.duration, 5))[0], traj.theta_grid_s, traj.u_grid
    )


def _exercise_moving() -> None:
    """Re-time a straight drive around two crossing movers (a stop on the way: the (s, t) search), a crossing cart and a parked one (blocked, and proved so); mark a swept region.

    The certificates of these re-timings reach the path bounds' look-ups (trajopt.moving._path_bounds),
    their tightened launches a drive's arc lengths at its times (trajopt.moving._st_search),
    the search's stops their forbidden and resting times (trajopt.moving._node_times), the
    grids their runs grouped and merged per node (trajopt.moving._grid_runs).
    """
    from trajopt.errors import BlockedError
    from trajopt.geometry import PolylineCurve
    from trajopt.moving import (
        MovingObstacle,
        certify_movers,
        no_way_past,
        reached_swept_mask,
        retime_for_movers,
        swept_mask,
    )
    from trajopt.robot import Footprint, Robot
    from trajopt.timing import time_parameterize

    robot = Robot(v_max=0.6, a_max=0.6, j_max=2.0)
    line = time_parameterize(PolylineCurve(np.array([[0.0, 0.0], [6.0, 0.0]])), robot)
    movers = [
        MovingObstacle.constant_velocity((4.5, -3.0), (0.0, 0.35), radius=0.3, horizon=24.0),
        MovingObstacle.constant_velocity((0.0, -1.5), (0.0, 0.5), radius=0.3, horizon=24.0),
    ]
    retime_for_movers(line, movers)
    # a cart crossing the drive: the polygon movers' grid (trajopt.moving._polygon_march)
    box = [(-0.4, -0.25), (0.4, -0.25), (0.4, 0.25), (-0.4, 0.25)]
    cart = MovingObstacle.constant_velocity(
        (3.0, -3.0), (0.0, 0.4), radius=0.05, horizon=24.0, vertices=box
    )
    retime_for_movers(line, [cart])
    # a robot with a footprint against it: the footprint's bounds (point to polygon,
    # trajopt.moving._polygon_distance; a disc robot's are trajopt.moving._bisection_bounds)
    body = Footprint(vertices=[(-0.3, -0.2), (0.3, -0.2), (0.3, 0.2), (-0.3, 0.2)])
    boxed = Robot(v_max=0.6, a_max=0.6, j_max=2.0, footprint=body)
    certify_movers(time_parameterize(line.path, boxed), [cart])
    # a cart parked on the drive: no re-timing gets past (the grid's sweep, trajopt.moving._grid_kernels)
    parked = MovingObstacle.from_waypoints([0.0], [(3.0, 0.0)], radius=0.05, vertices=box)
    with contextlib.suppress(BlockedError):
        retime_for_movers(line, [parked])
    # the quick proof that no re-timing gets past (its sweep, trajopt.moving._reach_kernel)
    no_way_past(line, [parked])
    # a mover's swept region on a grid, and where a robot could meet it (a re-route's marks,
    # trajopt.moving._swept_kernel)
    room = OccupancyGrid(np.zeros((40, 60), dtype=bool), 0.1, (0.0, -2.0))
    swept_mask(room, movers[0], 0.0, 4.0, 0.1)
    reached_swept_mask(room, movers[0], 0.0, 24.0, 0.1, np.zeros(2), 0.6, 0.2)


def _exercise_polygons() -> None:
    """Grow a polygon corridor along a polyline; intersect two of its polygons."""
    from trajopt.corridor import build_polygon_corridor

    planner, start, goal = _default_query()
    corridor = build_polygon_corridor(
        planner.grid, _around_the_wall(planner, start, goal), planner.robot.radius
    )
    if len(corridor.regions) > 1:
        corridor.regions[0].intersection(corridor.regions[1], tol=1e-9)


def _search_query() -> tuple[OccupancyGrid, tuple[int, int], tuple[int, int]]:
    grid, start, goal = warm_up_map(_default_planner())
    a, b = grid.world_to_cell(start), grid.world_to_cell(goal)
    return grid, (int(a[0]), int(a[1])), (int(b[0]), int(b[1]))


def _exercise_search() -> None:
    """Search without a cost (jump points), with a cost, with ALT landmarks, coarse-to-fine."""
    import astar

    grid, a, b = _search_query()
    astar.find_path(grid, a, b)
    cost = np.ones(grid.shape)
    astar.find_path(grid, a, b, cost=cost)
    astar.find_path(grid, a, b, landmarks=astar.build_landmarks(grid, cost, 2))
    cost.flags.writeable = False  # as the planner's search cost
    for c in (cost, None):  # the coarse-to-fine search, with and without a cost
        coarse = astar.build_coarse_grid(grid, 2, c)
        astar.find_path_coarse_to_fine(coarse.update(grid, c, (0, 1, 0, 1)), a, b)


def _exercise_astar() -> None:
    """Search 4-connected and cutting corners (plain A*, not jump points)."""
    import astar

    grid, a, b = _search_query()
    astar.find_path(grid, a, b, connectivity=4)
    astar.find_path(grid, a, b, corner_cutting=True)


def _exercise_grid() -> None:
    """Inflate (both metrics), the avoidance area, clearance fields and the clearance cost."""
    import astar

    grid, _, _ = warm_up_map(_default_planner())
    r = 2.0 * grid.resolution
    astar.inflate(grid, r)
    astar.inflate(grid, r, metric="square", outside_occupied=True)
    astar.avoidance_area(grid, 2, border=True)
    astar.clearance(grid)
    astar.clearance(grid, metric="square", outside_occupied=True)
    astar.clearance_cost(grid, r, outside_occupied=True)


def _exercise_fallback() -> None:
    """Run the stop-and-turn fallback's checks and the curvature witness (their own kernels)."""
    from trajopt.geometry import polyline_clearance
    from trajopt.planning import curvature_witness
    from trajopt.timing import stop_and_turn

    planner, start, goal = _default_query()
    points = _around_the_wall(planner, start, goal)
    r = planner.robot.radius
    polyline_clearance(points, planner.grid, window_m=2.0 * r, outside_occupied=True)
    stop_and_turn(points, planner.robot)
    curvature_witness(
        planner.grid, r, np.asarray(start), np.asarray(goal), 1.0 / (2.0 * r), time_limit_s=5.0
    )


def _exercise_plan() -> None:
    """Plan with the defaults: clearance cost, search, polygon corridor, smoother, timing.

    Its check that the ends are joined labels the components (trajopt.planning._label_kernel).
    """
    planner, start, goal = _default_query()
    planner.plan(start, goal)


def _exercise_footprint() -> None:
    """Plan for a rectangular robot (the footprint certificate and its rounds, on cells and on polygons)."""
    from trajopt.robot import Robot, certify_footprint

    r = _default_planner().robot.radius
    robot = Robot.rectangle(2.2 * r, 1.4 * r)
    _plan_like(Planner(_default_planner().grid, robot))
    # the certificate against the polygons of a map made from them
    grid, start, goal = warm_up_map(Planner(_default_planner().grid, robot))
    traj = Planner(grid, robot).plan(start, goal)
    x0, y0 = grid.origin
    square = [(x0, y0), (x0 + grid.resolution, y0), (x0 + grid.resolution, y0 + grid.resolution)]
    bounds = (x0, y0, x0 + grid.width, y0 + grid.height)
    polygons = OccupancyGrid.from_polygons([square], grid.resolution, bounds)
    certify_footprint(traj.path, robot.footprint, polygons)


def _exercise_planners() -> None:
    """Plan with the other planner kinds, on a costmap too, and re-plan.

    Boxes, the chapter's inflation, shortest paths, a curvature bound, ALT landmarks; a
    re-plan that keeps the corridor, one that does not and one that brakes (its plan from
    the moving state out of time).
    """
    from trajopt.robot import Robot
    from trajopt.smoother import Smoother

    base = _default_planner()
    r = base.robot.radius
    costmap = from_costmap(np.zeros((4, 4), dtype=np.uint8), 1.0, convention="costmap_2d")
    for p in (
        Planner(base.grid, corridor="boxes"),
        Planner(base.grid, inflation="paper"),
        Planner(base.grid, search="shortest"),
        Planner(base.grid, smoother=Smoother(kappa_max=1.0 / (2.0 * r))),
        Planner(base.grid, landmarks=2),
        Planner(costmap, Robot(radius=r)),
    ):
        _plan_like(p)
    planner, start, goal = _default_query()
    traj = planner.plan(start, goal)
    planner.replan(traj, 0.3 * traj.duration, latency=0.0)
    planner.replan(traj, 0.3 * traj.duration, latency=0.0, reuse=False)
    # a plan from the moving state out of time: brake, turn and go (trajopt.timing._greedy's
    # braking kernels, first reached by a re-plan with movers that braked)
    planner.replan(traj, 0.3 * traj.duration, latency=0.0, reuse=False, brake_after_s=1e-6)


def _exercise_car() -> None:
    """Search pose to pose for a car-like robot (Hybrid-A*): both ways, with a footprint."""
    import astar

    grid, a, b = _search_query()
    start, goal = (float(a[0]), float(a[1]), 0.0), (float(b[0]), float(b[1]), math.pi / 2)
    for reverse in (True, False):
        try:
            astar.find_pose_path(grid, start, goal, turning_radius=3.0, reverse=reverse)
        except astar.NoPathError:  # compiled all the same
            pass
    body = [[-0.3, -0.3], [0.6, -0.3], [0.6, 0.3], [-0.3, 0.3]]  # the footprint mode (cells)
    try:
        astar.find_pose_path(grid, start, goal, turning_radius=3.0, raw_grid=grid, footprint=body)
    except (astar.NoPathError, astar.InvalidInputError):  # compiled all the same
        pass
    # the exact body-to-polygon distance (a car on a grid made from polygons)
    square = np.array([[1.0, 1.0], [2.0, 1.0], [2.0, 2.0], [1.0, 2.0]])
    astar.bodies_distance(np.asarray(body), np.array([[0.0, 0.0, 0.3]]), [square])
    # the escape out of a tight pose (the car's last try): a body between two walls
    wall = np.array([[-1.0, 0.4], [2.0, 0.4], [2.0, 0.6], [-1.0, 0.6]])
    walls = [wall, wall * np.array([1.0, -1.0])]
    astar.find_escape(np.asarray(body), (0.0, 0.0, 0.0), walls, 3.0, room=0.2)
    astar.reeds_shepp_path((0.0, 0.0, 0.0), (1.0, 2.0, 1.0), 1.0).sample(0.5)
    astar.dubins_path((0.0, 0.0, 0.0), (1.0, 2.0, 1.0), 1.0).sample(0.5)


def _exercise_compare() -> None:
    """Compare the chapter's methods (:func:`trajopt.compare`)."""
    from trajopt.analysis.comparison import compare

    planner, start, goal = _default_query()
    compare(planner.grid, start, goal, robot_radius=planner.robot.radius, w_cells=2)


#: The warm-up exercises by name; between them they call every compiled kernel of astar and
#: trajopt (``tests/trajopt/test_warm_up.py`` checks it) with the library's argument types.
#: ``timing``, ``polygons``, ``search``, ``grid``, ``astar`` and ``fallback`` share few kernels
#: and run side by side; the others mostly load theirs.
EXERCISES: dict[str, Exercise] = {
    "timing": Exercise(_exercise_timing, seconds=13.5),
    "polygons": Exercise(_exercise_polygons, seconds=15.0),
    "search": Exercise(_exercise_search, seconds=4.0),
    "grid": Exercise(_exercise_grid, seconds=2.5),
    "astar": Exercise(_exercise_astar, seconds=2.0),
    "fallback": Exercise(_exercise_fallback, seconds=3.5),
    "plan": Exercise(_exercise_plan, after=("timing", "polygons", "search", "grid"), seconds=1.0),
    "footprint": Exercise(
        _exercise_footprint, after=("timing", "polygons", "search", "grid"), seconds=3.5
    ),
    "planners": Exercise(_exercise_planners, after=("plan", "astar", "fallback"), seconds=1.0),
    "compare": Exercise(_exercise_compare, after=("plan",), seconds=0.5),
    "car": Exercise(_exercise_car, seconds=8.0),
    "moving": Exercise(_exercise_moving, after=("timing",), seconds=3.0),
}

#: What a default plan and :func:`trajopt.compare` need (with what they depend on): the
#: command line compiles these first and starts its command when they are done.
CORE_EXERCISES: tuple[str, ...] = ("plan", "compare")


#: The command that starts a compile worker: this module, serving :data:`EXERCISES`
#: (:func:`trajopt.kernel_cache.serve`).
WORKER_COMMAND: tuple[str, ...] = (sys.executable, "-m", "trajopt.warmup", "--worker")


def compile_kernels(
    exercises: Sequence[str] | None = None,
    *,
    workers: int | None = None,
    progress: Callable[[int, int, str], None] | None = None,
    first: Sequence[str] | None = None,
    force: bool = False,
) -> CompileReport:
    """Compile the cold kernels into numba's disk cache by running the warm-up exercises.

    The exercises (:data:`EXERCISES`) run in worker processes
    (:func:`trajopt.kernel_cache.run_exercises`, each worker started with
    :data:`WORKER_COMMAND`).

    Parameters
    ----------
    exercises : sequence of str, optional
        Names in :data:`EXERCISES` (with the ones they depend on); default all, which call
        every kernel of the packages.
    workers : int, optional
        Worker processes; default ``min(2, CPUs)``. ``0`` or ``1`` runs the exercises in this
        process, one after the other (the kernels are then also loaded here).
    progress : callable, optional
        ``progress(done, total, kernel)`` after each cold kernel compiles (``total`` is the
        number of cold kernels), and once at the end with ``done == total``.
    first : sequence of str, optional
        Exercises to run before the others; the call returns as soon as they (and those
        they depend on) are done, while the workers go on with the rest in the background
        (:meth:`~trajopt.kernel_cache.CompileReport.wait` waits for them). Default: return
        when all are done.
    force : bool
        Run the exercises even when no kernel is cold.

    Returns
    -------
    CompileReport
        Nothing runs (and ``seconds`` is ~0) when every kernel is already cached. An
        exercise that fails is reported, not raised: its kernels then compile on first use.

    Raises
    ------
    InvalidInputError
        An unknown exercise name.
    """
    return kernel_cache.run_exercises(
        EXERCISES,
        exercises,
        worker=WORKER_COMMAND,
        workers=workers,
        progress=progress,
        first=first,
        force=force,
    )


if __name__ == "__main__":  # pragma: no cover - a worker of compile_kernels
    if sys.argv[1:] == ["--worker"]:
        sys.exit(kernel_cache.serve(EXERCISES))
    sys.exit(f"usage: {sys.executable} -m trajopt.warmup --worker (used by compile_kernels)")
