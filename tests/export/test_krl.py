"""KRL inline forms, both directions: what the reader makes of the statements inside a fold (as
BAS.SRC executes them, not the fold's text), the LIN speed the fold shows against the one the
program states, files as the controller writes them (CRLF, Windows-1252), and the spot package's
weld on the process cell (`weld: package`)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
import yaml

from robomax_py.errors import CellFileError, ProgramError
from robomax_py.export import DIALECTS, krl
from robomax_py.export.rebuild import rebuild
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import plan_cell
from robomax_py.program import (
    NULL_FRAME,
    UNSET_FRAME,
    Comment,
    FrameDef,
    Header,
    LinMove,
    Program,
    ProgramSetup,
    PtpMove,
    Spot,
)
from robomax_py.publish import publish
from robomax_py.robot import RobotModel
from robomax_py.safe_files import LIMITS, read_text
from robomax_py.verify import verify_program

REPO = Path(__file__).resolve().parents[2]
GOLDEN = REPO / "tests" / "golden" / "small_cell"

_E6POS = "{X 100.0,Y 0.0,Z 50.0,A 0.0,B 90.0,C 0.0,S 2,T 2,E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}"
_HOME = "{A1 0.0,A2 -90.0,A3 90.0,A4 0.0,A5 0.0,A6 0.0,E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}"
_LDAT = ("{VEL 0.2,ACC 50.0,APO_DIST 7.5,APO_FAC 50.0000,AXIS_VEL 100.000,AXIS_ACC 100.000,ORI_TYP #VAR,"
         "CIRC_TYP #BASE,JERK_FAC 50.0000,GEAR_JERK 50.0000,EXAX_IGN 0}")
# A smartPAD-style program: INI, a PTP to an axis point (tool 2, base 3), a LIN in base 0, a LIN whose
# FDAT_ACT line was deleted, a LIN whose BAS line was deleted, and an external-TCP LIN.
_SRC = """&ACCESS RVP
DEF folds( )
;FOLD INI;%{PE}
  ;FOLD BASISTECH INI
    BAS (#INITMOV,0 )
  ;ENDFOLD (BASISTECH INI)
  ;FOLD USER INI
    ;Make your modifications here
  ;ENDFOLD (USER INI)
;ENDFOLD (INI)
LIN XP9
;FOLD PTP P1 CONT Vel=100 % PDAT1 Tool[2]:gun Base[3]:plate;%{PE}%R 8.3.48,%MKUKATPBASIS,%CMOVE,%VPTP,%P 1:PTP, 2:P1, 3:C_DIS, 5:100, 7:PDAT1
$BWDSTART=FALSE
PDAT_ACT=PPDAT1
FDAT_ACT=FP1
BAS(#PTP_PARAMS,40)
PTP XP1 C_DIS
;ENDFOLD
;FOLD LIN P2 Vel=0.2 m/s CPDAT1 Tool[2]:gun Base[0];%{PE}%R 8.3.48,%MKUKATPBASIS,%CMOVE,%VLIN,%P 1:LIN, 2:P2, 3:, 5:0.2, 7:CPDAT1
$BWDSTART=FALSE
LDAT_ACT=LCPDAT1
FDAT_ACT=FP2
BAS(#CP_PARAMS,0.2)
LIN XP2 
;ENDFOLD
;FOLD LIN P3 CONT Vel=0.2 m/s CPDAT1 Tool[2]:gun Base[3]:plate;%{PE}%R 8.3.48,%MKUKATPBASIS,%CMOVE,%VLIN,%P 1:LIN, 2:P3, 3:C_DIS C_DIS, 5:0.2, 7:CPDAT1
$BWDSTART=FALSE
LDAT_ACT=LCPDAT1
BAS(#CP_PARAMS,0.2)
LIN XP3 C_DIS C_DIS
;ENDFOLD
;FOLD LIN P4 Vel=2 m/s CPDAT2 Tool[2]:gun Base[3]:plate;%{PE}%R 8.3.48,%MKUKATPBASIS,%CMOVE,%VLIN,%P 1:LIN, 2:P4, 3:, 5:2, 7:CPDAT2
$BWDSTART=FALSE
LDAT_ACT=LCPDAT2
FDAT_ACT=FP4
LIN XP4 
;ENDFOLD
;FOLD LIN P5 Vel=0.2 m/s CPDAT1 Tool[2]:gun Base[3]:plate extTCP;%{PE}%R 8.3.48,%MKUKATPBASIS,%CMOVE,%VLIN,%P 1:LIN, 2:P5, 3:, 5:0.2, 7:CPDAT1
$BWDSTART=FALSE
LDAT_ACT=LCPDAT1
FDAT_ACT=FP5
BAS(#CP_PARAMS,0.2)
LIN XP5 
;ENDFOLD
END
"""
_DAT = f"""DEFDAT folds
DECL E6AXIS XP1={_HOME}
DECL FDAT FP1={{TOOL_NO 2,BASE_NO 3,IPO_FRAME #BASE,POINT2[] " ",TQ_STATE FALSE}}
DECL PDAT PPDAT1={{VEL 100.000,ACC 60.000,APO_DIST 12.5,APO_MODE #CDIS,GEAR_JERK 50.0000,EXAX_IGN 0}}
DECL E6POS XP2={_E6POS}
DECL FDAT FP2={{TOOL_NO 2,BASE_NO 0,IPO_FRAME #BASE,POINT2[] " ",TQ_STATE FALSE}}
DECL LDAT LCPDAT1={_LDAT}
DECL LDAT LCPDAT2={_LDAT.replace("VEL 0.2", "VEL 2.0")}
DECL E6POS XP3={_E6POS}
DECL E6POS XP4={_E6POS}
DECL FDAT FP4={{TOOL_NO 2,BASE_NO 3,IPO_FRAME #BASE,POINT2[] " ",TQ_STATE FALSE}}
DECL E6POS XP5={_E6POS}
DECL FDAT FP5={{TOOL_NO 2,BASE_NO 3,IPO_FRAME #TCP,POINT2[] " ",TQ_STATE FALSE}}
DECL E6POS XP9={_E6POS}
ENDDAT
"""


@pytest.fixture(scope="module")
def kr125() -> RobotModel:
    return load_cell_robot(load_cell(REPO / "cells" / "cabin_flange.yaml"))


def _moves(parsed: Any) -> dict[int, Any]:
    """Instruction by the line of its statement (moves and not-simulated notes)."""
    return dict(zip(parsed.lines, parsed.program.instructions))


def test_the_statements_inside_the_folds_run_as_bas_src_says(kr125: RobotModel) -> None:
    parsed = krl.parse({".src": _SRC, ".dat": _DAT}, "folds.src", kr125)
    by_line = _moves(parsed)
    lines = [text.rstrip() for text in _SRC.splitlines()]

    def at(statement: str) -> Any:
        return by_line[lines.index(statement) + 1]

    # BAS(#INITMOV,0): $TOOL = TOOL_DATA[1], $BASE = $WORLD; $VEL.CP = DEF_VEL_CP 2 m/s
    first = at("LIN XP9")
    assert (first.tool, first.base, first.speed_mm_s) == ("TOOL_DATA[1]", NULL_FRAME, 2000.0)
    # PTP: Vel from BAS's argument (not the fold's 100 %), $ACC_AXIS = PDAT ACC ($ADAP_ACC #STEP2),
    # $APO.CDIS = APO_DIST (APO_MODE #CDIS)
    ptp = at("PTP XP1 C_DIS")
    assert isinstance(ptp, PtpMove) and (ptp.speed, ptp.accel, ptp.flyby_mm) == (0.4, 0.6, 12.5)
    # LIN: frames from its FDAT (BASE_NO 0: the robot base), speed from BAS, ACC -> the line's share
    lin = at("LIN XP2")
    assert isinstance(lin, LinMove)
    assert (lin.tool, lin.base, lin.speed_mm_s, lin.accel, lin.flyby_mm) == ("TOOL_DATA[2]", NULL_FRAME, 200.0, 0.5, 0.0)
    # FDAT_ACT deleted: BAS uses the FDAT_ACT last assigned (the previous fold's, base 0); APO_DIST
    assert (at("LIN XP3 C_DIS C_DIS").base, at("LIN XP3 C_DIS C_DIS").flyby_mm) == (NULL_FRAME, 7.5)
    # BAS deleted: nothing of the fold's data is applied; the frames and speed in force stay
    unapplied = at("LIN XP4")
    assert (unapplied.tool, unapplied.base, unapplied.speed_mm_s) == ("TOOL_DATA[2]", NULL_FRAME, 200.0)
    # IPO_FRAME #TCP: an external TCP is not simulated
    external = at("LIN XP5")
    assert isinstance(external, Comment) and "external TCP" in external.text
    # The fold says Vel=100 %, its BAS sets 40: noted, the statements run
    fold_line = next(i for i, t in enumerate(lines, start=1) if t.startswith(";FOLD PTP P1"))
    assert any(line == fold_line and "Vel 100 (BAS sets 40)" in text for line, text in parsed.ignored)
    # Comments inside folds are what the fold hides, not program comments
    assert not [i for i in parsed.program.instructions if isinstance(i, Comment) and "modifications" in i.text]


def test_no_fdat_act_before_bas_leaves_the_frames_unknown(kr125: RobotModel) -> None:
    src = _SRC.replace("FDAT_ACT=FP1\n", "").replace("FDAT_ACT=FP2\n", "")
    parsed = krl.parse({".src": src, ".dat": _DAT}, "folds.src", kr125)
    lin = next(i for i in parsed.program.instructions if isinstance(i, LinMove) and i.speed_mm_s == 200.0)
    assert (lin.tool, lin.base) == (UNSET_FRAME, UNSET_FRAME)


def _program(speed_mm_s: float) -> Program:
    header = Header("c", "kr125", "gun", 1.0, tuple(f"joint_a{i}" for i in range(1, 7)))
    tool = FrameDef("TOOL_DATA[2]", "tool", (0.0, 0.0, 200.0), (0.0, 0.0, 0.0), 2)
    return Program("c", header, (tool,), (
        PtpMove((0.0, -90.0, 90.0, 0.0, 0.0, 0.0)),
        LinMove((1000.0, 0.0, 1000.0), (0.0, 90.0, 0.0), "S010 T000010", speed_mm_s, tool="TOOL_DATA[2]"),
        Spot("s1", "seam", 0.0, 2, 7, package=True),
    ), ProgramSetup(weld="package", frame_names=(("TOOL_DATA[2]", "gun2"),)))


def test_the_fold_shows_the_lin_speed_to_a_millimetre_per_second(kr125: RobotModel) -> None:
    texts = krl.write(_program(123.456), kr125)
    src, dat = texts[".src"], texts[".dat"]
    assert ";FOLD LIN P2 Vel=0.123 m/s CPDAT1 Tool[2]:gun2 Base[0];" in src and "5:0.123, 7:CPDAT1" in src
    assert "BAS(#CP_PARAMS,0.123456)" in src and "DECL LDAT LCPDAT1={VEL 0.123456," in dat
    parsed = krl.parse(texts, "c.src", kr125)
    assert parsed.program.instructions == _program(123.456).instructions
    assert not [text for _, text in parsed.ignored if "fold" in text]      # the rounded Vel agrees


def test_a_package_weld_is_the_spot_packages_user_routine(kr125: RobotModel) -> None:
    texts = krl.write(_program(500.0), kr125)
    src, dat = texts[".src"], texts[".dat"]
    assert "  ;FOLD SPOTTECH INI\n    USERSPOT(#INIT)\n  ;ENDFOLD (SPOTTECH INI)" in src
    assert "\nUSERSPOT(#SPOT,SDAT1) ; seam/s1 gun 2 schedule 7\n" in src and "spot_weld" not in src
    assert "EXT  USERSPOT (S_COMMAND  :IN,SPOT_TYPE  :IN )" in dat
    assert "DECL SPOT_TYPE SDAT1={GUN 2,PAIR #FIRST,RETR #OPN,CLO_TM 0,PGNO1 7,PRESS1 0.0,PGNO2 0,PRESS2 0.0}" in dat
    # The data holds over the comment: SDAT1 says gun 3 schedule 5
    edited = {**texts, ".dat": dat.replace("{GUN 2,", "{GUN 3,").replace("PGNO1 7,", "PGNO1 5,")}
    spot = krl.parse(edited, "c.src", kr125).program.instructions[-1]
    assert spot == Spot("s1", "seam", 0.0, 3, 5, package=True)


def test_files_as_the_controller_writes_them_read_the_same(tmp_path: Path, kr125: RobotModel) -> None:
    """CRLF line ends and a Windows-1252 comment (KSS writes both)."""
    texts = {k: (GOLDEN / f"small_cell{k}").read_text() for k in (".src", ".dat", "_frames.src")}
    for key, text in texts.items():
        text = text.replace("; points of", "; Schweißpunkte:\n; points of") if key == ".dat" else text
        (tmp_path / f"small_cell{key}").write_bytes(text.replace("\n", "\r\n").encode("cp1252"))
    read = {k: read_text(tmp_path / f"small_cell{k}", LIMITS.program, ProgramError, "program file",
                         fallback=DIALECTS["krl"].fallback_encoding) for k in texts}
    assert "Schweißpunkte" in read[".dat"]
    assert krl.parse(read, "small_cell.src", kr125) == krl.parse(texts, "small_cell.src", kr125)
    with pytest.raises(ProgramError, match="not UTF-8 text"):
        read_text(tmp_path / "small_cell.dat", LIMITS.program, ProgramError, "program file")


# ------------------------------------------------------------------ the process cell, weld: package


@pytest.fixture(scope="module")
def package_cell(tmp_path_factory: pytest.TempPathFactory, write_process_cell) -> dict[str, Any]:  # type: ignore[no-untyped-def]
    folder = tmp_path_factory.mktemp("package")
    path = write_process_cell(folder, name="package_cell")
    data = yaml.safe_load(path.read_text())
    data["robot"]["controller"]["weld"] = "package"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    cell = load_cell(path)
    robot = load_cell_robot(cell)
    result = plan_cell(cell, robot)
    assert result.status == "planned", result.message
    return {"folder": folder, "path": path, "cell": cell, "robot": robot, "result": result}


@pytest.mark.slow
def test_package_welds_take_their_schedules_time(package_cell: dict[str, Any]) -> None:
    """s7 on schedule 4 (0.5 s), s8 on schedule 7 (0.8 s): the program names gun and schedule only,
    and the motion rebuilt from it welds each spot for its schedule's time (publish proves the rest)."""
    cell, robot = package_cell["cell"], package_cell["robot"]
    files, _ = publish(package_cell["result"], cell, robot, ("krl",))
    src, dat = files["package_cell.src"], files["package_cell.dat"]
    assert "USERSPOT(#SPOT,SDAT1) ; flange/s7 gun 2 schedule 4" in src
    assert "USERSPOT(#SPOT,SDAT2) ; flange/s8 gun 2 schedule 7" in src
    assert "spot_weld" not in src and ",PGNO1 4," in dat and ",PGNO1 7," in dat
    parsed = krl.parse({k: files[f"package_cell{k}"] for k in (".src", ".dat", "_frames.src")}, "package_cell.src",
                       robot)
    spots = [i for i in parsed.program.instructions if isinstance(i, Spot)]
    assert [(s.name, s.gun, s.schedule, s.time_s, s.package) for s in spots] == [
        ("s7", 2, 4, 0.0, True), ("s8", 2, 7, 0.0, True)]
    rebuilt = rebuild(parsed.program, cell, robot, "package_cell.src", parsed.lines, parsed.brand)
    assert not rebuilt.problems
    times = {s["name"]: round(s["t_leave"] - s["t_arrive"], 6) for s in rebuilt.spots}
    assert times == {"s7": 0.5, "s8": 0.8}
    for name, text in files.items():
        (package_cell["folder"] / name).write_text(text)
    report = verify_program(cell, robot, package_cell["folder"] / "package_cell.src")
    assert report.clean, report.violations


@pytest.mark.slow
def test_one_schedule_with_two_weld_times_is_refused(package_cell: dict[str, Any]) -> None:
    data = yaml.safe_load(package_cell["path"].read_text())
    for spot in data["seams"][0]["spots"]:
        if spot["name"] == "s8":
            spot["schedule"] = 4                 # s7's schedule, but welded 0.8 s instead of 0.5
    path = package_cell["folder"] / "one_schedule.yaml"
    data["name"] = "one_schedule"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    cell = load_cell(path)
    result = plan_cell(cell, package_cell["robot"])
    assert result.status == "planned", result.message
    with pytest.raises(CellFileError, match=r"robot\.controller\.weld.*schedule 4"):
        publish(result, cell, package_cell["robot"], ("krl",))
