"""Hand-built grids and curves shared by several test files (a helper module, not a test
module): test files import these instead of importing one another."""

from __future__ import annotations

import math

import numpy as np

import astar
from trajopt.corridor import build_polygon_corridor
from trajopt.geometry._bspline import BSplineCurve, clamped_uniform_knots
from trajopt.geometry._curve import ParametricCurve

__all__ = ["Arc", "door_grid", "l_shaped_grid", "line", "square_inflated", "staircase_passage"]


# ------------------------------------------------------------------ grids
def door_grid() -> astar.OccupancyGrid:
    """60 x 40 cells of 5 cm: a wall at x = 1.5 m with a 0.6 m door, a block below."""
    occ = np.zeros((40, 60), bool)
    occ[:, 30] = True
    occ[16:28, 30] = False
    occ[5:12, 40:50] = True
    return astar.OccupancyGrid(occ, 0.05, (0.0, 0.0))


def l_shaped_grid() -> np.ndarray:
    occ = np.ones((30, 30), bool)
    occ[3:10, 3:27] = False  # horizontal hall
    occ[3:27, 19:27] = False  # vertical hall
    return occ


def staircase_passage(angle_deg: float, width_cells: float, n: int = 60) -> np.ndarray:
    """Occupied: cells whose square lies entirely outside the open strip of
    ``width_cells`` around the line through the map centre at ``angle_deg``."""
    th = math.radians(angle_deg)
    iy, ix = np.mgrid[0:n, 0:n]
    ds = np.array(
        [
            -math.sin(th) * (ix + cx - n / 2) + math.cos(th) * (iy + cy - n / 2)
            for cx, cy in ((0, 0), (1, 0), (0, 1), (1, 1))
        ]
    )
    h = width_cells / 2
    return np.all(ds >= h, axis=0) | np.all(ds <= -h, axis=0)


def square_inflated(grid: astar.OccupancyGrid, radius: float) -> astar.OccupancyGrid:
    """``grid`` inflated by ``radius`` (m) with the square metric, outside occupied."""
    return astar.inflate(grid, radius, metric="square", outside_occupied=True)


# ------------------------------------------------------------------ curves
class Arc(ParametricCurve):
    """An exact circular arc of radius r (counter-clockwise), parameter = angle (rad)."""

    def __init__(self, r: float, angle: float) -> None:
        self.r, self.angle = r, angle

    @property
    def domain(self):
        return (0.0, self.angle)

    def __call__(self, u, nu=0):
        u = np.clip(np.asarray(u, dtype=float), 0.0, self.angle)
        c, s = np.cos(u), np.sin(u)
        r = self.r
        out = {
            0: (r * c, r * s),
            1: (-r * s, r * c),
            2: (-r * c, -r * s),
            3: (r * s, -r * c),
        }[nu]
        return np.stack(out, axis=-1)

    @property
    def length(self):
        return self.r * self.angle

    def s_at_u(self, u):
        return self.r * np.clip(np.asarray(u, dtype=float), 0.0, self.angle)

    def u_at_s(self, s):
        return np.clip(np.asarray(s, dtype=float), 0.0, self.length) / self.r


def line(length: float, direction: float = 0.3) -> BSplineCurve:
    """A straight segment as a cubic B-spline with uniformly spaced control points."""
    t = clamped_uniform_knots(5, 3)
    d = np.array([math.cos(direction), math.sin(direction)])
    c = np.linspace(0.0, length, 5)[:, None] * d[None, :]
    return BSplineCurve(t, c, 3)


#: The cost hall of the smoother's cost tests: cell size (m), start and end (m)
L_HALL_RES = 0.05
L_HALL_START, L_HALL_END = (0.8, 1.1), (2.9, 3.2)


def l_hall():
    """An L of two 1.2 m halls; the inner corner's walls lined with a 0.35 m band of cost 1."""
    occ = np.ones((80, 80), bool)
    occ[10:34, 10:70] = False  # y 0.5 .. 1.7 m
    occ[10:70, 46:70] = False  # x 2.3 .. 3.5 m
    grid = astar.OccupancyGrid(occ, L_HALL_RES)
    yy, xx = np.mgrid[0:80, 0:80]
    x, y = (xx + 0.5) * L_HALL_RES, (yy + 0.5) * L_HALL_RES
    band = ((y > 1.35) & (y < 1.7) & (x < 2.65)) | ((x > 2.3) & (x < 2.65) & (y > 1.35))
    cost = np.where(band & ~occ, 1.0, 0.0)
    pts = np.vstack(
        [np.linspace(L_HALL_START, (2.9, 1.1), 40), np.linspace((2.9, 1.1), L_HALL_END, 40)[1:]]
    )
    return grid, cost, build_polygon_corridor(grid, pts, 0.2)
