"""A Bézier TCP path followed by the KR 16 of the pick-and-place cell, carrying its housing."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan.bezier_follow import follow_within_limits
from robomax_py.robot.solve import solve_all
from robomax_py.timing.bezier import default_parameters, jerk_limited, path_of
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene

CELL = Path(__file__).resolve().parents[2] / "cells" / "pick_place.yaml"


@pytest.mark.parametrize(("waypoints", "z", "clean"), [
    (np.array([[0.25, -0.95], [0.55, -0.6], [0.55, 0.6], [0.25, 0.95]]), 1.0, True),    # over the floor
    (np.array([[0.6, -0.3], [1.1, -0.1], [1.1, 0.1], [0.6, 0.3]]), 0.6, False),         # into the rack
])
def test_a_path_is_followed_exactly_and_checked(waypoints: np.ndarray, z: float, clean: bool) -> None:
    cell = load_cell(CELL)
    robot = load_cell_robot(cell)
    housing = cell.part("housing")
    world = CollisionWorld(robot, build_scene(cell, robot, held=housing), cell.process.clearance)
    path = path_of(waypoints, np.pi / 2, np.pi / 2, default_parameters(waypoints))
    profile = jerk_limited(path, housing.limits, n=60)
    T0 = np.eye(4)
    T0[:2, 3], T0[2, 3] = waypoints[0], z
    start = solve_all(robot, T0[None])
    followed = follow_within_limits(profile, robot, world, z, np.eye(3), start.q[0][start.valid[0]][0])
    if clean:
        assert followed.ok, followed.problem
        assert followed.tcp_error_m < 1e-9
        assert followed.velocity_ratio <= 1.0 and followed.acceleration_ratio <= 1.0
        # One branch all the way: no joint jumps between 4 ms samples.
        assert np.degrees(np.abs(np.diff(followed.q, axis=0))).max() < 1.0
    else:
        assert followed.problem is not None and "collision" in followed.problem
