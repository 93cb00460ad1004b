"""A plan's files committed as one set: the old set or the new one, never a mix.

A plan's files (`commit_set`: the trajectory file, each dialect's files, the chart, and
`<name>.manifest.json`) are switched in as a whole: they are written into a fresh hidden folder
beside them, `.<name>.robomax-set-<plan>-<random>/`, and each `DIR/<file>` is a relative symbolic
link `.<name>.robomax-set/<file>` through one pointer, `DIR/.<name>.robomax-set`, a symbolic link
to the current set's folder. Renaming a new pointer over the old one (one `rename`) is the commit:
a reader, or a run killed at any instant (SIGKILL included), sees the old set or the new one,
never a mix. A file of the old set that the new one lacks (a dialect not written this time) then
names nothing and is removed; a regular file of the set's names that robomax did not write as
part of a set (an older robomax's, or one a user put there) is replaced when the new set has that
name and otherwise left alone (`robomax plan` names it). Files every plan of the folder
writes alike (`shared`: FANUC's `SPOT_WELD.ls`) are not the cell's: they are plain files, each
replaced atomically before the switch, and listed in the manifest apart from the set's own files
(`shared`), outside its sums, since any later plan of the folder may replace them.

Where the folder cannot hold symbolic links (a FAT-formatted stick), the files are replaced one by
one, the manifest last, and then the old set's files the new one lacks are removed: a kill can
leave a mix, which the manifest's sha256 sums expose (`io.plan_set_check.check_set`, which
`robomax verify` uses).

Everything is done under the folder's write lock (`io.atomic.folder_lock`), so two plans writing
one folder at once end with one plan's complete set. The next writer of a folder removes what a
killed writer left: temporary files, unfinished set folders and links that name nothing.
"""

from __future__ import annotations

import errno
import hashlib
import json
import os
import secrets
import shutil
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from robomax_py.io.atomic import (
    TMP_SUFFIX,
    _umask,
    folder_lock,
    signals_held,
    write_atomic_bytes,
)

SET_POINTER = ".robomax-set"            # DIR/.<name>.robomax-set -> the current set's folder
MANIFEST_SUFFIX = ".manifest.json"
MANIFEST_FORMAT = "robomax.manifest/1"
# The file systems that refuse symbolic links say so with one of these.
_NO_LINKS = (errno.EPERM, errno.EOPNOTSUPP, errno.ENOSYS, errno.EINVAL)


@dataclass(frozen=True, slots=True)
class CommittedSet:
    """What `commit_set` did.

    paths : the set's files in `DIR` as given (the manifest not among them).
    manifest : `DIR/<name>.manifest.json`.
    plan : the set's id, the sha256 of its manifest's file list and cell digest.
    removed : names of the previous set's files that this set lacks; removed from `DIR`.
    unlisted : files every plan writes alike (FANUC's `SPOT_WELD.ls`) that the previous set
        listed, this one does not, and no other set of the folder lists: left in `DIR` (the
        integrator may have put the gun's routine there), but no plan's any more.
    linked : False where the folder holds no symbolic links (files replaced one by one).
    """

    paths: tuple[Path, ...]
    manifest: Path
    plan: str
    removed: tuple[str, ...] = ()
    unlisted: tuple[str, ...] = ()
    linked: bool = True


def manifest_text(name: str, files: Mapping[str, bytes], cell_sha256: str,
                  shared: Collection[str] = ()) -> tuple[str, str]:
    """The manifest of a set (its text) and the set's id. Deterministic: the same files of the same
    cell give the same bytes. `files` lists the set's own files; `shared` those of `files` every
    plan of the folder writes alike, listed apart: any later plan of the folder may replace them
    (FANUC's `SPOT_WELD.ls` with another `--stamp` date), so they are not part of the set's sums."""
    def entries(names: list[str]) -> list[dict[str, str]]:
        return [{"name": n, "sha256": hashlib.sha256(files[n]).hexdigest()} for n in names]

    own = entries([n for n in files if n not in shared])
    alike = entries([n for n in files if n in shared])
    plan = hashlib.sha256(json.dumps({"cell_sha256": cell_sha256, "files": own, "shared": alike}, sort_keys=True,
                                     separators=(",", ":")).encode("utf-8")).hexdigest()
    doc = {"format": MANIFEST_FORMAT, "name": name, "plan": plan, "cell_sha256": cell_sha256, "files": own,
           "shared": alike}
    return json.dumps(doc, indent=1) + "\n", plan


