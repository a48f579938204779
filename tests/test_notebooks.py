"""Tests of the notebooks, which use astar and trajopt: execute every notebook in ``notebooks/`` with nbclient (issue 6, section 4).

Each notebook runs in a fresh ``python3`` kernel of the interpreter running the tests, with
``notebooks/`` as its working directory, and must finish without an error cell within
the limits of ``tests/notebook_runner.py`` (``TIMEOUT_S`` per cell, ``NOTEBOOK_LIMIT_S`` in
all). The notebooks find the
repository themselves (``sys.path`` fallback to the parent folder) and the shared maps
through ``TRAJOPT_DATA`` (default ``../../shared/data``); a notebook whose data is missing
shows a message cell instead of failing.

The notebooks execute once per session, one after another in a background thread started
when collection ends, while the other tests run; ``test_notebook_executes`` runs last and
checks each result (``tests/notebook_runner.py`` and ``tests/conftest.py``).

Skipped, with the reason, when nbclient, nbformat or ipykernel is not installed
(``pip install nbclient nbformat ipykernel``, all in the ``dev`` extra).
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from tests.notebook_runner import NOTEBOOK_LIMIT_S, NOTEBOOKS, missing_jupyter, runner


def _require_jupyter() -> None:
    mod = missing_jupyter()
    if mod is not None:
        pytest.skip(f"{mod} is not installed (pip install {mod})")


def test_notebooks_exist() -> None:
    names = {p.name for p in NOTEBOOKS}
    assert {
        "01_paper_reproduction.ipynb",
        "02_compare_plain_fits.ipynb",
        "03_velocity_profiles.ipynb",
    } <= names


def test_notebooks_stored_without_outputs() -> None:
    """Stored notebooks keep no outputs (small files, clean diffs)."""
    nbformat = pytest.importorskip("nbformat", reason="nbformat is not installed")
    for path in NOTEBOOKS:
        nb = nbformat.read(path, as_version=4)
        nbformat.validate(nb)
        dirty = [i for i, c in enumerate(nb.cells) if c.cell_type == "code" and c.get("outputs")]
        assert not dirty, f"{path.name}: code cells {dirty} have stored outputs; clear them"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_notebook_executes(path: Path) -> None:
    _require_jupyter()
    run = runner().result(path)
    assert run.kernel_argv0 == sys.executable, (
        f"python3 kernel runs {run.kernel_argv0}, not {sys.executable}"
    )
    if run.error is not None:  # CellExecutionError names the failing cell
        raise AssertionError(
            f"{path.name} failed: {run.error}\nkernel log (tail):\n{run.kernel_log[-3000:]}"
        ) from run.error
    errors = [
        o
        for c in run.nb.cells
        if c.cell_type == "code"
        for o in c.get("outputs", [])
        if o.get("output_type") == "error"
    ]
    assert not errors, f"{path.name}: error outputs {[e.get('ename') for e in errors]}"
    assert run.seconds < NOTEBOOK_LIMIT_S, (
        f"{path.name} took {run.seconds:.0f} s (limit {NOTEBOOK_LIMIT_S} s)"
    )
