"""Tests of trajopt.analysis.comparison (``trajopt.compare``): the table, the method registry, and the chapter's Section 5
reproduction on the paper scene (qualitative relations, no copied numbers)."""

from __future__ import annotations

import csv
import dataclasses
import importlib
import math
import re
import sys

import numpy as np
import pytest

from astar.grid import OccupancyGrid
from astar.inflation import avoidance_area
from astar.search import find_path
from trajopt.analysis import fits, scenes
from trajopt.errors import InvalidInputError, NoPathError

cmp = importlib.import_module("trajopt.analysis.comparison")

CHAPTER_METHODS = ("A*", "A* + avoidance area", "polynomial fit", "B-spline fit")
#: What compare runs by default: the chapter's four and the proposed method.
DEFAULT_METHODS = (*CHAPTER_METHODS, "proposed")


def _room() -> OccupancyGrid:
    """3 m x 3 m, 0.05 m cells, one 0.6 m square block in the middle."""
    occ = np.zeros((60, 60), bool)
    occ[24:36, 24:36] = True
    return OccupancyGrid(occ, 0.05, (0.0, 0.0))


def _line_method(ctx: cmp.ComparisonContext) -> np.ndarray:
    """A test method: the straight segment start -> goal (used by the lazy registration)."""
    return np.array([ctx.start, ctx.goal])


@pytest.fixture(scope="module")
def room_table() -> cmp.ComparisonTable:
    return cmp.compare(
        _room(),
        (0.5, 0.5),
        (2.5, 2.3),
        robot_radius=0.15,
        poly={"order": 3},
        bspline={"n_ctrl": 12},
    )


# ---------------------------------------------------------------------------- table
def test_default_rows_and_columns(room_table: cmp.ComparisonTable) -> None:
    assert room_table.methods == DEFAULT_METHODS
    for col in (
        "mse_m2",
        "hausdorff_m",
        "min_clearance_m",
        "collision",
        "length_ratio",
        "max_curvature_1pm",
        "max_heading_jump_rad",
        "runtime_s",
        "note",
    ):
        assert col in room_table.columns
    assert room_table.meta["w_cells"] == math.ceil(2 * 0.15 / 0.05)
    proposed = room_table.row("proposed")
    assert proposed["valid"] and not proposed["collision"]
    assert proposed["min_clearance_m"] >= 0.15 - 1e-9
    assert proposed["duration_s"] > 0 and proposed["ratio_v"] <= 1 + 1e-3
    avoid = room_table.row("A* + avoidance area")
    assert avoid["mse_m2"] == 0.0 and avoid["length_ratio"] == pytest.approx(1.0)
    assert room_table.row("polynomial fit")["note"].startswith("least_squares, order 3")
    assert "12 control points" in room_table.row("B-spline fit")["note"]
    with pytest.raises(InvalidInputError, match="method"):
        room_table.row("nope")


def test_table_conversions(room_table: cmp.ComparisonTable, tmp_path) -> None:
    recs = room_table.to_records()
    assert [r["method"] for r in recs] == list(DEFAULT_METHODS)
    recs[0]["method"] = "changed"  # fresh copies
    assert room_table.rows[0]["method"] == "A*"
    text = str(room_table)
    lines = text.splitlines()
    assert all(m in lines[0] for m in DEFAULT_METHODS)
    assert any(line.startswith("mse_m2") for line in lines)
    wide = room_table.to_text(transpose=False).splitlines()
    assert len(wide) == 2 + len(DEFAULT_METHODS) and wide[2].startswith("A*")
    # aligned: every body line of the wide table has the same width up to the note column
    md = room_table.to_markdown().splitlines()
    assert len(md) == 2 + len(DEFAULT_METHODS) and md[0].startswith("| method |")
    path = room_table.to_csv(tmp_path / "t.csv")
    with path.open() as fh:
        rows = list(csv.DictReader(fh))
    assert [r["method"] for r in rows] == list(DEFAULT_METHODS)
    assert float(rows[2]["hausdorff_m"]) == pytest.approx(room_table.rows[2]["hausdorff_m"])


