"""Marching points against polygon movers' tracks: one exact test decides a stretch of time.

On each piece of a mover's track between waypoint times its reference point moves at a
constant velocity ``v``, its heading turns at a constant rate ``w`` and its radius grows at
``g`` (:class:`PolygonPieces`), so every point of its polygon moves at most ``|v| + R |w|``
(``R`` its farthest vertex from the reference point) and the distance ``f(t)`` from a fixed
point to the shape, minus the radius and a limit, changes at most at ``lip = |v| + R |w| +
g`` (m/s). One exact evaluation ``f(t)`` (:func:`_clearance`) therefore proves the sign of
``f`` on ``(t - |f(t)| / lip, t + |f(t)| / lip)``. Two marches use it:

* :func:`polygon_runs` (:func:`march_kernel`): the ``(s, t)`` grid's forbidden runs of polygon
  movers against a disc robot (:func:`._st_grid.st_grid`). A node ``s_i`` is forbidden at
  grid time ``t_k`` when the path's point there is closer to the mover's shape at ``t_k``
  than ``lim(t_k)`` (the robot radius, the margin, the mover's radius and the grid's pad).
  Each pair of a piece and a node is marched through the piece's grid times: one exact test
  decides every grid time within ``|f| / lip`` of it (all have its sign), so where the point
  is far from the boundary the march strides over many grid times, near it it steps one at
  a time, and every grid time gets the answer of the exact test. Against rounding the test
  is conservative: ``lim`` is raised by :data:`EPS_LIM` on a sufficient grid (a node within
  1 nm of the limit counts as forbidden) and lowered by it on a necessary one, and a stride
  keeps 1 nm of ``|f|`` in hand. Only the pairs whose distance can come under the limit at
  all are marched (:func:`._disc_windows.near_pairs` with each piece's bounding disc: an
  exact filter). The tests fall on grid times, so (a disc robot) each piece's place, turn
  and rounding at a grid time is made once for all the nodes that test it. A disc robot's
  pair whose piece does not grow and turns the shape by at most :data:`FROZEN_PAD` is not
  marched: the shape turned to one heading moves on a line, and the times a point is within
  a limit of it are one interval in closed form (:func:`_frozen_window`), the turn a pad.
* :func:`windows_kernel`: the violation windows in continuous time of
  :meth:`._shape_windows.ShapeTracks.windows` (sampled with a least step; sufficient).

:func:`launch_bound_kernel` gives the clearance of points at times after a launch (the
refinement of :meth:`._shape_windows.ShapeWindows._exact`), and :func:`launch_min_kernel`
its least value over the points per launch, skipping the points that the same Lipschitz
bound shows cannot hold it. The refinement itself is compiled in two steps around the
path's evaluation: :func:`refine_samples_kernel` (the motion's sample times) and
:func:`launch_refine_kernel` (the launches not proved).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numba import njit

from trajopt.kernel_cache import watch_compiles
from trajopt.moving._disc_windows import mover_pieces, near_pairs
from trajopt.moving._mover_segments import mover_table
from trajopt.moving._obstacle import MovingObstacle

watch_compiles()  # a first compilation logs one notice (trajopt.kernel_cache)

#: The limit is raised (sufficient grid) or lowered (necessary grid) by this much (m).
EPS_LIM = 1e-9
#: Added to the pair filter's reach with a footprint (m): rounding of the reaches never drops
#: a pair the exact test hits.
NEAR_PAD = 1e-9
#: The most a piece of track may turn its shape (m, at its farthest vertex, about the middle
#: of its grid times) to be solved in closed form on the grid (:func:`march_kernel`).
FROZEN_PAD = 1e-3


class PolygonPieces:
    """The movers' tracks as linear pieces with headings, and their Lipschitz bounds (module docstring).

    Parameters
    ----------
    movers : sequence of MovingObstacle
        Any shapes (a disc is a polygon of one vertex at its reference point).

    Attributes
    ----------
    pieces : ndarray, shape (p, 9)
        :func:`._disc_windows.mover_pieces` of the movers (limit 0): their reference points.
    bound : ndarray, shape (p, 9)
        The same with each mover's reach added to the radius: its bounding discs.
    head0, turn : ndarray, shape (p,)
        Heading (rad) at each piece's start and its turn rate (rad/s).
    verts : ndarray, shape (movers, m, 2)
        Each mover's polygon in its own frame (m), CCW, padded by repeating its first vertex.
    edges : ndarray, shape (movers, m, 2)
        ``verts`` rolled by one minus ``verts`` (zero for the padding).
    poly : ndarray of bool, shape (movers,)
        The mover is a polygon (3 vertices or more).
    nv : ndarray of int64, shape (movers,)
        Its number of vertices (the first ``nv[j]`` rows of ``verts[j]``).
    reach : ndarray, shape (movers,)
        Farthest vertex from the reference point (m).
    lip : ndarray, shape (p,)
        ``|v| + R |w| + max(g, 0)`` (m/s) of each piece.
    rows : ndarray, shape (p, 8)
        Columns 1..8 of ``pieces`` (the kernels' form).
    who : ndarray of int64, shape (p,)
        The mover of each piece.
    """

    def __init__(self, movers: Sequence[MovingObstacle]) -> None:
        self.pieces = mover_pieces(movers, 0.0)
        who = self.pieces[:, 0].astype(np.int64)
        u, w = self.pieces[:, 1], self.pieces[:, 2]
        m_max = max((m.shape_vertices.shape[0] for m in movers), default=1)
        self.verts = np.zeros((len(movers), m_max, 2))
        self.nv = np.array([m.shape_vertices.shape[0] for m in movers], dtype=np.int64)
        for j, m in enumerate(movers):
            v = m.shape_vertices
            self.verts[j, : v.shape[0]] = v
            self.verts[j, v.shape[0] :] = v[0]  # repeated: edges of zero length
        self.poly = self.nv >= 3
        # the farthest vertex (the padding repeats one, so the same maximum)
        reach = np.max(np.hypot(self.verts[:, :, 0], self.verts[:, :, 1]), axis=1, initial=0.0)
        # the headings at both ends of each piece, numpy.interp's (bit for bit), all at once
        seg = mover_table(movers).seg
        fin = np.isfinite(w)
        at = np.concatenate([u, np.where(fin, w, u)])
        two = np.concatenate([who, who])
        heads = seg.at(seg.row(two, at), at)[:, 2]
        head0, h_w = heads[: u.shape[0]], heads[u.shape[0] :]
        with np.errstate(invalid="ignore", divide="ignore"):
            turn = np.where(fin, (h_w - head0) / np.where(fin, w - u, 1.0), 0.0)
        nxt = np.concatenate([self.verts[:, 1:], self.verts[:, :1]], axis=1)
        self.edges = nxt - self.verts
        self.head0, self.turn, self.reach = head0, turn, reach
        self.bound = self.pieces.copy()
        self.bound[:, 7] += reach[who]
        speed = np.hypot(self.pieces[:, 5], self.pieces[:, 6])
        self.lip = speed + reach[who] * np.abs(turn) + np.maximum(self.pieces[:, 8], 0.0)
        self.rows = np.ascontiguousarray(self.pieces[:, 1:9])
        self.who = who


#: The pieces of the last movers marched (:func:`pieces_of`), most recent last.
_PIECES: list[tuple[tuple[MovingObstacle, ...], PolygonPieces]] = []
_PIECES_KEPT = 4


def pieces_of(movers: Sequence[MovingObstacle]) -> PolygonPieces:
    """Return the :class:`PolygonPieces` of ``movers``, built or kept from a recent call.

    Movers are immutable values: the same objects in the same order have the same pieces
    (a re-timing's grids and its fine windows march the same movers). The last
    :data:`_PIECES_KEPT` are kept, their arrays read-only.
    """
    key = tuple(movers)
    for i, (kept, pieces) in enumerate(_PIECES):
        if len(kept) == len(key) and all(a is b for a, b in zip(kept, key, strict=True)):
            _PIECES.append(_PIECES.pop(i))
            return pieces
    pieces = PolygonPieces(key)
    for value in vars(pieces).values():
        if isinstance(value, np.ndarray):
            value.setflags(write=False)
    _PIECES.append((key, pieces))
    del _PIECES[:-_PIECES_KEPT]
    return pieces


def polygon_runs(
    pts: np.ndarray,
    movers: Sequence[MovingObstacle],
    owners: Sequence[int],
    lim0: np.ndarray,
    t: np.ndarray,
    sufficient: bool,
    after: np.ndarray | None = None,
    polys: np.ndarray | None = None,
) -> tuple[np.ndarray, ...]:
    """Return the runs ``(node, first, last, mover)`` of polygon movers against a disc or footprint robot (module docstring).

    Parameters
    ----------
    pts : ndarray, shape (n, 2)
        The path's points at the nodes (m).
    movers : sequence of MovingObstacle
        Polygon movers (a disc is accepted too: a polygon of one vertex).
    owners : sequence of int
        The grid's index of each mover (the runs' ``mover``).
    lim0 : ndarray, shape (len(movers),)
        Each mover's limit without its radius (m): the robot radius (none with ``polys``),
        the margin and the pad; the mover's radius at ``t_k`` (growing) is added.
    t : ndarray, shape (K,)
        Grid times ``k dt`` (s).
    sufficient : bool
        Raise the limit by :data:`EPS_LIM` (else lower it).
    after : ndarray, shape (n,), optional
        Per node (s): the pieces of track that end before it are left out for that node
        (their runs could not meet the robot).
    polys : ndarray, shape (n, mb, 2), optional
        A footprint robot: its convex CCW polygon at each node (m); the test is then the
        signed distance of the two polygons (:func:`._certificate.convex_distance`) against
        the limit, and a node's pairs are those within the footprint's reach of it.

    Returns
    -------
    node, first, last, mover : ndarray of int, shape (r,)
        A run per stretch of forbidden grid times of a node on one piece (first and last
        time index inclusive; runs of consecutive pieces may touch or overlap).
    """
    tracks = pieces_of(movers)
    j = tracks.who
    eps = EPS_LIM if sufficient else -EPS_LIM
    lim_add = np.asarray(lim0, dtype=float)[j] + eps
    rows = tracks.bound.copy()
    rows[:, 7] += lim_add
    if polys is None:
        body = np.zeros((0, 1, 2))
    else:
        body = np.ascontiguousarray(polys, dtype=np.float64)
        rows[:, 7] += float(np.max(np.hypot(*(body - pts[:, None, :]).reshape(-1, 2).T)))
        rows[:, 7] += NEAR_PAD
    band = None if after is None else (after, np.full(after.shape, np.inf))
    seg, pi = near_pairs(pts, rows, 0.0, band)
    dt, kk = float(t[1] - t[0]), int(t.shape[0])
    node, k0, k1, piece = march_kernel(
        np.ascontiguousarray(pts, dtype=np.float64),
        seg.astype(np.int64),
        pi.astype(np.int64),
        tracks.rows,
        j,
        tracks.head0,
        tracks.turn,
        tracks.lip,
        lim_add,
        tracks.verts,
        tracks.edges,
        tracks.poly,
        tracks.nv,
        body,
        dt,
        kk,
        tracks.reach[j],
        1.0 if sufficient else -1.0,
    )
    owner = np.asarray(owners, dtype=np.int64)[j[piece]]
    return node, k0, k1, owner


@njit(cache=True, inline="always")
def _mover_at(row, head0, turn, tk):  # pragma: no cover - compiled
    """Return a track piece's reference point, heading and rounding at time ``tk``.

    ``row``: the piece's ``(u, w, x, y, vx, vy, r, g)`` (:attr:`PolygonPieces.rows`: from
    ``u`` to ``w``, ``w`` infinite when the mover stands after its last prediction);
    ``head0``, ``turn``: its heading at ``u`` and its rate (rad, rad/s).
    """
    tau = tk - row[0]
    run = tau if np.isfinite(row[1]) else 0.0
    return row[2] + row[4] * run, row[3] + row[5] * run, head0 + turn * run, row[6] + row[7] * tau


@njit(cache=True)
def _clearance(
    px, py, row, head0, turn, lim_add, verts, edges, poly, j, tk
):  # pragma: no cover - compiled
    """Return the point's distance (m) to mover ``j``'s polygon at ``tk`` minus the limit."""
    cx, cy, th, rad = _mover_at(row, head0, turn, tk)
    return _clearance_to(
        px, py, cx, cy, np.cos(th), np.sin(th), rad, lim_add, verts, edges, poly, j
    )


@njit(cache=True, inline="always")
def _clearance_to(
    px, py, cx, cy, c, s, rad, lim_add, verts, edges, poly, j
):  # pragma: no cover - compiled
    """:func:`_clearance` of mover ``j`` placed at ``(cx, cy)``, turned by ``(cos, sin) = (c, s)``, rounded by ``rad``."""
    dx, dy = px - cx, py - cy
    qx0, qy0 = c * dx + s * dy, -s * dx + c * dy  # in the mover's frame
    best2, bx, by = np.inf, 0.0, 0.0  # the nearest edge by squared distance, one hypot
    inside = poly[j]
    for e in range(verts.shape[1]):
        qx, qy = qx0 - verts[j, e, 0], qy0 - verts[j, e, 1]
        ex, ey = edges[j, e, 0], edges[j, e, 1]
        ee = ex * ex + ey * ey
        dot = qx * ex + qy * ey
        # the nearest point of the edge: its start, its end or between (the division only
        # there; the same floats as clipping ``dot / ee`` to [0, 1])
        if dot <= 0.0 or ee <= 0.0:
            rx, ry = qx, qy
        elif dot >= ee:
            rx, ry = qx - ex, qy - ey
        else:
            lam = dot / ee
            rx, ry = qx - lam * ex, qy - lam * ey
        r2 = rx * rx + ry * ry
        if r2 < best2:
            best2, bx, by = r2, rx, ry
        if ex * qy - ey * qx < 0.0:
            inside = False
    d = 0.0 if inside else np.hypot(bx, by)
    return d - rad - lim_add


@njit(cache=True)
def _point_polygon(x, y, w, nw):  # pragma: no cover - compiled
    """Return the distance (m) of the point ``(x, y)`` to the convex CCW polygon ``w[:nw]``; 0 inside."""
    if nw == 1:
        return np.hypot(x - w[0, 0], y - w[0, 1])
    best = np.inf
    inside = True
    for e in range(nw):
        ax, ay = w[e, 0], w[e, 1]
        ex, ey = w[(e + 1) % nw, 0] - ax, w[(e + 1) % nw, 1] - ay
        qx, qy = x - ax, y - ay
        ee = max(ex * ex + ey * ey, 1e-300)
        lam = min(max((qx * ex + qy * ey) / ee, 0.0), 1.0)
        best = min(best, np.hypot(qx - lam * ex, qy - lam * ey))
        if ex * qy - ey * qx < 0.0:
            inside = False
    return 0.0 if inside else best


@njit(cache=True)
def _signed_distance(a, na, b, nb):  # pragma: no cover - compiled
    """Return the signed distance (m) of the convex CCW polygons ``a[:na]`` and ``b[:nb]``.

    :func:`._certificate.convex_distance` for one pair: separated, the least distance of a
    vertex of one to the other; overlapping, minus the penetration depth along the edge
    normals of both (a polygon of fewer than 3 vertices has none).
    """
    separated = False
    depth = np.inf
    for side in range(2):
        p, n_p, q, n_q = (a, na, b, nb) if side == 0 else (b, nb, a, na)
        if n_p < 3:
            continue
        for e in range(n_p):
            ax, ay = p[e, 0], p[e, 1]
            ex, ey = p[(e + 1) % n_p, 0] - ax, p[(e + 1) % n_p, 1] - ay
            norm = max(np.hypot(ex, ey), 1e-300)
            nx, ny = ey / norm, -ex / norm  # outward for CCW
            lo_q, hi_q, lo_p = np.inf, -np.inf, np.inf
            for v in range(n_q):
                d = (q[v, 0] - ax) * nx + (q[v, 1] - ay) * ny
                lo_q, hi_q = min(lo_q, d), max(hi_q, d)
            for v in range(n_p):
                lo_p = min(lo_p, (p[v, 0] - ax) * nx + (p[v, 1] - ay) * ny)
            if lo_q > 0.0:
                separated = True
            depth = min(depth, min(-lo_q, hi_q - lo_p))
    if separated or not np.isfinite(depth):
        d = np.inf
        for v in range(na):
            d = min(d, _point_polygon(a[v, 0], a[v, 1], b, nb))
        for v in range(nb):
            d = min(d, _point_polygon(b[v, 0], b[v, 1], a, na))
        return d
    return -depth


@njit(cache=True)
def _footprint_clearance(
    foot, row, head0, turn, lim_add, verts, nv, j, tk, shape
):  # pragma: no cover - compiled
    """Return the signed distance (m) of the polygon ``foot`` to mover ``j``'s polygon at ``tk`` minus the limit (``shape``: scratch)."""
    cx, cy, th, rad = _mover_at(row, head0, turn, tk)
    c, s = np.cos(th), np.sin(th)
    m = nv[j]
    for v in range(m):
        shape[v, 0] = cx + c * verts[j, v, 0] - s * verts[j, v, 1]
        shape[v, 1] = cy + s * verts[j, v, 0] + c * verts[j, v, 1]
    return _signed_distance(foot, foot.shape[0], shape, m) - rad - lim_add


