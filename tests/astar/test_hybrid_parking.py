"""Tests of astar: hybrid-A* searched from the goal (``search_from``): parking bodies, checked by brute force.

The search from the goal drives its primitives back in time and shoots from the start pose;
its path must be the same kind of path as a search from the start: it starts exactly at the
start pose, ends exactly at the goal, its pieces join, its curvature is within ``1/R``, it
drives only forwards with ``reverse=False`` and the body keeps clear of the raw map at every
pose (the naive reference of ``test_hybrid_footprint.py``: dense poses every 0.01 cells,
body boundary every 0.01 cells). The parking scene: a 0.88 x 0.4 m car (``R = 0.5 m``, rear
axle 0.18 m from its back) into a parallel slot 1.3 car lengths long, on 2.5 cm cells, in
cells.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import astar
from astar import InvalidInputError, NoPathError
from astar.hybrid import find_pose_path
from astar.hybrid_options import AUTO_PROBE
from tests.astar.hybrid_checks import REAR, SMALL, check_path, dense_poses
from tests.astar.hybrid_checks import inflated as _inflated
from tests.astar.hybrid_checks import polyline_clearance as _polyline_clearance
from tests.astar.hybrid_checks import world as _world
from tests.astar.hybrid_checks import wrap as _wrap

RES = 0.025  # m per cell
LENGTH, WIDTH, REAR_M, R_M = 0.88, 0.4, 0.18, 0.5


def parallel_slot(ratio: float):
    """Occupancy, footprint (cells), start and goal poses (cells) of a parallel slot.

    A lane 2.75 car widths wide above a row of parked cars with a slot ``ratio`` car lengths
    long and 1.35 widths deep; the car starts in the lane one length before the slot, facing
    along it, and parks in the slot's middle facing the same way.
    """
    lx, wy, rear = LENGTH / RES, WIDTH / RES, REAR_M / RES
    depth, lane, slot = round(1.35 * wy), round(2.75 * wy), round(ratio * lx)
    x0 = round(2.0 * lx)
    nx, ny = x0 + slot + round(2.0 * lx), 1 + depth + lane + 1
    occ = np.zeros((ny, nx), bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    occ[: 1 + depth, :] = True
    occ[1 : 1 + depth, x0 : x0 + slot] = False
    poly = np.array([[-rear, -wy / 2], [lx - rear, -wy / 2], [lx - rear, wy / 2], [-rear, wy / 2]])
    start = (x0 - lx + rear, 1 + depth + lane / 2 - 0.5, 0.0)
    goal = (x0 + (slot - lx) / 2 + rear - 0.5, 1 + depth / 2 - 0.5, 0.0)
    return occ, poly, start, goal


def check_big_body(p, occ, poly, start, goal, spacing=0.05):
    """The brute-force body check of a body many cells long (cells, its own closed forms).

    ``check_footprint_path``'s reference samples the interior every 0.1 cells, which for a
    body 35 cells long is slow; here: poses every ``spacing`` cells of arc (1.25 mm on 2.5 cm
    cells), the boundary every ``spacing`` cells looked up in the grid (a point on a square's
    closed boundary counts as in it), and every occupied cell's centre tested against the
    body's half-planes (a square wholly inside the body). Poses whose centre is farther than
    the body's reach from every occupied cell are skipped.
    """
    from scipy.ndimage import distance_transform_edt

    poses = dense_poses(p, spacing)
    np.testing.assert_allclose(poses[0], start, atol=1e-12)
    assert math.hypot(poses[-1, 0] - goal[0], poses[-1, 1] - goal[1]) < 1e-9
    assert abs(_wrap(poses[-1, 2] - goal[2])) < 1e-9
    ny, nx = occ.shape
    v = np.asarray(poly, float)
    e = np.roll(v, -1, axis=0) - v
    counts = np.maximum(1, np.ceil(np.hypot(e[:, 0], e[:, 1]) / spacing).astype(int))
    boundary = np.concatenate(
        [v[i] + e[i] * (np.arange(m) / m)[:, None] for i, m in enumerate(counts)]
    )
    normal = np.column_stack([e[:, 1], -e[:, 0]])
    if np.sum(v[:, 0] * np.roll(v[:, 1], -1) - np.roll(v[:, 0], -1) * v[:, 1]) < 0:
        normal = -normal  # clockwise: flip to outward
    offset = np.sum(normal * v, axis=1)
    rho = float(np.hypot(v[:, 0], v[:, 1]).max())
    dist = distance_transform_edt(~occ)  # cell centre to the nearest occupied centre
    cx = np.clip(np.floor(poses[:, 0] + 0.5).astype(int), 0, nx - 1)
    cy = np.clip(np.floor(poses[:, 1] + 0.5).astype(int), 0, ny - 1)
    near_pose = dist[cy, cx] <= rho + 2.0
    oy, ox = np.nonzero(occ)
    sel = poses[near_pose]
    for j in range(0, len(sel), 64):  # 64 poses at a time, as (poses, points) arrays
        x, y, th = sel[j : j + 64, :, None].transpose(1, 0, 2)
        c, s = np.cos(th), np.sin(th)
        bx = x + c * boundary[:, 0] - s * boundary[:, 1]
        by = y + s * boundary[:, 0] + c * boundary[:, 1]
        out = (
            (bx.min(1) < -0.5)
            | (bx.max(1) > nx - 0.5)
            | (by.min(1) < -0.5)
            | (by.max(1) > ny - 0.5)
        )
        assert not out.any(), sel[j + np.argmax(out)]
        # every square the point lies in (two or four on a shared side or corner)
        hit = np.zeros(len(x), bool)
        for dx, dy in ((-1e-9, -1e-9), (-1e-9, 1e-9), (1e-9, -1e-9), (1e-9, 1e-9)):
            jx = np.clip(np.floor(bx + dx + 0.5).astype(int), 0, nx - 1)
            jy = np.clip(np.floor(by + dy + 0.5).astype(int), 0, ny - 1)
            hit |= occ[jy, jx].any(axis=1)
        assert not hit.any(), sel[j + np.argmax(hit)]
        # the occupied centres in reach of the chunk's poses (no farther centre lies inside)
        near = (ox >= x.min() - rho - 1) & (ox <= x.max() + rho + 1)
        near &= (oy >= y.min() - rho - 1) & (oy <= y.max() + rho + 1)
        qx, qy = ox[near] - x, oy[near] - y
        lx, ly = c * qx + s * qy, -s * qx + c * qy  # into the body frame
        inside = np.ones(lx.shape, bool)
        for (n0, n1), off in zip(normal, offset, strict=True):
            inside &= lx * n0 + ly * n1 <= off
        inside = inside.any(axis=1)
        assert not inside.any(), sel[j + np.argmax(inside)]
    assert near_pose.sum() > 0


def _search(occ, poly, start, goal, **kw):
    inscribed = float(np.min(np.abs(poly)))  # the rectangle's about its origin
    free = _inflated(occ, inscribed - 0.5 * math.sqrt(2.0))
    return find_pose_path(
        free,
        start,
        goal,
        turning_radius=1.15 * R_M / RES,
        raw_grid=occ,
        footprint=poly,
        footprint_margin=0.01,
        footprint_slack=0.76,
        **kw,
    )


def test_parallel_slot_1_3_lengths_is_parked_backwards_from_the_goal():
    occ, poly, start, goal = parallel_slot(1.3)
    p = _search(occ, poly, start, goal, time_budget=2.0)
    # the slot is the tighter end: a probe from the start, then the search from the goal
    assert p.stats["search_from"] == "goal"
    probe, pull_out = p.stats["searches"]
    assert probe == {
        "from": "start",
        "status": 2,
        "stop": "max_expansions",
        "expanded": AUTO_PROBE,
    }
    assert pull_out["from"] == "goal" and pull_out["status"] == 1
    assert p.cusps >= 1 and p.reverse_length > 0.0
    check_big_body(p, occ, poly, start, goal)
    # the check is not vacuous: one more occupied cell under the body half way is caught
    mid = p.poses[len(p) // 2]
    worse = occ.copy()
    worse[int(math.floor(mid[1] + 0.5)), int(math.floor(mid[0] + 0.5))] = True
    with pytest.raises(AssertionError):
        check_big_body(p, worse, poly, start, goal)
    # entered backwards: the rear axle first crosses into the slot (below the parked cars'
    # line) driving backwards
    top = np.nonzero(~occ[:, 1])[0].min() - 0.5  # the upper side of the parked cars
    inside = np.nonzero(p.poses[:, 1] < top)[0]
    assert p.directions[inside[0]] == -1


def test_parallel_slot_from_the_start_is_the_old_search():
    """``search_from="start"`` is the search as it was: the slot's manoeuvre exhausts a small
    budget there (20 000 expansions; the search from the start, polishing its first path for
    at most as many expansions again plus 100, returns after 128 000, so its first path came
    after 64 000 at least), the search from the goal plans it within the same budget (in about 1 700).
    Budgets in expansions, so that the test does not depend on the machine's speed."""
    occ, poly, start, goal = parallel_slot(1.3)
    with pytest.raises(NoPathError) as info:
        _search(occ, poly, start, goal, max_expansions=20_000, search_from="start")
    assert info.value.reason == "max_expansions"
    assert info.value.stats["searches"] == [
        {"from": "start", "status": 2, "stop": "max_expansions", "expanded": 20_000}
    ]
    p = _search(occ, poly, start, goal, max_expansions=20_000, search_from="goal")
    check_big_body(p, occ, poly, start, goal)


