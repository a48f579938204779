"""Compiled kernels of :func:`astar.find_path`: octile A* and jump point search.

(With a per-cell cost the search runs :mod:`astar.weighted_kernel` instead.)

Both search a padded, flattened grid of free cells with a binary heap of ``(f, g, node)``
(ties: larger ``g`` first) plus a stack of nodes whose ``f`` equals the current minimum;
the shared open-list helpers are :func:`heap_push`, :func:`heap_pop` and
:func:`stack_push`. :func:`find_path` (module :mod:`astar.search`) validates the input and
chooses the kernel; the kernels' contracts are in their docstrings.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["astar_kernel", "heap_pop", "heap_push", "jps_kernel", "stack_push", "unroll_path"]


@njit(cache=True, inline="always")
def heap_pop(hf, hg, hn, size):  # pragma: no cover - compiled
    """Pop the heap's root: returns ``(node, f, new size)``."""
    u = hn[0]
    fcur = hf[0]
    size -= 1
    if size > 0:
        lf = hf[size]
        lg = hg[size]
        ln = hn[size]
        i = 0
        while True:
            c = 2 * i + 1
            if c >= size:
                break
            if c + 1 < size and (hf[c + 1] < hf[c] or (hf[c + 1] == hf[c] and hg[c + 1] > hg[c])):
                c += 1
            if hf[c] < lf or (hf[c] == lf and hg[c] > lg):
                hf[i] = hf[c]
                hg[i] = hg[c]
                hn[i] = hn[c]
                i = c
            else:
                break
        hf[i] = lf
        hg[i] = lg
        hn[i] = ln
    return u, fcur, size


@njit(cache=True, inline="always")
def stack_push(stk, ssize, scap, v):  # pragma: no cover - compiled
    """Push ``v`` on the stack of nodes whose f equals the current minimum (grown x2)."""
    if ssize == scap:
        scap *= 2
        ns = np.empty(scap, dtype=np.int32)
        for i in range(ssize):  # a loop, not a slice copy: no shape-mismatch error code
            ns[i] = stk[i]
        stk = ns
    stk[ssize] = v
    return stk, ssize + 1, scap


@njit(cache=True, inline="always")
def heap_push(hf, hg, hn, size, cap, fnew, gnew, v):  # pragma: no cover - compiled
    """Push ``(f, g, node)`` on the binary heap (ties: larger ``g`` first; grown x2)."""
    if size == cap:
        cap *= 2
        nf = np.empty(cap, dtype=np.float64)
        ng = np.empty(cap, dtype=np.float64)
        nn = np.empty(cap, dtype=np.int32)
        for i in range(size):  # a loop, not slice copies: no shape-mismatch error code
            nf[i] = hf[i]
            ng[i] = hg[i]
            nn[i] = hn[i]
        hf = nf
        hg = ng
        hn = nn
    i = size
    size += 1
    while i > 0:
        p = (i - 1) >> 1
        if fnew < hf[p] or (fnew == hf[p] and gnew > hg[p]):
            hf[i] = hf[p]
            hg[i] = hg[p]
            hn[i] = hn[p]
            i = p
        else:
            break
    hf[i] = fnew
    hg[i] = gnew
    hn[i] = v
    return hf, hg, hn, size, cap


