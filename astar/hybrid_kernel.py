"""Compiled kernels of :func:`astar.find_pose_path`: Hybrid-A* over (x, y, heading bin).

The search (Dolgov, Thrun, Montemerlo and Diebel, "Practical search techniques in path
planning for autonomous driving", 2008; "Path planning for autonomous vehicles in unknown
semi-structured environments", IJRR 2010) keeps continuous poses ``(x, y, heading)`` in
*cell units* (cell ``(ix, iy)`` covers ``[ix - 0.5, ix + 0.5) x [iy - 0.5, iy + 0.5)``, its
centre at ``(ix, iy)``) and merges them in discrete states ``(ix, iy, heading bin)``: a state
keeps the cheapest pose that reached it, and a closed state is never reopened.

* **Motion primitives**: an arc of signed curvature ``kappa`` (``curvatures``, e.g.
  ``{+1/R, 0, -1/R}``) and arc length ``prim_len``, forwards and (with ``reverse``) backwards.
* **Costs** (cells): the primitive's length, times ``reverse_penalty`` backwards, times
  ``1 + turn_penalty`` on an arc, times ``1 + steer_penalty`` when its curvature differs from
  the previous primitive's; plus ``cusp_penalty`` when the direction of travel flips.
* **Collision check**: each primitive (and each analytic shot) is sampled at arc-length spacing
  ``<= step`` (sub-cell) and every cell that the chords between consecutive samples cross is
  tested (a supercover traversal: a chord through a cell corner tests both side cells); on an
  arc, the chord moved by the sagitta towards the bulge too (:func:`arc_clear`). A
  primitive that stays inside the box of free cells round its start pose's cell (each
  cell's box measured once per search, :func:`free_box`) passes without that traversal
  (:func:`arc_in_box`): in open space, most of them. A primitive is tested only when its
  end state is open and not yet reached more cheaply (a closed state is never reopened,
  so the order of the checks changes nothing but their cost).
  In the footprint mode (``fp`` not empty) every pose of the arc also keeps the robot's
  convex footprint, rotated by the heading, ``fmargin`` cells from the raw map's occupied
  squares and inside the grid (:func:`footprint_arc_clear`).
* **Analytic expansion**: every few expansions (every ``max(1, floor(h / analytic_ratio))``,
  so every expansion near the goal) the Reeds-Shepp (Dubins without ``reverse``) word from the
  expanded pose to the goal pose that is cheapest *under the search's costs* (backwards
  lengths weighted, cusps charged; not merely the shortest, which is how Smac's shots end up
  driving long distances backwards) is collision-checked; a clear one gives a path that ends
  exactly at the goal pose. The search then goes on, for at most as many expansions again
  (plus ``polish``), while an open node could still lead to a cheaper path (its ``f``, a lower
  bound of the cost, is below the best path's cost), and returns the cheapest path found.
* **From the goal** (``motion.backward``): the query's first pose is the path's end and its
  second the path's start; the search drives each primitive the opposite way to the path
  (so the path's costs still apply: its backwards primitives cost ``reverse_penalty``), its
  shots are words from the path's start to the expanded pose, and its heuristic measures
  the car length that way (a Dubins length is not symmetric).
* **Heuristic**: ``max(h2d, euclid, car)``: ``h2d`` a lower bound of the 8-connected shortest
  distance on the free grid from the goal's cell (:func:`distance_field`, no corner cutting,
  as Smac's 2-D heuristic), ``car`` the obstacle-free Reeds-Shepp/Dubins length, evaluated
  within ``car_window`` cells of the goal (farther, it exceeds the Euclidean distance by a
  bounded amount that ``h2d`` already dominates) and lazily: a node enters the open list with
  ``max(h2d, euclid)``, and when popped the first time it gets ``car`` too and goes back if its
  ``f`` grew (a Reeds-Shepp length costs a few microseconds; most nodes are never popped).
"""

from __future__ import annotations

import math
import time
from typing import NamedTuple

import numba
import numpy as np
from numba import njit

from astar.body_polygons import body_distance
from astar.reeds_shepp import advance, car_word
from astar.search_kernels import heap_pop, heap_push

__all__ = [
    "KernelCollision",
    "KernelCosts",
    "KernelLimits",
    "KernelMotion",
    "KernelQuery",
    "distance_field",
    "footprint_arc_clear",
    "footprint_hit",
    "footprint_word_clear",
    "hybrid_kernel",
    "word_clear",
]

FOUND = 1
EXHAUSTED = 0
MAX_EXPANSIONS = 2
TIME_BUDGET = 3


# The records :func:`hybrid_kernel` takes (numba reads a NamedTuple's fields as typed values;
# :func:`astar.find_pose_path` builds them with the field types given, one compiled signature).
class KernelQuery(NamedTuple):
    """The grid, its heuristic field and the two poses of one :func:`hybrid_kernel` run.

    Attributes
    ----------
    free : ndarray of uint8, shape (ny, nx)
        1 on free cells.
    h2d : ndarray of float64, shape (ny, nx)
        :func:`distance_field` from the goal's cell (cells).
    sx, sy, sth : float
        Start pose (cells, cells, rad).
    gx, gy, gth : float
        Goal pose (cells, cells, rad).
    """

    free: np.ndarray
    h2d: np.ndarray
    sx: float
    sy: float
    sth: float
    gx: float
    gy: float
    gth: float


class KernelMotion(NamedTuple):
    """The car and its motion primitives.

    Attributes
    ----------
    radius : float
        Turning radius ``R`` (cells).
    curvatures : ndarray of float64, shape (nc,)
        Signed curvatures of the primitives (1/cells).
    prim_len : float
        Arc length of every primitive (cells).
    nbins : int
        Heading bins.
    reverse : bool
        Backwards primitives and Reeds-Shepp shots (else forwards only, Dubins shots).
    backward : bool
        Search from the goal (the query's ``sx, sy, sth`` is then the path's *end*, its
        ``gx, gy, gth`` the path's *start*): the search runs back in time, each primitive
        is driven in the opposite direction to the one the path drives it in (the path's
        backwards primitives cost ``reverse_penalty``), and the shots are words from the
        path's start to the expanded pose (a pull-out from a parking slot, searched where
        space is tight, whose shots land in the open).
    fine_r : float
        Cells: within this distance of either end pose the states are finer
        (:func:`state_key`: ``fine_f`` x ``fine_f`` sub-cells per cell and ``fine_f``
        times the heading bins) and primitives ``prim_len / fine_f`` long are expanded
        besides the others; ``<= 0``: off.
    fine_f : int
        ``>= 1``: the refinement factor of the fine states and primitives.
    """

    radius: float
    curvatures: np.ndarray
    prim_len: float
    nbins: int
    reverse: bool
    backward: bool
    fine_r: float
    fine_f: int


