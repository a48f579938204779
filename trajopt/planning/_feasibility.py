"""Is a curvature-bounded path possible at all? A constructive witness search.

:func:`curvature_witness` looks for a path from ``start`` to ``goal`` whose curvature never
exceeds ``kappa_max`` and whose every point keeps ``radius`` from the occupied squares of the
raw map (cells outside the map count as occupied). It is a hybrid A* (Dolgov et al., 2008
style): states are continuous poses ``(x, y, theta)`` on a lattice of ``n_headings`` headings;
each expansion appends a left arc, a straight segment or a right arc of one lattice step
(arc radius ``1 / kappa_max``, turning exactly one heading bin), and every expanded pose
tries an analytic finish to the exact goal point: an arc of that radius followed by a
straight segment (the goal heading is free, as is the start heading). Poses are merged per
heading bin and square of ``min(0.5, 0.7 * step)`` cells.

A returned witness is a proof (up to its sampling) that the query is feasible for the
curvature bound: its samples, at most ``resolution / 8`` apart, were all checked against
the raw map with the exact point-to-square distance. ``None`` means that the search did not
find one within its budget: the query is *probably* infeasible, not proven so. The
benchmark of the curvature-bounded smoother (``benchmarks/bench_curvature.py``) uses it to
tell the smoother's failures on feasible queries from queries no curve can serve.

:func:`witness_grid_path` turns a witness into a grid path of the inflated grid, so that the
corridor and the smoother can be run again along it (the planner's *witness rescue*, used
when the curvature-bounded smoother fails along the A* path).
"""

from __future__ import annotations

import heapq
import math
import time

import numpy as np
from numba import njit

import astar
from trajopt.errors import InvalidInputError
from trajopt.geometry import point_square_dist2
from trajopt.kernel_cache import watch_compiles

_SAMPLE = 0.125  # cells between clearance samples


