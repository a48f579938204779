"""ROS map_server / Nav2 maps: the YAML metadata and map_server's pixel semantics.

:func:`read_ros_yaml` checks the metadata (``image``, ``resolution``, ``origin``,
``negate``, the thresholds, ``mode``), :func:`map_server_values` turns image pixels into
the cell values a ``nav_msgs/OccupancyGrid`` published by map_server holds (``-1``
unknown, ``0..100``), and :func:`values_to_occupied` thresholds them to the boolean grid
(the rules are written out in :func:`astar.io.load_map`). :func:`read_map_values` is the
public entry point for costmaps and filter masks; :func:`load_ros` is what
:func:`astar.io.load_map` calls for a YAML file.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np

from astar.errors import InvalidInputError, MapFormatError
from astar.files import grid_from_file, read_text
from astar.grid import OccupancyGrid
from astar.images import Pixels, read_pixels
from astar.validation import short_repr

__all__ = [
    "YAML_SUFFIXES",
    "MapMode",
    "RosMeta",
    "load_ros",
    "map_server_values",
    "read_map_values",
    "read_ros_yaml",
    "values_to_occupied",
]

#: Suffixes of map_server metadata files.
YAML_SUFFIXES: tuple[str, ...] = (".yaml", ".yml")

#: map_server's cell values (``nav_msgs/OccupancyGrid``).
_FREE, _OCCUPIED, _UNKNOWN = 0, 100, -1

MapMode = Literal["trinary", "scale", "raw"]
_MODES: tuple[str, ...] = ("trinary", "scale", "raw")


def read_map_values(
    yaml_path: str | os.PathLike[str],
) -> tuple[np.ndarray, float, tuple[float, float], str]:
    """map_server's cell values of a ROS map YAML + image, before any thresholding to bool.

    The values are those a ``nav_msgs/OccupancyGrid`` published by map_server holds
    (``-1`` unknown, ``0..100``), computed with the rules of :func:`load_map` for the file's
    ``mode``; ``raw`` mode keeps ``0..100`` as written and anything above 100 as ``-1``.
    Costmaps and Nav2 filter masks are read through this function
    (:func:`astar.load_costmap`, :func:`trajopt.load_speed_mask`).

    Parameters
    ----------
    yaml_path : str or os.PathLike
        The ``.yaml`` / ``.yml`` metadata file (same keys as :func:`load_map`).

    Returns
    -------
    values : ndarray of int16, shape (ny, nx)
        Row 0 at the bottom (the last image row), like ``OccupancyGrid.occupied``.
    resolution : float
        Cell size (m).
    origin : tuple of float
        World ``(x, y)`` (m) of the lower-left corner of cell ``(0, 0)``.
    mode : str
        The file's ``mode`` (``trinary``, ``scale`` or ``raw``).

    Raises
    ------
    MapFormatError
        Missing or malformed files (the message names the file, the field and the rule).
    """
    p = Path(yaml_path)
    if p.suffix.lower() not in YAML_SUFFIXES:
        raise MapFormatError(
            f"{p}: expected a map_server YAML file ({', '.join(YAML_SUFFIXES)}), "
            f"got suffix {p.suffix!r}"
        )
    if not p.is_file():
        raise MapFormatError(f"{p}: map file does not exist (or is not a regular file)")
    meta = read_ros_yaml(p)
    values = _image_values(p, meta)
    return np.ascontiguousarray(values[::-1]), meta.resolution, meta.origin, meta.mode


@dataclass(frozen=True, slots=True)
class RosMeta:
    """The checked fields of a map_server YAML file (``image`` resolved to a path)."""

    image: Path
    resolution: float
    origin: tuple[float, float]
    negate: bool
    occupied_thresh: float
    free_thresh: float
    mode: str


def _image_values(p: Path, meta: RosMeta) -> np.ndarray:
    """map_server's values (int16, top image row first) of the image that ``p`` names."""
    if not meta.image.is_file():
        raise MapFormatError(
            f"{p}: field image: image file {str(meta.image)!r} does not exist "
            "(relative paths are resolved against the YAML file's folder)"
        )
    return map_server_values(
        read_pixels(meta.image, p),
        mode=meta.mode,
        negate=meta.negate,
        occupied_thresh=meta.occupied_thresh,
        free_thresh=meta.free_thresh,
    )


