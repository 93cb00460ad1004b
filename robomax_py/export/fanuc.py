"""FANUC TP (ASCII `.ls`), both directions: `<name>.ls` and the weld routine `spot_weld.ls`.

What a program states, in TP's terms (FANUC R-30iB operator's manual: motion instructions,
position data, frame instructions):
- `/MN` with `J P[i] n% FINE|CNTn` and `L P[i] n mm/sec FINE|CNTn`; `/POS` with `GP1`, `UF : 0`,
  `UT : 1`, and either `CONFIG : 'F|N U|D T|B, t4, t5, t6'` with X, Y, Z mm and W, P, R deg
  (R = Rz(R)·Ry(P)·Rx(W)) or J1..J6 in deg as the controller counts them: with robot.yaml
  `controller.j23_coupling: true` J3 is measured from the horizontal, J3 = J3(URDF) - J2(URDF)
  (the ROS-Industrial fanuc_driver's joint streamer, J23_factor = 1);
- the tool frame set by the program: `PR[1]` assigned element by element, `UTOOL[1]=PR[1]`,
  `UTOOL_NUM=1`; targets in the controller's world frame (`UFRAME_NUM=0`, `UF : 0`), which is the
  robot base: the program states no base frame;
- mm with TP's 3 decimals, W, P, R and joint values with 4, speeds in whole % and mm/sec, waits in 0.01 s (rounded up);
- blends as `CNTn`: robomax's model of CNT flies by with the joint-space radius n x 0.12 deg
  (CNT100 = 12 deg, the largest radius the planner uses), so the planner's radii are whole CNTs;
- a weld as `L ... FINE`, then `CALL SPOT_WELD(n,weld_time)`, then the `! seam/name` remark line
  (TP has no comment at the end of a statement); SPOT_WELD is written as its own program
  `spot_weld.ls` (TP defines one program per file): it waits `weld_time` (AR[2]);
- `WAIT t(sec)` and `WAIT DI[k:<signal>]=ON`.

Remarks: TP remarks are short; the notes other dialects carry on each move are left out.
"""

from __future__ import annotations

import dataclasses
import math
import re