def curvature_witness(
    raw_grid: astar.OccupancyGrid,
    radius: float,
    start: np.ndarray,
    goal: np.ndarray,
    kappa_max: float,
    *,
    n_headings: int = 32,
    max_expansions: int = 200_000,
    time_limit_s: float = 30.0,
) -> np.ndarray | None:
    """Return a curvature-bounded, collision-free path from ``start`` to ``goal``, or ``None``.

    Parameters
    ----------
    raw_grid : astar.OccupancyGrid
        The map as given (not inflated).
    radius : float
        Robot radius (m): every point of the path keeps at least this distance from an
        occupied square.
    start, goal : array_like, shape (2,)
        End points (m); both headings are free.
    kappa_max : float
        Curvature bound (1/m), > 0: the arcs have radius ``1 / kappa_max``.
    n_headings : int
        Heading bins of the lattice (>= 8).
    max_expansions : int
        Search budget (expanded poses).
    time_limit_s : float
        Wall-clock budget (s).

    Returns
    -------
    ndarray, shape (m, 2), or None
        Points of the witness (m), at most ``resolution / 8`` apart, from ``start`` exactly
        to ``goal`` exactly; ``None`` when none was found within the budget.
    """
    occ = np.ascontiguousarray(getattr(raw_grid, "occupied", None), dtype=np.bool_)
    res = float(raw_grid.resolution)
    origin = np.asarray(raw_grid.origin, dtype=float)
    for name, value in (("radius", radius), ("kappa_max", kappa_max)):
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise InvalidInputError(f"{name} must be a finite number > 0, got {value!r}")
    if not (isinstance(n_headings, int) and n_headings >= 8):
        raise InvalidInputError(f"n_headings must be an integer >= 8, got {n_headings!r}")
    p0 = (np.asarray(start, dtype=float).reshape(2) - origin) / res
    p1 = (np.asarray(goal, dtype=float).reshape(2) - origin) / res
    r = radius / res
    turn_r = 1.0 / (kappa_max * res)
    w = int(math.ceil(r)) + 2
    if not (_clear(p0[0], p0[1], occ, w, r) and _clear(p1[0], p1[1], occ, w, r)):
        return None
    h_field = _distance_field(occ, w, r, int(p1[0]), int(p1[1]))
    dth = 2.0 * math.pi / n_headings
    step = turn_r * dth  # arc length of one primitive: turns exactly one heading bin
    cell = min(0.5, 0.7 * step)  # merge size (cells): smaller than a step, so moves leave it
    t_end = time.perf_counter() + float(time_limit_s)

    def heuristic(x: float, y: float) -> float:
        ix, iy = int(x), int(y)
        if 0 <= iy < h_field.shape[0] and 0 <= ix < h_field.shape[1]:
            return float(h_field[iy, ix])
        return math.inf

    parents: dict[int, tuple[int, float, float, int, int]] = {}
    best_g: dict[tuple[int, int, int], float] = {}
    heap: list[tuple[float, float, int]] = []
    nodes: list[tuple[float, float, int]] = []
    for k in range(n_headings):
        nodes.append((p0[0], p0[1], k))
        parents[len(nodes) - 1] = (-1, 0.0, 0.0, 0, 0)
        heapq.heappush(heap, (1.5 * heuristic(p0[0], p0[1]), 0.0, len(nodes) - 1))
    expansions = 0
    while heap and expansions < max_expansions:
        if (expansions & 255) == 0 and time.perf_counter() > t_end:
            break
        _, g, i = heapq.heappop(heap)
        x, y, k = nodes[i]
        key = (int(x / cell), int(y / cell), k)
        if best_g.get(key, math.inf) < g - 1e-12:
            continue
        expansions += 1
        th = k * dth
        psi, side = _finish(x, y, th, p1[0], p1[1], turn_r, occ, w, r)
        if side != 0:
            pts = [_sample_finish(x, y, th, p1, turn_r, psi, side)]
            j = i
            while parents[j][0] >= 0:
                pj, _, _, kind, _ = parents[j]
                xs, ys, ks = nodes[pj]
                pts.append(_sample_primitive(xs, ys, ks * dth, kind, step, turn_r))
                j = pj
            out = np.vstack(pts[::-1])
            out[0] = p0
            out[-1] = p1
            return origin + res * out
        for kind in (-1, 0, 1):
            ok, xe, ye = _primitive(x, y, th, kind, step, turn_r, occ, w, r)
            if not ok:
                continue
            ke = (k + kind) % n_headings
            ge = g + step
            key = (int(xe / cell), int(ye / cell), ke)
            if ge >= best_g.get(key, math.inf) - 1e-12:
                continue
            hv = heuristic(xe, ye)
            if not math.isfinite(hv):
                continue
            best_g[key] = ge
            nodes.append((xe, ye, ke))
            parents[len(nodes) - 1] = (i, xe, ye, kind, ke)
            heapq.heappush(heap, (ge + 1.5 * hv, ge, len(nodes) - 1))
    return None


# ------------------------------------------------------------------ geometry
def _sample_primitive(x, y, th, kind, step, turn_r) -> np.ndarray:
    n = max(2, int(math.ceil(step / _SAMPLE)) + 1)
    s = np.linspace(0.0, step, n)
    if kind == 0:
        return np.column_stack([x + s * math.cos(th), y + s * math.sin(th)])
    cx = x - kind * turn_r * math.sin(th)
    cy = y + kind * turn_r * math.cos(th)
    ang = th - kind * math.pi / 2 + kind * s / turn_r
    return np.column_stack([cx + turn_r * np.cos(ang), cy + turn_r * np.sin(ang)])


def _sample_finish(x, y, th, goal, turn_r, psi, side) -> np.ndarray:
    arc = _sample_primitive(x, y, th, side, psi * turn_r, turn_r)
    tx, ty = arc[-1]
    d = math.hypot(goal[0] - tx, goal[1] - ty)
    n = max(2, int(math.ceil(d / _SAMPLE)) + 1)
    f = np.linspace(0.0, 1.0, n)[1:, None]
    line = arc[-1] + f * (np.asarray(goal) - arc[-1])
    return np.vstack([arc, line])


