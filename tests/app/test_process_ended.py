"""robomax_py.app.process_ended: a process counts as ended only where the system says so."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from robomax_py.app.process_ended import process_ended


def test_a_running_process_has_not_ended_and_a_reaped_one_has() -> None:
    assert not process_ended(os.getpid())
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()                                        # reaped: its number names no process now
    assert process_ended(child.pid)


def test_no_process_number_is_not_ended() -> None:
    assert not process_ended(2 ** 80)                  # OverflowError: not a process, nothing to remove


def test_where_the_system_cannot_tell_nothing_is_asked(monkeypatch: pytest.MonkeyPatch) -> None:
    """Not POSIX (Windows, where os.kill(pid, 0) would signal the process): no call, not ended."""
    def kill(pid: int, sig: int) -> None:
        raise AssertionError("os.kill must not be called")
    monkeypatch.setattr(os, "name", "nt")
    monkeypatch.setattr(os, "kill", kill)
    assert not process_ended(12345)
