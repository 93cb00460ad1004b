"""The values a program is made of: header, frame definitions, instructions and what its writer may
use, each float rounded when the value is built to the decimals the program files carry (the table
in `program`)."""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Literal, TypeAlias

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.transforms import pose_matrix

JOINT_DECIMALS = 4   # deg
MM_DECIMALS = 3      # mm
ANGLE_DECIMALS = 4   # deg (ZYX orientation angles)
SPEED_DECIMALS = 3   # PTP fractions and LIN mm/s
TIME_DECIMALS = 3    # s
# A fly-by stated as a TCP distance, mm: finer than positions, since a move that hardly displaces
# the TCP states a joint-space radius of degrees in a fraction of a millimetre.
FLYBY_MM_DECIMALS = 6

FrameKind: TypeAlias = Literal["tool", "base"]
# A LIN's part in a spline block: none, a spline point, a straight segment (`LinMove.spline`).
SplineSegment: TypeAlias = Literal["", "spl", "slin"]
# A LIN's tool or base: the controller's null frame (flange / robot base frame), or none selected.
NULL_FRAME = ""
UNSET_FRAME = "?"


def _fixed(value: float, decimals: int) -> float:
    """`value` rounded to `decimals` places; -0.0 becomes 0.0, NaN and inf pass through."""
    x = float(value)
    if not math.isfinite(x):
        return x
    return round(x, decimals) + 0.0


def _fixed_all(values: Iterable[float], decimals: int) -> tuple[float, ...]:
    return tuple(_fixed(v, decimals) for v in values)


def _set(obj: object, name: str, value: object) -> None:
    object.__setattr__(obj, name, value)


@dataclass(frozen=True, slots=True)
class Header:
    """What the program is for.

    Attributes
    ----------
    cell, robot, tool : str
        Names of the cell, robot model and tool.
    cycle_time_s : float
        Planned cycle time, s (3 decimals).
    joints : tuple[str, ...]
        Joint names in controller order; every `PtpMove` gives one value per joint.
    generator : str
        What wrote the program and its version ("robomax_py 0.1.0"); "" when not stated.
    cell_sha256 : str
        SHA-256 (hex) of the cell file's bytes the program was planned from; "" when not stated.
    stamp : str
        The date of writing, only when asked for (`plan --stamp`); "" keeps programs byte-identical.
    """

    cell: str
    robot: str
    tool: str
    cycle_time_s: float
    joints: tuple[str, ...]
    generator: str = ""
    cell_sha256: str = ""
    stamp: str = ""

    def __post_init__(self) -> None:
        _set(self, "cycle_time_s", _fixed(self.cycle_time_s, TIME_DECIMALS))
        _set(self, "joints", tuple(str(j) for j in self.joints))


@dataclass(frozen=True, slots=True)
class FrameDef:
    """A tool or user frame whose value the program's files state (docs/cell-files.md, "Controller programs").

    Attributes
    ----------
    name : str
        How the program refers to it (a LIN's `tool` / `base`): a RAPID data name, a KRL
        `TOOL_DATA[n]`, a FANUC `UTOOL[n]` ...; each dialect names them its own way.
    kind : {"tool", "base"}
        "tool": the TCP in the flange frame; "base": a user frame (KUKA base, ABB work object,
        FANUC user frame) in the controller's robot base frame. Targets relative to it.
    xyz_mm : (3,) tuple of float
        Origin, mm (3 decimals).
    zyx_deg : (3,) tuple of float
        Orientation as ZYX angles (A, B, C), deg (4 decimals).
    number : int
        The controller's slot for it (KUKA TOOL_DATA / BASE_DATA, FANUC UTOOL / UFRAME); 0: none.
    in_world : bool
        A user frame stated relative to the controller's world frame (KUKA `$WORLD`), which the
        integrator places away from the robot base on a tilted mount (`$ROBROOT`,
        `export.mount`); False: in the robot base frame itself. Set by the readers and adapters of
        the dialects whose frames are so stated (KRL).
    """

    name: str
    kind: FrameKind
    xyz_mm: tuple[float, ...]
    zyx_deg: tuple[float, ...]
    number: int = 0
    in_world: bool = False

    def __post_init__(self) -> None:
        _set(self, "xyz_mm", _fixed_all(self.xyz_mm, MM_DECIMALS))
        _set(self, "zyx_deg", _fixed_all(self.zyx_deg, ANGLE_DECIMALS))

    @property
    def pose(self) -> FloatArray:
        """The frame as a (4, 4) pose, m."""
        return lin_pose(LinMove(self.xyz_mm, self.zyx_deg))


