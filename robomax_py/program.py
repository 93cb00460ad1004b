"""A robot program as values, independent of any controller dialect.

An exporter turns a `Program` into text (`export/srcl/`) and a parser turns text back into one
(`parse_program`, both in `export/srcl/`). Every float is rounded *when the value is built* to the fixed number of
decimals the program files carry, so ``parse(write(p)) == p`` holds exactly:

=================================  =========  ========
quantity                           unit       decimals
=================================  =========  ========
joint values (`PtpMove.target_deg`)  deg        4
fly-by radii (joint space)         deg        4
positions, frame offsets           mm         3
ZYX orientation angles             deg        4
PTP speed / acceleration           fraction   3
LIN speed                          mm/s       3
weld, wait and cycle times         s          3
=================================  =========  ========

Rounding is Python's correctly rounded `round` (half-even on the exact binary value), which agrees
digit for digit with ``f"{x:.{n}f}"``; ``-0.0`` is stored as ``0.0``. Non-finite values are kept as
they are (the writer rejects them), and nothing is range-checked here: `find_problem` says what is
wrong with a value, and the writer (`ExportError`) and parser (`ProgramError`) report it.

Orientations are ZYX angles ``(a, b, c)`` in degrees, R = Rz(a)·Ry(b)·Rx(c), as KUKA's A, B, C.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Literal, TypeAlias

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.transforms import invert, pose_matrix, rpy_from_matrix

__all__ = [
    "ANGLE_DECIMALS",
    "JOINT_DECIMALS",
    "MM_DECIMALS",
    "NULL_FRAME",
    "SPEED_DECIMALS",
    "TIME_DECIMALS",
    "UNSET_FRAME",
    "Comment",
    "FrameDef",
    "Gripper",
    "Header",
    "Instruction",
    "LinMove",
    "Program",
    "ProgramSetup",
    "PtpMove",
    "Spot",
    "Wait",
    "WaitFor",
    "as_written_joints",
    "as_written_pose",
    "find_problem",
    "frame_in_world",
    "from_frame",
    "lin_pose",
    "pose_mm_zyx",
    "ptp_target",
    "to_frame",
    "written_seconds",
    "written_speed",
    "written_tcp_speed",
]

JOINT_DECIMALS = 4   # deg
MM_DECIMALS = 3      # mm
ANGLE_DECIMALS = 4   # deg (ZYX orientation angles)
SPEED_DECIMALS = 3   # PTP fractions and LIN mm/s
TIME_DECIMALS = 3    # s
# A fly-by stated as a TCP distance, mm: finer than positions, since a move that hardly displaces
# the TCP states a joint-space radius of degrees in a fraction of a millimetre.
FLYBY_MM_DECIMALS = 6

FrameKind: TypeAlias = Literal["tool", "base"]
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
    """

    name: str
    kind: FrameKind
    xyz_mm: tuple[float, ...]
    zyx_deg: tuple[float, ...]
    number: int = 0

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
        Joint values, deg (4 decimals).
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
class Comment:
    """A line of text for the reader; surrounding whitespace is stripped."""

    text: str

    def __post_init__(self) -> None:
        _set(self, "text", str(self.text).strip())


Instruction: TypeAlias = PtpMove | LinMove | Spot | Gripper | Wait | WaitFor | Comment


@dataclass(frozen=True, slots=True)
class ProgramSetup:
    """What the controller's integrator hands a program (the cell's `robot.controller`), for the
    writers: the position and numeric registers it may use (FANUC), whether a weld calls the
    program's own `spot_weld` routine ("call") or the controller's process package ("package"),
    frames a setup file lists for the integrator to enter by hand (`listed`: FANUC without position
    registers to set them from), and the controller's own names of the numbered frames the program
    selects, by the name the program refers to them with (`frame_names`: KUKA TOOL_NAME / BASE_NAME,
    which inline forms show). Nothing of it is read back: the statements say what they use."""

    position_registers: tuple[int, ...] = ()
    numeric_registers: tuple[int, ...] = ()
    weld: Literal["call", "package"] = "call"
    listed: tuple[FrameDef, ...] = ()
    frame_names: tuple[tuple[str, str], ...] = ()


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


