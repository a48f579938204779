"""Tests of astar.io: map formats, scenarios, round trips and bad input.

References are independent of the code under test: Moving AI maps are re-read character by
character, ROS PGMs are decoded from their raw bytes with the YAML thresholds, map_server's
pixel rule is re-derived per grey value, and known cells were picked by hand from the files.
"""

from __future__ import annotations

import io
import math
import os
import re
import time
import tracemalloc
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from PIL import Image

from astar import (
    InvalidInputError,
    MapFormatError,
    OccupancyGrid,
    Scenario,
    from_intensity,
    load_map,
    read_scenarios,
    save_map,
)

MOVINGAI = [
    "arena",
    "den312d",
    "rmtst01",
    "Berlin_0_256",
    "maze512-1-0",
    "random512-40-5",
    "Boston_0_1024",
]
ROS = ["depot", "smoothers_world", "turtlebot3_world", "willow-2010-02-18-0.10"]

# Known cells picked by hand from the files: (x = column, y = row from the top, character)
MOVINGAI_KNOWN = {
    "arena": [(0, 0, "T"), (19, 1, ".")],
    "den312d": [(0, 0, "T"), (5, 2, ".")],
    "rmtst01": [(0, 1, "T"), (0, 0, "@"), (1, 2, ".")],
    "Berlin_0_256": [(62, 2, "@"), (0, 0, ".")],
    "maze512-1-0": [(0, 0, "@"), (1, 1, ".")],
    "random512-40-5": [(0, 0, "T"), (3, 0, "@"), (39, 0, ".")],
    "Boston_0_1024": [(87, 0, "@"), (0, 0, ".")],
}
# (column, row from the top, raw grey value, state): black 0 is occupied, 254/255 free; grey
# 205 has occ = 1 - 205/255 = 0.196: unknown with free_thresh 0.196, but *free* in depot.yaml,
# whose free_thresh is 0.25 (map_server semantics, faithfully reproduced)
ROS_KNOWN = {
    "depot": [(603, 192, 0, "occ"), (124, 147, 254, "free"), (0, 0, 205, "free")],
    "smoothers_world": [(163, 135, 0, "occ"), (286, 152, 255, "free"), (0, 0, 0, "occ")],
    "turtlebot3_world": [(180, 184, 0, "occ"), (242, 183, 254, "free"), (0, 0, 205, "unk")],
    "willow-2010-02-18-0.10": [(269, 476, 0, "occ"), (86, 333, 254, "free"), (0, 0, 205, "unk")],
}


# ---------------------------------------------------------------- independent readers
def _movingai_text(path: Path) -> tuple[int, int, list[str]]:
    """(height, width, rows top first) read with plain string handling."""
    lines = path.read_text().splitlines()
    height = int(re.fullmatch(r"height (\d+)", lines[1].strip()).group(1))
    width = int(re.fullmatch(r"width (\d+)", lines[2].strip()).group(1))
    assert lines[0].strip() == "type octile" and lines[3].strip() == "map"
    return height, width, lines[4 : 4 + height]


def _pgm_pixels(path: Path) -> np.ndarray:
    """Decode a binary 8-bit PGM (P5) from its bytes, top row first."""
    data = path.read_bytes()
    m = re.match(rb"P5(?:\s|#[^\n]*\n)+(\d+)(?:\s|#[^\n]*\n)+(\d+)(?:\s|#[^\n]*\n)+(\d+)\s", data)
    w, h, maxval = (int(g) for g in m.groups())
    assert maxval == 255
    return np.frombuffer(data, np.uint8, count=w * h, offset=m.end()).reshape(h, w)


def _ros_reference(yaml_path: Path) -> tuple[dict, np.ndarray, np.ndarray]:
    """(yaml dict, occupied-if-unknown-occupied, occupied-if-unknown-free), bottom row 0."""
    meta = yaml.safe_load(yaml_path.read_text())
    assert meta.get("mode", "trinary") == "trinary" and meta["negate"] == 0
    v = _pgm_pixels(yaml_path.parent / meta["image"]).astype(float)
    occ = 1.0 - v / 255.0
    occupied = occ > meta["occupied_thresh"]
    free = occ < meta["free_thresh"]
    return meta, ~free[::-1], occupied[::-1]


@pytest.fixture(scope="module")
def boston(shared_data: Path) -> OccupancyGrid:
    return load_map(shared_data / "movingai" / "maps" / "Boston_0_1024.map")


def _load_movingai(shared_data: Path, name: str, boston_fixture) -> OccupancyGrid:
    if name == "Boston_0_1024":
        return boston_fixture
    return load_map(shared_data / "movingai" / "maps" / f"{name}.map")


# ---------------------------------------------------------------- Moving AI maps
@pytest.mark.parametrize("name", MOVINGAI)
def test_movingai_shape_counts_and_cells(shared_data: Path, request, name: str) -> None:
    path = shared_data / "movingai" / "maps" / f"{name}.map"
    boston_fixture = request.getfixturevalue("boston") if name == "Boston_0_1024" else None
    grid = _load_movingai(shared_data, name, boston_fixture)
    h, w, rows = _movingai_text(path)
    assert grid.shape == (h, w)
    assert grid.resolution == 1.0 and grid.origin == (0.0, 0.0)
    assert not grid.occupied.flags.writeable
    n_free = sum(row.count(".") + row.count("G") + row.count("S") for row in rows)
    assert int(grid.free.sum()) == n_free
    # whole grid against a character-by-character reference, flipped (row 0 = bottom)
    codes = np.frombuffer("".join(rows).encode("ascii"), np.uint8).reshape(h, w)
    blocked = np.isin(codes, [ord(c) for c in "@OTW"])
    assert np.array_equal(grid.occupied, blocked[::-1])
    for x, y, ch in MOVINGAI_KNOWN[name]:
        assert rows[y][x] == ch  # the hand-picked cell is what the file says
        cell = (x, h - 1 - y)
        assert grid.is_free(cell) == (ch in ".GS")


