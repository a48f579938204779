"""The certificate's interval bounds for a disc robot against polygon movers, compiled.

:func:`disc_robot_bounds_kernel` is the arithmetic of the bisection's bounds
(:class:`trajopt.moving._certificate._Bisection`, a robot without a footprint) after the
robot's and the movers' evaluations at the intervals' middles: the mover's polygon placed
at its pose, the distance from the robot's centre to it, the first-order bound and, for a
disc mover, the second-order one (module docstring of :mod:`trajopt.moving._certificate`).
One loop over the intervals, the same operations in the same order as the array form, so
the same floats.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from trajopt.kernel_cache import watch_compiles
from trajopt.moving._polygon_distance import point_edge

watch_compiles()  # a first compilation logs one notice (trajopt.kernel_cache)


@njit(cache=True)
def disc_robot_bounds_kernel(
    t1, tm, h, mj, g, p, rho_p, v_rob, c2, pose, ch, sh, vel, turn, mover, verts, extra
):  # pragma: no cover - compiled
    """Return each interval's lower bound of the slack (m) and its slack at the middle (m).

    Parameters
    ----------
    t1, tm, h : ndarray, shape (n,)
        The intervals' ends, middles and half widths (s).
    mj, g : ndarray of int64, shape (n,)
        Each interval's mover and the row of its waypoint segment holding ``tm``
        (:class:`._mover_segments.MoverSegments`).
    p, v_rob : ndarray, shape (n, 2)
        The robot's centre (m) and velocity (m/s) at ``tm``.
    rho_p, c2 : ndarray, shape (n,)
        The bound (m) of the robot's motion from ``tm`` over the interval and of its
        acceleration (m/s^2) there.
    pose : ndarray, shape (n, 3)
        The mover's pose ``(x, y, heading)`` (m, m, rad) at ``tm``; ``ch``, ``sh`` (n,):
        the heading's cosine and sine.
    vel, turn : ndarray, shape (rows, 2) and (rows,)
        Each waypoint segment's velocity (m/s) and turn rate (rad/s).
    mover : ndarray, shape (movers, 6)
        Per mover: reach (m), radius (m), growth (m/s), last time (s, at least 0), 1.0 for a
        disc mover (second order), its vertex count.
    verts : ndarray, shape (movers, m, 2)
        Its vertices (m, its own frame, counter-clockwise), the first ``count`` rows.
    extra : float
        The robot's radius plus the margin (m).

    Returns
    -------
    lower, slack_mid : ndarray, shape (n,)
    """
    n = tm.shape[0]
    lower = np.empty(n)
    slack_mid = np.empty(n)
    for i in range(n):
        j, gi = mj[i], g[i]
        vx, vy, w = vel[gi, 0], vel[gi, 1], turn[gi]
        reach, rad0, grow, t_last = mover[j, 0], mover[j, 1], mover[j, 2], mover[j, 3]
        rho_m = (math.hypot(vx, vy) + reach * abs(w)) * h[i]
        lim_mid = extra + (rad0 + grow * min(max(tm[i], 0.0), t_last))
        lim_hi = extra + (rad0 + grow * min(max(t1[i], 0.0), t_last))
        # the distance from the centre to the polygon (as point_polygon_kernel)
        mx, my, c, s = pose[i, 0], pose[i, 1], ch[i], sh[i]
        px, py = p[i, 0], p[i, 1]
        m = int(mover[j, 5])
        if m == 1:
            wx = mx + c * verts[j, 0, 0] - s * verts[j, 0, 1]
            wy = my + s * verts[j, 0, 0] + c * verts[j, 0, 1]
            dist = math.hypot(px - wx, py - wy)
        else:
            dist = math.inf
            inside = True
            for k in range(m):
                k1 = k + 1 if k + 1 < m else 0
                ax = mx + c * verts[j, k, 0] - s * verts[j, k, 1]
                ay = my + s * verts[j, k, 0] + c * verts[j, k, 1]
                bx = mx + c * verts[j, k1, 0] - s * verts[j, k1, 1]
                by = my + s * verts[j, k1, 0] + c * verts[j, k1, 1]
                r, left = point_edge(px, py, ax, ay, bx, by)
                if r < dist:
                    dist = r
                if not left:
                    inside = False
            if inside:
                dist = 0.0
        low = dist - rho_p[i] - rho_m - lim_hi
        if mover[j, 4] != 0.0:  # second order: min over |tau| <= h of |D + w tau|, less curvature
            dx, dy = px - mx, py - my
            rx, ry = v_rob[i, 0] - vx, v_rob[i, 1] - vy
            rr = rx * rx + ry * ry
            tau = -(dx * rx + dy * ry) / rr if rr > 0.0 else 0.0
            tau = min(max(tau, -h[i]), h[i])
            low2 = math.hypot(dx + tau * rx, dy + tau * ry) - 0.5 * c2[i] * h[i] * h[i] - 1e-12
            low2 = low2 - lim_hi
            if math.isnan(low):  # numpy.fmax: an unbounded curvature gives -inf or nan
                low = low2
            elif not math.isnan(low2):
                low = max(low, low2)
        lower[i] = low
        slack_mid[i] = dist - lim_mid
    return lower, slack_mid
