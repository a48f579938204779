"""Tests of trajopt.analysis.metrics (``trajopt.metrics``) on hand cases and against brute force / scipy references."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.distance import directed_hausdorff

from astar.grid import OccupancyGrid
from tests.reference import cell_square_clearance
from trajopt.analysis import metrics
from trajopt.analysis._distances import densify
from trajopt.errors import InvalidInputError
from trajopt.geometry._curve import ParametricCurve, PolylineCurve


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


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("border", [False, True])
def test_min_clearance_is_the_minimum_of_point_clearance_exactly(seed, border) -> None:
    # min_clearance evaluates the exact distance for a few points only: its value must be
    # point_clearance(...).min() bit for bit, and match brute force; paths along walls,
    # across cells and outside the map, on sparse, dense and empty grids
    rng = np.random.default_rng(seed)
    density = [0.0, 0.02, 0.15, 0.5, 0.9, 0.15][seed]
    occ = rng.random((30, 25)) < density
    g = OccupancyGrid(occ, 0.05, (-0.3, 0.2))
    walk = np.cumsum(rng.normal(scale=0.02, size=(400, 2)), axis=0) + [0.3, 1.0]
    pts = np.vstack([walk, rng.uniform([-0.5, 0.0], [1.2, 1.9], (50, 2))])
    pc = metrics.point_clearance(pts, g, border_occupied=border)
    mc = metrics.min_clearance(pts, g, border_occupied=border)
    assert mc == pc.min()
    brute = cell_square_clearance(pts, occ, 0.05, (-0.3, 0.2))
    if border:
        edge = np.minimum.reduce(
            [pts[:, 0] + 0.3, 0.95 - pts[:, 0], pts[:, 1] - 0.2, 1.7 - pts[:, 1]]
        )
        brute = np.minimum(brute, np.maximum(edge, 0.0))
    assert mc == pytest.approx(brute.min(), abs=1e-12) or (
        math.isinf(mc) and math.isinf(brute.min())
    )
    for i in range(0, len(pts), 37):  # one point alone: the same value
        assert metrics.min_clearance(pts[i : i + 1], g, border_occupied=border) == pc[i]


def test_clearance_tree_is_kept_per_grid_object_only() -> None:
    # the obstacle tree of an OccupancyGrid is reused; another grid (even with an equal
    # shape) never gets it, and a grid-like object that is not an OccupancyGrid is never
    # cached (its array could change)
    pts = np.array([[0.55, 0.8]])
    a = _one_cell_grid(5, 5)
    b = _one_cell_grid(5, 2)
    assert metrics.min_clearance(pts, a) == pytest.approx(0.2)
    assert metrics.min_clearance(pts, b) == pytest.approx(0.5)
    assert metrics.min_clearance(pts, a) == pytest.approx(0.2)

    class Loose:
        resolution, origin = 0.1, (0.0, 0.0)

        def __init__(self):
            self.occupied = np.zeros((20, 20), bool)

    g = Loose()
    g.occupied[5, 5] = True
    assert metrics.point_clearance(pts, g)[0] == pytest.approx(0.2)
    g.occupied[5, 5], g.occupied[7, 5] = False, True  # square [0.5, 0.6] x [0.7, 0.8]
    assert metrics.point_clearance(pts, g)[0] == pytest.approx(0.0)
    with pytest.raises(InvalidInputError, match="at least one point"):
        metrics.min_clearance(np.empty((0, 2)), a)


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


@pytest.mark.parametrize("seed", range(5))
def test_polyline_hausdorff_is_the_maximum_over_every_densified_point(seed) -> None:
    # the coarse-then-fine filter may skip points, but never one that holds the maximum:
    # the result equals the exact distance of every densified point, maximised, bit for bit
    # (and brute force); a curve near the reference, one far off, and the reference itself
    rng = np.random.default_rng(seed)
    ref = np.cumsum(rng.choice([-1.0, 0.0, 1.0], size=(60, 2)), axis=0) * 0.1
    curve = [
        ref + rng.normal(scale=0.03, size=ref.shape),
        ref + [0.0, 0.5],
        ref.copy(),
        np.c_[np.linspace(-1, 1, 300), np.sin(np.linspace(0, 9, 300))],
        ref[::-1] + rng.normal(scale=0.2, size=ref.shape),
    ][seed]
    spacing = 0.005
    got = metrics.polyline_hausdorff(curve, ref, spacing=spacing)
    want = 0.0
    for a, b in ((curve, ref), (ref, curve)):
        pa = densify(a, spacing)
        exact = metrics.distance_to_polyline(pa, b)
        want = max(want, float(exact.max()))
        seg0, seg = b[:-1], np.diff(b, axis=0)
        dd = np.sum(seg * seg, -1)  # 0 for a repeated vertex
        w = np.sum((pa[:, None] - seg0) * seg, -1)
        t = np.clip(np.divide(w, dd, out=np.zeros_like(w), where=dd > 0), 0, 1)
        brute = np.linalg.norm(pa[:, None] - (seg0 + t[..., None] * seg), axis=-1).min(axis=1)
        np.testing.assert_allclose(exact, brute, atol=1e-12)
    assert got == want


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
        metrics.path_metrics(
            Line([0, 0], [1, 0]), grid=_empty_grid(), reference=ref, radius=0.1, params=np.zeros(3)
        )
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


# ------------------------------------------------------ turns in place (issue 33, part 5)
#: The paper scene's query SP -> A with the robot facing away from the goal at the start and
#: a goal heading the curve does not arrive along: turns in place at both ends.
HEADINGS = (math.pi, -math.pi / 2)


@pytest.fixture(scope="module")
def posed(scene):
    """``(robot, chain)``: a default robot's pose-to-pose plan SP -> A."""
    import trajopt

    planner = trajopt.Planner(scene.grid)
    chain = planner.plan(
        scene.start, scene.goal("A"), start_heading=HEADINGS[0], goal_heading=HEADINGS[1]
    )
    return planner.robot, chain


