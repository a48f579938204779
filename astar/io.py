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
import math
import os
import re
import reprlib
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np

from astar.errors import InvalidInputError, MapFormatError
from astar.files import atomic_write
from astar.grid import OccupancyGrid

__all__ = [
    "IMAGE_SUFFIXES",
    "MAX_IMAGE_PIXELS",
    "Scenario",
    "from_intensity",
    "load_map",
    "read_map_values",
    "read_scenarios",
    "save_map",
]

logger = logging.getLogger(__name__)

#: Suffixes read as plain images by :func:`load_map` (and as the image named in a ROS YAML).
IMAGE_SUFFIXES: tuple[str, ...] = (
    ".pgm",
    ".pbm",
    ".ppm",
    ".pnm",
    ".png",
    ".bmp",
    ".gif",
    ".tif",
    ".tiff",
    ".jpg",
    ".jpeg",
)
#: Largest image (pixels) a map may declare; checked from the header before decoding, so a
#: small compressed file cannot make the loader allocate gigabytes (Pillow's own limit only
#: warns below twice its default of about 89 million pixels).
MAX_IMAGE_PIXELS = 89_478_485
_YAML_SUFFIXES = (".yaml", ".yml")
_SUPPORTED = (*_YAML_SUFFIXES, ".map", *IMAGE_SUFFIXES, ".npy")

#: Thresholds used for plain images (those of a typical ROS map YAML).
_IMAGE_OCCUPIED_THRESH = 0.65
_IMAGE_FREE_THRESH = 0.196

#: What :func:`save_map` writes (the defaults of Nav2's map saver).
_SAVE_OCCUPIED_THRESH = 0.65
_SAVE_FREE_THRESH = 0.25
_SAVE_OCCUPIED_PIXEL = 0
_SAVE_FREE_PIXEL = 254

#: map_server's cell values (``nav_msgs/OccupancyGrid``).
_FREE, _OCCUPIED, _UNKNOWN = 0, 100, -1

MapMode = Literal["trinary", "scale", "raw"]
_MODES: tuple[str, ...] = ("trinary", "scale", "raw")


# ====================================================================== public API
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
        resolution = _positive_float_arg(resolution, "resolution")
    origin_xy = _origin_arg(origin)
    suffix = p.suffix.lower()
    if suffix not in _SUPPORTED:
        raise MapFormatError(
            f"{p}: unsupported map file suffix {p.suffix!r}; supported suffixes are "
            f"{', '.join(_SUPPORTED)}"
        )
    if not p.is_file():
        raise MapFormatError(f"{p}: map file does not exist (or is not a regular file)")
    if suffix in _YAML_SUFFIXES:
        grid = _load_ros(p, resolution, origin_xy, bool(unknown_occupied))
    elif suffix == ".map":
        occ = _read_movingai(p)
        grid = _make_grid(p, occ, 1.0 if resolution is None else resolution, origin_xy)
    elif suffix == ".npy":
        occ = _read_npy(p)
        grid = _make_grid(p, occ, 1.0 if resolution is None else resolution, origin_xy)
    else:
        if resolution is None:
            raise InvalidInputError(
                f"{p}: resolution (m/cell) is required to load an image map; "
                "pass load_map(path, resolution=...)"
            )
        values = _map_server_values(
            _read_pixels(p, p),
            mode="trinary",
            negate=False,
            occupied_thresh=_IMAGE_OCCUPIED_THRESH,
            free_thresh=_IMAGE_FREE_THRESH,
        )
        occ = _values_to_occupied(
            values,
            mode="trinary",
            occupied_thresh=_IMAGE_OCCUPIED_THRESH,
            free_thresh=_IMAGE_FREE_THRESH,
            unknown_occupied=True,
        )
        grid = _make_grid(p, occ[::-1], resolution, origin_xy)
    logger.debug("loaded %s: %r", p, grid)
    return grid


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
    if p.suffix.lower() not in _YAML_SUFFIXES:
        raise MapFormatError(
            f"{p}: expected a map_server YAML file ({', '.join(_YAML_SUFFIXES)}), "
            f"got suffix {p.suffix!r}"
        )
    if not p.is_file():
        raise MapFormatError(f"{p}: map file does not exist (or is not a regular file)")
    meta = _read_ros_yaml(p)
    if not meta.image.is_file():
        raise MapFormatError(
            f"{p}: field image: image file {str(meta.image)!r} does not exist "
            "(relative paths are resolved against the YAML file's folder)"
        )
    values = _map_server_values(
        _read_pixels(meta.image, p),
        mode=meta.mode,
        negate=meta.negate,
        occupied_thresh=meta.occupied_thresh,
        free_thresh=meta.free_thresh,
    )
    return np.ascontiguousarray(values[::-1]), meta.resolution, meta.origin, meta.mode


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
    if yp.suffix.lower() not in _YAML_SUFFIXES:
        raise InvalidInputError(
            f"yaml_path must end in .yaml or .yml, got {str(yp)!r} (suffix {yp.suffix!r})"
        )
    if not yp.parent.is_dir():
        raise InvalidInputError(f"yaml_path folder {str(yp.parent)!r} does not exist")
    image_path = yp.with_suffix(".pgm")

    import yaml

    pixels = np.where(grid.occupied[::-1], _SAVE_OCCUPIED_PIXEL, _SAVE_FREE_PIXEL).astype(np.uint8)
    header = f"P5\n# written by astar.save_map\n{grid.nx} {grid.ny}\n255\n".encode("ascii")
    _atomic_write(image_path, header + pixels.tobytes())
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
    _atomic_write(yp, text.encode("utf-8"))
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


