"""SRCL writer and parser: golden file, round trips on random programs, located parse errors."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from robomax_py.errors import ExportError, ProgramError
from robomax_py.export.srcl import RESERVED, lin_frames, parse_program, write_program
from robomax_py.program import (
    Comment,
    FrameDef,
    Header,
    Instruction,
    LinMove,
    Program,
    PtpMove,
    Spot,
    Wait,
    WaitFor,
)

GOLDEN = Path(__file__).parent.parent / "golden" / "example.srcl"
JOINTS = tuple(f"joint_a{i}" for i in range(1, 7))


def example_program() -> Program:
    """Hand-built: every instruction kind, both frame kinds, flyby on and off, values needing rounding."""
    return Program(
        name="cabin_flange",
        header=Header(cell="cabin_flange", robot="kr125", tool="spot_gun_c", cycle_time_s=23.71449, joints=JOINTS),
        frames=(
            FrameDef("gun_tcp", "tool", (200.0, 0.0, 270.0), (0.0, -90.0, 0.0), 1),
            FrameDef("robot_base", "base", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)),
        ),
        instructions=(
            Comment("start at home"),
            PtpMove((0.0, -90.0, 90.0, 0.0, 0.0, 0.0), speed=1.0, accel=1.0, comment="home"),
            PtpMove((-29.53125, -71.2, 101.33333333, -0.000001, 55.5, 179.99999), speed=0.8, accel=0.5, flyby=11.999999),
            LinMove((1224.88, -693.91, 893.2), (90.0, 0.0, 180.0), "S010 T101010", 500.0, flyby=1.2,
                    comment="approach s1", tool="gun_tcp", base="robot_base"),
            LinMove((1224.88, -693.91, 843.2), (90.0, 0.0, 180.0), "S010 T101010", 150.0, tool="gun_tcp",
                    base="robot_base"),
            Spot("s1", "flange", 0.5),
            LinMove((1224.88, -693.91, 893.2), (90.0, 0.0, 180.0), "S010 T101010", 500.0, flyby=0.6, tool="gun_tcp",
                    base="robot_base"),
            WaitFor("door_clear"),
            WaitFor("clamp_1", 17),
            Wait(2.0),
            Comment("back home"),
            PtpMove((0.0, -90.0, 90.0, 0.0, 0.0, 0.0), speed=1.0, accel=1.0),
        ),
    )


# --------------------------------------------------------------------------------------------------
# golden file and exact round trip


def test_golden_file(update_golden: bool) -> None:
    text = write_program(example_program())
    if update_golden:
        GOLDEN.parent.mkdir(parents=True, exist_ok=True)
        GOLDEN.write_text(text, encoding="utf-8", newline="\n")
    assert GOLDEN.read_text(encoding="utf-8") == text


def test_golden_file_parses_back() -> None:
    text = GOLDEN.read_text(encoding="utf-8")
    program = parse_program(text, GOLDEN)
    assert program == example_program()
    assert write_program(program) == text


def test_values_are_rounded_when_built() -> None:
    move = PtpMove((-29.53125, 101.33333333, -0.000001), speed=0.8004)
    assert move.target_deg == (-29.5312, 101.3333, 0.0)   # half-even on the binary value; -0.0 -> 0.0
    assert math.copysign(1.0, move.target_deg[2]) == 1.0
    assert move.speed == 0.8
    assert Comment("  note  ").text == "note"


def test_parser_is_lenient_about_layout_but_not_meaning() -> None:
    text = (
        "PROGRAM p;  CELL c; { ignored } ROBOT r AXES(a1,a2); TOOL t; CYCLE 3 SEC;\n"
        "VAR f: BASE FRAME := (POS(1, 2, 3), ORI(4, 5, 6)); { ignored too }\n"
        "BEGIN MOVE PTP AXIS(1.5, -2) SPEED 1 ACCEL 0.25 FLYBY 3;   WAIT 1.25 SEC; ENDPROGRAM;"
    )
    program = parse_program(text)
    assert program == Program(
        "p", Header("c", "r", "t", 3.0, ("a1", "a2")),
        (FrameDef("f", "base", (1, 2, 3), (4, 5, 6)),),
        (PtpMove((1.5, -2.0), 1.0, 0.25, 3.0), Wait(1.25)),
    )


def test_empty_program_round_trips() -> None:
    program = Program("empty", Header("c", "r", "t", 0.0, ("j1",)))
    text = write_program(program)
    assert "VAR" not in text
    assert parse_program(text) == program
    assert write_program(parse_program(text)) == text


# --------------------------------------------------------------------------------------------------
# random programs

NAMES = st.from_regex(r"[A-Za-z_][A-Za-z0-9_]{0,11}", fullmatch=True).filter(lambda s: s not in RESERVED)
TEXT = st.text(
    st.characters(exclude_categories=("C", "Z"), include_characters=" ", exclude_characters="{}"), max_size=30
)
CONFIG = st.text(st.characters(exclude_categories=("C", "Z"), include_characters=" ", exclude_characters="'"),
                 max_size=16)


def _floats(lo: float, hi: float) -> st.SearchStrategy[float]:
    return st.floats(lo, hi, allow_nan=False, allow_infinity=False)


MM = _floats(-5000.0, 5000.0)
ANGLE = _floats(-360.0, 360.0)
FRACTION = _floats(0.001, 1.0)
SECONDS = _floats(0.0, 1000.0)
RADIUS = st.one_of(st.just(0.0), _floats(0.0001, 90.0))   # fly-by radius, deg; 0: exact stop


@st.composite
def programs(draw: st.DrawFn) -> Program:
    joints = tuple(draw(st.lists(NAMES, min_size=1, max_size=8, unique=True)))
    n = len(joints)
    header = Header(draw(NAMES), draw(NAMES), draw(NAMES), draw(SECONDS), joints)
    # SRCL declares at most one frame of each kind; every LIN is stated in them.
    kinds = draw(st.lists(st.sampled_from(["tool", "base"]), max_size=2, unique=True))
    frame_names = draw(st.lists(NAMES, min_size=len(kinds), max_size=len(kinds), unique=True))
    frames = tuple(
        FrameDef(name, kind, draw(st.tuples(MM, MM, MM)), draw(st.tuples(ANGLE, ANGLE, ANGLE)),  # type: ignore[arg-type]
                 draw(st.integers(0, 99)))
        for name, kind in zip(frame_names, kinds)
    )
    tool, base = lin_frames(frames)
    instruction: st.SearchStrategy[Instruction] = st.one_of(
        st.builds(PtpMove, st.tuples(*[_floats(-720.0, 720.0)] * n), FRACTION, FRACTION, RADIUS, TEXT),
        st.builds(LinMove, st.tuples(MM, MM, MM), st.tuples(ANGLE, ANGLE, ANGLE), CONFIG, _floats(0.001, 10000.0),
                  RADIUS, TEXT, tool=st.just(tool), base=st.just(base)),
        st.builds(Spot, NAMES, NAMES, SECONDS),
        st.builds(Wait, SECONDS),
        st.builds(WaitFor, NAMES, st.one_of(st.none(), st.integers(0, 4096))),
        st.builds(Comment, TEXT),
    )
    return Program(draw(NAMES), header, frames, tuple(draw(st.lists(instruction, max_size=12))))


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(programs())
def test_random_programs_round_trip(program: Program) -> None:
    text = write_program(program)
    parsed = parse_program(text)
    assert parsed == program
    assert write_program(parsed) == text


@settings(max_examples=100, deadline=None)
@given(st.lists(_floats(-1e6, 1e6), min_size=1, max_size=6))
def test_stored_floats_survive_their_own_format(values: list[float]) -> None:
    move = PtpMove(tuple(values))
    assert all(float(f"{v:.4f}") == v for v in move.target_deg)


# --------------------------------------------------------------------------------------------------
# writer rejects what it cannot write


def _with(ins: Instruction) -> Program:
    return replace(example_program(), instructions=(ins,))


@pytest.mark.parametrize(
    "ins",
    [
        PtpMove((0.0, math.nan, 0.0, 0.0, 0.0, 0.0)),
        PtpMove((0.0,) * 6, speed=math.inf),
        LinMove((0.0, -math.inf, 0.0), (0.0, 0.0, 0.0)),
        LinMove((0.0, 0.0, 0.0), (0.0, math.nan, 0.0)),
        LinMove((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), speed_mm_s=math.nan),
        Spot("s1", "seam", math.inf),
        Wait(math.nan),
    ],
)
def test_writer_rejects_non_finite(ins: Instruction) -> None:
    with pytest.raises(ExportError, match="finite"):
        write_program(_with(ins))


def test_writer_rejects_non_finite_header_and_frame() -> None:
    program = example_program()
    with pytest.raises(ExportError, match="header: cycle time must be finite"):
        write_program(replace(program, header=replace(program.header, cycle_time_s=math.nan)))
    bad_frame = FrameDef("f", "tool", (0.0, math.inf, 0.0), (0.0, 0.0, 0.0))
    with pytest.raises(ExportError, match="frame 0 .* frame position must be finite"):
        write_program(replace(program, frames=(bad_frame,)))


@pytest.mark.parametrize(
    ("ins", "match"),
    [
        (PtpMove((0.0,) * 5), "instruction 0 \\(MOVE PTP\\): PTP target has 5 axis values, but the robot has 6"),
        (PtpMove((0.0,) * 6, speed=0.0), "speed 0.000 is outside \\(0, 1\\]"),
        (PtpMove((0.0,) * 6, accel=1.5), "accel 1.500 is outside"),
        (LinMove((0.0, 0.0), (0.0, 0.0, 0.0)), "LIN position needs 3 values"),
        (LinMove((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), speed_mm_s=0.0), "must be > 0"),
        (Wait(-1.0), "negative"),
        (Spot("SPOT", "seam", 0.5), "keyword"),
        (Spot("s-1", "seam", 0.5), "not an SRCL name"),
        (WaitFor("1door"), "not an SRCL name"),
        (Comment("a } b"), "cannot contain '}'"),
        (Comment("two\nlines"), "cannot contain"),
        (PtpMove((0.0,) * 6, comment="{nested}"), "cannot contain '{'"),
        (LinMove((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), config="it's"), "cannot contain \"'\""),
    ],
)
def test_writer_rejects_bad_values(ins: Instruction, match: str) -> None:
    with pytest.raises(ExportError, match=match):
        write_program(_with(ins))


def test_writer_rejects_duplicate_frames_and_joints() -> None:
    program = example_program()
    with pytest.raises(ExportError, match="already defined"):
        write_program(replace(program, frames=program.frames[:1] * 2))
    with pytest.raises(ExportError, match="joint names must be unique"):
        write_program(replace(program, header=replace(program.header, joints=("a", "a"))))


# --------------------------------------------------------------------------------------------------
# parser errors name line and column

SMALL = """PROGRAM p;
CELL c;
ROBOT r AXES(a1, a2, a3);
TOOL t;
CYCLE 4.000 SEC;
BEGIN
  MOVE PTP AXIS(0.0000, 10.0000, 20.0000) SPEED 1.000 ACCEL 1.000;
  { weld }
  SPOT s1 SEAM left TIME 0.500 SEC;
  WAIT 1.000 SEC;
