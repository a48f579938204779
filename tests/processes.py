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

Processes that run in the background of other tests may start with a lower priority
(``nice``, :data:`BACKGROUND_NICE`): the tests' own process, the one the session waits for,
then keeps its core when the background wants more than the other one.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import textwrap
import threading

#: The ``nice`` increment of background processes (POSIX; ignored elsewhere).
BACKGROUND_NICE = 5


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


class StartedAfter:
    """``python -c script *args``, started as soon as the process ``after`` has ended.

    A thread waits for ``after`` and then starts this one, so that a check of a process that
    needs another one's result (a cache it filled) does not wait for the test to ask.
    :meth:`result` and :meth:`stop` behave as :class:`Started`'s.
    """

    def __init__(
        self, after: Started, script: str, *args: str, env: dict | None = None, nice: int = 0
    ) -> None:
        self.env = env
        self._run: Started | None = None
        self._stopped = False
        self._lock = threading.Lock()

        def start_when_done() -> None:
            after.proc.wait()
            with self._lock:
                if not self._stopped:
                    self._run = Started(script, *args, env=env, nice=nice)

        self._thread = threading.Thread(target=start_when_done, daemon=True)
        self._thread.start()

    def result(self, timeout: float | None = 600.0) -> subprocess.CompletedProcess:
        """The finished process (waits for ``after`` first)."""
        self._thread.join(timeout)
        assert self._run is not None, "the process was stopped before it started"
        return self._run.result(timeout)

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
_RUNS: dict[str, dict[str, Started | StartedAfter]] = {}  # test module name -> key -> process
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


def module_processes(request) -> dict[str, Started | StartedAfter]:
    """The processes of the requesting module: those started early, else started now."""
    name = request.module.__name__
    if name not in _RUNS:
        items = _module_items(request.session.items, request.module)
        _RUNS[name] = request.module.early_processes(items)
    return _RUNS[name]


def stop_all() -> None:
    """Kill the processes still running (a failed or interrupted session), remove scratch."""
    for runs in _RUNS.values():
        for run in runs.values():
            run.stop()
    _RUNS.clear()
    for path in _SCRATCH:
        shutil.rmtree(path, ignore_errors=True)
    _SCRATCH.clear()
