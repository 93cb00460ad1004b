"""Link pairs touching in every posture (an ABB arm's link_4 and link_6 in ROS-Industrial's meshes):
`import-urdf` writes them into robot.yaml's `collision.disable` and names them; a hand-written
robot.yaml without them gets a plan message saying what the contact is and how to exempt it.

The arm is made here: six revolute joints, joint 3 at joint 2's origin, and a 0.1 m box on link l1
and one on link l3 both centred on joint 2's axis point, so they overlap at every joint value
though l1 and l3 are not adjacent (l2 lies between them)."""

from __future__ import annotations

from pathlib import Path

import yaml
from typer.testing import CliRunner
from urdf_case import six_joint_urdf

from robomax_py.app.cli import app
from robomax_py.world.acm import CollisionOptions

runner = CliRunner()
SAMPLES = CollisionOptions().acm_samples


def _touchy_urdf(path: Path) -> Path:
    axes = ["0 0 1", "0 1 0", "0 1 0", "1 0 0", "0 1 0", "1 0 0"]
    origins = ["0 0 0.4", "0.1 0 0.3", "0 0 0", "0.5 0 0", "0.2 0 0", "0.1 0 0"]
    box = '<collision><origin xyz="{}"/><geometry><box size="0.1 0.1 0.1"/></geometry></collision>'
    # Both boxes around joint 2's point: l1 and l3 overlap in every posture.
    return six_joint_urdf(path, "touchy", axes, origins, {1: box.format("0.1 0 0.3"), 3: box.format("0 0 0")})


def test_import_writes_pairs_touching_in_every_sample_into_collision_disable(tmp_path: Path) -> None:
    source = _touchy_urdf(tmp_path / "touchy.urdf")
    done = runner.invoke(app, ["import-urdf", str(source), "-o", str(tmp_path / "touchy"), "--solver", "numeric"])
    assert done.exit_code == 0, done.output
    assert f"[l1, l3] touch in every one of {SAMPLES} sampled postures" in done.output
    text = (tmp_path / "touchy" / "robot.yaml").read_text()
    assert yaml.safe_load(text)["collision"]["disable"] == [["l1", "l3"]]
    assert f"in contact in {SAMPLES} of {SAMPLES} samples" in text and "Setup Assistant" in text

    # A pair the SRDF already disables is not written again; the SRDF stays the reason.
    srdf = tmp_path / "touchy.srdf"
    srdf.write_text('<robot name="touchy"><disable_collisions link1="l3" link2="l1" reason="Always"/></robot>')
    done = runner.invoke(app, ["import-urdf", str(source), "-o", str(tmp_path / "with_srdf" / "touchy"),
                               "--solver", "numeric", "--srdf", str(srdf), "--json"])
    assert done.exit_code == 0, done.output
    assert "collision" not in yaml.safe_load((tmp_path / "with_srdf" / "touchy" / "robot.yaml").read_text())


def test_plan_says_a_home_contact_is_a_pair_touching_in_every_posture(tmp_path: Path) -> None:
    folder = tmp_path / "robots" / "touchy"
    folder.mkdir(parents=True)
    _touchy_urdf(folder / "touchy.urdf")
    robot_yaml = folder / "robot.yaml"
    robot_yaml.write_text("name: touchy\nurdf: touchy.urdf\nflange: tool0\nik: {solver: numeric}\n")
    cell = tmp_path / "cells" / "touchy.yaml"
    cell.parent.mkdir()
    cell.write_text(
        "robomax: 1\nname: touchy_home\nrobot: {model: ../robots/touchy/robot.yaml, home: [0, 0, 0, 0, 0, 0]}\n"
        "tool: spot_gun_light\nseams:\n  - name: s\n    spots:\n"
        "      - {name: a, xyz: [0.6, 0.2, 0.5], normal: [1, 0, 0], direction: [0, 1, 0]}\n")
    done = runner.invoke(app, ["plan", str(cell), "-o", str(tmp_path / "out")])
    assert done.exit_code == 3, done.output
    [line] = [line for line in done.output.splitlines() if line.startswith("infeasible:")]   # one line, unwrapped
    assert f"home is in collision: l1 vs l3; links l1 and l3 touch in every one of the {SAMPLES} sampled postures" in line
    assert line.endswith(f"add [l1, l3] to collision.disable in {robot_yaml}")
    assert "Traceback" not in done.output and not (tmp_path / "out").exists()
