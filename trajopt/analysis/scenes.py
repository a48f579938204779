"""Built-in scenes: the chapter's setting as a value (:func:`paper`), and the warm-up map.

A :class:`Scene` bundles a raw occupancy grid, a start point, named targets (world
metres) and the robot size the chapter uses. Scenes are built by code, not read from data
files, so every demo, test and benchmark can start from the same setting.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import TYPE_CHECKING

import numpy as np

from astar.grid import OccupancyGrid
from trajopt.errors import InvalidInputError

if TYPE_CHECKING:  # pragma: no cover
    from trajopt import Planner

__all__ = ["Scene", "paper", "PAPER_OBSTACLES_CELLS", "WARM_UP_CELLS", "warm_up_map"]

#: The paper scene's square obstacles as ``(ix0, iy0, side_cells)``: the square covers
#: cells ``ix0 .. ix0 + side - 1`` and ``iy0 .. iy0 + side - 1`` (0.03 m cells).
PAPER_OBSTACLES_CELLS: tuple[tuple[int, int, int], ...] = (
    (70, 20, 20),  # O1 [2.1, 2.7] x [0.6, 1.2] m: across the line SP -> A, B behind it
    (90, 80, 20),  # O2 [2.7, 3.3] x [2.4, 3.0] m: C lies to its right
    (120, 110, 20),  # O3 [3.6, 4.2] x [3.3, 3.9] m: C lies under it
    (30, 80, 30),  # O4 [0.9, 1.8] x [2.4, 3.3] m: D lies above it, behind the left channel
    (80, 130, 20),  # O5 [2.4, 3.0] x [3.9, 4.5] m: against the top wall
)


@dataclass(frozen=True, slots=True)
class Scene:
    """A planning setting: raw map, start, named targets and robot size.

    Attributes
    ----------
    name : str
        Scene name.
    grid : astar.OccupancyGrid
        The raw map (obstacles only, no inflation).
    start : tuple of float
        Start point ``(x, y)`` in metres.
    targets : Mapping[str, tuple of float]
        Target name -> ``(x, y)`` in metres (read-only mapping).
    robot_width : float
        Robot width in metres (its radius is half of it).
    w_cells : int
        The chapter's avoidance-area width ``W`` in cells (rounds of 8-neighbour marking).
    obstacles : tuple of tuple of float
        The obstacle squares ``(x0, y0, side)`` in metres (documentation; the grid is the
        truth).
    description : str
        How the scene was built.
    """

    name: str
    grid: OccupancyGrid
    start: tuple[float, float]
    targets: Mapping[str, tuple[float, float]]
    robot_width: float
    w_cells: int
    obstacles: tuple[tuple[float, float, float], ...] = ()
    description: str = ""

    def __post_init__(self) -> None:
        if not isinstance(self.grid, OccupancyGrid):
            raise InvalidInputError(
                f"grid must be an astar.OccupancyGrid, got {type(self.grid).__name__}"
            )
        object.__setattr__(self, "start", _xy(self.start, "start"))
        targets = {str(k): _xy(v, f"targets[{k!r}]") for k, v in dict(self.targets).items()}
        object.__setattr__(self, "targets", MappingProxyType(targets))
        width = float(self.robot_width)
        if not (math.isfinite(width) and width > 0):
            raise InvalidInputError(f"robot_width must be finite and > 0 m, got {width!r}")
        object.__setattr__(self, "robot_width", width)
        if isinstance(self.w_cells, bool) or int(self.w_cells) != self.w_cells or self.w_cells < 0:
            raise InvalidInputError(f"w_cells must be an integer >= 0, got {self.w_cells!r}")
        object.__setattr__(self, "w_cells", int(self.w_cells))
        object.__setattr__(
            self, "obstacles", tuple(tuple(float(v) for v in o) for o in self.obstacles)
        )

    @property
    def robot_radius(self) -> float:
        """Half the robot width (m)."""
        return 0.5 * self.robot_width

    @property
    def target_names(self) -> tuple[str, ...]:
        """Target names in definition order."""
        return tuple(self.targets)

    def goal(self, name: str) -> tuple[float, float]:
        """World ``(x, y)`` (m) of target ``name``."""
        try:
            return self.targets[name]
        except KeyError:
            raise InvalidInputError(
                f"target name must be one of {list(self.targets)}, got {name!r}"
            ) from None

    def cell(self, xy: tuple[float, float]) -> tuple[int, int]:
        """Cell ``(ix, iy)`` holding world point ``xy`` (m)."""
        c = self.grid.world_to_cell(xy)
        return int(c[0]), int(c[1])

    @property
    def start_cell(self) -> tuple[int, int]:
        """Cell ``(ix, iy)`` of the start point."""
        return self.cell(self.start)

    def goal_cell(self, name: str) -> tuple[int, int]:
        """Cell ``(ix, iy)`` of target ``name``."""
        return self.cell(self.goal(name))


def _xy(value: object, name: str) -> tuple[float, float]:
    try:
        x, y = (float(v) for v in value)  # type: ignore[union-attr]
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(
            f"{name} must be two numbers (x, y) in metres, got {value!r}"
        ) from exc
    if not (math.isfinite(x) and math.isfinite(y)):
        raise InvalidInputError(f"{name} must be finite, got ({x}, {y})")
    return (x, y)


def paper() -> Scene:
    """Return the chapter's setting, reconstructed: 4.5 m x 4.5 m room, square obstacles, SP, A-D.

    The chapter gives the grid (150 x 150 cells of 0.03 m, origin (0, 0)), the robot
    (width 0.33 m, so ``W = 0.33 / 0.03 = 11`` cells of avoidance area), a start point SP
    near the lower-left corner and four targets A-D, but not its exact obstacle layout. This
    reconstruction follows its Figures 7-11:

    * **Obstacles**: five squares (:data:`PAPER_OBSTACLES_CELLS`), O1 [2.1, 2.7] x [0.6, 1.2],
      O2 [2.7, 3.3] x [2.4, 3.0], O3 [3.6, 4.2] x [3.3, 3.9], O4 [0.9, 1.8] x [2.4, 3.3]
      (the big one) and O5 [2.4, 3.0] x [3.9, 4.5] (on the top wall), all in metres and on
      cell boundaries. Every gap a route uses is wider than ``2 W`` cells plus the passage.
    * **SP = (0.5, 0.5)**, 0.5 m from both walls.
    * **A = (3.9, 1.2)**: level with O1's top face. O1 sits across the straight line
      SP -> A; the gap below it is closed by the avoidance area, so the path climbs
      diagonally over O1 and comes down to A: only 45-degree turns, and x increases all
      the way (``y = f(x)`` works; the sweeps are tuned here).
    * **B = (3.2, 0.7)**: tucked behind O1 (0.5 m from its right face, near the floor). The
      raw shortest path slips under O1; with the avoidance area the path must go over O1
      and drop steeply behind it.
    * **C = (3.8, 2.85)**: in the pocket between O2 (0.5 m to its left) and O3 (0.45 m above).
    * **D = (1.35, 3.8)**: above O4. The shortest route climbs the 0.9 m channel between the
      left wall and O4 (a vertical section) and turns sharply right over O4's top-left corner;
      x stays constant over the climb, so ``y = f(x)`` fails there.

    Start and targets are free in the chapter's avoidance area (``W = 11``, border as
    obstacle) and in the exact inflation by the robot radius 0.165 m (both the centre and
    the square metric), and every target is reachable from SP in all of them (checked by
    the tests).

    Returns
    -------
    Scene
    """
    res = 0.03
    n = 150
    occ = np.zeros((n, n), dtype=bool)
    obstacles = []
    for ix0, iy0, side in PAPER_OBSTACLES_CELLS:
        occ[iy0 : iy0 + side, ix0 : ix0 + side] = True
        obstacles.append((round(ix0 * res, 10), round(iy0 * res, 10), round(side * res, 10)))
    grid = OccupancyGrid(occ, res, (0.0, 0.0))
    return Scene(
        name="paper",
        grid=grid,
        start=(0.5, 0.5),
        targets={"A": (3.9, 1.2), "B": (3.2, 0.7), "C": (3.8, 2.85), "D": (1.35, 3.8)},
        robot_width=0.33,
        w_cells=11,
        obstacles=tuple(obstacles),
        description=(
            "Reconstruction of the chapter's scene: 150 x 150 cells of 0.03 m, five square "
            "obstacles, SP near the lower-left corner; A without tight turns, B and C close "
            "to obstacles, D behind a vertical channel and a sharp turn."
        ),
    )


#: side of the warm-up map in cells
WARM_UP_CELLS = 60


def warm_up_map(planner: Planner) -> tuple[OccupancyGrid, tuple[float, float], tuple[float, float]]:
    """Return the warm-up map for ``planner`` and its query.

    Parameters
    ----------
    planner : Planner
        Its robot's (circumscribed) radius and its smoother's curvature bound set the
        map's scale.

    Returns
    -------
    grid : astar.OccupancyGrid
        ``WARM_UP_CELLS`` square cells, side ``12 * max(radius, 1 / kappa_max)`` metres
        (three radii with ``inflation="paper"``),
        with a wall up from the bottom edge over 60 % of the height in the middle and a
        block 1.6 radii left of the start (so the clearance checks meet an obstacle).
    start, goal : tuple of float
        World points (m) on either side of the wall, ``0.2`` of the side from the
        bottom and from the left and right edges.
    """
    scale = planner.robot.radius
    if planner.inflation == "paper":  # the avoidance area adds about 2 radii
        scale *= 3.0
    if planner.smoother.kappa_max is not None:
        scale = max(scale, 1.0 / planner.smoother.kappa_max)
    n = WARM_UP_CELLS
    resolution = 12.0 * scale / n
    occupied = np.zeros((n, n), dtype=bool)
    half = max(1, math.ceil(0.05 * n))
    occupied[: int(0.6 * n), n // 2 - half : n // 2 + half] = True
    occupied[int(0.17 * n) : int(0.23 * n), int(0.03 * n) : int(0.07 * n)] = True  # near the start
    side = n * resolution
    return OccupancyGrid(occupied, resolution), (0.2 * side, 0.2 * side), (0.8 * side, 0.2 * side)