class KernelCosts(NamedTuple):
    """The costs of a path and the ordering of the search.

    Attributes
    ----------
    reverse_penalty : float
        ``>= 1``: multiplies a backwards primitive's length.
    cusp_penalty : float
        ``>= 0``: cells added per change of direction.
    turn_penalty : float
        ``>= 0``: an arc costs its length times ``1 + turn_penalty``.
    steer_penalty : float
        ``>= 0``: a change of curvature costs the length times ``1 + steer_penalty`` more.
    analytic_ratio : float
        ``> 0``: a shot every ``max(1, h / analytic_ratio)`` expansions.
    hweight : float
        ``>= 1``: ``f = g + hweight * h`` (1: A*; more: weighted A*, faster, cost <=
        ``hweight`` times the cheapest).
    car_window : float
        Cells: the car-length heuristic is evaluated closer than this to the goal.
    """

    reverse_penalty: float
    cusp_penalty: float
    turn_penalty: float
    steer_penalty: float
    analytic_ratio: float
    hweight: float
    car_window: float


class KernelLimits(NamedTuple):
    """When the search gives up.

    Attributes
    ----------
    max_expansions : int
        Expansions at most.
    deadline : float
        ``time.perf_counter()`` value at which the search gives up (s).
    polish : int
        After the first path: search on for at most ``expansions + polish`` more.
    """

    max_expansions: int
    deadline: float
    polish: int


class KernelCollision(NamedTuple):
    """The collision checks: the grid's cells, the exact clearance mode, the footprint mode.

    Attributes
    ----------
    step : float
        Collision sampling spacing (cells).
    safe : ndarray of uint8, shape (ny, nx)
        Exact mode: 1 where every point of the cell keeps ``exact_r`` (else a 1 x 1 array).
    occ : ndarray of uint8, shape (ny, nx)
        Exact and footprint modes: 1 on the raw map's occupied cells (else 1 x 1).
    exact_r : float
        ``> 0``: every chord keeps this Euclidean distance from ``occ`` (cells); ``<= 0``: off.
    fp : ndarray of float64, shape (k, 4)
        Footprint vertices and outward normals (footprint mode); shape (0, 4): off.
    fsafe : ndarray of uint8, shape (ny, nx)
        1 where the footprint needs no test (footprint mode).
    frho : float
        The footprint's circumscribed radius (cells).
    fmargin : float
        Cells: every pose's footprint keeps this distance from ``occ`` (footprint mode).
    fslack : float
        Cells: the body moves at most this far between a pose and its tested sample.
    fmin_slack : float
        Cells: the least slack a failed sample test is refined to
        (:func:`footprint_arc_clear`; ``>= fslack``: no refinement).
    onext : ndarray of int32, shape (ny, nx + 1)
        Footprint mode: :func:`astar.hybrid_modes.edge_next` of ``occ`` (the next cell of
        value 1 along each row; else 1 x 2).
    fdist : ndarray of float64, shape (ny, nx)
        Footprint mode: a lower bound of each cell centre's distance to the occupied
        squares and the outside (:func:`footprint_discs_clear`; else 1 x 1).
    discs : ndarray of float64, shape (n, 3)
        Footprint mode: discs covering the footprint (``(0, 3)``: no quick test).
    pedges, pstarts, pboxes : ndarray
        Footprint mode: the raw map's polygons in cells
        (:func:`astar.body_polygons.pack_polygons`; no edges: none known), tested exactly
        where the occupied squares do not clear the body (:func:`_fp_clear`).
    """

    step: float
    safe: np.ndarray
    occ: np.ndarray
    exact_r: float
    fp: np.ndarray
    fsafe: np.ndarray
    frho: float
    fmargin: float
    fslack: float
    fmin_slack: float
    onext: np.ndarray
    fdist: np.ndarray
    discs: np.ndarray
    pedges: np.ndarray
    pstarts: np.ndarray
    pboxes: np.ndarray


@njit(cache=True)
def distance_field(free, gx, gy, sx, sy, slack):  # pragma: no cover - compiled
    """Lower bound of the 8-connected grid distance (cells) to cell ``(gx, gy)``.

    Dial's bucket queue with integer step costs 5 (straight) and 7 (diagonal, which needs both
    orthogonal cells it passes between free): distances ``d / 5`` are exact for straight
    moves and under-estimate a diagonal (1.4 for ``sqrt(2)``), so they bound the octile
    distance from below. The search stops once cell ``(sx, sy)`` is settled and the frontier
    is ``slack`` cells beyond it; every cell not settled by then gets the frontier distance,
    which is below its true distance (a lower bound still).

    Parameters
    ----------
    free : ndarray of uint8, shape (ny, nx)
        1 on free cells.
    gx, gy : int
        The source cell (free).
    sx, sy : int
        The cell whose distance the caller needs first (the start).
    slack : float
        Cells to go on past ``(sx, sy)``'s distance (``inf``: the whole free region).

    Returns
    -------
    dist : ndarray of float64, shape (ny, nx)
        Distance in cells (a lower bound); ``inf`` on blocked cells and, when the search
        exhausted its region, on cells it could not reach.
    reached : bool
        Whether ``(sx, sy)`` was reached.
    """
    ny, nx = free.shape
    w = nx + 2  # padded with a blocked ring: no bounds checks in the loop
    pf = np.zeros((ny + 2) * w, dtype=np.uint8)
    for iy in range(ny):
        for ix in range(nx):
            pf[(iy + 1) * w + ix + 1] = free[iy, ix]
    big = np.int64(1) << 60
    d = np.full((ny + 2) * w, big, dtype=np.int64)
    # E, W, N, S, then NE, NW, SE, SW with the two orthogonal cells each diagonal passes
    off = np.array([1, -1, w, -w, w + 1, w - 1, -w + 1, -w - 1], dtype=np.int64)
    side_a = np.array([0, 0, 0, 0, 1, -1, 1, -1], dtype=np.int64)
    side_b = np.array([0, 0, 0, 0, w, w, -w, -w], dtype=np.int64)
    cap = 1024
    buckets = np.empty((8, cap), dtype=np.int64)
    counts = np.zeros(8, dtype=np.int64)
    src = (gy + 1) * w + gx + 1
    d[src] = 0
    buckets[0, 0] = src
    counts[0] = 1
    pending = 1
    cur = np.int64(0)
    s = (sy + 1) * w + sx + 1
    stop = big
    while pending > 0:
        b = cur & 7
        while counts[b] > 0:
            counts[b] -= 1
            pending -= 1
            u = buckets[b, counts[b]]
            if d[u] != cur:
                continue  # stale entry
            for k in range(8):
                v = u + off[k]
                if pf[v] == 0:
                    continue
                step = 5
                if k >= 4:
                    if pf[u + side_a[k]] == 0 or pf[u + side_b[k]] == 0:
                        continue
                    step = 7
                nd = cur + step
                if nd < d[v]:
                    d[v] = nd
                    bb = nd & 7
                    if counts[bb] == cap:
                        nb = np.empty((8, 2 * cap), dtype=np.int64)
                        for i in range(8):
                            for j in range(counts[i]):
                                nb[i, j] = buckets[i, j]
                        buckets = nb
                        cap *= 2
                    buckets[bb, counts[bb]] = v
                    counts[bb] += 1
                    pending += 1
        if stop == big and d[s] <= cur:
            stop = cur + np.int64(min(slack * 5.0, 1e15))
        if cur >= stop:
            break
        cur += 1
    out = np.empty((ny, nx))
    frontier = (cur + 1) / 5.0
    for iy in range(ny):
        for ix in range(nx):
            di = d[(iy + 1) * w + ix + 1]
            if free[iy, ix] == 0:
                out[iy, ix] = np.inf
            elif di <= cur:
                out[iy, ix] = di / 5.0
            elif pending > 0:
                out[iy, ix] = frontier  # not settled: at least the frontier's distance
            else:
                out[iy, ix] = np.inf  # unreachable
    return out, d[s] < big


