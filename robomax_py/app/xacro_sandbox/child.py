"""The expansion's own process: its limits set before anything is read, the request read from stdin,
the expansion run and its answer (or what ended it) written as JSON to stdout.
Imports only the standard library and its siblings, relatively (see the package's docstring)."""

from __future__ import annotations

import io
import json
import math
import os
import sys
from collections.abc import Mapping
from typing import Any

from .evaluator import Refused, shown
from .expansion import Expansion

# Warnings xacro prints (kept to report on failure), characters.
MAX_LOG_CHARS = 20_000


def _limit(cpu_s: float, memory_bytes: int, parent: int) -> None:
    """Cap this process before it reads anything: CPU seconds, address space, no files written, no
    processes started, no core dump, and die with the parent (Linux)."""
    import resource

    cpu = max(1, math.ceil(cpu_s))
    resource.setrlimit(resource.RLIMIT_CPU, (cpu, cpu + 1))
    resource.setrlimit(resource.RLIMIT_AS, (memory_bytes, memory_bytes))
    resource.setrlimit(resource.RLIMIT_FSIZE, (0, 0))
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
    resource.setrlimit(resource.RLIMIT_NPROC, (0, 0))
    try:
        import ctypes
        import signal

        PR_SET_PDEATHSIG = 1
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL)
    except (OSError, AttributeError):
        pass
    if os.getppid() != parent:      # the parent died before prctl: nobody waits for the answer
        os._exit(1)


class _Log(io.StringIO):
    """stderr kept in memory, at most MAX_LOG_CHARS (xacro's warnings)."""

    def write(self, s: str) -> int:
        room = MAX_LOG_CHARS - self.tell()
        return super().write(s[:room]) if room > 0 else len(s)


def _cause(exc: BaseException) -> BaseException:
    """What ended the expansion, looking inside xacro's wrapping (XacroException.exc, __cause__,
    __context__): a Refused first, else a MemoryError or RecursionError, else `exc` itself."""
    found: list[BaseException] = []
    todo: list[BaseException | None] = [exc]
    while todo and len(found) < 100:
        e = todo.pop()
        if e is None or any(e is f for f in found):
            continue
        found.append(e)
        todo.extend([getattr(e, "exc", None), e.__cause__, e.__context__])
    for kind in (Refused, MemoryError, RecursionError):
        hit = next((e for e in found if isinstance(e, kind)), None)
        if hit is not None:
            return hit
    return exc


def serve(request: Mapping[str, Any]) -> dict[str, Any]:
    """Expand request["source"]; the answer to print (see the module docstring)."""
    import xacro
    import xacro.substitution_args

    expansion = Expansion(xacro, request["roots"], int(request["max_file_bytes"]), int(request["max_yaml_bytes"]))
    log = _Log()
    sys.stderr = log
    given = {str(k): str(v) for k, v in dict(request.get("args") or {}).items()}
    try:
        defaults, notes = expansion.launch_defaults(request["source"], given)
        text = expansion.run(request["source"], {**defaults, **given})
    except Exception as exc:  # noqa: BLE001 - xacro raises XacroException, KeyError, NameError, ExpatError, ...
        cause = _cause(exc)
        where = expansion.current_file()
        if isinstance(cause, Refused):
            return {"kind": "refused", "file": cause.file, "where": cause.where, "problem": cause.problem}
        if isinstance(cause, MemoryError):
            return {"kind": "memory", "file": where, "where": None, "problem": "memory"}
        if isinstance(cause, RecursionError):
            return {"kind": "xacro", "file": where, "where": None,
                    "problem": "macros or properties nest too deeply (a macro that calls itself?)"}
        message = " ".join(str(exc).split()) or type(exc).__name__
        return {"kind": "xacro", "file": where, "where": None,
                "problem": f"xacro does not expand: {type(exc).__name__}: {shown(message, 400)}"}
    finally:
        sys.stderr = sys.__stderr__
    if len(text) > int(request["max_output_chars"]):
        return {"kind": "size", "file": request["source"], "where": None,
                "problem": f"the expanded URDF has {len(text)} characters, more than the "
                           f"{int(request['max_output_chars']) / 2**20:.0f} MB allowed"}
    return {"urdf": text, "log": log.getvalue(), "notes": notes}


def main() -> int:
    request = json.loads(sys.stdin.buffer.read(1_000_000))
    _limit(float(request["cpu_s"]), int(request["memory_bytes"]), int(request["parent"]))
    try:
        answer = serve(request)
    except MemoryError:
        answer = {"kind": "memory", "file": None, "where": None, "problem": "memory"}
    sys.stdout.write(json.dumps(answer))
    sys.stdout.flush()
    return 0
