"""robomax_py.plan.rrt_detour: the last-resort detour by OMPL's RRT-Connect.

What must hold: between two free configurations whose straight move is blocked (the UR10 swinging
its A1 through a pillar) it returns a detour that starts at qa, ends at qb and whose every segment
is free by the swept check (checked here again); the same generator state gives the same detour.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh

from robomax_py.io.robot import resolve_package_uri, urdf_package_dirs
from robomax_py.plan.rrt_detour import rrt_detour
from robomax_py.robot import RobotModel, load_robot
from robomax_py.spec import (
    Box,
    CellSpec,
    MeshShape,
    ObjectSpec,
    ProcessSpec,
    RobotSpec,
    ToolSpec,
    frozen_array,
)
from robomax_py.transforms import pose_matrix
from robomax_py.world.collision import CollisionOptions, CollisionWorld
from robomax_py.world.scene import build_scene

UR10_Q0 = np.array([0.0, -1.2, 1.5, -1.9, -1.57, 0.0])     # flange ~0.89 m ahead, 0.44 m up
CLEARANCE_M = 0.01


@pytest.fixture(scope="module")
def pillar_world(tmp_path_factory: pytest.TempPathFactory) -> tuple[RobotModel, CollisionWorld]:
    """The UR10 with a stub tool and a 0.6 m pillar standing where its flange is at UR10_Q0."""
    urdf = resolve_package_uri(
        "package://example-robot-data/robots/ur_description/urdf/ur10_robot.urdf", Path("ur10"), "urdf"
    )
    spec = RobotSpec("ur10", urdf, urdf, "tool0", "numeric", None, None, None, package_dirs=urdf_package_dirs(urdf, urdf))
    robot = load_robot(spec)
    folder = tmp_path_factory.mktemp("stub_tool")
    trimesh.creation.box([0.06, 0.06, 0.12]).apply_translation([0.0, 0.0, 0.06]).export(folder / "body.stl")
    trimesh.creation.box([0.02, 0.02, 0.02]).apply_translation([0.0, 0.0, 0.13]).export(folder / "tips.stl")
    tool = ToolSpec("stub", folder / "tool.yaml", MeshShape(folder / "body.stl"), MeshShape(folder / "tips.stl"),
                    frozen_array(pose_matrix([0.0, 0.0, 0.14], [0.0, 0.0, 0.0])))
    pillar = ObjectSpec("pillar", Box((0.2, 0.2, 0.6)), frozen_array(pose_matrix([0.9, 0.0, 0.3], [0.0, 0.0, 0.0])))
    cell = CellSpec(
        name="pillar", source=Path("cells/pillar.yaml"), robot=spec, T_world_base=frozen_array(np.eye(4)),
        home=frozen_array(np.zeros(robot.dof)), tool=tool, objects=(pillar,), seams=(),
        process=ProcessSpec(clearance=CLEARANCE_M), dynamic=(),
    )
    options = CollisionOptions(acm_samples=200, acm_proof_joints=0)     # obstacles matter here, not the ACM
    return robot, CollisionWorld(robot, build_scene(cell, robot), CLEARANCE_M, options)


def test_a_blocked_swing_is_joined_by_free_segments_and_the_same_seed_gives_the_same_path(
        pillar_world: tuple[RobotModel, CollisionWorld]) -> None:
    robot, world = pillar_world
    qa, qb = UR10_Q0 + [-0.6, 0, 0, 0, 0, 0], UR10_Q0 + [0.6, 0, 0, 0, 0, 0]
    assert world.is_free(qa) and world.is_free(qb) and not world.check_segment(qa, qb).free

    det, checks = rrt_detour(world, robot.limits, qa, qb, np.random.default_rng(0))
    assert det is not None
    assert checks > 0 and det.checks == checks and np.isfinite(det.time_estimate)
    np.testing.assert_array_equal(det.waypoints[0], qa)
    np.testing.assert_array_equal(det.waypoints[-1], qb)
    assert len(det.waypoints) >= 3                                  # the straight move is blocked
    assert all(world.check_segment(a, b).free for a, b in zip(det.waypoints[:-1], det.waypoints[1:]))
    assert np.all(robot.limits.contains(det.waypoints))

    again, checks_again = rrt_detour(world, robot.limits, qa, qb, np.random.default_rng(0))
    assert again is not None and checks_again == checks
    np.testing.assert_array_equal(again.waypoints, det.waypoints)