@njit(cache=True, inline="always")
def _cell_free(free, ix, iy):  # pragma: no cover - compiled
    ny, nx = free.shape
    return 0 <= ix < nx and 0 <= iy < ny and free[iy, ix] != 0


@njit(cache=True)
def segment_clear(free, x0, y0, x1, y1):  # pragma: no cover - compiled
    """Whether every cell the segment ``(x0, y0) -> (x1, y1)`` (cell units) crosses is free."""
    u0 = x0 + 0.5
    v0 = y0 + 0.5
    u1 = x1 + 0.5
    v1 = y1 + 0.5
    ix = int(math.floor(u0))
    iy = int(math.floor(v0))
    ex = int(math.floor(u1))
    ey = int(math.floor(v1))
    if not _cell_free(free, ix, iy):
        return False
    if ix == ex and iy == ey:
        return True
    if not _cell_free(free, ex, ey):
        return False
    du = u1 - u0
    dv = v1 - v0
    sx = 1 if du > 0.0 else -1
    sy = 1 if dv > 0.0 else -1
    inf = np.inf
    tdx = abs(1.0 / du) if du != 0.0 else inf
    tdy = abs(1.0 / dv) if dv != 0.0 else inf
    if du > 0.0:
        tmx = (ix + 1.0 - u0) * tdx
    elif du < 0.0:
        tmx = (u0 - ix) * tdx
    else:
        tmx = inf
    if dv > 0.0:
        tmy = (iy + 1.0 - v0) * tdy
    elif dv < 0.0:
        tmy = (v0 - iy) * tdy
    else:
        tmy = inf
    left = abs(ex - ix) + abs(ey - iy)
    while left > 0:
        if tmx < tmy:
            ix += sx
            tmx += tdx
            left -= 1
        elif tmy < tmx:
            iy += sy
            tmy += tdy
            left -= 1
        else:  # through a cell corner: both side cells count as touched
            if not _cell_free(free, ix + sx, iy) or not _cell_free(free, ix, iy + sy):
                return False
            ix += sx
            iy += sy
            tmx += tdx
            tmy += tdy
            left -= 2
        if not _cell_free(free, ix, iy):
            return False
    return True


@njit(cache=True, inline="always")
def _box_sq_dist(x, y, cx, cy):  # pragma: no cover - compiled
    """Squared distance (cells^2) from point ``(x, y)`` to the square of cell ``(cx, cy)``."""
    dx = max(abs(x - cx) - 0.5, 0.0)
    dy = max(abs(y - cy) - 0.5, 0.0)
    return dx * dx + dy * dy


@njit(cache=True, inline="always")
def _point_seg_sq_dist(px, py, x0, y0, dx, dy, dd):  # pragma: no cover - compiled
    """Squared distance from ``(px, py)`` to the segment ``(x0, y0) + t (dx, dy)``, t in [0, 1]."""
    t = 0.0
    if dd > 0.0:
        t = min(max(((px - x0) * dx + (py - y0) * dy) / dd, 0.0), 1.0)
    ex = x0 + t * dx - px
    ey = y0 + t * dy - py
    return ex * ex + ey * ey


@njit(cache=True, inline="always")
def _seg_hits_box(x0, y0, dx, dy, cx, cy):  # pragma: no cover - compiled
    """Whether the segment ``(x0, y0) + t (dx, dy)``, t in [0, 1], meets cell ``(cx, cy)``'s square.

    Liang-Barsky clipping against the closed square.
    """
    t0 = 0.0
    t1 = 1.0
    for k in range(4):
        if k == 0:
            p, q = -dx, x0 - (cx - 0.5)
        elif k == 1:
            p, q = dx, (cx + 0.5) - x0
        elif k == 2:
            p, q = -dy, y0 - (cy - 0.5)
        else:
            p, q = dy, (cy + 0.5) - y0
        if p == 0.0:
            if q < 0.0:
                return False
        else:
            t = q / p
            if p < 0.0:
                t0 = max(t0, t)
            else:
                t1 = min(t1, t)
            if t0 > t1:
                return False
    return True


@njit(cache=True)
def segment_clearance_ok(occ, x0, y0, x1, y1, r):  # pragma: no cover - compiled
    """Whether the segment ``(x0, y0) -> (x1, y1)`` keeps Euclidean distance ``>= r`` (cells).

    Exact: the distance from the closed segment to every occupied square of ``occ`` (cell
    ``(ix, iy)``'s square ``[ix - 0.5, ix + 0.5] x [iy - 0.5, iy + 0.5]``) within reach, and to
    the outside of the grid. Between a segment and a square that it does not meet, the
    distance is the least of the end points' distances to the square and the corners'
    distances to the segment.
    """
    ny, nx = occ.shape
    # the outside of the grid: a linear distance along the segment, least at an end
    for x, y in ((x0, y0), (x1, y1)):
        if min(x + 0.5, nx - 0.5 - x, y + 0.5, ny - 0.5 - y) < r:
            return False
    r2 = r * r
    dx = x1 - x0
    dy = y1 - y0
    dd = dx * dx + dy * dy
    lo_x = max(0, int(math.ceil(min(x0, x1) - r - 0.5)))
    hi_x = min(nx - 1, int(math.floor(max(x0, x1) + r + 0.5)))
    lo_y = max(0, int(math.ceil(min(y0, y1) - r - 0.5)))
    hi_y = min(ny - 1, int(math.floor(max(y0, y1) + r + 0.5)))
    bx0 = min(x0, x1)
    bx1 = max(x0, x1)
    by0 = min(y0, y1)
    by1 = max(y0, y1)
    for iy in range(lo_y, hi_y + 1):
        for ix in range(lo_x, hi_x + 1):
            if occ[iy, ix] == 0:
                continue
            # the square against the segment's bounding box first (a lower bound)
            gx = max(ix - 0.5 - bx1, bx0 - ix - 0.5, 0.0)
            gy = max(iy - 0.5 - by1, by0 - iy - 0.5, 0.0)
            if gx * gx + gy * gy >= r2:
                continue
            if _seg_hits_box(x0, y0, dx, dy, ix, iy):
                return False
            d = min(_box_sq_dist(x0, y0, ix, iy), _box_sq_dist(x1, y1, ix, iy))
            for sx in (-0.5, 0.5):
                for sy in (-0.5, 0.5):
                    d = min(d, _point_seg_sq_dist(ix + sx, iy + sy, x0, y0, dx, dy, dd))
            if d < r2:
                return False
    return True


@njit(cache=True)
def chord_clear(free, safe, occ, r, x0, y0, x1, y1):  # pragma: no cover - compiled
    """Whether a chord between two samples is clear (:func:`segment_clear` on ``free``).

    With ``r > 0`` (the exact mode of :func:`hybrid_kernel`) the chord must also keep
    Euclidean distance ``>= r`` from the occupied squares of ``occ`` (the raw map) and the
    outside: checked exactly (:func:`segment_clearance_ok`) unless every cell it crosses is
    ``safe`` (every point of a safe cell keeps ``r``).
    """
    if not segment_clear(free, x0, y0, x1, y1):
        return False
    if r <= 0.0 or segment_clear(safe, x0, y0, x1, y1):
        return True
    return segment_clearance_ok(occ, x0, y0, x1, y1, r)


