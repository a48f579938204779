"""A plan among predicted movers: the static plan re-timed, or re-routed when blocked.

:func:`plan_for_movers` turns a static plan of :func:`~trajopt.planning.run_query` into one
certified against the movers (:mod:`trajopt.moving`), planning the re-route's legs with the
same options on caches derived from the planner's. :meth:`trajopt.Planner.plan` and
:meth:`trajopt.Planner.replan` call it.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from types import SimpleNamespace
from typing import Any

import numpy as np

import astar
from astar.grid import OccupancyGrid
from trajopt.errors import BlockedError, InvalidInputError, NoPathError, TrajoptError
from trajopt.motion import PlanResult
from trajopt.moving import (
    MovingObstacle,
    around_final_places,
    goal_taken,
    meets_head_on,
    no_way_past,
    parked_on_path,
    reroute,
    retime_chain,
)
from trajopt.planning._caches import PlannerCaches, change_reach, component_labels
from trajopt.planning._options import PlannerOptions, PlanRequest
from trajopt.planning._runner import run_query
from trajopt.robot import Robot, State


@dataclass(frozen=True)
class _Curve:
    """A certified curve as the proofs read a plan: one curve of ``robot``, not yet timed."""

    path: Any
    robot: Robot
    own_orientation: bool = False
    single_curve: bool = True

    @property
    def length(self) -> float:
        return float(self.path.length)


#: The grid path screen (:class:`_GridScreen`) runs :func:`trajopt.moving.parked_on_path`
#: with the margin less this many robot radii: the search's grid path strays from the
#: certified curve fitted round it by up to 0.28 m (1.7 radii of 0.165 m; measured on 90
#: random queries on the shared maps), so a mover that parks this much closer to the grid
#: path than the limit parks within the limit of the curve.
SCREEN_SLACK_RADII = 2.0
#: The screen runs :func:`trajopt.moving.no_way_past` with the margin less this many robot
#: radii: smaller than the parked screen's, since a mover driving the curve strays from the
#: grid path at its corners (up to 0.28 m) and the sweep needs it near every node it holds;
#: measured on ``benchmarks/bench_moving_reroute.py``'s 30 head-on queries, half a radius
#: finds all 30, one radius 18.
HEAD_ON_SLACK_RADII = 0.5


class _Polyline:
    """A polyline as the quick proofs read a curve: arc length is its parameter (m)."""

    def __init__(self, points: np.ndarray):
        pts = np.asarray(points, dtype=float).reshape(-1, 2)
        keep = np.ones(pts.shape[0], dtype=bool)
        keep[1:] = np.any(pts[1:] != pts[:-1], axis=1)  # no zero-length segment
        self.points = pts[keep]
        seg = np.hypot(*np.diff(self.points, axis=0).T)
        self.s = np.concatenate([[0.0], np.cumsum(seg)])
        self.length = float(self.s[-1])

    def u_at_s(self, s: np.ndarray) -> np.ndarray:
        """Return the parameter (m) at arc lengths ``s`` (m): ``s`` clipped to the length."""
        return np.clip(np.asarray(s, dtype=float), 0.0, self.length)

    def __call__(self, u: np.ndarray) -> np.ndarray:
        """Return the points (m, shape (..., 2)) at parameters ``u`` (m)."""
        u = np.asarray(u, dtype=float)
        if self.points.shape[0] == 1:
            return np.broadcast_to(self.points[0], (*u.shape, 2)).copy()
        x = np.interp(u, self.s, self.points[:, 0])
        y = np.interp(u, self.s, self.points[:, 1])
        return np.stack([x, y], axis=-1)


#: The screen's robot faces the grid path's point this far along (m), not its first step, which
#: may be 45 degrees or more off the curve (:func:`trajopt.moving.meets_head_on` then missed 2
#: of ``benchmarks/bench_moving_reroute.py``'s 60 head-on and trapped queries; 0.1-1 m: none).
GRID_HEADING_M = 0.25


@dataclass(frozen=True)
class _GridCurve(_Curve):
    """A grid path (:class:`_Polyline`) as the quick proofs and their screen read a plan."""

    def sample(self, t: np.ndarray) -> SimpleNamespace:
        """Return the start, at rest, facing :data:`GRID_HEADING_M` along (``t`` not read; shape (1,))."""
        p = self.path.points
        d = self.path(np.array([min(GRID_HEADING_M, self.path.length)]))[0] - p[0]
        theta = float(np.arctan2(d[1], d[0]))
        return SimpleNamespace(x=p[:1, 0], y=p[:1, 1], theta=np.array([theta]))


class _GridBlocked(Exception):
    """Raised through the stages by :class:`_GridScreen` when the grid path is found blocked."""

    def __init__(self, blocked: BlockedError, length: float):
        super().__init__(str(blocked))
        self.blocked = blocked
        self.length = length  # the grid path's (m)


class _GridScreen:
    """``request.check_grid_path`` of a plan among movers: the quick proofs on the grid path."""

    def __init__(self, movers: tuple[MovingObstacle, ...], margin: float, robot: Robot):
        self.movers, self.margin, self.robot = movers, margin, robot

    def __call__(self, points: np.ndarray) -> None:
        line = _Polyline(points)
        if line.length <= 0.0:
            return
        r = float(self.robot.radius)
        plan = _GridCurve(line, self.robot)
        blocked = None
        if meets_head_on(plan, self.movers, self.margin):  # cheap where none comes head-on
            blocked = no_way_past(plan, self.movers, self.margin - HEAD_ON_SLACK_RADII * r)
        if blocked is None:
            blocked = parked_on_path(plan, self.movers, self.margin - SCREEN_SLACK_RADII * r)
        if blocked is not None:
            raise _GridBlocked(blocked, line.length)


class _PathBlocked(Exception):
    """Raised through the stages by :class:`_CurveProof` when the curve is proved blocked."""

    def __init__(self, blocked: BlockedError, curve: Any):
        super().__init__(str(blocked))
        self.blocked = blocked
        self.curve = curve


class _CurveProof:
    """``request.check_curve`` of a plan among movers: the quick proofs on the curve."""

    def __init__(self, movers: tuple[MovingObstacle, ...], margin: float, robot: Robot):
        self.movers, self.margin, self.robot = movers, margin, robot
        self.ran = False

    def __call__(self, curve: Any) -> None:
        blocked = _quick_proofs(_Curve(curve, self.robot), self.movers, self.margin)
        self.ran = True
        if blocked is not None:
            raise _PathBlocked(blocked, curve)


def _quick_proofs(
    plan: Any, movers: tuple[MovingObstacle, ...], margin: float
) -> BlockedError | None:
    """Return the first quick proof that the plan's path is blocked, or ``None``."""
    blocked = parked_on_path(plan, movers, margin)
    if blocked is None:
        blocked = no_way_past(plan, movers, margin)
    return blocked


