"""URScript: what a Universal Robots controller (CB3 / e-Series) executes, for a motion subset.

Sources (/work/notes/vendor_research.md §4 quotes each): Universal Robots, "URScript: Move with
respect to a custom feature/frame" (how-to 20115: "By default the 'pose' parameter ... is always
w.r.t to the base-frame"); the script manual's pose_trans page ("T_world->to = T_world->from *
T_from->to"); the ur_description frame documentation and xacro (UniversalRobots/
Universal_Robots_ROS2_Description ur_macro.xacro 362-372: the controller's Base is ``base_link``
turned pi about z); PolyScope-generated scripts (global pose variables, ``set_tcp`` before moves);
RoboDK's UR post (robodk_postprocessors Universal_Robots.py: ``set_tcp``,
``get_standard_digital_in`` wait loops, poses ``p[x, y, z, rx, ry, rz]`` in metres and a
rotation vector).

- Poses ``p[x, y, z, rx, ry, rz]``: metres and a rotation vector (axis times angle, radians).
  movel / movej targets are TCP poses in the controller's Base frame; the user frame is the
  identity (features appear as pose variables composed with pose_trans).
- ``movej(q, a, v, t, r)``: q a joint vector in radians (recorded in degrees), or a pose (the
  controller solves the inverse kinematics: a joint move to a Cartesian target).
  ``movel(pose, a, v, t, r)``: a straight TCP line. ``r`` is the blend radius; absent or 0 stops.
- ``set_tcp(pose)``: the tool frame (flange to TCP) in force from then on.
  ``pose_trans(p_from, p_from_to)`` = p_from · p_from_to. Pose and joint-vector variables
  (``name = p[...]``, ``global``) hold their value.
- ``def name(): ... end`` defines a function: a call ``name()`` runs its body (``return`` leaves
  it; ``halt()`` and the program's own ``return`` end the program); a call with arguments is
  recorded (name, args), not followed, and reported when the function moves or sets the TCP. A
  function whose body is only an input wait on one of its parameters (``def wait_for_signal(n):
  while not get_standard_digital_in(n): sync() end end``) waits for the input its call passes.
  ``sleep(t)`` waits t s; a loop
  doing only ``sync()`` / ``sleep`` while a standard digital input is not yet in a state
  (``while not get_standard_digital_in(n):``, ``while (get_standard_digital_in(n) != True):``,
  ...) waits for it.
- A script that is one ``def``, or ``def`` blocks and one call of one of them, runs that function.

Outside this subset (control flow, threads, other motion functions, pose arithmetic other than
pose_trans, inverse kinematics in the script, functions the model does not know) a statement is
an ``unsupported`` issue.
"""

from __future__ import annotations

import math
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
    Motion,
    MotionKind,
    ProgramRun,
    SetOutput,
    Wait,
    Where,
    arg_value,
    homogeneous,
    is_number,
    rot_vector,
    split_top,
    strip_comment,
)

_INERT_CALL = re.compile(r"^(set_(?!tcp$)\w+|write_\w+|modbus_\w+|socket_\w+|textmsg|popup|sync|rpc_factory|"
                         r"tool_wrench_limit_disable|motion_version_set|enable_\w+|disable_\w+|zero_ftsensor|"
                         r"to_str|str_\w+)$")
_MOTION_FUNCS = re.compile(r"^(movej|movel|movep|movec|servoj|servoc|speedj|speedl|stopj|stopl|position_deviation_"
                           r"warning|force_mode|end_force_mode|freedrive_mode|teach_mode|conveyor_pulse_decode|"
                           r"track_conveyor_\w+|path_offset_\w+|encoder_\w+|set_tcp)$")


@dataclass(slots=True)
class _Var:
    pose: FloatArray | None = None
    joints: tuple[float, ...] | None = None
    problem: str | None = None      # why its value is not known


@dataclass(frozen=True, slots=True)
class _Line:
    where: Where
    code: str
    raw: str


