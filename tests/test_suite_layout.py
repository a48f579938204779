"""Tests of the suite itself, for astar and trajopt alike: each test file names its package.

Tests may use a package's internals, but each test file says which package it tests (issue
43, section 5): its module docstring starts with ``Tests of`` and names, in its first
paragraph, the package of its folder (``tests/astar/`` -> ``astar``,
``tests/trajopt/timing/`` -> ``trajopt.timing``, ``tests/trajopt/`` -> ``trajopt``); the
files directly in ``tests/`` name ``astar`` or ``trajopt``.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

TESTS = Path(__file__).resolve().parent
FILES = sorted(TESTS.rglob("test_*.py"))


def _package(path: Path) -> str | None:
    """The dotted package that the folder of ``path`` mirrors; None directly in tests/."""
    parts = path.relative_to(TESTS).parent.parts
    return ".".join(parts) if parts else None


def _docstring(path: Path) -> str:
    """The module docstring: parsed from the file's head only (the text up to its end)."""
    text = path.read_text()
    end = text.find('"""', text.find('"""') + 3)
    head = text[: end + 3] if text.lstrip().startswith('"""') and end > 0 else ""
    return (ast.get_docstring(ast.parse(head)) if head else None) or ""


def test_there_are_test_files_in_every_package_folder():
    assert {_package(p) for p in FILES} >= {"astar", "trajopt", "trajopt.timing", None}


def test_every_test_file_names_the_package_it_tests():
    wrong = []
    for path in FILES:
        doc = _docstring(path)
        first = doc.split("\n\n")[0]
        pkg = _package(path)
        names = [pkg] if pkg is not None else ["astar", "trajopt"]
        named = any(re.search(rf"(?<![\w.]){re.escape(n)}(?![\w])", first) for n in names)
        if not first.startswith("Tests of ") or not named:
            wrong.append(f"{path.relative_to(TESTS)}: {first[:70]!r} (want 'Tests of' + {names})")
    assert not wrong, "\n".join(wrong)