def _one_curve(robot: Robot, request: PlanRequest) -> bool:
    """Whether the static plan is the certified curve of the disc stages, timed from rest.

    A differential drive's disc robot (it turns in place, faces its travel, drives forwards)
    with no heading given and at rest at both ends plans one curve (:func:`~trajopt.planning.plan_turning` runs the disc stages,
    :func:`~trajopt.planning._disc.plan_disc`, once, on this request).
    """
    drive = robot.drive
    return (
        drive.turns_in_place
        and not drive.orients_body
        and not drive.signed_speed
        and robot.footprint is None
        and not isinstance(request.start, State)
        and request.start_heading is None
        and request.goal_heading is None
        and request.v_start == 0.0
        and request.v_end == 0.0
    )


def plan_among_movers(
    movers: tuple[MovingObstacle, ...],
    margin: float,
    options: PlannerOptions,
    caches: PlannerCaches,
    request: PlanRequest,
) -> PlanResult:
    """Plan a query among movers (:meth:`trajopt.Planner.plan` with ``moving_obstacles``).

    The static plan (:func:`~trajopt.planning.run_query`) made into one certified against
    the movers by :func:`plan_for_movers`. For a single curve (:func:`_one_curve`) the quick
    proofs (:func:`trajopt.moving.parked_on_path`, :func:`trajopt.moving.no_way_past`) run
    on the certified curve before the timing (``request.check_curve``): they read only the
    path and the robot's limits, so they decide there what they decide on the timed plan,
    and a path they prove blocked is re-routed at once (:func:`trajopt.moving.reroute`)
    without timing it.

    Before that, they screen the search's grid path (``request.check_grid_path``,
    :class:`_GridScreen`), before the corridor and the fit: with the margin less
    :data:`SCREEN_SLACK_RADII` robot radii for a parked mover and
    :data:`HEAD_ON_SLACK_RADII` for one that leaves no way past (run only where
    :func:`trajopt.moving.meets_head_on` finds a mover coming along the grid path against
    the robot; this one first, as ``meets_head_on`` costs little where no mover comes
    head-on), since the curve fitted round the grid path strays from it (up to 0.28 m
    measured). A grid path they find blocked is re-routed at once, the static plan neither
    fitted nor timed. The finding is on the grid path, not a proof on the curve: when no re-route works the query is planned
    again without the screen (its curve, proofs and re-timing decide, the re-route's
    candidates tried again if the curve is blocked too), so the screen never turns a plan into
    a :class:`BlockedError`; a mover that stands on the goal for ever
    (:func:`trajopt.moving.goal_taken`) ends every plan, and its error is raised at once. A
    curve that a re-timing would have got past is re-routed where the screen is wrong: the
    result is certified all the same (every candidate is), only not the static path.

    Parameters
    ----------
    movers : tuple of MovingObstacle
        The predictions (checked, non-empty).
    margin : float
        Extra distance to every mover (m).
    options : PlannerOptions
        The planner's options.
    caches : PlannerCaches
        The planner's caches of the map.
    request : PlanRequest
        The query.

    Returns
    -------
    PlanResult
        As :func:`plan_for_movers`; a re-route's ``stats["moving"]["blocked_before_timing"]``
        tells whether the static plan was proved blocked before its timing, and
        ``stats["moving"]["blocked_on_grid_path"]`` whether the screen of its grid path
        found it (the static plan then neither fitted nor timed).
    """
    proof = None
    asked = screened = request
    if _one_curve(options.robot, request):
        proof = _CurveProof(movers, margin, options.robot)
        asked = dataclasses.replace(request, check_curve=proof)
        screened = dataclasses.replace(
            asked, check_grid_path=_GridScreen(movers, margin, options.robot)
        )
    try:
        try:
            out = run_query(options, caches, screened)
        except _GridBlocked as found:
            try:
                return _reroute_early(
                    found.blocked, movers, margin, options, caches, request, found.length
                )
            except BlockedError:
                p1 = np.asarray(request.goal, dtype=float).reshape(2)
                limit = float(options.robot.inscribed_radius) + margin
                if goal_taken(movers, p1, limit) is not None:
                    raise  # every plan ends where a mover stands for ever
            out = run_query(options, caches, asked)  # the curve and its own proofs decide
    except _PathBlocked as stop:
        p0, p1 = _curve_ends(stop.curve)
        out = _reroute(
            p0, p1, options.robot, movers, margin, stop.blocked, options, caches, request,
            length=float(stop.curve.length),
        )  # fmt: skip
        out.stats["moving"]["blocked_before_timing"] = True
        out.stats["moving"]["blocked_on_grid_path"] = False
        return out
    return plan_for_movers(
        out, movers, margin, options, caches, request, proved=proof is not None and proof.ran
    )


