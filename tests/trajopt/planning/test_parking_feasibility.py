"""Tests of trajopt.planning's parking benchmark: the feasibility check (benchmarks/parking_feasibility.py).

The check decides whether a car can get from one pose to another at all, from the
connectivity of its free configuration space. Its signed distance is tested against hand
values (a square 1 m from a polygon, a square 0.3 m into a wall) and against the suite's
independent exact checker (the sign and the clearance on random poses; every pose moving
body points less than the depth bound still overlaps). Its verdicts are tested on scenes
whose answer follows by hand: an empty walled box (feasible, with a witness the exact
checker finds clear), a closed room with the goal outside it (infeasible: the outer fill
proves it), a closed corridor narrower than the body's length with the goal turned round
(infeasible: at a heading across the corridor the body's extent exceeds its width), the
same corridor wider than the body's diagonal (feasible: it turns in place), and a turn
from heading 170 to -170 degrees in the narrow corridor (feasible only across the heading
seam).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from benchmarks import parking_cases as pc
from benchmarks import parking_feasibility as pf

#: A 1.0 x 0.5 m body, the reference point 0.2 m ahead of its back (counter-clockwise).
BODY = np.array([[-0.2, -0.25], [0.8, -0.25], [0.8, 0.25], [-0.2, 0.25]])


def _box(x0, y0, x1, y1):
    return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=float)


def _walls(x0, y0, x1, y1, t=0.2):
    """Four wall rectangles ``t`` thick closing the rectangle ``[x0, x1] x [y0, y1]``."""
    return [
        _box(x0 - t, y0 - t, x1 + t, y0),
        _box(x0 - t, y1, x1 + t, y1 + t),
        _box(x0 - t, y0, x0, y1),
        _box(x1, y0, x1 + t, y1),
    ]


def test_signed_distance_hand_values():
    square = _box(0.0, 0.0, 1.0, 1.0)
    poses = np.array([[0.0, 0.0, 0.0]])
    # a unit square 1 m left of a polygon: distance 1
    assert pf.signed_distance(square, poses, [_box(2.0, 0.0, 3.0, 1.0)])[0] == pytest.approx(1.0)
    # the square 0.3 m into a wall: its right edge is 0.3 m deep, the wall's edge 0.3 m in it
    assert pf.signed_distance(square, poses, [_box(0.7, -1.0, 2.0, 2.0)])[0] == pytest.approx(-0.3)
    # touching counts as meeting, depth 0
    assert pf.signed_distance(square, poses, [_box(1.0, 0.0, 2.0, 1.0)])[0] == 0.0
    # no polygon: infinitely far
    assert pf.signed_distance(square, poses, [])[0] == math.inf


def test_signed_distance_agrees_with_the_exact_checker_and_its_depth_is_sound():
    case = pc.make_cases(pc.CARS["small"], 3)[2]
    body = case.car.body()
    rng = np.random.default_rng(5)
    x0, y0, x1, y1 = case.bounds
    poses = np.column_stack(
        [rng.uniform(x0, x1, 400), rng.uniform(y0, y1, 400), rng.uniform(-np.pi, np.pi, 400)]
    )
    s = pf.signed_distance(body, poses, case.polygons)
    over = pc.body_overlaps(body, poses, case.polygons)
    np.testing.assert_array_equal(s <= 0.0, over)
    clr = pc.body_clearance(body, poses[~over], case.polygons)
    np.testing.assert_allclose(s[~over], clr, atol=1e-9)
    # every pose moving body points less than the depth bound still overlaps
    r_far = float(np.max(np.hypot(body[:, 0], body[:, 1])))
    deep = np.flatnonzero(s < 0.0)[:60]
    assert len(deep) >= 20
    moved = []
    for i in deep:
        d = rng.normal(size=(20, 3))
        d /= (np.hypot(d[:, 0], d[:, 1]) + np.abs(d[:, 2]) * r_far)[:, None]
        moved.append(poses[i] + d * (-s[i]) * rng.uniform(0.0, 0.999, (20, 1)))
    assert pc.body_overlaps(body, np.vstack(moved), case.polygons).all()


def _decide(polygons, start, goal, region, resolution=0.1, refine=0):
    return pf.feasibility(BODY, polygons, start, goal, region, resolution, refine=refine)


def test_an_empty_walled_box_is_feasible_with_a_clear_witness():
    walls = _walls(0.0, 0.0, 4.0, 3.0)
    start, goal = (1.0, 1.0, 0.0), (3.0, 2.0, 2.5)
    v = _decide(walls, start, goal, (-0.2, -0.2, 4.2, 3.2))
    assert v.verdict == "feasible"
    assert v.witness_clear is True
    w = v.witness
    np.testing.assert_allclose(w[0, :2], start[:2])
    np.testing.assert_allclose(w[-1, :2], goal[:2])
    assert math.remainder(w[0, 2] - start[2], 2 * math.pi) == pytest.approx(0.0, abs=1e-12)
    assert math.remainder(w[-1, 2] - goal[2], 2 * math.pi) == pytest.approx(0.0, abs=1e-12)


def test_a_closed_room_with_the_goal_outside_is_infeasible():
    # a 2 x 2 m room (walls 0.2 m thick) inside a 6 x 6 m box; the goal in the box outside
    polys = [*_walls(0.0, 0.0, 6.0, 6.0), *_walls(1.0, 1.0, 3.0, 3.0)]
    start, goal = (1.6, 2.0, 0.0), (4.5, 4.5, 0.0)
    v = _decide(polys, start, goal, (-0.2, -0.2, 6.2, 6.2))
    assert v.verdict == "infeasible"
    # the same room with a 0.9 m doorway in its right wall: feasible
    door = (
        [p for p in polys[:5]] + polys[6:7] + [_box(3.0, 1.0, 3.2, 1.55), _box(3.0, 2.45, 3.2, 3.2)]
    )
    door.append(_box(0.8, 0.8, 1.0, 3.2))
    v = _decide(door, start, goal, (-0.2, -0.2, 6.2, 6.2), resolution=0.05, refine=1)
    assert v.verdict == "feasible" and v.witness_clear is True


def _corridor(width, start_heading, goal_heading, resolution=0.05):
    """A closed corridor 4 m long; the body's centre at its middle line, 1 m apart."""
    polys = _walls(0.0, 0.0, 4.0, width)

    def pose(cx, h):  # the reference point lies 0.3 m behind the body's centre
        return (cx - 0.3 * math.cos(h), 0.5 * width - 0.3 * math.sin(h), h)

    region = (-0.2, -0.2, 4.2, width + 0.2)
    return _decide(polys, pose(1.5, start_heading), pose(2.5, goal_heading), region, resolution)