@dataclass(slots=True)
class _State:
    tool: FloatArray | None
    variables: dict[str, _Var] = field(default_factory=dict)
    functions: dict[str, list[_Line]] = field(default_factory=dict)
    parameters: dict[str, list[str]] = field(default_factory=dict)
    threads: set[str] = field(default_factory=set)               # defined with `thread`: never called
    events: list[Event] = field(default_factory=list)
    stopped: Where | None = None
    issues: list[Issue] = field(default_factory=list)

    def issue(self, line: _Line, kind: IssueKind, reason: str) -> None:
        self.issues.append(Issue(line.where, kind, line.raw.strip(), reason))


def run_urscript(script: str, *, name: str = "program.script", tcp: FloatArray | None = None,
                 variables: Mapping[str, FloatArray] | None = None) -> ProgramRun:
    """Runs a URScript program as the controller would.

    Parameters
    ----------
    tcp : (4, 4) float, optional
        The installation's TCP in force before the script's first ``set_tcp`` (None: unknown).
    variables : mapping of name to (4, 4) float, optional
        Installation pose variables (features) the script may use.

    Returns
    -------
    ProgramRun
        Motions with T_base_tcp the target pose in the UR base frame, the TCP in force, the user
        frame the identity; calls; waits; issues.
    """
    lines = [_Line(Where(name, i), strip_comment(raw, "#").strip(), raw) for i, raw in enumerate(script.splitlines(), 1)]
    lines = [ln for ln in lines if ln.code and not ln.code.startswith("$")]   # "$ 2 ..." PolyScope line markers
    state = _State(tool=tcp, variables={k: _Var(pose=v) for k, v in (variables or {}).items()})
    try:
        _block(_program_body(lines), state, [])
    except (_Stop, _Return):
        pass
    return ProgramRun("urscript", tuple(state.events), tuple(state.issues), stopped=state.stopped)


class _Stop(Exception):
    """The program stops (halt(), the program's own return, a call without end)."""


class _Return(Exception):
    """`return` in a called function."""


def _program_body(lines: list[_Line]) -> list[_Line]:
    """What the controller runs: the body of a script that is one ``def`` (as PolyScope sends it),
    or that is ``def`` blocks and one call of one of them without arguments (as RoboDK writes it);
    otherwise the script's top level."""
    top: list[tuple[int, int]] = []   # (first, last) index of each top-level statement or block
    i = 0
    while i < len(lines):
        end = _block_end(lines, i) if _opens(lines[i].code) else i
        top.append((i, end))
        i = end + 1
    defs = {m.group(1): (a, b) for a, b in top
            if (m := re.match(r"^def\s+(\w+)\s*\(\s*\)\s*:$", lines[a].code)) and b < len(lines)}
    rest = [lines[a].code for a, b in top if not re.match(r"^def\s", lines[a].code)]
    if len(top) == 1 and defs:
        a, b = next(iter(defs.values()))
        return lines[a + 1:b]
    called = re.fullmatch(r"(\w+)\(\s*\)", rest[0]) if len(rest) == 1 else None
    if called and called.group(1) in defs and len(top) == len(defs) + 1:
        a, b = defs[called.group(1)]
        return [ln for first, last in top if first != a for ln in lines[first:last + 1]
                if re.match(r"^def\s", lines[first].code)] + lines[a + 1:b]
    return lines


def _opens(code: str) -> bool:
    return bool(re.match(r"^(def|thread|if|elif|else|while|for)\b.*:$", code))


def _block_end(lines: list[_Line], start: int) -> int:
    """Index of the ``end`` closing the block opened at `start` (len(lines) if none)."""
    depth = 0
    for i in range(start, len(lines)):
        code = lines[i].code
        if re.match(r"^(elif|else)\b", code):
            continue
        if _opens(code):
            depth += 1
        elif code == "end":
            depth -= 1
            if depth == 0:
                return i
    return len(lines)