def _reroute_early(
    blocked: BlockedError,
    movers: tuple[MovingObstacle, ...],
    margin: float,
    options: PlannerOptions,
    caches: PlannerCaches,
    request: PlanRequest,
    length: float,
) -> PlanResult:
    """Re-route the query whose grid path the quick proofs found blocked (``blocked``).

    :func:`trajopt.moving.reroute` from the query's ends, as for a blocked curve (the grid
    path's ``length``, m, as the blocked path's); raises its :class:`BlockedError` when no
    candidate works.
    """
    p0 = np.asarray(request.start, dtype=float).reshape(2)
    p1 = np.asarray(request.goal, dtype=float).reshape(2)
    out = _reroute(
        p0, p1, options.robot, movers, margin, blocked, options, caches, request, length=length
    )
    out.stats["moving"]["blocked_before_timing"] = True
    out.stats["moving"]["blocked_on_grid_path"] = True
    return out


def plan_from_stop(
    movers: tuple[MovingObstacle, ...],
    margin: float,
    options: PlannerOptions,
    caches: PlannerCaches,
    request: PlanRequest,
    along: Any = None,
) -> PlanResult:
    """Plan on among movers from where a re-plan stopped (:meth:`trajopt.Planner.replan`).

    Without ``along``, as :func:`plan_among_movers`. With it (the path the robot followed,
    from the stop, proved blocked: :class:`trajopt.replan.Along`), the re-route's candidates
    (:func:`trajopt.moving.reroute`) come first and the static plan from the stop last. Every
    re-timing along the followed path from the stop is blocked (the proof holds every motion
    along it from the splice state, a brake to this stop and any motion from rest after it
    included). The static plan from the stop is a new search on the same map to the same goal
    from a point of that path, so it takes the path's rest again unless the new grid path,
    its smoothing or the start heading leave it: it may differ, hence it is tried, after the
    re-route's candidates have failed, re-timed only (no second re-route), unless a mover
    stands on the goal for ever (:func:`trajopt.moving.goal_taken`), where every plan ends.

    Parameters
    ----------
    movers : tuple of MovingObstacle
        The predictions seen from the stop.
    margin : float
        Extra distance to every mover (m).
    options, caches, request
        The planner's options and caches, and the query from the stop (at rest).
    along : Along, optional
        ``along.blocked``: the proof (its time on the clock seen from the stop);
        ``along.points``: the followed path's points from the stop (m, shape (n, 2)).

    Returns
    -------
    PlanResult
        As :func:`plan_among_movers`.

    Raises
    ------
    BlockedError
        No candidate works and the static plan from the stop is blocked too (the proof's mover
        and time, every reason appended).
    """
    if along is None:
        return plan_among_movers(movers, margin, options, caches, request)
    p0 = np.asarray(request.start, dtype=float).reshape(2)
    p1 = np.asarray(request.goal, dtype=float).reshape(2)
    robot = options.robot
    try:
        out = _reroute(
            p0, p1, robot, movers, margin, along.blocked, options, caches, request, along.points
        )
    except BlockedError as exc:
        if goal_taken(movers, p1, float(robot.inscribed_radius) + margin) is not None:
            raise  # a mover stands on the goal for ever: the static plan ends there too
        try:
            static = run_query(options, caches, request)
            out = plan_for_movers(
                static, movers, margin, options, caches, request, reroute_blocked=False
            )
        except TrajoptError as last:
            raise BlockedError(
                f"{exc}; the static plan from the stop: {type(last).__name__}: {last}",
                mover=exc.mover,
                t=exc.t,
            ) from exc
        return out
    out.stats["moving"]["blocked_before_timing"] = True
    return out


