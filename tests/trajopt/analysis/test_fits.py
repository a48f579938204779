"""Tests of trajopt.analysis.fits (``trajopt.fits``) against independent references (numpy polyfit, brute force,
explicit B-spline design matrices) and hand cases."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import assume, event, example, given, settings
from hypothesis import strategies as st
from scipy.interpolate import BSpline

from tests.reference import brute_force_schoenberg_whitney, control_point_swing
from trajopt.analysis import fits
from trajopt.analysis.fits._bspline_fit import BSPLINE_SWING_MAX, schoenberg_whitney_matches
from trajopt.analysis.fits._robust import bisquare
from trajopt.errors import IllPosedFitError, InvalidInputError
from trajopt.geometry._bspline import BSplineCurve, clamped_uniform_knots
from trajopt.geometry._curve import ParametricCurve


def _staircase(n: int = 60) -> np.ndarray:
    """An x-monotone A*-like path: diagonal then straight steps of 0.03 m."""
    steps = [(1, 1)] * (n // 3) + [(1, 0)] * (n // 3) + [(1, 1)] * (n - 2 * (n // 3))
    return 0.03 * np.vstack([[0, 0], np.cumsum(steps, axis=0)]).astype(float)


# ------------------------------------------------------------------ polynomial y = f(x)
def test_least_squares_matches_numpy_polyfit_with_weights() -> None:
    rng = np.random.default_rng(1)
    x = np.sort(rng.uniform(0.0, 3.0, 40))
    y = 0.2 * x**3 - x + 0.05 * rng.standard_normal(40)
    w = rng.uniform(0.5, 2.0, 40)
    fit = fits.fit_polynomial(np.c_[x, y], 3, method="least_squares", weights=w)
    # numpy's w multiplies the unsquared residual: pass sqrt of our squared-residual weights
    ref = np.polynomial.polynomial.Polynomial.fit(x, y, 3, w=np.sqrt(w))
    xs = np.linspace(x[0], x[-1], 50)  # the curve is defined on the data's x range
    assert fit.valid and fit.reason == ""
    np.testing.assert_allclose(fit.curve(xs)[:, 1], ref(xs), atol=1e-9)
    np.testing.assert_allclose(fit.curve(xs)[:, 0], xs)
    assert fit.mse == pytest.approx(np.mean((ref(x) - y) ** 2), rel=1e-9)


def test_lar_line_is_the_best_line_through_two_points_brute_force() -> None:
    # an L1 line fit has an optimum through two data points: enumerate them all
    rng = np.random.default_rng(2)
    x = np.sort(rng.uniform(0, 1, 9))
    y = 1.0 + 0.5 * x + rng.laplace(0, 0.1, 9)
    best = min(
        np.sum(np.abs(y - (y[i] + (y[j] - y[i]) / (x[j] - x[i]) * (x - x[i]))))
        for i, j in itertools.combinations(range(9), 2)
    )
    fit = fits.fit_polynomial(np.c_[x, y], 1, method="lar")
    ours = np.sum(np.abs(fit.curve(x)[:, 1] - y))
    assert ours == pytest.approx(best, rel=1e-7, abs=1e-10)


@pytest.mark.parametrize("method", ["lar", "bisquare"])
def test_robust_methods_ignore_gross_outliers(method: str) -> None:
    x = np.linspace(0.0, 2.0, 41)
    y = 0.3 * x**2 - 0.4 * x + 0.1
    y_bad = y.copy()
    y_bad[[5, 17, 30]] += [1.0, -2.0, 1.5]
    fit = fits.fit_polynomial(np.c_[x, y_bad], 2, method=method)
    np.testing.assert_allclose(fit.curve(x)[:, 1], y, atol=1e-6)
    ls = fits.fit_polynomial(np.c_[x, y_bad], 2, method="least_squares")
    assert np.max(np.abs(ls.curve(x)[:, 1] - y)) > 0.1  # least squares is pulled away
    if method == "bisquare":
        assert fit.converged and fit.iterations >= 1
        assert np.all(fit.weights[[5, 17, 30]] == 0.0)


# bisquare against statsmodels' RLM (TukeyBiweight, c = 4.685): RLM has no leverage
# adjustment and scales by MAD about zero / Phi^-1(3/4); given a scale callable with our
# documented rule (MAD about zero of the residuals after dropping the p - 1 smallest, over
# 0.6745) it computes the same estimator as ``_bisquare(..., leverage=False)``.
def _rlm_tukey():
    # the two modules, not statsmodels.api (which loads every model of the package)
    rlm = pytest.importorskip(
        "statsmodels.robust.robust_linear_model", reason="statsmodels is not installed"
    )
    norms = pytest.importorskip("statsmodels.robust.norms", reason="statsmodels is not installed")
    return rlm.RLM, norms.TukeyBiweight(c=4.685)


def _our_scale_rule(p: int):
    def scale(model, resid):  # the two-argument form: used by RLM without a dof correction
        return np.median(np.sort(np.abs(resid))[p - 1 :]) / 0.6745

    return scale


def _chebyshev_design(x: np.ndarray, order: int) -> np.ndarray:
    lo, hi = x.min(), x.max()
    return np.polynomial.chebyshev.chebvander((2.0 * x - (lo + hi)) / (hi - lo), order)


def _noisy_quadratic(seed: int, outlier_share: float, n: int = 200, sigma: float = 0.01):
    """``y = 0.3 x^2 - 2 x + 1`` on [0, 10] plus N(0, sigma^2) noise; a share of the points
    moved by 1-25 m up or down (gross outliers)."""
    rng = np.random.default_rng(seed)
    x = np.sort(rng.uniform(0.0, 10.0, n))
    truth = 0.3 * x**2 - 2.0 * x + 1.0
    y = truth + sigma * rng.standard_normal(n)
    n_bad = int(round(outlier_share * n))
    bad = rng.choice(n, n_bad, replace=False)
    y[bad] += rng.uniform(1.0, 25.0, n_bad) * rng.choice([-1.0, 1.0], n_bad)
    return x, y, truth, bad


@pytest.mark.parametrize("share", [0.0, 0.10, 0.15, 0.20])
@pytest.mark.parametrize("seed", [0, 1])
def test_bisquare_without_leverage_is_statsmodels_rlm(seed: int, share: float) -> None:
    rlm, tukey = _rlm_tukey()
    x, y, _, _ = _noisy_quadratic(seed, share)
    v = _chebyshev_design(x, 2)
    coef, robust, _, conv = bisquare(v, y[:, None], np.ones(len(y)), 1e-12, 500, leverage=False)
    ref = rlm(y, v, M=tukey).fit(scale_est=_our_scale_rule(3), conv="coefs", tol=1e-13, maxiter=500)
    assert conv
    # the same estimator: equal up to the two iterations' stopping tolerances (sigma = 0.01)
    np.testing.assert_allclose(v @ coef[:, 0], v @ ref.params, atol=1e-8)
    np.testing.assert_allclose(robust, ref.weights, atol=1e-6)


@pytest.mark.parametrize("share", [0.0, 0.10, 0.15, 0.20])
@pytest.mark.parametrize("seed", [0, 1])
def test_bisquare_with_leverage_is_close_to_rlm_and_to_the_true_curve(
    seed: int, share: float
) -> None:
    rlm, tukey = _rlm_tukey()
    sigma, n, p = 0.01, 200, 3
    x, y, truth, bad = _noisy_quadratic(seed, share, n=n, sigma=sigma)
    fit = fits.fit_polynomial(np.c_[x, y], 2, method="bisquare", tol=1e-10, max_iter=500)
    ref = rlm(y, _chebyshev_design(x, 2), M=tukey).fit(conv="coefs", tol=1e-13, maxiter=500)
    ours = fit.curve(x)[:, 1]
    assert fit.converged and fit.valid
    # the leverage factors 1/sqrt(1 - h_i) are within 3 % of 1 here, so the weights and the
    # fit move by a small part of the fit's own standard error sigma * sqrt(p / n)
    assert np.max(np.abs(ours - ref.fittedvalues)) < 0.2 * sigma * math.sqrt(p / n)
    # both estimate the true curve within the noise (LS is metres off with outliers)
    assert np.max(np.abs(ours - truth)) < sigma
    assert np.all(fit.weights[bad] == 0.0)


def test_bisquare_regression_every_seventh_point_raised() -> None:
    """Issue 17 item 4: the MAD was taken about the median but the weights used raw residuals,
    so every weight was 0 after the first step and the fit stayed least squares (4.05 m off)."""
    rng = np.random.default_rng(17)
    x = np.linspace(0.0, 10.0, 200)
    truth = 0.3 * x**2 - 2.0 * x + 1.0
    y = truth + 0.01 * rng.standard_normal(200)
    y[::7] += 25.0
    fit = fits.fit_polynomial(np.c_[x, y], 2, method="bisquare")
    assert fit.converged and fit.valid and fit.reason == ""
    assert np.max(np.abs(fit.curve(x)[:, 1] - truth)) < 0.01
    assert np.all(fit.weights[::7] == 0.0)
    ls = fits.fit_polynomial(np.c_[x, y], 2)
    assert np.max(np.abs(ls.curve(x)[:, 1] - truth)) > 1.0


@pytest.fixture(scope="module")
def paper_paths() -> dict[str, np.ndarray]:
    """Cell centres (m) of the A* paths from SP to A-D on the paper scene's avoidance area."""
    from astar.inflation import avoidance_area
    from astar.search import find_path
    from trajopt.analysis import scenes

    sc = scenes.paper()
    avoid = avoidance_area(sc.grid, sc.w_cells, border=True)
    return {
        name: sc.grid.cell_to_world(find_path(avoid, sc.start_cell, sc.goal_cell(name)).cells)
        for name in sc.target_names
    }


