"""xacro arguments for `import-urdf`: `--xacro-arg NAME:=VALUE`, the values a package's
`launch/load_<robot>.launch` passes, and a message naming the argument when a file name built from
an empty one names nothing (tests/data/xacro_args: a small arm whose joint velocities come from the
YAML file the argument `joint_velocities_file` names, read with old xacro's bare `load_yaml`)."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from typer.testing import CliRunner

from robomax_py.app.cli import app
from robomax_py.app.import_urdf import import_urdf
from robomax_py.errors import RobotModelError

PACKAGES = Path(__file__).parent.parent / "data" / "xacro_args"
PKG = PACKAGES / "args_arm_support"
SOURCE = PKG / "urdf" / "args_arm.xacro"
VELOCITY_TOL = 1e-12
runner = CliRunner()


def _velocities_deg_s(folder: Path) -> list[float]:
    root = ET.parse(folder / "args_arm.urdf").getroot()
    return [math.degrees(float(j.find("limit").get("velocity"))) for j in root.findall("joint")  # type: ignore[union-attr]
            if j.get("type") == "revolute"]


def test_without_the_argument_the_message_names_it_and_the_launch_value(tmp_path: Path) -> None:
    result = runner.invoke(app, ["import-urdf", str(SOURCE), "-o", str(tmp_path / "args_arm"),
                                 "--packages", str(PACKAGES)])
    assert result.exit_code == 2
    text = " ".join(result.output.split())
    assert "the xacro argument joint_velocities_file is empty" in text
    assert "--xacro-arg joint_velocities_file:=VALUE" in text
    assert "load_args_arm.launch passes joint_velocities_file:=" in text and "--xacro-arg controller:=VALUE" in text
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_xacro_arg_names_the_file(tmp_path: Path) -> None:
    slow = PKG / "config" / "joint_velocities_slow.yaml"
    result = runner.invoke(app, ["import-urdf", str(SOURCE), "-o", str(tmp_path / "args_arm"), "--packages", str(PACKAGES),
                                 "--xacro-arg", f"joint_velocities_file:={slow}"])
    assert result.exit_code == 0, result.output
    assert _velocities_deg_s(tmp_path / "args_arm") == pytest.approx([100, 90, 80, 200, 190, 300], abs=VELOCITY_TOL)


def test_the_launch_files_value_is_used_and_noted(tmp_path: Path) -> None:
    r = import_urdf(SOURCE, tmp_path / "args_arm", (PACKAGES,), xacro_args={"controller": "fast"})
    assert _velocities_deg_s(r.folder) == pytest.approx([150, 140, 130, 250, 240, 400], abs=VELOCITY_TOL)
    assert any("xacro argument joint_velocities_file:=" in w and "joint_velocities_fast.yaml" in w
               and "load_args_arm.launch" in w for w in r.warnings)
    # An argument given wins over the launch file's value.
    slow = PKG / "config" / "joint_velocities_slow.yaml"
    r = import_urdf(SOURCE, tmp_path / "args_arm", (PACKAGES,), force=True,
                    xacro_args={"controller": "fast", "joint_velocities_file": str(slow)})
    assert _velocities_deg_s(r.folder)[0] == pytest.approx(100, abs=VELOCITY_TOL)
    assert not any("load_args_arm.launch" in w for w in r.warnings)


def test_bad_xacro_args(tmp_path: Path) -> None:
    result = runner.invoke(app, ["import-urdf", str(SOURCE), "-o", str(tmp_path / "a"), "--xacro-arg", "oops"])
    assert result.exit_code == 2 and "--xacro-arg" in result.output and "NAME:=VALUE" in result.output
    # A file name outside the package folders is refused as every other read is.
    outside = tmp_path / "v.yaml"
    outside.write_text("joint_1: 1\n")
    with pytest.raises(RobotModelError, match="outside the package folders"):
        import_urdf(SOURCE, tmp_path / "args_arm", xacro_args={"joint_velocities_file": str(outside)})
