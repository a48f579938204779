"""The compiled kernels of astar and trajopt: their one-time compilation, shown and done ahead.

Every compiled kernel of the two packages is a numba ``@njit(cache=True)`` function in one of
:data:`KERNEL_MODULES`. numba compiles a kernel the first time it is called with a new
signature and keeps the machine code in its disk cache (``__pycache__`` beside the source,
or ``$NUMBA_CACHE_DIR``); later processes load it in milliseconds. A new environment (a
fresh clone, venv, container or CI runner) starts with an empty cache and pays the
compilation once: about 50 s of CPU for all kernels on a 2-core machine (numba 0.68).

This module makes that visible and lets it be paid ahead of time:

* :func:`watch_compiles` (installed by the trajopt kernel modules when they are imported,
  so a program that imports only ``astar`` is not told) logs one WARNING on the logger ``trajopt.kernel_cache`` the first time a kernel of the
  two packages compiles in a process. WARNING, not INFO, because it explains a one-time
  latency of tens of seconds in a call that otherwise takes milliseconds, which a robot
  program should hear about and can act on (``trajopt warm-up`` in its image build); it is
  the level Matplotlib uses for "building the font cache". Loading from the cache logs
  nothing. The library prints nothing; the ``trajopt`` command line shows the notice.
* :func:`cold_kernels` lists the kernels with nothing valid in the disk cache, without
  compiling anything (it reads numba's cache index files).
* :func:`run_exercises` compiles them by running the exercises its caller gives (each an
  :class:`Exercise`: library calls on small inputs) in worker processes, two at a time on
  two cores; numba's cache holds one file per kernel and signature and writes them
  atomically, so the workers fill one cache for every later process. The exercises that
  between them call every kernel with the argument types the library uses are
  ``trajopt.warmup.EXERCISES``, above this module: :func:`trajopt.warmup.compile_kernels`
  passes them in, with the command that starts a worker serving them (:func:`serve`), so
  this module imports nothing above the kernels.
* :func:`load_kernels` loads every kernel's cached signatures into this process (also the
  kernels that only other kernels call, whose code is otherwise only loaded inside their
  callers).

:func:`trajopt.warm_up` and ``trajopt warm-up`` combine the last two.
"""

from __future__ import annotations

import importlib
import logging
import os
import subprocess
import sys
import tempfile
import time
import traceback
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

_log = logging.getLogger(__name__)

#: Modules that define the compiled (numba) kernels of astar and trajopt.
KERNEL_MODULES: tuple[str, ...] = (
    "astar.body_polygons",
    "astar.coarse_to_fine",
    "astar.distance_transform",
    "astar.escape",
    "astar.hybrid_kernel",
    "astar.hybrid_shortcut",
    "astar.inflation",
    "astar.polygons",
    "astar.reeds_shepp",
    "astar.search_kernels",
    "astar.weighted_kernel",
    "trajopt.geometry._bspline",
    "trajopt.geometry._clearance",
    "trajopt.geometry._convex_hull",
    "trajopt.planning._feasibility",
    "trajopt.planning._label_kernel",
    "trajopt.robot._footprint_kernels",
    "trajopt.geometry._obstacle_index",
    "trajopt.motion._phase_motion",
    "trajopt.moving._st_kernels",
    "trajopt.moving._st_search",
    "trajopt.moving._node_times",
    "trajopt.moving._grid_runs",
    "trajopt.moving._polygon_march",
    "trajopt.moving._polygon_distance",
    "trajopt.moving._bisection_bounds",
    "trajopt.moving._path_bounds",
    "trajopt.moving._mover_segments",
    "trajopt.moving._grid_kernels",
    "trajopt.moving._swept_kernel",
    "trajopt.moving._reach_kernel",
    "trajopt.corridor._polygons.path_kernels",
    "trajopt.corridor._polygons.region_kernels",
    "trajopt.smoother._cost_kernels",
    "trajopt.timing._cap_cubic",
    "trajopt.timing._cap_kernel",
    "trajopt.timing._greedy",
)

#: CPU seconds one kernel takes to compile, on average (2-core machine, numba 0.68); the
#: notice's estimate.
SECONDS_PER_KERNEL = 0.5

#: Environment variable set in the worker processes of :func:`run_exercises`.
WORKER_ENV = "TRAJOPT_KERNEL_WORKER"

