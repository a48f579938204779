"""The path of :func:`astar.find_pose_path` from its search kernel's nodes and shot.

:func:`assemble` turns the chain of nodes and the analytic shot that
:func:`astar.hybrid_kernel.hybrid_kernel` returns into the exact pieces (arcs and lines),
the sampled poses, their directions of travel and the segments between cusps, for a search
from the start (the chain first, then the shot to the goal) and for a search from the goal
(the shot from the start first, then the chain driven back from its last node to the goal).
Units: cells and radians, as :mod:`astar.hybrid`.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["COLLISION_STEP", "assemble", "join_pieces", "piece_poses"]

#: Cells: the arc-length spacing of the kernel's collision samples (exact mode: the poses).
COLLISION_STEP = 0.2


def _prim(p, kappas, prim_len, fine_f):
    """Return a kernel primitive code's ``(curvature, length, backwards)`` (cells)."""
    nc = len(kappas)
    li, rest = divmod(p, 2 * nc)
    return float(kappas[rest >> 1]), (prim_len / fine_f if li else prim_len), bool(p & 1)


def _units(out, kappas, prim_len, radius, start, backward, fine_f=1):
    """Return the path's primitives and shot segments in driving order.

    Each unit is ``(piece, origin)``: ``piece = [x, y, heading, curvature, signed length]``
    from its start pose, ``origin`` None, or for a primitive the search drove the other way
    (``backward``) the kernel's ``(x, y, heading, curvature, signed length)`` from which its
    collision samples were taken (exact mode: the same samples, in reverse order).
    """
    from astar.reeds_shepp import advance

    _, chain, nodes, prims, skinds, slens, sn = out[:7]
    sn = int(sn)
    shot = []
    if backward:
        x, y, th = start
    else:
        x, y, th = (float(v) for v in nodes[chain[-1]])
    for i in range(sn):
        if slens[i] == 0.0:
            continue
        k = float(skinds[i]) / radius
        shot.append(([x, y, th, k, float(slens[i])], None))
        # the kernel's closed form run as Python (an inlined kernel has no signature of its own)
        x, y, th = advance.py_func(x, y, th, k, float(slens[i]))
    edges = list(zip(chain[:-1], chain[1:], strict=True))
    if not backward:
        prim = []
        for a, b in edges:
            k, ln, back = _prim(int(prims[b]), kappas, prim_len, fine_f)
            prim.append(([*map(float, nodes[a]), k, -ln if back else ln], None))
        return prim + shot
    # from the goal: the shot ends at the chain's last node (heading unwrapped from the start's,
    # the nodes' from the goal's): shift the nodes' headings by the whole turns between them
    off = 2.0 * math.pi * round((th - float(nodes[chain[-1], 2])) / (2.0 * math.pi))
    prim = []
    for a, b in reversed(edges):
        k, ln, back = _prim(int(prims[b]), kappas, prim_len, fine_f)
        s = -ln if back else ln  # as the path drives it: from b back to a
        bx, by, bth = (float(v) for v in nodes[b])
        ax, ay, ath = (float(v) for v in nodes[a])
        prim.append(([bx, by, bth + off, k, s], (ax, ay, ath, off, -s)))
    return shot + prim


def assemble(
    out, kappas, prim_len, radius, step, start, goal, exact=False, backward=False, fine_f=1
):
    """Pieces, poses, directions and segments of the path the kernel found.

    Parameters
    ----------
    out : tuple
        :func:`astar.hybrid_kernel.hybrid_kernel`'s return value (status FOUND).
    kappas : ndarray of float64
        The primitives' curvatures (1/cells).
    prim_len, radius, step : float
        Primitive length, turning radius and the poses' largest spacing (cells).
    start, goal : tuple of float
        The path's end poses ``(x, y, heading)`` (cells, rad), as given.
    exact : bool, optional
        The poses are the kernel's own collision samples (each primitive and shot segment
        from the pose the kernel sampled it from, ``m = ceil(|s| / COLLISION_STEP)`` equal
        steps), whose chords the exact mode checked.
    backward : bool, optional
        The kernel searched from the goal (:class:`~astar.hybrid_kernel.KernelMotion`).
    fine_f : int, optional
        The kernel's ``fine_f``: its fine primitives are ``prim_len / fine_f`` long.

    Returns
    -------
    poses : ndarray of float64, shape (n, 3)
    directions : ndarray of int8, shape (n,)
    segments : ndarray of int64, shape (s, 2)
    pieces : ndarray of float64, shape (m, 5)
        As :class:`astar.PosePath`'s fields.

    Raises
    ------
    RuntimeError
        The path does not end at the goal pose (an internal error).
    """
    from astar.reeds_shepp import advance

    units = _units(out, kappas, prim_len, radius, start, backward, fine_f)
    raw = [u[0] for u in units]
    pieces: list[list[float]] = []
    for r in raw:
        if pieces and pieces[-1][3] == r[3] and (pieces[-1][4] < 0) == (r[4] < 0):
            pieces[-1][4] += r[4]
        else:
            pieces.append(list(r))
    # sample every piece from its own start pose (the kernel's node poses)
    drive = units if exact else [(p, None) for p in pieces]
    first = drive[0][0][:3] if drive else list(start)
    chunks = [np.array([first])]
    for (px, py, pth, k, s), origin in drive:
        if exact:  # the kernel's samples (arc_clear), by its closed form
            m = max(1, math.ceil(abs(s) / COLLISION_STEP))
            if origin is None:
                c = np.array([advance.py_func(px, py, pth, k, s * j / m) for j in range(1, m + 1)])
            else:  # sampled from the other end, driven back: the same samples reversed
                ax, ay, ath, off, sk = origin
                c = np.array(
                    [advance.py_func(ax, ay, ath, k, sk * j / m) for j in range(m - 1, -1, -1)]
                )
                c[:, 2] += off
            chunks.append(c)
        else:
            chunks.append(piece_poses(px, py, pth, k, s, step))
    poses, directions, segments = join_pieces(chunks, [u[0][4] for u in drive], goal)
    arr = np.array(pieces, dtype=np.float64).reshape(-1, 5)
    return poses, directions, segments, arr


