"""RAPID modules written with a convention the controller does not share are rejected by `verify`,
naming a line: each mutant is the placed process cell's module edited as a mistaken writer would
have written it (the robot's placement as the work object's user frame, quaternions in x-y-z-w
order, the targets' rotations in another order, lengths in metres, joint values in radians, the
wrist bit of cfx flipped, the work object or the tool left out, the data module not loaded), and,
with the spot option's SpotL (`weld: package`), welds with another schedule's spotdata, another
program number or another gun's gundata. The package module is also judged by the controller
model: every SpotL stops at its spot in the world."""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import yaml
from controller_model.common import Call, Motion
from controller_model.rapid import run_rapid
from scipy.spatial.transform import Rotation
from verify_mutants import (
    Edit,
    Placed,
    detour_into_the_part,
    model_execution,
    placement_mm_zyx,
    read_execution,
)

from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import plan_cell
from robomax_py.publish import publish
from robomax_py.verify import verify_program

POS_TOL_M = 1e-4          # 0.1 mm

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


@pytest.fixture(scope="module")
def placed_package(tmp_path_factory: pytest.TempPathFactory, write_process_cell: Callable[..., Path]) -> Placed:
    """The process cell welding with the controller's spot option (`weld: package`); its tool is
    named tool_gun2, since gun2 is gun 2's gundata on such a controller."""
    folder = tmp_path_factory.mktemp("placed_package")
    path = write_process_cell(folder, name="placed_package")
    data = yaml.safe_load(path.read_text())
    data["robot"]["controller"]["weld"] = "package"
    data["robot"]["controller"]["tool"]["name"] = "tool_gun2"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    cell = load_cell(path)
    robot = load_cell_robot(cell)
    result = plan_cell(cell, robot)
    assert result.status == "planned", result.message
    files, _ = publish(result, cell, robot, ("rapid",))
    for name, text in files.items():
        (folder / name).write_text(text)
    return Placed(folder, path, cell, robot, files, "placed_package")


def _first(pattern: str, replacement: str) -> Edit:
    def edit(t: str) -> str:
        return re.sub(pattern, replacement, t, count=1, flags=re.MULTILINE)
    return edit


PACKAGE_MUTANTS = {
    # s7 (schedule 4, 0.5 s) welded with schedule 7's spotdata: longer, and another current program
    "SpotL with another spotdata": {".mod": _first(r"^(\s*SpotL p\d+, v_lin\d+, )sd4", r"\1sd7")},
    "spotdata with another program number": {".mod": _first(r"(PERS spotdata sd7 := \[)7,", r"\g<1>4,")},
    "another gun's gundata": {".mod": _first(r"^(\s*SpotL [^;]*, )gun2,", r"\1gun1,")},
}


@pytest.mark.slow
def test_the_package_module_welds_with_spotl_and_is_clean(placed_package: Placed) -> None:
    text = placed_package.files["placed_package.mod"]
    assert len(re.findall(r"^\s*SpotL p\d+, v_lin\d+, sd(4|7), gun2, tool_gun2 \\WObj:=fixture_plate;  ! flange/s[78]$",
                          text, re.MULTILINE)) == 2
    assert "PERS spotdata sd4 := [4, 1];" in text and "PERS spotdata sd7 := [7, 1];" in text
    assert "spot_weld" not in text and "gundata" not in text.split("PROC main")[0].replace("gundata;", "")
    report = placed_package.verify("rapid", {}, "unchanged")
    assert report.clean, report.violations


@pytest.mark.slow
@pytest.mark.parametrize("kind", sorted(PACKAGE_MUTANTS))
def test_rapid_package_mutant_is_rejected_with_a_line(placed_package: Placed, kind: str) -> None:
    report = placed_package.verify("rapid", PACKAGE_MUTANTS[kind], kind.replace(" ", "_").replace("'", ""))
    assert not report.clean, kind
    assert any(v.kind == "weld" and v.line is not None for v in report.violations), report.violations