def _standing_fd(traj, dt: float = 1e-3):
    """Peak |d theta/dt| and |d^2 theta/dt^2| of the standing samples, from theta alone.

    Independent of the samples' ``omega``: first and second differences of the heading
    sampled every ``dt`` over runs where the robot stands (``v == 0``). Both are averages
    of the true rate and acceleration over the stencil, so never above the true peaks.
    """
    t = np.linspace(0.0, traj.duration, int(round(traj.duration / dt)) + 1)
    smp = traj.sample(t)
    h = t[1] - t[0]
    still = np.asarray(smp.v) == 0.0
    theta = np.asarray(smp.theta)
    rate = np.diff(theta) / h
    both = still[1:] & still[:-1]
    acc = np.diff(theta, 2) / h**2
    three = both[1:] & both[:-1]
    return float(np.abs(rate[both]).max()), float(np.abs(acc[three]).max())


def test_chain_turns_are_held_to_the_turn_limits(posed) -> None:
    from tests.reference import turn_limits_by_hand
    from trajopt.motion import TrajectoryChain, TurnInPlace

    robot, chain = posed
    assert isinstance(chain, TrajectoryChain)
    assert [type(p) for p in chain.pieces][0] is TurnInPlace
    assert type(chain.pieces[-1]) is TurnInPlace
    out = metrics.trajectory_metrics(chain, robot)
    assert out["within_limits"] is True, out
    w_lim, alpha_lim, zeta_lim = turn_limits_by_hand(robot)
    assert out["limit_turn_omega_radps"] == pytest.approx(w_lim, rel=1e-12)
    assert out["limit_turn_alpha_radps2"] == pytest.approx(alpha_lim, rel=1e-12)
    assert out["limit_turn_zeta_radps3"] == pytest.approx(zeta_lim, rel=1e-12)
    # the turns of pi and ~2 rad reach the yaw-rate and yaw-acceleration limits: the peaks
    # of the metrics agree with the finite differences of the sampled heading
    rate_fd, acc_fd = _standing_fd(chain)
    assert rate_fd <= w_lim * (1 + 1e-9) and acc_fd <= alpha_lim * (1 + 1e-6)
    assert out["peak_turn_omega_radps"] == pytest.approx(rate_fd, rel=1e-3)
    assert out["peak_turn_alpha_radps2"] == pytest.approx(acc_fd, rel=1e-2)
    assert out["ratio_turn_omega"] == pytest.approx(1.0, rel=1e-3)
    assert out["ratio_turn_alpha"] == pytest.approx(1.0, rel=1e-2)
    # a turn in place has v = 0 and kappa = 0: nothing of the driving rule trips on it
    turn = chain.pieces[0].sample(np.linspace(0.0, chain.pieces[0].duration, 50))
    assert np.all(turn.v == 0) and np.all(turn.kappa == 0) and np.abs(turn.omega).max() > 1
    for key in ("ratio_v", "ratio_a", "ratio_jerk", "ratio_omega", "ratio_a_lat"):
        assert out[key] <= 1 + 1e-6, key


