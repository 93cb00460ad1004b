"""The cell file's schema: one pydantic model per section of a cell file (docs/cell-files.md, "A
cell file"), the value types its keys take, and the limits on its size. `io.cell` reads a file
through these models and turns it into a checked CellSpec; the modules that help it (frames,
includes, warnings, spot lists) take these models without importing the loader.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated, Literal, TypeVar

from pydantic import (
    AfterValidator,
    BaseModel,
    ConfigDict,
    Field,
    field_validator,
    model_validator,
)

from robomax_py.io.mesh_keys import (
    MESH_ONLY_KEYS,
    MeshScale,
    MeshTolerance,
    MeshUnits,
    misplaced_mesh_keys,
)

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


class OutputFile(_Strict):
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
    # The signals this robot sets for the others of a station (interlocks), as inputs are given.
    outputs: dict[Name, Annotated[int, Field(ge=0, le=65535)] | OutputFile] = {}


class RobotRefFile(_Strict):
    model: Reference
    base: PoseFile = PoseFile()
    frame: Name | None = None        # base given in this frame (docs/frames.md); default: the world
    home: list[Finite]               # deg (m for a prismatic joint)
    # Where the program starts, at rest, when not at home (a continuation, `robomax replan`); it
    # still ends at home. Checked as home is.
    start: list[Finite] | None = None
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
    frame: Name | None = None           # pose given in this frame (docs/frames.md); default: the world
    workpiece: bool = False
    signal: Name | None = None          # extension: clamp interlock input (docs/cell-extensions.md)

    @model_validator(mode="after")
    def _one_shape(self) -> ObjectFile:
        _check_one_shape(self)
        return self


def _check_one_shape(obj: ObjectFile) -> None:
    given = [k for k in _SHAPE_KEYS if getattr(obj, k) is not None]
    if len(given) != 1:
        got = ", ".join(given) if given else "none"
        raise ValueError(f"exactly one of {', '.join(_SHAPE_KEYS)} is required, got {got}")
    if (stray := misplaced_mesh_keys({k: getattr(obj, k) for k in ("mesh", *MESH_ONLY_KEYS)})) is not None:
        raise ValueError(stray)


class PathPoseFile(_Strict):
    """One timed pose of a moving object (`dynamic[i].path`), in the world frame."""

    t: WindowTime                             # s from program start
    xyz: Vec3                                 # m
    rpy: Vec3 = [0.0, 0.0, 0.0]               # deg


class OtherRobotFile(_Strict):
    """Another robot in the cell (`dynamic[i].robot`): which one, where it stands, its tool."""

    model: Reference                          # folder name in robots/, or a path to a robot.yaml
    base: PoseFile = PoseFile()
    tool: Reference | None = None             # folder name in robots/tools/, or a path to a tool.yaml


# m: how far a moving object may move within the time one of its sampled poses stands for (world.moving)
Sweep = Annotated[float, Field(gt=0, le=0.2, allow_inf_nan=False)]


Window = Annotated[list[WindowTime], Field(min_length=2, max_length=2)]


def _windows_in_order(windows: list[list[float]] | None) -> list[list[float]] | None:
    for i, (t0, t1) in enumerate(windows or ()):
        assert windows is not None
        if not t0 < t1:
            raise ValueError(f"window {i} [{t0}, {t1}]: start must be before end")
        if i and t0 < windows[i - 1][1]:
            raise ValueError(f"window {i} starts at {t0}, before window {i - 1} ends at {windows[i - 1][1]}")
    return windows


class DynamicObjectFile(ObjectFile):
    present: Annotated[list[Window], Field(min_length=1)] | None = None
    # Extensions (docs/cell-extensions.md, "Moving objects"): a rigid object carried along timed
    # poses, or another robot replaying a trajectory file.
    path: Annotated[list[PathPoseFile], Field(min_length=2, max_length=10_000)] | None = None
    repeat: Positive | None = None            # s between passes of the path (a conveyor's next part)
    count: Annotated[int, Field(ge=1, le=10_000)] | None = None   # passes; default: the tending cycles, else 1
    robot: OtherRobotFile | None = None
    trajectory: Reference | None = None       # a robomax.trajectory/1 file, relative to this file
    sweep: Sweep | None = None                # m; default 0.02

    @model_validator(mode="after")
    def _one_shape(self) -> DynamicObjectFile:
        if self.robot is None:
            _check_one_shape(self)
            if self.trajectory is not None:
                raise ValueError("trajectory: only with robot (another robot replaying it)")
        else:
            given = [k for k in (*_SHAPE_KEYS, *MESH_ONLY_KEYS, "path", "repeat", "count") if getattr(self, k) is not None]
            if given or self.pose != PoseFile() or self.frame is not None or self.workpiece:
                raise ValueError(f"a robot has no {', '.join(given) or 'pose, frame or workpiece'}: its links are its "
                                 "shape, robot.base its place, the trajectory its motion")
            if self.trajectory is None:
                raise ValueError("trajectory: required with robot (a robomax.trajectory/1 file)")
        if self.path is not None and (self.pose != PoseFile() or self.frame is not None):
            raise ValueError("pose, frame: not with path (the path's poses place it, in the world frame)")
        if self.path is None and self.robot is None:
            if self.present is None:
                raise ValueError("present: required (the windows in which the object is there), unless it moves "
                                 "(path or robot)")
            extra = [k for k in ("repeat", "count", "sweep") if getattr(self, k) is not None]
            if extra:
                raise ValueError(f"{', '.join(extra)}: only for a moving object (path)")
        if self.count is not None and self.repeat is None:
            raise ValueError("count: only with repeat (the number of passes)")
        if self.repeat is not None and self.present is not None:
            raise ValueError("present: not with repeat (each pass is there from its first to its last pose)")
        return self

    @field_validator("path")
    @classmethod
    def _times_increase(cls, poses: list[PathPoseFile] | None) -> list[PathPoseFile] | None:
        for i in range(1, len(poses or ())):
            assert poses is not None
            if not poses[i].t > poses[i - 1].t:
                raise ValueError(f"[{i}].t = {poses[i].t:g} s: times must increase strictly "
                                 f"(after {poses[i - 1].t:g} s)")
        return poses

    @field_validator("signal")
    @classmethod
    def _no_signal(cls, v: str | None) -> str | None:
        if v is not None:
            raise ValueError("a dynamic object has no clamp signal (the program waits for <name>_clear instead)")
        return v

    @field_validator("present")
    @classmethod
    def _present_in_order(cls, windows: list[list[float]] | None) -> list[list[float]] | None:
        return _windows_in_order(windows)


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
    frame: Name | None = None           # xyz, normal, direction in this frame; default: the seam's

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
    frame: Name | None = None           # the frame of its spots (docs/frames.md); default: the world
    spots: Annotated[list[SpotFile], Field(min_length=1)]


class SpotListFile(_Strict):
    """A CSV spot list whose spots become seams (docs/spot-lists.md)."""

    file: Reference                           # relative to the cell file
    part: Name                                # the object whose frame the list's coordinates are in
    units: Literal["m", "mm"]                 # of the list's coordinates: a file read again and again does not guess
    frame: Name | None = None                 # the frame the coordinates are in, when not the part's (docs/frames.md)
    max_distance: Annotated[float, Field(gt=0, le=1, allow_inf_nan=False)] = 0.002   # m from the part's surface
    ordered: bool = False                     # of every seam the list gives
    tolerance: ToleranceFile = ToleranceFile()
    grid: Annotated[int, Field(ge=1, le=64)] = 1


class ProcessFile(_Strict):
    weld_time: NonNegative = 0.5
    approach: NonNegative = 0.03
    clearance: NonNegative = 0.0
    # Extensions (docs/cell-extensions.md).
    gun: Annotated[int, Field(ge=1, le=99)] = 1
    schedule: Annotated[int, Field(ge=1, le=9999)] = 1
    interlock_distance: Annotated[float, Field(ge=0, le=10, allow_inf_nan=False)] = 0.2


class LearnedMapFile(_Strict):
    """The learned C-space map of `planner.detours: learned` (docs/learned-cspace.md)."""

    # The map has resolution^3 cells and ~26 edges each: 60 keeps its graph near 150 MB.
    resolution: Annotated[int, Field(ge=8, le=60)] = 40
    spacing: Annotated[float, Field(ge=0.02, le=1.0, allow_inf_nan=False)] = 0.1      # m between surface points
    inflation: Annotated[float, Field(ge=0, le=0.5, allow_inf_nan=False)] = 0.06     # m
    training: Literal["standard", "coarse"] = "coarse"
    neurons: Annotated[int, Field(ge=2, le=1000)] | None = None


class PlannerFile(_Strict):
    seed: Annotated[int, Field(ge=0)] = 0
    # Extensions (docs/cell-extensions.md): speeds the program states per move.
    speed: Annotated[float, Field(gt=0, le=1)] = 1.0
    tcp_speed: Annotated[float, Field(gt=0, le=2)] = 0.5
    detour_speed: Annotated[float, Field(gt=0, le=1)] = 1.0
    detours: Literal["roadmap", "cspace", "both", "learned"] = "both"
    detour_moves: Literal["ptp", "lin"] = "ptp"
    # KSS caps a LIN's $VEL.CP at 2 m/s (export.krl), as it does the approach lines' `tcp_speed`.
    detour_tcp_speed: Annotated[float, Field(gt=0, le=2)] = 1.0
    learned: LearnedMapFile = LearnedMapFile()
    dynamic: Literal["timed", "rest"] = "timed"
    max_wait: Annotated[float, Field(gt=0, le=MAX_WINDOW_S, allow_inf_nan=False)] = 600.0
    transfers: Literal["moves", "associative"] = "moves"
    # "spline": a junction's retract, move or detour and approach as one smooth Bézier TCP path
    # (`plan.spline_junction`) where that is faster than the lines and joint moves with fly-by.
    cartesian_moves: Literal["lin", "spline"] = "lin"


# Tending cells (docs/cell-extensions.md, "Machine tending"): stations visited in a fixed order per cycle, machines
# whose doors are closed while they machine, on a fixed schedule.


class StationFile(_Strict):
    name: Name
    xyz: Vec3                                 # m, the TCP at the station
    rpy: Vec3 = [0.0, 0.0, 0.0]               # deg: the TCP frame there; the tool arrives and leaves along +z
    action: Literal["grip", "release"]
    machine: Name | None = None               # the machine whose door the station lies behind
    config: Annotated[str, Field(min_length=1, max_length=64)] | None = None
    frame: Name | None = None                 # xyz, rpy in this frame (docs/frames.md); default: the world


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
    schedule: ScheduleFile | None = None
    # Or the door's closed windows as they are (s from program start), when they keep no period
    # (a machine running late: `robomax replan` writes them so); [] the door never closes.
    windows: list[Window] | None = None

    @model_validator(mode="after")
    def _one_timing(self) -> MachineFile:
        if (self.schedule is None) == (self.windows is None):
            raise ValueError("give exactly one of schedule (a fixed period) or windows (the door's closed windows)")
        return self

    @field_validator("windows")
    @classmethod
    def _ordered(cls, windows: list[list[float]] | None) -> list[list[float]] | None:
        return _windows_in_order(windows)


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
        if self.pose != PoseFile() or self.frame is not None or self.workpiece or self.signal is not None:
            raise ValueError("a part has no pose, frame, workpiece or signal: its locations place it")
        return self


class LocationFile(_Strict):
    name: Name
    pose: PoseFile                            # the part's frame when it lies here
    frame: Name | None = None                 # pose given in this frame (docs/frames.md); default: the world
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


class FrameFile(_Strict):
    """A named frame (docs/frames.md): its pose in its parent, the world or another frame or object."""

    name: Name
    pose: PoseFile = PoseFile()
    parent: Name | None = None                # default: the world


class ContinuationFile(_Strict):
    """The cell a program's continuation runs in (`robomax replan` writes it; docs/cell-files.md,
    "Continuations"): every time in the file is in the clock of the program continued, which this
    one takes up at `at`; the actions that program had done are left out."""

    cell: Name | None = None                  # the cell whose program this continues (for people)
    at: WindowTime                            # s of that program's clock at which this one starts
    done: list[Annotated[str, Field(min_length=1, max_length=2 * MAX_NAME_CHARS + 1)]] = []   # `seam/spot`


IncludePath = Annotated[str, Field(min_length=1, max_length=4096), AfterValidator(_printable_name)]


class CellFile(_Strict):
    robomax: int
    name: CellName | None = None
    include: list[IncludePath] = []           # merged before anything else is read (io.includes)
    frames: list[FrameFile] = []
    robot: RobotRefFile
    tool: Reference
    objects: list[ObjectFile] = []
    seams: list[SeamFile] = []                # required unless the cell tends machines
    spot_lists: list[SpotListFile] = []       # seams read from CSV spot lists, after `seams`
    process: ProcessFile = ProcessFile()
    planner: PlannerFile = PlannerFile()
    dynamic: list[DynamicObjectFile] = []
    tending: TendingFile | None = None
    pick_place: PickPlaceFile | None = None
    continuation: ContinuationFile | None = None


class IncludeFile(_Strict):
    """What a file a cell includes may hold (docs/frames.md, "Includes"): lists merged into the
    including cell's, a robot and tool given once in the whole tree, further includes."""

    robomax: int | None = None
    include: list[IncludePath] = []
    frames: list[FrameFile] = []
    robot: RobotRefFile | None = None
    tool: Reference | None = None
    objects: list[ObjectFile] = []
    dynamic: list[DynamicObjectFile] = []
    seams: list[SeamFile] = []
