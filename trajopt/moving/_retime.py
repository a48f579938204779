"""Re-time a trajectory along its fixed path so that predicted movers pass (or are passed).

:func:`retime_for_movers` keeps the path and changes only ``s(t)``:

1. if the trajectory as it is passes :func:`certify_movers`, it is returned unchanged (the
   time-optimal timing passes before, or never meets, every mover);
2. the movers' forbidden regions of the ``(s, t)`` plane on the *sufficient* grid
   (:mod:`._st_grid`) and a search over a family of jerk-limited profiles on it
   (:mod:`._st_search`): rest at the start, drive time-optimally (ruckig's rest-to-rest
   profile under the path's speed cap table, :class:`_PathTables`) to a stop, rest there,
   ..., drive to the goal and stand there; a dynamic programme over the stops finds the
   earliest arrival. From a moving start the first drive leaves at once from the start state
   (to the goal, or braking to rest at a stop);
3. the rests are shortened (:mod:`._tighten`): each drive, with everything after it, is
   launched as early as the movers' windows at fine nodes allow (exact for disc movers,
   sampled with a Lipschitz pad for polygons, :mod:`._shape_windows`) (the wait at the
   start first, then the waits at stops), and from rest the path's one drive (the plan's
   own timing) is launched at the earliest time they allow, the earlier arrival of the two
   tried first;
4. the chosen profile becomes one :class:`trajopt.Trajectory` on the same path (its rests are
   phases of zero speed) and is certified by :func:`certify_movers`, which decides: the
   profile before step 3 when the shortened one fails; when both fail (the grid's
   inflation is a proof for the grid, so only numerical slips) the search retries with a
   finer time step. When the search finds nothing, the path's one drive after the earliest
   wait the fine windows allow is tried;
5. when nothing is found, a sweep of the nodes a non-decreasing ``s(t)`` with ``v <= v_max``
   can occupy on the *necessary* grid names the mover that blocks the path and the time
   (:class:`BlockedError`).

The cap table, the grid's node points, the rest-to-rest drives and a moving start's
launches of the last few paths are kept (:data:`_TABLES`), found again by the path's
geometry (:func:`._path_bounds.geometry_key`): new predictions for the same path reuse them, also when the
path is a new object of the same geometry (a re-plan that keeps its rest at the same splice).
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Sequence
from typing import Any

import numpy as np

from trajopt.errors import BlockedError, InvalidInputError, TimingError
from trajopt.geometry import CurveSegment
from trajopt.motion import Trajectory
from trajopt.moving._braking import braking_distance, state_at
from trajopt.moving._certificate import (
    MoverCertificate,
    ccw,
    certify_movers,
    check_movers,
    convex_distance,
    shape_at,
)
from trajopt.moving._mover_segments import mover_table
from trajopt.moving._obstacle import MovingObstacle
from trajopt.moving._path_bounds import geometry_key, kappa_max
from trajopt.moving._shape_windows import ShapeWindows, launch_floor
from trajopt.moving._st_grid import STGrid, grid_nodes, reach_bound, reachable, st_grid
from trajopt.moving._st_search import Piece, compose, describe, parts_of, search
from trajopt.moving._tighten import (
    FINE_DS,
    REFINE_SPAN,
    FineWindows,
    bisect_start,
    pass_band,
    tail_occupancy,
    tail_s,
    tighten,
)
from trajopt.timing import RuckigProfile, build_cap_table, time_parameterize


def _piece_of(tr: Any, s0: float, s1: float) -> Piece:
    rows = np.column_stack([tr.phase_t, tr.phase_s + s0, tr.phase_v, tr.phase_a, tr.phase_j])
    return Piece(rows, float(tr.duration), s0, s1)


#: Relative speed tolerance of the cap test of ruckig's rows: the timing's own profiles reach
#: the cap table's value plus ruckig's velocity margin (1e-9 m/s), and a motion that starts in
#: such a state must pass.
CAP_TOLERANCE = 1e-7
_LOW = np.array([1.0, 1.0, 1.0 - CAP_TOLERANCE, 1.0 - CAP_TOLERANCE, 1.0 - CAP_TOLERANCE, 1.0])


def _under_caps(table: Any, rows: np.ndarray) -> bool:
    """Return whether ruckig rows ``(t0, s0, v0, a0, jerk, duration)`` stay under ``table``'s caps.

    :meth:`trajopt.timing.CapTable.rows_ok` of the same motion with its speed scaled by
    ``1 - CAP_TOLERANCE`` (speed, acceleration and jerk of every row; its arc lengths move by
    at most that fraction of the distance).
    """
    return bool(table.rows_ok(np.array(rows, dtype=float) * _LOW))


def _piece_of_rows(rows: np.ndarray | None, s1: float) -> Piece | None:
    """Return a :class:`Piece` of ruckig rows ``(t0, s0, v0, a0, jerk, duration)``, or ``None``."""
    if rows is None or rows.shape[0] == 0:
        return None
    duration = float(rows[-1, 0] + rows[-1, 5])
    return Piece(np.ascontiguousarray(rows[:, :5]), duration, float(rows[0, 1]), float(s1))


class _PathTables:
    """What a path's re-timings share: its speed cap table, grid points, rest-to-rest drives.

    Kept for the last few paths (:data:`_TABLES`): re-timing the same path for new
    predictions (a re-plan that keeps its path) reuses them.
    """

    def __init__(self, path: Any, robot: Any, length: float, speed_limits: Any = None) -> None:
        self.path, self.robot, self.length = path, robot, length
        self.speed_limits = speed_limits  # the zones the drives hold besides the robot's caps
        self.table = build_cap_table(path, robot, length, 0.0, 0.0, speed_limits)
        self.vtop = self.table.vtop
        self.rk = RuckigProfile(float(robot.a_max), float(robot.j_max))
        self.drives: dict[tuple[float, float], Piece | None] = {}
        self.points: dict[float, np.ndarray] = {}
        self.key: tuple[Any, ...] = (id(path),)
        self.launches: dict[tuple[Any, ...], dict[float, Piece | None]] = {}

    def nodes(self, s: np.ndarray, ds: float) -> np.ndarray:
        """Return the path's points (m), shape (n, 2), at the grid nodes ``s`` of spacing ``ds``."""
        if ds not in self.points:
            tb = self.table
            u = np.interp(s, tb.s_nodes, tb.u_nodes)
            self.points[ds] = np.asarray(self.path(u), dtype=float)
        return self.points[ds]

    def move(self, state: tuple[float, float, float], s1: float) -> Piece | None:
        """Return the time-optimal jerk-limited motion from ``state`` ``(s, v, a)`` to rest at ``s1``.

        Ruckig's profile under the highest cap when it stays under the cap table, else under
        the lowest cap over ``[s, s1]``; ``None`` when neither does (a fall-back times the
        piece of the path then).
        """
        tb, rk = self.table, self.rk
        for low in (False, True):  # the lowest cap looked up only when needed
            vcap = tb.range_min(state[0], s1) if low else self.vtop
            rows = rk.solve(state, (s1, 0.0, 0.0), vcap)
            if rows is not None and _under_caps(tb, rows):
                return _piece_of_rows(rows, s1)
        return None

    def segment(self, s0: float, s1: float, v0: float = 0.0, a0: float = 0.0) -> Piece | None:
        """Return the path's piece ``[s0, s1]`` timed by :func:`trajopt.time_parameterize`.

        The whole path is timed as itself (its arc-length table and compiled look-ups
        already made; from rest, on the tables' own cap table, not built again), a part of
        it as its :class:`~trajopt.geometry.CurveSegment`.
        """
        path = self.path
        u_lo, u_hi = path.domain
        ua = u_lo if s0 <= 0.0 else float(path.u_at_s(s0))
        ub = u_hi if s1 >= self.length else float(path.u_at_s(s1))
        whole = ua == u_lo and ub == u_hi
        try:
            tr = time_parameterize(
                path if whole else CurveSegment(path, ua, ub),
                self.robot,
                v_start=v0,
                a_start=a0,
                speed_limits=self.speed_limits,
                cap_table=self.table if whole and v0 == 0.0 and a0 == 0.0 else None,
            )
        except (TimingError, InvalidInputError, ValueError):
            return None
        return _piece_of(tr, s0, s1)

    def launches_from(self, traj: Trajectory) -> dict[float, Piece | None]:
        """Return the kept launches (motions to rest at ``s1``, by ``s1``) of a moving start.

        Keyed by ``traj``'s timing, byte for byte (a re-plan at the same splice gives the same
        kept rest); the last :data:`_LAUNCHES_KEPT` timings are kept. Holds ``traj`` itself as
        the launch to the goal.
        """
        phases = (traj.phase_t, traj.phase_s, traj.phase_v, traj.phase_a, traj.phase_j)
        key = (float(traj.duration), *(np.asarray(x, dtype=float).tobytes() for x in phases))
        if key not in self.launches:
            self.launches[key] = {self.length: _piece_of(traj, 0.0, self.length)}
            while len(self.launches) > _LAUNCHES_KEPT:
                del self.launches[next(iter(self.launches))]
        return self.launches[key]

    def drive(self, s0: float, s1: float) -> Piece | None:
        """Return the rest-to-rest drive over ``[s0, s1]`` (m) (cached)."""
        key = (s0, s1)
        if key not in self.drives:
            piece = self.move((s0, 0.0, 0.0), s1)
            self.drives[key] = self.segment(s0, s1) if piece is None else piece
        return self.drives[key]


