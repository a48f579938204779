"""Tests of trajopt.timing: speed-limit zones: Nav2's decoding rule, mask files, and trajectories that hold them.

References: the decoding rule written out by hand per value, a brute-force scan of mask
cells for the box queries, and 1 ms samples of the timed trajectories checked against the
zone of the cell under the robot centre.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from PIL import Image

import astar
import trajopt
from trajopt.errors import InvalidInputError, TimingError
from trajopt.timing._speed_limits import SpeedLimits, load_speed_mask
from trajopt.timing._stop_and_turn import stop_and_turn


def test_nav2_decoding_rule_by_hand():
    v = np.array([[0, -1, 70, 100, 30, 1]])
    pct = SpeedLimits.from_mask(v, 0.1, type="percentage", base=100.0, multiplier=-1.0)
    # 0 and -1: no limit; 70 -> 30 %; 100 -> 0 %, which nav2_msgs/SpeedLimit reads as "none"
    expect = [math.inf, math.inf, 30.0, math.inf, 70.0, 99.0]
    np.testing.assert_array_equal(pct.limit[0], expect)
    np.testing.assert_allclose(
        pct.speed_caps(2.0)[0], [math.inf, math.inf, 0.6, math.inf, 1.4, 1.98]
    )
    over = SpeedLimits.from_mask(v, 0.1, type=1, base=50.0, multiplier=1.0)
    # 50 + 70 = 120 % and 150 % are out of [0, 100]: ignored as Nav2 does
    np.testing.assert_array_equal(
        over.limit[0], [math.inf, math.inf, math.inf, math.inf, 80.0, 51.0]
    )
    ab = SpeedLimits.from_mask(v, 0.1, type="absolute", base=-0.2, multiplier=0.01)
    np.testing.assert_allclose(ab.limit[0], [math.inf, math.inf, 0.5, 0.8, 0.1, math.inf])
    assert ab.type == "absolute" and SpeedLimits.from_mask(v, 0.1, type=2).type == "absolute"
    np.testing.assert_allclose(ab.speed_caps(7.0)[0, 2], 0.5)  # absolute ignores v_max


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        (dict(type="percent"), "type must be 'percentage'"),
        (dict(type=3), "type must be 'percentage'"),
        (dict(type="absolute", base=float("nan")), "base must be finite"),
        (dict(type="absolute", multiplier="2"), "multiplier must be a number"),
    ],
)
def test_bad_mask_parameters(kwargs, match):
    with pytest.raises(InvalidInputError, match=match):
        SpeedLimits.from_mask(np.zeros((2, 2), int), 0.1, **kwargs)


def test_bad_mask_values():
    with pytest.raises(InvalidInputError, match=r"values\[1, 0\] = 101"):
        SpeedLimits.from_mask(np.array([[0, 1], [101, 0]]), 0.1, type="percentage")
    with pytest.raises(InvalidInputError, match="resolution"):
        SpeedLimits.from_mask(np.zeros((2, 2), int), -0.1, type="percentage")


def test_load_speed_mask_scale_mode_like_nav2_tutorial(tmp_path):
    # greys of g % (darker = higher value) in scale mode with thresholds 0 / 1 give value g
    g = np.array([[0, 40], [70, 0]])
    pix = np.rint(255.0 * (1.0 - g / 100.0)).astype(np.uint8)[::-1]
    Image.fromarray(pix, mode="L").save(tmp_path / "mask.pgm")
    (tmp_path / "mask.yaml").write_text(
        "image: mask.pgm\nmode: scale\nresolution: 0.5\norigin: [-1.0, -1.0, 0.0]\n"
        "negate: 0\noccupied_thresh: 1.0\nfree_thresh: 0.0\n"
    )
    sl = load_speed_mask(tmp_path / "mask.yaml", type="percentage", base=100.0, multiplier=-1.0)
    np.testing.assert_array_equal(sl.limit, [[math.inf, 60.0], [30.0, math.inf]])
    assert sl.origin == (-1.0, -1.0) and sl.resolution == 0.5
    np.testing.assert_allclose(
        sl.cap_at([[-0.75, -0.25], [0.1, -0.9], [5.0, 5.0]], 1.0), [0.3, math.inf, math.inf]
    )
    with pytest.raises(astar.MapFormatError, match="does not exist"):
        load_speed_mask(tmp_path / "nope.yaml", type="percentage")


def test_box_caps_against_brute_force():
    rng = np.random.default_rng(3)
    vals = rng.integers(0, 101, size=(7, 9))
    sl = SpeedLimits.from_mask(vals, 0.25, (0.3, -0.4), type="percentage")
    caps = sl.speed_caps(1.0)
    lo = rng.uniform([-0.2, -0.9], [2.6, 1.5], size=(300, 2))
    hi = lo + rng.uniform(0.0, [0.6, 0.6], size=(300, 2))
    got = sl.box_caps(lo, hi, 1.0)
    for k in range(len(lo)):
        best = math.inf
        for iy in range(7):
            for ix in range(9):
                x0, y0 = 0.3 + ix * 0.25, -0.4 + iy * 0.25
                if (
                    x0 <= hi[k, 0]
                    and x0 + 0.25 > lo[k, 0]
                    and y0 <= hi[k, 1]
                    and y0 + 0.25 > lo[k, 1]
                ):
                    best = min(best, caps[iy, ix])
        assert got[k] == best


def _zone_scene():
    sc = trajopt.scenes.paper()
    g = sc.grid
    vals = np.zeros(g.shape, int)
    vals[:, g.nx // 3 : 2 * g.nx // 3] = 30  # 30 % of v_max in a vertical band
    return sc, SpeedLimits.from_mask(vals, g.resolution, g.origin, type="percentage")


def _check_held(traj, sl: SpeedLimits, v_max: float) -> tuple[int, float]:
    t = np.arange(0.0, traj.duration, 1e-3)
    smp = traj.sample(t)
    cap = sl.cap_at(np.column_stack([smp.x, smp.y]), v_max)
    inside = np.isfinite(cap)
    assert np.all(smp.v[inside] <= cap[inside] * (1.0 + 1e-9))
    return int(inside.sum()), float(smp.v[~inside].max())


@pytest.mark.parametrize("goal", ["A", "C"])
def test_trajectory_holds_a_30_percent_zone(goal):
    sc, sl = _zone_scene()
    robot = trajopt.Robot()
    traj = trajopt.plan(sc.grid, sc.start, sc.goal(goal), robot, speed_limits=sl)
    n_in, v_out = _check_held(traj, sl, robot.v_max)
    assert n_in > 1000  # the path crosses the zone
    assert v_out > 0.3 * robot.v_max * 1.2  # and is faster outside it
    free = trajopt.plan(sc.grid, sc.start, sc.goal(goal), robot)
    assert traj.duration > free.duration


def test_mask_with_its_own_resolution_and_origin():
    sc = trajopt.scenes.paper()
    robot = trajopt.Robot()
    vals = np.full((5, 10), 80)  # a 1 x 0.5 m mask at 0.1 m cells, offset from the map
    sl = SpeedLimits.from_mask(
        vals, 0.1, (1.55, 0.22), type="percentage", base=100.0, multiplier=-1.0
    )
    traj = trajopt.plan(sc.grid, sc.start, sc.goal("A"), robot, speed_limits=sl)
    n_in, _ = _check_held(traj, sl, robot.v_max)
    assert n_in > 0


def test_stop_and_turn_holds_the_zone():
    vals = np.zeros((20, 40), int)
    vals[:, 10:20] = 40  # 40 % between x = 1 and 2 m
    sl = SpeedLimits.from_mask(vals, 0.1, type="percentage")
    robot = trajopt.Robot()
    pts = [(0.05, 0.3), (0.95, 0.3), (0.95, 0.8), (1.5, 0.8), (1.5, 1.5), (3.5, 1.5)]
    traj = stop_and_turn(pts, robot, speed_limits=sl)
    n_in, v_out = _check_held(traj, sl, robot.v_max)
    assert n_in > 0 and v_out > 0.5 * robot.v_max
    with pytest.raises(InvalidInputError, match="speed_limits must be"):
        stop_and_turn(pts, robot, speed_limits=vals)


def test_bad_speed_limit_uses():
    sc, sl = _zone_scene()
    far = SpeedLimits.from_mask(np.ones((3, 3), int), 0.1, (100.0, 100.0), type="percentage")
    with pytest.raises(InvalidInputError, match="does not overlap the map"):
        trajopt.Planner(sc.grid, speed_limits=far)
    with pytest.raises(InvalidInputError, match="speed_limits must be"):
        trajopt.Planner(sc.grid, speed_limits={"zone": 1})
    # a start speed above the zone's cap at the start is a TimingError naming the zone
    g = sc.grid
    vals = np.full(g.shape, 10)
    slow = SpeedLimits.from_mask(vals, g.resolution, g.origin, type="percentage")
    path = trajopt.plan(sc.grid, sc.start, sc.goal("A")).path
    with pytest.raises(TimingError, match="speed-limit zone"):
        trajopt.time_parameterize(path, trajopt.Robot(), v_start=0.2, speed_limits=slow)
    with pytest.raises(InvalidInputError, match="speed_limits must be"):
        trajopt.time_parameterize(path, trajopt.Robot(), speed_limits=vals)
