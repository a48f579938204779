"""Tests of trajopt.analysis.bench (issue 22): Dask rows equal serial rows, resume after a kill, bad input,
the report against brute-force counts, the peers' adapters."""

from __future__ import annotations

import math
import os
import signal
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("distributed", reason="the bench extra (dask[distributed]) is missing")
pytest.importorskip("pyarrow", reason="the bench extra (pyarrow) is missing")

from tests.processes import Started, module_processes, scratch_dir
from trajopt.analysis import bench  # noqa: E402
from trajopt.analysis.bench._dataset import part_files  # noqa: E402
from trajopt.analysis.bench._runner import query_cost  # noqa: E402
from trajopt.analysis.bench._suites import data_dir  # noqa: E402
from trajopt.errors import BenchmarkError, PeerUnavailableError

REPO = Path(__file__).resolve().parents[3]
METHODS = ("trajopt", "astar", "bspline-fit")


@pytest.fixture(scope="module")
def sources(shared_data):
    """3 feasible den312d scenarios and 2 random turtlebot3 queries."""
    return [
        bench.movingai_queries(
            shared_data / "movingai" / "scen" / "den312d.map.scen", limit=3, feasible_only=True
        ),
        bench.random_queries(shared_data / "ros" / "turtlebot3_world.yaml", 2, seed=3),
    ]


@pytest.fixture(scope="module")
def serial(sources, tmp_path_factory):
    out = tmp_path_factory.mktemp("serial") / "ds"
    bench.run(sources, out, methods=METHODS, scheduler="serial", chunk_size=2, progress=False)
    return bench.read_dataset(out)


@pytest.fixture(scope="module")
def client():
    from distributed import Client, LocalCluster

    env = {"PYTHONPATH": os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")])}
    cluster = LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None, env=env
    )
    cl = Client(cluster)
    yield cl
    cl.close()
    cluster.close()


def _by_key(df):
    return df.sort_values(["query_id", "method"]).reset_index(drop=True)


def assert_same_rows(a, b):
    """Every column but the wall times and the worker equal exactly (NaN == NaN)."""
    a, b = _by_key(a), _by_key(b)
    assert len(a) == len(b)
    for col in bench.COLUMNS:
        if col in bench.TIMING_COLUMNS:
            continue
        x, y = a[col].to_numpy(), b[col].to_numpy()
        if x.dtype.kind == "f":
            assert np.array_equal(x, y, equal_nan=True), col
        else:
            assert (x == y).all(), col


def test_serial_rows_are_queries_times_methods(serial, sources):
    n_queries = sum(len(s.queries) for s in sources)
    assert len(serial) == n_queries * len(METHODS)
    keys = set(zip(serial["query_id"], serial["method"], strict=True))
    assert len(keys) == len(serial)  # no pair twice
    assert keys == {(q.query_id, m) for s in sources for q in s.queries for m in METHODS}
    # the queries are feasible, so the reference exists: astar is always a path
    assert serial[serial["method"] == "astar"]["ok"].all()
    ok = serial[serial["ok"]]
    assert (ok["n_samples"] > 0).all() and np.isfinite(ok["min_clearance_m"]).all()
    # every scored row says how long its scoring took (apart from runtime_s)
    assert (ok["score_s"] > 0).all() and np.isfinite(ok["score_s"]).all()
    traj = serial[serial["method"].str.startswith("trajopt") & serial["ok"]]
    assert len(traj) > 0
    # trajopt's certificate, measured by the independent metric; the stage timings add up
    assert not traj["collision"].any()
    assert (traj["min_clearance_m"] >= traj["radius_m"] - 1e-9).all()
    parts = traj[["stage_search_s", "stage_corridor_s", "stage_smooth_s", "stage_timing_s"]]
    assert (parts.sum(axis=1) <= traj["stage_total_s"] + 1e-9).all()
    assert np.isfinite(traj["duration_s"]).all()


