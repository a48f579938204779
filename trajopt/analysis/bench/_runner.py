"""Running a benchmark: chunks of queries on Dask distributed, rows into the dataset.

:func:`run` checks everything first (maps and scenario files were checked when the
:class:`~trajopt.analysis.bench._suites.MapQueries` were made; here the methods, the scheduler
address and the dataset folder), then cuts the (query, method) pairs the dataset does not
hold yet into :class:`Chunk` tasks of ``chunk_size`` queries of one map
(:func:`make_chunks`; by default :func:`auto_chunk_size`: at least
:data:`TASKS_PER_WORKER` tasks per worker, at most :data:`MAX_AUTO_CHUNK` queries each),
longest first, and submits them:

* ``scheduler="local"`` (default): a :class:`distributed.LocalCluster` of ``workers``
  processes (default one per core, one thread each) started for the run and closed after;
  the workers get this process's ``sys.path`` entry of :mod:`trajopt` on their
  ``PYTHONPATH``, so they import the same code;
* ``scheduler="tcp://host:8786"`` (any Dask address): an existing scheduler (its workers
  need ``trajopt`` installed and the map files at the same paths);
* ``scheduler="serial"``: in this process, no Dask (the reference for the tests).

Before the clock starts, every worker (or this process, for ``"serial"``) runs
:func:`~trajopt.analysis.bench._methods.warm_up`: one small query with every method, which pays
the process's imports, numba kernel loads and solver plugin loads (about 1-3 s in a fresh
process; ``warm_up=False`` leaves them in the measured time). :class:`RunSummary` reports
the measured time (``elapsed_s``), the warm-up and the end-to-end wall time apart.

A worker runs a chunk with :func:`run_chunk` (the map is loaded and inflated once per
worker, :func:`~trajopt.analysis.bench._methods.map_context`); the client writes each finished
chunk to its own Parquet file (:func:`~trajopt.analysis.bench._dataset.write_chunk`, atomic) as it
arrives, with a ``tqdm`` progress bar counting rows. A chunk whose worker dies is
rescheduled by Dask and also retried ``retries`` times on an exception; as files are
named by chunk, a retried chunk replaces its own file and never duplicates rows.
"""

from __future__ import annotations

import hashlib
import logging
import math
import os
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from trajopt.analysis.bench._dataset import existing_keys, prepare, write_chunk
from trajopt.analysis.bench._methods import check_methods, evaluate_query, map_context
from trajopt.analysis.bench._suites import MapQueries, Query, draw_headings
from trajopt.errors import BenchmarkError

logger = logging.getLogger(__name__)

#: :func:`auto_chunk_size` makes at least this many tasks per worker (when there are
#: enough queries), so that the last tasks to finish are short and no worker idles long.
TASKS_PER_WORKER = 8
#: ... and at most this many queries per task (fewer tasks and files on large suites).
MAX_AUTO_CHUNK = 4
#: Dask settings of the local cluster (:func:`connect`). Its periodic monitors (each
#: worker's statistical profiler every 10 ms, the memory monitor every 100 ms, the event-loop
#: tick every 20 ms, the system monitor every 500 ms) feed a dashboard the local cluster
#: does not start, and took 0.14 of a core with 2 idle workers on the 2-core machine (0.016
#: with these settings): time taken from the workers when every core runs one.
LOCAL_DASK_CONFIG: dict[str, Any] = {
    "distributed.worker.profile.enabled": False,
    "distributed.worker.memory.monitor-interval": "1s",
    "distributed.admin.tick.interval": "1s",
    "distributed.admin.system-monitor.interval": "2s",
}
#: Fixed part of :func:`query_cost`, in metres of path: a short query still costs the
#: reference search, the corridor, the fits and the scoring of every method (about as
#: much as 25 m of trajectory, measured on ``shared-small``).
_COST_FIXED_M = 25.0


@dataclass(frozen=True, slots=True)
class Chunk:
    """One task: some queries of one map, each with the methods still to run.

    Attributes
    ----------
    chunk_id : str
        ``<map stem>-<12 hex digits of a hash of the work>``; names the Parquet file.
    maps : MapQueries
        The map (its ``queries`` are not used here).
    work : tuple of (Query, tuple of str)
        The queries and their methods.
    """

    chunk_id: str
    maps: MapQueries
    work: tuple[tuple[Query, tuple[str, ...]], ...]

    @property
    def n_rows(self) -> int:
        """Rows this chunk writes."""
        return sum(len(m) for _, m in self.work)

    @property
    def cost(self) -> float:
        """Estimated compute cost (:func:`query_cost` x methods, summed; no unit)."""
        return sum(query_cost(q, self.maps.resolution_m) * len(m) for q, m in self.work)


