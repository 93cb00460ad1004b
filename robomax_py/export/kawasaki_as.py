"""Kawasaki AS (a program file `<name>.as`, as `.pg` files hold too), both directions.

What a program states, in AS's terms (Kawasaki Robot Controller D Series, AS Language Reference
Manual, 902091017DEB; RoboDK's Kawasaki post, ros-industrial-attic/robodk_postprocessors@d7e6c1c0
Kawasaki.py:49-60, 85-91, 105-185, and its example RoboDK/Industrial-Robots-VSCode@6b1e43c3
examples/Kawasaki.pg):
- `.PROGRAM name()` ... `.END` blocks, one file holding the program and its weld and gripper
  routines; comments after `;`;
- joint moves `JMOVE #[j1, ..., j6]` to joint locations (deg, 4 decimals): the joint values are
  the configuration, turns included; linear moves `LMOVE TRANS(x, y, z, o, a, t)`, mm and the
  Euler angles O, A, T in deg with R = Rz(O)·Ry(A)·Rz(T) (z, y', z''; RoboDK robomath
  Adept_2_Pose, RoboDK/RoboDK-API@84099bba Python/robodk/robomath.py:815-835, and Roboception's
  "Kawasaki XYZ-OAT format" page agree), mm with 3 decimals and O, A, T with 5. RoboDK's post
  writes 4 (Kawasaki.py:55), too few: the ZYX angles (4 decimals) turned into OAT rounded to 4
  come back changed by up to 1e-4 deg, beyond verify's orientation tolerance of 1e-6 rad
  (5.7e-5 deg) for a spot the planner put at its tolerance's edge; rounded to 5 (at most 3e-7
  rad off) they come back as written away from ZYX's gimbal lock (|B| < 60 deg). A transformation location carries no
  configuration: along a straight line the arm keeps its own (the configuration instructions
  LEFTY ... DWRIST act on the next joint-interpolated motion), so LMOVE targets state none
  (`robot.ik.config.kawasaki_config` names the branch for SRCL);
- frames: `TOOL <name>` with `POINT <name> = TRANS(...)` the TCP in the flange frame, and
  `BASE <name>` / `BASE NULL`. AS's BASE is "the base coordinates relative to the null base
  coordinates": the null base is the robot's own base frame, and every transformation location is
  relative to the base coordinates. AS has no user frame besides it, so BASE is the program's user
  frame of docs/cell-files.md, "Controller programs": the cell's user frame in the robot base frame, or NULL (the robot base frame
  itself); the robot's placement in the cell is never written. Names `tool<n>` / `base<n>` after
  the cell's frame numbers;
- per motion (no ALWAYS: "applies to the next motion only"): `SPEED <%>` (joint moves, whole % of
  the maximum, 1 decimal) or `SPEED <v> MM/S` (linear, 1 decimal), and `ACCURACY <mm>`: a fly-by
  as the planned blend's TCP distance (1 decimal), and `ACCURACY 1 FINE` at every stop; a motion
  slower to accelerate than the axes allow (a part in the gripper: robot.yaml `limits.loaded`)
  `ACCEL <%>` and `DECEL <%>` (1 decimal), the share of the maximum acceleration and deceleration
  the next motion uses (RoboDK's post writes the same statement, robodk_postprocessors@d7e6c1c0
  Kawasaki.py:163-167; without it the controller accelerates at 100 % and every later event comes
  early);
- a weld (`weld: call`) as the stop, then `CALL spot_weld(n, weld_time) ; seam/name gun G
  schedule S`, `.PROGRAM spot_weld(n, t)` resting `TWAIT t`; grippers `CALL grip(n, t)` /
  `CALL release(n, t)` alike; `weld: package` has no AS form here;
- waits `TWAIT t` (3 decimals) and `SWAIT <1000 + k> ; <signal>`, external input k (AS numbers
  external inputs from 1001); a station's interlock output `BREAK` then `SIGNAL k ; <signal>`
  (`SIGNAL -k` off), external output k: AS runs the program ahead of the motion, and BREAK holds
  it until the robot has stopped.

The reader takes these programs and other writers' (RoboDK's: `SPEED ... ALWAYS`, `ACCURACY ...
ALWAYS`, `TWAIT`, `WAIT SIG(n)`, `BASE TRANS(...)`, `TOOL TRANS(...)`); JMOVE to a transformation
location, circular moves, calls of other programs and control flow are reported, not simulated.
"""

