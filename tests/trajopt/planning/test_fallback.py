"""Tests of trajopt.planning: the stop-and-turn fallback (issue 7, section 2) against independent references.

References: ruckig's own 1-DoF answer and a closed-form rest-to-rest time for each leg and
turn, limits on dense samples, brute-force clearance to the raw map's obstacle squares.
"""

from __future__ import annotations

import json
import math
import time

import numpy as np
import pytest

import astar
import trajopt
from tests.reference import (
    closed_form_duration,
    polyline_samples,
    ruckig_rest_to_rest_duration,
    square_clearance,
    turn_limits_by_hand,
    v_limit_by_hand,
)
from trajopt.analysis.metrics import trajectory_metrics
from trajopt.cli import main
from trajopt.errors import InvalidInputError, SmoothingError
from trajopt.geometry._clearance import polyline_clearance
from trajopt.motion._stop_and_turn import StopAndTurnTrajectory
from trajopt.timing._stop_and_turn import stop_and_turn

REL = 1e-9
DEFAULT = trajopt.Robot()
WHEELS = trajopt.Robot(v_max=0.8, omega_max=5.0, track_width=0.5, wheel_v_max=0.3)
PLAIN = trajopt.Robot(track_width=None, wheel_v_max=None, radius=0.2)


# ------------------------------------------------------------------ geometry
SQUARE = np.array([(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0), (0.0, 0.0)])


def test_square_path_matches_hand_computed_turns_and_ruckig_legs():
    traj = stop_and_turn(SQUARE, DEFAULT)
    leg = ruckig_rest_to_rest_duration(1.0, 0.5, 0.5, 2.0)
    assert leg == pytest.approx(3.25, rel=1e-12)  # by hand: ramps of 1.25 s + cruise 0.75 s
    w, al, z = 1.5, 0.5 / 0.14, 2.0 / 0.14  # omega_max binds: wheels allow 0.6/0.14 rad/s
    assert turn_limits_by_hand(DEFAULT) == pytest.approx((w, al, z), rel=1e-15)
    turn = closed_form_duration(math.pi / 2, w, al, z)
    assert turn == pytest.approx(ruckig_rest_to_rest_duration(math.pi / 2, w, al, z), rel=1e-9)
    assert traj.stats["n_turns"] == 3 and traj.stats["n_segments"] == 4
    assert traj.stats["turn_total_rad"] == pytest.approx(3 * math.pi / 2, rel=1e-15)
    assert traj.duration == pytest.approx(4 * leg + 3 * turn, rel=1e-12)
    assert traj.length == pytest.approx(4.0, rel=1e-15)
    # arrivals at the corners at rest, turns of +pi/2 at rest, then the next leg
    for k, corner in enumerate(SQUARE[1:4]):
        t_arrive = (k + 1) * leg + k * turn
        smp = traj.sample(np.array([t_arrive, t_arrive + 0.5 * turn, t_arrive + turn]))
        np.testing.assert_allclose(np.c_[smp.x, smp.y], [corner] * 3, atol=1e-12)
        np.testing.assert_allclose(smp.v, 0.0, atol=1e-12)
        assert smp.theta[0] == pytest.approx(k * math.pi / 2, abs=1e-9)
        assert smp.theta[1] == pytest.approx(k * math.pi / 2 + math.pi / 4, abs=1e-9)
        assert smp.theta[2] == pytest.approx((k + 1) * math.pi / 2, abs=1e-9)
        assert smp.omega[1] == pytest.approx(w, rel=1e-9)  # cruising turn rate at mid-turn
    end = traj.sample(traj.duration)
    assert (float(end.x), float(end.y)) == (0.0, 0.0)  # exact end point
    assert float(end.theta) == pytest.approx(3 * math.pi / 2, abs=1e-12)
    assert float(end.s) == traj.length


@pytest.mark.parametrize("robot", [DEFAULT, WHEELS, PLAIN], ids=["default", "wheels", "plain"])
def test_end_headings_use_the_shortest_signed_angle(robot):
    traj = stop_and_turn([(0, 0), (2, 0)], robot, start_heading=3.0, goal_heading=-0.5)
    w, al, z = turn_limits_by_hand(robot)
    # start: 3.0 -> 0 by -3.0 rad; end: 0 -> -0.5 rad
    expect = (
        closed_form_duration(3.0, w, al, z)
        + closed_form_duration(2.0, v_limit_by_hand(robot), robot.a_max, robot.j_max)
        + closed_form_duration(0.5, w, al, z)
    )
    assert traj.duration == pytest.approx(expect, rel=1e-9)
    assert traj.sample(0.0).theta == 3.0
    assert float(traj.sample(traj.duration).theta) == pytest.approx(-0.5, abs=1e-12)
    wrap = stop_and_turn([(0, 0), (2, 0)], robot, start_heading=7.0)
    # from 7.0 rad the shortest turn to the direction 0 (= 2 pi) is 2 pi - 7 = -0.717 rad
    assert wrap.stats["turn_total_rad"] == pytest.approx(7.0 - 2 * math.pi, abs=1e-12)
    assert float(wrap.sample(wrap.duration).theta) == pytest.approx(2 * math.pi, abs=1e-12)


