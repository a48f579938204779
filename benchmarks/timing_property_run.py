"""Timing property run: random clamped cubic B-splines, every limit checked every 1 ms.

Draws curves as in issue 17 (4-9 control points in [-2, 2]^2, consecutive points >= 0.2 m
apart, parametric speed never below 5 % of its maximum, length > 0.5 m) from a seeded
generator, times each with ``time_parameterize`` for a slow, tight-turning robot and checks
the trajectory on samples 1 ms apart against the speed cap computed from the trajectory's
own curvature and from the curve's curvature at ``u_at_s(s)``, and every other limit with ``tests/trajopt/timing/test_timing.check_limits``::

    python benchmarks/timing_property_run.py                   # 1000 curves, seed 0
    python benchmarks/timing_property_run.py --examples 200 --seed 3

Prints the number of curves, the errors raised, the violations with the worst ratio
``v / cap`` and the control points that reproduce each. Exit code 1 when a limit broke.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tests.trajopt.timing.test_timing import check_limits  # noqa: E402
from trajopt.errors import TimingError
from trajopt.geometry._bspline import BSplineCurve, clamped_uniform_knots
from trajopt.robot._robot import Robot
from trajopt.timing import time_parameterize

ROBOT = Robot(
    v_max=0.5,
    a_max=0.5,
    j_max=2.0,
    a_lat_max=0.5,
    omega_max=1.5,
    track_width=None,
    wheel_v_max=None,
)


def draw_curve(rng: np.random.Generator) -> BSplineCurve | None:
    """One random curve by the issue's recipe, or None when the draw is rejected."""
    n = int(rng.integers(4, 10))
    p = rng.uniform(-2.0, 2.0, size=(n, 2))
    if np.min(np.hypot(*np.diff(p, axis=0).T)) < 0.2:
        return None
    c = BSplineCurve(clamped_uniform_knots(n, 3), p, 3)
    sp = c.speed(np.linspace(*c.domain, 2001))
    if np.min(sp) < 0.05 * np.max(sp) or c.length <= 0.5:
        return None
    return c


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--examples", type=int, default=1000, help="curves to time")
    parser.add_argument("--seed", type=int, default=0, help="generator seed")
    args = parser.parse_args(argv)
    rng = np.random.default_rng(args.seed)
    done = errors = 0
    bad: list[tuple[float, str, np.ndarray]] = []
    worst = 0.0
    t0 = time.perf_counter()
    while done < args.examples:
        c = draw_curve(rng)
        if c is None:
            continue
        done += 1
        try:
            traj = time_parameterize(c, ROBOT)
        except TimingError:
            errors += 1
            continue
        smp = traj.sample(np.arange(0.0, traj.duration + 1e-3, 1e-3))
        kappa = np.asarray(c.curvature(c.u_at_s(smp.s)))  # from the curve, not the timing
        cap = np.minimum(ROBOT.speed_cap(smp.kappa), ROBOT.speed_cap(kappa))
        ratio = float(np.max(smp.v / np.maximum(cap, 1e-300)))
        worst = max(worst, ratio)
        try:
            check_limits(traj, ROBOT)
        except AssertionError as exc:
            bad.append((ratio, str(exc)[:200], np.asarray(c.c)))
    print(
        f"curves: {done}, TimingError: {errors}, violations: {len(bad)}, "
        f"max v/cap on 1 ms samples: {worst:.6f} ({time.perf_counter() - t0:.0f} s)"
    )
    for ratio, msg, ctrl in sorted(bad, key=lambda b: -b[0]):
        print(f"- v/cap {ratio:.4f}: {msg!r}\n  control points: {np.round(ctrl, 12).tolist()}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
