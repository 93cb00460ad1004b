"""Files a cell includes (docs/frames.md, "Includes"): read, checked on their own, merged.

A cell's `include:` lists files (paths relative to the including file; absolute paths are
refused) whose lists — frames, objects, dynamic objects, seams — are appended to the cell's, in
the order listed, each file's own items before those of the files it includes in turn; a robot and
a tool may come from an included file, once in the whole tree. Each included file is read with the
bounded YAML reader and checked against `IncludeFile` (an unknown key is an error, as in a cell)
before it is merged; an error found later in something it brought names that file and its own key
(`Expansion.locate`). The same file included twice (by resolved path) is one error naming both
places; a file including itself through others is an error listing the chain. Nothing is written.

Paths inside an included file (meshes, a robot or tool given by path) are relative to it; they are
rewritten relative to the including cell when merged.
"""

from __future__ import annotations

import hashlib
import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ValidationError

from robomax_py.errors import CellFileError
from robomax_py.io.robot import resolve_robot_file, resolve_tool_file
from robomax_py.io.yaml_files import load_yaml, validation_error
from robomax_py.safe_files import LIMITS, read_text
from robomax_py.spec import Notice

# The lists an included file's items are appended to, and the keys given once in the whole tree.
MERGED_LISTS = ("frames", "objects", "dynamic", "seams")
GIVEN_ONCE = ("robot", "tool")
# Files one cell may include, all levels together: a station of fixtures, robots and spot lists
# is tens of files; every file is read and checked whole before anything is planned.
MAX_INCLUDED_FILES = 100

_LIST_KEY = re.compile(r"^(frames|objects|dynamic|seams)\[(\d+)\](.*)$", re.DOTALL)
_LIST_REF = re.compile(r"\b(frames|objects|dynamic|seams)\[(\d+)\]")


@dataclass(slots=True)
class Expansion:
    """A cell's data with its included files merged in, and where each merged item came from."""

    data: dict[str, Any]
    cell: Path                                              # the including cell (as named)
    files: list[tuple[Path, str]] = field(default_factory=list)   # included files in reading order, text
    origins: dict[str, list[tuple[Path, int]]] = field(default_factory=dict)   # list key -> (file, index there)
    given_in: dict[str, Path] = field(default_factory=dict)                    # robot/tool -> file giving it

    def digest(self, own: bytes) -> str:
        """SHA-256 naming the exact input: of the cell's own bytes when it includes nothing (as
        before includes existed); else of the cell's bytes and each included file's path (relative
        to the cell's folder) and bytes, each part preceded by its length."""
        if not self.files:
            return hashlib.sha256(own).hexdigest()
        h = hashlib.sha256()
        parts = [own]
        for file, text in self.files:
            parts += [os.path.relpath(file, self.cell.parent).replace(os.sep, "/").encode("utf-8"), text.encode("utf-8")]
        for part in parts:
            h.update(f"{len(part)}\0".encode())
            h.update(part)
        return h.hexdigest()

    def locate(self, file: str | None, key: str | None, problem: str) -> tuple[str | None, str | None, str]:
        """Where a problem found in the merged cell lies: the included file and its own key when
        the key names an item an included file brought; places the problem names are rewritten so."""
        if not self.files or file != str(self.cell):
            return file, key, problem
        where = file
        if key is not None:
            found = _LIST_KEY.match(key)
            if found is not None:
                group, index, rest = found.group(1), int(found.group(2)), found.group(3)
                origin = self.origins.get(group, [])
                if index < len(origin):
                    where, key = str(origin[index][0]), f"{group}[{origin[index][1]}]{rest}"
            else:
                top = key.split(".", 1)[0].split("[", 1)[0]
                if top in self.given_in:
                    where = str(self.given_in[top])

        def place(m: re.Match[str]) -> str:
            origin = self.origins.get(m.group(1), [])
            index = int(m.group(2))
            if index >= len(origin):
                return m.group(0)
            other, there = origin[index]
            ref = f"{m.group(1)}[{there}]"
            return ref if str(other) == where else f"{ref} in {other}"

        return where, key, _LIST_REF.sub(place, problem)

    def relocated_notice(self, notice: Notice) -> Notice:
        file, key, message = self.locate(notice.file, notice.key, notice.message)
        return Notice(file or notice.file, key or notice.key, message)

    def relocated(self, exc: CellFileError) -> CellFileError:
        file, key, problem = self.locate(exc.file, exc.key, exc.problem)
        return exc if (file, key, problem) == (exc.file, exc.key, exc.problem) else CellFileError(file, key, problem)


