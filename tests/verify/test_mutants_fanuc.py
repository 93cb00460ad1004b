"""FANUC TP programs written with a convention the controller does not share are rejected by
`verify`, naming a line: each mutant is the placed process cell's program edited as a mistaken
writer would have written it (the robot's placement as the user frame, F and N swapped, the tool's
W and R exchanged, lengths in metres, joint values in radians, a position taught with another tool
or user frame number, the frame selections deleted); and the package-weld variant's SpotTool+
program with another weld schedule or gun."""

from __future__ import annotations

import math
import re
from collections.abc import Callable

import pytest
from controller_model.fanuc import run_fanuc
from verify_mutants import (
    Edit,
    Placed,
    detour_into_the_part,
    model_execution,
    placement_mm_zyx,
    read_execution,
)


def _placement_as_uframe(placed: Placed) -> dict[str, Edit]:
    xyz, zyx = placement_mm_zyx(placed.cell)
    values = [*xyz, zyx[2], zyx[1], zyx[0]]                      # X Y Z W P R
    return {"_FRAMES.ls": lambda t: re.sub(r"(PR\[41,)([1-6])(\]=)(-?[\d.]+)",
                                           lambda m: m[1] + m[2] + m[3] + f"{values[int(m[2]) - 1]:.4f}", t)}


def _flip_swapped(placed: Placed) -> dict[str, Edit]:
    return {".ls": lambda t: re.sub(r"CONFIG : '([FN])", lambda m: "CONFIG : '" + ("N" if m[1] == "F" else "F"), t)}


def _tool_w_r_exchanged(placed: Placed) -> dict[str, Edit]:
    def edit(t: str) -> str:
        w = re.search(r"PR\[40,4\]=(-?[\d.]+)", t)
        r = re.search(r"PR\[40,6\]=(-?[\d.]+)", t)
        assert w and r
        t = t.replace(f"PR[40,4]={w[1]}", "PR[40,4]=@R").replace(f"PR[40,6]={r[1]}", f"PR[40,6]={w[1]}")
        # The gun's W and R are both -90: an exchange alone changes nothing, so R is negated too
        # (a writer taking R about -z, as ROS-I FANUC arms turn J3 about -y).
        return t.replace("PR[40,4]=@R", f"PR[40,4]={-float(r[1]):.4f}")
    return {"_FRAMES.ls": edit}


def _targets_in_metres(placed: Placed) -> dict[str, Edit]:
    return {".ls": lambda t: re.sub(r"(\b[XYZ] =\s+)(-?[\d.]+)(  mm)", lambda m: m[1] + f"{float(m[2]) / 1000:.6f}" + m[3], t)}


def _joints_in_radians(placed: Placed) -> dict[str, Edit]:
    return {".ls": lambda t: re.sub(r"(\bJ\d=\s+)(-?[\d.]+)( deg)", lambda m: m[1] + f"{math.radians(float(m[2])):.6f}" + m[3], t)}


def _taught_with_tool_1(placed: Placed) -> dict[str, Edit]:
    return {".ls": lambda t: re.sub(r"(CONFIG[^\n]*\n)", r"\1", t.replace("UF : 3, UT : 2,\t\tCONFIG", "UF : 3, UT : 1,\t\tCONFIG", 1))}


def _selections_deleted(placed: Placed) -> dict[str, Edit]:
    return {".ls": lambda t: re.sub(r"^\s*\d+:\s+(UFRAME_NUM|UTOOL_NUM)=\d+ ;\r?\n", "", t, flags=re.MULTILINE)}


def _taught_in_user_frame_1(placed: Placed) -> dict[str, Edit]:
    return {".ls": lambda t: t.replace("UF : 3, UT : 2,\t\tCONFIG", "UF : 1, UT : 2,\t\tCONFIG", 1)}


MUTANTS = {
    "placement as the user frame": _placement_as_uframe,
    "F and N swapped": _flip_swapped,
    "tool W and R exchanged": _tool_w_r_exchanged,
    "targets in metres": _targets_in_metres,
    "joint values in radians": _joints_in_radians,
    "a position taught with tool 1": _taught_with_tool_1,
    "frame selections deleted": _selections_deleted,
    "a position taught in user frame 1": _taught_in_user_frame_1,
}

