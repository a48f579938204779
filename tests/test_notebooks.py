"""Execute every notebook in ``notebooks/`` with nbclient (issue 6, section 4).

Each notebook runs in a fresh ``python3`` kernel of the interpreter running the tests (a
kernel spec written for ``sys.executable`` into a temporary Jupyter path, so a ``python3``
spec installed for another Python cannot be picked up), with ``notebooks/`` as its working
directory, and must finish without an error cell within :data:`TIMEOUT_S` per cell and
:data:`NOTEBOOK_LIMIT_S` in all. The
notebooks find the repository themselves (``sys.path`` fallback to the parent folder) and
the shared maps through ``TRAJOPT_DATA`` (default ``../../shared/data``); a notebook whose
data is missing shows a message cell instead of failing.

Skipped, with the reason, when nbclient, nbformat or ipykernel is not installed
(``pip install nbclient nbformat ipykernel``, all in the ``dev`` extra).
"""

from __future__ import annotations

import os
import time
from pathlib import Path

import pytest

NOTEBOOK_DIR = Path(__file__).resolve().parent.parent / "notebooks"
NOTEBOOKS = sorted(NOTEBOOK_DIR.glob("*.ipynb"))
#: Per-cell execution limit (s).
TIMEOUT_S = 600
#: Whole-notebook limit (s): each takes about a minute on an idle 2-core machine; the margin
#: is for loaded CI runners and a cold numba cache.
NOTEBOOK_LIMIT_S = 900
#: Kernel start-up limit (s): generous, a loaded CI machine can be slow to import IPython.
STARTUP_TIMEOUT_S = 180


def _require_jupyter() -> None:
    for mod in ("nbformat", "nbclient", "ipykernel", "jupyter_client"):
        pytest.importorskip(mod, reason=f"{mod} is not installed (pip install {mod})")


def _use_this_interpreter(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Make ``python3`` resolve to a kernel spec of this interpreter (``sys.executable``)."""
    from ipykernel.kernelspec import install

    install(kernel_name="python3", prefix=str(tmp_path))
    jupyter_path = str(tmp_path / "share" / "jupyter")
    old = os.environ.get("JUPYTER_PATH", "")
    monkeypatch.setenv("JUPYTER_PATH", os.pathsep.join(p for p in (jupyter_path, old) if p))


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
def test_notebook_executes(path: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    _require_jupyter()
    import sys

    import nbformat
    from jupyter_client.kernelspec import KernelSpecManager
    from nbclient import NotebookClient

    _use_this_interpreter(tmp_path, monkeypatch)
    spec = KernelSpecManager().get_kernel_spec("python3")
    assert spec.argv[0] == sys.executable, (
        f"python3 kernel runs {spec.argv[0]}, not {sys.executable}"
    )

    nb = nbformat.read(path, as_version=4)
    root = str(NOTEBOOK_DIR.parent)
    env_path = os.environ.get("PYTHONPATH", "")
    if root not in env_path.split(os.pathsep):  # the kernel must import this checkout
        monkeypatch.setenv("PYTHONPATH", os.pathsep.join(p for p in (root, env_path) if p))
    client = NotebookClient(
        nb,
        timeout=TIMEOUT_S,
        startup_timeout=STARTUP_TIMEOUT_S,
        kernel_name="python3",
        resources={"metadata": {"path": str(NOTEBOOK_DIR)}},
    )
    t0 = time.perf_counter()
    client.execute()  # raises CellExecutionError naming the failing cell
    elapsed = time.perf_counter() - t0
    errors = [
        o
        for c in nb.cells
        if c.cell_type == "code"
        for o in c.get("outputs", [])
        if o.get("output_type") == "error"
    ]
    assert not errors, f"{path.name}: error outputs {[e.get('ename') for e in errors]}"
    assert elapsed < NOTEBOOK_LIMIT_S, (
        f"{path.name} took {elapsed:.0f} s (limit {NOTEBOOK_LIMIT_S} s)"
    )
