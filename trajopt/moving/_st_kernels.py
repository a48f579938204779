"""The compiled kernels of the ``(s, t)`` search and of the disc movers' windows.

A non-decreasing motion along the path (a drive) is at node ``i0 + i`` exactly at the steps
``first[i]..last[i]`` after its start (:func:`._st_grid.visits`); a forbidden run
``[lo, hi]`` of that node (the grid's merged runs, :attr:`._st_grid.STGrid.merged`) then
blocks the starts ``lo - last[i]..hi - first[i]``. :func:`blocked_starts_kernel` paints
those ranges for one drive (a difference array, then its running sum);
:func:`arrive_kernel` does it for every drive of a batch from one stop and sets, where the
robot rests at the stop at ``t_k``, the drive is not blocked there and its stop has no
arrival at ``t_(k + n)`` yet, that arrival and its parent (the dynamic programme of
:func:`._st_search.search`). Integer arithmetic only: the same answers as the numpy forms
(:meth:`._st_grid.STGrid.blocked_starts_many`).

:func:`close_kernel` is the point-to-segment test of the pair filter
(:func:`._disc_windows.near_pairs`), :func:`near_pairs_kernel` that filter whole, :func:`least_free_kernel` the sweep of the rests'
shortening (:func:`._tighten.sweep`), :func:`blocked_launches_kernel` the launches a motion's
stays near the fine nodes meet their windows at (:func:`._tighten.blocked_launches`), :func:`pass_band_kernel` the times a schedule can be near each fine node
(:func:`._tighten.pass_band`), :func:`track_knots_kernel` and :func:`mover_pieces_kernel` cut the movers' tracks into
linear pieces (:func:`._disc_windows.track_knots`, :func:`._disc_windows.mover_pieces`:
``numpy.interp``'s centres, the numpy form's operations), :func:`disc_windows_kernel` solves the closed-form windows of pairs of a point and a piece of
a disc mover's track (:func:`._disc_windows.disc_windows`): the same operations, in the same
order, as the numpy form (:func:`._disc_windows.inside_times`, then the clip to the piece's
span with ``numpy.nan_to_num``'s replacements), so the same floats.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from trajopt.kernel_cache import watch_compiles

watch_compiles()  # a first compilation logs one notice (trajopt.kernel_cache)


@njit(cache=True)
def _paint(ptr, m_lo, m_hi, i0, first, last, diff):  # pragma: no cover - compiled
    kk = diff.shape[0] - 1
    diff[:] = 0
    for i in range(first.shape[0]):
        f, la = first[i], last[i]
        if f > la:  # a node passed between grid steps
            continue
        node = i0 + i
        for r in range(ptr[node], ptr[node + 1]):
            lo = max(m_lo[r] - la, 0)
            hi = min(m_hi[r] - f, kk - 1)
            if lo <= hi:
                diff[lo] += 1
                diff[hi + 1] -= 1


@njit(cache=True)
def blocked_starts_kernel(ptr, m_lo, m_hi, kk, i0, first, last):  # pragma: no cover - compiled
    """Return ``bad`` (bool, shape (kk,)): the drive of visits ``(i0, first, last)`` leaving at step ``k`` meets a run.

    Parameters
    ----------
    ptr, m_lo, m_hi : ndarray of int64
        The grid's merged runs (``ptr`` (n + 1,) per node; ``m_lo``, ``m_hi`` (q,) steps).
    kk : int
        Grid times.
    i0 : int
        The drive's first node.
    first, last : ndarray of int64, shape (m,)
        The steps the drive is at node ``i0 + i`` (empty when ``first > last``).
    """
    diff = np.zeros(kk + 1, dtype=np.int64)
    _paint(ptr, m_lo, m_hi, i0, first, last, diff)
    bad = np.zeros(kk, dtype=np.bool_)
    run = 0
    for k in range(kk):
        run += diff[k]
        bad[k] = run > 0
    return bad


@njit(cache=True)
def arrive_kernel(
    ptr, m_lo, m_hi, rest, i0s, base, size, first, last, ns, vs, w, p0, arrivals, parent
):  # pragma: no cover - compiled
    """Set the arrivals of a batch of drives from stop ``w`` (in place).

    Parameters
    ----------
    ptr, m_lo, m_hi : ndarray of int64
        The grid's merged runs.
    rest : ndarray of bool, shape (kk,)
        The robot rests at stop ``w`` at step ``k`` (and may leave then).
    i0s, base, size : ndarray of int64, shape (d,)
        Drive ``j``'s first node and its visits' slice ``base[j]:base[j] + size[j]`` of
        ``first`` and ``last`` (int64).
    ns, vs : ndarray of int64, shape (d,)
        Drive ``j`` takes ``ns[j]`` steps and ends at stop ``vs[j]`` (distinct stops).
    w, p0 : int
        The stop left; drive ``j``'s index in the search's list of drives is ``p0 + j``.
    arrivals : ndarray of bool, shape (stops, kk)
        Set where a drive arrives first.
    parent : ndarray of int64, shape (3, stops, kk)
        The stop left, the step left and the drive's index of each arrival set.
    """
    kk = rest.shape[0]
    diff = np.zeros(kk + 1, dtype=np.int64)
    for j in range(i0s.shape[0]):
        b = base[j]
        _paint(ptr, m_lo, m_hi, i0s[j], first[b : b + size[j]], last[b : b + size[j]], diff)
        n, v = ns[j], vs[j]
        run = 0
        for k in range(kk - n if kk > n else 0):
            run += diff[k]
            if run <= 0 and rest[k] and not arrivals[v, k + n]:
                arrivals[v, k + n] = True
                parent[0, v, k + n] = w
                parent[1, v, k + n] = k
                parent[2, v, k + n] = p0 + j


@njit(cache=True)
def drive_nodes_kernel(rows, duration, s0, s1, dt, ds, n_nodes, never):  # pragma: no cover
    """Return a drive's node at each grid step and its visits ``(idx, first, last)``.

    Parameters
    ----------
    rows : ndarray, shape (p, 5)
        The drive's phases ``(t, s, v, a, j)`` from its start (s, m, m/s, m/s², m/s³).
    duration, s0, s1 : float
        Its duration (s) and ends (m).
    dt, ds : float
        The grid's spacings (s, m).
    n_nodes : int
        The grid's nodes.
    never : int
        The step of a node passed between grid steps (``first = never``, ``last = -never``).

    Returns
    -------
    idx : ndarray of int64, shape (m + 1,)
        The nearest node at steps ``0..m``, ``m = ceil(duration / dt - 1e-9)`` (clipped to
        the drive's end: :meth:`._st_search.Piece.s_at`).
    first, last : ndarray of int64, shape (idx[-1] - idx[0] + 1,)
        The steps the drive is at node ``idx[0] + i``.
    """
    m = int(np.ceil(duration / dt - 1e-9))
    idx = np.empty(m + 1, dtype=np.int64)
    p = rows.shape[0]
    r = 0
    for j in range(m + 1):
        tt = min(max(j * dt, 0.0), duration)
        while r + 1 < p and rows[r + 1, 0] <= tt:
            r += 1
        if tt >= duration:
            s = s1
        else:
            tau = tt - rows[r, 0]
            s = rows[r, 1] + tau * (rows[r, 2] + tau * (0.5 * rows[r, 3] + tau * rows[r, 4] / 6.0))
            s = min(max(s, s0), s1)
        i = np.rint(s / ds)
        idx[j] = int(min(max(i, 0.0), n_nodes - 1.0))
    i0 = idx[0]
    size = idx[m] - i0 + 1
    first = np.full(size, never, dtype=np.int64)
    last = np.full(size, -never, dtype=np.int64)
    for j in range(m + 1):
        q = idx[j] - i0
        if first[q] == never:
            first[q] = j
        last[q] = j
    return idx, first, last


_BIG = np.finfo(np.float64).max


@njit(cache=True)
def _max_nan(x, y):  # pragma: no cover - compiled
    """``numpy.maximum`` of two floats (NaN if either is)."""
    if np.isnan(x) or np.isnan(y):
        return np.nan
    return x if x >= y else y


@njit(cache=True)
def _min_nan(x, y):  # pragma: no cover - compiled
    """``numpy.minimum`` of two floats (NaN if either is)."""
    if np.isnan(x) or np.isnan(y):
        return np.nan
    return x if x <= y else y


@njit(cache=True)
def _finite(x, nan):  # pragma: no cover - compiled
    """``numpy.nan_to_num(x, nan=nan)`` of one float (infinities to the largest floats)."""
    if np.isnan(x):
        return nan
    if x == np.inf:
        return _BIG
    if x == -np.inf:
        return -_BIG
    return x


@njit(cache=True, error_model="numpy")
def _inside(dx, dy, vx, vy, rr, g):  # pragma: no cover - compiled
    """``(t_lo, t_hi)`` of one point and piece: :func:`._disc_windows.inside_times`, scalar."""
    # |D - V tau|^2 - (rr + g tau)^2 = a tau^2 + b tau + c < 0, with rr + g tau > 0
    a = vx * vx + vy * vy - g * g
    b = -2.0 * (dx * vx + dy * vy + rr * g)
    c = dx * dx + dy * dy - rr * rr
    disc = b * b - 4.0 * a * c
    two = disc > 0
    sq = np.sqrt(_max_nan(disc, 0.0))
    q = -0.5 * (b + (sq if b > 0 else -sq))
    r1 = q / a
    r2 = c / q
    up = a > 0
    if two:
        t_lo = _min_nan(r1, r2) if up else _max_nan(r1, r2)
    else:
        t_lo = np.inf if up else -np.inf
    if up:
        t_hi = _max_nan(r1, r2) if two else -np.inf
    else:
        t_hi = np.inf
    if abs(a) <= 1e-12:
        lin = -c / b
        t_lo = lin if b < 0 else -np.inf
        if b > 0:
            t_hi = lin
        elif b == 0 and c >= 0:
            t_hi = -np.inf
        else:
            t_hi = np.inf
    if g > 0:
        t_lo = _max_nan(t_lo, -rr / g)
    if not (g > 0 or rr > 0):
        t_lo = np.inf
    return t_lo, t_hi


@njit(cache=True)
def inside_times_kernel(dx, dy, vx, vy, rr, g):  # pragma: no cover - compiled
    """Return ``(t_lo, t_hi)`` (s) of :func:`._disc_windows.inside_times`, 1-D arrays of one length."""
    n = dx.shape[0]
    t_lo = np.empty(n)
    t_hi = np.empty(n)
    for i in range(n):
        t_lo[i], t_hi[i] = _inside(dx[i], dy[i], vx[i], vy[i], rr[i], g[i])
    return t_lo, t_hi


@njit(cache=True)
def disc_windows_kernel(pts, rows, limit, seg, pi):  # pragma: no cover - compiled
    """Return the open windows ``(lo, hi)`` (s) of the pairs ``(rows[seg[i]], pts[pi[i]])``.

    Parameters
    ----------
    pts : ndarray, shape (n, 2)
        Points (m).
    rows : ndarray, shape (p, 9)
        Pieces ``(mover, u, w, x, y, vx, vy, r, g)`` (:func:`._disc_windows.mover_pieces`).
    limit : float
        Added to every piece's ``r`` (m).
    seg, pi : ndarray of int64, shape (q,)
        The pairs.

    Returns
    -------
    lo, hi : ndarray, shape (q,)
        The window of each pair within its piece's span (``numpy.nan_to_num`` of its
        :func:`._disc_windows.inside_times` from the piece's start, clipped to the span);
        empty (``lo >= hi``) when none.
    """
    q = seg.shape[0]
    lo = np.empty(q)
    hi = np.empty(q)
    for i in range(q):
        k = seg[i]
        u, w = rows[k, 1], rows[k, 2]
        t_lo, t_hi = _inside(
            pts[pi[i], 0] - rows[k, 3],
            pts[pi[i], 1] - rows[k, 4],
            rows[k, 5],
            rows[k, 6],
            rows[k, 7] + limit,
            rows[k, 8],
        )
        lo[i] = _max_nan(u + _finite(t_lo, np.inf), u)
        hi[i] = _min_nan(u + _finite(t_hi, -np.inf), w)
    return lo, hi


@njit(cache=True, inline="always")
def _close_one(pts, a, b, reach, k, i):  # pragma: no cover - compiled
    """Whether point ``pts[i]`` is within ``reach[k]`` of segment ``k`` (:func:`close_kernel`, one pair)."""
    ax, ay = a[k, 0], a[k, 1]
    sx, sy = b[k, 0] - ax, b[k, 1] - ay
    dd = sx * sx + sy * sy
    inv = 1.0 / dd if dd > 0.0 else 0.0
    qx = pts[i, 0] - ax
    qy = pts[i, 1] - ay
    f = (qx * sx + qy * sy) * inv
    if not np.isnan(f):
        f = min(max(f, 0.0), 1.0)
    qx -= f * sx
    qy -= f * sy
    r = reach[k]
    return not (qx * qx + qy * qy >= r * r)


@njit(cache=True)
def close_kernel(pts, a, b, reach, seg, point):  # pragma: no cover - compiled
    """Return whether ``pts[point[i]]`` is within ``reach[seg[i]]`` of segment ``seg[i]`` (bool).

    The segments run from ``a[k]`` to ``b[k]`` (m, shape (p, 2)); the same operations as the
    numpy form of :func:`._disc_windows.close_pairs` (the projection's parameter clipped to
    ``[0, 1]``, a NaN or infinite distance kept).
    """
    q = seg.shape[0]
    out = np.empty(q, dtype=np.bool_)
    for i in range(q):
        out[i] = _close_one(pts, a, b, reach, seg[i], point[i])
    return out


@njit(cache=True)
def near_pairs_kernel(pts, a, b, reach, u, w, band_lo, band_hi, banded, box):  # pragma: no cover
    """Return ``(piece, point)``, the pairs of :func:`._disc_windows.near_pairs` (its docstring).

    The points boxed in runs of ``box``; each piece's segment box (``a`` to ``b``, shape
    (p, 2), grown by ``reach``) against them, and against the runs' time bands when
    ``banded`` (a piece's span ``[u, w]`` against the least ``band_lo`` and the largest
    ``band_hi`` of the run); then each pair's point-to-segment test (:func:`close_kernel`)
    and its own band. The same comparisons as the numpy form (NaN-propagating minima and
    maxima), the pairs in its order: by piece, then point.
    """
    n, p = pts.shape[0], a.shape[0]
    nb = (n + box - 1) // box
    lo = np.empty((nb, 2))
    hi = np.empty((nb, 2))
    b_lo = np.empty(nb)
    b_hi = np.empty(nb)
    for k in range(nb):
        s0, s1 = k * box, min(k * box + box, n)
        lo[k, 0], lo[k, 1] = pts[s0, 0], pts[s0, 1]
        hi[k, 0], hi[k, 1] = pts[s0, 0], pts[s0, 1]
        b_lo[k], b_hi[k] = band_lo[s0], band_hi[s0]
        for i in range(s0 + 1, s1):
            for c in range(2):
                lo[k, c] = _min_nan(lo[k, c], pts[i, c])
                hi[k, c] = _max_nan(hi[k, c], pts[i, c])
            b_lo[k] = _min_nan(b_lo[k], band_lo[i])
            b_hi[k] = _max_nan(b_hi[k], band_hi[i])
    cap = 64
    seg = np.empty(cap, dtype=np.int64)
    point = np.empty(cap, dtype=np.int64)
    m = 0
    for j in range(p):
        r = reach[j]
        lo_x = _min_nan(a[j, 0], b[j, 0]) - r
        lo_y = _min_nan(a[j, 1], b[j, 1]) - r
        hi_x = _max_nan(a[j, 0], b[j, 0]) + r
        hi_y = _max_nan(a[j, 1], b[j, 1]) + r
        for k in range(nb):
            if not (lo_x <= hi[k, 0] and hi_x >= lo[k, 0] and lo_y <= hi[k, 1]):
                continue
            if not hi_y >= lo[k, 1]:
                continue
            if banded and not (u[j] <= b_hi[k] and w[j] >= b_lo[k]):
                continue
            for i in range(k * box, min(k * box + box, n)):
                if not _close_one(pts, a, b, reach, j, i):
                    continue
                if banded and not (u[j] <= band_hi[i] and w[j] >= band_lo[i]):
                    continue
                if m == cap:
                    cap *= 2
                    seg = np.concatenate((seg, np.empty(cap - m, dtype=np.int64)))
                    point = np.concatenate((point, np.empty(cap - m, dtype=np.int64)))
                seg[m], point[m] = j, i
                m += 1
    return seg[:m].copy(), point[:m].copy()


#: A bucket of :func:`least_free_kernel` longer than this is sorted by numpy's sort, not by
#: insertion.
_INSERTION_MAX = 32


@njit(cache=True)
def least_free_kernel(f_lo, f_hi, lo, eps):  # pragma: no cover - compiled
    """Return the least ``L >= lo`` inside none of the open intervals ``(f_lo, f_hi + eps)``.

    Only the intervals with ``f_hi > lo`` count. The intervals in order of ``f_lo`` (a bucket
    sort: buckets of equal width over the finite ``f_lo``, each bucket sorted), then the
    walk of :func:`._tighten.sweep`'s numpy form: the first interval that starts at or
    after ``max(lo, max(f_hi so far) + eps)`` leaves that launch free. NaN when an
    ``f_lo`` is NaN (the caller then uses the numpy form).
    """
    n = f_lo.shape[0]
    idx = np.empty(n, dtype=np.int64)
    m = 0
    mn, mx = np.inf, -np.inf
    for i in range(n):
        if f_hi[i] > lo:
            x = f_lo[i]
            if np.isnan(x):
                return np.nan
            idx[m] = i
            m += 1
            if np.isfinite(x):
                mn = min(mn, x)
                mx = max(mx, x)
    if m == 0:
        return lo
    width = (mx - mn) / m if mx > mn else 1.0
    if not width > 0.0:  # an underflow
        width = 1.0
    key = np.empty(m, dtype=np.int64)
    count = np.zeros(m + 1, dtype=np.int64)
    for k in range(m):
        x = f_lo[idx[k]]
        if x <= mn:
            b = 0
        elif x >= mx:
            b = m - 1
        else:
            b = min(int((x - mn) / width), m - 1)
        key[k] = b
        count[b + 1] += 1
    for b in range(m):
        count[b + 1] += count[b]
    order = np.empty(m, dtype=np.int64)
    fill = count[:m].copy()
    for k in range(m):
        order[fill[key[k]]] = idx[k]
        fill[key[k]] += 1
    for b in range(m):
        s0, s1 = count[b], count[b + 1]
        if s1 - s0 > _INSERTION_MAX:
            part = order[s0:s1].copy()
            order[s0:s1] = part[np.argsort(f_lo[part])]
        else:
            for j in range(s0 + 1, s1):
                v = order[j]
                x = f_lo[v]
                h = j - 1
                while h >= s0 and f_lo[order[h]] > x:
                    order[h + 1] = order[h]
                    h -= 1
                order[h + 1] = v
    prev = lo
    top = -np.inf
    for k in range(m):
        j = order[k]
        if f_lo[j] >= prev:
            return prev
        top = max(top, f_hi[j])
        prev = max(top + eps, lo)
    return prev


@njit(cache=True)
def blocked_launches_kernel(node, a, b, ptr, lo, hi, after):  # pragma: no cover - compiled
    """Return the launches ``(lo_w - b, hi_w - a)`` (s) of :func:`._tighten.blocked_launches`, those ending after ``after``.

    Stay ``j`` (near node ``node[j]`` during ``[L + a[j], L + b[j]]``) against each window
    ``(lo, hi)[ptr[i]:ptr[i + 1]]`` of its node, in order of stay, then window; only the
    intervals with ``hi_w - a > after`` (s) are returned, with their ``j`` and window index.
    The same subtractions and comparison as the numpy form, so the same floats.
    """
    total = 0
    for j in range(node.shape[0]):
        total += ptr[node[j] + 1] - ptr[node[j]]
    f_lo = np.empty(total)
    f_hi = np.empty(total)
    which = np.empty(total, dtype=np.int64)
    run = np.empty(total, dtype=np.int64)
    m = 0
    for j in range(node.shape[0]):
        aj, bj = a[j], b[j]
        for r in range(ptr[node[j]], ptr[node[j] + 1]):
            x = hi[r] - aj
            if x > after:
                f_lo[m], f_hi[m], which[m], run[m] = lo[r] - bj, x, j, r
                m += 1
    return f_lo[:m].copy(), f_hi[:m].copy(), which[:m].copy(), run[:m].copy()


@njit(cache=True)
def _centre_at(tk, pos, f, last, x, out, o):  # pragma: no cover - compiled
    """Write into ``out[o]`` the centre (m) at ``x`` (s) of the mover with waypoints ``f..last``: ``numpy.interp``'s."""
    if x < tk[f]:
        out[o, 0], out[o, 1] = pos[f, 0], pos[f, 1]
        return
    if not x < tk[last]:
        out[o, 0], out[o, 1] = pos[last, 0], pos[last, 1]
        return
    k = f - 1  # the last waypoint at or before x
    for i in range(f, last + 1):
        if tk[i] <= x:
            k = i
    if tk[k] == x:
        out[o, 0], out[o, 1] = pos[k, 0], pos[k, 1]
        return
    dt = tk[k + 1] - tk[k]
    for c in range(2):
        out[o, c] = (pos[k + 1, c] - pos[k, c]) / dt * (x - tk[k]) + pos[k, c]


