"""The benchmark commands: ``bench run`` and ``bench report``.

``bench run`` runs maps x queries x methods into a Parquet dataset; ``bench report`` prints its
summary table and writes its figures.
"""

from __future__ import annotations

import argparse
from typing import Any

from trajopt.cli._common import CliError


def add_parsers(sub: Any) -> None:
    """Add ``bench`` (with ``run`` and ``report``) to the subparsers ``sub``."""
    p = sub.add_parser(
        "bench",
        help="benchmark methods on maps and scenarios (Dask, Parquet dataset)",
        description="Run maps x queries x methods on Dask distributed into a Parquet "
        "dataset (bench run), and summarise a dataset (bench report).",
    )
    bsub = p.add_subparsers(dest="bench_command", metavar="{run,report}", required=True)
    r = bsub.add_parser(
        "run",
        help="run methods on scenario files, maps or a named suite",
        description="Each INPUT is a Moving AI .scen file (its map found beside it or in "
        "../maps, or given with --map) or a map file (.yaml, .map) for seeded random "
        "queries (--queries, --seed). Rows, one per (query, method), go to the Parquet "
        "dataset --out; the summary table is printed at the end.",
    )
    r.add_argument("inputs", metavar="INPUT", nargs="*", help=".scen or map files")
    r.add_argument("--suite", help="a named suite: shared-small or shared-full")
    r.add_argument("--data", help="shared data folder for --suite (default $TRAJOPT_DATA)")
    r.add_argument("--map", help="the .map of a single .scen INPUT")
    r.add_argument("--out", required=True, help="dataset folder (Parquet files)")
    r.add_argument("--resume", action="store_true", help="skip rows the dataset already holds")
    r.add_argument("--methods", help="comma-separated methods (default: all but the peers)")
    r.add_argument("--limit", type=int, help="scenarios (or random queries) per map")
    r.add_argument(
        "--queries", type=int, default=20, help="random queries per map INPUT (default 20)"
    )
    r.add_argument("--seed", type=int, default=0, help="seed of the random queries (default 0)")
    r.add_argument(
        "--radius-cells",
        type=float,
        default=2.5,
        help="robot radius on Moving AI maps, in cells (default 2.5)",
    )
    r.add_argument(
        "--radius", type=float, default=0.165, help="robot radius on other maps [m] (default 0.165)"
    )
    r.add_argument(
        "--feasible-only",
        action="store_true",
        help="keep only scenarios whose end cells are free for the radius",
    )
    r.add_argument(
        "--scheduler",
        default="local",
        help="'local' (LocalCluster, default), 'serial', or tcp://host:8786",
    )
    r.add_argument("--workers", type=int, help="local worker processes (default: cores)")
    r.add_argument(
        "--chunk-size",
        type=int,
        help="queries per task (default: at least 8 tasks per worker, at most 4 queries each)",
    )
    r.add_argument("--no-progress", action="store_true", help="no progress bar")
    r.set_defaults(func=_cmd_bench_run)
    r = bsub.add_parser(
        "report",
        help="summary table and figures of a dataset",
        description="Prints the per-method summary of a dataset written by bench run and "
        "writes distribution figures with --figures.",
    )
    r.add_argument("dataset", metavar="DATASET", help="dataset folder (or .parquet file)")
    r.add_argument("--figures", help="folder for the figures (PNG)")
    r.set_defaults(func=_cmd_bench_report)


def _bench_sources(args: argparse.Namespace) -> list[Any]:
    from trajopt.analysis import bench

    if args.limit is not None and args.limit < 1:
        raise CliError(f"--limit must be >= 1, got {args.limit}")
    if not args.inputs and not args.suite:
        raise CliError("give INPUT files or --suite")
    if args.map and len(args.inputs) != 1:
        raise CliError(f"--map needs exactly one .scen INPUT, got {len(args.inputs)}")
    sources = []
    if args.suite:
        sources += bench.suite(
            args.suite,
            args.data,
            limit=args.limit,
            radius_cells=args.radius_cells,
            radius_m=args.radius,
            seed=args.seed,
        )
    for item in args.inputs:
        if item.endswith(".scen"):
            sources.append(
                bench.movingai_queries(
                    item,
                    args.map,
                    limit=args.limit,
                    radius_cells=args.radius_cells,
                    feasible_only=args.feasible_only,
                )
            )
        else:
            n = args.queries if args.limit is None else min(args.queries, args.limit)
            sources.append(bench.random_queries(item, n, seed=args.seed, radius_m=args.radius))
    return sources


def _cmd_bench_run(args: argparse.Namespace) -> int:
    from trajopt.analysis import bench

    sources = _bench_sources(args)
    res = bench.run(
        sources,
        args.out,
        methods=args.methods,
        scheduler=args.scheduler,
        workers=args.workers,
        chunk_size=args.chunk_size,
        resume=args.resume,
        progress=not args.no_progress,
    )
    print(
        f"{res.rows_written} rows written, {res.rows_skipped} already held, "
        f"{res.rows_expected} in all ({res.chunks} chunks, {res.workers} workers, "
        f"{res.elapsed_s:.1f} s) -> {res.out}"
    )
    print(bench.report(res.out))
    return 0


def _cmd_bench_report(args: argparse.Namespace) -> int:
    from trajopt.analysis import bench

    print(bench.report(args.dataset, figures_dir=args.figures))
    if args.figures:
        print(f"wrote figures to {args.figures}/")
    return 0