def random_polyline(rng: np.random.Generator, n: int = 9) -> np.ndarray:
    steps = rng.uniform(-1.5, 1.5, size=(n - 1, 2))
    steps[2] = [0.004, 0.0]  # a short leg: ruckig never reaches the speed limit
    steps[5] = -steps[4]  # an exact U-turn
    return np.vstack([[0.0, 0.0], np.cumsum(steps, axis=0)])


@pytest.mark.parametrize("robot", [DEFAULT, WHEELS, PLAIN], ids=["default", "wheels", "plain"])
def test_limits_continuity_and_turning_only_at_rest(robot):
    pts = random_polyline(np.random.default_rng(3))
    traj = stop_and_turn(pts, robot, start_heading=-2.0, goal_heading=1.0)
    t = np.linspace(0.0, traj.duration, 200_001)
    smp = traj.sample(t)
    th, w, al, z = traj.heading_motion(t)
    vl = v_limit_by_hand(robot)
    w_lim, al_lim, z_lim = turn_limits_by_hand(robot)
    assert smp.v.max() <= vl * (1 + REL) and smp.v.min() >= 0.0
    assert smp.v.max() >= vl * (1 - 1e-9)  # the long legs do reach it
    assert np.abs(smp.a).max() <= robot.a_max * (1 + REL)
    assert np.abs(smp.jerk).max() <= robot.j_max * (1 + REL)
    assert np.abs(smp.omega).max() <= w_lim * (1 + REL)
    assert np.abs(al).max() <= al_lim * (1 + REL)
    assert np.abs(z).max() <= z_lim * (1 + REL)
    np.testing.assert_array_equal(th, smp.theta)
    np.testing.assert_array_equal(w, smp.omega)
    if robot.track_width is not None:
        assert np.abs(smp.v_left).max() <= robot.wheel_v_max * (1 + REL)
        assert np.abs(smp.v_right).max() <= robot.wheel_v_max * (1 + REL)
        np.testing.assert_allclose(smp.v_right - smp.v_left, smp.omega * robot.track_width)
    else:
        assert smp.v_left is None and smp.v_right is None
    np.testing.assert_array_equal(smp.kappa, 0.0)
    np.testing.assert_array_equal(smp.a_lat, 0.0)
    # continuity: no sample-to-sample jump beyond the speed limits times the step
    dt = t[1] - t[0]
    assert np.hypot(np.diff(smp.x), np.diff(smp.y)).max() <= vl * dt * (1 + 1e-6)
    assert np.abs(np.diff(smp.theta)).max() <= w_lim * dt * (1 + 1e-6)
    assert np.all(np.diff(smp.s) >= -1e-12)
    np.testing.assert_allclose(np.diff(smp.s), np.hypot(np.diff(smp.x), np.diff(smp.y)), atol=1e-12)
    # translation and rotation never at once; heading along the segment while moving
    assert np.all((smp.v == 0.0) | (smp.omega == 0.0))
    moving = np.flatnonzero(np.diff(smp.s) > 1e-6)
    direction = np.arctan2(np.diff(smp.y)[moving], np.diff(smp.x)[moving])
    err = np.angle(np.exp(1j * (direction - smp.theta[moving])))
    assert np.abs(err).max() < 1e-6
    # while moving the heading is held exactly (one constant per segment)
    drive = (traj.phase_v != 0) | (traj.phase_a != 0) | (traj.phase_j != 0)
    turn = (traj.phase_omega != 0) | (traj.phase_alpha != 0) | (traj.phase_zeta != 0)
    assert not np.any(drive & turn)
    assert np.all(np.isin(smp.theta[smp.v > 0], traj.phase_theta[drive]))
    assert len(np.unique(traj.phase_theta[drive])) <= traj.stats["n_segments"]
    # exact ends
    assert (float(smp.x[0]), float(smp.y[0]), float(smp.theta[0])) == (0.0, 0.0, -2.0)
    assert (float(smp.x[-1]), float(smp.y[-1])) == tuple(pts[-1])
    assert math.remainder(float(smp.theta[-1]) - 1.0, 2 * math.pi) == pytest.approx(0, abs=1e-12)
    assert float(smp.s[-1]) == traj.length
    # each turn by the shortest signed angle: at most pi
    n_turn_phases = np.diff(np.concatenate([[0], (traj.phase_omega != 0) | (traj.phase_zeta != 0)]))
    assert traj.stats["n_turns"] == int((n_turn_phases == 1).sum())
    assert traj.stats["turn_total_rad"] <= math.pi * traj.stats["n_turns"] + 1e-12


