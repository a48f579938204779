"""Tests of trajopt.robot._robot: validation and the curvature-dependent speed cap (by hand)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from trajopt.errors import InvalidInputError
from trajopt.robot._robot import Robot


def test_default_is_the_chapter_robot():
    r = Robot()
    assert r.radius == pytest.approx(0.165)
    assert r.width == pytest.approx(0.33)
    for name in ("v_max", "a_max", "j_max", "a_lat_max", "omega_max"):
        assert getattr(r, name) > 0
    assert (r.track_width is None) == (r.wheel_v_max is None)


def test_frozen():
    r = Robot()
    with pytest.raises(dataclasses.FrozenInstanceError):
        r.v_max = 2.0  # type: ignore[misc]


@pytest.mark.parametrize("field", ["radius", "v_max", "a_max", "j_max", "a_lat_max", "omega_max"])
@pytest.mark.parametrize("bad", [0.0, -1.0, math.nan, math.inf, "fast", None])
def test_invalid_limits_name_the_field(field, bad):
    with pytest.raises(InvalidInputError, match=field):
        Robot(**{field: bad})


@pytest.mark.parametrize("bad", [0.0, -0.2, math.nan, math.inf])
def test_invalid_track_fields(bad):
    with pytest.raises(InvalidInputError, match="track_width"):
        Robot(track_width=bad, wheel_v_max=1.0)
    with pytest.raises(InvalidInputError, match="wheel_v_max"):
        Robot(track_width=0.3, wheel_v_max=bad)


def test_track_width_and_wheel_speed_go_together():
    with pytest.raises(InvalidInputError, match="together"):
        Robot(track_width=0.3, wheel_v_max=None)
    with pytest.raises(InvalidInputError, match="together"):
        Robot(track_width=None, wheel_v_max=0.5)
    r = Robot(track_width=None, wheel_v_max=None)
    assert r.track_width is None


def test_speed_cap_by_hand():
    r = Robot(v_max=1.0, a_lat_max=0.8, omega_max=2.0, track_width=0.4, wheel_v_max=1.2)
    # kappa = 0: only v_max (wheel term 1.2 > 1.0)
    assert r.speed_cap(0.0) == pytest.approx(1.0)
    # kappa = 2: sqrt(0.8/2)=0.632, 2/2=1, 1.2/(1+0.4)=0.857 -> lateral binds
    assert r.speed_cap(2.0) == pytest.approx(math.sqrt(0.4))
    assert r.speed_cap(-2.0) == pytest.approx(math.sqrt(0.4))
    # kappa = 10: sqrt(0.08)=0.283, 0.2, 1.2/3=0.4 -> yaw rate binds
    assert r.speed_cap(10.0) == pytest.approx(0.2)
    # wheel binding: a robot with a wide track
    w = Robot(v_max=1.0, a_lat_max=10.0, omega_max=10.0, track_width=1.0, wheel_v_max=1.0)
    assert w.speed_cap(1.0) == pytest.approx(1.0 / 1.5)


def test_speed_cap_vectorised_and_degenerate():
    r = Robot(track_width=None, wheel_v_max=None)
    k = np.array([[0.0, 1.0], [np.inf, np.nan]])
    cap = r.speed_cap(k)
    assert cap.shape == (2, 2)
    assert cap[0, 0] == pytest.approx(r.v_max)
    assert cap[1, 0] == 0.0 and cap[1, 1] == 0.0
    assert isinstance(r.speed_cap(0.5), float)


@settings(max_examples=60, deadline=None)
@given(
    k=st.floats(-100, 100, allow_nan=False),
    v_max=st.floats(0.1, 3),
    a_lat=st.floats(0.1, 3),
    omega=st.floats(0.1, 5),
    tw=st.floats(0.1, 1.0),
    wv=st.floats(0.1, 3),
)
def test_speed_cap_is_the_tightest_bound(k, v_max, a_lat, omega, tw, wv):
    r = Robot(v_max=v_max, a_lat_max=a_lat, omega_max=omega, track_width=tw, wheel_v_max=wv)
    c = r.speed_cap(k)
    ak = abs(k)
    rel = 1 + 1e-12
    assert c <= v_max * rel
    assert ak * c * c <= a_lat * rel + 1e-15
    assert ak * c <= omega * rel + 1e-15
    assert c * (1 + ak * tw / 2) <= wv * rel
    # and it is tight: one of them is active
    slack = [
        v_max - c,
        a_lat - ak * c * c,
        omega - ak * c,
        wv - c * (1 + ak * tw / 2),
    ]
    assert min(abs(x) for x in slack) <= 1e-9 * max(1.0, v_max, a_lat, omega, wv)
