"""The cell file's schema: `CellFile`, one pydantic model per section of a cell file
(docs/cell-files.md, "A cell file"), and `IncludeFile`, what an included file may hold. The models
here are the robot and its controller, seams and spot lists, process, planner, frames and the
continuation; the value types their keys take and the limits on a cell's size are in
`cell_file_values`, the `dynamic` section in `cell_file_dynamic`, the tending and pick-and-place
jobs in `cell_file_jobs`. `io.cell` reads a file through these models and turns it into a checked
CellSpec; the modules that help it (frames, includes, warnings, spot lists) take these models
without importing the loader.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import (
    AfterValidator,
    Field,
    field_validator,
    model_validator,
)

from robomax_py.io.cell_file_dynamic import DynamicObjectFile
from robomax_py.io.cell_file_jobs import PickPlaceFile, TendingFile
from robomax_py.io.cell_file_values import (
    MAX_NAME_CHARS,
    MAX_WINDOW_S,
    CellName,
    Finite,
    Name,
    NonNegative,
    ObjectFile,
    Place,
    PoseFile,
    Reference,
    Vec3,
    WindowTime,
    _printable_name,
    _Strict,
)

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
    # The controller's software limits, narrower than the URDF's (a dress pack's hoses allow the
    # wrist less than the gear does): one [min, max] per joint, deg (m for a prismatic joint), null
    # for a joint the URDF's range holds.
    joint_limits: list[Annotated[list[Finite], Field(min_length=2, max_length=2)] | None] | None = None
    controller: RobotControllerFile = RobotControllerFile()


class ToleranceFile(_Strict):
    alpha: Annotated[float, Field(ge=0, le=90, allow_inf_nan=False)] = 0.0   # deg
    beta: Annotated[float, Field(ge=0, le=90, allow_inf_nan=False)] = 0.0    # deg
    gamma: Annotated[list[Annotated[float, Field(ge=-360, le=360, allow_inf_nan=False)]],
                     Field(min_length=2, max_length=2)] = [0.0, 0.0]          # deg
    # Extension (docs/cell-files.md): "either" lets the gun stand on either side of the sheet, the
    # planner choosing per spot (a C-gun's jaws reach both sides; the normal's sign is then a
    # preference only, as where a CAD export gives none).
    sides: Literal["normal", "either"] = "normal"

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
    xyz: Place
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