#: How much (s) the fine windows' time band is widened (:func:`_fine_windows`).
BAND_PAD = 0.05
#: Timings of a moving start whose launches a path's tables keep.
_LAUNCHES_KEPT = 4

#: The tables of the last paths re-timed (most recent last).
_TABLES: list[_PathTables] = []
_TABLES_KEPT = 4


def _tables(traj: Trajectory) -> _PathTables:
    """Return the :class:`_PathTables` of ``traj``'s path, robot and speed-limit zones (built or reused)."""
    key = geometry_key(traj.path)
    zones = traj.speed_limits
    for i, tb in enumerate(_TABLES):
        same = tb.path is traj.path or tb.key == key
        if same and tb.robot == traj.robot and tb.speed_limits is zones:
            _TABLES.append(_TABLES.pop(i))
            return tb
    tb = _PathTables(traj.path, traj.robot, float(traj.length), zones)
    tb.key = key
    rests = (traj.phase_v == 0.0) & (traj.phase_a == 0.0) & (traj.phase_j == 0.0)
    if traj.v_start == 0.0 and traj.phase_a[0] == 0.0:  # the drive (0, L): the plan's own
        # timing (a re-timing's, with rests on the way: the path timed from rest again)
        whole = tb.segment(0.0, tb.length) if rests.any() else _piece_of(traj, 0.0, tb.length)
        if whole is not None:
            tb.drives[(0.0, tb.length)] = whole
    _TABLES.append(tb)
    del _TABLES[:-_TABLES_KEPT]
    return tb


