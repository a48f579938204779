"""Tests of trajopt.kernel_cache: every kernel is known, warmed up and compiled once, with a notice.

* Every numba dispatcher of astar and trajopt lives in a module of ``KERNEL_MODULES``.
* ``trajopt.warm_up()`` leaves every kernel compiled and loaded (a signature each), and
  its exercises reach every kernel, directly or through the kernels that call it (so a new
  kernel the exercises leave out fails here, whatever numba's cache holds).
* In a fresh numba cache: the kernels are cold, worker processes compile them into the
  cache, and a first compilation logs one notice per process (none when loading).
* ``trajopt warm-up`` on the command line.

The fresh processes these checks need are queued when collection ends
(:func:`early_processes`, ``tests/processes.py``) and run one after another in the background
of the other tests; each test reads its own.
"""

from __future__ import annotations

import json
import os

import pytest

import trajopt.kernel_cache as kernel_cache
from tests.processes import Queued, module_processes, scratch_dir
from trajopt.cli import main

EVERY_DISPATCHER = """
    import importlib, json, pkgutil
    from numba.core.dispatcher import Dispatcher
    import astar, trajopt
    found = {}
    for pkg in (astar, trajopt):
        for m in pkgutil.walk_packages(pkg.__path__, pkg.__name__ + "."):
            mod = importlib.import_module(m.name)
            for k, v in vars(mod).items():
                if isinstance(v, Dispatcher) and v.py_func.__module__ == m.name:
                    found.setdefault(m.name, []).append(k)
    print(json.dumps(found))
"""


WARM_UP_REACHES_EVERYTHING = """
    import json, types
    from numba.core.dispatcher import Dispatcher
    reached = set()
    enter = Dispatcher._compile_for_args  # a kernel's first call from Python
    def record(self, *args, **kws):
        reached.add(self)
        return enter(self, *args, **kws)
    Dispatcher._compile_for_args = record
    import trajopt
    import trajopt.kernel_cache as kernel_cache
    trajopt.warm_up()
    every = kernel_cache.dispatchers()
    def names(code):
        out = set(code.co_names)
        for c in code.co_consts:
            if isinstance(c, types.CodeType):
                out |= names(c)
        return out
    def callees(d):
        g, used = d.py_func.__globals__, names(d.py_func.__code__)
        out = []
        for n in used:
            v = g.get(n)
            if isinstance(v, types.ModuleType):  # module.kernel inside a kernel
                out += [getattr(v, a) for a in used if isinstance(getattr(v, a, None), Dispatcher)]
            elif isinstance(v, Dispatcher):
                out.append(v)
        return out
    closure, todo = set(), list(reached)
    while todo:
        d = todo.pop()
        if d not in closure:
            closure.add(d)
            todo += callees(d)
    inline = {k for k, d in every.items() if d.targetoptions.get("inline") == "always"}
    print(json.dumps({
        "unreached": sorted(k for k, d in every.items() if d not in closure),
        "unloaded": sorted(k for k, d in every.items() if k not in inline and not d.signatures),
        "inline_called_alone": sorted(k for k in inline if every[k].signatures),
    }))
"""


#: In a fresh numba cache: two workers compile the "grid" and "astar" exercises' kernels.
FRESH_CACHE_COMPILE = """
    import json
    import trajopt.kernel_cache as kernel_cache
    import trajopt.warmup as warm
    cold = kernel_cache.cold_kernels()
    report = warm.compile_kernels(["grid", "astar"], workers=2)
    print(json.dumps({"cold": cold, "compiled": report.compiled, "workers": report.workers,
                      "failed": report.failed, "left": kernel_cache.cold_kernels()}))
"""