#: Seconds without a line from any worker after which :func:`run_exercises` stops them
#: (a kernel compiles in seconds; the exercises' kernels then compile on first use).
IDLE_LIMIT_S = 300.0

_PACKAGES = ("astar.", "trajopt.")


# ----------------------------------------------------------------------------- inventory
def dispatchers(modules: Iterable[str] = KERNEL_MODULES) -> dict[str, Any]:
    """Return every numba dispatcher defined in ``modules``, by ``"module.name"``.

    The modules are imported (which compiles nothing). Kernels with ``inline="always"``
    are included: numba inlines them into their callers and never compiles them alone.
    """
    from numba.core.dispatcher import Dispatcher

    out: dict[str, Any] = {}
    for name in modules:
        module = importlib.import_module(name)
        for attr, value in vars(module).items():
            if isinstance(value, Dispatcher) and value.py_func.__module__ == name:
                out[f"{name}.{attr}"] = value
    return out


def kernels(modules: Iterable[str] = KERNEL_MODULES) -> dict[str, Any]:
    """:func:`dispatchers` without the ``inline="always"`` ones: the kernels numba compiles."""
    return {k: d for k, d in dispatchers(modules).items() if not _inlined(d)}


def _inlined(d: Any) -> bool:
    return d.targetoptions.get("inline", "never") == "always"


def _cached_signatures(d: Any) -> list[Any] | None:
    """Signatures of ``d`` with a valid entry in numba's disk cache (``None``: cannot tell).

    Valid means what numba itself checks before loading one: the index file matches the
    source file's stamp and this numba version, and the entry's key (signature, target
    machine, bytecode hash) is the one numba would look up now. Reads numba's private
    cache objects: any failure there answers ``None``.
    """
    try:
        cache = d._cache
        if not hasattr(cache, "_cache_file"):
            return None  # caching disabled (a NullCache)
        index = cache._cache_file._load_index()
        codegen = d.targetctx.codegen()
        return [key[0] for key in index if key == cache._index_key(key[0], codegen)]
    except Exception:  # noqa: BLE001 - a numba without these internals: unknown
        return None


def cold_kernels(modules: Iterable[str] = KERNEL_MODULES) -> list[str]:
    """Return the kernels with no valid entry in numba's disk cache (they would compile).

    Nothing is compiled or loaded: numba's index files are read. A kernel whose cache
    cannot be inspected counts as compiled.
    """
    cold = []
    for name, d in kernels(modules).items():
        sigs = _cached_signatures(d)
        if sigs is not None and not sigs:
            cold.append(name)
    return cold


def load_kernels(modules: Iterable[str] = KERNEL_MODULES) -> int:
    """Load every cached signature of every kernel into this process; return how many.

    Signatures already loaded are skipped. Only cached ones are loaded: nothing compiles.
    """
    n = 0
    for d in kernels(modules).values():
        for sig in _cached_signatures(d) or ():
            if tuple(sig) not in d.overloads:
                d.compile(sig)
                n += 1
    return n


def estimate_seconds(n_kernels: int, workers: int = 1) -> float:
    """Rough wall time (s) to compile ``n_kernels`` kernels with ``workers`` processes."""
    return SECONDS_PER_KERNEL * n_kernels / max(1, workers)


# ----------------------------------------------------------------------------- the notice
_watch: dict[str, Any] = {"installed": False, "noticed": False, "hooks": []}


def watch_compiles() -> None:
    """Install, once per process, the listener that announces kernel compilation.

    On the first compilation of an astar or trajopt kernel in the process it logs one
    WARNING (module docstring) and calls every hook of :func:`add_compile_hook`. A
    kernel loaded from numba's cache triggers nothing: numba only signals a compilation.
    """
    if _watch["installed"]:
        return
    from numba.core import event

    class _Listener(event.Listener):
        def on_start(self, ev: Any) -> None:
            d = ev.data["dispatcher"]
            if not getattr(d.py_func, "__module__", "").startswith(_PACKAGES):
                return
            if not _watch["noticed"]:
                _watch["noticed"] = True
                _notice(d)

        def on_end(self, ev: Any) -> None:
            d = ev.data["dispatcher"]
            name = f"{d.py_func.__module__}.{d.py_func.__name__}"
            if name.startswith(_PACKAGES):
                for hook in list(_watch["hooks"]):
                    hook(name)

    event.register("numba:compile", _Listener())
    _watch["installed"] = True