def test_bisquare_on_paper_paths_without_leverage_is_statsmodels_rlm(paper_paths) -> None:
    rlm, tukey = _rlm_tukey()
    cell = 0.03
    compared = 0
    for pts in paper_paths.values():
        x, y = pts[:, 0], pts[:, 1]
        for order in range(1, 11):
            v = _chebyshev_design(x, order)
            coef, _, _, conv = bisquare(v, y[:, None], np.ones(len(y)), 1e-12, 500, leverage=False)
            if not conv:  # a redescending M-estimate may cycle; RLM is then no reference
                continue
            ref = rlm(y, v, M=tukey).fit(
                scale_est=_our_scale_rule(order + 1), conv="coefs", tol=1e-13, maxiter=500
            )
            np.testing.assert_allclose(v @ coef[:, 0], ref.fittedvalues, atol=1e-6 * cell)
            compared += 1
    assert compared >= 36  # of 40 (target, order) pairs


@pytest.mark.parametrize(
    ("target", "order"),
    # every (target, order) of A-C at orders 2, 5, 8, 10 except C at order 2, where the
    # iteration cycles between two weight patterns (reported as converged=False)
    [(t, m) for t in "ABC" for m in (2, 5, 8, 10) if (t, m) != ("C", 2)],
)
def test_bisquare_on_paper_paths_is_a_fixed_point_of_the_documented_irls(
    paper_paths, target: str, order: int
) -> None:
    """Weights recomputed from the returned fit by the documented rule (leverage-adjusted
    residuals, MAD about zero after dropping the p - 1 smallest, c = 4.685) and a plain
    ``lstsq`` reproduce the fit."""
    pts = paper_paths[target]
    x, y = pts[:, 0], pts[:, 1]
    fit = fits.fit_polynomial(pts, order, method="bisquare", tol=1e-12, max_iter=1000)
    assert fit.converged
    v = _chebyshev_design(x, order)
    h = np.diag(v @ np.linalg.pinv(v))  # hat matrix diagonal, computed another way
    r_adj = (y - fit.curve(x)[:, 1]) / np.sqrt(1.0 - np.minimum(h, 0.9999))
    s = np.median(np.sort(np.abs(r_adj))[order:]) / 0.6745
    u = r_adj / (4.685 * s)
    w = np.where(np.abs(u) < 1, (1 - u**2) ** 2, 0.0)
    np.testing.assert_allclose(w, fit.weights, atol=1e-6)
    c, *_ = np.linalg.lstsq(np.sqrt(w)[:, None] * v, np.sqrt(w) * y, rcond=None)
    np.testing.assert_allclose(v @ c, fit.curve(x)[:, 1], atol=1e-6 * 0.03)


