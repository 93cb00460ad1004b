"""FANUC TP read: `parse`, a program from its `.ls` texts."""

from __future__ import annotations

import dataclasses
import re

from robomax_py.errors import ProgramError
from robomax_py.export.dialect import Parsed, read_gripper, read_header, read_spot_label
from robomax_py.export.fanuc.flow import (
    _LINEAR_UNITS,
    _classify,
    _not_resting,
    _program,
)
from robomax_py.export.fanuc.grammar import (
    _CALL,
    _EQUIPMENT,
    _FRAME_NUM,
    _FRAME_SET,
    _MOVE,
    _PR_ELEMENT,
    _PR_RESET,
    _SET_DO,
    _SPOT,
    _TARGET_OPTIONS,
    _UNSIMULATED,
    _WAIT,
    _WAIT_DI,
    _positions,
    _program_positions,
    _statements,
)
from robomax_py.export.fanuc.write import (
    CNT_DEG,
    FRAMES_FILE,
    ROUTINES,
    WEAPON,
    _from_controller,
)
from robomax_py.export.flow import Routine, Statement, follow
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
        set_do = _SET_DO.match(stmt)
        if set_do:
            add(SetSignal((set_do.group(2) or f"DO{set_do.group(1)}").strip(), int(set_do.group(1)),
                          set_do.group(3).upper() == "ON"), number, s)
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