def _robot_shape(traj: Trajectory, margin: float) -> tuple[float, np.ndarray | None, float]:
    """Return ``(limit, body, stretch)`` for the grids (:func:`st_grid`).

    A disc robot: its radius plus the margin. A footprint robot: the margin, its CCW polygon
    and ``1 + R kappa_max``; on a path with no curvature bound, its circumscribed disc.
    """
    fp = traj.robot.footprint
    if fp is None:
        return float(traj.robot.radius) + margin, None, 1.0
    body = ccw(np.asarray(fp.vertices, dtype=float))
    reach = float(np.max(np.hypot(body[:, 0], body[:, 1])))
    kappa = kappa_max(traj.path)
    if not math.isfinite(kappa):
        return reach + margin, None, 1.0
    return margin, body, 1.0 + reach * kappa


def _overlap_at_start(traj: Any, movers: Sequence[MovingObstacle], margin: float) -> None:
    """Refuse a mover that overlaps the robot at ``t = 0`` (:class:`InvalidInputError`)."""
    if not movers:
        return
    u0 = traj.path.domain[0]
    p0 = np.asarray(traj.path(u0), dtype=float).reshape(1, 2)
    robot: np.ndarray = p0[:, None, :]
    fp = traj.robot.footprint
    if fp is not None:
        v = ccw(np.asarray(fp.vertices, dtype=float))
        theta = float(traj.sample(np.zeros(1)).theta[0])
        c, sn = math.cos(theta), math.sin(theta)
        robot = (p0 + v @ np.array([[c, sn], [-sn, c]]))[None]
    # most movers are far: clear when their points' distance exceeds both reaches and the margin
    reach_r = (
        float(np.max(np.hypot(*(robot[0] - p0[0]).T))) if fp is not None else traj.robot.radius
    )
    # their places and reaches at t = 0 from the certificate's table of these movers (kept
    # for it): numpy.interp's positions, radius_at(0) plus the farthest vertex
    table = mover_table(movers)
    zero = np.zeros(len(movers))
    c = table.seg.at(table.seg.row(np.arange(len(movers)), zero), zero)[:, :2]
    reach_m = (table.rad0 + table.grow * zero) + table.reach
    gap = np.hypot(*(c - p0[0]).T) - reach_m - reach_r - margin
    for m in (m for m, g in zip(movers, gap, strict=True) if not g > 1e-9):
        d = float(convex_distance(robot, shape_at(m, np.zeros(1)))[0])
        need = margin + float(m.radius_at(0.0)) + (traj.robot.radius if fp is None else 0.0)
        if d < need:
            raise InvalidInputError(
                f"moving obstacle {m.name!r} overlaps the robot at t = 0: distance {d:.6g} m "
                f"< {need:.6g} m (robot, its radius and the margin)"
            )


