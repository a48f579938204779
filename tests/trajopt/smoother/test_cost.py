"""Tests of trajopt.smoother: the cost field in the smoother's objective (issue 34, part 2).

References are independent of the code under test: central finite differences of the
objective, the mean cost measured on dense samples of the returned curve, and the
certificate recomputed by ``certify``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import astar
from tests.cases import L_HALL_END as GOAL
from tests.cases import L_HALL_RES as RES
from tests.cases import L_HALL_START as START
from tests.cases import l_hall
from tests.reference import dense_mean_cost
from trajopt.errors import InvalidInputError
from trajopt.smoother import Smoother
from trajopt.smoother._cost import CostTerm, cost_field
from trajopt.smoother._problem import assemble, build_problem
from trajopt.smoother._qp import solve_qp


def test_gradient_matches_central_differences():
    """The cost term's gradient against central finite differences of its value."""
    grid, cost, corridor = l_hall()
    smooth_cost = cost_field(
        np.clip(cost + 0.3 * np.sin(np.arange(cost.size).reshape(cost.shape)), 0, 1), 2.0, grid
    )
    options = Smoother()
    prob, _, _ = build_problem(options, None, corridor, start=START, goal=GOAL, hs=None, hg=None)
    asm = assemble(options, prob, 4.0)
    z = solve_qp(options, asm.qp, x0=asm.x0).z
    qp = asm.qp
    term = CostTerm.on_knots(
        smooth_cost, np.asarray(corridor.origin), RES, asm.knots, options.degree, qp.nb
    )
    _, grad = term.value_grad(z)
    rng = np.random.default_rng(3)
    z = z + rng.uniform(-0.3, 0.3, z.shape) * (np.arange(len(z)) % qp.nb < qp.n)
    _, grad = term.value_grad(z)
    eps = 1e-6
    idx = [i for i in range(2 * qp.nb) if i % qp.nb < qp.n]
    fd = np.empty(len(idx))
    for k, i in enumerate(idx):
        e = np.zeros_like(z)
        e[i] = eps
        fd[k] = (term.value_grad(z + e)[0] - term.value_grad(z - e)[0]) / (2 * eps)
    assert np.max(np.abs(fd - grad[idx])) <= 1e-5 * (1 + np.max(np.abs(fd)))
    assert np.all(grad[[i for i in range(2 * qp.nb) if i % qp.nb >= qp.n]] == 0.0)


def _term_and_qp(weight: float = 2.0):
    """The L hall's cost term on one attempt's knots, its QP and the QP's solution."""
    grid, cost, corridor = l_hall()
    field = cost_field(
        np.clip(cost + 0.3 * np.sin(np.arange(cost.size).reshape(cost.shape)), 0, 1), weight, grid
    )
    options = Smoother()
    prob, _, _ = build_problem(options, None, corridor, start=START, goal=GOAL, hs=None, hg=None)
    asm = assemble(options, prob, 4.0)
    term = CostTerm.on_knots(
        field, np.asarray(corridor.origin), RES, asm.knots, options.degree, asm.qp.nb, 3.0
    )
    return options, term, asm, solve_qp(options, asm.qp, x0=asm.x0).z


def _reference_term(term, z):
    """Value, gradient and model band of the term in NumPy from ``CostField.at`` (dense)."""
    nb, n, p = term.nb, term.n, term.p
    c = np.column_stack([z[:n], z[nb : nb + n]])
    w = term.scale * term.field.weight * term.wq
    value, grad, hess = 0.0, np.zeros((n, 2)), np.zeros((n, n))
    h = term.field.resolution
    for q in range(len(term.wq)):
        ids = term.span[q] + np.arange(p + 1)
        pos = term.b0[q] @ c[ids]
        der = term.b1[q] @ c[ids]
        xy = term.origin + term.res * pos
        v, g = term.field.at(xy[None, :])
        speed = np.hypot(*der)
        value += w[q] * v[0] * speed
        grad[ids] += w[q] * (speed * np.outer(term.b0[q], g[0] * term.res))
        grad[ids] += w[q] * v[0] * np.outer(term.b1[q], der / speed)
        # the Hessian of the field: central differences of its gradient, one cell each side
        hxx_row = term.field.at((xy + [h, 0])[None])[1] - term.field.at((xy - [h, 0])[None])[1]
        hyy_row = term.field.at((xy + [0, h])[None])[1] - term.field.at((xy - [0, h])[None])[1]
        H = np.array([hxx_row[0], hyy_row[0]]) / (2 * h)
        lam = max(np.linalg.eigvalsh(0.5 * (H + H.T)).max(), 0.0) * term.res**2
        hess[np.ix_(ids, ids)] += w[q] * speed * lam * np.outer(term.b0[q], term.b0[q])
    out = np.zeros(2 * nb)
    out[:n], out[nb : nb + n] = grad[:, 0], grad[:, 1]
    band = np.zeros((p + 1, nb))
    for d in range(p + 1):
        band[d, : n - d] = np.diagonal(hess, d)
    return value, out, band