def test_a_corridor_narrower_than_the_body_is_long_cannot_turn_round():
    # at a heading across the corridor the body spans its length, 1.0 m > 0.7 m
    assert _corridor(0.7, 0.0, math.pi).verdict == "infeasible"


def test_a_corridor_wider_than_the_body_diagonal_lets_it_turn_round():
    # the body turns in place about its centre: its diagonal 1.03 m < 1.5 m
    v = _corridor(1.5, 0.0, math.pi)
    assert v.verdict == "feasible" and v.witness_clear is True


def test_a_turn_across_the_heading_seam():
    # 175 -> -175 degrees in a corridor 0.8 m wide: only through +-180 degrees (the body
    # spans 0.59 m across the corridor at 175 degrees, more than 0.8 m from about 160 on)
    v = _corridor(0.8, math.radians(175.0), math.radians(-175.0))
    assert v.verdict == "feasible" and v.witness_clear is True
    assert np.all(np.cos(v.witness[:, 2]) < -0.9)


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="resolution"):
        pf.feasibility(BODY, [], (0, 0, 0), (1, 0, 0), (-1, -1, 2, 1), 0.0)
    with pytest.raises(ValueError, match="refine"):
        pf.feasibility(BODY, [], (0, 0, 0), (1, 0, 0), (-1, -1, 2, 1), 0.1, refine=-1)
    with pytest.raises(ValueError, match="convex"):
        pf.signed_distance(
            np.array([[0, 0], [2, 0], [1, 0.2], [2, 1], [0, 1.0]]), np.zeros((1, 3)), []
        )
