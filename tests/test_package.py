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
    {"errors", "validation", "kernel_cache"},
    {"geometry"},
    {"drive"},
    {"robot"},
    {"motion"},
    {"corridor"},
    {"smoother"},
    {"timing"},
    {"moving"},
    {"planning"},
    {"replan"},
    {"_planner"},
    {"analysis"},
    {"warmup"},
    {"cli"},
]


def _layer(module: str) -> int:
    # a name of the lazy face is its defining module's (importing it loads that module)
    module = trajopt._EXPORTS.get(module.removeprefix("trajopt."), module)
    top = module.split(".")[1] if module.count(".") else "__init__"
    for i, names in enumerate(LAYERS):
        if top in names:
            return i
    return len(LAYERS)  # the package face, which loads lazily


def _imports(path: Path, prefixes: tuple[str, ...] = ("trajopt.",)) -> list[tuple[str, int]]:
    """``(imported module, line)`` of every import of ``prefixes`` outside TYPE_CHECKING."""
    return [(n, line) for n, line in _absolute_imports(path) if n.startswith(prefixes)]


@functools.cache
def _tree(path: Path) -> ast.Module:
    """The parsed file (each file is parsed once per session: several tests read every file)."""
    return ast.parse(path.read_text())


@functools.cache
def _nodes(tree: ast.AST) -> tuple[ast.AST, ...]:
    """Every node of ``tree``, in ``ast.walk`` order (walked once per tree: several tests
    read every node of every file, and walking is most of their time)."""
    return tuple(ast.walk(tree))


@functools.cache
def _absolute_imports(path: Path) -> tuple[tuple[str, int], ...]:
    """``(imported module, line)`` of every absolute import outside TYPE_CHECKING."""
    tree = _tree(path)
    guarded = {
        id(sub)
        for node in _nodes(tree)
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test)
        for sub in ast.walk(node)
    }
    out = []
    for node in _nodes(tree):
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
            if _layer(target) > _layer(here) and not _drive_composes(here, target, path, line):
                upward.append(f"{rel}.py:{line} imports {target}")
    assert not upward, upward


#: The faces a drive's plan and re-plan call (trajopt.drive: the drive is chosen once, at
#: the bottom, and composes the stages above it when a plan is asked for)
DRIVE_CALLS = ("trajopt.planning", "trajopt.replan")


def _drive_composes(here: str, target: str, path: Path, line: int) -> bool:
    """Whether ``here`` is a drive's module importing a stage face inside a function."""
    face = target if target in DRIVE_CALLS else target.rpartition(".")[0]
    if not here.startswith("trajopt.drive.") or face not in DRIVE_CALLS:
        return False
    tree = _tree(path)
    return any(
        isinstance(fn, ast.FunctionDef) and fn.lineno < line <= (fn.end_lineno or fn.lineno)
        for fn in _nodes(tree)
    )


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


#: The result classes of trajopt.motion: stages ask a motion what it is (its flags and
#: methods: single_curve, turning, polyline, own_orientation, playing, plan_at, ...)
#: rather than switch on its class
RESULT_CLASSES = {
    "Trajectory",
    "TrajectoryChain",
    "TurnInPlace",
    "StopAndTurnTrajectory",
    "OmniTrajectory",
}


def _class_switches(tree: ast.AST) -> list[int]:
    """Lines of ``isinstance(x, C)`` / ``type(x) is C`` on a result class that choose a branch.

    A check whose ``if`` only raises (the type check of an argument) is not a switch.
    """
    validation = {
        id(sub)
        for node in _nodes(tree)
        if isinstance(node, ast.If) and all(isinstance(b, ast.Raise) for b in node.body)
        for sub in ast.walk(node.test)
    }

    def names(node: ast.AST) -> set[str]:
        return {n.id for n in ast.walk(node) if isinstance(n, ast.Name)} | {
            n.attr for n in ast.walk(node) if isinstance(n, ast.Attribute)
        }

    out = []
    for node in _nodes(tree):
        if id(node) in validation:
            continue
        if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "isinstance":
            if len(node.args) == 2 and names(node.args[1]) & RESULT_CLASSES:
                out.append(node.lineno)
        elif isinstance(node, ast.Compare) and any(
            isinstance(op, ast.Is | ast.IsNot) for op in node.ops
        ):
            sides = [node.left, *node.comparators]
            typed = any(
                isinstance(s, ast.Call) and getattr(s.func, "id", None) == "type" for s in sides
            )
            if typed and any(names(s) & RESULT_CLASSES for s in sides):
                out.append(node.lineno)
    return out


def test_no_switch_on_result_classes_outside_motion_and_the_drives():
    root = Path(trajopt.__file__).parent
    found = []
    for path in sorted(root.rglob("*.py")):
        rel = path.relative_to(root)
        if rel.parts[0] in ("motion", "drive"):
            continue
        found += [f"{rel}:{line}" for line in _class_switches(_tree(path))]
    assert not found, found


def test_the_switch_check_finds_switches():
    code = (
        "if isinstance(t, TrajectoryChain):\n    x = 1\n"
        "y = 2 if type(t) is Trajectory else 3\n"
        "if not isinstance(t, Trajectory):\n    raise TypeError('t')\n"
    )
    assert _class_switches(ast.parse(code)) == [1, 3]


def _package(module: str) -> str:
    """``trajopt.<pkg>`` for a module of a package of trajopt, ``trajopt`` for a flat one."""
    parts = module.split(".")
    root = Path(trajopt.__file__).parent
    if parts[0] == "trajopt" and len(parts) >= 2 and (root / parts[1]).is_dir():
        return ".".join(parts[:2])
    return parts[0]


def test_packages_use_each_other_through_their_faces():
    """No import reaches into another package's ``_`` modules (function level included)."""
    root = Path(trajopt.__file__).parent
    reach = []
    for path in sorted(root.rglob("*.py")):
        rel = path.relative_to(root.parent).with_suffix("")
        here = ".".join(rel.parts).removesuffix(".__init__")
        for node in _nodes(_tree(path)):
            if not isinstance(node, ast.ImportFrom | ast.Import) or getattr(node, "level", 0):
                continue
            mods = (
                [node.module] if isinstance(node, ast.ImportFrom) else [a.name for a in node.names]
            )
            for mod in mods:
                if not mod or not mod.startswith("trajopt.") or _package(mod) == _package(here):
                    continue
                tail = mod.split(".")[len(_package(mod).split(".")) :]
                if any(part.startswith("_") and not part.startswith("__") for part in tail):
                    reach.append(f"{rel}.py:{node.lineno} imports {mod}")
    assert not reach, reach


def test_no_drive_is_named_outside_the_drives():
    """No comparison of a ``drive`` with a string outside ``trajopt/drive/``."""
    root = Path(trajopt.__file__).parent
    named = []
    for path in sorted(root.rglob("*.py")):
        if path.relative_to(root).parts[0] == "drive":
            continue
        for node in _nodes(_tree(path)):
            if not isinstance(node, ast.Compare):
                continue
            sides = [node.left, *node.comparators]
            drive = any(
                (isinstance(x, ast.Attribute) and x.attr in ("drive", "name"))
                or (isinstance(x, ast.Name) and x.id == "drive")
                for x in sides
            )
            text = any(isinstance(x, ast.Constant) and isinstance(x.value, str) for x in sides)
            if drive and text and "drive" in ast.unparse(node):
                named.append(f"{path.relative_to(root)}:{node.lineno} {ast.unparse(node)}")
    assert not named, named
