"""Tests of trajopt.analysis.bench's car methods (issue 36): ``trajopt-ackermann(-forward)``, ``ompl-reedsshepp``,
``ompl-dubins``, the query headings and the car metrics, on small built-in rooms (no shared data),
each checked against an independent reference (circles through three points of
``tests.reference``, closed-form arcs, brute-force clearance)."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("pyarrow", reason="the bench extra (pyarrow) is missing")

import astar  # noqa: E402
from tests.reference import square_clearance, three_point_curvature  # noqa: E402
from trajopt.analysis import bench  # noqa: E402
from trajopt.analysis.bench._car import pose_path_metrics  # noqa: E402
from trajopt.analysis.bench._methods import MapContext  # noqa: E402
from trajopt.analysis.bench._suites import MapQueries, Query, draw_headings, with_headings  # noqa: E402
from trajopt.errors import BenchmarkError  # noqa: E402

CAR = ("trajopt-ackermann", "trajopt-ackermann-forward")
RADIUS = 0.2  # m; R = 0.4 m


def room() -> MapContext:
    """A closed corridor 6 m long, 0.7 m wide (free; 0.1 m cells): narrower than 2 R = 0.8 m."""
    res = 0.1
    occ = np.zeros((9, 60), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    grid = astar.OccupancyGrid(occ, res)
    inflated = astar.inflate(grid, RADIUS, metric="square", outside_occupied=True)
    return MapContext(grid, RADIUS, inflated)


@pytest.fixture(scope="module")
def behind():
    """The goal 1 m straight behind the start, both facing +x, in a corridor too narrow to turn."""
    mctx = room()
    rows = bench.evaluate_query(mctx, (30, 4), (20, 4), CAR, headings=(0.0, 0.0))
    return mctx, {r["method"]: r for r in rows}


def test_existing_methods_and_queries_are_unchanged():
    assert not set(bench.DEFAULT_METHODS) & {*CAR, "ompl-reedsshepp", "ompl-dubins"}
    assert {"trajopt", "astar", "bspline-fit"} <= set(bench.DEFAULT_METHODS)
    q = Query("m.map/scen/3", 3, 0, (1, 2), (3, 4), 5.0)
    assert math.isnan(q.start_heading) and math.isnan(q.goal_heading)


def test_headings_are_seeded_and_follow_bench_hybrids_rule():
    import zlib

    rng = np.random.default_rng([7, zlib.crc32(b"den312d.map"), 12])
    assert draw_headings("den312d.map", 12, 7) == tuple(rng.uniform(-math.pi, math.pi, 2))
    q = Query("den312d.map/scen/12", 12, 0, (1, 2), (3, 4), 5.0)
    mq = MapQueries("/x/den312d.map", "den312d.map", "scen", 2.5, 1.0, (q,))
    (out,) = with_headings([mq], 7)
    (q2,) = out.queries
    assert (q2.start_heading, q2.goal_heading) == draw_headings("den312d.map", 12, 7)
    assert (q2.query_id, q2.start, q2.goal) == (q.query_id, q.start, q.goal)
    assert all(-math.pi <= h < math.pi for h in (q2.start_heading, q2.goal_heading))
    with pytest.raises(BenchmarkError, match="seed"):
        with_headings([mq], -1)


def test_reverse_plan_is_scored_by_the_car_metrics(behind):
    mctx, rows = behind
    r = rows["trajopt-ackermann"]
    assert r["ok"], r["note"]
    assert r["turning_radius_m"] == pytest.approx(2.0 * RADIUS)
    assert (r["start_heading_rad"], r["goal_heading_rad"]) == (0.0, 0.0)
    assert r["reverse_length_m"] >= 1.0 - 1e-9  # it cannot turn round: it backs up
    assert r["curvature_violations"] == 0 and r["kappa_over_kmax"] <= 1.0 + 1e-6
    assert r["cusp_speed_max_mps"] == pytest.approx(0.0, abs=1e-9)
    assert r["end_heading_error_rad"] < 1e-6 and r["heading_motion_error_rad"] < 1e-3
    assert not r["collision"] and r["min_clearance_m"] >= RADIUS - 1e-9
    assert r["duration_s"] > 0 and r["stage_search_s"] > 0 and r["hybrid_search_s"] >= 0


def test_car_metrics_match_an_independent_replan(behind):
    """The row's cusps, reverse length, curvature and clearance, recomputed from a fresh plan."""
    import trajopt

    mctx, rows = behind
    r = rows["trajopt-ackermann"]
    robot = trajopt.Robot(radius=RADIUS, drive="ackermann", min_turning_radius=2 * RADIUS)
    start, goal = mctx.grid.cell_to_world((30, 4)), mctx.grid.cell_to_world((20, 4))
    traj = trajopt.plan(mctx.grid, start, goal, robot, start_heading=0.0, goal_heading=0.0)
    dirs = [p.direction for p in traj.pieces]
    assert r["cusps"] == sum(a != b for a, b in zip(dirs, dirs[1:], strict=False))
    back = sum(p.length for p in traj.pieces if p.direction < 0)
    assert r["reverse_length_m"] == pytest.approx(back, rel=1e-9)
    kmax, clear = 0.0, math.inf
    for p in traj.pieces:
        s = np.linspace(0.0, p.length, max(3, math.ceil(p.length / 0.002)))
        pts = np.asarray(p.path(p.path.u_at_s(s)))
        kmax = max(kmax, float(three_point_curvature(pts).max()))
        clear = min(clear, float(square_clearance(mctx.grid, pts, reach=RADIUS + 0.2).min()))
    assert r["kappa_over_kmax"] == pytest.approx(kmax * 2 * RADIUS, rel=1e-3, abs=1e-6)
    assert r["min_clearance_m"] == pytest.approx(clear, abs=0.01)