# The package variant (SpotTool+): s7 is welded with schedule 4 (0.5 s), s8 with schedule 7 (0.8 s).
PACKAGE_MUTANTS: dict[str, dict[str, Edit]] = {
    "s8 welded with schedule 4": {".ls": lambda t: t.replace("S=7,", "S=4,", 1)},
    "s7 welded with schedule 7": {".ls": lambda t: t.replace("S=4,", "S=7,", 1)},
    "another gun": {".ls": lambda t: t.replace("Equipment Number : 2 ;", "Equipment Number : 1 ;", 1)},
}


@pytest.mark.slow
@pytest.mark.parametrize("kind", sorted(MUTANTS))
def test_fanuc_mutant_is_rejected_with_a_line(placed: Placed, kind: str) -> None:
    report = placed.verify("fanuc", MUTANTS[kind](placed), kind.replace(" ", "_"))
    assert not report.clean, kind
    assert any(v.line is not None for v in report.violations), report.violations


@pytest.mark.slow
def test_the_written_fanuc_program_is_clean(placed: Placed) -> None:
    report = placed.verify("fanuc", {}, "unchanged")
    assert report.clean, report.violations


@pytest.mark.slow
@pytest.mark.parametrize("kind", sorted(PACKAGE_MUTANTS))
def test_fanuc_package_mutant_is_rejected_with_a_line(placed_package: Placed, kind: str) -> None:
    report = placed_package.verify("fanuc", PACKAGE_MUTANTS[kind], kind.replace(" ", "_"))
    assert not report.clean, kind
    assert any(v.line is not None for v in report.violations), report.violations


@pytest.mark.slow
def test_the_package_weld_program_is_clean_and_welds_with_spot(placed_package: Placed) -> None:
    text = placed_package.files["PLACED_PACKAGE.ls"]
    assert "SPOT Welding Equipment Number : 2 ;" in text
    assert re.search(r"L P\[\d+:s7\] \d+mm/sec FINE\r\n    :  SPOT\[SD=1,P=1,S=4,ED=1\]    ;\r\n\s+\d+:  !flange/s7 ;", text)
    assert "CALL SPOT_WELD" not in text and "SPOT_WELD.ls" not in placed_package.files
    report = placed_package.verify("fanuc", {}, "unchanged")
    assert report.clean, report.violations


# ------------------------------------------------------------------ what the controller executes
# Mutants of the program's flow, speeds and weld times (export/fanuc's docstring, export/flow.py):
# each is caught with the violation the controller's execution implies; labels and a jump to the
# statement after one still verify clean.

NL = "\r\n"
CALL1 = re.compile(r"^(\s*\d+:\s*CALL SPOT_WELD\(1,[\d.]+\) ;\r\n\s*\d+:\s*![^\r\n]*;)(?=\r\n)", re.MULTILINE)


def _statement(text: str) -> str:
    """A /MN line (the reader does not need the lines numbered in order)."""
    return f"   0:  {text} ;"


def _before_frames(text: str) -> dict[str, Edit]:
    """`text` before the program selects its frames, before any motion."""
    return {".ls": lambda t: re.sub(r"^(\s*\d+:\s*UFRAME_NUM=)", lambda m: _statement(text) + NL + m[1], t, count=1,
                                    flags=re.MULTILINE)}


def _around_weld1(before: str, after: str) -> dict[str, Edit]:
    return {".ls": lambda t: CALL1.sub(lambda m: NL.join(x for x in (before and _statement(before), m[1],
                                                                    after and _statement(after)) if x), t, count=1)}


def _before_first_line(text: str) -> Edit:
    return lambda t: re.sub(r"^(\s*\d+:L P\[)", lambda m: _statement(text) + NL + m[1], t, count=1, flags=re.MULTILINE)


def _detour_in_frames_program(placed: Placed) -> Edit:
    """The frames program moves too: a detour into the part and back, its positions in its /POS."""
    detour, back = detour_into_the_part(placed)

    def position(k: int, q: list[float]) -> str:
        values = [f"J{i}={v:>10.4f} deg" for i, v in enumerate(q, start=1)]
        return NL.join([f"P[{k}]{{", "   GP1:", "\tUF : 0, UT : 0,\t", "\t" + ",\t".join(values[:3]) + ",",
                        "\t" + ",\t".join(values[3:]), "};"])

    def edit(t: str) -> str:
        t = t.replace(NL + "/POS" + NL, NL + _statement("J P[1] 100% FINE") + NL + _statement("J P[2] 100% FINE") + NL
                      + "/POS" + NL + position(1, detour) + NL + position(2, back) + NL, 1)
        return t
    return edit


