"""Tests of trajopt.geometry.rounded_polygon: every outline point at the radius from the polygon."""

from __future__ import annotations

import math

import numpy as np
import pytest

from trajopt.errors import InvalidInputError
from trajopt.geometry import rounded_polygon


def _dist_to_polygon(p, v):
    """Distance from points p (n, 2) to the convex CCW polygon v (m, 2), 0 inside (written out)."""
    if len(v) == 1:
        return np.hypot(*(p - v[0]).T)
    best = np.full(len(p), np.inf)
    inside = np.ones(len(p), dtype=bool)
    for a, b in zip(v, np.roll(v, -1, axis=0), strict=True):
        e = b - a
        q = p - a
        lam = np.clip(q @ e / (e @ e), 0.0, 1.0)
        best = np.minimum(best, np.hypot(*(q - lam[:, None] * e).T))
        inside &= e[0] * q[:, 1] - e[1] * q[:, 0] >= 0.0
    return np.where(inside & (len(v) >= 3), 0.0, best)  # a segment has no inside


@pytest.mark.parametrize(
    "verts",
    [
        [[0.3, -0.2]],
        [[0.0, 0.0], [1.0, 0.0]],
        [[0.0, 0.0], [1.0, 0.0], [0.2, 0.7]],
        [[-0.4, -0.2], [0.4, -0.2], [0.4, 0.2], [-0.4, 0.2]],
    ],
)
@pytest.mark.parametrize("radius", [0.0, 0.05, 0.3])
def test_outline_points_lie_at_the_radius(verts, radius):
    v = np.asarray(verts, dtype=float)
    out = rounded_polygon(v, radius, arc_points=64)
    d = _dist_to_polygon(out, v)
    if radius == 0.0:
        assert np.array_equal(out, v)
        return
    assert np.allclose(d, radius, atol=1e-12)
    # counter-clockwise and simple enough to enclose the polygon: positive area, at least pi r^2
    x, y = out[:, 0], out[:, 1]
    area = 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))
    assert area >= math.pi * radius**2 * 0.99
    # consecutive points are close: no gaps in the outline
    step = np.hypot(*np.diff(np.vstack([out, out[:1]]), axis=0).T)
    edges = np.hypot(*(np.roll(v, -1, axis=0) - v).T) if len(v) > 1 else np.zeros(1)
    assert np.max(step) <= max(float(np.max(edges)), 2 * math.pi * radius / 64) + 1e-9


def test_bad_arguments_are_named():
    with pytest.raises(InvalidInputError, match="radius"):
        rounded_polygon([[0.0, 0.0]], -1.0)
    with pytest.raises(InvalidInputError, match="vertices"):
        rounded_polygon([[0.0, math.nan]], 1.0)
    with pytest.raises(InvalidInputError, match="arc_points"):
        rounded_polygon([[0.0, 0.0]], 1.0, arc_points=3)
