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


@pytest.fixture
def quiet_timer(monkeypatch: pytest.MonkeyPatch) -> list[tuple[str, object]]:
    """The handler's calls into `signal` recorded instead of made: the test process keeps its own
    handlers and timers. The received signal starts unset."""
    calls: list[tuple[str, object]] = []
    monkeypatch.setattr(cli._Received, "signum", None)
    monkeypatch.setattr(cli._Received, "deferred", False)
    monkeypatch.setattr(signal, "signal", lambda signum, handler: calls.append(("signal", signum)))
    monkeypatch.setattr(signal, "setitimer", lambda which, seconds: calls.append(("setitimer", seconds)))
    monkeypatch.setattr(signal, "raise_signal", lambda signum: calls.append(("raise_signal", signum)))
    return calls


def test_an_interrupt_during_an_import_lets_the_import_finish_and_comes_again_after(
        tmp_path: Any, monkeypatch: pytest.MonkeyPatch, quiet_timer: list[tuple[str, object]]) -> None:
    """The handler runs where the signal finds the interpreter; here inside a module's own code
    while it is imported. Raised there, the exception would cut the import (an extension module's
    initialisation meeting it ends the process: see the test below)."""
    (tmp_path / "interrupted_mid_import.py").write_text(
        "import signal, sys\n"
        "from robomax_py.app import cli\n"
        "cli._on_signal(signal.SIGINT, sys._getframe())\n"
        "FINISHED = True\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delitem(sys.modules, "interrupted_mid_import", raising=False)
    import interrupted_mid_import

    assert interrupted_mid_import.FINISHED
    assert cli._Received.signum == signal.SIGINT and cli._Received.deferred
    assert quiet_timer == [("signal", signal.SIGALRM), ("setitimer", cli.IMPORT_RETRY_S)]
    cli._deliver_deferred(signal.SIGALRM, sys._getframe())            # the timer: the signal again ...
    assert quiet_timer[-1] == ("raise_signal", signal.SIGINT)
    with pytest.raises(KeyboardInterrupt):                             # ... which, outside the import, ends the run
        cli._on_signal(signal.SIGINT, sys._getframe())
    assert not cli._Received.deferred
    cli._deliver_deferred(signal.SIGALRM, sys._getframe())            # a late timer: not delivered twice
    assert quiet_timer[-1] == ("raise_signal", signal.SIGINT) and len(quiet_timer) == 3


def test_a_deferred_interrupt_honoured_at_a_stage_is_not_delivered_again(quiet_timer: list[tuple[str, object]]) -> None:
    from robomax_py.app.commands.base import _honour_signals

    cli._Received.signum, cli._Received.deferred = signal.SIGTERM, True
    with pytest.raises(SystemExit) as ended:
        _honour_signals()
    assert ended.value.code == 128 + signal.SIGTERM
    cli._deliver_deferred(signal.SIGALRM, sys._getframe())
    assert quiet_timer == []


# SIGINT raised (for real, through robomax's handler) at the first call into Python's `enum` while
# cascadio imports: its extension module (nanobind) builds its enums with `enum` as it initialises,
# and trimesh imports it when it first reads a mesh. Raised there, the interrupt ended the process
# with an uncaught C++ exception (SIGABRT), or SIGSEGV a few calls on.
_INTERRUPT_IN_EXTENSION_INIT = """
import enum, signal, sys
from robomax_py.app import cli

signal.signal(signal.SIGINT, cli._on_signal)
raised = []

def hook(frame, event, arg):
    if event == "call" and "cascadio" in sys.modules and frame.f_code.co_filename == enum.__file__:
        sys.setprofile(None)
        raised.append(frame.f_code.co_name)
        signal.raise_signal(signal.SIGINT)

sys.setprofile(hook)
try:
    import trimesh
    sys.setprofile(None)
    if not raised:
        sys.exit("cascadio imported without a call into enum: nothing was tried")
    signal.pause()                               # the interrupt, delivered again once the import is done
except KeyboardInterrupt:
    # Where it ended: the import whole, trimesh holding cascadio's STEP loader (not the exception
    # it caught in its place, as it would from an interrupt raised inside the import).
    loader = sys.modules["trimesh"].exchange.cascade._cascade_loaders["step"]
    print("interrupted", "cascadio._core" in sys.modules, type(loader).__name__)
    sys.exit(130)
"""


def test_an_interrupt_while_an_extension_module_initialises_ends_the_run_after_its_import() -> None:
    import importlib.util
    import subprocess

    if importlib.util.find_spec("cascadio") is None:
        pytest.skip("cascadio (the cad extra) is not installed")
    done = subprocess.run([sys.executable, "-c", _INTERRUPT_IN_EXTENSION_INIT], capture_output=True, text=True,
                          check=False, timeout=300)
    assert done.returncode == 130, (done.returncode, done.stderr[-3000:])
    assert done.stdout.split() == ["interrupted", "True", "function"], done.stdout
