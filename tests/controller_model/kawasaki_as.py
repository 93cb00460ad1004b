"""Kawasaki AS: what a Kawasaki robot controller (D / E series) executes, for a motion subset.

Sources: Kawasaki Robot Controller, AS Language Reference Manual (90209-1017DEB): locations are
transformation values (X, Y, Z, O, A, T) or joint displacement values (``#[...]``); a
transformation value is relative to the base coordinates, which ``BASE`` sets relative to the null
base coordinates (the robot's own base frame, ``BASE NULL``); ``TOOL`` sets the tool coordinates
relative to the null tool coordinates (the flange); O, A, T are Euler angles: O about z, A about the
new y, T about the new z (R = Rz(O)·Ry(A)·Rz(T); RoboDK's robomath Adept_2_Pose,
RoboDK/RoboDK-API@84099bba Python/robodk/robomath.py:815-835, composes the same); ``SPEED``,
``ACCURACY``, ``ACCEL`` and ``DECEL`` without ``ALWAYS`` apply to the next motion only;
``ACCURACY d FINE`` makes the motion end at rest inside d mm, without ``FINE`` the next motion
starts once the robot is within d mm (a blend); ``TWAIT t`` waits t s; ``SWAIT n`` waits for signal
n to be on (external inputs are 1001 ...; a negative number waits for it to be off); ``CALL
name(args)`` runs another program. RoboDK's Kawasaki post (ros-industrial-attic/
robodk_postprocessors@d7e6c1c0 Kawasaki.py:49-60, 130-193) writes these forms.

- ``.PROGRAM name(params)`` ... ``.END``: a file holds several programs; the first is the main one.
  ``;`` starts a comment.
- ``POINT name = TRANS(x, y, z, o, a, t)`` (mm, deg) or ``= name`` defines a transformation variable.
- ``JMOVE #[j1, ..., j6]``: a joint move (deg); ``LMOVE loc``: a straight TCP line to a
  transformation value (a ``TRANS(...)`` literal or a variable), commanded as BASE · loc.
- ``CALL name(args)`` is recorded (name and arguments); a call of a program without arguments that
  the file defines runs its body.

Anything else that could change motion (other motion instructions, configuration instructions,
control flow, ``HERE``, ``SHIFT``, ``JMOVE`` to a transformation, which the arm solves in its own
configuration) is an ``unsupported`` issue.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from .common import (
    MM,
    NUMBER,
    Call,
    Event,
    FloatArray,
    Issue,
    IssueKind,
    Motion,
    ProgramRun,
    Wait,
    Where,
    arg_value,
    homogeneous,
    rot_y_deg,
    rot_z_deg,
    split_top,
    strip_comment,
)

EXTERNAL_INPUT_BASE = 1000        # signal 1001 is external input 1
_PROGRAM = re.compile(r"^\.PROGRAM\s+(\w+)\s*(?:\(([^)]*)\))?", re.IGNORECASE)
_TRANS = re.compile(rf"^TRANS\s*\(\s*({NUMBER}(?:\s*,\s*{NUMBER}){{5}})\s*\)$", re.IGNORECASE)
_JOINTS = re.compile(rf"^#\[\s*({NUMBER}(?:\s*,\s*{NUMBER})*)\s*\]$")
_INERT = re.compile(r"^(SIGNAL|PRINT|TYPE|OPENI|CLAMP|ACCEL|DECEL)\b", re.IGNORECASE)


def rot_oat_deg(o: float, a: float, t: float) -> FloatArray:
    """(3, 3) R = Rz(O)·Ry(A)·Rz(T), degrees (AS's Euler angles O, A, T)."""
    return rot_z_deg(o) @ rot_y_deg(a) @ rot_z_deg(t)


def trans(x: float, y: float, z: float, o: float, a: float, t: float) -> FloatArray:
    """(4, 4) metres of an AS transformation value (mm, deg)."""
    return homogeneous(rot_oat_deg(o, a, t), (x * MM, y * MM, z * MM))


@dataclass(slots=True)
class _State:
    source: str
    programs: dict[str, list[tuple[int, str]]]
    events: list[Event] = field(default_factory=list)
    issues: list[Issue] = field(default_factory=list)
    points: dict[str, FloatArray] = field(default_factory=dict)
    tool: FloatArray | None = field(default_factory=lambda: np.eye(4))     # the null tool: the flange
    base: FloatArray | None = field(default_factory=lambda: np.eye(4))     # the null base
    accuracy: tuple[float, bool] | None = None                             # for the next motion
    accuracy_always: tuple[float, bool] = (1.0, False)
    stopped: Where | None = None

    def issue(self, line: int, kind: IssueKind, text: str, reason: str) -> None:
        self.issues.append(Issue(Where(self.source, line), kind, text, reason))


def run_as(text: str, *, name: str = "program.as") -> ProgramRun:
    """The run of the file's first program (its calls of argument-free programs followed)."""
    programs: dict[str, list[tuple[int, str]]] = {}
    current: list[tuple[int, str]] | None = None
    main = None
    for number, raw in enumerate(text.splitlines(), start=1):
        code = strip_comment(raw, ";").strip()
        head = _PROGRAM.match(code)
        if head:
            current = programs.setdefault(head.group(1).lower(), [])
            main = main or head.group(1).lower()
            continue
        if code.upper() == ".END":
            current = None
            continue
        if current is not None and code:
            current.append((number, code))
    state = _State(name, programs)
    if main is None:
        state.issue(1, "unsupported", "", "no .PROGRAM: not an AS program")
    else:
        _body(state, programs[main], [main])
    return ProgramRun("as", tuple(state.events), tuple(state.issues), stopped=state.stopped)


def _location(state: _State, line: int, text: str) -> FloatArray | None:
    text = text.strip()
    m = _TRANS.match(text)
    if m:
        return trans(*(float(v) for v in m.group(1).split(",")))
    if text in state.points:
        return state.points[text]
    state.issue(line, "undefined", text, "a transformation the program does not define")
    return None


def _body(state: _State, lines: list[tuple[int, str]], stack: list[str]) -> None:
    for line, code in lines:
        if state.stopped is not None:
            return
        word = code.split(None, 1)[0].upper()
        rest = code[len(word):].strip()
        if word == "POINT":
            target, _, value = rest.partition("=")
            loc = _location(state, line, value)
            if loc is not None:
                state.points[target.strip()] = loc
        elif word in ("TOOL", "BASE"):
            frame = np.eye(4) if rest.upper() == "NULL" else _location(state, line, rest)
            if word == "TOOL":
                state.tool = frame
            else:
                state.base = frame
        elif word == "SPEED" or _INERT.match(code):
            continue                 # speeds and accelerations time the motion; the path is the same
        elif word == "ACCURACY":
            m = re.match(rf"^({NUMBER})\s*(FINE)?\s*(ALWAYS)?$", rest, re.IGNORECASE)
            if m is None:
                state.issue(line, "unsupported", code, "an ACCURACY the model does not read")
                continue
            acc = (float(m.group(1)), bool(m.group(2)))
            if m.group(3):
                state.accuracy_always = acc
            else:
                state.accuracy = acc
        elif word in ("JMOVE", "LMOVE"):
            _motion(state, line, word, rest)
        elif word == "TWAIT":
            state.events.append(Wait(Where(state.source, line), seconds=float(rest)))
        elif word == "SWAIT":
            for signal in (int(float(s)) for s in split_top(rest)):
                number = abs(signal) - EXTERNAL_INPUT_BASE if abs(signal) > EXTERNAL_INPUT_BASE else abs(signal)
                state.events.append(Wait(Where(state.source, line), signal=str(signal), input_number=number,
                                         state=signal > 0))
        elif word == "CALL":
            m = re.match(r"^(\w+)\s*(?:\((.*)\))?$", rest)
            if m is None:
                state.issue(line, "unsupported", code, "a CALL the model does not read")
                continue
            callee, args = m.group(1).lower(), (m.group(2) or "").strip()
            if not args and callee in state.programs and callee not in stack:
                _body(state, state.programs[callee], [*stack, callee])
            else:
                state.events.append(Call(Where(state.source, line), m.group(1),
                                         tuple(arg_value(a) for a in split_top(args)) if args else ()))
        elif word in ("HALT", "STOP", "PAUSE"):
            state.stopped = Where(state.source, line)
        elif word == "RETURN":
            return
        else:
            state.issue(line, "unsupported", code, "outside the modelled subset")


def _motion(state: _State, line: int, word: str, target: str) -> None:
    accuracy = state.accuracy if state.accuracy is not None else state.accuracy_always
    state.accuracy = None
    blend = None if accuracy[1] else f"ACCURACY {accuracy[0]:g}"
    where = Where(state.source, line)
    if word == "JMOVE":
        joints = _JOINTS.match(target)
        if joints is None:
            state.issue(line, "unsupported", f"JMOVE {target}", "a joint move to a transformation: the arm's own "
                                                                "configuration decides the joints")
            return
        q = tuple(float(v) for v in joints.group(1).split(","))
        state.events.append(Motion(where, "JMOVE", "joint", target, q, None, state.tool, state.base, None, blend))
        return
    loc = _location(state, line, target)
    T = None if loc is None or state.base is None else state.base @ loc
    state.events.append(Motion(where, "LMOVE", "linear", target, None, T, state.tool, state.base, None, blend))