from __future__ import annotations

import dataclasses
import math
import re

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.errors import ControllerSetupError, ExportError, ProgramError
from robomax_py.export.dialect import (
    Parsed,
    PlannedProgram,
    controller_identifier,
    gripper_label,
    header_lines,
    numbered_inputs,
    numbered_outputs,
    read_gripper,
    read_header,
    read_spot_label,
    require_six_axes,
    spot_label,
    with_frame_names,
    with_tcp_blends,
    without_comments,
)
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
    SetSignal,
    Spot,
    Wait,
    WaitFor,
)
from robomax_py.robot import RobotModel

__all__ = ["adapt", "frame_name", "matrix_from_oat", "oat_from_matrix", "oat_from_zyx", "parse", "write",
           "zyx_from_oat"]

INPUT_BASE = 1000            # external input k is signal 1000 + k
ANGLE_DECIMALS = 5
EXT = ".as"
ROUTINES = ("spot_weld", "grip", "release")


def _rz(a: float) -> FloatArray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _ry(a: float) -> FloatArray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _rx(a: float) -> FloatArray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def matrix_from_oat(oat_deg: tuple[float, ...]) -> FloatArray:
    """(3, 3) rotation of AS's O, A, T (deg): Rz(O)·Ry(A)·Rz(T)."""
    o, a, t = (math.radians(v) for v in oat_deg)
    out: FloatArray = _rz(o) @ _ry(a) @ _rz(t)
    return out


def oat_from_matrix(R: FloatArray) -> tuple[float, float, float]:
    """Inverse of `matrix_from_oat`: A in [0, 180] deg; at A = 0 or 180 the whole turn is on O."""
    R = np.asarray(R, dtype=float)
    sin_a = math.hypot(R[0, 2], R[1, 2])
    a = math.atan2(sin_a, R[2, 2])
    if sin_a < 1e-12:
        o = math.atan2(R[1, 0], R[0, 0]) if R[2, 2] > 0 else math.atan2(-R[1, 0], -R[0, 0])
        return math.degrees(o), math.degrees(a), 0.0
    o = math.atan2(R[1, 2], R[0, 2])
    t = math.atan2(R[2, 1], -R[2, 0])
    return math.degrees(o), math.degrees(a), math.degrees(t)


def _zyx_matrix(zyx_deg: tuple[float, ...]) -> FloatArray:
    a, b, c = (math.radians(v) for v in zyx_deg)
    out: FloatArray = _rz(a) @ _ry(b) @ _rx(c)
    return out


def oat_from_zyx(zyx_deg: tuple[float, ...]) -> tuple[float, ...]:
    """robomax's ZYX angles (A, B, C: Rz·Ry·Rx) as AS's O, A, T, rounded as the program writes them."""
    return tuple(round(v, ANGLE_DECIMALS) + 0.0 for v in oat_from_matrix(_zyx_matrix(zyx_deg)))


def zyx_from_oat(oat_deg: tuple[float, ...]) -> tuple[float, float, float]:
    """AS's O, A, T as robomax's ZYX angles (deg)."""
    R = matrix_from_oat(oat_deg)
    b = math.atan2(-R[2, 0], math.hypot(R[0, 0], R[1, 0]))
    if math.hypot(R[0, 0], R[1, 0]) < 1e-12:
        return math.degrees(math.atan2(-R[0, 1], R[1, 1])), math.degrees(b), 0.0
    return math.degrees(math.atan2(R[1, 0], R[0, 0])), math.degrees(b), math.degrees(math.atan2(R[2, 1], R[2, 2]))


def frame_name(frame: FrameDef) -> str:
    """The AS variable a program holds a frame in: `tool<n>` / `base<n>`."""
    return f"{'tool' if frame.kind == 'tool' else 'base'}{frame.number}"