def _input_wait(code: str) -> tuple[int, bool] | None:
    """(input, awaited state) of a loop header that waits for a standard digital input:
    ``while not get_standard_digital_in(n):``, ``while get_standard_digital_in(n):`` or
    ``while (get_standard_digital_in(n) != True):`` (``==``, ``False`` likewise)."""
    text = re.sub(r"^while\s*|\s*:$", "", code).strip()
    while text.startswith("(") and text.endswith(")"):
        text = text[1:-1].strip()
    negated = text.startswith("not ")
    text = text.removeprefix("not ").strip()
    m = re.fullmatch(r"\(?\s*get_standard_digital_in\(\s*(\d+)\s*\)\s*\)?(?:\s*(==|!=)\s*(True|False))?", text)
    if not code.startswith("while") or not m:
        return None
    loops_while = not negated   # the loop runs while the input is True
    if m.group(2):
        loops_while = (m.group(2) == "==") == (m.group(3) == "True")
        loops_while = loops_while != negated
    return int(m.group(1)), not loops_while


def _moves(body: list[_Line]) -> bool:
    return any(re.match(r"^(movej|movel|movep|movec|servoj|speedj|speedl|set_tcp)\s*\(", ln.code) for ln in body)


def _block(lines: list[_Line], state: _State, stack: list[str]) -> None:
    """The URScript Programming Language: ``halt()`` terminates the program, ``return`` leaves a
    function (the program, when it is the program's own); a call ``name()`` of a function the
    script defines runs its body (RoboDK's UR post writes ``halt()`` to pause a program,
    ros-industrial-attic/robodk_postprocessors @ d7e6c1c0 Universal_Robots.py 634-639)."""
    depth = 0                      # of if, while, for: their bodies run straight through, reported
    i = 0
    while i < len(lines):
        line = lines[i]
        code = line.code
        if re.match(r"^(if|while|for)\b.*:$", code) and _input_wait(code) is None:
            depth += 1
        elif code == "end":
            depth = max(0, depth - 1)
        elif depth and re.fullmatch(r"halt\(\s*\)|return\b.*", code):
            state.issue(line, "unsupported", "an end under a condition: conditions are not evaluated")
            i += 1
            continue
        definition = re.match(r"^(def|thread)\s+(\w+)\s*\((.*)\)\s*:$", code)
        if definition:
            end = _block_end(lines, i)
            state.functions[definition.group(2)] = lines[i + 1:end]
            state.parameters[definition.group(2)] = [a for a in split_top(definition.group(3)) if a]
            if definition.group(1) == "thread":
                state.threads.add(definition.group(2))
            i = end + 1
            continue
        if re.fullmatch(r"halt\(\s*\)", code):
            state.stopped = line.where
            raise _Stop
        if re.fullmatch(r"return\b.*", code):
            if stack:
                raise _Return
            state.stopped = line.where
            raise _Stop
        call = re.fullmatch(r"(\w+)\(\s*\)", code)
        if (call and call.group(1) in state.functions and not state.parameters.get(call.group(1))
                and call.group(1) not in state.threads):
            if call.group(1) in stack:
                state.issue(line, "unsupported", f"{call.group(1)} calls itself: without end")
                state.stopped = line.where
                raise _Stop
            try:
                _block(state.functions[call.group(1)], state, [*stack, call.group(1)])
            except _Return:
                pass
            i += 1
            continue
        wait = _input_wait(code)
        if wait is not None:
            end = _block_end(lines, i)
            inner = [ln.code for ln in lines[i + 1:end]]
            if all(re.fullmatch(r"sync\(\)|sleep\(\s*[\d.]+\s*\)", c) for c in inner):
                state.events.append(Wait(line.where, signal=f"get_standard_digital_in({wait[0]})",
                                         input_number=wait[0], state=wait[1]))
                i = end + 1
                continue
        if re.match(r"^(if|elif|else|while|for|return|break|continue|halt|run|kill|join)\b", code):
            state.issue(line, "unsupported", "control flow or threads are not modelled")
        elif code != "end":
            _statement(line, state)
        i += 1


