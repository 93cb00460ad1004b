"""FANUC TP (ASCII `.ls`), both directions: the program `<NAME>.ls`, its frames setup program
`<NAME>_FRAMES.ls` and the default routines `SPOT_WELD.ls`, `GRIP.ls`, `RELEASE.ls`.

What a program states, in TP's terms:
- `/MN` with `J P[i] n% FINE|CNTn` and `L P[i] n mm/sec FINE|CNTn`; `/POS` with `GP1`, `UF : u`,
  `UT : t`, and either `CONFIG : 'F|N U|D T|B, t4, t5, t6'` with X, Y, Z mm and W, P, R deg
  (R = Rz(R)·Ry(P)·Rx(W)) or J1..J6 in deg as the controller counts them: with robot.yaml
  `controller.j23_coupling: true` J3 is measured from the horizontal, J3 = J3(URDF) - J2(URDF)
  (the ROS-Industrial fanuc_driver's joint streamer, J23_factor = 1);
- frames selected by number before the first motion, `UFRAME_NUM=u` and `UTOOL_NUM=t`, and each
  position's `UF : u, UT : t` the same: changing the numbers under a taught position "may cause a
  frame mismatch error and stop the TP program" (FANUC B-84184EN/03, Remote Motion Interface
  operator's manual, §2.3.6; INTP-251 / INTP-253 "Tool frame number mismatch" in a ROBOGUIDE
  probe, LeroyDu56/CrossArm docs/fanuc_ls_format.md). With factory settings the world frame is the
  robot base (the controller knows nothing of the cell), so `UF : 0` targets are in the robot base
  frame and a user frame is given in it; the robot's placement in the cell is never written. The
  frames' values go into the setup program (`PR[k]` set element by element, `UTOOL[t]=PR[k]`,
  `UFRAME[u]=PR[k]`) from the position registers the cell hands (`robot.controller.registers`);
  without them it lists the values as remarks for the SETUP Frames screen. The main program writes
  no register and no frame;
- mm with 3 decimals, W, P, R and joint values with 4, speeds in whole % and mm/sec, waits in 0.01 s (rounded up);
- blends as `CNTn`: robomax's model of CNT flies by with the joint-space radius n x 0.12 deg
  (CNT100 = 12 deg, the largest radius the planner uses), so the planner's radii are whole CNTs;
- a weld (`weld: call`, the default) as `L ... FINE`, then `CALL SPOT_WELD(n,weld_time)`, then the
  `!seam/name gun G schedule S` remark (TP has no comment at the end of a statement); SPOT_WELD is
  its own program (TP defines one program per file) that rests `weld_time` s: `WAIT AR[2]`, an
  argument register as a wait time (loaded and run in ROBOGUIDE, CrossArm docs/fanuc_ls_format.md
  "Call with arguments"; accepted by the JTremblayAGT/fanuc-lsp grammar, TpWaitInstructionTests.cs
  47), so it writes no register. With `weld: package` the weld is SpotTool+'s: the motion carries
  `SPOT[SD=1,P=1,S=<schedule>,ED=1]` on the continuation line the controller prints it on (S the
  weld schedule; SD / ED the start and end distance schedules and P the pressure schedule, all
  schedule 1 of the controller's tables), and the program's `/APPL` names the gun as SpotTool+'s
  `SPOT Welding Equipment Number` (one gun per program);
- `WAIT t(sec)` and `WAIT DI[k:<signal>]=ON`.

As a controller prints a program and loads it again (its own exports; FANUC B-84184EN/03 §5: "A
Teach Pendant program can be printed out as a LS file ... When loading an LS file into the
controller, the LS file goes through an ASCII to binary conversion"):
- program names of capital letters, digits and `_`, starting with a letter, at most NAME_CHARS =
  36 characters (B-84184EN/03 §2.4.6: "The ProgramName string can be up to 36 bytes"; R-30iB
  V8.30 exports hold 16-character names, kamilkozdro/FanucProgramAnalyze@e585a61d
  fanucPrograms/odbierzprzedmuch.ls). A cell's name becomes `program_name(name)`: capitals, `_`
  for other characters, a `P` before a leading digit or `_`, and past 29 characters (so that
  `<NAME>_FRAMES` fits) cut to 24 with `_` and 4 hexadecimal digits of its SHA-256, so that two long
  names stay apart. Each file is named as its program (`<NAME>.ls`): MakeTP turns `<NAME>.LS` into
  `<NAME>.TP`, and PrintTP "expects the .TP filename to match the internal program name"
  (djfacio/fanuc-ai-tp@ebec2792 AGENTS.md 170). `FILE_NAME` is left empty: in exports it names the
  program a copy was made from (`/PROG  REQMENU` with `FILE_NAME = SENDDATA`, FanucProgramAnalyze
  reqmenu.ls), and RoboDK's post (ros-industrial-attic/robodk_postprocessors@d7e6c1c0
  Fanuc_R30iA.py 182) writes it empty too;
- remarks `!text` of at most REMARK_CHARS = 32 characters: of 4566 remarks in 807 programs exported
  by controllers (mitchtown98/FANUC_LS_Examples@9948f158) 676 are exactly 32 characters long and
  none of the exported ones longer. Longer texts (the header's lines, a long seam or spot name)
  continue on the next remarks, each starting with `+` and followed by the rest of the text exactly
  as it goes on (a line breaks before a space, which the continuation keeps after its `+`); the
  reader joins them. The header's ` | ` separators are written `, ` (no `|` occurs in those
  remarks);
- `/ATTR` as exports have it: `COMMENT` of at most 16 characters (the exports' longest; ROBOGUIDE
  pads it to 16, CrossArm roboguide_export/PLACE.LS), `CREATE` / `MODIFIED` the `--stamp` date,
  else DATE 00-01-01 (the controller sets its own dates on loading, CrossArm), `PROG_SIZE` and
  `MEMORY_SIZE` 0 (recomputed on loading; RoboDK writes 0), `LINE_COUNT` the number of statements,
  `DEFAULT_GROUP = 1,*,*,*,*;` (R-30iB V8.30 and ROBOGUIDE exports; `*,*,*,*,*` for the routines,
  which hold no motion group);
- statements numbered `   1:  `, a motion's letter right after the colon (`   3:J P[1] 100% FINE
  ;`), CRLF line ends (ros-industrial/fanuc@8fee5e30 fanuc_driver/tpe/ros_movesm.ls; "MakeTP may
  reject" LF-only files, djfacio/fanuc-ai-tp tools/Invoke-FanucToolTests.ps1 1079); numbers below 1
  without their leading zero (`WAIT    .30(sec)`, `CALL SPOT_WELD(1,.500)`, `P =     -.234 deg`);
  the position blocks with the exports' spacing (`\\tX =   485.864  mm,`, `\\tJ1=    62.188 deg,`);
  a weld position carries the spot's name as its comment, cut to 16 characters (`P[4:s7]`, as
  `P[12:W_PT00045027_017]` in SpotTool+ exports).

The reader takes both these files and other writers' (any spacing, LF or CRLF, `/APPL`, position
comments, continuation lines). Remarks: TP remarks are short; the notes other dialects carry on
each move are left out.

It follows the program as the controller runs it (`export.flow`): END and ABORT end it, PAUSE
stops it until it is started again (the verified cycle ends there), JMP LBL[n] continues at
LBL[n]; a CALL of the frames setup program runs it in place. A CALL of any other program (the
default routines aside), RUN, conditional jumps and calls (IF ..., SELECT, WAIT ... TIMEOUT,LBL),
a speed OVERRIDE, waits other than `WAIT t(sec)` and `WAIT DI[k]=ON` (on a register, a flag, an
expression), and what runs inside IF ... THEN / FOR blocks are reported, never skipped. A
CALL SPOT_WELD / GRIP / RELEASE is the weld or gripper action it names while the routine shipped
beside the program (SPOT_WELD.ls ...) does nothing but `WAIT AR[2]`; the time is the call's second
argument, in s. Linear speeds in mm/sec, cm/min or inch/min are read in their units; a move
stated by its time (sec, msec) or its orientation speed (deg/sec) is reported; joint speeds in %
(rebuild reports them above 100 %, and lines above the cell's line speed).
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
import re

from robomax_py.errors import ControllerSetupError, ExportError, ProgramError
from robomax_py.export.dialect import (
    Parsed,
    PlannedProgram,
    gripper_label,
    header_lines,
    numbered_frames,
    numbered_inputs,
    percent,
    read_gripper,
    read_header,
    read_spot_label,
    require_six_axes,
    spot_label,
    with_brand_configs,
    with_frame_names,
    with_package_welds,
    without_comments,
)
from robomax_py.export.flow import Flow, Routine, Statement, follow
from robomax_py.program import (
    NULL_FRAME,
    UNSET_FRAME,
    Comment,
    FrameDef,
    Gripper,
    Instruction,
    LinMove,
    Program,
    PtpMove,
    Spot,
    Wait,
    WaitFor,
)
from robomax_py.robot import RobotModel

__all__ = ["CNT_DEG", "FRAMES_FILE", "NAME_CHARS", "REMARK_CHARS", "ROUTINES", "adapt", "frame_name", "parse",
           "program_name", "remarks", "write"]

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
    hexadecimal digits of its SHA-256 (a trailing `_BASELINE` is kept), a routine's name gets `_PROG`.

    >>> program_name("door-L 2"), program_name("7up"), program_name("spot_weld")
    ('DOOR_L_2', 'P7UP', 'SPOT_WELD_PROG')
    """
    ident = re.sub(r"[^A-Z0-9_]", "_", name.upper()) or "P"
    if not "A" <= ident[0] <= "Z":
        ident = "P" + ident
    room = NAME_CHARS - len(FRAMES_SUFFIX)
    if len(ident) > room:
        kept = "_BASELINE" if ident.endswith("_BASELINE") else ""
        digest = hashlib.sha256(name.encode()).hexdigest()[:4].upper()
        ident = ident[:room - len(kept) - 5] + "_" + digest + kept
    if ident in ROUTINES:
        ident += "_PROG"
    return ident


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
    numbered_inputs(planned.program, "FANUC TP", 1, INPUTS)
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


