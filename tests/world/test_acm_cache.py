"""The self-pair analysis kept in the cache folder: an answer read back from memory or from disk is
the one computed afresh, an entry made for other options or a changed tool is not reused, and a
damaged entry is computed again."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from robomax_py.cache_files import CACHE_ENV
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.world import acm_cache
from robomax_py.world.acm import CollisionOptions
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene

REPO = Path(__file__).resolve().parents[2]
FEW = CollisionOptions(acm_samples=300)     # a quicker analysis; the cache logic is the same


def _acm(cell_name: str, options: CollisionOptions = FEW):  # type: ignore[no-untyped-def]
    cell = load_cell(REPO / "cells" / f"{cell_name}.yaml")
    robot = load_cell_robot(cell)
    return CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance, options).acm


def test_memory_disk_and_fresh_answers_agree(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(CACHE_ENV, str(tmp_path))
    monkeypatch.setattr(acm_cache, "_MEMORY", {})
    computed = _acm("frame")
    entries = sorted((tmp_path / "acm").glob("*.npz"))
    assert len(entries) == 1
    assert _acm("frame") == computed                       # from memory
    monkeypatch.setattr(acm_cache, "_MEMORY", {})
    assert _acm("frame") == computed                       # from the file
    monkeypatch.setattr(acm_cache, "_key", lambda *a: None)
    fresh = _acm("frame")                                  # no cache at all
    assert fresh == computed
    assert any(d.reason == "never close" for d in fresh.disabled)     # the analysis had work to do


def test_other_options_and_another_arm_make_their_own_entries(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(CACHE_ENV, str(tmp_path))
    monkeypatch.setattr(acm_cache, "_MEMORY", {})
    a = _acm("frame")
    b = _acm("frame", replace(FEW, acm_margin=0.05))
    c = _acm("ur10_tray")
    assert len(list((tmp_path / "acm").glob("*.npz"))) == 3
    never = {frozenset((d.piece_a, d.piece_b)) for d in a.disabled if d.reason == "never close"}
    assert {frozenset((d.piece_a, d.piece_b)) for d in b.disabled if d.reason == "never close"} <= never
    assert c != a


def test_a_damaged_entry_is_computed_again(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(CACHE_ENV, str(tmp_path))
    monkeypatch.setattr(acm_cache, "_MEMORY", {})
    computed = _acm("frame")
    (entry,) = (tmp_path / "acm").glob("*.npz")
    entry.write_bytes(b"not an npz")
    monkeypatch.setattr(acm_cache, "_MEMORY", {})
    assert _acm("frame") == computed
    assert entry.read_bytes() != b"not an npz"
