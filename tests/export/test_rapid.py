"""RAPID reader and writer on hand-written modules: what the controller executes for frames (the
tool and work object a statement names, uframe · oframe · target, options that change no path),
the spot option's SpotL as a line and a weld of the spotdata's schedule, and the data module's
tooldata load. Expected poses are computed with scipy, not with robomax's conversions."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.spatial.transform import Rotation

from robomax_py.errors import ControllerSetupError, ProgramError
from robomax_py.export import rapid
from robomax_py.export.dialect import PlannedProgram
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.program import (
    FrameDef,
    Header,
    LinMove,
    Program,
    ProgramSetup,
    PtpMove,
    Spot,
    lin_pose,
)
from robomax_py.robot import RobotModel
from robomax_py.spec import ControllerFrame, ControllerSetup

REPO = Path(__file__).resolve().parents[2]
EAX = "[9E9, 9E9, 9E9, 9E9, 9E9, 9E9]"


@pytest.fixture(scope="module")
def robot() -> RobotModel:
    return load_cell_robot(load_cell(REPO / "cells" / "cabin_flange.yaml"))


def _module(body: str, data: str = "") -> str:
    return f"MODULE m\n{data}\n  PROC main()\n    MoveAbsJ [[0, -90, 90, 0, 0, 0], {EAX}], v100, fine, tool0;\n" \
           f"{body}\n  ENDPROC\nENDMODULE\n"


def _parse(robot: RobotModel, main: str, frames: str = "") -> rapid.Parsed:
    return rapid.parse({".mod": main, rapid.FRAMES_FILE: frames}, "m.mod", robot)


def _quat_wxyz(R: Rotation) -> str:
    x, y, z, w = R.as_quat()
    return f"[{w:.12f}, {x:.12f}, {y:.12f}, {z:.12f}]"


def _T(xyz_mm: list[float], R: Rotation) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R.as_matrix(), np.asarray(xyz_mm) / 1000.0
    return T


def test_target_lands_at_uframe_times_oframe_times_target(robot: RobotModel) -> None:
    """A work object with both a user frame and an object frame: the TCP in the world is
    uframe · oframe · target ([R3] wobjdata), with the tool the statement names."""
    Ru, Ro, Rt = (Rotation.from_euler("z", 15, degrees=True), Rotation.from_euler("x", 45, degrees=True),
                  Rotation.from_euler("ZYX", [30, -20, 170], degrees=True))
    data = (f'  PERS wobjdata fixture := [FALSE, TRUE, "", [[100, 200, 300], {_quat_wxyz(Ru)}], '
            f'[[10, 0, 5], {_quat_wxyz(Ro)}]];\n'
            f"  PERS tooldata gun := [TRUE, [[200, 0, 270], [0.5, -0.5, 0.5, -0.5]], [1, [200, 0, 270], "
            f"[1, 0, 0, 0], 0, 0, 0]];\n")
    main = _module(f"    MoveL [[1, 2, 3], {_quat_wxyz(Rt)}, [0, 0, 0, 1], {EAX}], v500, fine, gun \\WObj:=fixture;")
    parsed = _parse(robot, main, data)
    (lin,) = [i for i in parsed.program.instructions if isinstance(i, LinMove)]
    assert (lin.tool, lin.base) == ("gun", "fixture")
    frames = {f.name: f for f in parsed.program.frames}
    T_world_tcp = frames["fixture"].pose @ lin_pose(lin)
    want = _T([100, 200, 300], Ru) @ _T([10, 0, 5], Ro) @ _T([1, 2, 3], Rt)
    assert_allclose(T_world_tcp[:3, 3], want[:3, 3], atol=1e-6)               # 1 µm: 3-decimal mm
    assert Rotation.from_matrix(T_world_tcp[:3, :3].T @ want[:3, :3]).magnitude() < math.radians(1e-3)
    tool = frames["gun"].pose
    assert_allclose(tool[:3, 3], [0.2, 0.0, 0.27], atol=1e-9)


def test_options_that_change_no_path_are_harmless(robot: RobotModel) -> None:
    """\\WObj on a MoveAbsJ (a joint target has no work object) and \\TLoad (the load, not the path)
    read as the same motion as without them."""
    data = '  PERS wobjdata w1 := [FALSE, TRUE, "", [[500, 0, 0], [1, 0, 0, 0]], [[0, 0, 0], [1, 0, 0, 0]]];\n' \
           "  PERS loaddata part := [5, [0, 0, 50], [1, 0, 0, 0], 0, 0, 0];\n"
    target = f"[[400, 0, 600], [0, 0, 1, 0], [0, 0, 0, 0], {EAX}]"
    plain = _parse(robot, _module(f"    MoveAbsJ [[10, -80, 90, 0, 30, 0], {EAX}], v200, fine, tool0;\n"
                                  f"    MoveL {target}, v200, fine, tool0 \\WObj:=w1;"), data)
    optioned = _parse(robot, _module(f"    MoveAbsJ [[10, -80, 90, 0, 30, 0], {EAX}], v200, fine, tool0 \\WObj:=w1;\n"
                                     f"    MoveL {target}, v200, fine, tool0 \\WObj:=w1 \\TLoad:=part;"), data)
    assert optioned.program.instructions == plain.program.instructions
    assert isinstance(plain.program.instructions[1], PtpMove) and plain.program.instructions[1].target_deg[0] == 10.0


@pytest.mark.parametrize("wobj", ['[TRUE, TRUE, "", [[0, 0, 0], [1, 0, 0, 0]], [[0, 0, 0], [1, 0, 0, 0]]]',
                                  '[FALSE, FALSE, "STN1", [[0, 0, 0], [1, 0, 0, 0]], [[0, 0, 0], [1, 0, 0, 0]]]'])
def test_a_moving_work_object_is_reported_not_placed(robot: RobotModel, wobj: str) -> None:
    """Held by the robot (a stationary tool) or coordinated with a mechanical unit: the reader does
    not place it, and the move that names it is left without a known frame (rebuild reports it)."""
    parsed = _parse(robot, _module(f"    MoveL [[0, 0, 100], [1, 0, 0, 0], [0, 0, 0, 0], {EAX}], v100, fine, tool0 "
                                   "\\WObj:=moving;"), f"  PERS wobjdata moving := {wobj};\n")
    assert "moving" not in {f.name for f in parsed.program.frames}
    assert any("moving work object" in text for _, text in parsed.ignored)
    (lin,) = [i for i in parsed.program.instructions if isinstance(i, LinMove)]
    assert lin.base == "moving"


SPOT_MAIN = _module(f"""    SpotL [[10, 20, 30], [0, 0, 1, 0], [0, -1, -2, 0], {EAX}], v300, sd7 \\InPos \\Retract, GUN2, gun_tool
          \\WObj:=fixture;  ! flange/s8
    SpotL [[11, 20, 30], [0, 0, 1, 0], [0, -1, -2, 0], {EAX}], v300, spot_a, sgun, gun_tool;""",
                    "  PERS spotdata sd7 := [7, 1];\n  PERS spotdata spot_a := [12, 2, 3, 0];\n"
                    "  PERS tooldata gun_tool := [TRUE, [[0, 0, 400], [1, 0, 0, 0]], [1, [0, 0, 400], [1, 0, 0, 0], 0, 0, 0]];\n"
                    '  PERS wobjdata fixture := [FALSE, TRUE, "", [[900, 0, 0], [1, 0, 0, 0]], [[0, 0, 0], [1, 0, 0, 0]]];')


def test_spotl_is_a_stop_on_the_line_then_the_weld_of_its_schedule(robot: RobotModel) -> None:
    parsed = _parse(robot, SPOT_MAIN)
    ins = parsed.program.instructions
    lin, weld = ins[1], ins[2]
    assert isinstance(lin, LinMove) and isinstance(weld, Spot)
    assert (lin.position_mm, lin.flyby_mm, lin.speed_mm_s, lin.tool, lin.base) == ((10.0, 20.0, 30.0), 0.0, 300.0,
                                                                                    "gun_tool", "fixture")
    assert (weld.seam, weld.name, weld.gun, weld.schedule, weld.package, weld.time_s) == ("flange", "s8", 2, 7, True,
                                                                                          0.0)
    assert parsed.lines[1] == parsed.lines[2]
    # without a comment: weld 2 of an unnamed seam; a gundata not named gun<n>: gun unknown (0)
    other = ins[4]
    assert isinstance(other, Spot) and (other.seam, other.name, other.gun, other.schedule) == ("unnamed", "spot2", 0, 12)


def test_spotl_reads_its_schedule_from_the_statement_not_the_comment(robot: RobotModel) -> None:
    """The controller welds with the spotdata it is given: a comment saying otherwise is only a comment."""
    text = SPOT_MAIN.replace("! flange/s8", "! flange/s8 gun 1 schedule 3")
    weld = _parse(robot, text).program.instructions[2]
    assert isinstance(weld, Spot) and (weld.gun, weld.schedule) == (2, 7)


def test_spotl_without_its_spotdata_names_the_line(robot: RobotModel) -> None:
    text = SPOT_MAIN.replace("  PERS spotdata sd7 := [7, 1];\n", "")
    with pytest.raises(ProgramError, match="line 7.*sd7 is not declared"):
        _parse(robot, text)


def _planned(tool: str, weld: str) -> PlannedProgram:
    header = Header("c", "kr125", "spot_gun_c", 1.0, tuple(f"joint_a{i}" for i in range(1, 7)))
    program = Program("c", header, (FrameDef(tool, "tool", (0.0, 0.0, 400.0), (0.0, 0.0, 0.0), 2),),
                      (PtpMove((0.0, -90.0, 90.0, 0.0, 0.0, 0.0)), LinMove((1000.0, 0.0, 500.0), (0.0, 180.0, 0.0),
                                                                          tool=tool), Spot("s1", "flange", 0.5, 2, 4)),
                      ProgramSetup(weld=weld))                            # type: ignore[arg-type]
    return PlannedProgram(program, (), ControllerSetup(tool=ControllerFrame(2, tool, True), weld=weld))  # type: ignore[arg-type]


def test_a_tool_named_like_the_guns_gundata_is_refused(robot: RobotModel) -> None:
    """The spot option's gundata of gun 2 is `gun2` on the controller: a tooldata of that name
    cannot exist beside it."""
    with pytest.raises(ControllerSetupError, match="robot.controller.tool.name.*gun2 is also the name of gun 2's "
                                                   "gundata"):
        rapid.adapt(_planned("gun2", "package"), robot)


def test_written_tooldata_carries_a_point_load_at_the_tcp(robot: RobotModel) -> None:
    """loaddata [mass, cog, aom, ix, iy, iz]: mass > 0, the centre of gravity of a tool in the wrist
    frame ([R3] p. 183), no inertia: a point load ([R3] p. 226), flagged for replacement."""
    program = dataclasses.replace(_planned("gun_tcp", "call").program, setup=ProgramSetup())
    text = rapid.write(program, robot)[rapid.FRAMES_FILE]
    line = next(li for li in text.splitlines() if "PERS tooldata gun_tcp" in li)
    assert "[1, [0.000, 0.000, 400.000], [1, 0, 0, 0], 0, 0, 0]]" in line and "replace with the gun's" in line
