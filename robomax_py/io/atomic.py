"""Atomic output: a file appears whole or not at all.

Each file is written to a temporary file in the same folder, synced, and renamed over the target.
A folder's writers take its lock (`folder_lock`: flock on its directory descriptor, so no lock file
is left), which also removes the temporary files a killed writer left. `signals_held` keeps SIGINT
and SIGTERM from cutting a step short.
"""

from __future__ import annotations

import fcntl
import os
import shutil
import signal
import tempfile
import threading
from collections.abc import Iterator
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
            if stale.is_dir() and not stale.is_symlink():
                shutil.rmtree(stale, ignore_errors=True)
            else:
                stale.unlink(missing_ok=True)
        yield
    finally:
        fcntl.flock(fd, fcntl.LOCK_UN)
        os.close(fd)


def _umask() -> int:
    umask = os.umask(0)
    os.umask(umask)
    return umask


@contextmanager
def signals_held() -> Iterator[None]:
    """SIGINT and SIGTERM held (blocked in the main thread, delivered when the block ends) for a
    step that must not be cut: here the few renames of a switch (milliseconds), so an interrupt
    ends the run after the set is whole and the previous one's files are gone, not between."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    held = {signal.SIGINT, signal.SIGTERM}
    before = signal.pthread_sigmask(signal.SIG_BLOCK, held)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, before)


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
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
