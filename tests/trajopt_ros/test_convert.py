"""Tests of trajopt_ros: message conversions against references built with the generated constructors (needs ROS)."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("rclpy", reason="the ROS 2 wheels are not installed (pip install -e '.[ros2]')")

import astar  # noqa: E402
import trajopt  # noqa: E402
from tests.trajopt_ros import helpers as h  # noqa: E402
from trajopt_ros.errors import RequestError  # noqa: E402


@pytest.fixture(scope="module")
def traj():
    grid = astar.OccupancyGrid(np.zeros((60, 80), bool), resolution=0.05)
    return trajopt.Planner(grid, trajopt.Robot()).plan((0.5, 0.5), (3.5, 2.5))


def test_path_msg_equals_constructed_reference_and_round_trips(traj):
    from geometry_msgs.msg import PoseStamped
    from nav_msgs.msg import Path
    from rclpy.serialization import deserialize_message, serialize_message

    from trajopt_ros.convert import path_msg

    t0, dt = 1_700_000_000.25, 0.1
    msg = path_msg(traj, t0, "map", dt)
    smp = traj.sample_uniform(dt)
    ref = []
    for t, x, y, th in zip(smp.t, smp.x, smp.y, smp.theta, strict=True):
        p = PoseStamped()
        ns = round((t0 + t) * 1e9)
        p.header.stamp.sec, p.header.stamp.nanosec = ns // 10**9, ns % 10**9
        p.header.frame_id = "map"
        p.pose.position.x, p.pose.position.y = float(x), float(y)
        p.pose.orientation.z, p.pose.orientation.w = math.sin(th / 2), math.cos(th / 2)
        ref.append(p)
    assert msg.poses == ref
    back = deserialize_message(serialize_message(msg), Path)
    assert back == msg


def test_trajectory_msg_fields(traj):
    from trajopt_ros.convert import trajectory_msg

    msg = trajectory_msg(traj, 0.0, "map", 0.2)
    smp = traj.sample_uniform(0.2)
    v = [p.velocities[0].linear.x for p in msg.points]
    a = [p.accelerations[0].linear.x for p in msg.points]
    np.testing.assert_allclose(v, smp.v, atol=1e-12)
    np.testing.assert_allclose(a, smp.a, atol=1e-12)
    assert msg.points[-1].time_from_start.sec + 1e-9 * msg.points[-1].time_from_start.nanosec == (
        pytest.approx(traj.duration, abs=1e-9)
    )


def test_grid_from_msg_modes_and_refusals():
    from trajopt_ros.convert import grid_from_msg

    values = h.wall_map()
    g = grid_from_msg(h.grid_msg(values), mode="auto", threshold=65, unknown_occupied=True)
    assert isinstance(g, astar.OccupancyGrid)
    np.testing.assert_array_equal(g.occupied, values >= 65)
    values[0, 0] = 40  # a graded cell: a costmap in auto mode
    c = grid_from_msg(h.grid_msg(values), mode="auto", threshold=65, unknown_occupied=True)
    assert isinstance(c, astar.Costmap) and c.cost[0, 0] > 0
    bad = h.grid_msg(values)
    bad.info.width = 7
    with pytest.raises(RequestError, match="width 7") as err:
        grid_from_msg(bad, mode="auto", threshold=65, unknown_occupied=True)
    assert err.value.reason == "invalid_map"
    bad = h.grid_msg(values)
    bad.info.resolution = 0.0
    with pytest.raises(RequestError, match="resolution"):
        grid_from_msg(bad, mode="auto", threshold=65, unknown_occupied=True)


def test_pose_refusals():
    from trajopt_ros.convert import pose_from_msg

    assert pose_from_msg(h.pose(1.0, 2.0, 0.5), "map", "goal") == pytest.approx((1.0, 2.0, 0.5))
    p = h.pose(1.0, 2.0)
    p.pose.orientation.w = 0.5
    with pytest.raises(RequestError, match="unit quaternion"):
        pose_from_msg(p, "map", "goal")
    with pytest.raises(RequestError, match="frame 'odom'") as err:
        pose_from_msg(h.pose(1.0, 2.0, frame="odom"), "map", "goal")
    assert err.value.reason == "frame_mismatch"
    # a fixed odom -> map transform
    x, y, yaw = pose_from_msg(
        h.pose(1.0, 0.0, 0.0, frame="odom"), "map", "odometry", ("odom", (2.0, 1.0, math.pi / 2))
    )
    assert (x, y, yaw) == pytest.approx((2.0, 2.0, math.pi / 2))


def test_collides_against_brute_force(traj):
    from trajopt_ros.check import collides

    robot = trajopt.Robot()
    free = astar.OccupancyGrid(np.zeros((60, 80), bool), resolution=0.05)
    assert not collides(traj, free, robot)
    smp = traj.sample(np.array([0.5 * traj.duration]))
    occ = np.zeros((60, 80), bool)
    occ[int(smp.y[0] / 0.05), int(smp.x[0] / 0.05)] = True  # one cell under the middle
    assert collides(traj, astar.OccupancyGrid(occ, resolution=0.05), robot)
    assert not collides(
        traj, astar.OccupancyGrid(occ, resolution=0.05), robot, 0.9 * traj.duration
    ) or (
        h.clearance(np.column_stack([smp.x, smp.y]), occ.astype(np.int8) * 100).min() < robot.radius
    )
