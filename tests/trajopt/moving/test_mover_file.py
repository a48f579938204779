"""Tests of trajopt.moving's movers file (load_movers, save_movers) and ``trajopt plan --movers``.

The movers read from a hand-written file are checked against positions derived here from the
file's numbers (linear interpolation with ``np.interp``, ``p0 + v t``); the command line's
trajectory against the mover on its own 10 ms samples, and against the plan without the mover,
which must come too close (so the file is what keeps it away).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import astar
from trajopt.cli import main
from trajopt.errors import InvalidInputError
from trajopt.moving import MovingObstacle, load_movers, movers_from_data, save_movers

YAML = """
movers:
  - name: walker
    radius: 0.25
    growth: 0.05
    times: [0.0, 4.0, 9.0]
    positions: [[1.0, 2.0], [3.0, 2.0], [3.0, 5.0]]
  - name: cart
    radius: 0.05
    position: [6.0, 1.0]
    velocity: [-0.4, 0.3]
    horizon: 10.0
    vertices: [[-0.5, -0.3], [0.5, -0.3], [0.5, 0.3], [-0.5, 0.3]]
  - radius: 0.1
    times: [2.0]
    positions: [[0.5, 0.5]]
"""


def test_a_hand_written_yaml_file_predicts_what_it_says(tmp_path):
    path = tmp_path / "movers.yaml"
    path.write_text(YAML)
    walker, cart, still = load_movers(path)
    assert (walker.name, cart.name, still.name) == ("walker", "cart", "mover 2")
    for t in (0.0, 1.3, 4.0, 6.5, 9.0, 12.0):
        want = [np.interp(t, [0, 4, 9], [1, 3, 3]), np.interp(t, [0, 4, 9], [2, 2, 5])]
        np.testing.assert_allclose(walker.position_at(t), want, atol=1e-12)
        hold = min(t, 10.0)  # after its horizon the cart stays where it was
        np.testing.assert_allclose(cart.position_at(t), [6.0 - 0.4 * hold, 1.0 + 0.3 * hold])
        np.testing.assert_allclose(still.position_at(t), [0.5, 0.5])
    np.testing.assert_allclose(walker.radius_at(2.0), 0.25 + 0.05 * 2.0)
    assert walker.vertices is None and cart.vertices is not None
    assert cart.pose_at(3.0)[1] == pytest.approx(np.arctan2(0.3, -0.4))


@pytest.mark.parametrize("suffix", [".json", ".yaml", ".yml"])
def test_saved_movers_read_back_field_for_field(tmp_path, suffix):
    movers = [
        MovingObstacle.from_waypoints(
            [0.0, 1.5], [(0.1, 0.2), (1.0 / 3.0, 2.0)], radius=0.2, growth=0.01, name="a"
        ),
        MovingObstacle.constant_velocity(
            (1.0, 1.0), (0.2, 0.0), radius=0.0, horizon=3.0, heading=0.7,
            vertices=[(0, 0), (1, 0), (0, 1)], name="b",
        ),
    ]  # fmt: skip
    back = load_movers(save_movers(tmp_path / f"m{suffix}", movers))
    assert len(back) == 2
    for m, n in zip(movers, back, strict=True):
        assert (n.name, n.radius, n.growth) == (m.name, m.radius, m.growth)
        for field in ("times", "positions", "headings"):
            np.testing.assert_array_equal(getattr(n, field), getattr(m, field))
        if m.vertices is None:
            assert n.vertices is None
        else:
            np.testing.assert_array_equal(n.vertices, m.vertices)


@pytest.mark.parametrize(
    ("data", "words"),
    [
        ({"movers": [{"radius": 0.1, "times": [0], "positions": [[0, 0]], "speed": 1}]},
         ["mover 0", "unknown fields", "speed"]),
        ({"movers": [{"radius": 0.1, "times": [0], "positions": [[0, 0]], "velocity": [1, 0]}]},
         ["mover 0", "mixes"]),
        ({"movers": [{"radius": 0.1, "position": [0, 0], "velocity": [1, 0]}]},
         ["mover 0", "lacks", "horizon"]),
        ({"movers": [{"times": [0], "positions": [[0, 0]]}]}, ["lacks", "radius"]),
        ({"movers": [{"radius": "big", "times": [0], "positions": [[0, 0]]}]},
         ["radius", "number", "big"]),
        ({"movers": [{"radius": 0.1, "times": ["soon"], "positions": [[0, 0]]}]},
         ["mover 0", "numeric"]),
        ({"movers": [{"radius": -0.1, "times": [0], "positions": [[0, 0]], "name": "w"}]},
         ["'w'", "radius", "-0.1"]),
        ({"movers": [{"radius": 0.1, "times": [1, 0], "positions": [[0, 0], [1, 1]]}]},
         ["times", "increasing"]),
        ({"movers": {"radius": 0.1}}, ["must be a list"]),
        ({"obstacles": []}, ["unknown top-level keys", "obstacles"]),
        ([3], ["mover 0", "mapping"]),
    ],
)  # fmt: skip
def test_bad_entries_name_the_mover_and_the_field(data, words):
    with pytest.raises(InvalidInputError) as err:
        movers_from_data(data, source="f.yaml")
    for w in words:
        assert w in str(err.value), (w, str(err.value))


def test_bad_files_are_refused_with_their_path(tmp_path):
    with pytest.raises(InvalidInputError, match=r"\.json, \.yaml or \.yml"):
        load_movers(tmp_path / "movers.txt")
    with pytest.raises(InvalidInputError, match="cannot be read"):
        load_movers(tmp_path / "absent.json")
    broken = tmp_path / "broken.json"
    broken.write_text("{movers: [")
    with pytest.raises(InvalidInputError, match="does not parse"):
        load_movers(broken)


def _door_map(tmp_path):
    occ = np.zeros((40, 60), bool)
    occ[:, 30] = True
    occ[16:28, 30] = False  # a door 0.6 m wide at x = 1.5 m, y in [0.8, 1.4]
    return astar.save_map(astar.OccupancyGrid(occ, 0.05), tmp_path / "door.yaml")


def _closest(samples: dict, times, positions) -> float:
    """The least centre distance, on the samples, to a mover linear between waypoints."""
    t = np.asarray(samples["t"])
    mx = np.interp(t, times, [p[0] for p in positions])
    my = np.interp(t, times, [p[1] for p in positions])
    return float(np.min(np.hypot(np.asarray(samples["x"]) - mx, np.asarray(samples["y"]) - my)))


def test_plan_command_keeps_away_from_the_movers_of_the_file(tmp_path, capsys):
    """A porter stands in the only door until 6 s, then leaves: the robot waits for it."""
    times, positions = [0.0, 6.0, 9.0], [[1.5, 1.1], [1.5, 1.1], [2.5, 1.9]]
    movers = tmp_path / "movers.json"
    movers.write_text(
        json.dumps({"movers": [{"name": "porter", "radius": 0.1, "times": times,
                                "positions": positions}]})
    )  # fmt: skip
    plan = ["plan", str(_door_map(tmp_path)), "--start", "0.4", "0.3", "--goal", "2.6", "1.6",
            "--radius", "0.12", "--dt", "0.01"]  # fmt: skip
    limit = 0.12 + 0.1 + 0.02
    out = tmp_path / "with.json"
    assert main([*plan, "--movers", str(movers), "--mover-margin", "0.02", "--out", str(out)]) == 0
    assert "1 movers, route" in capsys.readouterr().out
    got = json.loads(out.read_text())
    assert got["samples"]["t"][-1] >= times[-1]  # it stands at the goal after the last time
    assert _closest(got["samples"], times, positions) >= limit - 1e-9
    plain = tmp_path / "plain.json"
    assert main([*plan, "--out", str(plain)]) == 0
    assert _closest(json.loads(plain.read_text())["samples"], times, positions) < limit


def test_plan_command_refuses_a_bad_movers_file_in_one_line(tmp_path, capsys):
    movers = tmp_path / "movers.yaml"
    movers.write_text("movers:\n  - radius: 0.1\n    times: [0]\n")
    argv = ["plan", str(_door_map(tmp_path)), "--start", "0.4", "0.3", "--goal", "2.6", "1.6",
            "--radius", "0.12", "--movers", str(movers)]  # fmt: skip
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert "mover 0 lacks the fields ['positions']" in err and "\n" not in err