FLOW_MUTANTS: dict[str, tuple[Callable[[Placed], dict[str, Edit]], set[str]]] = {
    "ABORT before the first motion": (lambda p: _before_frames("ABORT"), {"flow"}),
    "END before the first motion": (lambda p: _before_frames("END"), {"flow"}),
    "PAUSE before the first motion": (lambda p: _before_frames("PAUSE"), {"flow"}),
    "END after the first weld": (lambda p: _around_weld1("", "END"), {"flow"}),
    "JMP over a weld": (lambda p: _around_weld1("JMP LBL[1]", "LBL[1]"), {"spot"}),
    "JMP back to a label": (lambda p: _around_weld1("LBL[1:again]", "JMP LBL[1]"), {"unsupported"}),
    "JMP under a condition": (lambda p: _around_weld1("IF R[1]=1,JMP LBL[1]", "LBL[1]"), {"unsupported"}),
    "colliding move inside the called frames program": (
        lambda p: {".ls": _before_first_line(f"CALL {p.stem('fanuc')}_FRAMES"), "_FRAMES.ls": _detour_in_frames_program(p)},
        {"collision"}),
    "call of an unknown program": (lambda p: {".ls": _before_first_line("CALL MYSTERY")}, {"unsupported"}),
    "mm/sec three times the line speed": (
        lambda p: {".ls": lambda t: re.sub(r"(L P\[\d+(?::[^\]]*)?\] )\d+mm/sec",
                                           lambda m: f"{m[1]}{round(3000 * p.cell.planner.tcp_speed)}mm/sec", t)}, {"speed"}),
    "cm/min three times the line speed": (
        lambda p: {".ls": lambda t: re.sub(r"(L P\[\d+(?::[^\]]*)?\] )\d+mm/sec",
                                           lambda m: f"{m[1]}{round(3 * 6000 * p.cell.planner.tcp_speed)}cm/min", t)},
        {"speed"}),
    "J at 300 %": (lambda p: {".ls": lambda t: re.sub(r"(J P\[\d+\] )100%", r"\g<1>300%", t)}, {"speed"}),
    "weld time in ms": (lambda p: {".ls": lambda t: re.sub(r"(CALL SPOT_WELD\(1,)([\d.]+)",
                                                            lambda m: f"{m[1]}{1000 * float(m[2]):.3f}", t, count=1)},
                        {"weld"}),
    "SPOT_WELD waits another time": (lambda p: {"SPOT_WELD.ls": lambda t: t.replace("WAIT AR[2] ;", "WAIT 500.00(sec) ;")},
                                     {"unsupported"}),
}


@pytest.mark.slow
@pytest.mark.parametrize("kind", sorted(FLOW_MUTANTS))
def test_fanuc_flow_mutant_is_caught(placed: Placed, kind: str) -> None:
    edit, expected = FLOW_MUTANTS[kind]
    report = placed.verify("fanuc", edit(placed), "flow_" + re.sub(r"\W+", "_", kind))
    assert not report.clean, kind
    assert expected & {v.kind for v in report.violations}, report.violations


@pytest.mark.slow
def test_fanuc_flow_the_controller_follows_exactly_is_clean(placed: Placed) -> None:
    """A label with a comment and a JMP to the statement after it change nothing the controller does."""
    def edit(t: str) -> str:
        return _before_first_line("LBL[7:approach]")(_before_first_line("JMP LBL[7]")(t))
    report = placed.verify("fanuc", {".ls": edit}, "flow_followed")
    assert report.clean, report.violations


# The controller model (tests/controller_model, written from the vendors' documents) runs the same
# mutants: the welds that run, the motions and where the program stops agree with robomax's reading.
MODEL_CHECKED = ("ABORT before the first motion", "END before the first motion", "PAUSE before the first motion",
                 "END after the first weld", "JMP over a weld", "colliding move inside the called frames program")


@pytest.mark.slow
@pytest.mark.parametrize("kind", MODEL_CHECKED)
def test_fanuc_flow_mutant_reads_as_the_controller_model_runs_it(placed: Placed, kind: str) -> None:
    edit, _ = FLOW_MUTANTS[kind]
    main, read = read_execution(placed, "fanuc", edit(placed), "model_" + re.sub(r"\W+", "_", kind))
    frames = main.with_name(main.stem + "_FRAMES.ls")
    run = run_fanuc(main.read_text(), name=main.name, called={frames.name: frames.read_text()})
    assert model_execution(run, "SPOT_WELD") == read
