"""The escape manoeuvre of a car out of a tight end pose (a bay entered nose first).

Where a car's body barely fits at a pose (a perpendicular bay 1.2 car widths wide entered nose
first off a narrow aisle), the free poses round it form a thin tube: turning the car by a
degree moves the free positions sideways by centimetres, and a car moves sideways only through
cusps. A lattice search (:func:`astar.find_pose_path`) keeps one pose per cell and heading bin
and so drops the poses the tube is made of. :func:`find_escape` searches the continuous poses
from the tight pose outwards instead, until a pose whose body keeps ``room`` from every
polygon, where an ordinary search takes over (:func:`join_escape`).

The search (:func:`escape_kernel`, compiled) is best-first over poses reached by arcs of
curvature ``-kappa``, 0 and ``kappa`` (``kappa = 1 / radius``), forwards and backwards, of the
lengths ``moves`` (m) and of the longest clear length up to ``longest`` (m); a pose is dropped
only when its cell of ``cell`` m and ``heading_cell`` rad already holds one reached with no
more cusps. Its order: fewer cusps first, less ``rotation_weight`` per radian turned from the
tight pose's heading (either way: out of a tight bay the car must turn). Every move is tested
exactly against the polygons (:func:`astar.body_polygons.body_distance`), continuously: along an
arc of curvature ``k`` every point of a body whose farthest vertex lies ``rho`` from the
reference point moves at most ``1 + rho |k|`` per metre of arc, so a pose whose body keeps
``c >= margin`` from the polygons is followed by ``(c - margin) / (1 + rho |k|)`` m of arc that
keeps ``margin`` (:func:`arc_reach`: steps of that length, so that every pose of every move,
not only samples, keeps ``margin``). The longest clear length is found to within ``tol`` m.
Expansions decide the search (``max_expansions``); ``time_budget`` (s, wall clock) is a safety
net only.

A path it finds proves that an escape with that many cusps exists; it does not bound how few
an escape needs. Why written here: no kept library searches a car's continuous poses against
polygons exactly (OMPL's planners sample, with no certificate between their checks).
"""

from __future__ import annotations

import heapq
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numba
import numpy as np
from numba import njit, types
from numba.typed import Dict

from astar.body_polygons import body_distance, pack_polygons
from astar.errors import InvalidInputError, NoPathError
from astar.hybrid_shortcut import resample
from astar.reeds_shepp import advance

__all__ = [
    "ESCAPE_REASONS",
    "Escape",
    "NoEscapeError",
    "arc_reach",
    "escape_kernel",
    "find_escape",
    "join_escape",
    "pose_clearance",
    "reversed_pieces",
]

#: Why an escape search found nothing: every pose reachable expanded, the expansion cap, or
#: the wall-clock safety net (by the kernel's status code 0, 2, 3).
ESCAPE_REASONS = ("exhausted", "max_expansions", "time_budget")
#: Defaults of :func:`find_escape` as fractions of the turning radius (for the full-size car
#: of the parking benchmarks, R = 3 m: margin 1.2 cm, room 0.35 m, cells 1.8 cm, moves 5,
#: 10, 25, 50 cm, the longest 60 cm, the limit of a move to 1.5 mm).
MARGIN_R = 0.012 / 3.0
ROOM_R = 0.35 / 3.0
CELL_R = 0.006
MOVES_R = (0.05 / 3.0, 0.1 / 3.0, 0.25 / 3.0, 0.5 / 3.0)
LONGEST_R = 0.2
TOL_R = 0.0005
#: Default order weight: cusps per radian turned.
ROTATION_WEIGHT = 300.0
#: Default heading cell (rad): 0.3 degrees.
HEADING_CELL = math.radians(0.3)


class NoEscapeError(NoPathError):
    """The escape search found no pose with room (:func:`find_escape`).

    Attributes
    ----------
    reason : str
        One of :data:`ESCAPE_REASONS`.
    expanded : int
        Poses the search expanded.
    """

    def __init__(self, message: str, reason: str, expanded: int) -> None:
        super().__init__(message)
        self.reason = reason
        self.expanded = expanded


