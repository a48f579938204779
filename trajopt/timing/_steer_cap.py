"""The speed cap that holds a car-like robot's steering-angle rate.

A car steers with ``delta = atan(L kappa)`` (``L`` the wheelbase). Along a path timed with
speed ``v`` the steering rate is ``d delta / dt = L (d kappa / ds) v / (1 + (L kappa)^2)``,
so ``|d delta / dt| <= steer_rate_max`` is a speed cap,
``v <= steer_rate_max (1 + (L kappa)^2) / (L |d kappa / ds|)``
(:meth:`trajopt.drive.Ackermann.steer_speed_cap`), folded into the timing's cap table beside the
curvature caps. For a curve with a ``polynomial_degree`` (every curve of the library) the cap
of an interval of the table is a rigorous lower bound over the whole interval
(:func:`~trajopt.geometry._curvature_bound.interval_steer_cap`: Bernstein bounds of
``|d kappa / ds|`` from above and ``|kappa|`` from below on bisected polynomial pieces), so
the steering rate holds everywhere, between samples too. For other curves it is the lowest
of the exact pointwise cap at the interval's two nodes and :data:`INNER` points evenly
spaced in the curve parameter between them, less :data:`MARGIN` (sampled).
"""

from __future__ import annotations

import numpy as np

from trajopt.geometry import ParametricCurve, interval_steer_cap
from trajopt.robot import Robot

#: Points per interval besides its nodes where the sampled steering cap is evaluated.
INNER = 3
#: Relative margin below the sampled cap (curves without a polynomial degree).
MARGIN = 1e-3


def steer_caps(
    curve: ParametricCurve,
    robot: Robot,
    u_nodes: np.ndarray,
    h: float | None = None,
    degree: int | None = None,
) -> np.ndarray:
    """Return the steering-rate speed cap of each interval between ``u_nodes`` (m/s).

    Parameters
    ----------
    curve : ParametricCurve
        The path; needs ``curvature`` and ``curvature_rate``.
    robot : Robot
        A car-like robot with ``steer_rate_max`` and ``wheelbase``.
    u_nodes : ndarray, shape (n + 1,)
        Curve parameter at the nodes of the cap table.
    h : float, optional
        The table's arc-length spacing (m), with ``degree``.
    degree : int, optional
        The curve's ``polynomial_degree``: the rigorous caps (module docstring); without
        it the sampled ones.

    Returns
    -------
    ndarray, shape (n,)
        A cap per interval (``inf`` where the steering does not change).
    """
    u = np.asarray(u_nodes, dtype=float)
    if degree is not None and h is not None:
        return interval_steer_cap(
            curve, float(h), u.shape[0] - 1, int(degree), robot.drive.steer_speed_cap, robot.v_max
        )
    frac = np.arange(INNER + 2, dtype=float) / (INNER + 1)
    pts = u[:-1, None] + (u[1:] - u[:-1])[:, None] * frac[None, :]  # (n, INNER + 2)
    cap = np.asarray(robot.drive.steer_speed_cap(curve.curvature(pts), curve.curvature_rate(pts)))
    return np.min(cap, axis=1) * (1.0 - MARGIN)
