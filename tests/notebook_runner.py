"""Execute the notebooks in ``notebooks/`` with nbclient, in the background of the test session.

A helper module, not a test module (``tests/test_notebooks.py`` holds the checks). Each
notebook runs in a fresh ``python3`` kernel of the interpreter running the tests (a kernel
spec written for ``sys.executable`` into a temporary folder, the only one the kernel
manager searches, so a ``python3`` spec installed for another Python cannot be picked up),
with ``notebooks/`` as its working directory and the repository root on ``PYTHONPATH``.

The tests' own process computes on one core. So that the notebooks do not add their
minute of kernel start-ups, imports and plans to the suite's wall time, the session starts
them as soon as collection has finished (``tests/conftest.py``), one notebook after the
other in a background thread, on a second core, while the other tests run;
``test_notebook_executes`` runs last and checks each notebook's result. The result of a
notebook does not depend on when it runs: only the wall-time limits see the shared CPU,
and they have a wide margin. The background thread is the session's background lane
(``tests/processes.py``), which runs the fresh processes some tests read before the
notebooks and one job at a time, so that the tests' own process keeps its core. With one
usable CPU, or ``TRAJOPT_NOTEBOOKS_BACKGROUND=0``, each notebook runs inside its test
instead, as before.
"""

from __future__ import annotations

import functools
import os
import shutil
import tempfile
import threading
import time
from concurrent.futures import Future
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tests.processes import NOTEBOOKS_LAST, lane

NOTEBOOK_DIR = Path(__file__).resolve().parent.parent / "notebooks"
NOTEBOOKS = sorted(NOTEBOOK_DIR.glob("*.ipynb"))
#: Per-cell execution limit (s).
TIMEOUT_S = 600
#: Whole-notebook limit (s): each takes about a minute on an idle 2-core machine; the margin
#: is for loaded CI runners and a cold numba cache.
NOTEBOOK_LIMIT_S = 900
#: Kernel start-up limit (s): generous, a loaded CI machine can be slow to import IPython.
STARTUP_TIMEOUT_S = 180
#: The modules the notebook tests need (all in the ``dev`` extra).
JUPYTER_MODULES = ("nbformat", "nbclient", "ipykernel", "jupyter_client")


@dataclass
class Executed:
    """One notebook after execution: the notebook with its outputs, or the exception raised."""

    path: Path
    nb: Any  # nbformat.NotebookNode, with outputs
    seconds: float  # wall time from kernel start to the last cell
    error: BaseException | None  # nbclient's CellExecutionError names the failing cell
    kernel_argv0: str  # the interpreter of the kernel spec it ran
    kernel_log: str  # the kernel process's own stdout and stderr


def missing_jupyter() -> str | None:
    """The first module of :data:`JUPYTER_MODULES` that is not installed, else None."""
    import importlib.util

    for mod in JUPYTER_MODULES:
        if importlib.util.find_spec(mod) is None:
            return mod
    return None


def _spec_manager(kernels_dir: Path) -> Any:
    """A kernel spec manager that knows the specs in ``kernels_dir`` only."""
    from jupyter_client.kernelspec import KernelSpecManager

    return KernelSpecManager(kernel_dirs=[str(kernels_dir)], ensure_native_kernel=False)


def _kernel_manager_class(kernels_dir: Path) -> type:
    """An async kernel manager whose kernel specs are those in ``kernels_dir`` only."""
    from jupyter_client.manager import AsyncKernelManager
    from traitlets import default

    class ThisInterpreterKernelManager(AsyncKernelManager):
        @default("kernel_spec_manager")
        def _kernel_spec_manager_default(self) -> Any:
            return _spec_manager(kernels_dir)

    return ThisInterpreterKernelManager


def execute(path: Path, workdir: Path) -> Executed:
    """Run ``path`` in a fresh kernel of this interpreter; scratch files go to ``workdir``."""
    import nbformat
    from ipykernel.kernelspec import install
    from nbclient import NotebookClient

    prefix = workdir / path.stem
    install(kernel_name="python3", prefix=str(prefix))
    kernels_dir = prefix / "share" / "jupyter" / "kernels"
    argv0 = _spec_manager(kernels_dir).get_kernel_spec("python3").argv[0]
    env = dict(os.environ)
    root = str(NOTEBOOK_DIR.parent)
    paths = [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p]
    if root not in paths:  # the kernel must import this checkout
        env["PYTHONPATH"] = os.pathsep.join([root, *paths])
    nb = nbformat.read(path, as_version=4)
    client = NotebookClient(
        nb,
        timeout=TIMEOUT_S,
        startup_timeout=STARTUP_TIMEOUT_S,
        kernel_name="python3",
        kernel_manager_class=_kernel_manager_class(kernels_dir),
        resources={"metadata": {"path": str(NOTEBOOK_DIR)}},
    )
    log_path = workdir / f"{path.stem}.log"
    error: BaseException | None = None
    t0 = time.perf_counter()
    with open(log_path, "w") as log:
        try:
            client.execute(env=env, stdout=log, stderr=log)
        except Exception as exc:  # reported by the test, with the kernel's log
            error = exc
    seconds = time.perf_counter() - t0
    return Executed(
        path=path,
        nb=nb,
        seconds=seconds,
        error=error,
        kernel_argv0=argv0,
        kernel_log=log_path.read_text(errors="replace"),
    )


def usable_cpus() -> int:
    """CPUs this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


class NotebookRunner:
    """Executes notebooks once per session: in the background lane once started, else inline."""

    def __init__(self) -> None:
        self._workdir = Path(tempfile.mkdtemp(prefix="trajopt_notebooks_"))
        self._futures: dict[Path, Future] = {}
        self._lock = threading.Lock()

    def start(self, paths: list[Path]) -> None:
        """Queue ``paths`` for execution, one after another, in the background lane."""
        with self._lock:
            for p in paths:
                if p not in self._futures:
                    self._futures[p] = lane().submit(
                        NOTEBOOKS_LAST, functools.partial(execute, p, self._workdir)
                    )

    def result(self, path: Path) -> Executed:
        """The execution of ``path``: waits for the background run, or runs it here."""
        with self._lock:
            fut = self._futures.get(path)
            if fut is None:
                fut = self._futures[path] = Future()
                fut.set_running_or_notify_cancel()
                inline = True
            else:
                inline = False
        if inline:
            try:
                fut.set_result(execute(path, self._workdir))
            except BaseException as exc:
                fut.set_exception(exc)
        return fut.result()

    def shutdown(self) -> None:
        """Drop the notebooks not started yet, wait for the running one, remove scratch files."""
        with self._lock:
            futures = list(self._futures.values())
        for fut in futures:
            fut.cancel()  # those the lane has not started
        for fut in futures:
            if not fut.cancelled():
                try:
                    fut.result()
                except BaseException:  # reported by its test, if it ran
                    pass
        shutil.rmtree(self._workdir, ignore_errors=True)


_RUNNER: NotebookRunner | None = None


def runner() -> NotebookRunner:
    """The session's runner."""
    global _RUNNER
    if _RUNNER is None:
        _RUNNER = NotebookRunner()
    return _RUNNER


def background_wanted() -> bool:
    """Whether to run the notebooks in the background (module docstring)."""
    if os.environ.get("TRAJOPT_NOTEBOOKS_BACKGROUND", "1") == "0":
        return False
    return usable_cpus() >= 2 and missing_jupyter() is None


def shutdown() -> None:
    """End the session's runner, if any."""
    global _RUNNER
    if _RUNNER is not None:
        _RUNNER.shutdown()
        _RUNNER = None