def test_dask_two_workers_equal_serial(client, sources, serial, tmp_path):
    info = client.run(lambda: __import__("trajopt").__file__)
    assert all(str(REPO) in f for f in info.values()), info  # workers import this checkout
    out = tmp_path / "dask"
    res = bench.run(sources, out, methods=METHODS, client=client, chunk_size=1, progress=False)
    assert res.workers == 2 and res.rows_written == len(serial) and res.chunks == 5
    df = bench.read_dataset(out)
    assert_same_rows(df, serial)
    assert df["worker"].nunique() == 2  # both workers served chunks


def test_a_worker_killed_mid_task_has_its_chunk_retried(client, sources, serial, tmp_path):
    out = tmp_path / "killed"
    result: dict = {}
    run = threading.Thread(
        target=lambda: result.update(
            res=bench.run(
                sources[:1], out, methods=METHODS, client=client, chunk_size=1, progress=False
            )
        )
    )
    run.start()
    killed = None
    deadline = time.monotonic() + 30
    while killed is None and time.monotonic() < deadline:
        busy = [
            w
            for w, tasks in client.processing().items()
            if any("trajopt-bench" in str(t) for t in tasks)
        ]
        if busy:
            pid = client.run(os.getpid, workers=[busy[0]])[busy[0]]
            os.kill(pid, signal.SIGKILL)
            killed = busy[0]
        time.sleep(0.01)
    run.join(timeout=120)
    assert killed is not None and not run.is_alive()
    expected = serial[serial["map"] == "den312d.map"]
    assert result["res"].rows_written == len(expected)
    assert_same_rows(bench.read_dataset(out), expected)


#: A fresh process that runs ``trajopt bench run`` (serial, chunks of one query) in a process
#: of its own and SIGKILLs it as soon as its first part file exists; prints the signal.
KILLED_CLI_RUN = """
    import signal, subprocess, sys, time
    from trajopt.analysis.bench._dataset import part_files
    out, cmd = sys.argv[1], sys.argv[2:]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    while not part_files(out) and time.monotonic() < deadline:
        time.sleep(0.02)
    proc.send_signal(signal.SIGKILL)
    print(proc.wait())
"""


def early_processes(items) -> dict[str, Started]:
    """The killed CLI run (:data:`KILLED_CLI_RUN`), started when collection ends
    (tests/processes.py) when its test is selected and the shared data is there."""
    names = {getattr(i, "originalname", None) for i in items}
    try:
        scen = data_dir() / "movingai" / "scen" / "den312d.map.scen"
    except BenchmarkError:  # no shared data: the test skips with its reason
        return {}
    if "test_killed_run_resumes_without_loss_or_repeat" not in names or not scen.is_file():
        return {}
    out = Path(scratch_dir("trajopt_bench_killed_")) / "resumed"
    cmd = [
        sys.executable,
        "-m",
        "trajopt.cli",
        "bench",
        "run",
        str(scen),
        "--limit",
        "3",
        "--feasible-only",
        "--methods",
        ",".join(METHODS),
        "--out",
        str(out),
        "--scheduler",
        "serial",
        "--chunk-size",
        "1",
        "--no-progress",
    ]
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    return {"killed_cli": Started(KILLED_CLI_RUN, str(out), *cmd, env=env)}