def plan_for_movers(
    out: PlanResult,
    movers: tuple[MovingObstacle, ...],
    margin: float,
    options: PlannerOptions,
    caches: PlannerCaches,
    request: PlanRequest,
    *,
    proved: bool = False,
    reroute_blocked: bool = True,
) -> PlanResult:
    """Re-time a plan for movers, or re-route it; refuse what is not covered.

    The static plan is re-timed on one clock (:func:`trajopt.moving.retime_chain`), unless a
    mover parked on its path provably blocks it (:func:`trajopt.moving.parked_on_path`) or no
    re-timing provably gets past the movers (:func:`trajopt.moving.no_way_past`); when
    it is blocked, :func:`trajopt.moving.reroute` plans other routes on the map with the movers'
    swept regions marked (each leg planned by :func:`~trajopt.planning.run_query` with the
    planner's options, on caches derived from the planner's for the marked map). A re-timing
    that waits while a mover ends beside the path is compared with the route round the
    movers' final places, the earlier arrival kept (:func:`trajopt.moving.around_final_places`:
    the waiting witness's route, on which a shorter wait may do).

    Parameters
    ----------
    out : PlanResult
        The static plan of ``request``.
    movers : tuple of MovingObstacle
        The predictions.
    margin : float
        Extra distance to every mover (m).
    options, caches, request
        The planner's options and caches, and the query (its legs are planned with them).
    proved : bool
        The quick proofs already ran on ``out``'s path and found nothing (skipped here).
    reroute_blocked : bool
        ``False``: a blocked plan raises its :class:`BlockedError` instead of re-routing, and
        a re-timed one is returned as it is (no route round the final places either).
    """
    if out.v_start != 0.0:
        raise InvalidInputError(
            "moving_obstacles are covered for a plan from rest; this query gave a "
            f"{type(out).__name__} with v_start={out.v_start} m/s"
        )
    if out.polyline:
        raise InvalidInputError(
            "moving_obstacles are not covered for the stop-and-turn fallback's polyline "
            f"(stats['fallback'] = {out.stats.get('fallback')!r}): plan without the fallback"
        )
    blocked = None if proved else _quick_proofs(out, movers, margin)  # before the search's
    if blocked is None:
        try:
            kept = retime_chain(out, movers, margin=margin)
        except BlockedError as exc:
            blocked = exc
        else:
            kept.stats["moving"]["route"] = "retimed"
            if not reroute_blocked:
                return kept
            return _earlier_round_final_places(kept, out, movers, margin, options, caches, request)
    if not reroute_blocked:
        raise blocked
    p0, p1 = _plan_ends(out, request)
    out = _reroute(
        p0, p1, out.robot, movers, margin, blocked, options, caches, request,
        length=float(out.length),
    )  # fmt: skip
    out.stats["moving"]["blocked_before_timing"] = False
    return out


