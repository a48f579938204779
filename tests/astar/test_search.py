"""Tests of astar.find_path: optimality against Dijkstra, legality of every step, errors, and
the Moving AI optimal lengths on the shared real maps.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import astar
from astar import GridPath, InvalidInputError, NoPathError, OccupancyGrid, find_path
from tests.reference import check_path, dijkstra_costs, legal_step, step_graph

SQRT2 = math.sqrt(2.0)


# ----------------------------------------------------------------------------- property tests
@st.composite
def problems(draw):
    ny = draw(st.integers(1, 14))
    nx = draw(st.integers(1, 14))
    density = draw(st.floats(0.0, 0.45))
    rng = np.random.default_rng(draw(st.integers(0, 2**31)))
    occ = rng.random((ny, nx)) < density
    free = np.argwhere(~occ)
    assume(len(free) > 0)
    s = free[draw(st.integers(0, len(free) - 1))]
    t = free[draw(st.integers(0, len(free) - 1))]
    return occ, (int(s[1]), int(s[0])), (int(t[1]), int(t[0])), rng


@settings(max_examples=50, deadline=None)
@given(
    prob=problems(),
    connectivity=st.sampled_from([8, 4]),
    corner_cutting=st.booleans(),
    weighted=st.booleans(),
)
def test_matches_dijkstra(prob, connectivity, corner_cutting, weighted):
    occ, start, goal, rng = prob
    cost = rng.random(occ.shape) * 3.0 * (rng.random(occ.shape) < 0.7) if weighted else None
    grid = OccupancyGrid(occ, 0.1)
    ref = dijkstra_costs(occ, start, connectivity, corner_cutting, cost)[goal[1], goal[0]]
    kw = {"connectivity": connectivity, "corner_cutting": corner_cutting, "cost": cost}
    if math.isinf(ref):
        with pytest.raises(NoPathError, match="no path"):
            find_path(grid, start, goal, **kw)
        return
    path = find_path(grid, start, goal, **kw)
    assert path.cost == pytest.approx(ref, rel=1e-9, abs=1e-12)
    check_path(path, occ, start, goal, connectivity, corner_cutting, cost)
    assert path.expanded >= 1
    # deterministic
    assert find_path(grid, start, goal, **kw) == path


def test_reference_graph_is_the_step_rule():
    """The reference's graph (built a whole move at a time, for speed) has exactly the edges
    of ``legal_step`` (the documented move rules, one move at a time), with the step length
    times ``1 + (cost_a + cost_b) / 2``, on random grids up to their edges."""
    rng = np.random.default_rng(4)
    moves = [(dx, dy) for dx in (-1, 0, 1) for dy in (-1, 0, 1) if dx or dy]
    for trial in range(24):
        ny, nx = (int(v) for v in rng.integers(1, 9, size=2))
        occ = rng.random((ny, nx)) < 0.35
        cost = rng.random(occ.shape) * 3.0 if trial % 2 else None
        for connectivity, corner_cutting in ((8, False), (8, True), (4, False), (4, True)):
            want = {}
            for iy, ix, (dx, dy) in itertools.product(range(ny), range(nx), moves):
                if legal_step(occ, (ix, iy), (ix + dx, iy + dy), connectivity, corner_cutting):
                    step = SQRT2 if dx and dy else 1.0
                    if cost is not None:
                        step *= 1.0 + 0.5 * (cost[iy, ix] + cost[iy + dy, ix + dx])
                    want[(iy * nx + ix, (iy + dy) * nx + ix + dx)] = step
            g = step_graph(occ, connectivity, corner_cutting, cost).tocoo()
            got = {(int(r), int(c)): w for r, c, w in zip(g.row, g.col, g.data, strict=True)}
            assert got == want, (occ.astype(int).tolist(), connectivity, corner_cutting)


def test_open_grid_octile_length():
    grid = OccupancyGrid(np.zeros((30, 50), bool), 1.0)
    p = find_path(grid, (2, 3), (45, 20))
    assert p.length == pytest.approx(26 + 17 * SQRT2, rel=1e-14)
    assert p.cost == p.length
    p4 = find_path(grid, (2, 3), (45, 20), connectivity=4)
    assert p4.length == 43 + 17


def test_corner_cutting_rule():
    # free cells (0, 0) and (1, 1) touch only at a corner between two blocked cells
    occ = np.array([[False, True], [True, False]])
    grid = OccupancyGrid(occ, 1.0)
    with pytest.raises(NoPathError):
        find_path(grid, (0, 0), (1, 1))
    p = find_path(grid, (0, 0), (1, 1), corner_cutting=True)
    assert p.cells.tolist() == [[0, 0], [1, 1]] and p.length == pytest.approx(SQRT2)
    # one blocked orthogonal neighbour is enough to forbid the diagonal without corner cutting
    occ = np.array([[False, True], [False, False]])
    p = find_path(OccupancyGrid(occ, 1.0), (0, 0), (1, 1))
    assert p.length == 2.0


def test_start_equals_goal():
    grid = OccupancyGrid(np.zeros((3, 3), bool), 1.0)
    p = find_path(grid, (1, 2), (1, 2))
    assert p.cells.tolist() == [[1, 2]] and p.length == 0.0 and p.cost == 0.0


def test_cost_steers_path_and_zero_cost_changes_nothing():
    occ = np.zeros((5, 9), bool)
    grid = OccupancyGrid(occ, 1.0)
    plain = find_path(grid, (0, 2), (8, 2))
    assert plain.length == 8.0
    assert find_path(grid, (0, 2), (8, 2), cost=np.zeros(occ.shape)).cost == 8.0
    cost = np.zeros(occ.shape)
    cost[2, 2:7] = 10.0  # an expensive band on the straight line
    p = find_path(grid, (0, 2), (8, 2), cost=cost)
    assert p.length > 8.0 and p.cost < 8.0 * 6.0
    assert not any(cost[iy, ix] for ix, iy in p.cells)


def test_gridpath_value_semantics():
    grid = OccupancyGrid(np.zeros((4, 4), bool), 0.5, origin=(1.0, 2.0))
    p = find_path(grid, (0, 0), (3, 0))
    assert isinstance(p, GridPath)
    with pytest.raises(ValueError):
        p.cells[0, 0] = 5
    with pytest.raises(AttributeError):
        p.length = 1.0  # type: ignore[misc]
    np.testing.assert_allclose(p.to_world(grid), [[1.25 + 0.5 * i, 2.25] for i in range(4)])
    assert len(p) == 4 and "GridPath" in repr(p)


# ----------------------------------------------------------------------------- errors
@pytest.fixture
def small_grid():
    occ = np.zeros((4, 5), bool)
    occ[1, 2] = True
    return OccupancyGrid(occ, 1.0)


@pytest.mark.parametrize(
    "start, goal, pattern",
    [
        ((5, 0), (0, 0), r"start cell \(5, 0\) is outside the grid"),
        ((0, 0), (0, -1), r"goal cell \(0, -1\) is outside the grid"),
        ((2, 1), (0, 0), r"start cell \(2, 1\) is blocked"),
        ((0, 0), (2, 1), r"goal cell \(2, 1\) is blocked"),
        ((0.0, 1.0), (0, 0), "start must be a cell"),
        ((0, 0), (1, 2, 3), "goal must be a cell"),
        ((True, 0), (0, 0), "start must be a cell"),
        ("ab", (0, 0), "start must be a cell"),
        (None, (0, 0), "start must be a cell"),
    ],
)
def test_bad_start_goal(small_grid, start, goal, pattern):
    with pytest.raises(InvalidInputError, match=pattern):
        find_path(small_grid, start, goal)


def test_numpy_integer_cells_accepted(small_grid):
    p = find_path(small_grid, np.array([0, 0]), (np.int32(4), np.int64(3)))
    assert p.cells[-1].tolist() == [4, 3]


@pytest.mark.parametrize(
    "kw, pattern",
    [
        ({"connectivity": 6}, "connectivity"),
        ({"connectivity": True}, "connectivity"),
        ({"cost": np.zeros((3, 3))}, "shape"),
        ({"cost": -np.ones((4, 5))}, ">= 0"),
        ({"cost": np.full((4, 5), np.nan)}, "finite"),
        ({"cost": np.full((4, 5), np.inf)}, "finite"),
    ],
)
def test_bad_options(small_grid, kw, pattern):
    with pytest.raises(InvalidInputError, match=pattern):
        find_path(small_grid, (0, 0), (4, 3), **kw)


def test_unreachable_goal_raises_no_path():
    occ = np.zeros((5, 5), bool)
    occ[:, 2] = True
    with pytest.raises(NoPathError, match=r"no path from start \(0, 0\) to goal \(4, 4\)"):
        find_path(OccupancyGrid(occ, 1.0), (0, 0), (4, 4))
    assert not issubclass(NoPathError, ValueError)


def test_not_a_grid():
    with pytest.raises(InvalidInputError, match="OccupancyGrid"):
        find_path(np.zeros((3, 3), bool), (0, 0), (1, 1))


# ----------------------------------------------------------------------------- real maps
MAPS = (
    "arena",
    "den312d",
    "rmtst01",
    "Berlin_0_256",
    "random512-40-5",
    "maze512-1-0",
    "Boston_0_1024",
    "AR0046SR",
)
LARGE_CELLS = 50_000  # maps with more cells are sampled (256^2, 512^2 and 1024^2 here)
FAST_SAMPLE = 24  # per large map in the default run
FULL_SAMPLE = 200  # per large map in the slow run


def _sample(scens, n):
    """All scenarios of the longest bucket plus evenly spaced others: at least ``n``."""
    top = max(s.bucket for s in scens)
    longest = [s for s in scens if s.bucket == top]
    rest = [s for s in scens if s.bucket != top]
    k = max(0, n - len(longest))
    idx = np.unique(np.linspace(0, len(rest) - 1, num=min(k, len(rest))).round().astype(int))
    return longest + [rest[i] for i in idx]


def _check_scenarios(shared_data, name, n_large):
    root = shared_data / "movingai"
    scens = astar.read_scenarios(root / "scen" / f"{name}.map.scen")
    grid = astar.load_map(root / "maps" / f"{name}.map")
    large = grid.nx * grid.ny > LARGE_CELLS
    chosen = _sample(scens, n_large) if large else scens
    if large:
        assert len(chosen) >= n_large
        assert max(s.bucket for s in chosen) == max(s.bucket for s in scens)
    bad = []
    for s in chosen:
        assert (grid.nx, grid.ny) == (s.width, s.height)
        if s.optimal_length == 0.0 and s.start != s.goal:
            # the benchmark marks unsolvable problems with length 0 (rmtst01 has two)
            with pytest.raises(NoPathError):
                find_path(grid, s.start, s.goal)
            continue
        p = find_path(grid, s.start, s.goal)
        if abs(p.length - s.optimal_length) > 1e-5 * max(1.0, s.optimal_length):
            bad.append((s.start, s.goal, p.length, s.optimal_length))
    assert not bad, f"{name}: {len(bad)} lengths differ from the optimum, e.g. {bad[:3]}"
    return len(chosen)


def test_every_scen_file_is_checked(shared_data):
    names = {
        p.name.removesuffix(".map.scen") for p in (shared_data / "movingai" / "scen").glob("*.scen")
    }
    assert names and names <= set(MAPS), f"unchecked scenario files: {sorted(names - set(MAPS))}"


@pytest.mark.parametrize("name", MAPS)
def test_movingai_optimal_lengths(shared_data, name):
    """All scenarios of the small maps; longest bucket + evenly spaced others on large maps."""
    _check_scenarios(shared_data, name, FAST_SAMPLE)


@pytest.mark.slow
@pytest.mark.parametrize(
    "name", [m for m in MAPS if m.startswith(("Berlin", "random", "maze", "Boston", "AR"))]
)
def test_movingai_optimal_lengths_full_sample(shared_data, name):
    """At least 200 scenarios per large map, the longest bucket included (slow: ~10 s/map)."""
    _check_scenarios(shared_data, name, FULL_SAMPLE)