def test_to_csv_is_atomic(tmp_path) -> None:
    """A write that fails midway keeps the old file and leaves no temporary file."""

    class Unprintable:
        def __str__(self) -> str:
            raise RuntimeError("cannot format")

    target = tmp_path / "t.csv"
    good = cmp.ComparisonTable(rows=({"method": "a", "x": 1.5},))
    assert good.to_csv(target) == target
    before = target.read_bytes()
    bad = cmp.ComparisonTable(rows=({"method": "a", "x": 2.5}, {"method": "b", "x": Unprintable()}))
    with pytest.raises(RuntimeError, match="cannot format"):
        bad.to_csv(target)
    assert target.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["t.csv"]
    with target.open(newline="") as fh:
        assert list(csv.DictReader(fh)) == [{"method": "a", "x": "1.5"}]


def test_table_is_frozen(room_table: cmp.ComparisonTable) -> None:
    with pytest.raises(dataclasses.FrozenInstanceError):
        room_table.rows = ()  # type: ignore[misc]
    with pytest.raises(TypeError):
        room_table.rows[0]["method"] = "x"  # type: ignore[index]


def test_to_dataframe(room_table: cmp.ComparisonTable, monkeypatch) -> None:
    monkeypatch.setitem(sys.modules, "pandas", None)  # import fails as if not installed
    with pytest.raises(ImportError, match="needs pandas"):
        room_table.to_dataframe()
    monkeypatch.undo()
    pd = pytest.importorskip("pandas")
    df = room_table.to_dataframe()
    assert isinstance(df, pd.DataFrame) and list(df.index) == list(DEFAULT_METHODS)


def test_bspline_row_is_invalid_when_the_data_cannot_determine_the_fit() -> None:
    """Issue 23: n_ctrl beyond the path is cut to the number of points, a square system
    where the Schoenberg-Whitney condition fails; the row has no curve and says why."""
    chapter = ["A* + avoidance area", "B-spline fit"]
    query = (_room(), (0.5, 0.5), (2.5, 2.3))
    table = cmp.compare(*query, robot_radius=0.15, bspline={"n_ctrl": 80}, methods=chapter)
    row = table.row("B-spline fit")
    n = len(table.paths["A* + avoidance area"])
    assert not row["valid"] and table.paths["B-spline fit"] is None
    assert math.isnan(row["mse_m2"]) and math.isnan(row["end_error_x_m"])
    assert f"n_ctrl reduced from 80 to {n}" in row["note"]
    assert "Schoenberg-Whitney" in row["note"] and "degree 2" in row["note"]
    allowed = int(row["note"].rsplit("allow at most ", 1)[1].split()[0])
    assert allowed < n
    ok = cmp.compare(*query, robot_radius=0.15, bspline={"n_ctrl": allowed}, methods=chapter)
    good = ok.row("B-spline fit")
    assert good["valid"] and "end points not exact" in good["note"]
    errors = [good[f"{end}_error_{ax}_m"] for end in ("start", "end") for ax in "xy"]
    assert all(math.isfinite(e) and e >= 0.0 for e in errors)


# ------------------------------------------------------------------------- registry
def test_one_off_methods_by_mapping() -> None:
    def failing(ctx):
        raise NoPathError("nothing here")

    t = cmp.compare(
        _room(),
        (0.5, 0.5),
        (2.5, 2.3),
        robot_radius=0.15,
        methods={"line": _line_method, "broken": failing},
    )
    assert t.methods == ("line", "broken")
    line = t.row("line")
    assert line["length_m"] == pytest.approx(math.hypot(2.0, 1.8))
    assert line["collision"]  # the straight line crosses the block
    assert line["min_clearance_m"] == 0.0
    broken = t.row("broken")
    assert not broken["valid"] and "nothing here" in broken["note"]
    assert math.isnan(broken["mse_m2"])


def test_register_method_adds_a_row_without_touching_others() -> None:
    name = "straight line (test)"
    cmp.register_method(name, "tests.trajopt.analysis.test_comparison:_line_method")
    try:
        assert name in cmp.registered_methods()
        with pytest.raises(InvalidInputError, match="already registered"):
            cmp.register_method(name, _line_method)
        t = cmp.compare(_room(), (0.5, 0.5), (2.5, 2.3), robot_radius=0.15, bspline={"n_ctrl": 8})
        assert t.methods == (*DEFAULT_METHODS, name)
        t2 = cmp.compare(_room(), (0.5, 0.5), (2.5, 2.3), robot_radius=0.15, methods=[name])
        assert t2.methods == (name,)
    finally:
        cmp.unregister_method(name)
    assert name not in cmp.registered_methods()
    # the parametric polynomial is registered but not run by default
    assert "polynomial fit (parametric)" in cmp.registered_methods()
    assert "polynomial fit (parametric)" not in cmp.registered_methods(default_only=True)


