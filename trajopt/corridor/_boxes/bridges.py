"""45-degree *bridges* of the box corridor.

Certified rotated rectangles where the path crosses diagonally between two boxes that meet only
at a point or along a line.

A bridge is grown around the path while its exact distance to every occupied square of
the raw map (and to the outside of the map) stays at least the radius
(:func:`trajopt.geometry._clearance.polygon_rects_distance`); without it the smoother's control
points would be squeezed into that point and the curve would stop there.
"""

from __future__ import annotations

import numpy as np

from trajopt.corridor._boxes.regions import Box
from trajopt.geometry import polygon_rects_distance


def occupied_squares(occ: np.ndarray, x0: int, x1: int, y0: int, y1: int) -> np.ndarray:
    """Lower-left corners.

    Lower-left corners (cells) of the occupied unit squares among cells ``x0..x1`` by
    ``y0..y1``; cells outside the map count as occupied. Shape (M, 2).
    """
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


def diagonal_bridge(
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
    """Return a certified 45-degree rectangle.

    A certified 45-degree rectangle (cell units, ``(smin, smax, dmin, dmax)``) around the path
    near cell ``t`` when the path runs diagonally there, else ``None``.

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
    squares = occupied_squares(raw_occ, cx - pad, cx + pad, cy - pad, cy + pad)

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


def bridge_box(dg: tuple[float, float, float, float], res: float, ox: float, oy: float) -> Box:
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


def in_bridge(dg: tuple[float, float, float, float], cell: np.ndarray) -> bool:
    x, y = float(cell[0]) + 0.5, float(cell[1]) + 0.5
    eps = 1e-9
    return dg[0] - eps <= x + y <= dg[1] + eps and dg[2] - eps <= x - y <= dg[3] + eps


def insert_bridges(rects, runs, cells, raw_occ, radius_cells):
    """Insert certified 45-degree bridges between boxes that meet only at a point or line.

    Insert a certified 45-degree bridge between consecutive boxes whose shrunk boxes meet only
    at a point or along a line, where the path crosses them diagonally.
    """
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
            dg = diagonal_bridge(raw_occ, cells, t, radius_cells)
            if dg is not None:
                i0 = i1 = t
                while i0 > 0 and in_bridge(dg, cells[i0 - 1]):
                    i0 -= 1
                while i1 + 1 < len(cells) and in_bridge(dg, cells[i1 + 1]):
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
