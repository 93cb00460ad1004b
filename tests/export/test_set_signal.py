"""Setting an output between robots of a station (`SetSignal`) in every dialect: written as the
vendor states it (KRL `$OUT[k]=TRUE`, RAPID `SetDO name, 1`, FANUC TP `DO[k]=ON`, URScript
`set_standard_digital_out(k, True)`, SRCL `SET name OUTPUT k TRUE`), read back into the same
values, compared with golden files, and refused with the cell key when the dialect cannot
state the output."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from robomax_py.errors import ControllerSetupError, ProgramError
from robomax_py.export import DIALECTS
from robomax_py.export.dialect import PlannedProgram
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.program import Header, Instruction, Program, PtpMove, SetSignal, WaitFor
from robomax_py.spec import ControllerInput, ControllerOutput, ControllerSetup

REPO = Path(__file__).resolve().parents[2]
GOLDEN = REPO / "tests" / "golden" / "station_interlock"
FIVE = ("srcl", "krl", "rapid", "fanuc", "urscript")


@pytest.fixture(scope="module")
def small(tmp_path_factory: pytest.TempPathFactory, write_small_cell: Any) -> tuple[Any, Any]:
    cell = load_cell(write_small_cell(tmp_path_factory.mktemp("set_signal")))
    return cell, load_cell_robot(cell)


def _planned(cell: Any, robot: Any, outputs: tuple[ControllerOutput, ...], number: int | None = 3) -> PlannedProgram:
    """Home, wait for the other robot's zone, into the zone, stop, set this robot's output, out, reset it."""
    home = np.degrees(cell.home)
    inside = home + np.array([30.0, 10.0, -10.0, 0.0, 20.0, 0.0])
    ins: tuple[Instruction, ...] = (
        PtpMove(tuple(home)), WaitFor("r2_z1_clear", 2), PtpMove(tuple(inside)), PtpMove(tuple(home)),
        SetSignal("r1_z1_clear", number, True), SetSignal("r1_z1_clear", number, False))
    q = (cell.home, cell.home, np.radians(inside), cell.home, cell.home, cell.home)
    header = Header(cell.name, robot.name, cell.tool.name, 4.0, tuple(robot.joint_names))
    setup = ControllerSetup(inputs=(ControllerInput("r2_z1_clear", 2),), outputs=outputs)
    return PlannedProgram(Program("station_r1", header, instructions=ins), q, setup)


def _signals(program: Program) -> list[Instruction]:
    return [i for i in program.instructions if isinstance(i, (WaitFor, SetSignal))]


# What each dialect reads back: RAPID names the I/O configuration's signals, no numbers.
READ_BACK: dict[str, list[Instruction]] = {
    d: [WaitFor("r2_z1_clear", 2), SetSignal("r1_z1_clear", 3, True), SetSignal("r1_z1_clear", 3, False)]
    for d in FIVE if d != "rapid"
} | {"rapid": [WaitFor("r2_z1_clear"), SetSignal("doR1Z1", None, True), SetSignal("doR1Z1", None, False)]}


@pytest.mark.parametrize("dialect", FIVE)
def test_round_trip_and_golden(small: tuple[Any, Any], dialect: str, update_golden: bool) -> None:
    cell, robot = small
    d = DIALECTS[dialect]
    adapted = d.adapt(_planned(cell, robot, (ControllerOutput("r1_z1_clear", 3, "doR1Z1"),)), robot)
    texts = d.write(adapted, robot)
    parsed = d.parse(texts, "station_r1" + d.extensions[0], robot)
    assert _signals(parsed.program) == READ_BACK[dialect]
    assert _signals(parsed.program) == _signals(adapted)
    for key, text in texts.items():         # the set: main file, companions, shared routines
        golden = GOLDEN / (f"station_r1{key}" if key.startswith((".", "_")) else key)
        if update_golden:
            golden.parent.mkdir(parents=True, exist_ok=True)
            golden.write_bytes(text.encode("utf-8"))
        assert text.encode("utf-8") == golden.read_bytes(), golden.name


STATEMENTS = {"krl": ("$OUT[3]=TRUE", "$OUT[3]=FALSE"), "rapid": ("SetDO doR1Z1, 1;", "SetDO doR1Z1, 0;"),
              "fanuc": ("DO[3:r1_z1_clear]=ON", "DO[3:r1_z1_clear]=OFF"),
              "urscript": ("set_standard_digital_out(3, True)", "set_standard_digital_out(3, False)"),
              "srcl": ("SET r1_z1_clear OUTPUT 3 TRUE;", "SET r1_z1_clear OUTPUT 3 FALSE;")}


@pytest.mark.parametrize("dialect", FIVE)
def test_the_vendors_statement(small: tuple[Any, Any], dialect: str) -> None:
    cell, robot = small
    d = DIALECTS[dialect]
    main = d.write(d.adapt(_planned(cell, robot, (ControllerOutput("r1_z1_clear", 3, "doR1Z1"),)), robot), robot)
    lines = [line.strip() for line in main[d.extensions[0]].splitlines()]
    on, off = STATEMENTS[dialect]
    assert any(line.startswith(on) or on in line for line in lines) and any(off in line for line in lines)


@pytest.mark.parametrize(("dialect", "number", "problem"), [
    ("urscript", 8, "outside URScript's outputs 0..7"),
    ("urscript", None, "map the signal to the controller's output"),
    ("krl", 0, "outside KRL's outputs 1..4096"),
    ("krl", 4097, "outside KRL's outputs 1..4096"),
    ("fanuc", 0, "outside FANUC TP's outputs 1..9999"),
    ("fanuc", None, "map the signal"),
])
def test_an_output_the_dialect_cannot_state_names_the_key(small: tuple[Any, Any], dialect: str, number: int | None,
                                                         problem: str) -> None:
    cell, robot = small
    outputs = () if number is None else (ControllerOutput("r1_z1_clear", number),)
    with pytest.raises(ControllerSetupError) as caught:
        DIALECTS[dialect].adapt(_planned(cell, robot, outputs, number), robot)
    assert "robot.controller.outputs.r1_z1_clear" in str(caught.value) and problem in str(caught.value)


@pytest.mark.parametrize(("text", "problem"), [
    ("set_standard_digital_out(8, True)", "standard digital output 8 does not exist"),
    ("set_standard_digital_out(2, 1)", "True or False"),
])
def test_urscript_reader_refuses_what_the_controller_has_not(small: tuple[Any, Any], text: str, problem: str) -> None:
    cell, robot = small
    d = DIALECTS["urscript"]
    script = d.write(d.adapt(_planned(cell, robot, (ControllerOutput("r1_z1_clear", 3),)), robot), robot)[".script"]
    bad = script.replace("set_standard_digital_out(3, True)", text)
    with pytest.raises(ProgramError, match=problem.replace("(", r"\(")):
        d.parse({".script": bad}, "bad.script", robot)


def test_rapid_set_and_reset_are_setdo(small: tuple[Any, Any]) -> None:
    """RAPID's `Set sig;` / `Reset sig;` are SetDO sig, 1 / 0; SetDO with \\SDelay is not simulated."""
    cell, robot = small
    d = DIALECTS["rapid"]
    mod = d.write(d.adapt(_planned(cell, robot, (ControllerOutput("r1_z1_clear", 3),)), robot), robot)
    text = mod[".mod"].replace("SetDO r1_z1_clear, 1;", "Set r1_z1_clear;").replace("SetDO r1_z1_clear, 0;",
                                                                                      "SetDO \\SDelay:=0.2, r1_z1_clear, 0;")
    parsed = d.parse({**mod, ".mod": text}, "station_r1.mod", robot)
    assert _signals(parsed.program)[1] == SetSignal("r1_z1_clear", None, True)
    assert any("SDelay" in t for _, t in parsed.ignored)


