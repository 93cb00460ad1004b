"""The cells' tests' common ground: a world whose cells start undecided, and the definition a
certified cell stands for, checked the same way for every certificate (coal's distance of the pair
at configurations spread over the cell, the other joints anywhere)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from robomax_py.robot import RobotModel
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.pair_cells import CellTable
from robomax_py.world.scene import build_scene


def undecided_world(path: Path) -> tuple[RobotModel, CollisionWorld]:
    """The world of the cell at `path`, its cells undecided (the worlds of one arm and tool share
    their decisions: those earlier tests or runs made are cleared)."""
    from robomax_py.io.cell import load_cell, load_cell_robot

    cell = load_cell(path)
    robot = load_cell_robot(cell)
    world = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    assert world._s.prefilter is not None
    world._s.prefilter.cells.decided[:] = 0
    return robot, world


def either_side(exact: CollisionWorld, hit: np.ndarray, free: np.ndarray, steps: int = 20) -> tuple[np.ndarray, np.ndarray]:
    """Two configurations either side of a contact, `steps` halvings apart on the segment from a
    colliding configuration `hit` to a free one (by the world `exact`)."""
    a, b = hit, free
    for _ in range(steps):
        mid = (a + b) / 2
        a, b = (mid, b) if not exact.is_free(mid) else (a, mid)
    return a, b


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
