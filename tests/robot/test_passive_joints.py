"""Arms with `<mimic>` joints (balancer cylinders and pistons, parallelogram links), imported from
ROS-Industrial packages as published (tests/data/rosi, see SOURCES.md there): the passive links load
and follow the joint they mimic, collide like every link, the package's SRDF pairs for them are
honoured, and the robot keeps its six active joints for IK, the fit and programs."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from numpy.testing import assert_allclose

from robomax_py.app.import_urdf import import_urdf
from robomax_py.io.robot import load_robot_spec
from robomax_py.robot import active_joints, load_robot, mimic_relation, passive_joints
from robomax_py.robot.solve import solve_all
from robomax_py.transforms import pose_matrix
from robomax_py.world.bounds import KinematicBounds

ROSI = Path(__file__).parent.parent / "data" / "rosi"
IRB6640 = ROSI / "abb_irb6640_support/urdf/irb6640_185_280.xacro"
IRB6640_SRDF = ROSI / "abb_irb6640_moveit_config/config/abb_irb6640_185_280.srdf"
M900IA = ROSI / "fanuc_m900ia_support/urdf/m900ia260l.xacro"
POSE_TOL_M = 1e-9


@pytest.fixture(scope="module")
def folders(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("robots")
    return {
        "irb6640": import_urdf(IRB6640, root / "irb6640", (ROSI,), srdf=IRB6640_SRDF).folder,
        "m900ia": import_urdf(M900IA, root / "m900ia", (ROSI,)).folder,
    }


@pytest.fixture(scope="module")
def robots(folders: dict[str, Path]):  # type: ignore[no-untyped-def]
    return {name: load_robot(load_robot_spec(folder / "robot.yaml")) for name, folder in folders.items()}


def _params(folder: Path) -> dict[str, float]:
    import yaml

    return dict(yaml.safe_load((folder / "robot.yaml").read_text())["ik"]["params"])


def test_six_active_joints_and_the_passive_ones(robots) -> None:  # type: ignore[no-untyped-def]
    irb, m900 = robots["irb6640"], robots["m900ia"]
    assert irb.joint_names == tuple(f"joint_{i}" for i in range(1, 7))
    assert irb.dof == 6 and m900.dof == 6
    model = irb.model
    assert sorted(model.names[j] for j in passive_joints(model)) == ["joint_cylinder", "joint_piston"]
    assert [model.names[j] for j in active_joints(model)] == list(irb.joint_names)
    # abb_irb6640_support/urdf/irb6640_185_280_macro.xacro: mimic joint_2, multiplier -0.25 / -1.25
    relations = {model.names[j]: mimic_relation(model, j) for j in passive_joints(model)}
    assert relations == {"joint_cylinder": (1, -0.25, 0.0), "joint_piston": (1, -1.25, 0.0)}
    assert sorted(m900.model.names[j] for j in passive_joints(m900.model)) == ["pjoint_1", "pjoint_2"]


def test_fitted_opw_parameters_are_the_arms_dimensions(folders: dict[str, Path]) -> None:
    # The joint origins of abb_irb6640_support/urdf/irb6640_185_280_macro.xacro and
    # fanuc_m900ia_support/urdf/m900ia260l_macro.xacro (ros-industrial/abb@77db19b,
    # ros-industrial/fanuc@8fee5e3), which state ABB's and FANUC's data-sheet dimensions.
    want = {
        "irb6640": {"a1": 0.32, "a2": -0.2, "b": 0.0, "c1": 0.78, "c2": 1.075, "c3": 1.392, "c4": 0.2},
        "m900ia": {"a1": 0.37, "a2": -0.2, "b": 0.0, "c1": 0.95, "c2": 1.05, "c3": 1.705, "c4": 0.27},
    }
    for name, dims in want.items():
        got = _params(folders[name])
        assert {k: got[k] for k in dims} == pytest.approx(dims, abs=1e-9), name


def test_passive_links_follow_the_mimic_relation(robots) -> None:  # type: ignore[no-untyped-def]
    """link_piston = link_2 · origin(joint_piston) · Ry(-1.25 q2), from the URDF text itself."""
    robot = robots["irb6640"]
    root = ET.fromstring((robot.source.parent / "irb6640.urdf").read_text())
    joints = {j.get("name"): j for j in root.findall("joint")}
    model, data = robot.model, robot.model.createData()
    rng = np.random.default_rng(3)
    for q in rng.uniform(robot.limits.lower, robot.limits.upper, size=(5, 6)):
        pin.framesForwardKinematics(model, data, q)
        for joint, parent, child, mult in (("joint_piston", "link_2", "link_piston", -1.25),
                                           ("joint_cylinder", "link_1", "link_cylinder", -0.25)):
            origin = joints[joint].find("origin")
            T_origin = pose_matrix([float(v) for v in origin.get("xyz").split()],
                                   [float(v) for v in origin.get("rpy").split()])
            turn = pose_matrix([0, 0, 0], [0, mult * q[1], 0])          # axis y
            want = data.oMf[model.getFrameId(parent)].homogeneous @ T_origin @ turn
            assert_allclose(data.oMf[model.getFrameId(child)].homogeneous, want, atol=POSE_TOL_M)


def test_passive_links_collide_and_keep_their_srdf_pairs(robots) -> None:  # type: ignore[no-untyped-def]
    robot = robots["irb6640"]
    on = {robot.model.names[g.parentJoint] for g in robot.collision_model.geometryObjects}
    assert {"joint_piston", "joint_cylinder"} <= on
    # abb_irb6640_moveit_config/config/abb_irb6640_185_280.srdf disables link_cylinder/link_piston
    assert frozenset({"link_cylinder", "link_piston"}) in robot.disabled_links
    assert frozenset({"link_2", "link_piston"}) in robot.disabled_links
    # The sweep bound of joint 2 covers the piston turning 1.25 times as fast about its own axis.
    bounds = KinematicBounds.of(robot.model)
    moving = [g.parentJoint != 0 for g in robot.collision_model.geometryObjects]
    lever = bounds.lever_arms(robot.collision_model, moving)
    piston = robot.model.getJointId("joint_piston")
    pieces = [g for g in robot.collision_model.geometryObjects if g.parentJoint == piston]
    own = max(bounds.piece_lever(piston, g) for g in pieces)
    assert lever[1] >= max(bounds.piece_lever(2, g) for g in pieces) + 1.25 * own - 1e-12


def test_ik_round_trip_on_the_active_joints(robots) -> None:  # type: ignore[no-untyped-def]
    from robomax_py.robot import fk_flange

    for robot in robots.values():
        rng = np.random.default_rng(0)
        qs = rng.uniform(robot.limits.lower * 0.8, robot.limits.upper * 0.8, size=(20, 6))
        T = fk_flange(robot, qs)
        table = solve_all(robot, T)
        for k in range(len(qs)):
            sols = table.q[k][table.valid[k]]
            assert len(sols) > 0
            assert_allclose(fk_flange(robot, sols), np.broadcast_to(T[k], (len(sols), 4, 4)), atol=1e-8)


def test_an_srdf_naming_links_the_urdf_lacks_is_kept_for_the_others(tmp_path: Path) -> None:
    """With the passive links removed by hand, the package's SRDF still loads: its pairs naming them
    are skipped with a warning that names the user's files, never the staging folder."""
    staged = import_urdf(IRB6640, tmp_path / "full", (ROSI,)).folder
    root = ET.fromstring((staged / "full.urdf").read_text())
    for el in list(root):
        if el.get("name") in ("joint_piston", "joint_cylinder", "link_piston", "link_cylinder"):
            root.remove(el)
    cut = staged / "cut.urdf"
    cut.write_text(ET.tostring(root, encoding="unicode"))
    result = import_urdf(cut, tmp_path / "cut", (staged,), srdf=IRB6640_SRDF)
    warning = next(w for w in result.warnings if "disable_collisions" in w)
    assert str(IRB6640_SRDF) in warning and "cut.urdf" in warning and "robomax-import" not in warning
    assert "link_cylinder" in warning
    robot = load_robot(load_robot_spec(result.folder / "robot.yaml"))
    assert frozenset({"link_2", "link_3"}) in robot.disabled_links


