"""Argument checks shared by the modules of :mod:`trajopt`.

Every checker returns the cleaned value or raises :class:`~trajopt.errors.InvalidInputError`
whose message names the field, the value and the rule (with the unit where there is one),
so that every public function reports bad input the same way.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from astar.validation import short_repr
from trajopt.errors import InvalidInputError


def _unit(unit: str) -> str:
    return f" ({unit})" if unit else ""


def number(
    name: str,
    value: Any,
    *,
    unit: str = "",
    lo: float | None = None,
    strict: bool = False,
    hi: float | None = None,
) -> float:
    """Return a finite float, optionally bounded below.

    A finite float, optionally bounded below (``> lo`` if ``strict``, else ``>= lo``) and above
    (``<= hi``). Booleans and strings are not numbers.
    """
    if isinstance(value, bool | np.bool_ | str | bytes):
        raise InvalidInputError(f"{name} must be a number{_unit(unit)}, got {value!r}")
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InvalidInputError(
            f"{name} must be a number{_unit(unit)}, got {short_repr(value)}"
        ) from None
    ok = math.isfinite(x)
    if ok and lo is not None:
        ok = x > lo if strict else x >= lo
    if ok and hi is not None:
        ok = x <= hi
    if not ok:
        rules = []
        if lo is not None:
            rules.append(f"{'>' if strict else '>='} {lo:g}")
        if hi is not None:
            rules.append(f"<= {hi:g}")
        rule = " and ".join(["finite", *rules])
        raise InvalidInputError(f"{name} must be {rule}{_unit(unit)}, got {short_repr(value)}")
    return x


def positive(name: str, value: Any, unit: str = "") -> float:
    """Return a finite float ``> 0``."""
    return number(name, value, unit=unit, lo=0.0, strict=True)


def nonnegative(name: str, value: Any, unit: str = "") -> float:
    """Return a finite float ``>= 0``."""
    return number(name, value, unit=unit, lo=0.0)


def integer(name: str, value: Any, lo: int, hi: int | None = None) -> int:
    """Return an integer (not a bool) in ``[lo, hi]`` (``hi`` open when None)."""
    if isinstance(value, bool | np.bool_) or not isinstance(value, int | np.integer):
        raise InvalidInputError(f"{name} must be an integer, got {short_repr(value)}")
    v = int(value)
    if v < lo or (hi is not None and v > hi):
        rule = f">= {lo}" if hi is None else f"in {lo}..{hi}"
        raise InvalidInputError(f"{name} must be an integer {rule}, got {v}")
    return v


def choice(name: str, value: Any, choices: Sequence[Any]) -> Any:
    """One of ``choices`` (compared with ``==``; strings only match strings)."""
    for c in choices:
        if type(value) is type(c) and value == c:
            return value
    raise InvalidInputError(f"{name} must be one of {tuple(choices)}, got {short_repr(value)}")


def heading(name: str, value: Any) -> float | None:
    """Return an angle in radians (finite float) or None."""
    if value is None:
        return None
    return number(name, value, unit="rad")


def point(name: str, value: Any) -> np.ndarray:
    """Return a finite ``(x, y)`` in metres, as a new float array of shape (2,)."""
    try:
        p = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise InvalidInputError(
            f"{name} must be two numbers (x, y) in metres, got {short_repr(value)}"
        ) from None
    if p.shape != (2,):
        raise InvalidInputError(
            f"{name} must be two numbers (x, y) in metres, got {short_repr(value)}"
        )
    if not np.all(np.isfinite(p)):
        raise InvalidInputError(f"{name} must be finite, got {p.tolist()}")
    return p


def points(
    name: str, value: Any, *, min_points: int = 2, max_points: int | None = None
) -> np.ndarray:
    """Finite world points.

    Finite world points (m), a new float array of shape ``(n, 2)`` with ``min_points <= n <=
    max_points``.
    """
    if hasattr(value, "cells"):
        raise InvalidInputError(
            f"{name} must be world coordinates (m), shape (n, 2); convert a GridPath with "
            "grid.cell_to_world(path.cells)"
        )
    try:
        p = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise InvalidInputError(
            f"{name} must be an array of shape (n, 2) in metres, got {short_repr(value)}"
        ) from None
    if p.ndim != 2 or p.shape[1] != 2:
        raise InvalidInputError(f"{name} must have shape (n, 2), got {p.shape}")
    n = p.shape[0]
    if n < min_points or (max_points is not None and n > max_points):
        rule = f">= {min_points}" if max_points is None else f"in [{min_points}, {max_points}]"
        raise InvalidInputError(f"{name} must hold a number of points {rule}, got {n}")
    bad = ~np.isfinite(p).all(axis=1)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise InvalidInputError(f"{name} must be finite, got {name}[{i}] = {p[i].tolist()}")
    return p


def weights(name: str, value: Any, n: int, *, positive: bool = False) -> np.ndarray:
    """Per-point weights, a float array of shape ``(n,)``: ones when ``value`` is None.

    Finite, ``> 0`` with ``positive`` or else ``>= 0``, and not all zero.
    """
    if value is None:
        return np.ones(n)
    w = np.asarray(value, dtype=float)
    if w.shape != (n,):
        raise InvalidInputError(f"{name} must have shape ({n},) (one per point), got {w.shape}")
    if not np.all(np.isfinite(w)):
        raise InvalidInputError(f"{name} must be finite")
    if positive and np.any(w <= 0):
        raise InvalidInputError(f"{name} must be > 0, got min {w.min()!r}")
    if np.any(w < 0):
        raise InvalidInputError(f"{name} must be >= 0, got min {w.min()!r}")
    if not np.any(w > 0):
        raise InvalidInputError(f"{name} must not all be zero")
    return w


def readonly(value: Any, dtype: Any = float) -> np.ndarray:
    """Return a read-only copy of ``value`` as an array of ``dtype`` (the values' stored arrays)."""
    out = np.array(value, dtype=dtype, copy=True)
    out.flags.writeable = False
    return out
