"""Near time-optimal, jerk-limited time parameterisation of a curve along its arc length.

:func:`time_parameterize` times a 1-DoF motion ``s(t)`` from ``s = 0`` to ``s = L`` under

* ``|a| <= a_max``, ``|jerk| <= j_max``, ``v >= 0`` (``s`` never decreases), and
* the curvature-dependent speed cap ``v <= cap(s) = Robot.speed_cap(kappa(s))``, i.e.
  ``v <= v_max``, lateral acceleration ``|kappa| v^2 <= a_lat_max``, yaw rate
  ``|kappa| v <= omega_max`` and wheel speeds ``v (1 + |kappa| w/2) <= wheel_v_max`` (an
  omnidirectional robot, ``drive=Omni()``, has only the first two: its body turns
  independently of the path, see :func:`orient`).

ruckig (community edition, 1-DoF, no ``intermediate_positions``: that option sends the
problem to a cloud service) holds the first group; the cap is held by the design below.

Method
------
1. **Cap table.** One value per interval of a uniform arc-length grid (spacing 2.5 mm;
   at most 16 384 intervals, so longer on curves over 41 m):
   a lower bound of the cap over the interval, times ``1 - 1e-4``; speeds up to
   ``max(v_start, v_end)`` may use the cap without that factor so that boundary speeds
   equal to the cap are allowed. For a curve with a ``polynomial_degree`` (every curve of
   the library) the bound is rigorous whatever the width of a curvature peak:
   :func:`trajopt.geometry._curvature_bound.interval_kappa_max` bounds ``|kappa|`` on the curve's
   polynomial pieces by Bernstein coefficients, bisects them until the bound is tight
   (0.1 % of the cap) or harmless, and maps each piece to the intervals its exact arc-length
   range touches. For the library's curves (the base class's arc length and geometry, a
   ``Robot``'s own ``speed_cap``) compiled code does this together with the grid's
   ``u(s)``, heading and curvature (:func:`trajopt.timing._cap_kernel.polynomial_tables`,
   from the Taylor coefficients of each piece's velocity; ``interval_kappa_max`` is the NumPy
   form of the same method and the path for other curves). Any other curve is sampled: an
   interval gets the smaller cap at its ends minus a second-difference bound on a convex
   dip, and is resampled at 16 inner points
   (with a golden-section search next to the lowest) where that dip is large, or where the
   heading turned across it or a second-difference bound on ``|kappa|`` says the curvature
   may peak inside. A sparse table answers "minimum cap over ``[s_a, s_b]``" in O(1).
2. **Forward greedy** (compiled with numba). Steps of ``dt`` (20 ms) with a constant jerk
   ``u`` from ``{j, 0.75 j, ..., -j}`` plus the ``u`` that zeroes ``a`` (clamped at
   ``+-a_max``). A step is *safe* when the step and its **stop profile** (the time-optimal
   jerk-limited brake to ``v = 0``, ``a = 0``: closed form, the lowest continuation in the
   ``(s, v)`` plane) stay under the cap and the state can still reach ``(L, v_end)``. The
   cap test is exact on the grid: a constant-jerk piece passes when its speed maximum
   (including the interior peak ``v + a^2/(2|u|)``) is below the minimum cap over the
   ``s``-range it covers, otherwise it is bisected in time (down to 0.1 ms). A safe step
   also passes the *target* test when, for every local minimum of the cap within its stop
   distance, the time-optimal slow-down to that speed (with ``a = 0``) ends before it. The
   greedy takes the largest ``u`` passing both, else the largest safe one, else follows its
   own (safe) stop profile; at rest it only considers ``u > 0`` (a zero jerk there would idle
   forever). A cruise step (``a = 0``, jerk 0) is repeated without re-testing while all
   that its tests query lies on one run of equal caps (the same caps give the same choice:
   the phases are those of testing every step). When only the end condition blocks it, one ruckig position call to
   ``(L, v_end, 0)`` finishes the motion, its ``max_velocity`` the lowest cap ahead (or the
   state's own peak speed when that call breaks the cap).
3. **Compress.** Knots at the greedy's speed minima (states with ``a = 0``); between two
   knots one ruckig position call with ``max_velocity`` = the highest cap over the section
   when that is above the greedy's peak speed there, else the greedy's peak speed (the
   greedy is feasible for that problem, so ruckig's time-optimal answer is never slower).
   A section whose ruckig profile breaks the cap or is slower than the greedy is split at
   the greedy step nearest its mid-time (up to 6 levels), else the greedy's own phases are
   kept.

The result is a chain of constant-jerk phases (:class:`trajopt.Trajectory`). Limits hold on
dense samples: ``a`` and ``jerk`` exactly (ruckig and the greedy both clamp), the speed cap
by construction of the table for polynomial curves (relative 1e-4 margin), and up to the
sampling's resolution for other curves. On the benchmark paths the durations are within a few percent of TOPP-RA's
jerk-free time-optimal answer (``benchmarks/bench_timing.py``).

Modules: :mod:`~trajopt.timing._parameterize` (the entry point),
:mod:`~trajopt.timing._cap_table` (stage 1) with :mod:`~trajopt.timing._cap_kernel` (its
compiled path; :mod:`~trajopt.timing._cap_cubic` its bound on cubic pieces, unrolled),
:mod:`~trajopt.timing._greedy` (the compiled
kernels of stage 2), :mod:`~trajopt.timing._compress` (stages 3 and 4) and
:mod:`~trajopt.timing._ruckig_profile` (the ruckig wrapper, also used by the stop-and-turn
fallback). :mod:`~trajopt.timing._orientation` (:func:`orient`) gives an omnidirectional
robot's translation its own orientation profile, turned while it drives.
"""

from trajopt.timing._cap_table import CapTable, build_cap_table
from trajopt.timing._greedy import advance, brake_times
from trajopt.timing._orientation import orient, start_rates, stop_orientation, yaw_stop
from trajopt.timing._parameterize import time_parameterize
from trajopt.timing._ruckig_profile import RuckigProfile
from trajopt.timing._speed_limits import SpeedLimits, check_overlap, load_speed_mask
from trajopt.timing._stop_and_turn import stop_and_turn, turn_in_place, turn_limits

__all__ = [
    "CapTable",
    "RuckigProfile",
    "SpeedLimits",
    "advance",
    "brake_times",
    "build_cap_table",
    "check_overlap",
    "load_speed_mask",
    "orient",
    "start_rates",
    "stop_and_turn",
    "stop_orientation",
    "time_parameterize",
    "turn_in_place",
    "turn_limits",
    "yaw_stop",
]