def _blocked(grid: STGrid, movers: Sequence[MovingObstacle], robot: Any, v0: float = 0.0) -> None:
    speed = max(float(robot.v_max), v0)
    s_up = reach_bound(grid.t, speed, float(robot.a_max), float(robot.j_max), v0)
    ok, k, i = reachable(grid, speed, s_up)
    if ok:
        return
    row = grid.who[k]
    ahead = np.flatnonzero(row[i:] >= 0)
    j = int(row[i + ahead[0]]) if ahead.size else int(np.max(grid.who[k]))
    j = max(j, 0)
    name = movers[j].name
    t = float(grid.t[k])
    what = (
        f"still stands on it at t = {t:.3f} s, the end of the times searched"
        if k == grid.t.shape[0] - 1
        else f"leaves no way past from t = {t:.3f} s"
    )
    raise BlockedError(
        f"moving obstacle {name!r} blocks the path: it {what} "
        f"(robot at s <= {grid.s[i]:.3f} m of {grid.s[-1]:.3f} m; no motion along the path "
        f"under v_max={speed:.3g} m/s and the acceleration limits gets past)",
        mover=name,
        t=t,
    )


def retime_for_movers(
    traj: Trajectory,
    movers: Sequence[MovingObstacle],
    *,
    margin: float = 0.0,
    dt: float = 0.05,
    ds: float = 0.02,
    not_before: float = 0.0,
    certificate: MoverCertificate | None = None,
) -> Trajectory:
    """Re-time ``traj`` along its path so that it keeps clear of the movers (module docstring).

    Parameters
    ----------
    traj : Trajectory
        A disc or footprint robot's timed curve ending at rest (``v_end = 0``). It may start
        moving (``v_start > 0`` or a non-zero acceleration at ``t = 0``, e.g. the rest of a
        trajectory being driven): the re-timed motion then starts from that state (it cannot
        rest at once; it may brake to a stop and wait there).
    movers : sequence of MovingObstacle
        The predictions (seconds from the trajectory's ``t = 0``).
    margin : float
        Extra distance to every mover (m), >= 0.
    dt, ds : float
        The ``(s, t)`` grid's spacings (s, m).
    not_before : float
        The robot rests at the start until this time (s), >= 0 (a turn in place there):
        the result starts with a rest at least that long. Only for a start at rest.
    certificate : MoverCertificate, optional
        The certificate (:func:`certify_movers`) of ``traj`` as it is, after the rest
        ``not_before``, against these movers and this margin, when the caller has it (a
        caller that certified the same motion first): it decides whether ``traj`` is kept
        as planned, and is not computed again.

    Returns
    -------
    Trajectory
        ``traj``'s motion when it is already clear, else the same path re-timed with rests
        (a new value either way; ``traj`` is not changed), with ``traj``'s start state.
        ``stats["moving"]`` holds the certificate, the plan (``"as planned"``, ``"wait
        1.250 s at the start, stop at s = 2.100 m until t = 7.800 s"`` or, from a moving
        start, ``"brake to s = 0.400 m, stop at s = 0.400 m until t = 3.100 s"``) and the
        wall time (s). Its certificate (:func:`certify_movers`) holds at every instant until
        the last prediction ends.

    Raises
    ------
    BlockedError
        No profile of the family avoids the movers; the mover and the time are named (from
        the necessary grid when no non-decreasing ``s(t)`` with speed ``<= v_max`` gets
        past a mover within the grid's horizon).
    InvalidInputError
        A mover overlaps the robot at ``t = 0``; a trajectory that does not end at rest;
        ``not_before > 0`` with a moving start; bad spacings.
    """
    t_all = time.perf_counter()
    movers = check_movers(movers)
    if not isinstance(traj, Trajectory):
        raise InvalidInputError(f"traj must be a trajopt.Trajectory, got {type(traj).__name__}")
    if traj.v_end != 0.0:
        raise InvalidInputError(
            f"retime_for_movers needs a trajectory that ends at rest, got v_end={traj.v_end!r} m/s"
        )
    if not (isinstance(margin, (int, float)) and math.isfinite(margin) and margin >= 0.0):
        raise InvalidInputError(f"margin must be a finite number >= 0 m, got {margin!r}")
    for name, val in (("dt", dt), ("ds", ds)):
        if not (isinstance(val, (int, float)) and math.isfinite(val) and val > 0.0):
            raise InvalidInputError(f"{name} must be a finite number > 0, got {val!r}")
    if not (isinstance(not_before, (int, float)) and math.isfinite(not_before) and not_before >= 0):
        raise InvalidInputError(f"not_before must be a finite number >= 0 s, got {not_before!r}")
    v0, a0 = float(traj.v_start), float(traj.phase_a[0])
    moving = v0 != 0.0 or a0 != 0.0
    if moving and not_before > 0.0:
        raise InvalidInputError(
            f"not_before must be 0 for a trajectory that starts moving (v_start={v0!r} m/s, "
            f"a={a0!r} m/s^2), got {not_before!r} s"
        )
    limit, body, stretch = _robot_shape(traj, float(margin))
    _overlap_at_start(traj, movers, float(margin))
    path, length, robot = traj.path, float(traj.length), traj.robot
    plan = traj  # without the rest below: its drive (0, L) is the plan's own
    if not_before > 0.0:  # the plan as it is, after the rest
        whole = _piece_of(traj, 0.0, length)
        rows, duration = compose([(0.0, None, 0.0), (float(not_before), whole, 0.0)], length)
        traj = _timed(traj, rows, duration)
    cert = certify_movers(traj, movers, margin=margin) if certificate is None else certificate
    if cert.ok:
        return _with_stats(traj, cert, "as planned", t_all)
    vmax = float(robot.v_max)
    t_last = max(m.t_last for m in movers)
    horizon = max(t_last, 0.0) + 2.0 * traj.duration + 2.0
    tables = _tables(plan)
    grid_args = {
        "ds": ds,
        "horizon": horizon,
        "speed": max(vmax, v0),
        "body": body,
        "stretch": stretch,
    }
    s_nodes, ds_used = grid_nodes(length, ds)
    points = tables.nodes(s_nodes, ds_used)
    launch, brake_at = None, None
    if moving:
        brake_at = float(braking_distance(v0, a0, float(robot.a_max), float(robot.j_max)))
        first = tables.launches_from(traj)

        def launch(s1: float) -> Piece | None:
            if s1 < brake_at - 1e-9:  # closer than the robot can stop
                return None
            if s1 not in first:
                piece = tables.move((0.0, v0, a0), s1)
                if piece is None:
                    piece = _follow_then_stop(traj, tables, s1)
                first[s1] = tables.segment(0.0, s1, v0, a0) if piece is None else piece
            return first[s1]

    step = float(dt)
    for _ in range(3):
        grid = st_grid(
            path,
            length,
            movers,
            limit,
            dt=step,
            sufficient=True,
            points=points,
            leave=0.0 if moving else float(not_before),
            **grid_args,
        )
        k_min = int(math.ceil(not_before / step - 1e-9))
        found = search(
            grid,
            tables.drive,
            vmax,
            float(robot.a_max),
            k_min,
            float(robot.j_max),
            launch=launch,
            brake_at=brake_at,
        )
        if found is None:
            break
        schedule = [(t0, pc) for t0, pc, _ in found[0] if pc is not None]
        done = _tightened(traj, schedule, movers, margin, not_before, moving, tables, grid)
        if done is not None:
            return _with_stats(*done, t_all)
        step *= 0.5
    if not moving and found is None:  # the one drive after a wait, launched exactly
        done = _tightened(traj, [], movers, margin, not_before, moving, tables, grid)
        if done is not None:
            return _with_stats(*done, t_all)
    # why: the necessary grid names the mover that leaves no way past, when one does
    nec = st_grid(path, length, movers, limit, dt=dt, sufficient=False, points=points, **grid_args)
    _blocked(nec, movers, robot, v0)
    first_name = cert.mover or movers[0].name
    raise BlockedError(
        f"no re-timing along the path (rests at the start and at stops) avoids moving "
        f"obstacle {first_name!r} (near t = {cert.witness_t:.3f} s) within {horizon:.3g} s",
        mover=first_name,
        t=cert.witness_t,
    )


