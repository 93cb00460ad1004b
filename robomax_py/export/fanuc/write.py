"""FANUC TP written: the controller's limits, names and remarks, the adapter (the program as TP states
it) and the writer of `<NAME>.ls` and its frames' program (the package's docstring gives the sources)."""

from __future__ import annotations

import dataclasses
import math
import re

from robomax_py.errors import ControllerSetupError, ExportError
from robomax_py.export.dialect import (
    PlannedProgram,
    SignalNumbers,
    fitted_identifier,
    gripper_label,
    header_lines,
    numbered_frames,
    numbered_inputs,
    numbered_outputs,
    percent,
    require_six_axes,
    spot_label,
    with_brand_configs,
    with_frame_names,
    with_package_welds,
    without_comments,
)
from robomax_py.program import (
    UNSET_FRAME,
    Comment,
    FrameDef,
    Gripper,
    Instruction,
    LinMove,
    Program,
    PtpMove,
    SetSignal,
    Spot,
    Wait,
    WaitFor,
)
from robomax_py.robot import RobotModel

NAME_CHARS = 36           # a TP program name (B-84184EN/03 §2.4.6)
REMARK_CHARS = 32         # a remark's text after `!` (controller exports, see the module docstring)
COMMENT_CHARS = 16        # /ATTR COMMENT, a position's comment
FRAMES_SUFFIX = "_FRAMES"
# The setup program holding the frames' values (a companion of `<NAME>.ls`).
FRAMES_FILE = FRAMES_SUFFIX + ".ls"
WEAPON = "SPOT_WELD"
# The routines every program calls alike, each its own program and file.
ROUTINES = (WEAPON, "GRIP", "RELEASE")
# R-30iB: tool frames UTOOL[1..10], user frames UFRAME[1..9] (0 is the world frame).
TOOL_SLOTS, BASE_SLOTS, INPUTS = 10, 9, 9999
OUTPUTS = INPUTS     # DO[k], numbered as DI[k]
SIGNALS = SignalNumbers("FANUC TP", (1, INPUTS), (1, OUTPUTS))

CNT_DEG = 0.12            # joint-space fly-by radius of CNT1, deg
# Angles (W, P, R and joint values) with 4 decimals, as every robomax program states them (TP's
# listings show 3): a spot orientation the planner chose at the edge of its tolerance window stays
# inside it, and a 12 deg detour corner blends as planned.
ANGLE_DECIMALS = 4
NEWLINE = "\r\n"
NO_DATE = "00-01-01"      # CREATE / MODIFIED without --stamp: the controller sets its own on loading
# SpotTool+ schedules other than the weld schedule: distance schedule 1 to close and to open the
# gun (SD, ED), pressure schedule 1 (P).
SPOT_DISTANCE, SPOT_PRESSURE = 1, 1
_STAMP_DATE = re.compile(r"^(?:[0-9]{2})([0-9]{2})-([0-9]{2})-([0-9]{2})$")


def _round(value: float, decimals: int) -> float:
    return round(value, decimals) + 0.0


def _to_controller(q_deg: tuple[float, ...], coupled: bool) -> tuple[float, ...]:
    q = list(q_deg)
    if coupled:
        q[2] = q[2] - q[1]
    return tuple(q)


def _from_controller(q_deg: tuple[float, ...], coupled: bool) -> tuple[float, ...]:
    q = list(q_deg)
    if coupled:
        q[2] = q[2] + q[1]
    return tuple(q)


def frame_name(frame: FrameDef) -> str:
    """How TP refers to a stored frame: `UTOOL[n]` or `UFRAME[n]`."""
    return f"{'UTOOL' if frame.kind == 'tool' else 'UFRAME'}[{frame.number}]"


