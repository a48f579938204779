"""numba options of the timing's inner-loop kernels.

The kernels that the greedy and the cap bound call in their inner loops take arrays and
allocate nothing; compiled without numba's reference counting (its ``_nrt=False`` option),
they skip the atomic increments and decrements of every array they are handed, which took
most of those loops' time. ``_nrt`` is one of numba's own (underscored) target options:
when a numba release no longer knows it, the kernels are compiled with reference counting
(the same results, slower) instead of failing.
"""

from __future__ import annotations


def _no_refcount() -> dict[str, bool]:
    try:
        from numba.core.cpu import CPUTargetOptions
    except ImportError:  # pragma: no cover - a numba without that module
        return {}
    return {"_nrt": False} if hasattr(CPUTargetOptions, "_nrt") else {}


#: Keyword arguments of ``numba.njit`` for kernels that allocate nothing.
NO_REFCOUNT: dict[str, bool] = _no_refcount()
