"""The models on real programs from public repositories (tests/data/programs, see SOURCES.md there):
each is read without an exception, its motion subset is executed, and everything outside the
subset is reported at its line instead of being skipped."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from controller_model.common import FanucConfig, FloatArray, ProgramRun, pose_mm_zyx_deg
from controller_model.fanuc import run_fanuc
from controller_model.krl import run_krl
from controller_model.rapid import run_rapid
from controller_model.urscript import run_urscript

DATA = Path(__file__).resolve().parents[1] / "data" / "programs"
POS_TOL_M = 1e-9


def _text(name: str) -> str:
    return (DATA / name).read_text(encoding="utf-8", errors="replace")


def _krl(name: str, **kw: object) -> ProgramRun:
    """A KRL .src with its .dat (a smartPAD program's points and motion data)."""
    dat = name.replace(".src", ".dat")
    return run_krl(_text(name), _text(dat), src_name=name, dat_name=dat, **kw)   # type: ignore[arg-type]


READERS: dict[str, Callable[[str], ProgramRun]] = {
    "ros_rsi.src": lambda n: run_krl(_text(n), src_name=n),
    "style1app1opt1.src": _krl,
    "spindle_main.src": _krl,
    "Grey_T_ROB1.mod": lambda n: run_rapid({n: _text(n)}),
    "test_4.mod": lambda n: run_rapid({n: _text(n)}),
    "robodk_Program.mod": lambda n: run_rapid({n: _text(n)}, entry="Main"),
    "ros_movesm.ls": lambda n: run_fanuc(_text(n), name=n),
    "up222.ls": lambda n: run_fanuc(_text(n), name=n),
    "timing_debug.script": lambda n: run_urscript(_text(n), name=n),
}


def _known(T: FloatArray | None) -> FloatArray:
    assert T is not None, "the model left this frame undefined"
    return T


@pytest.mark.parametrize("name", sorted(READERS))
def test_every_issue_names_a_real_statement(name: str) -> None:
    run = READERS[name](name)
    lines = _text(name).splitlines()
    assert run.issues, "a real program outside the subset reads without a single issue"
    for issue in run.issues:
        assert issue.where.source == name
        text = lines[issue.where.line - 1].strip()
        assert text and issue.text.startswith(text), (issue, text)


def _unsupported_lines(run: ProgramRun) -> set[int]:
    return {i.where.line for i in run.unsupported}


def test_kuka_rsi_program() -> None:
    run = READERS["ros_rsi.src"]("ros_rsi.src")
    assert [m.joints_deg for m in run.motions] == [(0.0, -90.0, 90.0, 0.0, 90.0, 0.0)] * 2
    assert [c.name for c in run.calls] == ["RSI_MOVECORR"]   # a sensor-guided motion: recorded, not followed
    # RSI_CREATE / RSI_ON / RSI_OFF in assignments and the IF ... HALT ... ENDIF around each
    assert _unsupported_lines(run) == {72, 73, 74, 75, 78, 79, 80, 81, 87, 88, 89, 90}
    assert {i.kind for i in run.issues} == {"unsupported"}


def test_kuka_inline_form_program_moves_in_base_3() -> None:
    """KSS 8.3.43 inline forms: the fold of LIN P20 selects FDAT FP20 (TOOL_NO 1, BASE_NO 3, IPO_FRAME
    #BASE), so its target is the TCP in BASE_DATA[3]; the extTCP folds (IPO_FRAME #TCP) are reported."""
    base_3 = pose_mm_zyx_deg(1000.0, -500.0, 800.0, 90.0, 0.0, 0.0)
    tool_1 = pose_mm_zyx_deg(0.0, 0.0, 250.0, 0.0, 0.0, 0.0)
    run = _krl("style1app1opt1.src", tool_data={1: tool_1}, base_data={3: base_3})
    p20 = next(m for m in run.motions if m.where.line == 64)           # LIN XP20 C_DIS C_DIS
    xp20 = pose_mm_zyx_deg(-3850.82104, -108.397034, -435.544800, -178.432037, 0.654220462, -179.967712)
    assert_allclose(_known(p20.T_base_tcp), base_3 @ xp20, atol=POS_TOL_M)
    assert_allclose(_known(p20.T_flange_tcp), tool_1, atol=POS_TOL_M)
    assert p20.blend == "C_DIS C_DIS"
    external = {i.where.line for i in run.unsupported if "IPO_FRAME #TCP" in i.reason}
    assert external == {40, 47, 107, 118}                              # the BAS lines of the extTCP folds


def test_kuka_inline_form_program_of_kss_8_2() -> None:
    """Its HOME folds move to the controller's XHOME with FHOME, both in $config.dat, not given here."""
    run = READERS["spindle_main.src"]("spindle_main.src")
    undefined = {i.where.line for i in run.issues if i.kind == "undefined"}
    assert {24, 25, 27} <= undefined                  # FDAT_ACT=Fhome, BAS(#PTP_PARAMS,100), PTP Xhome


def test_abb_synchronised_program() -> None:
    run = READERS["Grey_T_ROB1.mod"]("Grey_T_ROB1.mod")
    first, second = run.motions[:2]
    assert len(run.motions) == 11 and first.statement == "MoveAbsJ"
    assert first.joints_deg == (82.467, -17.016, 48.414, 85.948, 96.306, -31.779)
    # DefaultFrame has identity frames, so the TCP is the robtarget; q = [0.5, 0.5, 0.5, 0.5]
    assert_allclose(_known(second.T_base_tcp)[:3, 3], [0.61391, 2.32615, 1.04068], atol=POS_TOL_M)
    assert_allclose(_known(second.T_base_tcp)[:3, :3], [[0, 0, 1], [1, 0, 0], [0, 1, 0]], atol=1e-12)
    # ConfL \Off, SyncMoveOn, SyncMoveOff, and the track (extax a) each MoveJ moves
    assert _unsupported_lines(run) == {11, 12, 24} | set(range(14, 24))


def test_abb_gripper_program() -> None:
    run = READERS["test_4.mod"]("test_4.mod")
    assert [m.statement for m in run.motions] == ["MoveJ", "MoveL", "MoveL", "MoveJ", "MoveJ", "MoveL"]
    assert [w.seconds for w in run.waits] == [None, 0.9, 1.0, 0.9, 1.0]
    assert run.waits[0].signal == "Stavbar_opt" and run.waits[0].state is False
    # the tool is custom_tool1's tframe
    assert_allclose(_known(run.motions[0].T_flange_tcp)[:3, 3], [-0.14418, -0.1544, 0.03477], atol=POS_TOL_M)
    # ConfL \Off, ConfJ \Off, IF, ENDIF, and extax a = 0 (an external axis, if there is one, goes to 0)
    assert _unsupported_lines(run) == {6, 7, 10, 12} | {m.where.line for m in run.motions}


def test_abb_program_in_a_work_object() -> None:
    """RoboDK's module: MoveAbsJ and MoveL with `,\\WObj:=Frame2` (Frame2's uframe 399.855 mm along x,
    100 mm up, its oframe identity): a target in Frame2 is the user frame's offset plus the target."""
    run = READERS["robodk_Program.mod"]("robodk_Program.mod")
    # STOP (line 28) stops the program until the operator starts it again: the cycle ends there
    assert run.stopped is not None and run.stopped.line == 28
    assert [m.statement for m in run.motions] == ["MoveAbsJ"] * 2 + ["MoveL"] * 2
    in_wobj0, in_frame2 = run.motions[2], run.motions[3]
    assert_allclose(_known(in_wobj0.T_base_tcp)[:3, 3], [0.018715, 0.147321, 0.458168], atol=POS_TOL_M)
    assert_allclose(_known(in_frame2.T_base_tcp)[:3, 3], [0.403136, 0.147321, 0.394993], atol=POS_TOL_M)
    assert_allclose(_known(in_frame2.T_base_user)[:3, 3], [0.399855, 0.0, 0.1], atol=POS_TOL_M)
    # the tool: TCP at (-30, 0, 40) mm, turned -60 deg about y (q = [cos 30, 0, -sin 30, 0])
    assert_allclose(_known(in_frame2.T_flange_tcp)[:3, 3], [-0.03, 0.0, 0.04], atol=POS_TOL_M)
    # ConfL \Off is outside the subset; without the STOP, the call of Subprog (not in the module)
    # is recorded and the module moves on
    assert _unsupported_lines(run) == {18}
    text = _text("robodk_Program.mod").replace("\t\tSTOP;\n", "\t\t! STOP;\n")
    going = run_rapid({"robodk_Program.mod": text}, entry="Main")
    assert going.stopped is None and [m.statement for m in going.motions] == ["MoveAbsJ"] * 2 + ["MoveL"] * 4
    assert [(c.name, c.where.line) for c in going.calls] == [("Subprog", 30)]


def test_fanuc_ros_relay_program() -> None:
    run = READERS["ros_movesm.ls"]("ros_movesm.ls")
    assert not run.motions            # its only motion goes to a position register
    assert _unsupported_lines(run) == {33, 43, 46}     # WAIT on a flag, J PR[...], JMP
    assert [(i.where.line, i.kind) for i in run.issues if i.kind != "unsupported"] == [(36, "undefined")]


def test_fanuc_backup_program() -> None:
    run = READERS["up222.ls"]("up222.ls")
    assert len(run.motions) == 25
    first = run.motions[0]
    assert isinstance(first.config, FanucConfig) and first.config.text == "N U T, 0, 0, 0"
    assert_allclose(_known(first.T_base_tcp)[:3, 3], [1.111865, 0.118787, 1.806347], atol=POS_TOL_M)
    R = _known(first.T_base_tcp)[:3, :3]
    w, p, r = np.radians([-70.737, 11.951, -35.487])
    Rz = np.array([[np.cos(r), -np.sin(r), 0], [np.sin(r), np.cos(r), 0], [0, 0, 1]])
    Ry = np.array([[np.cos(p), 0, np.sin(p)], [0, 1, 0], [-np.sin(p), 0, np.cos(p)]])
    Rx = np.array([[1, 0, 0], [0, np.cos(w), -np.sin(w)], [0, np.sin(w), np.cos(w)]])
    assert_allclose(R, Rz @ Ry @ Rx, atol=1e-12)
    # its tool frames live on the controller: each Cartesian motion reports UTOOL[n] as undefined
    assert sum(i.kind == "undefined" for i in run.issues) == 25
    # every motion line carries TB ..,P-SPS (a program run before the end of the motion), point logic
    # follows it, and positions move three more motion groups
    motion_lines = {m.where.line for m in run.motions}
    assert motion_lines <= _unsupported_lines(run)


def test_ur_polyscope_program() -> None:
    run = READERS["timing_debug.script"]("timing_debug.script")
    assert not run.motions
    unsupported = {i.where.line: i.text for i in run.unsupported}
    assert {179, 183} <= set(unsupported)           # movej(get_inverse_kin(...)): IK in the script
    assert unsupported[171] == "while (True):"
    assert all("run " in unsupported[line] for line in (46, 104, 141, 160, 170))   # threads started
