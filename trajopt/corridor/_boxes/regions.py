"""The box corridor's values.

:class:`Box` (an axis-aligned box of free cells, or a 45-degree bridge) and :class:`Corridor`
(the chain of boxes around a path).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from trajopt.validation import readonly


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
                [
                    [self.xmin, self.ymin],
                    [self.xmax, self.ymin],
                    [self.xmax, self.ymax],
                    [self.xmin, self.ymax],
                ]
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

    @property
    def unit_m(self) -> float:
        """The length unit the smoother counts in (m): the cell side (boxes are cells)."""
        return self.resolution

    def __post_init__(self) -> None:
        object.__setattr__(self, "boxes", tuple(self.boxes))
        object.__setattr__(self, "path_ranges", readonly(self.path_ranges, np.int64))
        for name in ("transitions_m", "overlap_start_m", "overlap_end_m", "path_s"):
            object.__setattr__(self, name, readonly(getattr(self, name), float))
        object.__setattr__(self, "path_points", readonly(self.path_points, float))
        lo = np.array([[b.xmin, b.ymin] for b in self.boxes], dtype=float).reshape(-1, 2)
        hi = np.array([[b.xmax, b.ymax] for b in self.boxes], dtype=float).reshape(-1, 2)
        inf = np.inf
        dlo = np.array(
            [
                [-inf, -inf] if b.diagonal is None else [b.diagonal[0], b.diagonal[2]]
                for b in self.boxes
            ],
            dtype=float,
        ).reshape(-1, 2)
        dhi = np.array(
            [
                [inf, inf] if b.diagonal is None else [b.diagonal[1], b.diagonal[3]]
                for b in self.boxes
            ],
            dtype=float,
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
        """Lower bounds ``(smin, dmin)`` on ``x + y`` and ``x - y`` (m), shape (m, 2).

        ``-inf`` for axis-aligned boxes.
        """
        return self._dlo

    @property
    def diag_upper(self) -> np.ndarray:
        """Upper bounds ``(smax, dmax)`` on ``x + y`` and ``x - y`` (m), shape (m, 2).

        ``+inf`` for axis-aligned boxes.
        """
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
