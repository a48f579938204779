"""Argument checks shared by the modules of :mod:`astar`.

Every checker takes the field's ``name`` first and the ``value`` second (as
:mod:`trajopt.validation`), returns the cleaned value, or raises
:class:`~astar.errors.InvalidInputError` whose message names the field, the value and the
rule, so that every public function of :mod:`astar` reports bad input the same way.

This module does not import :mod:`astar.grid` (which builds on it): the check of a ``grid``
argument is :func:`astar.grid.check_grid`.
"""

from __future__ import annotations

import math
import reprlib
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from astar.errors import InvalidInputError

if TYPE_CHECKING:  # pragma: no cover
    from astar.grid import OccupancyGrid  # annotations only: astar.grid imports this module

__all__ = [
    "bool_grid",
    "cell",
    "cell_costs",
    "choice",
    "float_at_least",
    "int_at_least",
    "integer_values",
    "nonnegative_float",
    "nonnegative_int",
    "origin",
    "positive_float",
    "short_repr",
]

_REPR = reprlib.Repr()
_REPR.maxlevel = 2
_REPR.maxlist = _REPR.maxtuple = _REPR.maxdict = 4
_REPR.maxstring = 80
_REPR.maxother = 80


def short_repr(value: object) -> str:
    """Return a bounded repr for error messages.

    YAML aliases can make a tiny file describe a structure with billions of elements (a
    "billion laughs" document), whose full repr would never finish.
    """
    return _REPR.repr(value)


def positive_float(name: str, value: object, *, allow_bool: bool = False) -> float:
    """Return a finite float ``> 0``.

    Booleans are not numbers, except with ``allow_bool`` (the rule of
    :class:`~astar.grid.OccupancyGrid`'s ``resolution``, which has always taken ``True``
    as ``1.0``).
    """
    if isinstance(value, bool) and not allow_bool:
        raise InvalidInputError(f"{name} must be a number, got {value!r}")
    try:
        v = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise InvalidInputError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(v) or v <= 0.0:
        raise InvalidInputError(f"{name} must be finite and > 0, got {v!r}")
    return v


def nonnegative_float(name: str, value: object, unit: str) -> float:
    """Return a finite float ``>= 0``; ``unit`` (e.g. ``"metres"``) is named in the message."""
    if isinstance(value, bool):
        raise InvalidInputError(f"{name} must be a number ({unit}), got {value!r}")
    try:
        v = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise InvalidInputError(f"{name} must be a number ({unit}), got {value!r}") from None
    if not math.isfinite(v) or v < 0.0:
        raise InvalidInputError(f"{name} must be finite and >= 0 ({unit}), got {v!r}")
    return v


def nonnegative_int(name: str, value: object) -> int:
    """Return an ``int`` (or NumPy integer, not a bool) ``>= 0``."""
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise InvalidInputError(f"{name} must be an int, got {value!r}")
    v = int(value)
    if v < 0:
        raise InvalidInputError(f"{name} must be >= 0, got {v}")
    return v


def float_at_least(name: str, value: object, lo: float, rule: str) -> float:
    """Return a finite float ``>= lo``; ``rule`` (e.g. ``">= 1"``) is named in the message."""
    if isinstance(value, bool):
        raise InvalidInputError(f"{name} must be a number, got {value!r}")
    try:
        v = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise InvalidInputError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(v) or v < lo:
        raise InvalidInputError(f"{name} must be finite and {rule}, got {v!r}")
    return v


def int_at_least(name: str, value: object, lo: int) -> int:
    """Return an ``int`` (or NumPy integer, not a bool) ``>= lo``."""
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise InvalidInputError(f"{name} must be an int, got {value!r}")
    if int(value) < lo:
        raise InvalidInputError(f"{name} must be >= {lo}, got {int(value)}")
    return int(value)


def origin(value: object) -> tuple[float, float]:
    """Return a finite world point ``(x, y)`` in metres (the ``origin`` of a grid)."""
    try:
        ox, oy = (float(v) for v in value)  # type: ignore[union-attr]
    except (TypeError, ValueError):
        raise InvalidInputError(
            f"origin must be two numbers (x, y) in metres, got {value!r}"
        ) from None
    if not (math.isfinite(ox) and math.isfinite(oy)):
        raise InvalidInputError(f"origin must be finite, got ({ox}, {oy})")
    return ox, oy


def choice(name: str, value: object, choices: Sequence[str]) -> str:
    """One of the strings ``choices``."""
    if not isinstance(value, str) or value not in choices:
        raise InvalidInputError(f"{name} must be one of {tuple(choices)}, got {value!r}")
    return value


