"""Cell files (docs/cell-files.md, "A cell file") -> checked CellSpec in SI units.

The only module that knows cell-file keys. Every user mistake becomes one CellFileError naming the
file, the key path (e.g. `seams[0].spots[3].normal`) and the problem; nothing here prints.
"""

from __future__ import annotations

import dataclasses
import json
import math
import re
import stat
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import (
    ValidationError,
)

from robomax_py.errors import CellFileError, RobotModelError
from robomax_py.io.cell_file import (
    CELL_LIMITS,
    MAX_CELL_NAME_CHARS,
    MAX_WINDOW_S,
    MIN_DIRECTION_SINE,
    PICK_PLACE_SEAM,
    SAME_ORIENTATION_RAD,
    SUPPORTED_VERSIONS,
    TENDING_SEAM,
    CellFile,
    DynamicObjectFile,
    IncludeFile,
    ObjectFile,
    PickPlaceFile,
    PoseFile,
    RobotControllerFile,
    SeamFile,
    SpotFile,
    T,
    TcpLimitsFile,
    ToleranceFile,
)
from robomax_py.io.cell_lint import library_hint, lint_cell
from robomax_py.io.frames import WORLD, FrameNode, resolve_frames
from robomax_py.io.includes import Expansion, expand_includes
from robomax_py.io.mesh_keys import (
    mesh_shape,
)
from robomax_py.io.robot import (
    load_robot_spec,
    load_tool_spec,
    resolve_robot_file,
    resolve_tool_file,
)
from robomax_py.io.yaml_files import (
    MAX_LISTED_PROBLEMS,
    count_items,
    read_yaml_mapping,
    several,
    validation_error,
)
from robomax_py.robot.geometry import load_mesh, mesh_shape_trimesh
from robomax_py.safe_files import LIMITS, checked_file, named_by, read_text
from robomax_py.spec import (
    Box,
    Capsule,
    CellSpec,
    ControllerFrame,
    ControllerInput,
    ControllerSetup,
    Cylinder,
    MachineSpec,
    MeshShape,
    Notice,
    ObjectSpec,
    PartSpec,
    PlannerSpec,
    ProcessSpec,
    RobotSpec,
    SeamSpec,
    Shape,
    Sphere,
    SpotSpec,
    TcpLimits,
    UserFrame,
    frozen_array,
)
from robomax_py.transforms import invert, pose_matrix
from robomax_py.units import deg_to_rad


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


def _located(expansion: Expansion, build: Callable[..., T], *args: Any) -> T:
    """`build(*args)`, an error in what an included file brought naming that file and its own key."""
    try:
        return build(*args)
    except CellFileError as exc:
        raise expansion.relocated(exc) from None


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
        problems.attempt(_stem_name, path)
    problems.raise_found()
    assert robot_file is not None and tool_file is not None and seams is not None   # else raised above
    robot_spec = load_robot_spec(robot_file)
    tool_spec = load_tool_spec(tool_file)
    for key, mesh in (("body", tool_spec.body), ("tips", tool_spec.tips)):
        triangles.append(_check_mesh_readable(mesh, RobotModelError(tool_file, key, f"cannot read mesh {mesh}"),
                                              triangles))
    objects = tuple(problems.attempt(_object, o, path, f"objects[{i}]", triangles) for i, o in enumerate(parsed.objects))
    dynamic = tuple(problems.attempt(_object, o, path, f"dynamic[{i}]", triangles) for i, o in enumerate(parsed.dynamic))
    parts = problems.attempt(_parts, parsed, path, robot_spec, triangles)
    home = problems.attempt(_home, parsed, robot_spec, path)
    problems.raise_found()
    assert parts is not None and home is not None
    if sum(triangles) > CELL_LIMITS.cell_triangles:
        raise CellFileError(path, "objects", f"its meshes and its tool's have {sum(triangles):,} triangles together, "
                            f"more than the {CELL_LIMITS.cell_triangles:,} a cell may have (cell_triangles)")

    cell = CellSpec(
        name=parsed.name or _stem_name(path),
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
                            dynamic=parsed.planner.dynamic, max_wait=parsed.planner.max_wait),
        dynamic=tuple(o for o in dynamic if o is not None) + doors,
        digest=digest,
        machines=machines,
        parts=parts,
        tcp_limits=_tcp_limits(parsed.pick_place.unloaded) if parsed.pick_place is not None else None,
    )
    cell = dataclasses.replace(cell, controller=_controller(parsed.robot.controller, cell, path))
    return dataclasses.replace(cell, notices=listed + tuple(map(expansion.relocated_notice, lint_cell(parsed, cell, path))))


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
    result = list_seams(spots, objects[index], objects, _pose(parsed.robot.base), parsed.process.approach,
                        max_distance, T_frame)
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