@dataclass(frozen=True, slots=True)
class PtpMove:
    """Joint-interpolated move.

    Attributes
    ----------
    target_deg : (n_joints,) tuple of float
        Joint values, deg (4 decimals); mm for a prismatic joint (a track), which the robot's joint
        kinds tell (`program.ptp_target`).
    speed, accel : float
        Fractions of the maximum joint speed / acceleration, in (0, 1] (3 decimals).
    flyby : float
        Fly-by radius, deg (4 decimals): pass the target without stopping, leaving the programmed
        path within this joint-space distance (Euclidean over the joint values) of the target and
        joining the next move; 0 stops exactly.
    comment : str
        Note carried with the move; surrounding whitespace is stripped; "" for none.
    flyby_mm : float
        The fly-by stated as a TCP distance instead, mm (6 decimals), as KRL `C_DIS`, RAPID
        zones and URScript `r` state it: the joint-space radius is this distance times the
        move's joint-to-TCP chord ratio (`timing.chain`). At most one of the two is non-zero.
    """

    target_deg: tuple[float, ...]
    speed: float = 1.0
    accel: float = 1.0
    flyby: float = 0.0
    comment: str = ""
    flyby_mm: float = 0.0

    def __post_init__(self) -> None:
        _set(self, "target_deg", _fixed_all(self.target_deg, JOINT_DECIMALS))
        _set(self, "speed", _fixed(self.speed, SPEED_DECIMALS))
        _set(self, "accel", _fixed(self.accel, SPEED_DECIMALS))
        _set(self, "flyby", _fixed(self.flyby, ANGLE_DECIMALS))
        _set(self, "comment", str(self.comment).strip())
        _set(self, "flyby_mm", _fixed(self.flyby_mm, FLYBY_MM_DECIMALS))

    @property
    def flies(self) -> bool:
        """Whether the move passes its target without stopping."""
        return self.flyby > 0 or self.flyby_mm > 0


@dataclass(frozen=True, slots=True)
class LinMove:
    """Straight-line TCP move.

    Attributes
    ----------
    position_mm : (3,) tuple of float
        TCP position in the base frame, mm (3 decimals).
    zyx_deg : (3,) tuple of float
        TCP orientation as ZYX angles (A, B, C), deg (4 decimals).
    config : str
        Arm configuration (status and turn), e.g. "S010 T101010"; "" for none.
    speed_mm_s : float
        TCP path speed, mm/s, > 0 (3 decimals).
    flyby : float
        As for `PtpMove` (deg, joint space; 0 stops exactly).
    comment : str
    flyby_mm : float
        As for `PtpMove` (mm of TCP distance).
    accel : float
        Fraction in (0, 1] of the joint acceleration (and jerk) limits the line may use, as a PTP
        move's (3 decimals): a part in the gripper slows the lines that carry it too.
    tool, base : str
        The tool and the user frame in force for this target, as the controller has them when it
        executes the move: names of `FrameDef`s (of the program, or stored on the controller).
        `NULL_FRAME` is the controller's null frame (the flange; the robot base frame itself);
        `UNSET_FRAME`: the program did not select one (the controller keeps whatever was active).
    spline : {"", "spl", "slin"}
        "": a LIN of its own. Otherwise a segment of a spline block (a run of consecutive moves
        with `spline` set; KRL `SPLINE ... ENDSPLINE`): "spl" a spline point the path passes
        through smoothly, "slin" a straight segment (`curve_move`, `space_bezier`).
    """

    position_mm: tuple[float, ...]
    zyx_deg: tuple[float, ...]
    config: str = ""
    speed_mm_s: float = 250.0
    flyby: float = 0.0
    comment: str = ""
    flyby_mm: float = 0.0
    accel: float = 1.0
    tool: str = NULL_FRAME
    base: str = NULL_FRAME
    spline: SplineSegment = ""

    def __post_init__(self) -> None:
        _set(self, "position_mm", _fixed_all(self.position_mm, MM_DECIMALS))
        _set(self, "zyx_deg", _fixed_all(self.zyx_deg, ANGLE_DECIMALS))
        _set(self, "config", str(self.config))
        _set(self, "speed_mm_s", _fixed(self.speed_mm_s, SPEED_DECIMALS))
        _set(self, "flyby", _fixed(self.flyby, ANGLE_DECIMALS))
        _set(self, "comment", str(self.comment).strip())
        _set(self, "flyby_mm", _fixed(self.flyby_mm, FLYBY_MM_DECIMALS))
        _set(self, "accel", _fixed(self.accel, SPEED_DECIMALS))

    @property
    def flies(self) -> bool:
        """Whether the move passes its target without stopping."""
        return self.flyby > 0 or self.flyby_mm > 0


