"""Tests of trajopt.drive: the drive records, their checks, the speed rule and a fourth drive.

The speed rule is checked against the formula written out by hand; the fourth drive (a
record defined here, answering the Drive protocol) plans through ``trajopt.Planner`` with
no change anywhere else, which is what "no stage names a drive" means.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
import pytest

import trajopt
from tests.cases import door_grid
from trajopt.drive import (
    Ackermann,
    Differential,
    Drive,
    Omni,
    SpeedTerms,
    as_drive,
    speed_cap,
)
from trajopt.errors import InvalidInputError

CAR = {"min_turning_radius": 0.5}


@pytest.mark.parametrize(
    ("fields", "field", "rule"),
    [
        ({}, "min_turning_radius", "is required"),
        ({"min_turning_radius": math.nan}, "min_turning_radius", "must be finite and > 0"),
        ({"min_turning_radius": -1.0}, "min_turning_radius", "must be finite and > 0"),
        ({**CAR, "reverse": "yes"}, "reverse", "must be True or False"),
        ({**CAR, "wheelbase": 0.0}, "wheelbase", "must be finite and > 0"),
        ({**CAR, "wheelbase": math.inf}, "wheelbase", "must be finite and > 0"),
        ({**CAR, "v_max_reverse": -0.1}, "v_max_reverse", "must be finite and > 0"),
        ({**CAR, "steer_rate_max": 0.0, "wheelbase": 0.3}, "steer_rate_max", "> 0"),
        ({**CAR, "steer_rate_max": 1.0}, "steer_rate_max", "needs a wheelbase"),
    ],
)
def test_each_car_field_is_checked_by_the_record_and_by_the_shorthand(fields, field, rule):
    with pytest.raises(InvalidInputError, match=rf"Ackermann\.{field}.*{rule}"):
        Ackermann(**fields)
    with pytest.raises(InvalidInputError, match=rf"Robot\.{field}.*{rule}"):
        trajopt.Robot(drive="ackermann", **fields)


@pytest.mark.parametrize("bad", ["tank", "Omni", 3, None, Differential])
def test_an_unknown_drive_is_refused_listing_the_drives(bad):
    with pytest.raises(InvalidInputError, match=r"one of \('differential', 'omni', 'ackermann'\)"):
        trajopt.Robot(drive=bad)


@pytest.mark.parametrize("drive", ["differential", "omni", Differential(), Omni()])
@pytest.mark.parametrize("field", ["min_turning_radius", "wheelbase", "steer_rate_max"])
def test_a_cars_field_is_refused_beside_another_drive(drive, field):
    with pytest.raises(InvalidInputError, match=field):
        trajopt.Robot(drive=drive, **{field: 1.0})


def test_the_shorthand_and_the_record_are_the_same_robot():
    short = trajopt.Robot(drive="ackermann", min_turning_radius=0.7, wheelbase=0.3)
    value = trajopt.Robot(drive=Ackermann(min_turning_radius=0.7, wheelbase=0.3))
    assert short == value and short.drive == Ackermann(0.7, True, 0.3)
    assert trajopt.Robot().drive == Differential() and trajopt.Robot(drive="omni").drive == Omni()
    # a car's fields beside its record replace its own (dataclasses.replace goes this way)
    fwd = dataclasses.replace(value, reverse=False)
    assert fwd.drive == Ackermann(0.7, False, 0.3) and fwd.v_max == value.v_max
    with pytest.raises(InvalidInputError, match=r"Ackermann\.wheelbase"):
        dataclasses.replace(value, wheelbase=-1.0)


def test_the_cars_fields_live_on_the_drive():
    robot = trajopt.Robot(drive=Ackermann(min_turning_radius=0.7))
    assert robot.drive.min_turning_radius == 0.7
    with pytest.raises(AttributeError, match=r"robot\.drive\.min_turning_radius"):
        _ = robot.min_turning_radius
    d = robot.to_dict()  # the label, then the car's fields, as files have them
    assert d["drive"] == "ackermann" and d["min_turning_radius"] == 0.7
    assert trajopt.Robot(**d) == robot
    assert "min_turning_radius" not in trajopt.Robot().to_dict()


def test_records_are_frozen_and_answer_the_protocol():
    for drive in (Differential(), Omni(), Ackermann(min_turning_radius=1.0)):
        assert isinstance(drive, Drive)
        car = {"min_turning_radius": 1.0} if drive.signed_speed else {}
        assert as_drive(drive) is drive and as_drive(drive.name, car) == drive
        for f in dataclasses.fields(drive):  # the car's; the others have none
            with pytest.raises(dataclasses.FrozenInstanceError):
                setattr(drive, f.name, None)


def hand_cap(robot: trajopt.Robot, k: np.ndarray, omni: bool) -> np.ndarray:
    """The speed cap written out term by term (the Robot docstring's formula)."""
    k = np.abs(k)
    out = []
    for kk in k:
        terms = [robot.v_max]
        if kk > 0:
            terms.append(math.sqrt(robot.a_lat_max / kk))
            if not omni:
                terms.append(robot.omega_max / kk)
        if not omni and robot.track_width is not None:
            terms.append(robot.wheel_v_max / (1.0 + kk * robot.track_width / 2.0))
        out.append(min(terms))
    return np.array(out)


@pytest.mark.parametrize("drive", [Differential(), Omni(), Ackermann(min_turning_radius=0.2)])
@pytest.mark.parametrize("track", [0.28, None])
def test_the_speed_rule_is_the_formula(drive, track):
    robot = trajopt.Robot(drive=drive, track_width=track, wheel_v_max=track and 0.6)
    k = np.array([0.0, 0.1, -0.7, 2.0, 5.0, -40.0])
    expect = hand_cap(robot, k, omni=drive.orients_body)
    np.testing.assert_allclose(robot.speed_cap(k), expect, rtol=1e-15)
    np.testing.assert_allclose(speed_cap(drive.speed_terms(robot), k), expect, rtol=1e-15)
    assert robot.speed_cap(np.inf) == 0.0 and robot.speed_cap(np.nan) == 0.0


@dataclass(frozen=True, slots=True)
class Tracked:
    """A fourth drive, defined here: a tracked base that turns in place but skids when it turns.

    It answers the Drive protocol with its own speed rule (a hundredth of the robot's yaw rate)
    and plans as a differential drive does.
    """

    name: ClassVar[str] = "tracked"
    turns_in_place: ClassVar[bool] = True
    orients_body: ClassVar[bool] = False
    signed_speed: ClassVar[bool] = False

    def speed_terms(self, robot: Any) -> SpeedTerms:
        return SpeedTerms(robot.v_max, robot.a_lat_max, robot.omega_max / 100.0, 0.0, np.inf)

    @property
    def steering(self) -> None:
        return None

    def sample_fields(self, robot: Any, arrays: dict, dkappa_dt: Any) -> None:
        return None

    def fields(self) -> dict[str, Any]:
        return {}

    def plan(self, options, caches, request, warm):
        from trajopt.planning import plan_turning

        return plan_turning(options, caches, request, warm)

    def replan(self, options, caches, trajectory, ts, goal, **kw):
        from trajopt.replan import replan_moving

        return replan_moving(options, caches, trajectory, ts, goal, **kw)


def test_a_fourth_drive_plans_without_a_change_elsewhere():
    robot = trajopt.Robot(radius=0.12, drive=Tracked())
    assert isinstance(robot.drive, Drive) and robot.to_dict()["drive"] == "tracked"
    grid = door_grid()
    planner = trajopt.Planner(grid, robot)
    traj = planner.plan((0.4, 0.3), (2.6, 1.6))
    smp = traj.sample(np.linspace(0.0, traj.duration, 4001))
    # its own speed rule holds: |omega| <= omega_max / 100 (the timing got the drive's terms)
    assert np.abs(smp.omega).max() <= robot.omega_max / 100.0 * (1.0 + 1e-6)
    assert np.all(smp.v <= robot.speed_cap(smp.kappa) * (1.0 + 1e-6) + 1e-9)
    disc = trajopt.Planner(grid, trajopt.Robot(radius=0.12)).plan((0.4, 0.3), (2.6, 1.6))
    assert traj.duration > disc.duration  # the slower yaw rate costs time
    again = planner.replan(traj, 0.3 * traj.duration, latency=0.0, goal=(2.8, 1.0))
    assert again.stats["replan"].startswith(("planned", "braked"))
