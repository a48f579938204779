"""The benchmark harness itself (issue 22): Dask scaling, kill + resume, report speed.

In one run:

1. **Throughput, 1 vs 2 workers** on the same queries: a local cluster of 1 worker
   process, then one of 2 (``bench.connect``, one thread each); every worker first plans one warm-up query
   per map (map load and inflation, numba cache load, first CasADi solver builds), then :func:`trajopt.bench.run` is timed from
   the first submission to the last Parquet file. Rows per second and the ratio.
2. **Kill and resume**: ``trajopt bench run`` (local cluster) in a subprocess, SIGKILL once
   about half the chunk files exist, then ``--resume``: the dataset must hold every
   (query, method) exactly once, the finished files untouched, and equal the complete run
   (every column but wall times).
3. **Report speed**: the rows of step 1 copied to ``--report-rows`` rows (new query ids, 20
   files), then ``trajopt.analysis.bench._report`` (read + summary table) and the figures, timed.

Run::

    python benchmarks/bench_harness.py                      # ~24 queries x 4 methods
    python benchmarks/bench_harness.py --limit 12 --methods trajopt,bspline-fit

``TRAJOPT_DATA`` may point to the shared data (default ``../shared/data`` beside the repo).
"""

from __future__ import annotations

import argparse
import functools
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import numpy as np  # noqa: E402

from trajopt.analysis import bench  # noqa: E402
from trajopt.analysis.bench._dataset import TIMING_COLUMNS, part_files  # noqa: E402

MAPS = ("den312d", "rmtst01", "Berlin_0_256")


def sources(data: Path, limit: int) -> list[bench.MapQueries]:
    return [
        bench.movingai_queries(
            data / "movingai" / "scen" / f"{m}.map.scen",
            data / "movingai" / "maps" / f"{m}.map",
            limit=limit,
            feasible_only=True,
        )
        for m in MAPS
    ]


def timed_run(srcs, methods, workers: int, out: Path, chunk_size: int) -> tuple[float, int]:
    client = bench.connect("local", workers=workers)  # the command line's local cluster
    cluster = client.cluster
    try:
        for src in srcs:  # every worker loads every map and plans one query of it, once
            warm = bench.make_chunks([src], methods, set(), 1)[0]
            client.run(functools.partial(bench.run_chunk, warm))
        res = bench.run(
            srcs, out, methods=methods, client=client, chunk_size=chunk_size, progress=False
        )
    finally:
        client.close()
        cluster.close()
    return res.elapsed_s, res.rows_written


def same_rows(a, b) -> bool:
    a = a.sort_values(["query_id", "method"]).reset_index(drop=True)
    b = b.sort_values(["query_id", "method"]).reset_index(drop=True)
    if len(a) != len(b):
        return False
    for col in bench.COLUMNS:
        if col in TIMING_COLUMNS:
            continue
        x, y = a[col].to_numpy(), b[col].to_numpy()
        eq = np.array_equal(x, y, equal_nan=True) if x.dtype.kind == "f" else (x == y).all()
        if not eq:
            print(f"  column {col} differs")
            return False
    return True


def kill_and_resume(data: Path, limit: int, methods, tmp: Path, reference) -> None:
    out = tmp / "killed"
    cmd = [sys.executable, "-m", "trajopt.cli", "bench", "run"]
    cmd += [str(data / "movingai" / "scen" / f"{m}.map.scen") for m in MAPS[:1]]
    cmd += [
        "--limit",
        str(limit),
        "--feasible-only",
        "--methods",
        ",".join(methods),
        "--out",
        str(out),
        "--workers",
        "2",
        "--chunk-size",
        "1",
        "--no-progress",
    ]
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    n_chunks = len(bench.make_chunks(sources(data, limit)[:1], methods, set(), 1))
    proc = subprocess.Popen(
        cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True
    )
    while len(part_files(out)) < n_chunks // 2 and proc.poll() is None:
        time.sleep(0.01)
    os.killpg(proc.pid, signal.SIGKILL)  # the CLI and its cluster's processes
    proc.wait()
    before = {p.name: p.read_bytes() for p in part_files(out)}
    t0 = time.perf_counter()
    subprocess.run(
        cmd + ["--resume"],
        env=env,
        check=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    dt = time.perf_counter() - t0
    df = bench.read_dataset(out)
    untouched = all((out / n).read_bytes() == b for n, b in before.items())
    dup = int(df.duplicated(["query_id", "method"]).sum())
    ref = reference[reference["map"] == f"{MAPS[0]}.map"]
    print(
        f"kill + resume: killed with {len(before)} of {n_chunks} chunk files; resume "
        f"{dt:.1f} s; rows {len(df)} (expected {len(ref)}), duplicates {dup}, finished "
        f"files untouched {untouched}, equal to the complete run {same_rows(df, ref)}"
    )


def report_speed(df, n_rows: int, tmp: Path) -> None:
    import pandas as pd
    import pyarrow as pa
    import pyarrow.parquet as pq

    out = tmp / "big"
    out.mkdir()
    reps = int(np.ceil(n_rows / len(df)))
    big = pd.concat([df.assign(query_id=df["query_id"] + f"#{i}") for i in range(reps)])
    big = big.iloc[:n_rows]
    for i, part in enumerate(np.array_split(np.arange(len(big)), 20)):
        pq.write_table(
            pa.Table.from_pandas(
                big.iloc[part], schema=bench.dataset.schema(), preserve_index=False
            ),
            out / f"part-{i:02d}.parquet",
        )
    t0 = time.perf_counter()
    text = bench.report(out)
    t_table = time.perf_counter() - t0
    t0 = time.perf_counter()
    bench.report(out, figures_dir=tmp / "figs")
    t_fig = time.perf_counter() - t0
    print(f"report on {len(big)} rows: table {t_table:.2f} s, table + figures {t_fig:.2f} s")
    print(text)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--limit", type=int, default=8, help="feasible scenarios per map")
    ap.add_argument("--methods", default="trajopt,trajopt-shortest,astar,bspline-fit")
    ap.add_argument("--chunk-size", type=int, default=1)
    ap.add_argument("--report-rows", type=int, default=100_000)
    args = ap.parse_args()
    data = bench.suites.data_dir()
    methods = bench.check_methods(args.methods)
    srcs = sources(data, args.limit)
    n_q = sum(len(s.queries) for s in srcs)
    print(f"{n_q} queries on {', '.join(MAPS)} x {len(methods)} methods, {os.cpu_count()} cores")
    tmp = Path(tempfile.mkdtemp(prefix="bench_harness_"))
    try:
        res = {}
        for w in (1, 2):
            elapsed, rows = timed_run(srcs, methods, w, tmp / f"w{w}", args.chunk_size)
            res[w] = rows / elapsed
            df = bench.read_dataset(tmp / f"w{w}")
            busy = float(np.nansum(df["runtime_s"]) + np.nansum(df["reference_search_s"]))
            print(
                f"{w} worker(s): {rows} rows in {elapsed:.2f} s = {res[w]:.2f} rows/s; "
                f"methods' compute {busy:.2f} s = {busy / (elapsed * w):.0%} of "
                f"{w} x wall (load average before: {os.getloadavg()[0]:.2f})"
            )
        print(f"throughput 2 workers / 1 worker: {res[2] / res[1]:.2f}x")
        d1, d2 = bench.read_dataset(tmp / "w1"), bench.read_dataset(tmp / "w2")
        print(f"1-worker and 2-worker rows equal (all but wall times): {same_rows(d1, d2)}")
        kill_and_resume(data, args.limit, methods, tmp, d1)
        report_speed(d1, args.report_rows, tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
