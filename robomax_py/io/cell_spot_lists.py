"""A cell's CSV spot lists (`spot_lists`, and `robomax import-spots`) as seams: each list read
(`io.spot_list`), its spots placed in the world by their part or a named frame, and what a person
should check kept as the cell's notices."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from robomax_py.errors import CellFileError
from robomax_py.io.cell_file import CellFile, SeamFile
from robomax_py.io.cell_limits import _refuse_counts
from robomax_py.io.cell_objects import _object, _pose
from robomax_py.io.frames import WORLD, FrameNode
from robomax_py.safe_files import LIMITS, checked_file, named_by
from robomax_py.spec import Notice


def spot_list_seams(parsed: CellFile, path: Path, key: str, csv_file: Path, part: str, units: str | None,
                    max_distance: float, seam: Mapping[str, Any] | None = None, frame: str | None = None,
                    tree: tuple[FrameNode, ...] = ()) -> tuple[list[SeamFile], Any]:
    """The seams a CSV spot list gives in the cell `parsed` (read from `path`, its poses in the
    world), and the `io.spot_list.SpotListResult` with what a person should check. `key` names the
    list's place in messages; `seam` holds the seams' settings as a file gives them (ordered,
    tolerance, grid). The list's coordinates are in the part's frame, or in `frame` when given: a
    named frame of the cell's frame `tree`, an object, or the world."""
    from robomax_py.io.spot_list import read_spot_list
    from robomax_py.io.spot_list import spot_list_seams as list_seams

    index = next((i for i, o in enumerate(parsed.objects) if o.name == part), None)
    if index is None:
        known = ", ".join(o.name for o in parsed.objects) or "none"
        raise CellFileError(path, f"{key}.part" if key else "--part", f"no object '{part}' in the cell "
                                                                      f"(objects: {known})")
    objects = [_object(o, path, f"objects[{i}]", []) for i, o in enumerate(parsed.objects)]
    if key:                                # a cell's list: a missing file is the cell's key's mistake
        checked_file(csv_file, LIMITS.cell, named_by(CellFileError, path, f"{key}.file"), f"spot list {csv_file}")
    T_frame = None if frame is None else _frame_world(frame, tree, parsed, path, f"{key}.frame" if key else "--frame")
    spots = read_spot_list(csv_file, units)
    either = ((seam or {}).get("tolerance") or {}).get("sides") == "either"
    result = list_seams(spots, objects[index], objects, _pose(parsed.robot.base), parsed.process.approach,
                        max_distance, T_frame, either_side=either)
    seams = [SeamFile.model_validate({**(seam or {}), **s}) for s in result.seams]
    return seams, result


def _frame_world(name: str, tree: tuple[FrameNode, ...], parsed: CellFile, path: Path, key: str) -> np.ndarray:
    """The world pose of the frame `name` of a cell whose poses are resolved to the world: a named
    frame (from its frame tree), an object's own frame (its pose) or the world."""
    if name == WORLD:
        return np.eye(4)
    node = next((n for n in tree if n.name == name and n.kind == "frame"), None)
    if node is not None:
        return np.asarray(node.T_world, dtype=float)
    obj = next((o for o in (*parsed.objects, *parsed.dynamic) if o.name == name), None)
    if obj is not None:
        return _pose(obj.pose)
    frames = [WORLD, *(n.name for n in tree if n.kind == "frame")]
    raise CellFileError(path, key, f"unknown frame '{name}' (frames: {', '.join(frames)}; an object's name is its "
                                   "own frame too)")


def _with_spot_lists(parsed: CellFile, path: Path, tree: tuple[FrameNode, ...] = ()) -> tuple[CellFile, tuple[Notice, ...]]:
    """The cell with its spot lists' seams after its own, and their reports as notices."""
    if not parsed.spot_lists:
        return parsed, ()
    seams, notices = list(parsed.seams), []
    for i, entry in enumerate(parsed.spot_lists):
        settings = entry.model_dump(mode="json", include={"ordered", "tolerance", "grid"}, exclude_unset=True)
        more, result = spot_list_seams(parsed, path, f"spot_lists[{i}]", path.parent / entry.file, entry.part,
                                       entry.units, entry.max_distance, settings, entry.frame, tree)
        seams += more
        notices += [Notice(str(path), f"spot_lists[{i}]", line) for line in (*result.warnings, *result.sides, *(result.formed if result.by_geometry else ()))]
    _refuse_counts(sum(len(s.spots) for s in seams), 0, path)
    return parsed.model_copy(update={"seams": seams, "spot_lists": []}), tuple(notices)