def test_bisquare_on_clean_data_equals_least_squares() -> None:
    p = _staircase(45)
    ls = fits.fit_polynomial(p, 4)
    bi = fits.fit_polynomial(p, 4, method="bisquare", tol=1e-10, max_iter=200)
    assert bi.mse >= ls.mse - 1e-15  # least squares minimises the MSE
    assert bi.mse < 2.0 * ls.mse


def test_polynomial_curve_derivatives_and_curvature() -> None:
    x = np.linspace(-1.0, 1.0, 30)
    fit = fits.fit_polynomial(np.c_[x, x**2], 2)
    c = fit.curve
    assert isinstance(c, ParametricCurve)
    assert c.domain == pytest.approx((-1.0, 1.0))
    assert c.curvature(0.0) == pytest.approx(2.0, rel=1e-9)  # y = x^2 at the vertex
    u = np.array([-0.5, 0.3])
    h = 1e-6
    fd = (c(u + h) - c(u - h)) / (2 * h)
    np.testing.assert_allclose(c(u, 1), fd, atol=1e-6)
    np.testing.assert_allclose(c(u, 2), [[0.0, 2.0], [0.0, 2.0]], atol=1e-9)
    assert c.heading(0.0) == pytest.approx(0.0, abs=1e-12)
    s = c.sample(50)
    assert s.xy.shape == (50, 2)
    # arc length of y = x^2 on [-1, 1]: 2 * (sqrt(5)/2 + asinh(2)/4)
    assert c.length == pytest.approx(math.sqrt(5) + math.asinh(2) / 2, rel=1e-8)


