"""URScript read: `parse`, a program from its `.script` text."""

from __future__ import annotations

import math
import re
from typing import Any

from lark import Token, Tree
from lark.exceptions import UnexpectedInput

from robomax_py.errors import ProgramError
from robomax_py.export.dialect import (
    Parsed,
    is_header_comment,
    read_gripper,
    read_header,
    read_spot_label,
)
from robomax_py.export.flow import follow
from robomax_py.export.quaternions import zyx_from_rotvec
from robomax_py.export.urscript.flow import (
    _MIDDLE,
    _OPEN,
    _OWN,
    _classifier,
    _not_resting,
    _script,
)
from robomax_py.export.urscript.grammar import _CALLS, _UNSIMULATED, _numbers, _parser
from robomax_py.export.urscript.write import _NOTE, LIN_ACCEL_M_S2, reference_limits
from robomax_py.program import (
    NULL_FRAME,
    UNSET_FRAME,
    Comment,
    FrameDef,
    Instruction,
    LinMove,
    Program,
    PtpMove,
    SetSignal,
    Wait,
    WaitFor,
)
from robomax_py.robot import RobotModel


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
            if re.match(r"^(move\w*|servo\w*|speed\w*|sleep|spot_weld|grip|release|wait_for_signal|set_tcp|"
                        r"set_standard_digital_out)\s*\(", stmt) \
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
            # Called only within this statement's iteration, so the loop's values are the right ones.
            return _numbers(keywords[key], file, number)[0] if key in keywords else default  # noqa: B023

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
        elif func == "set_standard_digital_out":
            add(_set_out(args, comment, file, number), number)
    for routine in routines.values():
        if routine.name in _OWN:
            for line, text, why in _not_resting(routine):
                ignored.append((line, text))
                add(Comment(f"not simulated: {text} ({why})"), line)
    header = read_header(header_comments)
    return Parsed(Program(name, header, tuple(frames), tuple(instructions)), tuple(where), "ur", tuple(ignored),
                  tuple(followed.problems))


def _set_out(args: list[Any], comment: str, file: str, line: int) -> SetSignal:
    """`set_standard_digital_out(n, b)`: output n in [0:7] to the level b, True or False (UR Script
    Manual); anything else is not a program this reader runs."""
    level = args[1] if len(args) == 2 else None
    if not (isinstance(level, Token) and str(level) in ("True", "False")):
        raise ProgramError(file, f"line {line}", "set_standard_digital_out(n, b) needs an output number and True "
                                                 "or False")
    k = int(_numbers(args[0], file, line)[0])
    if not 0 <= k <= 7:
        raise ProgramError(file, f"line {line}", f"standard digital output {k} does not exist (0..7)")
    return SetSignal(comment or f"digital_out_{k}", k, str(level) == "True")
