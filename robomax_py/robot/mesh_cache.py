"""What a run needs of a mesh file (its triangle count, convex hull, collision pieces, extents,
distances to points), kept in the cache folder by the file's content, so that a run which finds it
there reads no mesh and imports no trimesh (~0.15 s of CPU with the networkx, scipy.optimize and
cascadio it imports, and ~0.1 s more to read, split and hull a cell's meshes).

An entry is found by a digest of the file's bytes, the caller's parameters (scale, tolerance, the
thresholds its computation uses), the versions of trimesh and cascadio that computed it and
`FORMAT`; any change computes it again. The arrays stored are the ones the computation returned,
so a result read back is the same to the bit. A mesh that cannot be read is never stored: the
computation raises as it did, every time. An unwritable cache only costs computing again.
"""

from __future__ import annotations

import hashlib
import stat
import zipfile
from collections.abc import Callable
from functools import lru_cache
from importlib import metadata
from pathlib import Path

import numpy as np

from robomax_py.cache_files import cache_folder, store_arrays
from robomax_py.safe_files import LIMITS

# Raised when what is stored, or how, changes.
FORMAT = 1


@lru_cache(maxsize=1)
def _library_versions() -> str:
    found = []
    for name in ("trimesh", "cascadio"):
        try:
            found.append(f"{name}={metadata.version(name)}")
        except metadata.PackageNotFoundError:
            found.append(f"{name}=-")
    return ",".join(found)


def mesh_digest(path: Path, params: tuple[object, ...]) -> str | None:
    """sha256 of the mesh file's content digest, `params` (by repr), the libraries' versions and
    `FORMAT`; None when the file is not a regular file within `LIMITS.mesh` or cannot be read (the
    caller's computation then reports it as before)."""
    try:
        info = Path(path).stat()
    except OSError:
        return None
    if not stat.S_ISREG(info.st_mode) or info.st_size > LIMITS.mesh:
        return None
    content = _content_digest(str(Path(path).resolve()), info.st_size, info.st_mtime_ns, info.st_ino)
    if content is None:
        return None
    return hashlib.sha256(f"{content}|{params!r}|{_library_versions()}|{FORMAT}".encode()).hexdigest()


@lru_cache(maxsize=64)
def _content_digest(path: str, size: int, mtime_ns: int, inode: int) -> str | None:
    """sha256 of a file's bytes, once per process while its size, modification time and inode
    are the same (a run asks for several things of one mesh)."""
    try:
        return hashlib.sha256(Path(path).read_bytes()).hexdigest()
    except OSError:
        return None


def kept_arrays(kind: str, path: Path, params: tuple[object, ...],
                compute: Callable[[], dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    """`compute()` for the mesh file at `path`, or the arrays it returned for the same file content
    and `params` in an earlier run (`<cache>/meshes/<kind>-<digest>.npz`)."""
    digest = mesh_digest(path, params)
    if digest is None:
        return compute()
    stored_at = cache_folder("meshes") / f"{kind}-{digest}.npz"
    try:
        with np.load(stored_at, allow_pickle=False) as stored:
            return {name: stored[name] for name in stored.files}
    except (OSError, KeyError, ValueError, EOFError, zipfile.BadZipFile):
        pass                                    # not stored yet, or unreadable: compute again
    arrays = compute()
    store_arrays(stored_at, arrays)
    return arrays