def load_ros(
    p: Path, resolution: float | None, origin: tuple[float, float], unknown_occupied: bool
) -> OccupancyGrid:
    """Return the grid of a map_server YAML file and its image (the rules of :func:`astar.load_map`).

    ``resolution`` and ``origin`` are the caller's (already checked) arguments: a value that
    differs from the file's is an :class:`InvalidInputError`.
    """
    meta = read_ros_yaml(p)
    if resolution is not None and resolution != meta.resolution:
        raise InvalidInputError(
            f"{p}: resolution={resolution!r} given, but the YAML file sets resolution "
            f"{meta.resolution!r}; leave resolution=None for YAML maps"
        )
    if origin != (0.0, 0.0) and origin != meta.origin:
        raise InvalidInputError(
            f"{p}: origin={origin!r} given, but the YAML file sets origin {meta.origin!r}; "
            "leave origin at its default for YAML maps"
        )
    values = _image_values(p, meta)
    occ = values_to_occupied(
        values,
        mode=meta.mode,
        occupied_thresh=meta.occupied_thresh,
        free_thresh=meta.free_thresh,
        unknown_occupied=unknown_occupied,
    )
    return grid_from_file(p, occ[::-1], meta.resolution, meta.origin)


def read_ros_yaml(p: Path) -> RosMeta:
    """Parse and check a map_server YAML file (safe loader; messages name the field)."""
    import yaml

    text = read_text(p)
    try:
        doc = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise MapFormatError(f"{p}: not valid YAML (safe loader): {exc}") from None
    except RecursionError:
        raise MapFormatError(f"{p}: YAML nesting is too deep") from None
    if not isinstance(doc, Mapping):
        raise MapFormatError(
            f"{p}: a ROS map YAML must be a mapping of keys (image, resolution, ...), "
            f"got {type(doc).__name__}"
        )
    required = ("image", "resolution", "origin", "negate", "occupied_thresh", "free_thresh")
    missing = [k for k in required if k not in doc]
    if missing:
        raise MapFormatError(
            f"{p}: missing required key(s) {', '.join(missing)}; a ROS map YAML needs "
            f"{', '.join(required)} (mode is optional)"
        )
    image = doc["image"]
    if not isinstance(image, str) or not image.strip():
        raise MapFormatError(
            f"{p}: field image must be a non-empty file name, got {short_repr(image)}"
        )
    image_path = Path(image)
    if not image_path.is_absolute():
        image_path = p.parent / image_path
    res = _yaml_float(p, doc, "resolution")
    if res <= 0.0:
        raise MapFormatError(f"{p}: field resolution must be finite and > 0, got {res!r}")
    raw_origin = doc["origin"]
    if not isinstance(raw_origin, list | tuple) or len(raw_origin) != 3:
        raise MapFormatError(
            f"{p}: field origin must be a list of 3 numbers [x, y, yaw], got {short_repr(raw_origin)}"
        )
    ox, oy, yaw = (_yaml_number(p, f"origin[{i}]", v) for i, v in enumerate(raw_origin))
    if yaw != 0.0:
        raise MapFormatError(
            f"{p}: field origin has yaw {yaw!r} rad; only axis-aligned maps (yaw = 0) are supported"
        )
    negate = _yaml_negate(p, doc["negate"])
    occ_th = _yaml_float(p, doc, "occupied_thresh")
    free_th = _yaml_float(p, doc, "free_thresh")
    if not (0.0 <= free_th < occ_th <= 1.0):
        raise MapFormatError(
            f"{p}: fields free_thresh = {free_th!r} and occupied_thresh = {occ_th!r} must "
            "satisfy 0 <= free_thresh < occupied_thresh <= 1"
        )
    mode = doc.get("mode", "trinary")
    if mode is None:
        mode = "trinary"
    if not isinstance(mode, str) or mode not in _MODES:
        raise MapFormatError(
            f"{p}: field mode must be one of {', '.join(_MODES)} (default trinary), "
            f"got {short_repr(mode)}"
        )
    return RosMeta(image_path, res, (ox, oy), negate, occ_th, free_th, mode)