def test_a_turn_beyond_the_turn_limits_is_caught() -> None:
    import trajopt
    from trajopt.motion import TrajectoryChain
    from trajopt.timing import turn_in_place

    fast = trajopt.Robot()  # turns at min(1.5, 0.6 / 0.14) rad/s, 0.5 / 0.14 rad/s^2
    chain = TrajectoryChain((turn_in_place((1.0, 1.0), 0.0, 2.5, fast),), fast)
    assert metrics.trajectory_metrics(chain, fast)["within_limits"] is True
    # the same turn for slower wheels (1 rad/s): within omega_max, beyond the turn's rate
    slow_wheels = trajopt.Robot(wheel_v_max=0.14)
    out = metrics.trajectory_metrics(chain, slow_wheels)
    assert out["ratio_omega"] <= 1.0 and out["ratio_turn_omega"] == pytest.approx(1.5, rel=1e-6)
    assert out["within_limits"] is False
    # a wider track (h = 0.28 m): half the yaw acceleration allowed
    wide = trajopt.Robot(track_width=0.56, wheel_v_max=1.2)
    out = metrics.trajectory_metrics(chain, wide)
    assert out["ratio_turn_omega"] <= 1.0 and out["ratio_turn_alpha"] > 1.9
    assert out["within_limits"] is False

    # a robot without the fields of the turn limits: not checked
    class Bare:
        v_max, a_max, j_max, omega_max, a_lat_max = 1.0, 1.0, 1.0, 1.0, 1.0

    out = metrics.trajectory_metrics(chain, Bare())
    assert math.isnan(out["limit_turn_omega_radps"]) and out["peak_turn_omega_radps"] > 1
    assert out["within_limits"] is False  # omega_max = 1 still holds the turn's 1.5 rad/s


def test_plain_trajectory_and_stop_and_turn(driven) -> None:
    import trajopt
    from tests.reference import turn_limits_by_hand

    planner, traj = driven
    out = metrics.trajectory_metrics(traj, planner.robot)
    assert out["within_limits"] is True
    assert out["peak_turn_omega_radps"] == out["peak_turn_alpha_radps2"] == 0.0
    assert metrics.turns_in_place(traj) == []
    # the stop-and-turn fallback: a turn in place at each of its two corners
    robot = trajopt.Robot()
    sat = trajopt.stop_and_turn([(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)], robot)
    out = metrics.trajectory_metrics(sat, robot)
    assert out["within_limits"] is True
    w_lim, alpha_lim, _ = turn_limits_by_hand(robot)
    rate_fd, acc_fd = _standing_fd(sat)
    assert out["peak_turn_omega_radps"] == pytest.approx(rate_fd, rel=1e-3)
    assert rate_fd <= w_lim * (1 + 1e-9)
    assert acc_fd <= alpha_lim * (1 + 1e-6)
    spans = metrics.turns_in_place(sat)
    assert [(round(s.x, 9), round(s.y, 9)) for s in spans] == [(1.0, 0.0), (1.0, 1.0)]
    assert [s.turn_rad for s in spans] == pytest.approx([math.pi / 2] * 2, abs=1e-5)


