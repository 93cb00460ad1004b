"""A six-joint URDF written by a test, without meshes: the import tests' arms that no package ships."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path


def six_joint_urdf(path: Path, name: str, axes: Sequence[str], origins: Sequence[str],
                   collisions: Mapping[int, str] = {}) -> Path:
    """Links l0..l6 joined by revolute j1..j6 (limits ±3 rad, 2 rad/s) with the given axes and
    origins ("x y z"), `collisions` as the <collision> element of link i, and tool0 5 cm beyond l6
    with z along l6's x (the flange convention of ROS-Industrial)."""
    links = "".join(f'<link name="l{i}">{collisions.get(i, "")}</link>' for i in range(7))
    joints = "".join(
        f'<joint name="j{i + 1}" type="revolute"><parent link="l{i}"/><child link="l{i + 1}"/>'
        f'<origin xyz="{o}"/><axis xyz="{a}"/><limit lower="-3" upper="3" effort="1" velocity="2"/></joint>'
        for i, (a, o) in enumerate(zip(axes, origins)))
    path.write_text(f'<robot name="{name}">{links}{joints}<link name="tool0"/><joint name="j_t" type="fixed">'
                    f'<parent link="l6"/><child link="tool0"/><origin xyz="0.05 0 0" rpy="0 1.5707963267948966 0"/>'
                    f'</joint></robot>')
    return path


# The KUKA LBR iiwa 14 R820's chain as ros-industrial/kuka_experimental@e78bbd1 states it
# (kuka_lbr_iiwa_support/urdf/lbr_iiwa_14_r820.urdf): joint origins (m), axes, limits (rad, rad/s).
IIWA14_JOINTS = (
    ("0 0 0", "0 0 1", 2.9668, 1.4834), ("-0.00043624 0 0.36", "0 1 0", 2.0942, 1.4834),
    ("0 0 0", "0 0 1", 2.9668, 1.7452), ("0.00043624 0 0.42", "0 -1 0", 2.0942, 1.3089),
    ("0 0 0", "0 0 1", 2.9668, 2.2688), ("0 0 0.4", "0 1 0", 2.0942, 2.356),
    ("0 0 0", "0 0 1", 3.0541, 2.356),
)
# Each link's collision body, this file's own stand-in for the package's meshes: a cylinder along z
# (radius, length, centre height in the link's frame), each link's joint frame at its joint.
IIWA14_BODIES = ((0.07, 0.15, 0.075), (0.065, 0.115, 0.2225), (0.065, 0.06, 0.0), (0.06, 0.28, 0.18),
                 (0.06, 0.06, 0.0), (0.055, 0.26, 0.23), (0.05, 0.06, 0.0), (0.04, 0.06, 0.03))


def iiwa14_urdf(path: Path) -> Path:
    """A seven-joint arm with the LBR iiwa 14 R820's kinematics (`IIWA14_JOINTS`), cylinders for
    links and tool0 0.126 m along link 7's z, as the package has it."""
    links = "".join(
        f'<link name="link_{i}"><collision><origin xyz="0 0 {z}"/><geometry><cylinder radius="{r}" length="{h}"/>'
        f'</geometry></collision></link>' for i, (r, h, z) in enumerate(IIWA14_BODIES))
    joints = "".join(
        f'<joint name="joint_a{i + 1}" type="revolute"><parent link="link_{i}"/><child link="link_{i + 1}"/>'
        f'<origin xyz="{o}"/><axis xyz="{a}"/><limit lower="-{lim}" upper="{lim}" effort="0" velocity="{v}"/></joint>'
        for i, (o, a, lim, v) in enumerate(IIWA14_JOINTS))
    path.write_text(f'<robot name="lbr_iiwa_14_r820">{links}{joints}<link name="tool0"/>'
                    f'<joint name="joint_a7-tool0" type="fixed"><parent link="link_7"/><child link="tool0"/>'
                    f'<origin xyz="0 0 0.126"/></joint></robot>')
    return path