def program_name(name: str) -> str:
    """The TP program a cell's program `name` becomes (module docstring): capitals, digits and `_`,
    a letter first, at most NAME_CHARS - len("_FRAMES") characters; a longer name is cut and given 4
    hexadecimal digits of its SHA-256 and its ending (a baseline's suffix, a station robot's name;
    `dialect.fitted_identifier`), a routine's name gets `_PROG`.

    >>> program_name("door-L 2"), program_name("7up"), program_name("spot_weld")
    ('DOOR_L_2', 'P7UP', 'SPOT_WELD_PROG')
    """
    return fitted_identifier(name.upper(), max_chars=NAME_CHARS - len(FRAMES_SUFFIX), reserved=ROUTINES,
                             keep=("_BASELINE", "_PUBLISHED", "_TEACH_IN")).upper()


def remarks(text: str) -> list[str]:
    """A text as TP remark texts of at most REMARK_CHARS characters: the first, then continuations
    starting with `+`, each followed by the rest of the text as it goes on. A line breaks after a
    comma, else before a space or after a `/`, else after a `_`, else where it is full; it never
    ends in a space (the controller may pad remarks with spaces)."""
    out: list[str] = []
    rest, room = text, REMARK_CHARS
    while len(rest) > room:
        cut = _break_at(rest, room)
        out.append(rest[:cut])
        rest, room = rest[cut:], REMARK_CHARS - 1
    out.append(rest)
    return [out[0], *("+" + piece for piece in out[1:])]


def _break_at(text: str, room: int) -> int:
    """Where to break `text` (longer than `room`): the number of characters the line keeps."""
    spaces = [k for k in range(1, room + 1) if text[k] == " " and text[k - 1] != " "]
    for cuts in ([k for k in spaces if text[k - 1] == ","],
                 sorted({*spaces, *(k for k in range(1, room + 1) if text[k - 1] == "/")}),
                 [k for k in range(1, room + 1) if text[k - 1] == "_" and text[k] != " "]):
        if cuts:
            return cuts[-1]
    return room


def _number(name: str) -> int:
    """The frame number of `UTOOL[n]` / `UFRAME[n]`; 0 for the null frame."""
    if name == UNSET_FRAME:
        raise ExportError("a TP position names its UF and UT numbers: the program selects none")
    match = re.search(r"\[([0-9]+)\]", name)
    return int(match.group(1)) if match else 0


def adapt(planned: PlannedProgram, robot: RobotModel) -> Program:
    """The program as TP states it: its TP name, frames by number (their values in the setup program
    only with position registers to set them from), FANUC configuration, 3 decimals, CNT, whole %
    and mm/sec, waits on DI numbers, SpotTool+ welds with `weld: package`."""
    require_six_axes(robot, "FANUC TP")
    numbered_frames(planned.program, "FANUC TP", TOOL_SLOTS, BASE_SLOTS)
    numbered_inputs(planned.program, SIGNALS.label, *SIGNALS.inputs)
    numbered_outputs(planned.program, SIGNALS.label, *SIGNALS.outputs)
    registers = planned.program.setup.position_registers
    if registers and len(registers) < len(planned.program.frames):
        raise ControllerSetupError("robot.controller.registers.position", f"the frames setup program sets "
                                   f"{len(planned.program.frames)} frames from position registers; the cell hands "
                                   f"{len(registers)}")
    program = with_package_welds(with_frame_names(planned.program, frame_name), "FANUC TP")
    guns = sorted({i.gun for i in program.instructions if isinstance(i, Spot) and i.package})
    if len(guns) > 1:
        raise ControllerSetupError("robot.controller.weld", f"a SpotTool+ program welds with the one gun its /APPL "
                                   f"names (SPOT Welding Equipment Number); the welds use guns {guns}")
    program = without_comments(with_brand_configs(program, planned.joints, robot, "fanuc"))
    coupled = robot.controller.j23_coupling
    out: list[Instruction] = []
    for ins in program.instructions:
        if isinstance(ins, PtpMove):
            ctrl = tuple(_round(v, ANGLE_DECIMALS) for v in _to_controller(ins.target_deg, coupled))
            ins = dataclasses.replace(ins, target_deg=_from_controller(ctrl, coupled),
                                      speed=percent(ins.speed) / 100, accel=percent(ins.accel) / 100,
                                      flyby=_cnt(ins.flyby) * CNT_DEG)
        elif isinstance(ins, LinMove):
            ins = dataclasses.replace(ins, position_mm=tuple(_round(v, 3) for v in ins.position_mm),
                                      zyx_deg=tuple(_round(v, ANGLE_DECIMALS) for v in ins.zyx_deg),
                                      speed_mm_s=float(max(1, round(ins.speed_mm_s))), flyby=_cnt(ins.flyby) * CNT_DEG,
                                      accel=percent(ins.accel) / 100)
        elif isinstance(ins, Wait):
            ins = Wait(math.ceil(round(ins.seconds * 100, 6)) / 100)
        elif isinstance(ins, WaitFor):
            ins = WaitFor(ins.signal[:COMMENT_CHARS], ins.number)       # the input's comment
        elif isinstance(ins, SetSignal):
            ins = SetSignal(ins.signal[:COMMENT_CHARS], ins.number, ins.value)   # the output's comment
        out.append(ins)
    frames = tuple(dataclasses.replace(f, xyz_mm=tuple(_round(v, 3) for v in f.xyz_mm),
                                       zyx_deg=tuple(_round(v, ANGLE_DECIMALS) for v in f.zyx_deg))
                   for f in program.frames)
    name = program_name(program.name)
    if not registers:
        # Without registers to set them from, the setup program only lists the values: the frames
        # are the controller's own, as calibrated.
        setup = dataclasses.replace(program.setup, listed=frames)
        return dataclasses.replace(program, name=name, frames=(), instructions=tuple(out), setup=setup)
    return dataclasses.replace(program, name=name, frames=frames, instructions=tuple(out))


