"""The CLI's exit on SIGINT and SIGTERM when the signal's exception comes out of compiled code as
another error (numba's dispatcher turns a KeyboardInterrupt raised in its kernel into a
SystemError): the run still ends with 128 + the signal's number, and an error without a signal is
not taken for one."""

from __future__ import annotations

import signal
import sys
from typing import Any

import pytest

from robomax_py.app import cli


@pytest.fixture
def failing_app(monkeypatch: pytest.MonkeyPatch) -> Any:
    def install(signum: int | None) -> None:
        def run(args: list[str]) -> None:
            cli._Received.signum = signum
            raise SystemError("CPUDispatcher(<function _uncleared>) returned a result with an exception set")

        monkeypatch.setattr(cli, "app", run)
        monkeypatch.setattr(cli._Received, "signum", None)
        monkeypatch.setattr(signal, "signal", lambda *a: None)            # the test process keeps its handlers
        monkeypatch.setattr(sys, "unraisablehook", sys.unraisablehook)    # main() wraps it; put back after
        monkeypatch.setattr(cli._Process, "own", False)                  # main() marks the process its own ...
        monkeypatch.setattr(cli.gc, "freeze", lambda: None)                # ... and freezes it at the end
    return install


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_wrapped_by_compiled_code_ends_the_run_as_the_signal(failing_app: Any, signum: int) -> None:
    failing_app(signum)
    with pytest.raises(SystemExit) as ended:
        cli.main()
    assert ended.value.code == 128 + signum


def test_the_same_error_without_a_signal_is_not_an_interrupt(failing_app: Any) -> None:
    failing_app(None)
    with pytest.raises(SystemError):
        cli.main()