@dataclass(frozen=True, slots=True)
class Scenario:
    """One Moving AI benchmark query, with cells in this project's convention.

    Parameters
    ----------
    bucket : int
        The benchmark's difficulty bucket (>= 0).
    map_name : str
        File name of the map (any folder prefix of the ``.scen`` entry removed).
    width, height : int
        Map size in cells (> 0).
    start, goal : tuple of int
        Cells ``(ix, iy)`` with row 0 at the bottom: ``ix = x`` and
        ``iy = height - 1 - y`` for the file's ``(x, y)`` (row 0 at the top).
    optimal_length : float
        The benchmark's optimal length in cells (8-connected, diagonal sqrt(2), no corner
        cutting), >= 0.
    """

    bucket: int
    map_name: str
    width: int
    height: int
    start: tuple[int, int]
    goal: tuple[int, int]
    optimal_length: float

    def __post_init__(self) -> None:
        bucket = _nonneg_int(self.bucket, "bucket")
        width = _nonneg_int(self.width, "width")
        height = _nonneg_int(self.height, "height")
        if width == 0 or height == 0:
            raise InvalidInputError(f"width and height must be > 0, got {width} x {height}")
        if not isinstance(self.map_name, str) or not self.map_name:
            raise InvalidInputError(f"map_name must be a non-empty str, got {self.map_name!r}")
        cells = {}
        for name in ("start", "goal"):
            value = getattr(self, name)
            try:
                ix, iy = (_nonneg_int(v, name) for v in value)
            except (TypeError, ValueError) as exc:
                raise InvalidInputError(
                    f"{name} must be a cell (ix, iy) of two ints >= 0, got {value!r}"
                ) from exc
            if ix >= width or iy >= height:
                raise InvalidInputError(
                    f"{name} cell ({ix}, {iy}) lies outside the {width} x {height} map"
                )
            cells[name] = (ix, iy)
        try:
            length = float(self.optimal_length)
        except (TypeError, ValueError) as exc:
            raise InvalidInputError(
                f"optimal_length must be a number, got {self.optimal_length!r}"
            ) from exc
        if not math.isfinite(length) or length < 0.0:
            raise InvalidInputError(f"optimal_length must be finite and >= 0, got {length!r}")
        object.__setattr__(self, "bucket", bucket)
        object.__setattr__(self, "width", width)
        object.__setattr__(self, "height", height)
        object.__setattr__(self, "start", cells["start"])
        object.__setattr__(self, "goal", cells["goal"])
        object.__setattr__(self, "optimal_length", length)

    @classmethod
    def _construct_fast(
        cls,
        bucket: int,
        map_name: str,
        width: int,
        height: int,
        start: tuple[int, int],
        goal: tuple[int, int],
        optimal_length: float,
    ) -> Scenario:
        """Build without validation (internal: the reader has checked every field)."""
        self = object.__new__(cls)
        for name, value in (
            ("bucket", bucket),
            ("map_name", map_name),
            ("width", width),
            ("height", height),
            ("start", start),
            ("goal", goal),
            ("optimal_length", optimal_length),
        ):
            object.__setattr__(self, name, value)
        return self


