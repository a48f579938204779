"""Building the polygon corridor around a path (:func:`build_polygon_corridor`)."""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from trajopt.corridor._polygons.path_kernels import (
    centre_path,
    junction_extensions,
    path_clearances,
    simplify_path,
)
from trajopt.corridor._polygons.region_kernels import certify_all, chain_geometry, grow_all
from trajopt.corridor._polygons.regions import (
    CLEARANCE_TOL_M,
    ROUND_M,
    ConvexPolygon,
    PolygonCorridor,
    degenerate_from,
    point_region,
    segment_region,
    shoelace,
)
from trajopt.errors import InvalidInputError, SmoothingError
from trajopt.geometry import BUCKET_CELLS, ObstacleIndex, grid_cells, length_unit
from trajopt.validation import nonnegative, positive

logger = logging.getLogger("trajopt.corridor")

MAX_SIDES = 256


@dataclass(frozen=True)
class PolygonOptions:
    """How :func:`build_polygon_corridor` prepares the path and grows the regions.

    Validated on construction; every value is kept as a float. The values count length
    units (:func:`~trajopt.geometry.length_unit`: the cell side, or ``radius / 6`` on maps
    whose cells are finer), called cells below; :meth:`in_cells` converts them.

    Attributes
    ----------
    margin_cells : float
        How far (cells) a region may reach beyond its seed's bounding box (> 0).
    max_segment_cells : float
        Longest segment (cells) of the simplified path, hence of a region's seed (> 0).
    overlap_cells : float
        How far (cells) each seed reaches into the neighbouring segments (>= 0).
    centre_cells : float
        Largest push (cells) of an interior path point away from its nearest obstacle
        (>= 0; 0 disables centring).
    centre_trigger_cells : float
        Only points closer than ``radius`` plus this (cells) to an obstacle are pushed (>= 0).
    simplify_slack_cells : float
        Clearance (cells) a simplified segment may lose against the points it replaces (>= 0).
    open_cells : float
        Clearance beyond ``radius`` plus this (cells) counts as open space when simplifying
        (>= 0).

    Raises
    ------
    InvalidInputError
        A value that is not a finite number, or out of its range.
    """

    margin_cells: float = 16.0
    max_segment_cells: float = 20.0
    overlap_cells: float = 4.0
    centre_cells: float = 1.0
    centre_trigger_cells: float = 2.0
    simplify_slack_cells: float = 0.3
    open_cells: float = 2.0

    def __post_init__(self) -> None:
        checked = {
            "margin_cells": positive("margin_cells", self.margin_cells),
            "max_segment_cells": positive("max_segment_cells", self.max_segment_cells),
            "overlap_cells": nonnegative("overlap_cells", self.overlap_cells),
            "centre_cells": nonnegative("centre_cells", self.centre_cells),
            "centre_trigger_cells": nonnegative("centre_trigger_cells", self.centre_trigger_cells),
            "simplify_slack_cells": nonnegative("simplify_slack_cells", self.simplify_slack_cells),
            "open_cells": nonnegative("open_cells", self.open_cells),
        }
        for name, value in checked.items():
            object.__setattr__(self, name, value)

    def in_cells(self, cells_per_unit: float) -> PolygonOptions:
        """Return these options with every length multiplied by ``cells_per_unit`` (>= 1).

        ``self`` itself when ``cells_per_unit == 1`` (the unit is the cell).
        """
        if cells_per_unit == 1.0:
            return self
        return PolygonOptions(
            **{f.name: getattr(self, f.name) * cells_per_unit for f in fields(self)}
        )


