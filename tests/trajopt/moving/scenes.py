"""Maps the moving-obstacle and re-plan tests share (built by hand; 5 cm cells).

:func:`loop_occupancy`: two 1 m corridors (y = 1 and y = 4 m) joined at both ends, and a
niche at x = 6 m off the short one: a mover that parks on the short corridor sends the
robot the long way round.
"""

from __future__ import annotations

import numpy as np

#: the cell size (m) of the maps here
RES = 0.05

#: the loop's free rectangles ``(x0, x1, y0, y1)`` (m)
LOOP_ROOMS = (
    (0.5, 11.5, 0.5, 1.5),
    (0.5, 11.5, 3.5, 4.5),
    (0.5, 1.5, 0.5, 4.5),
    (10.5, 11.5, 0.5, 4.5),
    (5.5, 6.5, 1.5, 2.3),
)


def rooms_occupancy(shape: tuple[int, int], rooms) -> np.ndarray:
    """Return a map of ``shape`` cells, occupied but for the rectangles ``rooms`` (m)."""
    occ = np.ones(shape, dtype=bool)
    for x0, x1, y0, y1 in rooms:
        occ[round(y0 / RES) : round(y1 / RES), round(x0 / RES) : round(x1 / RES)] = False
    return occ


def loop_occupancy() -> np.ndarray:
    """Return the loop's occupancy, shape (100, 240) (module docstring): a fresh array."""
    return rooms_occupancy((100, 240), LOOP_ROOMS)
