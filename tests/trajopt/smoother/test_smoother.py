"""Tests of :mod:`trajopt.smoother` against independent references.

* basis values and the smoothness Gram matrix against scipy's ``BSpline``;
* the unconstrained fit against ``scipy.interpolate.make_lsq_spline`` on the same knots;
* hand-built hard cases (90-degree turn, narrow door, U-turn, wall hugging) checked by
  brute-force dense sampling against the raw map (a KD-tree over occupied squares, not the
  library's certificate code), exact endpoints, continuous heading, curvature bound;
* >= 100 scenarios of the shared Moving AI and ROS maps: zero guarantee violations.
"""

from __future__ import annotations

import math
import time

import numpy as np
import pytest
from scipy.interpolate import BSpline, make_lsq_spline

import trajopt.smoother._basis as smoother_basis
import trajopt.smoother._layout as smoother_layout
import trajopt.smoother._qp as smoother_qp
from astar.grid import OccupancyGrid
from tests.cases import l_shaped_grid
from tests.reference import brute_inflate_square, dijkstra_path, square_clearance
from trajopt.corridor import build_corridor
from trajopt.errors import InvalidInputError, SmoothingError
from trajopt.geometry._bspline import clamped_uniform_knots
from trajopt.smoother import Smoother, SmoothPath
from trajopt.smoother._problem import N_HEADING_ROWS


# ----------------------------------------------------------------- references
def check_guarantees(sp: SmoothPath, raw: OccupancyGrid, radius: float, start, goal, kappa=None):
    """Brute-force checks of every guarantee; returns the sampled minimum clearance.

    The clearance is looked up within ``2 radius + 1 cell`` of the samples: exact up to that
    reach (the check is against ``radius``), and only known to exceed it beyond.
    """
    u0, u1 = sp.domain
    assert np.abs(sp(u0) - start).max() <= 1e-9
    assert np.abs(sp(u1) - goal).max() <= 1e-9
    u = np.linspace(u0, u1, int((u1 - u0) / raw.resolution * 6) + 2)
    clear = square_clearance(raw, sp(u), reach=2.0 * radius + raw.resolution)
    assert clear.min() >= radius - 1e-9, f"clearance {clear.min()} < radius {radius}"
    d1 = sp(u, 1)
    speed = np.hypot(d1[:, 0], d1[:, 1])
    assert speed.min() > 1e-3 * speed.mean()  # no cusp
    dh = np.angle(np.exp(1j * np.diff(np.arctan2(d1[:, 1], d1[:, 0]))))
    assert np.abs(dh).max() < math.pi / 2  # a cusp flips the heading by ~pi
    if kappa is not None:
        assert np.abs(sp.curvature(u)).max() <= kappa * (1 + 1e-6)
    assert sp.certificate is not None and sp.certificate.ok
    return float(clear.min())


def make_case(occ: np.ndarray, r_cells: float, start, goal, res=0.1, origin=(-1.0, 2.0)):
    infl = brute_inflate_square(occ, r_cells)
    raw = OccupancyGrid(occ, res, origin)
    grid = OccupancyGrid(infl, res, origin)
    cells = dijkstra_path(~infl, start, goal)
    corr = build_corridor(grid, cells, radius=r_cells * res)
    return raw, cells, corr


def door_grid() -> np.ndarray:
    occ = np.zeros((24, 30), bool)
    occ[:, 14:16] = True  # a wall
    occ[11:18, 14:16] = False  # a door 7 cells wide: 2 cells left after inflating by 2.5
    return occ


def u_turn_grid() -> np.ndarray:
    occ = np.ones((26, 30), bool)
    occ[2:24, 2:28] = False
    occ[10:16, 2:22] = True  # the tongue the path turns around
    return occ


def wall_grid() -> np.ndarray:
    occ = np.zeros((20, 40), bool)
    occ[9, 5:35] = True  # a thin wall the shortest path runs along
    return occ


HARD_CASES = {
    "turn90": (l_shaped_grid, (5, 6), (23, 24)),
    "door": (door_grid, (4, 4), (26, 20)),
    "u_turn": (u_turn_grid, (5, 19), (5, 6)),
    "wall_hug": (wall_grid, (3, 13), (37, 12)),
}