@dataclass(frozen=True)
class GrownRegions:
    """Certified regions around a path, before the chain geometry.

    What :func:`grow_regions` returns and :func:`assemble_corridor` takes (``m`` regions, world
    metres). The arrays are padded: region ``k`` uses the first ``nrow[k]`` rows of ``hm[k]``
    and the first ``nvs[k]`` rows of ``vm[k]``.

    Attributes
    ----------
    regions : list of ConvexPolygon, length m
        The regions; region ``k`` contains segment ``k`` of ``path_m``.
    hm : ndarray, shape (m, q, 3)
        Half-plane rows ``(a_x, a_y, b)`` of every region (``a . p <= b``, m).
    vm : ndarray, shape (m, v, 2)
        Vertices of every region (m); a degenerate region's two are its segment's ends.
    nrow : ndarray of int64, shape (m,)
        Rows used per region.
    nvs : ndarray of int64, shape (m,)
        Vertices used per region.
    degen : ndarray of bool, shape (m,)
        Degenerate regions (no interior: a segment).
    path_m : ndarray, shape (m + 1, 2)
        The corridor's path (m): the simplified path, its ends the input path's.
    seed_src : ndarray of int, shape (m + 1,)
        Index in ``pts_m`` of each vertex of ``path_m``.
    pts_m : ndarray, shape (N, 2)
        The input path (m).
    clear_m : ndarray, shape (m,)
        Certified clearance of each region from the raw map (m).
    radius : float
        Clearance every region keeps (m).
    resolution : float
        Cell size of the map (m).
    origin : tuple of float
        World position of the map's corner ``(x, y)`` (m).
    unit_m : float
        The length unit the options counted (m; :func:`~trajopt.geometry.length_unit`).
    """

    regions: list[ConvexPolygon]
    hm: np.ndarray
    vm: np.ndarray
    nrow: np.ndarray
    nvs: np.ndarray
    degen: np.ndarray
    path_m: np.ndarray
    seed_src: np.ndarray
    pts_m: np.ndarray
    clear_m: np.ndarray
    radius: float
    resolution: float
    origin: tuple[float, float]
    unit_m: float


def _path_points(path: Any, res: float, ox: float, oy: float) -> np.ndarray:
    """World points (m) of a GridPath / integer cells (cell centres) or float points."""
    cells = getattr(path, "cells", None)
    arr = np.asarray(path if cells is None else cells)
    if arr.ndim != 2 or arr.shape[1] != 2 or arr.shape[0] < 1:
        raise InvalidInputError(f"path must have shape (n, 2) with n >= 1, got {arr.shape}")
    if np.issubdtype(arr.dtype, np.integer):
        c = arr.astype(float)
        return np.column_stack([ox + (c[:, 0] + 0.5) * res, oy + (c[:, 1] + 0.5) * res])
    if not np.issubdtype(arr.dtype, np.floating):
        raise InvalidInputError(
            f"path must hold integer cells (ix, iy) or float world points (m), got {arr.dtype}"
        )
    p = arr.astype(float)
    if not np.all(np.isfinite(p)):
        raise InvalidInputError("path points must be finite")
    return p


def _point_name(i: int, n: int) -> str:
    if i == 0:
        return "start"
    if i == n - 1:
        return "goal"
    return f"path point {i}"


def build_polygon_corridor(
    raw_grid: Any,
    path: Any,
    radius: float,
    *,
    margin_cells: float = 16.0,
    max_segment_cells: float = 20.0,
    overlap_cells: float = 4.0,
    centre_cells: float = 1.0,
    centre_trigger_cells: float = 2.0,
    simplify_slack_cells: float = 0.3,
    open_cells: float = 2.0,
    unit_m: float | None = None,
) -> PolygonCorridor:
    """Grow a chain of certified convex polygons around a path (module docstring).

    Parameters
    ----------
    raw_grid : astar.OccupancyGrid
        The *raw* map (obstacles not inflated); the outside of the map counts as occupied.
    path : astar.GridPath or array_like, shape (n, 2)
        Integer cells ``(ix, iy)`` (a ``GridPath`` or an integer array; their cell centres
        are used), or float world points (m), from start to goal. Every point and every
        segment between consecutive points must keep ``radius`` from the raw map: an A*
        path on ``astar.inflate(raw_grid, radius, metric="square", outside_occupied=True)``
        does.
    radius : float
        Clearance (m) every region keeps from the raw map (finite, ``> 0``: at 0 the
        certificate could not tell touching an obstacle from overlapping it).
    margin_cells : float, optional
        How far (cells) a region may reach beyond its seed's bounding box (> 0). Default 16.
    max_segment_cells : float, optional
        Longest segment (cells) of the simplified path, hence of a region's seed (> 0).
        Default 20.
    overlap_cells : float, optional
        How far (cells) each seed reaches into the neighbouring segments, so that
        consecutive regions share at least twice this much path where obstacles allow
        (>= 0). Default 4.
    centre_cells : float, optional
        Largest push (cells) of an interior path point away from its nearest obstacle
        (>= 0; 0 disables centring). Default 1.
    centre_trigger_cells : float, optional
        Only points closer than ``radius`` plus this (cells) to an obstacle are pushed
        (>= 0). Default 2.
    simplify_slack_cells : float, optional
        Clearance (cells) a simplified segment may lose against the points it replaces,
        never going below ``radius`` (>= 0). Default 0.3.
    open_cells : float, optional
        Clearance beyond ``radius`` plus this (cells) counts as open space when simplifying
        (>= 0). Default 2.
    unit_m : float, optional
        The length unit (m) the options above count ("cells"), at least the map's cell
        side. Default :func:`~trajopt.geometry.length_unit` of the map and ``radius``: the
        cell side, or ``radius / 4`` on maps whose cells are finer, so that the corridor
        of a path is about the same whatever the map's resolution.

    Returns
    -------
    PolygonCorridor
        Every region certified: exact clearance ``>= radius - CLEARANCE_TOL_M``.

    Raises
    ------
    InvalidInputError
        A path point outside the map; a start, goal or path point, or a path segment,
        closer than ``radius`` to an occupied square or the outside of the map (a radius
        larger than the free space there, or a gap narrower than ``2 radius``); fewer
        than two distinct path points; an option out of range. The message names the
        point, its clearance and the rule.
    SmoothingError
        A region failed its certificate or lost its seed (a bug: the construction
        prevents both; the corridor is never returned then).

    Notes
    -----
    Deterministic. Costs grow with the path length and the number of obstacle
    rectangles within ``margin_cells`` of it; see ``benchmarks/bench_polygon_corridor.py``.
    """
    options = PolygonOptions(
        margin_cells=margin_cells,
        max_segment_cells=max_segment_cells,
        overlap_cells=overlap_cells,
        centre_cells=centre_cells,
        centre_trigger_cells=centre_trigger_cells,
        simplify_slack_cells=simplify_slack_cells,
        open_cells=open_cells,
    )
    return assemble_corridor(grow_regions(raw_grid, path, radius, options, unit_m))


