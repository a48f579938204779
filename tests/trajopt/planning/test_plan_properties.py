"""Tests of trajopt.planning: a property-based test of the whole pipeline (issue 7, section 1).

Over random grids (20-300 cells per side, mostly small; open, random rectangles, random
noise or both at densities 0-40 %), random robot radii and limits and random start/goal
points in world metres, :func:`trajopt.plan` must either

* return a trajectory that keeps a clearance ``>= robot.radius`` from the *raw* map on
  dense samples (computed here by brute force: point to occupied square, the outside of the
  map counts as occupied), starts and ends exactly at the given points (1e-9 m), has a
  continuous heading (between two samples it turns by no more than ``omega_max * dt``
  allows) and holds every limit on dense samples (speed against the curvature-dependent
  cap, ``|a|``, ``|jerk|``, lateral acceleration, yaw rate, wheel speeds; 0.1 % tolerance),
* or raise one of ``NoPathError``, ``SmoothingError``, ``TimingError``,
  ``InvalidInputError`` with a non-empty message.

Any other exception fails the test. The outcomes are counted: on *easy* cases (an open
grid, start and goal well inside free space and at least two cells apart) at most
``EASY_FAILURE_LIMIT`` may raise, so that a planner that always raises cannot pass.

The default run checks ``N_EXAMPLES`` examples; the ``slow`` variant (``pytest -m slow``)
checks 10 000 (see also ``benchmarks/robustness_long_run.py``).
"""

from __future__ import annotations

import math
import time
from collections import Counter
from dataclasses import dataclass
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st
from scipy import ndimage

import astar
import trajopt
from tests.reference import square_clearance
from trajopt.errors import InvalidInputError, NoPathError, SmoothingError, TimingError

#: The documented failures of :func:`trajopt.plan`.
DOCUMENTED_ERRORS = (NoPathError, SmoothingError, TimingError, InvalidInputError)
#: Examples of the default (CI) run and of the slow run.
N_EXAMPLES = 300
N_EXAMPLES_SLOW = 10_000
#: Largest fraction of easy cases allowed to raise (expected: 0).
EASY_FAILURE_LIMIT = 0.05
#: Relative tolerance on every limit, checked on dense samples.
LIMIT_TOL = 1e-3
#: Dense samples per trajectory (plus every phase start).
N_SAMPLES = 2000
#: Exact endpoints: absolute tolerance (m).
ENDPOINT_TOL = 1e-9


# ------------------------------------------------------------------ the cases
@dataclass(frozen=True)
class CaseParams:
    """Everything that defines one example; :func:`build_case` turns it into inputs.

    The repr is the reproduction recipe of a failing example: ``build_case(CaseParams(...))``.
    """

    nx: int
    ny: int
    resolution: float
    origin: tuple[float, float]
    kind: str  # "open", "rects", "noise", "mixed"
    density: float  # target obstacle fraction, 0 .. 0.4
    seed: int
    radius_cells: float
    limits: tuple[float, float, float, float, float]  # v_max, a_max, j_max, a_lat_max, omega_max
    wheels: tuple[float, float] | None  # (track_width, wheel_v_max) or None
    placement: str  # "free": inside free space; "anywhere": any point, may be outside
    start_u: tuple[float, float]
    goal_u: tuple[float, float]
    search: str


@dataclass(frozen=True)
class Case:
    params: CaseParams
    grid: astar.OccupancyGrid
    robot: trajopt.Robot
    start: tuple[float, float]
    goal: tuple[float, float]
    easy: bool


_SMALL = st.integers(20, 36)
#: Grid sides: 80 % 20-36 cells, 14 % 37-100, 6 % 101-300 (most examples small, for speed).
_SIDE = st.one_of(*[_SMALL] * 40, *[st.integers(37, 100)] * 7, *[st.integers(101, 300)] * 3)


def _log_uniform(rng: np.random.Generator, lo: float, hi: float) -> float:
    return float(np.exp(rng.uniform(np.log(lo), np.log(hi))))


