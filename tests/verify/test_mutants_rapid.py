"""RAPID modules written with a convention the controller does not share are rejected by `verify`,
naming a line: each mutant is the placed process cell's module edited as a mistaken writer would
have written it (the robot's placement as the work object's user frame, quaternions in x-y-z-w
order, the targets' rotations in another order, lengths in metres, joint values in radians, the
wrist bit of cfx flipped, the work object or the tool left out, the data module not loaded)."""

from __future__ import annotations

import math
import re

import pytest
from conftest import Edit, Placed, placement_mm_zyx
from scipy.spatial.transform import Rotation

from robomax_py.verify import verify_program

QUAT = r"\[(-?[\d.]+), (-?[\d.]+), (-?[\d.]+), (-?[\d.]+)\]"


def _quat_text(q: list[float]) -> str:
    return "[" + ", ".join(f"{v:.9f}" for v in q) + "]"


def _placement_as_uframe(placed: Placed) -> dict[str, Edit]:
    xyz, zyx = placement_mm_zyx(placed.cell)
    x, y, z, w = Rotation.from_euler("ZYX", zyx, degrees=True).as_quat()
    uframe = f"[[{xyz[0]:.3f}, {xyz[1]:.3f}, {xyz[2]:.3f}], {_quat_text([w, x, y, z])}]"
    return {"_frames.mod": lambda t: re.sub(r'(wobjdata \w+ := \[FALSE, TRUE, "", )\[\[[^\]]*\], \[[^\]]*\]\]',
                                            lambda m: m[1] + uframe, t)}


def _quaternions_xyzw(placed: Placed) -> dict[str, Edit]:
    def edit(t: str) -> str:
        return re.sub(r"(robtarget p\d+ := \[\[[^\]]*\], )" + QUAT,
                      lambda m: m[1] + _quat_text([float(m[i]) for i in (3, 4, 5, 2)]), t)
    return {".mod": edit}


def _targets_in_xyz_order(placed: Placed) -> dict[str, Edit]:
    # The cell names its tool (gun2): it exists on the controller, the module states no tooldata;
    # the rotation order mistake is made on the robtargets instead.
    def edit(t: str) -> str:
        def wrong(m: re.Match[str]) -> str:
            w, x, y, z = (float(m[i]) for i in (2, 3, 4, 5))
            zyx = Rotation.from_quat([x, y, z, w]).as_euler("ZYX", degrees=True)
            qx, qy, qz, qw = Rotation.from_euler("XYZ", zyx, degrees=True).as_quat()   # angles read in X-Y-Z order
            return m[1] + _quat_text([qw, qx, qy, qz])
        return re.sub(r"(robtarget p\d+ := \[\[[^\]]*\], )" + QUAT, wrong, t)
    return {".mod": edit}


def _targets_in_metres(placed: Placed) -> dict[str, Edit]:
    return {".mod": lambda t: re.sub(r"(robtarget p\d+ := \[\[)(-?[\d.]+), (-?[\d.]+), (-?[\d.]+)",
                                     lambda m: m[1] + ", ".join(f"{float(v) / 1000:.6f}" for v in m.groups()[1:]), t)}


def _joints_in_radians(placed: Placed) -> dict[str, Edit]:
    return {".mod": lambda t: re.sub(r"(jointtarget jt\d+ := \[\[)([^\]]*)",
                                     lambda m: m[1] + ", ".join(f"{math.radians(float(v)):.6f}" for v in m[2].split(",")), t)}


def _wrist_bit_flipped(placed: Placed) -> dict[str, Edit]:
    return {".mod": lambda t: re.sub(r"(robtarget p\d+ := \[\[[^\]]*\], \[[^\]]*\], \[-?\d+, -?\d+, -?\d+, )(\d)",
                                     lambda m: m[1] + str(int(m[2]) ^ 1), t, count=1)}


def _work_object_left_out(placed: Placed) -> dict[str, Edit]:
    return {".mod": lambda t: t.replace(r" \WObj:=fixture_plate", "")}


def _tool0(placed: Placed) -> dict[str, Edit]:
    return {".mod": lambda t: re.sub(r"(MoveL [^;]*, )gun2( \\WObj)", r"\1tool0\2", t)}


MUTANTS = {
    "placement as the user frame": _placement_as_uframe,
    "quaternions x-y-z-w": _quaternions_xyzw,
    "target rotations in X-Y-Z order": _targets_in_xyz_order,
    "targets in metres": _targets_in_metres,
    "joint values in radians": _joints_in_radians,
    "wrist bit flipped": _wrist_bit_flipped,
    "work object left out": _work_object_left_out,
    "tool0 selected": _tool0,
}


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore:Gimbal lock")
@pytest.mark.parametrize("kind", sorted(MUTANTS))
def test_rapid_mutant_is_rejected_with_a_line(placed: Placed, kind: str) -> None:
    report = placed.verify("rapid", MUTANTS[kind](placed), kind.replace(" ", "_"))
    assert not report.clean, kind
    assert any(v.line is not None for v in report.violations), report.violations


@pytest.mark.slow
def test_the_written_rapid_module_is_clean(placed: Placed) -> None:
    report = placed.verify("rapid", {}, "unchanged")
    assert report.clean, report.violations


@pytest.mark.slow
def test_without_the_data_module_a_frame_it_declares_is_unknown(placed: Placed) -> None:
    """The controller holds only the frames the cell names (the tool gun2); the user frame
    fixture_plate exists only in the data module: without it the program refers to undeclared
    data, which verify reports at the first move that uses it."""
    folder = placed.folder / "mutant_rapid_no_data_module"
    folder.mkdir()
    for file, text in placed.files.items():
        if file != f"{placed.name}_frames.mod":
            (folder / file).write_text(text)
    report = verify_program(placed.cell, placed.robot, folder / f"{placed.name}.mod")
    assert not report.clean
    assert any("fixture_plate" in v.detail and v.line is not None for v in report.violations), report.violations