def grow_regions(
    raw_grid: Any,
    path: Any,
    radius: float,
    options: PolygonOptions | None = None,
    unit_m: float | None = None,
) -> GrownRegions:
    """Grow and certify the regions of :func:`build_polygon_corridor`.

    ``raw_grid``, ``path``, ``radius`` and ``unit_m`` as there; ``options`` its other
    keyword options (default ``PolygonOptions()``, its defaults). Raises what it raises, but
    does not compute the chain's intervals and overlaps (:func:`assemble_corridor` does).
    """
    if options is None:
        options = PolygonOptions()
    elif not isinstance(options, PolygonOptions):
        raise InvalidInputError(f"options must be a PolygonOptions, got {type(options).__name__}")
    occ, res, ox, oy = grid_cells(raw_grid)
    r = positive("radius", radius)
    unit = length_unit(res, r) if unit_m is None else positive("unit_m", unit_m)
    if unit < res * (1 - 1e-12):
        raise InvalidInputError(f"unit_m must be at least the cell side {res} m, got {unit_m!r}")
    options = options.in_cells(unit / res)
    ny, nx = occ.shape
    pts_m = _path_points(path, res, ox, oy)
    n_in = len(pts_m)
    r_c = r / res
    tol_c = CLEARANCE_TOL_M / res
    pc_ = (pts_m - np.array([ox, oy])) / res  # cell units
    outside = (pc_[:, 0] < 0) | (pc_[:, 0] > nx) | (pc_[:, 1] < 0) | (pc_[:, 1] > ny)
    if outside.any():
        i = int(np.nonzero(outside)[0][0])
        raise InvalidInputError(
            f"{_point_name(i, n_in)} {pts_m[i].tolist()} m lies outside the map "
            f"[{ox}, {ox + nx * res}] x [{oy}, {oy + ny * res}] m"
        )
    src, p = _distinct_points(pc_, n_in)
    if unit > res:  # cells finer than the unit: about one point per unit along straight runs
        keep = thin_runs(p, unit / res)
        src, p = src[keep], np.ascontiguousarray(p[keep])
    reach = options.margin_cells + r_c + options.centre_cells + options.overlap_cells + 3.0
    fine = unit > res  # cells finer than the unit: buckets and rectangles follow the unit
    idx = ObstacleIndex(
        occ,
        int(math.floor(p[:, 0].min() - reach)),
        int(math.ceil(p[:, 0].max() + reach)) + 1,
        int(math.floor(p[:, 1].min() - reach)),
        int(math.ceil(p[:, 1].max() + reach)) + 1,
        bucket_cells=max(BUCKET_CELLS, round(BUCKET_CELLS * unit / res)),
        whole_map=fine and not occ.flags.writeable,
    )
    seed, seed_src, hh, vv, nvs, degen = _grow_regions(idx, p, src, pts_m, r_c, tol_c, res, options)
    # the certificate: exact clearance of every region (cell units)
    clear_c = certify_all(vv, nvs, r_c + 1.0, *idx.args)
    bad = np.nonzero(clear_c < r_c - tol_c)[0]
    if len(bad):
        k = int(bad[0])
        raise SmoothingError(
            f"region {k} failed its certificate: clearance {clear_c[k] * res:.9g} m < radius "
            f"{r} m - {CLEARANCE_TOL_M:g} m",
            {"region": k, "clearance_m": float(clear_c[k] * res)},
        )
    logger.debug(
        "polygon corridor: %d regions for %d path points (%d obstacle rectangles)",
        len(seed) - 1,
        n_in,
        len(idx.rects),
    )
    regions, hm, vm, nrow = metric_regions(seed, hh, vv, nvs, degen, res, (ox, oy))
    path_m = np.array([ox, oy]) + res * seed
    path_m[0], path_m[-1] = pts_m[src[0]], pts_m[src[-1]]
    return GrownRegions(
        regions=regions,
        hm=hm,
        vm=vm,
        nrow=nrow,
        nvs=nvs,
        degen=degen,
        path_m=path_m,
        seed_src=seed_src,
        pts_m=pts_m,
        clear_m=clear_c * res,
        radius=r,
        resolution=res,
        origin=(ox, oy),
        unit_m=unit,
    )