def bool_grid(occupied: object) -> np.ndarray:
    """Return a non-empty 2-D occupancy, bool or 0/1 numbers, as a new read-only bool array.

    Returns
    -------
    ndarray of bool, shape (ny, nx)
        C-contiguous copy, not writeable.
    """
    a = np.asarray(occupied)
    if a.ndim != 2:
        raise InvalidInputError(f"occupied must be a 2-D array [ny, nx], got shape {a.shape}")
    if a.shape[0] == 0 or a.shape[1] == 0:
        raise InvalidInputError(f"occupied must not be empty, got shape {a.shape}")
    if a.dtype != bool:
        if a.dtype.kind not in "iuf":
            raise InvalidInputError(f"occupied must be bool or 0/1 numbers, got dtype {a.dtype}")
        if a.dtype.kind == "f" and not np.all(np.isfinite(a)):
            raise InvalidInputError("occupied must not contain NaN or infinity")
        if not np.all((a == 0) | (a == 1)):
            bad = a[(a != 0) & (a != 1)].ravel()[0].item()
            raise InvalidInputError(f"occupied must hold only 0/1 (or bool) values, found {bad!r}")
    out = np.array(a, dtype=bool, order="C", copy=True)
    out.flags.writeable = False
    return out


def integer_values(values: object) -> np.ndarray:
    """Return a non-empty 2-D array of integers (integer dtype, or floats holding integers).

    Returns
    -------
    ndarray of int64, shape (ny, nx)
    """
    try:
        arr = np.asarray(values)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(f"values must be a 2-D array of integers, got {exc}") from None
    if arr.ndim != 2 or arr.size == 0:
        raise InvalidInputError(
            f"values must be a non-empty 2-D array (ny, nx), got shape {arr.shape}"
        )
    if arr.dtype.kind in "iu":
        return arr.astype(np.int64)
    if arr.dtype.kind == "f":
        finite = np.isfinite(arr)
        if not np.all(finite) or np.any(arr != np.round(arr)):
            iy, ix = (int(i) for i in np.argwhere(~finite | (arr != np.round(arr)))[0])
            raise InvalidInputError(
                f"values must hold integers, got values[{iy}, {ix}] = {arr[iy, ix]!r}"
            )
        return arr.astype(np.int64)
    raise InvalidInputError(f"values must be an integer array, got dtype {arr.dtype}")


def _is_int(v: object) -> bool:
    return isinstance(v, (int, np.integer)) and not isinstance(v, (bool, np.bool_))


def cell(name: str, value: object, grid: OccupancyGrid) -> tuple[int, int]:
    """Return a free cell ``(ix, iy)`` of ``grid`` (two integers, inside the grid, not occupied)."""
    bad = InvalidInputError(f"{name} must be a cell (ix, iy) of two integers, got {value!r}")
    if isinstance(value, (str, bytes)) or (
        isinstance(value, (list, tuple)) and any(isinstance(v, (bool, np.bool_)) for v in value)
    ):
        raise bad
    try:
        arr = np.asarray(value)
    except (TypeError, ValueError) as exc:
        raise bad from exc
    if arr.shape != (2,):
        raise bad
    if arr.dtype.kind not in "iu" and not (arr.dtype == object and all(_is_int(v) for v in arr)):
        raise bad
    ix, iy = int(arr[0]), int(arr[1])
    if not (0 <= ix < grid.nx and 0 <= iy < grid.ny):
        raise InvalidInputError(
            f"{name} cell ({ix}, {iy}) is outside the grid: need 0 <= ix < {grid.nx} "
            f"and 0 <= iy < {grid.ny}"
        )
    if grid.occupied[iy, ix]:
        raise InvalidInputError(
            f"{name} cell ({ix}, {iy}) is blocked: it is occupied in the grid given to "
            "find_path (an obstacle, or inside the inflated avoidance area)"
        )
    return ix, iy


def cell_costs(cost: object, grid: OccupancyGrid) -> np.ndarray:
    """Return a per-cell cost of the grid's shape, finite and ``>= 0``, as float64.

    Returns
    -------
    ndarray of float64, shape (ny, nx)
    """
    try:
        c = np.asarray(cost, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(
            f"cost must be a float array of shape {grid.shape} (per-cell cost >= 0), "
            f"got {type(cost).__name__}"
        ) from exc
    if c.shape != grid.shape:
        raise InvalidInputError(
            f"cost must have the grid's shape (ny, nx) = {grid.shape}, got {c.shape}"
        )
    if c.size:
        # two reductions, no temporary: NaN propagates through min, +-inf shows in min or max
        lo = float(c.min())
        if not (math.isfinite(lo) and math.isfinite(float(c.max()))):
            raise InvalidInputError("cost must be finite everywhere (found NaN or infinity)")
        if lo < 0.0:
            raise InvalidInputError(f"cost must be >= 0 everywhere, found {lo!r}")
    return c
