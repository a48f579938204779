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

Processes that run in the background of other tests go through one queue
(:class:`Queued`): one at a time, with a lower priority (``nice``, :data:`BACKGROUND_NICE`),
so that the tests' own process, the one the session waits for, keeps its core.
"""

from __future__ import annotations

import os
import queue
import shutil
import subprocess
import sys
import tempfile
import textwrap
import threading

#: The ``nice`` increment of background processes (POSIX; ignored elsewhere).
BACKGROUND_NICE = 10


def lower_priority(pid: int, nice: int) -> None:
    """Raise the niceness of process ``pid`` by ``nice`` over this process's (POSIX only)."""
    if nice and hasattr(os, "setpriority"):
        try:
            mine = os.getpriority(os.PRIO_PROCESS, 0)
            os.setpriority(os.PRIO_PROCESS, pid, min(19, mine + nice))
        except OSError:  # the process has ended already, or no permission: keep it as is
            pass


class Started:
    """``python -c script *args``, started now; :meth:`result` waits for it.

    ``nice`` raises the niceness of the process (and so of its children) by that much.
    """

    def __init__(self, script: str, *args: str, env: dict | None = None, nice: int = 0) -> None:
        self._out = tempfile.TemporaryFile("w+")
        self._err = tempfile.TemporaryFile("w+")
        self.proc = subprocess.Popen(
            [sys.executable, "-c", textwrap.dedent(script), *args],
            stdout=self._out,
            stderr=self._err,
            text=True,
            env=env,
        )
        lower_priority(self.proc.pid, nice)
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


class Queued:
    """``python -c script *args``, run in the background queue of the session.

    The queue runs its processes one at a time, in the order they were queued, in a thread of
    its own, at a lower priority (``nice``): a second core works through them while the tests
    run, without taking the tests' own core. :meth:`result` starts the process at once if the
    queue has not reached it yet (the test needs it now), then waits for it. A process queued
    after another one starts after that one has ended (a cache it fills, for example).
    """

    def __init__(
        self, script: str, *args: str, env: dict | None = None, nice: int = BACKGROUND_NICE
    ) -> None:
        self.env = env
        self._spec = (script, args, env, nice)
        self._run: Started | None = None
        self._stopped = False
        self._lock = threading.Lock()
        _background_queue().put(self)

    def launch(self) -> Started | None:
        """Start the process unless it has started or was stopped; the process, or None."""
        with self._lock:
            if self._run is None and not self._stopped:
                script, args, env, nice = self._spec
                self._run = Started(script, *args, env=env, nice=nice)
            return self._run

    def result(self, timeout: float | None = 600.0) -> subprocess.CompletedProcess:
        """The finished process (started now if the queue has not reached it yet)."""
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


_QUEUE: queue.SimpleQueue | None = None


def _serve(jobs: queue.SimpleQueue) -> None:
    while True:
        job = jobs.get()
        if job is None:
            return
        run = job.launch()
        if run is not None:
            run.proc.wait()


def _background_queue() -> queue.SimpleQueue:
    global _QUEUE
    if _QUEUE is None:
        _QUEUE = queue.SimpleQueue()
        threading.Thread(target=_serve, args=(_QUEUE,), daemon=True, name="processes").start()
    return _QUEUE


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
    ones from starting, end the queue's thread, remove scratch."""
    global _QUEUE
    for runs in _RUNS.values():
        for run in runs.values():
            run.stop()
    _RUNS.clear()
    if _QUEUE is not None:
        _QUEUE.put(None)
        _QUEUE = None
    for path in _SCRATCH:
        shutil.rmtree(path, ignore_errors=True)
    _SCRATCH.clear()
