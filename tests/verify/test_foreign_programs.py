"""Every dialect's reader on programs written by others (tests/data/programs, SOURCES.md): it reads
their motion subset, and reports what it cannot simulate (a motion to a register or an
expression, circles, moves inside loops and conditions, jumps, calls) instead of guessing; `verify`
then says the program cannot be verified, never that it is clean."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.spatial.transform import Rotation

from robomax_py.errors import ProgramError
from robomax_py.export import dialect_for_file, rapid
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.program import Comment, LinMove, PtpMove, Wait, WaitFor, lin_pose
from robomax_py.robot import RobotModel
from robomax_py.safe_files import LIMITS, read_text
from robomax_py.verify import verify_program

DATA = Path(__file__).resolve().parents[1] / "data" / "programs"
REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def kr125() -> tuple[object, RobotModel]:
    cell = load_cell(REPO / "cells" / "cabin_flange.yaml")
    return cell, load_cell_robot(cell)


def _read(name: str, robot: RobotModel):  # type: ignore[no-untyped-def]
    """The program's files (a KRL .src with its .dat) as `verify` reads them."""
    path = DATA / name
    dialect = dialect_for_file(path.suffix)
    assert dialect is not None
    texts = {ext: read_text(path.with_suffix(ext), LIMITS.program, ProgramError, "program file",
                            fallback=dialect.fallback_encoding)
             for ext in dialect.extensions if path.with_suffix(ext).exists()}
    return dialect.parse(texts, str(path), robot)


def _unsimulated(parsed) -> list[tuple[int, str]]:  # type: ignore[no-untyped-def]
    return [(line, ins.text) for ins, line in zip(parsed.program.instructions, parsed.lines)
            if isinstance(ins, Comment) and ins.text.startswith("not simulated")]


def _count(parsed, kind: type) -> int:  # type: ignore[no-untyped-def]
    return sum(isinstance(i, kind) for i in parsed.program.instructions)


def test_krl_rsi_program(kr125) -> None:  # type: ignore[no-untyped-def]
    parsed = _read("ros_rsi.src", kr125[1])
    assert parsed.program.name == "RSI_AxisCorr"
    moves = [i for i in parsed.program.instructions if isinstance(i, PtpMove)]
    assert moves[0].target_deg == (0.0, -90.0, 90.0, 0.0, 90.0, 0.0)   # PTP {A1 0, A2 -90, ...}
    assert any("RSI_MOVECORR" in text for _, text in _unsimulated(parsed))   # sensor-guided motion
    assert parsed.ignored                                                    # BAS, RSI calls, IF blocks


def test_krl_smartpad_program_selects_its_frames_by_fdat(kr125) -> None:  # type: ignore[no-untyped-def]
    """KSS 8.3.43 inline forms (CRLF): each fold's FDAT selects tool 1 and base 3, so the LIN to P20
    is relative to BASE_DATA[3]; the folds with IPO_FRAME #TCP (extTCP) are an external TCP."""
    parsed = _read("style1app1opt1.src", kr125[1])
    assert parsed.program.name == "style1app1opt1"
    lins = [(line, i) for i, line in zip(parsed.program.instructions, parsed.lines) if isinstance(i, LinMove)]
    line, p20 = lins[0]
    assert line == 64 and p20.position_mm == (-3850.821, -108.397, -435.545)       # LIN XP20 C_DIS C_DIS
    assert (p20.tool, p20.base) == ("TOOL_DATA[1]", "BASE_DATA[3]")
    assert p20.speed_mm_s == 2000.0 and p20.flyby_mm == 100.0        # BAS(#CP_PARAMS,2), LCPDAT8 APO_DIST 100
    assert p20.config == "S010 T100010"                               # S 2, T 34
    texts = dict(_unsimulated(parsed))
    assert "external TCP" in texts[41] and "external TCP" in texts[48]       # PTP XP0, LIN XP8
    assert texts[78] == "not simulated: LIN XP19"                              # inside IF ... ELSE
    assert WaitFor("NUT_READY", None) in parsed.program.instructions           # WAIT FOR NUT_READY== TRUE
    assert not [t for _, t in parsed.ignored if "fold" in t]                   # its folds say what they do


def test_krl_smartpad_program_of_kss_8_2(kr125) -> None:  # type: ignore[no-untyped-def]
    """KSS 8.2.19: the HOME fold moves to the controller's global XHOME, the rest loops."""
    parsed = _read("spindle_main.src", kr125[1])
    assert parsed.program.name == "Spindle_MAIN"
    texts = dict(_unsimulated(parsed))
    assert texts[19].startswith("not simulated: PTP $AXIS_ACT")
    assert "global data" in texts[27]                                          # PTP Xhome
    assert texts[60] == "not simulated: PTP Xp1"                               # inside loop ... endloop
    assert not [i for i in parsed.program.instructions if isinstance(i, (PtpMove, LinMove))]


