"""Safe corridors: overlapping axis-aligned boxes of free cells grown around a grid path.

A :class:`Corridor` is the convex decomposition of free space that the smoother uses to
certify clearance: every span of the B-spline keeps its control points inside one box, so
(by the convex-hull property) the whole continuous curve lies inside the union of boxes.

Contract for certified clearance
--------------------------------
To certify a clearance ``r`` (metres) from the *raw* map, two things are needed together:

1. the grid given to :func:`build_corridor` must be
   ``astar.inflate(raw, r, metric="square", outside_occupied=True)``: a cell is blocked
   when its centre is closer than ``r`` to an occupied cell taken as a *square* (and the
   outside of the map counts as occupied);
2. every box of free cells is shrunk to the rectangle spanned by its cell *centres*
   (half a cell per side), which :func:`build_corridor` always does.

Then any point of a shrunk box is at least ``r`` from every occupied square: for an
occupied square ``Q`` outside the box, the box's cell centre nearest to ``Q`` along each
axis is no farther from ``Q`` on either axis than the point, and that centre is free, so
its distance to ``Q`` is ``>= r``. With centre-to-centre inflation, or without the
shrink, the curve can cut obstacle corners (GUIDE.md section 6).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from trajopt.clearance import polygon_rects_distance
from trajopt.errors import InvalidInputError

__all__ = ["Box", "Corridor", "build_corridor"]

logger = logging.getLogger(__name__)


def _readonly(a: np.ndarray, dtype: Any) -> np.ndarray:
    out = np.array(a, dtype=dtype, copy=True)
    out.flags.writeable = False
    return out


@dataclass(frozen=True, slots=True)
class Box:
    """A convex free region of a corridor (m).

    Usually an axis-aligned box of free cells of the inflated grid, shrunk to the rectangle
    of its cell centres. A *bridge* (``diagonal`` set) is a 45-degree rotated rectangle
    placed where the path crosses diagonally between two boxes that touch only at a point
    or along a line; it is certified by an exact polygon-to-square distance against the raw
    map instead (see :func:`build_corridor`).

    Attributes
    ----------
    xmin, xmax, ymin, ymax : float
        The shrunk box in world metres (cell centres of the outermost cells); for a bridge,
        its bounding box.
    ix0, ix1, iy0, iy1 : int
        The cell rectangle, inclusive: cells ``ix0..ix1`` by ``iy0..iy1`` (for a bridge the
        cells its bounding box touches, not all free).
    diagonal : tuple of float or None
        ``(smin, smax, dmin, dmax)``: a bridge is ``smin <= x + y <= smax`` and
        ``dmin <= x - y <= dmax`` (m) intersected with the bounding box; ``None`` for a box.
    """

    xmin: float
    xmax: float
    ymin: float
    ymax: float
    ix0: int
    ix1: int
    iy0: int
    iy1: int
    diagonal: tuple[float, float, float, float] | None = None

    @property
    def is_diagonal(self) -> bool:
        """Whether this is a 45-degree *bridge* region (``diagonal`` is set)."""
        return self.diagonal is not None

    def vertices(self) -> np.ndarray:
        """Corners of the region, counter-clockwise, shape (k, 2) (m).

        The axis-aligned rectangle, or for a bridge its (possibly clipped) rotated one.
        """
        if self.diagonal is None:
            return np.array(
                [[self.xmin, self.ymin], [self.xmax, self.ymin], [self.xmax, self.ymax],
                 [self.xmin, self.ymax]]
            )
        smin, smax, dmin, dmax = self.diagonal
        # corners of the rotated rectangle in (s, d) = (x + y, x - y)
        sd = np.array([[smin, dmax], [smin, dmin], [smax, dmin], [smax, dmax]])
        xy = np.column_stack([(sd[:, 0] + sd[:, 1]) / 2, (sd[:, 0] - sd[:, 1]) / 2])
        order = np.argsort(np.arctan2(*(xy - xy.mean(axis=0)).T[::-1]))
        return xy[order]

    @property
    def cells_x(self) -> int:
        """Width in cells."""
        return self.ix1 - self.ix0 + 1

    @property
    def cells_y(self) -> int:
        """Height in cells."""
        return self.iy1 - self.iy0 + 1

    def contains(self, points: np.ndarray, tol: float = 0.0) -> np.ndarray:
        """Whether world points (shape ``(..., 2)``, m) lie in the box (``tol`` m of slack)."""
        p = np.asarray(points, dtype=float)
        inside = (
            (p[..., 0] >= self.xmin - tol)
            & (p[..., 0] <= self.xmax + tol)
            & (p[..., 1] >= self.ymin - tol)
            & (p[..., 1] <= self.ymax + tol)
        )
        if self.diagonal is not None:
            smin, smax, dmin, dmax = self.diagonal
            s = p[..., 0] + p[..., 1]
            d = p[..., 0] - p[..., 1]
            t2 = 2 * tol
            inside &= (s >= smin - t2) & (s <= smax + t2) & (d >= dmin - t2) & (d <= dmax + t2)
        return inside

    def contains_cells(self, cells: np.ndarray) -> np.ndarray:
        """Whether cells ``(ix, iy)`` (shape ``(..., 2)``) lie in the cell rectangle."""
        c = np.asarray(cells)
        return (
            (c[..., 0] >= self.ix0)
            & (c[..., 0] <= self.ix1)
            & (c[..., 1] >= self.iy0)
            & (c[..., 1] <= self.iy1)
        )


@dataclass(frozen=True, slots=True)
class Corridor:
    """A chain of overlapping boxes covering a grid path.

    Attributes
    ----------
    boxes : tuple of Box, length m
        Consecutive boxes overlap (share at least one path cell).
    path_ranges : ndarray of int64, shape (m, 2)
        For each box the inclusive range ``[first, last]`` of path indices whose cells it
        contains (a contiguous run).
    transitions_m : ndarray of float, shape (m - 1,)
        Arc length along the path polyline (m) where box ``i`` hands over to box ``i + 1``:
        a point inside the run of path cells shared by both boxes.
    overlap_start_m, overlap_end_m : ndarray of float, shape (m - 1,)
        Arc-length interval (m) of the shared run of path cells.
    path_points : ndarray of float, shape (n, 2)
        World coordinates (m) of the path cell centres.
    path_s : ndarray of float, shape (n,)
        Arc length (m) of each path point along the polyline.
    resolution : float
        Cell side of the grid (m).
    origin : tuple of float
        Grid origin (m).
    radius : float or None
        Clearance (m) the inflated grid was built for, when given.
    """

    boxes: tuple[Box, ...]
    path_ranges: np.ndarray
    transitions_m: np.ndarray
    overlap_start_m: np.ndarray
    overlap_end_m: np.ndarray
    path_points: np.ndarray
    path_s: np.ndarray
    resolution: float
    origin: tuple[float, float]
    radius: float | None = None
    _lo: np.ndarray = field(init=False, repr=False, compare=False)
    _hi: np.ndarray = field(init=False, repr=False, compare=False)
    _dlo: np.ndarray = field(init=False, repr=False, compare=False)
    _dhi: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "boxes", tuple(self.boxes))
        object.__setattr__(self, "path_ranges", _readonly(self.path_ranges, np.int64))
        for name in ("transitions_m", "overlap_start_m", "overlap_end_m", "path_s"):
            object.__setattr__(self, name, _readonly(getattr(self, name), float))
        object.__setattr__(self, "path_points", _readonly(self.path_points, float))
        lo = np.array([[b.xmin, b.ymin] for b in self.boxes], dtype=float).reshape(-1, 2)
        hi = np.array([[b.xmax, b.ymax] for b in self.boxes], dtype=float).reshape(-1, 2)
        inf = np.inf
        dlo = np.array(
            [[-inf, -inf] if b.diagonal is None else [b.diagonal[0], b.diagonal[2]]
             for b in self.boxes], dtype=float,
        ).reshape(-1, 2)
        dhi = np.array(
            [[inf, inf] if b.diagonal is None else [b.diagonal[1], b.diagonal[3]]
             for b in self.boxes], dtype=float,
        ).reshape(-1, 2)
        for a in (lo, hi, dlo, dhi):
            a.flags.writeable = False
        object.__setattr__(self, "_lo", lo)
        object.__setattr__(self, "_hi", hi)
        object.__setattr__(self, "_dlo", dlo)
        object.__setattr__(self, "_dhi", dhi)

    def __len__(self) -> int:
        return len(self.boxes)

    @property
    def lower(self) -> np.ndarray:
        """Lower corners ``(xmin, ymin)`` of all boxes, shape (m, 2) (m)."""
        return self._lo

    @property
    def upper(self) -> np.ndarray:
        """Upper corners ``(xmax, ymax)`` of all boxes, shape (m, 2) (m)."""
        return self._hi

    @property
    def diag_lower(self) -> np.ndarray:
        """Lower bounds ``(smin, dmin)`` on ``x + y`` and ``x - y`` (m), shape (m, 2);
        ``-inf`` for axis-aligned boxes."""
        return self._dlo

    @property
    def diag_upper(self) -> np.ndarray:
        """Upper bounds ``(smax, dmax)`` on ``x + y`` and ``x - y`` (m), shape (m, 2);
        ``+inf`` for axis-aligned boxes."""
        return self._dhi

    @property
    def length_m(self) -> float:
        """Length of the path polyline (m)."""
        return float(self.path_s[-1])

    def contains(self, points: np.ndarray, tol: float = 0.0) -> np.ndarray:
        """Whether each world point (shape ``(..., 2)``, m) lies in at least one box."""
        p = np.asarray(points, dtype=float)
        flat = p.reshape(-1, 2)
        inside = np.all(
            (flat[:, None, :] >= self._lo[None] - tol) & (flat[:, None, :] <= self._hi[None] + tol),
            axis=2,
        )
        sd = np.column_stack([flat[:, 0] + flat[:, 1], flat[:, 0] - flat[:, 1]])
        inside &= np.all(
            (sd[:, None, :] >= self._dlo[None] - 2 * tol)
            & (sd[:, None, :] <= self._dhi[None] + 2 * tol),
            axis=2,
        )
        return inside.any(axis=1).reshape(p.shape[:-1])

    def box_of(self, s_m: np.ndarray | float) -> np.ndarray:
        """Index of the box whose share of the path holds arc length ``s_m`` (m)."""
        return np.searchsorted(self.transitions_m, np.asarray(s_m, dtype=float), side="right")


class _RectTester:
    """O(1) "is this cell rectangle all free" tests from a summed-area table."""

    __slots__ = ("sat", "nx", "ny", "x_off", "y_off")

    def __init__(self, occupied: np.ndarray, window: tuple[int, int, int, int]) -> None:
        # table only over ``window`` = (x0, x1, y0, y1) inclusive: rectangles outside it are
        # reported as not free (callers never need them)
        x0, x1, y0, y1 = window
        sub = occupied[y0 : y1 + 1, x0 : x1 + 1]
        ny, nx = sub.shape
        sat = np.zeros((ny + 1, nx + 1), dtype=np.int32)
        sat[1:, 1:] = np.cumsum(np.cumsum(sub, axis=0, dtype=np.int32), axis=1)
        self.sat = sat
        self.nx, self.ny = nx, ny
        self.x_off, self.y_off = x0, y0

    def free(self, x0: int, x1: int, y0: int, y1: int) -> bool:
        x0 -= self.x_off
        x1 -= self.x_off
        y0 -= self.y_off
        y1 -= self.y_off
        if x0 < 0 or y0 < 0 or x1 >= self.nx or y1 >= self.ny or x0 > x1 or y0 > y1:
            return False
        s = self.sat
        return int(s[y1 + 1, x1 + 1] - s[y0, x1 + 1] - s[y1 + 1, x0] + s[y0, x0]) == 0


def _as_cells(grid_path: Any) -> np.ndarray:
    cells = getattr(grid_path, "cells", grid_path)
    c = np.asarray(cells)
    if c.ndim != 2 or c.shape[1] != 2 or len(c) < 1:
        raise InvalidInputError(
            f"grid_path cells must have shape (n, 2) with n >= 1, got {c.shape}"
        )
    if not np.issubdtype(c.dtype, np.integer):
        if not np.all(np.isfinite(c)) or np.any(c != np.round(c)):
            raise InvalidInputError("grid_path cells must be integer (ix, iy) pairs")
        c = c.astype(np.int64)
    c = c.astype(np.int64)
    steps = np.abs(np.diff(c, axis=0))
    if len(c) > 1 and (np.any(steps.max(axis=1) != 1)):
        bad = int(np.nonzero(steps.max(axis=1) != 1)[0][0])
        raise InvalidInputError(
            f"grid_path must move to an 8-neighbour at every step; step {bad} goes from "
            f"{c[bad].tolist()} to {c[bad + 1].tolist()}"
        )
    return c


def build_corridor(
    inflated_grid: Any,
    grid_path: Any,
    *,
    max_side_cells: int = 32,
    seed_back_cells: int = 3,
    min_share_cells: float = 1.5,
    radius: float | None = None,
    raw_grid: Any = None,
) -> Corridor:
    """Grow a chain of overlapping free boxes around a grid path.

    Parameters
    ----------
    inflated_grid : astar.OccupancyGrid
        The grid the robot *centre* moves in. For certified clearance ``r`` from the raw
        map it must be ``astar.inflate(raw, r, metric="square", outside_occupied=True)``
        (module docstring).
    grid_path : astar.GridPath or array_like of int, shape (n, 2)
        Path cells ``(ix, iy)``, 8-connected, all free in ``inflated_grid``.
    max_side_cells : int, optional
        Largest box side in cells (>= 2). Default 32.
    seed_back_cells : int, optional
        How many already covered path cells each new box is seeded with (>= 1), so that
        consecutive boxes share a run of path cells. Default 3.
    min_share_cells : float, optional
        Transitions are moved inside their overlap runs so that each box's share of the
        path is at least this long (cells) where possible. Default 1.5.
    radius : float, optional
        The clearance (m) ``inflated_grid`` was built for; stored on the corridor.
    raw_grid : astar.OccupancyGrid, optional
        The raw map ``inflated_grid`` was inflated from (same shape, resolution and
        origin; requires ``radius``). When given, *bridges* are inserted where the path
        crosses diagonally between two boxes that meet only at a point or along a line
        (diagonal gaps, staircase passages): 45-degree rectangles around the path, grown
        while their exact distance to every occupied square of ``raw_grid`` (and to the
        outside of the map) stays ``>= radius``. Without bridges the smoother's control
        points are squeezed into that point and the curve stops there.

    Returns
    -------
    Corridor

    Raises
    ------
    InvalidInputError
        When a path cell is blocked or outside the grid, or an option breaks its rule.

    Notes
    -----
    Each box starts from the first path cell not yet covered, seeded with the bounding
    box of up to ``seed_back_cells`` previous path cells (shrunk until free), extends
    forward along the path while its bounding box stays free, then grows one cell at a
    time round-robin (+x, -x, +y, -y) while free and within ``max_side_cells``, using
    O(1) summed-area-table tests. A box made redundant by its successor (the successor
    overlaps the box before it) is dropped. Deterministic: no randomness, no ties broken
    by hashing.
    """
    if int(max_side_cells) != max_side_cells or max_side_cells < 2:
        raise InvalidInputError(f"max_side_cells must be an integer >= 2, got {max_side_cells!r}")
    if int(seed_back_cells) != seed_back_cells or seed_back_cells < 1:
        raise InvalidInputError(f"seed_back_cells must be an integer >= 1, got {seed_back_cells!r}")
    if not (np.isfinite(min_share_cells) and min_share_cells >= 0):
        raise InvalidInputError(f"min_share_cells must be finite and >= 0, got {min_share_cells!r}")
    if radius is not None and not (np.isfinite(radius) and radius >= 0):
        raise InvalidInputError(f"radius must be finite and >= 0 m, got {radius!r}")
    occ = np.asarray(inflated_grid.occupied, dtype=bool)
    raw_occ = None
    if raw_grid is not None:
        if radius is None:
            raise InvalidInputError("radius is required with raw_grid (bridges certify it)")
        raw_occ = np.asarray(raw_grid.occupied, dtype=bool)
        same = (
            raw_occ.shape == occ.shape
            and float(raw_grid.resolution) == float(inflated_grid.resolution)
            and tuple(map(float, raw_grid.origin)) == tuple(map(float, inflated_grid.origin))
        )
        if not same:
            raise InvalidInputError(
                "raw_grid must have the inflated grid's shape, resolution and origin; got "
                f"{raw_occ.shape} at {raw_grid.resolution} m vs {occ.shape} at "
                f"{inflated_grid.resolution} m"
            )
    ny, nx = occ.shape
    cells = _as_cells(grid_path)
    inb = (cells[:, 0] >= 0) & (cells[:, 0] < nx) & (cells[:, 1] >= 0) & (cells[:, 1] < ny)
    if not np.all(inb):
        i = int(np.nonzero(~inb)[0][0])
        raise InvalidInputError(
            f"grid_path cell {i} = {cells[i].tolist()} is outside the {nx}x{ny} grid"
        )
    blocked = occ[cells[:, 1], cells[:, 0]]
    if np.any(blocked):
        i = int(np.nonzero(blocked)[0][0])
        raise InvalidInputError(
            f"grid_path cell {i} = {cells[i].tolist()} is blocked in the inflated grid; "
            "the path must be searched on the same inflated grid"
        )
    res = float(inflated_grid.resolution)
    ox, oy = (float(v) for v in inflated_grid.origin)
    n = len(cells)
    cap = int(max_side_cells)
    window = (
        max(0, int(cells[:, 0].min()) - cap),
        min(nx - 1, int(cells[:, 0].max()) + cap),
        max(0, int(cells[:, 1].min()) - cap),
        min(ny - 1, int(cells[:, 1].max()) + cap),
    )
    tester = _RectTester(occ, window)

    rects: list[tuple[int, int, int, int]] = []
    runs: list[tuple[int, int]] = []

    def inside(r: tuple[int, int, int, int], j: int) -> bool:
        x, y = cells[j]
        return r[0] <= x <= r[1] and r[2] <= y <= r[3]

    i = 0
    while True:
        # seed: bounding box of cells [i - back, i], shrunk until free
        back = min(int(seed_back_cells), i)
        while True:
            seg = cells[i - back : i + 1]
            r = (
                int(seg[:, 0].min()),
                int(seg[:, 0].max()),
                int(seg[:, 1].min()),
                int(seg[:, 1].max()),
            )
            if (r[1] - r[0] < cap and r[3] - r[2] < cap and tester.free(*r)) or back == 0:
                break
            back -= 1
        # extend forward along the path
        j = i + 1
        while j < n:
            x, y = cells[j]
            cand = (min(r[0], int(x)), max(r[1], int(x)), min(r[2], int(y)), max(r[3], int(y)))
            if cand[1] - cand[0] >= cap or cand[3] - cand[2] >= cap or not tester.free(*cand):
                break
            r = cand
            j += 1
        # round-robin growth
        grew = True
        while grew:
            grew = False
            for side in range(4):
                x0, x1, y0, y1 = r
                if side == 0:
                    cand = (x0, x1 + 1, y0, y1)
                elif side == 1:
                    cand = (x0 - 1, x1, y0, y1)
                elif side == 2:
                    cand = (x0, x1, y0, y1 + 1)
                else:
                    cand = (x0, x1, y0 - 1, y1)
                if cand[1] - cand[0] < cap and cand[3] - cand[2] < cap and tester.free(*cand):
                    r = cand
                    grew = True
        # contiguous run of path cells containing i
        a = i
        while a > 0 and inside(r, a - 1):
            a -= 1
        b = i
        while b + 1 < n and inside(r, b + 1):
            b += 1
        # drop predecessors made redundant (this box overlaps the one before them)
        while len(rects) >= 2 and a <= runs[-2][1]:
            rects.pop()
            runs.pop()
        rects.append(r)
        runs.append((a, b))
        if b >= n - 1:
            break
        i = b + 1

    diags: list[tuple[float, float, float, float] | None] = [None] * len(rects)
    if raw_occ is not None:
        rects, runs, diags = _insert_bridges(rects, runs, cells, raw_occ, float(radius) / res)

    pts = np.column_stack([ox + (cells[:, 0] + 0.5) * res, oy + (cells[:, 1] + 0.5) * res])
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(pts, axis=0).T))])
    m = len(rects)
    ov_lo = np.empty(m - 1)
    ov_hi = np.empty(m - 1)
    for k in range(m - 1):
        lo_i = max(runs[k][0], runs[k + 1][0])
        hi_i = runs[k][1]
        if lo_i > hi_i:
            # only a diagonal step between two blocked cells (corner cutting) leaves two
            # consecutive path cells that no free box holds together
            a_c, b_c = cells[runs[k][1]].tolist(), cells[runs[k + 1][0]].tolist()
            raise InvalidInputError(
                f"grid_path step {runs[k][1]} from {a_c} to {b_c} cuts a corner of the inflated "
                "grid (a diagonal step whose two orthogonal neighbours are not both free), so no "
                "free box holds both cells; search with corner_cutting=False"
                + ("" if raw_occ is not None else " or pass raw_grid and radius for bridges")
            )
        ov_lo[k], ov_hi[k] = s[lo_i], s[hi_i]
    trans = _place_transitions(ov_lo, ov_hi, float(s[-1]), min_share_cells * res)
    boxes = tuple(
        Box(
            xmin=ox + (r[0] + 0.5) * res,
            xmax=ox + (r[1] + 0.5) * res,
            ymin=oy + (r[2] + 0.5) * res,
            ymax=oy + (r[3] + 0.5) * res,
            ix0=r[0],
            ix1=r[1],
            iy0=r[2],
            iy1=r[3],
        )
        if dg is None
        else _bridge_box(dg, res, ox, oy)
        for r, dg in zip(rects, diags, strict=True)
    )
    logger.debug("corridor: %d boxes for %d path cells", m, n)
    return Corridor(
        boxes=boxes,
        path_ranges=np.array(runs, dtype=np.int64).reshape(-1, 2),
        transitions_m=trans,
        overlap_start_m=ov_lo,
        overlap_end_m=ov_hi,
        path_points=pts,
        path_s=s,
        resolution=res,
        origin=(ox, oy),
        radius=None if radius is None else float(radius),
    )


def _place_transitions(
    lo: np.ndarray, hi: np.ndarray, length: float, min_share: float
) -> np.ndarray:
    """Transitions at the overlap midpoints, then nudged (inside their overlaps) so that
    every box's share is at least ``min_share`` where the overlaps allow it."""
    t = 0.5 * (lo + hi)
    m = len(t)
    if m == 0:
        return t
    for _ in range(3):
        for k in range(m + 1):
            left = t[k - 1] if k > 0 else 0.0
            right = t[k] if k < m else length
            deficit = min_share - (right - left)
            if deficit <= 0:
                continue
            if k < m:
                room = hi[k] - t[k]
                step = min(room, 0.5 * deficit if k > 0 else deficit)
                t[k] += step
                deficit -= step
            if k > 0 and deficit > 0:
                room = t[k - 1] - lo[k - 1]
                t[k - 1] -= min(room, deficit)
    # keep strictly increasing (guaranteed by the overlap structure; enforce defensively)
    for k in range(1, m):
        if t[k] <= t[k - 1]:
            t[k] = min(hi[k], t[k - 1] + 1e-9 * max(1.0, length))
    return t


