"""Least-squares B-spline fits of path points.

Least-squares B-spline fits of path points (the chapter's equation (3)), with the checks that
refuse a system the data cannot determine (Schoenberg-Whitney, conditioning) and a solution
that swings away from the data (:func:`swing_problem`).
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np

import trajopt.validation as validation
from trajopt.analysis.fits._curves import FittedBSpline
from trajopt.errors import IllPosedFitError
from trajopt.geometry import clamped_uniform_knots

Parameterization = Literal["uniform", "chord", "centripetal"]
PARAMETERIZATIONS: tuple[str, ...] = ("uniform", "chord", "centripetal")

#: Largest 2-norm condition number of the B-spline collocation matrix ``A_ji = B_i(u_j)``
#: that :func:`fit_bspline` accepts; above it the matrix counts as numerically singular.
#: The A* points are cell centres: they locate a path to half a cell, a relative accuracy
#: of ``1e-4`` or coarser for paths of up to a few thousand cells. With ``cond(A) > 1e4``
#: that uncertainty alone can change the control points by more than their own size (the
#: least-squares error bound is ``cond(A)`` times the relative data error): ``A`` is rank
#: deficient at the data's accuracy (its numerical rank with ``rcond = 1e-4``, as
#: :func:`numpy.linalg.lstsq` counts it, is below ``n_ctrl``). Well-posed designs of every
#: allowed degree stay far below (dense uniform sites: about 2 for degree 1, 5 for degree
#: 3, 100-850 for degree 9; the paper scene's sweeps at most 21). Below the threshold a
#: near-interpolating fit can still swing far from the data between the points: the
#: solution's check, :data:`BSPLINE_SWING_MAX`, refuses those.
BSPLINE_COND_MAX = 1e4

#: Largest distance of a control point from the data's bounding box, in units of the data's
#: extent (the longer side of that box), that :func:`fit_bspline` accepts in its solution.
#: Each span of the curve lies in the convex hull of its ``k + 1`` control points, so a
#: control polygon that leaves the box by more than the path's own size lets the curve
#: leave it too. Measured on 300 random 8-connected staircases of 20-43 cells (chord
#: parameters, degrees 2 and 3, ``n_ctrl`` from ``n`` down to ``n - 12``): the curve left
#: the box by about half its control points' excursion, and where the control points
#: were 1-2 extents out the curve's farthest point was a median 0.65 extents from every
#: data point (up to 300 extents for the fits beyond 10): it interpolates the points and
#: swings between them, and no longer approximates the path. Well-posed least-squares
#: fits stay inside the bound: with ``n_ctrl = n - 8``, 1 fit of 600 exceeded it, with
#: ``n - 12`` none exceeded half of it. The swing appears when a square or nearly square
#: system passes the conditioning check (:data:`BSPLINE_COND_MAX`) yet turns the
#: staircase's corners into alternating control points.
BSPLINE_SWING_MAX = 1.0


def curve_parameters(points: np.ndarray, parameterization: Parameterization) -> np.ndarray:
    """Return the data parameters ``u_i`` in [0, 1] for a point sequence.

    Parameters
    ----------
    points : array_like, shape (n, 2)
    parameterization : {'uniform', 'chord', 'centripetal'}
        Equally spaced; cumulative chord length ``|Q_i - Q_{i-1}|``; cumulative
        ``|Q_i - Q_{i-1}|^(1/2)``.

    Returns
    -------
    ndarray, shape (n,)
        Non-decreasing, ``u_0 = 0``, ``u_{n-1} = 1`` (uniform when all points coincide).
    """
    p = validation.points("points", points)
    kind = validation.choice("parameterization", parameterization, PARAMETERIZATIONS)
    n = len(p)
    if kind == "uniform":
        return np.linspace(0.0, 1.0, n)
    d = np.hypot(*np.diff(p, axis=0).T)
    if kind == "centripetal":
        d = np.sqrt(d)
    total = float(d.sum())
    if total <= 0:
        return np.linspace(0.0, 1.0, n)
    u = np.concatenate([[0.0], np.cumsum(d)]) / total
    u[-1] = 1.0
    return u


def dedup(p: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points ``p`` (n, 2) and weights ``w`` (n,) without consecutive duplicate points."""
    keep = np.ones(len(p), bool)
    keep[1:] = np.any(np.diff(p, axis=0) != 0, axis=1)
    return p[keep], w[keep]


