"""SRCL read: `parse_program` and `parse_with_lines`, and SRCL's `parse` as a dialect."""

from __future__ import annotations

from pathlib import Path

from lark import Token, Tree
from lark.exceptions import UnexpectedInput

from robomax_py.errors import ProgramError
from robomax_py.export.dialect import Parsed
from robomax_py.export.srcl.build import _Builder
from robomax_py.export.srcl.grammar import _parser
from robomax_py.export.srcl.syntax import _describe
from robomax_py.program import Program
from robomax_py.robot import RobotModel


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
    return _Builder(file).program(_tree(text, file))


def parse_with_lines(text: str, file: str | Path | None = None) -> tuple[Program, tuple[int, ...]]:
    """`parse_program`, and the line of each instruction."""
    builder = _Builder(file)
    program = builder.program(_tree(text, file))
    return program, tuple(builder.lines)


def _tree(text: str, file: str | Path | None) -> Tree[Token]:
    """The parse tree of an SRCL text; ProgramError with key "line L, column C" when it does not parse."""
    parser = _parser()
    try:
        return parser.parse(text)
    except UnexpectedInput as exc:
        line, column, problem = _describe(parser, text, exc)
        raise ProgramError(file, f"line {line}, column {column}", problem) from None


def parse(texts: dict[str, str], file: str, robot: RobotModel) -> Parsed:
    program, lines = parse_with_lines(texts[".srcl"], file)
    return Parsed(program, lines, robot.controller.brand)
