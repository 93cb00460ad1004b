"""URScript, both directions: one program `<name>.script` (a `def` the controller runs).

What a program states, in URScript's terms (Universal Robots, "The URScript Programming
Language", movej / movel / set_tcp / sleep / get_standard_digital_in):
- `movej([q1, ..., q6], a, v, r)` with joint values in rad, `v` and `a` the leading joint's
  speed (rad/s) and acceleration (rad/s^2): the planned fractions of the robot's slowest joint
  limits; `movel(p[x, y, z, rx, ry, rz], a, v, r)` with the TCP pose in m and a rotation vector
  (rad) in the UR controller's base frame, `v` the TCP speed in m/s, `a` the line's acceleration
  fraction times 1.2 m/s^2, UR's default (at 1.2 the line is timed under the full joint limits; a
  line carrying a part states less, and a reader takes a/1.2 as the fraction, at most 1);
- the frames as global pose variables, as PolyScope writes them: the TCP `global <tool> = p[...]`
  (in the flange frame) set with `set_tcp(<tool>)` before the first motion; targets relative to
  the robot base as the UR controller defines it (ROS-Industrial's `base` link: robot.yaml
  `controller.base`), the robot's placement in the cell never written; in a user frame (a feature)
  `movel(pose_trans(<frame>, p[...]), ...)` with `global <frame> = p[...]` its pose in the base;
- blends as `r`, the TCP distance (m) of the planned radius; 0 at every stop and weld;
- no configuration data: the controller keeps the branch the arm is in, as robomax's LIN moves do;
- a weld as `movel(..., r=0)` followed by `spot_weld(n, weld_time)  # seam/name`, `spot_weld`
  defined in the program (sleep weld_time; the integrator replaces it);
- `sleep(t)`, and `wait_for_signal(k)  # <signal>` waiting for standard digital input k (0..7), the
  input the cell maps the signal to (`robot.controller.inputs`).

The reader takes movej with a joint vector, movel with a pose or a pose_trans of a pose variable
and a pose, pose variables, set_tcp, sleep and the calls above from any script; other motions (movep, movec, servoj, movej to a pose ...) are reported as
not simulated, everything else as ignored.

It follows the program's def as the controller runs it (`export.flow`): `halt()` ends the
program, `return` ends it (returns from a called function), a call of a function the script
defines runs its body in place. A call of any other function (built-ins that change no motion
or flow aside, `_INERT`), threads, `break` / `continue`, and a call or end inside if / while /
for are reported, never skipped. spot_weld, grip and release are the weld and gripper actions
they name while their def does nothing but `sleep` of its time parameter, wait_for_signal the
wait for an input while it is the loop `write` gives; the weld time is the call's second
argument, in s. Speeds: movel `v` in m/s, movej `v` and `a` in rad/s and rad/s^2 (rebuild reports
them above the slowest joint's limits, and lines above the cell's line speed).
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Callable
from functools import lru_cache

from lark import Lark, Token, Tree
from lark.exceptions import UnexpectedInput

from robomax_py.errors import ExportError, ProgramError
from robomax_py.export.dialect import (
    Parsed,
    PlannedProgram,
    gripper_label,
    header_lines,
    is_header_comment,
    numbered_inputs,
    read_gripper,
    read_header,
    read_spot_label,
    require_six_axes,
    spot_label,
    tree_numbers,
    with_brand_configs,
    with_tcp_blends,
)
from robomax_py.export.flow import Flow, Routine, Statement, follow
from robomax_py.export.quaternions import rotvec_from_zyx, zyx_from_rotvec
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

__all__ = ["adapt", "parse", "reference_limits", "write"]

_NOTE = "URScript"
LIN_ACCEL_M_S2 = 1.2            # URScript's default movel acceleration


def reference_limits(robot: RobotModel) -> tuple[float, float]:
    """(rad/s, rad/s^2): what speed and acceleration fraction 1 of a PTP move means in movej."""
    return float(min(robot.limits.velocity)), float(min(robot.limits.acceleration))


# The controller's standard digital inputs, get_standard_digital_in(0..7).
INPUTS = 7


def adapt(planned: PlannedProgram, robot: RobotModel) -> Program:
    """The program as URScript states it: no configuration data, TCP-distance blends, frames as
    pose variables, waits on standard digital inputs."""
    require_six_axes(robot, "URScript")
    numbered_inputs(planned.program, "URScript", 0, INPUTS)
    program = with_brand_configs(planned.program, planned.joints, robot, "ur")
    # URScript refers to poses by variable name: the frames carry no slot number.
    program = dataclasses.replace(program, frames=tuple(dataclasses.replace(f, number=0) for f in program.frames))
    return with_tcp_blends(dataclasses.replace(planned, program=program), robot)


# ================================================================================== writing


def _pose(xyz_mm: tuple[float, ...], zyx: tuple[float, ...]) -> str:
    x, y, z = (v / 1000.0 for v in xyz_mm)
    rx, ry, rz = rotvec_from_zyx(zyx)
    return f"p[{x:.6f}, {y:.6f}, {z:.6f}, {rx:.9f}, {ry:.9f}, {rz:.9f}]"


def _tcp(name: str) -> str:
    if name == UNSET_FRAME:
        raise ExportError("a URScript program sets its TCP before a movel: the program selects none")
    return name or "p[0, 0, 0, 0, 0, 0]"


def write(program: Program, robot: RobotModel) -> dict[str, str]:
    v_ref, a_ref = reference_limits(robot)
    out = [f"def {program.name}():"]
    out += [f"  # {text}" for text in header_lines(program.header)]
    out.append(f"  # {_NOTE}: m, rad, rotation vectors; movej v rad/s, a rad/s^2; movel v m/s; blend r m")
    what = {"tool": "TCP in the flange frame", "base": "user frame in the robot base frame"}
    out += [f"  global {f.name} = {_pose(f.xyz_mm, f.zyx_deg)}  # {what[f.kind]}" for f in program.frames]
    first = next((i for i in program.instructions if isinstance(i, LinMove)), None)
    tool = UNSET_FRAME
    if first is not None:
        tool = first.tool
        out.append(f"  set_tcp({_tcp(tool)})")
    out += ["  def spot_weld(n, weld_time):",
            "    # default weld: rest for weld_time s; replace with the gun's technology package",
            "    sleep(weld_time)", "  end",
            "  def wait_for_signal(n):", "    while not get_standard_digital_in(n):", "      sync()", "    end", "  end"]
    for action in sorted({ins.action for ins in program.instructions if isinstance(ins, Gripper)}):
        out += [f"  def {action}(n, {action}_time):",
                f"    # default {action}: rest for {action}_time s; replace with the gripper's outputs and sensors",
                f"    sleep({action}_time)", "  end"]
    grips: dict[str, int] = {}
    n_weld = 0
    for ins in program.instructions:
        if isinstance(ins, Comment):
            out.append(f"  # {ins.text}" if ins.text else "  #")
            continue
        if isinstance(ins, (PtpMove, LinMove)):
            note = f"  # {ins.comment}" if ins.comment else ""
            r = ins.flyby_mm / 1000.0
            if isinstance(ins, PtpMove):
                q = ", ".join(f"{math.radians(v):.9f}" for v in ins.target_deg)
                out.append(f"  movej([{q}], a={ins.accel * a_ref:.6f}, v={ins.speed * v_ref:.6f}, r={r:.9f}){note}")
            else:
                if ins.tool != tool:
                    tool = ins.tool
                    out.append(f"  set_tcp({_tcp(tool)})")
                if ins.base == UNSET_FRAME:
                    raise ExportError("a URScript movel is relative to the base or a pose: the program selects none")
                a = f"{LIN_ACCEL_M_S2:.1f}" if ins.accel >= 1.0 else f"{ins.accel * LIN_ACCEL_M_S2:.6f}"
                target = _pose(ins.position_mm, ins.zyx_deg)
                target = f"pose_trans({ins.base}, {target})" if ins.base else target
                out.append(f"  movel({target}, a={a}, v={ins.speed_mm_s / 1000:.6f}, r={r:.9f}){note}")
        elif isinstance(ins, Spot):
            n_weld += 1
            out.append(f"  spot_weld({n_weld}, {ins.time_s:.3f})  # {spot_label(ins)}")
        elif isinstance(ins, Gripper):
            grips[ins.action] = grips.get(ins.action, 0) + 1
            out.append(f"  {ins.action}({grips[ins.action]}, {ins.time_s:.3f})  # {gripper_label(ins)}")
        elif isinstance(ins, Wait):
            out.append(f"  sleep({ins.seconds:.3f})")
        elif isinstance(ins, WaitFor):
            out.append(f"  wait_for_signal({ins.number})  # {ins.signal}")
        else:
            raise ExportError(f"URScript cannot write {type(ins).__name__}")
    out.append("end")
    return {".script": "\n".join(out) + "\n"}


# ================================================================================== reading

_GRAMMAR = r"""
start: NAME "(" [arg ("," arg)*] ")"
?arg: value | NAME "=" value -> keyword
?value: NUMBER | NAME | list | pose | call
list: "[" [value ("," value)*] "]"
call: NAME "(" [value ("," value)*] ")"
pose: _POSE_OPEN value ("," value)* "]"
_POSE_OPEN.2: /p\[/
NAME: /[A-Za-z_][A-Za-z0-9_]*/
NUMBER: /[+-]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][+-]?[0-9]+)?/
%ignore /[ \t]+/
"""

_CALLS = ("movej", "movel", "set_tcp", "sleep", "spot_weld", "grip", "release", "wait_for_signal")
_UNSIMULATED = ("movep", "movec", "servoj", "servoc", "speedj", "speedl", "move_path", "movej_pose")


@lru_cache(maxsize=1)
def _parser() -> Lark:
    return Lark(_GRAMMAR, parser="lalr", lexer="contextual")


def _split(raw: str) -> tuple[str, str]:
    in_string = False
    for i, c in enumerate(raw):
        if c in "\"'":
            in_string = not in_string
        elif c == "#" and not in_string:
            return raw[:i].strip(), raw[i + 1:].strip()
    return raw.strip(), ""


def _numbers(node: object, file: str, line: int) -> list[float]:
    return tree_numbers(node, file, line, ("list", "pose"))


# ------------------------------------------------------------------ control flow

# What URScript statements do to the flow (Universal Robots, "The URScript Programming Language":
# `def` defines a function, run when called; `halt()` terminates the program; `return` leaves the
# function, the program when it is the program's own def; `thread` bodies run only when `run`
# starts them). RoboDK's UR post writes `halt()` to "Pause the robot program"
# (ros-industrial-attic/robodk_postprocessors@d7e6c1c0 Universal_Robots.py:634-639): the program
# ends there.
_HEAD = re.compile(r"^(def|thread)\s+([A-Za-z_][A-Za-z0-9_]*)\s*\((.*)\)\s*:$")
_OPEN = re.compile(r"^(while|if|for)\b.*:$")
_MIDDLE = re.compile(r"^(elif\b.*|else\s*):$")
# Built-in functions that change no motion and no flow: messages, outputs, payload and gravity,
# registers, a control cycle's wait.
_INERT = frozenset((
    "textmsg", "popup", "sync", "set_digital_out", "set_standard_digital_out", "set_configurable_digital_out",
    "set_tool_digital_out", "set_analog_out", "set_standard_analog_out", "set_payload", "set_payload_cog",
    "set_payload_mass", "set_tool_voltage", "set_gravity", "set_flag", "write_output_boolean_register",
    "write_output_integer_register", "write_output_float_register", "rtde_set_watchdog"))
# robomax's own routines: a call is a weld, a gripper action or a wait for an input, while their
# bodies are the ones `write` gives (`_not_resting`).
_OWN = ("spot_weld", "grip", "release", "wait_for_signal")


def _script(lines: list[str]) -> tuple[str, Routine | None, dict[str, Routine], list[tuple[int, str]]]:
    """The program's def (its name and body, the functions and threads defined in it taken out)
    and every function defined in the script, by name; and the top-level lines outside them."""
    name = ""
    main: list[Statement] = []
    routines: dict[str, Routine] = {}
    outside: list[tuple[int, str]] = []
    # open definitions: (name, params, body, depth of blocks inside); blocks of the main program
    stack: list[tuple[str, tuple[str, ...], list[Statement], list[str]]] = []
    for number, raw in enumerate(lines, start=1):
        stmt, comment = _split(raw)
        st = Statement(number, stmt, comment, raw)
        head = _HEAD.match(stmt)
        if head:
            params = tuple(p.split("=")[0].strip() for p in head.group(3).split(",") if p.strip())
            if not stack and not name and head.group(1) == "def" and not params:
                name = head.group(2)
                stack.append((name, (), main, []))
            elif stack:
                stack.append((head.group(2), params if head.group(1) == "def" else ("<thread>",), [], []))
            else:
                stack.append((head.group(2), params, [], []))
            continue
        if not stack:
            if stmt:
                outside.append((number, stmt))
            continue
        routine, params, body, blocks = stack[-1]
        if _OPEN.match(stmt):
            blocks.append(stmt)
        elif stmt == "end":
            if blocks:
                blocks.pop()
            else:
                stack.pop()
                if body is not main:
                    routines[routine] = Routine(routine, tuple(body), params)
                continue
        body.append(st)
    while stack:                                   # a definition missing its end runs to the end
        routine, params, body, _ = stack.pop()
        if body is not main:
            routines[routine] = Routine(routine, tuple(body), params)
    return name, (Routine(name, tuple(main)) if name else None), routines, outside


def _classifier(functions: set[str]) -> Callable[[Statement], Flow]:
    def classify(st: Statement) -> Flow:
        text = st.text
        if not text:
            return Flow()
        if re.fullmatch(r"halt\s*\(\s*\)", text):
            return Flow("end", "halt()", scope="program")
        if re.fullmatch(r"return\b.*", text):
            return Flow("end", "return")
        if text in ("break", "continue"):
            return Flow("unsupported", why=f"{text} leaves a loop")
        if _OPEN.match(text):
            return Flow("open")
        if text == "end":
            return Flow("close")
        if _MIDDLE.match(text):
            return Flow()
        if re.match(r"^(run|kill|join)\b", text):
            return Flow("unsupported", why="a thread: its statements run beside the program")
        assign = re.match(r"^(?:global\s+|local\s+)?[A-Za-z_][A-Za-z0-9_]*(\[[^\]]*\])?\s*=(?!=)(.*)$", text)
        if assign:
            for name, args in re.findall(r"([A-Za-z_][A-Za-z0-9_]*)\s*\(([^()]*)\)", assign.group(2)):
                if name in functions:
                    return Flow("call", name, arguments=bool(args.strip()))
            return Flow()
        call = re.fullmatch(r"([A-Za-z_][A-Za-z0-9_]*)\s*\((.*)\)", text)
        if call:
            func = call.group(1)
            if func in _CALLS or func in _UNSIMULATED or func in _INERT or func in _OWN:
                return Flow()
            return Flow("call", func, arguments=bool(call.group(2).strip()))
        return Flow()
    return classify


def _not_resting(routine: Routine) -> list[tuple[int, str, str]]:
    """(line, statement, why) of what one of robomax's routines does besides what `write` gives
    it: spot_weld, grip and release `sleep(<second parameter>)` once; wait_for_signal loops on
    `get_standard_digital_in(<its parameter>)` with `sync()`. Anything else is reported."""
    if routine.name == "wait_for_signal":
        n = routine.params[0] if len(routine.params) == 1 else "?"
        want = [f"while not get_standard_digital_in({n}):", "sync()", "end"]
        said = [st for st in routine.body if st.text]
        if [st.text for st in said] == want:
            return []
        line = said[0].line if said else 0
        return [(line, routine.name, ("wait_for_signal: not the routine robomax writes (verify takes a call of it "
                                      "for a wait for that input)"))]
    time = routine.params[1] if len(routine.params) == 2 else None
    waits = 0
    out: list[tuple[int, str, str]] = []
    for st in routine.body:
        if not st.text:
            continue
        if time is not None and re.fullmatch(rf"sleep\(\s*{re.escape(time)}\s*\)", st.text) and waits == 0:
            waits += 1
            continue
        out.append((st.line, st.text, (f"{routine.name}: a weld or gripper routine that does more than rest its time "
                                       "(verify takes a call of it for the weld or action it names)")))
    if waits == 0:
        line = routine.body[0].line if routine.body else 0
        out.append((line, routine.name, f"{routine.name}: it does not rest its time (sleep of its second parameter)"))
    return out


def parse(texts: dict[str, str], file: str, robot: RobotModel) -> Parsed:
    """A URScript program's motion (the statements of its outer `def`, nested functions skipped)."""
    v_ref, a_ref = reference_limits(robot)
    lines = texts.get(".script", "").splitlines()
    instructions: list[Instruction] = []
    where: list[int] = []
    ignored: list[tuple[int, str]] = []
    header_comments: list[str] = []
    frames: list[FrameDef] = []               # pose variables the program sets: tools and frames alike
    poses: dict[str, tuple[tuple[float, ...], tuple[float, ...]]] = {}
    tool = UNSET_FRAME                        # the TCP in force: the installation's until set_tcp

    def error(line: int, problem: str) -> ProgramError:
        return ProgramError(file, f"line {line}", problem)

    def pose_of(node: object, line: int) -> tuple[tuple[float, ...], tuple[float, ...]]:
        values = _numbers(node, file, line)
        if len(values) != 6:
            raise error(line, f"a pose has 6 values, got {len(values)}")
        return tuple(v * 1000.0 for v in values[:3]), zyx_from_rotvec(tuple(values[3:]))

    def use(kind: str, name: str, line: int) -> str:
        """A pose variable used as a tool or a frame: declared once per kind it serves."""
        if name not in poses:
            raise error(line, f"{name} is not a pose this program sets")
        if not any(f.kind == kind and f.name == name for f in frames):
            frames.append(FrameDef(name, kind, *poses[name]))      # type: ignore[arg-type]
        return name

    def add(ins: Instruction, line: int) -> None:
        instructions.append(ins)
        where.append(line)

    name, main, routines, outside = _script(lines)
    ignored.extend(outside)
    if main is None:
        raise ProgramError(file, None, "no 'def NAME():' line: not a URScript program")
    followed = follow(main, routines, _classifier(set(routines)), key=str)
    for step in followed.steps:
        st, number = step.statement, step.line
        stmt, comment, raw = st.text, st.comment, st.raw
        if step.unsupported:
            ignored.append((number, stmt))
            add(Comment(f"not simulated: {stmt} ({step.unsupported})"), number)
            continue
        if _OPEN.match(stmt) or _MIDDLE.match(stmt) or stmt == "end":
            continue
        if step.conditional:
            if re.match(r"^(move\w*|servo\w*|speed\w*|sleep|spot_weld|grip|release|wait_for_signal|set_tcp)\s*\(", stmt) \
                    or re.match(r"^(?:global\s+)?[A-Za-z_][A-Za-z0-9_]*\s*=\s*p\[", stmt):
                # Inside while / if / for: whether, or how often, it runs depends on a condition.
                ignored.append((number, stmt))
                add(Comment(f"not simulated: {stmt}"), number)
            continue
        if not stmt:
            if raw.strip().startswith("#"):
                if is_header_comment(comment) or comment.startswith(_NOTE):
                    header_comments.append(comment)
                else:
                    add(Comment(comment), number)
            continue
        assign = re.match(r"^(?:global\s+)?([A-Za-z_][A-Za-z0-9_]*)\s*=\s*(p\[.*\])$", stmt)
        if assign:
            try:
                pose = _parser().parse(f"f({assign.group(2)})").children[1]
            except UnexpectedInput:
                raise error(number, f"cannot read {stmt!r}") from None
            if any(f.name == assign.group(1) for f in frames):
                raise error(number, f"{assign.group(1)} is set again after a move used it: not simulated here")
            poses[assign.group(1)] = pose_of(pose, number)
            continue
        call = re.match(r"^([A-Za-z_][A-Za-z0-9_]*)\s*\(", stmt)
        func = call.group(1) if call else ""
        if func in _UNSIMULATED:
            ignored.append((number, stmt))
            add(Comment(f"not simulated: {stmt}"), number)
            continue
        if func not in _CALLS:
            ignored.append((number, stmt))
            continue
        try:
            tree = _parser().parse(stmt)
        except UnexpectedInput:
            raise error(number, f"cannot read {stmt!r}") from None
        args = [c for c in tree.children[1:] if not (isinstance(c, Tree) and c.data == "keyword")]
        keywords = {str(c.children[0]): c.children[1] for c in tree.children[1:]
                    if isinstance(c, Tree) and c.data == "keyword"}
        order = ("a", "v", "t", "r")
        for key, value in zip(order, args[1:]):
            keywords.setdefault(key, value)

        def kw(key: str, default: float) -> float:
            return _numbers(keywords[key], file, number)[0] if key in keywords else default

        target = args[0] if args else None
        if func == "movej":
            if not (isinstance(target, Tree) and target.data == "list"):
                ignored.append((number, stmt))
                add(Comment(f"not simulated: {stmt}"), number)
                continue
            q = _numbers(target, file, number)
            add(PtpMove(tuple(math.degrees(v) for v in q), kw("v", 1.05) / v_ref, kw("a", 1.4) / a_ref,
                        comment=comment, flyby_mm=kw("r", 0.0) * 1000.0), number)
        elif func == "movel":
            base = NULL_FRAME
            if isinstance(target, Tree) and target.data == "call" and str(target.children[0]) == "pose_trans" \
                    and len(target.children) == 3 and isinstance(target.children[1], Token):
                base = use("base", str(target.children[1]), number)
                target = target.children[2]
            if not (isinstance(target, Tree) and target.data == "pose"):
                raise error(number, "movel needs a pose p[x, y, z, rx, ry, rz] or pose_trans(<pose variable>, p[...])")
            xyz, zyx = pose_of(target, number)
            add(LinMove(xyz, zyx, "", kw("v", 0.25) * 1000.0, comment=comment, flyby_mm=kw("r", 0.0) * 1000.0,
                        accel=max(min(kw("a", LIN_ACCEL_M_S2) / LIN_ACCEL_M_S2, 1.0), 0.001), tool=tool, base=base),
                number)
        elif func == "set_tcp":
            if isinstance(target, Token) and target.type == "NAME":
                tool = use("tool", str(target), number)
            else:
                tool = f"set_tcp of line {number}"
                frames.append(FrameDef(tool, "tool", *pose_of(target, number)))
        elif func == "sleep":
            add(Wait(_numbers(target, file, number)[0]), number)
        elif func == "spot_weld":
            n, seconds = (_numbers(a, file, number)[0] for a in args[:2])
            add(read_spot_label(comment, int(n), seconds, file, number), number)
        elif func in ("grip", "release"):
            n, seconds = (_numbers(a, file, number)[0] for a in args[:2])
            add(read_gripper(func, comment, int(n), seconds, file, number), number)
        elif func == "wait_for_signal":
            k = int(_numbers(target, file, number)[0])
            add(WaitFor(comment or f"digital_in_{k}", k), number)
    for routine in routines.values():
        if routine.name in _OWN:
            for line, text, why in _not_resting(routine):
                ignored.append((line, text))
                add(Comment(f"not simulated: {text} ({why})"), line)
    header = read_header(header_comments)
    return Parsed(Program(name, header, tuple(frames), tuple(instructions)), tuple(where), "ur", tuple(ignored),
                  tuple(followed.problems))
