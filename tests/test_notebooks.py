"""Execute every notebook in ``notebooks/`` with nbclient (issue 6, section 4).

Each notebook runs in a fresh ``python3`` kernel with ``notebooks/`` as its working
directory and must finish without an error cell within :data:`TIMEOUT_S` per cell. The
notebooks find the repository themselves (``sys.path`` fallback to the parent folder) and
the shared maps through ``TRAJOPT_DATA`` (default ``../../shared/data``); a notebook whose
data is missing shows a message cell instead of failing.

Skipped, with the reason, when nbclient, nbformat or ipykernel (or the ``python3`` kernel
spec) is not installed: ``pip install nbclient nbformat ipykernel``, then
``python -m ipykernel install --user`` if the kernel is still missing.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

NOTEBOOK_DIR = Path(__file__).resolve().parent.parent / "notebooks"
NOTEBOOKS = sorted(NOTEBOOK_DIR.glob("*.ipynb"))
#: Per-cell execution limit (s); a whole notebook normally takes well under a minute.
TIMEOUT_S = 300
#: Kernel start-up limit (s): generous, a loaded CI machine can be slow to import IPython.
STARTUP_TIMEOUT_S = 180


def _require_jupyter() -> None:
    for mod in ("nbformat", "nbclient", "ipykernel"):
        pytest.importorskip(mod, reason=f"{mod} is not installed (pip install {mod})")
    from jupyter_client.kernelspec import KernelSpecManager, NoSuchKernel

    try:
        KernelSpecManager().get_kernel_spec("python3")
    except NoSuchKernel:
        pytest.skip("no 'python3' Jupyter kernel (run: python -m ipykernel install --user)")


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


# Not yet in the default run: notebooks 01 and 02 have not been shown to finish within the
# CI budget (issue 6 stays open until they do); run them with `pytest -m slow`.
@pytest.mark.slow
@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_notebook_executes(path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    _require_jupyter()
    import nbformat
    from nbclient import NotebookClient

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
    client.execute()  # raises CellExecutionError naming the failing cell
    errors = [
        o
        for c in nb.cells
        if c.cell_type == "code"
        for o in c.get("outputs", [])
        if o.get("output_type") == "error"
    ]
    assert not errors, f"{path.name}: error outputs {[e.get('ename') for e in errors]}"
