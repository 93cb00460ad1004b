"""The robot library and the example cells are package data: a built wheel carries them (a
non-editable install had no robots), and `package://` meshes resolve near the robot folder and via ROS_PACKAGE_PATH."""

from __future__ import annotations

import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from robomax_py.app.examples import example_files
from robomax_py.errors import RobotModelError
from robomax_py.io.robot import (
    ROS_PACKAGE_PATH_ENV,
    resolve_package_uri,
    shipped_robots_dir,
)

REPO = Path(__file__).resolve().parents[2]


@pytest.mark.slow
def test_wheel_contains_the_robot_library_and_the_example_cells(tmp_path: Path) -> None:
    done = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q",
                           "-w", str(tmp_path), str(REPO)], capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr
    (wheel,) = tmp_path.glob("robomax_py-*.whl")
    names = set(zipfile.ZipFile(wheel).namelist())
    shipped = [p.relative_to(REPO).as_posix() for p in shipped_robots_dir().rglob("*")
               if p.is_file() and "__pycache__" not in p.parts]
    assert shipped and all(n in names for n in shipped), sorted(set(shipped) - names)[:5]
    assert "robomax_py/robots/kr125/robot.yaml" in names
    assert "robomax_py/robots/tools/spot_gun_c/tool.yaml" in names
    wanted = {f"robomax_py/examples/{rel.as_posix()}" for rel in example_files()}
    assert wanted <= names, sorted(wanted - names)


def _package(root: Path, name: str) -> Path:
    mesh = root / name / "meshes" / "link.stl"
    mesh.parent.mkdir(parents=True)
    shutil.copy(shipped_robots_dir() / "tools" / "spot_gun_c" / "tips.stl", mesh)
    return mesh


def test_package_uri_next_to_the_robot_folder(tmp_path: Path) -> None:
    mesh = _package(tmp_path / "src", "my_support")
    robot = tmp_path / "src" / "robots" / "my_arm" / "robot.yaml"
    robot.parent.mkdir(parents=True)
    got = resolve_package_uri("package://my_support/meshes/link.stl", robot, "urdf")
    assert got.samefile(mesh)


def test_package_uri_on_ros_package_path(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    mesh = _package(tmp_path / "ws" / "src" / "deep", "far_support")
    robot = tmp_path / "elsewhere" / "robot.yaml"
    robot.parent.mkdir(parents=True)
    with pytest.raises(RobotModelError, match="package://far_support/meshes/link.stl not found"):
        resolve_package_uri("package://far_support/meshes/link.stl", robot, "urdf")
    monkeypatch.setenv(ROS_PACKAGE_PATH_ENV, str(tmp_path / "ws"))
    assert resolve_package_uri("package://far_support/meshes/link.stl", robot, "urdf").samefile(mesh)