def test_auto_searches_from_the_start_when_the_start_is_tighter():
    # the same query turned round: from the slot out to the lane
    occ, poly, start, goal = parallel_slot(1.5)
    p = _search(occ, poly, goal, start, time_budget=2.0)
    assert p.stats["search_from"] == "start"
    check_big_body(p, occ, poly, goal, start)


def test_auto_falls_back_to_the_other_end():
    """A search that gives up passes what is left of the budget to the other end."""
    occ, poly, start, goal = parallel_slot(1.3)
    with pytest.raises(NoPathError) as info:
        _search(occ, poly, start, goal, max_expansions=200)
    st_ = info.value.stats
    assert info.value.reason == "max_expansions"
    assert [s["from"] for s in st_["searches"]] == ["start", "goal"]
    assert st_["searches"][0]["expanded"] == 100  # AUTO_FIRST_SHARE of 200 (< AUTO_PROBE)
    assert st_["expanded"] == sum(s["expanded"] for s in st_["searches"]) == 200
    # the pull-out turned round: the start is the tighter end, searched first with half
    p = _search(occ, poly, goal, start, max_expansions=4000)
    assert [s["from"] for s in p.stats["searches"]] == ["start"]


# --------------------------------------------------------------------------- random maps


@pytest.mark.parametrize("reverse", [True, False])
def test_random_grids_from_the_goal_disc(reverse):
    """Without footprint: the generic checks of ``test_hybrid.py`` on paths from the goal."""
    rng = np.random.default_rng(5 + reverse)
    found = 0
    for _ in range(15):
        free = rng.random((25, 35)) > 0.08
        free[0, :] = free[-1, :] = free[:, 0] = free[:, -1] = False
        cells = np.argwhere(free)
        (sy, sx), (gy, gx) = cells[rng.choice(len(cells), 2, replace=False)]
        s = (float(sx), float(sy), float(rng.uniform(-math.pi, math.pi)))
        g = (float(gx), float(gy), float(rng.uniform(-math.pi, math.pi)))
        try:
            p = find_pose_path(
                free, s, g, turning_radius=2.0, reverse=reverse, search_from="goal",
                time_budget=0.5,
            )  # fmt: skip
        except NoPathError:
            continue
        found += 1
        check_path(p, free, s, g, 2.0)
        if not reverse:
            assert p.reverse_length == 0.0
    assert found >= 5