# A small arm holding the two published forms the IRB 6700 and IRB 5400 packages use: a balancer
# cylinder hanging from link_1 whose joint name sorts before the joint it follows, with a
# placeholder velocity of 100 m/s on its prismatic piston; and an offset wrist whose second half
# (`joint_5b`) turns by -q5 on the chain to the flange.
_OFFSET_WRIST = """<robot name="offset_wrist">
  <link name="base_link"/><link name="link_1"/><link name="link_2"/><link name="link_3"/><link name="link_4"/>
  <link name="link_5"/><link name="link_5b"/><link name="link_6"/><link name="tool0"/>
  <link name="cylinder"/><link name="piston"/>
  <joint name="joint_1" type="revolute"><parent link="base_link"/><child link="link_1"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" velocity="2" effort="0"/></joint>
  <joint name="joint_2" type="revolute"><parent link="link_1"/><child link="link_2"/>
    <origin xyz="0.3 0 0.6"/><axis xyz="0 1 0"/><limit lower="-1.5" upper="1.5" velocity="2" effort="0"/></joint>
  <joint name="joint_3" type="revolute"><parent link="link_2"/><child link="link_3"/>
    <origin xyz="0 0 1.1"/><axis xyz="0 1 0"/><limit lower="-1.5" upper="1.5" velocity="2" effort="0"/></joint>
  <joint name="joint_4" type="revolute"><parent link="link_3"/><child link="link_4"/>
    <origin xyz="1.2 0 0.2"/><axis xyz="1 0 0"/><limit lower="-6" upper="6" velocity="6" effort="0"/></joint>
  <joint name="joint_5" type="revolute"><parent link="link_4"/><child link="link_5"/>
    <origin xyz="0.07 0 0" rpy="0 0.6109 0"/><axis xyz="1 0 0"/><limit lower="-6" upper="6" velocity="6" effort="0"/></joint>
  <joint name="joint_5b" type="revolute"><parent link="link_5"/><child link="link_5b"/>
    <origin xyz="0.1 0 0.07" rpy="0 -1.2217 0"/><axis xyz="1 0 0"/>
    <limit lower="-6" upper="6" velocity="6" effort="0"/><mimic joint="joint_5" multiplier="-1.0"/></joint>
  <joint name="joint_6" type="revolute"><parent link="link_5b"/><child link="link_6"/>
    <origin xyz="0.07 0 -0.05" rpy="0 0.6109 0"/><axis xyz="1 0 0"/><limit lower="-6" upper="6" velocity="9" effort="0"/></joint>
  <joint name="joint_6-tool0" type="fixed"><parent link="link_6"/><child link="tool0"/></joint>
  <joint name="cylinder_joint" type="revolute"><parent link="link_1"/><child link="cylinder"/>
    <origin xyz="-0.2 0 0.3"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" velocity="1" effort="0"/>
    <mimic joint="joint_2" multiplier="-0.25"/></joint>
  <joint name="piston_joint" type="prismatic"><parent link="cylinder"/><child link="piston"/>
    <axis xyz="0 0 1"/><limit lower="-0.25" upper="0.25" velocity="100" effort="0"/>
    <mimic joint="joint_2" multiplier="0.15"/></joint>
</robot>
"""


