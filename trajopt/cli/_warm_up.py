"""Compiling the numba kernels: the ``warm-up`` command and the compile notice.

Before a planning command in a new environment the kernels compile in worker processes, and a
line on stderr says so.
"""

from __future__ import annotations

import argparse
import logging
import os
import sys
import time
from collections.abc import Sequence
from typing import Any

from trajopt.cli._common import CliError

#: commands that plan
_PLANNING = ("plan", "compare", "demo", "bench")


def add_parser(sub: Any) -> None:
    """Add ``warm-up`` to the subparsers ``sub``."""
    p = sub.add_parser(
        "warm-up",
        help="compile and load every compiled kernel (once per environment)",
        description="Compile every numba kernel of astar and trajopt that numba's disk cache "
        "does not hold yet (in worker processes), then load them all and plan one small "
        "query. Run it once after installing (a container build, a CI cache step) so that "
        "no later command compiles.",
    )
    p.add_argument(
        "--workers",
        type=int,
        default=None,
        help="worker processes that compile (default: min(2, CPUs); 1: this one)",
    )
    p.set_defaults(func=_cmd_warm_up)


def _cmd_warm_up(args: argparse.Namespace) -> int:
    import trajopt.kernel_cache as kernel_cache
    import trajopt.warmup as warm

    if args.workers is not None and args.workers < 1:
        raise CliError(f"--workers must be >= 1, got {args.workers}")
    t0 = time.perf_counter()
    report = _compile_kernels(None, args.workers)
    if report.cold and not report.failed:
        print(
            f"compiled {len(report.compiled)} of {len(report.cold)} uncached kernels in "
            f"{report.seconds:.1f} s ({report.workers or 1} process(es))"
        )
    for name, error in report.failed.items():
        print(f"trajopt warm-up: exercise {name!r} failed: {error}", file=sys.stderr)
    warm.warm_up()
    n = len(kernel_cache.kernels())
    left = kernel_cache.cold_kernels()
    print(
        f"{n - len(left)} of {n} kernels compiled and loaded; warm-up took "
        f"{time.perf_counter() - t0:.1f} s"
    )
    if left:
        print(f"trajopt warm-up: not compiled: {', '.join(left)}", file=sys.stderr)
        return 1
    return 0


def _compile_kernels(first: Sequence[str] | None, workers: int | None) -> Any:
    """Compile the uncached kernels with a notice on stderr; a progress bar on a terminal.

    With ``first`` (warm-up exercises) it returns when those are compiled, the rest going on
    in the background (the report's ``wait()``).
    """
    import trajopt.kernel_cache as kernel_cache

    cold = kernel_cache.cold_kernels()
    if not cold:
        return kernel_cache.CompileReport()
    import trajopt.warmup as warm

    n_workers = workers if workers is not None else min(2, os.cpu_count() or 1)
    about = kernel_cache.estimate_seconds(len(cold), n_workers)
    print(
        f"trajopt: compiling numerical kernels once for this environment (about "
        f"{about:.0f} s; later runs load them from numba's cache)...",
        file=sys.stderr,
        flush=True,
    )
    bar = None
    if sys.stderr.isatty():
        try:
            from tqdm import tqdm

            bar = tqdm(total=len(cold), unit="kernel", file=sys.stderr, leave=False)
        except ImportError:
            pass

    def progress(done: int, total: int, kernel: str) -> None:
        if bar is not None:
            bar.n = done
            bar.set_postfix_str(kernel.rsplit(".", 1)[-1], refresh=True)

    try:
        report = warm.compile_kernels(workers=n_workers, progress=progress, first=first)
    finally:
        if bar is not None:
            bar.close()
    if first is None:
        print(
            f"trajopt: compiled {len(report.compiled)} kernels in {report.seconds:.1f} s",
            file=sys.stderr,
            flush=True,
        )
    return report


def compile_notice(args: argparse.Namespace) -> Any:
    """Before a planning command: compile what is not cached, and say so (stderr).

    The kernels of a default plan and of the comparison come first; the command starts when
    they are compiled while the worker processes go on with the others (the returned
    report's ``wait()``, called when the command is done). A kernel the command needs that
    is not compiled yet compiles when first used, with the library's one-line notice (logger
    ``trajopt.kernel_cache``) on stderr.
    """
    if args.command not in _PLANNING or getattr(args, "bench_command", "run") != "run":
        return None
    import trajopt.warmup as warm

    notice = logging.getLogger("trajopt.kernel_cache")
    if not any(isinstance(h, _StderrLines) for h in notice.handlers):
        notice.addHandler(_StderrLines())
        notice.propagate = False
    return _compile_kernels(warm.CORE_EXERCISES, None)


class _StderrLines(logging.StreamHandler):
    """Log records as plain lines on the current ``sys.stderr`` (as :data:`logging.lastResort`)."""

    def __init__(self) -> None:
        super().__init__()
        self.setFormatter(logging.Formatter("%(message)s"))

    @property
    def stream(self) -> Any:  # noqa: D102
        return sys.stderr

    @stream.setter
    def stream(self, value: Any) -> None:
        pass
