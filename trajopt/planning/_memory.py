"""The memory a planner needs for a map, checked before anything is allocated.

A planner's memory grows with the map's cell count: the raw and inflated grids, the
connected components, the search cost and the search's per-cell records, the coarse search's
blocks, the temporaries of the inflation and of the clearance cost, and the ALT landmarks'
distances. :func:`estimate_memory` counts them from the map's shape and the options;
:func:`check_memory` refuses a map whose estimate exceeds the memory available, naming the
estimate and the settings that lower it, instead of failing halfway through an allocation.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from trajopt.errors import InvalidInputError
from trajopt.planning._options import PlannerOptions

#: bytes per cell with a search cost: grids 2, components 4, cost 8, search records 16,
#: inflation and clearance-cost temporaries about 20, coarse blocks and band mask about 4
#: (peak of the allocations traced over plans on the willow map split 2 x 2 and 4 x 4: 38
#: per cell, plus the 16 of the search records, which a process allocates once)
BYTES_PER_CELL_COST = 54
#: bytes per cell with ``search="shortest"`` (no cost field, no clearance-cost temporaries)
BYTES_PER_CELL_SHORTEST = 26
#: bytes per cell per ALT landmark (its float64 distances and the build's temporaries)
BYTES_PER_CELL_LANDMARK = 17
#: the interpreter, NumPy, numba's kernels, CasADi and the solvers (bytes)
BASE_BYTES = 300 * 2**20


@dataclass(frozen=True, slots=True)
class MemoryEstimate:
    """What a planner needs for a map (bytes).

    Attributes
    ----------
    cells : int
        The map's cell count.
    per_cell : int
        Bytes per cell for these options.
    total : int
        ``BASE_BYTES + cells * per_cell``.
    """

    cells: int
    per_cell: int
    total: int


def estimate_memory(shape: tuple[int, int], options: PlannerOptions) -> MemoryEstimate:
    """Return the memory a planner with ``options`` needs for a map of ``shape`` cells.

    An upper estimate: the peak of the allocations (pages reserved, touched or not) of a
    new planner's first queries, measured on the shared maps; the resident memory measured
    is lower (``benchmarks/bench_scale.py --memory``).
    """
    cells = int(shape[0]) * int(shape[1])
    per = BYTES_PER_CELL_SHORTEST if options.search == "shortest" else BYTES_PER_CELL_COST
    if options.search != "shortest":
        per += BYTES_PER_CELL_LANDMARK * options.landmarks
    return MemoryEstimate(cells=cells, per_cell=per, total=BASE_BYTES + cells * per)


def available_memory() -> int | None:
    """Return the memory this process may still use (bytes), or ``None`` if unknown.

    The smaller of the system's available memory (``MemAvailable`` of ``/proc/meminfo``)
    and the room left under a cgroup v2 limit (``memory.max`` minus ``memory.current``).
    """
    found: list[int] = []
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                found.append(int(line.split()[1]) * 1024)
                break
    except (OSError, ValueError, IndexError):
        pass
    cg = Path("/sys/fs/cgroup")
    try:
        limit = (cg / "memory.max").read_text().strip()
        if limit != "max":
            found.append(int(limit) - int((cg / "memory.current").read_text().strip()))
    except (OSError, ValueError):
        pass
    if not found:
        try:
            found.append(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
        except (ValueError, OSError, AttributeError):
            return None
    return max(0, min(found))


def check_memory(shape: tuple[int, int], options: PlannerOptions) -> MemoryEstimate:
    """Return :func:`estimate_memory`, or refuse a map it says does not fit.

    Raises
    ------
    InvalidInputError
        The estimate exceeds :func:`available_memory`: the message gives both, the cell
        count, and the settings that lower the estimate (a coarser map,
        ``grid.coarsen(k)``; ``landmarks=0``; ``search="shortest"``).
    """
    est = estimate_memory(shape, options)
    room = available_memory()
    if room is None or est.total <= room:
        return est
    gib = 2.0**30
    knobs = ["plan on grid.coarsen(2) (a quarter of the cells; conservative)"]
    if options.landmarks:
        knobs.append(f"landmarks=0 (saves {BYTES_PER_CELL_LANDMARK * options.landmarks} B/cell)")
    if options.search != "shortest":
        saved = BYTES_PER_CELL_COST - BYTES_PER_CELL_SHORTEST
        knobs.append(f'search="shortest" (saves {saved} B/cell, loses the clearance cost)')
    raise InvalidInputError(
        f"grid of {shape[1]} x {shape[0]} = {est.cells:,} cells needs about "
        f"{est.total / gib:.2f} GiB ({est.per_cell} B/cell with search={options.search!r}, "
        f"landmarks={options.landmarks}), more than the {room / gib:.2f} GiB available; "
        "lower it with " + ", or ".join(knobs)
    )
