"""What a benchmark runs on: maps with their queries, and the named suites.

A :class:`MapQueries` is one map file, the robot radius used on it and the queries
(start/goal cells) to plan. Two sources make them:

* :func:`movingai_queries`: the scenarios of a Moving AI ``.scen`` file (all of them, or
  ``limit`` spread evenly over the file, which is sorted by difficulty bucket);
* :func:`random_queries`: seeded random start/goal pairs on any map
  :func:`astar.load_map` reads (ROS map_server ``.yaml`` maps in the shared suites), drawn
  among the cells free for the robot and in the same 4-connected free region, so that every
  query has a path for the radius.

Both check their inputs before any work starts and raise
:class:`~trajopt.errors.BenchmarkError` naming the file and the rule broken (missing map,
scenario file written for another map size, ...). :func:`suite` returns the named suites
``shared-small`` and ``shared-full`` over the shared map folder (``$TRAJOPT_DATA``).
"""

from __future__ import annotations

import dataclasses
import logging
import math
import os
import zlib
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import numpy as np

from trajopt.errors import BenchmarkError

logger = logging.getLogger(__name__)

#: Robot radius on Moving AI maps, in cells (1 m cells): the setup of the project's
#: Moving AI benchmarks (``Robot(radius=2.5 * resolution)``).
DEFAULT_RADIUS_CELLS = 2.5
#: Robot radius on ROS maps (m): :class:`trajopt.Robot`'s default footprint.
DEFAULT_RADIUS_M = 0.165
SourceKind = Literal["movingai", "random"]


@dataclass(frozen=True, slots=True)
class Query:
    """One start/goal query on a map.

    Attributes
    ----------
    query_id : str
        Unique within a dataset: ``"<map file>/<source>/<index>"``.
    index : int
        Position in its source (line order of the ``.scen`` file, or draw number).
    bucket : int
        Moving AI difficulty bucket; ``-1`` for random queries.
    start, goal : tuple of int
        Cells ``(ix, iy)``, row 0 at the bottom (the project's convention).
    optimal_length_cells : float
        The scenario file's optimal length (cells); NaN for random queries.
    start_heading, goal_heading : float
        End headings (rad) for the methods that plan poses (the car-like robots); NaN
        (the default) when the query has none: :func:`with_headings` draws them, and the
        car methods draw them with :func:`draw_headings` (seed 0) when they are NaN.
    """

    query_id: str
    index: int
    bucket: int
    start: tuple[int, int]
    goal: tuple[int, int]
    optimal_length_cells: float
    start_heading: float = math.nan
    goal_heading: float = math.nan


@dataclass(frozen=True, slots=True)
class MapQueries:
    """A map file, the robot radius used on it, and its queries.

    Attributes
    ----------
    map_path : str
        Absolute path of the map file (``.map``, ``.yaml``, ...).
    map_name : str
        The map's file name (the ``map`` column of the dataset).
    source : str
        ``"scen"`` (a Moving AI scenario file) or ``"random-seed<S>"``.
    radius_m : float
        Robot radius (m, > 0).
    resolution_m : float
        Cell size of the map (m).
    queries : tuple of Query
    """

    map_path: str
    map_name: str
    source: str
    radius_m: float
    resolution_m: float
    queries: tuple[Query, ...]


def draw_headings(map_name: str, index: int, seed: int = 0) -> tuple[float, float]:
    """Seeded random start and goal headings of one query (rad, uniform in ``[-pi, pi)``).

    The generator is ``numpy.random.default_rng([seed, crc32(map_name), index])`` (the rule of
    ``benchmarks/bench_hybrid.py``): the same headings on every machine, for every method.

    Parameters
    ----------
    map_name : str
        The map's file name (:attr:`MapQueries.map_name`).
    index : int
        The query's :attr:`Query.index` (>= 0).
    seed : int
        Seed (>= 0).

    Returns
    -------
    tuple of float
        ``(start_heading, goal_heading)`` (rad).
    """
    rng = np.random.default_rng([int(seed), zlib.crc32(map_name.encode()), int(index)])
    h0, h1 = rng.uniform(-math.pi, math.pi, 2)
    return float(h0), float(h1)


def with_headings(sources: Sequence[MapQueries], seed: int = 0) -> list[MapQueries]:
    """Return ``sources`` with seeded random end headings on every query (:func:`draw_headings`).

    Queries and maps are otherwise unchanged (same ids, cells and order); only the pose
    methods (``trajopt-ackermann``, ``ompl-reedsshepp``, ...) read the headings.

    Raises
    ------
    BenchmarkError
        ``seed`` is not an integer >= 0.
    """
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise BenchmarkError(f"seed must be an integer >= 0, got {seed!r}")
    out = []
    for mq in sources:
        qs = []
        for q in mq.queries:
            h0, h1 = draw_headings(mq.map_name, q.index, int(seed))
            qs.append(dataclasses.replace(q, start_heading=h0, goal_heading=h1))
        out.append(dataclasses.replace(mq, queries=tuple(qs)))
    return out


