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

from robomax_py.export.srcl.grammar import GRAMMAR
from robomax_py.export.srcl.read import parse, parse_program, parse_with_lines
from robomax_py.export.srcl.write import DIALECT, RESERVED, adapt, write, write_program
from robomax_py.export.srcl.write import lin_frames as lin_frames

__all__ = ["DIALECT", "GRAMMAR", "RESERVED", "adapt", "parse", "parse_program", "parse_with_lines", "write",
           "write_program"]