def _cnt(radius_deg: float) -> int:
    return max(0, min(100, int(round(radius_deg / CNT_DEG))))


# ================================================================================== writing


def _num(value: float, decimals: int) -> str:
    """A number as the controller prints it: no leading zero below 1 (`.500`, `-.234`), `0.000`."""
    text = f"{value:.{decimals}f}"
    if value != 0 and text.startswith(("0.", "-0.")):
        text = text.replace("0.", ".", 1)
    return text


def _pad(statement: str) -> str:
    """The statement with the end the controller prints: four spaces before `;` after a motion, a
    call without arguments, a register assignment and a conditional wait, one elsewhere (CrossArm
    docs/fanuc_ls_format.md, "Spaces before ;"; R-30iB exports)."""
    padded = re.match(r"^([JL] |CALL [A-Z0-9_]+$|PR\[[^\]]*\]=(?!UTOOL|UFRAME)|WAIT (DI|DO)\[)", statement)
    return statement + ("    ;" if padded else " ;")


def _remark_statements(text: str) -> list[str]:
    return [f"!{piece}" for piece in remarks(text)]


def _header_statements(program: Program) -> list[str]:
    # " | " as ", ": no `|` in the remarks of controller exports.
    return [s for line in header_lines(program.header) for s in _remark_statements(line.replace(" | ", ", "))]