# ------------------------------------------------------------------ bridges


def _occupied_squares(occ: np.ndarray, x0: int, x1: int, y0: int, y1: int) -> np.ndarray:
    """Lower-left corners (cells) of the occupied unit squares among cells ``x0..x1`` by
    ``y0..y1``; cells outside the map count as occupied. Shape (M, 2)."""
    ny, nx = occ.shape
    xs = np.arange(x0, x1 + 1)
    ys = np.arange(y0, y1 + 1)
    gx, gy = np.meshgrid(xs, ys)
    inside = (gx >= 0) & (gx < nx) & (gy >= 0) & (gy < ny)
    blocked = np.ones(gx.shape, dtype=bool)
    blocked[inside] = occ[gy[inside], gx[inside]]
    return np.column_stack([gx[blocked], gy[blocked]]).astype(float)


def rotated_rect_clearance(sd: tuple[float, float, float, float], squares: np.ndarray) -> float:
    """Exact distance from a 45-degree rectangle to a set of axis-aligned unit squares.

    Parameters
    ----------
    sd : (smin, smax, dmin, dmax)
        The rectangle ``smin <= x + y <= smax``, ``dmin <= x - y <= dmax`` (cell units).
    squares : ndarray, shape (M, 2)
        Lower-left corners of the unit squares (cell units).

    Returns
    -------
    float
        ``0`` when the rectangle meets a square, ``inf`` for no squares; otherwise the
        distance (cells): two disjoint convex polygons are closest at a vertex of one of
        them, so it is the smaller of the rectangle's corners to the squares and the
        squares' corners to the rectangle. Separation is decided exactly by the four axes
        of the two shapes (separating-axis theorem).
    """
    if len(squares) == 0:
        return float("inf")
    smin, smax, dmin, dmax = sd
    vs = np.array([smin, smax, smax, smin])
    vd = np.array([dmin, dmin, dmax, dmax])
    corners = np.ascontiguousarray(np.column_stack([0.5 * (vs + vd), 0.5 * (vs - vd)]))
    sq = np.asarray(squares, dtype=float)
    rects = np.ascontiguousarray(np.column_stack([sq, sq + 1.0]))
    return float(polygon_rects_distance(corners, 4, rects))


