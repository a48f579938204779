"""Shared fixtures and settings.

* Where the real maps live (``TRAJOPT_DATA``, default ``../shared/data``).
* Hypothesis profiles: ``deterministic`` (the default, and what CI runs: every run draws the
  same examples, so the README's test command cannot pass one run and fail the next) and
  ``explore`` (fresh random examples each run, for looking for new failures:
  ``HYPOTHESIS_PROFILE=explore python -m pytest``). Cases an exploration finds are pinned
  in their test with ``@example``.
* A fresh clone (or venv, or CI runner) has no compiled numba kernels yet: the session
  first compiles every kernel numba's cache lacks, in two worker processes
  (:func:`trajopt.warmup.compile_kernels`, what ``trajopt warm-up`` does), instead of
  one test after another compiling them serially. ``TRAJOPT_PRECOMPILE=0`` skips it.
* The fresh Python processes that some test modules check (``early_processes`` in
  ``tests/trajopt/test_warm_up.py``, ``tests/trajopt/test_kernel_cache.py`` and
  ``tests/trajopt/analysis/test_bench.py``) are started, or queued in the session's
  background lane, when collection ends, and run while the other tests run
  (``tests/processes.py``; ``TRAJOPT_EARLY_PROCESSES=0`` starts them when their module's
  first test runs).
* Bytecode is cached even where ``PYTHONDONTWRITEBYTECODE`` is set: pytest's rewritten test
  modules (``tests/**/__pycache__``) and the packages' compiled sources (``__pycache__``
  beside them, where numba's cache already lives; both ignored by git). Without it every
  run rewrites the assertions of every test module and compiles every source again before
  the first test (about 10 s of the collection on the shared 2-core machine), and every
  fresh process a test starts compiles the sources again.
* The heap is frozen (``gc.freeze``) when each test module starts, after a collection: what
  is alive then (the imports, the collected tests, the session's fixtures; most of a heap
  that ends near a million objects) lives on, and the collector's full passes during the
  module then walk only what the module made, not that whole heap again (in a 138 s run, 21
  full passes took 9.6 s; frozen so, 140 passes took 4.0 s, most of it pytest's 5 closing
  ones). The heap is unfrozen when the session finishes, so pytest's closing collections
  (for unraisable exceptions) see every object as before.
* The notebooks execute in the background lane too, after the queued processes, from the
  moment their tests are collected on (when no ``-k``, ``-m`` other than the default,
  ``--deselect``, ``--lf`` or ``--sw`` can drop them later; else from the end of collection
  on); their checks (``tests/test_notebooks.py::test_notebook_executes``) run last
  (``tests/notebook_runner.py``; ``TRAJOPT_NOTEBOOKS_BACKGROUND=0`` runs each inside its
  test instead).
"""

from __future__ import annotations

import gc
import os
import sys
from pathlib import Path

import pytest
from hypothesis import settings

# jsonschema (imported by nbformat and nbclient for the notebook tests) registers its
# optional "iri" format check when rfc3987_syntax is installed, whose import builds a grammar
# for ~2.5 s while holding the GIL, so the tests stall meanwhile. No schema the tests use has
# an "iri" format (nbformat's notebook schema has no format at all, and nbformat validates
# without a format checker), so the test process does without it.
if "rfc3987_syntax" not in sys.modules:
    sys.modules["rfc3987_syntax"] = None  # type: ignore[assignment]  # ImportError on import

# The bytecode caches (module docstring): pytest reads this flag when it imports each test
# module, after this file.
sys.dont_write_bytecode = False

settings.register_profile("deterministic", derandomize=True, database=None, print_blob=True)
settings.register_profile("explore", derandomize=False, print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "deterministic"))

_REPO = Path(__file__).resolve().parents[1]


