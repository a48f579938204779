"""Peer planners as benchmark methods (optional: the ``peers`` extra).

* ``ompl-rrtstar``, ``ompl-bitstar``: OMPL (the ``ompl`` wheel) in an R2 state space over
  the map's extent; a state is valid when its cell is free on the inflated grid (the same
  grid the reference A* searches); RRT* or BIT* minimising path length for
  :data:`OMPL_TIME_LIMIT_S` seconds (seeded with :data:`OMPL_SEED`), then
  ``PathSimplifier.simplifyMax`` and ``smoothBSpline``. OMPL checks motions at discrete
  states (its default resolution), as its users do.
* ``ompl-reedsshepp``, ``ompl-dubins`` (the car peers): OMPL's ``RRTstar`` in
  ``ReedsSheppStateSpace(R)`` (forwards and backwards) or ``DubinsStateSpace(R)`` (forwards
  only), ``R`` the car methods' turning radius (``2 x radius``), over the map's extent, from
  the start pose to the goal pose (the query's headings; goal threshold
  :data:`OMPL_CAR_GOAL_TOL`); a state is valid when its cell is free on the same inflated grid,
  motions checked every :data:`OMPL_CAR_CHECK_CELLS` cells; stopped at its first exact
  solution or after :data:`OMPL_CAR_TIME_LIMIT_S` s (``first_solution_s``), then
  ``simplifySolution`` (at most :data:`OMPL_CAR_SIMPLIFY_S` s; its shortcuts are Reeds-Shepp /
  Dubins curves, so the path keeps ``1/R``). ``runtime_s`` is both. The path is interpolated
  every :data:`OMPL_CAR_INTERPOLATE_CELLS` cells and scored by
  :func:`~trajopt.analysis.bench._car.pose_path_metrics`; it is not timed (``duration_s`` NaN:
  OMPL's geometric planners return no speeds), so it is compared by length.
* ``pmp-bspline``, ``pmp-cubic``: python-motion-planning's point-based curve generators
  (``BSpline`` interpolation, degree 3, and ``CubicSpline``) through the corner points of
  the reference A* path.

The outputs are sampled polylines (metres) that :func:`trajopt.analysis.bench._methods.evaluate_query`
scores like every other method. A peer that finds no solution, or raises any exception of its own
(e.g. python-motion-planning's interpolation on a singular system), raises
:class:`PeerFailure` (a row with ``failure = "PeerFailure"``, the reason in ``note``). A peer whose package is missing raises
:class:`~trajopt.errors.PeerUnavailableError` when the run is checked, before any work.
"""

from __future__ import annotations

import importlib.util
import math
import time
from collections.abc import Sequence
from typing import Any

import numpy as np

from trajopt.analysis.bench._records import MethodOutput, PeerFailure
from trajopt.errors import PeerUnavailableError

#: Planning time of the OMPL planners per query (s).
OMPL_TIME_LIMIT_S = 1.0
#: Seed of OMPL's random number generator (set before every query).
OMPL_SEED = 1
#: Time limit of the car peers per query (s): they stop at their first solution before it.
OMPL_CAR_TIME_LIMIT_S = 2.0
#: Time limit of the car peers' path simplification (s).
OMPL_CAR_SIMPLIFY_S = 0.2
#: Spacing of the car peers' motion validity checks (cells).
OMPL_CAR_CHECK_CELLS = 0.2
#: Spacing of the interpolated states the car peers are scored on (cells).
OMPL_CAR_INTERPOLATE_CELLS = 0.05
#: Goal threshold of the car peers (distance in their state space: m, and rad weighted).
OMPL_CAR_GOAL_TOL = 1e-6
_PACKAGES = {"ompl": "ompl", "python_motion_planning": "python-motion-planning"}


def require(module: str, method: str) -> None:
    """Raise :class:`PeerUnavailableError` unless ``module`` can be imported."""
    if importlib.util.find_spec(module) is None:
        raise PeerUnavailableError(
            f"method {method!r} needs the package {_PACKAGES.get(module, module)!r}, which is "
            "not installed: install the `peers` extra (pip install 'trajopt[peers]')"
        )