def _distinct_points(pc_: np.ndarray, n_in: int) -> tuple[np.ndarray, np.ndarray]:
    """Return the path without repeated points (cell units) and where each kept one came from."""
    keep_in = np.concatenate([[True], np.any(np.diff(pc_, axis=0) != 0.0, axis=1)])
    src = np.nonzero(keep_in)[0]
    p = np.ascontiguousarray(pc_[src])
    if len(p) < 2:
        raise InvalidInputError(
            f"path needs at least two distinct points, got {len(p)} ({n_in} given)"
        )
    return src, p


def thin_runs(p: np.ndarray, step: float) -> np.ndarray:
    """Return which points of a path to keep: its corners and about one per ``step`` between.

    ``p`` (cell units, no repeated points); a point is a corner when the steps before and
    after it differ. Dropping points inside a straight run changes neither the path nor the
    clearance of its segments (a segment's clearance is the least of its pieces'), only how
    many points the corridor's path has: about as many per metre as on a map of cells of
    side ``step``.

    Returns
    -------
    ndarray of bool, shape (n,)
        The first and last points, every corner, and the first point of every ``step`` of
        arc length.
    """
    n = len(p)
    keep = np.ones(n, dtype=bool)
    if n <= 2:
        return keep
    d = np.diff(p, axis=0)
    corner = np.any(d[1:] != d[:-1], axis=1)
    s = np.concatenate([[0.0], np.cumsum(np.hypot(d[:, 0], d[:, 1]))])
    bucket = np.floor(s / step)
    keep[1:-1] = corner | (bucket[1:-1] != bucket[:-2])
    return keep


def _grow_regions(
    idx: ObstacleIndex,
    p: np.ndarray,
    src: np.ndarray,
    pts_m: np.ndarray,
    r_c: float,
    tol_c: float,
    res: float,
    opts: PolygonOptions,
) -> tuple:
    """Check, centre and simplify the path, then grow one region per simplified segment.

    Cell units. Returns ``(seed, seed_src, hh, vv, nvs, degen)``.
    """
    margin, max_len, ext = opts.margin_cells, opts.max_segment_cells, opts.overlap_cells
    push, trigger = opts.centre_cells, opts.centre_trigger_cells
    slack, open_c = opts.simplify_slack_cells, opts.open_cells
    args = idx.args
    cap = r_c + open_c + 2.0
    pcl, scl = path_clearances(p, cap, *args)
    _check_path_clearance(pts_m, src, pcl, scl, r_c, tol_c, res)
    # centre, then simplify
    if push > 0.0 and len(p) > 2:
        p = centre_path(p, r_c, push, trigger, 2, *args)
        pcl, scl = path_clearances(p, cap, *args)
    keep = simplify_path(p, pcl, scl, r_c, slack, open_c, max_len, *args)
    seed = np.ascontiguousarray(p[keep])
    seed_src = src[keep]
    e = junction_extensions(seed, ext, r_c, tol_c, *args)
    kmax = int(min(4 + len(idx.rects), MAX_SIDES))
    hh, vv, nvs, status = grow_all(seed, e, r_c, margin, kmax, *args)
    bad = np.nonzero(status >= 2)[0]
    if len(bad):
        k, st = int(bad[0]), int(status[bad[0]])
        why = {
            2: "its seed meets an obstacle's dilation",
            3: "it lost a seed point",
            4: f"it needs more than {kmax} sides",
        }[st]
        raise SmoothingError(
            f"region {k} around path segment {seed_src[k]}..{seed_src[k + 1]} could not be "
            f"grown: {why}",
            {"region": k, "status": st},
        )
    degen = status == 1
    for k in np.nonzero(degen)[0]:  # no interior: the seed segment, extended along its line
        vv[k, :2] = _line_extension(seed[k], seed[k + 1], ext, r_c, tol_c, args)
        nvs[k] = 2
    return seed, seed_src, hh, vv, nvs, degen


