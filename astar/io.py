"""Map and scenario formats: read and write :class:`~astar.grid.OccupancyGrid` values.

Supported inputs of :func:`load_map` (chosen by the file suffix, case-insensitive):

``.yaml`` / ``.yml``
    ROS map_server / Nav2 map metadata plus the image it names (PGM, PNG, ...), read with
    map_server's own pixel semantics (see :func:`load_map`).
``.map``
    Moving AI grid benchmark maps (``type octile``).
``.pgm`` ``.pbm`` ``.ppm`` ``.pnm`` ``.png`` ``.bmp`` ``.gif`` ``.tif`` ``.tiff`` ``.jpg`` ``.jpeg``
    Plain images (dark = occupied); the cell size must be given.
``.npy``
    NumPy arrays of bool or 0/1 values, already in ``[iy, ix]`` order with row 0 at the bottom.

:func:`save_map` writes the ROS pair (YAML + trinary PGM) that :func:`load_map` reads back
identically, :func:`from_intensity` converts the "1 = free, 100 = occupied" matrices, and
:func:`read_scenarios` reads Moving AI ``.scen`` files into :class:`Scenario` records whose
cells are already converted to this project's bottom-row-0 ``(ix, iy)`` convention.

Every malformed file raises :class:`~astar.errors.MapFormatError` (a ``ValueError``) whose
message names the file, the field and the rule that was broken; errors raised by Pillow,
PyYAML or NumPy while parsing are wrapped, never leaked.
"""

from __future__ import annotations

import logging
import os
from pathlib import Path
from typing import Any

import numpy as np

from astar import validation
from astar.errors import InvalidInputError, MapFormatError
from astar.files import atomic_write, grid_from_file
from astar.grid import OccupancyGrid
from astar.images import IMAGE_SUFFIXES, MAX_IMAGE_PIXELS, read_pixels
from astar.movingai import Scenario, read_movingai, read_scenarios
from astar.ros_map import (
    YAML_SUFFIXES,
    MapMode,
    load_ros,
    map_server_values,
    read_map_values,
    values_to_occupied,
)

# Re-exported from the modules that own them (astar.images, astar.movingai, astar.ros_map),
# so that ``from astar.io import ...`` keeps working.
__all__ = [
    "IMAGE_SUFFIXES",
    "MAX_IMAGE_PIXELS",
    "MapMode",
    "Scenario",
    "from_intensity",
    "load_map",
    "read_map_values",
    "read_scenarios",
    "save_map",
]

logger = logging.getLogger(__name__)

_SUPPORTED = (*YAML_SUFFIXES, ".map", *IMAGE_SUFFIXES, ".npy")

#: Thresholds used for plain images (those of a typical ROS map YAML).
_IMAGE_OCCUPIED_THRESH = 0.65
_IMAGE_FREE_THRESH = 0.196

#: What :func:`save_map` writes (the defaults of Nav2's map saver).
_SAVE_OCCUPIED_THRESH = 0.65
_SAVE_FREE_THRESH = 0.25
_SAVE_OCCUPIED_PIXEL = 0
_SAVE_FREE_PIXEL = 254