def _program_name(name: str) -> str:
    return controller_identifier(name, upper=False, max_chars=15, reserved=tuple(ROUTINES))    # AS names: 15 characters


def adapt(planned: PlannedProgram, robot: RobotModel) -> Program:
    """The program as AS states it: frames as variables, OAT angles, ACCURACY blends (mm), speeds
    with 1 decimal, no configuration on transformation locations."""
    require_six_axes(robot, "AS")
    if planned.program.setup.weld == "package":
        raise ControllerSetupError("robot.controller.weld", "AS programs weld with a call of spot_weld (weld: call)")
    numbered_inputs(planned.program, "AS", 1, 999)
    numbered_outputs(planned.program, "AS", 1, 999)
    program = without_comments(with_frame_names(with_tcp_blends(planned, robot), frame_name))
    out: list[Instruction] = []
    for ins in program.instructions:
        if isinstance(ins, PtpMove):
            ins = dataclasses.replace(ins, speed=max(0.001, round(ins.speed * 100, 1) / 100), accel=_accel(ins.accel),
                                      flyby_mm=round(ins.flyby_mm, 1))
        elif isinstance(ins, LinMove):
            ins = dataclasses.replace(ins, zyx_deg=zyx_from_oat(oat_from_zyx(ins.zyx_deg)), config="",
                                      speed_mm_s=max(0.1, round(ins.speed_mm_s, 1)), accel=_accel(ins.accel),
                                      flyby_mm=round(ins.flyby_mm, 1))
        out.append(ins)
    frames = tuple(dataclasses.replace(f, zyx_deg=zyx_from_oat(oat_from_zyx(f.zyx_deg))) for f in program.frames)
    return dataclasses.replace(program, name=_program_name(program.name), frames=frames, instructions=tuple(out))


def _accel(fraction: float) -> float:
    """An acceleration share as ACCEL states it: % with 1 decimal, 0.1 to 100."""
    return max(0.1, min(100.0, round(fraction * 100, 1))) / 100


# ================================================================================== writing


def _num(value: float, decimals: int) -> str:
    return f"{value + 0.0:.{decimals}f}"


def _trans(xyz: tuple[float, ...], zyx: tuple[float, ...]) -> str:
    values = [*(_num(v, 3) for v in xyz), *(_num(v, ANGLE_DECIMALS) for v in oat_from_zyx(zyx))]
    return f"TRANS({','.join(values)})"


def write(program: Program, robot: RobotModel) -> dict[str, str]:
    body = [f"; {line}" for line in header_lines(program.header)]
    for f in program.frames:
        body.append(f"POINT {f.name} = {_trans(f.xyz_mm, f.zyx_deg)}")
    tool = base = UNSET_FRAME
    calls: dict[str, int] = {}
    for ins in program.instructions:
        if isinstance(ins, (PtpMove, LinMove)):
            accuracy = f"ACCURACY {_num(ins.flyby_mm, 1)}" if ins.flyby_mm > 0 else "ACCURACY 1 FINE"
            if ins.accel < 1.0:
                body += [f"ACCEL {_num(ins.accel * 100, 1)}", f"DECEL {_num(ins.accel * 100, 1)}"]
            if isinstance(ins, PtpMove):
                body += [f"SPEED {_num(ins.speed * 100, 1)}", accuracy,
                         "JMOVE #[" + ",".join(_num(v, 4) for v in ins.target_deg) + "]"]
            else:
                if ins.tool != tool:
                    tool = ins.tool
                    body.append(f"TOOL {tool or 'NULL'}")
                if ins.base != base:
                    base = ins.base
                    body.append(f"BASE {base or 'NULL'}")
                body += [f"SPEED {_num(ins.speed_mm_s, 1)} MM/S", accuracy,
                         f"LMOVE {_trans(ins.position_mm, ins.zyx_deg)}"]
        elif isinstance(ins, Spot):
            calls["spot_weld"] = calls.get("spot_weld", 0) + 1
            body.append(f"CALL spot_weld({calls['spot_weld']},{_num(ins.time_s, 3)}) ; {spot_label(ins)}")
        elif isinstance(ins, Gripper):
            calls[ins.action] = calls.get(ins.action, 0) + 1
            body.append(f"CALL {ins.action}({calls[ins.action]},{_num(ins.time_s, 3)}) ; {gripper_label(ins)}")
        elif isinstance(ins, Wait):
            body.append(f"TWAIT {_num(ins.seconds, 3)}")
        elif isinstance(ins, WaitFor):
            body.append(f"SWAIT {INPUT_BASE + (ins.number or 0)} ; {ins.signal}")
        elif isinstance(ins, SetSignal):
            # AS reads ahead of the motion: BREAK holds the program until the robot has stopped,
            # then SIGNAL k turns external output k on (SIGNAL -k off).
            body += ["BREAK", f"SIGNAL {'' if ins.value else '-'}{ins.number} ; {ins.signal}"]
        elif not isinstance(ins, Comment):
            raise ExportError(f"AS cannot write {type(ins).__name__}")
    lines = [f".PROGRAM {program.name}()", *(f"  {b}" for b in body), ".END"]
    for routine in ("spot_weld", *sorted(k for k in calls if k != "spot_weld")):
        note = f"  ; default {routine.replace('_', ' ')}: rests t s, for the integrator to replace"
        lines += [f".PROGRAM {routine}(n,t)", note, "  TWAIT t", ".END"]
    return {EXT: "\r\n".join(lines) + "\r\n"}


