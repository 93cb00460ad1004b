"""Cell files (docs/cell-files.md, "A cell file") -> checked CellSpec in SI units.

Every user mistake becomes one CellFileError naming the file, the key path (e.g.
`seams[0].spots[3].normal`) and the problem; nothing here prints. This module reads the file and
puts the cell together; its parts are built by the modules beside it, the only ones that know
cell-file keys: the schema (`cell_file`, with `cell_file_values`, `cell_file_dynamic` and
`cell_file_jobs`), the size limits (`cell_limits`), objects (`cell_objects`), the job's seams
(`cell_jobs`), the robot's home and controller (`cell_robot`), spot lists (`cell_spot_lists`),
likely mistakes (`cell_lint`) and how errors are reported (`cell_problems`). Tools that rewrite cells read and write them through `cell_rewrite`.
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import (
    ValidationError,
)

from robomax_py.errors import CellFileError, RobotModelError
from robomax_py.io.cell_continuation import file_continuation
from robomax_py.io.cell_file import CellFile, IncludeFile
from robomax_py.io.cell_file_jobs import PICK_PLACE_SEAM, TENDING_SEAM
from robomax_py.io.cell_file_values import (
    CELL_LIMITS,
    SUPPORTED_VERSIONS,
    stem_name,
)
from robomax_py.io.cell_jobs import (
    _job_seams,
    _machines,
    _parts,
    _tcp_limits,
    check_tool_load,
    same_identifier,
    signals_apart,
)
from robomax_py.io.cell_limits import (
    _check_counts,
    _check_declared_triangles,
    _check_mesh_readable,
    _check_orientations,
    _refuse_counts,
)
from robomax_py.io.cell_lint import library_hint, lint_cell
from robomax_py.io.cell_moving import moving_object
from robomax_py.io.cell_objects import _object, _pose
from robomax_py.io.cell_problems import _located, _Problems
from robomax_py.io.cell_rewrite import dump_cell_file, read_cell_file, read_cell_frames
from robomax_py.io.cell_robot import (
    _controller,
    _home,
    _joint_limits,
    _start,
    within_joint_limits,
)
from robomax_py.io.cell_spot_lists import _with_spot_lists, spot_list_seams
from robomax_py.io.frames import resolve_frames
from robomax_py.io.includes import Expansion, expand_includes
from robomax_py.io.robot import (
    load_robot_spec,
    load_tool_spec,
    resolve_robot_file,
    resolve_tool_file,
)
from robomax_py.io.yaml_files import (
    count_items,
    read_yaml_mapping,
    validation_error,
)
from robomax_py.safe_files import LIMITS, checked_file, named_by, read_text
from robomax_py.spec import (
    CellSpec,
    LearnedMapSpec,
    PlannerSpec,
    ProcessSpec,
    dynamic_signal,
    frozen_array,
)

# What this module offered before its parts moved out stays importable from here.
__all__ = [
    "CELL_LIMITS", "MAPPING_FILE", "PICK_PLACE_SEAM", "TENDING_SEAM", "CellFile", "cell_from_mapping",
    "dump_cell_file", "load_cell", "load_cell_robot", "read_cell_file", "read_cell_frames", "spot_list_seams",
]


def load_cell(path: str | Path) -> CellSpec:
    """Read and check a cell file and the robot.yaml / tool.yaml / meshes it names.

    The robot's URDF is parsed for its kinematics (flange frame, joint limits for `robot.home`); link
    meshes are read later, by `load_cell_robot`.
    """
    path = Path(path)
    text = read_text(path, LIMITS.cell, CellFileError, "cell file")
    early = count_items(text, (("seams", "*", "spots"), ("objects",), ("dynamic",)))
    if early is not None:                  # before the guarded reader composes what may be a very long list
        _refuse_counts(early[("seams", "*", "spots")], early[("objects",)] + early[("dynamic",)], path)
    data = read_yaml_mapping(path, CellFileError, "cell file", LIMITS.cell)
    expansion = expand_includes(data, path, IncludeFile)
    # Programs name the exact cell file they were planned from (their header): its bytes and its includes'.
    return _located(expansion, _cell_from_data, expansion.data, path, expansion.digest(text.encode("utf-8")),
                    expansion)


# The file a cell given as a mapping is named as in messages (there is none).
MAPPING_FILE = "<mapping>"


def cell_from_mapping(data: Mapping[str, Any], base_dir: str | Path) -> CellSpec:
    """A cell given as a mapping (built in code, or read from elsewhere), checked as its file would be.

    `data` holds what a cell file's YAML would parse to (degrees and millimetres as in the file;
    tuples and numpy arrays are taken as lists); relative paths in it (meshes, a robot or tool
    file) are relative to `base_dir`. A CellFileError names the file as "<mapping>". `name` is
    required (there is no file stem to default to); `source` is `base_dir/<mapping>` and `digest`
    the SHA-256 of the mapping as canonical JSON (keys sorted).
    """
    plain = _plain(data, "", 0)
    if not isinstance(plain, dict):
        raise CellFileError(MAPPING_FILE, None, f"expected a mapping of keys, got {type(data).__name__}")
    if plain.get("name") is None:
        raise CellFileError(MAPPING_FILE, "name", "required for a cell given as a mapping (its programs are named "
                                                  "after it)")
    stand_in = Path(base_dir) / MAPPING_FILE   # so that relative paths resolve against base_dir
    try:
        expansion = expand_includes(plain, stand_in, IncludeFile)
        digest = expansion.digest(json.dumps(plain, sort_keys=True, separators=(",", ":")).encode("utf-8"))
        return _located(expansion, _cell_from_data, expansion.data, stand_in, digest, expansion)
    except (CellFileError, RobotModelError) as exc:
        if exc.file != str(stand_in):
            raise
        raise type(exc)(MAPPING_FILE, exc.key, exc.problem) from None


def _plain(value: object, key: str, depth: int) -> Any:
    """`value` as the YAML reader would give it: dicts with string keys, lists, scalars."""
    if depth > LIMITS.yaml_depth:
        raise CellFileError(MAPPING_FILE, key or None, f"nested more than {LIMITS.yaml_depth} levels deep")
    if isinstance(value, Mapping):
        out: dict[str, Any] = {}
        for k, v in value.items():
            if not isinstance(k, str):
                raise CellFileError(MAPPING_FILE, key or None, f"key {k!r} is not a string")
            out[k] = _plain(v, f"{key}.{k}" if key else k, depth + 1)
        return out
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if isinstance(value, list | tuple):
        return [_plain(v, f"{key}[{i}]", depth + 1) for i, v in enumerate(value)]
    if isinstance(value, np.generic):
        return value.item()
    if value is None or isinstance(value, str | bool | int | float):
        return value
    raise CellFileError(MAPPING_FILE, key or None, f"expected plain data (mappings, lists, numbers, strings), "
                                                   f"got {type(value).__name__}")


def _cell_from_data(data: dict[str, Any], path: Path, digest: str, expansion: Expansion) -> CellSpec:
    """The checked cell of a cell file's parsed YAML, its includes merged (`expansion`); `path` names it
    in messages and anchors its relative paths."""
    _check_counts(data, path)              # before validating: the data as read, aliases expanded
    version = data.get("robomax")
    if "robomax" in data and version not in SUPPORTED_VERSIONS:
        supported = ", ".join(str(v) for v in SUPPORTED_VERSIONS)
        raise CellFileError(path, "robomax", f"unsupported format version {version!r}; this robomax reads {supported}")
    try:
        parsed = CellFile.model_validate(data)
    except ValidationError as exc:
        raise validation_error(exc, CellFile, path, CellFileError) from None
    parsed, tree = resolve_frames(parsed, path)   # world coordinates from here on
    parsed, listed = _with_spot_lists(parsed, path, tree)   # placed by their parts or frames, already in the world
    # Independent checks each run, and their errors are reported together (up to MAX_LISTED_PROBLEMS);
    # a check that needs what an earlier one refused waits until those are fixed.
    problems = _Problems(path, expansion.relocated)
    problems.attempt(_check_unique_names, parsed, path)
    jobs_ok = not problems.found           # one job, named uniquely: its seams can be built
    problems.attempt(_check_orientations, parsed, path)
    problems.attempt(_check_declared_triangles, parsed, path)
    triangles: list[int] = []              # of every mesh read, for the cell's total
    machines, doors = problems.attempt(_machines, parsed, path, triangles) or ((), ())
    seams = problems.attempt(_job_seams, parsed, path, problems) if jobs_ok else None
    robot_file = problems.attempt(checked_file, resolve_robot_file(parsed.robot.model, path), LIMITS.description,
                                  named_by(CellFileError, path, "robot.model"),
                                  f"unknown robot '{parsed.robot.model}'{library_hint(parsed.robot.model, 'robot')}:")
    tool_file = problems.attempt(checked_file, resolve_tool_file(parsed.tool, path), LIMITS.description,
                                 named_by(CellFileError, path, "tool"),
                                 f"unknown tool '{parsed.tool}'{library_hint(parsed.tool, 'tool')}:")
    if parsed.name is None:
        problems.attempt(stem_name, path)
    problems.raise_found()
    assert robot_file is not None and tool_file is not None and seams is not None   # else raised above
    robot_spec = load_robot_spec(robot_file)
    tool_spec = load_tool_spec(tool_file)
    for key, mesh in (("body", tool_spec.body), ("tips", tool_spec.tips)):
        triangles.append(_check_mesh_readable(mesh, RobotModelError(tool_file, key, f"cannot read mesh {mesh.path}"),
                                              triangles))
    objects = tuple(problems.attempt(_object, o, path, f"objects[{i}]", triangles) for i, o in enumerate(parsed.objects))
    cycles = parsed.tending.cycles if parsed.tending is not None else 1
    dynamic = tuple(problems.attempt(moving_object, o, path, f"dynamic[{i}]", triangles, cycles)
                    if o.path is not None or o.robot is not None else
                    problems.attempt(_object, o, path, f"dynamic[{i}]", triangles) for i, o in enumerate(parsed.dynamic))
    parts = problems.attempt(_parts, parsed, path, robot_spec, triangles)
    home = problems.attempt(_home, parsed, robot_spec, path)
    start = problems.attempt(_start, parsed, robot_spec, path)
    joint_limits = problems.attempt(_joint_limits, parsed, robot_spec, path)
    problems.raise_found()
    assert parts is not None and home is not None
    within_joint_limits(home, joint_limits, "robot.home", robot_spec, path)
    within_joint_limits(start, joint_limits, "robot.start", robot_spec, path)
    check_tool_load(robot_spec, tool_spec, parts, path)
    if sum(triangles) > CELL_LIMITS.cell_triangles:
        raise CellFileError(path, "objects", f"its meshes and its tool's have {sum(triangles):,} triangles together, "
                            f"more than the {CELL_LIMITS.cell_triangles:,} a cell may have (cell_triangles)")

    cell = CellSpec(
        name=parsed.name or stem_name(path),
        source=path.resolve(),
        robot=robot_spec,
        T_world_base=frozen_array(_pose(parsed.robot.base)),
        home=frozen_array(home),
        tool=tool_spec,
        objects=tuple(o for o in objects if o is not None),
        seams=seams,
        process=ProcessSpec(
            weld_time=parsed.process.weld_time,
            approach=parsed.process.approach,
            clearance=parsed.process.clearance,
            gun=parsed.process.gun,
            schedule=parsed.process.schedule,
            interlock_distance=parsed.process.interlock_distance,
        ),
        planner=PlannerSpec(seed=parsed.planner.seed, speed=parsed.planner.speed, tcp_speed=parsed.planner.tcp_speed,
                            detour_speed=parsed.planner.detour_speed, detours=parsed.planner.detours,
                            detour_moves=parsed.planner.detour_moves,
                            detour_tcp_speed=parsed.planner.detour_tcp_speed,
                            learned=LearnedMapSpec(**parsed.planner.learned.model_dump()),
                            dynamic=parsed.planner.dynamic, max_wait=parsed.planner.max_wait,
                            transfers=parsed.planner.transfers,
                            cartesian_moves=parsed.planner.cartesian_moves),
        dynamic=tuple(o for o in dynamic if o is not None) + doors,
        digest=digest,
        machines=machines,
        parts=parts,
        tcp_limits=_tcp_limits(parsed.pick_place.unloaded) if parsed.pick_place is not None else None,
        start=None if start is None else frozen_array(start),
        joint_limits=None if joint_limits is None else frozen_array(joint_limits),
    )
    if parsed.continuation is not None:
        cell = file_continuation(cell, parsed.continuation, path)
    cell = dataclasses.replace(cell, controller=_controller(parsed.robot.controller, cell, path))
    return dataclasses.replace(cell, notices=listed + tuple(map(expansion.relocated_notice, lint_cell(parsed, cell, path))))


def load_cell_robot(cell: CellSpec) -> Any:
    """The cell's `robomax_py.robot.RobotModel` with its tool mounted (imported lazily: Pinocchio is heavy)."""
    from robomax_py.robot import load_robot, mount_tool, with_joint_limits

    robot = mount_tool(load_robot(cell.robot), cell.tool.T_flange_tcp)
    return robot if cell.joint_limits is None else with_joint_limits(robot, cell.joint_limits)