def add_compile_hook(hook: Callable[[str], None]) -> None:
    """Call ``hook("module.kernel")`` each time a kernel of the packages finishes compiling."""
    watch_compiles()
    _watch["hooks"].append(hook)


def _notice(d: Any) -> None:
    if os.environ.get(WORKER_ENV):
        return  # a worker of run_exercises: its parent reports
    try:
        n = len(cold_kernels())
    except Exception:  # noqa: BLE001 - the notice must never break a compile
        n = 0
    about = f", up to about {estimate_seconds(n):.0f} s" if n else ""
    _log.warning(
        "trajopt: compiling numerical kernels once for this environment (numba, starting "
        "with %s%s); later processes load them from the cache. `trajopt warm-up` or "
        "trajopt.warm_up() compiles all of them ahead of time, in parallel.",
        d.py_func.__name__,
        about,
    )


# ----------------------------------------------------------------------------- compilation
@dataclass(frozen=True)
class Exercise:
    """A warm-up exercise: library calls on small inputs that compile a set of kernels.

    Attributes
    ----------
    run : callable
        Runs the calls (no arguments, no result).
    after : tuple of str
        Exercises to run first: their kernels are then loaded, not compiled again, when
        this one runs in another worker process.
    seconds : float
        Rough compile time (s) when every kernel is cold: longest first.
    """

    run: Callable[[], None]
    after: tuple[str, ...] = ()
    seconds: float = 1.0


@dataclass
class CompileReport:
    """What :func:`run_exercises` did.

    Attributes
    ----------
    cold : list of str
        Kernels with nothing cached before (``"module.kernel"``).
    compiled : list of str
        Kernels compiled by the workers (a kernel compiled for two signatures counts once).
    exercises : list of str
        Warm-up exercises run.
    timeline : list of tuple
        ``(exercise, worker, start, end)`` (s since the call; worker 0: this process).
    failed : dict of str to str
        Exercises that raised, with the error (their kernels compile when first used).
    workers : int
        Worker processes (0: ran in this process).
    seconds : float
        Wall time until every exercise was done (so far, while :meth:`wait` would wait).
    """

    cold: list[str] = field(default_factory=list)
    compiled: list[str] = field(default_factory=list)
    exercises: list[str] = field(default_factory=list)
    timeline: list[tuple[str, int, float, float]] = field(default_factory=list)
    failed: dict[str, str] = field(default_factory=dict)
    workers: int = 0
    seconds: float = 0.0
    _thread: Any = field(default=None, repr=False)

    def wait(self) -> CompileReport:
        """Wait for the exercises still running in the background (``first``); return self."""
        if self._thread is not None:
            self._thread.join()
            self._thread = None
        return self