@pytest.mark.slow
def test_the_controller_model_stops_every_spotl_at_its_spot(placed_package: Placed) -> None:
    """The independent model runs the package module (the data module beside it, the cell's tool
    gun on the controller): each SpotL is a stop whose TCP, placed in the world as the cell places
    the robot, is at a spot of the cell."""
    tool = placed_package.robot.T_flange_tcp
    xyz, zyx = (float(v) * 1000.0 for v in tool[:3, 3]), Rotation.from_matrix(tool[:3, :3])
    x, y, z, w = zyx.as_quat()
    calibrated = ("MODULE Calibration\n  PERS tooldata tool_gun2 := [TRUE, [[" + ", ".join(f"{v:.6f}" for v in xyz)
                  + f"], [{w:.12f}, {x:.12f}, {y:.12f}, {z:.12f}]], [1, [0, 0, 1], [1, 0, 0, 0], 0, 0, 0]];\nENDMODULE\n")
    modules = {n: t for n, t in placed_package.files.items() if n.endswith(".mod")} | {"Calibration.mod": calibrated}
    run = run_rapid(modules)
    assert run.clean, run.issues
    spots = np.asarray([s.xyz for seam in placed_package.cell.seams for s in seam.spots])
    T_world_base = placed_package.cell.T_world_base @ placed_package.cell.robot.controller.T_root_base
    welded = []
    for before, event in zip(run.events, run.events[1:]):
        if isinstance(event, Call) and event.name == "SpotL":
            assert isinstance(before, Motion) and before.stops and before.T_base_tcp is not None
            gaps = np.linalg.norm(spots - (T_world_base @ before.T_base_tcp)[:3, 3], axis=1)
            assert gaps.min() <= POS_TOL_M, gaps
            welded.append(int(gaps.argmin()))
            assert event.args[1] == "gun2"
    assert sorted(welded) == list(range(len(spots)))


# ------------------------------------------------------------------ what the controller executes
# Mutants of the module's flow, speeds and weld times (export/rapid's docstring, export/flow.py): each
# is caught with the violation the controller's execution implies; a module with flow verify can
# follow exactly (labels, one on the line of the statement it marks, a jump to the next
# statement, a call of a PROC without motion) still verifies clean.

WELD1 = re.compile(r"^(\s*spot_weld 1, [\d.]+;.*)$", re.MULTILINE)


def _first_in_main(statement: str) -> dict[str, Edit]:
    return {".mod": lambda t: t.replace("PROC main()\n", f"PROC main()\n    {statement}\n", 1)}


def _around_weld1(before: str, after: str) -> dict[str, Edit]:
    return {".mod": lambda t: WELD1.sub(lambda m: "\n".join(x for x in (before, m[1], after) if x), t, count=1)}


def _before_first_line(statement: str) -> Edit:
    return lambda t: re.sub(r"^(\s*MoveL )", lambda m: f"    {statement}\n{m[1]}", t, count=1, flags=re.MULTILINE)


def _detour_proc(placed: Placed) -> str:
    detour, back = detour_into_the_part(placed)
    eax = "[9E9, 9E9, 9E9, 9E9, 9E9, 9E9]"
    moves = "".join(f"    MoveAbsJ [[{', '.join(f'{v:.4f}' for v in q)}], {eax}], vmax, fine, tool0;\n" for q in (detour, back))
    return f"  PROC detour()\n{moves}  ENDPROC\n"


def _with_proc(proc: str) -> Edit:
    return lambda t: t.replace("ENDMODULE", proc + "ENDMODULE", 1)


def _faster_speeddata(placed: Placed) -> dict[str, Edit]:
    v = 3000.0 * placed.cell.planner.tcp_speed
    return {".mod": lambda t: re.sub(r"(speeddata v_lin1 := \[)[\d.]+", lambda m: f"{m[1]}{v:.3f}", t)}


