"""Tests of the shared atomic file write (:mod:`astar.files`)."""

from __future__ import annotations

import os
import stat

import pytest

from astar.files import atomic_write


def test_new_file_gets_umask_permissions_not_private_ones(tmp_path):
    old = os.umask(0o022)
    try:
        out = atomic_write(tmp_path / "a.csv", lambda p: p.write_text("x\n"))
    finally:
        os.umask(old)
    assert out.read_text() == "x\n"
    assert stat.S_IMODE(out.stat().st_mode) == 0o644
    assert [p.name for p in tmp_path.iterdir()] == ["a.csv"]  # no temporary left behind


def test_failed_write_keeps_the_old_file_and_leaves_no_temporary(tmp_path):
    target = tmp_path / "b.json"
    target.write_text("old")

    def broken(p):
        p.write_text("partial")
        raise RuntimeError("disk full")

    with pytest.raises(RuntimeError, match="disk full"):
        atomic_write(target, broken)
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["b.json"]
