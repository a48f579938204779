"""Tests of astar.hybrid: Hybrid-A* with an oriented footprint: brute-force body checks, narrow passages, bad input.

The reference here is deliberately naive and shares no code with the library: the path's
exact pieces are re-integrated in closed form with numpy every 0.01 cells, and at every such
pose the footprint is rotated and moved there and sampled densely (its boundary every 0.01
cells and an interior grid 0.01 cells apart); no sample may lie in an occupied square (the
closed square ``[ix - 0.5, ix + 0.5] x [iy - 0.5, iy + 0.5]``) or outside the grid.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from astar import InvalidInputError, NoPathError
from astar.body_polygons import pack_polygons
from astar.hybrid import NoPosePathError, find_pose_path
from tests.astar.hybrid_checks import (
    REAR,
    SMALL,
    body_collisions,
    body_points,
    check_footprint_path,
    dense_poses,
    square_distance,
)
from tests.astar.hybrid_checks import inflated as _inflated
from tests.astar.hybrid_checks import wrap as _wrap

RECT = np.array([[-2.0, -1.0], [2.0, -1.0], [2.0, 1.0], [-2.0, 1.0]])  # 4 x 2, origin centred
RECT_RHO = math.hypot(2.0, 1.0)


# --------------------------------------------------------------------------- the reference


# --------------------------------------------------------------------------- hand maps
def _rooms_and_corridor(width: int) -> np.ndarray:
    """Two rooms 40 x 20 joined by a straight corridor ``width`` cells wide and 10 long."""
    occ = np.zeros((50, 40), bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    occ[20:30, :] = True
    occ[20:30, 18 : 18 + width] = False
    return occ


def test_reference_catches_a_body_that_cuts_a_corner():
    """The checker is not vacuous: a centre-only path on the inscribed-radius grid, round an
    obstacle, sweeps the rectangle's corners through it."""
    occ = _rooms_and_corridor(4)
    free = _inflated(occ, 1.0)
    start, goal = (10.0, 8.0, 0.0), (30.0, 40.0, math.pi / 2)
    plain = find_pose_path(free, start, goal, turning_radius=4.0)
    assert len(body_collisions(dense_poses(plain), RECT, occ)) > 0
    # and a pose 0.02 cells too close to a wall is caught, one just clear is not
    wall = np.zeros((50, 40), bool)
    wall[49, :] = True  # the squares span y in [48.5, 49.5]
    assert len(body_collisions(np.array([[20.0, 47.52, 0.0]]), RECT, wall)) == 1
    assert len(body_collisions(np.array([[20.0, 47.48, 0.0]]), RECT, wall)) == 0
    assert len(body_collisions(np.array([[20.0, 47.0, 0.0]]), RECT, wall, margin=0.6)) == 1
    assert len(body_collisions(np.array([[20.0, 47.0, 0.0]]), RECT, wall, margin=0.4)) == 0
    # and a square wholly inside the body
    inner = np.zeros((50, 40), bool)
    inner[20, 20] = True
    assert len(body_collisions(np.array([[20.2, 20.1, 0.3]]), RECT, inner)) == 1


def test_narrow_corridor_rectangle_passes_disc_does_not():
    """A corridor 4 cells wide: narrower than the rectangle's length (4) plus any slack and
    than the circumscribed disc's diameter (4.47), wider than its width (2)."""
    occ = _rooms_and_corridor(4)
    start, goal = (10.0, 8.0, 0.0), (30.0, 40.0, math.pi / 2)
    p = find_pose_path(
        _inflated(occ, 1.0), start, goal, turning_radius=4.0, raw_grid=occ, footprint=RECT
    )
    check_footprint_path(p, occ, RECT, start, goal)
    # through the corridor: its poses there all face along it
    inside = (p.poses[:, 1] > 21.0) & (p.poses[:, 1] < 28.0)
    assert inside.any() and np.all(np.abs(_wrap(p.poses[inside, 2] - math.pi / 2)) < 0.5)
    with pytest.raises(NoPosePathError) as e:
        find_pose_path(
            _inflated(occ, RECT_RHO),
            start,
            goal,
            turning_radius=4.0,
            raw_grid=occ,
            clearance=RECT_RHO,
        )
    assert e.value.reason in ("exhausted", "disconnected")


