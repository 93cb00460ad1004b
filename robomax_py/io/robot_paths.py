"""Where robot and tool folders and `package://` meshes are found: the robot library path
(`--robots` folders, then `ROBOMAX_ROBOTS`, then the shipped library) and ROS package folders."""

from __future__ import annotations

import functools
import os
import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from robomax_py.errors import RobotModelError
from robomax_py.safe_files import LIMITS, checked_file, named_by, read_text

# Robot library folders searched before the shipped one, separated like PATH.
ROBOTS_ENV = "ROBOMAX_ROBOTS"
# Folders a `package://NAME/...` mesh is looked for below (ROS convention).
ROS_PACKAGE_PATH_ENV = "ROS_PACKAGE_PATH"
# How deep below the robot folder's parents and ROS_PACKAGE_PATH entries a folder named NAME is
# looked for: deep enough for a checkout of a ROS-Industrial repository next to the robot folder.
PACKAGE_SEARCH_DEPTH = 3
PACKAGE_SEARCH_PARENTS = 3


# ------------------------------------------------------------------------------ the library path


def shipped_robots_dir() -> Path:
    """The robot library shipped inside the package (package data)."""
    return Path(__file__).resolve().parent.parent / "robots"


def robot_library() -> tuple[Path, ...]:
    """Folders searched for robots/tools by name, first match wins: ROBOMAX_ROBOTS entries, then shipped.

    The CLI's `--robots DIR` options are put in front of ROBOMAX_ROBOTS, so batch workers inherit them.
    """
    extra = [Path(p).expanduser() for p in os.environ.get(ROBOTS_ENV, "").split(os.pathsep) if p.strip()]
    out: list[Path] = []
    for d in [*extra, shipped_robots_dir()]:
        if d not in out:
            out.append(d)
    return tuple(out)


def resolve_robot_file(ref: str, relative_to: Path) -> Path:
    """A cell's `robot.model`: a folder name in the library path, or a path to a robot.yaml."""
    return _resolve(ref, relative_to, (), "robot.yaml")


def resolve_tool_file(ref: str, relative_to: Path) -> Path:
    """A cell's `tool`: a folder name in the library path's `tools/`, or a path to a tool.yaml."""
    return _resolve(ref, relative_to, ("tools",), "tool.yaml")


def _resolve(ref: str, relative_to: Path, sub: tuple[str, ...], filename: str) -> Path:
    looks_like_path = "/" in ref or "\\" in ref or ref.endswith((".yaml", ".yml"))
    if not looks_like_path:
        candidates = [Path(d, *sub, ref, filename) for d in robot_library()]
        return next((c for c in candidates if _is(c, Path.is_file)), candidates[-1])
    path = relative_to.parent / ref
    return path / filename if _is(path, Path.is_dir) else path


def _is(path: Path, test: Any) -> bool:
    """`path.is_file()` / `is_dir()` that says False for paths the OS refuses (too long, a loop);
    the guard then names the problem when the file is opened."""
    try:
        return bool(test(path))
    except (OSError, ValueError, RuntimeError):
        return False


# ------------------------------------------------------------------------------ package:// meshes


def package_share_dirs() -> list[Path]:
    """`share` folders of installed packages, for URDFs naming meshes as package://<pkg>/...

    example-robot-data installs under <site-packages>/cmeel.prefix/share; we locate it through the
    installed distribution's file list rather than guessing a path. The list is read once per
    process (`_share_dirs`): it holds thousands of files, and reading it took 40 ms, on every
    robot loaded from a URDF with package:// meshes."""
    return list(_share_dirs())


@functools.cache
def _share_dirs() -> tuple[Path, ...]:
    """The folders `package_share_dirs` gives, found once: what is installed does not change while
    the process runs."""
    from importlib import metadata

    dirs: list[Path] = []
    try:
        files = metadata.files("example-robot-data") or []
    except metadata.PackageNotFoundError:
        files = []
    for f in files:
        parts = Path(str(f)).parts
        if "share" in parts and "example-robot-data" in parts:
            idx = parts.index("share")
            located = Path(str(f.locate())).resolve()
            share = located.parents[len(parts) - idx - 2]
            dirs.append(share)
            break
    return tuple(dirs)