ENDPROGRAM;
"""


def test_small_program_parses() -> None:
    assert parse_program(SMALL).instructions[2] == Spot("s1", "left", 0.5)


def _error(text: str) -> ProgramError:
    with pytest.raises(ProgramError) as info:
        parse_program(text, "cell.srcl")
    return info.value


@pytest.mark.parametrize(
    ("old", "new", "key", "problem"),
    [
        # the comment line becomes the move's own comment (it may stand before the ';'), so SPOT is the surprise
        ("ACCEL 1.000;", "ACCEL 1.000", "line 9, column 3", "expected ';' after MOVE statement, got 'SPOT'"),
        ("TIME 0.500 SEC;", "TIME 0.500 SEC", "line 10, column 3", "expected ';' after SPOT statement, got 'WAIT'"),
        ("  SPOT s1", "  WELD s1", "line 9, column 3",
         "unknown statement 'WELD'; expected MOVE, SPOT, GRIP, RELEASE, WAIT, SET, a { comment } or ENDPROGRAM"),
        ("  WAIT 1.000", "  wait 1.000", "line 10, column 3",
         "unknown statement 'wait' (keywords are upper case); expected MOVE, SPOT, GRIP, RELEASE, WAIT, SET, a { comment } or ENDPROGRAM"),
        ("TIME 0.500", "TIME 0.5.0", "line 9, column 26",
         "bad number '0.5.0': write digits with an optional '.' and decimals, e.g. 12.500"),
        ("10.0000,", "1e1,", "line 7, column 25",
         "bad number '1e1': write digits with an optional '.' and decimals, e.g. 12.500"),
        ("{ weld }", "{ weld", "line 8, column 3",
         "unterminated comment: '{' has no '}' on the same line (comments are one line, no nested braces)"),
        ("10.0000, 20.0000)", "10.0000)", "line 7, column 3", "PTP target has 2 axis values, but the robot has 3 joints"),
        ("SPEED 1.000", "SPEED 0.000", "line 7, column 3",
         "PTP speed 0.000 is outside (0, 1] (a fraction of the maximum)"),
        ("WAIT 1.000", "WAIT FOR 1.000", "line 10, column 12", "expected a name in WAIT statement, got '1.000'"),
        ("ENDPROGRAM;\n", "", "line 10, column 18",
         "unexpected end of file; expected one of 'ENDPROGRAM', 'GRIP', 'MOVE', 'RELEASE', 'SET', 'SPOT', 'WAIT' or a comment"),
        ("a2, a3", "a2, a2", "line 3, column 22", "joint 'a2' is listed twice in AXES"),
        ("CYCLE 4.000 SEC", "CYCLE 4.000", "line 5, column 12", "expected 'SEC' in CYCLE line, got ';'"),
        ("SEAM left", "SEAM left #", "line 9, column 21", "unexpected character '#'"),
    ],
)
def test_parse_errors_are_located(old: str, new: str, key: str, problem: str) -> None:
    assert old in SMALL
    err = _error(SMALL.replace(old, new, 1))
    assert (err.file, err.key, err.problem) == ("cell.srcl", key, problem)
    assert str(err) == f"cell.srcl: {key}: {problem}"


def test_parse_error_on_duplicate_frame() -> None:
    text = SMALL.replace(
        "BEGIN\n",
        "VAR\n  f: TOOL FRAME := (POS(0, 0, 0), ORI(0, 0, 0));\n  f: BASE FRAME := (POS(0, 0, 0), ORI(0, 0, 0));\nBEGIN\n",
    )
    err = _error(text)
    assert (err.key, err.problem) == ("line 8, column 3", "frame 'f' is already defined")
