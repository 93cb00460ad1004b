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