# ================================================================================== reading

_NUMBERED = re.compile(r"^\s*([0-9]+):(.*)$")
_CONTINUED = re.compile(r"^\s*:(.*)$")
_MOVE = re.compile(r"^(J|L)\s+P\[([0-9]+)(?::[^\]]*)?\]\s+([0-9.]+)\s*(%|mm/sec|cm/min|inch/min|deg/sec|sec|msec)\s+"
                   r"(FINE|CNT\s*([0-9]+))(.*)$", re.IGNORECASE)
_CALL = re.compile(r"^CALL\s+(SPOT_WELD|GRIP|RELEASE)\s*\(\s*([0-9]+)\s*,\s*([0-9]*\.?[0-9]+)\s*\)$", re.IGNORECASE)
_WAIT = re.compile(r"^WAIT\s+([0-9]*\.?[0-9]+)\s*\(sec\)$", re.IGNORECASE)
_WAIT_DI = re.compile(r"^WAIT\s+DI\[([0-9]+)(?::([^\]]*))?\]\s*=\s*ON$", re.IGNORECASE)
_PR_ELEMENT = re.compile(r"^PR\[([0-9]+),([1-6])\]\s*=\s*\(?\s*([+-]?[0-9]*\.?[0-9]+)\s*\)?$", re.IGNORECASE)
_FRAME_SET = re.compile(r"^(UTOOL|UFRAME)\[([0-9]+)\]\s*=\s*PR\[([0-9]+)\]$", re.IGNORECASE)
_FRAME_NUM = re.compile(r"^(UTOOL|UFRAME)_NUM\s*=\s*([0-9]+)$", re.IGNORECASE)
_PR_RESET = re.compile(r"^PR\[([0-9]+)\]\s*=\s*(LPOS|PR\[([0-9]+)\]\s*-\s*PR\[([0-9]+)\])$", re.IGNORECASE)
_UF_UT = re.compile(r"\bUF\s*:\s*([0-9]+)\s*,\s*UT\s*:\s*([0-9]+)", re.IGNORECASE)
_POS_HEAD = re.compile(r"^P\[([0-9]+)(?::[^\]]*)?\]\s*\{", re.IGNORECASE)
_FIELD = re.compile(r"\b(X|Y|Z|W|P|R|J[1-6])\s*=\s*([+-]?[0-9]*\.?[0-9]+)\s*(mm|deg)", re.IGNORECASE)
_CONFIG = re.compile(r"CONFIG\s*:\s*'([^']*)'", re.IGNORECASE)
_SPOT = re.compile(r"\bSPOT\[([^\]]*)\]", re.IGNORECASE)
_EQUIPMENT = re.compile(r"SPOT\s+Welding\s+Equipment\s+Number\s*:\s*([0-9]+)", re.IGNORECASE)
# Motion options that change the target or the way the robot moves to it (remote TCP: the part
# moves past a fixed tool); TB/TA/DB triggers and ACC are read or do not.
_TARGET_OPTIONS = re.compile(r"\b(Offset|Tool_Offset|INC|VOFFSET|Skip|RTCP)\b", re.IGNORECASE)
# Motions this reader does not simulate, and control flow (jumps, conditions): the program's
# motion then depends on what the reader cannot follow.
_UNSIMULATED = re.compile(r"^(C|A)\s+P|^(J|L|C|A)\s+PR\[|^JMP\b|^IF\b|^SELECT\b|^FOR\b|"
                          r"^CALL\s+(?!(SPOT_WELD|GRIP|RELEASE)\b)", re.IGNORECASE)


