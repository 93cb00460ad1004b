"""FANUC TP as the controller prints and loads it: program names, remarks, /ATTR and the statement
layout within the controller's limits (robomax_py/export/fanuc/ gives the sources), the reader on
real exports (tests/data/programs/SOURCES.md) and on SpotTool+ welds, and a cell whose names are far
longer than TP allows planned and proven."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
import yaml

from robomax_py.export import DIALECTS, fanuc
from robomax_py.export.fanuc import NAME_CHARS, REMARK_CHARS, program_name, remarks
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import plan_cell
from robomax_py.program import Comment, LinMove, Spot
from robomax_py.publish import publish
from robomax_py.robot import RobotModel

REPO = Path(__file__).resolve().parents[2]
DATA = REPO / "tests" / "data" / "programs"
TP_NAME = re.compile(r"^[A-Z][A-Z0-9_]*$")


@pytest.fixture(scope="module")
def kr125() -> RobotModel:
    return load_cell_robot(load_cell(REPO / "cells" / "cabin_flange.yaml"))


# ------------------------------------------------------------------------------------ names


@pytest.mark.parametrize(("name", "tp"), [("door-L 2", "DOOR_L_2"), ("7up", "P7UP"), ("_x", "P_X"),
                                          ("spot_weld", "SPOT_WELD_PROG"), ("grip", "GRIP_PROG"),
                                          ("small_cell", "SMALL_CELL")])
def test_program_names(name: str, tp: str) -> None:
    assert program_name(name) == tp


def test_a_long_name_is_cut_with_a_digest_and_its_frames_program_fits() -> None:
    a, b = "a" * 90 + "_left_door", "a" * 90 + "_right_door"
    for name in (a, b, a + "_baseline"):
        tp = program_name(name)
        assert TP_NAME.match(tp) and len(tp + fanuc.FRAMES_SUFFIX) <= NAME_CHARS, tp
        assert program_name(name) == tp                           # the same every time
    assert program_name(a) != program_name(b)
    assert program_name(a + "_baseline").endswith("_BASELINE")


# ---------------------------------------------------------------------------------- remarks


@pytest.mark.parametrize("text", [
    "robomax_py 0.1.0, cell process_cell, cell file sha256 " + "0123456789abcdef" * 4 + ", planned cycle 5.463 s",
    "flange/s7 gun 2 schedule 4",
    "seam_" + "x" * 70 + "/spot_" + "y" * 40 + " gun 1 schedule 12",
    "a b  c" * 20,
    "x" * 100,
])
def test_remarks_fit_and_join_back(text: str) -> None:
    pieces = remarks(text)
    assert all(0 < len(p) <= REMARK_CHARS and not p.endswith(" ") for p in pieces), pieces
    assert all(p.startswith("+") for p in pieces[1:]) and not pieces[0].startswith("+")
    assert pieces[0] + "".join(p[1:] for p in pieces[1:]) == text


def test_remarks_break_where_a_person_reads_them() -> None:
    assert remarks("robomax_py 0.1.0, cell process_cell, cell file sha256") == [
        "robomax_py 0.1.0,", "+ cell process_cell,", "+ cell file sha256"]
    assert remarks("flange_seam_on_the_left_hand_door_inner_panel/spot_number_seven_near_the_hinge gun 2") == [
        "flange_seam_on_the_left_hand_", "+door_inner_panel/", "+spot_number_seven_near_the_", "+hinge gun 2"]


# ------------------------------------------------------------------------- a cell's programs


def _statements(text: str) -> list[str]:
    mn = text.split("/MN\r\n", 1)[1].split("/POS\r\n", 1)[0]
    return [line for line in mn.split("\r\n") if re.match(r"^\s*\d+:", line)]


@pytest.fixture(scope="module")
def long_names(tmp_path_factory: pytest.TempPathFactory, write_process_cell) -> dict[str, str]:  # type: ignore[no-untyped-def]
    """The process cell named with 100 characters, its seam and a spot with long names."""
    folder = tmp_path_factory.mktemp("long")
    name = "door_assembly_station_" + "x" * 70 + "_left_v2"
    assert len(name) == 100
    path = write_process_cell(folder, name=name)
    data = yaml.safe_load(path.read_text())
    data["seams"][0]["name"] = "flange_seam_on_the_left_hand_door_inner_panel"
    data["seams"][0]["spots"][0]["name"] = "spot_number_seven_near_the_hinge"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    cell = load_cell(path)
    robot = load_cell_robot(cell)
    result = plan_cell(cell, robot)
    assert result.status == "planned", result.message
    files, _ = publish(result, cell, robot, ("fanuc",))
    return files


@pytest.mark.slow
def test_long_names_stay_within_the_controllers_limits(long_names: dict[str, str]) -> None:
    programs = {f: t for f, t in long_names.items() if f.endswith(".ls")}
    assert len(programs) == 3                                     # main, frames setup, SPOT_WELD
    for file, text in programs.items():
        assert text.endswith("\r\n") and "\n" not in text.replace("\r\n", "")
        prog = re.match(r"^/PROG  (\S+)\r\n", text)
        assert prog and f"{prog.group(1)}.ls" == file and TP_NAME.match(prog.group(1))
        assert len(prog.group(1)) <= NAME_CHARS
        comment = re.search(r'^COMMENT\t\t= "([^"]*)";', text, re.MULTILINE)
        assert comment and len(comment.group(1)) <= 16
        statements = _statements(text)
        assert f"LINE_COUNT\t= {len(statements)};" in text
        for line in statements:
            remark = re.match(r"^\s*\d+:  !(.*) ;$", line)
            if remark:
                assert len(remark.group(1)) <= REMARK_CHARS, line
        for label in re.findall(r"P\[\d+:([^\]]*)\]", text):
            assert len(label.strip('"')) <= 16
    main = next(t for f, t in programs.items() if "CALL SPOT_WELD" in t)
    # The long seam/spot label continues over remarks (publish proved it reads back whole), and the
    # weld position carries the spot's name cut to 16 characters.
    assert re.search(r"L P\[\d+:spot_number_seve\] \d+mm/sec FINE    ;\r\n\s+\d+:  CALL SPOT_WELD\(1,\.500\) ;\r\n"
                     r"\s+\d+:  !flange_seam_on_the_left_hand_ ;\r\n\s+\d+:  !\+door_inner_panel/ ;", main), main


# ------------------------------------------------------------------------- real exports read


def _read(name: str, robot: RobotModel, text: str | None = None):  # type: ignore[no-untyped-def]
    text = (DATA / name).read_text() if text is None else text
    return DIALECTS["fanuc"].parse({".ls": text}, name, robot)


def test_a_real_export_reads_with_its_spacing(kr125: RobotModel) -> None:
    """home.ls (R-30iB V8.30): `/PROG  HOME<tab>  Macro`, an empty /APPL, `   3:J P[1] 100% FINE    ;`
    to a Cartesian position: the joint move to a Cartesian point is reported, not guessed."""
    parsed = _read("home.ls", kr125)
    assert parsed.program.name == "HOME"
    assert [type(i) for i in parsed.program.instructions] == [Comment]
    assert parsed.lines == (25,) and parsed.ignored == ((25, "J P[1] 100% FINE"),)


def test_motions_with_register_speeds_are_reported(kr125: RobotModel) -> None:
    """gratowanie.ls: every motion is inside an IF, has an Offset or a speed from a register;
    each is reported as not simulated (none dropped without a word)."""
    parsed = _read("gratowanie.ls", kr125)
    motions = [line for line, text in parsed.ignored if re.match(r"^[JL] ", text)]
    assert motions == [30, 33, 34, 36, 42, 45, 46, 48]


def _unconditional(text: str) -> str:
    """gratowanie.ls with the IF ... THEN / ENDIF around gripper 1's motions made remarks (inside a
    condition a motion is reported, not read) and its speed register replaced by a number."""
    text = text.replace("L P[1] R[26:posuw gratow]mm/sec FINE", "L P[1] 250mm/sec FINE")
    return text.replace("IF (R[1:stan chwytaka 1]=1) THEN ;", "!if gripper 1 ;").replace("  15:  ENDIF ;", "  15:  !endif ;")


def test_a_position_in_user_frame_7_is_read_relative_to_uframe_7(kr125: RobotModel) -> None:
    """gratowanie.ls without its first IF, its speed register replaced by a number: P[1] (UF : 7,
    UT : 1) after UFRAME_NUM=7 / UTOOL_NUM=1 is a LIN in UFRAME[7] with UTOOL[1], the values as
    exported; the rebuild composes it with the controller's UFRAME[7] (`frame_name`)."""
    text = _unconditional((DATA / "gratowanie.ls").read_text())
    parsed = _read("gratowanie.ls", kr125, text)
    moves = [i for i in parsed.program.instructions if isinstance(i, LinMove)]
    assert len(moves) == 1
    move = moves[0]
    assert (move.base, move.tool, move.config, move.speed_mm_s) == ("UFRAME[7]", "UTOOL[1]", "N U T, 0, 0, 0", 250.0)
    np.testing.assert_allclose(move.position_mm, (856.686, 197.4, 172.511))
    np.testing.assert_allclose(move.zyx_deg, (142.594, 87.946, -126.099))      # R, P, W
    frame = fanuc.FrameDef("fixture", "base", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), 7)
    assert fanuc.frame_name(frame) == move.base