def data_dir(path: str | os.PathLike[str] | None = None) -> Path:
    """Return the shared data folder.

    ``path``, else ``$TRAJOPT_DATA``, else ``shared/data`` beside the repository checkout that
    holds this package.

    Raises
    ------
    BenchmarkError
        The folder has no ``movingai`` and ``ros`` subfolders.
    """
    if path is not None:
        d = Path(path)
    elif os.environ.get("TRAJOPT_DATA"):
        d = Path(os.environ["TRAJOPT_DATA"])
    else:
        checkout = Path(__file__).resolve().parents[3]  # trajopt/analysis/bench/ -> the checkout
        d = checkout.parent / "shared" / "data"
    if not ((d / "movingai").is_dir() and (d / "ros").is_dir()):
        raise BenchmarkError(
            f"data folder {str(d)!r} must hold the shared 'movingai' and 'ros' folders; "
            "set TRAJOPT_DATA or pass the folder"
        )
    return d


def select_evenly(items: Sequence, limit: int | None) -> list:
    """``limit`` items spread evenly over ``items``.

    ``limit`` items spread evenly over ``items`` (the first and the last always included; all
    when ``limit`` is None or >= the length). Deterministic.
    """
    n = len(items)
    if limit is None or limit >= n:
        return list(items)
    if isinstance(limit, bool) or not isinstance(limit, (int, np.integer)) or limit < 1:
        raise BenchmarkError(f"limit must be an integer >= 1 or None, got {limit!r}")
    idx = np.unique(np.round(np.linspace(0, n - 1, int(limit))).astype(int))
    return [items[i] for i in idx]


def _positive(name: str, value: object) -> float:
    try:
        v = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        v = math.nan
    if not (math.isfinite(v) and v > 0):
        raise BenchmarkError(f"{name} must be a finite number > 0, got {value!r}")
    return v


def _load(map_path: Path):
    import astar

    if not map_path.is_file():
        raise BenchmarkError(f"map {str(map_path)!r} does not exist")
    try:
        return astar.load_map(map_path)
    except (astar.AstarError, OSError) as exc:
        raise BenchmarkError(f"map {str(map_path)!r} cannot be read: {exc}") from exc


def _find_map(scen: Path, map_name: str) -> Path:
    for cand in (scen.parent / map_name, scen.parent.parent / "maps" / map_name):
        if cand.is_file():
            return cand
    raise BenchmarkError(
        f"map {map_name!r} named by {str(scen)!r} was found neither beside it nor in ../maps; "
        "give the map path"
    )