def test_mimic_joint_limits_are_not_checked_and_names_sorting_first_load() -> None:
    from robomax_py.io.robot import check_urdf
    from robomax_py.robot.model import urdf_model

    assert check_urdf(ET.fromstring(_OFFSET_WRIST), Path("offset_wrist.urdf")) == (
        "offset_wrist.urdf: no geometry at all (a kinematic model): collisions of the arm are not checked",)
    model = urdf_model(_OFFSET_WRIST)
    assert [model.names[j] for j in active_joints(model)] == [f"joint_{i}" for i in range(1, 7)]
    assert sorted(model.names[j] for j in passive_joints(model)) == ["cylinder_joint", "joint_5b", "piston_joint"]
    assert model.existFrame("piston_joint") and model.existFrame("piston")
    assert mimic_relation(model, model.getJointId("piston_joint")) == (1, 0.15, 0.0)


def test_a_passive_joint_on_the_flange_chain_moves_it_as_pinocchio_does() -> None:
    from robomax_py.robot.ik._chain import (
        chain_to_frame,
        frame_pose_and_jacobian,
        joint_axes_at_zero,
    )
    from robomax_py.robot.model import urdf_model

    model = urdf_model(_OFFSET_WRIST)
    frame = model.getFrameId("tool0")
    chain = chain_to_frame(model, frame)
    assert list(chain.active) == [True] * 5 + [False, True]
    assert len(joint_axes_at_zero(model, frame).u) == 6
    data = model.createData()
    for q in np.random.default_rng(5).uniform(-2.0, 2.0, (8, 6)):
        R, p, J = frame_pose_and_jacobian(chain, q[None])
        pin.framesForwardKinematics(model, data, q)
        assert_allclose(p[:, 0], data.oMf[frame].translation, atol=POSE_TOL_M)
        assert_allclose(R[:, :, 0], data.oMf[frame].rotation, atol=POSE_TOL_M)
        J_pin = pin.computeFrameJacobian(model, data, q, frame, pin.LOCAL_WORLD_ALIGNED)
        assert_allclose(J[0], J_pin, atol=POSE_TOL_M)
