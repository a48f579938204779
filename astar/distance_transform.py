"""Exact Euclidean distance transforms of occupancy grids, compiled with numba.

:func:`squared_distances` returns, for every cell centre, the squared distance to the nearest
occupied cell as an exact integer, under two metrics:

* ``"centre"``: to the nearest occupied cell *centre*, in cells squared;
* ``"square"``: to the nearest occupied cell taken as a closed unit *square*, in quarter cells
  squared (``4 d^2``, so that half-cell offsets stay integers).

Method
------
Both metrics are sums of one term per axis, ``d^2 = g(dx) + g(dy)`` with ``g(k) = k^2``
(centre) or ``4 g(k) = (2|k| - 1)^2`` for ``k != 0`` and ``0`` for ``k = 0`` (square). The
transform is therefore separable (Felzenszwalb and Huttenlocher's two passes):

1. along each column, the row offset ``k`` to the nearest occupied cell, mapped to ``g(k)``;
2. along each row, the lower envelope of one parabola per column value. For ``"centre"`` the
   parabola of column ``b`` is ``(x - b)^2 + f(b)`` at ``x = j``. For ``"square"`` each column
   ``b`` gives two parabolas centred on its square's edges, ``(x - (2b - 1))^2 + f(b)`` and
   ``(x - (2b + 1))^2 + f(b)`` at ``x = 2j``: the nearer edge gives ``(2|j - b| - 1)^2`` for
   ``b != j``, and the cell's own column (offset 0) is taken separately as ``f(j)``.

The envelope's breakpoints are computed in floating point, but every value is evaluated in
int64 from the parabola the envelope picks. A breakpoint is a ratio of integers with a
denominator of at most ``4 nx``, so it is never within rounding error of an integer ``x``
unless it lies exactly on it, where the two parabolas are equal: the result is exact.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from numba import njit

__all__ = ["squared_distances"]

#: Squared distance of a cell whose row and column hold no occupied cell.
UNREACHED = np.iinfo(np.int64).max // 4


@njit(cache=True)
def _column_pass(occ: np.ndarray, square: bool) -> np.ndarray:  # pragma: no cover
    """``g(k)`` for the row offset ``k`` to the nearest occupied cell of each column.

    ``occ`` bool [ny, nx]; returns int64 [ny, nx], :data:`UNREACHED` in empty columns.
    """
    ny, nx = occ.shape
    f = np.empty((ny, nx), dtype=np.int64)
    big = ny + 1  # larger than any real offset
    for j in range(nx):
        last = -big
        for i in range(ny):
            if occ[i, j]:
                last = i
            f[i, j] = i - last
        last = ny + big
        for i in range(ny - 1, -1, -1):
            if occ[i, j]:
                last = i
            k = min(f[i, j], last - i)
            if k >= big:
                f[i, j] = UNREACHED
            elif square:
                f[i, j] = 0 if k == 0 else (2 * k - 1) * (2 * k - 1)
            else:
                f[i, j] = k * k
    return f


@njit(cache=True)
def _row_pass(f: np.ndarray, square: bool) -> np.ndarray:  # pragma: no cover
    """Lower envelope along each row of the parabolas of :func:`_column_pass`'s values."""
    ny, nx = f.shape
    out = np.empty((ny, nx), dtype=np.int64)
    m = 2 * nx
    centre = np.empty(m, dtype=np.int64)
    value = np.empty(m, dtype=np.int64)
    left = np.empty(m + 1, dtype=np.float64)  # left end of each envelope parabola's range
    n_sides = 2 if square else 1
    for i in range(ny):
        row = f[i]
        n = 0
        for b in range(nx):
            fb = row[b]
            if fb >= UNREACHED:
                continue
            for side in range(n_sides):
                c = (2 * b - 1 + 2 * side) if square else b
                s = -np.inf
                keep = True
                while n > 0:
                    cl = centre[n - 1]
                    if cl == c:  # same centre: the lower parabola wins
                        if fb >= value[n - 1]:
                            keep = False
                            break
                        n -= 1
                        continue
                    s = ((fb + c * c) - (value[n - 1] + cl * cl)) / (2.0 * (c - cl))
                    if s <= left[n - 1]:
                        n -= 1
                    else:
                        break
                if not keep:
                    continue
                if n == 0:
                    s = -np.inf
                centre[n] = c
                value[n] = fb
                left[n] = s
                n += 1
        if n == 0:
            for j in range(nx):
                out[i, j] = UNREACHED
            continue
        q = 0
        for j in range(nx):
            x = 2 * j if square else j
            while q + 1 < n and left[q + 1] <= x:
                q += 1
            d = x - centre[q]
            v = d * d + value[q]
            if square and row[j] < v:  # the cell's own column: no horizontal offset
                v = row[j]
            out[i, j] = v
    return out


@njit(cache=True)
def _transform(occ: np.ndarray, square: bool) -> np.ndarray:  # pragma: no cover
    """Both passes in one compiled call (one kernel to load in a fresh process)."""
    return _row_pass(_column_pass(occ, square), square)


def squared_distances(occupied: np.ndarray, metric: Literal["centre", "square"]) -> np.ndarray:
    """Exact squared distance from every cell centre to the nearest occupied cell.

    Parameters
    ----------
    occupied : ndarray of bool, shape (ny, nx)
        Occupied cells.
    metric : {"centre", "square"}
        ``"centre"``: to the nearest occupied cell centre, in cells squared. ``"square"``: to
        the nearest occupied cell taken as a closed square, in quarter cells squared
        (``4 d^2``).

    Returns
    -------
    ndarray of int64, shape (ny, nx)
        ``0`` on occupied cells; :data:`UNREACHED` everywhere when no cell is occupied.
    """
    occ = np.ascontiguousarray(occupied, dtype=np.bool_)
    if occ.ndim != 2:
        raise ValueError(f"occupied must be 2-D, got shape {occ.shape}")
    if metric not in ("centre", "square"):
        raise ValueError(f"metric must be 'centre' or 'square', got {metric!r}")
    if occ.flags.writeable:  # read-only either way: one compiled signature (no copy)
        occ = occ.view()
        occ.flags.writeable = False
    return _transform(occ, metric == "square")