def movingai_queries(
    scen_path: str | os.PathLike[str],
    map_path: str | os.PathLike[str] | None = None,
    *,
    limit: int | None = None,
    radius_cells: float = DEFAULT_RADIUS_CELLS,
    feasible_only: bool = False,
    allow_empty: bool = False,
) -> MapQueries:
    """Return the scenarios of a Moving AI ``.scen`` file as a :class:`MapQueries`.

    Parameters
    ----------
    scen_path : str or os.PathLike
        The ``.scen`` file (version 1).
    map_path : str or os.PathLike, optional
        Its ``.map`` file; default: the map the scenarios name, beside the ``.scen`` or in
        ``../maps``.
    limit : int, optional
        Keep ``limit`` scenarios spread evenly over the file (:func:`select_evenly`).
    radius_cells : float
        Robot radius in cells (> 0); the radius in metres is ``radius_cells * resolution``.
    feasible_only : bool
        Keep only the scenarios whose start and goal cells are free on the grid inflated by
        the radius (``astar.inflate(..., metric="square", outside_occupied=True)``) and in
        the same 4-connected free region of it (then an octile path without corner cutting
        exists), before ``limit`` picks among them. Most Moving AI scenarios start or end next to a wall,
        where a robot wider than a cell cannot stand.
    allow_empty : bool
        Return a :class:`MapQueries` without queries when ``feasible_only`` leaves none
        (instead of raising).

    Raises
    ------
    BenchmarkError
        Missing or unreadable files, an empty or malformed scenario file, scenarios naming
        several maps, a scenario file whose map size is not the map's, or no feasible
        scenario (``feasible_only`` without ``allow_empty``).
    """
    import astar

    scen = Path(scen_path)
    r_cells = _positive("radius_cells", radius_cells)
    if not scen.is_file():
        raise BenchmarkError(f"scenario file {str(scen)!r} does not exist")
    try:
        scenarios = astar.read_scenarios(scen)
    except (astar.AstarError, OSError) as exc:
        raise BenchmarkError(f"scenario file {str(scen)!r} cannot be read: {exc}") from exc
    if not scenarios:
        raise BenchmarkError(f"scenario file {str(scen)!r} holds no scenarios")
    names = sorted({s.map_name for s in scenarios})
    if len(names) != 1:
        raise BenchmarkError(f"scenario file {str(scen)!r} names {len(names)} maps {names}; need 1")
    mp = Path(map_path) if map_path is not None else _find_map(scen, names[0])
    grid = _load(mp)
    ny, nx = grid.occupied.shape
    sizes = sorted({(s.width, s.height) for s in scenarios})
    if sizes != [(nx, ny)]:
        raise BenchmarkError(
            f"scenario file {str(scen)!r} is for maps of {sizes[0][0]} x {sizes[0][1]} cells "
            f"(width x height) but map {str(mp)!r} is {nx} x {ny}: the sizes must match"
        )
    indexed = list(enumerate(scenarios))
    if feasible_only:
        inflated = astar.inflate(
            grid, r_cells * float(grid.resolution), metric="square", outside_occupied=True
        )
        import scipy.ndimage as ndi

        labels, _ = ndi.label(~np.asarray(inflated.occupied))  # 4-connected free regions

        def connected(s: astar.Scenario) -> bool:
            a = labels[s.start[1], s.start[0]]
            return bool(a > 0 and a == labels[s.goal[1], s.goal[0]])

        indexed = [(i, s) for i, s in indexed if connected(s)]
        if not indexed and not allow_empty:
            raise BenchmarkError(
                f"no scenario of {str(scen)!r} has both end cells free and connected for the radius "
                f"{r_cells} cells (feasible_only=True)"
            )
    indexed = select_evenly(indexed, limit) if indexed else []
    name = mp.name
    queries = tuple(
        Query(
            query_id=f"{name}/scen/{i}",
            index=i,
            bucket=int(s.bucket),
            start=(int(s.start[0]), int(s.start[1])),
            goal=(int(s.goal[0]), int(s.goal[1])),
            optimal_length_cells=float(s.optimal_length),
        )
        for i, s in indexed
    )
    res = float(grid.resolution)
    return MapQueries(str(mp.resolve()), name, "scen", r_cells * res, res, queries)


