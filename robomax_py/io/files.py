"""Atomic output: a file appears whole or not at all."""

from __future__ import annotations

import os
import tempfile
from collections.abc import Mapping
from pathlib import Path


def write_atomic(path: Path, text: str) -> None:
    """Write text (UTF-8, newlines as given) atomically; see `write_atomic_bytes`."""
    write_atomic_bytes(path, text.encode("utf-8"))


def write_programs(out_dir: Path, texts: Mapping[str, str]) -> list[Path]:
    """Write rendered program files (file name -> text) into `out_dir`, each atomically; the paths written."""
    written: list[Path] = []
    for name, text in texts.items():
        path = out_dir / name
        write_atomic(path, text)
        written.append(path)
    return written


def write_atomic_bytes(path: Path, data: bytes) -> None:
    """Write to a temporary file in the same folder, then rename over the target."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        # mkstemp creates 0600; give the file the permissions a plain open() would have.
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
