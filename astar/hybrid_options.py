"""The options of :func:`astar.find_pose_path` as typed, frozen, validated records.

Four records group the search's settings by what they describe:

* :class:`HybridMotion`: the car (turning radius, reversing) and the motion primitives the
  search steps with (heading bins, primitive length, number of curvatures);
* :class:`HybridCosts`: the cost of a path (penalties for reversing, cusps, turning,
  steering) and how the search orders and shortcuts (heuristic weight, analytic ratio);
* :class:`HybridLimits`: when the search gives up (expansions, seconds) and how densely the
  returned path is sampled;
* :class:`HybridCollision`: what besides the grid a path must keep clear of (the raw map at
  an exact clearance, or a footprint polygon).

Each record checks its fields on construction and raises
:class:`~astar.errors.InvalidInputError` naming the field, the value and the rule, the same
errors :func:`astar.find_pose_path` has always raised for its keywords. The checks that need
the grid (a pose on a free cell, ``raw_grid`` of the grid's shape, the end poses' footprint)
stay in :func:`astar.find_pose_path`.

:func:`find_pose_path` also takes every field by name (``turning_radius=3.0,
reverse=False``): :func:`build_options` builds the records from such keywords, the accepted
names being the records' fields (:data:`FLAT_KEYWORDS`), so no second list is kept.

Units (those of the search): lengths in **cells**, angles in radians, times in seconds.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from astar import validation
from astar.errors import InvalidInputError
from astar.grid import OccupancyGrid
from astar.hybrid_modes import DEFAULT_SLACK, footprint_polygon, raw_occupied

__all__ = [
    "AUTO_FIRST_SHARE",
    "AUTO_PROBE",
    "FLAT_KEYWORDS",
    "SEARCH_FROM",
    "HybridCollision",
    "HybridCosts",
    "HybridLimits",
    "HybridMotion",
    "build_options",
]

#: The values of :attr:`HybridLimits.search_from`.
SEARCH_FROM = ("auto", "start", "goal")
#: ``search_from="auto"``: the share of the budgets (seconds, expansions) of the first search.
AUTO_FIRST_SHARE = 0.5
#: ``search_from="auto"``: expansions of the search from the start when the goal is tighter.
AUTO_PROBE = 1000


@dataclass(frozen=True, slots=True)
class HybridMotion:
    """The car and the motion primitives of :func:`astar.find_pose_path`.

    Parameters
    ----------
    turning_radius : float
        Minimum turning radius ``R`` in cells, finite and ``> 0``.
    reverse : bool, optional
        True (default): forwards and backwards (Reeds-Shepp shots). False: forwards only
        (Dubins shots).
    heading_bins : int, optional
        Heading bins of the discrete states (``>= 8``; default 72, 5 degrees, as Smac).
    primitive_length : float, optional
        Arc length of a motion primitive in cells (finite, ``> 0``). Default (None): the
        shortest arc of radius ``R`` that turns by a whole number of heading bins and is at
        least ``sqrt(2)`` cells long (:attr:`arc_length`).
    curvatures : int, optional
        Number of primitive curvatures, odd and ``>= 3``: evenly spaced in
        ``[-1/R, 1/R]``, zero included (3: ``{-1/R, 0, 1/R}``).
    fine_radius : float, optional
        Cells, finite, ``>= 0`` (default 0: off). When a search exhausts a small region (a
        pocket, a slot: :func:`astar.find_pose_path`'s Notes), its second run keeps the
        primitives and states and, within this distance of the start or the
        goal pose (a parking slot, a bay), a discrete state is a ``fine_factor`` x
        ``fine_factor`` sub-cell and one of ``fine_factor`` times as many heading bins, so
        that poses a fraction of a cell apart are kept apart, and primitives
        ``fine_factor`` times shorter are expanded besides the others: the many short
        moves of a manoeuvre in a tight space.
    fine_factor : int, optional
        ``>= 1`` (default 3): the refinement of :attr:`fine_radius`'s states and primitives.

    Raises
    ------
    InvalidInputError
        A field breaks its rule (the message names it, its value and the rule).

    Examples
    --------
    >>> HybridMotion(turning_radius=3.0, reverse=False).arc_length  # 6 bins of 5 degrees: pi / 6 R
    1.5707963267948966
    """

    turning_radius: float
    reverse: bool = True
    heading_bins: int = 72
    primitive_length: float | None = None
    curvatures: int = 3
    fine_radius: float = 0.0
    fine_factor: int = 3

    def __post_init__(self) -> None:
        radius = validation.positive_float("turning_radius", self.turning_radius)
        if not isinstance(self.reverse, (bool, np.bool_)):
            raise InvalidInputError(f"reverse must be a bool, got {self.reverse!r}")
        nbins = validation.int_at_least("heading_bins", self.heading_bins, 8)
        nc = validation.int_at_least("curvatures", self.curvatures, 3)
        if nc % 2 == 0:
            raise InvalidInputError(f"curvatures must be odd (zero included), got {nc}")
        plen = self.primitive_length
        if plen is not None:
            plen = validation.positive_float("primitive_length", plen)
        object.__setattr__(self, "turning_radius", radius)
        object.__setattr__(self, "reverse", bool(self.reverse))
        object.__setattr__(self, "heading_bins", nbins)
        object.__setattr__(self, "curvatures", nc)
        object.__setattr__(self, "primitive_length", plen)
        fine_r = validation.nonnegative_float("fine_radius", self.fine_radius, "cells")
        object.__setattr__(self, "fine_radius", fine_r)
        object.__setattr__(
            self, "fine_factor", validation.int_at_least("fine_factor", self.fine_factor, 1)
        )

    @property
    def arc_length(self) -> float:
        """Arc length of a primitive (cells): ``primitive_length`` or its default."""
        if self.primitive_length is not None:
            return self.primitive_length
        bin_w = 2.0 * math.pi / self.heading_bins
        turns = max(1, math.ceil(math.sqrt(2.0) / self.turning_radius / bin_w - 1e-12))
        return self.turning_radius * turns * bin_w

    def primitive_curvatures(self) -> np.ndarray:
        """Signed curvatures of the primitives (1/cells), by increasing magnitude.

        Returns
        -------
        ndarray of float64, shape (curvatures,)
            ``curvatures`` values evenly spaced in ``[-1/R, 1/R]``, zero first.
        """
        nc = self.curvatures
        radius = self.turning_radius
        kappas = np.linspace(-1.0 / radius, 1.0 / radius, nc)
        kappas[nc // 2] = 0.0
        return np.ascontiguousarray(kappas[np.argsort(np.abs(kappas), kind="stable")])


@dataclass(frozen=True, slots=True)
class HybridCosts:
    """The costs and the ordering of the search of :func:`astar.find_pose_path`.

    The cost of a path is its length in cells, weighted by the penalties below (defaults
    after Nav2 Smac Hybrid-A*).

    Parameters
    ----------
    reverse_penalty : float, optional
        ``>= 1``: a backwards primitive costs its length times this (Smac: 2.0).
    cusp_penalty : float, optional
        ``>= 0``: cost added per change of direction, in turning radii (default 2: ``2 R``
        cells).
    turn_penalty : float, optional
        ``>= 0``: an arc costs its length times ``1 + turn_penalty``.
    steer_penalty : float, optional
        ``>= 0``: a primitive whose curvature differs from the previous one's costs
        ``1 + steer_penalty`` times more.
    analytic_ratio : float, optional
        ``> 0``: an analytic shot to the goal is tried every ``max(1, floor(h /
        analytic_ratio))`` expansions, ``h`` the heuristic of the expanded node in cells
        (Smac's analytic expansion ratio: 3.5).
    heuristic_weight : float, optional
        ``>= 1``: nodes are ordered by ``g + heuristic_weight * h`` (weighted A*). 1 gives
        the cheapest path at the search's resolution (up to the caveat in
        :func:`astar.find_pose_path`) but may expand many more states; the default 1.5
        solved 36 of 36 held-out queries where 1.0 solved 32 within 1 s
        (``benchmarks/bench_hybrid.py``), at a cost at most 1.5 times the cheapest.

    Raises
    ------
    InvalidInputError
        A field breaks its rule (the message names it, its value and the rule).
    """

    reverse_penalty: float = 2.0
    cusp_penalty: float = 2.0
    turn_penalty: float = 0.05
    steer_penalty: float = 0.05
    analytic_ratio: float = 3.5
    heuristic_weight: float = 1.5

    def __post_init__(self) -> None:
        checked = {
            "reverse_penalty": validation.float_at_least(
                "reverse_penalty", self.reverse_penalty, 1.0, ">= 1"
            ),
            "cusp_penalty": validation.float_at_least(
                "cusp_penalty", self.cusp_penalty, 0.0, ">= 0"
            ),
            "turn_penalty": validation.float_at_least(
                "turn_penalty", self.turn_penalty, 0.0, ">= 0"
            ),
            "steer_penalty": validation.float_at_least(
                "steer_penalty", self.steer_penalty, 0.0, ">= 0"
            ),
            "analytic_ratio": validation.positive_float("analytic_ratio", self.analytic_ratio),
            "heuristic_weight": validation.float_at_least(
                "heuristic_weight", self.heuristic_weight, 1.0, ">= 1"
            ),
        }
        for name, value in checked.items():
            object.__setattr__(self, name, value)


@dataclass(frozen=True, slots=True)
class HybridLimits:
    """When the search of :func:`astar.find_pose_path` gives up, and the path's sampling.

    Parameters
    ----------
    max_expansions : int, optional
        ``>= 1``: the search gives up after this many expansions.
    time_budget : float, optional
        ``> 0``: seconds of wall clock; the search (not the 2-D distance field before it)
        gives up after this long (checked every 128 expansions). A search it stops depends on
        the machine's speed and load; for answers that do not, let ``max_expansions`` decide
        and set this far above the time those expansions take, as a safety net (the car
        planner does: ``trajopt/planning/_car_tries.py``).
    sample_step : float, optional
        ``> 0``: largest arc length between returned poses, cells (ignored in the exact
        clearance mode, whose poses are the collision samples, at most 0.2 cells apart).
    search_from : {"auto", "start", "goal"}, optional
        Where the search grows from. ``"start"``: from the start pose towards the goal, its
        shots ending at the goal. ``"goal"``: from the goal pose back in time (the path
        driven backwards from its end: a pull-out of a parking slot), its shots starting
        at the start pose; the path returned is the same kind of path, from the start to
        the goal. ``"auto"`` (default): from the start with :data:`AUTO_FIRST_SHARE` of
        ``time_budget`` and of ``max_expansions``, or, when the goal has less room than the
        start (the distance from its cell to a blocked cell of the grid, capped at ``2 R``,
        smaller by more than a cell), with at most :data:`AUTO_PROBE` expansions; when that
        search gives up (not when it exhausts the states), from the goal with what is left.
        A search from the tight end lands its shots in the open: parking into a slot 1.3
        car lengths long takes a few thousand expansions from the slot, and does not finish
        within 2 s from the lane.
    retry_expansions : int or None, optional
        ``>= 0``: at most this many expansions for the finer search that runs after a
        small region was exhausted (:func:`astar.find_pose_path`, Notes); 0: no such
        search, the search reports ``"exhausted"``. None (default): what is left of
        ``max_expansions``. A caller with further tries that do better on such places (a
        grid whose sampling is refined near obstacles) skips or bounds it.

    Raises
    ------
    InvalidInputError
        A field breaks its rule (the message names it, its value and the rule).
    """

    max_expansions: int = 500_000
    time_budget: float = 2.0
    sample_step: float = 0.5
    search_from: str = "auto"
    retry_expansions: int | None = None

    def __post_init__(self) -> None:
        max_exp = validation.int_at_least("max_expansions", self.max_expansions, 1)
        budget = validation.positive_float("time_budget", self.time_budget)
        step = validation.positive_float("sample_step", self.sample_step)
        if self.search_from not in SEARCH_FROM:
            raise InvalidInputError(
                f"search_from must be one of {', '.join(map(repr, SEARCH_FROM))}, got "
                f"{validation.short_repr(self.search_from)}"
            )
        object.__setattr__(self, "max_expansions", max_exp)
        object.__setattr__(self, "time_budget", budget)
        object.__setattr__(self, "sample_step", step)
        if self.retry_expansions is not None:
            retry = validation.int_at_least("retry_expansions", self.retry_expansions, 0)
            object.__setattr__(self, "retry_expansions", retry)


@dataclass(frozen=True, slots=True, eq=False)
class HybridCollision:
    """What a path of :func:`astar.find_pose_path` keeps clear of besides its grid.

    Three modes: none (the default: the search's ``grid`` alone), the **exact clearance
    mode** (``raw_grid`` and ``clearance``) and the **footprint mode** (``raw_grid`` and
    ``footprint``, optionally ``footprint_margin`` and ``footprint_slack``).

    Parameters
    ----------
    raw_grid : OccupancyGrid or ndarray of bool, shape (ny, nx), optional
        The raw map (an ``OccupancyGrid``, or a bool array ``True`` on *occupied* cells, as
        ``OccupancyGrid.occupied``), the same shape as the search's ``grid`` (checked by
        :func:`astar.find_pose_path`). Stored as a read-only bool array of the occupied
        cells (an ``OccupancyGrid``'s own, a copy of an array); an ``OccupancyGrid``'s
        :attr:`~astar.OccupancyGrid.polygons`, when known, are kept in
        :attr:`raw_polygons`.
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
        (the pose's point) strictly inside. Stored as a read-only float64 array as given.
        The body faces the pose's heading whatever the direction of travel. Every pose of
        the continuous path (every primitive and the final shot at every arc length, not
        only at samples) has its footprint, rotated by the heading and moved to the pose,
        at a distance greater than ``footprint_margin`` from every occupied square of
        ``raw_grid`` (closed squares ``[ix - 0.5, ix + 0.5] x [iy - 0.5, iy + 0.5]``) and
        within the grid (``[-0.5, nx - 0.5] x [-0.5, ny - 0.5]``, at least
        ``footprint_margin`` from its sides). Each arc of curvature ``kappa`` is cut into
        equal steps of at most ``ds = 2 footprint_slack / (1 + rho |kappa|)`` cells
        (``rho``: the farthest vertex from the origin), so that between a step's middle and
        any pose of the step every point of the body moves at most ``footprint_slack``; the
        footprint grown by ``footprint_margin + footprint_slack`` is tested exactly
        (separating axes, then the polygon-to-square distance) at each step's middle (an arc
        of more than one step is first tested once whole: the footprint grown by ``margin``
        plus the arc's sweep ``|s| (1 + rho |kappa|) / 2`` at its middle; clear, it needs no
        steps). The
        search's ``grid`` stays a necessary condition on the centre: pass the raw map
        inflated by the footprint's inscribed radius about the origin (a larger inflation
        loses paths, a smaller one only costs time). Cells whose every point keeps ``rho +
        footprint_margin + footprint_slack`` from the obstacles skip the polygon test. The
        returned poses are sampled as without footprint (``sample_step``); the guarantee
        holds for every pose of the exact ``pieces``, hence for the returned poses. The
        start and goal poses must pass the sample test themselves (else
        ``InvalidInputError`` from :func:`astar.find_pose_path`).
    footprint_margin : float, optional
        With ``footprint``: the distance (cells, finite, ``>= 0``; default 0) the footprint
        keeps from the obstacles and the grid's outside.
    footprint_slack : float, optional
        With ``footprint``: the sampling slack (cells, finite, ``> 0``; default 0.05). The
        number of footprint tests falls as ``1 / footprint_slack``, and poses whose footprint
        comes within ``footprint_margin + footprint_slack`` of an obstacle at a tested
        sample are refused, so a slack is also a margin at the samples: a large body on a
        fine grid wants a slack of a good fraction of a cell.
    footprint_min_slack : float, optional
        With ``footprint``: the least sampling slack (cells, finite, ``> 0``, at most
        ``footprint_slack``; default None: ``footprint_slack``, no refinement). A step
        whose test fails while the body at its middle keeps ``footprint_margin`` is halved,
        each half tested with half the slack, and so on down to this slack: poses within
        ``footprint_margin + footprint_min_slack`` of an obstacle are refused, and only
        near obstacles does the test cost more (a slot, a bay). The start and goal poses
        are tested with this slack.

    Raises
    ------
    InvalidInputError
        A field breaks its rule (the message names it, its value and the rule); ``raw_grid``
        without ``clearance`` or ``footprint``; ``clearance`` or ``footprint`` without
        ``raw_grid``; ``footprint`` with ``clearance``; ``footprint_margin``,
        ``footprint_slack`` or ``footprint_min_slack`` without ``footprint``;
        ``footprint_min_slack`` above ``footprint_slack``.
    """

    raw_grid: OccupancyGrid | np.ndarray | None = None
    clearance: float | None = None
    footprint: ArrayLike | None = None
    footprint_margin: float = 0.0
    footprint_slack: float = DEFAULT_SLACK
    footprint_min_slack: float | None = None
    #: The polygons ``raw_grid`` was rasterised from, in the search's cells (cell ``(ix,
    #: iy)``'s centre at ``(ix, iy)``), or None: set from an ``OccupancyGrid`` ``raw_grid``
    #: whose :attr:`~astar.OccupancyGrid.polygons` are known. In the footprint mode a pose
    #: whose grown body meets an occupied square inside the grid is decided by its exact
    #: distance to them (:mod:`astar.hybrid_modes`).
    raw_polygons: tuple[np.ndarray, ...] | None = dataclasses.field(default=None, init=False)

    def __post_init__(self) -> None:
        rings = None
        if isinstance(self.raw_grid, OccupancyGrid) and self.raw_grid.polygons is not None:
            g = self.raw_grid
            shift = np.array([g.origin[0], g.origin[1]]) + 0.5 * g.resolution
            rings = tuple((v - shift) / g.resolution for v in g.polygons)
        object.__setattr__(self, "raw_polygons", rings)
        margin = validation.nonnegative_float("footprint_margin", self.footprint_margin, "cells")
        slack = validation.positive_float("footprint_slack", self.footprint_slack)
        min_slack = self.footprint_min_slack
        if min_slack is not None:
            min_slack = validation.positive_float("footprint_min_slack", min_slack)
            if min_slack > slack:
                raise InvalidInputError(
                    f"footprint_min_slack={min_slack!r} must be at most footprint_slack={slack!r}"
                )
        raw_grid, clearance, footprint = self.raw_grid, self.clearance, self.footprint
        if footprint is None:
            if slack != DEFAULT_SLACK:
                raise InvalidInputError(
                    f"footprint_slack={slack!r} is used only with footprint: pass a footprint "
                    f"or leave footprint_slack at {DEFAULT_SLACK}"
                )
            if margin != 0.0:
                raise InvalidInputError(
                    f"footprint_margin={margin!r} is used only with footprint: pass a "
                    "footprint or leave footprint_margin at 0"
                )
            if min_slack is not None:
                raise InvalidInputError(
                    f"footprint_min_slack={min_slack!r} is used only with footprint: pass a "
                    "footprint or leave footprint_min_slack at None"
                )
            if clearance is None:
                if raw_grid is not None:
                    raise InvalidInputError(
                        "raw_grid is used only with clearance or footprint: pass it with one "
                        "of them or not at all"
                    )
            else:
                clearance = validation.positive_float("clearance", clearance)
                if raw_grid is None:
                    raise InvalidInputError(
                        f"clearance={clearance!r} needs raw_grid (the raw map) to measure it on"
                    )
        else:
            footprint_polygon(footprint)
            if clearance is not None:
                raise InvalidInputError(
                    f"footprint and clearance={clearance!r} exclude each other: the footprint "
                    "mode checks the polygon itself (grow it with footprint_margin)"
                )
            footprint = np.array(footprint, dtype=np.float64)
            footprint.flags.writeable = False
            if raw_grid is None:
                raise InvalidInputError(
                    f"footprint={footprint.tolist()} needs raw_grid (the raw map) to be "
                    "checked against"
                )
        if raw_grid is not None:
            raw_grid = raw_occupied(raw_grid)
        object.__setattr__(self, "raw_grid", raw_grid)
        object.__setattr__(self, "clearance", clearance)
        object.__setattr__(self, "footprint", footprint)
        object.__setattr__(self, "footprint_margin", margin)
        object.__setattr__(self, "footprint_slack", slack)
        object.__setattr__(self, "footprint_min_slack", slack if min_slack is None else min_slack)

    @property
    def mode(self) -> str:
        """``"grid"`` (no check beyond the grid), ``"clearance"`` or ``"footprint"``."""
        if self.footprint is not None:
            return "footprint"
        return "grid" if self.clearance is None else "clearance"


_RECORDS: dict[str, type] = {
    "motion": HybridMotion,
    "costs": HybridCosts,
    "limits": HybridLimits,
    "collision": HybridCollision,
}

#: The keywords :func:`astar.find_pose_path` takes besides its records: every field of the
#: records, mapped to the record keyword (``"motion"``, ``"costs"``, ``"limits"``,
#: ``"collision"``) whose record it builds.
FLAT_KEYWORDS: dict[str, str] = {
    f.name: key for key, cls in _RECORDS.items() for f in dataclasses.fields(cls)
}


def build_options(
    motion: HybridMotion | None,
    costs: HybridCosts | None,
    limits: HybridLimits | None,
    collision: HybridCollision | None,
    flat: dict[str, Any],
) -> tuple[HybridMotion, HybridCosts, HybridLimits, HybridCollision]:
    """Return the four records of a :func:`astar.find_pose_path` call.

    Parameters
    ----------
    motion, costs, limits, collision : record or None
        The records passed (None: built from ``flat``, defaults for the fields not there).
    flat : dict
        The other keywords of the call: fields of the records by name
        (:data:`FLAT_KEYWORDS`).

    Returns
    -------
    tuple of HybridMotion, HybridCosts, HybridLimits, HybridCollision

    Raises
    ------
    TypeError
        A keyword that is no field of the records (as Python's own message for an unknown
        keyword), or neither ``motion`` nor ``turning_radius`` is given.
    InvalidInputError
        A record keyword holds another type, a field is given both inside its record and by
        name, or a field breaks its rule.
    """
    unknown = [name for name in flat if name not in FLAT_KEYWORDS]
    if unknown:
        raise TypeError(f"find_pose_path() got an unexpected keyword argument {unknown[0]!r}")
    given = {"motion": motion, "costs": costs, "limits": limits, "collision": collision}
    out = []
    for key, cls in _RECORDS.items():
        record = given[key]
        fields = {name: v for name, v in flat.items() if FLAT_KEYWORDS[name] == key}
        if record is None:
            if key == "motion" and "turning_radius" not in fields:
                raise TypeError(
                    "find_pose_path() missing 1 required keyword-only argument: "
                    "'turning_radius' (or pass motion=astar.HybridMotion(turning_radius=...))"
                )
            record = cls(**fields)
        elif not isinstance(record, cls):
            raise InvalidInputError(
                f"{key} must be an astar.{cls.__name__}, got {validation.short_repr(record)}"
            )
        elif fields:
            raise InvalidInputError(
                f"{', '.join(fields)} and {key}={cls.__name__}(...) exclude each other: give "
                f"{'it' if len(fields) == 1 else 'them'} inside the {cls.__name__} record or "
                f"pass no {key}"
            )
        out.append(record)
    return out[0], out[1], out[2], out[3]
