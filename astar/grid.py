"""The occupancy grid value and its cell/world coordinate conversions.

Conventions (as ROS ``nav_msgs/OccupancyGrid`` and Nav2):

* ``occupied[iy, ix]``; ``iy`` grows with world y, so row 0 is the *bottom* row.
* A cell is written ``(ix, iy)``, x first.
* Cell ``(ix, iy)`` covers the world rectangle
  ``[ox + ix*res, ox + (ix+1)*res) x [oy + iy*res, oy + (iy+1)*res)`` with
  ``(ox, oy) = origin``; its centre is ``(ox + (ix+0.5)*res, oy + (iy+0.5)*res)``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from astar import validation
from astar.errors import InvalidInputError
from astar.polygons import check_bounds, rasterize_polygons, rasterize_rings

__all__ = ["OccupancyGrid", "check_grid", "from_polygons"]


def _factor(k: object) -> int:
    """Return ``k`` checked as the integer ``>= 1`` of :meth:`OccupancyGrid.split` / ``coarsen``."""
    k = validation.nonnegative_int("k", k)
    if k < 1:
        raise InvalidInputError(f"k must be an integer >= 1, got {k}")
    return k


@dataclass(frozen=True, slots=True)
class OccupancyGrid:
    """A 2-D occupancy grid: which cells are blocked, their size and where they are.

    Parameters
    ----------
    occupied : array_like of bool, shape (ny, nx)
        ``True`` where the cell is occupied. Copied and made read-only. Integer arrays
        holding only 0 and 1 are accepted; anything else is rejected.
    resolution : float
        Cell side in metres (> 0, finite).
    origin : tuple of float, optional
        World ``(x, y)`` in metres of the lower-left corner of cell ``(0, 0)``.

    Attributes
    ----------
    polygons : tuple of ndarray or None
        The polygon obstacles the grid was rasterised from (:meth:`from_polygons`), each
        a read-only array ``(k, 2)`` of counter-clockwise vertices in world metres, or
        ``None`` (a grid given as cells). Not a constructor parameter: set by
        :meth:`from_polygons` and kept by the operations whose occupied squares still
        cover every polygon (:meth:`split`, :meth:`coarsen`, :meth:`moved_to`); dropped by
        :meth:`with_occupied` (new occupancy). Where they are known, the car planner tests
        a body exactly against them (the cells a conservative pre-filter). Equality and
        ``repr`` ignore them.

    Examples
    --------
    >>> import numpy as np
    >>> g = OccupancyGrid(np.zeros((3, 4), bool), resolution=0.5, origin=(1.0, 2.0))
    >>> g.nx, g.ny
    (4, 3)
    >>> g.cell_to_world([1, 0]).tolist()
    [1.75, 2.25]
    """

    occupied: np.ndarray
    resolution: float
    origin: tuple[float, float] = (0.0, 0.0)
    polygons: tuple[np.ndarray, ...] | None = field(default=None, init=False, compare=False)

    def __post_init__(self) -> None:
        occ = validation.bool_grid(self.occupied)
        res = validation.positive_float("resolution", self.resolution, allow_bool=True)
        ox, oy = validation.origin(self.origin)
        object.__setattr__(self, "occupied", occ)
        object.__setattr__(self, "resolution", res)
        object.__setattr__(self, "origin", (ox, oy))
        object.__setattr__(self, "polygons", None)

    @classmethod
    def _construct_fast(
        cls, occupied: np.ndarray, resolution: float, origin: tuple[float, float]
    ) -> OccupancyGrid:
        """Build without validation (internal: ``occupied`` must be a fresh bool array)."""
        self = object.__new__(cls)
        occ = np.ascontiguousarray(occupied, dtype=bool)
        occ.flags.writeable = False
        object.__setattr__(self, "occupied", occ)
        object.__setattr__(self, "resolution", float(resolution))
        object.__setattr__(self, "origin", (float(origin[0]), float(origin[1])))
        object.__setattr__(self, "polygons", None)
        return self

    def _keeping(
        self, other: OccupancyGrid, shift: tuple[float, float] = (0.0, 0.0)
    ) -> OccupancyGrid:
        """Return ``other`` with this grid's polygons moved by ``shift`` (m) (internal).

        Only for an ``other`` whose occupied squares cover every polygon so moved.
        """
        if self.polygons is not None:
            if shift != (0.0, 0.0):
                d = np.asarray(shift, dtype=float)
                rings = []
                for v in self.polygons:
                    w = v + d
                    w.flags.writeable = False
                    rings.append(w)
                polys = tuple(rings)
            else:
                polys = self.polygons
            object.__setattr__(other, "polygons", polys)
        return other

    @classmethod
    def from_polygons(
        cls, polygons: Sequence[object], resolution: float, bounds: Sequence[float]
    ) -> OccupancyGrid:
        """Rasterise polygon obstacles conservatively: every cell a polygon touches is occupied.

        A cell is occupied iff its closed square meets a polygon, interior or boundary (a
        polygon edge on a grid line occupies the cells on both sides; points within 1e-9
        cells count as touching). The test is exact, not sampled: a square meets a simple
        polygon iff an edge of the polygon meets the square or the square's centre lies
        inside the polygon. Parts of polygons outside ``bounds`` are ignored; the map's
        outside is not marked (the planners treat it as blocked).

        Parameters
        ----------
        polygons : sequence of array_like, shape (k, 2)
            Simple polygons, convex or not (parked cars, kerbs), vertices ``(x, y)`` in
            world metres in either orientation; a last vertex equal to the first (a closed
            ring) is dropped.
        resolution : float
            Cell side in metres (> 0, finite).
        bounds : sequence of float
            ``(xmin, ymin, xmax, ymax)`` in metres. The origin is ``(xmin, ymin)``;
            ``nx = ceil((xmax - xmin) / resolution)`` columns (a whole number up to 1e-9
            cells is kept), so the grid reaches ``xmax`` or just beyond; the same along y.

        Returns
        -------
        OccupancyGrid

        Raises
        ------
        InvalidInputError
            A polygon that is not an array of shape ``(k, 2)``, has a non-finite
            coordinate, repeats a vertex consecutively, has fewer than 3 distinct vertices
            or zero area, or is self-intersecting; ``bounds`` not four finite numbers with
            ``xmax > xmin`` and ``ymax > ymin``; ``resolution`` not finite or ``<= 0``.
            The message names the field (``polygons[i]``, ``bounds``, ``resolution``), the
            value and the rule.

        Examples
        --------
        >>> g = OccupancyGrid.from_polygons([[(0.2, 0.2), (0.6, 0.2), (0.4, 0.6)]], 0.5,
        ...                                 (0.0, 0.0, 1.0, 1.0))
        >>> g.occupied.astype(int).tolist()
        [[1, 1], [1, 0]]
        """
        occ, res, origin, rings = rasterize_polygons(polygons, resolution, bounds)
        out = cls._construct_fast(occ, res, origin)
        object.__setattr__(out, "polygons", rings)
        return out

    def polygon_window(self, resolution: float, bounds: Sequence[float]) -> OccupancyGrid:
        """Rasterise this grid's own polygons at ``resolution`` over ``bounds``.

        The same cells as ``OccupancyGrid.from_polygons(self.polygons, resolution,
        bounds)``, without checking the polygons again (they were checked when this grid
        was made from them): a finer window round a stretch of a path, made once per fit.

        Parameters
        ----------
        resolution : float
            Cell side in metres (> 0, finite).
        bounds : sequence of float
            ``(xmin, ymin, xmax, ymax)`` in metres, as in :meth:`from_polygons`.

        Returns
        -------
        OccupancyGrid
            Keeps the same polygons.

        Raises
        ------
        InvalidInputError
            This grid was not made from polygons (``polygons`` is None); ``resolution`` or
            ``bounds`` as in :meth:`from_polygons`.
        """
        if self.polygons is None:
            raise InvalidInputError(
                "polygon_window needs a grid made from polygons (OccupancyGrid.from_polygons); "
                "this grid's polygons are None"
            )
        res = validation.positive_float("resolution", resolution)
        occ, res, origin, rings = rasterize_rings(self.polygons, res, check_bounds(bounds))
        out = type(self)._construct_fast(occ, res, origin)
        object.__setattr__(out, "polygons", rings)
        return out

    # ------------------------------------------------------------------ sizes
    @property
    def shape(self) -> tuple[int, int]:
        """``(ny, nx)``: rows, columns."""
        return self.occupied.shape  # type: ignore[return-value]

    @property
    def nx(self) -> int:
        """Number of columns (cells along x)."""
        return int(self.occupied.shape[1])

    @property
    def ny(self) -> int:
        """Number of rows (cells along y)."""
        return int(self.occupied.shape[0])

    @property
    def width(self) -> float:
        """Extent along x in metres."""
        return self.nx * self.resolution

    @property
    def height(self) -> float:
        """Extent along y in metres."""
        return self.ny * self.resolution

    @property
    def free(self) -> np.ndarray:
        """Read-only bool array ``[ny, nx]``, ``True`` where the cell is free."""
        out = ~self.occupied
        out.flags.writeable = False
        return out

    def with_occupied(self, occupied: np.ndarray) -> OccupancyGrid:
        """Return a grid with the same resolution and origin and new occupancy (validated).

        The result has no :attr:`polygons` (its cells need not cover them).
        """
        return OccupancyGrid(occupied, self.resolution, self.origin)

    def moved_to(self, origin: tuple[float, float]) -> OccupancyGrid:
        """Return the same cells with their lower-left corner at ``origin`` (m).

        The map moved as a whole: :attr:`polygons`, when known, move with the cells (by
        ``origin - self.origin``), so they stay covered.
        """
        o = validation.origin(origin)
        out = OccupancyGrid._construct_fast(self.occupied, self.resolution, o)
        return self._keeping(out, (o[0] - self.origin[0], o[1] - self.origin[1]))

    # ------------------------------------------------------- conversions
    def split(self, k: int) -> OccupancyGrid:
        """Return the same map with every cell split into ``k x k`` cells (side ``resolution / k``).

        The occupied squares cover exactly the same area and the origin is kept, so a plan
        on the result can be compared with one on this grid (the planner's sizes follow
        metres and the robot, not cells). ``k = 1`` returns ``self``. :attr:`polygons` are
        kept.

        Raises
        ------
        InvalidInputError
            ``k`` not an integer ``>= 1``.
        """
        k = _factor(k)
        if k == 1:
            return self
        occ = np.repeat(np.repeat(self.occupied, k, axis=0), k, axis=1)
        return self._keeping(OccupancyGrid(occ, self.resolution / k, self.origin))

    def coarsen(self, k: int) -> OccupancyGrid:
        """Return the map in cells ``k`` times larger, occupied wherever any of their cells was.

        Conservative: every occupied square of this grid lies inside an occupied square of
        the result, so a path clear on the result is clear here. The last row and column of
        blocks, when ``nx`` or ``ny`` is not a multiple of ``k``, are filled up with
        occupied cells (the outside of the map). The origin is kept. ``k = 1`` returns
        ``self``. :attr:`polygons` are kept (still covered). The planner's memory grows with
        the cell count: this is the knob that lowers it ``k * k`` times.

        Raises
        ------
        InvalidInputError
            ``k`` not an integer ``>= 1``.
        """
        k = _factor(k)
        if k == 1:
            return self
        ny, nx = self.shape
        by, bx = -(-ny // k), -(-nx // k)
        occ = np.ones((by * k, bx * k), dtype=bool)
        occ[:ny, :nx] = self.occupied
        blocks = occ.reshape(by, k, bx, k).any(axis=(1, 3))
        return self._keeping(OccupancyGrid(blocks, self.resolution * k, self.origin))

    def world_to_cell(self, xy: np.ndarray | tuple[float, float]) -> np.ndarray:
        """Cells ``(ix, iy)`` containing world points.

        Parameters
        ----------
        xy : array_like, shape (..., 2)
            World coordinates in metres.

        Returns
        -------
        ndarray of int64, shape (..., 2)
            ``floor((xy - origin) / resolution)``; may lie outside the grid (see
            :meth:`in_bounds`).
        """
        p = np.asarray(xy, dtype=float)
        if p.shape[-1:] != (2,):
            raise InvalidInputError(f"xy must have shape (..., 2), got {p.shape}")
        if not np.all(np.isfinite(p)):
            raise InvalidInputError(f"xy must be finite, got {p.tolist()}")
        cells = np.floor((p - np.asarray(self.origin)) / self.resolution)
        return cells.astype(np.int64)

    def cell_to_world(self, cells: np.ndarray | tuple[int, int]) -> np.ndarray:
        """World coordinates (metres) of cell centres.

        Parameters
        ----------
        cells : array_like of int, shape (..., 2)
            Cells ``(ix, iy)``.

        Returns
        -------
        ndarray of float, shape (..., 2)
        """
        c = np.asarray(cells, dtype=float)
        if c.shape[-1:] != (2,):
            raise InvalidInputError(f"cells must have shape (..., 2), got {c.shape}")
        return np.asarray(self.origin) + (c + 0.5) * self.resolution

    def in_bounds(self, cells: np.ndarray | tuple[int, int]) -> np.ndarray | bool:
        """Whether cells ``(ix, iy)`` (shape ``(..., 2)``) lie inside the grid."""
        c = np.asarray(cells)
        if c.shape[-1:] != (2,):
            raise InvalidInputError(f"cells must have shape (..., 2), got {c.shape}")
        ix, iy = c[..., 0], c[..., 1]
        out = (ix >= 0) & (ix < self.nx) & (iy >= 0) & (iy < self.ny)
        return bool(out) if out.ndim == 0 else out

    def is_free(self, cells: np.ndarray | tuple[int, int]) -> np.ndarray | bool:
        """Whether cells ``(ix, iy)`` are inside the grid and free (shape ``(...)``)."""
        c = np.asarray(cells, dtype=np.int64)
        inside = np.asarray(self.in_bounds(c))
        ix = np.where(inside, c[..., 0], 0)
        iy = np.where(inside, c[..., 1], 0)
        out = inside & ~self.occupied[iy, ix]
        return bool(out) if out.ndim == 0 else out

    def __repr__(self) -> str:
        return (
            f"OccupancyGrid(nx={self.nx}, ny={self.ny}, resolution={self.resolution!r}, "
            f"origin={self.origin!r}, occupied_cells={int(self.occupied.sum())})"
        )

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, OccupancyGrid):
            return NotImplemented
        return (
            self.resolution == other.resolution
            and self.origin == other.origin
            and self.occupied.shape == other.occupied.shape
            and bool(np.array_equal(self.occupied, other.occupied))
        )

    __hash__ = None  # type: ignore[assignment]


def check_grid(value: object) -> OccupancyGrid:
    """Return ``value`` if it is an :class:`OccupancyGrid` (the check of a ``grid`` argument).

    Parameters
    ----------
    value : object
        The ``grid`` argument of a public function of :mod:`astar`.

    Returns
    -------
    OccupancyGrid
        ``value`` itself.

    Raises
    ------
    InvalidInputError
        ``value`` is not an :class:`OccupancyGrid` (the message names its type).
    """
    if not isinstance(value, OccupancyGrid):
        raise InvalidInputError(f"grid must be an astar.OccupancyGrid, got {type(value).__name__}")
    return value


def from_polygons(
    polygons: Sequence[object], resolution: float, bounds: Sequence[float]
) -> OccupancyGrid:
    """Return :meth:`OccupancyGrid.from_polygons` ``(polygons, resolution, bounds)``.

    The conservative, exact rasterisation of polygon obstacles (m); see the method for the
    parameters, the rule and the errors.
    """
    return OccupancyGrid.from_polygons(polygons, resolution, bounds)
