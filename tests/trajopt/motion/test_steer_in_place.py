"""Tests of trajopt.motion: a car's steering at rest (:class:`trajopt.SteerInPlace`): its samples and its checks."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import trajopt
from trajopt.errors import InvalidInputError
from trajopt.motion import SteerInPlace, steer_in_place

CAR = trajopt.Robot(
    drive=trajopt.Ackermann(min_turning_radius=0.6, wheelbase=0.4, steer_rate_max=0.5)
)


def test_samples_tell_the_truth():
    piece = steer_in_place(CAR, np.array([1.0, 2.0]), 0.3, -0.5, 0.4, -1)
    assert piece.steering_at_rest and not piece.turning and piece.length == 0.0
    assert piece.duration == pytest.approx(0.9 / 0.5)
    t = np.linspace(0.0, piece.duration, 101)
    smp = piece.sample(t)
    np.testing.assert_array_equal(smp.v, 0.0)
    np.testing.assert_array_equal(smp.omega, 0.0)
    np.testing.assert_array_equal(smp.x, 1.0)
    np.testing.assert_array_equal(smp.theta, 0.3)
    np.testing.assert_array_equal(smp.direction, -1.0)
    # the steering angle runs linearly at the limit, from delta0 to delta1 exactly
    np.testing.assert_allclose(smp.steer, -0.5 + 0.5 * t, atol=1e-12)
    assert smp.steer[-1] == pytest.approx(0.4, abs=1e-15)
    np.testing.assert_allclose(smp.kappa, np.tan(smp.steer) / 0.4, rtol=1e-12)
    np.testing.assert_array_equal(smp.steer_rate[:-1], 0.5)
    assert smp.steer_rate[-1] == 0.0
    rate = np.diff(np.arctan(0.4 * smp.kappa)) / np.diff(t)
    np.testing.assert_allclose(rate, 0.5, rtol=1e-9)
    json.dumps(piece.to_dict(0.1))
    assert "SteerInPlace" in repr(piece)


def test_a_chain_joins_it_at_rest():
    a = steer_in_place(CAR, np.array([0.0, 0.0]), 0.0, 0.0, 0.3, 1)
    b = steer_in_place(CAR, np.array([0.0, 0.0]), 0.0, 0.3, -0.2, 1)
    chain = trajopt.TrajectoryChain((a, b), CAR)
    assert chain.duration == pytest.approx(1.6)
    smp = chain.sample(np.array([0.0, 0.6, 1.6]))
    np.testing.assert_allclose(smp.steer, [0.0, 0.3, -0.2], atol=1e-12)
    # a re-plan at the last piece continues the chain, not the piece (a motion at rest)
    assert chain.plan_at(1.0)[0] is chain


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        ({"delta0": math.nan}, "delta0 must be finite"),
        ({"delta1": 1.6}, r"delta1 must lie in \(-pi/2, pi/2\)"),
        ({"rate": 0.0}, r"rate must be finite and > 0 \(rad/s\)"),
        ({"wheelbase": -1.0}, r"wheelbase must be finite and > 0 \(m\)"),
        ({"direction": 0}, "direction must be 1 or -1"),
        ({"position": [0.0, math.inf]}, "position must be 2 finite numbers"),
    ],
)
def test_bad_input(kw, match):
    args = {
        "position": [0.0, 0.0],
        "theta": 0.0,
        "delta0": 0.0,
        "delta1": 0.2,
        "rate": 0.5,
        "wheelbase": 0.4,
        "direction": 1,
        "robot": CAR,
    }
    with pytest.raises(InvalidInputError, match=match):
        SteerInPlace(**(args | kw))


def test_needs_a_steering_rate_limit():
    car = trajopt.Robot(drive=trajopt.Ackermann(min_turning_radius=0.6, wheelbase=0.4))
    with pytest.raises(
        InvalidInputError, match="needs a car with a wheelbase and a steer_rate_max"
    ):
        steer_in_place(car, np.zeros(2), 0.0, 0.0, 0.1, 1)
