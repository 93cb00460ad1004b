"""SRCL programs with the conventions robomax's earlier writers had are rejected by `verify`,
naming a line: the robot's placement as the BASE FRAME, the tool's angles in another rotation
order, lengths in metres, the wrist bit flipped."""

from __future__ import annotations

import re
from collections.abc import Callable

import pytest
from scipy.spatial.transform import Rotation
from verify_mutants import Edit, Placed, placement_mm_zyx

from robomax_py.errors import ProgramError


def _placement_as_base(placed: Placed) -> dict[str, Edit]:
    xyz, zyx = placement_mm_zyx(placed.cell)
    frame = "(POS({:.3f}, {:.3f}, {:.3f}), ORI({:.4f}, {:.4f}, {:.4f}))".format(*xyz, *zyx)
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


# ------------------------------------------------------------------ what a controller would execute
# SRCL has no jumps, ends or calls: a program written with them does not read (a clear
# ProgramError naming the line); speeds and weld times are checked as for every dialect.

WELD1 = re.compile(r"^(  SPOT \w+ SEAM \w+ TIME )([\d.]+)", re.MULTILINE)

UNREADABLE: dict[str, Edit] = {
    "RETURN before the first motion": lambda t: t.replace("BEGIN\n", "BEGIN\n  RETURN;\n", 1),
    "GOTO over a weld": lambda t: WELD1.sub(lambda m: "  GOTO skip_weld;\n" + m[0], t, count=1),
    "a label": lambda t: WELD1.sub(lambda m: "  skip_weld:\n" + m[0], t, count=1),
    "call of a routine": lambda t: t.replace("  MOVE LIN", "  CALL detour;\n  MOVE LIN", 1),
    "PTP SPEED 300 %": lambda t: re.sub(r"(MOVE PTP AXIS\([^)]*\) SPEED )[\d.]+", r"\g<1>3.000", t, count=1),
    "PTP ACCEL 300 %": lambda t: re.sub(r"(MOVE PTP AXIS\([^)]*\) SPEED [\d.]+ ACCEL )[\d.]+", r"\g<1>3.000", t, count=1),
}

FLOW_MUTANTS: dict[str, tuple[Callable[[Placed], dict[str, Edit]], set[str]]] = {
    "LIN SPEED three times the line speed": (
        lambda p: {".srcl": lambda t: re.sub(r"(MOVE LIN [^;]* SPEED )[\d.]+( MM/S)",
                                             lambda m: f"{m[1]}{3000 * p.cell.planner.tcp_speed:.3f}{m[2]}", t)}, {"speed"}),
    "weld time in ms": (lambda p: {".srcl": lambda t: WELD1.sub(lambda m: f"{m[1]}{1000 * float(m[2]):.3f}", t, count=1)},
                        {"weld"}),
}


@pytest.mark.slow
@pytest.mark.parametrize("kind", sorted(UNREADABLE))
def test_srcl_flow_mutant_does_not_read(placed: Placed, kind: str) -> None:
    with pytest.raises(ProgramError, match=r"line \d+"):
        placed.verify("srcl", {".srcl": UNREADABLE[kind]}, "flow_" + re.sub(r"\W+", "_", kind))


@pytest.mark.slow
@pytest.mark.parametrize("kind", sorted(FLOW_MUTANTS))
def test_srcl_flow_mutant_is_caught(placed: Placed, kind: str) -> None:
    edit, expected = FLOW_MUTANTS[kind]
    report = placed.verify("srcl", edit(placed), "flow_" + re.sub(r"\W+", "_", kind))
    assert not report.clean, kind
    assert expected & {v.kind for v in report.violations}, report.violations