_SCEN_INT_FIELDS = tuple(
    (i, name)
    for i, name in enumerate(
        ("bucket", "map", "width", "height", "start_x", "start_y", "goal_x", "goal_y")
    )
    if name != "map"
)


def read_scenarios(path: str | os.PathLike[str]) -> list[Scenario]:
    """Read a Moving AI ``.scen`` file (version 1).

    The first non-blank line must be ``version 1`` (or ``version 1.0``); every further
    non-blank line holds nine fields separated by tabs (or, in a line without tabs, by
    whitespace): ``bucket map width height start_x start_y goal_x goal_y optimal_length``.
    ``x`` is the column and ``y`` the row counted from the top; the records convert them to
    ``(ix, iy) = (x, height - 1 - y)``. LF and CRLF line endings are accepted.

    Parameters
    ----------
    path : str or os.PathLike
        The ``.scen`` file.

    Returns
    -------
    list of Scenario
        In file order (empty when the file holds only the header).

    Raises
    ------
    MapFormatError
        Missing file, missing or unsupported version header, a line with the wrong number
        of fields, a non-integer or negative coordinate, a cell outside the map, a bad
        length; the message names the file, the line and the field.
    """
    p = Path(path)
    text = _read_text(p)
    lines = text.splitlines()
    n = 0
    while n < len(lines) and not lines[n].strip():
        n += 1
    if n == len(lines):
        raise MapFormatError(f"{p}: empty scenario file; expected a 'version 1' header line")
    header = lines[n].split()
    if len(header) != 2 or header[0].lower() != "version" or header[1] not in ("1", "1.0"):
        raise MapFormatError(
            f"{p}, line {n + 1}: expected the header 'version 1' (or 'version 1.0'), "
            f"got {lines[n].strip()[:80]!r}"
        )
    out: list[Scenario] = []
    for lineno, raw in enumerate(lines[n + 1 :], start=n + 2):
        line = raw.strip()
        if not line:
            continue
        fields = [f.strip() for f in line.split("\t")] if "\t" in line else line.split()
        if len(fields) != 9:
            raise MapFormatError(
                f"{p}, line {lineno}: expected 9 fields (bucket, map, width, height, start_x, "
                f"start_y, goal_x, goal_y, optimal_length), got {len(fields)}"
            )
        ints: dict[str, int] = {}
        for i, name in _SCEN_INT_FIELDS:
            f = fields[i]
            if not (f.isascii() and f.isdigit()):
                raise MapFormatError(
                    f"{p}, line {lineno}: field {name} must be an integer >= 0, got {f[:40]!r}"
                )
            ints[name] = int(f)
        try:
            length = float(fields[8])
        except ValueError:
            length = math.nan
        if not (length >= 0.0 and math.isfinite(length)):
            raise MapFormatError(
                f"{p}, line {lineno}: field optimal_length must be a finite number >= 0, "
                f"got {fields[8][:40]!r}"
            )
        w, h = ints["width"], ints["height"]
        if w == 0 or h == 0:
            raise MapFormatError(
                f"{p}, line {lineno}: fields width and height must be > 0, got {w} x {h}"
            )
        for name in ("start_x", "start_y", "goal_x", "goal_y"):
            limit = h if name[-1] == "y" else w
            if ints[name] >= limit:
                raise MapFormatError(
                    f"{p}, line {lineno}: field {name} = {ints[name]} must be < "
                    f"{'height' if name[-1] == 'y' else 'width'} = {limit}"
                )
        map_name = re.split(r"[\\/]", fields[1])[-1]
        if not map_name:
            raise MapFormatError(
                f"{p}, line {lineno}: field map must name a map file, got {fields[1][:80]!r}"
            )
        out.append(
            Scenario._construct_fast(
                ints["bucket"],
                map_name,
                w,
                h,
                (ints["start_x"], h - 1 - ints["start_y"]),
                (ints["goal_x"], h - 1 - ints["goal_y"]),
                length,
            )
        )
    return out