@njit(cache=True)
def free_box(free, safe, exact, ring, ix, iy, k_max):  # pragma: no cover - compiled
    """Return the largest ``k <= k_max`` whose box of cells round ``(ix, iy)`` is all clear.

    The box: cells ``[ix - k, ix + k] x [iy - k, iy + k]``, all inside the grid, free and
    (``exact``) ``safe``; -1 when the cell itself is not. ``ring`` (uint8, shape (ny, nx))
    caches ``k + 1`` per cell (0: not measured yet), so each cell is measured at most once
    per search, ring by ring outwards (``(2 k_max + 1)^2`` cells at most; ``k_max < 255``).
    """
    v = ring[iy, ix]
    if v != 0:
        return v - 1
    ny, nx = free.shape
    k = -1
    for r in range(k_max + 1):
        ok = True
        if ix - r < 0 or iy - r < 0 or ix + r >= nx or iy + r >= ny:
            break
        for j in range(-r, r + 1):  # the square ring of Chebyshev radius r
            for a, b in ((ix + j, iy - r), (ix + j, iy + r), (ix - r, iy + j), (ix + r, iy + j)):
                if free[b, a] == 0 or (exact and safe[b, a] == 0):
                    ok = False
                    break
            if not ok:
                break
        if not ok:
            break
        k = r
    ring[iy, ix] = k + 1
    return k


@njit(cache=True, inline="always")
def arc_in_box(free, safe, exact, ring, x, y, s, k_max):  # pragma: no cover - compiled
    """Return True when an arc of length ``|s|`` from ``(x, y)`` surely passes :func:`arc_clear`.

    Every point of the arc lies within ``|s|`` of ``(x, y)`` (Chebyshev distance too), so
    within ``|s| + |(x, y) - c|_inf`` of its cell's centre ``c``: when that (plus 0.01 for the
    sagitta-moved chords and rounding) stays below ``k + 1/2``, ``k`` from :func:`free_box`,
    every chord and corner :func:`arc_clear` tests lies in the box of free (and, exact mode,
    safe) cells round ``c``. False: not shown; test with :func:`arc_clear`.
    """
    ny, nx = free.shape
    ix = int(math.floor(x + 0.5))
    iy = int(math.floor(y + 0.5))
    if ix < 0 or iy < 0 or ix >= nx or iy >= ny:
        return False
    need = abs(s) + max(abs(x - ix), abs(y - iy)) + 0.01
    if need >= k_max + 0.5:
        return False
    return free_box(free, safe, exact, ring, ix, iy, k_max) + 0.5 > need


@njit(cache=True)
def arc_clear(free, x, y, th, kappa, s, step, safe, occ, r):  # pragma: no cover - compiled
    """Whether the arc from pose ``(x, y, th)``, curvature ``kappa``, signed length ``s`` is free.

    Sampled at arc-length spacing ``<= step``; between two samples the arc lies between the
    chord and the chord moved by the sagitta towards the arc's bulge (``(1 - cos(kappa ds /
    2)) / |kappa|``, below ``0.0025`` cells for ``step = 0.2`` and ``R >= 2``), and both
    segments are traversed, so a bulge across a cell boundary is caught. With ``r > 0`` each
    chord (the ``m = ceil(|s| / step)`` samples ``advance(x, y, th, kappa, s q / m)``, ``q = 0
    .. m``, joined) also keeps Euclidean distance ``r`` from the raw map ``occ``
    (:func:`chord_clear`).
    """
    m = max(1, int(math.ceil(abs(s) / step)))
    px = x
    py = y
    for q in range(1, m + 1):
        qx, qy, _ = advance(x, y, th, kappa, s * q / m)
        if not chord_clear(free, safe, occ, r, px, py, qx, qy):
            return False
        if kappa != 0.0:
            # offset of the arc's midpoint from the chord's, a hair longer
            mx, my, _ = advance(x, y, th, kappa, s * (q - 0.5) / m)
            ox = (mx - 0.5 * (px + qx)) * (1.0 + 1e-6)
            oy = (my - 0.5 * (py + qy)) * (1.0 + 1e-6)
            if not segment_clear(free, px + ox, py + oy, qx + ox, qy + oy):
                return False
        px = qx
        py = qy
    return True


@njit(cache=True)
def word_clear(
    free, x, y, th, radius, kinds, lens, n, step, safe, occ, r
):  # pragma: no cover - compiled
    """Whether a Reeds-Shepp/Dubins word from pose ``(x, y, th)`` is clear (:func:`arc_clear`)."""
    for i in range(n):
        if lens[i] == 0.0:
            continue
        kappa = kinds[i] / radius
        if not arc_clear(free, x, y, th, kappa, lens[i], step, safe, occ, r):
            return False
        x, y, th = advance(x, y, th, kappa, lens[i])
    return True


