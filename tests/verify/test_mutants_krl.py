"""KRL programs written with a convention the controller does not share are rejected by `verify`,
naming a line: each mutant is the placed process cell's program edited as a mistaken writer would
have written it (the robot's placement as the base frame, the tool's angles in another rotation
order, lengths in metres, joint values in radians, the wrist flag flipped, the folds' FDAT selecting
tool 1 or base 0, or the lines that select the frames deleted).

What the controller does without them (BAS.SRC, export/krl's docstring): a fold without its FDAT_ACT
line runs BAS with the FDAT_ACT last assigned, so with every FDAT_ACT line gone the frames are the
controller's from an earlier run (unknown: the program selects none); a fold without its BAS line
changes no frame, so with every BAS line gone the INI fold's BAS(#INITMOV) frames stay in force:
TOOL_DATA[1] and $WORLD."""

from __future__ import annotations

import math
import re
from collections.abc import Callable

import pytest
from controller_model.krl import run_krl
from scipy.spatial.transform import Rotation
from verify_mutants import (
    Edit,
    Placed,
    detour_into_the_part,
    model_execution,
    placement_mm_zyx,
    read_execution,
)

FRAME = re.compile(r"\{X (-?[\d.]+), Y (-?[\d.]+), Z (-?[\d.]+), A (-?[\d.]+), B (-?[\d.]+), C (-?[\d.]+)\}")


def _frame_text(xyz: list[float], zyx: list[float]) -> str:
    return "{{X {:.3f}, Y {:.3f}, Z {:.3f}, A {:.4f}, B {:.4f}, C {:.4f}}}".format(*xyz, *zyx)


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


# ------------------------------------------------------------------ what the controller executes
# Mutants of the program's flow, speeds and weld times (export/krl's docstring, export/flow.py): each
# is caught with the violation the controller's execution implies, and the program with flow it
# can follow exactly (a label, a jump to the next statement, a call of a routine without motion)
# still verifies clean.

WELD1 = re.compile(r"^(spot_weld\(1, [\d.]+\).*)$", re.MULTILINE)


def _after_ini(statement: str) -> dict[str, Edit]:
    """`statement` right after the INI fold, before the first motion."""
    return {".src": lambda t: t.replace(";ENDFOLD (INI)\n", f";ENDFOLD (INI)\n{statement}\n", 1)}


def _around_weld1(before: str, after: str) -> dict[str, Edit]:
    return {".src": lambda t: WELD1.sub(lambda m: f"{before}\n{m[1]}\n{after}".strip("\n"), t, count=1)}


def _before_first_line(statement: str) -> Edit:
    """`statement` before the first LIN's fold (after the joint target the approach starts from)."""
    return lambda t: t.replace(";FOLD LIN", f"{statement}\n;FOLD LIN", 1)


def _axes(q: list[float]) -> str:
    return "{" + ",".join(f"A{i} {v:.4f}" for i, v in enumerate(q, start=1)) + "}"


def _detour_routine(placed: Placed) -> str:
    detour, back = detour_into_the_part(placed)
    return f"\nDEF detour( )\n  PTP {_axes(detour)}\n  PTP {_axes(back)}\nEND\n"


def _faster_lines(placed: Placed) -> dict[str, Edit]:
    v = 3.0 * placed.cell.planner.tcp_speed
    return {".src": lambda t: re.sub(r"^(BAS\(#CP_PARAMS,[\d.]+\)\n)", lambda m: f"{m[1]}$VEL.CP={v:g}\n", t,
                                     flags=re.MULTILINE)}


def _weld_in_ms(placed: Placed) -> dict[str, Edit]:
    return {".src": lambda t: re.sub(r"^spot_weld\(1, ([\d.]+)\)", lambda m: f"spot_weld(1, {1000 * float(m[1]):.3f})",
                                     t, count=1, flags=re.MULTILINE)}