def _controller(ctrl: RobotControllerFile, cell: CellSpec, path: Path) -> ControllerSetup:
    """`robot.controller`: the tool and user frame programs select, registers, inputs, weld style."""
    key = "robot.controller"
    tool = None
    if ctrl.tool is not None:
        tool = ControllerFrame(ctrl.tool.number or 1, ctrl.tool.name or f"{cell.tool.name}_tcp", ctrl.tool.name is not None)
    frame = None
    if ctrl.frame is not None:
        f = ctrl.frame
        if f.object is not None:
            obj = next((o for o in cell.objects if o.name == f.object), None)
            if obj is None:
                known = ", ".join(o.name for o in cell.objects) or "none"
                raise CellFileError(path, f"{key}.frame.object", f"no object '{f.object}' in the cell (objects: {known})")
            T = np.asarray(obj.T_world_object)
        else:
            assert f.pose is not None  # guaranteed by UserFrameFile._one_place
            T = _pose(f.pose)
        name = f.name or (f.object if f.object and re.fullmatch(r"[A-Za-z][A-Za-z0-9_]{0,31}", f.object) else "user_frame")
        frame = UserFrame(ControllerFrame(f.number or 1, name, f.name is not None), frozen_array(T))
    signals = cell.signals
    inputs: list[ControllerInput] = []
    for signal, given in ctrl.inputs.items():
        if signal not in signals:
            raise CellFileError(path, f"{key}.inputs.{signal}", f"the cell has no signal '{signal}' (its signals: "
                                f"{', '.join(signals) or 'none'}; clamps name theirs, dynamic objects wait for "
                                "<name>_clear, machine doors for <machine>_open)")
        entry = ControllerInput(signal, given, None) if isinstance(given, int) else \
            ControllerInput(signal, given.number, given.name)
        twin = next((i for i in inputs if i.number == entry.number), None)
        if twin is not None:
            raise CellFileError(path, f"{key}.inputs.{signal}", f"input {entry.number} is also {twin.signal}'s")
        inputs.append(entry)
    return ControllerSetup(tool=tool, frame=frame, position_registers=tuple(ctrl.registers.position),
                           numeric_registers=tuple(ctrl.registers.numeric), inputs=tuple(inputs), weld=ctrl.weld)


def _job_seams(parsed: CellFile, path: Path, problems: _Problems) -> tuple[SeamSpec, ...]:
    if parsed.tending is not None:
        return _tending_seams(parsed, path)
    if parsed.pick_place is not None:
        return _pick_place_seams(parsed.pick_place, {o.name for o in parsed.objects}, path)
    return _seams(parsed, path, problems)


class _Problems:
    """The CellFileErrors of a cell file's independent checks, raised together as one (`several`)."""

    def __init__(self, path: Path, locate: Callable[[CellFileError], CellFileError]) -> None:
        self.path = path
        self.locate = locate               # an included file's item is named by its file and key there
        self.found: list[CellFileError] = []

    def attempt(self, check: Callable[..., T], *args: Any) -> T | None:
        """`check(*args)`, or None when it refuses the file (its error kept; raised at once when
        MAX_LISTED_PROBLEMS are kept: the rest of the file is not looked at)."""
        try:
            return check(*args)
        except CellFileError as exc:
            self.found.append(self.locate(exc))
            if len(self.found) >= MAX_LISTED_PROBLEMS:
                raise several(list(self.found), self.path, more=True) from None
            return None

    def raise_found(self) -> None:
        if self.found:
            raise several(list(self.found), self.path)