def load_map(
    path: str | os.PathLike[str],
    *,
    resolution: float | None = None,
    origin: tuple[float, float] = (0.0, 0.0),
    unknown_occupied: bool = True,
) -> OccupancyGrid:
    """Read an occupancy grid from a file, choosing the reader by its suffix.

    Parameters
    ----------
    path : str or os.PathLike
        The map file. Its suffix (case-insensitive) selects the format:

        * ``.yaml`` / ``.yml`` -- ROS map_server / Nav2 metadata. Required keys: ``image``
          (path, relative to the YAML file unless absolute), ``resolution`` (m/cell, > 0),
          ``origin`` (``[x, y, yaw]`` of the lower-left pixel; a non-zero ``yaw`` is rejected
          because :class:`OccupancyGrid` is axis-aligned), ``negate`` (0/1 or bool),
          ``occupied_thresh`` and ``free_thresh`` (``0 <= free < occupied <= 1``); optional
          ``mode`` (``trinary`` by default, ``scale`` or ``raw``). Each pixel gets
          map_server's value: with ``shade`` the mean of the R, G, B channels scaled to
          [0, 1] (in ``trinary`` mode an alpha channel, opaque = 1, is averaged in too) and
          ``occ = shade if negate else 1 - shade``:

          - ``trinary``: occupied if ``occ > occupied_thresh``, free if
            ``occ < free_thresh``, otherwise unknown;
          - ``scale``: unknown if the pixel is not fully opaque, else occupied/free as in
            ``trinary``; in-between pixels get map_server's intermediate cost
            ``rint(100 (occ - free) / (occupied - free))``: 100 counts as occupied, 0 as
            free and 1..99 as unknown;
          - ``raw``: the value is ``round(255 shade)`` (``negate`` ignored); 0..100 is an
            occupancy in percent (occupied if ``value / 100 > occupied_thresh``, free if
            ``value / 100 < free_thresh``, otherwise unknown) and anything above 100 is
            unknown.

          Unknown cells are occupied unless ``unknown_occupied=False``.
        * ``.map`` -- Moving AI benchmark map (``type octile``, ``height``, ``width``,
          ``map``, then ``height`` rows of ``width`` characters; LF or CRLF). Following the
          benchmark's definition, ``.`` and ``G`` (ground) and ``S`` (swamp, passable from
          regular terrain) are free; ``@`` and ``O`` (out of bounds), ``T`` (trees) and
          ``W`` (water, not passable from terrain) are occupied. Any other character is an
          error. ``resolution`` defaults to 1.0 m/cell.
        * images (see :data:`IMAGE_SUFFIXES`) -- dark is occupied: the pixel is read exactly
          as a ROS ``trinary`` map with ``negate: 0``, ``occupied_thresh: 0.65``,
          ``free_thresh: 0.196`` and unknown as occupied, so a cell is free only when
          ``1 - shade < 0.196`` (an 8-bit grey value of 206 or more; ROS's unknown grey
          205 is occupied). ``resolution`` is required.
        * ``.npy`` -- a 2-D bool or 0/1 array (``True``/1 = occupied) taken as already in
          ``[iy, ix]`` order with row 0 at the bottom (not flipped). Pickled object arrays
          are refused. ``resolution`` defaults to 1.0 m/cell.

        Image and ``.map`` rows are flipped so that row 0 of the grid is the bottom row
        (the last line of the file).
    resolution : float, optional
        Cell size in metres. Required for images; defaults to 1.0 for ``.map`` and
        ``.npy``. For YAML the file's value is used (a different value here is an error).
    origin : tuple of float, optional
        World ``(x, y)`` in metres of the lower-left corner of cell ``(0, 0)``. For YAML the
        file's origin is used (a different non-default value here is an error).
    unknown_occupied : bool, optional
        Whether unknown cells of a ROS map are occupied (default) or free. The other
        formats have no unknown cells.

    Returns
    -------
    OccupancyGrid
        ``occupied`` of shape ``(ny, nx)`` (read-only), row 0 at the bottom.

    Raises
    ------
    MapFormatError
        Missing or malformed file, unknown suffix, bad or missing field; the message names
        the file, the field and the rule.
    InvalidInputError
        Bad keyword arguments (e.g. a non-positive ``resolution``).

    Notes
    -----
    The ROS rule is map_server's, including its quirks: map_saver writes unknown cells as
    grey 205, whose ``occ = 1 - 205/255 = 0.196`` is *free* under ``free_thresh: 0.25``
    (e.g. Nav2's ``depot.yaml``) but unknown under ``free_thresh: 0.196``. Comparisons are
    in double precision as in map_server; a pixel whose ``occ`` equals a threshold to the
    last bit may differ from map_server's rounding. Netpbm headers are checked against the
    file size before decoding, so a truncated or lying header fails without allocating.

    Examples
    --------
    >>> grid = load_map("maps/arena.map")  # doctest: +SKIP
    >>> grid = load_map("maps/office.yaml", unknown_occupied=False)  # doctest: +SKIP
    >>> grid = load_map("maps/floor.png", resolution=0.05)  # doctest: +SKIP
    """
    p = Path(path)
    if not isinstance(unknown_occupied, bool | np.bool_):
        raise InvalidInputError(f"unknown_occupied must be a bool, got {unknown_occupied!r}")
    if resolution is not None:
        resolution = validation.positive_float("resolution", resolution)
    origin_xy = validation.origin(origin)
    suffix = p.suffix.lower()
    if suffix not in _SUPPORTED:
        raise MapFormatError(
            f"{p}: unsupported map file suffix {p.suffix!r}; supported suffixes are "
            f"{', '.join(_SUPPORTED)}"
        )
    if not p.is_file():
        raise MapFormatError(f"{p}: map file does not exist (or is not a regular file)")
    if suffix in YAML_SUFFIXES:
        grid = load_ros(p, resolution, origin_xy, bool(unknown_occupied))
    elif suffix == ".map":
        occ = read_movingai(p)
        grid = grid_from_file(p, occ, 1.0 if resolution is None else resolution, origin_xy)
    elif suffix == ".npy":
        occ = _read_npy(p)
        grid = grid_from_file(p, occ, 1.0 if resolution is None else resolution, origin_xy)
    else:
        if resolution is None:
            raise InvalidInputError(
                f"{p}: resolution (m/cell) is required to load an image map; "
                "pass load_map(path, resolution=...)"
            )
        values = map_server_values(
            read_pixels(p, p),
            mode="trinary",
            negate=False,
            occupied_thresh=_IMAGE_OCCUPIED_THRESH,
            free_thresh=_IMAGE_FREE_THRESH,
        )
        occ = values_to_occupied(
            values,
            mode="trinary",
            occupied_thresh=_IMAGE_OCCUPIED_THRESH,
            free_thresh=_IMAGE_FREE_THRESH,
            unknown_occupied=True,
        )
        grid = grid_from_file(p, occ[::-1], resolution, origin_xy)
    logger.debug("loaded %s: %r", p, grid)
    return grid