@njit(cache=True)
def astar_kernel(
    free,  # uint8 [H*W], padded with a blocked ring
    width,  # W = nx + 2
    start,  # padded flat index
    goal,
    conn8,  # bool
    cut,  # corner cutting allowed
    rec,  # int32 [4*H*W] per-cell record: stamp, parent, straight steps, diagonal steps
    gen,  # this search's stamp; gen + 1 marks closed
):  # pragma: no cover - numba
    """Run octile A* on the padded grid (the argument comments give each one's role).

    Returns ``(found, path, expanded, 0.0, straight steps, diagonal steps)``: the padded
    flat indices of the path from start to goal, the count of expanded cells, and the
    path's numbers of straight and diagonal steps (its length is ``a + b sqrt(2)``).
    (:func:`~astar.weighted_kernel.weighted_kernel` runs the search with a cell cost.)
    """
    sqrt2 = 1.4142135623730951
    w = width
    gx = goal % w
    gy = goal // w

    # neighbour table: E, W, N, S, then NE, NW, SE, SW
    ndir = 8 if conn8 else 4
    ddx = np.array([1, -1, 0, 0, 1, -1, 1, -1], dtype=np.int32)
    ddy = np.array([0, 0, 1, -1, 1, 1, -1, -1], dtype=np.int32)

    cap = 1024
    hf = np.empty(cap, dtype=np.float64)
    hg = np.empty(cap, dtype=np.float64)
    hn = np.empty(cap, dtype=np.int32)
    size = 0

    closed = gen + 1
    rec[4 * start] = gen
    rec[4 * start + 2] = 0
    rec[4 * start + 3] = 0
    rec[4 * start + 1] = -1
    sx = start % w
    sy = start // w
    ax = abs(sx - gx)
    ay = abs(sy - gy)
    if conn8:
        h0 = max(ax, ay) - min(ax, ay) + min(ax, ay) * sqrt2
    else:
        h0 = float(ax + ay)
    hf[0] = h0
    hg[0] = 0.0
    hn[0] = start
    size = 1

    # a node pushed with f equal to the f being expanded is minimal (consistent heuristic):
    # it bypasses the heap on a LIFO stack, which is popped first
    scap = 256
    stk = np.empty(scap, dtype=np.int32)
    ssize = 0
    fcur = h0

    expanded = 0
    found = False
    fr = np.zeros(8, dtype=np.bool_)
    while size > 0 or ssize > 0:
        if ssize > 0:
            ssize -= 1
            u = stk[ssize]
        else:
            # ---- pop the heap's root
            u, fcur, size = heap_pop(hf, hg, hn, size)
        if rec[4 * u] == closed:
            continue  # stale entry (lazy deletion)
        rec[4 * u] = closed
        expanded += 1
        if u == goal:
            found = True
            break
        ux = u % w
        uy = u // w
        gau = rec[4 * u + 2]
        gbu = rec[4 * u + 3]
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
                if not cut:
                    # both orthogonal neighbours: (dx, 0) is E/W = k 0/1, (0, dy) is N/S = k 2/3
                    if not fr[0 if dx > 0 else 1] or not fr[2 if dy > 0 else 3]:
                        continue
            r4 = 4 * v
            sv = rec[r4]
            if sv == closed:
                continue
            vx = ux + dx
            vy = uy + dy
            ax = abs(vx - gx)
            ay = abs(vy - gy)
            na = gau + (1 if k < 4 else 0)
            nb = gbu + (0 if k < 4 else 1)
            gnew = na + nb * sqrt2
            if sv == gen and gnew >= rec[r4 + 2] + rec[r4 + 3] * sqrt2:
                continue
            rec[r4 + 2] = na
            rec[r4 + 3] = nb
            if conn8:
                mn = min(ax, ay)
                fnew = (na + max(ax, ay) - mn) + (nb + mn) * sqrt2
            else:
                fnew = (na + ax + ay) + nb * sqrt2
            rec[r4] = gen
            rec[r4 + 1] = u
            if fnew == fcur:
                stk, ssize, scap = stack_push(stk, ssize, scap, v)
                continue
            # ---- push (sift up)
            hf, hg, hn, size, cap = heap_push(hf, hg, hn, size, cap, fnew, gnew, v)

    if not found:
        return False, np.empty(0, dtype=np.int64), expanded, 0.0, 0, 0
    return True, unroll_path(rec, start, goal), expanded, 0.0, rec[4 * goal + 2], rec[4 * goal + 3]


@njit(cache=True)
def unroll_path(rec, start, goal):  # pragma: no cover - compiled
    """Return the padded flat indices from ``start`` to ``goal`` along the parents in ``rec``."""
    n = 1
    v = goal
    while v != start:
        v = rec[4 * v + 1]
        n += 1
    path = np.empty(n, dtype=np.int64)
    v = goal
    for i in range(n - 1, -1, -1):
        path[i] = v
        if i > 0:
            v = rec[4 * v + 1]
    return path


