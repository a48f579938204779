"""Tests of trajopt.planning: the curvature-feasibility witness: checked by brute force, and against hand-made maps
where the answer is known (a wide room: feasible; a narrow L-bend: no curve can turn)."""

from __future__ import annotations

import numpy as np
import pytest

import astar
from tests.reference import square_clearance, three_point_curvature
from trajopt import Planner, Robot, Smoother, build_corridor
from trajopt.errors import InvalidInputError, SmoothingError
from trajopt.planning._feasibility import curvature_witness, witness_grid_path


def test_open_room_witness_holds_every_promise():
    occ = np.zeros((40, 50), dtype=bool)
    occ[15:25, 20:24] = True  # a pillar between start and goal
    grid = astar.OccupancyGrid(occ, 0.1)
    radius, kmax = 0.25, 1.0 / 0.5
    start, goal = np.array([0.6, 2.0]), np.array([4.4, 2.05])
    w = curvature_witness(grid, radius, start, goal, kmax)
    assert w is not None
    np.testing.assert_array_equal(w[0], start)
    np.testing.assert_array_equal(w[-1], goal)
    step = np.hypot(*np.diff(w, axis=0).T)
    assert step.max() <= 0.1 / 8 + 1e-12
    assert square_clearance(grid, w).min() >= radius - 1e-9
    keep = np.concatenate([[True], step > 1e-12])  # drop the repeated junction points
    kappa = three_point_curvature(w[keep])
    assert np.nanmax(kappa) <= kmax * (1 + 1e-6)


def _l_bend(width_cells: int) -> astar.OccupancyGrid:
    """A free L-shaped channel ``width_cells`` wide in a 32 x 32 block (1 m cells)."""
    occ = np.ones((32, 32), dtype=bool)
    occ[3 : 3 + width_cells, 3:29] = False  # horizontal leg along the bottom
    occ[3:29, 29 - width_cells : 29] = False  # vertical leg up the right side
    return astar.OccupancyGrid(occ, 1.0)


def test_narrow_l_bend_has_no_witness_and_the_smoother_agrees():
    # a 6-cell channel and radius 2.5 leave a 1-cell wide centre band: a turning radius of
    # 6.67 cells does not get round its corner (the search runs out of lattice states), and
    # the smoother fails as well
    grid = _l_bend(6)
    radius, kmax = 2.5, 0.15
    start, goal = np.array([8.5, 6.0]), np.array([26.0, 22.5])
    assert curvature_witness(grid, radius, start, goal, kmax, time_limit_s=20) is None
    infl = astar.inflate(grid, radius, metric="square", outside_occupied=True)
    a, b = tuple(grid.world_to_cell(start)), tuple(grid.world_to_cell(goal))
    path = astar.find_path(infl, a, b)
    corr = build_corridor(infl, path, radius=radius, raw_grid=grid)
    with pytest.raises(SmoothingError):
        Smoother(kappa_max=kmax, time_budget_s=2.0).fit(
            path, corr, raw_grid=grid, radius=radius, start=start, goal=goal
        )
    # a tighter turn fits in the same channel: the witness finds it
    w = curvature_witness(grid, radius, start, goal, 1.0)
    assert w is not None and square_clearance(grid, w).min() >= radius - 1e-9


def test_wide_l_bend_is_feasible():
    grid = _l_bend(16)  # 11-cell wide centre band: room for a 5-cell turning radius
    w = curvature_witness(grid, 2.5, np.array([8.5, 11.0]), np.array([21.0, 24.5]), 0.2)
    assert w is not None and square_clearance(grid, w).min() >= 2.5 - 1e-9


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"radius": -1.0}, "radius"),
        ({"kappa_max": 0.0}, "kappa_max"),
        ({"kappa_max": float("nan")}, "kappa_max"),
        ({"n_headings": 4}, "n_headings"),
    ],
)
def test_bad_input(kwargs, match):
    grid = astar.OccupancyGrid(np.zeros((10, 10), dtype=bool), 0.1)
    args = {"radius": 0.1, "kappa_max": 1.0, **kwargs}
    with pytest.raises(InvalidInputError, match=match):
        curvature_witness(grid, args.pop("radius"), (0.3, 0.3), (0.7, 0.7), **args)


def test_blocked_end_point_gives_none():
    grid = astar.OccupancyGrid(np.zeros((10, 10), dtype=bool), 0.1)
    assert curvature_witness(grid, 0.2, (0.1, 0.5), (0.5, 0.5), 1.0) is None  # near the edge