FLOW_MUTANTS: dict[str, tuple[Callable[[Placed], dict[str, Edit]], set[str]]] = {
    "RETURN before the first motion": (lambda p: _after_ini("RETURN"), {"flow"}),
    "HALT before the first motion": (lambda p: _after_ini("HALT"), {"flow"}),
    "RETURN after the first weld": (lambda p: _around_weld1("", "RETURN"), {"flow"}),
    "GOTO over a weld": (lambda p: _around_weld1("GOTO skip_weld", "skip_weld:"), {"spot"}),
    "GOTO back to a label": (lambda p: _around_weld1("again:", "GOTO again"), {"unsupported"}),
    "GOTO under a condition": (lambda p: _around_weld1("IF $IN[1] THEN\nGOTO skip_weld\nENDIF", "skip_weld:"),
                               {"unsupported"}),
    "colliding move inside a called DEF": (
        lambda p: {".src": lambda t: _before_first_line("detour( )")(t) + _detour_routine(p)}, {"collision"}),
    "colliding move inside the frames program's DEF": (
        lambda p: {".src": _before_first_line("detour( )"), "_frames.src": lambda t: t + _detour_routine(p)},
        {"collision"}),
    "call of an unknown routine": (lambda p: {".src": _before_first_line("mystery( )")}, {"unsupported"}),
    "$VEL.CP three times the line speed": (_faster_lines, {"speed"}),
    "$VEL_AXIS of 300 %": (lambda p: {".src": lambda t: re.sub(r"^(BAS\(#PTP_PARAMS,\d+\)\n)", r"\1$VEL_AXIS[1]=300\n", t,
                                                                flags=re.MULTILINE)}, {"speed"}),
    "PDAT ACC of 300 %": (lambda p: {".dat": lambda t: re.sub(r"(DECL PDAT PPDAT\d+=\{VEL [\d.]+,ACC )[\d.]+", r"\g<1>300.000",
                                                               t)}, {"speed"}),
    "weld time in ms": (_weld_in_ms, {"weld"}),
    "spot_weld waits in ms": (lambda p: {".src": lambda t: t.replace("  WAIT SEC weld_time\n", "  WAIT SEC weld_time*1000\n")},
                              {"unsupported"}),
}


@pytest.mark.slow
@pytest.mark.parametrize("kind", sorted(FLOW_MUTANTS))
def test_krl_flow_mutant_is_caught(placed: Placed, kind: str) -> None:
    edit, expected = FLOW_MUTANTS[kind]
    report = placed.verify("krl", edit(placed), "flow_" + re.sub(r"\W+", "_", kind))
    assert not report.clean, kind
    assert expected & {v.kind for v in report.violations}, report.violations


@pytest.mark.slow
def test_krl_flow_the_controller_follows_exactly_is_clean(placed: Placed) -> None:
    """A jump label, a GOTO to the statement after it, and a call of a DEF without motion change
    nothing the controller does."""
    edits = {".src": lambda t: _before_first_line("GOTO next\nnext:\nnoop( )")(t)
             + "\nDEF noop( )\n  ; nothing to do\nEND\n"}
    report = placed.verify("krl", edits, "flow_followed")
    assert report.clean, report.violations


# The controller model (tests/controller_model, written from the vendors' documents) runs the same
# mutants: the welds that run, the motions and where the program stops agree with robomax's reading.
MODEL_CHECKED = ("RETURN before the first motion", "HALT before the first motion", "RETURN after the first weld", "GOTO over a weld",
                 "colliding move inside a called DEF")


@pytest.mark.slow
@pytest.mark.parametrize("kind", MODEL_CHECKED)
def test_krl_flow_mutant_reads_as_the_controller_model_runs_it(placed: Placed, kind: str) -> None:
    edit, _ = FLOW_MUTANTS[kind]
    main, read = read_execution(placed, "krl", edit(placed), "model_" + re.sub(r"\W+", "_", kind))
    run = run_krl(main.read_text(), main.with_suffix(".dat").read_text(), src_name=main.name)
    assert model_execution(run, "spot_weld") == read
