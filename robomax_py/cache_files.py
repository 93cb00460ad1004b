"""The cache folder robomax_py keeps built data in (learned C-space models, IK tables), and the
one way files go into it: written whole to a temporary file and renamed into place, so a
concurrent reader never sees half a file. An unwritable cache only costs building again."""

from __future__ import annotations

import io
import os
import tempfile
from pathlib import Path

import numpy as np

CACHE_ENV = "ROBOMAX_CACHE"


def cache_folder(kind: str) -> Path:
    """`$ROBOMAX_CACHE/kind`, else `$XDG_CACHE_HOME/robomax_py/kind`, else `~/.cache/robomax_py/kind`
    (not created here)."""
    root = os.environ.get(CACHE_ENV) or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache"), "robomax_py")
    return Path(root) / kind


def store_arrays(path: Path, arrays: dict[str, np.ndarray], compressed: bool = False) -> bool:
    """An .npz of `arrays` at `path` (deflated when `compressed`), written atomically; False when
    the folder cannot be written."""
    buf = io.BytesIO()
    save = np.savez_compressed if compressed else np.savez
    save(buf, **arrays)  # type: ignore[arg-type]  # numpy's stub types **kwds as its allow_pickle flag
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=".", suffix=".tmp", dir=path.parent)
        try:
            with os.fdopen(fd, "wb") as f:
                f.write(buf.getvalue())
                f.flush()
                os.fsync(f.fileno())
            os.replace(tmp, path)
        finally:
            if os.path.exists(tmp):
                os.unlink(tmp)
    except OSError:
        return False
    return True
