"""Tests of trajopt.motion._omni: an omnidirectional motion built by hand, against references.

The translation and the orientation are both built from jerk signals whose states come from
numerical integration (``tests.reference.integrate_jerk``), not from the library's phase
polynomials; the turned angle and the velocities are checked against hand formulas.
"""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest

from tests.cases import line
from tests.reference import integrate_jerk
from trajopt.errors import InvalidInputError
from trajopt.motion import OmniTrajectory, Trajectory
from trajopt.robot._robot import Robot
from trajopt.timing import time_parameterize

OMNI = Robot(drive="omni")  # keeps the default track width: no wheel speeds all the same
DIRECTION = 0.4  # the line's direction (rad)
THETA0 = 2.5  # the orientation at the start (rad)
Z = 1.0  # the orientation's jerk (rad/s^3)
DT = 2.0**-13  # the references' step (s): divides every phase duration


def _translation() -> tuple[Trajectory, tuple[np.ndarray, ...]]:
    """A rest-to-rest drive of 3 s along a line of direction DIRECTION."""
    d = np.array([0.25, 0.5, 0.25, 1.0, 0.25, 0.5, 0.25])
    j = np.array([2.0, 0, -2.0, 0, -2.0, 0, 2.0])
    t, s, v, a = integrate_jerk(d, j, DT)
    edges = np.concatenate([[0.0], np.cumsum(d)])
    idx = np.round(edges[:-1] / DT).astype(int)
    traj = Trajectory(
        path=line(float(s[-1]), direction=DIRECTION),
        robot=OMNI,
        phase_t=edges[:-1],
        phase_s=s[idx],
        phase_v=v[idx],
        phase_a=a[idx],
        phase_j=j,
        duration=float(edges[-1]),
        v_start=0.0,
        v_end=0.0,
    )
    return traj, (t, s, v, a)


def _omni(tau: float, sign: float = 1.0):
    """The translation with a turn of jerks ``sign * (Z, -Z, -Z, Z)``, each lasting ``tau``.

    By hand the turn is ``2 Z tau^3`` (each half reaches ``Z tau^3``) and lasts ``4 tau``.
    Returns the motion and the orientation reference ``(t, theta, omega)`` on its own clock.
    """
    translation, _ = _translation()
    d = np.full(4, tau)
    j = sign * np.array([Z, -Z, -Z, Z])
    t, q, w, al = integrate_jerk(d, j, DT)
    edges = np.concatenate([[0.0], np.cumsum(d)])
    idx = np.round(edges[:-1] / DT).astype(int)
    rows = np.column_stack([edges[:-1], THETA0 + q[idx], w[idx], al[idx], j])
    turn = sign * 2.0 * Z * tau**3
    traj = OmniTrajectory(
        translation=translation,
        robot=OMNI,
        rows=rows,
        turn_duration=4.0 * tau,
        theta_start=THETA0,
        theta_end=THETA0 + turn,
    )
    return traj, (t, THETA0 + q, w)


def test_orientation_matches_numerical_integration():
    traj, (t_ref, th_ref, w_ref) = _omni(0.5)
    pick = np.linspace(0, len(t_ref) - 1, 777).astype(int)
    smp = traj.sample(t_ref[pick])
    np.testing.assert_allclose(smp.theta, th_ref[pick], atol=1e-9)
    np.testing.assert_allclose(smp.omega, w_ref[pick], atol=1e-9)
    assert smp.theta[0] == THETA0
    end = traj.sample(traj.duration)
    assert float(end.theta) == pytest.approx(THETA0 + 2.0 * Z * 0.5**3, abs=1e-12)
    assert float(end.omega) == 0.0
    # the turn (2 s) fits in the drive (3 s): the motion lasts the drive
    assert traj.duration == traj.translation.duration == 3.0
    th, w, al, z = traj.orientation([0.0, 2.0, 2.5])
    assert w[0] == al[0] == 0.0 and th[1] == th[2] == traj.theta_end
    assert w[2] == al[2] == z[2] == 0.0


