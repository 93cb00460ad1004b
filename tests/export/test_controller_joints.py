"""robot.yaml `controller.joint_signs` / `controller.joint_zeros_deg`: controller programs state each
joint as the controller counts it (sign * URDF value + zero, deg); SRCL and the trajectory keep the
URDF's values; what verify rebuilds from the controller's values is the plan."""

from __future__ import annotations

import dataclasses
import math
import re
import shutil
from pathlib import Path
from typing import Any

import pytest

from robomax_py.errors import RobotModelError
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.io.robot import load_robot_spec
from robomax_py.plan import plan_cell
from robomax_py.publish import publish
from robomax_py.robot import load_robot
from robomax_py.verify import verify_program
from tests.conftest import with_pulses

SIGNS = (-1.0, 1.0, -1.0, -1.0, 1.0, -1.0)
# Whole numbers of the test's INFORM pulses (tests/conftest.py), as an encoder's zero is: the home
# then stays exactly the home in pulses.
ZEROS_DEG = (10.0, -90.0, 90.0, 0.0, 0.0, 30.0)
FORMATS = ("srcl", "krl", "rapid", "urscript", "fanuc", "inform", "as")


def _numbers(text: str) -> list[float]:
    return [float(v) for v in re.findall(r"-?\d+\.\d+|-?\d+", text)]


@pytest.fixture(scope="module")
def written(tmp_path_factory: pytest.TempPathFactory, write_small_cell) -> dict[str, Any]:  # type: ignore[no-untyped-def]
    folder = tmp_path_factory.mktemp("conventions")
    cell = load_cell(write_small_cell(folder))
    plain = with_pulses(load_cell_robot(cell))           # INFORM counts joint positions in pulses
    robot = dataclasses.replace(plain, controller=dataclasses.replace(
        plain.controller, joint_signs=SIGNS, joint_zeros=tuple(math.radians(z) for z in ZEROS_DEG)))
    result = plan_cell(cell, robot)
    assert result.status == "planned", result.message
    files, _ = publish(result, cell, robot, FORMATS)      # proven: read back and rebuilt to the plan
    plain_files, _ = publish(result, cell, plain, FORMATS)
    for name, text in files.items():
        (folder / name).write_text(text)
    return {"cell": cell, "robot": robot, "files": files, "plain": plain_files, "folder": folder,
            "name": result.cell}


def _srcl_targets(written: dict[str, Any]) -> list[list[float]]:
    text = written["files"][f"{written['name']}.srcl"]
    return [_numbers(m) for m in re.findall(r"MOVE PTP AXIS\(([^)]*)\)", text)]


def _expected(urdf_deg: list[float]) -> list[float]:
    # Computed here from the keys' definition, not by robomax: controller = sign * URDF + zero.
    return [s * v + z for v, s, z in zip(urdf_deg, SIGNS, ZEROS_DEG)]


def test_joint_targets_are_the_controllers_values(written: dict[str, Any]) -> None:
    name, files = written["name"], written["files"]
    urdf = _srcl_targets(written)
    assert len(urdf) >= 3
    krl = [_numbers(re.sub(r"[AE]\d ", " ", m))[:6]
           for m in re.findall(r"DECL E6AXIS XP\d+=\{([^}]*)\}", files[f"{name}.dat"])]
    rapid = [_numbers(m) for m in re.findall(r"CONST jointtarget jt\d+ := \[\[([^\]]*)\]", files[f"{name}.mod"])]
    ur = [[math.degrees(v) for v in _numbers(m)] for m in re.findall(r"movej\(\[([^\]]*)\]", files[f"{name}.script"])]
    fanuc_text = next(t for f, t in files.items() if f.endswith(".ls") and f.upper().startswith(name.upper()))
    fanuc = [[float(v) for v in re.findall(r"J\d=\s*(-?\d*\.\d+) deg", block)]
             for block in re.findall(r"P\[\d+[^\]]*\]\{(.*?)\};", fanuc_text, re.DOTALL) if "J1=" in block]
    for got in (krl, rapid, ur, fanuc):
        assert len(got) == len(urdf)
        for g, u in zip(got, urdf):
            assert g == pytest.approx(_expected(u), abs=1e-4)
    # The home (URDF 0, -90, 90, 0, 0, 0) as this controller counts it.
    assert krl[0] == pytest.approx([10, -180, 0, 0, 0, 30], abs=1e-4)


def test_srcl_keeps_the_urdf_values_and_the_plain_robot_is_unchanged(written: dict[str, Any]) -> None:
    name = written["name"]
    assert written["files"][f"{name}.srcl"] == written["plain"][f"{name}.srcl"]
    assert written["files"][f"{name}.dat"] != written["plain"][f"{name}.dat"]
    # Cartesian targets do not depend on how the controller counts its joints.
    lins = [re.findall(r"LIN .*", t) for t in (written["files"][f"{name}.src"], written["plain"][f"{name}.src"])]
    assert lins[0] == lins[1]


@pytest.mark.parametrize("ext", [".src", ".mod", ".script", ".ls", ".jbi", ".as"])
def test_verify_rebuilds_the_plan_from_the_controllers_values(written: dict[str, Any], ext: str) -> None:
    # FANUC and INFORM name the file after the program (capitals).
    [main] = [f for f in written["files"] if f.lower() == f"{written['name']}{ext}"]
    report = verify_program(written["cell"], written["robot"], written["folder"] / main)
    assert report.clean, report.violations[:3]


def _robot_yaml(tmp_path: Path, name: str, controller: str) -> Path:
    """A copy of the shipped kr16 with `controller` lines in place of its controller section."""
    shutil.copytree(Path(__file__).resolve().parents[2] / "robomax_py" / "robots" / "kr16", tmp_path / name)
    path = tmp_path / name / "robot.yaml"
    body = re.sub(r"(?ms)^controller:.*?(?=^\S|\Z)", "", path.read_text()).replace("name: kr16", f"name: {name}")
    path.write_text(body + f"controller:\n  brand: kuka\n{controller}")
    return path


def test_keys_are_read_in_degrees_and_checked(tmp_path: Path) -> None:
    spec = load_robot_spec(_robot_yaml(tmp_path, "a", "  joint_signs: [-1, 1, 1, -1, 1, -1]\n"
                                                       "  joint_zeros_deg: [0, -90, 90, 0, 0, 180]\n"))
    assert spec.controller.joint_signs == (-1, 1, 1, -1, 1, -1)
    assert spec.controller.joint_zeros == pytest.approx((0, -math.pi / 2, math.pi / 2, 0, 0, math.pi))
    for name, bad, key in (("b", "  joint_signs: [1, 2, 1, 1, 1, 1]\n", "joint_signs"),
                           ("c", "  joint_zeros_deg: [0, .nan, 0, 0, 0, 0]\n", "joint_zeros_deg")):
        with pytest.raises(RobotModelError, match=key):
            load_robot_spec(_robot_yaml(tmp_path, name, bad))
    with pytest.raises(RobotModelError, match=r"controller.joint_signs.*expected 6 values"):
        load_robot(load_robot_spec(_robot_yaml(tmp_path, "d", "  joint_signs: [1, 1, 1]\n")))