@dataclass(frozen=True, slots=True, eq=False)
class Escape:
    """An escape found by :func:`find_escape` (metres, radians).

    Parameters
    ----------
    pieces : ndarray of float64, shape (m, 5)
        ``(x, y, heading, curvature, signed length)`` of each arc from its start pose (m, m,
        rad, 1/m, m; the length negative backwards), from the tight pose outwards, in the order
        driven away from it; equal neighbours merged. ``(0, 5)`` when the pose has room.
    end : tuple of float
        The pose with room it reaches ``(x, y, heading)`` (m, m, rad).
    expanded : int
        Poses the search expanded.
    stats : dict
        ``seconds`` (wall clock of the search) and ``created`` (poses created).

    Attributes
    ----------
    cusps : int
        Changes of the direction of travel between the pieces.
    length : float
        Arc length driven (m).
    """

    pieces: np.ndarray
    end: tuple[float, float, float]
    expanded: int
    stats: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        a = np.array(self.pieces, dtype=np.float64, copy=True).reshape(-1, 5)
        a.flags.writeable = False
        object.__setattr__(self, "pieces", a)
        object.__setattr__(self, "end", tuple(float(v) for v in self.end))
        object.__setattr__(self, "stats", dict(self.stats))

    @property
    def cusps(self) -> int:
        """Changes of the direction of travel."""
        s = np.sign(self.pieces[:, 4])
        return int(np.count_nonzero(s[1:] != s[:-1]))

    @property
    def length(self) -> float:
        """Arc length driven (m)."""
        return float(np.abs(self.pieces[:, 4]).sum())


@njit(cache=True)
def clock():  # pragma: no cover - compiled
    """Return ``time.perf_counter()`` inside compiled code (s)."""
    with numba.objmode(t="float64"):
        t = time.perf_counter()
    return t


@njit(cache=True)
def pose_clearance(edges, starts, boxes, fp, x, y, th, cap, buf):  # pragma: no cover
    """Return the distance (capped at ``cap``) of the body at ``(x, y, th)`` to the polygons.

    ``fp`` ``(k, 2)``: the body counter-clockwise in the robot frame; ``buf`` ``(k, 2)``: work
    space; the polygons as :func:`astar.body_polygons.pack_polygons` packs them.
    """
    c = math.cos(th)
    s = math.sin(th)
    for j in range(fp.shape[0]):
        buf[j, 0] = x + c * fp[j, 0] - s * fp[j, 1]
        buf[j, 1] = y + s * fp[j, 0] + c * fp[j, 1]
    return body_distance(edges, starts, boxes, buf, cap)


@njit(cache=True)
def arc_reach(
    edges, starts, boxes, fp, rho, x, y, th, k, d, longest, margin, tol, c0, buf
):  # pragma: no cover - compiled
    """Return the longest length ``<= longest`` of an arc whose every pose keeps ``margin``.

    The arc leaves ``(x, y, th)`` at curvature ``k`` in direction ``d`` (+1 forwards, -1
    backwards); ``c0``: a lower bound of the body's clearance there (negative: unknown).
    Steps of ``(c - margin) / (1 + rho |k|)``, ``c`` the clearance where the step starts
    (module docstring): every pose up to the returned length keeps ``margin``; the arc goes
    on past it by less than ``tol`` before a pose keeps less (or it is ``longest``).
    """
    v = 1.0 + rho * abs(k)
    s = 0.0
    while s < longest:
        if s == 0.0 and c0 >= 0.0:
            c = c0
        else:
            px, py, pt = advance(x, y, th, k, d * s)
            # capped at one step of at most a quarter of the longest move: polygons farther
            # than that from the body are skipped by their boxes
            c = pose_clearance(
                edges, starts, boxes, fp, px, py, pt, margin + v * 0.25 * longest, buf
            )
        free = (c - margin) / v
        if free < tol:
            return s
        s = min(longest, s + free)
    return longest