#: A new process on the cache the workers filled: it loads, nothing compiles and nothing
#: is logged; then a first compilation logs one line, a second one nothing.
FRESH_CACHE_LOAD = """
    import logging, sys
    logging.basicConfig(format="%(levelname)s %(name)s: %(message)s")
    import numba.core.event as ev
    import numpy as np
    import trajopt.kernel_cache as kernel_cache
    from trajopt.geometry._convex_hull import convex_hull
    rec = ev.install_recorder("numba:compile").__enter__()
    n = kernel_cache.load_kernels(["astar.distance_transform", "astar.inflation",
                                   "astar.search_kernels"])
    print(n, sum(1 for e in rec.buffer if e[1].is_start))
    print("LOADED", file=sys.stderr, flush=True)
    convex_hull(np.random.default_rng(0).normal(size=(20, 2)))
    convex_hull(np.random.default_rng(1).normal(size=(20, 2)))
"""

#: The exercises live in trajopt.warmup, a name of their own: importing that module (as
#: the compile workers do, which run it) leaves trajopt.warm_up the function.
EXERCISES_MODULE = """
    import types
    import trajopt.warmup
    assert trajopt.warmup.WORKER_COMMAND[1:] == ("-m", "trajopt.warmup", "--worker")
    from trajopt import warm_up
    assert callable(warm_up) and not isinstance(warm_up, types.ModuleType), warm_up
    assert warm_up is trajopt.warmup.warm_up
    print("ok")
"""

#: The fresh processes each test reads (the fresh-cache test's second one, FRESH_CACHE_LOAD,
#: is queued after its first one: :func:`early_processes`).
PROCESSES = {
    "test_every_dispatcher_is_in_a_kernel_module": EVERY_DISPATCHER,
    "test_warm_up_compiles_loads_and_reaches_every_kernel": WARM_UP_REACHES_EVERYTHING,
    "test_fresh_cache_workers_compile_and_a_notice_shows_once": FRESH_CACHE_COMPILE,
    "test_the_exercises_module_does_not_shadow_trajopt_warm_up": EXERCISES_MODULE,
}


def early_processes(items) -> dict[str, Queued]:
    """The fresh processes of the selected tests, queued when collection ends
    (tests/processes.py); those of a fresh numba cache share one new, empty cache folder (a
    fresh clone's), and the load runs after the compile."""
    names = {getattr(i, "originalname", None) for i in items}
    fresh_cache = dict(os.environ, NUMBA_CACHE_DIR=scratch_dir("trajopt_numba_"))
    runs: dict = {
        name: Queued(script, env=fresh_cache if "fresh_cache" in name else None)
        for name, script in PROCESSES.items()
        if name in names
    }
    compiled = runs.get("test_fresh_cache_workers_compile_and_a_notice_shows_once")
    if compiled is not None:  # a new process on the cache the workers filled
        runs["fresh_cache_load"] = Queued(FRESH_CACHE_LOAD, env=fresh_cache)
    return runs


@pytest.fixture(scope="module")
def started(request) -> dict[str, Queued]:
    """The fresh processes of the selected tests (:func:`early_processes`)."""
    return module_processes(request)


def _ok(run: Queued) -> str:
    out = run.result()
    assert out.returncode == 0, out.stderr[-3000:]
    return out.stdout


def test_every_dispatcher_is_in_a_kernel_module(started):
    found = json.loads(_ok(started["test_every_dispatcher_is_in_a_kernel_module"]))
    assert set(found) == set(kernel_cache.KERNEL_MODULES)
    listed = kernel_cache.dispatchers()
    assert sorted(listed) == sorted(f"{m}.{k}" for m, ks in found.items() for k in ks)


def test_warm_up_compiles_loads_and_reaches_every_kernel(started):
    # A fresh process: after trajopt.warm_up() every kernel has a compiled signature (the
    # inline="always" ones excepted: numba inlines them into their callers, so they have none
    # of their own), and the exercises reach every dispatcher, by a call from Python or as a
    # callee of one they call (read from the kernels' code): a new kernel left out of the
    # exercises fails here even when numba's cache already holds it from another run.
    run = started["test_warm_up_compiles_loads_and_reaches_every_kernel"]
    out = json.loads(_ok(run).splitlines()[-1])
    assert out["unreached"] == [], "kernels no warm-up exercise calls (trajopt.warmup.EXERCISES)"
    assert out["unloaded"] == [], "kernels without a compiled signature after warm_up()"
    assert out["inline_called_alone"] == []


