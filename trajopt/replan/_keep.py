"""What a re-plan keeps of the trajectory being driven, when nothing it relies on changed.

:meth:`~trajopt._planner.Planner.replan` first asks :func:`keep_rest` whether the old
trajectory's rest is still the answer. It is when the goal, the goal heading and the end
speed are the old ones and the map has not changed where the rest depends on it: no cell
of the inflated grid (the search's graph) was freed anywhere, since a freed cell may open a
better route, and no cell became occupied within the robot's reach of the corridor regions
the rest of the curve lies in (the regions the certificate holds it to). The trajectory is
taken to come from this planner (its speed limits and smoother options). Then nothing is
searched, fitted or timed again: the curve is cut at the splice
(:meth:`~trajopt.geometry._bspline.BSplineCurve.tail`, exact), the timing's constant-jerk phases from
the splice on are kept as they are, shifted in time and arc length, and the cut curve is
certified again against the corridor and the current map.

A plan re-routed around predicted movers was made on the map with their swept regions
marked (:mod:`trajopt.replan._marked`): "the map it was made on" is then the static map the
marks were drawn on (:func:`~trajopt.replan._marked.planned_on`), so that a re-plan with new
predictions keeps the rest of the detour when the static map has not changed where it
matters (the same rules); the re-plan's re-timing (:mod:`trajopt.replan._moving`) then
holds it to the new predictions. Its corridor, made on the marked map, is free on the
static map too, and the cut curve is certified against the current (static) map.

An omnidirectional base's :class:`~trajopt.motion.OmniTrajectory` is kept the same way
(:func:`keep_omni`): its translation's rest by :func:`keep_rest`, and beside it the rest of
its orientation profile, cut at the splice (:meth:`~trajopt.motion.OmniTrajectory.after`),
when the goal heading is the orientation it ends at.

When the rest cannot be kept because new obstacles came near it, :func:`remaining_grid_path`
may still hand the re-plan the rest of the old grid path, so that it skips the search (not
a re-routed plan's: its grid path was least-cost on the marked map only).
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Sequence

import numpy as np

from astar.search import GridPath
from trajopt.corridor import Box, ConvexPolygon, PolygonCorridor
from trajopt.motion import OmniTrajectory, PlanResult, Trajectory, TrajectoryChain
from trajopt.planning import PlannerCaches, PlannerOptions, PlanSteps, change_reach
from trajopt.replan._marked import MarkedSteps, planned_on
from trajopt.replan._omni import turn_piece
from trajopt.smoother import SmoothPath, certify
from trajopt.validation import point

#: why :func:`keep_rest` refuses when new obstacles come near the rest of the path
BLOCKED_NEAR = "cells blocked near the rest of the path"
#: changed cells near the grid path compared pairwise with its cells, at most this many
_MAX_NEAR_CHANGES = 20_000


def keep_rest(
    options: PlannerOptions,
    caches: PlannerCaches,
    trajectory: PlanResult,
    ts: float,
    goal: Sequence[float] | None,
    *,
    goal_heading: float | None,
    v_end: float,
) -> tuple[Trajectory | None, str]:
    """Return the rest of ``trajectory`` from ``ts`` if a re-plan may keep it.

    Parameters
    ----------
    options : PlannerOptions
        The re-planning planner's options.
    caches : PlannerCaches
        Its caches, with the current map.
    trajectory : Trajectory or StopAndTurnTrajectory
        The trajectory being driven.
    ts : float
        The splice time on its clock (s), in ``[0, duration]``.
    goal : sequence of float, shape (2,), or None
        The re-plan's goal (m); ``None``: the old one.
    goal_heading : float or None
        The re-plan's goal heading (rad).
    v_end : float
        The re-plan's end speed (m/s).

    Returns
    -------
    (Trajectory or None, str)
        The kept trajectory (time 0 at the splice; ``stats["replan"] == "kept"``) and
        ``"kept"``, or ``None`` and why the rest cannot be kept.
    """
    t0 = time.perf_counter()
    steps = getattr(trajectory, "steps", None)
    smooth = getattr(steps, "smooth_path", None)
    if not trajectory.single_curve or not isinstance(smooth, SmoothPath):
        return None, "not a smoothed trajectory of a Planner"
    if options.robot.footprint is not None:
        return None, "footprint robot"
    if trajectory.robot != options.robot:
        return None, "planned for another robot"
    why = target_change(trajectory, goal, goal_heading, v_end)
    if why:
        return None, why
    u_end = trajectory.path.domain[1]
    s0 = float(trajectory.motion(ts)[0])
    u0 = float(trajectory._u_at_s(np.array(s0)))
    if not u0 < u_end or s0 >= trajectory.length:
        return None, "at the end"
    if trajectory.path is not smooth:
        return None, "the trajectory does not drive its smooth path"
    span_box = smooth.certificate.span_box[int(smooth.curve.span_of(u0)) :]
    corridor = steps.corridor
    regions = corridor.regions if isinstance(corridor, PolygonCorridor) else corridor.boxes
    why = _map_change(options, caches, steps, [regions[i] for i in np.unique(span_box)])
    if why:
        return None, why
    tail = smooth.curve.tail(u0)
    start = tail.c[0]
    cert = certify(
        tail,
        corridor,
        span_box,
        start=start,
        goal=np.asarray(steps.goal),
        raw_grid=caches.grid,
        radius=smooth.certificate.radius_m,
        kappa_bound=smooth.certificate.kappa_bound,
    )
    if not cert.ok:
        return None, f"the rest fails its certificate ({', '.join(cert.failures)})"
    path = dataclasses.replace(smooth, curve=tail, certificate=cert, footprint_certificate=None)
    out = trajectory_after(trajectory, ts, path, u0)
    elapsed = time.perf_counter() - t0
    stages = {"keep": elapsed, "total": elapsed}
    maps = {"raw_grid": caches.grid, "inflated_grid": caches.inflated}
    if isinstance(steps, MarkedSteps):  # made on the marked map: the static map is the new
        maps = {"static_grid": caches.grid, "static_inflated": caches.inflated}
    new_steps = dataclasses.replace(
        steps,
        smooth_path=path,
        start=(float(start[0]), float(start[1])),
        stages_s=stages,
        **maps,
    )
    stats = dict(out.stats)
    stats["stages_s"] = stages
    stats["replan"] = "kept"
    stats["corridor_regions_kept"] = len(regions) if isinstance(corridor, PolygonCorridor) else 0
    return dataclasses.replace(out, steps=new_steps, stats=stats), "kept"


def keep_omni(
    options: PlannerOptions,
    caches: PlannerCaches,
    trajectory: OmniTrajectory,
    ts: float,
    goal: Sequence[float] | None,
    *,
    goal_heading: float | None,
    v_end: float,
) -> tuple[OmniTrajectory | TrajectoryChain | None, str]:
    """Return the rest of an omnidirectional base's motion from ``ts`` if a re-plan may keep it.

    The translation's rest is :func:`keep_rest`'s (the same rules: goal, end speed and map);
    the goal heading must be the orientation the motion ends at (``theta_end``, modulo
    ``2 pi`` within 1e-9 rad), or ``None``. The orientation's phases from ``ts`` on are kept
    as they are, shifted in time (:meth:`OmniTrajectory.after`). At a ``ts`` where the
    translation is over and the body stands finishing its turn, the rest is that turn (a
    :class:`~trajopt.motion._chain.TurnInPlace` in a
    :class:`~trajopt.motion._chain.TrajectoryChain`) when the map is the one planned on.

    Parameters
    ----------
    options, caches, ts, goal, goal_heading, v_end
        As :func:`keep_rest`; ``goal_heading`` the orientation asked at the goal (rad).
    trajectory : OmniTrajectory
        The trajectory being driven.

    Returns
    -------
    (OmniTrajectory or TrajectoryChain or None, str)
        The kept trajectory (time 0 at the splice; its ``steps`` record the headings the
        old plan asked for) and ``"kept"``, or ``None`` and why the rest cannot be kept.
    """
    steps = trajectory.steps
    if steps is None:
        return None, "not a smoothed trajectory of a Planner"
    if options.robot.footprint is not None:
        return None, "footprint robot"
    if goal is not None and tuple(point("goal", goal).tolist()) != tuple(steps.goal):
        return None, "new goal"
    if v_end != trajectory.v_end:
        return None, "new end speed"
    if goal_heading is not None and (
        abs(math.remainder(float(goal_heading) - trajectory.theta_end, 2.0 * math.pi)) > 1e-9
    ):
        return None, "new goal heading"
    translation = trajectory.translation
    if ts >= translation.duration:  # standing at the path's end: the turn goes on
        if caches.grid is not planned_on(steps)[0]:
            return None, "the map changed"
        rows, t_rot = trajectory.orientation_after(ts)
        if t_rot <= 0.0:
            return None, "at the end"
        end = translation.sample(np.array([translation.duration]))
        turn = turn_piece(
            (float(end.x[0]), float(end.y[0])), rows[0, 1], rows, t_rot, options.robot
        )
        stats = dict(trajectory.stats, stages_s={"keep": 0.0, "total": 0.0}, replan="kept")
        return TrajectoryChain((turn,), options.robot, stats, steps), "kept"
    rest, why = keep_rest(options, caches, translation, ts, goal, goal_heading=None, v_end=v_end)
    if rest is None:
        return None, why
    out = trajectory.after(ts, rest)
    new_steps = rest.steps
    if new_steps is not None:
        new_steps = dataclasses.replace(
            new_steps, start_heading=steps.start_heading, goal_heading=steps.goal_heading
        )
    stats = {**trajectory.stats, **rest.stats}  # the orientation's, and the keep's
    return dataclasses.replace(out, stats=stats, steps=new_steps), "kept"


def target_change(
    trajectory: PlanResult, goal: Sequence[float] | None, goal_heading: float | None, v_end: float
) -> str:
    """Why a re-plan's goal, goal heading or end speed differ from ``trajectory``'s.

    ``""`` when they do not. ``goal`` ``None`` is the old goal; a goal heading counts as
    new unless the old plan asked for it (its steps' ``goal_heading``) or ``trajectory``
    has a ``path`` that ends with it (within 1e-9 rad).
    """
    steps = trajectory.steps
    if goal is not None and tuple(point("goal", goal).tolist()) != tuple(steps.goal):
        return "new goal"
    if v_end != trajectory.v_end:
        return "new end speed"
    if goal_heading is not None:
        asked = getattr(steps, "goal_heading", None)
        if (
            asked is not None
            and abs(math.remainder(float(goal_heading) - asked, 2 * math.pi)) <= 1e-9
        ):
            return ""
        path = getattr(trajectory, "path", None)
        if path is None:
            return "new goal heading"
        old = float(path.heading(path.domain[1]))
        if abs(math.remainder(float(goal_heading) - old, 2.0 * math.pi)) > 1e-9:
            return "new goal heading"
    return ""


def _map_change(
    options: PlannerOptions,
    caches: PlannerCaches,
    steps: PlanSteps,
    regions: list[ConvexPolygon] | list[Box],
) -> str:
    """Return why the map change breaks the rest of the old curve ('' when it does not).

    The old map is the static map the plan was made on (:func:`planned_on`: for a plan
    re-routed on a map with movers' regions marked, the map the marks were drawn on).
    """
    old, old_inflated = planned_on(steps)
    new = caches.grid
    if old is new:
        return ""
    if (old.shape, old.resolution, old.origin) != (new.shape, new.resolution, new.origin):
        return "map of another shape"
    # a cell the search could not enter before and can now may open a better route; a raw
    # cell freed inside what stays inflated adds nothing to the search's graph
    if np.any(old_inflated.occupied & ~caches.inflated.occupied):
        return "cells freed"
    iy, ix = np.divmod(np.flatnonzero(new.occupied & ~old.occupied), new.nx)
    if ix.size == 0:
        return ""
    centres = np.asarray(new.cell_to_world(np.column_stack([ix, iy])), dtype=float)
    res = float(new.resolution)
    # a region keeps the radius (plus the avoidance area with inflation="paper") from every
    # occupied square; a new square whose centre is farther than that plus its half-diagonal
    # from the region's bounding box cannot come closer
    reach = options.robot.radius + res * (math.sqrt(0.5) + 1e-9)
    if options.inflation == "paper":
        reach += options.w_cells * res
    for reg in regions:
        v = np.asarray(reg.vertices if isinstance(reg.vertices, np.ndarray) else reg.vertices())
        lo, hi = v.min(axis=0) - reach, v.max(axis=0) + reach
        if np.any(np.all((centres >= lo) & (centres <= hi), axis=1)):
            return BLOCKED_NEAR
    return ""


def remaining_grid_path(
    options: PlannerOptions, caches: PlannerCaches, steps: PlanSteps, start_cell: np.ndarray
) -> GridPath | None:
    """Return the rest of the old grid path joined from ``start_cell``, if the map allows.

    The join is the straight line of king moves from ``start_cell`` to the nearest cell of
    the old path (the last one at that distance), then the old path from there. It is
    returned when every cell of it is free on the current inflated grid (diagonal moves
    without cutting corners, as the search moves), no inflated cell was freed anywhere, and
    no raw cell changed within the search cost's reach of it
    (:func:`~trajopt.planning._caches.change_reach`). Then the costs along the old part are the
    old ones and no other path got cheaper, so that part is still a least-cost path from its
    first cell to the goal; only the short join is not searched. ``None`` for a re-routed
    plan's steps (:class:`~trajopt.replan._marked.MarkedSteps`): its grid path was a
    least-cost path on the marked map, not on the static one.

    Parameters
    ----------
    options : PlannerOptions
        The re-planning planner's options.
    caches : PlannerCaches
        Its caches, with the current map.
    steps : PlanSteps
        The old trajectory's steps (its grid path, raw and inflated grids).
    start_cell : ndarray of int, shape (2,)
        The new start's cell ``(ix, iy)``.

    Returns
    -------
    astar.GridPath or None
        ``expanded`` 0, ``length`` and ``cost`` recomputed on the current search cost.
    """
    if isinstance(steps, MarkedSteps):
        return None  # its grid path was found on a marked map: no least-cost path here
    old, new = steps.raw_grid, caches.grid
    if (old.shape, old.resolution, old.origin) != (new.shape, new.resolution, new.origin):
        return None
    start = np.asarray(start_cell, dtype=np.int64)
    if not new.in_bounds(start):
        return None
    free = ~np.asarray(caches.inflated.occupied)
    if np.any(np.asarray(steps.inflated_grid.occupied) & free):
        return None  # cells freed: another route may be cheaper now
    cells = np.asarray(steps.grid_path.cells)
    d2 = np.sum((cells - start) ** 2, axis=1)
    i = int(len(d2) - 1 - np.argmin(d2[::-1]))
    n = int(np.max(np.abs(cells[i] - start)))
    k = np.arange(n + 1)[:, None] / max(n, 1)
    join = np.rint(start + (cells[i] - start) * k).astype(np.int64)
    path = np.vstack([join[:-1], cells[i:]])
    if not np.all(free[path[:, 1], path[:, 0]]):
        return None
    step = np.diff(path, axis=0)
    diag = np.all(step != 0, axis=1)
    a = path[:-1][diag]
    if not (
        np.all(free[a[:, 1], a[:, 0] + step[diag, 0]])
        and np.all(free[a[:, 1] + step[diag, 1], a[:, 0]])
    ):
        return None
    _, reach = change_reach(options, new.resolution)
    iy, ix = np.divmod(np.flatnonzero(new.occupied != old.occupied), new.nx)
    lo, hi = path.min(axis=0) - reach, path.max(axis=0) + reach
    near = (ix >= lo[0]) & (ix <= hi[0]) & (iy >= lo[1]) & (iy <= hi[1])
    if np.count_nonzero(near) > _MAX_NEAR_CHANGES:
        return None
    changed = np.column_stack([ix[near], iy[near]])
    for chunk in np.array_split(changed, max(1, len(changed) // 256)):
        if len(chunk) and np.min(np.max(np.abs(chunk[:, None, :] - path[None]), axis=2)) <= reach:
            return None
    length_steps = np.where(diag, math.sqrt(2.0), 1.0)
    cost = caches.search_cost
    if cost is None:
        step_costs = length_steps
    else:
        c = cost[path[:, 1], path[:, 0]]
        step_costs = length_steps * (1.0 + 0.5 * (c[:-1] + c[1:]))
    return GridPath(
        cells=path, length=float(length_steps.sum()), cost=float(step_costs.sum()), expanded=0
    )


def trajectory_after(traj: Trajectory, ts: float, path: SmoothPath, u0: float) -> Trajectory:
    """Return ``traj`` from time ``ts`` on, along ``path`` (its curve cut at ``u0``).

    The constant-jerk phases after ``ts`` are kept as they are, shifted by ``ts`` in time
    and by the arc length ``s(ts)``; the phase holding ``ts`` starts at ``ts`` with the
    motion's state there. ``path`` must be ``traj.path`` from ``u0 = u(s(ts))`` on, with
    the same parameter.
    """
    s0, v0, a0, _ = (float(x) for x in traj.motion(ts))
    k = int(np.searchsorted(traj.phase_t, ts, side="right")) - 1
    later = slice(k + 1, None)
    gs = traj.theta_grid_s
    ahead = gs > s0
    theta0 = float(traj.state_at(ts).theta)
    u_grid = traj.u_grid
    if u_grid.shape[0]:
        u_grid = np.concatenate([[u0], u_grid[ahead]])
    return Trajectory(
        path=path,
        robot=traj.robot,
        phase_t=np.concatenate([[0.0], traj.phase_t[later] - ts]),
        phase_s=np.concatenate([[0.0], traj.phase_s[later] - s0]),
        phase_v=np.concatenate([[v0], traj.phase_v[later]]),
        phase_a=np.concatenate([[a0], traj.phase_a[later]]),
        phase_j=np.concatenate([traj.phase_j[k : k + 1], traj.phase_j[later]]),
        duration=traj.duration - ts,
        v_start=v0,
        v_end=traj.v_end,
        stats=dict(traj.stats),
        theta_grid_s=np.concatenate([[0.0], gs[ahead] - s0]),
        theta_grid=np.concatenate([[theta0], traj.theta_grid[ahead]]),
        u_grid=u_grid,
        steps=traj.steps,
        speed_limits=traj.speed_limits,
    )
