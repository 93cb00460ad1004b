"""export.flow: the statements a controller executes, in order, on a toy dialect (one statement
per line: `end`, `halt`, `goto L`, `L:`, `call R`, `call R(x)`, `if` ... `endif`, `bad`, anything
else plain)."""

from __future__ import annotations

import re

from robomax_py.export.flow import MAX_CALL_DEPTH, Flow, Routine, Statement, follow


def _classify(st: Statement) -> Flow:
    text = st.text
    if text == "end":
        return Flow("end", "end")
    if text == "halt":
        return Flow("end", "halt", scope="program", pause=True)
    if m := re.fullmatch(r"goto (\w+)", text):
        return Flow("goto", m[1])
    if m := re.fullmatch(r"(\w+):", text):
        return Flow("label", m[1])
    if m := re.fullmatch(r"call (\w+)(\(.*\))?", text):
        return Flow("call", m[1], arguments=bool(m[2]))
    if text == "if":
        return Flow("open")
    if text == "endif":
        return Flow("close")
    if text == "bad":
        return Flow("unsupported", why="bad")
    return Flow()


def _routine(name: str, text: str, source: str = "", params: tuple[str, ...] = ()) -> Routine:
    return Routine(name, tuple(Statement(i, line.strip(), source=source) for i, line in enumerate(text.splitlines(), 1)),
                   params, source)


def _run(main: str, **routines: Routine) -> tuple[list[tuple[int, str, str]], list[tuple[int, str, str]]]:
    followed = follow(_routine("main", main), routines, _classify)
    steps = [(s.line, s.statement.text, s.unsupported) for s in followed.steps]
    return steps, followed.problems


def test_an_end_stops_the_program_and_says_what_does_not_run() -> None:
    steps, problems = _run("a\nend\nb")
    assert steps == [(1, "a", "")]
    assert [(line, kind) for line, kind, _ in problems] == [(2, "flow")]
    steps, problems = _run("a\nb\nend\n\nlast:")          # nothing runs after it: no problem
    assert [s[1] for s in steps] == ["a", "b"] and problems == []


def test_a_pause_ends_the_cycle() -> None:
    steps, problems = _run("a\nhalt\nb")
    assert [s[1] for s in steps] == ["a"]
    assert "operator" in problems[0][2]


def test_a_jump_forward_skips_to_its_label_and_a_jump_back_is_reported() -> None:
    steps, _ = _run("goto over\nskipped\nover:\nc")
    assert [s[1] for s in steps] == ["c"]
    steps, _ = _run("top:\na\ngoto top\nnever")
    assert [(s[1], bool(s[2])) for s in steps] == [("a", False), ("goto top", True)]
    steps, _ = _run("goto nowhere\na")
    assert steps[0][2].startswith("a jump to a label") and steps[1][1] == "a"


def test_a_jump_around_statements_that_have_not_run_is_followed() -> None:
    """Backwards to a statement that has not run yet is no loop."""
    steps, _ = _run("goto second\nfirst:\nb\ngoto done\nsecond:\na\ngoto first\ndone:")
    assert [s[1] for s in steps] == ["a", "b"]


def test_inside_a_block_jumps_ends_and_calls_are_reported_and_the_rest_is_conditional() -> None:
    steps = follow(_routine("main", "if\ngoto x\nend\ncall r\nm\nendif\nx:\nn"),
                   {"r": _routine("r", "moves")}, _classify).steps
    assert [(s.statement.text, s.conditional, bool(s.unsupported)) for s in steps] == [
        ("if", False, False), ("goto x", True, True), ("end", True, True), ("call r", True, True), ("m", True, False),
        ("endif", False, False), ("n", False, False)]


def test_a_call_runs_the_routine_in_place_and_its_end_returns() -> None:
    steps, problems = _run("a\ncall sub\nb", sub=_routine("sub", "s1\nend\ns2"))
    assert [s[1] for s in steps] == ["a", "s1", "b"] and problems == []


def test_a_called_routine_of_a_companion_is_reported_at_the_call() -> None:
    steps, _ = _run("a\ncall sub", sub=_routine("sub", "s1\nbad", source="_companion"))
    assert [(line, text) for line, text, _ in steps] == [(1, "a"), (2, "s1"), (2, "bad")]


def test_a_halt_in_a_called_routine_ends_the_program() -> None:
    steps, problems = _run("call sub\nb", sub=_routine("sub", "halt\ns2"))
    assert steps == [] and [line for line, _, _ in problems] == [1]


def test_calls_that_cannot_be_followed_are_reported() -> None:
    steps, _ = _run("call unknown\ncall args(1)\ncall takes\nnext", args=_routine("args", "x"),
                    takes=_routine("takes", "y", params=("n",)))
    assert [(s[1], bool(s[2])) for s in steps] == [("call unknown", True), ("call args(1)", True),
                                                   ("call takes", True), ("next", False)]


def test_a_recursion_is_reported_and_ends_the_walk() -> None:
    steps, _ = _run("call a\nafter", a=_routine("a", "x\ncall b"), b=_routine("b", "call a"))
    assert [(s[1], bool(s[2])) for s in steps] == [("x", False), ("call a", True)]


def test_calls_nested_too_deep_are_reported() -> None:
    chain = {f"r{i}": _routine(f"r{i}", f"call r{i + 1}") for i in range(MAX_CALL_DEPTH + 2)}
    steps, _ = _run("call r0", **chain)
    assert len(steps) == 1 and "deep" in steps[0][2]