def test_polynomial_path_towards_smaller_x_starts_at_its_first_point() -> None:
    x = np.linspace(2.0, 0.0, 25)
    fit = fits.fit_polynomial(np.c_[x, 0.5 * x], 1)
    assert fit.valid
    c = fit.curve
    np.testing.assert_allclose(c(c.domain[0]), [2.0, 1.0], atol=1e-12)
    np.testing.assert_allclose(c(c.domain[1]), [0.0, 0.0], atol=1e-12)
    assert c.heading(c.domain[0]) == pytest.approx(math.atan2(-0.5, -1.0))


def test_path_going_back_in_x_is_flagged_not_a_crash() -> None:
    t = np.linspace(0, np.pi, 40)
    p = np.c_[np.cos(t), np.sin(t)]  # a half circle: x goes back
    p = np.vstack([p[:20], p[19::-1] + [0.0, -0.01]])
    fit = fits.fit_polynomial(p, 3)
    assert not fit.valid
    assert "not a function y = f(x)" in fit.reason
    assert fit.curve is not None and fit.n_backtracks > 0


def test_vertical_step_flags_and_vertical_path_has_no_curve() -> None:
    p = _staircase(30)
    p = np.vstack([p, p[-1] + [0.0, 0.03]])  # one vertical step
    fit = fits.fit_polynomial(p, 2)
    assert not fit.valid and fit.n_backtracks == 1
    vertical = np.c_[np.full(10, 1.0), np.linspace(0, 1, 10)]
    v = fits.fit_polynomial(vertical, 2)
    assert not v.valid and v.curve is None and math.isinf(v.mse)
    assert "vertical" in v.reason
    # the parametric variant fits it
    par = fits.fit_polynomial_parametric(vertical, 2)
    assert par.valid and par.mse < 1e-20
    np.testing.assert_allclose(par.curve(par.params), vertical, atol=1e-10)


def test_parametric_polynomial_fits_a_circle_arc() -> None:
    t = np.linspace(0, 1.5 * np.pi, 80)
    p = np.c_[np.cos(t), np.sin(t)]
    for method in fits.FIT_METHODS:
        fit = fits.fit_polynomial_parametric(p, 8, method=method)
        assert fit.valid
        assert np.max(np.linalg.norm(fit.residuals, axis=1)) < 1e-3
    k = fit.curve.curvature(np.linspace(0.1, 0.9, 9))
    np.testing.assert_allclose(k, 1.0, atol=2e-2)


# ------------------------------------------------------------------------ B-spline
@pytest.mark.parametrize("kind", fits.PARAMETERIZATIONS)
def test_bspline_fit_equals_explicit_weighted_least_squares(kind: str) -> None:
    rng = np.random.default_rng(3)
    p = _staircase(60) + 0.002 * rng.standard_normal((61, 2))
    w = rng.uniform(0.5, 3.0, len(p))
    k, n = 3, 14
    curve = fits.fit_bspline(p, degree=k, n_ctrl=n, parameterization=kind, weights=w)
    assert isinstance(curve, BSplineCurve) and isinstance(curve, ParametricCurve)
    # independent reference: the full collocation matrix and numpy's lstsq
    u = fits.curve_parameters(p, kind)
    t = clamped_uniform_knots(n, k)
    a = BSpline.design_matrix(u, t, k).toarray()
    sw = np.sqrt(w)[:, None]
    c_ref, *_ = np.linalg.lstsq(sw * a, sw * p, rcond=None)
    np.testing.assert_allclose(curve.c, c_ref, atol=1e-9)
    np.testing.assert_allclose(curve.params, u)
    assert curve.mse == pytest.approx(np.mean(np.sum((a @ c_ref - p) ** 2, axis=1)), rel=1e-9)
    assert curve.parameterization == kind
    # end points are not forced onto the data (plain least squares)
    assert np.linalg.norm(curve(0.0) - p[0]) > 0.0


def test_curve_parameters_hand_case() -> None:
    p = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 4.0]])
    np.testing.assert_allclose(fits.curve_parameters(p, "uniform"), [0, 0.5, 1])
    np.testing.assert_allclose(fits.curve_parameters(p, "chord"), [0, 0.2, 1])
    np.testing.assert_allclose(fits.curve_parameters(p, "centripetal"), [0, 1 / 3, 1])


def test_bspline_with_many_control_points_interpolates_data() -> None:
    p = _staircase(20)
    # uniform parameters: the square system is well conditioned (cond ~ 41), an interpolant
    curve = fits.fit_bspline(p, degree=3, n_ctrl=len(p), parameterization="uniform")
    assert curve.mse < 1e-20
    assert np.max(np.abs(curve.c)) < 2.0 * np.max(np.abs(p))
    # chord parameters of the same staircase: cond ~ 3e4, the interpolant's control points
    # lie 50 m from a 0.6 m path; that is refused, naming how many control points work
    with pytest.raises(InvalidInputError, match=r"numerically singular.*allow at most 20"):
        fits.fit_bspline(p, degree=3, n_ctrl=len(p), parameterization="chord")


