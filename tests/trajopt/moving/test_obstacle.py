"""Tests of trajopt.moving: MovingObstacle, its constructors, its prediction and its checks."""

from __future__ import annotations

import math

import numpy as np
import pytest

import trajopt
from trajopt.errors import InvalidInputError
from trajopt.moving import MovingObstacle


def test_exported_from_the_face():
    assert trajopt.MovingObstacle is MovingObstacle
    assert issubclass(trajopt.BlockedError, trajopt.TrajoptError)


def test_constant_velocity_moves_then_stays():
    m = MovingObstacle.constant_velocity(
        (1.0, 2.0), (0.5, -0.25), radius=0.3, horizon=4.0, growth=0.1
    )
    np.testing.assert_allclose(m.position_at(0.0), [1.0, 2.0])
    np.testing.assert_allclose(m.position_at(2.0), [2.0, 1.5])
    np.testing.assert_allclose(m.position_at([4.0, 9.0]), [[3.0, 1.0], [3.0, 1.0]])
    np.testing.assert_allclose(m.radius_at([0.0, 2.0, 4.0, 10.0]), [0.3, 0.5, 0.7, 0.7])
    assert math.isclose(m.pose_at(1.0)[1], math.atan2(-0.25, 0.5))
    assert m.speed_max() == pytest.approx(math.hypot(0.5, 0.25))
    assert not m.positions.flags.writeable


def test_waypoints_are_linear_and_a_polygon_turns():
    sq = [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)]
    m = MovingObstacle.from_waypoints(
        [0.0, 2.0, 3.0],
        [(0, 0), (2, 0), (2, 1)],
        radius=0.0,
        headings=[0, 0, math.pi / 2],
        vertices=sq,
    )
    np.testing.assert_allclose(m.position_at([1.0, 2.5, 7.0]), [[1, 0], [2, 0.5], [2, 1]])
    assert m.pose_at(2.5)[1] == pytest.approx(math.pi / 4)
    cw = MovingObstacle.from_waypoints([0.0], [(0, 0)], radius=0.1, vertices=sq[::-1])
    assert np.allclose(cw.vertices, np.array(sq[::-1])[::-1])  # stored counter-clockwise


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"times": [0.0, 1.0, 1.0]}, "times"),
        ({"times": [0.0, float("nan"), 2.0]}, "times"),
        ({"times": [2.0, 1.0, 3.0]}, "times"),
        ({"radius": -0.1}, "radius"),
        ({"radius": float("inf")}, "radius"),
        ({"growth": -1.0}, "growth"),
        ({"positions": [(0, 0), (1, 1)]}, "positions"),
        ({"vertices": [(0, 0), (2, 0), (1, 0.2), (1, 2)]}, "vertices"),  # a dent
        ({"vertices": [(0, 0), (1, 1), (1, 0), (0, 1)]}, "vertices"),  # self-crossing
        ({"vertices": [(0, 0), (1, 0), (2, 0)]}, "vertices"),  # no area
        ({"headings": [0.0, 1.0]}, "headings"),
    ],
)
def test_bad_input_names_mover_field_and_rule(kwargs, field):
    base = {"times": [0.0, 1.0, 2.0], "positions": [(0, 0), (1, 0), (2, 0)], "radius": 0.2}
    base.update(kwargs)
    with pytest.raises(InvalidInputError) as err:
        MovingObstacle.from_waypoints(name="cart 7", **base)
    msg = str(err.value)
    assert "'cart 7'" in msg and field in msg and "must" in msg


def test_bad_horizon_and_velocity():
    with pytest.raises(InvalidInputError, match="horizon"):
        MovingObstacle.constant_velocity((0, 0), (1, 0), radius=0.1, horizon=0.0)
    with pytest.raises(InvalidInputError, match="velocity"):
        MovingObstacle.constant_velocity((0, 0), (math.inf, 0), radius=0.1, horizon=1.0)