# --------------------------------------------------------------------------- footprint mode
@njit(cache=True)
def footprint_hit(occ, onext, fsafe, fp, x, y, th, grow, buf):  # pragma: no cover - compiled
    """Test the footprint at pose ``(x, y, th)``, grown by ``grow`` cells, against the raw map.

    Parameters
    ----------
    occ : ndarray of uint8, shape (ny, nx)
        Nonzero on occupied cells (closed squares of side 1): 1 on an occupied cell with a
        free cell among its 8 neighbours, 2 (:func:`astar.hybrid_modes.edge_occupancy`) on
        one whose 8 neighbours are occupied or outside, which is not tested but for the
        cell of the pose's centre: a connected body that contains a point of a free square
        and meets an occupied square meets one of value 1 (where it first enters the
        occupied squares, along a path in the body from that point), so the test stays
        exact. Plain 0/1 maps work as they are.
    onext : ndarray of int32, shape (ny, nx + 1)
        :func:`astar.hybrid_modes.edge_next` of ``occ``: along each row, the next cell of
        value 1 at or after a column (``nx``: none), so that a row of the footprint's box is
        read only at its cells of value 1 (the others are skipped all the same).
    fsafe : ndarray of uint8, shape (ny, nx)
        :func:`astar.hybrid_modes.footprint_safe` for a reach of at least ``rho + grow``
        (or zeros): a pose whose centre lies in a safe cell is clear without further test.
    fp : ndarray of float64, shape (k, 4)
        :func:`astar.hybrid_modes.footprint_polygon`: counter-clockwise vertices and
        unit outward normals, cells.
    x, y, th : float
        The pose: cells, radians.
    grow : float
        ``>= 0`` cells: the footprint's Minkowski sum with the disc of this radius is tested.
    buf : ndarray of float64, shape (k, 5)
        Scratch space.

    Returns
    -------
    int
        -1: the grown footprint is disjoint from every occupied square and inside the
        grid; -2: it leaves the grid; otherwise ``iy * nx + ix`` of
        an occupied square within ``grow`` of the footprint (or meeting it). Exact: a
        square is hit iff its distance to the polygon is ``<= grow`` (0 when they meet).
    """
    ny, nx = occ.shape
    cx = int(math.floor(x + 0.5))
    cy = int(math.floor(y + 0.5))
    if 0 <= cx < nx and 0 <= cy < ny and fsafe[cy, cx] != 0:
        return -1
    c = math.cos(th)
    s = math.sin(th)
    k = fp.shape[0]
    minx = np.inf
    maxx = -np.inf
    miny = np.inf
    maxy = -np.inf
    for i in range(k):
        wx = x + c * fp[i, 0] - s * fp[i, 1]
        wy = y + s * fp[i, 0] + c * fp[i, 1]
        nwx = c * fp[i, 2] - s * fp[i, 3]
        nwy = s * fp[i, 2] + c * fp[i, 3]
        buf[i, 0] = wx
        buf[i, 1] = wy
        buf[i, 2] = nwx
        buf[i, 3] = nwy
        buf[i, 4] = nwx * wx + nwy * wy  # the polygon's support along its own edge normal
        minx = min(minx, wx)
        maxx = max(maxx, wx)
        miny = min(miny, wy)
        maxy = max(maxy, wy)
    # the outside of the grid: the grown convex polygon is inside the rectangle iff every
    # vertex keeps grow from its sides
    if minx - grow < -0.5 or maxx + grow > nx - 0.5 or miny - grow < -0.5 or maxy + grow > ny - 0.5:
        return -2
    if occ[cy, cx] != 0:  # inside the grid: the centre's cell is in the body
        return cy * nx + cx
    g2 = grow * grow
    lo_x = max(0, int(math.ceil(minx - grow - 0.5)))
    hi_x = min(nx - 1, int(math.floor(maxx + grow + 0.5)))
    lo_y = max(0, int(math.ceil(miny - grow - 0.5)))
    hi_y = min(ny - 1, int(math.floor(maxy + grow + 0.5)))
    for iy in range(lo_y, hi_y + 1):
        # the row's cells of value 1 only (free cells and those inside solid blocks: see occ)
        nxt = onext[iy, lo_x]
        while nxt <= hi_x:
            ix = nxt
            nxt = onext[iy, ix + 1]
            # separating axes x and y: the gaps between the polygon's box and the square
            gx = max(ix - 0.5 - maxx, minx - ix - 0.5, 0.0)
            gy = max(iy - 0.5 - maxy, miny - iy - 0.5, 0.0)
            if gx * gx + gy * gy > g2:
                continue  # the box's distance is a lower bound of the polygon's
            sep = max(gx, gy)
            for i in range(k):
                # the square's least projection on the edge normal, minus the polygon's most
                n0 = buf[i, 2]
                n1 = buf[i, 3]
                sep = max(sep, n0 * ix + n1 * iy - 0.5 * (abs(n0) + abs(n1)) - buf[i, 4])
            if sep > grow:
                continue  # a gap wider than grow along one axis
            if sep <= 0.0:
                return iy * nx + ix  # no separating axis: they meet
            # disjoint convex polygons: the distance is between a vertex of one and an edge
            # of the other
            d2 = np.inf
            for i in range(k):
                dx = max(abs(buf[i, 0] - ix) - 0.5, 0.0)
                dy = max(abs(buf[i, 1] - iy) - 0.5, 0.0)
                d2 = min(d2, dx * dx + dy * dy)
            for i in range(k):
                j = i + 1 if i + 1 < k else 0
                x0 = buf[i, 0]
                y0 = buf[i, 1]
                ex = buf[j, 0] - x0
                ey = buf[j, 1] - y0
                ee = ex * ex + ey * ey
                for qx in (ix - 0.5, ix + 0.5):
                    for qy in (iy - 0.5, iy + 0.5):
                        t = min(max(((qx - x0) * ex + (qy - y0) * ey) / ee, 0.0), 1.0)
                        ux = x0 + t * ex - qx
                        uy = y0 + t * ey - qy
                        d2 = min(d2, ux * ux + uy * uy)
            if d2 <= g2:
                return iy * nx + ix
    return -1


@njit(cache=True)
def footprint_discs_clear(fdist, discs, x, y, th, grow):  # pragma: no cover - compiled
    """Return True when the footprint's discs show it clear (a quick sufficient test).

    ``discs`` (``(n, 3)``: centre in the robot frame and radius, cells) cover the footprint
    (:func:`astar.hybrid_modes.footprint_discs`); ``fdist`` is a lower bound of the
    distance from a cell's centre to the occupied squares and the grid's outside
    (:func:`astar.hybrid_modes.clearance_bound`), so a point ``p`` of cell ``c`` keeps
    ``fdist[c] - |p - c|``. When every disc's centre, at pose ``(x, y, th)``, lies in the
    grid with that bound above its radius plus ``grow``, the grown discs, hence the grown
    footprint, keep clear: True. False means "not shown": test exactly
    (:func:`footprint_hit`). No discs: False.
    """
    n = discs.shape[0]
    if n == 0:
        return False
    ny, nx = fdist.shape
    c = math.cos(th)
    s = math.sin(th)
    for i in range(n):
        px = x + c * discs[i, 0] - s * discs[i, 1]
        py = y + s * discs[i, 0] + c * discs[i, 1]
        ix = int(math.floor(px + 0.5))
        iy = int(math.floor(py + 0.5))
        if ix < 0 or iy < 0 or ix >= nx or iy >= ny:
            return False
        d = fdist[iy, ix] - discs[i, 2] - grow
        # |p - c| <= sqrt(1/2): measured only where it decides
        if d <= 0.7072 and d <= math.hypot(px - ix, py - iy):
            return False
    return True


@njit(cache=True)
def _fp_clear(occ, onext, fsafe, fp, fdist, discs, poly, x, y, th, grow, buf):  # pragma: no cover
    """Return whether the footprint grown by ``grow`` is clear: quick test, else exact.

    ``poly``: the map's polygons in cells (:func:`astar.body_polygons.pack_polygons`; none:
    no edges). Where the cells (a conservative cover of the polygons) do not clear the body
    inside the grid, its distance to the polygons decides (:func:`body_distance`).
    """
    if footprint_discs_clear(fdist, discs, x, y, th, grow):
        return True
    hit = footprint_hit(occ, onext, fsafe, fp, x, y, th, grow, buf)
    if hit == -1:
        return True
    if hit == -2 or poly[0].shape[0] == 0:
        return False
    # footprint_hit left the body's vertices at this pose in buf[:, :2]; only whether the
    # distance exceeds grow matters, so polygons farther than a hair above it are skipped
    cap = grow + 1e-9 * (1.0 + grow)
    return body_distance(poly[0], poly[1], poly[2], buf[:, :2], cap) > grow