def test_movingai_terrain_letters_and_crlf(tmp_path: Path) -> None:
    text = "type octile\r\nheight 2\r\nwidth 8\r\nmap\r\n.GS@OTW.\r\n@.......\r\n"
    path = tmp_path / "t.map"
    path.write_bytes(text.encode())
    grid = load_map(path, resolution=0.5, origin=(1.0, 2.0))
    # bottom row (iy = 0) is the last line of the file
    assert grid.occupied[0].tolist() == [True] + [False] * 7
    assert grid.occupied[1].tolist() == [False, False, False, True, True, True, True, False]
    assert grid.resolution == 0.5 and grid.origin == (1.0, 2.0)
    # header keys in the other order, LF endings, no trailing newline
    path.write_text("type octile\nwidth 2\nheight 1\nmap\n.@")
    assert load_map(path).occupied.tolist() == [[False, True]]


# ---------------------------------------------------------------- ROS maps
@pytest.mark.parametrize("name", ROS)
def test_ros_maps_match_map_server_rule(shared_data: Path, name: str) -> None:
    yaml_path = shared_data / "ros" / f"{name}.yaml"
    meta, ref_unknown_occ, ref_unknown_free = _ros_reference(yaml_path)
    grid = load_map(yaml_path)
    assert grid.resolution == float(meta["resolution"])
    assert grid.origin == (float(meta["origin"][0]), float(meta["origin"][1]))
    assert grid.shape == ref_unknown_occ.shape
    assert np.array_equal(grid.occupied, ref_unknown_occ)
    grid_free = load_map(yaml_path, unknown_occupied=False)
    assert np.array_equal(grid_free.occupied, ref_unknown_free)
    assert int(grid_free.free.sum()) >= int(grid.free.sum())
    ny = grid.ny
    pixels = _pgm_pixels(yaml_path.parent / meta["image"])
    for col, row, value, state in ROS_KNOWN[name]:
        assert pixels[row, col] == value
        cell = (col, ny - 1 - row)
        assert grid.is_free(cell) == (state == "free")
        assert grid_free.is_free(cell) == (state != "occ")


def test_ros_world_coordinates(shared_data: Path) -> None:
    grid = load_map(shared_data / "ros" / "turtlebot3_world.yaml")
    # pixel (col 180, row 184) is black; origin (-10, -10), 0.05 m cells, 384 rows
    x = -10.0 + (180 + 0.5) * 0.05
    y = -10.0 + (384 - 1 - 184 + 0.5) * 0.05
    assert grid.world_to_cell((x, y)).tolist() == [180, 199]
    assert grid.occupied[199, 180]


def test_ros_free_counts_by_hand(shared_data: Path) -> None:
    # depot.pgm holds only 0, 205 and 254 (checked below); with free_thresh 0.25 both 254
    # (occ 0.004) and 205 (occ 0.196) are free, 0 (occ 1) is occupied: no unknown cells
    pixels = _pgm_pixels(shared_data / "ros" / "depot.pgm")
    assert set(np.unique(pixels).tolist()) == {0, 205, 254}
    for unknown_occupied in (True, False):
        grid = load_map(shared_data / "ros" / "depot.yaml", unknown_occupied=unknown_occupied)
        assert int(grid.occupied.sum()) == int((pixels == 0).sum())
    # turtlebot3_world.pgm: 0, 205, 254 with free_thresh 0.196: 205 is unknown
    pixels = _pgm_pixels(shared_data / "ros" / "turtlebot3_world.pgm")
    assert set(np.unique(pixels).tolist()) == {0, 205, 254}
    grid = load_map(shared_data / "ros" / "turtlebot3_world.yaml")
    assert int(grid.free.sum()) == int((pixels == 254).sum())
    grid = load_map(shared_data / "ros" / "turtlebot3_world.yaml", unknown_occupied=False)
    assert int(grid.occupied.sum()) == int((pixels == 0).sum())


@pytest.mark.parametrize("name", ["smoothers_world", "turtlebot3_world", "willow-2010-02-18-0.10"])
def test_plain_image_equals_ros_default_thresholds(shared_data: Path, name: str) -> None:
    # these YAMLs use negate 0, 0.65 / 0.196: the documented rule for plain images
    via_yaml = load_map(shared_data / "ros" / f"{name}.yaml")
    direct = load_map(
        shared_data / "ros" / f"{name}.pgm", resolution=via_yaml.resolution, origin=via_yaml.origin
    )
    assert direct == via_yaml


# ------------------------------------------------- map_server pixel semantics (synthetic)
_DROP = object()  # marks a key to leave out of the YAML


def _write_yaml(folder: Path, image_name: str, **overrides) -> Path:
    meta = {
        "image": image_name,
        "resolution": 0.1,
        "origin": [0.0, 0.0, 0.0],
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,
    }
    meta.update(overrides)
    meta = {k: v for k, v in meta.items() if v is not _DROP}
    path = folder / "m.yaml"
    path.write_text(yaml.safe_dump(meta))
    return path


def _ramp_pgm(folder: Path) -> Path:
    """A 1 x 256 grey ramp 0..255 (column = grey value)."""
    path = folder / "ramp.pgm"
    path.write_bytes(b"P5\n256 1\n255\n" + bytes(range(256)))
    return path


