"""A robot program as values, independent of any controller dialect.

An exporter turns a `Program` into text (`export/srcl/`) and a parser turns text back into one
(`parse_program`, both in `export/srcl/`). Every float is rounded *when the value is built* to the fixed number of
decimals the program files carry, so ``parse(write(p)) == p`` holds exactly:

=================================  =========  ========
quantity                           unit       decimals
=================================  =========  ========
joint values (`PtpMove.target_deg`)  deg (mm)   4
fly-by radii (joint space)         deg        4
positions, frame offsets           mm         3
ZYX orientation angles             deg        4
PTP speed / acceleration           fraction   3
LIN speed                          mm/s       3
weld, wait and cycle times         s          3
=================================  =========  ========

A prismatic joint's value (a robot on a track) is stated in mm, not deg; `stated_joints` and
`ptp_target` convert with the robot's joint kinds. A fly-by radius is the joint-space distance over
the values in rad (m for a prismatic joint), stated times 180/pi: in deg on a robot of revolute
joints.

Rounding is Python's correctly rounded `round` (half-even on the exact binary value), which agrees
digit for digit with ``f"{x:.{n}f}"``; ``-0.0`` is stored as ``0.0``. Non-finite values are kept as
they are (the writer rejects them), and nothing is range-checked here: `find_problem` says what is
wrong with a value, and the writer (`ExportError`) and parser (`ProgramError`) report it.

Orientations are ZYX angles ``(a, b, c)`` in degrees, R = Rz(a)·Ry(b)·Rx(c), as KUKA's A, B, C.
"""

from __future__ import annotations

import math
import re
import unicodedata
from collections.abc import Sequence

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.program_instructions import (
    ANGLE_DECIMALS,
    FLYBY_MM_DECIMALS,
    JOINT_DECIMALS,
    MM_DECIMALS,
    NULL_FRAME,
    SPEED_DECIMALS,
    TIME_DECIMALS,
    UNSET_FRAME,
    Comment,
    FrameDef,
    FrameKind,
    Gripper,
    Header,
    Instruction,
    LinMove,
    Program,
    ProgramSetup,
    PtpMove,
    SetSignal,
    Spot,
    ToolLoad,
    Wait,
    WaitFor,
    _fixed,
    lin_pose,
)
from robomax_py.transforms import invert, rpy_from_matrix

__all__ = [
    "ANGLE_DECIMALS",
    "FLYBY_MM_DECIMALS",
    "JOINT_DECIMALS",
    "KEYWORDS",
    "MM_DECIMALS",
    "NULL_FRAME",
    "SPEED_DECIMALS",
    "TIME_DECIMALS",
    "UNSET_FRAME",
    "Comment",
    "FrameDef",
    "FrameKind",
    "Gripper",
    "Header",
    "Instruction",
    "LinMove",
    "Program",
    "ProgramSetup",
    "PtpMove",
    "SetSignal",
    "Spot",
    "ToolLoad",
    "Wait",
    "WaitFor",
    "as_written_joints",
    "as_written_pose",
    "find_problem",
    "frame_in_world",
    "from_frame",
    "identifier",
    "lin_pose",
    "pose_mm_zyx",
    "ptp_target",
    "spelled_out",
    "stated_joints",
    "to_frame",
    "written_seconds",
    "written_speed",
    "written_tcp_speed",
]


