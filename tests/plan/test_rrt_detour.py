"""robomax_py.plan.rrt_detour: the last-resort detour by OMPL's RRT-Connect.

What must hold: between two free configurations whose straight move is blocked (the UR10 swinging
its A1 through a pillar) it returns a detour that starts at qa, ends at qb and whose every segment
is free by the swept check (checked here again); the same generator state gives the same detour.
"""

from __future__ import annotations

import itertools
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


def test_a_stop_that_sees_no_way_to_its_first_stop_goes_home_and_follows_the_tour_s_first_move(
        pillar_world: tuple[RobotModel, CollisionWorld], monkeypatch: pytest.MonkeyPatch) -> None:
    """`plan.lead_in`: a continuation stopped left of the pillar whose first stop is right of it,
    with no roadmap and the random trees out of budget (as on a stop beyond clamps and an object
    that appeared): the lead-in goes back to home, free from the stop, and follows the tour's own
    first move from home, every segment free; where home cannot be reached either, it refuses."""
    from robomax_py.plan import lead_in as lead
    from robomax_py.plan.results import Transition

    robot, world = pillar_world
    stop, first_stop = UR10_Q0 + [-0.6, 0, 0, 0, 0, 0], UR10_Q0 + [0.6, 0, 0, 0, 0, 0]
    home = UR10_Q0 + [0.0, -0.6, -0.5, 0, 0, 0]          # above the pillar: seen from both
    assert not world.check_segment(stop, first_stop).free
    monkeypatch.setattr(lead, "rrt_detour", lambda *args: (None, 0))      # the trees' budget spent
    tour = [Transition("move", np.vstack([home, first_stop]), "home -> s1")]

    moved = lead.lead_in(world, None, stop, tour, robot, np.random.default_rng(0))
    path = moved[0].waypoints
    assert moved[0].kind == "detour" and moved[0].label == "stop -> s1"
    np.testing.assert_allclose(path[0], stop, atol=1e-6)                    # as written: 1e-4 deg rounding
    np.testing.assert_allclose(path[-1], first_stop, atol=1e-6)
    assert any(np.allclose(w, home, atol=1e-6) for w in path)
    assert all(world.check_segment(a, b).free for a, b in itertools.pairwise(path))

    unseen = UR10_Q0 + [0.0, -0.8, 0, 0, 0, 0]           # free, but the stop's straight move to it is not
    assert world.is_free(unseen) and not world.check_segment(stop, unseen).free
    with pytest.raises(lead.LeadInError, match="nor back to home"):
        lead.lead_in(world, None, stop, [Transition("move", np.vstack([unseen, first_stop]), "home -> s1")],
                     robot, np.random.default_rng(0))


def test_a_search_stops_once_its_configurations_are_spent(pillar_world: tuple[RobotModel, CollisionWorld]) -> None:
    """The trees stop at `CHECK_BUDGET` configurations checked, however few swept checks that took:
    a world where every move is blocked and each swept check costs 300 configurations (a long tree
    edge of a fast arm) stops after about CHECK_BUDGET / 300 of them, not after BUDGET."""
    from robomax_py.plan.rrt_detour import BUDGET, CHECK_BUDGET
    from robomax_py.world.collision_results import SegmentCheck

    robot, _ = pillar_world

    class Walled:
        swept = 0

        def is_free(self, q: np.ndarray) -> bool:
            return True

        def check_segment(self, a: np.ndarray, b: np.ndarray) -> SegmentCheck:
            self.swept += 1
            return SegmentCheck(False, 300, 300, 300, 0.0)

    world = Walled()
    det, spent = rrt_detour(world, robot.limits, UR10_Q0, -UR10_Q0, np.random.default_rng(0))  # type: ignore[arg-type]
    assert det is None
    assert CHECK_BUDGET <= spent <= CHECK_BUDGET + 300 * 4 and world.swept < BUDGET, (spent, world.swept)
