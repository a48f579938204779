"""What a benchmark method hands back: a :class:`MethodOutput`, or a :class:`PeerFailure`.

A :class:`PeerFailure` is raised when a peer planner finds no solution. Both types are shared
by :mod:`~trajopt.analysis.bench._methods` (which scores outputs and turns a ``PeerFailure``
into a row) and :mod:`~trajopt.analysis.bench._peers` (which makes them), so neither of those
modules imports the other for its types.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any


@dataclass(frozen=True, slots=True)
class MethodOutput:
    """What a method returns for one query.

    Attributes
    ----------
    path : ParametricCurve or ndarray (n, 2) or None
        The path in metres (``None``: no path, metrics are NaN).
    valid : bool
        The method's own validity verdict (e.g. a fit the data cannot determine).
    note : str
        Free text.
    extras : Mapping[str, Any]
        Columns of the row this method fills (``duration_s``, ``stage_smooth_s``, ...).
    runtime_s : float or None
        Compute time (s); default the wall time of the call.
    score_s : float
        Time the method spent scoring its own output (s): the trajopt variants'
        :func:`~trajopt.metrics.trajectory_metrics`; not part of ``runtime_s``.
    """

    path: Any
    valid: bool = True
    note: str = ""
    extras: Mapping[str, Any] = field(default_factory=dict)
    runtime_s: float | None = None
    score_s: float = 0.0


class PeerFailure(RuntimeError):
    """A peer planner returned no solution for a query (a row value, not a crash)."""