def _statement(line: _Line, state: _State) -> None:
    code = line.code
    assign = re.fullmatch(r"(?:global\s+|local\s+)?(\w+)\s*=\s*(.+)", code)
    if assign and re.match(r"^run\b", assign.group(2).strip()):
        state.issue(line, "unsupported", "threads are not modelled")
        return
    if assign and not re.match(r"^\w+\s*==", code):
        _assign(assign.group(1), assign.group(2).strip(), state)
        return
    call = re.fullmatch(r"(\w+)\s*\((.*)\)", code)
    if not call:
        state.issue(line, "unsupported", "statement outside the modelled subset")
        return
    func, args = call.group(1), [a for a in split_top(call.group(2)) if a]
    if func in ("movej", "movel"):
        _motion(line, func, args, state)
        return
    if func == "set_tcp":
        pose = _pose(args[0], state) if len(args) == 1 else "set_tcp takes one pose"
        if isinstance(pose, str):
            state.issue(line, "unsupported", pose)
            state.tool = None
        else:
            state.tool = pose
        return
    if func == "sleep":
        if len(args) == 1 and is_number(args[0]):
            state.events.append(Wait(line.where, seconds=float(args[0])))
        else:
            state.issue(line, "unsupported", "sleep with an expression")
        return
    if func in state.functions:
        waited = _wait_function(state.functions[func], state.parameters.get(func, []), args)
        if waited is not None:
            state.events.append(Wait(line.where, signal=f"get_standard_digital_in({waited[0]})",
                                     input_number=waited[0], state=waited[1]))
            return
        if _moves(state.functions[func]):
            state.issue(line, "unsupported", f"{func} moves the robot or sets the TCP; calls are not followed")
        state.events.append(Call(line.where, func, tuple(arg_value(a) for a in args)))
        return
    if func == "set_standard_digital_out":
        # set_standard_digital_out(n, b): standard output n in [0:7] to b (UR Script Manual).
        if len(args) == 2 and re.fullmatch(r"[0-7]", args[0]) and args[1] in ("True", "False"):
            last = next((e for e in reversed(state.events) if isinstance(e, Motion)), None)
            state.events.append(SetOutput(line.where, f"digital_out[{args[0]}]", int(args[0]), args[1] == "True",
                                          after_stop=last is None or last.stops))
        elif len(args) == 2 and re.fullmatch(r"\d+", args[0]):
            state.issue(line, "alarm", f"standard digital output {args[0]} does not exist (0..7)")
        else:
            state.issue(line, "unsupported", "set_standard_digital_out with an expression")
        return
    if _INERT_CALL.match(func):
        return
    if _MOTION_FUNCS.match(func):
        state.issue(line, "unsupported", "motion function outside the modelled subset (movej, movel)")
        return
    state.issue(line, "unsupported", f"call of {func}, which the model does not know")


def _wait_function(body: list[_Line], parameters: list[str], args: list[str]) -> tuple[int, bool] | None:
    """(input, awaited state) when `body` is only a wait loop on a standard digital input named by a
    parameter, the call passing its number as a literal; else None."""
    if not body or len(parameters) != len(args):
        return None
    header = re.sub(r"get_standard_digital_in\(\s*(\w+)\s*\)",
                    lambda m: f"get_standard_digital_in({args[parameters.index(m.group(1))]})"
                    if m.group(1) in parameters else m.group(0), body[0].code)
    wait = _input_wait(header)
    end = _block_end(body, 0)
    inner = [ln.code for ln in body[1:end]]
    if wait is None or end != len(body) - 1 or not all(re.fullmatch(r"sync\(\)|sleep\(\s*[\d.]+\s*\)", c)
                                                       for c in inner):
        return None
    return wait