@dataclass(frozen=True, slots=True)
class RunSummary:
    """What :func:`run` did.

    Attributes
    ----------
    out : Path
        The dataset folder.
    rows_expected : int
        Queries x methods of the run.
    rows_skipped : int
        Pairs the dataset already held (``resume``).
    rows_written : int
        Rows written by this call.
    chunks : int
        Chunks run by this call.
    elapsed_s : float
        Wall time of the computation (s), from the first submission to the last file:
        the workers' warm-up is not in it (``warm_up_s``).
    workers : int
        Worker processes (1 for ``"serial"``).
    warm_up_s : float
        Wall time of the warm-up of every worker before the clock (s; 0 without it).
    wall_s : float
        End-to-end wall time of the call (s): checks, starting and closing a local
        cluster, the warm-up and the computation.
    chunk_size : int
        Queries per chunk used.
    """

    out: Path
    rows_expected: int
    rows_skipped: int
    rows_written: int
    chunks: int
    elapsed_s: float
    workers: int
    warm_up_s: float = 0.0
    wall_s: float = 0.0
    chunk_size: int = 0


def query_cost(q: Query, resolution_m: float) -> float:
    """Estimate the compute cost of one (query, method) pair roughly, to run long ones first.

    ``25 + L``, with ``L`` the path length in metres: the scenario's optimal length
    when known, else the octile distance between the end cells. The timing and the
    trajectory metrics, which dominate long queries, grow with the trajectory's duration,
    i.e. with its length in metres; the constant stands for the per-query costs.
    """
    length = q.optimal_length_cells
    if not math.isfinite(length):
        dx, dy = abs(q.goal[0] - q.start[0]), abs(q.goal[1] - q.start[1])
        length = max(dx, dy) + (math.sqrt(2.0) - 1.0) * min(dx, dy)
    return _COST_FIXED_M + float(length) * float(resolution_m)


