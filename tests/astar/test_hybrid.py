"""Tests of astar.hybrid: Hybrid-A* pose paths: hand-made manoeuvres, independent dense checks, bad input."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import astar
from astar import InvalidInputError, NoPathError, OccupancyGrid
from astar.hybrid import NoPosePathError, find_pose_path
from tests.astar.hybrid_checks import check_path
from tests.astar.hybrid_checks import polyline_clearance as _polyline_clearance
from tests.astar.hybrid_checks import world as _world


def _wrap(a):
    return (np.asarray(a) + np.pi) % (2 * np.pi) - np.pi


def _closed(ny, nx):
    free = np.zeros((ny, nx), bool)
    free[1:-1, 1:-1] = True
    return free


def test_goal_straight_behind():
    free = _closed(9, 30)
    start, goal = (20.0, 4.0, 0.0), (12.0, 4.0, 0.0)
    p = find_pose_path(free, start, goal, turning_radius=4.0)
    check_path(p, free, start, goal, 4.0)
    assert p.length == pytest.approx(8.0) and p.reverse_length == pytest.approx(8.0)
    assert p.cusps == 0 and np.all(p.directions == -1)
    # forwards only: a loop, which this corridor (7 cells < 2R + ...) cannot hold
    with pytest.raises(NoPosePathError, match="forwards only") as e:
        find_pose_path(free, start, goal, turning_radius=4.0, reverse=False)
    assert e.value.reason == "exhausted" and isinstance(e.value, NoPathError)
    # in the open, forwards only goes round: longer than a full circle of radius R... at least
    # pi R (turn back) and no backwards motion
    free = _closed(40, 40)
    p = find_pose_path(free, (24, 20, 0), (16, 20, 0), turning_radius=4.0, reverse=False)
    check_path(p, free, (24, 20, 0), (16, 20, 0), 4.0)
    assert p.reverse_length == 0 and p.cusps == 0 and p.length > 2 * math.pi * 4.0


def test_u_turn_round_a_block():
    """Lanes 5 cells wide (< 2R = 6): forwards only, the car must drive round the block."""
    free = _closed(22, 50)
    free[6:16, 6:44] = False
    start, goal = (20.0, 3.0, 0.0), (20.0, 18.0, math.pi)
    p = find_pose_path(free, start, goal, turning_radius=3.0, reverse=False)
    check_path(p, free, start, goal, 3.0)
    assert p.cusps == 0 and p.reverse_length == 0
    assert p.poses[:, 0].max() > 44  # round the east end of the block
    q = find_pose_path(free, start, goal, turning_radius=3.0)
    check_path(q, free, start, goal, 3.0)
    # plain A* ordering (heuristic_weight=1): a path no costlier than the weighted search's
    r = find_pose_path(free, start, goal, turning_radius=3.0, reverse=False, heuristic_weight=1.0)
    check_path(r, free, start, goal, 3.0)
    assert r.length <= p.length * 1.5


def test_three_point_turn_in_a_dead_end():
    """A corridor 7 cells wide, closed at its east end, R = 5 (2R = 10 > 7): turn round."""
    free = _closed(9, 40)
    start, goal = (30.0, 4.0, 0.0), (30.0, 4.0, math.pi)
    p = find_pose_path(free, start, goal, turning_radius=5.0)
    check_path(p, free, start, goal, 5.0)
    assert p.cusps >= 2 and p.reverse_length > 0
    t = time.perf_counter()
    with pytest.raises(NoPosePathError, match="no forwards-only path") as e:
        find_pose_path(free, start, goal, turning_radius=5.0, reverse=False)
    assert e.value.reason == "exhausted" and time.perf_counter() - t < 1.0


def test_parallel_parking():
    """A slot 1.3 car lengths long beside a street (car length = R = 6 cells, as a car of
    length 4.5 m with a 5 m turning radius), the free space of the car's reference point."""
    radius = 6.0
    free = np.zeros((16, 50), bool)
    free[6:15, 1:49] = True  # the street
    free[2:6, 20:28] = True  # the slot: 8 cells = 1.33 car lengths, 4 deep
    goal = (24.0, 3.0, 0.0)
    for start in [(32.0, 9.0, 0.0), (8.0, 10.0, 0.0), (40.0, 10.0, math.pi)]:
        p = find_pose_path(free, start, goal, turning_radius=radius)
        check_path(p, free, start, goal, radius)
    # backing in from beside the slot, the classic manoeuvre: it reverses
    p = find_pose_path(free, (32.0, 9.0, 0.0), goal, turning_radius=radius)
    assert p.reverse_length > 0


