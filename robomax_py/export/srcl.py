"""SRCL, both directions: `Program` -> text (`write_program`) and text -> `Program` (`parse_program`,
lark LALR). A small, regular, IRL-style (DIN 66312) dialect; see docs/srcl.md.

One statement per line, upper-case keywords, numbers with the fixed decimals of `robomax_py.program`
(joints 4, mm 3, angles 4, speeds 3, times 3), comments in ``{ ... }`` on one line. The text depends
on the program only (no timestamps), and `parse_program` reads it back to an equal `Program`; writing
that again gives the same bytes. Parse errors are a `ProgramError` whose key is "line L, column C"
(1-based) and whose problem is written for people, e.g. "expected ';' after MOVE statement, got
'SPOT'"; besides syntax the parser checks what the writer checks (plain decimal numbers, ranges via
`find_problem`, one PTP value per declared axis, unique joint and frame names).
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Iterable
from functools import lru_cache
from pathlib import Path
from typing import Literal

from lark import Lark, Token, Tree
from lark.exceptions import (
    UnexpectedCharacters,
    UnexpectedEOF,
    UnexpectedInput,
    UnexpectedToken,
)
from lark.lexer import PatternStr

from robomax_py.errors import ExportError, ProgramError
from robomax_py.export.dialect import Parsed, PlannedProgram
from robomax_py.program import (
    ANGLE_DECIMALS,
    JOINT_DECIMALS,
    MM_DECIMALS,
    NULL_FRAME,
    SPEED_DECIMALS,
    TIME_DECIMALS,
    UNSET_FRAME,
    Comment,
    FrameDef,
    Gripper,
    Header,
    Instruction,
    LinMove,
    Program,
    PtpMove,
    Spot,
    Wait,
    WaitFor,
    find_problem,
)
from robomax_py.robot import RobotModel

__all__ = ["DIALECT", "GRAMMAR", "RESERVED", "adapt", "parse", "parse_program", "parse_with_lines", "write",
           "write_program"]

DIALECT = "robomax SRCL/1"

# Upper-case keywords; they cannot be used as names (names are case-sensitive, so `spot` is a name).
RESERVED: frozenset[str] = frozenset(
    "PROGRAM CELL ROBOT AXES TOOL CYCLE SEC VAR FRAME BASE POS ORI BEGIN ENDPROGRAM "
    "MOVE PTP LIN AXIS SPEED ACCEL FLYBY CONFIG SPOT SEAM TIME WAIT FOR GUN SCHEDULE GRIP RELEASE INPUT".split()
)

_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_INDENT = "  "


def write_program(program: Program) -> str:
    """The SRCL text of a program.

    Parameters
    ----------
    program : Program

    Returns
    -------
    str
        Lines joined with "\\n", ending in a newline.

    Raises
    ------
    ExportError
        A name is not an identifier or is a keyword, a comment or config cannot be written
        (braces, quotes, control characters), a number is NaN or infinite or out of range, a PTP
        target has the wrong number of axes, or two frames share a name.
    """
    _check_program(program)
    h = program.header
    lines = [
        f"PROGRAM {program.name};",
        f"{{ {DIALECT}; lengths mm, angles deg, times s, PTP speed and accel as fractions }}",
        *(f"{{ {text} }}" for text in _provenance(h)),
        f"CELL {h.cell};",
        f"ROBOT {h.robot} AXES({', '.join(h.joints)});",
        f"TOOL {h.tool};",
        f"CYCLE {_num(h.cycle_time_s, TIME_DECIMALS)} SEC;",
    ]
    if program.frames:
        lines.append("VAR")
        lines.extend(_INDENT + _frame(f) for f in program.frames)
    lines.append("BEGIN")
    lines.extend(_INDENT + _statement(ins) for ins in program.instructions)
    lines.append("ENDPROGRAM;")
    return "\n".join(lines) + "\n"


def _provenance(h: Header) -> list[str]:
    """Generator, cell file hash and stamp as comment texts (the rest of the header is statements)."""
    out = []
    if h.generator or h.cell_sha256:
        out.append(f"{h.generator or 'robomax_py ?'} | cell file sha256 {h.cell_sha256 or 'unknown'}")
    if h.stamp:
        out.append(f"written {h.stamp}")
    return out


_PROVENANCE = re.compile(r"^(?P<gen>\S+ \S+) \| cell file sha256 (?P<sha>[0-9a-f]+|unknown)$")
_STAMP = re.compile(r"^written (?P<stamp>\S.*)$")


def _num(value: float, decimals: int) -> str:
    return f"{value:.{decimals}f}"


def _nums(values: Iterable[float], decimals: int) -> str:
    return ", ".join(_num(v, decimals) for v in values)


def _pose(xyz_mm: tuple[float, ...], zyx_deg: tuple[float, ...]) -> str:
    return f"POS({_nums(xyz_mm, MM_DECIMALS)}) ORI({_nums(zyx_deg, ANGLE_DECIMALS)})"


def _frame(f: FrameDef) -> str:
    pos = f"POS({_nums(f.xyz_mm, MM_DECIMALS)})"
    ori = f"ORI({_nums(f.zyx_deg, ANGLE_DECIMALS)})"
    number = f" {f.number}" if f.number else ""
    return f"{f.name}: {f.kind.upper()} FRAME{number} := ({pos}, {ori});"


def _tail(flyby: float, comment: str) -> str:
    fly = f" FLYBY {_num(flyby, ANGLE_DECIMALS)}" if flyby > 0 else ""
    return fly + (f" {{ {comment} }}" if comment else "") + ";"


def _statement(ins: Instruction) -> str:
    if isinstance(ins, PtpMove):
        return (
            f"MOVE PTP AXIS({_nums(ins.target_deg, JOINT_DECIMALS)}) "
            f"SPEED {_num(ins.speed, SPEED_DECIMALS)} ACCEL {_num(ins.accel, SPEED_DECIMALS)}"
            + _tail(ins.flyby, ins.comment)
        )
    if isinstance(ins, LinMove):
        return (
            f"MOVE LIN {_pose(ins.position_mm, ins.zyx_deg)} CONFIG '{ins.config}' "
            f"SPEED {_num(ins.speed_mm_s, SPEED_DECIMALS)} MM/S"
            + (f" ACCEL {_num(ins.accel, SPEED_DECIMALS)}" if ins.accel < 1.0 else "") + _tail(ins.flyby, ins.comment)
        )
    if isinstance(ins, Spot):
        return (f"SPOT {ins.name} SEAM {ins.seam} TIME {_num(ins.time_s, TIME_DECIMALS)} SEC "
                f"GUN {ins.gun} SCHEDULE {ins.schedule};")
    if isinstance(ins, Gripper):
        return f"{ins.action.upper()} {ins.name} SEAM {ins.seam} TIME {_num(ins.time_s, TIME_DECIMALS)} SEC;"
    if isinstance(ins, Wait):
        return f"WAIT {_num(ins.seconds, TIME_DECIMALS)} SEC;"
    if isinstance(ins, WaitFor):
        return f"WAIT FOR {ins.signal}" + ("" if ins.number is None else f" INPUT {ins.number}") + ";"
    if isinstance(ins, Comment):
        return f"{{ {ins.text} }}" if ins.text else "{ }"
    raise ExportError(f"SRCL cannot write instruction {ins!r}")


def _check_name(where: str, name: object) -> None:
    if not isinstance(name, str) or not _NAME.fullmatch(name):
        raise ExportError(f"{where}: {name!r} is not an SRCL name (letters, digits, '_'; not starting with a digit)")
    if name in RESERVED:
        raise ExportError(f"{where}: {name!r} is an SRCL keyword and cannot be used as a name")


def _check_text(where: str, text: str, forbidden: str) -> None:
    bad = [c for c in text if c in forbidden or not c.isprintable()]
    if bad:
        raise ExportError(f"{where}: {text!r} cannot contain {bad[0]!r} (no {forbidden}, newlines or control characters)")


def _kind(ins: Instruction) -> str:
    return {
        PtpMove: "MOVE PTP", LinMove: "MOVE LIN", Spot: "SPOT", Gripper: "GRIP/RELEASE", Wait: "WAIT",
        WaitFor: "WAIT FOR", Comment: "comment"
    }.get(type(ins), type(ins).__name__)


def _check_program(program: Program) -> None:
    _check_name("program name", program.name)
    h = program.header
    if not isinstance(h, Header):
        raise ExportError(f"program header must be a Header, got {type(h).__name__}")
    _check_name("header cell", h.cell)
    _check_name("header robot", h.robot)
    _check_name("header tool", h.tool)
    for j, joint in enumerate(h.joints):
        _check_name(f"header joint {j}", joint)
    problem = find_problem(h, len(h.joints))
    if problem:
        raise ExportError(f"header: {problem}")
    seen: set[str] = set()
    for i, f in enumerate(program.frames):
        where = f"frame {i} ({f.name!r})"
        _check_name(where, f.name)
        if f.name in seen:
            raise ExportError(f"{where}: a frame named {f.name!r} is already defined")
        seen.add(f.name)
        problem = find_problem(f, len(h.joints))
        if problem:
            raise ExportError(f"{where}: {problem}")
        if f.number < 0:
            raise ExportError(f"{where}: frame number {f.number} is negative")
    tool, base = lin_frames(program.frames)
    for i, ins in enumerate(program.instructions):
        where = f"instruction {i} ({_kind(ins)})"
        if isinstance(ins, (PtpMove, LinMove)):
            _check_text(where + " comment", ins.comment, "{}")
        if isinstance(ins, LinMove):
            _check_text(where + " config", ins.config, "'")
        elif isinstance(ins, (Spot, Gripper)):
            _check_name(where + " spot name", ins.name)
            _check_name(where + " seam name", ins.seam)
        elif isinstance(ins, WaitFor):
            _check_name(where + " signal", ins.signal)
            if ins.number is not None and ins.number < 0:
                raise ExportError(f"{where}: input number {ins.number} is negative")
        elif isinstance(ins, Comment):
            _check_text(where, ins.text, "{}")
        elif not isinstance(ins, (PtpMove, Wait)):
            raise ExportError(f"{where}: SRCL cannot write {type(ins).__name__}")
        if isinstance(ins, (PtpMove, LinMove)) and ins.flyby_mm > 0:
            raise ExportError(f"{where}: SRCL states fly-by radii in joint space (FLYBY deg), not as a TCP distance")
        problem = find_problem(ins, len(h.joints))
        if problem:
            raise ExportError(f"{where}: {problem}")
        if isinstance(ins, LinMove) and (ins.tool, ins.base) != (tool, base):
            raise ExportError(f"{where}: SRCL states every LIN in its one TOOL and BASE frame ({tool or 'none'}, "
                              f"{base or 'the robot base'}); this one names {ins.tool or 'none'}, "
                              f"{ins.base or 'the robot base'}")


def lin_frames(frames: tuple[FrameDef, ...]) -> tuple[str, str]:
    """The tool and base every SRCL LIN is stated in: the program's one TOOL FRAME (none declared:
    `UNSET_FRAME`, the program selects no tool) and its one BASE FRAME (none: the robot base frame)."""
    out = []
    for kind, absent in (("tool", UNSET_FRAME), ("base", NULL_FRAME)):
        named = [f.name for f in frames if f.kind == kind]
        if len(named) > 1:
            raise ExportError(f"SRCL declares at most one {kind.upper()} FRAME, got {len(named)}: {', '.join(named)}")
        out.append(named[0] if named else absent)
    return out[0], out[1]


# ================================================================================== reading

GRAMMAR = r"""
start: "PROGRAM" IDENT ";" COMMENT* header frames "BEGIN" _stmt* "ENDPROGRAM" ";"

