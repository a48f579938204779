"""Pose-to-pose paths for car-like robots: Hybrid-A* with Reeds-Shepp/Dubins shots.

:func:`find_pose_path` searches (x, y, heading) on a grid of free cells for a path of arcs of
curvature at most ``1 / turning_radius`` from a start pose to a goal pose, forwards and (with
``reverse=True``) backwards, and returns a :class:`PosePath`: poses sampled along it, the
direction of travel at each, the segments between cusps and the exact pieces (arcs and lines)
it is made of. The search itself is :mod:`astar.hybrid_kernel` (Dolgov et al. 2008/2010;
parameters after Nav2 Smac Hybrid-A*), the analytic curves :mod:`astar.reeds_shepp`.

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
from numpy.typing import ArrayLike

from astar import validation
from astar.errors import InvalidInputError, NoPathError
from astar.grid import OccupancyGrid
from astar.hybrid_modes import DEFAULT_SLACK, exact_mode, footprint_mode

__all__ = ["NoPosePathError", "PosePath", "find_pose_path"]

logger = logging.getLogger(__name__)

_COLLISION_STEP = 0.2  # cells: arc-length spacing of the collision samples
_DIJKSTRA_SLACK_R = 20.0  # the 2-D distance field reaches 20 R + 50 cells beyond the start
_RETRY_BELOW = 20_000  # an exhausted search this small is retried at a finer resolution
_POLISH = 100  # expansions the search may go on after its first path, besides as many again
_REASONS = ("disconnected", "exhausted", "max_expansions", "time_budget")


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
        ``footprint`` (True), ``footprint_margin`` and ``footprint_slack`` (cells).

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


def _number(name: str, value: object, lo: float, rule: str) -> float:
    if isinstance(value, bool):
        raise InvalidInputError(f"{name} must be a number, got {value!r}")
    try:
        v = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise InvalidInputError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(v) or v < lo:
        raise InvalidInputError(f"{name} must be finite and {rule}, got {v!r}")
    return v


def _int(name: str, value: object, lo: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise InvalidInputError(f"{name} must be an int, got {value!r}")
    if int(value) < lo:
        raise InvalidInputError(f"{name} must be >= {lo}, got {int(value)}")
    return int(value)


# --------------------------------------------------------------------------- public API
def find_pose_path(
    grid: OccupancyGrid | np.ndarray,
    start: tuple[float, float, float],
    goal: tuple[float, float, float],
    *,
    turning_radius: float,
    reverse: bool = True,
    heading_bins: int = 72,
    primitive_length: float | None = None,
    curvatures: int = 3,
    reverse_penalty: float = 2.0,
    cusp_penalty: float = 2.0,
    turn_penalty: float = 0.05,
    steer_penalty: float = 0.05,
    analytic_ratio: float = 3.5,
    sample_step: float = 0.5,
    max_expansions: int = 500_000,
    time_budget: float = 2.0,
    heuristic_weight: float = 1.5,
    raw_grid: OccupancyGrid | np.ndarray | None = None,
    clearance: float | None = None,
    footprint: ArrayLike | None = None,
    footprint_margin: float = 0.0,
    footprint_slack: float = DEFAULT_SLACK,
) -> PosePath:
    """Path of a car-like robot from a start pose to a goal pose by Hybrid-A*.

    Parameters
    ----------
    grid : OccupancyGrid or ndarray of bool, shape (ny, nx)
        Where the robot's centre may be: an (inflated, :func:`astar.inflate`) grid, or a bool
        array ``True`` on free cells (row 0 at the bottom). Outside the grid is blocked.
    start, goal : array_like of float, shape (3,)
        Poses ``(x, y, heading)``: ``x, y`` in cells (cell ``(ix, iy)``'s centre is
        ``(ix, iy)``), heading in radians counter-clockwise from ``+x``; inside the grid, on
        free cells.
    turning_radius : float
        Minimum turning radius ``R`` in cells, finite and ``> 0``.
    reverse : bool, optional
        True (default): forwards and backwards (Reeds-Shepp shots). False: forwards only
        (Dubins shots).
    heading_bins : int, optional
        Heading bins of the discrete states (``>= 8``; default 72, 5 degrees, as Smac).
    primitive_length : float, optional
        Arc length of a motion primitive in cells. Default: the shortest arc of radius ``R``
        that turns by a whole number of heading bins and is at least ``sqrt(2)`` cells long.
    curvatures : int, optional
        Number of primitive curvatures, odd and ``>= 3``: evenly spaced in
        ``[-1/R, 1/R]``, zero included (3: ``{-1/R, 0, 1/R}``).
    reverse_penalty : float, optional
        ``>= 1``: a backwards primitive costs its length times this (Smac: 2.0).
    cusp_penalty : float, optional
        ``>= 0``: cost added per change of direction, in turning radii (default 2: ``2 R``).
    turn_penalty : float, optional
        ``>= 0``: an arc costs its length times ``1 + turn_penalty``.
    steer_penalty : float, optional
        ``>= 0``: a primitive whose curvature differs from the previous one's costs
        ``1 + steer_penalty`` times more.
    analytic_ratio : float, optional
        ``> 0``: an analytic shot to the goal is tried every ``max(1, floor(h /
        analytic_ratio))`` expansions, ``h`` the heuristic of the expanded node in cells
        (Smac's analytic expansion ratio: 3.5).
    sample_step : float, optional
        ``> 0``: largest arc length between returned poses, cells.
    max_expansions : int, optional
        ``>= 1``: the search gives up after this many expansions.
    time_budget : float, optional
        ``> 0``: seconds; the search (not the 2-D distance field before it) gives up after
        this long (checked every 128 expansions).
    heuristic_weight : float, optional
        ``>= 1``: nodes are ordered by ``g + heuristic_weight * h`` (weighted A*). 1 gives
        the cheapest path at the search's resolution (up to the caveat below) but may expand
        many more states; the default 1.5 solved 36 of 36 held-out queries where 1.0 solved
        32 within 1 s (``benchmarks/bench_hybrid.py``), at a cost at most 1.5 times the
        cheapest.
    raw_grid : OccupancyGrid or ndarray of bool, shape (ny, nx), optional
        With ``clearance``: the raw map (an ``OccupancyGrid``, or a bool array ``True`` on
        *occupied* cells, as ``OccupancyGrid.occupied``), the same shape as ``grid``.
    clearance : float, optional
        Exact mode (with ``raw_grid``; finite, ``> 0``, cells): besides the cell checks on
        ``grid``, every chord between consecutive collision samples keeps Euclidean distance
        ``>= clearance`` from every occupied square of ``raw_grid`` and from the outside of the
        grid (checked exactly where a cell it crosses is within ``clearance + sqrt(2) / 2``
        cells of an obstacle), and the returned poses are those samples (arc-length spacing
        at most 0.2 cells, ``sample_step`` ignored), so the polyline through the poses keeps
        ``clearance``. For a ``grid`` inflated by a radius ``r`` (cell centres keep ``r``),
        ``clearance=r`` lets the poses lie anywhere in their cells without coming closer
        than ``r``, where a grid inflated by ``r`` plus half a cell's diagonal would block
        the cells next to a wall.
    footprint : array_like of float, shape (k, 2), optional
        Footprint mode (with ``raw_grid``; excludes ``clearance``): the robot's body as a
        convex polygon, vertices in cells in the robot frame (``x`` forwards along the
        heading, ``y`` to the left), counter-clockwise or clockwise, ``k >= 3``, the origin
        (the pose's point) strictly inside. The body faces the pose's heading whatever the
        direction of travel. Every pose of the continuous path (every primitive and the
        final shot at every arc length, not only at samples) has its footprint, rotated by
        the heading and moved to the pose, at a distance greater than ``footprint_margin``
        from every occupied square of ``raw_grid`` (closed squares ``[ix - 0.5, ix + 0.5] x
        [iy - 0.5, iy + 0.5]``) and within the grid (``[-0.5, nx - 0.5] x [-0.5, ny - 0.5]``,
        at least ``footprint_margin`` from its sides). Each arc of curvature ``kappa`` is
        cut into equal steps of at most ``ds = 2 footprint_slack / (1 + rho |kappa|)`` cells
        (``rho``: the farthest vertex from the origin), so that between a step's middle and
        any pose of the step every point of the body moves at most ``footprint_slack``; the
        footprint grown by ``footprint_margin + footprint_slack`` is tested exactly (separating axes, then the
        polygon-to-square distance) at each step's middle. ``grid`` stays a necessary
        condition on the centre: pass the raw map inflated by the footprint's inscribed
        radius about the origin (a larger inflation loses paths, a smaller one only costs
        time). Cells whose every point keeps ``rho + footprint_margin + footprint_slack`` from the
        obstacles skip the polygon test. The returned poses are sampled as without
        footprint (``sample_step``); the guarantee holds for every pose of the exact
        ``pieces``, hence for the returned poses. The start and goal poses must pass the
        sample test themselves (else ``InvalidInputError``).
    footprint_margin : float, optional
        With ``footprint``: the distance (cells, finite, ``>= 0``; default 0) the footprint
        keeps from the obstacles and the grid's outside.
    footprint_slack : float, optional
        With ``footprint``: the sampling slack (cells, finite, ``> 0``; default 0.05). The
        number of footprint tests falls as ``1 / footprint_slack``, and poses whose footprint
        comes within ``footprint_margin + footprint_slack`` of an obstacle at a tested
        sample are refused, so a slack is also a margin at the samples: a large body on a
        fine grid wants a slack of a good fraction of a cell.

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
        ``footprint``.
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
    within the remaining budgets. The heuristic is
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
    radius = validation.positive_float("turning_radius", turning_radius)
    if not isinstance(reverse, (bool, np.bool_)):
        raise InvalidInputError(f"reverse must be a bool, got {reverse!r}")
    reverse = bool(reverse)
    nbins = _int("heading_bins", heading_bins, 8)
    nc = _int("curvatures", curvatures, 3)
    if nc % 2 == 0:
        raise InvalidInputError(f"curvatures must be odd (zero included), got {nc}")
    bin_w = 2.0 * math.pi / nbins
    if primitive_length is None:
        turns = max(1, math.ceil(math.sqrt(2.0) / radius / bin_w - 1e-12))
        prim_len = radius * turns * bin_w
    else:
        prim_len = validation.positive_float("primitive_length", primitive_length)
    rp = _number("reverse_penalty", reverse_penalty, 1.0, ">= 1")
    cp = _number("cusp_penalty", cusp_penalty, 0.0, ">= 0") * radius
    tp = _number("turn_penalty", turn_penalty, 0.0, ">= 0")
    sp = _number("steer_penalty", steer_penalty, 0.0, ">= 0")
    ratio = validation.positive_float("analytic_ratio", analytic_ratio)
    step = validation.positive_float("sample_step", sample_step)
    max_exp = _int("max_expansions", max_expansions, 1)
    budget = validation.positive_float("time_budget", time_budget)
    hw = _number("heuristic_weight", heuristic_weight, 1.0, ">= 1")
    foot = footprint_mode(
        footprint,
        footprint_margin,
        footprint_slack,
        raw_grid,
        clearance,
        free,
        (("start", (sx, sy, sth)), ("goal", (gx, gy, gth))),
    )
    if foot is None:
        safe, occ, exact_r = exact_mode(raw_grid, clearance, free)
        fp, fsafe, frho, fmargin, fslack = np.zeros((0, 4)), safe, 0.0, 0.0, 0.0
    else:
        safe, occ, exact_r = np.zeros((1, 1), dtype=np.uint8), foot.occ, 0.0
        fp, fsafe, frho, fmargin, fslack = foot.fp, foot.safe, foot.rho, foot.margin, foot.slack

    from astar.hybrid_kernel import EXHAUSTED, FOUND, TIME_BUDGET, distance_field, hybrid_kernel

    gix, giy = int(math.floor(gx + 0.5)), int(math.floor(gy + 0.5))
    six, siy = int(math.floor(sx + 0.5)), int(math.floor(sy + 0.5))
    h2d, reached = distance_field(free, gix, giy, six, siy, _DIJKSTRA_SLACK_R * radius + 50.0)
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
    }
    if foot is not None:
        stats.update(footprint=True, footprint_margin=foot.margin, footprint_slack=foot.slack)
    if not reached:
        stats["total_s"] = time.perf_counter() - t0
        raise NoPosePathError(
            f"no path from start ({sx:g}, {sy:g}) to goal ({gx:g}, {gy:g}): their cells "
            f"({six}, {siy}) and ({gix}, {giy}) lie in different free regions of the "
            f"{free.shape[1]} x {free.shape[0]} grid",
            "disconnected",
            stats,
        )
    kappas = np.linspace(-1.0 / radius, 1.0 / radius, nc)
    kappas[nc // 2] = 0.0
    kappas = np.ascontiguousarray(kappas[np.argsort(np.abs(kappas), kind="stable")])

    def search(plen: float, bins: int, exp_left: int, deadline: float) -> tuple:
        return hybrid_kernel(
            free,
            h2d,
            sx,
            sy,
            sth,
            gx,
            gy,
            gth,
            radius,
            kappas,
            plen,
            bins,
            reverse,
            rp,
            cp,
            tp,
            sp,
            ratio,
            max(30.0, 12.0 * radius),
            _COLLISION_STEP,
            exp_left,
            deadline,
            _POLISH,
            hw,
            safe,
            occ,
            exact_r,
            fp,
            fsafe,
            frho,
            fmargin,
            fslack,
        )

    out = search(prim_len, nbins, max_exp, t1 + budget)
    status, expanded, shots, retried = out[0], int(out[7]), int(out[8]), False
    if status == EXHAUSTED and expanded <= _RETRY_BELOW and max_exp > expanded:
        # a small region was exhausted (a pocket where no primitive fits?): once more with
        # primitives a third as long and three times as many heading bins
        out = search(prim_len / 3.0, 3 * nbins, max_exp - expanded, t1 + budget)
        status, retried = out[0], True
        expanded += int(out[7])
        shots += int(out[8])
        if status == FOUND:
            prim_len, nbins = prim_len / 3.0, 3 * nbins
    _, chain, nodes, prims, skinds, slens, sn = out[:7]
    t2 = time.perf_counter()
    stats.update(
        expanded=expanded,
        nodes=int(nodes.shape[0]),
        shots=shots,
        search_s=t2 - t1,
        retried=retried,
        primitive_length=prim_len,
        heading_bins=nbins,
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
            if retried:
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
            why = f"the search ran out of its time_budget of {budget:g} s ({expanded} expansions)"
        else:
            reason = "max_expansions"
            why = f"the search reached max_expansions={max_exp}"
        raise NoPosePathError(
            f"no path from start pose ({sx:g}, {sy:g}, {sth:g}) to goal pose ({gx:g}, {gy:g}, "
            f"{gth:g}): {why}",
            reason,
            stats,
        )
    path = _assemble(
        nodes,
        prims,
        chain,
        skinds,
        slens,
        int(sn),
        kappas,
        prim_len,
        radius,
        step,
        (gx, gy, gth),
        exact_r > 0.0,
    )
    stats["total_s"] = time.perf_counter() - t0
    object.__setattr__(path, "stats", stats)
    logger.debug("find_pose_path: %r, stats %s", path, stats)
    return path


def _assemble(
    nodes: np.ndarray,
    prims: np.ndarray,
    chain: np.ndarray,
    skinds: np.ndarray,
    slens: np.ndarray,
    sn: int,
    kappas: np.ndarray,
    prim_len: float,
    radius: float,
    step: float,
    goal: tuple[float, float, float],
    exact: bool = False,
) -> PosePath:
    """Pieces, poses, directions and segments from the kernel's chain of nodes and shot.

    ``exact``: the poses are the kernel's own collision samples (each primitive and shot
    segment from its start pose, ``m = ceil(|s| / _COLLISION_STEP)`` equal steps), whose
    chords the exact mode checked.
    """
    from astar.reeds_shepp import advance

    raw: list[list[float]] = []
    for a, b in zip(chain[:-1], chain[1:], strict=True):
        p = int(prims[b])
        s = -prim_len if p & 1 else prim_len
        raw.append([*nodes[a], float(kappas[p >> 1]), s])
    x, y, th = (float(v) for v in nodes[chain[-1]])
    for i in range(sn):
        if slens[i] == 0.0:
            continue
        k = float(skinds[i]) / radius
        raw.append([x, y, th, k, float(slens[i])])
        # the kernel's closed form run as Python (an inlined kernel has no signature of its own)
        x, y, th = advance.py_func(x, y, th, k, float(slens[i]))
    pieces: list[list[float]] = []
    for r in raw:
        if pieces and pieces[-1][3] == r[3] and (pieces[-1][4] < 0) == (r[4] < 0):
            pieces[-1][4] += r[4]
        else:
            pieces.append(list(r))
    # sample every piece from its own start pose (the kernel's node poses)
    units = raw if exact else pieces
    chunks = [np.array([units[0][:3]]) if units else np.array([nodes[0]])]
    dirs = [np.array([-1 if units and units[0][4] < 0 else 1], dtype=np.int8)]
    ends = []
    for px, py, pth, k, s in units:
        if exact:  # the kernel's samples (arc_clear), by its closed form
            m = max(1, math.ceil(abs(s) / _COLLISION_STEP))
            c = np.array([advance.py_func(px, py, pth, k, s * j / m) for j in range(1, m + 1)])
            chunks.append(c)
            dirs.append(np.full(m, -1 if s < 0 else 1, dtype=np.int8))
            ends.append(sum(len(ch) for ch in chunks) - 1)
            continue
        m = max(1, math.ceil(abs(s) / step - 1e-9))
        q = s * np.arange(1, m + 1) / m
        if k == 0.0:
            c = np.column_stack([px + q * math.cos(pth), py + q * math.sin(pth), np.full(m, pth)])
        else:
            th1 = pth + k * q
            c = np.column_stack(
                [
                    px + (np.sin(th1) - math.sin(pth)) / k,
                    py - (np.cos(th1) - math.cos(pth)) / k,
                    th1,
                ]
            )
        chunks.append(c)
        dirs.append(np.full(m, -1 if s < 0 else 1, dtype=np.int8))
        ends.append(sum(len(ch) for ch in chunks) - 1)
    poses = np.concatenate(chunks)
    directions = np.concatenate(dirs)
    # the end pose exactly (the word lands on it to rounding, ~1e-12 cells)
    gx, gy, gth = goal
    end_th = poses[-1, 2]
    exact_th = gth + 2.0 * math.pi * round((end_th - gth) / (2.0 * math.pi))
    if math.hypot(poses[-1, 0] - gx, poses[-1, 1] - gy) > 1e-6 or abs(end_th - exact_th) > 1e-6:
        raise RuntimeError(  # pragma: no cover - an internal error, not bad input
            f"internal error: the path ends at {poses[-1].tolist()}, not at the goal {goal}"
        )
    poses[-1] = (gx, gy, exact_th)
    cuts = [0]
    for i in range(len(units) - 1):
        if (units[i][4] < 0) != (units[i + 1][4] < 0):
            cuts.append(ends[i])
    cuts.append(len(poses) - 1)
    segments = np.array([[a, b] for a, b in zip(cuts[:-1], cuts[1:], strict=True)], np.int64)
    arr = np.array(pieces, dtype=np.float64).reshape(-1, 5)
    return PosePath(poses, directions, segments, arr, radius)
