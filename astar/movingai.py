"""Moving AI benchmark files: ``.map`` grids and ``.scen`` scenario lists.

:func:`read_movingai` reads a ``type octile`` map into an occupancy array with row 0 at
the bottom; :func:`read_scenarios` reads a ``version 1`` scenario file into
:class:`Scenario` records whose cells are already in this project's bottom-row-0
``(ix, iy)`` convention.
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from astar import validation
from astar.errors import InvalidInputError, MapFormatError
from astar.files import read_bytes, read_text

__all__ = ["Scenario", "read_movingai", "read_scenarios"]


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
        bucket = validation.nonnegative_int("bucket", self.bucket)
        width = validation.nonnegative_int("width", self.width)
        height = validation.nonnegative_int("height", self.height)
        if width == 0 or height == 0:
            raise InvalidInputError(f"width and height must be > 0, got {width} x {height}")
        if not isinstance(self.map_name, str) or not self.map_name:
            raise InvalidInputError(f"map_name must be a non-empty str, got {self.map_name!r}")
        cells = {}
        for name in ("start", "goal"):
            value = getattr(self, name)
            try:
                ix, iy = (validation.nonnegative_int(name, v) for v in value)
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
    text = read_text(p)
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


# 0 = free, 1 = occupied, 255 = not a terrain character
_MOVINGAI_LUT = np.full(256, 255, dtype=np.uint8)
for _ch in b".GS":
    _MOVINGAI_LUT[_ch] = 0
for _ch in b"@OTW":
    _MOVINGAI_LUT[_ch] = 1


def read_movingai(p: Path) -> np.ndarray:
    """Occupancy of a Moving AI ``.map`` (``type octile``).

    Parameters
    ----------
    p : pathlib.Path
        The ``.map`` file.

    Returns
    -------
    ndarray of bool, shape (height, width)
        ``[iy, ix]``, bottom row (the file's last line) first; ``True`` = occupied.

    Raises
    ------
    MapFormatError
        Malformed header, rows of the wrong width or count, unknown terrain characters.
    """
    data = read_bytes(p)
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
