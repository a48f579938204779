"""What a planner is set up with (:class:`PlannerOptions`) and what one query asks (:class:`PlanRequest`).

:class:`PlannerOptions` is the one definition of the planner's settings: their names, types,
defaults, documentation and validation. :func:`trajopt.plan` and :class:`trajopt.Planner`
take them as keywords derived from its fields (:meth:`PlannerOptions.from_keywords`), so the
two cannot disagree on a setting, its default or its validation.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from astar.costmap import Costmap
from astar.grid import OccupancyGrid
from trajopt.errors import InvalidInputError
from trajopt.robot import Robot, State, avoidance_width
from trajopt.smoother import Smoother
from trajopt.timing import SpeedLimits, check_overlap
from trajopt.validation import heading, integer, number

Inflation = Literal["exact", "paper"]
Search = Literal["clearance", "shortest", "costmap", "costmap+clearance"]
Fallback = Literal["stop_and_turn"]
CorridorKind = Literal["polygons", "boxes"]
SearchMode = Literal["auto", "exact", "coarse"]
INFLATIONS = ("exact", "paper")
SEARCHES = ("clearance", "shortest", "costmap", "costmap+clearance")
FALLBACKS = (None, "stop_and_turn")
CORRIDORS = ("polygons", "boxes")
SEARCH_MODES = ("auto", "exact", "coarse")
#: ``search_mode="auto"`` searches coarse-to-fine on inflated grids of at least this many
#: cells (smaller maps, and every map the tests and benchmarks used before, search exactly).
COARSE_MIN_CELLS = 1_500_000
#: ... and for queries whose ends are at least this many blocks apart (octile distance).
COARSE_MIN_BLOCKS = 16


@dataclass(frozen=True, slots=True)
class PlannerOptions:
    """A planner's settings, validated: the one definition of each setting and its default.

    :class:`trajopt.Planner` and :func:`trajopt.plan` take these fields by name as keywords
    (``Planner(grid, robot, corridor="boxes")``), or all of them as one value
    (``Planner(grid, options=PlannerOptions(...))``); the keywords accepted are this class's
    fields (:data:`SETTINGS`), with these defaults.

    Attributes
    ----------
    robot : Robot
        Size and limits; ``None`` is ``Robot()`` (the chapter's robot).
    inflation : {"exact", "paper"}
        ``"exact"`` (default): obstacles grown by ``robot.radius`` (square metric,
        certified). ``"paper"``: the chapter's avoidance area of ``w_cells`` rounds on top
        of it.
    w_cells : int or None
        ``W`` of ``inflation="paper"`` (cells, ``>= 0``); ``None`` (default) until
        :meth:`for_map` sets the default :func:`~trajopt.robot.avoidance_width` (11 on the
        paper scene).
    search : {"clearance", "shortest", "costmap", "costmap+clearance"} or None
        A* cost: clearance-aware (:func:`astar.clearance_cost`), plain shortest path, the
        costmap's graded cost (:meth:`astar.Costmap.search_cost` with ``costmap_weight``) or
        the sum of both. The costmap modes need the map to be a costmap. ``None``
        (default) until :meth:`for_map` picks ``"clearance"`` (occupancy grid) or
        ``"costmap"`` (costmap).
    smoother : Smoother
        Smoother options (e.g. ``Smoother(kappa_max=...)``); ``None`` is ``Smoother()``.
    timing_dt : float
        Step of the timing's forward greedy (s), in (0, 0.5]; default 0.02.
    fallback : {None, "stop_and_turn"}
        ``None`` (default): smoother and timing failures raise. ``"stop_and_turn"``: when
        they fail and both end speeds are 0, the planner returns a
        :class:`~trajopt.motion.StopAndTurnTrajectory` along the A* polyline, checked
        against the raw map (:mod:`trajopt._planner`); ``stats["fallback"]`` says so.
    corridor : {"polygons", "boxes"}
        ``"polygons"`` (default): convex polygons grown around the A* path in continuous
        space (:func:`~trajopt.corridor.build_polygon_corridor`), with the taut objective;
        where the polygon corridor cannot be built or the fit in it fails, the box corridor
        is tried next (``stats["corridor"]`` names the one used). ``"boxes"``: axis-aligned
        boxes of free cells only (:func:`~trajopt.corridor.build_corridor`). With
        ``inflation="paper"`` the corridor is always boxes (the polygons keep the radius
        from the raw map, not from the chapter's avoidance area).
    costmap_weight : float
        ``weight`` of :meth:`astar.Costmap.search_cost` (default 2: a step through the
        costliest graded cells costs three times its length).
    speed_limits : SpeedLimits or None
        Speed-limit zones (:func:`trajopt.load_speed_mask`): the timing caps the speed by the
        zone under the robot's centre (and the stop-and-turn fallback by the zones its
        segments cross). The mask is looked up in world coordinates with its own resolution
        and origin; a mask that does not overlap the map at all is refused. Default
        ``None``: none.
    landmarks : int
        ALT landmarks for the searches with a cost (:func:`astar.build_landmarks`), 0-64
        (0, the default: none). Exact either way; on large maps they cut a long search
        several times, for a one-time cost on the first query after each map (about 0.1 s
        per landmark per million cells; :meth:`trajopt.Planner.update_map` keeps them
        through changes that only add obstacles) and ``8 landmarks`` bytes per cell. A
        :func:`trajopt.plan` call builds them for its one query (``landmarks + 1`` searches
        of the whole map), which costs more than the search they shorten; they pay off
        across the queries of one :class:`~trajopt.Planner`.
    search_mode : {"auto", "exact", "coarse"}
        ``"exact"``: the optimal A* (:func:`astar.find_path`). ``"coarse"``: coarse-to-fine
        (:func:`astar.find_path_coarse_to_fine`): an A* over blocks of about the robot
        radius (:meth:`search_block_cells`), then the fine A* in a band of blocks around its
        path; the path's cost is proven at most ``bound`` times the optimum, with
        ``bound <= search_bound`` (otherwise, and when the blocks or the band hold no path,
        the exact search runs). ``"auto"`` (default): coarse-to-fine on inflated grids of
        at least :data:`COARSE_MIN_CELLS` cells for ends at least
        :data:`COARSE_MIN_BLOCKS` blocks apart, without landmarks; exact otherwise (so maps
        up to about 1 M cells plan exactly). ``stats["search_info"]`` reports the mode run,
        the block (cells and m), the bound and its lower bound, and any fallback. The
        blocks are computed on the first coarse search and kept through
        :meth:`trajopt.Planner.update_map` outside the changed window.
    search_bound : float
        The largest suboptimality a coarse-to-fine search may return, ``>= 1`` (default
        1.5; ``inf``: any); beyond it the exact search runs. Typical proven bounds are
        1.1-1.3 while the band path's actual cost is within a fraction of a percent of the
        optimum (``docs/concepts.md``).

    Raises
    ------
    InvalidInputError
        A setting of the wrong type or outside its range, naming it and its rule.
    """

    robot: Robot = field(default_factory=Robot)
    inflation: Inflation = "exact"
    w_cells: int | None = None
    search: Search | None = None
    smoother: Smoother = field(default_factory=Smoother)
    timing_dt: float = 0.02
    fallback: Fallback | None = None
    corridor: CorridorKind = "polygons"
    costmap_weight: float = 2.0
    speed_limits: SpeedLimits | None = None
    landmarks: int = 0
    search_mode: SearchMode = "auto"
    search_bound: float = 1.5

    def __post_init__(self) -> None:
        robot = Robot() if self.robot is None else self.robot
        if not isinstance(robot, Robot):
            raise InvalidInputError(f"robot must be a trajopt.Robot, got {type(robot).__name__}")
        if self.inflation not in INFLATIONS:
            raise InvalidInputError(
                f"inflation must be one of {INFLATIONS}, got {self.inflation!r}"
            )
        if self.search is not None and self.search not in SEARCHES:
            raise InvalidInputError(f"search must be one of {SEARCHES}, got {self.search!r}")
        fallback = self.fallback
        if not (fallback is None or (isinstance(fallback, str) and fallback in FALLBACKS)):
            raise InvalidInputError(f"fallback must be one of {FALLBACKS}, got {fallback!r}")
        corridor = self.corridor
        if not (isinstance(corridor, str) and corridor in CORRIDORS):
            raise InvalidInputError(f"corridor must be one of {CORRIDORS}, got {corridor!r}")
        landmarks = integer("landmarks", self.landmarks, 0, 64)
        mode = self.search_mode
        if not (isinstance(mode, str) and mode in SEARCH_MODES):
            raise InvalidInputError(f"search_mode must be one of {SEARCH_MODES}, got {mode!r}")
        bound = self.search_bound
        if (
            isinstance(bound, bool)
            or not isinstance(bound, (int, float, np.integer, np.floating))
            or not float(bound) >= 1.0
        ):
            raise InvalidInputError(
                f"search_bound must be a number >= 1 (the largest accepted ratio of the "
                f"path's cost to the optimal cost; inf: any), got {bound!r}"
            )
        w = self.w_cells
        if w is not None and (isinstance(w, bool) or not isinstance(w, (int, np.integer)) or w < 0):
            raise InvalidInputError(f"w_cells must be an integer >= 0, got {w!r}")
        dt = self.timing_dt
        if (
            isinstance(dt, bool)
            or not isinstance(dt, (int, float, np.integer, np.floating))
            or not 0.0 < float(dt) <= 0.5
        ):
            raise InvalidInputError(f"timing_dt must be a number in (0, 0.5] s, got {dt!r}")
        smoother = Smoother() if self.smoother is None else self.smoother
        if not isinstance(smoother, Smoother):
            raise InvalidInputError(
                f"smoother must be a trajopt.Smoother, got {type(smoother).__name__}"
            )
        object.__setattr__(self, "robot", robot)
        object.__setattr__(self, "smoother", smoother)
        object.__setattr__(self, "landmarks", int(landmarks))
        object.__setattr__(self, "search_bound", float(bound))
        object.__setattr__(self, "timing_dt", float(dt))
        object.__setattr__(self, "costmap_weight", float(self.costmap_weight))
        if w is not None:
            object.__setattr__(self, "w_cells", int(w))

    @classmethod
    def from_keywords(
        cls, options: PlannerOptions | None, settings: Mapping[str, Any], *, caller: str
    ) -> PlannerOptions:
        """Return the settings a call gave: ``options``, or built from the keywords.

        The keywords accepted are the fields of this class (:data:`SETTINGS`), read with
        :func:`dataclasses.fields`; their defaults are the fields' own. A keyword is *given*
        when its value is not its field's default (``None`` for a field with a default
        factory: ``robot``, ``smoother``).

        Parameters
        ----------
        options : PlannerOptions or None
            Every setting as one value; the keywords must then stay at their defaults.
        settings : mapping of str to object
            The keywords of the call (``robot`` among them), by name.
        caller : str
            The function called, for the messages (e.g. ``"trajopt.Planner"``).

        Raises
        ------
        TypeError
            A keyword that is not a setting (the message names it and lists the settings).
        InvalidInputError
            ``options`` is not a :class:`PlannerOptions`, or it comes with a keyword (or the
            robot) set as well; a setting of the wrong type or outside its range.
        """
        fields = dataclasses.fields(cls)
        unknown = [k for k in settings if k not in SETTINGS]
        if unknown:
            what = (
                "unexpected keyword arguments"
                if len(unknown) > 1
                else "an unexpected keyword argument"
            )
            raise TypeError(
                f"{caller}() got {what} "
                f"{', '.join(repr(k) for k in unknown)}; the planner's settings "
                f"(the fields of trajopt.PlannerOptions) are: {', '.join(SETTINGS)}"
            )
        if options is None:
            return cls(**settings)
        if not isinstance(options, PlannerOptions):
            raise InvalidInputError(
                f"options must be a trajopt.PlannerOptions, got {type(options).__name__}"
            )
        given = []
        for f in fields:
            if f.name not in settings:
                continue
            value, default = settings[f.name], _keyword_default(f)
            if value is not default and value != default:
                given.append(f.name)
        if given:
            raise InvalidInputError(
                f"give the planner's settings either as options or as keywords, not both: got "
                f"options and {', '.join(given)}"
            )
        return options

    def for_map(
        self, grid: OccupancyGrid | Costmap
    ) -> tuple[PlannerOptions, OccupancyGrid, Costmap | None]:
        """Return the options resolved for a map, the raw grid and the costmap (or ``None``).

        Picks the default search (``"costmap"`` for a costmap, else ``"clearance"``) and the
        default ``w_cells`` (:func:`~trajopt.robot.avoidance_width` at the map's resolution),
        and checks what depends on the map: a costmap search needs a costmap, the costmap
        weight, and speed-limit zones that overlap the map.

        Parameters
        ----------
        grid : astar.OccupancyGrid or astar.Costmap
            The raw map, or a costmap (its obstacle cells are the map).

        Raises
        ------
        InvalidInputError
            Naming the setting and the rule.
        """
        costmap: Costmap | None = None
        if isinstance(grid, Costmap):
            costmap, grid = grid, grid.grid
        if not isinstance(grid, OccupancyGrid):
            raise InvalidInputError(
                f"grid must be an astar.OccupancyGrid or astar.Costmap, got {type(grid).__name__}"
            )
        search = self.search
        if search is None:
            search = "clearance" if costmap is None else "costmap"
        if search.startswith("costmap") and costmap is None:
            raise InvalidInputError(
                f"search={search!r} needs the grid to be an astar.Costmap "
                "(astar.load_costmap / astar.from_costmap), got an OccupancyGrid"
            )
        if costmap is not None:
            costmap.search_cost(self.costmap_weight)  # validates the weight
        if self.speed_limits is not None:
            check_overlap(self.speed_limits, grid)
        w_cells = self.w_cells
        if w_cells is None:
            w_cells = avoidance_width(self.robot.width, grid.resolution)
        resolved = dataclasses.replace(self, search=search, w_cells=w_cells)
        return resolved, grid, costmap

    def search_block_cells(self, resolution: float) -> int:
        """Fine cells per block side of the coarse-to-fine search on a map of ``resolution`` (m).

        Blocks of about the robot radius (at least 2 cells), so the block follows the robot
        and the geometry, not the map's cell count. (On the willow map split to 1.7 cm,
        blocks of the radius searched 2-3 times faster than blocks of half of it, with the
        same bounds; the blocks' side connections, not whole free blocks, carry narrow
        passages.)
        """
        return max(2, int(round(self.robot.radius / resolution)))

    def disc(self, radius: float, *, last: bool) -> PlannerOptions:
        """Return the options of a footprint robot's disc model of ``radius`` (m).

        The disc has the robot's limits and drive and no footprint; it keeps the fallback
        only when ``last`` (the circumscribed disc, which holds the footprint in every
        heading).
        """
        disc = dataclasses.replace(self.robot, radius=radius, footprint=None)
        return dataclasses.replace(self, robot=disc, fallback=self.fallback if last else None)

    def with_budget(self, budget_s: float | None) -> PlannerOptions:
        """Return the options with the smoother's time budget capped at ``budget_s`` (s)."""
        if budget_s is None:
            return self
        sm = self.smoother
        capped = dataclasses.replace(sm, time_budget_s=min(sm.time_budget_s, budget_s))
        return dataclasses.replace(self, smoother=capped)