FLOW_MUTANTS: dict[str, tuple[Callable[[Placed], dict[str, Edit]], set[str]]] = {
    "RETURN before the first motion": (lambda p: _first_in_main("RETURN;"), {"flow"}),
    "Stop before the first motion": (lambda p: _first_in_main("Stop;"), {"flow"}),
    "EXIT after the first weld": (lambda p: _around_weld1("", "    EXIT;"), {"flow"}),
    "GOTO over a weld": (lambda p: _around_weld1("    GOTO skip_weld;", "  skip_weld:"), {"spot"}),
    "GOTO back to a label": (lambda p: _around_weld1("  again:", "    GOTO again;"), {"unsupported"}),
    "GOTO under a compact IF": (lambda p: _around_weld1("    IF DInput(diClamp1Closed) = 1 GOTO skip_weld;", "  skip_weld:"),
                                {"unsupported"}),
    "colliding move inside a called PROC": (
        lambda p: {".mod": lambda t: _with_proc(_detour_proc(p))(_before_first_line("detour;")(t))}, {"collision"}),
    "colliding move inside the data module's PROC": (
        lambda p: {".mod": _before_first_line("detour;"), "_frames.mod": _with_proc(_detour_proc(p))}, {"collision"}),
    "call of an unknown routine": (lambda p: {".mod": _before_first_line("mystery;")}, {"unsupported"}),
    "speeddata three times the line speed": (_faster_speeddata, {"speed"}),
    "v5000 on a line": (lambda p: {".mod": lambda t: re.sub(r"(MoveL p\d+, )v_lin\d+", r"\1v5000", t, count=1)}, {"speed"}),
    "VelSet 300 %": (lambda p: {".mod": lambda t: re.sub(r"VelSet [\d.]+,", "VelSet 300,", t, count=1)}, {"speed"}),
    "AccSet 300 %": (lambda p: {".mod": lambda t: re.sub(r"AccSet [\d.]+,", "AccSet 300,", t, count=1)}, {"speed"}),
    "weld time in ms": (lambda p: {".mod": lambda t: re.sub(r"(spot_weld 1, )([\d.]+)", lambda m: f"{m[1]}{1000 * float(m[2]):.3f}",
                                                             t, count=1)}, {"weld"}),
    "spot_weld waits in ms": (lambda p: {".mod": lambda t: t.replace("WaitTime \\InPos, weld_time;",
                                                                      "WaitTime \\InPos, weld_time * 1000;")}, {"unsupported"}),
}


@pytest.mark.slow
@pytest.mark.parametrize("kind", sorted(FLOW_MUTANTS))
def test_rapid_flow_mutant_is_caught(placed: Placed, kind: str) -> None:
    edit, expected = FLOW_MUTANTS[kind]
    report = placed.verify("rapid", edit(placed), "flow_" + re.sub(r"\W+", "_", kind))
    assert not report.clean, kind
    assert expected & {v.kind for v in report.violations}, report.violations


@pytest.mark.slow
def test_rapid_flow_the_controller_follows_exactly_is_clean(placed: Placed) -> None:
    """A label on its own line before the first weld (it swallowed the weld once), one on the
    line of the statement it marks, a GOTO to the statement after it and a call of a PROC without
    motion change nothing the controller does."""
    def edit(t: str) -> str:
        t = WELD1.sub(lambda m: "  before_weld:\n" + m[1], t, count=1)
        t = _before_first_line("GOTO next;\n  next: noop;")(t)
        return _with_proc("  PROC noop()\n    ! nothing to do\n  ENDPROC\n")(t)
    report = placed.verify("rapid", {".mod": edit}, "flow_followed")
    assert report.clean, report.violations


# The controller model (tests/controller_model, written from the vendors' documents) runs the same
# mutants: the welds that run, the motions and where the program stops agree with robomax's reading.
MODEL_CHECKED = ("RETURN before the first motion", "Stop before the first motion", "EXIT after the first weld", "GOTO over a weld",
                 "colliding move inside a called PROC", "colliding move inside the data module's PROC")


@pytest.mark.slow
@pytest.mark.parametrize("kind", MODEL_CHECKED)
def test_rapid_flow_mutant_reads_as_the_controller_model_runs_it(placed: Placed, kind: str) -> None:
    edit, _ = FLOW_MUTANTS[kind]
    main, read = read_execution(placed, "rapid", edit(placed), "model_" + re.sub(r"\W+", "_", kind))
    run = run_rapid({p.name: p.read_text() for p in (main, main.with_name(main.stem + "_frames.mod"))})
    assert model_execution(run, "spot_weld") == read
