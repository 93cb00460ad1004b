"""SRCL's grammar (docs/srcl.md) and its parser."""

from __future__ import annotations

import re
from functools import lru_cache

from lark import Lark

from robomax_py.export.parsers import lalr_parser

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

_stmt: ptp | lin | spl | slin | spot | gripper | wait | wait_for | set_signal | note
ptp: "MOVE" "PTP" "AXIS" "(" NUMBER ("," NUMBER)* ")" "SPEED" NUMBER "ACCEL" NUMBER flyby? COMMENT? ";"
lin: "MOVE" "LIN" pos ori "CONFIG" STRING "SPEED" NUMBER _MM_S ("ACCEL" NUMBER)? flyby? COMMENT? ";"
spl: "MOVE" "SPL" pos ori "CONFIG" STRING "SPEED" NUMBER _MM_S ("ACCEL" NUMBER)? COMMENT? ";"
slin: "MOVE" "SLIN" pos ori "CONFIG" STRING "SPEED" NUMBER _MM_S ("ACCEL" NUMBER)? COMMENT? ";"
flyby: FLYBY NUMBER
spot: "SPOT" IDENT "SEAM" IDENT "TIME" NUMBER "SEC" ("GUN" NUMBER "SCHEDULE" NUMBER)? ";"
gripper: (GRIP | RELEASE) IDENT "SEAM" IDENT "TIME" NUMBER "SEC" ";"
wait: "WAIT" NUMBER "SEC" ";"
wait_for: "WAIT" "FOR" IDENT ("INPUT" NUMBER)? ";"
set_signal: "SET" IDENT ("OUTPUT" NUMBER)? (set_on | set_off) ";"
set_on: "TRUE"
set_off: "FALSE"
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
    "GRIP": "GRIP statement", "RELEASE": "RELEASE statement", "SET": "SET statement", "ENDPROGRAM": "ENDPROGRAM",
}
_NAMED = {
    "IDENT": "a name", "NUMBER": "a number", "STRING": "a quoted string", "COMMENT": "a comment",
    "FLYBY": "FLYBY", "$END": "end of file",
}


@lru_cache(maxsize=1)
def _parser() -> Lark:
    return lalr_parser("srcl", GRAMMAR, lexer="basic", propagate_positions=True, maybe_placeholders=False)
