"""KUKA KRL (KSS 8.x): what the controller executes, for a motion subset.

Sources (/work/notes/vendor_research.md quotes each; KSS system files are from public controller
backups: NAQIU = Naqiu06/KUKA-Robotics @ 66cb2cd0, KRC/R1/System/bas.src and $config.dat,
KRC/R1/Mada/$machine.dat; CHINA = HugoDanielson/ChinaMilling @ 04c963fe, KSS 8.3.48 programs):

- Positions: POS/E6POS/FRAME aggregates ``{X, Y, Z, A, B, C[, S, T]}``, X, Y, Z in mm, A, B, C in
  degrees with R = Rz(A)·Ry(B)·Rx(C) (KUKA: rotation about Z by A, then about the new Y by B, then
  about the new X by C). AXIS/E6AXIS ``{A1 .. A6}`` in degrees as the controller counts them.
  S (Status) and T (Turn) are kept as written (``'B010'`` is a binary literal; KSS 8 sets S bit 4
  in taught points, see the notes §1.5). External axes (E1..E6) are not modelled: a non-zero value
  is reported.
- Frames: ``$ROBROOT`` is the robot in ``$WORLD``; factory value ``{X 0, ..., C 0}`` "ROBOTER IM
  WELTKOORDINATENSYSTEM" (NAQIU $machine.dat 96), so the robot base is $WORLD. $BASE is relative to
  $WORLD (BAS.SRC assigns ``$BASE=$WORLD`` for base 0 and ``$BASE=BASE_DATA[n]`` otherwise), $TOOL is
  the TCP relative to the flange ($NULLFRAME = the flange). With ``$IPO_MODE = #BASE`` a Cartesian
  target is the TCP relative to $BASE, so the TCP in the robot base is $BASE · target.
  TOOL_DATA[n] / BASE_DATA[n] are the controller's stored frames ($config.dat); the model takes
  them from setup programs, data lists and the caller, and reports one it is not given.
- Inline forms (CHINA amm_periphery.src 49-63, 235-241): ``;FOLD ... ;%{PE}`` / ``;ENDFOLD`` are
  comments; the lines between them run. BAS.SRC (NAQIU bas.src): ``#PTP_PARAMS`` and
  ``#CP_PARAMS`` call PTP_DAT / CP_DAT, then FRAMES, then VEL_PTP / VEL_CP (28-52); ``#FRAMES``
  calls FRAMES; FRAMES sets $TOOL with TOOL(FDAT_ACT.TOOL_NO) and $BASE with
  BASE(FDAT_ACT.BASE_NO) and $IPO_MODE from FDAT_ACT.IPO_FRAME (461-557); TOOL(n) gives
  $NULLFRAME for n <= 0, else TOOL_DATA[n] (404-441); BASE(n) gives $WORLD for n <= 0, else
  BASE_DATA[n] (159-186) -- with no tool/base corrections active and no machine frames (factory).
  ``#TOOL, n`` and ``#BASE, n`` call TOOL / BASE; ``#INITMOV`` sets speeds, accelerations,
  approximation, ``BASE (0)`` and ``$TOOL=TOOL_DATA[1]`` (57-100). IPO_FRAME #TCP (external TCP)
  is reported.
- Motions: ``PTP``/``LIN`` to a named point (.src or .dat) or an aggregate; approximation
  ``C_PTP``/``C_DIS``/``C_VEL``/``C_ORI`` kept as written (KSS 8.3 writes ``LIN X C_DIS C_DIS``);
  none = exact stop. A partial aggregate (missing components are taken from the current position)
  is reported.
- Spline blocks (KUKA System Software 8.x, Operating and Programming Instructions for System
  Integrators, "Spline motion type"): ``SPLINE`` ... ``ENDSPLINE`` with ``SPL`` points and ``SLIN``
  straight segments to named points or aggregates, each with at most ``WITH $VEL.CP = v`` (the
  segment's path speed: no effect on targets). The path passes through every point without
  stopping (blend ``"SPLINE"``) and stops at the last (``ENDSPLINE`` without ``C_SPL``). A block
  ``WITH`` other variables, ``ENDSPLINE C_SPL``, a segment outside a block, ``SCIRC`` and the
  spline's PTP forms are reported.
- ``WAIT SEC t``; ``WAIT FOR $IN[k]`` (``==TRUE``/``==FALSE``/``NOT``) or a name declared by
  ``SIGNAL name $IN[k]``. A call of a DEF of the .src without parameters runs its body (`_Flow`:
  RETURN, HALT, GOTO and jump labels too); other subroutine calls are recorded (name, args), not
  followed, and a call with arguments of a routine given in the texts that moves or changes
  frames is reported.

Outside this subset (control flow, relative motions, spline motions other than the blocks above, CIRC,
offsets and geometric operators, $ROBROOT or $IPO_MODE changes, interrupts other than the template's stop-message
handler, assignments to position variables, function calls) a statement is an ``unsupported`` issue.
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from .common import (
    Call,
    Event,
    FloatArray,
    Issue,
    IssueKind,
    KrlConfig,
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
    strip_comment,
)

_AXES = ("A1", "A2", "A3", "A4", "A5", "A6")
_CART = ("X", "Y", "Z", "A", "B", "C")
_POSITION_TYPES = {"E6POS", "POS", "FRAME", "E6AXIS", "AXIS"}
# Assignments that change speed, acceleration, approximation, outputs or the display only.
_INERT_SYSVARS = re.compile(
    r"^\$(VEL|VEL_AXIS|ACC|ACC_AXIS|APO|ADVANCE|OV_PRO|OUT|BWDSTART|LOAD|ORI_TYPE|CIRC_TYPE|ACT_TOOL|"
    r"ACT_BASE|ACT_EX_AX|H_POS|TIMER|TIMER_STOP|FLAG|CP_VEL_TYPE|GEAR_JERK|VEL_EXTAX|ACC_EXTAX)\b",
    re.IGNORECASE)
_INERT_BAS = {"PTP_DAT", "CP_DAT", "VEL_PTP", "VEL_CP", "ACC_PTP", "ACC_CP", "OUT_SYNC", "OUT_ASYNC"}
_FRAME_BAS = {"PTP_PARAMS", "CP_PARAMS", "FRAMES"}
_CONTROL = re.compile(
    r"^(IF|ELSE|ENDIF|FOR|ENDFOR|WHILE|ENDWHILE|LOOP|ENDLOOP|REPEAT|UNTIL|SWITCH|CASE|DEFAULT|ENDSWITCH|"
    r"GOTO|EXIT|HALT|RETURN|CONTINUE|BRAKE|RESUME|TRIGGER|ON_ERROR_PROCEED|ERR_RAISE|ASYPTP|ASYSTOP|ASYCONT|"
    r"ASYCANCEL)\b", re.IGNORECASE)
_UNSUPPORTED_MOTION = re.compile(
    r"^(PTP_REL|LIN_REL|CIRC|CIRC_REL|SPTP|SPTP_REL|SLIN|SLIN_REL|SCIRC|SCIRC_REL|SPL|SPLINE|ENDSPLINE|"
    r"PTP_SPLINE|ENDPTP_SPLINE|TIME_BLOCK|CONST_VEL)\b", re.IGNORECASE)
_DECL_TYPES = r"INT|REAL|BOOL|CHAR|FRAME|POS|E6POS|AXIS|E6AXIS|FDAT|PDAT|LDAT|LOAD|STRUC|ENUM"
_OPENS = re.compile(r"^(IF\b.*\bTHEN|WHILE\b.*|FOR\b.*|LOOP|REPEAT|SWITCH\b.*)$", re.IGNORECASE)
_CLOSES = re.compile(r"^(ENDIF|ENDWHILE|ENDFOR|ENDLOOP|UNTIL\b.*|ENDSWITCH)$", re.IGNORECASE)


@dataclass(slots=True)
class _Value:
    """A declared variable: its KRL type and its value as written (an aggregate's fields, or text)."""

    type: str
    fields: dict[str, str] | None
    text: str


@dataclass(slots=True)
class _Line:
    where: Where
    code: str          # without comment, stripped
    raw: str


@dataclass(slots=True)
class _State:
    tool: FloatArray | None
    base: FloatArray | None
    tool_data: dict[int, FloatArray]
    base_data: dict[int, FloatArray]
    variables: dict[str, _Value] = field(default_factory=dict)
    signals: dict[str, int] = field(default_factory=dict)
    outputs: dict[str, int] = field(default_factory=dict)     # SIGNAL name -> $OUT number
    continued: bool = False                                     # CONTINUE before this statement
    fdat: _Value | None = None
    events: list[Event] = field(default_factory=list)
    issues: list[Issue] = field(default_factory=list)
    spline: int | None = None          # inside SPLINE ... ENDSPLINE: the index of its first event

    def issue(self, line: _Line, kind: IssueKind, reason: str) -> None:
        self.issues.append(Issue(line.where, kind, line.raw.strip(), reason))


def run_krl(src: str, dat: str = "", *, src_name: str = "program.src", dat_name: str = "program.dat",
            data: Mapping[str, str] | None = None, setup: Mapping[str, str] | None = None,
            tool_data: Mapping[int, FloatArray] | None = None, base_data: Mapping[int, FloatArray] | None = None,
            tool: FloatArray | None = None, base: FloatArray | None = None) -> ProgramRun:
    """Runs the first routine (``DEF``) of `src`, with the points of `dat`, as KSS 8.x would.

    Parameters
    ----------
    src, dat : str
        The program's .src and .dat texts (`dat` may be empty).
    data : mapping of name to text, optional
        Further data lists read before the .dat (e.g. the controller's ``$config.dat``): their
        declarations are global, their ``TOOL_DATA[n]``/``BASE_DATA[n]`` entries stored frames.
    setup : mapping of name to text, optional
        Setup programs (.src) run before, on the same controller: their ``TOOL_DATA[n] = {...}`` and
        ``BASE_DATA[n] = {...}`` assignments become stored frames. Anything else in them is an issue.
    tool_data, base_data : mapping of int to (4, 4) float, optional
        The controller's stored TOOL_DATA / BASE_DATA (metres), before the setup programs run.
    tool, base : (4, 4) float, optional
        $TOOL and $BASE in force when the program starts (None: unknown until the program sets them).

    Returns
    -------
    ProgramRun
        Motions with T_base_tcp = $BASE · target in the robot base ($ROBROOT = $WORLD), the $TOOL
        and $BASE in force, S and T as written; calls; waits; issues.
    """
    state = _State(tool=tool, base=base, tool_data=dict(tool_data or {}), base_data=dict(base_data or {}))
    for name, text in (data or {}).items():
        _read_dat(text, name, state)
    for name, text in (setup or {}).items():
        _run_setup(text, name, state)
    if dat:
        _read_dat(dat, dat_name, state)
    lines = _lines(src, src_name)
    routines = _routines(lines)
    if not routines:
        where = Where(src_name, 1)
        state.issues.append(Issue(where, "unsupported", "", "no DEF routine in the .src"))
        return ProgramRun("krl", (), tuple(state.issues))
    first = next(iter(routines))
    moving = {name for name, (a, b) in routines.items() if _moves(lines[a + 1:b]) and _params(lines[a])}
    flow = _Flow(lines, routines, state, moving)
    flow.run(first, [])
    return ProgramRun("krl", tuple(state.events), tuple(state.issues), stopped=flow.stopped)


def _params(head: _Line) -> bool:
    """Whether a DEF line declares parameters."""
    m = _DEF_RE.match(head.code)
    return bool(m and m.group(2).strip())


class _Stop(Exception):
    """The program stops: an end, a pause, or a jump that repeats without end."""


@dataclass(slots=True)
class _Flow:
    """KSS 8.3 Operating and Programming Instructions for System Integrators, program execution
    control: ``GOTO label`` continues at ``label:`` in the same routine; ``RETURN`` returns from a
    subprogram and ends the main program; ``HALT`` stops the program until it is started again
    (RoboDK's KRC4 post, ros-industrial-attic/robodk_postprocessors @ d7e6c1c0 KUKA_KRC4.py 281-286
    and 345-354, writes ``HALT`` to pause a program and ``START_TIMER:`` / ``GOTO START_TIMER``); a
    subprogram call ``name()`` runs the DEF ``name`` of the file."""

    lines: list[_Line]
    routines: dict[str, tuple[int, int]]
    state: _State
    moving: set[str]
    stopped: Where | None = None

    def run(self, name: str, stack: list[str]) -> None:
        try:
            self._body(name, stack)
        except _Stop:
            pass

    def _body(self, name: str, stack: list[str]) -> None:
        a, b = self.routines[name]
        body = self.lines[a + 1:b]
        labels = {m.group(1).upper(): i for i, ln in enumerate(body) if (m := re.fullmatch(r"(\w+)\s*:", ln.code))}
        depth = 0                  # of IF, loops, SWITCH: their bodies run straight through, reported
        i = 0
        while i < len(body):
            line, code = body[i], body[i].code
            if _OPENS.match(code):
                depth += 1
            elif _CLOSES.match(code):
                depth = max(0, depth - 1)
            elif depth and re.fullmatch(r"RETURN|HALT|GOTO\s+\w+", code, re.IGNORECASE):
                self.state.issue(line, "unsupported", "an end or a jump under a condition: conditions are not evaluated")
                i += 1
                continue
            if re.fullmatch(r"RETURN", code, re.IGNORECASE):
                if stack:
                    return
                self.stopped = line.where
                raise _Stop
            if re.fullmatch(r"HALT", code, re.IGNORECASE):
                self.stopped = line.where
                raise _Stop
            jump = re.fullmatch(r"GOTO\s+(\w+)", code, re.IGNORECASE)
            if jump:
                target = labels.get(jump.group(1).upper())
                if target is None:
                    self.state.issue(line, "undefined", f"no jump label {jump.group(1)} in the routine")
                elif target <= i:
                    self.state.issue(line, "unsupported", "a jump back: the statements from its label repeat")
                    self.stopped = line.where
                    raise _Stop
                else:
                    i = target
                    continue
                i += 1
                continue
            if re.fullmatch(r"\w+\s*:", code):
                i += 1
                continue
            call = _CALL_RE.match(code)
            callee = call.group(1).upper() if call else ""
            if call and callee in self.routines and not call.group(2).strip() and not _params(self.lines[self.routines[callee][0]]):
                if callee in stack or callee == name:
                    self.state.issue(line, "unsupported", f"{call.group(1)} calls itself: without end")
                    self.stopped = line.where
                    raise _Stop
                self._body(callee, [*stack, name])
                i += 1
                continue
            _execute(line, self.state, self.moving)
            i += 1


# --------------------------------------------------------------------------------------- structure
def _lines(text: str, name: str) -> list[_Line]:
    out = []
    for i, raw in enumerate(text.splitlines(), start=1):
        out.append(_Line(Where(name, i), strip_comment(raw, ";").strip(), raw))
    return out


_DEF_RE = re.compile(r"^(?:GLOBAL\s+)?DEF\s+(\w+)\s*\((.*)\)\s*$", re.IGNORECASE)
_DEFFCT_RE = re.compile(r"^(?:GLOBAL\s+)?DEFFCT\s+\w+\s+(\w+)\s*\(", re.IGNORECASE)


def _routines(lines: list[_Line]) -> dict[str, tuple[int, int]]:
    """Routine name (upper case) -> (index of its DEF line, index of its END line), in text order."""
    out: dict[str, tuple[int, int]] = {}
    current: str | None = None
    start = 0
    for i, line in enumerate(lines):
        m = _DEF_RE.match(line.code) or _DEFFCT_RE.match(line.code)
        if m:
            current, start = m.group(1).upper(), i
        elif current and re.match(r"^(END|ENDFCT)$", line.code, re.IGNORECASE):
            out[current] = (start, i)
            current = None
    return out


def _moves(body: list[_Line]) -> bool:
    """Whether a routine's body moves the robot or changes its frames (then a call is reported)."""
    for line in body:
        code = line.code
        if re.match(r"^(PTP|LIN|CIRC|SPTP|SLIN|SCIRC|SPL|PTP_REL|LIN_REL)\b", code, re.IGNORECASE):
            return True
        if re.match(r"^\$(TOOL|BASE|ROBROOT|IPO_MODE)\s*=", code, re.IGNORECASE) or re.match(r"^BAS\s*\(", code, re.IGNORECASE):
            return True
    return False


# ---------------------------------------------------------------------------------- declarations
_DECL_RE = re.compile(r"^(?:GLOBAL\s+)?(DECL\s+)?(?:GLOBAL\s+)?(?:CONST\s+)?(\w+)\s+([\w$].*)$", re.IGNORECASE)
_SIGNAL_RE = re.compile(r"^(?:GLOBAL\s+)?SIGNAL\s+(\w+)\s+\$(\w+)\[(\d+)\](\s+TO\s+.*)?$", re.IGNORECASE)


def _declaration(line: _Line, state: _State) -> bool:
    """Stores a declaration (DECL, typed variable, SIGNAL, EXT); False when `line` is none."""
    code = line.code
    if re.match(r"^(EXT|EXTFCT|EXTP|EXTFCTP|IMPORT)\b", code, re.IGNORECASE):
        return True
    sig = _SIGNAL_RE.match(code)
    if sig:
        if sig.group(2).upper() == "IN" and not sig.group(4):
            state.signals[sig.group(1).upper()] = int(sig.group(3))
        elif sig.group(2).upper() == "OUT" and not sig.group(4):
            state.outputs[sig.group(1).upper()] = int(sig.group(3))
        return True
    m = _DECL_RE.match(code)
    if not m or not (m.group(1) or re.fullmatch(_DECL_TYPES, m.group(2), re.IGNORECASE)):
        return False
    type_, rest = m.group(2).upper(), m.group(3)
    items: list[tuple[str, str | None]]
    if "=" in rest:
        name, value = rest.split("=", 1)
        items = [(name, value.strip())]
    else:
        items = [(name, None) for name in split_top(rest)]
    if not all(re.fullmatch(r"[\w$]+\s*(\[[^\]]*\])?", name.strip()) for name, _ in items):
        return False
    for name, value in items:
        key = _name(re.sub(r"\[.*$", "", name))
        if value is None:
            state.variables.setdefault(key, _Value(type_, None, ""))
        else:
            state.variables[key] = _Value(type_, _aggregate(value) if value.startswith("{") else None, value)
    return True


def _read_dat(text: str, name: str, state: _State) -> None:
    """A data list: declarations and initialisations of array elements (``NAME[3]={...}``)."""
    for line in _lines(text, name):
        code = line.code
        if not code or re.match(r"^(DEFDAT|ENDDAT)\b", code, re.IGNORECASE) or code.startswith("&"):
            continue
        if re.match(r"^(GLOBAL\s+)?(STRUC|ENUM)\b", code, re.IGNORECASE) or _stored_frame(line, state):
            continue
        element = re.fullmatch(r"([\w$]+\s*\[[^\]]*\])\s*=\s*(.+)", code)
        if element:
            key = _name(element.group(1))
            declared = state.variables.get(key.split("[")[0])
            value = element.group(2).strip()
            state.variables[key] = _Value(declared.type if declared else "", _aggregate(value), value)
            continue
        if not _declaration(line, state):
            state.issue(line, "unsupported", "not a declaration in the .dat")


def _name(text: str) -> str:
    """A variable's key: upper case, no spaces (``xp1`` -> ``XP1``, ``Pos[ 2 ]`` -> ``POS[2]``)."""
    return re.sub(r"\s+", "", text).upper()


def _aggregate(text: str) -> dict[str, str] | None:
    """``{X 1, Y 2, S 'B010', IPO_FRAME #BASE}`` -> {"X": "1", ...}, keys upper case; None if malformed."""
    text = text.strip()
    if not (text.startswith("{") and text.endswith("}")):
        return None
    body = text[1:-1].strip()
    if re.match(r"^\w+\s*:", body):        # {E6POS: X 1, ...}
        body = body.split(":", 1)[1]
    out: dict[str, str] = {}
    for item in split_top(body):
        if not item:
            continue
        m = re.match(r"^(\w+)(?:\[\])?\s+(.+)$", item, re.DOTALL)
        if not m:
            return None
        out[m.group(1).upper()] = m.group(2).strip()
    return out


def _int_literal(text: str) -> int | None:
    """KRL integer literal: ``42``, ``'B101010'`` (binary) or ``'H2A'`` (hex)."""
    text = text.strip()
    m = re.fullmatch(r"'([BH])([0-9A-Fa-f]+)'", text, re.IGNORECASE)
    if m:
        return int(m.group(2), 2 if m.group(1).upper() == "B" else 16)
    return int(text) if re.fullmatch(r"[-+]?\d+", text) else None


def _frame(fields: dict[str, str]) -> FloatArray | None:
    """(4, 4) metres from X, Y, Z mm and A, B, C deg, when all six are number literals."""
    if not all(k in fields and is_number(fields[k]) for k in _CART):
        return None
    x, y, z, a, b, c = (float(fields[k]) for k in _CART)
    return pose_mm_zyx_deg(x, y, z, a, b, c)


# ---------------------------------------------------------------------------------------- setup
def _run_setup(text: str, name: str, state: _State) -> None:
    """A setup program: only stored-frame assignments (and its structure and comments) are allowed."""
    for line in _lines(text, name):
        code = line.code
        if not code or code.startswith("&") or _DEF_RE.match(code) or re.fullmatch(r"END", code, re.IGNORECASE):
            continue
        if not _stored_frame(line, state):
            state.issue(line, "unsupported", "a setup program may only assign TOOL_DATA[n] and BASE_DATA[n]")


_STORED_RE = re.compile(r"^(TOOL_DATA|BASE_DATA)\s*\[\s*(\d+)\s*\]\s*=\s*(\{.*\})$", re.IGNORECASE)


def _stored_frame(line: _Line, state: _State) -> bool:
    m = _STORED_RE.match(line.code)
    if not m:
        return False
    fields = _aggregate(m.group(3))
    frame = _frame(fields) if fields is not None else None
    if frame is None:
        state.issue(line, "unsupported", "a stored frame needs all of X, Y, Z, A, B, C as numbers")
        return True
    (state.tool_data if m.group(1).upper() == "TOOL_DATA" else state.base_data)[int(m.group(2))] = frame
    return True


# ------------------------------------------------------------------------------------- statements
_MOTION_RE = re.compile(r"^(PTP|LIN)\s+(.+?)((?:\s+(?:C_PTP|C_DIS|C_VEL|C_ORI))*)\s*$", re.IGNORECASE)
_CALL_RE = re.compile(r"^(\w+)\s*\((.*)\)$", re.DOTALL)
_FRAME_ASSIGN_RE = re.compile(r"^\$(TOOL|BASE)\s*=\s*(.+)$", re.IGNORECASE)


def _execute(line: _Line, state: _State, moving: set[str]) -> None:
    code = line.code
    if not code:
        return
    if _declaration(line, state) or _stored_frame(line, state):
        return
    if re.fullmatch(r"CONTINUE", code, re.IGNORECASE):
        state.continued = True
        return
    continued, state.continued = state.continued, False
    out = re.fullmatch(r"(\$OUT\s*\[\s*(\d+)\s*\]|\w+)\s*=\s*(TRUE|FALSE)", code, re.IGNORECASE)
    if out and (out.group(2) or _name(out.group(1)) in state.outputs):
        # KSS: an output assignment stops the advance run unless CONTINUE precedes it (the OUT
        # inline form's CONT), so it is set once the motion before it has ended.
        number = int(out.group(2)) if out.group(2) else state.outputs[_name(out.group(1))]
        state.events.append(SetOutput(line.where, out.group(1), number, out.group(3).upper() == "TRUE",
                                      after_stop=not continued))
        return
    if _spline(line, state):
        return
    if _UNSUPPORTED_MOTION.match(code):
        state.issue(line, "unsupported", "motion type outside the modelled subset (PTP, LIN)")
        return
    motion = _MOTION_RE.match(code)
    if motion:
        _motion(line, motion.group(1).upper(), motion.group(2).strip(), motion.group(3), state)
        return
    assign = _FRAME_ASSIGN_RE.match(code)
    if assign:
        _frame_assignment(line, assign.group(1).upper(), assign.group(2).strip(), state)
        return
    if re.match(r"^WAIT\b", code, re.IGNORECASE):
        _wait(line, state)
        return
    if _CONTROL.match(code) or re.match(r"^\w+:\s*$", code):
        state.issue(line, "unsupported", "control flow is not modelled")
        return
    if re.match(r"^(GLOBAL\s+)?INTERRUPT\b", code, re.IGNORECASE):
        if re.match(r"^(GLOBAL\s+)?INTERRUPT\s+DECL\s+\d+\s+WHEN\s+\$STOPMESS\s*==\s*TRUE\s+DO\s+IR_STOPM\s*\(\s*\)$",
                    code, re.IGNORECASE) or re.match(r"^INTERRUPT\s+(ON|OFF)\s+\d+$", code, re.IGNORECASE):
            return   # the template's stop-message handler (BASISTECH INI)
        state.issue(line, "unsupported", "interrupts are not modelled")
        return
    fdat = re.match(r"^FDAT_ACT\s*=\s*([\w$]+)$", code, re.IGNORECASE)
    if fdat:
        value = state.variables.get(_name(fdat.group(1)))
        if value is None or value.fields is None:
            state.issue(line, "undefined", f"FDAT {fdat.group(1)} is not declared with a value")
            state.fdat = None
        else:
            state.fdat = value
        return
    if re.match(r"^(PDAT_ACT|LDAT_ACT)\s*=\s*\w+$", code, re.IGNORECASE):
        return   # motion parameters (velocity, acceleration, approximation): no effect on targets
    if code.startswith("$"):
        if _INERT_SYSVARS.match(code):
            return
        state.issue(line, "unsupported", "system variable assignment that may change motion")
        return
    call = _CALL_RE.match(code)
    if call:
        name = call.group(1).upper()
        args = [a for a in split_top(call.group(2)) if a]
        if name == "BAS":
            _bas(line, args, state)
            return
        if name == "PULSE":
            return   # an output pulse
        if name in moving:
            state.issue(line, "unsupported", f"{call.group(1)} moves the robot or changes frames; calls are not followed")
        state.events.append(Call(line.where, call.group(1), tuple(arg_value(a) for a in args)))
        return
    plain = re.match(r"^([\w$]+)((?:\[[^\]]*\]|\.\w+)*)\s*=\s*(.+)$", code)
    if plain:
        var = state.variables.get(_name(plain.group(1)))
        if var is not None and var.type in _POSITION_TYPES:
            state.issue(line, "unsupported", "assignment to a position variable")
        elif re.search(r"[\w$]\s*\(", plain.group(3)):
            state.issue(line, "unsupported", "function call in an expression (may act on motion)")
        return   # a plain variable assignment: no motion
    state.issue(line, "unsupported", "statement outside the modelled subset")


_SEGMENT_RE = re.compile(r"^(SPL|SLIN)\s+(.+?)(?:\s+WITH\s+(.+))?$", re.IGNORECASE)


def _spline(line: _Line, state: _State) -> bool:
    """A statement of a spline block, handled (True) or not one (False)."""
    code = line.code
    word = code.split()[0].upper()
    if word == "SPLINE":
        if code.upper() != "SPLINE":
            state.issue(line, "unsupported", "a spline block WITH system variables")
        elif state.spline is not None:
            state.issue(line, "alarm", "SPLINE inside a spline block")
        state.spline = len(state.events)
        return True
    if word == "ENDSPLINE":
        if state.spline is None:
            state.issue(line, "alarm", "ENDSPLINE without SPLINE")
        elif code.upper() != "ENDSPLINE":
            state.issue(line, "unsupported", "an approximated spline block (C_SPL)")
        elif state.events and len(state.events) > state.spline and isinstance(state.events[-1], Motion):
            # The block ends at an exact stop at its last point.
            state.events[-1] = dataclasses.replace(state.events[-1], blend=None)
        state.spline = None
        return True
    segment = _SEGMENT_RE.match(code)
    if word not in ("SPL", "SLIN") or segment is None:
        return False
    if state.spline is None:
        state.issue(line, "unsupported", f"{word} outside a spline block (a spline motion of its own)")
        return True
    if segment.group(3) is not None and not re.fullmatch(r"\$VEL\.CP\s*=\s*[0-9.]+", segment.group(3).strip(),
                                                         re.IGNORECASE):
        state.issue(line, "unsupported", "a segment WITH variables other than $VEL.CP")
        return True
    _motion(line, word, segment.group(2).strip(), " SPLINE", state)
    return True


def _frame_assignment(line: _Line, which: str, expr: str, state: _State) -> None:
    frame: FloatArray | None
    stored = re.fullmatch(r"(TOOL_DATA|BASE_DATA)\s*\[\s*(\d+)\s*\]", expr, re.IGNORECASE)
    if stored:
        table = state.tool_data if stored.group(1).upper() == "TOOL_DATA" else state.base_data
        number = int(stored.group(2))
        if stored.group(1).upper() != f"{which}_DATA":
            state.issue(line, "unsupported", f"${which} from {stored.group(1)}")
            return
        frame = table.get(number)
        if frame is None:
            state.issue(line, "undefined", f"{stored.group(1).upper()}[{number}] is neither set by a setup "
                                           "program nor given as a stored value")
    elif re.fullmatch(r"\$NULLFRAME|\$WORLD", expr, re.IGNORECASE):
        frame = np.eye(4)
    elif expr.startswith("{"):
        fields = _aggregate(expr)
        frame = _frame(fields) if fields is not None else None
        if frame is None:
            state.issue(line, "unsupported", "a frame aggregate needs all of X, Y, Z, A, B, C as numbers")
            return
    elif re.fullmatch(r"[\w$]+(\s*\[\s*\d+\s*\])?", expr) and _name(expr) in state.variables:
        value = state.variables[_name(expr)]
        frame = _frame(value.fields) if value.fields is not None else None
        if frame is None:
            state.issue(line, "undefined", f"{expr} has no complete frame value")
    else:
        state.issue(line, "unsupported", f"${which} from an expression")
        return
    if which == "TOOL":
        state.tool = frame
    else:
        state.base = frame


def _bas(line: _Line, args: list[str], state: _State) -> None:
    command = args[0].lstrip("#").upper() if args else ""
    if command in _INERT_BAS:
        return
    if command == "INITMOV":   # BAS.SRC INITMOV: BASE (0) ($BASE = $WORLD) and $TOOL = TOOL_DATA[1]
        state.base = np.eye(4)
        state.tool = state.tool_data.get(1)
        return
    if command in _FRAME_BAS:
        if state.fdat is None or state.fdat.fields is None:
            state.issue(line, "undefined", "BAS sets frames from FDAT_ACT, which the program has not set")
            state.tool = state.base = None
            return
        fields = state.fdat.fields
        ipo = fields.get("IPO_FRAME", "#BASE").upper()
        if ipo != "#BASE":
            state.issue(line, "unsupported", f"IPO_FRAME {ipo} (external TCP) is not modelled")
        tool_no, base_no = _int_literal(fields.get("TOOL_NO", "")), _int_literal(fields.get("BASE_NO", ""))
        if tool_no is None or base_no is None:
            state.issue(line, "undefined", "FDAT without TOOL_NO or BASE_NO")
            state.tool = state.base = None
            return
        state.tool = _numbered(line, "TOOL_DATA", tool_no, state.tool_data, state)
        state.base = _numbered(line, "BASE_DATA", base_no, state.base_data, state)
        return
    if command in {"TOOL", "BASE"} and len(args) == 2 and is_number(args[1]):
        number = int(float(args[1]))
        if command == "TOOL":
            state.tool = _numbered(line, "TOOL_DATA", number, state.tool_data, state)
        else:
            state.base = _numbered(line, "BASE_DATA", number, state.base_data, state)
        return
    state.issue(line, "unsupported", f"BAS command {args[0] if args else ''} is not modelled")


def _numbered(line: _Line, table_name: str, number: int, table: dict[int, FloatArray],
              state: _State) -> FloatArray | None:
    if number <= 0:
        return np.eye(4)    # BAS.SRC TOOL / BASE: number <= 0 gives $NULLFRAME / $WORLD
    frame = table.get(number)
    if frame is None:
        state.issue(line, "undefined", f"{table_name}[{number}] is neither set by a setup program nor given")
    return frame


def _motion(line: _Line, statement: str, target: str, approx: str, state: _State) -> None:
    kind: MotionKind = "joint" if statement == "PTP" else "linear"      # SPL / SLIN: Cartesian targets
    fields: dict[str, str] | None
    type_: str
    if target.startswith("{"):
        fields = _aggregate(target)
        type_ = "E6AXIS" if fields is not None and any(k in fields for k in _AXES) else "E6POS"
    elif re.fullmatch(r"[\w$]+(\s*\[\s*\d+\s*\])?", target) and not target.startswith("$"):
        value = state.variables.get(_name(target))
        if value is None or value.fields is None:
            state.issue(line, "undefined", f"point {target} is not declared with a value in the .src or .dat")
            return
        fields, type_ = value.fields, value.type
    else:
        state.issue(line, "unsupported", "motion to an expression (offsets, geometric operator, system variable)")
        return
    if fields is None:
        state.issue(line, "unsupported", "malformed aggregate")
        return
    blend = " ".join(approx.upper().split()) or None   # "C_DIS", or "C_DIS C_DIS" as KSS 8.3 writes LIN; "SPLINE"
    external = [k for k in ("E1", "E2", "E3", "E4", "E5", "E6") if k in fields and fields[k] != "0"
                and not (is_number(fields[k]) and float(fields[k]) == 0.0)]
    if external:
        state.issue(line, "unsupported", f"external axis values {', '.join(external)} are not modelled")
    if type_ in {"E6AXIS", "AXIS"}:
        if statement != "PTP":
            state.issue(line, "unsupported", f"{statement} to an axis position")
            return
        if not all(k in fields and is_number(fields[k]) for k in _AXES):
            state.issue(line, "unsupported", "partial axis aggregate (missing axes keep their current value)")
            return
        joints = tuple(float(fields[k]) for k in _AXES)
        state.events.append(Motion(line.where, statement, "joint", target, joints, None, state.tool, state.base,
                                   None, blend))
        return
    if type_ not in {"E6POS", "POS", "FRAME"}:
        state.issue(line, "unsupported", f"motion to a {type_}")
        return
    T_target = _frame(fields)
    if T_target is None:
        state.issue(line, "unsupported", "partial Cartesian aggregate (missing components keep their current value)")
        return
    config = None
    if "S" in fields or "T" in fields:
        config = KrlConfig(_int_literal(fields["S"]) if "S" in fields else None,
                           _int_literal(fields["T"]) if "T" in fields else None)
    if state.base is None:
        state.issue(line, "undefined", "Cartesian target while $BASE is unknown")
    if state.tool is None:
        state.issue(line, "undefined", "Cartesian target while $TOOL is unknown")
    T_base_tcp = state.base @ T_target if state.base is not None else None
    state.events.append(Motion(line.where, statement, kind, target, None, T_base_tcp, state.tool, state.base,
                               config, blend))


def _wait(line: _Line, state: _State) -> None:
    code = line.code
    sec = re.fullmatch(r"WAIT\s+SEC\s+(.+)", code, re.IGNORECASE)
    if sec:
        if is_number(sec.group(1)):
            state.events.append(Wait(line.where, seconds=float(sec.group(1))))
        else:
            state.issue(line, "unsupported", "WAIT SEC with an expression")
        return
    cond = re.fullmatch(r"WAIT\s+FOR\s+(.+)", code, re.IGNORECASE)
    if cond:
        text = cond.group(1).strip()
        while text.startswith("(") and text.endswith(")"):
            text = text[1:-1].strip()
        state_ = True
        neg = re.fullmatch(r"NOT\s+(.+)", text, re.IGNORECASE)
        if neg:
            text, state_ = neg.group(1).strip(), False
        cmp = re.fullmatch(r"(.+?)\s*==\s*(TRUE|FALSE)", text, re.IGNORECASE)
        if cmp:
            text = cmp.group(1).strip()
            state_ = state_ == (cmp.group(2).upper() == "TRUE")
        inp = re.fullmatch(r"\$IN\s*\[\s*(\d+)\s*\]", text, re.IGNORECASE)
        if inp:
            state.events.append(Wait(line.where, signal=text, input_number=int(inp.group(1)), state=state_))
            return
        if re.fullmatch(r"\w+", text) and _name(text) in state.signals:
            state.events.append(Wait(line.where, signal=text, input_number=state.signals[_name(text)], state=state_))
            return
    state.issue(line, "unsupported", "WAIT other than WAIT SEC t or WAIT FOR an input")