@njit(cache=True)
def march_kernel(
    pts,
    seg,
    pi,
    rows,
    who,
    head0,
    turn,
    lip,
    lim_add,
    verts,
    edges,
    poly,
    nv,
    body,
    dt,
    kk,
    reach,
    widen,
):  # pragma: no cover - compiled
    """Return the runs ``(node, first, last, piece)`` of the pairs ``(seg[q], pi[q])`` (module docstring).

    Against a disc robot, each piece's state at a grid time (its place, the cosine and sine
    of its heading, its rounding) is kept in a table when first made, for the other nodes
    that test that time. A disc robot's pair whose piece does not grow and turns the shape
    by at most ``pad = reach |turn| (span of its grid times) / 2 <= FROZEN_PAD`` (m) is not
    marched: the shape turned to the heading at the middle is within ``pad`` of the true one
    at those grid times, so the grid times at which the node is within the limit plus
    ``widen pad`` of it (``widen`` = 1 on a sufficient grid: every time the exact test
    forbids, and a few more; -1 on a necessary one: only times it forbids), one interval in
    closed form (:func:`_frozen_window`), are its run (its ends included on a sufficient
    grid, left out on a necessary one). ``reach``: shape (p,), the farthest vertex of each
    piece's mover (m).

    Parameters
    ----------
    pts : ndarray, shape (n, 2)
        Points (m).
    seg, pi : ndarray of int64, shape (q,)
        The piece and the point of each pair.
    rows : ndarray, shape (p, 8)
        Columns 1..8 of :func:`._disc_windows.mover_pieces`: ``u, w, x, y, vx, vy, r, g``.
    who : ndarray of int64, shape (p,)
        The mover of each piece (a row of ``verts``).
    head0, turn, lip, lim_add : ndarray, shape (p,)
        Heading (rad) at ``u``, turn rate (rad/s), Lipschitz bound (m/s), and the limit
        besides the mover's radius (m) of each piece.
    verts, edges : ndarray, shape (movers, m, 2)
    poly, nv : ndarray, shape (movers,)
        As :class:`PolygonPieces`.
    body : ndarray, shape (n, mb, 2)
        A footprint robot's polygon at each point (m, CCW); ``n = 0``: a disc robot (the
        point itself, its radius in the limit).
    dt : float
        Grid step (s).
    kk : int
        Grid times.
    """
    cap = max(16, 2 * seg.shape[0])
    out = np.empty((cap, 4), dtype=np.int64)
    foot = body.shape[0] > 0
    shape = np.empty((verts.shape[1], 2))  # a mover's polygon in the world
    # each piece's state at its grid times (place, turn, rounding), made once when first
    # tested: every node paired with the piece tests the same grid times
    n_p = rows.shape[0]
    base = np.zeros(n_p + 1, dtype=np.int64)
    for p in range(n_p):
        ka = max(int(np.ceil(rows[p, 0] / dt - 1e-9)), 0)
        kb = kk - 1
        if np.isfinite(rows[p, 1]):
            kb = min(int(np.floor(rows[p, 1] / dt + 1e-9)), kk - 1)
        base[p + 1] = base[p] + max(kb - ka + 1, 0)
    state = np.empty((base[n_p], 5))
    made = np.zeros(base[n_p], dtype=np.bool_)
    nr = 0
    for q in range(seg.shape[0]):
        p, i = seg[q], pi[q]
        u, w = rows[p, 0], rows[p, 1]
        ka = max(int(np.ceil(u / dt - 1e-9)), 0)
        kb = kk - 1
        if np.isfinite(w):
            kb = min(int(np.floor(w / dt + 1e-9)), kk - 1)
        j = who[p]
        lp = lip[p]
        px, py = pts[i, 0], pts[i, 1]
        row = rows[p]
        fin = np.isfinite(w)
        pad = reach[p] * abs(turn[p]) * 0.5 * (kb - ka) * dt if fin else 0.0
        if not foot and row[7] == 0.0 and pad <= FROZEN_PAD:
            tm = 0.5 * (ka + kb) * dt if fin else u
            th = head0[p] + turn[p] * (tm - u)
            c, sn = np.cos(th), np.sin(th)
            vx, vy = (row[4], row[5]) if fin else (0.0, 0.0)
            ox, oy = px - row[2] + vx * u, py - row[3] + vy * u  # p - c(0)
            qx, qy = c * ox + sn * oy, -sn * ox + c * oy
            dx, dy = -(c * vx + sn * vy), sn * vx - c * vy
            lim = lim_add[p] + row[6] + widen * pad
            if lim > 0.0:
                w_lo, w_hi = _frozen_window(qx, qy, dx, dy, lim, verts, edges, poly, j)
                if widen > 0.0:  # the ends count (a time on them is forbidden)
                    f0, f1 = np.ceil(w_lo / dt), np.floor(w_hi / dt)
                else:  # only the times strictly inside
                    f0, f1 = np.floor(w_lo / dt) + 1.0, np.ceil(w_hi / dt) - 1.0
                if f0 <= f1 and f0 <= kb and f1 >= ka:  # (empty: w_lo > w_hi, or NaN)
                    k0, k1 = int(max(f0, ka)), int(min(f1, kb))
                    if nr == out.shape[0]:
                        bigger = np.empty((2 * out.shape[0], 4), dtype=np.int64)
                        bigger[:nr] = out[:nr]
                        out = bigger
                    out[nr, 0], out[nr, 1], out[nr, 2], out[nr, 3] = i, k0, k1, p
                    nr += 1
            continue
        k = ka
        start = -1  # first time index of the open run
        while k <= kb:
            if foot:
                f = _footprint_clearance(
                    body[i], rows[p], head0[p], turn[p], lim_add[p], verts, nv, j, k * dt, shape
                )
            else:
                x = base[p] + k - ka
                if not made[x]:
                    cx, cy, th, rad = _mover_at(rows[p], head0[p], turn[p], k * dt)
                    state[x, 0], state[x, 1], state[x, 2] = cx, cy, np.cos(th)
                    state[x, 3], state[x, 4] = np.sin(th), rad
                    made[x] = True
                st = state[x]
                f = _clearance_to(
                    px, py, st[0], st[1], st[2], st[3], st[4], lim_add[p], verts, edges, poly, j
                )
            hit = f < 0.0
            room = abs(f) - 1e-9  # in hand against rounding
            more = 0
            if lp <= 0.0:
                if room > 0.0:
                    more = kb - k
            elif room > 0.0:
                x = room / (lp * dt)
                if x > kb - k + 1.0:
                    more = kb - k
                else:
                    more = int(x)
                    if more * lp * dt >= room:
                        more -= 1
                    more = max(more, 0)
            if hit and start < 0:
                start = k
            elif not hit and start >= 0:
                if nr == out.shape[0]:
                    bigger = np.empty((2 * out.shape[0], 4), dtype=np.int64)
                    bigger[:nr] = out[:nr]
                    out = bigger
                out[nr, 0], out[nr, 1], out[nr, 2], out[nr, 3] = i, start, k - 1, p
                nr += 1
                start = -1
            k += more + 1
        if start >= 0:
            if nr == out.shape[0]:
                bigger = np.empty((2 * out.shape[0], 4), dtype=np.int64)
                bigger[:nr] = out[:nr]
                out = bigger
            out[nr, 0], out[nr, 1], out[nr, 2], out[nr, 3] = i, start, kb, p
            nr += 1
    return out[:nr, 0].copy(), out[:nr, 1].copy(), out[:nr, 2].copy(), out[:nr, 3].copy()