def _finite(label: str, values: tuple[float, ...]) -> str | None:
    for v in values:
        if not math.isfinite(v):
            return f"{label} must be finite, got {v}"
    return None


def _triple(label: str, values: tuple[float, ...]) -> str | None:
    if len(values) != 3:
        return f"{label} needs 3 values, got {len(values)}"
    return _finite(label, values)


def _flyby_problem(move: PtpMove | LinMove) -> str | None:
    problem = _finite("fly-by radius", (move.flyby, move.flyby_mm))
    if problem:
        return problem
    if move.flyby < 0 or move.flyby_mm < 0:
        return f"fly-by radius {min(move.flyby, move.flyby_mm):.4f} is negative"
    if move.flyby > 0 and move.flyby_mm > 0:
        return "a fly-by is stated both as a joint-space radius and as a TCP distance"
    return None


def find_problem(item: Header | FrameDef | Instruction, n_joints: int) -> str | None:
    """What is wrong with one value of a program, independent of the dialect; None if nothing.

    Parameters
    ----------
    item : Header | FrameDef | Instruction
    n_joints : int
        Joint count from the header; a `PtpMove` must give exactly this many values.

    Returns
    -------
    str | None
        A short message such as "speed 0.000 is outside (0, 1]".
    """
    if isinstance(item, Header):
        if not item.joints:
            return "the robot needs at least one joint"
        if len(set(item.joints)) != len(item.joints):
            return "joint names must be unique"
        return _finite("cycle time", (item.cycle_time_s,)) or (
            f"cycle time {item.cycle_time_s:.3f} s is negative" if item.cycle_time_s < 0 else None
        )
    if isinstance(item, FrameDef):
        if item.kind not in ("tool", "base"):
            return f"frame kind must be 'tool' or 'base', got {item.kind!r}"
        return _triple("frame position", item.xyz_mm) or _triple("frame orientation", item.zyx_deg)
    if isinstance(item, PtpMove):
        if len(item.target_deg) != n_joints:
            return f"PTP target has {len(item.target_deg)} axis values, but the robot has {n_joints} joints"
        problem = _finite("PTP axis value", item.target_deg) or _finite("PTP speed/accel", (item.speed, item.accel))
        if problem:
            return problem
        for label, v in (("speed", item.speed), ("accel", item.accel)):
            if not 0.0 < v <= 1.0:
                return f"PTP {label} {v:.3f} is outside (0, 1] (a fraction of the maximum)"
        return _flyby_problem(item)
    if isinstance(item, LinMove):
        problem = (
            _triple("LIN position", item.position_mm)
            or _triple("LIN orientation", item.zyx_deg)
            or _finite("LIN speed/accel", (item.speed_mm_s, item.accel))
        )
        if problem:
            return problem
        if item.speed_mm_s <= 0:
            return f"LIN speed {item.speed_mm_s:.3f} mm/s must be > 0"
        if not 0.0 < item.accel <= 1.0:
            return f"LIN accel {item.accel:.3f} is outside (0, 1] (a fraction of the maximum)"
        return _flyby_problem(item)
    if isinstance(item, Spot):
        problem = _finite("weld time", (item.time_s,))
        return problem or (f"weld time {item.time_s:.3f} s is negative" if item.time_s < 0 else None)
    if isinstance(item, Gripper):
        problem = _finite("gripper time", (item.time_s,))
        if item.action not in ("grip", "release"):
            return f"gripper action {item.action!r} is neither grip nor release"
        return problem or (f"gripper time {item.time_s:.3f} s is negative" if item.time_s < 0 else None)
    if isinstance(item, Wait):
        problem = _finite("wait time", (item.seconds,))
        return problem or (f"wait time {item.seconds:.3f} s is negative" if item.seconds < 0 else None)
    return None


