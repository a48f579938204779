"""The waypoint segments of several movers in one table: their rates and poses, gathered.

:class:`MoverSegments` lets the moving-obstacle certificate
(:func:`trajopt.moving.certify_movers`) evaluate every mover's pose and rates on many time
intervals with one gather instead of one ``numpy.interp`` per mover (compiled:
:func:`rows_kernel`, :func:`poses_kernel`); :func:`mover_table` keeps it, with the movers'
sizes and shapes, for the last movers certified.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numba import njit

from trajopt.kernel_cache import watch_compiles
from trajopt.moving._obstacle import MovingObstacle

watch_compiles()  # a first compilation logs one notice (trajopt.kernel_cache)


class MoverSegments:
    """The movers' waypoint segments, all movers at once: their rates and poses.

    Mover ``j``'s segment ``k`` (``-1`` before its first time, ``len(times) - 1`` from its
    last) is row ``base[j] + k + 1``: its start time, the next waypoint time (``inf`` after
    the last), its velocity (m/s) and turn rate (rad/s) (zero outside the times) and its
    start pose. A pose at ``t`` on segment ``k`` is what ``numpy.interp`` gives, bit for
    bit: the waypoint at its time, the first (last) waypoint before (from) the times, else
    ``slope (t - t_k) + p_k``.
    """

    def __init__(self, movers: Sequence[MovingObstacle]) -> None:
        n_j = np.array([m.times.shape[0] for m in movers], dtype=np.int64)
        self.n = n_j
        self.base = np.cumsum(n_j + 1) - (n_j + 1)
        rows = int(np.sum(n_j + 1))
        self.start = np.full(rows, -np.inf)
        self.next = np.full(rows, np.inf)
        self.vel = np.zeros((rows, 2))
        self.turn = np.zeros(rows)
        self.pose = np.zeros((rows, 3))  # x, y, heading at the start (or the held waypoint)
        self.moves = np.zeros(rows, dtype=bool)  # interpolated: t_k <= t < t_{k+1}
        own = np.repeat(np.arange(n_j.shape[0]), n_j)
        tk = np.concatenate([m.times for m in movers])
        pos = np.concatenate([m.positions for m in movers])
        wp = np.column_stack([pos, np.concatenate([m.headings for m in movers])])
        rows_wp = self.base[own] + 1 + (np.arange(tk.shape[0]) - (np.cumsum(n_j) - n_j)[own])
        self.start[rows_wp] = tk
        self.next[rows_wp - 1] = tk
        self.pose[rows_wp] = wp
        self.pose[self.base] = wp[np.cumsum(n_j) - n_j]
        pair = np.flatnonzero(own[1:] == own[:-1])  # consecutive waypoints of one mover
        dt = tk[pair + 1] - tk[pair]
        self.vel[rows_wp[pair]] = (pos[pair + 1] - pos[pair]) / dt[:, None]
        self.turn[rows_wp[pair]] = (wp[pair + 1, 2] - wp[pair, 2]) / dt
        self.moves[rows_wp[pair]] = True

    def row(self, j: np.ndarray, t: np.ndarray) -> np.ndarray:
        """Return the row of mover ``j``'s segment holding each ``t`` (s), shape (n,).

        The segment ``k`` with ``t_k <= t < t_{k+1}`` (``searchsorted`` right, less one);
        compiled (:func:`rows_kernel`).
        """
        return rows_kernel(
            self.base,
            self.n,
            self.start,
            np.ascontiguousarray(j, dtype=np.int64),
            np.ascontiguousarray(t, dtype=np.float64),
        )

    def at(self, g: np.ndarray, t: np.ndarray) -> np.ndarray:
        """Return the pose ``(x, y, heading)`` (m, m, rad), shape (n, 3), at times ``t`` (s) on rows ``g``.

        ``g`` (n,) must be the rows holding ``t`` (:meth:`row`); compiled
        (:func:`poses_kernel`).
        """
        return poses_kernel(
            self.pose,
            self.vel,
            self.turn,
            self.moves,
            self.start,
            np.ascontiguousarray(g, dtype=np.int64),
            np.ascontiguousarray(t, dtype=np.float64),
        )


@njit(cache=True)
def rows_kernel(base, n, start, j, t):  # pragma: no cover - compiled
    """Return :meth:`MoverSegments.row`: mover ``j[q]``'s row holding ``t[q]`` (s).

    Parameters
    ----------
    base, n : ndarray of int64, shape (movers,)
        Each mover's first row and its waypoint count.
    start : ndarray, shape (rows,)
        Each row's start time (s).
    j : ndarray of int64, shape (m,)
        The movers.
    t : ndarray, shape (m,)
        The times (s).

    Returns
    -------
    ndarray of int64, shape (m,)
    """
    m = t.shape[0]
    out = np.empty(m, dtype=np.int64)
    for q in range(m):
        r = base[j[q]]
        out[q] = r + np.searchsorted(start[r + 1 : r + n[j[q]] + 1], t[q], side="right")
    return out


@njit(cache=True)
def poses_kernel(pose, vel, turn, moves, start, g, t):  # pragma: no cover - compiled
    """Return :meth:`MoverSegments.at`: the pose (m, m, rad), shape (m, 3), at ``t[q]`` on row ``g[q]``.

    The row's start pose, plus its rates times the time since its start when it is
    interpolated there (``numpy.interp``'s floats: ``slope (t - t_k) + p_k``).

    Parameters
    ----------
    pose : ndarray, shape (rows, 3)
        Each row's start pose.
    vel, turn : ndarray, shape (rows, 2) and (rows,)
        Each row's velocity (m/s) and turn rate (rad/s).
    moves : ndarray of bool, shape (rows,)
        Interpolated rows.
    start : ndarray, shape (rows,)
        Each row's start time (s).
    g : ndarray of int64, shape (m,)
        The rows holding the times.
    t : ndarray, shape (m,)
        The times (s).

    Returns
    -------
    ndarray, shape (m, 3)
    """
    m = t.shape[0]
    out = np.empty((m, 3))
    for q in range(m):
        r = g[q]
        if moves[r] and t[q] != start[r]:
            off = t[q] - start[r]
            out[q, 0] = vel[r, 0] * off + pose[r, 0]
            out[q, 1] = vel[r, 1] * off + pose[r, 1]
            out[q, 2] = turn[r] * off + pose[r, 2]
        else:
            out[q, 0] = pose[r, 0]
            out[q, 1] = pose[r, 1]
            out[q, 2] = pose[r, 2]
    return out


class MoverTable:
    """What the certificate's bisection reads of its movers, all movers at once (:func:`mover_table`).

    ``seg`` (:class:`MoverSegments`); per mover, shape (movers,): ``reach`` (its farthest
    vertex, m), ``rad0`` (radius, m), ``grow`` (growth, m/s), ``t_last`` (its last time, at
    least 0, s), ``disc`` (no vertices), ``sizes`` (vertex count); ``verts``: each vertex
    count's table of the movers' vertices, shape (movers, count, 2) (zeros for the others).
    The compiled bounds' form (:func:`._bisection_bounds.disc_robot_bounds_kernel`):
    ``columns``, shape (movers, 6), the columns reach, rad0, grow, t_last, disc (1.0) and
    sizes; ``padded``, shape (movers, largest count, 2), each mover's vertices first.
    ``movers``: the movers themselves; :attr:`shape_speed` their shapes' speed bounds.
    """

    def __init__(self, movers: Sequence[MovingObstacle]) -> None:
        self.seg = MoverSegments(movers)
        self.reach = np.array([float(np.max(np.hypot(*m.shape_vertices.T))) for m in movers])
        self.rad0 = np.array([m.radius for m in movers])
        self.grow = np.array([m.growth for m in movers])
        self.t_last = np.array([max(m.t_last, 0.0) for m in movers])
        self.disc = np.array([m.vertices is None for m in movers])
        self.sizes = np.array([m.shape_vertices.shape[0] for m in movers])
        self.verts = {
            int(size): np.stack(
                [
                    m.shape_vertices if m.shape_vertices.shape[0] == size else np.zeros((size, 2))
                    for m in movers
                ]
            )
            for size in np.unique(self.sizes)
        }
        self.columns = np.column_stack(
            [self.reach, self.rad0, self.grow, self.t_last, self.disc, self.sizes]
        ).astype(np.float64)
        self.padded = np.zeros((len(movers), int(np.max(self.sizes, initial=1)), 2))
        for j, m in enumerate(movers):
            self.padded[j, : m.shape_vertices.shape[0]] = m.shape_vertices
        for value in (*vars(self.seg).values(), *vars(self).values(), *self.verts.values()):
            if isinstance(value, np.ndarray):
                value.setflags(write=False)
        self.movers = tuple(movers)
        self._shape_speed: np.ndarray | None = None

    @property
    def shape_speed(self) -> np.ndarray:
        """Each mover's :meth:`MovingObstacle.shape_speed_max` (m/s), shape (movers,), all at once.

        The pieces of every track in one pass, each mover's largest by
        ``numpy.maximum.reduceat``: the same operations on the same floats (0 for a mover
        with one waypoint). Computed on first use, read-only.
        """
        if self._shape_speed is None:
            ms = self.movers
            n_j = np.array([m.times.shape[0] for m in ms], dtype=np.int64)
            tk = np.concatenate([m.times for m in ms])
            pos = np.concatenate([m.positions for m in ms])
            hd = np.concatenate([m.headings for m in ms])
            own = np.repeat(np.arange(n_j.shape[0]), n_j)
            pair = np.flatnonzero(own[1:] == own[:-1])  # consecutive waypoints of one mover
            dt = tk[pair + 1] - tk[pair]
            d = pos[pair + 1] - pos[pair]
            w = np.abs(hd[pair + 1] - hd[pair]) / dt
            v = np.hypot(d[:, 0], d[:, 1]) / dt + self.reach[own[pair]] * w
            out = np.zeros(n_j.shape[0])
            moving = n_j >= 2
            if pair.size:
                starts = np.cumsum(n_j - 1) - (n_j - 1)
                out[moving] = np.maximum.reduceat(v, starts[moving])
            out.setflags(write=False)
            self._shape_speed = out
        return self._shape_speed


#: The tables of the last movers certified (:func:`mover_table`), most recent last.
_TABLES: list[tuple[tuple[MovingObstacle, ...], MoverTable]] = []
_TABLES_KEPT = 4


def mover_table(movers: Sequence[MovingObstacle]) -> MoverTable:
    """Return the :class:`MoverTable` of ``movers``, built or kept from a recent certificate.

    Movers are immutable values: the same objects in the same order have the same table (a
    re-timing certifies its candidates against the same movers). The last
    :data:`_TABLES_KEPT` are kept, their arrays read-only.
    """
    key = tuple(movers)
    for i, (kept, table) in enumerate(_TABLES):
        if len(kept) == len(key) and all(a is b for a, b in zip(kept, key, strict=True)):
            _TABLES.append(_TABLES.pop(i))
            return table
    table = MoverTable(key)
    _TABLES.append((key, table))
    del _TABLES[:-_TABLES_KEPT]
    return table


def kept_table(movers: Sequence[MovingObstacle]) -> MoverTable | None:
    """Return the kept :class:`MoverTable` of ``movers`` (:func:`mover_table`'s), or ``None``.

    Nothing is built, and the order of the kept tables is left as it is.
    """
    key = tuple(movers)
    for kept, table in _TABLES:
        if len(kept) == len(key) and all(a is b for a, b in zip(kept, key, strict=True)):
            return table
    return None