def test_a_planned_interlock_takes_the_cells_output_number() -> None:
    from robomax_py.export.plan_program import set_signal, wait_for

    setup = ControllerSetup(inputs=(ControllerInput("r2_z1_clear", 2),), outputs=(ControllerOutput("r1_z1_clear", 3),))
    assert set_signal("r1_z1_clear", setup) == SetSignal("r1_z1_clear", 3, True)
    assert set_signal("r1_z1_clear", setup, False) == SetSignal("r1_z1_clear", 3, False)
    assert set_signal("r9_z1_clear", setup) == SetSignal("r9_z1_clear", None, True)
    assert wait_for("r2_z1_clear", setup) == WaitFor("r2_z1_clear", 2)


@pytest.mark.parametrize(("dialect", "on", "off"), [("as", "SIGNAL 3 ; r1_z1_clear", "SIGNAL -3 ; r1_z1_clear"),
                                                    ("inform", "DOUT OT#(3) ON", "DOUT OT#(3) OFF")])
def test_as_and_inform_set_their_outputs(small: tuple[Any, Any], dialect: str, on: str, off: str) -> None:
    """Kawasaki AS: BREAK (the program waits for the motion's end), then SIGNAL k / -k; Yaskawa
    INFORM: DOUT OT#(k) ON / OFF after a PL=0 point. Read back to the same outputs."""
    from tests.conftest import with_pulses

    cell, robot = small
    robot = with_pulses(robot)
    d = DIALECTS[dialect]
    adapted = d.adapt(_planned(cell, robot, (ControllerOutput("r1_z1_clear", 3),)), robot)
    texts = d.write(adapted, robot)
    lines = [line.strip() for line in texts[d.extensions[0]].splitlines()]
    assert on in lines and off in lines
    if dialect == "as":
        assert lines[lines.index(on) - 1] == "BREAK"
    parsed = d.parse({d.extensions[0]: texts[d.extensions[0]]}, "station_r1" + d.extensions[0], robot)
    sets = [i for i in parsed.program.instructions if isinstance(i, SetSignal)]
    assert [(s.number, s.value) for s in sets] == [(3, True), (3, False)]
    with pytest.raises(ControllerSetupError, match="robot.controller.outputs.r1_z1_clear"):
        d.adapt(_planned(cell, robot, (ControllerOutput("r1_z1_clear", 10000),), 10000), robot)


def test_an_as_output_without_break_is_not_simulated(small: tuple[Any, Any]) -> None:
    cell, robot = small
    d = DIALECTS["as"]
    text = d.write(d.adapt(_planned(cell, robot, (ControllerOutput("r1_z1_clear", 3),)), robot), robot)[".as"]
    bare = text.replace("BREAK\r\n", "", 1).replace("  BREAK\r\n", "", 1)
    parsed = d.parse({".as": bare}, "station_r1.as", robot)
    assert any("without BREAK" in getattr(i, "text", "") for i in parsed.program.instructions)