def save_map(grid: OccupancyGrid, yaml_path: str | os.PathLike[str]) -> Path:
    """Write a grid as a ROS map_server YAML file plus a trinary PGM image beside it.

    The image is ``yaml_path`` with the suffix ``.pgm``; occupied cells are black (0) and
    free cells 254, the top image row is the grid's top row (``iy = ny - 1``). The YAML
    holds ``image`` (the PGM's file name), ``mode: trinary``, ``resolution``, ``origin``
    ``[x, y, 0.0]``, ``negate: 0``, ``occupied_thresh: 0.65`` and ``free_thresh: 0.25``.
    :func:`load_map` reads the pair back to an equal grid (same ``occupied``, resolution
    and origin, bit for bit). Both files are written atomically (a temporary file in the
    same folder, then :func:`os.replace`); existing files are overwritten.

    Parameters
    ----------
    grid : OccupancyGrid
        The grid to write.
    yaml_path : str or os.PathLike
        Destination YAML file; must end in ``.yaml`` or ``.yml`` and its folder must exist.

    Returns
    -------
    pathlib.Path
        ``yaml_path`` as a :class:`~pathlib.Path`.

    Raises
    ------
    InvalidInputError
        ``grid`` is not an :class:`OccupancyGrid`, or the suffix or folder is wrong.
    """
    if not isinstance(grid, OccupancyGrid):
        raise InvalidInputError(f"grid must be an OccupancyGrid, got {type(grid).__name__}")
    yp = Path(yaml_path)
    if yp.suffix.lower() not in YAML_SUFFIXES:
        raise InvalidInputError(
            f"yaml_path must end in .yaml or .yml, got {str(yp)!r} (suffix {yp.suffix!r})"
        )
    if not yp.parent.is_dir():
        raise InvalidInputError(f"yaml_path folder {str(yp.parent)!r} does not exist")
    image_path = yp.with_suffix(".pgm")

    import yaml

    pixels = np.where(grid.occupied[::-1], _SAVE_OCCUPIED_PIXEL, _SAVE_FREE_PIXEL).astype(np.uint8)
    header = f"P5\n# written by astar.save_map\n{grid.nx} {grid.ny}\n255\n".encode("ascii")
    image = header + pixels.tobytes()
    atomic_write(image_path, lambda tmp: tmp.write_bytes(image))
    meta = {
        "image": image_path.name,
        "mode": "trinary",
        "resolution": float(grid.resolution),
        "origin": [float(grid.origin[0]), float(grid.origin[1]), 0.0],
        "negate": 0,
        "occupied_thresh": _SAVE_OCCUPIED_THRESH,
        "free_thresh": _SAVE_FREE_THRESH,
    }
    text = yaml.safe_dump(meta, sort_keys=False, default_flow_style=None)
    atomic_write(yp, lambda tmp: tmp.write_bytes(text.encode("utf-8")))
    logger.debug("saved %r to %s and %s", grid, yp, image_path)
    return yp


