"""The staging folder of `import_urdf` beside the output folder, removed by the next import once
its process has ended, its commit into place by one rename (an atomic exchange when it replaces a
folder), the bounded copy of a checked file into it, and the test that a path lies inside the
folders an import may read from."""

from __future__ import annotations

import hashlib
import os
import re
import shutil
import tempfile
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

from robomax_py.app.process_ended import process_ended
from robomax_py.errors import RobotModelError
from robomax_py.safe_files import MB, printable


def _inside(path: Path, roots: Sequence[Path]) -> bool:
    real = os.path.realpath(path)
    return any(real == str(r) or real.startswith(str(r).rstrip(os.sep) + os.sep) for r in roots)


def _copy(real: Path, dst: Path, limit: int, source: Path, local: str) -> None:
    """Copy a checked file, never more than `limit` bytes (it may have grown since the check), to a
    new file (an existing file or link at `dst` is an error, never written through)."""
    dst.parent.mkdir(parents=True, exist_ok=True)
    copied = 0
    with open(real, "rb") as src, open(dst, "xb") as target:
        while chunk := src.read(1 << 20):
            copied += len(chunk)
            if copied > limit:
                raise RobotModelError(source, local, f"{printable(str(real))} grew beyond {limit / MB:.0f} MB "
                                      "while it was copied")
            target.write(chunk)


# ------------------------------------------------------------------------------ staging

# A staging folder: `.<robot>.robomax-import-<pid>-<8 random characters>` beside the output folder,
# holding STAGING_MARKER (its first line MARKER_TEXT, then `out <folder name>`) and the robot folder
# being built. The next import in that folder removes one whose process has ended (a killed
# import); nothing else is ever removed.
STAGING_MARKER = ".robomax-import"
MARKER_TEXT = "robomax import-urdf staging folder; removed by the next import once its process has ended\n"
_NAME = r"[A-Za-z0-9_][A-Za-z0-9_.-]*"
_STAGING = re.compile(rf"\.(?P<name>{_NAME})\.robomax-import-(?P<pid>[0-9]+)-[a-z0-9_]{{8}}")


@contextmanager
def _staging(parent: Path, name: str) -> Iterator[Path]:
    """A fresh staging folder in `parent` (created if missing); yields the robot folder to build in
    it. Removed afterwards, and on failure also the parent folders this made."""
    made = _make_folders(parent)
    holder: Path | None = None
    try:
        holder = Path(tempfile.mkdtemp(prefix=f".{name}.robomax-import-{os.getpid()}-", dir=parent))
        with open(holder / STAGING_MARKER, "x", encoding="utf-8") as f:
            f.write(f"{MARKER_TEXT}out {name}\n")
        stage = Path(os.path.realpath(holder / name))
        stage.mkdir()
        yield stage
    except BaseException:
        if holder is not None:
            shutil.rmtree(holder, ignore_errors=True)
            holder = None
        for folder in reversed(made):
            try:
                folder.rmdir()
            except OSError:
                break
        raise
    finally:
        if holder is not None:
            shutil.rmtree(holder, ignore_errors=True)


def _make_folders(folder: Path) -> list[Path]:
    """mkdir -p `folder`; the folders created, outermost first."""
    missing = []
    while not os.path.lexists(folder):
        missing.append(folder)
        if folder.parent == folder:
            break
        folder = folder.parent
    made = []
    for f in reversed(missing):
        f.mkdir()
        made.append(f)
    return made


def clean_stale_staging(parent: Path) -> list[Path]:
    """Remove the staging folders in `parent` left by imports that were killed (their process has
    ended, `process_ended`: never on Windows, where that cannot be told): recognised by their name
    (`_STAGING`) and their marker file, or holding nothing but a marker cut short (killed before or
    while the marker was written). A folder a killed replacement had moved aside (`old`) is put back first
    when its place is still empty. Returns the folders removed."""
    removed: list[Path] = []
    try:
        entries = list(os.scandir(parent))
    except OSError:
        return removed
    for entry in entries:
        m = _STAGING.fullmatch(entry.name)
        if m is None or not entry.is_dir(follow_symlinks=False) or not process_ended(int(m["pid"])):
            continue
        folder = Path(entry.path)
        out_name = _marked(folder / STAGING_MARKER)
        if out_name is None:
            if _half_marked(folder, m["name"]):
                try:
                    (folder / STAGING_MARKER).unlink(missing_ok=True)
                    folder.rmdir()       # only ever an empty folder
                    removed.append(folder)
                except OSError:
                    pass
            continue
        old, target = folder / "old", parent / out_name
        if old.is_dir() and not old.is_symlink() and not os.path.lexists(target):
            try:
                os.rename(old, target)
            except OSError:
                continue             # kept, with the folder it holds, for the user to look at
        shutil.rmtree(folder, ignore_errors=True)
        removed.append(folder)
    return removed


def _marked(marker: Path) -> str | None:
    """The output folder name a staging marker states; None when `marker` is not one."""
    try:
        if marker.is_symlink() or not marker.is_file() or marker.stat().st_size > 4096:
            return None
        text = marker.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return None
    if not text.startswith(MARKER_TEXT):
        return None
    m = re.fullmatch(rf"out ({_NAME})\n", text[len(MARKER_TEXT):])
    return None if m is None else m.group(1)


def _half_marked(folder: Path, name: str) -> bool:
    """True when `folder` holds nothing or only a marker cut short by a kill while it was written
    (its text a prefix of the marker `_staging` writes for `name`): the states before the robot
    folder is made, so removing them loses nothing."""
    try:
        entries = os.listdir(folder)
    except OSError:
        return False
    if not entries:
        return True
    marker = folder / STAGING_MARKER
    if entries != [STAGING_MARKER] or marker.is_symlink() or not marker.is_file():
        return False
    try:
        text = marker.read_bytes()[:4097]
    except OSError:
        return False
    return f"{MARKER_TEXT}out {name}\n".encode().startswith(text)


def _commit(stage: Path, out: Path) -> None:
    """Put the staged folder at `out` in one step: a rename, or (replacing a folder) an atomic
    exchange, so that `out` is the old folder or the new one at every instant. Where the system
    cannot exchange, the old folder is moved into the staging folder first (a kill between the two
    renames leaves it there, and the next import puts it back)."""
    if not os.path.lexists(out):
        os.rename(stage, out)
        return
    if out.is_symlink() or not out.is_dir():
        raise RobotModelError(out, None, "exists and is not a folder")
    if _exchange(stage, out):
        return                       # the old folder is now at `stage`, removed with the staging folder
    os.rename(out, stage.parent / "old")
    os.rename(stage, out)


def _exchange(a: Path, b: Path) -> bool:
    """Swap two paths atomically (Linux renameat2 RENAME_EXCHANGE); False where unsupported."""
    import ctypes
    import errno

    try:
        renameat2 = ctypes.CDLL(None, use_errno=True).renameat2
    except (OSError, AttributeError):
        return False
    renameat2.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    at_fdcwd, rename_exchange = -100, 2
    if renameat2(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), rename_exchange) == 0:
        return True
    code = ctypes.get_errno()
    if code in (errno.ENOSYS, errno.EINVAL, errno.EOPNOTSUPP):
        return False
    raise OSError(code, os.strerror(code), str(b))


def _digest(folder: Path) -> str:
    h = hashlib.sha256()
    for path in sorted(p for p in folder.rglob("*") if p.is_file()):
        h.update(str(path.relative_to(folder)).encode() + b"\0" + path.read_bytes() + b"\0")
    return h.hexdigest()