def _diagonal_bridge(
    raw_occ: np.ndarray,
    cells: np.ndarray,
    t: int,
    radius_cells: float,
    *,
    reach: int = 3,
    step: float = 0.25,
    grow_along: float = 2.0,
    max_width: float = 4.0,
    min_width: float = 0.5,
) -> tuple[float, float, float, float] | None:
    """A certified 45-degree rectangle (cell units, ``(smin, smax, dmin, dmax)``) around the
    path near cell ``t`` when the path runs diagonally there, else ``None``.

    Seeded with the path cell centres ``t - k .. t + k`` (``k <= reach``, reduced until
    the seed is certified), then grown ``step`` at a time, round-robin across and along the
    path, while its exact distance to every occupied square of the raw map (and to the
    outside of the map) stays ``>= radius_cells``.
    """
    n = len(cells)
    k = min(reach, t, n - 1 - t)
    if k < 1:
        return None
    dv = cells[t + k] - cells[t - k]
    ax, ay = abs(int(dv[0])), abs(int(dv[1]))
    if ax == 0 or ay == 0 or max(ax, ay) > 2 * min(ax, ay):
        return None  # not a diagonal stretch: axis-aligned boxes serve it
    along_s = dv[0] * dv[1] > 0  # direction (1, 1): along x + y; else along x - y
    pad = int(np.ceil(radius_cells)) + reach + int(np.ceil(grow_along + max_width)) + 2
    cx, cy = int(cells[t, 0]), int(cells[t, 1])
    squares = _occupied_squares(raw_occ, cx - pad, cx + pad, cy - pad, cy + pad)

    def certified(r: list[float]) -> bool:
        return rotated_rect_clearance((r[0], r[1], r[2], r[3]), squares) >= radius_cells

    rect = None
    while k >= 1:
        seg = cells[t - k : t + k + 1] + 0.5
        s = seg[:, 0] + seg[:, 1]
        d = seg[:, 0] - seg[:, 1]
        cand = [float(s.min()), float(s.max()), float(d.min()), float(d.max())]
        if certified(cand):
            rect = cand
            break
        k -= 1
    if rect is None:
        return None
    # indices into rect: across (perpendicular) and along the path
    across = (2, 3) if along_s else (0, 1)
    along = (0, 1) if along_s else (2, 3)
    limit = {
        across[0]: rect[across[0]] - 0.5 * max_width,
        across[1]: rect[across[1]] + 0.5 * max_width,
        along[0]: rect[along[0]] - grow_along,
        along[1]: rect[along[1]] + grow_along,
    }
    sides = [across[0], across[1], along[0], along[1]]
    active = set(sides)
    while active:
        for side in sides:
            if side not in active:
                continue
            cand = list(rect)
            sign = -1.0 if side in (0, 2) else 1.0
            cand[side] += sign * step
            beyond = cand[side] < limit[side] if sign < 0 else cand[side] > limit[side]
            if beyond or not certified(cand):
                active.discard(side)
                continue
            rect = cand
    if rect[across[1]] - rect[across[0]] < min_width:
        return None
    return (rect[0], rect[1], rect[2], rect[3])