header: "CELL" IDENT ";" COMMENT* \
        "ROBOT" IDENT "AXES" "(" IDENT ("," IDENT)* ")" ";" COMMENT* \
        "TOOL" IDENT ";" COMMENT* \
        "CYCLE" NUMBER "SEC" ";" COMMENT*

frames: ("VAR" COMMENT* frame*)?
frame: IDENT ":" kind "FRAME" NUMBER? ":=" "(" pos "," ori ")" ";" COMMENT*
kind: "TOOL" -> tool_kind
    | "BASE" -> base_kind
pos: "POS" "(" NUMBER "," NUMBER "," NUMBER ")"
ori: "ORI" "(" NUMBER "," NUMBER "," NUMBER ")"

_stmt: ptp | lin | spot | gripper | wait | wait_for | note
ptp: "MOVE" "PTP" "AXIS" "(" NUMBER ("," NUMBER)* ")" "SPEED" NUMBER "ACCEL" NUMBER flyby? COMMENT? ";"
lin: "MOVE" "LIN" pos ori "CONFIG" STRING "SPEED" NUMBER _MM_S ("ACCEL" NUMBER)? flyby? COMMENT? ";"
flyby: FLYBY NUMBER
spot: "SPOT" IDENT "SEAM" IDENT "TIME" NUMBER "SEC" ("GUN" NUMBER "SCHEDULE" NUMBER)? ";"
gripper: (GRIP | RELEASE) IDENT "SEAM" IDENT "TIME" NUMBER "SEC" ";"
wait: "WAIT" NUMBER "SEC" ";"
wait_for: "WAIT" "FOR" IDENT ("INPUT" NUMBER)? ";"
note: COMMENT