def test_translation_samples_are_the_translations():
    traj, _ = _omni(0.5)
    t = np.linspace(0.0, traj.duration, 1001)
    smp, ref = traj.sample(t), traj.translation.sample(t)
    for name in ("x", "y", "v", "a", "jerk", "kappa", "a_lat", "s"):
        np.testing.assert_array_equal(getattr(smp, name), getattr(ref, name), err_msg=name)
    np.testing.assert_array_equal(smp.course, ref.theta)
    np.testing.assert_allclose(smp.course, DIRECTION, atol=1e-12)  # a straight line
    assert traj.length == traj.translation.length and traj.path is traj.translation.path


def test_a_turn_longer_than_the_drive_stands_at_the_end():
    traj, (t_ref, th_ref, _) = _omni(1.0, sign=-1.0)  # 4 s turn of -2 rad, 3 s drive
    assert traj.duration == 4.0 and traj.turn_rad == -2.0
    t = np.linspace(3.0, 4.0, 257)
    smp = traj.sample(t)
    end = traj.translation.sample(3.0)
    assert np.all(smp.x == end.x) and np.all(smp.y == end.y)
    assert np.all(smp.s == traj.length)
    for name in ("v", "a", "jerk", "vx", "vy", "v_body_x", "v_body_y"):
        assert np.all(getattr(smp, name) == 0.0), name
    idx = np.round(t / DT).astype(int)
    np.testing.assert_allclose(smp.theta, th_ref[idx], atol=1e-9)  # still turning
    assert smp.theta[-1] == THETA0 - 2.0 and smp.omega[-1] == 0.0
    assert traj.v_end == 0.0 and traj.motion(3.5)[1] == 0.0


def test_body_velocity_is_the_world_velocity_rotated():
    traj, _ = _omni(0.5)
    h = 1e-3  # central differences are within h^2 |jerk| / 6 (and the rows' 1e-9 / h)
    t = np.linspace(0.1, 2.9, 401)
    smp = traj.sample(t)
    # by hand: on a line of direction phi, v_world = v (cos phi, sin phi) and the body frame
    # turned by theta sees v (cos(phi - theta), sin(phi - theta))
    np.testing.assert_allclose(smp.vx, smp.v * math.cos(DIRECTION), atol=1e-12)
    np.testing.assert_allclose(smp.vy, smp.v * math.sin(DIRECTION), atol=1e-12)
    np.testing.assert_allclose(smp.v_body_x, smp.v * np.cos(DIRECTION - smp.theta), atol=1e-12)
    np.testing.assert_allclose(smp.v_body_y, smp.v * np.sin(DIRECTION - smp.theta), atol=1e-12)
    # and the world velocity is the rate of the position (central differences)
    ahead, back = traj.sample(t + h), traj.sample(t - h)
    np.testing.assert_allclose(smp.vx, (ahead.x - back.x) / (2 * h), atol=1e-6)
    np.testing.assert_allclose(smp.vy, (ahead.y - back.y) / (2 * h), atol=1e-6)
    np.testing.assert_allclose(smp.omega, (ahead.theta - back.theta) / (2 * h), atol=1e-6)
    # speed is kept: |v_body| = |v_world| = v
    np.testing.assert_allclose(np.hypot(smp.v_body_x, smp.v_body_y), smp.v, atol=1e-12)


def test_samples_are_readonly_and_have_no_wheel_speeds():
    traj, _ = _omni(0.5)
    smp = traj.sample(np.linspace(0.0, 1.0, 6).reshape(2, 3))
    assert not hasattr(smp, "v_left") and not hasattr(smp, "v_right")  # OMNI has a track width
    names = list(smp.as_dict())
    assert names == [
        "t",
        "x",
        "y",
        "theta",
        "v",
        "omega",
        "a",
        "jerk",
        "a_lat",
        "kappa",
        "s",
        "course",
        "vx",
        "vy",
        "v_body_x",
        "v_body_y",
    ]
    for name, arr in smp.as_dict().items():
        assert arr.shape == (2, 3), name
        assert not arr.flags.writeable, name
    assert traj.sample(-1.0).t == 0.0 and traj.sample(99.0).t == traj.duration