def _check_unique_names(parsed: CellFile, path: Path) -> None:
    seen: dict[str, str] = {}
    doors = [(f"tending.machines[{i}].door", m.door) for i, m in enumerate(parsed.tending.machines)] \
        if parsed.tending else []
    named = [(f"{group}[{i}]", obj) for group, items in (("objects", parsed.objects), ("dynamic", parsed.dynamic))
             for i, obj in enumerate(items)]
    for key, obj in named + doors:
        if obj.name in seen:
            raise CellFileError(path, f"{key}.name", f"duplicate name '{obj.name}' (also {seen[obj.name]})")
        seen[obj.name] = key
    clamps = [(f"objects[{i}].signal", obj.signal) for i, obj in enumerate(parsed.objects) if obj.signal]
    cleared = [(f"dynamic[{i}].name", dynamic_signal(obj.name, False)) for i, obj in enumerate(parsed.dynamic)]
    opened = [(f"{key}.name", dynamic_signal(door.name, True)) for key, door in doors]
    signals_apart(clamps + cleared + opened, path)
    outputs = parsed.robot.controller.outputs
    signals_apart([(f"robot.controller.outputs.{name}", name) for name in outputs], path)
    jobs = [key for key, given in (("seams", bool(parsed.seams)), ("tending", parsed.tending is not None),
                                   ("pick_place", parsed.pick_place is not None)) if given]
    if len(jobs) > 1:
        raise CellFileError(path, jobs[1], f"a cell has one job: {' and '.join(jobs)} are both given; keep one")
    if not jobs:
        raise CellFileError(path, "seams", "required: at least one seam (or a tending or pick_place section)")
    if parsed.pick_place is not None and parsed.dynamic:
        raise CellFileError(path, "dynamic", "pick-and-place cells do not plan dynamic objects yet: remove them")
    seams: dict[str, int] = {}
    for i, seam in enumerate(parsed.seams):
        if seam.name in seams:
            raise CellFileError(path, f"seams[{i}].name", f"duplicate seam name '{seam.name}' (also seams[{seams[seam.name]}])")
        seams[seam.name] = i
        spots: dict[str, int] = {}
        for j, spot in enumerate(seam.spots):
            if spot.name in spots:
                raise CellFileError(
                    path, f"seams[{i}].spots[{j}].name",
                    f"duplicate spot name '{spot.name}' (also spots[{spots[spot.name]}])",
                )
            spots[spot.name] = j
        same_identifier([spot.name for spot in seam.spots], f"seams[{i}].spots", path)
    same_identifier([seam.name for seam in parsed.seams], "seams", path)
