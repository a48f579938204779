"""Exceptions raised by :mod:`astar`.

Every error raised on bad input derives from :class:`InvalidInputError`, which is a
:class:`ValueError`, so ``except ValueError`` keeps working for callers that do not care
about the finer types.
"""

from __future__ import annotations

__all__ = ["AstarError", "InvalidInputError", "MapFormatError", "NoPathError"]


class AstarError(Exception):
    """Base class of every exception raised by :mod:`astar`."""


class InvalidInputError(AstarError, ValueError):
    """An argument breaks a documented rule (the message names the field, value and rule)."""


class MapFormatError(InvalidInputError):
    """A map or scenario file is malformed (the message names the file, field and rule)."""


class NoPathError(AstarError):
    """No path connects the start and the goal on the given grid."""
