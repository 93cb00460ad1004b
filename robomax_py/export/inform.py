"""Yaskawa INFORM (a job file, `<NAME>.jbi`), both directions, and the default weld job `SPOTWELD.jbi`.

The job file's sections as the DX100 "Options: Instructions for Interface with an Easy Offline
Teaching System" (156191-1CD, HW0482494) and its NX100 edition (HW0481924) §4.1 "Job Data Format"
define them: `/JOB`, `//NAME`, `//POS` with `///NPOS C,BC,EC,P,BP,EX`, the pseudo instructions
`///TOOL n`, `///USER n`, `///POSTYPE PULSE|BASE|USER`, `///PULSE`, `///RECTAN`, `///RCONF` valid
for the positions that follow them, `C<5 digits>=...` teaching positions, then `//INST` with
`///DATE`, `///COMM` (at most 32 characters), `///ATTR`, `///GROUP1 RB1`, and the instructions
from `NOP` to `END`. Published jobs written the same way: RoboDK's Motoman post
(ros-industrial-attic/robodk_postprocessors@d7e6c1c0 Motoman.py:183-215 the header, 550-632 the
positions) and its example RoboDK/Industrial-Robots-VSCode@6b1e43c3 examples/PROGRAM.JBI.

What a program states:
- joint moves `MOVJ C<n> VJ=<%>` to pulse positions (`///POSTYPE PULSE`): each axis in encoder
  pulses, its angle (deg) times robot.yaml `controller.pulses_per_degree` (the controller's
  pulse/degree parameters, per axis), rounded to whole pulses; a robot that does not state them
  gets no INFORM program (a Cartesian position cannot fix R and T at the wrist singularity, where
  programs start: the home posture's B = 0);
- linear moves `MOVL C<n> V=<mm/s>` to Cartesian positions (`///RECTAN`): X, Y, Z in mm and Rx,
  Ry, Rz in deg, "rotating the specified coordinate system in the order of Rz, Ry and Rx" (DX100
  §4.3.1.1): R = Rz(Rz)·Ry(Ry)·Rx(Rx), robomax's ZYX angles (a, b, c) = (Rz, Ry, Rx), with the
  manipulator type `///RCONF l,m,n,o,p,q,0,0` (`robot.ik.config.yaskawa_rconf`);
- frames by number, the values being the controller's (the integrator calibrates tool t and user
  frame u; the job lists them as comments): every position carries `///TOOL t`; a position in the
  user frame `///USER u` with `///POSTYPE USER`, else `///POSTYPE BASE` (the robot's base
  coordinates, the robot base frame on a controller without base axes). NX100: tool and user
  frame numbers 0..23; the robot's placement in the cell is never written;
- `PL=0` at every stop (positioning level 0: the robot stops at the point); a fly-by as the corner
  radius `CR=<mm>` of the planned blend (one decimal). Positioning levels 1..8 blend by distances
  the controller's parameters (S1CxG033-040) hold, which a program cannot state; the `CR=` tag is
  the DX100/YRC1000 corner radius (its manual text was not available: UNCONFIRMED);
- `VJ=` in % with 2 decimals, `V=` in mm/s with 1 decimal; waits `TIMER T=<s>` (2 decimals,
  rounded up) and `WAIT IN#(<k>)=ON` (general input k of the cell's `robot.controller.inputs`);
  a station's interlock outputs `DOUT OT#(<k>) ON` / `OFF` (general output k of
  `robot.controller.outputs`), after a `PL=0` point;
- a weld (`weld: call`) as `MOVL ... PL=0`, then `CALL JOB:SPOTWELD ARGF<n> ARGF<time>` and the
  comment `'seam/name gun G schedule S`; SPOTWELD.jbi takes its second argument (`GETARG LR000
  IARG#(2)`) and rests that long (`TIMER T=LR000`): the job call with arguments is a DX100 option
  (UNCONFIRMED here); with `weld: package` the weld is the servo gun instruction
  `SVSPOT GUN#(<gun>) PRESS#(1) WTM=<schedule> WST=0` (spot welding option; UNCONFIRMED);
- comments `'text` of at most 32 characters, longer texts continued on `'+` lines
  (`fanuc.remarks`).

The reader takes these files and other writers' (RoboDK's): MOVJ / MOVL to C positions (pulse or
Cartesian), VJ=, V=, PL=, CR=, TIMER T=, WAIT IN#(k)=ON, DOUT OT#(k) ON/OFF, the weld calls; NOP
and END; other instructions (DOUT of other signal kinds, MSG, PAUSE, SET..., jumps, calls of other jobs, MOVC, MOVS) are reported as
not simulated or ignored (an END stops the job, PAUSE stops the verified cycle).
"""

