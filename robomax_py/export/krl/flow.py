"""KRL's routines and control flow: DEF / DEFFCT routines and what each statement does to control."""

from __future__ import annotations

import re
from collections.abc import Callable

from robomax_py.export.flow import Flow, Routine, Statement, not_resting
from robomax_py.export.krl.grammar import (
    _BLOCK_END,
    _BLOCK_START,
    _TEMPLATE,
    _statement,
)

# ------------------------------------------------------------------ control flow

# Routines and statements (KUKA, KSS 8.3 Operating and Programming Instructions for System
# Integrators, "Program execution control": GOTO to a jump label `name:` in the same routine,
# HALT, RETURN; as RoboDK's KRC4 post writes them, ros-industrial-attic/robodk_postprocessors@
# d7e6c1c0 KUKA_KRC4.py:281-286 `HALT`, 345 and 354 `START_TIMER:` / `GOTO START_TIMER`). HALT stops
# the program until it is started again (flow.py: a pause ends the verified cycle).
_DEF_HEAD = re.compile(r"^(?:GLOBAL\s+)?DEF\s+([A-Za-z_][A-Za-z0-9_]*)\s*\((.*)\)\s*$", re.IGNORECASE)
_DEFFCT_HEAD = re.compile(r"^(?:GLOBAL\s+)?DEFFCT\s+\w+(?:\s*\[[^\]]*\])?\s+([A-Za-z_][A-Za-z0-9_]*)\s*\((.*)\)\s*$",
                          re.IGNORECASE)
_ROUTINE_END = re.compile(r"^(END|ENDFCT)$", re.IGNORECASE)
# Statements of call form that are not calls of a routine: BAS.SRC, the spot package's user
# routine, the default weld and gripper routines (a weld or gripper action, `_not_resting` checks
# their bodies) and PULSE (an output pulse).
_STATEMENT_CALLS = frozenset({"bas", "userspot", "spot_weld", "grip", "release", "pulse"})
# robomax's default routines that rest for their second argument: a call of one is a weld or a
# gripper action; the reader takes it for that only while its body does nothing else.
_REST_ROUTINES = frozenset({"spot_weld", "grip", "release"})
_INTERRUPT_DECL = re.compile(r"^(GLOBAL\s+)?INTERRUPT\s+DECL\b", re.IGNORECASE)


def _routines(text: str, source: str) -> list[Routine]:
    """The DEF / DEFFCT routines of a .src text, in order (a routine missing its END runs to the
    end of the text)."""
    out: list[Routine] = []
    head: tuple[str, tuple[str, ...]] | None = None
    body: list[Statement] = []
    for number, raw in enumerate(text.splitlines(), start=1):
        stmt, comment = _statement(raw)
        match = _DEF_HEAD.match(stmt) or _DEFFCT_HEAD.match(stmt)
        if match and head is None:
            params = tuple(p.split(":")[0].strip() for p in match.group(2).split(",") if p.strip())
            head, body = (match.group(1), params), []
            continue
        if head is None or stmt.startswith("&"):
            continue
        if _ROUTINE_END.match(stmt):
            out.append(Routine(head[0], tuple(body), head[1], source))
            head = None
            continue
        body.append(Statement(number, stmt, comment, raw, source))
    if head is not None:
        out.append(Routine(head[0], tuple(body), head[1], source))
    return out


def _classifier(defined: set[str]) -> Callable[[Statement], Flow]:
    """What a KRL statement does to the flow (`flow.Flow`); `defined`: the routines the texts
    define (lower case), whose calls in expressions (a DEFFCT's) run their bodies."""
    def classify(st: Statement) -> Flow:
        text = st.text
        if not text:
            return Flow()
        if re.fullmatch(r"RETURN\b.*", text, re.IGNORECASE):
            return Flow("end", "RETURN")
        if re.fullmatch(r"HALT", text, re.IGNORECASE):
            return Flow("end", "HALT", scope="program", pause=True)
        if re.fullmatch(r"EXIT", text, re.IGNORECASE):
            return Flow("unsupported", why="EXIT leaves a loop")
        if re.fullmatch(r"(RESUME|BRAKE(\s+F)?)", text, re.IGNORECASE):
            return Flow("unsupported", why="an interrupt routine's statement")
        jump = re.fullmatch(r"GOTO\s+([A-Za-z_][A-Za-z0-9_]*)", text, re.IGNORECASE)
        if jump:
            return Flow("goto", jump.group(1))
        label = re.fullmatch(r"([A-Za-z_][A-Za-z0-9_]*)\s*:", text)
        if label:
            return Flow("label", label.group(1))
        if _BLOCK_START.match(text):
            return Flow("open", loop=bool(re.match(r"(LOOP|WHILE|FOR|REPEAT)\b", text, re.IGNORECASE)))
        if _BLOCK_END.match(text):
            return Flow("close")
        if _INTERRUPT_DECL.match(text) and not _TEMPLATE.match(text):
            return Flow("unsupported", why="an interrupt: its routine runs whenever its condition holds")
        if re.match(r"^TRIGGER\b", text, re.IGNORECASE) and re.search(r"\bDO\s+[A-Za-z_]\w*\s*\(", text, re.IGNORECASE):
            return Flow("unsupported", why="a trigger calls a routine along the path")
        call = re.fullmatch(r"([A-Za-z_][A-Za-z0-9_]*)\s*\((.*)\)", text)
        if call:
            if call.group(1).lower() in _STATEMENT_CALLS:
                return Flow()
            return Flow("call", call.group(1), arguments=bool(call.group(2).strip()))
        assign = re.match(r"^[$A-Za-z_][\w$.\[\], ]*=(?!=)(.*)$", text)
        if assign:
            for name, args in re.findall(r"([A-Za-z_][A-Za-z0-9_]*)\s*\(([^()]*)\)", assign.group(1)):
                if name.lower() in defined:
                    return Flow("call", name, arguments=bool(args.strip()))
        return Flow()
    return classify


def _not_resting(routine: Routine) -> list[tuple[int, str, str]]:
    """(line, statement, why) of what a default routine (spot_weld, grip, release) does besides
    resting for its second parameter: its declarations, comments and one `WAIT SEC <it>` (the
    routine `write` gives). A call of it is then a weld or a gripper action of that time;
    anything else in it (a motion, another time, another unit) is reported."""
    time = routine.params[1] if len(routine.params) == 2 else None

    def rests(text: str) -> bool:
        wait = re.fullmatch(r"WAIT\s+SEC\s+([A-Za-z_]\w*)", text, re.IGNORECASE)
        return bool(wait and time is not None and wait.group(1).lower() == time.lower())

    def declaration(text: str) -> bool:
        return bool(re.fullmatch(r"(DECL\s+)?(INT|REAL)\s+[A-Za-z_]\w*(\s*,\s*[A-Za-z_]\w*)*", text, re.IGNORECASE))

    return not_resting(routine, rests, "WAIT SEC of its second parameter",
                       routine.body[0].line - 1 if routine.body else 0, skip=declaration)
