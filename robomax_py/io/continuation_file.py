"""The cell file of a program's continuation (`robomax replan` writes `<name>.cell.yaml` beside
its programs): the original cell file as it stands, with what changed written into it, so that
`robomax plan` and `robomax verify` read the cell the continuation runs in.

The text is the original cell read flat through its schema (`io.cell_rewrite`: includes merged,
poses in the world; spot lists read into seams), every relative reference (meshes, a robot or
tool given by path, another robot's trajectory) rewritten relative to the output folder, and:
- the events applied (`io.replan_events`): objects gone are left out, objects that appeared are
  added (static, or dynamic with their window), changed windows written as they now are (a
  machine's door as `windows` when they no longer keep its schedule's period);
- `robot.start`: the stop configuration, deg, as the programs write it;
- `continuation:` `at` the stop (s of the original program's clock, which every time in the file
  keeps) and `done` the actions completed by then.
Loading it gives the cell `robomax replan` planned in (`io.cell_continuation`).
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from robomax_py.io.cell_file import CellFile, ContinuationFile
from robomax_py.io.cell_file_dynamic import DynamicObjectFile
from robomax_py.io.cell_file_values import MAX_WINDOW_S, ObjectFile
from robomax_py.io.cell_rewrite import _read_resolved, dump_cell_file
from robomax_py.io.cell_spot_lists import _with_spot_lists
from robomax_py.io.includes import rebased_reference
from robomax_py.io.robot import resolve_robot_file, resolve_tool_file
from robomax_py.spec import Box, CellSpec, Cylinder, ObjectSpec, Sphere, dynamic_signal
from robomax_py.transforms import rpy_from_matrix

__all__ = ["ContinuationText", "continuation_cell_text"]

DECIMALS = 9                 # m, deg and s written: far below every tolerance verify applies


@dataclass(frozen=True, slots=True)
class ContinuationText:
    """The continuation's cell file: `text` (None when it cannot be written, `reason` says why)."""

    text: str | None
    reason: str = ""


def continuation_cell_text(source: Path, out_dir: Path, name: str, original: CellSpec, changed: CellSpec,
                           at: float, done: Sequence[str], start_deg: Sequence[float],
                           header: str = "") -> ContinuationText:
    """The cell file `out_dir/<name>.cell.yaml` of a continuation (see the module docstring):
    `source` the original cell file, `original` its cell, `changed` that cell with the events
    applied (the original program's clock), `at` the stop (s), `done` the actions done
    (`seam/spot`), `start_deg` the stop configuration (deg; m for a prismatic joint)."""
    parsed, tree, _ = _read_resolved(source)
    parsed, _ = _with_spot_lists(parsed, source, tree)
    if parsed.pick_place is not None:
        return ContinuationText(None, "pick-and-place cells are not replanned")
    parsed = _relocated(parsed, source, out_dir)
    # A continuation's own continuation: the file keeps the first program's clock, and its actions done.
    prior = parsed.continuation
    offset = 0.0 if prior is None else prior.at
    gone = {o.name for o in (*original.objects, *original.dynamic)} - {o.name for o in (*changed.objects, *changed.dynamic)}
    windows = {d.name: d.present for d in changed.dynamic}
    before = {d.name: d.present for d in original.dynamic}
    objects = [o for o in parsed.objects if o.name not in gone]
    dynamic: list[DynamicObjectFile] = []
    dropped: set[str] = set()
    for d in parsed.dynamic:
        if d.name in gone:
            continue
        now = windows[d.name]
        if now is not None and now != before[d.name]:
            if not now:
                dropped.add(dynamic_signal(d.name, False))      # never there again: nothing to wait for
                continue
            d = d.model_copy(update={"present": _written(now, offset)})
        dynamic.append(d)
    known = {o.name for o in (*original.objects, *original.dynamic)}
    for o in changed.objects:
        if o.name not in known:
            objects.append(ObjectFile.model_validate(_object_data(o)))
    for o in changed.dynamic:
        if o.name not in known:
            dynamic.append(DynamicObjectFile.model_validate({**_object_data(o),
                                                             "present": _written(o.present or (), offset)}))
    update: dict[str, Any] = {"objects": objects}
    if dynamic or parsed.dynamic:
        update["dynamic"] = dynamic
    if parsed.tending is not None:
        machines = []
        for m in parsed.tending.machines:
            if m.door.name in gone:
                return ContinuationText(None, f"the door of machine {m.name} is removed: a machine has a door")
            spec = next(s for s in changed.machines if s.name == m.name)
            if spec.windows != next(s for s in original.machines if s.name == m.name).windows:
                m = m.model_copy(update={"schedule": None, "windows": _written(spec.windows, offset)})
                m.__pydantic_fields_set__.discard("schedule")
            machines.append(m)
        update["tending"] = parsed.tending.model_copy(update={"machines": machines})
    controller = parsed.robot.controller
    if dropped & set(controller.inputs):
        controller = controller.model_copy(update={"inputs": {k: v for k, v in controller.inputs.items()
                                                              if k not in dropped}})
    robot: dict[str, Any] = {"start": [_round(v) for v in start_deg]}
    if controller is not parsed.robot.controller:
        robot["controller"] = controller
    update["robot"] = parsed.robot.model_copy(update=robot)
    update["name"] = name
    update["continuation"] = ContinuationFile(cell=original.name, at=_round(offset + at),
                                              done=[*(prior.done if prior else ()), *done])
    cell = CellFile.model_validate(parsed.model_copy(update=update).model_dump(mode="json", exclude_unset=True,
                                                                                  by_alias=True))
    return ContinuationText(dump_cell_file(cell, header))