# ------------------------------------------------------------ witness_grid_path
def _check_grid_path(cells: np.ndarray, occ: np.ndarray) -> None:
    """8-connected, no corner cutting, all free, no cell visited twice (brute force)."""
    assert cells.dtype == np.int64 and cells.ndim == 2 and cells.shape[1] == 2
    assert not occ[cells[:, 1], cells[:, 0]].any()
    step = np.abs(np.diff(cells, axis=0))
    assert np.all(step.max(axis=1) == 1)
    for (x0, y0), (x1, y1) in zip(cells[:-1], cells[1:], strict=True):
        if x0 != x1 and y0 != y1:
            assert not occ[y0, x1] and not occ[y1, x0]
    assert len({(int(x), int(y)) for x, y in cells}) == len(cells)


def test_witness_grid_path_follows_an_open_room_witness():
    occ = np.zeros((40, 50), dtype=bool)
    occ[15:25, 20:24] = True
    grid = astar.OccupancyGrid(occ, 0.1)
    radius = 0.25
    start, goal = np.array([0.6, 2.0]), np.array([4.4, 2.05])
    w = curvature_witness(grid, radius, start, goal, 2.0)
    infl = astar.inflate(grid, radius, metric="square", outside_occupied=True)
    cells = witness_grid_path(w, infl)
    _check_grid_path(cells, infl.occupied)
    np.testing.assert_array_equal(cells[0], grid.world_to_cell(start))
    np.testing.assert_array_equal(cells[-1], grid.world_to_cell(goal))
    # every cell holds a witness point or neighbours one that does (the detours round
    # witness cells blocked in the inflated grid are one cell wide here)
    held = np.floor(w / 0.1).astype(np.int64)
    cheb = np.abs(cells[:, None, :] - held[None, :, :]).max(axis=2).min(axis=1)
    assert cheb.max() <= 1
    assert (cheb == 0).mean() > 0.8


def test_witness_grid_path_goes_round_blocked_cells_and_cuts_loops():
    occ = np.zeros((12, 12), dtype=bool)
    occ[5, 4:8] = True  # a wall the hand-made "witness" runs straight through
    grid = astar.OccupancyGrid(occ, 1.0)
    line = np.column_stack([np.full(81, 6.5), np.linspace(1.5, 9.5, 81)])
    loop = np.array([[6.5, 9.5], [7.5, 9.5], [7.5, 10.5], [6.5, 10.5], [6.5, 9.6]])
    cells = witness_grid_path(np.vstack([line, loop]), grid)
    _check_grid_path(cells, occ)
    assert tuple(cells[0]) == (6, 1) and tuple(cells[-1]) == (6, 9)


def test_witness_grid_path_none_and_errors():
    grid = astar.OccupancyGrid(np.zeros((5, 5), dtype=bool), 1.0)
    walled = astar.OccupancyGrid(np.pad(np.zeros((3, 3), dtype=bool), 1, constant_values=True), 1.0)
    assert witness_grid_path(np.array([[0.5, 0.5], [1.5, 0.5]]), walled) is None  # blocked end
    assert witness_grid_path(np.array([[-0.5, 0.5], [1.5, 0.5]]), grid) is None  # outside
    split = np.zeros((5, 5), dtype=bool)
    split[:, 2] = True
    assert (
        witness_grid_path(np.array([[0.5, 0.5], [4.5, 0.5]]), astar.OccupancyGrid(split, 1.0))
        is None
    )
    with pytest.raises(InvalidInputError, match="witness"):
        witness_grid_path(np.zeros((3, 3)), grid)
    with pytest.raises(InvalidInputError, match="witness"):
        witness_grid_path(np.array([[0.5, np.nan]]), grid)