# ----------------------------------------- B-spline: Schoenberg-Whitney and conditioning
_STEP = {"x": (1, 0), "y": (0, 1), "d": (1, 1)}


def _steps_to_points(steps: str, cell: float = 0.03) -> np.ndarray:
    """An A*-like staircase: unit steps in x ('x') or y ('y') and diagonal steps ('d')."""
    st = np.array([_STEP[c] for c in steps], dtype=float).reshape(-1, 2)
    return cell * np.vstack([[0.0, 0.0], np.cumsum(st, axis=0)])


#: Random 38-40-point staircases whose square chord-parameter fits diverged before the
#: checks (issue 23; found by seeding numpy's default_rng 0..299 and keeping the fits with
#: |C| > 1e4 m): (steps, degree, |C| the fit used to return, what is wrong).
_DIVERGED = [
    ("dxdddyxddyxyxxdyyydyyxxyyxxxdyyxxydydxx", 2, 1.95e14, "Schoenberg-Whitney"),
    ("dddddyxxdxdxxyydxdddyyyxxxydyxyxydyyydx", 2, 2.48e24, "numerically singular"),
    ("yxdxdyyyddyyyxyyddyxyyxxdydxddydyddddd", 3, 3.59e22, "numerically singular"),
    ("xxxdxydydxxxxyyyddyxyydxyxddxxxdxyxddx", 3, 1.01e4, "numerically singular"),
]


def _reference_design(p: np.ndarray, k: int, n_ctrl: int, kind: str):
    """The full collocation matrix (scipy's B-spline values) and the sites."""
    u = fits.curve_parameters(p, kind)
    t = clamped_uniform_knots(n_ctrl, k)
    return BSpline.design_matrix(u, t, k).toarray(), u, t


@pytest.mark.parametrize(("steps", "k", "c_before", "condition"), _DIVERGED)
def test_square_staircase_fits_that_diverged_now_raise(
    steps: str, k: int, c_before: float, condition: str
) -> None:
    p = _steps_to_points(steps)
    n = len(p)
    a, _, _ = _reference_design(p, k, n, "chord")
    # independent reference: at the data's accuracy (rcond = 1 / BSPLINE_COND_MAX) lstsq
    # finds the square system rank deficient
    rank = np.linalg.lstsq(a, p, rcond=1.0 / fits.BSPLINE_COND_MAX)[2]
    assert rank < n
    with pytest.raises(InvalidInputError) as info:
        fits.fit_bspline(p, degree=k, n_ctrl=n, parameterization="chord")
    msg = str(info.value)
    assert condition in msg
    assert f"degree {k}" in msg and f"n_ctrl {n}" in msg and "chord" in msg
    assert f"{n} distinct points" in msg
    allowed = int(msg.rsplit("allow at most ", 1)[1].split()[0])
    assert k + 1 <= allowed < n
    curve = fits.fit_bspline(p, degree=k, n_ctrl=allowed, parameterization="chord")
    a_ok, _, _ = _reference_design(p, k, allowed, "chord")
    c_ref, _, rank_ok, _ = np.linalg.lstsq(a_ok, p, rcond=1.0 / fits.BSPLINE_COND_MAX)
    assert rank_ok == allowed
    np.testing.assert_allclose(curve.c, c_ref, atol=1e-9)
    assert np.max(np.abs(curve.c)) < 1e-3 * c_before


def test_schoenberg_whitney_failure_is_exact_rank_deficiency() -> None:
    steps, k, _, _ = _DIVERGED[0]
    p = _steps_to_points(steps)
    a, u, t = _reference_design(p, k, len(p), "chord")
    assert schoenberg_whitney_matches(u, t, k) < len(p)
    assert np.linalg.matrix_rank(a) < len(p)  # numpy's default tolerance: singular


@given(
    k=st.integers(1, 4),
    extra=st.integers(0, 3),
    # dyadic sites: they hit the knots 0, 0.25, 0.5, 0.75, 1 exactly and never underflow a
    # B-spline value to 0 (a site like 1e-311 does: then only the conditioning check sees it)
    sites=st.lists(st.integers(0, 2**16).map(lambda i: i / 2**16), min_size=3, max_size=9),
)
@example(k=1, extra=3, sites=[0.0, 0.25, 0.5, 0.75, 1.0])  # linear: every site on a knot
@example(k=2, extra=3, sites=[0.0, 0.25, 0.25, 0.5, 0.75, 1.0])
@example(k=2, extra=2, sites=[0.0, 0.25, 0.5, 0.75, 1.0])
@example(k=3, extra=0, sites=[0.0, 0.0, 1.0, 1.0])  # two distinct sites for four functions
@settings(max_examples=300, deadline=None)
def test_schoenberg_whitney_greedy_equals_enumeration(k: int, extra: int, sites) -> None:
    # clamped uniform knots (interior knots at 0.25, 0.5, 0.75 for n = k + 4) and sorted
    # sites that may sit on knots, repeat, or sit on the clamped ends
    n = k + 1 + extra
    u = np.sort(np.asarray(sites, dtype=float))
    t = clamped_uniform_knots(n, k)
    a = BSpline.design_matrix(u, t, k).toarray() if n <= len(u) else None
    ours = schoenberg_whitney_matches(u, t, k) == n
    event(f"schoenberg-whitney holds: {ours}")
    assert ours == (a is not None and brute_force_schoenberg_whitney(a, u))


