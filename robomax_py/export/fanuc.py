"""FANUC TP (ASCII `.ls`), both directions: `<name>.ls` and the weld routine `spot_weld.ls`.

What a program states, in TP's terms (FANUC R-30iB operator's manual: motion instructions,
position data, frame instructions):
- `/MN` with `J P[i] n% FINE|CNTn` and `L P[i] n mm/sec FINE|CNTn`; `/POS` with `GP1`, `UF : 0`,
  `UT : 1`, and either `CONFIG : 'F|N U|D T|B, t4, t5, t6'` with X, Y, Z mm and W, P, R deg
  (R = Rz(R)·Ry(P)·Rx(W)) or J1..J6 in deg as the controller counts them: with robot.yaml
  `controller.j23_coupling: true` J3 is measured from the horizontal, J3 = J3(URDF) - J2(URDF)
  (the ROS-Industrial fanuc_driver's joint streamer, J23_factor = 1);
- frames selected by number before the first motion, `UFRAME_NUM=u` and `UTOOL_NUM=t`, and each
  position's `UF : u, UT : t` the same (the controller stops with an alarm when a position's
  numbers are not the active ones). With factory settings the world frame is the robot base (the
  controller knows nothing of the cell), so `UF : 0` targets are in the robot base frame and a user
  frame is given in it; the robot's placement in the cell is never written. The frames' values go
  into a setup program `<name>_frames.ls` (`PR[k]` assigned element by element, `UTOOL[t]=PR[k]`,
  `UFRAME[u]=PR[k]`) with the position registers the cell hands (`robot.controller.registers`);
  without them it lists the values as remarks for the SETUP Frames screen. The main program writes
  no register and no frame;
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

from robomax_py.errors import ControllerSetupError, ExportError, ProgramError
from robomax_py.export.dialect import (
    Parsed,
    PlannedProgram,
    gripper_label,
    header_lines,
    is_header_comment,
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
    Spot,
    Wait,
    WaitFor,
)
from robomax_py.robot import RobotModel

__all__ = ["CNT_DEG", "FRAMES_FILE", "adapt", "frame_name", "parse", "write"]

# The setup program holding the frames' values (a companion of `<name>.ls`).
FRAMES_FILE = "_frames.ls"
# R-30iB: tool frames UTOOL[1..10], user frames UFRAME[1..9] (0 is the world frame).
TOOL_SLOTS, BASE_SLOTS, INPUTS = 10, 9, 9999

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


def frame_name(frame: FrameDef) -> str:
    """How TP refers to a stored frame: `UTOOL[n]` or `UFRAME[n]`."""
    return f"{'UTOOL' if frame.kind == 'tool' else 'UFRAME'}[{frame.number}]"


def _number(name: str) -> int:
    """The frame number of `UTOOL[n]` / `UFRAME[n]`; 0 for the null frame."""
    if name == UNSET_FRAME:
        raise ExportError("a TP position names its UF and UT numbers: the program selects none")
    match = re.search(r"\[([0-9]+)\]", name)
    return int(match.group(1)) if match else 0


def adapt(planned: PlannedProgram, robot: RobotModel) -> Program:
    """The program as TP states it: frames by number (their values in the setup program only with
    position registers to set them from), FANUC configuration, 3 decimals, CNT, whole % and mm/sec,
    waits on DI numbers."""
    require_six_axes(robot, "FANUC TP")
    numbered_frames(planned.program, "FANUC TP", TOOL_SLOTS, BASE_SLOTS)
    numbered_inputs(planned.program, "FANUC TP", 1, INPUTS)
    registers = planned.program.setup.position_registers
    if registers and len(registers) < len(planned.program.frames):
        raise ControllerSetupError("robot.controller.registers.position", f"the frames setup program sets "
                                   f"{len(planned.program.frames)} frames from position registers; the cell hands "
                                   f"{len(registers)}")
    program = with_frame_names(planned.program, frame_name)
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
        out.append(ins)
    frames = tuple(dataclasses.replace(f, xyz_mm=tuple(_round(v, 3) for v in f.xyz_mm),
                                       zyx_deg=tuple(_round(v, ANGLE_DECIMALS) for v in f.zyx_deg))
                   for f in program.frames)
    if not registers:
        # Without registers to set them from, the setup program only lists the values: the frames
        # are the controller's own, as calibrated.
        setup = dataclasses.replace(program.setup, listed=frames)
        return dataclasses.replace(program, name=program.name.upper(), frames=(), instructions=tuple(out), setup=setup)
    return dataclasses.replace(program, name=program.name.upper(), frames=frames, instructions=tuple(out))


def _cnt(radius_deg: float) -> int:
    return max(0, min(100, int(round(radius_deg / CNT_DEG))))


# ================================================================================== writing


def write(program: Program, robot: RobotModel) -> dict[str, str]:
    coupled = robot.controller.j23_coupling
    mn: list[str] = [f"! {text} ;" for text in header_lines(program.header)]
    first = next((i for i in program.instructions if isinstance(i, LinMove)), None)
    uf, ut = (0, 0) if first is None else (_number(first.base), _number(first.tool))
    mn += [f"UFRAME_NUM={uf} ;", f"UTOOL_NUM={ut} ;"]
    pos: list[str] = []
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
                pos.append(f"P[{k}]{{\n   GP1:\n\tUF : {uf}, UT : {ut},\n"
                           f"\tJ1= {q[0]:.4f} deg,\tJ2= {q[1]:.4f} deg,\tJ3= {q[2]:.4f} deg,\n"
                           f"\tJ4= {q[3]:.4f} deg,\tJ5= {q[4]:.4f} deg,\tJ6= {q[5]:.4f} deg\n}};")
            else:
                acc = f" ACC{percent(ins.accel)}" if percent(ins.accel) != 100 else ""
                if (_number(ins.base), _number(ins.tool)) != (uf, ut):
                    uf, ut = _number(ins.base), _number(ins.tool)
                    mn += [f"UFRAME_NUM={uf} ;", f"UTOOL_NUM={ut} ;"]
                mn.append(f"L P[{k}] {int(round(ins.speed_mm_s))}mm/sec {term}{acc} ;")
                x, y, z = ins.position_mm
                a, b, c = ins.zyx_deg
                pos.append(f"P[{k}]{{\n   GP1:\n\tUF : {uf}, UT : {ut},\t\tCONFIG : '{ins.config}',\n"
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
            mn.append(f"WAIT DI[{ins.number}:{ins.signal}]=ON ;")
        elif not isinstance(ins, Comment):
            raise ExportError(f"FANUC TP cannot write {type(ins).__name__}")
    main = _ls(program.name, "robomax_py", mn, pos)
    out = {".ls": main, FRAMES_FILE: _frames_program(program)}
    if n_weld or not grips:
        # WAIT takes an argument register directly: the routine writes no register.
        out["spot_weld.ls"] = _ls(WEAPON, "default weld", ["! default weld: rest AR[2] s ;",
                                                             "! replace with the gun's package ;", "WAIT AR[2] ;"], [])
    for action in sorted(grips):
        out[f"{action}.ls"] = _ls(action.upper(), f"default {action}", [
            f"! default {action}: rest AR[2] s ;", "! replace with the gripper's DO and sensors ;", "WAIT AR[2] ;"], [])
    return out


def _frames_program(program: Program) -> str:
    """The setup program: each frame's value into a position register the cell hands, then into
    the frame (`UTOOL[t]=PR[k]`, `UFRAME[u]=PR[k]`); without registers, the values as remarks."""
    mn = [f"! {text} ;" for text in header_lines(program.header)] + [f"! frames of {program.name} ;"]
    registers = program.setup.position_registers
    for k, f in enumerate(program.frames or program.setup.listed):
        values = (*f.xyz_mm, f.zyx_deg[2], f.zyx_deg[1], f.zyx_deg[0])     # X Y Z W P R
        if registers:
            pr = registers[k]
            mn += [f"PR[{pr}]=LPOS ;", f"PR[{pr}]=PR[{pr}]-PR[{pr}] ;"]
            mn += [f"PR[{pr},{i}]={v:.{3 if i <= 3 else ANGLE_DECIMALS}f} ;" for i, v in enumerate(values, start=1)]
            mn.append(f"{f.name}=PR[{pr}] ;")
        else:
            mn.append(f"! {f.name} X Y Z W P R ;")
            mn += [f"! {v:.{3 if i < 3 else ANGLE_DECIMALS}f} ;" for i, v in enumerate(values)]
    return _ls(f"{program.name}_FRAMES", "robomax_py frames", mn, [])


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
_FRAME_SET = re.compile(r"^(UTOOL|UFRAME)\[([0-9]+)\]\s*=\s*PR\[([0-9]+)\]$", re.I)
_FRAME_NUM = re.compile(r"^(UTOOL|UFRAME)_NUM\s*=\s*([0-9]+)$", re.I)
_PR_RESET = re.compile(r"^PR\[([0-9]+)\]\s*=\s*(LPOS|PR\[([0-9]+)\]\s*-\s*PR\[([0-9]+)\])$", re.I)
_UF_UT = re.compile(r"\bUF\s*:\s*([0-9]+)\s*,\s*UT\s*:\s*([0-9]+)", re.I)
_POS_HEAD = re.compile(r"^P\[([0-9]+)(?::[^\]]*)?\]\s*\{", re.I)
_FIELD = re.compile(r"\b(X|Y|Z|W|P|R|J[1-6])\s*=\s*([+-]?[0-9]*\.?[0-9]+)\s*(mm|deg)", re.I)
_CONFIG = re.compile(r"CONFIG\s*:\s*'([^']*)'", re.I)
# Motions this reader does not simulate, and control flow (jumps, conditions): the program's
# motion then depends on what the reader cannot follow.
_UNSIMULATED = re.compile(r"^(C|A)\s+P\[|^(J|L)\s+PR\[|^JMP\b|^IF\b|^SELECT\b|^FOR\b|^CALL\s+(?!(SPOT_WELD|GRIP|RELEASE)\b)", re.I)


def _positions(text: str, file: str, start_line: int) -> dict[int, tuple[dict[str, float], str, tuple[int, int] | None]]:
    """P[k] -> its fields (X..R, J1..J6), its CONFIG and its (UF, UT) numbers."""
    out: dict[int, tuple[dict[str, float], str, tuple[int, int] | None]] = {}
    blocks = re.split(r"(?=^P\[)", text, flags=re.M)
    line = start_line
    for block in blocks:
        head = _POS_HEAD.match(block)
        if head:
            group1 = re.split(r"\bGP[2-9]\s*:", block)[0]         # the robot's group; others are positioners
            fields = {m.group(1).upper(): float(m.group(2)) for m in _FIELD.finditer(group1)}
            config = _CONFIG.search(group1)
            frames = _UF_UT.search(group1)
            out[int(head.group(1))] = (fields, config.group(1) if config else "",
                                       (int(frames.group(1)), int(frames.group(2))) if frames else None)
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
    for raw in setup_lines[setup_mn + 1:]:
        match = _MN_LINE.match(raw)
        if match:
            register_or_frame(match.group(2).strip())

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
            fields, config, numbers = positions[k]
            if kind == "J" and all(f"J{i}" in fields for i in range(1, 7)):
                if unit != "%":
                    raise error(number, f"a joint move's speed must be in %, got {unit}")
                q = _from_controller(tuple(fields[f"J{i}"] for i in range(1, 7)), coupled)
                instructions.append(PtpMove(q, speed / 100, (float(acc.group(1)) if acc else 100.0) / 100,
                                            flyby=cnt * CNT_DEG))
            elif kind == "L" and all(c in fields for c in "XYZWPR"):
                if unit != "mm/sec":
                    raise error(number, f"a linear move's speed must be in mm/sec here, got {unit}")
                uf, ut = numbers if numbers is not None else (active["UFRAME"], active["UTOOL"])
                mismatch = [f"{name} {n} is not the active {name}_NUM {active[name]}"
                            for name, n in (("UFRAME", uf), ("UTOOL", ut))
                            if active[name] is not None and n != active[name]]
                if mismatch:
                    # The controller stops at such a position with a frame-number alarm.
                    ignored.append((number, stmt))
                    instructions.append(Comment(f"not simulated: {stmt} (P[{k}]'s {'; '.join(mismatch)}: the "
                                                "controller stops with an alarm)"))
                    where.append(number)
                    continue
                # A program that selects no frame numbers runs only if the numbers left active by
                # whatever ran before match its positions': unknown here.
                instructions.append(LinMove((fields["X"], fields["Y"], fields["Z"]), (fields["R"], fields["P"], fields["W"]),
                                            config, speed, flyby=cnt * CNT_DEG,
                                            accel=(float(acc.group(1)) if acc else 100.0) / 100,
                                            tool=_frame_ref("UTOOL", ut if active["UTOOL"] is not None else None),
                                            base=_frame_ref("UFRAME", uf if active["UFRAME"] is not None else None)))
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
            instructions.append(WaitFor((wait_di.group(2) or f"DI{wait_di.group(1)}").strip(), int(wait_di.group(1))))
            where.append(number)
            continue
        selected = _FRAME_NUM.match(stmt)
        if selected:
            active[selected.group(1).upper()] = int(selected.group(2))
            continue
        if register_or_frame(stmt):
            continue
        ignored.append((number, stmt))
    header = read_header(header_comments)
    return Parsed(Program(head.group(1), header, tuple(frames), tuple(instructions)), tuple(where), "fanuc",
                  tuple(ignored))


def _frame_ref(kind: str, number: int | None) -> str:
    """A position's frame as a name: `UTOOL[n]` / `UFRAME[n]`, the null frame for 0, unset when
    neither the position nor a *_NUM statement gives one."""
    if number is None:
        return UNSET_FRAME
    return NULL_FRAME if number == 0 else f"{kind}[{number}]"