def test_exact_clearance_from_the_goal_keeps_the_clearance():
    """The exact mode's poses are its collision samples, from the goal too: the polyline
    through them keeps the clearance (brute force against the raw squares)."""
    rng = np.random.default_rng(3)
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
            p = find_pose_path(
                free, s, g, turning_radius=3.0, raw_grid=raw, clearance=r, search_from="goal"
            )
        except NoPathError:
            continue
        found += 1
        assert _polyline_clearance(raw, p.poses) >= r - 1e-9
        np.testing.assert_array_equal(p.poses[0], s)
        assert np.hypot(*np.diff(p.poses[:, :2], axis=0).T).max() <= 0.2 + 1e-9
    assert found >= 4


def test_search_from_bad_input():
    free = np.ones((10, 20), bool)
    with pytest.raises(InvalidInputError, match=r"search_from must be one of 'auto', 'start'"):
        find_pose_path(free, (5, 5, 0.0), (12, 5, 0.0), turning_radius=3.0, search_from="end")
    with pytest.raises(InvalidInputError, match="search_from"):
        astar.HybridLimits(search_from=None)


def test_edge_occupancy_gives_the_same_footprint_test():
    """Solid blocks tested by their rim only (:func:`astar.hybrid_modes.edge_occupancy`):
    the same answer as the full map, at random poses, centres inside blocks included."""
    from astar.hybrid_kernel import footprint_hit
    from astar.hybrid_modes import edge_next, edge_occupancy, footprint_polygon

    rng = np.random.default_rng(7)
    occ = np.zeros((40, 50), bool)
    for _ in range(8):
        x0, y0 = rng.integers(0, 45), rng.integers(0, 35)
        occ[y0 : y0 + rng.integers(2, 12), x0 : x0 + rng.integers(2, 12)] = True
    edge = edge_occupancy(occ)
    assert set(np.unique(edge)) == {0, 1, 2}
    assert np.array_equal(edge != 0, occ)
    full = occ.astype(np.uint8)
    nosafe = np.zeros_like(full)
    seen = {True: 0, False: 0}
    for poly in (REAR * 2.0, SMALL * 3.0, REAR):
        fp = footprint_polygon(poly)
        buf = np.empty((len(fp), 5))
        for _ in range(800):
            x, y = rng.uniform(-0.5, 49.5), rng.uniform(-0.5, 39.5)
            th, grow = rng.uniform(-np.pi, np.pi), float(rng.choice([0.0, 0.4]))
            a = footprint_hit(full, edge_next(full), nosafe, fp, x, y, th, grow, buf)
            b = footprint_hit(edge, edge_next(edge), nosafe, fp, x, y, th, grow, buf)
            assert (a == -1) == (b == -1) and (a == -2) == (b == -2), (x, y, th, grow)
            seen[a == -1] += 1
    assert min(seen.values()) > 100