# ================================================================================== reading

_PROGRAM = re.compile(r"^\.PROGRAM\s+([A-Za-z_][A-Za-z0-9_.]*)\s*(\(([^)]*)\))?", re.IGNORECASE)
_NUM = r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?"
_TRANS = re.compile(rf"^TRANS\s*\(\s*({_NUM}(?:\s*,\s*{_NUM}){{5}})\s*\)$", re.IGNORECASE)
_JOINTS = re.compile(rf"^#\[\s*({_NUM}(?:\s*,\s*{_NUM})*)\s*\]$")
_POINT = re.compile(r"^POINT\s+([A-Za-z_][A-Za-z0-9_.]*)\s*=\s*(.+)$", re.IGNORECASE)
_SPEED = re.compile(rf"^SPEED\s+({_NUM})\s*(MM/S|MM/MIN|S)?\s*(ALWAYS)?$", re.IGNORECASE)
_ACCEL = re.compile(rf"^(ACCEL|DECEL)\s+({_NUM})\s*(ALWAYS)?$", re.IGNORECASE)
_ACCURACY = re.compile(rf"^ACCURACY\s+({_NUM})\s*(FINE)?\s*(ALWAYS)?$", re.IGNORECASE)
_CALL = re.compile(rf"^CALL\s+(spot_weld|grip|release)\s*\(\s*([0-9]+)\s*,\s*({_NUM})\s*\)$", re.IGNORECASE)
_SWAIT = re.compile(r"^(?:SWAIT\s+([0-9]+)|WAIT\s+SIG\s*\(\s*([0-9]+)\s*\))$", re.IGNORECASE)
_SIGNAL = re.compile(r"^SIGNAL\s+(-?)([0-9]+)$", re.IGNORECASE)
_TWAIT = re.compile(rf"^TWAIT\s+({_NUM})$", re.IGNORECASE)
_FRAME = re.compile(r"^(TOOL|BASE)\s+(.+)$", re.IGNORECASE)
_UNSIMULATED = re.compile(r"^(C1MOVE|C2MOVE|JAPPRO|LAPPRO|JDEPART|LDEPART|HOME|DRIVE|DRAW|TDRAW|GOTO|IF|CALL|"
                          r"WHILE|DO|FOR|CASE|PAUSE|HALT|STOP)\b", re.IGNORECASE)


def _split(raw: str) -> tuple[str, str]:
    """A line -> (statement, comment after `;`)."""
    code, _, comment = raw.partition(";")
    return code.strip(), comment.strip()


def _numbers(text: str) -> tuple[float, ...]:
    return tuple(float(v) for v in text.split(","))


