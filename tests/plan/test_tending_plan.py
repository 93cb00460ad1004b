"""A generated tending cell planned both ways: the time-aware plan is never slower than waiting at
rest. (The shipped tending cell's program and door clearance are checked with the shipped cells, in
tests/test_shipped_cells.py.)"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions, plan_cell

REPO = Path(__file__).resolve().parents[2]


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
    # Seed 5 stopped waiting once the local map repaired its detours; seed 0's second cell still
    # enters a machine in a later opening when planned at rest.
    rng = np.random.default_rng(0)
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
