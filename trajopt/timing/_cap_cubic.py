"""The cap kernel's interval bound for a cubic piece, unrolled (numba).

The pieces of the library's curves are cubic (B-splines of degree 3); the bound of
:func:`trajopt.timing._cap_kernel._evaluate` on such a piece, with its loops over the degree
written out, takes about half the time.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from trajopt.kernel_cache import watch_compiles
from trajopt.timing._kernel_options import NO_REFCOUNT

watch_compiles()  # a first compilation logs one notice (trajopt.kernel_cache)


@njit(cache=True, **NO_REFCOUNT)
def bound_cubic(coef, piece, w, a, b, gam):  # pragma: no cover - compiled
    """Bound on ``|kappa|`` over ``[a, b]`` in cubic piece ``piece``, no zero-speed end (1/m).

    :func:`trajopt.timing._cap_kernel._evaluate` for ``p = 3``, ``flip = 0``: the same
    operations in the same order as its general loops (``_taylor``: the Taylor coefficients
    ``g`` of ``c_t`` about the interval's middle, also written to ``gam``; the shift to
    powers of ``t``, ``v``; ``_cross_and_norm``: ``X = v x v'`` and ``S = |v|^2``;
    ``_bernstein_range`` with the factors of ``matrices`` as literals), unrolled, so the
    bounds are bit-identical (``tests/trajopt/timing/test_cap_kernel.py`` compares the two).
    """
    pm = 0.5 * (w[piece] + w[piece + 1])
    ph = 0.5 * (w[piece + 1] - w[piece])
    hh = b - a
    x0 = (0.5 * (a + b) - pm) / ph
    r = hh / ph
    g00 = coef[piece, 0, 0]
    g10 = coef[piece, 1, 0]
    g20 = coef[piece, 2, 0]
    g10 = g10 + x0 * g20
    g00 = g00 + x0 * g10
    g10 = g10 + x0 * g20
    f = hh
    g00 = g00 * f
    f = f * r
    g10 = g10 * f
    f = f * r
    g20 = g20 * f
    f = f * r
    g01 = coef[piece, 0, 1]
    g11 = coef[piece, 1, 1]
    g21 = coef[piece, 2, 1]
    g11 = g11 + x0 * g21
    g01 = g01 + x0 * g11
    g11 = g11 + x0 * g21
    f = hh
    g01 = g01 * f
    f = f * r
    g11 = g11 * f
    f = f * r
    g21 = g21 * f
    f = f * r
    gam[0, 0] = g00
    gam[1, 0] = g10
    gam[2, 0] = g20
    gam[0, 1] = g01
    gam[1, 1] = g11
    gam[2, 1] = g21
    v00 = ((0.0 + 1.0 * g00) + -0.5 * g10) + 0.25 * g20
    v01 = ((0.0 + 1.0 * g01) + -0.5 * g11) + 0.25 * g21
    v10 = (0.0 + 1.0 * g10) + -1.0 * g20
    v11 = (0.0 + 1.0 * g11) + -1.0 * g21
    v20 = 0.0 + 1.0 * g20
    v21 = 0.0 + 1.0 * g21
    S0 = (0.0 + v00 * v00) + (0.0 + v01 * v01)
    S1 = ((0.0 + v00 * v10) + v10 * v00) + ((0.0 + v01 * v11) + v11 * v01)
    S2 = (((0.0 + v00 * v20) + v10 * v10) + v20 * v00) + (
        ((0.0 + v01 * v21) + v11 * v11) + v21 * v01
    )
    S3 = ((0.0 + v10 * v20) + v20 * v10) + ((0.0 + v11 * v21) + v21 * v11)
    S4 = (0.0 + v20 * v20) + (0.0 + v21 * v21)
    X0 = (0.0 + v00 * (v11 * 1.0)) - (0.0 + v01 * (v10 * 1.0))
    X1 = ((0.0 + v00 * (v21 * 2.0)) + v10 * (v11 * 1.0)) - (
        (0.0 + v01 * (v20 * 2.0)) + v11 * (v10 * 1.0)
    )
    X2 = ((0.0 + v10 * (v21 * 2.0)) + v20 * (v11 * 1.0)) - (
        (0.0 + v11 * (v20 * 2.0)) + v21 * (v10 * 1.0)
    )
    X3 = (0.0 + v20 * (v21 * 2.0)) - (0.0 + v21 * (v20 * 2.0))
    best = 0.0
    bb = 0.0 + 1.0 * X0
    bb = abs(bb)
    if bb > best:
        best = bb
    bb = (0.0 + 1.0 * X0) + 0.3333333333333333 * X1
    bb = abs(bb)
    if bb > best:
        best = bb
    bb = ((0.0 + 1.0 * X0) + 0.6666666666666666 * X1) + 0.3333333333333333 * X2
    bb = abs(bb)
    if bb > best:
        best = bb
    bb = (((0.0 + 1.0 * X0) + 1.0 * X1) + 1.0 * X2) + 1.0 * X3
    bb = abs(bb)
    if bb > best:
        best = bb
    bx = best
    best = np.inf
    bb = 0.0 + 1.0 * S0
    if bb < best:
        best = bb
    bb = (0.0 + 1.0 * S0) + 0.25 * S1
    if bb < best:
        best = bb
    bb = ((0.0 + 1.0 * S0) + 0.5 * S1) + 0.16666666666666666 * S2
    if bb < best:
        best = bb
    bb = (((0.0 + 1.0 * S0) + 0.75 * S1) + 0.5 * S2) + 0.25 * S3
    if bb < best:
        best = bb
    bb = ((((0.0 + 1.0 * S0) + 1.0 * S1) + 1.0 * S2) + 1.0 * S3) + 1.0 * S4
    if bb < best:
        best = bb
    bs = best
    if bx == 0.0:
        return 0.0
    if not bs > 0.0:
        return np.inf
    return bx / (bs * math.sqrt(bs))