def test_linear_speeds_are_read_in_their_units(kr125: RobotModel) -> None:
    """A linear move's speed in mm/sec, cm/min or inch/min is a TCP speed (mm/s); one stated by the
    move's time (sec) or its orientation speed (deg/sec) is reported, not guessed."""
    base = _unconditional((DATA / "gratowanie.ls").read_text())
    speeds = {}
    for unit, value in (("mm/sec", "250"), ("cm/min", "1500"), ("inch/min", "590.551")):
        parsed = _read("gratowanie.ls", kr125, base.replace("L P[1] 250mm/sec FINE", f"L P[1] {value}{unit} FINE"))
        (move,) = [i for i in parsed.program.instructions if isinstance(i, LinMove)]
        speeds[unit] = move.speed_mm_s
    assert speeds["mm/sec"] == speeds["cm/min"] == 250.0 and abs(speeds["inch/min"] - 250.0) < 1e-3
    for unit in ("sec", "deg/sec"):
        parsed = _read("gratowanie.ls", kr125, base.replace("L P[1] 250mm/sec FINE", f"L P[1] 2{unit} FINE"))
        assert not any(isinstance(i, LinMove) for i in parsed.program.instructions)
        assert any(f"speed in {unit}" in i.text for i in parsed.program.instructions if isinstance(i, Comment))


