"""Corridors: chains of convex regions around a path that certify a clearance from the raw map.

Two kinds, with the same role for the smoother (every span of the curve keeps its control
points in one region, so by the convex-hull property the whole curve stays in the union):

* :class:`PolygonCorridor` of :class:`ConvexPolygon` (:func:`build_polygon_corridor`, the
  default): regions grown in continuous space around the path, certified by the exact
  distance to every occupied square (contract in :mod:`trajopt.corridor._polygons`);
* :class:`Corridor` of :class:`Box` (:func:`build_corridor`): axis-aligned boxes of free
  cells of the inflated grid (contract in :mod:`trajopt.corridor._boxes`).
"""

from trajopt.corridor._boxes.bridges import rotated_rect_clearance
from trajopt.corridor._boxes.build import build_corridor
from trajopt.corridor._boxes.regions import Box, Corridor
from trajopt.corridor._polygons.build import build_polygon_corridor
from trajopt.corridor._polygons.regions import CLEARANCE_TOL_M, ConvexPolygon, PolygonCorridor
from trajopt.corridor._polygons.reuse import corridor_with_rest

__all__ = [
    "Box",
    "CLEARANCE_TOL_M",
    "ConvexPolygon",
    "Corridor",
    "PolygonCorridor",
    "build_corridor",
    "build_polygon_corridor",
    "corridor_with_rest",
    "rotated_rect_clearance",
]
