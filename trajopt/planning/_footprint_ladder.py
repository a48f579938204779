"""Planning for a robot with an oriented footprint.

A :class:`~trajopt._planner.Planner` whose robot has a
:class:`~trajopt.robot._footprint.Footprint` first checks that the footprint can stand at both
ends (:func:`check_end_poses`), then plans with disc models of growing radius and keeps
the first result whose footprint certificate passes:

1. the **inscribed** radius first: the centre keeps at least it from every obstacle, so
   the search accepts every passage at least as wide as the footprint's narrowest
   extent through the rotation centre, and the corridor and the smoother certify that
   disc clearance (no path for it: :class:`~trajopt.errors.NoPathError` at once);
2. the disc model's smoother is given the footprint (the ``footprint`` of
   :func:`~trajopt.planning._disc.plan_disc`): it accepts a curve only when
   :func:`~trajopt.robot._footprint.certify_footprint` passes too (per span, the Minkowski sum of
   the control-point hull and the footprint swept over the span's heading interval,
   exactly clear of the raw map), and runs its footprint rounds (pinned end headings, the
   footprint SCP: :mod:`trajopt.smoother._footprint_rounds`) before refining its knots;
3. when that fails, the same disc is tried again with the footprint's oriented check of
   its grid path (:func:`oriented_path_check`), then the next radius of the ladder
   (halfway to the circumscribed radius, then the circumscribed radius, whose disc holds
   the footprint in every heading).

What is exact and what is conservative: every returned smooth trajectory passes the
footprint certificate, which bounds the footprint over each piece rigorously (the swept
hull and the control-point hull both contain what they stand for), so the footprint never
meets an obstacle. The search is a disc search with an oriented check of its grid path
(:func:`oriented_path_check`: the footprint at the path's own heading at every cell,
re-searching around the cells where it collides), not a search over positions and
headings: a passage the footprint can only take at a heading the grid path does not
suggest may be missed. The stop-and-turn fallback is used only on the circumscribed rung:
it turns in place, where only the circumscribed disc is free in every heading.
"""

from __future__ import annotations

import dataclasses
import math
import time
from typing import Any

import numpy as np

import astar
from astar.grid import OccupancyGrid
from trajopt.errors import InvalidInputError, NoPathError, SmoothingError, TimingError
from trajopt.motion import PlanResult
from trajopt.planning._caches import PlannerCaches
from trajopt.planning._disc import plan_disc
from trajopt.planning._options import PlannerOptions, PlanRequest
from trajopt.planning._query import PlanQuery
from trajopt.robot import Footprint, certify_footprint


def radius_ladder(inscribed: float, circumscribed: float) -> list[float]:
    """Return the disc radii tried in order (m): inscribed, halfway, circumscribed."""
    out = [inscribed, 0.5 * (inscribed + circumscribed), circumscribed]
    return [r for i, r in enumerate(out) if i == 0 or r > out[i - 1] * (1 + 1e-9)]


#: most re-searches of the oriented grid-path check
MAX_RESEARCHES = 4


def oriented_path_check(
    caches: PlannerCaches, q: PlanQuery, footprint: Footprint
) -> tuple[astar.GridPath, OccupancyGrid]:
    """Check the footprint along a disc model's grid path; re-search around collisions.

    At every interior path cell the footprint is placed at the heading of the path there
    (the direction from two cells back to two cells ahead) and its exact clearance from
    the raw map is computed (:func:`trajopt.robot._footprint.polygons_clearance`). Cells where it
    meets an obstacle are blocked and the search is run again, up to
    :data:`MAX_RESEARCHES` times; a re-search that finds no path keeps the last path
    found (the certificate of the curve decides). Returns the grid path and the inflated
    grid it was found on.
    """
    from trajopt.robot import polygons_clearance

    raw = caches.grid
    path, grid = q.path, q.inflated
    for _ in range(MAX_RESEARCHES):
        cells = np.asarray(path.cells)
        n = len(cells)
        if n < 5:
            return path, grid
        centres = raw.cell_to_world(cells)
        ahead = centres[np.minimum(np.arange(n) + 2, n - 1)]
        back = centres[np.maximum(np.arange(n) - 2, 0)]
        d = ahead - back
        theta = np.arctan2(d[:, 1], d[:, 0])
        inner = np.arange(2, n - 2)
        clr = polygons_clearance(
            [footprint.at(*centres[i], theta[i]) for i in inner], raw, raw.resolution
        )
        bad = inner[clr <= 0.0]
        if bad.size == 0:
            return path, grid
        occ = np.array(grid.occupied)
        occ[cells[bad, 1], cells[bad, 0]] = True
        trial = grid.with_occupied(occ)
        try:
            path = astar.find_path(
                trial, tuple(cells[0]), tuple(cells[-1]), cost=caches.search_cost
            )
        except astar.NoPathError:
            return path, grid
        grid = trial
    return path, grid


