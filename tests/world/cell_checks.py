"""The definition a certified cell stands for, checked the same way for every certificate: coal's
distance of the pair at configurations spread over the cell, the other joints anywhere."""

from __future__ import annotations

from typing import Any

import numpy as np
import pinocchio as pin

from robomax_py.robot import RobotModel
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.pair_cells import CellTable


def free_throughout(world: CollisionWorld, robot: RobotModel, pair: int, table: CellTable, lo: np.ndarray,
                    hi: np.ndarray, rng: np.random.Generator, scratch: tuple[Any, Any], samples: int = 5) -> int:
    """Assert that `pair` is farther apart than its margin at `samples` configurations: the table's
    joints spread over the cell [lo, hi], the others anywhere within the limits. scratch: Pinocchio
    data and geometry data of the world's models. Returns the configurations checked."""
    s = world._s
    data, gdata = scratch
    joints = list(table.q_index)
    for _ in range(samples):
        x = rng.uniform(robot.limits.lower, robot.limits.upper)
        x[joints] = rng.uniform(lo, hi)[joints]
        pin.updateGeometryPlacements(s.model, data, s.geom_model, gdata, x)
        distance = pin.computeDistance(s.geom_model, gdata, pair).min_distance
        assert distance > s.pair_margin[pair], (pair, x, distance)
    return samples
