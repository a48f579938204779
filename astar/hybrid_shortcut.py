"""Fewer cusps: the Hybrid-A* path's stretches replaced by cheaper Reeds-Shepp words.

The search (:mod:`astar.hybrid_kernel`) drives primitives of one length on a lattice of
headings, so in tight places its path can back and fill more often than the space needs:
a change of direction costs a turning radius or two in the search's own cost, and a
primitive that lands one heading bin off must be undone later. :func:`shorten_cusps` passes
over the found path once, from its start: from each piece's start pose it looks for the
farthest later piece boundary that a single Reeds-Shepp word (:func:`astar.reeds_shepp.car_word`,
the cheapest word under the search's weights) joins at a lower cost *and* with no more
cusps than the stretch it replaces (counting the cusps where it meets its neighbours), and
whose every pose keeps the search's clearance: the same tests as the search's analytic shot
(:func:`~astar.hybrid_kernel.word_clear` on the free cells, and in the footprint mode
:func:`~astar.hybrid_kernel.footprint_word_clear`, the body grown by the margin, exactly
against the polygons where the grid knows them). A stretch is replaced only where both hold;
otherwise the piece is kept as it is, so the path never gets dearer in the search's cost, never
gets a cusp more, and keeps the search's guarantee.

Why written here: the words and the footprint tests are this package's own compiled kernels
(called from this module's kernel without a Python round trip per candidate); no kept
library shortens a lattice path under a body's exact clearance. After the shortcut-based
smoothing of Dolgov et al. (2010) and the "analytic expansion" of Nav2 Smac, done once on
the whole path instead of only towards the goal.

The exact-clearance mode (``clearance > 0``), whose returned poses are the kernel's own
collision samples, is left as the search found it.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from astar.hybrid_assemble import join_pieces, piece_poses
from astar.hybrid_kernel import KernelCollision, footprint_word_clear, word_clear
from astar.reeds_shepp import advance, car_word

__all__ = ["MAX_SPAN", "MAX_TESTS", "resample", "shorten_cusps", "shortcut_kernel"]

#: The most pieces one word may replace (the candidates' count grows with its square).
MAX_SPAN = 48
#: The most collision tests of candidate words per path (the search's cost decides first).
MAX_TESTS = 96


@njit(cache=True)
def shortcut_kernel(
    free, pieces, end, radius, rev_w, cusp_w, arc_w, collision, max_span, max_tests
):  # pragma: no cover - compiled
    """Replace stretches of a reversing car path by cheaper, clear Reeds-Shepp words.

    Parameters
    ----------
    free : ndarray of uint8, shape (ny, nx)
        The search's free cells, 1 where the reference point may be.
    pieces : ndarray of float64, shape (m, 5)
        ``(x, y, heading, curvature, signed length)`` of each piece from its start pose
        (cells, rad, 1/cells), in driving order (:class:`astar.PosePath`'s ``pieces``).
    end : ndarray of float64, shape (3,)
        The last piece's end pose.
    radius : float
        The search's turning radius (cells).
    rev_w, cusp_w, arc_w : float
        The search's weights: backwards length, a cusp (cells), arcs (``1 + turn_penalty``).
    collision : KernelCollision
        The search's collision record.
    max_span, max_tests : int
        The most pieces a word may replace; the most words tested for collisions.

    Returns
    -------
    out : ndarray of float64, shape (k, 5)
        The new pieces, in the same layout (the input's where nothing was replaced; the
        headings after a word shifted by the whole turns it saves, so they stay continuous).
    replaced : int
        Stretches replaced.
    tests : int
        Candidate words tested for collisions.
    """
    step, safe, occ, exact_r = collision.step, collision.safe, collision.occ, collision.exact_r
    fp, fsafe, frho, onext = collision.fp, collision.fsafe, collision.frho, collision.onext
    fmargin, fslack, fmin_slack = collision.fmargin, collision.fslack, collision.fmin_slack
    fdist, discs = collision.fdist, collision.discs
    poly = (collision.pedges, collision.pstarts, collision.pboxes)
    footprint = fp.shape[0] > 0
    fbuf = np.empty((max(fp.shape[0], 1), 5))
    m = pieces.shape[0]
    bp = np.empty((m + 1, 3))
    bp[:m] = pieces[:, :3]
    bp[m] = end
    back = pieces[:, 4] < 0.0
    cost = np.zeros(m + 1)  # cost[i]: pieces before i, with the cusps between them
    cusps = np.zeros(m + 1, dtype=np.int64)
    for i in range(m):
        s = pieces[i, 4]
        w = rev_w if s < 0.0 else 1.0
        if pieces[i, 3] != 0.0:
            w *= arc_w
        c = abs(s) * w
        k = 0
        if i > 0 and back[i - 1] != back[i]:
            c += cusp_w
            k = 1
        cost[i + 1] = cost[i] + c
        cusps[i + 1] = cusps[i] + k
    kinds = np.zeros(5, dtype=np.int8)
    lens = np.zeros(5)
    buf = np.zeros(5)
    out = np.empty((m + 5 * m, 5))
    n_out = 0
    replaced = 0
    tests = 0
    off = 0.0  # whole turns (rad) the words so far saved: added to the later headings
    i = 0
    while i < m:
        done = False
        j = min(m, i + max_span)
        while j >= i + 2 and tests < max_tests:
            # the stretch's cusps: inside it, and where it meets the piece after it
            out_cusp = j < m and back[j - 1] != back[j]
            old_cusps = cusps[j] - cusps[i] + (1 if out_cusp else 0)
            if old_cusps == 0:
                j -= 1
                continue
            old = cost[j] - cost[i] + (cusp_w if out_cusp else 0.0)
            wc, n = car_word(
                bp[i, 0],
                bp[i, 1],
                bp[i, 2],
                bp[j, 0],
                bp[j, 1],
                bp[j, 2],
                radius,
                True,
                kinds,
                lens,
                buf,
                rev_w,
                cusp_w,
                arc_w,
            )
            first = -1
            last = -1
            new_cusps = 0
            for q in range(n):
                if lens[q] != 0.0:
                    if last >= 0 and (lens[last] < 0.0) != (lens[q] < 0.0):
                        new_cusps += 1
                    if first < 0:
                        first = q
                    last = q
            if first < 0:  # the two poses coincide: nothing to drive
                j -= 1
                continue
            if i > 0 and back[i - 1] != (lens[first] < 0.0):
                wc += cusp_w
                new_cusps += 1
            if j < m and (lens[last] < 0.0) != back[j]:
                wc += cusp_w
                new_cusps += 1
            if wc < old - 1e-9 and new_cusps <= old_cusps:
                tests += 1
                th0 = bp[i, 2] + off
                clear = word_clear(
                    free, bp[i, 0], bp[i, 1], th0, radius, kinds, lens, n, step, safe, occ,
                    exact_r,
                )  # fmt: skip
                if clear and footprint:
                    clear = footprint_word_clear(
                        occ, onext, fsafe, fp, fdist, discs, poly, frho, bp[i, 0], bp[i, 1], th0,
                        radius, kinds, lens, n, fmargin, fslack, fmin_slack, fbuf,
                    )  # fmt: skip
                if clear:
                    x = bp[i, 0]
                    y = bp[i, 1]
                    th = th0
                    for q in range(n):
                        if lens[q] == 0.0:
                            continue
                        kappa = kinds[q] / radius
                        out[n_out, 0] = x
                        out[n_out, 1] = y
                        out[n_out, 2] = th
                        out[n_out, 3] = kappa
                        out[n_out, 4] = lens[q]
                        n_out += 1
                        x, y, th = advance(x, y, th, kappa, lens[q])
                    off = 2.0 * math.pi * round((th - bp[j, 2]) / (2.0 * math.pi))
                    replaced += 1
                    i = j
                    done = True
                    break
            j -= 1
        if not done:
            out[n_out] = pieces[i]
            out[n_out, 2] += off
            n_out += 1
            i += 1
    return out[:n_out].copy(), replaced, tests


def resample(pieces: np.ndarray, step: float, goal: tuple[float, float, float]) -> tuple:
    """Return the poses, directions and segments of ``pieces`` (the search's sampling).

    Parameters
    ----------
    pieces : ndarray of float64, shape (m, 5)
        ``(x, y, heading, curvature, signed length)`` per piece, in driving order (cells).
    step : float
        The poses' largest arc-length spacing (cells).
    goal : tuple of float
        The end pose ``(x, y, heading)``; the last pose is set to it exactly (heading
        unwrapped to the path's).

    Returns
    -------
    poses : ndarray of float64, shape (n, 3)
    directions : ndarray of int8, shape (n,)
    segments : ndarray of int64, shape (s, 2)
    pieces : ndarray of float64, shape (m', 5)
        Consecutive pieces of equal curvature and direction merged (the search's layout).

    Raises
    ------
    RuntimeError
        The pieces do not end at ``goal`` (an internal error).
    """
    merged: list[list[float]] = []
    for r in pieces.tolist():
        if (
            merged
            and merged[-1][3] == r[3]
            and (merged[-1][4] < 0) == (r[4] < 0)
            and math.hypot(*np.subtract(_end(merged[-1])[:2], r[:2])) < 1e-9
        ):
            merged[-1][4] += r[4]
        else:
            merged.append(list(r))
    chunks = [np.array([merged[0][:3]])]
    chunks += [piece_poses(px, py, pth, k, s, step) for px, py, pth, k, s in merged]
    poses, directions, segments = join_pieces(chunks, [p[4] for p in merged], goal)
    return poses, directions, segments, np.array(merged, dtype=np.float64).reshape(-1, 5)


def _end(piece: list[float]) -> tuple[float, float, float]:
    """Return a piece's end pose."""
    x, y, th, k, s = piece
    return advance.py_func(x, y, th, k, s)


def shorten_cusps(
    free: np.ndarray,
    pieces: np.ndarray,
    goal: tuple[float, float, float],
    radius: float,
    weights: tuple[float, float, float],
    collision: KernelCollision,
    step: float,
) -> tuple | None:
    """Return the path with stretches replaced by cheaper, clear words, or ``None``.

    Parameters
    ----------
    free : ndarray of uint8, shape (ny, nx)
        The search's free cells (1 free).
    pieces : ndarray of float64, shape (m, 5)
        The search's pieces (:class:`astar.PosePath`), cells.
    goal : tuple of float
        The path's end pose (cells, rad).
    radius : float
        The search's turning radius (cells).
    weights : tuple of float
        ``(reverse_penalty, cusp cost in cells, 1 + turn_penalty)``: the search's costs.
    collision : KernelCollision
        The search's collision record (not the exact-clearance mode).
    step : float
        The poses' spacing (cells).

    Returns
    -------
    tuple or None
        ``(poses, directions, segments, pieces, replaced, tests)`` as :func:`resample`
        returns them plus the stretches replaced and the words tested; ``None`` when no
        stretch was replaced (the path stays as it is, bit for bit).
    """
    if collision.exact_r > 0.0:
        return None
    rev_w, cusp_w, arc_w = weights
    end = np.array(goal, dtype=np.float64)
    new, replaced, tests = shortcut_kernel(
        free,
        np.ascontiguousarray(pieces, dtype=np.float64),
        end,
        float(radius),
        float(rev_w),
        float(cusp_w),
        float(arc_w),
        collision,
        MAX_SPAN,
        MAX_TESTS,
    )
    if replaced == 0:
        return None
    return (*resample(new, step, goal), int(replaced), int(tests))