def package_dirs_for(name: str, near: Path) -> list[Path]:
    """Folders P such that P/name is the ROS package `name`, best first.

    Searched: the folder `near` and its parents (one of them named `name`, or holding a folder of
    that name), folders named `name` up to PACKAGE_SEARCH_DEPTH levels below `near`'s first
    PACKAGE_SEARCH_PARENTS parents, then each ROS_PACKAGE_PATH entry (and below it), then the
    installed packages' share folders.
    """
    found: list[Path] = []

    def add(p: Path) -> None:
        if (p / name).is_dir() and p not in found:
            found.append(p)

    near = near.resolve()
    ancestors = [near, *near.parents]
    for a in ancestors:
        if a.name == name:
            add(a.parent)
        add(a)
    for a in ancestors[:PACKAGE_SEARCH_PARENTS + 1]:
        for hit in _folders_named(a, name, PACKAGE_SEARCH_DEPTH):
            add(hit.parent)
    for entry in os.environ.get(ROS_PACKAGE_PATH_ENV, "").split(os.pathsep):
        if not entry.strip():
            continue
        root = Path(entry).expanduser()
        if root.name == name:
            add(root.parent)
        add(root)
        for hit in _folders_named(root, name, PACKAGE_SEARCH_DEPTH):
            add(hit.parent)
    for share in package_share_dirs():
        add(share)
    return found


def _folders_named(root: Path, name: str, depth: int) -> list[Path]:
    """Folders called `name` at most `depth` levels below root (sorted, hidden folders skipped)."""
    out: list[Path] = []
    level = [root]
    for _ in range(depth):
        nxt: list[Path] = []
        for d in level:
            try:
                children = sorted(c for c in d.iterdir() if c.is_dir() and not c.name.startswith("."))
            except OSError:
                continue
            for c in children:
                (out if c.name == name else nxt).append(c)
        level = nxt
    return out


def resolve_package_uri(uri: str, file: Path, key: str, near: Path | None = None) -> Path:
    """package://<pkg>/<rest> -> an existing file, searched as `package_dirs_for` says."""
    rest = uri[len("package://"):]
    name, _, tail = rest.partition("/")
    for d in package_dirs_for(name, near if near is not None else file.parent):
        candidate = d / name / tail
        if candidate.exists():
            return candidate
    raise RobotModelError(file, key, f"{uri} not found (searched near {file.parent}, ROS_PACKAGE_PATH and installed packages)")


_PACKAGE_URI = re.compile(r"package://([^/\"']+)/")


def urdf_package_names(urdf_text: str) -> list[str]:
    """The ROS package names a URDF's mesh filenames use, in first-use order."""
    names: list[str] = []
    for m in _PACKAGE_URI.finditer(urdf_text):
        if m.group(1) not in names:
            names.append(m.group(1))
    return names


def urdf_package_dirs(urdf: Path, file: Path, text: str | None = None) -> tuple[Path, ...]:
    """Package folders for the `package://NAME/...` meshes a URDF names (searched near the URDF).

    Every mesh file the URDF names that exists is checked by the guard here (a regular file within
    the mesh size limit), so Pinocchio never opens a device, a pipe or a symlink loop. `text` is the
    URDF's text when the caller has read it already."""
    if text is None:
        text = read_text(urdf, LIMITS.urdf, named_by(RobotModelError, file, "urdf"), f"URDF {urdf}")
    dirs: list[Path] = []
    for name in urdf_package_names(text):
        for d in package_dirs_for(name, urdf.parent):
            if d not in dirs:
                dirs.append(d)
    for uri in _MESH_FILENAME.findall(text):
        for candidate in mesh_candidates(uri, urdf, dirs):
            if os.path.lexists(candidate):
                checked_file(candidate, LIMITS.mesh, named_by(RobotModelError, urdf, f"mesh {uri}"), f"mesh {candidate}")
                break
    return tuple(dirs)


_MESH_FILENAME = re.compile(r"<mesh[^>]*\sfilename\s*=\s*[\"']([^\"']*)[\"']")


def mesh_candidates(uri: str, urdf: Path, dirs: Sequence[Path]) -> list[Path]:
    """Where a URDF's mesh `filename` may be: package:// under each package folder, file://, or
    relative to the URDF."""
    if "\x00" in uri:
        return [Path(uri)]
    if uri.startswith("package://"):
        name, _, rest = uri[len("package://"):].partition("/")
        return [d / name / rest for d in dirs]
    if uri.startswith("file://"):
        return [Path(uri[len("file://"):])]
    return [urdf.parent / uri]