def test_decorator_registration_and_extras() -> None:
    @cmp.register_method("with extras (test)", default=False)
    def _m(ctx):
        return cmp.MethodResult(ctx.reference, valid=False, note="hi", extras={"custom": 7})

    try:
        t = cmp.compare(
            _room(), (0.5, 0.5), (2.5, 2.3), robot_radius=0.15, methods=["with extras (test)"]
        )
        row = t.row("with extras (test)")
        assert row["custom"] == 7 and row["valid"] is False and row["note"] == "hi"
    finally:
        cmp.unregister_method("with extras (test)")


def test_bad_inputs() -> None:
    g = _room()
    with pytest.raises(InvalidInputError, match="outside the map"):
        cmp.compare(g, (-1.0, 0.5), (2.5, 2.3))
    with pytest.raises(InvalidInputError, match="blocked in the avoidance area"):
        cmp.compare(g, (0.1, 0.5), (2.5, 2.3), robot_radius=0.15)
    with pytest.raises(InvalidInputError, match="not registered"):
        cmp.compare(g, (0.5, 0.5), (2.5, 2.3), methods=["nope"])
    with pytest.raises(InvalidInputError, match="method"):
        cmp.compare(g, (0.5, 0.5), (2.5, 2.3), poly={"method": "ransac"})
    with pytest.raises(InvalidInputError, match="robot_radius"):
        cmp.compare(g, (0.5, 0.5), (2.5, 2.3), robot_radius=0.0)
    with pytest.raises(InvalidInputError, match="w_cells"):
        cmp.compare(g, (0.5, 0.5), (2.5, 2.3), w_cells=-2)
    walled = np.zeros((60, 60), bool)
    walled[:, 30] = True
    with pytest.raises(NoPathError):
        cmp.compare(OccupancyGrid(walled, 0.05), (0.5, 0.5), (2.5, 2.3), robot_radius=0.05)


# ------------------------------------------------------- Section 5: reproduction check
@pytest.fixture(scope="module")
def paper_results() -> dict:
    """Sweeps tuned on target A (Tables 1 and 2), reused unchanged for B, C and D."""
    sc = scenes.paper()
    avoid = avoidance_area(sc.grid, sc.w_cells, border=True)
    path_a = find_path(avoid, sc.start_cell, sc.goal_cell("A"))
    pts_a = sc.grid.cell_to_world(path_a.cells)
    poly_sweep = fits.sweep_polynomial(pts_a)
    bs_sweep = fits.sweep_bspline(pts_a)
    poly, bspline = poly_sweep[0].kwargs, bs_sweep[0].kwargs
    tables = {
        name: cmp.compare(
            sc.grid,
            sc.start,
            sc.goal(name),
            robot_radius=sc.robot_radius,
            w_cells=sc.w_cells,
            poly=poly,
            bspline=bspline,
        )
        for name in sc.target_names
    }
    return {"scene": sc, "poly": poly_sweep, "bspline": bs_sweep, "tables": tables}


def test_sweeps_have_the_tables_sizes(paper_results: dict) -> None:
    assert len(paper_results["poly"]) == 30
    bs = paper_results["bspline"]
    assert 480 <= len(bs) <= 520 and all(r.valid for r in bs)
    assert [r.mse for r in bs] == sorted(r.mse for r in bs)


def test_traditional_astar_runs_closer_than_the_robot_radius(paper_results: dict) -> None:
    r = paper_results["scene"].robot_radius
    for name, t in paper_results["tables"].items():
        raw = t.row("A*")
        assert raw["collision"] and raw["min_clearance_m"] < r, name


def test_avoidance_area_keeps_clear_but_has_heading_jumps(paper_results: dict) -> None:
    r = paper_results["scene"].robot_radius
    for name, t in paper_results["tables"].items():
        row = t.row("A* + avoidance area")
        assert not row["collision"] and row["min_clearance_m"] >= r, name
        assert row["max_heading_jump_rad"] >= np.pi / 4 - 1e-9, name  # 45-degree corners