def _yaml_number(p: Path, name: str, value: object) -> float:
    # PyYAML (YAML 1.1) reads "1e-3" as a string; map_server's yaml-cpp reads it as a
    # number, so numeric strings are accepted. Booleans are not numbers here.
    if isinstance(value, bool) or not isinstance(value, int | float | str):
        raise MapFormatError(f"{p}: field {name} must be a number, got {short_repr(value)}")
    try:
        v = float(value)
    except ValueError:
        raise MapFormatError(
            f"{p}: field {name} must be a number, got {short_repr(value)}"
        ) from None
    if not math.isfinite(v):
        raise MapFormatError(f"{p}: field {name} must be finite, got {value!r}")
    return v


def _yaml_float(p: Path, doc: Mapping[str, Any], key: str) -> float:
    return _yaml_number(p, key, doc[key])


def _yaml_negate(p: Path, value: object) -> bool:
    if isinstance(value, bool):
        return value
    if isinstance(value, int):
        return value != 0
    if isinstance(value, str) and re.fullmatch(r"[+-]?[0-9]+", value.strip()):
        return int(value) != 0
    raise MapFormatError(f"{p}: field negate must be 0, 1 or a bool, got {short_repr(value)}")


def map_server_values(
    pixels: Pixels,
    *,
    mode: str,
    negate: bool,
    occupied_thresh: float,
    free_thresh: float,
) -> np.ndarray:
    """map_server's cell values (-1 unknown, 0..100) of image pixels, int16 ``[h, w]``."""
    top = pixels.maxval
    if mode == "raw":  # colour channels only, negate ignored
        pct = np.floor(pixels.rgb_sum / 3.0 / top * 255.0 + 0.5)  # std::round
        return np.where(pct <= 100.0, pct, _UNKNOWN).astype(np.int16)
    if mode == "trinary" and pixels.alpha is not None:
        shade = (pixels.rgb_sum + pixels.alpha) / 4.0 / top
    else:
        shade = pixels.rgb_sum / 3.0 / top
    occ = shade if negate else 1.0 - shade
    del shade
    if mode == "scale":
        mid = np.rint((occ - free_thresh) / (occupied_thresh - free_thresh) * 100.0)
        out = np.clip(mid, 0, 100).astype(np.int16)
        del mid
    else:
        out = np.full(occ.shape, _UNKNOWN, dtype=np.int16)
    out[occ < free_thresh] = _FREE
    out[occ > occupied_thresh] = _OCCUPIED
    if mode == "scale" and pixels.alpha is not None:
        out[pixels.alpha < top] = _UNKNOWN
    return out


def values_to_occupied(
    values: np.ndarray,
    *,
    mode: str,
    occupied_thresh: float,
    free_thresh: float,
    unknown_occupied: bool,
) -> np.ndarray:
    """Boolean occupancy from map_server values (see :func:`load_map` for the rule)."""
    if mode == "raw":
        frac = values / 100.0
        occupied = (values >= 0) & (frac > occupied_thresh)
        free = (values >= 0) & (frac < free_thresh)
    else:
        occupied = values == _OCCUPIED
        free = values == _FREE
    unknown = ~(occupied | free)
    return occupied | (unknown & unknown_occupied)
