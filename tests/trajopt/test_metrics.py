"""Tests of trajopt.metrics on hand cases and against brute force / scipy references."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.distance import directed_hausdorff

from astar.grid import OccupancyGrid
from trajopt import metrics
from trajopt.curve import ParametricCurve, PolylineCurve
from trajopt.errors import InvalidInputError


class Circle(ParametricCurve):
    """Exact circle of radius r about (cx, cy), u = angle (counter-clockwise)."""

    def __init__(self, r: float, cx: float = 0.0, cy: float = 0.0, turns: float = 1.0):
        self.r, self.cx, self.cy, self.turns = r, cx, cy, turns

    @property
    def domain(self):
        return (0.0, 2 * np.pi * self.turns)

    def __call__(self, u, nu=0):
        u = np.asarray(u, dtype=float)
        c, s = np.cos(u), np.sin(u)
        r = self.r
        if nu == 0:
            return np.stack([self.cx + r * c, self.cy + r * s], -1)
        rot = [(-s, c), (-c, -s), (s, -c), (c, s)][(nu - 1) % 4]
        return np.stack([r * rot[0], r * rot[1]], -1)


class Line(ParametricCurve):
    """Segment p0 -> p1, u in [0, 1]."""

    def __init__(self, p0, p1):
        self.p0, self.p1 = np.asarray(p0, float), np.asarray(p1, float)

    @property
    def domain(self):
        return (0.0, 1.0)

    def __call__(self, u, nu=0):
        u = np.asarray(u, dtype=float)[..., None]
        if nu == 0:
            return self.p0 + u * (self.p1 - self.p0)
        if nu == 1:
            return np.broadcast_to(self.p1 - self.p0, u.shape[:-1] + (2,)).copy()
        return np.zeros(u.shape[:-1] + (2,))


def _empty_grid(n: int = 40, res: float = 0.1) -> OccupancyGrid:
    return OccupancyGrid(np.zeros((n, n), bool), res, (0.0, 0.0))


def _one_cell_grid(ix: int, iy: int, n: int = 20, res: float = 0.1, origin=(0.0, 0.0)):
    occ = np.zeros((n, n), bool)
    occ[iy, ix] = True
    return OccupancyGrid(occ, res, origin)


# ------------------------------------------------------------------------ curvature
def test_circle_curvature_and_heading_jump() -> None:
    r = 0.5
    ref = Circle(r)(np.linspace(0, 2 * np.pi, 50))
    m = metrics.path_metrics(
        Circle(r, turns=1.0), grid=_empty_grid(), reference=ref, radius=0.1, sample_spacing=0.01
    )
    assert m.max_curvature_1pm == pytest.approx(1 / r, rel=1e-6)
    assert m.rms_curvature_1pm == pytest.approx(1 / r, rel=1e-6)
    assert m.int_sq_curvature_1pm == pytest.approx(2 * np.pi / r, rel=1e-6)
    assert m.length_m == pytest.approx(2 * np.pi * r, rel=1e-9)
    # consecutive samples are <= 0.01 m apart: heading changes by ds / r
    n = math.ceil(2 * np.pi * r / 0.01) + 1
    assert m.max_heading_jump_rad == pytest.approx(2 * np.pi / (n - 1), rel=1e-6)
    # the reference is an inscribed 49-gon: the deviation is its sagitta
    assert m.hausdorff_m == pytest.approx(r * (1 - np.cos(np.pi / 49)), rel=1e-3)
    assert m.min_clearance_m == math.inf and not m.collision


def test_zigzag_heading_jump_and_discrete_curvature() -> None:
    d = 0.03
    pts = np.array([[i * d, (i % 2) * d] for i in range(11)])  # +-45 degree zigzag
    m = metrics.path_metrics(pts, grid=_empty_grid(), reference=pts, radius=0.1)
    assert m.max_heading_jump_rad == pytest.approx(np.pi / 2, rel=1e-9)
    # discrete curvature: 90-degree turns over a local length d*sqrt(2)
    assert m.max_curvature_1pm == pytest.approx((np.pi / 2) / (d * math.sqrt(2)), rel=1e-9)
    assert m.int_sq_curvature_1pm == pytest.approx(9 * (np.pi / 2) ** 2 / (d * math.sqrt(2)))
    assert m.mse_m2 == 0.0 and m.hausdorff_m < 1e-12 and m.length_ratio == pytest.approx(1.0)
    straight = metrics.path_metrics(
        [[0, 0], [1, 0], [2, 0]], grid=_empty_grid(), reference=pts, radius=0.1
    )
    assert straight.max_heading_jump_rad == 0.0 and straight.max_curvature_1pm == 0.0


def test_heading_jumps_wraps_angles() -> None:
    np.testing.assert_allclose(metrics.heading_jumps([3.1, -3.1, 0.0]), [2 * np.pi - 6.2, 3.1])


# ------------------------------------------------------------------------ clearance
def test_clearance_to_a_single_square_hand_cases() -> None:
    g = _one_cell_grid(5, 5)  # square [0.5, 0.6] x [0.5, 0.6]
    pts = np.array(
        [
            [0.55, 0.8],  # above the middle: 0.2
            [0.9, 0.55],  # right: 0.3
            [0.9, 1.0],  # diagonal from corner (0.6, 0.6): hypot(0.3, 0.4) = 0.5
            [0.52, 0.58],  # inside: 0
            [0.6, 0.45],  # below the corner column: 0.05
        ]
    )
    np.testing.assert_allclose(
        metrics.point_clearance(pts, g), [0.2, 0.3, 0.5, 0.0, 0.05], atol=1e-12
    )


def test_clearance_matches_brute_force_on_random_grid() -> None:
    rng = np.random.default_rng(4)
    occ = rng.random((30, 25)) < 0.15
    g = OccupancyGrid(occ, 0.05, (-0.3, 0.2))
    pts = rng.uniform([-0.5, 0.0], [1.2, 1.9], (200, 2))
    iy, ix = np.nonzero(occ)
    cx = -0.3 + (ix + 0.5) * 0.05
    cy = 0.2 + (iy + 0.5) * 0.05
    dx = np.maximum(0, np.abs(pts[:, None, 0] - cx[None]) - 0.025)
    dy = np.maximum(0, np.abs(pts[:, None, 1] - cy[None]) - 0.025)
    brute = np.hypot(dx, dy).min(axis=1)
    np.testing.assert_allclose(metrics.point_clearance(pts, g), brute, atol=1e-12)


def test_clearance_border_occupied() -> None:
    g = _empty_grid(10, 0.1)  # 1 m x 1 m, nothing occupied
    pts = np.array([[0.3, 0.5], [0.5, 0.95], [1.5, 0.5]])
    assert np.all(np.isinf(metrics.point_clearance(pts, g)))
    np.testing.assert_allclose(
        metrics.point_clearance(pts, g, border_occupied=True), [0.3, 0.05, 0.0], atol=1e-12
    )


def test_collision_flag_uses_the_radius() -> None:
    g = _one_cell_grid(10, 10)  # square [1.0, 1.1] x [1.0, 1.1]
    line = Line([0.0, 1.3], [2.0, 1.3])  # 0.2 m above the square
    ref = np.array([[0.0, 1.3], [2.0, 1.3]])
    m = metrics.path_metrics(line, grid=g, reference=ref, radius=0.25)
    assert m.min_clearance_m == pytest.approx(0.2, abs=1e-12) and m.collision
    assert not metrics.path_metrics(line, grid=g, reference=ref, radius=0.15).collision


# ---------------------------------------------------------------- deviation metrics
def test_hausdorff_distance_matches_scipy() -> None:
    rng = np.random.default_rng(5)
    a = rng.normal(size=(70, 2))
    b = rng.normal(size=(50, 2)) + [0.3, 0.0]
    ref = max(directed_hausdorff(a, b)[0], directed_hausdorff(b, a)[0])
    assert metrics.hausdorff_distance(a, b) == pytest.approx(ref, rel=1e-12)


def test_distance_to_polyline_matches_brute_force() -> None:
    rng = np.random.default_rng(6)
    v = np.cumsum(rng.normal(size=(30, 2)), axis=0)
    p = rng.normal(size=(100, 2)) * 4
    a, d = v[:-1], np.diff(v, axis=0)
    t = np.clip(np.sum((p[:, None] - a) * d, -1) / np.sum(d * d, -1), 0, 1)
    brute = np.linalg.norm(p[:, None] - (a + t[..., None] * d), axis=-1).min(axis=1)
    np.testing.assert_allclose(metrics.distance_to_polyline(p, v), brute, atol=1e-12)


def test_offset_line_mse_hausdorff_and_end_errors() -> None:
    ref = np.c_[np.linspace(0, 1, 11), np.zeros(11)]
    line = Line([0.0, 0.04], [1.0, 0.04])
    m = metrics.path_metrics(line, grid=_empty_grid(), reference=ref, radius=0.1)
    assert m.mse_m2 == pytest.approx(0.04**2, rel=1e-9)
    assert m.hausdorff_m == pytest.approx(0.04, rel=1e-9)
    assert (m.start_error_x_m, m.start_error_y_m) == pytest.approx((0.0, 0.04))
    assert (m.end_error_x_m, m.end_error_y_m) == pytest.approx((0.0, 0.04))
    # with explicit parameters: equation (3) at u_i, here shifted by 0.1 along x
    m2 = metrics.path_metrics(
        line, grid=_empty_grid(), reference=ref, radius=0.1, params=np.linspace(0, 1, 11) * 0.9
    )
    expected = np.mean((0.1 * np.linspace(0, 1, 11)) ** 2 + 0.04**2)
    assert m2.mse_m2 == pytest.approx(expected, rel=1e-9)
    # a shorter line: Hausdorff is the uncovered end
    short = metrics.path_metrics(
        Line([0.0, 0.0], [0.7, 0.0]), grid=_empty_grid(), reference=ref, radius=0.1
    )
    assert short.hausdorff_m == pytest.approx(0.3, rel=1e-9)
    assert short.length_ratio == pytest.approx(0.7)
    assert short.end_error_x_m == pytest.approx(0.3)


def test_as_dict_and_bad_inputs() -> None:
    ref = np.c_[np.linspace(0, 1, 5), np.zeros(5)]
    m = metrics.path_metrics(ref, grid=_empty_grid(), reference=PolylineCurve(ref), radius=0.1)
    d = m.as_dict()
    assert d["mse_m2"] == 0.0 and set(d) == set(metrics.PathMetrics.__dataclass_fields__)
    with pytest.raises(InvalidInputError, match="sample_spacing"):
        metrics.path_metrics(ref, grid=_empty_grid(), reference=ref, radius=0.1, sample_spacing=0)
    with pytest.raises(InvalidInputError, match="radius"):
        metrics.path_metrics(ref, grid=_empty_grid(), reference=ref, radius=-1)
    with pytest.raises(InvalidInputError, match="params"):
        metrics.path_metrics(Line([0, 0], [1, 0]), grid=_empty_grid(), reference=ref, radius=0.1,
                             params=np.zeros(3))  # fmt: skip
    with pytest.raises(InvalidInputError, match="reference"):
        metrics.path_metrics(ref, grid=_empty_grid(), reference=np.ones(3), radius=0.1)
    with pytest.raises(InvalidInputError, match="grid"):
        metrics.path_metrics(ref, grid=None, reference=ref, radius=0.1)


# ---------------------------------------------------------------------- trajectories
class _FakeTrajectory:
    """v(t) = 0.5 t on [0, 2] s, on a circle of radius 2 m."""

    duration = 2.0

    def sample(self, t):
        t = np.asarray(t, dtype=float)
        v = 0.5 * t
        return {
            "t": t,
            "v": v,
            "a": np.full_like(t, 0.5),
            "jerk": np.zeros_like(t),
            "omega": v / 2.0,
            "a_lat": v * v / 2.0,
            "kappa": np.full_like(t, 0.5),
        }


class _FakeRobot:
    v_max, a_max, j_max, omega_max, a_lat_max = 2.0, 0.4, 1.0, 1.0, 1.0


def test_trajectory_metrics_peaks_and_ratios() -> None:
    out = metrics.trajectory_metrics(_FakeTrajectory(), _FakeRobot())
    assert out["duration_s"] == 2.0
    assert out["peak_v_mps"] == pytest.approx(1.0)
    assert out["ratio_v"] == pytest.approx(0.5)
    assert out["peak_a_mps2"] == pytest.approx(0.5) and out["ratio_a"] == pytest.approx(1.25)
    assert out["peak_jerk_mps3"] == 0.0
    assert out["peak_omega_radps"] == pytest.approx(0.5)
    assert out["peak_a_lat_mps2"] == pytest.approx(0.5)
    assert out["limit_a_lat_mps2"] == 1.0
    assert out["within_limits"] is False  # a exceeds a_max


def test_trajectory_metrics_record_without_a_lat_and_missing_limit() -> None:
    class Rec:
        def __init__(self, d):
            self.__dict__.update(d)

    class Traj(_FakeTrajectory):
        def sample(self, t):
            d = super().sample(t)
            del d["a_lat"]
            return Rec(d)

    class Robot:
        v_max, a_max, j_max, omega_max = 2.0, 1.0, 1.0, 1.0
        a_lat_max = None

    out = metrics.trajectory_metrics(Traj(), Robot())
    assert out["peak_a_lat_mps2"] == pytest.approx(0.5)  # v^2 kappa = 1 * 0.5
    assert math.isnan(out["ratio_a_lat"]) and out["within_limits"] is True
    with pytest.raises(InvalidInputError, match="dt"):
        metrics.trajectory_metrics(Traj(), Robot(), dt=0.0)
