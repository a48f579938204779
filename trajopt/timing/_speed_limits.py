"""Speed-limit zones from a Nav2 speed filter mask.

Nav2's ``SpeedFilter`` reads a *filter mask*, a map_server map whose cell values (the
``nav_msgs/OccupancyGrid`` values ``-1``, ``0..100`` of the mask image) encode a speed
limit through two coefficients of the costmap filter info (``base``, ``multiplier``) and a
``type``:

* mask value ``0``: no limit; ``-1`` (unknown): no limit (Nav2 keeps the limit it had
  before; a planner has none, so none applies);
* otherwise ``limit = value * multiplier + base``, read as a percentage of the robot's
  maximum speed (``type="percentage"``, Nav2's filter type 1) or in m/s
  (``type="absolute"``, type 2);
* a percentage outside ``[0, 100]`` or a negative absolute limit is ignored (no limit), as
  Nav2 does; a limit of exactly 0 means "no limit" (``nav2_msgs/SpeedLimit``'s
  convention).

:class:`SpeedLimits` holds the decoded limit per mask cell. The timing
(:func:`trajopt.time_parameterize`) caps the robot's speed by the limit of the cell under
its centre: each interval of its arc-length cap table takes the lowest limit over every
mask cell the curve can touch in that interval, so the trajectory holds the limit wherever
the centre is inside a zone (it slows down just before the boundary, by at most the table
spacing, 2.5 mm up to 41 m of curve). The mask is looked up in world coordinates with its own resolution and
origin (as Nav2 does), so it may cover the map only partly or use another cell size;
outside the mask there is no limit.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np

from trajopt.errors import InvalidInputError
from trajopt.validation import number, point, positive

SpeedLimitType = Literal["percentage", "absolute"]
_TYPES: tuple[str, ...] = ("percentage", "absolute")
_NAV2_TYPES = {1: "percentage", 2: "absolute"}


@dataclass(frozen=True, slots=True)
class SpeedLimits:
    """Speed limit per cell of a mask (``inf`` where there is none).

    Attributes
    ----------
    limit : ndarray of float64, shape (ny, nx)
        Decoded limit per cell, row 0 at the bottom (read-only): percent of the robot's
        ``v_max`` for ``type="percentage"``, m/s for ``type="absolute"``; ``inf`` = no limit.
    resolution : float
        Mask cell size (m).
    origin : tuple of float
        World ``(x, y)`` (m) of the lower-left corner of mask cell ``(0, 0)``.
    type : {"percentage", "absolute"}
        Unit of :attr:`limit`.
    """

    limit: np.ndarray
    resolution: float
    origin: tuple[float, float]
    type: SpeedLimitType

    # ------------------------------------------------------------ constructors
    @classmethod
    def from_mask(
        cls,
        values: np.ndarray,
        resolution: float,
        origin: tuple[float, float] = (0.0, 0.0),
        *,
        type: SpeedLimitType | int,
        base: float = 0.0,
        multiplier: float = 1.0,
    ) -> SpeedLimits:
        """Decode mask values with Nav2's rule (module docstring).

        Parameters
        ----------
        values : array_like of int, shape (ny, nx)
            ``nav_msgs/OccupancyGrid`` values (``-1`` or ``0..100``), row 0 at the bottom.
        resolution : float
            Mask cell size (m), finite and > 0.
        origin : tuple of float, optional
            World ``(x, y)`` (m) of the mask's lower-left corner.
        type : {"percentage", "absolute"} or {1, 2}
            Meaning of the decoded limit (Nav2's costmap filter ``type`` 1 or 2). Required.
        base, multiplier : float, optional
            Nav2's coefficients: ``limit = value * multiplier + base``.

        Raises
        ------
        InvalidInputError
            An unknown ``type``, a value outside ``-1..100``, non-finite coefficients, a bad
            resolution or origin.
        """
        kind = _limit_type(type)
        b = number("base", base)
        m = number("multiplier", multiplier)
        res = positive("resolution", resolution, "m")
        org = _origin(origin)
        try:
            v = np.asarray(values)
        except (TypeError, ValueError) as exc:
            raise InvalidInputError(f"values must be a 2-D integer array: {exc}") from None
        if v.ndim != 2 or v.size == 0 or v.dtype.kind not in "iuf":
            raise InvalidInputError(
                f"values must be a non-empty 2-D numeric array (ny, nx), got shape {v.shape} "
                f"dtype {v.dtype}"
            )
        bad = ~np.isfinite(v) | (v != np.round(v)) | (v < -1) | (v > 100)
        if np.any(bad):
            iy, ix = (int(i) for i in np.argwhere(bad)[0])
            raise InvalidInputError(
                f"speed mask values[{iy}, {ix}] = {v[iy, ix].item()!r} is not an OccupancyGrid value "
                "(integers -1..100)"
            )
        v = v.astype(np.int64)
        with np.errstate(invalid="ignore"):
            lim = v * m + b
        if kind == "percentage":
            ignored = (lim < 0.0) | (lim > 100.0)
        else:
            ignored = lim < 0.0
        none = (v == 0) | (v == -1) | ignored | (lim == 0.0)
        lim = np.where(none, np.inf, lim).astype(np.float64)
        lim.flags.writeable = False
        return cls(limit=lim, resolution=res, origin=org, type=kind)  # type: ignore[arg-type]

    # ------------------------------------------------------------------ queries
    @property
    def shape(self) -> tuple[int, int]:
        """``(ny, nx)``."""
        return self.limit.shape  # type: ignore[return-value]

    @property
    def extent(self) -> tuple[float, float, float, float]:
        """``(x_min, x_max, y_min, y_max)`` of the mask in world metres."""
        ny, nx = self.shape
        ox, oy = self.origin
        return ox, ox + nx * self.resolution, oy, oy + ny * self.resolution

    def speed_caps(self, v_max: float) -> np.ndarray:
        """Return the limit per cell in m/s (shape ``(ny, nx)``), ``inf`` where there is none.

        Parameters
        ----------
        v_max : float
            The robot's maximum speed (m/s), the 100 % of a percentage mask.
        """
        if self.type == "percentage":
            return self.limit * (float(v_max) / 100.0)
        return np.asarray(self.limit, dtype=np.float64)

    def cap_at(self, xy: np.ndarray, v_max: float) -> np.ndarray:
        """Speed limit (m/s) of the cell under each point, ``inf`` outside the mask.

        Parameters
        ----------
        xy : array_like, shape (..., 2)
            World points (m).
        v_max : float
            The robot's maximum speed (m/s).

        Returns
        -------
        ndarray, shape (...)
        """
        p = np.asarray(xy, dtype=float)
        caps = self.speed_caps(v_max)
        ix = np.floor((p[..., 0] - self.origin[0]) / self.resolution)
        iy = np.floor((p[..., 1] - self.origin[1]) / self.resolution)
        ny, nx = self.shape
        inside = (ix >= 0) & (ix < nx) & (iy >= 0) & (iy < ny)
        out = np.full(ix.shape, np.inf)
        out[inside] = caps[iy[inside].astype(np.int64), ix[inside].astype(np.int64)]
        return out

    def box_caps(self, lo: np.ndarray, hi: np.ndarray, v_max: float) -> np.ndarray:
        """Lowest limit (m/s) over every mask cell meeting each axis-aligned box.

        Parameters
        ----------
        lo, hi : array_like, shape (n, 2)
            Box corners (m), ``lo <= hi``.
        v_max : float
            The robot's maximum speed (m/s).

        Returns
        -------
        ndarray, shape (n,)
            ``inf`` for boxes meeting no limited cell (or lying outside the mask).
        """
        lo = np.asarray(lo, dtype=float)
        hi = np.asarray(hi, dtype=float)
        caps = self.speed_caps(v_max)
        ny, nx = self.shape
        res = self.resolution
        ox, oy = self.origin
        ix0 = np.clip(np.floor((lo[:, 0] - ox) / res), -1, nx).astype(np.int64)
        ix1 = np.clip(np.floor((hi[:, 0] - ox) / res), -1, nx).astype(np.int64)
        iy0 = np.clip(np.floor((lo[:, 1] - oy) / res), -1, ny).astype(np.int64)
        iy1 = np.clip(np.floor((hi[:, 1] - oy) / res), -1, ny).astype(np.int64)
        out = np.full(lo.shape[0], np.inf)
        if out.size == 0:
            return out
        span_x = int((ix1 - ix0).max()) + 1
        span_y = int((iy1 - iy0).max()) + 1
        if span_x * span_y > 64:  # boxes much larger than a cell: a 2-D running minimum
            return np.array(
                [
                    self._box_min(caps, a, b, c, d)
                    for a, b, c, d in zip(ix0, ix1, iy0, iy1, strict=True)
                ]
            )
        for dx in range(span_x):
            ix = ix0 + dx
            for dy in range(span_y):
                iy = iy0 + dy
                ok = (ix <= ix1) & (iy <= iy1) & (ix >= 0) & (ix < nx) & (iy >= 0) & (iy < ny)
                if np.any(ok):
                    out[ok] = np.minimum(out[ok], caps[iy[ok], ix[ok]])
        return out

    @staticmethod
    def _box_min(caps: np.ndarray, ix0: int, ix1: int, iy0: int, iy1: int) -> float:
        ny, nx = caps.shape
        a, b = max(ix0, 0), min(ix1, nx - 1)
        c, d = max(iy0, 0), min(iy1, ny - 1)
        if a > b or c > d:
            return math.inf
        return float(caps[c : d + 1, a : b + 1].min())

    def __repr__(self) -> str:
        ny, nx = self.shape
        limited = np.isfinite(self.limit)
        lo = f", lowest {float(self.limit[limited].min()):.4g}" if np.any(limited) else ""
        unit = "%" if self.type == "percentage" else " m/s"
        return (
            f"SpeedLimits({nx} x {ny} cells of {self.resolution} m, type={self.type!r}, "
            f"{int(limited.sum())} limited cells{lo}{unit if lo else ''})"
        )


def load_speed_mask(
    path: str | os.PathLike[str],
    *,
    type: SpeedLimitType | int,
    base: float = 0.0,
    multiplier: float = 1.0,
) -> SpeedLimits:
    """Read a Nav2 speed filter mask (map_server YAML + image).

    The image is read with map_server's rules for the file's ``mode``
    (:func:`astar.read_map_values`); Nav2's tutorial masks use ``mode: scale`` with
    ``free_thresh: 0.0`` and ``occupied_thresh: 1.0``, where a grey of ``g`` % gives the
    value ``g``. ``type``, ``base`` and ``multiplier`` are the parameters of Nav2's
    costmap filter info server (they are not in the mask's YAML).

    Parameters
    ----------
    path : str or os.PathLike
        The mask's YAML file.
    type : {"percentage", "absolute"} or {1, 2}
        Meaning of the decoded limit. Required.
    base, multiplier : float, optional
        ``limit = value * multiplier + base`` (Nav2's tutorial: ``base=100``,
        ``multiplier=-1`` so that darker is slower).

    Returns
    -------
    SpeedLimits

    Raises
    ------
    astar.MapFormatError
        A missing or malformed file.
    InvalidInputError
        An unknown ``type`` or bad coefficients.
    """
    from astar.errors import MapFormatError
    from astar.io import read_map_values

    p = Path(path)
    kind = _limit_type(type)
    values, resolution, origin, _mode = read_map_values(p)
    try:
        return SpeedLimits.from_mask(
            values, resolution, origin, type=kind, base=base, multiplier=multiplier
        )
    except InvalidInputError as exc:
        raise MapFormatError(f"{p}: {exc}") from None


# ------------------------------------------------------------------ checks
def _limit_type(value: object) -> str:
    if isinstance(value, int | np.integer) and not isinstance(value, bool):
        if int(value) in _NAV2_TYPES:
            return _NAV2_TYPES[int(value)]
    elif isinstance(value, str) and value in _TYPES:
        return value
    raise InvalidInputError(
        f"type must be 'percentage' (Nav2 filter type 1) or 'absolute' (type 2), got {value!r}"
    )


def _origin(value: object) -> tuple[float, float]:
    ox, oy = point("origin", value)
    return float(ox), float(oy)


def check_overlap(limits: object, grid: Any) -> None:
    """Raise unless ``limits`` is a :class:`SpeedLimits` whose mask overlaps ``grid``'s extent."""
    if not isinstance(limits, SpeedLimits):
        raise InvalidInputError(
            f"speed_limits must be a trajopt.SpeedLimits (trajopt.load_speed_mask), "
            f"got {type(limits).__name__}"
        )
    x0, x1, y0, y1 = limits.extent
    gx0, gy0 = grid.origin
    gx1, gy1 = gx0 + grid.width, gy0 + grid.height
    if x1 <= gx0 or x0 >= gx1 or y1 <= gy0 or y0 >= gy1:
        raise InvalidInputError(
            f"speed_limits: the mask covers x in [{x0:.6g}, {x1:.6g}] m, y in [{y0:.6g}, "
            f"{y1:.6g}] m, which does not overlap the map (x in [{gx0:.6g}, {gx1:.6g}] m, "
            f"y in [{gy0:.6g}, {gy1:.6g}] m); masks are looked up in world coordinates"
        )
