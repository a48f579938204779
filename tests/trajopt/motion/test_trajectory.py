"""Tests of trajopt.motion._trajectory: vectorised evaluation against independent references."""

from __future__ import annotations

import csv
import dataclasses
import json
import math
import re

import numpy as np
import pytest

from tests.cases import Arc, line
from tests.reference import integrate_jerk
from trajopt.errors import InvalidInputError
from trajopt.motion._samples import SAMPLE_UNITS
from trajopt.motion._trajectory import Trajectory
from trajopt.robot._robot import Robot
from trajopt.timing import time_parameterize

J = 2.0
PLAIN = Robot(track_width=None, wheel_v_max=None)


def _rest_to_rest():
    """Jerk +J, 0, -J, 0 (cruise), -J, 0, +J: phase durations and jerks."""
    d = np.array([0.25, 0.5, 0.25, 1.0, 0.25, 0.5, 0.25])
    j = np.array([J, 0, -J, 0, -J, 0, J], dtype=float)
    return d, j


def _hand_trajectory(robot=PLAIN):
    d, j = _rest_to_rest()
    t_ref, s_ref, v_ref, a_ref = integrate_jerk(d, j)
    edges = np.concatenate([[0.0], np.cumsum(d)])
    idx = np.round(edges[:-1] / (t_ref[1] - t_ref[0])).astype(int)
    length = float(s_ref[-1])
    traj = Trajectory(
        path=line(length, direction=0.0),
        robot=robot,
        phase_t=edges[:-1],
        phase_s=s_ref[idx],
        phase_v=v_ref[idx],
        phase_a=a_ref[idx],
        phase_j=j,
        duration=float(edges[-1]),
        v_start=0.0,
        v_end=0.0,
    )
    return traj, (t_ref, s_ref, v_ref, a_ref)


def test_evaluation_matches_numerical_integration():
    traj, (t_ref, s_ref, v_ref, a_ref) = _hand_trajectory()
    pick = np.linspace(0, len(t_ref) - 1, 997).astype(int)
    smp = traj.sample(t_ref[pick])
    assert np.allclose(smp.s, np.minimum(s_ref[pick], traj.length), atol=1e-8)
    assert np.allclose(smp.v, v_ref[pick], atol=1e-8)
    assert np.allclose(smp.a, a_ref[pick], atol=1e-8)
    assert np.allclose(smp.x, smp.s) and np.allclose(smp.y, 0.0)
    assert np.allclose(smp.theta, 0.0) and np.allclose(smp.omega, 0.0)


def test_evaluation_matches_ruckig_at_time():
    from ruckig import InputParameter, Ruckig
    from ruckig import Trajectory as RT

    length = 0.3  # short: the speed cap never binds, so the answer is ruckig's own
    traj = time_parameterize(line(length), PLAIN)
    inp = InputParameter(1)
    inp.current_position, inp.current_velocity, inp.current_acceleration = [0.0], [0.0], [0.0]
    inp.target_position, inp.target_velocity, inp.target_acceleration = [length], [0.0], [0.0]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [PLAIN.v_max], [PLAIN.a_max], [J]
    ref = RT(1)
    Ruckig(1).calculate(inp, ref)
    assert traj.duration == pytest.approx(ref.duration, rel=1e-9)
    ts = np.linspace(0.0, ref.duration, 101)
    smp = traj.sample(ts)
    for i, t in enumerate(ts):
        p, v, a = ref.at_time(t)
        assert smp.s[i] == pytest.approx(p[0], abs=1e-9)
        assert smp.v[i] == pytest.approx(v[0], abs=1e-9)
        assert smp.a[i] == pytest.approx(a[0], abs=1e-9)


def test_shapes_clipping_and_readonly():
    traj, _ = _hand_trajectory()
    t = np.linspace(-1.0, traj.duration + 1.0, 12).reshape(3, 4)
    smp = traj.sample(t)
    for name, arr in smp.as_dict().items():
        assert arr.shape == (3, 4), name
        assert not arr.flags.writeable
    assert smp.t.min() == 0.0 and smp.t.max() == traj.duration
    end = traj.sample(traj.duration + 5.0)
    assert end.s.shape == ()
    assert float(end.s) == traj.length and float(end.v) == 0.0 and float(end.a) == 0.0
    start = traj.sample(-3.0)
    assert float(start.s) == 0.0 and float(start.v) == 0.0
    assert smp.v_left is None and smp.v_right is None
    assert "v_left" not in smp.as_dict()
    with pytest.raises(dataclasses.FrozenInstanceError):
        traj.duration = 1.0  # type: ignore[misc]
    assert not traj.phase_t.flags.writeable


