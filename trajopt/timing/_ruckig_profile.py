"""A reusable 1-DoF ruckig position problem.

The time-optimal jerk-limited profile between two states, as constant-jerk rows.
"""

from __future__ import annotations

import numpy as np

from trajopt.timing._greedy import profile_rows

RUCKIG_V_MARGIN = 1e-9  # m/s added to ruckig's max_velocity
_NO_BRAKE = (0.0, 0.0)  # durations and jerks of an absent brake


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

        ``max_velocity`` is ``max(vmax, v0, v1) + v_margin`` (m/s). The rows are ruckig's
        phases of positive duration (its brake first); their start states are integrated
        from ``state0`` over those phases (:func:`trajopt.timing._greedy.profile_rows`; within
        a few 1e-15 of ruckig's own).
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
        b = prof.brake
        brake = (tuple(b.t), tuple(b.j)) if b.duration > 0.0 else (_NO_BRAKE, _NO_BRAKE)
        rows = profile_rows(float(s0), float(v0), float(a0), *brake, tuple(prof.t), tuple(prof.j))
        return rows if rows.shape[0] else None