def test_killed_run_resumes_without_loss_or_repeat(shared_data, serial, sources, request):
    # the CLI run was started, and killed after its first part file, by early_processes
    run = module_processes(request)["killed_cli"]
    done = run.result()
    assert done.returncode == 0 and done.stdout.split() == [str(-signal.SIGKILL)], done.stderr
    out = Path(done.args[3])
    first = {p.name: p.read_bytes() for p in part_files(out)}
    assert 1 <= len(first) < 3, "the run should have been killed between chunks 1 and 3"
    src = [sources[0]]
    res = bench.run(
        src, out, methods=METHODS, scheduler="serial", chunk_size=1, resume=True, progress=False
    )
    assert res.rows_skipped == len(first) * len(METHODS)
    assert res.rows_skipped + res.rows_written == res.rows_expected == 3 * len(METHODS)
    for name, data in first.items():  # finished files untouched
        assert (out / name).read_bytes() == data
    df = bench.read_dataset(out)
    assert not df.duplicated(["query_id", "method"]).any()
    assert_same_rows(df, serial[serial["map"] == "den312d.map"])
    # a second resume has nothing to do
    again = bench.run(src, out, methods=METHODS, scheduler="serial", resume=True, progress=False)
    assert again.rows_written == 0 and again.chunks == 0


def _mq(name: str, lengths, resolution: float = 1.0, cells=None) -> bench.MapQueries:
    """Synthetic map queries (never loaded): optimal lengths, or NaN with end cells."""
    qs = []
    for i, length in enumerate(lengths):
        goal = (1, 0) if cells is None else cells[i]
        qs.append(bench.Query(f"{name}/scen/{i}", i, 0, (0, 0), goal, length))
    return bench.MapQueries(f"/nowhere/{name}", name, "scen", 1.0, resolution, tuple(qs))


def test_auto_chunk_size_rule():
    from trajopt.analysis.bench._runner import MAX_AUTO_CHUNK, TASKS_PER_WORKER, auto_chunk_size

    assert auto_chunk_size(20, 2) == 1  # shared-small on 2 workers: one query per task
    assert auto_chunk_size(20, 1) == 2
    assert auto_chunk_size(10_000, 2) == MAX_AUTO_CHUNK  # large suites: chunks of 4
    assert auto_chunk_size(3, 16) == 1
    for n in range(1, 300):
        for w in (1, 2, 3, 8):
            k = auto_chunk_size(n, w)
            assert 1 <= k <= MAX_AUTO_CHUNK
            if k > 1:  # chunks of several queries only while every worker gets 8 tasks
                assert math.ceil(n / k) >= TASKS_PER_WORKER * w


def test_make_chunks_runs_the_longest_first():
    nan = math.nan
    a = _mq("a.map", [5.0, 300.0, 40.0, 300.0, 1.0])
    b = _mq(
        "b.yaml", [nan] * 4, resolution=0.05, cells=[(10, 0), (400, 300), (0, 2000), (3, 4)]
    )  # octile lengths, 0.05 m cells
    c = _mq("c.map", [2.0, 3.0])
    methods = ("astar", "trajopt")
    done = {("a.map/scen/1", "trajopt"), ("c.map/scen/0", "astar"), ("c.map/scen/0", "trajopt")}
    chunks = bench.make_chunks([c, b, a], methods, done, 2)
    # every pair not done, exactly once; chunks of <= 2 queries of one map
    pairs = [(q.query_id, m) for ch in chunks for q, ms in ch.work for m in ms]
    want = {(q.query_id, m) for mq in (a, b, c) for q in mq.queries for m in methods} - done
    assert len(pairs) == len(set(pairs)) and set(pairs) == want
    assert all(1 <= len(ch.work) <= 2 for ch in chunks)
    assert all(ch.maps.map_name == ch.work[0][0].query_id.split("/")[0] for ch in chunks)
    # maps one after the other, the costliest first
    names = [ch.maps.map_name for ch in chunks]
    order = list(dict.fromkeys(names))
    assert order == ["a.map", "b.yaml", "c.map"]
    assert names == sorted(names, key=order.index)
    totals = [sum(ch.cost for ch in chunks if ch.maps.map_name == m) for m in order]
    assert totals == sorted(totals, reverse=True)
    # within a map, the longest query first (pairs already done count less); ties in order
    flat_a = [q.query_id for ch in chunks if ch.maps is a for q, _ in ch.work]
    assert flat_a == [
        "a.map/scen/3",
        "a.map/scen/1",
        "a.map/scen/2",
        "a.map/scen/0",
        "a.map/scen/4",
    ]
    flat_b = [q.index for ch in chunks if ch.maps is b for q, _ in ch.work]
    assert flat_b == [2, 1, 0, 3]  # 2000 cells, then 400 x 300 (octile 524), 10, 5
    assert query_cost(b.queries[1], 0.05) == pytest.approx(
        25 + 0.05 * (400 + (math.sqrt(2) - 1) * 300)
    )
    assert chunks[0].cost == pytest.approx(2 * (25 + 300) + 1 * (25 + 300))