def _tightened(
    traj: Trajectory,
    schedule: list[tuple[float, Piece]],
    movers: Sequence[MovingObstacle],
    margin: float,
    not_before: float,
    moving: bool,
    tables: _PathTables,
    grid: STGrid,
) -> tuple[Trajectory, Any, str] | None:
    """Return the schedule, its rests shortened, as a certified trajectory, or ``None``.

    Tries, earliest arrival first: the schedule with every rest as short as the fine windows
    allow (:mod:`._tighten`), (from rest) the path's one drive launched at the earliest time
    they allow, and the schedule as it is; the first that :func:`certify_movers` accepts,
    with its certificate and its plan in words. The fine windows of a disc robot are
    closed-form for disc movers, sampled (:class:`._shape_windows.ShapeWindows`) when a
    mover is a polygon; a footprint robot: the wait at the start bisected over certificates. An empty ``schedule``: only
    the one drive, at any launch up to the grid's horizon.
    """
    length = tables.length

    def timed(sched: list[tuple[float, Piece]]) -> Trajectory:
        rows, duration = compose(parts_of(sched, moving), length)
        return _timed(traj, rows, duration)

    def arrival(sched: list[tuple[float, Piece]]) -> float:
        return sched[-1][0] + sched[-1][1].duration if sched else math.inf

    candidates: list[list[tuple[float, Piece]]] = []
    if traj.robot.footprint is None:
        speed = max(float(traj.robot.v_max), abs(float(traj.v_start)))
        t_to = arrival(schedule) if schedule else float(grid.t[-1])
        limit = float(traj.robot.radius) + margin
        whole = None if moving else tables.drive(0.0, length)
        if len(schedule) == 1 and schedule[0][1] is whole:
            whole = None  # the tightened schedule is this drive at its earliest launch
        latest = [schedule] if schedule else []  # the motions' latest launches
        if whole is not None:
            t_max = min(arrival(schedule), float(grid.t[-1])) - whole.duration
            latest.append([(t_max, whole)])
        firsts = [schedule] if schedule and not moving else []
        firsts += [[(0.0, whole)]] if whole is not None else []
        span = (not_before, t_to, speed)
        fine, t_from = _fine_windows(tables, grid, movers, limit, span, latest, firsts)
        if schedule:
            candidates.append(tighten(fine, schedule, math.inf if moving else t_from))
        if whole is not None:
            one = [(0.0, whole)]
            drives, rests = tail_occupancy(fine, one, 0)
            launch = fine.earliest(drives, t_from, t_max, tail_s(one, 0), rests)
            if launch is not None:
                candidates.append([(launch, whole)])
    elif schedule and not moving and schedule[0][0] > not_before:

        def ok(t1: float) -> bool:
            sched = [(t - schedule[0][0] + t1, pc) for t, pc in schedule]
            return bool(certify_movers(timed(sched), movers, margin=margin).ok)

        t1 = bisect_start(ok, max(not_before, schedule[0][0] - grid.dt), schedule[0][0])
        candidates.append([(t - schedule[0][0] + t1, pc) for t, pc in schedule])
    if schedule:
        candidates.append(schedule)
    seen: set[tuple[tuple[float, int], ...]] = set()
    for sched in sorted(candidates, key=arrival):  # stable: the schedule as it is last
        key = tuple((t, id(pc)) for t, pc in sched)
        if key in seen:
            continue
        seen.add(key)
        out = timed(sched)
        cert = certify_movers(out, movers, margin=margin)
        if cert.ok:
            return out, cert, describe(sched, moving, length)
    return None


