"""Tests of astar: the option records of astar.find_pose_path: validation per field, flat keywords = records."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import astar
from astar import (
    HybridCollision,
    HybridCosts,
    HybridLimits,
    HybridMotion,
    InvalidInputError,
    find_pose_path,
)
from astar.hybrid_options import FLAT_KEYWORDS

RECORDS = {
    "motion": HybridMotion,
    "costs": HybridCosts,
    "limits": HybridLimits,
    "collision": HybridCollision,
}
SMALL = np.array([[-0.5, -0.5], [1.5, -0.5], [1.5, 0.5], [-0.5, 0.5]])
_FREE = np.ones((10, 20), bool)
_RAW = np.zeros((10, 20), bool)


def _closed(ny: int, nx: int) -> np.ndarray:
    free = np.zeros((ny, nx), bool)
    free[1:-1, 1:-1] = True
    return free


def _inflated(occ: np.ndarray, r: float) -> np.ndarray:
    g = astar.OccupancyGrid(occ, 1.0)
    return ~astar.inflate(g, r, metric="square", outside_occupied=True).occupied


def _as_records(kwargs: dict) -> dict:
    """The same options as records: each field under the record that owns it."""
    parts: dict[str, dict] = {}
    for name, value in kwargs.items():
        parts.setdefault(FLAT_KEYWORDS[name], {})[name] = value
    return {key: RECORDS[key](**fields) for key, fields in parts.items()}


def _same(p, q) -> None:
    for name in ("poses", "directions", "segments", "pieces"):
        a, b = getattr(p, name), getattr(q, name)
        assert a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes(), name
    assert p.turning_radius == q.turning_radius
    drop = ("heuristic_s", "search_s", "shortcut_s", "total_s")
    assert {k: v for k, v in p.stats.items() if k not in drop} == {
        k: v for k, v in q.stats.items() if k not in drop
    }


# --------------------------------------------------------------------------- the records
def test_every_field_is_a_flat_keyword_of_one_record():
    names = [f.name for cls in RECORDS.values() for f in dataclasses.fields(cls)]
    assert len(names) == len(set(names)) == len(FLAT_KEYWORDS)
    for key, cls in RECORDS.items():
        for f in dataclasses.fields(cls):
            assert FLAT_KEYWORDS[f.name] == key


def test_records_are_on_the_face_and_frozen():
    for cls in RECORDS.values():
        assert getattr(astar, cls.__name__) is cls and cls.__name__ in astar.__all__
    m = HybridMotion(turning_radius=3)
    assert m.turning_radius == 3.0 and type(m.turning_radius) is float
    with pytest.raises(dataclasses.FrozenInstanceError):
        m.turning_radius = 4.0  # type: ignore[misc]
    assert HybridMotion(turning_radius=2.0) == HybridMotion(2.0, True, 72, None, 3)
    assert HybridCosts() == HybridCosts(2.0, 2.0, 0.05, 0.05, 3.5, 1.5)
    assert HybridLimits() == HybridLimits(500_000, 2.0, 0.5)
    c = HybridCollision(raw_grid=astar.OccupancyGrid(_RAW, 0.05), footprint=SMALL.tolist())
    assert c.mode == "footprint" and HybridCollision().mode == "grid"
    assert c.raw_grid.dtype == bool and c.raw_grid.shape == (10, 20)
    assert not c.raw_grid.flags.writeable and not c.footprint.flags.writeable
    assert c.footprint.dtype == np.float64 and c.footprint.tolist() == SMALL.tolist()
    assert HybridCollision(raw_grid=_RAW, clearance=1).clearance == 1.0


def test_motion_primitives():
    m = HybridMotion(turning_radius=3.0, heading_bins=72)
    assert m.arc_length == pytest.approx(3.0 * 6 * 2 * math.pi / 72)  # 6 bins: >= sqrt(2)
    assert HybridMotion(turning_radius=3.0, primitive_length=1.25).arc_length == 1.25
    k = HybridMotion(turning_radius=2.0, curvatures=5).primitive_curvatures()
    assert k.tolist() == [0.0, -0.25, 0.25, -0.5, 0.5]


# (record, field, bad value, message): a test per field's typed error
BAD = [
    (HybridMotion, "turning_radius", 0.0, "turning_radius must be finite and > 0, got 0.0"),
    (HybridMotion, "turning_radius", math.nan, "turning_radius must be finite and > 0"),
    (HybridMotion, "turning_radius", "three", "turning_radius must be a number, got 'three'"),
    (HybridMotion, "turning_radius", True, "turning_radius must be a number, got True"),
    (HybridMotion, "reverse", "yes", "reverse must be a bool, got 'yes'"),
    (HybridMotion, "heading_bins", 4, "heading_bins must be >= 8, got 4"),
    (HybridMotion, "heading_bins", 72.0, "heading_bins must be an int, got 72.0"),
    (HybridMotion, "primitive_length", -1.0, "primitive_length must be finite and > 0"),
    (HybridMotion, "curvatures", 4, "curvatures must be odd (zero included), got 4"),
    (HybridMotion, "curvatures", 1, "curvatures must be >= 3, got 1"),
    (HybridCosts, "reverse_penalty", 0.5, "reverse_penalty must be finite and >= 1, got 0.5"),
    (HybridCosts, "cusp_penalty", -1, "cusp_penalty must be finite and >= 0, got -1.0"),
    (HybridCosts, "turn_penalty", math.inf, "turn_penalty must be finite and >= 0, got inf"),
    (HybridCosts, "steer_penalty", "a", "steer_penalty must be a number, got 'a'"),
    (HybridCosts, "analytic_ratio", 0.0, "analytic_ratio must be finite and > 0, got 0.0"),
    (HybridCosts, "heuristic_weight", 0.9, "heuristic_weight must be finite and >= 1, got 0.9"),
    (HybridLimits, "max_expansions", 0, "max_expansions must be >= 1, got 0"),
    (HybridLimits, "max_expansions", 1e6, "max_expansions must be an int, got 1000000.0"),
    (HybridLimits, "time_budget", 0, "time_budget must be finite and > 0, got 0.0"),
    (HybridLimits, "sample_step", -0.5, "sample_step must be finite and > 0, got -0.5"),
    (HybridLimits, "retry_expansions", -1, "retry_expansions must be >= 0, got -1"),
    (HybridLimits, "retry_expansions", 2.5, "retry_expansions must be an int, got 2.5"),
    (HybridCollision, "clearance", -1.0, "clearance must be finite and > 0, got -1.0"),
    (HybridCollision, "footprint", "square", "footprint must be an array of vertices"),
    (HybridCollision, "footprint", [[-1, -1], [1, 1]], "footprint must have shape (k, 2)"),
    (HybridCollision, "footprint_margin", -1.0, "footprint_margin must be finite and >= 0"),
    (HybridCollision, "footprint_slack", 0.0, "footprint_slack must be finite and > 0"),
    (HybridCollision, "raw_grid", np.zeros((10, 20)), "raw_grid must be an astar.OccupancyGrid"),
]
# the other fields a bad value needs to be checked at all
_CONTEXT = {
    HybridMotion: {"turning_radius": 2.0},
    HybridCollision: {"raw_grid": _RAW, "footprint": SMALL},
}


@pytest.mark.parametrize(
    ("cls", "name", "value", "match"),
    BAD,
    ids=[f"{c.__name__}.{n}-{i}" for i, (c, n, *_) in enumerate(BAD)],
)
def test_each_field_raises_its_typed_error(cls, name, value, match):
    """The record raises the error find_pose_path raises for the same keyword: same type,
    same message."""
    fields = dict(_CONTEXT.get(cls, {}))
    if name in ("clearance", "raw_grid") and cls is HybridCollision:
        fields = {"raw_grid": _RAW, "clearance": 1.0}
    fields[name] = value
    with pytest.raises(InvalidInputError) as by_record:
        cls(**fields)
    if match is not None:
        assert str(by_record.value).startswith(match), str(by_record.value)
    assert name in str(by_record.value)
    with pytest.raises(InvalidInputError) as by_name:
        find_pose_path(_FREE, (3, 5, 0), (12, 5, 0), **{"turning_radius": 2.0, **fields})
    assert str(by_name.value) == str(by_record.value)


@pytest.mark.parametrize(
    ("fields", "match"),
    [
        ({"clearance": 1.0}, "clearance=1.0 needs raw_grid"),
        ({"raw_grid": _RAW}, "raw_grid is used only with clearance or footprint"),
        ({"footprint": SMALL}, "needs raw_grid"),
        ({"footprint": SMALL, "raw_grid": _RAW, "clearance": 1.0}, "exclude each other"),
        ({"footprint_margin": 0.5}, "footprint_margin=0.5 is used only with footprint"),
        ({"footprint_slack": 0.5}, "footprint_slack=0.5 is used only with footprint"),
    ],
)
def test_collision_modes_are_checked_on_construction(fields, match):
    with pytest.raises(InvalidInputError, match=match):
        HybridCollision(**fields)


def test_grid_checks_stay_with_the_search():
    """raw_grid's shape and the end poses' footprints need the grid: find_pose_path checks
    them, with the record as with the keywords."""
    small = HybridCollision(raw_grid=np.zeros((5, 5), bool), clearance=1.0)
    with pytest.raises(InvalidInputError, match=r"raw_grid must have the grid's shape"):
        find_pose_path(_FREE, (3, 5, 0), (12, 5, 0), turning_radius=2, collision=small)
    big = HybridCollision(raw_grid=_RAW, footprint=SMALL * 8)
    with pytest.raises(InvalidInputError, match=r"start pose \(3, 5, 0\).*leaves the grid"):
        find_pose_path(_FREE, (3, 5, 0), (12, 5, 0), turning_radius=2, collision=big)


# --------------------------------------------------------------------------- the call
def test_records_and_keywords_mix_by_record():
    motion = HybridMotion(turning_radius=2.0)
    p = find_pose_path(_FREE, (3, 5, 0), (12, 5, 0), motion=motion, time_budget=1.0)
    q = find_pose_path(_FREE, (3, 5, 0), (12, 5, 0), turning_radius=2.0, time_budget=1.0)
    _same(p, q)
    with pytest.raises(InvalidInputError, match=r"reverse and motion=HybridMotion\(...\)"):
        find_pose_path(_FREE, (3, 5, 0), (12, 5, 0), motion=motion, reverse=False)
    with pytest.raises(InvalidInputError, match=r"limits must be an astar.HybridLimits"):
        find_pose_path(_FREE, (3, 5, 0), (12, 5, 0), motion=motion, limits={"time_budget": 1})
    with pytest.raises(TypeError, match=r"unexpected keyword argument 'turning_radus'"):
        find_pose_path(_FREE, (3, 5, 0), (12, 5, 0), turning_radus=2.0)
    with pytest.raises(TypeError, match=r"missing 1 required keyword-only argument"):
        find_pose_path(_FREE, (3, 5, 0), (12, 5, 0), reverse=False)


def _bay() -> np.ndarray:
    occ = np.zeros((30, 40), bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    occ[15:, :] = True
    occ[15:22, 19:22] = False
    return occ


def _cases():
    free = _closed(22, 50)
    free[6:16, 6:44] = False
    yield free, (20.0, 3.0, 0.0), (20.0, 18.0, math.pi), {"turning_radius": 3.0}
    yield (
        free,
        (20.0, 3.0, 0.0),
        (20.0, 18.0, math.pi),
        {
            "turning_radius": 3.0,
            "reverse": False,
            "heading_bins": 36,
            "curvatures": 5,
            "primitive_length": 1.6,
            "reverse_penalty": 1.5,
            "cusp_penalty": 1.0,
            "turn_penalty": 0.1,
            "steer_penalty": 0.2,
            "analytic_ratio": 2.0,
            "heuristic_weight": 1.2,
            "max_expansions": 100_000,
            "time_budget": 30.0,
            "sample_step": 0.3,
        },
    )
    occ = np.zeros((20, 40), bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    occ[8:20, 18:21] = True
    yield (
        _inflated(occ, 2.5),
        (5.0, 3.0, 0.3),
        (32.0, 14.0, math.pi / 2),
        {"turning_radius": 5.0, "raw_grid": occ, "clearance": 2.5},
    )
    bay = _bay()
    yield (
        _inflated(bay, 1.0),
        (8.0, 6.0, 0.0),
        (20.0, 19.0, math.pi / 2),
        {
            "turning_radius": 3.0,
            "raw_grid": astar.OccupancyGrid(bay, 0.05),
            "footprint": [[-2.0, -1.0], [2.0, -1.0], [2.0, 1.0], [-2.0, 1.0]],
            "footprint_margin": 0.1,
            "footprint_slack": 0.2,
        },
    )


@pytest.mark.parametrize("case", range(4))
def test_keywords_and_records_give_identical_paths(case):
    grid, start, goal, kwargs = list(_cases())[case]
    by_name = find_pose_path(grid, start, goal, **kwargs)
    by_record = find_pose_path(grid, start, goal, **_as_records(kwargs))
    _same(by_name, by_record)


def test_refusals_are_the_same_with_records():
    free = _closed(9, 40)
    kwargs = {"turning_radius": 5.0, "reverse": False}
    errors = []
    for options in (kwargs, _as_records(kwargs)):
        with pytest.raises(astar.NoPosePathError) as e:
            find_pose_path(free, (30.0, 4.0, 0.0), (30.0, 4.0, math.pi), **options)
        errors.append(e.value)
    assert errors[0].reason == errors[1].reason == "exhausted"
    assert str(errors[0]) == str(errors[1])