def test_state_at_is_the_motion_along_the_path():
    traj, (t_ref, th_ref, _) = _omni(1.0)
    st = traj.state_at(1.25)
    ref = traj.translation.sample(1.25)
    assert st.theta == pytest.approx(DIRECTION, abs=1e-12)  # the course, not the orientation
    assert (st.x, st.y, st.v, st.a) == (
        float(ref.x),
        float(ref.y),
        float(ref.v),
        float(ref.a),
    )
    late = traj.state_at(3.5)  # standing at the end while it turns
    assert late.v == 0.0 and late.a == 0.0
    assert float(traj.orientation(1.25)[0]) == pytest.approx(th_ref[round(1.25 / DT)], abs=1e-9)
    with pytest.raises(InvalidInputError, match="t"):
        traj.state_at(4.5)


def _reference_columns(frame: str) -> list[str]:
    return [
        "t [s]",
        f"x [m] ({frame})",
        f"y [m] ({frame})",
        f"theta [rad] ({frame})",
        "v [m/s]",
        "omega [rad/s]",
        "a [m/s^2]",
        "jerk [m/s^3]",
        "a_lat [m/s^2]",
        "kappa [1/m]",
        "s [m]",
        f"course [rad] ({frame})",
        f"vx [m/s] ({frame})",
        f"vy [m/s] ({frame})",
        "v_body_x [m/s]",
        "v_body_y [m/s]",
    ]


@pytest.mark.parametrize("frame", ["map", "robot1/odom"])
def test_csv_round_trip(frame, tmp_path):
    pd = pytest.importorskip("pandas")
    traj, (t_ref, th_ref, w_ref) = _omni(1.0)
    dt = 2.0**-6  # a multiple of the references' step
    path = traj.to_csv(tmp_path / "omni.csv", dt=dt, frame_id=frame)
    df = pd.read_csv(path)
    assert list(df.columns) == _reference_columns(frame)
    assert all(df.dtypes == np.float64)
    t = df["t [s]"].to_numpy()
    np.testing.assert_array_equal(t, np.arange(len(t)) * dt)
    assert t[-1] == traj.duration == 4.0
    idx = np.round(t / DT).astype(int)
    np.testing.assert_allclose(df[f"theta [rad] ({frame})"], th_ref[idx], atol=1e-9)
    np.testing.assert_allclose(df["omega [rad/s]"], w_ref[idx], atol=1e-9)
    v = df["v [m/s]"].to_numpy()
    th = df[f"theta [rad] ({frame})"].to_numpy()
    np.testing.assert_allclose(df["v_body_x [m/s]"], v * np.cos(DIRECTION - th), atol=1e-12)
    np.testing.assert_allclose(df["v_body_y [m/s]"], v * np.sin(DIRECTION - th), atol=1e-12)
    smp = traj.sample_uniform(dt).as_dict()
    for name, col in zip(smp, df.columns, strict=True):  # repr round-trips exactly
        np.testing.assert_array_equal(df[col].to_numpy(), smp[name], err_msg=col)
    arr = np.genfromtxt(path, delimiter=",", names=True)
    assert "v_body_x_ms" in arr.dtype.names and "course_rad_" in "".join(arr.dtype.names)


def test_json_and_poses(tmp_path):
    traj, (t_ref, th_ref, _) = _omni(0.5)
    loaded = json.loads(traj.to_json(tmp_path / "omni.json", dt=0.125).read_text())
    assert loaded["format"] == "trajopt.OmniTrajectory" and loaded["frame_id"] == "map"
    assert loaded["robot"]["drive"] == "omni"
    assert loaded["duration"] == 3.0 and loaded["v_end"] == 0.0
    assert loaded["units"]["course"] == "rad" and loaded["units"]["v_body_y"] == "m/s"
    assert "v_left" not in loaded["units"] and "v_left" not in loaded["samples"]
    ori = loaded["orientation"]
    assert ori["theta_start"] == THETA0 and ori["duration"] == 2.0
    assert ori["theta_end"] == pytest.approx(THETA0 + 0.25, abs=1e-12)
    assert ori["phases"]["zeta"] == [Z, -Z, -Z, Z] and ori["phases"]["t"] == [0, 0.5, 1, 1.5]
    assert ori["phases"]["units"]["zeta"] == "rad/s^3"
    assert loaded["translation"]["phases"]["t"] == traj.translation.phase_t.tolist()
    t = np.asarray(loaded["samples"]["t"])
    np.testing.assert_allclose(
        loaded["samples"]["theta"], th_ref[np.round(np.minimum(t, 2.0) / DT).astype(int)]
    )

    poses = traj.to_poses(dt=0.125)
    yaw = 2.0 * np.arctan2(poses["qz"], poses["qw"])  # the pose's yaw is the orientation
    want = th_ref[np.round(np.minimum(poses["t"], 2.0) / DT).astype(int)]
    np.testing.assert_allclose(
        np.remainder(yaw - want + math.pi, 2 * math.pi) - math.pi, 0.0, atol=1e-9
    )