@njit(cache=True, inline="always")
def _linear_span(alpha, beta, lo, hi):  # pragma: no cover - compiled
    """Return ``[lo, hi]`` cut to the ``tau`` with ``alpha + beta tau <= 0``."""
    if beta > 0.0:
        return lo, min(hi, -alpha / beta)
    if beta < 0.0:
        return max(lo, -alpha / beta), hi
    if alpha > 0.0:
        return np.inf, -np.inf
    return lo, hi


@njit(cache=True)
def _frozen_window(qx, qy, dx, dy, lim, verts, edges, poly, j):  # pragma: no cover - compiled
    """Return ``(lo, hi)``: the ``tau`` at which the point ``q + d tau`` is within ``lim`` of polygon ``j``.

    In the mover's frame (its heading fixed): ``q`` (m) the point at ``tau = 0``, ``d`` its
    velocity (m/s). The points within ``lim`` of a convex polygon are the polygon, the
    rectangles of depth ``lim`` on its edges (outward) and the discs of radius ``lim`` at its
    vertices, a convex set: a line meets it in one interval, the hull of the intervals in
    which it meets the parts (each a quadratic or linear inequality). ``lo > hi`` when empty.
    """
    lo, hi = np.inf, -np.inf
    dd = dx * dx + dy * dy
    inside_lo, inside_hi = -np.inf, np.inf
    for e in range(verts.shape[1]):
        wx, wy = qx - verts[j, e, 0], qy - verts[j, e, 1]
        # the disc at the vertex: |w + d tau|^2 < lim^2
        c0 = wx * wx + wy * wy - lim * lim
        if dd > 0.0:
            bb = 2.0 * (wx * dx + wy * dy)
            disc = bb * bb - 4.0 * dd * c0
            if disc > 0.0:
                sq = np.sqrt(disc)
                qq = -0.5 * (bb + sq) if bb >= 0.0 else -0.5 * (bb - sq)
                r1, r2 = qq / dd, c0 / qq
                lo, hi = min(lo, min(r1, r2)), max(hi, max(r1, r2))
        elif c0 < 0.0:
            lo, hi = -np.inf, np.inf
        ex, ey = edges[j, e, 0], edges[j, e, 1]
        ee = ex * ex + ey * ey
        if ee <= 0.0:
            continue
        # the edge's rectangle: 0 <= w.e <= |e|^2, 0 <= n.w <= lim |e| (n = (ey, -ex), outward)
        along0, along1 = wx * ex + wy * ey, dx * ex + dy * ey
        out0, out1 = ey * wx - ex * wy, ey * dx - ex * dy
        a0, a1 = _linear_span(-along0, -along1, -np.inf, np.inf)
        a0, a1 = _linear_span(along0 - ee, along1, a0, a1)
        a0, a1 = _linear_span(-out0, -out1, a0, a1)
        a0, a1 = _linear_span(out0 - lim * np.sqrt(ee), out1, a0, a1)
        if a0 <= a1:
            lo, hi = min(lo, a0), max(hi, a1)
        if poly[j]:  # the polygon itself: inside every edge's line
            inside_lo, inside_hi = _linear_span(out0, out1, inside_lo, inside_hi)
    if poly[j] and inside_lo <= inside_hi:
        lo, hi = min(lo, inside_lo), max(hi, inside_hi)
    return lo, hi


