"""Tests of trajopt.planning: determinism (issue 7, section 4): the same inputs give the same trajectory bit for bit.

Every comparison here is exact (``np.array_equal``, ``==``), never ``allclose``: a planner
whose answer depends on what it solved before cannot be replayed or debugged.
"""

from __future__ import annotations

import math
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

import trajopt
from tests.cases import door_grid

ROBOT = trajopt.Robot(radius=0.12)
START, GOAL = (0.4, 0.3), (2.6, 1.6)
OTHER_QUERIES = [((0.4, 0.3), (2.8, 0.3)), ((0.4, 1.6), (2.0, 1.8)), ((2.6, 1.6), (0.4, 0.3))]


def fingerprint(traj: trajopt.Trajectory) -> dict[str, np.ndarray]:
    """Everything a user can read from a trajectory, as arrays to compare exactly."""
    out = {
        f"sample_{k}": np.asarray(v)
        for k, v in traj.sample(np.linspace(0.0, traj.duration, 1000)).as_dict().items()
    }
    out["control_points"] = np.asarray(traj.path.control_points)
    out["knots"] = np.asarray(traj.path.knots)
    for name in ("phase_t", "phase_s", "phase_v", "phase_a", "phase_j"):
        out[name] = np.asarray(getattr(traj, name))
    out["duration"] = np.asarray([traj.duration])
    return out


def assert_identical(a: dict[str, np.ndarray], b: dict[str, np.ndarray]) -> None:
    assert a.keys() == b.keys()
    for k in a:
        assert a[k].shape == b[k].shape, k
        if not np.array_equal(a[k], b[k]):
            diff = float(np.max(np.abs(a[k] - b[k])))
            pytest.fail(f"{k} differs between identical runs (max |difference| {diff!r})")


def test_two_fresh_planners_are_bit_identical() -> None:
    grid = door_grid()
    a = fingerprint(trajopt.Planner(grid, ROBOT).plan(START, GOAL))
    b = fingerprint(trajopt.Planner(grid, ROBOT).plan(START, GOAL))
    assert_identical(a, b)


def test_plan_equals_planner_bit_for_bit() -> None:
    grid = door_grid()
    a = fingerprint(trajopt.plan(grid, START, GOAL, ROBOT))
    b = fingerprint(trajopt.Planner(grid, ROBOT).plan(START, GOAL))
    c = fingerprint(trajopt.plan(grid, START, GOAL, ROBOT))
    assert_identical(a, b)
    assert_identical(a, c)


def test_answer_does_not_depend_on_earlier_queries() -> None:
    # the same query before and after other queries of the same process (and the same
    # planner): cached solvers must not carry state from one query to the next
    grid = door_grid()
    planner = trajopt.Planner(grid, ROBOT)
    first = fingerprint(planner.plan(START, GOAL))
    for s, g in OTHER_QUERIES:
        planner.plan(s, g)
        trajopt.plan(grid, s, g, ROBOT)
    assert_identical(first, fingerprint(planner.plan(START, GOAL)))
    assert_identical(first, fingerprint(trajopt.plan(grid, START, GOAL, ROBOT)))


def _plan_in_worker(query: tuple[tuple[float, float], tuple[float, float]]) -> dict:
    return fingerprint(trajopt.plan(door_grid(), query[0], query[1], ROBOT))


def test_fresh_process_gives_the_same_answer() -> None:
    here = fingerprint(trajopt.plan(door_grid(), START, GOAL, ROBOT))
    with ProcessPoolExecutor(max_workers=1) as pool:
        there = pool.submit(_plan_in_worker, (START, GOAL)).result()
    assert_identical(here, there)


def _records_equal(a: dict, b: dict) -> bool:
    """Exact equality of two benchmark rows, wall times and the worker left out."""
    from trajopt.analysis.bench import TIMING_COLUMNS

    ka = {k for k in a if k not in TIMING_COLUMNS}
    kb = {k for k in b if k not in TIMING_COLUMNS}
    if ka != kb:
        return False
    for k in ka:
        x, y = a[k], b[k]
        if isinstance(x, float) and isinstance(y, float) and math.isnan(x) and math.isnan(y):
            continue
        if x != y:
            return False
    return True


def test_bench_records_serial_equal_parallel_exactly(shared_data) -> None:
    # the benchmark's rows (every metric of every scenario) of a serial run and of a
    # 2-process run are equal exactly (tests/trajopt/analysis/test_bench.py does the same on Dask)
    from trajopt.analysis import bench

    src = bench.movingai_queries(
        shared_data / "movingai" / "scen" / "den312d.map.scen", limit=4, feasible_only=True
    )
    chunks = bench.make_chunks([src], ["trajopt", "bspline-fit"], set(), 1)
    serial = [r for ch in chunks for r in bench.run_chunk(ch)]
    with ProcessPoolExecutor(max_workers=2) as pool:
        parallel = [r for rows in pool.map(bench.run_chunk, chunks) for r in rows]
    assert len(serial) == len(parallel) == 8
    for i, (a, b) in enumerate(zip(serial, parallel, strict=True)):
        assert _records_equal(a, b), f"row {i}: serial {a} != parallel {b}"
