"""Kawasaki AS programs written with a convention the controller does not share are rejected by
`verify`: the placed process cell's program edited as a mistaken writer would write it (the
robot's placement as BASE, OAT read as ZYX angles, BASE left out, the tool left out, joint values
in radians, a weld time in ms)."""

from __future__ import annotations

import math
import re

import pytest
from verify_mutants import Edit, Placed, placement_mm_zyx


def _placement_as_base(placed: Placed) -> dict[str, Edit]:
    from scipy.spatial.transform import Rotation

    xyz, zyx = placement_mm_zyx(placed.cell)
    oat = Rotation.from_euler("ZYX", zyx, degrees=True).as_euler("ZYZ", degrees=True)
    trans = "TRANS(" + ",".join(f"{v:.4f}" for v in (*xyz, *oat)) + ")"
    return {".as": lambda t: re.sub(r"(POINT base3 = )TRANS\([^)]*\)", lambda m: m[1] + trans, t)}


def _zyx_written_as_oat(placed: Placed) -> dict[str, Edit]:
    from scipy.spatial.transform import Rotation

    def edit(m: re.Match[str]) -> str:
        v = [float(x) for x in m[2].split(",")]
        zyx = Rotation.from_euler("ZYZ", v[3:], degrees=True).as_euler("ZYX", degrees=True)
        return m[1] + ",".join(f"{x:.4f}" for x in (*v[:3], *zyx)) + ")"
    return {".as": lambda t: re.sub(r"(LMOVE TRANS\()([^)]*)\)", edit, t)}


def _base_left_out(placed: Placed) -> dict[str, Edit]:
    return {".as": lambda t: t.replace("  BASE base3\r\n", "")}


def _tool_left_out(placed: Placed) -> dict[str, Edit]:
    return {".as": lambda t: t.replace("  TOOL tool2\r\n", "  TOOL NULL\r\n")}


def _joints_in_radians(placed: Placed) -> dict[str, Edit]:
    return {".as": lambda t: re.sub(r"(JMOVE #\[)([^\]]*)",
                                    lambda m: m[1] + ",".join(f"{math.radians(float(v)):.4f}" for v in m[2].split(",")), t)}


def _weld_time_in_ms(placed: Placed) -> dict[str, Edit]:
    return {".as": lambda t: re.sub(r"(CALL spot_weld\(1,)([\d.]+)", lambda m: f"{m[1]}{1000 * float(m[2]):.3f}", t)}


MUTANTS = {
    "placement as BASE": _placement_as_base,
    "ZYX angles as OAT": _zyx_written_as_oat,
    "BASE left out": _base_left_out,
    "tool left out": _tool_left_out,
    "joint values in radians": _joints_in_radians,
    "weld time in ms": _weld_time_in_ms,
}


@pytest.mark.slow
@pytest.mark.parametrize("kind", sorted(MUTANTS))
def test_as_mutant_is_rejected(placed: Placed, kind: str) -> None:
    report = placed.verify("as", MUTANTS[kind](placed), re.sub(r"\W+", "_", kind))
    assert not report.clean, kind


@pytest.mark.slow
def test_the_written_program_is_clean(placed: Placed) -> None:
    report = placed.verify("as", {}, "unchanged")
    assert report.clean, report.violations