FLYBY: "FLYBY"
GRIP: "GRIP"
RELEASE: "RELEASE"
_MM_S.2: "MM/S"
IDENT: /[A-Za-z_][A-Za-z0-9_]*/
NUMBER: /[+-]?\.?[0-9][A-Za-z0-9_.]*/
STRING: /'[^'\n]*'/
COMMENT: /\{[^{}\n]*\}/
%ignore /[ \t\r\n]+/
"""

_PLAIN_NUMBER = re.compile(r"[+-]?[0-9]+(\.[0-9]+)?")

# Statement keywords, for "... in/after MOVE statement" in messages.
_CONTEXT = {
    "PROGRAM": "PROGRAM heading", "CELL": "CELL line", "ROBOT": "ROBOT line", "TOOL": "TOOL line",
    "CYCLE": "CYCLE line", "MOVE": "MOVE statement", "SPOT": "SPOT statement", "WAIT": "WAIT statement",
    "GRIP": "GRIP statement", "RELEASE": "RELEASE statement", "ENDPROGRAM": "ENDPROGRAM",
}
_NAMED = {
    "IDENT": "a name", "NUMBER": "a number", "STRING": "a quoted string", "COMMENT": "a comment",
    "FLYBY": "FLYBY", "$END": "end of file",
}


@lru_cache(maxsize=1)
def _parser() -> Lark:
    return Lark(GRAMMAR, parser="lalr", lexer="basic", propagate_positions=True, maybe_placeholders=False)


def parse_program(text: str, file: str | Path | None = None) -> Program:
    """Read an SRCL program.

    Parameters
    ----------
    text : str
        The program text.
    file : str | Path | None
        Named in error messages only.

    Returns
    -------
    Program

    Raises
    ------
    ProgramError
        With key "line L, column C" and a readable problem.
    """
    parser = _parser()
    try:
        tree = parser.parse(text)
    except UnexpectedInput as exc:
        line, column, problem = _describe(parser, text, exc)
        raise ProgramError(file, f"line {line}, column {column}", problem) from None
    return _Builder(file).program(tree)


def parse_with_lines(text: str, file: str | Path | None = None) -> tuple[Program, tuple[int, ...]]:
    """`parse_program`, and the line of each instruction."""
    parser = _parser()
    try:
        tree = parser.parse(text)
    except UnexpectedInput as exc:
        line, column, problem = _describe(parser, text, exc)
        raise ProgramError(file, f"line {line}, column {column}", problem) from None
    builder = _Builder(file)
    program = builder.program(tree)
    return program, tuple(builder.lines)


# --------------------------------------------------------------------------------------------------
# syntax errors


def _show(token: Token) -> str:
    if token.type == "$END":
        return "end of file"
    return repr(str(token)) if "'" not in token else f'"{token}"'


def _expected(parser: Lark, names: set[str]) -> str:
    shown: list[str] = []
    for name in names:
        if name in _NAMED:
            shown.append(_NAMED[name])
            continue
        pattern = parser.get_terminal(name).pattern
        shown.append(f"'{pattern.value}'" if isinstance(pattern, PatternStr) else name)
    shown = sorted(set(shown), key=lambda s: (not s.startswith("'"), s))
    if len(shown) == 1:
        return shown[0]
    return "one of " + ", ".join(shown[:-1]) + " or " + shown[-1]


def _context(parser: Lark, text: str, pos: int) -> tuple[str, bool]:
    """The construct being read at `pos` and whether a ';' has closed it."""
    last = ""
    closed = False
    try:
        for tok in parser.lex(text[:pos]):
            if tok.type == "SEMICOLON":
                closed = True
            elif str(tok) in _CONTEXT and tok.type != "IDENT":
                last, closed = _CONTEXT[str(tok)], False
            elif tok.type == "COMMENT" and closed:
                last = ""
    except UnexpectedInput:
        return "", True
    return last, closed


def _end_position(text: str) -> tuple[int, int]:
    body = text.rstrip()
    line = body.count("\n") + 1
    column = len(body) - (body.rfind("\n") + 1) + 1
    return line, column


def _describe(parser: Lark, text: str, exc: UnexpectedInput) -> tuple[int, int, str]:
    if isinstance(exc, UnexpectedCharacters):
        char = text[exc.pos_in_stream] if exc.pos_in_stream is not None else ""
        if char == "{":
            problem = "unterminated comment: '{' has no '}' on the same line (comments are one line, no nested braces)"
        elif char == "'":
            problem = "unterminated string: quote has no closing quote on the same line"
        else:
            problem = f"unexpected character {char!r}"
        return exc.line, exc.column, problem
    if isinstance(exc, UnexpectedEOF):
        line, column = _end_position(text)
        return line, column, f"unexpected end of file; expected {_expected(parser, set(exc.expected))}"
    if not isinstance(exc, UnexpectedToken):
        return exc.line, exc.column, str(exc)
    token: Token = exc.token
    expected = set(exc.expected)
    if token.type == "$END":
        line, column = _end_position(text)
        pos = len(text)
    else:
        line, column = token.line or 0, token.column or 0
        pos = token.start_pos or 0
    got = _show(token)
    if token.type == "NUMBER" and not _PLAIN_NUMBER.fullmatch(str(token)):
        return line, column, f"bad number {got}: write digits with an optional '.' and decimals, e.g. 12.500"
    if token.type == "$END":
        return line, column, f"unexpected end of file; expected {_expected(parser, expected)}"
    if "MOVE" in expected and "ENDPROGRAM" in expected and token.type != "SEMICOLON":
        hint = " (keywords are upper case)" if str(token).upper() in RESERVED else ""
        return line, column, (
            f"unknown statement {got}{hint}; expected MOVE, SPOT, GRIP, RELEASE, WAIT, a {{ comment }} or ENDPROGRAM"
        )
    where, closed = _context(parser, text, pos)
    if where and not closed:
        if "SEMICOLON" in expected and (str(token) in _CONTEXT or token.type == "COMMENT"):
            return line, column, f"expected ';' after {where}, got {got}"
        return line, column, f"expected {_expected(parser, expected)} in {where}, got {got}"
    return line, column, f"expected {_expected(parser, expected)}, got {got}"


# --------------------------------------------------------------------------------------------------
# tree -> Program


class _Builder:
    def __init__(self, file: str | Path | None) -> None:
        self.file = file
        self.lines: list[int] = []

    def error(self, line: int | None, column: int | None, problem: str) -> ProgramError:
        return ProgramError(self.file, f"line {line}, column {column}", problem)

    def number(self, token: Token) -> float:
        if not _PLAIN_NUMBER.fullmatch(str(token)):
            raise self.error(
                token.line, token.column,
                f"bad number '{token}': write digits with an optional '.' and decimals, e.g. 12.500",
            )
        return float(token)

    def whole(self, token: Token, low: int = 1) -> int:
        if not re.fullmatch(r"[0-9]+", str(token)) or int(str(token)) < low:
            raise self.error(token.line, token.column, f"expected a whole number from {low}, got '{token}'")
        return int(str(token))

    def tokens(self, tree: Tree[Token], kind: str) -> list[Token]:
        return [c for c in tree.children if isinstance(c, Token) and c.type == kind]

    def subtree(self, tree: Tree[Token], name: str) -> Tree[Token]:
        return next(c for c in tree.children if isinstance(c, Tree) and c.data == name)

    def triple(self, tree: Tree[Token]) -> tuple[float, ...]:
        return tuple(self.number(t) for t in self.tokens(tree, "NUMBER"))

    def check(self, tree: Tree[Token], item: Header | FrameDef | Instruction, n_joints: int) -> None:
        problem = find_problem(item, n_joints)
        if problem:
            raise self.error(tree.meta.line, tree.meta.column, problem)

    def program(self, tree: Tree[Token]) -> Program:
        name = self.tokens(tree, "IDENT")[0]
        header = self.header(self.subtree(tree, "header"))
        for comment in self.tokens(tree, "COMMENT"):
            text = str(comment)[1:-1].strip()
            match = _PROVENANCE.match(text)
            if match:
                sha = "" if match["sha"] == "unknown" else match["sha"]
                header = dataclasses.replace(header, generator=match["gen"], cell_sha256=sha)
            match = _STAMP.match(text)
            if match:
                header = dataclasses.replace(header, stamp=match["stamp"])
        n_joints = len(header.joints)
        frames = self.frames(self.subtree(tree, "frames"), n_joints)
        try:
            tool, base = lin_frames(tuple(frames))
        except ExportError as exc:
            raise self.error(tree.meta.line, tree.meta.column, str(exc)) from None
        instructions: list[Instruction] = []
        for child in tree.children:
            if isinstance(child, Tree) and child.data not in ("header", "frames"):
                ins = self.statement(child)
                if isinstance(ins, LinMove):
                    ins = dataclasses.replace(ins, tool=tool, base=base)
                self.check(child, ins, n_joints)
                instructions.append(ins)
                self.lines.append(child.meta.line)
        return Program(str(name), header, tuple(frames), tuple(instructions))

    def header(self, tree: Tree[Token]) -> Header:
        idents = self.tokens(tree, "IDENT")
        cell, robot, *joints, tool = idents
        seen: set[str] = set()
        for joint in joints:
            if str(joint) in seen:
                raise self.error(joint.line, joint.column, f"joint {str(joint)!r} is listed twice in AXES")
            seen.add(str(joint))
        (cycle,) = self.tokens(tree, "NUMBER")
        header = Header(str(cell), str(robot), str(tool), self.number(cycle), tuple(str(j) for j in joints))
        self.check(tree, header, len(joints))
        return header

    def frames(self, tree: Tree[Token], n_joints: int) -> list[FrameDef]:
        frames: list[FrameDef] = []
        for node in tree.children:
            if not (isinstance(node, Tree) and node.data == "frame"):
                continue
            (name,) = self.tokens(node, "IDENT")
            if any(f.name == str(name) for f in frames):
                raise self.error(name.line, name.column, f"frame {str(name)!r} is already defined")
            kind: Literal["tool", "base"] = \
                "tool" if any(isinstance(c, Tree) and c.data == "tool_kind" for c in node.children) else "base"
            number = [t for t in node.children if isinstance(t, Token) and t.type == "NUMBER"]
            frame = FrameDef(
                str(name), kind, self.triple(self.subtree(node, "pos")), self.triple(self.subtree(node, "ori")),
                self.whole(number[0], 0) if number else 0,
            )
            self.check(node, frame, n_joints)
            frames.append(frame)
        return frames

    def note(self, tree: Tree[Token]) -> str:
        comments = self.tokens(tree, "COMMENT")
        return str(comments[0])[1:-1].strip() if comments else ""

    def statement(self, tree: Tree[Token]) -> Instruction:
        fly = [c for c in tree.children if isinstance(c, Tree) and c.data == "flyby"]
        flyby = self.number(self.tokens(fly[0], "NUMBER")[0]) if fly else 0.0
        if tree.data == "ptp":
            values = [self.number(t) for t in self.tokens(tree, "NUMBER")]
            return PtpMove(tuple(values[:-2]), values[-2], values[-1], flyby, self.note(tree))
        if tree.data == "lin":
            (config,) = self.tokens(tree, "STRING")
            speed, *accel = self.tokens(tree, "NUMBER")
            return LinMove(
                self.triple(self.subtree(tree, "pos")), self.triple(self.subtree(tree, "ori")),
                str(config)[1:-1], self.number(speed), flyby, self.note(tree),
                accel=self.number(accel[0]) if accel else 1.0,
            )
        if tree.data == "spot":
            name, seam = self.tokens(tree, "IDENT")
            numbers = self.tokens(tree, "NUMBER")
            gun, schedule = (self.whole(t) for t in numbers[1:]) if len(numbers) == 3 else (1, 1)
            return Spot(str(name), str(seam), self.number(numbers[0]), gun, schedule)
        if tree.data == "gripper":
            name, seam = self.tokens(tree, "IDENT")
            (seconds,) = self.tokens(tree, "NUMBER")
            action: Literal["grip", "release"] = "grip" if self.tokens(tree, "GRIP") else "release"
            return Gripper(action, str(name), str(seam), self.number(seconds))
        if tree.data == "wait":
            (seconds,) = self.tokens(tree, "NUMBER")
            return Wait(self.number(seconds))
        if tree.data == "wait_for":
            (signal,) = self.tokens(tree, "IDENT")
            number = self.tokens(tree, "NUMBER")
            return WaitFor(str(signal), self.whole(number[0], 0) if number else None)
        return Comment(self.note(tree))


# ================================================================================== as a dialect


def adapt(planned: PlannedProgram, robot: RobotModel) -> Program:
    """SRCL states the planned program as it is."""
    return planned.program


def write(program: Program, robot: RobotModel) -> dict[str, str]:
    return {".srcl": write_program(program)}


def parse(texts: dict[str, str], file: str, robot: RobotModel) -> Parsed:
    program, lines = parse_with_lines(texts[".srcl"], file)
    return Parsed(program, lines, robot.controller.brand)