def _line_extension(
    a: np.ndarray, b: np.ndarray, ext: float, r_c: float, tol_c: float, args: tuple
) -> np.ndarray:
    """Return the ends of segment ``a -> b`` extended along its line (cell units).

    A degenerate region (a passage exactly ``2 r`` wide) is a segment of the line its
    free space lies on. Its neighbours meet it where the path enters that line, often at
    the tip of a wedge (the path reaches the line at an angle); a region holding only its
    seed segment then overlaps the wedge in a sliver, and the control points shared by the
    two regions are squeezed into it (the QP stalls or the curve nearly stops there).
    Each end is therefore extended along the line by the largest of ``ext``, ``ext / 2``,
    ``ext / 4`` (cells) whose added piece keeps ``r_c - tol_c`` from every obstacle, as
    the seed extensions of the other regions are (the region is certified afterwards
    like every other).
    """
    d = b - a
    u = d / math.hypot(d[0], d[1])
    cap = r_c + 1.0
    out = np.array([a, b], dtype=float)
    for end, sign in ((0, -1.0), (1, 1.0)):
        p = out[end]
        for e in (ext, 0.5 * ext, 0.25 * ext):
            if e <= 0.0:
                break
            q = p + sign * e * u
            _, sc = path_clearances(np.ascontiguousarray(np.array([p, q])), cap, *args)
            if sc[0] >= r_c - tol_c:
                out[end] = q
                break
    return out


def metric_regions(
    seed: np.ndarray,
    hh: np.ndarray,
    vv: np.ndarray,
    nvs: np.ndarray,
    degen: np.ndarray,
    res: float,
    origin: tuple[float, float],
) -> tuple[list[ConvexPolygon], np.ndarray, np.ndarray, np.ndarray]:
    """Return grown regions (cell units) in world metres: ``(regions, hm, vm, nrow)``.

    ``hm[k, :nrow[k]]`` are region ``k``'s rows ``(a_x, a_y, b)`` (m), ``vm[k, :nvs[k]]``
    its vertices (m); a degenerate region becomes its seed segment's region.
    """
    o = np.array(origin, dtype=float)
    vm = o + res * vv
    hm = hh.copy()
    hm[:, :, 2] = res * hh[:, :, 2] + hh[:, :, :2] @ o
    nrow = nvs.copy()
    regions: list[ConvexPolygon] = []
    for k in range(len(seed) - 1):
        if degen[k]:
            reg = segment_region(vm[k, 0], vm[k, 1])
            nrow[k] = reg.n_sides
            hm[k, : nrow[k], :2] = reg.A
            hm[k, : nrow[k], 2] = reg.b
        else:
            n = nvs[k]
            reg = ConvexPolygon._construct_fast(hm[k, :n, :2], hm[k, :n, 2], vm[k, :n], False)
        regions.append(reg)
    return regions, hm, vm, nrow