@njit(cache=True)
def track_knots_kernel(n_j, tk, pos, a, b):  # pragma: no cover - compiled
    """Return ``(owner, knots, centre)`` of :func:`._disc_windows.track_knots` (its docstring).

    ``n_j`` (shape (m,)): each mover's number of waypoints, ``tk`` (s) and ``pos`` (m) their
    times and positions one mover after another, ``a``, ``b`` (s, shape (m,)) each mover's
    range. The centre at ``a`` and ``b`` is ``numpy.interp``'s (the waypoint at its time,
    the first or last outside the times, else ``slope (t - t_k) + p_k``, the same
    operations), at a waypoint strictly inside the range its position.
    """
    m = n_j.shape[0]
    base = np.empty(m, dtype=np.int64)
    total = 0
    acc = 0
    for j in range(m):
        base[j] = acc
        acc += n_j[j]
        total += 2
        for i in range(base[j], acc):
            if tk[i] > a[j] and tk[i] < b[j]:
                total += 1
    owner = np.empty(total, dtype=np.int64)
    knots = np.empty(total)
    centre = np.empty((total, 2))
    o = 0
    for j in range(m):
        f, last = base[j], base[j] + n_j[j] - 1
        owner[o], knots[o] = j, a[j]
        _centre_at(tk, pos, f, last, a[j], centre, o)
        o += 1
        for i in range(f, last + 1):
            if tk[i] > a[j] and tk[i] < b[j]:
                owner[o], knots[o] = j, tk[i]
                centre[o, 0], centre[o, 1] = pos[i, 0], pos[i, 1]
                o += 1
        owner[o], knots[o] = j, b[j]
        _centre_at(tk, pos, f, last, b[j], centre, o)
        o += 1
    return owner, knots, centre