def test_rapid_moveabsj_program(kr125) -> None:  # type: ignore[no-untyped-def]
    parsed = _read("Grey_T_ROB1.mod", kr125[1])
    assert parsed.program.name == "Grey_T_ROB1"
    (first,) = [i for i in parsed.program.instructions if isinstance(i, PtpMove)]
    assert first.target_deg == (82.467, -17.016, 48.414, 85.948, 96.306, -31.779)
    assert first.flyby_mm == 0.0                                             # fine
    assert len([t for _, t in _unsimulated(parsed) if "MoveJ" in t]) == 10    # MoveJ to robtargets
    assert [f.name for f in parsed.program.frames] == ["DefaultGHTool", "DefaultFrame"]


def test_rapid_program_with_conditions(kr125) -> None:  # type: ignore[no-untyped-def]
    parsed = _read("test_4.mod", kr125[1])
    lins = [i for i in parsed.program.instructions if isinstance(i, LinMove)]
    assert lins[0].position_mm == (25.0, 540.0, 45.8)
    assert lins[0].speed_mm_s == 100.0 and lins[0].flyby_mm == 1.0          # speeddata Work, zone z1
    assert _count(parsed, Wait) == 4                                        # WaitTime 0.9 and 1, twice (after ENDIF)
    lines = [line for line, text in _unsimulated(parsed)]
    assert 11 in lines                                                      # WaitDI inside IF ... ENDIF
    tool = parsed.program.frames[0]
    assert tool.name == "custom_tool1" and tool.xyz_mm == (-144.18, -154.4, 34.77)


def _T(xyz_mm: list[float], q_wxyz: list[float]) -> np.ndarray:
    """A RAPID pose [[x, y, z], [q1, q2, q3, q4]] (q1 = w) as (4, 4) in metres, by scipy."""
    w, x, y, z = q_wxyz
    T = np.eye(4)
    T[:3, :3] = Rotation.from_quat([x, y, z, w]).as_matrix()
    T[:3, 3] = np.asarray(xyz_mm) / 1000.0
    return T


def _assert_pose(T: np.ndarray, want: np.ndarray) -> None:
    assert_allclose(T[:3, 3], want[:3, 3], atol=1e-6)                                 # 1 µm
    assert Rotation.from_matrix(T[:3, :3].T @ want[:3, :3]).magnitude() < 1e-6


def test_rapid_robodk_program_in_its_work_object(kr125) -> None:  # type: ignore[no-untyped-def]
    """RoboDK's module moves in Frame2 (a user frame 399.855 mm along x, 100 mm up) and once in
    WObj0: each target lands at uframe · oframe · target, with the tool the statement names. Its
    `STOP;` stops the program until the operator starts it again: the cycle verify checks ends
    there (reported); without that line (as its comment offers) the call of Subprog, which the
    module does not define, is reported and the lines after it are read."""
    stopped = _read("robodk_Program.mod", kr125[1])
    assert [(line, kind) for line, kind, _ in stopped.problems] == [(28, "flow")]
    assert sum(isinstance(i, LinMove) for i in stopped.program.instructions) == 2
    text = (DATA / "robodk_Program.mod").read_text()
    assert "\t\tSTOP;\n" in text
    parsed = rapid.parse({".mod": text.replace("\t\tSTOP;\n", "\t\t! STOP;\n")}, "robodk_Program.mod", kr125[1])
    assert not parsed.problems
    assert [t for _, t in _unsimulated(parsed)] == [("not simulated: Subprog (a call of Subprog, which neither "
                                                      "the program nor its companion files define)")]
    frames = {f.name: f for f in parsed.program.frames}
    assert set(frames) == {"Tool", "Frame2"}
    lins = [i for i in parsed.program.instructions if isinstance(i, LinMove)]
    assert [(lin.tool, lin.base) for lin in lins] == [("Tool", ""), ("Tool", "Frame2"), ("Tool", "Frame2"),
                                                      ("Tool", "Frame2")]
    q = [0.0, -0.97969618, 0.0, 0.20048792]
    _assert_pose(lin_pose(lins[0]), _T([18.715, 147.321, 458.168], q))
    uframe = _T([399.855, 0.0, 100.0], [1.0, 0.0, 0.0, 0.0])
    _assert_pose(frames["Frame2"].pose @ lin_pose(lins[1]), uframe @ _T([3.281, 147.321, 294.993], q))
    _assert_pose(frames["Tool"].pose, _T([-30.0, 0.0, 40.0], [0.86602540, 0.0, -0.5, 0.00000001]))
    moves = [i for i in parsed.program.instructions if isinstance(i, PtpMove)]
    assert moves[1].target_deg[4] == -56.1147                                 # `,\\WObj:=` on MoveAbsJ: harmless