def test_planner_rescues_a_curvature_bounded_query_along_the_witness(shared_data):
    # turtlebot3_world: the clearance-aware A* path zigzags between two pillars and the
    # smoother's SCP stalls in its corridor; the witness runs diagonally through the open
    # space between them, and the fit along it is certified
    raw = astar.load_map(shared_data / "ros" / "turtlebot3_world.yaml")
    radius, kmax = 0.2, 1.0 / 0.4
    planner = Planner(
        raw,
        Robot(radius=radius),
        smoother=Smoother(kappa_max=kmax, time_budget_s=10),
        corridor="boxes",
    )
    p0, p1 = raw.cell_to_world(np.array([169, 205])), raw.cell_to_world(np.array([197, 230]))
    path = astar.find_path(planner.inflated_grid, (169, 205), (197, 230), cost=planner.search_cost)
    corr = build_corridor(planner.inflated_grid, path, radius=radius, raw_grid=raw)
    try:
        Smoother(kappa_max=kmax, time_budget_s=10).fit(path, corr, raw_grid=raw, radius=radius)
    except SmoothingError:
        pass
    else:
        pytest.skip("the smoother now succeeds along the A* path: no rescue to test here")
    traj = planner.plan(p0, p1)
    assert traj.stats["smoother"]["rescue"] == "witness"
    sp = traj.steps.smooth_path
    assert sp.certificate.ok
    u = np.linspace(*sp.domain, 2000)
    xy = sp(u)
    assert square_clearance(raw, xy).min() >= radius - 1e-9
    np.testing.assert_allclose(xy[[0, -1]], [p0, p1], atol=1e-9)
    _check_grid_path(traj.steps.grid_path.cells, planner.inflated_grid.occupied)


def test_polygon_corridor_plans_the_curvature_bounded_pillar_query(shared_data):
    # the query above, in the default polygon corridor: a certified curve that holds the
    # bound, found along the A* path or through the rescue
    raw = astar.load_map(shared_data / "ros" / "turtlebot3_world.yaml")
    radius, kmax = 0.2, 1.0 / 0.4
    planner = Planner(
        raw, Robot(radius=radius), smoother=Smoother(kappa_max=kmax, time_budget_s=10)
    )
    p0, p1 = raw.cell_to_world(np.array([169, 205])), raw.cell_to_world(np.array([197, 230]))
    traj = planner.plan(p0, p1)
    sp = traj.steps.smooth_path
    assert sp.certificate.ok and traj.stats["corridor"] in ("polygons", "boxes")
    u = np.linspace(*sp.domain, 4000)
    assert square_clearance(raw, sp(u)).min() >= radius - 1e-9
    assert np.abs(sp.curvature(u)).max() <= kmax * (1 + 1e-6)


def test_planner_without_a_witness_raises_the_smoothers_error():
    grid = _l_bend(6)  # no curve of this turning radius gets round (test above)
    planner = Planner(grid, Robot(radius=2.5), smoother=Smoother(kappa_max=0.15, time_budget_s=5))
    with pytest.raises(SmoothingError, match="no certified curve"):
        planner.plan((8.5, 6.0), (26.0, 22.5))


# ------------------------------------------------------------------ the planner's rescue
def test_planner_failure_says_whether_a_witness_exists():
    # the narrow L-bend: no curvature-bounded path; the planner's error says the witness
    # search found none (and its stats carry it)
    grid = _l_bend(6)
    planner = Planner(grid, Robot(radius=2.5), smoother=Smoother(kappa_max=0.15))
    with pytest.raises(SmoothingError, match="witness rescue: no curvature-bounded path") as ei:
        planner.plan((8.5, 6.0), (26.0, 22.5))
    assert ei.value.stats["witness"].startswith("no curvature-bounded path")


@pytest.mark.parametrize(
    ("radius", "start", "goal"),
    [
        (2.5, (32.5, 41.5), (27.5, 68.5)),
        (1.5, (6.5, 58.5), (8.5, 70.5)),
    ],
)
def test_witness_rescue_grows_its_polygons_around_the_witness(shared_data, radius, start, goal):
    # den312d, kappa_max = 1 / (2 r): the fit along the A* path fails; the witness hugs the
    # walls at the exact radius and the corridor of its (centred, simplified) grid path left
    # its arcs outside every region; polygons grown around the witness itself hold a curve
    grid = astar.load_map(shared_data / "movingai" / "maps" / "den312d.map")
    kmax = 1.0 / (2.0 * radius)
    planner = Planner(grid, Robot(radius=radius), smoother=Smoother(kappa_max=kmax))
    traj = planner.plan(start, goal)
    assert traj.stats["smoother"]["rescue"] == "witness"
    assert traj.stats["corridor"] == "polygons"
    sp = traj.steps.smooth_path
    u = np.linspace(*sp.domain, 8000)
    assert square_clearance(grid, sp(u)).min() >= radius - 1e-9
    p = sp(u)
    assert three_point_curvature(p[::4]).max() <= kmax * 1.01
    np.testing.assert_allclose(p[[0, -1]], [start, goal], atol=1e-9)
