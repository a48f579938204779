"""Tests of trajopt.cli: the ``trajopt`` command line: outputs, one-line errors with exit code 2, atomic files."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

import astar
from trajopt.cli import main


@pytest.fixture()
def door_map(tmp_path):
    occ = np.zeros((40, 60), bool)
    occ[:, 30] = True
    occ[16:28, 30] = False
    grid = astar.OccupancyGrid(occ, 0.05)
    return astar.save_map(grid, tmp_path / "door.yaml")


def door_plan(door_map, *extra: str) -> list[str]:
    """The argv of ``trajopt plan`` on the door map, start to goal, radius 0.12 m, then ``extra``."""
    return [
        "plan",
        str(door_map),
        "--start",
        "0.4",
        "0.3",
        "--goal",
        "2.6",
        "1.6",
        "--radius",
        "0.12",
        *extra,
    ]


def test_plan_writes_csv_and_json(door_map, tmp_path, capsys):
    out = tmp_path / "traj.csv"
    rc = main(door_plan(door_map, "--out", str(out), "--dt", "0.05"))
    assert rc == 0
    # read as a user would, with no options: the first line is the header
    with open(out, newline="") as fh:
        reader = csv.DictReader(fh)
        header = list(reader.fieldnames or ())
        rows = list(reader)
    assert header[:3] == ["t [s]", "x [m] (map)", "y [m] (map)"]
    body = np.array([[float(r[h]) for h in header] for r in rows])
    assert body.shape == (len(rows), len(header)) and len(rows) > 2
    assert np.all(np.isfinite(body))
    t = body[:, 0]
    assert t[0] == 0.0 and np.all(np.diff(t) > 0)
    assert "duration" in capsys.readouterr().out
    js = tmp_path / "traj.json"
    assert main(door_plan(door_map, "--out", str(js))) == 0
    assert "duration" in json.loads(js.read_text())


def run(argv) -> int:
    """Exit code of ``trajopt argv`` whether it returns or raises SystemExit."""
    try:
        return main(argv)
    except SystemExit as exc:
        return int(exc.code)


@pytest.mark.parametrize(
    ("argv", "match"),
    [
        (["plan", "MISSING.yaml", "--start", "0", "0", "--goal", "1", "1"], "does not exist"),
        (["plan", "{map}", "--start", "1.52", "0.3", "--goal", "2.6", "1.6"], "occupied cell"),
        (["plan", "{map}", "--start", "0.4", "0.3", "--goal", "9", "9"], "outside the map"),
        (
            ["plan", "{map}", "--start", "0.4", "0.3", "--goal", "2.6", "1.6", "--v-max", "-1"],
            "v_max",
        ),
        (
            ["plan", "{map}", "--start", "0.4", "0.3", "--goal", "2.6", "1.6", "--out", "x.txt"],
            "--out must end in .csv, .json or .mcap",
        ),
        (["plan", "{map}", "--start", "0.4"], "expected 2 arguments"),
        (["bench", "run", "{map}", "--limit", "0", "--out", "o"], "--limit must be >= 1"),
        (["nonsense"], "invalid choice"),
        # issue 7: bad values reach the library's typed errors, still one line and exit 2
        (
            ["plan", "{map}", "--start", "nan", "0.3", "--goal", "2.6", "1.6"],
            "start must be finite",
        ),
        (["plan", "{map}", "--start", "0.4", "0.3", "--goal", "inf", "1.6"], "goal must be finite"),
        (
            ["plan", "{map}", "--start", "1.40", "0.3", "--goal", "2.6", "1.6"],
            "0.1 m from the nearest obstacle (or the map edge); the robot needs at least its "
            "radius 0.165 m",
        ),
        (
            ["plan", "{map}", "--start", "0.4", "0.3", "--goal", "2.6", "1.6", "--radius", "0"],
            "Robot.radius must be finite and > 0",
        ),
        (
            ["plan", "{map}", "--start", "0.4", "0.3", "--goal", "2.6", "1.6", "--v-max", "inf"],
            "Robot.v_max must be finite",
        ),
        (
            [
                "plan",
                "{map}",
                "--start",
                "0.4",
                "0.3",
                "--goal",
                "2.6",
                "1.6",
                "--resolution",
                "-1",
            ],
            "resolution must be finite and > 0",
        ),
        (
            ["plan", "{map}", "--start", "0.4", "0.3", "--goal", "2.6", "1.6", "--kappa-max", "-2"],
            "kappa_max",
        ),
        (
            ["plan", "{map}", "--start", "0.4", "0.3", "--goal", "2.6", "1.6", "--radius", "abc"],
            "invalid float value",
        ),
        (["plan", "{garbage}", "--start", "0", "0", "--goal", "1", "1"], "MapFormatError"),
        (
            ["compare", "{map}", "--start", "0.4", "0.3", "--goal", "2.6", "1.6", "--radius", "-1"],
            "robot_radius must be finite and > 0",
        ),
        (
            ["compare", "{map}", "--start", "nan", "0.3", "--goal", "2.6", "1.6"],
            "start must be finite",
        ),
        (["bench", "run", "{badscen}", "--out", "o"], "field start_y must be an integer >= 0"),
        (
            ["bench", "run", "{map}", "--chunk-size", "0", "--out", "o"],
            "chunk_size must be an integer >= 1",
        ),
        (
            ["bench", "run", "{map}", "--radius", "nan", "--out", "o"],
            "radius_m must be a finite number > 0",
        ),
        (["bench", "run", "{map}", "--methods", "rrt", "--out", "o"], "method 'rrt' is unknown"),
        (["bench", "run", "--out", "o"], "give INPUT files or --suite"),
        (["bench", "report", "missing"], "dataset 'missing' does not exist"),
    ],
)
def test_errors_are_one_line_exit_2(argv, match, door_map, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "garbage.map").write_bytes(b"\x00\xff\xfe garbage")
    (tmp_path / "bad.scen").write_text("version 1\n0\tx.map\t4\t4\t0\t-1\t1\t1\t1\n")
    subs = {"{map}": str(door_map), "{garbage}": "garbage.map", "{badscen}": "bad.scen"}
    argv = [subs.get(a, a) for a in argv]
    assert run(argv) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert match in err


def test_help_for_every_command(capsys):
    for cmd in ("plan", "compare", "demo", "bench", "bench run", "bench report"):
        with pytest.raises(SystemExit) as exc:
            main([*cmd.split(), "--help"])
        assert exc.value.code == 0
        assert "usage: trajopt " + cmd in capsys.readouterr().out


def test_failed_write_keeps_the_old_file(door_map, tmp_path):
    out = tmp_path / "traj.csv"
    out.write_text("good\n")
    rc = main(
        ["plan", str(door_map), "--start", "0.4", "0.3", "--goal", "9", "9", "--out", str(out)]
    )
    assert rc == 2
    assert out.read_text() == "good\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["door.pgm", "door.yaml", "traj.csv"]


def test_compare_markdown(door_map, capsys):
    rc = main(
        [
            "compare",
            str(door_map),
            "--start",
            "0.4",
            "0.3",
            "--goal",
            "2.6",
            "1.6",
            "--radius",
            "0.12",
            "--format",
            "markdown",
        ]
    )
    assert rc == 0
    out = capsys.readouterr().out
    assert out.count("|") > 20 and "proposed" in out


def test_plan_on_a_costmap_with_a_speed_mask_to_mcap(tmp_path, capsys):
    from PIL import Image

    from trajopt.motion._mcap import read_mcap

    # a 3 x 2 m room at 5 cm with a wall stub; costmap in raw mode (OccupancyGrid values)
    og = np.zeros((40, 60), np.int64)
    og[:, 0] = og[:, -1] = og[0, :] = og[-1, :] = 100
    og[:25, 30] = 100
    og[:28, 28:33] = np.maximum(og[:28, 28:33], 60)  # graded cost around the stub
    Image.fromarray(og.astype(np.uint8)[::-1], mode="L").save(tmp_path / "cm.pgm")
    (tmp_path / "cm.yaml").write_text(
        "image: cm.pgm\nmode: raw\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\n"
        "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.25\n"
    )
    mask = np.zeros((40, 60), np.uint8)
    mask[:, 40:] = 50  # 50 % of v_max for x >= 2 m (scale mode: grey 50 % -> value 50)
    Image.fromarray(np.rint(255 * (1 - mask / 100)).astype(np.uint8)[::-1], mode="L").save(
        tmp_path / "mask.pgm"
    )
    (tmp_path / "mask.yaml").write_text(
        "image: mask.pgm\nmode: scale\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\n"
        "negate: 0\noccupied_thresh: 1.0\nfree_thresh: 0.0\n"
    )
    out = tmp_path / "traj.mcap"
    rc = main(
        [
            "plan",
            str(tmp_path / "cm.yaml"),
            "--costmap",
            "--start",
            "0.5",
            "0.5",
            "--goal",
            "2.6",
            "0.5",
            "--radius",
            "0.12",
            "--speed-mask",
            str(tmp_path / "mask.yaml"),
            "--out",
            str(out),
            "--dt",
            "0.01",
        ]
    )
    assert rc == 0, capsys.readouterr().err
    back = read_mcap(out)
    zone = back.x >= 2.0 + 1e-9
    assert zone.any() and np.all(back.v[zone] <= 0.5 * 0.5 + 1e-9)
    assert back.v[~zone].max() > 0.3
    assert back.y.max() > 25 * 0.05  # around the stub, not through it


# ------------------------------------------------------------ footprints (issue 18, item 6)
PLAN = ["--start", "0.4", "0.3", "--goal", "2.6", "1.6"]


def _figures(monkeypatch) -> list:
    """Record the figures the CLI saves (then save them as usual)."""
    import trajopt.cli._plan as plan_commands

    saved, original = [], plan_commands.save_figure

    def record(fig, path):
        saved.append(fig)
        return original(fig, path)

    monkeypatch.setattr(plan_commands, "save_figure", record)
    return saved


def test_plan_with_a_rectangle_footprint_writes_it_and_plots_it(
    door_map, tmp_path, capsys, monkeypatch
):
    from matplotlib.patches import Polygon

    saved = _figures(monkeypatch)
    out, fig = tmp_path / "traj.json", tmp_path / "fig.png"
    # 0.2 x 0.12 m, rotation centre 0.05 m ahead of the rear edge: circumscribed radius
    # hypot(0.15, 0.06) = 0.1616 m, below the 0.3 m clearance of start and goal
    rc = main(
        [
            "plan",
            str(door_map),
            *PLAN,
            "--footprint",
            "0.2",
            "0.12",
            "0.05",
            "--out",
            str(out),
            "--plot",
            str(fig),
        ]
    )
    assert rc == 0, capsys.readouterr().err
    robot = json.loads(out.read_text())["robot"]
    np.testing.assert_allclose(
        robot["footprint"], [[-0.05, -0.06], [0.15, -0.06], [0.15, 0.06], [-0.05, 0.06]]
    )
    assert robot["radius"] == pytest.approx(np.hypot(0.15, 0.06))
    assert fig.stat().st_size > 0
    (ax,) = saved[0].axes
    outlines = [p for p in ax.patches if isinstance(p, Polygon) and len(p.get_xy()) == 5]
    assert 5 <= len(outlines) <= 40  # closed quadrilaterals: 4 corners + the first again
    assert "footprint" in [t.get_text() for t in ax.get_legend().get_texts()]


def test_plan_footprint_files(door_map, tmp_path, capsys):
    square = [[-0.08, -0.08], [0.08, -0.08], [0.08, 0.08], [-0.08, 0.08]]
    files = {
        "list.json": json.dumps(square),
        "object.json": json.dumps({"vertices": square[::-1]}),  # clockwise is fine
        "rows.csv": "# a square\nx, y\n" + "".join(f"{x}, {y}\n" for x, y in square),
        "rows.txt": "\n".join(f"{x} {y}" for x, y in square) + "\n\n",
    }
    for name, text in files.items():
        (tmp_path / name).write_text(text)
        out = tmp_path / f"{name}.json"
        rc = main(
            [
                "plan",
                str(door_map),
                *PLAN,
                "--footprint-file",
                str(tmp_path / name),
                "--out",
                str(out),
            ]
        )
        assert rc == 0, (name, capsys.readouterr().err)
        robot = json.loads(out.read_text())["robot"]
        assert len(robot["footprint"]) == 4
        assert robot["radius"] == pytest.approx(0.08 * np.sqrt(2)), name


def test_compare_takes_the_footprint_circumscribed_radius(door_map, capsys, monkeypatch):
    import trajopt.analysis.comparison

    seen = {}
    real = trajopt.comparison.compare

    def spy(*args, **kwargs):
        seen.update(kwargs)
        return real(*args, **kwargs)

    monkeypatch.setattr(trajopt.comparison, "compare", spy)
    rc = main(["compare", str(door_map), *PLAN, "--footprint", "0.2", "0.12"])
    assert rc == 0, capsys.readouterr().err
    assert seen["robot_radius"] == pytest.approx(np.hypot(0.1, 0.06))


@pytest.mark.parametrize(
    ("extra", "files", "match"),
    [
        (["--footprint", "0.2"], {}, "--footprint: expected 2 or 3 numbers"),
        (["--footprint", "0.2", "0.1", "0.05", "0.3"], {}, "expected 2 or 3 numbers"),
        (["--footprint", "0.2", "0.1", "0.3"], {}, "--footprint 0.2 0.1 0.3: rear_offset"),
        (["--footprint", "0.2", "-0.1"], {}, "--footprint 0.2 -0.1: width must be finite"),
        (
            ["--radius", "0.1", "--footprint", "0.2", "0.1"],
            {},
            "argument --footprint: not allowed with argument --radius",
        ),
        (
            ["--footprint", "0.2", "0.1", "--footprint-file", "fp.json"],
            {},
            "not allowed with argument --footprint",
        ),
        (
            ["--footprint-file", "missing.json"],
            {},
            "--footprint-file 'missing.json' does not exist",
        ),
        (
            ["--footprint-file", "star.json"],
            {"star.json": "[[0.2, 0], [0.02, 0.02], [0, 0.2], [-0.2, 0], [0, -0.2]]"},
            "--footprint-file 'star.json': footprint must be a convex polygon",
        ),
        (
            ["--footprint-file", "out.csv"],
            {"out.csv": "0.1,0.1\n0.2,0.1\n0.2,0.2\n"},
            "must contain the rotation centre (0, 0) strictly inside",
        ),
        (
            ["--footprint-file", "bad.json"],
            {"bad.json": '{"corners": [[0, 1]]}'},
            "--footprint-file 'bad.json' has no key 'vertices'",
        ),
        (
            ["--footprint-file", "bad.json"],
            {"bad.json": "[[0.1, 0.1, 0], [1, 2]]"},
            "--footprint-file 'bad.json' must hold a JSON list of [x, y] vertices",
        ),
        (
            ["--footprint-file", "bad.json"],
            {"bad.json": "[[0.1, 0.1],"},
            "--footprint-file 'bad.json' is not valid JSON",
        ),
        (
            ["--footprint-file", "bad.csv"],
            {"bad.csv": "x,y\n0.1,0.1\n0.1;oops\n"},
            "--footprint-file 'bad.csv' line 3: '0.1;oops' is not rows of two numbers",
        ),
        (
            ["--footprint-file", "bad.csv"],
            {"bad.csv": "-0.1 -0.1 0\n0.1 -0.1\n0 0.1\n"},
            "line 1: '-0.1 -0.1 0' is not rows of two numbers 'x, y' (m)",
        ),
    ],
)
def test_bad_footprints_are_one_line_exit_2(
    extra, files, match, door_map, tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(tmp_path)
    for name, text in files.items():
        (tmp_path / name).write_text(text)
    for cmd in ("plan", "compare"):
        assert run([cmd, str(door_map), *PLAN, *extra]) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1, err
        assert match in err, err


# ------------------------------------------------- drives and end headings (issue 33, part 5)
def _wrapped(a):
    return np.remainder(np.asarray(a, dtype=float) + np.pi, 2.0 * np.pi) - np.pi


def test_plan_honours_the_headings_in_every_written_file(door_map, tmp_path, capsys, monkeypatch):
    """Start facing away from the goal: the plan turns in place, every file ends exactly."""
    import pandas as pd
    from matplotlib.quiver import Quiver

    from trajopt.motion._mcap import read_mcap

    saved = _figures(monkeypatch)
    h0, h1 = 3.0, -1.5
    head = ["--radius", "0.12", "--start-heading", str(h0), "--goal-heading", str(h1)]
    csv_out, fig = tmp_path / "traj.csv", tmp_path / "fig.png"
    rc = main(["plan", str(door_map), *PLAN, *head, "--out", str(csv_out), "--plot", str(fig)])
    assert rc == 0, capsys.readouterr().err
    line = capsys.readouterr().out.splitlines()[0]
    assert "turned in place at the start" in line and "goal" in line, line
    df = pd.read_csv(csv_out)
    theta = df["theta [rad] (map)"].to_numpy()
    assert abs(_wrapped(theta[0] - h0)) <= 1e-9 and abs(_wrapped(theta[-1] - h1)) <= 1e-9
    still = df["v [m/s]"].to_numpy() == 0.0
    assert still[:3].all() and still[-3:].all()  # the turns: standing while the heading moves
    assert np.abs(df["omega [rad/s]"].to_numpy()[still]).max() > 0.1
    assert df["x [m] (map)"].iloc[0] == pytest.approx(0.4) and df["y [m] (map)"].iloc[-1] == (
        pytest.approx(1.6)
    )
    # JSON and MCAP of the same chain
    js, mc = tmp_path / "traj.json", tmp_path / "traj.mcap"
    for out in (js, mc):
        assert main(["plan", str(door_map), *PLAN, *head, "--out", str(out)]) == 0
    data = json.loads(js.read_text())
    assert data["format"] == "trajopt.TrajectoryChain"
    th = data["samples"]["theta"]
    assert abs(_wrapped(th[0] - h0)) <= 1e-9 and abs(_wrapped(th[-1] - h1)) <= 1e-9
    assert [p["type"] for p in data["pieces"]] == ["TurnInPlace", "Trajectory", "TurnInPlace"]
    back = read_mcap(mc)
    assert abs(_wrapped(back.theta[0] - h0)) <= 1e-6 and abs(_wrapped(back.theta[-1] - h1)) <= 1e-6
    # the figure: heading arrows along the trajectory and the two turns marked
    (ax,) = saved[0].axes
    assert any(isinstance(c, Quiver) for c in ax.collections)
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "turn in place" in labels


def test_plan_heading_without_a_turn_says_so(door_map, capsys):
    # the free curve leaves and arrives close to these: the curve takes them, no turn
    rc = main(
        [
            "plan",
            str(door_map),
            *PLAN,
            "--radius",
            "0.12",
            "--start-heading",
            "0.5",
            "--goal-heading",
            "0.9",
        ]
    )
    assert rc == 0, capsys.readouterr().err
    out = capsys.readouterr().out
    assert "turned in place" in out or "end headings met by the curve, no turn in place" in out
    from trajopt.cli._plan import _turn_note

    assert _turn_note({}) == ""  # no heading asked: nothing said
    assert _turn_note({"pose": {"turn_start_rad": 0.0, "turn_goal_rad": 0.0}}) == (
        "; end headings met by the curve, no turn in place"
    )
    assert _turn_note({"pose": {"turn_start_rad": 0.0, "turn_goal_rad": -1.25}}) == (
        "; turned in place at the goal -1.250 rad"
    )
    # an omni base turns its body while it drives (trajopt.timing.orient's statistics)
    assert _turn_note({"orientation": {"turn_rad": 1.5, "hold_s": 0.0}}) == (
        "; orientation turned +1.500 rad while driving"
    )
    assert _turn_note({"orientation": {"turn_rad": -3.0, "hold_s": 0.25}}) == (
        "; orientation turned -3.000 rad while driving and 0.250 s standing at the goal"
    )


@pytest.mark.parametrize(
    ("extra", "match"),
    [
        (["--start-heading", "nan"], "argument --start-heading: the angle must be finite (rad)"),
        (["--goal-heading", "inf"], "argument --goal-heading: the angle must be finite (rad)"),
        (["--goal-heading=-inf"], "the angle must be finite (rad), got '-inf'"),
        (["--start-heading", "north"], "expected an angle in radians, got 'north'"),
        (
            ["--drive", "ackermann"],
            "InvalidInputError: Robot.min_turning_radius is required with drive='ackermann'",
        ),
        (
            ["--drive", "tank"],
            "Robot.drive must be one of ('differential', 'omni', 'ackermann'), got 'tank'",
        ),
    ],
)
def test_bad_heading_or_drive_is_one_line_exit_2(extra, match, door_map, capsys):
    assert run(["plan", str(door_map), *PLAN, *extra]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert match in err, err


def test_drive_reaches_the_robot(door_map, tmp_path, capsys, monkeypatch):
    import trajopt._planner

    seen = []
    real = trajopt._planner.Planner

    class Spy(real):
        def __init__(self, grid, robot=None, **kwargs):
            seen.append(robot)
            super().__init__(grid, robot, **kwargs)

    monkeypatch.setattr(trajopt._planner, "Planner", Spy)
    monkeypatch.setattr(trajopt, "Planner", Spy)  # the command takes it from the face
    out = tmp_path / "omni.json"
    rc = main(
        ["plan", str(door_map), *PLAN, "--radius", "0.12", "--drive", "omni", "--out", str(out)]
    )
    assert rc == 0, capsys.readouterr().err
    assert seen[-1].drive == trajopt.Omni() and seen[-1].radius == 0.12
    assert json.loads(out.read_text())["robot"]["drive"] == "omni"
    assert "omni drive" in capsys.readouterr().out
    # with headings: the orientation turns while driving and ends exactly at the goal's
    import pandas as pd

    csv_out = tmp_path / "omni.csv"
    rc = main(
        [
            "plan",
            str(door_map),
            *PLAN,
            "--radius",
            "0.12",
            "--drive",
            "omni",
            "--start-heading",
            "3",
            "--goal-heading",
            "-1.5",
            "--out",
            str(csv_out),
        ]
    )
    assert rc == 0, capsys.readouterr().err
    assert "omni drive" in (line := capsys.readouterr().out) and "orientation turned" in line
    df = pd.read_csv(csv_out)
    theta = df["theta [rad] (map)"].to_numpy()
    assert abs(_wrapped(theta[0] - 3.0)) <= 1e-9 and abs(_wrapped(theta[-1] + 1.5)) <= 1e-9
    assert "course [rad] (map)" in df.columns and "v_body_y [m/s]" in df.columns
    assert main(["plan", str(door_map), *PLAN, "--radius", "0.12"]) == 0
    assert seen[-1].drive == trajopt.Differential()  # the default
    with pytest.raises(SystemExit):
        main(["plan", "--help"])
    help_text = capsys.readouterr().out
    for opt in (
        "--drive {differential,omni,ackermann}",
        "--start-heading RAD",
        "--goal-heading RAD",
    ):
        assert opt in help_text


def test_ros_is_handed_to_the_nodes_command_line(capsys):
    # `trajopt ros ...` is trajopt-ros's own parser (its --ros-args are not argparse's)
    with pytest.raises(SystemExit) as info:
        main(["ros", "--help"])
    assert info.value.code == 0
    assert "usage: trajopt-ros" in capsys.readouterr().out