def _positions(text: str) -> dict[int, tuple[dict[str, float], str, tuple[int, int] | None]]:
    """P[k] -> its fields (X..R, J1..J6), its CONFIG and its (UF, UT) numbers."""
    out: dict[int, tuple[dict[str, float], str, tuple[int, int] | None]] = {}
    for block in re.split(r"(?=^P\[)", text, flags=re.MULTILINE):
        head = _POS_HEAD.match(block)
        if head:
            group1 = re.split(r"\bGP[2-9]\s*:", block)[0]         # the robot's group; others are positioners
            fields = {m.group(1).upper(): float(m.group(2)) for m in _FIELD.finditer(group1)}
            config = _CONFIG.search(group1)
            frames = _UF_UT.search(group1)
            out[int(head.group(1))] = (fields, config.group(1) if config else "",
                                       (int(frames.group(1)), int(frames.group(2))) if frames else None)
    return out


def _program_positions(text: str) -> dict[int, tuple[dict[str, float], str, tuple[int, int] | None]]:
    """The /POS positions of a whole TP program text."""
    lines = text.splitlines()
    at = next((i for i, ln in enumerate(lines) if ln.strip() == "/POS"), len(lines))
    return _positions("\n".join(lines[at + 1:]))


def _statements(lines: list[str], start: int, end: int) -> list[tuple[int, str]]:
    """(file line, statement) of the /MN lines start..end-1: a numbered line with its continuation
    lines (`    :  SPOT[...]`), without the closing `;`; a remark's continuations (`!+...`, see
    `remarks`) joined into it."""
    out: list[tuple[int, str]] = []
    for index in range(start, end):
        numbered = _NUMBERED.match(lines[index])
        continued = None if numbered else _CONTINUED.match(lines[index])
        if numbered:
            out.append((index + 1, numbered.group(2).strip()))
        elif continued and out:
            out[-1] = (out[-1][0], f"{out[-1][1]} {continued.group(1).strip()}")
    joined: list[tuple[int, str]] = []
    for line, raw in out:
        stmt = re.sub(r"\s*;\s*$", "", raw).strip()
        remark = stmt[1:].strip() if stmt.startswith("!") else None
        if remark is not None and remark.startswith("+") and joined and joined[-1][1].startswith("!"):
            joined[-1] = (joined[-1][0], joined[-1][1] + remark[1:])
        else:
            joined.append((line, "!" + remark if remark is not None else stmt))
    return joined