def parse(texts: dict[str, str], file: str, robot: RobotModel) -> Parsed:
    """An AS program's motion subset (the first .PROGRAM of the file): JMOVE to joint locations,
    LMOVE to transformations, SPEED, ACCURACY, TOOL, BASE, TWAIT, SWAIT, the weld and gripper calls."""
    text = texts.get(EXT, texts.get(".pg", ""))
    lines = text.splitlines()
    start = next((i for i, ln in enumerate(lines) if _PROGRAM.match(ln.strip())), None)
    if start is None:
        raise ProgramError(file, None, "no .PROGRAM line: not a Kawasaki AS program")
    name = _PROGRAM.match(lines[start].strip()).group(1)         # type: ignore[union-attr]
    instructions: list[Instruction] = []
    where: list[int] = []
    ignored: list[tuple[int, str]] = []
    problems: list[tuple[int, str, str]] = []
    header: list[str] = []
    variables: dict[str, tuple[tuple[float, ...], tuple[float, ...]]] = {}
    frames: dict[str, FrameDef] = {}
    tool = base = UNSET_FRAME
    speed: dict[str, float] = {}
    always: dict[str, float] = {}
    accuracy: tuple[float, bool] | None = None
    accuracy_always: tuple[float, bool] = (1.0, False)
    accel: dict[str, float] = {}                  # ACCEL / DECEL for the next motion, in %
    accel_always: dict[str, float] = {}
    leading = True
    broke = False                                 # a BREAK since the last motion: the robot is at rest

    def error(line: int, problem: str) -> ProgramError:
        return ProgramError(file, f"line {line}", problem)

    def add(ins: Instruction, line: int) -> None:
        nonlocal broke
        broke = broke and not isinstance(ins, (PtpMove, LinMove))
        instructions.append(ins)
        where.append(line)

    def not_simulated(line: int, stmt: str, why: str = "") -> None:
        ignored.append((line, stmt))
        add(Comment(f"not simulated: {stmt}{why}"), line)

    def location(value: str, line: int) -> tuple[str, tuple[tuple[float, ...], tuple[float, ...]]]:
        value = value.strip()
        if value.upper() == "NULL":
            return NULL_FRAME, ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
        trans = _TRANS.match(value)
        if trans:
            v = _numbers(trans.group(1))
            return "", (v[:3], zyx_from_oat(v[3:6]))
        if value in variables:
            return value, variables[value]
        raise error(line, f"{value!r} is not a transformation this reader knows")

    def use_frame(kind: str, value: str, line: int) -> str:
        ref, (xyz, zyx) = location(value, line)
        if value.strip().upper() == "NULL":
            return NULL_FRAME
        label = ref or f"{kind}_{line}"
        match = re.search(r"([0-9]+)$", label)
        frames[label] = FrameDef(label, "tool" if kind == "tool" else "base", xyz, zyx, int(match.group(1)) if match else 0)
        return label

    def share() -> float:
        """robomax's one acceleration share of a motion: the smaller of ACCEL and DECEL."""
        values = [accel.get(k, accel_always.get(k, 100.0)) for k in ("ACCEL", "DECEL")]
        return min(values) / 100

    def blend() -> float:
        acc = accuracy if accuracy is not None else accuracy_always
        return 0.0 if acc[1] else acc[0]

    for index in range(start + 1, len(lines)):
        number = index + 1
        stmt, comment = _split(lines[index])
        if stmt.upper() == ".END":
            break
        if not stmt:
            if comment and leading:
                header.append(comment)
            continue
        leading = False
        point = _POINT.match(stmt)
        if point:
            _, value = location(point.group(2), number)
            variables[point.group(1)] = value
            continue
        frame = _FRAME.match(stmt)
        if frame:
            kind = frame.group(1).lower()
            label = use_frame(kind, frame.group(2), number)
            if kind == "tool":
                tool = label
            else:
                base = label
            continue
        sp = _SPEED.match(stmt)
        if sp:
            unit = "mm/s" if (sp.group(2) or "").upper() == "MM/S" else ("mm/min" if sp.group(2) else "%")
            if (sp.group(2) or "").upper() == "S":
                not_simulated(number, stmt, " (a motion stated by its time)")
                continue
            per_s = float(sp.group(1)) / (60.0 if unit == "mm/min" else 1.0)
            (always if sp.group(3) else speed)["%" if unit == "%" else "mm/s"] = per_s
            continue
        acc = _ACCURACY.match(stmt)
        if acc:
            value2 = (float(acc.group(1)), bool(acc.group(2)))
            if acc.group(3):
                accuracy_always = value2
            else:
                accuracy = value2
            continue
        ac = _ACCEL.match(stmt)
        if ac:
            value3 = float(ac.group(2))
            if not 0.0 < value3 <= 100.0:
                problems.append((number, "speed", f"{stmt}: an acceleration is 0.01 to 100 %"))
                value3 = min(max(value3, 0.01), 100.0)
            (accel_always if ac.group(3) else accel)[ac.group(1).upper()] = value3
            continue
        if stmt.upper().startswith("JMOVE"):
            target = stmt[5:].strip()
            joints = _JOINTS.match(target)
            pct = speed.get("%", always.get("%", 100.0))
            if joints is None:
                not_simulated(number, stmt, " (a joint move to a transformation: the configuration is the arm's)")
            else:
                q = _numbers(joints.group(1))
                if len(q) < 6:
                    raise error(number, f"a joint location of {len(q)} axes")
                add(PtpMove(q[:6], pct / 100, share(), flyby_mm=blend()), number)
            speed.pop("%", None)
            speed.pop("mm/s", None)
            accuracy = None
            accel.clear()
            continue
        if stmt.upper().startswith("LMOVE"):
            _, (xyz, zyx) = location(stmt[5:], number)
            v = speed.get("mm/s", always.get("mm/s"))
            if v is None:
                not_simulated(number, stmt, " (a linear speed in % of the maximum)")
            else:
                add(LinMove(xyz, zyx, "", v, flyby_mm=blend(), accel=share(), tool=tool, base=base), number)
            speed.pop("%", None)
            speed.pop("mm/s", None)
            accuracy = None
            accel.clear()
            continue
        call = _CALL.match(stmt)
        if call:
            routine, n, seconds = call.group(1).lower(), int(call.group(2)), float(call.group(3))
            add(read_spot_label(comment, n, seconds, file, number) if routine == "spot_weld"
                else read_gripper(routine, comment, n, seconds, file, number), number)
            continue
        tw = _TWAIT.match(stmt)
        if tw:
            add(Wait(float(tw.group(1))), number)
            continue
        if re.fullmatch(r"BREAK", stmt, re.IGNORECASE):
            broke = True
            continue
        sig = _SIGNAL.match(stmt)
        if sig:
            if not broke and any(isinstance(i, (PtpMove, LinMove)) for i in instructions):
                # Without BREAK the controller sets it as the motion before it starts, not at its end.
                not_simulated(number, stmt, " (an output after a motion without BREAK)")
            else:
                add(SetSignal(comment or f"OUT{sig.group(2)}", int(sig.group(2)), not sig.group(1)), number)
            continue
        sw = _SWAIT.match(stmt)
        if sw:
            signal = int(sw.group(1) or sw.group(2))
            k = signal - INPUT_BASE if signal > INPUT_BASE else signal
            add(WaitFor(comment or f"IN{k}", k), number)
            continue
        if re.match(r"^(PAUSE|HALT|STOP)\b", stmt, re.IGNORECASE):
            problems.append((number, "flow", f"{stmt} ends the verified cycle"))
            not_simulated(number, stmt)
            break
        if _UNSIMULATED.match(stmt) or re.match(r"^\w*MOVE\b", stmt, re.IGNORECASE):
            not_simulated(number, stmt)
            continue
        ignored.append((number, stmt))
    used = {i.tool for i in instructions if isinstance(i, LinMove)} | {i.base for i in instructions if isinstance(i, LinMove)}
    return Parsed(Program(name, read_header(header), tuple(f for k, f in frames.items() if k in used),
                          tuple(instructions)), tuple(where), "kawasaki", tuple(ignored), tuple(problems))
