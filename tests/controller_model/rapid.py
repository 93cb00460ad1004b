r"""ABB RAPID: what an IRC5 / OmniCore controller executes, for a motion subset.

Sources (/work/notes/vendor_research.md §2 quotes each): ABB RAPID reference manual, data types
robtarget, wobjdata, tooldata, confdata (BaseWare OS 3.x edition on yumpu, pp. 165, 233-234);
ABB's ROS message definitions citing the "Technical reference manual - RAPID Instructions,
Functions and Data types" (ros-industrial/abb_robot_driver_interfaces @ f5d7d117,
abb_rapid_msgs/msg/RobTarget.msg, WObjData.msg, ToolData.msg, ConfData.msg).

- robtarget ``[trans, rot, robconf, extax]``: trans [x, y, z] in mm "in relation to the current
  object coordinate system ... If no work object is specified then this is the world coordinate
  system"; rot a quaternion [q1, q2, q3, q4], q1 the scalar part, which must be normalised (the
  model reports a norm off by more than `QUATERNION_NORM_TOL`; ABB states no tolerance); robconf
  confdata [cf1, cf4, cf6, cfx] kept as written; extax: a value other than 9E9 (an external
  axis that moves) is reported, external axes are not modelled.
- jointtarget ``[robax, extax]``: robax in degrees as the controller counts them.
- tooldata ``[robhold, tframe, tload]``: robhold TRUE = the robot holds the tool; tframe is the
  TCP "in mm, expressed in the wrist coordinate system (tool0)".
- wobjdata ``[robhold, ufprog, ufmec, uframe, oframe]``: robhold FALSE with ufprog TRUE (fixed user
  frame, ufmec "") -- "the user coordinate system is defined in the world coordinate system" and
  "the object coordinate system is defined in the user coordinate system", so a target's TCP is
  uframe · oframe · target in the world. On a controller with factory settings the robot base is
  the world frame (ROS-I ``base_link`` to "ABB World Coordinates" is the identity), hence this is
  also the TCP in the robot base. wobj0 and tool0 are the identity.
- MoveJ / MoveL ToPoint, Speed, Zone, Tool [\WObj]; MoveAbsJ ToJointPos, Speed, Zone, Tool; zone
  ``fine`` (or a zonedata with finep TRUE) is a stop point. SpotL / SpotJ (SpotWare: "Move the TCP
  along a linear path and perform a spot welding at the end position") are read with ToPoint the
  first and Tool the last positional argument (the exact argument list is UNCONFIRMED): a stop
  motion followed by a call.
- WaitTime [\InPos,] Time; WaitDI Signal, Value; a call ``Name;`` of a procedure of the modules
  without parameters runs it (`_run`: RETURN, EXIT, Stop, GOTO and labels too); other procedure
  calls ``Name arg, ...;`` are recorded, not followed (a call of a procedure given in the texts
  that moves is reported). Data may be declared in any module of the task.

Outside this subset (control flow, other motion instructions, offsets such as Offs / RelTool /
PDispOn, \Conc, \Corr, ConfL/ConfJ \Off, coordinated work objects, stationary tools,
assignments to position data) a statement is an ``unsupported`` issue.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from .common import (
    MM,
    Call,
    Event,
    FloatArray,
    Issue,
    IssueKind,
    Motion,
    MotionKind,
    ProgramRun,
    RapidConfig,
    SetOutput,
    Wait,
    Where,
    arg_value,
    homogeneous,
    is_number,
    rot_quat_wxyz,
    split_top,
    strip_comment,
)

QUATERNION_NORM_TOL = 1e-3   # |‖q‖ - 1| above this: the controller refuses the orient (model's bound)

Value = float | bool | str | list["Value"]

_BLOCK = re.compile(
    r"^(MODULE|ENDMODULE|PROC|ENDPROC|FUNC|ENDFUNC|TRAP|ENDTRAP|IF|ELSE|ELSEIF|ENDIF|WHILE|ENDWHILE|FOR|"
    r"ENDFOR|TEST|CASE|DEFAULT|ENDTEST|ERROR|BACKWARD|UNDO|LOCAL\s+PROC|LOCAL\s+FUNC|LOCAL\s+TRAP)\b", re.IGNORECASE)
_CONTROL = re.compile(
    r"^(IF|ELSE|ELSEIF|ENDIF|WHILE|ENDWHILE|FOR|ENDFOR|TEST|CASE|DEFAULT|ENDTEST|GOTO|RETURN|EXIT|EXITCYCLE|"
    r"Stop|Break|RAISE|RETRY|TRYNEXT|ERROR|BACKWARD|UNDO|CallByVar|WaitUntil|WaitSyncTask|ProcCall)\b", re.IGNORECASE)
_MOTION_LIKE = re.compile(
    r"^(Move\w*|Search\w*|Trigg\w*|Arc\w*|Spot(?:L|J|ML|MJ)|Calib(?:L|J)|Corr\w*|EGM\w*|PathRec\w*|StopMove\w*|StartMove\w*|StorePath|"
    r"RestoPath|ActUnit|DeactUnit|Ind[ACDR]Move|IndReset|SoftAct|SoftDeact|CirPathMode|PDisp\w*|EOffs\w*|"
    r"SyncMove\w*|ConfJ|ConfL|CSSAct|CSSDeact|ContactL|SensorOn|SensorOff|WZ\w*)$", re.IGNORECASE)
_INERT = re.compile(
    r"^(VelSet|AccSet|SetAO|SetGO|PulseDO|TPWrite|TPErase|ErrWrite|SingArea|GripLoad|"
    r"WorldAccLim|PathAccLim|SpeedRefresh|InvertDO|Load)$", re.IGNORECASE)
_POSITION_TYPES = {"robtarget", "jointtarget", "tooldata", "wobjdata", "pose", "pos", "orient", "confdata"}
_IDENTITY_WOBJ: Value = [False, True, "", [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]],
                         [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]]]
_IDENTITY_TOOL: Value = [True, [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]], [0.001, [0.0, 0.0, 0.001],
                                                                          [1.0, 0.0, 0.0, 0.0], 0.0, 0.0, 0.0]]


@dataclass(frozen=True, slots=True)
class _Statement:
    where: Where
    code: str     # comments removed, lines joined, final ';' removed
    raw: str


@dataclass(slots=True)
class _Data:
    type: str
    value: Value | None


@dataclass(slots=True)
class _State:
    data: dict[str, _Data]
    signals: dict[str, int]
    procedures: dict[str, list[_Statement]]
    parameters: dict[str, bool] = field(default_factory=dict)   # procedure -> whether it has any
    outputs: dict[str, int] = field(default_factory=dict)      # the I/O configuration's digital outputs
    events: list[Event] = field(default_factory=list)
    issues: list[Issue] = field(default_factory=list)

    def issue(self, st: _Statement, kind: IssueKind, reason: str) -> None:
        self.issues.append(Issue(st.where, kind, st.raw, reason))


def run_rapid(modules: Sequence[str] | Mapping[str, str], *, entry: str = "main",
              signals: Mapping[str, int] | None = None, outputs: Mapping[str, int] | None = None) -> ProgramRun:
    """Runs procedure `entry` of a task made of `modules` (texts; a mapping names them).

    Parameters
    ----------
    modules : texts of the task's modules (data may be declared in any of them)
    entry : str
        The procedure to run (RAPID's main routine, ``main`` by default).
    signals : mapping of signal name to input number, optional
        The I/O configuration's digital inputs, to number the WaitDI signals.
    outputs : mapping of signal name to output number, optional
        Its digital outputs, to number the SetDO signals.

    Returns
    -------
    ProgramRun
        Motions with T_base_tcp = uframe · oframe · target (robot base = world), the tframe of the
        instruction's tool and the wobj's uframe · oframe; confdata as written; calls; waits; issues.
    """
    named = modules if isinstance(modules, Mapping) else {f"module{i + 1}.mod": t for i, t in enumerate(modules)}
    state = _State(data={"TOOL0": _Data("tooldata", _IDENTITY_TOOL), "WOBJ0": _Data("wobjdata", _IDENTITY_WOBJ)},
                   signals={k.upper(): v for k, v in (signals or {}).items()}, procedures={},
                   outputs={k.upper(): v for k, v in (outputs or {}).items()})
    for name, text in named.items():
        _read_module(_statements(text, name), state)
    body = state.procedures.get(entry.upper())
    if body is None:
        state.issues.append(Issue(Where(next(iter(named), ""), 1), "undefined", "", f"no procedure {entry}"))
        return ProgramRun("rapid", (), tuple(state.issues))
    moving = {name for name, stmts in state.procedures.items() if _moves(stmts) and state.parameters.get(name)}
    stopped: list[Where] = []
    try:
        _run(entry.upper(), [], state, moving, stopped)
    except _Stop:
        pass
    return ProgramRun("rapid", tuple(state.events), tuple(state.issues), stopped=stopped[0] if stopped else None)


class _Stop(Exception):
    """The program stops: an end, a pause, or a jump that repeats without end."""


def _run(name: str, stack: list[str], state: _State, moving: set[str], stopped: list[Where]) -> None:
    """RAPID reference manual, instructions RETURN ("finishes the execution of a routine"; the
    main routine's ends the program), EXIT and EXITCYCLE (end the program or its cycle), Stop and
    Break (stop program execution until it is started again; RoboDK's IRC5 post writes ``STOP;``
    to pause, ros-industrial-attic/robodk_postprocessors @ d7e6c1c0 ABB_RAPID_IRC5.py 381-386),
    GOTO (continues at a label of the same routine); a procedure call ``Name;`` runs the
    procedure. A routine's ERROR / BACKWARD / UNDO handler runs only on an error or a backward
    step: the body ends there."""
    body = state.procedures[name]
    end = next((i for i, st in enumerate(body) if re.fullmatch(r"ERROR|BACKWARD|UNDO", st.code, re.IGNORECASE)),
               len(body))
    body = body[:end]
    labels = {st.code[:-1].upper(): i for i, st in enumerate(body) if re.fullmatch(r"\w+:", st.code)}
    depth = 0                      # of IF, WHILE, FOR, TEST: their bodies run straight through, reported
    i = 0
    while i < len(body):
        st, code = body[i], body[i].code
        word = code.split(None, 1)[0].upper() if code.split() else ""
        if re.match(r"^((IF|WHILE|FOR)\b.*\b(THEN|DO)|TEST\b.*)$", code, re.IGNORECASE):
            depth += 1
        elif re.fullmatch(r"ENDIF|ENDWHILE|ENDFOR|ENDTEST", code, re.IGNORECASE):
            depth = max(0, depth - 1)
        elif depth and word in ("RETURN", "EXIT", "EXITCYCLE", "STOP", "BREAK", "GOTO"):
            state.issue(st, "unsupported", "an end or a jump under a condition: conditions are not evaluated")
            i += 1
            continue
        if word == "RETURN":
            if stack:
                return
            stopped.append(st.where)
            raise _Stop
        if word in ("EXIT", "EXITCYCLE", "STOP", "BREAK"):
            stopped.append(st.where)
            raise _Stop
        jump = re.fullmatch(r"GOTO\s+(\w+)", code, re.IGNORECASE)
        if jump:
            target = labels.get(jump.group(1).upper())
            if target is None:
                state.issue(st, "undefined", f"no label {jump.group(1)} in the routine")
            elif target <= i:
                state.issue(st, "unsupported", "a jump back: the statements from its label repeat")
                stopped.append(st.where)
                raise _Stop
            else:
                i = target
                continue
            i += 1
            continue
        if re.fullmatch(r"\w+:", code):
            i += 1
            continue
        callee = code.upper()
        if re.fullmatch(r"\w+", code) and callee in state.procedures and not state.parameters.get(callee):
            if callee in stack or callee == name:
                state.issue(st, "unsupported", f"{code} calls itself: without end")
                stopped.append(st.where)
                raise _Stop
            _run(callee, [*stack, name], state, moving, stopped)
            i += 1
            continue
        _execute(st, state, moving)
        i += 1


# -------------------------------------------------------------------------------------- structure
def _statements(text: str, name: str) -> list[_Statement]:
    """Statements with the line each starts on; ``;`` ends a statement, block keywords end a line."""
    out: list[_Statement] = []
    buffer, raw, start = "", "", 0
    in_header = False
    for number, line in enumerate(text.splitlines(), start=1):
        if line.strip() == "%%%":
            in_header = not in_header
            continue
        if in_header:
            continue
        code = strip_comment(line, "!").strip()
        if not code:
            continue
        label = re.match(r"^(\w+)\s*:(?!=)\s*(.*)$", code) if not buffer else None
        if label and label.group(1).upper() not in ("CASE", "DEFAULT"):
            # A label is a statement of its own (GOTO's target), whatever follows it on the line.
            out.append(_Statement(Where(name, number), f"{label.group(1)}:", line.strip()))
            code = label.group(2)
            if not code:
                continue
        if not buffer:
            start = number
        buffer = f"{buffer} {code}".strip()
        raw = f"{raw} {line.strip()}".strip()
        if buffer.endswith(";") or _BLOCK.match(buffer):
            out.append(_Statement(Where(name, start), buffer.rstrip(";").strip(), raw))
            buffer, raw = "", ""
    if buffer:
        out.append(_Statement(Where(name, start), buffer, raw))
    return out


_DATA_RE = re.compile(r"^(?:(?:LOCAL|TASK)\s+)*(CONST|PERS|VAR)\s+(\w+)\s+(\w+)\s*(\{[^}]*\})?\s*(?::=\s*(.*))?$",
                      re.IGNORECASE | re.DOTALL)
_PROC_RE = re.compile(r"^(?:LOCAL\s+)?PROC\s+(\w+)\s*\((.*)\)$", re.IGNORECASE | re.DOTALL)


def _read_module(statements: list[_Statement], state: _State) -> None:
    block: str | None = None      # the routine being read: a procedure's name, or "" for a FUNC / TRAP
    for st in statements:
        code = st.code
        if block is not None:
            if re.fullmatch(r"ENDPROC|ENDFUNC|ENDTRAP", code, re.IGNORECASE):
                block = None
            elif block:
                state.procedures[block].append(st)
            continue
        m = _PROC_RE.match(code)
        if m:
            block = m.group(1).upper()
            state.procedures[block] = []
            state.parameters[block] = bool(m.group(2).strip())
            continue
        if re.match(r"^(?:LOCAL\s+)?(FUNC|TRAP)\b", code, re.IGNORECASE):
            block = ""   # functions and traps are not run (a statement using one is reported where it is)
            continue
        if re.match(r"^(MODULE|ENDMODULE)\b", code, re.IGNORECASE):
            continue
        if not _declare(st, state):
            state.issue(st, "unsupported", "module-level statement that is not a data declaration")


def _declare(st: _Statement, state: _State) -> bool:
    m = _DATA_RE.match(st.code)
    if not m:
        return False
    type_, name, init = m.group(2).lower(), m.group(3).upper(), m.group(5)
    value = _parse_value(init) if init is not None else None
    if init is not None and value is None:
        state.issue(st, "unsupported", "initial value is not a literal")
    state.data[name] = _Data(type_, value)
    return True


def _moves(statements: list[_Statement]) -> bool:
    return any(_MOTION_LIKE.match(st.code.split(None, 1)[0] if st.code.split() else "") for st in statements)


# --------------------------------------------------------------------------------------- values
def _parse_value(text: str) -> Value | None:
    """A RAPID literal: number, TRUE/FALSE, "string" or a nested aggregate ``[...]``; None if not one."""
    text = text.strip()
    if text.startswith("["):
        if not text.endswith("]"):
            return None
        items = [_parse_value(t) for t in split_top(text[1:-1], ",", "[]()")]
        if any(i is None for i in items):
            return None
        return [i for i in items if i is not None]
    if is_number(text):
        return float(text)
    if text.upper() in ("TRUE", "FALSE"):
        return text.upper() == "TRUE"
    if len(text) >= 2 and text.startswith('"') and text.endswith('"'):
        return text[1:-1]
    return None


def _numbers(value: Value, n: int) -> list[float] | None:
    if not isinstance(value, list) or len(value) != n or not all(isinstance(v, float) for v in value):
        return None
    return [float(v) for v in value if isinstance(v, float)]


def _pose(value: Value) -> FloatArray | None:
    """[[x, y, z], [q1, q2, q3, q4]] (mm, quaternion w first) -> (4, 4) metres; None if malformed."""
    if not isinstance(value, list) or len(value) != 2:
        return None
    trans, rot = _numbers(value[0], 3), _numbers(value[1], 4)
    if trans is None or rot is None:
        return None
    return homogeneous(rot_quat_wxyz((rot[0], rot[1], rot[2], rot[3])), (trans[0] * MM, trans[1] * MM, trans[2] * MM))


def _quaternion_ok(value: Value) -> bool:
    if isinstance(value, list) and len(value) == 2:
        rot = _numbers(value[1], 4)
        if rot is not None:
            return abs(math.sqrt(sum(q * q for q in rot)) - 1.0) <= QUATERNION_NORM_TOL
    return False


# ----------------------------------------------------------------------------------- statements
@dataclass(frozen=True, slots=True)
class _Args:
    positional: list[str]
    optional: dict[str, str | None]   # \Name:=value -> value; \Switch -> None


def _arguments(text: str) -> _Args:
    positional: list[str] = []
    optional: dict[str, str | None] = {}
    for item in split_top(text, ",", "[]()"):
        parts = split_top(item, "\\", "[]()")
        if parts[0]:
            positional.append(parts[0])
        for part in parts[1:]:
            name, _, value = part.partition(":=")
            optional[name.strip().upper()] = value.strip() if value else None
    return _Args(positional, optional)


def _execute(st: _Statement, state: _State, moving: set[str]) -> None:
    code = st.code
    if _declare(st, state):
        return
    if _CONTROL.match(code) or re.match(r"^\w+:$", code):
        state.issue(st, "unsupported", "control flow is not modelled")
        return
    assign = re.match(r"^([\w.{}\[\], ]+?)\s*:=\s*(.+)$", code, re.DOTALL)
    if assign:
        target = re.split(r"[.{\[]", assign.group(1))[0].strip().upper()
        data = state.data.get(target)
        if data is None or data.type in _POSITION_TYPES:
            state.issue(st, "unsupported", "assignment to position data (or to undeclared data)")
        elif "(" in assign.group(2):
            state.issue(st, "unsupported", "function call in an expression")
        return
    head = re.match(r"^(\w+)\s*(.*)$", code, re.DOTALL)
    if not head:
        state.issue(st, "unsupported", "statement outside the modelled subset")
        return
    name, rest = head.group(1), head.group(2)
    args = _arguments(rest) if rest else _Args([], {})
    upper = name.upper()
    if upper in ("MOVEJ", "MOVEL", "MOVEABSJ", "SPOTL", "SPOTJ"):
        _motion(st, name, args, state)
        return
    if upper == "WAITTIME":
        if len(args.positional) == 1 and is_number(args.positional[0]) and set(args.optional) <= {"INPOS"}:
            state.events.append(Wait(st.where, seconds=float(args.positional[0])))
        else:
            state.issue(st, "unsupported", "WaitTime with an expression or options")
        return
    if upper == "WAITDI":
        if len(args.positional) == 2 and args.positional[1] in ("0", "1") and not args.optional:
            signal = args.positional[0]
            state.events.append(Wait(st.where, signal=signal, input_number=state.signals.get(signal.upper()),
                                     state=args.positional[1] == "1"))
        else:
            state.issue(st, "unsupported", "WaitDI other than WaitDI signal, 0|1")
        return
    if upper in ("SETDO", "SET", "RESET"):
        # SetDO Signal, Value; Set Signal (1); Reset Signal (0) (RAPID instructions reference). After
        # a stop point (zone fine) the robot is at rest when it runs; \SDelay sets it later, in the
        # background: not modelled.
        value = args.positional[1] if upper == "SETDO" and len(args.positional) == 2 else \
            ("1" if upper == "SET" else "0") if upper != "SETDO" and len(args.positional) == 1 else None
        if value in ("0", "1") and not set(args.optional) - {"SYNC"}:
            last = next((e for e in reversed(state.events) if isinstance(e, Motion)), None)
            state.events.append(SetOutput(st.where, args.positional[0], state.outputs.get(args.positional[0].upper()),
                                          value == "1", after_stop=last is None or last.stops))
        else:
            state.issue(st, "unsupported", f"{name} other than SetDO signal, 0|1 / Set / Reset signal")
        return
    if upper in ("CONFJ", "CONFL"):
        if set(args.optional) == {"ON"} and not args.positional:
            return
        state.issue(st, "unsupported", f"{name} \\Off: the controller may reach targets in another configuration")
        return
    if upper in state.procedures:
        if upper in moving:
            state.issue(st, "unsupported", f"{name} moves the robot; calls are not followed")
    elif _INERT.match(name):
        return
    elif _MOTION_LIKE.match(name):
        state.issue(st, "unsupported", "motion instruction outside the modelled subset")
        return
    state.events.append(Call(st.where, name, tuple(arg_value(a) for a in split_top(rest, ",", "[]()") if a)))


def _motion(st: _Statement, name: str, args: _Args, state: _State) -> None:
    upper = name.upper()
    allowed = {"WOBJ", "ID", "V", "T", "Z", "INPOS", "TLOAD", "NOEOFFS", "NOCONC", "RETRACT", "QUICKRELEASE"}
    extra = set(args.optional) - allowed
    if extra:
        state.issue(st, "unsupported", f"option(s) {', '.join(sorted(extra))} not modelled")
        return
    if upper in ("SPOTL", "SPOTJ"):
        if len(args.positional) < 4:
            state.issue(st, "unsupported", f"{name} without ToPoint, Speed, Spot and Tool")
            return
        target, zone, tool_name = args.positional[0], "fine", args.positional[-1]
    else:
        if len(args.positional) != 4:
            state.issue(st, "unsupported", f"{name} needs ToPoint, Speed, Zone, Tool")
            return
        target, _, zone, tool_name = args.positional
    blend = None if _stops(zone, state) else zone
    tool = _literal_or_data(st, tool_name, "tooldata", state)
    wobj = _literal_or_data(st, args.optional.get("WOBJ") or "wobj0", "wobjdata", state)
    T_flange_tcp = _tool_frame(st, tool, state) if tool is not None else None
    T_base_user = _user_frame(st, wobj, state) if wobj is not None else None
    if upper == "MOVEABSJ":
        value = _literal_or_data(st, target, "jointtarget", state)
        if value is None:
            return
        joints = _numbers(value[0], 6) if isinstance(value, list) and value else None
        if joints is None:
            state.issue(st, "unsupported", "jointtarget is not [[6 numbers], [extax]]")
            return
        state.events.append(Motion(st.where, name, "joint", target, tuple(joints), None, T_flange_tcp, T_base_user,
                                   None, blend))
        return
    value = _literal_or_data(st, target, "robtarget", state)
    if value is None:
        return
    if not isinstance(value, list) or len(value) != 4:
        state.issue(st, "unsupported", "robtarget is not [trans, rot, robconf, extax]")
        return
    T_user_tcp = _pose([value[0], value[1]])
    conf = _numbers(value[2], 4)
    if T_user_tcp is None or conf is None:
        state.issue(st, "unsupported", "robtarget with non-numeric components")
        return
    if not _quaternion_ok([value[0], value[1]]):
        state.issue(st, "alarm", "robtarget orientation is not a normalised quaternion")
    extax = value[3] if isinstance(value[3], list) else []
    if any(not (isinstance(e, float) and e >= 9e9) for e in extax):
        state.issue(st, "unsupported", "external axis values (not 9E9) are not modelled")
    config = RapidConfig(*(int(c) for c in conf))
    T_base_tcp = T_base_user @ T_user_tcp if T_base_user is not None else None
    kind: MotionKind = "linear" if upper in ("MOVEL", "SPOTL") else "joint"
    state.events.append(Motion(st.where, name, kind, target, None, T_base_tcp, T_flange_tcp, T_base_user, config,
                               blend))
    if upper in ("SPOTL", "SPOTJ"):
        state.events.append(Call(st.where, name, tuple(arg_value(a) for a in args.positional[2:-1])))


def _stops(zone: str, state: _State) -> bool:
    if zone.lower() == "fine":
        return True
    data = state.data.get(zone.upper())
    return bool(data is not None and isinstance(data.value, list) and data.value and data.value[0] is True)


def _literal_or_data(st: _Statement, text: str, type_: str, state: _State) -> Value | None:
    if text.startswith("["):
        value = _parse_value(text)
        if value is None:
            state.issue(st, "unsupported", f"malformed {type_} literal")
        return value
    if not re.fullmatch(r"\w+", text):
        state.issue(st, "unsupported", f"{type_} from an expression (Offs, RelTool, CRobT, ...)")
        return None
    data = state.data.get(text.upper())
    if data is None or data.value is None:
        state.issue(st, "undefined", f"{text} is not declared with a value in the given modules")
        return None
    if data.type != type_:
        state.issue(st, "unsupported", f"{text} is a {data.type}, not a {type_}")
        return None
    return data.value


def _tool_frame(st: _Statement, tool: Value, state: _State) -> FloatArray | None:
    if not isinstance(tool, list) or len(tool) != 3 or not isinstance(tool[0], bool):
        state.issue(st, "unsupported", "tooldata is not [robhold, tframe, tload]")
        return None
    if not tool[0]:
        state.issue(st, "unsupported", "stationary tool (robhold FALSE)")
        return None
    frame = _pose(tool[1])
    if frame is None or not _quaternion_ok(tool[1]):
        state.issue(st, "unsupported", "tframe is not [[x, y, z], [unit quaternion]]")
    return frame


def _user_frame(st: _Statement, wobj: Value, state: _State) -> FloatArray | None:
    if not isinstance(wobj, list) or len(wobj) != 5:
        state.issue(st, "unsupported", "wobjdata is not [robhold, ufprog, ufmec, uframe, oframe]")
        return None
    robhold, ufprog, ufmec = wobj[0], wobj[1], wobj[2]
    if robhold is not False or ufprog is not True or ufmec != "":
        state.issue(st, "unsupported", "work object held by the robot or coordinated with a mechanical unit")
        return None
    uframe, oframe = _pose(wobj[3]), _pose(wobj[4])
    if uframe is None or oframe is None or not (_quaternion_ok(wobj[3]) and _quaternion_ok(wobj[4])):
        state.issue(st, "unsupported", "uframe / oframe is not [[x, y, z], [unit quaternion]]")
        return None
    return np.asarray(uframe @ oframe)
