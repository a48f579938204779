"""Corridors of convex polygons grown around a path in continuous space.

A :class:`PolygonCorridor` is a chain of convex polygons (:class:`ConvexPolygon`, world
metres, half-planes ``A @ p <= b``) that covers a path and keeps a clearance ``radius``
from the *raw* map: from every occupied cell taken as a closed square and from the outside
of the map. Unlike the axis-aligned boxes of :mod:`trajopt.corridor`, the polygons are not
made of cells: in a diagonal street they are long rotated regions, and consecutive ones
overlap along a stretch of the path rather than in a sliver.

Contract for certified clearance
--------------------------------
The set of robot centres that touch an occupied square ``Q`` is ``Q`` dilated by a disk of
radius ``r`` (a rounded square). A half-plane ``a . p <= b`` with ``|a| = 1`` keeps every
point at least ``r`` from ``Q`` exactly when ``b <= min over Q's four corners of a . c - r``.
Every obstacle row of a polygon is built with equality there, so every polygon keeps
``r`` from every square by construction. :func:`build_polygon_corridor` does not rely on
that: it *certifies* every region after growing it with the exact distance from the
polygon to every occupied square within reach and to the outside of the map
(:func:`polygon_clearance` computes the same distance for any polygon), and raises rather
than return a region closer than ``radius - CLEARANCE_TOL_M``.

Growth (segment-ellipse method)
-------------------------------
1. **Path preparation.** The path points (cell centres of an A* path, or world points) are
   checked: every point and every segment between consecutive points must keep ``radius``
   from the raw map. Interior points closer than ``radius + centre_trigger_cells`` to an
   obstacle are then pushed away from their nearest obstacle point (two passes; each move
   is the step of ``centre_cells``, half or a quarter of it that raises the point's
   clearance most, and is kept only when both adjacent segments keep ``radius``), because
   an A* path hugs the inflated walls and a seed touching a dilated obstacle cannot grow
   past it. The path is then simplified greedily: a segment replaces the points it skips
   only if it keeps at least the clearance of the points and segments it replaces (capped
   at ``radius + open_cells``, less ``simplify_slack_cells``, never below ``radius``) and
   is at most ``max_segment_cells`` long. The result is the corridor's ``path``.
2. **Seeds.** Region ``k`` is grown around segment ``k`` of that path, extended by up to
   ``overlap_cells`` into the previous and next segments (the extension is halved, then
   dropped, while the seed's convex hull comes closer than ``radius`` to an obstacle).
   Consecutive regions both contain the extension around their shared vertex, so they
   overlap along at least that stretch of the path.
3. **Half-planes.** The obstacle rectangles (maximal runs of occupied cells merged across
   rows) near the seed are taken in order of their distance from the seed segment's
   midpoint in the metric of an ellipse centred there: semi-axis ``L / 2 + e + 0.5`` cells
   along the segment (``L`` its length, ``e`` its larger seed extension) and ``min(that,
   max(0.5, c))`` across, ``c`` the segment's distance to the nearest rectangle (cells).
   Each rectangle not yet excluded adds the half-plane tangent to its ``r``-dilation whose
   normal is the ellipse's gradient at the rectangle's nearest point; when that line would
   cut the seed, the normal is the direction of the closest pair between the seed hull and
   the rectangle instead (a separating direction, which exists since the seed keeps
   ``radius``). Every rectangle the new half-plane already keeps ``r`` away is dropped. A
   window (the seed's bounding box grown by ``margin_cells``, inside the map shrunk by
   ``r``) closes the region.

Degenerate regions
------------------
Where the free space of the robot centre has no interior (a passage exactly ``2 r``
wide, a door exactly ``2 r`` wide), the half-planes leave a segment (the clipped polygon
has fewer than 3 vertices or an area of at most 1e-9 square cells). Such a region is kept
as a *degenerate* :class:`ConvexPolygon`: its ``vertices`` are the two ends of its seed
segment, its first two rows state the segment's line as two opposite inequalities and
the other two are end caps (:attr:`ConvexPolygon.line` gives the line as one equality,
which a QP should use instead of the two opposite rows). Its overlaps with its neighbours
may be a single point (the shared path vertex).

Modules: :mod:`~trajopt.corridor._polygons.regions` (the values),
:mod:`~trajopt.corridor._polygons.build` (:func:`build_polygon_corridor`),
:mod:`~trajopt.corridor._polygons.reuse` (a re-plan's corridor that keeps a previous
corridor's regions along the path the two share),
:mod:`~trajopt.geometry._obstacle_index` (obstacles as rectangles, with exact
distance queries), and the compiled kernels :mod:`~trajopt.corridor._polygons.path_kernels`
and :mod:`~trajopt.corridor._polygons.region_kernels`. :func:`polygon_clearance` is
:func:`trajopt.geometry._clearance.polygon_clearance`.
"""
