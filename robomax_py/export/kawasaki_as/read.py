"""An AS program's motion subset read back (`parse`): this package's programs and other writers'
(RoboDK's `SPEED ... ALWAYS`, `WAIT SIG(n)`, `BASE TRANS(...)`)."""

from __future__ import annotations

import re

from robomax_py.errors import ProgramError
from robomax_py.export.dialect import Parsed, read_gripper, read_header, read_spot_label
from robomax_py.export.kawasaki_as.oat import zyx_from_oat
from robomax_py.export.kawasaki_as.write import EXT, INPUT_BASE
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
    Wait,
    WaitFor,
)
from robomax_py.robot import RobotModel

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
