"""The timing's last stages on the greedy's answer.

Finish at ``(L, v_end, 0)`` with one ruckig call, then compress the sections between speed
minima into ruckig's time-optimal profiles where they stay under the cap.
"""

from __future__ import annotations

from bisect import bisect_left

import numpy as np

import trajopt.timing._greedy as greedy
from trajopt.timing._cap_table import T_MIN, CapTable
from trajopt.timing._ruckig_profile import RuckigProfile

MAX_SPLIT_DEPTH = 6
MIN_SPLIT_STEPS = 6  # split a failed section only when it spans at least this many steps


def rows_from_greedy(phases: np.ndarray, i0: int, i1: int, t_end: float) -> np.ndarray:
    """Greedy phases ``i0:i1`` as rows ``(t0, s0, v0, a0, jerk, duration)``."""
    ph = phases[i0:i1]
    rows = np.empty((ph.shape[0], 6))
    rows[:, :5] = ph
    rows[:-1, 5] = ph[1:, 0] - ph[:-1, 0]
    rows[-1, 5] = t_end - ph[-1, 0]
    return rows


def finish(
    rk: RuckigProfile,
    table: CapTable,
    phases: np.ndarray,
    bounds: np.ndarray,
    v_end: float,
    jmax: float,
) -> tuple[np.ndarray, np.ndarray] | None:
    """Append one ruckig position call to ``(L, v_end, 0)``; back off a few steps if needed.

    Returns ``(phases, bounds)`` with ``phases`` rows ``(t0, s0, v0, a0, jerk)`` and ``bounds``
    rows ``(t, s, v, a, phase_index)``, the last bound being the end state; or None.
    """
    length = table.length
    target = (length, v_end, 0.0)
    nb = bounds.shape[0]
    for back in range(min(nb, 25)):
        ib = nb - 1 - back
        t_b, s_b, v_b, a_b, p_b = bounds[ib].tolist()
        if s_b > length:
            continue
        v_pk = v_b + (a_b * a_b / (2.0 * jmax) if a_b > 0 else 0.0)
        # the lowest cap ahead bounds a profile that holds the cap everywhere; the state's
        # own peak speed is the fallback (from rest that peak is 0: never the only bound)
        v_room = table.range_min(s_b, length)
        rows = None
        for vmax in dict.fromkeys((max(v_room, v_pk, v_end), max(v_pk, v_end))):
            rows = rk.solve((s_b, v_b, a_b), target, vmax)
            if rows is not None and table.rows_ok(rows):
                break
            rows = None
        if rows is None:
            continue
        rows[:, 0] += t_b  # rows: a fresh array from rk.solve
        new_ph = np.concatenate((phases[: int(p_b)], rows[:, :5]))
        t_end = t_b + float(rows[:, 5].sum())
        end = np.array([[t_end, length, v_end, 0.0, new_ph.shape[0]]], dtype=float)
        return new_ph, np.concatenate((bounds[: ib + 1], end))
    return None


def compress(
    rk: RuckigProfile, table: CapTable, phases: np.ndarray, bounds: np.ndarray
) -> tuple[np.ndarray, int]:
    """Replace the greedy between its speed minima by ruckig's time-optimal sections.

    A section is tried with ruckig at the highest cap over it when that is above the
    greedy's peak speed there, else (or when ruckig gives no profile for it) at the greedy's
    peak; a profile is kept when it is no slower than the greedy and under the cap. A
    failed section is split at the greedy step nearest its mid-time (down to
    ``MAX_SPLIT_DEPTH`` levels and ``MIN_SPLIT_STEPS`` steps); the greedy's own phases stand
    where nothing fits.

    Returns
    -------
    rows : ndarray, shape (k, 6)
        The sections' rows ``(t0, s0, v0, a0, jerk, duration)`` laid end to end in time
        (:func:`greedy.chain_times`).
    sections : int
        Number of sections.
    """
    nb = bounds.shape[0]
    v, a = bounds[:, 2], bounds[:, 3]
    vm, vc, vp = v[:-2], v[1:-1], v[2:]
    inner = (a[1:-1] == 0.0) & (vc <= vm) & (vc <= vp) & ~((vm == vc) & (vc == vp))
    knots = [0, *(np.flatnonzero(inner) + 1).tolist(), nb - 1]
    t_next = np.append(phases[1:, 0], bounds[-1, 0])
    peaks = greedy.phase_peaks(phases, t_next)
    b_t: list[float] = []  # bound times, non-decreasing (listed at the first split)
    ci, h = table.ci, table.h
    st, lg, length = table.st, table.lg, table.length
    rows_ok, section_speeds = greedy.rows_ok, greedy.section_speeds
    solve_rk = rk.solve
    budget = [3 * len(knots) + 32]  # ruckig calls; the greedy answer is kept beyond it

    def solve(i0: int, i1: int, depth: int) -> list[np.ndarray]:
        b0, b1 = bounds[i0].tolist(), bounds[i1].tolist()  # (t, s, v, a, phase_index)
        p0, p1 = int(b0[4]), int(b1[4])
        if p1 <= p0:
            return []
        if i1 - i0 < 2 or budget[0] <= 0:
            return [rows_from_greedy(phases, p0, p1, b1[0])]
        budget[0] -= 1
        g_dur = b1[0] - b0[0]
        st0, st1 = b0[1:4], b1[1:4]
        peak, top = section_speeds(peaks, ci, p0, p1, st0[0], st1[0], h)
        rows = None
        # first try the highest cap in the section (better than the greedy's peak if it
        # fits), then the peak when there was no top attempt or ruckig gave no profile;
        # a profile fits when it is no slower than the greedy and under the cap
        if top > peak * (1.0 + 1e-6):
            rows = solve_rk(st0, st1, top)
            if (
                rows is not None
                and rows[-1, 0] + rows[-1, 5] <= g_dur
                and rows_ok(st, lg, h, length, rows, T_MIN)
            ):
                return [rows]
        if rows is None:
            rows = solve_rk(st0, st1, peak)
            if (
                rows is not None
                and rows[-1, 0] + rows[-1, 5] <= g_dur
                and rows_ok(st, lg, h, length, rows, T_MIN)
            ):
                return [rows]
        if i1 - i0 >= MIN_SPLIT_STEPS and depth < MAX_SPLIT_DEPTH:
            if not b_t:
                b_t.extend(bounds[:, 0].tolist())
            im = min(bisect_left(b_t, 0.5 * (b0[0] + b1[0]), i0 + 1, i1), i1 - 1)
            return solve(i0, im, depth + 1) + solve(im, i1, depth + 1)
        return [rows_from_greedy(phases, p0, p1, b1[0])]

    chain: list[np.ndarray] = []
    for k0, k1 in zip(knots[:-1], knots[1:], strict=True):
        chain += solve(k0, k1, 0)
    sizes = np.array([r.shape[0] for r in chain], dtype=np.int64)
    rows = np.concatenate(chain) if len(chain) > 1 else chain[0].copy()
    greedy.chain_times(rows, sizes)
    return rows, len(chain)