def pytest_sessionstart(session: pytest.Session) -> None:
    """Compile the kernels numba's disk cache lacks before the first test (module docstring)."""
    if os.environ.get("TRAJOPT_PRECOMPILE", "1") == "0":
        return
    import trajopt.kernel_cache as kernel_cache

    cold = kernel_cache.cold_kernels()
    if not cold:
        return
    tr = session.config.pluginmanager.get_plugin("terminalreporter")
    say = tr.write_line if tr is not None else print
    say(
        f"trajopt: compiling {len(cold)} numba kernels first (once per environment; "
        "TRAJOPT_PRECOMPILE=0 skips)..."
    )
    import trajopt.warmup as warm

    report = warm.compile_kernels()
    say(f"trajopt: compiled {len(report.compiled)} kernels in {report.seconds:.1f} s")
    for name, error in report.failed.items():
        say(f"trajopt: warm-up exercise {name!r} failed: {error}")


def data_dir() -> Path:
    """The shared map folder: ``$TRAJOPT_DATA`` or ``<repo>/../shared/data``."""
    env = os.environ.get("TRAJOPT_DATA")
    return Path(env) if env else _REPO.parent / "shared" / "data"


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """The shared data folder; skips the test with a reason when it is absent."""
    d = data_dir()
    if not (d / "movingai").is_dir() or not (d / "ros").is_dir():
        pytest.skip(f"shared map data not found at {d} (set TRAJOPT_DATA)")
    return d


# ------------------------------------------------------------------ the notebooks
def _notebook_items(items: list[pytest.Item]) -> list[pytest.Item]:
    return [
        i
        for i in items
        if getattr(i, "originalname", None) == "test_notebook_executes"
        and getattr(getattr(i, "module", None), "__name__", None) == "tests.test_notebooks"
    ]


def _is_notebook_item(item: pytest.Item) -> bool:
    return bool(_notebook_items([item]))


def _selection_is_final(config: pytest.Config) -> bool:
    """Whether every collected test is also selected (no -k, no other -m, no --deselect, no
    --lf or --sw, which deselect too)."""
    opt = config.option
    return (
        not getattr(opt, "keyword", "")
        and getattr(opt, "markexpr", "") in ("", "not slow")
        and not getattr(opt, "deselect", None)
        and not getattr(opt, "lf", False)
        and not getattr(opt, "stepwise", False)
        and not opt.collectonly
    )


def pytest_itemcollected(item: pytest.Item) -> None:
    """Start a notebook as soon as its test is collected, when it cannot be deselected."""
    if _is_notebook_item(item) and _selection_is_final(item.config):
        from tests import notebook_runner

        if notebook_runner.background_wanted():
            notebook_runner.runner().start([item.callspec.params["path"]])


@pytest.hookimpl(trylast=True)
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Run the notebook executions last: meanwhile they execute in the background."""
    last = set(_notebook_items(items))
    if last:
        items[:] = [i for i in items if i not in last] + [i for i in items if i in last]


def pytest_collection_finish(session: pytest.Session) -> None:
    """Start the modules' fresh processes (tests/processes.py) and the selected notebooks in a
    background thread (tests/notebook_runner.py)."""
    if session.config.option.collectonly:
        return
    from tests import processes

    if processes.early_wanted():
        processes.start_early(session.items)
    items = _notebook_items(session.items)
    if not items:
        return
    from tests import notebook_runner

    if notebook_runner.background_wanted():
        notebook_runner.runner().start([i.callspec.params["path"] for i in items])


_module_started: list[object] = [None]


def pytest_runtest_setup(item: pytest.Item) -> None:
    """Freeze the heap when a test module starts (module docstring): collected first, so that
    no garbage is frozen (the previous module's fixtures are torn down by now)."""
    module = getattr(item, "module", None)
    if module is not _module_started[0]:
        _module_started[0] = module
        gc.collect()
        gc.freeze()


def pytest_sessionfinish(session: pytest.Session) -> None:
    """Stop the notebook runner (drop what has not started) and the modules' processes still
    running; remove their scratch files. Unfreeze the heap (frozen as each module started)."""
    gc.unfreeze()
    if "tests.notebook_runner" in sys.modules:
        sys.modules["tests.notebook_runner"].shutdown()
    if "tests.processes" in sys.modules:
        sys.modules["tests.processes"].stop_all()
