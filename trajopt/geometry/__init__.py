"""Geometry the other stages share: curves, B-splines, curvature bounds, hulls, exact clearance.

* :class:`ParametricCurve` (arc length, heading, curvature of any planar curve),
  :class:`PolylineCurve` and :class:`CurveSegment`;
* :class:`BSplineCurve`, the smoother's curve (:meth:`BSplineCurve.pose_at_s`: positions and
  headings at arc lengths, compiled: :func:`arc_pose`);
* :func:`kappa_bound`: a certified upper bound of a curve's curvature on an interval;
* :func:`polygon_clearance`, :func:`polyline_clearance`: exact distances from the raw map
  (occupied cells taken as closed squares); :func:`derive_blocks`: the occupied blocks these
  search, for a map changed in a window, from the unchanged map's;
* :func:`convex_hull`;
* :func:`length_unit`: the length unit the corridor and the smoother count in;
* :func:`rounded_polygon`: the outline of a convex polygon rounded by a radius (a mover's shape).
"""

from trajopt.geometry._bspline import (
    BSplineCurve,
    arc_pose,
    clamped_uniform_knots,
    concatenate,
    derivative_control_points,
)
from trajopt.geometry._clearance import (
    box_clearance,
    derive_blocks,
    grid_cells,
    min_points_clearance,
    point_segment_distance,
    point_square_dist2,
    points_clearance,
    polygon_clearance,
    polygon_rect_closest,
    polygon_rects_distance,
    polyline_clearance,
    segment_rect_distance,
)
from trajopt.geometry._convex_hull import convex_hull, monotone_chain, sort_xy
from trajopt.geometry._curvature_bound import (
    MAX_DEPTH,
    MAX_WORK,
    TIP_M,
    TIP_RTOL,
    ZERO_SPEED_RATIO,
    interval_kappa_max,
    interval_steer_cap,
    kappa_bound,
)
from trajopt.geometry._curve import (
    STILL_SPEED_RATIO,
    CurveSegment,
    ParametricCurve,
    PolylineCurve,
    ShiftedCurve,
    signed_curvature,
)
from trajopt.geometry._length_unit import length_unit
from trajopt.geometry._obstacle_index import (
    BUCKET_CELLS,
    ObstacleIndex,
    gather,
    point_nearest,
    poly_clearance,
    seg_clearance,
)
from trajopt.geometry._rounded_polygon import rounded_polygon

__all__ = [
    "BSplineCurve",
    "BUCKET_CELLS",
    "CurveSegment",
    "MAX_DEPTH",
    "MAX_WORK",
    "ObstacleIndex",
    "ParametricCurve",
    "PolylineCurve",
    "STILL_SPEED_RATIO",
    "ShiftedCurve",
    "TIP_M",
    "TIP_RTOL",
    "ZERO_SPEED_RATIO",
    "arc_pose",
    "box_clearance",
    "clamped_uniform_knots",
    "concatenate",
    "convex_hull",
    "derive_blocks",
    "derivative_control_points",
    "gather",
    "grid_cells",
    "interval_kappa_max",
    "interval_steer_cap",
    "kappa_bound",
    "length_unit",
    "min_points_clearance",
    "monotone_chain",
    "point_nearest",
    "point_segment_distance",
    "point_square_dist2",
    "points_clearance",
    "poly_clearance",
    "polygon_clearance",
    "polygon_rect_closest",
    "polygon_rects_distance",
    "polyline_clearance",
    "rounded_polygon",
    "seg_clearance",
    "segment_rect_distance",
    "signed_curvature",
    "sort_xy",
]