def test_turns_in_place_of_a_chain(posed, scene) -> None:
    robot, chain = posed
    spans = metrics.turns_in_place(chain)
    assert len(spans) == 2
    first, last = spans
    assert first.t0 == 0.0 and (first.x, first.y) == pytest.approx(scene.start, abs=1e-12)
    assert (last.x, last.y) == pytest.approx(scene.goal("A"), abs=1e-9)
    assert first.theta0 == pytest.approx(HEADINGS[0], abs=1e-12)
    assert first.turn_rad == pytest.approx(chain.pieces[0].turn_rad, abs=1e-4)
    assert last.t1 == pytest.approx(chain.duration)
    assert math.remainder(last.theta1 - HEADINGS[1], 2 * math.pi) == pytest.approx(0, abs=1e-9)
    assert last.turn_rad == pytest.approx(chain.pieces[-1].turn_rad, abs=1e-4)
    with pytest.raises(InvalidInputError, match="dt"):
        metrics.turns_in_place(chain, dt=0.0)


def test_path_metrics_of_a_chain_score_the_curve_it_drives(posed, scene) -> None:
    robot, chain = posed
    curve = chain.pieces[1].path
    assert metrics.trajectory_path(chain) is curve
    ref = chain.steps.grid_path.to_world(scene.grid)
    kw = dict(grid=scene.grid, reference=ref, radius=robot.radius)
    a = metrics.path_metrics(chain, **kw)
    b = metrics.path_metrics(curve, **kw)
    assert a == b and not a.collision
    assert a.length_m == pytest.approx(chain.length, rel=1e-6)
    # a chain played from the middle of its curve: the polyline of its sampled positions
    rest = chain.after(0.5 * chain.duration)
    line = metrics.trajectory_path(rest)
    assert isinstance(line, PolylineCurve)
    assert line.length == pytest.approx(rest.length, rel=1e-3)
    np.testing.assert_allclose(line.points[-1], np.asarray(scene.goal("A")), atol=1e-9)


def test_omni_orientation_is_held_to_the_turn_limits_everywhere() -> None:
    """An omni base turns while it drives: every sample's yaw is a turn (skip until wired)."""
    import trajopt
    import trajopt.timing
    from tests.reference import turn_limits_by_hand
    from trajopt.geometry._curve import PolylineCurve

    orient = getattr(trajopt.timing, "orient", None)
    if orient is None:
        pytest.skip("trajopt.timing.orient (the omni orientation profile) is not in yet")
    robot = trajopt.Robot(drive="omni")
    line = trajopt.time_parameterize(PolylineCurve(np.array([[0.0, 0.0], [0.6, 0.0]])), robot)
    traj = orient(line, robot, 0.0, 3.0)  # the half turn outlasts the 0.6 m drive
    assert traj.duration > line.duration
    out = metrics.trajectory_metrics(traj, robot)
    assert out["within_limits"] is True, out
    w_lim, alpha_lim, _ = turn_limits_by_hand(robot)
    t = np.linspace(0.0, traj.duration, int(round(traj.duration / 1e-3)) + 1)
    theta = np.asarray(traj.sample(t).theta)
    rate = np.abs(np.diff(theta) / (t[1] - t[0])).max()
    acc = np.abs(np.diff(theta, 2) / (t[1] - t[0]) ** 2).max()
    assert rate <= w_lim * (1 + 1e-9) and acc <= alpha_lim * (1 + 1e-6)
    assert out["peak_turn_omega_radps"] == pytest.approx(rate, rel=1e-3)
    assert out["peak_turn_alpha_radps2"] == pytest.approx(acc, rel=1e-2)
    # while driving too: the same profile against slower wheels is caught
    out = metrics.trajectory_metrics(traj, trajopt.Robot(drive="omni", wheel_v_max=0.07))
    assert out["ratio_turn_omega"] > 1 and out["within_limits"] is False
