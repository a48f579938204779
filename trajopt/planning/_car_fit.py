"""Fitting a car's search path, segment by segment (:mod:`trajopt.planning._car`, step 2).

The search path (:func:`astar.find_pose_path`) is split at its cusps (where the direction
of travel flips; the heading is continuous there, the tangent flips by ``pi``). Each stretch
between cusps is fitted as an ordinary curve in the direction of travel
(:func:`fit_run`, :func:`fit_segment`): a certified polygon corridor grown around its poses
(:func:`~trajopt.corridor.build_polygon_corridor`), then the planner's smoother with
``kappa_max = min(its own, 1/R)``, exact end points, exact end travel headings (the body
heading forwards, heading ``+ pi`` backwards) and the search path's start curvature
(:func:`start_curvature`); then without that curvature; then from its end to its start with
the path's curvature at the end, the curve then turned round (:func:`turned_round`; the
smoother takes a start curvature, not a goal one). Where those fail, it is fitted again in
polygons grown around the poses themselves without centring (the witness corridor of
:func:`~trajopt.planning._corridor_fit.witness_corridor`). A stretch that turns by more than
:data:`SPLIT_TURN_RAD` and that neither the first nor the reversed fit fits is fitted in
pieces spanning at most :data:`PIECE_TURN_RAD` of heading each (:func:`split_points`; before
the other whole fits), each starting with the previous piece's end curvature; the car rests
at each join as at a cusp (:attr:`CarSegment.joined`). A stretch that no fit fits at all is
halved at its middle pose and its halves fitted the same way (:data:`HALVING_DEPTH`; the car
rests at the join where their curvatures differ). Every curve is the smoother's
certified curve (convex-hull clearance certificate per segment) and its sampled curvature
(the certificate's dense samples) must be within ``1/R`` (to :data:`KAPPA_TOL`); nothing
else is returned.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from astar.grid import OccupancyGrid
from astar.hybrid import PosePath
from trajopt.corridor import PolygonCorridor, build_polygon_corridor
from trajopt.errors import InvalidInputError, SmoothingError
from trajopt.geometry import BSplineCurve
from trajopt.planning._corridor_fit import witness_corridor
from trajopt.planning._options import PlannerOptions
from trajopt.planning._query import StageTimer
from trajopt.robot import Footprint
from trajopt.smoother import Smoother, SmoothPath

#: Relative tolerance of the curvature check of each fitted segment.
KAPPA_TOL = 1e-6
#: A stretch between cusps that turns by more than this (rad, the sum of its heading changes)
#: and whose first fits fail is fitted in pieces (:func:`split_points`): one B-spline round
#: a loop of the search's forward-only shots (4.7-6.6 rad on the held-out failures) left the
#: curvature SCP without a step (its trust region collapsed), where its thirds fitted at
#: once. Only after whole fits failed (:data:`WHOLE_FIRST`): the car rests at each join,
#: and long paths turn by tens of radians in small steps.
SPLIT_TURN_RAD = math.pi
#: The fits (:func:`fit_segment` ``tries``) of a stretch that may be split, tried before its
#: pieces: with the search path's start curvature, and from the end with its end curvature.
#: The others (without a start curvature, the witness corridor) come after the pieces: a
#: failing whole fit of a long loop costs 0.4-1.9 s, its pieces 0.01-0.03 s each.
WHOLE_FIRST = (0, 2)
#: Largest turn (rad) of each piece of a split stretch.
PIECE_TURN_RAD = 0.6 * math.pi
#: How many times a stretch whose fits all fail is halved at its middle pose
#: (:func:`fit_run`): a backwards segment into a parking slot whose curve left the body's
#: certificate no margin near the slot (footprint certificate at 0 m) or whose curvature
#: SCP did not converge fitted as two or four shorter curves.
HALVING_DEPTH = 2
#: Fewest steps (pose index differences) of a stretch that is halved.
HALVING_MIN_POSES = 4
#: Where the map knows its polygons, a segment near them is smoothed on a raster of them
#: whose cells divide the map's and are at most the turning radius over this (:func:`fine_window`:
#: 1.25 cm for R = 3 m, 2.5 mm for R = 0.6 m); its footprint certificate is exact against the
#: polygons (:func:`trajopt.robot.certify_footprint` on a grid that knows them). With the
#: exact certificate, R / 60 and R / 120 planned the same 7 suite cases in the same time as
#: R / 240 (three rounds back to back).
FINE_CELLS_PER_RADIUS = 240.0
#: Room (m) around the segment's poses and body in the window of :func:`fine_window`.
FINE_PAD_M = 0.5
#: A segment whose search poses hold the body more than this many cells off the map's
#: occupied squares is fitted on them (:func:`bodies_clear_of_cells`), else on the finer
#: raster of the polygons (:func:`fine_window`, about 16 times the cells: its fits cost 3-10
#: times as long).
CELL_FIT_CLEARANCE_CELLS = 0.25


@dataclass(frozen=True, slots=True)
class CarSegment:
    """One segment of a car's plan between cusps.

    Attributes
    ----------
    direction : int
        ``+1`` forwards, ``-1`` backwards.
    first, last : int
        Pose indices (into :attr:`~trajopt.planning._car.CarSteps.poses`) of its ends.
    corridor : PolygonCorridor
        The certified corridor it was fitted in.
    smooth_path : SmoothPath
        The certified curve in the direction of travel (its certificate included).
    corridor_kind : str
        ``"polygons"`` (grown around the centred poses), ``"reversed"`` (the same, fitted
        from the segment's end with its curvature there, then turned round) or ``"witness"``
        (around the poses themselves, the last try).
    joined : bool
        Whether it continues the previous segment in the same direction of travel (a stretch
        between cusps that turns by more than :data:`SPLIT_TURN_RAD` and that its first
        whole fits miss is fitted in pieces, and one that no fit fits is halved:
        :func:`fit_run`). Its curve then starts with the previous curve's end curvature
        where that fit succeeds (``"polygons"``) and the car drives through the join;
        otherwise it rests there, as at a cusp.
    """

    direction: int
    first: int
    last: int
    corridor: PolygonCorridor
    smooth_path: SmoothPath
    corridor_kind: str
    joined: bool = False


def start_curvature(path: PosePath, first: int, res: float) -> float:
    """Return the curvature (1/m) the search's path starts pose ``first`` with.

    Signed along the direction of travel: a backwards arc of body curvature ``k`` traces,
    in its direction of travel, a curve of curvature ``-k``.
    """
    xy = np.asarray(path.poses[first, :2])
    pieces = np.asarray(path.pieces)
    i = int(np.argmin(np.hypot(*(pieces[:, :2] - xy).T)))
    k, length = float(pieces[i, 3]), float(pieces[i, 4])
    return (k if length >= 0.0 else -k) / res


def split_points(headings: np.ndarray, first: int, last: int) -> list[int]:
    """Return the pose indices where a stretch between cusps is cut into pieces.

    ``[first, last]`` (no cut) when the stretch turns (the sum of ``|d heading|``) by at most
    :data:`SPLIT_TURN_RAD`; else greedy pieces, each as long as its headings span (largest
    minus smallest unwrapped heading) at most :data:`PIECE_TURN_RAD` and it has at least
    two poses: a loop is cut every ``PIECE_TURN_RAD`` of turn, a path that wiggles about
    one direction is not cut.

    Parameters
    ----------
    headings : ndarray, shape (m,)
        Unwrapped headings (rad) of the search path's poses.
    first, last : int
        Pose indices of the stretch's ends.

    Returns
    -------
    list of int
        Increasing indices from ``first`` to ``last``.
    """
    th = np.asarray(headings[first : last + 1], dtype=float)
    if float(np.abs(np.diff(th)).sum()) <= SPLIT_TURN_RAD or last - first < 4:
        return [first, last]
    cuts = [first]
    lo = hi = float(th[0])
    for k in range(1, len(th)):
        lo, hi = min(lo, th[k]), max(hi, th[k])
        if hi - lo > PIECE_TURN_RAD and k - 1 - (cuts[-1] - first) >= 2:
            cuts.append(first + k - 1)
            lo, hi = min(th[k - 1], th[k]), max(th[k - 1], th[k])
    if last - cuts[-1] < 2 and len(cuts) > 1:
        cuts.pop()  # a last piece of one step joins the one before
    cuts.append(last)
    return cuts


def end_curvature(path: SmoothPath) -> float:
    """Return a fitted curve's signed curvature (1/m) at its end, along its direction."""
    return float(np.asarray(path.curvature(np.array([path.domain[1]])), dtype=float)[-1])


def fit_path(
    options: PlannerOptions,
    grid: OccupancyGrid,
    smoother: Smoother,
    path: PosePath,
    poses: np.ndarray,
    res: float,
    timer: StageTimer,
) -> list[CarSegment]:
    """Fit every stretch between cusps of a search's ``path``, in order (:func:`fit_run`).

    ``poses``: the path's poses in world metres, shape ``(n, 3)``; ``res``: the search
    grid's cell side (m). Raises :class:`~trajopt.errors.SmoothingError` from the first
    stretch that gets no certified curve.
    """
    segments: list[CarSegment] = []
    for a, b in np.asarray(path.segments):
        segments.extend(
            fit_run(
                options,
                grid,
                smoother,
                poses,
                (int(a), int(b)),
                int(path.directions[b]),
                start_curvature(path, int(a), res),
                timer,
            )
        )
    return segments


def fit_run(
    options: PlannerOptions,
    grid: OccupancyGrid,
    smoother: Smoother,
    poses: np.ndarray,
    ends: tuple[int, int],
    direction: int,
    kappa0: float,
    timer: StageTimer,
    depth: int = 0,
) -> list[CarSegment]:
    """Fit a stretch between cusps (module docstring).

    As one segment (:func:`fit_segment`: first its fits with the search path's end
    curvatures, :data:`WHOLE_FIRST`); when those fail and the stretch turns by more than
    :data:`SPLIT_TURN_RAD`, in pieces (:func:`split_points`), each piece starting with the
    previous curve's end curvature (the car rests at each join); then the whole stretch's
    other fits. When every one of those fails, the stretch is halved at its middle pose
    and each half fitted the same way (down to :data:`HALVING_DEPTH` halvings, halves of
    at least :data:`HALVING_MIN_POSES` steps), the second half starting with the first
    half's end curvature where it can: the search's pose there is exact (its body clear,
    its heading the curves' common tangent), and each half is a shorter curve held closer
    to the search's arcs. Where the curvatures differ the car rests at the join and steers
    there (as at a cusp).

    ``depth``: how many halvings led to this stretch.
    """
    try:
        return _fit_whole_or_turns(options, grid, smoother, poses, ends, direction, kappa0, timer)
    except SmoothingError as exc:
        first, last = ends
        if depth >= HALVING_DEPTH or last - first < HALVING_MIN_POSES:
            raise
        failed = exc
    # halves at the middle pose (its exact pose and heading from the search), the car
    # resting there unless the second half starts with the first's end curvature
    mid = (ends[0] + ends[1]) // 2
    try:
        left = fit_run(
            options, grid, smoother, poses, (ends[0], mid), direction, kappa0, timer, depth + 1
        )
        right = fit_run(
            options,
            grid,
            smoother,
            poses,
            (mid, ends[1]),
            direction,
            end_curvature(left[-1].smooth_path),
            timer,
            depth + 1,
        )
    except SmoothingError as exc:
        raise SmoothingError(f"{failed}; halved at pose {mid}: {exc}", exc.stats) from exc
    return left + [dataclasses.replace(right[0], joined=True)] + right[1:]


def _fit_whole_or_turns(
    options: PlannerOptions,
    grid: OccupancyGrid,
    smoother: Smoother,
    poses: np.ndarray,
    ends: tuple[int, int],
    direction: int,
    kappa0: float,
    timer: StageTimer,
) -> list[CarSegment]:
    """Fit a stretch as one segment, or in pieces of :data:`PIECE_TURN_RAD` (:func:`fit_run`)."""
    args = (options, grid, smoother, poses)
    cuts = split_points(np.asarray(poses[:, 2]), *ends)
    if len(cuts) == 2:
        return [fit_segment(*args, ends, direction, kappa0, timer)]
    try:
        return [fit_segment(*args, ends, direction, kappa0, timer, tries=WHOLE_FIRST)]
    except SmoothingError as exc:
        whole = exc
    out: list[CarSegment] = []
    k_start = kappa0
    try:
        for a, b in zip(cuts[:-1], cuts[1:], strict=True):
            seg = fit_segment(*args, (a, b), direction, k_start, timer)
            out.append(dataclasses.replace(seg, joined=bool(out)))
            k_start = end_curvature(seg.smooth_path)
        return out
    except SmoothingError as exc:
        pieces = exc
    rest = tuple(i for i in range(4) if i not in WHOLE_FIRST)
    try:
        return [fit_segment(*args, ends, direction, kappa0, timer, tries=rest)]
    except SmoothingError as exc:
        raise SmoothingError(
            f"{whole}; in {len(cuts) - 1} pieces: {pieces}; then {exc}", exc.stats
        ) from exc


def fit_segment(
    options: PlannerOptions,
    grid: OccupancyGrid,
    smoother: Smoother,
    poses: np.ndarray,
    ends: tuple[int, int],
    direction: int,
    kappa0: float,
    timer: StageTimer,
    tries: tuple[int, ...] = (0, 1, 2, 3),
) -> CarSegment:
    """Fit one segment in the direction of travel (module docstring).

    ``ends``: its first and last pose indices; ``kappa0``: the search path's curvature at
    its start (1/m, along the direction of travel), the first fit's start curvature (the
    car may steer while at rest, so the curve may start bending as the search's arc does; a
    curve made to leave straight along a pose pinned against a wall can need a near-cusp).
    """
    first, last = ends
    robot = options.robot
    radius = robot.inscribed_radius
    pts = np.ascontiguousarray(poses[first : last + 1, :2])
    cgrid = grid  # the corridor's grid
    if robot.footprint is not None and grid.polygons is not None:
        if not bodies_clear_of_cells(robot.footprint, grid, poses[first : last + 1]):
            # near the polygons: the corridor on the map's cells for a disc smaller by a
            # cell's diagonal (every centre whose inscribed disc is clear of the polygons
            # keeps it from the cells), the smoother on the fine raster of the polygons (its
            # footprint certificate exact against them: the window keeps the polygons)
            radius = max(0.0, radius - math.sqrt(2.0) * grid.resolution)
            cell = robot.drive.min_turning_radius / FINE_CELLS_PER_RADIUS
            grid = fine_window(grid, pts, robot.footprint.circumscribed_radius, cell)
    turn = 0.0 if direction > 0 else math.pi
    h0, h1 = float(poses[first, 2] + turn), float(poses[last, 2] + turn)
    kmax = 1.0 / robot.drive.min_turning_radius
    errors: list[str] = []
    corridor = None
    # the end's curvature along the direction of travel, from the last two poses (on an arc)
    d_end = float(np.hypot(*(pts[-1] - pts[-2]))) if len(pts) > 1 else 0.0
    k_end = (float(poses[last, 2] - poses[last - 1, 2]) / d_end) if d_end > 0.0 else 0.0
    every = (("polygons", kappa0), ("polygons", None), ("reversed", -k_end), ("witness", None))
    for kind, k_start in (every[i] for i in tries):
        # "reversed": the segment fitted from its end to its start, starting with the end's
        # curvature (the smoother takes a start curvature, not a goal one), then turned round
        p_fit = pts[::-1].copy() if kind == "reversed" else pts
        hs, hg = (h1 + math.pi, h0 + math.pi) if kind == "reversed" else (h0, h1)
        try:
            with timer.stage("corridor"):
                if kind == "witness":
                    corridor = witness_corridor(
                        cgrid, radius, dense_polyline(pts, cgrid.resolution)
                    )
                elif kind == "reversed":
                    corridor = build_polygon_corridor(cgrid, p_fit, radius)
                elif corridor is None:  # the two polygon fits share one corridor
                    corridor = build_polygon_corridor(cgrid, pts, radius)
            with timer.stage("smooth"):
                smooth = smoother.fit(
                    p_fit,
                    corridor,
                    raw_grid=grid,
                    radius=radius,
                    start=p_fit[0],
                    goal=p_fit[-1],
                    start_heading=hs,
                    goal_heading=hg,
                    start_curvature=k_start,
                    footprint=body_along(robot.footprint, direction, kind == "reversed"),
                )
        except (SmoothingError, InvalidInputError) as exc:
            errors.append(f"{kind}{'' if k_start is None else ' (start curvature)'}: {exc}")
            continue
        cert = smooth.certificate
        fcert = smooth.footprint_certificate
        if robot.footprint is not None and (fcert is None or not fcert.ok):
            errors.append(f"{kind}: the footprint is not certified")
            continue
        if cert is None or not cert.ok or cert.kappa_max_sampled > kmax * (1.0 + KAPPA_TOL):
            k = None if cert is None else cert.kappa_max_sampled
            errors.append(f"{kind}: not certified within 1/R (kappa {k})")
            continue
        if kind == "reversed":
            smooth = turned_round(smooth)
        return CarSegment(direction, first, last, corridor, smooth, kind)
    where = "forwards" if direction > 0 else "backwards"
    raise SmoothingError(
        f"no certified curve with curvature <= 1/R = {kmax:.6g} 1/m for the {where} segment "
        f"from ({pts[0, 0]:.6g}, {pts[0, 1]:.6g}) m to ({pts[-1, 0]:.6g}, {pts[-1, 1]:.6g}) "
        f"m: {'; '.join(errors)}",
        {"car_segment_failures": errors},
    )


def bodies_clear_of_cells(footprint: Footprint, grid: OccupancyGrid, poses: np.ndarray) -> bool:
    """Whether the body at every pose ``(x, y, heading)`` (m, m, rad) is clear of the cells.

    Clear of ``grid``'s occupied squares by more than :data:`CELL_FIT_CLEARANCE_CELLS`
    cells: a segment whose search poses are has room for its certified curve on the map's
    own cells (as on a map without polygons); one whose poses touch or near them (the
    search cleared them against the polygons) is fitted in :func:`fine_window`.
    """
    from trajopt.robot import polygons_clearance

    bodies = [footprint.at(float(x), float(y), float(h)) for x, y, h in poses]
    cap = 2.0 * CELL_FIT_CLEARANCE_CELLS * grid.resolution
    clr = polygons_clearance(bodies, grid, cap)
    return bool(np.all(clr > CELL_FIT_CLEARANCE_CELLS * grid.resolution))


def fine_window(grid: OccupancyGrid, pts: np.ndarray, reach: float, cell_m: float) -> OccupancyGrid:
    """Return a finer raster of ``grid``'s polygons around a segment's poses (m).

    The map's polygons (:attr:`astar.OccupancyGrid.polygons`) rasterised conservatively
    (:meth:`astar.OccupancyGrid.polygon_window`) in cells that divide ``grid``'s, of side at
    most ``cell_m`` (m), over the poses' box grown by ``reach`` (the
    body's circumscribed radius) plus :data:`FINE_PAD_M`, clipped to the map. The window's
    outside counts as occupied (as a map's), so a curve and a body certified in it are
    clear of the map's polygons and inside the map: the fits' certificate holds against the
    polygons, with a cover that reaches at most a fine cell's diagonal beyond them (where
    ``grid``'s cells reach up to its own diagonal).
    """
    k = max(1, math.ceil(grid.resolution / cell_m - 1e-9))
    res = grid.resolution / k
    ox, oy = grid.origin
    pad = reach + FINE_PAD_M
    lo = np.maximum(pts.min(axis=0) - pad, (ox, oy))
    hi = np.minimum(pts.max(axis=0) + pad, (ox + grid.width, oy + grid.height))
    # the window's corner on the map's own cell lines: its fine cells nest in the map's
    i0 = np.floor((lo - (ox, oy)) / grid.resolution)
    i1 = np.ceil((hi - (ox, oy)) / grid.resolution)
    i1 = np.minimum(i1, (grid.nx, grid.ny))
    a = np.array([ox, oy]) + i0 * grid.resolution
    b = np.array([ox, oy]) + i1 * grid.resolution
    return grid.polygon_window(res, (float(a[0]), float(a[1]), float(b[0]), float(b[1])))


def body_along(footprint: Footprint | None, direction: int, turned: bool) -> Footprint | None:
    """Return the footprint oriented along a fitted curve's tangent (None without one).

    The body faces the pose heading: along the tangent of a forwards segment's curve, against
    it backwards, where the footprint turned by ``pi`` (its vertices negated) is the body
    along the tangent; a curve fitted from the segment's end (``turned``) flips it again.
    """
    if footprint is None:
        return None
    if (direction > 0) != turned:
        return footprint
    return Footprint(-np.asarray(footprint.vertices, dtype=float))


def turned_round(path: SmoothPath) -> SmoothPath:
    """Return ``path`` traversed from its end to its start (the same certified curve).

    ``C'(u) = C(t_0 + t_N - u)``: the knots mirrored and the control points reversed give
    the same point set, spans and convex hulls, so the certificate (clearance, curvature
    magnitude, speed) holds as it is; ``stats["turned_round"]`` marks it.
    """
    c = path.curve
    t = np.asarray(c.t, dtype=float)
    curve = BSplineCurve((t[0] + t[-1]) - t[::-1], np.asarray(c.c)[::-1], c.k)
    return dataclasses.replace(path, curve=curve, stats=dict(path.stats, turned_round=True))


def dense_polyline(pts: np.ndarray, res: float) -> np.ndarray:
    """Return the poses' polyline resampled at most an eighth of a cell apart (m)."""
    d = np.hypot(*np.diff(pts, axis=0).T)
    out = [pts[:1]]
    for i, di in enumerate(d):
        n = max(1, math.ceil(di / (res / 8.0)))
        f = (np.arange(1, n + 1) / n)[:, None]
        out.append(pts[i] + f * (pts[i + 1] - pts[i]))
    return np.vstack(out)
