"""Yaskawa INFORM: what a DX100 / YRC1000 controller executes from a job file, for a motion subset.

Sources: Yaskawa DX100 "Options: Instructions for Interface with an Easy Offline Teaching
System" (156191-1CD) and its NX100 edition §4.1 "Job Data Format": ``/JOB``, ``//NAME``, ``//POS``
with the pseudo instructions ``///TOOL n``, ``///USER n``, ``///POSTYPE PULSE|BASE|ROBOT|USER``,
``///PULSE``, ``///RECTAN``, ``///RCONF``, valid for the positions ``C<n>=`` that follow them,
then ``//INST`` and the instructions from ``NOP`` to ``END``. A pulse position counts each axis
in encoder pulses (the controller's pulses per degree, robot.yaml ``controller.pulses_per_degree``);
a rectangular position is X, Y, Z (mm) and Rx, Ry, Rz (deg), "rotating the specified coordinate
system in the order of Rz, Ry and Rx" (§4.3.1.1): R = Rz·Ry·Rx, in the robot (base) coordinates or
in user frame n (``POSTYPE USER``), with tool n. RoboDK's Motoman post (ros-industrial-attic/
robodk_postprocessors@d7e6c1c0 Motoman.py:183-215, 550-632) writes the same forms.

- ``MOVJ C<n> VJ=<%> [PL=<0..8>]`` joint move, ``MOVL C<n> V=<mm/s> [PL=...]`` straight TCP line;
  ``PL=0`` or no ``PL``: the robot stops at the point; ``PL`` 1..8 or ``CR=`` (corner radius): blended.
- ``TIMER T=<s>`` waits; ``WAIT IN#(k)=ON`` waits for general input k; ``CALL JOB:<name> [args]``
  is recorded (name and ARGF arguments); comments start with ``'``.
- The tool and user frames are the controller's (a job names them by number): the caller gives
  the values the integrator calibrated; a number it does not give is ``undefined``.

Other instructions that could change motion (MOVC, MOVS, IMOV, SFTON, jumps, conditions) are
``unsupported`` issues.
"""

from __future__ import annotations

import re
from collections.abc import Mapping

import numpy as np

from .common import (
    MM,
    NUMBER,
    Call,
    Event,
    FloatArray,
    Issue,
    Motion,
    MotionKind,
    ProgramRun,
    Wait,
    Where,
    arg_value,
    homogeneous,
    rot_zyx_deg,
)

_POSITION = re.compile(r"^C(\d{4,5})\s*=\s*(.*)$")
_MOVE = re.compile(r"^(MOVJ|MOVL)\s+C(\d{4,5})((?:\s+\w+\s*=\s*" + NUMBER + r")*)\s*$", re.IGNORECASE)
_TAG = re.compile(rf"(\w+)\s*=\s*({NUMBER})")
_INERT = re.compile(r"^(NOP|DOUT|MSG|SET\w*|GETARG|ADD|SUB|MUL|DIV|INC|DEC)\b", re.IGNORECASE)