def test_random_grids_are_checked():
    rng = np.random.default_rng(1)
    found = 0
    for _ in range(12):
        free = _closed(30, 30) & (rng.random((30, 30)) > 0.12)
        cells = np.argwhere(free)
        a, b = cells[rng.choice(len(cells), 2, replace=False)]
        start = (float(a[1]), float(a[0]), float(rng.uniform(-np.pi, np.pi)))
        goal = (float(b[1]), float(b[0]), float(rng.uniform(-np.pi, np.pi)))
        for rev in (True, False):
            try:
                p = find_pose_path(
                    free, start, goal, turning_radius=2.0, reverse=rev, time_budget=0.5
                )
            except NoPosePathError as e:
                assert e.reason in ("disconnected", "exhausted", "time_budget")
                continue
            found += 1
            check_path(p, free, start, goal, 2.0)
            if not rev:
                assert p.cusps == 0 and p.reverse_length == 0
    assert found >= 6


def test_occupancy_grid_input_and_world():
    occ = ~_closed(12, 20)
    g = OccupancyGrid(occ, resolution=0.05, origin=(1.0, 2.0))
    p = find_pose_path(g, (5, 5, 0), (14, 6, 0.3), turning_radius=3.0)
    check_path(p, ~occ, (5, 5, 0), (14, 6, 0.3), 3.0)
    w = p.to_world(g)
    assert w[0].tolist() == pytest.approx([1.0 + 5.5 * 0.05, 2.0 + 5.5 * 0.05, 0.0])
    assert not p.poses.flags.writeable and p.stats["expanded"] >= 1


def test_same_pose():
    free = _closed(10, 10)
    p = find_pose_path(free, (4, 4, 1.0), (4, 4, 1.0), turning_radius=2.0)
    assert len(p) == 1 and p.length == 0 and p.cusps == 0 and p.pieces.shape == (0, 5)
    assert p.poses.tolist() == [[4.0, 4.0, 1.0]] and p.segments.tolist() == [[0, 0]]


def test_refusals_say_why():
    free = _closed(10, 21)
    free[:, 10] = False
    t = time.perf_counter()
    with pytest.raises(NoPosePathError, match="different free regions") as e:
        find_pose_path(free, (3, 5, 0), (15, 5, 0), turning_radius=2.0)
    assert e.value.reason == "disconnected" and time.perf_counter() - t < 0.5
    free = _closed(40, 40)
    free[10:30, 20] = False
    with pytest.raises(NoPosePathError, match="max_expansions=3") as e:
        find_pose_path(free, (5, 20, 0), (35, 20, math.pi), turning_radius=3.0, max_expansions=3)
    assert e.value.reason == "max_expansions" and e.value.stats["expanded"] >= 3


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"turning_radius": 0.0}, "turning_radius"),
        ({"turning_radius": -2.0}, "turning_radius"),
        ({"turning_radius": math.nan}, "turning_radius"),
        ({"turning_radius": math.inf}, "turning_radius"),
        ({"turning_radius": 2.0, "reverse": "yes"}, "reverse must be a bool"),
        ({"turning_radius": 2.0, "heading_bins": 4}, "heading_bins must be >= 8"),
        ({"turning_radius": 2.0, "curvatures": 4}, "curvatures must be odd"),
        (
            {"turning_radius": 2.0, "reverse_penalty": 0.5},
            "reverse_penalty must be finite and >= 1",
        ),
        ({"turning_radius": 2.0, "cusp_penalty": -1}, "cusp_penalty"),
        ({"turning_radius": 2.0, "time_budget": 0}, "time_budget"),
        ({"turning_radius": 2.0, "max_expansions": 0}, "max_expansions must be >= 1"),
        ({"turning_radius": 2.0, "primitive_length": -1.0}, "primitive_length"),
        (
            {"turning_radius": 2.0, "heuristic_weight": 0.9},
            "heuristic_weight must be finite and >= 1",
        ),
    ],
)
def test_bad_parameters(kwargs, match):
    with pytest.raises(InvalidInputError, match=match):
        find_pose_path(_closed(10, 10), (3, 3, 0), (6, 6, 0), **kwargs)