def test_duration_is_the_sum_of_ruckig_legs_and_turns():
    pts = random_polyline(np.random.default_rng(11))
    traj = stop_and_turn(pts, WHEELS)
    d = np.diff(traj.vertices, axis=0)
    legs = sum(
        ruckig_rest_to_rest_duration(float(np.hypot(*x)), 0.3, WHEELS.a_max, WHEELS.j_max)
        for x in d
    )
    heads = np.arctan2(d[:, 1], d[:, 0])
    turns = [
        abs(math.remainder(b - a, 2 * math.pi)) for a, b in zip(heads[:-1], heads[1:], strict=True)
    ]
    w, al, z = turn_limits_by_hand(WHEELS)
    assert w == pytest.approx(0.3 / 0.25)  # the wheels bind, not omega_max
    total = legs + sum(ruckig_rest_to_rest_duration(x, w, al, z) for x in turns)
    assert traj.duration == pytest.approx(total, rel=1e-12)
    assert traj.stats["drive_time_s"] == pytest.approx(legs, rel=1e-12)


def test_zero_length_and_straight_on_vertices_are_dropped():
    pts = [(0, 0), (0, 0), (0.5, 0), (1, 0), (1, 0), (1, 1e-10 / 3), (1, 1), (1, 2), (1, 2)]
    traj = stop_and_turn(pts, DEFAULT)
    np.testing.assert_array_equal(traj.vertices, [(0, 0), (1, 0), (1, 2)])
    assert traj.stats["n_turns"] == 1 and traj.stats["n_segments"] == 2
    back = stop_and_turn([(0, 0), (1, 0), (0.5, 0)], DEFAULT)  # a U-turn is kept
    assert len(back.vertices) == 3 and back.stats["turn_total_rad"] == pytest.approx(math.pi)


def test_interface_exports_and_metrics(tmp_path):
    traj = stop_and_turn(SQUARE, DEFAULT, goal_heading=0.0)
    assert traj.v_start == 0.0 and traj.v_end == 0.0 and traj.steps is None
    assert traj.stats["fallback"] == "stop_and_turn"
    assert isinstance(traj.path, trajopt.ParametricCurve)
    np.testing.assert_array_equal(traj.path.points, traj.vertices)
    smp = traj.sample(np.zeros((3, 4)))
    assert smp.x.shape == (3, 4) and not smp.x.flags.writeable
    assert float(traj.sample(-5.0).x) == 0.0
    assert float(traj.sample(1e9).theta) == pytest.approx(2 * math.pi, abs=1e-12)
    uni = traj.sample_uniform(0.1)
    assert uni.t[0] == 0.0 and uni.t[-1] == traj.duration
    m = trajectory_metrics(traj, DEFAULT)
    assert m["within_limits"] and m["ratio_v"] == pytest.approx(1.0)
    js = json.loads(
        traj.to_json(tmp_path / "t.json", dt=0.05).read_text(),
        parse_constant=lambda c: pytest.fail(f"non-finite {c} in JSON"),
    )
    assert js["format"] == "trajopt.StopAndTurnTrajectory"
    assert js["stats"]["fallback"] == "stop_and_turn"
    assert js["vertices"]["xy"] == SQUARE.tolist()
    assert js["samples"]["kappa"] == [0.0] * len(js["samples"]["t"])
    lines = traj.to_csv(tmp_path / "t.csv", dt=0.05, frame_id="odom").read_text().splitlines()
    assert lines[0].startswith("t [s],x [m] (odom),y [m] (odom),theta [rad] (odom),v [m/s]")
    body = np.array([r.split(",") for r in lines[1:]], float)
    assert np.all(np.isfinite(body)) and body[-1, 0] == traj.duration
    assert "StopAndTurnTrajectory(" in repr(traj)


def test_sampling_is_vectorised():
    traj = stop_and_turn(random_polyline(np.random.default_rng(5), 60), DEFAULT)
    t = np.linspace(0.0, traj.duration, 10_000)
    best = math.inf
    for _ in range(5):
        t0 = time.perf_counter()
        traj.sample(t)
        best = min(best, time.perf_counter() - t0)
    assert best < 0.01


