"""A new route when no re-timing along the planned path avoids the movers.

A speed profile along a fixed path cannot avoid a mover that stops on it, or one that comes
head-on along a corridor (Fraichard's incompleteness of the path-speed split). When
:func:`~trajopt.moving.retime_chain` raises :class:`~trajopt.errors.BlockedError`,
:func:`reroute` tries a few other plans, in this order, each planned by the caller's
``plan_leg`` on a map the movers' swept regions are marked on (:mod:`._swept`), then re-timed
for **all** the movers and certified (:func:`~trajopt.moving.certify_movers`):

1. ``"rerouted"``: the same query on the map with every mover's final place marked (where
   each stands after its prediction ends; the cells whose square meets its bounding disc
   grown by the margin, :func:`~trajopt.moving.mark_swept`, and the planner inflates them by
   the robot's radius as any obstacle): a route that no mover stays on; its re-timing waits
   at the start, or on the way, while a mover still passes (the waiting witness of the
   issue, whose route is planned on the same marks), usually the smallest detour;
2. ``"rerouted"``: the same query with the blocking mover's swept region marked where the
   robot may meet it (:func:`~trajopt.moving.reached_swept_mask`): the cells it covers only
   before a robot from the start at its top speed (forwards or backwards) could come near
   them are left free (it has passed by then), and so are those it first covers only after
   :data:`LATE_FACTOR` times that earliest time plus :data:`LATE_S` (the robot has likely
   passed them by then; the re-timing decides): a way round where they would meet, often
   the static path but for a side step (a mover coming head-on); then with the cells it
   covers at any time a robot could be near them marked (the first rule alone: a way that
   meets it nowhere it could still be, after it has passed); then its whole swept region: a
   way that never meets it, so its re-timing is mostly the certificate alone; then its region
   over ``[t, t_last]`` only (``t`` the time from which it blocks): a way round where it
   stops, or round the rest of its track;
3. ``"waited"``: drive to a **safe place**, wait there until the way is clear, drive to the
   goal. A safe place is a cell
   where the robot's centre may stand on the static map and that keeps the robot's radius
   plus the margin from every mover's whole swept region; the candidates, at least a metre apart, are those with the shortest
   straight-line detour ``|start - p| + |p - goal|``. The first leg is re-timed for the movers
   (standing at the safe place is safe whenever it arrives), the second leg, from the first's
   end heading (a turn in place), on the clock from the first's arrival
   (:func:`~trajopt.moving.shift_clock`); the two are one chain, certified by the two legs'
   certificates on their clocks (the first's until the last prediction ends, the robot
   standing at the safe place from its arrival; the second's from then on). A car, which cannot turn in
   place, stands there with a heading (:func:`car_headings`: towards the goal, else along its
   way in); the second leg leaves with the first's end heading and last steering angle.

A detour round where the robot may (or could) meet the blocking mover whose path is longer
than :data:`LONG_WAY_FACTOR` times the blocked path's plus :data:`LONG_WAY_M` (going back
round a loop, say) is kept aside, the detours after it not tried: the waits of option 3 are,
and the earlier arrival of the kept detour and the first wait that works is returned (the
kept detour when none works).

Given the blocked path's points (``path``), the detours of options 1 and 2 whose marks keep
clear of it (no marked cell within the robot's radius of a point beyond the start's and the
goal's kept discs) are tried after the others, in the same order: their map leaves the blocked
path open, so their plan likely takes it again (a mover's final place behind the robot, say).

Such a detour's plan is first given the quick proofs (:func:`~trajopt.moving.parked_on_path`,
:func:`~trajopt.moving.no_way_past`), which refuse a blocked one in milliseconds, before the
re-timing's search. Given the caller's ``sketch`` (the search's grid path on a map, no
corridor or smoothing), such a detour whose grid path stays within :data:`FOLLOWS_RADII` robot
radii of the blocked path is tried after the waits instead: its plan would take that path
again. A candidate whose map has no path, whose plan fails or whose re-timing is
blocked is skipped (its reason and wall time kept). When none works, the original :class:`BlockedError` is raised again (it
names the mover and the time) with the reasons appended. None is tried when a mover ends
standing on the goal (its final shape closer than the robot's inscribed radius plus the margin
to the goal point, for ever): every route ends there (:func:`goal_taken`).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from astar.grid import OccupancyGrid
from trajopt.errors import BlockedError, TrajoptError
from trajopt.motion import TrajectoryChain
from trajopt.moving._certificate import point_polygon_distance, shape_at
from trajopt.moving._chain import retime_chain, shift_clock
from trajopt.moving._no_way_past import no_way_past
from trajopt.moving._obstacle import MovingObstacle
from trajopt.moving._parked import parked_on_path, path_curves
from trajopt.moving._swept import mark_swept, swept_cells, swept_mask

#: The first detour round the blocking mover (option 2) leaves free the cells it first covers
#: after this many times the earliest time a robot could be near them, plus
#: :data:`LATE_S` (s): measured on ``benchmarks/bench_moving_reroute.py``'s 30 head-on
#: queries, (1.25, 1 s), (1.5, 2 s) and (2, 3 s) all give a certified route on the first
#: try, arriving 1.04x the static plan's time (median).
LATE_FACTOR = 1.5
#: See :data:`LATE_FACTOR` (s).
LATE_S = 2.0
#: A detour round where the robot may meet the blocking mover whose path is longer than
#: this many times the blocked path's, plus :data:`LONG_WAY_M` (m), is kept aside while the
#: waits are tried (the earlier arrival of it and the first wait that works is returned):
#: the detours of ``benchmarks/bench_moving_reroute.py``'s head-on queries are at most 1.7x
#: the static path; going back round a loop instead of waiting in a niche is 2.5x.
LONG_WAY_FACTOR = 1.5
#: See :data:`LONG_WAY_FACTOR` (m).
LONG_WAY_M = 2.0
#: Safe places tried (option 3).
N_SAFE_PLACES = 2
#: Smallest distance (m) between two safe places tried.
SAFE_PLACE_SPACING = 1.0
#: A detour's grid path follows the blocked path when every point of it (beyond the kept
#: discs) is within this many robot radii of the blocked path's points: the grid path of a
#: curve in the same corridor strays from the smoothed one by up to about two radii at
#: corners (0.43 m for 0.165 m on the benchmark maps), another way by far more.
FOLLOWS_RADII = 3.0

#: ``plan_leg(grid, start, goal, start_heading, goal_heading=None, start_steer=0.0)``: a plan
#: from rest to rest on ``grid`` (the planner's stages and options), raising a
#: :class:`TrajoptError` when it fails. ``start`` ``None``: the query's start (with its
#: heading and steering); else a point (m) left with ``start_heading`` (rad) and a car's
#: steering angle ``start_steer`` (rad). ``goal`` ``None``: the query's goal (with its heading);
#: else a point (m) reached with ``goal_heading`` (rad; ``None``: free, a car needs one).
PlanLeg = Callable[..., Any]


def reroute(
    start: np.ndarray,
    goal: np.ndarray,
    robot: Any,
    movers: Sequence[MovingObstacle],
    margin: float,
    blocked: BlockedError,
    *,
    grid: OccupancyGrid,
    free: Callable[[], np.ndarray],
    plan_leg: PlanLeg,
    path: np.ndarray | None = None,
    sketch: Callable[[OccupancyGrid], np.ndarray] | None = None,
    label: Callable[[np.ndarray], np.ndarray] | None = None,
    length: float | None = None,
) -> Any:
    """Return a certified plan by another route or a wait at a safe place (module docstring).

    Parameters
    ----------
    start, goal : ndarray, shape (2,)
        The query's ends (m): those of the static plan whose re-timing is blocked.
    robot : Robot
        The robot (its radius, drive and limits).
    movers : sequence of MovingObstacle
        The predictions.
    margin : float
        Extra distance to every mover (m).
    blocked : BlockedError
        The proof that the static plan's path is blocked, or what its re-timing raised (its
        ``mover`` and ``t``).
    grid : astar.OccupancyGrid
        The raw map.
    free : callable
        ``free()``: where the robot's centre may stand on the static map, bool, shape
        (ny, nx) (the planner's inflated grid's free cells in the start's connected part);
        called only when a wait at a safe place is tried.
    plan_leg : callable
        ``plan_leg(grid, start, goal, start_heading, goal_heading, start_steer)``
        (:data:`PlanLeg`).
    path : ndarray, shape (n, 2), optional
        Points (m) of the blocked path from ``start`` to ``goal``: the detours whose marks keep
        clear of it are tried after the others (module docstring).
    sketch : callable, optional
        ``sketch(grid)``: the points (m, shape (k, 2)) of the search's grid path of the query
        on a marked map, a :class:`TrajoptError` when there is none. With ``path``, a detour
        whose marks keep clear of the blocked path and whose sketch follows it is tried after
        the waits (module docstring).
    label : callable, optional
        ``label(occupied)``: the 4-connected components of the cells not occupied (bool,
        shape (ny, nx)), an int array of that shape, 0 on occupied cells and one positive
        label per component (the planner's own labelling); used to keep the safe places the
        goal is joined to. ``None``: :func:`scipy.ndimage.label` of the free cells (the same
        partition; its import costs a process's first wait about 0.1 s).
    length : float, optional
        The blocked path's length (m); ``None``: that of ``path``'s polyline, at least
        ``|goal - start|``. A detour round where the robot may meet the mover longer than
        :data:`LONG_WAY_FACTOR` times it plus :data:`LONG_WAY_M` is kept aside while the
        waits are tried (module docstring).

    Returns
    -------
    PlanResult
        Certified; ``stats["moving"]["route"]`` is ``"rerouted"`` or ``"waited"``,
        ``stats["moving"]["reroute"]`` lists the candidates tried (``what``, ``result``,
        ``time_s``, the wall time of each) and ``stats["moving"]["reroute_time_s"]`` the
        wall time of all.

    Raises
    ------
    BlockedError
        No candidate works: ``blocked``'s mover and time, the candidates' reasons appended.
    """
    t_all = time.perf_counter()
    p0 = np.asarray(start, dtype=float).reshape(2)
    p1 = np.asarray(goal, dtype=float).reshape(2)
    keep = [(p0, robot.radius + 2.0 * grid.resolution), (p1, robot.radius + 2.0 * grid.resolution)]
    by_name = {m.name: m for m in movers}
    tried: list[dict[str, str]] = []
    t_last = max(max(m.t_last for m in movers), 0.0)
    taken = goal_taken(movers, p1, float(robot.inscribed_radius) + margin)
    if taken is not None:
        raise BlockedError(
            f"{blocked} (no re-route either: {taken.name!r} stands on the goal from "
            f"t = {max(taken.t_last, 0.0):.3f} s, where every route ends)",
            mover=blocked.mover,
            t=blocked.t,
        ) from blocked

    def finish(out: Any) -> Any:  # a kept detour returned after the waits: every try listed
        out.stats["moving"] = dict(out.stats["moving"], reroute=list(tried))
        out.stats["moving"]["reroute_time_s"] = time.perf_counter() - t_all
        return out

    def attempt(what: str, run: Callable[[], Any], route: str) -> Any:
        t0 = time.perf_counter()
        try:
            out = run()
        except TrajoptError as exc:
            tried.append(
                {
                    "what": what,
                    "result": f"{type(exc).__name__}: {exc}",
                    "time_s": time.perf_counter() - t0,
                }
            )
            return None
        tried.append({"what": what, "result": "ok", "time_s": time.perf_counter() - t0})
        stats = out.stats
        stats["moving"] = dict(stats["moving"], route=route, reroute=list(tried))
        stats["moving"]["reroute_time_s"] = time.perf_counter() - t_all
        return out

    marked_maps: list[OccupancyGrid] = []
    marks: dict[int, OccupancyGrid | None] = {}

    def mark(i: int) -> OccupancyGrid | None:  # candidate i's map, marked once
        if i not in marks:
            marks[i] = mark_swept(grid, detours[i][1], margin, keep, *reaches.get(i, (None,)))
        return marks[i]

    def detour(i: int, prove: bool = False) -> Callable[[], Any]:
        def run() -> Any:
            marked = mark(i)
            if marked is None:
                raise BlockedError("the marked region adds no cell to the map")
            if any(np.array_equal(marked.occupied, m.occupied) for m in marked_maps):
                raise BlockedError("the same map as a candidate tried before")
            marked_maps.append(marked)
            leg = plan_leg(marked, None, None, None)
            if prove:  # before the re-timing's search, which would end in it
                proof = parked_on_path(leg, movers, margin) or no_way_past(leg, movers, margin)
                if proof is not None:
                    raise proof
            return retime_chain(leg, movers, margin=margin)

        return run

    finals = [(m, max(m.t_last, 0.0), max(m.t_last, 0.0)) for m in movers]
    detours = [("around every mover's final place", finals)]
    # detours marked where the robot may meet the mover: (origin, speed, slack), late rule
    reaches: dict[int, tuple[tuple[np.ndarray, float, float], tuple[float, float]]] = {}
    who = by_name.get(blocked.mover)
    if who is not None:
        t_end = max(who.t_last, 0.0)
        t_from = min(max(blocked.t, 0.0), t_end)
        t_all_of = min(0.0, float(who.times[0]))
        back = getattr(robot.drive, "v_max_backwards", None)  # a car may reverse faster
        top = max(float(robot.v_max), float(back(robot)) if back is not None else 0.0)
        reach = (p0, top, float(robot.radius))
        reaches[len(detours)] = (reach, (LATE_FACTOR, LATE_S))
        detours.append(
            (f"around {who.name!r} where the robot may meet it", [(who, t_all_of, t_end)])
        )
        reaches[len(detours)] = (reach, (0.0, 0.0))
        detours.append(
            (f"around {who.name!r} where the robot could meet it", [(who, t_all_of, t_end)])
        )
        spans = [(t_all_of, "")]
        if t_from > 0.0:
            spans.append((t_from, f" from t = {t_from:.3f} s"))
        for t0, when in spans:
            detours.append((f"around {who.name!r}{when}", [(who, t0, max(t_end, t0))]))
    clear = [False] * len(detours)
    pts = np.zeros((0, 2))
    if path is not None:
        pts = _beyond(np.asarray(path, dtype=float).reshape(-1, 2), keep)
        seen: dict[tuple[tuple[int, float, float], ...], bool] = {}  # the same regions once
        for i, (_, regions) in enumerate(detours):
            key = tuple((id(m), t0, t1) for m, t0, t1 in regions)
            if key not in seen:
                seen[key] = _keeps_clear(grid, regions, margin + robot.radius, pts)
            clear[i] = seen[key]
    order = [i for i, c in enumerate(clear) if not c] + [i for i, c in enumerate(clear) if c]
    late: list[int] = []  # detours whose sketch follows the blocked path: after the waits
    kept = None  # a detour round where the robot may meet the mover, too long to take at once
    if length is None:
        along = np.zeros((0, 2)) if path is None else np.asarray(path, dtype=float).reshape(-1, 2)
        length = float(np.sum(np.hypot(*np.diff(along, axis=0).T))) if along.shape[0] > 1 else 0.0
        length = max(length, math.hypot(*(p1 - p0)))
    long_way = LONG_WAY_FACTOR * float(length) + LONG_WAY_M
    for i in order:
        what, regions = detours[i]
        if clear[i] and sketch is not None and pts.shape[0] and mark(i) is not None:
            t0 = time.perf_counter()
            try:
                drawn = sketch(mark(i))
            except TrajoptError as exc:
                tried.append(
                    {
                        "what": what,
                        "result": f"{type(exc).__name__}: {exc}",
                        "time_s": time.perf_counter() - t0,
                    }
                )
                continue
            if _follows(drawn, pts, keep, FOLLOWS_RADII * float(robot.radius)):
                late.append(i)
                continue
        out = attempt(what, detour(i, prove=clear[i]), "rerouted")
        if out is not None and i in reaches and _path_length(out) > long_way:
            kept = out  # a long way round: a wait may arrive sooner
            tried[-1]["result"] = (
                f"ok, kept: {_path_length(out):.2f} m, longer than {long_way:.2f} m"
            )
            break
        if out is not None:
            return out
    turns = robot.drive.turns_in_place and not robot.drive.signed_speed
    if turns or not robot.drive.turns_in_place:  # a car stands at the place with a heading
        room = free()
        places = safe_places(grid, room, movers, robot.radius + margin, p0, p1, t_last)
        places = _joined_at_last(grid, room, movers, robot.radius + margin, places, p1, label)
        for place in places:
            for heading in [None] if turns else car_headings(place, p0, p1):
                at = "" if heading is None else f", heading {heading:.3f} rad"
                out = attempt(
                    f"wait at ({place[0]:.2f}, {place[1]:.2f}) m{at}",
                    _wait_at(place, heading, movers, margin, grid, plan_leg),
                    "waited",
                )
                if out is not None and kept is not None and kept.duration < out.duration:
                    return finish(kept)
                if out is not None:
                    return out
    if kept is not None:
        return finish(kept)
    for i in late:
        out = attempt(detours[i][0], detour(i, prove=True), "rerouted")
        if out is not None:
            return out
    reasons = "; ".join(f"{c['what']}: {c['result']}" for c in tried)
    raise BlockedError(
        f"{blocked} (no re-route either: {reasons or 'none tried'})",
        mover=blocked.mover,
        t=blocked.t,
    ) from blocked


def around_final_places(
    start: np.ndarray,
    goal: np.ndarray,
    robot: Any,
    movers: Sequence[MovingObstacle],
    margin: float,
    retimed: Any,
    *,
    grid: OccupancyGrid,
    plan_leg: PlanLeg,
    path: np.ndarray,
) -> Any:
    """Return the earlier of ``retimed`` and the route round the movers' final places.

    ``retimed``: the static plan re-timed for the movers (certified), whose path ``path``
    (points, m, shape (n, 2)) is the static plan's. When it waits (it arrives later than the
    path's own drive, ``stats["moving"]["plan"]`` not ``"as planned"``) and a mover's final
    place, grown by the margin and the robot's radius, covers a point of the path beyond the
    kept discs at its ends, the first candidate of :func:`reroute` is planned too (the same
    query on the map with every mover's final place marked), re-timed for all the movers and
    certified: the waiting witness's construction (rest at the start while a mover passes,
    then the route round the final places) is among its re-timings, and a wait on the static
    path may last longer than one on that route (a mover that ends beside the path holds the
    static path's timing back). The earlier arrival is returned; the route's with
    ``stats["moving"]["route"] == "rerouted"``. Either way ``stats["moving"]["final_places"]``
    tells what was tried (``what``, ``result``, ``time_s``); a failed candidate (no path, a
    blocked re-timing) leaves ``retimed``.
    """
    t0 = time.perf_counter()
    mv = retimed.stats["moving"]
    if mv.get("plan") == "as planned" or not movers:
        return retimed
    p0 = np.asarray(start, dtype=float).reshape(2)
    p1 = np.asarray(goal, dtype=float).reshape(2)
    keep = [(p0, robot.radius + 2.0 * grid.resolution), (p1, robot.radius + 2.0 * grid.resolution)]
    finals = [(m, max(m.t_last, 0.0), max(m.t_last, 0.0)) for m in movers]
    pts = _beyond(np.asarray(path, dtype=float).reshape(-1, 2), keep)
    if _keeps_clear(grid, finals, margin + robot.radius, pts):
        return retimed  # the marks would leave the static path as it is
    what = "around every mover's final place"
    try:
        marked = mark_swept(grid, finals, margin, keep)
        if marked is None:
            raise BlockedError("the marked region adds no cell to the map")
        out = retime_chain(plan_leg(marked, None, None, None), movers, margin=margin)
    except TrajoptError as exc:
        result, out = f"{type(exc).__name__}: {exc}", None
    else:
        result = f"ok, arrives at {float(out.duration):.3f} s"
    took = time.perf_counter() - t0
    tried = {"what": what, "result": result, "time_s": took}
    if out is not None and float(out.duration) < float(retimed.duration):
        out.stats["moving"] = dict(
            out.stats["moving"],
            route="rerouted",
            final_places=tried,
            reroute=[tried],
            reroute_time_s=took,
            blocked_before_timing=False,
        )
        return out
    retimed.stats["moving"] = dict(mv, final_places=tried)
    return retimed


def _path_length(plan: Any) -> float:
    """Return a plan's path length (m): its curves end to end."""
    return float(sum(float(c.length) for c in path_curves(plan)))


def _beyond(points: np.ndarray, keep: Sequence[tuple[np.ndarray, float]]) -> np.ndarray:
    """Return the points (m, shape (k, 2)) outside every kept disc (centre m, radius m)."""
    out = np.ones(points.shape[0], dtype=bool)
    for p, r in keep:
        out &= np.hypot(*(points - np.asarray(p, dtype=float)).T) > r
    return points[out]


def _follows(
    drawn: np.ndarray, path: np.ndarray, keep: Sequence[tuple[np.ndarray, float]], tol: float
) -> bool:
    """Whether every point of ``drawn`` (m) beyond the kept discs is within ``tol`` (m) of ``path``'s."""
    rest = _beyond(drawn, keep)
    for a in range(0, rest.shape[0], 256):
        d = np.hypot(
            rest[a : a + 256, None, 0] - path[None, :, 0],
            rest[a : a + 256, None, 1] - path[None, :, 1],
        )
        if np.any(np.min(d, axis=1) > tol):
            return False
    return True


def _keeps_clear(
    grid: OccupancyGrid,
    regions: Sequence[tuple[MovingObstacle, float, float]],
    grow: float,
    points: np.ndarray,
) -> bool:
    """Whether no swept region, grown by ``grow`` (m), covers the cell of any of ``points`` (m)."""
    if points.shape[0] == 0:
        return True
    cells = np.asarray(grid.world_to_cell(points), dtype=np.int64).reshape(-1, 2)
    ny, nx = grid.shape
    inside = (cells[:, 0] >= 0) & (cells[:, 0] < nx) & (cells[:, 1] >= 0) & (cells[:, 1] < ny)
    cells = cells[inside]
    for mover, t0, t1 in regions:
        if swept_cells(grid, mover, t0, t1, grow, cells).any():
            return False
    return True


def goal_taken(
    movers: Sequence[MovingObstacle], goal: np.ndarray, limit: float
) -> MovingObstacle | None:
    """Return a mover that stands on ``goal`` for ever, or ``None``.

    After its last prediction time a mover stands still with its last shape and radius; it is
    on the goal when that shape is closer than ``limit`` plus its radius (m) to ``goal`` (m,
    shape (2,)). A robot standing at the goal (any plan, from its arrival on) then meets it.
    """
    p = np.asarray(goal, dtype=float).reshape(1, 2)
    for m in movers:
        t = np.array([max(m.t_last, 0.0)])
        d = float(point_polygon_distance(p, shape_at(m, t))[0])
        if d < limit + float(m.radius_at(t[0])):
            return m
    return None


def safe_places(
    grid: OccupancyGrid,
    free: np.ndarray,
    movers: Sequence[MovingObstacle],
    clearance: float,
    p0: np.ndarray,
    p1: np.ndarray,
    t_last: float,
) -> list[np.ndarray]:
    """Return up to :data:`N_SAFE_PLACES` places (m) clear of every mover at every time.

    Cell centres free in ``free`` whose cell keeps ``clearance`` (m) from every mover's
    swept region over ``[0, t_last]`` (:func:`swept_mask`), by the shortest detour
    ``|p0 - p| + |p - p1|`` (ties: the lower row, then the lower column), each the first in
    that order at least :data:`SAFE_PLACE_SPACING` from those before it.

    The points of detour at most ``c`` fill an ellipse with foci ``p0`` and ``p1``: the
    places are chosen among the cells of detour at most ``c`` in that ellipse's bounding
    box, for a growing ``c``, until all are found there (no cell outside, of a larger
    detour, comes before them) or the box is the whole grid.
    """
    res = float(grid.resolution)
    ox, oy = (float(v) for v in grid.origin)
    ny, nx = grid.shape
    mid = 0.5 * (p0 + p1)
    f = 0.5 * math.hypot(*(p1 - p0))
    cos, sin = ((p1 - p0) / (2.0 * f)).tolist() if f > 0.0 else (1.0, 0.0)
    slack = 2.0 * SAFE_PLACE_SPACING
    while True:
        a = f + 0.5 * slack  # the ellipse's semi-axes
        b = math.sqrt(a * a - f * f)
        wx = math.hypot(a * cos, b * sin) + res
        wy = math.hypot(a * sin, b * cos) + res
        ix0 = max(0, int(math.floor((mid[0] - wx - ox) / res)))
        ix1 = min(nx - 1, int(math.floor((mid[0] + wx - ox) / res)))
        iy0 = max(0, int(math.floor((mid[1] - wy - oy) / res)))
        iy1 = min(ny - 1, int(math.floor((mid[1] + wy - oy) / res)))
        whole = ix0 == 0 and iy0 == 0 and ix1 == nx - 1 and iy1 == ny - 1
        c = math.inf if whole else 2.0 * f + slack
        places = _places_in(grid, free, movers, clearance, p0, p1, t_last, (ix0, ix1, iy0, iy1), c)
        if whole or len(places) == N_SAFE_PLACES:
            return places
        slack *= 3.0


def _places_in(
    grid: OccupancyGrid,
    free: np.ndarray,
    movers: Sequence[MovingObstacle],
    clearance: float,
    p0: np.ndarray,
    p1: np.ndarray,
    t_last: float,
    box: tuple[int, int, int, int],
    most: float,
) -> list[np.ndarray]:
    """Return :func:`safe_places`'s places (m) among the cells of ``box`` of detour <= ``most`` (m)."""
    ix0, ix1, iy0, iy1 = box
    res = float(grid.resolution)
    ox, oy = (float(v) for v in grid.origin)
    x = ox + (np.arange(ix0, ix1 + 1) + 0.5) * res
    y = oy + (np.arange(iy0, iy1 + 1) + 0.5) * res
    cost = np.hypot(x[None, :] - p0[0], y[:, None] - p0[1]) + np.hypot(
        x[None, :] - p1[0], y[:, None] - p1[1]
    )
    ok = free[iy0 : iy1 + 1, ix0 : ix1 + 1] & (cost <= most)
    for m in movers:
        if not ok.any():
            return []
        ok &= ~swept_mask(grid, m, min(0.0, float(m.times[0])), t_last, clearance, box)
    cost = np.where(ok, cost, np.inf)
    out: list[np.ndarray] = []
    while len(out) < N_SAFE_PLACES:
        k = int(np.argmin(cost))  # row-major: the first of equal detours is the lower row
        iy, ix = divmod(k, cost.shape[1])
        if not math.isfinite(float(cost[iy, ix])):
            break
        p = np.array([x[ix], y[iy]])
        out.append(p)
        cost[np.hypot(x[None, :] - p[0], y[:, None] - p[1]) < SAFE_PLACE_SPACING] = np.inf
    return out


def _joined_at_last(
    grid: OccupancyGrid,
    free: np.ndarray,
    movers: Sequence[MovingObstacle],
    clearance: float,
    places: Sequence[np.ndarray],
    goal: np.ndarray,
    label: Callable[[np.ndarray], np.ndarray] | None = None,
) -> list[np.ndarray]:
    """Return the ``places`` joined to ``goal`` once every mover stands at its final place.

    4-connected free cells of ``free`` less every mover's final shape grown by ``clearance``
    (the planner's search joins exactly the 4-connected free cells), labelled by ``label``
    (:func:`reroute`'s; ``None``: :func:`scipy.ndimage.label`). A wait helps only where the
    way on stays open after the movers have passed.
    """
    if not places:
        return []
    open_ = np.array(free)
    for m in movers:
        t = max(m.t_last, 0.0)
        open_ &= ~swept_mask(grid, m, t, t, clearance)
    if label is None:
        from scipy import ndimage  # only a re-route without the planner's labelling pays it

        labels, _ = ndimage.label(open_)
    else:
        labels = label(~open_)
    ny, nx = grid.shape

    def label(p: np.ndarray) -> int:
        ix, iy = (int(v) for v in grid.world_to_cell(np.asarray(p, dtype=float).reshape(1, 2))[0])
        return int(labels[iy, ix]) if 0 <= ix < nx and 0 <= iy < ny else 0

    at_goal = label(goal)
    return [p for p in places if at_goal > 0 and label(p) == at_goal]


def car_headings(place: np.ndarray, p0: np.ndarray, p1: np.ndarray) -> list[float]:
    """Return the headings (rad) a car is to stand with at a safe place, in the order tried.

    Facing on towards the goal (it then drives off forwards), then along the way it came from
    the start (it drives in forwards); one of them when both agree within a degree.
    """
    out: list[float] = []
    for a, b in ((place, p1), (p0, place)):
        d = np.asarray(b, dtype=float) - np.asarray(a, dtype=float)
        if math.hypot(*d) == 0.0:
            continue
        h = math.atan2(float(d[1]), float(d[0]))
        if all(abs(math.remainder(h - g, 2.0 * math.pi)) > math.radians(1.0) for g in out):
            out.append(h)
    return out


def _wait_at(
    place: np.ndarray,
    heading: float | None,
    movers: Sequence[MovingObstacle],
    margin: float,
    grid: OccupancyGrid,
    plan_leg: PlanLeg,
) -> Callable[[], Any]:
    """Return the wait at ``place`` (a car stands there with ``heading``, rad; else free)."""

    def run() -> Any:
        first = plan_leg(grid, None, place, None, heading, 0.0)
        first = retime_chain(first, movers, margin=margin)
        t1 = float(first.duration)
        end = first.sample(np.array([t1]))
        steer = 0.0 if getattr(end, "steer", None) is None else float(end.steer[0])
        seen = [shift_clock(m, t1) for m in movers]
        second = plan_leg(grid, place, None, float(end.theta[0]), None, steer)
        second = retime_chain(second, seen, margin=margin)
        pieces = _pieces(first) + _pieces(second)
        starts = _starts(first) + _starts(second)
        stats = dict(second.stats)
        chain = TrajectoryChain(tuple(pieces), first.robot, stats, second.steps, tuple(starts))
        summary = _certificate(first, second, t1)
        stats["moving"] = {
            "plan": (
                f"to ({place[0]:.2f}, {place[1]:.2f}) m: {first.stats['moving']['plan']}; "
                f"on at t = {t1:.3f} s: {second.stats['moving']['plan']}"
            ),
            "certificate": summary,
            "time_s": first.stats["moving"]["time_s"] + second.stats["moving"]["time_s"],
        }
        return chain

    return run


def _certificate(first: Any, second: Any, t1: float) -> dict[str, Any]:
    """Return the certificate summary of both legs as one chain, from the legs' own.

    Each leg's re-timing certified it (:func:`~trajopt.moving.certify_movers`): the first against the movers
    from ``t = 0`` until the last prediction ends, the robot standing at the safe place from
    its arrival ``t1`` (s) on; the second on the clock from ``t1`` until the last prediction
    ends, the robot standing at the goal from its arrival on. Together they cover the chain at
    every instant (before ``t1`` the first leg, after it the second), so the chain is
    certified without a third pass.
    """
    a = first.stats["moving"]["certificate"]
    b = second.stats["moving"]["certificate"]
    if not (a["ok"] and b["ok"]):  # each leg's re-timing raises first; kept as a guard
        raise BlockedError("a leg's certificate failed", mover=a["mover"] or b["mover"], t=t1)
    worst = a if a["slack_m"] <= b["slack_m"] else b
    return {
        "ok": True,
        "slack_m": worst["slack_m"],
        "mover": worst["mover"],
        "horizon_s": max(a["horizon_s"], t1 + b["horizon_s"]),
        "intervals": a["intervals"] + b["intervals"],
    }


def _pieces(plan: Any) -> list[Any]:
    """Return a re-timed plan's pieces (a flat chain's, or the one curve)."""
    return list(plan.pieces) if getattr(plan, "pieces", None) is not None else [plan]


def _starts(plan: Any) -> list[float]:
    """Return each flat piece's start time in it (a chain's ``starts``; 0 for one curve)."""
    if getattr(plan, "pieces", None) is None:
        return [0.0]
    return [float(s) for s in plan.starts]
