"""KRL read, line by line: the statement grammar and the patterns the reader sorts lines by."""

from __future__ import annotations

import re
from functools import lru_cache

from lark import Lark

from robomax_py.export.krl.write import _DATA_TYPES
from robomax_py.export.parsers import lalr_parser

# ================================================================================== reading

_GRAMMAR = r"""
?start: motion | assign | frame_data | weld | gripper | wait_sec | wait_for | signal | decl | data_act | bas
      | userspot
motion: MOTION target APPROX*
target: NAME | aggregate
aggregate: "{" (NAME ":")? [field ("," field)*] "}"
field: NAME ("[" "]")? value
?value: NUMBER | BITS | NAME | ENUM | STRING
assign: SYSVAR ("." NAME)? ("[" NUMBER "]")? "=" (NUMBER | aggregate | linked | indexed | NAME)
indexed: NAME "[" NUMBER "]"
linked: SYSVAR [":" aggregate]
frame_data: NAME "[" NUMBER "]" "=" (aggregate | linked)
weld: "spot_weld"i "(" NUMBER "," NUMBER ")"
gripper: GRIPPER "(" NUMBER "," NUMBER ")"
wait_sec: "WAIT"i "SEC"i NUMBER
wait_for: "WAIT"i "FOR"i (NAME | SYSVAR "[" NUMBER "]") ("==" NAME)?
signal: "SIGNAL"i NAME SYSVAR "[" NUMBER "]"
decl: "DECL"i NAME NAME "=" aggregate
data_act: DATA_ACT "=" NAME
bas: "BAS"i "(" ENUM ["," bas_arg] ")"
bas_arg: NUMBER | NAME ("." NAME)?
userspot: "USERSPOT"i "(" ENUM ["," NAME] ")"

MOTION.2: /(PTP|LIN)\b/i
GRIPPER.2: /(grip|release)\b/i
APPROX.2: /C_(DIS|PTP|VEL|ORI)\b/i
DATA_ACT.2: /(PDAT|LDAT|FDAT)_ACT\b/i
SYSVAR: /\$[A-Za-z_][A-Za-z0-9_]*/
NAME: /[A-Za-z_][A-Za-z0-9_$]*/
ENUM: /#[A-Za-z_][A-Za-z0-9_]*/
STRING: /"[^"]*"/
BITS: /'[Bb][01]+'/
NUMBER: /[+-]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][+-]?[0-9]+)?/
%ignore /[ \t]+/
"""

# Motions KRL has that this reader does not simulate: a program with one is not verified clean.
_UNSIMULATED = re.compile(r"^(CIRC|SPTP|SLIN|SCIRC|PTP_REL|LIN_REL|CIRC_REL|SPTP_REL|SLIN_REL|SPLINE|PTP_SPLINE|RSI_MOVECORR)\b",
                          re.IGNORECASE)
_KNOWN = re.compile(r"^(PTP|LIN|\$|spot_weld\s*\(|(grip|release)\s*\(|WAIT\s+(SEC|FOR)\b|SIGNAL\b|"
                    rf"DECL\s+({'|'.join(_DATA_TYPES)})\b|(TOOL|BASE)_DATA\s*\[|(PDAT|LDAT|FDAT)_ACT\b|BAS\s*\(|"
                    r"USERSPOT\s*\()", re.IGNORECASE)
# The statements of a spline block (KSS 8.x "Spline motion type"): read by `read._Reader.on_spline`.
_SPLINE = re.compile(r"^(SPLINE|ENDSPLINE|SPL|SLIN)\b", re.IGNORECASE)
# The segment form robomax writes and reads: a named point, at most the segment's own CP speed.
_SPLINE_SEGMENT = re.compile(r"^(SPL|SLIN)\s+([A-Za-z_][A-Za-z0-9_$]*)(\s+WITH\s+\$VEL\.CP\s*=\s*"
                             r"([+-]?([0-9]+\.?[0-9]*|\.[0-9]+)))?$", re.IGNORECASE)
# A motion to a named point or an aggregate; anything else (an array element, a system variable, an
# expression) is not simulated.
_PLAIN_MOTION = re.compile(r"^(PTP|LIN)\s+([A-Za-z_][A-Za-z0-9_$]*|\{.*\})(\s+C_(DIS|PTP|VEL|ORI))*$", re.IGNORECASE)
_PLAIN_WAIT_FOR = re.compile(r"^WAIT\s+FOR\s+([A-Za-z_]\w*|\$IN\s*\[\s*\d+\s*\])(\s*==\s*TRUE)?$", re.IGNORECASE)
# The template's stop-message interrupt (BASISTECH INI): no effect on the motion.
_TEMPLATE = re.compile(r"^((GLOBAL\s+)?INTERRUPT\s+DECL\s+3\s+WHEN\s+\$STOPMESS\s*==\s*TRUE\s+DO\s+IR_STOPM\s*\(\s*\)|"
                       r"INTERRUPT\s+ON\s+3)$", re.IGNORECASE)

_BLOCK_START = re.compile(r"^(IF\b.*\bTHEN|LOOP|WHILE\b.*|FOR\b.*|REPEAT|SWITCH\b.*)$", re.IGNORECASE)
_BLOCK_END = re.compile(r"^(ENDIF|ENDLOOP|ENDWHILE|ENDFOR|UNTIL\b.*|ENDSWITCH)$", re.IGNORECASE)
# An inline form's fold: `;FOLD PTP P1 ... ;%{PE}%R 8.3.48,...,%P 1:PTP, 2:P1, 3:C_DIS, 5:100, 7:PDAT1`.
_MOTION_FOLD = re.compile(r"^;FOLD\s+(PTP|LIN)\b.*;%\{PE\}.*%P\s+(.*)$", re.IGNORECASE)


@lru_cache(maxsize=1)
def _parser() -> Lark:
    return lalr_parser("krl", _GRAMMAR, lexer="contextual")


def _statement(text: str) -> tuple[str, str]:
    """A KRL line -> (statement, comment): the comment is what follows the first ';' outside
    quotes ('B010' literals, "strings")."""
    quote = ""
    for i, c in enumerate(text):
        if c in "'\"":
            quote = "" if quote == c else (quote or c)
        elif c == ";" and not quote:
            return text[:i].strip(), text[i + 1:].strip()
    return text.strip(), ""
