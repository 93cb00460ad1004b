"""SRCL read: what a syntax error says (where, what was expected, what was found)."""

from __future__ import annotations

from lark import Lark, Token
from lark.exceptions import (
    UnexpectedCharacters,
    UnexpectedEOF,
    UnexpectedInput,
    UnexpectedToken,
)
from lark.lexer import PatternStr

from robomax_py.export.srcl.grammar import _CONTEXT, _NAMED, _PLAIN_NUMBER
from robomax_py.export.srcl.write import RESERVED

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
            f"unknown statement {got}{hint}; expected MOVE, SPOT, GRIP, RELEASE, WAIT, SET, a {{ comment }} or ENDPROGRAM"
        )
    where, closed = _context(parser, text, pos)
    if where and not closed:
        if "SEMICOLON" in expected and (str(token) in _CONTEXT or token.type == "COMMENT"):
            return line, column, f"expected ';' after {where}, got {got}"
        return line, column, f"expected {_expected(parser, expected)} in {where}, got {got}"
    return line, column, f"expected {_expected(parser, expected)}, got {got}"
