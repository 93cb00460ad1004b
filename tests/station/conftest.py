"""Two KR 125-class arms of tests/data/station/two_robots.yaml, r2 brought to 2.2 m from r1 (facing
it), so that random postures often touch or come near: the robot-robot checks' test bodies."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from robomax_py._typing import FloatArray
from robomax_py.io.cell import load_cell_robot
from robomax_py.io.station import load_station
from robomax_py.station.bodies import RobotBody, body_poses, robot_body
from robomax_py.world.scene import build_scene

STATION = Path(__file__).parents[1] / "data" / "station" / "two_robots.yaml"


@pytest.fixture(scope="module")
def bodies() -> tuple[RobotBody, RobotBody]:
    station = load_station(STATION)
    out = []
    for r in station.robots:
        model = load_cell_robot(r.cell)
        out.append(robot_body(r.name, model, build_scene(r.cell, model)))
    T = np.array(out[1].T_world_base)
    T[0, 3] = 2.2
    return out[0], dataclasses.replace(out[1], T_world_base=T)


@pytest.fixture(scope="module")
def random_poses(bodies: tuple[RobotBody, RobotBody]) -> Callable[[int, int], tuple[FloatArray, FloatArray]]:
    """(seed, count) -> each robot's piece poses at `count` postures drawn uniformly within its limits."""

    def draw(seed: int, count: int) -> tuple[FloatArray, FloatArray]:
        a, b = bodies
        rng = np.random.default_rng(seed)
        lim = a.robot.limits
        qa = rng.uniform(lim.lower, lim.upper, (count, a.robot.dof))
        qb = rng.uniform(lim.lower, lim.upper, (count, b.robot.dof))
        return body_poses(a, qa), body_poses(b, qb)

    return draw