@given(
    steps=st.text(alphabet="xyd", min_size=37, max_size=39),
    k=st.sampled_from([2, 3]),
    fewer=st.integers(0, 3),
    kind=st.sampled_from(fits.PARAMETERIZATIONS),
)
@example(steps=_DIVERGED[0][0], k=2, fewer=0, kind="chord")
@example(steps=_DIVERGED[1][0], k=2, fewer=0, kind="chord")
@example(steps=_DIVERGED[2][0], k=3, fewer=0, kind="chord")
@example(steps=_DIVERGED[3][0], k=3, fewer=0, kind="chord")
@settings(max_examples=200, deadline=None)
def test_bspline_fit_raises_exactly_when_lstsq_rank_is_deficient(
    steps: str, k: int, fewer: int, kind: str
) -> None:
    """Staircases (A*-like) against the full least-squares matrix and numpy's lstsq: the fit
    raises iff the matrix is rank deficient at rcond = 1 / BSPLINE_COND_MAX (or the exact
    Schoenberg-Whitney condition fails) or lstsq's control points leave the data's box by
    more than BSPLINE_SWING_MAX extents, and otherwise returns lstsq's control points."""
    p = _steps_to_points(steps)
    n = len(p) - fewer
    assume(n >= k + 1)
    a, u, t = _reference_design(p, k, n, kind)
    sv = np.linalg.svd(a, compute_uv=False)
    cond = sv[0] / sv[-1] if sv[-1] > 0 else math.inf
    assume(abs(math.log(cond / fits.BSPLINE_COND_MAX)) > 1e-3)  # not at the threshold
    c_ref, _, rank, _ = np.linalg.lstsq(a, p, rcond=1.0 / fits.BSPLINE_COND_MAX)
    if rank < n or schoenberg_whitney_matches(u, t, k) < n:
        event("ill-posed")
        with pytest.raises(IllPosedFitError, match="Schoenberg-Whitney|numerically singular"):
            fits.fit_bspline(p, degree=k, n_ctrl=n, parameterization=kind)
        return
    swing = control_point_swing(p, c_ref)
    assume(abs(swing - BSPLINE_SWING_MAX) > 1e-6)  # not at the threshold
    if swing > BSPLINE_SWING_MAX:
        event("swings")
        with pytest.raises(IllPosedFitError, match="swings away from the data"):
            fits.fit_bspline(p, degree=k, n_ctrl=n, parameterization=kind)
    else:
        event("fitted")
        curve = fits.fit_bspline(p, degree=k, n_ctrl=n, parameterization=kind)
        np.testing.assert_allclose(curve.c, c_ref, atol=1e-9)


_DIRS8 = [(1, 0), (1, 1), (0, 1), (-1, 1), (-1, 0), (-1, -1), (0, -1), (1, -1)]


def _random_walk(rng: np.random.Generator, cell: float = 0.05) -> np.ndarray:
    """Cell centres of an 8-connected walk of 20-43 cells that never steps straight back."""
    d = int(rng.integers(8))
    cells = [(0, 0)]
    for _ in range(int(rng.integers(20, 44)) - 1):
        d = int(rng.choice([e for e in range(8) if e != (d + 4) % 8]))
        cells.append((cells[-1][0] + _DIRS8[d][0], cells[-1][1] + _DIRS8[d][1]))
    return cell * (np.array(cells, dtype=float) + 0.5)