def test_trinary_boundaries_by_hand(tmp_path: Path) -> None:
    _ramp_pgm(tmp_path)
    y = _write_yaml(tmp_path, "ramp.pgm")
    occ = load_map(y).occupied[0]
    occ_known = load_map(y, unknown_occupied=False).occupied[0]
    # 1 - v/255 > 0.65  <=>  v < 89.25;   1 - v/255 < 0.196  <=>  v > 205.02
    assert occ_known.tolist() == [v <= 89 for v in range(256)]
    assert occ.tolist() == [v <= 205 for v in range(256)]
    # negate: occ = v/255 -> occupied when v > 165.75, free when v < 49.98
    y = _write_yaml(tmp_path, "ramp.pgm", negate=1)
    assert load_map(y, unknown_occupied=False).occupied[0].tolist() == [
        v >= 166 for v in range(256)
    ]
    assert load_map(y).occupied[0].tolist() == [v >= 50 for v in range(256)]
    # negate as a YAML bool means the same
    y = _write_yaml(tmp_path, "ramp.pgm", negate=True)
    assert load_map(y).occupied[0].tolist() == [v >= 50 for v in range(256)]


def test_scale_mode_opaque_and_alpha(tmp_path: Path) -> None:
    _ramp_pgm(tmp_path)
    y = _write_yaml(tmp_path, "ramp.pgm", mode="scale", free_thresh=0.25)
    # opaque, occ = 1 - v/255: occupied if occ > 0.65 (v <= 89), free if occ < 0.25
    # (v >= 192); in between the cost rint(100 (occ - 0.25) / 0.4) is 0 (free) when
    # occ < 0.252 (v >= 191) and never 100 (that needs occ > 0.648, v <= 89), so
    # 90..190 keep a cost of 1..99 and count as unknown
    assert load_map(y, unknown_occupied=False).occupied[0].tolist() == [v <= 89 for v in range(256)]
    assert load_map(y).occupied[0].tolist() == [v <= 190 for v in range(256)]
    # alpha: any pixel that is not fully opaque is unknown in scale mode
    rgba = np.zeros((1, 4, 4), np.uint8)
    rgba[0, :, :3] = [[0, 0, 0], [255, 255, 255], [255, 255, 255], [0, 0, 0]]
    rgba[0, :, 3] = [255, 255, 254, 0]
    Image.fromarray(rgba, "RGBA").save(tmp_path / "a.png")
    y = _write_yaml(tmp_path, "a.png", mode="scale")
    assert load_map(y, unknown_occupied=False).occupied[0].tolist() == [True, False, False, False]
    assert load_map(y).occupied[0].tolist() == [True, False, True, True]


def test_trinary_averages_alpha_like_map_server(tmp_path: Path) -> None:
    # map_server averages (R, G, B, alpha) in trinary mode; shade = (3g + a) / 4 / 255
    cases = [(0, 255), (0, 0), (255, 0), (255, 255), (100, 255), (200, 200)]
    la = np.array([[[g, a] for g, a in cases]], np.uint8)
    Image.fromarray(la, "LA").save(tmp_path / "la.png")
    y = _write_yaml(tmp_path, "la.png")
    got = load_map(y, unknown_occupied=False).occupied[0].tolist()
    expected = [1.0 - (3 * g + a) / 4.0 / 255.0 > 0.65 for g, a in cases]
    assert got == expected == [True, True, False, False, False, False]
    got_free = (~load_map(y).occupied[0]).tolist()
    assert got_free == [1.0 - (3 * g + a) / 4.0 / 255.0 < 0.196 for g, a in cases]


def test_raw_mode(tmp_path: Path) -> None:
    _ramp_pgm(tmp_path)
    y = _write_yaml(tmp_path, "ramp.pgm", mode="raw", negate=1)
    # raw: value = grey (negate ignored); 0..100 percent, > 100 unknown
    occ_known = load_map(y, unknown_occupied=False).occupied[0].tolist()
    assert occ_known == [66 <= v <= 100 for v in range(256)]
    occ = load_map(y).occupied[0].tolist()
    assert occ == [v >= 20 for v in range(256)]


def test_rgb_image_mean_of_channels(tmp_path: Path) -> None:
    rgb = np.array([[[255, 255, 0], [255, 255, 255], [60, 60, 60]]], np.uint8)
    Image.fromarray(rgb, "RGB").save(tmp_path / "c.png")
    grid = load_map(tmp_path / "c.png", resolution=1.0)
    # means 170 (unknown -> occupied), 255 (free), 60 (occupied)
    assert grid.occupied[0].tolist() == [True, False, True]


def test_palette_and_sixteen_bit_png(tmp_path: Path) -> None:
    grey = np.array([[0, 255, 120]], np.uint8)
    Image.fromarray(grey).convert("P").save(tmp_path / "p.png")
    assert load_map(tmp_path / "p.png", resolution=1.0).occupied[0].tolist() == [True, False, True]
    Image.fromarray(np.array([[0, 65535, 60000]], np.uint16)).save(tmp_path / "w.png")
    # 60000 / 65535 = 0.9155 -> occ = 0.0845 < 0.196: free
    got = load_map(tmp_path / "w.png", resolution=1.0).occupied[0].tolist()
    assert got == [True, False, False]


def test_sixteen_bit_pgm(tmp_path: Path) -> None:
    data = np.array([[0, 65535, 30000]], ">u2").tobytes()
    (tmp_path / "w.pgm").write_bytes(b"P5\n3 1\n65535\n" + data)
    grid = load_map(tmp_path / "w.pgm", resolution=0.1)
    assert grid.occupied[0].tolist() == [True, False, True]


def test_image_rows_flipped_and_resolution_required(tmp_path: Path) -> None:
    img = np.full((3, 2), 255, np.uint8)
    img[0, 0] = 0  # top-left pixel black
    Image.fromarray(img).save(tmp_path / "f.png")
    Image.fromarray(img).save(tmp_path / "f.bmp")
    for name in ("f.png", "f.bmp"):
        grid = load_map(tmp_path / name, resolution=0.25)
        assert grid.shape == (3, 2)
        assert grid.occupied[2, 0] and int(grid.occupied.sum()) == 1
    with pytest.raises(InvalidInputError, match="resolution"):
        load_map(tmp_path / "f.png")