@njit(cache=True)
def windows_kernel(
    pts, seg, pi, a, b, rows, who, head0, turn, lip, reach, limit, verts, edges, poly, step, eps
):  # pragma: no cover - compiled
    """Return the violation windows ``(pair, lo, hi)`` (s) of the pairs ``(seg[q], pi[q])`` during ``[a[q], b[q]]``.

    The march of :meth:`._shape_windows.ShapeTracks.windows`: from ``t = a`` a sample
    ``f = f(t)`` (the clearance minus ``limit``, m) proves ``f > 0`` or ``f < 0`` on
    ``(t - |f| / lip, t + |f| / lip)``; every stretch from the first time not yet settled
    to ``t - f / lip`` (capped at ``b``) is a window, and the next sample is
    ``max(|f| / lip, step)`` later (capped at ``b``), until ``b`` is settled or sampled.
    Each window is widened by ``eps`` (s) at both ends, and the consecutive ones of a pair
    that then overlap are merged. Arguments as :func:`march_kernel`, besides ``a``, ``b``
    (shape (q,), s; ``b`` may be ``inf``), ``reach`` (shape (p,), m: the farthest vertex of
    each piece's mover), ``limit`` (m) and ``step`` (s).

    A pair whose piece does not grow and turns by little during ``[a, b]`` is not marched:
    its shape turned to the heading at the middle of ``[a, b]`` is within ``pad = reach
    |turn| (b - a) / 2`` (m) of the true one at every instant, so the times its point is
    within ``limit + radius + pad`` (+ :data:`EPS_LIM`) of that shape, one interval in closed
    form (:func:`_frozen_window`), hold the true window; used when ``2 pad <= lip step``
    (as tight as the march's windows, which are within ``2 lip step`` of the limit).

    Returns
    -------
    pair : ndarray of int64, shape (r,)
        Index into ``seg``/``pi``.
    lo, hi : ndarray, shape (r,)
        The windows (s), in order of pair and time.
    """
    cap = max(16, seg.shape[0])
    pair = np.empty(cap, dtype=np.int64)
    lo = np.empty(cap)
    hi = np.empty(cap)
    nr = 0
    for q in range(seg.shape[0]):
        p, i = seg[q], pi[q]
        j = who[p]
        lp = lip[p]
        px, py = pts[i, 0], pts[i, 1]
        bq = b[q]
        t = a[q]
        row = rows[p]
        if row[7] == 0.0:
            fin = np.isfinite(row[1])
            span = bq - t if fin else 0.0
            pad = reach[p] * abs(turn[p]) * 0.5 * span if fin else 0.0
            if 2.0 * pad <= lp * step or pad == 0.0:
                tm = 0.5 * (t + bq) if fin else row[0]
                th = head0[p] + turn[p] * (tm - row[0])
                c, sn = np.cos(th), np.sin(th)
                vx, vy = (row[4], row[5]) if fin else (0.0, 0.0)
                ox, oy = px - row[2] + vx * row[0], py - row[3] + vy * row[0]  # p - c(0)
                qx, qy = c * ox + sn * oy, -sn * ox + c * oy
                dx, dy = -(c * vx + sn * vy), sn * vx - c * vy
                lim = limit + row[6] + pad + EPS_LIM
                w_lo, w_hi = _frozen_window(qx, qy, dx, dy, lim, verts, edges, poly, j)
                w_lo, w_hi = max(w_lo, t), min(w_hi, bq)
                if w_lo < w_hi:
                    if nr == pair.shape[0]:
                        pair = np.concatenate((pair, np.empty(nr, dtype=np.int64)))
                        lo = np.concatenate((lo, np.empty(nr)))
                        hi = np.concatenate((hi, np.empty(nr)))
                    pair[nr], lo[nr], hi[nr] = q, w_lo - eps, w_hi + eps
                    nr += 1
                continue
        cov = a[q]
        last_hi = -np.inf  # the widened end of the pair's last window
        while True:
            f = _clearance(px, py, rows[p], head0[p], turn[p], limit, verts, edges, poly, j, t)
            if lp > 0.0:
                rho = f / lp
            elif f > 0.0:
                rho = np.inf
            else:
                rho = -np.inf
            w_hi = min(t - rho, bq)
            if w_hi > cov:
                w_lo, w_up = cov - eps, w_hi + eps
                if nr > 0 and pair[nr - 1] == q and not (w_lo > last_hi):
                    hi[nr - 1] = max(hi[nr - 1], w_up)
                else:
                    if nr == pair.shape[0]:
                        pair = np.concatenate((pair, np.empty(nr, dtype=np.int64)))
                        lo = np.concatenate((lo, np.empty(nr)))
                        hi = np.concatenate((hi, np.empty(nr)))
                    pair[nr], lo[nr], hi[nr] = q, w_lo, w_up
                    nr += 1
                last_hi = w_up
            cov = max(cov, t + abs(rho))
            done = t >= bq
            t = min(t + max(abs(rho), step), bq)
            if done or not (cov < bq):
                break
    return pair[:nr].copy(), lo[:nr].copy(), hi[:nr].copy()


