"""FANUC TP (ASCII .ls): what an R-30iA / R-30iB controller executes, for a motion subset.

Sources (/work/notes/vendor_research.md §3 quotes each): the .ls layout of controller exports
(ros-industrial/fanuc @ 8fee5e30 fanuc_driver/tpe/ros_movesm.ls; kamilkozdro/FanucProgramAnalyze
@ e585a61d home.ls, gratowanie.ls, R-30iB V8.30); frame and register instructions as RoboDK's
FANUC post writes them (ros-industrial-attic/robodk_postprocessors @ d7e6c1c0 Fanuc_R30iA.py
375-403) and a public TP grammar (JTremblayAGT/fanuc-lsp TpOffsetFrameInstruction.cs); the J2/J3
interaction from the ROS-Industrial FANUC driver (fanuc_driver/src/fanuc_utils.cpp 60-67,
fanuc_joint_streamer_node.cpp 73-74, launch files ``J23_factor`` = 1).

- A program: ``/PROG name``, ``/ATTR``, ``/MN`` with statements ``n: statement ;`` (n right-aligned
  in four columns; a continuation line starts with ``:``; point-logic lines are indented further),
  ``/POS`` with the positions, ``/END``.
- Positions ``P[n]{ GP1: UF : u, UT : t, CONFIG : 'F|N U|D T|B, t1, t2, t3', X = .. mm, ...,
  W = .. deg, P = .. deg, R = .. deg };`` (Cartesian: the TCP of tool frame t in user frame u) or
  ``J1 = .. deg ...`` (joints, degrees as the controller counts them). W, P, R turn about the fixed
  x, y, z axes: R = Rz(R)·Ry(P)·Rx(W). CONFIG is kept as written.
- Frames: user frame 0 is the World frame, which is the robot's base frame as the controller
  defines it (for ROS-I FANUC models the ``base`` link, above ``base_link``); tool frame 0 is the
  faceplate. ``UFRAME_NUM = n`` / ``UTOOL_NUM = n`` select the frames in force (they persist on the
  controller, also after a setup program); ``UFRAME[n] = PR[m]`` / ``UTOOL[n] = PR[m]`` store
  register m's Cartesian value (X, Y, Z, W, P, R) as frame n. ``PR[m] = LPOS`` makes PR[m] a
  Cartesian position (values unknown to the model), ``PR[m] = PR[a] - PR[b]`` (or ``+``) works
  element by element (``PR[m] - PR[m]`` is zero), ``PR[m, i] = v`` sets element i. A Cartesian
  position whose UF or UT differs from the selected numbers stops the program with an alarm
  (INTP-250/252-type, number UNCONFIRMED): the model reports it and records the motion with the
  position's own frames.
- Motion lines ``J|L P[n] speed FINE|CNTk [ACCk] [SPOT[...]]``; FINE is a stop point. A SpotTool
  ``SPOT[SD=..,P=..,S=..,ED=..]`` option welds at the position: a call after the motion.
- ``CALL name`` of a program given as `called` runs it (`_Flow`: END, ABORT, PAUSE, JMP LBL[n]
  too); other calls ``CALL name(args)`` are recorded, not followed (a call of a given program
  that moves is reported), ``WAIT t(sec)``, ``WAIT DI[k]=ON|OFF``, ``WAIT (DI[k])`` and
  ``WAIT (!DI[k])``.
- J2/J3 interaction: on arms whose J3 is measured from the horizontal, J3 as the controller counts
  it is J3_urdf - J2_urdf for the ROS-I URDF convention (J3 turning about -y): the driver sends
  ``J3 - J23_factor·J2`` to the controller with ``J23_factor = 1`` for all but the M-430iA
  (`controller_joints_deg`, `urdf_joints_deg`). The model returns joint values as written.

Outside this subset (control flow, position registers as targets, Offset / Tool_Offset / INC /
RTCP, circular and arc motions, TB / TA / DB and point logic, other motion groups and extended
axes E1.. not at 0, register waits) a statement is an ``unsupported`` issue.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from .common import (
    NUMBER,
    Call,
    Event,
    FanucConfig,
    FloatArray,
    Issue,
    IssueKind,
    Motion,
    MotionKind,
    ProgramRun,
    SetOutput,
    Wait,
    Where,
    arg_value,
    is_number,
    pose_mm_zyx_deg,
    split_top,
)


def controller_joints_deg(urdf_deg: tuple[float, ...], j23_coupling: bool) -> tuple[float, ...]:
    """Joint values (deg) as the FANUC controller counts them from URDF values (deg)."""
    if not j23_coupling:
        return tuple(urdf_deg)
    return (*urdf_deg[:2], urdf_deg[2] - urdf_deg[1], *urdf_deg[3:])


def urdf_joints_deg(controller_deg: tuple[float, ...], j23_coupling: bool) -> tuple[float, ...]:
    """URDF joint values (deg) from the values a FANUC program gives (deg)."""
    if not j23_coupling:
        return tuple(controller_deg)
    return (*controller_deg[:2], controller_deg[2] + controller_deg[1], *controller_deg[3:])


@dataclass(frozen=True, slots=True)
class _Position:
    where: Where
    uf: int | None
    ut: int | None
    config: FanucConfig | None
    cartesian: tuple[float, ...] | None    # X, Y, Z mm, W, P, R deg
    joints: tuple[float, ...] | None       # J1.. deg
    other_groups: bool                     # other motion groups, or extended axes (E1..) not at 0
    problem: str | None                    # why the position cannot be used


@dataclass(slots=True)
class _Register:
    cartesian: bool
    values: list[float]     # NaN: unknown (e.g. copied from LPOS)


@dataclass(frozen=True, slots=True)
class _Line:
    where: Where
    number: int | None      # the /MN line number, None for a nested (point logic) line
    code: str
    raw: str


@dataclass(slots=True)
class _State:
    uframes: dict[int, FloatArray]
    utools: dict[int, FloatArray]
    registers: dict[int, _Register] = field(default_factory=dict)
    uframe_num: int | None = None
    utool_num: int | None = None
    events: list[Event] = field(default_factory=list)
    issues: list[Issue] = field(default_factory=list)

    def issue(self, line: _Line, kind: IssueKind, reason: str) -> None:
        self.issues.append(Issue(line.where, kind, line.raw.strip(), reason))


def run_fanuc(program: str, *, name: str = "program.ls", setup: Mapping[str, str] | None = None,
              called: Mapping[str, str] | None = None, uframes: Mapping[int, FloatArray] | None = None,
              utools: Mapping[int, FloatArray] | None = None, uframe_num: int | None = None,
              utool_num: int | None = None, j23_coupling: bool = False) -> ProgramRun:
    """Runs the TP program `program` (.ls text) as the controller would.

    Parameters
    ----------
    setup : mapping of name to .ls text, optional
        Programs run before on the same controller (e.g. ``<NAME>_FRAMES.ls``): their register and
        frame assignments and frame selections are kept; their motions and calls are issues.
    called : mapping of name to .ls text, optional
        Other programs on the controller; a CALL of one without arguments runs it, a CALL of one
        that moves with arguments is reported (calls with arguments are not followed).
    uframes, utools : mapping of int to (4, 4) float, optional
        Frames stored on the controller (metres), before the setup programs run. 0 is always the
        identity (world = robot base; faceplate).
    uframe_num, utool_num : int, optional
        The frame numbers selected when the program starts (None: unknown).
    j23_coupling : bool
        Recorded in the run: whether J3 in joint positions is measured from the horizontal
        (see `urdf_joints_deg`). Joint values are returned as written.
    """
    state = _State(uframes={0: np.eye(4), **dict(uframes or {})}, utools={0: np.eye(4), **dict(utools or {})},
                   uframe_num=uframe_num, utool_num=utool_num)
    for setup_name, text in (setup or {}).items():
        mark = len(state.events)
        _Flow(state, set(), {}).run(text, setup_name)
        for event in state.events[mark:]:
            state.issues.append(Issue(event.where, "unsupported", "", "a setup program may only assign registers "
                                      "and frames"))
        del state.events[mark:]
    moving = {n for n, text in (called or {}).items() if _moves(text)}
    moving |= {_prog_name(text) for text in (called or {}).values() if _moves(text)}
    programs = {_prog_name(text): (n, text) for n, text in (called or {}).items()}
    flow = _Flow(state, moving, programs)
    flow.run(program, name)
    return ProgramRun("fanuc", tuple(state.events), tuple(state.issues), j23_coupling=j23_coupling,
                      stopped=flow.stopped)


class _Stop(Exception):
    """The program stops: an end, a pause, or a jump that repeats without end."""


@dataclass(slots=True)
class _Flow:
    """TP program control (public TP grammar JTremblayAGT/fanuc-lsp @ b0e9a1ea TPLangParser/TPLang/
    Instructions/TpBranchingInstruction.cs 8-57 and TpProgControlInstruction.cs 20-26; RoboDK's
    R-30iA post, ros-industrial-attic/robodk_postprocessors @ d7e6c1c0 Fanuc_R30iA.py 405-410 and
    474-479): ``END`` ends the program (a called program returns to its caller), ``ABORT`` ends it,
    ``PAUSE`` stops it until it is started again; ``JMP LBL[n]`` continues at ``LBL[n]``; ``CALL
    name`` runs the program name (here: one of `called`, without arguments; the others are
    recorded)."""

    state: _State
    moving: set[str]
    programs: dict[str, tuple[str, str]]          # /PROG name -> (file name, text)
    stopped: Where | None = None

    def run(self, text: str, source: str) -> None:
        try:
            self._program(text, source, [])
        except _Stop:
            pass

    def _program(self, text: str, source: str, stack: list[str]) -> None:
        positions = _positions(text, source)
        lines = _main_lines(text, source)
        labels = {m.group(1): i for i, ln in enumerate(lines)
                  if (m := re.fullmatch(r"LBL\[\s*(\d+)\s*(?::[^\]]*)?\]", ln.code, re.IGNORECASE))}
        depth = 0                  # of IF ... THEN and FOR: their bodies run straight through, reported
        i = 0
        while i < len(lines):
            line, code = lines[i], lines[i].code
            if line.number is None:
                self.state.issue(line, "unsupported", "point logic / nested statement of a motion is not modelled")
                i += 1
                continue
            word = code.upper()
            if re.match(r"^IF\b.*\bTHEN$|^FOR\b", code, re.IGNORECASE):
                depth += 1
            elif word in ("ENDIF", "ENDFOR"):
                depth = max(0, depth - 1)
            elif depth and (word in ("END", "ABORT", "PAUSE") or word.startswith("JMP")):
                self.state.issue(line, "unsupported", "an end or a jump under a condition: conditions are not evaluated")
                i += 1
                continue
            if word == "END" and stack:
                return
            if word in ("END", "ABORT", "PAUSE"):
                self.stopped = line.where
                raise _Stop
            jump = re.fullmatch(r"JMP\s+LBL\[\s*(\d+)\s*(?::[^\]]*)?\]", code, re.IGNORECASE)
            if jump:
                target = labels.get(jump.group(1))
                if target is None:
                    self.state.issue(line, "undefined", f"no LBL[{jump.group(1)}] in the program")
                elif target <= i:
                    self.state.issue(line, "unsupported", "a jump back: the statements from its label repeat")
                    self.stopped = line.where
                    raise _Stop
                else:
                    i = target
                    continue
                i += 1
                continue
            call = re.fullmatch(r"CALL\s+(\w+)", code, re.IGNORECASE)
            if call and call.group(1).upper() in self.programs:
                name = call.group(1).upper()
                if name in stack or name == _prog_name(text):
                    self.state.issue(line, "unsupported", f"{call.group(1)} calls itself: without end")
                    self.stopped = line.where
                    raise _Stop
                file, called = self.programs[name]
                self._program(called, file, [*stack, _prog_name(text)])
                i += 1
                continue
            _execute(line, positions, self.state, self.moving)
            i += 1


def _prog_name(text: str) -> str:
    m = re.search(r"^/PROG\s+(\w+)", text, re.MULTILINE)
    return m.group(1).upper() if m else ""


def _moves(text: str) -> bool:
    mn = _section(text, "MN")
    return any(re.match(r"^\s*\d+:\s*[JLCA]\s+P", line) for _, line in mn)


def _section(text: str, name: str) -> list[tuple[int, str]]:
    """(file line number, line) of the lines inside section /`name`."""
    out: list[tuple[int, str]] = []
    inside = False
    for number, line in enumerate(text.splitlines(), start=1):
        if line.startswith("/"):
            inside = line.strip().upper().startswith(f"/{name}")
            continue
        if inside:
            out.append((number, line))
    return out


# ------------------------------------------------------------------------------------- positions
def _xyzwpr(values: tuple[float, ...] | list[float]) -> FloatArray:
    """(4, 4) metres from FANUC (X, Y, Z mm, W, P, R deg): R = Rz(R)·Ry(P)·Rx(W)."""
    x, y, z, w, p, r = values
    return pose_mm_zyx_deg(x, y, z, r, p, w)


_FIELD = rf"({NUMBER})"


def _positions(text: str, source: str) -> dict[int, _Position]:
    out: dict[int, _Position] = {}
    block: list[str] = []
    start = 0
    index: int | None = None
    for number, line in _section(text, "POS"):
        head = re.match(r"^\s*P\[(\d+)(?::[^\]]*)?\]\s*\{", line)
        if head:
            index, start, block = int(head.group(1)), number, []
            continue
        if index is not None and re.match(r"^\s*\}\s*;", line):
            out[index] = _position(" ".join(block), Where(source, start))
            index = None
            continue
        if index is not None:
            block.append(line)
    return out


def _position(text: str, where: Where) -> _Position:
    groups = re.split(r"\bGP(\d+)\s*:", text)
    # groups: [before, "1", body1, "2", body2, ...]
    bodies = {int(groups[i]): groups[i + 1] for i in range(1, len(groups) - 1, 2)}
    body = bodies.get(1)
    if body is None:
        return _Position(where, None, None, None, None, None, False, "no GP1 data")
    uf = re.search(r"\bUF\s*:\s*(\w+)", body)
    ut = re.search(r"\bUT\s*:\s*(\w+)", body)
    problem = None
    uf_num = int(uf.group(1)) if uf and uf.group(1).isdigit() else None
    ut_num = int(ut.group(1)) if ut and ut.group(1).isdigit() else None
    if uf_num is None or ut_num is None:
        problem = "UF / UT is not a frame number"
    config_m = re.search(r"\bCONFIG\s*:\s*'([^']*)'", body)
    config = _config(config_m.group(1)) if config_m else None
    if config_m and config is None:
        problem = f"CONFIG '{config_m.group(1)}' is not 'F|N U|D T|B, t4, t5, t6'"
    values = {}
    for key, unit in (("X", "mm"), ("Y", "mm"), ("Z", "mm"), ("W", "deg"), ("P", "deg"), ("R", "deg")):
        m = re.search(rf"\b{key}\s*=\s*{_FIELD}\s*{unit}", body)
        if m:
            values[key] = float(m.group(1))
    joints = {int(m.group(1)): float(m.group(2)) for m in re.finditer(rf"\bJ(\d)\s*=\s*{_FIELD}\s*deg", body)}
    external = any(float(m.group(2)) != 0.0 for m in re.finditer(rf"\bE(\d)\s*=\s*{_FIELD}", body))
    cartesian = tuple(values[k] for k in "XYZWPR") if len(values) == 6 else None
    joint_values = tuple(joints[i] for i in range(1, 7)) if all(i in joints for i in range(1, 7)) else None
    if cartesian is None and joint_values is None:
        problem = problem or "neither X, Y, Z, W, P, R nor J1..J6"
    if cartesian is not None and config is None:
        problem = problem or "Cartesian position without CONFIG"
    return _Position(where, uf_num, ut_num, config, cartesian, joint_values, len(bodies) > 1 or external, problem)


def _config(text: str) -> FanucConfig | None:
    m = re.fullmatch(r"\s*([FN])\s+([UD])\s+([TB])\s*,\s*(-?\d+)\s*,\s*(-?\d+)\s*,\s*(-?\d+)\s*", text)
    if not m:
        return None
    return FanucConfig(text, m.group(1), m.group(2), m.group(3), (int(m.group(4)), int(m.group(5)), int(m.group(6))))


# ------------------------------------------------------------------------------------------ lines
def _main_lines(text: str, source: str) -> list[_Line]:
    """The /MN statements; continuation lines (``   :``) joined; nested lines (point logic) marked."""
    out: list[_Line] = []
    for number, line in _section(text, "MN"):
        m = re.match(r"^(\s*)(\d+):(.*)$", line)
        if m:
            # a statement's number is right-aligned in four columns; point-logic lines are indented further
            main = len(m.group(1)) + len(m.group(2)) <= 4
            out.append(_Line(Where(source, number), int(m.group(2)) if main else None, m.group(3).strip(), line))
        elif re.match(r"^\s*:", line) and out:
            last = out[-1]
            out[-1] = _Line(last.where, last.number, f"{last.code} {line.split(':', 1)[1].strip()}",
                            f"{last.raw} {line.strip()}")
        elif re.match(r"^\s*-+\s*;?\s*$", line) or not line.strip():
            continue
        else:
            out.append(_Line(Where(source, number), None, line.strip(), line))
    return [_Line(ln.where, ln.number, ln.code.rstrip().removesuffix(";").strip(), ln.raw) for ln in out]


# ------------------------------------------------------------------------------------- execution
_PR = r"PR\[\s*(\d+)\s*(?::[^\]]*)?\]"
_CONTROL = re.compile(r"^(JMP|IF|SELECT|ELSE|ENDIF|FOR|ENDFOR|END|ABORT|PAUSE|RUN|TC_ONLINE|"
                      r"SKIP|OFFSET|TOOL_OFFSET|VOFFSET|UALM|STOP_TRACKING|MONITOR|SPOT_CONDITION)\b", re.IGNORECASE)
_INERT = re.compile(r"^(R\[|DO\[|RO\[|GO\[|AO\[|F\[|M\[|TIMER\[|PAYLOAD\[|OVERRIDE\s*=|LBL\[\s*\d+(?::[^\]]*)?\]$|"
                    r"MESSAGE\[|JOINT_MAX_SPEED\[|LINEAR_MAX_SPEED\s*=|TIMER_OVERFLOW)", re.IGNORECASE)
_TARGET_OPTIONS = re.compile(r"^(Offset|Tool_Offset|INC|VOFFSET|Skip|RTCP|COORD|EV|Ind\.EV|PSPD|TIME\s+BEFORE|"
                             r"TIME\s+AFTER|DISTANCE\s+BEFORE)", re.IGNORECASE)


def _execute(line: _Line, positions: dict[int, _Position], state: _State, moving: set[str]) -> None:
    code = line.code
    if not code or code.startswith(("!", "//")):
        return
    motion = re.match(r"^([JLCA])\s+(.*)$", code)
    if motion and re.match(r"^(P|PR)\[", motion.group(2)):
        _motion(line, motion.group(1), motion.group(2), positions, state)
        return
    frame_num = re.fullmatch(r"(UFRAME_NUM|UTOOL_NUM)\s*=\s*(\S+)", code, re.IGNORECASE)
    if frame_num:
        if not frame_num.group(2).isdigit():
            state.issue(line, "unsupported", "frame number from a register")
            if frame_num.group(1).upper() == "UFRAME_NUM":
                state.uframe_num = None
            else:
                state.utool_num = None
            return
        if frame_num.group(1).upper() == "UFRAME_NUM":
            state.uframe_num = int(frame_num.group(2))
        else:
            state.utool_num = int(frame_num.group(2))
        return
    frame_set = re.fullmatch(rf"(UFRAME|UTOOL)\[\s*(\d+)\s*\]\s*=\s*{_PR}", code, re.IGNORECASE)
    if frame_set:
        _frame_from_register(line, frame_set.group(1).upper(), int(frame_set.group(2)), int(frame_set.group(3)),
                             state)
        return
    if re.match(r"^PR\[", code, re.IGNORECASE):
        _register(line, code, state)
        return
    call = re.fullmatch(r"CALL\s+(\w+)\s*(?:\((.*)\))?", code, re.IGNORECASE)
    if call:
        if call.group(1).upper() in moving:
            state.issue(line, "unsupported", f"{call.group(1)} moves the robot; calls are not followed")
        args = tuple(arg_value(a) for a in split_top(call.group(2) or "") if a)
        state.events.append(Call(line.where, call.group(1), args))
        return
    if re.match(r"^WAIT\b", code, re.IGNORECASE):
        _wait(line, state)
        return
    do = re.fullmatch(r"DO\[\s*(\d+)\s*(?::([^\]]*))?\]\s*=\s*(ON|OFF)", code, re.IGNORECASE)
    if do:
        # DO[k]=ON/OFF (FANUC TP I/O instructions): after a FINE point the robot is at rest when it runs.
        last = next((e for e in reversed(state.events) if isinstance(e, Motion)), None)
        state.events.append(SetOutput(line.where, f"DO[{do.group(1)}]", int(do.group(1)), do.group(3).upper() == "ON",
                                      after_stop=last is None or last.stops))
        return
    if _INERT.match(code) and not re.search(r"\bCALL\b|\bRUN\b", code, re.IGNORECASE):
        return
    if _CONTROL.match(code) or code.startswith("$"):
        state.issue(line, "unsupported", "control flow or system variable is not modelled")
        return
    state.issue(line, "unsupported", "statement outside the modelled subset")


def _frame_from_register(line: _Line, which: str, number: int, register: int, state: _State) -> None:
    table = state.uframes if which == "UFRAME" else state.utools
    reg = state.registers.get(register)
    if reg is None or not reg.cartesian or any(math.isnan(v) for v in reg.values):
        state.issue(line, "undefined", f"PR[{register}] has no complete Cartesian value")
        table.pop(number, None)
        return
    if number == 0:
        state.issue(line, "alarm", f"{which}[0] cannot be set")
        return
    table[number] = _xyzwpr(reg.values)


def _register(line: _Line, code: str, state: _State) -> None:
    element = re.fullmatch(r"PR\[\s*(\d+)\s*(?::[^\],]*)?,\s*(\d+)\s*\]\s*=\s*(\S+)", code, re.IGNORECASE)
    if element:
        reg = state.registers.get(int(element.group(1)))
        index = int(element.group(2))
        if not is_number(element.group(3)):
            state.issue(line, "unsupported", "register element from an expression")
            if reg is not None and 1 <= index <= len(reg.values):
                reg.values[index - 1] = math.nan
            return
        if reg is None:
            state.issue(line, "undefined", f"PR[{element.group(1)}] is neither set by the program nor given")
            return
        if not 1 <= index <= len(reg.values):
            state.issue(line, "alarm", f"PR element {index} does not exist")
            return
        reg.values[index - 1] = float(element.group(3))
        return
    whole = re.fullmatch(rf"{_PR}\s*=\s*(.+)", code, re.IGNORECASE)
    if not whole:
        state.issue(line, "unsupported", "register statement outside the modelled subset")
        return
    target, expr = int(whole.group(1)), whole.group(2).strip()
    if re.fullmatch(r"LPOS", expr, re.IGNORECASE):
        state.registers[target] = _Register(True, [math.nan] * 6)
        return
    if re.fullmatch(r"JPOS", expr, re.IGNORECASE):
        state.registers[target] = _Register(False, [math.nan] * 6)
        return
    terms = re.fullmatch(rf"{_PR}(?:\s*([-+])\s*{_PR})?", expr, re.IGNORECASE)
    if not terms:
        state.issue(line, "unsupported", "register expression outside the modelled subset")
        state.registers.pop(target, None)
        return
    a = state.registers.get(int(terms.group(1)))
    b = state.registers.get(int(terms.group(3))) if terms.group(3) else None
    if a is None or (terms.group(3) and b is None):
        state.issue(line, "undefined", "a position register neither set by the program nor given")
        state.registers.pop(target, None)
        return
    if b is None:
        state.registers[target] = _Register(a.cartesian, list(a.values))
        return
    if a.cartesian != b.cartesian:
        state.issue(line, "alarm", "arithmetic on registers of different representations")
        state.registers.pop(target, None)
        return
    same = terms.group(1) == terms.group(3) and terms.group(2) == "-"
    values = [0.0] * 6 if same else [x - y if terms.group(2) == "-" else x + y for x, y in zip(a.values, b.values)]
    state.registers[target] = _Register(a.cartesian, values)


def _motion(line: _Line, statement: str, rest: str, positions: dict[int, _Position], state: _State) -> None:
    if statement in ("C", "A"):
        state.issue(line, "unsupported", "circular / arc motion")
        return
    target = re.match(r"^P\[\s*(\d+)\s*(?::[^\]]*)?\]\s*(.*)$", rest)
    if not target:
        state.issue(line, "unsupported", "motion to a position register (its value is not modelled)")
        return
    index, tail = int(target.group(1)), target.group(2)
    m = re.match(r"^(R\[[^\]]*\]\S*|\S+)\s+(FINE|CNT\s*\d+|CNT\s+R\[[^\]]*\]|CR\s*\d+)\s*(.*)$", tail, re.IGNORECASE)
    if not m:
        state.issue(line, "unsupported", "speed or termination outside the modelled subset")
        return
    termination, options = m.group(2).upper().replace(" ", ""), m.group(3).strip()
    spots: list[str] = []
    for option in _options(options):
        if re.fullmatch(r"ACC\s*\d+|PTH", option, re.IGNORECASE):
            continue
        spot_option = re.fullmatch(r"SPOT\[(.*)\]", option, re.IGNORECASE)
        if spot_option:
            spots.append(spot_option.group(1))
            continue
        if _TARGET_OPTIONS.match(option):
            state.issue(line, "unsupported", f"motion option {option} changes the target")
            return
        state.issue(line, "unsupported", f"motion option {option} is not modelled")
    position = positions.get(index)
    if position is None:
        state.issue(line, "undefined", f"P[{index}] has no data in /POS")
        return
    if position.problem or position.uf is None or position.ut is None:
        state.issue(line, "unsupported", f"P[{index}]: {position.problem}")
        return
    if position.other_groups:
        state.issue(line, "unsupported", f"P[{index}] moves other motion groups or extended axes too (only GP1's "
                                         "six axes are modelled)")
    tool = state.utools.get(position.ut)
    user = state.uframes.get(position.uf)
    blend = None if termination == "FINE" else termination
    kind: MotionKind = "joint" if statement == "J" else "linear"
    target_text = f"P[{index}]"
    if position.cartesian is not None:
        if position.uf != state.uframe_num or position.ut != state.utool_num:
            state.issue(line, "alarm", f"P[{index}] has UF {position.uf}, UT {position.ut}; selected UFRAME_NUM "
                                       f"{state.uframe_num}, UTOOL_NUM {state.utool_num}")
        if user is None:
            state.issue(line, "undefined", f"UFRAME[{position.uf}] is neither set by the program nor given")
        if tool is None:
            state.issue(line, "undefined", f"UTOOL[{position.ut}] is neither set by the program nor given")
        T_base_tcp = user @ _xyzwpr(position.cartesian) if user is not None else None
        state.events.append(Motion(line.where, statement, kind, target_text, None, T_base_tcp, tool, user,
                                   position.config, blend))
    elif position.joints is not None:
        state.events.append(Motion(line.where, statement, kind, target_text,
                                   position.joints, None, tool, user, None, blend))
        if statement == "L":
            state.issue(line, "unsupported", "L to a joint position (its Cartesian pose needs the arm's FK)")
    for spot in spots:
        state.events.append(Call(line.where, "SPOT", tuple(arg_value(a) for a in split_top(spot) if a)))


def _options(text: str) -> list[str]:
    """Motion options split at spaces outside brackets; ``TB .10sec,P-SPS`` kept as one option."""
    out: list[str] = []
    depth = 0
    current = ""
    for ch in text:
        if ch == "[":
            depth += 1
        elif ch == "]":
            depth -= 1
        if ch.isspace() and depth == 0:
            if current:
                out.append(current)
                current = ""
            continue
        current += ch
    if current:
        out.append(current)
    merged: list[str] = []
    for item in out:   # "TB" ".10sec,P-SPS" -> one option
        if merged and re.fullmatch(r"TB|TA|DB", merged[-1], re.IGNORECASE):
            merged[-1] = f"{merged[-1]} {item}"
        else:
            merged.append(item)
    return merged


def _wait(line: _Line, state: _State) -> None:
    code = line.code
    timed = re.fullmatch(rf"WAIT\s+({NUMBER})\s*\(sec\)", code, re.IGNORECASE)
    if timed:
        state.events.append(Wait(line.where, seconds=float(timed.group(1))))
        return
    di = re.fullmatch(r"WAIT\s+\(?\s*(!?)\s*DI\[\s*(\d+)\s*(?::[^\]]*)?\]\s*(?:=\s*(ON|OFF))?\s*\)?", code, re.IGNORECASE)
    if di and not (di.group(1) and di.group(3)):
        awaited = (di.group(3) or "ON").upper() == "ON" and not di.group(1)
        signal = f"DI[{di.group(2)}]"
        state.events.append(Wait(line.where, signal=signal, input_number=int(di.group(2)), state=awaited))
        return
    state.issue(line, "unsupported", "WAIT other than WAIT t(sec) or WAIT DI[k]=ON|OFF")