def assemble_corridor(grown: GrownRegions) -> PolygonCorridor:
    """Return the :class:`PolygonCorridor` of certified regions around the path ``grown.path_m``.

    Computes the chain's path intervals, overlaps and transitions.

    Parameters
    ----------
    grown : GrownRegions
        The regions (region ``k`` contains segment ``k`` of ``grown.path_m``).

    Returns
    -------
    PolygonCorridor

    Raises
    ------
    SmoothingError
        A region does not contain its path segment, or two consecutive regions do not both
        contain their shared path vertex (not expected of :func:`grow_regions`' regions).
    """
    hm, vm, nrow, nvs, degen = grown.hm, grown.vm, grown.nrow, grown.nvs, grown.degen
    path_m = grown.path_m
    ox, oy = grown.origin
    m = len(path_m) - 1
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(path_m, axis=0).T))])
    region_s, overlap_s, ov_v, ov_h, ov_n = chain_geometry(
        hm, vm, nrow, nvs, degen, path_m, s, ROUND_M
    )
    bad = np.nonzero(~np.isfinite(region_s[:, 0]))[0]
    if len(bad):
        raise SmoothingError(
            f"region {int(bad[0])} does not contain its path segment", {"region": int(bad[0])}
        )
    bad = np.nonzero(~np.isfinite(overlap_s[:, 0]))[0]
    if len(bad):
        k = int(bad[0])
        raise SmoothingError(
            f"regions {k} and {k + 1} do not both contain their shared path vertex",
            {"region": k},
        )
    region_index = np.column_stack(
        [
            np.searchsorted(s, region_s[:, 0] - 1e-12, side="left"),
            np.searchsorted(s, region_s[:, 1] + 1e-12, side="right") - 1,
        ]
    )
    overlaps: list[ConvexPolygon] = []
    for k in range(m - 1):
        n = int(ov_n[k])
        v = ov_v[k, :n]
        if n >= 3 and not (degen[k] or degen[k + 1]) and shoelace(v) > 0.0:
            ov = ConvexPolygon._construct_fast(ov_h[k, :n, :2], ov_h[k, :n, 2], v, False)
        elif n == 0:  # only touching at their shared path vertex (within rounding)
            ov = point_region(path_m[k + 1])
        else:
            ov = degenerate_from(v)
        overlaps.append(ov)
    lo, hi = overlap_s[:, 0], overlap_s[:, 1]
    trans = 0.5 * (
        np.maximum(lo, 0.5 * (s[:-2] + s[1:-1])) + np.minimum(hi, 0.5 * (s[1:-1] + s[2:]))
    )
    trans_pts = np.column_stack(
        [np.interp(trans, s, path_m[:, 0]), np.interp(trans, s, path_m[:, 1])]
    ).reshape(-1, 2)
    return PolygonCorridor(
        regions=tuple(grown.regions),
        path=path_m,
        path_s=s,
        source_index=grown.seed_src,
        input_path=grown.pts_m,
        region_s=region_s,
        region_index=region_index,
        transitions_m=trans,
        transition_points=trans_pts,
        overlap_s=overlap_s,
        overlaps=tuple(overlaps),
        clearance_m=grown.clear_m,
        radius=grown.radius,
        resolution=grown.resolution,
        origin=(ox, oy),
        unit_m=grown.unit_m,
    )


def _check_path_clearance(
    pts_m: np.ndarray,
    src: np.ndarray,
    pcl: np.ndarray,
    scl: np.ndarray,
    r_c: float,
    tol_c: float,
    res: float,
) -> None:
    """Raise for the first point, then segment, closer than ``r`` to the raw map.

    Raise for the first point, then segment, closer than ``r`` to the raw map (``src`` maps the
    de-duplicated points, whose clearances ``pcl``/``scl`` are in cells, to the input points
    ``pts_m``).
    """
    n_in = len(pts_m)
    bad = np.nonzero(pcl < r_c - tol_c)[0]
    if len(bad):
        # the end points first: a radius larger than the free space there
        last = len(pcl) - 1
        i = sorted(bad.tolist(), key=lambda j: (j not in (0, last), j))[0]
        j = int(src[i])
        raise InvalidInputError(
            f"{_point_name(j, n_in)} {pts_m[j].tolist()} m has clearance {pcl[i] * res:.6g} m, "
            f"less than the radius {r_c * res:.6g} m: every path point must keep the radius "
            "from every occupied cell (a square) and from the outside of the map"
        )
    bad = np.nonzero(scl < r_c - tol_c)[0]
    if len(bad):
        i = int(bad[0])
        a, b = int(src[i]), int(src[i + 1])
        raise InvalidInputError(
            f"path segment from point {a} {pts_m[a].tolist()} m to point {b} "
            f"{pts_m[b].tolist()} m has clearance {scl[i] * res:.6g} m, less than the radius "
            f"{r_c * res:.6g} m: it passes a gap narrower than 2 * radius = "
            f"{2 * r_c * res:.6g} m; search the path on "
            "astar.inflate(raw_grid, radius, metric='square', outside_occupied=True)"
        )