@st.composite
def case_params(draw: Any) -> CaseParams:
    """Random grid, robot and query parameters.

    The structural choices (sizes, kind, density, radius, placement) are hypothesis draws,
    so failures shrink along them; the many continuous values (limits, origin, end points)
    come from a seeded generator, which keeps each example cheap to draw.
    """
    nx, ny = draw(_SIDE), draw(_SIDE)
    kind = draw(st.sampled_from(["open", "open", "rects", "noise", "mixed"]))
    density = 0.0 if kind == "open" else draw(st.floats(0.0, 0.4))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    limits = tuple(
        _log_uniform(rng, lo, hi)
        for lo, hi in ((0.05, 3.0), (0.05, 5.0), (0.1, 20.0), (0.05, 5.0), (0.1, 6.0))
    )
    wheels = None
    if rng.random() < 0.6:
        wheels = (_log_uniform(rng, 0.05, 1.0), _log_uniform(rng, 0.05, 4.0))
    return CaseParams(
        nx=nx,
        ny=ny,
        resolution=draw(st.sampled_from([0.02, 0.05, 0.1, 0.25, 1.0, 1.9])),
        origin=(float(rng.uniform(-50.0, 50.0)), float(rng.uniform(-50.0, 50.0))),
        kind=kind,
        density=density,
        seed=seed,
        radius_cells=draw(st.floats(0.3, 4.0)),
        limits=limits,  # type: ignore[arg-type]
        wheels=wheels,
        placement=draw(st.sampled_from(["free", "free", "anywhere"])),
        start_u=(float(rng.random()), float(rng.random())),
        goal_u=(float(rng.random()), float(rng.random())),
        search=draw(st.sampled_from(["clearance", "clearance", "shortest"])),
    )


