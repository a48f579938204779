"""Benchmark: ``time_parameterize`` of this tree against an earlier commit, on the same curves.

The curves are planned once with this tree (``bench_timing.py``'s paths: the paper scene's
targets and Moving AI scenarios) and saved as B-splines; each code version then times every
curve in a fresh process (the earlier commit's ``trajopt`` exported with ``git archive``),
and the rounds alternate between the two versions so that both see the same machine load.
It prints, per path and over all of them, the compute time per second of trajectory (best
of the runs) and the relative difference of the durations.

Run from the repository root::

    python benchmarks/compare_timing.py                      # against 1510844, 20 scenarios
    python benchmarks/compare_timing.py --base main --limit 60 --repeat 5 --rounds 3
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
BASE = "1510844"  # the timing before the speed-up of issue #19 (part 4)


def _worker(curves_file: str, repeat: int) -> None:
    """Time every saved curve with the ``trajopt`` on ``sys.path``; print JSON."""
    import trajopt
    from trajopt.geometry._bspline import BSplineCurve
    from trajopt.robot._robot import Robot
    from trajopt.timing import time_parameterize

    data = np.load(curves_file)
    robot = Robot()
    curves = [
        BSplineCurve(data[f"t{i}"], data[f"c{i}"], int(data[f"k{i}"]))
        for i in range(int(data["n"]))
    ]
    for c in curves:
        time_parameterize(c, robot)  # numba cache, arc-length tables
    out = []
    for c in curves:
        best = np.inf
        for _ in range(repeat):
            t0 = time.perf_counter()
            traj = time_parameterize(c, robot)
            best = min(best, time.perf_counter() - t0)
        out.append({"duration": traj.duration, "best_s": best})
    print(json.dumps({"trajopt": trajopt.__file__, "rows": out}))


def _save_curves(limit: int, path: Path) -> list[str]:
    """Plan the bench paths with this tree; save their B-splines to ``path`` (npz)."""
    sys.path.insert(0, str(ROOT))
    sys.path.insert(0, str(ROOT / "benchmarks"))
    import bench_timing

    from tests.conftest import data_dir
    from trajopt.robot._robot import Robot

    robot = Robot()
    curves = bench_timing.paper_curves(robot)
    curves += bench_timing.movingai_curves(robot, limit, data_dir())[0]
    arrays: dict[str, np.ndarray] = {"n": np.array(len(curves))}
    for i, (_, c) in enumerate(curves):
        spline = getattr(c, "curve", c)  # SmoothPath -> its BSplineCurve
        arrays[f"t{i}"], arrays[f"c{i}"], arrays[f"k{i}"] = spline.t, spline.c, np.array(spline.k)
    np.savez(path, **arrays)
    return [name for name, _ in curves]


def _run(tree: Path, curves_file: Path, repeat: int) -> dict:
    env = dict(os.environ, PYTHONPATH=str(tree))
    cmd = [
        sys.executable,
        str(Path(__file__).resolve()),
        "--worker",
        str(curves_file),
        "--repeat",
        str(repeat),
    ]
    res = subprocess.run(cmd, env=env, cwd=tree, capture_output=True, text=True, check=True)
    return json.loads(res.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--base", default=BASE, help=f"git revision to compare with (default {BASE})")
    ap.add_argument("--limit", type=int, default=20, help="Moving AI scenarios (default 20)")
    ap.add_argument("--repeat", type=int, default=3, help="timings per curve and round (best)")
    ap.add_argument("--rounds", type=int, default=2, help="alternating rounds per version")
    ap.add_argument("--worker", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        _worker(args.worker, args.repeat)
        return
    warnings.filterwarnings("ignore")
    with tempfile.TemporaryDirectory() as tmp:
        base_tree = Path(tmp) / "base"
        base_tree.mkdir()
        archive = subprocess.run(
            ["git", "archive", args.base, "trajopt", "astar"],
            cwd=ROOT,
            capture_output=True,
            check=True,
        ).stdout
        subprocess.run(["tar", "-x", "-C", str(base_tree)], input=archive, check=True)
        curves_file = Path(tmp) / "curves.npz"
        names = _save_curves(args.limit, curves_file)
        rev = subprocess.run(
            ["git", "rev-parse", "--short", args.base],
            cwd=ROOT,
            capture_output=True,
            text=True,
            check=True,
        ).stdout.strip()
        print(
            f"{len(names)} curves; base {args.base} ({rev}) vs this tree; best of "
            f"{args.repeat} x {args.rounds} rounds"
        )
        best = {"base": np.full(len(names), np.inf), "head": np.full(len(names), np.inf)}
        dur: dict[str, np.ndarray] = {}
        for _ in range(args.rounds):
            for key, tree in (("base", base_tree), ("head", ROOT)):
                out = _run(tree, curves_file, args.repeat)
                best[key] = np.minimum(best[key], [r["best_s"] for r in out["rows"]])
                dur[key] = np.array([r["duration"] for r in out["rows"]])
    rel = (dur["head"] - dur["base"]) / dur["base"]
    per = {k: 1e3 * best[k] / dur[k] for k in best}  # ms of compute per s of trajectory
    print(
        f"\n  {'path':42s} {'duration s':>10s} {'rel. diff':>10s} {'ms/s base':>10s} "
        f"{'ms/s new':>9s} {'speed-up':>8s}"
    )
    for i, name in enumerate(names):
        print(
            f"  {name[:42]:42s} {dur['head'][i]:10.3f} {rel[i]:10.2e} {per['base'][i]:10.4f} "
            f"{per['head'][i]:9.4f} {per['base'][i] / per['head'][i]:8.2f}"
        )
    paper = np.array([n.startswith("paper:") for n in names])
    for label, sel in (("paper scene", paper), ("all paths", np.ones_like(paper))):
        print(
            f"\n{label}: compute per second of trajectory (best of runs), median "
            f"{np.median(per['base'][sel]):.4f} ms -> {np.median(per['head'][sel]):.4f} ms, "
            f"max {per['base'][sel].max():.4f} ms -> {per['head'][sel].max():.4f} ms"
        )
    print(
        f"max |relative duration difference| {np.abs(rel).max():.2e} "
        f"(median {np.median(np.abs(rel)):.2e})"
    )


if __name__ == "__main__":
    main()