def _tcp_limits(limits: TcpLimitsFile | None) -> TcpLimits | None:
    return None if limits is None else TcpLimits(limits.v, limits.a_T, limits.a_R, limits.j_T, limits.j_R)


def _parts(parsed: CellFile, path: Path, robot: RobotSpec, triangles: list[int]) -> tuple[PartSpec, ...]:
    """The parts with their held pose in the TCP frame and the supports of the locations they visit."""
    job = parsed.pick_place
    if job is None:
        return ()
    out = []
    for i, part in enumerate(job.parts):
        key = f"pick_place.parts[{i}]"
        if robot.payload_kg is not None and part.mass > robot.payload_kg:
            raise CellFileError(path, f"{key}.mass", f"{part.mass:g} kg is above the robot's rated payload "
                                f"{robot.payload_kg:g} kg ({robot.source})")
        shape = _object(part, path, key, triangles).shape
        at = {t.from_ for t in job.transfers if t.part == part.name} | {t.to for t in job.transfers if t.part == part.name}
        supports = sorted({name for loc in job.locations if loc.name in at for name in loc.support})
        out.append(PartSpec(name=part.name, shape=shape, mass=part.mass,
                            T_tcp_part=frozen_array(invert(_pose(part.grasp))),
                            limits=_tcp_limits(part.limits), supports=tuple(supports)))
    return tuple(out)


def _index_by_name(names: list[str], what: str, key: str, path: Path) -> dict[str, int]:
    """name -> index in the list at `key`; a repeated name is refused with both places."""
    out: dict[str, int] = {}
    for i, name in enumerate(names):
        if name in out:
            raise CellFileError(path, f"{key}[{i}].name", f"duplicate {what} name '{name}' (also {key.split('.')[-1]}[{out[name]}])")
        out[name] = i
    return out


def _pick_place_seams(job: PickPlaceFile, objects: set[str], path: Path) -> tuple[SeamSpec, ...]:
    """The transfers as one ordered seam: per transfer a grip where the part lies and a release
    where it goes, each at the TCP pose the part's grasp gives there."""
    parts = _index_by_name([p.name for p in job.parts], "part", "pick_place.parts", path)
    locations = _index_by_name([loc.name for loc in job.locations], "location", "pick_place.locations", path)
    for i, loc in enumerate(job.locations):
        for j, name in enumerate(loc.support):
            if name not in objects:
                raise CellFileError(path, f"pick_place.locations[{i}].support[{j}]",
                                    f"unknown object '{name}' (a support is one of the cell's objects)")
    spots = []
    for k, tr in enumerate(job.transfers):
        key = f"pick_place.transfers[{k}]"
        if tr.part not in parts:
            raise CellFileError(path, f"{key}.part", f"unknown part '{tr.part}' (parts: {', '.join(parts)})")
        for field, name in (("from", tr.from_), ("to", tr.to)):
            if name not in locations:
                raise CellFileError(path, f"{key}.{field}", f"unknown location '{name}' (locations: {', '.join(locations)})")
        if tr.from_ == tr.to:
            raise CellFileError(path, f"{key}.to", f"the part goes back where it lies ('{tr.to}'): a transfer moves it")
        T_tcp_in_part = _pose(job.parts[parts[tr.part]].grasp)
        for action, name, visit in (("grip", tr.from_, "pick"), ("release", tr.to, "place")):
            T = _pose(job.locations[locations[name]].pose) @ T_tcp_in_part
            R = T[:3, :3]
            spots.append(SpotSpec(
                name=f"t{k + 1}_{visit}_{name}", xyz=frozen_array(T[:3, 3]), normal=frozen_array(-R[:, 2]),
                direction=frozen_array(R[:, 0]),
                weld_time=job.gripper.grip if action == "grip" else job.gripper.release,
                angles=(0.0, 0.0, 0.0), action=action, key=key, part=tr.part,  # type: ignore[arg-type]
            ))
    return (SeamSpec(name=PICK_PLACE_SEAM, ordered=True, alpha_max=0.0, beta_max=0.0, gamma_range=(0.0, 0.0),
                     grid=1, spots=tuple(spots)),)