def write(program: Program, robot: RobotModel) -> dict[str, str]:
    coupled = robot.controller.j23_coupling
    mn: list[str] = _header_statements(program)
    first = next((i for i in program.instructions if isinstance(i, LinMove)), None)
    uf, ut = (0, 0) if first is None else (_number(first.base), _number(first.tool))
    mn += [f"UFRAME_NUM={uf}", f"UTOOL_NUM={ut}"]
    pos: list[str] = []
    k = calls = packages = 0
    gun: int | None = None
    grips: dict[str, int] = {}
    instructions = program.instructions
    for index, ins in enumerate(instructions):
        if isinstance(ins, (PtpMove, LinMove)):
            k += 1
            following = instructions[index + 1] if index + 1 < len(instructions) else None
            comment = f":{following.name[:COMMENT_CHARS]}" if isinstance(following, Spot) else ""
            term = f"CNT{_cnt(ins.flyby)}" if ins.flyby > 0 else "FINE"
            acc = f" ACC{percent(ins.accel)}" if percent(ins.accel) != 100 else ""
            if isinstance(ins, PtpMove):
                mn.append(f"J P[{k}{comment}] {percent(ins.speed)}% {term}{acc}")
                q = [f"J{i}={_num(v, ANGLE_DECIMALS):>10} deg" for i, v in
                     enumerate(_to_controller(ins.target_deg, coupled), start=1)]
                block = [f"\tUF : {uf}, UT : {ut},\t", "\t" + ",\t".join(q[:3]) + ",", "\t" + ",\t".join(q[3:])]
            else:
                if (_number(ins.base), _number(ins.tool)) != (uf, ut):
                    uf, ut = _number(ins.base), _number(ins.tool)
                    mn += [f"UFRAME_NUM={uf}", f"UTOOL_NUM={ut}"]
                mn.append(f"L P[{k}{comment}] {int(round(ins.speed_mm_s))}mm/sec {term}{acc}")
                x, y, z = (_num(v, 3) for v in ins.position_mm)
                r, p, w = (_num(v, ANGLE_DECIMALS) for v in ins.zyx_deg)
                block = [f"\tUF : {uf}, UT : {ut},\t\tCONFIG : '{ins.config}',",
                         f"\tX = {x:>9}  mm,\tY = {y:>9}  mm,\tZ = {z:>9}  mm,",
                         f"\tW = {w:>9} deg,\tP = {p:>9} deg,\tR = {r:>9} deg"]
            quoted = f':"{comment[1:]}"' if comment else ""
            pos += [f"P[{k}{quoted}]{{", "   GP1:", *block, "};"]
        elif isinstance(ins, Spot) and ins.package:
            packages += 1
            gun = ins.gun
            # The motion and its SPOT option are one statement, the option on the controller's
            # continuation line.
            mn[-1] += f"\n    :  SPOT[SD={SPOT_DISTANCE},P={SPOT_PRESSURE},S={ins.schedule},ED={SPOT_DISTANCE}]"
            mn += _remark_statements(f"{ins.seam}/{ins.name}")
        elif isinstance(ins, Spot):
            calls += 1
            mn += [f"CALL {WEAPON}({calls},{_num(ins.time_s, 3)})", *_remark_statements(spot_label(ins))]
        elif isinstance(ins, Gripper):
            grips[ins.action] = grips.get(ins.action, 0) + 1
            mn += [f"CALL {ins.action.upper()}({grips[ins.action]},{_num(ins.time_s, 3)})",
                   *_remark_statements(gripper_label(ins))]
        elif isinstance(ins, Wait):
            mn.append(f"WAIT {_num(ins.seconds, 2):>6}(sec)")
        elif isinstance(ins, WaitFor):
            mn.append(f"WAIT DI[{ins.number}:{ins.signal[:COMMENT_CHARS]}]=ON")
        elif isinstance(ins, SetSignal):
            # After a FINE move the robot has stopped before the next line runs (TP: FINE, a stop point).
            mn.append(f"DO[{ins.number}:{ins.signal[:COMMENT_CHARS]}]={'ON' if ins.value else 'OFF'}")
        elif not isinstance(ins, Comment):
            raise ExportError(f"FANUC TP cannot write {type(ins).__name__}")
    appl = [] if gun is None else ["  SPOT : TRUE ; ", f"  SPOT Welding Equipment Number : {gun} ;"]
    stamp = program.header.stamp
    out = {".ls": _ls(program.name, "robomax_py", mn, pos, stamp=stamp, appl=appl),
           FRAMES_FILE: _frames_program(program)}
    if calls or not (grips or packages):
        # WAIT takes an argument register directly: the routine writes no register.
        out[f"{WEAPON}.ls"] = _ls(WEAPON, "default weld", [
            "!default weld: rests AR[2] s", "!replace with the gun package", "WAIT AR[2]"], [], group="*")
    for action in sorted(grips):
        out[f"{action.upper()}.ls"] = _ls(action.upper(), f"default {action}", [
            f"!default {action}: rests AR[2] s", "!replace with gripper DO, inputs",
            "WAIT AR[2]"], [], group="*")
    return out