def run_exercises(
    table: Mapping[str, Exercise],
    exercises: Sequence[str] | None = None,
    *,
    worker: Sequence[str],
    workers: int | None = None,
    progress: Callable[[int, int, str], None] | None = None,
    first: Sequence[str] | None = None,
    force: bool = False,
) -> CompileReport:
    """Compile the cold kernels into numba's disk cache by running exercises of ``table``.

    Parameters
    ----------
    table : mapping of str to Exercise
        The exercises by name (``trajopt.warmup.EXERCISES``: between them they call every
        kernel of the packages).
    exercises : sequence of str, optional
        Names in ``table`` (with the ones they depend on); default all.
    worker : sequence of str
        The command that starts a worker process serving ``table`` (:func:`serve` on its
        stdin and stdout), e.g. ``[sys.executable, "-m", "trajopt.warmup", "--worker"]``.
    workers : int, optional
        Worker processes; default ``min(2, CPUs)``. ``0`` or ``1`` runs the exercises in this
        process, one after the other (the kernels are then also loaded here).
    progress : callable, optional
        ``progress(done, total, kernel)`` after each cold kernel compiles (``total`` is the
        number of cold kernels), and once at the end with ``done == total``.
    first : sequence of str, optional
        Exercises to run before the others; the call returns as soon as they (and those
        they depend on) are done, while the workers go on with the rest in the background
        (:meth:`CompileReport.wait` waits for them). Default: return when all are done.
    force : bool
        Run the exercises even when no kernel is cold.

    Returns
    -------
    CompileReport
        Nothing runs (and ``seconds`` is ~0) when every kernel is already cached. An
        exercise that fails is reported, not raised: its kernels then compile on first use.

    Raises
    ------
    InvalidInputError
        An exercise name not in ``table``.
    """
    import threading

    t0 = time.perf_counter()
    cold = cold_kernels()
    report = CompileReport(cold=list(cold))
    if not cold and not force:
        return report
    names = _with_dependencies(table, list(table) if exercises is None else exercises)
    early = set(_with_dependencies(table, first)) if first is not None else set(names)
    names.sort(key=lambda n: (n not in early, -table[n].seconds))  # early, longest first
    if workers is None:
        workers = min(2, os.cpu_count() or 1)
    if os.environ.get(WORKER_ENV):
        workers = 0  # never nest workers
    done: set[str] = set()

    def seen(kernel: str) -> None:
        if kernel in report.cold and kernel not in done:
            done.add(kernel)
            report.compiled.append(kernel)
            if progress is not None:
                progress(len(done), len(cold), kernel)

    def finish() -> None:
        if progress is not None:
            progress(len(cold), len(cold), "")
        report.seconds = time.perf_counter() - t0

    if workers >= 2:
        try:
            pool = _Workers(min(workers, len(names)), worker, table, report, seen, t0)
        except OSError as exc:  # no subprocess here: run them in this process
            _log.info("run_exercises: no worker processes (%s); compiling here", exc)
        else:
            report.workers = pool.n
            early_done = threading.Event()

            def run() -> None:
                try:
                    pool.run(names, early, early_done)
                finally:
                    early_done.set()
                    finish()

            thread = threading.Thread(target=run, name="trajopt-compile", daemon=True)
            thread.start()
            report._thread = thread
            early_done.wait()
            if first is None:
                report.wait()
            return report
    add_compile_hook(seen)
    try:
        for name in names:
            t1 = time.perf_counter() - t0
            try:
                table[name].run()
                report.exercises.append(name)
                report.timeline.append((name, 0, t1, time.perf_counter() - t0))
            except Exception as exc:  # noqa: BLE001 - reported, the kernels compile later
                report.failed[name] = f"{type(exc).__name__}: {exc}"
    finally:
        _watch["hooks"].remove(seen)
    finish()
    return report


def _with_dependencies(table: Mapping[str, Exercise], names: Iterable[str]) -> list[str]:
    """``names`` and what they depend on, dependencies first, unknown names rejected."""
    from trajopt.errors import InvalidInputError

    out: list[str] = []

    def add(name: str) -> None:
        if name not in table:
            raise InvalidInputError(
                f"unknown warm-up exercise {name!r}; known: {', '.join(sorted(table))}"
            )
        if name in out:
            return
        for dep in table[name].after:
            add(dep)
        out.append(name)

    for name in names:
        add(name)
    return out