def load_cell_robot(cell: CellSpec) -> Any:
    """The cell's `robomax_py.robot.RobotModel` with its tool mounted (imported lazily: Pinocchio is heavy)."""
    from robomax_py.robot import load_robot, mount_tool

    return mount_tool(load_robot(cell.robot), cell.tool.T_flange_tcp)


def _home(parsed: CellFile, robot: RobotSpec, path: Path) -> np.ndarray:
    """`robot.home` in SI, checked against the URDF: deg -> rad, prismatic joints stay in metres."""
    from robomax_py.robot import active_joints, kinematic_model, prismatic_mask

    model = kinematic_model(robot)
    given = np.asarray(parsed.robot.home, dtype=float)
    if len(given) != model.nq:
        raise CellFileError(path, "robot.home", f"expected {model.nq} joint values for {robot.name}, got {len(given)}")
    prismatic = prismatic_mask(model)
    home = np.where(prismatic, given, np.radians(given))
    lower, upper = np.asarray(model.lowerPositionLimit), np.asarray(model.upperPositionLimit)
    tol = 1e-9
    outside = (home < lower - tol) | (home > upper + tol)
    if outside.any():
        i = int(np.flatnonzero(outside)[0])
        unit, scale = ("m", 1.0) if prismatic[i] else ("deg", 180 / math.pi)
        raise CellFileError(
            path, f"robot.home[{i}]",
            f"{model.names[active_joints(model)[i]]} = {given[i]:.3f} {unit} is outside its limits "
            f"[{lower[i] * scale:.3f}, {upper[i] * scale:.3f}] {unit}",
        )
    return home


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


def _pose(pose: PoseFile) -> np.ndarray:
    return pose_matrix(pose.xyz, [deg_to_rad(a) for a in pose.rpy])


def _object(obj: ObjectFile, path: Path, key: str, triangles: list[int]) -> ObjectSpec:
    """The object's spec; a mesh is read (and refused when unreadable or too large) and its
    triangles are added to `triangles`."""
    shape: Shape
    if obj.box is not None:
        shape = Box(extents=(obj.box[0], obj.box[1], obj.box[2]))
    elif obj.cylinder is not None:
        shape = Cylinder(radius=obj.cylinder.radius, length=obj.cylinder.length)
    elif obj.sphere is not None:
        shape = Sphere(radius=obj.sphere.radius)
    elif obj.capsule is not None:
        shape = Capsule(radius=obj.capsule.radius, length=obj.capsule.length)
    else:
        assert obj.mesh is not None  # guaranteed by ObjectFile._one_shape
        named = path.parent / obj.mesh
        mesh = checked_file(named, LIMITS.mesh, named_by(CellFileError, path, f"{key}.mesh"), f"mesh {named}")
        shape = mesh_shape(mesh, obj.units, obj.scale, obj.tolerance, path, key)
        triangles.append(_check_mesh_readable(shape, CellFileError(path, f"{key}.mesh", f"cannot read mesh {mesh}"),
                                              triangles))
    present = None
    if isinstance(obj, DynamicObjectFile):
        present = tuple((float(t0), float(t1)) for t0, t1 in obj.present)
    return ObjectSpec(
        name=obj.name, shape=shape, T_world_object=frozen_array(_pose(obj.pose)),
        workpiece=obj.workpiece, present=present, signal=obj.signal,
    )


