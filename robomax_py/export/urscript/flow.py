"""URScript's routines and control flow: the script's functions and what each statement does to control."""

from __future__ import annotations

import re
from collections.abc import Callable

from robomax_py.export.flow import Flow, Routine, Statement, not_resting
from robomax_py.export.urscript.grammar import _CALLS, _UNSIMULATED, _split

# ------------------------------------------------------------------ control flow

# What URScript statements do to the flow (Universal Robots, "The URScript Programming Language":
# `def` defines a function, run when called; `halt()` terminates the program; `return` leaves the
# function, the program when it is the program's own def; `thread` bodies run only when `run`
# starts them). RoboDK's UR post writes `halt()` to "Pause the robot program"
# (ros-industrial-attic/robodk_postprocessors@d7e6c1c0 Universal_Robots.py:634-639): the program
# ends there.
_HEAD = re.compile(r"^(def|thread)\s+([A-Za-z_][A-Za-z0-9_]*)\s*\((.*)\)\s*:$")
_OPEN = re.compile(r"^(while|if|for)\b.*:$")
_MIDDLE = re.compile(r"^(elif\b.*|else\s*):$")
# Built-in functions that change no motion and no flow: messages, outputs, payload and gravity,
# registers, a control cycle's wait.
_INERT = frozenset((
    "textmsg", "popup", "sync", "set_digital_out", "set_standard_digital_out", "set_configurable_digital_out",
    "set_tool_digital_out", "set_analog_out", "set_standard_analog_out", "set_payload", "set_payload_cog",
    "set_payload_mass", "set_tool_voltage", "set_gravity", "set_flag", "write_output_boolean_register",
    "write_output_integer_register", "write_output_float_register", "rtde_set_watchdog"))
# robomax's own routines: a call is a weld, a gripper action or a wait for an input, while their
# bodies are the ones `write` gives (`_not_resting`).
_OWN = ("spot_weld", "grip", "release", "wait_for_signal")


def _script(lines: list[str]) -> tuple[str, Routine | None, dict[str, Routine], list[tuple[int, str]]]:
    """The program's def (its name and body, the functions and threads defined in it taken out)
    and every function defined in the script, by name; and the top-level lines outside them."""
    name = ""
    main: list[Statement] = []
    routines: dict[str, Routine] = {}
    outside: list[tuple[int, str]] = []
    # open definitions: (name, params, body, depth of blocks inside); blocks of the main program
    stack: list[tuple[str, tuple[str, ...], list[Statement], list[str]]] = []
    for number, raw in enumerate(lines, start=1):
        stmt, comment = _split(raw)
        st = Statement(number, stmt, comment, raw)
        head = _HEAD.match(stmt)
        if head:
            params = tuple(p.split("=")[0].strip() for p in head.group(3).split(",") if p.strip())
            if not stack and not name and head.group(1) == "def" and not params:
                name = head.group(2)
                stack.append((name, (), main, []))
            elif stack:
                stack.append((head.group(2), params if head.group(1) == "def" else ("<thread>",), [], []))
            else:
                stack.append((head.group(2), params, [], []))
            continue
        if not stack:
            if stmt:
                outside.append((number, stmt))
            continue
        routine, params, body, blocks = stack[-1]
        if _OPEN.match(stmt):
            blocks.append(stmt)
        elif stmt == "end":
            if blocks:
                blocks.pop()
            else:
                stack.pop()
                if body is not main:
                    routines[routine] = Routine(routine, tuple(body), params)
                continue
        body.append(st)
    while stack:                                   # a definition missing its end runs to the end
        routine, params, body, _ = stack.pop()
        if body is not main:
            routines[routine] = Routine(routine, tuple(body), params)
    return name, (Routine(name, tuple(main)) if name else None), routines, outside


def _classifier(functions: set[str]) -> Callable[[Statement], Flow]:
    def classify(st: Statement) -> Flow:
        text = st.text
        if not text:
            return Flow()
        if re.fullmatch(r"halt\s*\(\s*\)", text):
            return Flow("end", "halt()", scope="program")
        if re.fullmatch(r"return\b.*", text):
            return Flow("end", "return")
        if text in ("break", "continue"):
            return Flow("unsupported", why=f"{text} leaves a loop")
        if _OPEN.match(text):
            return Flow("open", loop=not text.startswith("if"))
        if text == "end":
            return Flow("close")
        if _MIDDLE.match(text):
            return Flow()
        if re.match(r"^(run|kill|join)\b", text):
            return Flow("unsupported", why="a thread: its statements run beside the program")
        assign = re.match(r"^(?:global\s+|local\s+)?[A-Za-z_][A-Za-z0-9_]*(\[[^\]]*\])?\s*=(?!=)(.*)$", text)
        if assign:
            for name, args in re.findall(r"([A-Za-z_][A-Za-z0-9_]*)\s*\(([^()]*)\)", assign.group(2)):
                if name in functions:
                    return Flow("call", name, arguments=bool(args.strip()))
            return Flow()
        call = re.fullmatch(r"([A-Za-z_][A-Za-z0-9_]*)\s*\((.*)\)", text)
        if call:
            func = call.group(1)
            if func in _CALLS or func in _UNSIMULATED or func in _INERT or func in _OWN:
                return Flow()
            return Flow("call", func, arguments=bool(call.group(2).strip()))
        return Flow()
    return classify


def _not_resting(routine: Routine) -> list[tuple[int, str, str]]:
    """(line, statement, why) of what one of robomax's routines does besides what `write` gives
    it: spot_weld, grip and release `sleep(<second parameter>)` once; wait_for_signal loops on
    `get_standard_digital_in(<its parameter>)` with `sync()`. Anything else is reported."""
    if routine.name == "wait_for_signal":
        n = routine.params[0] if len(routine.params) == 1 else "?"
        want = [f"while not get_standard_digital_in({n}):", "sync()", "end"]
        said = [st for st in routine.body if st.text]
        if [st.text for st in said] == want:
            return []
        line = said[0].line if said else 0
        return [(line, routine.name, ("wait_for_signal: not the routine robomax writes (verify takes a call of it "
                                      "for a wait for that input)"))]
    time = routine.params[1] if len(routine.params) == 2 else None
    return not_resting(routine,
                       lambda text: time is not None and bool(re.fullmatch(rf"sleep\(\s*{re.escape(time)}\s*\)", text)),
                       "sleep of its second parameter", routine.body[0].line if routine.body else 0)
