"""URScript, both directions: one program `<name>.script` (a `def` the controller runs).

What a program states, in URScript's terms (Universal Robots, "The URScript Programming
Language", movej / movel / set_tcp / sleep / get_standard_digital_in):
- `movej([q1, ..., q6], a, v, r)` with joint values in rad, `v` and `a` the leading joint's
  speed (rad/s) and acceleration (rad/s^2): the planned fractions of the robot's slowest joint
  limits; `movel(p[x, y, z, rx, ry, rz], a, v, r)` with the TCP pose in m and a rotation vector
  (rad) in the UR controller's base frame, `v` the TCP speed in m/s, `a` the line's acceleration
  fraction times 1.2 m/s^2, UR's default (at 1.2 the line is timed under the full joint limits; a
  line carrying a part states less, and a reader takes a/1.2 as the fraction, at most 1);
- `set_tcp` (the TCP in the flange frame) before the first motion; the base is the controller's;
- blends as `r`, the TCP distance (m) of the planned radius; 0 at every stop and weld;
- no configuration data: the controller keeps the branch the arm is in, as robomax's LIN moves do;
- a weld as `movel(..., r=0)` followed by `spot_weld(n, weld_time)  # seam/name`, `spot_weld`
  defined in the program (sleep weld_time; the integrator replaces it);
- `sleep(t)`, and `wait_for_signal(k)  # <signal>` waiting for standard digital input k.

The reader takes movej with a joint vector, movel with a pose, set_tcp, sleep and the calls
above from any script; other motions (movep, movec, servoj, movej to a pose ...) are reported as
not simulated, everything else as ignored.
"""

from __future__ import annotations

import dataclasses
import math
import re
from functools import lru_cache

from lark import Lark, Tree
from lark.exceptions import UnexpectedInput

from robomax_py.errors import ExportError, ProgramError
from robomax_py.export.dialect import (
    Parsed,
    PlannedProgram,
    gripper_label,
    header_lines,
    is_header_comment,
    read_gripper,
    read_header,
    read_spot_label,
    require_six_axes,
    spot_label,
    tree_numbers,
    with_brand_configs,
    with_tcp_blends,
)
from robomax_py.export.quaternions import rotvec_from_zyx, zyx_from_rotvec
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

__all__ = ["adapt", "parse", "reference_limits", "write"]

_NOTE = "URScript"
LIN_ACCEL_M_S2 = 1.2            # URScript's default movel acceleration


def reference_limits(robot: RobotModel) -> tuple[float, float]:
    """(rad/s, rad/s^2): what speed and acceleration fraction 1 of a PTP move means in movej."""
    return float(min(robot.limits.velocity)), float(min(robot.limits.acceleration))


def adapt(planned: PlannedProgram, robot: RobotModel) -> Program:
    """The program as URScript states it: no configuration data, TCP-distance blends, no base frame."""
    require_six_axes(robot, "URScript")
    program = with_brand_configs(planned.program, planned.joints, robot, "ur")
    program = with_tcp_blends(dataclasses.replace(planned, program=program), robot)
    return dataclasses.replace(program, frames=tuple(f for f in program.frames if f.kind == "tool"))


# ================================================================================== writing


def _pose(xyz_mm: tuple[float, ...], zyx: tuple[float, ...]) -> str:
    x, y, z = (v / 1000.0 for v in xyz_mm)
    rx, ry, rz = rotvec_from_zyx(zyx)
    return f"p[{x:.6f}, {y:.6f}, {z:.6f}, {rx:.9f}, {ry:.9f}, {rz:.9f}]"


def write(program: Program, robot: RobotModel) -> dict[str, str]:
    v_ref, a_ref = reference_limits(robot)
    out = [f"def {program.name}():"]
    out += [f"  # {text}" for text in header_lines(program.header)]
    out.append(f"  # {_NOTE}: m, rad, rotation vectors; movej v rad/s, a rad/s^2; movel v m/s; blend r m")
    for f in program.frames:
        out.append(f"  set_tcp({_pose(f.xyz_mm, f.zyx_deg)})  # tool frame {f.name}")
    out += ["  def spot_weld(n, weld_time):",
            "    # default weld: rest for weld_time s; replace with the gun's technology package",
            "    sleep(weld_time)", "  end",
            "  def wait_for_signal(n):", "    while not get_standard_digital_in(n):", "      sync()", "    end", "  end"]
    for action in sorted({ins.action for ins in program.instructions if isinstance(ins, Gripper)}):
        out += [f"  def {action}(n, {action}_time):",
                f"    # default {action}: rest for {action}_time s; replace with the gripper's outputs and sensors",
                f"    sleep({action}_time)", "  end"]
    signals: dict[str, int] = {}
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
                a = f"{LIN_ACCEL_M_S2:.1f}" if ins.accel >= 1.0 else f"{ins.accel * LIN_ACCEL_M_S2:.6f}"
                out.append(f"  movel({_pose(ins.position_mm, ins.zyx_deg)}, a={a}, "
                           f"v={ins.speed_mm_s / 1000:.6f}, r={r:.9f}){note}")
        elif isinstance(ins, Spot):
            n_weld += 1
            out.append(f"  spot_weld({n_weld}, {ins.time_s:.3f})  # {spot_label(ins)}")
        elif isinstance(ins, Gripper):
            grips[ins.action] = grips.get(ins.action, 0) + 1
            out.append(f"  {ins.action}({grips[ins.action]}, {ins.time_s:.3f})  # {gripper_label(ins)}")
        elif isinstance(ins, Wait):
            out.append(f"  sleep({ins.seconds:.3f})")
        elif isinstance(ins, WaitFor):
            k = signals.setdefault(ins.signal, len(signals))
            out.append(f"  wait_for_signal({k})  # {ins.signal}")
        else:
            raise ExportError(f"URScript cannot write {type(ins).__name__}")
    out.append("end")
    return {".script": "\n".join(out) + "\n"}