def test_square_fits_of_random_staircases_never_swing() -> None:
    """Square and nearly square chord fits (degrees 2, 3) of seeded random walks: every fit
    returned keeps its control points within BSPLINE_SWING_MAX extents of the data's box;
    every fit refused is ill-posed by the design checks or by lstsq's own swing. Without the
    swing check, 123 of these 600 square fits had control points beyond 10 extents."""
    rng = np.random.default_rng(0)
    returned = refused_swing = 0
    for _ in range(150):
        p = _random_walk(rng)
        for k, fewer in itertools.product((2, 3), (0, 1)):
            n = len(p) - fewer
            a, u, t = _reference_design(p, k, n, "chord")
            try:
                curve = fits.fit_bspline(p, degree=k, n_ctrl=n, parameterization="chord")
            except IllPosedFitError as exc:
                msg = str(exc)
                assert f"degree {k}, n_ctrl {n}" in msg and "chord" in msg
                if "swings away" in msg:
                    refused_swing += 1
                    c_ref = np.linalg.lstsq(a, p, rcond=None)[0]
                    assert control_point_swing(p, c_ref) > BSPLINE_SWING_MAX
                    ratio = float(msg.split(" times the data's extent")[0].rsplit(", ", 1)[1])
                    assert ratio == pytest.approx(control_point_swing(p, c_ref), rel=1e-2)
                else:
                    assert "Schoenberg-Whitney" in msg or "numerically singular" in msg
                continue
            returned += 1
            assert control_point_swing(p, curve.c) <= BSPLINE_SWING_MAX
            np.testing.assert_allclose(a @ curve.c, curve(u), atol=1e-9)
    assert returned > 50 and refused_swing > 50  # both branches are exercised


def test_a_fit_that_swings_raises_naming_the_fit_the_value_and_the_rule() -> None:
    # an 11-point staircase (diagonals, then x-y steps), chord parameters, degree 3, one
    # control point per point: the interpolant passes every cell centre, but a control
    # point lies about 8.8 extents outside the path's box (independent reference: lstsq)
    steps = "ddxxyxyxxx"
    p = _steps_to_points(steps)
    k, n = 3, len(p)
    a, _, _ = _reference_design(p, k, n, "chord")
    c_ref, _, rank, _ = np.linalg.lstsq(a, p, rcond=1.0 / fits.BSPLINE_COND_MAX)
    assert rank == n  # well conditioned enough for the design checks
    swing = control_point_swing(p, c_ref)
    assert swing > BSPLINE_SWING_MAX
    # the package face re-exports the check and its bound
    assert fits.BSPLINE_SWING_MAX == BSPLINE_SWING_MAX
    assert f"{swing:.3g} times the data's extent" in fits.swing_problem(p, c_ref)
    with pytest.raises(IllPosedFitError) as info:
        fits.fit_bspline(p, degree=k, n_ctrl=n, parameterization="chord")
    msg = str(info.value)
    assert f"degree {k}, n_ctrl {n}" in msg and "chord" in msg and f"{n} distinct points" in msg
    assert f"{swing:.3g} times the data's extent" in msg
    assert f"BSPLINE_SWING_MAX = {BSPLINE_SWING_MAX:g}" in msg
    allowed = int(msg.rsplit("allow at most ", 1)[1].split()[0])
    assert k + 1 <= allowed < n  # and that count does fit, inside the bound
    ok = fits.fit_bspline(p, degree=k, n_ctrl=allowed, parameterization="chord")
    assert control_point_swing(p, ok.c) <= BSPLINE_SWING_MAX
    # the comparison records the refused fit as invalid, with the reason
    from trajopt.analysis.comparison._builtin_methods import _method_bspline

    class Ctx:
        reference = p

        @staticmethod
        def options_for(name: str) -> dict:
            return {"parameterization": "chord", "degree": k, "n_ctrl": n}

    res = _method_bspline(Ctx())
    assert res.path is None and not res.valid and "swings away from the data" in res.note


def test_sweep_records_ill_posed_combinations_with_the_reason() -> None:
    steps, k, _, _ = _DIVERGED[1]
    p = _steps_to_points(steps)
    n = len(p)
    recs = fits.sweep_bspline(p, parameterizations=("chord",), degrees=(k,), n_ctrls=(8, n))
    by_n = {r.params["n_ctrl"]: r for r in recs}
    assert by_n[8].valid and by_n[8].rank == 1
    bad = by_n[n]
    assert not bad.valid and math.isinf(bad.mse) and bad.rank == 2
    assert "numerically singular" in bad.reason and "allow at most" in bad.reason
    with pytest.raises(IllPosedFitError) as info:  # the reason is fit_bspline's message
        fits.fit_bspline(p, **bad.kwargs)
    assert str(info.value) == bad.reason


