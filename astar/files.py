"""File access shared by the map readers and writers, the trajectory exporters and the CLI.

:func:`atomic_write` replaces a file atomically; :func:`read_bytes`, :func:`read_text` and
:func:`grid_from_file` are the map readers' ways to read a file and to build its grid, each
raising :class:`~astar.errors.MapFormatError` that names the file.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from astar.errors import InvalidInputError, MapFormatError

if TYPE_CHECKING:  # pragma: no cover
    import numpy as np

    from astar.grid import OccupancyGrid

__all__ = ["atomic_write", "grid_from_file", "read_bytes", "read_text"]


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def atomic_write(path: str | os.PathLike, write: Callable[[Path], None]) -> Path:
    """Call ``write(tmp)`` on a temporary file beside ``path``, then move it into place.

    :func:`os.replace` is atomic, so readers see the old file or the new one, never a
    partial one; on any error the temporary file is removed and the old file is kept. The
    new file gets the usual permissions (``0o666`` less the umask), not the temporary
    file's private ``0o600``. The data is not fsynced: durability after a power loss is not
    promised.

    Parameters
    ----------
    path : path-like
        Destination; its folder must exist.
    write : callable
        Writes the content to the given temporary path (keeps ``path``'s suffix, so
        format-sniffing writers such as ``savefig`` behave).

    Returns
    -------
    Path
        ``path``.
    """
    target = Path(path)
    fd, tmp = tempfile.mkstemp(
        prefix=f".{target.name}.", suffix=target.suffix or ".tmp", dir=target.parent
    )
    os.close(fd)
    try:
        write(Path(tmp))
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, target)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return target


def read_bytes(p: Path) -> bytes:
    """Return the content of ``p``; an :class:`OSError` becomes a :class:`MapFormatError`."""
    try:
        return p.read_bytes()
    except OSError as exc:
        raise MapFormatError(f"{p}: cannot read file: {exc}") from None


def read_text(p: Path) -> str:
    """Return the content of ``p`` decoded as UTF-8 (:class:`MapFormatError` when it is not)."""
    data = read_bytes(p)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise MapFormatError(f"{p}: not UTF-8/ASCII text ({exc})") from None


def grid_from_file(
    p: Path, occupied: np.ndarray, resolution: float, origin: tuple[float, float]
) -> OccupancyGrid:
    """``OccupancyGrid(occupied, resolution, origin)`` read from file ``p``.

    A value the grid refuses (:class:`InvalidInputError`) becomes a :class:`MapFormatError`
    naming the file.
    """
    from astar.grid import OccupancyGrid

    try:
        return OccupancyGrid(occupied, resolution, origin)
    except InvalidInputError as exc:
        raise MapFormatError(f"{p}: {exc}") from None
