"""The collector around a command's heavy imports: paused and then frozen only in a process that
is the command's own (`cli.main`), untouched in a caller's process (tests, scripts)."""

from __future__ import annotations

import gc

import pytest

from robomax_py.app.commands import base


def test_a_caller_s_process_keeps_its_collector(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(base._Process, "own", False)
    before = (gc.isenabled(), gc.get_threshold(), gc.get_freeze_count())
    with base._heavy_imports():
        assert gc.isenabled() == before[0]
    assert (gc.isenabled(), gc.get_threshold(), gc.get_freeze_count()) == before


def test_the_command_s_own_process_collects_nothing_during_imports_then_freezes_them(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(base._Process, "own", True)
    threshold, enabled = gc.get_threshold(), gc.isenabled()
    gc.enable()
    try:
        with base._heavy_imports():
            assert not gc.isenabled()
            made = [[k] for k in range(100)]            # objects the imports would make
        assert gc.isenabled()
        assert gc.get_freeze_count() >= len(made)
        assert gc.get_threshold()[0] == base.YOUNG_COLLECTION_THRESHOLD
        assert gc.get_threshold()[1:] == threshold[1:]
    finally:
        gc.unfreeze()
        gc.set_threshold(*threshold)
        if not enabled:
            gc.disable()