# ---------------------------------------------------------------------- basis
def test_basis_derivatives_match_scipy():
    rng = np.random.default_rng(1)
    for p in (3, 4, 5):
        n = 14
        inner = np.sort(rng.uniform(0, 10, n - p - 1))
        t = np.concatenate([np.zeros(p + 1), inner, np.full(p + 1, 10.0)])
        u = np.concatenate([rng.uniform(0, 10, 40), [0.0, 10.0]])
        span = smoother_basis.find_spans(t, p, n, u)
        for nu in range(p + 1):
            vals = smoother_basis.basis_derivs(t, p, span, u, nu)
            dense = np.zeros((len(u), n))
            for a in range(p + 1):
                dense[np.arange(len(u)), span + a] = vals[:, a]
            ref = BSpline(t, np.eye(n), p)(u, nu)
            np.testing.assert_allclose(dense, ref, atol=1e-9 * 10.0**nu)


@pytest.mark.parametrize(("nb", "p", "m", "k"), [(12, 3, 0, 2), (20, 3, 4, 2), (9, 5, 2, 8)])
def test_constraint_layout_ccs_order_matches_casadi_and_scipy(nb, p, m, k):
    """The layout's compressed-column order (numpy) is casadi's triplet mapping, and its
    non-zeros in that order rebuild the same matrix as scipy's COO -> CSC conversion."""
    import casadi as ca
    import scipy.sparse as sps

    layout = smoother_layout.constraint_layout(nb, p, m, k)
    rows, cols = layout.trip_rows, layout.trip_cols
    _, mapping = ca.Sparsity.triplet(
        layout.n_rows, layout.n_cols, rows.tolist(), cols.tolist(), False
    )
    np.testing.assert_array_equal(layout.nz_from_triplet, np.asarray(mapping))
    vals = np.random.default_rng(nb).normal(size=layout.n_triplets)
    ref = sps.coo_array((vals, (rows, cols)), shape=(layout.n_rows, layout.n_cols)).tocsc()
    ref.sort_indices()
    np.testing.assert_array_equal(layout.nonzeros(vals), ref.data)
    sp = layout.sparsity  # built on demand, the same pattern
    assert (sp.size1(), sp.size2(), sp.nnz()) == (layout.n_rows, layout.n_cols, ref.nnz)
    np.testing.assert_array_equal(np.asarray(sp.row()), ref.indices)


def _random_scp_qp(rng, nb=20, p=3, m=4):
    """A random strictly convex QP with the SCP's row layout (heading, 45-degree and sample
    rows, one l1-penalised slack per sample)."""
    full = np.zeros((p + 1, nb))
    full[0] = 4.0 + rng.uniform(0, 1, nb)
    full[1:] = rng.uniform(-0.5, 0.5, (p, nb))  # diagonally dominant: positive definite
    g = rng.normal(0, 3, 2 * nb)
    layout = smoother_layout.constraint_layout(nb, p, m)
    S = layout.n_samples
    heading = np.zeros((N_HEADING_ROWS, 2 * nb))
    heading[0, :4] = rng.normal(0, 1, 4)
    vals = rng.normal(0, 1, (S, 3, 2 * (p + 1)))
    lba = np.full(layout.n_rows, -np.inf)
    uba = np.full(layout.n_rows, np.inf)
    lba[0], uba[0] = -1.0, 1.0
    r0 = layout.sample_row0
    lba[N_HEADING_ROWS:r0] = -3.0
    uba[N_HEADING_ROWS:r0] = 3.0
    rows = r0 + 3 * np.arange(S)
    uba[rows] = rng.uniform(-1, 1, S)
    uba[rows + 1] = rng.uniform(-1, 1, S)
    lba[rows + 2] = rng.uniform(-1, 1, S)
    lbx = np.concatenate([np.full(2 * nb, -5.0), np.zeros(S)])
    ubx = np.concatenate([np.full(2 * nb, 5.0), np.full(S, 1e3)])
    return full, g, layout, heading, vals, lba, uba, lbx, ubx