def plan_with_footprint(
    options: PlannerOptions, caches: PlannerCaches, request: PlanRequest
) -> PlanResult:
    """Plan one query for a footprint robot (module docstring): the disc ladder.

    Each rung is a disc model (:meth:`PlannerOptions.disc`, with caches of its own on the
    map: :meth:`PlannerCaches.disc`) planned by :func:`~trajopt.planning._disc.plan_disc`
    with the footprint its smoother must also certify; below the circumscribed radius each
    rung is tried again with :func:`oriented_path_check`. A re-plan's warm start is not
    used: its grid path and corridor were made for one rung's radius.

    Raises
    ------
    InvalidInputError
        The start or goal is invalid even for the inscribed disc.
    NoPathError
        No disc of the ladder finds a path.
    SmoothingError
        No rung gives a curve whose footprint certificate passes (the message lists why
        each radius failed).
    """
    robot = options.robot
    fp = robot.footprint
    check_end_poses(fp, caches.grid, request)
    ladder = radius_ladder(fp.inscribed_radius, fp.circumscribed_radius)
    failures: list[str] = []
    errors: list[Exception] = []
    attempts: list[tuple[float, bool]] = []
    for r in ladder:
        attempts.append((r, False))
        if r < ladder[-1]:  # a second try with the oriented check of the grid path
            attempts.append((r, True))
    for i, (r, checked) in enumerate(attempts):
        disc = options.disc(r, last=r >= robot.circumscribed_radius * (1 - 1e-9))
        check = None
        if checked:

            def check(c: PlannerCaches, q: PlanQuery) -> tuple[astar.GridPath, OccupancyGrid]:
                return oriented_path_check(c, q, fp)

        try:
            traj = plan_disc(disc, caches.disc(disc), request, footprint=fp, path_check=check)
        except InvalidInputError as exc:
            if i == 0:
                raise
            failures.append(f"{_label(r, checked)}: {type(exc).__name__}: {exc}")
            errors.append(exc)
            continue
        except NoPathError as exc:
            if i == 0:  # no path for the inscribed disc: none for any footprint pose either
                raise NoPathError(f"no path for the footprint's inscribed disc: {exc}") from None
            failures.append(f"{_label(r, checked)}: {type(exc).__name__}: {exc}")
            errors.append(exc)
            continue
        except (SmoothingError, TimingError) as exc:
            failures.append(f"{_label(r, checked)}: {type(exc).__name__}: {exc}")
            errors.append(exc)
            continue
        cert_s = 0.0
        smoother_stats = getattr(getattr(traj, "path", None), "stats", None) or {}
        if traj.polyline:
            cert = None  # only on the circumscribed rung: its disc holds every heading
        else:
            cert = getattr(traj.path, "footprint_certificate", None)  # the smoother's
            cert_s = smoother_stats.get("footprint_certificate_s", 0.0)
            if cert is None:  # a box corridor's fit, or a curve from elsewhere
                t_cert = time.perf_counter()
                cert = certify_footprint(traj.path, fp, caches.grid)
                cert_s = time.perf_counter() - t_cert
            if not cert.ok:
                failures.append(
                    f"{_label(r, checked)}: footprint certificate failed at span "
                    f"{cert.worst_span} (margin {cert.min_margin_m:.4g} m)"
                )
                errors.append(SmoothingError(failures[-1], {}))
                continue
        stats = dict(traj.stats)
        stats["footprint"] = {
            "disc_radius_m": r,
            "ladder_m": ladder,
            "rejected": list(failures),
            "min_margin_m": None if cert is None else cert.min_margin_m,
            "spans": None if cert is None else int(cert.margins_m.size),
            "certificate_s": cert_s,
            "rounds": int(smoother_stats.get("footprint_rounds", 0)),
        }
        return dataclasses.replace(traj, robot=robot, stats=stats)
    if errors and all(isinstance(e, NoPathError) for e in errors):
        raise NoPathError("no path for any disc of the footprint's ladder: " + "; ".join(failures))
    stats: dict[str, Any] = {"footprint_failures": failures}
    for e in reversed(errors):
        if isinstance(e, SmoothingError) and e.stats:
            stats.update(e.stats)
            break
    raise SmoothingError("no footprint-certified trajectory: " + "; ".join(failures), stats)