watch_compiles()  # a first compilation logs one notice (trajopt.kernel_cache)


@njit(cache=True)
def _clear(px, py, occ, w, r):
    """Distance from ``(px, py)`` (cells) to the nearest occupied square is >= ``r``."""
    r2 = r * r - 1e-9
    return point_square_dist2(px, py, occ, w, r2) >= r2


@njit(cache=True)
def _primitive(x, y, th, kind, step, turn_r, occ, w, r):
    """Check one lattice primitive (left arc -1/+1 sides, straight 0); its end point."""
    n = max(2, int(math.ceil(step / _SAMPLE)) + 1)
    cx = x - kind * turn_r * math.sin(th)
    cy = y + kind * turn_r * math.cos(th)
    xe, ye = x, y
    for i in range(1, n):
        s = step * i / (n - 1)
        if kind == 0:
            xe = x + s * math.cos(th)
            ye = y + s * math.sin(th)
        else:
            ang = th - kind * math.pi / 2 + kind * s / turn_r
            xe = cx + turn_r * math.cos(ang)
            ye = cy + turn_r * math.sin(ang)
        if not _clear(xe, ye, occ, w, r):
            return False, xe, ye
    return True, xe, ye


@njit(cache=True)
def _finish(x, y, th, gx, gy, turn_r, occ, w, r):
    """Return an arc (radius ``turn_r``, either side) then a straight line to ``(gx, gy)``, checked.

    Returns ``(psi, side)``: the arc's turning angle and side (+1 left, -1 right), or side 0
    when neither is free.
    """
    for side in (1, -1):
        cx = x - side * turn_r * math.sin(th)
        cy = y + side * turn_r * math.cos(th)
        d = math.hypot(gx - cx, gy - cy)
        if d < turn_r * (1.0 + 1e-9):
            continue
        phi = math.atan2(gy - cy, gx - cx)
        alpha = math.acos(turn_r / d)
        beta0 = math.atan2(y - cy, x - cx)
        if side == 1:
            psi = (phi - alpha - beta0) % (2.0 * math.pi)
        else:
            psi = (beta0 - phi - alpha) % (2.0 * math.pi)
        if psi > 2.0 * math.pi - 1e-9:
            psi = 0.0
        if psi > math.pi:  # a loop: never the better way in a cluttered map
            continue
        ok = True
        arc_len = psi * turn_r
        n = max(2, int(math.ceil(arc_len / _SAMPLE)) + 1)
        tx, ty = x, y
        for i in range(1, n):
            s = arc_len * i / (n - 1)
            ang = th - side * math.pi / 2 + side * s / turn_r
            tx = cx + turn_r * math.cos(ang)
            ty = cy + turn_r * math.sin(ang)
            if not _clear(tx, ty, occ, w, r):
                ok = False
                break
        if not ok:
            continue
        seg = math.hypot(gx - tx, gy - ty)
        m = max(2, int(math.ceil(seg / _SAMPLE)) + 1)
        for i in range(1, m):
            f = i / (m - 1)
            if not _clear(tx + f * (gx - tx), ty + f * (gy - ty), occ, w, r):
                ok = False
                break
        if ok:
            return psi, side
    return 0.0, 0


