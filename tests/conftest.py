"""Shared fixtures and settings.

* Where the real maps live (``TRAJOPT_DATA``, default ``../shared/data``).
* Hypothesis profiles: ``deterministic`` (the default, and what CI runs: every run draws the
  same examples, so the README's test command cannot pass one run and fail the next) and
  ``explore`` (fresh random examples each run, for looking for new failures:
  ``HYPOTHESIS_PROFILE=explore python -m pytest``). Cases an exploration finds are pinned
  in their test with ``@example``.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from hypothesis import settings

settings.register_profile("deterministic", derandomize=True, database=None, print_blob=True)
settings.register_profile("explore", derandomize=False, print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "deterministic"))

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
