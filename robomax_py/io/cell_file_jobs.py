"""The job sections of a cell file that take the place of its seams: machine tending (`tending`)
and pick and place (`pick_place`), and the seam each becomes (docs/cell-extensions.md, "Machine
tending", "Pick and place"). `io.cell_jobs` turns them into that seam.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, field_validator, model_validator

from robomax_py.io.cell_file_values import (
    Name,
    NonNegative,
    ObjectFile,
    Place,
    PoseFile,
    Positive,
    Vec3,
    Window,
    WindowTime,
    _Strict,
    _windows_in_order,
)

# The seam a tending job becomes (one ordered seam: the cycles' station visits).
TENDING_SEAM = "tending"
PICK_PLACE_SEAM = "transfers"


# Tending cells (docs/cell-extensions.md, "Machine tending"): stations visited in a fixed order per cycle, machines
# whose doors are closed while they machine, on a fixed schedule.


class StationFile(_Strict):
    name: Name
    xyz: Place                                # m, the TCP at the station
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