def _plan_ends(out: PlanResult, request: PlanRequest) -> tuple[np.ndarray, np.ndarray]:
    """Return a static plan's first and last points (m), each shape (2,), as a re-route reads them."""
    if out.single_curve and _one_curve(out.robot, request):  # as the proofs before the timing
        return _curve_ends(out.path)
    smp = out.sample(np.array([0.0, out.duration]))
    return (
        np.array([smp.x[0], smp.y[0]], dtype=float),
        np.array([smp.x[1], smp.y[1]], dtype=float),
    )


def _earlier_round_final_places(
    kept: PlanResult,
    out: PlanResult,
    movers: tuple[MovingObstacle, ...],
    margin: float,
    options: PlannerOptions,
    caches: PlannerCaches,
    request: PlanRequest,
) -> PlanResult:
    """Return the earlier of the re-timed static plan ``kept`` and the route round the final places.

    :func:`trajopt.moving.around_final_places` on the static plan ``out``'s path (its centre
    sampled at least every half cell), the route's leg planned as a re-route's
    (:func:`_leg_planner`): tried only when ``kept`` waits and a mover ends beside the path.
    """
    if kept.stats["moving"].get("plan") == "as planned":
        return kept
    grid = caches.grid
    n = int(math.ceil(float(out.length) / (0.5 * float(grid.resolution)))) + 2
    smp = out.sample(np.linspace(0.0, float(out.duration), n))
    path = np.stack([np.asarray(smp.x, dtype=float), np.asarray(smp.y, dtype=float)], axis=-1)
    p0, p1 = _plan_ends(out, request)
    plan_leg = _leg_planner(p0, out.robot, options, caches, request)[1]
    return around_final_places(
        p0, p1, out.robot, movers, margin, kept, grid=grid, plan_leg=plan_leg, path=path
    )


def _curve_ends(curve: Any) -> tuple[np.ndarray, np.ndarray]:
    """Return a curve's first and last points (m), each shape (2,)."""
    ends = np.asarray(curve(curve.u_at_s(np.array([0.0, float(curve.length)]))), dtype=float)
    return ends[0].copy(), ends[1].copy()


def _reroute(
    p0: np.ndarray,
    p1: np.ndarray,
    robot: Robot,
    movers: tuple[MovingObstacle, ...],
    margin: float,
    blocked: BlockedError,
    options: PlannerOptions,
    caches: PlannerCaches,
    request: PlanRequest,
    path: np.ndarray | None = None,
    length: float | None = None,
) -> PlanResult:
    """Re-route a blocked query (:func:`trajopt.moving.reroute`), its legs planned here.

    ``length``: the blocked path's (m; :func:`trajopt.moving.reroute`'s). The legs, the
    sketches and the free cells come from :func:`_leg_planner`.
    """
    free, plan_leg, sketch = _leg_planner(p0, robot, options, caches, request, path)
    return reroute(
        p0,
        p1,
        robot,
        movers,
        margin,
        blocked,
        grid=caches.grid,
        free=free,
        plan_leg=plan_leg,
        path=path,
        sketch=sketch if _disc_search(robot) else None,
        label=component_labels,
        length=length,
    )


