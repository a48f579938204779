"""Benchmarks at scale: maps x queries x methods on Dask, rows in a Parquet dataset.

::

    from trajopt.analysis import bench

    sources = bench.suite("shared-small")                 # or movingai_queries / random_queries
    bench.run(sources, "out/small", methods=["trajopt", "bspline-fit"])   # LocalCluster
    print(bench.report("out/small", figures_dir="out/small-figures"))
    df = bench.read_dataset("out/small")                   # pandas, one row per (query, method)

Modules, one thing each: :mod:`~trajopt.analysis.bench._suites` (maps, queries, named suites),
:mod:`~trajopt.analysis.bench._methods` (the methods and the shared scoring),
:mod:`~trajopt.analysis.bench._peers` (OMPL and python-motion-planning, optional),
:mod:`~trajopt.analysis.bench._records` (a method's output and a peer's failure, shared by both),
:mod:`~trajopt.analysis.bench._runner` (chunks on Dask distributed),
:mod:`~trajopt.analysis.bench._dataset` (the Parquet files), :mod:`~trajopt.analysis.bench._report`
(summary table and figures). Needs the ``bench`` extra (dask[distributed], pyarrow, tqdm,
pandas); the peers need the ``peers`` extra.
"""

from trajopt.analysis.bench._dataset import COLUMNS, TIMING_COLUMNS, read_dataset, write_chunk
from trajopt.analysis.bench._methods import DEFAULT_METHODS, METHODS, check_methods, evaluate_query
from trajopt.analysis.bench._report import figures, format_summary, report, summary
from trajopt.analysis.bench._runner import Chunk, RunSummary, connect, make_chunks, run, run_chunk
from trajopt.analysis.bench._suites import (
    SUITES,
    MapQueries,
    Query,
    movingai_queries,
    random_queries,
    select_evenly,
    suite,
)

__all__ = [
    "COLUMNS",
    "TIMING_COLUMNS",
    "DEFAULT_METHODS",
    "METHODS",
    "SUITES",
    "Chunk",
    "MapQueries",
    "Query",
    "RunSummary",
    "check_methods",
    "connect",
    "evaluate_query",
    "figures",
    "format_summary",
    "make_chunks",
    "movingai_queries",
    "random_queries",
    "read_dataset",
    "report",
    "run",
    "run_chunk",
    "select_evenly",
    "suite",
    "summary",
    "write_chunk",
]
