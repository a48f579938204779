"""The movers' places and sizes, all movers at once: :class:`MoverPlaces`.

The quick proofs (:func:`~trajopt.moving.parked_on_path`, :func:`~trajopt.moving.over_start`,
:func:`~trajopt.moving.meets_head_on`) screen every mover at once. They read the movers'
places from the certificate's table of them (:func:`._mover_segments.mover_table`) when it
is kept, or when there are enough movers to pay for building it; a few movers with no kept
table are read one by one (``numpy.interp``, the same floats as the table's).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from trajopt.moving._mover_segments import MoverTable, kept_table, mover_table
from trajopt.moving._obstacle import MovingObstacle

#: From this many movers on, their table is built when none is kept (a build costs about as
#: much as reading this many movers one by one, ~0.1 ms).
TABLE_FROM = 4


class MoverPlaces:
    """The movers' places at given times and their sizes, all at once.

    Attributes
    ----------
    reach : ndarray, shape (movers,)
        Each mover's farthest vertex from its reference point (m; 0 for a disc).
    rad0, grow : ndarray, shape (movers,)
        Each mover's radius (m) and its growth (m/s).
    t_last : ndarray, shape (movers,)
        Each mover's last time, at least 0 (s).
    """

    def __init__(self, movers: Sequence[MovingObstacle]) -> None:
        self.movers = movers
        table = kept_table(movers)
        if table is None and len(movers) >= TABLE_FROM:
            table = mover_table(movers)
        self.table: MoverTable | None = table
        if table is not None:
            self.reach, self.rad0, self.grow, self.t_last = (
                table.reach,
                table.rad0,
                table.grow,
                table.t_last,
            )
        else:
            self.reach = np.array([float(np.max(np.hypot(*m.shape_vertices.T))) for m in movers])
            self.rad0 = np.array([m.radius for m in movers], dtype=float)
            self.grow = np.array([m.growth for m in movers], dtype=float)
            self.t_last = np.array([max(m.t_last, 0.0) for m in movers], dtype=float)

    def radius_at(self, t: np.ndarray) -> np.ndarray:
        """Each mover's radius (m), shape (movers,), at its time ``t`` (s): ``radius_at``'s floats."""
        return self.rad0 + self.grow * np.clip(t, 0.0, self.t_last)

    def at(self, j: np.ndarray, t: np.ndarray) -> np.ndarray:
        """Return mover ``j[q]``'s reference point (m), shape (n, 2), at ``t[q]`` (s).

        ``numpy.interp``'s floats (``position_at``'s); ``j`` in runs of one mover each.
        """
        j = np.asarray(j, dtype=np.int64)
        t = np.asarray(t, dtype=float)
        if self.table is not None:
            return self.table.seg.at(self.table.seg.row(j, t), t)[:, :2]
        out = np.empty((t.shape[0], 2))
        if not t.shape[0]:
            return out
        cut = (np.flatnonzero(j[1:] != j[:-1]) + 1).tolist() if len(self.movers) > 1 else []
        for a, b in zip([0, *cut], [*cut, j.shape[0]], strict=True):
            m = self.movers[int(j[a])]  # position_at's floats, without its heading
            out[a:b, 0] = np.interp(t[a:b], m.times, m.positions[:, 0])
            out[a:b, 1] = np.interp(t[a:b], m.times, m.positions[:, 1])
        return out
