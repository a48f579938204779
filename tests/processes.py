"""Fresh Python processes a test starts early and reads later (a helper module, not a test module).

Tests that check a property of a *fresh* process (what it loads, compiles or logs) pay a
Python start and the numba start-up for each one. The tests' own process computes on one
core and only waits meanwhile, so the processes a module needs are started early and each
test reads its own; they run side by side on the other core while the other tests run.
Output goes to temporary files, not pipes, so that no process blocks on a full pipe nobody
reads yet.

A test module that needs fresh processes defines ``early_processes(items)``, which returns
``{key: Started(...)}`` for its selected test items; the session calls it for every such
module when collection ends (``tests/conftest.py``, :func:`start_early`), and the module's
fixture reads them with :func:`module_processes` (which starts them itself if the session
has not, e.g. with ``TRAJOPT_EARLY_PROCESSES=0``). What a process computes does not depend
on when it starts: only its wall time sees the shared CPU.

Processes that run in the background of other tests go through the session's one
background lane (:class:`Queued`, :class:`BackgroundLane`), one at a time and before the
notebooks, so that the tests' own process, the one the session waits for, keeps its core.
"""

from __future__ import annotations

import itertools
import math
import os
import queue
import shutil
import subprocess
import sys
import tempfile
import textwrap
import threading
from collections.abc import Callable
from concurrent.futures import Future
from typing import Any


class Started:
    """``python -c script *args``, started now; :meth:`result` waits for it."""

    def __init__(self, script: str, *args: str, env: dict | None = None) -> None:
        self._out = tempfile.TemporaryFile("w+")
        self._err = tempfile.TemporaryFile("w+")
        self.proc = subprocess.Popen(
            [sys.executable, "-c", textwrap.dedent(script), *args],
            stdout=self._out,
            stderr=self._err,
            text=True,
            env=env,
        )
        self.env = env
        self._done: subprocess.CompletedProcess | None = None

    def result(self, timeout: float | None = 600.0) -> subprocess.CompletedProcess:
        """The finished process, its stdout and stderr (as ``subprocess.run`` returns them)."""
        if self._done is None:
            self.proc.wait(timeout)
            text = []
            for f in (self._out, self._err):
                f.seek(0)
                text.append(f.read())
                f.close()
            self._done = subprocess.CompletedProcess(self.proc.args, self.proc.returncode, *text)
        return self._done

    def stop(self) -> None:
        """Kill the process if it still runs (a failed or interrupted session)."""
        if self.proc.poll() is None:
            self.proc.kill()
        self.result()


class BackgroundLane:
    """One background thread that runs jobs one at a time: the most urgent first (the lowest
    ``priority``), in the order they came among equals.

    The session's background work, the queued fresh processes (:class:`Queued`, priority
    :data:`PROCESSES_FIRST`) and the notebooks (``tests/notebook_runner.py``, priority
    :data:`NOTEBOOKS_LAST`), goes through one lane, so that it takes one core beside the
    tests' own process and never more.
    """

    def __init__(self) -> None:
        self._jobs: queue.PriorityQueue = queue.PriorityQueue()
        self._order = itertools.count()
        self._thread = threading.Thread(target=self._serve, daemon=True, name="background")
        self._thread.start()

    def submit(self, priority: int, fn: Callable[[], Any]) -> Future:
        """Queue ``fn``; its future (cancel it to drop it while it waits)."""
        fut: Future = Future()
        self._jobs.put((priority, next(self._order), fut, fn))
        return fut

    def _serve(self) -> None:
        while True:
            _, _, fut, fn = self._jobs.get()
            if fut is None:
                return
            if not fut.set_running_or_notify_cancel():
                continue
            try:
                fut.set_result(fn())
            except BaseException as exc:  # handed to whoever reads the future
                fut.set_exception(exc)

    def shutdown(self) -> None:
        """Drop the jobs not started, wait for the running one, end the thread."""
        while True:
            try:
                _, _, fut, _ = self._jobs.get_nowait()
            except queue.Empty:
                break
            if fut is not None:
                fut.cancel()
        self._jobs.put((math.inf, next(self._order), None, None))
        self._thread.join()