# The upper-case keywords of SRCL, the program's own text (docs/srcl.md); no name may be one
# (names are case-sensitive, so `spot` is a name).
KEYWORDS: frozenset[str] = frozenset(
    ["PROGRAM", "CELL", "ROBOT", "AXES", "TOOL", "CYCLE", "SEC", "VAR", "FRAME", "BASE", "POS", "ORI", "BEGIN",
     "ENDPROGRAM", "MOVE", "PTP", "LIN", "AXIS", "SPEED", "ACCEL", "FLYBY", "CONFIG", "SPOT", "SEAM", "TIME", "WAIT",
     "FOR", "GUN", "SCHEDULE", "GRIP", "RELEASE", "INPUT", "SET", "OUTPUT", "TRUE", "FALSE", "SPL", "SLIN"]
)
_NOT_IDENT = re.compile(r"[^A-Za-z0-9_]")
# German letters written out as German does without them; other accented letters lose their
# accents (NFKD): what a controller's names and comments, in ASCII, can keep of a name.
_SPELLED = str.maketrans({"ä": "ae", "ö": "oe", "ü": "ue", "Ä": "Ae", "Ö": "Oe", "Ü": "Ue", "ß": "ss"})


def spelled_out(text: str, other: str) -> str:
    """`text` in ASCII: German letters spelled out, accents dropped, every other character outside
    ASCII replaced by `other`. 'Naht_Äußen' -> 'Naht_Aeussen', 'café' -> 'cafe'."""
    if text.isascii():
        return text
    plain = unicodedata.normalize("NFKD", text.translate(_SPELLED))
    return "".join(c if c.isascii() else other for c in plain if not unicodedata.combining(c))


def identifier(name: str) -> str:
    """The name a program states for a cell's seam, spot, frame or signal: letters, digits and `_`
    (`spelled_out`, then every other character becomes `_`: `Schweißpunkt 1` is
    `Schweisspunkt_1`, `点1` is `_1`), not a digit first, not a keyword. Two names of a cell that
    give the same identifier are refused when the cell is read (`io.cell_jobs.same_identifier`): a
    program could not tell them apart."""
    ident = _NOT_IDENT.sub("_", spelled_out(name, "_")) or "_"
    if ident[0].isdigit():
        ident = "_" + ident
    if ident.upper() in KEYWORDS or ident in KEYWORDS:
        ident += "_"
    return ident


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
        if item.spline not in ("", "spl", "slin"):
            return f"spline segment {item.spline!r} is neither 'spl' nor 'slin'"
        if item.spline and item.flies:
            return "a spline block's segment states no fly-by: the spline passes through its points"
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


def _kinds(prismatic: Sequence[bool] | np.ndarray, n: int) -> np.ndarray:
    mask = np.asarray(prismatic, dtype=bool)
    if mask.shape != (n,):
        raise ValueError(f"{n} joint values but {mask.size} joint kinds")
    return mask


def stated_joints(q: FloatArray, prismatic: Sequence[bool] | np.ndarray) -> tuple[float, ...]:
    """Joint values q (n,), rad (m for a prismatic joint), as a program states them: deg (mm for
    a prismatic joint), before rounding."""
    q = np.asarray(q, dtype=float)
    # np.degrees and np.deg2rad below, as for every arm before tracks: the same values to the bit.
    return tuple(float(v) for v in np.where(_kinds(prismatic, q.size), q * 1000.0, np.degrees(q)))


def ptp_target(move: PtpMove, prismatic: Sequence[bool] | np.ndarray) -> FloatArray:
    """The joint target a PTP move states, rad (m for a prismatic joint): its values are deg, or mm
    for the joints `prismatic` marks."""
    values = np.asarray(move.target_deg, dtype=float)
    target: FloatArray = np.where(_kinds(prismatic, values.size), values / 1000.0, np.deg2rad(values))
    return target


def as_written_joints(q: FloatArray, prismatic: Sequence[bool] | np.ndarray) -> FloatArray:
    """q (n,) or (m, n) rad (m for prismatic joints) as PTP statements give it back: rounded to the
    program's decimals (of deg, or of mm for a prismatic joint).

    The planner times and checks these values, so the program is exactly what was checked.
    """
    q = np.asarray(q, dtype=float)
    if q.ndim == 2:
        return np.array([as_written_joints(row, prismatic) for row in q]).reshape(q.shape)
    return ptp_target(PtpMove(stated_joints(q, prismatic)), prismatic)


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
