"""SRCL programs with the conventions robomax's earlier writers had are rejected by `verify`,
naming a line: the robot's placement as the BASE FRAME, the tool's angles in another rotation
order, lengths in metres, the wrist bit flipped."""

from __future__ import annotations

import re

import pytest
from scipy.spatial.transform import Rotation

from conftest import Edit, Placed, placement_mm_zyx


def _placement_as_base(placed: Placed) -> dict[str, Edit]:
    xyz, zyx = placement_mm_zyx(placed.cell)
    frame = "(POS(%.3f, %.3f, %.3f), ORI(%.4f, %.4f, %.4f))" % (*xyz, *zyx)
    return {".srcl": lambda t: re.sub(r"(BASE FRAME \d* ?:= )\([^;]*\)(;)", lambda m: m[1] + frame + m[2], t)}


def _tool_in_xyz_order(placed: Placed) -> dict[str, Edit]:
    def edit(t: str) -> str:
        def wrong(m: re.Match[str]) -> str:
            zyx = [float(v) for v in m[2].split(",")]
            abc = Rotation.from_euler("ZYX", zyx, degrees=True).as_euler("XYZ", degrees=True)
            return m[1] + ", ".join(f"{v:.4f}" for v in abc) + m[3]
        return re.sub(r"(TOOL FRAME[^;]*ORI\()([^)]*)(\))", wrong, t)
    return {".srcl": edit}


def _targets_in_metres(placed: Placed) -> dict[str, Edit]:
    return {".srcl": lambda t: re.sub(r"(MOVE LIN POS\()([^)]*)",
                                      lambda m: m[1] + ", ".join(f"{float(v) / 1000:.6f}" for v in m[2].split(",")), t)}


def _wrist_bit_flipped(placed: Placed) -> dict[str, Edit]:
    return {".srcl": lambda t: re.sub(r"CONFIG 'S(\d)(\d\d)", lambda m: f"CONFIG 'S{int(m[1]) ^ 1}{m[2]}", t, count=1)}


MUTANTS = {
    "placement as the base frame": _placement_as_base,
    "tool angles in X-Y-Z order": _tool_in_xyz_order,
    "targets in metres": _targets_in_metres,
    "wrist bit flipped": _wrist_bit_flipped,
}


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore:Gimbal lock")
@pytest.mark.parametrize("kind", sorted(MUTANTS))
def test_srcl_mutant_is_rejected_with_a_line(placed: Placed, kind: str) -> None:
    report = placed.verify("srcl", MUTANTS[kind](placed), kind.replace(" ", "_"))
    assert not report.clean, kind
    assert any(v.line is not None for v in report.violations), report.violations