def test_yaml_image_relative_and_absolute(tmp_path: Path) -> None:
    sub = tmp_path / "maps"
    sub.mkdir()
    _ramp_pgm(sub)
    (tmp_path / "m.yaml").write_text(
        "image: maps/ramp.pgm\nresolution: 0.1\norigin: [1.5, -2, 0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    g1 = load_map(tmp_path / "m.yaml")
    assert g1.origin == (1.5, -2.0) and g1.shape == (1, 256)
    y2 = _write_yaml(sub, str((sub / "ramp.pgm").resolve()))
    assert load_map(y2).occupied.tolist() == g1.occupied.tolist()
    # YAML 1.1 reads 1e-1 as a string; map_server's parser reads it as a number
    (tmp_path / "e.yaml").write_text(
        "image: maps/ramp.pgm\nresolution: 1e-1\norigin: [0, 0, 0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\nmode: trinary\n"
    )
    assert load_map(tmp_path / "e.yaml").resolution == 0.1


# ---------------------------------------------------------------- .npy and intensities
def test_npy(tmp_path: Path) -> None:
    a = np.array([[0, 1, 0], [1, 1, 0]], np.uint8)
    np.save(tmp_path / "a.npy", a)
    grid = load_map(tmp_path / "a.npy")
    assert grid.occupied.tolist() == a.astype(bool).tolist()  # not flipped
    assert grid.resolution == 1.0
    np.save(tmp_path / "b.npy", a.astype(bool))
    assert load_map(tmp_path / "b.npy", resolution=0.2).resolution == 0.2
    for bad, rule in [
        (np.array([[0, 2]]), "0/1"),
        (np.zeros((2, 2, 2), bool), "2-D"),
        (np.zeros((0, 3), bool), "empty"),
        (np.array([[0.0, np.nan]]), "NaN"),
        (np.array([["a"]]), "dtype"),
    ]:
        np.save(tmp_path / "bad.npy", bad)
        with pytest.raises(MapFormatError, match=rule) as info:
            load_map(tmp_path / "bad.npy")
        assert "bad.npy" in str(info.value)
    np.save(tmp_path / "obj.npy", np.array([[None]], dtype=object), allow_pickle=True)
    with pytest.raises(MapFormatError, match="obj.npy"):
        load_map(tmp_path / "obj.npy")


def test_npy_huge_declared_shape_is_rejected_fast(tmp_path: Path) -> None:
    # a version 1.0 header declaring ~10 GB while the file holds 4 bytes of data
    header = b"{'descr': '|b1', 'fortran_order': False, 'shape': (99999, 99999), }"
    header = header.ljust(118) + b"\n"
    data = b"\x93NUMPY\x01\x00" + len(header).to_bytes(2, "little") + header + b"\x00" * 4
    (tmp_path / "huge.npy").write_bytes(data)
    with pytest.raises(MapFormatError, match="huge.npy"):
        load_map(tmp_path / "huge.npy")


def test_from_intensity() -> None:
    v = np.array([[1, 100, 1], [100, 100, 1]])
    grid = from_intensity(v, 0.5, origin=(1.0, 2.0))
    assert grid.occupied.tolist() == (v == 100).tolist()
    assert grid.resolution == 0.5 and grid.origin == (1.0, 2.0)
    assert from_intensity(v.astype(float), 1.0) == from_intensity(v, 1.0)
    with pytest.raises(InvalidInputError, match=r"found 50 at cell \(ix=1, iy=0\)"):
        from_intensity([[1, 50], [100, 0]], 1.0)
    with pytest.raises(InvalidInputError, match="nan"):
        from_intensity([[1.0, math.nan]], 1.0)
    with pytest.raises(InvalidInputError, match="dtype bool"):
        from_intensity(np.ones((2, 2), bool), 1.0)
    with pytest.raises(InvalidInputError, match="2-D"):
        from_intensity([1, 100], 1.0)
    with pytest.raises(InvalidInputError, match="resolution"):
        from_intensity([[1]], 0.0)


# ---------------------------------------------------------------- round trips
def _assert_saved_files(yaml_path: Path, grid: OccupancyGrid) -> None:
    meta = yaml.safe_load(yaml_path.read_text())
    assert meta["mode"] == "trinary" and meta["negate"] == 0
    assert meta["origin"][2] == 0.0
    pixels = _pgm_pixels(yaml_path.parent / meta["image"])
    assert set(np.unique(pixels).tolist()) <= {0, 254}
    assert np.array_equal(pixels == 0, grid.occupied[::-1])
    leftovers = [p.name for p in yaml_path.parent.iterdir() if p.name.endswith(".tmp")]
    assert leftovers == []


@pytest.mark.parametrize("name", ["arena", "Boston_0_1024", "turtlebot3_world", "depot"])
def test_round_trip_real(shared_data: Path, tmp_path: Path, request, name: str) -> None:
    if name in ROS:
        grid = load_map(shared_data / "ros" / f"{name}.yaml")
    else:
        fixture = request.getfixturevalue("boston") if name == "Boston_0_1024" else None
        grid = _load_movingai(shared_data, name, fixture)
    out = save_map(grid, tmp_path / f"{name}.yaml")
    assert out == tmp_path / f"{name}.yaml"
    _assert_saved_files(out, grid)
    assert load_map(out) == grid


@pytest.fixture(scope="module")
def rt_dir(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("roundtrip")


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    shape=st.tuples(st.integers(1, 12), st.integers(1, 12)),
    seed=st.integers(0, 2**32 - 1),
    resolution=st.floats(1e-6, 1e6, allow_nan=False, allow_infinity=False),
    ox=st.floats(-1e9, 1e9, allow_nan=False),
    oy=st.floats(-1e9, 1e9, allow_nan=False),
)
def test_round_trip_random(rt_dir: Path, shape, seed, resolution, ox, oy) -> None:
    occ = np.random.default_rng(seed).random(shape) < 0.4
    grid = OccupancyGrid(occ, resolution, (ox, oy))
    out = save_map(grid, rt_dir / "r.yml")
    back = load_map(out)
    assert back == grid  # bit-identical resolution and origin too
    _assert_saved_files(out, grid)


def test_save_map_errors(tmp_path: Path) -> None:
    grid = OccupancyGrid(np.zeros((2, 2), bool), 1.0)
    with pytest.raises(InvalidInputError, match="suffix"):
        save_map(grid, tmp_path / "m.pgm")
    with pytest.raises(InvalidInputError, match="does not exist"):
        save_map(grid, tmp_path / "nope" / "m.yaml")
    with pytest.raises(InvalidInputError, match="OccupancyGrid"):
        save_map(np.zeros((2, 2), bool), tmp_path / "m.yaml")
    # overwriting works and leaves no temporary files
    save_map(grid, tmp_path / "m.yaml")
    grid2 = grid.with_occupied(np.eye(2, dtype=bool))
    save_map(grid2, tmp_path / "m.yaml")
    assert load_map(tmp_path / "m.yaml") == grid2
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.pgm", "m.yaml"]


# ---------------------------------------------------------------- scenarios
@pytest.mark.parametrize("name", MOVINGAI)
def test_scenarios_against_raw_text(shared_data: Path, request, name: str) -> None:
    path = shared_data / "movingai" / "scen" / f"{name}.map.scen"
    scens = read_scenarios(path)
    lines = [ln for ln in path.read_text().splitlines()[1:] if ln.strip()]
    assert len(scens) == len(lines)
    for idx in (0, len(lines) // 2, len(lines) - 1):
        f = lines[idx].split("\t")
        s = scens[idx]
        h = int(f[3])
        assert s.bucket == int(f[0])
        assert s.map_name == f"{name}.map" == f[1].split("/")[-1]
        assert (s.width, s.height) == (int(f[2]), h)
        assert s.start == (int(f[4]), h - 1 - int(f[5]))
        assert s.goal == (int(f[6]), h - 1 - int(f[7]))
        assert s.optimal_length == float(f[8])
    # the coordinate flip agrees with the map: every start and goal is a free cell
    fixture = request.getfixturevalue("boston") if name == "Boston_0_1024" else None
    grid = _load_movingai(shared_data, name, fixture)
    assert all((s.width, s.height) == (grid.nx, grid.ny) for s in scens)
    starts = np.array([s.start for s in scens])
    goals = np.array([s.goal for s in scens])
    assert grid.is_free(starts).all() and grid.is_free(goals).all()


def test_scenario_formats(tmp_path: Path) -> None:
    p = tmp_path / "s.scen"
    p.write_bytes(b"version 1.0\r\n3  dir\\x.map 10 20  1 2 3 19 4.5\r\n\r\n")
    (s,) = read_scenarios(p)
    assert s == Scenario(3, "x.map", 10, 20, (1, 17), (3, 0), 4.5)
    p.write_text("version 1\n")
    assert read_scenarios(p) == []


def test_scenario_record_is_frozen_and_validated() -> None:
    s = Scenario(0, "a.map", 4, 3, (0, 0), (3, 2), 2.5)
    with pytest.raises(AttributeError):
        s.bucket = 2  # type: ignore[misc]
    for kwargs, rule in [
        ({"start": (4, 0)}, "outside"),
        ({"goal": (0, -1)}, ">= 0"),
        ({"width": 0}, "> 0"),
        ({"optimal_length": math.nan}, "finite"),
        ({"map_name": ""}, "map_name"),
        ({"bucket": 1.5}, "int"),
    ]:
        args = dict(
            bucket=0,
            map_name="a.map",
            width=4,
            height=3,
            start=(0, 0),
            goal=(3, 2),
            optimal_length=2.5,
        )
        args.update(kwargs)
        with pytest.raises(InvalidInputError, match=rule):
            Scenario(**args)


@pytest.mark.parametrize(
    ("text", "rule"),
    [
        ("", "empty"),
        ("0\tx.map\t4\t4\t0\t0\t1\t1\t1.4\n", "version 1"),
        ("version 2\n", "version 1"),
        ("version 1\n0\tx.map\t4\t4\t0\t0\t1\t1\n", "9 fields"),
        ("version 1\n0\tx.map\t4\t4\t0\t-1\t1\t1\t1\n", "start_y"),
        ("version 1\n0\tx.map\t4\t4\t0\t1.5\t1\t1\t1\n", "start_y"),
        ("version 1\n0\tx.map\t4\t4\t4\t0\t1\t1\t1\n", "start_x = 4 must be < width"),
        ("version 1\n0\tx.map\t4\t4\t0\t0\t1\t9\t1\n", "goal_y = 9 must be < height"),
        ("version 1\n0\tx.map\t0\t4\t0\t0\t0\t0\t1\n", "width and height"),
        ("version 1\n0\tx.map\t4\t4\t0\t0\t1\t1\tabc\n", "optimal_length"),
        ("version 1\n0\tx.map\t4\t4\t0\t0\t1\t1\tnan\n", "optimal_length"),
        ("version 1\n0\tx.map\t4\t4\t0\t0\t1\t1\t-2\n", "optimal_length"),
        ("version 1\n0\tdir/\t4\t4\t0\t0\t1\t1\t2\n", "field map"),
    ],
)
def test_bad_scenarios(tmp_path: Path, text: str, rule: str) -> None:
    p = tmp_path / "bad.scen"
    p.write_text(text)
    with pytest.raises(MapFormatError, match=rule) as info:
        read_scenarios(p)
    assert "bad.scen" in str(info.value)


def test_scenario_missing_and_binary(tmp_path: Path) -> None:
    with pytest.raises(MapFormatError, match="missing.scen"):
        read_scenarios(tmp_path / "missing.scen")
    (tmp_path / "b.scen").write_bytes(b"version 1\n\xff\xfe\x00")
    with pytest.raises(MapFormatError, match="UTF-8"):
        read_scenarios(tmp_path / "b.scen")


# ---------------------------------------------------------------- bad maps
@pytest.mark.parametrize(
    ("text", "rule"),
    [
        ("", "header"),
        ("type octile\nheight 2\nwidth 2\n", "header"),
        ("type tile\nheight 1\nwidth 1\nmap\n.\n", "octile"),
        ("type octile\nheight -5\nwidth 2\nmap\n..\n", "height must be a positive integer"),
        ("type octile\nheight 0\nwidth 2\nmap\n", "> 0"),
        ("type octile\nheight x\nwidth 2\nmap\n..\n", "height"),
        ("type octile\nwidth 2\nmap\n..\n", "height is missing"),
        ("type octile\nheight 2\nwidth 2\nmap\n..\n", "truncated"),
        ("type octile\nheight 2\nwidth 3\nmap\n...\n..\n.\n", "has 2 characters"),
        ("type octile\nheight 1\nwidth 2\nmap\n..\n..\n", "more map rows"),
        ("type octile\nheight 2\nwidth 2\nmap\n..\n.x\n", r"unknown terrain character b'x'"),
        ("type octile\nheight 1\nwidth 2\nbogus 3\nmap\n..\n", "unexpected header"),
        ("type octile\nheight 999999999\nwidth 999999999\nmap\n..\n", "truncated"),
    ],
)
def test_bad_movingai(tmp_path: Path, text: str, rule: str) -> None:
    p = tmp_path / "bad.map"
    p.write_text(text)
    with pytest.raises(MapFormatError, match=rule) as info:
        load_map(p)
    assert "bad.map" in str(info.value)


def test_unknown_suffix_and_missing_file(tmp_path: Path) -> None:
    (tmp_path / "m.txt").write_text("x")
    with pytest.raises(MapFormatError, match=r"'\.txt'.*\.yaml.*\.map.*\.pgm.*\.npy"):
        load_map(tmp_path / "m.txt")
    with pytest.raises(MapFormatError, match="does not exist"):
        load_map(tmp_path / "nope.map")
    (tmp_path / "folder.map").mkdir()
    with pytest.raises(MapFormatError, match="not a regular file"):
        load_map(tmp_path / "folder.map")


def test_bad_keyword_arguments(tmp_path: Path) -> None:
    p = tmp_path / "m.map"
    p.write_text("type octile\nheight 1\nwidth 1\nmap\n.\n")
    for res in (0.0, -1.0, math.nan, math.inf, "a", True):
        with pytest.raises(InvalidInputError, match="resolution"):
            load_map(p, resolution=res)
    with pytest.raises(InvalidInputError, match="origin"):
        load_map(p, origin=(0.0, math.nan))
    with pytest.raises(InvalidInputError, match="origin"):
        load_map(p, origin=(1.0,))
    with pytest.raises(InvalidInputError, match="unknown_occupied"):
        load_map(p, unknown_occupied="no")
    _ramp_pgm(tmp_path)
    y = _write_yaml(tmp_path, "ramp.pgm")
    assert load_map(y, resolution=0.1).resolution == 0.1  # agrees with the file
    with pytest.raises(InvalidInputError, match="resolution=0.2 given"):
        load_map(y, resolution=0.2)
    with pytest.raises(InvalidInputError, match="origin"):
        load_map(y, origin=(1.0, 1.0))


@pytest.mark.parametrize(
    "key", ["image", "resolution", "origin", "negate", "occupied_thresh", "free_thresh"]
)
def test_yaml_missing_key(tmp_path: Path, key: str) -> None:
    _ramp_pgm(tmp_path)
    y = _write_yaml(tmp_path, "ramp.pgm", **{key: _DROP})
    with pytest.raises(MapFormatError, match=f"missing required key.*{key}") as info:
        load_map(y)
    assert "m.yaml" in str(info.value)


@pytest.mark.parametrize(
    ("overrides", "rule"),
    [
        ({"mode": "ternary"}, "mode must be one of trinary, scale, raw"),
        ({"mode": 3}, "mode"),
        ({"resolution": 0}, "resolution must be finite and > 0"),
        ({"resolution": -0.05}, "resolution must be finite and > 0"),
        ({"resolution": math.nan}, "resolution must be finite"),
        ({"resolution": "abc"}, "resolution must be a number"),
        ({"resolution": True}, "resolution must be a number"),
        ({"origin": [0.0, 0.0, 0.5]}, "yaw"),
        ({"origin": [0.0, 0.0]}, "3 numbers"),
        ({"origin": "0 0 0"}, "3 numbers"),
        ({"origin": [0.0, "x", 0.0]}, r"origin\[1\]"),
        ({"negate": "maybe"}, "negate"),
        ({"occupied_thresh": 0.1}, "free_thresh < occupied_thresh"),
        ({"occupied_thresh": 1.5}, "occupied_thresh <= 1"),
        ({"free_thresh": -0.1}, "0 <= free_thresh"),
        ({"image": ""}, "image must be a non-empty"),
        ({"image": 5}, "image must be a non-empty"),
        ({"image": "missing.pgm"}, "missing.pgm.*does not exist"),
    ],
)
def test_bad_yaml_fields(tmp_path: Path, overrides: dict, rule: str) -> None:
    _ramp_pgm(tmp_path)
    y = _write_yaml(tmp_path, "ramp.pgm", **overrides)
    with pytest.raises(MapFormatError, match=rule) as info:
        load_map(y)
    assert "m.yaml" in str(info.value)


@pytest.mark.parametrize(
    ("text", "rule"),
    [
        ("image: ramp.pgm\nresolution: [unclosed\n", "not valid YAML"),
        ("- just\n- a list\n", "mapping"),
        ("", "mapping"),
        ("!!python/object/apply:os.system ['echo pwned']\n", "not valid YAML"),
        ("image: !!python/name:os.getcwd ''\n", "not valid YAML"),
    ],
)
def test_garbled_yaml(tmp_path: Path, text: str, rule: str) -> None:
    p = tmp_path / "g.yaml"
    p.write_text(text)
    with pytest.raises(MapFormatError, match=rule) as info:
        load_map(p)
    assert "g.yaml" in str(info.value)


@pytest.mark.parametrize(
    ("data", "rule"),
    [
        (b"", "cannot read image"),
        (b"P6 garbage not an image", "malformed netpbm header"),
        (b"JUNKJUNKJUNKJUNK" * 10, "cannot read image"),
        (b"P5\n4 4\n255\n" + bytes(5), "declares 4 x 4 pixels"),
        (b"P5\n100000 100000\n255\n" + bytes(10), "declares 100000 x 100000"),
        (b"P5\n0 4\n255\n", "must be > 0"),
        (b"P5\n2 2\n0\n" + bytes(4), "maxval"),
        (b"P5\n2 2\n", "truncated netpbm header"),
    ],
)
def test_bad_pgm(tmp_path: Path, data: bytes, rule: str) -> None:
    (tmp_path / "bad.pgm").write_bytes(data)
    with pytest.raises(MapFormatError, match=rule):
        load_map(tmp_path / "bad.pgm", resolution=0.1)
    y = _write_yaml(tmp_path, "bad.pgm")
    with pytest.raises(MapFormatError, match="m.yaml.*bad.pgm"):
        load_map(y)


def test_huge_declared_sizes_fail_fast(tmp_path: Path) -> None:
    cases = {
        "h.map": b"type octile\nheight 99999999\nwidth 99999999\nmap\n" + b"." * 100,
        "h.pgm": b"P5\n60000 60000\n255\n" + bytes(100),
        "h2.pgm": b"P2\n# ascii\n60000 60000\n255\n" + b"0 " * 100,
        "h3.ppm": b"P3 9000 9000 255\n" + b"0 " * 100,
    }
    for name, data in cases.items():
        (tmp_path / name).write_bytes(data)
        # the declared size is checked against the file before anything is allocated
        with pytest.raises(MapFormatError, match="truncated"):
            load_map(tmp_path / name, resolution=1.0)


# ---------------------------------------------------------------- fuzzing
_ALLOWED = (MapFormatError, InvalidInputError)


@pytest.fixture(scope="module")
def fuzz_dir(tmp_path_factory) -> Path:
    d = tmp_path_factory.mktemp("fuzz")
    # a valid ROS pair to truncate
    grid = OccupancyGrid(np.random.default_rng(0).random((6, 9)) < 0.3, 0.05, (1.0, -2.0))
    save_map(grid, d / "valid.yaml")
    buf = io.BytesIO()
    Image.fromarray(np.arange(24, dtype=np.uint8).reshape(4, 6) * 10).save(buf, "PNG")
    (d / "valid.png").write_bytes(buf.getvalue())
    np.save(d / "valid.npy", np.eye(3, dtype=bool))
    (d / "valid.map").write_bytes(
        b"type octile\r\nheight 3\r\nwidth 4\r\nmap\r\n.@..\r\nTT.S\r\nW...\r\n"
    )
    (d / "valid.scen").write_bytes(b"version 1\n0\tmaps/valid.map\t4\t3\t0\t0\t2\t1\t2.41421356\n")
    return d


def _load_any(path: Path) -> object:
    if path.suffix == ".scen":
        return read_scenarios(path)
    return load_map(path, resolution=0.1 if path.suffix in (".pgm", ".png") else None)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    suffix=st.sampled_from([".map", ".scen", ".yaml", ".pgm", ".png", ".npy"]),
    data=st.binary(max_size=300),
)
def test_fuzz_random_bytes(fuzz_dir: Path, suffix: str, data: bytes) -> None:
    path = fuzz_dir / f"fuzz{suffix}"
    path.write_bytes(data)
    try:
        _load_any(path)
    except _ALLOWED:
        pass


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    suffix=st.sampled_from([".map", ".scen", ".yaml", ".pgm", ".png", ".npy"]),
    cut=st.floats(0.0, 1.0),
    flip=st.one_of(st.none(), st.tuples(st.floats(0.0, 1.0), st.integers(0, 255))),
)
def test_fuzz_truncated_or_corrupted(fuzz_dir: Path, suffix: str, cut: float, flip) -> None:
    valid = (fuzz_dir / f"valid{suffix}").read_bytes()
    data = bytearray(valid[: int(cut * len(valid))])
    if flip is not None and data:
        where, value = flip
        data[min(int(where * len(data)), len(data) - 1)] = value
    name = f"t{suffix}"
    path = fuzz_dir / name
    path.write_bytes(bytes(data))
    if suffix == ".pgm":  # the YAML still points at valid.pgm; fuzz the image through it
        (fuzz_dir / "t.yaml").write_text(
            (fuzz_dir / "valid.yaml").read_text().replace("valid.pgm", "t.pgm")
        )
        try:
            load_map(fuzz_dir / "t.yaml")
        except _ALLOWED:
            pass
    try:
        _load_any(path)
    except _ALLOWED:
        assert bytes(data) != valid  # the untouched file must load