def _fine_windows(
    tables: _PathTables,
    grid: STGrid,
    movers: Sequence[MovingObstacle],
    limit: float,
    span: tuple[float, float, float],
    latest: Sequence[list[tuple[float, Piece]]] = (),
    firsts: Sequence[list[tuple[float, Piece]]] = (),
) -> tuple[FineWindows, float]:
    """Return the movers' windows at the path's fine nodes (spacing at most ``dt`` times the speed).

    Only the pairs of a piece of a track and a fine node that can come within the limit are
    solved (:func:`._disc_windows.near_pairs`, an exact filter), and only for the times the
    motions asked about can be near the node: ``span = (t_from, t_to, V)``, the robot leaves
    the start no earlier than ``t_from`` (s), arrives at the goal no later than ``t_to`` (s)
    and drives at most ``V`` (m/s), so it is within ``h/2`` of ``s_i`` only between
    ``t_from + (s_i - h/2) / V`` and ``t_to - (L - s_i - h/2) / V``; with polygon movers
    also cut to :func:`._tighten.pass_band` of ``latest``, the schedules at their latest
    launches (discs' closed-form windows save less than the cut's ~0.2 ms). Widened by
    :data:`BAND_PAD` (the drives' samples reach a step beyond) and ``V`` by 1 %. A window left
    out by a wrong bound would only make a launch too early, which the certificate refuses.
    With polygon movers and ``firsts`` (the schedules from the start whose first launches
    are asked about, each launched as a block), the band is then cut again from a later
    ``t_from``: the least launch :func:`._shape_windows.launch_floor` allows them, less
    :data:`BAND_PAD` and two :data:`._tighten.REFINE_SPAN` (the refinement of a launch moves
    it earlier by at most that much), never past a latest first launch. Returns the windows
    and that ``t_from`` (s), the earliest launch to ask them about.
    """
    h = min(FINE_DS, grid.dt * float(tables.robot.v_max))
    s, h = grid_nodes(tables.length, h)
    pts = tables.nodes(s, h)
    tb = tables.table
    t_from, t_to, speed = span
    v = 1.01 * speed
    kind = FineWindows if all(m.vertices is None for m in movers) else ShapeWindows
    hi = np.minimum(t_to - np.maximum(tables.length - s - 0.5 * h, 0.0) / v, np.inf)

    def band_from(t0: float) -> tuple[np.ndarray, np.ndarray]:
        p_lo, p_hi = pass_band(s, h, latest if kind is ShapeWindows else (), t0)
        lo = np.maximum(t0 + np.maximum(s - 0.5 * h, 0.0) / v, p_lo)
        return lo - BAND_PAD, np.minimum(hi, p_hi) + BAND_PAD

    band = band_from(t_from)
    if kind is ShapeWindows and firsts:
        floor = launch_floor(s, pts, movers, limit, band, firsts, t_from)
        # never past a latest launch (the launches asked about start no later)
        floor = min(floor - 2.0 * REFINE_SPAN - BAND_PAD, *(x[0][0] for x in latest))
        if floor > t_from:
            t_from = floor
            band = band_from(t_from)

    def where(s_at: np.ndarray) -> np.ndarray:
        return np.asarray(tables.path(np.interp(s_at, tb.s_nodes, tb.u_nodes)), dtype=float)

    return kind(s, pts, movers, limit, band, where, float(tables.robot.v_max)), t_from


