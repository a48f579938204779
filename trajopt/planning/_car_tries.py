"""The tries of a car's plan: search grids, search radii and their fits, within a budget.

:func:`search_and_fit` runs :func:`astar.find_pose_path` (Hybrid-A* with Reeds-Shepp
shots, or Dubins shots when ``robot.drive.reverse`` is False) from the start pose to the goal pose,
on the raw map inflated by the robot radius plus :data:`SEARCH_MARGIN_CELLS`
(:func:`car_search_grid`: every point of a free cell, not only its centre, keeps the radius:
the search's poses lie anywhere in their cells), with a turning radius
:data:`SEARCH_RADIUS_FACTORS` times ``R``: the first factor leaves the smoother room (a
segment turning at exactly ``1/R`` between fixed end poses admits no other curve, and a
B-spline is no circle); when a segment of its path has no certified fit
(:mod:`trajopt.planning._car_fit`), the search runs again with gentler arcs (the second
factor); when the search finds no path, with 1.05 ``R`` and then ``R`` itself (larger
factors are then skipped), their fits with the smoother's ``kappa_margin`` raised to
:data:`TIGHT_KAPPA_MARGIN` (a turn at nearly full lock, e.g. a start facing a wall with
just the room to turn; the certificate's dense curvature check still holds them to
``1/R``). When an end point is blocked on that grid, or the margin disconnects the poses or
leaves no path, the same tries run on the map inflated by the radius alone (the other
planners' grid): end points near walls and passages the margin closes. There only the cell
centres keep the radius, so that search runs in its exact mode (:func:`astar.find_pose_path`
``raw_grid``, ``clearance``; :func:`exact_clearance`): the chords between its poses keep the
radius from the raw map exactly, as the corridor requires (a pose anywhere in a free cell
could come up to half a cell's diagonal closer). A car with a body searches each radius
with the default costs first, capped at :data:`FOOTPRINT_DEFAULT_EXPANSIONS`, then with
:data:`FOOTPRINT_COSTS` (:func:`cost_variants`), and goes on to the second grid as soon as
the first grid's first radius finds no path (there the sampling slack is refined near
obstacles: :func:`exact_clearance`). When every radius of the second grid exhausted its
states, a car with a body searches it once more at :data:`TIGHT_FACTORS` with finer heading
bins, shorter primitives and finer states near the end poses (:func:`tight_motion`,
:func:`search_factors`): a bay entered nose first off a narrow aisle.
When every try failed and expansions are left, the caller's last try runs
(``last_try``: the escape out of a tight end pose, :mod:`trajopt.planning._car_escape`).
``stats["car"]["tries"]`` lists them.

Budgets: expansion counts decide, so that the plan does not depend on the machine's load.
Each search stops after :data:`SEARCH_EXPANSIONS` expansions
(:data:`FOOTPRINT_SEARCH_EXPANSIONS` for a car with a body, its default costs after
:data:`FOOTPRINT_DEFAULT_EXPANSIONS`), and the searches of one plan share
:data:`CAR_EXPANSIONS` (:data:`FOOTPRINT_CAR_EXPANSIONS`): no try starts once they are
spent, and a try gets at most what is left (the last try included). The wall-clock
limits, :data:`SEARCH_SAFETY_S` per search and :data:`CAR_BUDGET_S` per plan, are only
safety nets, far above what the searches take; when one fires, the plan stops with a :class:`~trajopt.errors.NoPathError`
that says so (its answer would depend on the machine's load) instead of going on to the
next try. The fits keep the smoother's own wall-clock budget (at most
``trajopt.planning._car.SEGMENT_BUDGET_S``, 2 s, per fit; the smooth stage of a plan
takes about 20 ms at the median on ``benchmarks/bench_car.py``'s queries), and a fit that
runs out of it goes on to the next try: not yet a count.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

import astar
from astar.grid import OccupancyGrid
from trajopt.errors import InvalidInputError, NoPathError, SmoothingError
from trajopt.planning._car_fit import CarSegment, fit_path
from trajopt.planning._options import PlannerOptions
from trajopt.planning._query import StageTimer
from trajopt.robot import Robot
from trajopt.smoother import Smoother

#: Extra inflation (cells) of the search grid beyond the robot radius: half a cell's
#: diagonal (any point of a free cell keeps the radius) plus slack for the chords between
#: the search's poses (at most half a cell apart).
SEARCH_MARGIN_CELLS = 0.5 * math.sqrt(2.0) + 0.05
#: Margin (cells) of the footprint search (:func:`exact_clearance`): the returned poses lie
#: on the searched arcs, the chords between them at most the sagitta of a half-cell step
#: (below 0.008 cells for ``R >= 4`` cells) off them, so with this margin the polyline
#: through the poses keeps the inscribed radius, as the corridor requires.
FOOTPRINT_TOL_CELLS = 0.01
#: Sampling slack (cells) of the footprint search on the second grid (``footprint_slack``
#: of :func:`astar.find_pose_path`; on the first grid :data:`SEARCH_MARGIN_CELLS`): the
#: footprint tests fall as its inverse (the default 0.05 made a 35-cell car on a 2.5 cm
#: grid expand 2 000 states a second), and poses within it of an obstacle are refused.
FOOTPRINT_SLACK_CELLS = 0.25
#: The second grid's sampling slack is at least this (m): on cells finer than 0.1 m the
#: slack in cells grows, so that the number of footprint tests per metre of a manoeuvre
#: stays that of 0.1 m cells (the refinement to :data:`FOOTPRINT_MIN_SLACK_CELLS` keeps
#: the tight places).
FOOTPRINT_SLACK_M = 0.025
#: Least sampling slack (cells) of the footprint search on the second grid
#: (``footprint_min_slack`` of :func:`astar.find_pose_path`; the first grid keeps its
#: slack whole, room for the smoother): a sample test that fails near an obstacle is
#: refined down to it, so end poses and manoeuvres within :data:`FOOTPRINT_SLACK_CELLS` of
#: a (conservative, rasterised) obstacle cell are kept, and only there do the tests cost
#: more.
FOOTPRINT_MIN_SLACK_CELLS = 0.05
#: Costs of the search of a car with a body (``astar.HybridCosts`` fields): a parking
#: manoeuvre drives backwards and changes direction often, and Smac's defaults (a cusp at
#: 2 turning radii, backwards at twice the length, the heuristic weighted 1.5) made the
#: search expand every state a cusp fewer reaches first. On 7 parking cases of the suite
#: that ran the second grid's search out of 3 s, these planned 5 (0.3-2.6 s). Tried after
#: the default costs (:func:`cost_variants`).
FOOTPRINT_COSTS = {"cusp_penalty": 0.5, "reverse_penalty": 1.2, "heuristic_weight": 2.5}
#: Cap (expansions) on the search of a car with a body at the default costs, before
#: :data:`FOOTPRINT_COSTS` (0.05-0.08 s of CPU on the parking suite's slow cases at 0.1 m).
FOOTPRINT_DEFAULT_EXPANSIONS = 5000
#: Turning radii of the search, as multiples of ``min_turning_radius``, tried in order
#: (module docstring: a factor above one that failed to search is skipped afterwards).
SEARCH_RADIUS_FACTORS = (1.15, 1.5, 1.05, 1.0)
#: Search radius factors at or below this fit with :data:`TIGHT_KAPPA_MARGIN`.
TIGHT_FACTOR = 1.05
#: The smoother's ``kappa_margin`` (bound at its collocation samples, as a fraction of
#: ``1/R``) for the fits of a path searched at :data:`TIGHT_FACTOR` ``R`` or less: with the
#: default 0.9 a curve cannot follow an arc of 1.02-1.05 ``R`` (held-out depot #5, forward
#: only, a start facing a wall), with 0.99 it does.
TIGHT_KAPPA_MARGIN = 0.99
#: The tight search of a car with a body (:func:`tight_motion`), run on the radius grid at
#: a turning radius whose searches exhausted their states: heading bins, the primitive's
#: arc length and the radius round the end poses with finer states (both as fractions of
#: the turning radius in cells) and their refinement (``astar.HybridMotion`` fields). A
#: bay entered nose first off an aisle of 1.5 turning radii (the suite's
#: perpendicular-forwards-0, 1.34 car widths) exhausts every state at 72 bins and 5 degree
#: arcs, and with these finds a path of 15-18 cusps in about 1 s at 0.1 m. The factors in
#: order: 1.05 first, its fits with :data:`TIGHT_KAPPA_MARGIN`; at 1.15 (the ordinary
#: margin) that case's path of short moves had no certified fit, after 1.3 s.
TIGHT_HEADING_BINS = 180
TIGHT_FACTORS = (1.05, 1.15)
TIGHT_PRIMITIVE_R = 1.0 / 15.0
TIGHT_FINE_RADIUS_R = 1.0
TIGHT_FINE_FACTOR = 2
TIGHT_MIN_SLACK_CELLS = 0.05
#: Cap on the expansions of the finer search that :func:`astar.find_pose_path` runs after
#: a small region was exhausted (``retry_expansions``), on the first grid of a car with a
#: body (:func:`first_grid_limits`): 0, none. There the grid's coarse sampling slack closes
#: a slot, and the second grid, whose slack is refined near obstacles, plans it with fewer
#: expansions and cusps (the suite's full-parallel-forwards-3 at 0.1 m: 68 000 expansions
#: and 12 cusps on the first grid against about 20 000 and 9 on the second).
FIRST_GRID_RETRY_EXPANSIONS = 0
#: Caps (expansions) that decide when a search of a car's plan gives up (module docstring):
#: ``(per search, all the searches of one plan)``, for a disc and for a car with a body
#: (:func:`expansion_caps`). About what 2 s per search and 6 s per plan allow on a quiet
#: machine: a disc's search expands a state in about 3.5 us, a body's in 10-14 us (its
#: footprint tests).
#: What the searches need: on the parking suite (full-size car at 0.1 and 0.05 m, small car
#: at 0.05 m) the largest search that found a path expanded 51 225 states, the most one
#: plan expanded in all 70 380; on the held-out road and room queries of
#: ``benchmarks/bench_car.py`` (5 a map) a disc's largest search expanded 105 711 (its
#: states exhausted), the largest that found a path 31 238.
SEARCH_EXPANSIONS = 500_000
CAR_EXPANSIONS = 1_500_000
FOOTPRINT_SEARCH_EXPANSIONS = 150_000
FOOTPRINT_CAR_EXPANSIONS = 450_000
#: Safety net (s, wall clock) on one search (``time_budget`` of
#: :func:`astar.find_pose_path`): about 15 times what a search that reaches its expansion
#: cap takes on a quiet machine (1.7-2.1 s); the searches of the parking suite take at most
#: 0.6 s. When it fires, the plan stops with a :class:`~trajopt.errors.NoPathError` saying so.
SEARCH_SAFETY_S = 30.0
#: Safety net (s, wall clock) on a car's plan: a try due to start after it raises
#: :class:`~trajopt.errors.NoPathError` saying so instead. About 10 times what the tries
#: take when they spend every expansion on a quiet machine (about 6 s).
CAR_BUDGET_S = 60.0
#: Slack (m) of the search's exact clearance on the radius grid: a quarter of the corridor's
#: tolerance (``trajopt.corridor`` accepts points ``1e-9`` m closer than the radius), so that
#: an end point exactly at the radius from a wall (a cell centre) may leave it.
EXACT_TOL_M = 0.25e-9


@dataclass(frozen=True, slots=True)
class CarFound:
    """The try of a car's plan that completed (:func:`search_and_fit`).

    Attributes
    ----------
    search_grid : astar.OccupancyGrid
        The grid it searched (:func:`car_search_grid`).
    path : astar.PosePath
        The Hybrid-A* path (cells).
    radius_cells : float
        The turning radius it was searched with (cells).
    poses : ndarray, shape (n, 3)
        Its poses in world units ``(x, y, heading)`` (m, m, rad).
    segments : list of CarSegment
        The certified fits, in order.
    tries : list of str
        Every try made, this one last.
    expansions : int
        The expansions of every try's search, this one's included (at most the plan's cap:
        :func:`expansion_caps`).
    """

    search_grid: OccupancyGrid
    path: Any
    radius_cells: float
    poses: np.ndarray
    segments: list[CarSegment]
    tries: list[str]
    expansions: int


def search_and_fit(
    options: PlannerOptions,
    grid: OccupancyGrid,
    cells: tuple[tuple[float, float, float], tuple[float, float, float]],
    points: tuple[np.ndarray, np.ndarray],
    smoother: Smoother,
    timer: StageTimer,
    last_try: Callable[..., CarFound | None] | None = None,
) -> CarFound:
    """Run the tries of a car's plan until one searches and fits (module docstring).

    Parameters
    ----------
    options : PlannerOptions
        Resolved for ``grid``; ``options.robot.drive`` an :class:`~trajopt.drive.Ackermann`.
    grid : astar.OccupancyGrid
        The raw map.
    cells : tuple
        The start and goal poses in cells ``(x, y, heading)`` (cells, cells, rad).
    points : tuple of ndarray
        The start and goal points (m), for the messages.
    smoother : Smoother
        The smoother of the fits (its ``kappa_max`` at most ``1/R``); its ``kappa_margin``
        is raised to :data:`TIGHT_KAPPA_MARGIN` for the tight search radii.
    timer : StageTimer
        Receives the ``inflate``, ``search``, ``corridor`` and ``smooth`` stages.
    last_try : callable, optional
        Run when every try failed and expansions are left, as ``last_try(options, grid,
        cells, tight smoother, timer, tries, failures, expansions left)``: a
        :class:`CarFound` or None (the escape try,
        :func:`trajopt.planning._car_escape.escape_and_fit`).

    Returns
    -------
    CarFound
        The try that completed.

    Raises
    ------
    InvalidInputError
        An end point blocked on every search grid tried.
    NoPathError
        No path joins the poses (an :class:`astar.NoPosePathError` as its cause; with
        ``reverse=False`` the message says that a forward-only path was asked for).
    SmoothingError
        A path was found and a segment of it has no certified curve within ``1/R``.
    """
    robot = options.robot
    res = grid.resolution
    start, goal = cells
    p0, p1 = points
    sm = smoother
    sm_tight = dataclasses.replace(sm, kappa_margin=max(sm.kappa_margin, TIGHT_KAPPA_MARGIN))
    t_end = time.perf_counter() + CAR_BUDGET_S
    search_cap, car_cap = expansion_caps(robot)
    spent = 0  # expansions of the searches so far
    tries: list[str] = []
    failures: list[Exception] = []
    for margin in (True, False):
        with timer.stage("inflate"):
            search_grid = car_search_grid(robot, grid, margin=margin)
        blocked = blocked_end(
            robot, search_grid, margin, (("start", start, p0), ("goal", goal, p1))
        )
        if blocked is not None:
            tries.append(f"{grid_name(margin)}: {blocked}")
            failures.append(InvalidInputError(blocked))
            continue
        largest = math.inf
        exhausted: list[float] = []
        for factor, tight in search_factors(robot, margin):
            if spent >= car_cap or (factor > largest if not tight else factor not in exhausted):
                continue
            r_cells = factor * robot.drive.min_turning_radius / res
            path = None
            stop = False
            variants = (
                (
                    (
                        TIGHT_NAME,
                        tight_motion(robot.drive.min_turning_radius / res),
                        search_cap,
                    ),
                )
                if tight
                else cost_variants(robot)
            )
            for name, costs, cap in variants:
                if spent >= car_cap:
                    break
                label = f"{grid_name(margin)}, {factor:g} R{name}"
                if time.perf_counter() > t_end:
                    raise safety_net_error(
                        f"the plan's wall-clock safety net of {CAR_BUDGET_S:g} s fired before "
                        f"the try {label!r} ({spent} of {car_cap} expansions spent)",
                        tries,
                    )
                try:
                    with timer.stage("search"):
                        path = astar.find_pose_path(
                            search_grid,
                            start,
                            goal,
                            turning_radius=r_cells,
                            reverse=robot.drive.reverse,
                            max_expansions=min(cap, car_cap - spent),
                            time_budget=SEARCH_SAFETY_S,
                            **{**exact_clearance(robot, grid, margin), **costs},
                            **first_grid_limits(robot, margin),
                        )
                    spent += int(path.stats["expanded"])
                    if any(sub["stop"] == "time_budget" for sub in path.stats["searches"]):
                        # the first of two searches stopped by its share of the safety net
                        raise safety_net_error(
                            f"the search {label!r} ran into its wall-clock safety net "
                            f"(a share of {SEARCH_SAFETY_S:g} s) before its expansion cap",
                            tries,
                        )
                    break
                except astar.NoPosePathError as exc:
                    spent += int((exc.stats or {}).get("expanded", 0))
                    tries.append(f"{label}: no path ({exc.reason})")
                    failures.append(exc)
                    subs = (exc.stats or {}).get("searches", [])
                    if exc.reason == "time_budget" or any(
                        sub["stop"] == "time_budget" for sub in subs
                    ):  # the clock stopped a search (the first of two: the second's answer
                        # could differ from the one after the first's expansion share)
                        raise safety_net_error(
                            f"the search {label!r} ran into its wall-clock safety net of "
                            f"{SEARCH_SAFETY_S:g} s ({exc.stats.get('expanded', 0)} expansions)",
                            tries,
                            exc,
                        ) from exc
                    if exc.reason == "disconnected":
                        stop = True
                        break
                    if exc.reason == "exhausted":
                        break  # every reachable state expanded: other costs reach no more
                except astar.InvalidInputError as exc:
                    if robot.footprint is None:
                        raise
                    # an end pose whose footprint does not keep this grid's slack: next grid
                    tries.append(f"{grid_name(margin)}: {exc}")
                    failures.append(InvalidInputError(str(exc)))
                    stop = True
                    break
            if stop:
                break
            if path is None:
                if robot.footprint is not None and margin:
                    break  # a body: the second grid (its slack refined near obstacles) next
                largest = min(largest, factor)
                if not tight and failures and getattr(failures[-1], "reason", "") == "exhausted":
                    exhausted.append(factor)
                continue
            poses = path.to_world(grid)
            try:
                segments = fit_path(
                    options,
                    grid,
                    sm if factor > TIGHT_FACTOR else sm_tight,
                    path,
                    poses,
                    res,
                    timer,
                )
            except SmoothingError as exc:
                tries.append(f"{label}: a segment has no fit")
                failures.append(exc)
                continue
            tries.append(f"{label}: planned")
            return CarFound(search_grid, path, r_cells, poses, segments, tries, spent)
    if last_try is not None and spent < car_cap:
        if time.perf_counter() > t_end:
            raise safety_net_error(
                f"the plan's wall-clock safety net of {CAR_BUDGET_S:g} s fired before the "
                f"last try ({spent} of {car_cap} expansions spent)",
                tries,
            )
        found = last_try(options, grid, cells, sm_tight, timer, tries, failures, car_cap - spent)
        if found is not None:
            return dataclasses.replace(found, expansions=found.expansions + spent)
    raise failure(robot, grid, start, goal, tries, failures)


def search_factors(robot: Robot, margin: bool) -> list[tuple[float, bool]]:
    """Return the tries of one search grid: ``(turning radius factor, tight)`` in order.

    :data:`SEARCH_RADIUS_FACTORS`, then, for a car with a body on the radius grid, the tight
    search (:func:`tight_motion`) at :data:`TIGHT_FACTORS`: each runs only when the
    ordinary search at its factor exhausted its states (:func:`search_and_fit`), so a plan
    the ordinary tries find is the same with or without the tight ones.
    """
    out = [(f, False) for f in SEARCH_RADIUS_FACTORS]
    if robot.footprint is not None and not margin:
        out += [(f, True) for f in TIGHT_FACTORS]
    return out


def cost_variants(robot: Robot) -> tuple[tuple[str, dict[str, Any], int], ...]:
    """Return the search costs a try runs with, in order: ``(name, costs, expansion cap)``.

    A disc: the search's default costs, :data:`SEARCH_EXPANSIONS`. A car with a body: the
    default costs for :data:`FOOTPRINT_DEFAULT_EXPANSIONS` expansions (the paths they find
    where they find one quickly: drives into a bay without reversing), then
    :data:`FOOTPRINT_COSTS` (named ``", parking costs"`` in the tries) for
    :data:`FOOTPRINT_SEARCH_EXPANSIONS`. A search that exhausts its states (every reachable
    state expanded) ends the variants of its try: the costs change the order of the
    expansions, not the states reachable.
    """
    search_cap = expansion_caps(robot)[0]
    if robot.footprint is None:
        return (("", {}, search_cap),)
    return (
        ("", {}, FOOTPRINT_DEFAULT_EXPANSIONS),
        (", parking costs", FOOTPRINT_COSTS, search_cap),
    )


def expansion_caps(robot: Robot) -> tuple[int, int]:
    """Return the expansion caps of a car's plan: ``(per search, per plan)``.

    :data:`SEARCH_EXPANSIONS` and :data:`CAR_EXPANSIONS` for a disc,
    :data:`FOOTPRINT_SEARCH_EXPANSIONS` and :data:`FOOTPRINT_CAR_EXPANSIONS` for a car with
    a body (its expansions test the footprint, about 3-4 times slower).
    """
    if robot.footprint is None:
        return SEARCH_EXPANSIONS, CAR_EXPANSIONS
    return FOOTPRINT_SEARCH_EXPANSIONS, FOOTPRINT_CAR_EXPANSIONS


#: The name of the tight search in the tries (:func:`tight_motion`).
TIGHT_NAME = ", tight (finer states and primitives near the ends)"


def tight_motion(r_cells: float) -> dict[str, Any]:
    """Return the search arguments of the tight try at turning radius ``r_cells`` (cells).

    :data:`FOOTPRINT_COSTS` with :data:`TIGHT_HEADING_BINS` heading bins, primitives
    :data:`TIGHT_PRIMITIVE_R` ``r_cells`` long, and, when a small region is exhausted,
    states and primitives :data:`TIGHT_FINE_FACTOR` times finer within
    :data:`TIGHT_FINE_RADIUS_R` ``r_cells`` of the end poses (``astar.HybridMotion``'s
    ``fine_radius``). Run after a search of a car with a body on the radius grid exhausted
    its states at that radius (:func:`search_and_fit`): the same search space sampled more
    finely, where a manoeuvre of many short moves fits between the poses the coarse states
    keep apart.
    """
    return {
        **FOOTPRINT_COSTS,
        "heading_bins": TIGHT_HEADING_BINS,
        "primitive_length": TIGHT_PRIMITIVE_R * r_cells,
        "fine_radius": TIGHT_FINE_RADIUS_R * r_cells,
        "fine_factor": TIGHT_FINE_FACTOR,
        "footprint_min_slack": TIGHT_MIN_SLACK_CELLS,
    }


def first_grid_limits(robot: Robot, margin: bool) -> dict[str, Any]:
    """Return the search's limits beyond its budgets on a search grid (``margin``: the first).

    A car with a body on the first grid: ``retry_expansions``
    :data:`FIRST_GRID_RETRY_EXPANSIONS` (the second grid does better where a small region
    is exhausted); otherwise none.
    """
    if robot.footprint is not None and margin:
        return {"retry_expansions": FIRST_GRID_RETRY_EXPANSIONS}
    return {}


def car_search_grid(robot: Robot, grid: OccupancyGrid, margin: bool = True) -> OccupancyGrid:
    """Return the grid a car's search runs on: ``grid`` inflated by the radius plus a margin.

    Parameters
    ----------
    robot : Robot
        The car (its ``radius``, m).
    grid : astar.OccupancyGrid
        The raw map.
    margin : bool, optional
        False: the radius alone (the second grid the search tries; module docstring).

    Returns
    -------
    astar.OccupancyGrid
        ``grid`` with every cell within ``robot.radius`` plus :data:`SEARCH_MARGIN_CELLS`
        cells (without ``margin``: within ``robot.radius``) of an occupied square (or of the
        outside) occupied. A car with a body: every cell whose centre is closer than the
        inscribed radius minus half a cell's diagonal to an occupied square, or, where the
        map knows its polygons (:attr:`astar.OccupancyGrid.polygons`), to a polygon
        (:func:`polygon_band`), or to the outside.
    """
    r = robot.radius + (SEARCH_MARGIN_CELLS * grid.resolution if margin else 0.0)
    if robot.footprint is not None:
        # a necessary condition only (the search checks the footprint itself): a pose
        # anywhere in a cell keeps the inscribed radius, so its centre keeps that minus
        # half the cell's diagonal
        r = max(0.0, robot.inscribed_radius - 0.5 * math.sqrt(2.0) * grid.resolution)
    occ = astar.inflate(grid, r, metric="square", outside_occupied=True).occupied
    if robot.footprint is not None and grid.polygons is not None and r > 0.0:
        occ = polygon_band(grid, occ, r)
    return grid.with_occupied(occ)


def polygon_band(grid: OccupancyGrid, blocked: np.ndarray, r: float) -> np.ndarray:
    """Free the cells of ``blocked`` whose centre keeps ``r`` (m) from the map's polygons.

    ``blocked``: the cells whose centre is closer than ``r`` to an occupied square or the
    map's outside. Every occupied square lies within its diagonal of a polygon
    (:meth:`astar.OccupancyGrid.from_polygons`), so a centre closer than ``r`` minus the
    diagonal to a square is closer than ``r`` to a polygon: only the band between the two
    is measured exactly against the polygons (:func:`astar.points_distance`) and against
    the map's outside; a cell of it that keeps ``r`` from both is freed.
    """
    res = grid.resolution
    inner = r - math.sqrt(2.0) * res
    sure = (
        astar.inflate(grid, inner, metric="square", outside_occupied=True).occupied
        if inner > 0.0
        else grid.occupied
    )
    iy, ix = np.nonzero(blocked & ~sure)
    if not len(ix):
        return blocked
    centres = grid.cell_to_world(np.column_stack([ix, iy]))
    ox, oy = grid.origin
    edge = np.minimum.reduce(
        [
            centres[:, 0] - ox,
            ox + grid.width - centres[:, 0],
            centres[:, 1] - oy,
            oy + grid.height - centres[:, 1],
        ]
    )
    keep = (astar.points_distance(centres, grid.polygons) >= r) & (edge >= r)
    out = np.array(blocked, dtype=bool)
    out[iy[keep], ix[keep]] = False
    return out


def exact_clearance(robot: Robot, grid: OccupancyGrid, margin: bool) -> dict[str, Any]:
    """Return the search's exact-mode arguments on the radius grid (none on the margin grid).

    With a footprint, on both grids: the footprint mode (:func:`astar.find_pose_path`
    ``footprint``, the footprint in cells), where every pose of the search's arcs keeps its
    oriented footprint :data:`FOOTPRINT_TOL_CELLS` off the raw map, tested at samples with
    the slack :data:`SEARCH_MARGIN_CELLS` (the first grid's margin: room for the smoother)
    or :data:`FOOTPRINT_SLACK_CELLS` refined down to :data:`FOOTPRINT_MIN_SLACK_CELLS`
    near obstacles (the second grid). The search's ``fine_radius`` (finer states near the
    end poses when a small region is exhausted) is used only by the tight search
    (:func:`tight_motion`), after the ordinary ones exhausted their states: as the first
    search on the parking suite at 0.1 m (half a body length, factor 3) it planned one
    case more of 40 (a slot 1.23 car lengths long, 20 cusps) at 1.4x the median and 1.9x
    the p95 plan time.

    On the grid inflated by the radius alone only the cell centres keep the radius; the
    search's exact mode (:func:`astar.find_pose_path` ``clearance``) makes the polyline of
    its poses keep it too, as the corridor requires, to within :data:`EXACT_TOL_M`.
    """
    if robot.footprint is not None:
        fp = np.asarray(robot.footprint.vertices, dtype=float) / grid.resolution
        return {
            "raw_grid": grid,
            "footprint": fp,
            "footprint_margin": FOOTPRINT_TOL_CELLS,
            "footprint_slack": (
                SEARCH_MARGIN_CELLS
                if margin
                else max(FOOTPRINT_SLACK_CELLS, FOOTPRINT_SLACK_M / grid.resolution)
            ),
            "footprint_min_slack": None if margin else FOOTPRINT_MIN_SLACK_CELLS,
        }
    if margin:
        return {}
    r_cells = robot.radius / grid.resolution - EXACT_TOL_M / grid.resolution
    return {"raw_grid": grid, "clearance": r_cells}


def grid_name(margin: bool) -> str:
    """Return the name of a search grid in the tries' messages (with or without margin)."""
    return "radius + margin grid" if margin else "radius grid"