def test_no_temp_files_left_by_fuzz(fuzz_dir: Path) -> None:
    assert not [p for p in os.listdir(fuzz_dir) if p.endswith(".tmp")]


# ------------------------------------------------------------- hostile input (issue 7)
def test_yaml_alias_bomb_fails_fast(tmp_path: Path) -> None:
    # "billion laughs": 9 levels of 9 aliases describe 9^9 elements in a few hundred bytes;
    # safe_load shares them, and the error message must not expand them either
    (tmp_path / "a.pgm").write_bytes(b"P5\n2 2\n255\n" + bytes(4))
    lines = ["a0: &a0 [x, x, x, x, x, x, x, x, x]"]
    lines += [f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * 9) + "]" for i in range(1, 9)]
    base = [
        "image: a.pgm",
        "origin: [0, 0, 0]",
        "negate: 0",
        "occupied_thresh: 0.65",
        "free_thresh: 0.196",
        "resolution: 0.1",
    ]
    for key in ("resolution", "origin", "negate", "image", "mode", "free_thresh"):
        body = [ln for ln in base if not ln.startswith(key + ":")] + [f"{key}: *a8"]
        path = tmp_path / f"bomb_{key}.yaml"
        path.write_text("\n".join(lines + body) + "\n")
        t0 = time.perf_counter()
        with pytest.raises(MapFormatError, match=f"bomb_{key}.yaml.*{key}") as info:
            load_map(path)
        assert time.perf_counter() - t0 < 5.0
        assert len(str(info.value)) < 1000