def commit_set(out_dir: Path, name: str, files: Mapping[str, str | bytes], cell_sha256: str = "",
               shared: Collection[str] = ()) -> CommittedSet:
    """Write a plan's files (file name -> text or bytes) into `out_dir` as one set with its
    manifest, switched in whole (see the module docstring); what was done.

    `name` is the set's name (the cell's, or `<cell>_baseline`): its pointer and manifest are named
    after it, its files may be named otherwise (FANUC's `<NAME>.ls`). Files named in `shared`
    (those every plan of a folder writes alike, `export.SHARED_FILES`: FANUC's `SPOT_WELD.ls`) are
    written as plain files beside the set.
    """
    data = {n: (v.encode("utf-8") if isinstance(v, str) else bytes(v)) for n, v in files.items()}
    for n in data:
        if "/" in n or n in ("", ".", "..") or n.startswith("."):
            raise ValueError(f"not a file name: {n!r}")
    manifest = f"{name}{MANIFEST_SUFFIX}"
    text, plan = manifest_text(name, data, cell_sha256, shared)
    if manifest in data:
        raise ValueError(f"{manifest} is the set's manifest, not one of its files")
    own = {n: b for n, b in data.items() if n not in shared}
    own[manifest] = text.encode("utf-8")
    alike = {n: b for n, b in data.items() if n in shared}
    paths = tuple(out_dir / n for n in data)
    with folder_lock(out_dir):
        before = _listed(out_dir / manifest)
        for n, b in alike.items():
            write_atomic_bytes(out_dir / n, b)
        try:
            removed = _switch(out_dir, name, own, plan)
            linked = True
        except _NoLinks:
            _clean_leftovers(out_dir, name, None)
            gone = sorted(n for n in before if n not in own and n not in shared)
            removed = _replace_one_by_one(out_dir, own, manifest, gone)
            linked = False
        others = {n for m in out_dir.glob(f"*{MANIFEST_SUFFIX}") for n in _listed(m)}
        unlisted = tuple(sorted(n for n in before if n in shared and n not in data and n not in others
                                and (out_dir / n).exists()))
    return CommittedSet(paths, out_dir / manifest, plan, removed, unlisted, linked)


def _listed(manifest: Path) -> set[str]:
    """The file names a manifest lists, its own and shared ones (none when it cannot be read)."""
    try:
        doc = json.loads(manifest.read_text(encoding="utf-8"))
        return {str(f["name"]) for key in ("files", "shared") for f in doc.get(key, [])}
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return set()


class _NoLinks(Exception):
    """The folder's file system refuses symbolic links."""


def _pointer(name: str) -> str:
    return f".{name}{SET_POINTER}"


def _link_target(name: str, file_name: str) -> str:
    return f"{_pointer(name)}/{file_name}"


def _switch(out_dir: Path, name: str, own: dict[str, bytes], plan: str) -> tuple[str, ...]:
    """Stage the set's own files in a fresh folder and switch the pointer to it (the commit); the
    names of the previous set's files removed."""
    pointer = out_dir / _pointer(name)
    current = _current_folder(out_dir, name)
    _clean_leftovers(out_dir, name, current)
    plain = any((out_dir / n).is_file() and not (out_dir / n).is_symlink() for n in own)
    if current is not None and not plain and _holds(out_dir / current, own):
        folder = None                             # the same bytes are current: nothing to switch
    else:
        folder = _stage(out_dir, name, plan, own)
    try:
        with signals_held():
            if folder is not None and current is None:
                # First set in this folder: an empty one becomes current, so that links made
                # before the switch read as absent files, as the folder had them.
                current = _new_folder(out_dir, name, "none")
                _fsync_dir(out_dir / current)
                _replace_link(pointer, current)
            _adopt_plain_files(out_dir, name, own, current)
            for n in own:
                link = out_dir / n
                if not (link.is_symlink() and os.readlink(link) == _link_target(name, n)):
                    _replace_link(link, _link_target(name, n))
            if folder is not None:
                _replace_link(pointer, folder)   # the commit
                _fsync_dir(out_dir)
                folder = None
            removed = []
            for e in _entries(out_dir):
                if e.is_symlink() and os.readlink(e) == _link_target(name, e.name) and e.name not in own:
                    e.unlink(missing_ok=True)
                    removed.append(e.name)
            _clean_leftovers(out_dir, name, _current_folder(out_dir, name))
    except BaseException:
        if folder is not None:                   # not switched in: the old set stays whole
            shutil.rmtree(out_dir / folder, ignore_errors=True)
        raise
    return tuple(sorted(removed))