def _obstacles(p: CaseParams, rng: np.random.Generator) -> np.ndarray:
    occ = np.zeros((p.ny, p.nx), bool)
    if p.kind == "open" or p.density <= 0.0:
        return occ
    target = p.density * occ.size
    if p.kind in ("rects", "mixed"):
        goal = target if p.kind == "rects" else 0.6 * target
        side = max(2, min(p.nx, p.ny) // 4)
        for _ in range(200):
            if occ.sum() >= goal:
                break
            w, h = rng.integers(1, side + 1, size=2)
            x0, y0 = rng.integers(0, p.nx - w + 1), rng.integers(0, p.ny - h + 1)
            occ[y0 : y0 + h, x0 : x0 + w] = True
    if p.kind in ("noise", "mixed"):
        need = max(0.0, target - occ.sum()) / occ.size
        occ |= rng.random(occ.shape) < need
    return occ


def _point(
    p: CaseParams, u: tuple[float, float], safe: np.ndarray, grid: astar.OccupancyGrid
) -> tuple[float, float]:
    ox, oy = grid.origin
    if p.placement == "anywhere" or not safe.any():
        # anywhere in the map or up to 10 % outside it
        return (ox + (1.2 * u[0] - 0.1) * grid.width, oy + (1.2 * u[1] - 0.1) * grid.height)
    cells = np.argwhere(safe)  # (iy, ix)
    iy, ix = cells[min(int(u[0] * len(cells)), len(cells) - 1)]
    jitter = 0.6 * (u[1] - 0.5)  # within +-0.3 cells of the centre
    res = grid.resolution
    return (ox + (ix + 0.5 + jitter) * res, oy + (iy + 0.5 - jitter) * res)


def build_case(p: CaseParams) -> Case:
    """The grid, robot, start and goal of one example (deterministic in ``p``)."""
    rng = np.random.default_rng([p.seed, 1])
    occ = _obstacles(p, rng)
    grid = astar.OccupancyGrid(occ, p.resolution, p.origin)
    radius = p.radius_cells * p.resolution
    v, a, j, alat, om = p.limits
    tw, wv = (None, None) if p.wheels is None else p.wheels
    robot = trajopt.Robot(
        radius=radius,
        v_max=v,
        a_max=a,
        j_max=j,
        a_lat_max=alat,
        omega_max=om,
        track_width=tw,
        wheel_v_max=wv,
    )
    # cells whose centre is at least radius + 1.2 cells from every occupied cell centre
    # and the outside (so a point within 0.3 cells of the centre clears the squares by
    # more than the radius)
    padded = np.pad(~occ, 1, constant_values=False)
    dist = ndimage.distance_transform_edt(padded)[1:-1, 1:-1]
    safe = dist >= p.radius_cells + 1.2
    start = _point(p, p.start_u, safe, grid)
    goal = _point(p, p.goal_u, safe, grid)
    cs, cg = grid.world_to_cell(start), grid.world_to_cell(goal)
    easy = (
        p.kind == "open"
        and p.placement == "free"
        and bool(safe.any())
        and float(np.max(np.abs(cs - cg))) >= 2
    )
    return Case(p, grid, robot, start, goal, easy)


# ------------------------------------------------------------------ the checks
def check_trajectory(case: Case, traj: trajopt.Trajectory) -> None:
    """Every guarantee of a returned trajectory, on dense samples."""
    robot, grid = case.robot, case.grid
    T = traj.duration
    assert math.isfinite(T) and T > 0.0, T
    t = np.union1d(np.linspace(0.0, T, N_SAMPLES), traj.phase_t[traj.phase_t <= T])
    smp = traj.sample(t)
    for name, arr in smp.as_dict().items():
        assert np.all(np.isfinite(arr)), f"non-finite {name}"
    # exact endpoints
    assert abs(smp.x[0] - case.start[0]) <= ENDPOINT_TOL, (smp.x[0], case.start)
    assert abs(smp.y[0] - case.start[1]) <= ENDPOINT_TOL, (smp.y[0], case.start)
    assert abs(smp.x[-1] - case.goal[0]) <= ENDPOINT_TOL, (smp.x[-1], case.goal)
    assert abs(smp.y[-1] - case.goal[1]) <= ENDPOINT_TOL, (smp.y[-1], case.goal)
    # clearance from the raw map (absolute slack for rounding at |coordinates| ~ 1e2 m)
    pts = np.c_[smp.x, smp.y]
    clr = square_clearance(grid, pts, reach=2.0 * robot.radius + grid.resolution)
    k = int(np.argmin(clr))
    assert clr[k] >= robot.radius - 1e-9, (
        f"clearance {clr[k]!r} m < radius {robot.radius!r} m at t={t[k]!r} s, "
        f"point {pts[k].tolist()}"
    )
    # progress along the path, continuous heading
    assert np.all(np.diff(smp.s) >= -1e-12)
    assert np.all(smp.v >= -1e-9)
    dtheta = np.abs(np.diff(smp.theta))
    allowed = robot.omega_max * np.diff(t) * (1 + LIMIT_TOL) + 1e-6
    k = int(np.argmax(dtheta - allowed))
    assert dtheta[k] <= allowed[k], (
        f"heading jumps by {dtheta[k]!r} rad between t={t[k]!r} and {t[k + 1]!r} s "
        f"(omega_max allows {allowed[k]!r})"
    )
    # limits
    tol = 1.0 + LIMIT_TOL
    cap = np.asarray(robot.speed_cap(smp.kappa))
    k = int(np.argmax(smp.v - cap * tol))
    assert smp.v[k] <= cap[k] * tol + 1e-12, (
        f"speed {smp.v[k]!r} m/s above the cap {cap[k]!r} at t={t[k]!r} s "
        f"(kappa {smp.kappa[k]!r} 1/m)"
    )
    for name, arr, lim in (
        ("v", smp.v, robot.v_max),
        ("a", smp.a, robot.a_max),
        ("jerk", smp.jerk, robot.j_max),
        ("a_lat", smp.a_lat, robot.a_lat_max),
        ("omega", smp.omega, robot.omega_max),
    ):
        worst = float(np.max(np.abs(arr)))
        assert worst <= lim * tol, f"|{name}| reaches {worst!r}, limit {lim!r}"
    if robot.track_width is not None:
        for name in ("v_left", "v_right"):
            worst = float(np.max(np.abs(getattr(smp, name))))
            assert worst <= robot.wheel_v_max * tol, (
                f"|{name}| reaches {worst!r}, limit {robot.wheel_v_max!r}"
            )


def run_case(case: Case) -> str:
    """Plan one case and check it: ``"ok"`` or the name of the documented error raised."""
    try:
        traj = trajopt.plan(case.grid, case.start, case.goal, case.robot, search=case.params.search)
    except DOCUMENTED_ERRORS as exc:
        assert str(exc).strip(), f"{type(exc).__name__} with an empty message"
        return type(exc).__name__
    check_trajectory(case, traj)
    return "ok"


# ------------------------------------------------------------------ the runs
def run_property(
    n_examples: int,
    counts: Counter | None = None,
    *,
    keep_going: bool = False,
    violations: list[tuple[CaseParams, str]] | None = None,
) -> Counter:
    """Run the property over ``n_examples`` hypothesis examples and count the outcomes.

    The counter keys are ``(group, outcome)`` with group ``"easy"`` or ``"other"``;
    ``counts["examples"]`` is the total and ``counts["seconds"]`` the wall time. With
    ``keep_going`` (the long-run script), a broken guarantee or an undocumented exception
    is counted as outcome ``"VIOLATION"`` and appended to ``violations`` as
    ``(params, message)`` instead of failing (no shrinking).
    """
    counts = Counter() if counts is None else counts
    phases = (Phase.generate,) if keep_going else tuple(Phase)

    @settings(
        max_examples=n_examples,
        deadline=None,
        database=None,
        phases=phases,
        suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
    )
    @given(params=case_params())
    def prop(params: CaseParams) -> None:
        case = build_case(params)
        try:
            outcome = run_case(case)
        except Exception as exc:
            if not keep_going:
                raise
            outcome = "VIOLATION"
            if violations is not None:
                violations.append((params, f"{type(exc).__name__}: {exc}"))
        counts[("easy" if case.easy else "other", outcome)] += 1
        counts["examples"] += 1

    t0 = time.perf_counter()
    prop()
    counts["seconds"] += time.perf_counter() - t0
    return counts


def summary(counts: Counter) -> str:
    """One line per group and outcome, with fractions."""
    lines = [f"examples {counts['examples']} in {counts['seconds']:.1f} s"]
    for group in ("easy", "other"):
        n = sum(v for k, v in counts.items() if isinstance(k, tuple) and k[0] == group)
        outs = sorted(
            (k[1], v) for k, v in counts.items() if isinstance(k, tuple) and k[0] == group
        )
        text = ", ".join(f"{o} {v} ({100 * v / max(n, 1):.1f}%)" for o, v in outs)
        lines.append(f"{group:5s} {n:6d}: {text}")
    return "\n".join(lines)


def check_counts(counts: Counter) -> None:
    """Fail when too many easy cases raise, or when almost nothing succeeds."""
    easy = sum(v for k, v in counts.items() if isinstance(k, tuple) and k[0] == "easy")
    easy_ok = counts[("easy", "ok")]
    ok = easy_ok + counts[("other", "ok")]
    assert easy >= 0.05 * counts["examples"], f"too few easy cases drawn:\n{summary(counts)}"
    assert easy - easy_ok <= EASY_FAILURE_LIMIT * easy, (
        f"more than {EASY_FAILURE_LIMIT:.0%} of the easy cases raised:\n{summary(counts)}"
    )
    assert ok >= 0.2 * counts["examples"], f"too few trajectories returned:\n{summary(counts)}"


def test_plan_property() -> None:
    counts = run_property(N_EXAMPLES)
    print(summary(counts))
    assert counts["examples"] >= N_EXAMPLES
    check_counts(counts)


@pytest.mark.slow
def test_plan_property_long() -> None:
    counts = run_property(N_EXAMPLES_SLOW)
    print(summary(counts))
    check_counts(counts)


# ------------------------------------------------------------------ hand-made cases
def test_brute_clearance_reference() -> None:
    occ = np.zeros((4, 5), bool)
    occ[1, 2] = True
    grid = astar.OccupancyGrid(occ, 0.5, (1.0, -1.0))
    pts = np.array(
        [
            [2.25, -0.25],  # inside the occupied cell (2, 1)
            [2.25, 0.5],  # 0.5 m above the cell's top edge, 1.0 m from the top of the map
            [3.0, 0.25],  # 0.5 m from the right edge of the map, 0.56 m from the cell
            [1.1, -0.9],  # 0.1 m from the left and the bottom edge
            [0.0, 0.0],  # outside the map
        ]
    )
    expected = [0.0, 0.5, 0.5, 0.1, 0.0]
    np.testing.assert_allclose(square_clearance(grid, pts), expected)
    # a finite reach changes nothing below it
    got = square_clearance(grid, pts, reach=0.3)
    np.testing.assert_allclose(got[[0, 3, 4]], [0.0, 0.1, 0.0])
    assert np.all(got[[1, 2]] > 0.3)


def test_easy_case_is_solved_and_checked() -> None:
    p = CaseParams(
        nx=30,
        ny=24,
        resolution=0.1,
        origin=(-3.0, 7.0),
        kind="open",
        density=0.0,
        seed=1,
        radius_cells=2.0,
        limits=(0.5, 0.5, 2.0, 0.5, 1.5),
        wheels=(0.28, 0.6),
        placement="free",
        start_u=(0.05, 0.5),
        goal_u=(0.9, 0.2),
        search="clearance",
    )
    case = build_case(p)
    assert case.easy
    assert run_case(case) == "ok"


#: Cases on which the 10 000-example runs (session 4) found a trajectory 0.1-0.8 % above its
#: speed cap. First run: a curvature peak (|kappa| ~ 25 1/m on 2 cm cells) narrower than the
#: timing's cap-table refinement (fix: golden-section search next to the lowest fine sample).
#: Rerun: a curvature peak inside one table interval whose two ends were both capped by
#: ``v_max`` alone, so the cap's second differences saw nothing (fix: the refinement is also
#: triggered by the curvature and the heading turned across the interval).
LONG_RUN_REGRESSIONS = [
    CaseParams(
        nx=37,
        ny=35,
        resolution=0.02,
        origin=(-42.03455006990392, 1.0610332041184023),
        kind="noise",
        density=0.04461853399020709,
        seed=271,
        radius_cells=0.3,
        limits=(
            1.2287056093495625,
            2.4631022051498985,
            2.436874143589767,
            0.15759917419355918,
            0.2200679889025887,
        ),
        wheels=(0.1273194557145569, 0.16939038094315778),
        placement="free",
        start_u=(0.6707056139143968, 0.48952608447613766),
        goal_u=(0.22077411087396948, 0.1794140376661879),
        search="shortest",
    ),
    CaseParams(
        nx=185,
        ny=185,
        resolution=0.02,
        origin=(-22.715220426935844, 14.809789894512278),
        kind="rects",
        density=0.3228308498960803,
        seed=404449,
        radius_cells=1.0,
        limits=(
            1.8397166384476524,
            1.2758191036121025,
            0.13863895925020747,
            0.051971840274298554,
            0.2134671579100811,
        ),
        wheels=None,
        placement="free",
        start_u=(0.44158910125218054, 0.45388536497759757),
        goal_u=(0.6248740044942592, 0.39199239484726056),
        search="shortest",
    ),
    CaseParams(
        nx=263,
        ny=53,
        resolution=0.02,
        origin=(-32.635599283490635, 8.560444051930936),
        kind="open",
        density=0.0,
        seed=88951,
        radius_cells=3.7341887608176094,
        limits=(
            0.19640807923914286,
            0.6048735300260856,
            2.9379557705089585,
            0.477313259224586,
            1.1985725787341952,
        ),
        wheels=(0.1350596797315405, 0.7925183391904915),
        placement="free",
        start_u=(0.9039971539893077, 0.552487378838519),
        goal_u=(0.10263176663338891, 0.5327734746412508),
        search="shortest",
    ),
    CaseParams(
        nx=241,
        ny=241,
        resolution=0.02,
        origin=(-7.063890756780431, -37.04815565142743),
        kind="open",
        density=0.0,
        seed=241,
        radius_cells=1.793505217775715,
        limits=(
            0.12334911502200994,
            0.256570939580716,
            4.997715717676668,
            0.3549876964665092,
            0.24937269029064907,
        ),
        wheels=(0.06206227062020115, 0.398343455474496),
        placement="free",
        start_u=(0.25276862474180684, 0.614340341618957),
        goal_u=(0.6050592382758567, 0.7928488771994384),
        search="clearance",
    ),
]


@pytest.mark.parametrize(
    "params", LONG_RUN_REGRESSIONS, ids=["yaw-rate", "speed-cap", "flat-cap-yaw", "flat-cap-speed"]
)
def test_long_run_regressions(params: CaseParams) -> None:
    assert run_case(build_case(params)) == "ok"
