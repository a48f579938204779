"""Image maps: decoding pixels with Pillow, and netpbm headers checked before decoding.

A map image (PGM, PNG, ...) is read into :class:`Pixels` (the sum of the colour channels
and the alpha channel, on the image's own scale), from which :mod:`astar.ros_map` computes
map_server's cell values. Netpbm headers are compared with the file size before Pillow
sees the file, and every image's declared size with :data:`MAX_IMAGE_PIXELS`, so a
truncated or lying file fails without allocating.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from astar.errors import MapFormatError

__all__ = ["IMAGE_SUFFIXES", "MAX_IMAGE_PIXELS", "Pixels", "check_netpbm_size", "read_pixels"]

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


@dataclass(frozen=True, slots=True)
class Pixels:
    """Image pixels, top row first.

    ``rgb_sum`` = R + G + B (float ``[h, w]``), ``alpha`` (float ``[h, w]``, ``maxval`` =
    opaque) or None, both on the scale 0..``maxval``.
    """

    rgb_sum: np.ndarray
    alpha: np.ndarray | None
    maxval: float


_GREY_MODES = {"1": 255.0, "L": 255.0, "I": 65535.0, "I;16": 65535.0, "I;16L": 65535.0}
_GREY_MODES.update({"I;16B": 65535.0, "I;16N": 65535.0})


def read_pixels(image: Path, source: Path) -> Pixels:
    """Decode an image with Pillow (errors wrapped as MapFormatError naming ``source``).

    Parameters
    ----------
    image : pathlib.Path
        The image file.
    source : pathlib.Path
        The file named in error messages (the YAML file that names the image, or the image).

    Returns
    -------
    Pixels
        Top row first, as stored in the file.
    """
    from PIL import Image

    check_netpbm_size(image, source)
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
                return Pixels(grey * 3.0, None, top)
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
            return Pixels(rgb_sum, alpha, 255.0)
    except MapFormatError:
        raise
    except Exception as exc:  # Pillow raises many types (OSError, SyntaxError, ...)
        raise MapFormatError(
            f"{source}: cannot read image {str(image)!r} as a map ({type(exc).__name__}: {exc})"
        ) from None


def check_netpbm_size(image: Path, source: Path) -> None:
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