def test_wheel_speeds_and_heading_on_an_arc():
    robot = Robot()
    r = 0.5
    arc = Arc(r, 1.5 * 2 * np.pi)
    traj = time_parameterize(arc, robot)
    ts = np.linspace(0.0, traj.duration, 3001)
    smp = traj.sample(ts)
    half = 0.5 * robot.track_width
    assert np.allclose(smp.v_left, smp.v * (1 - half / r))
    assert np.allclose(smp.v_right, smp.v * (1 + half / r))
    assert np.allclose(smp.kappa, 1 / r)
    assert np.allclose(smp.omega, smp.v / r)
    assert np.allclose(smp.a_lat, smp.v**2 / r)
    # heading = polar angle + pi/2, unwrapped over 1.5 turns
    assert np.allclose(smp.theta, smp.s / r + np.pi / 2, atol=1e-7)
    # same answer when sampled in a random order (unwrapping does not depend on order)
    rng = np.random.default_rng(1)
    perm = rng.permutation(len(ts))
    shuffled = traj.sample(ts[perm])
    assert np.allclose(shuffled.theta, smp.theta[perm])


def test_sample_uniform():
    traj, _ = _hand_trajectory()
    smp = traj.sample_uniform(0.1)
    assert smp.t[0] == 0.0 and smp.t[-1] == traj.duration
    assert np.allclose(np.diff(smp.t)[:-1], 0.1)
    assert np.all(np.diff(smp.t) > 0)
    for bad in (0.0, -1.0, math.nan, "x"):
        with pytest.raises(InvalidInputError, match="dt"):
            traj.sample_uniform(bad)  # type: ignore[arg-type]


def test_exports(tmp_path):
    traj = time_parameterize(Arc(0.5, 2.0), Robot())
    d = traj.to_dict(dt=0.05)
    assert d["units"]["v"] == "m/s" and d["units"]["theta"] == "rad"
    assert d["duration"] == traj.duration and d["duration_unit"] == "s"
    # v_left/v_right present with track_width; an omni motion's course, vx, ... absent
    omni_only = {"course", "vx", "vy", "v_body_x", "v_body_y"}
    car_only = {"direction", "steer", "steer_rate"}  # drive="ackermann" only
    assert set(d["samples"]) == set(SAMPLE_UNITS) - omni_only - car_only
    smp = traj.sample_uniform(0.05)
    assert np.allclose(d["samples"]["x"], smp.x)
    p = traj.to_json(tmp_path / "sub" / "traj.json", dt=0.05)
    loaded = json.loads(p.read_text())
    assert loaded["robot"]["v_max"] == Robot().v_max
    assert np.allclose(loaded["phases"]["t"], traj.phase_t)
    q = traj.to_csv(tmp_path / "traj.csv", dt=0.05)
    with open(q, newline="") as f:
        rows = list(csv.reader(f))
    assert loaded["frame_id"] == "map"
    assert rows[0][0] == "t [s]" and "v [m/s]" in rows[0] and "theta [rad] (map)" in rows[0]
    table = np.array(rows[1:], dtype=float)
    assert table.shape == (len(smp.t), len(rows[0]))
    assert np.allclose(table[:, rows[0].index("theta [rad] (map)")], smp.theta)
    assert sorted(x.name for x in tmp_path.iterdir()) == ["sub", "traj.csv"]  # no temp files
    assert [x.name for x in (tmp_path / "sub").iterdir()] == ["traj.json"]


def _csv_references(traj, dt, frame):
    """Column name (header text) -> reference samples from ``traj.sample_uniform(dt)``."""
    smp = traj.sample_uniform(dt).as_dict()
    pose = {"x", "y", "theta"}
    return {
        f"{k} [{SAMPLE_UNITS[k]}]" + (f" ({frame})" if k in pose else ""): np.asarray(v)
        for k, v in smp.items()
    }


@pytest.fixture(scope="module")
def exported(driven):
    """A planned trajectory (SP -> A), a chain (a turn in place, then it) and a stop-and-turn."""
    from trajopt.motion._chain import TrajectoryChain
    from trajopt.timing._stop_and_turn import stop_and_turn, turn_in_place

    planner, traj = driven
    x0, y0, th0 = (float(v) for v in traj.sample(0.0)[1:4])
    turn = turn_in_place((x0, y0), th0 - 1.0, th0, traj.robot)
    chain = TrajectoryChain((turn, traj), traj.robot)
    square = np.array([[0.5, 0.5], [1.5, 0.5], [1.5, 1.5]])
    return {"planned": traj, "chain": chain, "stop_and_turn": stop_and_turn(square, traj.robot)}