# --------------------------------------------------------------------------- jump point search
@njit(cache=True)
def _jump_straight(free, n, d, p, goal):  # pragma: no cover - numba
    """Walk from ``n`` by ``d`` to the next jump point (``-1`` if blocked first)."""
    # p is the perpendicular offset (1 or the row width); a cell is a jump point when a side
    # cell is free while the side cell one step back is blocked (a forced neighbour)
    while True:
        n += d
        if free[n] == 0:
            return -1
        if n == goal:
            return n
        b = n - d
        if (free[n + p] != 0 and free[b + p] == 0) or (free[n - p] != 0 and free[b - p] == 0):
            return n


@njit(cache=True)
def _jump_diag(free, n, dh, dv, w, goal):  # pragma: no cover - numba
    """Walk diagonally from ``n`` by ``dh + dv`` to the next jump point (``-1`` if none)."""
    while True:
        # no corner cutting: both orthogonal cells of the step must be free
        if free[n + dh] == 0 or free[n + dv] == 0:
            return -1
        n += dh + dv
        if free[n] == 0:
            return -1
        if n == goal:
            return n
        if (
            _jump_straight(free, n, dh, w, goal) >= 0
            or _jump_straight(free, n, dv, np.int64(1), goal) >= 0  # not a literal 1
        ):
            return n


