"""A part carried on a conveyor across the arm's way (tests/data/moving/conveyor_cross.yaml):
planned in time, `verify` finds the program clean, and a program that drives into the part while
it passes is caught with the part's name and the time."""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from robomax_py.export.plan_program import program_from_plan
from robomax_py.export.srcl import write_program
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions, plan_cell
from robomax_py.verify import verify_program

CELL = Path(__file__).resolve().parents[1] / "data" / "moving" / "conveyor_cross.yaml"


def _plans() -> dict[str, Any]:
    cell = load_cell(CELL)
    robot = load_cell_robot(cell)
    timed = plan_cell(cell, robot, PlanOptions())
    rest = plan_cell(cell, robot, PlanOptions(dynamic="rest"))
    astar = plan_cell(cell, robot, PlanOptions(dynamic="astar"))
    return {"timed": (timed.status, timed.cycle_time, write_program(program_from_plan(timed))),
            "rest": (rest.status, rest.cycle_time),
            "astar": (astar.status, astar.cycle_time, sum(t.wait is not None for t in astar.transitions),
                      write_program(program_from_plan(astar)))}


@pytest.fixture(scope="module")
def plans(shared_once: Callable[[str, Callable[[], Any]], Any]) -> dict[str, Any]:
    out: dict[str, Any] = shared_once("moving-conveyor-cross " + CELL.read_text(), _plans)
    return out


def test_the_part_is_waited_for_and_the_program_verifies_clean(plans: dict[str, Any], tmp_path: Path) -> None:
    status, cycle, text = plans["timed"]
    rest_status, rest_cycle = plans["rest"]
    assert status == rest_status == "planned"
    # The part stands in the way until it goes back: the robot waits, no longer than waiting at rest
    # for the part's last window to end.
    assert re.search(r"^\s*WAIT [0-9.]+ SEC;", text, re.MULTILINE)
    assert cycle <= rest_cycle + 1e-9
    cell = load_cell(CELL)
    program = tmp_path / "conveyor_cross.srcl"
    program.write_text(text)
    report = verify_program(cell, load_cell_robot(cell), program)
    assert report.clean, report.violations


def test_verify_catches_a_program_that_meets_the_passing_part(plans: dict[str, Any], tmp_path: Path) -> None:
    """The program's wait cut to 1 s: the arm reaches the other station while the part stands there."""
    _, _, text = plans["timed"]
    short, n = re.subn(r"WAIT [0-9.]+ SEC;", "WAIT 1.0 SEC;", text, count=1)
    assert n == 1
    program = tmp_path / "conveyor_cross.srcl"
    program.write_text(short)
    cell = load_cell(CELL)
    report = verify_program(cell, load_cell_robot(cell), program)
    hits = [v for v in report.violations if v.kind == "collision" and "part" in v.detail]
    assert hits, report.violations
    # The part is in front of the stations from 4 s to 8 s (moving in before, out after).
    assert all(v.t is not None and 0.0 < v.t < 12.0 for v in hits)


def test_the_classical_astar_baseline_must_stop_for_the_part(plans: dict[str, Any], tmp_path: Path) -> None:
    """`dynamic: astar`: the same graph searched with time ignored; its route meets the part at its
    time, so the robot stops at rest before it (a dangerous situation of the paper); the program
    with the stop verifies clean and is no shorter than the time-aware one."""
    status, cycle, stops, text = plans["astar"]
    assert status == "planned" and stops >= 1
    assert plans["timed"][1] <= cycle + 1e-9
    cell = load_cell(CELL)
    program = tmp_path / "astar.srcl"
    program.write_text(text)
    assert verify_program(cell, load_cell_robot(cell), program).clean