# ====================================================================== ROS map_server
@dataclass(frozen=True, slots=True)
class _RosMeta:
    image: Path
    resolution: float
    origin: tuple[float, float]
    negate: bool
    occupied_thresh: float
    free_thresh: float
    mode: str


def _load_ros(
    p: Path, resolution: float | None, origin: tuple[float, float], unknown_occupied: bool
) -> OccupancyGrid:
    meta = _read_ros_yaml(p)
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
    if not meta.image.is_file():
        raise MapFormatError(
            f"{p}: field image: image file {str(meta.image)!r} does not exist "
            "(relative paths are resolved against the YAML file's folder)"
        )
    values = _map_server_values(
        _read_pixels(meta.image, p),
        mode=meta.mode,
        negate=meta.negate,
        occupied_thresh=meta.occupied_thresh,
        free_thresh=meta.free_thresh,
    )
    occ = _values_to_occupied(
        values,
        mode=meta.mode,
        occupied_thresh=meta.occupied_thresh,
        free_thresh=meta.free_thresh,
        unknown_occupied=unknown_occupied,
    )
    return _make_grid(p, occ[::-1], meta.resolution, meta.origin)


def _read_ros_yaml(p: Path) -> _RosMeta:
    import yaml

    text = _read_text(p)
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
            f"{p}: field image must be a non-empty file name, got {_short_repr(image)}"
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
            f"{p}: field origin must be a list of 3 numbers [x, y, yaw], got {_short_repr(raw_origin)}"
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
            f"got {_short_repr(mode)}"
        )
    return _RosMeta(image_path, res, (ox, oy), negate, occ_th, free_th, mode)