def test_sweep_of_random_staircases_ranks_no_swinging_fit_valid() -> None:
    """Chord sweeps (degrees 2, 3, the default control-point counts) of seeded random walks:
    every record ranked valid keeps lstsq's control points within BSPLINE_SWING_MAX extents
    of the data's box, the swinging ones are invalid with the reason, and the best valid
    record's kwargs fit without raising. Without the sweep's swing check, 106 swinging fits
    were ranked valid here, the best record of 17 of the 30 walks among them, and
    fit_bspline refused it."""
    rng = np.random.default_rng(0)
    refused_swing = 0
    for _ in range(30):
        p = _random_walk(rng)
        recs = fits.sweep_bspline(p, parameterizations=("chord",), degrees=(2, 3))
        first_swing = True
        for r in recs:
            if r.valid:
                a, _, _ = _reference_design(p, r.params["degree"], r.params["n_ctrl"], "chord")
                c_ref = np.linalg.lstsq(a, p, rcond=None)[0]
                assert control_point_swing(p, c_ref) <= BSPLINE_SWING_MAX, r
            elif "swings away from the data" in r.reason:
                refused_swing += 1
                assert math.isinf(r.mse)
                if first_swing:  # the reason is fit_bspline's message
                    first_swing = False
                    with pytest.raises(IllPosedFitError) as info:
                        fits.fit_bspline(p, **r.kwargs)
                    assert str(info.value) == r.reason
        best = recs[0]
        assert best.valid and best.rank == 1
        curve = fits.fit_bspline(p, **best.kwargs)
        assert curve.mse == pytest.approx(best.mse, rel=1e-9, abs=1e-18)
    assert refused_swing > 30  # the branch is exercised


def test_bspline_too_many_control_points_says_how_many_the_data_allow() -> None:
    p = _staircase(60)
    with pytest.raises(InvalidInputError, match=r"distinct points \(61\).*allow at most \d+"):
        fits.fit_bspline(p, degree=3, n_ctrl=70)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"parameterization": "arc"}, "parameterization"),
        ({"degree": 0}, "degree"),
        ({"n_ctrl": 3, "degree": 3}, "n_ctrl"),
        ({"n_ctrl": 500}, "n_ctrl"),
        ({"weights": np.zeros(61)}, "weights"),
    ],
)
def test_bspline_bad_options_raise(kwargs: dict, field: str) -> None:
    with pytest.raises(InvalidInputError, match=field):
        fits.fit_bspline(_staircase(60), **kwargs)


@pytest.mark.parametrize(
    ("call", "field"),
    [
        (lambda p: fits.fit_polynomial(p, 3, method="ransac"), "method"),
        (lambda p: fits.fit_polynomial(p, 0), "order"),
        (lambda p: fits.fit_polynomial(p[:3], 5), "order"),
        (lambda p: fits.fit_polynomial(p, 3, tol=-1.0), "tol"),
        (lambda p: fits.fit_polynomial(p, 3, weights=np.ones(3)), "weights"),
        (lambda p: fits.fit_polynomial(np.ones((5, 3)), 2), "shape"),
        (lambda p: fits.fit_polynomial_parametric(p, 3, parameterization="x"), "parameter"),
    ],
)
def test_polynomial_bad_options_raise(call, field: str) -> None:
    with pytest.raises(InvalidInputError, match=field):
        call(_staircase(30))


# ------------------------------------------------------------------------- sweeps
def test_sweep_polynomial_ranks_thirty_combinations() -> None:
    p = _staircase(60)
    recs = fits.sweep_polynomial(p)
    assert len(recs) == 30
    assert [r.rank for r in recs] == list(range(1, 31))
    mses = [r.mse for r in recs]
    assert mses == sorted(mses)
    assert {(r.params["method"], r.params["order"]) for r in recs} == set(
        itertools.product(fits.FIT_METHODS, range(1, 11))
    )
    best = recs[0]
    assert fits.fit_polynomial(p, **best.kwargs).mse == pytest.approx(best.mse)
    # least squares over nested models: MSE never grows with the order
    ls = sorted((r.params["order"], r.mse) for r in recs if r.params["method"] == "least_squares")
    assert all(b <= a * (1 + 1e-9) + 1e-15 for (_, a), (_, b) in itertools.pairwise(ls))
    assert best.params["method"] == "least_squares"  # LS minimises exactly this MSE


def test_sweep_bspline_subset_matches_single_fits() -> None:
    p = _staircase(60)
    recs = fits.sweep_bspline(p, degrees=(2, 3), n_ctrls=(3, 8, 12, 70))
    assert len(recs) == 3 * 2 * 4
    bad = [r for r in recs if not r.valid]
    # n_ctrl 3 is too few for degree 3, 70 exceeds the 61 points
    assert {(r.params["degree"], r.params["n_ctrl"]) for r in bad} == {(3, 3), (2, 70), (3, 70)}
    assert all(math.isinf(r.mse) for r in bad) and recs[-1] in bad
    for r in recs:
        if r.valid:
            assert fits.fit_bspline(p, **r.kwargs).mse == pytest.approx(r.mse, rel=1e-9)
    assert recs[0].as_dict()["rank"] == 1
    assert fits.SWEEP_N_CTRL and len(fits.PARAMETERIZATIONS) * len(fits.SWEEP_DEGREES) * len(
        fits.SWEEP_N_CTRL
    ) == pytest.approx(500, abs=10)
