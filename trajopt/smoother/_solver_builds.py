"""The smoother's solver builds: one lock around them and which were built in this process.

The convex QP (:mod:`~trajopt.smoother._qp`) and the IPOPT problems
(:mod:`~trajopt.smoother._nlp`) are CasADi solvers built once per padded size and cached for
the process. CasADi's builders are not thread safe, so every build holds :data:`LOCK`; the
first build of a size takes long enough to be reported apart from the solve
(``SolveInfo.build_time_s``), and :func:`is_built` tells a solve whether it paid for one.
"""

from __future__ import annotations

import threading

#: Held by every CasADi solver build of the smoother (``casadi.conic``, ``casadi.nlpsol``).
LOCK = threading.Lock()

_BUILT: set[tuple[str, int, int, bool]] = set()


def is_built(kind: str, nb: int, p: int, verbose: bool) -> bool:
    """Return whether the solver ``(kind, nb, p, verbose)`` was built before in this process.

    The solver is marked built by the call, so that its build time is counted once.

    Parameters
    ----------
    kind : str
        Which solver (e.g. ``"curv"`` for the curvature NLP, ``"piqp-0-2"`` for a QP).
    nb : int
        Padded number of control points.
    p : int
        Degree of the B-spline.
    verbose : bool
        Whether the solver prints (a separate build).

    Returns
    -------
    bool
        ``True`` when an earlier call asked for the same key.
    """
    key = (kind, nb, p, verbose)
    if key in _BUILT:
        return True
    _BUILT.add(key)
    return False
