"""The cost term of the IPOPT problems: a smooth cost field on the corridor's window.

The IPOPT problems minimise the cost term of :mod:`trajopt.smoother._cost` exactly,
``s * w * sum_q wq cost(C(u_q)) |C'(u_q)|`` at the same Gauss-Legendre points as
:class:`~trajopt.smoother._cost.CostTerm` (cell units, the same scale ``s`` and weight ``w``),
with two smooth stand-ins for its non-smooth parts:

* ``cost`` is the interpolating tensor-product cubic B-spline (not-a-knot end conditions, the
  spline ``casadi.interpolant(..., "bspline", ...)`` builds) through the field's smoothed
  cell values at the cell centres, instead of the bilinear interpolation of
  :meth:`~trajopt.smoother._cost.CostField.at` (equal at the centres; C2 between them);
* ``|C'|`` is ``sqrt(x'^2 + y'^2 + EPS)``.

The spline's coefficients (computed with scipy, one linear pass per axis) are constants of
the IPOPT problem (a parameter would need CasADi's parametric B-spline, whose derivatives
are far slower to build and evaluate), so the problem is built once per problem shape and
cost window: the whole field when it has at most :data:`WHOLE_FIELD_CELLS` cells (built once
per cost array), else the cells of the corridor's regions' bounding box plus
:data:`WINDOW_MARGIN` cells (the curve stays in the convex hull of its control points, which
stay in their regions), its sides rounded up to a multiple of :data:`WINDOW_BUCKET` cells.
Cells beyond the map repeat its edge cells, as :meth:`~trajopt.smoother._cost.CostField.at`
clamps.
"""

from __future__ import annotations

import functools
import hashlib
from dataclasses import dataclass

import numpy as np

from trajopt.smoother._cost import N_GAUSS, CostField, CostTerm

#: cells of cost field around the corridor's regions in the window
WINDOW_MARGIN = 4
#: the window's sides are rounded up to a multiple of this many cells
WINDOW_BUCKET = 64
#: a field of at most this many cells is one window (one IPOPT build per cost array)
WHOLE_FIELD_CELLS = 512 * 512
#: ``|C'|`` is ``sqrt(x'^2 + y'^2 + EPS)`` (cells^2 per cell^2 of the parameter)
EPS = 1e-8
#: windows kept (their coefficients)
_WINDOWS_KEPT = 16

# (shape, cell0, digest) -> window
_WINDOWS: dict[tuple, CostWindow] = {}


class CostWindow:
    """The cost field's spline on one window of cells (hashed by its place and values).

    Attributes
    ----------
    shape : tuple of int
        ``(wx, wy)``: the window's cells per axis.
    cell0 : tuple of int
        ``(ix0, iy0)``: the field's cell at the window's local grid point ``(0, 0)``.
    coef : ndarray, shape (wx * wy,)
        Spline coefficients, x index fastest (CasADi's column-major order).
    digest : bytes
        A digest of the window's cell values: two windows of equal shape, place and digest
        are equal (and share one IPOPT build).
    """

    __slots__ = ("shape", "cell0", "coef", "digest")

    def __init__(self, shape: tuple, cell0: tuple, coef: np.ndarray, digest: bytes) -> None:
        self.shape = (int(shape[0]), int(shape[1]))
        self.cell0 = (int(cell0[0]), int(cell0[1]))
        self.coef, self.digest = coef, digest

    def _key(self) -> tuple:
        return (self.shape, self.cell0, self.digest)

    def __hash__(self) -> int:
        return hash(self._key())

    def __eq__(self, other: object) -> bool:
        return isinstance(other, CostWindow) and other._key() == self._key()

    def offset(self, field: CostField, origin: np.ndarray, res: float) -> np.ndarray:
        """Return ``o`` with local coordinates ``pos + o`` for smoother cells ``pos``.

        ``origin``: world position (m) of the smoother's cell-unit origin (the corridor's);
        ``res``: its cell size (m). Local coordinates count cells from the centre of the
        window's cell ``cell0``.
        """
        o = (np.asarray(origin, dtype=float) - field.origin) / field.resolution - 0.5
        scale = res / field.resolution
        if not np.isclose(scale, 1.0, rtol=1e-9):  # pragma: no cover - checked by cost_field
            raise ValueError(f"cost field resolution {field.resolution} != corridor's {res}")
        return o - np.asarray(self.cell0, dtype=float)


def knots(size: int) -> np.ndarray:
    """Knots of the not-a-knot cubic interpolant on the grid ``0 .. size - 1`` (cells)."""
    g = np.arange(size, dtype=float)
    return np.concatenate([[g[0]] * 4, g[2:-2], [g[-1]] * 4])


