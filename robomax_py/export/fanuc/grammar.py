"""FANUC TP read, line by line: the statement patterns, a program's positions and its numbered lines."""

from __future__ import annotations

import re

# ================================================================================== reading

_NUMBERED = re.compile(r"^\s*([0-9]+):(.*)$")
_CONTINUED = re.compile(r"^\s*:(.*)$")
_MOVE = re.compile(r"^(J|L)\s+P\[([0-9]+)(?::[^\]]*)?\]\s+([0-9.]+)\s*(%|mm/sec|cm/min|inch/min|deg/sec|sec|msec)\s+"
                   r"(FINE|CNT\s*([0-9]+))(.*)$", re.IGNORECASE)
_CALL = re.compile(r"^CALL\s+(SPOT_WELD|GRIP|RELEASE)\s*\(\s*([0-9]+)\s*,\s*([0-9]*\.?[0-9]+)\s*\)$", re.IGNORECASE)
_WAIT = re.compile(r"^WAIT\s+([0-9]*\.?[0-9]+)\s*\(sec\)$", re.IGNORECASE)
# DO[k:comment]=ON / OFF (FANUC TP operator's manual, digital I/O instructions).
_SET_DO = re.compile(r"^DO\[([0-9]+)(?::([^\]]*))?\]\s*=\s*(ON|OFF)$", re.IGNORECASE)
_WAIT_DI = re.compile(r"^WAIT\s+DI\[([0-9]+)(?::([^\]]*))?\]\s*=\s*ON$", re.IGNORECASE)
_PR_ELEMENT = re.compile(r"^PR\[([0-9]+),([1-6])\]\s*=\s*\(?\s*([+-]?[0-9]*\.?[0-9]+)\s*\)?$", re.IGNORECASE)
_FRAME_SET = re.compile(r"^(UTOOL|UFRAME)\[([0-9]+)\]\s*=\s*PR\[([0-9]+)\]$", re.IGNORECASE)
_FRAME_NUM = re.compile(r"^(UTOOL|UFRAME)_NUM\s*=\s*([0-9]+)$", re.IGNORECASE)
_PR_RESET = re.compile(r"^PR\[([0-9]+)\]\s*=\s*(LPOS|PR\[([0-9]+)\]\s*-\s*PR\[([0-9]+)\])$", re.IGNORECASE)
_UF_UT = re.compile(r"\bUF\s*:\s*([0-9]+)\s*,\s*UT\s*:\s*([0-9]+)", re.IGNORECASE)
_POS_HEAD = re.compile(r"^P\[([0-9]+)(?::[^\]]*)?\]\s*\{", re.IGNORECASE)
_FIELD = re.compile(r"\b(X|Y|Z|W|P|R|J[1-6])\s*=\s*([+-]?[0-9]*\.?[0-9]+)\s*(mm|deg)", re.IGNORECASE)
_CONFIG = re.compile(r"CONFIG\s*:\s*'([^']*)'", re.IGNORECASE)
_SPOT = re.compile(r"\bSPOT\[([^\]]*)\]", re.IGNORECASE)
_EQUIPMENT = re.compile(r"SPOT\s+Welding\s+Equipment\s+Number\s*:\s*([0-9]+)", re.IGNORECASE)
# Motion options that change the target or the way the robot moves to it (remote TCP: the part
# moves past a fixed tool); TB/TA/DB triggers and ACC are read or do not.
_TARGET_OPTIONS = re.compile(r"\b(Offset|Tool_Offset|INC|VOFFSET|Skip|RTCP)\b", re.IGNORECASE)
# Motions this reader does not simulate, and control flow (jumps, conditions): the program's
# motion then depends on what the reader cannot follow.
_UNSIMULATED = re.compile(r"^(C|A)\s+P|^(J|L|C|A)\s+PR\[|^JMP\b|^IF\b|^SELECT\b|^FOR\b|"
                          r"^CALL\s+(?!(SPOT_WELD|GRIP|RELEASE)\b)", re.IGNORECASE)


def _positions(text: str) -> dict[int, tuple[dict[str, float], str, tuple[int, int] | None]]:
    """P[k] -> its fields (X..R, J1..J6), its CONFIG and its (UF, UT) numbers."""
    out: dict[int, tuple[dict[str, float], str, tuple[int, int] | None]] = {}
    for block in re.split(r"(?=^P\[)", text, flags=re.MULTILINE):
        head = _POS_HEAD.match(block)
        if head:
            group1 = re.split(r"\bGP[2-9]\s*:", block)[0]         # the robot's group; others are positioners
            fields = {m.group(1).upper(): float(m.group(2)) for m in _FIELD.finditer(group1)}
            config = _CONFIG.search(group1)
            frames = _UF_UT.search(group1)
            out[int(head.group(1))] = (fields, config.group(1) if config else "",
                                       (int(frames.group(1)), int(frames.group(2))) if frames else None)
    return out


def _program_positions(text: str) -> dict[int, tuple[dict[str, float], str, tuple[int, int] | None]]:
    """The /POS positions of a whole TP program text."""
    lines = text.splitlines()
    at = next((i for i, ln in enumerate(lines) if ln.strip() == "/POS"), len(lines))
    return _positions("\n".join(lines[at + 1:]))


def _statements(lines: list[str], start: int, end: int) -> list[tuple[int, str]]:
    """(file line, statement) of the /MN lines start..end-1: a numbered line with its continuation
    lines (`    :  SPOT[...]`), without the closing `;`; a remark's continuations (`!+...`, see
    `remarks`) joined into it."""
    out: list[tuple[int, str]] = []
    for index in range(start, end):
        numbered = _NUMBERED.match(lines[index])
        continued = None if numbered else _CONTINUED.match(lines[index])
        if numbered:
            out.append((index + 1, numbered.group(2).strip()))
        elif continued and out:
            out[-1] = (out[-1][0], f"{out[-1][1]} {continued.group(1).strip()}")
    joined: list[tuple[int, str]] = []
    for line, raw in out:
        stmt = re.sub(r"\s*;\s*$", "", raw).strip()
        remark = stmt[1:].strip() if stmt.startswith("!") else None
        if remark is not None and remark.startswith("+") and joined and joined[-1][1].startswith("!"):
            joined[-1] = (joined[-1][0], joined[-1][1] + remark[1:])
        else:
            joined.append((line, "!" + remark if remark is not None else stmt))
    return joined
