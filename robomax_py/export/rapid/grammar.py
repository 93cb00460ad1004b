"""RAPID read, statement by statement: the grammar, the patterns the reader sorts statements by, and
the statements of a module's text."""

from __future__ import annotations

import re
from functools import lru_cache

from lark import Lark

from robomax_py.export.parsers import lalr_parser

# ================================================================================== reading

_GRAMMAR = r"""
?start: decl | move | velset | accset | waittime | waitdi | setdo | setreset | weld | gripper
decl: ("CONST"i | "PERS"i | "VAR"i) NAME NAME (":=" value)?
move: MOVE arg ("," arg | opt)*
velset: "VelSet"i NUMBER "," NUMBER
accset: "AccSet"i NUMBER "," NUMBER ("\\" NAME ":=" NUMBER)?
waittime: "WaitTime"i ("\\" NAME ",")? NUMBER
waitdi: "WaitDI"i NAME "," NUMBER ("\\" NAME (":=" value)?)*
setdo: "SetDO"i NAME "," NUMBER
setreset: SETRESET NAME
weld: "spot_weld"i NUMBER "," NUMBER
gripper: GRIPPER NUMBER "," NUMBER
?arg: value | opt
opt: "\\" NAME (":=" value)?
?value: NUMBER | NAME | STRING | list | BOOL
list: "[" [value ("," value)*] "]"
MOVE.2: /(MoveAbsJ|MoveL|SpotL)\b/i
GRIPPER.2: /(grip|release)\b/i
SETRESET.2: /(Set|Reset)\b/i
BOOL.2: /(TRUE|FALSE)\b/i
NAME: /[A-Za-z_][A-Za-z0-9_]*/
STRING: /"[^"]*"/
NUMBER: /[+-]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][+-]?[0-9]+)?/
%ignore /[ \t\r\n]+/
"""

_UNSIMULATED = re.compile(r"^(MoveJ|MoveC|MoveLDO|MoveJDO|MoveLSync|MoveJSync|MoveCSync|MoveExtJ|SearchL|SearchC|"
                          r"TriggL|TriggJ|TriggC|MoveLRel|MoveAbsJDO|MoveAbsJSync|SpotJ|SpotML|SpotMJ)\b", re.IGNORECASE)
_KNOWN = re.compile(r"^(MoveAbsJ|MoveL|SpotL|VelSet|AccSet|WaitTime|WaitDI|SetDO|Set|Reset|spot_weld|grip|release)\b",
                    re.IGNORECASE)
# SetDO with \SDelay (set later, in the background) or \Sync (waits for the output's acknowledgement):
# not simulated.
_TIMED_SET = re.compile(r"^SetDO\s*\\", re.IGNORECASE)
# Lines that end a statement without ';': routine heads and ends, a routine's handler sections,
# and control-flow lines.
_HEADLINE = re.compile(r"^(MODULE|ENDMODULE|(LOCAL\s+)?PROC|ENDPROC|(LOCAL\s+)?FUNC|ENDFUNC|(LOCAL\s+)?TRAP|ENDTRAP|"
                       r"ERROR|BACKWARD|UNDO)\b", re.IGNORECASE)
# A label `name:` opening a line (RAPID reference, GOTO: "GOTO next; ... next:"); a statement may
# follow it on the same line. CASE ...: and DEFAULT: open a TEST's branches instead.
_LABEL = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*:(?!=)\s*(.*)$")
_OPENS = re.compile(r"\b(THEN|DO)\s*$|^(TEST\b.*|ELSE|DEFAULT\s*:|CASE\b.*:)\s*$", re.IGNORECASE)
_CLOSES = re.compile(r"^(ENDIF|ENDWHILE|ENDFOR|ENDTEST|ELSE)\s*$", re.IGNORECASE)
# The declarations the motion depends on (spotdata: a package weld's schedule); others (num,
# confdata, syncident, arrays ...) are ignored.
_MOTION_DATA = re.compile(r"^((LOCAL|TASK)\s+)*(CONST|PERS|VAR)\s+(robtarget|jointtarget|speeddata|zonedata|tooldata|wobjdata|spotdata)\b",
                          re.IGNORECASE)
_PREDEFINED_SPEED = re.compile(r"^v([0-9]+)$", re.IGNORECASE)
_PREDEFINED_ZONE = re.compile(r"^z([0-9]+)$", re.IGNORECASE)
# The spot option's gundata of gun n (`gun_data`); another name leaves the gun unknown (0).
_GUN_DATA = re.compile(r"^gun([0-9]+)$", re.IGNORECASE)


@lru_cache(maxsize=1)
def _parser() -> Lark:
    return lalr_parser("rapid", _GRAMMAR, lexer="contextual")


def _statements(text: str) -> list[tuple[int, str, str]]:
    """(line, statement, comment) for every ';'-terminated statement; comment lines as ("", text)."""
    out: list[tuple[int, str, str]] = []
    pending: list[str] = []
    start = 0
    for number, raw in enumerate(text.splitlines(), start=1):
        if re.match(r"^\s*(%%%|VERSION:|LANGUAGE:)", raw):
            continue
        code, comment = _split_comment(raw)
        if not code.strip():
            if comment is not None and not pending:
                out.append((number, "", comment))
            continue
        label = _LABEL.match(code) if not pending else None
        if label and label.group(1).upper() not in ("DEFAULT", "CASE"):
            # A label is a statement of its own: the statement after it is not part of it.
            out.append((number, f"{label.group(1)}:", comment or "" if not label.group(2).strip() else ""))
            code = label.group(2)
            if not code.strip():
                continue
        if not pending:
            start = number
        pending.append(code)
        joined = " ".join(pending).strip()
        if joined.endswith(";") or _HEADLINE.match(joined) or _OPENS.search(joined) or _CLOSES.match(joined):
            out.append((start, joined.rstrip(";").strip(), comment or ""))
            pending = []
    return out


def _split_comment(raw: str) -> tuple[str, str | None]:
    in_string = False
    for i, c in enumerate(raw):
        if c == '"':
            in_string = not in_string
        elif c == "!" and not in_string:
            return raw[:i], raw[i + 1:].strip()
    return raw, None