# ------------------------------------------------------------------ control flow

# What TP statements do to the flow: `END` ends the program (a called program returns to its
# caller), `ABORT` ends it, `PAUSE` stops it until it is started again, `JMP LBL[n]` continues at
# `LBL[n]`, `CALL NAME[(args)]` runs the program NAME (public TP grammar JTremblayAGT/fanuc-lsp@
# b0e9a1ea TPLangParser/TPLang/Instructions/TpBranchingInstruction.cs:8-57 (labels, JMP, CALL,
# IF, SELECT, IF ... THEN / ELSE / ENDIF, END) and TpProgControlInstruction.cs:20-26 (PAUSE,
# ABORT); RoboDK's R-30iA post writes `PAUSE ;` to "Pause the robot program" and
# `WAIT ... TIMEOUT, LBL[n]` / `LBL[n] ;`, ros-industrial-attic/robodk_postprocessors@d7e6c1c0
# Fanuc_R30iA.py:405-410, 474-479). A pause ends the verified cycle (flow.py).
_LBL = re.compile(r"^LBL\[\s*([0-9]+)\s*(?::[^\]]*)?\]$", re.IGNORECASE)
_JMP = re.compile(r"^JMP\s+LBL\[\s*([0-9]+)\s*(?::[^\]]*)?\]$", re.IGNORECASE)
_CALL_ANY = re.compile(r"^CALL\s+([A-Za-z_][A-Za-z0-9_]*)\s*(\((.*)\))?$", re.IGNORECASE)
# Speeds of a linear move in other units than mm/sec, as mm/s per unit.
_LINEAR_UNITS = {"mm/sec": 1.0, "cm/min": 10.0 / 60.0, "inch/min": 25.4 / 60.0}