def _leg_planner(
    p0: np.ndarray,
    robot: Robot,
    options: PlannerOptions,
    caches: PlannerCaches,
    request: PlanRequest,
    path: np.ndarray | None = None,
) -> tuple[Any, Any, Any]:
    """Return ``(free, plan_leg, sketch)`` of a re-route of ``request`` from ``p0`` (m).

    ``free()``: where the centre may stand on the static map, in the start's part
    (:func:`trajopt.moving.reroute`'s ``free``); ``plan_leg``: its ``plan_leg``, each leg
    planned by :func:`~trajopt.planning.run_query` with the planner's options; ``sketch``:
    the search's grid path on a marked map (:func:`_grid_path`).

    Each marked map's caches are derived once (:meth:`PlannerCaches.derived`), shared by its
    ``sketch`` and its plan. Given the blocked ``path`` (a re-plan from a stop on it, which
    stands in the blocking mover's swept region more often than not), a differential drive's
    disc leg whose start or goal is shut in on the marked map (:func:`shut_in`) is refused
    with a :class:`NoPathError` before the caches are derived.
    """

    def free() -> np.ndarray:  # where the centre may stand, in the start's part of the map
        inflated = np.asarray(caches.inflated.occupied)
        ix, iy = (int(c) for c in caches.grid.world_to_cell((float(p0[0]), float(p0[1]))))
        labels = caches.components
        return ~inflated & (labels == labels[iy, ix]) if labels[iy, ix] > 0 else ~inflated

    made: dict[int, tuple[OccupancyGrid, PlannerCaches]] = {}

    def caches_of(grid: OccupancyGrid) -> PlannerCaches:  # a marked map's, derived once
        if grid is caches.grid:
            return caches
        if id(grid) not in made:
            made[id(grid)] = (grid, caches.derived(grid))  # the grid kept: its id stays its own
        return made[id(grid)][1]

    def ends(a: np.ndarray | None, b: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
        start = request.start.position if isinstance(request.start, State) else request.start
        return (
            np.asarray(start if a is None else a, dtype=float).reshape(2),
            np.asarray(request.goal if b is None else b, dtype=float).reshape(2),
        )

    def refuse_shut_in(grid: OccupancyGrid, a: np.ndarray | None, b: np.ndarray | None) -> None:
        if path is None or grid is caches.grid or id(grid) in made or not _disc_search(robot):
            return  # not from a stop on the blocked path; the plan's own check is as cheap; or
            # the search is not the disc's
        p, q = ends(a, b)
        for name, here, there in (("start", p, q), ("goal", q, p)):
            if shut_in(caches, grid, here, there):
                raise NoPathError(
                    f"no path from start to goal on the marked map: the {name} "
                    f"({here[0]:.3f}, {here[1]:.3f}) m lies in a part of the inflated grid shut in "
                    f"within {SHUT_IN_CELLS} cells of it"
                )

    def sketch(grid: OccupancyGrid) -> np.ndarray:
        refuse_shut_in(grid, None, None)
        return _grid_path(caches_of(grid), *ends(None, None))

    def plan_leg(
        grid: OccupancyGrid,
        a: np.ndarray | None,
        b: np.ndarray | None,
        heading: float | None,
        goal_heading: float | None = None,
        start_steer: float = 0.0,
    ) -> PlanResult:
        refuse_shut_in(grid, a, b)
        leg = request
        if a is not None:
            leg = dataclasses.replace(
                leg,
                start=(float(a[0]), float(a[1])),
                start_heading=heading,
                start_steer=start_steer,
            )
        if b is not None:
            leg = dataclasses.replace(
                leg, goal=(float(b[0]), float(b[1])), goal_heading=goal_heading, goal_steer=None
            )
        return run_query(options, caches_of(grid), leg)

    return free, plan_leg, sketch


#: Half the side (cells) of the window round an end in which :func:`shut_in` looks.
SHUT_IN_CELLS = 24


def _disc_search(robot: Robot) -> bool:
    """Whether the robot's plans search its disc's inflated grid (a differential drive's disc)."""
    drive = robot.drive
    return (
        robot.footprint is None
        and drive.turns_in_place
        and not drive.orients_body
        and not drive.signed_speed
    )


def shut_in(caches: PlannerCaches, grid: OccupancyGrid, p: np.ndarray, other: np.ndarray) -> bool:
    """Whether the search from ``p`` (m) on ``grid`` provably cannot reach ``other`` (m).

    The search reaches exactly the 4-connected free cells of the inflated grid joined to the
    start's (:func:`~trajopt.planning._caches.component_labels`). They are labelled in the
    window of :data:`SHUT_IN_CELLS` cells round ``p``, its inflated cells exact
    (:meth:`PlannerCaches.inflated_window`): when ``p``'s part touches no side of the window
    but the map's own edges, it is the whole component, and ``other`` is reached only when
    its cell is in it. ``False`` when that does not settle it (the part reaches a side, or
    ``p``'s cell is not free, which the plan refuses itself) or when ``grid`` differs from
    the planner's map nowhere that reaches the window (nothing to look at).
    """
    ny, nx = grid.shape
    ix, iy = (int(v) for v in grid.world_to_cell(np.asarray(p, dtype=float)))
    if not (0 <= ix < nx and 0 <= iy < ny):
        return False
    k = SHUT_IN_CELLS
    x0, x1, y0, y1 = max(0, ix - k), min(nx - 1, ix + k), max(0, iy - k), min(ny - 1, iy + k)
    r = change_reach(caches.options, grid.resolution)[0]  # what reaches the window's cells
    near = (slice(max(0, y0 - r), y1 + r + 1), slice(max(0, x0 - r), x1 + r + 1))
    if np.array_equal(grid.occupied[near], caches.grid.occupied[near]):
        return False  # no mark near: the map the planner's own labels settle
    free = ~caches.inflated_window(grid, (x0, x1, y0, y1))
    if not free[iy - y0, ix - x0]:
        return False
    labels = component_labels(~free)
    part = labels == labels[iy - y0, ix - x0]
    sides = (
        (x0 > 0 and part[:, 0].any())
        or (x1 < nx - 1 and part[:, -1].any())
        or (y0 > 0 and part[0, :].any())
        or (y1 < ny - 1 and part[-1, :].any())
    )
    if sides:
        return False
    gx, gy = (int(v) for v in grid.world_to_cell(np.asarray(other, dtype=float)))
    return not (x0 <= gx <= x1 and y0 <= gy <= y1 and part[gy - y0, gx - x0])


def _grid_path(caches: PlannerCaches, p0: np.ndarray, p1: np.ndarray) -> np.ndarray:
    """Return the search's grid path (cell centres, m, shape (k, 2)) from ``p0`` to ``p1``.

    The disc search of a plan on ``caches`` (exact, with its cost or landmarks), no
    corridor or smoothing: :class:`NoPathError` when the ends are not joined.
    """
    grid = caches.grid
    s, g = (tuple(int(v) for v in grid.world_to_cell(p)) for p in (p0, p1))
    ny, nx = grid.shape
    labels = caches.components
    if not all(0 <= c[0] < nx and 0 <= c[1] < ny for c in (s, g)) or (
        labels[s[1], s[0]] == 0 or labels[s[1], s[0]] != labels[g[1], g[0]]
    ):
        raise NoPathError(f"no path from start {p0.tolist()} m to goal {p1.tolist()} m")
    lms = caches.landmarks
    try:
        path = astar.find_path(
            caches.inflated, s, g, cost=caches.search_cost if lms is None else None, landmarks=lms
        )
    except astar.NoPathError as exc:
        raise NoPathError(f"no path from start {p0.tolist()} m to goal {p1.tolist()} m") from exc
    return np.asarray(grid.cell_to_world(path.cells), dtype=float).reshape(-1, 2)
