"""Shortest paths of a car with a minimum turning radius: Reeds-Shepp and Dubins.

A car of turning radius ``R`` moves along its heading, forwards or backwards, on arcs of
curvature ``+-1/R`` (``L``: left, ``R``: right) and straight segments (``S``). The shortest
path between two poses is

* **Reeds-Shepp** (forwards and backwards; Reeds and Shepp, "Optimal paths for a car that goes
  both forwards and backwards", Pacific J. Math. 145(2), 1990): a *word* of at most five
  segments from the families CSC, CC|C, C|CC, C|C|C, CC|CC, C|CC|C, C|C_{pi/2}SC,
  CSC_{pi/2}|C, C|C_{pi/2}SC_{pi/2}|C (``|`` a cusp), 48 words with their time-flip and
  reflection symmetries. :func:`reeds_shepp_path` evaluates the closed forms of the paper's
  formulas 8.1-8.11 for every word (the base formulas are re-derived in the comments) and keeps
  the shortest;
* **Dubins** (forwards only; Dubins 1957): one of the six words LSL, RSR, LSR, RSL, LRL, RLR
  (:func:`dubins_path`).

Why our own implementation: the Hybrid-A* search (:mod:`astar.hybrid_kernel`) needs these
lengths and words *inside* its compiled numba kernel, as the obstacle-free heuristic of every
node and as the analytic shot to the goal, and neither OMPL's ``ReedsSheppStateSpace`` /
``DubinsStateSpace`` (C++ behind Python bindings) nor ``rsplan`` (pure Python) can be called
from numba; calling them from Python per node would cost 10-100 us each. The kernels here are
``@njit(cache=True)`` functions on scalars and small preallocated buffers, tested against
OMPL's distances and against the end pose of the returned word (``tests/astar/
test_reeds_shepp.py``).

Conventions: a pose is ``(x, y, heading)``, heading in radians counter-clockwise from ``+x``;
lengths are in the unit of the poses and of ``R`` (the search uses cells). A segment has a
*kind* ``+1`` (L, curvature ``+1/R``), ``0`` (S) or ``-1`` (R, curvature ``-1/R``) and a
*signed length* ``s``: ``s > 0`` forwards, ``s < 0`` backwards; along it the heading changes by
``kind * s / R``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from astar import validation
from astar.errors import InvalidInputError

__all__ = ["CarPath", "dubins_path", "reeds_shepp_path"]

_PI = math.pi
_TWO_PI = 2.0 * math.pi
_HALF_PI = 0.5 * math.pi
_EPS = 1e-10  # tolerance of the validity tests of the base formulas (normalised units)
_LETTERS = {1: "L", 0: "S", -1: "R"}


# --------------------------------------------------------------------------- kernels
@njit(cache=True, inline="always")
def _mod_pi(a):  # pragma: no cover - compiled
    """Angle wrapped to ``[-pi, pi)``."""
    return a - _TWO_PI * math.floor((a + _PI) / _TWO_PI)


@njit(cache=True, inline="always")
def _mod_2pi(a):  # pragma: no cover - compiled
    """Angle wrapped to ``[0, 2 pi)``, with values within ``_EPS`` of ``2 pi`` set to 0."""
    v = a - _TWO_PI * math.floor(a / _TWO_PI)
    if v > _TWO_PI - _EPS:
        v = 0.0
    return v


@njit(cache=True, inline="always")
def _tau_omega(u, v, xi, eta, phi):  # pragma: no cover - compiled
    """Return the two outer arcs ``(tau, omega)`` of the CCCC words (Reeds and Shepp, 8.7/8.8)."""
    delta = _mod_pi(u - v)
    a = math.sin(u) - math.sin(delta)
    b = math.cos(u) - math.cos(delta) - 1.0
    t1 = math.atan2(eta * a - xi * b, xi * a + eta * b)
    t2 = 2.0 * (math.cos(delta) - math.cos(v) - math.cos(u)) + 3.0
    tau = _mod_pi(t1 + _PI) if t2 < 0.0 else _mod_pi(t1)
    omega = _mod_pi(tau - u + v - phi)
    return tau, omega


# Base words (normalised: R = 1, start at the origin heading 0, goal (x, y, phi)). Each writes
# its signed lengths into ``out`` and returns whether the word exists with the signs its name
# says (p: forwards, m: backwards). Kinds of the base words, in order:
#   0 LpSpLp (L S L)   1 LpSpRp (L S R)   2 LpRmL (L R L)   3 LpRupLumRm (L R L R)
#   4 LpRumLumRp (L R L R)   5 LpRmSmLm (L R S L)   6 LpRmSmRm (L R S R)   7 LpRmSLmRp (L R S L R)
@njit(cache=True)
def _base_word(k, x, y, phi, sphi, cphi, out):  # pragma: no cover - compiled
    """Signed lengths of base word ``k`` into ``out`` (see the table above); False if none.

    ``sphi, cphi`` are ``sin(phi), cos(phi)`` (computed once for the eight variants).
    """
    if k == 0:
        # L(t) S(u) L(v): (x - sin phi, y - 1 + cos phi) = u (cos t, sin t), v = phi - t
        xi = x - sphi
        eta = y - 1.0 + cphi
        u = math.hypot(xi, eta)
        t = math.atan2(eta, xi)
        if t < -_EPS:
            return False
        v = _mod_pi(phi - t)
        if v < -_EPS:
            return False
        out[0] = t
        out[1] = u
        out[2] = v
        return True
    if k == 1:
        # L(t) S(u) R(v): (x + sin phi, y - 1 - cos phi) = (u, -2) rotated by t, v = t - phi
        xi = x + sphi
        eta = y - 1.0 - cphi
        r2 = xi * xi + eta * eta
        if r2 < 4.0:
            return False
        u = math.sqrt(r2 - 4.0)
        t = _mod_pi(math.atan2(eta, xi) + math.atan2(2.0, u))
        v = _mod_pi(t - phi)
        if t < -_EPS or v < -_EPS:
            return False
        out[0] = t
        out[1] = u
        out[2] = v
        return True
    if k == 2:
        # L(t) R(u) L(v), u <= 0: the circles' centres (0, 1) and (x - sin phi, y + cos phi)
        # are 4 sin(-u/2) apart
        xi = x - sphi
        eta = y - 1.0 + cphi
        r = math.hypot(xi, eta)
        if r > 4.0:
            return False
        theta = math.atan2(eta, xi)
        u = -2.0 * math.asin(0.25 * r)
        t = _mod_pi(theta + 0.5 * u + _PI)
        v = _mod_pi(phi - t + u)
        if t < -_EPS or u > _EPS:
            return False
        out[0] = t
        out[1] = u
        out[2] = v
        return True
    if k == 3 or k == 4:
        xi = x + sphi
        eta = y - 1.0 - cphi
        if k == 3:
            # L(t) R(u) L(-u) R(v), t >= 0, v <= 0
            rho = 0.25 * (2.0 + math.hypot(xi, eta))
            if rho > 1.0:
                return False
            u = math.acos(rho)
            t, v = _tau_omega(u, -u, xi, eta, phi)
            if t < -_EPS or v > _EPS:
                return False
            out[0] = t
            out[1] = u
            out[2] = -u
            out[3] = v
            return True
        # L(t) R(u) L(u) R(v), u in [-pi/2, 0], t >= 0, v >= 0
        rho = (20.0 - xi * xi - eta * eta) / 16.0
        if rho < 0.0 or rho > 1.0:
            return False
        u = -math.acos(rho)
        if u < -_HALF_PI:
            return False
        t, v = _tau_omega(u, u, xi, eta, phi)
        if t < -_EPS or v < -_EPS:
            return False
        out[0] = t
        out[1] = u
        out[2] = u
        out[3] = v
        return True
    if k == 5:
        # L(t) R(-pi/2) S(u) L(v): (x - sin phi, y - 1 + cos phi) = (-2, -(2 - u)) rotated by t,
        # v = phi - t - pi/2; t >= 0, u <= 0, v <= 0
        xi = x - sphi
        eta = y - 1.0 + cphi
        rho = math.hypot(xi, eta)
        if rho < 2.0:
            return False
        r = math.sqrt(rho * rho - 4.0)
        u = 2.0 - r
        t = _mod_pi(math.atan2(eta, xi) + math.atan2(r, -2.0))
        v = _mod_pi(phi - _HALF_PI - t)
        if t < -_EPS or u > _EPS or v > _EPS:
            return False
        out[0] = t
        out[1] = -_HALF_PI
        out[2] = u
        out[3] = v
        return True
    if k == 6:
        # L(t) R(-pi/2) S(u) R(v): (x + sin phi, y - 1 - cos phi) = (2 - u)(sin t, -cos t),
        # v = t + pi/2 - phi; t >= 0, u <= 0, v <= 0
        xi = x + sphi
        eta = y - 1.0 - cphi
        rho = math.hypot(xi, eta)
        if rho < 2.0:
            return False
        t = math.atan2(xi, -eta)
        u = 2.0 - rho
        v = _mod_pi(t + _HALF_PI - phi)
        if t < -_EPS or u > _EPS or v > _EPS:
            return False
        out[0] = t
        out[1] = -_HALF_PI
        out[2] = u
        out[3] = v
        return True
    # k == 7: L(t) R(-pi/2) S(u) L(-pi/2) R(v): with b = 4 - u,
    # (x + sin phi, y - 1 - cos phi) = (b sin t - 2 cos t, -b cos t - 2 sin t), v = t - phi
    xi = x + sphi
    eta = y - 1.0 - cphi
    rho = math.hypot(xi, eta)
    if rho < 2.0:
        return False
    b = math.sqrt(rho * rho - 4.0)
    u = 4.0 - b
    if u > _EPS:
        return False
    t = _mod_pi(math.atan2(b * xi - 2.0 * eta, -2.0 * xi - b * eta))
    v = _mod_pi(t - phi)
    if t < -_EPS or v < -_EPS:
        return False
    out[0] = t
    out[1] = -_HALF_PI
    out[2] = u
    out[3] = -_HALF_PI
    out[4] = v
    return True


# kinds (+1 L, 0 S, -1 R) and segment counts of the base words
_BASE_KINDS = np.array(
    [
        [1, 0, 1, 0, 0],
        [1, 0, -1, 0, 0],
        [1, -1, 1, 0, 0],
        [1, -1, 1, -1, 0],
        [1, -1, 1, -1, 0],
        [1, -1, 0, 1, 0],
        [1, -1, 0, -1, 0],
        [1, -1, 0, 1, -1],
    ],
    dtype=np.int8,
)
_BASE_N = np.array([3, 3, 3, 4, 4, 4, 4, 5], dtype=np.int64)
# whether the backwards (reversed-order) variants of the base word are distinct words
_BASE_BACKWARDS = np.array([False, False, True, False, False, True, True, False])


@njit(cache=True)
def rs_word(x, y, phi, kinds, lens, buf, rev_w, cusp_w, arc_w):  # pragma: no cover - compiled
    """Shortest (or cheapest) Reeds-Shepp word to ``(x, y, phi)`` from the origin, ``R = 1``.

    A word costs ``sum(|s_i| w_i) + cusp_w * cusps`` with ``w_i = rev_w`` (times ``arc_w`` on
    an arc) for a backwards segment and ``1`` (times ``arc_w`` on an arc) forwards; with
    ``rev_w = arc_w = 1`` and ``cusp_w = 0`` that is the length (the shortest word).

    Parameters
    ----------
    x, y, phi : float
        Goal pose in the start's frame, lengths divided by ``R``.
    kinds : ndarray of int8, shape (5,)
        Out: segment kinds (+1 L, 0 S, -1 R).
    lens : ndarray of float64, shape (5,)
        Out: signed segment lengths (units of ``R``).
    buf : ndarray of float64, shape (5,)
        Scratch.

    rev_w, cusp_w, arc_w : float
        Weights of the cost (``cusp_w`` in units of ``R``); ``1, 0, 1`` for the length.

    Returns
    -------
    cost : float
        The word's cost (its length with unit weights), units of ``R`` (``inf`` only on
        non-finite input).
    n : int
        Number of segments written.
    """
    best = np.inf
    nbest = 0
    cphi = math.cos(phi)
    sphi = math.sin(phi)
    xb = x * cphi + y * sphi
    yb = x * sphi - y * cphi
    for k in range(8):
        nseg = _BASE_N[k]
        ntr = 8 if _BASE_BACKWARDS[k] else 4
        for tr in range(ntr):
            back = tr >= 4
            flip = (tr & 1) == 1  # time flip: (-x, y, -phi), lengths negated
            refl = (tr & 2) == 2  # reflection: (x, -y, -phi), L and R swapped
            px = xb if back else x
            py = yb if back else y
            pphi = phi
            psin = sphi
            if flip:
                px = -px
                pphi = -pphi
                psin = -psin
            if refl:
                py = -py
                pphi = -pphi
                psin = -psin
            if not _base_word(k, px, py, pphi, psin, cphi, buf):
                continue
            total = 0.0
            last = 0.0
            for i in range(nseg):
                si = buf[i]
                if si != 0.0:
                    w = rev_w if (si < 0.0) != flip else 1.0
                    if _BASE_KINDS[k, i] != 0:
                        w *= arc_w
                    total += abs(si) * w
                    if last != 0.0 and (last < 0.0) != (si < 0.0):
                        total += cusp_w
                    last = si
            if total < best:
                best = total
                nbest = nseg
                for i in range(nseg):
                    j = nseg - 1 - i if back else i
                    kk = _BASE_KINDS[k, j]
                    kinds[i] = -kk if refl else kk
                    lens[i] = -buf[j] if flip else buf[j]
    return best, nbest


@njit(cache=True)
def _dubins_ccc(x, y, phi, out):  # pragma: no cover - compiled
    """Shortest L(t) R(u) L(v) forwards (mirror image for ``sign = -1``); False if none."""
    # centres of the first and last circles; the middle circle touches both (radius 1 each)
    c1x = 0.0
    c1y = 1.0
    c3x = x - math.sin(phi)
    c3y = y + math.cos(phi)
    dx = c3x - c1x
    dy = c3y - c1y
    d = math.hypot(dx, dy)
    if d > 4.0 or d < 1e-12:
        return False
    theta = math.atan2(dy, dx)
    a = math.acos(0.25 * d)
    best = np.inf
    for side in (-1.0, 1.0):
        # centre of the middle circle at angle t - pi/2 from c1
        ang = theta + side * a
        c2x = c1x + 2.0 * math.cos(ang)
        c2y = c1y + 2.0 * math.sin(ang)
        t = _mod_2pi(ang + _HALF_PI)
        # tangency of circles 2 and 3: heading h there on the right circle 2
        mx = 0.5 * (c2x + c3x) - c2x
        my = 0.5 * (c2y + c3y) - c2y
        h = math.atan2(-mx, my)
        u = _mod_2pi(t - h)
        v = _mod_2pi(phi - h)
        if t + u + v < best:
            best = t + u + v
            out[0] = t
            out[1] = u
            out[2] = v
    return True


@njit(cache=True)
def dubins_word(x, y, phi, kinds, lens, buf, arc_w):  # pragma: no cover - compiled
    """Shortest (or cheapest) Dubins word (forwards only) to ``(x, y, phi)``, ``R = 1``.

    Same arguments and returns as :func:`rs_word` (arcs weigh ``arc_w``, 1 for the length);
    every length is ``>= 0`` and ``n = 3``.
    """
    best = np.inf
    for fam in range(3):  # 0: C S C same side, 1: C S C opposite sides, 2: C C C
        for refl in (False, True):
            py = -y if refl else y
            pphi = -phi if refl else phi
            sp = math.sin(pphi)
            cp = math.cos(pphi)
            ok = False
            if fam == 0:
                xi = x - sp
                eta = py - 1.0 + cp
                buf[0] = _mod_2pi(math.atan2(eta, xi))
                buf[1] = math.hypot(xi, eta)
                buf[2] = _mod_2pi(pphi - buf[0])
                ok = True
            elif fam == 1:
                xi = x + sp
                eta = py - 1.0 - cp
                r2 = xi * xi + eta * eta
                if r2 >= 4.0:
                    u = math.sqrt(r2 - 4.0)
                    buf[0] = _mod_2pi(math.atan2(eta, xi) + math.atan2(2.0, u))
                    buf[1] = u
                    buf[2] = _mod_2pi(buf[0] - pphi)
                    ok = True
            else:
                ok = _dubins_ccc(x, py, pphi, buf)
            if not ok:
                continue
            total = (buf[0] + buf[2]) * arc_w + buf[1] * (arc_w if fam == 2 else 1.0)
            if total < best:
                best = total
                s = -1 if refl else 1
                kinds[0] = s
                kinds[1] = 0 if fam < 2 else -s
                kinds[2] = s if fam != 1 else -s
                lens[0] = buf[0]
                lens[1] = buf[1]
                lens[2] = buf[2]
    return best, 3


@njit(cache=True)
def car_word(
    x0, y0, th0, x1, y1, th1, radius, reverse, kinds, lens, buf, rev_w, cusp_w, arc_w
):  # pragma: no cover - compiled
    """Shortest (or cheapest) car path between two poses: Reeds-Shepp (``reverse``) or Dubins.

    Parameters
    ----------
    x0, y0, th0, x1, y1, th1 : float
        Start and goal poses (lengths in any unit, headings in radians).
    radius : float
        Turning radius ``R`` (same unit), ``> 0``.
    reverse : bool
        True: Reeds-Shepp (backwards allowed); False: Dubins.
    kinds, lens, buf : ndarray, shape (5,)
        Out: kinds (int8) and signed lengths (float64, unit of ``R``); scratch (float64).
    rev_w, cusp_w, arc_w : float
        Cost weights (:func:`rs_word`; ``cusp_w`` in the unit of ``R``); ``1, 0, 1``: the
        shortest path.

    Returns
    -------
    cost : float
        Its cost (the length with unit weights), unit of ``R``.
    n : int
        Number of segments.
    """
    dx = x1 - x0
    dy = y1 - y0
    c = math.cos(th0)
    s = math.sin(th0)
    x = (c * dx + s * dy) / radius
    y = (-s * dx + c * dy) / radius
    phi = _mod_pi(th1 - th0)
    if reverse:
        total, n = rs_word(x, y, phi, kinds, lens, buf, rev_w, cusp_w / radius, arc_w)
    else:
        total, n = dubins_word(x, y, phi, kinds, lens, buf, arc_w)
    for i in range(n):
        lens[i] *= radius
    return total * radius, n


@njit(cache=True, inline="always")
def advance(x, y, th, kappa, s):  # pragma: no cover - compiled
    """Pose after signed arc length ``s`` at curvature ``kappa`` (closed form)."""
    if kappa == 0.0:
        return x + s * math.cos(th), y + s * math.sin(th), th
    th1 = th + kappa * s
    return (
        x + (math.sin(th1) - math.sin(th)) / kappa,
        y - (math.cos(th1) - math.cos(th)) / kappa,
        th1,
    )


@njit(cache=True, inline="always")
def _pieces(s, step):  # pragma: no cover - compiled
    """Return the number of sub-steps of a segment of length ``|s|`` (0 if empty)."""
    if s == 0.0:
        return 0
    return max(1, int(math.ceil(abs(s) / step - 1e-9)))


@njit(cache=True)
def sample_word(x0, y0, th0, radius, kinds, lens, n, step):  # pragma: no cover - compiled
    """Poses along a word at spacing ``<= step``, segment ends included.

    Returns
    -------
    poses : ndarray of float64, shape (m, 3)
        ``(x, y, heading)``, heading unwrapped; the first is the start. Empty segments add
        no pose.
    seg : ndarray of int64, shape (m,)
        Index of the segment leading to each pose (for the start: the first non-empty one).
    """
    count = 1
    for i in range(n):
        count += _pieces(lens[i], step)
    poses = np.empty((count, 3))
    seg = np.zeros(count, dtype=np.int64)
    for i in range(n):
        if lens[i] != 0.0:
            seg[0] = i
            break
    poses[0, 0] = x0
    poses[0, 1] = y0
    poses[0, 2] = th0
    j = 1
    x = x0
    y = y0
    th = th0
    for i in range(n):
        m = _pieces(lens[i], step)
        kappa = kinds[i] / radius
        for q in range(1, m + 1):
            px, py, pth = advance(x, y, th, kappa, lens[i] * q / m)
            poses[j, 0] = px
            poses[j, 1] = py
            poses[j, 2] = pth
            seg[j] = i
            j += 1
        x, y, th = advance(x, y, th, kappa, lens[i])
    return poses, seg


# --------------------------------------------------------------------------- public API
@dataclass(frozen=True, slots=True, eq=False)
class CarPath:
    """A shortest path of a car with turning radius ``R``: a word of arcs and segments.

    Parameters
    ----------
    start, goal : tuple of float
        Poses ``(x, y, heading)``: lengths in the unit of ``turning_radius``, heading in
        radians counter-clockwise from ``+x``.
    turning_radius : float
        ``R`` (> 0).
    kinds : str
        One letter per segment: ``L`` (curvature ``+1/R``), ``S`` (0), ``R`` (``-1/R``).
    lengths : ndarray of float64, shape (n,)
        Signed length of each segment (unit of ``R``): ``> 0`` forwards, ``< 0`` backwards.
        Read-only.

    Attributes
    ----------
    length : float
        ``sum(abs(lengths))``.
    """

    start: tuple[float, float, float]
    goal: tuple[float, float, float]
    turning_radius: float
    kinds: str
    lengths: np.ndarray

    def __post_init__(self) -> None:
        arr = np.array(self.lengths, dtype=np.float64, copy=True)
        arr.flags.writeable = False
        object.__setattr__(self, "lengths", arr)

    @property
    def length(self) -> float:
        """Total length (unit of ``R``)."""
        return float(np.abs(self.lengths).sum())

    @property
    def directions(self) -> np.ndarray:
        """Direction of travel per segment, shape ``(n,)``: ``+1`` forwards, ``-1`` backwards."""
        return np.where(self.lengths < 0.0, -1, 1).astype(np.int8)

    @property
    def curvatures(self) -> np.ndarray:
        """Signed curvature per segment, shape ``(n,)`` (``+-1/R`` or 0, unit ``1/unit``)."""
        return np.array([{"L": 1.0, "S": 0.0, "R": -1.0}[c] for c in self.kinds]) / (
            self.turning_radius
        )

    @property
    def cusps(self) -> int:
        """Number of changes of direction between consecutive non-empty segments."""
        d = self.directions[np.abs(self.lengths) > 0.0]
        return int(np.count_nonzero(d[1:] != d[:-1]))

    def sample(self, step: float) -> tuple[np.ndarray, np.ndarray]:
        """Poses along the path at spacing ``<= step``, every segment's end included.

        Parameters
        ----------
        step : float
            Largest arc length between consecutive poses (unit of ``R``), ``> 0``.

        Returns
        -------
        poses : ndarray of float64, shape (m, 3)
            ``(x, y, heading)`` from ``start`` to the end of the word (heading unwrapped,
            radians); the last pose equals ``goal`` up to rounding (about 1e-12 R).
        directions : ndarray of int8, shape (m,)
            Direction of travel of the segment leading to each pose (the first pose: that of
            the first segment).
        """
        step = validation.positive_float("step", step)
        kinds = np.array([{"L": 1, "S": 0, "R": -1}[c] for c in self.kinds], dtype=np.int8)
        poses, seg = sample_word(
            *self.start, self.turning_radius, kinds, self.lengths, len(self.kinds), step
        )
        return poses, self.directions[seg] if len(self.kinds) else np.ones(1, np.int8)

    def __repr__(self) -> str:
        segs = " ".join(f"{c}{s:+.4g}" for c, s in zip(self.kinds, self.lengths, strict=True))
        return f"CarPath({segs}, length={self.length:.6g}, R={self.turning_radius:g})"


def _pose(name: str, value: object) -> tuple[float, float, float]:
    """Return a finite pose ``(x, y, heading)``."""
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise InvalidInputError(
            f"{name} must be a pose (x, y, heading) of three numbers, got {value!r}"
        ) from None
    if a.shape != (3,):
        raise InvalidInputError(
            f"{name} must be a pose (x, y, heading) of three numbers, got shape {a.shape}"
        )
    if not np.all(np.isfinite(a)):
        raise InvalidInputError(f"{name} must be finite, got {a.tolist()}")
    return float(a[0]), float(a[1]), float(a[2])


def _car_path(start: object, goal: object, turning_radius: object, reverse: bool) -> CarPath:
    s = _pose("start", start)
    g = _pose("goal", goal)
    r = validation.positive_float("turning_radius", turning_radius)
    kinds = np.zeros(5, np.int8)
    lens = np.zeros(5)
    buf = np.zeros(5)
    _, n = car_word(*s, *g, r, reverse, kinds, lens, buf, 1.0, 0.0, 1.0)
    letters = "".join(_LETTERS[int(k)] for k in kinds[:n])
    return CarPath(s, g, r, letters, lens[:n])


def reeds_shepp_path(start: object, goal: object, turning_radius: float) -> CarPath:
    """Shortest path of a car that drives forwards and backwards (Reeds-Shepp).

    Parameters
    ----------
    start, goal : array_like of float, shape (3,)
        Poses ``(x, y, heading)``: ``x, y`` in any unit (that of ``turning_radius``), heading
        in radians counter-clockwise from ``+x``.
    turning_radius : float
        Minimum turning radius ``R`` (same unit), finite and ``> 0``.

    Returns
    -------
    CarPath
        The word (at most five segments, at most two cusps) and its signed lengths.

    Raises
    ------
    InvalidInputError
        A pose is not three finite numbers; ``turning_radius`` is not finite and ``> 0``.

    Examples
    --------
    >>> p = reeds_shepp_path((0, 0, 0), (-3, 0, 0), 1.0)
    >>> p.kinds, p.length, p.cusps, p.directions[1]
    ('LSL', 3.0, 0, np.int8(-1))
    """
    return _car_path(start, goal, turning_radius, True)


def dubins_path(start: object, goal: object, turning_radius: float) -> CarPath:
    """Shortest forwards-only path of a car (Dubins).

    Parameters
    ----------
    start, goal : array_like of float, shape (3,)
        Poses ``(x, y, heading)`` (unit of ``turning_radius``; heading in radians).
    turning_radius : float
        Minimum turning radius ``R``, finite and ``> 0``.

    Returns
    -------
    CarPath
        Three segments, every length ``>= 0``.

    Raises
    ------
    InvalidInputError
        A pose is not three finite numbers; ``turning_radius`` is not finite and ``> 0``.

    Examples
    --------
    >>> p = dubins_path((0, 0, 0), (4, 0, 0), 1.0)
    >>> p.kinds, p.lengths.tolist()
    ('LSL', [0.0, 4.0, 0.0])
    """
    return _car_path(start, goal, turning_radius, False)
