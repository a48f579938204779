"""Shared fixtures: where the real maps live (``TRAJOPT_DATA``, default ``../shared/data``)."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

_REPO = Path(__file__).resolve().parents[1]


def data_dir() -> Path:
    """The shared map folder: ``$TRAJOPT_DATA`` or ``<repo>/../shared/data``."""
    env = os.environ.get("TRAJOPT_DATA")
    return Path(env) if env else _REPO.parent / "shared" / "data"


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """The shared data folder; skips the test with a reason when it is absent."""
    d = data_dir()
    if not (d / "movingai").is_dir() or not (d / "ros").is_dir():
        pytest.skip(f"shared map data not found at {d} (set TRAJOPT_DATA)")
    return d
