"""KRL programs written with a convention the controller does not share are rejected by `verify`,
naming a line: each mutant is the placed process cell's program edited as a mistaken writer would
have written it (the robot's placement as the base frame, the tool's angles in another rotation
order, lengths in metres, joint values in radians, the wrist flag flipped, the folds' FDAT selecting
tool 1 or base 0, or the lines that select the frames deleted).

What the controller does without them (BAS.SRC, krl.py's docstring): a fold without its FDAT_ACT
line runs BAS with the FDAT_ACT last assigned, so with every FDAT_ACT line gone the frames are the
controller's from an earlier run (unknown: the program selects none); a fold without its BAS line
changes no frame, so with every BAS line gone the INI fold's BAS(#INITMOV) frames stay in force:
TOOL_DATA[1] and $WORLD."""

from __future__ import annotations

import math
import re

import pytest
from scipy.spatial.transform import Rotation

from conftest import Edit, Placed, placement_mm_zyx

FRAME = re.compile(r"\{X (-?[\d.]+), Y (-?[\d.]+), Z (-?[\d.]+), A (-?[\d.]+), B (-?[\d.]+), C (-?[\d.]+)\}")


def _frame_text(xyz: list[float], zyx: list[float]) -> str:
    return "{X %.3f, Y %.3f, Z %.3f, A %.4f, B %.4f, C %.4f}" % (*xyz, *zyx)


def _placement_as_base(placed: Placed) -> dict[str, Edit]:
    xyz, zyx = placement_mm_zyx(placed.cell)
    return {"_frames.src": lambda t: re.sub(r"(BASE_DATA\[\d+\] = )\{[^}]*\}", lambda m: m[1] + _frame_text(xyz, zyx), t)}


def _tool_in_xyz_order(placed: Placed) -> dict[str, Edit]:
    def edit(t: str) -> str:
        def swap(m: re.Match[str]) -> str:
            a, b, c = (float(v) for v in m.groups()[3:])
            R = Rotation.from_euler("ZYX", [a, b, c], degrees=True)
            wrong = R.as_euler("XYZ", degrees=True)          # the angles of an X-Y-Z convention
            return _frame_text([float(v) for v in m.groups()[:3]], [float(v) for v in wrong])
        return re.sub(r"(?<=TOOL_DATA\[2\] = )" + FRAME.pattern, swap, t)
    return {"_frames.src": edit}


def _targets_in_metres(placed: Placed) -> dict[str, Edit]:
    return {".dat": lambda t: re.sub(r"(E6POS XP\d+=\{X )(-?[\d.]+)(,Y )(-?[\d.]+)(,Z )(-?[\d.]+)",
                                     lambda m: "".join([m[1], f"{float(m[2]) / 1000:.6f}", m[3], f"{float(m[4]) / 1000:.6f}",
                                                        m[5], f"{float(m[6]) / 1000:.6f}"]), t)}


def _joints_in_radians(placed: Placed) -> dict[str, Edit]:
    return {".dat": lambda t: re.sub(r"(\bA\d )(-?[\d.]+)", lambda m: m[1] + f"{math.radians(float(m[2])):.6f}", t)}


def _wrist_flag_flipped(placed: Placed) -> dict[str, Edit]:
    return {".dat": lambda t: re.sub(r"(E6POS XP\d+=\{[^}]*,S )(\d+)", lambda m: m[1] + str(int(m[2]) ^ 4), t, count=1)}


def _another_tool(placed: Placed) -> dict[str, Edit]:
    return {".dat": lambda t: t.replace("{TOOL_NO 2,", "{TOOL_NO 1,")}


def _robot_base(placed: Placed) -> dict[str, Edit]:
    """The folds select base 0: the targets, stated in the fixture's frame, are taken in the robot base."""
    return {".dat": lambda t: t.replace(",BASE_NO 3,", ",BASE_NO 0,")}


def _fdat_act_deleted(placed: Placed) -> dict[str, Edit]:
    return {".src": lambda t: re.sub(r"^FDAT_ACT=.*\n", "", t, flags=re.MULTILINE)}


def _bas_deleted(placed: Placed) -> dict[str, Edit]:
    return {".src": lambda t: re.sub(r"^BAS\(#(PTP|CP)_PARAMS,.*\n", "", t, flags=re.MULTILINE)}


MUTANTS = {
    "placement as the base frame": _placement_as_base,
    "tool angles in X-Y-Z order": _tool_in_xyz_order,
    "targets in metres": _targets_in_metres,
    "joint values in radians": _joints_in_radians,
    "wrist flag flipped": _wrist_flag_flipped,
    "FDAT selects tool 1": _another_tool,
    "FDAT selects base 0": _robot_base,
    "FDAT_ACT lines deleted": _fdat_act_deleted,
    "BAS lines deleted": _bas_deleted,
}


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore:Gimbal lock")     # the gun's -90/0/-90 has B = +-90 in X-Y-Z order
@pytest.mark.parametrize("kind", sorted(MUTANTS))
def test_krl_mutant_is_rejected_with_a_line(placed: Placed, kind: str) -> None:
    report = placed.verify("krl", MUTANTS[kind](placed), kind.replace(" ", "_"))
    assert not report.clean, kind
    assert any(v.line is not None for v in report.violations), report.violations


@pytest.mark.slow
def test_the_written_krl_program_is_clean(placed: Placed) -> None:
    report = placed.verify("krl", {}, "unchanged")
    assert report.clean, report.violations