@njit(cache=True)
def mover_pieces_kernel(n_j, tk, pos, t_last, radius, growth, limit):  # pragma: no cover - compiled
    """Return the rows of :func:`._disc_windows.mover_pieces` (its docstring), shape (p, 9).

    The knots of :func:`track_knots_kernel` from 0 to ``t_end = max(t_last, 0) + 1``; per
    pair of consecutive knots ``u < w`` of a mover, the numpy form's operations: the
    velocity ``(c(w) - c(u)) / (w - u)`` where the middle is strictly inside the waypoint
    times (else 0), ``w = inf`` from ``t_end`` on, the limit ``limit + r + g clip(u, 0,
    max(t_last, 0))`` and the growth where the middle is before ``t_last``.
    """
    m = n_j.shape[0]
    hi_t = np.empty(m)
    t_end = np.empty(m)
    t_first = np.empty(m)
    acc = 0
    for j in range(m):
        hi_t[j] = max(t_last[j], 0.0)
        t_end[j] = hi_t[j] + 1.0
        t_first[j] = tk[acc]
        acc += n_j[j]
    owner, knots, pk = track_knots_kernel(n_j, tk, pos, np.zeros(m), t_end)
    rows = np.empty((owner.shape[0] - m, 9))
    r = 0
    for k in range(owner.shape[0] - 1):
        j = owner[k]
        if owner[k + 1] != j:
            continue
        u, w = knots[k], knots[k + 1]
        mid = 0.5 * (u + w)
        rows[r, 0] = j
        rows[r, 1] = u
        rows[r, 2] = np.inf if w >= t_end[j] else w
        rows[r, 3], rows[r, 4] = pk[k, 0], pk[k, 1]
        if mid > t_first[j] and mid < t_last[j]:
            rows[r, 5] = (pk[k + 1, 0] - pk[k, 0]) / (w - u)
            rows[r, 6] = (pk[k + 1, 1] - pk[k, 1]) / (w - u)
        else:
            rows[r, 5], rows[r, 6] = 0.0, 0.0
        rows[r, 7] = limit + radius[j] + growth[j] * min(max(u, 0.0), hi_t[j])
        rows[r, 8] = growth[j] if mid < t_last[j] else 0.0
        r += 1
    return rows


