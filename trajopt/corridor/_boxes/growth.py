"""Growing the box corridor's boxes along a grid path, with O(1) free-rectangle tests."""

from __future__ import annotations

import numpy as np


class RectTester:
    """O(1) "is this cell rectangle all free" tests from a summed-area table."""

    __slots__ = ("sat", "nx", "ny", "x_off", "y_off")

    def __init__(self, occupied: np.ndarray, window: tuple[int, int, int, int]) -> None:
        # table only over ``window`` = (x0, x1, y0, y1) inclusive: rectangles outside it are
        # reported as not free (callers never need them)
        x0, x1, y0, y1 = window
        sub = occupied[y0 : y1 + 1, x0 : x1 + 1]
        ny, nx = sub.shape
        sat = np.zeros((ny + 1, nx + 1), dtype=np.int32)
        sat[1:, 1:] = np.cumsum(np.cumsum(sub, axis=0, dtype=np.int32), axis=1)
        self.sat = sat
        self.nx, self.ny = nx, ny
        self.x_off, self.y_off = x0, y0

    def free(self, x0: int, x1: int, y0: int, y1: int) -> bool:
        """Return whether the cell rectangle ``[x0, x1] x [y0, y1]`` is all free."""
        x0 -= self.x_off
        x1 -= self.x_off
        y0 -= self.y_off
        y1 -= self.y_off
        if x0 < 0 or y0 < 0 or x1 >= self.nx or y1 >= self.ny or x0 > x1 or y0 > y1:
            return False
        s = self.sat
        return int(s[y1 + 1, x1 + 1] - s[y0, x1 + 1] - s[y1 + 1, x0] + s[y0, x0]) == 0


def grow_boxes(
    cells: np.ndarray, tester: RectTester, cap: int, seed_back: int
) -> tuple[list[tuple[int, int, int, int]], list[tuple[int, int]]]:
    """Boxes ``(x0, x1, y0, y1)``.

    Boxes ``(x0, x1, y0, y1)`` (inclusive cells) covering the path ``cells`` in order, and the
    run of path cells ``(a, b)`` each one holds (see :func:`build_corridor`).
    """
    n = len(cells)
    rects: list[tuple[int, int, int, int]] = []
    runs: list[tuple[int, int]] = []

    def inside(r: tuple[int, int, int, int], j: int) -> bool:
        x, y = cells[j]
        return r[0] <= x <= r[1] and r[2] <= y <= r[3]

    i = 0
    while True:
        # seed: bounding box of cells [i - back, i], shrunk until free
        back = min(int(seed_back), i)
        while True:
            seg = cells[i - back : i + 1]
            r = (
                int(seg[:, 0].min()),
                int(seg[:, 0].max()),
                int(seg[:, 1].min()),
                int(seg[:, 1].max()),
            )
            if (r[1] - r[0] < cap and r[3] - r[2] < cap and tester.free(*r)) or back == 0:
                break
            back -= 1
        # extend forward along the path
        j = i + 1
        while j < n:
            x, y = cells[j]
            cand = (min(r[0], int(x)), max(r[1], int(x)), min(r[2], int(y)), max(r[3], int(y)))
            if cand[1] - cand[0] >= cap or cand[3] - cand[2] >= cap or not tester.free(*cand):
                break
            r = cand
            j += 1
        # round-robin growth
        grew = True
        while grew:
            grew = False
            for side in range(4):
                x0, x1, y0, y1 = r
                if side == 0:
                    cand = (x0, x1 + 1, y0, y1)
                elif side == 1:
                    cand = (x0 - 1, x1, y0, y1)
                elif side == 2:
                    cand = (x0, x1, y0, y1 + 1)
                else:
                    cand = (x0, x1, y0 - 1, y1)
                if cand[1] - cand[0] < cap and cand[3] - cand[2] < cap and tester.free(*cand):
                    r = cand
                    grew = True
        # contiguous run of path cells containing i
        a = i
        while a > 0 and inside(r, a - 1):
            a -= 1
        b = i
        while b + 1 < n and inside(r, b + 1):
            b += 1
        # drop predecessors made redundant (this box overlaps the one before them)
        while len(rects) >= 2 and a <= runs[-2][1]:
            rects.pop()
            runs.pop()
        rects.append(r)
        runs.append((a, b))
        if b >= n - 1:
            break
        i = b + 1

    return rects, runs
