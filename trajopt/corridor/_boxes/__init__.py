"""Safe corridors: overlapping axis-aligned boxes of free cells grown around a grid path.

A :class:`Corridor` is the convex decomposition of free space that the smoother uses to
certify clearance: every span of the B-spline keeps its control points inside one box, so
(by the convex-hull property) the whole continuous curve lies inside the union of boxes.

Contract for certified clearance
--------------------------------
To certify a clearance ``r`` (metres) from the *raw* map, two things are needed together:

1. the grid given to :func:`build_corridor` must be
   ``astar.inflate(raw, r, metric="square", outside_occupied=True)``: a cell is blocked
   when its centre is closer than ``r`` to an occupied cell taken as a *square* (and the
   outside of the map counts as occupied);
2. every box of free cells is shrunk to the rectangle spanned by its cell *centres*
   (half a cell per side), which :func:`build_corridor` always does.

Then any point of a shrunk box is at least ``r`` from every occupied square: for an
occupied square ``Q`` outside the box, the box's cell centre nearest to ``Q`` along each
axis is no farther from ``Q`` on either axis than the point, and that centre is free, so
its distance to ``Q`` is ``>= r``. With centre-to-centre inflation, or without the
shrink, the curve can cut obstacle corners (see ``docs/concepts.md``).

Modules: :mod:`~trajopt.corridor._boxes.regions` (the values), :mod:`~trajopt.corridor._boxes.build`
(:func:`build_corridor`), :mod:`~trajopt.corridor._boxes.growth` (growing the boxes) and
:mod:`~trajopt.corridor._boxes.bridges` (45-degree bridges).
"""