@pytest.mark.parametrize("fraction", [1.0, 0.3])
def test_working_set_qp_matches_a_reference_solver(fraction):
    """The SCP's piqp QP over a working set of samples equals osqp (through casadi, a
    different algorithm and interface) on the same problem with the other samples' rows
    dropped and their slacks fixed at zero."""
    import casadi as ca

    rng = np.random.default_rng(7)
    full, g, layout, heading, vals, lba, uba, lbx, ubx = _random_scp_qp(rng)
    nb, p, S = layout.nb, layout.p, layout.n_samples
    active = rng.uniform(0, 1, S) < fraction
    penalty = 50.0
    trip = layout.values(heading, vals)
    z, cost, ok, status, _ = smoother_qp.solve_working_set(
        full, g, layout, trip, lbx, ubx, lba, uba, active, penalty
    )
    assert ok, status
    # reference: every row, the inactive ones unbounded, their slacks fixed at 0
    lba_r, uba_r, ubx_r = lba.copy(), uba.copy(), ubx.copy()
    off = np.repeat(~active, 3)
    lba_r[layout.sample_row0 :][off] = -np.inf
    uba_r[layout.sample_row0 :][off] = np.inf
    ubx_r[2 * nb :][~active] = 0.0
    ref = ca.conic(
        "ref",
        "osqp",
        {
            "h": smoother_qp.qp_solver(nb, p, "osqp", layout.m, False).sparsity_in("h"),
            "a": layout.sparsity,
        },
        {
            "osqp": {
                "verbose": False,
                "eps_abs": 1e-9,
                "eps_rel": 1e-9,
                "max_iter": 200000,
                "polish": True,
            },
            "print_time": False,
            "error_on_fail": True,
        },
    )
    gg = np.concatenate([g, np.full(S, penalty)])
    out = ref(
        h=ca.DM(ref.sparsity_in("h"), smoother_qp.h_nonzeros(full, nb, p)),
        g=gg,
        a=ca.DM(layout.sparsity, layout.nonzeros(trip)),
        lbx=lbx,
        ubx=ubx_r,
        lba=lba_r,
        uba=uba_r,
    )
    x_ref = np.asarray(out["x"]).ravel()
    np.testing.assert_allclose(cost, float(out["cost"]), rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(z, x_ref[: 2 * nb], atol=1e-4)
    assert int(active.sum()) < S or fraction == 1.0


def test_smoothness_gram_matches_quadrature_of_scipy_derivative():
    rng = np.random.default_rng(2)
    p, n = 3, 10
    t = np.concatenate(
        [np.zeros(p + 1), np.sort(rng.uniform(0, 5, n - p - 1)), np.full(p + 1, 5.0)]
    )
    c = rng.normal(size=n)
    band = smoother_basis.smoothness_band(t, p, n, 2)
    quad = band[0] @ (c * c) + 2 * sum(
        band[d, : n - d] @ (c[: n - d] * c[d:]) for d in range(1, p + 1)
    )
    d2 = BSpline(t, c, p).derivative(2)
    fine = np.linspace(0, 5, 200_001)
    ref = np.trapezoid(d2(fine) ** 2, fine)
    assert quad == pytest.approx(ref, rel=1e-6)


# --------------------------------------------------------- independent reference
@pytest.mark.parametrize("solver", ["osqp", "piqp"])
def test_unconstrained_fit_equals_make_lsq_spline(solver):
    rng = np.random.default_rng(3)
    u = np.sort(rng.uniform(0, 20, 60))
    u[0], u[-1] = 0.0, 20.0
    pts = np.column_stack([np.cos(u / 3) * 5, np.sin(u / 4) * 3]) + rng.normal(0, 0.1, (60, 2))
    p = 3
    t = np.concatenate([np.zeros(p + 1), np.linspace(0, 20, 9)[1:-1], np.full(p + 1, 20.0)])
    ref = make_lsq_spline(u, pts, t, k=p)
    got = Smoother(smoothness_weight=0.0, qp_solver=solver).fit_free(pts, u, t)
    np.testing.assert_allclose(got.c, ref.c, atol=1e-5)
    ug = np.linspace(0, 20, 101)
    np.testing.assert_allclose(got(ug), ref(ug), atol=1e-5)


# ------------------------------------------------------------------ hard cases
@pytest.mark.parametrize("name", sorted(HARD_CASES))
def test_hard_cases_keep_every_guarantee(name):
    make, s, g = HARD_CASES[name]
    raw, cells, corr = make_case(make(), 2.5, s, g)
    sp = Smoother().fit(cells, corr, raw_grid=raw)
    start, goal = corr.path_points[0], corr.path_points[-1]
    check_guarantees(sp, raw, 0.25, start, goal)
    assert sp.stats["success"] and sp.stats["attempts"] >= 1
    assert sp.certificate.min_clearance_m >= 0.25 - 1e-9
    # the fit follows the path: the curve's length is close to the A* polyline's
    assert 0.7 * corr.length_m < sp.length < 1.1 * corr.length_m


def test_headings_are_exact_and_endpoints_can_be_moved():
    raw, cells, corr = make_case(l_shaped_grid(), 2.5, (5, 6), (23, 24))
    start = corr.path_points[0] + [0.02, -0.01]
    sp = Smoother().fit(
        cells, corr, raw_grid=raw, start=start, start_heading=0.3, goal_heading=math.pi / 2
    )
    u0, u1 = sp.domain
    assert sp.heading(u0) == pytest.approx(0.3, abs=1e-9)
    assert sp.heading(u1) == pytest.approx(math.pi / 2, abs=1e-9)
    check_guarantees(sp, raw, 0.25, start, corr.path_points[-1])


@pytest.mark.parametrize("method", ["scp", "ipopt"])
def test_curvature_bound_holds_on_dense_samples(method):
    raw, cells, corr = make_case(l_shaped_grid(), 2.5, (5, 6), (23, 24))
    kappa = 1 / (2 * 0.25)
    sp = Smoother(kappa_max=kappa, curvature_solver=method, time_budget_s=120).fit(
        cells, corr, raw_grid=raw
    )
    check_guarantees(sp, raw, 0.25, corr.path_points[0], corr.path_points[-1], kappa=kappa)
    assert sp.stats["solver"].endswith("+" + method)
    # the QP alone is sharper than the bound here, so the bound did something
    plain = Smoother().fit(cells, corr, raw_grid=raw)
    assert plain.certificate.kappa_max_sampled > kappa


def test_failure_is_typed_and_carries_stats():
    raw, cells, corr = make_case(l_shaped_grid(), 2.5, (5, 6), (23, 24))
    with pytest.raises(SmoothingError) as info:
        Smoother(time_budget_s=1e-12).fit(cells, corr, raw_grid=raw)
    assert info.value.stats["success"] is False
    assert "attempts" in info.value.stats


def test_option_and_input_validation():
    with pytest.raises(InvalidInputError, match="degree"):
        Smoother(degree=6)
    with pytest.raises(InvalidInputError, match="qp_solver"):
        Smoother(qp_solver="gurobi")  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="smoothness_order"):
        Smoother(degree=3, smoothness_order=3)
    with pytest.raises(InvalidInputError, match="kappa_max"):
        Smoother(kappa_max=-1.0)
    raw, cells, corr = make_case(l_shaped_grid(), 2.5, (5, 6), (23, 24))
    with pytest.raises(InvalidInputError, match="start"):
        Smoother().fit(cells, corr, start=(100.0, 100.0))
    with pytest.raises(InvalidInputError, match="must match"):
        Smoother().fit(cells[:-1], corr)