#: Priorities in the :class:`BackgroundLane`: the processes that tests read during the
#: session before the notebooks, whose checks run last.
PROCESSES_FIRST, NOTEBOOKS_LAST = 0, 1

_LANE: BackgroundLane | None = None


def lane() -> BackgroundLane:
    """The session's background lane."""
    global _LANE
    if _LANE is None:
        _LANE = BackgroundLane()
    return _LANE


class Queued:
    """``python -c script *args``, run in the session's background lane (:func:`lane`).

    The lane runs it when its turn comes, one process or notebook at a time, beside the tests;
    :meth:`result` starts it at once if its turn has not come yet (the test needs it now), then
    waits for it. A process queued after another one starts after that one has ended (a cache
    it fills, for example), unless a test asks for it first.
    """

    def __init__(self, script: str, *args: str, env: dict | None = None) -> None:
        self.env = env
        self._spec = (script, args, env)
        self._run: Started | None = None
        self._stopped = False
        self._lock = threading.Lock()
        lane().submit(PROCESSES_FIRST, self._run_in_lane)

    def _run_in_lane(self) -> None:
        run = self.launch()
        if run is not None:
            run.proc.wait()

    def launch(self) -> Started | None:
        """Start the process unless it has started or was stopped; the process, or None."""
        with self._lock:
            if self._run is None and not self._stopped:
                script, args, env = self._spec
                self._run = Started(script, *args, env=env)
            return self._run

    def result(self, timeout: float | None = 600.0) -> subprocess.CompletedProcess:
        """The finished process (started now if its turn has not come yet)."""
        run = self.launch()
        assert run is not None, "the process was stopped before it started"
        return run.result(timeout)

    def stop(self) -> None:
        """Kill the process if it runs, or keep it from starting."""
        with self._lock:
            self._stopped = True
            run = self._run
        if run is not None:
            run.stop()


def selected_params(items, test_name: str, param: str) -> list:
    """The values of ``param`` of the test items ``test_name`` among ``items``."""
    return [
        i.callspec.params[param] for i in items if getattr(i, "originalname", None) == test_name
    ]


# ------------------------------------------------------------ started when collection ends
_RUNS: dict[str, dict[str, Started | Queued]] = {}  # test module name -> key -> process
_SCRATCH: list[str] = []


def scratch_dir(prefix: str) -> str:
    """A temporary folder removed when the session ends (:func:`stop_all`)."""
    path = tempfile.mkdtemp(prefix=prefix)
    _SCRATCH.append(path)
    return path


def early_wanted() -> bool:
    """Whether the session starts the modules' processes when collection ends."""
    return os.environ.get("TRAJOPT_EARLY_PROCESSES", "1") != "0"


def _module_items(items, module) -> list:
    return [i for i in items if getattr(i, "module", None) is module]


def start_early(items) -> None:
    """Start the processes of every selected module that defines ``early_processes``."""
    modules = {}
    for item in items:
        module = getattr(item, "module", None)
        if hasattr(module, "early_processes"):
            modules.setdefault(module.__name__, module)
    for name, module in modules.items():
        if name not in _RUNS:
            _RUNS[name] = module.early_processes(_module_items(items, module))


def module_processes(request) -> dict[str, Started | Queued]:
    """The processes of the requesting module: those started early, else started now."""
    name = request.module.__name__
    if name not in _RUNS:
        items = _module_items(request.session.items, request.module)
        _RUNS[name] = request.module.early_processes(items)
    return _RUNS[name]


def stop_all() -> None:
    """Kill the processes still running (a failed or interrupted session), keep the queued
    ones from starting, end the background lane, remove scratch."""
    global _LANE
    for runs in _RUNS.values():
        for run in runs.values():
            run.stop()
    _RUNS.clear()
    if _LANE is not None:
        _LANE.shutdown()
        _LANE = None
    for path in _SCRATCH:
        shutil.rmtree(path, ignore_errors=True)
    _SCRATCH.clear()
