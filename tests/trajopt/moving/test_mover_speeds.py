"""Tests of trajopt.moving: the mover table's speed bounds of the movers' shapes, all at once.

``MoverTable.shape_speed`` must equal each mover's ``shape_speed_max`` bit for bit (the
grid's pads are built from it), and bound the speed of every vertex of every shape, from
finite differences of densely sampled poses (an independent reference), on random tracks
of polygons, discs, turning shapes and single waypoints.
"""

from __future__ import annotations

import numpy as np

from trajopt.moving import MovingObstacle
from trajopt.moving._mover_segments import MoverTable

BOX = [(-0.4, -0.25), (0.4, -0.25), (0.4, 0.25), (-0.4, 0.25)]


def _random_movers(rng: np.random.Generator) -> list[MovingObstacle]:
    out = []
    for _ in range(int(rng.integers(1, 7))):
        k = int(rng.integers(1, 6))
        times = np.cumsum(rng.uniform(0.1, 1.5, k)) - 0.5
        points = rng.uniform(-3.0, 3.0, (k, 2))
        headings = rng.uniform(-3.0, 3.0, k)
        verts = BOX if rng.random() < 0.7 else None
        out.append(
            MovingObstacle.from_waypoints(
                times, points, radius=0.2, vertices=verts, headings=headings
            )
        )
    return out


def test_shape_speed_equals_each_movers_bound_and_bounds_dense_vertex_speeds():
    rng = np.random.default_rng(21)
    for _ in range(40):
        movers = _random_movers(rng)
        speed = MoverTable(movers).shape_speed
        for j, m in enumerate(movers):
            assert float(speed[j]) == m.shape_speed_max()
            if m.times.shape[0] < 2:
                assert speed[j] == 0.0
                continue
            t = np.linspace(m.times[0], m.times[-1], 4001)
            pos, th = m.pose_at(t)[:2]
            c, s = np.cos(th)[:, None], np.sin(th)[:, None]
            v = m.shape_vertices
            x = pos[:, 0:1] + c * v[None, :, 0] - s * v[None, :, 1]
            y = pos[:, 1:2] + s * v[None, :, 0] + c * v[None, :, 1]
            step = np.hypot(np.diff(x, axis=0), np.diff(y, axis=0)) / np.diff(t)[:, None]
            assert np.max(step) <= speed[j] * (1.0 + 1e-9) + 1e-9
