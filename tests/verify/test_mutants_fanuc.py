"""FANUC TP programs written with a convention the controller does not share are rejected by
`verify`, naming a line: each mutant is the placed process cell's program edited as a mistaken
writer would have written it (the robot's placement as the user frame, F and N swapped, the tool's
W and R exchanged, lengths in metres, joint values in radians, a position taught with another tool
or user frame number, the frame selections deleted); and the package-weld variant's SpotTool+
program with another weld schedule or gun."""

from __future__ import annotations

import math
import re

import pytest

from conftest import Edit, Placed, placement_mm_zyx


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
    return {".ls": lambda t: re.sub(r"^\s*\d+:\s+(UFRAME_NUM|UTOOL_NUM)=\d+ ;\r?\n", "", t, flags=re.M)}


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