@njit(cache=True)
def footprint_arc_clear(
    occ,
    onext,
    fsafe,
    fp,
    fdist,
    discs,
    poly,
    rho,
    x,
    y,
    th,
    kappa,
    s,
    margin,
    slack,
    min_slack,
    buf,
):  # pragma: no cover - compiled
    """Whether every pose of an arc keeps the footprint ``margin`` from the raw map.

    The arc from pose ``(x, y, th)`` (cells, radians) with curvature ``kappa`` (1/cells) and
    signed length ``s`` (cells; negative backwards: the body still faces ``th``) is cut into
    ``m = ceil(|s| / ds_max)`` equal steps, ``ds_max = 2 slack / (1 + rho |kappa|)``, and the
    footprint grown by ``margin + slack`` is tested (:func:`footprint_hit`) at the middle of
    each: every pose of a step lies within ``slack`` of its middle pose's body, so the whole
    arc, its ends included, keeps ``margin``. ``rho``: the footprint's circumscribed radius.
    A step whose test fails, while the footprint grown by ``margin`` alone at its middle is
    clear, is halved and each half tested with half the slack (every pose of a half lies
    within half the slack of its middle), recursively while the slack stays at least
    ``min_slack`` (``min_slack >= slack``: no halving); the arc is refused when a test fails
    at the least slack. With ``m > 1`` the footprint grown by ``margin + |s| (1 + rho
    |kappa|) / 2`` is tested at the arc's middle first (one step covering the whole arc;
    only where ``fsafe``, made for a smaller growth, does not answer for the middle's cell);
    when it is clear, so is the arc. Each test tries :func:`footprint_discs_clear` (``fdist``,
    ``discs``) first, :func:`footprint_hit` when it does not answer, and the body's distance to
    the map's polygons ``poly`` when the cells do not clear it (:func:`_fp_clear`).
    """
    ds_max = 2.0 * slack / (1.0 + rho * abs(kappa))
    m = max(1, int(math.ceil(abs(s) / ds_max)))
    if m > 1:
        # one test of the whole arc first: every pose lies within |s| / 2 of its middle, so
        # within |s| (1 + rho |kappa|) / 2 of the middle pose's body (clear in open space);
        # not where fsafe (made for the smaller grow margin + slack) would answer for it
        qx, qy, qth = advance(x, y, th, kappa, 0.5 * s)
        cx = int(math.floor(qx + 0.5))
        cy = int(math.floor(qy + 0.5))
        ny, nx = occ.shape
        if 0 <= cx < nx and 0 <= cy < ny and fsafe[cy, cx] == 0:
            sweep = 0.5 * abs(s) * (1.0 + rho * abs(kappa))
            if _fp_clear(
                occ, onext, fsafe, fp, fdist, discs, poly, qx, qy, qth, margin + sweep, buf
            ):
                return True
    grow = margin + slack
    half = 0.5 * s / m
    for j in range(m):
        mid = s * (j + 0.5) / m
        qx, qy, qth = advance(x, y, th, kappa, mid)
        if _fp_clear(occ, onext, fsafe, fp, fdist, discs, poly, qx, qy, qth, grow, buf):
            continue
        if 0.5 * slack < min_slack or not _fp_clear(
            occ, onext, fsafe, fp, fdist, discs, poly, qx, qy, qth, margin, buf
        ):
            return False
        # halve the step (a stack of (middle, half length, slack)), down to min_slack
        stack = np.empty((64, 3))
        stack[0, 0] = mid - 0.5 * half
        stack[1, 0] = mid + 0.5 * half
        stack[0, 1] = stack[1, 1] = 0.5 * half
        stack[0, 2] = stack[1, 2] = 0.5 * slack
        top = 2
        while top > 0:
            top -= 1
            c, h, sl = stack[top, 0], stack[top, 1], stack[top, 2]
            qx, qy, qth = advance(x, y, th, kappa, c)
            if _fp_clear(occ, onext, fsafe, fp, fdist, discs, poly, qx, qy, qth, margin + sl, buf):
                continue
            if 0.5 * sl < min_slack or top + 2 > 64:
                return False
            if not _fp_clear(occ, onext, fsafe, fp, fdist, discs, poly, qx, qy, qth, margin, buf):
                return False
            stack[top, 0] = c - 0.5 * h
            stack[top + 1, 0] = c + 0.5 * h
            stack[top, 1] = stack[top + 1, 1] = 0.5 * h
            stack[top, 2] = stack[top + 1, 2] = 0.5 * sl
            top += 2
    return True


@njit(cache=True)
def footprint_word_clear(
    occ,
    onext,
    fsafe,
    fp,
    fdist,
    discs,
    poly,
    rho,
    x,
    y,
    th,
    radius,
    kinds,
    lens,
    n,
    margin,
    slack,
    min_slack,
    buf,
):  # pragma: no cover - compiled
    """Whether every pose of a Reeds-Shepp/Dubins word keeps the footprint ``margin`` clear.

    The word (``n`` segments: curvature ``kinds[i] / radius``, signed length ``lens[i]``)
    from pose ``(x, y, th)``, each segment by :func:`footprint_arc_clear`.
    """
    for i in range(n):
        if lens[i] == 0.0:
            continue
        kappa = kinds[i] / radius
        if not footprint_arc_clear(
            occ,
            onext,
            fsafe,
            fp,
            fdist,
            discs,
            poly,
            rho,
            x,
            y,
            th,
            kappa,
            lens[i],
            margin,
            slack,
            min_slack,
            buf,
        ):
            return False
        x, y, th = advance(x, y, th, kappa, lens[i])
    return True


@njit(cache=True, inline="always")
def _hash(key, mask):  # pragma: no cover - compiled
    h = (key * 0x9E3779B97F4A7C15) & 0x7FFFFFFFFFFFFFFF
    return (h >> 17) & mask


@njit(cache=True)
def _slot(keys, key):  # pragma: no cover - compiled
    """Slot of ``key`` in the open-addressing table ``keys`` (or the empty slot it would take)."""
    mask = keys.shape[0] - 1
    i = _hash(key, mask)
    while keys[i] != key and keys[i] != -1:
        i = (i + 1) & mask
    return i


@njit(cache=True)
def _rehash(keys, vals):  # pragma: no cover - compiled
    nk = np.full(2 * keys.shape[0], -1, dtype=np.int64)
    nv = np.empty(2 * keys.shape[0], dtype=np.int32)
    for i in range(keys.shape[0]):
        if keys[i] != -1:
            j = _slot(nk, keys[i])
            nk[j] = keys[i]
            nv[j] = vals[i]
    return nk, nv


@njit(cache=True)
def _grow_f(a):  # pragma: no cover - compiled
    b = np.empty(2 * a.shape[0], dtype=a.dtype)
    for i in range(a.shape[0]):
        b[i] = a[i]
    return b


@njit(cache=True)
def _grow_i(a):  # pragma: no cover - compiled
    b = np.empty(2 * a.shape[0], dtype=a.dtype)
    for i in range(a.shape[0]):
        b[i] = a[i]
    return b


@njit(cache=True)
def _grow_b(a):  # pragma: no cover - compiled
    b = np.zeros(2 * a.shape[0], dtype=a.dtype)
    for i in range(a.shape[0]):
        b[i] = a[i]
    return b


@njit(cache=True)
def _now():  # pragma: no cover - compiled
    with numba.objmode(t="float64"):
        t = time.perf_counter()
    return t