def _classify(st: Statement) -> Flow:
    """What a TP statement does to the flow (`flow.Flow`)."""
    text = st.text
    if not text or text.startswith("!"):
        return Flow()
    word = text.split()[0].upper()
    if text.upper() == "END":
        return Flow("end", "END")
    if text.upper() == "ABORT":
        return Flow("end", "ABORT", scope="program")
    if text.upper() == "PAUSE":
        return Flow("end", "PAUSE", scope="program", pause=True)
    jump = _JMP.match(text)
    if jump:
        return Flow("goto", jump.group(1))
    label = _LBL.match(text)
    if label:
        return Flow("label", label.group(1))
    if re.match(r"^IF\b.*\bTHEN$", text, re.IGNORECASE) or word == "FOR":
        return Flow("open")
    if word in ("ENDIF", "ENDFOR"):
        return Flow("close")
    if word == "ELSE":
        return Flow()
    if word in ("IF", "SELECT") or text.startswith("=") or re.match(r"^ELSE\s*,", text, re.IGNORECASE):
        return Flow("unsupported", why="a conditional jump or call")
    if re.search(r"\bTIMEOUT\s*,\s*LBL\[", text, re.IGNORECASE):
        return Flow("unsupported", why="a wait that jumps when it times out")
    if word == "RUN":
        return Flow("unsupported", why="a program run beside this one")
    override = re.match(r"^OVERRIDE\s*=\s*([0-9.]+)\s*%$", text, re.IGNORECASE)
    if override:
        return Flow() if float(override.group(1)) == 100.0 else Flow("unsupported", why="a speed override")
    call = _CALL_ANY.match(text)
    if call and call.group(1).upper() not in ROUTINES:
        return Flow("call", call.group(1).upper(), arguments=bool((call.group(3) or "").strip()))
    return Flow()


def _program(text: str, source: str) -> Routine | None:
    """A TP program text as a routine: its /PROG name and its /MN statements."""
    lines = text.splitlines()
    head = next((re.match(r"^/PROG\s+(\S+)", ln) for ln in lines if ln.startswith("/PROG")), None)
    if head is None:
        return None
    mn = next((i for i, ln in enumerate(lines) if ln.strip() == "/MN"), len(lines))
    pos = next((i for i, ln in enumerate(lines) if ln.strip() == "/POS"), len(lines))
    body = tuple(Statement(line, stmt, source=source) for line, stmt in _statements(lines, mn + 1, pos))
    return Routine(head.group(1).upper(), body, (), source)


