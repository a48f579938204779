"""The length unit the corridor and the smoother count in (:func:`length_unit`).

The polygon corridor's sizes (seed lengths, growth margins, simplification tolerances) and
the smoother's (knot spans, path samples, certificate samples, weights) are counted in one
length unit. It is the map's cell size, except on maps whose cells are finer than the robot
needs: there it is a fixed fraction of the robot's radius, so that the same query on the
same site gives nearly the same curve at nearly the same cost whatever the resolution. The
cells still decide where obstacles are: every certificate stays exact against the raw map's
squares.
"""

from __future__ import annotations

import math

#: On maps whose cells are finer than ``radius / UNITS_PER_RADIUS``, the length unit is
#: ``radius / UNITS_PER_RADIUS``: a knot span of 4 units is then two thirds of the radius,
#: short enough to follow gaps of one robot width (12 units), and the corridor's seeds of
#: 20 units are about three radii long.
UNITS_PER_RADIUS = 4.0


def length_unit(resolution: float, radius: float | None) -> float:
    """Return the length unit (m) of a corridor on a map of cell size ``resolution``.

    Parameters
    ----------
    resolution : float
        The map's cell side (m), > 0.
    radius : float or None
        The clearance the corridor keeps (m); ``None`` or 0: the unit is the cell.

    Returns
    -------
    float
        ``max(resolution, radius / UNITS_PER_RADIUS)`` (m).

    Examples
    --------
    >>> length_unit(0.05, 0.2)   # cells as coarse as radius / 4: the cell
    0.05
    >>> round(length_unit(0.01, 0.3), 6)   # 1 cm cells, 30 cm radius: 7.5 cm units
    0.075
    """
    res = float(resolution)
    if radius is None or not math.isfinite(float(radius)):
        return res
    return max(res, float(radius) / UNITS_PER_RADIUS)
