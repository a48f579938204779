"""Nav2 / costmap_2d costmaps as obstacles plus a graded search cost.

A costmap says two things per cell: whether the robot centre may be there at all (lethal,
and optionally inscribed and unknown cells) and how much the planner should avoid it (the
graded cost that ``inflation_layer`` spreads around obstacles). :class:`Costmap` keeps them
apart: :attr:`Costmap.grid` is an :class:`~astar.grid.OccupancyGrid` of the obstacle cells
(what ``trajopt`` inflates by the robot radius and certifies against, exactly as for any
map), and :attr:`Costmap.cost` is the graded cost normalised to ``[0, 1]``, which
:meth:`Costmap.search_cost` turns into a per-cell cost for :func:`astar.find_path`.

Two value conventions exist and the caller names one (it is never guessed):

``"costmap_2d"``
    The costmap's own ``uint8`` cells: ``0`` free, ``1..252`` graded, ``253`` inscribed
    (``INSCRIBED_INFLATED_OBSTACLE``), ``254`` lethal (``LETHAL_OBSTACLE``), ``255`` unknown
    (``NO_INFORMATION``). The normalised cost of a graded cell is ``value / 252``.
``"occupancy_grid"``
    A costmap published as ``nav_msgs/OccupancyGrid`` (``int8``): Nav2's publisher maps
    ``0 -> 0``, ``253 -> 99``, ``254 -> 100``, ``255 -> -1`` and a graded ``c`` in
    ``1..252`` to ``1 + floor(97 (c - 1) / 251)`` in ``1..98``. The normalised cost of a
    graded value ``v`` is that of the smallest ``c`` published as ``v``, i.e.
    ``(1 + ceil(251 (v - 1) / 97)) / 252``, so the two conventions agree to one bucket
    (at most ``3 / 252``).

How this relates to Nav2's ``inflation_layer``: beyond the inscribed radius ``r_i`` a cell
at distance ``d`` from the nearest lethal cell gets
``252 exp(-cost_scaling_factor (d - r_i))`` up to ``inflation_radius`` and 0 beyond, so
the normalised cost is ``exp(-cost_scaling_factor (d - r_i))``. The search cost of a step
here is its length times ``1 + weight * mean normalised cost of its two cells`` (the form of
Nav2's Smac 2D planner with ``cost_travel_multiplier = weight``): a larger
``cost_scaling_factor`` makes the cost fall off faster, so paths may pass closer to walls;
a larger ``weight`` trades length for distance from what the costmap marks as costly.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import numpy as np

from astar import validation
from astar.errors import InvalidInputError, MapFormatError
from astar.grid import OccupancyGrid
from astar.ros_map import read_map_values

__all__ = ["Costmap", "CostmapConvention", "from_costmap", "load_costmap"]

CostmapConvention = Literal["occupancy_grid", "costmap_2d"]
_CONVENTIONS: tuple[str, ...] = ("occupancy_grid", "costmap_2d")

#: costmap_2d's reserved values.
MAX_NON_OBSTACLE = 252
INSCRIBED = 253
LETHAL = 254
NO_INFORMATION = 255
#: The same classes after Nav2's translation to ``nav_msgs/OccupancyGrid``.
OG_INSCRIBED = 99
OG_LETHAL = 100
OG_UNKNOWN = -1


@dataclass(frozen=True, slots=True)
class Costmap:
    """Obstacles and graded cost of a costmap (see the module docstring).

    Attributes
    ----------
    grid : OccupancyGrid
        The obstacle cells, shape ``(ny, nx)``: lethal cells, plus inscribed and unknown
        cells when the loader was asked to count them (:func:`from_costmap`).
    cost : ndarray of float64, shape (ny, nx)
        Normalised graded cost in ``[0, 1]`` (read-only): 0 free, ``c / 252`` graded, 1 for
        inscribed, lethal and unknown cells.
    values : ndarray of int16, shape (ny, nx)
        The cell values as given (read-only), row 0 at the bottom.
    convention : {"occupancy_grid", "costmap_2d"}
        How :attr:`values` is to be read.
    """

    grid: OccupancyGrid
    cost: np.ndarray
    values: np.ndarray
    convention: CostmapConvention

    @property
    def shape(self) -> tuple[int, int]:
        """``(ny, nx)``."""
        return self.grid.shape

    def search_cost(self, weight: float = 2.0) -> np.ndarray:
        """Per-cell cost for :func:`astar.find_path`: ``weight * cost``.

        Parameters
        ----------
        weight : float, optional
            Finite, ``>= 0`` (dimensionless, relative to the step length); with the default
            2 a step through the most costly graded cells costs three times its length.

        Returns
        -------
        ndarray of float64, shape (ny, nx)
        """
        if isinstance(weight, bool) or not isinstance(weight, int | float | np.number):
            raise InvalidInputError(f"weight must be a number >= 0, got {weight!r}")
        w = float(weight)
        if not math.isfinite(w) or w < 0.0:
            raise InvalidInputError(f"weight must be finite and >= 0 (dimensionless), got {w!r}")
        return w * self.cost

    def __repr__(self) -> str:
        ny, nx = self.shape
        return (
            f"Costmap({nx} x {ny} cells of {self.grid.resolution} m, convention="
            f"{self.convention!r}, {int(self.grid.occupied.sum())} obstacle cells)"
        )


def from_costmap(
    values: np.ndarray,
    resolution: float,
    origin: tuple[float, float] = (0.0, 0.0),
    *,
    convention: CostmapConvention,
    inscribed_occupied: bool = False,
    unknown_occupied: bool = True,
) -> Costmap:
    """Return a :class:`Costmap` from an array of costmap cell values.

    Parameters
    ----------
    values : array_like of int, shape (ny, nx)
        Cell values in ``[iy, ix]`` order, row 0 at the bottom (the order of
        ``nav_msgs/OccupancyGrid.data`` reshaped to ``(height, width)``). Integer values
        (or floats holding integers) in the convention's range.
    resolution : float
        Cell size (m), finite and > 0.
    origin : tuple of float, optional
        World ``(x, y)`` (m) of the lower-left corner of cell ``(0, 0)``.
    convention : {"occupancy_grid", "costmap_2d"}
        ``"occupancy_grid"``: ``-1`` or ``0..100``; ``"costmap_2d"``: ``0..255``. Required.
    inscribed_occupied : bool, optional
        Count inscribed cells (costmap_2d 253, OccupancyGrid 99) as obstacles. Default
        ``False``: Nav2 marks them from *its* footprint; ``trajopt`` inflates the lethal
        cells by its own robot radius.
    unknown_occupied : bool, optional
        Count unknown cells as obstacles (default ``True``, as :func:`astar.load_map`).

    Returns
    -------
    Costmap

    Raises
    ------
    InvalidInputError
        An unknown convention, a value outside the convention's range (the message gives the
        first offending cell and value), a non-integer value, a bad shape or resolution.
    """
    if not (isinstance(convention, str) and convention in _CONVENTIONS):
        raise InvalidInputError(
            f"convention must be one of {_CONVENTIONS} (the value encoding of the costmap; "
            f"it is never guessed), got {convention!r}"
        )
    for name, flag in (
        ("inscribed_occupied", inscribed_occupied),
        ("unknown_occupied", unknown_occupied),
    ):
        if not isinstance(flag, bool | np.bool_):
            raise InvalidInputError(f"{name} must be a bool, got {flag!r}")
    v = validation.integer_values(values)
    if convention == "costmap_2d":
        lo, hi, rule = (
            0,
            255,
            "0..255 (0 free, 1..252 graded, 253 inscribed, 254 lethal, 255 unknown)",
        )
    else:
        lo, hi, rule = (
            -1,
            100,
            "-1..100 (-1 unknown, 0 free, 1..98 graded, 99 inscribed, 100 lethal)",
        )
    bad = (v < lo) | (v > hi)
    if np.any(bad):
        iy, ix = (int(i) for i in np.argwhere(bad)[0])
        hint = ""
        if convention == "costmap_2d" and v[iy, ix] < 0:
            hint = " (an int8 view of uint8 costmap cells? pass values.view(np.uint8))"
        raise InvalidInputError(
            f"values[{iy}, {ix}] = {int(v[iy, ix])} is outside the {convention} range {rule}"
            f"{hint}; {int(bad.sum())} cell(s) are out of range"
        )
    if convention == "costmap_2d":
        lethal, inscribed, unknown = v == LETHAL, v == INSCRIBED, v == NO_INFORMATION
        graded = v <= MAX_NON_OBSTACLE
        norm = np.where(graded, v / float(MAX_NON_OBSTACLE), 1.0)
    else:
        lethal, inscribed, unknown = v == OG_LETHAL, v == OG_INSCRIBED, v == OG_UNKNOWN
        graded = (v >= 0) & (v < OG_INSCRIBED)
        # smallest costmap_2d value Nav2 publishes as v (v = 0 -> 0)
        c = np.where(v > 0, 1 + np.ceil(251.0 * (v - 1) / 97.0), 0.0)
        norm = np.where(graded, c / float(MAX_NON_OBSTACLE), 1.0)
    occupied = lethal.copy()
    if inscribed_occupied:
        occupied |= inscribed
    if unknown_occupied:
        occupied |= unknown
    try:
        grid = OccupancyGrid(occupied, resolution, origin)
    except InvalidInputError as exc:
        raise InvalidInputError(f"from_costmap: {exc}") from None
    norm = np.ascontiguousarray(norm, dtype=np.float64)
    norm.flags.writeable = False
    vals = np.array(v, dtype=np.int16)
    vals.flags.writeable = False
    return Costmap(grid=grid, cost=norm, values=vals, convention=convention)  # type: ignore[arg-type]


def load_costmap(
    path: str | os.PathLike[str],
    *,
    inscribed_occupied: bool = False,
    unknown_occupied: bool = True,
) -> Costmap:
    """Read a costmap saved by Nav2's map saver (map_server YAML + image).

    A costmap topic (``nav_msgs/OccupancyGrid``, the ``"occupancy_grid"`` convention) saved
    with ``map_saver_cli -t /global_costmap/costmap --mode raw`` keeps every value: the
    image holds the values ``0..100`` as grey levels and ``255`` for unknown. ``scale``
    files give map_server's intermediate values (``rint(100 (occ - free) / (occupied -
    free))``) and ``trinary`` files only free, lethal and unknown cells (no graded cost);
    both are read with map_server's rules (:func:`astar.read_map_values`).

    Parameters
    ----------
    path : str or os.PathLike
        The YAML file.
    inscribed_occupied, unknown_occupied : bool, optional
        As in :func:`from_costmap`.

    Returns
    -------
    Costmap
        With ``convention == "occupancy_grid"``.

    Raises
    ------
    MapFormatError
        A missing or malformed file (the message names the file, the field and the rule).
    """
    p = Path(path)
    values, resolution, origin, _mode = read_map_values(p)
    try:
        return from_costmap(
            values,
            resolution,
            origin,
            convention="occupancy_grid",
            inscribed_occupied=inscribed_occupied,
            unknown_occupied=unknown_occupied,
        )
    except InvalidInputError as exc:
        raise MapFormatError(f"{p}: {exc}") from None
