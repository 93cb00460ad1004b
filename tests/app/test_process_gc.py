"""The collector around a command's heavy imports: paused and then frozen only in a process that
is the command's own (`cli.main`), untouched in a caller's process (tests, scripts)."""

from __future__ import annotations

import gc
import subprocess
import sys
from pathlib import Path

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


# A command run after OMPL made objects that only a collection frees (a cycle), as a plan's last-resort
# detour or a replan leaves them: the exit must not freeze them, or OMPL's bindings (nanobind) print
# each of its types and functions as leaked.
_OMPL_THEN_COMMAND = """
import sys
from ompl import base as ob
space = ob.RealVectorStateSpace(2)
si = ob.SpaceInformation(space)
cycle = [si]
cycle.append(cycle)
del cycle, si, space
sys.argv = ["robomax", "--version"]
from robomax_py.app.cli import main
main()
"""


def test_a_command_after_ompl_ends_without_leak_reports() -> None:
    pytest.importorskip("ompl")
    repo = Path(__file__).resolve().parents[2]
    run = subprocess.run([sys.executable, "-c", _OMPL_THEN_COMMAND], cwd=repo, capture_output=True, text=True,
                         check=False, timeout=120)
    assert run.returncode == 0, run.stderr
    assert "robomax_py" in run.stdout
    assert "leaked" not in run.stderr, run.stderr[:500]