@njit(cache=True)
def piece_at(rows, lo, hi, t):  # pragma: no cover - compiled
    """Return the last piece among ``lo..hi`` whose start time ``rows[., 0]`` (s) is at most ``t``; ``lo`` if none.

    A binary search over the pieces of one mover's track (their starts increase).
    """
    while lo < hi:
        m = (lo + hi + 1) // 2
        if rows[m, 0] <= t:
            lo = m
        else:
            hi = m - 1
    return lo


@njit(cache=True)
def launch_bound_kernel(
    launch, tau, mover, pts, pad, rows, first, head0, turn, verts, edges, poly
):  # pragma: no cover - compiled
    """Return the clearance (m) of points at times ``launch + tau`` less ``pad``, shape (L, q).

    Point ``pts[r]`` (m) is measured against mover ``mover[r]`` at ``launch[l] + tau[r]``
    (s, at least 0) on the piece of its track holding that time (the last piece starting at
    or before it), minus the radius and ``pad[r]`` (m) (the bound ``G`` of
    :meth:`._shape_windows.ShapeWindows._exact` before its minimum over the points).

    Parameters
    ----------
    launch : ndarray, shape (L,)
    tau, pad : ndarray, shape (q,)
    mover : ndarray of int64, shape (q,)
    pts : ndarray, shape (q, 2)
    rows : ndarray, shape (p, 8)
        As :func:`march_kernel` (the pieces in order of mover and time).
    first : ndarray of int64, shape (movers + 1,)
        The pieces of mover ``j`` are ``first[j]:first[j + 1]``.
    head0, turn, verts, edges, poly
        As :func:`march_kernel`.
    """
    out = np.empty((launch.shape[0], tau.shape[0]))
    for r in range(tau.shape[0]):
        j = mover[r]
        a, b = first[j], first[j + 1]
        for li in range(launch.shape[0]):
            t = launch[li] + tau[r]
            p = piece_at(rows, a, b - 1, t)
            out[li, r] = _clearance(
                pts[r, 0], pts[r, 1], rows[p], head0[p], turn[p], pad[r], verts, edges, poly, j, t
            )
    return out