def random_queries(
    map_path: str | os.PathLike[str],
    n: int,
    *,
    seed: int = 0,
    radius_m: float = DEFAULT_RADIUS_M,
    min_distance_cells: float = 10.0,
) -> MapQueries:
    """``n`` seeded random start/goal pairs on a map, each with a path for the radius.

    Start and goal are cell centres free on the planner's inflated grid
    (``astar.inflate(grid, radius_m, metric="square", outside_occupied=True)``), in the same
    4-connected free region (so an octile path exists), at least ``min_distance_cells``
    apart. The generator is ``numpy.random.default_rng([seed, crc32(map file name)])``: the
    same seed gives the same queries on every machine.

    Parameters
    ----------
    map_path : str or os.PathLike
        Any map :func:`astar.load_map` reads without extra arguments (ROS ``.yaml``,
        Moving AI ``.map``).
    n : int
        Number of queries (>= 1).
    seed : int
        Seed (>= 0).
    radius_m : float
        Robot radius (m, > 0).
    min_distance_cells : float
        Smallest start-goal distance (cells, >= 0).

    Raises
    ------
    BenchmarkError
        Missing or unreadable map, bad ``n``/``seed``/radius, or no free region large
        enough for a query.
    """
    import scipy.ndimage as ndi

    import astar

    mp = Path(map_path)
    r = _positive("radius_m", radius_m)
    for nm, v in (("n", n), ("seed", seed)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < (nm == "n"):
            raise BenchmarkError(f"{nm} must be an integer >= {int(nm == 'n')}, got {v!r}")
    grid = _load(mp)
    inflated = astar.inflate(grid, r, metric="square", outside_occupied=True)
    free = ~np.asarray(inflated.occupied)
    labels, _ = ndi.label(free)
    rng = np.random.default_rng([int(seed), zlib.crc32(mp.name.encode())])
    counts = np.bincount(labels.ravel())
    counts[0] = 0
    if counts.max(initial=0) < 2:
        raise BenchmarkError(
            f"map {str(mp)!r} has no free region of 2 cells or more for radius {r} m"
        )
    cells = np.argwhere(labels > 0)  # (iy, ix)
    out: list[Query] = []
    attempts = 0
    while len(out) < n:
        attempts += 1
        if attempts > 1000 * n:
            raise BenchmarkError(
                f"map {str(mp)!r}: found only {len(out)} of {n} start/goal pairs at least "
                f"{min_distance_cells} cells apart in one free region for radius {r} m"
            )
        iy0, ix0 = cells[rng.integers(len(cells))]
        region = np.argwhere(labels == labels[iy0, ix0])
        iy1, ix1 = region[rng.integers(len(region))]
        if math.hypot(float(ix1 - ix0), float(iy1 - iy0)) < min_distance_cells:
            continue
        i = len(out)
        out.append(
            Query(
                f"{mp.name}/random-seed{seed}/{i}",
                i,
                -1,
                (int(ix0), int(iy0)),
                (int(ix1), int(iy1)),
                math.nan,
            )
        )
    res = float(grid.resolution)
    return MapQueries(str(mp.resolve()), mp.name, f"random-seed{seed}", r, res, tuple(out))


#: The named suites: per Moving AI map the number of scenarios (``None``: all), per ROS map
#: the number of seeded random queries (seed 0).
SUITES: dict[str, dict[str, dict[str, int | None]]] = {
    "shared-small": {
        "movingai": {"den312d": 4, "rmtst01": 4, "Berlin_0_256": 4},
        "ros": {"turtlebot3_world": 4, "smoothers_world": 4},
    },
    "shared-full": {
        "movingai": {
            name: None
            for name in (
                "den312d",
                "rmtst01",
                "Berlin_0_256",
                "AR0046SR",
                "random512-40-5",
                "maze512-1-0",
                "Boston_0_1024",
            )
        },
        "ros": {
            "turtlebot3_world": 100,
            "smoothers_world": 100,
            "depot": 100,
            "willow-2010-02-18-0.10": 100,
        },
    },
}


def suite(
    name: str,
    data: str | os.PathLike[str] | None = None,
    *,
    limit: int | None = None,
    radius_cells: float = DEFAULT_RADIUS_CELLS,
    radius_m: float = DEFAULT_RADIUS_M,
    seed: int = 0,
) -> list[MapQueries]:
    """Return a named suite of the shared maps (:data:`SUITES`).

    ``shared-small``: a few scenarios of three Moving AI maps and a few random
    queries on two ROS maps (a minute on one core); ``shared-full``: every scenario of seven
    shared Moving AI maps (not ``arena``: none of its scenarios is feasible for 2.5 cells) and
    100 random queries on each of the four ROS maps (hours of CPU: a cluster job). The Moving
    AI scenarios are those feasible for the radius (``movingai_queries(..., feasible_only=True)``);
    a map with none (``random512-40-5`` and ``maze512-1-0`` at 2.5 cells: their passages are
    narrower than the robot) is left out with a logged warning.

    Parameters
    ----------
    name : {"shared-small", "shared-full"}
    data : str or os.PathLike, optional
        The shared data folder (default :func:`data_dir`).
    limit : int, optional
        At most this many scenarios / random queries per map.
    radius_cells : float
        Robot radius on the Moving AI maps (cells).
    radius_m : float
        Robot radius on the ROS maps (m).
    seed : int
        Seed of the random queries.

    Raises
    ------
    BenchmarkError
        Unknown suite name, missing data folder or files, or no feasible query on any map.
    """
    if name not in SUITES:
        raise BenchmarkError(f"suite must be one of {sorted(SUITES)}, got {name!r}")
    root = data_dir(data)
    spec = SUITES[name]
    out: list[MapQueries] = []
    for m, k in spec["movingai"].items():
        lim = k if limit is None else (limit if k is None else min(k, limit))
        mq = movingai_queries(
            root / "movingai" / "scen" / f"{m}.map.scen",
            root / "movingai" / "maps" / f"{m}.map",
            limit=lim,
            radius_cells=radius_cells,
            feasible_only=True,
            allow_empty=True,
        )
        if mq.queries:
            out.append(mq)
        else:
            logger.warning(
                "suite %s: no scenario of %s is feasible for the radius %g cells; map left out",
                name,
                m,
                radius_cells,
            )
    for m, k in spec["ros"].items():
        n = int(k if limit is None else min(int(k or 0), limit))
        out.append(random_queries(root / "ros" / f"{m}.yaml", n, seed=seed, radius_m=radius_m))
    if not any(mq.queries for mq in out):
        raise BenchmarkError(
            f"suite {name!r} has no feasible query for radius_cells="
            f"{radius_cells} and radius_m={radius_m}"
        )
    return out
