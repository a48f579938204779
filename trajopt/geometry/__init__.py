"""Geometry the other stages share: curves, B-splines, curvature bounds, hulls, exact clearance.

* :class:`ParametricCurve` (arc length, heading, curvature of any planar curve),
  :class:`PolylineCurve` and :class:`CurveSegment`;
* :class:`BSplineCurve`, the smoother's curve;
* :func:`kappa_bound`: a certified upper bound of a curve's curvature on an interval;
* :func:`polygon_clearance`, :func:`polyline_clearance`: exact distances from the raw map
  (occupied cells taken as closed squares);
* :func:`convex_hull`;
* :func:`length_unit`: the length unit the corridor and the smoother count in.
"""

from trajopt.geometry._bspline import BSplineCurve
from trajopt.geometry._clearance import polygon_clearance, polyline_clearance
from trajopt.geometry._convex_hull import convex_hull
from trajopt.geometry._curvature_bound import kappa_bound
from trajopt.geometry._curve import CurveSegment, ParametricCurve, PolylineCurve
from trajopt.geometry._length_unit import length_unit

__all__ = [
    "BSplineCurve",
    "CurveSegment",
    "ParametricCurve",
    "PolylineCurve",
    "convex_hull",
    "kappa_bound",
    "length_unit",
    "polygon_clearance",
    "polyline_clearance",
]