@pytest.mark.parametrize(
    ("start", "match"),
    [
        ((3, 3), "start must be a pose"),
        ((3, 3, math.nan), "start must be finite"),
        ((30, 3, 0), "outside the grid"),
        ((0, 0, 0), "blocked cell"),
        ("abc", "start must be a pose"),
    ],
)
def test_bad_poses(start, match):
    with pytest.raises(InvalidInputError, match=match):
        find_pose_path(_closed(10, 10), start, (6, 6, 0), turning_radius=2.0)


def test_bad_grid():
    for g in (np.ones((5, 5), int), np.ones((2, 5, 5), bool), [[True]], np.ones((0, 3), bool)):
        with pytest.raises(InvalidInputError, match="grid must be"):
            find_pose_path(g, (1, 1, 0), (2, 2, 0), turning_radius=1.0)


def test_arc_bulge_between_samples_is_caught():
    """An arc (R = 6.6) whose samples and chords stay right of x = 4.5 but which bulges
    0.0002 cells into the blocked column ix = 4 between two samples (seen on smoothers_world)."""
    from astar.hybrid_kernel import arc_clear, segment_clear
    from astar.reeds_shepp import advance

    free = np.ones((10, 10), np.uint8)
    free[:, 4] = 0
    x, y, th, k, s = (
        4.50037729000536,
        5.11793064003186,
        4.699224192658562,
        1 / 6.6,
        1.727875959474386,
    )
    m = math.ceil(abs(s) / 0.2)
    pts = [advance(x, y, th, k, s * q / m)[:2] for q in range(m + 1)]
    assert all(segment_clear(free, *a, *b) for a, b in zip(pts[:-1], pts[1:], strict=True))
    off = np.zeros((1, 1), np.uint8)
    assert not arc_clear(free, x, y, th, k, s, 0.2, off, off, 0.0)


