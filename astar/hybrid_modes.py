"""The collision modes of :func:`astar.find_pose_path` beyond its grid: exact clearance, a footprint.

The exact mode (``raw_grid``, ``clearance``) keeps the chords between the search's samples a
Euclidean distance from the raw map's squares. The footprint mode (``raw_grid``,
``footprint``) checks a car-like robot as the convex polygon it is, rotated by the pose's
heading, instead of a disc. Both are chosen by :class:`~astar.hybrid_options.HybridCollision`
(or the same fields by name, as keywords of :func:`astar.find_pose_path`). Units are
those of the search: **cells** (cell ``(ix, iy)`` is the closed square ``[ix - 0.5, ix + 0.5]
x [iy - 0.5, iy + 0.5]``, its centre at ``(ix, iy)``), headings in radians. The polygon is
given in the robot frame: ``x`` forwards along the heading, ``y`` to the left.

* :func:`footprint_polygon` validates a footprint and returns it counter-clockwise with its
  unit outward edge normals; :func:`footprint_radii` gives its inscribed and circumscribed
  radii about the origin.
* :func:`footprint_safe` marks the cells where no test is needed: every point of the cell
  keeps ``rho + margin + slack`` from every occupied square and from the outside.
* :func:`edge_occupancy` marks the occupied cells inside solid blocks (all 8 neighbours
  occupied or outside), which the footprint test skips, exactly (a body reaching one
  crosses the block's rim first).
* :func:`edge_next` indexes, along each row, the next occupied cell that the footprint test
  reads (value 1 of :func:`edge_occupancy`), so the test skips the free cells of the body's
  box without reading them.
* :func:`kernel_collision` builds the search kernel's collision record
  (:class:`~astar.hybrid_kernel.KernelCollision`) of a mode given as a
  :class:`~astar.hybrid_options.HybridCollision` (which validates its fields on
  construction), and tests the end poses' footprints; :func:`raw_occupied` reads the raw
  map of both modes, :func:`raw_occupancy` checks it against the grid.
* Polygons: where ``raw_grid`` is an :class:`~astar.grid.OccupancyGrid` made by
  :meth:`~astar.grid.OccupancyGrid.from_polygons` (its ``polygons`` known), the footprint
  mode's test of a pose whose grown body meets an occupied square inside the grid is decided
  by the body's exact distance to the polygons (:func:`grid_polygons`,
  :func:`astar.body_polygons.body_distance`): the squares cover the polygons, so a body they
  clear is clear, and the guarantee becomes "clear of the polygons by the margin". Without
  polygons nothing changes.

The compiled tests live in :mod:`astar.hybrid_kernel`, beside the search that calls them (so
that numba's cache of the search is rebuilt whenever they change):

* :func:`~astar.hybrid_kernel.footprint_hit` tests one pose: the footprint grown by a
  distance ``grow`` (its Minkowski sum with a disc) against every occupied square of the raw
  map and the outside of the grid, exactly (separating axes, then the polygon-to-square
  distance).
* :func:`~astar.hybrid_kernel.footprint_arc_clear` and
  :func:`~astar.hybrid_kernel.footprint_word_clear` test every pose of an arc (a
  Reeds-Shepp/Dubins word), not only samples: along an arc of curvature ``kappa`` every
  point of the body moves at most ``(1 + rho |kappa|)`` per cell of arc length (``rho``:
  the farthest vertex from the origin), so the body at every pose within ``ds / 2`` of a
  sample lies within ``slack = ds (1 + rho |kappa|) / 2`` of the body at the sample;
  testing the footprint grown by ``margin + slack`` at the middle of each of ``m`` equal
  steps of length ``ds`` covers the whole arc, its end poses included (and one test at the
  arc's middle, the footprint grown by ``margin`` plus the whole arc's sweep, covers it in
  open space).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from astar import validation
from astar.errors import InvalidInputError
from astar.grid import OccupancyGrid

if TYPE_CHECKING:  # pragma: no cover
    from astar.body_polygons import PackedPolygons  # numba: imported when a search runs
    from astar.hybrid_kernel import KernelCollision  # numba: imported when a search runs
    from astar.hybrid_options import HybridCollision  # it imports this module

__all__ = [
    "DEFAULT_SLACK",
    "clearance_bound",
    "edge_next",
    "edge_occupancy",
    "footprint_discs",
    "footprint_polygon",
    "footprint_radii",
    "footprint_safe",
    "grid_polygons",
    "kernel_collision",
    "raw_occupancy",
    "raw_occupied",
]

#: Default sampling slack (cells): how far the body moves between a pose and its sample.
DEFAULT_SLACK = 0.05
#: Discs per footprint width along its length (:func:`footprint_discs`).
DISCS_PER_WIDTH = 8


def footprint_discs(fp: np.ndarray) -> np.ndarray:
    """Return discs whose union covers a footprint (the quick test of the footprint mode).

    The footprint's bounding box in the robot frame, ``[x0, x1] x [y0, y1]``, is cut along
    its longer side into ``n = ceil(DISCS_PER_WIDTH * long / short)`` equal boxes, each
    covered by the disc about its centre through its corners: the union covers the box,
    hence the footprint, and grown by ``g`` they cover the footprint grown by ``g``.

    Parameters
    ----------
    fp : ndarray of float64, shape (k, 4)
        A footprint from :func:`footprint_polygon` (cells).

    Returns
    -------
    ndarray of float64, shape (n, 3)
        Per disc its centre ``(x, y)`` in the robot frame and its radius (cells).
    """
    x0, x1 = float(fp[:, 0].min()), float(fp[:, 0].max())
    y0, y1 = float(fp[:, 1].min()), float(fp[:, 1].max())
    along_x = x1 - x0 >= y1 - y0
    long, short = (x1 - x0, y1 - y0) if along_x else (y1 - y0, x1 - x0)
    n = max(1, math.ceil(DISCS_PER_WIDTH * long / short))
    w = long / n
    r = math.hypot(0.5 * w, 0.5 * short)
    t = (np.arange(n) + 0.5) * w
    if along_x:
        centres = np.column_stack([x0 + t, np.full(n, 0.5 * (y0 + y1))])
    else:
        centres = np.column_stack([np.full(n, 0.5 * (x0 + x1)), y0 + t])
    return np.ascontiguousarray(np.column_stack([centres, np.full(n, r * (1.0 + 1e-12))]))


def clearance_bound(occ: np.ndarray) -> np.ndarray:
    """Return a lower bound of the distance from each cell's centre to the obstacles.

    The obstacles are the occupied squares of ``occ`` and the outside of the grid (a ring of
    occupied cells round it). With ``E`` the Euclidean distance between the cell's centre
    and the nearest obstacle cell's centre (:func:`scipy.ndimage.distance_transform_edt`),
    the centre is at least ``E - sqrt(2) / 2`` from every obstacle square (half a diagonal
    from a square's centre to its points), and a point ``p`` of the cell at least that
    minus its distance to the centre (:func:`astar.hybrid_kernel.footprint_discs_clear`).

    Parameters
    ----------
    occ : ndarray of bool or uint8, shape (ny, nx)
        Nonzero on occupied cells.

    Returns
    -------
    ndarray of float64, shape (ny, nx)
        The bound (cells); ``<= 0`` on obstacles.
    """
    from scipy.ndimage import distance_transform_edt

    occ = np.asarray(occ) != 0
    pad = np.zeros((occ.shape[0] + 2, occ.shape[1] + 2), dtype=bool)  # the ring: occupied
    pad[1:-1, 1:-1] = ~occ  # True where free: the distances to the nearest False
    e = distance_transform_edt(pad)[1:-1, 1:-1]
    return np.ascontiguousarray(e - math.sqrt(0.5) - 1e-9)


def footprint_polygon(value: object) -> np.ndarray:
    """Validate a footprint and return its vertices and outward normals, counter-clockwise.

    Parameters
    ----------
    value : array_like of float, shape (k, 2)
        Vertices ``(x, y)`` in cells, robot frame (``x`` forwards along the heading, ``y``
        to the left), ``k >= 3``, in order (counter-clockwise or clockwise): a convex
        polygon (no repeated consecutive vertices, turning one way once round; collinear
        vertices are allowed) with the origin strictly inside.

    Returns
    -------
    ndarray of float64, shape (k, 4)
        Per vertex ``i``: ``(x, y, nx, ny)``, the vertex and the unit outward normal of the
        edge from vertex ``i`` to vertex ``i + 1`` (cyclic), counter-clockwise.

    Raises
    ------
    InvalidInputError
        The value is not a finite ``(k, 2)`` array with ``k >= 3``, not convex, or does not
        contain the origin strictly inside (the message names ``footprint``, the value and
        the rule).
    """
    shown = validation.short_repr(value)
    if isinstance(value, (str, bytes)):
        raise InvalidInputError(f"footprint must be an array of vertices (k, 2), got {shown}")
    try:
        a = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise InvalidInputError(
            f"footprint must be an array of vertices (k, 2) in cells, got {shown}"
        ) from None
    if a.ndim != 2 or a.shape[1] != 2 or a.shape[0] < 3:
        raise InvalidInputError(
            f"footprint must have shape (k, 2) with k >= 3 vertices (cells), got shape "
            f"{a.shape}: {shown}"
        )
    if not np.all(np.isfinite(a)):
        raise InvalidInputError(f"footprint vertices must be finite, got {a.tolist()}")
    e = np.roll(a, -1, axis=0) - a  # edge i: vertex i -> vertex i + 1
    size = float(np.abs(a).max())
    elen = np.hypot(e[:, 0], e[:, 1])
    if np.any(elen <= 1e-12 * size):
        i = int(np.argmin(elen))
        raise InvalidInputError(
            f"footprint vertices {i} and {(i + 1) % len(a)} coincide ({a[i].tolist()}): "
            f"a polygon needs distinct consecutive vertices, got {a.tolist()}"
        )
    en = np.roll(e, -1, axis=0)
    cross = e[:, 0] * en[:, 1] - e[:, 1] * en[:, 0]
    dot = e[:, 0] * en[:, 0] + e[:, 1] * en[:, 1]
    tol = 1e-12 * size * size
    turns = np.arctan2(cross, dot)
    if (
        (np.any(cross > tol) and np.any(cross < -tol))
        or np.any((np.abs(cross) <= tol) & (dot < 0.0))  # an edge folding back on itself
        or abs(abs(turns.sum()) - 2 * math.pi) > 1e-6
    ):
        raise InvalidInputError(
            "footprint must be a convex polygon (every turn the same way, once round), got "
            f"{a.tolist()}"
        )
    if turns.sum() < 0.0:  # clockwise: reverse
        a = a[::-1].copy()
        e = np.roll(a, -1, axis=0) - a
        elen = np.hypot(e[:, 0], e[:, 1])
    normals = np.column_stack([e[:, 1], -e[:, 0]]) / elen[:, None]
    # the origin's distance inside each edge (its support line): all > 0 for strictly inside
    inside = normals[:, 0] * a[:, 0] + normals[:, 1] * a[:, 1]
    if np.any(inside <= 1e-12 * size):
        raise InvalidInputError(
            "footprint must contain the robot's origin (0, 0) strictly inside (the pose is "
            f"the origin), got {a.tolist()} (distance {float(inside.min()):.6g} cells inside "
            "its nearest edge)"
        )
    return np.ascontiguousarray(np.column_stack([a, normals]))


def footprint_radii(fp: np.ndarray) -> tuple[float, float]:
    """Return ``(inscribed, circumscribed)`` radii about the origin (cells) of a footprint.

    Parameters
    ----------
    fp : ndarray of float64, shape (k, 4)
        A footprint from :func:`footprint_polygon`.

    Returns
    -------
    inscribed : float
        Distance from the origin to the nearest edge line (the largest disc about the
        origin inside the polygon).
    circumscribed : float
        Distance from the origin to the farthest vertex (``rho``: the polygon lies in the
        disc of this radius about the origin).
    """
    inscribed = float(np.min(fp[:, 2] * fp[:, 0] + fp[:, 3] * fp[:, 1]))
    return inscribed, float(np.hypot(fp[:, 0], fp[:, 1]).max())


def footprint_safe(occ: np.ndarray, reach: float) -> np.ndarray:
    """Cells every point of which keeps more than ``reach`` cells from occupied squares.

    Parameters
    ----------
    occ : ndarray of uint8 or bool, shape (ny, nx)
        Nonzero on the raw map's occupied cells.
    reach : float
        Distance in cells (``>= 0``), e.g. ``rho + margin + slack``.

    Returns
    -------
    ndarray of uint8, shape (ny, nx)
        1 where every point of the cell's square is farther than ``reach`` from every
        occupied square and from the outside of the grid (the cell's centre keeps ``reach +
        sqrt(2) / 2``, plus ``1e-6`` against rounding), 0 elsewhere.
    """
    from astar.inflation import inflate

    blocked = inflate(
        OccupancyGrid(np.asarray(occ, dtype=bool), 1.0),
        reach + math.sqrt(0.5) + 1e-6,
        metric="square",
        outside_occupied=True,
    )
    return np.ascontiguousarray(~np.asarray(blocked.occupied), dtype=np.uint8)


def edge_occupancy(occ: np.ndarray) -> np.ndarray:
    """Occupied cells marked by whether a free cell touches them (the footprint test's map).

    Parameters
    ----------
    occ : ndarray of bool, shape (ny, nx)
        True on occupied cells.

    Returns
    -------
    ndarray of uint8, shape (ny, nx)
        0 on free cells, 1 on occupied cells with a free cell among their 8 neighbours, 2
        on occupied cells whose 8 neighbours are occupied or outside the grid (inside a
        solid block: :func:`~astar.hybrid_kernel.footprint_hit` skips them, exactly).
    """
    from scipy.ndimage import binary_dilation

    occ = np.asarray(occ, dtype=bool)
    near_free = binary_dilation(~occ, structure=np.ones((3, 3), bool))
    out = np.where(occ, np.where(near_free, 1, 2), 0).astype(np.uint8)
    return np.ascontiguousarray(out)


def edge_next(occ: np.ndarray) -> np.ndarray:
    """Along each row, the next cell of value 1 of an :func:`edge_occupancy` map.

    Parameters
    ----------
    occ : ndarray of uint8, shape (ny, nx)
        :func:`edge_occupancy` (or a plain 0/1 map).

    Returns
    -------
    ndarray of int32, shape (ny, nx + 1)
        ``out[iy, ix]``: the least ``j >= ix`` with ``occ[iy, j] == 1``, ``nx`` when there is
        none (column ``nx`` is ``nx``): :func:`~astar.hybrid_kernel.footprint_hit` reads a row
        of the footprint's box at those cells only, the ones it tests.
    """
    occ = np.asarray(occ)
    ny, nx = occ.shape
    cols = np.where(occ == 1, np.arange(nx, dtype=np.int32), np.int32(nx)).astype(np.int32)
    out = np.full((ny, nx + 1), nx, dtype=np.int32)
    out[:, :nx] = np.minimum.accumulate(cols[:, ::-1], axis=1)[:, ::-1]
    return np.ascontiguousarray(out)


def raw_occupied(raw_grid: object) -> np.ndarray:
    """Return the occupied cells of a raw map as a read-only bool array (ny, nx).

    Parameters
    ----------
    raw_grid : OccupancyGrid or ndarray of bool, shape (ny, nx)
        The raw map: an ``OccupancyGrid`` (its ``occupied``, already a read-only bool
        array, is returned as it is) or a bool array ``True`` on occupied cells (copied).

    Raises
    ------
    InvalidInputError
        Neither an ``OccupancyGrid`` nor a 2-D bool array.
    """
    if isinstance(raw_grid, OccupancyGrid):
        return raw_grid.occupied
    a = np.asarray(raw_grid) if isinstance(raw_grid, np.ndarray) else None
    if a is None or a.dtype != bool or a.ndim != 2:
        raise InvalidInputError(
            "raw_grid must be an astar.OccupancyGrid or a 2-D bool array True on occupied "
            f"cells, got {type(raw_grid).__name__}"
            + (f" of dtype {a.dtype} and shape {a.shape}" if a is not None else "")
        )
    out = np.array(a, dtype=bool, copy=True)
    out.flags.writeable = False
    return out


def raw_occupancy(raw_grid: object, free: np.ndarray) -> np.ndarray:
    """Return the bool occupied mask (ny, nx) of ``raw_grid``, checked against ``free``."""
    occ = raw_occupied(raw_grid)
    if occ.shape != free.shape:
        raise InvalidInputError(
            f"raw_grid must have the grid's shape {free.shape} (ny, nx), got {occ.shape}"
        )
    return occ


def kernel_collision(
    collision: HybridCollision,
    free: np.ndarray,
    step: float,
    poses: tuple[tuple[str, tuple[float, float, float]], ...],
) -> KernelCollision:
    """Build the search kernel's collision record of a validated :class:`HybridCollision`.

    Parameters
    ----------
    collision : HybridCollision
        The collision mode (its fields are checked on construction).
    free : ndarray of uint8, shape (ny, nx)
        The search's free cells (``raw_grid`` must have their shape).
    step : float
        Collision sampling spacing along the primitives (cells).
    poses : tuple of (str, (x, y, heading))
        The start and goal poses by name: in the footprint mode, their footprint grown by
        the margin and the slack must keep clear of the raw map and inside the grid.

    Returns
    -------
    KernelCollision
        Off modes get placeholders: 1 x 1 ``safe``/``occ``, ``exact_r = 0``, a (0, 4)
        footprint.

    Raises
    ------
    InvalidInputError
        ``raw_grid`` does not have the grid's shape, or (footprint mode) an end pose's grown
        footprint meets an occupied square or leaves the grid.
    """
    from astar.body_polygons import pack_polygons
    from astar.hybrid_kernel import KernelCollision

    dummy = np.zeros((1, 1), dtype=np.uint8)
    no_fp = np.zeros((0, 4))
    no_next = np.ones((1, 2), dtype=np.int32)
    if collision.footprint is not None:
        return _footprint_inputs(collision, free, step, poses)
    if collision.clearance is None:
        no_discs = np.zeros((0, 3))
        return KernelCollision(
            step,
            dummy,
            dummy,
            0.0,
            no_fp,
            dummy,
            0.0,
            0.0,
            0.0,
            0.0,
            no_next,
            np.zeros((1, 1)),
            no_discs,
            *pack_polygons(None),
        )
    r = collision.clearance
    occ = raw_occupancy(collision.raw_grid, free)
    from astar.inflation import inflate

    margin = r + math.sqrt(0.5) + 1e-9
    blocked = inflate(OccupancyGrid(occ, 1.0), margin, metric="square", outside_occupied=True)
    safe = np.ascontiguousarray(~np.asarray(blocked.occupied), dtype=np.uint8)
    occ8 = np.ascontiguousarray(occ, dtype=np.uint8)
    no_discs = np.zeros((0, 3))
    return KernelCollision(
        step,
        safe,
        occ8,
        r,
        no_fp,
        safe,
        0.0,
        0.0,
        0.0,
        0.0,
        no_next,
        np.zeros((1, 1)),
        no_discs,
        *pack_polygons(None),
    )


def _footprint_inputs(
    collision: HybridCollision,
    free: np.ndarray,
    step: float,
    poses: tuple[tuple[str, tuple[float, float, float]], ...],
) -> KernelCollision:
    """Build the footprint mode's kernel inputs and test the end poses' footprints."""
    from astar.body_polygons import body_distance
    from astar.hybrid_kernel import KernelCollision, footprint_hit

    margin, slack = collision.footprint_margin, collision.footprint_slack
    min_slack = collision.footprint_min_slack
    fp = footprint_polygon(collision.footprint)
    occ = edge_occupancy(raw_occupancy(collision.raw_grid, free))
    onext = edge_next(occ)
    _, rho = footprint_radii(fp)
    safe = footprint_safe(occ, rho + margin + slack)
    buf = np.empty((fp.shape[0], 5))
    poly = grid_polygons(collision)
    fdist = clearance_bound(occ)
    discs = footprint_discs(fp)
    for name, (x, y, th) in poses:
        grow = margin + min_slack
        hit = int(footprint_hit(occ, onext, safe, fp, x, y, th, grow, buf))
        if hit >= 0 and len(poly[0]):  # the cells do not clear it: the polygons decide
            if body_distance(*poly, np.ascontiguousarray(buf[:, :2]), np.inf) > grow:
                hit = -1
        if hit != -1:
            where = (
                "leaves the grid"
                if hit == -2
                else f"meets the occupied cell ({hit % occ.shape[1]}, {hit // occ.shape[1]}) "
                "of raw_grid"
            )
            raise InvalidInputError(
                f"{name} pose ({x:g}, {y:g}, {th:g}): its footprint grown by footprint_margin + "
                f"the least sampling slack ({margin:g} + {min_slack:g} cells) {where}; it must keep "
                "clear of every occupied square and inside the grid"
                + (" (and of raw_grid's polygons)" if len(poly[0]) else "")
            )
    dummy = np.zeros((1, 1), dtype=np.uint8)
    return KernelCollision(
        step, dummy, occ, 0.0, fp, safe, rho, margin, slack, min_slack, onext, fdist, discs, *poly
    )


def grid_polygons(collision: HybridCollision) -> PackedPolygons:
    """Return the raw map's polygons in cells (:func:`pack_polygons`), or none.

    :attr:`HybridCollision.raw_polygons` (set from an :class:`OccupancyGrid` ``raw_grid``
    whose :attr:`~OccupancyGrid.polygons` are known), packed; none without them.
    """
    from astar.body_polygons import pack_polygons

    return pack_polygons(collision.raw_polygons)
