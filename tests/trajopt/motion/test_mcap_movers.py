"""Tests of trajopt.motion: the movers in the MCAP export, ``/movers`` and ``/movers/predicted``.

The file is decoded by ``mcap-ros2-support`` (from the definitions stored in it); each
marker is checked against the mover's prediction computed here (``np.interp`` on its
waypoints, its polygon turned and rounded by its radius written out), and the export
without movers against itself with ``movers=None`` and ``movers=[]``, byte for byte.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import trajopt
from trajopt.errors import InvalidInputError
from trajopt.geometry import PolylineCurve
from trajopt.motion import read_mcap, write_mcap

mcap_reader = pytest.importorskip("mcap.reader", reason="needs the 'ros' extra (mcap)")
mcap_ros2_decoder = pytest.importorskip("mcap_ros2.decoder", reason="needs mcap-ros2-support")

BOX = [[-0.3, -0.15], [0.3, -0.15], [0.3, 0.15], [-0.3, 0.15]]
T0 = 1_700_000_000.5  # start_time (s since the epoch)


@pytest.fixture(scope="module")
def line():
    return trajopt.time_parameterize(
        PolylineCurve(np.array([[0.0, 0.0], [3.0, 1.0]])), trajopt.Robot(radius=0.2)
    )


@pytest.fixture(scope="module")
def movers(line):
    walker = trajopt.MovingObstacle.from_waypoints(
        [0.5, 3.0, 6.0], [(2.0, -2.0), (2.0, -0.9), (2.5, 1.5)], radius=0.2, name="walker"
    )
    cart = trajopt.MovingObstacle.from_waypoints(
        [0.0, line.duration + 1.5], [(3.0, 1.5), (1.0, 2.5)], radius=0.05, growth=0.02,
        headings=[0.2, 1.4], vertices=BOX, name="cart",
    )  # fmt: skip
    return [walker, cart]


def _messages(path):
    out = []
    with open(path, "rb") as f:
        reader = mcap_reader.make_reader(f, decoder_factories=[mcap_ros2_decoder.DecoderFactory()])
        for _, channel, message, ros in reader.iter_decoded_messages(log_time_order=False):
            out.append((channel.topic, message.log_time, ros))
    return out


def _dist_to_convex(p, w):
    best = np.full(len(p), np.inf)
    inside = np.ones(len(p), dtype=bool)
    for a, b in zip(w, np.roll(w, -1, axis=0), strict=True):
        e, q = b - a, p - a
        lam = np.clip(q @ e / (e @ e), 0.0, 1.0)
        best = np.minimum(best, np.hypot(*(q - lam[:, None] * e).T))
        inside &= e[0] * q[:, 1] - e[1] * q[:, 0] >= 0.0
    return np.where(inside, 0.0, best)


def test_without_movers_nothing_changes(line, tmp_path):
    a = write_mcap(line, tmp_path / "a.mcap", dt=0.05, start_time=T0)
    b = write_mcap(line, tmp_path / "b.mcap", dt=0.05, start_time=T0, movers=None)
    c = line.to_mcap(tmp_path / "c.mcap", dt=0.05, start_time=T0, movers=[])
    assert a.read_bytes() == b.read_bytes() == c.read_bytes()
    assert {topic for topic, _, _ in _messages(a)} == {"/plan", "/pose", "/twist"}


def test_mover_markers_follow_the_prediction(line, movers, tmp_path):
    dt = 0.1
    path = line.to_mcap(tmp_path / "m.mcap", dt=dt, start_time=T0, movers=movers)
    msgs = _messages(path)
    logs = [log for _, log, _ in msgs]
    assert logs == sorted(logs)  # written in time order, movers among the poses
    ns0 = int(T0) * 10**9 + 500_000_000
    predicted = [ros for topic, _, ros in msgs if topic == "/movers/predicted"]
    assert len(predicted) == 1
    for j, (m, mk) in enumerate(zip(movers, predicted[0].markers, strict=True)):
        assert (mk.ns, mk.id, mk.type, mk.text) == ("predicted", j, 4, m.name)
        assert np.allclose([[q.x, q.y] for q in mk.points], m.positions)
    frames = [(log, ros) for topic, log, ros in msgs if topic == "/movers"]
    end = max(line.duration, movers[1].times[-1])
    t = np.array([(log - ns0) / 1e9 for log, _ in frames])
    assert t[0] == 0.0 and t[-1] == pytest.approx(end, abs=1e-9)
    assert np.allclose(np.diff(t[:-1]), dt) and 0.0 < t[-1] - t[-2] <= dt + 1e-9
    for tk, (log, ros) in zip(t, frames, strict=True):
        assert len(ros.markers) == 2
        for j, (m, mk) in enumerate(zip(movers, ros.markers, strict=True)):
            st = mk.header.stamp
            assert st.sec * 10**9 + st.nanosec == log and mk.header.frame_id == "map"
            assert (mk.ns, mk.id, mk.type, mk.text) == ("movers", j, 4, m.name)
            c = np.array([np.interp(tk, m.times, m.positions[:, i]) for i in (0, 1)])
            h = float(np.interp(tk, m.times, m.headings))
            p, o = mk.pose.position, mk.pose.orientation
            assert (p.x, p.y) == pytest.approx(tuple(c), abs=1e-9)
            assert 2.0 * math.atan2(o.z, o.w) == pytest.approx(h, abs=1e-9)
            # the outline, to the world by the marker's pose, lies at radius(t) from the shape
            local = np.array([[q.x, q.y] for q in mk.points])
            assert np.allclose(local[0], local[-1])  # closed
            rot = np.array([[math.cos(h), -math.sin(h)], [math.sin(h), math.cos(h)]])
            world = c + local @ rot.T
            rad = m.radius + m.growth * min(max(tk, 0.0), m.times[-1])
            shape = c + (np.asarray(BOX) if m.vertices is not None else np.zeros((1, 2))) @ rot.T
            d = _dist_to_convex(world, shape) if len(shape) > 1 else np.hypot(*(world - c).T)
            assert np.allclose(d, rad, atol=1e-9)
    back = read_mcap(path)
    assert set(back.movers) == {"walker", "cart"} and set(back.predicted) == {"walker", "cart"}
    w = back.movers["walker"]
    assert np.allclose(w[:, 0], t)
    assert np.allclose(w[:, 1], np.interp(w[:, 0], movers[0].times, movers[0].positions[:, 0]))
    assert np.allclose(w[:, 2], np.interp(w[:, 0], movers[0].times, movers[0].positions[:, 1]))
    assert len(back.x) == len(line.sample_uniform(dt).t)  # the robot's topics as without movers


def test_movers_dt_spaces_the_mover_frames(line, movers, tmp_path):
    path = line.to_mcap(tmp_path / "m.mcap", dt=0.01, movers=movers, movers_dt=0.25)
    back = read_mcap(path)
    t = back.movers["cart"][:, 0]
    end = max(line.duration, movers[1].times[-1])
    assert np.allclose(np.diff(t[:-1]), 0.25) and t[-1] == pytest.approx(end)
    assert np.allclose(np.diff(back.t[:-1]), 0.01)  # the robot's poses keep dt
    for bad in (0.0, -1.0, float("nan"), "0.1"):
        with pytest.raises(InvalidInputError, match="movers_dt"):
            write_mcap(line, tmp_path / "x.mcap", movers=movers, movers_dt=bad)


def test_a_bad_mover_is_named(line, tmp_path):
    with pytest.raises(InvalidInputError, match=r"movers\[1\]"):
        write_mcap(line, tmp_path / "x.mcap", movers=[_walker_only(), (1.0, 2.0)])
    with pytest.raises(InvalidInputError, match="movers"):
        write_mcap(line, tmp_path / "x.mcap", movers=3)
    assert not (tmp_path / "x.mcap").exists()


def _walker_only():
    return trajopt.MovingObstacle.constant_velocity((0.0, 2.0), (0.1, 0.0), radius=0.2, horizon=1.0)
