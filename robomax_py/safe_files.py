"""The one guarded reading path for every file robomax_py reads, below the YAML layer.

Before a file is opened its path is checked: no NUL byte, not too long, no symlink loop, a regular
file (not a folder, device or pipe, which could block a read forever), not larger than the limit
of its kind. Text must be UTF-8. Each refusal is one located error naming the file, the key and
the limit. `io.yaml_files` adds the bounded YAML loader on top.

Since every read passes here, `recording_reads` can list the files a step read: `robomax batch`
ships exactly those with each cell to a machine that shares no folder with the one that started it.
"""

from __future__ import annotations

import os
import stat
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from robomax_py.errors import _LocatedError

# The located error to raise: an error class, or a factory naming the file that named the path.
ErrorFactory = Callable[[Any, Any, str], _LocatedError]

MB = 1024 * 1024


@dataclass(frozen=True, slots=True)
class FileLimits:
    """Largest files read, by kind (bytes), the YAML bounds, and the bounds of a xacro expansion."""

    cell: int = 10 * MB
    description: int = 1 * MB          # robot.yaml, tool.yaml, SRDF
    urdf: int = 20 * MB
    mesh: int = 200 * MB
    program: int = 50 * MB
    # Lines of one program file: the readers parse about 5,000 statements a CPU second, so this
    # bounds a read to about ten seconds; plans write about 15 lines a spot (a 240-spot cell about
    # 4,000 lines).
    program_lines: int = 50_000
    path_chars: int = 4096             # PATH_MAX on Linux
    name_chars: int = 255              # NAME_MAX: one path component
    yaml_nodes: int = 1_000_000        # after expanding aliases
    yaml_depth: int = 64               # nested collections
    int_digits: int = 30               # no quantity in a cell needs more
    urdf_links: int = 1000             # links (and joints) of one URDF; arms have fewer than 50
    # One xacro expansion (`import-urdf`, run in a process of its own): CPU seconds and address
    # space. The ROS-Industrial support packages expand in under 0.2 s and 60 MB.
    xacro_cpu_s: float = 30.0
    xacro_memory: int = 1024 * MB


LIMITS = FileLimits()

# The files passed by `checked_file` while `recording_reads` is active (per thread and task).
_RECORDING: ContextVar[list[str] | None] = ContextVar("robomax_recorded_reads", default=None)


@contextmanager
def recording_reads() -> Iterator[list[str]]:
    """A list that collects, in reading order, every file `checked_file` lets through while the
    block runs: absolute, normalised paths as named (not resolved through symbolic links, so that
    the same relative paths lead to them from a copy of the files), repeats included."""
    found: list[str] = []
    token = _RECORDING.set(found)
    try:
        yield found
    finally:
        _RECORDING.reset(token)


def named_by(error: Callable[[Any, Any, str], _LocatedError], file: Path, key: str) -> ErrorFactory:
    """An ErrorFactory that names `file` and `key` (the file and key that name the path) rather than
    the path itself, which may not be printable."""

    def make(_path: object, _key: object, problem: str) -> _LocatedError:
        return error(file, key, problem)

    return make


def checked_file(path: Path, limit: int, error: ErrorFactory, what: str, key: str | None = None) -> Path:
    """`path` made safe to open: the located `error` (file, key, problem) for a NUL byte, a path or
    name too long, a symlink loop, something that is not a regular file, or more than `limit` bytes."""
    text = os.fspath(path)
    shown = printable(text)
    what = printable(what)
    if "\x00" in text:
        raise error(shown, key, f"{what}: the path contains a NUL byte")
    if len(text) > LIMITS.path_chars:
        raise error(shown, key, f"{what}: the path has {len(text)} characters (at most {LIMITS.path_chars})")
    for part in Path(text).parts:
        if len(part.encode("utf-8", "surrogateescape")) > LIMITS.name_chars:
            raise error(shown, key, f"{what}: a name in the path is longer than {LIMITS.name_chars} bytes")
    try:
        resolved = Path(text).resolve(strict=True)
    except RuntimeError:
        raise error(shown, key, f"{what}: the path is a symlink loop") from None
    except FileNotFoundError:
        raise error(shown, key, f"{what} not found") from None
    except OSError as exc:
        raise error(shown, key, f"{what}: cannot resolve the path ({exc.strerror or exc})") from None
    try:
        st = resolved.stat()
    except OSError as exc:
        raise error(shown, key, f"{what}: cannot read ({exc.strerror or exc})") from None
    if stat.S_ISDIR(st.st_mode):
        raise error(shown, key, f"{what}: is a folder, not a file")
    if not stat.S_ISREG(st.st_mode):
        raise error(shown, key, f"{what}: not a regular file (a device, pipe or socket)")
    if st.st_size > limit:
        raise error(shown, key, f"{what}: {st.st_size / MB:.1f} MB is more than the {limit / MB:.0f} MB allowed")
    recording = _RECORDING.get()
    if recording is not None:
        recording.append(os.path.abspath(text))
    return resolved


def read_text(path: Path, limit: int, error: ErrorFactory, what: str, key: str | None = None,
              fallback: str = "", max_lines: int | None = None) -> str:
    """The UTF-8 text of a checked file (`checked_file`); a BOM is dropped. fallback: the encoding
    to read a file in that is not UTF-8 (KRL files are Windows-1252 when written on the controller).
    max_lines: refuse a file of more lines (before any parsing)."""
    safe = checked_file(path, limit, error, what, key)
    try:
        data = safe.read_bytes()
    except OSError as exc:
        raise error(path, key, f"cannot read {what}: {exc.strerror or exc}") from None
    if len(data) > limit:      # grew since the check
        raise error(path, key, f"{what}: more than the {limit / MB:.0f} MB allowed")
    if max_lines is not None and (lines := data.count(b"\n") + 1) > max_lines:
        raise error(path, key, f"{what}: {lines} lines is more than the {max_lines} allowed")
    try:
        return data.decode("utf-8").removeprefix("\ufeff")
    except UnicodeDecodeError as exc:
        if fallback:
            try:
                return data.decode(fallback)
            except UnicodeDecodeError:
                pass
        line = data[:exc.start].count(b"\n") + 1
        encodings = "UTF-8" + (f" or {fallback}" if fallback else "")
        raise error(path, f"line {line}", f"{what} is not {encodings} text (byte 0x{data[exc.start]:02x} at offset "
                                          f"{exc.start})") from None


def printable(text: str, limit: int = 200) -> str:
    """Text fit for a one-line message: control characters escaped, long text shortened."""
    out = "".join(ch if ch.isprintable() else ascii(ch)[1:-1] for ch in text)
    return out if len(out) <= limit else out[: limit // 2] + " ... " + out[-limit // 4:]