from robomax_py.errors import ExportError, ProgramError
from robomax_py.export.dialect import (
    Parsed,
    PlannedProgram,
    gripper_label,
    header_lines,
    is_header_comment,
    percent,
    read_gripper,
    read_header,
    read_spot_label,
    require_six_axes,
    spot_label,
    with_brand_configs,
    without_comments,
)
from robomax_py.program import (
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

__all__ = ["CNT_DEG", "adapt", "parse", "write"]

CNT_DEG = 0.12            # joint-space fly-by radius of CNT1, deg
# Angles (W, P, R and joint values) with 4 decimals, as every robomax program states them (TP's
# listings show 3): a spot orientation the planner chose at the edge of its tolerance window stays
# inside it, and a 12 deg detour corner blends as planned.
ANGLE_DECIMALS = 4
WEAPON = "SPOT_WELD"


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


def adapt(planned: PlannedProgram, robot: RobotModel) -> Program:
    """The program as TP states it: FANUC configuration, 3 decimals, CNT, whole % and mm/sec."""
    require_six_axes(robot, "FANUC TP")
    program = without_comments(with_brand_configs(planned.program, planned.joints, robot, "fanuc"))
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
        out.append(ins)
    frames = tuple(dataclasses.replace(f, xyz_mm=tuple(_round(v, 3) for v in f.xyz_mm),
                                       zyx_deg=tuple(_round(v, ANGLE_DECIMALS) for v in f.zyx_deg))
                   for f in program.frames if f.kind == "tool")
    return dataclasses.replace(program, name=program.name.upper(), frames=frames, instructions=tuple(out))


def _cnt(radius_deg: float) -> int:
    return max(0, min(100, int(round(radius_deg / CNT_DEG))))


# ================================================================================== writing


def write(program: Program, robot: RobotModel) -> dict[str, str]:
    coupled = robot.controller.j23_coupling
    mn: list[str] = [f"! {text} ;" for text in header_lines(program.header)]
    tool = next((f for f in program.frames if f.kind == "tool"), None)
    if tool:
        mn += ["PR[1]=LPOS ;", "PR[1]=PR[1]-PR[1] ;"]
        values = (*tool.xyz_mm, tool.zyx_deg[2], tool.zyx_deg[1], tool.zyx_deg[0])
        mn += [f"PR[1,{i}]={v:.{3 if i <= 3 else ANGLE_DECIMALS}f} ;" for i, v in enumerate(values, start=1)]
        mn += ["UTOOL[1]=PR[1] ;", "UTOOL_NUM=1 ;"]
    mn.append("UFRAME_NUM=0 ;")
    pos: list[str] = []
    signals: dict[str, int] = {}
    n_weld = 0
    grips: dict[str, int] = {}
    for ins in program.instructions:
        if isinstance(ins, (PtpMove, LinMove)):
            k = len(pos) + 1
            term = f"CNT{_cnt(ins.flyby)}" if ins.flyby > 0 else "FINE"
            if isinstance(ins, PtpMove):
                acc = f" ACC{percent(ins.accel)}" if percent(ins.accel) != 100 else ""
                mn.append(f"J P[{k}] {percent(ins.speed)}% {term}{acc} ;")
                q = _to_controller(ins.target_deg, coupled)
                pos.append(f"P[{k}]{{\n   GP1:\n\tUF : 0, UT : 1,\n"
                           f"\tJ1= {q[0]:.4f} deg,\tJ2= {q[1]:.4f} deg,\tJ3= {q[2]:.4f} deg,\n"
                           f"\tJ4= {q[3]:.4f} deg,\tJ5= {q[4]:.4f} deg,\tJ6= {q[5]:.4f} deg\n}};")
            else:
                acc = f" ACC{percent(ins.accel)}" if percent(ins.accel) != 100 else ""
                mn.append(f"L P[{k}] {int(round(ins.speed_mm_s))}mm/sec {term}{acc} ;")
                x, y, z = ins.position_mm
                a, b, c = ins.zyx_deg
                pos.append(f"P[{k}]{{\n   GP1:\n\tUF : 0, UT : 1,\t\tCONFIG : '{ins.config}',\n"
                           f"\tX = {x:.3f}  mm,\tY = {y:.3f}  mm,\tZ = {z:.3f}  mm,\n"
                           f"\tW = {c:.4f} deg,\tP = {b:.4f} deg,\tR = {a:.4f} deg\n}};")
        elif isinstance(ins, Spot):
            n_weld += 1
            mn += [f"CALL {WEAPON}({n_weld},{ins.time_s:.3f}) ;", f"! {spot_label(ins)} ;"]
        elif isinstance(ins, Gripper):
            grips[ins.action] = grips.get(ins.action, 0) + 1
            mn += [f"CALL {ins.action.upper()}({grips[ins.action]},{ins.time_s:.3f}) ;", f"! {gripper_label(ins)} ;"]
        elif isinstance(ins, Wait):
            mn.append(f"WAIT {ins.seconds:.2f}(sec) ;")
        elif isinstance(ins, WaitFor):
            k = signals.setdefault(ins.signal, len(signals) + 1)
            mn.append(f"WAIT DI[{k}:{ins.signal}]=ON ;")
        elif not isinstance(ins, Comment):
            raise ExportError(f"FANUC TP cannot write {type(ins).__name__}")
    main = _ls(program.name, "robomax_py", mn, pos)
    out = {".ls": main}
    if n_weld or not grips:
        out["spot_weld.ls"] = _ls(WEAPON, "default weld", ["! default weld: rest AR[2] s ;",
                                                             "! replace with the gun's package ;",
                                                             "R[1:weld_time]=AR[2] ;", "WAIT R[1] ;"], [])
    for action in sorted(grips):
        out[f"{action}.ls"] = _ls(action.upper(), f"default {action}", [
            f"! default {action}: rest AR[2] s ;", "! replace with the gripper's DO and sensors ;",
            f"R[1:{action}_time]=AR[2] ;", "WAIT R[1] ;"], [])
    return out


def _ls(name: str, comment: str, mn: list[str], pos: list[str]) -> str:
    lines = [f"/PROG  {name}", "/ATTR", "OWNER\t\t= MNEDITOR;", f'COMMENT\t\t= "{comment}";', "PROG_SIZE\t= 0;",
             f"FILE_NAME\t= {name};", "VERSION\t\t= 0;", f"LINE_COUNT\t= {len(mn)};", "MEMORY_SIZE\t= 0;",
             "PROTECT\t\t= READ_WRITE;", "TCD:  STACK_SIZE\t= 0,", "      TASK_PRIORITY\t= 50,",
             "      TIME_SLICE\t= 0,", "      BUSY_LAMP_OFF\t= 0,", "      ABORT_REQUEST\t= 0,",
             "      PAUSE_REQUEST\t= 0;", "DEFAULT_GROUP\t= 1,*,*,*,*;", "CONTROL_CODE\t= 00000000 00000000;", "/MN"]
    lines += [f"{i:4d}:  {text}" for i, text in enumerate(mn, start=1)]
    lines.append("/POS")
    lines += pos
    lines.append("/END")
    return "\n".join(lines) + "\n"


# ================================================================================== reading

_MN_LINE = re.compile(r"^\s*([0-9]+):\s*(.*?)\s*;?\s*$")
_MOVE = re.compile(r"^(J|L)\s+P\[([0-9]+)(?::[^\]]*)?\]\s+([0-9.]+)\s*(%|mm/sec|cm/min|inch/min|deg/sec|sec|msec)\s+"
                   r"(FINE|CNT\s*([0-9]+))(.*)$", re.I)
_CALL = re.compile(r"^CALL\s+(SPOT_WELD|GRIP|RELEASE)\s*\(\s*([0-9]+)\s*,\s*([0-9.]+)\s*\)$", re.I)
_WAIT = re.compile(r"^WAIT\s+([0-9]*\.?[0-9]+)\s*\(sec\)$", re.I)
_WAIT_DI = re.compile(r"^WAIT\s+DI\[([0-9]+)(?::([^\]]*))?\]\s*=\s*ON$", re.I)
_PR_ELEMENT = re.compile(r"^PR\[([0-9]+),([1-6])\]\s*=\s*([+-]?[0-9]*\.?[0-9]+)$", re.I)
_UTOOL = re.compile(r"^UTOOL\[([0-9]+)\]\s*=\s*PR\[([0-9]+)\]$", re.I)
_POS_HEAD = re.compile(r"^P\[([0-9]+)(?::[^\]]*)?\]\s*\{", re.I)
_FIELD = re.compile(r"\b(X|Y|Z|W|P|R|J[1-6])\s*=\s*([+-]?[0-9]*\.?[0-9]+)\s*(mm|deg)", re.I)
_CONFIG = re.compile(r"CONFIG\s*:\s*'([^']*)'", re.I)
# Motions this reader does not simulate, and control flow (jumps, conditions): the program's
# motion then depends on what the reader cannot follow.
_UNSIMULATED = re.compile(r"^(C|A)\s+P\[|^(J|L)\s+PR\[|^JMP\b|^IF\b|^SELECT\b|^FOR\b|^CALL\s+(?!(SPOT_WELD|GRIP|RELEASE)\b)", re.I)


def _positions(text: str, file: str, start_line: int) -> dict[int, tuple[dict[str, float], str, int]]:
    out: dict[int, tuple[dict[str, float], str, int]] = {}
    blocks = re.split(r"(?=^P\[)", text, flags=re.M)
    line = start_line
    for block in blocks:
        head = _POS_HEAD.match(block)
        if head:
            group1 = re.split(r"\bGP[2-9]\s*:", block)[0]         # the robot's group; others are positioners
            fields = {m.group(1).upper(): float(m.group(2)) for m in _FIELD.finditer(group1)}
            config = _CONFIG.search(group1)
            out[int(head.group(1))] = (fields, config.group(1) if config else "", line)
        line += block.count("\n")
    return out


def parse(texts: dict[str, str], file: str, robot: RobotModel) -> Parsed:
    """A TP program's motion subset: J and L to P[] positions, FINE/CNT, CALL SPOT_WELD, WAIT."""
    text = texts.get(".ls", "")
    lines = text.splitlines()
    head = next((re.match(r"^/PROG\s+(\S+)", ln) for ln in lines if ln.startswith("/PROG")), None)
    if head is None:
        raise ProgramError(file, None, "no /PROG line: not a FANUC TP (.ls) program")
    try:
        mn_at = next(i for i, ln in enumerate(lines) if ln.strip() == "/MN")
    except StopIteration:
        raise ProgramError(file, None, "no /MN section") from None
    pos_at = next((i for i, ln in enumerate(lines) if ln.strip() == "/POS"), len(lines))
    positions = _positions("\n".join(lines[pos_at + 1:]), file, pos_at + 2)
    coupled = robot.controller.j23_coupling
    instructions: list[Instruction] = []
    where: list[int] = []
    ignored: list[tuple[int, str]] = []
    header_comments: list[str] = []
    registers: dict[int, dict[int, float]] = {}
    frames: list[FrameDef] = []

    def error(line: int, problem: str) -> ProgramError:
        return ProgramError(file, f"line {line}", problem)

    for index in range(mn_at + 1, pos_at):
        number = index + 1
        match = _MN_LINE.match(lines[index])
        if not match:
            continue
        stmt = match.group(2).strip()
        if stmt.startswith("!"):
            remark = stmt[1:].strip()
            if is_header_comment(remark):
                header_comments.append(remark)
            elif instructions and isinstance(instructions[-1], Spot) and where[-1] == number - 1:
                n = int(instructions[-1].name[4:]) if instructions[-1].seam == "unnamed" else 0
                instructions[-1] = read_spot_label(remark, n, instructions[-1].time_s, file, number)
            elif instructions and isinstance(instructions[-1], Gripper) and where[-1] == number - 1:
                last = instructions[-1]
                n = int(last.name[7:]) if last.seam == "unnamed" else 0
                instructions[-1] = read_gripper(last.action, remark, n, last.time_s, file, number)
            continue
        move = _MOVE.match(stmt)
        # Offsets and incremental moves change the target; TB/TA/DB triggers do not (ACC is read).
        if _UNSIMULATED.match(stmt) or (move and re.search(r"\b(Offset|Tool_Offset|INC|VOFFSET|Skip)\b",
                                                           move.group(7) or "", re.I)):
            ignored.append((number, stmt))
            instructions.append(Comment(f"not simulated: {stmt}"))
            where.append(number)
            continue
        if move:
            kind, k, speed, unit = move.group(1).upper(), int(move.group(2)), float(move.group(3)), move.group(4).lower()
            cnt = 0 if move.group(5).upper() == "FINE" else int(move.group(6))
            acc = re.search(r"ACC\s*([0-9]+)", move.group(7) or "", re.I)
            if k not in positions:
                raise error(number, f"P[{k}] has no position in /POS")
            fields, config, _ = positions[k]
            if kind == "J" and all(f"J{i}" in fields for i in range(1, 7)):
                if unit != "%":
                    raise error(number, f"a joint move's speed must be in %, got {unit}")
                q = _from_controller(tuple(fields[f"J{i}"] for i in range(1, 7)), coupled)
                instructions.append(PtpMove(q, speed / 100, (float(acc.group(1)) if acc else 100.0) / 100,
                                            flyby=cnt * CNT_DEG))
            elif kind == "L" and all(c in fields for c in "XYZWPR"):
                if unit != "mm/sec":
                    raise error(number, f"a linear move's speed must be in mm/sec here, got {unit}")
                instructions.append(LinMove((fields["X"], fields["Y"], fields["Z"]), (fields["R"], fields["P"], fields["W"]),
                                            config, speed, flyby=cnt * CNT_DEG,
                                            accel=(float(acc.group(1)) if acc else 100.0) / 100))
            else:                          # a joint move to a Cartesian point, or the other way round
                ignored.append((number, stmt))
                instructions.append(Comment(f"not simulated: {stmt}"))
            where.append(number)
            continue
        call = _CALL.match(stmt)
        if call:
            routine, n, seconds = call.group(1).upper(), int(call.group(2)), float(call.group(3))
            instructions.append(read_spot_label("", n, seconds, file, number) if routine == "SPOT_WELD"
                                else read_gripper(routine.lower(), "", n, seconds, file, number))
            where.append(number)
            continue
        wait = _WAIT.match(stmt)
        if wait:
            instructions.append(Wait(float(wait.group(1))))
            where.append(number)
            continue
        wait_di = _WAIT_DI.match(stmt)
        if wait_di:
            instructions.append(WaitFor((wait_di.group(2) or f"DI{wait_di.group(1)}").strip()))
            where.append(number)
            continue
        element = _PR_ELEMENT.match(stmt)
        if element:
            registers.setdefault(int(element.group(1)), {})[int(element.group(2))] = float(element.group(3))
            continue
        utool = _UTOOL.match(stmt)
        if utool:
            reg = registers.get(int(utool.group(2)), {})
            x, y, z, w, p, r = (reg.get(i, 0.0) for i in range(1, 7))
            frames = [FrameDef(f"utool_{utool.group(1)}", "tool", (x, y, z), (r, p, w))]
            continue
        ignored.append((number, stmt))
    header = read_header(header_comments)
    frames = [dataclasses.replace(f, name=_tool_name(header.tool)) for f in frames] if header.tool else frames
    return Parsed(Program(head.group(1), header, tuple(frames), tuple(instructions)), tuple(where), "fanuc",
                  tuple(ignored))


def _tool_name(tool: str) -> str:
    return f"{tool}_tcp"