from __future__ import annotations

import dataclasses
import math
import re

from robomax_py.errors import ControllerSetupError, ExportError, ProgramError
from robomax_py.export.dialect import (
    Parsed,
    PlannedProgram,
    SignalNumbers,
    controller_identifier,
    header_lines,
    numbered_frames,
    numbered_inputs,
    numbered_outputs,
    read_header,
    read_spot_label,
    require_six_axes,
    spot_label,
    with_brand_configs,
    with_frame_names,
    with_package_welds,
    with_tcp_blends,
    without_comments,
)
from robomax_py.export.fanuc import remarks
from robomax_py.program import (
    NULL_FRAME,
    UNSET_FRAME,
    Comment,
    FrameDef,
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

__all__ = ["ROUTINES", "SIGNALS", "adapt", "frame_name", "needs", "parse", "program_name", "write"]

NAME_CHARS = 32              # a job name (DX100; the NX100 took 8)
TOOL_SLOTS, USER_SLOTS = 23, 23       # ///TOOL 0..23, ///USER 0..23 (NX100 §4.1.3)
INPUTS = 1024                # general inputs IN#(1..)
OUTPUTS = 1024               # general outputs OT#(1..)
SIGNALS = SignalNumbers("INFORM", (1, INPUTS), (1, OUTPUTS))
WELD_JOB = "SPOTWELD"
ROUTINES = (WELD_JOB,)
ANGLE_DECIMALS = 4           # Rx, Ry, Rz (RoboDK writes 2; robomax's angles carry 4)
EXT = ".jbi"
NO_DATE = "2000/01/01 00:00"


def frame_name(frame: FrameDef) -> str:
    """How a job refers to a stored frame: `TOOL[n]` / `USER[n]`."""
    return f"{'TOOL' if frame.kind == 'tool' else 'USER'}[{frame.number}]"


def program_name(name: str) -> str:
    """The job a cell's program becomes: capitals, digits and `_`, a letter first, at most NAME_CHARS."""
    return controller_identifier(name, upper=True, max_chars=NAME_CHARS, reserved=tuple(ROUTINES))


def _number(name: str) -> int:
    if name == UNSET_FRAME:
        raise ExportError("an INFORM position names its tool and user frame: the program selects none")
    match = re.search(r"\[([0-9]+)\]", name)
    return int(match.group(1)) if match else 0


PULSES_KEY = "controller.pulses_per_degree"
PULSES_WHY = "INFORM joint positions count encoder pulses (the controller's pulse/degree parameters, 6 axes)"


def needs(robot: RobotModel) -> tuple[tuple[str, str], ...]:
    """What robot.yaml must state for a job and `robot` does not: its encoder pulses per degree."""
    return () if len(robot.controller.pulses_per_degree) == 6 else ((PULSES_KEY, PULSES_WHY),)


def _pulses(robot: RobotModel) -> tuple[float, ...]:
    ppd = robot.controller.pulses_per_degree
    if len(ppd) != 6:
        raise ExportError(f"--format inform: {robot.source}: {PULSES_KEY} is not given for {robot.name}: {PULSES_WHY}")
    return ppd


def _to_pulses(q_deg: tuple[float, ...], ppd: tuple[float, ...]) -> tuple[int, ...]:
    return tuple(round(v * k) for v, k in zip(q_deg, ppd))


def _from_pulses(pulses: tuple[int, ...], ppd: tuple[float, ...]) -> tuple[float, ...]:
    return tuple(p / k for p, k in zip(pulses, ppd))


def _wait_s(seconds: float) -> float:
    return math.ceil(round(seconds * 100, 6)) / 100


def adapt(planned: PlannedProgram, robot: RobotModel) -> Program:
    """The program as a job states it: numbered frames, pulses, Yaskawa RCONF, CR blends (mm),
    V= mm/s with 1 decimal, VJ= % with 2, TIMER in 0.01 s."""
    require_six_axes(robot, "INFORM")
    ppd = _pulses(robot)
    numbered_frames(planned.program, "INFORM", TOOL_SLOTS, USER_SLOTS)
    numbered_inputs(planned.program, SIGNALS.label, *SIGNALS.inputs)
    numbered_outputs(planned.program, SIGNALS.label, *SIGNALS.outputs)
    program = with_tcp_blends(planned, robot)
    program = with_package_welds(with_frame_names(program, frame_name), "INFORM")
    program = without_comments(with_brand_configs(program, planned.joints, robot, "yaskawa"))
    out: list[Instruction] = []
    for ins in program.instructions:
        if isinstance(ins, PtpMove):
            ins = dataclasses.replace(ins, target_deg=_from_pulses(_to_pulses(ins.target_deg, ppd), ppd),
                                      speed=max(0.001, round(ins.speed * 100, 1) / 100), accel=1.0,
                                      flyby_mm=round(ins.flyby_mm, 1))
        elif isinstance(ins, LinMove):
            ins = dataclasses.replace(ins, speed_mm_s=max(0.1, round(ins.speed_mm_s, 1)), accel=1.0,
                                      flyby_mm=round(ins.flyby_mm, 1))
        elif isinstance(ins, Wait):
            ins = Wait(_wait_s(ins.seconds))
        elif isinstance(ins, WaitFor):
            ins = WaitFor(f"IN{ins.number}", ins.number)
        elif isinstance(ins, SetSignal):
            ins = SetSignal(f"OT{ins.number}", ins.number, ins.value)     # INFORM names outputs by number only
        elif not isinstance(ins, (Spot, Comment)):
            raise ControllerSetupError("robot.controller", f"INFORM cannot state {type(ins).__name__}")
        out.append(ins)
    setup = dataclasses.replace(program.setup, listed=program.frames)
    return dataclasses.replace(program, name=program_name(program.name), frames=(), instructions=tuple(out),
                               setup=setup)


# ================================================================================== writing


def _comments(text: str) -> list[str]:
    return [f"'{piece}" for piece in remarks(text)]


def _num(value: float, decimals: int) -> str:
    return f"{value + 0.0:.{decimals}f}"


def write(program: Program, robot: RobotModel) -> dict[str, str]:
    ppd = _pulses(robot)
    pos: list[str] = []
    inst: list[str] = []
    state: tuple[object, ...] = ()
    k = calls = 0
    for f in program.setup.listed:
        x, y, z = (_num(v, 3) for v in f.xyz_mm)
        a, b, c = (_num(v, ANGLE_DECIMALS) for v in f.zyx_deg)
        inst += _comments(f"{f.name} {x},{y},{z},{c},{b},{a}")
    for ins in program.instructions:
        if isinstance(ins, (PtpMove, LinMove)):
            end = f" CR={_num(ins.flyby_mm, 1)}" if ins.flyby_mm > 0 else " PL=0"
            if isinstance(ins, PtpMove):
                head: tuple[object, ...] = ("pulse", _number(_tool_of(program)))
                if head != state:
                    pos += [f"///TOOL {head[1]}", "///POSTYPE PULSE", "///PULSE"]
                pos.append(f"C{k:05d}=" + ",".join(str(p) for p in _to_pulses(ins.target_deg, ppd)))
                inst.append(f"MOVJ C{k:05d} VJ={_num(ins.speed * 100, 2)}{end}")
            else:
                user, tool = _number(ins.base), _number(ins.tool)
                head = ("rectan", tool, user, ins.config)
                if head != state:
                    if user:
                        pos.append(f"///USER {user}")
                    pos += [f"///TOOL {tool}", f"///POSTYPE {'USER' if user else 'BASE'}", "///RECTAN",
                            f"///RCONF {ins.config}"]
                rz, ry, rx = ins.zyx_deg
                values = [*(_num(v, 3) for v in ins.position_mm), *(_num(v, ANGLE_DECIMALS) for v in (rx, ry, rz))]
                pos.append(f"C{k:05d}=" + ",".join(values))
                inst.append(f"MOVL C{k:05d} V={_num(ins.speed_mm_s, 1)}{end}")
            state = head
            k += 1
        elif isinstance(ins, Spot) and ins.package:
            inst += [f"SVSPOT GUN#({ins.gun}) PRESS#(1) WTM={ins.schedule} WST=0",
                     *_comments(f"{ins.seam}/{ins.name}")]
        elif isinstance(ins, Spot):
            calls += 1
            inst += [f"CALL JOB:{WELD_JOB} ARGF{calls} ARGF{_num(ins.time_s, 3)}", *_comments(spot_label(ins))]
        elif isinstance(ins, Wait):
            inst.append(f"TIMER T={_num(ins.seconds, 2)}")
        elif isinstance(ins, WaitFor):
            inst.append(f"WAIT IN#({ins.number})=ON")
        elif isinstance(ins, SetSignal):
            # DOUT OT#(k) ON / OFF: general output k; after a PL=0 point the robot has stopped.
            inst.append(f"DOUT OT#({ins.number}) {'ON' if ins.value else 'OFF'}")
        elif not isinstance(ins, Comment):
            raise ExportError(f"INFORM cannot write {type(ins).__name__}")
    header = [c for line in header_lines(program.header) for c in _comments(line.replace(" | ", ", "))]
    out = {EXT: _job(program.name, "robomax_py", pos, k, header + inst, program.header.stamp)}
    out[f"{WELD_JOB}{EXT}"] = _job(WELD_JOB, "default weld", [], 0, [
        "'default weld: rests ARGF 2 s", "'replace with the gun's job", "GETARG LR000 IARG#(2)", "TIMER T=LR000"], "")
    return out


def _tool_of(program: Program) -> str:
    first = next((i for i in program.instructions if isinstance(i, LinMove)), None)
    return first.tool if first is not None else NULL_FRAME


def _job(name: str, comment: str, pos: list[str], n_pos: int, inst: list[str], stamp: str) -> str:
    if len(name) > NAME_CHARS:
        raise ExportError(f"INFORM: job name {name} is too long")
    date = NO_DATE
    match = re.match(r"^([0-9]{4})-([0-9]{2})-([0-9]{2})", stamp)
    if match:
        date = f"{match.group(1)}/{match.group(2)}/{match.group(3)} 00:00"
    lines = ["/JOB", f"//NAME {name}", "//POS", f"///NPOS {n_pos},0,0,0,0,0", *pos, "//INST", f"///DATE {date}",
             f"///COMM {comment}", "///ATTR SC,RW", "///GROUP1 RB1", "NOP", *inst, "END"]
    return "\r\n".join(lines) + "\r\n"


# ================================================================================== reading

_C = re.compile(r"^C([0-9]{4,5})\s*=\s*(.*)$")
_MOVE = re.compile(r"^(MOVJ|MOVL)\s+C([0-9]{4,5})\b(.*)$", re.IGNORECASE)
_TAG = re.compile(r"\b(VJ|V|PL|CR)\s*=\s*([0-9]*\.?[0-9]+)", re.IGNORECASE)
_TIMER = re.compile(r"^TIMER\s+T\s*=\s*([0-9]*\.?[0-9]+)$", re.IGNORECASE)
_DOUT = re.compile(r"^DOUT\s+OT#\(\s*([0-9]+)\s*\)\s+(ON|OFF)$", re.IGNORECASE)
_WAIT_IN = re.compile(r"^WAIT\s+IN#\(\s*([0-9]+)\s*\)\s*=\s*ON$", re.IGNORECASE)
_WELD = re.compile(rf"^CALL\s+JOB:{WELD_JOB}\s+ARGF\s*([0-9]+)\s+ARGF\s*([0-9]*\.?[0-9]+)$", re.IGNORECASE)
_SVSPOT = re.compile(r"^SVSPOT\s+GUN#\(\s*([0-9]+)\s*\).*\bWTM\s*=\s*([0-9]+)", re.IGNORECASE)
# Motions the reader does not simulate, and control flow that makes the motion depend on what it
# cannot follow.
_UNSIMULATED = re.compile(r"^(MOVC|MOVS|IMOV|REFP|JUMP|CALL|IF|PAUSE|SFTON)\b|^(MOVJ|MOVL)\b", re.IGNORECASE)


def _positions(lines: list[str]) -> dict[int, tuple[str, tuple[float, ...], int, int, str]]:
    """C<n> -> (kind "pulse" | "base" | "user" | "robot" ..., values, tool, user, RCONF)."""
    out: dict[int, tuple[str, tuple[float, ...], int, int, str]] = {}
    tool = user = 0
    postype, rconf = "pulse", ""
    for raw in lines:
        ln = raw.strip()
        word = ln.split()[0].upper() if ln else ""
        value = ln.split(None, 1)[1].strip() if len(ln.split(None, 1)) > 1 else ""
        if word == "///TOOL":
            tool = int(value)
        elif word == "///USER":
            user = int(value)
        elif word == "///POSTYPE":
            postype = value.lower()
        elif word == "///PULSE":
            postype = "pulse"
        elif word == "///RCONF":
            rconf = ",".join(v.strip() for v in value.split(","))
        else:
            match = _C.match(ln)
            if match:
                out[int(match.group(1))] = (postype, tuple(float(v) for v in match.group(2).split(",")), tool, user,
                                            rconf)
    return out


def parse(texts: dict[str, str], file: str, robot: RobotModel) -> Parsed:
    """A job's motion subset: MOVJ / MOVL to C positions, PL / CR, TIMER, WAIT IN#, weld calls."""
    lines = texts.get(EXT, "").splitlines()
    if not lines or lines[0].strip().upper() != "/JOB":
        raise ProgramError(file, None, "no /JOB line: not a Yaskawa INFORM job")
    name = next((ln.split(None, 1)[1].strip() for ln in lines if ln.startswith("//NAME")), "")
    try:
        at = next(i for i, ln in enumerate(lines) if ln.strip().upper() == "//INST")
    except StopIteration:
        raise ProgramError(file, None, "no //INST section") from None
    positions = _positions(lines[:at])
    ppd = robot.controller.pulses_per_degree
    instructions: list[Instruction] = []
    where: list[int] = []
    ignored: list[tuple[int, str]] = []
    problems: list[tuple[int, str, str]] = []

    def add(ins: Instruction, line: int) -> None:
        instructions.append(ins)
        where.append(line)

    def not_simulated(line: int, stmt: str, why: str = "") -> None:
        ignored.append((line, stmt))
        add(Comment(f"not simulated: {stmt}{why}"), line)

    body: list[tuple[int, str]] = []              # (line, statement), comment continuations joined
    started = False
    for index in range(at + 1, len(lines)):
        stmt = lines[index].strip()
        if not stmt or stmt.startswith("///"):
            continue
        if not started:
            started = stmt.upper() == "NOP"
            continue
        if stmt.startswith("'+") and body and body[-1][1].startswith("'"):
            body[-1] = (body[-1][0], body[-1][1] + stmt[2:])
            continue
        body.append((index + 1, stmt))
        if stmt.upper() == "END":
            break
    header_comments: list[str] = []
    leading = True
    for s, (number, stmt) in enumerate(body):
        if stmt.upper() == "END":
            break
        if stmt.startswith("'"):
            text = stmt[1:]
            follows = bool(where) and s > 0 and body[s - 1][0] == where[-1]
            if leading:
                header_comments.append(text)
            elif follows and isinstance(instructions[-1], Spot):
                last = instructions[-1]
                n = int(last.name[4:]) if last.seam == "unnamed" else 0
                named = read_spot_label(text.split(" gun ")[0] if last.package else text, n, last.time_s, file, number)
                instructions[-1] = (dataclasses.replace(last, name=named.name, seam=named.seam) if last.package
                                    else named)
            continue
        leading = False
        move = _MOVE.match(stmt)
        if move:
            kind, k, rest = move.group(1).upper(), int(move.group(2)), move.group(3)
            if k not in positions:
                raise ProgramError(file, f"line {number}", f"C{k:05d} has no position in //POS")
            postype, values, tool, user, rconf = positions[k]
            tags = {m.group(1).upper(): float(m.group(2)) for m in _TAG.finditer(rest)}
            if tags.get("PL", 0.0) > 0 and "CR" not in tags:
                # Positioning levels blend by distances the controller's parameters hold.
                not_simulated(number, stmt, " (a positioning level's blend distance is the controller's parameter)")
                continue
            flyby = tags.get("CR", 0.0)
            if kind == "MOVJ" and postype == "pulse" and len(values) >= 6 and "VJ" in tags:
                if len(ppd) != 6:
                    not_simulated(number, stmt, " (pulses, and robot.yaml states no controller.pulses_per_degree)")
                    continue
                q = _from_pulses(tuple(int(v) for v in values[:6]), ppd)
                add(PtpMove(q, tags["VJ"] / 100, 1.0, flyby_mm=flyby), number)
            elif kind == "MOVL" and postype in ("base", "user") and len(values) >= 6 and "V" in tags:
                rx, ry, rz = values[3:6]
                add(LinMove(values[:3], (rz, ry, rx), rconf, tags["V"], flyby_mm=flyby,
                            tool=_frame_ref("TOOL", tool), base=_frame_ref("USER", user if postype == "user" else 0)),
                    number)
            else:
                not_simulated(number, stmt, f" ({kind} to a {postype} position)")
            continue
        timer = _TIMER.match(stmt)
        if timer:
            add(Wait(float(timer.group(1))), number)
            continue
        wait = _WAIT_IN.match(stmt)
        if wait:
            add(WaitFor(f"IN{wait.group(1)}", int(wait.group(1))), number)
            continue
        dout = _DOUT.match(stmt)
        if dout:
            add(SetSignal(f"OT{dout.group(1)}", int(dout.group(1)), dout.group(2).upper() == "ON"), number)
            continue
        weld = _WELD.match(stmt)
        if weld:
            add(read_spot_label("", int(weld.group(1)), float(weld.group(2)), file, number), number)
            continue
        spot = _SVSPOT.match(stmt)
        if spot:
            n = sum(isinstance(i, Spot) for i in instructions) + 1
            add(Spot(f"spot{n}", "unnamed", 0.0, int(spot.group(1)), int(spot.group(2)), package=True), number)
            continue
        if stmt.upper() == "PAUSE":
            problems.append((number, "flow", "PAUSE stops the job until it is started again"))
            not_simulated(number, stmt)
            break
        if _UNSIMULATED.match(stmt):
            not_simulated(number, stmt)
            continue
        ignored.append((number, stmt))
    header = read_header([c.replace(", ", " | ") for c in header_comments])
    # A job states joint positions in whole pulses: one is 1/ppd deg (2e-3 deg on a wrist axis of
    # 455 pulses/deg), coarser than the home check's 1e-6 rad.
    step = tuple(math.radians(1.0 / p) for p in ppd) if len(ppd) == 6 else ()
    return Parsed(Program(name, header, (), tuple(instructions)), tuple(where), "yaskawa", tuple(ignored),
                  tuple(problems), joint_step=step)


def _frame_ref(kind: str, number: int) -> str:
    return NULL_FRAME if number == 0 else f"{kind}[{number}]"