def test_forward_only_is_a_typed_refusal_row(behind):
    _, rows = behind
    r = rows["trajopt-ackermann-forward"]
    assert not r["ok"] and r["failure"] == "NoPathError"
    assert "forward" in r["note"] and math.isnan(r["min_clearance_m"])


def test_a_car_method_without_headings_is_a_typed_row():
    rows = bench.evaluate_query(room(), (30, 4), (20, 4), ("trajopt-ackermann", "astar"))
    assert rows[0]["failure"] == "BenchmarkError" and "headings" in rows[0]["note"]
    assert rows[1]["ok"]  # the other methods are unaffected


def test_pose_path_metrics_on_closed_form_arcs():
    """A quarter circle of radius R forwards, then 1 m straight backwards: 1 cusp, 1 m back."""
    R = 0.5
    a = np.linspace(0.0, math.pi / 2, 400)
    arc = np.column_stack([R * np.sin(a), R * (1.0 - np.cos(a))])  # leaves (0,0) along +x
    yaw_arc = a
    back = np.column_stack([np.full(200, R), R - np.linspace(0.0, 1.0, 200)])[1:]
    xy = np.vstack([arc, back])
    yaw = np.concatenate([yaw_arc, np.full(len(back), math.pi / 2)])  # nose up, driving down
    m = pose_path_metrics(xy, yaw, 1.0 / R, (0.0, math.pi / 2))
    assert m["cusps"] == 1
    assert m["reverse_length_m"] == pytest.approx(1.0, rel=1e-9)
    assert m["kappa_over_kmax"] == pytest.approx(1.0, rel=1e-6)
    assert m["curvature_violations"] == 0
    assert m["end_heading_error_rad"] == pytest.approx(0.0, abs=1e-12)
    assert m["heading_motion_error_rad"] < 1e-9
    # a path that turns tighter than R is counted
    m2 = pose_path_metrics(xy, yaw, 1.0 / (0.9 * R), (0.0, math.pi / 2))
    assert m2["curvature_violations"] == 0
    m3 = pose_path_metrics(xy, yaw, 1.0 / (1.1 * R), (0.0, math.pi / 2))
    assert m3["curvature_violations"] > 0 and m3["kappa_over_kmax"] == pytest.approx(1.1, rel=1e-6)


@pytest.mark.parametrize("method", ["ompl-reedsshepp", "ompl-dubins"])
def test_ompl_car_peer_rows(method, monkeypatch):
    pytest.importorskip("ompl", reason=f"{method} needs the ompl wheel")
    import trajopt.analysis.bench._peers as peers

    monkeypatch.setattr(peers, "OMPL_CAR_TIME_LIMIT_S", 0.5)
    (r,) = bench.evaluate_query(room(), (10, 4), (50, 4), (method,), headings=(0.0, 0.0))
    assert r["method"] == method
    if not r["ok"]:
        assert r["failure"] == "PeerFailure"
        return
    assert r["curvature_violations"] == 0 and r["kappa_over_kmax"] <= 1.0 + 1e-6
    assert r["end_heading_error_rad"] < 1e-6
    assert 0.0 < r["first_solution_s"] <= r["runtime_s"]
    assert math.isnan(r.get("duration_s", math.nan))  # untimed: compared by length only
    assert r["length_m"] >= 4.0 - 1e-6  # at least the straight distance
    if method == "ompl-dubins":
        assert r["cusps"] == 0 and r["reverse_length_m"] == 0.0


def test_car_rows_go_through_the_dataset(tmp_path):
    """run_chunk draws headings for queries without them; the car columns survive Parquet."""
    grid = room().grid
    path = tmp_path / "room.map"
    rows_txt = ["".join("@" if o else "." for o in row) for row in grid.occupied[::-1]]
    path.write_text(
        f"type octile\nheight {grid.occupied.shape[0]}\nwidth {grid.occupied.shape[1]}\nmap\n"
        + "\n".join(rows_txt)
        + "\n"
    )
    g = astar.load_map(path)
    assert np.array_equal(np.asarray(g.occupied), np.asarray(grid.occupied))
    q = Query("room.map/random/0", 0, -1, (30, 4), (20, 4), math.nan)
    mq = MapQueries(
        str(path), "room.map", "random", RADIUS * g.resolution / 0.1, g.resolution, (q,)
    )
    (ch,) = bench.make_chunks([mq], ["trajopt-ackermann", "astar"], set(), 1)
    rows = bench.run_chunk(ch)
    car = rows[0]
    assert (car["start_heading_rad"], car["goal_heading_rad"]) == draw_headings("room.map", 0, 0)
    bench.write_chunk(tmp_path, ch.chunk_id, rows)
    df = bench.read_dataset(tmp_path).set_index("method")
    assert df.loc["astar", "cusps"] == -1 and math.isnan(df.loc["astar", "turning_radius_m"])
    if car["ok"]:
        assert df.loc["trajopt-ackermann", "cusps"] == car["cusps"]
    assert df.loc["trajopt-ackermann", "turning_radius_m"] == pytest.approx(2 * mq.radius_m)