def from_intensity(
    values: Any, resolution: float, origin: tuple[float, float] = (0.0, 0.0)
) -> OccupancyGrid:
    """Build a grid from a matrix in the "1 = free, 100 = occupied" convention.

    Parameters
    ----------
    values : array_like of int, shape (ny, nx)
        Cell values, ``values[iy, ix]`` with row 0 at the bottom (not flipped; use
        ``np.flipud`` first for a matrix printed top row first). Only 1 and 100 are allowed.
    resolution : float
        Cell size in metres (> 0).
    origin : tuple of float, optional
        World ``(x, y)`` in metres of the lower-left corner of cell ``(0, 0)``.

    Returns
    -------
    OccupancyGrid
        ``occupied = (values == 100)``.

    Raises
    ------
    InvalidInputError
        A value other than 1 or 100 (the message names it, its cell and the count of bad
        cells), a non-numeric or bool array, a non-2-D or empty array, a bad resolution.
    """
    a = np.asarray(values)
    if a.dtype == bool or a.dtype.kind not in "iuf":
        raise InvalidInputError(
            f"values must be numbers (1 = free, 100 = occupied), got dtype {a.dtype}"
        )
    if a.ndim != 2 or a.size == 0:
        raise InvalidInputError(f"values must be a non-empty 2-D array [ny, nx], got {a.shape}")
    bad = ~((a == 1) | (a == 100))
    if np.any(bad):
        iy, ix = (int(v) for v in np.argwhere(bad)[0])
        raise InvalidInputError(
            f"values must hold only 1 (free) or 100 (occupied); found {a[iy, ix].item()!r} at cell "
            f"(ix={ix}, iy={iy}) ({int(bad.sum())} bad cells)"
        )
    return OccupancyGrid(a == 100, resolution, origin)


def _read_npy(p: Path) -> np.ndarray:
    try:
        # memory-mapping reads the header and checks the declared size against the file
        # without allocating; object (pickled) arrays cannot be mapped and are refused
        mm = np.load(p, mmap_mode="r", allow_pickle=False)
        arr = np.array(mm)
        del mm
    except Exception as exc:
        raise MapFormatError(
            f"{p}: not a readable .npy array of bool or 0/1 values ({type(exc).__name__}: {exc})"
        ) from None
    if not isinstance(arr, np.ndarray):
        raise MapFormatError(f"{p}: expected a single array, got {type(arr).__name__}")
    return arr