# ================================================================================== reading

_GRAMMAR = r"""
start: NAME "(" [arg ("," arg)*] ")"
?arg: value | NAME "=" value -> keyword
?value: NUMBER | NAME | list | pose
list: "[" [value ("," value)*] "]"
pose: _POSE_OPEN value ("," value)* "]"
_POSE_OPEN.2: /p\[/
NAME: /[A-Za-z_][A-Za-z0-9_]*/
NUMBER: /[+-]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][+-]?[0-9]+)?/
%ignore /[ \t]+/
"""

_CALLS = ("movej", "movel", "set_tcp", "sleep", "spot_weld", "grip", "release", "wait_for_signal")
_UNSIMULATED = ("movep", "movec", "servoj", "servoc", "speedj", "speedl", "move_path", "movej_pose")
_BLOCK = re.compile(r"^(def|thread|while|if|for)\b.*:\s*$")
# elif / else continue a block rather than open one.


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


def parse(texts: dict[str, str], file: str, robot: RobotModel) -> Parsed:
    """A URScript program's motion (the statements of its outer `def`, nested functions skipped)."""
    v_ref, a_ref = reference_limits(robot)
    lines = texts.get(".script", "").splitlines()
    name = ""
    blocks: list[str] = []           # open blocks inside the program's def
    instructions: list[Instruction] = []
    where: list[int] = []
    ignored: list[tuple[int, str]] = []
    header_comments: list[str] = []
    frames: list[FrameDef] = []

    def error(line: int, problem: str) -> ProgramError:
        return ProgramError(file, f"line {line}", problem)

    def add(ins: Instruction, line: int) -> None:
        instructions.append(ins)
        where.append(line)

    for number, raw in enumerate(lines, start=1):
        stmt, comment = _split(raw)
        if not name:
            head = re.match(r"^def\s+([A-Za-z_][A-Za-z0-9_]*)\s*\(\s*\)\s*:$", stmt)
            if head:
                name = head.group(1)
            elif stmt:
                ignored.append((number, stmt))
            continue
        if _BLOCK.match(stmt):
            blocks.append(stmt.split()[0].split("(")[0])
            continue
        if stmt == "end":
            if not blocks:
                break
            blocks.pop()
            continue
        if "def" in blocks:             # a function's body runs when it is called: not here
            continue
        if blocks and re.match(r"^(move\w*|servo\w*|speed\w*|sleep|spot_weld|grip|release|wait_for_signal)\s*\(", stmt):
            # Inside while / if / for / thread: the reader does not follow control flow.
            ignored.append((number, stmt))
            add(Comment(f"not simulated: {stmt}"), number)
            continue
        if blocks:
            continue
        if not stmt:
            if raw.strip().startswith("#"):
                if is_header_comment(comment) or comment.startswith(_NOTE):
                    header_comments.append(comment)
                else:
                    add(Comment(comment), number)
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
            if not (isinstance(target, Tree) and target.data == "pose"):
                raise error(number, "movel needs a pose p[x, y, z, rx, ry, rz]")
            values = _numbers(target, file, number)
            if len(values) != 6:
                raise error(number, f"a pose has 6 values, got {len(values)}")
            add(LinMove(tuple(v * 1000.0 for v in values[:3]), zyx_from_rotvec(tuple(values[3:])), "",
                        kw("v", 0.25) * 1000.0, comment=comment, flyby_mm=kw("r", 0.0) * 1000.0,
                        accel=max(min(kw("a", LIN_ACCEL_M_S2) / LIN_ACCEL_M_S2, 1.0), 0.001)), number)
        elif func == "set_tcp":
            values = _numbers(target, file, number)
            frame_name = comment.split()[-1] if comment.startswith("tool frame ") else "tcp"
            frames = [FrameDef(frame_name, "tool", tuple(v * 1000.0 for v in values[:3]), zyx_from_rotvec(tuple(values[3:])))]
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
            add(WaitFor(comment or f"digital_in_{k}"), number)
    if not name:
        raise ProgramError(file, None, "no 'def NAME():' line: not a URScript program")
    header = read_header(header_comments)
    return Parsed(Program(name, header, tuple(frames), tuple(instructions)), tuple(where), "ur", tuple(ignored))