def schoenberg_whitney_matches(u: np.ndarray, t: np.ndarray, k: int) -> int:
    """How many B-splines a strictly increasing subsequence of the sites ``u`` can serve.

    Greedy matching: basis function ``B_i`` (``i = 0, 1, ...``) takes the first site after
    the previous one with ``B_i(u_j) != 0``, i.e. ``t_i < u_j < t_{i+k+1}``, the interval
    closed on the left where ``t_i`` is a ``(k + 1)``-fold knot (the clamped start, where
    ``B_0 = 1``) and on the right for the last function at the last knot (the clamped end,
    where ``B_{n-1} = 1``; the last interval is closed). Both ends of the supports are
    non-decreasing in ``i``, so taking the earliest admissible site is optimal: the
    condition holds iff all ``n = len(t) - k - 1`` functions are matched. ``u`` must be
    non-decreasing.
    """
    n = len(t) - k - 1
    m = len(u)
    j = -1  # index of the last site used
    for i in range(n):
        lo, hi = t[i], t[i + k + 1]
        left_closed = t[i] == t[i + k] < hi
        right_closed = i == n - 1 and t[i + 1] == hi
        start = j + 1
        if j >= 0:  # strictly increasing sites
            start = max(start, int(np.searchsorted(u, u[j], side="right")))
        start = max(start, int(np.searchsorted(u, lo, side="left" if left_closed else "right")))
        if start >= m or not (u[start] < hi or (right_closed and u[start] == hi)):
            return i
        j = start
    return n


def _collocation_cond(u: np.ndarray, t: np.ndarray, k: int) -> float:
    """2-norm condition number of ``A_ji = B_i(u_j)``, from the banded Gram matrix.

    ``cond(A) = sqrt(lambda_max / lambda_min)`` of ``A^T A`` (bandwidth ``k``); the squaring
    is harmless up to ``cond(A) ~ 1e7``, far above :data:`BSPLINE_COND_MAX`. ``inf`` when
    ``A^T A`` is not numerically positive definite.
    """
    from scipy.interpolate import BSpline
    from scipy.linalg import LinAlgError, eigvals_banded

    a = BSpline.design_matrix(u, t, k).tocsc()
    g = (a.T @ a).toarray()
    n = g.shape[0]
    band = np.zeros((k + 1, n))
    for d in range(min(k + 1, n)):
        band[d, : n - d] = np.diagonal(g, -d)
    try:
        lam = eigvals_banded(band, lower=True)
    except (LinAlgError, ValueError):
        return math.inf
    lo, hi = float(lam[0]), float(lam[-1])
    return math.sqrt(hi / lo) if lo > 0 and hi > 0 else math.inf


def design_problem(u: np.ndarray, t: np.ndarray, k: int) -> str:
    """Why the least-squares B-spline on knots ``t`` is ill-posed at sites ``u`` ('' if not)."""
    n = len(t) - k - 1
    matched = schoenberg_whitney_matches(u, t, k)
    if matched < n:
        return (
            f"the Schoenberg-Whitney condition fails: there are no strictly increasing data "
            f"parameters u_(j_i) with t_i < u_(j_i) < t_(i+k+1) for i = 0..{n - 1} (matching "
            f"each control point to the earliest admissible site runs out at i = {matched}), "
            f"so the least-squares system is singular"
        )
    cond = _collocation_cond(u, t, k)
    if not cond <= BSPLINE_COND_MAX:
        return (
            f"the collocation matrix is numerically singular: cond_2 = {cond:.3g} > "
            f"BSPLINE_COND_MAX = {BSPLINE_COND_MAX:g}, so the control points are not "
            f"determined by the data (they would diverge)"
        )
    return ""


def swing_problem(points: np.ndarray, c: np.ndarray) -> str:
    """Why the control points ``c`` swing too far from ``points`` ('' if they do not).

    Parameters
    ----------
    points : ndarray, shape (n, 2)
        The fitted data (m).
    c : ndarray, shape (n_ctrl, 2)
        Control points of a fit of ``points`` (m).

    Returns
    -------
    str
        Empty when every control point lies within :data:`BSPLINE_SWING_MAX` times the data's
        extent (the longer side of its bounding box) of that box; otherwise the farthest
        control point, its distance, the ratio and the rule. Non-finite control points fail.
    """
    p = np.asarray(points, dtype=float)
    cc = np.asarray(c, dtype=float)
    lo, hi = p.min(axis=0), p.max(axis=0)
    extent = float(np.max(hi - lo))
    outside = np.maximum(0.0, np.maximum(lo - cc, cc - hi))
    dist = np.hypot(outside[:, 0], outside[:, 1])
    dist[~np.all(np.isfinite(cc), axis=1)] = math.inf
    i = int(np.argmax(dist))
    ratio = float(dist[i]) / extent if extent > 0 else (0.0 if dist[i] == 0 else math.inf)
    if ratio <= BSPLINE_SWING_MAX:
        return ""
    return (
        f"the solution swings away from the data: control point {i} lies {dist[i]:.3g} m "
        f"outside the data's bounding box, {ratio:.3g} times the data's extent "
        f"{extent:.3g} m > BSPLINE_SWING_MAX = {BSPLINE_SWING_MAX:g}, so the curve swings "
        f"between the points instead of following them"
    )