def test_compiled_term_matches_a_numpy_reference():
    """Value, gradient and model band of the kernel against a dense NumPy evaluation."""
    _, term, asm, z = _term_and_qp()
    rng = np.random.default_rng(5)
    z = z + rng.uniform(-0.4, 0.4, z.shape) * (np.arange(len(z)) % asm.qp.nb < asm.qp.n)
    value, grad, band = term.evaluate(z)
    ref_value, ref_grad, ref_band = _reference_term(term, z)
    assert value == pytest.approx(ref_value, rel=1e-12)
    np.testing.assert_allclose(grad, ref_grad, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(band, ref_band, rtol=1e-10, atol=1e-12)
    assert np.any(band > 0.0)
    assert term.mean_cost(z) == pytest.approx(
        value / (term.scale * term.field.weight * np.sum(term.wq * np.hypot(*_derivs(term, z)))),
        rel=1e-12,
    )


def _derivs(term, z):
    nb, n, p = term.nb, term.n, term.p
    c = np.column_stack([z[:n], z[nb : nb + n]])
    der = np.array([term.b1[q] @ c[term.span[q] + np.arange(p + 1)] for q in range(len(term.wq))])
    return der.T


def test_round_solver_updates_match_fresh_solves():
    """piqp set up once and updated with new Hessians and linear terms: fresh solves' answers."""
    from trajopt.smoother._cost import linearised
    from trajopt.smoother._qp import RoundSolver

    options, term, asm, z = _term_and_qp()
    rounds = RoundSolver(asm.qp)
    for k, rho in enumerate((1.0, 0.1, 0.01)):
        qp = linearised(asm.qp, term, z + 0.1 * k, rho)
        a, b = rounds(options, qp, z), solve_qp(options, qp, x0=z)
        assert a.success and b.success
        np.testing.assert_allclose(a.z, b.z, atol=1e-7)
    assert rounds.solver is not None


def test_rounds_descend_and_stay_feasible():
    """Every round lowers the true objective; the result satisfies the QP's rows and bounds."""
    from trajopt.smoother._basis import band_quadratic
    from trajopt.smoother._cost import cost_rounds
    from trajopt.smoother._qp import RoundSolver

    options, term, asm, z0 = _term_and_qp()
    qp = asm.qp
    f0 = band_quadratic(qp.full, qp.g, z0, asm.const) + term.value_grad(z0)[0]
    z, g_lin, stats = cost_rounds(options, qp, term, z0, asm.const, math.inf, RoundSolver(qp))
    f = band_quadratic(qp.full, qp.g, z, asm.const) + term.value_grad(z)[0]
    assert stats["accepted"] >= 1 and f < f0
    assert stats["cost_term"] == pytest.approx(term.value_grad(z)[0], rel=1e-12)
    np.testing.assert_allclose(g_lin, qp.g + term.value_grad(z)[1], rtol=1e-12)
    assert np.all(z >= qp.lbx - 1e-9) and np.all(z <= qp.ubx + 1e-9)
    coef, lb, ub = asm.point_rows
    c = np.column_stack([z[: qp.nb], z[qp.nb :]])
    rows = np.einsum("ikd,id->ik", coef, c)
    assert np.all(rows >= lb - 1e-7) and np.all(rows <= ub + 1e-7)


def test_bilinear_field_interpolates_cell_centres():
    """At the cell centres the field is the Gaussian-smoothed cell's value."""
    from scipy import ndimage

    from trajopt.smoother._cost import SIGMA

    grid, cost, _ = l_hall()
    f = cost_field(cost, 1.0, grid)
    iy, ix = np.nonzero(np.ones_like(cost, bool))
    v, _ = f.at(np.column_stack([(ix + 0.5) * RES, (iy + 0.5) * RES]))
    smooth = ndimage.gaussian_filter(np.asarray(cost, float), SIGMA, mode="nearest")
    np.testing.assert_allclose(v, smooth[iy, ix], atol=1e-12)
    assert f.cost.min() >= 0.0 and f.cost.max() <= 1.0


def test_read_only_cost_is_validated_once_and_reused():
    """A read-only cost array (a Costmap's) is smoothed once; a writeable one every call."""
    grid, cost, _ = l_hall()
    ro = np.array(cost, dtype=float)
    ro.flags.writeable = False
    assert cost_field(ro, 1.0, grid).cost is cost_field(ro, 2.0, grid).cost
    rw = np.array(cost, dtype=float)
    a = cost_field(rw, 1.0, grid).cost
    rw[:] = 0.0
    assert np.all(cost_field(rw, 1.0, grid).cost == 0.0) and np.any(a > 0.0)


@pytest.mark.parametrize("kappa_max", [None, 2.0])
def test_cost_aware_curve_leaves_the_band(kappa_max):
    """Cost-blind, the taut curve cuts the band at the inner corner; cost-aware it does not."""
    grid, cost, corridor = l_hall()
    sm = Smoother(kappa_max=kappa_max)
    kw = dict(raw_grid=grid, radius=0.2, start=START, goal=GOAL)
    blind = sm.fit(None, corridor, **kw)
    aware = sm.fit(None, corridor, cost=cost, cost_weight=2.0, **kw)
    m_blind = dense_mean_cost(blind.curve, cost, grid)
    m_aware = dense_mean_cost(aware.curve, cost, grid)
    assert m_blind > 0.04
    assert m_aware < 0.25 * m_blind
    assert aware.certificate.ok and aware.certificate.min_clearance_m >= 0.2 - 1e-9
    assert aware.stats["cost_rounds"]["accepted"] >= 1
    if kappa_max is not None:
        assert aware.certificate.kappa_max_sampled <= kappa_max * (1 + 1e-9)


def test_mean_cost_non_increasing_in_the_weight():
    """Heavier weights never raise the curve's mean cost (beyond the rounds' tolerance)."""
    grid, cost, corridor = l_hall()
    kw = dict(raw_grid=grid, radius=0.2, start=START, goal=GOAL, cost=cost)
    means = [
        dense_mean_cost(Smoother().fit(None, corridor, cost_weight=w, **kw).curve, cost, grid)
        for w in (0.0, 0.5, 2.0, 10.0)
    ]
    assert all(b <= a + 2e-3 for a, b in zip(means, means[1:], strict=False)), means


def test_no_cost_and_zero_weight_are_the_cost_blind_fit():
    """cost=None and cost_weight=0 give the cost-blind curve bit for bit."""
    grid, cost, corridor = l_hall()
    kw = dict(raw_grid=grid, radius=0.2, start=START, goal=GOAL)
    a = Smoother().fit(None, corridor, **kw)
    b = Smoother().fit(None, corridor, cost=cost, cost_weight=0.0, **kw)
    assert np.array_equal(a.curve.c, b.curve.c)
    assert "cost_rounds" not in a.stats


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        (dict(cost_weight=-1.0), "cost_weight must be finite and >= 0"),
        (dict(cost_weight=math.inf), "cost_weight must be finite and >= 0"),
        (dict(cost_weight=math.nan), "cost_weight must be finite and >= 0"),
        (dict(cost_weight="2"), "cost_weight must be a number"),
        (dict(cost=np.zeros((79, 80))), r"raw grid's shape \(80, 80\)"),
        (dict(cost=np.full((80, 80), np.nan)), "cost must be finite"),
        (dict(cost=np.full((80, 80), 2.0)), r"normalised to \[0, 1\]"),
        (dict(cost=np.full((80, 80), -0.1)), r"normalised to \[0, 1\]"),
    ],
)
def test_bad_cost_input_is_refused(kwargs, match):
    grid, cost, corridor = l_hall()
    kw = dict(raw_grid=grid, radius=0.2, start=START, goal=GOAL, cost=cost)
    kw.update(kwargs)
    with pytest.raises(InvalidInputError, match=match):
        Smoother().fit(None, corridor, **kw)


def test_costmap_of_another_resolution_is_refused():
    grid, cost, corridor = l_hall()
    values = np.zeros((80, 80), np.int16)
    other = astar.from_costmap(values, resolution=0.1, convention="costmap_2d")
    kw = dict(raw_grid=grid, radius=0.2, start=START, goal=GOAL)
    with pytest.raises(InvalidInputError, match="resolution 0.1 m must equal"):
        Smoother().fit(None, corridor, cost=other, **kw)
    with pytest.raises(InvalidInputError, match="cost needs raw_grid"):
        Smoother().fit(None, corridor, cost=cost, start=START, goal=GOAL, radius=0.2)