@pytest.mark.parametrize("kind", ["planned", "chain", "stop_and_turn"])
@pytest.mark.parametrize("frame", ["map", "robot1/odom"])
def test_csv_reads_with_pandas_and_numpy_without_options(exported, kind, frame, tmp_path):
    pd = pytest.importorskip("pandas")
    traj, dt = exported[kind], 0.05
    path = traj.to_csv(tmp_path / "traj.csv", dt=dt, frame_id=frame)
    ref = _csv_references(traj, dt, frame)
    n = len(ref["t [s]"])
    assert n > 10 and ref["t [s]"][-1] == traj.duration

    df = pd.read_csv(path)
    assert list(df.columns) == list(ref)
    assert len(df) == n and all(df.dtypes == np.float64)
    for name, want in ref.items():
        np.testing.assert_array_equal(df[name].to_numpy(), want, err_msg=name)  # repr round-trips

    arr = np.genfromtxt(path, delimiter=",", names=True)
    assert arr.shape == (n,) and len(arr.dtype.names) == len(ref)
    for field_name, want in zip(arr.dtype.names, ref.values(), strict=True):
        np.testing.assert_array_equal(arr[field_name], want, err_msg=field_name)
    mangled = "".join(c for c in frame if c.isalnum() or c == "_")
    assert arr.dtype.names[:4] == (
        "t_s",
        f"x_m_{mangled}",
        f"y_m_{mangled}",
        f"theta_rad_{mangled}",
    )
    assert "v_ms" in arr.dtype.names and "a_ms2" in arr.dtype.names

    # the frame is recoverable from the header alone
    frames = {re.fullmatch(r"(\w+) \[[^]]+\] \((.+)\)", c).groups() for c in df.columns[1:4]}
    assert frames == {("x", frame), ("y", frame), ("theta", frame)}
    assert not any("(" in c for c in df.columns if c.split()[0] not in {"x", "y", "theta"})


@pytest.mark.parametrize("frame", ["a,b", 'a"b', "map#1", "map(2)", "ta\tb", "a\rb", "", 7])
def test_csv_refuses_a_frame_its_header_cannot_carry(exported, frame, tmp_path):
    with pytest.raises(InvalidInputError, match="frame_id"):
        exported["planned"].to_csv(tmp_path / "t.csv", dt=0.1, frame_id=frame)
    assert list(tmp_path.iterdir()) == []


def test_invalid_construction():
    traj, _ = _hand_trajectory()
    with pytest.raises(InvalidInputError, match="phase_s"):
        dataclasses.replace(traj, phase_s=np.zeros(3))
    with pytest.raises(InvalidInputError, match="duration"):
        dataclasses.replace(traj, duration=0.1)
    with pytest.raises(InvalidInputError, match="duration"):
        dataclasses.replace(traj, duration=math.nan)


@pytest.mark.parametrize("direction", [1, -1])
def test_the_pose_is_the_sample_s_pose(direction):
    # Trajectory.pose (the certificate's light evaluation) against sample at 2001 times: the
    # same x, y, s and body speed, and a heading equal to sample's modulo 2 pi
    path = Arc(2.0, 4.0)  # past the heading angle pi: the tangent angle wraps
    tr = time_parameterize(path, PLAIN)
    if direction < 0:
        car = Robot(drive="ackermann", wheelbase=0.5, min_turning_radius=1.0)
        tr = dataclasses.replace(tr, robot=car, direction=-1)
    t = np.linspace(-0.5, tr.duration + 0.5, 2001)
    x, y, theta, s, v = tr.pose(t)
    smp = tr.sample(t)
    for got, want in ((x, smp.x), (y, smp.y), (s, smp.s), (v, smp.v)):
        assert np.array_equal(got, np.asarray(want))
    turns = (np.asarray(smp.theta) - theta) / (2.0 * math.pi)
    assert np.max(np.abs(turns - np.round(turns))) < 1e-12
    if direction < 0:
        assert np.all(v <= 0.0) and np.any(v < 0.0)


def test_pose_on_a_bspline_lies_at_the_quadrature_arc_length():
    # an S-bend B-spline (its arc-length inversion is compiled): at 15 times, the pose is the
    # curve's point at the motion's arc length found independently (scipy brentq on scipy
    # quad of |C'|), within 1e-9 m; the NaN time gives NaN
    from scipy.integrate import quad
    from scipy.optimize import brentq

    from trajopt.geometry import BSplineCurve, clamped_uniform_knots

    pts = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 1.0], [3.0, 1.0], [4.0, 0.0], [5.0, 0.0]])
    curve = BSplineCurve(clamped_uniform_knots(len(pts), 3, (0.0, 6.0)), pts, 3)
    tr = time_parameterize(curve, PLAIN)
    assert tr.u_grid.shape[0] >= 2  # the table's guess, then the compiled steps
    t = np.linspace(0.0, tr.duration, 15)
    x, y, _, s, _ = tr.pose(t)
    knots = np.unique(curve.t)

    def arc(u):
        edges = [*knots[knots < u], u]
        return sum(
            quad(lambda w: float(np.hypot(*curve(np.array([w]), 1)[0])), a, b, epsabs=1e-13)[0]
            for a, b in zip(edges[:-1], edges[1:], strict=True)
        )

    for xi, yi, si in zip(x, y, s, strict=True):
        u = brentq(lambda w, si=si: arc(w) - si, 0.0, 6.0, xtol=1e-14) if si > 0 else 0.0
        assert np.hypot(*(curve(np.array([u]))[0] - (xi, yi))) < 1e-9
    nan = tr.pose(np.array([np.nan]))
    assert np.isnan(nan[0][0]) and np.isnan(nan[1][0]) and np.isnan(nan[3][0])