@njit(cache=True)
def _first_at_least(a, v, k):  # pragma: no cover - compiled
    """Return the first index ``i`` with ``a[i] >= v`` of the non-decreasing ``a`` (``len(a)`` if none): ``numpy.searchsorted``'s left side.

    Walked from ``k`` (a guess no later than the answer: the answer for a smaller ``v``), or
    from 0 when ``k`` is already past it.
    """
    if k > 0 and not a[k - 1] < v:
        k = 0
    while k < a.shape[0] and a[k] < v:
        k += 1
    return k


@njit(cache=True)
def pass_band_kernel(
    s, half, tau, s_cat, first, launch, pack, end, start, lo, hi
):  # pragma: no cover
    """Lower ``lo`` and raise ``hi`` (s, shape (n,)) to one schedule's entries and exits of the nodes ``s`` (m).

    The numpy form of :func:`._tighten.pass_band` for one schedule: its drives' samples
    ``tau`` (s) and arc lengths ``s_cat`` (m), drive ``d``'s at ``first[d]:first[d + 1]``,
    launched at ``launch[d]`` as it is and at ``pack[d]`` back to back; the arc lengths'
    running maximum; node ``i`` is left at the sample ``k``, the first at or past
    ``s_i + half`` (at ``launch + tau[k]``; ``end`` when none), and entered at the sample
    before the first at or past ``s_i - half`` (at ``pack + tau[k]``; ``start`` when none).
    The same additions and comparisons, so the same floats.
    """
    m = tau.shape[0]
    run = np.empty(m)
    late = np.empty(m)
    early = np.empty(m)
    top = -np.inf
    for d in range(first.shape[0] - 1):
        for k in range(first[d], first[d + 1]):
            top = s_cat[k] if k == 0 else max(top, s_cat[k])
            run[k] = top
            late[k] = launch[d] + tau[k]
            early[k] = pack[d] + tau[k]
    k_hi, k_lo = 0, 0  # the nodes in order: each search walks on from the last one's
    for i in range(s.shape[0]):
        k_hi = _first_at_least(run, s[i] + half, k_hi)
        hi[i] = max(hi[i], late[k_hi] if k_hi < m else end)
        k_lo = _first_at_least(run, s[i] - half, k_lo)
        lo[i] = min(lo[i], early[k_lo - 1] if k_lo > 0 else start)
