"""The last try of a car's plan: escapes out of tight end poses joined by a search.

Where an end pose holds the body a few centimetres from the polygons on both sides (a
perpendicular bay 1.20 car widths wide entered nose first off a 4.3 m aisle), the free poses
round it form a thin tube that the lattice searches of :mod:`trajopt.planning._car_tries`
exhaust without finding (they keep one pose per cell and heading bin).
:func:`escape_and_fit`, given to :func:`~trajopt.planning._car_tries.search_and_fit` as its
``last_try`` (run only when every other try failed, so a plan they find is the same with
or without it), searches the continuous poses from each tight end pose outwards
(:func:`astar.find_escape`: many short moves and cusps, every pose of every move exactly
clear of the polygons by a margin), joins the poses with room by an ordinary search
(:func:`astar.find_pose_path` on the radius grid, as the tight try searches), and fits every
segment of the whole path as the other tries do (:func:`~trajopt.planning._car_fit.fit_run`).
Expansion counts decide it, within the plan's (:func:`~trajopt.planning._car_tries.expansion_caps`);
the wall-clock safety nets stop the plan as for the other tries.
"""

from __future__ import annotations

import math

import numpy as np

import astar
from astar.grid import OccupancyGrid
from trajopt.errors import InvalidInputError, SmoothingError
from trajopt.planning._car_fit import fit_path
from trajopt.planning._car_tries import (
    FOOTPRINT_COSTS,
    FOOTPRINT_SEARCH_EXPANSIONS,
    SEARCH_SAFETY_S,
    CarFound,
    car_search_grid,
    exact_clearance,
    grid_name,
    safety_net_error,
)
from trajopt.planning._options import PlannerOptions
from trajopt.planning._query import StageTimer
from trajopt.robot import Robot
from trajopt.smoother import Smoother

#: The escape try (:func:`escape_and_fit`): its arcs' radius as a multiple of ``R`` (fitted
#: with :data:`~trajopt.planning._car_tries.TIGHT_KAPPA_MARGIN`: a segment at exactly ``1/R`` has no other curve), the
#: expansions of each end's escape search (:func:`astar.find_escape`) and of the search that
#: joins the escapes (its own caps: the plan's may be spent by the tries before it).
ESCAPE_FACTOR = 1.05
ESCAPE_EXPANSIONS = 300_000
ESCAPE_JOIN_EXPANSIONS = FOOTPRINT_SEARCH_EXPANSIONS
#: An end pose is tight (escaped from) when its body keeps less than this many escape
#: radii from the polygons; the escape ends at a pose that keeps as much (0.37 m for the
#: full-size car of the parking benchmarks, R = 3 m).
ESCAPE_ROOM_R = 0.35 / 3.0
#: The escape's shortest move (cells of the map): the fits of the small car's moves of
#: 1 cm between cusps on 5 cm cells (0.2 cells) ran their QP solver out of iterations.
ESCAPE_SHORTEST_CELLS = 0.3
#: The poses' spacing (cells) of the joined path (the search's own sample step).
ESCAPE_STEP_CELLS = 0.5


def escape_applies(robot: Robot, grid: OccupancyGrid) -> bool:
    """Return whether the escape try may run: a car with a body that reverses, on polygons.

    The escape tests the body exactly against the map's polygons
    (:attr:`astar.OccupancyGrid.polygons`); without them, or for a car that only drives
    forwards (the escape backs and fills), it is not tried.
    """
    return (
        robot.footprint is not None
        and robot.drive.reverse
        and grid.polygons is not None
        and len(grid.polygons) > 0
    )