def test_run_reports_warm_up_wall_time_and_chunk_size(sources, tmp_path):
    from trajopt.analysis.bench._runner import auto_chunk_size

    res = bench.run(
        [sources[0]],
        tmp_path / "a",
        methods=["astar", "bspline-fit"],
        scheduler="serial",
        progress=False,
    )
    assert res.chunk_size == auto_chunk_size(3, 1) and res.chunks == 3
    assert res.warm_up_s > 0 and res.wall_s >= res.elapsed_s + res.warm_up_s
    res = bench.run(
        [sources[0]],
        tmp_path / "b",
        methods=["astar"],
        scheduler="serial",
        progress=False,
        warm_up=False,
        chunk_size=2,
    )
    assert res.warm_up_s == 0 and res.chunk_size == 2 and res.chunks == 2
    with pytest.raises(BenchmarkError, match="chunk_size must be an integer >= 1"):
        bench.run(
            [sources[0]],
            tmp_path / "c",
            methods=["astar"],
            scheduler="serial",
            chunk_size=0,
            progress=False,
        )


def test_warm_up_plans_and_scores_every_method_once():
    from trajopt.analysis.bench._methods import warm_up

    assert warm_up(["astar", "bspline-fit", "trajopt"]) > 0
    with pytest.raises(BenchmarkError, match="method 'rrt' is unknown"):
        warm_up("astar,rrt")


def test_half_written_chunk_is_never_read(sources, tmp_path):
    out = tmp_path / "ds"
    ch = bench.make_chunks([sources[1]], ["astar"], set(), 1)
    bench.write_chunk(out if out.mkdir() is None else out, ch[0].chunk_id, bench.run_chunk(ch[0]))
    (out / ".part-x.parquet.tmp-1").write_bytes(b"PAR1 half a file")
    assert len(bench.read_dataset(out)) == 1


def test_bad_input_is_a_typed_error_before_any_work(shared_data, sources, tmp_path):
    out = tmp_path / "never"
    scen = shared_data / "movingai" / "scen" / "den312d.map.scen"
    with pytest.raises(BenchmarkError, match="does not exist"):
        bench.movingai_queries(scen, shared_data / "movingai" / "maps" / "nowhere.map")
    wrong = tmp_path / "wrong.scen"
    wrong.write_text("version 1\n0\tden312d.map\t10\t12\t1\t1\t2\t2\t1.4\n")
    with pytest.raises(BenchmarkError, match=r"10 x 12 .* is 65 x 81"):
        bench.movingai_queries(wrong, shared_data / "movingai" / "maps" / "den312d.map")
    with pytest.raises(BenchmarkError, match="method 'rrt' is unknown"):
        bench.run(sources, out, methods=["trajopt", "rrt"], progress=False)
    with pytest.raises(BenchmarkError, match="'tcp://127.0.0.1:9' is unreachable"):
        bench.run(
            sources, out, scheduler="tcp://127.0.0.1:9", connect_timeout_s=0.5, progress=False
        )
    with pytest.raises(BenchmarkError, match="scheduler must be"):
        bench.run(sources, out, scheduler="localhost:8786", progress=False)
    with pytest.raises(BenchmarkError, match="suite must be one of"):
        bench.suite("shared-huge", shared_data)
    assert not out.exists()  # nothing was written