def _stage(out_dir: Path, name: str, plan: str, own: Mapping[str, bytes]) -> str:
    """A fresh hidden folder holding the set's own files, written and synced; its name."""
    folder = _new_folder(out_dir, name, plan[:12])
    try:
        for n, b in own.items():
            with open(out_dir / folder / n, "xb") as fh:
                fh.write(b)
                fh.flush()
                os.fsync(fh.fileno())
            os.chmod(out_dir / folder / n, 0o666 & ~_umask())
        _fsync_dir(out_dir / folder)
    except BaseException:
        shutil.rmtree(out_dir / folder, ignore_errors=True)
        raise
    return folder


def _new_folder(out_dir: Path, name: str, tag: str) -> str:
    while True:
        folder = f"{_pointer(name)}-{tag}-{secrets.token_hex(4)}"
        try:
            os.mkdir(out_dir / folder)
            return folder
        except FileExistsError:
            continue


def _current_folder(out_dir: Path, name: str) -> str | None:
    """The folder the set's pointer names, when it is one of the set's folders and exists."""
    pointer = out_dir / _pointer(name)
    if not pointer.is_symlink():
        return None
    target = os.readlink(pointer)
    if "/" in target or not target.startswith(f"{_pointer(name)}-") or not (out_dir / target).is_dir():
        return None
    return target


def _clean_leftovers(out_dir: Path, name: str, current: str | None) -> None:
    """Remove set folders of `name` other than the current one (a killed writer's, or the previous
    set's) and links of the set that name nothing."""
    prefix = f"{_pointer(name)}-"
    for e in _entries(out_dir):
        if e.name.startswith(prefix) and e.name != current and e.is_dir() and not e.is_symlink():
            shutil.rmtree(e, ignore_errors=True)
        elif e.is_symlink() and os.readlink(e) == _link_target(name, e.name) and not e.exists():
            e.unlink(missing_ok=True)


def _adopt_plain_files(out_dir: Path, name: str, own: Mapping[str, bytes], current: str | None) -> None:
    """A regular file in the place of one of the set's links (an older robomax's set): linked into
    the current set's folder first, then replaced by the link, so it reads the same until the switch."""
    for n in own:
        path = out_dir / n
        if path.is_symlink() or not path.is_file() or current is None:
            continue
        kept = out_dir / current / n
        kept.unlink(missing_ok=True)
        try:
            os.link(path, kept)
        except OSError:
            shutil.copy2(path, kept)
        _replace_link(path, _link_target(name, n))


def _holds(folder: Path, own: Mapping[str, bytes]) -> bool:
    """Whether a set folder holds exactly these files with these bytes."""
    try:
        names = {p.name for p in folder.iterdir()}
        return names == set(own) and all((folder / n).read_bytes() == b for n, b in own.items())
    except OSError:
        return False


def _replace_link(path: Path, target: str) -> None:
    """Make `path` a symbolic link to `target`, atomically (a link beside it renamed over it)."""
    tmp = path.with_name(f".{path.name}.{secrets.token_hex(4)}{TMP_SUFFIX}")
    try:
        os.symlink(target, tmp)
    except OSError as exc:
        if exc.errno in _NO_LINKS:
            raise _NoLinks() from None
        raise
    try:
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def _replace_one_by_one(out_dir: Path, own: Mapping[str, bytes], manifest: str,
                        gone: Sequence[str]) -> tuple[str, ...]:
    """Without symbolic links: each file replaced atomically, the manifest last, then the previous
    set's own files that this one lacks (`gone`) removed; the names removed."""
    for n, b in own.items():
        if n != manifest:
            write_atomic_bytes(out_dir / n, b)
    write_atomic_bytes(out_dir / manifest, own[manifest])
    removed = []
    for n in gone:
        path = out_dir / n
        if path.is_file() and not path.is_symlink():
            path.unlink(missing_ok=True)
            removed.append(n)
    return tuple(removed)


def _entries(folder: Path) -> list[Path]:
    try:
        return sorted(folder.iterdir())
    except OSError:
        return []


def _fsync_dir(folder: Path) -> None:
    fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def write_programs(out_dir: Path, texts: Mapping[str, str], shared: Collection[str] = ()) -> list[Path]:
    """Write rendered program files (file name -> text) into `out_dir` as one set (`commit_set`,
    named after the first `.json` file, the trajectory file); the paths written."""
    first_json = next((n for n in texts if n.endswith(".json")), None)
    name = first_json[: -len(".json")] if first_json else Path(next(iter(texts))).stem
    return list(commit_set(out_dir, name, texts, shared=shared).paths)