def _yaml_number(p: Path, name: str, value: object) -> float:
    # PyYAML (YAML 1.1) reads "1e-3" as a string; map_server's yaml-cpp reads it as a
    # number, so numeric strings are accepted. Booleans are not numbers here.
    if isinstance(value, bool) or not isinstance(value, int | float | str):
        raise MapFormatError(f"{p}: field {name} must be a number, got {_short_repr(value)}")
    try:
        v = float(value)
    except ValueError:
        raise MapFormatError(
            f"{p}: field {name} must be a number, got {_short_repr(value)}"
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
    raise MapFormatError(f"{p}: field negate must be 0, 1 or a bool, got {_short_repr(value)}")


def _map_server_values(
    pixels: _Pixels,
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


def _values_to_occupied(
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


# ====================================================================== images
@dataclass(frozen=True, slots=True)
class _Pixels:
    """Image pixels, top row first: ``rgb_sum`` = R + G + B (float ``[h, w]``), ``alpha``
    (float ``[h, w]``, ``maxval`` = opaque) or None, both on the scale 0..``maxval``."""

    rgb_sum: np.ndarray
    alpha: np.ndarray | None
    maxval: float


_GREY_MODES = {"1": 255.0, "L": 255.0, "I": 65535.0, "I;16": 65535.0, "I;16L": 65535.0}
_GREY_MODES.update({"I;16B": 65535.0, "I;16N": 65535.0})


def _read_pixels(image: Path, source: Path) -> _Pixels:
    """Decode an image with Pillow (errors wrapped as MapFormatError naming ``source``)."""
    from PIL import Image

    _check_netpbm_size(image, source)
    try:
        with Image.open(image) as im:
            w, h = im.size  # from the header, before any pixel is decoded
            if w * h > MAX_IMAGE_PIXELS:
                raise MapFormatError(
                    f"{source}: image {str(image)!r} declares {w} x {h} = {w * h} pixels, "
                    f"more than astar.io.MAX_IMAGE_PIXELS = {MAX_IMAGE_PIXELS}"
                )
            im.load()
            mode = im.mode
            if mode in _GREY_MODES:
                top = _GREY_MODES[mode]
                grey = np.asarray(im.convert("L") if mode == "1" else im)
                if grey.dtype.kind not in "ui" or grey.ndim != 2:
                    raise ValueError(f"unexpected pixel array {grey.dtype} {grey.shape}")
                if grey.size and (int(grey.min()) < 0 or int(grey.max()) > top):
                    raise MapFormatError(
                        f"{source}: image {str(image)!r} has pixel values outside 0..{top:.0f}; "
                        "only 8- and 16-bit images are supported"
                    )
                return _Pixels(grey * 3.0, None, top)
            if mode in ("P", "PA", "LA", "La", "RGBA"):
                if mode == "P" and "transparency" not in im.info:
                    arr = np.asarray(im.convert("RGB"))
                else:
                    arr = np.asarray(im if mode == "RGBA" else im.convert("RGBA"))
            elif mode in ("RGB", "RGBa", "RGBX", "CMYK", "YCbCr", "LAB", "HSV"):
                arr = np.asarray(im if mode == "RGB" else im.convert("RGB"))
            else:
                raise MapFormatError(
                    f"{source}: image {str(image)!r} has unsupported pixel mode {mode!r} "
                    "(expected grey, RGB or palette, with or without alpha, 8 or 16 bit)"
                )
            if arr.ndim != 3 or arr.shape[2] not in (3, 4) or arr.dtype != np.uint8:
                raise ValueError(f"unexpected pixel array {arr.dtype} {arr.shape}")
            rgb_sum = arr[:, :, :3].sum(axis=2, dtype=np.float64)
            alpha = arr[:, :, 3].astype(np.float64) if arr.shape[2] == 4 else None
            return _Pixels(rgb_sum, alpha, 255.0)
    except MapFormatError:
        raise
    except Exception as exc:  # Pillow raises many types (OSError, SyntaxError, ...)
        raise MapFormatError(
            f"{source}: cannot read image {str(image)!r} as a map ({type(exc).__name__}: {exc})"
        ) from None


def _check_netpbm_size(image: Path, source: Path) -> None:
    """Compare a netpbm (PBM/PGM/PPM) header's declared size with the file size.

    Pillow would otherwise allocate the declared size before noticing a truncated file.
    Binary variants (P4-P6) need the exact byte count; plain-text ones (P1-P3) at least one
    byte per sample. Other formats are left to Pillow (whose decompression-bomb limit
    refuses more than ~179 million pixels).
    """
    try:
        with open(image, "rb") as f:
            head = f.read(4096)
        size = image.stat().st_size
    except OSError as exc:
        raise MapFormatError(f"{source}: cannot read image {str(image)!r}: {exc}") from None
    magic = head[:2]
    if magic not in (b"P1", b"P2", b"P3", b"P4", b"P5", b"P6"):
        return
    tokens: list[bytes] = []
    pos = 2
    need = 2 if magic in (b"P1", b"P4") else 3
    while len(tokens) < need and pos < len(head):
        c = head[pos : pos + 1]
        if c == b"#":
            end = head.find(b"\n", pos)
            pos = len(head) if end < 0 else end + 1
        elif c.isspace():
            pos += 1
        else:
            m = re.match(rb"[0-9]+", head[pos:])
            if not m:
                raise MapFormatError(
                    f"{source}: image {str(image)!r}: malformed netpbm header near byte {pos} "
                    "(expected width, height and maxval as decimal integers)"
                )
            tokens.append(m.group())
            pos += len(m.group())
    if len(tokens) < need:
        raise MapFormatError(
            f"{source}: image {str(image)!r}: truncated netpbm header (width, height, maxval)"
        )
    w, h = int(tokens[0]), int(tokens[1])
    if w <= 0 or h <= 0:
        raise MapFormatError(
            f"{source}: image {str(image)!r}: width and height must be > 0, got {w} x {h}"
        )
    if magic == b"P4":
        expected = ((w + 7) // 8) * h
    elif magic == b"P1":
        expected = w * h
    else:
        maxval = int(tokens[2])
        if not 0 < maxval < 65536:
            raise MapFormatError(
                f"{source}: image {str(image)!r}: maxval must be in 1..65535, got {maxval}"
            )
        channels = 3 if magic in (b"P3", b"P6") else 1
        if magic in (b"P2", b"P3"):
            expected = w * h * channels
        else:
            expected = w * h * channels * (1 if maxval < 256 else 2)
    available = size - (pos + 1)
    if expected > available:
        raise MapFormatError(
            f"{source}: image {str(image)!r} declares {w} x {h} pixels ({expected} bytes) but "
            f"only {max(available, 0)} bytes of pixel data follow the header (truncated?)"
        )


# ====================================================================== Moving AI
# 0 = free, 1 = occupied, 255 = not a terrain character
_MOVINGAI_LUT = np.full(256, 255, dtype=np.uint8)
for _ch in b".GS":
    _MOVINGAI_LUT[_ch] = 0
for _ch in b"@OTW":
    _MOVINGAI_LUT[_ch] = 1


def _read_movingai(p: Path) -> np.ndarray:
    """Occupancy ``[iy, ix]`` (bottom row first) of a Moving AI ``.map``."""
    data = _read_bytes(p)
    lines = data.split(b"\n")
    header: dict[str, int] = {}
    i = 0
    # header: "type octile", then "height H" and "width W" (either order), then "map"
    while True:
        if i >= len(lines) or i > 16:
            raise MapFormatError(
                f"{p}: truncated or malformed header; expected 'type octile', 'height H', "
                "'width W' and 'map' lines"
            )
        tokens = lines[i].strip().split()
        i += 1
        if not tokens:
            continue
        try:
            key = tokens[0].decode("ascii").lower()
        except UnicodeDecodeError:
            raise MapFormatError(f"{p}, line {i}: non-ASCII header line") from None
        if key == "map" and len(tokens) == 1:
            break
        if key == "type":
            if len(tokens) != 2 or tokens[1] != b"octile":
                raise MapFormatError(
                    f"{p}, line {i}: field type must be 'octile', got {lines[i - 1][:40]!r}"
                )
            header["type"] = 1
        elif key in ("height", "width"):
            if len(tokens) != 2 or not re.fullmatch(rb"[0-9]{1,9}", tokens[1]):
                raise MapFormatError(
                    f"{p}, line {i}: field {key} must be a positive integer, "
                    f"got {lines[i - 1].strip()[:40]!r}"
                )
            header[key] = int(tokens[1])
        else:
            raise MapFormatError(
                f"{p}, line {i}: unexpected header line {lines[i - 1].strip()[:40]!r}; "
                "expected 'type octile', 'height H', 'width W', 'map'"
            )
    for key in ("type", "height", "width"):
        if key not in header:
            raise MapFormatError(f"{p}: header field {key} is missing before the 'map' line")
    h, w = header["height"], header["width"]
    if h <= 0 or w <= 0:
        raise MapFormatError(f"{p}: height and width must be > 0, got height {h}, width {w}")
    body_bytes = sum(len(line) for line in lines[i:])
    if h * w > body_bytes:
        raise MapFormatError(
            f"{p}: declares height {h} x width {w} = {h * w} cells but only {body_bytes} "
            "bytes follow the 'map' line (truncated?)"
        )
    rows = [line.rstrip(b" \t\r") for line in lines[i : i + h]]
    if len(rows) < h:
        raise MapFormatError(f"{p}: declares height {h} but has only {len(rows)} map rows")
    for r, row in enumerate(rows):
        if len(row) != w:
            raise MapFormatError(
                f"{p}, line {i + r + 1}: map row {r} has {len(row)} characters, expected width {w}"
            )
    extra = [line for line in lines[i + h :] if line.strip()]
    if extra:
        raise MapFormatError(
            f"{p}, line {i + h + 1}: more map rows than the declared height {h} "
            "(or trailing garbage after the map)"
        )
    codes = _MOVINGAI_LUT[np.frombuffer(b"".join(rows), dtype=np.uint8)].reshape(h, w)
    bad = codes == 255
    if np.any(bad):
        r, c = (int(v) for v in np.argwhere(bad)[0])
        ch = rows[r][c : c + 1]
        raise MapFormatError(
            f"{p}, line {i + r + 1}, column {c + 1}: unknown terrain character {ch!r}; "
            "allowed: . G S (passable), @ O T W (blocked)"
        )
    return codes[::-1] == 1


# ====================================================================== NumPy
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


# ====================================================================== helpers
def _make_grid(
    p: Path, occupied: np.ndarray, resolution: float, origin: tuple[float, float]
) -> OccupancyGrid:
    try:
        return OccupancyGrid(occupied, resolution, origin)
    except InvalidInputError as exc:
        raise MapFormatError(f"{p}: {exc}") from None


def _read_bytes(p: Path) -> bytes:
    try:
        return p.read_bytes()
    except OSError as exc:
        raise MapFormatError(f"{p}: cannot read file: {exc}") from None


def _read_text(p: Path) -> str:
    data = _read_bytes(p)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise MapFormatError(f"{p}: not UTF-8/ASCII text ({exc})") from None


_REPR = reprlib.Repr()
_REPR.maxlevel = 2
_REPR.maxlist = _REPR.maxtuple = _REPR.maxdict = 4
_REPR.maxstring = 80
_REPR.maxother = 80


def _short_repr(value: object) -> str:
    """A bounded repr for error messages: YAML aliases can make a tiny file describe a
    structure with billions of elements (a "billion laughs" document), whose full repr
    would never finish."""
    return _REPR.repr(value)


def _positive_float_arg(value: object, name: str) -> float:
    if isinstance(value, bool):
        raise InvalidInputError(f"{name} must be a number, got {value!r}")
    try:
        v = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise InvalidInputError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(v) or v <= 0.0:
        raise InvalidInputError(f"{name} must be finite and > 0, got {v!r}")
    return v


def _origin_arg(origin: object) -> tuple[float, float]:
    try:
        ox, oy = (float(v) for v in origin)  # type: ignore[union-attr]
    except (TypeError, ValueError):
        raise InvalidInputError(
            f"origin must be two numbers (x, y) in metres, got {origin!r}"
        ) from None
    if not (math.isfinite(ox) and math.isfinite(oy)):
        raise InvalidInputError(f"origin must be finite, got ({ox}, {oy})")
    return ox, oy


def _nonneg_int(value: object, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise InvalidInputError(f"{name} must be an int, got {value!r}")
    v = int(value)
    if v < 0:
        raise InvalidInputError(f"{name} must be >= 0, got {v}")
    return v


def _atomic_write(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically (:func:`astar.files.atomic_write`)."""
    atomic_write(path, lambda tmp: tmp.write_bytes(data))