@dataclass(frozen=True, slots=True)
class Spot:
    """Weld spot `name` of seam `seam` at the current point, holding for `time_s` s (3 decimals),
    with weld gun `gun` and weld schedule `schedule`.

    package : the weld is the controller's process package instruction (FANUC SPOT[], ABB SpotL,
        KUKA's spot technology): the program names gun and schedule only, the weld time is the
        schedule's on the controller, and `time_s` is 0 (the cell's schedule gives it back).
    """

    name: str
    seam: str
    time_s: float
    gun: int = 1
    schedule: int = 1
    package: bool = False

    def __post_init__(self) -> None:
        _set(self, "time_s", _fixed(self.time_s, TIME_DECIMALS))


@dataclass(frozen=True, slots=True)
class Gripper:
    """The gripper's action at rest at station `name` of job `seam` (tending cells): close ("grip")
    or open ("release"), taking `time_s` s (3 decimals)."""

    action: Literal["grip", "release"]
    name: str
    seam: str
    time_s: float

    def __post_init__(self) -> None:
        _set(self, "time_s", _fixed(self.time_s, TIME_DECIMALS))


@dataclass(frozen=True, slots=True)
class Wait:
    """Dwell for `seconds` s (3 decimals), >= 0."""

    seconds: float

    def __post_init__(self) -> None:
        _set(self, "seconds", _fixed(self.seconds, TIME_DECIMALS))


@dataclass(frozen=True, slots=True)
class WaitFor:
    """Block until an input is set: the cell's signal `signal`, on the controller's input `number`
    (KUKA $IN, FANUC DI, UR standard digital input); None where the program names the signal only
    (SRCL, RAPID's named signals)."""

    signal: str
    number: int | None = None


@dataclass(frozen=True, slots=True)
class SetSignal:
    """Switch an output: the cell's signal `signal` on (`value` True) or off, on the controller's
    output `number` (KUKA $OUT, FANUC DO, UR standard digital output); None where the program names
    the signal only (SRCL, RAPID's named signals). Robots of a station tell each other with it that
    a shared zone is clear: another robot's `WaitFor` of the same signal name waits for it."""

    signal: str
    number: int | None
    value: bool


@dataclass(frozen=True, slots=True)
class Comment:
    """A line of text for the reader; surrounding whitespace is stripped."""

    text: str

    def __post_init__(self) -> None:
        _set(self, "text", str(self.text).strip())


Instruction: TypeAlias = PtpMove | LinMove | Spot | Gripper | Wait | WaitFor | SetSignal | Comment


@dataclass(frozen=True, slots=True)
class ToolLoad:
    """The mounted tool's load (tool.yaml `load`): its mass, kg, and its centre of gravity in the
    flange frame, m; a point mass (no inertia is stated)."""

    mass: float
    cog: tuple[float, float, float]


@dataclass(frozen=True, slots=True)
class ProgramSetup:
    """What the controller's integrator hands a program (the cell's `robot.controller`), for the
    writers: the position and numeric registers it may use (FANUC), whether a weld calls the
    program's own `spot_weld` routine ("call") or the controller's process package ("package"),
    frames a setup file lists for the integrator to enter by hand (`listed`: FANUC without position
    registers to set them from), and the controller's own names of the numbered frames the program
    selects, by the name the program refers to them with (`frame_names`: KUKA TOOL_NAME / BASE_NAME,
    which inline forms show), and the tool's load where the tool file states one (`tool_load`, for
    the dialects that declare it: RAPID tooldata, URScript set_payload), and whether the robot is
    mounted tilted (`tilted_mount`: ceiling, wall; `export.mount`), which KRL states its base frames
    for. Nothing of it is read back: the statements say what they use."""

    position_registers: tuple[int, ...] = ()
    numeric_registers: tuple[int, ...] = ()
    weld: Literal["call", "package"] = "call"
    listed: tuple[FrameDef, ...] = ()
    frame_names: tuple[tuple[str, str], ...] = ()
    tool_load: ToolLoad | None = None
    tilted_mount: bool = False


@dataclass(frozen=True, slots=True)
class Program:
    """A complete program: header, frame definitions and the instruction list, in order, and
    what its writer may use on the controller (`setup`, not part of the text's meaning)."""

    name: str
    header: Header
    frames: tuple[FrameDef, ...] = ()
    instructions: tuple[Instruction, ...] = ()
    setup: ProgramSetup = ProgramSetup()

    def __post_init__(self) -> None:
        _set(self, "frames", tuple(self.frames))
        _set(self, "instructions", tuple(self.instructions))


def lin_pose(move: LinMove) -> FloatArray:
    """The TCP pose a LIN move states, (4, 4) in m."""
    a, b, c = np.deg2rad(np.asarray(move.zyx_deg, dtype=float))
    return pose_matrix(np.asarray(move.position_mm, dtype=float) / 1000.0, [c, b, a])