# ------------------------------------------------------------------ clearance
def test_polyline_clearance_is_exact():
    rng = np.random.default_rng(0)
    occ = rng.random((30, 40)) < 0.03
    grid = astar.OccupancyGrid(occ, 0.1, (-1.0, 2.0))
    spacing = 2e-4
    positive = 0
    for _ in range(30):
        p0 = rng.uniform([-0.8, 2.2], [2.8, 4.8])
        pts = np.clip(p0 + np.cumsum(rng.normal(0, 0.25, (3, 2)), axis=0), [-1, 2], [3, 5])
        exact = polyline_clearance(pts, grid, window_m=1.0)
        dense = min(square_clearance(grid, polyline_samples(pts, spacing)).min(), 1.0)
        assert exact <= dense + 1e-12  # never more optimistic than any sample
        assert dense - exact <= spacing  # and within the sample spacing of the true minimum
        positive += exact > 0
        capped = polyline_clearance(pts, grid, window_m=0.05)
        assert capped == pytest.approx(min(exact, 0.05), abs=1e-12)
    assert positive >= 5  # the check saw clear polylines, not only collisions


# ------------------------------------------------------------------ planner
def zigzag_grid(gap: int = 5, legs: int = 6, leg: int = 6):
    """A corridor of alternating x and y legs, ``gap`` cells wide (5 cm cells): one cell
    wide after inflation by 0.12 m; the smoother fails on its staircase."""
    size = 2 * gap + legs * leg + 10
    occ = np.ones((size, size), bool)
    x = y = 3
    for k in range(legs):
        if k % 2 == 0:
            occ[y : y + gap, x : x + leg + gap] = False
            x += leg
        else:
            occ[y : y + leg + gap, x : x + gap] = False
            y += leg
    res = 0.05
    start = ((3 + gap / 2) * res + 0.004, (3 + gap / 2) * res + 0.003)
    goal = ((x + gap / 2) * res, (y + gap / 2) * res - 0.004)
    return astar.OccupancyGrid(occ, res, (0.0, 0.0)), start, goal


ZZ_ROBOT = trajopt.Robot(radius=0.12)


@pytest.fixture(scope="module")
def zigzag():
    return zigzag_grid()


def test_without_fallback_the_zigzag_raises(zigzag):
    # the box corridor of the one-cell staircase squeezes the control points together
    grid, start, goal = zigzag
    with pytest.raises(SmoothingError):
        trajopt.plan(grid, start, goal, ZZ_ROBOT, corridor="boxes")


def test_polygon_corridor_smooths_the_zigzag(zigzag):
    # the polygons are rotated regions with real overlaps: a certified curve, no fallback
    grid, start, goal = zigzag
    traj = trajopt.plan(grid, start, goal, ZZ_ROBOT)
    assert traj.stats["corridor"] == "polygons" and traj.steps.smooth_path.certificate.ok
    smp = traj.sample(np.linspace(0.0, traj.duration, 4000))
    assert square_clearance(grid, np.c_[smp.x, smp.y]).min() >= ZZ_ROBOT.radius - 1e-9
    assert trajectory_metrics(traj, ZZ_ROBOT)["within_limits"]


def test_planner_fallback_is_safe_exact_and_deterministic(zigzag):
    # the box corridor cannot smooth the zigzag (above): the fallback drives the polyline
    # and turns in place onto the goal heading at its end
    grid, start, goal = zigzag
    planner = trajopt.Planner(grid, ZZ_ROBOT, fallback="stop_and_turn", corridor="boxes")
    traj = planner.plan(start, goal, goal_heading=0.0)
    assert isinstance(traj, StopAndTurnTrajectory)
    st = traj.stats
    assert st["fallback"] == "stop_and_turn" and st["fallback_error"] == "SmoothingError"
    assert "certified" in st["fallback_reason"] and "smoother" in st
    assert {"search", "corridor", "smooth", "fallback", "total"} <= set(st["stages_s"])
    steps = traj.steps
    assert steps.smooth_path is None and steps.start == start and steps.goal == goal
    # the polyline: exact start -> A* cell centres (straight-on ones dropped) -> exact goal
    centres = grid.cell_to_world(np.asarray(steps.grid_path.cells))
    verts = traj.vertices
    assert tuple(verts[0]) == start and tuple(verts[-1]) == goal
    for v in verts[1:-1]:
        assert np.min(np.hypot(*(centres - v).T)) == 0.0
    # dense samples keep the clearance from the raw map (brute force, outside = occupied)
    smp = traj.sample(np.linspace(0.0, traj.duration, 3000))
    pts = np.vstack([np.c_[smp.x, smp.y], verts])
    assert square_clearance(grid, pts).min() >= ZZ_ROBOT.radius - 1e-9
    assert square_clearance(grid, polyline_samples(verts, 0.002)).min() >= ZZ_ROBOT.radius - 1e-9
    assert st["fallback_min_clearance_m"] >= ZZ_ROBOT.radius - 1e-9
    assert (float(smp.x[-1]), float(smp.y[-1])) == goal
    assert math.remainder(float(smp.theta[-1]), 2 * math.pi) == pytest.approx(0.0, abs=1e-12)
    assert trajectory_metrics(traj, ZZ_ROBOT)["within_limits"]
    # determinism: a fresh planner and trajopt.plan give the same answer bit for bit
    again = trajopt.plan(
        grid, start, goal, ZZ_ROBOT, goal_heading=0.0, fallback="stop_and_turn", corridor="boxes"
    )
    t = np.linspace(0.0, traj.duration, 500)
    for a, b in zip(traj.sample(t), again.sample(t), strict=True):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(traj.phase_t, again.phase_t)