def _bridge_box(dg: tuple[float, float, float, float], res: float, ox: float, oy: float) -> Box:
    """World-metre :class:`Box` of a bridge given in cell units."""
    smin, smax, dmin, dmax = dg
    xmin, xmax = 0.5 * (smin + dmin), 0.5 * (smax + dmax)
    ymin, ymax = 0.5 * (smin - dmax), 0.5 * (smax - dmin)
    return Box(
        xmin=ox + xmin * res,
        xmax=ox + xmax * res,
        ymin=oy + ymin * res,
        ymax=oy + ymax * res,
        ix0=int(np.floor(xmin)),
        ix1=int(np.ceil(xmax)) - 1,
        iy0=int(np.floor(ymin)),
        iy1=int(np.ceil(ymax)) - 1,
        diagonal=(
            smin * res + ox + oy,
            smax * res + ox + oy,
            dmin * res + ox - oy,
            dmax * res + ox - oy,
        ),
    )


def _in_bridge(dg: tuple[float, float, float, float], cell: np.ndarray) -> bool:
    x, y = float(cell[0]) + 0.5, float(cell[1]) + 0.5
    eps = 1e-9
    return (
        dg[0] - eps <= x + y <= dg[1] + eps and dg[2] - eps <= x - y <= dg[3] + eps
    )


