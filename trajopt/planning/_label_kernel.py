"""The compiled labelling of :func:`trajopt.planning.component_labels`: :func:`label_kernel`.

Two passes over the cells in row-major order with a union-find forest (Rosenfeld and
Pfaltz's two-pass connected-component labelling, 4-connected): the first gives each free
cell its left or upper neighbour's provisional label, or a new one, and joins the two when
both are free (the larger root under the smaller); the second numbers the roots in
increasing order and relabels every cell. A component's first cell in row-major order opens
its smallest label (no free neighbour of it comes before it), which stays its root, so the
components are numbered by their first cell: the labels of ``scipy.ndimage.label`` with its
default (4-connected) structure.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from trajopt.kernel_cache import watch_compiles

watch_compiles()  # a first compilation logs one notice (trajopt.kernel_cache)


@njit(cache=True)
def _root(parent, i):  # pragma: no cover - compiled
    """Return the root of ``i`` in ``parent``, halving the path on the way."""
    while parent[i] != i:
        parent[i] = parent[parent[i]]
        i = parent[i]
    return i


@njit(cache=True)
def label_kernel(occupied):  # pragma: no cover - compiled
    """Return the 4-connected component labels of the free cells of ``occupied``.

    Parameters
    ----------
    occupied : ndarray of bool, shape (ny, nx)
        ``True`` on occupied cells.

    Returns
    -------
    ndarray of int32, shape (ny, nx)
        0 on occupied cells; ``1 .. n`` on free cells, one per component, numbered by each
        component's first cell in row-major order.
    """
    ny, nx = occupied.shape
    labels = np.zeros((ny, nx), dtype=np.int32)
    parent = np.empty(ny * nx // 2 + 2, dtype=np.int32)  # a label per run start at most
    n = 0
    for iy in range(ny):
        for ix in range(nx):
            if occupied[iy, ix]:
                continue
            left = labels[iy, ix - 1] if ix > 0 else 0
            up = labels[iy - 1, ix] if iy > 0 else 0
            if left == 0 and up == 0:
                n += 1
                if n >= parent.size:
                    grown = np.empty(2 * parent.size, dtype=np.int32)
                    grown[: parent.size] = parent
                    parent = grown
                parent[n] = n
                labels[iy, ix] = n
            elif up == 0:
                labels[iy, ix] = left
            elif left == 0 or left == up:
                labels[iy, ix] = up
            else:
                a = _root(parent, left)
                b = _root(parent, up)
                if a < b:
                    parent[b] = a
                elif b < a:
                    parent[a] = b
                labels[iy, ix] = left
    # a component's first cell opens its smallest label, which a join keeps as the root
    final = np.zeros(n + 1, dtype=np.int32)
    k = 0
    for lab in range(1, n + 1):
        r = _root(parent, lab)
        if r == lab:
            k += 1
            final[lab] = k
        else:
            final[lab] = final[r]  # r < lab: numbered already
    for iy in range(ny):
        for ix in range(nx):
            labels[iy, ix] = final[labels[iy, ix]]
    return labels