def window(field: CostField, lo: np.ndarray, hi: np.ndarray) -> CostWindow:
    """Return the window of ``field`` for the box ``[lo, hi]`` (field cells).

    Parameters
    ----------
    field : CostField
    lo, hi : ndarray, shape (2,)
        Bounding box of the corridor's regions in the *field's* fractional cell indices
        (cell centres at integers).

    Returns
    -------
    CostWindow
        The whole field when it has at most :data:`WHOLE_FIELD_CELLS` cells (and at least 4
        per axis), else the box plus :data:`WINDOW_MARGIN` cells, sides rounded up to
        :data:`WINDOW_BUCKET`; windows are cached by place and values, so that an equal
        window gives the same object.
    """
    ny, nx = field.cost.shape
    if nx * ny <= WHOLE_FIELD_CELLS:
        shape, cell0 = (max(nx, 4), max(ny, 4)), (0, 0)
    else:
        lo_i = np.floor(np.asarray(lo, dtype=float)).astype(int) - WINDOW_MARGIN
        hi_i = np.ceil(np.asarray(hi, dtype=float)).astype(int) + WINDOW_MARGIN
        size = hi_i - lo_i + 1
        shape = tuple(int(WINDOW_BUCKET * -(-s // WINDOW_BUCKET)) for s in size)
        cell0 = tuple(int(a - (s - b) // 2) for a, s, b in zip(lo_i, shape, size, strict=True))
    return _cached_window(field.cost, shape, cell0)


def _cached_window(cost: np.ndarray, shape: tuple, cell0: tuple) -> CostWindow:
    """Return the window, cached by its place and a digest of its values."""
    values = window_values(cost, shape, cell0)
    digest = hashlib.blake2b(values.tobytes(), digest_size=16).digest()
    key = (shape, cell0, digest)
    if key not in _WINDOWS:
        if len(_WINDOWS) >= _WINDOWS_KEPT:
            _WINDOWS.pop(next(iter(_WINDOWS)))
        _WINDOWS[key] = CostWindow(shape, cell0, spline_coefficients(values), digest)
    return _WINDOWS[key]


def window_values(cost: np.ndarray, shape: tuple, cell0: tuple) -> np.ndarray:
    """Return the cell values of the window, shape ``(wx, wy)`` (``[ix, iy]``).

    Cells beyond the map repeat its edge cells.
    """
    ny, nx = cost.shape
    ix = np.clip(np.arange(cell0[0], cell0[0] + shape[0]), 0, nx - 1)
    iy = np.clip(np.arange(cell0[1], cell0[1] + shape[1]), 0, ny - 1)
    return np.ascontiguousarray(cost[np.ix_(iy, ix)].T)


def spline_coefficients(values: np.ndarray) -> np.ndarray:
    """Return the coefficients of the cubic interpolant through ``values[ix, iy]``.

    On the knots :func:`knots` of each axis; x index fastest (shape ``(wx * wy,)``).
    """
    from scipy.interpolate import make_interp_spline

    wx, wy = values.shape
    cx = make_interp_spline(np.arange(wx, dtype=float), values, k=3, axis=0).c  # (wx, wy)
    cxy = make_interp_spline(np.arange(wy, dtype=float), cx, k=3, axis=1).c  # (wy, wx)
    return np.ascontiguousarray(cxy).ravel()


@functools.lru_cache(maxsize=8)
def spline_function(win: CostWindow):
    """Return the CasADi function ``xy (2, 1) -> cost`` of a window (coefficients constant).

    ``xy`` in the window's local coordinates (cells from the centre of its first cell);
    zero outside ``[0, wx - 1] x [0, wy - 1]``.
    """
    import casadi as ca

    wx, wy = win.shape
    xy = ca.MX.sym("xy", 2)
    tx, ty = knots(wx).tolist(), knots(wy).tolist()
    val = ca.bspline(xy, ca.DM(win.coef), [tx, ty], [3, 3], 1, {})
    return ca.Function(f"cost_spline_{wx}x{wy}", [xy], [val])


def quadrature(term: CostTerm) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return the term's quadrature padded to ``N_GAUSS (nb - p)`` points.

    Point ``q`` lies on span ``q // N_GAUSS`` (control points ``q // N_GAUSS + 0 .. p``).

    Returns
    -------
    b0, b1 : ndarray, shape (N_GAUSS (nb - p), p + 1)
        Basis values and first derivatives (zero on the padded spans).
    wq : ndarray, shape (N_GAUSS (nb - p),)
        ``s * w * wq`` (cells; zero on the padded spans).
    """
    nb, p = term.nb, term.p
    Q = N_GAUSS * (nb - p)
    b0 = np.zeros((Q, p + 1))
    b1 = np.zeros((Q, p + 1))
    wq = np.zeros(Q)
    # span j holds the N_GAUSS points of its knot interval (the points come in increasing
    # parameter order, so by span); place each point by its span and rank within it
    span = np.asarray(term.span, dtype=np.int64)
    rank = np.arange(len(span)) - np.searchsorted(span, span, side="left")
    if len(span) and rank.max() >= N_GAUSS:  # pragma: no cover - one interval per span
        raise ValueError(f"a span holds more than {N_GAUSS} quadrature points")
    slot = N_GAUSS * span + rank
    b0[slot], b1[slot] = term.b0, term.b1
    wq[slot] = term.scale * term.field.weight * term.wq
    return b0, b1, wq


@dataclass(frozen=True, slots=True)
class WindowedCost:
    """A cost term and its window: the cost parameters of one IPOPT problem.

    Attributes
    ----------
    term : CostTerm
        The term on the attempt's knots (the QP path's quadrature, scale and weight).
    window : CostWindow
    offset : ndarray, shape (2,)
        Smoother cells to the window's local coordinates (``pos + offset``).
    """

    term: CostTerm
    window: CostWindow
    offset: np.ndarray

    def parameters(self) -> list[np.ndarray]:
        """Return ``[qb0, qb1, wq, offset]`` (:func:`~trajopt.smoother._nlp.smoother_nlp`)."""
        b0, b1, wq = quadrature(self.term)
        return [b0.ravel(order="F"), b1.ravel(order="F"), wq, self.offset]


def windowed(term: CostTerm, lo: np.ndarray, hi: np.ndarray) -> WindowedCost:
    """Return ``term`` on the window of the smoother cells ``[lo, hi]``.

    Parameters
    ----------
    term : CostTerm
    lo, hi : ndarray, shape (2,)
        Bounding box of the corridor's regions (smoother cells, relative to ``term.origin``).
    """
    field = term.field
    base = (term.origin - field.origin) / field.resolution - 0.5
    win = window(field, np.asarray(lo, dtype=float) + base, np.asarray(hi, dtype=float) + base)
    return WindowedCost(term, win, win.offset(field, term.origin, term.res))