def expand_includes(data: dict[str, Any], cell: Path, schema: type[BaseModel]) -> Expansion:
    """`data` (a cell file's top-level mapping, as read) with the files it includes merged in;
    `schema` checks each included file (cell.IncludeFile). CellFileError naming the file and key."""
    out = Expansion(data=data, cell=cell)
    if "include" not in data:
        return out
    merged = {k: v for k, v in data.items() if k != "include"}
    for group in MERGED_LISTS:
        own = data.get(group)
        if own is not None and not isinstance(own, list):
            return out              # the schema refuses it, naming the key
        out.origins[group] = [(cell, i) for i in range(len(own or []))]
        merged[group] = list(own or [])
    for key in GIVEN_ONCE:
        if key in data:
            out.given_in[key] = cell
    seen: dict[Path, tuple[Path, str]] = {}
    _include(data, cell, [cell.resolve()], seen, merged, out, schema)
    out.data = {k: v for k, v in merged.items() if not (k in MERGED_LISTS and not v and k not in data)}
    return out


def _include(data: dict[str, Any], file: Path, chain: list[Path], seen: dict[Path, tuple[Path, str]],
             merged: dict[str, Any], out: Expansion, schema: type[BaseModel]) -> None:
    entries = data.get("include", [])
    if not isinstance(entries, list):
        raise CellFileError(file, "include", f"expected a list of file paths, got {type(entries).__name__}")
    for i, entry in enumerate(entries):
        key = f"include[{i}]"
        if not isinstance(entry, str) or not entry.strip():
            raise CellFileError(file, key, "expected the path of a file to include")
        if Path(entry).is_absolute() or re.match(r"^[A-Za-z]:[\\/]", entry):
            raise CellFileError(file, key, f"'{entry}' is an absolute path: give it relative to this file, so the "
                                           "cell's folder can be moved or shared whole")
        target = file.parent / entry
        resolved = target.resolve()
        if resolved in chain:
            names = [str(p) for p in chain[chain.index(resolved):]] + [str(resolved)]
            raise CellFileError(file, key, "include cycle: " + " -> ".join(names) + " (each includes the next)")
        if resolved in seen:
            first, first_key = seen[resolved]
            raise CellFileError(file, key, f"{target} is already included by {first}: {first_key}; a file is "
                                           "included once (its items would be there twice)")
        seen[resolved] = (file, key)
        if len(seen) > MAX_INCLUDED_FILES:
            raise CellFileError(file, key, f"more than the {MAX_INCLUDED_FILES} files a cell may include, all "
                                           "levels together")
        text = read_text(target, LIMITS.cell, CellFileError, "included file")
        included = load_yaml(text, target, CellFileError, "included file")
        if not isinstance(included, dict):
            raise CellFileError(target, None, "expected a mapping of keys at the top level (frames, objects, "
                                              "dynamic, seams, robot, tool, include)")
        try:
            schema.model_validate(included)
        except ValidationError as exc:
            raise validation_error(exc, schema, target, CellFileError) from None
        out.files.append((target, text))
        _merge(included, target, merged, out)
        _include(included, target, [*chain, resolved], seen, merged, out, schema)


def _merge(included: dict[str, Any], file: Path, merged: dict[str, Any], out: Expansion) -> None:
    for group in MERGED_LISTS:
        items = included.get(group) or []
        for i, item in enumerate(items):
            merged.setdefault(group, []).append(_rebased(item, group, file, out.cell))
            out.origins.setdefault(group, []).append((file, i))
    for key in GIVEN_ONCE:
        if key not in included:
            continue
        if key in out.given_in:
            raise CellFileError(file, key, f"also given in {out.given_in[key]}; a cell has one {key}: give it once")
        out.given_in[key] = file
        value = included[key]
        if key == "robot" and isinstance(value.get("model"), str):
            value = {**value, "model": rebased_reference(value["model"], file, out.cell, resolve_robot_file)}
        elif key == "tool":
            value = rebased_reference(value, file, out.cell, resolve_tool_file)
        merged[key] = value


def _rebased(item: Any, group: str, file: Path, cell: Path) -> Any:
    """An object of an included file with its mesh path relative to the cell (as named there)."""
    if group not in ("objects", "dynamic") or not isinstance(item, dict):
        return item
    mesh = item.get("mesh")
    if isinstance(mesh, str):
        return {**item, "mesh": _rebased_path(mesh, file, cell)}
    if isinstance(mesh, dict):          # a mesh given with its options: its file under `file` or `path`
        keys = [k for k in ("file", "path") if isinstance(mesh.get(k), str)]
        return {**item, "mesh": {**mesh, **{k: _rebased_path(mesh[k], file, cell) for k in keys}}}
    return item


def _rebased_path(named: str, file: Path, cell: Path) -> str:
    if Path(named).is_absolute():
        return named
    return Path(os.path.relpath(file.parent / named, cell.parent)).as_posix()


def rebased_reference(ref: str, file: Path, cell: Path, resolve: Any) -> str:
    """A robot or tool reference as named in `file`, named from `cell` instead (an included file's
    in its including cell; a cell's in a copy written elsewhere): kept where it names the same file
    from both (a library name), else the path relative to `cell`'s folder."""
    there = resolve(ref, file)
    return ref if there == resolve(ref, cell) else Path(os.path.relpath(there, cell.parent)).as_posix()
