"""A seven-joint arm (the LBR iiwa 14 R820's kinematics, `urdf_case.iiwa14_urdf`) welds a panel
held on a post above a table: planned from the command line, its program verifies clean, and a
six-axis dialect is refused. Before approach lines and LIN moves followed the self-motion, no spot
of such an arm had a candidate."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml
from typer.testing import CliRunner
from urdf_case import iiwa14_urdf

from robomax_py.app.cli import app
from robomax_py.app.import_urdf import import_urdf

runner = CliRunner()
UP = [0.0, 0.0, 1.0]
ALONG = [0.978148, -0.207912, 0.0]           # the panel's long edge: the panel turned -12 deg


def _cell(folder: Path, pin: str | None = None) -> Path:
    import_urdf(iiwa14_urdf(folder / "iiwa.urdf"), folder / "robots" / "iiwa")
    tolerance = {"alpha": 15, "beta": 15, "gamma": [-180, 180]}
    data: dict[str, Any] = {
        "robomax": 1, "name": "iiwa_panel",
        "robot": {"model": "../robots/iiwa/robot.yaml", "base": {"xyz": [0.0, -0.05, 0.6], "rpy": [0, 0, 20]},
                  "home": [0, 20, 0, -80, 0, 60, 0]},
        "tool": "spot_gun_light",
        "objects": [
            {"name": "pedestal", "box": [0.3, 0.3, 0.6], "pose": {"xyz": [0.0, -0.05, 0.3]}},
            {"name": "table", "box": [0.6, 0.5, 0.75], "pose": {"xyz": [0.6, 0.05, 0.375], "rpy": [0, 0, -12]}},
            {"name": "post", "box": [0.08, 0.08, 0.2], "pose": {"xyz": [0.55, 0.05, 0.85], "rpy": [0, 0, -12]}},
            {"name": "panel", "box": [0.4, 0.22, 0.0015], "workpiece": True,
             "pose": {"xyz": [0.55, 0.05, 0.95075], "rpy": [0, 0, -12]}}],
        "seams": [
            {"name": "edge_near", "ordered": False, "tolerance": tolerance, "grid": 3,
             "spots": [{"name": name, "xyz": xyz, "normal": UP, "direction": ALONG} for name, xyz in (
                 ("n2", [0.45408, -0.01651, 0.9515]), ("n3", [0.53233, -0.03314, 0.9515]),
                 ("n4", [0.61058, -0.04978, 0.9515]))]},
            {"name": "ends", "ordered": False, "tolerance": tolerance, "grid": 5,
             "spots": [{"name": "e1", "xyz": [0.7087, -0.04507, 0.9515], "normal": UP,
                        "direction": [0.207912, 0.978148, 0.0]}]}],
        "process": {"weld_time": 0.3, "approach": 0.03, "clearance": 0.005},
        "planner": {"seed": 0},
    }
    if pin is not None:
        data["seams"][0]["spots"][1]["config"] = pin
    path = folder / "cells" / "iiwa_panel.yaml"
    path.parent.mkdir()
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def test_a_seven_joint_arm_plans_and_its_program_verifies(tmp_path: Path) -> None:
    cell = _cell(tmp_path)
    done = runner.invoke(app, ["plan", str(cell), "--out", str(tmp_path / "out")])
    assert done.exit_code == 0, done.output
    program = tmp_path / "out" / "iiwa_panel.srcl"
    text = program.read_text()
    assert "AXES(joint_a1, joint_a2, joint_a3, joint_a4, joint_a5, joint_a6, joint_a7)" in text
    assert text.count("MOVE LIN") == text.count("CONFIG ''") == 8       # four spots: approach, retract
    checked = runner.invoke(app, ["verify", str(cell), str(program)])
    assert checked.exit_code == 0 and "clean" in checked.output, checked.output


def test_six_axis_dialects_are_refused_before_planning_and_passed_over_by_all(tmp_path: Path) -> None:
    cell = _cell(tmp_path)
    for asked in ("krl", "native"):                      # robot.yaml says kuka: native is KRL
        done = runner.invoke(app, ["plan", str(cell), "--out", str(tmp_path / "out"), "--format", asked])
        assert done.exit_code == 2
        assert "krl programs are for 6-axis arms; iiwa has 7 joints" in done.output
        assert "planning" not in done.output and not (tmp_path / "out").exists()
    done = runner.invoke(app, ["plan", str(cell), "--out", str(tmp_path / "out"), "--format", "all"])
    assert done.exit_code == 0, done.output
    assert sorted(p.name for p in (tmp_path / "out").glob("iiwa_panel*")) == [
        "iiwa_panel.json", "iiwa_panel.manifest.json", "iiwa_panel.srcl"]
    for dialect in ("krl", "rapid", "fanuc", "urscript", "inform", "as"):
        assert f"no {dialect} program written ({dialect} programs are for 6-axis arms" in done.output


def test_configuration_data_pinned_on_it_is_refused_naming_the_key(tmp_path: Path) -> None:
    cell = _cell(tmp_path, pin="S010 T000000")
    done = runner.invoke(app, ["plan", str(cell), "--out", str(tmp_path / "out")])
    assert done.exit_code == 2 and "Traceback" not in done.output
    assert f"{cell}: seams[0].spots[1].config: iiwa has 7 joints: its targets carry no configuration data" in \
        " ".join(done.output.split())
    assert not (tmp_path / "out").exists()
    checked = runner.invoke(app, ["check", str(cell)])
    assert checked.exit_code == 2 and "seams[0].spots[1].config" in " ".join(checked.output.split())