def test_fallback_needs_rest_at_both_ends(zigzag):
    grid, start, goal = zigzag
    planner = trajopt.Planner(grid, ZZ_ROBOT, fallback="stop_and_turn", corridor="boxes")
    with pytest.raises(SmoothingError):
        planner.plan(start, goal, v_end=0.1)


def test_failed_clearance_check_reraises_the_original_error(zigzag, monkeypatch):
    import trajopt.planning._fallback as fallback

    monkeypatch.setattr(fallback, "polyline_clearance", lambda *a, **k: 0.0)
    grid, start, goal = zigzag
    with pytest.raises(SmoothingError, match="certified"):
        trajopt.Planner(grid, ZZ_ROBOT, fallback="stop_and_turn", corridor="boxes").plan(
            start, goal
        )


def test_fallback_unused_when_the_smoother_succeeds():
    from tests.cases import door_grid

    grid = door_grid()
    a = trajopt.plan(grid, (0.4, 0.3), (2.6, 1.6), ZZ_ROBOT, fallback="stop_and_turn")
    assert isinstance(a, trajopt.Trajectory) and "fallback" not in a.stats
    assert a.steps.smooth_path is not None


def test_cli_plan_fallback(zigzag, tmp_path, capsys):
    grid, start, goal = zigzag
    path = astar.save_map(grid, tmp_path / "zz.yaml")
    args = [
        "plan",
        str(path),
        "--start",
        *map(str, start),
        "--goal",
        *map(str, goal),
        "--radius",
        "0.12",
        "--corridor",
        "boxes",
    ]
    assert main(args) == 2
    assert "SmoothingError" in capsys.readouterr().err
    out = tmp_path / "fb.json"
    assert main([*args, "--fallback", "--out", str(out)]) == 0
    line = capsys.readouterr().out
    assert "FALLBACK stop_and_turn" in line and "SmoothingError" in line
    assert json.loads(out.read_text())["stats"]["fallback"] == "stop_and_turn"


# ------------------------------------------------------------------ bad inputs
@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"points": [(0, 0)]}, r"points must have shape \(n, 2\) with 2 <= n"),
        ({"points": [(0, 0, 0), (1, 1, 1)]}, r"points must have shape \(n, 2\).*\(2, 3\)"),
        ({"points": "abc"}, "points must"),
        ({"points": [(0, 0), (1, float("nan"))]}, r"points must be finite.*points\[1\]"),
        ({"points": [(1, 1), (1, 1), (1, 1 + 1e-12)]}, "points must span a length"),
        ({"robot": "fast"}, "robot must be a trajopt.Robot, got str"),
        ({"start_heading": float("inf")}, "start_heading must be finite"),
        ({"goal_heading": True}, "goal_heading must be a number"),
        ({"goal_heading": "north"}, "goal_heading must be a number.*'north'"),
    ],
)
def test_bad_inputs(kwargs, match):
    args = {"points": [(0, 0), (1, 0)], "robot": None} | kwargs
    points, robot = args.pop("points"), args.pop("robot")
    with pytest.raises(InvalidInputError, match=match):
        stop_and_turn(points, robot, **args)


def test_bad_fallback_option(zigzag):
    grid, start, goal = zigzag
    for bad in ("stop-and-turn", True, 1):
        with pytest.raises(InvalidInputError, match="fallback must be one of"):
            trajopt.Planner(grid, ZZ_ROBOT, fallback=bad)
    with pytest.raises(InvalidInputError, match="fallback must be one of"):
        trajopt.plan(grid, start, goal, ZZ_ROBOT, fallback="yes")
