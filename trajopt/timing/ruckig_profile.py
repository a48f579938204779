"""A reusable 1-DoF ruckig position problem.

The time-optimal jerk-limited profile between two states, as constant-jerk rows.
"""

from __future__ import annotations

import numpy as np

__all__ = ["RUCKIG_V_MARGIN", "RuckigProfile"]

RUCKIG_V_MARGIN = 1e-9  # m/s added to ruckig's max_velocity


class RuckigProfile:
    """One reusable 1-DoF ruckig position problem (no intermediate_positions, ever).

    Used by the timing (finish and compress stages) and by the stop-and-turn fallback
    (rest-to-rest moves and turns).

    Parameters
    ----------
    amax : float
        Acceleration limit (units of the motion per s^2).
    jmax : float
        Jerk limit (per s^3).
    """

    def __init__(self, amax: float, jmax: float) -> None:
        from ruckig import InputParameter, Result, Ruckig, RuckigError, Trajectory

        self.inp = InputParameter(1)
        self.otg = Ruckig(1)
        self.calculate = self.otg.calculate
        self.traj = Trajectory(1)
        self.ok = (Result.Working, Result.Finished)
        self.errors = (RuntimeError, RuckigError)
        self.inp.max_acceleration = [amax]
        self.inp.max_jerk = [jmax]
        self.inp.min_velocity = [0.0]

    def solve(
        self, state0, state1, vmax: float, *, v_margin: float = RUCKIG_V_MARGIN
    ) -> np.ndarray | None:
        """Rows ``(t0, s0, v0, a0, jerk, duration)`` from ``state0`` to ``state1`` or None.

        ``max_velocity`` is ``max(vmax, v0, v1) + v_margin`` (m/s).
        """
        inp = self.inp
        s0, v0, a0 = state0
        s1, v1, a1 = state1
        inp.current_position = [s0]
        inp.current_velocity = [v0]
        inp.current_acceleration = [a0]
        inp.target_position = [s1]
        inp.target_velocity = [v1]
        inp.target_acceleration = [a1]
        inp.max_velocity = [max(vmax, v0, v1) + v_margin]
        try:
            res = self.calculate(inp, self.traj)
        except self.errors:  # ruckig rejects some target states (e.g. a != 0 near v limit)
            return None
        if res not in self.ok:
            return None
        prof = self.traj.profiles[0][0]
        if prof.accel.duration > 1e-15:
            return None
        flat: list[float] = []  # rows laid end to end
        t = 0.0
        b = prof.brake
        if b.duration > 0.0:
            bt, bj, bp, bv, ba = b.t, b.j, b.p, b.v, b.a
            for i in range(2):
                ti = bt[i]
                if ti > 0.0:
                    flat += (t, bp[i], bv[i], ba[i], bj[i], ti)
                    t += ti
        pt, pj, pp, pv, pa = prof.t, prof.j, prof.p, prof.v, prof.a
        for i in range(7):
            ti = pt[i]
            if ti > 0.0:
                flat += (t, pp[i], pv[i], pa[i], pj[i], ti)
                t += ti
        if not flat:
            return None
        # the start times are the running sums of the durations
        return np.array(flat).reshape(-1, 6)