@njit(cache=True)
def launch_min_kernel(
    launch, tau, mover, pts, pad, rows, first, head0, turn, lip, verts, edges, poly
):  # pragma: no cover - compiled
    """Return the least clearance (m) over the points at each launch where it is positive: :func:`launch_bound_kernel`'s row minima.

    Where the row's minimum is positive it is returned bit for bit, with fewer tests: a
    point's clearance changes at most at the ``lip`` (m/s) of the pieces of its mover's track
    between two times, so a value tested at one launch bounds it from below at another; a
    point whose bound is above the least value found so far at this launch (by more than
    1e-9 m, against rounding) cannot hold the minimum and is not tested. Where a point's
    clearance is zero or less the launch is not proved whatever the minimum
    (:meth:`._shape_windows.ShapeWindows._exact` uses only the positive ones), so the first
    such clearance found is returned and the launch's other points are not tested. Each
    launch first tests the point that held its value at the one before. Arguments as
    :func:`launch_bound_kernel`, besides ``lip``, shape (p,): each piece's bound
    (:attr:`PolygonPieces.lip`).

    Returns
    -------
    ndarray, shape (L,)
        The least clearance where it is positive, a clearance of zero or less (of one
        point) where the least is; ``inf`` where there are no points.
    """
    nl, q = launch.shape[0], tau.shape[0]
    out = np.full(nl, np.inf)
    if q == 0:
        return out
    val = np.empty(q)  # each point's last tested clearance ...
    at = np.full(q, np.nan)  # ... the launch it was tested at (NaN: never) ...
    held = np.zeros(q, dtype=np.int64)  # ... and the piece holding its time then
    arg = 0
    arg_now = 0
    for li in range(nl):
        best = np.inf
        for x in range(q + 1):
            r = arg if x == 0 else x - 1
            if x > 0 and r == arg:
                continue
            j = mover[r]
            t = launch[li] + tau[r]
            p = piece_at(rows, first[j], first[j + 1] - 1, t)
            if not np.isnan(at[r]):
                rate = 0.0  # the largest lip of the pieces between the two times
                for pp in range(min(p, held[r]), max(p, held[r]) + 1):
                    rate = max(rate, lip[pp])
                if val[r] - rate * abs(launch[li] - at[r]) > best + 1e-9:
                    continue
            g = _clearance(
                pts[r, 0], pts[r, 1], rows[p], head0[p], turn[p], pad[r], verts, edges, poly, j, t
            )
            val[r], at[r], held[r] = g, launch[li], p
            if g < best:
                best, arg_now = g, r
            if g <= 0.0:  # the launch is not proved: its least value is not needed
                break
        if best < np.inf:
            arg = arg_now
        out[li] = best
    return out


