"""The footprint side of a fit: its certificate, pinned end headings and the SCP rounds.

With a robot footprint, :meth:`~trajopt.smoother.Smoother.fit` accepts a curve only when
:func:`trajopt.robot._footprint.certify_footprint` passes too. When only that fails:

1. **End headings.** If an end span fails and that end's heading is free, the heading is
   pinned (once per end) to the one nearest the curve's own end tangent among
   :data:`END_HEADINGS` sampled headings at which the footprint on the fixed end point is
   well clear of the raw map (at least half the best clearance found, capped at a cell), and
   the knots are solved again: no row can move a fixed end point.
2. **SCP rounds** (polygon corridors, no curvature bound): :func:`footprint_scp` solves the
   same knots again with the corner rows of :class:`~trajopt.smoother._footprint_scp.
   FootprintSCP` on the failing spans, up to :data:`FOOTPRINT_ROUNDS` times, certifying
   every round's curve.
3. Otherwise, the knots are refined as for any failed certificate.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from trajopt.robot import Footprint, FootprintCertificate, certify_footprint, polygons_clearance
from trajopt.smoother._cost import CostField, CostTerm, cost_scale, linearised
from trajopt.smoother._footprint_scp import FootprintSCP, corners_cells
from trajopt.smoother._problem import Problem, assemble, project_heading

if TYPE_CHECKING:
    from trajopt.smoother._options import Smoother

#: most SCP rounds on one knot vector (then the knots are refined)
FOOTPRINT_ROUNDS = 4
#: each SCP round moves every control point coordinate by at most this many cells
TRUST_CELLS = 2.0
#: headings sampled at a fixed end point whose footprint collides
END_HEADINGS = 72


class FootprintRounds:
    """The footprint state of one fit.

    Parameters
    ----------
    footprint : Footprint
    raw_grid : astar.OccupancyGrid
    res : float
        Metres per cell.
    start_heading, goal_heading : float or None
        The fit's end headings (rad); ``None`` ends may be pinned.

    Attributes
    ----------
    start_heading, goal_heading : float or None
        The end headings, as pinned.
    rounds, time_s : int, float
        Pins and SCP rounds run, and the footprint certificates' time (s), over the fit.
    """

    def __init__(
        self,
        footprint: Footprint,
        raw_grid: Any,
        res: float,
        start_heading: float | None,
        goal_heading: float | None,
    ) -> None:
        self.footprint, self.raw_grid, self.res = footprint, raw_grid, float(res)
        self.start_heading, self.goal_heading = start_heading, goal_heading
        self._free = [start_heading is None, goal_heading is None]
        self._before: tuple[float | None, float | None] = (start_heading, goal_heading)
        self.rounds, self.time_s = 0, 0.0

    def certify(self, curve: Any) -> FootprintCertificate:
        """Return the footprint certificate of ``curve`` (timed into :attr:`time_s`)."""
        t0 = time.perf_counter()
        out = certify_footprint(curve, self.footprint, self.raw_grid)
        self.time_s += time.perf_counter() - t0
        return out

    def pin(
        self, cert: FootprintCertificate, c_cells: np.ndarray, ends_m: tuple[np.ndarray, np.ndarray]
    ) -> bool:
        """Pin a free end heading whose end span failed ``cert``; ``True`` if one was pinned.

        ``c_cells``: the failed curve's control points (their end directions are its end
        tangents); ``ends_m``: its end points (m).
        """
        m = cert.margins_m
        if len(m) == 0:
            return False
        for end, (span, a, b) in enumerate(((0, 0, 1), (len(m) - 1, -2, -1))):
            if not (self._free[end] and m[span] <= 0.0):
                continue
            self._free[end] = False  # one try per end
            d = c_cells[b] - c_cells[a]
            theta = _nearest(
                *end_headings(self.footprint, self.raw_grid, ends_m[end]), math.atan2(d[1], d[0])
            )
            if theta is None:
                continue
            self._before = (self.start_heading, self.goal_heading)
            if end == 0:
                self.start_heading = theta
            else:
                self.goal_heading = theta
            self.rounds += 1
            return True
        return False

    def unpin(self) -> None:
        """Undo the last :meth:`pin`."""
        self.start_heading, self.goal_heading = self._before


def footprint_scp(
    options: Smoother,
    prob: Problem,
    h: float,
    c_cells: np.ndarray,
    cert: FootprintCertificate,
    fp: FootprintRounds,
    r_cells: float,
    check: Callable[..., tuple],
    cost_at: tuple[CostField, np.ndarray] | None = None,
) -> tuple | None:
    """Run the SCP rounds on the knots of span ``h`` from the failed curve ``c_cells``.

    ``check(c_cells, knots, span_box)`` returns ``(curve, certificate, footprint
    certificate)``. Returns that triple for the first round whose certificates both pass,
    or ``None`` (a QP failed, the disc certificate failed, or the rounds ran out). With a
    cost field (``cost_at``: the field and the corridor's origin, m) each round minimises
    the objective with the cost term's convex model around the round's start
    (:func:`~trajopt.smoother._cost.linearised`), as the cost rounds do.
    """
    asm = assemble(options, prob, h)
    p, n, nb = options.degree, asm.qp.n, asm.qp.nb
    term = None
    if cost_at is not None:
        scale = cost_scale(options, prob.taut)
        term = CostTerm.on_knots(cost_at[0], cost_at[1], prob.res, asm.knots, p, nb, scale)
    scp = FootprintSCP(
        asm, prob, corners_cells(fp.footprint, fp.res), r_cells, p, options.speed_floor
    )
    spans = None
    c = np.asarray(c_cells, dtype=float)
    for _ in range(FOOTPRINT_ROUNDS):
        fp.rounds += 1
        spans = spans_to_tighten(cert.margins_m, n - p, p, spans)
        scp.activate(spans)
        z = np.zeros(2 * nb)
        z[:n], z[nb : nb + n] = c[:, 0], c[:, 1]
        scp.linearise(z)
        objective = None if term is None else linearised(asm.qp, term, z)
        znew, _ = scp.solve(z, TRUST_CELLS, objective)
        if znew is None:
            return None
        c = np.column_stack([znew[:n], znew[nb : nb + n]])
        project_heading(c, prob, asm.lo, asm.hi, asm.point_rows, asm.start_alpha)
        curve, disc, cert = check(c, asm.knots, asm.span_box)
        if not disc.ok:
            return None
        if cert.ok:
            return curve, disc, cert
    return None


def spans_to_tighten(
    margins_m: np.ndarray, n_spans: int, degree: int, previous: np.ndarray | None
) -> np.ndarray:
    """Return the spans that get footprint rows: the failing ones, ``p`` spans around each.

    ``margins_m``: the footprint certificate's margin per span (a length other than
    ``n_spans``, the curve's span count, marks every span). ``previous``: the spans of
    the earlier rounds on the same knots, kept.
    """
    p = int(degree)
    if len(margins_m) != n_spans:
        return np.ones(n_spans, dtype=bool)
    out = np.zeros(n_spans, dtype=bool) if previous is None else previous.copy()
    for j in np.flatnonzero(np.asarray(margins_m) <= 0.0):
        out[max(0, j - p) : j + p + 1] = True
    return out


def end_headings(
    footprint: Footprint, raw_grid: Any, point: np.ndarray, cap_m: float | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Return :data:`END_HEADINGS` sampled headings (rad) and the footprint's clearance there (m).

    The exact clearance of the footprint placed on ``point`` (m) at each heading in
    ``[-pi, pi)``, capped at ``cap_m`` (default one cell).
    """
    ths = -math.pi + 2 * math.pi * np.arange(END_HEADINGS) / END_HEADINGS
    polys = [footprint.at(float(point[0]), float(point[1]), float(t)) for t in ths]
    cap = raw_grid.resolution if cap_m is None else cap_m
    return ths, polygons_clearance(polys, raw_grid, cap)


def _nearest(headings: np.ndarray, clearance: np.ndarray, theta: float) -> float | None:
    """Return the well-clear heading nearest ``theta`` on the circle (``None``: none clear).

    Well clear: a clearance of at least half the best one found (at most a cell), so that
    the curve leaving the end has room to turn.
    """
    best = float(clearance.max(initial=0.0))
    if best <= 0.0:
        return None
    ok = clearance >= 0.5 * best
    diff = np.abs(np.remainder(headings[ok] - theta + math.pi, 2 * math.pi) - math.pi)
    return float(headings[ok][int(np.argmin(diff))])