def test_free_box_and_arc_in_box_against_brute_force():
    """free_box against a scan of the boxes round each cell; arc_in_box (the search's quick
    test) only says True where every point of the arc, sampled 0.01 cells apart, lies in a
    free cell (and, exact mode, a safe one) and arc_clear agrees."""
    from astar.hybrid_kernel import arc_clear, arc_in_box, free_box
    from astar.reeds_shepp import advance

    rng = np.random.default_rng(5)
    shown = 0
    for trial in range(24):
        ny, nx = rng.integers(8, 22, size=2)
        free = (rng.random((ny, nx)) > rng.uniform(0.0, 0.08)).astype(np.uint8)
        exact = trial % 2 == 1
        safe = (free & (rng.random((ny, nx)) > 0.03)).astype(np.uint8) if exact else free
        ring = np.zeros((ny, nx), np.uint8)
        k_max = 4
        ok = free & safe if exact else free
        for iy in range(ny):
            for ix in range(nx):
                want = -1
                for k in range(k_max + 1):
                    y0, y1, x0, x1 = iy - k, iy + k + 1, ix - k, ix + k + 1
                    if y0 < 0 or x0 < 0 or y1 > ny or x1 > nx or not ok[y0:y1, x0:x1].all():
                        break
                    want = k
                assert free_box(free, safe, exact, ring, ix, iy, k_max) == want
        for _ in range(80):
            x, y = rng.uniform(-0.5, nx - 0.5), rng.uniform(-0.5, ny - 0.5)
            th, kappa = rng.uniform(-np.pi, np.pi), rng.choice([-1 / 3, 0.0, 1 / 3])
            s = rng.uniform(-3.5, 3.5)
            if not arc_in_box(free, safe, exact, ring, x, y, s, k_max):
                continue
            shown += 1
            for q in np.linspace(0.0, 1.0, int(abs(s) / 0.01) + 2):
                px, py, _ = advance(x, y, th, kappa, s * q)
                assert ok[int(math.floor(py + 0.5)), int(math.floor(px + 0.5))]
            # exact mode: a safe cell keeps any clearance, so r only matters off the box
            assert arc_clear(free, x, y, th, kappa, s, 0.2, safe, 1 - free, 1.0 if exact else 0.0)
    assert shown > 50  # the quick test does answer


POCKET = """
##############################
####################...#######
#.......................######
#.......................######
#.......................######
#........................S####
###.......................####
###.......................####
###.......................####
#########################.####
#########################.####
##############################
"""


def test_pocket_where_no_primitive_fits_is_retried_finer():
    """A start at the end of a pocket, heading into the wall (den312d inflated by 2.5 cells,
    held-out query 21): no primitive of 1.75 cells fits; the finer second search gets out."""
    rows = [r for r in POCKET.strip().splitlines()][::-1]  # row 0 at the bottom
    free = np.array([[c != "#" for c in r] for r in rows])
    sy = next(i for i, r in enumerate(rows) if "S" in r)
    start, goal = (
        (float(rows[sy].index("S")), float(sy), 2.1211601392508337),
        (14.0, float(sy), 2.356),
    )
    p = find_pose_path(free, start, goal, turning_radius=5.0)
    check_path(p, free, start, goal, 5.0)
    assert p.stats["retried"] and p.cusps >= 1


def test_retry_expansions_bounds_the_finer_search():
    """``retry_expansions`` caps the finer search after a small region was exhausted: 0
    skips it (the pocket's coarse states are all expanded: ``"exhausted"``), a cap below
    what it needs stops it there (``"max_expansions"``, the count within the cap), and a
    cap above what it needs returns the same path as no cap."""
    rows = [r for r in POCKET.strip().splitlines()][::-1]
    free = np.array([[c != "#" for c in r] for r in rows])
    sy = next(i for i, r in enumerate(rows) if "S" in r)
    start, goal = ((float(rows[sy].index("S")), float(sy), 2.1211601392508337), (14.0, sy, 2.356))
    ref = find_pose_path(free, start, goal, turning_radius=5.0)
    with pytest.raises(NoPosePathError) as none:
        find_pose_path(free, start, goal, turning_radius=5.0, retry_expansions=0)
    assert none.value.reason == "exhausted" and not none.value.stats["retried"]
    first = none.value.stats["expanded"]
    assert 0 < first < ref.stats["expanded"]
    with pytest.raises(NoPosePathError, match=r"reached retry_expansions=3\b") as capped:
        find_pose_path(free, start, goal, turning_radius=5.0, retry_expansions=3)
    assert capped.value.reason == "max_expansions" and capped.value.stats["retried"]
    assert first < capped.value.stats["expanded"] <= first + 3
    again = find_pose_path(
        free, start, goal, turning_radius=5.0, retry_expansions=ref.stats["expanded"]
    )
    np.testing.assert_array_equal(again.poses, ref.poses)


