"""The arm and gun the collision-world tests share: the UR10 of example-robot-data, and a
synthetic box gun of known dimensions."""

from __future__ import annotations

from pathlib import Path

import pytest
import trimesh

from robomax_py.io.robot import resolve_package_uri, urdf_package_dirs
from robomax_py.robot import RobotModel, load_robot
from robomax_py.spec import MeshShape, RobotSpec, ToolSpec, frozen_array
from robomax_py.transforms import pose_matrix


@pytest.fixture(scope="module")
def ur10() -> RobotModel:
    urdf = resolve_package_uri(
        "package://example-robot-data/robots/ur_description/urdf/ur10_robot.urdf", Path("ur10"), "urdf"
    )
    return load_robot(RobotSpec("ur10", urdf, urdf, "tool0", "numeric", None, None, None, package_dirs=urdf_package_dirs(urdf, urdf)))


@pytest.fixture(scope="module")
def gun(tmp_path_factory: pytest.TempPathFactory) -> ToolSpec:
    """A synthetic C-gun in the flange frame (m): body = three closed boxes, tips = one box whose
    lower face is at z = 0.30 and which touches the body only at z = 0.35."""
    folder = tmp_path_factory.mktemp("gun")
    body = trimesh.util.concatenate([
        trimesh.creation.box([0.08, 0.08, 0.10]).apply_translation([0.0, 0.0, 0.05]),
        trimesh.creation.box([0.05, 0.05, 0.30]).apply_translation([0.10, 0.0, 0.25]),
        trimesh.creation.box([0.25, 0.05, 0.05]).apply_translation([0.0, 0.0, 0.375]),
    ])
    tips = trimesh.creation.box([0.02, 0.02, 0.05]).apply_translation([-0.10, 0.0, 0.325])
    body.export(folder / "body.stl")
    tips.export(folder / "tips.stl")
    return ToolSpec("gun", folder / "tool.yaml", MeshShape(folder / "body.stl"), MeshShape(folder / "tips.stl"),
                    frozen_array(pose_matrix([-0.1, 0.0, 0.3], [0.0, 0.0, 0.0])))