@njit(cache=True, inline="always")
def state_key(x, y, th, nx, nbins, fine, f):  # pragma: no cover - compiled
    """Return the discrete state of a pose: its cell and heading bin, or a finer one.

    Coarse (``fine`` False): ``(cell, bin)`` with ``nbins`` bins, the key even. Fine: the
    ``f`` x ``f`` sub-cell of the pose and one of ``f nbins`` bins, the key odd (the two
    kinds never share a key).
    """
    if not fine:
        b = int(math.floor(th / (2.0 * math.pi / nbins) + 0.5)) % nbins
        return ((int(math.floor(y + 0.5)) * nx + int(math.floor(x + 0.5))) * nbins + b) * 2
    fb = f * nbins
    b = int(math.floor(th / (2.0 * math.pi / fb) + 0.5)) % fb
    ix = int(math.floor((x + 0.5) * f))
    iy = int(math.floor((y + 0.5) * f))
    return ((iy * nx * f + ix) * fb + b) * 2 + 1


@njit(cache=True, inline="always")
def _near_ends(x, y, sx, sy, gx, gy, r):  # pragma: no cover - compiled
    """Whether ``(x, y)`` lies within ``r`` cells of ``(sx, sy)`` or ``(gx, gy)``."""
    return r > 0.0 and (math.hypot(x - sx, y - sy) < r or math.hypot(x - gx, y - gy) < r)


@njit(cache=True, inline="always")
def _cheap_h(x, y, gx, gy, h2d):  # pragma: no cover - compiled
    """Return ``max(h2d of the pose's cell, Euclidean distance to the goal)`` (cells)."""
    ny, nx = h2d.shape
    ix = min(max(int(math.floor(x + 0.5)), 0), nx - 1)
    iy = min(max(int(math.floor(y + 0.5)), 0), ny - 1)
    return max(h2d[iy, ix], math.hypot(gx - x, gy - y))


@njit(cache=True)
def _heuristic(
    x, y, th, gx, gy, gth, h2d, radius, reverse, backward, window, kinds, lens, buf
):  # pragma: no cover
    """Return the full heuristic: :func:`_cheap_h` and, near the goal, the car length.

    ``backward``: the car length from ``(gx, gy, gth)`` to the pose (the path drives it that
    way; a Dubins length is not symmetric).
    """
    h = _cheap_h(x, y, gx, gy, h2d)
    if math.hypot(gx - x, gy - y) < window:
        if backward:
            c, _ = car_word(gx, gy, gth, x, y, th, radius, reverse, kinds, lens, buf, 1.0, 0.0, 1.0)
        else:
            c, _ = car_word(x, y, th, gx, gy, gth, radius, reverse, kinds, lens, buf, 1.0, 0.0, 1.0)
        h = max(h, c)
    return h