def test_fine_states_near_the_ends_park_a_slot_1_2_lengths():
    """A slot 1.2 car lengths long: the pull-out from the goal exhausts its states at one
    pose per cell and heading bin; the second run, with 3 x 3 sub-cells, three times the
    heading bins and primitives a third as long within half a car length of the ends,
    leads out of it. The path passes the brute-force body check."""
    occ, poly, start, goal = parallel_slot(1.2)
    p = _search(occ, poly, start, goal, time_budget=4.0, fine_radius=0.5 * LENGTH / RES)
    assert p.stats["retried"] and p.stats["search_from"] == "goal"
    assert p.cusps >= 1
    check_big_body(p, occ, poly, start, goal)


def test_min_slack_admits_an_end_pose_the_slack_refuses():
    """An end pose whose body keeps 0.3 cells from the raw map (the parked car behind it):
    refused with a slack of 0.76 cells, searched from with footprint_min_slack 0.05 (failed
    samples refined); the path passes the brute-force body check, and a pose within the
    least slack is still refused."""
    occ, poly, start, goal = parallel_slot(1.5)
    # move the goal back until its body is 0.3 cells from the parked car behind the slot
    back = np.nonzero(~occ[1])[0][0] - 0.5  # the slot's back end (its first free column)
    body_back = goal[0] + poly[:, 0].min()
    goal = (goal[0] - (body_back - back - 0.3), goal[1], goal[2])
    with pytest.raises(InvalidInputError, match="least sampling slack"):
        _search(occ, poly, start, goal, time_budget=3.0)
    p = _search(occ, poly, start, goal, time_budget=3.0, footprint_min_slack=0.05)
    check_big_body(p, occ, poly, start, goal)
    too_close = (goal[0] - 0.27, goal[1], goal[2])  # 0.03 cells: within 0.01 + 0.05
    with pytest.raises(InvalidInputError, match="least sampling slack"):
        _search(occ, poly, start, too_close, time_budget=3.0, footprint_min_slack=0.05)
