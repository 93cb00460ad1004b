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


# ---------------------------------------------------------------------------- controller.base default

def _with_base_link(path: Path, joints: str, controller: str | None = None) -> Path:
    """The test arm with extra URDF links and joints (`joints`, XML) and, optionally, a `controller`
    section for robot.yaml (YAML text under `controller:`)."""
    urdf = path.parent / "testarm.urdf"
    urdf.write_text(urdf.read_text().replace("</robot>", joints + "</robot>"))
    if controller is not None:
        path.write_text(path.read_text() + "controller:\n" + controller)
    return path


def _link_pose(urdf: Path, link: str) -> np.ndarray:
    """The link's pose in the URDF root frame at q = 0, from Pinocchio (not robomax_py's URDF reading)."""
    import pinocchio as pin

    model = pin.buildModelFromUrdf(str(urdf))
    data = model.createData()
    pin.framesForwardKinematics(model, data, pin.neutral(model))
    return np.asarray(data.oMf[model.getFrameId(link)].homogeneous)


ROS_I_BASE = ('<link name="base"/><joint name="base_link-base" type="fixed"><parent link="base_link"/>'
              '<child link="base"/><origin xyz="0.1 -0.2 0.45" rpy="0.1 -0.2 1.2"/></joint>')


def test_without_a_base_link_the_controller_base_is_the_root(tmp_path: Path) -> None:
    spec = load_robot_spec(write_arm(tmp_path / "testarm"))
    assert np.array_equal(spec.controller.T_root_base, np.eye(4))


def test_the_base_link_is_the_default_controller_base(tmp_path: Path) -> None:
    path = _with_base_link(write_arm(tmp_path / "testarm"), ROS_I_BASE)
    robot = load_robot(load_robot_spec(path))
    want = _link_pose(path.parent / "testarm.urdf", "base")
    np.testing.assert_allclose(want[:3, 3], [0.1, -0.2, 0.45], atol=POS_TOL_M)
    np.testing.assert_allclose(robot.controller.T_root_base, want, atol=POS_TOL_M)


def test_fixed_joints_in_a_row_compose(tmp_path: Path) -> None:
    # base_link -> mount -> base, both fixed: the base link's pose is the product of the two origins.
    joints = ('<link name="mount"/><joint name="base_link-mount" type="fixed"><parent link="base_link"/>'
              '<child link="mount"/><origin xyz="0 0 0.2" rpy="0 0 1.5707963267948966"/></joint>'
              '<link name="base"/><joint name="mount-base" type="fixed"><parent link="mount"/>'
              '<child link="base"/><origin xyz="0.3 0 0.1" rpy="0 0.4 0"/></joint>')
    path = _with_base_link(write_arm(tmp_path / "testarm"), joints)
    got = load_robot_spec(path).controller.T_root_base
    want = _link_pose(path.parent / "testarm.urdf", "base")
    np.testing.assert_allclose(want[:3, 3], [0.0, 0.3, 0.3], atol=POS_TOL_M)   # the mount turned 90 deg
    np.testing.assert_allclose(got, want, atol=POS_TOL_M)


def test_a_given_controller_base_wins_identity_included(tmp_path: Path) -> None:
    path = _with_base_link(write_arm(tmp_path / "a" / "testarm"), ROS_I_BASE,
                           "  base: {xyz: [0, 0, 0], rpy: [0, 0, 0]}\n")
    assert np.array_equal(load_robot_spec(path).controller.T_root_base, np.eye(4))
    path = _with_base_link(write_arm(tmp_path / "b" / "testarm"), ROS_I_BASE, "  base: {xyz: [0, 0, 0.3]}\n")
    want = np.eye(4)
    want[2, 3] = 0.3
    assert np.array_equal(load_robot_spec(path).controller.T_root_base, want)
    # Another controller key alone leaves the default to the URDF.
    path = _with_base_link(write_arm(tmp_path / "c" / "testarm"), ROS_I_BASE, "  brand: fanuc\n")
    np.testing.assert_allclose(load_robot_spec(path).controller.T_root_base,
                               _link_pose(path.parent / "testarm.urdf", "base"), atol=POS_TOL_M)


def test_a_base_link_behind_a_movable_joint_is_not_the_controller_base(tmp_path: Path) -> None:
    # A link named `base` carried by joint 1 moves with it: no fixed frame of the controller, so the
    # default stays the URDF root frame (and loading says nothing about it).
    joints = ('<link name="base"/><joint name="link_1-base" type="fixed"><parent link="link_1"/>'
              '<child link="base"/><origin xyz="0 0 0.45"/></joint>')
    path = _with_base_link(write_arm(tmp_path / "testarm"), joints)
    robot = load_robot(load_robot_spec(path))
    assert np.array_equal(robot.controller.T_root_base, np.eye(4))
    assert not any("base" in w and "controller" in w for w in robot.warnings)


def test_a_bad_origin_on_the_way_to_the_base_link_names_the_joint(tmp_path: Path) -> None:
    from robomax_py.errors import RobotModelError

    path = _with_base_link(write_arm(tmp_path / "testarm"), ROS_I_BASE.replace('xyz="0.1 -0.2 0.45"', 'xyz="0.1 nan"'))
    with pytest.raises(RobotModelError, match=r"testarm\.urdf: joint base_link-base: origin xyz: expected 3 finite numbers"):
        load_robot_spec(path)