@njit(cache=True)
def escape_kernel(
    edges,
    starts,
    boxes,
    fp,
    rho,
    pose,
    kmax,
    moves,
    longest,
    margin,
    tol,
    shortest,
    room,
    cell,
    cell_th,
    rot_w,
    turns,
    max_exp,
    deadline,
):  # pragma: no cover - compiled
    """Best-first searches of an escape, one per turn, in turn (module docstring).

    ``turns`` ``(t,)``: the sign of the rotation each search rewards (+1 counter-clockwise,
    -1 clockwise); the searches keep their own poses and cells and expand one pose each in
    turn (a search whose poses are spent is skipped), ``max_exp`` expansions in all.
    Lengths in the polygons' units.

    Returns
    -------
    tuple
        ``(status, last, expanded, created, xs, ys, ts, parent, kap, lens)``: status 1 found
        (``last`` the pose with room), 0 exhausted, 2 ``max_expansions``, 3 past ``deadline``
        (``perf_counter`` seconds); per pose created its ``(x, y, heading)``, its parent (-1
        for the first of each search), the curvature and signed length of the arc that reached
        it.
    """
    buf = np.empty((fp.shape[0], 2))
    nt = turns.shape[0]
    cap = 4 * max_exp + 1024
    xs = np.empty(cap)
    ys = np.empty(cap)
    ts = np.empty(cap)
    cusps = np.zeros(cap, np.int64)
    parent = np.full(cap, -1, np.int64)
    dirs = np.zeros(cap, np.int8)
    side = np.zeros(cap, np.int64)
    kap = np.zeros(cap)
    lens = np.zeros(cap)
    best = Dict.empty(types.int64, types.int64)
    heaps = []
    for h in range(nt):
        xs[h], ys[h], ts[h] = pose[0], pose[1], pose[2]
        side[h] = h
        heaps.append([(0.0, h)])
    n = nt
    done = np.zeros(cap, np.bool_)
    expanded = 0
    status = 0
    last = -1
    turn_no = 0
    while True:
        h = -1
        for q in range(nt):  # the next search in turn with poses left
            cand = (turn_no + q) % nt
            if len(heaps[cand]) > 0:
                h = cand
                break
        if h < 0:
            break
        turn_no = h + 1
        if expanded >= max_exp:
            status = 2
            break
        if (expanded & 255) == 0 and clock() > deadline:
            status = 3
            break
        _, i = heapq.heappop(heaps[h])
        if done[i]:
            continue
        done[i] = True
        expanded += 1
        c0 = pose_clearance(edges, starts, boxes, fp, xs[i], ys[i], ts[i], room, buf)
        if c0 >= room:
            status = 1
            last = i
            break
        for d in (-1, 1):
            for kk in (-1.0, 0.0, 1.0):
                k = kk * kmax
                far = arc_reach(
                    edges, starts, boxes, fp, rho, xs[i], ys[i], ts[i], k, d, longest, margin,
                    tol, c0, buf,
                )  # fmt: skip
                for j in range(moves.shape[0] + 1):
                    s = moves[j] if j < moves.shape[0] else far
                    if s > far or s < tol or (j < moves.shape[0] and s == far):
                        continue
                    if s < shortest and dirs[i] != 0 and dirs[i] != d:
                        continue  # a segment between cusps is at least ``shortest`` long
                    x, y, t = advance(xs[i], ys[i], ts[i], k, d * s)
                    key = (
                        (np.int64(round(x / cell)) * 1000003 + np.int64(round(y / cell))) * 1000003
                        + np.int64(round(t / cell_th))
                    ) * nt + h
                    c = cusps[i] + (1 if dirs[i] != 0 and dirs[i] != d else 0)
                    if n >= cap or (key in best and best[key] <= c):
                        continue
                    best[key] = c
                    xs[n], ys[n], ts[n] = x, y, t
                    cusps[n], parent[n], dirs[n], kap[n], lens[n] = c, i, d, k, d * s
                    side[n] = h
                    heapq.heappush(heaps[h], (c - rot_w * turns[h] * (t - pose[2]), n))
                    n += 1
    return status, last, expanded, n, xs[:n], ys[:n], ts[:n], parent[:n], kap[:n], lens[:n]