def test_png_declaring_huge_size_is_refused_before_decoding(tmp_path: Path) -> None:
    import struct
    import zlib

    def chunk(kind: bytes, data: bytes) -> bytes:
        return (
            struct.pack(">I", len(data))
            + kind
            + data
            + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
        )

    for w, h in ((10_000, 10_000), (100_000, 100_000), (2**31 - 1, 2**31 - 1)):
        ihdr = struct.pack(">IIBBBBB", w, h, 8, 0, 0, 0, 0)  # 8-bit grey
        data = (
            b"\x89PNG\r\n\x1a\n"
            + chunk(b"IHDR", ihdr)
            + chunk(b"IDAT", zlib.compress(b"\x00" * 1000))
            + chunk(b"IEND", b"")
        )
        (tmp_path / "big.png").write_bytes(data)
        tracemalloc.start()
        try:
            with pytest.raises(MapFormatError, match="big.png"):
                load_map(tmp_path / "big.png", resolution=0.05)
            peak = tracemalloc.get_traced_memory()[1]
        finally:
            tracemalloc.stop()
        assert peak < 50e6, f"{w} x {h}: peak {peak / 1e6:.0f} MB"


@pytest.mark.parametrize(
    ("name", "data"),
    [
        ("h.map", b"type octile\nheight 99999999\nwidth 99999999\nmap\n" + b"." * 100),
        ("h.pgm", b"P5\n60000 60000\n255\n" + bytes(100)),
        ("h.pbm", b"P4\n2000000000 2000000000\n" + bytes(100)),
        (
            "h.npy",
            b"\x93NUMPY\x01\x00\x46\x00{'descr': '|b1', 'fortran_order': False, "
            b"'shape': (999999, 999999), }   \n" + bytes(8),
        ),
    ],
)
def test_huge_declared_sizes_allocate_nothing(tmp_path: Path, name: str, data: bytes) -> None:
    (tmp_path / name).write_bytes(data)
    tracemalloc.start()
    try:
        with pytest.raises(_ALLOWED):
            load_map(tmp_path / name, resolution=1.0)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 20e6, f"{name}: peak {peak / 1e6:.0f} MB"