def run_inform(text: str, *, name: str = "JOB.JBI", pulses_per_degree: tuple[float, ...],
               tools: Mapping[int, FloatArray], users: Mapping[int, FloatArray]) -> ProgramRun:
    """The job's run. tools: tool number -> flange to TCP (4x4, m); users: user frame number ->
    the frame in the robot base (4x4, m), as the controller holds them."""
    events: list[Event] = []
    issues: list[Issue] = []
    positions: dict[int, tuple[str, tuple[float, ...], int, int]] = {}
    section = ""
    tool = user = 0
    postype = "PULSE"
    stopped = None
    for number, raw in enumerate(text.splitlines(), start=1):
        code = raw.strip()
        where = Where(name, number)
        if code.startswith("//") and not code.startswith("///"):
            section = code[2:].split()[0].upper()
            continue
        if not code or code.startswith("'") or code.upper() == "/JOB":
            continue
        if section == "POS":
            word, _, value = code.partition(" ")
            if word == "///TOOL":
                tool = int(value)
            elif word == "///USER":
                user = int(value)
            elif word == "///POSTYPE":
                postype = value.strip().upper()
            elif word == "///PULSE":
                postype = "PULSE"
            elif word in ("///RECTAN", "///RCONF", "///NPOS"):
                continue
            else:
                m = _POSITION.match(code)
                if m:
                    positions[int(m.group(1))] = (postype, tuple(float(v) for v in m.group(2).split(",")), tool, user)
                else:
                    issues.append(Issue(where, "unsupported", code, "a position line the model does not read"))
            continue
        if section != "INST" or code.startswith("///"):
            continue
        word = code.split()[0].upper()
        if word == "END":
            break
        move = _MOVE.match(code)
        if move:
            done = _motion(where, move, positions, pulses_per_degree, tools, users)
            if isinstance(done, Motion):
                events.append(done)
            else:
                issues.append(done)
            continue
        m = re.match(rf"^TIMER\s+T\s*=\s*({NUMBER})$", code, re.IGNORECASE)
        if m:
            events.append(Wait(where, seconds=float(m.group(1))))
            continue
        m = re.match(r"^WAIT\s+IN#\(\s*(\d+)\s*\)\s*=\s*(ON|OFF)$", code, re.IGNORECASE)
        if m:
            events.append(Wait(where, signal=f"IN#({m.group(1)})", input_number=int(m.group(1)),
                               state=m.group(2).upper() == "ON"))
            continue
        m = re.match(r"^CALL\s+JOB:(\w+)(.*)$", code, re.IGNORECASE)
        if m:
            args = tuple(arg_value(a) for a in re.findall(rf"ARGF\s*({NUMBER})", m.group(2), re.IGNORECASE))
            events.append(Call(where, m.group(1), args))
            continue
        if word in ("PAUSE", "HOLD"):
            stopped = where
            break
        if _INERT.match(code):
            continue
        issues.append(Issue(where, "unsupported", code, "outside the modelled subset"))
    return ProgramRun("inform", tuple(events), tuple(issues), stopped=stopped)


def _motion(where: Where, move: re.Match[str], positions: Mapping[int, tuple[str, tuple[float, ...], int, int]],
            ppd: tuple[float, ...], tools: Mapping[int, FloatArray],
            users: Mapping[int, FloatArray]) -> Motion | Issue:
    statement, n = move.group(1).upper(), int(move.group(2))
    tags = {k.upper(): float(v) for k, v in _TAG.findall(move.group(3))}
    blend = None if tags.get("PL", 0.0) == 0.0 and "CR" not in tags else \
        (f"CR={tags['CR']:g}" if "CR" in tags else f"PL={tags['PL']:g}")
    kind: MotionKind = "joint" if statement == "MOVJ" else "linear"
    if n not in positions:
        return Issue(where, "undefined", f"C{n:05d}", "a position the job does not define")
    postype, values, tool_no, user_no = positions[n]
    target = f"C{n:05d}"
    T_tool = tools.get(tool_no)
    if postype == "PULSE":
        if statement == "MOVL":
            return Issue(where, "unsupported", move.group(0), "a straight line to a pulse position")
        joints = tuple(p / k for p, k in zip(values, ppd, strict=False))
        return Motion(where, statement, kind, target, joints, None, T_tool, None, None, blend)
    x, y, z, rx, ry, rz = values[:6]
    pose = homogeneous(rot_zyx_deg(rz, ry, rx), (x * MM, y * MM, z * MM))
    if postype == "USER":
        frame = users.get(user_no)
        if frame is None:
            return Issue(where, "undefined", f"USER {user_no}", "a user frame the controller does not hold")
    elif postype in ("BASE", "ROBOT"):
        frame = np.eye(4)          # the robot (base) coordinates: no base axes
    else:
        return Issue(where, "unsupported", f"POSTYPE {postype}", "a position type the model does not read")
    if T_tool is None:
        return Issue(where, "undefined", f"TOOL {tool_no}", "a tool the controller does not hold")
    return Motion(where, statement, kind, target, None, frame @ pose, T_tool, frame, None, blend)