def _check_pinned(spot: SpotFile, tol: ToleranceFile, path: Path, key: str) -> None:
    """A pinned orientation must lie inside its seam's tolerance window."""
    for name, value, lo, hi in (("alpha", spot.alpha, -tol.alpha, tol.alpha), ("beta", spot.beta, -tol.beta, tol.beta)):
        if value is not None and not lo - 1e-9 <= value <= hi + 1e-9:
            raise CellFileError(path, f"{key}.{name}", f"pinned {name} {value:g} deg is outside the seam's tolerance "
                                                      f"[{lo:g}, {hi:g}]")
    g0, g1 = tol.gamma
    g = spot.gamma
    if g is not None and g1 - g0 < 360 and not any(g0 - 1e-9 <= g + k * 360 <= g1 + 1e-9 for k in (-1, 0, 1)):
        raise CellFileError(path, f"{key}.gamma", f"pinned gamma {g:g} deg is outside the seam's tolerance [{g0:g}, {g1:g}]")


def _stem_name(path: Path) -> str:
    """The cell's name when the file gives none: its file stem, under the rules of `name`."""
    stem = path.stem
    if len(stem) > MAX_CELL_NAME_CHARS:
        raise CellFileError(path, "name", f"not given, and the file name is longer than {MAX_CELL_NAME_CHARS} "
                            "characters (the programs are named after the cell); give a shorter name:")
    return stem




def _check_mesh_readable(shape: Path | MeshShape, error: CellFileError | RobotModelError, triangles: list[int]) -> int:
    """The mesh's triangles, when it reads, has at most `CELL_LIMITS.mesh_triangles` and keeps the
    cell's meshes read so far (`triangles`) within `CELL_LIMITS.cell_triangles`. What the file
    states of its size is judged before it is read (reading a mesh of millions of triangles takes
    seconds)."""
    mesh = shape.path if isinstance(shape, MeshShape) else shape
    limit, total = CELL_LIMITS.mesh_triangles, sum(triangles)
    declared, exact = _declared_triangles(mesh)
    more = "" if exact else " or more"
    if declared > limit:
        raise type(error)(error.file, error.key, f"mesh {mesh} has {declared:,} triangles{more}, more than the "
                                                 f"{limit:,} a mesh may have (mesh_triangles)")
    if total + declared > CELL_LIMITS.cell_triangles:
        raise type(error)(error.file, error.key, f"mesh {mesh} brings the cell's meshes and its tool's to "
                                                 f"{total + declared:,} triangles{more}, more than the "
                                                 f"{CELL_LIMITS.cell_triangles:,} a cell may have (cell_triangles)")
    try:
        n = len((mesh_shape_trimesh(shape) if isinstance(shape, MeshShape) else load_mesh(mesh)).faces)
    except Exception as exc:  # noqa: BLE001 - trimesh raises many kinds for unreadable files
        raise type(error)(error.file, error.key, f"{error.problem}: {exc}") from None
    if n > limit:
        raise type(error)(error.file, error.key, f"mesh {mesh} has {n:,} triangles, more than the {limit:,} a mesh "
                                                 "may have (mesh_triangles)")
    return n


def _declared_triangles(mesh: Path) -> tuple[int, bool]:
    """As many triangles as the file states before it is read, at least, and whether exactly: a
    binary STL's count (exact: its size is 84 bytes plus 50 per triangle), a PLY header's faces, an
    OBJ's face lines (a face is one triangle or more); 0 for other formats or a file that cannot
    be read, is not a regular file or is larger than LIMITS.mesh (refused when it is checked)."""
    suffix = mesh.suffix.lower()
    try:
        info = mesh.stat()
        size = info.st_size
        if not stat.S_ISREG(info.st_mode) or size > LIMITS.mesh:
            return 0, False
        if suffix == ".stl":
            with open(mesh, "rb") as fh:
                head = fh.read(84)
            n = int.from_bytes(head[80:84], "little") if len(head) == 84 else 0
            return (n, True) if size == 84 + 50 * n else (0, False)
        if suffix == ".ply":
            with open(mesh, "rb") as fh:
                header = fh.read(4096).split(b"end_header", 1)[0]
            found = re.search(rb"^element\s+face\s+(\d{1,12})\s*$", header, re.MULTILINE)
            return (int(found.group(1)) if found else 0), False
        if suffix == ".obj":
            faces, tail = 0, b"\n"             # a face line starts the file or follows a line end
            with open(mesh, "rb") as fh:
                while chunk := fh.read(1 << 24):
                    data = tail + chunk
                    faces += data.count(b"\nf ") + data.count(b"\nf\t")
                    tail = data[-2:]
            return faces, False
    except OSError:
        pass
    return 0, False


