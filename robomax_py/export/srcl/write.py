"""SRCL written: the program's checks and its text, and SRCL's adapter and writer as a dialect."""

from __future__ import annotations

import re
from collections.abc import Iterable

from robomax_py.errors import ExportError
from robomax_py.export.dialect import PlannedProgram
from robomax_py.program import (
    ANGLE_DECIMALS,
    JOINT_DECIMALS,
    KEYWORDS,
    MM_DECIMALS,
    NULL_FRAME,
    SPEED_DECIMALS,
    TIME_DECIMALS,
    UNSET_FRAME,
    Comment,
    FrameDef,
    Gripper,
    Header,
    Instruction,
    LinMove,
    Program,
    PtpMove,
    SetSignal,
    Spot,
    Wait,
    WaitFor,
    find_problem,
)
from robomax_py.robot import RobotModel

DIALECT = "robomax SRCL/1"

# Upper-case keywords; they cannot be used as names (names are case-sensitive, so `spot` is a name).
RESERVED = KEYWORDS

_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_INDENT = "  "


def write_program(program: Program) -> str:
    """The SRCL text of a program.

    Parameters
    ----------
    program : Program

    Returns
    -------
    str
        Lines joined with "\\n", ending in a newline.

    Raises
    ------
    ExportError
        A name is not an identifier or is a keyword, a comment or config cannot be written
        (braces, quotes, control characters), a number is NaN or infinite or out of range, a PTP
        target has the wrong number of axes, or two frames share a name.
    """
    _check_program(program)
    h = program.header
    lines = [
        f"PROGRAM {program.name};",
        f"{{ {DIALECT}; lengths mm, angles deg, times s, PTP speed and accel as fractions }}",
        *(f"{{ {text} }}" for text in _provenance(h)),
        f"CELL {h.cell};",
        f"ROBOT {h.robot} AXES({', '.join(h.joints)});",
        f"TOOL {h.tool};",
        f"CYCLE {_num(h.cycle_time_s, TIME_DECIMALS)} SEC;",
    ]
    if program.frames:
        lines.append("VAR")
        lines.extend(_INDENT + _frame(f) for f in program.frames)
    lines.append("BEGIN")
    lines.extend(_INDENT + _statement(ins) for ins in program.instructions)
    lines.append("ENDPROGRAM;")
    return "\n".join(lines) + "\n"


def _provenance(h: Header) -> list[str]:
    """Generator, cell file hash and stamp as comment texts (the rest of the header is statements)."""
    out = []
    if h.generator or h.cell_sha256:
        out.append(f"{h.generator or 'robomax_py ?'} | cell file sha256 {h.cell_sha256 or 'unknown'}")
    if h.stamp:
        out.append(f"written {h.stamp}")
    return out


_PROVENANCE = re.compile(r"^(?P<gen>\S+ \S+) \| cell file sha256 (?P<sha>[0-9a-f]+|unknown)$")
_STAMP = re.compile(r"^written (?P<stamp>\S.*)$")


def _num(value: float, decimals: int) -> str:
    return f"{value:.{decimals}f}"


def _nums(values: Iterable[float], decimals: int) -> str:
    return ", ".join(_num(v, decimals) for v in values)


def _pose(xyz_mm: tuple[float, ...], zyx_deg: tuple[float, ...]) -> str:
    return f"POS({_nums(xyz_mm, MM_DECIMALS)}) ORI({_nums(zyx_deg, ANGLE_DECIMALS)})"


def _frame(f: FrameDef) -> str:
    pos = f"POS({_nums(f.xyz_mm, MM_DECIMALS)})"
    ori = f"ORI({_nums(f.zyx_deg, ANGLE_DECIMALS)})"
    number = f" {f.number}" if f.number else ""
    return f"{f.name}: {f.kind.upper()} FRAME{number} := ({pos}, {ori});"


def _tail(flyby: float, comment: str) -> str:
    fly = f" FLYBY {_num(flyby, ANGLE_DECIMALS)}" if flyby > 0 else ""
    return fly + (f" {{ {comment} }}" if comment else "") + ";"


def _statement(ins: Instruction) -> str:
    if isinstance(ins, PtpMove):
        return (
            f"MOVE PTP AXIS({_nums(ins.target_deg, JOINT_DECIMALS)}) "
            f"SPEED {_num(ins.speed, SPEED_DECIMALS)} ACCEL {_num(ins.accel, SPEED_DECIMALS)}"
            + _tail(ins.flyby, ins.comment)
        )
    if isinstance(ins, LinMove):
        return (
            f"MOVE {ins.spline.upper() or 'LIN'} {_pose(ins.position_mm, ins.zyx_deg)} CONFIG '{ins.config}' "
            f"SPEED {_num(ins.speed_mm_s, SPEED_DECIMALS)} MM/S"
            + (f" ACCEL {_num(ins.accel, SPEED_DECIMALS)}" if ins.accel < 1.0 else "") + _tail(ins.flyby, ins.comment)
        )
    if isinstance(ins, Spot):
        return (f"SPOT {ins.name} SEAM {ins.seam} TIME {_num(ins.time_s, TIME_DECIMALS)} SEC "
                f"GUN {ins.gun} SCHEDULE {ins.schedule};")
    if isinstance(ins, Gripper):
        return f"{ins.action.upper()} {ins.name} SEAM {ins.seam} TIME {_num(ins.time_s, TIME_DECIMALS)} SEC;"
    if isinstance(ins, Wait):
        return f"WAIT {_num(ins.seconds, TIME_DECIMALS)} SEC;"
    if isinstance(ins, WaitFor):
        return f"WAIT FOR {ins.signal}" + ("" if ins.number is None else f" INPUT {ins.number}") + ";"
    if isinstance(ins, SetSignal):
        number = "" if ins.number is None else f" OUTPUT {ins.number}"
        return f"SET {ins.signal}{number} {'TRUE' if ins.value else 'FALSE'};"
    if isinstance(ins, Comment):
        return f"{{ {ins.text} }}" if ins.text else "{ }"
    raise ExportError(f"SRCL cannot write instruction {ins!r}")


