"""The exceptions of :mod:`trajopt`: one hierarchy, every failure typed.

``TrajoptError`` is the base of everything :mod:`trajopt` raises on purpose.
``InvalidInputError`` and ``NoPathError`` also derive from their :mod:`astar`
counterparts (and ``InvalidInputError`` from :class:`ValueError`), so one ``except``
clause catches a failure whichever stage raised it.
"""

from __future__ import annotations

from typing import Any

import astar.errors as _astar_errors

__all__ = [
    "TrajoptError",
    "InvalidInputError",
    "IllPosedFitError",
    "NoPathError",
    "SmoothingError",
    "TimingError",
    "BlockedError",
    "BenchmarkError",
    "PeerUnavailableError",
]


class TrajoptError(Exception):
    """Base class of every exception raised by :mod:`trajopt`."""


class InvalidInputError(TrajoptError, _astar_errors.InvalidInputError):
    """An argument breaks a documented rule (the message names the field, value and rule)."""


class IllPosedFitError(InvalidInputError):
    """The data cannot determine the requested plain fit.

    Raised by :func:`trajopt.fits.fit_bspline` when there are more control points than
    distinct points, the Schoenberg-Whitney condition fails, the collocation matrix is
    numerically singular (condition number above :data:`trajopt.fits.BSPLINE_COND_MAX`), or
    the solution swings: a control point lies more than :data:`trajopt.fits.BSPLINE_SWING_MAX`
    times the data's extent outside the data's bounding box. :func:`trajopt.compare` records
    such a fit as invalid with this message, and :func:`trajopt.fits.sweep_bspline` lists it
    as an invalid record with the message as its reason.
    """


class NoPathError(TrajoptError, _astar_errors.NoPathError):
    """The grid search found no path between start and goal."""


class SmoothingError(TrajoptError):
    """The smoother could not produce a curve meeting every guarantee.

    Attributes
    ----------
    stats : dict
        Solver statistics of the last attempt (status, iterations, time, ...).
    """

    def __init__(self, message: str, stats: dict[str, Any] | None = None) -> None:
        super().__init__(message)
        self.stats: dict[str, Any] = dict(stats or {})


class TimingError(TrajoptError):
    """The time parameterisation cannot meet the requested boundary speeds or limits."""


class BlockedError(TrajoptError):
    """A moving obstacle blocks the way: no motion avoids it within its prediction.

    Attributes
    ----------
    mover : str
        The name of the blocking :class:`trajopt.MovingObstacle`.
    t : float
        The time (s, the trajectory's clock) from which nothing avoids it.
    """

    def __init__(self, message: str, mover: str = "", t: float = 0.0) -> None:
        super().__init__(message)
        self.mover = mover
        self.t = float(t)


class BenchmarkError(InvalidInputError):
    """A benchmark run cannot start.

    A missing map or scenario file, a scenario file for another map size, an unknown method or
    suite, an unreachable Dask scheduler, or an output dataset that does not match the run.
    Raised before any query is planned; the message names the input, its value and the rule.
    """


class PeerUnavailableError(BenchmarkError):
    """A peer method was requested but its package is not installed.

    The peers are OMPL and python-motion-planning; the message says to install the ``peers``
    extra (``pip install 'trajopt[peers]'``).
    """