def _check_declared_triangles(parsed: CellFile, path: Path) -> None:
    """The cell's meshes within `CELL_LIMITS.cell_triangles` by what their files state
    (`_declared_triangles`), before any is read: three meshes of 1.9 million triangles each were
    read, 20 s of CPU, before the third was refused. The tool's meshes and what the files do not
    state are counted as they are read."""
    named = [(f"objects[{i}]", o) for i, o in enumerate(parsed.objects)]
    named += [(f"dynamic[{i}]", o) for i, o in enumerate(parsed.dynamic)]
    if parsed.tending is not None:
        named += [(f"tending.machines[{i}].door", m.door) for i, m in enumerate(parsed.tending.machines)]
    if parsed.pick_place is not None:
        named += [(f"pick_place.parts[{i}]", p) for i, p in enumerate(parsed.pick_place.parts)]
    total, exact = 0, True
    for key, obj in named:
        if obj.mesh is None:
            continue
        n, known = _declared_triangles(path.parent / obj.mesh)
        total, exact = total + n, exact and known
        if total > CELL_LIMITS.cell_triangles:
            raise CellFileError(path, f"{key}.mesh", f"the cell's meshes up to this one have {total:,} triangles"
                                f"{'' if exact else ' or more'}, more than the {CELL_LIMITS.cell_triangles:,} a "
                                "cell may have (cell_triangles)")


def _check_counts(data: dict[str, Any], path: Path) -> None:
    """Spots and objects within `CELL_LIMITS`, counted in the file's data before it is validated."""
    seams = data.get("seams")
    spots = sum(len(s["spots"]) for s in seams if isinstance(s, dict) and isinstance(s.get("spots"), list)) \
        if isinstance(seams, list) else 0
    objects = sum(len(v) for v in (data.get("objects"), data.get("dynamic")) if isinstance(v, list))
    _refuse_counts(spots, objects, path)


def _refuse_counts(spots: int, objects: int, path: Path) -> None:
    if spots > CELL_LIMITS.spots:
        raise CellFileError(path, "seams", f"{spots:,} spots, more than the {CELL_LIMITS.spots:,} a cell may have "
                                           "(spots); split the job into cells")
    if objects > CELL_LIMITS.objects:
        raise CellFileError(path, "objects", f"{objects:,} objects and dynamic objects, more than the "
                                             f"{CELL_LIMITS.objects:,} a cell may have (objects)")


def _check_orientations(parsed: CellFile, path: Path) -> None:
    """Each seam's orientations (its grid's samples, as `plan.poses.orientation_grid` takes them,
    and its spots' pinned orientations) within `CELL_LIMITS.orientations`: every spot of the seam
    is solved at every one of them."""
    for i, seam in enumerate(parsed.seams):
        tol = seam.tolerance
        ranges = (2 * deg_to_rad(tol.alpha), 2 * deg_to_rad(tol.beta), deg_to_rad(tol.gamma[1] - tol.gamma[0]))
        grid = 1
        for r in ranges:
            grid *= 1 if seam.grid == 1 or r <= SAME_ORIENTATION_RAD else seam.grid
        pinned = sum(1 for s in seam.spots if s.alpha is not None and not s.skip)
        if grid + pinned > CELL_LIMITS.orientations:
            raise CellFileError(path, f"seams[{i}].grid", f"{grid:,} grid orientations and {pinned:,} pinned ones, "
                                f"more than the {CELL_LIMITS.orientations:,} a seam may have (orientations): "
                                "every spot is solved at each")


