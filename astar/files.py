"""Atomic file writes, shared by the map writers, the trajectory exporters and the CLI."""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable
from pathlib import Path


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