def test_fresh_cache_workers_compile_and_a_notice_shows_once(started):
    compiled_run = started["test_fresh_cache_workers_compile_and_a_notice_shows_once"]
    out = json.loads(_ok(compiled_run))
    grid = {
        "astar.distance_transform._transform",
        "astar.distance_transform._column_pass",
        "astar.distance_transform._row_pass",
        "astar.inflation._dilate_rows",
        "astar.search_kernels.astar_kernel",
        "astar.search_kernels.unroll_path",
    }
    assert set(out["cold"]) == set(kernel_cache.kernels())  # nothing cached yet
    assert out["workers"] == 2 and out["failed"] == {}
    assert grid <= set(out["compiled"])
    assert not grid & set(out["left"])
    assert set(out["left"]) == set(out["cold"]) - set(out["compiled"])
    # the cache the workers filled serves a new process (FRESH_CACHE_LOAD)
    run = started["fresh_cache_load"]
    loaded, compiled = map(int, _ok(run).split())
    assert loaded >= len(grid) and compiled == 0
    before, after = run.result().stderr.split("LOADED")
    assert "compiling numerical kernels" not in before, before
    lines = [s for s in after.splitlines() if "compiling numerical kernels once" in s]
    assert len(lines) == 1, after
    assert lines[0].startswith("WARNING trajopt.kernel_cache: trajopt: compiling")
    assert "trajopt warm-up" in lines[0]


def test_cli_warm_up(capsys):
    assert main(["warm-up", "--workers", "1"]) == 0
    out = capsys.readouterr().out
    n = len(kernel_cache.kernels())
    assert f"{n} of {n} kernels compiled and loaded" in out
    assert kernel_cache.cold_kernels() == []


@pytest.mark.parametrize("workers", ["0", "-1"])
def test_cli_warm_up_rejects_bad_workers(workers, capsys):
    assert main(["warm-up", "--workers", workers]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--workers must be >= 1" in err


def test_unknown_exercise_is_an_error():
    import trajopt.warmup as warm
    from trajopt.errors import InvalidInputError

    with pytest.raises(InvalidInputError, match="unknown warm-up exercise 'nope'"):
        warm.compile_kernels(["nope"], force=True)


def test_the_kernel_cache_loads_only_kernel_modules_by_name():
    """``kernel_cache`` sits below every module that uses it: the only modules it names (and
    loads with importlib) are the kernel modules; the warm-up exercises come from its caller
    (``trajopt.warmup.compile_kernels``), so no run-time import cycle closes through it."""
    import ast
    from pathlib import Path

    tree = ast.parse(Path(kernel_cache.__file__).read_text())
    docstrings = {
        id(node.body[0].value)
        for node in ast.walk(tree)
        if isinstance(node, (ast.Module, ast.FunctionDef, ast.ClassDef))
        and node.body
        and isinstance(node.body[0], ast.Expr)
        and isinstance(node.body[0].value, ast.Constant)
    }
    named = {
        node.value
        for node in ast.walk(tree)
        if isinstance(node, ast.Constant)
        and isinstance(node.value, str)
        and id(node) not in docstrings
        and node.value.startswith(("trajopt.", "astar."))
    }
    assert named - {"trajopt.", "astar."} == set(kernel_cache.KERNEL_MODULES)
    imported = {
        a.name if isinstance(node, ast.Import) else node.module
        for node in ast.walk(tree)
        if isinstance(node, (ast.Import, ast.ImportFrom))
        for a in node.names
    }
    assert not {m for m in imported if m and m.startswith("trajopt.")} - {"trajopt.errors"}


def test_the_exercises_module_does_not_shadow_trajopt_warm_up(started):
    run = started["test_the_exercises_module_does_not_shadow_trajopt_warm_up"]
    assert _ok(run).strip() == "ok"  # EXERCISES_MODULE