@njit(cache=True)
def float_arange(start, stop, step):  # pragma: no cover - compiled
    """Return ``numpy.arange(start, stop, step)`` for floats, the same values.

    NumPy's length, ``ceil((stop - start) / step)`` (none when not positive), and its fill:
    ``start``, ``start + step``, then ``start + i delta`` with ``delta`` the difference of
    the first two.
    """
    n = np.ceil((stop - start) / step)
    if not n > 0.0:
        return np.zeros(0)
    m = int(n)
    out = np.empty(m)
    out[0] = start
    if m > 1:
        out[1] = start + step
        delta = out[1] - start
        for i in range(2, m):
            out[i] = start + i * delta
    return out


@njit(cache=True)
def refine_samples_kernel(a, b, owner, dt):  # pragma: no cover - compiled
    """Return the refinement's sample times ``tau`` (s) and their movers: each owner's spans merged, sampled every ``dt``.

    :func:`._tighten.merged_spans` (the spans ``[a_j, b_j]`` of one owner that overlap or
    touch made one, the same floats and decisions: its stable sort by owner, then start,
    and its running maximum of ``owner * big + b``), then each merged span ``[a, b]`` at
    ``min(a + k dt, b)``, ``k = 0 .. max(ceil((b - a) / dt), 1)``: the numpy form of
    :meth:`._shape_windows.ShapeWindows._exact`.
    """
    q = a.shape[0]
    if q == 0:
        return np.zeros(0), np.zeros(0, dtype=np.int64)
    order = np.argsort(a, kind="mergesort")
    order = order[np.argsort(owner[order], kind="mergesort")]
    big = 2.0 * (np.max(np.abs(b)) + np.max(np.abs(a)) + 1.0)
    m_a = np.empty(q)
    m_b = np.empty(q)
    m_o = np.empty(q, dtype=np.int64)
    nm = 0
    top = -np.inf
    prev_o = -1
    for k in range(q):
        r = order[k]
        o = owner[r]
        key = o * big + b[r]
        if k == 0 or o != prev_o:
            new = True
            top = key
        else:
            new = a[r] > top - prev_o * big
            top = max(top, key)
        if new:
            m_a[nm], m_b[nm], m_o[nm] = a[r], b[r], o
            nm += 1
        else:
            m_b[nm - 1] = max(m_b[nm - 1], b[r])
        prev_o = o
    total = 0
    for k in range(nm):
        total += max(int(np.ceil((m_b[k] - m_a[k]) / dt)), 1) + 1
    tau = np.empty(total)
    who = np.empty(total, dtype=np.int64)
    x = 0
    for k in range(nm):
        n = max(int(np.ceil((m_b[k] - m_a[k]) / dt)), 1) + 1
        for i in range(n):
            tau[x] = min(m_a[k] + i * dt, m_b[k])
            who[x] = m_o[k]
            x += 1
    return tau, who