def find_escape(
    footprint: np.ndarray,
    pose: tuple[float, float, float],
    polygons: Sequence[np.ndarray],
    turning_radius: float,
    *,
    margin: float | None = None,
    room: float | None = None,
    cell: float | None = None,
    heading_cell: float = HEADING_CELL,
    moves: Sequence[float] | None = None,
    longest: float | None = None,
    tol: float | None = None,
    shortest: float | None = None,
    rotation_weight: float = ROTATION_WEIGHT,
    turns: Sequence[float] = (1.0, -1.0),
    max_expansions: int = 200_000,
    time_budget: float = math.inf,
) -> Escape:
    """Search the escape of a car's body from a tight pose to one with room (module docstring).

    Parameters
    ----------
    footprint : ndarray, shape (k, 2)
        The convex body in the robot frame (m; ``x`` forwards, ``y`` left), either orientation.
    pose : tuple of float
        The tight pose ``(x, y, heading)`` (m, m, rad); its body must keep ``margin``.
    polygons : sequence of ndarray, shape (j, 2)
        The obstacles: simple polygons (m).
    turning_radius : float
        The radius of the search's arcs (m), e.g. 1.05 times the car's least.
    margin, room, cell, moves, longest, tol : optional
        Clearance kept by every pose of every move, clearance of the end pose, the position
        cell, the fixed move lengths, the longest move and the tolerance of a move's limit
        (m); by default :data:`MARGIN_R`, :data:`ROOM_R`, :data:`CELL_R`, :data:`MOVES_R`,
        :data:`LONGEST_R` and :data:`TOL_R` times ``turning_radius``.
    shortest : float, optional
        No move that changes the direction of travel is shorter (m; default ``tol``), so no
        stretch between cusps is: a curve fitted to a fraction of a map cell between two
        cusps is ill-posed.
    heading_cell : float, optional
        The heading cell (rad).
    rotation_weight : float, optional
        Cusps per radian turned in the search's order.
    turns : sequence of float, optional
        The searches run in turn, one per sign: +1 rewards turning counter-clockwise, -1
        clockwise (the default both: which way out of a bay needs fewer expansions depends on
        centimetres of its geometry).
    max_expansions : int, optional
        Poses expanded before the search gives up.
    time_budget : float, optional
        Wall-clock safety net (s).

    Returns
    -------
    Escape
        From ``pose`` to the first pose expanded whose body keeps ``room``.

    Raises
    ------
    InvalidInputError
        A field is not finite or positive where it must be, or the body at ``pose`` does not
        keep ``margin`` from the polygons (the message names the field, the value and the rule).
    NoEscapeError
        The search found no pose with room (its reason and expansions in the message).
    """
    r = _positive("turning_radius", turning_radius)
    margin = _positive("margin", MARGIN_R * r if margin is None else margin)
    room = _positive("room", ROOM_R * r if room is None else room)
    cell = _positive("cell", CELL_R * r if cell is None else cell)
    longest = _positive("longest", LONGEST_R * r if longest is None else longest)
    tol = _positive("tol", TOL_R * r if tol is None else tol)
    shortest = _positive("shortest", tol if shortest is None else shortest)
    heading_cell = _positive("heading_cell", heading_cell)
    if not (math.isfinite(rotation_weight) and rotation_weight >= 0.0):
        raise InvalidInputError(f"rotation_weight must be finite and >= 0, got {rotation_weight}")
    mv = np.array([m * r for m in MOVES_R] if moves is None else list(moves), dtype=float)
    if mv.ndim != 1 or not np.all(np.isfinite(mv)) or np.any(mv <= 0.0):
        raise InvalidInputError(f"moves must be positive lengths (m), got {mv.tolist()}")
    if int(max_expansions) < 1:
        raise InvalidInputError(f"max_expansions must be >= 1, got {max_expansions}")
    if not (time_budget > 0.0):
        raise InvalidInputError(f"time_budget must be > 0 s, got {time_budget}")
    tw = np.array(list(turns), dtype=float).reshape(-1)
    if len(tw) < 1 or not np.all(np.isin(tw, (1.0, -1.0))):
        raise InvalidInputError(f"turns must be signs +1 or -1 (at least one), got {tw.tolist()}")
    p = tuple(float(v) for v in pose)
    if len(p) != 3 or not all(math.isfinite(v) for v in p):
        raise InvalidInputError(f"pose must be 3 finite numbers (x, y, heading), got {pose}")
    fp = np.ascontiguousarray(np.asarray(footprint, dtype=float).reshape(-1, 2))
    if len(fp) < 3 or not np.all(np.isfinite(fp)):
        raise InvalidInputError(f"footprint must be >= 3 finite vertices (m), got {fp.tolist()}")
    if float(np.sum(fp[:, 0] * np.roll(fp[:, 1], -1) - np.roll(fp[:, 0], -1) * fp[:, 1])) < 0:
        fp = np.ascontiguousarray(fp[::-1])  # counter-clockwise
    rho = float(np.max(np.hypot(fp[:, 0], fp[:, 1])))
    # coordinates relative to the pose (parking cases may lie far from the origin)
    shift = (p[0], p[1])
    edges, starts, boxes = pack_polygons(polygons, shift)
    local = np.array([0.0, 0.0, p[2]])
    c0 = pose_clearance(edges, starts, boxes, fp, 0.0, 0.0, p[2], margin + 1.0, np.empty_like(fp))
    if c0 < margin:
        raise InvalidInputError(
            f"pose {list(p)}: the body keeps {c0:.6g} m from the polygons, less than the "
            f"escape's margin {margin:.6g} m"
        )
    t0 = time.perf_counter()
    deadline = t0 + time_budget if math.isfinite(time_budget) else 1e300
    out = escape_kernel(
        edges, starts, boxes, fp, rho, local, 1.0 / r, mv, longest, margin, tol, shortest,
        room, cell, heading_cell, float(rotation_weight), tw, int(max_expansions), deadline,
    )  # fmt: skip
    seconds = time.perf_counter() - t0
    status, last, expanded, created = (int(v) for v in out[:4])
    if status != 1:
        reason = ESCAPE_REASONS[{0: 0, 2: 1, 3: 2}[status]]
        raise NoEscapeError(
            f"the escape from pose {list(p)} found no pose whose body keeps {room:.6g} m from "
            f"the polygons ({reason}: {expanded} expansions of at most {int(max_expansions)}, "
            f"{seconds:.3g} s)",
            reason,
            expanded,
        )
    xs, ys, ts, parent, kap, lens = out[4:]
    arcs = []
    i = last
    while parent[i] >= 0:
        q = parent[i]
        arcs.append([xs[q] + shift[0], ys[q] + shift[1], ts[q], kap[i], lens[i]])
        i = q
    arcs.reverse()
    merged: list[list[float]] = []
    for a in arcs:
        if merged and merged[-1][3] == a[3] and (merged[-1][4] < 0) == (a[4] < 0):
            merged[-1][4] += a[4]
        else:
            merged.append(list(a))
    end = (float(xs[last] + shift[0]), float(ys[last] + shift[1]), float(ts[last]))
    return Escape(
        np.array(merged, dtype=float).reshape(-1, 5),
        end,
        expanded,
        {"seconds": seconds, "created": created},
    )


