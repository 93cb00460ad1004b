"""The tending cell planned both ways: the time-aware plan is never slower than waiting at rest,
waits in front of the doors for them to open, grips and releases at the stations, never comes
within the clearance of a closed door, and its program rebuilds to exactly the planned motion."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from robomax_py.export.plan_program import program_from_plan
from robomax_py.export.rebuild import rebuild
from robomax_py.export.srcl import parse_program, write_program
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions, plan_cell
from robomax_py.program import Gripper, Spot, WaitFor
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.motion import min_clearance
from robomax_py.world.scene import build_scene

REPO = Path(__file__).resolve().parents[2]


@pytest.mark.slow
def test_time_aware_tending_against_waiting_at_rest() -> None:
    cell = load_cell(REPO / "cells" / "tending.yaml")
    robot = load_cell_robot(cell)
    rest = plan_cell(cell, robot, PlanOptions(dynamic="rest"))
    timed = plan_cell(cell, robot, PlanOptions())
    assert rest.status == timed.status == "planned", (rest.message, timed.message)
    assert timed.cycle_time <= rest.cycle_time
    staged = [t for t in timed.transitions if t.stages]
    assert staged and all(s.wait.door for t in staged for s in t.stages)
    program = parse_program(write_program(program_from_plan(timed)))
    waits = [i.signal for i in program.instructions if isinstance(i, WaitFor)]
    assert set(waits) <= {"cnc1_door_open", "cnc2_door_open"} and waits
    actions = [(i.action, i.name) for i in program.instructions if isinstance(i, Gripper)]
    assert [a for a, _ in actions] == ["grip", "release", "grip", "release"] * 3
    assert not any(isinstance(i, Spot) for i in program.instructions)
    rebuilt = rebuild(program, cell, robot, "tending.srcl")
    assert rebuilt.problems == []
    np.testing.assert_array_equal(rebuilt.trajectory.q, timed.trajectory.q)
    # Never within the clearance of a door while it is closed (every sample of the dense program).
    doors = CollisionWorld(robot, build_scene(replace(cell, objects=()), robot), 0.0).restricted(self_pairs=False)
    traj = timed.trajectory
    least = min_clearance(doors, traj.t, traj.q)      # every sample's exact minimum, then refined between
    assert least is not None and least.distance_m >= cell.process.clearance


@pytest.mark.slow
def test_a_generated_tending_cell_plans_both_ways(tmp_path: Path) -> None:
    """A seeded cell from tests/bench/tending_cells.py (KR 16 class arm, its machines and schedules
    drawn) that waiting at rest could only plan by entering a machine in a later opening (a door
    would otherwise close on the robot inside): both ways plan, the time-aware plan is no longer."""
    import importlib.util

    import yaml

    spec = importlib.util.spec_from_file_location("tending_cells", REPO / "tests" / "bench" / "tending_cells.py")
    assert spec is not None and spec.loader is not None
    generator = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(generator)
    rng = np.random.default_rng(5)
    data = [generator.cell(rng, i) for i in range(2)][1]
    path = tmp_path / "generated.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    cell = load_cell(path)
    robot = load_cell_robot(cell)
    rest = plan_cell(cell, robot, PlanOptions(dynamic="rest"))
    timed = plan_cell(cell, robot, PlanOptions())
    assert rest.status == timed.status == "planned", (rest.message, timed.message)
    assert timed.cycle_time <= rest.cycle_time
    assert any(t.wait is not None and not t.wait.for_signal for t in rest.transitions)   # held back a window