def check_end_poses(
    footprint: Footprint, raw: OccupancyGrid, request: PlanRequest, polygons: bool = False
) -> None:
    """Raise when the footprint cannot stand at the start or the goal.

    With a heading (given, or a :class:`~trajopt.robot._state.State`'s ``theta``) the footprint at
    that pose must be clear of the raw map: of its occupied squares, or, with ``polygons``
    (a planner that tests the body against them: the car's) where the map knows the polygons
    it was rasterised from (:attr:`astar.OccupancyGrid.polygons`), of those polygons
    (exactly, :func:`astar.bodies_distance`) and inside the map; without one, at least one of
    :data:`~trajopt.smoother._footprint_rounds.END_HEADINGS` sampled headings must be.

    Raises
    ------
    InvalidInputError
        Naming the end, its position and heading (or the sampled headings), and the
        clearance found.
    """
    from trajopt.robot import polygons_clearance
    from trajopt.smoother import END_HEADINGS, end_headings

    fp = footprint
    ends = (
        ("start", request.start, request.start_heading),
        ("goal", request.goal, request.goal_heading),
    )
    for name, end, heading in ends:
        theta = getattr(end, "theta", None) if heading is None else heading
        xy = np.array([getattr(end, "x", None), getattr(end, "y", None)], dtype=float)
        if not np.all(np.isfinite(xy)):
            try:
                xy = np.asarray(end, dtype=float).reshape(2)
            except (TypeError, ValueError):
                return  # malformed: the disc planner's validation names it
        if not np.all(np.isfinite(xy)):
            return
        if theta is not None and math.isfinite(float(theta)):
            clr = float(polygons_clearance([fp.at(*xy, float(theta))], raw, raw.resolution)[0])
            exact = polygons and raw.polygons is not None
            if clr <= 0.0 and exact and _inside_map(fp, raw, xy, float(theta)):
                # the cells cover the polygons conservatively: the polygons decide
                pose = np.array([[xy[0], xy[1], float(theta)]])
                clr = float(astar.bodies_distance(fp.vertices, pose, raw.polygons)[0])
            if clr <= 0.0:
                raise InvalidInputError(
                    f"{name} pose ({xy[0]:.4g}, {xy[1]:.4g}) m, heading {float(theta):.4g} rad: "
                    "the footprint meets an obstacle or the map edge there (clearance 0 m)"
                )
        elif not np.any(end_headings(fp, raw, xy)[1] > 0.0):
            raise InvalidInputError(
                f"{name} ({xy[0]:.4g}, {xy[1]:.4g}) m: the footprint meets an obstacle or the "
                f"map edge at each of {END_HEADINGS} sampled headings; it cannot stand there"
            )


def _inside_map(fp: Footprint, raw: OccupancyGrid, xy: np.ndarray, theta: float) -> bool:
    """Whether the footprint at pose ``(xy, theta)`` lies inside the map's rectangle."""
    c, s = math.cos(theta), math.sin(theta)
    v = np.asarray(fp.vertices, dtype=float)
    w = xy + v @ np.array([[c, s], [-s, c]])
    ox, oy = raw.origin
    return bool(
        np.all(w[:, 0] > ox)
        and np.all(w[:, 0] < ox + raw.width)
        and np.all(w[:, 1] > oy)
        and np.all(w[:, 1] < oy + raw.height)
    )


def _label(radius: float, checked: bool) -> str:
    return f"radius {radius:.4g} m" + (", oriented check" if checked else "")