class _Workers:
    """Worker processes that run warm-up exercises named on their stdin (:func:`serve`)."""

    def __init__(
        self,
        n: int,
        command: Sequence[str],
        table: Mapping[str, Exercise],
        report: CompileReport,
        seen: Callable[[str], None],
        t0: float,
    ) -> None:
        self.table, self.report, self.seen, self.t0 = table, report, seen, t0
        env = dict(os.environ, **{WORKER_ENV: "1"})
        self.procs: list[subprocess.Popen] = []
        self.logs = []
        try:
            for _ in range(n):
                log = tempfile.TemporaryFile(mode="w+")
                self.logs.append(log)
                self.procs.append(
                    subprocess.Popen(
                        list(command),
                        stdin=subprocess.PIPE,
                        stdout=subprocess.PIPE,
                        stderr=log,
                        text=True,
                        bufsize=1,
                        env=env,
                    )
                )
        except OSError:
            self.close()
            raise
        self.n = n

    def run(self, names: list[str], early: set[str], early_done: Any) -> None:
        """Run ``names`` in this order as their dependencies allow.

        ``early_done`` is set once every exercise in ``early`` is over. One thread per
        worker reads its lines (a blocking read each: no line can wait unseen in a buffer);
        a worker silent for :data:`IDLE_LIMIT_S` is stopped and its exercise reported.
        """
        import queue
        import threading

        table, report = self.table, self.report
        pending = list(names)
        finished: set[str] = set()
        busy: dict[int, str | None] = {p.pid: None for p in self.procs}
        started: dict[int, float] = {}
        lines: queue.Queue = queue.Queue()

        def read(proc: subprocess.Popen) -> None:
            for line in proc.stdout:
                lines.put((proc, line))
            lines.put((proc, None))

        for proc in self.procs:
            threading.Thread(target=read, args=(proc,), daemon=True).start()

        def assign() -> None:
            for proc in self.procs:
                if busy[proc.pid] is not None or proc.poll() is not None:
                    continue
                ready = [n for n in pending if all(d in finished for d in table[n].after)]
                if not ready:
                    return
                name = ready[0]
                pending.remove(name)
                busy[proc.pid] = name
                started[proc.pid] = time.perf_counter() - self.t0
                try:
                    proc.stdin.write(name + "\n")
                    proc.stdin.flush()
                except OSError:  # it died: its reader reports the end
                    pass

        def over(proc: subprocess.Popen, error: str | None) -> None:
            name = busy[proc.pid]
            busy[proc.pid] = None
            finished.add(name)
            if error is None:
                report.exercises.append(name)
                report.timeline.append(
                    (
                        name,
                        self.procs.index(proc) + 1,
                        started[proc.pid],
                        time.perf_counter() - self.t0,
                    )
                )
            else:
                report.failed[name] = error
            if early <= finished:
                early_done.set()

        try:
            assign()
            while any(v is not None for v in busy.values()):
                try:
                    proc, line = lines.get(timeout=IDLE_LIMIT_S)
                except queue.Empty:
                    for proc in self.procs:
                        if busy[proc.pid] is not None:
                            over(proc, f"no word from its worker for {IDLE_LIMIT_S:.0f} s")
                    self.kill()
                    break
                if line is None:  # the worker ended
                    if busy[proc.pid] is not None:
                        over(proc, f"worker exited with {proc.wait()}: {self._tail(proc)}")
                    continue
                kind, _, rest = line.rstrip("\n").partition(" ")
                if kind == "compiled":
                    self.seen(rest)
                elif kind == "done" and busy[proc.pid] is not None:
                    over(proc, None)
                elif kind == "failed" and busy[proc.pid] is not None:
                    over(proc, rest.replace("\\n", "\n"))
                assign()
            for name in pending:  # workers gone before these could run
                report.failed[name] = "not run: no worker left"
        finally:
            self.close()

    def _tail(self, proc: subprocess.Popen) -> str:
        log = self.logs[self.procs.index(proc)]
        log.seek(0)
        return log.read()[-500:].strip()

    def kill(self) -> None:
        for proc in self.procs:
            if proc.poll() is None:
                proc.kill()

    def close(self) -> None:
        for proc in self.procs:
            try:
                proc.stdin.close()
            except OSError:
                pass
        for proc in self.procs:
            try:
                proc.wait(timeout=60)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        for log in self.logs:
            log.close()


def serve(table: Mapping[str, Exercise]) -> int:
    """Serve :func:`run_exercises` as its worker: run the exercises named on stdin, one a line.

    Each line to the parent (``compiled <kernel>``, ``done <exercise>``, ``failed <error>``)
    goes to the original stdout; anything else written to file descriptor 1 (by Python or
    by a solver's C code) goes to stderr, the parent's log.

    Parameters
    ----------
    table : mapping of str to Exercise
        The exercises by name (the parent's ``table``).

    Returns
    -------
    int
        0, once stdin is closed (the exit status of the worker).
    """
    protocol = os.fdopen(os.dup(1), "w", buffering=1)
    os.dup2(2, 1)

    def say(*words: str) -> None:
        protocol.write(" ".join(words) + "\n")
        protocol.flush()

    add_compile_hook(lambda name: say("compiled", name))
    for line in sys.stdin:
        name = line.strip()
        if not name:
            continue
        try:
            table[name].run()
        except Exception as exc:  # noqa: BLE001 - reported to the parent
            detail = "".join(traceback.format_exception_only(type(exc), exc)).strip()
            say("failed", detail.replace("\n", "\\n"))
        else:
            say("done", name)
    return 0
