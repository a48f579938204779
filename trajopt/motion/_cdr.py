"""CDR encoding of the ROS 2 messages in the MCAP files of :mod:`trajopt.motion._mcap`.

Little-endian CDR (XCDR1, the ROS 2 wire format) of the occupancy grids, the stamped poses
and the path, and of the ``visualization_msgs/Marker`` line strips: the corridor's regions
and the predicted movers' tracks and outlines over time.
"""

from __future__ import annotations

import functools
import math
import struct
from dataclasses import dataclass
from typing import Any

import numpy as np

from astar.grid import OccupancyGrid
from trajopt.geometry import rounded_polygon

#: Colours ``(r, g, b)`` of the movers' markers, in order (repeated beyond four).
MOVER_RGB = ((0.84, 0.15, 0.16), (1.0, 0.5, 0.05), (0.55, 0.34, 0.29), (0.89, 0.47, 0.76))
#: Points per full turn of a mover outline's arcs.
MOVER_ARC_POINTS = 32


class CdrWriter:
    """Little-endian CDR (XCDR1) writer.

    Primitives aligned to their size from the start of the payload (after the 4-byte
    encapsulation header).
    """

    __slots__ = ("buf",)

    def __init__(self) -> None:
        self.buf = bytearray(b"\x00\x01\x00\x00")

    def _align(self, n: int) -> None:
        pad = (-(len(self.buf) - 4)) % n
        if pad:
            self.buf += b"\x00" * pad

    def pack(self, fmt: str, size: int, *values: Any) -> None:
        self._align(size)
        self.buf += struct.pack("<" + fmt, *values)

    def string(self, s: str) -> None:
        data = s.encode("utf-8") + b"\x00"
        self.pack("I", 4, len(data))
        self.buf += data

    def byte_seq(self, data: bytes) -> None:
        self.pack("I", 4, len(data))
        self.buf += data

    def time(self, ns: int) -> None:
        self.pack("iI", 4, ns // 1_000_000_000, ns % 1_000_000_000)

    def header(self, ns: int, frame_id: str) -> None:
        self.time(ns)
        self.string(frame_id)

    def pose(self, x: float, y: float, qz: float, qw: float) -> None:
        self.pack("7d", 8, x, y, 0.0, 0.0, 0.0, qz, qw)

    def data(self) -> bytes:
        return bytes(self.buf)


def encode_grid(grid: OccupancyGrid, ns: int, frame_id: str) -> bytes:
    w = CdrWriter()
    w.header(ns, frame_id)
    w.time(ns)
    ny, nx = grid.shape
    w.pack("fII", 4, float(grid.resolution), nx, ny)
    w.pose(float(grid.origin[0]), float(grid.origin[1]), 0.0, 1.0)
    w.byte_seq(np.where(grid.occupied, 100, 0).astype(np.int8).tobytes())
    return w.data()


def encode_pose_stamped(w: CdrWriter, ns: int, frame_id: str, x, y, qz, qw) -> None:
    w.header(ns, frame_id)
    w.pose(x, y, qz, qw)


def encode_path(ns0: int, stamps, frame_id: str, x, y, qz, qw) -> bytes:
    w = CdrWriter()
    w.header(ns0, frame_id)
    w.pack("I", 4, len(stamps))
    for k in range(len(stamps)):
        encode_pose_stamped(w, int(stamps[k]), frame_id, x[k], y[k], qz[k], qw[k])
    return w.data()


def marker(
    w: CdrWriter,
    ns: int,
    frame_id: str,
    namespace: str,
    ident: int,
    pose: tuple[float, float, float, float],
    width: float,
    rgba: tuple[float, float, float, float],
    points: np.ndarray,
    text: str = "",
) -> None:
    """Append one ``LINE_STRIP`` marker (``points`` (k, 2) in the marker's pose frame)."""
    w.header(ns, frame_id)
    w.string(namespace)
    w.pack("iii", 4, ident, 4, 0)  # id, LINE_STRIP, ADD
    w.pose(*pose)
    w.pack("3d", 8, width, 0.0, 0.0)  # scale.x: line width (m)
    w.pack("4f", 4, *rgba)
    w.pack("iI", 4, 0, 0)  # lifetime 0: forever
    w.pack("?", 1, False)
    w.pack("I", 4, len(points))
    if len(points):  # geometry_msgs/Point[]: (x, y, 0) after one alignment to 8
        xyz = np.zeros((len(points), 3))
        xyz[:, :2] = points
        w.pack(f"{3 * len(points)}d", 8, *xyz.ravel().tolist())
    w.buf += marker_tail(text)


@functools.lru_cache(maxsize=256)
def marker_tail(text: str) -> bytes:
    """Return the fields of a marker after its points, for a ``text``: constant bytes.

    They start 4-aligned (after 8-byte points, or after the 4-byte count) and need no
    alignment above 4, so their encoding does not depend on where they start.
    """
    w = CdrWriter()
    w.pack("I", 4, 0)  # colors
    w.string("")  # texture_resource
    w.header(0, "")  # texture.header
    w.string("")  # texture.format
    w.byte_seq(b"")  # texture.data
    w.pack("I", 4, 0)  # uv_coordinates
    w.string(text)
    w.string("")  # mesh_resource
    w.string("")  # mesh_file.filename
    w.byte_seq(b"")  # mesh_file.data
    w.pack("?", 1, False)
    return bytes(w.buf[4:])


def closed(poly: np.ndarray) -> np.ndarray:
    return np.vstack([poly, poly[:1]]) if len(poly) > 1 else poly


def encode_markers(polygons: list[np.ndarray], ns: int, frame_id: str) -> bytes:
    w = CdrWriter()
    w.pack("I", 4, len(polygons))
    for k, poly in enumerate(polygons):
        marker(w, ns, frame_id, "corridor", k, (0.0, 0.0, 0.0, 1.0), 0.01,
                (0.1, 0.45, 0.85, 1.0), closed(poly))  # fmt: skip
    return w.data()


def encode_predicted(movers: tuple[Any, ...], ns: int, frame_id: str) -> bytes:
    w = CdrWriter()
    w.pack("I", 4, len(movers))
    for j, m in enumerate(movers):
        pts = np.asarray(m.positions, dtype=float)
        if len(pts) == 1:  # a line strip needs two points
            pts = np.vstack([pts, pts])
        rgb = MOVER_RGB[j % len(MOVER_RGB)]
        marker(w, ns, frame_id, "predicted", j, (0.0, 0.0, 0.0, 1.0), 0.01, (*rgb, 0.5), pts,
                m.name)  # fmt: skip
    return w.data()


@dataclass(frozen=True)
class MoverFrames:
    """A mover sampled at the frame times: reference points (m), headings (rad), outlines.

    Its outline at radius ``r`` is ``base + r * spread`` (the rounded polygon's points move
    along fixed unit directions as the radius grows; :func:`trajopt.geometry.rounded_polygon`).
    """

    name: str
    centre: np.ndarray  # (n, 2)
    heading: np.ndarray  # (n,)
    radius: np.ndarray  # (n,)
    base: np.ndarray  # (k, 2), closed
    spread: np.ndarray  # (k, 2), closed

    @classmethod
    def of(cls, mover: Any, times: np.ndarray) -> MoverFrames:
        c, h = mover.pose_at(times)
        v = np.asarray(mover.shape_vertices, dtype=float)
        one = closed(rounded_polygon(v, 1.0, arc_points=MOVER_ARC_POINTS))
        two = closed(rounded_polygon(v, 2.0, arc_points=MOVER_ARC_POINTS))
        return cls(
            name=str(mover.name),
            centre=np.asarray(c, dtype=float).reshape(-1, 2),
            heading=np.asarray(h, dtype=float).reshape(-1),
            radius=np.asarray(mover.radius_at(times), dtype=float).reshape(-1),
            base=2.0 * one - two,
            spread=two - one,
        )


def encode_movers_at(frames: list[MoverFrames], k: int, ns: int, frame_id: str) -> bytes:
    """Encode every mover's marker at frame ``k`` (stamp ``ns``)."""
    w = CdrWriter()
    w.pack("I", 4, len(frames))
    for j, f in enumerate(frames):
        half = 0.5 * float(f.heading[k])
        pose = (float(f.centre[k, 0]), float(f.centre[k, 1]), math.sin(half), math.cos(half))
        outline = f.base + float(f.radius[k]) * f.spread
        rgb = MOVER_RGB[j % len(MOVER_RGB)]
        marker(w, ns, frame_id, "movers", j, pose, 0.02, (*rgb, 1.0), outline, f.name)
    return w.data()
