"""The outline of a rounded convex polygon: the points within a radius of its hull.

A predicted mover's shape (:class:`trajopt.MovingObstacle`) is such a set: a disc is one
vertex rounded by its radius, a polygon is rounded by its ``radius``. Drawings and
visualisation markers need its outline as a closed polyline.
"""

from __future__ import annotations

import math

import numpy as np

from trajopt.errors import InvalidInputError


def rounded_polygon(vertices: np.ndarray, radius: float, *, arc_points: int = 48) -> np.ndarray:
    """Return the outline (m) of the points within ``radius`` of a convex polygon.

    The boundary of the Minkowski sum of the polygon and a disc: each edge shifted
    outwards by ``radius``, joined by circular arcs about the vertices. Every returned
    point lies at distance exactly ``radius`` from the polygon (up to rounding).

    Parameters
    ----------
    vertices : array_like, shape (m, 2)
        The polygon's vertices in counter-clockwise order (m); one vertex for a disc, two
        for a segment.
    radius : float
        The rounding (m), finite and >= 0; 0 gives the polygon itself.
    arc_points : int
        Points per full turn of the arcs (>= 8); a disc's outline has exactly this many.

    Returns
    -------
    ndarray, shape (k, 2)
        The outline counter-clockwise, not closed (the first point is not repeated).

    Raises
    ------
    InvalidInputError
        ``vertices`` not finite of shape (m, 2), ``radius`` negative or not finite,
        ``arc_points`` not an integer >= 8.
    """
    v = np.asarray(vertices, dtype=float)
    if v.ndim != 2 or v.shape[1] != 2 or v.shape[0] < 1 or not np.all(np.isfinite(v)):
        raise InvalidInputError(
            f"vertices must be a finite array of shape (m, 2), m >= 1, got shape {v.shape}"
        )
    r = float(radius)
    if not (math.isfinite(r) and r >= 0.0):
        raise InvalidInputError(f"radius must be a finite number >= 0 (m), got {radius!r}")
    if isinstance(arc_points, bool) or not isinstance(arc_points, int | np.integer):
        raise InvalidInputError(f"arc_points must be an integer >= 8, got {arc_points!r}")
    if arc_points < 8:
        raise InvalidInputError(f"arc_points must be an integer >= 8, got {arc_points!r}")
    if r == 0.0:
        return v.copy()
    if v.shape[0] == 1:
        a = np.linspace(0.0, 2.0 * math.pi, int(arc_points), endpoint=False)
        return v[0] + r * np.column_stack([np.cos(a), np.sin(a)])
    e = np.roll(v, -1, axis=0) - v  # edge i from vertex i to vertex i + 1
    out_angle = np.arctan2(-e[:, 0], e[:, 1])  # outward normal of a CCW edge: (ey, -ex)
    pts = []
    for i in range(v.shape[0]):
        a0 = out_angle[i - 1]  # the incoming edge's normal
        a1 = out_angle[i]
        turn = (a1 - a0) % (2.0 * math.pi)
        n = max(1, int(math.ceil(turn / (2.0 * math.pi) * arc_points)))
        a = a0 + turn * np.arange(n + 1) / n
        pts.append(v[i] + r * np.column_stack([np.cos(a), np.sin(a)]))
    return np.concatenate(pts)
