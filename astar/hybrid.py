"""Pose-to-pose paths for car-like robots: Hybrid-A* with Reeds-Shepp/Dubins shots.

:func:`find_pose_path` searches (x, y, heading) on a grid of free cells for a path of arcs of
curvature at most ``1 / turning_radius`` from a start pose to a goal pose, forwards and (with
``reverse=True``) backwards, and returns a :class:`PosePath`: poses sampled along it, the
direction of travel at each, the segments between cusps and the exact pieces (arcs and lines)
it is made of. The search itself is :mod:`astar.hybrid_kernel` (Dolgov et al. 2008/2010;
parameters after Nav2 Smac Hybrid-A*), the analytic curves :mod:`astar.reeds_shepp`. Its
settings are four typed records (:mod:`astar.hybrid_options`: :class:`~astar.HybridMotion`,
:class:`~astar.HybridCosts`, :class:`~astar.HybridLimits`, :class:`~astar.HybridCollision`),
or their fields by name.

Units (those of :func:`astar.find_path`): positions, lengths and the turning radius are in
**cells**; a position ``(x, y)`` is a point of the grid in which cell ``(ix, iy)`` is the square
``[ix - 0.5, ix + 0.5) x [iy - 0.5, iy + 0.5)``, its centre at ``(ix, iy)`` (so the integer
cells of :func:`astar.find_path` are points here, and world metres are
``origin + (xy + 0.5) * resolution``: :meth:`PosePath.to_world`). Headings are radians,
counter-clockwise from ``+x`` (row 0 at the bottom, so ``+y`` is up).
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from astar import validation
from astar.errors import InvalidInputError, NoPathError
from astar.grid import OccupancyGrid
from astar.hybrid_assemble import COLLISION_STEP, assemble
from astar.hybrid_modes import kernel_collision
from astar.hybrid_options import (
    AUTO_FIRST_SHARE,
    AUTO_PROBE,
    HybridCollision,
    HybridCosts,
    HybridLimits,
    HybridMotion,
    build_options,
)

__all__ = ["NoPosePathError", "PosePath", "find_pose_path"]

logger = logging.getLogger(__name__)

_DIJKSTRA_SLACK_R = 20.0  # the 2-D distance field reaches 20 R + 50 cells beyond the start
_RETRY_BELOW = 20_000  # an exhausted search this small is retried at a finer resolution
_POLISH = 100  # expansions the search may go on after its first path, besides as many again
_REASONS = ("disconnected", "exhausted", "max_expansions", "time_budget")
_STOPS = ("exhausted", "found", "max_expansions", "time_budget")  # by the kernel's status code


class NoPosePathError(NoPathError):
    """No path of a car-like robot joins the two poses (see :attr:`reason`).

    Attributes
    ----------
    reason : str
        ``"disconnected"`` (start and goal lie in different free regions: refused before the
        search), ``"exhausted"`` (every reachable state was expanded; with ``reverse=False``
        no forward-only path exists at the search's resolution), ``"max_expansions"`` or
        ``"time_budget"`` (the search gave up).
    stats : dict
        What the search did (``expanded``, ``shots``, timings in seconds).
    """

    def __init__(self, message: str, reason: str, stats: dict[str, Any]) -> None:
        super().__init__(message)
        self.reason = reason
        self.stats = stats


# --------------------------------------------------------------------------- result value
@dataclass(frozen=True, slots=True, eq=False)
class PosePath:
    """A path of a car-like robot found by :func:`find_pose_path` (cell units, radians).

    Parameters
    ----------
    poses : ndarray of float64, shape (n, 3)
        ``(x, y, heading)`` along the path at arc-length spacing ``<= sample_step``, every
        piece's end (so every cusp) included; ``x, y`` in cells (module docstring), heading in
        radians, *unwrapped* (continuous along the path; equal to the given headings modulo
        ``2 pi``; the first is the start heading as given). The first pose is the start, the
        last exactly the goal.
    directions : ndarray of int8, shape (n,)
        Direction of travel of the piece arriving at each pose: ``+1`` forwards (along the
        heading), ``-1`` backwards; the first pose carries that of the first piece. At a cusp
        the pose carries the direction of the segment that ends there.
    segments : ndarray of int64, shape (s, 2)
        ``[first, last]`` pose indices (both included) of each stretch without a change of
        direction; consecutive segments share their cusp pose (``segments[i, 1] ==
        segments[i + 1, 0]``). The heading is continuous across a cusp.
    pieces : ndarray of float64, shape (m, 5)
        The exact geometry: per piece ``(x, y, heading, curvature, signed length)`` of its
        start pose, signed curvature (1/cells, ``|curvature| <= 1 / turning_radius``) and arc
        length (cells, negative backwards). Consecutive primitives of equal curvature and
        direction are merged.
    turning_radius : float
        ``R`` in cells.
    stats : dict
        ``expanded`` (nodes expanded), ``nodes`` (created), ``shots`` (analytic expansions
        tried), ``heuristic_s``, ``search_s``, ``total_s`` (seconds), ``primitive_length``
        (cells) and ``heading_bins`` of the search that found the path, ``retried`` (whether
        the finer second search ran); in the footprint mode of :func:`find_pose_path` also
        ``footprint`` (True), ``footprint_margin`` and ``footprint_slack`` (cells);
        ``search_from`` (``"start"`` or ``"goal"``: the search that returned) and
        ``searches`` (per search run: ``from``, ``status`` (the kernel's code: 1 found, 0
        exhausted, 2 max_expansions, 3 time_budget), ``stop`` (the same as a word:
        ``"found"``, ``"exhausted"``, ``"max_expansions"`` or ``"time_budget"``; only
        ``"time_budget"`` depends on the machine's speed) and ``expanded``).

    Attributes
    ----------
    length, reverse_length : float
        Arc length in cells, all of it and the backwards part.
    cusps : int
        Number of changes of direction (``len(segments) - 1``).
    """

    poses: np.ndarray
    directions: np.ndarray
    segments: np.ndarray
    pieces: np.ndarray
    turning_radius: float
    stats: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        for name, dtype in (
            ("poses", np.float64),
            ("directions", np.int8),
            ("segments", np.int64),
            ("pieces", np.float64),
        ):
            a = np.array(getattr(self, name), dtype=dtype, copy=True)
            a.flags.writeable = False
            object.__setattr__(self, name, a)
        object.__setattr__(self, "stats", dict(self.stats))

    @property
    def length(self) -> float:
        """Total arc length (cells)."""
        return float(np.abs(self.pieces[:, 4]).sum())

    @property
    def reverse_length(self) -> float:
        """Arc length driven backwards (cells)."""
        s = self.pieces[:, 4]
        return float(-s[s < 0.0].sum()) + 0.0  # + 0.0: no -0.0

    @property
    def cusps(self) -> int:
        """Number of changes of direction of travel."""
        return int(self.segments.shape[0] - 1)

    def __len__(self) -> int:
        """Return the number of poses ``n``."""
        return int(self.poses.shape[0])

    def to_world(self, grid: OccupancyGrid) -> np.ndarray:
        """Poses in world coordinates.

        Parameters
        ----------
        grid : OccupancyGrid
            The grid searched (its resolution and origin are used).

        Returns
        -------
        ndarray of float64, shape (n, 3)
            ``(x, y)`` in metres (``origin + (xy + 0.5) * resolution``), heading in radians.
        """
        out = self.poses.copy()
        out[:, :2] = np.asarray(grid.origin) + (out[:, :2] + 0.5) * grid.resolution
        return out

    def __repr__(self) -> str:
        s = self.poses[0]
        g = self.poses[-1]
        return (
            f"PosePath(n={len(self)}, start=({s[0]:.4g}, {s[1]:.4g}, {s[2]:.4g}), "
            f"goal=({g[0]:.4g}, {g[1]:.4g}, {g[2]:.4g}), length={self.length:.6g}, "
            f"reverse_length={self.reverse_length:.6g}, cusps={self.cusps})"
        )


# --------------------------------------------------------------------------- checks
def _free(grid: object) -> np.ndarray:
    """Return the uint8 free mask (ny, nx) of an OccupancyGrid or of a bool array of free cells."""
    if isinstance(grid, OccupancyGrid):
        return np.ascontiguousarray(~grid.occupied, dtype=np.uint8)
    a = np.asarray(grid) if isinstance(grid, np.ndarray) else None
    if a is None or a.dtype != bool or a.ndim != 2 or a.size == 0:
        raise InvalidInputError(
            "grid must be an astar.OccupancyGrid or a non-empty 2-D bool array (ny, nx) "
            f"True on free cells, got {type(grid).__name__}"
            + (f" of dtype {a.dtype} and shape {a.shape}" if a is not None else "")
        )
    return np.ascontiguousarray(a, dtype=np.uint8)


def _pose(name: str, value: object, free: np.ndarray) -> tuple[float, float, float]:
    bad = f"{name} must be a pose (x, y, heading): x, y in cells, heading in radians"
    if isinstance(value, (str, bytes)):
        raise InvalidInputError(f"{bad}, got {value!r}")
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise InvalidInputError(f"{bad}, got {validation.short_repr(value)}") from None
    if a.shape != (3,):
        raise InvalidInputError(f"{bad}, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise InvalidInputError(f"{name} must be finite, got {a.tolist()}")
    ny, nx = free.shape
    ix = int(math.floor(a[0] + 0.5))
    iy = int(math.floor(a[1] + 0.5))
    if not (0 <= ix < nx and 0 <= iy < ny):
        raise InvalidInputError(
            f"{name} ({a[0]:g}, {a[1]:g}) is outside the grid: need -0.5 <= x < {nx - 0.5} "
            f"and -0.5 <= y < {ny - 0.5} (cells)"
        )
    if not free[iy, ix]:
        raise InvalidInputError(
            f"{name} ({a[0]:g}, {a[1]:g}) lies in the blocked cell ({ix}, {iy}) (an obstacle, "
            "or inside the inflated avoidance area)"
        )
    return float(a[0]), float(a[1]), float(a[2])


# --------------------------------------------------------------------------- public API
def find_pose_path(
    grid: OccupancyGrid | np.ndarray,
    start: tuple[float, float, float],
    goal: tuple[float, float, float],
    *,
    motion: HybridMotion | None = None,
    costs: HybridCosts | None = None,
    limits: HybridLimits | None = None,
    collision: HybridCollision | None = None,
    **options: Any,
) -> PosePath:
    """Path of a car-like robot from a start pose to a goal pose by Hybrid-A*.

    The settings come as four records (:class:`~astar.HybridMotion`,
    :class:`~astar.HybridCosts`, :class:`~astar.HybridLimits`,
    :class:`~astar.HybridCollision`), or their fields by name: ``find_pose_path(grid, s, g,
    turning_radius=3.0, reverse=False)`` is ``find_pose_path(grid, s, g,
    motion=HybridMotion(turning_radius=3.0, reverse=False))``. A record and fields of the
    same record by name exclude each other; fields of the other records may be given by
    name beside it.

    Parameters
    ----------
    grid : OccupancyGrid or ndarray of bool, shape (ny, nx)
        Where the robot's centre may be: an (inflated, :func:`astar.inflate`) grid, or a bool
        array ``True`` on free cells (row 0 at the bottom). Outside the grid is blocked.
    start, goal : array_like of float, shape (3,)
        Poses ``(x, y, heading)``: ``x, y`` in cells (cell ``(ix, iy)``'s centre is
        ``(ix, iy)``), heading in radians counter-clockwise from ``+x``; inside the grid, on
        free cells.
    motion : HybridMotion, optional
        The car and the primitives: ``turning_radius`` (cells, required: here or by name),
        ``reverse`` (default True), ``heading_bins`` (72), ``primitive_length`` (cells;
        default from the radius and the bins), ``curvatures`` (3).
    costs : HybridCosts, optional
        ``reverse_penalty`` (2), ``cusp_penalty`` (2 turning radii), ``turn_penalty``
        (0.05), ``steer_penalty`` (0.05), ``analytic_ratio`` (3.5), ``heuristic_weight``
        (1.5). Default: ``HybridCosts()``.
    limits : HybridLimits, optional
        ``max_expansions`` (500 000), ``time_budget`` (2 s), ``sample_step`` (0.5 cells),
        ``search_from`` (``"auto"``: from the start, then from the goal; see Notes),
        ``retry_expansions`` (None: the finer search after a small region was exhausted
        gets what is left of ``max_expansions``). Default: ``HybridLimits()``.
    collision : HybridCollision, optional
        What the path keeps clear of besides ``grid``: nothing (the default), the raw map
        at an exact ``clearance`` (cells), or a ``footprint`` polygon (cells) with
        ``footprint_margin`` and ``footprint_slack``. ``raw_grid`` must have ``grid``'s
        shape. In the footprint mode the start and goal poses' footprints, grown by the
        margin and the slack, must keep clear of the raw map and inside the grid. A
        ``raw_grid`` made by :meth:`~astar.OccupancyGrid.from_polygons` (its polygons known)
        is tested against its polygons where its occupied squares do not clear the body:
        the footprint then keeps the margin from the polygons, not from the squares.

    Other Parameters
    ----------------
    **options
        Any field of the four records by name (``turning_radius=3.0``,
        ``time_budget=0.5``, ``raw_grid=occ, clearance=2.0``, ...): the records are built
        from them (:data:`astar.hybrid_options.FLAT_KEYWORDS` lists them), with the same
        checks and errors. The records' docstrings give each field's rule and units.

    Returns
    -------
    PosePath
        Poses (shape ``(n, 3)``), directions, segments between cusps, the exact pieces,
        ``length``, ``reverse_length``, ``cusps`` and ``stats``.

    Raises
    ------
    InvalidInputError
        A parameter breaks its rule (the message names it, its value and the rule); a pose is
        not three finite numbers, lies outside the grid or on a blocked cell, or (footprint
        mode) its grown footprint meets an obstacle or leaves the grid; ``footprint``
        without ``raw_grid`` or with ``clearance``; ``footprint_margin`` without
        ``footprint``; a record of the wrong type, or a record and fields of it by name.
    TypeError
        A keyword that is no field of the records, or no ``motion`` and no
        ``turning_radius``.
    NoPosePathError
        (a :class:`~astar.NoPathError`) No path: ``reason`` says why: ``"disconnected"``
        (refused before searching), ``"exhausted"`` (with ``reverse=False``: no forwards-only
        path), ``"max_expansions"``, ``"time_budget"``.

    Notes
    -----
    Every primitive and the final shot are checked at arc-length spacing 0.2 cells, every
    cell crossed by the chords between samples being tested. Hybrid-A* is resolution-complete
    only: a path that needs finer headings or shorter primitives than the search uses may be
    missed, and the path found is cheap, not cheapest: after the first collision-free analytic
    shot the search goes on for at most as many expansions again (plus 100) and keeps the
    cheapest path (costs: length, backwards and arc weights, cusps). When the search exhausts
    a small region (at most 20 000 expansions: a pocket where no primitive fits, a dead end),
    it runs once more with primitives a third as long and three times as many heading bins,
    within the remaining budgets and ``retry_expansions`` (with ``fine_radius``: the same
    primitives and states, and within ``fine_radius`` of the end poses finer states and
    shorter primitives besides, :class:`~astar.HybridMotion`). The search may also grow from the goal
    (``search_from="goal"``): it drives its primitives back in time from the goal pose and
    shoots words from the start pose, and the path it returns is the same kind of path (from
    the start, each piece driven as the path drives it, checked the same way). With
    ``search_from="auto"`` (the default) the search from the start runs first, with half the
    budgets, or, when the goal's cell has less room than the start's (a parking slot, a
    bay), as a probe of 1000 expansions; when it gives up, the search from the goal runs with
    what is left (``stats["searches"]`` lists both, ``stats["search_from"]`` names the one
    that returned). From the tight end the shots land in the open: that is what parks a car
    into a slot with many short moves. The heuristic is
    ``max(h2d, Euclidean distance, Reeds-Shepp/Dubins length)``, all lower bounds of the
    length: ``h2d`` is a Dijkstra distance from the goal's cell on the free grid (steps 1 and
    1.4, below the octile ``sqrt(2)``; computed up to ``20 R + 50`` cells beyond the start,
    farther cells get that frontier distance), the car length is evaluated lazily (when a node
    is popped, within ``max(30, 12 R)`` cells of the goal; the node goes back to the open list
    if its ``f`` grew). Caveat: ``h2d`` is measured between cell centres, so a pose off its
    cell's centre may be up to about one cell closer to the goal than it says (Smac's 2-D
    heuristic has the same slack). Concurrent calls are independent (no shared buffers).

    Examples
    --------
    >>> import numpy as np
    >>> free = np.ones((10, 20), bool)
    >>> p = find_pose_path(free, (12, 5, 0.0), (6, 5, 0.0), turning_radius=3.0)
    >>> round(p.length, 9), p.reverse_length == p.length, p.cusps
    (6.0, True, 0)
    """
    t0 = time.perf_counter()
    free = _free(grid)
    sx, sy, sth = _pose("start", start, free)
    gx, gy, gth = _pose("goal", goal, free)
    motion, costs, limits, collision = build_options(motion, costs, limits, collision, options)
    radius, reverse = motion.turning_radius, motion.reverse
    nbins, prim_len = motion.heading_bins, motion.arc_length
    max_exp, budget = limits.max_expansions, limits.time_budget
    kcoll = kernel_collision(
        collision, free, COLLISION_STEP, (("start", (sx, sy, sth)), ("goal", (gx, gy, gth)))
    )

    from astar.hybrid_kernel import (
        EXHAUSTED,
        FOUND,
        TIME_BUDGET,
        KernelCosts,
        KernelLimits,
        KernelMotion,
        KernelQuery,
        distance_field,
        hybrid_kernel,
    )

    gix, giy = int(math.floor(gx + 0.5)), int(math.floor(gy + 0.5))
    six, siy = int(math.floor(sx + 0.5)), int(math.floor(sy + 0.5))
    order = _order(limits.search_from, free, (six, siy), (gix, giy), radius)
    fields: dict[bool, np.ndarray] = {}
    reach = _DIJKSTRA_SLACK_R * radius + 50.0
    if order[0][0]:  # from the goal: the 2-D distances to the start
        h2d, reached = distance_field(free, six, siy, gix, giy, reach)
    else:
        h2d, reached = distance_field(free, gix, giy, six, siy, reach)
    fields[order[0][0]] = h2d
    t1 = time.perf_counter()
    stats: dict[str, Any] = {
        "expanded": 0,
        "nodes": 0,
        "shots": 0,
        "heuristic_s": t1 - t0,
        "search_s": 0.0,
        "total_s": 0.0,
        "primitive_length": prim_len,
        "heading_bins": nbins,
        "search_from": "goal" if order[0][0] else "start",
        "searches": [],
    }
    if collision.footprint is not None:
        stats.update(
            footprint=True,
            footprint_margin=collision.footprint_margin,
            footprint_slack=collision.footprint_slack,
        )
    if not reached:
        stats["total_s"] = time.perf_counter() - t0
        raise NoPosePathError(
            f"no path from start ({sx:g}, {sy:g}) to goal ({gx:g}, {gy:g}): their cells "
            f"({six}, {siy}) and ({gix}, {giy}) lie in different free regions of the "
            f"{free.shape[1]} x {free.shape[0]} grid",
            "disconnected",
            stats,
        )
    kappas = motion.primitive_curvatures()
    kcosts = KernelCosts(
        costs.reverse_penalty,
        costs.cusp_penalty * radius,
        costs.turn_penalty,
        costs.steer_penalty,
        costs.analytic_ratio,
        costs.heuristic_weight,
        max(30.0, 12.0 * radius),
    )

    def search(
        backward: bool, plen: float, bins: int, exp_left: int, deadline: float, fine: bool = False
    ) -> tuple:
        if backward not in fields:  # 2-D distances to the search's target
            src, dst = ((six, siy), (gix, giy)) if backward else ((gix, giy), (six, siy))
            fields[backward] = distance_field(free, *src, *dst, reach)[0]
        if backward:  # the search's root is the goal, its target the start
            query = KernelQuery(free, fields[backward], gx, gy, gth, sx, sy, sth)
        else:
            query = KernelQuery(free, fields[backward], sx, sy, sth, gx, gy, gth)
        kmotion = KernelMotion(
            radius,
            kappas,
            plen,
            bins,
            reverse,
            backward,
            motion.fine_radius if fine else 0.0,
            motion.fine_factor,
        )
        klimits = KernelLimits(exp_left, deadline, _POLISH)
        return hybrid_kernel(query, kmotion, kcosts, klimits, kcoll)

    expanded = shots = 0
    retried = False
    backward = order[0][0]
    for backward, cap in order:
        exp_cap, deadline = max_exp - expanded, t1 + budget
        if cap is not None:  # the first of two: a share of the budgets
            share = max(1, int(AUTO_FIRST_SHARE * max_exp))
            exp_cap = share if cap < 0 else min(cap, share)
            deadline = t1 + AUTO_FIRST_SHARE * budget
        plen, bins = prim_len, nbins
        out = search(backward, plen, bins, exp_cap, deadline)
        status, n_exp = out[0], min(int(out[7]), exp_cap)  # the kernel counts the one refused
        expanded += n_exp
        shots += int(out[8])
        left = max_exp - expanded
        if limits.retry_expansions is not None:
            left = min(left, limits.retry_expansions)
        if status == EXHAUSTED and n_exp <= _RETRY_BELOW and left > 0:
            # a small region was exhausted (a pocket where no primitive fits?): once more with
            # primitives a third as long and three times as many heading bins
            if motion.fine_radius > 0.0:  # finer states and primitives near the ends only
                out = search(backward, prim_len, nbins, left, t1 + budget, fine=True)
            else:
                plen, bins = prim_len / 3.0, 3 * nbins
                out = search(backward, plen, bins, left, t1 + budget)
            status, retried = out[0], True
            expanded += min(int(out[7]), left)
            shots += int(out[8])
        stats["searches"].append(
            {
                "from": "goal" if backward else "start",
                "status": int(status),
                "stop": _STOPS[int(status)],
                "expanded": n_exp,
            }
        )
        if status in (FOUND, EXHAUSTED) or retried or expanded >= max_exp:
            break  # found, or no path at all: the other end's states are the same
    nodes = out[2]
    t2 = time.perf_counter()
    stats.update(
        expanded=expanded,
        nodes=int(nodes.shape[0]),
        shots=shots,
        search_s=t2 - t1,
        retried=retried,
        primitive_length=plen if status == FOUND else prim_len,
        heading_bins=bins if status == FOUND else nbins,
        search_from="goal" if backward else "start",
    )
    if status != FOUND:
        stats["total_s"] = time.perf_counter() - t0
        mode = "forwards and backwards" if reverse else "forwards only (reverse=False)"
        if status == EXHAUSTED:
            reason = "exhausted"
            why = (
                f"every reachable (x, y, heading) state was expanded ({expanded}) driving {mode} "
                f"with turning radius {radius:g} cells"
            )
            if retried and motion.fine_radius > 0.0:
                f = motion.fine_factor
                why += (
                    f", and again with {f} x {f} sub-cells, {f * nbins} heading bins and "
                    f"primitives of {prim_len / f:.3g} cells within {motion.fine_radius:.3g} "
                    "cells of the end poses"
                )
            elif retried:
                why += (
                    f", and again with primitives of {prim_len / 3.0:.3g} cells and {3 * nbins} "
                    "heading bins"
                )
            if not reverse:
                why += (
                    "; no forwards-only path exists at this resolution (reverse=True may find one)"
                )
        elif status == TIME_BUDGET:
            reason = "time_budget"
            why = (
                f"the search ran out of its time_budget of {budget:g} s ({expanded} expansions; "
                "wall clock: where it stops depends on the machine's load)"
            )
        else:
            reason = "max_expansions"
            why = f"the search reached max_expansions={max_exp}"
            if retried and expanded < max_exp:
                why = (
                    f"the finer search after a small region was exhausted reached "
                    f"retry_expansions={limits.retry_expansions}"
                )
        raise NoPosePathError(
            f"no path from start pose ({sx:g}, {sy:g}, {sth:g}) to goal pose ({gx:g}, {gy:g}, "
            f"{gth:g}): {why}",
            reason,
            stats,
        )
    arrays = assemble(
        out,
        kappas,
        plen,
        radius,
        limits.sample_step,
        (sx, sy, sth),
        (gx, gy, gth),
        kcoll.exact_r > 0.0,
        backward,
        motion.fine_factor,
    )
    if reverse:  # fewer cusps where a cheaper word is clear (the search's own costs and tests)
        from astar.hybrid_shortcut import shorten_cusps

        t3 = time.perf_counter()
        short = shorten_cusps(
            free,
            arrays[3],
            (gx, gy, gth),
            radius,
            (costs.reverse_penalty, costs.cusp_penalty * radius, 1.0 + costs.turn_penalty),
            kcoll,
            limits.sample_step,
        )
        stats["shortcut"] = {
            "replaced": 0 if short is None else short[4],
            "cusps_before": len(arrays[2]) - 1,
        }
        stats["shortcut_s"] = time.perf_counter() - t3
        if short is not None:
            arrays = short[:4]
    path = PosePath(*arrays, radius)
    stats["total_s"] = time.perf_counter() - t0
    object.__setattr__(path, "stats", stats)
    logger.debug("find_pose_path: %r, stats %s", path, stats)
    return path


def _order(
    search_from: str, free: np.ndarray, s: tuple[int, int], g: tuple[int, int], radius: float
) -> tuple[tuple[bool, int | None], ...]:
    """Return the searches to run in order: ``(backward, expansion cap or None)``.

    ``"auto"``: from the start, then from the goal. When the goal's cell is nearer a blocked
    cell of ``free`` (or the grid's side) than the start's (distances between cell centres,
    capped at ``2 radius`` cells, by more than one cell), the search from the start is a
    probe of :data:`AUTO_PROBE` expansions (a goal tight but easy to reach keeps the path
    searched from the start), else it has :data:`AUTO_FIRST_SHARE` of the expansions.
    """
    if search_from != "auto":
        return ((search_from == "goal", None),)
    cap = max(2.0, 2.0 * radius)
    tight_goal = _room(free, g, cap) < _room(free, s, cap) - 1.0
    return ((False, AUTO_PROBE if tight_goal else -1), (True, None))


def _room(free: np.ndarray, cell: tuple[int, int], cap: float) -> float:
    """Distance (cells) from ``cell``'s centre to the nearest blocked cell's, at most ``cap``."""
    ny, nx = free.shape
    ix, iy = cell
    w = int(math.ceil(cap))
    x0, x1 = max(0, ix - w), min(nx, ix + w + 1)
    y0, y1 = max(0, iy - w), min(ny, iy + w + 1)
    room = float(min(cap, ix + 1, nx - ix, iy + 1, ny - iy))  # the outside of the grid
    by, bx = np.nonzero(free[y0:y1, x0:x1] == 0)
    if bx.size:
        room = min(room, float(np.hypot(bx + x0 - ix, by + y0 - iy).min()))
    return room
