"""IPOPT on the general constraint layout: polygon corridors, against piqp as the reference.

The convex corridor QP solved by IPOPT must reach piqp's optimum (the same objective value
and control points within solver tolerance); the exact curvature-bounded NLP must hold its
bound on dense samples (three-point curvature, no curve evaluation of its own); end
headings hold; an IPOPT failure is a typed error carrying IPOPT's status.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import astar
import trajopt
from tests.cases import square_inflated
from tests.reference import square_clearance, three_point_curvature
from trajopt.analysis import scenes
from trajopt.analysis.bench._suites import random_queries
from trajopt.corridor import build_polygon_corridor
from trajopt.errors import SmoothingError
from trajopt.smoother import Smoother, _layout, _nlp, _qp
from trajopt.smoother._attempts import solve_attempt
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
