"""FANUC TP programs written with a convention the controller does not share are rejected by
`verify`, naming a line: each mutant is the placed process cell's program edited as a mistaken
writer would have written it (the robot's placement as the user frame, F and N swapped, the tool's
W and R exchanged, lengths in metres, joint values in radians, a position taught with another tool
number, the frame selections deleted)."""

from __future__ import annotations

import math
import re

import pytest

from conftest import Edit, Placed, placement_mm_zyx


def _placement_as_uframe(placed: Placed) -> dict[str, Edit]:
    xyz, zyx = placement_mm_zyx(placed.cell)
    values = [*xyz, zyx[2], zyx[1], zyx[0]]                      # X Y Z W P R
    return {"_frames.ls": lambda t: re.sub(r"(PR\[41,)([1-6])(\]=)(-?[\d.]+)",
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
    return {"_frames.ls": edit}


def _targets_in_metres(placed: Placed) -> dict[str, Edit]:
    return {".ls": lambda t: re.sub(r"(\b[XYZ] = )(-?[\d.]+)(  mm)", lambda m: m[1] + f"{float(m[2]) / 1000:.6f}" + m[3], t)}


def _joints_in_radians(placed: Placed) -> dict[str, Edit]:
    return {".ls": lambda t: re.sub(r"(\bJ\d= )(-?[\d.]+)( deg)", lambda m: m[1] + f"{math.radians(float(m[2])):.6f}" + m[3], t)}


def _taught_with_tool_1(placed: Placed) -> dict[str, Edit]:
    return {".ls": lambda t: re.sub(r"(CONFIG[^\n]*\n)", r"\1", t.replace("UF : 3, UT : 2,\t\tCONFIG", "UF : 3, UT : 1,\t\tCONFIG", 1))}


def _selections_deleted(placed: Placed) -> dict[str, Edit]:
    return {".ls": lambda t: re.sub(r"^\s*\d+:\s+(UFRAME_NUM|UTOOL_NUM)=\d+ ;\n", "", t, flags=re.M)}


MUTANTS = {
    "placement as the user frame": _placement_as_uframe,
    "F and N swapped": _flip_swapped,
    "tool W and R exchanged": _tool_w_r_exchanged,
    "targets in metres": _targets_in_metres,
    "joint values in radians": _joints_in_radians,
    "a position taught with tool 1": _taught_with_tool_1,
    "frame selections deleted": _selections_deleted,
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
