"""Cell files (docs/cell-files.md, "A cell file") -> checked CellSpec in SI units.

The only module that knows cell-file keys. Every user mistake becomes one CellFileError naming the
file, the key path (e.g. `seams[0].spots[3].normal`) and the problem; nothing here prints.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import re
import stat
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, Literal, TypeVar

import numpy as np
from pydantic import (
    AfterValidator,
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
    field_validator,
    model_validator,
)

from robomax_py.errors import CellFileError, RobotModelError
from robomax_py.io.cell_lint import library_hint, lint_cell
from robomax_py.io.mesh_keys import (
    MESH_ONLY_KEYS,
    MeshScale,
    MeshTolerance,
    MeshUnits,
    mesh_shape,
    misplaced_mesh_keys,
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

T = TypeVar("T")
SUPPORTED_VERSIONS = (1,)
# A direction this close to parallel with the normal (sine of the angle) leaves no seam direction.
MIN_DIRECTION_SINE = 1e-3

Finite = Annotated[float, Field(allow_inf_nan=False)]
Positive = Annotated[float, Field(gt=0, allow_inf_nan=False)]
NonNegative = Annotated[float, Field(ge=0, allow_inf_nan=False)]
Vec3 = Annotated[list[Finite], Field(min_length=3, max_length=3)]
# Names end up in messages, program identifiers and (the cell's) file names: printable text of a
# bounded length; a cell name is also a file stem, so no path separators and at most 100 characters.
MAX_NAME_CHARS = 200
MAX_CELL_NAME_CHARS = 100
# The seam a tending job becomes (one ordered seam: the cycles' station visits).
TENDING_SEAM = "tending"
PICK_PLACE_SEAM = "transfers"
# Dynamic windows beyond a day of program time are a typo, and would overflow the time grid.
MAX_WINDOW_S = 86_400.0


@dataclass(frozen=True, slots=True)
class CellLimits:
    """The most one cell may ask for (docs/limits.md), checked at load
    before anything is planned: planning time and memory grow with each. A spot costs its seam's
    orientations x approach samples x IK columns of IK table and its candidates' approach lines;
    every object adds pairs to every collision check; triangles are held in memory as BVHs."""

    spots: int = 2_000                  # spots of all seams together (a robot welds tens per cycle)
    objects: int = 1_000                # objects and dynamic objects together
    orientations: int = 1_000           # per seam: its grid's orientations and its spots' pinned ones
    mesh_triangles: int = 2_000_000     # one mesh
    cell_triangles: int = 5_000_000     # every mesh of the cell and its tool together


CELL_LIMITS = CellLimits()
# A tolerance range this narrow is one orientation sample (as `plan.poses.axis_samples` takes it).
SAME_ORIENTATION_RAD = 1e-9


def _printable_name(v: str) -> str:
    if not v.strip():
        raise ValueError("must not be blank")
    bad = next((ch for ch in v if not ch.isprintable()), None)
    if bad is not None:
        raise ValueError(f"must be printable text, got the control character {bad!a}")
    return v


def _file_stem(v: str) -> str:
    _printable_name(v)
    if any(sep in v for sep in "/\\") or v in (".", ".."):
        raise ValueError(f"is the program's file name: no '/', '\\', '.' or '..', got {v!r}")
    return v


def _reference(v: str) -> str:
    """A robot or tool: a library name or a path; printable, and short enough for the file system."""
    _printable_name(v)
    if len(v) > 4096 or any(len(part.encode()) > 255 for part in v.replace("\\", "/").split("/")):
        raise ValueError("is longer than a file name or path can be")
    return v


Name = Annotated[str, Field(min_length=1, max_length=MAX_NAME_CHARS), AfterValidator(_printable_name)]
CellName = Annotated[str, Field(min_length=1, max_length=MAX_CELL_NAME_CHARS), AfterValidator(_file_stem)]
Reference = Annotated[str, Field(min_length=1), AfterValidator(_reference)]
WindowTime = Annotated[float, Field(ge=0, le=MAX_WINDOW_S, allow_inf_nan=False)]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True)


class PoseFile(_Strict):
    xyz: Vec3 = [0.0, 0.0, 0.0]      # m
    rpy: Vec3 = [0.0, 0.0, 0.0]      # deg


# Names a controller holds (RAPID data and signals, UR variables): identifiers of at most 32
# characters starting with a letter, the RAPID rule (RAPID reference, "Identifiers").
ControllerName = Annotated[str, Field(pattern=r"^[A-Za-z][A-Za-z0-9_]{0,31}$")]


class ControllerFrameFile(_Strict):
    number: Annotated[int, Field(ge=1, le=999)] | None = None
    name: ControllerName | None = None


class UserFrameFile(ControllerFrameFile):
    pose: PoseFile | None = None     # in the cell's world
    object: Name | None = None       # or at this object's pose

    @model_validator(mode="after")
    def _one_place(self) -> UserFrameFile:
        if (self.pose is None) == (self.object is None):
            raise ValueError("give exactly one of pose (in the cell's world) or object (at that object's pose)")
        return self


class InputFile(_Strict):
    number: Annotated[int, Field(ge=0, le=65535)]
    name: ControllerName | None = None


class RegistersFile(_Strict):
    position: list[Annotated[int, Field(ge=1, le=9999)]] = []
    numeric: list[Annotated[int, Field(ge=1, le=9999)]] = []

    @field_validator("position", "numeric")
    @classmethod
    def _unique(cls, v: list[int]) -> list[int]:
        repeated = sorted({r for r in v if v.count(r) > 1})
        if repeated:
            raise ValueError(f"register {repeated[0]} is listed twice")
        return v


class RobotControllerFile(_Strict):
    """The integrator's numbers on the robot's controller (docs/cell-extensions.md, "The integrator's numbers")."""

    tool: ControllerFrameFile | None = None
    frame: UserFrameFile | None = None
    registers: RegistersFile = RegistersFile()
    inputs: dict[Name, Annotated[int, Field(ge=0, le=65535)] | InputFile] = {}
    weld: Literal["call", "package"] = "call"


class RobotRefFile(_Strict):
    model: Reference
    base: PoseFile = PoseFile()
    home: list[Finite]               # deg (m for a prismatic joint)
    controller: RobotControllerFile = RobotControllerFile()


class CylinderFile(_Strict):
    radius: Positive
    length: Positive


class SphereFile(_Strict):
    radius: Positive


_SHAPE_KEYS = ("box", "cylinder", "sphere", "capsule", "mesh")


class ObjectFile(_Strict):
    name: Name
    box: Annotated[list[Positive], Field(min_length=3, max_length=3)] | None = None
    cylinder: CylinderFile | None = None
    sphere: SphereFile | None = None
    capsule: CylinderFile | None = None
    mesh: Reference | None = None
    units: MeshUnits | None = None      # of the mesh file's numbers (docs/cad.md)
    scale: MeshScale | None = None
    tolerance: MeshTolerance | None = None
    pose: PoseFile = PoseFile()
    workpiece: bool = False
    signal: Name | None = None          # extension: clamp interlock input (docs/cell-extensions.md)

    @model_validator(mode="after")
    def _one_shape(self) -> ObjectFile:
        given = [k for k in _SHAPE_KEYS if getattr(self, k) is not None]
        if len(given) != 1:
            got = ", ".join(given) if given else "none"
            raise ValueError(f"exactly one of {', '.join(_SHAPE_KEYS)} is required, got {got}")
        if (stray := misplaced_mesh_keys({k: getattr(self, k) for k in ("mesh", *MESH_ONLY_KEYS)})) is not None:
            raise ValueError(stray)
        return self


class DynamicObjectFile(ObjectFile):
    present: Annotated[list[Annotated[list[WindowTime], Field(min_length=2, max_length=2)]], Field(min_length=1)]

    @field_validator("signal")
    @classmethod
    def _no_signal(cls, v: str | None) -> str | None:
        if v is not None:
            raise ValueError("a dynamic object has no clamp signal (the program waits for <name>_clear instead)")
        return v

    @field_validator("present")
    @classmethod
    def _windows_in_order(cls, windows: list[list[float]]) -> list[list[float]]:
        for i, (t0, t1) in enumerate(windows):
            if not t0 < t1:
                raise ValueError(f"window {i} [{t0}, {t1}]: start must be before end")
            if i and t0 < windows[i - 1][1]:
                raise ValueError(f"window {i} starts at {t0}, before window {i - 1} ends at {windows[i - 1][1]}")
        return windows


class ToleranceFile(_Strict):
    alpha: Annotated[float, Field(ge=0, le=90, allow_inf_nan=False)] = 0.0   # deg
    beta: Annotated[float, Field(ge=0, le=90, allow_inf_nan=False)] = 0.0    # deg
    gamma: Annotated[list[Annotated[float, Field(ge=-360, le=360, allow_inf_nan=False)]],
                     Field(min_length=2, max_length=2)] = [0.0, 0.0]          # deg

    @field_validator("gamma")
    @classmethod
    def _range(cls, v: list[float]) -> list[float]:
        if v[0] > v[1]:
            raise ValueError(f"expected [min, max] with min <= max, got {v}")
        if v[1] - v[0] > 360:
            raise ValueError(f"range wider than 360 deg: {v}")
        return v


Angle = Annotated[float, Field(ge=-360, le=360, allow_inf_nan=False)]


class SpotFile(_Strict):
    name: Name
    xyz: Vec3
    normal: Vec3
    direction: Vec3
    # Extensions (docs/cell-extensions.md): per-spot process and pinned choices.
    weld_time: NonNegative | None = None
    schedule: Annotated[int, Field(ge=1, le=9999)] | None = None
    alpha: Angle | None = None
    beta: Angle | None = None
    gamma: Angle | None = None
    config: Annotated[str, Field(min_length=1, max_length=64)] | None = None
    skip: bool = False

    @model_validator(mode="after")
    def _pinned_together(self) -> SpotFile:
        given = [k for k in ("alpha", "beta", "gamma") if getattr(self, k) is not None]
        if given and len(given) != 3:
            missing = ", ".join(k for k in ("alpha", "beta", "gamma") if k not in given)
            raise ValueError(f"a pinned orientation needs alpha, beta and gamma; {missing} missing")
        return self


class SeamFile(_Strict):
    name: Name
    ordered: bool = False
    tolerance: ToleranceFile = ToleranceFile()
    grid: Annotated[int, Field(ge=1, le=64)] = 1
    spots: Annotated[list[SpotFile], Field(min_length=1)]


class ProcessFile(_Strict):
    weld_time: NonNegative = 0.5
    approach: NonNegative = 0.03
    clearance: NonNegative = 0.0
    # Extensions (docs/cell-extensions.md).
    gun: Annotated[int, Field(ge=1, le=99)] = 1
    schedule: Annotated[int, Field(ge=1, le=9999)] = 1
    interlock_distance: Annotated[float, Field(ge=0, le=10, allow_inf_nan=False)] = 0.2


class PlannerFile(_Strict):
    seed: Annotated[int, Field(ge=0)] = 0
    # Extensions (docs/cell-extensions.md): speeds the program states per move.
    speed: Annotated[float, Field(gt=0, le=1)] = 1.0
    tcp_speed: Annotated[float, Field(gt=0, le=2)] = 0.5
    detour_speed: Annotated[float, Field(gt=0, le=1)] = 1.0
    detours: Literal["roadmap", "cspace", "both"] = "both"
    dynamic: Literal["timed", "rest"] = "timed"
    max_wait: Annotated[float, Field(gt=0, le=MAX_WINDOW_S, allow_inf_nan=False)] = 600.0


# Tending cells (docs/cell-extensions.md, "Machine tending"): stations visited in a fixed order per cycle, machines
# whose doors are closed while they machine, on a fixed schedule.


class StationFile(_Strict):
    name: Name
    xyz: Vec3                                 # m, the TCP at the station
    rpy: Vec3 = [0.0, 0.0, 0.0]               # deg: the TCP frame there; the tool arrives and leaves along +z
    action: Literal["grip", "release"]
    machine: Name | None = None               # the machine whose door the station lies behind
    config: Annotated[str, Field(min_length=1, max_length=64)] | None = None


class ScheduleFile(_Strict):
    start: WindowTime = 0.0                   # s: the first machining starts (door closes)
    machining: Positive                       # s the door stays closed per part
    period: Positive                          # s from one machining start to the next
    count: Annotated[int, Field(ge=1, le=10_000)] | None = None   # machinings; default: the cycles

    @model_validator(mode="after")
    def _door_opens(self) -> ScheduleFile:
        if self.machining >= self.period:
            raise ValueError(f"machining {self.machining:g} s fills the period {self.period:g} s: the door never "
                             "opens, so the schedule can never be met")
        return self


class MachineFile(_Strict):
    name: Name
    door: ObjectFile                          # the door's shape and pose when closed
    schedule: ScheduleFile


class GripperFile(_Strict):
    grip: NonNegative = 0.5                   # s the gripper takes to close, at rest
    release: NonNegative = 0.5                # s to open


class TendingFile(_Strict):
    cycles: Annotated[int, Field(ge=1, le=1000)] = 1
    gripper: GripperFile = GripperFile()
    machines: list[MachineFile] = []
    stations: Annotated[list[StationFile], Field(min_length=1)]
    sequence: Annotated[list[Name], Field(min_length=1)] | None = None   # one cycle; default: the stations


# Pick-and-place cells (docs/cell-extensions.md, "Pick and place"): parts carried from location to location, each
# transfer a grip and a release; while held, a part moves with the TCP and is checked for collisions.


class TcpLimitsFile(_Strict):
    v: Positive                               # m/s, TCP speed
    a_T: Positive                             # m/s^2, tangential (along the path) acceleration
    a_R: Positive                             # m/s^2, radial (centripetal) acceleration
    j_T: Positive                             # m/s^3, rate of change of a_T
    j_R: Positive                             # m/s^3, rate of change of a_R


class PartFile(ObjectFile):
    mass: Annotated[float, Field(ge=0, allow_inf_nan=False)]          # kg
    grasp: PoseFile = PoseFile()              # the TCP in the part's frame while held
    limits: TcpLimitsFile | None = None       # TCP limits while this part is carried

    @model_validator(mode="after")
    def _no_placement(self) -> PartFile:
        if self.pose != PoseFile() or self.workpiece or self.signal is not None:
            raise ValueError("a part has no pose, workpiece or signal: its locations place it")
        return self


class LocationFile(_Strict):
    name: Name
    pose: PoseFile                            # the part's frame when it lies here
    support: list[Name] = []                  # objects the part rests on here (it may touch them)


class TransferFile(_Strict):
    part: Name
    from_: Annotated[Name, Field(alias="from")]
    to: Name


class PickPlaceFile(_Strict):
    gripper: GripperFile = GripperFile()
    unloaded: TcpLimitsFile | None = None     # TCP limits without a part
    parts: Annotated[list[PartFile], Field(min_length=1)]
    locations: Annotated[list[LocationFile], Field(min_length=2)]
    transfers: Annotated[list[TransferFile], Field(min_length=1, max_length=10_000)]


class CellFile(_Strict):
    robomax: int
    name: CellName | None = None
    robot: RobotRefFile
    tool: Reference
    objects: list[ObjectFile] = []
    seams: list[SeamFile] = []                # required unless the cell tends machines
    process: ProcessFile = ProcessFile()
    planner: PlannerFile = PlannerFile()
    dynamic: list[DynamicObjectFile] = []
    tending: TendingFile | None = None
    pick_place: PickPlaceFile | None = None


def load_cell(path: str | Path) -> CellSpec:
    """Read and check a cell file and the robot.yaml / tool.yaml / meshes it names.

    The robot's URDF is parsed for its kinematics (flange frame, joint limits for `robot.home`); link
    meshes are read later, by `load_cell_robot`.
    """
    path = Path(path)
    text = read_text(path, LIMITS.cell, CellFileError, "cell file")
    # Programs name the exact cell file they were planned from (their header).
    digest = hashlib.sha256(text.encode("utf-8")).hexdigest()
    early = count_items(text, (("seams", "*", "spots"), ("objects",), ("dynamic",)))
    if early is not None:                  # before the guarded reader composes what may be a very long list
        _refuse_counts(early[("seams", "*", "spots")], early[("objects",)] + early[("dynamic",)], path)
    data = read_yaml_mapping(path, CellFileError, "cell file", LIMITS.cell)
    return _cell_from_data(data, path, digest)


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
    digest = hashlib.sha256(json.dumps(plain, sort_keys=True, separators=(",", ":")).encode("utf-8")).hexdigest()
    stand_in = Path(base_dir) / MAPPING_FILE   # so that relative paths resolve against base_dir
    try:
        return _cell_from_data(plain, stand_in, digest)
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


def _cell_from_data(data: dict[str, Any], path: Path, digest: str) -> CellSpec:
    """The checked cell of a cell file's parsed YAML; `path` names it in messages and anchors its relative
    paths."""
    _check_counts(data, path)              # before validating: the data as read, aliases expanded
    version = data.get("robomax")
    if "robomax" in data and version not in SUPPORTED_VERSIONS:
        supported = ", ".join(str(v) for v in SUPPORTED_VERSIONS)
        raise CellFileError(path, "robomax", f"unsupported format version {version!r}; this robomax reads {supported}")
    try:
        parsed = CellFile.model_validate(data)
    except ValidationError as exc:
        raise validation_error(exc, CellFile, path, CellFileError) from None
    # Independent checks each run, and their errors are reported together (up to MAX_LISTED_PROBLEMS);
    # a check that needs what an earlier one refused waits until those are fixed.
    problems = _Problems(path)
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
    return dataclasses.replace(cell, notices=lint_cell(parsed, cell, path))


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

    def __init__(self, path: Path) -> None:
        self.path = path
        self.found: list[CellFileError] = []

    def attempt(self, check: Callable[..., T], *args: Any) -> T | None:
        """`check(*args)`, or None when it refuses the file (its error kept; raised at once when
        MAX_LISTED_PROBLEMS are kept: the rest of the file is not looked at)."""
        try:
            return check(*args)
        except CellFileError as exc:
            self.found.append(exc)
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
    """A cell file as its checked schema (file units, keys as written), for tools that rewrite cells.

    Only the file itself is checked here; `load_cell` checks what it names (robot, tool, meshes).
    """
    path = Path(path)
    data = read_yaml_mapping(path, CellFileError, "cell file", LIMITS.cell)
    try:
        return CellFile.model_validate(data)
    except ValidationError as exc:
        raise validation_error(exc, CellFile, path, CellFileError) from None


def dump_cell_file(cell: CellFile, header: str = "") -> str:
    """Cell-file text of a schema object: the keys that were set, in schema order; `header` as comments.

    Deterministic: the same object gives the same bytes. Lists of numbers are written inline.
    """
    import yaml

    data = cell.model_dump(mode="json", exclude_unset=True)
    comment = "".join(f"# {line}\n" if line else "#\n" for line in header.splitlines())
    text: str = yaml.safe_dump(data, sort_keys=False, default_flow_style=None, allow_unicode=True, width=120)
    return comment + text