def _follow_then_stop(traj: Trajectory, tables: _PathTables, s1: float) -> Piece | None:
    """Return ``traj``'s motion until it must brake, then its shortest stop at ``s1`` (m).

    The latest time ``tau`` (on two grids of 256, the second inside the bracket of the first)
    whose state still stops by ``s1`` (:func:`braking_distance`), then ruckig's stop to rest
    at ``s1`` under the speed at ``tau``; ``None`` when that stop leaves the cap table (the
    caller times the piece of the path then).
    """
    robot = traj.robot
    a_max, j_max = float(robot.a_max), float(robot.j_max)
    lo, hi = 0.0, float(traj.duration)
    for _ in range(2):
        tau = np.linspace(lo, hi, 256)
        s, v, a = state_at(traj, tau)
        ok = s1 - s - braking_distance(v, a, a_max, j_max) >= 0.0
        if not ok[0]:
            return None
        i = int(np.argmin(ok)) - 1 if not ok.all() else tau.shape[0] - 1
        lo, hi = float(tau[i]), float(tau[min(i + 1, tau.shape[0] - 1)])
    s, v, a = (float(x[0]) for x in state_at(traj, np.array([lo])))
    rows = tables.rk.solve((s, v, a), (s1, 0.0, 0.0), max(v, 1e-9))
    if rows is None or not _under_caps(tables.table, rows):
        return None
    phases = (traj.phase_t, traj.phase_s, traj.phase_v, traj.phase_a, traj.phase_j)
    head = np.column_stack(phases)[traj.phase_t < lo]
    tail = rows[:, :5].copy()
    tail[:, 0] += lo
    duration = float(lo + rows[-1, 0] + rows[-1, 5])
    return Piece(np.concatenate([head, tail]), duration, 0.0, float(s1))


def _timed(traj: Trajectory, rows: np.ndarray, duration: float) -> Trajectory:
    """Return ``traj``'s path with the phase rows ``(t, s, v, a, j)``, shape (p, 5), from rest to rest."""
    return Trajectory(
        path=traj.path,
        robot=traj.robot,
        phase_t=rows[:, 0],
        phase_s=rows[:, 1],
        phase_v=rows[:, 2],
        phase_a=rows[:, 3],
        phase_j=rows[:, 4],
        duration=duration,
        v_start=traj.v_start,
        v_end=0.0,
        stats=dict(traj.stats),
        theta_grid_s=traj.theta_grid_s,
        theta_grid=traj.theta_grid,
        u_grid=traj.u_grid,
        steps=traj.steps,
        direction=traj.direction,
        speed_limits=traj.speed_limits,
    )


def _with_stats(traj: Trajectory, cert: Any, label: str, t_all: float) -> Trajectory:
    """Return ``traj`` as a new value whose ``stats["moving"]`` describes the re-timing."""
    stats = dict(traj.stats)
    stats["moving"] = {
        "plan": label,
        "certificate": cert.summary(),
        "time_s": time.perf_counter() - t_all,
    }
    return dataclasses.replace(traj, stats=stats)
