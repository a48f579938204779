"""Occupancy grids, map formats, exact inflation and octile-optimal A*.

Public names are imported lazily (PEP 562), so ``import astar`` is cheap and the
compiled search kernel (numba) is loaded only when a search runs.
"""

from __future__ import annotations

import importlib
import logging
from typing import TYPE_CHECKING, Any

logging.getLogger(__name__).addHandler(logging.NullHandler())

__version__ = "0.1.0"

_EXPORTS: dict[str, str] = {
    # values and errors
    "OccupancyGrid": "astar.grid",
    "from_polygons": "astar.grid",
    "bodies_distance": "astar.body_polygons",
    "points_distance": "astar.body_polygons",
    "AstarError": "astar.errors",
    "InvalidInputError": "astar.errors",
    "MapFormatError": "astar.errors",
    "NoPathError": "astar.errors",
    # map formats
    "load_map": "astar.io",
    "save_map": "astar.io",
    "from_intensity": "astar.io",
    "read_scenarios": "astar.movingai",
    "read_map_values": "astar.ros_map",
    # costmaps
    "Costmap": "astar.costmap",
    "from_costmap": "astar.costmap",
    "load_costmap": "astar.costmap",
    "Scenario": "astar.movingai",
    # inflation
    "inflate": "astar.inflation",
    "clearance": "astar.inflation",
    "avoidance_area": "astar.inflation",
    "clearance_cost": "astar.inflation",
    # search
    "find_path": "astar.search",
    "GridPath": "astar.search",
    "Landmarks": "astar.landmarks",
    "build_landmarks": "astar.landmarks",
    "CoarseGrid": "astar.coarse_to_fine",
    "CoarsePath": "astar.coarse_to_fine",
    "build_coarse_grid": "astar.coarse_to_fine",
    "find_path_coarse_to_fine": "astar.coarse_to_fine",
    # car-like robots: Hybrid-A* over (x, y, heading), Reeds-Shepp and Dubins paths
    "find_pose_path": "astar.hybrid",
    "PosePath": "astar.hybrid",
    "NoPosePathError": "astar.hybrid",
    "HybridMotion": "astar.hybrid_options",
    "HybridCosts": "astar.hybrid_options",
    "HybridLimits": "astar.hybrid_options",
    "HybridCollision": "astar.hybrid_options",
    "Escape": "astar.escape",
    "NoEscapeError": "astar.escape",
    "find_escape": "astar.escape",
    "join_escape": "astar.escape",
    "reversed_pieces": "astar.escape",
    "CarPath": "astar.reeds_shepp",
    "reeds_shepp_path": "astar.reeds_shepp",
    "dubins_path": "astar.reeds_shepp",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'astar' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


if TYPE_CHECKING:  # pragma: no cover
    from astar.body_polygons import bodies_distance, points_distance
    from astar.coarse_to_fine import (
        CoarseGrid,
        CoarsePath,
        build_coarse_grid,
        find_path_coarse_to_fine,
    )
    from astar.costmap import Costmap, from_costmap, load_costmap
    from astar.errors import AstarError, InvalidInputError, MapFormatError, NoPathError
    from astar.escape import (
        Escape,
        NoEscapeError,
        find_escape,
        join_escape,
        reversed_pieces,
    )
    from astar.grid import OccupancyGrid, from_polygons
    from astar.hybrid import NoPosePathError, PosePath, find_pose_path
    from astar.hybrid_options import HybridCollision, HybridCosts, HybridLimits, HybridMotion
    from astar.inflation import avoidance_area, clearance, clearance_cost, inflate
    from astar.io import from_intensity, load_map, save_map
    from astar.landmarks import Landmarks, build_landmarks
    from astar.movingai import Scenario, read_scenarios
    from astar.reeds_shepp import CarPath, dubins_path, reeds_shepp_path
    from astar.ros_map import read_map_values
    from astar.search import GridPath, find_path
