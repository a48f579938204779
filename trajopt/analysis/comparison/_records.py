"""What the comparison methods share and return.

:class:`ComparisonContext` (built once per :func:`trajopt.compare` call) and
:class:`MethodResult`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import numpy as np

from astar.grid import OccupancyGrid


@dataclass(frozen=True, slots=True)
class MethodResult:
    """What a method returns when it has more to say than the path.

    Attributes
    ----------
    path : ParametricCurve or ndarray (n, 2) or None
        The path (metres); ``None`` when the method produced none (metrics are NaN).
    valid : bool
        ``False`` when the method's own validity test failed (shown in the table).
    note : str
        Free text for the table (why invalid, parameters used, ...).
    runtime_s : float or None
        Overrides the measured wall time (e.g. the A* rows report the search time).
    extras : Mapping[str, Any]
        Extra columns for this row (e.g. ``fit_mse_m2``: equation (3) at the parameters
        the fit used); other rows show them empty.
    """

    path: Any
    valid: bool = True
    note: str = ""
    runtime_s: float | None = None
    extras: Mapping[str, Any] = field(default_factory=dict)


@dataclass(frozen=True, slots=True)
class ComparisonContext:
    """Everything the methods share, computed once per :func:`compare` call.

    Attributes
    ----------
    grid : astar.OccupancyGrid
        The raw map.
    start, goal : tuple of float
        World points (m).
    start_cell, goal_cell : tuple of int
        Their cells ``(ix, iy)``.
    robot_radius : float
        Robot radius (m).
    w_cells : int
        Avoidance-area width ``W`` (cells).
    border_occupied : bool
        Whether the map border counts as an obstacle (avoidance area, inflation, clearance).
    avoidance : astar.OccupancyGrid
        :func:`astar.avoidance_area` of ``grid`` with ``W = w_cells``.
    inflated : astar.OccupancyGrid
        :func:`astar.inflation` of ``grid`` by ``robot_radius`` with ``metric="square"``.
    path_raw, path_avoid : astar.GridPath
        A* on the raw grid and on the avoidance area.
    reference : ndarray, shape (n, 2)
        Cell centres of ``path_avoid`` (m): what the fits fit and the metrics compare to.
    options : Mapping[str, Mapping[str, Any]]
        Per-method options (read with :meth:`options_for`).
    timings : Mapping[str, float]
        Wall times (s) of the shared steps (``'astar_raw'``, ``'astar_avoid'``, ...).
    """

    grid: OccupancyGrid
    start: tuple[float, float]
    goal: tuple[float, float]
    start_cell: tuple[int, int]
    goal_cell: tuple[int, int]
    robot_radius: float
    w_cells: int
    border_occupied: bool
    avoidance: OccupancyGrid
    inflated: OccupancyGrid
    path_raw: Any
    path_avoid: Any
    reference: np.ndarray
    options: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)
    timings: Mapping[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        ref = np.array(self.reference, dtype=float)
        ref.flags.writeable = False
        object.__setattr__(self, "reference", ref)
        opts = {str(k): MappingProxyType(dict(v)) for k, v in dict(self.options).items()}
        object.__setattr__(self, "options", MappingProxyType(opts))
        object.__setattr__(self, "timings", MappingProxyType(dict(self.timings)))

    def options_for(self, name: str) -> dict[str, Any]:
        """Return a fresh dict of the options given for method ``name`` (empty when none)."""
        return dict(self.options.get(name, {}))

    def points(self, grid_path: Any) -> np.ndarray:
        """Cell centres (m) of an :class:`astar.GridPath`, shape (n, 2)."""
        return self.grid.cell_to_world(np.asarray(grid_path.cells))


MethodFn = Callable[[ComparisonContext], Any]