#: The planner's settings by name, in order: the fields of :class:`PlannerOptions` (the
#: keywords :class:`trajopt.Planner` and :func:`trajopt.plan` accept).
SETTINGS: tuple[str, ...] = tuple(f.name for f in dataclasses.fields(PlannerOptions))


def _keyword_default(f: dataclasses.Field) -> Any:
    """Return a setting's default as a keyword: the field's, ``None`` for a default factory."""
    return None if f.default is dataclasses.MISSING else f.default


@dataclass(frozen=True, slots=True)
class PlanRequest:
    """What one query asks: the ends, their headings and speeds.

    The headings are checked here (finite, in radians); the points and speeds by the stages
    that use them.

    Attributes
    ----------
    start : sequence of float, shape (2,), or State
        Start point ``(x, y)`` (m), or a moving robot's state (then ``start_heading`` and
        ``v_start`` stay at their defaults: the state's ``theta`` and ``v`` are used).
    goal : sequence of float, shape (2,)
        End point (m).
    start_heading, goal_heading : float or None
        Exact headings at the ends (rad). For an omnidirectional base, the orientation of
        the body (also with a :class:`State` start, whose ``theta`` is the direction of
        travel).
    v_start, v_end : float
        Speeds at the ends (m/s).
    start_omega, start_alpha : float
        An omnidirectional base's yaw rate (rad/s) and yaw acceleration (rad/s^2) at the
        start: a re-plan continues the orientation of a body that is turning (default 0;
        finite here, within the yaw limits where the orientation is planned).
    start_steer : float
        A car's steering angle at the start (rad, default 0: the wheels straight), which a
        car with a ``wheelbase`` and a ``steer_rate_max`` turns at rest onto its first
        drive's (:func:`~trajopt.planning._car.plan_car`); finite here, within the car's
        largest angle ``atan(wheelbase / min_turning_radius)`` there. Another drive, or a
        car without a wheelbase, refuses any other value (:func:`check_steer`).
    goal_steer : float or None
        A car's steering angle asked for at the goal (rad), turned to at rest after the
        last drive; ``None`` (default): whatever the last drive ends with.
    check_curve : callable or None
        ``check_curve(curve)``: called by a disc robot's stages
        (:func:`~trajopt.planning._disc.plan_disc`, without a footprint) on the certified
        curve (:class:`~trajopt.smoother.SmoothPath`) before it is timed; whatever it raises
        ends the query. A plan among movers proves there that its path is blocked, before
        paying for the timing (:func:`~trajopt.planning.plan_among_movers`). Default
        ``None``: nothing is called. Not part of the request's equality.
    check_grid_path : callable or None
        ``check_grid_path(points)``: called by the same stages on the search's grid path
        (its cell centres from the start point to the goal point, m, shape (k, 2), the
        exact ends in place of their cells' centres) before the corridor and the fit;
        whatever it raises ends the query. A plan among movers screens there for a mover
        that blocks the path, before paying for the fit
        (:func:`~trajopt.planning.plan_among_movers`). Default ``None``. Not part of the
        request's equality.
    """

    start: Sequence[float] | State
    goal: Sequence[float]
    start_heading: float | None = None
    goal_heading: float | None = None
    v_start: float = 0.0
    v_end: float = 0.0
    start_omega: float = 0.0
    start_alpha: float = 0.0
    start_steer: float = 0.0
    goal_steer: float | None = None
    check_curve: Callable[[Any], None] | None = field(default=None, compare=False)
    check_grid_path: Callable[[np.ndarray], None] | None = field(default=None, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "start_heading", heading("start_heading", self.start_heading))
        object.__setattr__(self, "goal_heading", heading("goal_heading", self.goal_heading))
        object.__setattr__(
            self, "start_omega", number("start_omega", self.start_omega, unit="rad/s")
        )
        object.__setattr__(
            self, "start_alpha", number("start_alpha", self.start_alpha, unit="rad/s^2")
        )
        object.__setattr__(self, "start_steer", number("start_steer", self.start_steer, unit="rad"))
        object.__setattr__(self, "goal_steer", heading("goal_steer", self.goal_steer))