def test_missing_peer_names_the_extra(monkeypatch):
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(
        importlib.util, "find_spec", lambda name, *a: None if name == "ompl" else real(name, *a)
    )
    with pytest.raises(PeerUnavailableError, match="install the `peers` extra"):
        bench.check_methods(["trajopt", "ompl-rrtstar"])


def test_existing_dataset_needs_resume(sources, tmp_path):
    out = tmp_path / "ds"
    bench.run([sources[1]], out, methods=["astar"], scheduler="serial", progress=False)
    with pytest.raises(BenchmarkError, match="--resume"):
        bench.run([sources[1]], out, methods=["astar"], scheduler="serial", progress=False)


def test_report_matches_brute_force_counts(serial, tmp_path):
    table = bench.summary(serial)
    for method in METHODS:
        rows = [r for r in serial.to_dict("records") if r["method"] == method]
        ok = [r for r in rows if r["ok"]]
        assert table.loc[method, "queries"] == len(rows)
        assert table.loc[method, "success"] == len(ok)
        assert table.loc[method, "collisions"] == sum(r["collision"] for r in ok)
        times = sorted(r["runtime_s"] * 1e3 for r in ok)
        assert math.isclose(table.loc[method, "compute_median_ms"], float(np.median(times)))
        ratio = [r["min_clearance_m"] / r["radius_m"] for r in ok]
        assert math.isclose(table.loc[method, "min_clearance_over_radius"], np.median(ratio))
    text = bench.format_summary(table)
    assert all(m in text for m in METHODS)
    files = bench.figures(serial, tmp_path / "fig")
    assert [f.name for f in files] == ["distributions.png", "outcomes.png"]
    assert all(f.stat().st_size > 1000 for f in files)


def test_cli_run_and_report(shared_data, tmp_path, capsys):
    from trajopt.cli import main

    out = tmp_path / "cli"
    scen = shared_data / "movingai" / "scen" / "rmtst01.map.scen"
    assert (
        main(
            [
                "bench",
                "run",
                str(scen),
                "--limit",
                "2",
                "--feasible-only",
                "--methods",
                "astar,bspline-fit",
                "--out",
                str(out),
                "--scheduler",
                "serial",
                "--no-progress",
            ]
        )
        == 0
    )
    text = capsys.readouterr().out
    assert "4 rows written" in text and "bspline-fit" in text
    assert main(["bench", "report", str(out), "--figures", str(tmp_path / "f")]) == 0
    assert "astar" in capsys.readouterr().out
    assert (tmp_path / "f" / "distributions.png").is_file()


@pytest.mark.parametrize("method", ["ompl-rrtstar", "ompl-bitstar", "pmp-bspline", "pmp-cubic"])
def test_peer_rows_are_scored(method, sources, monkeypatch):
    import trajopt.analysis.bench._peers as peers

    for mod in bench.METHODS[method].requires:
        pytest.importorskip(mod, reason=f"{method} needs the peers extra")
    monkeypatch.setattr(peers, "OMPL_TIME_LIMIT_S", 0.1)
    ch = bench.make_chunks([sources[1]], [method], set(), 1)[0]
    row = bench.run_chunk(ch)[0]
    assert row["method"] == method
    if row["ok"]:  # a path: scored by the same metrics, a collision is a value
        assert row["n_samples"] > 0 and isinstance(row["collision"], bool)
        assert math.isfinite(row["min_clearance_m"]) and math.isfinite(row["runtime_s"])
    else:
        assert row["failure"] == "PeerFailure"


def test_the_default_data_folder_is_beside_the_checkout(monkeypatch):
    # shared/data next to the checkout that holds the package (no $TRAJOPT_DATA)
    monkeypatch.delenv("TRAJOPT_DATA", raising=False)
    expected = REPO.parent / "shared" / "data"
    if not (expected / "movingai").is_dir():
        pytest.skip(f"no shared data at {expected}")
    assert data_dir() == expected