# ------------------------------------------------------------------ values as a program states them


def pose_mm_zyx(T: FloatArray) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """(4, 4) pose -> position (mm) and ZYX angles (deg): R = Rz(a) Ry(b) Rx(c)."""
    roll, pitch, yaw = rpy_from_matrix(np.asarray(T)[:3, :3])
    xyz = tuple(float(v) * 1000.0 for v in np.asarray(T)[:3, 3])
    return xyz, (math.degrees(yaw), math.degrees(pitch), math.degrees(roll))


def ptp_target(move: PtpMove) -> FloatArray:
    """The joint target a PTP move states, rad."""
    target: FloatArray = np.deg2rad(np.asarray(move.target_deg, dtype=float))
    return target


def lin_pose(move: LinMove) -> FloatArray:
    """The TCP pose a LIN move states, (4, 4) in m."""
    a, b, c = np.deg2rad(np.asarray(move.zyx_deg, dtype=float))
    return pose_matrix(np.asarray(move.position_mm, dtype=float) / 1000.0, [c, b, a])


def as_written_joints(q: FloatArray) -> FloatArray:
    """q (n,) or (m, n) rad as PTP statements give it back: rounded to the program's decimals.

    The planner times and checks these values, so the program is exactly what was checked.
    """
    q = np.asarray(q, dtype=float)
    if q.ndim == 2:
        return np.array([as_written_joints(row) for row in q]).reshape(q.shape)
    return ptp_target(PtpMove(tuple(float(v) for v in np.degrees(q))))


def as_written_pose(T: FloatArray) -> FloatArray:
    """A TCP pose as a LIN statement gives it back."""
    xyz, zyx = pose_mm_zyx(T)
    return lin_pose(LinMove(xyz, zyx))


def _identity(T: FloatArray) -> bool:
    return bool(np.array_equal(np.asarray(T, dtype=float), np.eye(4)))


def to_frame(T_root_frame: FloatArray, T: FloatArray) -> FloatArray:
    """A pose given in the URDF root frame, expressed in another frame (the controller's base,
    docs/cell-files.md, "Controller programs"). An exactly identity frame returns T itself: no floating-point touch, so programs of
    robots without `controller.base` stay byte for byte what they were."""
    if _identity(T_root_frame):
        return np.asarray(T, dtype=float)
    out: FloatArray = invert(np.asarray(T_root_frame, dtype=float)) @ np.asarray(T, dtype=float)
    return out


def from_frame(T_root_frame: FloatArray, T: FloatArray) -> FloatArray:
    """Inverse of `to_frame`: a pose stated in `T_root_frame`, in the URDF root frame."""
    if _identity(T_root_frame):
        return np.asarray(T, dtype=float)
    out: FloatArray = np.asarray(T_root_frame, dtype=float) @ np.asarray(T, dtype=float)
    return out


def frame_in_world(T_world_root: FloatArray, T_root_frame: FloatArray) -> FloatArray:
    """Where a frame given in the URDF root frame is in the world (identity frame: untouched)."""
    if _identity(T_root_frame):
        return np.asarray(T_world_root, dtype=float)
    out: FloatArray = np.asarray(T_world_root, dtype=float) @ np.asarray(T_root_frame, dtype=float)
    return out


def written_speed(fraction: float) -> float:
    """A PTP speed or acceleration fraction as a program states it."""
    return _fixed(fraction, SPEED_DECIMALS)


def written_tcp_speed(m_s: float) -> float:
    """A LIN speed (m/s) as a program states it (in mm/s)."""
    return _fixed(m_s * 1000.0, SPEED_DECIMALS) / 1000.0


def written_seconds(seconds: float) -> float:
    """A time (weld, wait) as a program states it."""
    return _fixed(seconds, TIME_DECIMALS)
