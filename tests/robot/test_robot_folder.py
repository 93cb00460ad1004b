"""A new OPW arm is a folder, not code: robot.yaml + URDF written here solve through the normal path.

The URDF is built from the OPW convention joint by joint (offsets and signs in the joint origins and
axes), so Pinocchio's forward kinematics of it is independent of the closed-form IK under test.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from robomax_py.io.robot import load_robot_spec
from robomax_py.robot import fk_flange, load_robot
from robomax_py.robot.solve import solve_all
from robomax_py.transforms import rotation_angle

POS_TOL_M = 1e-9
ROT_TOL_RAD = 1e-9
Q_TOL_RAD = 1e-6   # recovering the original q away from singularities

PARAMS = {"a1": 0.3, "a2": -0.05, "b": 0.02, "c1": 0.6, "c2": 0.9, "c3": 0.8, "c4": 0.12}
OFFSETS_DEG = [10.0, -90.0, 5.0, 0.0, 0.0, 180.0]
SIGNS = [1, -1, 1, -1, 1, 1]
LOWER_DEG = [-170, -140, -120, -300, -125, -300]
UPPER_DEG = [170, 60, 150, 300, 125, 300]


def write_arm(folder: Path) -> Path:
    p = PARAMS
    # (xyz of the joint origin in the parent link, rotation axis index: 2 = z, 1 = y)
    joints = [((0, 0, 0), 2), ((p["a1"], p["b"], p["c1"]), 1), ((0, 0, p["c2"]), 1),
              ((p["a2"], 0, p["c3"]), 2), ((0, 0, 0), 1), ((0, 0, 0), 2)]
    parts = ['<robot name="testarm">', '<link name="base_link"/>']
    for k, ((x, y, z), axis) in enumerate(joints):
        off = -math.radians(OFFSETS_DEG[k])
        rpy = [0.0, 0.0, 0.0]
        rpy[axis] = off
        ax = [0, 0, 0]
        ax[axis] = SIGNS[k]
        parent = "base_link" if k == 0 else f"link_{k}"
        parts.append(
            f'<joint name="j{k + 1}" type="revolute"><parent link="{parent}"/><child link="link_{k + 1}"/>'
            f'<origin xyz="{x} {y} {z}" rpy="{rpy[0]} {rpy[1]} {rpy[2]}"/><axis xyz="{ax[0]} {ax[1]} {ax[2]}"/>'
            f'<limit lower="{math.radians(LOWER_DEG[k])}" upper="{math.radians(UPPER_DEG[k])}" velocity="2" effort="1"/>'
            f"</joint>"
        )
        parts.append(f'<link name="link_{k + 1}"/>')
    parts.append(f'<joint name="flange" type="fixed"><parent link="link_6"/><child link="tool0"/>'
                 f'<origin xyz="0 0 {p["c4"]}"/></joint><link name="tool0"/></robot>')
    folder.mkdir(parents=True)
    (folder / "testarm.urdf").write_text("\n".join(parts))
    lines = ["name: testarm", "urdf: testarm.urdf", "flange: tool0", "ik:", "  solver: opw", "  params:"]
    lines += [f"    {k}: {v}" for k, v in p.items()]
    lines += [f"    offsets: {OFFSETS_DEG}", f"    sign_corrections: {SIGNS}"]
    (folder / "robot.yaml").write_text("\n".join(lines) + "\n")
    return folder / "robot.yaml"


def test_opw_arm_from_a_folder_solves(tmp_path: Path) -> None:
    robot = load_robot(load_robot_spec(write_arm(tmp_path / "testarm")))
    rng = np.random.default_rng(7)
    q = rng.uniform(robot.limits.lower, robot.limits.upper, size=(300, 6))
    q = q[np.abs(np.sin(q[:, 4] * SIGNS[4] - math.radians(OFFSETS_DEG[4]))) > 0.05]   # away from the wrist singularity
    T = fk_flange(robot, q)
    table = solve_all(robot, T)
    assert table.valid.any(axis=-1).all()
    for k in range(len(q)):
        cols = np.flatnonzero(table.valid[k])
        got = fk_flange(robot, table.q[k, cols])
        np.testing.assert_allclose(got[:, :3, 3], np.broadcast_to(T[k, :3, 3], (len(cols), 3)), atol=POS_TOL_M)
        assert rotation_angle(got[:, :3, :3], T[k, :3, :3]).max() <= ROT_TOL_RAD
        assert np.abs(table.q[k, cols] - q[k]).max(axis=1).min() <= Q_TOL_RAD


@pytest.mark.parametrize("key", ["c2", "offsets"])
def test_broken_params_name_the_key(tmp_path: Path, key: str) -> None:
    path = write_arm(tmp_path / "testarm")
    text = path.read_text()
    text = text.replace("    c2: 0.9\n", "") if key == "c2" else text.replace("offsets: [10.0, -90.0, 5.0, 0.0, 0.0, 180.0]", "offsets: [10.0]")
    path.write_text(text)
    from robomax_py.errors import RobotModelError

    with pytest.raises(RobotModelError, match=rf"robot\.yaml: ik\.params\.{key}"):
        load_robot_spec(path)