@njit(cache=True)
def launch_refine_kernel(
    tau,
    who,
    pts,
    lip_m,
    speed,
    limit,
    dt,
    lo,
    hi,
    steps,
    rows,
    first,
    head0,
    turn,
    lip,
    verts,
    edges,
    poly,
):  # pragma: no cover - compiled
    """Return the open intervals ``(f_lo, f_hi)`` (s) of the launches in ``[lo, hi]`` not proved clear.

    The numpy form of :meth:`._shape_windows.ShapeWindows._exact` after the path's points,
    the same floats: the points' pads ``dt / 2 (speed + lip) + limit`` (m; ``lip`` the most
    of the mover's pieces, ``lip_m``); the points whose bound at the middle launch is above
    ``lip`` times the half range left out; then per launch step of ``steps`` the launches
    from ``left`` to ``right`` (``numpy.arange``'s, :func:`float_arange`), their least
    bound (:func:`launch_min_kernel`), each positive one proving the launches within
    ``bound / lip_all`` of it, the next level between the first proved launch and one step
    before it; last, the complement in ``[lo, hi]`` of the proved launches (sorted by
    start, the running maximum of the ends; ``hi`` itself allowed).
    """
    q = tau.shape[0]
    pad = np.empty(q)
    lip_r = np.empty(q)
    half = 0.5 * dt
    for r in range(q):
        lip_r[r] = lip_m[who[r]]
        pad[r] = half * (speed + lip_r[r]) + limit
    mid = 0.5 * (lo + hi)
    at_mid = launch_bound_kernel(
        np.array([mid]), tau, who, pts, pad, rows, first, head0, turn, verts, edges, poly
    )[0]
    keep = np.zeros(q, dtype=np.bool_)
    lip_all = 0.0
    for r in range(q):
        if at_mid[r] <= lip_r[r] * (mid - lo):
            keep[r] = True
            lip_all = max(lip_all, lip_r[r])
    idx = np.flatnonzero(keep)
    n_tau, n_who, n_pts, n_pad = tau[idx], who[idx], pts[idx], pad[idx]
    cap = 16
    s_lo = np.empty(cap)
    s_hi = np.empty(cap)
    ns = 0
    left, right = lo, hi
    for level in range(steps.shape[0]):
        dl = steps[level]
        launch = float_arange(left, right + 0.5 * dl, dl)
        bound = launch_min_kernel(
            launch, n_tau, n_who, n_pts, n_pad, rows, first, head0, turn, lip, verts, edges, poly
        )
        found = -1
        for li in range(launch.shape[0]):
            if not bound[li] > 0.0:
                continue
            reach = bound[li] / max(lip_all, 1e-300)
            if not reach > 0.0:
                continue
            if ns == cap:
                cap *= 2
                s_lo = np.concatenate((s_lo, np.empty(cap - ns)))
                s_hi = np.concatenate((s_hi, np.empty(cap - ns)))
            s_lo[ns], s_hi[ns] = launch[li] - reach, launch[li] + reach
            ns += 1
            if found < 0:
                found = li
        if found < 0:
            break
        left, right = max(lo, launch[found] - dl), launch[found]
    order = np.argsort(s_lo[:ns], kind="mergesort")
    f_lo = np.empty(ns + 1)
    f_hi = np.empty(ns + 1)
    f_lo[0] = lo - 1.0
    top = -np.inf
    for k in range(ns):
        top = s_hi[order[k]] if k == 0 else max(top, s_hi[order[k]])
        f_hi[k] = s_lo[order[k]]
        f_lo[k + 1] = top
    f_hi[ns] = hi
    out = np.empty(ns + 1, dtype=np.bool_)
    for k in range(ns + 1):
        out[k] = f_hi[k] > f_lo[k]
    return f_lo[out], f_hi[out]
