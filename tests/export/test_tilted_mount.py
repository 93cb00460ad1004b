"""A robot hung from the ceiling: KRL states its base frames on $ROBROOT (the integrator enters the
mounting there, and $BASE is relative to $WORLD), and verify composes the frames as the controller
does, so a program stating them as if $ROBROOT were $WORLD is reported (export/mount.py)."""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from scipy.spatial.transform import Rotation

from robomax_py.export import krl
from robomax_py.export.mount import is_tilted, robroot
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import plan_cell
from robomax_py.program import FrameDef, Header, LinMove, Program, ProgramSetup, PtpMove
from robomax_py.publish import publish
from robomax_py.robot import RobotModel
from robomax_py.verify import verify_program

REPO = Path(__file__).resolve().parents[2]
CEILING = REPO / "tests" / "data" / "ceiling_cell" / "ceiling_cell.yaml"
# Where the hand-composed weld target may lie from the spot: the .dat states mm to 3 decimals and
# the plan puts the TCP on the spot to well under 0.1 mm (verify's weld tolerance).
SPOT_TOL_MM = 0.1


@pytest.fixture(scope="module")
def ceiling(tmp_path_factory: pytest.TempPathFactory, shared_once: Callable[[str, Callable[[], Any]], Any]) -> Path:
    """The ceiling cell planned once per test run, its KRL written into a folder; the .src's path."""
    cell = load_cell(CEILING)
    robot = load_cell_robot(cell)

    def compute() -> dict[str, str]:
        result = plan_cell(cell, robot)
        assert result.status == "planned", result.message
        files, _ = publish(result, cell, robot, ("krl",))
        return dict(files)

    files: dict[str, str] = shared_once(f"ceiling|krl|{CEILING.read_text()}", compute)
    folder = tmp_path_factory.mktemp("ceiling")
    for name, text in files.items():
        if not name.endswith(".json"):      # the manifest names the set: the edited copies are lone programs
            (folder / name).write_text(text)
    return folder / "ceiling_cell.src"


def _edited(src: Path, folder: Path, file: str, old: str, new: str) -> Path:
    """A copy of the program's files in `folder` with `old` replaced by `new` in one of them."""
    folder.mkdir()
    for path in src.parent.glob("ceiling_cell*"):
        text = path.read_text()
        if path.name == file:
            assert old in text
            text = text.replace(old, new)
        (folder / path.name).write_text(text)
    return folder / src.name


def test_mount_tilt_is_judged_by_the_base_z_axis() -> None:
    def R(rpy: tuple[float, float, float]) -> Any:
        return Rotation.from_euler("xyz", rpy, degrees=True).as_matrix()

    # Upright (yawed, the test process cell's 2 deg riser) keeps the factory $ROBROOT; ceiling and wall do not.
    assert not is_tilted(R((0, 0, 90))) and not is_tilted(R((2, 0, 30)))
    assert is_tilted(R((180, 0, 30))) and is_tilted(R((0, 90, 0)))
    assert np.array_equal(robroot(R((2, 0, 30))), np.eye(4))
    assert np.allclose(robroot(R((180, 0, 30)))[:3, :3], R((180, 0, 30))) and not robroot(R((180, 0, 30)))[:3, 3].any()


def test_the_ceiling_program_states_the_robot_base_on_robroot_and_verifies_clean(ceiling: Path) -> None:
    frames = (ceiling.parent / "ceiling_cell_frames.src").read_text()
    assert "\nBASE_DATA[1] = $ROBROOT ; " in frames
    src = ceiling.read_text()
    assert "; KRL of KSS 8.x, mounted tilted (ceiling, wall): $BASE is relative to $WORLD" in src
    assert "Base[1]:robot_base" in src and "BASE_NO 0," not in ceiling.with_suffix(".dat").read_text()
    report = verify_program(load_cell(CEILING), load_cell_robot(load_cell(CEILING)), ceiling)
    assert report.clean, report.violations


@pytest.mark.parametrize(("file", "old", "new"), [
    # The frames stated as if $ROBROOT were $WORLD: base 0 ($WORLD), or the robot base as a literal.
    (".dat", "BASE_NO 1,", "BASE_NO 0,"),
    ("_frames.src", "BASE_DATA[1] = $ROBROOT ;", "BASE_DATA[1] = {X 0, Y 0, Z 0, A 0, B 0, C 0} ;"),
])
def test_frames_stated_as_if_robroot_were_world_are_reported(ceiling: Path, tmp_path: Path, file: str, old: str,
                                                             new: str) -> None:
    edited = _edited(ceiling, tmp_path / "old", f"ceiling_cell{file}", old, new)
    report = verify_program(load_cell(CEILING), load_cell_robot(load_cell(CEILING)), edited)
    found = [v for v in report.violations if v.kind == "frame"]
    assert found and "as if $ROBROOT were $WORLD" in found[0].detail and "180.0 deg off" in found[0].detail, \
        report.violations


