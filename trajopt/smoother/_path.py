"""The smoother's result: a certified B-spline that is a :class:`~trajopt.geometry._curve.ParametricCurve`."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from trajopt.geometry import BSplineCurve, ParametricCurve
from trajopt.smoother._certificate import Certificate


@dataclass(frozen=True, slots=True, eq=False)
class SmoothPath(ParametricCurve):
    """A certified smooth path: a :class:`~trajopt.geometry._bspline.BSplineCurve` plus evidence.

    The :class:`~trajopt.geometry._curve.ParametricCurve` interface (``__call__(u, nu)``, ``heading``,
    ``curvature``, ``length``, ``u_at_s``, ``sample``) delegates to :attr:`curve`; ``u`` is
    in metres (arc length of the A* polyline) and positions are world metres.

    Attributes
    ----------
    curve : BSplineCurve
        The clamped B-spline in world coordinates.
    stats : dict
        Solver statistics: ``status``, ``success``, ``solver``, ``iterations``,
        ``solve_time_s`` (solver calls), ``build_time_s`` (solvers built in this call),
        ``total_time_s``, ``cost``, ``attempts``, ``n_control_points``, ``padded_size``.
    certificate : Certificate
    footprint_certificate : FootprintCertificate or None
        With a robot footprint (:meth:`Smoother.fit`'s ``footprint``): its certificate.
    """

    curve: BSplineCurve
    stats: dict[str, Any] = field(default_factory=dict)
    certificate: Certificate | None = None
    footprint_certificate: Any = None

    @property
    def domain(self) -> tuple[float, float]:
        """Parameter interval ``(u0, u1)`` of the curve."""
        return self.curve.domain

    def __call__(self, u: np.ndarray | float, nu: int = 0) -> np.ndarray:
        """Evaluate the ``nu``-th derivative at ``u``, shape ``(..., 2)``."""
        return self.curve(u, nu)

    def breakpoints(self) -> np.ndarray:
        """Return the parameters where the polynomial pieces meet (with the ends)."""
        return self.curve.breakpoints()

    def _arc_table(self):
        return self.curve._arc_table()

    def refine_u_at_s(self, s: np.ndarray, u: np.ndarray) -> np.ndarray:
        """Refine first guesses ``u`` at arc lengths ``s`` (m): the B-spline's (compiled)."""
        return self.curve.refine_u_at_s(s, u)

    @property
    def control_points(self) -> np.ndarray:
        """Control points, shape (n, 2) (m, read-only)."""
        return self.curve.c

    @property
    def knots(self) -> np.ndarray:
        """Knot vector, shape (n + k + 1,) (m, read-only)."""
        return self.curve.t

    @property
    def degree(self) -> int:
        """Spline degree."""
        return self.curve.k

    @property
    def polynomial_degree(self) -> int:
        """Degree of the polynomial pieces (the curvature bound uses it)."""
        return self.curve.k
