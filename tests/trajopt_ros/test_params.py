"""Tests of trajopt_ros: parameter validation and the import boundary (no ROS needed)."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import trajopt
from trajopt_ros import codes
from trajopt_ros.errors import ParameterError, RequestError
from trajopt_ros.params import PARAMETERS, build_config, defaults


def test_defaults_build_the_library_defaults():
    cfg = build_config({})
    assert cfg.robot == trajopt.Robot()
    assert cfg.options == trajopt.PlannerOptions(robot=trajopt.Robot())
    assert set(cfg.values) == {p.name for p in PARAMETERS}


def test_footprint_and_car():
    fp = [0.4, 0.2, -0.3, 0.2, -0.3, -0.2, 0.4, -0.2]
    cfg = build_config({"robot.footprint": fp})
    np.testing.assert_allclose(cfg.robot.footprint.vertices, np.reshape(fp, (-1, 2)))
    car = build_config(
        {"robot.drive": "ackermann", "robot.min_turning_radius": 1.5, "robot.reverse": False}
    )
    assert car.robot == trajopt.Robot(drive="ackermann", min_turning_radius=1.5, reverse=False)


@pytest.mark.parametrize(
    ("name", "value", "words"),
    [
        ("robot.v_max", -1.0, "> 0"),
        ("robot.v_max", float("nan"), "finite"),
        ("robot.drive", "tank", "differential"),
        ("robot.min_turning_radius", 1.0, "must be 0 with robot.drive differential"),
        ("robot.footprint", [0.1, 0.2, 0.3], "even"),
        ("robot.footprint", [0.1, 0.1, 0.2, 0.1, 0.2, 0.2], "robot.footprint"),  # origin outside
        ("planner.corridor", "tubes", "polygons"),
        ("planner.costmap_weight", -2.0, ">= 0"),
        ("map.occupied_threshold", 0, "1..100"),
        ("odom.to_map", [0.0, 1.0], "three"),
        ("topics.plan", "9plan", "ROS name"),
        ("replan.rate", 0.0, "> 0"),
        ("no.such", 1, "not a parameter"),
    ],
)
def test_bad_parameter_named_with_value_and_rule(name, value, words):
    with pytest.raises(ParameterError) as err:
        build_config(defaults() | {name: value})
    msg = str(err.value)
    assert name in msg and words in msg


def test_car_needs_turning_radius():
    with pytest.raises(ParameterError, match="robot.min_turning_radius"):
        build_config({"robot.drive": "ackermann"})


def test_reasons_and_codes():
    assert codes.reason_of(trajopt.NoPathError("x")) == "no_path"
    assert codes.reason_of(trajopt.SmoothingError("x")) == "smoothing_failed"
    assert codes.reason_of(trajopt.TimingError("x")) == "timing_failed"
    assert codes.reason_of(trajopt.InvalidInputError("x")) == "invalid_input"
    assert codes.reason_of(RequestError("goal_occupied", "x")) == "goal_occupied"
    assert codes.reason_of(RuntimeError("x")) == "unknown"
    assert len(set(codes.PLAN_TRAJECTORY.values())) == len(codes.REASONS)
    assert codes.code_for(codes.COMPUTE_PATH_TO_POSE, "no_odometry") == 200  # UNKNOWN


def test_core_and_package_never_import_rclpy():
    code = (
        "import sys, trajopt, astar, trajopt_ros, trajopt_ros.params, trajopt_ros.codes; "
        "trajopt.Planner; trajopt.Robot(); "
        "assert not any(m == 'rclpy' or m.startswith('rclpy.') for m in sys.modules), 'rclpy'"
    )
    subprocess.run([sys.executable, "-c", code], check=True)
