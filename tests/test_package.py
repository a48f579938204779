"""Tests of the packages astar and trajopt as wholes: package-level checks: lazy exports resolve, import stays light."""

from __future__ import annotations

import ast
import functools
import importlib
import inspect
import subprocess
import sys
from pathlib import Path

import pytest

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


def _type_checking_imports(module) -> dict[str, str]:
    """Name -> module of every ``from M import name`` under ``if TYPE_CHECKING:``."""
    tree = ast.parse(inspect.getsource(module))
    out: dict[str, str] = {}
    for block in tree.body:
        if isinstance(block, ast.If) and ast.unparse(block.test) == "TYPE_CHECKING":
            for node in ast.walk(block):
                if isinstance(node, ast.ImportFrom):
                    out.update({a.asname or a.name: node.module for a in node.names})
    return out


@pytest.mark.parametrize("package", ["astar", "trajopt"])
def test_type_checking_block_imports_every_lazy_export(package):
    """Static type checkers see the lazy exports (PEP 562) only through the TYPE_CHECKING
    imports: each must name the module ``__getattr__`` loads it from, and the block must
    hold nothing that is not exported."""
    mod = importlib.import_module(package)
    seen = _type_checking_imports(mod)
    want = dict(mod._EXPORTS)
    subs = getattr(mod, "_SUBMODULES", ())
    # a public module is imported from the package that holds it (trajopt.analysis for
    # trajopt.scenes) when the lazy map names where it lives, else from the package itself
    want.update(
        {
            name: subs[name].rpartition(".")[0] if isinstance(subs, dict) else package
            for name in subs
        }
    )
    wrong = {
        name: (where, seen.get(name)) for name, where in want.items() if seen.get(name) != where
    }
    assert not wrong, f"{package}: TYPE_CHECKING imports missing or from another module: {wrong}"
    assert set(seen) == set(mod.__all__) == set(want)
    for name, where in seen.items():  # and each names the very object __getattr__ returns
        value = getattr(mod, name)
        assert getattr(importlib.import_module(where), name) is value, name


def test_import_is_light():
    code = "import sys, trajopt, astar; print(' '.join(sorted(m for m in ('casadi', 'piqp', 'ruckig', 'numba', 'matplotlib', 'scipy') if m in sys.modules)))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""


#: trajopt's layers from the bottom (docs/architecture.md): a module may import its own
#: layer's and lower layers' modules, never a higher layer's (TYPE_CHECKING imports aside)
LAYERS = [
    {"errors", "_validation", "_kernel_cache"},
    {"geometry"},
    {"robot"},
    {"motion"},
    {"corridor"},
    {"smoother"},
    {"timing"},
    {"planning"},
    {"replan"},
    {"_planner"},
    {"analysis"},
    {"_warm_up"},
    {"cli"},
]


def _layer(module: str) -> int:
    top = module.split(".")[1] if module.count(".") else "__init__"
    for i, names in enumerate(LAYERS):
        if top in names:
            return i
    return len(LAYERS)  # the package face, which loads lazily


def _imports(path: Path, prefixes: tuple[str, ...] = ("trajopt.",)) -> list[tuple[str, int]]:
    """``(imported module, line)`` of every import of ``prefixes`` outside TYPE_CHECKING."""
    return [(n, line) for n, line in _absolute_imports(path) if n.startswith(prefixes)]


@functools.cache
def _absolute_imports(path: Path) -> tuple[tuple[str, int], ...]:
    """``(imported module, line)`` of every absolute import outside TYPE_CHECKING (each file
    is parsed once per session: two tests read every file)."""
    tree = ast.parse(path.read_text())
    guarded = {
        id(sub)
        for node in ast.walk(tree)
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test)
        for sub in ast.walk(node)
    }
    out = []
    for node in ast.walk(tree):
        if id(node) in guarded:
            continue
        if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names = [node.module]
        elif isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        else:
            continue
        if isinstance(node, ast.ImportFrom):  # "from pkg import module" imports pkg.module
            names += [f"{node.module}.{a.name}" for a in node.names]
        out += [(n, node.lineno) for n in names]
    return tuple(out)


def test_no_import_runs_up_a_layer():
    root = Path(trajopt.__file__).parent
    upward = []
    for path in root.rglob("*.py"):
        rel = path.relative_to(root.parent).with_suffix("")
        here = ".".join(rel.parts).removesuffix(".__init__")
        if here == "trajopt":
            continue
        for target, line in _imports(path):
            if _layer(target) > _layer(here):
                upward.append(f"{rel}.py:{line} imports {target}")
    assert not upward, upward


def test_no_import_circle_between_files():
    """No cycle in the graph of imports between trajopt's and astar's files (function-level
    imports included, TYPE_CHECKING ones aside): a depth-first search for a back edge."""
    root = Path(trajopt.__file__).parent.parent
    files = {
        ".".join(p.relative_to(root).with_suffix("").parts).removesuffix(".__init__"): p
        for pkg in ("trajopt", "astar")
        for p in (root / pkg).rglob("*.py")
    }

    def resolve(name: str) -> str | None:
        while name and name not in files:
            name = name.rpartition(".")[0]
        return name or None

    edges = {}
    for mod, path in files.items():
        targets = set()
        for target, _ in _imports(path, prefixes=("trajopt.", "astar.")):
            t = resolve(target)
            # a package face loads its own modules: not an edge back from them
            if t and t != mod and not (path.name == "__init__.py" and t.startswith(mod + ".")):
                targets.add(t)
        edges[mod] = targets
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(m: str) -> list[str] | None:
        state[m] = 1
        stack.append(m)
        for n in sorted(edges[m]):
            if state.get(n) == 1:
                return stack[stack.index(n) :] + [n]
            if n not in state and (cycle := visit(n)):
                return cycle
        state[m] = 2
        stack.pop()
        return None

    for m in sorted(files):
        if m not in state:
            cycle = visit(m)
            assert cycle is None, " -> ".join(cycle)