@st.composite
def _queries(draw):
    ny = draw(st.integers(8, 18))
    nx = draw(st.integers(8, 18))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    free = _closed(ny, nx) & (rng.random((ny, nx)) > draw(st.floats(0.0, 0.25)))
    cells = np.argwhere(free)
    assume(len(cells) >= 2)
    i, j = rng.choice(len(cells), 2, replace=False)
    heads = draw(st.tuples(st.floats(-math.pi, math.pi), st.floats(-math.pi, math.pi)))
    start = (float(cells[i][1]), float(cells[i][0]), heads[0])
    goal = (float(cells[j][1]), float(cells[j][0]), heads[1])
    return free, start, goal, draw(st.floats(0.8, 4.0)), draw(st.booleans())


@settings(max_examples=30, deadline=None)
@given(_queries())
def test_random_grids_hypothesis(q):
    """Every path found is collision-free (dense), within the curvature bound, exact at both
    ends, its segments consistent; every refusal a typed NoPathError with a reason."""
    free, start, goal, radius, reverse = q
    try:
        p = find_pose_path(
            free, start, goal, turning_radius=radius, reverse=reverse, time_budget=0.3
        )
    except NoPosePathError as e:
        assert e.reason in ("disconnected", "exhausted", "time_budget", "max_expansions")
        return
    check_path(p, free, start, goal, radius)
    if not reverse:
        assert p.cusps == 0 and p.reverse_length == 0


