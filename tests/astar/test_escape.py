"""Tests of astar.escape: the escape of a car's body out of a tight pose, against polygons.

References, independent of :func:`astar.body_polygons.body_distance`: shapely's exact
polygon distance (the body as a shapely polygon at each pose), at poses so dense that no
body corner moves more than 5 mm between two (every returned move, driven from its start
pose by the closed-form arc written here); a hand derivation (a square driven straight at a
wall stops ``margin`` short of it); dense sampling of an arc's clearance (the longest clear
length of a turning move).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely

import astar
from astar.body_polygons import pack_polygons
from astar.escape import NoEscapeError, arc_reach

#: The small delivery car of the parking benchmarks (0.9 x 0.5 m, rear axle 0.184 m from
#: its back; its reference point), R = 0.6 m: the escape's arcs at 1.05 R.
BODY = np.array([[-0.184, -0.25], [0.716, -0.25], [0.716, 0.25], [-0.184, 0.25]])
RADIUS = 1.05 * 0.6


def box(x0: float, y0: float, x1: float, y1: float) -> np.ndarray:
    return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=float)


def bay_scene() -> list[np.ndarray]:
    """A bay 1.24 car widths wide entered nose first (+x) off an aisle 1.3 car lengths wide.

    The car's sides keep 0.06 m from the bay's neighbours; the aisle behind it ends at a
    wall; the aisle runs along y.
    """
    return [
        box(-0.05, 0.31, 1.0, 1.2),  # the neighbour on the left
        box(-0.05, -1.2, 1.0, -0.31),  # on the right
        box(0.8, -1.2, 1.2, 1.2),  # the kerb ahead
        box(-1.45, -3.0, -1.25, 3.0),  # the aisle's far wall
        box(-1.45, 3.0, 1.2, 3.2),  # the aisle's ends
        box(-1.45, -3.2, 1.2, -3.0),
    ]


def body_at(x: float, y: float, th: float) -> shapely.Polygon:
    c, s = math.cos(th), math.sin(th)
    return shapely.Polygon([(x + c * a - s * b, y + s * a + c * b) for a, b in BODY])


def arc_end(x: float, y: float, th: float, k: float, s: float) -> tuple[float, float, float]:
    if k == 0.0:
        return x + s * math.cos(th), y + s * math.sin(th), th
    t = th + k * s
    return x + (math.sin(t) - math.sin(th)) / k, y - (math.cos(t) - math.cos(th)) / k, t


def dense_clearance(pieces: np.ndarray, polygons: list[np.ndarray]) -> float:
    """The least shapely distance of the body to the polygons along every piece."""
    obstacles = shapely.union_all([shapely.Polygon(p) for p in polygons])
    rho = float(np.max(np.hypot(BODY[:, 0], BODY[:, 1])))
    least = math.inf
    for x, y, th, k, s in pieces:
        m = max(2, math.ceil(abs(s) * (1.0 + rho * abs(k)) / 0.005))
        for v in np.linspace(0.0, s, m + 1):
            least = min(least, body_at(*arc_end(x, y, th, k, v)).distance(obstacles))
    return least


@pytest.fixture(scope="module")
def bay_escape():
    return astar.find_escape(BODY, (0.0, 0.0, 0.0), bay_scene(), RADIUS, max_expansions=20_000)


def test_the_escape_leaves_the_bay_clear_of_the_polygons(bay_escape):
    polygons = bay_scene()
    obstacles = shapely.union_all([shapely.Polygon(p) for p in polygons])
    margin = 0.004 * RADIUS  # the default margin, MARGIN_R times the radius
    room = 0.35 / 3.0 * RADIUS
    assert body_at(0.0, 0.0, 0.0).distance(obstacles) < room  # the pose is tight
    p = bay_escape.pieces
    assert len(p) >= 1 and bay_escape.cusps == int(np.count_nonzero(np.diff(np.sign(p[:, 4]))))
    np.testing.assert_allclose(p[0, :3], [0.0, 0.0, 0.0], atol=1e-12)
    for a, b in zip(p, p[1:], strict=False):  # the moves join in pose
        np.testing.assert_allclose(arc_end(*a), b[:3], atol=1e-9)
    np.testing.assert_allclose(arc_end(*p[-1]), bay_escape.end, atol=1e-9)
    assert np.all(np.abs(p[:, 3]) <= 1.0 / RADIUS + 1e-12)  # arcs no tighter than the radius
    assert np.all(np.isin(np.round(np.abs(p[:, 3]) * RADIUS, 12), (0.0, 1.0)))
    # every pose of every move keeps the margin (to the 5 mm corner steps' slack)
    assert dense_clearance(p, polygons) >= margin - 1e-9
    assert body_at(*bay_escape.end).distance(obstacles) >= room - 1e-9
    assert bay_escape.length == pytest.approx(float(np.abs(p[:, 4]).sum()))
    assert 0 < bay_escape.expanded <= 20_000


def test_the_escape_is_deterministic(bay_escape):
    again = astar.find_escape(BODY, (0.0, 0.0, 0.0), bay_scene(), RADIUS, max_expansions=20_000)
    np.testing.assert_array_equal(again.pieces, bay_escape.pieces)
    assert again.expanded == bay_escape.expanded


def test_reversed_pieces_drive_the_escape_back_to_the_pose(bay_escape):
    back = astar.reversed_pieces(bay_escape.pieces)
    np.testing.assert_allclose(back[0, :3], bay_escape.end, atol=1e-9)
    np.testing.assert_allclose(arc_end(*back[-1]), (0.0, 0.0, 0.0), atol=1e-9)
    assert np.all(np.sign(back[:, 4]) == -np.sign(bay_escape.pieces[::-1, 4]))
    poses, directions, segments, _ = astar.join_escape([back], (0.0, 0.0, 0.0), 0.05)
    np.testing.assert_allclose(poses[0], bay_escape.end, atol=1e-9)
    np.testing.assert_array_equal(poses[-1], [0.0, 0.0, 0.0])
    assert len(segments) == bay_escape.cusps + 1
    assert np.max(np.hypot(*np.diff(poses[:, :2], axis=0).T)) <= 0.05 + 1e-9


def test_a_move_straight_at_a_wall_stops_margin_short_of_it():
    # a square 0.6 m wide centred on its reference point, a wall 1.0 m ahead of the centre:
    # the body may advance 1.0 - 0.3 - margin
    sq = np.ascontiguousarray(box(-0.3, -0.3, 0.3, 0.3))
    edges, starts, boxes = pack_polygons([box(1.0, -2.0, 1.2, 2.0)])
    margin, tol = 0.01, 1e-4
    buf = np.empty_like(sq)
    rho = float(np.max(np.hypot(sq[:, 0], sq[:, 1])))
    s = arc_reach(edges, starts, boxes, sq, rho, 0.0, 0.0, 0.0, 0.0, 1, 5.0, margin, tol, -1.0, buf)
    assert 0.69 - tol <= s <= 0.69
    # backwards: nothing behind within the longest move
    s = arc_reach(
        edges, starts, boxes, sq, rho, 0.0, 0.0, 0.0, 0.0, -1, 0.5, margin, tol, -1.0, buf
    )
    assert s == 0.5


def test_a_turning_move_stops_where_dense_sampling_says():
    sq = np.ascontiguousarray(box(-0.2, -0.3, 0.9, 0.3))
    wall = box(1.2, -2.0, 1.4, 2.0)
    edges, starts, boxes = pack_polygons([wall])
    margin, tol, k = 0.01, 1e-4, 1.0 / 0.8
    buf = np.empty_like(sq)
    rho = float(np.max(np.hypot(sq[:, 0], sq[:, 1])))
    s = arc_reach(edges, starts, boxes, sq, rho, 0.0, 0.0, 0.0, k, 1, 2.0, margin, tol, -1.0, buf)
    ob = shapely.Polygon(wall)

    def clear(v: float) -> float:
        x, y, th = arc_end(0.0, 0.0, 0.0, k, v)
        c, si = math.cos(th), math.sin(th)
        return shapely.Polygon([(x + c * a - si * b, y + si * a + c * b) for a, b in sq]).distance(
            ob
        )

    grid = np.arange(0.0, 2.0, 2e-4)
    d = np.array([clear(v) for v in grid])
    first_below = grid[np.argmax(d < margin)]  # where dense sampling first finds less
    assert np.all(d[grid <= s] >= margin - 1e-9)
    assert first_below - tol - 2e-4 <= s <= first_below


def test_a_boxed_in_pose_has_no_escape_and_says_so():
    walls = [
        box(-0.3, 0.26, 0.8, 0.4),  # 1 cm from each side of the body
        box(-0.3, -0.4, 0.8, -0.26),
        box(0.726, -0.4, 0.86, 0.4),
        box(-0.34, -0.4, -0.194, 0.4),
    ]
    with pytest.raises(NoEscapeError, match=r"exhausted: \d+ expansions") as info:
        astar.find_escape(BODY, (0.0, 0.0, 0.0), walls, RADIUS, max_expansions=50_000)
    assert info.value.reason == "exhausted"
    assert 0 < info.value.expanded < 50_000
    assert isinstance(info.value, astar.NoPathError)


def test_the_expansion_cap_decides():
    with pytest.raises(NoEscapeError, match="max_expansions") as info:
        astar.find_escape(BODY, (0.0, 0.0, 0.0), bay_scene(), RADIUS, max_expansions=3)
    assert info.value.expanded == 3


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"pose": (0.0, 0.3, 0.0)}, "margin"),  # the body meets the left neighbour
        ({"turning_radius": 0.0}, "turning_radius"),
        ({"margin": -0.01}, "margin"),
        ({"rotation_weight": -1.0}, "rotation_weight"),
        ({"turns": (2.0,)}, "turns"),
        ({"max_expansions": 0}, "max_expansions"),
        ({"moves": (0.1, -0.2)}, "moves"),
        ({"pose": (0.0, math.nan, 0.0)}, "pose"),
    ],
)
def test_bad_input_is_refused_naming_the_field(kwargs, field):
    args = {"pose": (0.0, 0.0, 0.0), "turning_radius": RADIUS, **kwargs}
    pose, radius = args.pop("pose"), args.pop("turning_radius")
    with pytest.raises(astar.InvalidInputError, match=field):
        astar.find_escape(BODY, pose, bay_scene(), radius, **args)