def test_a_position_in_another_user_frame_is_an_alarm(kr125: RobotModel) -> None:
    text = _unconditional((DATA / "gratowanie.ls").read_text())
    text = text.replace("UF : 7, UT : 1,", "UF : 3, UT : 1,")
    parsed = _read("gratowanie.ls", kr125, text)
    alarms = [i.text for i in parsed.program.instructions if isinstance(i, Comment) and "mismatch" in i.text]
    assert alarms and "UFRAME 3 is not the active UFRAME_NUM 7" in alarms[0]


SPOT_PROGRAM = """/PROG  S012WELD
/ATTR
OWNER\t\t= MNEDITOR;
COMMENT\t\t= "";
PROG_SIZE\t= 900;
CREATE\t\t= DATE 21-07-09  TIME 07:32:38;
MODIFIED\t= DATE 21-08-01  TIME 23:39:36;
FILE_NAME\t= S012POUN;
VERSION\t\t= 0;
LINE_COUNT\t= 7;
MEMORY_SIZE\t= 900;
PROTECT\t\t= READ_WRITE;
TCD:  STACK_SIZE\t= 0,
      TASK_PRIORITY\t= 50,
      TIME_SLICE\t= 0,
      BUSY_LAMP_OFF\t= 0,
      ABORT_REQUEST\t= 0,
      PAUSE_REQUEST\t= 0;
DEFAULT_GROUP\t= 1,*,*,*,*;
CONTROL_CODE\t= 00000000 00000000;
/APPL
  SPOT : TRUE ; 
  SPOT Welding Equipment Number : 2 ;
/MN
   1:  UFRAME_NUM=0 ;
   2:  UTOOL_NUM=1 ;
   3:L P[1:W_PT00045027_017] 2000mm/sec FINE
    :  SPOT[SD=6,P=15,t=5.3,S=207,ED=6]    ;
   4:  !flange/s7 ;
   5:L P[2] 2000mm/sec FINE
    :  SPOT[SD=3,P=1,S=1,ED=3]    ;
   6:L P[2] 2000mm/sec FINE RTCP
    :  SPOT[SD=3,P=1,S=1,ED=3]    ;
   7:  ! WELD 3 ;
/POS
P[1:"W_PT00045027_017"]{
   GP1:
\tUF : 0, UT : 1,\t\tCONFIG : 'N U T, 0, 0, 0',
\tX =  1050.000  mm,\tY =  -300.000  mm,\tZ =   425.000  mm,
\tW =   180.000 deg,\tP =     -.234 deg,\tR =      .606 deg
};
P[2]{
   GP1:
\tUF : 0, UT : 1,\t\tCONFIG : 'N U T, 0, 0, 0',
\tX =  1050.000  mm,\tY =  -100.000  mm,\tZ =   425.000  mm,
\tW =   180.000 deg,\tP =     0.000 deg,\tR =     0.000 deg
};
/END
""".replace("\n", "\r\n")


def test_spottool_welds_read_as_package_welds(kr125: RobotModel) -> None:
    """The layout of SpotTool+ exports (the option on the continuation line, the equipment in
    /APPL, a servo gun's t=): a LIN, then the package weld of gun 2 and schedule S, named by the
    remark after it; without a remark a weld of an unnamed seam; RTCP moves the part past the gun:
    reported, not simulated."""
    parsed = _read("S012WELD.ls", kr125, SPOT_PROGRAM)
    ins = parsed.program.instructions
    assert isinstance(ins[0], LinMove) and ins[0].zyx_deg == (0.606, -0.234, 180.0)
    assert ins[1] == Spot("s7", "flange", 0.0, 2, 207, package=True)
    assert isinstance(ins[2], LinMove) and ins[3] == Spot("spot2", "unnamed", 0.0, 2, 1, package=True)
    assert isinstance(ins[4], Comment) and "RTCP" in ins[4].text
    assert parsed.lines[:4] == (27, 27, 30, 30)


def test_a_spot_without_a_schedule_is_an_error(kr125: RobotModel) -> None:
    from robomax_py.errors import ProgramError

    with pytest.raises(ProgramError, match="no weld schedule"):
        _read("S012WELD.ls", kr125, SPOT_PROGRAM.replace("S=207,", ""))
