"""URScript read, line by line: the statement grammar, the calls the reader knows, and a line's
statement, comment and numbers."""

from __future__ import annotations

from functools import lru_cache

from lark import Lark

from robomax_py.export.dialect import tree_numbers
from robomax_py.export.parsers import lalr_parser

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

_CALLS = ("movej", "movel", "set_tcp", "sleep", "spot_weld", "grip", "release", "wait_for_signal",
          "set_standard_digital_out")
_UNSIMULATED = ("movep", "movec", "servoj", "servoc", "speedj", "speedl", "move_path", "movej_pose")


@lru_cache(maxsize=1)
def _parser() -> Lark:
    return lalr_parser("urscript", _GRAMMAR, lexer="contextual")


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
