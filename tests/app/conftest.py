"""`serve_preview`: `robomax preview` running as a command in its own process group."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
URL_PREFIX = "meshcat preview at "


@dataclass(frozen=True, slots=True)
class Served:
    """A running `robomax preview`: the process (leader of its own group), the URL it printed,
    the web port, and the file its stderr goes to."""

    proc: subprocess.Popen[bytes]
    url: str
    port: int
    stderr_file: Path

    def stderr(self) -> str:
        return self.stderr_file.read_text(encoding="utf-8", errors="replace")

    def stop(self) -> tuple[int, str]:
        """Ctrl-C to the whole group (the command and its server), as a terminal sends it;
        returns the exit code and what the command printed after the URL."""
        os.killpg(self.proc.pid, signal.SIGINT)
        rest, _ = self.proc.communicate()
        return self.proc.returncode, rest.decode("utf-8", "replace")


def _default_interrupt() -> None:
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _free_port(host: str = "127.0.0.1") -> int:
    with socket.socket(socket.AF_INET6 if ":" in host else socket.AF_INET) as probe:
        probe.bind((host, 0))
        return int(probe.getsockname()[1])


@pytest.fixture(scope="session")
def free_port() -> Callable[..., int]:
    """free_port(host="127.0.0.1"): a TCP port nothing listens on at `host` now."""
    return _free_port


def _end_group(proc: subprocess.Popen[bytes]) -> None:
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass                                   # the group has ended already
    proc.wait()
    if proc.stdout is not None:
        proc.stdout.close()


@pytest.fixture(scope="module")
def serve_preview(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Callable[..., Served]]:
    """Start `python -m robomax_py preview CELL ARGS...` in a new process group and wait for the
    URL it prints; every group started is killed by its id when the test module ends (or when a
    test stops it)."""
    started: list[subprocess.Popen[bytes]] = []
    tmp_path = tmp_path_factory.mktemp("serve_preview")

    def start(cell: Path, *args: str) -> Served:
        env = dict(os.environ, PYTHONUNBUFFERED="1", COLUMNS="200")
        env["PYTHONPATH"] = os.pathsep.join([str(REPO), *[p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p]])
        err = tmp_path / f"preview_{len(started)}.err"
        with err.open("wb") as err_out:
            # Ctrl-C as a terminal delivers it: a shell's background job (and so a test run started
            # with `&`) inherits SIGINT ignored, and Python then never raises KeyboardInterrupt.
            proc = subprocess.Popen([sys.executable, "-m", "robomax_py", "preview", str(cell), *args],
                                    stdout=subprocess.PIPE, stderr=err_out, env=env, start_new_session=True,
                                    preexec_fn=_default_interrupt)  # noqa: PLW1509 - one thread here
        started.append(proc)
        assert proc.stdout is not None
        for raw in proc.stdout:                # ends when the command exits without a URL
            line = raw.decode("utf-8", "replace")
            if line.startswith(URL_PREFIX):
                url = line[len(URL_PREFIX):].split()[0]
                return Served(proc, url, int(url.rsplit(":", 1)[1].split("/")[0]), err)
        proc.wait()
        pytest.fail(f"preview exited {proc.returncode} without a URL: {err.read_text()}")

    try:
        yield start
    finally:
        for proc in started:
            _end_group(proc)