_NUMBER = st.one_of(
    st.integers(-(2**70), 2**70).map(str),
    st.sampled_from(["-1", "0", "1e9", "nan", "inf", "-0", "0x10", "1_000", "", "9" * 40]),
)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    kind=st.sampled_from(["map", "scen", "pgm", "ppm", "yaml"]),
    a=_NUMBER,
    b=_NUMBER,
    c=_NUMBER,
    tail=st.binary(max_size=64),
)
def test_fuzz_hostile_headers(
    fuzz_dir: Path, kind: str, a: str, b: str, c: str, tail: bytes
) -> None:
    # well-formed looking headers with hostile numbers: negative, huge, NaN, empty
    if kind == "map":
        data = f"type octile\nheight {a}\nwidth {b}\nmap\n".encode() + tail
    elif kind == "scen":
        data = f"version 1\n{c}\tx.map\t{a}\t{b}\t0\t{c}\t1\t1\t{a}\n".encode() + tail
    elif kind in ("pgm", "ppm"):
        magic = "P5" if kind == "pgm" else "P3"
        data = f"{magic}\n{a} {b}\n{c}\n".encode() + tail
    else:
        data = (
            f"image: valid.pgm\nresolution: {a}\norigin: [{b}, {c}, 0]\nnegate: {c}\n"
            f"occupied_thresh: {b}\nfree_thresh: {a}\nmode: !!python/name:os.system\n"
        ).encode() + tail
    path = fuzz_dir / f"hostile.{kind}"
    path.write_bytes(data)
    t0 = time.perf_counter()
    tracemalloc.start()
    try:
        try:
            _load_any(path) if kind != "ppm" else load_map(path, resolution=0.1)
        except _ALLOWED as exc:
            assert str(exc)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert time.perf_counter() - t0 < 5.0
    assert peak < 50e6