def test_higher_degrees_also_certified():
    raw, cells, corr = make_case(u_turn_grid(), 2.5, (5, 19), (5, 6))
    for sm in (Smoother(degree=4), Smoother(degree=5), Smoother(degree=5, smoothness_order=3)):
        sp = sm.fit(cells, corr, raw_grid=raw)
        check_guarantees(sp, raw, 0.25, corr.path_points[0], corr.path_points[-1])


# ------------------------------------------------------------------- real maps
def _map_scenarios(shared_data, per_map: int, seed: int = 0):
    """(raw, inflated, radius_m, path) on the shared maps: Moving AI scenarios (radius 2.5
    cells) and random free pairs on the ROS maps (radius 0.2 m), reachable ones only."""
    import astar

    rng = np.random.default_rng(seed)
    maps = []
    for name in ["arena", "den312d", "Berlin_0_256", "rmtst01"]:
        raw = astar.load_map(shared_data / "movingai" / "maps" / f"{name}.map")
        scen = astar.read_scenarios(shared_data / "movingai" / "scen" / f"{name}.map.scen")
        pairs = [(tuple(s.start), tuple(s.goal)) for s in scen if 20 <= s.optimal_length <= 200]
        maps.append((raw, 2.5 * raw.resolution, [pairs[i] for i in rng.permutation(len(pairs))]))
    for name in ["turtlebot3_world", "smoothers_world", "depot"]:
        raw = astar.load_map(shared_data / "ros" / f"{name}.yaml")
        maps.append((raw, 0.2, None))
    out = []
    for raw, r, pairs in maps:
        infl = astar.inflate(raw, r, metric="square", outside_occupied=True)
        ys, xs = np.nonzero(~infl.occupied)
        got = 0
        for k in range(per_map * 100):
            if pairs is not None and k < len(pairs):
                a, b = pairs[k]  # the benchmark's own scenarios first, then random pairs
            else:
                i, j = rng.choice(len(xs), 2, replace=False)
                a, b = (int(xs[i]), int(ys[i])), (int(xs[j]), int(ys[j]))
            if infl.occupied[a[1], a[0]] or infl.occupied[b[1], b[0]]:
                continue
            if not 10 <= math.hypot(a[0] - b[0], a[1] - b[1]) <= 150:
                continue
            try:
                path = astar.find_path(infl, a, b)
            except astar.NoPathError:
                continue
            out.append((raw, infl, r, path))
            got += 1
            if got == per_map:
                break
    return out


