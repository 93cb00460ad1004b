"""Atomic output: a file appears whole or not at all, and a set of programs is never mixed.

Each file is written to a temporary file in the same folder and renamed over the target. A set of
program files (the `.json` and `.srcl` of one plan) is written holding an exclusive lock on the
folder itself (flock on its directory descriptor: no lock file is left), so two plans writing the same folder at once end with one plan's
complete set, never one file of each. A writer killed mid-write (SIGKILL) can leave a temporary
file behind; the next writer of that folder removes it under the lock (no live writer holds one).
"""

from __future__ import annotations

import fcntl
import os
import tempfile
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path

TMP_SUFFIX = ".robomax-tmp"


def write_atomic(path: Path, text: str) -> None:
    """Write text (UTF-8, newlines as given) atomically; see `write_atomic_bytes`."""
    write_atomic_bytes(path, text.encode("utf-8"))


@contextmanager
def folder_lock(folder: Path) -> Iterator[None]:
    """Hold the folder's write lock (blocking), removing temporary files a killed writer left."""
    folder.mkdir(parents=True, exist_ok=True)
    fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        for stale in folder.glob(f".*{TMP_SUFFIX}"):
            stale.unlink(missing_ok=True)
        yield
    finally:
        fcntl.flock(fd, fcntl.LOCK_UN)
        os.close(fd)


def write_programs(out_dir: Path, texts: Mapping[str, str]) -> list[Path]:
    """Write rendered program files (file name -> text) into `out_dir` as one set under the folder
    lock, each atomically; the paths written."""
    written: list[Path] = []
    with folder_lock(out_dir):
        for name, text in texts.items():
            path = out_dir / name
            write_atomic(path, text)
            written.append(path)
    return written


def write_atomic_bytes(path: Path, data: bytes) -> None:
    """Write to a temporary file in the same folder, then rename over the target."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=TMP_SUFFIX, dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        # mkstemp creates 0600; give the file the permissions a plain open() would have.
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