def _check_name(where: str, name: object) -> None:
    if not isinstance(name, str) or not _NAME.fullmatch(name):
        raise ExportError(f"{where}: {name!r} is not an SRCL name (letters, digits, '_'; not starting with a digit)")
    if name in RESERVED:
        raise ExportError(f"{where}: {name!r} is an SRCL keyword and cannot be used as a name")


def _check_text(where: str, text: str, forbidden: str) -> None:
    bad = [c for c in text if c in forbidden or not c.isprintable()]
    if bad:
        raise ExportError(f"{where}: {text!r} cannot contain {bad[0]!r} (no {forbidden}, newlines or control characters)")


def _kind(ins: Instruction) -> str:
    return {
        PtpMove: "MOVE PTP", LinMove: "MOVE LIN", Spot: "SPOT", Gripper: "GRIP/RELEASE", Wait: "WAIT",
        WaitFor: "WAIT FOR", SetSignal: "SET", Comment: "comment"
    }.get(type(ins), type(ins).__name__)


def _check_program(program: Program) -> None:
    _check_name("program name", program.name)
    h = program.header
    if not isinstance(h, Header):
        raise ExportError(f"program header must be a Header, got {type(h).__name__}")
    _check_name("header cell", h.cell)
    _check_name("header robot", h.robot)
    _check_name("header tool", h.tool)
    for j, joint in enumerate(h.joints):
        _check_name(f"header joint {j}", joint)
    problem = find_problem(h, len(h.joints))
    if problem:
        raise ExportError(f"header: {problem}")
    seen: set[str] = set()
    for i, f in enumerate(program.frames):
        where = f"frame {i} ({f.name!r})"
        _check_name(where, f.name)
        if f.name in seen:
            raise ExportError(f"{where}: a frame named {f.name!r} is already defined")
        seen.add(f.name)
        problem = find_problem(f, len(h.joints))
        if problem:
            raise ExportError(f"{where}: {problem}")
        if f.number < 0:
            raise ExportError(f"{where}: frame number {f.number} is negative")
    tool, base = lin_frames(program.frames)
    for i, ins in enumerate(program.instructions):
        where = f"instruction {i} ({_kind(ins)})"
        if isinstance(ins, (PtpMove, LinMove)):
            _check_text(where + " comment", ins.comment, "{}")
        if isinstance(ins, LinMove):
            _check_text(where + " config", ins.config, "'")
        elif isinstance(ins, (Spot, Gripper)):
            _check_name(where + " spot name", ins.name)
            _check_name(where + " seam name", ins.seam)
        elif isinstance(ins, WaitFor):
            _check_name(where + " signal", ins.signal)
            if ins.number is not None and ins.number < 0:
                raise ExportError(f"{where}: input number {ins.number} is negative")
        elif isinstance(ins, SetSignal):
            _check_name(where + " signal", ins.signal)
            if ins.number is not None and ins.number < 0:
                raise ExportError(f"{where}: output number {ins.number} is negative")
        elif isinstance(ins, Comment):
            _check_text(where, ins.text, "{}")
        elif not isinstance(ins, (PtpMove, Wait)):
            raise ExportError(f"{where}: SRCL cannot write {type(ins).__name__}")
        if isinstance(ins, (PtpMove, LinMove)) and ins.flyby_mm > 0:
            raise ExportError(f"{where}: SRCL states fly-by radii in joint space (FLYBY deg), not as a TCP distance")
        problem = find_problem(ins, len(h.joints))
        if problem:
            raise ExportError(f"{where}: {problem}")
        if isinstance(ins, LinMove) and (ins.tool, ins.base) != (tool, base):
            raise ExportError(f"{where}: SRCL states every LIN in its one TOOL and BASE frame ({tool or 'none'}, "
                              f"{base or 'the robot base'}); this one names {ins.tool or 'none'}, "
                              f"{ins.base or 'the robot base'}")


def lin_frames(frames: tuple[FrameDef, ...]) -> tuple[str, str]:
    """The tool and base every SRCL LIN is stated in: the program's one TOOL FRAME (none declared:
    `UNSET_FRAME`, the program selects no tool) and its one BASE FRAME (none: the robot base frame)."""
    out = []
    for kind, absent in (("tool", UNSET_FRAME), ("base", NULL_FRAME)):
        named = [f.name for f in frames if f.kind == kind]
        if len(named) > 1:
            raise ExportError(f"SRCL declares at most one {kind.upper()} FRAME, got {len(named)}: {', '.join(named)}")
        out.append(named[0] if named else absent)
    return out[0], out[1]


# ================================================================================== as a dialect


def adapt(planned: PlannedProgram, robot: RobotModel) -> Program:
    """SRCL states the planned program as it is."""
    return planned.program


def write(program: Program, robot: RobotModel) -> dict[str, str]:
    return {".srcl": write_program(program)}
