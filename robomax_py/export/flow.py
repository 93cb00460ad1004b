"""Control flow as a controller executes it, for the dialects' readers: which statements run, in
which order, and what the reader cannot follow.

A reader splits its files into routines (`Routine`: a KRL DEF, a RAPID PROC, a URScript def, a
FANUC TP program) of statements (`Statement`) and says, per statement, what it does to the flow
(`Flow`); `follow` then walks the main routine as the controller does:

- an unconditional end (kind "end") stops the program: RETURN / END of the main routine, EXIT,
  ABORT, halt(). A pause (KRL HALT, RAPID Stop and Break, FANUC PAUSE) stops it too until an
  operator restarts it: a cycle does not go on past a pause by itself, so verify checks the cycle
  up to it (RoboDK's post processors write exactly these statements for "Pause the robot program":
  ros-industrial-attic/robodk_postprocessors@d7e6c1c0 KUKA_KRC4.py:281-286 `HALT`,
  ABB_RAPID_IRC5.py:381-386 `STOP;`, Fanuc_R30iA.py:405-410 `PAUSE ;`, Universal_Robots.py:634-639
  `halt()`). A RETURN in a called routine returns to the caller;
- an unconditional jump (kind "goto") continues at its label in the same routine. Nothing here
  depends on data (conditions are not evaluated), so a jump back to a statement that already ran
  repeats forever: that is reported (`unsupported`) and ends the walk, as the program never gets
  past the jump. A jump into a block (IF, WHILE, ...) or to a label the routine does not have is
  reported too;
- a call of a routine the texts define (the same file or the dialect's companion files) runs its
  body in place, up to `MAX_CALL_DEPTH` deep; a call of a routine that is already running (a
  recursion, unconditional here, so endless), a call with arguments (their binding is not
  modelled) and a call of a routine the texts do not define are reported. The dialect's own
  weld, gripper and wait routines are plain statements to the reader (kind "plain");
- inside a block (IF, WHILE, FOR, LOOP, TEST, SWITCH ...) the reader cannot tell whether, or how
  often, a statement runs: every jump, end and call there is reported (a label there is passed
  over), and the other statements are passed on marked `conditional` (the readers report the
  motions among them). A loop's first statement (LOOP, WHILE, FOR, REPEAT ...) is reported
  itself: how often its block runs decides the cycle, and an endless one (KRL's `LOOP ...
  ENDLOOP` without EXIT, a WHILE on an input that never comes) stops the program there for good.

What is reported becomes an `unsupported` violation in verify: never a skipped statement.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Literal

__all__ = ["MAX_CALL_DEPTH", "Flow", "Followed", "Routine", "Statement", "Step", "follow", "not_resting"]

# Calls nested deeper than this are reported rather than followed (no program robomax reads
# nests routines so deep; a deeper chain is more likely a recursion through several routines).
MAX_CALL_DEPTH = 16

FlowKind = Literal["plain", "end", "goto", "label", "call", "open", "close", "unsupported"]


@dataclass(frozen=True, slots=True)
class Statement:
    """One statement of a routine as its reader split it.

    line : 1-based line in its file.
    text : the statement without its comment ("" for a comment or blank line).
    comment : its comment, "" for none.
    raw : the whole line (a reader that needs more than the statement, as KRL's folds).
    source : the file it is in: "" for the program's main file, else a companion's key.
    """

    line: int
    text: str
    comment: str = ""
    raw: str = ""
    source: str = ""


@dataclass(frozen=True, slots=True)
class Routine:
    """A routine: its name as written, its statements, its parameters' names, its file."""

    name: str
    body: tuple[Statement, ...]
    params: tuple[str, ...] = ()
    source: str = ""

    @property
    def takes_arguments(self) -> bool:
        return bool(self.params)


@dataclass(frozen=True, slots=True)
class Flow:
    """What a statement does to the flow.

    kind : "plain" (runs, then the next statement), "end" (see `scope`), "goto" / "label"
        (`name` the label), "call" (`name` the routine, `arguments` whether it passes any),
        "open" / "close" (a block's first / last statement: IF ... THEN, ENDIF ...; `loop` an
        open whose block repeats: LOOP, WHILE, FOR, REPEAT),
        "unsupported" (`why`).
    scope : of an end: "routine" (RETURN: back to the caller, the program's end in the main
        routine) or "program" (EXIT, ABORT, halt(), and the pauses).
    pause : an end that waits for an operator's restart (HALT, Stop, PAUSE).
    """

    kind: FlowKind = "plain"
    name: str = ""
    arguments: bool = False
    scope: Literal["routine", "program"] = "routine"
    pause: bool = False
    why: str = ""
    loop: bool = False


@dataclass(frozen=True, slots=True)
class Step:
    """A statement the controller executes, in order; or one the reader cannot follow.

    line : where to report it: its own line when it is in the main file, else the line (in the
        main file) of the call that led to it.
    conditional : inside a block: whether (and how often) it runs depends on a condition.
    unsupported : why the statement cannot be followed ("" when it can).
    """

    statement: Statement
    line: int
    conditional: bool = False
    unsupported: str = ""


@dataclass(slots=True)
class Followed:
    """The walk: the steps in execution order, and what the flow itself says about the program
    (`problems`: (line, kind, detail), such as an end that leaves statements unexecuted)."""

    steps: list[Step] = field(default_factory=list)
    problems: list[tuple[int, str, str]] = field(default_factory=list)


class _Ended(Exception):
    """The program has ended (an end of the program, or a jump that never gets past itself)."""


def follow(main: Routine, routines: Mapping[str, Routine], classify: Callable[[Statement], Flow],
           key: Callable[[str], str] = str.lower) -> Followed:
    """Walk `main` as the controller executes it (module docstring).

    routines : every routine the texts define, by `key(name)` (the dialect's spelling rule:
        KRL and RAPID names are case-insensitive, URScript's are not).
    classify : the dialect's reading of one statement's effect on the flow.
    """
    out = Followed()
    walker = _Walker(out, routines, classify, key)
    try:
        walker.run(main, [], None)
    except _Ended:
        pass
    return out


@dataclass(slots=True)
class _Frame:
    routine: Routine
    index: int                     # of the statement being run (the call, for a caller)


class _Walker:
    def __init__(self, out: Followed, routines: Mapping[str, Routine], classify: Callable[[Statement], Flow],
                 key: Callable[[str], str]) -> None:
        self.out, self.routines, self.classify, self.key = out, routines, classify, key

    def site(self, statement: Statement, call_line: int | None) -> int:
        return statement.line if statement.source == "" or call_line is None else call_line

    def report(self, statement: Statement, line: int, why: str, conditional: bool = False) -> None:
        self.out.steps.append(Step(statement, line, conditional, why))

    def run(self, routine: Routine, stack: list[_Frame], call_line: int | None) -> None:
        """Run `routine`'s body; return at its end or at a RETURN; `_Ended` when the program ends."""
        body = routine.body
        flows = [self.classify(s) for s in body]
        depth = _depths(flows)
        labels: dict[str, int] = {}
        for i, f in enumerate(flows):
            if f.kind == "label":
                labels.setdefault(self.key(f.name), i)
        frame = _Frame(routine, 0)
        stack = [*stack, frame]
        ran: set[int] = set()
        i = 0
        while i < len(body):
            s, f, inside = body[i], flows[i], depth[i] > 0
            line = self.site(s, call_line)
            frame.index = i
            ran.add(i)
            if inside and f.kind in ("end", "goto", "call", "label"):
                if f.kind != "label":
                    what = {"end": "an end", "goto": "a jump", "call": "a call"}[f.kind]
                    self.report(s, line, f"{what} inside a condition or loop: verify does not evaluate conditions",
                                conditional=True)
                i += 1
                continue
            if f.kind == "open" and f.loop:
                # Reported, and passed on as a block's start too: the readers keep their blocks' depth.
                self.report(s, line, "a loop: verify does not evaluate how often its block runs, nor whether it "
                                     "ends (the program goes on only when it does)", conditional=inside)
            if f.kind in ("plain", "open", "close"):
                self.out.steps.append(Step(s, line, inside and f.kind == "plain"))
                i += 1
                continue
            if f.kind == "unsupported":
                self.report(s, line, f.why, conditional=inside)
                i += 1
                continue
            if f.kind == "label":
                i += 1
                continue
            if f.kind == "end":
                if f.scope == "routine" and len(stack) > 1:
                    return
                self.end(s, line, f, stack)
                raise _Ended
            if f.kind == "goto":
                target = labels.get(self.key(f.name))
                if target is None:
                    self.report(s, line, "a jump to a label the routine does not have")
                elif depth[target] > 0:
                    self.report(s, line, "a jump into a block (IF, WHILE, FOR ...)")
                elif target in ran:
                    # Nothing here depends on data: a jump back to what already ran repeats it forever.
                    self.report(s, line, "a jump back to statements that already ran: they repeat without end "
                                         "(verify follows no loop)")
                    raise _Ended
                else:
                    i = target
                    continue
                i += 1
                continue
            # a call
            callee = self.routines.get(self.key(f.name))
            if callee is None:
                self.report(s, line, f"a call of {f.name}, which neither the program nor its companion files define")
            elif any(self.key(fr.routine.name) == self.key(callee.name) for fr in stack):
                self.report(s, line, f"a call of {f.name} while {f.name} runs (a recursion): the calls never end")
                raise _Ended
            elif f.arguments or callee.takes_arguments:
                self.report(s, line, f"a call of {f.name} with arguments (verify follows routines without)")
            elif len(stack) >= MAX_CALL_DEPTH:
                self.report(s, line, f"a call of {f.name} nested more than {MAX_CALL_DEPTH} routines deep")
            else:
                self.run(callee, stack, line)
            i += 1

    def end(self, statement: Statement, line: int, flow: Flow, stack: list[_Frame]) -> None:
        """An end of the program: a problem when statements would have followed it."""
        left = any(self._runs(fr.routine.body[fr.index + 1:]) for fr in stack)
        if not left:
            return
        what = statement.text.strip()
        why = (" (the controller waits there until an operator restarts it: verify checks the cycle up to it)"
               if flow.pause else "")
        self.out.problems.append((line, "flow", f"{what} ends the program here{why}: the statements after it do not run"))

    def _runs(self, statements: tuple[Statement, ...]) -> bool:
        """Whether any of `statements` is more than a label, a comment or a blank line."""
        return any(s.text.strip() and self.classify(s).kind != "label" for s in statements)


def not_resting(routine: Routine, rests: Callable[[str], bool], rest_words: str, missing_line: int,
                skip: Callable[[str], bool] = lambda text: False) -> list[tuple[int, str, str]]:
    """(line, statement, why) of what a default routine (spot_weld, grip, release) does besides
    resting its time once, in any dialect: `rests` tells the dialect's one rest statement (the
    routine `write` gives), `skip` what else may stand there (declarations, remarks); a call of
    such a routine is then a weld or a gripper action of that time, and anything else in it is
    reported. `rest_words` names the rest statement and `missing_line` is the line reported when
    the routine never rests."""
    waits = 0
    out: list[tuple[int, str, str]] = []
    for st in routine.body:
        if not st.text or skip(st.text):
            continue
        if waits == 0 and rests(st.text):
            waits += 1
            continue
        out.append((st.line, st.text, (f"{routine.name}: a weld or gripper routine that does more than rest its time "
                                       "(verify takes a call of it for the weld or action it names)")))
    if waits == 0:
        out.append((missing_line, routine.name, f"{routine.name}: it does not rest its time ({rest_words})"))
    return out


def _depths(flows: list[Flow]) -> list[int]:
    """Each statement's block depth: 0 outside every block; a block's opening and closing
    statements are at the depth around the block."""
    out, depth = [], 0
    for f in flows:
        if f.kind == "close":
            depth = max(0, depth - 1)
        out.append(depth)
        if f.kind == "open":
            depth += 1
    return out
