"""RAPID's routines and control flow: PROCs and what each statement does to control."""

from __future__ import annotations

import re
from collections.abc import Callable

from robomax_py.export.flow import Flow, Routine, Statement, not_resting
from robomax_py.export.rapid.grammar import (
    _KNOWN,
    _MOTION_DATA,
    _UNSIMULATED,
    _statements,
)

# ------------------------------------------------------------------ control flow

# What RAPID statements do to the flow (ABB, RAPID Reference Manual, instructions RETURN, EXIT,
# EXITCYCLE, Stop, Break, GOTO and the labels it jumps to; procedure calls "Name arg, ...;"; the
# handlers after ERROR / BACKWARD / UNDO run only on an error, a backward step or an undo). Stop
# and Break stop the program until it is started again (RoboDK's IRC5 post writes `STOP;` to
# "Pause the robot program", ros-industrial-attic/robodk_postprocessors@d7e6c1c0
# ABB_RAPID_IRC5.py:381-386); flow.py: a pause ends the verified cycle.
_PROC_HEAD = re.compile(r"^(?:LOCAL\s+)?PROC\s+([A-Za-z_][A-Za-z0-9_]*)\s*\((.*)\)\s*$", re.IGNORECASE)
_FUNC_HEAD = re.compile(r"^(?:LOCAL\s+)?(FUNC|TRAP)\s+(?:[A-Za-z_]\w*\s+)?([A-Za-z_][A-Za-z0-9_]*)\b", re.IGNORECASE)
_HANDLER = re.compile(r"^(ERROR|BACKWARD|UNDO)\b", re.IGNORECASE)
_BLOCK_OPEN = re.compile(r"^((IF|WHILE|FOR)\b.*\b(THEN|DO)|TEST\b.*)$", re.IGNORECASE)
_BLOCK_CLOSE = re.compile(r"^(ENDIF|ENDWHILE|ENDFOR|ENDTEST)$", re.IGNORECASE)
# Instructions that change no motion and no flow: outputs, FlexPendant text, counters and clocks,
# configuration and singularity handling (the lines keep their configuration in robomax's
# rebuild, which checks it), the gripped load, the trigger data TriggL uses (TriggL itself is not
# simulated).
_INERT = frozenset(s.lower() for s in (
    "SetDO", "SetAO", "SetGO", "Set", "Reset", "PulseDO", "InvertDO", "TPWrite", "TPErase", "ErrWrite", "Incr", "Decr",
    "Add", "Clear", "ClkStart", "ClkStop", "ClkReset", "ConfJ", "ConfL", "SingArea", "GripLoad", "TriggIO",
    "TriggEquip", "TriggInt"))
# The default routines whose call is a weld or a gripper action (their bodies rest their time).
_REST_ROUTINES = frozenset({"spot_weld", "grip", "release"})


def _params(text: str) -> tuple[str, ...]:
    """A PROC's parameter names: `num n, num weld_time` -> ("n", "weld_time")."""
    return tuple(part.split()[-1].lstrip("\\") for part in re.split(r"[,|]", text) if part.split())


def _classifier(functions: set[str]) -> Callable[[Statement], Flow]:
    """What a RAPID statement does to the flow; `functions`: the FUNCs the texts define (lower
    case), whose calls in expressions run their bodies (not followed: reported)."""
    def classify(st: Statement) -> Flow:
        text = st.text
        if not text:
            return Flow()
        word = re.match(r"^%|^[A-Za-z_][A-Za-z0-9_]*", text)
        first = word.group(0).lower() if word else ""
        if first == "return":
            return Flow("end", "RETURN")
        if first in ("exit", "exitcycle"):
            return Flow("end", text, scope="program")
        if first in ("stop", "break"):
            return Flow("end", text, scope="program", pause=True)
        if first == "goto":
            target = re.fullmatch(r"GOTO\s+([A-Za-z_][A-Za-z0-9_]*)", text, re.IGNORECASE)
            return Flow("goto", target.group(1)) if target else Flow("unsupported", why="a jump to an expression")
        label = re.fullmatch(r"([A-Za-z_][A-Za-z0-9_]*):", text)
        if label:
            return Flow("label", label.group(1))
        if _BLOCK_OPEN.match(text):
            return Flow("open", loop=first in ("while", "for"))
        if _BLOCK_CLOSE.match(text):
            return Flow("close")
        if first == "if":
            return Flow("unsupported", why="a statement under a condition (IF without THEN)")
        if first in ("else", "elseif", "case", "default"):
            return Flow()
        if first in ("raise", "retry", "trynext", "callbyvar", "%", "connect", "waituntil", "stopmove", "startmove"):
            return Flow("unsupported", why={"connect": "an interrupt: its TRAP runs whenever its signal changes",
                                            "waituntil": "a wait for a condition",
                                            "stopmove": "the robot waits for StartMove",
                                            "startmove": "the robot waits for StartMove"}.get(
                                                first, "error handling or a call by name"))
        if _MOTION_DATA.match(text) or re.match(r"^((LOCAL|TASK)\s+)*(CONST|PERS|VAR)\b", text, re.IGNORECASE):
            return Flow()
        assign = re.match(r"^[A-Za-z_][\w.{}\[\], ]*:=(.*)$", text)
        if assign:
            for name in re.findall(r"([A-Za-z_][A-Za-z0-9_]*)\s*\(", assign.group(1)):
                if name.lower() in functions:
                    return Flow("unsupported", why=f"a call of {name}, a function of the program (not followed)")
            return Flow()
        if _KNOWN.match(text) or _UNSIMULATED.match(text) or first in _INERT:
            return Flow()
        rest = text[len(first):].strip()
        return Flow("call", word.group(0) if word else text, arguments=bool(rest))
    return classify


def _routines(text: str, source: str) -> list[Routine]:
    """The PROCs of a module text (a FUNC's or TRAP's body is not a procedure), each without its
    ERROR / BACKWARD / UNDO handler."""
    out: list[Routine] = []
    head: tuple[str, tuple[str, ...]] | None = None
    body: list[Statement] = []
    handler = False
    for line, stmt, comment in _statements(text):
        proc = _PROC_HEAD.match(stmt)
        if proc:
            head, body, handler = (proc.group(1), _params(proc.group(2))), [], False
            continue
        if re.match(r"^END(PROC|FUNC|TRAP)\b", stmt, re.IGNORECASE):
            if head is not None:
                out.append(Routine(head[0], tuple(body), head[1], source))
            head = None
            continue
        if head is None:
            continue
        if _HANDLER.match(stmt):
            handler = True
        if not handler:
            body.append(Statement(line, stmt, comment, source=source))
    return out


def _not_resting(routine: Routine) -> list[tuple[int, str, str]]:
    """(line, statement, why) of what a default routine (spot_weld, grip, release) does besides
    resting for its second parameter: comments and one `WaitTime [\\InPos,] <it>` (the routine
    `write` gives); anything else (a motion, another time, another unit) is reported."""
    time = routine.params[1] if len(routine.params) == 2 else None

    def rests(text: str) -> bool:
        wait = re.fullmatch(r"WaitTime\s+(\\InPos\s*,\s*)?([A-Za-z_]\w*)", text, re.IGNORECASE)
        return bool(wait and time is not None and wait.group(2).lower() == time.lower())

    return not_resting(routine, rests, "WaitTime of its second parameter", routine.body[0].line if routine.body else 0)