def test_bspline_removes_heading_jumps_and_stays_close(paper_results: dict) -> None:
    sc = paper_results["scene"]
    cell = sc.grid.resolution
    for name, t in paper_results["tables"].items():
        bs, avoid = t.row("B-spline fit"), t.row("A* + avoidance area")
        assert bs["max_heading_jump_rad"] < 0.2 * avoid["max_heading_jump_rad"], name
        assert bs["mse_m2"] < (0.1 * cell) ** 2, name  # small MSE
        assert bs["hausdorff_m"] < cell, name  # within one cell of the A* path
        assert not bs["collision"], name
        assert abs(bs["length_ratio"] - 1.0) < 0.02, name


def test_polynomial_tuned_on_a_does_worse_elsewhere_especially_vertical(paper_results) -> None:
    rows = {n: t.row("polynomial fit") for n, t in paper_results["tables"].items()}
    bs = {n: t.row("B-spline fit") for n, t in paper_results["tables"].items()}
    assert rows["A"]["valid"]
    for name in ("B", "C", "D"):
        assert rows[name]["fit_mse_m2"] > rows["A"]["fit_mse_m2"], name
        assert rows[name]["hausdorff_m"] > rows["A"]["hausdorff_m"], name
    # the vertical target D: not a function of x, the worst fit, and it even collides
    d = rows["D"]
    assert not d["valid"] and "y = f(x)" in d["note"]
    assert d["fit_mse_m2"] == max(r["fit_mse_m2"] for r in rows.values())
    assert d["max_curvature_1pm"] == max(r["max_curvature_1pm"] for r in rows.values())
    assert d["length_ratio"] == max(r["length_ratio"] for r in rows.values())
    assert d["collision"]
    # and the B-spline fit beats the polynomial on every target
    for name in rows:
        assert bs[name]["fit_mse_m2"] < rows[name]["fit_mse_m2"], name
        assert bs[name]["hausdorff_m"] < rows[name]["hausdorff_m"], name


# ------------------------------------------------------ pose to pose (issue 33, part 5)
def test_proposed_with_headings_turns_in_place_and_holds_the_turn_limits() -> None:
    """The paper scene SP -> A facing away from A: the plan is a chain with turns in place."""
    from trajopt.analysis.metrics import trajectory_metrics, trajectory_path

    scene = scenes.paper()
    headings = {"start_heading": math.pi, "goal_heading": -math.pi / 2}
    table = cmp.compare(
        scene.grid,
        scene.start,
        scene.goal("A"),
        robot_radius=scene.robot_radius,
        w_cells=scene.w_cells,
        methods=["A*", "proposed"],
        options={"proposed": headings},
    )
    row = table.row("proposed")
    assert row["valid"] and not row["collision"], row["note"]
    # facing away from A (start heading pi, the path leaves towards +x): a turn of about pi
    turn = re.search(r"turns in place start ([+-][0-9.]+) rad", row["note"])
    assert turn is not None, row["note"]
    assert 3.0 <= abs(float(turn.group(1))) <= math.pi, row["note"]
    for key in ("ratio_v", "ratio_a", "ratio_omega", "ratio_turn_omega", "ratio_turn_alpha"):
        assert row[key] <= 1 + 1e-6, key
    assert row["ratio_turn_omega"] > 0.9  # a half turn reaches the turn's yaw-rate limit
    # the row scores the curve the chain drives; the turn columns are the proposed row's
    import trajopt

    chain = trajopt.Planner(scene.grid).plan(scene.start, scene.goal("A"), **headings)
    assert isinstance(chain, trajopt.TrajectoryChain)
    assert row["length_m"] == pytest.approx(trajectory_path(chain).length, rel=1e-9)
    assert row["duration_s"] == pytest.approx(trajectory_metrics(chain, chain.robot)["duration_s"])
    assert math.isnan(table.row("A*").get("ratio_turn_omega", math.nan))
    # an omni base turns its body while it drives: same columns, the turn in the note
    omni = trajopt.Robot(radius=scene.robot_radius, drive="omni")
    table = cmp.compare(
        scene.grid,
        scene.start,
        scene.goal("A"),
        robot_radius=scene.robot_radius,
        w_cells=scene.w_cells,
        methods=["proposed"],
        options={"proposed": {"robot": omni, **headings}},
    )
    row = table.row("proposed")
    assert row["valid"] and "orientation turned" in row["note"], row["note"]
    assert 0 < row["ratio_turn_omega"] <= 1 + 1e-6 and row["ratio_turn_alpha"] <= 1 + 1e-6