def blocked_end(
    robot: Robot,
    search_grid: OccupancyGrid,
    margin: bool,
    ends: Sequence[tuple[str, ArrayLike, np.ndarray]],
) -> str | None:
    """Return why an end point's cell is blocked on ``search_grid``, or None."""
    for name, c, p in ends:
        ix, iy = int(math.floor(c[0] + 0.5)), int(math.floor(c[1] + 0.5))
        if search_grid.occupied[iy, ix]:
            extra = f" plus {SEARCH_MARGIN_CELLS:.3g} cells" if margin else ""
            return (
                f"{name} {p.tolist()} m lies in cell ({ix}, {iy}), blocked on the car's search "
                f"grid (robot radius {robot.radius} m{extra}); move it towards free space"
            )
    return None


def failure(
    robot: Robot,
    grid: OccupancyGrid,
    start: ArrayLike,
    goal: ArrayLike,
    tries: list[str],
    failures: list[Exception],
) -> Exception:
    """Return the error of a car's plan that no try completed (module docstring)."""
    if failures and isinstance(failures[-1], astar.NoEscapeError):
        last = failures[-1]
        err = NoPathError(
            f"no path of a car-like robot (turning radius {robot.drive.min_turning_radius} m) "
            f"from pose {pose_m(start, grid)} to pose {pose_m(goal, grid)}: no search found a "
            f"path, and the escape out of the tight end pose found nothing "
            f"({last.reason}, {last.expanded} expansions): {last} (tries: {'; '.join(tries)})"
        )
        err.__cause__ = last
        return err
    fits = [f for f in failures if isinstance(f, SmoothingError)]
    searches = [f for f in failures if isinstance(f, astar.NoPosePathError)]
    summary = "; ".join(tries)
    if fits:  # a path was found, and no curve fits it
        return SmoothingError(f"{fits[-1]} (tries: {summary})", {"car_tries": tries})
    if searches:
        last = searches[-1]
        mode = (
            "forwards and backwards"
            if robot.drive.reverse
            else "forwards only (reverse=False): no forward-only path was found; a goal only "
            "reachable backwards needs reverse=True"
        )
        err = NoPathError(
            f"no path of a car-like robot (turning radius {robot.drive.min_turning_radius} m, radius "
            f"{robot.radius} m) driving {mode}, from pose {pose_m(start, grid)} to pose "
            f"{pose_m(goal, grid)} ({last.reason}): {last} (tries: {summary})"
        )
        err.__cause__ = last
        return err
    return failures[-1]


def safety_net_error(why: str, tries: list[str], cause: Exception | None = None) -> NoPathError:
    """Return the error of a car's plan stopped by a wall-clock safety net (module docstring).

    The expansion caps decide a plan; a safety net fires only when the machine is far slower
    or busier than the constants assume, and the plan stops there rather than go on to a try
    that a quiet machine would not have reached.
    """
    err = NoPathError(
        f"no car plan: {why}. The wall-clock limits are safety nets far above normal search "
        "times (the expansion caps decide the plan); on this machine's load the answer would "
        f"depend on timing, so the plan stops (tries: {'; '.join(tries) or 'none'})"
    )
    err.__cause__ = cause
    return err


def pose_m(c: ArrayLike, grid: OccupancyGrid) -> str:
    """Return a cell pose ``(x, y, heading)`` (cells, rad) written in world units (m, rad)."""
    x = grid.origin[0] + (c[0] + 0.5) * grid.resolution
    y = grid.origin[1] + (c[1] + 0.5) * grid.resolution
    return f"({x:.6g} m, {y:.6g} m, {c[2]:.6g} rad)"