def _assign(name: str, expr: str, state: _State) -> None:
    if expr.startswith(("p[", "pose_trans(")):
        pose = _pose(expr, state)
        state.variables[name] = _Var(problem=pose) if isinstance(pose, str) else _Var(pose=pose)
        return
    if expr.startswith("["):
        joints = _numbers(expr[1:-1] if expr.endswith("]") else "", 6)
        state.variables[name] = (_Var(joints=tuple(joints)) if joints is not None
                                 else _Var(problem="not a vector of 6 numbers"))
        return
    if re.fullmatch(r"\w+", expr) and expr in state.variables:
        state.variables[name] = state.variables[expr]
        return
    state.variables[name] = _Var(problem=f"value of '{expr}' is not modelled")


def _numbers(text: str, n: int) -> list[float] | None:
    items = split_top(text)
    if len(items) != n or not all(is_number(i) for i in items):
        return None
    return [float(i) for i in items]


def _pose(expr: str, state: _State) -> FloatArray | str:
    """(4, 4) metres of a pose expression, or why it cannot be evaluated."""
    expr = expr.strip()
    if expr.startswith("p[") and expr.endswith("]"):
        values = _numbers(expr[2:-1], 6)
        if values is None:
            return "pose literal without 6 numbers"
        return homogeneous(rot_vector(values[3], values[4], values[5]), (values[0], values[1], values[2]))
    trans = re.fullmatch(r"pose_trans\((.*)\)", expr)
    if trans:
        parts = split_top(trans.group(1))
        if len(parts) != 2:
            return "pose_trans takes two poses"
        a, b = _pose(parts[0], state), _pose(parts[1], state)
        if isinstance(a, str):
            return a
        if isinstance(b, str):
            return b
        return np.asarray(a @ b)
    if re.fullmatch(r"\w+", expr):
        var = state.variables.get(expr)
        if var is None:
            return f"{expr} is not defined"
        if var.pose is None:
            return f"{expr} holds no pose ({var.problem or 'a joint vector'})"
        return var.pose
    return f"pose expression '{expr}' is not modelled"


def _motion(line: _Line, func: str, args: list[str], state: _State) -> None:
    if not args:
        state.issue(line, "unsupported", f"{func} without a target")
        return
    positional = [a for a in args[1:] if not re.match(r"^\w+\s*=", a)]
    keywords = dict(a.split("=", 1) for a in args[1:] if re.match(r"^\w+\s*=", a))
    keywords = {k.strip(): v.strip() for k, v in keywords.items()}
    for key, value in zip(("a", "v", "t", "r"), positional):
        keywords.setdefault(key, value)
    if set(keywords) - {"a", "v", "t", "r"}:
        state.issue(line, "unsupported", f"{func} arguments {sorted(set(keywords) - {'a', 'v', 't', 'r'})}")
        return
    radius = keywords.get("r", "0")
    if not is_number(radius):
        state.issue(line, "unsupported", "blend radius from an expression")
        return
    blend = f"r={radius}" if float(radius) > 0 else None
    target = args[0]
    joints: tuple[float, ...] | None = None
    if target.startswith("["):
        values = _numbers(target[1:-1] if target.endswith("]") else "", 6)
        joints = tuple(values) if values is not None else None
        if joints is None:
            state.issue(line, "unsupported", "joint vector without 6 numbers")
            return
    elif re.fullmatch(r"\w+", target) and target in state.variables and state.variables[target].joints is not None:
        joints = state.variables[target].joints
    if joints is not None:
        if func == "movel":
            state.issue(line, "unsupported", "movel to a joint vector (its pose needs the arm's FK)")
            return
        state.events.append(Motion(line.where, func, "joint", target, tuple(math.degrees(q) for q in joints), None,
                                   state.tool, np.eye(4), None, blend))
        return
    pose = _pose(target, state)
    if isinstance(pose, str):
        state.issue(line, "unsupported" if "not modelled" in pose else "undefined", pose)
        return
    if state.tool is None:
        state.issue(line, "undefined", "Cartesian target while the TCP is unknown (no set_tcp, none given)")
    kind: MotionKind = "joint" if func == "movej" else "linear"
    state.events.append(Motion(line.where, func, kind, target, None, pose, state.tool, np.eye(4), None, blend))