def auto_chunk_size(n_queries: int, n_workers: int) -> int:
    """Return the queries per chunk when none is given.

    ``n_queries // (TASKS_PER_WORKER * n_workers)`` clipped to ``[1, MAX_AUTO_CHUNK]``:
    many small tasks balance the workers (``shared-small``, 20 queries, on 2 workers: one
    query per task); large suites keep chunks of 4 queries.
    """
    return max(1, min(MAX_AUTO_CHUNK, n_queries // (TASKS_PER_WORKER * max(1, n_workers))))


def make_chunks(
    sources: Sequence[MapQueries],
    methods: Sequence[str],
    done: set[tuple[str, str]],
    chunk_size: int,
) -> list[Chunk]:
    """Cut the (query, method) pairs not in ``done`` into chunks, in the order to run them.

    Chunks hold ``chunk_size`` queries of one map. The order is longest first at two
    levels (by :func:`query_cost`), so the last tasks to finish are short: the maps by
    their total cost, and within a map the queries (ties in query order), cut into chunks
    in that order. A worker thus moves from map to map and loads each at most once
    while the maps' chunks last, and the last chunks are the cheapest map's shortest
    queries. Chunk ids hash the work, so a chunk's file is the same in every run that
    cuts it the same way.
    """
    per_map: list[tuple[float, int, list[Chunk]]] = []
    for k, mq in enumerate(sources):
        todo = []
        for q in mq.queries:
            ms = tuple(m for m in methods if (q.query_id, m) not in done)
            if ms:
                todo.append((q, ms))
        todo.sort(key=lambda w: -query_cost(w[0], mq.resolution_m) * len(w[1]))  # stable
        chunks: list[Chunk] = []
        for i in range(0, len(todo), chunk_size):
            work = tuple(todo[i : i + chunk_size])
            h = hashlib.sha1(repr([(q.query_id, ms) for q, ms in work]).encode()).hexdigest()
            stem = Path(mq.map_name).stem.replace(" ", "_")
            chunks.append(Chunk(f"{stem}-{h[:12]}", mq, work))
        per_map.append((sum(c.cost for c in chunks), k, chunks))
    per_map.sort(key=lambda t: (-t[0], t[1]))
    return [c for _, _, chunks in per_map for c in chunks]


def run_chunk(chunk: Chunk) -> list[dict[str, Any]]:
    """Plan and score every (query, method) of a chunk; the rows (plain dicts).

    Runs in a worker process (or in this one for ``scheduler="serial"``).
    """
    mq = chunk.maps
    mctx = map_context(mq.map_path, mq.radius_m)
    worker = f"{os.uname().nodename}:{os.getpid()}"
    rows: list[dict[str, Any]] = []
    for q, methods in chunk.work:
        base = {
            "map": mq.map_name,
            "source": mq.source,
            "query_id": q.query_id,
            "query_index": q.index,
            "bucket": q.bucket,
            "start_ix": q.start[0],
            "start_iy": q.start[1],
            "goal_ix": q.goal[0],
            "goal_iy": q.goal[1],
            "optimal_length_cells": q.optimal_length_cells,
            "radius_m": mq.radius_m,
            "resolution_m": mq.resolution_m,
            "worker": worker,
        }
        headings = (q.start_heading, q.goal_heading)
        if not all(math.isfinite(h) for h in headings):
            headings = draw_headings(mq.map_name, q.index, 0)  # only the car methods read them
        for r in evaluate_query(mctx, q.start, q.goal, methods, headings=headings):
            rows.append({**base, **r})
    return rows


def worker_env() -> dict[str, str]:
    import trajopt

    root = str(Path(trajopt.__file__).resolve().parents[1])
    paths = [root] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]
    return {
        "PYTHONPATH": os.pathsep.join(dict.fromkeys(paths)),
        "OMP_NUM_THREADS": "1",
        "OPENBLAS_NUM_THREADS": "1",
        "MKL_NUM_THREADS": "1",
    }


def _quiet_dask() -> None:
    """Keep the in-process scheduler's INFO lines off the terminal.

    Keep the in-process scheduler's INFO lines off the terminal unless the root logger is at
    INFO or below (``trajopt -v``): dask gives its loggers their own levels.
    """
    if logging.getLogger().getEffectiveLevel() <= logging.INFO:
        return
    names = [n for n in logging.root.manager.loggerDict if n.startswith("distributed")]
    for name in ["distributed", *names]:
        logging.getLogger(name).setLevel(logging.WARNING)


def connect(scheduler: str, *, workers: int | None = None, timeout_s: float = 10.0) -> Any:
    """Return a :class:`distributed.Client` for ``scheduler`` (``"local"`` or an address).

    With ``"local"`` the client owns a new :class:`distributed.LocalCluster` of
    ``workers`` processes (default ``os.cpu_count()``, one thread each, no dashboard, the
    quiet monitors of :data:`LOCAL_DASK_CONFIG`), closed with the client
    (``client.close(); client.cluster.close()``).

    Raises
    ------
    BenchmarkError
        Malformed address, or no scheduler answering at it within ``timeout_s``.
    """
    import dask
    from distributed import Client, LocalCluster

    if scheduler == "local":
        _quiet_dask()
        n = workers or os.cpu_count() or 1
        with dask.config.set(LOCAL_DASK_CONFIG):  # the workers get it when they start
            cluster = LocalCluster(
                n_workers=n,
                threads_per_worker=1,
                processes=True,
                dashboard_address=None,
                silence_logs=logging.ERROR,
                env=worker_env(),
            )
            return Client(cluster)
    if "://" not in scheduler or not scheduler.split("://", 1)[1]:
        raise BenchmarkError(
            f"scheduler must be 'local', 'serial' or a Dask address like "
            f"'tcp://host:8786', got {scheduler!r}"
        )
    try:
        return Client(scheduler, timeout=timeout_s)
    except (OSError, TimeoutError, ValueError) as exc:
        raise BenchmarkError(
            f"scheduler {scheduler!r} is unreachable (no answer within {timeout_s} s): {exc}"
        ) from exc


def run(
    sources: Sequence[MapQueries],
    out: str | os.PathLike[str],
    *,
    methods: Sequence[str] | str | None = None,
    scheduler: str = "local",
    workers: int | None = None,
    chunk_size: int | None = None,
    resume: bool = False,
    retries: int = 2,
    progress: bool = True,
    client: Any = None,
    connect_timeout_s: float = 10.0,
    warm_up: bool = True,
) -> RunSummary:
    """Run ``methods`` on every query of ``sources`` and write the rows to ``out``.

    Parameters
    ----------
    sources : sequence of MapQueries
        Maps and queries (:func:`~trajopt.analysis.bench._suites.suite`,
        :func:`~trajopt.analysis.bench._suites.movingai_queries`, ...).
    out : path
        Dataset folder (created; must be new or empty unless ``resume``).
    methods : sequence of str or comma-separated str, optional
        Method names (:data:`~trajopt.analysis.bench._methods.METHODS`); default
        :data:`~trajopt.analysis.bench._methods.DEFAULT_METHODS`.
    scheduler : str
        ``"local"``, ``"serial"`` or a Dask scheduler address (module docstring).
    workers : int, optional
        Worker processes of the local cluster (default one per core).
    chunk_size : int, optional
        Queries per task (>= 1); default :func:`auto_chunk_size` of the queries to run
        and the workers.
    resume : bool
        Skip the (query, method) pairs ``out`` already holds.
    retries : int
        Extra attempts of a chunk that raised (worker deaths are rescheduled anyway).
    progress : bool
        Show a tqdm progress bar on stderr.
    client : distributed.Client, optional
        Use this client instead of ``scheduler`` (not closed).
    connect_timeout_s : float
        How long to wait for a remote scheduler (s).
    warm_up : bool
        Run :func:`~trajopt.analysis.bench._methods.warm_up` on every worker before the clock
        starts (``RunSummary.warm_up_s``).

    Returns
    -------
    RunSummary

    Raises
    ------
    BenchmarkError
        No queries, an unknown method, a bad option, an unreachable scheduler, a dataset
        folder holding another run: all before any query is planned.
    PeerUnavailableError
        A peer method whose package is missing.
    """
    from trajopt.analysis.bench._methods import DEFAULT_METHODS
    from trajopt.analysis.bench._methods import warm_up as warm_up_worker

    t_call = time.perf_counter()
    names = check_methods(DEFAULT_METHODS if methods is None else methods)
    srcs = list(sources)
    if not srcs or not any(mq.queries for mq in srcs):
        raise BenchmarkError("sources must hold at least one query")
    ids = [q.query_id for mq in srcs for q in mq.queries]
    if len(set(ids)) != len(ids):
        raise BenchmarkError("query ids must be unique: a map and source appear twice")
    for nm, v, lo in (
        ("chunk_size", 1 if chunk_size is None else chunk_size, 1),
        ("retries", retries, 0),
        ("workers", 1 if workers is None else workers, 1),
    ):
        if isinstance(v, bool) or not isinstance(v, int) or v < lo:
            raise BenchmarkError(f"{nm} must be an integer >= {lo}, got {v!r}")
    if client is None and scheduler != "serial" and scheduler != "local" and "://" not in scheduler:
        raise BenchmarkError(
            f"scheduler must be 'local', 'serial' or a Dask address like 'tcp://host:8786', "
            f"got {scheduler!r}"
        )
    serial = client is None and scheduler == "serial"
    own_client = None
    if client is None and scheduler not in ("serial", "local"):
        own_client = connect(scheduler, timeout_s=connect_timeout_s)  # fail before writing
    warm_s = 0.0
    try:
        d = prepare(out, {"radius_m": {mq.map_name: mq.radius_m for mq in srcs}}, resume=resume)
        done = existing_keys(d) if resume else set()
        expected = len(ids) * len(names)
        skipped = sum(1 for i in ids for m in names if (i, m) in done)
        n_todo = sum(1 for i in ids if any((i, m) not in done for m in names))
        n_workers = 1
        cl = None
        if not serial and n_todo:
            if client is None and own_client is None:
                own_client = connect("local", workers=workers)
            cl = client if client is not None else own_client
            n_workers = max(1, len(cl.scheduler_info()["workers"]))
        size = chunk_size if chunk_size is not None else auto_chunk_size(n_todo, n_workers)
        chunks = make_chunks(srcs, names, done, size)
        if warm_up and chunks:
            t_warm = time.perf_counter()
            if cl is None:
                warm_up_worker(names)
            else:
                cl.run(warm_up_worker, names)  # every worker, in parallel; waits for all
            warm_s = time.perf_counter() - t_warm
        from tqdm.auto import tqdm

        bar = tqdm(
            total=expected,
            initial=skipped,
            unit="row",
            desc="bench",
            disable=not progress,
            file=sys.stderr,
            dynamic_ncols=True,
        )
        written = 0
        t0 = time.perf_counter()
        try:
            if cl is None:
                for ch in chunks:
                    rows = run_chunk(ch)
                    write_chunk(d, ch.chunk_id, rows)
                    written += len(rows)
                    bar.update(len(rows))
            elif chunks:
                from distributed import as_completed

                # make_chunks' order (longest first) as Dask priorities: a queued task
                # with a higher priority is handed to the next free worker first
                futures = {
                    cl.submit(
                        run_chunk,
                        ch,
                        key=f"trajopt-bench-{ch.chunk_id}",
                        retries=retries,
                        pure=False,
                        priority=len(chunks) - k,
                    ): ch
                    for k, ch in enumerate(chunks)
                }
                for fut in as_completed(futures):
                    ch = futures[fut]
                    rows = fut.result()
                    write_chunk(d, ch.chunk_id, rows)
                    written += len(rows)
                    bar.update(len(rows))
                    fut.release()
        finally:
            bar.close()
        elapsed = time.perf_counter() - t0
    finally:
        if own_client is not None:
            cluster = getattr(own_client, "cluster", None)  # the local cluster, else None
            own_client.close()
            if cluster is not None:
                cluster.close()
    if written + skipped != expected:  # a chunk returned a wrong number of rows
        raise BenchmarkError(
            f"wrote {written} rows and skipped {skipped}, expected {expected} (queries x methods)"
        )
    return RunSummary(
        Path(d),
        expected,
        skipped,
        written,
        len(chunks),
        elapsed if math.isfinite(elapsed) else 0.0,
        n_workers,
        warm_s,
        time.perf_counter() - t_call,
        size,
    )
