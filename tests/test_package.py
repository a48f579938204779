"""Package-level checks: lazy exports resolve, import stays light."""

from __future__ import annotations

import subprocess
import sys

import astar
import trajopt


def test_error_hierarchy():
    assert issubclass(trajopt.InvalidInputError, ValueError)
    assert issubclass(trajopt.InvalidInputError, astar.InvalidInputError)
    assert issubclass(trajopt.NoPathError, astar.NoPathError)
    for name in ("InvalidInputError", "NoPathError", "SmoothingError", "TimingError"):
        assert issubclass(getattr(trajopt, name), trajopt.TrajoptError)
    assert trajopt.SmoothingError("x", {"status": "s"}).stats == {"status": "s"}


def test_all_exports_resolve():
    for mod in (astar, trajopt):
        for name in mod.__all__:
            assert getattr(mod, name) is not None, name


def test_import_is_light():
    code = "import sys, trajopt, astar; print(' '.join(sorted(m for m in ('casadi', 'piqp', 'ruckig', 'numba', 'matplotlib', 'scipy') if m in sys.modules)))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""