def _insert_bridges(rects, runs, cells, raw_occ, radius_cells):
    """Insert a certified 45-degree bridge between consecutive boxes whose shrunk boxes
    meet only at a point or along a line, where the path crosses them diagonally."""
    out_r = [rects[0]]
    out_run = [runs[0]]
    out_d: list = [None]
    for k in range(len(rects) - 1):
        a, b = rects[k], rects[k + 1]
        ext_x = min(a[1], b[1]) - max(a[0], b[0])
        ext_y = min(a[3], b[3]) - max(a[2], b[2])
        if ext_x < 1 or ext_y < 1:
            lo_i, hi_i = runs[k + 1][0], runs[k][1]
            t = (lo_i + hi_i) // 2
            dg = _diagonal_bridge(raw_occ, cells, t, radius_cells)
            if dg is not None:
                i0 = i1 = t
                while i0 > 0 and _in_bridge(dg, cells[i0 - 1]):
                    i0 -= 1
                while i1 + 1 < len(cells) and _in_bridge(dg, cells[i1 + 1]):
                    i1 += 1
                # it must share path cells with both neighbours, beyond the single cell t
                left = (max(runs[k][0], i0), min(runs[k][1], i1))
                right = (max(runs[k + 1][0], i0), min(runs[k + 1][1], i1))
                if left[0] <= left[1] and right[0] <= right[1] and left[0] < right[1]:
                    out_r.append(None)  # a bridge has no cell rectangle
                    out_run.append((i0, i1))
                    out_d.append(dg)
        out_r.append(b)
        out_run.append(runs[k + 1])
        out_d.append(None)
    return out_r, out_run, out_d
