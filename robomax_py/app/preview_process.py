"""The preview's own server (`preview_server`) as a child process: started with the page's
overlay, its ZMQ URL read from what it prints, and stopped with its pipes closed."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from robomax_py.errors import PreviewError


def _start_server(host: str, port: int | None, overlay: str | None = None) -> tuple[Any, str]:
    """Start `preview_server` and return the process and its ZMQ URL.

    `overlay` goes to the server as the first line of its stdin (JSON), read before it listens; no
    size limit, unlike an argument, and nothing on disk. The server stays in this process group (a Ctrl-C or a signal to the group ends it too) and
    stops by itself when its stdin, a pipe kept open by this process, closes (this process ended,
    however). Its stderr goes to the null device: it says what went wrong on stdout.
    """
    import os
    import subprocess
    import sys

    import robomax_py

    package_root = str(Path(robomax_py.__file__).resolve().parents[1])
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([package_root, *[p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p]])
    args = [sys.executable, "-u", "-m", "robomax_py.app.preview_server", "--host", host]
    if port is not None:
        args += ["--port", str(port)]
    if overlay is not None:
        args.append("--overlay-stdin")
    proc = subprocess.Popen(args, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, env=env)
    if overlay is not None:
        assert proc.stdin is not None
        try:
            proc.stdin.write(json.dumps(overlay).encode("ascii") + b"\n")
            proc.stdin.flush()
        except BrokenPipeError:
            pass                                  # it exited already; said below, from its stdout
    found: dict[str, str] = {}
    assert proc.stdout is not None
    for raw in proc.stdout:                       # ends at end of file: the server exited
        key, _, value = raw.decode("utf-8", "replace").strip().partition("=")
        found[key] = value
        if key in ("web_url", "error"):
            break
    proc.stdout.close()
    if "web_url" not in found or "zmq_url" not in found:
        _stop(proc)
        raise PreviewError(found.get("error") or f"the preview server exited (code {proc.returncode}) before listening")
    return proc, found["zmq_url"]


def _close(vis: Any) -> None:
    proc = getattr(vis.window, "server_proc", None)
    if proc is not None:
        _stop(proc)


def _stop(proc: Any) -> None:
    proc.kill()
    proc.wait()
    for pipe in (proc.stdin, proc.stdout):
        if pipe is not None and not pipe.closed:
            pipe.close()