def _supported_n_ctrl(
    u: np.ndarray,
    k: int,
    below: int,
    points: np.ndarray | None,
    w: np.ndarray | None,
    memo: dict[int, bool] | None,
) -> int:
    """Largest ``n_ctrl < below`` (clamped uniform knots) the sites support; 0 if none.

    With ``points`` (and their weights ``w``) the fit must also pass :func:`swing_problem`.
    ``memo`` maps counts already checked to their outcome and is filled in place.
    """
    for n in range(min(below - 1, len(u)), k, -1):
        ok = memo.get(n) if memo is not None else None
        if ok is None:
            ok = _passes(u, k, n, points, w)
            if memo is not None:
                memo[n] = ok
        if ok:
            return n
    return 0


def _passes(u: np.ndarray, k: int, n: int, points: np.ndarray | None, w: np.ndarray | None) -> bool:
    """Whether ``n`` control points pass the design checks (and, with ``points``, the swing)."""
    t = clamped_uniform_knots(n, k)
    if design_problem(u, t, k):
        return False
    if points is None:
        return True
    ww = np.ones(len(points)) if w is None else w
    try:
        c = _lsq(points, u, t, k, ww, "").c
    except IllPosedFitError:
        return False
    return not swing_problem(points, c)


def allowed_message(
    u: np.ndarray,
    k: int,
    below: int,
    *,
    points: np.ndarray | None = None,
    weights: np.ndarray | None = None,
    memo: dict[int, bool] | None = None,
) -> str:
    """How many control points (``< below``) the sites ``u`` allow for degree ``k``, in words.

    Without ``points`` the count passes the design checks (:func:`design_problem`); with the
    data ``points`` (shape ``(len(u), 2)``, optional ``weights``) its fit also passes
    :func:`swing_problem`. ``memo``, when given, maps control-point counts already checked
    for these ``u``, ``k``, ``points`` and ``weights`` to whether they pass; the counts
    checked here are added to it (:func:`~trajopt.fits.sweep_bspline` shares one per
    parameterisation and degree).
    """
    best = _supported_n_ctrl(u, k, below, points, weights, memo)
    if best:
        return f"these data allow at most {best} control points for degree {k}"
    return f"these data allow no control-point count for degree {k} (tried {k + 1}-{below - 1})"


def ill_posed_message(
    reason: str,
    k: int,
    n_ctrl: int,
    parameterization: str,
    u: np.ndarray,
    *,
    points: np.ndarray | None = None,
    weights: np.ndarray | None = None,
    memo: dict[int, bool] | None = None,
) -> str:
    """Return the message of an ill-posed fit: the design, the ``reason`` and what the data allow.

    ``points``, ``weights`` and ``memo`` go to :func:`allowed_message`.
    """
    allowed = allowed_message(u, k, n_ctrl, points=points, weights=weights, memo=memo)
    return (
        f"least-squares B-spline with degree {k}, n_ctrl {n_ctrl} (clamped uniform knots) "
        f"and {parameterization} parameters of {len(u)} distinct points: {reason}; {allowed}"
    )


