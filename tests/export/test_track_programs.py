"""A six-axis arm on a floor track (a prismatic first joint, `urdf_case.track_arm_urdf`), placed off
the cell's origin and turned, welds two spots farther apart than the arm reaches. A program states
a prismatic joint's value in mm (a revolute one's in deg): checked here by reading the SRCL text
from its definition (docs/srcl.md), not with the package's reader, against the planned trajectory.
Before, the track's metres were written as if they were radians (0.5 m as 28.6479)."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from hypothesis import given
from hypothesis import strategies as st
from typer.testing import CliRunner
from urdf_case import TRACK_JOINTS, serial_urdf, track_arm_urdf

from robomax_py.app.cli import app
from robomax_py.app.import_urdf import import_urdf
from robomax_py.errors import ProgramError
from robomax_py.export.dialect import not_six_axes
from robomax_py.io.robot import load_robot_spec
from robomax_py.program import PtpMove, as_written_joints, ptp_target, stated_joints
from robomax_py.robot import load_robot
from robomax_py.verify import read_program_files

runner = CliRunner()
GOLDEN_KRL = Path(__file__).resolve().parents[1] / "golden" / "small_cell" / "small_cell.src"
UP = [0.0, 0.0, 1.0]
# SRCL states joint values with 4 decimals: 5e-5 mm (5e-8 m) or 5e-5 deg (8.7e-7 rad) of rounding.
STATED_M = 1e-7
STATED_RAD = 1e-6
_PTP = re.compile(r"MOVE PTP AXIS\(([^)]*)\)")


@pytest.fixture(scope="module")
def planned(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """The cell and its output folder, planned once with `robomax plan`."""
    folder = tmp_path_factory.mktemp("track")
    import_urdf(track_arm_urdf(folder / "track_arm.urdf"), folder / "robots" / "track_arm")
    tolerance = {"alpha": 15, "beta": 15, "gamma": [-180, 180]}
    data: dict[str, Any] = {
        "robomax": 1, "name": "track_panel",
        # The track's zero at x = 3.0 m, running towards -x: the robot turned 180 deg, 0.1 m up.
        "robot": {"model": "../robots/track_arm/robot.yaml", "base": {"xyz": [3.0, -0.8, 0.1], "rpy": [0, 0, 180]},
                  "home": [0.5, 0, -20, 60, 0, 50, 0]},
        "tool": "spot_gun_light",
        "objects": [
            # The panel overhangs the table by 0.1 m on the robot's side, where the gun closes on it.
            {"name": "table", "box": [2.8, 0.2, 0.8], "pose": {"xyz": [1.6, 0.0, 0.4]}},
            {"name": "panel", "box": [2.6, 0.3, 0.0015], "workpiece": True, "pose": {"xyz": [1.6, -0.05, 0.80075]}}],
        "seams": [{"name": "edge", "ordered": False, "tolerance": tolerance, "grid": 3,
                   "spots": [{"name": name, "xyz": [x, -0.17, 0.8015], "normal": UP, "direction": [1, 0, 0]}
                             for name, x in (("near", 2.7), ("far", 0.5))]}],
        "process": {"weld_time": 0.3, "approach": 0.03, "clearance": 0.005},
        "planner": {"seed": 0},
    }
    cell = folder / "cells" / "track_panel.yaml"
    cell.parent.mkdir()
    cell.write_text(yaml.safe_dump(data, sort_keys=False))
    out = folder / "out"
    done = runner.invoke(app, ["plan", str(cell), "--out", str(out)])
    assert done.exit_code == 0, done.output
    return cell, out


def _stated(values: str) -> np.ndarray:
    """One AXIS(...) as docs/srcl.md defines it: the track (the first joint, prismatic) in mm, the
    arm's joints in deg; returned in m and rad."""
    v = [float(x) for x in values.split(",")]
    return np.array([v[0] / 1000.0, *(math.radians(a) for a in v[1:])])


def test_the_track_is_stated_in_mm_and_the_program_is_the_plan(planned: tuple[Path, Path]) -> None:
    cell, out = planned
    text = (out / "track_panel.srcl").read_text()
    targets = [_stated(m.group(1)) for m in _PTP.finditer(text)]
    assert targets[0][0] == pytest.approx(0.5, abs=STATED_M)             # home: 0.5 m, written 500.0000
    assert "AXIS(500.0000, 0.0000, -20.0000, 60.0000, 0.0000, 50.0000, 0.0000)" in text
    traj = json.loads((out / "track_panel.json").read_text())
    q = np.asarray(traj["q"])
    # The spots are 2.2 m apart: the arm alone does not span them, the track carried it along.
    assert float(q[:, 0].max()) - float(q[:, 0].min()) > 0.5
    # Every joint target the program states is where the planned motion goes, to the stated decimals.
    for target in targets:
        off = np.abs(q - target)
        nearest = off[int(np.argmin(off.max(axis=1)))]
        assert nearest[0] <= STATED_M and nearest[1:].max() <= STATED_RAD
    checked = runner.invoke(app, ["verify", str(cell), str(out / "track_panel.srcl")])
    assert checked.exit_code == 0 and "clean" in checked.output, checked.output