@njit(cache=True)
def hybrid_kernel(query, motion, costs, limits, collision):  # pragma: no cover - numba
    """Run Hybrid-A* from the start pose to the goal pose.

    Parameters
    ----------
    query : KernelQuery
        The free cells, the heuristic field, the start and goal poses.
    motion : KernelMotion
        Turning radius, primitive curvatures and length, heading bins, reversing.
    costs : KernelCosts
        Penalties, heuristic weight, analytic ratio, car-heuristic window.
    limits : KernelLimits
        Expansions, deadline, polish.
    collision : KernelCollision
        Sampling step and the inputs of the exact and footprint modes.

    Returns
    -------
    status : int
        ``FOUND`` (1), ``EXHAUSTED`` (0), ``MAX_EXPANSIONS`` (2) or ``TIME_BUDGET`` (3).
    chain : ndarray of int32, shape (k,)
        Node indices from the start node (0) to the node the shot leaves from (found only).
    nodes : ndarray of float64, shape (n, 3)
        Poses of the nodes created (x, y, heading unwrapped).
    prims : ndarray of int32, shape (n,)
        Primitive reaching each node: ``2 nc li + 2 * curvature index + (1 if the path
        drives it backwards)``, ``li`` 1 for a fine primitive (``prim_len / fine_f`` long),
        else 0, ``nc`` the number of curvatures; -1 at start.
    shot_kinds, shot_lens : ndarray, shape (5,)
        The analytic shot's word (from the last node of ``chain`` to the goal pose; with
        ``motion.backward`` from the query's ``gx, gy, gth`` to that node); ``shot_n``
        segments of it.
    shot_n, expansions, shots : int
        Segments of the shot, nodes expanded, analytic shots tried.
    """
    free, h2d, sx, sy, sth, gx, gy, gth = query
    radius, curvatures, prim_len, nbins, reverse, backward, fine_r, fine_f = motion
    (
        reverse_penalty,
        cusp_penalty,
        turn_penalty,
        steer_penalty,
        analytic_ratio,
        hweight,
        car_window,
    ) = costs
    max_expansions, deadline, polish = limits
    (
        step,
        safe,
        occ,
        exact_r,
        fp,
        fsafe,
        frho,
        fmargin,
        fslack,
        fmin_slack,
        onext,
        fdist,
        discs,
        pedges,
        pstarts,
        pboxes,
    ) = collision
    poly = (pedges, pstarts, pboxes)
    ny, nx = free.shape
    nc = curvatures.shape[0]
    ndirs = 2 if reverse else 1
    kinds = np.zeros(5, dtype=np.int8)
    lens = np.zeros(5)
    buf = np.zeros(5)
    shot_kinds = np.zeros(5, dtype=np.int8)
    shot_lens = np.zeros(5)
    footprint = fp.shape[0] > 0
    fbuf = np.empty((max(fp.shape[0], 1), 5))
    # the quick test of the primitives on the free cells (arc_in_box): boxes of free
    # cells round each cell, measured once, wide enough for a primitive
    ring = np.zeros((ny, nx), dtype=np.uint8)
    exact = exact_r > 0.0
    k_box = min(250, int(math.ceil(prim_len + 1.01)))

    ncap = 4096
    px = np.empty(ncap)
    py = np.empty(ncap)
    pth = np.empty(ncap)
    pg = np.empty(ncap)
    par = np.empty(ncap, dtype=np.int32)
    prim = np.empty(ncap, dtype=np.int32)
    closed = np.zeros(ncap, dtype=np.uint8)
    lazy = np.zeros(ncap, dtype=np.uint8)  # 1: the car-length heuristic is still to add
    keyof = np.empty(ncap, dtype=np.int64)
    keys = np.full(1 << 14, -1, dtype=np.int64)
    vals = np.empty(1 << 14, dtype=np.int32)
    used = 0

    hcap = 4096
    hf = np.empty(hcap)
    hg = np.empty(hcap)
    hn = np.empty(hcap, dtype=np.int32)
    size = 0

    # start node
    k0 = state_key(sx, sy, sth, nx, nbins, _near_ends(sx, sy, sx, sy, gx, gy, fine_r), fine_f)
    fine_len = prim_len / fine_f
    px[0] = sx
    py[0] = sy
    pth[0] = sth
    pg[0] = 0.0
    par[0] = -1
    prim[0] = -1
    keyof[0] = k0
    nn = 1
    s0 = _slot(keys, k0)
    keys[s0] = k0
    vals[s0] = 0
    used = 1
    h0 = _heuristic(
        sx, sy, sth, gx, gy, gth, h2d, radius, reverse, backward, car_window, kinds, lens, buf
    )
    hf, hg, hn, size, hcap = heap_push(hf, hg, hn, size, hcap, hweight * h0, 0.0, 0)

    expansions = 0
    shots = 0
    countdown = 0
    status = EXHAUSTED
    last = -1
    shot_n = 0
    best = np.inf  # cost of the best path found so far (search path + shot)
    stop_at = max_expansions
    while size > 0:
        u, fu, size = heap_pop(hf, hg, hn, size)
        if closed[u] != 0:
            continue
        su = _slot(keys, keyof[u])
        if vals[su] != u:
            continue  # superseded by a cheaper pose in the same state
        if fu >= best:
            break  # no open node can lead to a cheaper path (f is a lower bound of the cost)
        if lazy[u] != 0:
            # the car-length part of the heuristic, evaluated when popped (lazy A*)
            lazy[u] = 0
            fl = pg[u] + hweight * _heuristic(
                px[u],
                py[u],
                pth[u],
                gx,
                gy,
                gth,
                h2d,
                radius,
                reverse,
                backward,
                car_window,
                kinds,
                lens,
                buf,
            )
            if fl > fu:
                hf, hg, hn, size, hcap = heap_push(hf, hg, hn, size, hcap, fl, pg[u], u)
                continue
        closed[u] = 1
        expansions += 1
        if expansions > stop_at:
            if status != FOUND:
                status = MAX_EXPANSIONS
            break
        if (expansions & 127) == 0 and _now() > deadline:
            if status != FOUND:
                status = TIME_BUDGET
            break
        ux = px[u]
        uy = py[u]
        uth = pth[u]
        ug = pg[u]
        pu = prim[u]
        # analytic expansion to the goal pose: the cheapest word under the search's costs
        countdown -= 1
        if countdown <= 0:
            shots += 1
            # the word as the path drives it: to the goal, or (backward) from the path's start
            if backward:
                ax, ay, ath, bx, by, bth = gx, gy, gth, ux, uy, uth
            else:
                ax, ay, ath, bx, by, bth = ux, uy, uth, gx, gy, gth
            c, n = car_word(
                ax,
                ay,
                ath,
                bx,
                by,
                bth,
                radius,
                reverse,
                kinds,
                lens,
                buf,
                reverse_penalty,
                cusp_penalty,
                1.0 + turn_penalty,
            )
            if pu >= 0:
                # a cusp where the word meets the node's primitive (its first segment after
                # the primitive forwards, its last before the primitive driven back)
                for j in range(n):
                    i = n - 1 - j if backward else j
                    if lens[i] != 0.0:
                        if (lens[i] < 0.0) != ((pu & 1) == 1):
                            c += cusp_penalty
                        break
            # the footprint first: on the parking suite it refused most shots in about half
            # the time the free cells' traversal took (both must pass)
            if (
                ug + c < best
                and (
                    not footprint
                    or footprint_word_clear(
                        occ,
                        onext,
                        fsafe,
                        fp,
                        fdist,
                        discs,
                        poly,
                        frho,
                        ax,
                        ay,
                        ath,
                        radius,
                        kinds,
                        lens,
                        n,
                        fmargin,
                        fslack,
                        fmin_slack,
                        fbuf,
                    )
                )
                and word_clear(free, ax, ay, ath, radius, kinds, lens, n, step, safe, occ, exact_r)
            ):
                if status != FOUND:
                    # keep searching for a cheaper path, at most as long again
                    stop_at = min(max_expansions, 2 * expansions + polish)
                status = FOUND
                best = ug + c
                last = u
                shot_n = n
                for i in range(n):
                    shot_kinds[i] = kinds[i]
                    shot_lens[i] = lens[i]
            countdown = max(1, int((fu - ug) / hweight / analytic_ratio))
        nlen = 2 if fine_f > 1 and _near_ends(ux, uy, sx, sy, gx, gy, fine_r) else 1
        for pi in range(nc * ndirs * nlen):
            li = pi // (nc * ndirs)  # 0: prim_len, 1: the fine primitives' length
            ci = (pi // ndirs) % nc
            di = pi % ndirs
            kappa = curvatures[ci]
            plen = prim_len if li == 0 else fine_len
            # di: the direction the path drives the primitive (0 forwards); the search
            # drives it the other way when it runs back from the goal
            d = 1.0 if di == 0 else -1.0
            s = -d * plen if backward else d * plen
            cx, cy, cth = advance(ux, uy, uth, kappa, s)
            if not (-0.5 <= cx < nx - 0.5 and -0.5 <= cy < ny - 0.5):
                continue  # off the grid (arc_clear would refuse it)
            cost = plen
            if di == 1:
                cost *= reverse_penalty
            if kappa != 0.0:
                cost *= 1.0 + turn_penalty
            if pu >= 0:
                if curvatures[(pu % (2 * nc)) >> 1] != kappa:
                    cost *= 1.0 + steer_penalty
                if (pu & 1) != di:
                    cost += cusp_penalty
            cg = ug + cost
            ck = state_key(
                cx, cy, cth, nx, nbins, _near_ends(cx, cy, sx, sy, gx, gy, fine_r), fine_f
            )
            sl = _slot(keys, ck)
            if keys[sl] == ck:
                v = vals[sl]
                if closed[v] != 0 or cg >= pg[v]:
                    continue  # before the collision tests: they cost the most
            if not arc_in_box(free, safe, exact, ring, ux, uy, s, k_box) and not arc_clear(
                free, ux, uy, uth, kappa, s, step, safe, occ, exact_r
            ):
                continue
            if footprint and not footprint_arc_clear(
                occ,
                onext,
                fsafe,
                fp,
                fdist,
                discs,
                poly,
                frho,
                ux,
                uy,
                uth,
                kappa,
                s,
                fmargin,
                fslack,
                fmin_slack,
                fbuf,
            ):
                continue
            if nn == px.shape[0]:
                px = _grow_f(px)
                py = _grow_f(py)
                pth = _grow_f(pth)
                pg = _grow_f(pg)
                par = _grow_i(par)
                prim = _grow_i(prim)
                keyof = _grow_i(keyof)
                closed = _grow_b(closed)
                lazy = _grow_b(lazy)
            w = nn
            nn += 1
            px[w] = cx
            py[w] = cy
            pth[w] = cth
            pg[w] = cg
            par[w] = u
            prim[w] = 2 * nc * li + 2 * ci + di
            keyof[w] = ck
            if keys[sl] != ck:
                keys[sl] = ck
                used += 1
            vals[sl] = w
            if 2 * used > keys.shape[0]:
                keys, vals = _rehash(keys, vals)
            lazy[w] = 1
            hf, hg, hn, size, hcap = heap_push(
                hf, hg, hn, size, hcap, cg + hweight * _cheap_h(cx, cy, gx, gy, h2d), cg, w
            )

    nodes = np.empty((nn, 3))
    for i in range(nn):
        nodes[i, 0] = px[i]
        nodes[i, 1] = py[i]
        nodes[i, 2] = pth[i]
    if status == FOUND:
        k = 0
        v = last
        while v >= 0:
            k += 1
            v = par[v]
        chain = np.empty(k, dtype=np.int32)
        v = last
        for i in range(k - 1, -1, -1):
            chain[i] = v
            v = par[v]
    else:
        chain = np.empty(0, dtype=np.int32)
    return (
        status,
        chain,
        nodes,
        prim[:nn].copy(),
        shot_kinds,
        shot_lens,
        shot_n,
        expansions,
        shots,
    )
