"""Latency of the first ``plan`` in a fresh process, and where its time goes.

Each run is a new Python process that imports ``trajopt`` and then plans SP -> A on the
paper scene, with numba's on-disk cache and Python's bytecode cache already warm (one
untimed process runs first to fill both). The children may write bytecode even where
``PYTHONDONTWRITEBYTECODE`` is set: an installed package has its bytecode compiled by pip,
and without it every fresh process compiles trajopt's sources again (about 70-80 ms here). The scene (its grid, which needs numpy) is built before the clock starts. The child splits the first call's wall time into

* ``imports``: modules first imported during the call (numba, scipy, casadi, ...),
  counted once at the outermost ``import`` statement;
* ``numba cache``: loading compiled kernels from numba's disk cache, with the modules
  numba imports for itself while it loads them (its typing and lowering registries);
* ``solver build``: the smoother's CasADi solver builds (its own stat; 0 on the default
  path, whose QPs go to piqp directly and build no CasADi solver);
* ``rest``: everything else (search, corridor, QP solves, timing).

The second plan in the same process (SP -> B) shows the warm latency. Reported: the
median over ``--runs`` processes of each part, and of ``import trajopt`` itself; then, in
as many other fresh processes, the time of ``trajopt.warm_up()`` called at start-up and of
the first plan after it.

Run::

    python benchmarks/bench_first_call.py            # 5 fresh processes
    python benchmarks/bench_first_call.py --runs 9
    python benchmarks/bench_first_call.py --python /tmp/venv/bin/python   # an installed copy
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

CHILD = r"""
import builtins, json, sys, time

t0 = time.perf_counter()
import trajopt
t_import = time.perf_counter() - t0

state = {"depth": 0, "imports": 0.0, "numba": 0.0, "patched": False}
real_import = builtins.__import__


def outermost(fn, key):
    # fn, whose outermost calls add their wall time to state[key]

    def wrapped(*args, **kwargs):
        if state["depth"]:
            return fn(*args, **kwargs)
        state["depth"] += 1
        t = time.perf_counter()
        try:
            return fn(*args, **kwargs)
        finally:
            state[key] += time.perf_counter() - t
            state["depth"] -= 1
            if key == "imports":
                patch_numba()

    return wrapped


def patch_numba():
    caching = sys.modules.get("numba.core.caching")
    if not state["patched"] and caching is not None:
        state["patched"] = True
        caching.Cache.load_overload = outermost(caching.Cache.load_overload, "numba")


timed_import = outermost(real_import, "imports")


t_warm = trajopt.warm_up() if WARM else 0.0
scene = trajopt.scenes.paper()
robot = trajopt.Robot(radius=scene.robot_radius)
builtins.__import__ = timed_import
t1 = time.perf_counter()
first = trajopt.plan(scene.grid, scene.start, scene.goal("A"), robot=robot)
t_first = time.perf_counter() - t1
builtins.__import__ = real_import
t2 = time.perf_counter()
trajopt.plan(scene.grid, scene.start, scene.goal("B"), robot=robot)
t_second = time.perf_counter() - t2
build = float(first.stats.get("smoother", {}).get("build_time_s", 0.0) or 0.0)
print(json.dumps({"import_trajopt": t_import, "warm_up": t_warm, "first": t_first, "imports": state["imports"],
                  "numba": state["numba"], "build": build, "second": t_second,
                  "cffi": "cffi" in sys.modules}))
"""


def run_child(cwd: Path, python: str, warm: bool = False) -> dict:
    """Run one fresh process (after ``trajopt.warm_up()`` if ``warm``); timings in seconds."""
    code = f"WARM = {warm}\n" + CHILD
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    out = subprocess.run(
        [python, "-c", code], cwd=cwd, check=True, capture_output=True, text=True, env=env
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    """Print the median first-call breakdown over fresh processes."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=5, help="fresh processes (default 5)")
    ap.add_argument(
        "--python",
        default=None,
        help="interpreter of another environment with trajopt installed, e.g. a "
        "clean virtual environment's (default: this one, on this checkout)",
    )
    args = ap.parse_args()
    if args.python is None:  # this checkout, from its root
        python, cwd = sys.executable, Path(__file__).resolve().parents[1]
    else:  # the other environment's own trajopt: not this checkout's from the working dir
        python, cwd = args.python, Path(tempfile.gettempdir())
    run_child(cwd, python)  # fills numba's disk cache and the bytecode cache; not counted
    runs = [run_child(cwd, python) for _ in range(args.runs)]
    warm = [run_child(cwd, python, warm=True) for _ in range(args.runs)]

    def med(key: str) -> float:
        return 1e3 * statistics.median(r[key] for r in runs)

    rest = [1e3 * (r["first"] - r["imports"] - r["numba"] - r["build"]) for r in runs]
    print(f"first plan in a fresh process, paper scene SP -> A, median of {args.runs} processes")
    print(f"  interpreter {python}; cffi imported by numba: {runs[0]['cffi']}")
    print(f"  import trajopt            {med('import_trajopt'):7.1f} ms")
    print(f"  first plan (wall)         {med('first'):7.1f} ms   target <= 500 ms")
    print(f"    imports during the call {med('imports'):7.1f} ms")
    print(f"    numba cache loads       {med('numba'):7.1f} ms")
    print(f"    first solver build      {med('build'):7.1f} ms")
    print(f"    rest                    {statistics.median(rest):7.1f} ms")
    print(f"  second plan (SP -> B)     {med('second'):7.1f} ms")
    total = 1e3 * statistics.median(r["import_trajopt"] + r["first"] for r in runs)
    print(f"  import trajopt + first plan {total:7.1f} ms")
    print(f"after trajopt.warm_up() at start-up, median of {args.runs} processes")
    print(
        f"  warm_up()                 {1e3 * statistics.median(r['warm_up'] for r in warm):7.1f} ms"
    )
    print(
        f"  first plan (wall)         {1e3 * statistics.median(r['first'] for r in warm):7.1f} ms"
    )


if __name__ == "__main__":
    main()