def escape_and_fit(
    options: PlannerOptions,
    grid: OccupancyGrid,
    cells: tuple[tuple[float, float, float], tuple[float, float, float]],
    smoother: Smoother,
    timer: StageTimer,
    tries: list[str],
    failures: list[Exception],
    left: int,
) -> CarFound | None:
    """Run the last try of a car's plan: escapes out of tight end poses joined by a search.

    Run after every other try failed (:func:`~trajopt.planning._car_tries.search_and_fit`).
    An end pose is tight when its body keeps less than :data:`ESCAPE_ROOM_R` times the
    escape's radius from the map's polygons; from each tight end, :func:`astar.find_escape`
    (arcs at :data:`ESCAPE_FACTOR` ``R``, at most :data:`ESCAPE_EXPANSIONS`, both turning
    senses in turn) searches a way out to a pose with room: from the start forwards in
    time, from the goal backwards (:func:`astar.reversed_pieces`).
    :func:`astar.find_pose_path` joins the two poses with room on the radius grid as the
    tight try searches it (:func:`~trajopt.planning._car_tries.exact_clearance`,
    :data:`~trajopt.planning._car_tries.FOOTPRINT_COSTS`, at most
    :data:`ESCAPE_JOIN_EXPANSIONS`); where it finds no path (an escape that left the car
    turned the wrong way in a narrow aisle), the escapes run once more, each turning the
    car the other way only, and the search again. Every segment of the whole path is fitted
    with ``smoother`` (its ``kappa_margin`` raised to
    :data:`~trajopt.planning._car_tries.TIGHT_KAPPA_MARGIN`) as the other tries' are.

    Parameters
    ----------
    options, grid, cells, timer
        As :func:`~trajopt.planning._car_tries.search_and_fit`.
    smoother : Smoother
        The tight fits' smoother.
    tries, failures : list
        The tries so far and their failures; this try's are appended.
    left : int
        The plan's expansions left (:func:`~trajopt.planning._car_tries.expansion_caps`):
        the searches of this try share them, each capped as well by its own cap.

    Returns
    -------
    CarFound or None
        None when no end is tight or a step failed (its failure appended).

    Raises
    ------
    NoPathError
        A search ran into its wall-clock safety net
        (:func:`~trajopt.planning._car_tries.safety_net_error`).
    """
    robot = options.robot
    res = grid.resolution
    ox, oy = grid.origin
    r_m = ESCAPE_FACTOR * robot.drive.min_turning_radius
    r_cells = r_m / res
    room = ESCAPE_ROOM_R * r_m
    body = np.asarray(robot.footprint.vertices, dtype=float)
    world = [(ox + (c[0] + 0.5) * res, oy + (c[1] + 0.5) * res, float(c[2])) for c in cells]
    clear = astar.bodies_distance(body, np.array(world), grid.polygons, room + 1.0)
    if np.all(clear >= room):
        return None  # no tight end: the tries before searched what this one would
    spent = 0
    # first turn each end's car towards the other end's heading (out of a bay entered nose
    # first, backwards in time, the car turns back to the heading it came with)
    toward = [
        1.0 if math.remainder(world[1 - e][2] - world[e][2], 2.0 * math.pi) >= 0.0 else -1.0
        for e in (0, 1)
    ]
    senses: list[tuple[float, ...]] = [(toward[0],), (toward[1],)]
    with timer.stage("inflate"):
        search_grid = car_search_grid(robot, grid, margin=False)
    for attempt in range(2):
        ends = list(cells)
        runs: list[np.ndarray] = [np.zeros((0, 5)), np.zeros((0, 5))]
        esc_failed = True  # until every tight end's escape is found
        for e, name in ((0, "start"), (1, "goal")):
            if clear[e] >= room:
                continue
            way = ("counter-clockwise", "clockwise")[int(senses[e][0] < 0.0)]
            label = f"escape from the {name} turning {way}"
            if spent >= left:
                tries.append(f"{label}: not tried (the plan's expansions spent)")
                return None
            try:
                with timer.stage("search"):
                    esc = astar.find_escape(
                        body,
                        world[e],
                        grid.polygons,
                        r_m,
                        room=room,
                        shortest=ESCAPE_SHORTEST_CELLS * res,
                        turns=senses[e],
                        max_expansions=min(ESCAPE_EXPANSIONS, left - spent),
                        time_budget=SEARCH_SAFETY_S,
                    )
            except astar.NoEscapeError as exc:
                spent += exc.expanded
                tries.append(f"{label}: none ({exc.reason}, {exc.expanded} expansions)")
                failures.append(exc)
                if exc.reason == "time_budget":
                    raise safety_net_error(
                        f"the {label} ran into its wall-clock safety net of "
                        f"{SEARCH_SAFETY_S:g} s ({exc.expanded} expansions)",
                        tries,
                        exc,
                    ) from exc
                break
            except astar.InvalidInputError as exc:  # the body at the end pose keeps no margin
                tries.append(f"{label}: {exc}")
                failures.append(InvalidInputError(str(exc)))
                return None
            spent += esc.expanded
            tries.append(f"{label}: {esc.cusps} cusps, {esc.expanded} expansions")
            run = esc.pieces if e == 0 else astar.reversed_pieces(esc.pieces)
            runs[e] = np.column_stack(
                [
                    (run[:, 0] - ox) / res - 0.5,
                    (run[:, 1] - oy) / res - 0.5,
                    run[:, 2],
                    run[:, 3] * res,
                    run[:, 4] / res,
                ]
            )
            ends[e] = ((esc.end[0] - ox) / res - 0.5, (esc.end[1] - oy) / res - 0.5, esc.end[2])
        else:
            esc_failed = False
        if esc_failed:
            if attempt == 0:
                senses = [(-toward[0],), (-toward[1],)]
                continue
            return None
        label = f"{grid_name(False)}, {ESCAPE_FACTOR:g} R, joining the escapes"
        if spent >= left:
            tries.append(f"{label}: not tried (the plan's expansions spent)")
            return None
        try:
            with timer.stage("search"):
                join = astar.find_pose_path(
                    search_grid,
                    tuple(ends[0]),
                    tuple(ends[1]),
                    turning_radius=r_cells,
                    reverse=True,
                    max_expansions=min(ESCAPE_JOIN_EXPANSIONS, left - spent),
                    time_budget=SEARCH_SAFETY_S,
                    **{**exact_clearance(robot, grid, False), **FOOTPRINT_COSTS},
                )
        except astar.NoPosePathError as exc:
            spent += int((exc.stats or {}).get("expanded", 0))
            tries.append(f"{label}: no path ({exc.reason})")
            failures.append(exc)
            if exc.reason == "time_budget" or any(
                sub["stop"] == "time_budget" for sub in (exc.stats or {}).get("searches", [])
            ):
                raise safety_net_error(
                    f"the search {label!r} ran into its wall-clock safety net of "
                    f"{SEARCH_SAFETY_S:g} s",
                    tries,
                    exc,
                ) from exc
            if attempt == 0 and exc.reason in ("exhausted", "disconnected"):
                # an escape's end the search cannot reach (a car turned the wrong way in a
                # narrow aisle): once more, each escape turning the other way
                senses = [(-toward[0],), (-toward[1],)]
                continue
            return None
        except astar.InvalidInputError as exc:
            tries.append(f"{label}: {exc}")
            failures.append(InvalidInputError(str(exc)))
            return None
        break
    spent += int(join.stats["expanded"])
    if any(sub["stop"] == "time_budget" for sub in join.stats["searches"]):
        raise safety_net_error(
            f"the search {label!r} ran into its wall-clock safety net (a share of "
            f"{SEARCH_SAFETY_S:g} s) before its expansion cap",
            tries,
        )
    arrays = astar.join_escape(
        [runs[0], np.asarray(join.pieces), runs[1]], cells[1], ESCAPE_STEP_CELLS
    )
    stats = {**join.stats, "escape_expanded": spent - int(join.stats["expanded"])}
    path = astar.PosePath(*arrays, r_cells, stats)
    poses = path.to_world(grid)
    try:
        segments = fit_path(options, grid, smoother, path, poses, res, timer)
    except SmoothingError as exc:
        tries.append(f"{label}: a segment has no fit")
        failures.append(exc)
        return None
    tries.append(f"{label}: planned")
    return CarFound(search_grid, path, r_cells, poses, segments, tries, spent)