def piece_poses(px: float, py: float, pth: float, k: float, s: float, step: float) -> np.ndarray:
    """Return the poses along one piece after its start, at arc-length spacing ``<= step``.

    Parameters
    ----------
    px, py, pth : float
        The piece's start pose (cells, rad).
    k, s : float
        Its curvature (1/cells) and signed length (cells, negative backwards).
    step : float
        The largest spacing (cells).

    Returns
    -------
    ndarray of float64, shape (m, 3)
        ``m = max(1, ceil(|s| / step))`` equal steps, its end pose last (closed form).
    """
    m = max(1, math.ceil(abs(s) / step - 1e-9))
    q = s * np.arange(1, m + 1) / m
    if k == 0.0:
        return np.column_stack([px + q * math.cos(pth), py + q * math.sin(pth), np.full(m, pth)])
    th1 = pth + k * q
    return np.column_stack(
        [px + (np.sin(th1) - math.sin(pth)) / k, py - (np.cos(th1) - math.cos(pth)) / k, th1]
    )


def join_pieces(
    chunks: list[np.ndarray], lengths: list[float], goal: tuple[float, float, float]
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return the poses, directions and segments of a path sampled piece by piece.

    Parameters
    ----------
    chunks : list of ndarray, shape (1, 3) then (m_i, 3)
        The start pose, then each piece's poses after its start (:func:`piece_poses`).
    lengths : list of float
        Each piece's signed length (its sign: the direction of travel).
    goal : tuple of float
        The end pose; the last pose is set to it exactly (its heading unwrapped to the path's).

    Returns
    -------
    poses, directions, segments
        As :class:`astar.PosePath`'s fields.

    Raises
    ------
    RuntimeError
        The pieces do not end at ``goal`` (an internal error).
    """
    dirs = [np.array([-1 if lengths and lengths[0] < 0 else 1], dtype=np.int8)]
    dirs += [
        np.full(len(c), -1 if s < 0 else 1, dtype=np.int8)
        for c, s in zip(chunks[1:], lengths, strict=True)
    ]
    ends = np.cumsum([len(c) for c in chunks])[1:] - 1
    poses = np.concatenate(chunks)
    directions = np.concatenate(dirs)
    # the end pose exactly (the word lands on it to rounding, ~1e-12 cells)
    gx, gy, gth = goal
    end_th = poses[-1, 2]
    exact_th = gth + 2.0 * math.pi * round((end_th - gth) / (2.0 * math.pi))
    if math.hypot(poses[-1, 0] - gx, poses[-1, 1] - gy) > 1e-6 or abs(end_th - exact_th) > 1e-6:
        raise RuntimeError(  # pragma: no cover - an internal error, not bad input
            f"internal error: the path ends at {poses[-1].tolist()}, not at the goal {goal}"
        )
    poses[-1] = (gx, gy, exact_th)
    cuts = [0]
    for i in range(len(lengths) - 1):
        if (lengths[i] < 0) != (lengths[i + 1] < 0):
            cuts.append(int(ends[i]))
    cuts.append(len(poses) - 1)
    segments = np.array([[a, b] for a, b in zip(cuts[:-1], cuts[1:], strict=True)], np.int64)
    return poses, directions, segments
