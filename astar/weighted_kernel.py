"""Compiled A* of :func:`astar.find_path` with a per-cell cost, on a radix heap.

With a ``cost`` array the keys ``f = g + h`` are floats that rarely tie, and A* with a
consistent heuristic pops them in nondecreasing order: a *monotone* priority queue serves,
and a radix heap (Ahuja, Mehlhorn, Orlin and Tarjan) is one. Its keys here are the IEEE-754
bit patterns of ``f >= 0``, which order as unsigned integers exactly as the floats do, so the
order is exact. Bucket ``b`` holds the entries whose key first differs from the last popped
key at bit ``b - 1`` (bucket 0: equal to it); a pop takes bucket 0, or finds the smallest key
of the lowest non-empty bucket, makes it the last popped key and redistributes that bucket
into lower ones. Each entry moves down at most 64 times, and in practice once or twice.

A key below the last popped one can only come from rounding (``g + h`` of a successor equal
to the expanded node's ``f`` in exact arithmetic, an ulp lower in floating point); it is
taken as equal to it. Among equal keys the last pushed is popped first.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from astar.search_kernels import unroll_path

__all__ = ["bit_length", "weighted_kernel"]


@njit(cache=True, inline="always")
def bit_length(x):  # pragma: no cover - compiled
    """Return the number of bits of the unsigned 64-bit ``x`` (0 for 0)."""
    n = 0
    for s in (32, 16, 8, 4, 2, 1):
        if x >= np.uint64(1) << np.uint64(s):
            x >>= np.uint64(s)
            n += s
    if x >= np.uint64(1):
        n += 1
    return n


def read_only(a: np.ndarray) -> np.ndarray:
    """Return ``a`` read-only (a read-only view when ``a`` is writable; no copy)."""
    if not a.flags.writeable:
        return a
    view = a.view()
    view.flags.writeable = False
    return view


def weighted_kernel(free, width, start, goal, conn8, cut, cost, rec, recf, gen, lm, lg):
    """Run :func:`_weighted_search` with its inputs ``free``, ``cost``, ``lm``, ``lg`` read-only.

    The compiled search takes read-only and writable arrays alike, but numba compiles it
    once for each combination of flags it meets; handing it read-only views (no copies)
    keeps one compiled signature for every caller (the searches, the landmark trees). The
    arguments and the result are :func:`_weighted_search`'s.
    """
    return _weighted_search(
        read_only(free),
        width,
        start,
        goal,
        conn8,
        cut,
        read_only(cost),
        rec,
        recf,
        gen,
        read_only(lm),
        read_only(lg),
    )


@njit(cache=True)
def _weighted_search(
    free,  # uint8 [H*W], padded with a blocked ring
    width,  # W = nx + 2
    start,  # padded flat index
    goal,
    conn8,  # bool
    cut,  # corner cutting allowed
    cost,  # float64 [ny*nx], unpadded
    rec,  # int32 [4*H*W] per-cell record: stamp, parent, (cost so far as float64)
    recf,  # float64 view of rec: recf[2 * v + 1] is the cost so far
    gen,  # this search's stamp; gen + 1 marks closed
    lm,  # float64 [K, H*W]: landmark distances (ALT heuristic; K = 0: none)
    lg,  # float64 [K]: the landmarks' distances to the goal
):  # pragma: no cover - numba
    """Run octile A* with step costs ``length (1 + (cost[a] + cost[b]) / 2)`` (module docstring).

    The heuristic is the octile distance, or with landmarks the larger of it and
    ``max_k |lg[k] - lm[k, v]|`` (both consistent, so their maximum is). ``goal < 0``: no
    goal and no heuristic, every reachable cell is closed with its cost from ``start`` in
    ``recf`` (a single-source shortest-path tree, as Dijkstra's algorithm).

    Returns ``(found, path, expanded, cost, 0, 0)``, as :func:`~astar.search_kernels.
    astar_kernel` does for a weighted search.
    """
    sqrt2 = 1.4142135623730951
    w = width
    gx = goal % w
    gy = goal // w
    ndir = 8 if conn8 else 4
    ddx = np.array([1, -1, 0, 0, 1, -1, 1, -1], dtype=np.int32)
    ddy = np.array([0, 0, 1, -1, 1, 1, -1, -1], dtype=np.int32)

    # the radix heap: a pool of entries (key, node, next) in 65 singly linked buckets
    cap = 4096
    pkey = np.empty(cap, dtype=np.uint64)
    pnode = np.empty(cap, dtype=np.int32)
    pnext = np.empty(cap, dtype=np.int32)
    head = np.full(65, -1, dtype=np.int32)
    spare = -1  # free list of popped entries
    used = 0
    count = 0
    fbits = np.empty(1, dtype=np.float64)
    ubits = fbits.view(np.uint64)

    closed = gen + 1
    rec[4 * start] = gen
    rec[4 * start + 1] = -1
    recf[2 * start + 1] = 0.0
    ax = abs(start % w - gx)
    ay = abs(start // w - gy)
    fbits[0] = max(ax, ay) - min(ax, ay) + min(ax, ay) * sqrt2 if conn8 else float(ax + ay)
    if goal < 0:
        fbits[0] = 0.0
    last = ubits[0]
    pkey[0] = last
    pnode[0] = start
    pnext[0] = -1
    head[0] = 0
    used = 1
    count = 1

    expanded = 0
    found = False
    fr = np.zeros(8, dtype=np.bool_)
    while count > 0:
        if head[0] < 0:  # the smallest key of the lowest bucket becomes the last popped
            i = 1
            while head[i] < 0:
                i += 1
            e = head[i]
            low = pkey[e]
            while e >= 0:
                low = min(low, pkey[e])
                e = pnext[e]
            last = low
            e = head[i]
            head[i] = -1
            while e >= 0:
                after = pnext[e]
                b = bit_length(pkey[e] ^ last)
                pnext[e] = head[b]
                head[b] = e
                e = after
        e = head[0]
        head[0] = pnext[e]
        u = pnode[e]
        pnext[e] = spare
        spare = e
        count -= 1
        if rec[4 * u] == closed:
            continue  # stale entry (lazy deletion)
        rec[4 * u] = closed
        expanded += 1
        if u == goal:
            found = True
            break
        ux = u % w
        uy = u // w
        gu = recf[2 * u + 1]
        # unpadded cell index of a padded index v in row vy: v - 2 * vy - (w - 1)
        cu = cost[u - 2 * uy - (w - 1)]
        for k in range(4):
            fr[k] = free[u + ddy[k] * w + ddx[k]] != 0
        for k in range(ndir):
            dx = ddx[k]
            dy = ddy[k]
            v = u + dy * w + dx
            if k < 4:
                if not fr[k]:
                    continue
            else:
                if free[v] == 0:
                    continue
                if not cut and (not fr[0 if dx > 0 else 1] or not fr[2 if dy > 0 else 3]):
                    continue
            r4 = 4 * v
            sv = rec[r4]
            if sv == closed:
                continue
            vy = uy + dy
            step = 1.0 if k < 4 else sqrt2
            gnew = gu + step * (1.0 + 0.5 * (cu + cost[v - 2 * vy - (w - 1)]))
            if sv == gen and gnew >= recf[2 * v + 1]:
                continue
            recf[2 * v + 1] = gnew
            rec[r4] = gen
            rec[r4 + 1] = u
            hv = 0.0
            if goal >= 0:
                ax = abs(ux + dx - gx)
                ay = abs(vy - gy)
                hv = max(ax, ay) - min(ax, ay) + min(ax, ay) * sqrt2 if conn8 else float(ax + ay)
                for q in range(lm.shape[0]):
                    d = abs(lg[q] - lm[q, v])
                    if d > hv:  # NaN (both unreachable from the landmark) is no bound
                        hv = d
            fbits[0] = gnew + hv
            key = max(ubits[0], last)
            if spare >= 0:
                e = spare
                spare = pnext[e]
            else:
                if used == cap:
                    cap *= 2
                    nk = np.empty(cap, dtype=np.uint64)
                    nn = np.empty(cap, dtype=np.int32)
                    nt = np.empty(cap, dtype=np.int32)
                    for q in range(used):  # loops, not slice copies: no shape-error code
                        nk[q] = pkey[q]
                        nn[q] = pnode[q]
                        nt[q] = pnext[q]
                    pkey = nk
                    pnode = nn
                    pnext = nt
                e = used
                used += 1
            pkey[e] = key
            pnode[e] = v
            b = bit_length(key ^ last)
            pnext[e] = head[b]
            head[b] = e
            count += 1

    if not found:
        return False, np.empty(0, dtype=np.int64), expanded, 0.0, 0, 0
    return True, unroll_path(rec, start, goal), expanded, recf[2 * goal + 1], 0, 0
