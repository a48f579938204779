"""Analysis around the planner: metrics, the chapter's plain fits, comparison, benchmarks, plots.

Public modules, each also reachable as ``trajopt.<name>``: :mod:`~trajopt.analysis.metrics`,
:mod:`~trajopt.analysis.fits`, :mod:`~trajopt.analysis.comparison`,
:mod:`~trajopt.analysis.bench`, :mod:`~trajopt.analysis.scenes` and
:mod:`~trajopt.analysis.plotting` (matplotlib).
"""