def fit_bspline(
    points: np.ndarray,
    *,
    degree: int = 3,
    n_ctrl: int = 20,
    parameterization: Parameterization = "chord",
    weights: np.ndarray | None = None,
) -> FittedBSpline:
    """Least-squares clamped B-spline through path points (the chapter's equation (3)).

    Minimises ``sum_i w_i |C(u_i) - Q_i|^2`` over the control points with
    :func:`scipy.interpolate.make_lsq_spline`, on clamped uniform knots ``t`` over
    ``[0, 1]``. Consecutive duplicate points are dropped first.

    The end points are **not** exact: as in the chapter's Table 2, the curve starts and
    ends near, not at, the first and last point (on the paper scene's A* paths a few
    hundredths of a cell for the sweep's best fit, up to several cells with few control
    points). The chapter tabulates these start and end errors in x and y;
    :func:`trajopt.metrics.path_metrics` and :func:`trajopt.compare` report them as
    ``start_error_x_m``, ``start_error_y_m``, ``end_error_x_m`` and ``end_error_y_m``.

    Before solving, the system is checked, and an ill-posed one raises instead of
    returning a diverged curve:

    * **Schoenberg-Whitney**, exactly for these knots and data parameters: the design
      matrix ``A_ji = B_i(u_j)`` has full column rank iff there are data parameters
      ``u_(j_0) < u_(j_1) < ... < u_(j_(n_ctrl-1))`` with ``B_i(u_(j_i)) != 0``, i.e.
      ``t_i < u_(j_i) < t_(i+k+1)``, the first basis function also taking ``u = 0`` and
      the last ``u = 1`` (the clamped ends, where they equal 1). Matching every control
      point, in order, to the earliest admissible parameter after the previous one finds
      such a sequence whenever one exists (the supports' ends increase with ``i``).
    * **Conditioning**: the 2-norm condition number of ``A`` must not exceed
      :data:`BSPLINE_COND_MAX` (``1e4``); above it ``A`` is numerically singular at the
      accuracy of A* points and the control points would diverge.

    After solving, the solution is checked too:

    * **Swing**: every control point must lie within :data:`BSPLINE_SWING_MAX` (``1``)
      times the data's extent (the longer side of the data's bounding box) of that box
      (:func:`swing_problem`); farther out, the curve interpolates the points and swings
      between them instead of approximating the path.

    All three fail typically when ``n_ctrl`` is close to the number of points (a square or
    nearly square system whose data parameters fall outside or near the ends of the basis
    functions' supports, or that turns a staircase's corners into alternating control
    points).

    Parameters
    ----------
    points : array_like, shape (n, 2)
        Path points in metres, in path order.
    degree : int
        ``k`` in 1..9.
    n_ctrl : int
        Number of control points, ``k + 1 <= n_ctrl <= n`` (distinct points).
    parameterization : {'uniform', 'chord', 'centripetal'}
        How the data parameters ``u_i`` are chosen (:func:`curve_parameters`).
    weights : array_like, shape (n,), optional
        Positive weights ``w_i`` on the squared residuals.

    Returns
    -------
    FittedBSpline
        A :class:`~trajopt.geometry._bspline.BSplineCurve` on ``u in [0, 1]`` carrying ``params``,
        ``residuals``, ``mse`` and ``parameterization``.

    Raises
    ------
    InvalidInputError
        Bad arguments.
    IllPosedFitError
        The data cannot determine the fit (a subclass of :class:`InvalidInputError`): more
        control points than distinct points, the Schoenberg-Whitney condition fails,
        ``cond(A) > BSPLINE_COND_MAX``, or a control point lies more than
        ``BSPLINE_SWING_MAX`` extents outside the data's bounding box. The message names the
        condition (with the offending value and the bound), the degree, ``n_ctrl``, the
        parameterisation and the number of points, and says how many control points the
        data allow (the largest count below ``n_ctrl`` that passes every check).
    """
    p = validation.points("points", points)
    k = validation.integer("degree", degree, 1, 9)
    parameterization = validation.choice("parameterization", parameterization, PARAMETERIZATIONS)
    w = validation.weights("weights", weights, len(p), positive=True)
    p, w = dedup(p, w)
    n_c = validation.integer("n_ctrl", n_ctrl, k + 1)
    u = curve_parameters(p, parameterization)
    if n_c > len(p):
        raise IllPosedFitError(
            f"n_ctrl must be <= the number of distinct points ({len(p)}), got {n_c}; "
            f"{allowed_message(u, k, len(p) + 1, points=p, weights=w)} "
            f"({parameterization} parameters)"
        )
    t = clamped_uniform_knots(n_c, k)
    problem = design_problem(u, t, k)
    if problem:
        raise IllPosedFitError(
            ill_posed_message(problem, k, n_c, parameterization, u, points=p, weights=w)
        )
    curve = _lsq(p, u, t, k, w, parameterization)
    problem = swing_problem(p, curve.c)
    if problem:
        raise IllPosedFitError(
            ill_posed_message(problem, k, n_c, parameterization, u, points=p, weights=w)
        )
    return curve


def _lsq(
    p: np.ndarray, u: np.ndarray, t: np.ndarray, k: int, w: np.ndarray, parameterization: str
) -> FittedBSpline:
    from scipy.interpolate import make_lsq_spline

    try:
        spl = make_lsq_spline(u, p, t, k=k, w=np.sqrt(w), check_finite=False)
    except (ValueError, np.linalg.LinAlgError) as exc:
        raise IllPosedFitError(
            f"least-squares B-spline with degree {k} and {len(t) - k - 1} control points "
            f"is not defined for these {len(p)} points ({parameterization} parameters): {exc}"
        ) from exc
    c = np.asarray(spl.c)
    if not np.all(np.isfinite(c)):  # not expected after the checks of fit_bspline
        raise IllPosedFitError(
            f"least-squares B-spline with degree {k} and {len(c)} control points is singular "
            f"for these {len(p)} points (Schoenberg-Whitney condition)"
        )
    curve = FittedBSpline(t, c, k)
    res = np.asarray(spl(u)) - p
    res.flags.writeable = False
    uu = u.copy()
    uu.flags.writeable = False
    curve.params = uu
    curve.residuals = res
    curve.mse = float(np.mean(np.sum(res * res, axis=1)))
    curve.parameterization = parameterization
    return curve