def corner_points(points: np.ndarray) -> np.ndarray:
    """Return the vertices of a polyline where its direction changes, ends included.

    Parameters
    ----------
    points : ndarray, shape (n, 2)

    Returns
    -------
    ndarray, shape (m, 2), m <= n
    """
    p = np.asarray(points, dtype=float)
    if len(p) <= 2:
        return p.copy()
    d = np.diff(p, axis=0)
    cross = d[:-1, 0] * d[1:, 1] - d[:-1, 1] * d[1:, 0]
    dot = np.sum(d[:-1] * d[1:], axis=1)
    turn = (np.abs(cross) > 1e-12) | (dot < 0)
    keep = np.concatenate([[True], turn, [True]])
    return p[keep]


def _ompl(planner: str, q: Any) -> np.ndarray:
    from ompl import base as ob
    from ompl import geometric as og
    from ompl import util as ou

    ou.setLogLevel(ou.LOG_NONE)
    ou.RNG.setSeed(OMPL_SEED)
    grid = q.map.grid
    occ = np.asarray(q.map.inflated.occupied)
    res = float(grid.resolution)
    ox, oy = (float(v) for v in grid.origin)
    ny, nx = occ.shape
    space = ob.RealVectorStateSpace(2)
    bounds = ob.RealVectorBounds(2)
    bounds.setLow(0, ox)
    bounds.setHigh(0, ox + nx * res)
    bounds.setLow(1, oy)
    bounds.setHigh(1, oy + ny * res)
    space.setBounds(bounds)
    ss = og.SimpleSetup(space)

    def valid(state: Any) -> bool:
        ix = math.floor((state[0] - ox) / res)
        iy = math.floor((state[1] - oy) / res)
        return 0 <= ix < nx and 0 <= iy < ny and not occ[iy, ix]

    ss.setStateValidityChecker(valid)
    s = space.allocState()
    g = space.allocState()
    s[0], s[1] = (float(v) for v in q.start)
    g[0], g[1] = (float(v) for v in q.goal)
    ss.setStartAndGoalStates(s, g)
    si = ss.getSpaceInformation()
    ss.setPlanner(og.RRTstar(si) if planner == "rrtstar" else og.BITstar(si))
    ss.solve(OMPL_TIME_LIMIT_S)
    if not ss.haveExactSolutionPath():
        raise PeerFailure(f"OMPL {planner}: no exact solution in {OMPL_TIME_LIMIT_S} s")
    path = ss.getSolutionPath()
    simplifier = og.PathSimplifier(si)
    simplifier.simplifyMax(path)
    simplifier.smoothBSpline(path)
    return np.array([(st[0], st[1]) for st in path.getStates()], dtype=float)


def _ompl_car(q: Any, reverse: bool) -> tuple[np.ndarray, dict[str, Any]]:
    """Plan one pose query with OMPL's RRT* in a Reeds-Shepp / Dubins space (module doc)."""
    from ompl import base as ob
    from ompl import geometric as og
    from ompl import util as ou

    from trajopt.analysis.bench._car import pose_path_metrics

    ou.setLogLevel(ou.LOG_NONE)
    ou.RNG.setSeed(OMPL_SEED)
    h0, h1 = q.headings
    grid = q.map.grid
    occ = np.asarray(q.map.inflated.occupied)
    res = float(grid.resolution)
    ox, oy = (float(v) for v in grid.origin)
    ny, nx = occ.shape
    R = float(q.map.turning_radius)
    space = ob.ReedsSheppStateSpace(R) if reverse else ob.DubinsStateSpace(R)
    bounds = ob.RealVectorBounds(2)
    bounds.setLow(0, ox)
    bounds.setHigh(0, ox + nx * res)
    bounds.setLow(1, oy)
    bounds.setHigh(1, oy + ny * res)
    space.setBounds(bounds)
    ss = og.SimpleSetup(space)

    def valid(state: Any) -> bool:
        ix = math.floor((state.getX() - ox) / res)
        iy = math.floor((state.getY() - oy) / res)
        return 0 <= ix < nx and 0 <= iy < ny and not occ[iy, ix]

    ss.setStateValidityChecker(valid)
    si = ss.getSpaceInformation()
    si.setStateValidityCheckingResolution(OMPL_CAR_CHECK_CELLS * res / space.getMaximumExtent())
    a = space.allocState()
    g = space.allocState()
    for st, p, h in ((a, q.start, h0), (g, q.goal, h1)):
        st.setX(float(p[0]))
        st.setY(float(p[1]))
        st.setYaw(float(h))
    ss.setStartAndGoalStates(a, g, OMPL_CAR_GOAL_TOL)
    obj = ob.PathLengthOptimizationObjective(si)
    obj.setCostThreshold(ob.Cost(math.inf))  # stop at the first solution
    ss.setOptimizationObjective(obj)
    ss.setPlanner(og.RRTstar(si))
    t0 = time.perf_counter()
    ss.solve(OMPL_CAR_TIME_LIMIT_S)
    first = time.perf_counter() - t0
    kind = "Reeds-Shepp" if reverse else "Dubins"
    if not ss.haveExactSolutionPath():
        raise PeerFailure(f"OMPL RRT* ({kind}): no exact solution in {OMPL_CAR_TIME_LIMIT_S} s")
    ss.simplifySolution(OMPL_CAR_SIMPLIFY_S)
    path = ss.getSolutionPath()
    n = max(2, math.ceil(path.length() / (OMPL_CAR_INTERPOLATE_CELLS * res)) + 1)
    path.interpolate(n)
    m = path.getStateCount()
    xy = np.empty((m, 2))
    yaw = np.empty(m)
    for i in range(m):
        st = path.getState(i)
        xy[i] = st.getX(), st.getY()
        yaw[i] = st.getYaw()
    extras = pose_path_metrics(xy, yaw, 1.0 / R, (h0, h1))
    extras["first_solution_s"] = first
    return xy, extras


