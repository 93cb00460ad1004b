"""A spot whose every straight move is blocked, with a way out found to one neighbour and not another.

Generated bracket cell 117 (tests/data/pocket_spot): the best order found goes from `seam4_1` to
`seam2_4`, and neither a straight move from any configuration reached there nor the detour searches
(RRT-Connect the last resort) join them, while RRT-Connect joins `seam4_1` to home, the move after
it in the cell file's order. The plan was `infeasible: ... nothing known joins seam4_1 -> seam2_4`;
the sequencer now opens the file's order's dead end too before it gives up.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions, plan_cell
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene

CELL = Path(__file__).resolve().parents[1] / "data" / "pocket_spot" / "cells" / "c117_irb2400_bracket_12.yaml"


@pytest.mark.slow
def test_a_spot_left_only_towards_home_plans_collision_free() -> None:
    cell = load_cell(CELL)
    robot = load_cell_robot(cell)
    result = plan_cell(cell, robot, PlanOptions())
    assert result.status == "planned", result.message
    assert result.trajectory is not None
    assert sorted(s.name for s in result.spots) == sorted(p.name for seam in cell.seams for p in seam.spots)
    # The plan's moves checked again by the collision world itself, sample to sample.
    world = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    q = result.trajectory.q
    blocked = [k for k in range(len(q) - 1) if not world.check_segment(q[k], q[k + 1]).free]
    assert not blocked, f"{len(blocked)} moves between samples collide, the first at t = {result.trajectory.t[blocked[0]]:.3f} s"