def test_a_track_moved_in_the_program_is_seen_by_verify(planned: tuple[Path, Path], tmp_path: Path) -> None:
    """500 mm read as 500 deg, or the other way round, would pass here or fail the plan above."""
    cell, out = planned
    text = (out / "track_panel.srcl").read_text()
    moved = text.replace("AXIS(500.0000, ", "AXIS(2900.0000, ", 1)       # the start 2.4 m along the track
    assert moved != text
    program = tmp_path / "track_panel.srcl"
    program.write_text(moved)
    checked = runner.invoke(app, ["verify", str(cell), str(program)])
    assert checked.exit_code == 1, checked.output


def test_six_axis_dialects_refuse_a_prismatic_joint(planned: tuple[Path, Path], tmp_path: Path) -> None:
    cell, _ = planned
    robot = load_robot(load_robot_spec(cell.parent.parent / "robots" / "track_arm" / "robot.yaml"))
    assert robot.prismatic == (True, *(False,) * 6)
    assert "7 joints" in not_six_axes(robot, "krl")
    done = runner.invoke(app, ["plan", str(cell), "--out", str(tmp_path / "o"), "--format", "rapid"])
    assert done.exit_code == 2 and "rapid programs are for 6-axis arms" in done.output



def test_check_counts_the_track_in_the_arms_reach(planned: tuple[Path, Path], tmp_path: Path) -> None:
    """`check` bounds each spot's reach without IK; the bound moved the arm's shoulder along the
    track's travel. Before, it took the track for axis 1 and refused this cell, which plans."""
    cell, _ = planned
    done = runner.invoke(app, ["check", str(cell)])
    assert done.exit_code == 0 and "all 2 spots within reach" in done.output, done.output
    data = yaml.safe_load(cell.read_text())
    data["seams"][0]["spots"][1]["xyz"] = [-2.5, -0.17, 0.8015]      # 2.5 m beyond the track's far end
    far = cell.parent / "beyond.yaml"
    far.write_text(yaml.safe_dump(data, sort_keys=False))
    done = runner.invoke(app, ["check", str(far)])
    assert done.exit_code == 2 and "seams[0].spots[1]: spot edge/far is out of track_arm's reach by" in \
        " ".join(done.output.split()), done.output


def test_the_reach_bound_never_refuses_a_pose_the_arm_takes(planned: tuple[Path, Path]) -> None:
    """Every TCP pose of a configuration within the limits (the track anywhere on its travel) lies
    within the bound: the bound may only be weaker than the arm, never stronger."""
    from robomax_py.plan import reach
    from robomax_py.robot import fk_tcp, mount_tool

    cell, _ = planned
    robot = load_robot(load_robot_spec(cell.parent.parent / "robots" / "track_arm" / "robot.yaml"))
    robot = mount_tool(robot, np.eye(4))
    model = reach._reach_model(robot)
    assert model is not None and len(model.offsets) == reach.TRAVEL_SAMPLES
    rng = np.random.default_rng(7)
    q = rng.uniform(robot.limits.lower, robot.limits.upper, (2000, robot.dof))
    T = fk_tcp(robot, q)
    points = np.einsum("nij,j->ni", T, np.append(model.p_tcp_ref, 1.0))[:, :3]
    best = np.full(len(q), np.inf)
    for offset in model.offsets:
        best = np.minimum(best, reach._distance_to_circle(points - offset, model))
    assert np.all(best - model.offset_slack_m <= model.reach + 1e-9)


def test_a_six_joint_arm_with_a_track_is_not_taken_for_a_six_axis_arm(tmp_path: Path) -> None:
    """A track under a five-axis arm makes six joints; a dialect stating every joint in deg must
    still refuse it."""
    urdf = serial_urdf(tmp_path / "track5.urdf", "track5", TRACK_JOINTS[:6], '<origin xyz="0 0 0"/>',
                       prismatic=frozenset({1}))
    robot = load_robot(load_robot_spec(import_urdf(urdf, tmp_path / "track5").folder / "robot.yaml"))
    assert robot.dof == 6
    assert not_six_axes(robot, "krl") == "krl programs are for arms of six revolute axes; track5's j1 is prismatic"
    # Nor does verify read a KRL program as this arm's: its A1 in deg would be taken for the track in mm.
    with pytest.raises(ProgramError, match="cannot be this robot's program: krl programs are for arms of six revolute"):
        read_program_files(robot, GOLDEN_KRL)


@given(st.lists(st.floats(-6.0, 6.0), min_size=7, max_size=7), st.lists(st.booleans(), min_size=7, max_size=7))
def test_stated_values_are_deg_or_mm_and_come_back_within_their_decimals(q: list[float], kinds: list[bool]) -> None:
    stated = stated_joints(np.array(q), kinds)
    for value, given_value, prismatic in zip(stated, q, kinds):
        assert value == pytest.approx(given_value * (1000.0 if prismatic else 180.0 / math.pi), rel=1e-12)
    back = as_written_joints(np.array(q), kinds)
    off = np.abs(back - np.array(q))
    assert np.all(off <= np.where(kinds, 0.5e-7, math.radians(0.5e-4)) + 1e-15)
    # Revolute joints go through the arithmetic every six-axis plan has used, to the bit.
    revolute = ~np.array(kinds)
    np.testing.assert_array_equal(back[revolute], np.deg2rad([round(float(v), 4) for v in np.degrees(np.array(q))[revolute]]))
    np.testing.assert_array_equal(ptp_target(PtpMove(tuple(1000.0 * np.array(q))), [True] * 7),
                                  np.round(1000.0 * np.array(q), 4) / 1000.0)