def test_shared_maps_zero_guarantee_violations(shared_data):
    # 105 shortest-path scenarios (the hardest seed: paths hug the walls)
    cases = _map_scenarios(shared_data, per_map=15)
    sm = Smoother()
    done = errors = violations_plain = 0
    t0 = time.perf_counter()
    for raw, infl, r, path in cases:
        corr = build_corridor(infl, path, radius=r, raw_grid=raw)
        try:
            sp = sm.fit(path, corr, raw_grid=raw)
        except SmoothingError:
            errors += 1
            continue
        check_guarantees(sp, raw, r, corr.path_points[0], corr.path_points[-1])
        done += 1
        # the plain least-squares spline on the same points (uniform knots, same number of
        # control points), for comparison: it has no clearance guarantee
        n = len(sp.control_points)
        t = clamped_uniform_knots(min(n, len(corr.path_s) - 1), 3, (0.0, corr.length_m))
        plain = make_lsq_spline(corr.path_s, corr.path_points, t, k=3)
        uu = np.linspace(0, corr.length_m, int(corr.length_m / raw.resolution * 4) + 2)
        xy = plain(uu)
        reach = 2.0 * r + raw.resolution  # exact up to the reach; the check is against r
        if not np.all(np.isfinite(xy)) or square_clearance(raw, xy, reach).min() < r - 1e-9:
            violations_plain += 1
    print(
        f"\nshared maps: {len(cases)} cases, {done} certified, {errors} SmoothingError, plain "
        f"lsq fit violated clearance on {violations_plain}/{done} "
        f"({time.perf_counter() - t0:.1f} s)"
    )
    assert len(cases) >= 100
    assert errors <= 0.03 * len(cases)
    assert done + errors == len(cases)


def test_curvature_excess_between_samples_is_retried_on_the_same_knots(shared_data):
    # den312d, radius 2.5 cells, kappa_max = 1/(2r), clearance-aware A* path: the first SCP
    # solution holds the bound at its samples but breaks it between them (the certificate's
    # dense check); the retry keeps the knots, tightens the sampled bound by the excess
    # found and is certified, instead of refining to a problem twice the size
    import astar

    raw = astar.load_map(shared_data / "movingai" / "maps" / "den312d.map")
    r = 2.5 * raw.resolution
    kappa = 1.0 / (2.0 * r)
    infl = astar.inflate(raw, r, metric="square", outside_occupied=True)
    cost = astar.clearance_cost(raw, r, outside_occupied=True)
    path = astar.find_path(infl, (21, 76), (27, 49), cost=cost)
    corr = build_corridor(infl, path, radius=r, raw_grid=raw)
    sp = Smoother(kappa_max=kappa, time_budget_s=30).fit(path, corr, raw_grid=raw, radius=r)
    check_guarantees(sp, raw, r, corr.path_points[0], corr.path_points[-1], kappa=kappa)
    log = sp.stats["attempt_log"]
    if log[0].get("certificate_ok", False) or len(log) < 2:
        pytest.skip("the first attempt is now certified: no retry to test here")
    assert log[0]["failure"] == "certificate: curvature_bound"
    assert log[1]["span_cells"] == log[0]["span_cells"]
    assert log[1]["n_control_points"] == log[0]["n_control_points"]
    assert 0 < log[1]["kappa_margin"] < Smoother().kappa_margin
    assert log[1]["qp"]["solver"] == "warm"


def test_paper_scene_targets_certified():
    import astar
    from trajopt.analysis import scenes

    sc = scenes.paper()
    r = sc.robot_width / 2
    infl = astar.inflate(sc.grid, r, metric="square", outside_occupied=True)
    for target in "ABCD":
        path = astar.find_path(infl, sc.start_cell, sc.goal_cell(target))
        corr = build_corridor(infl, path, radius=r)
        sp = Smoother().fit(path, corr, raw_grid=sc.grid)
        check_guarantees(sp, sc.grid, r, corr.path_points[0], corr.path_points[-1])
