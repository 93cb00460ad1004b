"""URScript programs written with a convention the controller does not share are rejected by
`verify`, naming a line: each mutant is the placed process cell's script edited as a mistaken
writer would have written it (the robot's placement as the feature, the tool's rotation vector in
degrees, lengths in millimetres, joint values in degrees, the TCP never set, the feature left out)."""

from __future__ import annotations

import math
import re

import pytest
from scipy.spatial.transform import Rotation

from conftest import Edit, Placed, placement_mm_zyx


def _placement_as_feature(placed: Placed) -> dict[str, Edit]:
    xyz, zyx = placement_mm_zyx(placed.cell)
    rx, ry, rz = Rotation.from_euler("ZYX", zyx, degrees=True).as_rotvec()
    pose = f"p[{xyz[0] / 1000:.6f}, {xyz[1] / 1000:.6f}, {xyz[2] / 1000:.6f}, {rx:.9f}, {ry:.9f}, {rz:.9f}]"
    return {".script": lambda t: re.sub(r"(global fixture_plate = )p\[[^\]]*\]", lambda m: m[1] + pose, t)}


def _tool_rotation_in_degrees(placed: Placed) -> dict[str, Edit]:
    def edit(t: str) -> str:
        return re.sub(r"(global gun2 = p\[[^,]*, [^,]*, [^,]*, )([^\]]*)\]",
                      lambda m: m[1] + ", ".join(f"{math.degrees(float(v)):.6f}" for v in m[2].split(",")) + "]", t)
    return {".script": edit}


def _lengths_in_millimetres(placed: Placed) -> dict[str, Edit]:
    return {".script": lambda t: re.sub(r"(pose_trans\(fixture_plate, p\[)(-?[\d.]+), (-?[\d.]+), (-?[\d.]+)",
                                        lambda m: m[1] + ", ".join(f"{float(v) * 1000:.3f}" for v in m.groups()[1:]), t)}


def _joints_in_degrees(placed: Placed) -> dict[str, Edit]:
    return {".script": lambda t: re.sub(r"(movej\(\[)([^\]]*)",
                                        lambda m: m[1] + ", ".join(f"{math.degrees(float(v)):.6f}" for v in m[2].split(",")), t)}


def _tcp_never_set(placed: Placed) -> dict[str, Edit]:
    return {".script": lambda t: re.sub(r"^\s*set_tcp\(.*\)\n", "", t, flags=re.M)}


def _feature_left_out(placed: Placed) -> dict[str, Edit]:
    return {".script": lambda t: re.sub(r"pose_trans\(fixture_plate, (p\[[^\]]*\])\)", r"\1", t)}


MUTANTS = {
    "placement as the feature": _placement_as_feature,
    "tool rotation vector in degrees": _tool_rotation_in_degrees,
    "lengths in millimetres": _lengths_in_millimetres,
    "joint values in degrees": _joints_in_degrees,
    "TCP never set": _tcp_never_set,
    "feature left out": _feature_left_out,
}


@pytest.mark.slow
@pytest.mark.parametrize("kind", sorted(MUTANTS))
def test_urscript_mutant_is_rejected_with_a_line(placed: Placed, kind: str) -> None:
    report = placed.verify("urscript", MUTANTS[kind](placed), kind.replace(" ", "_"))
    assert not report.clean, kind
    assert any(v.line is not None for v in report.violations), report.violations


@pytest.mark.slow
def test_the_written_script_is_clean(placed: Placed) -> None:
    report = placed.verify("urscript", {}, "unchanged")
    assert report.clean, report.violations
