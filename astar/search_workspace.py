"""The shared state of the compiled searches: work buffers, padded grids and their lock.

:func:`astar.find_path` and :func:`astar.build_landmarks` run the kernels of
:mod:`astar.search_kernels` and :mod:`astar.weighted_kernel` on a flat ``uint8`` copy of the
grid padded with one ring of blocked cells (:func:`padded_free`) and on work buffers reused
between calls (:func:`workspace`). Both caches keep the last few sizes or grids and are
shared by every caller, so a search holds :data:`LOCK` from fetching them until its kernel
returns.
"""

from __future__ import annotations

import threading
from collections import OrderedDict

import numpy as np

__all__ = ["LOCK", "Workspace", "padded_free", "workspace"]


class Workspace:
    """Work buffers of one padded size, reused between searches (guarded by :data:`LOCK`).

    Parameters
    ----------
    n : int
        Number of cells of the padded grid, ``(ny + 2) (nx + 2)``.

    Attributes
    ----------
    rec : ndarray of int32, shape (4 n,)
        Per cell ``[stamp, parent, straight steps, diagonal steps]``; a cell belongs to the
        current search when its stamp is that search's generation (or one more, when closed).
    recf : ndarray of float64, shape (2 n,)
        A view of ``rec``: the two step counts read as the float64 cost so far of the
        weighted search.
    gen : int
        The generation of the last search (odd).
    """

    __slots__ = ("gen", "rec", "recf")

    def __init__(self, n: int) -> None:
        # one cache line touch per cell: [stamp, parent, straight steps, diagonal steps]; the
        # two step counts double as the float64 cost so far of the weighted search (recf)
        self.rec = np.zeros(4 * n, dtype=np.int32)
        self.recf = self.rec.view(np.float64)
        self.gen = 1

    def next_gen(self) -> int:
        """Start a search: return a new generation stamp (the buffers need no clearing).

        Returns
        -------
        int
            The new generation, odd; the stamps are reset when it nears ``2**31``.
        """
        self.gen += 2
        if self.gen >= 2**31 - 4:
            self.rec[0::4] = 0
            self.gen = 1
        return self.gen


LOCK = threading.Lock()
"""Serialises the searches: held while a caller uses :func:`padded_free`, :func:`workspace`
and the buffers they return."""

_WORKSPACES: OrderedDict[int, Workspace] = OrderedDict()
_PADDED: OrderedDict[int, tuple[np.ndarray, np.ndarray]] = OrderedDict()
_CACHE_SIZE = 4


def workspace(n: int) -> Workspace:
    """Return the work buffers for a padded grid of ``n`` cells (cached, call under :data:`LOCK`).

    Parameters
    ----------
    n : int
        Number of cells of the padded grid.

    Returns
    -------
    Workspace
        The cached buffers of that size (the last few sizes are kept), or new ones.
    """
    ws = _WORKSPACES.get(n)
    if ws is None:
        ws = Workspace(n)
        _WORKSPACES[n] = ws
        while len(_WORKSPACES) > _CACHE_SIZE:
            _WORKSPACES.popitem(last=False)
    else:
        _WORKSPACES.move_to_end(n)
    return ws


def padded_free(occupied: np.ndarray) -> np.ndarray:
    """Flat uint8 free mask of ``occupied`` with a blocked one-cell ring (cached by identity).

    Call under :data:`LOCK`.

    Parameters
    ----------
    occupied : ndarray of bool, shape (ny, nx)
        A grid's occupancy (read-only, as :class:`~astar.grid.OccupancyGrid` holds it).

    Returns
    -------
    ndarray of uint8, shape ((ny + 2) (nx + 2),)
        1 on free cells, 0 on occupied cells and on the ring; read-only.
    """
    key = id(occupied)
    hit = _PADDED.get(key)
    if hit is not None and hit[0] is occupied:
        _PADDED.move_to_end(key)
        return hit[1]
    ny, nx = occupied.shape
    free = np.zeros((ny + 2, nx + 2), dtype=np.uint8)
    free[1:-1, 1:-1] = ~occupied
    flat = free.ravel()
    flat.flags.writeable = False
    # keep a reference to `occupied` so its id cannot be reused while cached
    _PADDED[key] = (occupied, flat)
    while len(_PADDED) > _CACHE_SIZE:
        _PADDED.popitem(last=False)
    return flat