@njit(cache=True)
def _distance_field(occ, w, r, gx, gy):
    """8-connected step counts from the goal cell over cells that may hold a free point.

    Such a cell's centre keeps at least ``r - sqrt(2)/2``; the counts are a heuristic in
    cells (inf elsewhere).
    """
    ny, nx = occ.shape
    relax = max(0.0, r - 0.7072)
    free = np.zeros((ny, nx), dtype=np.bool_)
    for iy in range(ny):
        for ix in range(nx):
            free[iy, ix] = _clear(ix + 0.5, iy + 0.5, occ, w, relax)
    dist = np.full((ny, nx), np.inf)
    if not (0 <= gx < nx and 0 <= gy < ny):
        return dist
    qx = np.empty(nx * ny, dtype=np.int64)
    qy = np.empty(nx * ny, dtype=np.int64)
    head, tail = 0, 0
    dist[gy, gx] = 0.0
    free[gy, gx] = True
    qx[tail], qy[tail] = gx, gy
    tail += 1
    while head < tail:
        cx, cy = qx[head], qy[head]
        head += 1
        dn = dist[cy, cx] + 1.0
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                ex, ey = cx + dx, cy + dy
                if 0 <= ex < nx and 0 <= ey < ny and free[ey, ex] and dist[ey, ex] > dn:
                    dist[ey, ex] = dn
                    qx[tail], qy[tail] = ex, ey
                    tail += 1
    return dist


def witness_grid_path(witness: np.ndarray, inflated_grid: astar.OccupancyGrid) -> np.ndarray | None:
    """Return a grid path of ``inflated_grid`` that follows ``witness`` (for the witness rescue).

    The cells the witness passes through are taken in order; those blocked in the inflated
    grid (a witness point may keep the exact clearance where its cell centre does not) are
    skipped, and consecutive kept cells that are not 8-neighbours, or are diagonal
    neighbours across a blocked corner, are joined by a shortest A* path. Revisited cells
    (loops) are cut out.

    Parameters
    ----------
    witness : array_like, shape (m, 2)
        Points in metres, consecutive points less than a cell apart (as returned by
        :func:`curvature_witness`).
    inflated_grid : astar.OccupancyGrid
        The grid the robot centre moves in (the A* grid of the planner).

    Returns
    -------
    ndarray of int64, shape (n, 2), or None
        Cells ``(ix, iy)``, 8-connected without corner cutting, all free; its first and
        last cells hold the witness's end points. ``None`` when an end cell is blocked or
        outside the grid, or two kept cells are not connected in the inflated grid.
    """
    pts = np.asarray(witness, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 1 or not np.all(np.isfinite(pts)):
        raise InvalidInputError(
            f"witness must be a finite array of shape (m, 2) with m >= 1, got {pts.shape}"
        )
    occ = np.asarray(inflated_grid.occupied, dtype=bool)
    ny, nx = occ.shape
    cells = np.floor(
        (pts - np.asarray(inflated_grid.origin, dtype=float)) / float(inflated_grid.resolution)
    ).astype(np.int64)
    inside = (cells[:, 0] >= 0) & (cells[:, 0] < nx) & (cells[:, 1] >= 0) & (cells[:, 1] < ny)
    if not (inside[0] and inside[-1]):
        return None
    cells = cells[inside]
    free = ~occ[cells[:, 1], cells[:, 0]]
    if not (free[0] and free[-1]):
        return None
    way = cells[free]
    way = way[np.concatenate([[True], np.any(np.diff(way, axis=0) != 0, axis=1)])]
    out: list[tuple[int, int]] = [(int(way[0, 0]), int(way[0, 1]))]
    for c in way[1:]:
        a = out[-1]
        b = (int(c[0]), int(c[1]))
        dx, dy = abs(b[0] - a[0]), abs(b[1] - a[1])
        if max(dx, dy) == 1 and (min(dx, dy) == 0 or not (occ[a[1], b[0]] or occ[b[1], a[0]])):
            out.append(b)
            continue
        try:
            seg = astar.find_path(inflated_grid, a, b).cells
        except astar.NoPathError:
            return None
        out.extend((int(x), int(y)) for x, y in seg[1:])
    simple: list[tuple[int, int]] = []
    where: dict[tuple[int, int], int] = {}
    for c in out:
        k = where.get(c)
        if k is not None:  # a loop: cut back to the first visit
            for q in simple[k + 1 :]:
                del where[q]
            del simple[k + 1 :]
            continue
        where[c] = len(simple)
        simple.append(c)
    return np.array(simple, dtype=np.int64).reshape(-1, 2)