def _positive(name: str, value: float) -> float:
    v = float(value)
    if not (math.isfinite(v) and v > 0.0):
        raise InvalidInputError(f"{name} must be finite and > 0, got {value}")
    return v


def join_escape(
    pieces: Sequence[np.ndarray],
    goal: tuple[float, float, float],
    step: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Return one path (the layout of :class:`astar.PosePath`) through consecutive pieces.

    Parameters
    ----------
    pieces : sequence of ndarray, shape (m_i, 5)
        Runs of ``(x, y, heading, curvature, signed length)`` per arc, in driving order, each
        starting where the previous ends (any units, as long as they agree): e.g. an escape
        from the start (:attr:`Escape.pieces`), a search's pieces, an escape into the goal
        (:func:`reversed_pieces`).
    goal : tuple of float
        The last pose ``(x, y, heading)``.
    step : float
        The poses' largest arc-length spacing.

    Returns
    -------
    poses, directions, segments, pieces
        As :func:`astar.hybrid_shortcut.resample` returns them (headings unwrapped).
    """
    runs = [np.asarray(p, dtype=float).reshape(-1, 5) for p in pieces]
    runs = [r for r in runs if len(r)]
    if not runs:
        raise InvalidInputError("pieces must hold at least one arc, got none")
    rows = []
    th_end = None
    for run in runs:
        r = run.copy()
        if th_end is not None:  # unwrap each run onto the heading the previous one ends with
            r[:, 2] += 2.0 * math.pi * round((th_end - r[0, 2]) / (2.0 * math.pi))
        rows.append(r)
        th_end = float(advance.py_func(*r[-1])[2])
    gth = goal[2] + 2.0 * math.pi * round((th_end - goal[2]) / (2.0 * math.pi))
    return resample(np.vstack(rows), float(step), (float(goal[0]), float(goal[1]), gth))


def reversed_pieces(pieces: np.ndarray) -> np.ndarray:
    """Return arcs driven the other way in time: last first, each from its end, length negated.

    ``pieces`` ``(m, 5)``: ``(x, y, heading, curvature, signed length)``; an escape from a goal
    pose (:attr:`Escape.pieces`) becomes the manoeuvre that ends at the goal.
    """
    out = []
    for x, y, th, k, s in np.asarray(pieces, dtype=float).reshape(-1, 5)[::-1]:
        ex, ey, eth = advance.py_func(x, y, th, k, s)
        out.append([ex, ey, eth, k, -s])
    return np.array(out, dtype=float).reshape(-1, 5)
