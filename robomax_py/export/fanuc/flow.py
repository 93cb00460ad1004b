"""FANUC TP's routines and control flow: labels, jumps and calls, and what each statement does to control."""

from __future__ import annotations

import re

from robomax_py.export.fanuc.grammar import _statements
from robomax_py.export.fanuc.write import ROUTINES
from robomax_py.export.flow import Flow, Routine, Statement, not_resting

# ------------------------------------------------------------------ control flow

# What TP statements do to the flow: `END` ends the program (a called program returns to its
# caller), `ABORT` ends it, `PAUSE` stops it until it is started again, `JMP LBL[n]` continues at
# `LBL[n]`, `CALL NAME[(args)]` runs the program NAME (public TP grammar JTremblayAGT/fanuc-lsp@
# b0e9a1ea TPLangParser/TPLang/Instructions/TpBranchingInstruction.cs:8-57 (labels, JMP, CALL,
# IF, SELECT, IF ... THEN / ELSE / ENDIF, END) and TpProgControlInstruction.cs:20-26 (PAUSE,
# ABORT); RoboDK's R-30iA post writes `PAUSE ;` to "Pause the robot program" and
# `WAIT ... TIMEOUT, LBL[n]` / `LBL[n] ;`, ros-industrial-attic/robodk_postprocessors@d7e6c1c0
# Fanuc_R30iA.py:405-410, 474-479). A pause ends the verified cycle (flow.py).
_LBL = re.compile(r"^LBL\[\s*([0-9]+)\s*(?::[^\]]*)?\]$", re.IGNORECASE)
_JMP = re.compile(r"^JMP\s+LBL\[\s*([0-9]+)\s*(?::[^\]]*)?\]$", re.IGNORECASE)
_CALL_ANY = re.compile(r"^CALL\s+([A-Za-z_][A-Za-z0-9_]*)\s*(\((.*)\))?$", re.IGNORECASE)
# Speeds of a linear move in other units than mm/sec, as mm/s per unit.
_LINEAR_UNITS = {"mm/sec": 1.0, "cm/min": 10.0 / 60.0, "inch/min": 25.4 / 60.0}


def _classify(st: Statement) -> Flow:
    """What a TP statement does to the flow (`flow.Flow`)."""
    text = st.text
    if not text or text.startswith("!"):
        return Flow()
    word = text.split()[0].upper()
    if text.upper() == "END":
        return Flow("end", "END")
    if text.upper() == "ABORT":
        return Flow("end", "ABORT", scope="program")
    if text.upper() == "PAUSE":
        return Flow("end", "PAUSE", scope="program", pause=True)
    jump = _JMP.match(text)
    if jump:
        return Flow("goto", jump.group(1))
    label = _LBL.match(text)
    if label:
        return Flow("label", label.group(1))
    if re.match(r"^IF\b.*\bTHEN$", text, re.IGNORECASE) or word == "FOR":
        return Flow("open")
    if word in ("ENDIF", "ENDFOR"):
        return Flow("close")
    if word == "ELSE":
        return Flow()
    if word in ("IF", "SELECT") or text.startswith("=") or re.match(r"^ELSE\s*,", text, re.IGNORECASE):
        return Flow("unsupported", why="a conditional jump or call")
    if re.search(r"\bTIMEOUT\s*,\s*LBL\[", text, re.IGNORECASE):
        return Flow("unsupported", why="a wait that jumps when it times out")
    if word == "RUN":
        return Flow("unsupported", why="a program run beside this one")
    override = re.match(r"^OVERRIDE\s*=\s*([0-9.]+)\s*%$", text, re.IGNORECASE)
    if override:
        return Flow() if float(override.group(1)) == 100.0 else Flow("unsupported", why="a speed override")
    call = _CALL_ANY.match(text)
    if call and call.group(1).upper() not in ROUTINES:
        return Flow("call", call.group(1).upper(), arguments=bool((call.group(3) or "").strip()))
    return Flow()


def _program(text: str, source: str) -> Routine | None:
    """A TP program text as a routine: its /PROG name and its /MN statements."""
    lines = text.splitlines()
    head = next((re.match(r"^/PROG\s+(\S+)", ln) for ln in lines if ln.startswith("/PROG")), None)
    if head is None:
        return None
    mn = next((i for i, ln in enumerate(lines) if ln.strip() == "/MN"), len(lines))
    pos = next((i for i, ln in enumerate(lines) if ln.strip() == "/POS"), len(lines))
    body = tuple(Statement(line, stmt, source=source) for line, stmt in _statements(lines, mn + 1, pos))
    return Routine(head.group(1).upper(), body, (), source)


def _not_resting(routine: Routine) -> list[tuple[int, str, str]]:
    """(line, statement, why) of what a default routine (SPOT_WELD, GRIP, RELEASE) does besides
    resting for its second argument: remarks and one `WAIT AR[2]` (the routine `write` gives)."""
    return not_resting(routine, lambda text: bool(re.fullmatch(r"WAIT\s+AR\[\s*2\s*\]", text, re.IGNORECASE)),
                       "WAIT AR[2]", 0, skip=lambda text: text.startswith("!"))