def _not_resting(routine: Routine) -> list[tuple[int, str, str]]:
    """(line, statement, why) of what a default routine (SPOT_WELD, GRIP, RELEASE) does besides
    resting for its second argument: remarks and one `WAIT AR[2]` (the routine `write` gives)."""
    waits = 0
    out: list[tuple[int, str, str]] = []
    for st in routine.body:
        if not st.text or st.text.startswith("!"):
            continue
        if re.fullmatch(r"WAIT\s+AR\[\s*2\s*\]", st.text, re.IGNORECASE) and waits == 0:
            waits += 1
            continue
        out.append((st.line, st.text, (f"{routine.name}: a weld or gripper routine that does more than rest its time "
                                       "(verify takes a call of it for the weld or action it names)")))
    if waits == 0:
        out.append((0, routine.name, f"{routine.name}: it does not rest its time (WAIT AR[2])"))
    return out


def parse(texts: dict[str, str], file: str, robot: RobotModel) -> Parsed:
    """A TP program's motion subset: J and L to P[] positions, FINE/CNT, CALL SPOT_WELD / GRIP /
    RELEASE, SpotTool+ SPOT[], WAIT; with its frames setup program when there is one."""
    lines = texts.get(".ls", "").splitlines()
    head = next((re.match(r"^/PROG\s+(\S+)", ln) for ln in lines if ln.startswith("/PROG")), None)
    if head is None:
        raise ProgramError(file, None, "no /PROG line: not a FANUC TP (.ls) program")
    try:
        mn_at = next(i for i, ln in enumerate(lines) if ln.strip() == "/MN")
    except StopIteration:
        raise ProgramError(file, None, "no /MN section") from None
    pos_at = next((i for i, ln in enumerate(lines) if ln.strip() == "/POS"), len(lines))
    positions = _positions("\n".join(lines[pos_at + 1:]))
    equipment = next((int(m.group(1)) for m in map(_EQUIPMENT.search, lines[:mn_at]) if m), 1)
    coupled = robot.controller.j23_coupling
    instructions: list[Instruction] = []
    where: list[int] = []
    at: list[int] = []                          # the statement (index) of each instruction
    ignored: list[tuple[int, str]] = []
    header_comments: list[str] = []
    registers: dict[int, dict[int, float]] = {}
    frames: list[FrameDef] = []
    active: dict[str, int | None] = {"UFRAME": None, "UTOOL": None}     # the selected numbers; None: unknown

    def error(line: int, problem: str) -> ProgramError:
        return ProgramError(file, f"line {line}", problem)

    def register_or_frame(stmt: str) -> bool:
        """PR elements, PR resets and UTOOL/UFRAME[n]=PR[m]: the frames' values (either text)."""
        element = _PR_ELEMENT.match(stmt)
        if element:
            registers.setdefault(int(element.group(1)), {})[int(element.group(2))] = float(element.group(3))
            return True
        reset = _PR_RESET.match(stmt)
        if reset:
            # LPOS, or a register minus itself: a Cartesian register whose elements are then set.
            registers[int(reset.group(1))] = {}
            return True
        frame = _FRAME_SET.match(stmt)
        if frame:
            kind, n = frame.group(1).upper(), int(frame.group(2))
            reg = registers.get(int(frame.group(3)), {})
            x, y, z, w, p, r = (reg.get(i, 0.0) for i in range(1, 7))
            name = f"{kind}[{n}]"
            frames[:] = [f for f in frames if f.name != name]
            frames.append(FrameDef(name, "tool" if kind == "UTOOL" else "base", (x, y, z), (r, p, w), n))
            return True
        return False

    setup_lines = texts.get(FRAMES_FILE, "").splitlines()
    setup_mn = next((i for i, ln in enumerate(setup_lines) if ln.strip() == "/MN"), len(setup_lines))
    setup_pos = next((i for i, ln in enumerate(setup_lines) if ln.strip() == "/POS"), len(setup_lines))
    for _, stmt in _statements(setup_lines, setup_mn + 1, setup_pos):
        register_or_frame(stmt)

    def add(ins: Instruction, number: int, statement: int) -> None:
        instructions.append(ins)
        where.append(number)
        at.append(statement)

    def not_simulated(number: int, statement: int, stmt: str, why: str = "") -> None:
        ignored.append((number, stmt))
        add(Comment(f"not simulated: {stmt}{why}"), number, statement)

    main = Routine(head.group(1).upper(), tuple(Statement(line, stmt) for line, stmt in _statements(lines, mn_at + 1, pos_at)))
    called = [r for r in (_program(texts.get(FRAMES_FILE, ""), FRAMES_FILE),) if r is not None]
    followed = follow(main, {r.name: r for r in called}, _classify, key=str.upper)
    leading = True                              # remarks before the first statement: the header
    for s, step in enumerate(followed.steps):
        number, stmt = step.line, step.statement.text
        if step.unsupported:
            leading = False
            not_simulated(number, s, stmt, f" ({step.unsupported})")
            continue
        if step.conditional and stmt and not stmt.startswith("!"):
            # Inside IF ... THEN / FOR: whether, or how often, it runs depends on a condition.
            not_simulated(number, s, stmt)
            continue
        if stmt.startswith("!"):
            remark = stmt[1:].strip()
            follows = bool(at) and at[-1] == s - 1
            if leading:
                header_comments.append(remark)
            elif follows and isinstance(instructions[-1], Spot) and instructions[-1].package:
                spot = instructions[-1]
                named = read_spot_label(remark.split(" gun ")[0], 0, 0.0, file, number)
                instructions[-1] = dataclasses.replace(spot, name=named.name, seam=named.seam)
            elif follows and isinstance(instructions[-1], Spot):
                n = int(instructions[-1].name[4:]) if instructions[-1].seam == "unnamed" else 0
                instructions[-1] = read_spot_label(remark, n, instructions[-1].time_s, file, number)
            elif follows and isinstance(instructions[-1], Gripper):
                last = instructions[-1]
                n = int(last.name[7:]) if last.seam == "unnamed" else 0
                instructions[-1] = read_gripper(last.action, remark, n, last.time_s, file, number)
            continue
        leading = False
        if not stmt:
            continue
        move = _MOVE.match(stmt)
        if _UNSIMULATED.match(stmt) or (move and _TARGET_OPTIONS.search(move.group(7) or "")):
            not_simulated(number, s, stmt)
            continue
        if move:
            kind, k, speed, unit = move.group(1).upper(), int(move.group(2)), float(move.group(3)), move.group(4).lower()
            cnt = 0 if move.group(5).upper() == "FINE" else int(move.group(6))
            options = move.group(7) or ""
            acc = re.search(r"ACC\s*([0-9]+)", options, re.IGNORECASE)
            # A called program's P[k] is in its own /POS.
            own = positions if step.statement.source == "" else _program_positions(texts.get(step.statement.source, ""))
            if k not in own:
                raise error(number, f"P[{k}] has no position in /POS"
                                    + ("" if step.statement.source == "" else f" of {step.statement.source}"))
            fields, config, numbers = own[k]
            if (kind == "J" and unit != "%") or (kind == "L" and unit not in _LINEAR_UNITS):
                # A move stated by its time (sec, msec) or by its orientation speed (deg/sec).
                not_simulated(number, s, stmt, f" (a {'joint' if kind == 'J' else 'linear'} move's speed in {unit})")
                continue
            if kind == "J" and all(f"J{i}" in fields for i in range(1, 7)):
                q = _from_controller(tuple(fields[f"J{i}"] for i in range(1, 7)), coupled)
                add(PtpMove(q, speed / 100, (float(acc.group(1)) if acc else 100.0) / 100, flyby=cnt * CNT_DEG), number, s)
            elif kind == "L" and all(c in fields for c in "XYZWPR"):
                speed *= _LINEAR_UNITS[unit]            # mm/sec
                uf, ut = numbers if numbers is not None else (active["UFRAME"], active["UTOOL"])
                mismatch = [f"{name} {n} is not the active {name}_NUM {active[name]}"
                            for name, n in (("UFRAME", uf), ("UTOOL", ut))
                            if active[name] is not None and n != active[name]]
                if mismatch:
                    # The controller stops at such a position with a frame number mismatch alarm.
                    not_simulated(number, s, stmt, f" (P[{k}]'s {'; '.join(mismatch)}: the controller stops with "
                                                   "a frame number mismatch alarm)")
                    continue
                # A program that selects no frame numbers runs only if the numbers left active by
                # whatever ran before match its positions': unknown here.
                add(LinMove((fields["X"], fields["Y"], fields["Z"]), (fields["R"], fields["P"], fields["W"]),
                            config, speed, flyby=cnt * CNT_DEG, accel=(float(acc.group(1)) if acc else 100.0) / 100,
                            tool=_frame_ref("UTOOL", ut if active["UTOOL"] is not None else None),
                            base=_frame_ref("UFRAME", uf if active["UFRAME"] is not None else None)), number, s)
            else:                          # a joint move to a Cartesian point, or the other way round
                not_simulated(number, s, stmt)
                continue
            spot_option = _SPOT.search(options)
            if spot_option:
                schedules = dict(part.split("=", 1) for part in spot_option.group(1).replace(" ", "").split(",")
                                 if "=" in part)
                if not schedules.get("S", "").isdigit():
                    raise error(number, f"SPOT[{spot_option.group(1)}] names no weld schedule S")
                n = sum(isinstance(i, Spot) for i in instructions) + 1
                add(Spot(f"spot{n}", "unnamed", 0.0, equipment, int(schedules["S"]), package=True), number, s)
            continue
        if re.match(r"^(J|L|C|A)\s", stmt):     # a motion in a form not read above (register speeds...)
            not_simulated(number, s, stmt)
            continue
        call = _CALL.match(stmt)
        if call:
            routine, n, seconds = call.group(1).upper(), int(call.group(2)), float(call.group(3))
            add(read_spot_label("", n, seconds, file, number) if routine == WEAPON
                else read_gripper(routine.lower(), "", n, seconds, file, number), number, s)
            continue
        wait = _WAIT.match(stmt)
        if wait:
            add(Wait(float(wait.group(1))), number, s)
            continue
        wait_di = _WAIT_DI.match(stmt)
        if wait_di:
            add(WaitFor((wait_di.group(2) or f"DI{wait_di.group(1)}").strip(), int(wait_di.group(1))), number, s)
            continue
        if re.match(r"^WAIT\b", stmt, re.IGNORECASE):
            # A wait on a register, a flag, an expression: how long it holds the robot is not known.
            not_simulated(number, s, stmt, " (a wait other than WAIT t(sec) or WAIT DI[k]=ON)")
            continue
        selected = _FRAME_NUM.match(stmt)
        if selected:
            active[selected.group(1).upper()] = int(selected.group(2))
            continue
        if register_or_frame(stmt):
            continue
        ignored.append((number, stmt))
    for name in ROUTINES:
        # A default routine shipped beside the program (SPOT_WELD.ls ...), where the program calls it:
        # reported at the first call, as that is where the program runs it.
        routine = _program(texts.get(f"{name}.ls", ""), f"{name}.ls")
        first = next((step.line for step in followed.steps
                      if re.match(rf"^CALL\s+{name}\b", step.statement.text, re.IGNORECASE)), None)
        if routine is None or first is None:
            continue
        for line, text, why in _not_resting(routine):
            where_in = f"{name}.ls line {line}: " if line else f"{name}.ls: "
            not_simulated(first, len(followed.steps), f"{where_in}{text}", f" ({why})")
    # The header's lines as `_header_statements` wrote them (continuations joined), ", " for " | ".
    header = read_header([t.replace(", ", " | ") for t in header_comments])
    return Parsed(Program(head.group(1), header, tuple(frames), tuple(instructions)), tuple(where), "fanuc",
                  tuple(ignored), tuple(followed.problems))


def _frame_ref(kind: str, number: int | None) -> str:
    """A position's frame as a name: `UTOOL[n]` / `UFRAME[n]`, the null frame for 0, unset when
    neither the position nor a *_NUM statement gives one."""
    if number is None:
        return UNSET_FRAME
    return NULL_FRAME if number == 0 else f"{kind}[{number}]"