def _pmp(kind: str, q: Any) -> np.ndarray:
    import python_motion_planning as pmp

    pts = corner_points(q.reference)
    if len(pts) < 2:
        raise PeerFailure("python-motion-planning: the reference has fewer than 2 points")
    length_cells = float(np.sum(np.hypot(*np.diff(q.reference, axis=0).T))) / float(
        q.map.grid.resolution
    )
    step = 1.0 / min(2000.0, max(200.0, 2.0 * length_cells))
    gen = pmp.BSpline(step=step, k=3) if kind == "bspline" else pmp.CubicSpline(step=step)
    path, info = gen.generate([tuple(p) for p in pts])
    if not info.get("success") or len(path) < 2:
        raise PeerFailure(f"python-motion-planning {kind}: generation failed ({info})")
    return np.asarray(path, dtype=float)[:, :2]


def run(name: str, q: Any, requires: Sequence[str]) -> MethodOutput:
    """Run the peer ``name`` on a :class:`~trajopt.analysis.bench._methods.QueryContext`.

    ``requires`` are the modules the peer needs (its method's ``requires``), checked first.

    Returns
    -------
    MethodOutput
        The peer's polyline (metres) and its compute time.

    Raises
    ------
    PeerUnavailableError
        Its package is missing.
    PeerFailure
        It found no solution.
    """
    for mod in requires:
        require(mod, name)
    t0 = time.perf_counter()
    extras: dict[str, Any] = {}
    try:
        if name in ("ompl-reedsshepp", "ompl-dubins"):
            pts, extras = _ompl_car(q, name == "ompl-reedsshepp")
            note = (
                f"RRT* first solution within {OMPL_CAR_TIME_LIMIT_S} s, simplifySolution; "
                "untimed (length only)"
            )
        elif name.startswith("ompl-"):
            pts = _ompl(name.removeprefix("ompl-"), q)
            note = (
                f"{name.removeprefix('ompl-')}, {OMPL_TIME_LIMIT_S} s, simplifyMax + smoothBSpline"
            )
        else:
            pts = _pmp(name.removeprefix("pmp-"), q)
            note = f"{name.removeprefix('pmp-')} through the reference's corner points"
    except PeerFailure:
        raise
    except Exception as exc:  # the peer's own crash is its row's failure, not the run's
        raise PeerFailure(f"{name} raised {type(exc).__name__}: {exc}") from exc
    runtime = time.perf_counter() - t0
    # drop repeated vertices (a polyline needs distinct consecutive points)
    keep = np.concatenate([[True], np.any(np.diff(pts, axis=0) != 0.0, axis=1)])
    pts = pts[keep]
    if len(pts) < 2:
        raise PeerFailure(f"{name}: the path has fewer than 2 distinct points")
    return MethodOutput(pts, True, note, extras, runtime_s=runtime)
