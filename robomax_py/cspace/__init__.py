"""Configuration-space maps of A1-A3 with the wrist fixed (the ROBOMAX C-space method).

`build_map(cell, robot, wrist, resolution)` checks every cell of the grid exactly with the cell's
collision world; `learned_model` (trained once, cached on disk) and `learned_map` give the same map
from the method's learned point model (`cspace.learned`). Detours are searched in a learned map by
`plan.learned_detour` (`planner.detours: learned`), in exact local maps by `plan.cspace_detour`.
"""

from __future__ import annotations

from typing import Literal

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.cspace.cache import cache_dir, learned_model
from robomax_py.cspace.exact import CSpaceMap, default_workers, exact_map
from robomax_py.cspace.grid import (
    MAX_RESOLUTION,
    MIN_RESOLUTION,
    CSpaceError,
    CSpaceGrid,
    check_arm,
)
from robomax_py.cspace.learned import LearnedModel, TrainingSettings, learned_map
from robomax_py.cspace.points import cover_radius, surface_points
from robomax_py.robot import RobotModel
from robomax_py.spec import CellSpec
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene


def build_map(
    cell: CellSpec,
    robot: RobotModel,
    wrist: Literal["home"] | FloatArray = "home",
    resolution: int = 50,
    workers: int = 1,
    world: CollisionWorld | None = None,
) -> CSpaceMap:
    """The exact A1-A3 map of `cell` (its clearance applied) with the wrist at home or at the given
    joint values (rad, joints 4..6), in `world` when the caller has built the cell's world already.
    A cell without objects is a CSpaceError: there is nothing to map."""
    check_arm(robot)
    values = np.asarray(cell.home, dtype=float)[3:] if isinstance(wrist, str) and wrist == "home" else wrist
    grid = CSpaceGrid.of(robot, resolution, np.asarray(values, dtype=float))
    if not (cell.objects or cell.dynamic):
        raise CSpaceError(f"{cell.source}: objects: the cell has no objects, so its C-space map has no obstacles")
    if world is None:
        world = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    return exact_map(world, grid, workers)


__all__ = [
    "MAX_RESOLUTION", "MIN_RESOLUTION", "CSpaceError", "CSpaceGrid", "CSpaceMap", "LearnedModel", "TrainingSettings",
    "build_map", "cache_dir", "check_arm", "cover_radius", "default_workers", "exact_map", "learned_map",
    "learned_model", "surface_points",
]
