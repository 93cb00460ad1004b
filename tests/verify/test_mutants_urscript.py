"""URScript programs written with a convention the controller does not share are rejected by
`verify`, naming a line: each mutant is the placed process cell's script edited as a mistaken
writer would have written it (the robot's placement as the feature, the tool's rotation vector in
degrees, lengths in millimetres, joint values in degrees, the TCP never set, the feature left out)."""

from __future__ import annotations

import math
import re
from collections.abc import Callable

import pytest
from controller_model.urscript import run_urscript
from scipy.spatial.transform import Rotation
from verify_mutants import (
    Edit,
    Placed,
    detour_into_the_part,
    model_execution,
    placement_mm_zyx,
    read_execution,
)


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
    return {".script": lambda t: re.sub(r"^\s*set_tcp\(.*\)\n", "", t, flags=re.MULTILINE)}


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


# ------------------------------------------------------------------ what the controller executes
# Mutants of the script's flow, speeds and weld times (export/urscript's docstring, export/flow.py):
# each is caught with the violation the controller's execution implies; a call of a function
# without motion still verifies clean. URScript has no jumps: a weld under a condition or in a
# loop stands for them.

WELD1 = re.compile(r"^(  spot_weld\(1, [\d.]+\).*)$", re.MULTILINE)


def _before_first_motion(statement: str) -> Edit:
    return lambda t: re.sub(r"^(  movej\()", lambda m: f"  {statement}\n{m[1]}", t, count=1, flags=re.MULTILINE)


def _before_first_line(statement: str) -> Edit:
    return lambda t: re.sub(r"^(  movel\()", lambda m: f"  {statement}\n{m[1]}", t, count=1, flags=re.MULTILINE)


def _around_weld1(before: str, after: str, indent: bool = False) -> dict[str, Edit]:
    def edit(t: str) -> str:
        return WELD1.sub(lambda m: "\n".join(x for x in (before, ("  " if indent else "") + m[1], after) if x), t, count=1)
    return {".script": edit}


def _detour_def(placed: Placed) -> str:
    detour, back = detour_into_the_part(placed)
    moves = "".join(f"    movej([{', '.join(f'{math.radians(v):.9f}' for v in q)}], a=1.0, v=1.0, r=0)\n"
                    for q in (detour, back))
    return f"  def detour():\n{moves}  end\n"


def _with_def(definition: str) -> Edit:
    return lambda t: t.replace("  def wait_for_signal(n):", definition + "  def wait_for_signal(n):", 1)


FLOW_MUTANTS: dict[str, tuple[Callable[[Placed], dict[str, Edit]], set[str]]] = {
    "return before the first motion": (lambda p: {".script": _before_first_motion("return")}, {"flow"}),
    "halt() before the first motion": (lambda p: {".script": _before_first_motion("halt()")}, {"flow"}),
    "halt() after the first weld": (lambda p: _around_weld1("", "  halt()"), {"flow"}),
    "a weld under a condition": (lambda p: _around_weld1("  if get_standard_digital_in(1):", "  end", indent=True),
                                 {"unsupported"}),
    "a weld in a loop": (lambda p: _around_weld1("  while True:", "  end", indent=True), {"unsupported"}),
    "colliding move inside a called def": (
        lambda p: {".script": lambda t: _with_def(_detour_def(p))(_before_first_line("detour()")(t))}, {"collision"}),
    "a def calling itself": (
        lambda p: {".script": lambda t: _with_def("  def again():\n    again()\n  end\n")(_before_first_line("again()")(t))},
        {"unsupported"}),
    "call of an unknown function": (lambda p: {".script": _before_first_line("mystery()")}, {"unsupported"}),
    "movel v three times the line speed": (
        lambda p: {".script": lambda t: re.sub(r"(movel\([^\n]*, v=)([\d.]+)",
                                               lambda m: f"{m[1]}{3 * p.cell.planner.tcp_speed:.6f}", t)}, {"speed"}),
    "movej v three times the joints' speed": (
        lambda p: {".script": lambda t: re.sub(r"(movej\([^\n]*, v=)([\d.]+)", lambda m: f"{m[1]}{3 * float(m[2]):.6f}", t)},
        {"speed"}),
    "weld time in ms": (lambda p: {".script": lambda t: re.sub(r"(spot_weld\(1, )([\d.]+)",
                                                                lambda m: f"{m[1]}{1000 * float(m[2]):.3f}", t, count=1)},
                        {"weld"}),
    "spot_weld sleeps in ms": (lambda p: {".script": lambda t: t.replace("    sleep(weld_time)\n", "    sleep(weld_time * 1000)\n")},
                               {"unsupported"}),
}


@pytest.mark.slow
@pytest.mark.parametrize("kind", sorted(FLOW_MUTANTS))
def test_urscript_flow_mutant_is_caught(placed: Placed, kind: str) -> None:
    edit, expected = FLOW_MUTANTS[kind]
    report = placed.verify("urscript", edit(placed), "flow_" + re.sub(r"\W+", "_", kind))
    assert not report.clean, kind
    assert expected & {v.kind for v in report.violations}, report.violations


@pytest.mark.slow
def test_urscript_flow_the_controller_follows_exactly_is_clean(placed: Placed) -> None:
    """A call of a function without motion (a message) changes nothing the controller does."""
    edit = {".script": lambda t: _with_def("  def note():\n    textmsg(\"approach\")\n  end\n")(
        _before_first_line("note()")(t))}
    report = placed.verify("urscript", edit, "flow_followed")
    assert report.clean, report.violations


# The controller model (tests/controller_model, written from the vendors' documents) runs the same
# mutants: the welds that run, the motions and where the program stops agree with robomax's reading.
MODEL_CHECKED = ("return before the first motion", "halt() before the first motion", "halt() after the first weld",
                 "colliding move inside a called def")


@pytest.mark.slow
@pytest.mark.parametrize("kind", MODEL_CHECKED)
def test_urscript_flow_mutant_reads_as_the_controller_model_runs_it(placed: Placed, kind: str) -> None:
    edit, _ = FLOW_MUTANTS[kind]
    main, read = read_execution(placed, "urscript", edit(placed), "model_" + re.sub(r"\W+", "_", kind))
    run = run_urscript(main.read_text(), name=main.name)
    assert model_execution(run, "spot_weld") == read
