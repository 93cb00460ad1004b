"""Dynamic obstacles: the robot waits at rest until a door's window is over; programs say WAIT."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from robomax_py.app.cli import EXIT_OK, app
from robomax_py.export.plan_program import program_from_plan
from robomax_py.export.rebuild import rebuild
from robomax_py.export.srcl import parse_program, write_program
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions, plan_cell
from robomax_py.plan.waiting import clear_wait
from robomax_py.program import WaitFor
from robomax_py.robot import fk_tcp

SmallCell = Callable[..., Path]
runner = CliRunner()
DOOR_BOX_M = [0.12, 0.12, 0.12]


def test_clear_wait_rounds_up_past_the_window_end() -> None:
    windows = ((1.0, 2.5), (4.0, 5.0))
    assert clear_wait(0.5, windows) == 0.0
    assert clear_wait(1.0, windows) == pytest.approx(1.501, abs=1e-12)
    assert clear_wait(2.4996, windows) == pytest.approx(0.002, abs=1e-12)   # 0.4 ms -> 1 ms, + 1 ms
    assert clear_wait(3.0, windows) == 0.0
    assert clear_wait(5.0, windows) == pytest.approx(0.001, abs=1e-12)     # windows include their end


@pytest.fixture(scope="module")
def door_cell(tmp_path_factory: pytest.TempPathFactory, write_small_cell: SmallCell) -> dict[str, Any]:
    """The small cell with a door where the robot passes on its way to the first spot."""
    tmp = tmp_path_factory.mktemp("door")
    path = write_small_cell(tmp)
    cell = load_cell(path)
    robot = load_cell_robot(cell)
    free = plan_cell(cell, robot, PlanOptions())
    assert free.status == "planned", free.message
    traj = free.trajectory
    q_way = traj.q[len(traj.q) // 6]
    door_xyz = (np.asarray(cell.T_world_base) @ fk_tcp(robot, q_way))[:3, 3]
    assert traj.t[len(traj.q) // 6] < 1.5             # the premise: it passes there while the door is there
    data = yaml.safe_load(path.read_text())
    data["dynamic"] = [{"name": "door", "box": DOOR_BOX_M, "pose": {"xyz": door_xyz.tolist()},
                        "present": [[0, 1.5]]}]
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return {"tmp": tmp, "path": path, "data": data, "robot": robot, "free": free}


def test_robot_waits_for_the_door_and_the_program_says_so(door_cell: dict[str, Any]) -> None:
    cell = load_cell(door_cell["path"])
    robot = door_cell["robot"]
    result = plan_cell(cell, robot, PlanOptions(dynamic="rest"))
    assert result.status == "planned", result.message
    wait = result.transitions[0].wait
    assert wait is not None and wait.obstacle == "door" and wait.for_signal
    assert wait.seconds == pytest.approx(1.501, abs=1e-9)
    # The same motion, started after the door is gone (same tour, same junction timing).
    assert result.cycle_time == pytest.approx(door_cell["free"].cycle_time + wait.seconds, abs=1e-9)
    (phase,) = result.trajectory.phases_of("wait")
    assert phase.t_start == 0.0 and phase.t_end == pytest.approx(1.501, abs=1e-9)
    program = parse_program(write_program(program_from_plan(result)))
    assert WaitFor("door_clear") in program.instructions
    rebuilt = rebuild(program, cell, robot, "door.srcl")
    assert rebuilt.problems == []
    np.testing.assert_array_equal(rebuilt.trajectory.q, result.trajectory.q)
    np.testing.assert_array_equal(rebuilt.trajectory.t, result.trajectory.t)


def test_time_aware_planning_is_never_slower_and_verifies(door_cell: dict[str, Any]) -> None:
    """The default (`planner.dynamic: timed`) against waiting at rest on the same cell: never a
    longer cycle, the dynamic obstacle never met, the program rebuilt exactly."""
    cell = load_cell(door_cell["path"])
    robot = door_cell["robot"]
    rest = plan_cell(cell, robot, PlanOptions(dynamic="rest"))
    timed = plan_cell(cell, robot, PlanOptions())
    assert timed.status == "planned", timed.message
    assert timed.cycle_time <= rest.cycle_time + 1e-9
    program = parse_program(write_program(program_from_plan(timed)))
    rebuilt = rebuild(program, cell, robot, "door.srcl")
    assert rebuilt.problems == []
    np.testing.assert_array_equal(rebuilt.trajectory.q, timed.trajectory.q)
    np.testing.assert_array_equal(rebuilt.trajectory.t, timed.trajectory.t)


def test_plan_and_verify_a_door_cell_from_the_command_line(door_cell: dict[str, Any]) -> None:
    out = door_cell["tmp"] / "out"
    data = dict(door_cell["data"], planner={"dynamic": "rest"})
    path = door_cell["tmp"] / "door_rest.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    door_cell = dict(door_cell, path=path)
    result = runner.invoke(app, ["plan", str(door_cell["path"]), "-o", str(out)])
    assert result.exit_code == EXIT_OK, result.output
    for program in ("small_cell.srcl", "small_cell.json"):
        checked = runner.invoke(app, ["verify", str(door_cell["path"]), str(out / program)])
        assert checked.exit_code == EXIT_OK, checked.output
    # Without the wait the program runs into the door: verify must see it.
    text = (out / "small_cell.srcl").read_text().replace("WAIT FOR door_clear;\n", "")
    (out / "no_wait.srcl").write_text(text)
    checked = runner.invoke(app, ["verify", str(door_cell["path"]), str(out / "no_wait.srcl")])
    assert checked.exit_code != EXIT_OK and "door" in checked.output


def test_a_door_that_would_hit_the_waiting_robot_is_infeasible(door_cell: dict[str, Any]) -> None:
    data = dict(door_cell["data"])
    home_tcp = (np.asarray(load_cell(door_cell["path"]).T_world_base)
                @ fk_tcp(door_cell["robot"], np.deg2rad(data["robot"]["home"])))[:3, 3]
    data["dynamic"] = [{"name": "door", "box": [0.3, 0.3, 0.3], "pose": {"xyz": home_tcp.tolist()},
                        "present": [[0.05, 100]]}]
    path = door_cell["tmp"] / "trap.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    cell = load_cell(path)
    result = plan_cell(cell, door_cell["robot"], PlanOptions())
    assert result.status == "infeasible"
    assert "door" in result.message and "waiting" in result.message


def test_an_obstacle_appearing_while_the_robot_rests_is_found(door_cell: dict[str, Any]) -> None:
    """At rest over [0, 10] s, an obstacle at the robot that appears at 5 s is a hit at 5 s (its
    appearance, not the start of the rest, when it is not there yet)."""
    import dataclasses

    from robomax_py.plan.waiting import first_dynamic_hit
    from robomax_py.spec import Box, ObjectSpec
    from robomax_py.timing import dwell
    from robomax_py.world.collision import CollisionWorld
    from robomax_py.world.scene import build_scene

    cell = load_cell(door_cell["path"])
    robot = door_cell["robot"]
    home_tcp = (np.asarray(cell.T_world_base) @ fk_tcp(robot, cell.home))[:3, 3]
    T = np.eye(4)
    T[:3, 3] = home_tcp
    box = ObjectSpec("shutter", Box((0.3, 0.3, 0.3)), T, present=((5.0, 6.0),))
    world = CollisionWorld(robot, build_scene(dataclasses.replace(cell, objects=(), dynamic=(box,)), robot), 0.0)
    assert first_dynamic_hit(world, [dwell(cell.home, 10.0, kind="wait")], 0.0) == ("shutter", 5.0)
    assert first_dynamic_hit(world, [dwell(cell.home, 4.0, kind="wait")], 0.0) is None