def test_corridor_reversing_body_faces_its_heading():
    """Backwards down the corridor facing up, to a goal whose body (ahead of its origin)
    ends 2 cells from the bottom wall: a body turned to the direction of travel would be in
    the wall there."""
    occ = _rooms_and_corridor(4)
    start, goal = (20.0, 40.0, math.pi / 2), (20.0, 3.0, math.pi / 2)
    p = find_pose_path(
        _inflated(occ, 0.5),
        start,
        goal,
        turning_radius=4.0,
        raw_grid=occ,
        footprint=REAR,
        reverse_penalty=1.0,
    )
    check_footprint_path(p, occ, REAR, start, goal)
    assert p.reverse_length > 30.0
    turned = dense_poses(p)[-1:] + (0.0, 0.0, math.pi)
    assert len(body_collisions(turned, REAR, occ)) == 1


def _parking() -> np.ndarray:
    """An aisle (rows 1..14) under two blocks (rows 15..28) with a bay 3 cells wide between."""
    occ = np.zeros((30, 40), bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    occ[15:, :] = True
    occ[15:22, 19:22] = False  # the bay: x in [18.5, 21.5], y up to 21.5
    return occ


def test_parking_bay_reached_aligned():
    occ = _parking()
    start, goal = (8.0, 6.0, 0.0), (20.0, 19.0, math.pi / 2)
    p = find_pose_path(
        _inflated(occ, 1.0), start, goal, turning_radius=3.0, raw_grid=occ, footprint=RECT
    )
    check_footprint_path(p, occ, RECT, start, goal)
    assert abs(_wrap(p.pieces[-1, 2] + p.pieces[-1, 3] * p.pieces[-1, 4] - goal[2])) < 1e-9
    assert abs(_wrap(p.poses[-1, 2] - goal[2])) < 1e-12
    # with the whole body in the bay (centre above y = 17.5) it is aligned with the bay:
    # the corners' spread across it, 2 cos(a) + 4 sin(a), is at most its width 3
    bay = dense_poses(p)
    bay = bay[bay[:, 1] > 17.5]
    assert len(bay) and np.all(np.abs(_wrap(bay[:, 2] - math.pi / 2)) < 0.28)
    # the disc of the circumscribed radius does not fit in the bay
    assert not _inflated(occ, RECT_RHO)[19, 20]


def test_margin_is_kept():
    """A margin of 0.3 cells into the bay 3 cells wide (0.5 cells each side of the aligned
    body): every boundary point keeps 0.3 from the squares; with 0.5 the goal is refused."""
    occ = _parking()
    start, goal = (8.0, 6.0, 0.0), (20.0, 19.0, math.pi / 2)
    p = find_pose_path(
        _inflated(occ, 1.0),
        start,
        goal,
        turning_radius=3.0,
        raw_grid=occ,
        footprint=RECT,
        footprint_margin=0.3,
    )
    check_footprint_path(p, occ, RECT, start, goal, margin=0.3)
    assert p.stats["footprint_margin"] == 0.3
    with pytest.raises(InvalidInputError, match=r"goal pose \(20, 19, 1.5708\)"):
        find_pose_path(
            _inflated(occ, 1.0),
            start,
            goal,
            turning_radius=3.0,
            raw_grid=occ,
            footprint=RECT,
            footprint_margin=0.5,
        )


def test_a_coarse_slack_keeps_the_guarantee():
    """``footprint_slack=0.4``: steps eight times as long, and still every pose of the path
    keeps the body clear (the brute force); the slack also acts as a margin at the samples,
    so into the bay 3 cells wide (0.5 each side of the aligned body) 0.5 is refused."""
    occ = _parking()
    start, goal = (8.0, 6.0, 0.0), (20.0, 19.0, math.pi / 2)
    args = (_inflated(occ, 1.0), start, goal)
    p = find_pose_path(*args, turning_radius=3.0, raw_grid=occ, footprint=RECT, footprint_slack=0.4)
    check_footprint_path(p, occ, RECT, start, goal)
    assert p.stats["footprint_slack"] == 0.4
    with pytest.raises(InvalidInputError, match=r"goal pose .*0 \+ 0.5 cells"):
        find_pose_path(*args, turning_radius=3.0, raw_grid=occ, footprint=RECT, footprint_slack=0.5)


def test_nose_to_the_wall():
    """The body 3.5 cells ahead of its rear origin: a goal whose nose stops 0.1 cells short
    of the wall is reached; one whose nose touches the wall is refused (though its centre is
    3.5 cells from the wall: the quick test skips only cells beyond the farthest vertex)."""
    occ = np.zeros((20, 40), bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True  # the right wall from x = 38.5
    free = _inflated(occ, 0.5)
    start, goal = (5.0, 10.0, 0.0), (34.9, 10.0, 0.0)
    p = find_pose_path(free, start, goal, turning_radius=3.0, raw_grid=occ, footprint=REAR)
    check_footprint_path(p, occ, REAR, start, goal)
    with pytest.raises(InvalidInputError, match=r"goal pose \(35, 10, 0\).*occupied cell \(39, "):
        find_pose_path(
            free, start, (35.0, 10.0, 0.0), turning_radius=3.0, raw_grid=occ, footprint=REAR
        )


def test_edge_next_against_a_row_scan():
    """edge_next: along each row, the first column at or after ``ix`` holding a 1 (``nx``:
    none), against a plain scan of the row; 2s (inside solid blocks) are skipped."""
    from astar.hybrid_modes import edge_next

    rng = np.random.default_rng(11)
    occ = rng.choice(np.array([0, 1, 2], dtype=np.uint8), size=(9, 13), p=[0.6, 0.25, 0.15])
    got = edge_next(occ)
    ny, nx = occ.shape
    assert got.shape == (ny, nx + 1) and got.dtype == np.int32
    for iy in range(ny):
        for ix in range(nx + 1):
            want = next((j for j in range(ix, nx) if occ[iy, j] == 1), nx)
            assert got[iy, ix] == want, (iy, ix)


def test_footprint_hit_against_dense_samples():
    """footprint_hit against the brute-force distance of dense boundary and interior samples."""
    from astar.hybrid_kernel import footprint_hit
    from astar.hybrid_modes import edge_next, footprint_polygon

    rng = np.random.default_rng(7)
    occ = rng.random((16, 18)) < 0.12
    occ8 = occ.astype(np.uint8)
    nosafe = np.zeros_like(occ8)
    seen = {True: 0, False: 0}
    for _ in range(300):
        # an ellipse's inscribed polygon (convex), turned, moved a little off the origin
        n = int(rng.integers(3, 8))
        ang = np.sort(rng.uniform(0, 2 * np.pi, n))
        poly = np.column_stack([np.cos(ang), np.sin(ang)]) * rng.uniform(0.3, 2.0, 2)
        a = rng.uniform(0, np.pi)
        poly = poly @ np.array([[np.cos(a), np.sin(a)], [-np.sin(a), np.cos(a)]])
        poly += rng.normal(0.0, 0.1, 2)
        if rng.random() < 0.5:
            poly = poly[::-1]
        try:
            fp = footprint_polygon(poly)
        except InvalidInputError:
            continue  # not convex, or the origin not strictly inside
        x, y = rng.uniform(0, 17), rng.uniform(0, 15)
        th = rng.uniform(-np.pi, np.pi)
        grow = float(rng.choice([0.0, 0.3]))
        c, s = math.cos(th), math.sin(th)
        boundary, interior = body_points(poly, 0.005, 0.05)
        rot = np.array([[c, -s], [s, c]])
        b = boundary @ rot.T + (x, y)
        d = square_distance(b, occ).min()
        pts = interior @ rot.T + (x, y)
        ix = np.floor(pts[:, 0] + 0.5).astype(int)
        iy = np.floor(pts[:, 1] + 0.5).astype(int)
        ok = (ix >= 0) & (ix < 18) & (iy >= 0) & (iy < 16)
        inside_hit = (~ok).any() or occ[iy[ok], ix[ok]].any()
        if not inside_hit and abs(d - grow) < 0.01:
            continue  # too close to tell by samples
        want = (not inside_hit) and d > grow
        got = (
            footprint_hit(occ8, edge_next(occ8), nosafe, fp, x, y, th, grow, np.empty((len(fp), 5)))
            == -1
        )
        assert got == want, (poly.tolist(), x, y, th, grow, d)
        seen[want] += 1
    assert min(seen.values()) > 20


def test_footprint_discs_clear_is_sound():
    """The discs' quick test never calls a pose clear that the exact test (footprint_hit)
    does not, on random maps, poses and growths; and it does answer in open space."""
    from astar.hybrid_kernel import footprint_discs_clear, footprint_hit
    from astar.hybrid_modes import clearance_bound, edge_next, footprint_discs, footprint_polygon

    rng = np.random.default_rng(5)
    answered = 0
    for trial in range(6):
        occ = rng.random((40, 40)) < (0.02 if trial % 2 else 0.005)
        occ8 = occ.astype(np.uint8)
        fdist = clearance_bound(occ8)
        nosafe = np.zeros_like(occ8)
        for poly in (SMALL, RECT, 3.0 * RECT):
            fp = footprint_polygon(poly)
            discs = footprint_discs(fp)
            # the discs cover the polygon: its vertices lie in their union
            for vx, vy in fp[:, :2]:
                assert np.any(np.hypot(discs[:, 0] - vx, discs[:, 1] - vy) <= discs[:, 2])
            for _ in range(300):
                x, y = rng.uniform(-2, 42, 2)
                th = rng.uniform(-np.pi, np.pi)
                grow = float(rng.choice([0.0, 0.3, 1.0]))
                if footprint_discs_clear(fdist, discs, x, y, th, grow):
                    answered += 1
                    buf = np.empty((len(fp), 5))
                    assert (
                        footprint_hit(occ8, edge_next(occ8), nosafe, fp, x, y, th, grow, buf) == -1
                    )
    assert answered > 200


@pytest.mark.parametrize("slack, min_slack", [(0.05, 0.05), (0.4, 0.025)])
def test_footprint_arc_clear_covers_the_whole_arc(slack, min_slack):
    """footprint_arc_clear against dense poses (0.01 cells apart) near obstacles: a clear
    verdict means no body point of any pose lies in an occupied square (sound between its
    samples), and an arc whose bodies all keep more than twice the least sampling slack
    (0.1 cells; 0.05 cells when a slack of 0.4 is halved down to 0.025) is clear."""
    from astar.hybrid_kernel import footprint_arc_clear
    from astar.hybrid_modes import (
        clearance_bound,
        edge_next,
        footprint_discs,
        footprint_polygon,
        footprint_radii,
        footprint_safe,
    )

    rng = np.random.default_rng(3)
    occ = rng.random((20, 20)) < 0.1
    occ8 = occ.astype(np.uint8)
    ny, nx = occ.shape
    pad = np.ones((ny + 2, nx + 2), bool)
    pad[1:-1, 1:-1] = occ
    seen = {"clear": 0, "blocked": 0}
    for poly in (SMALL, RECT):
        fp = footprint_polygon(poly)
        rho = footprint_radii(fp)[1]
        safe = footprint_safe(occ8, rho + slack)
        fdist, discs = clearance_bound(occ8), footprint_discs(fp)
        boundary, interior = body_points(poly, 0.01)
        pts0 = np.concatenate([boundary, interior])
        for _ in range(100):
            x, y, th = rng.uniform(3, 16), rng.uniform(3, 16), rng.uniform(-np.pi, np.pi)
            k = float(rng.choice([0.0, 0.5, -0.5, 1 / 3, -1 / 3]))
            s = float(rng.choice([-1, 1]) * rng.uniform(0.3, 2.0))
            m = math.ceil(abs(s) / 0.01)
            t = s * np.arange(m + 1) / m
            a = th + k * t
            if k == 0.0:
                poses = np.column_stack([x + t * math.cos(th), y + t * math.sin(th), a])
            else:
                poses = np.column_stack(
                    [x + (np.sin(a) - math.sin(th)) / k, y - (np.cos(a) - math.cos(th)) / k, a]
                )
            got = footprint_arc_clear(
                occ8,
                edge_next(occ8),
                safe,
                fp,
                fdist,
                discs,
                pack_polygons(None),
                rho,
                x,
                y,
                th,
                k,
                s,
                0.0,
                slack,
                min_slack,
                np.empty((len(fp), 5)),
            )
            c, sn = np.cos(poses[:, 2])[:, None], np.sin(poses[:, 2])[:, None]
            wx = poses[:, :1] + c * pts0[:, 0] - sn * pts0[:, 1]  # (poses, points)
            wy = poses[:, 1:2] + sn * pts0[:, 0] + c * pts0[:, 1]
            # the square (ix, iy) of each point, clipped to the pad's ring outside the grid
            jx = np.clip(np.floor(wx + 0.5), -1, nx) + 1
            jy = np.clip(np.floor(wy + 0.5), -1, ny) + 1
            hit = bool(pad.ravel()[(jy * (nx + 2) + jx).astype(np.intp)].any())
            if got:
                assert not hit, (poly.tolist(), x, y, th, k, s)
                seen["clear"] += 1
                continue
            seen["blocked"] += 1
            if hit:
                continue
            # clearance sampled every 0.04 cells of arc: the body moves <= 0.04 (1 + rho k)
            nb = len(boundary)
            w = np.column_stack([wx[::4, :nb].ravel(), wy[::4, :nb].ravel()])
            dmin = square_distance(w, occ).min()
            assert dmin <= 2 * min_slack + 0.04 * (1 + rho * abs(k)), (x, y, th, k, s, dmin)
    assert min(seen.values()) > 25


# --------------------------------------------------------------------------- random maps
@st.composite
def _maps(draw):
    occ = np.zeros((30, 30), bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    for _ in range(draw(st.integers(1, 6))):
        x0, y0 = draw(st.integers(1, 27)), draw(st.integers(1, 27))
        w, h = draw(st.integers(1, 6)), draw(st.integers(1, 6))
        occ[y0 : y0 + h, x0 : x0 + w] = True
    poly = draw(st.sampled_from([SMALL, REAR]))
    rho = float(np.hypot(poly[:, 0], poly[:, 1]).max())
    wide = _inflated(occ, rho + 0.1)  # any heading fits at these cells' centres
    cells = np.argwhere(wide)
    assume(len(cells) >= 2)
    i, j = draw(st.lists(st.integers(0, len(cells) - 1), min_size=2, max_size=2, unique=True))
    hs = draw(st.lists(st.floats(-math.pi, math.pi), min_size=2, max_size=2))
    start = (float(cells[i][1]), float(cells[i][0]), hs[0])
    goal = (float(cells[j][1]), float(cells[j][0]), hs[1])
    radius = draw(st.sampled_from([2.0, 3.0]))
    reverse = draw(st.booleans())
    return occ, start, goal, radius, reverse, poly


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(_maps())
def test_random_maps_bodies_are_clear(q):
    occ, start, goal, radius, reverse, poly = q
    try:
        p = find_pose_path(
            _inflated(occ, 0.5),  # both footprints' inscribed radius
            start,
            goal,
            turning_radius=radius,
            reverse=reverse,
            raw_grid=occ,
            footprint=poly,
            max_expansions=20_000,
            time_budget=1.0,
        )
    except NoPathError:
        assume(False)
        return
    check_footprint_path(p, occ, poly, start, goal)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(_maps())
def test_random_maps_from_the_goal_bodies_are_clear(q):
    occ, start, goal, radius, reverse, poly = q
    try:
        p = find_pose_path(
            _inflated(occ, 0.5),
            start,
            goal,
            turning_radius=radius,
            reverse=reverse,
            raw_grid=occ,
            footprint=poly,
            max_expansions=20_000,
            time_budget=1.0,
            search_from="goal",
        )
    except NoPathError:
        assume(False)
        return
    assert p.stats["search_from"] == "goal"
    check_footprint_path(p, occ, poly, start, goal)
    if not reverse:
        assert np.all(p.pieces[:, 4] > 0.0)


def test_without_footprint_nothing_changes():
    """No footprint: the same path as before the footprint mode existed (no new stats keys),
    and the footprint mode on an empty map finds the same path (no obstacle within reach)."""
    occ = np.zeros((20, 40), bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    free = _inflated(occ, 0.5)
    start, goal = (6.0, 6.0, 0.0), (30.0, 12.0, 1.0)
    plain = find_pose_path(free, start, goal, turning_radius=3.0)
    assert "footprint" not in plain.stats
    foot = find_pose_path(free, start, goal, turning_radius=3.0, raw_grid=occ, footprint=SMALL)
    assert foot.stats["footprint"] is True and foot.stats["footprint_margin"] == 0.0
    check_footprint_path(foot, occ, SMALL, start, goal)


# --------------------------------------------------------------------------- bad input
_FREE = np.ones((10, 20), bool)
_RAW = np.zeros((10, 20), bool)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"footprint": SMALL}, r"footprint=.*needs raw_grid"),
        ({"footprint": SMALL, "raw_grid": _RAW, "clearance": 1.0}, r"footprint and clearance=1"),
        (
            {"footprint": [[-1, -1], [1, -1], [0, 0.5], [1, 1], [-1, 1]], "raw_grid": _RAW},
            r"footprint must be a convex polygon.*\[0\.0, 0\.5\]",
        ),
        (
            {"footprint": [[1, -1], [3, -1], [3, 1], [1, 1]], "raw_grid": _RAW},
            r"footprint must contain the robot's origin.*\[3\.0, -1\.0\]",
        ),
        (
            {"footprint": [[-1, -1], [1, -1], [1, 0], [-1, 0]], "raw_grid": _RAW},
            r"footprint must contain the robot's origin.*strictly",
        ),
        (
            {"footprint": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "raw_grid": _RAW},
            r"footprint.*\(3, 3\)",
        ),
        ({"footprint": [[-1, -1], [1, 1]], "raw_grid": _RAW}, r"footprint.*k >= 3.*\(2, 2\)"),
        ({"footprint": [1.0, 2.0, 3.0], "raw_grid": _RAW}, r"footprint.*shape \(3,\)"),
        ({"footprint": "square", "raw_grid": _RAW}, r"footprint.*'square'"),
        (
            {"footprint": [[-1, -1], [np.nan, -1], [1, 1], [-1, 1]], "raw_grid": _RAW},
            r"footprint vertices must be finite.*nan",
        ),
        (
            {"footprint": [[-1, -1], [1, -1], [1, -1], [-1, 1]], "raw_grid": _RAW},
            r"footprint vertices 1 and 2 coincide",
        ),
        (
            {"footprint": [[-1, -1], [1, -1], [-1, 1], [1, 1]], "raw_grid": _RAW},
            r"footprint must be a convex polygon",
        ),
        (
            {"footprint": SMALL, "raw_grid": _RAW, "footprint_margin": -1.0},
            r"footprint_margin must be finite and >= 0.*-1\.0",
        ),
        (
            {"footprint": SMALL, "raw_grid": _RAW, "footprint_margin": math.inf},
            r"footprint_margin must be finite.*inf",
        ),
        ({"footprint_margin": 0.5}, r"footprint_margin=0\.5 is used only with footprint"),
        (
            {"footprint": SMALL, "raw_grid": _RAW, "footprint_slack": 0.0},
            r"footprint_slack must be finite and > 0.*0\.0",
        ),
        (
            {"footprint": SMALL, "raw_grid": _RAW, "footprint_slack": math.nan},
            r"footprint_slack must be finite.*nan",
        ),
        ({"footprint_slack": 0.5}, r"footprint_slack=0\.5 is used only with footprint"),
        ({"footprint": SMALL, "raw_grid": np.zeros((5, 5), bool)}, r"raw_grid.*shape"),
        (
            {"footprint": SMALL * 8, "raw_grid": _RAW},
            r"start pose \(3, 5, 0\).*footprint.*leaves the grid",
        ),
    ],
)
def test_footprint_bad_input(kwargs, match):
    with pytest.raises(InvalidInputError, match=match):
        find_pose_path(_FREE, (3, 5, 0), (12, 5, 0), turning_radius=2, **kwargs)


def test_start_footprint_on_an_obstacle_names_the_cell():
    raw = np.zeros((10, 20), bool)
    raw[5, 5] = True  # 1.5 cells ahead of the start's rear origin: under the 2 x 1 body
    with pytest.raises(InvalidInputError, match=r"start pose .*occupied cell \(5, 5\)"):
        find_pose_path(
            _FREE, (4, 5, 0), (12, 5, 0), turning_radius=2, raw_grid=raw, footprint=SMALL
        )