@njit(cache=True)
def jps_kernel(free, width, start, goal, rec, gen):  # pragma: no cover - numba
    """Jump point search: 8-connected, no corner cutting, octile costs (exact, integer pairs).

    Same record layout and result tuple as :func:`astar_kernel` (``rec`` holds the jump
    points only; the path between two jump points is a straight or diagonal segment).
    """
    sqrt2 = 1.4142135623730951
    w = width
    gx = goal % w
    gy = goal // w

    cap = 256
    hf = np.empty(cap, dtype=np.float64)
    hg = np.empty(cap, dtype=np.float64)
    hn = np.empty(cap, dtype=np.int32)

    closed = gen + 1
    rec[4 * start] = gen
    rec[4 * start + 2] = 0
    rec[4 * start + 3] = 0
    rec[4 * start + 1] = -1
    ax = abs(start % w - gx)
    ay = abs(start // w - gy)
    h0 = max(ax, ay) - min(ax, ay) + min(ax, ay) * sqrt2
    hf[0] = h0
    hg[0] = 0.0
    hn[0] = start
    size = 1

    scap = 64
    stk = np.empty(scap, dtype=np.int32)
    ssize = 0
    fcur = h0

    succ = np.empty(8, dtype=np.int64)
    # the 8 directions as (horizontal offset, vertical offset), straight ones first
    sdh = np.array([1, -1, 0, 0, 1, -1, 1, -1], dtype=np.int64)
    sdv = np.array([0, 0, w, -w, w, w, -w, -w], dtype=np.int64)

    expanded = 0
    found = False
    while size > 0 or ssize > 0:
        # u as int64 (the open lists hold int32): _jump_straight and _jump_diag then have
        # one compiled signature each
        if ssize > 0:
            ssize -= 1
            u = np.int64(stk[ssize])
        else:
            u32, fcur, size = heap_pop(hf, hg, hn, size)
            u = np.int64(u32)
        if rec[4 * u] == closed:
            continue
        rec[4 * u] = closed
        expanded += 1
        if u == goal:
            found = True
            break
        ux = u % w
        uy = u // w
        gau = rec[4 * u + 2]
        gbu = rec[4 * u + 3]
        pu = rec[4 * u + 1]

        # ---- successors: jump points in the pruned directions
        ns = 0
        if pu < 0:
            for k in range(8):
                dh = sdh[k]
                dv = sdv[k]
                if k < 4:
                    if free[u + dh + dv] != 0:
                        v = _jump_straight(free, u, dh + dv, np.int64(1) if dh == 0 else w, goal)
                        if v >= 0:
                            succ[ns] = v
                            ns += 1
                else:
                    v = _jump_diag(free, u, dh, dv, w, goal)
                    if v >= 0:
                        succ[ns] = v
                        ns += 1
        else:
            px = pu % w
            py = pu // w
            sx = 1 if ux > px else (-1 if ux < px else 0)
            sy = 1 if uy > py else (-1 if uy < py else 0)
            dh = sx
            dv = sy * w
            if sx != 0 and sy != 0:
                if free[u + dh] != 0:
                    v = _jump_straight(free, u, dh, w, goal)
                    if v >= 0:
                        succ[ns] = v
                        ns += 1
                if free[u + dv] != 0:
                    v = _jump_straight(free, u, dv, np.int64(1), goal)
                    if v >= 0:
                        succ[ns] = v
                        ns += 1
                v = _jump_diag(free, u, dh, dv, w, goal)
                if v >= 0:
                    succ[ns] = v
                    ns += 1
            else:
                d = dh + dv  # the direction of travel
                p = w if sy == 0 else np.int64(1)  # perpendicular offset
                if free[u + d] != 0:
                    v = _jump_straight(free, u, d, p, goal)
                    if v >= 0:
                        succ[ns] = v
                        ns += 1
                for q in (p, -p):
                    if free[u + q] != 0 and free[u - d + q] == 0:
                        # forced: turn to the side, straight or diagonally forward
                        v = _jump_straight(free, u, q, w + 1 - p, goal)
                        if v >= 0:
                            succ[ns] = v
                            ns += 1
                        if sy == 0:
                            v = _jump_diag(free, u, d, q, w, goal)
                        else:
                            v = _jump_diag(free, u, q, d, w, goal)
                        if v >= 0:
                            succ[ns] = v
                            ns += 1

        for j in range(ns):
            v = succ[j]
            r4 = 4 * v
            sv = rec[r4]
            if sv == closed:
                continue
            vx = v % w
            vy = v // w
            ddx = abs(vx - ux)
            ddy = abs(vy - uy)
            if ddx != 0 and ddy != 0:
                na = gau
                nb = gbu + ddx
            else:
                na = gau + ddx + ddy
                nb = gbu
            gnew = na + nb * sqrt2
            if sv == gen and gnew >= rec[r4 + 2] + rec[r4 + 3] * sqrt2:
                continue
            rec[r4] = gen
            rec[r4 + 2] = na
            rec[r4 + 3] = nb
            rec[r4 + 1] = u
            ax = abs(vx - gx)
            ay = abs(vy - gy)
            mn = min(ax, ay)
            fnew = (na + max(ax, ay) - mn) + (nb + mn) * sqrt2
            if fnew == fcur:
                stk, ssize, scap = stack_push(stk, ssize, scap, v)
                continue
            hf, hg, hn, size, cap = heap_push(hf, hg, hn, size, cap, fnew, gnew, v)

    if not found:
        return False, np.empty(0, dtype=np.int64), expanded, 0.0, 0, 0
    # ---- unroll the jump points into cells (each hop is a straight or diagonal segment)
    n = 1
    v = goal
    while v != start:
        pv = rec[4 * v + 1]
        n += max(abs(v % w - pv % w), abs(v // w - pv // w))
        v = pv
    path = np.empty(n, dtype=np.int64)
    i = n - 1
    path[i] = goal
    v = goal
    while v != start:
        pv = rec[4 * v + 1]
        vx = v % w
        vy = v // w
        sx = 1 if pv % w > vx else (-1 if pv % w < vx else 0)
        sy = 1 if pv // w > vy else (-1 if pv // w < vy else 0)
        step = sx + sy * w
        c = v
        while c != pv:
            c += step
            i -= 1
            path[i] = c
        v = pv
    return True, path, expanded, 0.0, rec[4 * goal + 2], rec[4 * goal + 3]