def test_a_frame_stated_on_robroot_verifies_as_the_robot_base(ceiling: Path, tmp_path: Path) -> None:
    # `$ROBROOT : {null frame}` is `$ROBROOT`: the same motion.
    edited = _edited(ceiling, tmp_path / "linked", "ceiling_cell_frames.src", "BASE_DATA[1] = $ROBROOT ;",
                     "BASE_DATA[1] = $ROBROOT : {X 0, Y 0, Z 0, A 0, B 0, C 0} ;")
    report = verify_program(load_cell(CEILING), load_cell_robot(load_cell(CEILING)), edited)
    assert report.clean, report.violations


def _kuka(values: dict[str, float]) -> Any:
    """A KRL FRAME/E6POS (mm, deg; R = Rz(A) Ry(B) Rx(C)) as a (4, 4) pose in mm."""
    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler("ZYX", [values["A"], values["B"], values["C"]], degrees=True).as_matrix()
    T[:3, 3] = [values["X"], values["Y"], values["Z"]]
    return T


def _aggregate(text: str) -> dict[str, float]:
    return {k: float(v) for k, v in re.findall(r"\b([XYZABC])\s+(-?[0-9.]+)", text)}


def test_the_weld_target_composed_by_hand_is_the_spot(ceiling: Path) -> None:
    """The controller's composition written out from its definition, independently of robomax:
    TCP in the robot base = inv($ROBROOT) · $BASE · target, $BASE = $ROBROOT as the program
    stores it, $ROBROOT the mounting the integrator enters (the cell's robot.base rotation); the
    robot base in the cell is robot.base (the kr125's controller base is its URDF root)."""
    data = yaml.safe_load(CEILING.read_text())
    base = data["robot"]["base"]
    T_cell_base = np.eye(4)
    T_cell_base[:3, :3] = Rotation.from_euler("xyz", base["rpy"], degrees=True).as_matrix()
    T_cell_base[:3, 3] = np.asarray(base["xyz"]) * 1000.0
    T_world_robroot = np.eye(4)
    T_world_robroot[:3, :3] = T_cell_base[:3, :3]
    src = ceiling.read_text().splitlines()
    dat = ceiling.with_suffix(".dat").read_text()
    weld = next(i for i, line in enumerate(src) if line.startswith("spot_weld(1,"))
    point = next(re.match(r"LIN (XP\d+)", line)[1] for line in reversed(src[:weld])      # type: ignore[index]
                 if re.match(r"LIN XP\d+", line))
    target = _kuka(_aggregate(re.search(rf"DECL E6POS {point}=\{{([^}}]*)\}}", dat)[1]))     # type: ignore[index]
    spot = np.asarray(next(s for s in data["seams"][0]["spots"] if s["name"] == "s7")["xyz"]) * 1000.0
    BASE = T_world_robroot                                                    # BASE_DATA[1] = $ROBROOT
    tcp = T_cell_base @ np.linalg.inv(T_world_robroot) @ BASE @ target
    assert np.linalg.norm(tcp[:3, 3] - spot) < SPOT_TOL_MM
    # The same target with $BASE = $WORLD (the factory form) lands far from the spot: upside down.
    upright = T_cell_base @ np.linalg.inv(T_world_robroot) @ np.eye(4) @ target
    assert np.linalg.norm(upright[:3, 3] - spot) > 500.0


def test_a_user_frame_on_a_tilted_mount_is_stated_on_robroot_and_read_back(kr125: RobotModel) -> None:
    header = Header("c", "kr125", "gun", 1.0, tuple(f"joint_a{i}" for i in range(1, 7)))
    tool = FrameDef("TOOL_DATA[1]", "tool", (0.0, 0.0, 200.0), (0.0, 0.0, 0.0), 1)
    plate = FrameDef("BASE_DATA[3]", "base", (1200.0, -50.0, 300.0), (90.0, 0.0, 0.0), 3)
    program = Program("c", header, (tool, plate), (
        PtpMove((0.0, -90.0, 90.0, 0.0, 0.0, 0.0)),
        LinMove((100.0, 0.0, 50.0), (0.0, 90.0, 0.0), "S010 T000010", 200.0, tool="TOOL_DATA[1]", base="BASE_DATA[3]"),
    ), ProgramSetup(tilted_mount=True))
    texts = krl.write(program, kr125)
    assert ("\nBASE_DATA[3] = $ROBROOT : {X 1200.000, Y -50.000, Z 300.000, A 90.0000, B 0.0000, C 0.0000} ; "
            in texts[krl.FRAMES_FILE])
    read = {f.name: f for f in krl.parse(texts, "c.src", kr125).program.frames}["BASE_DATA[3]"]
    assert (read.xyz_mm, read.zyx_deg, read.in_world) == (plate.xyz_mm, plate.zyx_deg, False)
    # Upright, the same frame is a literal relative to $WORLD (= the robot base there).
    upright = krl.write(Program("c", header, (tool, plate), program.instructions), kr125)[krl.FRAMES_FILE]
    assert "\nBASE_DATA[3] = {X 1200.000," in upright
    assert {f.name: f for f in krl.parse({**texts, krl.FRAMES_FILE: upright}, "c.src", kr125).program.frames}[
        "BASE_DATA[3]"].in_world


@pytest.fixture(scope="module")
def kr125() -> RobotModel:
    return load_cell_robot(load_cell(REPO / "cells" / "cabin_flange.yaml"))
