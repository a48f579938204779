"""Tests of trajopt.motion: ROS 2 MCAP export (trajopt.motion._mcap), checked with two independent readers.

``mcap-ros2-support``'s decoder and ``rosbags``' deserialiser both decode the file from the
message definitions stored in it; neither shares code with :mod:`trajopt.motion._mcap`.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import trajopt
from trajopt.errors import InvalidInputError
from trajopt.motion._mcap import TOPICS, McapExportError, read_mcap, write_mcap
from trajopt.timing._stop_and_turn import stop_and_turn

mcap_reader = pytest.importorskip("mcap.reader", reason="needs the 'ros' extra (mcap)")
mcap_ros2_decoder = pytest.importorskip("mcap_ros2.decoder", reason="needs mcap-ros2-support")


@pytest.fixture(scope="module")
def planned():
    sc = trajopt.scenes.paper()
    return trajopt.plan(sc.grid, sc.start, sc.goal("B"))


def _decode_with_mcap_ros2(path: Path) -> dict[str, list]:
    out: dict[str, list] = {}
    with open(path, "rb") as f:
        reader = mcap_reader.make_reader(f, decoder_factories=[mcap_ros2_decoder.DecoderFactory()])
        for schema, channel, message, ros in reader.iter_decoded_messages():
            assert schema.encoding == "ros2msg" and channel.message_encoding == "cdr"
            assert schema.name == TOPICS[channel.topic]
            out.setdefault(channel.topic, []).append((message.log_time, ros))
    return out


def test_round_trip_with_mcap_ros2_decoder(planned, tmp_path):
    path = planned.to_mcap(tmp_path / "traj.mcap", dt=0.01, start_time=1700000000.25)
    msgs = _decode_with_mcap_ros2(path)
    assert set(msgs) == set(TOPICS)
    ref = planned.to_poses(0.01)
    poses = msgs["/pose"]
    assert len(poses) == len(ref)
    ns = np.array([r.header.stamp.sec * 10**9 + r.header.stamp.nanosec for _, r in poses])
    np.testing.assert_allclose((ns - 1700000000_250000000) / 1e9, ref["t"], atol=1e-9, rtol=0)
    assert all(log == r.header.stamp.sec * 10**9 + r.header.stamp.nanosec for log, r in poses)
    got = np.array(
        [
            [r.pose.position.x, r.pose.position.y, r.pose.orientation.z, r.pose.orientation.w]
            for _, r in poses
        ]
    )
    for k, name in enumerate(("x", "y", "qz", "qw")):
        np.testing.assert_allclose(got[:, k], ref[name], atol=1e-9, rtol=0)
    assert {r.header.frame_id for _, r in poses} == {"map"}
    smp = planned.sample_uniform(0.01)
    tw = np.array([[r.twist.linear.x, r.twist.angular.z] for _, r in msgs["/twist"]])
    np.testing.assert_allclose(tw[:, 0], smp.v, atol=1e-12)
    np.testing.assert_allclose(tw[:, 1], smp.omega, atol=1e-12)
    assert {r.header.frame_id for _, r in msgs["/twist"]} == {"base_link"}
    # the raw map, cell for cell, in nav_msgs/OccupancyGrid order (row 0 at the origin)
    ((_, grid_msg),) = msgs["/map"]
    g = planned.steps.raw_grid
    assert (grid_msg.info.width, grid_msg.info.height) == (g.nx, g.ny)
    assert math.isclose(grid_msg.info.resolution, g.resolution, rel_tol=1e-7)
    data = np.frombuffer(bytes(grid_msg.data), np.int8).reshape(g.ny, g.nx)
    np.testing.assert_array_equal(data == 100, g.occupied)
    ((_, path_msg),) = msgs["/plan"]
    assert len(path_msg.poses) == len(ref)
    ((_, markers),) = msgs["/corridor"]
    regions = planned.steps.corridor.regions
    assert len(markers.markers) == len(regions)
    for m, region in zip(markers.markers, regions, strict=True):
        assert m.type == 4 and m.action == 0
        pts = np.array([[q.x, q.y] for q in m.points])
        np.testing.assert_allclose(pts[:-1], region.vertices)
        np.testing.assert_allclose(pts[-1], pts[0])


def test_rosbags_reads_the_file(planned, tmp_path):
    highlevel = pytest.importorskip("rosbags.highlevel", reason="rosbags not installed")
    path = planned.to_mcap(tmp_path / "traj.mcap", dt=0.05)
    ref = planned.to_poses(0.05)
    with highlevel.AnyReader([path]) as reader:
        types = {c.topic: c.msgtype for c in reader.connections}
        assert types == TOPICS
        xs, stamps, n_markers = [], [], 0
        for conn, _t, raw in reader.messages():
            msg = reader.deserialize(raw, conn.msgtype)
            if conn.topic == "/pose":
                xs.append(msg.pose.position.x)
                stamps.append(msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec)
            elif conn.topic == "/corridor":
                n_markers = len(msg.markers)
    np.testing.assert_allclose(xs, ref["x"], atol=1e-12)
    np.testing.assert_allclose(stamps, ref["t"], atol=1e-9)
    assert n_markers == len(planned.steps.corridor.regions)


def test_read_mcap_reads_back(planned, tmp_path):
    path = write_mcap(
        planned, tmp_path / "t.mcap", dt=0.02, frame_id="world", child_frame_id="base_footprint"
    )
    back = read_mcap(path)
    smp = planned.sample_uniform(0.02)
    np.testing.assert_allclose(back.t, smp.t, atol=1e-9)
    np.testing.assert_allclose(back.x, smp.x, atol=1e-12)
    np.testing.assert_allclose(back.theta - smp.theta, 0.0, atol=1e-9)
    np.testing.assert_allclose(back.v, smp.v, atol=1e-12)
    assert back.frame_id == "world" and back.child_frame_id == "base_footprint"
    assert back.maps["/map"] == planned.steps.raw_grid
    assert back.maps["/map_inflated"] == planned.steps.inflated_grid
    assert back.path.shape == (len(smp.t), 3)


def test_to_poses_is_a_unit_quaternion_of_the_heading(planned):
    rec = planned.to_poses(0.1)
    assert rec.dtype.names == ("t", "x", "y", "qz", "qw")
    np.testing.assert_allclose(rec["qz"] ** 2 + rec["qw"] ** 2, 1.0)
    smp = planned.sample_uniform(0.1)
    yaw = 2.0 * np.arctan2(rec["qz"], rec["qw"])
    np.testing.assert_allclose(
        np.remainder(yaw - smp.theta + np.pi, 2 * np.pi) - np.pi, 0.0, atol=1e-12
    )
    assert rec["t"][-1] == planned.duration


def test_trajectory_without_steps_and_the_fallback(tmp_path):
    traj = stop_and_turn([(0.0, 0.0), (1.0, 0.0), (1.0, 1.0)])
    back = read_mcap(traj.to_mcap(tmp_path / "f.mcap", dt=0.05))
    assert back.maps == {} and back.corridor == []
    np.testing.assert_allclose(back.x[-1], 1.0) and np.testing.assert_allclose(back.y[-1], 1.0)
    msgs = _decode_with_mcap_ros2(tmp_path / "f.mcap")
    assert set(msgs) == {"/plan", "/pose", "/twist"}


def test_atomic_and_typed_failures(planned, tmp_path, monkeypatch):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(McapExportError, match="cannot write the MCAP file"):
        planned.to_mcap(blocker / "t.mcap")
    good = planned.to_mcap(tmp_path / "t.mcap", dt=0.1)
    before = good.read_bytes()
    import trajopt.motion._mcap as rm

    def boom(*args, **kwargs):
        raise OSError("disk full")

    monkeypatch.setattr(rm, "encode_path", boom)
    with pytest.raises(McapExportError, match="disk full"):
        planned.to_mcap(good, dt=0.1)
    assert good.read_bytes() == before  # the old file is intact
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file", "t.mcap"]  # no temp file
    with pytest.raises(InvalidInputError, match="frame_id"):
        planned.to_mcap(tmp_path / "x.mcap", frame_id="")
    with pytest.raises(InvalidInputError, match="start_time"):
        planned.to_mcap(tmp_path / "x.mcap", start_time=-1.0)
    with pytest.raises(McapExportError, match="not a readable MCAP"):
        read_mcap(blocker)


def test_box_corridor_markers(tmp_path):
    sc = trajopt.scenes.paper()
    traj = trajopt.plan(sc.grid, sc.start, sc.goal("A"), corridor="boxes")
    back = read_mcap(traj.to_mcap(tmp_path / "b.mcap", dt=0.1))
    boxes = traj.steps.corridor.boxes
    assert len(back.corridor) == len(boxes)
    for outline, box in zip(back.corridor, boxes, strict=True):
        np.testing.assert_allclose(outline[:-1], box.vertices())
