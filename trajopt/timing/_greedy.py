"""Compiled kernels of the jerk-limited timing along arc length (numba).

All kernels work on a 1-DoF motion ``s(t)`` made of constant-jerk pieces and on a speed cap
given as one value per interval of a uniform arc-length grid (spacing ``h``), stored as a
sparse table for O(1) range minima. See :mod:`trajopt.timing` for the method.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from trajopt.kernel_cache import watch_compiles
from trajopt.timing._kernel_options import NO_REFCOUNT

#: greedy exit codes
OK_FINISH = 1  # the end condition binds: finish with one position call to (L, v_end, 0)
STUCK = 2  # at rest and no step is safe (speed cap ~0 ahead)
START_INFEASIBLE = 3  # the initial state cannot stay under the cap
MAX_STEPS = 4
_NEED_ROOM = 5  # internal: the buffers filled up (greedy runs again with more room)

_NEG_V_TOL = 1e-9  # a piece whose speed dips below -1e-9 m/s reverses
_CAP_TOL = 2e-9  # m/s: absorbs the 1e-9 margin given to ruckig's max_velocity
_REST_V = 1e-12  # m/s: a speed this low with a = 0 is rest (round-off of a stop)
STACK = 96  # rows of piece_ok's bisection stack

# The kernels that take the cap table and run inside the greedy's loops (range_min,
# _piece_test, piece_ok, stop_ok, _put) are compiled without numba's reference counting
# (``NO_REFCOUNT``, :mod:`trajopt.timing._kernel_options`): they allocate nothing, and the
# atomic increments and decrements of the arrays passed to them otherwise take most of the
# greedy's time. Their callers allocate (the bisection stack ``stk`` included).


watch_compiles()  # a first compilation logs one notice (trajopt.kernel_cache)


class CapArrays(NamedTuple):
    """The speed cap as the greedy kernels read it.

    A numba kernel takes arrays and numbers, not a :class:`~trajopt.timing._cap_table.CapTable`:
    this record (:attr:`CapTable.arrays <trajopt.timing._cap_table.CapTable.arrays>`) carries
    the part of it the kernels query, with fixed types (one compiled signature).

    Attributes
    ----------
    st : ndarray of float64, shape (levels, n)
        Sparse table of the interval caps (m/s) for O(1) range minima (:func:`build_table`);
        row 0 holds the caps of the ``n`` grid intervals.
    lg : ndarray of int64, shape (n + 2,)
        ``floor(log2(k))`` for range lengths ``k`` (:func:`build_table`).
    h : float
        Grid spacing (m).
    length : float
        Arc length of the curve (m), ``n h``.
    min_s : ndarray of float64, shape (k,)
        Arc lengths (m) of the cap's local minima, ascending.
    min_v : ndarray of float64, shape (k,)
        The caps there (m/s).
    """

    st: np.ndarray
    lg: np.ndarray
    h: float
    length: float
    min_s: np.ndarray
    min_v: np.ndarray


class GreedyLimits(NamedTuple):
    """The start state, the end speed, the limits and the settings of one :func:`greedy` run.

    Build it with the field types given (Python ``float``, ``int``, ``bool``): numba compiles
    :func:`greedy` once per type signature.

    Attributes
    ----------
    v0 : float
        Speed at ``s = 0`` (m/s).
    a0 : float
        Acceleration at ``s = 0`` (m/s^2).
    v_end : float
        Speed to end with at ``s = length`` (m/s).
    amax : float
        Largest ``|a|`` (m/s^2).
    j : float
        Largest ``|jerk|`` (m/s^3).
    dt : float
        Step of the greedy (s).
    ncand : int
        Jerk candidates per step, ``j`` down to ``-j`` evenly (>= 2).
    tmin : float
        Finest bisection of a piece in the cap test (s).
    max_steps : int
        Steps at most.
    cruise : bool
        Repeat a speed-holding step without re-testing while the caps ahead allow it.
    """

    v0: float
    a0: float
    v_end: float
    amax: float
    j: float
    dt: float
    ncand: int
    tmin: float
    max_steps: int
    cruise: bool


class _Buffers(NamedTuple):
    """Work arrays of :func:`_run`, allocated by :func:`greedy`.

    Attributes
    ----------
    run_end : ndarray of int64, shape (n,)
        Last interval of the run of equal caps holding each interval.
    phases : ndarray, shape (rows, 5)
        Receives the phase rows ``(t0, s0, v0, a0, jerk)``.
    bounds : ndarray, shape (rows, 5)
        Receives the bound rows ``(t, s, v, a, phase_index)``.
    stk : ndarray, shape (STACK, 4)
        :func:`piece_ok`'s bisection stack.
    cands : ndarray, shape (ncand + 1,)
        The step's candidate jerks (m/s^3).
    counts : ndarray of int64, shape (2,)
        Receives the numbers of phase and bound rows written.
    """

    run_end: np.ndarray
    phases: np.ndarray
    bounds: np.ndarray
    stk: np.ndarray
    cands: np.ndarray
    counts: np.ndarray


@njit(cache=True)
def advance(s, v, a, j, t):
    """State after ``t`` seconds of constant jerk ``j`` from ``(s, v, a)``."""
    return (
        s + t * (v + t * (0.5 * a + t * j / 6.0)),
        v + t * (a + 0.5 * j * t),
        a + j * t,
    )


@njit(cache=True)
def build_table(ci):
    """Sparse table of range minima over ``ci`` (shape (n,)): returns (table, log2 table)."""
    n = ci.shape[0]
    levels = 1
    while (1 << levels) <= n:
        levels += 1
    st = np.empty((levels, n))
    for i in range(n):  # a loop, not st[0, :] = ci: no shape-mismatch error code to compile
        st[0, i] = ci[i]
    for k in range(1, levels):
        w = 1 << (k - 1)
        for i in range(n - (1 << k) + 1):
            x = st[k - 1, i]
            y = st[k - 1, i + w]
            st[k, i] = x if x < y else y
    lg = np.zeros(n + 2, dtype=np.int64)
    for i in range(2, n + 2):
        lg[i] = lg[i // 2] + 1
    return st, lg


@njit(cache=True)
def finish_caps(ci, scale, v_bound, lo0, lo1):
    """Finish the cap table on the interval caps ``ci`` (changed in place).

    ``ci = max(ci * scale, min(ci, v_bound))``, then ``ci[0] = max(ci[0], lo0)`` and
    ``ci[-1] = max(ci[-1], lo1)``. Returns ``(i_low, vtop, st, lg, minima)``: the first
    lowest interval, the highest cap, the sparse table (:func:`build_table`) and the
    intervals of the cap's local minima (strictly below the interval before, not above the
    one after, below ``vtop``; not the first or last).
    """
    n = ci.shape[0]
    for i in range(n):
        c = ci[i]
        if c == c:  # a nan stays (as with np.maximum)
            x = c * scale
            y = c if c < v_bound else v_bound
            ci[i] = x if x >= y else y
    if lo0 > ci[0]:
        ci[0] = lo0
    if lo1 > ci[n - 1]:
        ci[n - 1] = lo1
    i_low = 0  # np.argmin: the first nan if any, else the first lowest
    vtop = ci[0]
    for i in range(1, n):
        if ci[i_low] != ci[i_low]:
            break
        if ci[i] < ci[i_low] or ci[i] != ci[i]:
            i_low = i
        if ci[i] > vtop:
            vtop = ci[i]
    st, lg = build_table(ci)
    minima = np.empty(n, np.int64)
    k = 0
    for i in range(1, n - 1):
        if ci[i] < ci[i - 1] and ci[i] <= ci[i + 1] and ci[i] < vtop:
            minima[k] = i
            k += 1
    return i_low, vtop, st, lg, minima[:k]


@njit(cache=True, **NO_REFCOUNT)
def range_min(st, lg, h, sa, sb):
    """Minimum cap over the grid intervals touched by ``[sa, sb]`` (m, ``sa <= sb``)."""
    n = st.shape[1]
    ia = int(sa / h)
    ib = int(sb / h)
    if ia < 0:
        ia = 0
    if ib < 0:
        ib = 0
    if ia > n - 1:
        ia = n - 1
    if ib > n - 1:
        ib = n - 1
    if ib < ia:
        ia, ib = ib, ia
    k = lg[ib - ia + 1]
    x = st[k, ia]
    y = st[k, ib - (1 << k) + 1]
    return x if x < y else y


@njit(cache=True, **NO_REFCOUNT)
def _piece_test(st, lg, h, length, s0, v0, a0, j, t0):
    """One level of :func:`piece_ok`: 0 under the cap, 1 over it (or reversing), 2 undecided."""
    if s0 >= length:
        return 0
    s1, v1, a1 = advance(s0, v0, a0, j, t0)
    vmax = v0 if v0 > v1 else v1
    vmin = v0 if v0 < v1 else v1
    peak = False
    if a0 > 0.0 and a1 < 0.0:
        pk = v0 - a0 * a0 / (2.0 * j)
        if pk > vmax:
            vmax = pk
            peak = True
    elif a0 < 0.0 and a1 > 0.0:
        tr = v0 - a0 * a0 / (2.0 * j)
        if tr < vmin:
            vmin = tr
    if vmin < -_NEG_V_TOL:
        return 1
    se = s1 if s1 < length else length
    if se < s0:
        se = s0
    if vmax <= range_min(st, lg, h, s0, se) + _CAP_TOL:
        return 0
    # a point of the piece over the cap: the bisection would end there
    if s1 < length and v1 > range_min(st, lg, h, s1, s1) + _CAP_TOL:
        return 1
    if v0 > range_min(st, lg, h, s0, s0) + _CAP_TOL:
        return 1
    if peak:
        s_pk = advance(s0, v0, a0, j, -a0 / j)[0]
        if s_pk < length and vmax > range_min(st, lg, h, s_pk, s_pk) + _CAP_TOL:
            return 1
    return 2


@njit(cache=True, **NO_REFCOUNT)
def piece_ok(st, lg, h, length, s, v, a, j, T, tmin, stk):
    """Return True when the constant-jerk piece keeps ``v >= 0`` and ``v <= cap(s)`` up to ``length``.

    Conservative and exact on the grid: a piece passes when its speed maximum is below the
    minimum cap over the arc-length range it covers; otherwise it is bisected in time down
    to ``tmin`` seconds on the caller's stack ``stk`` (shape ``(STACK, 4)``).
    """
    if T <= 0.0:
        return True
    res = _piece_test(st, lg, h, length, s, v, a, j, T)
    if res != 2:
        return res == 0
    if T <= tmin:
        return False
    half = 0.5 * T
    sm, vm, am = advance(s, v, a, j, half)
    stk[0, 0] = sm
    stk[0, 1] = vm
    stk[0, 2] = am
    stk[0, 3] = half
    stk[1, 0] = s
    stk[1, 1] = v
    stk[1, 2] = a
    stk[1, 3] = half
    top = 2
    while top > 0:
        top -= 1
        s0 = stk[top, 0]
        v0 = stk[top, 1]
        a0 = stk[top, 2]
        t0 = stk[top, 3]
        res = _piece_test(st, lg, h, length, s0, v0, a0, j, t0)
        if res == 0:
            continue
        if res == 1:
            return False
        if t0 <= tmin or top + 2 > stk.shape[0]:
            return False
        half = 0.5 * t0
        sm, vm, am = advance(s0, v0, a0, j, half)
        stk[top, 0] = sm
        stk[top, 1] = vm
        stk[top, 2] = am
        stk[top, 3] = half
        stk[top + 1, 0] = s0
        stk[top + 1, 1] = v0
        stk[top + 1, 2] = a0
        stk[top + 1, 3] = half
        top += 2
    return True


@njit(cache=True)
def brake_times(v, a, vt, j, amax):
    """Time-optimal jerk-limited change from ``(v, a)`` down to ``(vt, 0)``.

    Returns ``(t1, t2, t3, kind)``: phases of jerk ``-j``, ``0``, ``+j``. ``kind`` 0: a real
    slow-down; 1: the speed never exceeds ``vt`` (``t1`` ramps ``a >= 0`` down to 0); 2: the
    state already decelerates so hard that ramping ``a`` up to 0 (``t3``) ends below ``vt``.
    """
    q = j * (v - vt) + 0.5 * a * a
    if a >= 0.0 and q <= 0.0:
        return a / j, 0.0, 0.0, 1
    if a < 0.0 and q < a * a:
        return 0.0, 0.0, -a / j, 2
    ap = np.sqrt(q)
    if ap <= amax:
        t1 = (a + ap) / j
        if t1 < 0.0:
            t1 = 0.0
        return t1, 0.0, ap / j, 0
    t1 = (a + amax) / j
    if t1 < 0.0:
        t1 = 0.0
    t2 = (q - amax * amax) / (j * amax)
    if t2 < 0.0:
        t2 = 0.0
    return t1, t2, amax / j, 0


@njit(cache=True)
def brake_end(s, v, a, t1, t2, t3, j):
    """Arc length at the end of the ``brake_times`` phases."""
    s, v, a = advance(s, v, a, -j, t1)
    s, v, a = advance(s, v, a, 0.0, t2)
    s, v, a = advance(s, v, a, j, t3)
    return s


@njit(cache=True, **NO_REFCOUNT)
def stop_ok(st, lg, h, length, s, v, a, j, amax, tmin, stk):
    """Is the stop profile from ``(s, v, a)`` under the cap? Returns ``(ok, s_stop)``."""
    t1, t2, t3, kind = brake_times(v, a, 0.0, j, amax)
    if kind == 2 and a < -1e-12:
        # cannot stop without reversing unless the undershoot is round-off
        if v - a * a / (2.0 * j) < -_NEG_V_TOL:
            return False, s
    if not piece_ok(st, lg, h, length, s, v, a, -j, t1, tmin, stk):
        return False, s
    s, v, a = advance(s, v, a, -j, t1)
    if not piece_ok(st, lg, h, length, s, v, a, 0.0, t2, tmin, stk):
        return False, s
    s, v, a = advance(s, v, a, 0.0, t2)
    if not piece_ok(st, lg, h, length, s, v, a, j, t3, tmin, stk):
        return False, s
    s, v, a = advance(s, v, a, j, t3)
    return True, s


@njit(cache=True)
def _end_test(s1, v1, a1, v_end, length, j, amax):
    """Return whether ``(s1, v1, a1)`` can still end at ``length`` with ``v_end``, and ``s_stop``.

    ``ok``: ``s1 < length``, its stop profile ends at or before ``length`` and so does its
    slow-down to ``v_end``; ``s_stop`` is the end of the stop profile (``s1`` if
    ``s1 >= length``).
    """
    end_ok = s1 < length
    s_stop = s1
    if end_ok:
        b1, b2, b3, _ = brake_times(v1, a1, 0.0, j, amax)
        s_stop = brake_end(s1, v1, a1, b1, b2, b3, j)
        if v_end == 0.0:
            end_ok = s_stop <= length
        else:
            b1, b2, b3, kind = brake_times(v1, a1, v_end, j, amax)
            if kind != 1:
                end_ok = brake_end(s1, v1, a1, b1, b2, b3, j) <= length
    return end_ok, s_stop


@njit(cache=True)
def cruise_reach(v, v_end, amax, j, dt):
    """Farthest arc length (m) a greedy step from ``(s, v, a = 0)`` queries, less ``s``.

    The largest jerk ``j`` gives the farthest step end and, from there, the longest brake to
    rest and to ``v_end``: every query of the step (its pieces, the stop profile, the end
    test) lies within that distance of ``s``.
    """
    ta = dt
    if j * dt > amax:
        ta = amax / j
    s1, v1, a1 = advance(0.0, v, 0.0, j, ta)
    if ta < dt:
        s1, v1, a1 = advance(s1, v1, amax, 0.0, dt - ta)
    t1, t2, t3, _ = brake_times(v1, a1, 0.0, j, amax)
    far = brake_end(s1, v1, a1, t1, t2, t3, j)
    t1, t2, t3, kind = brake_times(v1, a1, v_end, j, amax)
    if kind != 1:
        far = max(far, brake_end(s1, v1, a1, t1, t2, t3, j))
    return max(far, s1)


@njit(cache=True, **NO_REFCOUNT)
def _put(buf, n, t, s, v, a, j):
    """Write row ``n`` of ``buf`` (the caller checked the room)."""
    buf[n, 0] = t
    buf[n, 1] = s
    buf[n, 2] = v
    buf[n, 3] = a
    buf[n, 4] = j


@njit(cache=True)
def greedy(cap, lim, rows):
    """Run the forward greedy over piecewise-constant jerk with an exact stop-profile test.

    It starts at ``s = 0`` with speed ``lim.v0`` and acceleration ``lim.a0``. With
    ``lim.cruise``, a step that holds the speed (``a = 0`` before and after, jerk 0) is
    repeated without re-testing while every query of the step (its pieces, its stop profile
    and the end test, within :func:`cruise_reach` of the state) lies on one run of equal caps
    ahead: each repeat would see the same caps and make the same choice, so the phases are the
    same as without ``cruise``. The phase and bound buffers start with ``rows`` rows (0: twice
    the time at the cap everywhere, in steps, plus 1024); a run that fills them runs again
    with twice the room.

    Parameters
    ----------
    cap : CapArrays
        The speed cap.
    lim : GreedyLimits
        Start state, end speed, limits and settings.
    rows : int
        Initial rows of the phase and bound buffers (0: sized from the cap).

    Returns
    -------
    phases : ndarray, shape (p, 5)
        Rows ``(t0, s0, v0, a0, jerk)`` of the constant-jerk phases, in time order.
    bounds : ndarray, shape (m, 5)
        Rows ``(t, s, v, a, phase_index)`` at every step boundary (the first is the start).
    status : int
        One of the exit codes of this module.
    """
    st, h = cap.st, cap.h
    n_int = st.shape[1]
    # last interval of the run of equal caps holding each interval (for cruise steps)
    run_end = np.empty(n_int, np.int64)
    run_end[n_int - 1] = n_int - 1
    for i in range(n_int - 2, -1, -1):
        run_end[i] = run_end[i + 1] if st[0, i] == st[0, i + 1] else i
    if rows <= 0:  # buffers sized by the time at the cap everywhere
        t_cap = 0.0
        for i in range(n_int):
            t_cap += h / st[0, i]
        rows = int(min(2.0 * t_cap / lim.dt, 4.0 * lim.max_steps)) + 1024
    stk = np.empty((STACK, 4))  # piece_ok's bisection stack
    cands = np.empty(lim.ncand + 1)
    counts = np.zeros(2, np.int64)
    while True:
        phases = np.empty((rows, 5))
        bounds = np.empty((rows, 5))
        status = _run(cap, lim, _Buffers(run_end, phases, bounds, stk, cands, counts))
        if status != _NEED_ROOM:
            return phases[: counts[0]], bounds[: counts[1]], status
        rows *= 2


@njit(cache=True, **NO_REFCOUNT)
def _run(cap, lim, buf):
    """Run the loop of :func:`greedy` on buffers it does not grow; return the status.

    ``cap`` (:class:`CapArrays`) and ``lim`` (:class:`GreedyLimits`) as for :func:`greedy`;
    ``buf`` (:class:`_Buffers`) receives the rows and, in ``buf.counts``, their numbers; the
    status ``_NEED_ROOM`` means the buffers filled up (nothing is kept).
    """
    st, lg, h, length, min_s, min_v = cap.st, cap.lg, cap.h, cap.length, cap.min_s, cap.min_v
    v0, a0, v_end, amax, j, dt = lim.v0, lim.a0, lim.v_end, lim.amax, lim.j, lim.dt
    ncand, tmin, max_steps, cruise = lim.ncand, lim.tmin, lim.max_steps, lim.cruise
    run_end, phases, bounds = buf.run_end, buf.phases, buf.bounds
    stk, cands, counts = buf.stk, buf.cands, buf.counts
    # row counters typed int64 from the start: a literal 0 would compile _put once more
    n_ph = np.int64(0)
    n_b = np.int64(0)
    s = 0.0
    v = v0
    a = a0
    t = 0.0
    if n_b == bounds.shape[0]:
        return _NEED_ROOM
    _put(bounds, n_b, t, s, v, a, 0.0)
    n_b += 1
    ok0, _ = stop_ok(st, lg, h, length, s, v, a, j, amax, tmin, stk)
    if not ok0:
        counts[0] = n_ph
        counts[1] = n_b
        return START_INFEASIBLE
    nmin = min_s.shape[0]
    ptr = 0
    status = MAX_STEPS
    n_int = st.shape[1]
    reach = -1.0  # cruise reach of the speed held last (m); < 0: not computed
    reach_v = -1.0
    steps = 0
    while steps < max_steps:
        steps += 1
        while ptr < nmin and min_s[ptr] <= s:
            ptr += 1
        # candidate jerks, descending, plus the one that zeroes a at the step end
        uz = -a / dt
        nc = 0
        placed = not (-j <= uz <= j)
        for i in range(ncand):
            ui = j * (1.0 - 2.0 * i / (ncand - 1))
            if not placed and uz >= ui:
                if uz != ui:
                    cands[nc] = uz
                    nc += 1
                placed = True
            cands[nc] = ui
            nc += 1
        chosen = np.nan
        safe = np.nan
        safe_noend = False
        # at rest, a jerk <= 0 makes no progress (or reverses): taking it would idle forever
        at_rest = v <= _REST_V and a == 0.0
        for ic in range(nc):
            u = cands[ic]
            if at_rest and u <= 0.0:
                continue
            # exact step with clamping at +-amax
            ta = dt
            if u > 0.0 and a + u * dt > amax:
                ta = max(0.0, (amax - a) / u)
            elif u < 0.0 and a + u * dt < -amax:
                ta = max(0.0, (-amax - a) / u)
            sa, va, aa = advance(s, v, a, u, ta)
            if ta < dt:
                aa = amax if u > 0.0 else -amax
                s1, v1, a1 = advance(sa, va, aa, 0.0, dt - ta)
            else:
                s1, v1, a1 = sa, va, aa
            if u == uz or abs(a1) < 1e-9:
                a1 = 0.0
            # the end test (closed form; the stop profile's end is stop_ok's): a candidate
            # that fails it can only set safe_noend, so once that is set it goes first and
            # spares the cap tests; before, the step's cap tests go first (the same outcome)
            if safe_noend:
                end_ok, s_stop = _end_test(s1, v1, a1, v_end, length, j, amax)
                if not end_ok:
                    continue
            if not piece_ok(st, lg, h, length, s, v, a, u, ta, tmin, stk):
                continue
            if ta < dt and not piece_ok(st, lg, h, length, sa, va, aa, 0.0, dt - ta, tmin, stk):
                continue
            if not safe_noend:
                end_ok, s_stop = _end_test(s1, v1, a1, v_end, length, j, amax)
            if s1 >= length:
                safe_noend = True
                continue
            if not end_ok:
                if not safe_noend:
                    safe_noend = stop_ok(st, lg, h, length, s1, v1, a1, j, amax, tmin, stk)[0]
                continue
            if not stop_ok(st, lg, h, length, s1, v1, a1, j, amax, tmin, stk)[0]:
                continue
            if np.isnan(safe):
                safe = u
            target_ok = True
            k = ptr
            while k < nmin and min_s[k] <= s_stop:
                if min_s[k] > s1:
                    b1, b2, b3, kind = brake_times(v1, a1, min_v[k], j, amax)
                    if kind != 1 and brake_end(s1, v1, a1, b1, b2, b3, j) > min_s[k]:
                        target_ok = False
                        break
                k += 1
            if target_ok:
                chosen = u
                break
        if np.isnan(chosen):
            chosen = safe
        if not np.isnan(chosen):
            u = chosen
            s_prev = s
            at_zero = a == 0.0
            ta = dt
            if u > 0.0 and a + u * dt > amax:
                ta = max(0.0, (amax - a) / u)
            elif u < 0.0 and a + u * dt < -amax:
                ta = max(0.0, (-amax - a) / u)
            if ta > 0.0:
                if n_ph == phases.shape[0]:
                    return _NEED_ROOM
                _put(phases, n_ph, t, s, v, a, u)
                n_ph += 1
                s, v, a = advance(s, v, a, u, ta)
                t += ta
            if ta < dt:
                a = amax if u > 0.0 else -amax
                if n_ph == phases.shape[0]:
                    return _NEED_ROOM
                _put(phases, n_ph, t, s, v, a, 0.0)
                n_ph += 1
                s, v, a = advance(s, v, a, 0.0, dt - ta)
                t += dt - ta
            if u == uz or abs(a) < 1e-9:
                a = 0.0
            if a == 0.0 and v < _REST_V:
                v = 0.0  # round-off of a stop: rest exactly
            if n_b == bounds.shape[0]:
                return _NEED_ROOM
            _put(bounds, n_b, t, s, v, a, float(n_ph))
            n_b += 1
            if cruise and u == 0.0 and a == 0.0 and at_zero and v > _REST_V:
                # a cruise step: repeat it while every query lies on one run of equal caps
                if v != reach_v:
                    reach = cruise_reach(v, v_end, amax, j, dt) + 2.0 * h
                    reach_v = v
                i0 = min(max(int(s_prev / h), 0), n_int - 1)
                lim = min(run_end[i0] * h, length - h) - reach
                while s_prev <= lim and s <= lim and steps < max_steps:
                    if n_ph == phases.shape[0] or n_b == bounds.shape[0]:
                        return _NEED_ROOM
                    steps += 1
                    phases[n_ph, 0] = t
                    phases[n_ph, 1] = s
                    phases[n_ph, 2] = v
                    phases[n_ph, 3] = 0.0
                    phases[n_ph, 4] = u
                    n_ph += 1
                    s, v, a = advance(s, v, 0.0, u, dt)
                    t += dt
                    bounds[n_b, 0] = t
                    bounds[n_b, 1] = s
                    bounds[n_b, 2] = v
                    bounds[n_b, 3] = a
                    bounds[n_b, 4] = float(n_ph)
                    n_b += 1
            continue
        if safe_noend:
            status = OK_FINISH
            break
        # follow the stop profile (safe by construction) for one step
        if v <= 0.0 and a == 0.0:
            status = STUCK
            break
        t1, t2, t3, kind = brake_times(v, a, 0.0, j, amax)
        rem = dt
        for p in range(3):
            tp = t1 if p == 0 else (t2 if p == 1 else t3)
            jp = -j if p == 0 else (0.0 if p == 1 else j)
            tp = min(tp, rem)
            if tp > 0.0:
                if n_ph == phases.shape[0]:
                    return _NEED_ROOM
                _put(phases, n_ph, t, s, v, a, jp)
                n_ph += 1
                s, v, a = advance(s, v, a, jp, tp)
                t += tp
                rem -= tp
        if rem > 0.0:  # stopped inside the step
            v = 0.0 if v < _REST_V else v
            a = 0.0
        if abs(a) < 1e-9:
            a = 0.0
        if n_b == bounds.shape[0]:
            return _NEED_ROOM
        _put(bounds, n_b, t, s, v, a, float(n_ph))
        n_b += 1
    counts[0] = n_ph
    counts[1] = n_b
    return status


@njit(cache=True)
def rows_ok(st, lg, h, length, rows, tmin):
    """Rows ``(t0, s0, v0, a0, jerk, duration)`` (shape (k, 6)) all under the cap."""
    stk = np.empty((STACK, 4))
    for i in range(rows.shape[0]):
        if not piece_ok(
            st,
            lg,
            h,
            length,
            rows[i, 1],
            rows[i, 2],
            rows[i, 3],
            rows[i, 4],
            rows[i, 5],
            tmin,
            stk,
        ):
            return False
    return True


@njit(cache=True)
def phase_peaks(phases, t_next):
    """Highest speed reached in each greedy phase (rows ``(t0, s0, v0, a0, jerk)``)."""
    n = phases.shape[0]
    out = np.empty(n)
    for i in range(n):
        v0, a0, j = phases[i, 2], phases[i, 3], phases[i, 4]
        d = t_next[i] - phases[i, 0]
        v1 = v0 + d * (a0 + 0.5 * j * d)
        a1 = a0 + j * d
        pk = max(v0, v1)
        if a0 > 0.0 and a1 < 0.0 and j < 0.0:
            pk = max(pk, v0 - a0 * a0 / (2.0 * j))
        out[i] = pk
    return out


@njit(cache=True)
def section_speeds(peaks, ci, p0, p1, s0, s1, h):
    """Highest greedy speed and highest cap of a compress section.

    Returns ``(peak, top)``: the largest of ``peaks[p0:p1]`` (the phases' highest speeds,
    :func:`phase_peaks`) and the largest cap ``ci`` over the grid intervals from the one
    holding ``s0`` to the one holding ``s1`` (m; spacing ``h``).
    """
    peak = -np.inf
    for i in range(p0, p1):
        if peaks[i] > peak:
            peak = peaks[i]
    n = ci.shape[0]
    i_a = min(int(s0 / h), n - 1)
    i_b = min(int(s1 / h), n - 1)
    top = -np.inf
    for i in range(i_a, i_b + 1):
        if ci[i] > top:
            top = ci[i]
    return peak, top


@njit(cache=True)
def chain_times(rows, sizes):
    """Lay sections of rows ``(t0, s0, v0, a0, jerk, duration)`` end to end in time, in place.

    ``rows`` holds the sections one after the other (``sizes`` rows each); a section's start
    times become ``t0 - t0[0] + t_out``, ``t_out`` the end (``t0 + duration``) of the last
    row before it (0 for the first).
    """
    t_out = 0.0
    i = 0
    for k in range(sizes.shape[0]):
        r0 = rows[i, 0]
        for q in range(i, i + sizes[k]):
            rows[q, 0] = rows[q, 0] - r0 + t_out
        i += sizes[k]
        t_out = rows[i - 1, 0] + rows[i - 1, 5]


@njit(cache=True)
def profile_rows(s, v, a, brake_t, brake_j, phase_t, phase_j):
    """Rows ``(t0, s0, v0, a0, jerk, duration)`` of a ruckig profile from ``(s, v, a)``.

    The brake phases (``brake_t``, ``brake_j``), then the profile's phases (``phase_t``,
    ``phase_j``); phases of zero duration are left out, start times are the running sums of
    the durations and start states come from :func:`advance` (shape ``(0, 6)`` if none).
    """
    n = 0
    for x in brake_t:
        if x > 0.0:
            n += 1
    for x in phase_t:
        if x > 0.0:
            n += 1
    rows = np.empty((n, 6))
    t = 0.0
    k = 0
    for q in range(len(brake_t) + len(phase_t)):
        if q < len(brake_t):
            ti, jq = brake_t[q], brake_j[q]
        else:
            ti, jq = phase_t[q - len(brake_t)], phase_j[q - len(brake_t)]
        if ti > 0.0:
            rows[k, 0] = t
            rows[k, 1] = s
            rows[k, 2] = v
            rows[k, 3] = a
            rows[k, 4] = jq
            rows[k, 5] = ti
            s, v, a = advance(s, v, a, jq, ti)
            t += ti
            k += 1
    return rows
