"""Tests of trajopt.smoother: IPOPT on the general constraint layout: polygon corridors, against piqp as the reference.

The convex corridor QP solved by IPOPT must reach piqp's optimum (the same objective value
and control points within solver tolerance); the exact curvature-bounded NLP must hold its
bound on dense samples (three-point curvature, no curve evaluation of its own); end
headings hold; an IPOPT failure is a typed error carrying IPOPT's status. With a cost field,
IPOPT's exact cost term reaches an objective no higher than the QP rounds' (piqp, an
independent solver) and keeps the curve out of a high-cost band (dense nearest-cell costs);
its cost spline matches the field at the cell centres, CasADi's own bspline interpolant
between them, and central differences; the IPOPT polish (``refine="ipopt"``) never raises
the objective and keeps the certificate and the end headings.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import astar
import trajopt
from tests.cases import L_HALL_END as HALL_GOAL
from tests.cases import L_HALL_RES as RES
from tests.cases import L_HALL_START as HALL_START
from tests.cases import l_hall, square_inflated
from tests.reference import (
    dense_mean_cost,
    footprint_collides,
    square_clearance,
    three_point_curvature,
)
from trajopt.analysis import scenes
from trajopt.analysis.bench._suites import random_queries
from trajopt.corridor import build_polygon_corridor
from trajopt.errors import InvalidInputError, SmoothingError
from trajopt.smoother import Smoother, _layout, _nlp, _nlp_cost, _qp
from trajopt.smoother._attempts import solve_attempt
from trajopt.smoother._cost import CostTerm, cost_field
from trajopt.smoother._nlp_solve import on_window
from trajopt.smoother._problem import assemble, build_problem
from trajopt.smoother._status import AttemptRecord


def _paper_corridor(target: str):
    scene = scenes.paper()
    grid, r = scene.grid, scene.robot_radius
    path = astar.find_path(square_inflated(grid, r), scene.start_cell, scene.goal_cell(target))
    return scene, grid, r, build_polygon_corridor(grid, path, r)


def _qp_of(options: Smoother, corr, **ends):
    prob, _, _ = build_problem(options, None, corr, start=None, goal=None, hs=None, hg=None, **ends)
    return assemble(options, prob, float(options.span_cells))


def _dense_kappa(curve, n: int = 6000) -> float:
    u = np.linspace(*curve.domain, n)
    return float(three_point_curvature(curve(u)).max())


@pytest.mark.parametrize("target", ["A", "B", "C", "D"])
def test_ipopt_qp_reaches_piqps_optimum_on_polygons(target):
    _, _, _, corr = _paper_corridor(target)
    asm = _qp_of(Smoother(), corr)
    qp = asm.qp
    assert qp.region_coef is not None  # the polygon layout, not the box one
    ref = _qp.solve_qp(Smoother(qp_solver="piqp"), qp, x0=asm.x0)
    got = _qp.solve_qp(Smoother(qp_solver="ipopt"), qp, x0=asm.x0)
    assert ref.success and got.success and got.solver == "ipopt"
    assert got.cost == pytest.approx(ref.cost, rel=1e-7, abs=1e-7)
    np.testing.assert_allclose(got.z, ref.z, atol=1e-4)  # cells
    # IPOPT's point is feasible for every region row (to its tolerance)
    layout = _layout.constraint_layout(qp.nb, 3, 0, qp.k)
    trip = layout.values(qp.heading, None, qp.region_coef)
    az = np.bincount(
        layout.trip_rows, weights=trip * got.z[layout.trip_cols], minlength=layout.n_rows
    )
    assert np.all(az >= qp.lba - 1e-7) and np.all(az <= qp.uba + 1e-7)


@pytest.mark.parametrize("name", ["turtlebot3_world", "depot"])
def test_ipopt_plan_matches_piqp_plan_on_a_ros_map(shared_data, name):
    path = shared_data / "ros" / f"{name}.yaml"
    raw = astar.load_map(path)
    robot = trajopt.Robot(radius=0.165)
    q = random_queries(path, 1, seed=3, radius_m=0.165).queries[0]
    p0, p1 = raw.cell_to_world(np.array(q.start)), raw.cell_to_world(np.array(q.goal))
    out = {
        s: trajopt.plan(raw, p0, p1, robot, smoother=Smoother(qp_solver=s))
        for s in ("piqp", "ipopt")
    }
    assert out["ipopt"].stats["corridor"] == "polygons"
    a, b = (out[s].steps.smooth_path for s in ("piqp", "ipopt"))
    assert a.certificate.ok and b.certificate.ok
    assert b.stats["solver"] == "ipopt" and b.stats["attempts"] == a.stats["attempts"]
    assert b.stats["cost"] == pytest.approx(a.stats["cost"], rel=1e-7)
    np.testing.assert_allclose(b.curve.control_points, a.curve.control_points, atol=1e-5)
    assert out["ipopt"].duration == pytest.approx(out["piqp"].duration, rel=1e-4)


def test_plan_with_ipopt_qp_on_polygon_corridors():
    scene = scenes.paper()
    robot = trajopt.Robot(radius=scene.robot_radius)
    ref = trajopt.plan(scene.grid, scene.start, scene.goal("B"), robot)
    traj = trajopt.plan(
        scene.grid, scene.start, scene.goal("B"), robot, smoother=Smoother(qp_solver="ipopt")
    )
    sp = traj.steps.smooth_path
    assert traj.stats["corridor"] == "polygons"
    assert sp.certificate.ok and sp.stats["solver"] == "ipopt"
    assert traj.duration == pytest.approx(ref.duration, rel=1e-3)
    u = np.linspace(*sp.domain, 4000)
    assert square_clearance(scene.grid, sp(u)).min() >= scene.robot_radius - 1e-9


@pytest.mark.parametrize("target", ["A", "C"])
def test_plan_with_ipopt_curvature_bound_on_polygon_corridors(target):
    scene = scenes.paper()
    r = scene.robot_radius
    kmax = 1.0 / (2.0 * r)
    traj = trajopt.plan(
        scene.grid,
        scene.start,
        scene.goal(target),
        trajopt.Robot(radius=r),
        smoother=Smoother(kappa_max=kmax, curvature_solver="ipopt"),
    )
    sp = traj.steps.smooth_path
    assert traj.stats["corridor"] == "polygons"
    assert sp.certificate.ok and sp.stats["solver"].endswith("+ipopt")
    assert _dense_kappa(sp.curve) <= kmax * (1 + 1e-3)
    u = np.linspace(*sp.domain, 4000)
    assert square_clearance(scene.grid, sp(u)).min() >= r - 1e-9


def test_ipopt_curvature_nlp_binds_where_the_qp_is_sharper():
    # a tight bound that the QP's curve breaks: IPOPT bends it within the bound
    _, grid, r, corr = _paper_corridor("A")
    plain = Smoother().fit(None, corr, raw_grid=grid, radius=r)
    kmax = 0.8 * _dense_kappa(plain.curve)
    sp = Smoother(kappa_max=kmax, curvature_solver="ipopt").fit(None, corr, raw_grid=grid, radius=r)
    assert sp.certificate.ok and sp.stats["solver"].endswith("+ipopt")
    assert _dense_kappa(sp.curve) <= kmax * (1 + 1e-3)
    scp = Smoother(kappa_max=kmax).fit(None, corr, raw_grid=grid, radius=r)
    # the exact NLP is no worse than the SCP's convexified one on the same objective
    assert sp.stats["cost"] <= scp.stats["cost"] * (1 + 1e-3)


@pytest.mark.parametrize("options", [{"qp_solver": "ipopt"}, {"curvature_solver": "ipopt"}])
def test_end_headings_with_ipopt(options):
    scene, grid, r, corr = _paper_corridor("B")
    start, goal = np.array(scene.start), np.array(scene.goal("B"))
    kw = {"kappa_max": 1.0 / (2.0 * r)} if "curvature_solver" in options else {}
    sp = Smoother(**options, **kw).fit(
        None,
        corr,
        raw_grid=grid,
        radius=r,
        start=start,
        goal=goal,
        start_heading=1.2,
        goal_heading=0.5,
    )
    assert sp.certificate.ok and "ipopt" in sp.stats["solver"]
    h = sp.heading(np.array(sp.domain))
    np.testing.assert_allclose(np.angle(np.exp(1j * (h - [1.2, 0.5]))), 0.0, atol=1e-9)
    np.testing.assert_allclose(sp.curve(np.array(sp.domain)), [start, goal], atol=1e-12)


def test_ipopt_failure_is_typed_with_its_status(monkeypatch):
    # IPOPT allowed one iteration: every attempt fails, and the error says IPOPT's status
    _, grid, r, corr = _paper_corridor("A")
    opts = _nlp._ipopt_opts(False)
    opts["ipopt"] = dict(opts["ipopt"], max_iter=1)
    monkeypatch.setattr(_nlp, "_ipopt_opts", lambda verbose: opts)
    build = _nlp.qp_ipopt.__wrapped__  # uncached: a fresh solver with these options
    monkeypatch.setattr(_qp, "qp_ipopt", lambda nb, p, k, verbose: build(nb, p, k, verbose))
    with pytest.raises(SmoothingError, match="IPOPT status 'Maximum_Iterations_Exceeded'") as ei:
        Smoother(qp_solver="ipopt", max_attempts=1).fit(None, corr, raw_grid=grid, radius=r)
    st = ei.value.stats
    assert st["success"] is False and st["solver"] == "ipopt"
    assert st["status"] == "Maximum_Iterations_Exceeded" and st["iterations"] == 1


def test_ipopt_curvature_failure_is_not_a_qp_result(monkeypatch):
    # the curvature NLP fails: the attempt fails (no QP curve passed off as IPOPT's)
    _, _, r, corr = _paper_corridor("A")
    opts = _nlp._ipopt_opts(False)
    opts["ipopt"] = dict(opts["ipopt"], max_iter=0)
    monkeypatch.setattr(_nlp, "_ipopt_opts", lambda verbose: opts)
    build = _nlp.curvature_nlp.__wrapped__  # uncached: a fresh solver with these options
    monkeypatch.setattr(_nlp, "curvature_nlp", lambda nb, p, k, v: build(nb, p, k, v))
    options = Smoother(kappa_max=0.5 / r, curvature_solver="ipopt")
    asm_prob, _, _ = build_problem(options, None, corr, start=None, goal=None, hs=None, hg=None)
    rec = AttemptRecord(attempt=1, span_cells=float(options.span_cells))
    with pytest.raises(Exception, match="curvature bound \\(ipopt\\): IPOPT status") as ei:
        solve_attempt(options, asm_prob, float(options.span_cells), 60.0, 1.0, None, rec)
    assert type(ei.value).__name__ == "AttemptFailed"
    assert rec.nlp is not None and rec.nlp.solver == "ipopt" and not rec.nlp.success
    assert math.isfinite(rec.nlp.solve_time_s)


# --- the cost term in the IPOPT problem, and the IPOPT polish (refine="ipopt") ---------------


def _hall_attempt(options: Smoother, cost_at, h: float = 4.0):
    """One attempt of ``options`` in the L hall of test_cost: (control points, record, prob)."""
    _, _, corridor = l_hall()
    prob, _, _ = build_problem(
        options, None, corridor, start=HALL_START, goal=HALL_GOAL, hs=None, hg=None
    )
    rec = AttemptRecord(attempt=1, span_cells=h)
    c, t, _ = solve_attempt(options, prob, h, 60.0, options.kappa_margin, None, rec, cost_at)
    return c, t, rec, prob


@pytest.mark.parametrize("kappa_max", [None, 2.0])
def test_cost_ipopt_no_worse_than_the_rounds_and_out_of_the_band(kappa_max):
    """IPOPT on the exact cost term: an objective no higher than the QP rounds' (its own
    objective, at both points), and, like them, a curve out of the high-cost band."""
    grid, cost, corridor = l_hall()
    field = cost_field(cost, 2.0, grid)
    cost_at = (field, np.asarray(corridor.origin, dtype=float))
    rounds = Smoother(kappa_max=kappa_max)
    fast = {"qp_solver": "ipopt"} if kappa_max is None else {"curvature_solver": "ipopt"}
    exact = Smoother(kappa_max=kappa_max, **fast)
    c_r, t, rec_r, prob = _hall_attempt(rounds, cost_at)
    c_i, t_i, rec_i, _ = _hall_attempt(exact, cost_at)
    np.testing.assert_array_equal(t, t_i)
    assert rec_i.nlp is not None and rec_i.nlp.solver == "ipopt" and rec_i.nlp.success
    assert rec_i.cost_rounds["rounds"] == 0  # no QP rounds: IPOPT minimised the term
    # the objective IPOPT minimised, at the rounds' result (same knots, same problem)
    asm = assemble(exact, prob, 4.0)
    qp = asm.qp
    z = np.zeros(2 * qp.nb)
    z[: qp.n], z[qp.nb : qp.nb + qp.n] = c_r[:, 0], c_r[:, 1]
    term = CostTerm.on_knots(field, cost_at[1], RES, t, 3, qp.nb, rec_scale(rounds, prob))
    kw = {} if kappa_max is None else {"kmax": kappa_max * RES, "margin": exact.kappa_margin}
    _, f_rounds = _nlp.solve_nlp(exact, qp, t, z, 60.0, cost=on_window(term, prob), **kw)
    assert rec_i.nlp.cost <= f_rounds + 1e-6 * abs(f_rounds)
    # both fits: certified and out of the band (dense nearest-cell cost, no interpolation)
    kw = dict(raw_grid=grid, radius=0.2, start=HALL_START, goal=HALL_GOAL)
    blind = rounds.fit(None, corridor, **kw)
    sp = exact.fit(None, corridor, cost=cost, cost_weight=2.0, **kw)
    assert sp.certificate.ok and "ipopt" in sp.stats["solver"]
    assert dense_mean_cost(sp.curve, cost, grid) < 0.25 * dense_mean_cost(blind.curve, cost, grid)
    if kappa_max is not None:
        assert _dense_kappa(sp.curve) <= kappa_max * (1 + 1e-3)


def rec_scale(options: Smoother, prob) -> float:
    """``s`` of the cost term as the attempt built it (CostTerm.on_knots's ``scale``)."""
    from trajopt.smoother import _cost

    if hasattr(_cost, "cost_scale"):
        return _cost.cost_scale(options, prob.taut)
    return 2.0 * options.taut_length_weight if prob.taut else 1.0


def test_cost_spline_interpolates_the_field_and_its_gradient():
    """The problem's cost spline: the field's values at cell centres (CostField.at), CasADi's
    own bspline interpolant between them, and its gradient against central differences."""
    import casadi as ca

    grid, cost, corridor = l_hall()
    rough = np.clip(cost + 0.3 * np.sin(np.arange(cost.size).reshape(cost.shape)), 0, 1)
    field = cost_field(rough, 1.0, grid)
    win = _nlp_cost.window(field, np.array([10.0, 10.0]), np.array([60.0, 60.0]))
    f = _nlp_cost.spline_function(win)
    wx, wy = win.shape
    # cell centres: the (smoothed) cell values, as CostField.at gives them there
    rng = np.random.default_rng(5)
    ij = np.column_stack([rng.integers(2, wx - 2, 40), rng.integers(2, wy - 2, 40)])
    cells = ij + np.asarray(win.cell0)
    ok = (cells[:, 0] < field.cost.shape[1]) & (cells[:, 1] < field.cost.shape[0])
    world = field.origin + field.resolution * (cells[ok] + 0.5)
    at, _ = field.at(world)
    got = np.array([float(f(p)) for p in ij[ok].astype(float)])
    np.testing.assert_allclose(got, at, atol=1e-12)
    # between the centres: CasADi's interpolant of the same values (its own coefficients)
    vals = _nlp_cost.window_values(field.cost, win.shape, win.cell0)
    ref = ca.interpolant(
        "ref",
        "bspline",
        [np.arange(wx, dtype=float), np.arange(wy, dtype=float)],
        vals.ravel(order="F"),
    )
    pts = rng.uniform(2.0, min(wx, wy) - 3.0, (40, 2)) + rng.uniform(0.2, 0.8, (40, 2))
    pts = np.floor(pts) + rng.uniform(0.2, 0.8, (40, 2))  # away from the cell boundaries
    np.testing.assert_allclose([float(f(p)) for p in pts], [float(ref(p)) for p in pts], atol=1e-9)
    # its gradient (CasADi AD, what IPOPT uses) against central differences
    xy = ca.MX.sym("xy", 2)
    grad = ca.Function("g", [xy], [ca.gradient(f(xy), xy)])
    eps = 1e-6
    for p in pts[:10]:
        fd = [
            (float(f(p + e)) - float(f(p - e))) / (2 * eps)
            for e in (np.array([eps, 0]), np.array([0, eps]))
        ]
        np.testing.assert_allclose(np.asarray(grad(p)).ravel(), fd, atol=1e-6)


def test_cost_window_of_a_large_field_covers_the_corridor_and_clamps():
    """A field above WHOLE_FIELD_CELLS: a window around the box, edge cells repeated."""
    big = np.zeros((8, 2 * _nlp_cost.WHOLE_FIELD_CELLS // 8 + 8))
    big[:, -1] = 1.0
    grid = astar.OccupancyGrid(np.zeros(big.shape, bool), 0.05)
    field = cost_field(big, 1.0, grid)
    nx = big.shape[1]
    win = _nlp_cost.window(field, np.array([nx - 20.0, 2.0]), np.array([nx - 3.0, 5.0]))
    assert win.shape[0] % _nlp_cost.WINDOW_BUCKET == 0 and win.shape[0] < nx
    lo = np.asarray(win.cell0)
    assert lo[0] <= nx - 20 - _nlp_cost.WINDOW_MARGIN
    assert lo[0] + win.shape[0] - 1 >= nx - 3 + _nlp_cost.WINDOW_MARGIN
    vals = _nlp_cost.window_values(field.cost, win.shape, win.cell0)
    np.testing.assert_array_equal(vals[:, 0], vals[:, 1])  # rows below the map: row 0
    assert _nlp_cost.window(field, np.array([nx - 20.0, 2.0]), np.array([nx - 3.0, 5.0])) is win


@pytest.mark.parametrize(
    "options",
    [{}, {"kappa_max": 2.0}],
    ids=["qp-rounds", "scp-rounds"],
)
def test_refine_never_raises_the_objective_and_keeps_the_certificate(options):
    grid, cost, corridor = l_hall()
    kw = dict(raw_grid=grid, radius=0.2, start=HALL_START, goal=HALL_GOAL)
    for extra in ({}, {"cost": cost, "cost_weight": 2.0}):
        fast = Smoother(**options).fit(None, corridor, **kw, **extra)
        sp = Smoother(refine="ipopt", **options).fit(None, corridor, **kw, **extra)
        st = sp.stats["refine"]
        assert st["status"] in ("improved", "not better", "failed", "not certified")
        assert sp.certificate.ok
        # the same knots: the polish starts from the fast result, whose objective it reports
        assert sp.stats["n_control_points"] == fast.stats["n_control_points"]
        if st["kept"]:
            assert st["status"] == "improved"
            assert st["objective_after"] <= st["objective_before"]
            if not extra:  # no cost term: stats["cost"] is the whole objective
                assert sp.stats["cost"] <= fast.stats["cost"] + 1e-9 * abs(fast.stats["cost"])
        else:
            np.testing.assert_array_equal(sp.curve.control_points, fast.curve.control_points)
        if "kappa_max" in options:
            assert _dense_kappa(sp.curve) <= options["kappa_max"] * (1 + 1e-3)


def test_refine_is_skipped_when_ipopt_solved_the_whole_problem():
    _, grid, r, corr = _paper_corridor("B")
    sp = Smoother(qp_solver="ipopt", refine="ipopt").fit(None, corr, raw_grid=grid, radius=r)
    assert sp.stats["refine"]["status"] == "skipped" and not sp.stats["refine"]["kept"]


def test_end_headings_hold_with_refine():
    scene, grid, r, corr = _paper_corridor("B")
    start, goal = np.array(scene.start), np.array(scene.goal("B"))
    sp = Smoother(kappa_max=1.0 / (2.0 * r), refine="ipopt").fit(
        None,
        corr,
        raw_grid=grid,
        radius=r,
        start=start,
        goal=goal,
        start_heading=1.2,
        goal_heading=0.5,
    )
    assert sp.certificate.ok and sp.stats["refine"]["status"] != "skipped"
    h = sp.heading(np.array(sp.domain))
    np.testing.assert_allclose(np.angle(np.exp(1j * (h - [1.2, 0.5]))), 0.0, atol=1e-9)
    np.testing.assert_allclose(sp.curve(np.array(sp.domain)), [start, goal], atol=1e-12)


@pytest.mark.parametrize("value", ["IPOPT", "scp", "piqp", True, 1, ""])
def test_bad_refine_values_are_typed_errors(value):
    with pytest.raises(InvalidInputError, match=r"refine must be one of \(None, 'ipopt'\)"):
        Smoother(refine=value)


def _short_halls(width: float = 0.56, res: float = 0.02, n: int = 120):
    """Two halls of ``width`` (m) at a right angle, shorter than test_footprint_rounds'."""
    occ = np.ones((n, n), bool)
    w, e = int(round(width / res)), n - 20
    occ[20 : 20 + w, 20:e] = False
    occ[20:e, e - w : e] = False
    return astar.OccupancyGrid(occ, res), (0.9, (20 + w / 2) * res), ((e - w / 2) * res, 1.64)


@pytest.mark.parametrize("options", [{"qp_solver": "ipopt"}, {"refine": "ipopt"}])
def test_footprint_with_ipopt(options):
    """A rectangle turning between two halls: the footprint rounds (QP footprint SCP, end
    headings pinned) with IPOPT's QP or the polish; every pose clear on dense samples."""
    robot = trajopt.Robot.rectangle(0.7, 0.4)
    grid, s, g = _short_halls()
    traj = trajopt.Planner(grid, robot, smoother=Smoother(**options)).plan(s, g)
    st = traj.steps.smooth_path.stats
    assert traj.stats["footprint"]["rejected"] == []
    if "qp_solver" in options:
        assert st["solver"] == "ipopt"
    else:
        assert st["refine"]["status"] in ("improved", "not better", "not certified", "skipped")
    smp = traj.sample(np.linspace(0.0, traj.duration, 3000))
    assert not footprint_collides(grid, robot.footprint, smp.x, smp.y, smp.theta)


def test_nlp_cost_term_matches_a_dense_integral_off_the_origin():
    """The IPOPT problem's cost term (its objective with the term less without) at a curve,
    on a map whose origin is not (0, 0), against a dense trapezoid of ``s w cost |C'|`` with
    scipy's FITPACK interpolating bicubic spline of the same smoothed cells."""
    from scipy.interpolate import BSpline, RectBivariateSpline

    grid0, cost, _ = l_hall()
    origin = (-3.2, 1.7)
    grid = astar.OccupancyGrid(~grid0.free, RES, origin)
    shift = np.asarray(origin)
    pts = np.vstack(
        [np.linspace(HALL_START, (2.9, 1.1), 40), np.linspace((2.9, 1.1), HALL_GOAL, 40)[1:]]
    )
    corridor = build_polygon_corridor(grid, pts + shift, 0.2)
    options = Smoother(qp_solver="ipopt")
    ends = {"start": np.add(HALL_START, shift), "goal": np.add(HALL_GOAL, shift)}
    prob, _, _ = build_problem(options, None, corridor, hs=None, hg=None, **ends)
    asm = assemble(options, prob, 4.0)
    qp = asm.qp
    z = _qp.solve_qp(Smoother(), qp, x0=asm.x0).z
    field = cost_field(cost, 2.0, grid)
    scale = rec_scale(options, prob)
    term = CostTerm.on_knots(field, np.asarray(corridor.origin), RES, asm.knots, 3, qp.nb, scale)
    _, with_cost = _nlp.solve_nlp(options, qp, asm.knots, z, 60.0, cost=on_window(term, prob))
    _, without = _nlp.solve_nlp(options, qp, asm.knots, z, 60.0)
    # the reference: the curve in metres, the field on cell centres in metres
    c = np.column_stack([z[: qp.n], z[qp.nb : qp.nb + qp.n]]) * RES + np.asarray(corridor.origin)
    curve = BSpline(asm.knots * RES, c, 3)
    ny, nx = field.cost.shape
    xc = field.origin[0] + (np.arange(nx) + 0.5) * RES
    yc = field.origin[1] + (np.arange(ny) + 0.5) * RES
    spl = RectBivariateSpline(xc, yc, field.cost.T, kx=3, ky=3, s=0)
    u = np.linspace(curve.t[3], curve.t[-4], 40001)
    xy, d = curve(u), curve.derivative()(u)
    f = spl(xy[:, 0], xy[:, 1], grid=False) * np.hypot(d[:, 0], d[:, 1])  # |dC/du|: unitless
    ref = scale * 2.0 * np.trapezoid(f, u / RES)
    assert with_cost - without == pytest.approx(ref, rel=1e-4)
