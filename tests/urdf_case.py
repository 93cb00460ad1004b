"""Serial-arm URDFs written by tests, without meshes: the arms that no package the tests keep ships."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path


def serial_urdf(path: Path, name: str, joints: Sequence[tuple[str, str, float, float, float]], tool0: str, *,
                link: str = "l{}", joint: str = "j{}", tool0_joint: str = "j_t",
                collisions: Mapping[int, str] = {}, prismatic: frozenset[int] = frozenset()) -> Path:
    """A serial arm: links `link`.format(0..n) joined by revolute joints `joint`.format(1..n), each
    (origin "x y z", axis "x y z", lower, upper rad, velocity rad/s); `collisions` the <collision>
    element of link i; tool0 fixed on the last link at `tool0` (an <origin> element). The joints
    numbered in `prismatic` (1..n) slide instead (limits in m, velocity in m/s)."""
    links = "".join(f'<link name="{link.format(i)}">{collisions.get(i, "")}</link>' for i in range(len(joints) + 1))
    body = "".join(
        f'<joint name="{joint.format(i + 1)}" type="{"prismatic" if i + 1 in prismatic else "revolute"}">'
        f'<parent link="{link.format(i)}"/>'
        f'<child link="{link.format(i + 1)}"/><origin xyz="{origin}"/><axis xyz="{axis}"/>'
        f'<limit lower="{lower}" upper="{upper}" effort="1" velocity="{velocity}"/></joint>'
        for i, (origin, axis, lower, upper, velocity) in enumerate(joints))
    path.write_text(f'<robot name="{name}">{links}{body}<link name="tool0"/><joint name="{tool0_joint}" type="fixed">'
                    f'<parent link="{link.format(len(joints))}"/><child link="tool0"/>{tool0}</joint></robot>')
    return path


def six_joint_urdf(path: Path, name: str, axes: Sequence[str], origins: Sequence[str],
                   collisions: Mapping[int, str] = {}) -> Path:
    """Links l0..l6 joined by revolute j1..j6 (limits ±3 rad, 2 rad/s) with the given axes and
    origins ("x y z"), `collisions` as the <collision> element of link i, and tool0 5 cm beyond l6
    with z along l6's x (the flange convention of ROS-Industrial)."""
    return serial_urdf(path, name, [(o, a, -3, 3, 2) for a, o in zip(axes, origins)],
                       '<origin xyz="0.05 0 0" rpy="0 1.5707963267948966 0"/>', collisions=collisions)


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
    bodies = {i: f'<collision><origin xyz="0 0 {z}"/><geometry><cylinder radius="{r}" length="{h}"/></geometry>'
                 f'</collision>' for i, (r, h, z) in enumerate(IIWA14_BODIES)}
    return serial_urdf(path, "lbr_iiwa_14_r820", [(o, a, -lim, lim, v) for o, a, lim, v in IIWA14_JOINTS],
                       '<origin xyz="0 0 0.126"/>', link="link_{}", joint="joint_a{}", tool0_joint="joint_a7-tool0",
                       collisions=bodies)


# A six-axis arm of the KR 16's proportions on a 3 m floor track along x: joint 1 slides (0 to 3 m,
# 1 m/s), the arm stands 0.2 m above the track's zero. Cylinders for the arm's links.
TRACK_JOINTS = (
    ("0 0 0", "1 0 0", 0.0, 3.0, 1.0),
    ("0 0 0.6", "0 0 1", -3.0, 3.0, 2.5), ("0.26 0 0", "0 1 0", -3.0, 1.2, 2.5),
    ("0 0 0.68", "0 1 0", -2.0, 2.6, 2.5), ("0.3 0 0.035", "1 0 0", -3.0, 3.0, 5.0),
    ("0.37 0 0", "0 1 0", -2.0, 2.0, 5.0), ("0.08 0 0", "1 0 0", -3.0, 3.0, 7.0),
)
TRACK_BODIES = {
    1: '<collision><origin xyz="0 0 0.3"/><geometry><cylinder radius="0.12" length="0.5"/></geometry></collision>',
    3: '<collision><origin xyz="0 0 0.34"/><geometry><cylinder radius="0.07" length="0.5"/></geometry></collision>',
    4: '<collision><origin xyz="0.2 0 0.035" rpy="0 1.5708 0"/><geometry><cylinder radius="0.06" length="0.3"/>'
       '</geometry></collision>',
}


def track_arm_urdf(path: Path) -> Path:
    """`TRACK_JOINTS`: a prismatic track (joint j1) carrying a six-axis arm (joints j2..j7),
    tool0 on the last link with z along its x (the flange convention of ROS-Industrial)."""
    return serial_urdf(path, "track_arm", TRACK_JOINTS, '<origin xyz="0 0 0" rpy="0 1.5707963267948966 0"/>',
                       collisions=TRACK_BODIES, prismatic=frozenset({1}))