def _machines(parsed: CellFile, path: Path, triangles: list[int]) -> tuple[tuple[MachineSpec, ...], tuple[ObjectSpec, ...]]:
    """Each machine and its door, a dynamic object closed in the schedule's windows."""
    if parsed.tending is None:
        return (), ()
    machines, doors = [], []
    for i, m in enumerate(parsed.tending.machines):
        sched = m.schedule
        count = sched.count or parsed.tending.cycles
        windows = tuple((sched.start + k * sched.period, sched.start + k * sched.period + sched.machining)
                        for k in range(count))
        if windows[-1][1] > MAX_WINDOW_S:
            raise CellFileError(path, f"tending.machines[{i}].schedule", f"the last machining ends at "
                                f"{windows[-1][1]:g} s, beyond a day ({MAX_WINDOW_S:g} s) of program time")
        door = _object(m.door, path, f"tending.machines[{i}].door", triangles)
        doors.append(ObjectSpec(name=door.name, shape=door.shape, T_world_object=door.T_world_object,
                                present=windows, door=True))
        machines.append(MachineSpec(m.name, door.name, windows))
    return tuple(machines), tuple(doors)


def _tending_seams(parsed: CellFile, path: Path) -> tuple[SeamSpec, ...]:
    """The tending job as one ordered seam: every cycle's station visits in order, each a stop at
    the station's TCP pose (pinned, orientation as given) with the gripper's action as its dwell."""
    tending = parsed.tending
    assert tending is not None
    stations = _index_by_name([st.name for st in tending.stations], "station", "tending.stations", path)
    machines = {m.name for m in tending.machines}
    for i, st in enumerate(tending.stations):
        if st.machine is not None and st.machine not in machines:
            known = ", ".join(sorted(machines)) or "none"
            raise CellFileError(path, f"tending.stations[{i}].machine", f"unknown machine '{st.machine}' (machines: {known})")
    sequence = tending.sequence or [st.name for st in tending.stations]
    for j, name in enumerate(sequence):
        if name not in stations:
            raise CellFileError(path, f"tending.sequence[{j}]", f"unknown station '{name}' (stations: "
                                f"{', '.join(stations)})")
    spots = []
    for cycle in range(1, tending.cycles + 1):
        seen: dict[str, int] = {}
        for name in sequence:
            seen[name] = seen.get(name, 0) + 1
            st = tending.stations[stations[name]]
            R = pose_matrix([0.0, 0.0, 0.0], [deg_to_rad(a) for a in st.rpy])[:3, :3]
            visit = f"c{cycle}_{name}" + (f"_{seen[name]}" if seen[name] > 1 else "")
            spots.append(SpotSpec(
                name=visit, xyz=frozen_array(st.xyz), normal=frozen_array(-R[:, 2]), direction=frozen_array(R[:, 0]),
                weld_time=tending.gripper.grip if st.action == "grip" else tending.gripper.release,
                angles=(0.0, 0.0, 0.0), config=st.config, action=st.action, machine=st.machine,
                key=f"tending.stations[{stations[name]}]",
            ))
    return (SeamSpec(name=TENDING_SEAM, ordered=True, alpha_max=0.0, beta_max=0.0, gamma_range=(0.0, 0.0), grid=1,
                     spots=tuple(spots)),)


def _seams(parsed: CellFile, path: Path, problems: _Problems) -> tuple[SeamSpec, ...]:
    """The seams with their spots to weld: spots marked `skip` are left out, and so is a seam
    left without spots; a cell left without any is an error. Every seam is checked (`problems`
    keeps each refusal)."""
    before = len(problems.found)
    checked = [_seam(s, path, f"seams[{i}]", problems) for i, s in enumerate(parsed.seams)]
    seams = tuple(s for s in checked if s.spots)
    if not seams and len(problems.found) == before:     # not when spots were refused: those are the problem
        raise CellFileError(path, "seams", "every spot is marked skip: nothing to weld")
    return seams


