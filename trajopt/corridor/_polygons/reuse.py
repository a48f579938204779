"""A polygon corridor that keeps a previous corridor's regions along the path the two share.

A re-plan (:mod:`trajopt.replan._replan`) often needs a corridor around a path that ends like
the previous one: the same goal, and the same cells from some point on (the rest of the old
grid path joined from the robot, or a new search that meets the old path after a detour).
:func:`corridor_with_rest` grows regions only around the new part, the *head*, and keeps
the previous corridor's regions along the shared *rest*:

1. **The shared rest.** The longest common suffix of the two input paths (exact equality of
   their points: cell centres, and the same goal).
2. **The first kept region** ``k0`` is the first one whose previous path vertex also lies on
   the shared rest, so that region ``k0`` was grown, and extended backwards, along the
   shared path and the head's last region arrives along it too.
3. **Still certified?** A kept region was certified against the previous map; on the new one
   its clearance can only have dropped because of cells occupied since. Those cells (in a
   window around the kept regions) are indexed alone and every kept region's exact distance
   to them and to the outside of the map is computed (the certificate of
   :func:`~trajopt.corridor._polygons.build.build_polygon_corridor`, on the added cells). A
   region closer than the radius (less :data:`CLEARANCE_TOL_M`) moves ``k0`` past it.
4. **The head** (the new path up to region ``k0``'s first vertex, which ends it exactly) is
   grown and certified as a corridor of its own, and the chain is assembled again (path
   intervals, overlaps, transitions) over the head's regions and the kept ones.

Anything that does not fit (another map geometry or radius, no shared rest, no region left
to keep, a head that cannot be grown) returns ``None``; the caller then builds the whole
corridor.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from trajopt.corridor._polygons.build import GrownRegions, assemble_corridor, grow_regions
from trajopt.corridor._polygons.region_kernels import certify_all
from trajopt.corridor._polygons.regions import CLEARANCE_TOL_M, PolygonCorridor
from trajopt.errors import InvalidInputError, SmoothingError
from trajopt.geometry import ObstacleIndex, grid_cells


def shared_suffix(a: np.ndarray, b: np.ndarray) -> int:
    """Return how many trailing points (rows) ``a`` and ``b`` have exactly in common."""
    k = min(len(a), len(b))
    if k == 0:
        return 0
    same = np.all(a[len(a) - k :][::-1] == b[len(b) - k :][::-1], axis=1)
    return k if bool(same.all()) else int(np.argmin(same))


def corridor_with_rest(
    raw_grid: Any,
    points: np.ndarray,
    radius: float,
    previous: PolygonCorridor,
    previous_grid: Any,
) -> tuple[PolygonCorridor, int] | None:
    """Return a corridor around ``points`` keeping ``previous``'s regions along the shared rest.

    Parameters
    ----------
    raw_grid : astar.OccupancyGrid
        The current raw map.
    points : ndarray of float, shape (N, 2)
        The new path (m): exact start, cell centres, exact goal.
    radius : float
        Clearance (m) of every region; must equal ``previous.radius``.
    previous : PolygonCorridor
        A corridor built on ``previous_grid`` (same shape, resolution and origin).
    previous_grid : astar.OccupancyGrid
        The raw map ``previous`` was certified against.

    Returns
    -------
    (PolygonCorridor, int) or None
        The corridor (every region certified on ``raw_grid``) and how many of its regions,
        at its end, are ``previous``'s; ``None`` when no region can be kept (module
        docstring).
    """
    occ, res, ox, oy = grid_cells(raw_grid)
    old_occ, old_res, old_ox, old_oy = grid_cells(previous_grid)
    if (occ.shape, res, ox, oy) != (old_occ.shape, old_res, old_ox, old_oy):
        return None
    if (previous.resolution, tuple(previous.origin)) != (res, (ox, oy)):
        return None
    if float(radius) != float(previous.radius):
        return None
    pts = np.asarray(points, dtype=float)
    old_in = np.asarray(previous.input_path, dtype=float)
    shared = shared_suffix(pts, old_in)
    if shared < 2:
        return None
    first_shared = len(old_in) - shared  # previous input index of the rest's first point
    offset = len(pts) - len(old_in)  # new input index = previous input index + offset
    src = np.asarray(previous.source_index)
    m = len(previous.regions)
    on_rest = np.nonzero(src[:-1] >= first_shared)[0] + 1  # k with vertex k - 1 on the rest
    if len(on_rest) == 0 or on_rest[0] > m - 1:
        return None
    kept = _still_certified(previous, int(on_rest[0]), occ, old_occ, res, (ox, oy))
    if kept is None:
        return None
    k0, clear_kept = kept
    end = int(src[k0]) + offset
    head_pts = pts[: end + 1].copy()
    head_pts[-1] = previous.path[k0]  # the kept region's first vertex ends the head exactly
    try:
        head = grow_regions(raw_grid, head_pts, radius, unit_m=previous.unit_m)
    except (InvalidInputError, SmoothingError):
        return None
    try:
        corridor = assemble_corridor(_joined(head, previous, k0, offset, pts, clear_kept))
    except SmoothingError:  # the chain does not close at the join (not expected)
        return None
    return corridor, m - k0


def _still_certified(
    previous: PolygonCorridor,
    k0: int,
    occ: np.ndarray,
    old_occ: np.ndarray,
    res: float,
    origin: tuple[float, float],
) -> tuple[int, np.ndarray] | None:
    """Return the first region from ``k0`` after which all keep the radius on ``occ``.

    Returns ``(k0, clearance_m)``: that region and the certified clearances (m) of it and
    every later one on ``occ`` (capped at ``radius + resolution``); ``None`` when the last
    region fails.
    """
    m = len(previous.regions)
    o = np.asarray(origin, dtype=float)
    vv_list = [(np.asarray(reg.vertices, dtype=float) - o) / res for reg in previous.regions[k0:]]
    r_c = previous.radius / res
    ny, nx = occ.shape
    lo = np.min([v.min(axis=0) for v in vv_list], axis=0) - r_c - 2.0
    hi = np.max([v.max(axis=0) for v in vv_list], axis=0) + r_c + 2.0
    x0, y0 = max(0, int(np.floor(lo[0]))), max(0, int(np.floor(lo[1])))
    x1, y1 = min(nx, int(np.ceil(hi[0])) + 1), min(ny, int(np.ceil(hi[1])) + 1)
    added = occ[y0:y1, x0:x1] & ~old_occ[y0:y1, x0:x1]
    old_clear = np.asarray(previous.clearance_m, dtype=float)
    if not added.any():
        return k0, old_clear[k0:]
    only_added = np.zeros(occ.shape, dtype=bool)
    only_added[y0:y1, x0:x1] = added
    idx = ObstacleIndex(only_added, x0, x1, y0, y1)
    kv = max(len(v) for v in vv_list)
    vv = np.zeros((len(vv_list), kv, 2))
    nvs = np.zeros(len(vv_list), dtype=np.int64)
    for i, v in enumerate(vv_list):
        vv[i, : len(v)] = v
        nvs[i] = len(v)
    clear = np.minimum(old_clear[k0:], res * certify_all(vv, nvs, r_c + 1.0, *idx.args))
    bad = np.nonzero(clear < previous.radius - CLEARANCE_TOL_M)[0]
    if len(bad) == 0:
        return k0, clear
    first = int(bad[-1]) + 1
    return (k0 + first, clear[first:]) if k0 + first <= m - 1 else None


def _joined(
    head: GrownRegions,
    previous: PolygonCorridor,
    k0: int,
    offset: int,
    pts: np.ndarray,
    clear_kept: np.ndarray,
) -> GrownRegions:
    """Return the head's regions then ``previous``'s from ``k0``, as one :class:`GrownRegions`.

    ``offset`` maps ``previous``'s input indices to those of ``pts`` (the new input path, m);
    ``clear_kept`` (m) are the kept regions' clearances on the current map.
    """
    kept = previous.regions[k0:]
    n_head = len(head.regions)
    n = n_head + len(kept)
    rows = max(head.hm.shape[1], max(len(reg.b) for reg in kept))
    verts = max(head.vm.shape[1], max(len(reg.vertices) for reg in kept))
    hm = np.zeros((n, rows, 3))
    vm = np.zeros((n, verts, 2))
    hm[:n_head, : head.hm.shape[1]] = head.hm
    vm[:n_head, : head.vm.shape[1]] = head.vm
    nrow = np.concatenate([head.nrow, np.zeros(len(kept), dtype=np.int64)])
    nvs = np.concatenate([head.nvs, np.zeros(len(kept), dtype=np.int64)])
    degen = np.concatenate([head.degen, np.zeros(len(kept), dtype=bool)])
    for i, reg in enumerate(kept, start=n_head):
        q, v = len(reg.b), np.asarray(reg.vertices)
        hm[i, :q, :2], hm[i, :q, 2] = reg.A, reg.b
        vm[i, : len(v)] = v
        nrow[i], nvs[i], degen[i] = q, len(v), reg.degenerate
    src = np.asarray(previous.source_index)
    path_m = np.vstack([head.path_m[:-1], previous.path[k0:]])
    seed_src = np.concatenate([head.seed_src[:-1], src[k0:] + offset])
    clear = np.concatenate([head.clear_m, clear_kept])
    return GrownRegions(
        regions=list(head.regions) + list(kept),
        hm=hm,
        vm=vm,
        nrow=nrow,
        nvs=nvs,
        degen=degen,
        path_m=path_m,
        seed_src=seed_src,
        pts_m=pts,
        clear_m=clear,
        radius=head.radius,
        resolution=head.resolution,
        origin=head.origin,
        unit_m=head.unit_m,
    )