def test_rapid_calibration_module_as_the_data_module(kr125) -> None:  # type: ignore[no-untyped-def]
    """SMR1's calibration module (TASK PERS work objects whose oframe is the calibrated one, CRLF)
    loaded beside a main module: a target in Mandrell lands at uframe · oframe · target."""
    main = ("MODULE Main\n  PROC main()\n    MoveAbsJ [[0, -30, 30, 0, 60, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]], "
            "v100, fine, Gripper;\n    MoveL [[100, -50, 20], [0.7071068, 0, 0.7071068, 0], [0, 0, 0, 0], "
            "[9E9, 9E9, 9E9, 9E9, 9E9, 9E9]], v100, fine, Gripper_Sleeve \\WObj:=Mandrell;\n  ENDPROC\nENDMODULE\n")
    data = (DATA / "smr1_CalibData.mod").read_text(encoding="utf-8")
    parsed = rapid.parse({".mod": main, rapid.FRAMES_FILE: data}, "Main.mod", kr125[1])
    frames = {f.name: f for f in parsed.program.frames}
    assert {"Gripper", "Sleeves", "Mandrell", "Laser", "Gripper_Sleeve"} <= set(frames)
    (lin,) = [i for i in parsed.program.instructions if isinstance(i, LinMove)]
    assert (lin.tool, lin.base) == ("Gripper_Sleeve", "Mandrell")
    uframe = _T([0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0])
    oframe = _T([2812.88, -226.05, 592.36], [0.27444, 0.27271, 0.64992, 0.65415])    # scipy normalises it
    target = _T([100.0, -50.0, 20.0], [0.7071068, 0.0, 0.7071068, 0.0])
    _assert_pose(frames["Mandrell"].pose @ lin_pose(lin), uframe @ oframe @ target)
    _assert_pose(frames["Gripper_Sleeve"].pose, _T([0.0, 6.4, 1700.0], [1.0, -0.00161, 0.0, 0.0]))


def test_fanuc_streaming_program(kr125) -> None:  # type: ignore[no-untyped-def]
    parsed = _read("ros_movesm.ls", kr125[1])
    texts = [t for _, t in _unsimulated(parsed)]
    assert any("PR[2" in t for t in texts)                                   # J to a position register
    assert any(t.startswith("not simulated: JMP LBL[10] (a jump back") for t in texts)   # a loop


def test_fanuc_production_program(kr125) -> None:  # type: ignore[no-untyped-def]
    parsed = _read("up222.ls", kr125[1])
    assert parsed.program.name == "UP222"
    lins = [i for i in parsed.program.instructions if isinstance(i, LinMove)]
    assert lins[0].position_mm == (344.99, -1889.465, -357.235)              # P[12], GP1 only
    assert lins[0].zyx_deg == (-132.732, 62.119, -86.967)                    # R, P, W
    assert lins[0].speed_mm_s == 1500.0 and lins[0].config == "N U T, 0, 0, 0"
    texts = [t for _, t in _unsimulated(parsed)]
    assert any(t.startswith("not simulated: J P[1]") for t in texts)         # J to a Cartesian point
    assert any("CALL MAKRO050" in t for t in texts)                          # calls may move


def test_urscript_polyscope_program(kr125) -> None:  # type: ignore[no-untyped-def]
    parsed = _read("timing_debug.script", kr125[1])
    assert parsed.program.name == "timing_debug"
    assert parsed.program.frames[0].xyz_mm == (0.0, 0.0, 0.0)               # set_tcp(p[0, ...])
    texts = [t for _, t in _unsimulated(parsed)]
    assert len([t for t in texts if "movej(get_inverse_kin" in t]) == 2       # inside while, to an expression


@pytest.mark.parametrize("name", ["ros_rsi.src", "style1app1opt1.src", "spindle_main.src", "Grey_T_ROB1.mod",
                                  "test_4.mod", "ros_movesm.ls", "up222.ls", "timing_debug.script"])
def test_verify_never_calls_them_clean(kr125, name: str, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    cell, robot = kr125
    program = tmp_path / name
    for sibling in DATA.glob(f"{Path(name).stem}.*"):        # a KRL .src with its .dat
        (tmp_path / sibling.name).write_bytes(sibling.read_bytes())
    from robomax_py.errors import ProgramError

    try:
        report = verify_program(cell, robot, program)
    except ProgramError:                     # bad input is an acceptable answer too (any other error fails)
        return
    assert not report.clean
    assert any(v.kind == "unsupported" and v.line is not None for v in report.violations)