def _seam(seam: SeamFile, path: Path, key: str, problems: _Problems) -> SeamSpec:
    spots = []
    for j, spot in enumerate(seam.spots):
        checked = None if spot.skip else problems.attempt(_spot, spot, seam.tolerance, path, f"{key}.spots[{j}]")
        if checked is not None:
            spots.append(checked)
    tol = seam.tolerance
    return SeamSpec(
        name=seam.name,
        ordered=seam.ordered,
        alpha_max=deg_to_rad(tol.alpha),
        beta_max=deg_to_rad(tol.beta),
        gamma_range=(deg_to_rad(tol.gamma[0]), deg_to_rad(tol.gamma[1])),
        grid=seam.grid,
        spots=tuple(spots),
    )


def _spot(spot: SpotFile, tol: ToleranceFile, path: Path, spot_key: str) -> SpotSpec:
    normal = _unit(spot.normal, path, f"{spot_key}.normal")
    direction = _unit(spot.direction, path, f"{spot_key}.direction")
    along = direction - np.dot(direction, normal) * normal
    if np.linalg.norm(along) < MIN_DIRECTION_SINE:
        raise CellFileError(path, f"{spot_key}.direction", f"parallel to the normal {spot.normal}: no seam direction")
    angles = None
    if spot.alpha is not None and spot.beta is not None and spot.gamma is not None:
        angles = (deg_to_rad(spot.alpha), deg_to_rad(spot.beta), deg_to_rad(spot.gamma))
        _check_pinned(spot, tol, path, spot_key)
    return SpotSpec(
        name=spot.name,
        xyz=frozen_array(spot.xyz),
        normal=frozen_array(normal),
        direction=frozen_array(along / np.linalg.norm(along)),
        weld_time=spot.weld_time, schedule=spot.schedule, angles=angles, config=spot.config,
    )


def _unit(v: list[float], path: Path, key: str) -> np.ndarray:
    arr = np.asarray(v, dtype=float)
    scale = float(np.max(np.abs(arr)))           # scaled first: the norm of [1e308, 1e308, 0] overflows
    if not 1e-9 <= scale <= 1e9:
        raise CellFileError(path, key, f"expected a direction (not zero-length, components at most 1e9), got {v}")
    arr = arr / scale
    return arr / float(np.linalg.norm(arr))


def read_cell_file(path: str | Path) -> CellFile:
    """A cell file as its checked schema (file units), for tools that rewrite cells: flat, its
    includes merged (their paths relative to the cell) and every pose in world coordinates
    (docs/frames.md), so what is written from it stands alone.

    Only the files themselves are checked here; `load_cell` checks what they name (robot, tool, meshes).
    """
    flat = _read_resolved(Path(path))[0].model_copy(update={"frames": [], "include": []})
    flat.__pydantic_fields_set__.difference_update({"frames", "include"})   # resolved: not written back
    return flat


def read_cell_frames(path: str | Path) -> tuple[tuple[FrameNode, ...], tuple[Path, ...]]:
    """The cell's frame tree (`io.frames.FrameNode`, file order) and the files it includes (reading order)."""
    _, tree, files = _read_resolved(Path(path))
    return tree, files


def _read_resolved(path: Path) -> tuple[CellFile, tuple[FrameNode, ...], tuple[Path, ...]]:
    data = read_yaml_mapping(path, CellFileError, "cell file", LIMITS.cell)
    expansion = expand_includes(data, path, IncludeFile)

    def parse() -> tuple[CellFile, tuple[FrameNode, ...]]:
        try:
            parsed = CellFile.model_validate(expansion.data)
        except ValidationError as exc:
            raise validation_error(exc, CellFile, path, CellFileError) from None
        return resolve_frames(parsed, path)

    parsed, tree = _located(expansion, parse)
    return parsed, tree, tuple(file for file, _ in expansion.files)


def dump_cell_file(cell: CellFile, header: str = "") -> str:
    """Cell-file text of a schema object: the keys that were set, in schema order; `header` as comments.

    Deterministic: the same object gives the same bytes. Lists of numbers are written inline.
    """
    import yaml

    data = cell.model_dump(mode="json", exclude_unset=True)
    comment = "".join(f"# {line}\n" if line else "#\n" for line in header.splitlines())
    text: str = yaml.safe_dump(data, sort_keys=False, default_flow_style=None, allow_unicode=True, width=120)
    return comment + text