def test_distance_field_matches_dijkstra():
    """The 2-D heuristic against scipy's Dijkstra on the same graph (steps 1 and 1.4, no
    corner cutting); stopped early, every value stays a lower bound."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import dijkstra

    from astar.hybrid_kernel import distance_field

    rng = np.random.default_rng(2)
    free = _closed(15, 20) & (rng.random((15, 20)) > 0.25)
    ny, nx = free.shape
    rows, cols, w = [], [], []
    for iy, ix in np.argwhere(free):
        for dx, dy in ((1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (-1, 1), (1, -1), (-1, -1)):
            vx, vy = ix + dx, iy + dy
            if not free[vy, vx] or (dx and dy and not (free[iy, vx] and free[vy, ix])):
                continue
            rows.append(iy * nx + ix)
            cols.append(vy * nx + vx)
            w.append(1.4 if dx and dy else 1.0)
    graph = coo_matrix((w, (rows, cols)), shape=(ny * nx, ny * nx)).tocsr()
    gy, gx = np.argwhere(free)[0]
    sy, sx = np.argwhere(free)[-1]
    ref = dijkstra(graph, indices=gy * nx + gx).reshape(ny, nx)
    ref[~free] = np.inf
    full, reached = distance_field(free.astype(np.uint8), gx, gy, sx, sy, np.inf)
    assert reached == bool(np.isfinite(ref[sy, sx]))
    np.testing.assert_allclose(full, ref, rtol=1e-12)
    part, _ = distance_field(free.astype(np.uint8), gx, gy, gx, gy, 2.0)
    fin = np.isfinite(ref)
    assert np.all(part[fin] <= ref[fin] + 1e-12) and np.all(np.isinf(part[~free]))


# --------------------------------------------------------------------------- exact clearance


def test_segment_clearance_against_dense_samples():
    """segment_clearance_ok against the brute-force clearance of dense points on the segment."""
    from astar.hybrid_kernel import segment_clearance_ok
    from tests.reference import square_clearance

    rng = np.random.default_rng(5)
    occ = rng.random((14, 16)) < 0.15
    grid = _world(occ)
    occ8 = occ.astype(np.uint8)
    seen = {True: 0, False: 0}
    for _ in range(400):
        a, b = rng.uniform(-0.5, 15.5, 2), rng.uniform(-0.5, 13.5, 2)
        p0 = np.array([a[0], b[0]])
        p1 = p0 + rng.normal(0.0, 1.0, 2)
        r = rng.uniform(0.3, 2.5)
        t = np.linspace(0.0, 1.0, 2001)[:, None]
        d = square_clearance(grid, p0 + t * (p1 - p0)).min()
        spacing = float(np.hypot(*(p1 - p0))) / 2000
        if abs(d - r) < spacing + 1e-6:
            continue  # too close to tell by samples
        got = segment_clearance_ok(occ8, p0[0], p0[1], p1[0], p1[1], r)
        assert got == (d > r), (p0, p1, r, d)
        seen[got] += 1
    assert min(seen.values()) > 20


def test_exact_clearance_start_at_the_radius_from_a_wall():
    """A start exactly the radius from a wall (a cell centre 2.5 cells from the wall's
    squares): blocked on a grid inflated by the radius plus half a cell's diagonal; on the
    grid inflated by the radius, the exact mode's poses and the chords between them keep the
    radius, where the plain search's poses may come closer (anywhere in their cells)."""
    r = 2.5
    occ = np.zeros((20, 40), bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    occ[8:20, 18:21] = True  # a wall down from the top: the path goes round its end
    raw = _world(occ)
    free = ~astar.inflate(raw, r, metric="square", outside_occupied=True).occupied
    margin = ~astar.inflate(raw, r + 0.757, metric="square", outside_occupied=True).occupied
    start, goal = (5.0, 3.0, 0.3), (32.0, 14.0, math.pi / 2)
    assert free[3, 5] and not margin[3, 5]
    plain = find_pose_path(free, start, goal, turning_radius=5.0)
    exact = find_pose_path(free, start, goal, turning_radius=5.0, raw_grid=occ, clearance=r)
    assert _polyline_clearance(raw, plain.poses) < r - 0.05  # the plain poses cut corners
    assert _polyline_clearance(raw, exact.poses) >= r - 1e-9
    np.testing.assert_allclose(exact.poses[[0, -1], :2], [start[:2], goal[:2]], atol=1e-12)
    # the poses are the collision samples: at most 0.2 cells apart
    assert np.hypot(*np.diff(exact.poses[:, :2], axis=0).T).max() <= 0.2 + 1e-9


def test_exact_clearance_random_grids():
    """Every exact-mode path on random grids keeps the clearance (brute force)."""
    rng = np.random.default_rng(11)
    found = 0
    for _ in range(12):
        occ = rng.random((30, 30)) < 0.04
        occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
        raw = _world(occ)
        r = float(rng.uniform(1.0, 2.0))
        free = ~astar.inflate(raw, r, metric="square", outside_occupied=True).occupied
        cells = np.argwhere(free)
        if len(cells) < 2:
            continue
        (sy, sx), (gy, gx) = cells[rng.choice(len(cells), 2, replace=False)]
        s = (float(sx), float(sy), float(rng.uniform(-math.pi, math.pi)))
        g = (float(gx), float(gy), float(rng.uniform(-math.pi, math.pi)))
        try:
            p = find_pose_path(free, s, g, turning_radius=3.0, raw_grid=raw, clearance=r)
        except NoPathError:
            continue
        found += 1
        assert _polyline_clearance(raw, p.poses) >= r - 1e-9
    assert found >= 4


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"clearance": 1.0}, "needs raw_grid"),
        ({"raw_grid": np.zeros((10, 20), bool)}, "only with clearance"),
        ({"raw_grid": np.zeros((5, 5), bool), "clearance": 1.0}, "shape"),
        ({"raw_grid": np.zeros((10, 20)), "clearance": 1.0}, "bool array True on occupied"),
        ({"raw_grid": np.zeros((10, 20), bool), "clearance": -1.0}, "clearance"),
    ],
)
def test_exact_clearance_bad_input(kwargs, match):
    with pytest.raises(InvalidInputError, match=match):
        find_pose_path(np.ones((10, 20), bool), (3, 5, 0), (12, 5, 0), turning_radius=2, **kwargs)