def _round(v: float) -> float:
    return round(float(v), DECIMALS) + 0.0       # + 0.0: no "-0.0" in files


def _written(windows: tuple[tuple[float, float], ...], offset: float) -> list[list[float]]:
    """Windows as a file holds them, `offset` s later: one open to the end (for good) ends after a day."""
    return [[_round(a + offset), _round(min(b + offset, MAX_WINDOW_S))] for a, b in windows]


def _object_data(o: ObjectSpec) -> dict[str, Any]:
    """An object that appeared (a box, sphere or cylinder at a pose) as a cell file gives it."""
    T = np.asarray(o.T_world_object)
    pose = {"xyz": [_round(v) for v in T[:3, 3]], "rpy": [_round(math.degrees(v)) for v in rpy_from_matrix(T[:3, :3])]}
    shape = o.shape
    if isinstance(shape, Box):
        given: dict[str, Any] = {"box": [_round(v) for v in shape.extents]}
    elif isinstance(shape, Sphere):
        given = {"sphere": {"radius": _round(shape.radius)}}
    elif isinstance(shape, Cylinder):
        given = {"cylinder": {"radius": _round(shape.radius), "length": _round(shape.length)}}
    else:
        raise TypeError(f"an event adds boxes, spheres and cylinders, not {type(shape).__name__}")
    return {"name": o.name, **given, "pose": pose}


def _rebased(ref: str, src_dir: Path, dst_dir: Path) -> str:
    """A file path relative to the original cell's folder, relative to the output folder instead."""
    if Path(ref).is_absolute():
        return ref
    return Path(os.path.relpath((src_dir / ref).resolve(), dst_dir)).as_posix()


def _relocated(cell: CellFile, source: Path, out_dir: Path) -> CellFile:
    """Every relative reference of the flat cell rewritten relative to `out_dir` (a library robot
    or tool name stays as it is)."""
    # The folder the cell file is named in, as the loader takes it (a set's file is a symbolic link
    # into the set's folder: its target's folder is not the one its paths are relative to).
    here = Path(os.path.abspath(source))
    src_dir, dst_dir = here.parent, out_dir.resolve()
    there = dst_dir / source.name

    def obj(o: Any) -> Any:
        update: dict[str, Any] = {}
        if o.mesh is not None:
            update["mesh"] = _rebased(o.mesh, src_dir, dst_dir)
        if getattr(o, "trajectory", None) is not None:
            update["trajectory"] = _rebased(o.trajectory, src_dir, dst_dir)
        if getattr(o, "robot", None) is not None:
            r = o.robot
            robot_update: dict[str, Any] = {"model": rebased_reference(r.model, here, there, resolve_robot_file)}
            if r.tool is not None:
                robot_update["tool"] = rebased_reference(r.tool, here, there, resolve_tool_file)
            update["robot"] = r.model_copy(update=robot_update)
        return o.model_copy(update=update) if update else o

    update: dict[str, Any] = {"objects": [obj(o) for o in cell.objects]}
    if cell.dynamic:
        update["dynamic"] = [obj(o) for o in cell.dynamic]
    update["robot"] = cell.robot.model_copy(update={"model": rebased_reference(cell.robot.model, here, there,
                                                                             resolve_robot_file)})
    update["tool"] = rebased_reference(cell.tool, here, there, resolve_tool_file)
    if cell.tending is not None:
        machines = [m.model_copy(update={"door": obj(m.door)}) for m in cell.tending.machines]
        update["tending"] = cell.tending.model_copy(update={"machines": machines})
    return cell.model_copy(update=update)