def test_mcap_poses_carry_the_orientation(tmp_path):
    pytest.importorskip("mcap")
    from trajopt.motion import read_mcap

    traj, _ = _omni(1.0)
    got = read_mcap(traj.to_mcap(tmp_path / "omni.mcap", dt=0.05))
    smp = traj.sample_uniform(0.05)
    np.testing.assert_allclose(got.x, smp.x, atol=1e-12)
    np.testing.assert_allclose(
        np.remainder(got.theta - smp.theta + math.pi, 2 * math.pi) - math.pi, 0.0, atol=1e-9
    )
    np.testing.assert_allclose(got.omega, smp.omega, atol=1e-12)


def test_no_turn():
    translation, _ = _translation()
    traj = OmniTrajectory(translation, OMNI, np.zeros((0, 5)), 0.0, 1.0, 1.0)
    smp = traj.sample(np.linspace(0.0, 3.0, 7))
    assert np.all(smp.theta == 1.0) and np.all(smp.omega == 0.0)
    assert traj.duration == 3.0 and traj.n_phases == 0
    assert traj.to_dict(0.5)["orientation"]["phases"]["t"] == []


def test_invalid_construction():
    traj, _ = _omni(0.5)
    with pytest.raises(InvalidInputError, match="rows"):
        dataclasses.replace(traj, rows=np.zeros((3, 4)))
    with pytest.raises(InvalidInputError, match="rows"):
        dataclasses.replace(traj, rows=traj.rows[::-1])
    with pytest.raises(InvalidInputError, match="turn_duration"):
        dataclasses.replace(traj, turn_duration=1.0)  # before the last row's start (1.5 s)
    with pytest.raises(InvalidInputError, match="theta_end"):
        dataclasses.replace(traj, theta_end=math.nan)
    with pytest.raises(InvalidInputError, match="theta_end"):
        dataclasses.replace(traj, rows=np.zeros((0, 5)), turn_duration=0.0)
    with pytest.raises(InvalidInputError, match="translation"):
        dataclasses.replace(traj, translation="a path")
    with pytest.raises(InvalidInputError, match="robot"):
        dataclasses.replace(traj, robot=None)
    moving = time_parameterize(line(1.0), OMNI, v_end=0.2)
    with pytest.raises(InvalidInputError, match="v_end"):
        dataclasses.replace(traj, translation=moving, turn_duration=moving.duration + 1.0)


def test_the_mcap_twist_of_an_omni_base_is_its_body_velocity(tmp_path):
    read_ros2_messages = pytest.importorskip("mcap_ros2.reader").read_ros2_messages
    traj, _ = _omni(0.5)
    path = traj.to_mcap(tmp_path / "omni.mcap", dt=0.05)
    twists = [m.ros_msg.twist for m in read_ros2_messages(str(path), topics=["/twist"])]
    smp = traj.sample(np.arange(len(twists)) * 0.05)
    np.testing.assert_allclose([t.linear.x for t in twists], smp.v_body_x, atol=1e-12)
    np.testing.assert_allclose([t.linear.y for t in twists], smp.v_body_y, atol=1e-12)
    np.testing.assert_allclose([t.angular.z for t in twists], smp.omega, atol=1e-12)