def _frames_program(program: Program) -> str:
    """The setup program: each frame's value into a position register the cell hands, then into
    the frame (`UTOOL[t]=PR[k]`, `UFRAME[u]=PR[k]`); without registers, the values as remarks."""
    mn = [*_header_statements(program), *_remark_statements(f"frames of {program.name}")]
    registers = program.setup.position_registers
    for k, f in enumerate(program.frames or program.setup.listed):
        values = (*f.xyz_mm, f.zyx_deg[2], f.zyx_deg[1], f.zyx_deg[0])     # X Y Z W P R
        if registers:
            pr = registers[k]
            # A Cartesian register set to zero, then element by element.
            mn += [f"PR[{pr}]=LPOS", f"PR[{pr}]=PR[{pr}]-PR[{pr}]"]
            mn += [f"PR[{pr},{i}]={_num(v, 3 if i <= 3 else ANGLE_DECIMALS)}" for i, v in enumerate(values, start=1)]
            mn.append(f"{f.name}=PR[{pr}]")
        else:
            mn.append(f"!{f.name} for SETUP Frames:")
            mn += [f"!{axis} = {_num(v, 3 if i < 3 else ANGLE_DECIMALS)} {'mm' if i < 3 else 'deg'}"
                   for i, (axis, v) in enumerate(zip("XYZWPR", values))]
    return _ls(f"{program.name}{FRAMES_SUFFIX}", "robomax frames", mn, [], stamp=program.header.stamp)


def _date(stamp: str) -> str:
    match = _STAMP_DATE.match(stamp)
    day = "-".join(match.groups()) if match else NO_DATE
    return f"DATE {day}  TIME 00:00:00"


def _ls(name: str, comment: str, mn: list[str], pos: list[str], *, stamp: str = "", group: str = "1",
        appl: list[str] | None = None) -> str:
    if len(name) > NAME_CHARS or len(comment) > COMMENT_CHARS:
        raise ExportError(f"FANUC TP: program {name} or its comment {comment!r} is too long")
    date = _date(stamp)
    lines = [f"/PROG  {name}", "/ATTR", "OWNER\t\t= MNEDITOR;", f'COMMENT\t\t= "{comment}";', "PROG_SIZE\t= 0;",
             f"CREATE\t\t= {date};", f"MODIFIED\t= {date};", "FILE_NAME\t= ;", "VERSION\t\t= 0;",
             f"LINE_COUNT\t= {len(mn)};", "MEMORY_SIZE\t= 0;", "PROTECT\t\t= READ_WRITE;", "TCD:  STACK_SIZE\t= 0,",
             "      TASK_PRIORITY\t= 50,", "      TIME_SLICE\t= 0,", "      BUSY_LAMP_OFF\t= 0,",
             "      ABORT_REQUEST\t= 0,", "      PAUSE_REQUEST\t= 0;", f"DEFAULT_GROUP\t= {group},*,*,*,*;",
             "CONTROL_CODE\t= 00000000 00000000;"]
    if appl:
        lines += ["/APPL", *appl]
    lines.append("/MN")
    for i, statement in enumerate(mn, start=1):
        first, *more = statement.split("\n")
        if first.startswith("!") and len(first) > REMARK_CHARS + 1:
            raise ExportError(f"FANUC TP: the remark {first!r} of {name} is too long")
        gap = "" if first[:2] in ("J ", "L ") else "  "
        if more:          # a motion and its options on the continuation line, which ends the statement
            lines += [f"{i:4d}:{gap}{first}", *more[:-1], more[-1] + "    ;"]
        else:
            lines.append(f"{i:4d}:{gap}{_pad(first)}")
    lines.append("/POS")
    lines += pos
    lines.append("/END")
    return NEWLINE.join(lines) + NEWLINE
